//! Co-simulation error against a reference: for each signal common to a
//! result and a reference (CSV, `time` first, `component.variable`
//! columns, as `fricsim run` and `fricsim reference` write them, or MAT v4
//! result files, [`crate::matfile`]), the relative RMS error
//!
//! `e_rms = √(Σ (y_i − r_i)²) / √(Σ r_i²)`  (RMS of the difference over RMS
//! of the reference, over the result's time points),
//!
//! and the largest absolute error `max |y_i − r_i|` with the time where it
//! occurs. When the time grids differ the reference is interpolated
//! linearly onto the result's times (it must cover them).

use crate::formats::ResultFormat;
use std::fmt;
use std::path::{Path, PathBuf};

/// Why two result files could not be compared; every message names the
/// file and, where there is one, the line and the column.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    #[error("{}: {message}", path.display())]
    Read { path: PathBuf, message: String },
    #[error("{}: line {line}: {message}", path.display())]
    Format {
        path: PathBuf,
        line: u64,
        message: String,
    },
    #[error("{}: line {line}: time {time} does not increase (previous {previous}); time must be strictly increasing", path.display())]
    NonMonotoneTime {
        path: PathBuf,
        line: u64,
        time: f64,
        previous: f64,
    },
    #[error("{}: line {line}: {column} = {value} is not a finite number", path.display())]
    NotFinite {
        path: PathBuf,
        line: u64,
        column: String,
        value: f64,
    },
    #[error("no common columns: the result has {result:?}, the reference has {reference:?}")]
    NoCommonColumns {
        result: Vec<String>,
        reference: Vec<String>,
    },
    #[error("signal `{name}` is not a column of {}", path.display())]
    UnknownSignal { name: String, path: PathBuf },
    #[error("the reference covers t = {ref_start} … {ref_end}, but the result has t = {time}: the reference must cover the result's time span")]
    NotCovered {
        time: f64,
        ref_start: f64,
        ref_end: f64,
    },
}

/// A result file: time and columns of values, with the line number of
/// each row (for messages) and the note of an incomplete run, if any.
#[derive(Clone, Debug, PartialEq)]
pub struct ResultFile {
    pub path: PathBuf,
    pub columns: Vec<String>,
    pub time: Vec<f64>,
    /// `values[k][i]`: column `k` at row `i`.
    pub values: Vec<Vec<f64>>,
    /// 1-based line of each row (of a MAT file: its time point).
    pub lines: Vec<u64>,
    /// The text of a `# INCOMPLETE: …` line (a run that stopped early).
    pub incomplete: Option<String>,
}

impl ResultFile {
    /// Reads a CSV with a header `time,<columns…>` and at least one row of
    /// numbers (`NaN` and `inf` parse and are refused when compared);
    /// `#` lines are comments. Time must be finite and strictly increasing.
    /// A path ending in `.mat` is read as a MAT v4 result file
    /// ([`crate::matfile::read`]), with the same checks.
    pub fn read(path: &Path) -> Result<ResultFile, CompareError> {
        match ResultFormat::from_path(path) {
            ResultFormat::Mat => Self::read_mat(path),
            ResultFormat::Csv => {
                let text = std::fs::read_to_string(path).map_err(|e| CompareError::Read {
                    path: path.to_path_buf(),
                    message: e.to_string(),
                })?;
                Self::parse(path, &text)
            }
        }
    }

    /// A MAT v4 result file: the variables of its `data_2`, time strictly
    /// increasing and finite, at least one time point and one column.
    fn read_mat(path: &Path) -> Result<ResultFile, CompareError> {
        let read_error = |message: String| CompareError::Read {
            path: path.to_path_buf(),
            message,
        };
        let mat = crate::matfile::read(path).map_err(|message| CompareError::Read {
            path: path.to_path_buf(),
            // the reader's messages name the file already
            message: message
                .strip_prefix(&format!("{}: ", path.display()))
                .map_or(message.clone(), str::to_string),
        })?;
        if mat.columns.is_empty() {
            return Err(read_error("no variables but time in data_2".into()));
        }
        if mat.time.is_empty() {
            return Err(read_error("no time points in data_2".into()));
        }
        for (i, pair) in mat.time.windows(2).enumerate() {
            if !pair[0].is_finite() || pair[1] <= pair[0] {
                return Err(read_error(format!(
                    "time point {}: time {} after {}; time must be finite and strictly increasing",
                    i + 2,
                    pair[1],
                    pair[0]
                )));
            }
        }
        if let Some(t) = mat.time.iter().find(|t| !t.is_finite()) {
            return Err(read_error(format!("time {t} is not a finite number")));
        }
        Ok(ResultFile {
            path: path.to_path_buf(),
            columns: mat.columns,
            lines: (1..=mat.time.len() as u64).collect(),
            time: mat.time,
            values: mat.values,
            incomplete: mat.incomplete,
        })
    }

    /// As [`ResultFile::read`], from the file's text.
    pub fn parse(path: &Path, text: &str) -> Result<ResultFile, CompareError> {
        let format = |line: u64, message: String| CompareError::Format {
            path: path.to_path_buf(),
            line,
            message,
        };
        let incomplete = text
            .lines()
            .find_map(|l| l.trim().strip_prefix("# INCOMPLETE:"))
            .map(|s| s.trim().to_string());
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(true)
            .flexible(true)
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| format(1, e.to_string()))?
            .iter()
            .map(|h| h.trim_start_matches('\u{feff}').to_string())
            .collect();
        match header.first().map(String::as_str) {
            Some("time") => {}
            Some("") | None => return Err(format(1, "empty header: expected `time,…`".into())),
            Some(other) => {
                return Err(format(
                    1,
                    format!("the first column must be `time`, found `{other}`"),
                ))
            }
        }
        if header.len() < 2 {
            return Err(format(1, "no columns after `time`".into()));
        }
        for (k, name) in header.iter().enumerate() {
            if name.is_empty() {
                return Err(format(1, format!("column {} has no name", k + 1)));
            }
            if header[..k].contains(name) {
                return Err(format(1, format!("column `{name}` appears twice")));
            }
        }
        let columns = header[1..].to_vec();
        let mut file = ResultFile {
            path: path.to_path_buf(),
            values: vec![Vec::new(); columns.len()],
            columns,
            time: Vec::new(),
            lines: Vec::new(),
            incomplete,
        };
        for record in reader.records() {
            let record = record.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line());
                format(line, e.to_string())
            })?;
            let line = record.position().map_or(0, |p| p.line());
            if record.len() != header.len() {
                return Err(format(
                    line,
                    format!(
                        "{} values, but the header has {} columns",
                        record.len(),
                        header.len()
                    ),
                ));
            }
            let mut numbers = Vec::with_capacity(record.len());
            for (k, field) in record.iter().enumerate() {
                let x: f64 = field.parse().map_err(|_| {
                    format(line, format!("`{}` = `{field}` is not a number", header[k]))
                })?;
                numbers.push(x);
            }
            let t = numbers[0];
            if !t.is_finite() {
                return Err(CompareError::NotFinite {
                    path: path.to_path_buf(),
                    line,
                    column: "time".into(),
                    value: t,
                });
            }
            if let Some(&previous) = file.time.last() {
                if t <= previous {
                    return Err(CompareError::NonMonotoneTime {
                        path: path.to_path_buf(),
                        line,
                        time: t,
                        previous,
                    });
                }
            }
            file.time.push(t);
            file.lines.push(line);
            for (k, x) in numbers[1..].iter().enumerate() {
                file.values[k].push(*x);
            }
        }
        if file.time.is_empty() {
            return Err(format(2, "no rows after the header".into()));
        }
        Ok(file)
    }

    fn column(&self, name: &str) -> Option<&[f64]> {
        let k = self.columns.iter().position(|c| c == name)?;
        Some(&self.values[k])
    }

    /// The first non-finite value of column `name`, as an error.
    fn check_finite(&self, name: &str) -> Result<(), CompareError> {
        let col = self.column(name).unwrap_or(&[]);
        match col.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(i) => Err(match ResultFormat::from_path(&self.path) {
                ResultFormat::Mat => CompareError::Read {
                    path: self.path.clone(),
                    message: format!(
                        "time point {}: {name} = {} is not a finite number",
                        self.lines[i], col[i]
                    ),
                },
                ResultFormat::Csv => CompareError::NotFinite {
                    path: self.path.clone(),
                    line: self.lines[i],
                    column: name.to_string(),
                    value: col[i],
                },
            }),
        }
    }
}

/// The errors of one signal.
#[derive(Clone, Debug, PartialEq)]
pub struct SignalError {
    pub name: String,
    /// RMS of the difference over RMS of the reference; `None` when the
    /// reference is identically 0.
    pub relative_rms: Option<f64>,
    /// RMS of the difference.
    pub rms: f64,
    /// RMS of the reference.
    pub reference_rms: f64,
    /// Largest absolute difference and the (result) time where it occurs.
    pub max_abs: f64,
    pub max_at: f64,
}

/// The comparison of a result with a reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    pub signals: Vec<SignalError>,
    /// The reference was interpolated onto the result's times (the grids
    /// differ).
    pub interpolated: bool,
    /// Number of time points compared.
    pub points: usize,
}

/// Relative tolerance for "the same time grid".
const SAME_TIME: f64 = 1e-12;

/// Compares `signals` (every column common to both files, in the result's
/// order, when empty) over the result's time points.
pub fn compare(
    result: &ResultFile,
    reference: &ResultFile,
    signals: &[String],
) -> Result<Comparison, CompareError> {
    let names: Vec<String> = if signals.is_empty() {
        let common: Vec<String> = result
            .columns
            .iter()
            .filter(|c| reference.columns.contains(c))
            .cloned()
            .collect();
        if common.is_empty() {
            return Err(CompareError::NoCommonColumns {
                result: result.columns.clone(),
                reference: reference.columns.clone(),
            });
        }
        common
    } else {
        for name in signals {
            for file in [result, reference] {
                if file.column(name).is_none() {
                    return Err(CompareError::UnknownSignal {
                        name: name.clone(),
                        path: file.path.clone(),
                    });
                }
            }
        }
        signals.to_vec()
    };
    for name in &names {
        result.check_finite(name)?;
        reference.check_finite(name)?;
    }
    let scale = |t: f64| SAME_TIME * t.abs().max(1.0);
    let same_grid = result.time.len() == reference.time.len()
        && result
            .time
            .iter()
            .zip(&reference.time)
            .all(|(a, b)| (a - b).abs() <= scale(*a));
    // Where each result time falls in the reference: (index, weight) with
    // r(t) = (1 − w)·r[i] + w·r[i + 1].
    let mut at = Vec::with_capacity(result.time.len());
    if same_grid {
        at.extend((0..result.time.len()).map(|i| (i, 0.0)));
    } else {
        let rt = &reference.time;
        let (first, last) = (rt[0], rt[rt.len() - 1]);
        for &t in &result.time {
            if t < first - scale(first) || t > last + scale(last) {
                return Err(CompareError::NotCovered {
                    time: t,
                    ref_start: first,
                    ref_end: last,
                });
            }
            let j = rt.partition_point(|&x| x <= t);
            if j == 0 {
                at.push((0, 0.0));
            } else if j >= rt.len() {
                at.push((rt.len() - 1, 0.0));
            } else {
                let w = (t - rt[j - 1]) / (rt[j] - rt[j - 1]);
                at.push((j - 1, w));
            }
        }
    }
    let signals = names
        .iter()
        .map(|name| {
            let y = result.column(name).expect("checked");
            let r = reference.column(name).expect("checked");
            let (mut sum_d, mut sum_r, mut max_abs, mut max_at) = (0.0, 0.0, 0.0, result.time[0]);
            for (i, &(j, w)) in at.iter().enumerate() {
                let ri = if w == 0.0 {
                    r[j]
                } else {
                    (1.0 - w) * r[j] + w * r[j + 1]
                };
                let d = y[i] - ri;
                sum_d += d * d;
                sum_r += ri * ri;
                if d.abs() > max_abs {
                    max_abs = d.abs();
                    max_at = result.time[i];
                }
            }
            let n = at.len() as f64;
            let (rms, reference_rms) = ((sum_d / n).sqrt(), (sum_r / n).sqrt());
            SignalError {
                name: name.clone(),
                relative_rms: (reference_rms > 0.0).then(|| rms / reference_rms),
                rms,
                reference_rms,
                max_abs,
                max_at,
            }
        })
        .collect();
    Ok(Comparison {
        signals,
        interpolated: !same_grid,
        points: at.len(),
    })
}

impl fmt::Display for Comparison {
    /// One line per signal: relative RMS, RMS, largest absolute error and
    /// where it occurs.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let width = self
            .signals
            .iter()
            .map(|s| s.name.len())
            .max()
            .unwrap_or(6)
            .max(6);
        writeln!(
            f,
            "  {:<width$} {:>12} {:>12} {:>12} {:>12}",
            "signal", "rel. RMS", "RMS", "max |error|", "at t (s)"
        )?;
        for s in &self.signals {
            let rel = match s.relative_rms {
                Some(r) => format!("{r:.4e}"),
                None => "(ref. = 0)".to_string(),
            };
            writeln!(
                f,
                "  {:<width$} {rel:>12} {:>12.4e} {:>12.4e} {:>12}",
                s.name,
                s.rms,
                s.max_abs,
                short_time(s.max_at)
            )?;
        }
        Ok(())
    }
}

/// A time rounded to 12 significant digits for display (`i·h` sums show
/// as 14.9194, not 14.919400000000001).
fn short_time(t: f64) -> String {
    format!("{t:.11e}")
        .parse::<f64>()
        .map_or_else(|_| t.to_string(), |r| r.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(name: &str, text: &str) -> ResultFile {
        ResultFile::parse(Path::new(name), text).unwrap()
    }

    fn err(name: &str, text: &str) -> String {
        ResultFile::parse(Path::new(name), text)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn same_grid_gives_rms_and_maximum_per_signal() {
        let result = file("r.csv", "time,a,b,c\n0,1,0,5\n1,2,0,5\n2,3,1,5\n3,4,0,5\n");
        let reference = file(
            "ref.csv",
            "time,b,a,d\n0,0,1,0\n1,0,2,0\n2,0,2,0\n3,0,4,0\n",
        );
        let c = compare(&result, &reference, &[]).unwrap();
        assert!(!c.interpolated);
        assert_eq!(c.points, 4);
        // Common columns in the result's order: a, b.
        let names: Vec<&str> = c.signals.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["a", "b"]);
        let a = &c.signals[0];
        // a: differences (0, 0, 1, 0): RMS 1/2; reference RMS √(25/4) = 5/2.
        assert!((a.rms - 0.5).abs() < 1e-15);
        assert!((a.reference_rms - 2.5).abs() < 1e-15);
        assert!((a.relative_rms.unwrap() - 0.2).abs() < 1e-15);
        assert_eq!((a.max_abs, a.max_at), (1.0, 2.0));
        // b: the reference is 0: no relative error, the absolute ones stay.
        let b = &c.signals[1];
        assert_eq!(b.relative_rms, None);
        assert_eq!((b.max_abs, b.max_at), (1.0, 2.0));
        assert_eq!(short_time(14.919400000000001), "14.9194");
        assert_eq!(short_time(0.30000000000000004), "0.3");
        assert_eq!(short_time(2.5e-7), "0.00000025");
        let shown = c.to_string();
        assert!(
            shown.contains("(ref. = 0)") && shown.contains("2.0000e-1"),
            "{shown}"
        );
        // Chosen signals only.
        let c = compare(&result, &reference, &["b".to_string()]).unwrap();
        assert_eq!(c.signals.len(), 1);
    }

    #[test]
    fn differing_grids_interpolate_the_reference_linearly() {
        // Reference y = t² on a fine grid; result exactly y = t² at other
        // times: the only error is the interpolation's, ≤ h²/4 = 2.5e-5.
        let mut text = String::from("time,y\n");
        for i in 0..=100 {
            let t = i as f64 * 0.01;
            text += &format!("{t:?},{:?}\n", t * t);
        }
        let reference = file("ref.csv", &text);
        let mut text = String::from("time,y\n");
        for i in 0..=30 {
            let t = i as f64 / 30.0;
            text += &format!("{t:?},{:?}\n", t * t);
        }
        let result = file("r.csv", &text);
        let c = compare(&result, &reference, &[]).unwrap();
        assert!(c.interpolated);
        let s = &c.signals[0];
        assert!(
            s.max_abs > 0.0 && s.max_abs <= 2.5e-5 + 1e-15,
            "{}",
            s.max_abs
        );
        // A linear reference is interpolated exactly.
        let lin = file("ref.csv", "time,y\n0,0\n1,10\n");
        let res = file("r.csv", "time,y\n0,0\n0.25,2.5\n0.7,7\n1,10\n");
        let c = compare(&res, &lin, &[]).unwrap();
        assert!(c.signals[0].max_abs < 1e-15);
        // The reference must cover the result.
        let short = file("ref.csv", "time,y\n0,0\n0.5,5\n");
        let e = compare(&res, &short, &[]).unwrap_err().to_string();
        assert!(e.contains("t = 0.7") && e.contains("0 … 0.5"), "{e}");
    }

    #[test]
    fn bad_files_are_refused_with_file_line_and_column() {
        let e = err("r.csv", "time,a\n0,1\n1,2\n1,3\n");
        assert!(e.contains("r.csv: line 4: time 1 does not increase"), "{e}");
        let e = err("r.csv", "time,a\n0,1\n-1,2\n");
        assert!(e.contains("line 3") && e.contains("previous 0"), "{e}");
        let e = err("r.csv", "t,a\n0,1\n");
        assert!(
            e.contains("line 1: the first column must be `time`, found `t`"),
            "{e}"
        );
        let e = err("r.csv", "time,a\n0,x\n");
        assert!(e.contains("line 2: `a` = `x` is not a number"), "{e}");
        let e = err("r.csv", "time,a\n0,1,2\n");
        assert!(e.contains("line 2: 3 values, but the header has 2"), "{e}");
        let e = err("r.csv", "time,a\n");
        assert!(e.contains("no rows"), "{e}");
        let e = err("r.csv", "");
        assert!(e.contains("r.csv: line 1"), "{e}");
        let e = err("r.csv", "time,a,a\n0,1,1\n");
        assert!(e.contains("`a` appears twice"), "{e}");
        let e = err("r.csv", "time,a\nNaN,1\n");
        assert!(e.contains("line 2: time = NaN"), "{e}");
        // NaN in a compared column: refused when compared, naming it.
        let nan = file("r.csv", "time,a,b\n0,1,1\n1,NaN,1\n");
        let reference = file("ref.csv", "time,a,b\n0,1,1\n1,1,1\n");
        let e = compare(&nan, &reference, &[]).unwrap_err().to_string();
        assert!(
            e.contains("r.csv: line 3: a = NaN is not a finite number"),
            "{e}"
        );
        assert!(compare(&nan, &reference, &["b".into()]).is_ok());
        let e = compare(&reference, &nan, &["a".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("r.csv: line 3"), "{e}");
        // No common columns; an unknown signal.
        let other = file("o.csv", "time,c\n0,1\n");
        let e = compare(&reference, &other, &[]).unwrap_err().to_string();
        assert!(
            e.contains("no common columns") && e.contains("\"c\""),
            "{e}"
        );
        let e = compare(&reference, &other, &["c".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("signal `c` is not a column of ref.csv"), "{e}");
        // A missing file.
        let e = ResultFile::read(Path::new("/nonexistent/r.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("/nonexistent/r.csv: "), "{e}");
    }

    #[test]
    fn comments_and_an_incomplete_run_are_read() {
        let f = file(
            "r.csv",
            "time,a\n0,1\n1,2\n# INCOMPLETE: the run stopped early: boom\n",
        );
        assert_eq!(f.time, [0.0, 1.0]);
        assert_eq!(f.lines, [2, 3]);
        assert_eq!(f.incomplete.as_deref(), Some("the run stopped early: boom"));
        assert!(file("r.csv", "time,a\n0,1\n").incomplete.is_none());
    }
}
