//! Result files: CSV with `time` first and `component.variable` columns
//! (FMPy's convention), numbers written so that they parse back exactly.
//! A run that stopped early keeps its rows and ends with a comment line
//! `# INCOMPLETE: …` (CSV readers such as numpy's skip `#` lines).
//!
//! [`ResultWriter`] takes the rows of a run as they are computed
//! ([`crate::master::simulate_streaming`]) and writes them at once, keeping
//! only a summary of each column and the columns to be plotted, so that a
//! run's memory does not grow with its length; [`write_csv`] writes a
//! [`Run`] held in memory as the same file.

use crate::master::{RowSink, Run};
use crate::rows::Rows;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A CSV result file written row by row: created (with its directory) at
/// the first rows, so that a run that fails before its first row leaves
/// no file.
pub struct CsvFile {
    path: PathBuf,
    header: String,
    out: Option<BufWriter<File>>,
}

impl CsvFile {
    /// A file at `path` with the columns `time` and `columns`.
    pub fn new(path: &Path, columns: &[String]) -> CsvFile {
        CsvFile {
            path: path.to_path_buf(),
            header: format!("time,{}", columns.join(",")),
            out: None,
        }
    }

    fn out(&mut self) -> std::io::Result<&mut BufWriter<File>> {
        if self.out.is_none() {
            if let Some(dir) = self.path.parent() {
                std::fs::create_dir_all(dir)?;
            }
            let mut out = BufWriter::with_capacity(1 << 16, File::create(&self.path)?);
            writeln!(out, "{}", self.header)?;
            self.out = Some(out);
        }
        Ok(self.out.as_mut().expect("opened above"))
    }

    /// The first `times.len()` rows of `rows`, at `times`.
    pub fn write_rows(&mut self, times: &[f64], rows: &Rows) -> std::io::Result<()> {
        let out = self.out()?;
        for (t, row) in times.iter().zip(rows) {
            write!(out, "{t:?}")?;
            for x in row {
                write!(out, ",{x:?}")?;
            }
            writeln!(out)?;
        }
        Ok(())
    }

    /// The end of the file: `# INCOMPLETE: the run stopped early: …` if
    /// `error` says why the run stopped early.
    pub fn finish(mut self, error: Option<&str>) -> std::io::Result<()> {
        let out = self.out()?;
        if let Some(e) = error {
            let one_line = e.replace(['\n', '\r'], " ");
            writeln!(out, "# INCOMPLETE: the run stopped early: {one_line}")?;
        }
        out.flush()
    }
}

/// Write `run` (rows held in memory) as a CSV result file.
pub fn write_csv(run: &Run, path: &Path) -> std::io::Result<()> {
    let mut file = CsvFile::new(path, &run.columns);
    file.write_rows(&run.time, &run.rows)?;
    file.finish(run.error.as_deref())
}

/// What a summary tells of each column: its least, greatest and last
/// value, over the rows seen so far, and of the rows their number and
/// first and last times.
#[derive(Clone, Debug)]
pub struct ColumnStats {
    pub rows: usize,
    pub first_time: Option<f64>,
    pub last_time: Option<f64>,
    pub min: Vec<f64>,
    pub max: Vec<f64>,
    /// The last row (NaN before the first).
    pub last: Vec<f64>,
}

impl ColumnStats {
    pub fn new(width: usize) -> ColumnStats {
        ColumnStats {
            rows: 0,
            first_time: None,
            last_time: None,
            min: vec![f64::INFINITY; width],
            max: vec![f64::NEG_INFINITY; width],
            last: vec![f64::NAN; width],
        }
    }

    /// The first `times.len()` rows of `rows`, at `times`.
    pub fn add(&mut self, times: &[f64], rows: &Rows) {
        for (t, row) in times.iter().zip(rows) {
            self.first_time.get_or_insert(*t);
            self.last_time = Some(*t);
            self.rows += 1;
            for ((lo, hi), x) in self.min.iter_mut().zip(&mut self.max).zip(row) {
                *lo = lo.min(*x);
                *hi = hi.max(*x);
            }
            self.last.copy_from_slice(row);
        }
    }
}

/// The rows of a run as they come: written to a CSV file, summed up in
/// [`ColumnStats`], and the columns to be plotted kept.
pub struct ResultWriter {
    file: CsvFile,
    pub stats: ColumnStats,
    /// The columns kept (their indices), their names, their times and rows.
    kept: Option<Kept>,
}

struct Kept {
    indices: Vec<usize>,
    names: Vec<String>,
    time: Vec<f64>,
    rows: Rows,
}

impl ResultWriter {
    /// A writer of the rows of `columns` to the CSV file `path`.
    pub fn new(path: &Path, columns: &[String]) -> ResultWriter {
        ResultWriter {
            file: CsvFile::new(path, columns),
            stats: ColumnStats::new(columns.len()),
            kept: None,
        }
    }

    /// Keep the columns `names` in memory besides writing them (for a
    /// plot: [`ResultWriter::kept`]).
    pub fn keep_columns(&mut self, columns: &[String], names: &[String]) -> Result<(), String> {
        let indices = names
            .iter()
            .map(|s| {
                columns.iter().position(|c| c == s).ok_or_else(|| {
                    format!(
                        "cannot plot `{s}`: no such column (columns: {})",
                        columns.join(", ")
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        self.kept = Some(Kept {
            rows: Rows::new(indices.len()),
            indices,
            names: names.to_vec(),
            time: Vec::new(),
        });
        Ok(())
    }

    /// The columns kept ([`ResultWriter::keep_columns`]), as a run of
    /// those columns alone.
    pub fn kept(&self) -> Option<Run> {
        self.kept.as_ref().map(|k| Run {
            columns: k.names.clone(),
            time: k.time.clone(),
            rows: k.rows.clone(),
            error: None,
        })
    }

    /// The end of the file (see [`CsvFile::finish`]).
    pub fn finish(self, error: Option<&str>) -> std::io::Result<()> {
        self.file.finish(error)
    }
}

impl RowSink for ResultWriter {
    fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String> {
        self.file
            .write_rows(times, rows)
            .map_err(|e| format!("{}: {e}", self.file.path.display()))?;
        self.stats.add(times, rows);
        if let Some(k) = &mut self.kept {
            k.time.extend_from_slice(times);
            for row in rows.iter().take(times.len()) {
                let new = k.rows.push_zeros();
                for (x, &i) in new.iter_mut().zip(&k.indices) {
                    *x = row[i];
                }
            }
        }
        Ok(())
    }
}
