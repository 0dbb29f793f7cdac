//! Result files: CSV with `time` first and `component.variable` columns
//! (FMPy's convention), numbers written so that they parse back exactly.
//! A run that stopped early keeps its rows and ends with a comment line
//! `# INCOMPLETE: …` (CSV readers such as numpy's skip `#` lines).
//!
//! [`ResultWriter`] takes the rows of a run as they are computed
//! ([`crate::master::simulate_streaming`]) and writes them at once, keeping
//! only a summary of each column and the columns to be plotted, so that a
//! run's memory does not grow with its length; [`write_run`] writes a
//! [`Run`] held in memory as the same file. A path ending in `.mat` gets
//! a MAT v4 file instead ([`crate::matfile`], [`create`]). Both write
//! through an [`OutputFile`]: a result is put in place whole (or marked
//! incomplete) or not at all.

use crate::master::{RowSink, Run};
use crate::matfile::MatFile;
use crate::output_file::{OutputError, OutputFile};
use crate::rows::Rows;
use crate::system::RecordedType;
use std::io::Write;
use std::path::Path;

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

/// The result file written to `out` for the columns `time` and `columns`:
/// MAT v4 when its path's extension is `.mat` ([`crate::matfile::is_mat`]),
/// else CSV.
pub fn create(out: OutputFile, columns: &[String]) -> Box<dyn RowFile + Send> {
    if crate::matfile::is_mat(out.path()) {
        Box::new(MatFile::new(out, columns))
    } else {
        Box::new(CsvFile::new(out, columns))
    }
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

/// A CSV result file written row by row to an [`OutputFile`] (so that it
/// is put in place whole, or marked incomplete, or not at all).
pub struct CsvFile {
    header: String,
    header_written: bool,
    out: OutputFile,
    /// Per column, whether it holds whole numbers (an Integer or a
    /// Boolean variable), written as such: `3`, not `3.0`; empty: none.
    whole: Vec<bool>,
    /// The text of a chunk of rows, laid out whole before one `write`
    /// (kept from chunk to chunk: its size is bounded by the chunk's).
    text: Vec<u8>,
}

impl CsvFile {
    /// A CSV file in `out` with the columns `time` and `columns`.
    pub fn new(out: OutputFile, columns: &[String]) -> CsvFile {
        CsvFile {
            header: header(columns),
            header_written: false,
            out,
            whole: Vec::new(),
            text: Vec::new(),
        }
    }

    /// Write the columns whose `types` are Integer or Boolean as whole
    /// numbers (`3`, a Boolean `0` or `1`, as FMPy's `write_csv` does),
    /// not as Reals (`3.0`); `types` has one entry per column
    /// ([`crate::system::System::column_types`]).
    pub fn whole_number_columns(&mut self, types: &[RecordedType]) {
        self.whole = types.iter().map(|t| *t != RecordedType::Real).collect();
        if !self.whole.contains(&true) {
            self.whole.clear();
        }
    }

    /// The path the file is put at.
    pub fn path(&self) -> &Path {
        self.out.path()
    }

    fn out(&mut self) -> std::io::Result<&mut OutputFile> {
        if !self.header_written {
            self.header_written = true;
            writeln!(self.out, "{}", self.header)?;
        }
        Ok(&mut self.out)
    }

    /// The first `times.len()` rows of `rows`, at `times`: laid out in
    /// one buffer, then written with one call.
    pub fn write_rows(&mut self, times: &[f64], rows: &Rows) -> std::io::Result<()> {
        self.out()?;
        let n = times.len().min(rows.len());
        let line_max = (rows.width() + 1) * (NUMBER_MAX + 1);
        let mut text = std::mem::take(&mut self.text);
        text.clear();
        text.reserve(n * line_max);
        let mut digits = zmij::Buffer::new();
        // SAFETY: `reserve` left room for `n` lines of at most `line_max`
        // bytes (each number at most NUMBER_MAX, a separator after each);
        // `end` stays within it, and the bytes up to it are written.
        unsafe {
            let start = text.as_mut_ptr();
            let mut end = start;
            for (t, row) in times.iter().zip(rows).take(n) {
                end = put_number(end, &mut digits, *t);
                if self.whole.is_empty() {
                    for x in row {
                        *end = b',';
                        end = put_number(end.add(1), &mut digits, *x);
                    }
                } else {
                    for (x, whole) in row.iter().zip(&self.whole) {
                        *end = b',';
                        end = if *whole {
                            put_whole(end.add(1), *x)
                        } else {
                            put_number(end.add(1), &mut digits, *x)
                        };
                    }
                }
                *end = b'\n';
                end = end.add(1);
            }
            text.set_len(end.offset_from(start) as usize);
        }
        let written = self.out.write_all(&text);
        self.text = text;
        written
    }

    /// The end of the file: `# INCOMPLETE: the run stopped early: …` if
    /// `error` says why the run stopped early; then the file is put in
    /// place ([`OutputFile::commit`]: not after a write error).
    pub fn finish(mut self, error: Option<&str>) -> Result<(), OutputError> {
        // a write error is kept by the OutputFile and reported by commit
        if let Ok(out) = self.out() {
            if let Some(e) = error {
                let one_line = e.replace(['\n', '\r'], " ");
                let _ = writeln!(out, "# INCOMPLETE: the run stopped early: {one_line}");
            }
        }
        self.out.commit()
    }
}

/// The header line: `time`, then the columns, comma-separated (`time`
/// alone when nothing else is recorded, not `time,`).
fn header(columns: &[String]) -> String {
    std::iter::once("time")
        .chain(columns.iter().map(String::as_str))
        .collect::<Vec<_>>()
        .join(",")
}

/// Write `run` (rows held in memory) to `out` in the format its path
/// names ([`create`]: MAT v4 for `.mat`, else CSV).
pub fn write_run(run: &Run, out: OutputFile) -> Result<(), OutputError> {
    let mut file = create(out, &run.columns);
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

/// The rows of a run as they come: written to a result file ([`create`]),
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
    /// or MAT v4 if its path ends in `.mat`: [`create`]).
    pub fn new(out: OutputFile, columns: &[String]) -> ResultWriter {
        ResultWriter {
            file: create(out, columns),
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

    /// See [`CsvFile::whole_number_columns`].
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

    /// The end of the file (see [`CsvFile::finish`], [`MatFile::finish`]).
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

/// The longest text [`put_number`] writes: `-1.2345678901234567e-308`.
const NUMBER_MAX: usize = 24;

// zmij lays a number out in a buffer of this size, from its start
const _: () = assert!(std::mem::size_of::<zmij::Buffer>() >= NUMBER_MAX);

/// Write `x` at `dst` as Rust's `{x:?}` writes it (the shortest digits
/// that parse back to the same `f64`; plain decimal from 1e-4 to below
/// 1e16, else `1.5e-7`, `2e16`; of two shortest digit strings equally
/// near `x` the even one, where std may take the other, both exact),
/// several times faster; returns the end. The digits come from the `zmij` crate, whose own layout is Rust's
/// except from 1e-5 to below 1e-4 (`0.00001`, Rust's `1e-5`) and from
/// 1e16 up (`1e+16`, Rust's `1e16`), which are laid out again here
/// ([`relaid`]). zmij's buffer is copied whole, a fixed 24 bytes that
/// compile to two moves, rather than by its length (a call to `memcpy`
/// per number, a quarter of the time of writing a CSV file); the bytes
/// after the text are overwritten by what follows it.
///
/// # Safety
/// `dst` has [`NUMBER_MAX`] bytes of room.
#[inline(always)]
unsafe fn put_number(dst: *mut u8, digits: &mut zmij::Buffer, x: f64) -> *mut u8 {
    if !x.is_finite() {
        // SAFETY: as this function's
        return unsafe { put_bytes(dst, format!("{x:?}").as_bytes()) };
    }
    let buffer: *mut zmij::Buffer = digits;
    // SAFETY: `buffer` is `digits`, borrowed for this function
    let text = unsafe { (*buffer).format_finite(x) }.as_bytes();
    let (len, from_start) = (
        text.len(),
        text.as_ptr() == buffer.cast::<u8>().cast_const(),
    );
    let magnitude = x.abs();
    if (1e-4..1e16).contains(&magnitude) || magnitude < 1e-5 {
        if from_start {
            // SAFETY: the buffer holds NUMBER_MAX bytes (checked at compile
            // time), the text at their start; the copy is untyped (bytes
            // past the text may be uninitialized: they are overwritten or
            // past the end); `dst` has room for NUMBER_MAX
            unsafe {
                std::ptr::copy_nonoverlapping(buffer.cast::<u8>().cast_const(), dst, NUMBER_MAX);
                dst.add(len)
            }
        } else {
            // SAFETY: as this function's (len <= NUMBER_MAX)
            unsafe { put_bytes(dst, text) }
        }
    } else {
        // SAFETY: as this function's: relaid writes no more than `text`
        unsafe { relaid(dst, text) }
    }
}

/// Copy `bytes` (at most [`NUMBER_MAX`]) to `dst`; returns the end.
///
/// # Safety
/// `dst` has room for `bytes`.
#[inline]
unsafe fn put_bytes(dst: *mut u8, bytes: &[u8]) -> *mut u8 {
    // SAFETY: as this function's
    unsafe {
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), dst, bytes.len());
        dst.add(bytes.len())
    }
}

/// [`put_number`] for zmij's `[-]0.0000ddd` (Rust's `[-]d.ddde-5`: the
/// exponent one more than the zeros after the point) and `[-]d.ddde+x`
/// (Rust's `[-]d.dddex`), which are no longer than zmij's. Common:
/// LuGre's bristle deflection z, about 1e-5 m, is in every row of a
/// friction run.
///
/// # Safety
/// `dst` has room for `text`.
unsafe fn relaid(dst: *mut u8, text: &[u8]) -> *mut u8 {
    // SAFETY: `dst` has room for `text`, and what is written is no longer
    unsafe {
        let mut end = dst;
        let body = match text {
            [b'-', rest @ ..] => {
                *end = b'-';
                end = end.add(1);
                rest
            }
            _ => text,
        };
        match body.strip_prefix(b"0.") {
            Some(fraction) => {
                let zeros = fraction.iter().take_while(|&&b| b == b'0').count();
                // the shortest digits: no zero ends them
                if let Some((first, rest)) = fraction[zeros..].split_first() {
                    *end = *first;
                    end = end.add(1);
                    if !rest.is_empty() {
                        *end = b'.';
                        end = put_bytes(end.add(1), rest);
                    }
                }
                // `e-` and the exponent (5: `0.0000` has four zeros) in
                // the two bytes of the `0.` left out and those zeros
                end = put_bytes(end, b"e-");
                put_bytes(end, itoa::Buffer::new().format(zeros + 1).as_bytes())
            }
            None => match body.iter().position(|&b| b == b'+') {
                Some(plus) => {
                    end = put_bytes(end, &body[..plus]);
                    put_bytes(end, &body[plus + 1..])
                }
                None => put_bytes(end, body),
            },
        }
    }
}

/// Write the whole number `x` (an Integer or a Boolean read into an
/// `f64`: exact) at `dst`, `3` rather than `3.0`; returns the end.
///
/// # Safety
/// `dst` has [`NUMBER_MAX`] bytes of room.
#[inline]
unsafe fn put_whole(dst: *mut u8, x: f64) -> *mut u8 {
    // (an i32 has at most 11 characters, an i64 20 digits and a sign)
    let n = x as i64;
    // SAFETY: as this function's
    unsafe {
        if n == 0 || n == 1 {
            // a Boolean
            *dst = b'0' + n as u8;
            return dst.add(1);
        }
        put_bytes(dst, itoa::Buffer::new().format(n).as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::{header, put_number, ColumnStats, CsvFile, NUMBER_MAX};
    use crate::output_file::OutputFile;
    use crate::rows::Rows;
    use crate::system::RecordedType;

    /// A chunk laid out in one buffer is what its rows give one by one:
    /// Reals as `{:?}` writes them (non-finite values too), Integers and
    /// Booleans as whole numbers, one line per row.
    #[test]
    fn a_chunk_is_written_as_its_rows_one_by_one() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.csv");
        let out = OutputFile::create(&path, &[]).unwrap();
        let columns = ["a".to_string(), "n".to_string(), "b".to_string()];
        let mut file = CsvFile::new(out, &columns);
        file.whole_number_columns(&[
            RecordedType::Real,
            RecordedType::Integer,
            RecordedType::Boolean,
        ]);
        let rows = [
            [1.4764e-5, -7.0, 1.0],
            [f64::NAN, 2147483647.0, 0.0],
            [f64::NEG_INFINITY, -2147483648.0, 1.0],
            [-1.5e300, 0.0, 0.0],
            [f64::INFINITY, 10.0, 1.0],
        ];
        let times = [0.0, 0.1, 0.2, 0.30000000000000004, 1e16];
        // the rows in two chunks, the second reusing the first's buffer
        let table = Rows::from_rows(3, rows);
        file.write_rows(&times[..2], &Rows::from_rows(3, &rows[..2]))
            .unwrap();
        let rest = Rows::from_rows(3, table.iter().skip(2));
        file.write_rows(&times[2..], &rest).unwrap();
        file.finish(None).unwrap();
        let mut expected = "time,a,n,b\n".to_string();
        for (t, [a, n, b]) in times.iter().zip(rows) {
            expected += &format!("{t:?},{a:?},{},{}\n", n as i64, b as i64);
        }
        assert_eq!(std::fs::read_to_string(&path).unwrap(), expected);
    }

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

    /// No trailing comma when nothing but time is recorded.
    #[test]
    fn the_header_is_time_then_the_columns() {
        assert_eq!(header(&[]), "time");
        assert_eq!(
            header(&["rig.x".to_string(), "friction.F".to_string()]),
            "time,rig.x,friction.F"
        );
    }

    fn written(x: f64) -> String {
        let mut line = [0u8; NUMBER_MAX];
        let start = line.as_mut_ptr();
        // SAFETY: NUMBER_MAX bytes of room; those up to the end written
        let len = unsafe { put_number(start, &mut zmij::Buffer::new(), x).offset_from(start) };
        String::from_utf8(line[..len as usize].to_vec()).unwrap()
    }

    /// Every value is written as `{:?}` writes it, and parses back to the
    /// same bits: edge values, every power of ten and its neighbours, and
    /// millions of random bit patterns and of random magnitudes.
    #[test]
    fn numbers_are_written_as_rust_writes_them_and_parse_back_bit_for_bit() {
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1e-4,
            -1e-4,
            1e16,
            1e15,
            9.999999999999998e15,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            f64::from_bits(0x000f_ffff_ffff_ffff),
            f64::EPSILON,
            1.0 / 3.0,
            123456.789,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in -325..=308 {
            let x: f64 = format!("1e{p}").parse().unwrap();
            for y in [
                x,
                f64::from_bits(x.to_bits() + 1),
                f64::from_bits(x.to_bits().saturating_sub(1)),
            ] {
                values.extend([y, -y, 1.5 * y, 9.87654321 * y]);
            }
        }
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for i in 0..2_000_000u64 {
            let r = next();
            values.push(if i % 2 == 0 {
                f64::from_bits(r)
            } else {
                (r >> 11) as f64 / (1u64 << 53) as f64 * 10f64.powi((i % 48) as i32 - 24)
            });
        }
        let mut ties = 0;
        for x in values {
            let text = written(x);
            let std = format!("{x:?}");
            if text != std {
                // the one difference allowed: of two shortest digit
                // strings equally near `x`, zmij takes the even one
                // (1500000000000000.25 as `…0.2`, std `…0.3`); both parse
                // back to `x`
                assert_eq!(
                    text.len(),
                    std.len(),
                    "bits {:#x}: {text} {std}",
                    x.to_bits()
                );
                assert_eq!(std.parse::<f64>().unwrap().to_bits(), x.to_bits());
                ties += 1;
            }
            let back: f64 = text.parse().unwrap();
            if x.is_nan() {
                assert!(back.is_nan());
            } else {
                assert_eq!(back.to_bits(), x.to_bits(), "{text}");
            }
        }
        // ties are rare (about 0.2 % of these values)
        assert!(ties < 10_000, "{ties} ties");
    }
}
