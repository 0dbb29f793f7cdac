//! The one error the laws produce: a parameter outside its physical range.

use std::fmt;

/// An invalid parameter, named with its value and the rule it breaks, e.g.
/// `sigma0 = -1: must be > 0`.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    pub name: &'static str,
    pub value: f64,
    pub rule: String,
}

impl ParamError {
    pub fn new(name: &'static str, value: f64, rule: impl Into<String>) -> Self {
        ParamError {
            name,
            value,
            rule: rule.into(),
        }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "invalid parameter {} = {}: {}",
            self.name, self.value, self.rule
        )
    }
}

impl std::error::Error for ParamError {}

/// `Ok` when `value` is finite and strictly positive.
pub fn require_positive(name: &'static str, value: f64) -> Result<(), ParamError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, value, "must be finite and > 0"))
    }
}

/// `Ok` when `value` is finite and ≥ 0.
pub fn require_non_negative(name: &'static str, value: f64) -> Result<(), ParamError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, value, "must be finite and >= 0"))
    }
}

/// `Ok` when `value` is finite (any sign).
pub fn require_finite(name: &'static str, value: f64) -> Result<(), ParamError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ParamError::new(name, value, "must be finite"))
    }
}
