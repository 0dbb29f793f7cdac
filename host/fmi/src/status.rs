//! `fmi2Status` (FMI 2.0.4 §2.1.3) and `fmi3Status` (FMI 3.0.1 §2.2.3,
//! the same values without `Pending`) as a Rust value.

use fmi2_types::{fmi2Discard, fmi2Error, fmi2Fatal, fmi2OK, fmi2Pending, fmi2Warning};
use std::fmt;
use std::os::raw::c_int;

/// The status an FMU function returned. `Ok` and `Warning` are successes
/// (a warning is logged by the FMU); every other status becomes an
/// [`FmuError::Call`](crate::FmuError::Call).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    Ok,
    Warning,
    Discard,
    Error,
    Fatal,
    Pending,
    /// A value outside the standard's 0..=5 (a broken FMU).
    Invalid(c_int),
}

impl Status {
    /// The status an FMU returned as a C integer ([`fmi2_types::fmi2Status`]).
    #[allow(non_upper_case_globals)] // the standard's names, as patterns
    pub fn from_raw(raw: c_int) -> Status {
        match raw {
            fmi2OK => Status::Ok,
            fmi2Warning => Status::Warning,
            fmi2Discard => Status::Discard,
            fmi2Error => Status::Error,
            fmi2Fatal => Status::Fatal,
            fmi2Pending => Status::Pending,
            other => Status::Invalid(other),
        }
    }

    /// The status's name in the FMI version of `function` (a call's
    /// name, "fmi2DoStep" or "fmi3DoStep"): "fmi3Error" for FMI 3.0.
    pub fn named_for(self, function: &str) -> String {
        let name = self.to_string();
        match function.get(..4) {
            Some("fmi3") => name.replacen("fmi2", "fmi3", 1),
            _ => name,
        }
    }

    /// `Ok` or `Warning`: the call did what was asked.
    pub fn is_success(self) -> bool {
        matches!(self, Status::Ok | Status::Warning)
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Status::Ok => f.write_str("fmi2OK"),
            Status::Warning => f.write_str("fmi2Warning"),
            Status::Discard => f.write_str("fmi2Discard"),
            Status::Error => f.write_str("fmi2Error"),
            Status::Fatal => f.write_str("fmi2Fatal"),
            Status::Pending => f.write_str("fmi2Pending"),
            Status::Invalid(raw) => write!(f, "invalid status {raw}"),
        }
    }
}
