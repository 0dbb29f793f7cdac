//! The rig FMUs: the mechanical side of the papers' scenarios, on the same FMI
//! layer as the friction FMUs. `Rig1D.fmu`: mass, damper, spring to a
//! prescribed or input actuator point, drive force, PD/PI controller,
//! moving and dithered surface, external force, friction input.
//! `Rig2D.fmu`: the planar oscillator of Wijata et al. 2016 with surface
//! dither.
#![forbid(unsafe_code)]

pub mod rig1d;
pub mod rig2d;

use fmi_export::{ModelFactory, ModelInfo};
use std::sync::LazyLock;

pub static REGISTRY: LazyLock<[ModelFactory; 2]> = LazyLock::new(|| {
    [
        ModelFactory {
            info: &rig1d::INFO,
            create: || Box::new(rig1d::Rig1DFmu::default()),
            create_model_exchange: None,
        },
        ModelFactory {
            info: &rig2d::INFO,
            create: || Box::new(rig2d::Rig2DFmu::default()),
            create_model_exchange: None,
        },
    ]
});

pub fn models() -> Vec<&'static ModelInfo> {
    REGISTRY.iter().map(|f| f.info).collect()
}

pub const GENERATION_TOOL: &str = concat!("rig-fmu ", env!("CARGO_PKG_VERSION"));

#[cfg(test)]
mod tests {
    #[test]
    fn every_variable_table_is_consistent() {
        for info in super::models() {
            info.check().unwrap();
        }
    }
}
