//! `Bristle2D.fmu`: the two-dimensional reset-integrator bristle of Wijata
//! et al. 2016, with the equations derived in docs/models.md
//! "Two-dimensional bristle"; exact for piecewise-constant slip velocity in
//! Co-Simulation. The law is an ODE (deterministic, one continuous state
//! `z` that an exact update or an integrator carries alike) with a switch,
//! the boundary of the stiction disc, so it has a Model Exchange interface
//! too ([`Bristle2DMe`]).

use crate::{input_ramp, param_err};
use fmi_export::{
    Capabilities, ContinuousState, DefaultExperiment, Model, ModelExchange, ModelInfo, Ode, Values,
    Variable,
};
use friction_laws::bristle2d::{Bristle2D, Bristle2DParams};

pub mod vr {
    pub const V1: u32 = 0;
    pub const V2: u32 = 1;
    pub const F1: u32 = 2;
    pub const F2: u32 = 3;
    pub const Z1: u32 = 4;
    pub const Z2: u32 = 5;
    pub const SLIDING: u32 = 6;
    pub const SIGMA01: u32 = 7;
    pub const SIGMA02: u32 = 8;
    pub const SIGMA11: u32 = 9;
    pub const SIGMA12: u32 = 10;
    pub const A1: u32 = 11;
    pub const A2: u32 = 12;
    pub const Z0: u32 = 13;
    pub const AV: u32 = 14;
    pub const DER_Z1: u32 = 15;
    pub const DER_Z2: u32 = 16;
    /// Added with the energy outputs of the newer laws.
    pub const P_DISS: u32 = 17;
    pub const E_STORED: u32 = 18;
}

const V: &[u32] = &[vr::V1, vr::V2];
const Z: &[u32] = &[vr::Z1, vr::Z2];

static VARIABLES: [Variable; 19] = [
    Variable::input(vr::V1, "v1", 0.0, "m/s", 1e-3, "Slip velocity along axis 1"),
    Variable::input(vr::V2, "v2", 0.0, "m/s", 1e-3, "Slip velocity along axis 2"),
    Variable::output(
        vr::F1,
        "F1",
        "N",
        "Friction force along axis 1 (the rig applies -F1)",
        V,
    )
    .with_state_dependencies(Z),
    Variable::output(
        vr::F2,
        "F2",
        "N",
        "Friction force along axis 2 (the rig applies -F2)",
        V,
    )
    .with_state_dependencies(Z),
    Variable::output(vr::Z1, "z1", "m", "Bristle deflection along axis 1", &[])
        .with_state_dependencies(&[vr::Z1]),
    Variable::output(vr::Z2, "z2", "m", "Bristle deflection along axis 2", &[])
        .with_state_dependencies(&[vr::Z2]),
    Variable::boolean_output(
        vr::SLIDING,
        "sliding",
        "True when |z| = z0 and the slip strains the bristle outward",
        V,
    )
    .with_state_dependencies(Z),
    Variable::parameter(
        vr::SIGMA01,
        "sigma01",
        1e4,
        "N/m",
        "Bristle stiffness along axis 1 (Wijata et al. 2016: 1e4 N/m)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::SIGMA02,
        "sigma02",
        1e4,
        "N/m",
        "Bristle stiffness along axis 2 (Wijata et al. 2016: 1e4 N/m)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::SIGMA11,
        "sigma11",
        74.15,
        "N.s/m",
        "Bristle damping along axis 1 (Wijata et al. 2016: 74.15 N.s/m)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::SIGMA12,
        "sigma12",
        74.15,
        "N.s/m",
        "Bristle damping along axis 2 (Wijata et al. 2016: 74.15 N.s/m)",
    )
    .with_min(0.0),
    Variable::parameter(vr::A1, "a1", 0.1, "", "Stiction gradient along axis 1").with_min(0.0),
    Variable::parameter(vr::A2, "a2", 0.1, "", "Stiction gradient along axis 2").with_min(0.0),
    Variable::parameter(
        vr::Z0,
        "z0",
        1e-4,
        "m",
        "Radius of the stiction disc |z| < z0",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::AV,
        "av",
        1e-2,
        "m/s",
        "Damping decay velocity: sigma1i(|v|) = sigma1i*exp(-(|v|/av)^2); 0 = constant",
    )
    .with_min(0.0),
    Variable::derivative(
        vr::DER_Z1,
        "der(z1)",
        "m/s",
        "dz1/dt of dz/dt = v - [sliding]*(z.v)*z/|z|^2: the derivative of the continuous state z1 (Model Exchange)",
        V,
        Z,
    ),
    Variable::derivative(
        vr::DER_Z2,
        "der(z2)",
        "m/s",
        "dz2/dt of dz/dt = v - [sliding]*(z.v)*z/|z|^2: the derivative of the continuous state z2 (Model Exchange)",
        V,
        Z,
    ),
    Variable::output(
        vr::P_DISS,
        "P_diss",
        "W",
        "Power the contact dissipates, F.v - dE_stored/dt: the dampers inside the stiction disc, sigma0*z.v + damping sliding on its boundary (never negative for equal axes)",
        V,
    )
    .with_state_dependencies(Z),
    Variable::output(
        vr::E_STORED,
        "E_stored",
        "J",
        "Elastic energy held in the bristle, ((1 + a1)*sigma01*z1^2 + (1 + a2)*sigma02*z2^2)/2",
        &[],
    )
    .with_state_dependencies(Z),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "Bristle2D",
    model_identifier: "Bristle2D",
    guid: "{4ac05ffa-4571-4523-9d95-9effa10f3869}",
    description: "Two-dimensional bristle (reset integrator): dz/dt = v - [|z| >= z0 and z.v > 0]*(z.v)*z/|z|^2; Fi = (1 + ai(|z|))*sigma0i*zi + sigma1i(|v|)*dzi/dt.",
    source: "Wijata, Awrejcewicz, Matej, Makowski 2016; equations derived in docs/models.md.",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment { start_time: 0.0, stop_time: 1.0, step_size: 1e-3 },
    capabilities: Capabilities::FULL,
    co_simulation_states: &[],
    model_exchange: Some(ModelExchange {
        states: &[
            ContinuousState {
                state: vr::Z1,
                derivative: vr::DER_Z1,
            },
            ContinuousState {
                state: vr::Z2,
                derivative: vr::DER_Z2,
            },
        ],
        event_indicators: 1,
        // put back on the circle at events
        states_jump_at_events: true,
    }),
};

#[derive(Clone, Debug)]
pub struct Bristle2DFmu {
    law: Bristle2D,
}

impl Default for Bristle2DFmu {
    fn default() -> Self {
        Bristle2DFmu {
            law: Bristle2D::new(Bristle2DParams::default()).expect("default parameters are valid"),
        }
    }
}

impl Bristle2DFmu {
    pub fn params(values: &Values) -> Bristle2DParams {
        Bristle2DParams {
            sigma01: values.real(vr::SIGMA01),
            sigma02: values.real(vr::SIGMA02),
            sigma11: values.real(vr::SIGMA11),
            sigma12: values.real(vr::SIGMA12),
            a1: values.real(vr::A1),
            a2: values.real(vr::A2),
            z0: values.real(vr::Z0),
            av: values.real(vr::AV),
        }
    }
}

impl Model for Bristle2DFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        self.law = Bristle2D::new(Self::params(values)).map_err(param_err)?;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let v = [values.real(vr::V1), values.real(vr::V2)];
        let f = self.law.force(v);
        let z = self.law.z();
        values.set(vr::F1, f[0]);
        values.set(vr::F2, f[1]);
        values.set(vr::Z1, z[0]);
        values.set(vr::Z2, z[1]);
        values.set_boolean(vr::SLIDING, self.law.sliding(v));
        values.set(vr::P_DISS, self.law.dissipated_power(v));
        values.set(vr::E_STORED, self.law.stored_energy());
    }

    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        let ramp = |i| input_ramp(values, slopes, i);
        self.law.step(ramp(vr::V1), ramp(vr::V2), h);
        Ok(())
    }

    fmi_export::delegate_state!(law);

    /// Directional derivatives by replaying the step: no partial derivatives.
    fn supplies_partial_derivatives(&self) -> bool {
        false
    }

    fn output_derivative(&self, values: &Values, _slopes: &[f64], output: u32) -> Option<f64> {
        let z_dot = self.law.z_dot([values.real(vr::V1), values.real(vr::V2)]);
        match output {
            vr::Z1 => Some(z_dot[0]),
            vr::Z2 => Some(z_dot[1]),
            _ => None,
        }
    }

    /// `dz/dt` with the contact state of the deflection (on the boundary
    /// when `|z| = z0`).
    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        dx.copy_from_slice(&self.law.z_dot(slip(values)));
    }
}

/// The slip velocity `(v1, v2)` in `values`.
fn slip(values: &Values) -> [f64; 2] {
    [values.real(vr::V1), values.real(vr::V2)]
}

/// `Bristle2D.fmu` for Model Exchange: the law's equations
/// ([`Bristle2D::z_rate`], [`Bristle2D::force_of`]) with the contact state
/// (inside the disc, or on its boundary) held as a discrete state that
/// changes at events only, as the monolithic reference solutions hold it:
/// an integrator keeps `|z| = z0` only to its tolerance, and deciding the
/// contact from `|z|` would switch the equations at every step. The
/// continuous states are `z1`, `z2`, taken as the integrator gives them.
#[derive(Clone, Debug)]
pub struct Bristle2DMe {
    law: Bristle2D,
    z: [f64; 2],
    on_boundary: bool,
}

impl Default for Bristle2DMe {
    fn default() -> Self {
        Bristle2DMe {
            law: Bristle2D::new(Bristle2DParams::default()).expect("default parameters are valid"),
            z: [0.0; 2],
            on_boundary: false,
        }
    }
}

impl Model for Bristle2DMe {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        self.law = Bristle2D::new(Bristle2DFmu::params(values)).map_err(param_err)?;
        self.z = [0.0; 2];
        self.on_boundary = false;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let v = slip(values);
        let f = self.law.force_of(self.z, v, self.on_boundary);
        values.set(vr::F1, f[0]);
        values.set(vr::F2, f[1]);
        values.set(vr::Z1, self.z[0]);
        values.set(vr::Z2, self.z[1]);
        let sliding = self.law.sliding_of(self.z, v, self.on_boundary);
        values.set_boolean(vr::SLIDING, sliding);
        let power = self.law.dissipated_power_of(self.z, v, self.on_boundary);
        values.set(vr::P_DISS, power);
        values.set(vr::E_STORED, self.law.stored_energy_of(self.z));
    }

    /// Never called: a Model Exchange instance takes no communication
    /// steps (the state table refuses `fmi2DoStep`); the importer
    /// integrates.
    fn do_step(&mut self, _values: &Values, _slopes: &[f64], _h: f64) -> Result<(), String> {
        Err("a Model Exchange instance takes no communication steps".into())
    }

    /// `[z1, z2, on_boundary]`.
    fn save_state(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&[self.z[0], self.z[1], self.on_boundary as u8 as f64]);
    }

    fn restore_state(&mut self, state: &[f64]) -> Result<(), String> {
        match state {
            [z1, z2, b] if z1.is_finite() && z2.is_finite() && (*b == 0.0 || *b == 1.0) => {
                self.z = [*z1, *z2];
                self.on_boundary = *b == 1.0;
                Ok(())
            }
            _ => Err(format!(
                "2-D bristle state for Model Exchange is [z1, z2, on_boundary (0 or 1)], got {state:?}"
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
        dx.copy_from_slice(&self.law.z_rate(self.z, slip(values), self.on_boundary));
    }

    fmi_export::ode_is_self!();
}

/// The states `z1`, `z2`; one event indicator, the switching function of
/// the contact state ([`Bristle2D::switching_function`]): it crosses zero
/// where the deflection reaches the boundary and where the slip turns
/// inward and releases it. At an event the contact state switches and a
/// deflection on the boundary is put back on the circle
/// ([`Bristle2D::at_event`]).
impl Ode for Bristle2DMe {
    fn continuous_states(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.z);
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        self.z = [x[0], x[1]];
        Ok(())
    }

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        z[0] = self
            .law
            .switching_function(self.z, slip(values), self.on_boundary);
    }

    /// Both on the scale of the stiction radius `z0`.
    fn nominals(&self, values: &Values, nominal: &mut [f64]) {
        let z0 = Bristle2DFmu::params(values).z0;
        nominal.fill(z0);
    }

    fn event_update(&mut self, values: &Values) -> bool {
        let (z, on_boundary) = self.law.at_event(self.z, slip(values), self.on_boundary);
        let changed = z != self.z;
        self.z = z;
        self.on_boundary = on_boundary;
        changed
    }

    /// The law's closed forms ([`Bristle2D::partials`]) for `der(z1)`,
    /// `der(z2)`, `F1`, `F2`; the outputs `z1`, `z2` are the states.
    fn partial_derivative(&self, values: &Values, unknown: u32, known: u32) -> Option<f64> {
        let d = self.law.partials(self.z, slip(values), self.on_boundary);
        let (p_z, p_v, e_z) = self
            .law
            .energy_partials(self.z, slip(values), self.on_boundary);
        let (by_z, by_v) = match unknown {
            vr::P_DISS => (p_z, p_v),
            vr::E_STORED => (e_z, [0.0; 2]),
            vr::DER_Z1 => (d.rate_z[0], d.rate_v[0]),
            vr::DER_Z2 => (d.rate_z[1], d.rate_v[1]),
            vr::F1 => (d.force_z[0], d.force_v[0]),
            vr::F2 => (d.force_z[1], d.force_v[1]),
            vr::Z1 => ([1.0, 0.0], [0.0; 2]),
            vr::Z2 => ([0.0, 1.0], [0.0; 2]),
            _ => return None,
        };
        match known {
            vr::Z1 => Some(by_z[0]),
            vr::Z2 => Some(by_z[1]),
            vr::V1 => Some(by_v[0]),
            vr::V2 => Some(by_v[1]),
            _ => None,
        }
    }
}
