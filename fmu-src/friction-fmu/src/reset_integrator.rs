//! `ResetIntegrator.fmu`: the 1-D reset integrator (Haessig & Friedland
//! 1991; docs/models.md "Reset integrator"), integrated exactly in
//! Co-Simulation; in Model Exchange ([`ResetMe`]) the strain `z` is the
//! continuous state, `dz/dt` ([`ResetIntegrator::z_rate`]) its derivative,
//! and two event indicators locate where the strain reaches a limit and
//! where a reversal releases it.

use crate::{input_ramp, param_err, sliding_velocity_input};
use fmi_export::{
    Capabilities, ContinuousState, DefaultExperiment, Model, ModelExchange, ModelInfo, Ode, Values,
    Variable,
};
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
    pub const DER_Z: u32 = 8;
    /// Added with the energy outputs of the newer laws.
    pub const P_DISS: u32 = 9;
    pub const E_STORED: u32 = 10;
}

static VARIABLES: [Variable; 11] = [
    sliding_velocity_input(vr::V),
    Variable::output(
        vr::F,
        "F",
        "N",
        "Friction force F = (1 + a(z))*sigma0*z + sigma1*dz/dt",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::Z]),
    Variable::output(vr::Z, "z", "m", "Bristle strain, |z| <= z0", &[])
        .with_state_dependencies(&[vr::Z]),
    Variable::boolean_output(
        vr::SLIDING,
        "sliding",
        "True when z is at the stiction limit and moving outward",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::Z]),
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
    Variable::derivative(
        vr::DER_Z,
        "der(z)",
        "m/s",
        "dz/dt = v, or 0 at the stiction limit moving outward: the derivative of the continuous state z (Model Exchange)",
        &[vr::V],
        &[vr::Z],
    ),
    Variable::output(
        vr::P_DISS,
        "P_diss",
        "W",
        "Power the contact dissipates, F*v - dE_stored/dt: sigma1*v^2 inside the stiction range, sigma0*z0*|v| held at its limit; never negative",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::Z]),
    Variable::output(
        vr::E_STORED,
        "E_stored",
        "J",
        "Elastic energy held in the bristle, (1 + a)*sigma0*z^2/2 (it stays (1 + a)*sigma0*z0^2/2 held at the limit)",
        &[],
    )
    .with_state_dependencies(&[vr::Z]),
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
    co_simulation_states: &[],
    model_exchange: Some(ModelExchange {
        states: &[ContinuousState {
            state: vr::Z,
            derivative: vr::DER_Z,
        }],
        event_indicators: 2,
        // an integrator's overshoot of the limit is put back at the event
        states_jump_at_events: true,
    }),
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
        values.set(vr::P_DISS, self.law.dissipated_power(v));
        values.set(vr::E_STORED, self.law.stored_energy());
    }

    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        self.law.step(input_ramp(values, slopes, vr::V), h);
        Ok(())
    }

    fmi_export::delegate_state!(law);

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

    /// `dz/dt`: `v`, or 0 held at a limit (the law's `ż`).
    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        dx[0] = self.law.z_dot(values.real(vr::V));
    }
}

/// `ResetIntegrator.fmu` for Model Exchange: the law's equations
/// ([`ResetIntegrator::z_rate`], [`ResetIntegrator::force_of`]) with the
/// limit the strain is at (`contact`: +1, −1, 0) held as a discrete state
/// that changes at events only: an integrator keeps a held strain at
/// `±z0` only to the last bit, and deciding the contact from `z` would
/// release and catch it again at every step. The continuous state is `z`;
/// two event indicators, one per limit
/// ([`ResetIntegrator::switching_functions`]), each crossing zero where
/// the strain reaches its limit and where a reversal releases it; at an
/// event the strain is put on its limit and caught or released
/// ([`ResetIntegrator::at_event`]).
#[derive(Clone, Debug)]
pub struct ResetMe {
    law: ResetIntegrator,
    contact: i8,
}

impl Default for ResetMe {
    fn default() -> Self {
        ResetMe {
            law: ResetFmu::default().law,
            contact: 0,
        }
    }
}

impl Model for ResetMe {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        self.law = ResetIntegrator::new(ResetFmu::params(values)).map_err(param_err)?;
        self.contact = 0;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let v = values.real(vr::V);
        let z = self.law.z();
        values.set(vr::F, self.law.force_of(z, v, self.contact));
        values.set(vr::Z, z);
        values.set_boolean(vr::SLIDING, self.law.sliding_of(v, self.contact));
        let power = self.law.dissipated_power_of(z, v, self.contact);
        values.set(vr::P_DISS, power);
        values.set(vr::E_STORED, self.law.stored_energy_of(z));
    }

    /// Never called: a Model Exchange instance takes no communication
    /// steps (the state table refuses `fmi2DoStep`); the importer
    /// integrates.
    fn do_step(&mut self, _values: &Values, _slopes: &[f64], _h: f64) -> Result<(), String> {
        Err("a Model Exchange instance takes no communication steps".into())
    }

    /// `[z, contact]`.
    fn save_state(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&[self.law.z(), f64::from(self.contact)]);
    }

    fn restore_state(&mut self, state: &[f64]) -> Result<(), String> {
        match state {
            [z, c] if z.is_finite() && [-1.0, 0.0, 1.0].contains(c) => {
                self.law.set_z(*z);
                self.contact = *c as i8;
                Ok(())
            }
            _ => Err(format!(
                "reset-integrator state for Model Exchange is [z, contact (-1, 0 or 1)], got {state:?}"
            )),
        }
    }

    fn clone_model(&self) -> Box<dyn Model> {
        Box::new(self.clone())
    }

    fn supplies_partial_derivatives(&self) -> bool {
        false
    }

    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        dx[0] = self.law.z_rate(values.real(vr::V), self.contact);
    }

    fmi_export::ode_is_self!();
}

impl Ode for ResetMe {
    fmi_export::delegate_continuous_states!(law);

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        let v = values.real(vr::V);
        z.copy_from_slice(&self.law.switching_functions(self.law.z(), v, self.contact));
    }

    /// `z` on the scale of the stiction range `z0`.
    fn nominals(&self, values: &Values, nominal: &mut [f64]) {
        nominal[0] = ResetFmu::params(values).z0;
    }

    fn event_update(&mut self, values: &Values) -> bool {
        let z = self.law.z();
        let (after, contact) = self.law.at_event(z, values.real(vr::V), self.contact);
        self.law.set_z(after);
        self.contact = contact;
        after != z
    }

    /// The law's closed forms ([`ResetIntegrator::partials`]).
    fn partial_derivative(&self, values: &Values, unknown: u32, known: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let (dzd_dz, dzd_dv, df_dz, df_dv) = self.law.partials(v, self.contact);
        let (dp_dz, dp_dv, de_dz) = self.law.energy_partials(self.law.z(), v, self.contact);
        let (by_z, by_v) = match unknown {
            vr::DER_Z => (dzd_dz, dzd_dv),
            vr::F => (df_dz, df_dv),
            vr::Z => (1.0, 0.0),
            vr::P_DISS => (dp_dz, dp_dv),
            vr::E_STORED => (de_dz, 0.0),
            _ => return None,
        };
        match known {
            vr::Z => Some(by_z),
            vr::V => Some(by_v),
            _ => None,
        }
    }
}
