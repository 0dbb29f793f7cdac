//! Result files in MAT v4, in the trajectory layout Dymola and
//! OpenModelica write (`Aclass` = `Atrajectory`, version `1.1`,
//! `binTrans`), so that `scipy.io.loadmat`, DyMat, OMPython's
//! `readSimulationResult`, MATLAB and Dymola read them. A file is a
//! sequence of matrices, each a header of five little-endian `i32`
//! (type `MOPT`: M = 0 little-endian IEEE, O = 0, P the element type,
//! T = 0 numeric or 1 text; rows; columns; 0 for real; the length of the
//! name with its NUL), the name, then the elements column by column
//! (MATLAB's "MAT-File Format", Level 4). The matrices, in order:
//!
//! | matrix | type | size | holds |
//! |---|---|---|---|
//! | `Aclass` | text | 4 × 11 | `Atrajectory`, `1.1`, ``, `binTrans` |
//! | `name` | text | longest name × n | one name per column: `time`, then the columns |
//! | `description` | text | longest × n | `Time in [s]` for time, the others empty |
//! | `dataInfo` | `i32` | 4 × n | per variable: matrix (0 for time: in every one; 2), column in it (1-based), interpolation 0 (linear), extrapolation −1 (none) |
//! | `data_1` | `f64` | 1 × 2 | the first and last time (no parameters) |
//! | `data_2` | `f64` | n × points | one time point per column: the time, then the values |
//! | `incomplete` | text | 1 × length | only when the run stopped early: `the run stopped early: …` |
//!
//! Since `data_2` holds one time point per column and comes last, the rows
//! of a run are written as they come, each as it is (`f64`, exact); the
//! number of points in `data_2`'s header and the last time in `data_1`
//! are written in place when the run ends. A run that stopped early keeps
//! its rows and adds the `incomplete` matrix after `data_2` (the CSV's
//! `# INCOMPLETE` line): readers of the trajectory layout skip a matrix
//! they do not know; `scipy.io.loadmat` shows it as the key `incomplete`.

use crate::output_file::{OutputError, OutputFile};
use crate::rows::Rows;
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom, Write};
use std::path::Path;

/// Element types (the P digit of a header's type).
const DOUBLE: i32 = 0;
const FLOAT: i32 = 1;
const INT32: i32 = 2;
const INT16: i32 = 3;
const UINT16: i32 = 4;
const UINT8: i32 = 5;
/// The type of a text matrix: `uint8` elements (P = 5), text (T = 1).
const TEXT: i32 = 10 * UINT8 + 1;
/// The type of a matrix of `i32` (P = 2).
const INT32_MATRIX: i32 = 10 * INT32;
/// The largest number of time points a header can give (`i32`).
pub const MAX_POINTS: usize = i32::MAX as usize;

/// The header of a matrix and its name.
fn header(
    out: &mut impl Write,
    kind: i32,
    rows: usize,
    cols: usize,
    name: &str,
) -> std::io::Result<()> {
    let count = |n: usize| {
        i32::try_from(n).map_err(|_| {
            std::io::Error::other(format!(
                "matrix `{name}`: {n} rows or columns, MAT v4 holds at most {MAX_POINTS}"
            ))
        })
    };
    for x in [kind, count(rows)?, count(cols)?, 0, count(name.len() + 1)?] {
        out.write_all(&x.to_le_bytes())?;
    }
    out.write_all(name.as_bytes())?;
    out.write_all(&[0])
}

/// A text matrix of `strings`, one per column (`binTrans`), each padded
/// with spaces to the longest (at least one character, so that the
/// matrix has rows).
fn text_columns(out: &mut impl Write, name: &str, strings: &[&str]) -> std::io::Result<()> {
    let longest = strings.iter().map(|s| s.len()).max().unwrap_or(0).max(1);
    header(out, TEXT, longest, strings.len(), name)?;
    for s in strings {
        out.write_all(s.as_bytes())?;
        out.write_all(&vec![b' '; longest - s.len()])?;
    }
    Ok(())
}

/// A MAT result file written row by row ([module docs](self)) to an
/// [`OutputFile`] (put in place whole, or marked incomplete, or not at
/// all), as [`crate::csvfile::CsvFile`].
pub struct MatFile {
    out: OutputFile,
    columns: Vec<String>,
    open: Option<Open>,
}

/// A file being written: where the numbers to patch at the end are, and
/// the points written so far.
struct Open {
    /// Offset of `data_1`'s last time.
    last_time_at: u64,
    /// Offset of `data_2`'s column count.
    points_at: u64,
    points: usize,
    last_time: f64,
    /// The bytes of one chunk of rows, used again for the next.
    bytes: Vec<u8>,
}

impl MatFile {
    /// A file in `out` with the columns `time` and `columns`.
    pub fn new(out: OutputFile, columns: &[String]) -> MatFile {
        MatFile {
            out,
            columns: columns.to_vec(),
            open: None,
        }
    }

    /// The path the file is put at.
    pub fn path(&self) -> &Path {
        self.out.path()
    }

    /// The file, its matrices up to `data_2`'s header written, `first`
    /// the time of its first point.
    fn open(&mut self, first: f64) -> std::io::Result<&mut Open> {
        if self.open.is_none() {
            let out = &mut self.out;
            // Aclass: 4 strings of 11 characters, written column by column
            let aclass = ["Atrajectory", "1.1        ", "           ", "binTrans   "];
            header(out, TEXT, 4, 11, "Aclass")?;
            for c in 0..11 {
                for s in aclass {
                    out.write_all(&s.as_bytes()[c..c + 1])?;
                }
            }
            let names: Vec<&str> = std::iter::once("time")
                .chain(self.columns.iter().map(String::as_str))
                .collect();
            text_columns(out, "name", &names)?;
            let mut descriptions = vec![""; names.len()];
            descriptions[0] = "Time in [s]";
            text_columns(out, "description", &descriptions)?;
            header(out, INT32_MATRIX, 4, names.len(), "dataInfo")?;
            out.write_all(&[0i32, 1, 0, -1].map(i32::to_le_bytes).concat())?;
            for k in 1..names.len() {
                let column = i32::try_from(k + 1).map_err(std::io::Error::other)?;
                out.write_all(&[2i32, column, 0, -1].map(i32::to_le_bytes).concat())?;
            }
            header(out, DOUBLE, 1, 2, "data_1")?;
            out.write_all(&first.to_le_bytes())?;
            let last_time_at = out.stream_position()?;
            out.write_all(&first.to_le_bytes())?;
            let points_at = out.stream_position()? + 8;
            header(out, DOUBLE, names.len(), 0, "data_2")?;
            self.open = Some(Open {
                last_time_at,
                points_at,
                points: 0,
                last_time: first,
                bytes: Vec::new(),
            });
        }
        Ok(self.open.as_mut().expect("opened above"))
    }

    /// The first `times.len()` rows of `rows`, at `times`: one column of
    /// `data_2` each, the time then the row.
    pub fn write_rows(&mut self, times: &[f64], rows: &Rows) -> std::io::Result<()> {
        let Some(&first) = times.first() else {
            return Ok(());
        };
        let file = self.open(first)?;
        if file.points + times.len() > MAX_POINTS {
            return Err(std::io::Error::other(format!(
                "more than {MAX_POINTS} time points, the most a MAT v4 file holds: write a CSV (--out NAME.csv)"
            )));
        }
        // the chunk's bytes laid out first, then filled 8 at a time: no
        // growth check per number (a third of the cost of writing them)
        let point = 8 * (rows.width() + 1);
        file.bytes.resize(point * times.len(), 0);
        for ((bytes, t), row) in file.bytes.chunks_exact_mut(point).zip(times).zip(rows) {
            let (time, values) = bytes.split_at_mut(8);
            time.copy_from_slice(&t.to_le_bytes());
            for (b, x) in values.chunks_exact_mut(8).zip(row) {
                b.copy_from_slice(&x.to_le_bytes());
            }
        }
        file.points += times.len();
        file.last_time = times[times.len() - 1];
        let bytes = std::mem::take(&mut file.bytes);
        let written = self.out.write_all(&bytes);
        if let Some(file) = &mut self.open {
            file.bytes = bytes;
        }
        written
    }

    /// The end of the file: the `incomplete` matrix if `error` says why
    /// the run stopped early, then the number of points and the last time
    /// written in place; then the file is put in place
    /// ([`OutputFile::commit`]; not after a write error, which it reports).
    pub fn finish(mut self, error: Option<&str>) -> Result<(), OutputError> {
        // a write error is kept by the OutputFile and reported by commit
        let _ = self.write_end(error);
        self.out.commit()
    }

    fn write_end(&mut self, error: Option<&str>) -> std::io::Result<()> {
        let (last_time_at, points_at, points, last_time) = {
            let file = self.open(0.0)?;
            (
                file.last_time_at,
                file.points_at,
                file.points,
                file.last_time,
            )
        };
        let out = &mut self.out;
        if let Some(e) = error {
            let one_line = format!("the run stopped early: {}", e.replace(['\n', '\r'], " "));
            header(out, TEXT, 1, one_line.len(), "incomplete")?;
            out.write_all(one_line.as_bytes())?;
        }
        out.seek(SeekFrom::Start(last_time_at))?;
        out.write_all(&last_time.to_le_bytes())?;
        out.seek(SeekFrom::Start(points_at))?;
        // at most MAX_POINTS (write_rows)
        out.write_all(&(points as i32).to_le_bytes())?;
        out.flush()
    }
}

/// What [`read`] finds in a MAT result file.
#[derive(Clone, Debug, PartialEq)]
pub struct MatResult {
    /// The variables of `data_2` but time, in the file's order.
    pub columns: Vec<String>,
    pub time: Vec<f64>,
    /// `values[k][i]`: column `k` at point `i`.
    pub values: Vec<Vec<f64>>,
    /// The text of the `incomplete` matrix (`the run stopped early: …`,
    /// as the CSV's `# INCOMPLETE:` line), if the file has one.
    pub incomplete: Option<String>,
}

/// One matrix of a MAT v4 file: its size and elements as `f64` (text as
/// its bytes).
struct Matrix {
    rows: usize,
    cols: usize,
    values: Vec<f64>,
    text: Vec<u8>,
}

impl Matrix {
    /// Element (`i`, `j`), stored column by column.
    fn at(&self, i: usize, j: usize) -> f64 {
        self.values[j * self.rows + i]
    }

    /// The strings of a text matrix, one per column (`binTrans`) or one
    /// per row, trailing spaces and NULs removed.
    fn strings(&self, per_column: bool) -> Vec<String> {
        let (count, length) = if per_column {
            (self.cols, self.rows)
        } else {
            (self.rows, self.cols)
        };
        (0..count)
            .map(|s| {
                let bytes: Vec<u8> = (0..length)
                    .map(|c| match per_column {
                        true => self.text[s * self.rows + c],
                        false => self.text[c * self.rows + s],
                    })
                    .collect();
                String::from_utf8_lossy(&bytes)
                    .trim_end_matches([' ', '\0'])
                    .to_string()
            })
            .collect()
    }
}

/// The next matrix of `input` and its name; `None` at the end of the file.
fn next_matrix(input: &mut impl Read) -> Result<Option<(String, Matrix)>, String> {
    let mut head = [0u8; 20];
    match input.read(&mut head[..1]) {
        Ok(0) => return Ok(None),
        Ok(_) => {}
        Err(e) => return Err(e.to_string()),
    }
    input
        .read_exact(&mut head[1..])
        .map_err(|_| "the file ends inside a matrix header".to_string())?;
    let field = |k: usize| i32::from_le_bytes(head[4 * k..4 * k + 4].try_into().expect("4 bytes"));
    let (kind, rows, cols, imaginary, name_length) =
        (field(0), field(1), field(2), field(3), field(4));
    if !(0..=52).contains(&kind) || kind % 10 > 1 || (kind / 10) % 10 > UINT8 {
        return Err(format!(
            "matrix type {kind} is not one of a little-endian MAT v4 file (MOPT with M = 0, O = 0, P ≤ 5, T ≤ 1): not a MAT v4 file, or a big-endian one"
        ));
    }
    if rows < 0 || cols < 0 || !(1..=4096).contains(&name_length) || imaginary != 0 {
        return Err(format!(
            "matrix header with {rows} rows, {cols} columns, a name of {name_length} bytes, imaginary flag {imaginary}: not a real matrix of a MAT v4 file"
        ));
    }
    let mut name = vec![0u8; name_length as usize];
    input
        .read_exact(&mut name)
        .map_err(|_| "the file ends inside a matrix name".to_string())?;
    let name = String::from_utf8_lossy(&name)
        .trim_end_matches('\0')
        .to_string();
    let (rows, cols) = (rows as usize, cols as usize);
    let count = rows
        .checked_mul(cols)
        .ok_or_else(|| format!("matrix `{name}`: {rows} × {cols} elements"))?;
    let precision = (kind / 10) % 10;
    let size = match precision {
        DOUBLE => 8,
        FLOAT | INT32 => 4,
        INT16 | UINT16 => 2,
        _ => 1,
    };
    let mut bytes = Vec::new();
    input
        .take((count * size) as u64)
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() != count * size {
        return Err(format!(
            "matrix `{name}`: the file ends after {} of its {} elements",
            bytes.len() / size,
            count
        ));
    }
    let values: Vec<f64> = match precision {
        DOUBLE => bytes
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
            .collect(),
        FLOAT => bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes")) as f64)
            .collect(),
        INT32 => bytes
            .chunks_exact(4)
            .map(|b| i32::from_le_bytes(b.try_into().expect("4 bytes")) as f64)
            .collect(),
        INT16 => bytes
            .chunks_exact(2)
            .map(|b| i16::from_le_bytes(b.try_into().expect("2 bytes")) as f64)
            .collect(),
        UINT16 => bytes
            .chunks_exact(2)
            .map(|b| u16::from_le_bytes(b.try_into().expect("2 bytes")) as f64)
            .collect(),
        _ => bytes.iter().map(|&b| b as f64).collect(),
    };
    let text = if precision == UINT8 {
        bytes
    } else {
        Vec::new()
    };
    Ok(Some((
        name,
        Matrix {
            rows,
            cols,
            values,
            text,
        },
    )))
}

/// Read a MAT v4 result file in the trajectory layout ([module
/// docs](self)), as `fricsim run` writes it or Dymola and OpenModelica do
/// (`binTrans` or `binNormal`, `f64` or `f32` data): the variables of
/// `data_2` against its time. Parameters (`data_1`) are not read. Every
/// message names the file.
pub fn read(path: &Path) -> Result<MatResult, String> {
    let shown = path.display();
    let file = File::open(path).map_err(|e| format!("{shown}: {e}"))?;
    let mut input = BufReader::with_capacity(1 << 16, file);
    let mut matrices = std::collections::HashMap::new();
    while let Some((name, matrix)) = next_matrix(&mut input).map_err(|e| format!("{shown}: {e}"))? {
        matrices.insert(name, matrix);
    }
    let get = |name: &str| {
        matrices.get(name).ok_or_else(|| {
            format!("{shown}: no matrix `{name}`: not a result file in the Dymola/OpenModelica trajectory layout (Aclass, name, description, dataInfo, data_1, data_2)")
        })
    };
    let aclass = get("Aclass")?.strings(false);
    if aclass.first().map(String::as_str) != Some("Atrajectory") {
        return Err(format!(
            "{shown}: Aclass is {aclass:?}: not a trajectory (`Atrajectory`)"
        ));
    }
    // without a fourth line, the layout is binNormal (Dymola's rule)
    let transposed = match aclass.get(3).map(String::as_str) {
        Some("binTrans") => true,
        None | Some("binNormal") => false,
        Some(other) => {
            return Err(format!(
                "{shown}: Aclass layout `{other}`: expected binTrans or binNormal"
            ))
        }
    };
    let names = get("name")?.strings(transposed);
    let info = get("dataInfo")?;
    let data = get("data_2")?;
    let (width, points) = if transposed {
        (data.rows, data.cols)
    } else {
        (data.cols, data.rows)
    };
    let value = |variable: usize, point: usize| match transposed {
        true => data.at(variable, point),
        false => data.at(point, variable),
    };
    let info_of = |variable: usize, field: usize| -> Option<i64> {
        let (i, j) = if transposed {
            (field, variable)
        } else {
            (variable, field)
        };
        (i < info.rows && j < info.cols).then(|| info.at(i, j) as i64)
    };
    let mut time_row = None;
    let mut columns = Vec::new();
    let mut values = Vec::new();
    for (k, name) in names.iter().enumerate() {
        let (Some(matrix), Some(index)) = (info_of(k, 0), info_of(k, 1)) else {
            return Err(format!(
                "{shown}: dataInfo has no entry for variable {} `{name}`",
                k + 1
            ));
        };
        let row = index.unsigned_abs() as usize;
        if (matrix == 0 || matrix == 2) && (row == 0 || row > width) {
            return Err(format!(
                "{shown}: dataInfo puts `{name}` in row {index} of data_2, which has {width}"
            ));
        }
        match matrix {
            0 => time_row = Some(row - 1),
            2 => {
                let sign = if index < 0 { -1.0 } else { 1.0 };
                columns.push(name.clone());
                values.push((0..points).map(|p| sign * value(row - 1, p)).collect());
            }
            _ => {}
        }
    }
    let time_row = time_row
        .ok_or_else(|| format!("{shown}: no time variable (dataInfo matrix 0) among {names:?}"))?;
    let time: Vec<f64> = (0..points).map(|p| value(time_row, p)).collect();
    let incomplete = matrices
        .get("incomplete")
        .map(|m| m.strings(false).concat());
    Ok(MatResult {
        columns,
        time,
        values,
        incomplete,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(width: usize, values: &[&[f64]]) -> Rows {
        Rows::from_rows(width, values.iter())
    }

    /// Written in two chunks and read back: the same numbers bit for bit,
    /// the names, and no `incomplete` matrix.
    #[test]
    fn a_file_written_in_chunks_reads_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/r.mat");
        let columns = vec!["rig.x".to_string(), "friction.F".to_string()];
        let mut file = MatFile::new(OutputFile::create(&path, &[]).unwrap(), &columns);
        let tiny = f64::from_bits(1);
        file.write_rows(&[0.0, 0.1], &rows(2, &[&[1.0 / 3.0, -0.0], &[tiny, 1e300]]))
            .unwrap();
        file.write_rows(&[0.2], &rows(2, &[&[f64::NAN, -2.5], &[9.0, 9.0]]))
            .unwrap();
        file.finish(None).unwrap();
        let r = read(&path).unwrap();
        assert_eq!(r.columns, columns);
        assert_eq!(r.time, [0.0, 0.1, 0.2]);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&r.values[0]),
            bits(&[1.0 / 3.0, tiny, f64::NAN]),
            "{:?}",
            r.values[0]
        );
        assert_eq!(bits(&r.values[1]), bits(&[-0.0, 1e300, -2.5]));
        assert_eq!(r.incomplete, None);
    }

    #[test]
    fn a_run_that_stopped_early_says_why() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.MAT");
        let mut file = MatFile::new(
            OutputFile::create(&path, &[]).unwrap(),
            &["a.y".to_string()],
        );
        file.write_rows(&[0.0], &rows(1, &[&[1.0]])).unwrap();
        file.finish(Some("at t = 0: fmi2DoStep failed\nin a"))
            .unwrap();
        let r = read(&path).unwrap();
        assert_eq!(r.time, [0.0]);
        assert_eq!(
            r.incomplete.as_deref(),
            Some("the run stopped early: at t = 0: fmi2DoStep failed in a")
        );
    }

    #[test]
    fn bad_files_are_refused_naming_the_file_and_the_problem() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.mat");
        let err = |bytes: &[u8]| {
            std::fs::write(&path, bytes).unwrap();
            read(&path).unwrap_err()
        };
        let e = err(b"time,rig.x\n0,1\n0.1,2\n0.2,3\n");
        assert!(e.starts_with(&format!("{}: ", path.display())), "{e}");
        assert!(e.contains("not a MAT v4 file"), "{e}");
        let e = err(&[0; 7]);
        assert!(e.contains("ends inside a matrix header"), "{e}");
        // a good file cut short inside data_2
        let good = dir.path().join("good.mat");
        let mut file = MatFile::new(
            OutputFile::create(&good, &[]).unwrap(),
            &["a.y".to_string()],
        );
        file.write_rows(&[0.0, 1.0], &rows(1, &[&[1.0], &[2.0]]))
            .unwrap();
        file.finish(None).unwrap();
        let bytes = std::fs::read(&good).unwrap();
        let e = err(&bytes[..bytes.len() - 4]);
        assert!(
            e.contains("matrix `data_2`: the file ends after 3 of its 4 elements"),
            "{e}"
        );
        // a MAT file without the trajectory matrices
        let mut other = Vec::new();
        header(&mut other, DOUBLE, 1, 1, "x").unwrap();
        other.extend_from_slice(&1.0f64.to_le_bytes());
        let e = err(&other);
        assert!(e.contains("no matrix `Aclass`"), "{e}");
        let e = read(Path::new("/nonexistent/r.mat")).unwrap_err();
        assert!(e.starts_with("/nonexistent/r.mat: "), "{e}");
    }

    /// Dymola's other layout (`binNormal`: a string per row, a point per
    /// row), `f32` data, and a negated alias are read too.
    #[test]
    fn bin_normal_float_data_and_negated_aliases_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("normal.mat");
        let mut out = Vec::new();
        let text_rows = |out: &mut Vec<u8>, name: &str, strings: &[&str]| {
            let longest = strings.iter().map(|s| s.len()).max().unwrap();
            header(out, TEXT, strings.len(), longest, name).unwrap();
            for c in 0..longest {
                for s in strings {
                    out.push(*s.as_bytes().get(c).unwrap_or(&b' '));
                }
            }
        };
        text_rows(&mut out, "Aclass", &["Atrajectory", "1.1", "", "binNormal"]);
        text_rows(&mut out, "name", &["Time", "x", "minus_x"]);
        text_rows(&mut out, "description", &["", "", ""]);
        header(&mut out, INT32_MATRIX, 3, 4, "dataInfo").unwrap();
        // column by column: matrices, columns, interpolation, extrapolation
        for x in [0i32, 2, 2, 1, 2, -2, 0, 0, 0, -1, -1, -1] {
            out.extend_from_slice(&x.to_le_bytes());
        }
        header(&mut out, 10 * FLOAT, 2, 2, "data_2").unwrap();
        // points in rows: time column (0, 1), x column (0.5, 0.25)
        for x in [0.0f32, 1.0, 0.5, 0.25] {
            out.extend_from_slice(&x.to_le_bytes());
        }
        std::fs::write(&path, out).unwrap();
        let r = read(&path).unwrap();
        assert_eq!(r.columns, ["x", "minus_x"]);
        assert_eq!(r.time, [0.0, 1.0]);
        assert_eq!(r.values, [vec![0.5, 0.25], vec![-0.5, -0.25]]);
    }
}
