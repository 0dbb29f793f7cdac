//! `Rig2D.fmu`: the planar oscillator of Wijata et al. 2016,
//! m·ẍ_i = −k_i·x_i − c_i·ẋ_i + F_ext,i − F_i (i = 1, 2), over a surface
//! moving at (vs1, vs2) with dither along either axis (see
//! `rig_dynamics::rig2d`). Connect `v1, v2 → Bristle2D.v1, v2` and
//! `Bristle2D.F1, F2 → F1, F2`.

use fmi_export::{Capabilities, DefaultExperiment, Model, ModelInfo, Values, Variable};
use rig_dynamics::rig2d::{Rig2D, Rig2DInputs, Rig2DParams};
use rig_dynamics::signals::Sinusoid;

pub mod vr {
    pub const F1: u32 = 0;
    pub const F2: u32 = 1;
    pub const F_EXT1: u32 = 2;
    pub const F_EXT2: u32 = 3;
    pub const V1: u32 = 4;
    pub const V2: u32 = 5;
    pub const X1: u32 = 6;
    pub const X2: u32 = 7;
    pub const X1_REL: u32 = 8;
    pub const X2_REL: u32 = 9;
    pub const A1: u32 = 10;
    pub const A2: u32 = 11;
    pub const M: u32 = 12;
    pub const K1: u32 = 13;
    pub const K2: u32 = 14;
    pub const C1: u32 = 15;
    pub const C2: u32 = 16;
    pub const X1_0: u32 = 17;
    pub const X2_0: u32 = 18;
    pub const V1_0: u32 = 19;
    pub const V2_0: u32 = 20;
    pub const VS1: u32 = 21;
    pub const VS2: u32 = 22;
    pub const DITHER_AMP1: u32 = 23;
    pub const DITHER_FREQ1: u32 = 24;
    pub const DITHER_AMP2: u32 = 25;
    pub const DITHER_FREQ2: u32 = 26;
}

/// Per axis: (F_i, F_ext,i, v_i, x_i, x_i_rel, a_i).
const AXES: [[u32; 6]; 2] = [
    [vr::F1, vr::F_EXT1, vr::V1, vr::X1, vr::X1_REL, vr::A1],
    [vr::F2, vr::F_EXT2, vr::V2, vr::X2, vr::X2_REL, vr::A2],
];

static VARIABLES: [Variable; 27] = [
    Variable::input(
        vr::F1,
        "F1",
        0.0,
        "N",
        1.0,
        "Friction force along axis 1, applied to the body as -F1",
    ),
    Variable::input(
        vr::F2,
        "F2",
        0.0,
        "N",
        1.0,
        "Friction force along axis 2, applied to the body as -F2",
    ),
    Variable::input(
        vr::F_EXT1,
        "F_ext1",
        0.0,
        "N",
        1.0,
        "External force along axis 1",
    ),
    Variable::input(
        vr::F_EXT2,
        "F_ext2",
        0.0,
        "N",
        1.0,
        "External force along axis 2",
    ),
    Variable::output(
        vr::V1,
        "v1",
        "m/s",
        "Slip velocity along axis 1: dx1/dt - vs1 - d/dt(dither_amp1*sin(2*pi*dither_freq1*t))",
        &[],
    ),
    Variable::output(
        vr::V2,
        "v2",
        "m/s",
        "Slip velocity along axis 2: dx2/dt - vs2 - d/dt(dither_amp2*sin(2*pi*dither_freq2*t))",
        &[],
    ),
    Variable::output(
        vr::X1,
        "x1",
        "m",
        "Body position along axis 1 (anchor at 0)",
        &[],
    ),
    Variable::output(
        vr::X2,
        "x2",
        "m",
        "Body position along axis 2 (anchor at 0)",
        &[],
    ),
    Variable::output(
        vr::X1_REL,
        "x1_rel",
        "m",
        "Displacement relative to the surface along axis 1: x1 - vs1*t - dither_amp1*sin(2*pi*dither_freq1*t)",
        &[],
    ),
    Variable::output(
        vr::X2_REL,
        "x2_rel",
        "m",
        "Displacement relative to the surface along axis 2: x2 - vs2*t - dither_amp2*sin(2*pi*dither_freq2*t)",
        &[],
    ),
    Variable::output(
        vr::A1,
        "a1",
        "m/s2",
        "Body acceleration along axis 1",
        &[vr::F1, vr::F_EXT1],
    ),
    Variable::output(
        vr::A2,
        "a2",
        "m/s2",
        "Body acceleration along axis 2",
        &[vr::F2, vr::F_EXT2],
    ),
    Variable::parameter(vr::M, "m", 1.0, "kg", "Mass, > 0 (Wijata et al. 2016: 1 kg)").with_min(0.0),
    Variable::parameter(
        vr::K1,
        "k1",
        100.0,
        "N/m",
        "Spring stiffness along axis 1 (Wijata et al. 2016: 100 N/m)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::K2,
        "k2",
        100.0,
        "N/m",
        "Spring stiffness along axis 2 (Wijata et al. 2016: 100 N/m)",
    )
    .with_min(0.0),
    Variable::parameter(vr::C1, "c1", 0.0, "N.s/m", "Viscous damping along axis 1").with_min(0.0),
    Variable::parameter(vr::C2, "c2", 0.0, "N.s/m", "Viscous damping along axis 2").with_min(0.0),
    Variable::parameter(
        vr::X1_0,
        "x1_0",
        0.08,
        "m",
        "Initial position along axis 1 (Wijata et al. 2016: 0.08 m)",
    ),
    Variable::parameter(
        vr::X2_0,
        "x2_0",
        0.08,
        "m",
        "Initial position along axis 2 (Wijata et al. 2016: 0.08 m)",
    ),
    Variable::parameter(
        vr::V1_0,
        "v1_0",
        -0.8,
        "m/s",
        "Initial body velocity along axis 1 (Wijata et al. 2016: -0.8 m/s)",
    ),
    Variable::parameter(
        vr::V2_0,
        "v2_0",
        0.8,
        "m/s",
        "Initial body velocity along axis 2 (Wijata et al. 2016: 0.8 m/s)",
    ),
    Variable::parameter(vr::VS1, "vs1", 0.0, "m/s", "Surface velocity along axis 1"),
    Variable::parameter(vr::VS2, "vs2", 0.0, "m/s", "Surface velocity along axis 2"),
    Variable::parameter(
        vr::DITHER_AMP1,
        "dither_amp1",
        0.0,
        "m",
        "Surface dither amplitude along axis 1 (displacement)",
    ),
    Variable::parameter(
        vr::DITHER_FREQ1,
        "dither_freq1",
        0.0,
        "Hz",
        "Surface dither frequency along axis 1",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::DITHER_AMP2,
        "dither_amp2",
        0.0,
        "m",
        "Surface dither amplitude along axis 2 (displacement)",
    ),
    Variable::parameter(
        vr::DITHER_FREQ2,
        "dither_freq2",
        0.0,
        "Hz",
        "Surface dither frequency along axis 2",
    )
    .with_min(0.0),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "Rig2D",
    model_identifier: "Rig2D",
    guid: "{1631f706-d309-41c5-8dca-8f8df1794ec4}",
    description: "Planar oscillator: m*xi'' = -ki*xi - ci*xi' + F_exti - Fi (i = 1, 2), springs to a fixed anchor, surface moving at (vs1, vs2) with sinusoidal dither along either axis; slip velocities vi = xi' - vsi(t). 2-stage Gauss-Legendre, sub-stepped. Defaults: the oscillator of Wijata et al. 2016 (m = 1, k1 = k2 = 100, x(0) = (0.08, 0.08) m, v(0) = (-0.8, 0.8) m/s).",
    source: "Wijata et al. 2016, planar oscillator with surface dither; docs/models.md, Rig2D.",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment { start_time: 0.0, stop_time: 10.0, step_size: 1e-4 },
    capabilities: Capabilities::FULL,
    co_simulation_states: &[],
    model_exchange: None,
};

#[derive(Clone, Debug)]
pub struct Rig2DFmu {
    rig: Rig2D,
}

impl Default for Rig2DFmu {
    fn default() -> Self {
        Rig2DFmu {
            rig: Rig2D::new(Rig2DParams::default()).expect("default parameters are valid"),
        }
    }
}

impl Rig2DFmu {
    pub fn params(v: &Values) -> Rig2DParams {
        let r = |vr| v.real(vr);
        Rig2DParams {
            m: r(vr::M),
            k: [r(vr::K1), r(vr::K2)],
            c: [r(vr::C1), r(vr::C2)],
            x0: [r(vr::X1_0), r(vr::X2_0)],
            v0: [r(vr::V1_0), r(vr::V2_0)],
            v_surface: [r(vr::VS1), r(vr::VS2)],
            dither: [
                Sinusoid::new(r(vr::DITHER_AMP1), r(vr::DITHER_FREQ1)),
                Sinusoid::new(r(vr::DITHER_AMP2), r(vr::DITHER_FREQ2)),
            ],
        }
    }
}

/// Both axes' inputs read through `at` (values or slopes).
fn inputs(at: impl Fn(u32) -> f64) -> Rig2DInputs {
    Rig2DInputs {
        friction: AXES.map(|a| at(a[0])),
        f_ext: AXES.map(|a| at(a[1])),
    }
}

impl Model for Rig2DFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, v: &Values) -> Result<(), String> {
        self.rig = Rig2D::new(Self::params(v))?;
        Ok(())
    }

    fn compute_outputs(&self, v: &mut Values) {
        let u = inputs(|r| v.real(r));
        for (i, [_, _, slip, x, x_rel, a]) in AXES.into_iter().enumerate() {
            let (axis, ui) = (self.rig.axis(i), u.axis(i));
            v.set(slip, axis.slip_velocity());
            v.set(x, axis.position(&ui));
            v.set(x_rel, axis.relative_displacement(&ui));
            v.set(a, axis.acceleration(&ui));
        }
    }

    fn do_step(&mut self, v: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        let u = inputs(|r| v.real(r));
        let du = inputs(|r| slopes[r as usize]);
        self.rig.step(&u, &du, h);
        Ok(())
    }

    /// dx_i/dt, dv_i/dt (acceleration minus the surface's) and dx_i_rel/dt.
    fn output_derivative(&self, v: &Values, _slopes: &[f64], output: u32) -> Option<f64> {
        let u = inputs(|r| v.real(r));
        let i = AXES.iter().position(|a| a[2..5].contains(&output))?;
        let (axis, ui) = (self.rig.axis(i), u.axis(i));
        let t = axis.time();
        Some(match AXES[i].iter().position(|r| *r == output)? {
            2 => axis.acceleration(&ui) - axis.surface_acceleration(),
            3 => axis.velocity(),
            _ => axis.velocity() - axis.surface_velocity(t),
        })
    }

    fmi_export::delegate_state!(rig);

    /// Directional derivatives by replaying the step: no partial derivatives.
    fn supplies_partial_derivatives(&self) -> bool {
        false
    }
}
