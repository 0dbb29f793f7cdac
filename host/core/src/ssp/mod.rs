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
//! [`SystemFile::build`] instantiates the [`crate::system::System`].
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
//!
//! This module holds the definitions (what a system file says, its
//! errors) and opens a file; the work is in its submodules, each a step:
//! `parse` (the ssd, one function per element kind), `check` (against the
//! FMUs), `build` (the [`crate::system::System`]), [`mod@pack`] (an `.ssp`),
//! and `xml` (the raw elements and their lines). They use the importer
//! ([`crate::fmu`]) and [`crate::system`]; nothing of the masters but
//! their names ([`MASTERS`]).

mod build;
mod check;
pub mod pack;
mod parse;
pub(crate) mod xml;

pub use pack::pack;

use crate::fmu::archive::{unpack_requiring, UnpackOptions};
use crate::fmu::model_description::Causality;
use crate::fmu::Fmu;
use std::path::{Component as PathPart, Path, PathBuf};
use tempfile::TempDir;
use xml::{Lines, RawParameterSet, SyntaxError};

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
#[derive(Clone, Debug)]
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
    /// The archive's unpacked directory, shared by the copies of the
    /// file (removed when the last is dropped).
    _unpacked: Option<std::sync::Arc<TempDir>>,
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
            file._unpacked = Some(std::sync::Arc::new(dir));
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

    /// The component `name` given another FMU, `source`: its connectors
    /// that `keep` refuses (those the new FMU does not have) are dropped
    /// with every connection to them, and so are its parameter bindings
    /// (they were the old FMU's). What the diagnosis co-simulates when it
    /// tries another friction law in place of the nominal one.
    pub fn with_component_source(
        &self,
        name: &str,
        source: &Path,
        keep: impl Fn(&str) -> bool,
    ) -> Result<SystemFile, String> {
        let mut file = self.clone();
        let component = file
            .components
            .iter_mut()
            .find(|c| c.name == name)
            .ok_or_else(|| format!("{}: no component `{name}`", self.ssd))?;
        component.source = source.to_path_buf();
        component.source_text = source.display().to_string();
        component.connectors.retain(|c| keep(&c.name));
        let kept: Vec<String> = component
            .connectors
            .iter()
            .map(|c| c.name.clone())
            .collect();
        let gone =
            |(c, v): &(Option<String>, String)| c.as_deref() == Some(name) && !kept.contains(v);
        file.connections
            .retain(|c| !gone(&c.start) && !gone(&c.end));
        file.parameters.retain(|p| p.component != name);
        Ok(file)
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
