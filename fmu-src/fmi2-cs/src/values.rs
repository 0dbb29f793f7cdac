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
