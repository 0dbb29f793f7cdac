//! Positions in XML text for messages: the line and column of a byte
//! offset, and where a `--` inside a comment is (shared with the SSP
//! reader).

/// 1-based line and column (in characters) of byte `offset`.
pub fn line_column(text: &[u8], offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let column = String::from_utf8_lossy(&before[line_start..])
        .chars()
        .count()
        + 1;
    (line, column)
}

/// The byte offset of the `--` inside the first comment at or after byte
/// `event_start` (where the event quick-xml refused with
/// `DoubleHyphenInComment` starts): located here, as quick-xml's own
/// offset for this error can be off within a comment that holds a single
/// `-` before.
pub fn double_hyphen_offset(xml: &str, event_start: usize) -> usize {
    let opened = xml[event_start..]
        .find("<!--")
        .map_or(event_start, |p| event_start + p + 4);
    xml[opened..].find("--").map_or(opened, |p| opened + p)
}
