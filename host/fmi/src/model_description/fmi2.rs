//! FMI 2.0's `modelDescription.xml` (FMI 2.0.4 §2.2, §4.3.1 for the
//! `CoSimulation` element), read into the version-neutral types of
//! [`super`]. An FMU that also offers Model Exchange (a `ModelExchange`
//! element, state derivatives with a `derivative` attribute) is read for
//! its Co-Simulation interface, which is the one fricsim uses; the other
//! is only noted ([`ModelDescription::model_exchange`]).
//!
//! The elements inside the root fill `Raw…` structs that mirror the XML;
//! they are then converted into the public types with the checks of
//! §2.2.7 (legal causality/variability/initial values and combinations,
//! unique names, units declared in `UnitDefinitions`, `ModelStructure`
//! indices).

use super::xml::{Document, ElementAt, Root};
use super::{
    check_unit, choice, combination_allowed, default_experiment, index_variables, invalid,
    is_c_identifier, log_category, output_unknown, required, unit_with_declared_type, Causality,
    CoSimulation, DefaultExperiment, Initial, LogCategory, ModelDescription, Variability, Variable,
    VariableKind,
};
use crate::error::FmuError;
use std::collections::HashMap;

/// The rest of an FMI 2.0 document whose root (`fmiVersion` = `version`)
/// has been read: the root's other attributes, the elements inside it,
/// then the checks.
pub(super) fn read(
    document: Document<'_>,
    root: Root<'_>,
    version: String,
) -> Result<ModelDescription, FmuError> {
    let at = &root.at;
    let mut raw = RawModelDescription::default();
    let (mut model_name, mut guid, mut indicators) = (None, None, None);
    for (key, value) in &root.attributes {
        let value = Some(value.clone());
        match key.as_str() {
            "modelName" => model_name = value,
            "guid" => guid = value,
            "description" => raw.description = value,
            "author" => raw.author = value,
            "version" => raw.version = value,
            "generationTool" => raw.generation_tool = value,
            "generationDateAndTime" => raw.generation_date_and_time = value,
            "numberOfEventIndicators" => indicators = value,
            _ => {}
        }
    }
    raw.fmi_version = version;
    raw.model_name = model_name.ok_or_else(|| at.missing("modelName"))?;
    raw.guid = guid.ok_or_else(|| at.missing("guid"))?;
    if let Some(text) = indicators {
        raw.number_of_event_indicators = Some(at.number("numberOfEventIndicators", &text)?);
    }
    document.children(&root, Scope::Root, |scope, e, at| {
        element(&mut raw, scope, e, at)
    })?;
    raw.validate()
}

/// What the children of an open element are read as.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Scope {
    Root,
    UnitDefinitions,
    TypeDefinitions,
    /// Inside a `SimpleType`: its `Real`, `Integer`, … element.
    SimpleType,
    LogCategories,
    ModelVariables,
    ScalarVariable,
    ModelStructure,
    Outputs,
    /// An element fricsim does not read (annotations,
    /// `BaseUnit`, …) or one without children of interest: what is inside
    /// is only checked for well-formedness.
    Skip,
}

/// Read the element at `at` whose parent's children are read as `scope`
/// into `raw`; returns what its own children are read as.
fn element(
    raw: &mut RawModelDescription,
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
            once(raw.unit_definitions.is_some())?;
            raw.unit_definitions = Some(Vec::new());
            Scope::UnitDefinitions
        }
        (Scope::Root, "TypeDefinitions") => {
            once(raw.types.is_some())?;
            raw.types = Some(HashMap::new());
            Scope::TypeDefinitions
        }
        (Scope::TypeDefinitions, "SimpleType") => {
            let name = required(e, at, "name")?;
            let types = raw.types.as_mut().expect("open");
            if types.insert(name.clone(), None).is_some() {
                return Err(at.error(format!(
                    "a second <SimpleType> named \"{name}\" in <TypeDefinitions>"
                )));
            }
            raw.open_type = Some(name);
            Scope::SimpleType
        }
        (Scope::SimpleType, "Real") => {
            // the unit a Real type gives the variables that declare it
            // (FMI 2.0 §2.2.3)
            let mut unit = None;
            at.attributes(e, |key, value| {
                if key == "unit" {
                    unit = Some(value.into_owned());
                }
                Ok(())
            })?;
            let name = raw.open_type.as_ref().expect("open");
            raw.types.as_mut().expect("open").insert(name.clone(), unit);
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
            once(raw.model_variables.is_some())?;
            raw.model_variables = Some(RawModelVariables::default());
            Scope::ModelVariables
        }
        (Scope::Root, "ModelStructure") => {
            once(raw.model_structure.is_some())?;
            raw.model_structure = Some(RawModelStructure::default());
            Scope::ModelStructure
        }
        (Scope::UnitDefinitions, "Unit") => {
            let unit = required(e, at, "name")?;
            raw.unit_definitions.as_mut().expect("open").push(unit);
            Scope::Skip
        }
        (Scope::LogCategories, "Category") => {
            let category = log_category(e, at)?;
            raw.log_categories.as_mut().expect("open").push(category);
            Scope::Skip
        }
        (Scope::ModelVariables, "ScalarVariable") => {
            let variable = scalar_variable(e, at)?;
            let variables = raw.model_variables.as_mut().expect("open");
            variables.variables.push(variable);
            Scope::ScalarVariable
        }
        (Scope::ScalarVariable, "Real" | "Integer" | "Boolean" | "String" | "Enumeration") => {
            let variables = raw.model_variables.as_mut().expect("open");
            let variable = variables.variables.last_mut().expect("open");
            type_element(e, at, variable)?;
            Scope::Skip
        }
        (Scope::ModelStructure, "Outputs") => {
            let structure = raw.model_structure.as_mut().expect("open");
            if structure.outputs.is_some() {
                return Err(at.error("a second <Outputs> in <ModelStructure>".into()));
            }
            structure.outputs = Some(RawUnknowns::default());
            Scope::Outputs
        }
        (Scope::Outputs, "Unknown") => {
            let mut index = None;
            let mut dependencies = None;
            at.attributes(e, |key, value| {
                match key {
                    "index" => index = Some(at.number(key, &value)?),
                    "dependencies" => dependencies = Some(value.into_owned()),
                    _ => {}
                }
                Ok(())
            })?;
            let index = index.ok_or_else(|| at.missing("index"))?;
            let structure = raw.model_structure.as_mut().expect("open");
            let outputs = structure.outputs.as_mut().expect("open");
            outputs.unknowns.push(RawUnknown {
                index,
                dependencies,
            });
            Scope::Skip
        }
        _ => Scope::Skip,
    })
}

/// The `CoSimulation` element (FMI 2.0 §4.3.1).
fn co_simulation(
    e: &quick_xml::events::BytesStart<'_>,
    at: &ElementAt<'_>,
) -> Result<RawCoSimulation, FmuError> {
    let mut cs = RawCoSimulation::default();
    let mut identified = false;
    at.attributes(e, |key, value| {
        let flag = match key {
            "modelIdentifier" => {
                cs.model_identifier = value.into_owned();
                identified = true;
                return Ok(());
            }
            "maxOutputDerivativeOrder" => {
                cs.max_output_derivative_order = Some(at.number(key, &value)?);
                return Ok(());
            }
            "needsExecutionTool" => &mut cs.needs_execution_tool,
            "canHandleVariableCommunicationStepSize" => {
                &mut cs.can_handle_variable_communication_step_size
            }
            "canInterpolateInputs" => &mut cs.can_interpolate_inputs,
            "canRunAsynchronuously" => &mut cs.can_run_asynchronuously,
            "canBeInstantiatedOnlyOncePerProcess" => {
                &mut cs.can_be_instantiated_only_once_per_process
            }
            "canGetAndSetFMUstate" => &mut cs.can_get_and_set_fmu_state,
            "canSerializeFMUstate" => &mut cs.can_serialize_fmu_state,
            "providesDirectionalDerivative" => &mut cs.provides_directional_derivative,
            _ => return Ok(()),
        };
        *flag = Some(at.boolean(key, &value)?);
        Ok(())
    })?;
    if !identified {
        return Err(at.missing("modelIdentifier"));
    }
    Ok(cs)
}

/// The attributes of a `ScalarVariable` (FMI 2.0 §2.2.7); whether they are
/// present and legal is checked by [`RawScalarVariable::validate`], which
/// names the variable.
fn scalar_variable(
    e: &quick_xml::events::BytesStart<'_>,
    at: &ElementAt<'_>,
) -> Result<RawScalarVariable, FmuError> {
    let mut v = RawScalarVariable::default();
    at.attributes(e, |key, value| {
        match key {
            "name" => v.name = Some(value.into_owned()),
            "valueReference" => v.value_reference = Some(at.number(key, &value)?),
            "description" => v.description = Some(value.into_owned()),
            "causality" => v.causality = Some(value.into_owned()),
            "variability" => v.variability = Some(value.into_owned()),
            "initial" => v.initial = Some(value.into_owned()),
            _ => {}
        }
        Ok(())
    })?;
    Ok(v)
}

/// A type element inside a `ScalarVariable` (`Real`, `Integer`, …), into
/// `variable`; more than one is counted and refused by validation.
fn type_element(
    e: &quick_xml::events::BytesStart<'_>,
    at: &ElementAt<'_>,
    variable: &mut RawScalarVariable,
) -> Result<(), FmuError> {
    variable.type_elements += 1;
    match at.name {
        "Real" => {
            let mut r = RawReal::default();
            at.attributes(e, |key, value| {
                let field = match key {
                    "unit" => {
                        r.unit = Some(value.into_owned());
                        return Ok(());
                    }
                    "declaredType" => {
                        r.declared_type = Some(value.into_owned());
                        return Ok(());
                    }
                    "derivative" => {
                        r.derivative = Some(at.number(key, &value)?);
                        return Ok(());
                    }
                    "start" => &mut r.start,
                    "nominal" => &mut r.nominal,
                    "min" => &mut r.min,
                    "max" => &mut r.max,
                    _ => return Ok(()),
                };
                *field = Some(at.number(key, &value)?);
                Ok(())
            })?;
            variable.real = Some(r);
        }
        "Integer" | "Enumeration" => {
            let mut i = RawInteger::default();
            at.attributes(e, |key, value| {
                let field = match key {
                    "declaredType" => {
                        i.declared_type = Some(value.into_owned());
                        return Ok(());
                    }
                    "start" => &mut i.start,
                    "min" => &mut i.min,
                    "max" => &mut i.max,
                    _ => return Ok(()),
                };
                *field = Some(at.number(key, &value)?);
                Ok(())
            })?;
            if at.name == "Integer" {
                variable.integer = Some(i);
            } else {
                variable.enumeration = Some(i);
            }
        }
        "Boolean" => {
            let mut b = RawBoolean::default();
            at.attributes(e, |key, value| {
                if key == "start" {
                    b.start = Some(at.boolean(key, &value)?);
                }
                Ok(())
            })?;
            variable.boolean = Some(b);
        }
        _ => {
            let mut s = RawString::default();
            at.attributes(e, |key, value| {
                if key == "start" {
                    s.start = Some(value.into_owned());
                }
                Ok(())
            })?;
            variable.string = Some(s);
        }
    }
    Ok(())
}

// The XML as it is, before validation: the attributes and child elements
// fricsim reads, filled in by `read`; elements not listed
// here (TypeDefinitions, annotations, …) are skipped.

#[derive(Default)]
struct RawModelDescription {
    fmi_version: String,
    model_name: String,
    guid: String,
    description: Option<String>,
    author: Option<String>,
    version: Option<String>,
    generation_tool: Option<String>,
    generation_date_and_time: Option<String>,
    number_of_event_indicators: Option<u32>,
    /// `ModelExchange`'s `modelIdentifier`.
    model_exchange: Option<String>,
    co_simulation: Option<RawCoSimulation>,
    /// The names of `UnitDefinitions`' units.
    unit_definitions: Option<Vec<String>>,
    /// `TypeDefinitions`: each `SimpleType`'s name and, for a `Real` one,
    /// its unit.
    types: Option<HashMap<String, Option<String>>>,
    /// The `SimpleType` being read.
    open_type: Option<String>,
    log_categories: Option<Vec<LogCategory>>,
    default_experiment: Option<DefaultExperiment>,
    model_variables: Option<RawModelVariables>,
    model_structure: Option<RawModelStructure>,
}

#[derive(Default)]
struct RawCoSimulation {
    model_identifier: String,
    needs_execution_tool: Option<bool>,
    can_handle_variable_communication_step_size: Option<bool>,
    can_interpolate_inputs: Option<bool>,
    max_output_derivative_order: Option<u32>,
    can_run_asynchronuously: Option<bool>,
    can_be_instantiated_only_once_per_process: Option<bool>,
    can_get_and_set_fmu_state: Option<bool>,
    can_serialize_fmu_state: Option<bool>,
    provides_directional_derivative: Option<bool>,
}

#[derive(Default)]
struct RawModelVariables {
    variables: Vec<RawScalarVariable>,
}

#[derive(Default)]
struct RawScalarVariable {
    name: Option<String>,
    value_reference: Option<u32>,
    description: Option<String>,
    causality: Option<String>,
    variability: Option<String>,
    initial: Option<String>,
    real: Option<RawReal>,
    integer: Option<RawInteger>,
    boolean: Option<RawBoolean>,
    string: Option<RawString>,
    enumeration: Option<RawInteger>,
    /// How many type elements (`Real`, `Integer`, …) it has: exactly one
    /// is allowed.
    type_elements: usize,
}

#[derive(Default)]
struct RawReal {
    start: Option<f64>,
    unit: Option<String>,
    declared_type: Option<String>,
    nominal: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
    derivative: Option<usize>,
}

/// `Integer` and `Enumeration` share their attributes.
#[derive(Default)]
struct RawInteger {
    declared_type: Option<String>,
    start: Option<i32>,
    min: Option<i32>,
    max: Option<i32>,
}

#[derive(Default)]
struct RawBoolean {
    start: Option<bool>,
}

#[derive(Default)]
struct RawString {
    start: Option<String>,
}

#[derive(Default)]
struct RawModelStructure {
    outputs: Option<RawUnknowns>,
}

#[derive(Default)]
struct RawUnknowns {
    unknowns: Vec<RawUnknown>,
}

#[derive(Default)]
struct RawUnknown {
    index: usize,
    dependencies: Option<String>,
}

impl RawModelDescription {
    fn validate(self) -> Result<ModelDescription, FmuError> {
        let cs = self.co_simulation.ok_or(FmuError::NotCoSimulation)?;
        if !is_c_identifier(&cs.model_identifier) {
            return Err(invalid(
                "<CoSimulation>",
                format!(
                    "modelIdentifier \"{}\" is not a valid C identifier",
                    cs.model_identifier
                ),
            ));
        }
        let co_simulation = CoSimulation {
            model_identifier: cs.model_identifier,
            needs_execution_tool: cs.needs_execution_tool.unwrap_or(false),
            can_handle_variable_communication_step_size: cs
                .can_handle_variable_communication_step_size
                .unwrap_or(false),
            can_interpolate_inputs: cs.can_interpolate_inputs.unwrap_or(false),
            max_output_derivative_order: cs.max_output_derivative_order.unwrap_or(0),
            can_run_asynchronuously: cs.can_run_asynchronuously.unwrap_or(false),
            can_be_instantiated_only_once_per_process: cs
                .can_be_instantiated_only_once_per_process
                .unwrap_or(false),
            can_get_and_set_fmu_state: cs.can_get_and_set_fmu_state.unwrap_or(false),
            can_serialize_fmu_state: cs.can_serialize_fmu_state.unwrap_or(false),
            provides_directional_derivative: cs.provides_directional_derivative.unwrap_or(false),
        };
        if co_simulation.can_serialize_fmu_state && !co_simulation.can_get_and_set_fmu_state {
            return Err(invalid(
                "<CoSimulation>",
                "canSerializeFMUstate=\"true\" requires canGetAndSetFMUstate=\"true\"",
            ));
        }

        let unit_definitions = self.unit_definitions;
        let raw_variables = self
            .model_variables
            .ok_or_else(|| {
                invalid(
                    "<fmiModelDescription>",
                    "the <ModelVariables> element is missing",
                )
            })?
            .variables;

        let variables = raw_variables
            .into_iter()
            .enumerate()
            .map(|(i, raw)| raw.validate(i + 1, unit_definitions.as_deref(), self.types.as_ref()))
            .collect::<Result<Vec<_>, _>>()?;
        let (variables, by_name) = index_variables(variables)?;

        let mut outputs = Vec::new();
        for (i, raw) in self
            .model_structure
            .and_then(|s| s.outputs)
            .map(|o| o.unknowns)
            .unwrap_or_default()
            .into_iter()
            .enumerate()
        {
            let location = format!(
                "ModelStructure/Outputs/Unknown[{}] (index {})",
                i + 1,
                raw.index
            );
            let dependencies = match raw.dependencies {
                None => None,
                Some(text) => Some(
                    text.split_whitespace()
                        .map(|word| {
                            word.parse::<usize>()
                                .ok()
                                .filter(|&d| d >= 1 && d <= variables.len())
                                .ok_or_else(|| {
                                    invalid(
                                        &location,
                                        format!(
                                            "dependency \"{word}\" is not an index of ModelVariables"
                                        ),
                                    )
                                })
                        })
                        .collect::<Result<Vec<_>, _>>()?,
                ),
            };
            outputs.push(output_unknown(
                &location,
                raw.index,
                dependencies,
                &variables,
            )?);
        }

        Ok(ModelDescription {
            fmi_version: self.fmi_version,
            model_name: self.model_name,
            guid: self.guid,
            description: self.description,
            author: self.author,
            version: self.version,
            generation_tool: self.generation_tool,
            generation_date_and_time: self.generation_date_and_time,
            co_simulation,
            model_exchange: self.model_exchange,
            number_of_event_indicators: self.number_of_event_indicators.unwrap_or(0),
            unit_definitions,
            log_categories: self.log_categories.unwrap_or_default(),
            default_experiment: self.default_experiment,
            variables,
            outputs,
            arrays: Vec::new(),
            by_name,
        })
    }
}

impl RawScalarVariable {
    fn validate(
        self,
        index: usize,
        units: Option<&[String]>,
        types: Option<&HashMap<String, Option<String>>>,
    ) -> Result<Variable, FmuError> {
        let name = match self.name {
            Some(n) if !n.is_empty() => n,
            _ => {
                return Err(invalid(
                    format!("variable at index {index}"),
                    "the name attribute is missing or empty",
                ))
            }
        };
        let location = format!("variable \"{name}\" (index {index})");
        let value_reference = self
            .value_reference
            .ok_or_else(|| invalid(&location, "the valueReference attribute is missing"))?;
        let causality = choice(
            self.causality.as_deref(),
            Causality::Local,
            &location,
            "causality",
        )?;
        let variability = choice(
            self.variability.as_deref(),
            Variability::Continuous,
            &location,
            "variability",
        )?;
        let initial = match self.initial.as_deref() {
            None => None,
            text => Some(choice(text, Initial::Exact, &location, "initial")?),
        };
        if !combination_allowed(causality, variability) {
            return Err(invalid(
                &location,
                format!("causality \"{causality}\" with variability \"{variability}\" is not allowed (FMI 2.0 §2.2.7)"),
            ));
        }

        let mut kinds = Vec::with_capacity(1);
        if let Some(r) = self.real {
            let unit = unit_with_declared_type(
                r.unit,
                r.declared_type.as_deref(),
                types,
                "<SimpleType>",
                &location,
            )?;
            check_unit(unit.as_deref(), units, &location)?;
            kinds.push(VariableKind::Real {
                start: r.start,
                unit,
                nominal: r.nominal,
                min: r.min,
                max: r.max,
                derivative: r.derivative,
            });
        }
        // an Integer's or Enumeration's declared type must exist too
        // (their units are not read: fricsim checks units of Reals only)
        for declared in [&self.integer, &self.enumeration]
            .into_iter()
            .flatten()
            .filter_map(|i| i.declared_type.as_deref())
        {
            unit_with_declared_type(None, Some(declared), types, "<SimpleType>", &location)?;
        }
        if let Some(i) = self.integer {
            kinds.push(VariableKind::Integer {
                start: i.start,
                min: i.min,
                max: i.max,
            });
        }
        if let Some(b) = self.boolean {
            kinds.push(VariableKind::Boolean { start: b.start });
        }
        if let Some(s) = self.string {
            kinds.push(VariableKind::String { start: s.start });
        }
        if let Some(e) = self.enumeration {
            let declared_type = e.declared_type.ok_or_else(|| {
                invalid(&location, "an <Enumeration> needs a declaredType attribute")
            })?;
            kinds.push(VariableKind::Enumeration {
                declared_type,
                start: e.start,
                min: e.min,
                max: e.max,
            });
        }
        if self.type_elements != 1 {
            return Err(invalid(
                &location,
                format!("expected exactly one of <Real>, <Integer>, <Boolean>, <String>, <Enumeration>, found {}", self.type_elements),
            ));
        }
        let kind = kinds.pop().expect("one element");
        Ok(Variable {
            name,
            index,
            value_reference,
            description: self.description,
            causality,
            variability,
            initial,
            kind,
            fmi3_type: None,
            element: None,
        })
    }
}
