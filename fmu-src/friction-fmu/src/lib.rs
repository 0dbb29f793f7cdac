//! The friction FMUs. Each module binds one law of `friction-laws` to the FMI
//! layer: its variable table (the single source of the model description)
//! and a [`fmi_export::Model`] implementation. The same binary is packaged as
//! `Dahl.fmu`, `LuGre.fmu`, `ResetIntegrator.fmu`, `Bristle.fmu`,
//! `Bristle2D.fmu`, `Classical.fmu`, `BlimanSorine.fmu` and
//! `ElastoPlastic.fmu`;
//! `fmi2Instantiate` picks the law by GUID. Every law but the bristle one
//! is offered for Model Exchange too ([`fmi_export::Ode`]), from the same
//! equations: as an ODE, or (the stateless classical law) by its event
//! indicators alone.
#![forbid(unsafe_code)]

pub mod bliman_sorine;
pub mod bristle;
pub mod bristle2d;
pub mod classical;
pub mod dahl;
pub mod elasto_plastic;
pub mod in_process;
pub mod lugre;
pub mod maxwell_slip;
pub mod reset_integrator;

use fmi_export::{Model, ModelFactory, ModelInfo, Values, Variable};
use friction_laws::Ramp;
use std::sync::LazyLock;

/// Every model this binary holds.
pub static REGISTRY: LazyLock<[ModelFactory; 10]> = LazyLock::new(|| {
    [
        ModelFactory {
            info: &dahl::INFO,
            create: || Box::new(dahl::DahlFmu::default()),
            create_model_exchange: Some(|| Box::new(dahl::DahlFmu::default())),
        },
        ModelFactory {
            info: &lugre::INFO,
            create: || Box::new(lugre::LuGreFmu::default()),
            create_model_exchange: Some(|| Box::new(lugre::LuGreFmu::default())),
        },
        ModelFactory {
            info: &reset_integrator::INFO,
            create: || Box::new(reset_integrator::ResetFmu::default()),
            create_model_exchange: Some(|| Box::new(reset_integrator::ResetMe::default())),
        },
        // Co-Simulation only: bristles that disconnect and reconnect at
        // random relaxations are a discrete process, not an ODE (docs/fmu-reference.md)
        ModelFactory {
            info: &bristle::INFO,
            create: || Box::new(bristle::BristleFmu::default()),
            create_model_exchange: None,
        },
        ModelFactory {
            info: &bristle2d::INFO,
            create: || Box::new(bristle2d::Bristle2DFmu::default()),
            create_model_exchange: Some(|| Box::new(bristle2d::Bristle2DMe::default())),
        },
        // Model Exchange without continuous states: the classical law's
        // force follows from v and F_app, its switches are events
        ModelFactory {
            info: &classical::INFO,
            create: || Box::new(classical::ClassicalFmu::default()),
            create_model_exchange: Some(|| Box::new(classical::ClassicalFmu::default())),
        },
        ModelFactory {
            info: &bliman_sorine::INFO,
            create: || Box::new(bliman_sorine::BlimanSorineFmu::default()),
            create_model_exchange: Some(|| Box::new(bliman_sorine::BlimanSorineFmu::default())),
        },
        ModelFactory {
            info: &elasto_plastic::INFO,
            create: || Box::new(elasto_plastic::ElastoPlasticFmu::default()),
            create_model_exchange: Some(|| Box::new(elasto_plastic::ElastoPlasticFmu::default())),
        },
        ModelFactory {
            info: &maxwell_slip::MAXWELL_SLIP_INFO,
            create: || Box::new(maxwell_slip::MaxwellSlipFmu::default()),
            create_model_exchange: Some(|| Box::new(maxwell_slip::MaxwellSlipFmu::default())),
        },
        ModelFactory {
            info: &maxwell_slip::GMS_INFO,
            create: || Box::new(maxwell_slip::GmsFmu::default()),
            create_model_exchange: Some(|| Box::new(maxwell_slip::GmsFmu::default())),
        },
    ]
});

/// The model infos, in registry order.
pub fn models() -> Vec<&'static ModelInfo> {
    REGISTRY.iter().map(|f| f.info).collect()
}

/// A fresh model by name (for in-process runs that bypass the C ABI).
pub fn create(model_name: &str) -> Option<Box<dyn Model>> {
    REGISTRY
        .iter()
        .find(|f| f.info.model_name == model_name)
        .map(|f| (f.create)())
}

/// Name and version written into `generationTool`.
pub const GENERATION_TOOL: &str = concat!("friction-fmu ", env!("CARGO_PKG_VERSION"));

/// Convert a law's parameter error into the message the FMI layer logs.
fn param_err(e: friction_laws::ParamError) -> String {
    e.to_string()
}

/// The input `v` of the laws driven by the sliding velocity (Dahl, LuGre,
/// reset integrator), at value reference `vr`.
const fn sliding_velocity_input(vr: u32) -> Variable {
    Variable::input(
        vr,
        "v",
        0.0,
        "m/s",
        1e-3,
        "Sliding velocity of the body relative to the surface",
    )
}

/// Input `vr` over the step: `u(τ) = u + (du/dt)·τ`, from its value and its
/// slope (zero when not set).
#[inline]
fn input_ramp(values: &Values, slopes: &[f64], vr: u32) -> Ramp {
    Ramp::new(values.real(vr), slopes[vr as usize])
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_variable_table_is_consistent() {
        for info in super::models() {
            info.check().unwrap();
        }
    }
}
