//! CSV result files: [`CsvFile`], the writer of a run's rows (`time`
//! first, then `component.variable` columns, FMPy's convention; a name
//! with a comma, the element `c.A[1,2]` of a 2-D array, quoted), and the
//! number text of every CSV file the host writes (`push_number`: the
//! result files and the sweep's table alike), written so that each
//! number parses back to the same `f64`. A run that stopped early keeps
//! its rows and ends with a comment line `# INCOMPLETE: …` (CSV readers
//! such as numpy's skip `#` lines). Uses [`crate::output_file`] and
//! [`crate::rows`]; chosen by [`crate::formats::ResultFormat`].

use crate::output_file::{OutputError, OutputFile};
use crate::rows::Rows;
use crate::system::RecordedType;
use std::io::Write;
use std::path::Path;

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
/// alone when nothing else is recorded, not `time,`), each a
/// [`header_field`].
fn header(columns: &[String]) -> String {
    std::iter::once("time")
        .chain(columns.iter().map(String::as_str))
        .map(header_field)
        .collect::<Vec<_>>()
        .join(",")
}

/// A column name as a field of a CSV header: as it is, unless it holds a
/// comma, a quote or a line break (the element of a 2-D array, `c.A[1,2]`,
/// in FMI's structured naming), which is quoted as RFC 4180 quotes it
/// (`"c.A[1,2]"`, an inner quote doubled), as FMPy's `write_csv` quotes
/// every name; the input tables are read back with a CSV reader that
/// takes it either way.
pub(crate) fn header_field(name: &str) -> std::borrow::Cow<'_, str> {
    if name.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", name.replace('"', "\"\"")).into()
    } else {
        name.into()
    }
}

/// Append `x` to `text` as [`put_number`] writes it: the number text of
/// every CSV file the host writes, so that a sweep's table and a run's
/// result file write a value alike.
pub(crate) fn push_number(text: &mut Vec<u8>, digits: &mut zmij::Buffer, x: f64) {
    text.reserve(NUMBER_MAX);
    let len = text.len();
    // SAFETY: `reserve` left NUMBER_MAX bytes of room after the text;
    // put_number writes the bytes up to the end it returns
    unsafe {
        let start = text.as_mut_ptr().add(len);
        let end = put_number(start, digits, x);
        text.set_len(len + end.offset_from(start) as usize);
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
    use super::{header, put_number, CsvFile, NUMBER_MAX};
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
