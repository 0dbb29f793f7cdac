//! System files: the subset of SSP 1.0 (System Structure and
//! Parameterization, Modelica Association 2019) that describes a flat
//! system of FMI 2.0 Co-Simulation FMUs.
//!
//! A system is read from a `SystemStructure.ssd` file (component sources
//! relative to it, e.g. `../dist/LuGre.fmu`) or from an `.ssp` archive (a
//! zip with `SystemStructure.ssd` at its root and the FMUs under
//! `resources/`, unpacked with the checks of [`crate::fmu::archive`]).
//! [`SystemFile::open`] parses it; [`SystemFile::check`] opens the FMUs and
//! checks every name, kind, type and unit against their model descriptions;
//! [`SystemFile::build`] instantiates the [`System`].
//!
//! Supported: one `ssd:System` of `ssd:Component`s of type
//! `application/x-fmu-sharedlibrary`; their `ssd:Connectors` (kind input,
//! output, parameter, calculatedParameter; optional `ssc:Real`/`Integer`/
//! `Boolean`/`String` type, `ssc:Real unit`); `ssd:Connections` between
//! component connectors (output → input; the direction comes from the
//! kinds, as the standard says, not from start/end); `ssd:ParameterBindings`
//! on the system or a component with an inline `ssv:ParameterSet` or a
//! `source` `.ssv` file (`ssv:Real`/`Integer`/`Boolean`/`String`,
//! `prefix`); `ssd:DefaultExperiment` start and stop time; and our own
//! annotation ([`ANNOTATION_TYPE`]) for the step size, the master algorithm
//! and the signals to plot and record, which SSP 1.0 has no place for.
//!
//! Refused with a message (rather than half-supported): nested systems,
//! signal dictionaries, connectors of the system itself, parameter mappings,
//! connection transformations and unit conversion, enumeration and binary
//! values. Deliberately stricter than the standard: a parameter whose name
//! matches no variable is an error (the standard ignores it), since it is
//! almost always a typing mistake.

pub mod pack;
pub(crate) mod xml;

pub use pack::pack;

use crate::fmu::archive::{unpack_requiring, UnpackOptions};
use crate::fmu::model_description::{Causality, ScalarVariable, Variability, VariableKind};
use crate::fmu::Fmu;
use crate::system::{Experiment, ParameterValue, System, SystemError};
use crate::FmuError;
use std::path::{Component as PathPart, Path, PathBuf};
use tempfile::TempDir;
use xml::{Lines, RawParameterBinding, RawParameterSet, SyntaxError};

pub use xml::{NS_SSC, NS_SSD, NS_SSV};

/// The `type` of our `ssc:Annotation` (in `ssd:DefaultExperiment` or at the
/// root of the ssd); its content is one `Simulation` element, conventionally
/// in the namespace [`ANNOTATION_NAMESPACE`].
pub const ANNOTATION_TYPE: &str = "org.friction-fmu.fricsim";
/// The namespace used in the examples for the annotation's content (only
/// the local names are read).
pub const ANNOTATION_NAMESPACE: &str = "urn:friction-fmu:fricsim:1";
/// The MIME type of an FMU component (the default of `Component/@type`).
pub const FMU_TYPE: &str = "application/x-fmu-sharedlibrary";
/// The master algorithms that `master=` may name.
pub use crate::master::NAMES as MASTERS;

/// Why a system file was refused: `location` names the file, the line and
/// the element (`SystemStructure.ssd:12: <Connection …>`), `message` the
/// rule and the value.
#[derive(Debug, thiserror::Error)]
#[error("{location}: {message}")]
pub struct SspError {
    pub location: String,
    pub message: String,
}

/// `Connector/@kind`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConnectorKind {
    Input,
    Output,
    Parameter,
    CalculatedParameter,
}

impl ConnectorKind {
    fn parse(text: &str) -> Option<ConnectorKind> {
        Some(match text {
            "input" => ConnectorKind::Input,
            "output" => ConnectorKind::Output,
            "parameter" => ConnectorKind::Parameter,
            "calculatedParameter" => ConnectorKind::CalculatedParameter,
            _ => return None,
        })
    }

    pub fn as_str(self) -> &'static str {
        match self {
            ConnectorKind::Input => "input",
            ConnectorKind::Output => "output",
            ConnectorKind::Parameter => "parameter",
            ConnectorKind::CalculatedParameter => "calculatedParameter",
        }
    }

    /// The FMI 2.0 causality a connector of this kind stands for.
    fn causality(self) -> Causality {
        match self {
            ConnectorKind::Input => Causality::Input,
            ConnectorKind::Output => Causality::Output,
            ConnectorKind::Parameter => Causality::Parameter,
            ConnectorKind::CalculatedParameter => Causality::CalculatedParameter,
        }
    }
}

/// One `ssd:Connector` of a component.
#[derive(Clone, Debug)]
pub struct ConnectorDef {
    pub name: String,
    pub kind: ConnectorKind,
    /// `Real`, `Integer`, `Boolean`, `String` when the connector gives a type.
    pub type_name: Option<&'static str>,
    pub unit: Option<String>,
    pub location: String,
}

/// One `ssd:Component`.
#[derive(Clone, Debug)]
pub struct ComponentDef {
    pub name: String,
    /// The `source` attribute as written.
    pub source_text: String,
    /// Where it points.
    pub source: PathBuf,
    pub connectors: Vec<ConnectorDef>,
    pub location: String,
}

impl ComponentDef {
    fn connector(&self, name: &str) -> Option<&ConnectorDef> {
        self.connectors.iter().find(|c| c.name == name)
    }
}

/// One `ssd:Connection`, as written (start and end, not yet ordered by data flow).
#[derive(Clone, Debug)]
pub struct ConnectionDef {
    pub start: (Option<String>, String),
    pub end: (Option<String>, String),
    /// Has a transformation element (not supported).
    pub transformation: Option<&'static str>,
    pub location: String,
}

/// A value of a parameter set.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(String),
}

impl Value {
    pub fn type_name(&self) -> &'static str {
        match self {
            Value::Real(_) => "Real",
            Value::Integer(_) => "Integer",
            Value::Boolean(_) => "Boolean",
            Value::String(_) => "String",
        }
    }
}

/// One parameter value, with the component it applies to.
#[derive(Clone, Debug)]
pub struct ParameterDef {
    pub component: String,
    pub variable: String,
    pub value: Value,
    pub unit: Option<String>,
    pub location: String,
}

/// Our annotation: what SSP 1.0 has no place for.
#[derive(Clone, Debug, Default)]
pub struct Settings {
    /// Macro step in seconds.
    pub step_size: Option<f64>,
    /// One of [`MASTERS`].
    pub master: Option<String>,
    /// Signals (`component.variable`) to plot.
    pub plot: Vec<String>,
    /// Variables (`component.variable`) to record besides the outputs.
    pub record: Vec<String>,
    pub location: Option<String>,
}

impl Settings {
    /// The annotation's master algorithm, else `jacobi`.
    pub fn master_or_default(&self) -> String {
        self.master.clone().unwrap_or_else(|| "jacobi".to_string())
    }
}

/// A parsed system file. For an `.ssp`, the unpacked archive lives as long
/// as this value.
#[derive(Debug)]
pub struct SystemFile {
    /// The file given to [`SystemFile::open`].
    pub path: PathBuf,
    /// How the ssd is named in messages (`x.ssp!/SystemStructure.ssd`).
    pub ssd: String,
    /// `SystemStructureDescription/@name`.
    pub name: String,
    pub components: Vec<ComponentDef>,
    pub connections: Vec<ConnectionDef>,
    /// In the order they apply: component bindings, then system bindings
    /// (which take precedence, SSP 1.0 §5.3.5), each in document order.
    pub parameters: Vec<ParameterDef>,
    pub start_time: Option<f64>,
    pub stop_time: Option<f64>,
    pub settings: Settings,
    /// Whether sources must stay inside the base directory (an archive).
    in_archive: bool,
    base: PathBuf,
    /// The `.ssv` files of the parameter bindings (outside an archive).
    parameter_files: Vec<PathBuf>,
    _unpacked: Option<TempDir>,
}

/// A connection checked against the FMUs: from an output to an input.
#[derive(Clone, Debug)]
pub struct CheckedConnection {
    pub from: String,
    pub to: String,
    pub location: String,
}

/// The system file with its FMUs opened and everything checked.
pub struct CheckedSystem {
    pub fmus: Vec<(String, Fmu)>,
    pub connections: Vec<CheckedConnection>,
}

fn error(location: impl Into<String>, message: impl Into<String>) -> SspError {
    SspError {
        location: location.into(),
        message: message.into(),
    }
}

/// `<Name a="x" b="y">` for messages, with the attributes that are present.
fn element(name: &str, attributes: &[(&str, &Option<String>)]) -> String {
    let mut s = format!("<{name}");
    for (k, v) in attributes {
        if let Some(v) = v {
            s.push_str(&format!(" {k}=\"{v}\""));
        }
    }
    s.push('>');
    s
}

/// `a, b, c`, or `none`.
fn list(items: &[String]) -> String {
    if items.is_empty() {
        "none".to_string()
    } else {
        items.join(", ")
    }
}

/// Variable names for a message: runs of `name[1]`, `name[2]`, … are
/// shown as `name[1..n]` so that a table does not bury the other names.
fn compact_names<'a>(names: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut run: Option<(String, usize, usize)> = None;
    let flush = |run: &mut Option<(String, usize, usize)>, out: &mut Vec<String>| {
        if let Some((base, first, last)) = run.take() {
            if first == last {
                out.push(format!("{base}[{first}]"));
            } else {
                out.push(format!("{base}[{first}..{last}]"));
            }
        }
    };
    for name in names {
        let indexed = name
            .strip_suffix(']')
            .and_then(|s| s.rsplit_once('['))
            .and_then(|(base, i)| i.parse::<usize>().ok().map(|i| (base.to_string(), i)));
        match (indexed, &mut run) {
            (Some((base, i)), Some((b, _, last))) if *b == base && i == *last + 1 => *last = i,
            (Some((base, i)), _) => {
                flush(&mut run, &mut out);
                run = Some((base, i, i));
            }
            (None, _) => {
                flush(&mut run, &mut out);
                out.push(name.to_string());
            }
        }
    }
    flush(&mut run, &mut out);
    out
}

/// The names of `fmu`'s variables of causality `causality`, compacted.
fn names_with(fmu: &Fmu, causality: Causality) -> String {
    list(&compact_names(
        fmu.description()
            .variables
            .iter()
            .filter(|v| v.causality == causality)
            .map(|v| v.name.as_str()),
    ))
}

fn parse_number(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|x| x.is_finite())
}

impl SystemFile {
    /// The files a run of this system reads, each with what it is: the
    /// system file, and outside an archive the FMUs and `.ssv` files it
    /// points at (an archive's are unpacked copies).
    pub fn files_read(&self) -> Vec<(&'static str, &Path)> {
        let mut files = vec![("the system file", self.path.as_path())];
        if !self.in_archive {
            files.extend(
                self.components
                    .iter()
                    .map(|c| ("the FMU", c.source.as_path())),
            );
            files.extend(
                self.parameter_files
                    .iter()
                    .map(|p| ("the parameter file", p.as_path())),
            );
        }
        files
    }

    /// Read a `.ssd` file or an `.ssp` archive (by its extension).
    pub fn open(path: impl AsRef<Path>) -> Result<SystemFile, SspError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let is_archive = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ssp"));
        if !path.is_file() {
            return Err(error(shown, "no such file"));
        }
        if is_archive {
            let dir = unpack_requiring(path, &UnpackOptions::default(), "SystemStructure.ssd")
                .map_err(|e| error(shown.clone(), format!("cannot unpack the archive: {e}")))?;
            let ssd = dir.path().join("SystemStructure.ssd");
            let name = format!("{shown}!/SystemStructure.ssd");
            let base = dir.path().to_path_buf();
            let mut file = SystemFile::parse_file(path, &ssd, name, base, true)?;
            file._unpacked = Some(dir);
            Ok(file)
        } else {
            let base = path
                .parent()
                .map(Path::to_path_buf)
                .unwrap_or_else(|| PathBuf::from("."));
            SystemFile::parse_file(path, path, shown, base, false)
        }
    }

    fn parse_file(
        path: &Path,
        ssd: &Path,
        shown: String,
        base: PathBuf,
        in_archive: bool,
    ) -> Result<SystemFile, SspError> {
        let text = read_text(ssd, &shown)?;
        let mut file = SystemFile {
            path: path.to_path_buf(),
            ssd: shown,
            name: String::new(),
            components: Vec::new(),
            connections: Vec::new(),
            parameters: Vec::new(),
            start_time: None,
            stop_time: None,
            settings: Settings::default(),
            in_archive,
            base,
            parameter_files: Vec::new(),
            _unpacked: None,
        };
        file.parse(&text)?;
        Ok(file)
    }

    /// Parse the text of an ssd (sources relative to `base`).
    fn parse(&mut self, text: &str) -> Result<(), SspError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let syntax =
            |e: SyntaxError| error(format!("{}:{}:{}", self.ssd, e.line, e.column), e.message);
        let (_, lines) =
            xml::first_pass(text, "SystemStructureDescription", NS_SSD).map_err(syntax)?;
        let raw: xml::RawSsd = xml::deserialize(text).map_err(syntax)?;
        let at = |name: &str, k: usize, what: String| match lines.of(name, k) {
            Some(line) => format!("{}:{line}: {what}", self.ssd),
            None => format!("{}: {what}", self.ssd),
        };
        let root = element("SystemStructureDescription", &[("name", &raw.name)]);
        self.name = raw.name.clone().unwrap_or_default();
        let Some(system) = raw.system else {
            return Err(error(
                at("SystemStructureDescription", 0, root),
                "it has no <ssd:System> element",
            ));
        };
        let system_element = element("System", &[("name", &system.name)]);

        // connectors of the system itself: there is no outside to connect them to
        if let Some(c) = system.connectors.as_ref().and_then(|c| c.list.first()) {
            return Err(error(
                at("Connector", 0, element("Connector", &[("name", &c.name), ("kind", &c.kind)])),
                format!(
                    "connectors of the system {system_element} are not supported: a system file here is the top level, with nothing outside it; drive unconnected inputs with `fricsim run --input`"
                ),
            ));
        }

        let mut connector_k = 0usize;
        let mut component_k = 0usize;
        let mut binding_k = 0usize;
        let mut parameter_k = 0usize;
        let mut component_bindings = Vec::new();
        if let Some(elements) = system.elements {
            for item in elements.items {
                let c = match item {
                    xml::RawElement::Component(c) => c,
                    xml::RawElement::System(s) => {
                        return Err(error(
                            at("System", 1, element("System", &[("name", &s.name)])),
                            "nested systems are not supported: put every component in the one top-level system",
                        ))
                    }
                    xml::RawElement::SignalDictionaryReference(s) => {
                        return Err(error(
                            at(
                                "SignalDictionaryReference",
                                0,
                                element("SignalDictionaryReference", &[("name", &s.name)]),
                            ),
                            "signal dictionaries are not supported",
                        ))
                    }
                };
                let shown = element("Component", &[("name", &c.name), ("source", &c.source)]);
                let location = at("Component", component_k, shown);
                component_k += 1;
                let name = c
                    .name
                    .clone()
                    .filter(|n| !n.is_empty())
                    .ok_or_else(|| error(&location, "the name attribute is missing"))?;
                if name.contains('.') {
                    return Err(error(
                        &location,
                        format!("component name `{name}` contains a `.`, which separates component and variable in `component.variable`"),
                    ));
                }
                if let Some(first) = self.components.iter().find(|x| x.name == name) {
                    return Err(error(
                        &location,
                        format!(
                            "component name `{name}` is already used by {}",
                            first.location
                        ),
                    ));
                }
                let kind = c.kind.as_deref().unwrap_or(FMU_TYPE);
                if kind != FMU_TYPE {
                    return Err(error(
                        &location,
                        format!("type=\"{kind}\" is not supported: only FMUs ({FMU_TYPE})"),
                    ));
                }
                if let Some(imp) = c.implementation.as_deref() {
                    if imp != "any" && imp != "CoSimulation" {
                        return Err(error(
                            &location,
                            format!("implementation=\"{imp}\" is not supported: fricsim runs FMUs as Co-Simulation (\"CoSimulation\" or \"any\")"),
                        ));
                    }
                }
                let source_text = c
                    .source
                    .clone()
                    .ok_or_else(|| error(&location, "the source attribute is missing"))?;
                let source = self
                    .resolve(&source_text)
                    .map_err(|m| error(&location, format!("source=\"{source_text}\": {m}")))?;
                let mut connectors: Vec<ConnectorDef> = Vec::new();
                for raw in c.connectors.map(|c| c.list).unwrap_or_default() {
                    let shown = element("Connector", &[("name", &raw.name), ("kind", &raw.kind)]);
                    let location = at(
                        "Connector",
                        connector_k,
                        format!("component `{name}`: {shown}"),
                    );
                    connector_k += 1;
                    let cname = raw
                        .name
                        .clone()
                        .ok_or_else(|| error(&location, "the name attribute is missing"))?;
                    if connectors.iter().any(|x| x.name == cname) {
                        return Err(error(
                            &location,
                            format!("connector `{cname}` is declared twice"),
                        ));
                    }
                    let kind_text = raw.kind.clone().unwrap_or_default();
                    let kind = ConnectorKind::parse(&kind_text).ok_or_else(|| {
                        error(
                            &location,
                            format!("kind=\"{kind_text}\" is not supported (input, output, parameter, calculatedParameter)"),
                        )
                    })?;
                    let type_name = if raw.real.is_some() {
                        Some("Real")
                    } else if raw.integer.is_some() {
                        Some("Integer")
                    } else if raw.boolean.is_some() {
                        Some("Boolean")
                    } else if raw.string.is_some() {
                        Some("String")
                    } else if raw.enumeration.is_some() || raw.binary.is_some() {
                        return Err(error(
                            &location,
                            "Enumeration and Binary connectors are not supported",
                        ));
                    } else {
                        None
                    };
                    connectors.push(ConnectorDef {
                        name: cname,
                        kind,
                        type_name,
                        unit: raw.real.and_then(|r| r.unit),
                        location,
                    });
                }
                if let Some(bindings) = c.parameter_bindings {
                    for b in bindings.list {
                        component_bindings.push((Some(name.clone()), b, binding_k));
                        binding_k += 1;
                    }
                }
                self.components.push(ComponentDef {
                    name,
                    source_text,
                    source,
                    connectors,
                    location,
                });
            }
        }
        if self.components.is_empty() {
            return Err(error(
                at("System", 0, system_element),
                "the system has no components",
            ));
        }

        // Bindings: the system's come first in the document (its
        // ParameterBindings precede its Elements), but they apply last.
        let mut system_bindings = Vec::new();
        if let Some(bindings) = system.parameter_bindings {
            for b in bindings.list {
                system_bindings.push((None, b, 0));
            }
        }
        // renumber in document order: system bindings first
        let n_system = system_bindings.len();
        for (k, b) in system_bindings.iter_mut().enumerate() {
            b.2 = k;
        }
        for b in component_bindings.iter_mut() {
            b.2 += n_system;
        }
        // inline parameters are numbered in document order too
        let mut ordered: Vec<_> = system_bindings
            .into_iter()
            .chain(component_bindings)
            .collect();
        let mut inline_first = Vec::with_capacity(ordered.len());
        for (_, b, _) in &ordered {
            inline_first.push(parameter_k);
            parameter_k += b
                .values
                .as_ref()
                .and_then(|v| v.set.as_ref())
                .and_then(|s| s.parameters.as_ref())
                .map_or(0, |p| p.list.len());
        }
        let mut applied: Vec<(Option<String>, Vec<ParameterDef>)> = Vec::new();
        for ((owner, b, k), first_parameter) in ordered.drain(..).zip(inline_first) {
            let shown = element(
                "ParameterBinding",
                &[("source", &b.source), ("prefix", &b.prefix)],
            );
            let owner_text = match &owner {
                Some(c) => format!("component `{c}`: "),
                None => String::new(),
            };
            let location = at("ParameterBinding", k, format!("{owner_text}{shown}"));
            if let (Some(source), false) = (&b.source, self.in_archive) {
                if let Ok(path) = self.resolve(source) {
                    self.parameter_files.push(path);
                }
            }
            let params = self.binding(owner.as_deref(), b, &location, &lines, first_parameter)?;
            applied.push((owner, params));
        }
        // component bindings first, then the system's: a system binding wins
        let (system_params, component_params): (Vec<_>, Vec<_>) =
            applied.into_iter().partition(|(owner, _)| owner.is_none());
        for (_, params) in component_params.into_iter().chain(system_params) {
            self.parameters.extend(params);
        }

        if let Some(connections) = system.connections {
            for (k, c) in connections.list.into_iter().enumerate() {
                let shown = element(
                    "Connection",
                    &[
                        ("startElement", &c.start_element),
                        ("startConnector", &c.start_connector),
                        ("endElement", &c.end_element),
                        ("endConnector", &c.end_connector),
                    ],
                );
                let location = at("Connection", k, shown);
                let transformation = if c.linear.is_some() {
                    Some("LinearTransformation")
                } else if c.boolean_mapping.is_some() {
                    Some("BooleanMappingTransformation")
                } else if c.integer_mapping.is_some() {
                    Some("IntegerMappingTransformation")
                } else if c.enumeration_mapping.is_some() {
                    Some("EnumerationMappingTransformation")
                } else {
                    None
                };
                let start = c
                    .start_connector
                    .ok_or_else(|| error(&location, "the startConnector attribute is missing"))?;
                let end = c
                    .end_connector
                    .ok_or_else(|| error(&location, "the endConnector attribute is missing"))?;
                self.connections.push(ConnectionDef {
                    start: (c.start_element, start),
                    end: (c.end_element, end),
                    transformation,
                    location,
                });
            }
        }

        if let Some(e) = &raw.default_experiment {
            let location = at(
                "DefaultExperiment",
                0,
                element(
                    "DefaultExperiment",
                    &[("startTime", &e.start_time), ("stopTime", &e.stop_time)],
                ),
            );
            let time = |name: &str, text: &Option<String>| -> Result<Option<f64>, SspError> {
                match text {
                    None => Ok(None),
                    Some(t) => parse_number(t).map(Some).ok_or_else(|| {
                        error(&location, format!("{name}=\"{t}\" is not a finite number"))
                    }),
                }
            };
            self.start_time = time("startTime", &e.start_time)?;
            self.stop_time = time("stopTime", &e.stop_time)?;
            if let (Some(a), Some(b)) = (self.start_time, self.stop_time) {
                if b <= a {
                    return Err(error(
                        &location,
                        format!("stopTime {b} is not after startTime {a}"),
                    ));
                }
            }
        }

        // our annotation, in DefaultExperiment or at the root
        let annotations = raw
            .default_experiment
            .into_iter()
            .flat_map(|e| e.annotations)
            .chain(raw.annotations)
            .flat_map(|a| a.list);
        let mut found: Option<(String, xml::RawSimulation)> = None;
        for (k_all, a) in annotations.enumerate() {
            // annotations are numbered in document order; DefaultExperiment precedes the root's
            let location = at(
                "Annotation",
                k_all,
                element("ssc:Annotation", &[("type", &a.kind)]),
            );
            if a.kind.as_deref() != Some(ANNOTATION_TYPE) {
                continue; // another tool's annotation
            }
            if let Some((first, _)) = &found {
                return Err(error(
                    &location,
                    format!("a second {ANNOTATION_TYPE} annotation (the first is at {first})"),
                ));
            }
            let simulation = a.simulation.ok_or_else(|| {
                error(
                    &location,
                    format!("the {ANNOTATION_TYPE} annotation has no <Simulation> element"),
                )
            })?;
            found = Some((location, simulation));
        }
        if let Some((location, s)) = found {
            let shown = format!(
                "{location}: {}",
                element(
                    "Simulation",
                    &[("stepSize", &s.step_size), ("master", &s.master)]
                )
            );
            if let Some(t) = &s.step_size {
                let h = parse_number(t).filter(|h| *h > 0.0).ok_or_else(|| {
                    error(&shown, format!("stepSize=\"{t}\" is not a positive number"))
                })?;
                self.settings.step_size = Some(h);
            }
            if let Some(m) = &s.master {
                if !MASTERS.contains(&m.as_str()) {
                    return Err(error(
                        &shown,
                        format!("master=\"{m}\" is not one of {}", MASTERS.join(", ")),
                    ));
                }
                self.settings.master = Some(m.clone());
            }
            for item in s.items {
                let (what, signal) = match item {
                    xml::RawSimulationItem::Plot(p) => ("Plot", p.signal),
                    xml::RawSimulationItem::Record(r) => ("Record", r.signal),
                };
                let signal = signal.ok_or_else(|| {
                    error(
                        &shown,
                        format!("a <{what}> element has no signal attribute"),
                    )
                })?;
                let list = if what == "Plot" {
                    &mut self.settings.plot
                } else {
                    &mut self.settings.record
                };
                list.push(signal);
            }
            self.settings.location = Some(location);
        }
        Ok(())
    }

    /// The parameters of one binding (inline set or `.ssv` source) of the
    /// component `owner` (`None`: of the system); `location` names the
    /// binding, `first_parameter` is the index of its first inline
    /// `Parameter` element in the ssd.
    fn binding(
        &self,
        owner: Option<&str>,
        b: RawParameterBinding,
        location: &str,
        lines: &Lines,
        first_parameter: usize,
    ) -> Result<Vec<ParameterDef>, SspError> {
        if let Some(kind) = b.kind.as_deref() {
            if kind != "application/x-ssp-parameter-set" {
                return Err(error(
                    location,
                    format!(
                        "type=\"{kind}\" is not supported: only application/x-ssp-parameter-set"
                    ),
                ));
            }
        }
        if b.mapping.is_some() {
            return Err(error(location, "parameter mappings (<ssd:ParameterMapping>) are not supported: use the variable names in the parameter set"));
        }
        if let Some(base) = b.source_base.as_deref() {
            if base != "SSD" {
                return Err(error(location, format!("sourceBase=\"{base}\" is not supported: sources are relative to the ssd (\"SSD\")")));
            }
        }
        let prefix = b.prefix.clone().unwrap_or_default();
        let inline = b.values.and_then(|v| v.set);
        let (set, file_lines, file_shown) = match (&b.source, inline) {
            (Some(_), Some(_)) => {
                return Err(error(
                    location,
                    "the binding has both a source and inline ParameterValues; give one",
                ))
            }
            (None, None) => {
                return Err(error(
                    location,
                    "the binding has neither a source nor inline ParameterValues",
                ))
            }
            (None, Some(set)) => (set, None, None),
            (Some(source), None) => {
                let path = self
                    .resolve(source)
                    .map_err(|m| error(location, format!("source=\"{source}\": {m}")))?;
                let shown = if self.in_archive {
                    format!("{}!/{}", self.path.display(), source)
                } else {
                    path.display().to_string()
                };
                if !path.is_file() {
                    return Err(error(
                        location,
                        format!("source=\"{source}\": {shown} does not exist"),
                    ));
                }
                let (set, lines) = read_parameter_set(&path, &shown)?;
                (set, Some(lines), Some(shown))
            }
        };
        self.parameter_set(owner, set, &prefix, |k, shown| {
            match (&file_lines, &file_shown) {
                (Some(l), Some(f)) => match l.of("Parameter", k) {
                    Some(line) => format!("{f}:{line}: {shown}"),
                    None => format!("{f}: {shown}"),
                },
                _ => match lines.of("Parameter", first_parameter + k) {
                    Some(line) => format!("{}:{line}: {shown}", self.ssd),
                    None => format!("{}: {shown}", self.ssd),
                },
            }
        })
    }

    /// The parameter values of an SSP parameter-value file (`.ssv`, an
    /// `ssv:ParameterSet`) at `path`, named `component.variable` as in a
    /// binding of the system: start values for a run of this system
    /// (`fricsim run --start-values`). The values are not checked against
    /// the FMUs here (see [`crate::run::check_start_value`]).
    pub fn parameter_values_file(&self, path: &Path) -> Result<Vec<ParameterDef>, SspError> {
        let shown = path.display().to_string();
        let (set, lines) = read_parameter_set(path, &shown)?;
        self.parameter_set(None, set, "", |k, what| match lines.of("Parameter", k) {
            Some(line) => format!("{shown}:{line}: {what}"),
            None => format!("{shown}: {what}"),
        })
    }

    /// The parameters of `set` for the component `owner` (`None`: of the
    /// system, named `component.variable`), their names after `prefix`;
    /// `locate(k, element)` says where parameter `k` is, for messages.
    fn parameter_set(
        &self,
        owner: Option<&str>,
        set: RawParameterSet,
        prefix: &str,
        locate: impl Fn(usize, &str) -> String,
    ) -> Result<Vec<ParameterDef>, SspError> {
        let mut out = Vec::new();
        for (k, p) in set
            .parameters
            .map(|p| p.list)
            .unwrap_or_default()
            .into_iter()
            .enumerate()
        {
            let shown = element("Parameter", &[("name", &p.name)]);
            let here = locate(k, &shown);
            let name = p
                .name
                .clone()
                .ok_or_else(|| error(&here, "the name attribute is missing"))?;
            let full = format!("{prefix}{name}");
            let (kind, raw) = if let Some(v) = p.real {
                ("Real", v)
            } else if let Some(v) = p.integer {
                ("Integer", v)
            } else if let Some(v) = p.boolean {
                ("Boolean", v)
            } else if let Some(v) = p.string {
                ("String", v)
            } else if p.enumeration.is_some() || p.binary.is_some() {
                return Err(error(
                    &here,
                    "Enumeration and Binary parameter values are not supported",
                ));
            } else {
                return Err(error(&here, "the parameter has no value element (ssv:Real, ssv:Integer, ssv:Boolean or ssv:String)"));
            };
            let text = raw
                .value
                .clone()
                .ok_or_else(|| error(&here, format!("<ssv:{kind}> has no value attribute")))?;
            let value = match kind {
                "Real" => Value::Real(parse_number(&text).ok_or_else(|| {
                    error(
                        &here,
                        format!("<ssv:Real value=\"{text}\">: not a finite number"),
                    )
                })?),
                "Integer" => Value::Integer(text.trim().parse().map_err(|_| {
                    error(
                        &here,
                        format!("<ssv:Integer value=\"{text}\">: not a 32-bit integer"),
                    )
                })?),
                "Boolean" => Value::Boolean(match text.trim() {
                    "true" | "1" => true,
                    "false" | "0" => false,
                    _ => {
                        return Err(error(
                            &here,
                            format!("<ssv:Boolean value=\"{text}\">: not true, false, 1 or 0"),
                        ))
                    }
                }),
                _ => Value::String(text),
            };
            // a component binding names the component's variables; a system
            // binding names `component.variable`
            let (component, variable) = match owner {
                Some(c) => (c.to_string(), full),
                None => {
                    let found = self
                        .components
                        .iter()
                        .filter(|c| full.starts_with(&format!("{}.", c.name)))
                        .max_by_key(|c| c.name.len());
                    match found {
                        Some(c) => (c.name.clone(), full[c.name.len() + 1..].to_string()),
                        None => {
                            let names: Vec<String> =
                                self.components.iter().map(|c| c.name.clone()).collect();
                            return Err(error(
                                &here,
                                format!(
                                    "parameter `{full}` of a system binding names no component: system-level names are component.variable (components: {})",
                                    list(&names)
                                ),
                            ));
                        }
                    }
                }
            };
            out.push(ParameterDef {
                component,
                variable,
                value,
                unit: raw.unit,
                location: here,
            });
        }
        Ok(out)
    }

    /// Where a `source` attribute points: a relative reference resolved
    /// against the ssd's directory (`%XX` escapes decoded). Inside an
    /// archive it must stay inside the archive.
    pub fn resolve(&self, source: &str) -> Result<PathBuf, String> {
        let scheme = source.split_once(':').map(|(s, _)| s).filter(|s| {
            s.len() > 1
                && s.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
                && s.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
        });
        if let Some(s) = scheme {
            return Err(format!(
                "URI scheme `{s}:` is not supported: give a path relative to the ssd"
            ));
        }
        if source.is_empty() {
            return Err("empty".to_string());
        }
        let decoded = percent_decode(source).ok_or("a `%` escape is not two hex digits")?;
        let relative = Path::new(&decoded);
        let escapes = relative.is_absolute()
            || relative
                .components()
                .any(|c| matches!(c, PathPart::ParentDir));
        if self.in_archive && escapes {
            return Err(
                "a source inside an .ssp must stay inside the archive (no absolute path, no `..`)"
                    .to_string(),
            );
        }
        Ok(self.base.join(relative))
    }

    /// The SystemStructure.ssd itself: the file given, or the one unpacked
    /// from the archive.
    pub fn ssd_path(&self) -> PathBuf {
        if self.in_archive {
            self.base.join("SystemStructure.ssd")
        } else {
            self.path.clone()
        }
    }

    /// Open each component's FMU and check the system against the model
    /// descriptions: connectors, connections, parameters, settings.
    pub fn check(&self) -> Result<CheckedSystem, SspError> {
        // unpacked and loaded at the same time, each on a thread of its
        // own (inflating a binary is most of an FMU's opening); the
        // errors are then taken in the components' order, as one by one
        let opened = open_all(self.components.iter().map(|c| &c.source));
        let mut fmus: Vec<(String, Fmu)> = Vec::new();
        for (c, opened) in self.components.iter().zip(opened) {
            if !c.source.is_file() {
                let shown = if self.in_archive {
                    format!("{}!/{}", self.path.display(), c.source_text)
                } else {
                    c.source.display().to_string()
                };
                return Err(error(
                    &c.location,
                    format!("component `{}`: FMU file {shown} does not exist", c.name),
                ));
            }
            let fmu = opened.map_err(|e| {
                error(
                    &c.location,
                    format!(
                        "component `{}`: cannot import {}: {e}",
                        c.name, c.source_text
                    ),
                )
            })?;
            for k in &c.connectors {
                check_connector(c, k, &fmu)?;
            }
            fmus.push((c.name.clone(), fmu));
        }
        let fmu_of = |name: &str| fmus.iter().position(|(n, _)| n == name);
        let names: Vec<String> = self.components.iter().map(|c| c.name.clone()).collect();

        let mut connections: Vec<CheckedConnection> = Vec::new();
        for conn in &self.connections {
            let end_of = |(element, connector): &(Option<String>, String)| -> Result<(usize, &ConnectorDef), SspError> {
                let Some(element) = element else {
                    return Err(error(
                        &conn.location,
                        format!("connector `{connector}` of the system itself: connections to the system's own connectors are not supported (name a component in startElement/endElement)"),
                    ));
                };
                let i = fmu_of(element).ok_or_else(|| {
                    error(&conn.location, format!("no component `{element}` (components: {})", list(&names)))
                })?;
                let c = &self.components[i];
                let k = c.connector(connector).ok_or_else(|| {
                    let declared: Vec<String> = c.connectors.iter().map(|k| k.name.clone()).collect();
                    let hint = if fmus[i].1.variable(connector).is_ok() {
                        format!("; {} has a variable `{connector}`: declare it in the component's <ssd:Connectors>", c.source_text)
                    } else {
                        format!(
                            "; {} has no variable `{connector}` either (inputs: {}; outputs: {})",
                            c.source_text,
                            names_with(&fmus[i].1, Causality::Input),
                            names_with(&fmus[i].1, Causality::Output)
                        )
                    };
                    error(
                        &conn.location,
                        format!("component `{element}` has no connector `{connector}` (its connectors: {}){hint}", list(&declared)),
                    )
                })?;
                Ok((i, k))
            };
            if let Some(t) = conn.transformation {
                return Err(error(
                    &conn.location,
                    format!("<ssc:{t}> on a connection is not supported: connect equal quantities"),
                ));
            }
            let (si, sk) = end_of(&conn.start)?;
            let (ei, ek) = end_of(&conn.end)?;
            let port =
                |i: usize, k: &ConnectorDef| format!("{}.{}", self.components[i].name, k.name);
            let (from, to, (fi, fk), (ti, tk)) = match (sk.kind, ek.kind) {
                (ConnectorKind::Output, ConnectorKind::Input) => (port(si, sk), port(ei, ek), (si, sk), (ei, ek)),
                // start and end do not imply a direction (SSP 1.0 §5.3.4)
                (ConnectorKind::Input, ConnectorKind::Output) => (port(ei, ek), port(si, sk), (ei, ek), (si, sk)),
                (a, b) => {
                    return Err(error(
                        &conn.location,
                        format!(
                            "connects {} `{}` to {} `{}`: a connection goes from an output to an input{}",
                            a.as_str(),
                            port(si, sk),
                            b.as_str(),
                            port(ei, ek),
                            if a == b && a == ConnectorKind::Output { " (two outputs cannot drive each other)" } else { "" }
                        ),
                    ))
                }
            };
            let var = |i: usize, k: &ConnectorDef| {
                fmus[i]
                    .1
                    .variable(&k.name)
                    .expect("checked with the connectors")
                    .clone()
            };
            let (fv, tv) = (var(fi, fk), var(ti, tk));
            for (p, v) in [(&from, &fv), (&to, &tv)] {
                if !matches!(v.kind, VariableKind::Real { .. }) {
                    return Err(error(
                        &conn.location,
                        format!(
                            "`{p}` is a {} variable: only Real variables can be connected",
                            v.kind.type_name()
                        ),
                    ));
                }
            }
            let unit_of = |k: &ConnectorDef, v: &ScalarVariable| {
                k.unit.clone().or_else(|| v.kind.unit().map(str::to_string))
            };
            let (fu, tu) = (unit_of(fk, &fv), unit_of(tk, &tv));
            // (a side without a unit connects with a warning, which the
            // built system carries: `System::warnings`)
            if let Err(e) =
                crate::system::connection_units(&from, fu.as_deref(), &to, tu.as_deref())
            {
                return Err(error(&conn.location, e));
            }
            if let Some(first) = connections.iter().find(|c| c.to == to) {
                return Err(error(
                    &conn.location,
                    format!("input `{to}` is already connected (from `{}` by {}): an input has one source", first.from, first.location),
                ));
            }
            connections.push(CheckedConnection {
                from,
                to,
                location: conn.location.clone(),
            });
        }

        for p in &self.parameters {
            let i = fmu_of(&p.component).ok_or_else(|| {
                error(
                    &p.location,
                    format!(
                        "no component `{}` (components: {})",
                        p.component,
                        list(&names)
                    ),
                )
            })?;
            check_parameter(p, &self.components[i], &fmus[i].1)?;
        }

        if let Some(location) = &self.settings.location {
            for s in self.settings.plot.iter().chain(&self.settings.record) {
                check_signal(s, &fmus, &names).map_err(|m| error(location, m))?;
            }
        }
        Ok(CheckedSystem { fmus, connections })
    }

    /// Check, then instantiate the system with its parameters and
    /// connections, set up to start at `start`.
    pub fn build(&self, start: f64) -> Result<System, SspError> {
        self.build_with(start, &[])
    }

    /// [`SystemFile::build`] with `overrides` (`component.variable`, value)
    /// set after the file's own parameter values, so that they win: one
    /// point of a parameter sweep (`fricsim sweep`).
    pub fn build_with(
        &self,
        experiment: impl Into<Experiment>,
        overrides: &[(String, ParameterValue)],
    ) -> Result<System, SspError> {
        self.instantiate(&self.check()?, experiment, overrides)
    }

    /// [`SystemFile::build_with`] on FMUs already opened and checked by
    /// [`SystemFile::check`]: new instances of the same loaded FMUs, so
    /// that repeated runs (`fricsim sweep`) unpack and load nothing again.
    pub fn instantiate(
        &self,
        checked: &CheckedSystem,
        experiment: impl Into<Experiment>,
        overrides: &[(String, ParameterValue)],
    ) -> Result<System, SspError> {
        let parameters: Vec<(String, ParameterValue)> = self
            .parameters
            .iter()
            .map(|p| {
                let v = match &p.value {
                    Value::Real(x) => ParameterValue::Number(*x),
                    Value::Integer(i) => ParameterValue::Number(*i as f64),
                    Value::Boolean(b) => ParameterValue::Number(if *b { 1.0 } else { 0.0 }),
                    Value::String(s) => ParameterValue::Text(s.clone()),
                };
                (format!("{}.{}", p.component, p.variable), v)
            })
            .chain(overrides.iter().cloned())
            .collect();
        let connections: Vec<(String, String)> = checked
            .connections
            .iter()
            .map(|c| (c.from.clone(), c.to.clone()))
            .collect();
        let mut system =
            System::from_fmus(checked.fmus.clone(), &parameters, &connections, experiment)
                .map_err(|e| error(&self.ssd, system_error(e)))?;
        for s in self.settings.record.iter().chain(&self.settings.plot) {
            system.record(s).map_err(|e| {
                error(
                    self.settings.location.as_deref().unwrap_or(&self.ssd),
                    system_error(e),
                )
            })?;
        }
        Ok(system)
    }
}

fn system_error(e: SystemError) -> String {
    e.to_string()
}

/// A `component.variable` of the annotation: the component exists and has
/// a variable of that name that can be recorded (not a String).
fn check_signal(signal: &str, fmus: &[(String, Fmu)], names: &[String]) -> Result<(), String> {
    let (c, v) = signal
        .split_once('.')
        .ok_or_else(|| format!("signal `{signal}` is not of the form component.variable"))?;
    let (_, fmu) = fmus.iter().find(|(n, _)| n == c).ok_or_else(|| {
        format!(
            "signal `{signal}`: no component `{c}` (components: {})",
            list(names)
        )
    })?;
    let var = fmu.variable(v).map_err(|_| {
        format!(
            "signal `{signal}`: `{c}` has no variable `{v}` (outputs: {}; inputs: {})",
            names_with(fmu, Causality::Output),
            names_with(fmu, Causality::Input)
        )
    })?;
    if matches!(var.kind, VariableKind::String { .. }) {
        return Err(format!(
            "signal `{signal}` is a String variable; only Real, Integer, Enumeration and Boolean variables are recorded and plotted"
        ));
    }
    Ok(())
}

/// A connector against its FMU variable: it exists, the causality is the
/// kind, the type and the unit agree.
fn check_connector(c: &ComponentDef, k: &ConnectorDef, fmu: &Fmu) -> Result<(), SspError> {
    let var = fmu.variable(&k.name).map_err(|_| {
        error(
            &k.location,
            format!(
                "{} has no variable `{}` ({}s: {})",
                c.source_text,
                k.name,
                k.kind.as_str(),
                names_with(fmu, k.kind.causality())
            ),
        )
    })?;
    if var.causality != k.kind.causality() {
        return Err(error(
            &k.location,
            format!(
                "kind=\"{}\", but `{}` in {} has causality \"{}\"",
                k.kind.as_str(),
                k.name,
                c.source_text,
                var.causality
            ),
        ));
    }
    if let Some(t) = k.type_name {
        if t != var.kind.type_name() {
            return Err(error(
                &k.location,
                format!(
                    "the connector is ssc:{t}, but `{}` in {} is {}",
                    k.name,
                    c.source_text,
                    var.kind.type_name()
                ),
            ));
        }
    }
    if let Some(u) = &k.unit {
        match var.kind.unit() {
            Some(declared) if declared == u => {}
            declared => {
                return Err(error(
                    &k.location,
                    format!(
                        "unit mismatch: the connector has unit `{u}`, `{}` in {} declares {}",
                        k.name,
                        c.source_text,
                        declared.map_or("no unit".to_string(), |d| format!("unit `{d}`"))
                    ),
                ))
            }
        }
    }
    Ok(())
}

/// A parameter value against its FMU variable: it exists, may be set
/// before initialization (a parameter or an input, not constant), and the
/// type and unit agree.
fn check_parameter(p: &ParameterDef, c: &ComponentDef, fmu: &Fmu) -> Result<(), SspError> {
    let var = fmu.variable(&p.variable).map_err(|_| {
        error(
            &p.location,
            format!(
                "component `{}` ({}) has no variable `{}` (parameters: {}; inputs: {})",
                c.name,
                c.source_text,
                p.variable,
                names_with(fmu, Causality::Parameter),
                names_with(fmu, Causality::Input)
            ),
        )
    })?;
    let settable = matches!(var.causality, Causality::Parameter | Causality::Input)
        && var.variability != Variability::Constant;
    if !settable {
        return Err(error(
            &p.location,
            format!(
                "`{}.{}` has causality \"{}\" and variability \"{}\": only parameters and inputs can be given values",
                c.name, p.variable, var.causality, var.variability
            ),
        ));
    }
    let expected = match &var.kind {
        VariableKind::Enumeration { .. } => "Integer",
        k => k.type_name(),
    };
    if p.value.type_name() != expected {
        return Err(error(
            &p.location,
            format!(
                "the value is ssv:{}, but `{}.{}` is {}: use <ssv:{expected}>",
                p.value.type_name(),
                c.name,
                p.variable,
                var.kind.type_name()
            ),
        ));
    }
    if let Some(u) = &p.unit {
        if var.kind.unit() != Some(u.as_str()) {
            return Err(error(
                &p.location,
                format!(
                    "unit mismatch: the value has unit `{u}`, `{}.{}` declares {} (fricsim does not convert units)",
                    c.name,
                    p.variable,
                    var.kind.unit().map_or("no unit".to_string(), |d| format!("unit `{d}`"))
                ),
            ));
        }
    }
    Ok(())
}

/// Read and parse the `ssv:ParameterSet` file at `path` (`shown` in
/// messages), with the lines of its elements.
fn read_parameter_set(path: &Path, shown: &str) -> Result<(RawParameterSet, Lines), SspError> {
    let text = read_text(path, shown)?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text).to_string();
    let syntax = |e: SyntaxError| error(format!("{shown}:{}:{}", e.line, e.column), e.message);
    let (_, lines) = xml::first_pass(&text, "ParameterSet", NS_SSV).map_err(syntax)?;
    let set: RawParameterSet = xml::deserialize(&text).map_err(syntax)?;
    Ok((set, lines))
}

fn read_text(path: &Path, shown: &str) -> Result<String, SspError> {
    let bytes = std::fs::read(path).map_err(|e| error(shown, format!("cannot read: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        let (line, column) = xml::line_column(e.as_bytes(), e.utf8_error().valid_up_to());
        error(format!("{shown}:{line}:{column}"), "not valid UTF-8")
    })
}

/// Decode `%XX` escapes of a URI reference; `None` if one is malformed or
/// the result is not UTF-8.
fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// [`Fmu::open`] of each path that is a file, all at once, one thread
/// each; in the paths' order.
fn open_all<'a>(paths: impl Iterator<Item = &'a PathBuf>) -> Vec<Result<Fmu, FmuError>> {
    let open = |path: &PathBuf| {
        if path.is_file() {
            Fmu::open(path)
        } else {
            Err(FmuError::Io {
                path: path.clone(),
                source: std::io::ErrorKind::NotFound.into(),
            })
        }
    };
    let paths: Vec<&PathBuf> = paths.collect();
    if paths.len() < 2 {
        return paths.into_iter().map(open).collect();
    }
    std::thread::scope(|scope| {
        let opening: Vec<_> = paths
            .iter()
            .map(|path| scope.spawn(move || open(path)))
            .collect();
        opening
            .into_iter()
            .map(|thread| {
                thread
                    .join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            })
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_names_are_compacted() {
        let names = [
            "sigma0",
            "x_table[1]",
            "x_table[2]",
            "x_table[3]",
            "n",
            "s[1]",
        ];
        assert_eq!(
            compact_names(names.into_iter()),
            vec!["sigma0", "x_table[1..3]", "n", "s[1]"]
        );
    }

    #[test]
    fn percent_escapes_are_decoded() {
        assert_eq!(percent_decode("a%20b.fmu").as_deref(), Some("a b.fmu"));
        assert_eq!(percent_decode("a%2").as_deref(), None);
        assert_eq!(percent_decode("a%zz").as_deref(), None);
    }
}
