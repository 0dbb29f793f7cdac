//! Writing result files, whatever their format (a [`RowFile`] of the
//! format the path names: [`ResultFormat::from_path`]):
//! [`ResultWriter`], which takes the rows of a run as they are computed
//! (the masters' `simulate_streaming`) and writes them at once, keeping
//! only a summary of each column and the columns to be plotted, so that a
//! run's memory does not grow with its length; [`write_run`] writes a
//! [`Run`] held in memory as the same file. Every format writes through
//! an [`OutputFile`]: a result is put in place whole (or marked
//! incomplete) or not at all.

use crate::formats::{ResultFormat, RowFile};
use crate::master::{RowSink, Run};
use crate::output_file::{OutputError, OutputFile};
use crate::rows::Rows;
use crate::system::RecordedType;

/// Write `run` (rows held in memory) to `out` in the format its path
/// names ([`ResultFormat::from_path`]: MAT v4 for `.mat`, else CSV).
pub fn write_run(run: &Run, out: OutputFile) -> Result<(), OutputError> {
    let mut file = ResultFormat::from_path(out.path()).writer(out, &run.columns);
    // a write error is reported by finish, with the path
    let _ = file.write_rows(&run.time, &run.rows);
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
        let n = times.len().min(rows.len());
        let (Some(first), Some(last)) = (times.first(), times.get(n.wrapping_sub(1))) else {
            return;
        };
        self.first_time.get_or_insert(*first);
        self.last_time = Some(*last);
        self.rows += n;
        for row in rows.into_iter().take(n) {
            for ((lo, hi), &x) in self.min.iter_mut().zip(&mut self.max).zip(row) {
                // `f64::min` and `max` as the processor's `minsd` and
                // `maxsd` compute them, without a branch: a NaN leaves the
                // bound as it was (the bounds start infinite, never NaN)
                *lo = if x < *lo { x } else { *lo };
                *hi = if x > *hi { x } else { *hi };
            }
        }
        // the last row, copied once per chunk rather than once per row
        if let Some(row) = rows.get(n - 1) {
            self.last.copy_from_slice(row);
        }
    }
}

/// The rows of a run as they come: written to a result file
/// ([`ResultFormat::writer`]),
/// summed up in [`ColumnStats`], and the columns to be plotted kept.
pub struct ResultWriter {
    file: Box<dyn RowFile + Send>,
    /// The summary of the rows written ([`ResultWriter::summarized_elsewhere`]:
    /// left empty).
    pub stats: ColumnStats,
    summarize: bool,
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
    /// A writer of the rows of `columns` to the result file `out` (CSV,
    /// or MAT v4 if its path ends in `.mat`: [`ResultFormat::from_path`]).
    pub fn new(out: OutputFile, columns: &[String]) -> ResultWriter {
        ResultWriter {
            file: ResultFormat::from_path(out.path()).writer(out, columns),
            stats: ColumnStats::new(columns.len()),
            summarize: true,
            kept: None,
        }
    }

    /// Leave [`ResultWriter::stats`] empty: for a writer behind a
    /// [`crate::run::Recorder`], which sums up the same rows (the summary
    /// costs about a tenth of writing a CSV row).
    pub fn summarized_elsewhere(mut self) -> ResultWriter {
        self.summarize = false;
        self
    }

    /// See [`crate::csvfile::CsvFile::whole_number_columns`].
    pub fn whole_number_columns(&mut self, types: &[RecordedType]) {
        self.file.whole_number_columns(types);
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
            warnings: Vec::new(),
        })
    }

    /// The end of the file (see [`crate::csvfile::CsvFile::finish`],
    /// [`crate::matfile::MatFile::finish`]).
    pub fn finish(self, error: Option<&str>) -> Result<(), OutputError> {
        self.file.finish(error)
    }
}

impl RowSink for ResultWriter {
    fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String> {
        self.file
            .write_rows(times, rows)
            .map_err(|e| format!("{}: {e}", self.file.path().display()))?;
        if self.summarize {
            self.stats.add(times, rows);
        }
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

    /// A termination signal stops the run ([`crate::signals`]).
    fn stop_requested(&self) -> Option<String> {
        crate::signals::stop_reason()
    }
}

#[cfg(test)]
mod tests {
    use super::ColumnStats;
    use crate::output_file::OutputFile;
    use crate::rows::Rows;

    /// A writer whose rows are summed up elsewhere writes the same file
    /// and keeps no summary; the default one sums the rows up.
    #[test]
    fn a_writer_summarized_elsewhere_keeps_no_summary() {
        use crate::master::RowSink;
        let dir = tempfile::tempdir().unwrap();
        let rows = Rows::from_rows(1, [[2.0], [-1.0]]);
        let mut texts = Vec::new();
        for elsewhere in [false, true] {
            let path = dir.path().join(format!("{elsewhere}.csv"));
            let out = OutputFile::create(&path, &[]).unwrap();
            let mut writer = super::ResultWriter::new(out, &["x".to_string()]);
            if elsewhere {
                writer = writer.summarized_elsewhere();
            }
            writer.write(&[0.0, 1.0], &rows).unwrap();
            let stats = writer.stats.clone();
            writer.finish(None).unwrap();
            texts.push(std::fs::read_to_string(&path).unwrap());
            if elsewhere {
                assert_eq!((stats.rows, stats.min[0]), (0, f64::INFINITY));
            } else {
                assert_eq!((stats.rows, stats.min[0], stats.max[0]), (2, -1.0, 2.0));
            }
        }
        assert_eq!(texts[0], "time,x\n0.0,2.0\n1.0,-1.0\n");
        assert_eq!(texts[0], texts[1]);
    }

    /// The least and greatest of each column, a NaN passed over.
    #[test]
    fn column_stats_pass_over_nan() {
        let mut stats = ColumnStats::new(2);
        let rows = Rows::from_rows(2, [[1.0, f64::NAN], [-2.0, 3.0], [f64::NAN, -0.5]]);
        stats.add(&[0.0, 1.0, 2.0], &rows);
        assert_eq!(stats.min, [-2.0, -0.5]);
        assert_eq!(stats.max, [1.0, 3.0]);
        assert_eq!(stats.rows, 3);
        assert!(stats.last[0].is_nan());
        assert_eq!(stats.last[1], -0.5);
    }
}
