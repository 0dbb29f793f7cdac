//! `Dahl.fmu`: the Dahl law (Dahl 1968; Sun et al. 2016 eq. 2–3, 16–17;
//! docs/models.md "Dahl"), integrated exactly in the displacement domain
//! for every α in Co-Simulation; in Model Exchange the force of the law
//! `F_dahl` (a local variable) is the continuous state and `dF_dahl/dt`
//! ([`Dahl::force_rate`]) its derivative. The output is
//! `F = F_dahl + F_offset`.

use crate::{input_ramp, param_err, sliding_velocity_input};
use fmi_export::{
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
    /// `der(F_dahl)` (named `der(F)` while the state was the output `F`).
    pub const DER_F_DAHL: u32 = 7;
    /// Added after the first version, after the derivative: the state
    /// `F_dahl` and the parameter `F_offset`.
    pub const F_DAHL: u32 = 8;
    pub const F_OFFSET: u32 = 9;
    /// Added with the energy outputs of the newer laws.
    pub const P_DISS: u32 = 10;
    pub const E_STORED: u32 = 11;
}

static VARIABLES: [Variable; 12] = [
    sliding_velocity_input(vr::V),
    Variable::output(
        vr::F,
        "F",
        "N",
        "Friction force F = F_dahl + F_offset, resisting positive motion (the rig applies -F)",
        &[],
    )
    .with_state_dependencies(&[vr::F_DAHL]),
    Variable::output(vr::Z, "z", "m", "Bristle deflection z = F_dahl/sigma", &[])
        .with_state_dependencies(&[vr::F_DAHL]),
    Variable::boolean_output(
        vr::SLIDING,
        "sliding",
        "True when moving and |F_dahl| has reached 99 % of Fc",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::F_DAHL]),
    Variable::parameter(
        vr::SIGMA,
        "sigma",
        87750.0,
        "N/m",
        "Rest stiffness dF/dx at F_dahl = 0 (Sun et al. 2016, Table 7)",
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
        vr::DER_F_DAHL,
        "der(F_dahl)",
        "N/s",
        "dF_dahl/dt = sigma*|y|^alpha*sgn(y)*v, y = 1 - F_dahl/Fc*sgn(v): the derivative of the continuous state F_dahl (Model Exchange)",
        &[vr::V],
        &[vr::F_DAHL],
    ),
    Variable::state(
        vr::F_DAHL,
        "F_dahl",
        "N",
        "Force of the Dahl law, without the offset: the continuous state (Model Exchange); 0 at the start",
    ),
    Variable::parameter(
        vr::F_OFFSET,
        "F_offset",
        0.0,
        "N",
        "Constant force on the contact, added to F at rest and in motion (as the offset of Janot, Gautier, Brunot 2019); the Dahl law does not see it",
    ),
    Variable::output(
        vr::P_DISS,
        "P_diss",
        "W",
        "Power the contact dissipates, F*v - F_dahl*dF_dahl/dt/sigma = F_dahl*v*(1 - |y|^alpha*sgn(y)) + F_offset*v: the law's part never negative",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::F_DAHL]),
    Variable::output(
        vr::E_STORED,
        "E_stored",
        "J",
        "Elastic energy held in the contact, F_dahl^2/(2*sigma)",
        &[],
    )
    .with_state_dependencies(&[vr::F_DAHL]),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "Dahl",
    model_identifier: "Dahl",
    guid: "{a54e3c99-50b7-48eb-af8d-f492d8bea339}",
    description: "Dahl friction: dF_dahl/dx = sigma*|1 - F_dahl/Fc*sgn v|^alpha*sgn(1 - F_dahl/Fc*sgn v), dF_dahl/dt = dF_dahl/dx*v, F = F_dahl + F_offset; exact update in x for every alpha.",
    source: "Dahl 1968; Sun et al. 2016 eq. 2-3, 16-17; Thimmalapura 2004 eq. 2.4-2.5; Janot, Gautier, Brunot 2019 (offset). See docs/models.md.",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment { start_time: 0.0, stop_time: 1.0, step_size: 1e-3 },
    capabilities: Capabilities::FULL,
    co_simulation_states: &[],
    model_exchange: Some(ModelExchange {
        states: &[ContinuousState {
            state: vr::F_DAHL,
            derivative: vr::DER_F_DAHL,
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
            f_offset: values.real(vr::F_OFFSET),
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

    /// The outputs, and the local state `F_dahl`.
    fn compute_outputs(&self, values: &mut Values) {
        let v = values.real(vr::V);
        values.set(vr::F, self.law.force());
        values.set(vr::Z, self.law.z());
        values.set_boolean(vr::SLIDING, self.law.sliding(v));
        values.set(vr::F_DAHL, self.law.dahl_force());
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

    /// dF/dt = dF_dahl/dt = (dF_dahl/dx)·v (Sun et al. 2016 eq. 3; the
    /// offset is constant); dz/dt = (dF_dahl/dt)/σ.
    fn output_derivative(&self, values: &Values, _slopes: &[f64], output: u32) -> Option<f64> {
        let rate = self
            .law
            .force_rate(self.law.dahl_force(), values.real(vr::V));
        match output {
            vr::F => Some(rate),
            vr::Z => Some(rate / self.law.params().sigma),
            _ => None,
        }
    }

    /// `dF_dahl/dt` at the current state and velocity: the law's rate,
    /// which its step integrates exactly.
    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        dx[0] = self
            .law
            .force_rate(self.law.dahl_force(), values.real(vr::V));
    }

    fmi_export::ode_is_self!();
}

/// Model Exchange: the state is `F_dahl`; the one event indicator is `v`,
/// where `sgn v` switches the law's branch (the rate has a kink there); no
/// discrete state, so an event changes nothing.
impl Ode for DahlFmu {
    fmi_export::delegate_continuous_states!(law);

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        z[0] = values.real(vr::V);
    }

    /// `F_dahl` on the scale of `Fc`.
    fn nominals(&self, values: &Values, nominal: &mut [f64]) {
        nominal[0] = Self::params(values).fc;
    }

    fn event_update(&mut self, _values: &Values) -> bool {
        false
    }

    /// `∂(dF_dahl/dt)/∂F_dahl`, `∂(dF_dahl/dt)/∂v`
    /// ([`Dahl::force_rate_partials`]); the outputs `F = F_dahl + F_offset`
    /// and `z = F_dahl/σ` do not depend on `v` (nor on the offset).
    fn partial_derivative(&self, values: &Values, unknown: u32, known: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let f = self.law.dahl_force();
        let sigma = self.law.params().sigma;
        let (by_f, by_v) = match unknown {
            vr::DER_F_DAHL => self.law.force_rate_partials(f, v),
            vr::F => (1.0, 0.0),
            vr::Z => (1.0 / sigma, 0.0),
            // P = (F_dahl + F_offset)·v − F_dahl·Ḟ(F_dahl, v)/σ
            vr::P_DISS => {
                let rate = self.law.force_rate(f, v);
                let (rf, rv) = self.law.force_rate_partials(f, v);
                (
                    v - (rate + f * rf) / sigma,
                    self.law.force() - f * rv / sigma,
                )
            }
            vr::E_STORED => (f / sigma, 0.0),
            _ => return None,
        };
        match known {
            vr::F_DAHL => Some(by_f),
            vr::V => Some(by_v),
            _ => None,
        }
    }
}
