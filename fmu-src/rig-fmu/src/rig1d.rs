//! `Rig1D.fmu`: m·ẍ = k·(x_a(t) − x) − c·ẋ + F_ext − F (see
//! `rig_dynamics::rig1d`). The friction force F is an input, applied as −F;
//! the slip velocity v = ẋ − v_surface is the output a friction FMU takes.

use fmi2_cs::{Capabilities, DefaultExperiment, Model, ModelInfo, Values, Variable};
use rig_dynamics::rig1d::{Rig1D, Rig1DParams};

pub mod vr {
    pub const F: u32 = 0;
    pub const F_EXT: u32 = 1;
    pub const X: u32 = 2;
    pub const V: u32 = 3;
    pub const A: u32 = 4;
    pub const F_SPRING: u32 = 5;
    pub const X_ACT: u32 = 6;
    pub const M: u32 = 7;
    pub const C: u32 = 8;
    pub const K: u32 = 9;
    pub const X_A0: u32 = 10;
    pub const V_A: u32 = 11;
    pub const V_SURFACE: u32 = 12;
    pub const X0: u32 = 13;
    pub const V0: u32 = 14;
}

const FORCES: &[u32] = &[vr::F, vr::F_EXT];

static VARIABLES: [Variable; 15] = [
    Variable::input(
        vr::F,
        "F",
        0.0,
        "N",
        1.0,
        "Friction force from the friction block, applied to the body as -F",
    ),
    Variable::input(
        vr::F_EXT,
        "F_ext",
        0.0,
        "N",
        1.0,
        "External force on the body",
    ),
    Variable::output(
        vr::X,
        "x",
        "m",
        "Body position (quasi-static mode m = c = 0: x = x_act + (F_ext - F)/k)",
        FORCES,
    ),
    Variable::output(
        vr::V,
        "v",
        "m/s",
        "Slip velocity: body velocity minus surface speed",
        &[],
    ),
    Variable::output(vr::A, "a", "m/s2", "Body acceleration", FORCES),
    Variable::output(
        vr::F_SPRING,
        "F_spring",
        "N",
        "Actuator (spring) force on the body k*(x_act - x)",
        FORCES,
    ),
    Variable::output(vr::X_ACT, "x_act", "m", "Actuator point x_a0 + v_a*t", &[]),
    Variable::parameter(
        vr::M,
        "m",
        1.0,
        "kg",
        "Mass; 0 selects the quasi-static force balance (seed 000)",
    )
    .with_min(0.0),
    Variable::parameter(vr::C, "c", 0.0, "N.s/m", "Viscous damping to ground").with_min(0.0),
    Variable::parameter(
        vr::K,
        "k",
        2.0,
        "N/m",
        "Spring stiffness to the actuator point",
    )
    .with_min(0.0),
    Variable::parameter(vr::X_A0, "x_a0", 0.0, "m", "Actuator point at t = 0"),
    Variable::parameter(
        vr::V_A,
        "v_a",
        0.1,
        "m/s",
        "Actuator speed (1995 benchmark: 0.1 m/s; seed 000 piezo: 8.25e-8 m/s)",
    ),
    Variable::parameter(
        vr::V_SURFACE,
        "v_surface",
        0.0,
        "m/s",
        "Surface (belt) speed",
    ),
    Variable::parameter(vr::X0, "x0", 0.0, "m", "Initial position"),
    Variable::parameter(vr::V0, "v0", 0.0, "m/s", "Initial velocity"),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "Rig1D",
    model_identifier: "Rig1D",
    guid: "{f9254f7d-c408-47bd-a8a6-d02748805905}",
    description: "One-degree-of-freedom rig: m*x'' = k*(x_a(t) - x) - c*x' + F_ext - F, slip velocity v = x' - v_surface; 2-stage Gauss-Legendre, sub-stepped. Defaults: the 1995 stick-slip benchmark (m = 1, k = 2, pulled at 0.1 m/s).",
    source: "MODELS.md, Rigs in the seeds (1995 benchmark; seed 000 piezo push, quasi-static).",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment { start_time: 0.0, stop_time: 20.0, step_size: 1e-4 },
    capabilities: Capabilities::FULL,
};

#[derive(Clone, Debug)]
pub struct Rig1DFmu {
    rig: Rig1D,
}

impl Default for Rig1DFmu {
    fn default() -> Self {
        Rig1DFmu {
            rig: Rig1D::new(Rig1DParams::default()).expect("default parameters are valid"),
        }
    }
}

impl Model for Rig1DFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, v: &Values) -> Result<(), String> {
        let p = Rig1DParams {
            m: v.real(vr::M),
            c: v.real(vr::C),
            k: v.real(vr::K),
            x_a0: v.real(vr::X_A0),
            v_a: v.real(vr::V_A),
            v_surface: v.real(vr::V_SURFACE),
            x0: v.real(vr::X0),
            v0: v.real(vr::V0),
        };
        self.rig = Rig1D::new(p)?;
        Ok(())
    }

    fn compute_outputs(&self, v: &mut Values) {
        let (f, fe) = (v.real(vr::F), v.real(vr::F_EXT));
        v.set(vr::X, self.rig.position(f, fe));
        v.set(vr::V, self.rig.slip_velocity(0.0, 0.0));
        v.set(vr::A, self.rig.acceleration(f, fe));
        v.set(vr::F_SPRING, self.rig.spring_force(f, fe));
        v.set(vr::X_ACT, self.rig.actuator_position(self.rig.time()));
    }

    fn do_step(&mut self, v: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        self.rig.step(
            v.real(vr::F),
            slopes[vr::F as usize],
            v.real(vr::F_EXT),
            slopes[vr::F_EXT as usize],
            h,
        );
        Ok(())
    }

    fmi2_cs::delegate_state!(rig);
}
