//! `modelDescription.xml` parsed into typed structs and validated: the
//! types here are the host's view of any FMU, whichever FMI version
//! describes it (the variables with name, value reference, causality,
//! variability, type, start, unit and description; the default
//! experiment; the capabilities the host reads), and the root element is
//! read here too, to pick the reader of its `fmiVersion`:
//!
//! - [`fmi2`]: FMI 2.0 (FMI 2.0.4 §2.2, §4.3.1);
//! - [`fmi3`]: FMI 3.0 (FMI 3.0.1 §2.4, §4.3.1): its variables of every
//!   type but `Binary` and `Clock`, each as the FMI 2.0 type that holds
//!   its values ([`Fmi3Type::kind_name`]), and its arrays of fixed size
//!   expanded into one variable per element, `name[i]` ([`Array`]); a
//!   structural parameter, an array sized by one, `Binary` and `Clock`
//!   are refused by name.
//!
//! Parsing is one pass of quick-xml's pull reader over the document
//! (`xml.rs`: well-formedness, positions, attribute values), which the
//! version's reader fills into structs that mirror its XML; those are
//! then checked against the standard's rules and converted into the
//! types below.

pub mod fmi2;
pub mod fmi3;
mod xml;

use crate::error::FmuError;
use crate::xml_text::line_column;
use std::collections::HashMap;
use std::fmt;
use std::path::Path;
use xml::{Document, XML_SPACE};

/// A value reference (`fmi2ValueReference`, `fmi3ValueReference`).
pub type ValueReference = u32;

/// The parsed, validated model description, whichever FMI version it
/// was written for.
#[derive(Clone, Debug)]
pub struct ModelDescription {
    /// The root's `fmiVersion` as written ("2.0").
    pub fmi_version: String,
    pub model_name: String,
    /// FMI 2.0's `guid` (FMI 3.0 calls it `instantiationToken`): what
    /// instantiation must be given.
    pub guid: String,
    pub description: Option<String>,
    pub author: Option<String>,
    pub version: Option<String>,
    pub generation_tool: Option<String>,
    pub generation_date_and_time: Option<String>,
    pub co_simulation: CoSimulation,
    /// The `modelIdentifier` of the `ModelExchange` element, if the FMU
    /// also offers Model Exchange (not used by fricsim, which
    /// co-simulates).
    pub model_exchange: Option<String>,
    /// `numberOfEventIndicators` (Model Exchange), 0 when absent.
    pub number_of_event_indicators: u32,
    /// Names of the units of `UnitDefinitions`; `None` without that element.
    pub unit_definitions: Option<Vec<String>>,
    pub log_categories: Vec<LogCategory>,
    pub default_experiment: Option<DefaultExperiment>,
    /// In document order (an FMI 3.0 array as its elements, in its
    /// place): `variables[i]` has `index == i + 1`.
    pub variables: Vec<Variable>,
    /// `ModelStructure/Outputs`.
    pub outputs: Vec<Unknown>,
    /// FMI 3.0's arrays, in document order: each is in `variables` as its
    /// elements (empty for FMI 2.0, which has none).
    pub arrays: Vec<Array>,
    by_name: HashMap<String, usize>,
}

/// The `CoSimulation` element (FMI 2.0 §4.3.1, FMI 3.0 §4.3.1): the
/// capabilities of the FMU that the host reads. FMI 3.0 has the same
/// flags under the same names but two (`providesDirectionalDerivatives`,
/// plural; no `canRunAsynchronuously`), and more of its own, which join
/// this struct with its reader.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CoSimulation {
    pub model_identifier: String,
    pub needs_execution_tool: bool,
    pub can_handle_variable_communication_step_size: bool,
    pub can_interpolate_inputs: bool,
    pub max_output_derivative_order: u32,
    pub can_run_asynchronuously: bool,
    pub can_be_instantiated_only_once_per_process: bool,
    pub can_get_and_set_fmu_state: bool,
    pub can_serialize_fmu_state: bool,
    pub provides_directional_derivative: bool,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LogCategory {
    pub name: String,
    pub description: Option<String>,
}

/// `DefaultExperiment` (FMI 2.0 §2.2.5; the same in FMI 3.0).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DefaultExperiment {
    pub start_time: Option<f64>,
    pub stop_time: Option<f64>,
    pub tolerance: Option<f64>,
    pub step_size: Option<f64>,
}

/// One variable of `ModelVariables`: FMI 2.0's `ScalarVariable` (§2.2.7),
/// or an FMI 3.0 variable element.
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    pub name: String,
    /// 1-based position in [`ModelDescription::variables`]: in
    /// `ModelVariables`, as FMI 2.0's `ModelStructure` uses it; for FMI 3.0
    /// with the arrays expanded into their elements.
    pub index: usize,
    pub value_reference: ValueReference,
    pub description: Option<String>,
    pub causality: Causality,
    pub variability: Variability,
    pub initial: Option<Initial>,
    pub kind: VariableKind,
    /// FMI 3.0: the type the FMU declares (`None` for FMI 2.0, whose type
    /// is `kind`'s): which `fmi3Get…`/`fmi3Set…` reach the value.
    pub fmi3_type: Option<Fmi3Type>,
    /// FMI 3.0: the array this variable is an element of, if it is one
    /// (its `value_reference` is then fricsim's, not the FMU's).
    pub element: Option<ArrayElement>,
}

impl Variable {
    /// The type's name in the FMU's own FMI version: `Real`, `Integer`, …
    /// for FMI 2.0; `Float64`, `UInt8`, … for FMI 3.0.
    pub fn type_name(&self) -> &'static str {
        match self.fmi3_type {
            Some(t) => t.as_str(),
            None => self.kind.type_name(),
        }
    }

    /// The SSP connector type (`ssc:Real`, `ssc:Integer`, …) that
    /// describes the variable ([`Fmi3Type::ssp_type_name`] for an FMI 3.0
    /// one).
    pub fn ssp_type_name(&self) -> &'static str {
        match self.fmi3_type {
            Some(t) => t.ssp_type_name(),
            None => self.kind.type_name(),
        }
    }
}

/// An FMI 3.0 array variable of fixed size (a variable with
/// `<Dimension start="…"/>` children, FMI 3.0.1 §2.4.7.4), which fricsim
/// reads per element: each element is a [`Variable`] of its own, named
/// with FMI's structured naming (`x_table[1]`, `A[1,2]`: 1-based indices,
/// the last running fastest, i.e. row-major as the FMU lays the values
/// out), with its own start value and a value reference that fricsim
/// gives it (see [`Array::first_element`]). An instance reads and writes
/// the elements through the array's own value reference
/// ([`crate::Fmi3Instance`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Array {
    /// The name the FMU gives the array (`x_table`).
    pub name: String,
    /// The FMU's value reference of the whole array.
    pub value_reference: ValueReference,
    pub value_type: Fmi3Type,
    /// The size of each dimension, outermost first.
    pub dimensions: Vec<usize>,
    /// The value reference fricsim gives the first element (in row-major
    /// order); the others follow it. Element value references are
    /// numbered from [`ELEMENT_VALUE_REFERENCES`] (2³¹), or from just above
    /// the FMU's largest value reference if the FMU uses that range too,
    /// array after array in document order, so that none is one of the
    /// FMU's own.
    pub first_element: ValueReference,
    /// The 1-based index of the first element in `ModelVariables` (as
    /// fricsim has it, elements expanded); the others follow it.
    pub first_index: usize,
}

impl Array {
    /// The number of elements (the product of the dimensions).
    pub fn len(&self) -> usize {
        element_count(&self.dimensions)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether `vr` is the value reference of one of its elements; which.
    pub fn element_position(&self, vr: ValueReference) -> Option<usize> {
        let position = vr.checked_sub(self.first_element)? as usize;
        (position < self.len()).then_some(position)
    }
}

/// The number of elements of an array of `dimensions`: their product,
/// which the reader has kept within [`fmi3::MAX_ARRAY_ELEMENTS`] unless a
/// size is 0 (the sizes before it may then multiply past `usize`, and the
/// count is 0).
pub(crate) fn element_count(dimensions: &[usize]) -> usize {
    dimensions
        .iter()
        .try_fold(1usize, |n, &d| n.checked_mul(d))
        .unwrap_or(0)
}

/// Where the first element value reference fricsim gives the elements of
/// FMI 3.0 arrays is ([`Array::first_element`]): 2³¹, above the value
/// references exporters number from 0.
pub const ELEMENT_VALUE_REFERENCES: ValueReference = 1 << 31;

/// Which element of an [`Array`] a [`Variable`] is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ArrayElement {
    /// Index into [`ModelDescription::arrays`].
    pub array: usize,
    /// 0-based position in the array's values, row-major.
    pub position: usize,
}

/// The type of a variable with its attributes, by FMI 2.0's names: the
/// core's view of a value. An FMI 3.0 variable is the kind that holds its
/// type's values ([`Fmi3Type::kind_name`]: `Float64` and `Float32` are
/// `Real`, `Int8` … `Int32` are `Integer`, …), with its FMI 3.0 type in
/// [`Variable::fmi3_type`].
#[derive(Clone, Debug, PartialEq)]
pub enum VariableKind {
    Real {
        start: Option<f64>,
        unit: Option<String>,
        nominal: Option<f64>,
        min: Option<f64>,
        max: Option<f64>,
        /// Index of the variable this one is the derivative of.
        derivative: Option<usize>,
    },
    Integer {
        start: Option<i32>,
        min: Option<i32>,
        max: Option<i32>,
    },
    Boolean {
        start: Option<bool>,
    },
    String {
        start: Option<String>,
    },
    Enumeration {
        declared_type: String,
        start: Option<i32>,
        min: Option<i32>,
        max: Option<i32>,
    },
}

/// FMI 2.0's name for a [`Variable`], kept for the code written before
/// there was another version.
pub type ScalarVariable = Variable;

impl VariableKind {
    /// The type's name in FMI `version` ("2.0": `Real`, `Integer`,
    /// `Boolean`, `String`, `Enumeration`; "3.0": `Float64` and `Int32`
    /// for the first two).
    pub fn type_name_in(&self, version: &str) -> &'static str {
        match (version.trim(), self) {
            ("3.0", VariableKind::Real { .. }) => "Float64",
            ("3.0", VariableKind::Integer { .. }) => "Int32",
            _ => self.type_name(),
        }
    }

    /// The FMI 2.0 XML element name: `Real`, `Integer`, `Boolean`,
    /// `String`, `Enumeration`.
    pub fn type_name(&self) -> &'static str {
        match self {
            VariableKind::Real { .. } => "Real",
            VariableKind::Integer { .. } => "Integer",
            VariableKind::Boolean { .. } => "Boolean",
            VariableKind::String { .. } => "String",
            VariableKind::Enumeration { .. } => "Enumeration",
        }
    }

    /// The start value as written in a table (`None` without one).
    pub fn start_text(&self) -> Option<String> {
        match self {
            VariableKind::Real { start, .. } => start.map(|s| format!("{s:?}")),
            VariableKind::Integer { start, .. } | VariableKind::Enumeration { start, .. } => {
                start.map(|s| s.to_string())
            }
            VariableKind::Boolean { start } => start.map(|s| s.to_string()),
            VariableKind::String { start } => start.clone(),
        }
    }

    pub fn unit(&self) -> Option<&str> {
        match self {
            VariableKind::Real { unit, .. } => unit.as_deref(),
            _ => None,
        }
    }
}

/// An entry of `ModelStructure/Outputs` (FMI 2.0 §2.2.8).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Unknown {
    /// 1-based index into `ModelVariables`.
    pub index: usize,
    /// Indices this output depends on; `None` if the attribute is absent
    /// (= it may depend on all knowns).
    pub dependencies: Option<Vec<usize>>,
}

macro_rules! xml_enum {
    ($(#[$meta:meta])* $name:ident { $($variant:ident = $text:literal),* $(,)? }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum $name { $($variant),* }

        impl $name {
            /// Every value, in the order of the standard.
            pub const ALL: &'static [$name] = &[$($name::$variant),*];

            pub fn as_str(self) -> &'static str {
                match self { $($name::$variant => $text),* }
            }

            /// The value written `text`, if it is one.
            pub(crate) fn parse(text: &str) -> Option<$name> {
                match text { $($text => Some($name::$variant),)* _ => None }
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.as_str())
            }
        }

        impl Choice for $name {
            fn all() -> &'static [Self] {
                $name::ALL
            }

            fn parse(text: &str) -> Option<Self> {
                $name::parse(text)
            }
        }
    };
}

/// An attribute with a fixed set of values ([`Causality`], …), as
/// [`choice`] reads it.
pub(super) trait Choice: Copy + fmt::Display + 'static {
    fn all() -> &'static [Self];
    fn parse(text: &str) -> Option<Self>;
}

xml_enum!(
    /// `causality` (FMI 2.0 §2.2.7, FMI 3.0 adds `structuralParameter`); default `local`.
    Causality {
        Parameter = "parameter",
        CalculatedParameter = "calculatedParameter",
        Input = "input",
        Output = "output",
        Local = "local",
        Independent = "independent",
    }
);

xml_enum!(
    /// `variability` (FMI 2.0 §2.2.7, the same in FMI 3.0); default `continuous`.
    Variability {
        Constant = "constant",
        Fixed = "fixed",
        Tunable = "tunable",
        Discrete = "discrete",
        Continuous = "continuous",
    }
);

xml_enum!(
    /// `initial` (FMI 2.0 §2.2.7, the same in FMI 3.0).
    Initial {
        Exact = "exact",
        Approx = "approx",
        Calculated = "calculated",
    }
);

xml_enum!(
    /// The types of FMI 3.0 variables that fricsim reads (FMI 3.0.1
    /// §2.4.7; not `Binary` and `Clock`). Each is held by the FMI 2.0
    /// type of the core that holds all its values ([`Fmi3Type::kind_name`]).
    Fmi3Type {
        Float32 = "Float32",
        Float64 = "Float64",
        Int8 = "Int8",
        UInt8 = "UInt8",
        Int16 = "Int16",
        UInt16 = "UInt16",
        Int32 = "Int32",
        UInt32 = "UInt32",
        Int64 = "Int64",
        UInt64 = "UInt64",
        Boolean = "Boolean",
        String = "String",
        Enumeration = "Enumeration",
    }
);

impl Fmi3Type {
    /// The [`VariableKind`] that holds the values: `Real` (an `f64`) for
    /// the floats and for the integers `i32` cannot hold (`UInt32`,
    /// `Int64`, `UInt64`: every `UInt32` exactly, a 64-bit value only if
    /// an `f64` holds it exactly, else refused where it is met), `Integer`
    /// for the narrower integers, and `Boolean`, `String`, `Enumeration`
    /// as themselves (an FMI 3.0 `Enumeration` is read and written as
    /// `Int64`, and held as FMI 2.0's 32-bit one).
    pub fn kind_name(self) -> &'static str {
        use Fmi3Type as T;
        match self {
            T::Float32 | T::Float64 | T::UInt32 | T::Int64 | T::UInt64 => "Real",
            T::Int8 | T::UInt8 | T::Int16 | T::UInt16 | T::Int32 => "Integer",
            T::Boolean => "Boolean",
            T::String => "String",
            T::Enumeration => "Enumeration",
        }
    }

    /// The SSP 1.0 connector type of this type (`ssc:Real`, …): `Real`
    /// for the floats, `Integer` for every integer width, the others as
    /// themselves. Not [`Fmi3Type::kind_name`]: an `Int64` is held as a
    /// `Real` but is an `Integer` connector.
    pub fn ssp_type_name(self) -> &'static str {
        use Fmi3Type as T;
        match self {
            T::Float32 | T::Float64 => "Real",
            T::Int8 | T::UInt8 | T::Int16 | T::UInt16 => "Integer",
            T::Int32 | T::UInt32 | T::Int64 | T::UInt64 => "Integer",
            T::Boolean => "Boolean",
            T::String => "String",
            T::Enumeration => "Enumeration",
        }
    }

    /// Whether `fmi3Get<Type>` of it is that of the [`VariableKind`] that
    /// holds it (`Float64` for `Real`, `Int32` for `Integer`, `Boolean`,
    /// `String`): the value passes as it is, with no conversion.
    pub fn is_kind_native(self) -> bool {
        matches!(
            self,
            Fmi3Type::Float64 | Fmi3Type::Int32 | Fmi3Type::Boolean | Fmi3Type::String
        )
    }
}

impl ModelDescription {
    /// Whether the FMU is an FMI 3.0 one (`fmiVersion="3.0"`): its binary
    /// exports `fmi3…` functions and lives in `binaries/x86_64-linux`.
    pub fn is_fmi3(&self) -> bool {
        self.fmi_version.trim_matches(XML_SPACE) == "3.0"
    }

    /// Read and parse the file at `path`.
    pub fn from_file(path: &Path) -> Result<ModelDescription, FmuError> {
        let bytes = std::fs::read(path).map_err(|source| FmuError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let text = std::str::from_utf8(&bytes).map_err(|e| {
            let (line, column) = line_column(&bytes, e.valid_up_to());
            FmuError::XmlSyntax {
                line,
                column,
                message: format!("not valid UTF-8: {e}"),
            }
        })?;
        ModelDescription::parse(text)
    }

    /// Parse the text of a `modelDescription.xml`: the root element is
    /// read here, and the rest by the reader of the FMI version its
    /// `fmiVersion` names (an FMI 1.0 or 3.0 file has another schema,
    /// and saying "version 3.0" is more useful than a missing-attribute
    /// error).
    pub fn parse(xml: &str) -> Result<ModelDescription, FmuError> {
        let xml = xml.strip_prefix('\u{feff}').unwrap_or(xml);
        let mut document = Document::new(xml);
        let root = document.root()?;
        let version = root
            .attribute("fmiVersion")
            .ok_or_else(|| root.at.missing("fmiVersion"))?
            .to_string();
        match version.trim_matches(XML_SPACE) {
            "2.0" => fmi2::read(document, root, version),
            "3.0" => fmi3::read(document, root, version),
            _ => Err(FmuError::UnsupportedFmiVersion { found: version }),
        }
    }

    /// The variable whose value reference is `vr` (an FMI 3.0 array's
    /// element by the value reference fricsim gives it), if there is one.
    pub fn variable_by_value_reference(&self, vr: ValueReference) -> Option<&Variable> {
        self.variables.iter().find(|v| v.value_reference == vr)
    }

    /// For a name that is no variable's: if it is an FMI 3.0 array's (`k`),
    /// what to name instead, to add to a message (``; `k` is an FMI 3.0
    /// array of 3 elements, which are variables one by one: `k[1]` …
    /// `k[3]` ``); "" for any other name.
    pub fn array_hint(&self, name: &str) -> String {
        match self.arrays.iter().find(|a| a.name == name) {
            Some(a) if !a.is_empty() => format!(
                "; `{name}` is an FMI 3.0 array of {} elements, which are variables one by one: `{}` … `{}`",
                a.len(),
                self.variables[a.first_index - 1].name,
                self.variables[a.first_index + a.len() - 2].name
            ),
            _ => String::new(),
        }
    }

    /// The variable called `name`.
    pub fn variable(&self, name: &str) -> Result<&Variable, FmuError> {
        self.by_name
            .get(name)
            .map(|&i| &self.variables[i])
            .ok_or_else(|| FmuError::UnknownVariable {
                name: name.to_string(),
                model: self.model_name.clone(),
            })
    }
}

// ---- the rules both versions' readers apply ---------------------------

pub(super) fn invalid(location: impl Into<String>, message: impl Into<String>) -> FmuError {
    FmuError::InvalidModelDescription {
        location: location.into(),
        message: message.into(),
    }
}

/// A valid C identifier: `modelIdentifier` names the binary and prefixes
/// function names (FMI 2.0 §2.2.1, §4.3.1; FMI 3.0 §2.4.1), so anything
/// else (a `/`, `..`) is refused.
pub(super) fn is_c_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// The values of a choice, quoted, for a message.
pub(super) fn list<T: fmt::Display>(items: &[T]) -> String {
    items
        .iter()
        .map(|i| format!("\"{i}\""))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The value of the choice attribute `what` written `text`, `default` when
/// it is absent; a value outside the choice is refused with the list.
pub(super) fn choice<T: Choice>(
    text: Option<&str>,
    default: T,
    location: &str,
    what: &str,
) -> Result<T, FmuError> {
    match text {
        None => Ok(default),
        Some(text) => T::parse(text).ok_or_else(|| {
            invalid(
                location,
                format!("{what} \"{text}\" is not one of {}", list(T::all())),
            )
        }),
    }
}

/// The causality/variability combinations the standard allows (FMI 2.0
/// §2.2.7; FMI 3.0 §2.4.7.4 has the same table, plus its structural
/// parameters, which are not read).
pub(super) fn combination_allowed(c: Causality, v: Variability) -> bool {
    use Causality as C;
    use Variability as V;
    match v {
        V::Constant => matches!(c, C::Output | C::Local),
        V::Fixed | V::Tunable => matches!(c, C::Parameter | C::CalculatedParameter | C::Local),
        V::Discrete => matches!(c, C::Input | C::Output | C::Local),
        V::Continuous => matches!(c, C::Input | C::Output | C::Local | C::Independent),
    }
}

/// A variable's unit must be one of `UnitDefinitions`, when there is that
/// element.
pub(super) fn check_unit(
    unit: Option<&str>,
    units: Option<&[String]>,
    location: &str,
) -> Result<(), FmuError> {
    match (unit, units) {
        (Some(unit), Some(units)) if !units.iter().any(|u| u == unit) => Err(invalid(
            location,
            format!("unit \"{unit}\" is not defined in <UnitDefinitions>"),
        )),
        _ => Ok(()),
    }
}

/// A variable's unit: its own (`own`), else that of its declared type
/// (`declared`, looked up in `types`: each type of `TypeDefinitions` and
/// the unit it gives, FMI 2.0 §2.2.3, FMI 3.0 §2.4.4); a declared type
/// that is not defined is refused (`kind`: what the version calls a type
/// definition, for the message).
pub(super) fn unit_with_declared_type(
    own: Option<String>,
    declared: Option<&str>,
    types: Option<&HashMap<String, Option<String>>>,
    kind: &str,
    location: &str,
) -> Result<Option<String>, FmuError> {
    let Some(declared) = declared else {
        return Ok(own);
    };
    match types.and_then(|types| types.get(declared)) {
        Some(unit) => Ok(own.or_else(|| unit.clone())),
        None => Err(invalid(
            location,
            format!("declaredType=\"{declared}\" is not a {kind} of <TypeDefinitions>"),
        )),
    }
}

/// The variables in document order, checked for unique names and for
/// `derivative` indices inside `ModelVariables`, with the index by name.
pub(super) fn index_variables(
    variables: Vec<Variable>,
) -> Result<(Vec<Variable>, HashMap<String, usize>), FmuError> {
    let mut by_name = HashMap::with_capacity(variables.len());
    for (i, variable) in variables.iter().enumerate() {
        if let Some(&first) = by_name.get(&variable.name) {
            return Err(invalid(
                format!("variable \"{}\" (index {})", variable.name, i + 1),
                format!(
                    "the name is already used by the variable at index {}",
                    first + 1
                ),
            ));
        }
        by_name.insert(variable.name.clone(), i);
    }
    for v in &variables {
        if let VariableKind::Real {
            derivative: Some(d),
            ..
        } = v.kind
        {
            if d == 0 || d > variables.len() {
                return Err(invalid(
                    format!("variable \"{}\" (index {})", v.name, v.index),
                    format!(
                        "derivative=\"{d}\" is not an index of ModelVariables (1..={})",
                        variables.len()
                    ),
                ));
            }
        }
    }
    Ok((variables, by_name))
}

/// An output of `ModelStructure` at `location`: the variable at `index`
/// (1-based) must exist and be an output; `dependencies` are indices
/// already checked.
pub(super) fn output_unknown(
    location: &str,
    index: usize,
    dependencies: Option<Vec<usize>>,
    variables: &[Variable],
) -> Result<Unknown, FmuError> {
    let variable = index
        .checked_sub(1)
        .and_then(|k| variables.get(k))
        .ok_or_else(|| {
            invalid(
                location,
                format!("not an index of ModelVariables (1..={})", variables.len()),
            )
        })?;
    if variable.causality != Causality::Output {
        return Err(invalid(
            location,
            format!(
                "variable \"{}\" has causality \"{}\", expected \"output\"",
                variable.name, variable.causality
            ),
        ));
    }
    Ok(Unknown {
        index,
        dependencies,
    })
}

// ---- elements both versions write alike --------------------------------

/// `DefaultExperiment` (FMI 2.0 §2.2.5; the same in FMI 3.0).
fn default_experiment(
    e: &quick_xml::events::BytesStart<'_>,
    at: &xml::ElementAt<'_>,
) -> Result<DefaultExperiment, FmuError> {
    let mut d = DefaultExperiment::default();
    at.attributes(e, |key, value| {
        let field = match key {
            "startTime" => &mut d.start_time,
            "stopTime" => &mut d.stop_time,
            "tolerance" => &mut d.tolerance,
            "stepSize" => &mut d.step_size,
            _ => return Ok(()),
        };
        *field = Some(at.number(key, &value)?);
        Ok(())
    })?;
    Ok(d)
}

/// The attribute `key` of the element at `at`, which must have it
/// (`Unit`'s `name`, `ModelExchange`'s `modelIdentifier`, …).
fn required(
    e: &quick_xml::events::BytesStart<'_>,
    at: &xml::ElementAt<'_>,
    key: &str,
) -> Result<String, FmuError> {
    let mut found = None;
    at.attributes(e, |k, value| {
        if k == key {
            found = Some(value.into_owned());
        }
        Ok(())
    })?;
    found.ok_or_else(|| at.missing(key))
}

/// A `Category` of `LogCategories` (the same in both versions).
fn log_category(
    e: &quick_xml::events::BytesStart<'_>,
    at: &xml::ElementAt<'_>,
) -> Result<LogCategory, FmuError> {
    let mut name = None;
    let mut description = None;
    at.attributes(e, |key, value| {
        match key {
            "name" => name = Some(value.into_owned()),
            "description" => description = Some(value.into_owned()),
            _ => {}
        }
        Ok(())
    })?;
    let name = name.ok_or_else(|| at.missing("name"))?;
    Ok(LogCategory { name, description })
}
