//! The one registry of result-file formats: which format a path names
//! ([`ResultFormat::from_path`]: MAT v4 for `.mat`, any case, else CSV),
//! its writer ([`ResultFormat::writer`], a [`RowFile`]), and whether it
//! can hold a column of text ([`ResultFormat::holds_text`]). Every command that reads or
//! writes a result file asks here (`run`, `cosim`, `reference`, `sweep`,
//! `compare`, input tables, `diagnose`'s data), and the readers
//! ([`crate::inputs::InputTable::read`], [`crate::compare::ResultFile::read`])
//! `match` on the format, so that a new format is a compile error wherever
//! it is not yet handled. Uses the writers ([`crate::csvfile`],
//! [`crate::matfile`]); used by the readers and [`crate::results`], never
//! the reverse.

use crate::csvfile::CsvFile;
use crate::matfile::MatFile;
use crate::output_file::{OutputError, OutputFile};
use crate::rows::Rows;
use crate::system::RecordedType;
use std::path::Path;

/// A format of result files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResultFormat {
    /// Comma-separated text, `time` first ([`crate::csvfile`]).
    Csv,
    /// MAT v4 in the Dymola/OpenModelica trajectory layout
    /// ([`crate::matfile`]).
    Mat,
}

impl ResultFormat {
    /// The format the path names by its extension: `.mat` (any case) is
    /// MAT v4, anything else CSV.
    pub fn from_path(path: &Path) -> ResultFormat {
        let mat = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mat"));
        if mat {
            ResultFormat::Mat
        } else {
            ResultFormat::Csv
        }
    }

    /// Whether a file of this format can hold a column of text (a sweep's
    /// `status`): CSV can; MAT v4's matrices hold numbers (text there is
    /// one matrix of names), so a command with a text column refuses a
    /// `.mat` rather than write it another way.
    pub fn holds_text(self) -> bool {
        match self {
            ResultFormat::Csv => true,
            ResultFormat::Mat => false,
        }
    }

    /// The writer of a result file of this format in `out`, with the
    /// columns `time` and `columns`.
    pub fn writer(self, out: OutputFile, columns: &[String]) -> Box<dyn RowFile + Send> {
        match self {
            ResultFormat::Csv => Box::new(CsvFile::new(out, columns)),
            ResultFormat::Mat => Box::new(MatFile::new(out, columns)),
        }
    }
}

/// A result file written row by row, whatever its format.
pub trait RowFile {
    fn path(&self) -> &Path;
    /// Write the Integer and Boolean columns as whole numbers, where the
    /// format distinguishes them (CSV); `types` has one entry per column.
    fn whole_number_columns(&mut self, _types: &[RecordedType]) {}
    /// The first `times.len()` rows of `rows`, at `times`.
    fn write_rows(&mut self, times: &[f64], rows: &Rows) -> std::io::Result<()>;
    /// The end of the file, saying why the run stopped early if `error`
    /// is given; then the file is put in place ([`OutputFile::commit`]).
    fn finish(self: Box<Self>, error: Option<&str>) -> Result<(), OutputError>;
}

impl RowFile for CsvFile {
    fn path(&self) -> &Path {
        CsvFile::path(self)
    }
    fn whole_number_columns(&mut self, types: &[RecordedType]) {
        CsvFile::whole_number_columns(self, types)
    }
    fn write_rows(&mut self, times: &[f64], rows: &Rows) -> std::io::Result<()> {
        CsvFile::write_rows(self, times, rows)
    }
    fn finish(self: Box<Self>, error: Option<&str>) -> Result<(), OutputError> {
        CsvFile::finish(*self, error)
    }
}

impl RowFile for MatFile {
    fn path(&self) -> &Path {
        MatFile::path(self)
    }
    fn write_rows(&mut self, times: &[f64], rows: &Rows) -> std::io::Result<()> {
        MatFile::write_rows(self, times, rows)
    }
    fn finish(self: Box<Self>, error: Option<&str>) -> Result<(), OutputError> {
        MatFile::finish(*self, error)
    }
}

#[cfg(test)]
mod tests {
    use super::ResultFormat;
    use std::path::Path;

    #[test]
    fn the_extension_names_the_format() {
        for (path, format) in [
            ("r.mat", ResultFormat::Mat),
            ("R.MAT", ResultFormat::Mat),
            ("r.csv", ResultFormat::Csv),
            ("r", ResultFormat::Csv),
            ("r.mat.csv", ResultFormat::Csv),
        ] {
            assert_eq!(ResultFormat::from_path(Path::new(path)), format, "{path}");
        }
        assert!(ResultFormat::Csv.holds_text() && !ResultFormat::Mat.holds_text());
    }
}
