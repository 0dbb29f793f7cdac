//! The XML reading every version's model description shares: one pass of
//! quick-xml's pull reader over the document ([`Document`]), which checks
//! well-formedness (matching end tags, attribute syntax, `--` in comments,
//! nothing but markup and white space outside the root) as it goes and
//! hands each element to the version's reader with its position, and the
//! attribute values as numbers and booleans of XML Schema, every refusal
//! with its line and column.

use crate::error::FmuError;
use crate::xml_text::{double_hyphen_offset, line_column};
use quick_xml::events::{BytesStart, Event};

/// The error for a comment holding `--`, in the event starting at byte
/// `event_start`.
fn double_hyphen(xml: &str, event_start: usize) -> FmuError {
    let offset = double_hyphen_offset(xml, event_start);
    syntax(
        xml,
        offset,
        "`--` inside a comment, which XML does not allow (XML 1.0 §2.5): \
         FMPy and other importers refuse the file"
            .to_string(),
    )
}

/// A syntax error at byte `offset` of `xml`.
pub(super) fn syntax(xml: &str, offset: usize, message: String) -> FmuError {
    let (line, column) = line_column(xml.as_bytes(), offset);
    FmuError::XmlSyntax {
        line,
        column,
        message,
    }
}

/// A document being read, up to its root element ([`Document::root`]),
/// then inside it ([`Document::children`]).
pub(super) struct Document<'x> {
    xml: &'x str,
    reader: quick_xml::Reader<&'x [u8]>,
    /// The byte offset of the `<` of each open element, for the message
    /// of a truncated file.
    open: Vec<usize>,
}

/// The start tag of the root element, `<fmiModelDescription …>`.
pub(super) struct Root<'x> {
    pub at: ElementAt<'x>,
    /// Its attributes, normalized, in document order.
    pub attributes: Vec<(String, String)>,
    /// `<fmiModelDescription …/>`: no children.
    empty: bool,
}

/// What [`Document::next_tag`] meets.
enum Tag<'x> {
    /// A start tag at a byte offset; `true` if empty (`<x/>`).
    Start(BytesStart<'x>, usize, bool),
    End,
    Eof,
}

impl Root<'_> {
    /// The value of the attribute `key`, if the root has it.
    pub fn attribute(&self, key: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
}

/// The element whose attributes are being read, for error messages.
pub(super) struct ElementAt<'x> {
    pub xml: &'x str,
    /// Byte offset of its `<`.
    pub position: usize,
    pub name: &'x str,
}

/// The numeric types of attributes, and what an error calls them.
pub(super) trait XmlNumber: std::str::FromStr {
    const KIND: &'static str;
}

impl XmlNumber for f64 {
    const KIND: &'static str = "number";
}

impl XmlNumber for i32 {
    const KIND: &'static str = "integer";
}

impl XmlNumber for u32 {
    const KIND: &'static str = "non-negative integer";
}

impl XmlNumber for u64 {
    const KIND: &'static str = "non-negative integer";
}

impl XmlNumber for usize {
    const KIND: &'static str = "non-negative integer";
}

/// XML white space, which XML Schema allows around a number or boolean.
pub(super) const XML_SPACE: [char; 4] = [' ', '\t', '\n', '\r'];

impl ElementAt<'_> {
    pub(super) fn error(&self, message: String) -> FmuError {
        syntax(self.xml, self.position, message)
    }

    pub(super) fn missing(&self, attribute: &str) -> FmuError {
        self.error(format!("<{}> has no {attribute} attribute", self.name))
    }

    /// An `xs:double`, `xs:int` or `xs:unsignedInt` attribute (`INF`,
    /// `-INF` and `NaN` included).
    pub(super) fn number<T: XmlNumber>(&self, key: &str, value: &str) -> Result<T, FmuError> {
        value.trim_matches(XML_SPACE).parse().map_err(|_| {
            self.error(format!(
                "<{}> {key}=\"{value}\" is not a valid {}",
                self.name,
                T::KIND
            ))
        })
    }

    /// An `xs:boolean` attribute: `true`, `false`, `1` or `0`.
    pub(super) fn boolean(&self, key: &str, value: &str) -> Result<bool, FmuError> {
        match value.trim_matches(XML_SPACE) {
            "true" | "1" => Ok(true),
            "false" | "0" => Ok(false),
            _ => Err(self.error(format!(
                "<{}> {}=\"{value}\" is not a boolean (true, false, 1 or 0)",
                self.name, key
            ))),
        }
    }

    /// Call `f` with the name and the normalized value of each attribute
    /// of `element` (quick-xml refuses a duplicated attribute).
    pub(super) fn attributes(
        &self,
        element: &quick_xml::events::BytesStart<'_>,
        mut f: impl FnMut(&str, std::borrow::Cow<'_, str>) -> Result<(), FmuError>,
    ) -> Result<(), FmuError> {
        for attribute in element.attributes() {
            let attribute = attribute.map_err(|e| self.error(format!("<{}>: {e}", self.name)))?;
            let value = attribute
                .normalized_value(quick_xml::XmlVersion::Implicit1_0)
                .map_err(|e| self.error(format!("<{}>: {e}", self.name)))?;
            f(attribute.key.as_ref(), value)?;
        }
        Ok(())
    }
}

impl<'x> Document<'x> {
    pub fn new(xml: &'x str) -> Self {
        let mut reader = quick_xml::Reader::from_str(xml);
        // `--` inside a comment is not well-formed XML (XML 1.0 §2.5):
        // FMPy's parser, lxml, refuses such a file, so it is refused here
        // too, with the line.
        reader.config_mut().check_comments = true;
        Document {
            xml,
            reader,
            open: Vec::new(),
        }
    }

    /// The next event and the byte offset where it starts; malformed XML
    /// and text outside the root element refused.
    fn next(&mut self) -> Result<(Event<'x>, usize), FmuError> {
        let xml = self.xml;
        let position = self.reader.buffer_position() as usize;
        let event = match self.reader.read_event() {
            Ok(event) => event,
            Err(quick_xml::Error::IllFormed(
                quick_xml::errors::IllFormedError::DoubleHyphenInComment,
            )) => return Err(double_hyphen(xml, position)),
            Err(e) => {
                let mut message = e.to_string();
                if let (quick_xml::Error::Syntax(_), Some(&at)) = (&e, self.open.last()) {
                    message = format!("{message}; {}", self.truncated(at));
                }
                // (quick-xml leaves the error position at 0 for some
                // errors: the event that failed starts at `position`)
                let at = (self.reader.error_position() as usize).max(position);
                return Err(syntax(xml, at, message));
            }
        };
        // XML 1.0 §2.1: only markup and white space may come before
        // and after the root element
        let outside_root = self.open.is_empty()
            && match &event {
                Event::Text(text) => !text.trim_matches(XML_SPACE).is_empty(),
                Event::GeneralRef(_) | Event::CData(_) => true,
                _ => false,
            };
        if outside_root {
            return Err(syntax(
                xml,
                position,
                "text outside the root element <fmiModelDescription>".into(),
            ));
        }
        Ok((event, position))
    }

    /// The next start tag (and whether it is empty, `<x/>`), end tag or
    /// the end of the document, other markup skipped; the open elements
    /// followed.
    fn next_tag(&mut self) -> Result<Tag<'x>, FmuError> {
        loop {
            let (event, position) = self.next()?;
            return Ok(match event {
                Event::Start(e) => {
                    self.open.push(position);
                    Tag::Start(e, position, false)
                }
                Event::Empty(e) => Tag::Start(e, position, true),
                Event::End(_) => {
                    self.open.pop();
                    Tag::End
                }
                Event::Eof => Tag::Eof,
                _ => continue,
            });
        }
    }

    /// Read up to the root element's start tag, which must be
    /// `<fmiModelDescription>`, and its attributes.
    pub fn root(&mut self) -> Result<Root<'x>, FmuError> {
        let xml = self.xml;
        loop {
            let (e, position, empty) = match self.next_tag()? {
                Tag::Start(e, position, empty) => (e, position, empty),
                Tag::End => continue,
                Tag::Eof => return Err(syntax(xml, xml.len(), "no root element".into())),
            };
            let name = e.name().into_inner();
            let at = ElementAt {
                xml,
                position,
                name,
            };
            if name != "fmiModelDescription" {
                return Err(at.error(format!(
                    "root element is <{name}>, expected <fmiModelDescription>"
                )));
            }
            let mut attributes = Vec::new();
            at.attributes(&e, |key, value| {
                attributes.push((key.to_string(), value.into_owned()));
                Ok(())
            })?;
            return Ok(Root {
                at: ElementAt {
                    xml,
                    position,
                    name: "fmiModelDescription",
                },
                attributes,
                empty,
            });
        }
    }

    /// Read the rest of the document: each element inside the root is
    /// given to `element` with what its parent's children are read as
    /// (`root_scope` for the root's), and what `element` returns is what
    /// its own children are read as. After the root, only markup and
    /// white space.
    pub fn children<S: Copy>(
        mut self,
        root: &Root<'_>,
        root_scope: S,
        mut element: impl FnMut(S, &BytesStart<'_>, &ElementAt<'_>) -> Result<S, FmuError>,
    ) -> Result<(), FmuError> {
        let xml = self.xml;
        let mut scopes = if root.empty {
            Vec::new()
        } else {
            vec![root_scope]
        };
        loop {
            let (e, position, empty) = match self.next_tag()? {
                Tag::Start(e, position, empty) => (e, position, empty),
                Tag::End => {
                    scopes.pop();
                    continue;
                }
                Tag::Eof => match self.open.last() {
                    Some(&at) => return Err(syntax(xml, xml.len(), self.truncated(at))),
                    None => return Ok(()),
                },
            };
            let name = e.name().into_inner();
            let at = ElementAt {
                xml,
                position,
                name,
            };
            // no element open: the root has ended
            let Some(&scope) = scopes.last() else {
                return Err(at.error(format!(
                    "a second root element <{name}> after </fmiModelDescription>"
                )));
            };
            let scope = element(scope, &e, &at)?;
            if !empty {
                scopes.push(scope);
            }
        }
    }

    /// "The document ends inside <X> (line N)" for the element opened at
    /// byte `at`.
    fn truncated(&self, at: usize) -> String {
        let name: String = self.xml[at + 1..]
            .chars()
            .take_while(|c| !c.is_whitespace() && !matches!(c, '>' | '/'))
            .collect();
        let (line, _) = line_column(self.xml.as_bytes(), at);
        format!("the document ends inside <{name}> (opened at line {line}): the file is truncated")
    }
}
