//! `Classical.fmu`: Coulomb + viscous + static friction on the Stribeck
//! curve with Karnopp's zero-velocity band (Sun et al. 2016 eq. 1 and 12;
//! Thimmalapura 2004 eq. 2.1–2.3; Karnopp 1985; docs/models.md
//! "Classical"). The law has no state: its force follows from the two
//! inputs, the sliding velocity `v` and the force `F_app` the rest of the
//! system applies to the contact, which a stuck contact holds up to `Fs`.
//! In Model Exchange it has no continuous state either; its four event
//! indicators mark the switches, where the force jumps: the band's edges
//! `v = ±dv` and the static level `F_app = ±Fs`.

use crate::param_err;
use fmi_export::{
    Capabilities, DefaultExperiment, Model, ModelExchange, ModelInfo, Ode, Values, Variable,
};
use friction_laws::classical::{Branch, Classical, ClassicalParams};

pub mod vr {
    pub const V: u32 = 0;
    pub const F_APP: u32 = 1;
    pub const F: u32 = 2;
    pub const STUCK: u32 = 3;
    pub const P_DISS: u32 = 4;
    pub const E_STORED: u32 = 5;
    pub const FC: u32 = 6;
    pub const FS: u32 = 7;
    pub const VS: u32 = 8;
    pub const DELTA: u32 = 9;
    pub const SIGMA2: u32 = 10;
    pub const DV: u32 = 11;
}

static VARIABLES: [Variable; 12] = [
    Variable::input(
        vr::V,
        "v",
        0.0,
        "m/s",
        1e-3,
        "Sliding velocity of the body relative to the surface",
    ),
    Variable::input(
        vr::F_APP,
        "F_app",
        0.0,
        "N",
        1.0,
        "Force the rest of the system applies to the body along the contact (every force but friction, positive in the direction of positive v): held by a stuck contact up to Fs",
    ),
    Variable::output(
        vr::F,
        "F",
        "N",
        "Friction force resisting positive motion (the rig applies -F): F_app clipped to +-Fs inside the band |v| < dv, the Stribeck curve sgn(v)*(Fc + (Fs - Fc)*exp(-|v/vs|^delta)) + sigma2*v outside it",
        &[vr::V, vr::F_APP],
    ),
    Variable::boolean_output(
        vr::STUCK,
        "stuck",
        "True inside the band |v| < dv with |F_app| <= Fs",
        &[vr::V, vr::F_APP],
    ),
    Variable::output(
        vr::P_DISS,
        "P_diss",
        "W",
        "Power the contact dissipates, F*v (the law stores no energy); inside the band it can be slightly negative, |P_diss| < Fs*dv",
        &[vr::V, vr::F_APP],
    ),
    Variable::output(
        vr::E_STORED,
        "E_stored",
        "J",
        "Elastic energy held in the contact: 0, the law has no elastic state",
        &[],
    ),
    Variable::parameter(
        vr::FC,
        "Fc",
        1.284,
        "N",
        "Coulomb level (Sun et al. 2016, Table 6)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::FS,
        "Fs",
        2.35,
        "N",
        "Static level, >= Fc: the most a stuck contact holds, and the curve's value at v = 0+ (Sun et al. 2016, Table 6)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::VS,
        "vs",
        1.13975e-3,
        "m/s",
        "Stribeck velocity; 0: no Stribeck term, Fc*sgn(v) + sigma2*v in sliding (Sun et al. 2016 eq. 1) (Table 6)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::DELTA,
        "delta",
        2.0,
        "",
        "Stribeck exponent",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::SIGMA2,
        "sigma2",
        173.0,
        "N.s/m",
        "Viscous coefficient (Sun et al. 2016, Table 6)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::DV,
        "dv",
        1e-5,
        "m/s",
        "Half-width of Karnopp's zero-velocity band, inside which the contact sticks",
    )
    .with_min(0.0),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "Classical",
    model_identifier: "Classical",
    guid: "{5d8e1a42-96c7-4b3f-8e0a-2c7f41d9b6e3}",
    description: "Classical friction: Stribeck curve sgn(v)*(Fc + (Fs - Fc)*exp(-|v/vs|^delta)) + sigma2*v outside Karnopp's band |v| < dv, the applied force F_app clipped to +-Fs inside it.",
    source: "Sun et al. 2016 eq. 1 and 12, Table 6; Thimmalapura 2004 eq. 2.1-2.3; Karnopp 1985. See docs/models.md.",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 1.0,
        step_size: 1e-3,
    },
    capabilities: Capabilities::FULL,
    co_simulation_states: &[],
    model_exchange: Some(ModelExchange {
        states: &[],
        event_indicators: 4,
        states_jump_at_events: false,
    }),
};

#[derive(Clone, Debug)]
pub struct ClassicalFmu {
    law: Classical,
    /// In Model Exchange, the branch chosen at the last event, whose
    /// formula holds until the next ([`Classical::force_on`]); `None`
    /// before the first event and always in Co-Simulation, where the
    /// branch follows the inputs.
    latched: Option<Branch>,
}

impl Default for ClassicalFmu {
    fn default() -> Self {
        ClassicalFmu {
            law: Classical::new(ClassicalParams::default()).expect("default parameters are valid"),
            latched: None,
        }
    }
}

impl ClassicalFmu {
    /// The branch in force at these inputs: the latched one in Model
    /// Exchange, the inputs' own otherwise.
    fn branch(&self, v: f64, f_app: f64) -> Branch {
        self.latched.unwrap_or_else(|| self.law.branch(v, f_app))
    }

    pub fn params(values: &Values) -> ClassicalParams {
        ClassicalParams {
            fc: values.real(vr::FC),
            fs: values.real(vr::FS),
            vs: values.real(vr::VS),
            delta: values.real(vr::DELTA),
            sigma2: values.real(vr::SIGMA2),
            dv: values.real(vr::DV),
        }
    }
}

impl Model for ClassicalFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        self.law = Classical::new(Self::params(values)).map_err(param_err)?;
        self.latched = None;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let (v, f_app) = (values.real(vr::V), values.real(vr::F_APP));
        let branch = self.branch(v, f_app);
        let f = self.law.force_on(branch, v, f_app);
        values.set(vr::F, f);
        values.set_boolean(vr::STUCK, branch == Branch::Stuck);
        // (the law stores no energy: all of F·v is dissipated)
        values.set(vr::P_DISS, f * v);
        values.set(vr::E_STORED, 0.0);
    }

    /// Nothing to advance: the force is a function of the inputs.
    fn do_step(&mut self, _values: &Values, _slopes: &[f64], _h: f64) -> Result<(), String> {
        Ok(())
    }

    /// The state is the latched branch (Model Exchange), one number:
    /// its code, or −1 for none.
    fn save_state(&self, out: &mut Vec<f64>) {
        out.push(self.latched.map_or(-1.0, Branch::code));
    }

    fn state_len(&self) -> Option<usize> {
        Some(1)
    }

    fn write_state_into(&self, out: &mut [f64]) {
        out[0] = self.latched.map_or(-1.0, Branch::code);
    }

    fn state_is_finite(&self) -> Option<bool> {
        Some(true)
    }

    fn restore_state(&mut self, state: &[f64]) -> Result<(), String> {
        self.latched = match state {
            [code] if *code == -1.0 => None,
            [code] => Some(Branch::from_code(*code).ok_or_else(|| {
                format!("Classical: {code} is not a branch (0 to 3, or -1 for none)")
            })?),
            _ => {
                return Err(format!(
                    "Classical's state is one value (its branch), got {}",
                    state.len()
                ))
            }
        };
        Ok(())
    }

    fn clone_model(&self) -> Box<dyn Model> {
        Box::new(self.clone())
    }

    /// `∂F/∂v`, `∂F/∂F_app` ([`Classical::force_partials_on`] the branch in
    /// force) and those of `P_diss = F·v`.
    fn partial_derivative(&self, values: &Values, output: u32, input: u32) -> Option<f64> {
        let (v, f_app) = (values.real(vr::V), values.real(vr::F_APP));
        let branch = self.branch(v, f_app);
        let (by_v, by_app) = self.law.force_partials_on(branch, v);
        match (output, input) {
            (vr::F, vr::V) => Some(by_v),
            (vr::F, vr::F_APP) => Some(by_app),
            (vr::P_DISS, vr::V) => Some(by_v * v + self.law.force_on(branch, v, f_app)),
            (vr::P_DISS, vr::F_APP) => Some(by_app * v),
            (vr::E_STORED, vr::V | vr::F_APP) => Some(0.0),
            _ => None,
        }
    }

    fn needs_step_replay(&self) -> bool {
        false
    }

    /// `dF/dt = ∂F/∂v·dv/dt + ∂F/∂F_app·dF_app/dt` (between switches).
    fn output_derivative(&self, values: &Values, slopes: &[f64], output: u32) -> Option<f64> {
        let (v, f_app) = (values.real(vr::V), values.real(vr::F_APP));
        let (by_v, by_app) = self.law.force_partials_on(self.branch(v, f_app), v);
        (output == vr::F)
            .then(|| by_v * slopes[vr::V as usize] + by_app * slopes[vr::F_APP as usize])
    }

    fmi_export::ode_is_self!();
}

/// Model Exchange: no continuous states; the indicators are `v − dv`,
/// `v + dv`, `Fs − F_app` and `Fs + F_app`, each continuous in the inputs
/// and crossing zero where [`Classical::branch`] changes (the last two
/// change it only inside the band; outside it their crossings are
/// harmless events). The event iteration latches the branch of the
/// inputs at the event; between events the force is that branch's formula,
/// continuous, as the standard asks of the right-hand side an importer's
/// solver integrates.
impl Ode for ClassicalFmu {
    fn continuous_states(&self, _x: &mut [f64]) {}

    fn set_continuous_states(&mut self, _x: &[f64]) -> Result<(), String> {
        Ok(())
    }

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        let (v, f_app) = (values.real(vr::V), values.real(vr::F_APP));
        let p = self.law.params();
        z.copy_from_slice(&[v - p.dv, v + p.dv, p.fs - f_app, p.fs + f_app]);
    }

    fn nominals(&self, _values: &Values, _nominal: &mut [f64]) {}

    fn event_update(&mut self, values: &Values) -> bool {
        let (v, f_app) = (values.real(vr::V), values.real(vr::F_APP));
        self.latched = Some(match self.latched {
            None => self.law.branch(v, f_app),
            Some(from) => self.law.branch_after_event(from, v, f_app),
        });
        false
    }

    /// The outputs' partials with respect to the inputs, as in
    /// Co-Simulation.
    fn partial_derivative(&self, values: &Values, unknown: u32, known: u32) -> Option<f64> {
        Model::partial_derivative(self, values, unknown, known)
    }
}
