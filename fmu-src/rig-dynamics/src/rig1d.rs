//! One-degree-of-freedom rig (docs/models.md, "Rig1D"): a mass `m`
//! with viscous damping `c` to ground, a spring `k` to an actuator point
//! `x_a(t)`, an external force, a built-in drive force, an optional built-in
//! controller, and the friction force applied as −F:
//!
//! m·ẍ = k·(x_a(t) − x) − c·ẋ + F_ext − F + F_d(t) + F_ctrl,
//!
//! with the slip velocity v = ẋ − v_s(t) and relative displacement
//! x − x_s(t) over a moving surface x_s(t) = v_surface·t + A_s·sin(2π f_s t)
//! (belt speed plus dither; the dither d = A·sin(ωt) of Wijata et al. 2016).
//!
//! - **Actuator point** ([`Actuator`]): `Prescribed`: x_a(t) = x_a0 + v_a·t +
//!   A_a·sin(2π f_a t) (the pulled spring of the 1995 benchmark of Canudas
//!   de Wit et al., the piezo ramp of Appels & Herder, the imposed
//!   sinusoidal displacement of Dion et al. 2013); `Input`: x_a = the input
//!   `x_act_in`, linear over a step with its slope (Appels & Herder's piezo
//!   staircase of 0.825e-9 m every 10 ms).
//! - **Drive force** ([`DriveForce`]): F_d(t) = F_step·[t ≥ t_step] +
//!   A_d·sin(2π f_d t) (the step forces 0.5–1.5 N of Sun et al. 2016; the
//!   1 Hz sine drive of Thimmalapura 2004), added to the input F_ext. A step
//!   inside a communication step splits the integration there, so it is
//!   taken exactly.
//! - **Controller** ([`Controller`], needs m > 0):
//!   u = Kp·(x_ref − x) + Kd·(β·v_ref − ẋ) + Ki·ξ,  ξ̇ = v_ref − ẋ, ξ(0) = 0,
//!   F_ctrl = G·sat(u, ±u_max) (u_max = 0: no saturation). The reference is
//!   built in, v_ref = v_r0 + V·sin(2π f_r t) and x_ref = x_r0 + v_r0·t +
//!   (V/ω_r)(1 − cos ω_r t) (the velocity trials ±1e-3·sin(t/k) m/s of Sun
//!   et al. 2016: V = 1e-3, f_r = 1/(2πk)), or taken from the inputs
//!   `x_ref`, `v_ref`.
//!   Position PD: Ki = 0, β = 1. Velocity PI: Kp = 0, β = 1 (Kd is the
//!   proportional and Ki the integral gain on the velocity error). The EMPS
//!   loop (Janot et al. 2019; docs/models.md "Rig1D"), force =
//!   gtau·sat(kv·(kp·(qg − qm) − q̇m), ±10 V), is Kp = kv·kp, Kd = kv,
//!   Ki = 0, β = 0, G = gtau, u_max = 10, reference from the input
//!   x_ref = qg.
//!   ξ is integrated exactly: over any interval ξ changes by ∫v_ref − Δx.
//!   There is no anti-windup: ξ integrates the error also while saturated.
//!
//! Integration. The right-hand side is affine in (x, ẋ) with a linear part
//! L fixed by the parameters (and by the saturation's piece), and the
//! inputs (F, F_ext, x_act_in, x_ref, v_ref) move linearly over a step
//! with their slopes (first-order input interpolation).
//!
//! - **Exact step** (`exact::ExactStep`) when m > 0, the controller is off
//!   or does not saturate (u_max = 0), and no sinusoid drives the body
//!   (actuator, drive force, built-in reference; a surface dither is
//!   allowed): the forcing is then a polynomial of degree ≤ 2 in time
//!   between drive steps, and the step is y(h) = e^{hL}·y(0) plus the
//!   forcing integrated against e^{(h−s)L} in closed form (φ-functions
//!   from one matrix exponential, formed once per step length). Exact for
//!   any step length, to rounding: no sub-steps, no stability limit. This
//!   covers the default mode (the 1995 benchmark), the unsaturated loops
//!   and the actuator input.
//! - **Otherwise** 2-stage Gauss–Legendre (order 4, A-stable), sub-stepped
//!   so that ω·h_sub ≤ 0.02, with ω = √(K/m + (C/2m)²) + C/2m from the
//!   effective stiffness K = k + G·(Kp + Ki) and damping C = c + G·Kd of the
//!   unsaturated loop, and ω at least every active forcing frequency.
//!   Gauss–Legendre has no amplitude error on an undamped oscillator; its
//!   phase error at the bound ω·h_sub = 0.02 is 1.4e-9 of a radian per
//!   natural period (∝ (ω·h)⁴: 9e-11 at ω·h = 0.01, and one sub-step of h is
//!   used when ω·h ≤ 0.02). The stage equations reduce to a 2×2 system
//!   solved in closed form (`gauss_legendre::linear_stage_sums`).
//!
//! **Saturation** is handled piecewise and exactly up to event location:
//! sat(u) is continuous, and on each side of ±u_max the closed loop is
//! affine (linear: F_ctrl = G·u; saturated: F_ctrl = ±G·u_max, constant).
//! Each sub-step is integrated with the piece in which u lies at its start;
//! if u at its end lies in another piece, the crossing time θ of u = ±u_max
//! is located (Illinois regula falsi on the Gauss–Legendre solution over
//! [0, θ], to 1e-12 of the sub-step), the sub-step is advanced to θ, and the
//! rest is integrated with the other piece (at most 8 switches per
//! sub-step; two crossings inside one sub-step, which ω·h_sub ≤ 0.02 makes
//! negligible, are not resolved).
//!
//! m = 0 selects the quasi-static force balance of Appels & Herder:
//! 0 = k·(x_a − x) − c·ẋ + F_ext − F + F_d. With c = 0 the position follows
//! the forces directly, x = x_a + (F_ext − F + F_d)/k (direct feedthrough
//! from F); with c > 0 it is first order, c·ẋ = k·(x_a − x) + F_ext − F + F_d.
//! In this mode ẋ is its value at the end of the last step with the inputs
//! and slopes of that step (before the first step: with zero inputs), and
//! the acceleration output is 0.
//!
//! **Applied force** ([`Rig1D::applied_force`]): every force on the body
//! but the friction input F, along the contact, positive with v, the input
//! `F_app` of a law with a stuck state (Karnopp's band: Classical):
//!
//! F_app = k·(x_a − x) − c·ẋ + F_ext + F_d + F_ctrl − m·a_s(t),
//!
//! so that m·v̇ = F_app − F: a contact that holds F = F_app keeps the slip
//! velocity constant. −m·a_s is the inertial force of the surface's
//! acceleration (its dither; the belt speed is constant). It depends on
//! the state and on F_ext, x_act_in, x_ref, v_ref, never on F. With m = 0
//! the body has no velocity of its own to keep: F_app is the force that
//! holds it on the surface (v = 0), k·(x_a − x_h) + F_ext + F_d − c·v_s(t),
//! at the held position x_h: the position state when c > 0; when c = 0,
//! where x follows F at once, the position at the start of the last step
//! (with that step's inputs) carried with the surface to its end (before
//! the first step: x0). A contact holding F = F_app at each communication
//! point then keeps the body where it was.
//!
//! Defaults: the 1995 stick-slip benchmark (m = 1 kg, k = 2 N/m, pulled at
//! 0.1 m/s, everything else off), stepped exactly; the first version of
//! this file stepped it with Gauss–Legendre, which the results match to
//! that method's truncation error (the tests give the figures).

use crate::exact::{ExactStep, NODES};
use crate::gauss_legendre::{linear_stage_sums, StageSolver, C};
use crate::signals::Sinusoid;
use crate::{check_finite, check_non_negative};

/// Sub-step rule ω·h_sub ≤ this.
const OMEGA_H_MAX: f64 = 0.02;
/// Most saturation switches located inside one sub-step.
const MAX_SWITCHES: usize = 8;

/// Where the actuator point (the far end of the spring) comes from;
/// parameter `actuator`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Actuator {
    /// 0: x_a(t) = x_a0 + v_a·t + act_amp·sin(2π·act_freq·t).
    Prescribed,
    /// 1: x_a = input `x_act_in` (with its interpolation slope).
    Input,
}

impl Actuator {
    pub fn from_code(code: i32) -> Result<Self, String> {
        match code {
            0 => Ok(Actuator::Prescribed),
            1 => Ok(Actuator::Input),
            _ => Err(format!(
                "invalid parameter actuator = {code}: must be 0 (prescribed ramp + sinusoid) or 1 (input x_act_in)"
            )),
        }
    }

    pub fn code(self) -> i32 {
        match self {
            Actuator::Prescribed => 0,
            Actuator::Input => 1,
        }
    }
}

/// Which controller runs; parameter `control`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// 0: no controller.
    Off,
    /// 1: on, built-in reference v_ref = ref_v0 + ref_v_amp·sin(2π·ref_freq·t).
    BuiltIn,
    /// 2: on, reference from the inputs `x_ref` and `v_ref`.
    Input,
}

impl Control {
    pub fn from_code(code: i32) -> Result<Self, String> {
        match code {
            0 => Ok(Control::Off),
            1 => Ok(Control::BuiltIn),
            2 => Ok(Control::Input),
            _ => Err(format!(
                "invalid parameter control = {code}: must be 0 (off), 1 (built-in sinusoidal reference) or 2 (reference from inputs x_ref, v_ref)"
            )),
        }
    }

    pub fn code(self) -> i32 {
        match self {
            Control::Off => 0,
            Control::BuiltIn => 1,
            Control::Input => 2,
        }
    }
}

/// Built-in drive force F_d(t) = f_step·[t ≥ t_step] + sine(t).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DriveForce {
    pub f_step: f64,
    pub t_step: f64,
    pub sine: Sinusoid,
}

impl DriveForce {
    pub fn value(&self, t: f64) -> f64 {
        let step = if self.f_step != 0.0 && t >= self.t_step {
            self.f_step
        } else {
            0.0
        };
        step + self.sine.value(t)
    }

    /// dF_d/dt away from the step instant.
    pub fn rate(&self, t: f64) -> f64 {
        self.sine.rate(t)
    }
}

/// Built-in reference: v_ref = v0 + sine(t), x_ref = x0 + v0·t + ∫sine.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reference {
    pub x0: f64,
    pub v0: f64,
    pub sine: Sinusoid,
}

/// u = kp·(x_ref − x) + kd·(ff·v_ref − ẋ) + ki·ξ; F_ctrl = gain·sat(u, ±u_max).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Controller {
    pub mode: Control,
    /// Position gain (V/m with the command in volts).
    pub kp: f64,
    /// Velocity gain (V·s/m).
    pub kd: f64,
    /// Gain on ξ = ∫(v_ref − ẋ) dt (V/m).
    pub ki: f64,
    /// Velocity feed-forward weight β in kd·(β·v_ref − ẋ), 0..1.
    pub ff: f64,
    /// Drive gain G (N/V).
    pub gain: f64,
    /// Saturation of the command |u| ≤ u_max (V); 0 = none.
    pub u_max: f64,
    pub reference: Reference,
}

impl Default for Controller {
    fn default() -> Self {
        Controller {
            mode: Control::Off,
            kp: 0.0,
            kd: 0.0,
            ki: 0.0,
            ff: 1.0,
            gain: 1.0,
            u_max: 0.0,
            reference: Reference::default(),
        }
    }
}

impl Controller {
    fn on(&self) -> bool {
        self.mode != Control::Off
    }

    fn saturates(&self) -> bool {
        self.on() && self.u_max > 0.0
    }

    /// sat(u, ±u_max).
    fn saturate(&self, u: f64) -> f64 {
        if self.u_max > 0.0 {
            u.clamp(-self.u_max, self.u_max)
        } else {
            u
        }
    }

    /// Piece of sat(·) in which u lies: −1, 0 (|u| ≤ u_max, or no
    /// saturation), +1.
    fn piece(&self, u: f64) -> i8 {
        if !self.saturates() || u.abs() <= self.u_max {
            0
        } else if u > 0.0 {
            1
        } else {
            -1
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rig1DParams {
    pub m: f64,
    pub c: f64,
    pub k: f64,
    pub actuator: Actuator,
    /// Prescribed actuator point at t = 0, its speed and its sinusoid.
    pub x_a0: f64,
    pub v_a: f64,
    pub act_sine: Sinusoid,
    /// Belt (surface) speed and dither: x_s(t) = v_surface·t + dither(t).
    pub v_surface: f64,
    pub dither: Sinusoid,
    pub x0: f64,
    pub v0: f64,
    pub drive: DriveForce,
    pub control: Controller,
}

impl Default for Rig1DParams {
    /// The 1995 stick-slip benchmark: m = 1 kg, k = 2 N/m, pulled at 0.1 m/s.
    fn default() -> Self {
        Rig1DParams {
            m: 1.0,
            c: 0.0,
            k: 2.0,
            actuator: Actuator::Prescribed,
            x_a0: 0.0,
            v_a: 0.1,
            act_sine: Sinusoid::OFF,
            v_surface: 0.0,
            dither: Sinusoid::OFF,
            x0: 0.0,
            v0: 0.0,
            drive: DriveForce::default(),
            control: Controller::default(),
        }
    }
}

impl Rig1DParams {
    /// Every value finite, physical ranges, consistent modes; the error
    /// names the parameter (as the FMU calls it) and its value.
    pub fn validate(&self) -> Result<(), String> {
        for (name, value) in [("m", self.m), ("c", self.c), ("k", self.k)] {
            check_non_negative(name, value)?;
        }
        for (name, value) in [
            ("x_a0", self.x_a0),
            ("v_a", self.v_a),
            ("v_surface", self.v_surface),
            ("x0", self.x0),
            ("v0", self.v0),
            ("F_step", self.drive.f_step),
            ("t_step", self.drive.t_step),
            ("ref_x0", self.control.reference.x0),
            ("ref_v0", self.control.reference.v0),
        ] {
            check_finite(name, value)?;
        }
        self.act_sine.validate("act_amp", "act_freq")?;
        self.dither.validate("dither_amp", "dither_freq")?;
        self.drive.sine.validate("drive_amp", "drive_freq")?;
        self.control
            .reference
            .sine
            .validate("ref_v_amp", "ref_freq")?;
        let ctrl = &self.control;
        for (name, value) in [
            ("ctrl_kp", ctrl.kp),
            ("ctrl_kd", ctrl.kd),
            ("ctrl_ki", ctrl.ki),
            ("ctrl_gain", ctrl.gain),
            ("ctrl_u_max", ctrl.u_max),
        ] {
            check_non_negative(name, value)?;
        }
        if !(0.0..=1.0).contains(&ctrl.ff) {
            return Err(format!(
                "invalid parameter ctrl_ff = {}: must be in 0..1",
                ctrl.ff
            ));
        }
        if self.m == 0.0 && self.k == 0.0 && self.c == 0.0 {
            return Err(
                "invalid parameters m = 0, k = 0, c = 0: a massless rig needs a spring or a damper"
                    .into(),
            );
        }
        if ctrl.on() && self.m == 0.0 {
            return Err(format!(
                "invalid parameter control = {}: the built-in controller needs m > 0, but m = 0 (quasi-static mode)",
                ctrl.mode.code()
            ));
        }
        Ok(())
    }
}

/// The rig's inputs at one instant (or their slopes d/dt over a step).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rig1DInputs {
    /// Friction force F, applied as −F.
    pub friction: f64,
    pub f_ext: f64,
    /// Actuator point when `Actuator::Input`.
    pub x_act: f64,
    /// Reference position and velocity when `Control::Input`.
    pub x_ref: f64,
    pub v_ref: f64,
}

impl Rig1DInputs {
    /// u + du·τ.
    pub fn at(&self, du: &Rig1DInputs, tau: f64) -> Rig1DInputs {
        Rig1DInputs {
            friction: self.friction + du.friction * tau,
            f_ext: self.f_ext + du.f_ext * tau,
            x_act: self.x_act + du.x_act * tau,
            x_ref: self.x_ref + du.x_ref * tau,
            v_ref: self.v_ref + du.v_ref * tau,
        }
    }
}

/// Every output of the rig at one instant ([`Rig1D::outputs`]), each the
/// value of the single-output function of the same name.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rig1DOutputs {
    /// [`Rig1D::position`].
    pub position: f64,
    /// [`Rig1D::slip_velocity`].
    pub slip_velocity: f64,
    /// [`Rig1D::acceleration`].
    pub acceleration: f64,
    /// [`Rig1D::spring_force`].
    pub spring_force: f64,
    /// [`Rig1D::actuator_position`].
    pub actuator_position: f64,
    /// [`Rig1D::relative_displacement`].
    pub relative_displacement: f64,
    /// [`Rig1D::velocity`].
    pub velocity: f64,
    /// [`Rig1D::drive_force`].
    pub drive_force: f64,
    /// [`Rig1D::control_command`].
    pub control_command: f64,
    /// [`Rig1D::control_force`].
    pub control_force: f64,
    /// [`Rig1D::applied_force`].
    pub applied_force: f64,
}

/// `∂/∂F` of the state and outputs after a step with the friction force
/// `F` held ([`Rig1D::held_step_sensitivity`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSensitivity {
    /// Of the position `x` (and `x_rel`), m/N.
    pub x: f64,
    /// Of the velocity `ẋ` (and the slip velocity `v`), m/(N·s).
    pub xd: f64,
    /// Of the acceleration output, direct feedthrough included, 1/kg.
    pub acceleration: f64,
    /// Of the spring force `k·(x_a − x)`.
    pub spring_force: f64,
    /// Of the applied force `F_app` ([`Rig1D::applied_force`]), through
    /// the state only (it has no direct feedthrough from `F`):
    /// `−k·∂x/∂F − c·∂ẋ/∂F`.
    pub applied_force: f64,
}

/// A state or input of the rig's linearization ([`Rig1D::partials`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Known {
    /// The position state x.
    Position,
    /// The velocity state ẋ.
    Velocity,
    /// The friction force input F (applied as −F).
    Friction,
    /// The external force input F_ext.
    ExternalForce,
    /// The actuator point input x_act_in (`Actuator::Input`).
    ActuatorInput,
    /// The reference inputs x_ref and v_ref (`Control::Input`).
    ReferencePosition,
    ReferenceVelocity,
}

/// `∂/∂known` of the rig's outputs and of the time derivatives of its
/// states (x, ẋ) at one instant ([`Rig1D::partials`]): the derivative of
/// x is ẋ, that of ẋ the acceleration output.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Partials {
    /// Of dx/dt = ẋ.
    pub position_rate: f64,
    /// Of every output; `acceleration` is also that of dẋ/dt.
    pub outputs: Rig1DOutputs,
}

/// The state at one instant: position, velocity, velocity-error integral.
#[derive(Clone, Copy, Debug)]
struct Point {
    x: f64,
    xd: f64,
    xi: f64,
}

#[derive(Clone, Debug)]
pub struct Rig1D {
    p: Rig1DParams,
    /// Time since the start (the prescribed signals depend on it).
    t: f64,
    /// Position; in the quasi-static mode with c = 0, where the position
    /// follows the forces, the held position of [`Rig1D::applied_force`].
    x: f64,
    xd: f64,
    /// ξ = ∫(v_ref − ẋ) dt of the controller (0 when it is off).
    xi: f64,
    /// ω of the sub-step rule (it depends on the parameters only).
    omega: f64,
    /// The linear part of the right-hand side, unsaturated
    /// ([`Rig1D::linear_part`] of piece 0; from the parameters only).
    linear: [[f64; 2]; 2],
    /// The stage equations of `linear` formed for the last sub-step length
    /// (a cache: `hs` is NaN until the first step forms it), so that they
    /// are formed once, not at every sub-step.
    solver: StageSolver,
    /// The exact step formed for the last step (or segment) length, of
    /// `linear` with the forcing scaled by 1/m (a cache: `h` is NaN until
    /// the first step forms it).
    exact: ExactStep,
    /// Whether the rig steps exactly ([`Rig1D::exact_segment`]): m > 0, a
    /// controller that does not saturate or none, and no active sinusoid
    /// in the forcing (actuator, drive force, built-in reference), so that
    /// between drive steps the forcing is a polynomial of degree ≤ 2 in
    /// time and the loop linear.
    exactly: bool,
    /// The plain mode of [`Rig1D::step_plain`]: m > 0, no controller, the
    /// prescribed ramp without a sinusoid, no drive force (a dither is
    /// allowed: it moves the surface, not the body). A case of `exactly`.
    plain: bool,
}

impl Rig1D {
    pub fn new(p: Rig1DParams) -> Result<Self, String> {
        p.validate()?;
        let mut rig = Rig1D {
            p,
            t: 0.0,
            x: p.x0,
            xd: p.v0,
            xi: 0.0,
            omega: 0.0,
            linear: [[0.0; 2]; 2],
            solver: StageSolver::new(f64::NAN, [[0.0; 2]; 2]),
            exact: ExactStep::UNFORMED,
            exactly: steps_exactly(&p),
            plain: p.m > 0.0
                && !p.control.on()
                && p.actuator == Actuator::Prescribed
                && !p.act_sine.is_active()
                && p.drive.f_step == 0.0
                && !p.drive.sine.is_active(),
        };
        rig.omega = rig.substep_omega(p.m == 0.0);
        rig.linear = rig.linear_part(0, p.m == 0.0);
        if p.m == 0.0 {
            rig.xd = rig.quasi_static_velocity(&Rig1DInputs::default(), &Rig1DInputs::default());
        }
        Ok(rig)
    }

    pub fn params(&self) -> &Rig1DParams {
        &self.p
    }

    pub fn time(&self) -> f64 {
        self.t
    }

    // ---- prescribed signals -------------------------------------------

    /// x_a at absolute time t; `x_act_in` is the input's value then.
    fn actuator_at(&self, t: f64, x_act_in: f64) -> f64 {
        match self.p.actuator {
            Actuator::Prescribed => self.p.x_a0 + self.p.v_a * t + self.p.act_sine.value(t),
            Actuator::Input => x_act_in,
        }
    }

    fn actuator_rate(&self, t: f64, x_act_slope: f64) -> f64 {
        match self.p.actuator {
            Actuator::Prescribed => self.p.v_a + self.p.act_sine.rate(t),
            Actuator::Input => x_act_slope,
        }
    }

    /// Surface position x_s(t) = v_surface·t + A_s·sin(2π f_s t).
    pub fn surface_position(&self, t: f64) -> f64 {
        self.p.v_surface * t + self.p.dither.value(t)
    }

    /// Surface velocity v_s(t) = v_surface + 2π f_s·A_s·cos(2π f_s t).
    pub fn surface_velocity(&self, t: f64) -> f64 {
        self.p.v_surface + self.p.dither.rate(t)
    }

    /// (x_ref, v_ref, R) at absolute time t = self.t + tau with inputs
    /// u + du·tau; R is an antiderivative of v_ref in time (differences of R
    /// are ∫v_ref).
    fn reference(&self, t: f64, tau: f64, u: &Rig1DInputs, du: &Rig1DInputs) -> (f64, f64, f64) {
        let r = &self.p.control.reference;
        match self.p.control.mode {
            Control::Off => (0.0, 0.0, 0.0),
            Control::BuiltIn => {
                let x_ref = r.x0 + r.v0 * t + r.sine.integral(t);
                (x_ref, r.v0 + r.sine.value(t), x_ref)
            }
            Control::Input => (
                u.x_ref + du.x_ref * tau,
                u.v_ref + du.v_ref * tau,
                u.v_ref * tau + 0.5 * du.v_ref * tau * tau,
            ),
        }
    }

    /// Unsaturated command u = Kp·(x_ref − x) + Kd·(β·v_ref − ẋ) + Ki·ξ.
    fn command(&self, s: &Point, x_ref: f64, v_ref: f64) -> f64 {
        let g = &self.p.control;
        g.kp * (x_ref - s.x) + g.kd * (g.ff * v_ref - s.xd) + g.ki * s.xi
    }

    fn command_at(&self, s: &Point, tau: f64, u: &Rig1DInputs, du: &Rig1DInputs) -> f64 {
        let (x_ref, v_ref, _) = self.reference(self.t + tau, tau, u, du);
        self.command(s, x_ref, v_ref)
    }

    fn here(&self) -> Point {
        Point {
            x: self.x,
            xd: self.xd,
            xi: self.xi,
        }
    }

    // ---- outputs at the current time, with the current inputs ----------

    /// Position; in the quasi-static mode with c = 0 it follows the forces,
    /// x = x_a + (F_ext − F + F_d)/k.
    pub fn position(&self, u: &Rig1DInputs) -> f64 {
        if self.p.m == 0.0 && self.p.c == 0.0 {
            self.actuator_at(self.t, u.x_act)
                + (u.f_ext - u.friction + self.p.drive.value(self.t)) / self.p.k
        } else {
            self.x
        }
    }

    /// Body velocity ẋ.
    pub fn velocity(&self) -> f64 {
        self.xd
    }

    /// Slip velocity v = ẋ − v_s(t).
    pub fn slip_velocity(&self) -> f64 {
        self.xd - self.surface_velocity(self.t)
    }

    /// Relative displacement x − x_s(t).
    pub fn relative_displacement(&self, u: &Rig1DInputs) -> f64 {
        self.position(u) - self.surface_position(self.t)
    }

    pub fn actuator_position(&self, u: &Rig1DInputs) -> f64 {
        self.actuator_at(self.t, u.x_act)
    }

    /// Spring force on the body, k·(x_a − x).
    pub fn spring_force(&self, u: &Rig1DInputs) -> f64 {
        self.p.k * (self.actuator_position(u) - self.position(u))
    }

    pub fn drive_force(&self) -> f64 {
        self.p.drive.value(self.t)
    }

    /// Saturated command sat(u, ±u_max) (0 when the controller is off).
    pub fn control_command(&self, u: &Rig1DInputs) -> f64 {
        if !self.p.control.on() {
            return 0.0;
        }
        let raw = self.command_at(&self.here(), 0.0, u, &Rig1DInputs::default());
        self.p.control.saturate(raw)
    }

    /// Control force G·sat(u, ±u_max).
    pub fn control_force(&self, u: &Rig1DInputs) -> f64 {
        if !self.p.control.on() {
            return 0.0;
        }
        self.p.control.gain * self.control_command(u)
    }

    /// Applied force F_app: every force on the body but friction, along
    /// the contact, positive with v, such that m·v̇ = F_app − F (see the
    /// module documentation):
    /// k·(x_a − x) − c·ẋ + F_ext + F_d + F_ctrl − m·a_s(t) when m > 0;
    /// k·(x_a − x_h) + F_ext + F_d − c·v_s(t) when m = 0, the force that
    /// holds the body on the surface at its held position x_h. Never a
    /// function of F.
    pub fn applied_force(&self, u: &Rig1DInputs) -> f64 {
        let held_spring = self.p.k * (self.actuator_position(u) - self.x);
        self.applied_force_of(
            held_spring,
            u.f_ext,
            self.drive_force(),
            self.control_force(u),
        )
    }

    /// [`Rig1D::applied_force`] from the spring force at the held position
    /// `k·(x_a − x)` (x the state), F_ext, F_d and F_ctrl, for it and for
    /// [`Rig1D::outputs`] alike.
    #[inline]
    fn applied_force_of(&self, held_spring: f64, f_ext: f64, drive: f64, control: f64) -> f64 {
        let p = &self.p;
        if p.m == 0.0 {
            // no inertia, no controller: the force that makes v = 0
            held_spring + f_ext + drive - p.c * self.surface_velocity(self.t)
        } else {
            held_spring - p.c * self.xd + f_ext + drive + control
                - p.m * self.surface_acceleration()
        }
    }

    pub fn acceleration(&self, u: &Rig1DInputs) -> f64 {
        if self.p.m == 0.0 {
            return 0.0;
        }
        (self.spring_force(u) - self.p.c * self.xd + u.f_ext - u.friction
            + self.drive_force()
            + self.control_force(u))
            / self.p.m
    }

    /// Every output at once, each bit for bit what its single-output
    /// function above gives: the same operations in the same order, but the
    /// quantities several outputs share (the drive force F_d(t), the
    /// actuator point x_a(t), the position, the spring force, the command)
    /// computed once instead of once per output that uses them.
    #[inline]
    pub fn outputs(&self, u: &Rig1DInputs) -> Rig1DOutputs {
        let p = &self.p;
        let t = self.t;
        let drive_force = p.drive.value(t);
        let actuator_position = self.actuator_at(t, u.x_act);
        // x = x_a + (F_ext − F + F_d)/k in the quasi-static mode with c = 0
        let position = if p.m == 0.0 && p.c == 0.0 {
            actuator_position + (u.f_ext - u.friction + drive_force) / p.k
        } else {
            self.x
        };
        let spring_force = p.k * (actuator_position - position);
        let (control_command, control_force) = if p.control.on() {
            let command = self.control_command(u);
            (command, p.control.gain * command)
        } else {
            (0.0, 0.0)
        };
        // m·ẍ = k(x_a − x) − c·ẋ + F_ext − F + F_d + F_ctrl; 0 when m = 0
        let acceleration = if p.m == 0.0 {
            0.0
        } else {
            (spring_force - p.c * self.xd + u.f_ext - u.friction + drive_force + control_force)
                / p.m
        };
        // at the state's position (the held one when m = c = 0): no F
        let held_spring = if p.m == 0.0 && p.c == 0.0 {
            p.k * (actuator_position - self.x)
        } else {
            spring_force
        };
        let applied_force = self.applied_force_of(held_spring, u.f_ext, drive_force, control_force);
        Rig1DOutputs {
            position,
            slip_velocity: self.xd - self.surface_velocity(t),
            acceleration,
            spring_force,
            actuator_position,
            relative_displacement: position - self.surface_position(t),
            velocity: self.xd,
            drive_force,
            control_command,
            control_force,
            applied_force,
        }
    }

    /// dx/dt now, the inputs moving at `du`: ẋ (m > 0), or the rate of the
    /// quasi-static balance.
    pub fn position_rate(&self, u: &Rig1DInputs, du: &Rig1DInputs) -> f64 {
        if self.p.m == 0.0 {
            self.quasi_static_velocity(u, du)
        } else {
            self.xd
        }
    }

    /// d²x_s/dt² of the surface.
    pub fn surface_acceleration(&self) -> f64 {
        self.p.dither.acceleration(self.t)
    }

    pub fn actuator_velocity(&self, du: &Rig1DInputs) -> f64 {
        self.actuator_rate(self.t, du.x_act)
    }

    pub fn drive_force_rate(&self) -> f64 {
        self.p.drive.rate(self.t)
    }

    /// The continuous-time partial derivatives `∂/∂known` of the outputs
    /// and of (ẋ, ẍ) at the current state and inputs `u`, with the states
    /// x and ẋ (m > 0): the rig's right-hand side is affine in them and in
    /// the inputs on each piece of the saturation, so these are its
    /// coefficients on the piece the command `u` lies in now (saturated:
    /// the controller adds nothing).
    ///
    /// The controller's integral is not a state of its own: ξ = ∫(v_ref −
    /// ẋ) dt = ∫v_ref dt − (x − x0) from ξ(0) = 0, a function of the
    /// position, so the command u = Kp·(x_ref − x) + Kd·(β·v_ref − ẋ) +
    /// Ki·ξ has ∂u/∂x = −(Kp + Ki), ∂u/∂ẋ = −Kd, and from the reference
    /// inputs ∂u/∂x_ref = Kp, ∂u/∂v_ref = β·Kd. With F_ctrl = G·u,
    ///
    /// ```text
    /// m·ẍ = k·(x_a − x) − c·ẋ + F_ext − F + F_d(t) + F_ctrl,
    /// F_app = k·(x_a − x) − c·ẋ + F_ext + F_d(t) + F_ctrl − m·a_s(t).
    /// ```
    ///
    /// The quasi-static mode (m = 0) has no velocity state: an error.
    pub fn partials(&self, u: &Rig1DInputs, known: Known) -> Result<Partials, String> {
        let p = &self.p;
        if p.m == 0.0 {
            return Err(
                "the quasi-static mode (m = 0) has no velocity state: the partial derivatives of the states x and v_body are not defined"
                    .into(),
            );
        }
        let one = |k: Known| if k == known { 1.0 } else { 0.0 };
        let actuator = match p.actuator {
            Actuator::Input => one(Known::ActuatorInput),
            Actuator::Prescribed => 0.0,
        };
        let g = &p.control;
        // the command's partial on the piece it lies in now
        let command = if g.on()
            && g.piece(self.command_at(&self.here(), 0.0, u, &Rig1DInputs::default())) == 0
        {
            let reference = match g.mode {
                Control::Input => {
                    g.kp * one(Known::ReferencePosition)
                        + g.kd * g.ff * one(Known::ReferenceVelocity)
                }
                _ => 0.0,
            };
            -(g.kp + g.ki) * one(Known::Position) - g.kd * one(Known::Velocity) + reference
        } else {
            0.0
        };
        let control_force = g.gain * command;
        let position = one(Known::Position);
        let velocity = one(Known::Velocity);
        let spring_force = p.k * (actuator - position);
        let applied_force =
            spring_force - p.c * velocity + one(Known::ExternalForce) + control_force;
        Ok(Partials {
            position_rate: velocity,
            outputs: Rig1DOutputs {
                position,
                slip_velocity: velocity,
                acceleration: (applied_force - one(Known::Friction)) / p.m,
                spring_force,
                actuator_position: actuator,
                relative_displacement: position,
                velocity,
                drive_force: 0.0,
                control_command: command,
                control_force,
                applied_force,
            },
        })
    }

    /// Quasi-static ẋ at the current time with inputs u moving at du:
    /// c = 0: ẋ_a + (Ḟ_ext − Ḟ + Ḟ_d)/k; c > 0: (k·(x_a − x) + F_ext − F + F_d)/c.
    fn quasi_static_velocity(&self, u: &Rig1DInputs, du: &Rig1DInputs) -> f64 {
        let p = &self.p;
        if p.c == 0.0 {
            self.actuator_rate(self.t, du.x_act)
                + (du.f_ext - du.friction + p.drive.rate(self.t)) / p.k
        } else {
            (p.k * (self.actuator_at(self.t, u.x_act) - self.x) + u.f_ext - u.friction
                + p.drive.value(self.t))
                / p.c
        }
    }

    // ---- stepping --------------------------------------------------------

    /// Advance by `h` with inputs u(τ) = u + du·τ, τ ∈ [0, h].
    pub fn step(&mut self, u: &Rig1DInputs, du: &Rig1DInputs, h: f64) {
        if self.plain {
            self.step_plain(u, du, h);
        } else {
            self.step_general(u, du, h);
        }
    }

    /// The step sensitivity to the friction force of the last step, of
    /// length `h`, in the plain mode ([`Rig1D::step_plain`]; else `None`)
    /// with `F` held over it: `∂/∂F` of the state after the step and of
    /// the outputs linear in it and in `F`.
    ///
    /// The step is exact ([`ExactStep`]): `(x, ẋ)⁺ = e^{hL}·(x, ẋ) +
    /// Σ_j w_j·g_j/m`, with the forcing `g_j = k·x_a + F_ext − F` at the
    /// three nodes. A held `F` enters every sample as `−F`, so
    ///
    /// ```text
    /// ∂(x, ẋ)⁺/∂F = −Σ_j w_j/m = −h·φ₁(hL)·e₂/m,
    /// ```
    ///
    /// whatever the state (the step is affine in it and in `F`). The
    /// outputs: the slip velocity `v = ẋ − v_s(t)` and `v_body` take
    /// `∂ẋ⁺/∂F`, the position `x` and `x_rel` take `∂x⁺/∂F`, the spring
    /// force `−k·∂x⁺/∂F`, the acceleration `(−k·∂x⁺/∂F − c·∂ẋ⁺/∂F − 1)/m`
    /// (its direct feedthrough `−F/m` included), the applied force
    /// `−k·∂x⁺/∂F − c·∂ẋ⁺/∂F` (no direct feedthrough from `F`). `F_ext`
    /// enters the state with the opposite sign (and `F_app` directly, +1).
    pub fn held_step_sensitivity(&self, h: f64) -> Option<StepSensitivity> {
        if !self.plain || h.is_nan() || h <= 0.0 {
            return None;
        }
        let p = &self.p;
        // the step's own weights when they cover this length (the usual
        // case: asked after the step), else formed for `h`
        let step = if self.exact.covers(h) {
            self.exact
        } else {
            ExactStep::new(h, self.linear, 1.0 / p.m)
        };
        let [x, xd] = step.held_response(h).map(|r| -r);
        Some(StepSensitivity {
            x,
            xd,
            acceleration: (-p.k * x - p.c * xd - 1.0) / p.m,
            spring_force: -p.k * x,
            applied_force: -p.k * x - p.c * xd,
        })
    }

    /// [`Rig1D::step`] in the plain mode: what the general path's exact
    /// segment ([`Rig1D::exact_segment`]) computes there, bit for bit (the
    /// terms that are zero in this mode are added as zeros, as it adds
    /// them), without its mode dispatch.
    fn step_plain(&mut self, u: &Rig1DInputs, du: &Rig1DInputs, h: f64) {
        if !self.exact.covers(h) {
            self.exact = ExactStep::new(h, self.linear, 1.0 / self.p.m);
        }
        // the nodes of the step length the exact step was formed for
        let hs = self.exact.h;
        let p = &self.p;
        let (t0, tau0) = (self.t + 0.0, 0.0);
        // the force without its part linear in the state (−k·x − c·ẋ)
        let forcing = |node: f64| -> f64 {
            let (t, tau) = (t0 + node * hs, tau0 + node * hs);
            // x_a0 + v_a·t + (inactive sinusoid); F_d and F_ctrl are 0
            let xa = p.x_a0 + p.v_a * t + 0.0;
            let ext = u.f_ext + du.f_ext * tau;
            let fr = u.friction + du.friction * tau;
            p.k * xa + ext - fr + 0.0 + 0.0
        };
        let g = NODES.map(forcing);
        [self.x, self.xd] = self.exact.advance([self.x, self.xd], g, h);
        self.t += h;
    }

    /// [`Rig1D::step`] in every mode.
    fn step_general(&mut self, u: &Rig1DInputs, du: &Rig1DInputs, h: f64) {
        let p = self.p;
        if p.m == 0.0 && p.c == 0.0 {
            // pure force balance: nothing to integrate. The held position
            // of `applied_force`: x at the start of the step, carried with
            // the surface to its end.
            let moved = self.surface_position(self.t + h) - self.surface_position(self.t);
            self.x = self.position(u) + moved;
            self.t += h;
            self.xd = self.quasi_static_velocity(&u.at(du, h), du);
            return;
        }
        let first_order = p.m == 0.0;
        // F_step·[t ≥ t_step] jumps inside this step: integrate up to it and on.
        let d = &p.drive;
        if d.f_step != 0.0 && d.t_step > self.t && d.t_step < self.t + h {
            let tau = d.t_step - self.t;
            self.integrate(0.0, tau, u, du, first_order);
            self.integrate(tau, h - tau, u, du, first_order);
        } else {
            self.integrate(0.0, h, u, du, first_order);
        }
        self.t += h;
        if first_order {
            self.xd = self.quasi_static_velocity(&u.at(du, h), du);
        }
    }

    /// Largest angular frequency the sub-steps must resolve.
    fn substep_omega(&self, first_order: bool) -> f64 {
        let p = &self.p;
        let g = &p.control;
        let mut forcing = p.drive.sine.active_omega();
        if p.actuator == Actuator::Prescribed {
            forcing = forcing.max(p.act_sine.active_omega());
        }
        if g.mode == Control::BuiltIn {
            forcing = forcing.max(g.reference.sine.active_omega());
        }
        let omega = if first_order {
            p.k / p.c.max(f64::MIN_POSITIVE)
        } else {
            let (k, c) = if g.on() {
                (p.k + g.gain * (g.kp + g.ki), p.c + g.gain * g.kd)
            } else {
                (p.k, p.c)
            };
            (k / p.m + (c / (2.0 * p.m)).powi(2)).sqrt() + c / (2.0 * p.m)
        };
        omega.max(forcing)
    }

    /// Integrate over τ ∈ [tau_start, tau_start + len] of the current step.
    fn integrate(
        &mut self,
        tau_start: f64,
        len: f64,
        u: &Rig1DInputs,
        du: &Rig1DInputs,
        first_order: bool,
    ) {
        if self.exactly {
            let end = self.exact_segment(tau_start, len, u, du);
            self.set(end);
            return;
        }
        // ⌈q⌉ is 1 for 0 < q ≤ 1: no call to ceil at the usual step
        let q = self.omega * len / OMEGA_H_MAX;
        let n = if q <= 1.0 { 1 } else { q.ceil() as usize }.clamp(1, 1_000_000);
        let hs = len / n as f64;
        if self.solver.hs != hs {
            self.solver = StageSolver::new(hs, self.linear);
        }
        for i in 0..n {
            let tau0 = tau_start + i as f64 * hs;
            self.substep(tau0, hs, u, du, first_order);
        }
    }

    /// The linear part `L` of the right-hand side in (x, ẋ) with sat(·)
    /// replaced by its piece `piece` (0: linear, ±1: constant).
    fn linear_part(&self, piece: i8, first_order: bool) -> [[f64; 2]; 2] {
        let p = &self.p;
        if first_order {
            // c·ẋ = k(x_a − x) + …
            return [[-p.k / p.c, 0.0], [0.0, 0.0]];
        }
        let g = &p.control;
        let (k, c) = if g.on() && piece == 0 {
            (p.k + g.gain * (g.kp + g.ki), p.c + g.gain * g.kd)
        } else {
            (p.k, p.c)
        };
        [[0.0, 1.0], [-k / p.m, -c / p.m]]
    }

    /// One sub-step, split where the command crosses ±u_max (see the module
    /// documentation).
    fn substep(
        &mut self,
        tau0: f64,
        hs: f64,
        u: &Rig1DInputs,
        du: &Rig1DInputs,
        first_order: bool,
    ) {
        let ctrl = self.p.control;
        if !ctrl.saturates() {
            let end = self.segment(tau0, hs, 0, u, du, first_order);
            self.set(end);
            return;
        }
        let (mut tau, mut remaining) = (tau0, hs);
        let mut piece = ctrl.piece(self.command_at(&self.here(), tau, u, du));
        for switches in 0..=MAX_SWITCHES {
            let end = self.segment(tau, remaining, piece, u, du, first_order);
            let u_end = self.command_at(&end, tau + remaining, u, du);
            let piece_end = ctrl.piece(u_end);
            if piece_end == piece || switches == MAX_SWITCHES {
                self.set(end);
                return;
            }
            // the boundary u = ±u_max that the trajectory leaves `piece` through
            let side = if piece == 0 { piece_end } else { piece };
            let boundary = f64::from(side) * ctrl.u_max;
            let g0 = self.command_at(&self.here(), tau, u, du) - boundary;
            let theta = find_crossing(
                |th| {
                    let s = self.segment(tau, th, piece, u, du, first_order);
                    self.command_at(&s, tau + th, u, du) - boundary
                },
                g0,
                u_end - boundary,
                remaining,
            );
            if theta >= remaining {
                self.set(end);
                return;
            }
            if theta > 0.0 {
                let mid = self.segment(tau, theta, piece, u, du, first_order);
                self.set(mid);
            }
            tau += theta;
            remaining -= theta;
            piece = if piece == 0 { piece_end } else { 0 };
        }
    }

    fn set(&mut self, s: Point) {
        (self.x, self.xd, self.xi) = (s.x, s.xd, s.xi);
    }

    /// One Gauss–Legendre step of length `len` from the current state at
    /// τ = tau0 of the step, with sat(·) replaced by its piece `piece`
    /// (0: linear, ±1: ±u_max). Returns the state at its end.
    fn segment(
        &self,
        tau0: f64,
        len: f64,
        piece: i8,
        u: &Rig1DInputs,
        du: &Rig1DInputs,
        first_order: bool,
    ) -> Point {
        let p = &self.p;
        let ctrl = &p.control;
        let (x, xd, xi) = (self.x, self.xd, self.xi);
        let t0 = self.t + tau0;
        let r0 = self.reference_integral(t0, tau0, u, du);
        // The right-hand side at the start state (x, ẋ) at stage time
        // t0 + c·len: affine in the state with the linear part
        // `linear_part`, so the stage equations are solved in closed form
        // (gauss_legendre::linear_stage_sums) from these two values.
        let rhs = |c: f64| -> (f64, f64) {
            let (t, tau) = (t0 + c * len, tau0 + c * len);
            let xa = self.actuator_at(t, u.x_act + du.x_act * tau);
            let ext = u.f_ext + du.f_ext * tau;
            let fr = u.friction + du.friction * tau;
            let drive = p.drive.value(t);
            if first_order {
                // c·ẋ = k(x_a − x) + F_ext − F + F_d (quasi-static, as
                // Appels & Herder's piezo push)
                return ((p.k * (xa - x) + ext - fr + drive) / p.c, 0.0);
            }
            // F_ctrl with sat(·) replaced by its piece
            let control = match (ctrl.on(), piece) {
                (false, _) => 0.0,
                (true, 0) => {
                    let (x_ref, v_ref, r) = self.reference(t, tau, u, du);
                    // ξ at the stage is ξ_base − x_stage (exact: ξ̇ = v_ref − ẋ)
                    let xi_base = xi + (r - r0) + x;
                    ctrl.gain
                        * (ctrl.kp * (x_ref - x)
                            + ctrl.kd * (ctrl.ff * v_ref - xd)
                            + ctrl.ki * (xi_base - x))
                }
                (true, side) => ctrl.gain * f64::from(side) * ctrl.u_max,
            };
            // m·ẍ = k(x_a − x) − c·ẋ + F_ext − F + F_d + F_ctrl
            let force = p.k * (xa - x) - p.c * xd + ext - fr + drive + control;
            (xd, force / p.m)
        };
        let ((a0, a1), (b0, b1)) = (rhs(C[0]), rhs(C[1]));
        let b = [a0, a1, b0, b1];
        // a whole unsaturated sub-step: the solver formed for it
        let sums = if piece == 0 && len == self.solver.hs {
            self.solver.sums(b)
        } else {
            let linear = if piece == 0 {
                self.linear
            } else {
                self.linear_part(piece, first_order)
            };
            linear_stage_sums(len, linear, b)
        };
        let x_new = x + len * 0.5 * sums[0];
        let xd_new = if first_order {
            0.5 * sums[0]
        } else {
            xd + len * 0.5 * sums[1]
        };
        self.segment_end((t0, tau0, len), r0, (x_new, xd_new), u, du)
    }

    /// R(t) of [`Rig1D::reference`] (an antiderivative of v_ref) at time
    /// `t`, `tau` into the step; 0 without the controller.
    fn reference_integral(&self, t: f64, tau: f64, u: &Rig1DInputs, du: &Rig1DInputs) -> f64 {
        if self.p.control.on() {
            self.reference(t, tau, u, du).2
        } else {
            0.0
        }
    }

    /// The state at the end of a segment of length `len` from the current
    /// state at time `t0`, `tau0` into the step (`r0`: R there), whose
    /// position and velocity reached `(x, ẋ)`: ξ changes exactly by
    /// ∫v_ref − Δx (ξ̇ = v_ref − ẋ).
    fn segment_end(
        &self,
        (t0, tau0, len): (f64, f64, f64),
        r0: f64,
        (x, xd): (f64, f64),
        u: &Rig1DInputs,
        du: &Rig1DInputs,
    ) -> Point {
        let xi = if self.p.control.on() {
            let r1 = self.reference(t0 + len, tau0 + len, u, du).2;
            self.xi + (r1 - r0) - (x - self.x)
        } else {
            self.xi
        };
        Point { x, xd, xi }
    }

    /// The exact step ([`ExactStep`]) of length `len` from the current
    /// state at τ = tau0 of the step, in a mode where the rig steps
    /// exactly (`exactly`: no saturation, no sinusoid in the forcing, and
    /// no drive step inside the segment). Returns the state at its end.
    ///
    /// The forcing is the force without its part linear in the state,
    /// which `linear` holds: `−k·x − c·ẋ` and, with the controller,
    /// `−G·((Kp + Ki)·x + Kd·ẋ)`, since ξ(s) = ξ₀ + ∫v_ref − (x(s) − x₀)
    /// (ξ̇ = v_ref − ẋ, exactly). What is left is a polynomial of degree ≤ 2
    /// in time: ramps, inputs linear over the step, and the integral of a
    /// ramped reference velocity.
    fn exact_segment(&mut self, tau0: f64, len: f64, u: &Rig1DInputs, du: &Rig1DInputs) -> Point {
        if !self.exact.covers(len) {
            self.exact = ExactStep::new(len, self.linear, 1.0 / self.p.m);
        }
        // the nodes of the length the exact step was formed for
        let hs = self.exact.h;
        let p = &self.p;
        let ctrl = &p.control;
        let (x, xd, xi) = (self.x, self.xd, self.xi);
        let t0 = self.t + tau0;
        let r0 = self.reference_integral(t0, tau0, u, du);
        let forcing = |node: f64| -> f64 {
            let (t, tau) = (t0 + node * hs, tau0 + node * hs);
            let xa = self.actuator_at(t, u.x_act + du.x_act * tau);
            let ext = u.f_ext + du.f_ext * tau;
            let fr = u.friction + du.friction * tau;
            let drive = p.drive.value(t);
            let control = if ctrl.on() {
                let (x_ref, v_ref, r) = self.reference(t, tau, u, du);
                // ξ(s) + x(s) = ξ₀ + (R(s) − R₀) + x₀
                let xi_base = xi + (r - r0) + x;
                ctrl.gain * (ctrl.kp * x_ref + ctrl.kd * (ctrl.ff * v_ref) + ctrl.ki * xi_base)
            } else {
                0.0
            };
            // m·ẍ = k·x_a + F_ext − F + F_d + (F_ctrl's forcing) + L-part
            p.k * xa + ext - fr + drive + control
        };
        let g = NODES.map(forcing);
        let [x_new, xd_new] = self.exact.advance([x, xd], g, len);
        self.segment_end((t0, tau0, len), r0, (x_new, xd_new), u, du)
    }

    /// The number of values of the state (4).
    #[inline]
    pub fn state_len(&self) -> usize {
        4
    }

    /// The state `[t, x, ẋ, ξ]` (ξ the controller's integral) into `out`,
    /// of [`Rig1D::state_len`] values.
    #[inline]
    pub fn write_state_into(&self, out: &mut [f64]) {
        out.copy_from_slice(&[self.t, self.x, self.xd, self.xi]);
    }

    /// Whether the state is finite (a scan of [`Rig1D::write_state_into`],
    /// without the copy).
    #[inline]
    pub fn state_is_finite(&self) -> bool {
        [self.t, self.x, self.xd, self.xi]
            .iter()
            .all(|v| v.is_finite())
    }

    /// The same state as a new vector.
    pub fn state_to_vec(&self) -> Vec<f64> {
        let mut v = vec![0.0; self.state_len()];
        self.write_state_into(&mut v);
        v
    }

    /// (Inlined into a caller, the message out of line.)
    #[inline]
    pub fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
        match s {
            // x·0 is 0 for a finite x, NaN otherwise: one test for the four
            [t, x, xd, xi] if t * 0.0 + x * 0.0 + xd * 0.0 + xi * 0.0 == 0.0 => {
                (self.t, self.x, self.xd, self.xi) = (*t, *x, *xd, *xi);
                Ok(())
            }
            _ => Err(state_refused(s)),
        }
    }
}

/// Whether a rig with parameters `p` steps exactly ([`Rig1D::exact_segment`]):
/// m > 0, no saturation, and no sinusoid driving the body.
fn steps_exactly(p: &Rig1DParams) -> bool {
    let sine_actuator = p.actuator == Actuator::Prescribed && p.act_sine.is_active();
    let sine_reference = p.control.mode == Control::BuiltIn && p.control.reference.sine.is_active();
    p.m > 0.0
        && !p.control.saturates()
        && !sine_actuator
        && !p.drive.sine.is_active()
        && !sine_reference
}

/// Why [`Rig1D::state_from_slice`] refused `s`.
#[cold]
#[inline(never)]
fn state_refused(s: &[f64]) -> String {
    format!("Rig1D state must be 4 finite numbers, got {s:?}")
}

/// θ ∈ [0, len] where g changes sign, g(0) = g0, g(len) = g_len (Illinois
/// regula falsi, to 1e-12·len). Returns the end of the final bracket on
/// the far side of the crossing; 0 when g0 already has the far side's sign
/// (the piece was read at the boundary itself).
fn find_crossing(g: impl Fn(f64) -> f64, g0: f64, g_len: f64, len: f64) -> f64 {
    if g0 == 0.0 || (g0 > 0.0) == (g_len > 0.0) {
        return 0.0;
    }
    let (mut a, mut b, mut ga, mut gb) = (0.0, len, g0, g_len);
    let mut kept = 0i8;
    for _ in 0..200 {
        if b - a <= 1e-12 * len {
            break;
        }
        let mut c = (a * gb - b * ga) / (gb - ga);
        if !(c > a && c < b) {
            c = 0.5 * (a + b);
        }
        let gc = g(c);
        if gc == 0.0 {
            return c;
        }
        if (gc > 0.0) == (gb > 0.0) {
            (b, gb) = (c, gc);
            if kept == -1 {
                ga *= 0.5;
            }
            kept = -1;
        } else {
            (a, ga) = (c, gc);
            if kept == 1 {
                gb *= 0.5;
            }
            kept = 1;
        }
    }
    b
}

#[cfg(test)]
mod tests;
