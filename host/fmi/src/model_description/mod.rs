//! `modelDescription.xml` parsed into typed structs and validated: the
//! types here are the host's view of any FMU, whichever FMI version
//! describes it (the variables with name, value reference, causality,
//! variability, type, start, unit and description; the default
//! experiment; the capabilities the host reads), and the root element is
//! read here too, to pick the reader of its `fmiVersion`:
//!
//! - [`fmi2`]: FMI 2.0 (FMI 2.0.4 §2.2, §4.3.1);
//! - [`fmi3`]: FMI 3.0 (FMI 3.0.1 §2.4, §4.3.1), for its scalar variables
//!   of the types that have an FMI 2.0 counterpart (`Float64`, `Int32`,
//!   `Boolean`, `String`, `Enumeration`); an array, a structural
//!   parameter or another type is refused by name. `fricsim info` shows
//!   such an FMU; running one needs the FMI 3.0 calls, which the host does
//!   not make yet ([`crate::instance`] refuses it with a message).
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
    /// In document order: `variables[i]` has `index == i + 1`.
    pub variables: Vec<Variable>,
    /// `ModelStructure/Outputs`.
    pub outputs: Vec<Unknown>,
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
    /// 1-based position in `ModelVariables`, as used by `ModelStructure`.
    pub index: usize,
    pub value_reference: ValueReference,
    pub description: Option<String>,
    pub causality: Causality,
    pub variability: Variability,
    pub initial: Option<Initial>,
    pub kind: VariableKind,
}

/// The type of a variable with its attributes, by FMI 2.0's names: FMI
/// 3.0's `Float64` is `Real` and its `Int32` is `Integer` (the types
/// issue 45 imports); its other types (`Float32`, the other integer
/// widths, `Binary`, `Clock`) and arrays will need variants of their own.
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
