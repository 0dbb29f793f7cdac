//! `Rig1D.fmu`: m·ẍ = k·(x_a(t) − x) − c·ẋ + F_ext − F + F_d(t) + F_ctrl
//! (see `rig_dynamics::rig1d` for the modes and formulas). The friction
//! force F is an input, applied as −F; the slip velocity v = ẋ − v_s(t) is
//! the output a velocity-driven friction FMU takes, x_rel = x − x_s(t) the
//! one a displacement-driven law (Bristle) takes.
//!
//! Value references 0–14 are those of the first version (ramp actuator
//! only); the modes' variables follow, then the applied force `F_app`
//! (43), the input of a friction law with a stuck state (Classical), then
//! the derivatives of the two continuous states the model description
//! lists (44, 45): the position `x` and the body velocity `v_body`, whose
//! partial derivatives an importer can linearize the rig with
//! (`fmi2GetDirectionalDerivative` with a state among the knowns or a
//! derivative among the unknowns; [`Rig1D::partials`]).

use fmi_export::{
    Capabilities, ContinuousState, DefaultExperiment, Model, ModelInfo, Values, Variable,
};
use rig_dynamics::rig1d::{
    Actuator, Control, Controller, DriveForce, Known, Reference, Rig1D, Rig1DInputs, Rig1DParams,
};
use rig_dynamics::signals::Sinusoid;

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
    pub const X_ACT_IN: u32 = 15;
    pub const X_REF: u32 = 16;
    pub const V_REF: u32 = 17;
    pub const X_REL: u32 = 18;
    pub const V_BODY: u32 = 19;
    pub const F_DRIVE: u32 = 20;
    pub const U_CTRL: u32 = 21;
    pub const F_CTRL: u32 = 22;
    pub const ACTUATOR: u32 = 23;
    pub const ACT_AMP: u32 = 24;
    pub const ACT_FREQ: u32 = 25;
    pub const DITHER_AMP: u32 = 26;
    pub const DITHER_FREQ: u32 = 27;
    pub const F_STEP: u32 = 28;
    pub const T_STEP: u32 = 29;
    pub const DRIVE_AMP: u32 = 30;
    pub const DRIVE_FREQ: u32 = 31;
    pub const CONTROL: u32 = 32;
    pub const REF_X0: u32 = 33;
    pub const REF_V0: u32 = 34;
    pub const REF_V_AMP: u32 = 35;
    pub const REF_FREQ: u32 = 36;
    pub const CTRL_KP: u32 = 37;
    pub const CTRL_KD: u32 = 38;
    pub const CTRL_KI: u32 = 39;
    pub const CTRL_FF: u32 = 40;
    pub const CTRL_GAIN: u32 = 41;
    pub const CTRL_U_MAX: u32 = 42;
    pub const F_APP: u32 = 43;
    pub const DER_X: u32 = 44;
    pub const DER_V_BODY: u32 = 45;
}

/// Direct feedthrough, over every mode (a dependency that is zero in the
/// selected mode is allowed; a missing one is not):
/// the position follows F, F_ext and x_act_in in the quasi-static mode;
const POSITION_DEPS: &[u32] = &[vr::F, vr::F_EXT, vr::X_ACT_IN];
/// the acceleration takes every force, the spring (x_act_in) and the
/// controller's reference;
const ALL_INPUTS: &[u32] = &[vr::F, vr::F_EXT, vr::X_ACT_IN, vr::X_REF, vr::V_REF];
/// the command takes the reference inputs. The slip velocity v is a state
/// (quasi-static: its value at the end of the last step): no feedthrough.
const REFERENCE_INPUTS: &[u32] = &[vr::X_REF, vr::V_REF];
/// The applied force takes every input but the friction force F: F_ext,
/// the spring (x_act_in) and the controller's reference. Not F, in any
/// mode (the quasi-static one takes the held position): a friction law fed
/// with it (Classical) and feeding F back forms no algebraic loop.
const APPLIED_FORCE_DEPS: &[u32] = &[vr::F_EXT, vr::X_ACT_IN, vr::X_REF, vr::V_REF];

/// The listed states (position, body velocity) and both.
const POSITION: &[u32] = &[vr::X];
const VELOCITY: &[u32] = &[vr::V_BODY];
const STATES: &[u32] = &[vr::X, vr::V_BODY];

static VARIABLES: [Variable; 46] = [
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
        "Body position (quasi-static mode m = c = 0: x = x_act + (F_ext - F + F_drive)/k)",
        POSITION_DEPS,
    )
    .with_state_dependencies(POSITION),
    Variable::output(
        vr::V,
        "v",
        "m/s",
        "Slip velocity: body velocity minus surface velocity, v_body - v_s(t)",
        &[],
    )
    .with_state_dependencies(VELOCITY),
    Variable::output(
        vr::A,
        "a",
        "m/s2",
        "Body acceleration (0 in the quasi-static mode)",
        ALL_INPUTS,
    )
    .with_state_dependencies(STATES),
    Variable::output(
        vr::F_SPRING,
        "F_spring",
        "N",
        "Actuator (spring) force on the body k*(x_act - x)",
        POSITION_DEPS,
    )
    .with_state_dependencies(POSITION),
    Variable::output(
        vr::X_ACT,
        "x_act",
        "m",
        "Actuator point: x_a0 + v_a*t + act_amp*sin(2*pi*act_freq*t), or x_act_in",
        &[vr::X_ACT_IN],
    ),
    Variable::parameter(
        vr::M,
        "m",
        1.0,
        "kg",
        "Mass; 0 selects the quasi-static force balance (Appels and Herder's piezo push)",
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
    Variable::parameter(
        vr::X_A0,
        "x_a0",
        0.0,
        "m",
        "Actuator point at t = 0 (actuator = 0)",
    ),
    Variable::parameter(
        vr::V_A,
        "v_a",
        0.1,
        "m/s",
        "Actuator speed (Canudas de Wit et al. 1995: 0.1 m/s; Appels and Herder's piezo: 8.25e-8 m/s)",
    ),
    Variable::parameter(
        vr::V_SURFACE,
        "v_surface",
        0.0,
        "m/s",
        "Surface (belt) speed; surface x_s(t) = v_surface*t + dither_amp*sin(2*pi*dither_freq*t)",
    ),
    Variable::parameter(
        vr::X0,
        "x0",
        0.0,
        "m",
        "Initial position (m = c = 0: only the held position of F_app before the first step)",
    ),
    Variable::parameter(
        vr::V0,
        "v0",
        0.0,
        "m/s",
        "Initial body velocity (unused when m = 0)",
    ),
    Variable::input(
        vr::X_ACT_IN,
        "x_act_in",
        0.0,
        "m",
        1e-3,
        "Actuator point when actuator = 1 (interpolation slope honoured)",
    ),
    Variable::input(
        vr::X_REF,
        "x_ref",
        0.0,
        "m",
        1e-2,
        "Reference position of the controller when control = 2 (EMPS: qg)",
    ),
    Variable::input(
        vr::V_REF,
        "v_ref",
        0.0,
        "m/s",
        1e-3,
        "Reference velocity of the controller when control = 2",
    ),
    Variable::output(
        vr::X_REL,
        "x_rel",
        "m",
        "Displacement relative to the surface x - x_s(t), for displacement-driven friction laws",
        POSITION_DEPS,
    )
    .with_state_dependencies(POSITION),
    Variable::output(
        vr::V_BODY,
        "v_body",
        "m/s",
        "Body velocity dx/dt",
        &[],
    )
    .with_state_dependencies(VELOCITY),
    Variable::output(
        vr::F_DRIVE,
        "F_drive",
        "N",
        "Built-in drive force F_step*[t >= t_step] + drive_amp*sin(2*pi*drive_freq*t)",
        &[],
    ),
    Variable::output(
        vr::U_CTRL,
        "u_ctrl",
        "V",
        "Controller command after saturation, sat(u, +-ctrl_u_max) (EMPS: vir); 0 when control = 0",
        REFERENCE_INPUTS,
    )
    .with_state_dependencies(STATES),
    Variable::output(
        vr::F_CTRL,
        "F_ctrl",
        "N",
        "Controller force on the body ctrl_gain*u_ctrl",
        REFERENCE_INPUTS,
    )
    .with_state_dependencies(STATES),
    Variable::integer_parameter(
        vr::ACTUATOR,
        "actuator",
        0,
        "Actuator point: 0 = prescribed x_a0 + v_a*t + act_amp*sin(2*pi*act_freq*t); 1 = input x_act_in",
    )
    .with_min(0.0)
    .with_max(1.0),
    Variable::parameter(
        vr::ACT_AMP,
        "act_amp",
        0.0,
        "m",
        "Amplitude of the actuator sinusoid (actuator = 0)",
    ),
    Variable::parameter(
        vr::ACT_FREQ,
        "act_freq",
        0.0,
        "Hz",
        "Frequency of the actuator sinusoid",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::DITHER_AMP,
        "dither_amp",
        0.0,
        "m",
        "Amplitude of the surface dither displacement (Wijata et al. 2016: d = A*sin(omega*t))",
    ),
    Variable::parameter(
        vr::DITHER_FREQ,
        "dither_freq",
        0.0,
        "Hz",
        "Frequency of the surface dither",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::F_STEP,
        "F_step",
        0.0,
        "N",
        "Drive force step, applied from t_step on (Sun et al. 2016: 0.5 to 1.5 N)",
    ),
    Variable::parameter(vr::T_STEP, "t_step", 0.0, "s", "Time of the drive force step"),
    Variable::parameter(
        vr::DRIVE_AMP,
        "drive_amp",
        0.0,
        "N",
        "Amplitude of the sinusoidal drive force",
    ),
    Variable::parameter(
        vr::DRIVE_FREQ,
        "drive_freq",
        0.0,
        "Hz",
        "Frequency of the sinusoidal drive force (Thimmalapura 2004: 1 Hz)",
    )
    .with_min(0.0),
    Variable::integer_parameter(
        vr::CONTROL,
        "control",
        0,
        "Controller u = ctrl_kp*(x_ref - x) + ctrl_kd*(ctrl_ff*v_ref - v_body) + ctrl_ki*integral(v_ref - v_body): 0 = off; 1 = built-in reference (ref_*); 2 = reference from inputs x_ref, v_ref. Needs m > 0",
    )
    .with_min(0.0)
    .with_max(2.0),
    Variable::parameter(
        vr::REF_X0,
        "ref_x0",
        0.0,
        "m",
        "Built-in reference position at t = 0: x_ref = ref_x0 + ref_v0*t + integral of the sinusoid",
    ),
    Variable::parameter(
        vr::REF_V0,
        "ref_v0",
        0.0,
        "m/s",
        "Built-in reference velocity, constant part (Sun et al. 2016: 2 to 5.5 mm/s)",
    ),
    Variable::parameter(
        vr::REF_V_AMP,
        "ref_v_amp",
        0.0,
        "m/s",
        "Built-in reference velocity amplitude: v_ref = ref_v0 + ref_v_amp*sin(2*pi*ref_freq*t) (Sun et al. 2016: 1e-3)",
    ),
    Variable::parameter(
        vr::REF_FREQ,
        "ref_freq",
        0.0,
        "Hz",
        "Built-in reference frequency (Sun et al. 2016, sin(t/k): 1/(2*pi*k))",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::CTRL_KP,
        "ctrl_kp",
        0.0,
        "V/m",
        "Position gain (EMPS: kv*kp = 243.45*160.18)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::CTRL_KD,
        "ctrl_kd",
        0.0,
        "V.s/m",
        "Velocity gain (EMPS: kv = 243.45); the P gain of a velocity PI",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::CTRL_KI,
        "ctrl_ki",
        0.0,
        "V/m",
        "Gain on the integral of the velocity error; the I gain of a velocity PI (no anti-windup)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::CTRL_FF,
        "ctrl_ff",
        1.0,
        "",
        "Velocity feed-forward weight in ctrl_kd*(ctrl_ff*v_ref - v_body): 1 = derivative of the error, 0 = of the measurement (EMPS)",
    )
    .with_min(0.0)
    .with_max(1.0),
    Variable::parameter(
        vr::CTRL_GAIN,
        "ctrl_gain",
        1.0,
        "N/V",
        "Drive gain: control force = ctrl_gain*u_ctrl (EMPS: gtau = 35.15065188)",
    )
    .with_min(0.0),
    Variable::parameter(
        vr::CTRL_U_MAX,
        "ctrl_u_max",
        0.0,
        "V",
        "Saturation |u_ctrl| <= ctrl_u_max (EMPS: 10 V); 0 = no saturation",
    )
    .with_min(0.0),
    Variable::output(
        vr::F_APP,
        "F_app",
        "N",
        "Applied force, every force on the body but F, positive with v (Classical's input F_app): k*(x_act - x) - c*v_body + F_ext + F_drive + F_ctrl - m*a_s, a_s the surface acceleration; holding F = F_app keeps v constant. No feedthrough from F. m = 0: k*(x_act - x_h) + F_ext + F_drive - c*v_s, which holds the body on the surface at x_h (c = 0: x at the start of the last step, moved with the surface)",
        APPLIED_FORCE_DEPS,
    )
    .with_state_dependencies(STATES),
    Variable::derivative(
        vr::DER_X,
        "der(x)",
        "m/s",
        "Time derivative of the position state x: v_body (m > 0). x and v_body are the continuous states listed in the model structure (not in the quasi-static mode m = 0, whose partial derivatives are refused)",
        &[],
        VELOCITY,
    ),
    Variable::derivative(
        vr::DER_V_BODY,
        "der(v_body)",
        "m/s2",
        "Time derivative of the velocity state v_body: the acceleration a. The controller's integral xi = integral of (v_ref - v_body) dt is the integral of v_ref minus (x - x0): a function of x, not a state of its own",
        ALL_INPUTS,
        STATES,
    ),
];

pub static INFO: ModelInfo = ModelInfo {
    model_name: "Rig1D",
    model_identifier: "Rig1D",
    guid: "{f9254f7d-c408-47bd-a8a6-d02748805905}",
    description: "One-degree-of-freedom rig: m*x'' = k*(x_a(t) - x) - c*x' + F_ext - F + F_drive(t) + F_ctrl, slip velocity v = x' - v_s(t). Actuator point prescribed (ramp + sinusoid) or from an input; drive force step + sinusoid; PD/PI controller with saturation on a built-in or input reference; moving surface with dither; quasi-static mode m = 0; output F_app, every force on the body but friction, for a law with a stuck state (Classical). 2-stage Gauss-Legendre, sub-stepped, saturation switches located. Defaults: the 1995 stick-slip benchmark (m = 1, k = 2, pulled at 0.1 m/s).",
    source: "docs/models.md, Rig1D (Canudas de Wit et al. 1995 stick-slip benchmark; Appels and Herder piezo push, quasi-static; Sun et al. 2016 step forces and velocity trials; Thimmalapura 2004 sine drive; EMPS control loop, Janot et al. 2019).",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment { start_time: 0.0, stop_time: 20.0, step_size: 1e-4 },
    capabilities: Capabilities::FULL,
    co_simulation_states: &[
        ContinuousState { state: vr::X, derivative: vr::DER_X },
        ContinuousState { state: vr::V_BODY, derivative: vr::DER_V_BODY },
    ],
    model_exchange: None,
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

impl Rig1DFmu {
    pub fn params(v: &Values) -> Result<Rig1DParams, String> {
        Ok(Rig1DParams {
            m: v.real(vr::M),
            c: v.real(vr::C),
            k: v.real(vr::K),
            actuator: Actuator::from_code(v.integer(vr::ACTUATOR))?,
            x_a0: v.real(vr::X_A0),
            v_a: v.real(vr::V_A),
            act_sine: Sinusoid::new(v.real(vr::ACT_AMP), v.real(vr::ACT_FREQ)),
            v_surface: v.real(vr::V_SURFACE),
            dither: Sinusoid::new(v.real(vr::DITHER_AMP), v.real(vr::DITHER_FREQ)),
            x0: v.real(vr::X0),
            v0: v.real(vr::V0),
            drive: DriveForce {
                f_step: v.real(vr::F_STEP),
                t_step: v.real(vr::T_STEP),
                sine: Sinusoid::new(v.real(vr::DRIVE_AMP), v.real(vr::DRIVE_FREQ)),
            },
            control: Controller {
                mode: Control::from_code(v.integer(vr::CONTROL))?,
                kp: v.real(vr::CTRL_KP),
                kd: v.real(vr::CTRL_KD),
                ki: v.real(vr::CTRL_KI),
                ff: v.real(vr::CTRL_FF),
                gain: v.real(vr::CTRL_GAIN),
                u_max: v.real(vr::CTRL_U_MAX),
                reference: Reference {
                    x0: v.real(vr::REF_X0),
                    v0: v.real(vr::REF_V0),
                    sine: Sinusoid::new(v.real(vr::REF_V_AMP), v.real(vr::REF_FREQ)),
                },
            },
        })
    }
}

impl Rig1DFmu {
    /// Output `output` as [`Model::compute_outputs`] computes it; `None`
    /// for anything else. Not inlined into a loop over outputs, where the
    /// compiler would compute every prescribed sinusoid ahead, active or
    /// not.
    #[inline(never)]
    fn output(&self, v: &Values, output: u32) -> Option<f64> {
        let rig = &self.rig;
        let u = || inputs(v.as_slice());
        Some(match output {
            vr::X => rig.position(&u()),
            vr::V => rig.slip_velocity(),
            vr::A => rig.acceleration(&u()),
            vr::F_SPRING => rig.spring_force(&u()),
            vr::X_ACT => rig.actuator_position(&u()),
            vr::X_REL => rig.relative_displacement(&u()),
            vr::V_BODY => rig.velocity(),
            vr::F_DRIVE => rig.drive_force(),
            vr::U_CTRL => rig.control_command(&u()),
            vr::F_CTRL => rig.control_force(&u()),
            vr::F_APP => rig.applied_force(&u()),
            _ => return None,
        })
    }
}

/// The rig's inputs read from a table indexed by value reference (the
/// values, or their slopes). The inputs are value references 0, 1 and
/// 15..=17, so one length check covers the five.
#[inline]
fn inputs(table: &[f64]) -> Rig1DInputs {
    const LAST: usize = vr::V_REF as usize;
    const _: () = assert!(
        vr::F as usize <= LAST && vr::F_EXT as usize <= LAST && vr::X_ACT_IN as usize <= LAST
    );
    let Some(t) = table.get(..=LAST) else {
        unreachable!("a value table holds every variable")
    };
    Rig1DInputs {
        friction: t[vr::F as usize],
        f_ext: t[vr::F_EXT as usize],
        x_act: t[vr::X_ACT_IN as usize],
        x_ref: t[vr::X_REF as usize],
        v_ref: t[vr::V_REF as usize],
    }
}

impl Model for Rig1DFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, v: &Values) -> Result<(), String> {
        self.rig = Rig1D::new(Self::params(v)?)?;
        Ok(())
    }

    /// The eleven outputs from [`Rig1D::outputs`] (what the monolithic loop of
    /// `speed-table` records too), the values the single-output functions
    /// of `compute_outputs_of` give.
    fn compute_outputs(&self, v: &mut Values) {
        let y = self.rig.outputs(&inputs(v.as_slice()));
        // the last output's entry checked once covers the other ten
        const LAST: usize = vr::F_APP as usize;
        let Some(out) = v.as_mut_slice().get_mut(..=LAST) else {
            unreachable!("a value table holds every variable")
        };
        let mut set = |output: u32, x: f64| out[output as usize] = x;
        set(vr::X, y.position);
        set(vr::V, y.slip_velocity);
        set(vr::A, y.acceleration);
        set(vr::F_SPRING, y.spring_force);
        set(vr::X_ACT, y.actuator_position);
        set(vr::X_REL, y.relative_displacement);
        set(vr::V_BODY, y.velocity);
        set(vr::F_DRIVE, y.drive_force);
        set(vr::U_CTRL, y.control_command);
        set(vr::F_CTRL, y.control_force);
        set(vr::F_APP, y.applied_force);
    }

    /// The outputs asked for only (a directional derivative wants v, say):
    /// each as [`Model::compute_outputs`] computes it.
    fn compute_outputs_of(&self, v: &mut Values, outputs: &[u32]) {
        for &output in outputs {
            if let Some(value) = self.output(v, output) {
                v.set(output, value);
            }
        }
    }

    fn do_step(&mut self, v: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        let u = inputs(v.as_slice());
        let du = inputs(slopes);
        self.rig.step(&u, &du, h);
        Ok(())
    }

    /// dx/dt, dx_rel/dt, dx_act/dt, dF_drive/dt always; dv/dt and
    /// dv_body/dt when m > 0 (the quasi-static velocity has no rate here).
    fn output_derivative(&self, v: &Values, slopes: &[f64], output: u32) -> Option<f64> {
        let u = inputs(v.as_slice());
        let du = inputs(slopes);
        let rig = &self.rig;
        let massive = rig.params().m > 0.0;
        match output {
            vr::X => Some(rig.position_rate(&u, &du)),
            vr::X_REL => Some(rig.position_rate(&u, &du) - rig.surface_velocity(rig.time())),
            vr::X_ACT => Some(rig.actuator_velocity(&du)),
            vr::F_DRIVE => Some(rig.drive_force_rate()),
            vr::V_BODY if massive => Some(rig.acceleration(&u)),
            vr::V if massive => Some(rig.acceleration(&u) - rig.surface_acceleration()),
            _ => None,
        }
    }

    fmi_export::delegate_state!(rig);

    /// Directional derivatives by replaying the step (or, after a held
    /// step in the plain mode, from the closed form below): no partial
    /// derivatives.
    fn supplies_partial_derivatives(&self) -> bool {
        false
    }

    /// ∂y/∂F and ∂y/∂F_ext after a held step that took the plain path: the
    /// rig's closed form ([`Rig1D::held_step_sensitivity`]; the step is
    /// linear in the forces, smooth for any spread). The outputs that do
    /// not depend on the forces in that mode (the prescribed actuator
    /// point, no drive force, no controller) have 0. F_app depends on F
    /// through the state only, on F_ext also directly (+1). Any other
    /// input, and every other mode: `None`.
    fn step_partial_derivative(
        &self,
        _values: &Values,
        output: u32,
        input: u32,
        h: f64,
        _spread: f64,
    ) -> Option<f64> {
        // F is applied as −F, F_ext as +F_ext
        let sign = match input {
            vr::F => 1.0,
            vr::F_EXT => -1.0,
            _ => return None,
        };
        let d = self.rig.held_step_sensitivity(h)?;
        Some(match output {
            vr::X | vr::X_REL => sign * d.x,
            vr::V | vr::V_BODY => sign * d.xd,
            vr::A => sign * d.acceleration,
            vr::F_SPRING => sign * d.spring_force,
            vr::F_APP if input == vr::F => d.applied_force,
            vr::F_APP => 1.0 - d.applied_force,
            vr::X_ACT | vr::F_DRIVE | vr::U_CTRL | vr::F_CTRL => 0.0,
            _ => return None,
        })
    }

    fn supplies_step_derivatives(&self) -> bool {
        true
    }

    /// The derivatives of the listed states: ẋ (the quasi-static rate
    /// when m = 0, with the inputs held) and the acceleration.
    fn derivatives(&self, v: &Values, dx: &mut [f64]) {
        let u = inputs(v.as_slice());
        dx[0] = self.rig.position_rate(&u, &Rig1DInputs::default());
        dx[1] = self.rig.acceleration(&u);
    }

    /// The continuous-time partial derivatives of the rig's outputs and
    /// state derivatives in its states (x, v_body) and inputs
    /// ([`Rig1D::partials`]).
    fn state_partial_derivative(
        &self,
        v: &Values,
        unknown: u32,
        known: u32,
    ) -> Result<f64, String> {
        let known = match known {
            vr::X => Known::Position,
            vr::V_BODY => Known::Velocity,
            vr::F => Known::Friction,
            vr::F_EXT => Known::ExternalForce,
            vr::X_ACT_IN => Known::ActuatorInput,
            vr::X_REF => Known::ReferencePosition,
            vr::V_REF => Known::ReferenceVelocity,
            _ => {
                return Err(format!(
                    "value reference {known} is not a state or input of Rig1D"
                ))
            }
        };
        let d = self.rig.partials(&inputs(v.as_slice()), known)?;
        let y = &d.outputs;
        Ok(match unknown {
            vr::DER_X => d.position_rate,
            vr::DER_V_BODY | vr::A => y.acceleration,
            vr::X => y.position,
            vr::V => y.slip_velocity,
            vr::F_SPRING => y.spring_force,
            vr::X_ACT => y.actuator_position,
            vr::X_REL => y.relative_displacement,
            vr::V_BODY => y.velocity,
            vr::F_DRIVE => y.drive_force,
            vr::U_CTRL => y.control_command,
            vr::F_CTRL => y.control_force,
            vr::F_APP => y.applied_force,
            _ => {
                return Err(format!(
                    "value reference {unknown} is not an output or state derivative of Rig1D"
                ))
            }
        })
    }

    /// Every input value is accepted (no `check_input`).
    fn input_checked(&self, _vr: u32) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each output alone from `compute_outputs_of` is the value
    /// `compute_outputs` writes, in every mode the outputs depend on.
    #[test]
    fn outputs_asked_for_alone_are_the_full_outputs() {
        let mut values = Values::from_start(&VARIABLES);
        for (vr, x) in [
            (vr::CONTROL, 2.0),
            (vr::CTRL_KP, 30.0),
            (vr::CTRL_KD, 4.0),
            (vr::CTRL_U_MAX, 0.5),
            (vr::DITHER_AMP, 1e-4),
            (vr::DITHER_FREQ, 20.0),
            (vr::DRIVE_AMP, 0.3),
            (vr::DRIVE_FREQ, 1.0),
        ] {
            values.set(vr, x);
        }
        let mut fmu = Rig1DFmu::default();
        fmu.initialize(&values).unwrap();
        let slopes = vec![0.0; VARIABLES.len()];
        let outputs: Vec<u32> = VARIABLES
            .iter()
            .filter(|v| v.causality == fmi_export::Causality::Output)
            .map(|v| v.vr)
            .collect();
        for k in 0..50 {
            values.set(vr::F, 0.2 * (k as f64).sin());
            values.set(vr::X_REF, 1e-3 * k as f64);
            values.set(vr::V_REF, 2e-3);
            fmu.do_step(&values, &slopes, 1e-3).unwrap();
            let mut all = values.clone();
            fmu.compute_outputs(&mut all);
            for &o in &outputs {
                let mut one = values.clone();
                fmu.compute_outputs_of(&mut one, &[o]);
                assert_eq!(one.real(o).to_bits(), all.real(o).to_bits(), "vr {o}");
            }
        }
    }
}
