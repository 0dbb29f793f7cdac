//! The C driver of `fmi2-cs/tests/support/c_driver.rs` over the exported C
//! functions of the friction FMU library.
#![allow(dead_code)]

// The same exports the shipped library has, generated into this test binary.
fmi2_cs::export_fmi2!(&friction_fmu::REGISTRY[..]);
pub use fmi2_exports::*;

fn models() -> Vec<&'static fmi2_cs::ModelInfo> {
    friction_fmu::models()
}

include!("../../../fmi2-cs/tests/support/c_driver.rs");
