//! `modelDescription.xml` rendered from a [`ModelInfo`]: the variable table
//! is the only place a variable is written down. A model with a Model
//! Exchange interface gets both `<ModelExchange>` and `<CoSimulation>`
//! under one model identifier (one binary serves both).

use crate::variables::{
    Causality, Initial, ModelInfo, VarType, Variability, Variable, LOG_CATEGORIES,
};
use std::fmt::Write;

/// SI base-unit exponents (kg, m, s, A) of the units our models use.
const UNITS: &[(&str, [i32; 4])] = &[
    ("kg", [1, 0, 0, 0]),
    ("1/N", [-1, -1, 2, 0]),
    ("m", [0, 1, 0, 0]),
    ("s", [0, 0, 1, 0]),
    ("1/m", [0, -1, 0, 0]),
    ("m/s", [0, 1, -1, 0]),
    ("m/s2", [0, 1, -2, 0]),
    ("s/m", [0, -1, 1, 0]),
    ("N", [1, 1, -2, 0]),
    ("N/s", [1, 1, -3, 0]),
    ("N/m", [1, 0, -2, 0]),
    ("N.s/m", [1, 0, -1, 0]),
    ("Hz", [0, 0, -1, 0]),
    // energy and power (the contact's stored energy and dissipated power)
    ("J", [1, 2, -2, 0]),
    ("W", [1, 2, -3, 0]),
    // a drive command in volts (the rig controller; EMPS: vir) and its gains
    ("V", [1, 2, -3, -1]),
    ("V/m", [1, 1, -3, -1]),
    ("V.s/m", [1, 1, -2, -1]),
    ("N/V", [0, -1, 1, 1]),
];

pub(crate) fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Shortest representation that parses back to the same `f64`.
pub(crate) fn number(x: f64) -> String {
    format!("{x:?}")
}

pub(crate) fn causality(c: Causality) -> &'static str {
    match c {
        Causality::Parameter => "parameter",
        Causality::Input => "input",
        Causality::Output => "output",
        Causality::Local => "local",
    }
}

pub(crate) fn variability(v: Variability) -> &'static str {
    match v {
        Variability::Fixed => "fixed",
        Variability::Tunable => "tunable",
        Variability::Discrete => "discrete",
        Variability::Continuous => "continuous",
    }
}

/// Render the FMI 2.0 model description. `generation_tool` names the crate
/// and version that built the binary.
pub fn render(info: &ModelInfo, generation_tool: &str) -> Result<String, String> {
    info.check()?;
    let mut x = String::new();
    let caps = &info.capabilities;
    let w = &mut x;
    let _ = writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        w,
        "<!-- Generated from the variable table in the source code; do not edit by hand. -->"
    );
    let _ = writeln!(
        w,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{}" guid="{}" description="{}" author="friction-fmu project" generationTool="{}" variableNamingConvention="structured" numberOfEventIndicators="{}">"#,
        escape(info.model_name),
        escape(info.guid),
        escape(&format!("{} Source: {}", info.description, info.source)),
        escape(generation_tool),
        info.model_exchange.map_or(0, |me| me.event_indicators)
    );
    if info.model_exchange.is_some() {
        // (before <CoSimulation>: the schema's order) The same binary and
        // model identifier for both interfaces; no step events, so no call
        // of fmi2CompletedIntegratorStep is needed.
        let _ = writeln!(
            w,
            r#"  <ModelExchange modelIdentifier="{}" needsExecutionTool="false" completedIntegratorStepNotNeeded="true" canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="{}" canSerializeFMUstate="{}" providesDirectionalDerivative="{}"/>"#,
            escape(info.model_identifier),
            caps.can_get_and_set_state,
            caps.can_serialize_state,
            caps.provides_directional_derivative
        );
    }
    let _ = writeln!(
        w,
        r#"  <CoSimulation modelIdentifier="{}" needsExecutionTool="false" canHandleVariableCommunicationStepSize="{}" canInterpolateInputs="{}" maxOutputDerivativeOrder="{}" canRunAsynchronuously="false" canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="{}" canSerializeFMUstate="{}" providesDirectionalDerivative="{}"/>"#,
        escape(info.model_identifier),
        caps.can_handle_variable_step,
        caps.can_interpolate_inputs,
        caps.max_output_derivative_order,
        caps.can_get_and_set_state,
        caps.can_serialize_state,
        caps.provides_directional_derivative
    );

    unit_definitions(w, info, &[])?;
    log_categories(w);
    default_experiment(w, info);

    let _ = writeln!(w, "  <ModelVariables>");
    for (i, v) in info.variables.iter().enumerate() {
        let _ = writeln!(w, "    <!-- index {} -->", i + 1);
        let initial = match (v.initial(), v.causality) {
            (Some(Initial::Exact), _) => r#" initial="exact""#,
            (Some(Initial::Approx), _) => r#" initial="approx""#,
            (Some(Initial::Calculated), Causality::Output | Causality::Local) => {
                r#" initial="calculated""#
            }
            _ => "",
        };
        let _ = writeln!(
            w,
            r#"    <ScalarVariable name="{}" valueReference="{}" description="{}" causality="{}" variability="{}"{initial}>"#,
            escape(v.name),
            v.vr,
            escape(v.description),
            causality(v.causality),
            variability(v.variability)
        );
        let mut attrs = value_attributes(v);
        let tag = match v.var_type {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
        };
        let start = v.start.map(|s| value(v, s));
        if let Some(s) = start {
            let _ = write!(attrs, r#" start="{s}""#);
        }
        // a derivative names its state by index (value reference + 1)
        if let Some(s) = info
            .continuous_states()
            .iter()
            .find(|s| s.derivative == v.vr)
        {
            let _ = write!(attrs, r#" derivative="{}""#, s.state + 1);
        }
        if let Some(me) = &info.model_exchange {
            if me.states_jump_at_events && me.is_state(v.vr) {
                let _ = write!(attrs, r#" reinit="true""#);
            }
        }
        let _ = writeln!(w, "      <{tag}{attrs}/>");
        let _ = writeln!(w, "    </ScalarVariable>");
    }
    let _ = writeln!(w, "  </ModelVariables>");

    let _ = writeln!(w, "  <ModelStructure>");
    let outputs: Vec<_> = info
        .variables
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output)
        .collect();
    // An unknown with the knowns it depends on: its inputs and states, by
    // index, ascending.
    let unknown = |w: &mut String, i: usize, v: &crate::Variable| {
        let mut deps: Vec<u32> = v
            .depends_on
            .iter()
            .chain(v.depends_on_states)
            .copied()
            .collect();
        deps.sort_unstable();
        deps.dedup();
        let deps: Vec<String> = deps.iter().map(|d| (d + 1).to_string()).collect();
        if deps.is_empty() {
            let _ = writeln!(w, r#"      <Unknown index="{}" dependencies=""/>"#, i + 1);
        } else {
            let kinds = vec!["dependent"; deps.len()].join(" ");
            let _ = writeln!(
                w,
                r#"      <Unknown index="{}" dependencies="{}" dependenciesKind="{kinds}"/>"#,
                i + 1,
                deps.join(" ")
            );
        }
    };
    let _ = writeln!(w, "    <Outputs>");
    for (i, v) in &outputs {
        unknown(w, *i, v);
    }
    let _ = writeln!(w, "    </Outputs>");
    let mut initial_unknowns: Vec<usize> = outputs.iter().map(|(i, _)| *i).collect();
    // (a model without continuous states, only event indicators, has no
    // `<Derivatives>`: the schema wants at least one `<Unknown>` in it)
    let states = info.continuous_states();
    if !states.is_empty() {
        let _ = writeln!(w, "    <Derivatives>");
        for s in states {
            let i = s.derivative as usize;
            unknown(w, i, &info.variables[i]);
            // the derivatives and the states, all `initial="calculated"`
            // (FMI 2.0.4 §2.2.8): a state that is an output is listed as one
            initial_unknowns.push(i);
            initial_unknowns.push(s.state as usize);
        }
        let _ = writeln!(w, "    </Derivatives>");
    }
    initial_unknowns.sort_unstable();
    initial_unknowns.dedup();
    let _ = writeln!(w, "    <InitialUnknowns>");
    for i in initial_unknowns {
        let _ = writeln!(w, r#"      <Unknown index="{}"/>"#, i + 1);
    }
    let _ = writeln!(w, "    </InitialUnknowns>");
    let _ = writeln!(w, "  </ModelStructure>");
    let _ = writeln!(w, "</fmiModelDescription>");
    Ok(x)
}

/// `<UnitDefinitions>` of the units the variables use, each with its SI
/// base-unit exponents (the same element in FMI 2.0 and 3.0).
pub(crate) fn unit_definitions(
    w: &mut String,
    info: &ModelInfo,
    more: &[&'static str],
) -> Result<(), String> {
    let mut used: Vec<&str> = info.variables.iter().filter_map(|v| v.unit).collect();
    used.extend(more);
    used.sort();
    used.dedup();
    if !used.is_empty() {
        let _ = writeln!(w, "  <UnitDefinitions>");
        for unit in used {
            let (_, [kg, m, s, a]) =
                UNITS
                    .iter()
                    .find(|(name, _)| *name == unit)
                    .ok_or_else(|| {
                        format!(
                            "{}: unit {unit} has no base-unit definition",
                            info.model_name
                        )
                    })?;
            let mut base = String::new();
            for (name, e) in [("kg", kg), ("m", m), ("s", s), ("A", a)] {
                if *e != 0 {
                    let _ = write!(base, r#" {name}="{e}""#);
                }
            }
            let _ = writeln!(
                w,
                r#"    <Unit name="{}"><BaseUnit{base}/></Unit>"#,
                escape(unit)
            );
        }
        let _ = writeln!(w, "  </UnitDefinitions>");
    }

    Ok(())
}

/// `<LogCategories>` (the same element in FMI 2.0 and 3.0).
pub(crate) fn log_categories(w: &mut String) {
    let _ = writeln!(w, "  <LogCategories>");
    for (name, description) in LOG_CATEGORIES {
        let _ = writeln!(
            w,
            r#"    <Category name="{name}" description="{}"/>"#,
            escape(description)
        );
    }
    let _ = writeln!(w, "  </LogCategories>");
}

/// `<DefaultExperiment>` (the same element in FMI 2.0 and 3.0).
pub(crate) fn default_experiment(w: &mut String, info: &ModelInfo) {
    let e = &info.default_experiment;
    let _ = writeln!(
        w,
        r#"  <DefaultExperiment startTime="{}" stopTime="{}" stepSize="{}"/>"#,
        number(e.start_time),
        number(e.stop_time),
        number(e.step_size)
    );
}

/// ` unit=… nominal=… min=… max=…` of a variable, those it has (the same
/// attributes in FMI 2.0 and 3.0); bounds in the variable's own type (an
/// Integer's min is "0", not "0.0").
pub(crate) fn value_attributes(v: &Variable) -> String {
    let mut attrs = String::new();
    if let Some(u) = v.unit {
        let _ = write!(attrs, r#" unit="{}""#, escape(u));
    }
    if let Some(n) = v.nominal {
        let _ = write!(attrs, r#" nominal="{}""#, number(n));
    }
    if let Some(m) = v.min {
        let _ = write!(attrs, r#" min="{}""#, value(v, m));
    }
    if let Some(m) = v.max {
        let _ = write!(attrs, r#" max="{}""#, value(v, m));
    }
    attrs
}

/// A value of variable `v` as the XML writes it: a Real's shortest
/// round-trip form, an Integer's digits, a Boolean's `true`/`false`.
pub(crate) fn value(v: &Variable, x: f64) -> String {
    match v.var_type {
        VarType::Real => number(x),
        VarType::Integer => format!("{}", x as i64),
        VarType::Boolean => (x != 0.0).to_string(),
    }
}
