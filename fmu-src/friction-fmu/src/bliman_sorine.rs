//! `BlimanSorine.fmu`: the Bliman–Sorine law (Bliman and Sorine 1991–1995;
//! Sun et al. 2016 eq. 4–8; docs/models.md "Bliman–Sorine"), integrated
//! exactly in the displacement domain in Co-Simulation; in Model Exchange
//! the two forces `x1`, `x2` are the continuous states and their rates
//! ([`BlimanSorine::rates`]) the derivatives. The parameters are either
//! `f1, f2, eps_f, eta` or, with `from_reference_points`, the two points
//! of a hysteresis loop Sun et al. identify them from.

use crate::{input_ramp, param_err, sliding_velocity_input};
use fmi_export::{
    Capabilities, ContinuousState, DefaultExperiment, Model, ModelExchange, ModelInfo, Ode, Values,
    Variable,
};
use friction_laws::bliman_sorine::{BlimanSorine, BlimanSorineParams, ReferencePoints};

pub mod vr {
    pub const V: u32 = 0;
    pub const F: u32 = 1;
    pub const X1: u32 = 2;
    pub const X2: u32 = 3;
    pub const SLIDING: u32 = 4;
    pub const P_DISS: u32 = 5;
    pub const E_STORED: u32 = 6;
    pub const F1: u32 = 7;
    pub const F2: u32 = 8;
    pub const EPS_F: u32 = 9;
    pub const ETA: u32 = 10;
    pub const FROM_REFERENCE_POINTS: u32 = 11;
    pub const FS_REF: u32 = 12;
    pub const FC_REF: u32 = 13;
    pub const X_E: u32 = 14;
    pub const X_P: u32 = 15;
    pub const DER_X1: u32 = 16;
    pub const DER_X2: u32 = 17;
}

static VARIABLES: [Variable; 18] = [
    sliding_velocity_input(vr::V),
    Variable::output(
        vr::F,
        "F",
        "N",
        "Friction force F = x1 + x2, resisting positive motion (the rig applies -F)",
        &[],
    )
    .with_state_dependencies(&[vr::X1, vr::X2]),
    Variable::state(
        vr::X1,
        "x1",
        "N",
        "Fast element's force: dx1/dt = (f1*v - |v|*x1)/(eta*eps_f); 0 at the start (a continuous state in Model Exchange)",
    ),
    Variable::state(
        vr::X2,
        "x2",
        "N",
        "Slow element's force: dx2/dt = (-f2*v - |v|*x2)/eps_f; 0 at the start (a continuous state in Model Exchange)",
    ),
    Variable::boolean_output(
        vr::SLIDING,
        "sliding",
        "True when moving and F is within 1 % of the Coulomb level f1 - f2",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::X1, vr::X2]),
    Variable::output(
        vr::P_DISS,
        "P_diss",
        "W",
        "Power the contact dissipates, P_diss = F*v - dE_stored/dt = |v|*(x1^2/f1 - x2^2/f2): Fc*|v| in sliding, negative for part of the way after a reversal, its integral over a closed loop the loop's area",
        &[vr::V],
    )
    .with_state_dependencies(&[vr::X1, vr::X2]),
    Variable::output(
        vr::E_STORED,
        "E_stored",
        "J",
        "Elastic energy of the two elements, E_stored = x1^2/(2*k1) - x2^2/(2*k2), k1 = f1/(eta*eps_f), k2 = f2/eps_f (the slow element enters with the sign of its force)",
        &[],
    )
    .with_state_dependencies(&[vr::X1, vr::X2]),
    Variable::parameter(
        vr::F1,
        "f1",
        19.875,
        "N",
        "Level of the fast element (Sun et al. 2016, Table 8, trial 6)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::F2,
        "f2",
        17.8227,
        "N",
        "Level of the slow element, < f1; Coulomb level f1 - f2 (Sun et al. 2016, Table 8, trial 6)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::EPS_F,
        "eps_f",
        1.21e-4,
        "m",
        "Length of the slow element (Sun et al. 2016, Table 8, trial 6)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::ETA,
        "eta",
        0.9063,
        "",
        "Ratio of the fast element's length to the slow one's, 0 < eta < 1 (Sun et al. 2016, Table 8, trial 6)",
    )
    .with_min(0.0)
    .with_max(1.0),
    Variable::boolean_parameter(
        vr::FROM_REFERENCE_POINTS,
        "from_reference_points",
        false,
        "Take f1, f2, eps_f, eta from the loop's reference points (Fs_ref, x_e) and (x_p, Fc_ref) by the map of Bliman and Sorine 1995 (Sun et al. 2016 eq. 5-8) instead of their own values",
    ),
    Variable::parameter(
        vr::FS_REF,
        "Fs_ref",
        2.5017013870499,
        "N",
        "Break-away peak of the loop (with from_reference_points); default: the peak of Table 8, trial 6",
    ),
    Variable::parameter(
        vr::FC_REF,
        "Fc_ref",
        2.0523,
        "N",
        "Coulomb level the loop settles at (with from_reference_points)",
    ),
    Variable::parameter(
        vr::X_E,
        "x_e",
        2.4270202376850e-4,
        "m",
        "Displacement from the velocity reversal at the peak (with from_reference_points)",
    ),
    Variable::parameter(
        vr::X_P,
        "x_p",
        3.63e-4,
        "m",
        "Displacement from the reversal beyond which the force has settled, 3*eps_f (with from_reference_points)",
    ),
    Variable::derivative(
        vr::DER_X1,
        "der(x1)",
        "N/s",
        "dx1/dt = (f1*v - |v|*x1)/(eta*eps_f) (Model Exchange)",
        &[vr::V],
        &[vr::X1],
    ),
    Variable::derivative(
        vr::DER_X2,
        "der(x2)",
        "N/s",
        "dx2/dt = (-f2*v - |v|*x2)/eps_f (Model Exchange)",
        &[vr::V],
        &[vr::X2],
    ),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "BlimanSorine",
    model_identifier: "BlimanSorine",
    guid: "{0f6b2d1e-7c43-4a8e-9d5b-3e21c8a4b7f6}",
    description: "Bliman-Sorine friction: dx1/dt = (f1*v - |v|*x1)/(eta*eps_f), dx2/dt = (-f2*v - |v|*x2)/eps_f, F = x1 + x2; rate-independent, exact update in x.",
    source: "Bliman and Sorine 1991, 1993, 1995; Sun et al. 2016 eq. 4-8 and Table 8. See docs/models.md.",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 18.85,
        step_size: 1e-3,
    },
    capabilities: Capabilities::FULL,
    co_simulation_states: &[],
    model_exchange: Some(ModelExchange {
        states: &[
            ContinuousState {
                state: vr::X1,
                derivative: vr::DER_X1,
            },
            ContinuousState {
                state: vr::X2,
                derivative: vr::DER_X2,
            },
        ],
        event_indicators: 1,
        states_jump_at_events: false,
    }),
};

#[derive(Clone, Debug)]
pub struct BlimanSorineFmu {
    law: BlimanSorine,
}

impl Default for BlimanSorineFmu {
    fn default() -> Self {
        BlimanSorineFmu {
            law: BlimanSorine::new(BlimanSorineParams::default())
                .expect("default parameters are valid"),
        }
    }
}

impl BlimanSorineFmu {
    /// The parameters: their own values, or from the reference points.
    pub fn params(values: &Values) -> Result<BlimanSorineParams, String> {
        if values.boolean(vr::FROM_REFERENCE_POINTS) {
            BlimanSorineParams::from_reference_points(ReferencePoints {
                fs: values.real(vr::FS_REF),
                fc: values.real(vr::FC_REF),
                x_e: values.real(vr::X_E),
                x_p: values.real(vr::X_P),
            })
            .map_err(|e| format!("from_reference_points: {e}"))
        } else {
            Ok(BlimanSorineParams {
                f1: values.real(vr::F1),
                f2: values.real(vr::F2),
                eps_f: values.real(vr::EPS_F),
                eta: values.real(vr::ETA),
            })
        }
    }
}

impl BlimanSorineFmu {
    /// The partials of `P_diss = |v|·(x1²/f1 − x2²/f2)` and
    /// `E_stored = x1²/(2k1) − x2²/(2k2)` in `x1`, `x2` and `v` (at
    /// `v = 0` the kink of `|v|`: the mean of the two sides, 0).
    fn energy_partial(&self, v: f64, unknown: u32, known: u32) -> Option<f64> {
        let p = self.law.params();
        let (x1, x2) = self.law.states();
        let s = if v == 0.0 { 0.0 } else { v.signum() };
        match (unknown, known) {
            (vr::P_DISS, vr::X1) => Some(2.0 * v.abs() * x1 / p.f1),
            (vr::P_DISS, vr::X2) => Some(-2.0 * v.abs() * x2 / p.f2),
            (vr::P_DISS, vr::V) => Some(s * (x1 * x1 / p.f1 - x2 * x2 / p.f2)),
            (vr::E_STORED, vr::X1) => Some(x1 * p.eta * p.eps_f / p.f1),
            (vr::E_STORED, vr::X2) => Some(-x2 * p.eps_f / p.f2),
            (vr::E_STORED, vr::V) => Some(0.0),
            _ => None,
        }
    }
}

impl Model for BlimanSorineFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        self.law = BlimanSorine::new(Self::params(values)?).map_err(param_err)?;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let v = values.real(vr::V);
        let (x1, x2) = self.law.states();
        values.set(vr::F, self.law.force());
        values.set(vr::X1, x1);
        values.set(vr::X2, x2);
        values.set_boolean(vr::SLIDING, self.law.sliding(v));
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

    /// `dF/dt = dx1/dt + dx2/dt`.
    fn output_derivative(&self, values: &Values, _slopes: &[f64], output: u32) -> Option<f64> {
        let (x1, x2) = self.law.states();
        let (r1, r2) = self.law.rates(x1, x2, values.real(vr::V));
        (output == vr::F).then_some(r1 + r2)
    }

    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        let (x1, x2) = self.law.states();
        let (r1, r2) = self.law.rates(x1, x2, values.real(vr::V));
        dx[0] = r1;
        dx[1] = r2;
    }

    fmi_export::ode_is_self!();
}

/// Model Exchange: the states are `x1`, `x2`; the one event indicator is
/// `v`, where `|v|` puts a kink in both rates; no discrete state.
impl Ode for BlimanSorineFmu {
    fmi_export::delegate_continuous_states!(law);

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        z[0] = values.real(vr::V);
    }

    /// Both states on the scale of their levels.
    fn nominals(&self, _values: &Values, nominal: &mut [f64]) {
        let p = self.law.params();
        nominal[0] = p.f1;
        nominal[1] = p.f2;
    }

    fn event_update(&mut self, _values: &Values) -> bool {
        false
    }

    /// The partials of the rates ([`BlimanSorine::rate_partials`]); the
    /// force `F = x1 + x2` has slope 1 in each state and none in `v`.
    fn partial_derivative(&self, values: &Values, unknown: u32, known: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let ((d11, d1v), (d22, d2v)) = self.law.rate_partials(v);
        match (unknown, known) {
            (vr::DER_X1, vr::X1) => Some(d11),
            (vr::DER_X1, vr::X2) => Some(0.0),
            (vr::DER_X1, vr::V) => Some(d1v),
            (vr::DER_X2, vr::X1) => Some(0.0),
            (vr::DER_X2, vr::X2) => Some(d22),
            (vr::DER_X2, vr::V) => Some(d2v),
            (vr::F, vr::X1 | vr::X2) => Some(1.0),
            (vr::F, vr::V) => Some(0.0),
            (vr::P_DISS | vr::E_STORED, _) => self.energy_partial(v, unknown, known),
            _ => None,
        }
    }
}
