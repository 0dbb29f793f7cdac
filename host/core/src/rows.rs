//! [`Rows`]: a table of numbers with a fixed number of columns, stored row
//! after row in one buffer.
//!
//! A run records one row of outputs per communication point, tens of
//! thousands of them; a `Vec<Vec<f64>>` would allocate (and later free)
//! each row on its own, which costs as much as a large part of the host's
//! work in a macro step. Here a new row is a few more numbers at the end
//! of one buffer, and reading stays as natural: `rows[i][k]`,
//! `rows.last()`, `for row in &rows`.
//!
//! A run that needs only a summary (`fricsim sweep`: the last row and each
//! column's RMS) records into a table that keeps its last rows only
//! ([`Rows::windowed`]): when its buffer is full, the rows but the last are
//! folded into per-column sums of squares and the buffer is used again.
//! A 20 s run at 1e-4 s then holds about 100 kB instead of 19 MB (and
//! the times of the rows it holds only, [`crate::master::Run::time`]), so
//! parallel runs neither wait on fresh memory nor share the memory bus
//! for numbers nobody reads.

use std::ops::{Index, IndexMut};

/// Rows of `width` numbers each, row-major in one `Vec<f64>`.
#[derive(Clone, Default)]
pub struct Rows {
    /// Numbers per row.
    width: usize,
    /// Number of rows (kept apart: with `width` 0 it does not follow from
    /// `values`).
    len: usize,
    /// Row 0, then row 1, …: the first `len · width` numbers. Any after
    /// them are zeros: rows made ready ahead ([`Rows::with_capacity`]), so
    /// that a new row costs no filling with zeros, one row at a time.
    values: Vec<f64>,
    /// For a table that keeps its last rows only ([`Rows::windowed`]):
    /// what the rows folded out of it leave behind.
    folded: Option<Box<Folded>>,
}

/// The rows a [`Rows::windowed`] table no longer holds.
#[derive(Clone, Debug, PartialEq)]
struct Folded {
    /// How many.
    rows: usize,
    /// Per column, `Σ y²` over them, summed in row order.
    square_sums: Vec<f64>,
}

impl PartialEq for Rows {
    /// The same rows (the zeros made ready ahead do not count).
    fn eq(&self, other: &Rows) -> bool {
        self.width == other.width
            && self.len == other.len
            && self.as_flat() == other.as_flat()
            && self.folded == other.folded
    }
}

impl std::fmt::Debug for Rows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Rows")
            .field("width", &self.width)
            .field("len", &self.len)
            .field("values", &self.as_flat())
            .field("folded", &self.folded)
            .finish()
    }
}

impl Rows {
    /// No rows yet, each of `width` numbers.
    pub fn new(width: usize) -> Rows {
        Rows {
            width,
            len: 0,
            values: Vec::new(),
            folded: None,
        }
    }

    /// No rows yet, with room for `rows` rows of `width` numbers before
    /// any allocation: zeros made ready at once (fresh zeroed memory from
    /// the allocator), so that [`Rows::push_zeros`] has nothing to fill.
    pub fn with_capacity(width: usize, rows: usize) -> Rows {
        Rows {
            width,
            len: 0,
            values: vec![0.0; width * rows],
            folded: None,
        }
    }

    /// No rows yet, each of `width` numbers, keeping at most the last
    /// `window` of them (at least 2): when the buffer is full, every row
    /// but the last is folded into per-column sums of squares
    /// ([`Rows::square_sums`]) and counted ([`Rows::rows_pushed`]), and no
    /// longer read. [`Rows::last`] and [`Rows::pop`] work as in any table,
    /// so a run records into it as into any other.
    ///
    /// # Panics
    /// If `window` is below 2.
    pub fn windowed(width: usize, window: usize) -> Rows {
        assert!(window >= 2, "a window of {window} rows: at least 2");
        Rows {
            folded: Some(Box::new(Folded {
                rows: 0,
                square_sums: vec![0.0; width],
            })),
            ..Rows::with_capacity(width, window)
        }
    }

    /// The rows of `rows`, each of which must hold `width` numbers.
    ///
    /// # Panics
    /// If a row is of another width.
    pub fn from_rows<R: AsRef<[f64]>>(width: usize, rows: impl IntoIterator<Item = R>) -> Rows {
        let mut table = Rows::new(width);
        for row in rows {
            table.push_row(row.as_ref());
        }
        table
    }

    /// Numbers per row.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Number of rows held (of a [`Rows::windowed`] table: since the last
    /// fold).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Number of rows pushed and not popped: [`Rows::len`], and the rows
    /// a [`Rows::windowed`] table folded out.
    pub fn rows_pushed(&self) -> usize {
        self.len + self.rows_folded()
    }

    /// Whether the table keeps its last rows only ([`Rows::windowed`]).
    pub fn is_windowed(&self) -> bool {
        self.folded.is_some()
    }

    /// Number of rows a [`Rows::windowed`] table folded out (0 for any
    /// other): row `i` held is row `rows_folded() + i` of those pushed
    /// (counting from 0).
    pub fn rows_folded(&self) -> usize {
        self.folded.as_ref().map_or(0, |f| f.rows)
    }

    /// Per column, `Σ y²` over every row pushed and not popped, summed in
    /// row order (the rows folded out of a [`Rows::windowed`] table
    /// included): the same numbers, bit for bit, from a windowed table as
    /// from one that kept every row.
    pub fn square_sums(&self) -> Vec<f64> {
        let mut sums = match &self.folded {
            Some(f) => f.square_sums.clone(),
            None => vec![0.0; self.width],
        };
        for row in self {
            for (sum, y) in sums.iter_mut().zip(row) {
                *sum += y * y;
            }
        }
        sums
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Row `i`, if there is one.
    pub fn get(&self, i: usize) -> Option<&[f64]> {
        (i < self.len).then(|| &self.values[i * self.width..(i + 1) * self.width])
    }

    pub fn first(&self) -> Option<&[f64]> {
        self.get(0)
    }

    #[inline] // read at every macro step
    pub fn last(&self) -> Option<&[f64]> {
        // the last row ends where the rows end
        let end = self.len * self.width;
        (self.len > 0).then(|| &self.values[end - self.width..end])
    }

    /// Append a copy of `row`.
    ///
    /// # Panics
    /// If `row` does not hold [`Rows::width`] numbers.
    pub fn push_row(&mut self, row: &[f64]) {
        assert_eq!(
            row.len(),
            self.width,
            "a row of {} numbers in a table of {} columns",
            row.len(),
            self.width
        );
        self.push_zeros().copy_from_slice(row);
    }

    /// Append a row of zeros and return it to be filled in place (no
    /// row is built elsewhere and copied).
    #[inline] // once per communication point, a few instructions
    pub fn push_zeros(&mut self) -> &mut [f64] {
        let start = self.len * self.width;
        let end = start.wrapping_add(self.width);
        // the usual case: a row made ready (the test also spares the
        // slicing its own)
        if start <= end && end <= self.values.len() {
            self.len += 1;
            return &mut self.values[start..end];
        }
        let start = self.make_room();
        self.len += 1;
        &mut self.values[start..start + self.width]
    }

    /// Room for one more row when none is made ready; where it starts. A
    /// [`Rows::windowed`] table folds every row but the last out of its
    /// full buffer and moves the last to the front; any other grows by
    /// one row (the numbers after the rows are zeros still).
    #[cold]
    #[inline(never)]
    fn make_room(&mut self) -> usize {
        let width = self.width;
        let Some(folded) = self.folded.as_deref_mut() else {
            let start = self.len * width;
            self.values.resize(start + width, 0.0);
            return start;
        };
        // len ≥ 2 here: the window holds at least two rows, and only a full
        // buffer lacks room (width > 0, or nothing would be missing)
        let folding = self.len - 1;
        for row in self.values[..folding * width].chunks_exact(width) {
            for (sum, y) in folded.square_sums.iter_mut().zip(row) {
                *sum += y * y;
            }
        }
        folded.rows += folding;
        self.values
            .copy_within(folding * width..self.len * width, 0);
        self.values[width..].fill(0.0);
        self.len = 1;
        width
    }

    /// Drop every row but the last, which becomes row 0 (the numbers
    /// after it are zeros made ready again): for a run that hands its
    /// rows on as it goes and reads the next step's inputs from the last.
    ///
    /// # Panics
    /// For a [`Rows::windowed`] table, whose rows are folded instead.
    pub fn keep_last(&mut self) {
        assert!(!self.is_windowed(), "keep_last on a windowed table");
        if self.len <= 1 {
            return;
        }
        let width = self.width;
        let end = self.len * width;
        self.values.copy_within(end - width..end, 0);
        self.values[width..end].fill(0.0);
        self.len = 1;
    }

    /// Drop every row (their numbers become zeros made ready again), so
    /// that the table can record again without allocating.
    pub fn clear(&mut self) {
        self.values[..self.len * self.width].fill(0.0);
        self.len = 0;
    }

    /// Rows that fit before the table allocates again.
    pub fn capacity(&self) -> usize {
        self.values.len().checked_div(self.width).unwrap_or(0)
    }

    /// Remove the last row, if any (its numbers become zeros made ready
    /// for the next row).
    pub fn pop(&mut self) {
        if self.len > 0 {
            self.len -= 1;
            let start = self.len * self.width;
            self.values[start..start + self.width].fill(0.0);
        }
    }

    /// The rows in order.
    pub fn iter(&self) -> Iter<'_> {
        Iter {
            rest: self.as_flat(),
            width: self.width,
            len: self.len,
        }
    }

    /// Column `k` from the first row to the last.
    ///
    /// # Panics
    /// If `k` is not below [`Rows::width`] (and there is a row).
    pub fn column(&self, k: usize) -> impl DoubleEndedIterator<Item = f64> + '_ {
        self.iter().map(move |row| row[k])
    }

    /// All numbers, row after row.
    pub fn as_flat(&self) -> &[f64] {
        &self.values[..self.len * self.width]
    }
}

impl Index<usize> for Rows {
    type Output = [f64];

    /// Row `i`.
    ///
    /// # Panics
    /// If there is no row `i`.
    fn index(&self, i: usize) -> &[f64] {
        assert!(i < self.len, "row {i} of a table of {} rows", self.len);
        &self.values[i * self.width..(i + 1) * self.width]
    }
}

impl IndexMut<usize> for Rows {
    fn index_mut(&mut self, i: usize) -> &mut [f64] {
        assert!(i < self.len, "row {i} of a table of {} rows", self.len);
        &mut self.values[i * self.width..(i + 1) * self.width]
    }
}

/// The rows of a [`Rows`], in order, as slices.
#[derive(Clone, Debug)]
pub struct Iter<'a> {
    /// The numbers of the rows not yet returned.
    rest: &'a [f64],
    width: usize,
    /// Rows not yet returned.
    len: usize,
}

impl<'a> Iterator for Iter<'a> {
    type Item = &'a [f64];

    fn next(&mut self) -> Option<&'a [f64]> {
        if self.len == 0 {
            return None;
        }
        let (row, rest) = self.rest.split_at(self.width);
        self.rest = rest;
        self.len -= 1;
        Some(row)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        (self.len, Some(self.len))
    }
}

impl DoubleEndedIterator for Iter<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        if self.len == 0 {
            return None;
        }
        let (rest, row) = self.rest.split_at(self.rest.len() - self.width);
        self.rest = rest;
        self.len -= 1;
        Some(row)
    }
}

impl ExactSizeIterator for Iter<'_> {}

impl<'a> IntoIterator for &'a Rows {
    type Item = &'a [f64];
    type IntoIter = Iter<'a>;

    fn into_iter(self) -> Iter<'a> {
        self.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::Rows;

    #[test]
    fn rows_read_as_a_list_of_rows() {
        let mut rows = Rows::with_capacity(2, 3);
        assert!(rows.is_empty() && rows.last().is_none());
        rows.push_row(&[1.0, 2.0]);
        rows.push_zeros().copy_from_slice(&[3.0, 4.0]);
        rows.push_row(&[5.0, 6.0]);
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[1][0], 3.0);
        assert_eq!(rows.last(), Some(&[5.0, 6.0][..]));
        assert_eq!(rows.first(), Some(&[1.0, 2.0][..]));
        assert_eq!(rows.get(3), None);
        let all: Vec<&[f64]> = (&rows).into_iter().collect();
        assert_eq!(all, [&[1.0, 2.0][..], &[3.0, 4.0], &[5.0, 6.0]]);
        assert_eq!(rows.iter().next_back(), Some(&[5.0, 6.0][..]));
        assert_eq!(rows.iter().len(), 3);
        assert_eq!(rows.column(1).collect::<Vec<_>>(), [2.0, 4.0, 6.0]);
        rows.pop();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows.as_flat(), [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(rows.push_zeros(), [0.0, 0.0]);
        rows.pop();
        assert_eq!(Rows::from_rows(2, [[1.0, 2.0], [3.0, 4.0]]), rows);
        rows[1][0] = 7.0;
        assert_eq!(rows[1], [7.0, 4.0]);
    }

    /// Rows of mixed sizes and signs: sums of their squares taken in
    /// another order than row order would differ in their last bits.
    fn test_row(i: usize) -> [f64; 3] {
        let x = i as f64;
        [x.sin() * 1e3, 1.0 / (1.0 + x), -x * 0.1 + 1e-7 * x * x]
    }

    #[test]
    fn a_windowed_table_keeps_its_last_rows_and_sums_the_others_bit_for_bit() {
        for window in [2, 3, 7] {
            for n in [0, 1, 2, 3, 6, 7, 8, 20, 21, 50] {
                let mut full = Rows::new(3);
                let mut windowed = Rows::windowed(3, window);
                for i in 0..n {
                    full.push_row(&test_row(i));
                    windowed.push_zeros().copy_from_slice(&test_row(i));
                    assert_eq!(windowed.last(), full.last(), "window {window}, row {i}");
                    assert!(windowed.len() <= window && !windowed.is_empty());
                }
                assert_eq!(windowed.rows_pushed(), n, "window {window}");
                assert_eq!(full.rows_pushed(), n);
                assert_eq!(windowed.rows_folded(), n - windowed.len());
                assert_eq!(full.rows_folded(), 0);
                // the same sums bit for bit, as the full table's in row order
                let mut expected = [0.0f64; 3];
                for row in &full {
                    for (e, y) in expected.iter_mut().zip(row) {
                        *e += y * y;
                    }
                }
                let got = windowed.square_sums();
                assert_eq!(
                    got.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                    expected.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                    "window {window}, {n} rows"
                );
                assert_eq!(full.square_sums(), expected);
                // the rows held are the full table's last ones
                let held: Vec<&[f64]> = windowed.iter().collect();
                let tail: Vec<&[f64]> = full.iter().skip(n - windowed.len()).collect();
                assert_eq!(held, tail);
            }
        }
    }

    #[test]
    fn a_windowed_table_pops_as_any_table() {
        // a row read and then refused (a NaN row) is popped right after it
        // was pushed, also when that push folded the window
        let mut full = Rows::new(3);
        let mut windowed = Rows::windowed(3, 3);
        for i in 0..12 {
            full.push_row(&test_row(i));
            windowed.push_row(&test_row(i));
            if i % 4 == 3 {
                full.pop();
                windowed.pop();
                assert_eq!(windowed.last(), full.last(), "row {i}");
                assert_eq!(
                    windowed.push_zeros(),
                    [0.0; 3],
                    "a popped row's numbers are zeros"
                );
                windowed.pop();
            }
        }
        assert_eq!(windowed.rows_pushed(), full.rows_pushed());
        assert_eq!(windowed.square_sums(), full.square_sums());
        assert_eq!(windowed.last(), full.last());
    }

    #[test]
    #[should_panic(expected = "a window of 1 rows: at least 2")]
    fn a_window_of_one_row_is_refused() {
        Rows::windowed(3, 1);
    }

    #[test]
    fn rows_of_no_columns_are_still_counted() {
        let mut rows = Rows::new(0);
        rows.push_row(&[]);
        rows.push_zeros();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows.iter().count(), 2);
        assert_eq!(rows.last(), Some(&[][..]));
    }

    #[test]
    #[should_panic(expected = "a row of 1 numbers in a table of 2 columns")]
    fn a_row_of_another_width_is_refused() {
        Rows::new(2).push_row(&[1.0]);
    }
}
