//! The C driver of `fmi-export/tests/support/c_driver.rs` over the exported C
//! functions of the rig FMU library.
#![allow(dead_code)]

// The same exports the shipped library has, generated into this test binary.
fmi_export::export_fmi2!(&rig_fmu::REGISTRY[..]);
pub use fmi2_exports::*;

fn models() -> Vec<&'static fmi_export::ModelInfo> {
    rig_fmu::models()
}

include!("../../../fmi-export/tests/support/c_driver.rs");
