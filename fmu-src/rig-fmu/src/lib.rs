//! The rig FMUs: the mechanical side of the seed scenarios, on the same FMI
//! layer as the friction FMUs. `Rig1D.fmu`: mass, damper, spring to a
//! prescribed actuator point, moving surface, external force, friction input.
#![forbid(unsafe_code)]

pub mod rig1d;

use fmi2_cs::{ModelFactory, ModelInfo};
use std::sync::LazyLock;

pub static REGISTRY: LazyLock<[ModelFactory; 1]> = LazyLock::new(|| {
    [ModelFactory {
        info: &rig1d::INFO,
        create: || Box::new(rig1d::Rig1DFmu::default()),
    }]
});

pub fn models() -> Vec<&'static ModelInfo> {
    REGISTRY.iter().map(|f| f.info).collect()
}

pub const GENERATION_TOOL: &str = concat!("rig-fmu ", env!("CARGO_PKG_VERSION"));
