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

    /// Overwrite the values at `vrs` with those of `from` (the values of
    /// another instance of the same model).
    #[inline]
    pub fn copy_at(&mut self, from: &[f64], vrs: &[u32]) {
        copy_at(&mut self.data, from, vrs);
    }

    /// Overwrite from a slice of the same length.
    pub fn copy_from_slice(&mut self, data: &[f64]) {
        self.data.copy_from_slice(data);
    }
}

/// `to[vr] = from[vr]` for each `vr` of `vrs`: the few entries of a
/// per-variable array that can differ (the inputs), with both arrays
/// borrowed once rather than looked up through their owners per entry.
#[inline]
pub fn copy_at(to: &mut [f64], from: &[f64], vrs: &[u32]) {
    for &vr in vrs {
        to[vr as usize] = from[vr as usize];
    }
}
