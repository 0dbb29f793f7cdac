//! `Bristle2D.fmu`: the two-dimensional reset-integrator bristle of Wijata
//! et al. 2016, with the equations derived in docs/models.md
//! "Two-dimensional bristle"; exact for piecewise-constant slip velocity.

use crate::{input_ramp, param_err};
use fmi2_cs::{Capabilities, DefaultExperiment, Model, ModelInfo, Values, Variable};
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
}

const V: &[u32] = &[vr::V1, vr::V2];

static VARIABLES: [Variable; 15] = [
    Variable::input(vr::V1, "v1", 0.0, "m/s", 1e-3, "Slip velocity along axis 1"),
    Variable::input(vr::V2, "v2", 0.0, "m/s", 1e-3, "Slip velocity along axis 2"),
    Variable::output(
        vr::F1,
        "F1",
        "N",
        "Friction force along axis 1 (the rig applies -F1)",
        V,
    ),
    Variable::output(
        vr::F2,
        "F2",
        "N",
        "Friction force along axis 2 (the rig applies -F2)",
        V,
    ),
    Variable::output(vr::Z1, "z1", "m", "Bristle deflection along axis 1", &[]),
    Variable::output(vr::Z2, "z2", "m", "Bristle deflection along axis 2", &[]),
    Variable::boolean_output(
        vr::SLIDING,
        "sliding",
        "True when |z| = z0 and the slip strains the bristle outward",
        V,
    ),
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
    }

    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        let ramp = |i| input_ramp(values, slopes, i);
        self.law.step(ramp(vr::V1), ramp(vr::V2), h);
        Ok(())
    }

    fmi2_cs::delegate_state!(law);

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
}
