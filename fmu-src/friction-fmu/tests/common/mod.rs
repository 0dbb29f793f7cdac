//! The C driver of `fmi-export/tests/support/c_driver.rs` over the exported C
//! functions of the friction FMU library.
#![allow(dead_code)]

// The same exports the shipped library has, generated into this test binary.
fmi_export::export_fmi2!(&friction_fmu::REGISTRY[..]);
pub use fmi2_exports::*;

/// LuGre's levels scaled by a position table of three points (the
/// position-dependent option).
pub const LUGRE_TABLE: &[(&str, f64)] = &[
    ("position_dependent", 1.0),
    ("n_table", 3.0),
    ("x_table[1]", 0.0),
    ("x_table[2]", 0.5),
    ("x_table[3]", 1.0),
    ("scale_pos[1]", 1.0),
    ("scale_pos[2]", 1.3),
    ("scale_pos[3]", 0.8),
];

fn models() -> Vec<&'static fmi_export::ModelInfo> {
    friction_fmu::models()
}

include!("../../../fmi-export/tests/support/c_driver.rs");
