//! `Dahl.fmu`: the Dahl law (Dahl 1968; Sun et al. 2016 eq. 2–3, 16–17;
//! docs/models.md "Dahl"), integrated exactly in the displacement domain
//! for every α in Co-Simulation; in Model Exchange the force `F` is the
//! continuous state and `dF/dt` ([`Dahl::force_rate`]) its derivative.

use crate::{input_ramp, param_err, sliding_velocity_input};
use fmi2_cs::{
    Capabilities, ContinuousState, DefaultExperiment, Model, ModelExchange, ModelInfo, Ode, Values,
    Variable,
};
use friction_laws::dahl::{Dahl, DahlParams};

pub mod vr {
    pub const V: u32 = 0;
    pub const F: u32 = 1;
    pub const Z: u32 = 2;
    pub const SLIDING: u32 = 3;
    pub const SIGMA: u32 = 4;
    pub const FC: u32 = 5;
    pub const ALPHA: u32 = 6;
    pub const DER_F: u32 = 7;
}

static VARIABLES: [Variable; 8] = [
    sliding_velocity_input(vr::V),
    Variable::output(
        vr::F,
        "F",
        "N",
        "Friction force, resisting positive motion (the rig applies -F)",
        &[],
    )
    .with_state_dependencies(&[vr::F]),
    Variable::output(vr::Z, "z", "m", "Bristle deflection z = F/sigma", &[])
        .with_state_dependencies(&[vr::F]),
    Variable::boolean_output(
        vr::SLIDING,
        "sliding",
        "True when moving and |F| has reached 99 % of Fc",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::F]),
    Variable::parameter(
        vr::SIGMA,
        "sigma",
        87750.0,
        "N/m",
        "Rest stiffness dF/dx at F = 0 (Sun et al. 2016, Table 7)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::FC,
        "Fc",
        2.0,
        "N",
        "Coulomb friction level (Sun et al. 2016, Table 7)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::ALPHA,
        "alpha",
        1.0,
        "",
        "Shape exponent (alpha = 1: classical Dahl)",
    )
    .with_min(0.0),
    Variable::derivative(
        vr::DER_F,
        "der(F)",
        "N/s",
        "dF/dt = sigma*|y|^alpha*sgn(y)*v, y = 1 - F/Fc*sgn(v): the derivative of the continuous state F (Model Exchange)",
        &[vr::V],
        &[vr::F],
    ),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "Dahl",
    model_identifier: "Dahl",
    guid: "{a54e3c99-50b7-48eb-af8d-f492d8bea339}",
    description: "Dahl friction: dF/dx = sigma*|1 - F/Fc*sgn v|^alpha*sgn(1 - F/Fc*sgn v), dF/dt = dF/dx*v; exact update in x for every alpha.",
    source: "Dahl 1968; Sun et al. 2016 eq. 2-3, 16-17; Thimmalapura 2004 eq. 2.4-2.5. See docs/models.md.",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment { start_time: 0.0, stop_time: 1.0, step_size: 1e-3 },
    capabilities: Capabilities::FULL,
    model_exchange: Some(ModelExchange {
        states: &[ContinuousState {
            state: vr::F,
            derivative: vr::DER_F,
        }],
        event_indicators: 1,
        states_jump_at_events: false,
    }),
};

#[derive(Clone, Debug)]
pub struct DahlFmu {
    law: Dahl,
}

impl Default for DahlFmu {
    fn default() -> Self {
        DahlFmu {
            law: Dahl::new(DahlParams::default()).expect("default parameters are valid"),
        }
    }
}

impl DahlFmu {
    pub fn params(values: &Values) -> DahlParams {
        DahlParams {
            sigma: values.real(vr::SIGMA),
            fc: values.real(vr::FC),
            alpha: values.real(vr::ALPHA),
        }
    }
}

impl Model for DahlFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        self.law = Dahl::new(Self::params(values)).map_err(param_err)?;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let v = values.real(vr::V);
        values.set(vr::F, self.law.force());
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

    /// dF/dt = (dF/dx)·v (Sun et al. 2016 eq. 3); dz/dt = (dF/dt)/σ.
    fn output_derivative(&self, values: &Values, _slopes: &[f64], output: u32) -> Option<f64> {
        let p = self.law.params();
        let v = values.real(vr::V);
        let y = 1.0 - self.law.force() / p.fc * v.signum();
        let rate = if v == 0.0 {
            0.0
        } else {
            p.sigma * y.abs().powf(p.alpha) * y.signum() * v
        };
        match output {
            vr::F => Some(rate),
            vr::Z => Some(rate / p.sigma),
            _ => None,
        }
    }

    /// `dF/dt` at the current force and velocity: the law's rate, which its
    /// step integrates exactly.
    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        dx[0] = self.law.force_rate(self.law.force(), values.real(vr::V));
    }

    fmi2_cs::ode_is_self!();
}

/// Model Exchange: the state is `F`; the one event indicator is `v`, where
/// `sgn v` switches the law's branch (the rate has a kink there); no
/// discrete state, so an event changes nothing.
impl Ode for DahlFmu {
    fmi2_cs::delegate_continuous_states!(law);

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        z[0] = values.real(vr::V);
    }

    /// `F` on the scale of `Fc`.
    fn nominals(&self, values: &Values, nominal: &mut [f64]) {
        nominal[0] = Self::params(values).fc;
    }

    fn event_update(&mut self, _values: &Values) -> bool {
        false
    }

    /// `∂(dF/dt)/∂F`, `∂(dF/dt)/∂v` ([`Dahl::force_rate_partials`]); the
    /// outputs `F` (the state) and `z = F/σ` do not depend on `v`.
    fn partial_derivative(&self, values: &Values, unknown: u32, known: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let (by_f, by_v) = match unknown {
            vr::DER_F => self.law.force_rate_partials(self.law.force(), v),
            vr::F => (1.0, 0.0),
            vr::Z => (1.0 / self.law.params().sigma, 0.0),
            _ => return None,
        };
        match known {
            vr::F => Some(by_f),
            vr::V => Some(by_v),
            _ => None,
        }
    }
}
