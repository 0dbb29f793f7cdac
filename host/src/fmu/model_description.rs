//! `modelDescription.xml` of FMI 2.0 (FMI 2.0.4 §2.2, §4.3.1 for the
//! `CoSimulation` element) parsed into typed structs and validated. An FMU
//! that also offers Model Exchange (a `ModelExchange` element, state
//! derivatives with a `derivative` attribute) is read for its
//! Co-Simulation interface, which is the one fricsim uses; the other is
//! only noted ([`ModelDescription::model_exchange`]).
//!
//! Parsing has two passes: the root element's `fmiVersion` is read first
//! (an FMI 1.0 or 3.0 file has another schema, and saying "version 3.0" is
//! more useful than a missing-attribute error), then the whole document is
//! deserialized with quick-xml + serde into `Raw…` structs that mirror the
//! XML, and converted into the public types with the checks of §2.2.7
//! (legal causality/variability/initial values and combinations, unique
//! names, units declared in `UnitDefinitions`, `ModelStructure` indices).

use crate::error::FmuError;
use crate::ssp::xml::{double_hyphen_offset, line_column};
use quick_xml::events::Event;
use serde::Deserialize;
use std::collections::HashMap;
use std::fmt;
use std::path::Path;

/// A value reference (`fmi2ValueReference`).
pub type ValueReference = u32;

/// The parsed, validated model description.
#[derive(Clone, Debug)]
pub struct ModelDescription {
    pub fmi_version: String,
    pub model_name: String,
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
    pub variables: Vec<ScalarVariable>,
    /// `ModelStructure/Outputs`.
    pub outputs: Vec<Unknown>,
    by_name: HashMap<String, usize>,
}

/// The `CoSimulation` element (§4.3.1): the capabilities of the FMU.
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

/// `DefaultExperiment` (§2.2.5).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DefaultExperiment {
    pub start_time: Option<f64>,
    pub stop_time: Option<f64>,
    pub tolerance: Option<f64>,
    pub step_size: Option<f64>,
}

/// One `ScalarVariable` (§2.2.7).
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarVariable {
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

/// The type element of a variable with its attributes.
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

impl VariableKind {
    /// The XML element name: `Real`, `Integer`, `Boolean`, `String`, `Enumeration`.
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

/// An entry of `ModelStructure/Outputs` (§2.2.8).
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

            fn parse(text: &str) -> Option<$name> {
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
    /// `causality` (§2.2.7); default `local`.
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
    /// `variability` (§2.2.7); default `continuous`.
    Variability {
        Constant = "constant",
        Fixed = "fixed",
        Tunable = "tunable",
        Discrete = "discrete",
        Continuous = "continuous",
    }
);

xml_enum!(
    /// `initial` (§2.2.7).
    Initial {
        Exact = "exact",
        Approx = "approx",
        Calculated = "calculated",
    }
);

/// The causality/variability combinations the table of §2.2.7 allows.
fn combination_allowed(c: Causality, v: Variability) -> bool {
    use Causality as C;
    use Variability as V;
    match v {
        V::Constant => matches!(c, C::Output | C::Local),
        V::Fixed | V::Tunable => matches!(c, C::Parameter | C::CalculatedParameter | C::Local),
        V::Discrete => matches!(c, C::Input | C::Output | C::Local),
        V::Continuous => matches!(c, C::Input | C::Output | C::Local | C::Independent),
    }
}

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

    /// Parse the text of a `modelDescription.xml`.
    pub fn parse(xml: &str) -> Result<ModelDescription, FmuError> {
        let xml = xml.strip_prefix('\u{feff}').unwrap_or(xml);
        check_fmi_version(xml)?;
        let mut de = quick_xml::de::Deserializer::from_str(xml);
        let raw = RawModelDescription::deserialize(&mut de).map_err(|e| {
            let reader = de.get_ref().get_ref();
            // Syntax errors point at the offending markup; errors found at
            // the end of input (truncation) or by serde at the last event.
            let position = match e {
                quick_xml::DeError::InvalidXml(_) if reader.error_position() > 0 => {
                    reader.error_position()
                }
                _ => reader.buffer_position(),
            };
            let (line, column) = line_column(xml.as_bytes(), position as usize);
            FmuError::XmlSyntax {
                line,
                column,
                message: e.to_string(),
            }
        })?;
        raw.validate()
    }

    /// The variable called `name`.
    pub fn variable(&self, name: &str) -> Result<&ScalarVariable, FmuError> {
        self.by_name
            .get(name)
            .map(|&i| &self.variables[i])
            .ok_or_else(|| FmuError::UnknownVariable {
                name: name.to_string(),
                model: self.model_name.clone(),
            })
    }
}

/// First pass: the root element must be `fmiModelDescription` with
/// `fmiVersion="2.0"`, and no comment may hold `--` (XML 1.0 §2.5: FMPy's
/// parser, lxml, refuses such a file, so it is refused here too, with the
/// line).
fn check_fmi_version(xml: &str) -> Result<(), FmuError> {
    let mut reader = quick_xml::Reader::from_str(xml);
    reader.config_mut().check_comments = true;
    let syntax = |reader: &quick_xml::Reader<&[u8]>, message: String| {
        let (line, column) = line_column(xml.as_bytes(), reader.error_position() as usize);
        FmuError::XmlSyntax {
            line,
            column,
            message,
        }
    };
    loop {
        let position = reader.buffer_position() as usize;
        match reader.read_event() {
            Err(quick_xml::Error::IllFormed(
                quick_xml::errors::IllFormedError::DoubleHyphenInComment,
            )) => return Err(double_hyphen(xml, position)),
            Err(e) => return Err(syntax(&reader, e.to_string())),
            Ok(Event::Eof) => return Err(syntax(&reader, "no root element".into())),
            Ok(Event::Start(e) | Event::Empty(e)) => {
                if e.name().0 != "fmiModelDescription" {
                    let found = e.name().0.to_string();
                    return Err(syntax(
                        &reader,
                        format!("root element is <{found}>, expected <fmiModelDescription>"),
                    ));
                }
                let version = e
                    .try_get_attribute("fmiVersion")
                    .map_err(|err| syntax(&reader, err.to_string()))?
                    .ok_or_else(|| {
                        syntax(
                            &reader,
                            "<fmiModelDescription> has no fmiVersion attribute".into(),
                        )
                    })?;
                let version = version
                    .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                    .map_err(|err| syntax(&reader, err.to_string()))?;
                if version.trim() != "2.0" {
                    return Err(FmuError::UnsupportedFmiVersion {
                        found: version.into_owned(),
                    });
                }
                return check_comments(xml, reader);
            }
            Ok(_) => {}
        }
    }
}

/// The rest of the first pass: only a comment holding `--` is reported
/// here; any other error is left to the deserializer, whose messages say
/// more (a truncated file names the element left open).
fn check_comments(xml: &str, mut reader: quick_xml::Reader<&[u8]>) -> Result<(), FmuError> {
    loop {
        let position = reader.buffer_position() as usize;
        match reader.read_event() {
            Err(quick_xml::Error::IllFormed(
                quick_xml::errors::IllFormedError::DoubleHyphenInComment,
            )) => return Err(double_hyphen(xml, position)),
            Err(_) | Ok(Event::Eof) => return Ok(()),
            Ok(_) => {}
        }
    }
}

/// The error for a comment holding `--`, in the event starting at byte
/// `event_start`.
fn double_hyphen(xml: &str, event_start: usize) -> FmuError {
    let offset = double_hyphen_offset(xml, event_start);
    let (line, column) = line_column(xml.as_bytes(), offset);
    FmuError::XmlSyntax {
        line,
        column,
        message: "`--` inside a comment, which XML does not allow (XML 1.0 §2.5): \
                  FMPy and other importers refuse the file"
            .to_string(),
    }
}

fn invalid(location: impl Into<String>, message: impl Into<String>) -> FmuError {
    FmuError::InvalidModelDescription {
        location: location.into(),
        message: message.into(),
    }
}

/// A valid C identifier: `modelIdentifier` names the binary and prefixes
/// function names (§2.2.1, §4.3.1), so anything else (a `/`, `..`) is refused.
fn is_c_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

// The XML as it is, before validation. quick-xml maps attributes to `@name`
// fields and child elements to fields named like the element; elements not
// listed here (TypeDefinitions, annotations, …) are skipped.

#[derive(Deserialize)]
struct RawModelDescription {
    #[serde(rename = "@fmiVersion")]
    fmi_version: String,
    #[serde(rename = "@modelName")]
    model_name: String,
    #[serde(rename = "@guid")]
    guid: String,
    #[serde(rename = "@description")]
    description: Option<String>,
    #[serde(rename = "@author")]
    author: Option<String>,
    #[serde(rename = "@version")]
    version: Option<String>,
    #[serde(rename = "@generationTool")]
    generation_tool: Option<String>,
    #[serde(rename = "@generationDateAndTime")]
    generation_date_and_time: Option<String>,
    #[serde(rename = "@numberOfEventIndicators")]
    number_of_event_indicators: Option<u32>,
    #[serde(rename = "ModelExchange")]
    model_exchange: Option<RawModelExchange>,
    #[serde(rename = "CoSimulation")]
    co_simulation: Option<RawCoSimulation>,
    #[serde(rename = "UnitDefinitions")]
    unit_definitions: Option<RawUnitDefinitions>,
    #[serde(rename = "LogCategories")]
    log_categories: Option<RawLogCategories>,
    #[serde(rename = "DefaultExperiment")]
    default_experiment: Option<RawDefaultExperiment>,
    #[serde(rename = "ModelVariables")]
    model_variables: Option<RawModelVariables>,
    #[serde(rename = "ModelStructure")]
    model_structure: Option<RawModelStructure>,
}

/// The one attribute of `ModelExchange` fricsim reports.
#[derive(Deserialize)]
struct RawModelExchange {
    #[serde(rename = "@modelIdentifier")]
    model_identifier: String,
}

#[derive(Deserialize)]
struct RawCoSimulation {
    #[serde(rename = "@modelIdentifier")]
    model_identifier: String,
    #[serde(rename = "@needsExecutionTool")]
    needs_execution_tool: Option<bool>,
    #[serde(rename = "@canHandleVariableCommunicationStepSize")]
    can_handle_variable_communication_step_size: Option<bool>,
    #[serde(rename = "@canInterpolateInputs")]
    can_interpolate_inputs: Option<bool>,
    #[serde(rename = "@maxOutputDerivativeOrder")]
    max_output_derivative_order: Option<u32>,
    #[serde(rename = "@canRunAsynchronuously")]
    can_run_asynchronuously: Option<bool>,
    #[serde(rename = "@canBeInstantiatedOnlyOncePerProcess")]
    can_be_instantiated_only_once_per_process: Option<bool>,
    #[serde(rename = "@canGetAndSetFMUstate")]
    can_get_and_set_fmu_state: Option<bool>,
    #[serde(rename = "@canSerializeFMUstate")]
    can_serialize_fmu_state: Option<bool>,
    #[serde(rename = "@providesDirectionalDerivative")]
    provides_directional_derivative: Option<bool>,
}

#[derive(Deserialize)]
struct RawUnitDefinitions {
    #[serde(rename = "Unit", default)]
    units: Vec<RawUnit>,
}

#[derive(Deserialize)]
struct RawUnit {
    #[serde(rename = "@name")]
    name: String,
}

#[derive(Deserialize)]
struct RawLogCategories {
    #[serde(rename = "Category", default)]
    categories: Vec<RawCategory>,
}

#[derive(Deserialize)]
struct RawCategory {
    #[serde(rename = "@name")]
    name: String,
    #[serde(rename = "@description")]
    description: Option<String>,
}

#[derive(Deserialize)]
struct RawDefaultExperiment {
    #[serde(rename = "@startTime")]
    start_time: Option<f64>,
    #[serde(rename = "@stopTime")]
    stop_time: Option<f64>,
    #[serde(rename = "@tolerance")]
    tolerance: Option<f64>,
    #[serde(rename = "@stepSize")]
    step_size: Option<f64>,
}

#[derive(Deserialize)]
struct RawModelVariables {
    #[serde(rename = "ScalarVariable", default)]
    variables: Vec<RawScalarVariable>,
}

#[derive(Deserialize)]
struct RawScalarVariable {
    #[serde(rename = "@name")]
    name: Option<String>,
    #[serde(rename = "@valueReference")]
    value_reference: Option<u32>,
    #[serde(rename = "@description")]
    description: Option<String>,
    #[serde(rename = "@causality")]
    causality: Option<String>,
    #[serde(rename = "@variability")]
    variability: Option<String>,
    #[serde(rename = "@initial")]
    initial: Option<String>,
    #[serde(rename = "Real")]
    real: Option<RawReal>,
    #[serde(rename = "Integer")]
    integer: Option<RawInteger>,
    #[serde(rename = "Boolean")]
    boolean: Option<RawBoolean>,
    #[serde(rename = "String")]
    string: Option<RawString>,
    #[serde(rename = "Enumeration")]
    enumeration: Option<RawInteger>,
}

#[derive(Deserialize)]
struct RawReal {
    #[serde(rename = "@start")]
    start: Option<f64>,
    #[serde(rename = "@unit")]
    unit: Option<String>,
    #[serde(rename = "@nominal")]
    nominal: Option<f64>,
    #[serde(rename = "@min")]
    min: Option<f64>,
    #[serde(rename = "@max")]
    max: Option<f64>,
    #[serde(rename = "@derivative")]
    derivative: Option<usize>,
}

/// `Integer` and `Enumeration` share their attributes.
#[derive(Deserialize)]
struct RawInteger {
    #[serde(rename = "@declaredType")]
    declared_type: Option<String>,
    #[serde(rename = "@start")]
    start: Option<i32>,
    #[serde(rename = "@min")]
    min: Option<i32>,
    #[serde(rename = "@max")]
    max: Option<i32>,
}

#[derive(Deserialize)]
struct RawBoolean {
    #[serde(rename = "@start")]
    start: Option<bool>,
}

#[derive(Deserialize)]
struct RawString {
    #[serde(rename = "@start")]
    start: Option<String>,
}

#[derive(Deserialize)]
struct RawModelStructure {
    #[serde(rename = "Outputs")]
    outputs: Option<RawUnknowns>,
}

#[derive(Deserialize)]
struct RawUnknowns {
    #[serde(rename = "Unknown", default)]
    unknowns: Vec<RawUnknown>,
}

#[derive(Deserialize)]
struct RawUnknown {
    #[serde(rename = "@index")]
    index: usize,
    #[serde(rename = "@dependencies")]
    dependencies: Option<String>,
}

impl RawModelDescription {
    fn validate(self) -> Result<ModelDescription, FmuError> {
        if self.fmi_version.trim() != "2.0" {
            return Err(FmuError::UnsupportedFmiVersion {
                found: self.fmi_version,
            });
        }
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

        let unit_definitions = self
            .unit_definitions
            .map(|u| u.units.into_iter().map(|u| u.name).collect::<Vec<_>>());
        let raw_variables = self
            .model_variables
            .ok_or_else(|| {
                invalid(
                    "<fmiModelDescription>",
                    "the <ModelVariables> element is missing",
                )
            })?
            .variables;

        let mut variables = Vec::with_capacity(raw_variables.len());
        let mut by_name = HashMap::with_capacity(raw_variables.len());
        for (i, raw) in raw_variables.into_iter().enumerate() {
            let variable = raw.validate(i + 1, unit_definitions.as_deref())?;
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
            variables.push(variable);
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
            let variable = raw
                .index
                .checked_sub(1)
                .and_then(|k| variables.get(k))
                .ok_or_else(|| {
                    invalid(
                        &location,
                        format!("not an index of ModelVariables (1..={})", variables.len()),
                    )
                })?;
            if variable.causality != Causality::Output {
                return Err(invalid(
                    &location,
                    format!(
                        "variable \"{}\" has causality \"{}\", expected \"output\"",
                        variable.name, variable.causality
                    ),
                ));
            }
            let dependencies = match raw.dependencies {
                None => None,
                Some(text) => {
                    let mut deps = Vec::new();
                    for word in text.split_whitespace() {
                        let d: usize = word
                            .parse()
                            .ok()
                            .filter(|&d| d >= 1 && d <= variables.len())
                            .ok_or_else(|| {
                                invalid(
                                    &location,
                                    format!(
                                        "dependency \"{word}\" is not an index of ModelVariables"
                                    ),
                                )
                            })?;
                        deps.push(d);
                    }
                    Some(deps)
                }
            };
            outputs.push(Unknown {
                index: raw.index,
                dependencies,
            });
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
            model_exchange: self.model_exchange.map(|me| me.model_identifier),
            number_of_event_indicators: self.number_of_event_indicators.unwrap_or(0),
            unit_definitions,
            log_categories: self
                .log_categories
                .map(|c| {
                    c.categories
                        .into_iter()
                        .map(|c| LogCategory {
                            name: c.name,
                            description: c.description,
                        })
                        .collect()
                })
                .unwrap_or_default(),
            default_experiment: self.default_experiment.map(|e| DefaultExperiment {
                start_time: e.start_time,
                stop_time: e.stop_time,
                tolerance: e.tolerance,
                step_size: e.step_size,
            }),
            variables,
            outputs,
            by_name,
        })
    }
}

impl RawScalarVariable {
    fn validate(self, index: usize, units: Option<&[String]>) -> Result<ScalarVariable, FmuError> {
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
        let causality = match self.causality.as_deref() {
            None => Causality::Local,
            Some(text) => Causality::parse(text).ok_or_else(|| {
                invalid(
                    &location,
                    format!(
                        "causality \"{text}\" is not one of {}",
                        list(Causality::ALL)
                    ),
                )
            })?,
        };
        let variability = match self.variability.as_deref() {
            None => Variability::Continuous,
            Some(text) => Variability::parse(text).ok_or_else(|| {
                invalid(
                    &location,
                    format!(
                        "variability \"{text}\" is not one of {}",
                        list(Variability::ALL)
                    ),
                )
            })?,
        };
        let initial = match self.initial.as_deref() {
            None => None,
            Some(text) => Some(Initial::parse(text).ok_or_else(|| {
                invalid(
                    &location,
                    format!("initial \"{text}\" is not one of {}", list(Initial::ALL)),
                )
            })?),
        };
        if !combination_allowed(causality, variability) {
            return Err(invalid(
                &location,
                format!("causality \"{causality}\" with variability \"{variability}\" is not allowed (FMI 2.0 §2.2.7)"),
            ));
        }

        let mut kinds = Vec::with_capacity(1);
        if let Some(r) = self.real {
            if let (Some(unit), Some(units)) = (&r.unit, units) {
                if !units.iter().any(|u| u == unit) {
                    return Err(invalid(
                        &location,
                        format!("unit \"{unit}\" is not defined in <UnitDefinitions>"),
                    ));
                }
            }
            kinds.push(VariableKind::Real {
                start: r.start,
                unit: r.unit,
                nominal: r.nominal,
                min: r.min,
                max: r.max,
                derivative: r.derivative,
            });
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
        if kinds.len() != 1 {
            return Err(invalid(
                &location,
                format!("expected exactly one of <Real>, <Integer>, <Boolean>, <String>, <Enumeration>, found {}", kinds.len()),
            ));
        }
        let kind = kinds.pop().expect("one element");
        Ok(ScalarVariable {
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

fn list<T: fmt::Display>(items: &[T]) -> String {
    items
        .iter()
        .map(|i| format!("\"{i}\""))
        .collect::<Vec<_>>()
        .join(", ")
}
