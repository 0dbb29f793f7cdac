//! Elasto-plastic friction (Dupont, Hayward, Armstrong, Altpeter 2002;
//! docs/models.md "Elasto-plastic").
//!
//! LuGre's bristle with a factor `α(z, v)` on its plastic term:
//!
//! `ż = v − α(z, v)·σ0·|v|·z/g(v)`, `F = σ0·z + σ1·ż + σ2·v`,
//! `g(v) = Fc + (Fs − Fc)·e^(−|v/vs|^δ)`.
//!
//! With `w = sgn(v)·z` (the deflection in the direction of motion) and
//! `w_ss = g(v)/σ0` (its steady state), `α = 0` while `w ≤ z_ba` (the
//! break-away deflection: the contact is purely elastic, `ż = v`, which
//! includes every motion that unloads it, `sgn v ≠ sgn z`), `α = 1` for
//! `w ≥ w_ss` (LuGre), and between them
//! `α = ½·sin(π·(w − (w_ss + z_ba)/2)/(w_ss − z_ba)) + ½`,
//! which joins both ends with zero slope. Below break-away the law has true
//! stiction: a force that oscillates under `σ0·z_ba` moves the contact
//! back and forth elastically and never lets it creep, where LuGre drifts
//! a little at every cycle (Dupont et al. 2002).
//!
//! [`ElastoPlastic::step`] integrates in displacement. For a velocity
//! held over a piece, `w` obeys `dw/du = 1 − α(w)·w/w_ss` in the distance
//! `u` travelled: exactly `w + u` in the elastic zone, exactly
//! `w_ss + (w − w_ss)·e^(−u/w_ss)` at or beyond `w_ss`, and by an embedded
//! Runge–Kutta pair (Dormand and Prince 1980) under a tolerance of 1e-13
//! of `w_ss` in the transition zone, whose entry at `z_ba` is located
//! exactly. A ramped velocity is taken as held at its midpoint over
//! sub-steps short enough that it changes by at most 1e-3 of `|v| + vs`,
//! at most 1000 of them (the displacement of each stays exact; the
//! steady state moving within a sub-step is an error of second order in
//! its length, about 1e-7 of `Fs/σ0` over a step in the tests).

use crate::error::{require_non_negative, require_positive};
use crate::interval::{displacement, each_held_substep};
use crate::state::one_value_state;
use crate::{ParamError, Ramp};
use std::f64::consts::PI;

/// Elasto-plastic parameters: LuGre's (`sigma0` N/m, `sigma1` N·s/m,
/// `sigma2` N·s/m, `fc`, `fs` N, `vs` m/s, `delta` the Stribeck exponent)
/// and the break-away deflection `z_ba` (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElastoPlasticParams {
    pub sigma0: f64,
    pub sigma1: f64,
    pub sigma2: f64,
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub delta: f64,
    pub z_ba: f64,
}

impl Default for ElastoPlasticParams {
    /// LuGre's benchmark set (Canudas de Wit et al. 1995: σ0 = 1e5 N/m,
    /// σ1 = √1e5 N·s/m, σ2 = 0.4 N·s/m, Fc = 1 N, Fs = 1.5 N,
    /// vs = 1e-3 m/s, δ = 2) with `z_ba = 0.95·Fc/σ0 = 9.5e-6 m` (ours):
    /// elastic up to 95 % of the Coulomb level.
    fn default() -> Self {
        ElastoPlasticParams {
            sigma0: 1e5,
            sigma1: 1e5_f64.sqrt(),
            sigma2: 0.4,
            fc: 1.0,
            fs: 1.5,
            vs: 1e-3,
            delta: 2.0,
            z_ba: 9.5e-6,
        }
    }
}

impl ElastoPlasticParams {
    /// LuGre's rules (σ0, Fc, vs, δ > 0; σ1, σ2 ≥ 0; Fs ≥ Fc) and
    /// `0 ≤ z_ba < Fc/σ0`: break-away before the smallest steady-state
    /// deflection, so that the transition zone is never empty.
    pub fn validate(&self) -> Result<(), ParamError> {
        require_positive("sigma0", self.sigma0)?;
        require_non_negative("sigma1", self.sigma1)?;
        require_non_negative("sigma2", self.sigma2)?;
        require_positive("Fc", self.fc)?;
        require_positive("Fs", self.fs)?;
        if self.fs < self.fc {
            return Err(ParamError::new(
                "Fs",
                self.fs,
                format!("must be >= Fc = {}", self.fc),
            ));
        }
        require_positive("vs", self.vs)?;
        require_positive("stribeck_exponent", self.delta)?;
        require_non_negative("z_ba", self.z_ba)?;
        let most = self.fs / self.sigma0;
        if !most.is_finite() {
            return Err(ParamError::new(
                "sigma0",
                self.sigma0,
                format!("too small: Fs/sigma0 = {most} (the largest deflection) is not finite"),
            ));
        }
        let least = self.fc / self.sigma0;
        if self.z_ba >= least {
            return Err(ParamError::new(
                "z_ba",
                self.z_ba,
                format!("must be < Fc/sigma0 = {least} (the smallest steady-state deflection)"),
            ));
        }
        Ok(())
    }
}

/// Elasto-plastic state: the bristle deflection `z` (m).
#[derive(Clone, Debug)]
pub struct ElastoPlastic {
    p: ElastoPlasticParams,
    z: f64,
}

/// Tolerance of the Runge–Kutta pair, relative to `w_ss`.
const TOLERANCE: f64 = 1e-13;
/// The shortest step of the pair, relative to `w_ss`: a floor that only a
/// transition zone narrower than about 1e-9 of `w_ss` reaches (`z_ba`
/// within 1e-9 of `Fc/σ0`); there the step is taken with a larger error
/// rather than cut without end.
const MIN_SCALED_STEP: f64 = 1e-12;

impl ElastoPlastic {
    /// A relaxed contact (`z = 0`) with validated parameters.
    pub fn new(p: ElastoPlasticParams) -> Result<Self, ParamError> {
        p.validate()?;
        Ok(ElastoPlastic { p, z: 0.0 })
    }

    pub fn params(&self) -> &ElastoPlasticParams {
        &self.p
    }

    pub fn z(&self) -> f64 {
        self.z
    }

    /// The Stribeck level `g(v) = Fc + (Fs − Fc)·e^(−|v/vs|^δ)`.
    pub fn level(&self, v: f64) -> f64 {
        let p = &self.p;
        p.fc + (p.fs - p.fc) * (-(v.abs() / p.vs).powf(p.delta)).exp()
    }

    /// `dg/dv`.
    fn level_slope(&self, v: f64) -> f64 {
        let p = &self.p;
        if v == 0.0 {
            return 0.0;
        }
        let r = v.abs() / p.vs;
        -(p.fs - p.fc) * (-r.powf(p.delta)).exp() * p.delta * r.powf(p.delta - 1.0) / p.vs
            * v.signum()
    }

    /// `α` and `∂α/∂w`, `∂α/∂w_ss` at the deflection `w` in the direction
    /// of motion, for the steady state `w_ss`.
    fn alpha_parts(&self, w: f64, w_ss: f64) -> (f64, f64, f64) {
        let z_ba = self.p.z_ba;
        if w <= z_ba {
            (0.0, 0.0, 0.0)
        } else if w >= w_ss {
            (1.0, 0.0, 0.0)
        } else {
            let span = w_ss - z_ba;
            let theta = PI * (w - 0.5 * (w_ss + z_ba)) / span;
            let half_cos = 0.5 * theta.cos();
            (
                0.5 * theta.sin() + 0.5,
                half_cos * PI / span,
                half_cos * PI * (z_ba - w) / (span * span),
            )
        }
    }

    /// `α(z, v)` (Dupont et al. 2002): 0 at rest and while unloading.
    pub fn alpha(&self, z: f64, v: f64) -> f64 {
        if v == 0.0 {
            return 0.0;
        }
        self.alpha_parts(v.signum() * z, self.level(v) / self.p.sigma0)
            .0
    }

    /// The state equation `ż = v − α(z, v)·σ0·|v|·z/g(v)`.
    pub fn z_rate(&self, z: f64, v: f64) -> f64 {
        if v == 0.0 {
            return 0.0;
        }
        v - self.alpha(z, v) * self.p.sigma0 * v.abs() * z / self.level(v)
    }

    /// `(∂ż/∂z, ∂ż/∂v)` in closed form; at `v = 0` (a kink) the mean of
    /// the one-sided slopes `1 ∓ α(z, 0±)·σ0·z/Fs`.
    pub fn z_rate_partials(&self, z: f64, v: f64) -> (f64, f64) {
        let p = &self.p;
        if v == 0.0 {
            let w_ss = p.fs / p.sigma0;
            let forward = self.alpha_parts(z, w_ss).0;
            let backward = self.alpha_parts(-z, w_ss).0;
            return (0.0, 1.0 + 0.5 * (backward - forward) * p.sigma0 * z / p.fs);
        }
        let s = v.signum();
        let g = self.level(v);
        let dg = self.level_slope(v);
        let w_ss = g / p.sigma0;
        let (alpha, da_dw, da_dwss) = self.alpha_parts(s * z, w_ss);
        let k = p.sigma0 * v.abs() / g;
        let by_z = -k * (alpha + z * s * da_dw);
        // α(s·z, g(v)/σ0)·σ0·|v|·z/g(v), differentiated in v
        let by_v = 1.0 - (da_dwss * dg / p.sigma0) * k * z - alpha * p.sigma0 * s * z / g
            + alpha * p.sigma0 * v.abs() * z * dg / (g * g);
        (by_z, by_v)
    }

    /// `F = σ0·z + σ1·ż + σ2·v` at the current state.
    pub fn force(&self, v: f64) -> f64 {
        self.force_of(self.z, v)
    }

    /// The output equation for any state.
    pub fn force_of(&self, z: f64, v: f64) -> f64 {
        let p = &self.p;
        p.sigma0 * z + p.sigma1 * self.z_rate(z, v) + p.sigma2 * v
    }

    /// Whether the contact is elastic (`α = 0`: sticking, `ż = v`).
    pub fn elastic(&self, v: f64) -> bool {
        self.alpha(self.z, v) == 0.0
    }

    /// The elastic energy of the bristle, `σ0·z²/2` (J).
    pub fn stored_energy(&self) -> f64 {
        0.5 * self.p.sigma0 * self.z * self.z
    }

    /// `P_diss = F·v − σ0·z·ż` (W): `α·σ0²·|v|·z²/g + σ1·ż·v + σ2·v²`.
    pub fn dissipated_power(&self, v: f64) -> f64 {
        self.force(v) * v - self.p.sigma0 * self.z * self.z_rate(self.z, v)
    }

    /// Advances over `[0, h]` with `v(τ) = v.value + v.slope·τ` (the
    /// module's documentation).
    pub fn step(&mut self, v: Ramp, h: f64) {
        each_held_substep(v, h, self.p.vs, |s, t0, t1| {
            let u = displacement(v, t0, t1).abs();
            let w_ss = self.level(v.at(0.5 * (t0 + t1))) / self.p.sigma0;
            self.z = s * self.advance(s * self.z, u, w_ss);
        });
    }

    /// `w` after the distance `u` at the held steady state `w_ss`.
    fn advance(&self, mut w: f64, mut u: f64, w_ss: f64) -> f64 {
        let z_ba = self.p.z_ba;
        if w < z_ba {
            // elastic: dw/du = 1, up to the break-away deflection
            let room = z_ba - w;
            if u <= room {
                return w + u;
            }
            w = z_ba;
            u -= room;
        }
        if w >= w_ss {
            // plastic (α = 1): LuGre's exact relaxation
            return w_ss + (w - w_ss) * (-u / w_ss).exp();
        }
        self.transition(w, u, w_ss)
    }

    /// `dw/du = 1 − α(w)·w/w_ss` across the transition zone
    /// `z_ba ≤ w < w_ss` by the Dormand–Prince 5(4) pair with step
    /// control, in the scaled deflection `r = w/w_ss` and distance
    /// `s = u/w_ss`: `dr/ds = 1 − α̂(r)·r`, with
    /// `α̂ = ½·sin(π·(r − (1 + b)/2)/(1 − b)) + ½` and `b = z_ba/w_ss`,
    /// the same on every scale (a `w_ss` of 1e-300 m integrates as
    /// 1e-3 m does). `r` rises towards 1, where `α̂` reaches 1 to rounding
    /// (about 1e-8 of the zone's width below it): from there on the
    /// relaxation is LuGre's, exact. (Integrating on, the pair's step
    /// grows to its stability limit and `r` hovers near 1 - 4e-14 without
    /// settling.) A step the
    /// control would cut below `MIN_SCALED_STEP` is taken as it is, so the
    /// loop always advances.
    fn transition(&self, w: f64, u: f64, w_ss: f64) -> f64 {
        let b = self.p.z_ba / w_ss;
        let span = 1.0 - b;
        let alpha = |r: f64| {
            if r <= b {
                0.0
            } else if r >= 1.0 {
                1.0
            } else {
                0.5 * (PI * (r - 0.5 * (1.0 + b)) / span).sin() + 0.5
            }
        };
        let f = |r: f64| 1.0 - alpha(r) * r;
        let length = u / w_ss;
        let mut r = w / w_ss;
        let mut done = 0.0;
        let mut ds = (0.05 * span).min(length);
        while done < length {
            if alpha(r) == 1.0 {
                // α is 1 to rounding from here on (it rises with r):
                // LuGre's exact relaxation, as in the plastic zone
                return w_ss * (1.0 - (1.0 - r) * (-(length - done)).exp());
            }
            ds = ds.min(length - done).max(MIN_SCALED_STEP);
            let k1 = f(r);
            let k2 = f(r + ds * (1.0 / 5.0) * k1);
            let k3 = f(r + ds * (3.0 / 40.0 * k1 + 9.0 / 40.0 * k2));
            let k4 = f(r + ds * (44.0 / 45.0 * k1 - 56.0 / 15.0 * k2 + 32.0 / 9.0 * k3));
            let k5 = f(r + ds
                * (19372.0 / 6561.0 * k1 - 25360.0 / 2187.0 * k2 + 64448.0 / 6561.0 * k3
                    - 212.0 / 729.0 * k4));
            let k6 = f(r + ds
                * (9017.0 / 3168.0 * k1 - 355.0 / 33.0 * k2
                    + 46732.0 / 5247.0 * k3
                    + 49.0 / 176.0 * k4
                    - 5103.0 / 18656.0 * k5));
            let next = r + ds
                * (35.0 / 384.0 * k1 + 500.0 / 1113.0 * k3 + 125.0 / 192.0 * k4
                    - 2187.0 / 6784.0 * k5
                    + 11.0 / 84.0 * k6);
            let k7 = f(next);
            let error = ds
                * (71.0 / 57600.0 * k1 - 71.0 / 16695.0 * k3 + 71.0 / 1920.0 * k4
                    - 17253.0 / 339200.0 * k5
                    + 22.0 / 525.0 * k6
                    - 1.0 / 40.0 * k7)
                    .abs();
            if error <= TOLERANCE || ds <= MIN_SCALED_STEP {
                done += ds;
                r = next.min(1.0);
            }
            let scale = if error == 0.0 {
                5.0
            } else if error.is_finite() {
                (0.9 * (TOLERANCE / error).powf(0.2)).clamp(0.2, 5.0)
            } else {
                0.2
            };
            ds *= scale;
        }
        r * w_ss
    }

    one_value_state!("ElastoPlastic", "z", z);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law() -> ElastoPlastic {
        ElastoPlastic::new(ElastoPlasticParams::default()).unwrap()
    }

    #[test]
    fn validation_names_the_parameter() {
        let p = ElastoPlasticParams::default();
        let e = ElastoPlastic::new(ElastoPlasticParams { z_ba: 1e-5, ..p }).unwrap_err();
        assert_eq!(e.name, "z_ba");
        assert!(e.rule.contains("Fc/sigma0 = 0.00001"), "{e}");
        assert_eq!(
            ElastoPlastic::new(ElastoPlasticParams { fs: 0.5, ..p })
                .unwrap_err()
                .name,
            "Fs"
        );
        assert_eq!(
            ElastoPlastic::new(ElastoPlasticParams { z_ba: -1.0, ..p })
                .unwrap_err()
                .name,
            "z_ba"
        );
    }

    /// α: 0 up to z_ba and while unloading, 1 from w_ss on, the sine
    /// between with its midpoint value ½ halfway.
    #[test]
    fn alpha_is_dupont_et_al_s() {
        let l = law();
        let p = *l.params();
        let v = 2e-3;
        let w_ss = l.level(v) / p.sigma0;
        assert_eq!(l.alpha(0.5 * p.z_ba, v), 0.0);
        assert_eq!(l.alpha(p.z_ba, v), 0.0);
        assert_eq!(l.alpha(-0.9 * w_ss, v), 0.0);
        assert_eq!(l.alpha(0.9 * w_ss, -v), 0.0);
        assert_eq!(l.alpha(w_ss, v), 1.0);
        assert_eq!(l.alpha(-1.2 * w_ss, -v), 1.0);
        let mid = 0.5 * (w_ss + p.z_ba);
        assert!((l.alpha(mid, v) - 0.5).abs() < 1e-15);
        assert!((l.alpha(-mid, -v) - 0.5).abs() < 1e-15);
    }

    /// Below break-away the step is exactly elastic: z moves with x.
    #[test]
    fn below_break_away_the_contact_is_elastic() {
        let mut l = law();
        for (v, h) in [(1e-3, 5e-3), (-2e-3, 4e-3), (5e-4, 1e-2)] {
            let z = l.z();
            l.step(Ramp::constant(v), h);
            assert!(
                (l.z() - (z + v * h)).abs() < 1e-20,
                "{} vs {}",
                l.z(),
                z + v * h
            );
            assert!(l.elastic(v));
        }
    }

    /// A fine RK4 in time of `ż = v − α·σ0·|v|·z/g` from the same start.
    fn reference(l: &ElastoPlastic, z0: f64, v: Ramp, h: f64, n: usize) -> f64 {
        let mut z = z0;
        let dt = h / n as f64;
        for k in 0..n {
            let t = k as f64 * dt;
            let f = |t: f64, z: f64| l.z_rate(z, v.at(t));
            let k1 = f(t, z);
            let k2 = f(t + 0.5 * dt, z + 0.5 * dt * k1);
            let k3 = f(t + 0.5 * dt, z + 0.5 * dt * k2);
            let k4 = f(t + dt, z + dt * k3);
            z += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        z
    }

    /// Through every zone in one step, held and ramped, both directions:
    /// the step equals a fine RK4 in time, to 1e-9 of `Fs/σ0` for a held
    /// velocity and 1e-6 for a ramped one: held at its midpoint over each
    /// sub-step, the steady state `w_ss` moves within it, an error of
    /// second order in the sub-step (measured: 1.1e-8 and 3.0e-7 of
    /// `Fs/σ0` here, where the 1000 sub-steps are the limit).
    #[test]
    fn steps_match_a_fine_reference_through_every_zone() {
        let p = ElastoPlasticParams::default();
        for (z0, v, h) in [
            (0.0, Ramp::constant(1e-3), 2e-2),
            (-8e-6, Ramp::constant(2e-4), 0.1),
            (1.2e-5, Ramp::constant(5e-3), 1e-2),
            (5e-6, Ramp::new(1e-4, 0.2), 2e-2),
            (0.0, Ramp::new(-3e-3, 0.1), 2e-2),
        ] {
            let mut l = law();
            l.state_from_slice(&[z0]).unwrap();
            let expected = reference(&l, z0, v, h, 400_000);
            l.step(v, h);
            let tolerance = if v.slope == 0.0 { 1e-9 } else { 1e-6 };
            assert!(
                (l.z() - expected).abs() < tolerance * p.fs / p.sigma0,
                "from {z0} at {v:?}: {} vs {expected}",
                l.z()
            );
        }
    }

    /// At constant velocity the force settles on the Stribeck curve, for
    /// any step size.
    /// Steps end, and end in the zone, on every scale: a steady
    /// deflection of 1e-300 m, a transition zone 1e-14 of it wide, a
    /// distance of 1e300 m (the fuzzed FMU once looped here: the
    /// unscaled step control underflowed to a zero step).
    #[test]
    fn steps_end_on_extreme_scales() {
        for (sigma0, z_ba_fraction) in [
            (1e300, 0.0),
            (1e300, 0.5),
            (1e5, 1.0 - 1e-14),
            (1e-290, 0.3),
        ] {
            let fc = 1.0;
            let p = ElastoPlasticParams {
                sigma0,
                z_ba: z_ba_fraction * fc / sigma0,
                ..Default::default()
            };
            let mut l = ElastoPlastic::new(p).unwrap();
            let w_ss = l.level(1e-3) / sigma0;
            for (v, h) in [(1e-3, 1e-12), (1e-3, 1.0), (1e300, 1.0), (-1e-3, 0.5)] {
                l.step(Ramp::constant(v), h);
                assert!(
                    l.z().is_finite() && l.z().abs() <= 1.5 * fc / sigma0,
                    "{p:?}: {}",
                    l.z()
                );
            }
            // 100 steady deflections further on, at the steady state
            l.step(Ramp::constant(1e-3), 100.0 * w_ss / 1e-3);
            assert!(
                (l.z() - w_ss).abs() <= 1e-12 * w_ss,
                "{p:?}: {} vs {w_ss}",
                l.z()
            );
        }
        let p = ElastoPlasticParams {
            sigma0: 1e-310,
            ..Default::default()
        };
        assert!(p.validate().is_err());
    }

    #[test]
    fn steady_state_is_the_stribeck_curve() {
        for v in [1e-4_f64, -5e-4, 2e-3, -1e-2] {
            for n in [1, 10, 1000] {
                let mut l = law();
                let h = 5e-3 / v.abs() / n as f64;
                for _ in 0..n {
                    l.step(Ramp::constant(v), h);
                }
                let p = l.params();
                let expected = v.signum() * l.level(v) + p.sigma2 * v;
                assert!(
                    (l.force(v) - expected).abs() < 1e-12,
                    "{v}, {n}: {}",
                    l.force(v)
                );
            }
        }
    }

    #[test]
    fn partials_match_differences() {
        let l = law();
        for (z, v) in [
            (3e-6, 1e-3),
            (9.8e-6, 1e-3),
            (1.1e-5, 4e-4),
            (-1.05e-5, -2e-3),
            (1.2e-5, 3e-3),
            (6e-6, 0.0),
        ] {
            let (by_z, by_v) = l.z_rate_partials(z, v);
            let ez = 1e-12;
            let fz = (l.z_rate(z + ez, v) - l.z_rate(z - ez, v)) / (2.0 * ez);
            let ev = 1e-10;
            let fv = (l.z_rate(z, v + ev) - l.z_rate(z, v - ev)) / (2.0 * ev);
            assert!(
                (fz - by_z).abs() <= 1e-5 * by_z.abs().max(1.0),
                "{z}, {v}: {fz} vs {by_z}"
            );
            assert!(
                (fv - by_v).abs() <= 1e-5 * by_v.abs().max(1.0),
                "{z}, {v}: {fv} vs {by_v}"
            );
        }
    }
}
