//! A rig with mass and a dynamic friction law as one ODE system, solved by
//! [`crate::radau`].
//!
//! State `y = (x, ẋ, ξ, s)`: body position and velocity, the controller's
//! velocity-error integral ξ (constant 0 without controller), and the
//! friction law's state `s` (LuGre: the bristle deflection `z`; Dahl: the
//! force of the law `F_dahl`). Right-hand side, from the physics crates:
//!
//! - friction inputs: `v` = the rig's slip velocity `ẋ − v_s(t)`
//!   ([`Rig1D::slip_velocity`]) or its body velocity, `x` = its position or
//!   its displacement relative to the surface ([`Rig1D::relative_displacement`]);
//! - LuGre (Sun et al. 2016 eq. 9–11): `ż = v − σ0·|v|·z/g(v)` ([`LuGre::z_rate`]),
//!   `F = σ0·z + σ1(v)·ż + σ2·v` ([`LuGre::force_of`]);
//!   Dahl (Sun et al. 2016 eq. 2–3): `dF/dt = σ·|1 − F/Fc·sgn v|^α·sgn(1 − F/Fc·sgn v)·v`
//!   for `F = F_dahl` ([`Dahl::force_rate`]), the force `F_dahl + F_offset`
//!   ([`Dahl::force_of`]);
//! - rig (docs/models.md "Rigs", `rig-dynamics/src/rig1d.rs`):
//!   `m·ẍ = k·(x_a(t) − x) − c·ẋ + F_ext − F + F_d(t) + F_ctrl`, evaluated by
//!   [`Rig1D::acceleration`] on a copy of the rig set to `(t, x, ẋ, ξ)`, so
//!   actuator law, drive force, controller and surface motion are the
//!   crate's own;
//! - controller integral (rig1d.rs): `ξ̇ = v_ref(t) − ẋ`, with the built-in
//!   reference `v_ref = v_r0 + V·sin(2π f_r t)` or the (constant) input.
//!
//! The rig's clock starts at 0 at the start of the run, as in the FMU.
//! The kinks of the friction laws at `v = 0` (and at the points of LuGre's
//! position table) are declared as switching functions, so that no
//! integration step straddles one ([`crate::radau`]).

use crate::radau::{self, OdeSystem, RadauError, RadauOptions, RadauStats};
use friction_laws::dahl::Dahl;
use friction_laws::lugre::LuGre;
use rig_dynamics::rig1d::{Control, Rig1D, Rig1DInputs};

/// The friction law of the coupled system.
#[derive(Clone, Debug)]
pub enum DynamicLaw {
    /// LuGre with its (constant) normal force input `Fn`.
    LuGre {
        law: Box<LuGre>,
        normal_force: f64,
    },
    Dahl(Dahl),
}

/// Which rig output drives the friction law's velocity input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VelocitySource {
    /// `rig.v`, the slip velocity ẋ − v_s(t).
    Slip,
    /// `rig.v_body`, ẋ.
    Body,
}

/// What drives LuGre's position input `x` (the position table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PositionSource {
    /// Unconnected: the input's start value.
    Constant(f64),
    /// `rig.x`.
    Position,
    /// `rig.x_rel`, x − x_s(t).
    Relative,
}

/// Rig1D (m > 0) coupled with LuGre or Dahl.
#[derive(Clone, Debug)]
pub struct RigWithFriction {
    /// The rig as constructed from its parameters (its state is replaced
    /// at every evaluation).
    pub rig: Rig1D,
    pub law: DynamicLaw,
    /// The rig's unconnected inputs (F_ext, x_act_in, x_ref, v_ref) at
    /// their constant values; `friction` is set at every evaluation.
    pub inputs: Rig1DInputs,
    pub velocity: VelocitySource,
    pub position: PositionSource,
}

/// The coupled quantities at one state.
#[derive(Clone, Debug)]
pub struct Coupling {
    /// The rig set to the state.
    pub rig: Rig1D,
    /// The friction law's inputs.
    pub v: f64,
    pub x: f64,
    /// The friction force, applied to the rig as −F.
    pub force: f64,
}

impl RigWithFriction {
    /// Initial state: the rig's `x0`, `v0`, ξ = 0 and the relaxed law.
    pub fn initial_state(&self) -> [f64; 4] {
        let s = self.rig.state_to_vec();
        let law_state = match &self.law {
            DynamicLaw::LuGre { law, .. } => law.z(),
            DynamicLaw::Dahl(d) => d.dahl_force(),
        };
        [s[1], s[2], s[3], law_state]
    }

    /// The rig at rig time `tau` in state `(x, ẋ, ξ)` (refused when not
    /// finite).
    pub fn rig_at(&self, tau: f64, y: &[f64]) -> Result<Rig1D, String> {
        let mut rig = self.rig.clone();
        rig.state_from_slice(&[tau, y[0], y[1], y[2]])?;
        Ok(rig)
    }

    /// Friction inputs and force at state `y`, rig time `tau`.
    pub fn coupling(&self, tau: f64, y: &[f64]) -> Result<Coupling, String> {
        let rig = self.rig_at(tau, y)?;
        let v = match self.velocity {
            VelocitySource::Slip => rig.slip_velocity(),
            VelocitySource::Body => rig.velocity(),
        };
        let x = match self.position {
            PositionSource::Constant(x) => x,
            PositionSource::Position => rig.position(&self.inputs),
            PositionSource::Relative => rig.relative_displacement(&self.inputs),
        };
        let force = match &self.law {
            DynamicLaw::LuGre { law, normal_force } => law.force_of(y[3], v, x, *normal_force),
            DynamicLaw::Dahl(d) => d.force_of(y[3]),
        };
        Ok(Coupling { rig, v, x, force })
    }

    fn controller_on(&self) -> bool {
        self.rig.params().control.mode != Control::Off
    }

    /// Reference velocity of the controller at rig time `tau`.
    fn v_ref(&self, tau: f64) -> f64 {
        let ctrl = &self.rig.params().control;
        match ctrl.mode {
            Control::Off => 0.0,
            Control::BuiltIn => ctrl.reference.v0 + ctrl.reference.sine.value(tau),
            Control::Input => self.inputs.v_ref,
        }
    }

    /// Times in `(0, tau_end)` where the right-hand side jumps (the step
    /// of the drive force), at which the integration restarts.
    pub fn breakpoints(&self, tau_end: f64) -> Vec<f64> {
        let d = &self.rig.params().drive;
        if d.f_step != 0.0 && d.t_step > 0.0 && d.t_step < tau_end {
            vec![d.t_step]
        } else {
            Vec::new()
        }
    }

    /// Absolute tolerances: `rtol` times a scale per state: a length
    /// `L = max(F*/k, |x0|, |x_a0|, (|v_a| + |v_s|)·1 s)` (F* the friction
    /// level), a velocity `L·√(k/m)` (at least the rig's speeds), `L·1 s`
    /// for ξ, and the law's own scale (LuGre: g/σ0, Dahl: Fc).
    pub fn tolerances(&self, rtol: f64) -> Vec<f64> {
        let p = self.rig.params();
        let (level, law_scale) = match &self.law {
            DynamicLaw::LuGre { law, normal_force } => {
                let q = law.params();
                let n = if q.normal_force_form {
                    normal_force.max(1e-300)
                } else {
                    1.0
                };
                let fs = q.fs.max(if q.direction_dependent { q.fs_neg } else { 0.0 });
                (fs * n, fs / q.sigma0)
            }
            DynamicLaw::Dahl(d) => (d.params().fc, d.params().fc),
        };
        let mut length = (p.x0.abs())
            .max(p.x_a0.abs())
            .max(p.v_a.abs() + p.v_surface.abs());
        if p.k > 0.0 {
            length = length.max(level / p.k);
        }
        let length = length.max(1e-9);
        let speed = (length * (p.k / p.m).sqrt())
            .max(p.v0.abs())
            .max(p.v_a.abs())
            .max(p.v_surface.abs())
            .max(1e-12);
        [length, speed, length, law_scale]
            .iter()
            .map(|s| rtol * s)
            .collect()
    }

    /// States at the rig times `taus` (increasing, `taus[0] ≥ 0`), the
    /// integration restarted at each breakpoint.
    pub fn solve(
        &self,
        taus: &[f64],
        rtol: f64,
        mut out: impl FnMut(f64, &[f64]),
    ) -> Result<RadauStats, RadauError> {
        let Some(&tau_end) = taus.last() else {
            return Ok(RadauStats::default());
        };
        let opts = RadauOptions::new(rtol, rtol).with_atol(self.tolerances(rtol));
        let mut stats = RadauStats::default();
        let mut y = self.initial_state().to_vec();
        let mut tau0 = 0.0;
        let mut rest = taus;
        let mut cuts = self.breakpoints(tau_end);
        cuts.push(f64::INFINITY);
        for cut in cuts {
            // Outputs before the jump; the segment ends a few ulps short of
            // it so that no stage sees the jumped value.
            let n = rest.partition_point(|&t| t < cut);
            let (seg, tail) = rest.split_at(n);
            let seg_end = if cut.is_finite() {
                cut - 4.0 * f64::EPSILON * cut.abs()
            } else {
                tau_end
            };
            let mut times: Vec<f64> = seg.to_vec();
            let extra = cut.is_finite() && !matches!(times.last(), Some(&t) if t >= seg_end);
            if extra {
                times.push(seg_end);
            }
            if times.is_empty() {
                break;
            }
            let mut last = y.clone();
            let count = seg.len();
            let mut k = 0;
            let s = radau::solve_with(self, tau0, &y, &times, &opts, |t, yi| {
                if k < count {
                    out(t, yi);
                }
                k += 1;
                last.copy_from_slice(yi);
            })?;
            stats.add(&s);
            y = last;
            tau0 = if cut.is_finite() { cut } else { tau_end };
            rest = tail;
            if rest.is_empty() {
                break;
            }
        }
        Ok(stats)
    }
}

impl RigWithFriction {
    /// The table points of LuGre's position-dependent levels, when its
    /// position input is connected.
    fn table_points(&self) -> &[f64] {
        match (&self.law, self.position) {
            (
                DynamicLaw::LuGre { law, .. },
                PositionSource::Position | PositionSource::Relative,
            ) if law.params().position_dependent => &law.params().x_table[..law.params().n_table],
            _ => &[],
        }
    }
}

impl OdeSystem for RigWithFriction {
    fn dim(&self) -> usize {
        4
    }

    /// The friction velocity `v` (kinks of `|v|`, `sgn v` and of the
    /// direction-dependent levels) and `x − x_table[i]` (kinks of the
    /// piecewise-linear position table). Not located: the corners of the
    /// controller's saturation, left to the step size control.
    fn switching_count(&self) -> usize {
        1 + self.table_points().len()
    }

    fn switching(&self, tau: f64, y: &[f64], g: &mut [f64]) {
        match self.coupling(tau, y) {
            Ok(c) => {
                g[0] = c.v;
                for (gi, xi) in g[1..].iter_mut().zip(self.table_points()) {
                    *gi = c.x - xi;
                }
            }
            Err(_) => g.fill(0.0),
        }
    }

    fn rhs(&self, tau: f64, y: &[f64], dydt: &mut [f64]) {
        let Ok(c) = self.coupling(tau, y) else {
            // A non-finite state: the integrator rejects the step.
            dydt.fill(f64::NAN);
            return;
        };
        let u = Rig1DInputs {
            friction: c.force,
            ..self.inputs
        };
        dydt[0] = y[1];
        dydt[1] = c.rig.acceleration(&u);
        dydt[2] = if self.controller_on() {
            self.v_ref(tau) - y[1]
        } else {
            0.0
        };
        dydt[3] = match &self.law {
            DynamicLaw::LuGre { law, normal_force } => law.z_rate(y[3], c.v, c.x, *normal_force),
            DynamicLaw::Dahl(d) => d.force_rate(y[3], c.v),
        };
    }
}
