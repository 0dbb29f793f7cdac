//! The planar oscillator of Wijata et al. 2016 (Rig2D) with the 2-D bristle law
//! (Bristle2D) as a hybrid ODE system, solved by [`crate::radau`].
//!
//! State `y = (x1, ẋ1, x2, ẋ2, z1, z2)`. Right-hand side, from the physics
//! crates:
//!
//! - rig (docs/models.md "Rigs", `rig-dynamics/src/rig2d.rs`):
//!   `m·ẍ_i = −k_i·x_i − c_i·ẋ_i + F_ext,i − F_i`, each axis a [`Rig1D`]
//!   ([`Rig2D::axis`]) set to `(t, x_i, ẋ_i)`, whose
//!   [`Rig1D::acceleration`] and [`Rig1D::slip_velocity`]
//!   (`v_i = ẋ_i − v_s,i(t)`, surface speed and dither) are used;
//! - 2-D bristle (docs/models.md, "Two-dimensional bristle", derived from Wijata
//!   et al. 2016): `ż = v − [on the boundary and z·v > 0]·(z·v)·z/|z|²`
//!   ([`Bristle2D::z_rate`]), `F_i = (1 + a_i)·σ0i·z_i + σ1i(|v|)·ż_i`
//!   inside the disc `|z| < z0`, without the `a_i` on its boundary
//!   ([`Bristle2D::force_of`]).
//!
//! The law switches between two modes, tracked explicitly rather than read
//! from `|z|`: *stick* (inside the disc, `ż = v`) and *slide* (on the
//! circle `|z| = z0`, `z` turning toward the slip direction). Stick ends
//! when `|z|` reaches `z0` (switching function `|z|²/z0² − 1`) with the slip
//! pointing outward (`z·v > 0`); slide ends when `z·v` falls to 0. At each
//! change the integration stops exactly there
//! ([`radau::solve_until_switch`]), `z` is put on the circle, and it
//! restarts in the other mode. While sliding the equations use `z` scaled
//! to the circle, so round-off in `|z|` cannot accumulate. The force jumps
//! by `a_i·σ0i·z_i` at the change (the stiction peak of the reset
//! integrator), which the restart handles exactly.

use crate::radau::{self, OdeSystem, RadauError, RadauOptions, RadauStats};
use friction_laws::bristle2d::Bristle2D;
use rig_dynamics::rig1d::{Rig1D, Rig1DInputs};
use rig_dynamics::rig2d::Rig2D;

/// Rig2D coupled with the 2-D bristle law (`v_i → v_i`, `F_i → F_i`).
#[derive(Clone, Debug)]
pub struct PlanarBristle {
    pub rig: Rig2D,
    pub law: Bristle2D,
    /// The rig's unconnected external forces.
    pub f_ext: [f64; 2],
}

/// The coupled quantities at one state.
#[derive(Clone, Debug)]
pub struct PlanarCoupling {
    pub axes: [Rig1D; 2],
    /// Slip velocity, the law's input.
    pub v: [f64; 2],
    /// Deflection as the mode sees it (on the circle when sliding).
    pub z: [f64; 2],
    pub force: [f64; 2],
}

/// Most mode changes in one run.
const MAX_SWITCHES: usize = 1_000_000;

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

impl PlanarBristle {
    /// `(x1, ẋ1, x2, ẋ2, z1, z2)` at the start.
    pub fn initial_state(&self) -> [f64; 6] {
        let s = self.rig.state_to_vec();
        let z = self.law.z();
        [s[1], s[2], s[5], s[6], z[0], z[1]]
    }

    fn z0(&self) -> f64 {
        self.law.params().z0
    }

    /// `z` scaled onto the circle `|z| = z0` (unchanged at 0).
    fn on_circle(&self, z: [f64; 2]) -> [f64; 2] {
        let r = z[0].hypot(z[1]);
        if r > 0.0 {
            let f = self.z0() / r;
            [z[0] * f, z[1] * f]
        } else {
            z
        }
    }

    /// Rig axes, slip velocity, deflection and force at state `y`, rig
    /// time `tau`, in mode `sliding`.
    pub fn coupling(&self, tau: f64, y: &[f64], sliding: bool) -> Result<PlanarCoupling, String> {
        let mut axes = [self.rig.axis(0).clone(), self.rig.axis(1).clone()];
        for (i, a) in axes.iter_mut().enumerate() {
            a.state_from_slice(&[tau, y[2 * i], y[2 * i + 1], 0.0])?;
        }
        let v = [axes[0].slip_velocity(), axes[1].slip_velocity()];
        let raw = [y[4], y[5]];
        if !(raw[0].is_finite() && raw[1].is_finite()) {
            return Err(format!("deflection {raw:?} is not finite"));
        }
        let z = if sliding { self.on_circle(raw) } else { raw };
        let force = self.law.force_of(z, v, sliding);
        Ok(PlanarCoupling { axes, v, z, force })
    }

    /// Absolute tolerances: `rtol` times a length `L = max(|x0|, F*/k)`
    /// (F* the sliding level), a velocity (at least `|v0|`, the surface
    /// speeds, `L·√(k/m)`) and `z0`.
    pub fn tolerances(&self, rtol: f64) -> Vec<f64> {
        let p = self.rig.params();
        let q = self.law.params();
        let level = (q.sigma01 * (1.0 + q.a1)).max(q.sigma02 * (1.0 + q.a2)) * q.z0;
        let mut scale = Vec::with_capacity(6);
        for i in 0..2 {
            let mut length = p.x0[i].abs().max(q.z0);
            if p.k[i] > 0.0 {
                length = length.max(level / p.k[i]);
            }
            let speed = (length * (p.k[i] / p.m).sqrt())
                .max(p.v0[i].abs())
                .max(p.v_surface[i].abs())
                .max(1e-12);
            scale.push(length);
            scale.push(speed);
        }
        scale.extend([q.z0, q.z0]);
        scale.iter().map(|s| rtol * s).collect()
    }

    /// States at the rig times `taus` (increasing, ≥ 0), each handed to
    /// `out` with the mode (`true`: sliding).
    pub fn solve(
        &self,
        taus: &[f64],
        rtol: f64,
        mut out: impl FnMut(f64, &[f64], bool),
    ) -> Result<RadauStats, RadauError> {
        let opts = RadauOptions::new(rtol, rtol).with_atol(self.tolerances(rtol));
        let mut stats = RadauStats::default();
        let mut y = self.initial_state().to_vec();
        let (mut tau, mut rest) = (0.0, taus);
        let mut sliding = self.starts_sliding(0.0, &y);
        if sliding {
            self.put_on_circle(&mut y);
        }
        for _ in 0..MAX_SWITCHES {
            if rest.is_empty() {
                return Ok(stats);
            }
            let mode = Mode { sys: self, sliding };
            let end = radau::solve_until_switch(&mode, tau, &y, rest, &opts, |t, yi| {
                out(t, yi, sliding)
            })?;
            stats.add(&end.stats);
            if !end.switched {
                return Ok(stats);
            }
            rest = &rest[rest.partition_point(|&t| t <= end.t)..];
            (tau, y) = (end.t, end.y);
            sliding = if sliding {
                // z·v has fallen to 0: back into the disc.
                false
            } else {
                self.starts_sliding(tau, &y)
            };
            let r = y[4].hypot(y[5]);
            if sliding || r > self.z0() {
                self.put_on_circle(&mut y);
            }
        }
        Err(RadauError::InvalidInput(format!(
            "more than {MAX_SWITCHES} changes between sticking and sliding before t = {tau}"
        )))
    }

    /// On the circle (to 1e-9) with the slip pointing outward.
    fn starts_sliding(&self, tau: f64, y: &[f64]) -> bool {
        let z = [y[4], y[5]];
        let Ok(c) = self.coupling(tau, y, false) else {
            return false;
        };
        z[0].hypot(z[1]) >= self.z0() * (1.0 - 1e-9) && dot(z, c.v) > 0.0
    }

    fn put_on_circle(&self, y: &mut [f64]) {
        let z = self.on_circle([y[4], y[5]]);
        y[4] = z[0];
        y[5] = z[1];
    }
}

/// The equations of one mode.
struct Mode<'a> {
    sys: &'a PlanarBristle,
    sliding: bool,
}

impl OdeSystem for Mode<'_> {
    fn dim(&self) -> usize {
        6
    }

    fn rhs(&self, tau: f64, y: &[f64], dydt: &mut [f64]) {
        let Ok(c) = self.sys.coupling(tau, y, self.sliding) else {
            dydt.fill(f64::NAN);
            return;
        };
        let zd = self.sys.law.z_rate(c.z, c.v, self.sliding);
        for i in 0..2 {
            let u = Rig1DInputs {
                friction: c.force[i],
                f_ext: self.sys.f_ext[i],
                ..Rig1DInputs::default()
            };
            dydt[2 * i] = y[2 * i + 1];
            dydt[2 * i + 1] = c.axes[i].acceleration(&u);
        }
        dydt[4] = zd[0];
        dydt[5] = zd[1];
    }

    /// Stick: `|z|²/z0² − 1` (reaching the circle). Slide: `z·v` (the slip
    /// turning inward), and `|v|`-kinks need none: `σ1(|v|)` is smooth.
    fn switching_count(&self) -> usize {
        1
    }

    fn switching(&self, tau: f64, y: &[f64], g: &mut [f64]) {
        let z0 = self.sys.z0();
        g[0] = if self.sliding {
            match self.sys.coupling(tau, y, true) {
                Ok(c) => dot(c.z, c.v) / z0,
                Err(_) => 0.0,
            }
        } else {
            (y[4] * y[4] + y[5] * y[5]) / (z0 * z0) - 1.0
        };
    }
}
