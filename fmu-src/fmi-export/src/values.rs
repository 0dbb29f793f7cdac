//! The current value of every variable, indexed by value reference.
//! Integers and booleans are held as exact `f64` (every `i32` is exact).

#[derive(Clone, Debug, PartialEq)]
pub struct Values {
    data: Vec<f64>,
}

impl Values {
    /// Start values of a table; outputs start at 0.
    pub fn from_start(variables: &[crate::Variable]) -> Self {
        Values {
            data: variables.iter().map(|v| v.start.unwrap_or(0.0)).collect(),
        }
    }

    pub fn real(&self, vr: u32) -> f64 {
        self.data[vr as usize]
    }

    pub fn integer(&self, vr: u32) -> i32 {
        self.data[vr as usize] as i32
    }

    pub fn boolean(&self, vr: u32) -> bool {
        self.data[vr as usize] != 0.0
    }

    pub fn set(&mut self, vr: u32, value: f64) {
        self.data[vr as usize] = value;
    }

    pub fn set_integer(&mut self, vr: u32, value: i32) {
        self.data[vr as usize] = value as f64;
    }

    pub fn set_boolean(&mut self, vr: u32, value: bool) {
        self.data[vr as usize] = if value { 1.0 } else { 0.0 };
    }

    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// Every value, writable (a model writing its outputs with one length
    /// check rather than one per output).
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.data
    }

    pub fn len(&self) -> usize {
        self.data.len()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Overwrite from a slice of the same length.
    pub fn copy_from_slice(&mut self, data: &[f64]) {
        self.data.copy_from_slice(data);
    }
}

/// A fixed list of value references (an instance's inputs) and their bound,
/// for copying their entries between per-variable tables: the two lengths
/// are checked once per copy against the bound, not per entry (a master's
/// rollback copies the inputs into a snapshot and back at every step).
#[derive(Clone, Debug, Default)]
pub struct Indices {
    vrs: Box<[u32]>,
    /// One more than the largest of `vrs` (0 when empty): every entry is
    /// below it.
    bound: usize,
}

impl Indices {
    pub fn new(vrs: Vec<u32>) -> Self {
        let bound = vrs.iter().map(|&vr| vr as usize + 1).max().unwrap_or(0);
        Indices {
            vrs: vrs.into_boxed_slice(),
            bound,
        }
    }

    /// `to[vr] = from[vr]` for each value reference: the few entries of a
    /// per-variable table that can differ (the inputs).
    #[inline]
    pub fn copy(&self, to: &mut [f64], from: &[f64]) {
        // Both tables cut to the bound: an entry's one index check then
        // covers both (a shorter table is a bug in the layer, a panic as
        // an out-of-bounds index would be).
        let (to, from) = (&mut to[..self.bound], &from[..self.bound]);
        for &vr in self.vrs.iter() {
            to[vr as usize] = from[vr as usize];
        }
    }
}

impl std::ops::Deref for Indices {
    type Target = [u32];

    fn deref(&self) -> &[u32] {
        &self.vrs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`Indices::copy`] copies exactly the entries of its value
    /// references, in any order of them, and refuses tables shorter than
    /// them (a panic, as an index out of bounds is).
    #[test]
    fn indices_copy_copies_exactly_their_entries() {
        let from: Vec<f64> = (0..20).map(|k| k as f64 + 0.5).collect();
        for vrs in [vec![], vec![0], vec![17, 3, 4, 0], vec![19, 1]] {
            let indices = Indices::new(vrs.clone());
            assert_eq!(&*indices, &vrs[..]);
            let (mut a, mut b) = (vec![-1.0; 20], vec![-1.0; 20]);
            indices.copy(&mut a, &from);
            for &vr in &vrs {
                b[vr as usize] = from[vr as usize];
            }
            assert_eq!(a, b);
        }
        let indices = Indices::new(vec![2, 5]);
        let short = std::panic::catch_unwind(|| indices.copy(&mut [0.0; 5], &[0.0; 6]));
        assert!(short.is_err());
        let short = std::panic::catch_unwind(|| indices.copy(&mut [0.0; 6], &[0.0; 5]));
        assert!(short.is_err());
        indices.copy(&mut [0.0; 6], &[0.0; 6]);
    }
}
