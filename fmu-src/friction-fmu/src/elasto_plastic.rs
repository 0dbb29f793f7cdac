//! `ElastoPlastic.fmu`: the single-state elasto-plastic law (Dupont,
//! Hayward, Armstrong, Altpeter 2002; docs/models.md "Elasto-plastic"),
//! LuGre with a purely elastic range below the break-away deflection
//! `z_ba`. Co-Simulation integrates it in displacement (exactly in the
//! elastic and plastic zones, under a tolerance in the transition); in
//! Model Exchange the deflection `z` is the continuous state, with event
//! indicators where `α(z, v)` changes branch.

use crate::{input_ramp, param_err, sliding_velocity_input};
use fmi_export::{
    Capabilities, ContinuousState, DefaultExperiment, Model, ModelExchange, ModelInfo, Ode, Values,
    Variable,
};
use friction_laws::elasto_plastic::{ElastoPlastic, ElastoPlasticParams};

pub mod vr {
    pub const V: u32 = 0;
    pub const F: u32 = 1;
    pub const Z: u32 = 2;
    pub const ELASTIC: u32 = 3;
    pub const P_DISS: u32 = 4;
    pub const E_STORED: u32 = 5;
    pub const SIGMA0: u32 = 6;
    pub const SIGMA1: u32 = 7;
    pub const SIGMA2: u32 = 8;
    pub const FC: u32 = 9;
    pub const FS: u32 = 10;
    pub const VS: u32 = 11;
    pub const STRIBECK_EXPONENT: u32 = 12;
    pub const Z_BA: u32 = 13;
    pub const DER_Z: u32 = 14;
}

static VARIABLES: [Variable; 15] = [
    sliding_velocity_input(vr::V),
    Variable::output(
        vr::F,
        "F",
        "N",
        "Friction force F = sigma0*z + sigma1*dz/dt + sigma2*v, resisting positive motion (the rig applies -F)",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::Z]),
    Variable::output(
        vr::Z,
        "z",
        "m",
        "Bristle deflection: dz/dt = v - alpha(z, v)*sigma0*|v|*z/g(v); 0 at the start",
        &[],
    )
    .with_state_dependencies(&[vr::Z]),
    Variable::boolean_output(
        vr::ELASTIC,
        "elastic",
        "True while alpha = 0: below break-away, or unloading, the contact deforms elastically (dz/dt = v) and does not creep",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::Z]),
    Variable::output(
        vr::P_DISS,
        "P_diss",
        "W",
        "Power the contact dissipates, F*v - sigma0*z*dz/dt = alpha*sigma0^2*|v|*z^2/g + sigma1*v*dz/dt + sigma2*v^2",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::Z]),
    Variable::output(
        vr::E_STORED,
        "E_stored",
        "J",
        "Elastic energy of the bristle, sigma0*z^2/2",
        &[],
    )
    .with_state_dependencies(&[vr::Z]),
    Variable::parameter(vr::SIGMA0, "sigma0", 1e5, "N/m", "Bristle stiffness").with_min(0.0),
    Variable::parameter(
        vr::SIGMA1,
        "sigma1",
        316.22776601683796,
        "N.s/m",
        "Bristle damping",
    )
    .with_min(0.0),
    Variable::parameter(vr::SIGMA2, "sigma2", 0.4, "N.s/m", "Viscous coefficient").with_min(0.0),
    Variable::parameter(vr::FC, "Fc", 1.0, "N", "Coulomb level").with_min(0.0),
    Variable::parameter(vr::FS, "Fs", 1.5, "N", "Static level, >= Fc").with_min(0.0),
    Variable::parameter(vr::VS, "vs", 1e-3, "m/s", "Stribeck velocity").with_min(0.0),
    Variable::parameter(
        vr::STRIBECK_EXPONENT,
        "stribeck_exponent",
        2.0,
        "",
        "Stribeck exponent delta in g(v) = Fc + (Fs - Fc)*exp(-|v/vs|^delta)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::Z_BA,
        "z_ba",
        9.5e-6,
        "m",
        "Break-away deflection, 0 <= z_ba < Fc/sigma0: below it the contact is purely elastic (default 0.95*Fc/sigma0)",
    )
    .with_min(0.0),
    Variable::derivative(
        vr::DER_Z,
        "der(z)",
        "m/s",
        "dz/dt = v - alpha(z, v)*sigma0*|v|*z/g(v): the derivative of the continuous state z (Model Exchange)",
        &[vr::V],
        &[vr::Z],
    ),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "ElastoPlastic",
    model_identifier: "ElastoPlastic",
    guid: "{b3c9e7a1-4f52-4d8b-a6e0-91d27c5f3a84}",
    description: "Elasto-plastic friction: dz/dt = v - alpha(z, v)*sigma0*|v|*z/g(v), F = sigma0*z + sigma1*dz/dt + sigma2*v; alpha = 0 below the break-away deflection z_ba and while unloading (true stiction, no drift), 1 at the steady state g(v)/sigma0.",
    source: "Dupont, Hayward, Armstrong, Altpeter 2002; the LuGre parameters of Canudas de Wit et al. 1995. See docs/models.md.",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 1.0,
        step_size: 1e-3,
    },
    capabilities: Capabilities::FULL,
    co_simulation_states: &[],
    model_exchange: Some(ModelExchange {
        states: &[ContinuousState {
            state: vr::Z,
            derivative: vr::DER_Z,
        }],
        event_indicators: 5,
        states_jump_at_events: false,
    }),
};

#[derive(Clone, Debug)]
pub struct ElastoPlasticFmu {
    law: ElastoPlastic,
}

impl Default for ElastoPlasticFmu {
    fn default() -> Self {
        ElastoPlasticFmu {
            law: ElastoPlastic::new(ElastoPlasticParams::default())
                .expect("default parameters are valid"),
        }
    }
}

impl ElastoPlasticFmu {
    pub fn params(values: &Values) -> ElastoPlasticParams {
        ElastoPlasticParams {
            sigma0: values.real(vr::SIGMA0),
            sigma1: values.real(vr::SIGMA1),
            sigma2: values.real(vr::SIGMA2),
            fc: values.real(vr::FC),
            fs: values.real(vr::FS),
            vs: values.real(vr::VS),
            delta: values.real(vr::STRIBECK_EXPONENT),
            z_ba: values.real(vr::Z_BA),
        }
    }
}

impl Model for ElastoPlasticFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        self.law = ElastoPlastic::new(Self::params(values)).map_err(param_err)?;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let v = values.real(vr::V);
        values.set(vr::F, self.law.force(v));
        values.set(vr::Z, self.law.z());
        values.set_boolean(vr::ELASTIC, self.law.elastic(v));
        values.set(vr::P_DISS, self.law.dissipated_power(v));
        values.set(vr::E_STORED, self.law.stored_energy());
    }

    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        self.law.step(input_ramp(values, slopes, vr::V), h);
        Ok(())
    }

    fmi_export::delegate_state!(law);

    /// Directional derivatives of a step by replaying it.
    fn supplies_partial_derivatives(&self) -> bool {
        false
    }

    /// `dF/dt = σ0·ż + σ1·(∂ż/∂z·ż + ∂ż/∂v·dv/dt) + σ2·dv/dt`,
    /// `dz/dt = ż`.
    fn output_derivative(&self, values: &Values, slopes: &[f64], output: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let dv = slopes[vr::V as usize];
        let z = self.law.z();
        let rate = self.law.z_rate(z, v);
        let p = self.law.params();
        match output {
            vr::F => {
                let (by_z, by_v) = self.law.z_rate_partials(z, v);
                Some(p.sigma0 * rate + p.sigma1 * (by_z * rate + by_v * dv) + p.sigma2 * dv)
            }
            vr::Z => Some(rate),
            _ => None,
        }
    }

    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        dx[0] = self.law.z_rate(self.law.z(), values.real(vr::V));
    }

    fmi_export::ode_is_self!();
}

/// Model Exchange: the state is `z`; the event indicators are `v`,
/// `z ∓ z_ba` and `z ∓ g(v)/σ0`, where `α` changes branch (it is
/// continuous, with a continuous slope, at each of them, but its second
/// derivative jumps); no discrete state.
impl Ode for ElastoPlasticFmu {
    fmi_export::delegate_continuous_states!(law);

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        let v = values.real(vr::V);
        let p = self.law.params();
        let w_ss = self.law.level(v) / p.sigma0;
        let x = self.law.z();
        z[0] = v;
        z[1] = x - p.z_ba;
        z[2] = x + p.z_ba;
        z[3] = x - w_ss;
        z[4] = x + w_ss;
    }

    /// `z` on the scale of the static deflection `Fs/σ0`.
    fn nominals(&self, values: &Values, nominal: &mut [f64]) {
        let p = Self::params(values);
        nominal[0] = p.fs / p.sigma0;
    }

    fn event_update(&mut self, _values: &Values) -> bool {
        false
    }

    /// In closed form from [`ElastoPlastic::z_rate_partials`]: `der(z)`,
    /// `F = σ0·z + σ1·ż + σ2·v`, `P_diss = F·v − σ0·z·ż` and
    /// `E_stored = σ0·z²/2` in `z` and `v`.
    fn partial_derivative(&self, values: &Values, unknown: u32, known: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let z = self.law.z();
        let p = self.law.params();
        let rate = self.law.z_rate(z, v);
        let force = self.law.force(v);
        let (rz, rv) = self.law.z_rate_partials(z, v);
        let (fz, fv) = (p.sigma0 + p.sigma1 * rz, p.sigma1 * rv + p.sigma2);
        let (by_z, by_v) = match unknown {
            vr::DER_Z => (rz, rv),
            vr::Z => (1.0, 0.0),
            vr::F => (fz, fv),
            vr::P_DISS => (
                fz * v - p.sigma0 * rate - p.sigma0 * z * rz,
                fv * v + force - p.sigma0 * z * rv,
            ),
            vr::E_STORED => (p.sigma0 * z, 0.0),
            _ => return None,
        };
        match known {
            vr::Z => Some(by_z),
            vr::V => Some(by_v),
            _ => None,
        }
    }
}
