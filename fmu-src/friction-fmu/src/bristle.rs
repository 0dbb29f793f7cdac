//! `Bristle.fmu`: the pre-sliding bristle model of Appels & Herder
//! (docs/models.md "Pre-sliding bristle model"), driven by the relative
//! displacement `x`.
//! A static, position-dependent law: the force follows `x` at once (direct
//! feedthrough), so the output is evaluated at the current input without
//! committing the move; `fmi2DoStep` commits it.

use crate::{input_ramp, param_err};
use fmi_export::{Capabilities, DefaultExperiment, Model, ModelInfo, Values, Variable};
use friction_laws::bristle::{Bristle, BristleParams};

pub mod vr {
    pub const X: u32 = 0;
    pub const F: u32 = 1;
    pub const N_CONNECTED: u32 = 2;
    pub const SLIDING: u32 = 3;
    pub const SIGMA_INI: u32 = 4;
    pub const DELTA_MAX: u32 = 5;
    pub const X_REL: u32 = 6;
    pub const STIFFNESS_FROM_LOAD: u32 = 7;
    pub const COUNT_FROM_LOAD: u32 = 8;
    pub const N_BRISTLES: u32 = 9;
    pub const C: u32 = 10;
    pub const MU_C: u32 = 11;
    pub const FN: u32 = 12;
    pub const SEED: u32 = 13;
    /// Added with the energy outputs of the newer laws.
    pub const P_DISS: u32 = 14;
    pub const E_STORED: u32 = 15;
}

/// Appels & Herder: lightest mass 0.352 kg, g = 9.81 m/s².
const APPELS_HERDER_NORMAL_FORCE: f64 = 0.352 * 9.81;

static VARIABLES: [Variable; 16] = [
    Variable::input(vr::X, "x", 0.0, "m", 1e-8, "Relative displacement of the body"),
    Variable::output(vr::F, "F", "N", "Friction force sigma_b*(sum of connected deflections + disconnected +-delta_max)", &[vr::X]),
    Variable::integer_output(vr::N_CONNECTED, "n_connected", "Number of connected bristles", &[vr::X]),
    Variable::boolean_output(vr::SLIDING, "sliding", "True when every bristle is disconnected (gross sliding)", &[vr::X]),
    Variable::parameter(vr::SIGMA_INI, "sigma_ini", 2.2173e7, "N/m", "Initial stiffness (all bristles), used when stiffness_from_load is false (Appels and Herder, Table 3)").with_min(0.0),
    Variable::parameter(vr::DELTA_MAX, "delta_max", 1.5584e-8, "m", "Bristle deflection at which it disconnects (Appels and Herder, Table 3)").with_min(0.0),
    Variable::parameter(vr::X_REL, "x_rel", 4.4206e-9, "m", "Mean relaxation of a reconnecting bristle (Appels and Herder, Table 3)").with_min(0.0),
    Variable::boolean_parameter(vr::STIFFNESS_FROM_LOAD, "stiffness_from_load", true, "sigma_ini = mu_c*Fn/delta_max, so the sliding level is mu_c*Fn (Appels and Herder's code)"),
    Variable::boolean_parameter(vr::COUNT_FROM_LOAD, "count_from_load", true, "Bristle count N = round(c*mu_c*Fn) (Appels and Herder) instead of n_bristles"),
    Variable::integer_parameter(vr::N_BRISTLES, "n_bristles", 100, "Bristle count when count_from_load is false (>= 1)"),
    Variable::parameter(vr::C, "c", 500.0, "1/N", "Scale factor of the bristle count (Appels and Herder: 500 gives about 100 bristles at 0.352 kg)").with_min(0.0),
    Variable::parameter(vr::MU_C, "mu_c", 0.0633, "", "Coulomb friction coefficient (Appels and Herder, Table 3)").with_min(0.0),
    Variable::parameter(vr::FN, "Fn", APPELS_HERDER_NORMAL_FORCE, "N", "Normal force m*g (Appels and Herder: 0.352 kg)").with_min(0.0),
    Variable::integer_parameter(vr::SEED, "seed", 1, "Random seed of the bristle realisation: same seed, bit-identical output"),
    Variable::output(vr::P_DISS, "P_diss", "W", "Mean power the contact dissipated over the last communication step, (integral of F dx - change of E_stored)/h: the sliding of disconnected bristles and the loss of each reconnection at a reversal (an impulse); never negative, 0 before the first step", &[]),
    Variable::output(vr::E_STORED, "E_stored", "J", "Elastic energy held in the bristles, sigma_b*(sum of connected deflections^2 + disconnected*delta_max^2)/2", &[vr::X]),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "Bristle",
    model_identifier: "Bristle",
    guid: "{676098e4-701d-41e0-b1ca-6d4cfe1c7bd8}",
    description: "Pre-sliding bristle friction: N bristles of stiffness sigma_ini/N with random pre-tension; each disconnects at |delta| >= delta_max; sliding level sigma_ini*delta_max; bristles reconnect with a random relaxation when the motion reverses.",
    source: "Appels and Herder (TU Delft), Appendix C code; reconnection on reversal derived here, see docs/models.md.",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment { start_time: 0.0, stop_time: 1.0, step_size: 1e-3 },
    capabilities: Capabilities::FULL,
    co_simulation_states: &[],
    model_exchange: None,
};

#[derive(Clone, Debug)]
pub struct BristleFmu {
    law: Bristle,
}

impl Default for BristleFmu {
    fn default() -> Self {
        BristleFmu {
            law: Bristle::new(BristleParams::default()).expect("default parameters are valid"),
        }
    }
}

impl BristleFmu {
    /// The law's parameters from the FMU's, resolving the from-load options.
    pub fn params(values: &Values) -> Result<BristleParams, String> {
        let (c, mu_c, fn_) = (
            values.real(vr::C),
            values.real(vr::MU_C),
            values.real(vr::FN),
        );
        let delta_max = values.real(vr::DELTA_MAX);
        // Checked first: the from-load stiffness divides by it.
        if !(delta_max.is_finite() && delta_max > 0.0) {
            return Err(format!(
                "invalid parameter delta_max = {delta_max}: must be finite and > 0"
            ));
        }
        let seed = values.integer(vr::SEED) as u32 as u64;
        let from_load =
            BristleParams::from_load(c, mu_c, fn_, delta_max, values.real(vr::X_REL), seed);
        let needs_load =
            values.boolean(vr::STIFFNESS_FROM_LOAD) || values.boolean(vr::COUNT_FROM_LOAD);
        if needs_load {
            for (name, value) in [("mu_c", mu_c), ("Fn", fn_)] {
                if !(value.is_finite() && value > 0.0) {
                    return Err(format!(
                        "invalid parameter {name} = {value}: must be finite and > 0"
                    ));
                }
            }
        }
        let sigma_ini = if values.boolean(vr::STIFFNESS_FROM_LOAD) {
            from_load.sigma_ini
        } else {
            values.real(vr::SIGMA_INI)
        };
        let n_bristles = if values.boolean(vr::COUNT_FROM_LOAD) {
            if !(c.is_finite() && c > 0.0) {
                return Err(format!("invalid parameter c = {c}: must be finite and > 0"));
            }
            from_load.n_bristles
        } else {
            let n = values.integer(vr::N_BRISTLES);
            if n < 1 {
                return Err(format!("invalid parameter n_bristles = {n}: must be >= 1"));
            }
            n as usize
        };
        Ok(BristleParams {
            sigma_ini,
            n_bristles,
            ..from_load
        })
    }
}

impl Model for BristleFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        self.law = Bristle::new(Self::params(values)?).map_err(param_err)?;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let x = values.real(vr::X);
        if x == self.law.position() {
            values.set(vr::F, self.law.force());
            values.set_integer(vr::N_CONNECTED, self.law.n_connected() as i32);
            values.set_boolean(vr::SLIDING, self.law.sliding());
            values.set(vr::E_STORED, self.law.stored_energy());
        } else {
            // one evaluation: a reversal rebuilds the offsets, O(N)
            let (force, n, energy) = self.law.outputs_at(x);
            values.set(vr::F, force);
            values.set_integer(vr::N_CONNECTED, n as i32);
            values.set_boolean(vr::SLIDING, n == 0);
            values.set(vr::E_STORED, energy);
        }
        values.set(vr::P_DISS, self.law.step_power());
    }

    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        self.law.step(input_ramp(values, slopes, vr::X), h);
        Ok(())
    }

    fmi_export::delegate_state!(law);

    /// ∂F/∂x is the tangent stiffness n_connected·σb at the current input,
    /// exact between disconnection events, whether or not a step preceded.
    fn partial_derivative(&self, values: &Values, output: u32, input: u32) -> Option<f64> {
        (output == vr::F && input == vr::X).then(|| self.law.stiffness_at(values.real(vr::X)))
    }

    fn needs_step_replay(&self) -> bool {
        false
    }

    /// dF/dt = (tangent stiffness)·dx/dt.
    fn output_derivative(&self, values: &Values, slopes: &[f64], output: u32) -> Option<f64> {
        (output == vr::F)
            .then(|| self.law.stiffness_at(values.real(vr::X)) * slopes[vr::X as usize])
    }
}
