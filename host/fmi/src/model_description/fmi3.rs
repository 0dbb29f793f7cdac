//! FMI 3.0's `modelDescription.xml` (FMI 3.0.1 §2.4; §4.3.1 for the
//! `CoSimulation` element), read into the version-neutral types of
//! [`super`]: the variables of every type but `Binary` and `Clock`, each
//! as the FMI 2.0 kind that holds its values (`Float64` and `Float32` as
//! `Real`, `Int8` … `Int32` as `Integer`, `UInt32`, `Int64` and `UInt64`
//! as `Real`, which holds a 64-bit value only if it is exact in an `f64`:
//! [`Fmi3Type::kind_name`]), with the FMI 3.0 type in
//! [`Variable::fmi3_type`]; the Co-Simulation capabilities, units, log
//! categories, the default experiment and the outputs of
//! `ModelStructure`.
//!
//! Arrays of fixed size (`<Dimension start="…"/>`) are expanded here into
//! one variable per element, named by FMI's structured naming (`k[1]`,
//! `A[2,3]`: 1-based, row-major; the elements of `der(x)` are
//! `der(x[1])`, … as FMI 2.0 names them), each with its start value from
//! the array's space-separated `start` list and with a value reference
//! of fricsim's that cannot be one of the FMU's ([`Array`]); what names
//! the array (`derivative`, `ModelStructure`) names each element. The
//! rest of fricsim sees scalars; the instance maps an element back to its
//! array ([`crate::Fmi3Instance`]).
//!
//! Refused by name rather than read wrongly: a structural parameter, an
//! array sized by one (`<Dimension valueReference="…"/>`), an array of
//! `String`, and the types `Binary` and `Clock`.
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

use super::element_count;
use super::xml::{Document, ElementAt, Root};
use super::{
    check_unit, choice, combination_allowed, default_experiment, index_variables, invalid,
    is_c_identifier, list, log_category, output_unknown, required, unit_with_declared_type, Array,
    ArrayElement, Causality, CoSimulation, Fmi3Type, Initial, ModelDescription, ValueReference,
    Variability, Variable, VariableKind, ELEMENT_VALUE_REFERENCES,
};
use crate::error::FmuError;
use std::collections::{HashMap, HashSet};

/// The types of FMI 3.0 variables that are not read.
const OTHER_TYPES: &[&str] = &["Binary", "Clock"];

/// The most array elements one model description may expand into: each
/// is a variable of its own, so a `<Dimension start="…"/>` of a billion
/// is refused here, not as an allocation failure.
pub const MAX_ARRAY_ELEMENTS: usize = 100_000;

/// The most dependencies the outputs keep, all together: an output array
/// of n elements that depends on arrays of m elements has n·m. Past it an
/// output's dependencies are left out (`None`: it may depend on every
/// known, what is assumed of an output that does not list them), rather
/// than filling the memory.
pub const MAX_DEPENDENCIES: usize = 4_000_000;

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
            let dimension = dimension(e, at)?;
            last_variable(raw).dimensions.push(dimension);
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
            let vr = required(e, at, "valueReference")?;
            raw.event_indicators.push(at.number("valueReference", &vr)?);
            Scope::Skip
        }
        _ => Scope::Skip,
    })
}

/// A `<Dimension>` (FMI 3.0.1 §2.4.7.4): its size given as `start`, or
/// by the structural parameter whose `valueReference` it names.
fn dimension(
    e: &quick_xml::events::BytesStart<'_>,
    at: &ElementAt<'_>,
) -> Result<RawDimension, FmuError> {
    let (mut start, mut vr) = (None, None);
    at.attributes(e, |key, value| {
        match key {
            "start" => start = Some(at.number::<u64>(key, &value)?),
            "valueReference" => vr = Some(at.number(key, &value)?),
            _ => {}
        }
        Ok(())
    })?;
    match (start, vr) {
        (Some(size), None) => Ok(RawDimension::Fixed(size)),
        (None, Some(vr)) => Ok(RawDimension::Structural(vr)),
        _ => Err(at.error(
            "a <Dimension> has either a start or a valueReference attribute (FMI 3.0.1 §2.4.7.4)"
                .to_string(),
        )),
    }
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
    /// `<EventIndicator>`s: value references.
    event_indicators: Vec<ValueReference>,
}

/// A `<Dimension>` as written.
#[derive(Clone, Copy)]
enum RawDimension {
    /// `start="n"`: a fixed size.
    Fixed(u64),
    /// `valueReference="vr"`: the size is the structural parameter `vr`.
    Structural(ValueReference),
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
    /// `<Dimension>` children, outermost first: an array when there is one.
    dimensions: Vec<RawDimension>,
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
        // value reference → 1-based index in ModelVariables as written
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
        let context = Context {
            units: self.units.as_deref(),
            types: self.types.as_ref(),
            by_vr: &by_vr,
        };
        let mut elements_left = MAX_ARRAY_ELEMENTS;
        let declared = raw_variables
            .into_iter()
            .enumerate()
            .map(|(i, raw)| raw.validate(i + 1, &context, &mut elements_left))
            .collect::<Result<Vec<_>, _>>()?;
        let Expanded {
            variables,
            arrays,
            indices,
        } = expand(declared)?;
        let (variables, by_name) = index_variables(variables)?;

        let mut outputs = Vec::with_capacity(self.outputs.len());
        let mut dependencies_left = MAX_DEPENDENCIES;
        for (i, (vr, dependencies)) in self.outputs.into_iter().enumerate() {
            let location = format!("ModelStructure/Output[{}] (valueReference {vr})", i + 1);
            let indices_of = |vr: ValueReference, what: &str| {
                indices.get(&vr).cloned().ok_or_else(|| {
                    invalid(
                        &location,
                        format!("{what} {vr} is not the value reference of a variable"),
                    )
                })
            };
            let own = indices_of(vr, "valueReference")?;
            // an array's dependencies are those of each element (FMI 3.0
            // says which arrays, not which of their elements)
            let dependencies = match dependencies {
                None => None,
                Some(text) => {
                    let mut all = Some(Vec::new());
                    for word in text.split_whitespace() {
                        let vr = word.parse().map_err(|_| {
                            invalid(
                                &location,
                                format!("dependency \"{word}\" is not a value reference"),
                            )
                        })?;
                        let range = indices_of(vr, "dependency")?;
                        if let Some(kept) = &mut all {
                            if kept.len() + range.len() > dependencies_left {
                                all = None;
                            } else {
                                kept.extend(range);
                            }
                        }
                    }
                    match all {
                        Some(all) if all.len() * own.len() <= dependencies_left => {
                            dependencies_left -= all.len() * own.len();
                            Some(all)
                        }
                        _ => None,
                    }
                }
            };
            for index in own {
                outputs.push(output_unknown(
                    &location,
                    index,
                    dependencies.clone(),
                    &variables,
                )?);
            }
        }
        // an array of event indicators counts its elements
        let number_of_event_indicators = self
            .event_indicators
            .iter()
            .map(|vr| indices.get(vr).map_or(1, |i| i.len()))
            .sum::<usize>();

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
            number_of_event_indicators: u32::try_from(number_of_event_indicators)
                .unwrap_or(u32::MAX),
            unit_definitions: self.units,
            log_categories: self.log_categories.unwrap_or_default(),
            default_experiment: self.default_experiment,
            variables,
            outputs,
            arrays,
            by_name,
        })
    }
}

/// What the variables are checked against: the units and types defined,
/// and every value reference (→ 1-based index as written).
struct Context<'a> {
    units: Option<&'a [String]>,
    /// `TypeDefinitions`: each type's name and, for a Float type, its unit.
    types: Option<&'a HashMap<String, Option<String>>>,
    by_vr: &'a HashMap<ValueReference, usize>,
}

/// One variable element, checked, with the variables fricsim makes of
/// it: itself for a scalar, its elements for an array (their indices and
/// value references are given by [`expand`]).
struct Declared {
    name: String,
    location: String,
    value_reference: ValueReference,
    value_type: Fmi3Type,
    /// `Some`: an array of these sizes, `variables` its elements in
    /// row-major order.
    dimensions: Option<Vec<usize>>,
    /// `derivative`: the FMU's value reference of the state this is the
    /// derivative of.
    derivative: Option<ValueReference>,
    variables: Vec<Variable>,
}

/// The variables of a description, arrays expanded.
struct Expanded {
    variables: Vec<Variable>,
    arrays: Vec<Array>,
    /// Each FMU value reference → the 1-based indices of the variables
    /// it became (one for a scalar, the elements of an array).
    indices: HashMap<ValueReference, std::ops::Range<usize>>,
}

/// The declared variables in document order, each array replaced by its
/// elements, which get their value references (from
/// [`ELEMENT_VALUE_REFERENCES`], or above the FMU's largest, so that none
/// is the FMU's); `derivative` resolved element by element.
fn expand(declared: Vec<Declared>) -> Result<Expanded, FmuError> {
    let mut indices = HashMap::with_capacity(declared.len());
    let mut next_index = 1;
    for d in &declared {
        let n = d.variables.len();
        indices.insert(d.value_reference, next_index..next_index + n);
        next_index += n;
    }
    let largest = declared.iter().map(|d| d.value_reference).max();
    let elements: usize = declared
        .iter()
        .filter(|d| d.dimensions.is_some())
        .map(|d| d.variables.len())
        .sum();
    let first = u64::from(ELEMENT_VALUE_REFERENCES).max(largest.map_or(0, |l| u64::from(l) + 1));
    if first + elements as u64 > u64::from(u32::MAX) + 1 {
        return Err(invalid(
            "<ModelVariables>",
            format!(
                "the FMU's value references reach {}, which leaves no room for the value \
                 references fricsim gives the {elements} array elements (above the FMU's own)",
                largest.unwrap_or(0)
            ),
        ));
    }
    // (u64: after the last element it may be 2³², one past the last value reference)
    let mut next_element = first;
    let array_vrs: HashSet<ValueReference> = declared
        .iter()
        .filter(|d| d.dimensions.is_some())
        .map(|d| d.value_reference)
        .collect();

    let mut variables = Vec::with_capacity(next_index - 1);
    let mut arrays = Vec::new();
    for d in declared {
        let first_index = variables.len() + 1;
        let derivatives = match d.derivative {
            None => None,
            Some(vr) => Some(derivative_indices(&d, vr, &indices, &array_vrs)?),
        };
        let array = d.dimensions.map(|dimensions| {
            arrays.push(Array {
                name: d.name.clone(),
                value_reference: d.value_reference,
                value_type: d.value_type,
                dimensions,
                first_element: next_element as ValueReference,
                first_index,
            });
            arrays.len() - 1
        });
        for (position, mut v) in d.variables.into_iter().enumerate() {
            v.index = first_index + position;
            if let (Some(states), VariableKind::Real { derivative, .. }) =
                (&derivatives, &mut v.kind)
            {
                *derivative = Some(states.start + position);
            }
            if let Some(array) = array {
                v.value_reference = (next_element + position as u64) as ValueReference;
                v.element = Some(ArrayElement { array, position });
            }
            variables.push(v);
        }
        if let Some(array) = array {
            next_element += arrays[array].len() as u64;
        }
    }
    Ok(Expanded {
        variables,
        arrays,
        indices,
    })
}

/// The indices of the state(s) the variable `d` is the derivative of
/// (`derivative="vr"`): a scalar's state is a scalar, an array's an array
/// of as many elements, element by element.
fn derivative_indices(
    d: &Declared,
    vr: ValueReference,
    indices: &HashMap<ValueReference, std::ops::Range<usize>>,
    array_vrs: &HashSet<ValueReference>,
) -> Result<std::ops::Range<usize>, FmuError> {
    let states = indices.get(&vr).cloned().ok_or_else(|| {
        invalid(
            &d.location,
            format!("derivative=\"{vr}\" is not the value reference of a variable"),
        )
    })?;
    let describe = |array: bool, n: usize| {
        if array {
            format!("an array of {n} elements")
        } else {
            "a scalar".to_string()
        }
    };
    let (own_array, state_array) = (d.dimensions.is_some(), array_vrs.contains(&vr));
    if own_array != state_array || states.len() != d.variables.len() {
        return Err(invalid(
            &d.location,
            format!(
                "derivative=\"{vr}\" names {}, but this variable is {}",
                describe(state_array, states.len()),
                describe(own_array, d.variables.len())
            ),
        ));
    }
    Ok(states)
}

impl RawVariable {
    fn validate(
        self,
        index: usize,
        context: &Context<'_>,
        elements_left: &mut usize,
    ) -> Result<Declared, FmuError> {
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
                    Fmi3Type::ALL
                        .iter()
                        .map(|t| t.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        let Some(value_type) = Fmi3Type::parse(type_name) else {
            return Err(invalid(
                &location,
                format!("<{type_name}> is not a variable type of FMI 3.0"),
            ));
        };
        let value_reference = self
            .value_reference
            .ok_or_else(|| invalid(&location, "the valueReference attribute is missing"))?;
        if self.causality.as_deref() == Some("structuralParameter") {
            return Err(invalid(
                &location,
                "structural parameters (the sizes of arrays) are not read yet",
            ));
        }
        let dimensions = fixed_dimensions(&self.dimensions, &location, elements_left)?;
        if dimensions.is_some() && value_type == Fmi3Type::String {
            return Err(invalid(
                &location,
                "it is a String array; FMI 3.0 arrays of String are not read yet",
            ));
        }
        let causality = choice(
            self.causality.as_deref(),
            Causality::Local,
            &location,
            "causality",
        )?;
        let float = matches!(value_type, Fmi3Type::Float64 | Fmi3Type::Float32);
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
        // (every declared type must exist, FMI 3.0 §2.4.7)
        let unit = unit_with_declared_type(
            self.unit,
            self.declared_type.as_deref(),
            context.types,
            "type",
            &location,
        )?;
        let mut derivative = None;
        if float {
            check_unit(unit.as_deref(), context.units, &location)?;
            if let Some(vr) = self.derivative {
                if !context.by_vr.contains_key(&vr) {
                    return Err(invalid(
                        &location,
                        format!("derivative=\"{vr}\" is not the value reference of a variable"),
                    ));
                }
                derivative = Some(vr);
            }
        }
        let values = ValueText {
            location: &location,
            value_type,
        };
        // the kind of the variable (or of one element) whose start is `start`
        let kind = |start: Option<&str>| -> Result<VariableKind, FmuError> {
            use Fmi3Type as T;
            Ok(match value_type {
                T::Float64 | T::Float32 => VariableKind::Real {
                    start: values.float("start", start)?,
                    unit: unit.clone(),
                    nominal: self.nominal,
                    min: values.float("min", self.min.as_deref())?,
                    max: values.float("max", self.max.as_deref())?,
                    derivative: None, // set by `expand`
                },
                T::Int8 | T::UInt8 | T::Int16 | T::UInt16 | T::Int32 => VariableKind::Integer {
                    start: values.narrow_integer("start", start)?,
                    min: values.narrow_integer("min", self.min.as_deref())?,
                    max: values.narrow_integer("max", self.max.as_deref())?,
                },
                T::UInt32 | T::Int64 | T::UInt64 => VariableKind::Real {
                    start: values.wide_integer("start", start)?,
                    unit: None,
                    nominal: None,
                    min: values.wide_integer("min", self.min.as_deref())?,
                    max: values.wide_integer("max", self.max.as_deref())?,
                    derivative: None,
                },
                T::Boolean => VariableKind::Boolean {
                    start: values.boolean("start", start)?,
                },
                T::String => VariableKind::String {
                    start: self.start_elements.first().cloned(),
                },
                T::Enumeration => VariableKind::Enumeration {
                    declared_type: self.declared_type.clone().ok_or_else(|| {
                        invalid(&location, "an <Enumeration> needs a declaredType attribute")
                    })?,
                    start: values.enumeration("start", start)?,
                    min: values.enumeration("min", self.min.as_deref())?,
                    max: values.enumeration("max", self.max.as_deref())?,
                },
            })
        };
        let variable = |name: String, kind: VariableKind| Variable {
            name,
            index, // the elements' by `expand`
            value_reference,
            description: self.description.clone(),
            causality,
            variability,
            initial,
            kind,
            fmi3_type: Some(value_type),
            element: None, // the elements' by `expand`
        };
        let variables = match &dimensions {
            None => vec![variable(name.clone(), kind(self.start.as_deref())?)],
            Some(dimensions) => {
                let n = element_count(dimensions);
                let starts: Vec<Option<&str>> = match self.start.as_deref() {
                    None => vec![None; n],
                    Some(text) => {
                        let words: Vec<&str> = text.split_whitespace().collect();
                        if words.len() != n {
                            return Err(invalid(
                                &location,
                                format!(
                                    "start has {} values for the {n} elements of the array \
                                     (dimensions {}): an array's start lists every element, \
                                     row-major",
                                    words.len(),
                                    shape(dimensions)
                                ),
                            ));
                        }
                        words.into_iter().map(Some).collect()
                    }
                };
                starts
                    .into_iter()
                    .enumerate()
                    .map(|(position, start)| {
                        let name = element_name(&name, &element_indices(position, dimensions));
                        Ok(variable(name, kind(start)?))
                    })
                    .collect::<Result<Vec<_>, FmuError>>()?
            }
        };
        Ok(Declared {
            name,
            location,
            value_reference,
            value_type,
            dimensions,
            derivative,
            variables,
        })
    }
}

/// The sizes of an array's `<Dimension>`s (`None` for a scalar), each
/// fixed, and within what is left of [`MAX_ARRAY_ELEMENTS`].
fn fixed_dimensions(
    dimensions: &[RawDimension],
    location: &str,
    elements_left: &mut usize,
) -> Result<Option<Vec<usize>>, FmuError> {
    if dimensions.is_empty() {
        return Ok(None);
    }
    let mut sizes = Vec::with_capacity(dimensions.len());
    let mut elements: u64 = 1;
    for d in dimensions {
        let size = match *d {
            RawDimension::Fixed(size) => size,
            RawDimension::Structural(vr) => {
                return Err(invalid(
                    location,
                    format!(
                        "it is an array whose size is the structural parameter with \
                         valueReference {vr} (<Dimension valueReference=\"{vr}\"/>); arrays \
                         sized by structural parameters are not read yet, only fixed sizes \
                         (<Dimension start=\"…\"/>)"
                    ),
                ))
            }
        };
        elements = elements.saturating_mul(size);
        sizes.push(usize::try_from(size).unwrap_or(usize::MAX));
    }
    if elements > *elements_left as u64 {
        return Err(invalid(
            location,
            format!(
                "the array has {elements} elements (dimensions {}): fricsim reads at most \
                 {MAX_ARRAY_ELEMENTS} array elements per FMU, each as a variable of its own",
                shape(&sizes)
            ),
        ));
    }
    *elements_left -= elements as usize;
    Ok(Some(sizes))
}

/// `3` or `2 × 3`, for messages.
fn shape(dimensions: &[usize]) -> String {
    dimensions
        .iter()
        .map(usize::to_string)
        .collect::<Vec<_>>()
        .join(" × ")
}

/// The 1-based indices of the element at `position` (row-major: the
/// last index runs fastest).
fn element_indices(mut position: usize, dimensions: &[usize]) -> Vec<usize> {
    let mut indices = vec![0; dimensions.len()];
    for (index, &size) in indices.iter_mut().zip(dimensions).rev() {
        *index = position % size + 1;
        position /= size;
    }
    indices
}

/// The name of an element in FMI's structured naming: `k[2]`, `A[1,3]`;
/// an element of `der(x)` (or `der(x,2)`) is `der(x[2])` (`der(x[2],2)`),
/// as FMI 2.0 names the derivative of an element.
fn element_name(array: &str, indices: &[usize]) -> String {
    let subscript = format!(
        "[{}]",
        indices
            .iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(",")
    );
    if let Some(inner) = array.strip_prefix("der(").and_then(|r| r.strip_suffix(')')) {
        let (state, order) = inner.split_at(inner.find(',').unwrap_or(inner.len()));
        return format!("der({state}{subscript}{order})");
    }
    format!("{array}{subscript}")
}

/// A variable's values as written, read as its type's.
struct ValueText<'a> {
    location: &'a str,
    value_type: Fmi3Type,
}

impl ValueText<'_> {
    fn float(&self, what: &str, text: Option<&str>) -> Result<Option<f64>, FmuError> {
        text.map(|t| {
            t.trim()
                .parse::<f64>()
                .map_err(|_| invalid(self.location, format!("{what}=\"{t}\" is not a number")))
        })
        .transpose()
    }

    /// An integer within the range of the variable's integer type.
    fn integer(&self, what: &str, t: &str) -> Result<i128, FmuError> {
        let (low, high) = integer_range(self.value_type);
        t.trim()
            .parse::<i128>()
            .ok()
            .filter(|v| (low..=high).contains(v))
            .ok_or_else(|| {
                invalid(
                    self.location,
                    format!(
                        "{what}=\"{t}\" is not a value of type {} (whole numbers from {low} to {high})",
                        self.value_type
                    ),
                )
            })
    }

    /// `Int8` … `Int32`, held as an `i32`.
    fn narrow_integer(&self, what: &str, text: Option<&str>) -> Result<Option<i32>, FmuError> {
        text.map(|t| Ok(self.integer(what, t)? as i32)).transpose()
    }

    /// `UInt32`, `Int64`, `UInt64`, held as an `f64`: only if it holds
    /// the value exactly.
    fn wide_integer(&self, what: &str, text: Option<&str>) -> Result<Option<f64>, FmuError> {
        text.map(|t| {
            let v = self.integer(what, t)?;
            let x = v as f64;
            if x as i128 != v {
                return Err(invalid(
                    self.location,
                    format!(
                        "{what}=\"{t}\": fricsim holds {} values as 64-bit floats, which \
                         cannot hold this one exactly",
                        self.value_type
                    ),
                ));
            }
            Ok(x)
        })
        .transpose()
    }

    /// An `Enumeration`'s value (`Int64` in FMI 3.0), held as FMI 2.0's
    /// 32-bit one.
    fn enumeration(&self, what: &str, text: Option<&str>) -> Result<Option<i32>, FmuError> {
        text.map(|t| {
            t.trim().parse::<i32>().map_err(|_| {
                invalid(
                    self.location,
                    format!("{what}=\"{t}\" is not a 32-bit integer"),
                )
            })
        })
        .transpose()
    }

    fn boolean(&self, what: &str, text: Option<&str>) -> Result<Option<bool>, FmuError> {
        match text.map(str::trim) {
            None => Ok(None),
            Some("true" | "1") => Ok(Some(true)),
            Some("false" | "0") => Ok(Some(false)),
            Some(t) => Err(invalid(
                self.location,
                format!(
                    "{what}=\"{t}\" is not a boolean (one of {})",
                    list(&["true", "false", "1", "0"])
                ),
            )),
        }
    }
}

/// The values of an FMI 3.0 integer type (§2.4.7.5).
fn integer_range(t: Fmi3Type) -> (i128, i128) {
    use Fmi3Type as T;
    match t {
        T::Int8 => (i8::MIN.into(), i8::MAX.into()),
        T::UInt8 => (0, u8::MAX.into()),
        T::Int16 => (i16::MIN.into(), i16::MAX.into()),
        T::UInt16 => (0, u16::MAX.into()),
        T::UInt32 => (0, u32::MAX.into()),
        T::Int64 | T::Enumeration => (i64::MIN.into(), i64::MAX.into()),
        T::UInt64 => (0, u64::MAX.into()),
        _ => (i32::MIN.into(), i32::MAX.into()),
    }
}
