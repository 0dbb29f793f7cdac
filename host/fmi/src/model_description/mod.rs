//! `modelDescription.xml` parsed into typed structs and validated: the
//! types here are the host's view of any FMU, whichever FMI version
//! describes it (the variables with name, value reference, causality,
//! variability, type, start, unit and description; the default
//! experiment; the capabilities the host reads), and the root element is
//! read here too, to pick the reader of its `fmiVersion`:
//!
//! - [`fmi2`]: FMI 2.0 (FMI 2.0.4 §2.2, §4.3.1), the one version read
//!   today;
//! - FMI 3.0 refused (`fmiVersion is "3.0", but only FMI 2.0 is
//!   supported`) until its reader, `fmi3.rs`, joins `fmi2.rs` (issue 45;
//!   see the crate's README).
//!
//! Parsing is one pass of quick-xml's pull reader over the document
//! (`xml.rs`: well-formedness, positions, attribute values), which the
//! version's reader fills into structs that mirror its XML; those are
//! then checked against the standard's rules and converted into the
//! types below.

pub mod fmi2;
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
    };
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
            // FMI 3.0 (issue 45): "3.0" => fmi3::read(document, root, version),
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
