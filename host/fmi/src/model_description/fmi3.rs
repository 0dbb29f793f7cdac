//! FMI 3.0's `modelDescription.xml` (FMI 3.0.1 §2.4; §4.3.1 for the
//! `CoSimulation` element), read into the version-neutral types of
//! [`super`], as far as they reach: scalar variables of the types that
//! have an FMI 2.0 counterpart (`Float64` as `Real`, `Int32` as
//! `Integer`, `Boolean`, `String`, `Enumeration`), the Co-Simulation
//! capabilities, units, log categories, the default experiment and the
//! outputs of `ModelStructure`. What has no counterpart yet is refused by
//! name rather than read wrongly: an array (a `<Dimension>`), a structural
//! parameter, and the types `Float32`, `Int8`…`UInt64` but `Int32`,
//! `Binary` and `Clock`.
//!
//! Where FMI 3.0 differs from FMI 2.0 in what is read here:
//! - the root's `instantiationToken` is FMI 2.0's `guid`;
//! - a variable is an element named by its type, with the type's
//!   attributes on it (no `ScalarVariable` wrapper); a `String`'s start is
//!   a `<Start value="…"/>` child;
//! - `variability` defaults to `continuous` for a float and `discrete`
//!   otherwise (only floats may be continuous);
//! - `derivative`, and `ModelStructure`'s `<Output valueReference="…"
//!   dependencies="…">`, name value references, not indices;
//! - the `CoSimulation` flags `canGetAndSetFMUState`,
//!   `canSerializeFMUState` and `providesDirectionalDerivatives` are
//!   spelled so; `canInterpolateInputs` and `canRunAsynchronuously` are
//!   gone (read as false);
//! - event indicators are `<EventIndicator>` elements of `ModelStructure`.

use super::xml::{Document, ElementAt, Root};
use super::{
    check_unit, choice, combination_allowed, default_experiment, index_variables, invalid,
    is_c_identifier, log_category, output_unknown, required, unit_with_declared_type, Causality,
    CoSimulation, Initial, ModelDescription, ValueReference, Variability, Variable, VariableKind,
};
use crate::error::FmuError;
use std::collections::HashMap;

/// The types of FMI 3.0 variables, and whether they are read.
const READ_TYPES: &[&str] = &["Float64", "Int32", "Boolean", "String", "Enumeration"];
const OTHER_TYPES: &[&str] = &[
    "Float32", "Int8", "UInt8", "Int16", "UInt16", "UInt32", "Int64", "UInt64", "Binary", "Clock",
];

/// The rest of an FMI 3.0 document whose root (`fmiVersion` = `version`)
/// has been read.
pub(super) fn read(
    document: Document<'_>,
    root: Root<'_>,
    version: String,
) -> Result<ModelDescription, FmuError> {
    let at = &root.at;
    let mut raw = Raw::default();
    let text = |key: &str| root.attribute(key).map(str::to_string);
    let model_name = text("modelName").ok_or_else(|| at.missing("modelName"))?;
    let token = text("instantiationToken").ok_or_else(|| at.missing("instantiationToken"))?;
    document.children(&root, Scope::Root, |scope, e, at| {
        element(&mut raw, scope, e, at)
    })?;
    let header = Header {
        fmi_version: version,
        model_name,
        token,
        description: text("description"),
        author: text("author"),
        version: text("version"),
        generation_tool: text("generationTool"),
        generation_date_and_time: text("generationDateAndTime"),
    };
    raw.validate(header)
}

/// The root's attributes.
struct Header {
    fmi_version: String,
    model_name: String,
    token: String,
    description: Option<String>,
    author: Option<String>,
    version: Option<String>,
    generation_tool: Option<String>,
    generation_date_and_time: Option<String>,
}

/// What the children of an open element are read as.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Scope {
    Root,
    UnitDefinitions,
    TypeDefinitions,
    LogCategories,
    ModelVariables,
    /// Inside a variable element: its `<Dimension>`, `<Start>`, `<Alias>`.
    Variable,
    ModelStructure,
    Skip,
}

fn element(
    raw: &mut Raw,
    scope: Scope,
    e: &quick_xml::events::BytesStart<'_>,
    at: &ElementAt<'_>,
) -> Result<Scope, FmuError> {
    let name = at.name;
    let once = |seen: bool| {
        if seen {
            Err(at.error(format!(
                "a second <{name}> in <fmiModelDescription>, which allows one"
            )))
        } else {
            Ok(())
        }
    };
    Ok(match (scope, name) {
        (Scope::Root, "ModelExchange") => {
            once(raw.model_exchange.is_some())?;
            raw.model_exchange = Some(required(e, at, "modelIdentifier")?);
            Scope::Skip
        }
        (Scope::Root, "CoSimulation") => {
            once(raw.co_simulation.is_some())?;
            raw.co_simulation = Some(co_simulation(e, at)?);
            Scope::Skip
        }
        (Scope::Root, "UnitDefinitions") => {
            once(raw.units.is_some())?;
            raw.units = Some(Vec::new());
            Scope::UnitDefinitions
        }
        (Scope::Root, "TypeDefinitions") => {
            once(raw.types.is_some())?;
            raw.types = Some(HashMap::new());
            Scope::TypeDefinitions
        }
        (Scope::TypeDefinitions, type_name) => {
            // a type's name, and the unit a Float type gives the variables
            // that declare it (FMI 3.0 §2.4.4)
            let name = required(e, at, "name")?;
            let mut unit = None;
            if type_name.starts_with("Float") {
                at.attributes(e, |key, value| {
                    if key == "unit" {
                        unit = Some(value.into_owned());
                    }
                    Ok(())
                })?;
            }
            let types = raw.types.as_mut().expect("open");
            if types.insert(name.clone(), unit).is_some() {
                return Err(at.error(format!(
                    "a second type named \"{name}\" in <TypeDefinitions>"
                )));
            }
            Scope::Skip
        }
        (Scope::Root, "LogCategories") => {
            once(raw.log_categories.is_some())?;
            raw.log_categories = Some(Vec::new());
            Scope::LogCategories
        }
        (Scope::Root, "DefaultExperiment") => {
            once(raw.default_experiment.is_some())?;
            raw.default_experiment = Some(default_experiment(e, at)?);
            Scope::Skip
        }
        (Scope::Root, "ModelVariables") => {
            once(raw.variables.is_some())?;
            raw.variables = Some(Vec::new());
            Scope::ModelVariables
        }
        (Scope::Root, "ModelStructure") => {
            once(raw.structure_seen)?;
            raw.structure_seen = true;
            Scope::ModelStructure
        }
        (Scope::UnitDefinitions, "Unit") => {
            let unit = required(e, at, "name")?;
            raw.units.as_mut().expect("open").push(unit);
            Scope::Skip
        }
        (Scope::LogCategories, "Category") => {
            let category = log_category(e, at)?;
            raw.log_categories.as_mut().expect("open").push(category);
            Scope::Skip
        }
        (Scope::ModelVariables, type_name) => {
            let variable = variable(e, at, type_name)?;
            raw.variables.as_mut().expect("open").push(variable);
            Scope::Variable
        }
        (Scope::Variable, "Dimension") => {
            last_variable(raw).dimensions += 1;
            Scope::Skip
        }
        (Scope::Variable, "Start") => {
            let start = required(e, at, "value")?;
            last_variable(raw).start_elements.push(start);
            Scope::Skip
        }
        (Scope::ModelStructure, "Output" | "ContinuousStateDerivative" | "InitialUnknown") => {
            let mut vr = None;
            let mut dependencies = None;
            at.attributes(e, |key, value| {
                match key {
                    "valueReference" => vr = Some(at.number(key, &value)?),
                    "dependencies" => dependencies = Some(value.into_owned()),
                    _ => {}
                }
                Ok(())
            })?;
            let vr = vr.ok_or_else(|| at.missing("valueReference"))?;
            if name == "Output" {
                raw.outputs.push((vr, dependencies));
            }
            Scope::Skip
        }
        (Scope::ModelStructure, "EventIndicator") => {
            raw.event_indicators += 1;
            Scope::Skip
        }
        _ => Scope::Skip,
    })
}

fn last_variable(raw: &mut Raw) -> &mut RawVariable {
    let variables = raw.variables.as_mut().expect("open");
    variables.last_mut().expect("open")
}

/// The `CoSimulation` element (FMI 3.0 §4.3.1): the capabilities
/// [`CoSimulation`] carries.
fn co_simulation(
    e: &quick_xml::events::BytesStart<'_>,
    at: &ElementAt<'_>,
) -> Result<CoSimulation, FmuError> {
    let mut cs = CoSimulation {
        model_identifier: String::new(),
        needs_execution_tool: false,
        can_handle_variable_communication_step_size: false,
        can_interpolate_inputs: false,
        max_output_derivative_order: 0,
        can_run_asynchronuously: false,
        can_be_instantiated_only_once_per_process: false,
        can_get_and_set_fmu_state: false,
        can_serialize_fmu_state: false,
        provides_directional_derivative: false,
    };
    let mut identified = false;
    at.attributes(e, |key, value| {
        let flag = match key {
            "modelIdentifier" => {
                cs.model_identifier = value.into_owned();
                identified = true;
                return Ok(());
            }
            "maxOutputDerivativeOrder" => {
                cs.max_output_derivative_order = at.number(key, &value)?;
                return Ok(());
            }
            "needsExecutionTool" => &mut cs.needs_execution_tool,
            "canHandleVariableCommunicationStepSize" => {
                &mut cs.can_handle_variable_communication_step_size
            }
            "canBeInstantiatedOnlyOncePerProcess" => {
                &mut cs.can_be_instantiated_only_once_per_process
            }
            "canGetAndSetFMUState" => &mut cs.can_get_and_set_fmu_state,
            "canSerializeFMUState" => &mut cs.can_serialize_fmu_state,
            "providesDirectionalDerivatives" => &mut cs.provides_directional_derivative,
            _ => return Ok(()),
        };
        *flag = at.boolean(key, &value)?;
        Ok(())
    })?;
    if !identified {
        return Err(at.missing("modelIdentifier"));
    }
    Ok(cs)
}

/// A variable element named `type_name` (FMI 3.0 §2.4.7): its attributes,
/// kept as text until [`RawVariable::validate`] knows its name.
fn variable(
    e: &quick_xml::events::BytesStart<'_>,
    at: &ElementAt<'_>,
    type_name: &str,
) -> Result<RawVariable, FmuError> {
    let mut v = RawVariable {
        type_name: type_name.to_string(),
        ..RawVariable::default()
    };
    at.attributes(e, |key, value| {
        let text = Some(value.clone().into_owned());
        match key {
            "name" => v.name = text,
            "valueReference" => v.value_reference = Some(at.number(key, &value)?),
            "description" => v.description = text,
            "causality" => v.causality = text,
            "variability" => v.variability = text,
            "initial" => v.initial = text,
            "start" => v.start = text,
            "unit" => v.unit = text,
            "declaredType" => v.declared_type = text,
            "nominal" => v.nominal = Some(at.number(key, &value)?),
            "min" => v.min = text,
            "max" => v.max = text,
            "derivative" => v.derivative = Some(at.number(key, &value)?),
            _ => {}
        }
        Ok(())
    })?;
    Ok(v)
}

// The XML as it is, before validation.

#[derive(Default)]
struct Raw {
    model_exchange: Option<String>,
    co_simulation: Option<CoSimulation>,
    units: Option<Vec<String>>,
    /// `TypeDefinitions`: each type's name and, for a Float type, its unit.
    types: Option<HashMap<String, Option<String>>>,
    log_categories: Option<Vec<super::LogCategory>>,
    default_experiment: Option<super::DefaultExperiment>,
    variables: Option<Vec<RawVariable>>,
    structure_seen: bool,
    /// `<Output>`s: value reference and `dependencies` as written.
    outputs: Vec<(ValueReference, Option<String>)>,
    event_indicators: u32,
}

#[derive(Default)]
struct RawVariable {
    type_name: String,
    name: Option<String>,
    value_reference: Option<ValueReference>,
    description: Option<String>,
    causality: Option<String>,
    variability: Option<String>,
    initial: Option<String>,
    start: Option<String>,
    unit: Option<String>,
    declared_type: Option<String>,
    nominal: Option<f64>,
    min: Option<String>,
    max: Option<String>,
    /// `derivative`: the value reference of the state this is the
    /// derivative of.
    derivative: Option<ValueReference>,
    /// `<Dimension>` children: an array when there is one.
    dimensions: usize,
    /// `<Start value="…"/>` children (`String`, `Binary`).
    start_elements: Vec<String>,
}

impl Raw {
    fn validate(self, header: Header) -> Result<ModelDescription, FmuError> {
        let co_simulation = self.co_simulation.ok_or(FmuError::NotCoSimulation)?;
        if !is_c_identifier(&co_simulation.model_identifier) {
            return Err(invalid(
                "<CoSimulation>",
                format!(
                    "modelIdentifier \"{}\" is not a valid C identifier",
                    co_simulation.model_identifier
                ),
            ));
        }
        if co_simulation.can_serialize_fmu_state && !co_simulation.can_get_and_set_fmu_state {
            return Err(invalid(
                "<CoSimulation>",
                "canSerializeFMUState=\"true\" requires canGetAndSetFMUState=\"true\"",
            ));
        }
        let raw_variables = self.variables.ok_or_else(|| {
            invalid(
                "<fmiModelDescription>",
                "the <ModelVariables> element is missing",
            )
        })?;
        // value reference → 1-based index, for derivative and ModelStructure
        let mut by_vr = HashMap::with_capacity(raw_variables.len());
        for (i, v) in raw_variables.iter().enumerate() {
            if let Some(vr) = v.value_reference {
                if let Some(first) = by_vr.insert(vr, i + 1) {
                    return Err(invalid(
                        format!("variable at index {}", i + 1),
                        format!(
                            "valueReference {vr} is already the variable at index {first} \
                             (FMI 3.0 value references are unique)"
                        ),
                    ));
                }
            }
        }
        let variables = raw_variables
            .into_iter()
            .enumerate()
            .map(|(i, raw)| raw.validate(i + 1, self.units.as_deref(), self.types.as_ref(), &by_vr))
            .collect::<Result<Vec<_>, _>>()?;
        let (variables, by_name) = index_variables(variables)?;

        let mut outputs = Vec::with_capacity(self.outputs.len());
        for (i, (vr, dependencies)) in self.outputs.into_iter().enumerate() {
            let location = format!("ModelStructure/Output[{}] (valueReference {vr})", i + 1);
            let index = |vr: ValueReference, what: &str| {
                by_vr.get(&vr).copied().ok_or_else(|| {
                    invalid(
                        &location,
                        format!("{what} {vr} is not the value reference of a variable"),
                    )
                })
            };
            let own = index(vr, "valueReference")?;
            let dependencies = match dependencies {
                None => None,
                Some(text) => Some(
                    text.split_whitespace()
                        .map(|word| {
                            let vr = word.parse().map_err(|_| {
                                invalid(
                                    &location,
                                    format!("dependency \"{word}\" is not a value reference"),
                                )
                            })?;
                            index(vr, "dependency")
                        })
                        .collect::<Result<Vec<_>, _>>()?,
                ),
            };
            outputs.push(output_unknown(&location, own, dependencies, &variables)?);
        }

        Ok(ModelDescription {
            fmi_version: header.fmi_version,
            model_name: header.model_name,
            guid: header.token,
            description: header.description,
            author: header.author,
            version: header.version,
            generation_tool: header.generation_tool,
            generation_date_and_time: header.generation_date_and_time,
            co_simulation,
            model_exchange: self.model_exchange,
            number_of_event_indicators: self.event_indicators,
            unit_definitions: self.units,
            log_categories: self.log_categories.unwrap_or_default(),
            default_experiment: self.default_experiment,
            variables,
            outputs,
            by_name,
        })
    }
}

impl RawVariable {
    fn validate(
        self,
        index: usize,
        units: Option<&[String]>,
        types: Option<&HashMap<String, Option<String>>>,
        by_vr: &HashMap<ValueReference, usize>,
    ) -> Result<Variable, FmuError> {
        let type_name = self.type_name.as_str();
        let name = match self.name {
            Some(n) if !n.is_empty() => n,
            _ => {
                return Err(invalid(
                    format!("<{type_name}> at index {index}"),
                    "the name attribute is missing or empty",
                ))
            }
        };
        let location = format!("variable \"{name}\" (index {index})");
        if OTHER_TYPES.contains(&type_name) {
            return Err(invalid(
                &location,
                format!(
                    "its type <{type_name}> is not read yet (fricsim reads FMI 3.0's {})",
                    READ_TYPES.join(", ")
                ),
            ));
        }
        if !READ_TYPES.contains(&type_name) {
            return Err(invalid(
                &location,
                format!("<{type_name}> is not a variable type of FMI 3.0"),
            ));
        }
        if self.dimensions > 0 {
            return Err(invalid(
                &location,
                "it is an array (<Dimension>); FMI 3.0 arrays are not read yet",
            ));
        }
        let value_reference = self
            .value_reference
            .ok_or_else(|| invalid(&location, "the valueReference attribute is missing"))?;
        if self.causality.as_deref() == Some("structuralParameter") {
            return Err(invalid(
                &location,
                "structural parameters (the sizes of arrays) are not read yet",
            ));
        }
        let causality = choice(
            self.causality.as_deref(),
            Causality::Local,
            &location,
            "causality",
        )?;
        let float = type_name == "Float64";
        let default_variability = if float {
            Variability::Continuous
        } else {
            Variability::Discrete
        };
        let variability = choice(
            self.variability.as_deref(),
            default_variability,
            &location,
            "variability",
        )?;
        if variability == Variability::Continuous && !float {
            return Err(invalid(
                &location,
                format!("a <{type_name}> cannot be continuous (FMI 3.0 §2.4.7.4)"),
            ));
        }
        let initial = match self.initial.as_deref() {
            None => None,
            text => Some(choice(text, Initial::Exact, &location, "initial")?),
        };
        if !combination_allowed(causality, variability) {
            return Err(invalid(
                &location,
                format!(
                    "causality \"{causality}\" with variability \"{variability}\" is not allowed (FMI 3.0 §2.4.7.4)"
                ),
            ));
        }
        let number = |what: &str, text: &Option<String>| -> Result<Option<f64>, FmuError> {
            text.as_deref()
                .map(|t| {
                    t.trim()
                        .parse::<f64>()
                        .map_err(|_| invalid(&location, format!("{what}=\"{t}\" is not a number")))
                })
                .transpose()
        };
        let integer = |what: &str, text: &Option<String>| -> Result<Option<i32>, FmuError> {
            text.as_deref()
                .map(|t| {
                    t.trim().parse::<i32>().map_err(|_| {
                        invalid(&location, format!("{what}=\"{t}\" is not a 32-bit integer"))
                    })
                })
                .transpose()
        };
        // (every declared type must exist, FMI 3.0 §2.4.7)
        let unit = unit_with_declared_type(
            self.unit,
            self.declared_type.as_deref(),
            types,
            "type",
            &location,
        )?;
        let kind = match type_name {
            "Float64" => {
                check_unit(unit.as_deref(), units, &location)?;
                let derivative = match self.derivative {
                    None => None,
                    Some(vr) => Some(by_vr.get(&vr).copied().ok_or_else(|| {
                        invalid(
                            &location,
                            format!("derivative=\"{vr}\" is not the value reference of a variable"),
                        )
                    })?),
                };
                VariableKind::Real {
                    start: number("start", &self.start)?,
                    unit,
                    nominal: self.nominal,
                    min: number("min", &self.min)?,
                    max: number("max", &self.max)?,
                    derivative,
                }
            }
            "Int32" => VariableKind::Integer {
                start: integer("start", &self.start)?,
                min: integer("min", &self.min)?,
                max: integer("max", &self.max)?,
            },
            "Boolean" => VariableKind::Boolean {
                start: match self.start.as_deref().map(str::trim) {
                    None => None,
                    Some("true" | "1") => Some(true),
                    Some("false" | "0") => Some(false),
                    Some(t) => {
                        return Err(invalid(
                            &location,
                            format!("start=\"{t}\" is not a boolean"),
                        ))
                    }
                },
            },
            "String" => VariableKind::String {
                start: self.start_elements.into_iter().next(),
            },
            _ => VariableKind::Enumeration {
                declared_type: self.declared_type.ok_or_else(|| {
                    invalid(&location, "an <Enumeration> needs a declaredType attribute")
                })?,
                start: integer("start", &self.start)?,
                min: integer("min", &self.min)?,
                max: integer("max", &self.max)?,
            },
        };
        Ok(Variable {
            name,
            index,
            value_reference,
            description: self.description,
            causality,
            variability,
            initial,
            kind,
        })
    }
}
