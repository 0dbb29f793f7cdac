//! The FMI 3.0 `modelDescription.xml` rendered from the same [`ModelInfo`]
//! as the FMI 2.0 one ([`crate::model_description`]): the variable table
//! stays the only place a variable is written down. What FMI 3.0 writes
//! differently (FMI 3.0 section 2.4):
//!
//! - a variable is an element of its type (`<Float64>`, `<Int32>`,
//!   `<Boolean>`), not a `<ScalarVariable>`;
//! - the independent variable `time` is declared, and the event indicators
//!   of Model Exchange are variables, with value references after the
//!   table's ([`super::time_vr`], [`super::event_indicator_vr`]);
//! - the table's numbered scalars `x[1]` … `x[n]` are one array `x` with a
//!   `<Dimension>` ([`super::arrays`]);
//! - the model structure names value references, not indices, and a
//!   derivative names its state by value reference;
//! - `instantiationToken` for `guid`, and the capability flags' FMI 3.0
//!   names.

use super::arrays::{Fmi3Variable, Layout};
use super::{event_indicator_vr, time_vr};
use crate::model_description::{
    causality, default_experiment, escape, log_categories, unit_definitions, value,
    value_attributes, variability,
};
use crate::variables::{Causality, Initial, ModelInfo, VarType};
use std::fmt::Write;

/// The FMI 3.0 element of a variable type.
pub fn type_name(t: VarType) -> &'static str {
    match t {
        VarType::Real => "Float64",
        VarType::Integer => "Int32",
        VarType::Boolean => "Boolean",
    }
}

/// The name of event indicator `k` (0-based) as an FMI 3.0 variable.
pub fn event_indicator_name(k: u32) -> String {
    format!("eventIndicator[{}]", k + 1)
}

/// Render the FMI 3.0 model description. `generation_tool` names the crate
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
        r#"<fmiModelDescription fmiVersion="3.0" modelName="{}" instantiationToken="{}" description="{}" author="friction-fmu project" generationTool="{}" variableNamingConvention="structured">"#,
        escape(info.model_name),
        escape(info.guid),
        escape(&format!("{} Source: {}", info.description, info.source)),
        escape(generation_tool),
    );
    if info.model_exchange.is_some() {
        // one binary and model identifier for both interfaces; no step
        // events, so fmi3CompletedIntegratorStep need not be called
        let _ = writeln!(
            w,
            r#"  <ModelExchange modelIdentifier="{}" needsExecutionTool="false" canBeInstantiatedOnlyOncePerProcess="false" canGetAndSetFMUState="{}" canSerializeFMUState="{}" providesDirectionalDerivatives="{}" providesAdjointDerivatives="{}" providesPerElementDependencies="false" needsCompletedIntegratorStep="false" providesEvaluateDiscreteStates="false"/>"#,
            escape(info.model_identifier),
            caps.can_get_and_set_state,
            caps.can_serialize_state,
            caps.provides_directional_derivative,
            caps.provides_directional_derivative,
        );
    }
    // a law with a stick/slip indicator (an Integer or Boolean output)
    // reports its switches inside a step and can end the step at one
    let switches = info
        .variables
        .iter()
        .any(|v| v.causality == Causality::Output && v.var_type != VarType::Real);
    let _ = writeln!(
        w,
        r#"  <CoSimulation modelIdentifier="{}" needsExecutionTool="false" canBeInstantiatedOnlyOncePerProcess="false" canGetAndSetFMUState="{}" canSerializeFMUState="{}" providesDirectionalDerivatives="{}" providesAdjointDerivatives="{}" providesPerElementDependencies="false" canHandleVariableCommunicationStepSize="{}" maxOutputDerivativeOrder="{}" providesIntermediateUpdate="{switches}" mightReturnEarlyFromDoStep="{switches}" canReturnEarlyAfterIntermediateUpdate="{switches}" hasEventMode="false" providesEvaluateDiscreteStates="false"/>"#,
        escape(info.model_identifier),
        caps.can_get_and_set_state,
        caps.can_serialize_state,
        caps.provides_directional_derivative,
        caps.provides_directional_derivative,
        caps.can_handle_variable_step,
        caps.max_output_derivative_order,
    );
    // (with the unit of `time`)
    unit_definitions(w, info, &["s"])?;
    log_categories(w);
    default_experiment(w, info);

    let _ = writeln!(w, "  <ModelVariables>");
    let _ = writeln!(
        w,
        r#"    <Float64 name="time" valueReference="{}" causality="independent" variability="continuous" description="Simulation time" unit="s"/>"#,
        time_vr(info)
    );
    let layout = Layout::new(info);
    for v in &layout.variables {
        let _ = writeln!(w, "    {}", variable(info, &layout, v));
    }
    let ni = info.model_exchange.map_or(0, |me| me.event_indicators);
    for k in 0..ni {
        let _ = writeln!(
            w,
            r#"    <Float64 name="{}" valueReference="{}" causality="local" variability="continuous" initial="calculated" description="Event indicator {} of Model Exchange: changes sign where the law switches"/>"#,
            event_indicator_name(k as u32),
            event_indicator_vr(info, k),
            k + 1
        );
    }
    let _ = writeln!(w, "  </ModelVariables>");

    let _ = writeln!(w, "  <ModelStructure>");
    let mut initial_unknowns: Vec<u32> = Vec::new();
    for v in &layout.variables {
        let first = &info.variables[v.vr as usize];
        if first.causality == Causality::Output {
            let _ = writeln!(w, "    {}", unknown("Output", &layout, v, info));
            initial_unknowns.push(v.vr);
        }
    }
    let states = info.continuous_states();
    if !states.is_empty() {
        // one element per derivative variable (an array of derivatives
        // is one: FMI 3.0 counts the states by its elements)
        for v in &layout.variables {
            if info.is_derivative(v.vr) {
                let _ = writeln!(
                    w,
                    "    {}",
                    unknown("ContinuousStateDerivative", &layout, v, info)
                );
            }
        }
        for s in states {
            // the derivatives and the states, all `initial="calculated"`
            // (FMI 3.0 section 2.4.8): a state that is an output is listed
            // once
            initial_unknowns.push(layout.head_of(s.derivative));
            initial_unknowns.push(layout.head_of(s.state));
        }
    }
    initial_unknowns.sort_unstable();
    initial_unknowns.dedup();
    for vr in initial_unknowns {
        let _ = writeln!(w, r#"    <InitialUnknown valueReference="{vr}"/>"#);
    }
    for k in 0..ni {
        let _ = writeln!(
            w,
            r#"    <EventIndicator valueReference="{}"/>"#,
            event_indicator_vr(info, k)
        );
    }
    let _ = writeln!(w, "  </ModelStructure>");
    let _ = writeln!(w, "</fmiModelDescription>");
    Ok(x)
}

/// One FMI 3.0 variable as its element: a scalar of the table, or an
/// array of its numbered scalars with their start values in order and a
/// `<Dimension>`.
fn variable(info: &ModelInfo, layout: &Layout, fmi3: &Fmi3Variable) -> String {
    let v = &info.variables[fmi3.vr as usize];
    let elements = &info.variables[fmi3.vr as usize..(fmi3.vr + fmi3.len) as usize];
    let initial = match (v.initial(), v.causality) {
        (Some(Initial::Exact), _) => r#" initial="exact""#,
        (Some(Initial::Approx), _) => r#" initial="approx""#,
        (Some(Initial::Calculated), Causality::Output | Causality::Local) => {
            r#" initial="calculated""#
        }
        _ => "",
    };
    let mut e = format!(
        r#"<{} name="{}" valueReference="{}" description="{}" causality="{}" variability="{}"{initial}"#,
        type_name(v.var_type),
        escape(&fmi3.name),
        v.vr,
        escape(v.description),
        causality(v.causality),
        variability(v.variability)
    );
    e.push_str(&value_attributes(v));
    // every element's start, separated by spaces (all or none have one)
    let starts: Option<Vec<String>> = elements
        .iter()
        .map(|e| e.start.map(|x| value(v, x)))
        .collect();
    if let Some(starts) = starts {
        let _ = write!(e, r#" start="{}""#, starts.join(" "));
    }
    // a derivative names its state (array) by value reference
    if let Some(s) = info
        .continuous_states()
        .iter()
        .find(|s| s.derivative == v.vr)
    {
        let _ = write!(e, r#" derivative="{}""#, layout.head_of(s.state));
    }
    if let Some(me) = &info.model_exchange {
        if me.states_jump_at_events && me.is_state(v.vr) {
            let _ = write!(e, r#" reinit="true""#);
        }
    }
    if fmi3.is_array {
        let _ = write!(
            e,
            r#"><Dimension start="{}"/></{}>"#,
            fmi3.len,
            type_name(v.var_type)
        );
    } else {
        e.push_str("/>");
    }
    e
}

/// An element of the model structure with the knowns `v` depends on (any
/// of its elements): their inputs and states, by the value reference of
/// their FMI 3.0 variable, ascending.
fn unknown(element: &str, layout: &Layout, v: &Fmi3Variable, info: &ModelInfo) -> String {
    let elements = &info.variables[v.vr as usize..(v.vr + v.len) as usize];
    let mut deps: Vec<u32> = elements
        .iter()
        .flat_map(|e| e.depends_on.iter().chain(e.depends_on_states))
        .map(|&d| layout.head_of(d))
        .collect();
    deps.sort_unstable();
    deps.dedup();
    if deps.is_empty() {
        return format!(r#"<{element} valueReference="{}" dependencies=""/>"#, v.vr);
    }
    let kinds = vec!["dependent"; deps.len()].join(" ");
    let deps: Vec<String> = deps.iter().map(u32::to_string).collect();
    format!(
        r#"<{element} valueReference="{}" dependencies="{}" dependenciesKind="{kinds}"/>"#,
        v.vr,
        deps.join(" ")
    )
}
