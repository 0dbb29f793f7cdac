//! The quasi-static rig (m = 0, c = 0) pushing the pre-sliding bristle
//! model (Appels and Herder: a piezo pushes the block through a spring),
//! solved exactly.
//!
//! With no mass and no damper the rig is the force balance
//! `0 = k·(x_a(t) − x) + F_ext − F + F_d(t)` (docs/models.md "Rigs";
//! `rig-dynamics/src/rig1d.rs`), and the bristle force `F(ξ)` of Appels
//! and Herder is a function of the displacement ξ it is driven with
//! (`rig.x`, or `rig.x_rel = x − x_s(t)`). In the bristle's coordinate the balance is
//!
//! `ξ + F(ξ)/k = R(t)`,  `R(t) = x_a(t) + (F_ext + F_d(t))/k − x_s(t)`
//!
//! (`x_s` only for `x_rel`). `R` is the position the rig would take without
//! friction ([`Rig1D::position`] with F = 0). For motion in one direction
//! `F(ξ)` is continuous, piecewise linear and monotone, with slope
//! `n_connected·σb` that only drops as bristles disconnect, so the left side
//! is increasing and its root unique; Newton's method from the current
//! position, `ξ ← ξ + (R − ξ − F(ξ)/k)/(1 + K(ξ)/k)` with the tangent
//! stiffness `K`, never overshoots (the function is convex in the direction
//! of motion) and ends on the root's linear piece, where one more step is
//! exact. The state is advanced monotonically from root to root
//! ([`Bristle::move_to`]).
//!
//! The law is rate-independent, so only the path of `R` matters: between
//! output times the extrema of `R(t)` (sinusoidal actuator, drive force or
//! dither) are located (sign changes of `R'` on a grid of 32 points per
//! period, refined by bisection) and visited, and the instant just before
//! a drive-force step too.
//!
//! At a reversal the disconnected bristles reconnect with a force drop (the
//! paper's relaxation), so `F` jumps at the turning point and the balance
//! may have no root beyond it: the body then stays where it is until `R`
//! has travelled through the jump, the friction force being set-valued
//! there; it is reported as the balance value `k·(R − ξ)`, inside the jump.
//!
//! Velocity: differentiating the balance, `ξ' = R'/(1 + K/k)` (0 while held
//! at a reversal), and the body's `ẋ = ξ' + x_s'(t)` for `x_rel`.

use friction_laws::bristle::Bristle;
use rig_dynamics::rig1d::{Actuator, Rig1D, Rig1DInputs};

/// What drives the bristle's input `x`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BristleInput {
    /// `rig.x`.
    Position,
    /// `rig.x_rel`, x − x_s(t).
    Relative,
}

/// Rig1D with m = 0, c = 0 coupled with the bristle model.
#[derive(Clone, Debug)]
pub struct QuasiStaticBristle {
    pub rig: Rig1D,
    /// The bristle realisation at the start.
    pub bristle: Bristle,
    /// The rig's unconnected inputs at their constant values.
    pub inputs: Rig1DInputs,
    pub input: BristleInput,
}

/// The solution at one output time.
#[derive(Clone, Debug, PartialEq)]
pub struct QuasiStaticPoint {
    /// Rig time.
    pub tau: f64,
    /// The bristle's input ξ.
    pub xi: f64,
    /// Body position and velocity.
    pub x: f64,
    pub xd: f64,
    /// Friction force: `F(ξ)`, or while held at a reversal the balance
    /// value `k·(R − ξ)`, which then lies inside the jump of `F`.
    pub force: f64,
    /// Held at a reversal (the balance has no root beyond the jump).
    pub held: bool,
}

impl QuasiStaticBristle {
    fn rig_at(&self, tau: f64) -> Rig1D {
        let mut rig = self.rig.clone();
        // The quasi-static position does not depend on the stored x, ẋ.
        rig.state_from_slice(&[tau, 0.0, 0.0, 0.0])
            .expect("finite state");
        rig
    }

    fn surface(&self, rig: &Rig1D, tau: f64) -> (f64, f64) {
        match self.input {
            BristleInput::Position => (0.0, 0.0),
            BristleInput::Relative => (rig.surface_position(tau), rig.surface_velocity(tau)),
        }
    }

    /// `R(τ)`: the frictionless position in the bristle's coordinate.
    pub fn free_position(&self, tau: f64) -> f64 {
        let rig = self.rig_at(tau);
        let u = Rig1DInputs {
            friction: 0.0,
            ..self.inputs
        };
        rig.position(&u) - self.surface(&rig, tau).0
    }

    /// `R'(τ)` (away from a drive-force step).
    pub fn free_rate(&self, tau: f64) -> f64 {
        let rig = self.rig_at(tau);
        let u = Rig1DInputs {
            friction: 0.0,
            ..self.inputs
        };
        rig.position_rate(&u, &Rig1DInputs::default()) - self.surface(&rig, tau).1
    }

    /// Largest angular frequency in `R(t)` (0: `R` is linear in time).
    fn omega(&self) -> f64 {
        let p = self.rig.params();
        let mut w = p.drive.sine.active_omega();
        if p.actuator == Actuator::Prescribed {
            w = w.max(p.act_sine.active_omega());
        }
        if self.input == BristleInput::Relative {
            w = w.max(p.dither.active_omega());
        }
        w
    }

    /// Rig times in `(a, b)` at which `R` turns, increasing.
    fn turning_points(&self, a: f64, b: f64) -> Vec<f64> {
        let w = self.omega();
        let mut out = Vec::new();
        if w == 0.0 {
            return out;
        }
        let n = (((b - a) * w / (2.0 * std::f64::consts::PI) * 32.0).ceil() as usize).max(1);
        let at = |i: usize| a + (b - a) * i as f64 / n as f64;
        let mut r0 = self.free_rate(at(0));
        for i in 1..=n {
            let r1 = self.free_rate(at(i));
            if r0 * r1 < 0.0 {
                let (mut lo, mut hi, mut rlo) = (at(i - 1), at(i), r0);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if mid <= lo || mid >= hi {
                        break;
                    }
                    let rm = self.free_rate(mid);
                    if rm * rlo > 0.0 {
                        (lo, rlo) = (mid, rm);
                    } else {
                        hi = mid;
                    }
                }
                out.push(0.5 * (lo + hi));
            }
            r0 = r1;
        }
        out
    }

    /// Moves the bristle to the root of `ξ + F(ξ)/k = r` beyond its current
    /// position (see the module documentation); `true` when there is none
    /// because `r` lies in the jump at a reversal, and the bristle stays.
    pub fn settle(&self, b: &mut Bristle, r: f64) -> bool {
        let k = self.rig.params().k;
        let x0 = b.position();
        let residual = |x: f64, f: f64| r - x - f / k;
        let g0 = residual(x0, b.force());
        if g0 == 0.0 || !g0.is_finite() {
            return false;
        }
        let s = g0.signum();
        // A probe just beyond the current position shows the branch the
        // move starts on (with the reconnection jump after a reversal).
        let eps = (1e-9 * b.params().delta_max).max(8.0 * f64::EPSILON * x0.abs());
        let probe = x0 + s * eps;
        let fp = b.force_at(probe);
        let gp = residual(probe, fp);
        if gp * s <= 0.0 {
            let slope = b.stiffness_at(probe);
            let jump = fp - b.force() - slope * (probe - x0);
            if jump.abs() > 1e-9 * b.sliding_level() {
                // The root lies in the jump: the body stays.
                return true;
            }
            // No jump: the root lies within the probe distance, on the
            // first linear piece.
            b.move_to(x0 + g0 / (1.0 + slope / k));
            return false;
        }
        let mut x = probe;
        let mut gx = gp;
        for _ in 0..b.n_bristles() + 16 {
            let next = x + gx / (1.0 + b.stiffness_at(x) / k);
            if next == x {
                break;
            }
            let same_piece = b.n_connected_at(next) == b.n_connected_at(x);
            x = next;
            gx = residual(x, b.force_at(x));
            if same_piece || gx * s <= 0.0 {
                break;
            }
        }
        b.move_to(x);
        false
    }

    /// Velocity `ξ'` at the settled state for the current `R'`.
    fn xi_rate(&self, b: &Bristle, rate: f64) -> f64 {
        if rate == 0.0 {
            return 0.0;
        }
        let k = self.rig.params().k;
        let s = rate.signum();
        let x0 = b.position();
        let eps = (1e-9 * b.params().delta_max).max(8.0 * f64::EPSILON * x0.abs());
        let probe = x0 + s * eps;
        let stiffness = b.stiffness_at(probe);
        let jump = b.force_at(probe) - b.force() - stiffness * s * eps;
        if jump.abs() > 1e-9 * b.sliding_level() {
            // Held at a reversal until R has crossed the jump.
            return 0.0;
        }
        rate / (1.0 + stiffness / k)
    }

    /// The solution at the rig times `taus` (increasing, ≥ 0), each handed
    /// to `out` with the bristle at that time.
    pub fn solve(&self, taus: &[f64], mut out: impl FnMut(&QuasiStaticPoint, &Bristle)) {
        let mut b = self.bristle.clone();
        let drive = self.rig.params().drive;
        let mut prev = 0.0;
        // The initial balance.
        self.settle(&mut b, self.free_position(0.0));
        for &tau in taus {
            let mut visits = if tau > prev {
                self.turning_points(prev, tau)
            } else {
                Vec::new()
            };
            if drive.f_step != 0.0 && drive.t_step > prev && drive.t_step <= tau {
                // Just before the step, then the step itself.
                let before = drive.t_step - 4.0 * f64::EPSILON * drive.t_step.abs();
                visits.retain(|&t| t < before || t >= drive.t_step);
                visits.push(before.max(prev));
                visits.sort_by(f64::total_cmp);
            }
            for t in visits {
                self.settle(&mut b, self.free_position(t));
            }
            let r = self.free_position(tau);
            let held = self.settle(&mut b, r);
            let rig = self.rig_at(tau);
            let (xs, vs) = self.surface(&rig, tau);
            let xi = b.position();
            let point = QuasiStaticPoint {
                tau,
                xi,
                x: xi + xs,
                xd: self.xi_rate(&b, self.free_rate(tau)) + vs,
                force: if held {
                    self.rig.params().k * (r - xi)
                } else {
                    b.force()
                },
                held,
            };
            out(&point, &b);
            prev = tau;
        }
    }
}
