//! The C types of the FMI 2.0 standard, from `fmi2-types` (the crate the
//! importer, fricsim, uses too), and the exporter's own [`fmi2Status`].
#![allow(non_camel_case_types)]

use std::os::raw::c_int;

// Every type and constant of the standard but `fmi2Status`, which the
// enum below shadows on this side of the ABI.
pub use fmi2_types::*;

/// `fmi2Status` as this exporter returns it, ordered by severity. An enum
/// is sound here, unlike in an importer, because the exporter only returns
/// values it made; it is ABI-compatible with the standard's `c_int`
/// ([`fmi2_types::fmi2Status`]), as the checks below make sure.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum fmi2Status {
    fmi2OK = fmi2_types::fmi2OK as isize,
    fmi2Warning = fmi2_types::fmi2Warning as isize,
    fmi2Discard = fmi2_types::fmi2Discard as isize,
    fmi2Error = fmi2_types::fmi2Error as isize,
    fmi2Fatal = fmi2_types::fmi2Fatal as isize,
    fmi2Pending = fmi2_types::fmi2Pending as isize,
}

const _: () = assert!(std::mem::size_of::<fmi2Status>() == std::mem::size_of::<c_int>());
const _: () = assert!(std::mem::align_of::<fmi2Status>() == std::mem::align_of::<c_int>());
