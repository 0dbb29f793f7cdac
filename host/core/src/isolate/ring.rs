//! The rows of the isolated run, from the child to the parent through a
//! ring buffer in shared memory (one writer, one reader): a row the child
//! has stored is the parent's even if the child dies the next instant, and
//! no system call is made per row. The child waits while the ring is full.

use crate::rows::Rows;
use fricsim_fmi::shared_memory::Mapping;
use std::path::Path;
use std::sync::atomic::Ordering::{Acquire, Relaxed, Release};
use std::time::Duration;

const WRITTEN: usize = 0;
const READ: usize = 1;
const WIDTH: usize = 2;
const CAPACITY: usize = 3;
/// The first word of the rows.
const DATA: usize = 8;
/// Words of row data in the ring (8 MiB), at least a few rows.
const DATA_WORDS: usize = 1 << 20;

/// The ring of rows (`time` first, then the columns).
pub struct RowRing {
    map: Mapping,
    /// Values per row: the time and the columns.
    width: usize,
    capacity: u64,
}

impl RowRing {
    /// Create the ring file at `path` for rows of `columns` values and a
    /// time (the child).
    pub fn create(path: &Path, columns: usize) -> std::io::Result<RowRing> {
        let width = columns + 1;
        let capacity = (DATA_WORDS / width).max(16);
        let map = Mapping::open(path, DATA + capacity * width, true)?;
        map.word(WIDTH).store(width as u64, Relaxed);
        map.word(CAPACITY).store(capacity as u64, Release);
        Ok(RowRing {
            map,
            width,
            capacity: capacity as u64,
        })
    }

    /// Map the ring the child created (the parent).
    pub fn open(path: &Path) -> std::io::Result<RowRing> {
        let head = Mapping::open(path, DATA, false)?;
        let capacity = head.word(CAPACITY).load(Acquire);
        let width = head.word(WIDTH).load(Relaxed) as usize;
        drop(head);
        let words = (capacity as usize)
            .checked_mul(width)
            .and_then(|w| w.checked_add(DATA))
            .filter(|_| width > 0 && capacity > 0)
            .ok_or_else(|| std::io::Error::other("the row ring's header is damaged"))?;
        Ok(RowRing {
            map: Mapping::open(path, words, false)?,
            width,
            capacity,
        })
    }

    /// Store the row `row` at `t` (the child), waiting while the ring is
    /// full.
    pub fn push(&self, t: f64, row: &[f64]) {
        debug_assert_eq!(row.len() + 1, self.width);
        let written = self.map.word(WRITTEN).load(Relaxed);
        while written - self.map.word(READ).load(Acquire) >= self.capacity {
            std::thread::sleep(Duration::from_micros(200));
        }
        let base = DATA + (written % self.capacity) as usize * self.width;
        self.map.word(base).store(t.to_bits(), Relaxed);
        for (k, x) in row.iter().enumerate() {
            self.map.word(base + 1 + k).store(x.to_bits(), Relaxed);
        }
        self.map.word(WRITTEN).store(written + 1, Release);
    }

    /// The rows stored since the last call (the parent): their times and
    /// the rows.
    pub fn take(&self) -> (Vec<f64>, Rows) {
        let written = self.map.word(WRITTEN).load(Acquire);
        let read = self.map.word(READ).load(Relaxed);
        let n = (written - read) as usize;
        let mut times = Vec::with_capacity(n);
        let mut rows = Rows::with_capacity(self.width - 1, n);
        for k in read..written {
            let base = DATA + (k % self.capacity) as usize * self.width;
            times.push(f64::from_bits(self.map.word(base).load(Relaxed)));
            let row = rows.push_zeros();
            for (j, x) in row.iter_mut().enumerate() {
                *x = f64::from_bits(self.map.word(base + 1 + j).load(Relaxed));
            }
        }
        self.map.word(READ).store(written, Release);
        (times, rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_pass_through_the_ring_in_order_and_whole_past_its_capacity() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rows");
        let child = RowRing::create(&path, 2).unwrap();
        let parent = RowRing::open(&path).unwrap();
        let capacity = child.capacity as usize;
        let mut seen = Vec::new();
        for i in 0..capacity * 3 + 5 {
            child.push(i as f64, &[-(i as f64), f64::NAN]);
            if i % (capacity / 2) == 0 {
                let (t, rows) = parent.take();
                seen.extend(t.iter().zip(&rows).map(|(t, r)| (*t, r[0], r[1].is_nan())));
            }
        }
        let (t, rows) = parent.take();
        seen.extend(t.iter().zip(&rows).map(|(t, r)| (*t, r[0], r[1].is_nan())));
        assert_eq!(seen.len(), capacity * 3 + 5);
        for (i, (t, x, nan)) in seen.into_iter().enumerate() {
            assert_eq!((t, x, nan), (i as f64, -(i as f64), true));
        }
    }
}
