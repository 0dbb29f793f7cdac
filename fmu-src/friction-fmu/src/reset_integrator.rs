//! `ResetIntegrator.fmu`: the 1-D reset integrator (Haessig & Friedland
//! 1991; docs/models.md "Reset integrator"), integrated exactly.

use crate::{input_ramp, param_err, sliding_velocity_input};
use fmi2_cs::{Capabilities, DefaultExperiment, Model, ModelInfo, Values, Variable};
use friction_laws::reset_integrator::{ResetIntegrator, ResetParams};

pub mod vr {
    pub const V: u32 = 0;
    pub const F: u32 = 1;
    pub const Z: u32 = 2;
    pub const SLIDING: u32 = 3;
    pub const SIGMA0: u32 = 4;
    pub const SIGMA1: u32 = 5;
    pub const A: u32 = 6;
    pub const Z0: u32 = 7;
}

static VARIABLES: [Variable; 8] = [
    sliding_velocity_input(vr::V),
    Variable::output(
        vr::F,
        "F",
        "N",
        "Friction force F = (1 + a(z))*sigma0*z + sigma1*dz/dt",
        &[vr::V],
    ),
    Variable::output(vr::Z, "z", "m", "Bristle strain, |z| <= z0", &[]),
    Variable::boolean_output(
        vr::SLIDING,
        "sliding",
        "True when z is at the stiction limit and moving outward",
        &[vr::V],
    ),
    Variable::parameter(vr::SIGMA0, "sigma0", 1e4, "N/m", "Bristle stiffness").with_min(0.0),
    Variable::parameter(vr::SIGMA1, "sigma1", 74.15, "N.s/m", "Bristle damping").with_min(0.0),
    Variable::parameter(
        vr::A,
        "a",
        0.1,
        "",
        "Stiction gradient: break-away peak (1 + a)*sigma0*z0",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::Z0,
        "z0",
        1e-4,
        "m",
        "Stiction range: sliding level sigma0*z0",
    )
    .with_min(0.0),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "ResetIntegrator",
    model_identifier: "ResetIntegrator",
    guid: "{39de5f74-c513-4262-b587-f0e6ca39667a}",
    description: "Reset-integrator friction: dz/dt = v unless |z| >= z0 and moving outward; F = (1 + a(z))*sigma0*z + sigma1*dz/dt.",
    source: "Haessig and Friedland 1991; the 1-D base of Wijata et al. 2016. See docs/models.md.",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment { start_time: 0.0, stop_time: 1.0, step_size: 1e-3 },
    capabilities: Capabilities::FULL,
};

#[derive(Clone, Debug)]
pub struct ResetFmu {
    law: ResetIntegrator,
}

impl Default for ResetFmu {
    fn default() -> Self {
        ResetFmu {
            law: ResetIntegrator::new(ResetParams::default())
                .expect("default parameters are valid"),
        }
    }
}

impl ResetFmu {
    pub fn params(values: &Values) -> ResetParams {
        ResetParams {
            sigma0: values.real(vr::SIGMA0),
            sigma1: values.real(vr::SIGMA1),
            a: values.real(vr::A),
            z0: values.real(vr::Z0),
        }
    }
}

impl Model for ResetFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        self.law = ResetIntegrator::new(Self::params(values)).map_err(param_err)?;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let v = values.real(vr::V);
        values.set(vr::F, self.law.force(v));
        values.set(vr::Z, self.law.z());
        values.set_boolean(vr::SLIDING, self.law.sliding(v));
    }

    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        self.law.step(input_ramp(values, slopes, vr::V), h);
        Ok(())
    }

    fmi2_cs::delegate_state!(law);

    /// Directional derivatives by replaying the step: no partial derivatives.
    fn supplies_partial_derivatives(&self) -> bool {
        false
    }

    /// Inside the stiction range ż = v, so dF/dt = (1 + a)·σ0·v + σ1·dv/dt;
    /// at the limit moving outward ż = 0 and F is constant.
    fn output_derivative(&self, values: &Values, slopes: &[f64], output: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let z_dot = self.law.z_dot(v);
        let p = ResetFmu::params(values);
        let inside = self.law.z().abs() < p.z0;
        match output {
            vr::Z => Some(z_dot),
            vr::F if z_dot == 0.0 => Some(0.0),
            vr::F => Some(
                if inside { 1.0 + p.a } else { 1.0 } * p.sigma0 * z_dot
                    + p.sigma1 * slopes[vr::V as usize],
            ),
            _ => None,
        }
    }
}
