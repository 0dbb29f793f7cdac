//! [`Rows`]: a table of numbers with a fixed number of columns, stored row
//! after row in one buffer.
//!
//! A run records one row of outputs per communication point, tens of
//! thousands of them; a `Vec<Vec<f64>>` would allocate (and later free)
//! each row on its own, which costs as much as a large part of the host's
//! work in a macro step. Here a new row is a few more numbers at the end
//! of one buffer, and reading stays as natural: `rows[i][k]`,
//! `rows.last()`, `for row in &rows`.

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
}

impl PartialEq for Rows {
    /// The same rows (the zeros made ready ahead do not count).
    fn eq(&self, other: &Rows) -> bool {
        self.width == other.width && self.len == other.len && self.as_flat() == other.as_flat()
    }
}

impl std::fmt::Debug for Rows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Rows")
            .field("width", &self.width)
            .field("len", &self.len)
            .field("values", &self.as_flat())
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

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.len
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
        let end = start + self.width;
        if self.values.len() < end {
            // no row made ready: one more (the numbers after `end` are
            // zeros still)
            self.values.resize(end, 0.0);
        }
        self.len += 1;
        &mut self.values[start..end]
    }

    /// Remove the last row, if any.
    pub fn pop(&mut self) {
        if self.len > 0 {
            self.len -= 1;
            self.values.truncate(self.len * self.width);
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
