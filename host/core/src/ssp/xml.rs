//! The XML of SSP 1.0 as it is: `Raw…` structs that mirror the elements
//! of `SystemStructure.ssd` and of `.ssv` parameter files, deserialized with
//! quick-xml + serde, and a first pass over the document with quick-xml's
//! namespace-aware reader.
//!
//! serde matches elements by their local name (`ssd:Component` and
//! `Component` alike), so the first pass checks what serde cannot: that the
//! document is well-formed and complete (a truncated file names the element
//! left open), and that the root element is the expected one in the SSP 1.0
//! namespace. It also records the line of every element, so that the checks
//! of [`super`] can say where an element is.

use quick_xml::events::Event;
use quick_xml::name::ResolveResult;
use serde::de::IgnoredAny;
use serde::Deserialize;
use std::collections::HashMap;

/// Namespaces of SSP 1.0 (SSP 1.0 §1.3).
pub const NS_SSD: &str = "http://ssp-standard.org/SSP1/SystemStructureDescription";
pub const NS_SSC: &str = "http://ssp-standard.org/SSP1/SystemStructureCommon";
pub const NS_SSV: &str = "http://ssp-standard.org/SSP1/SystemStructureParameterValues";

/// A syntax error: 1-based line and column, and what is wrong.
#[derive(Debug)]
pub struct SyntaxError {
    pub line: usize,
    pub column: usize,
    pub message: String,
}

/// The lines of the elements of a document, by local name, in document
/// order. Elements inside `Annotation` are left out: their content belongs
/// to whoever defined the annotation and may reuse any name.
#[derive(Debug, Default)]
pub struct Lines {
    by_name: HashMap<String, Vec<usize>>,
}

impl Lines {
    /// The line of the `k`-th (0-based) element called `name`.
    pub fn of(&self, name: &str, k: usize) -> Option<usize> {
        self.by_name.get(name).and_then(|v| v.get(k)).copied()
    }
}

pub use fricsim_fmi::xml_text::{double_hyphen_offset, line_column};

/// The line of byte offsets met in increasing order, counted as the
/// parser goes: each byte of the document is looked at once, so a pass
/// over a document with many elements stays linear in its size (asking
/// [`line_column`] per element rescanned the document from its start,
/// 77 s for 120 000 elements).
struct LineCounter {
    counted_to: usize,
    line: usize,
}

impl LineCounter {
    fn new() -> Self {
        LineCounter {
            counted_to: 0,
            line: 1,
        }
    }

    /// The 1-based line of byte `offset` of `text`, at or after every
    /// offset asked before.
    fn line_at(&mut self, text: &[u8], offset: usize) -> usize {
        let offset = offset.min(text.len());
        if offset > self.counted_to {
            self.line += text[self.counted_to..offset]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            self.counted_to = offset;
        }
        self.line
    }
}

/// First pass: well-formedness, completeness, the root element
/// (`root` in namespace `namespace`) and its `version` attribute, and the
/// lines of the elements. Returns the version.
pub fn first_pass(xml: &str, root: &str, namespace: &str) -> Result<(String, Lines), SyntaxError> {
    let mut reader = quick_xml::NsReader::from_str(xml);
    // `--` inside a comment is not well-formed XML (XML 1.0 §2.5): other
    // SSP tools' parsers refuse such a file, so it is refused here too.
    reader.config_mut().check_comments = true;
    let at = |offset: u64, message: String| {
        let (line, column) = line_column(xml.as_bytes(), offset as usize);
        SyntaxError {
            line,
            column,
            message,
        }
    };
    let mut lines = Lines::default();
    let mut counter = LineCounter::new();
    // open elements: local name and line
    let mut open: Vec<(String, usize)> = Vec::new();
    let mut annotation_depth: Option<usize> = None;
    let mut version = None;
    loop {
        let position = reader.buffer_position();
        let (ns, event) = match reader.read_resolved_event() {
            Ok((ResolveResult::Bound(n), event)) => (n.into_inner().to_string(), event),
            Ok((_, event)) => (String::new(), event),
            Err(quick_xml::Error::IllFormed(
                quick_xml::errors::IllFormedError::DoubleHyphenInComment,
            )) => {
                return Err(at(
                    double_hyphen_offset(xml, position as usize) as u64,
                    "`--` inside a comment, which XML does not allow (XML 1.0 §2.5): \
                     other SSP tools refuse the file"
                        .to_string(),
                ));
            }
            Err(e) => {
                let mut message = e.to_string();
                // A file cut inside a tag, an attribute value or a comment
                // fails with an "unclosed … before end of input" syntax
                // error: say it is truncated.
                let unclosed = matches!(
                    &e,
                    quick_xml::Error::Syntax(s)
                        if !matches!(s, quick_xml::errors::SyntaxError::InvalidBangMarkup)
                );
                if unclosed {
                    message = match open.last() {
                        Some((name, line)) => format!(
                            "{message}; the document ends inside <{name}> (opened at line {line}): the file is truncated"
                        ),
                        None => format!("{message}; the file is truncated"),
                    };
                }
                // (quick-xml leaves the error position at 0 for some
                // errors, such as a nesting deeper than its namespace
                // resolver's limit: the event that failed starts at
                // `position`)
                return Err(at(reader.error_position().max(position), message));
            }
        };
        // XML 1.0 §2.1: only markup and white space may come before and
        // after the root element (other SSP tools' parsers refuse the rest)
        // (where the stray text starts: a text event starts with the white
        // space before it)
        let outside_root = match &event {
            _ if !open.is_empty() => None,
            Event::Text(text) => text
                .as_ref()
                .find(|c: char| !matches!(c, ' ' | '\t' | '\n' | '\r'))
                .map(|k| position + k as u64),
            Event::GeneralRef(_) | Event::CData(_) => Some(position),
            _ => None,
        };
        if let Some(stray) = outside_root {
            let place = if version.is_some() { "after" } else { "before" };
            return Err(at(
                stray,
                format!("text {place} the root element <{root}>: XML allows only markup and white space outside it"),
            ));
        }
        let is_empty = matches!(event, Event::Empty(_));
        match event {
            Event::Start(e) | Event::Empty(e) => {
                let local = e.local_name().into_inner().to_string();
                let line = counter.line_at(xml.as_bytes(), position as usize);
                if open.is_empty() {
                    if version.is_some() {
                        return Err(at(
                            position,
                            format!(
                                "a second root element <{local}> after the end of the document"
                            ),
                        ));
                    }
                    let found_ns = ns;
                    if local != root || found_ns != namespace {
                        let shown = if found_ns.is_empty() {
                            "no namespace".to_string()
                        } else {
                            format!("namespace {found_ns}")
                        };
                        return Err(at(
                            position,
                            format!(
                                "the root element is <{local}> in {shown}; expected <{root}> in namespace {namespace} (SSP 1.0)"
                            ),
                        ));
                    }
                    let v = e
                        .try_get_attribute("version")
                        .map_err(|err| at(position, err.to_string()))?
                        .ok_or_else(|| {
                            at(position, format!("<{root}> has no version attribute"))
                        })?;
                    let v = v
                        .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                        .map_err(|err| at(position, err.to_string()))?
                        .trim()
                        .to_string();
                    if !(v == "1.0" || v.starts_with("1.0.")) {
                        return Err(at(
                            position,
                            format!("<{root}> has version=\"{v}\"; only SSP 1.0 is supported"),
                        ));
                    }
                    version = Some(v);
                }
                if annotation_depth.is_none() {
                    lines.by_name.entry(local.clone()).or_default().push(line);
                    if local == "Annotation" {
                        annotation_depth = Some(open.len());
                    }
                }
                if is_empty {
                    if annotation_depth == Some(open.len()) {
                        annotation_depth = None;
                    }
                } else {
                    open.push((local, line));
                }
            }
            Event::End(_) => {
                open.pop();
                if annotation_depth == Some(open.len()) {
                    annotation_depth = None;
                }
            }
            Event::Eof => {
                if let Some((name, line)) = open.last() {
                    return Err(at(
                        xml.len() as u64,
                        format!(
                            "the document ends inside <{name}> (opened at line {line}): the file is truncated"
                        ),
                    ));
                }
                return match version {
                    Some(v) => Ok((v, lines)),
                    None => Err(at(xml.len() as u64, "no root element".to_string())),
                };
            }
            _ => {}
        }
    }
}

/// Deserialize `xml` into `T`; errors with line and column.
pub fn deserialize<T: for<'de> Deserialize<'de>>(xml: &str) -> Result<T, SyntaxError> {
    let mut de = quick_xml::de::Deserializer::from_str(xml);
    T::deserialize(&mut de).map_err(|e| {
        let reader = de.get_ref().get_ref();
        let position = match e {
            quick_xml::DeError::InvalidXml(_) if reader.error_position() > 0 => {
                reader.error_position()
            }
            _ => reader.buffer_position(),
        };
        let (line, column) = line_column(xml.as_bytes(), position as usize);
        SyntaxError {
            line,
            column,
            message: e.to_string(),
        }
    })
}

// `SystemStructure.ssd` (SSP 1.0 §5). Attributes are `@name` fields, child
// elements are fields named like the element; values are kept as text so
// that the checks can quote them. Elements not listed here (geometry,
// signal dictionaries, units) are skipped.

#[derive(Deserialize)]
pub struct RawSsd {
    #[serde(rename = "@name")]
    pub name: Option<String>,
    #[serde(rename = "System")]
    pub system: Option<RawSystem>,
    #[serde(rename = "DefaultExperiment")]
    pub default_experiment: Option<RawDefaultExperiment>,
    #[serde(rename = "Annotations")]
    pub annotations: Option<RawAnnotations>,
}

#[derive(Deserialize)]
pub struct RawSystem {
    #[serde(rename = "@name")]
    pub name: Option<String>,
    #[serde(rename = "Connectors")]
    pub connectors: Option<RawConnectors>,
    #[serde(rename = "ParameterBindings")]
    pub parameter_bindings: Option<RawParameterBindings>,
    #[serde(rename = "Elements")]
    pub elements: Option<RawElements>,
    #[serde(rename = "Connections")]
    pub connections: Option<RawConnections>,
}

#[derive(Deserialize)]
pub struct RawElements {
    /// Components, systems and signal-dictionary references may alternate,
    /// so they are read as one list of variants.
    #[serde(rename = "$value", default)]
    pub items: Vec<RawElement>,
}

#[derive(Deserialize)]
pub enum RawElement {
    Component(RawComponent),
    System(RawNamed),
    SignalDictionaryReference(RawNamed),
}

#[derive(Deserialize)]
pub struct RawNamed {
    #[serde(rename = "@name")]
    pub name: Option<String>,
}

#[derive(Deserialize)]
pub struct RawComponent {
    #[serde(rename = "@name")]
    pub name: Option<String>,
    #[serde(rename = "@type")]
    pub kind: Option<String>,
    #[serde(rename = "@source")]
    pub source: Option<String>,
    #[serde(rename = "@implementation")]
    pub implementation: Option<String>,
    #[serde(rename = "Connectors")]
    pub connectors: Option<RawConnectors>,
    #[serde(rename = "ParameterBindings")]
    pub parameter_bindings: Option<RawParameterBindings>,
}

#[derive(Deserialize)]
pub struct RawConnectors {
    #[serde(rename = "Connector", default)]
    pub list: Vec<RawConnector>,
}

#[derive(Deserialize)]
pub struct RawConnector {
    #[serde(rename = "@name")]
    pub name: Option<String>,
    #[serde(rename = "@kind")]
    pub kind: Option<String>,
    #[serde(rename = "Real")]
    pub real: Option<RawRealType>,
    #[serde(rename = "Integer")]
    pub integer: Option<IgnoredAny>,
    #[serde(rename = "Boolean")]
    pub boolean: Option<IgnoredAny>,
    #[serde(rename = "String")]
    pub string: Option<IgnoredAny>,
    #[serde(rename = "Enumeration")]
    pub enumeration: Option<IgnoredAny>,
    #[serde(rename = "Binary")]
    pub binary: Option<IgnoredAny>,
}

#[derive(Deserialize)]
pub struct RawRealType {
    #[serde(rename = "@unit")]
    pub unit: Option<String>,
}

#[derive(Deserialize)]
pub struct RawParameterBindings {
    #[serde(rename = "ParameterBinding", default)]
    pub list: Vec<RawParameterBinding>,
}

#[derive(Deserialize)]
pub struct RawParameterBinding {
    #[serde(rename = "@type")]
    pub kind: Option<String>,
    #[serde(rename = "@source")]
    pub source: Option<String>,
    #[serde(rename = "@sourceBase")]
    pub source_base: Option<String>,
    #[serde(rename = "@prefix")]
    pub prefix: Option<String>,
    #[serde(rename = "ParameterValues")]
    pub values: Option<RawParameterValues>,
    #[serde(rename = "ParameterMapping")]
    pub mapping: Option<IgnoredAny>,
}

#[derive(Deserialize)]
pub struct RawParameterValues {
    #[serde(rename = "ParameterSet")]
    pub set: Option<RawParameterSet>,
}

/// `ssv:ParameterSet`, inline in a binding or the root of an `.ssv` file.
#[derive(Deserialize)]
pub struct RawParameterSet {
    #[serde(rename = "Parameters")]
    pub parameters: Option<RawParameters>,
}

#[derive(Deserialize)]
pub struct RawParameters {
    #[serde(rename = "Parameter", default)]
    pub list: Vec<RawParameter>,
}

#[derive(Deserialize)]
pub struct RawParameter {
    #[serde(rename = "@name")]
    pub name: Option<String>,
    #[serde(rename = "Real")]
    pub real: Option<RawValue>,
    #[serde(rename = "Integer")]
    pub integer: Option<RawValue>,
    #[serde(rename = "Boolean")]
    pub boolean: Option<RawValue>,
    #[serde(rename = "String")]
    pub string: Option<RawValue>,
    #[serde(rename = "Enumeration")]
    pub enumeration: Option<RawValue>,
    #[serde(rename = "Binary")]
    pub binary: Option<IgnoredAny>,
}

#[derive(Deserialize)]
pub struct RawValue {
    #[serde(rename = "@value")]
    pub value: Option<String>,
    #[serde(rename = "@unit")]
    pub unit: Option<String>,
}

#[derive(Deserialize)]
pub struct RawConnections {
    #[serde(rename = "Connection", default)]
    pub list: Vec<RawConnection>,
}

#[derive(Deserialize)]
pub struct RawConnection {
    #[serde(rename = "@startElement")]
    pub start_element: Option<String>,
    #[serde(rename = "@startConnector")]
    pub start_connector: Option<String>,
    #[serde(rename = "@endElement")]
    pub end_element: Option<String>,
    #[serde(rename = "@endConnector")]
    pub end_connector: Option<String>,
    #[serde(rename = "LinearTransformation")]
    pub linear: Option<IgnoredAny>,
    #[serde(rename = "BooleanMappingTransformation")]
    pub boolean_mapping: Option<IgnoredAny>,
    #[serde(rename = "IntegerMappingTransformation")]
    pub integer_mapping: Option<IgnoredAny>,
    #[serde(rename = "EnumerationMappingTransformation")]
    pub enumeration_mapping: Option<IgnoredAny>,
}

#[derive(Deserialize)]
pub struct RawDefaultExperiment {
    #[serde(rename = "@startTime")]
    pub start_time: Option<String>,
    #[serde(rename = "@stopTime")]
    pub stop_time: Option<String>,
    #[serde(rename = "Annotations")]
    pub annotations: Option<RawAnnotations>,
}

#[derive(Deserialize)]
pub struct RawAnnotations {
    #[serde(rename = "Annotation", default)]
    pub list: Vec<RawAnnotation>,
}

/// `ssc:Annotation`: its content is read only for our own type (the
/// `Simulation` element of [`super::ANNOTATION_TYPE`]).
#[derive(Deserialize)]
pub struct RawAnnotation {
    #[serde(rename = "@type")]
    pub kind: Option<String>,
    #[serde(rename = "Simulation")]
    pub simulation: Option<RawSimulation>,
}

/// `<fricsim:Simulation stepSize=".." master="..">` with `Plot` and
/// `Record` children in any order.
#[derive(Deserialize)]
pub struct RawSimulation {
    #[serde(rename = "@stepSize")]
    pub step_size: Option<String>,
    #[serde(rename = "@master")]
    pub master: Option<String>,
    #[serde(rename = "$value", default)]
    pub items: Vec<RawSimulationItem>,
}

#[derive(Deserialize)]
pub enum RawSimulationItem {
    Plot(RawSignal),
    Record(RawSignal),
}

#[derive(Deserialize)]
pub struct RawSignal {
    #[serde(rename = "@signal")]
    pub signal: Option<String>,
}
