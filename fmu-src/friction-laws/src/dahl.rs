//! Dahl friction (Dahl 1968; Sun et al. 2016 eq. 2–3 and 16–17;
//! Thimmalapura 2004 eq. 2.4–2.5; docs/models.md "Dahl").
//!
//! `dF/dx = σ·|1 − (F/Fc)·sgn v|^α · sgn(1 − (F/Fc)·sgn v)`, `dF/dt = (dF/dx)·v`.
//!
//! The law is rate-independent, so it is integrated in the displacement
//! domain: over an interval on which `v` keeps one sign `s`, the increment
//! `Δx = ∫ v dt` is exact for a ramped `v`, and with `y = 1 − F·s/Fc`,
//! `u = |Δx|`, the ODE `d|y|/du = −(σ/Fc)·|y|^α` (sign of `y` preserved) has
//! the closed-form solution used by [`Dahl::step`] for every `α > 0`.
//!
//! `F_offset` is a constant force on the contact (0 by default), which
//! acts at rest as in motion: the output is `F = F_dahl + F_offset`, with
//! `F_dahl` the state of the law above (the `F` of Dahl 1968). The law
//! does not see it: the levels it saturates at become `F_offset ± Fc`.
//! The same term as LuGre's offset (Janot, Gautier, Brunot 2019).

use crate::error::{require_finite, require_positive};
use crate::interval::each_one_sign_displacement;
use crate::state::one_value_state;
use crate::{ParamError, Ramp};

/// Dahl parameters: rest stiffness `sigma` (N/m), Coulomb level `fc` (N),
/// shape exponent `alpha` (–), constant offset force `f_offset` (N).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DahlParams {
    pub sigma: f64,
    pub fc: f64,
    pub alpha: f64,
    /// Constant force added to the output, at rest and in motion (0: none).
    pub f_offset: f64,
}

impl Default for DahlParams {
    /// Sun et al. 2016, Table 7 (nominal): σ = 87 750 N/m, Fc = 2.0 N, α = 1.
    fn default() -> Self {
        DahlParams {
            sigma: 87_750.0,
            fc: 2.0,
            alpha: 1.0,
            f_offset: 0.0,
        }
    }
}

impl DahlParams {
    /// `sigma`, `Fc` and `alpha` must be finite and > 0, `F_offset`
    /// finite (any sign).
    pub fn validate(&self) -> Result<(), ParamError> {
        require_positive("sigma", self.sigma)?;
        require_positive("Fc", self.fc)?;
        require_positive("alpha", self.alpha)?;
        require_finite("F_offset", self.f_offset)?;
        Ok(())
    }
}

/// Dahl friction state: the force of the law `F_dahl` (N), without the
/// offset.
#[derive(Clone, Debug)]
pub struct Dahl {
    p: DahlParams,
    f: f64,
}

impl Dahl {
    /// A relaxed contact (`F_dahl = 0`, so `F = F_offset`) with validated
    /// parameters.
    pub fn new(p: DahlParams) -> Result<Self, ParamError> {
        p.validate()?;
        Ok(Dahl { p, f: 0.0 })
    }

    pub fn params(&self) -> &DahlParams {
        &self.p
    }

    /// The friction force `F = F_dahl + F_offset` (Dahl has no direct
    /// feedthrough).
    #[inline]
    pub fn force(&self) -> f64 {
        self.force_of(self.f)
    }

    /// The force of the law `F_dahl`: the state, without the offset.
    #[inline]
    pub fn dahl_force(&self) -> f64 {
        self.f
    }

    /// The friction force for the state `f_dahl`: `f_dahl + F_offset`
    /// (the output equation, for integrating the law with other
    /// equations).
    #[inline]
    pub fn force_of(&self, f_dahl: f64) -> f64 {
        f_dahl + self.p.f_offset
    }

    /// The elastic energy held in the contact, `F_dahl²/(2·σ)` (J): the
    /// energy of a spring of the rest stiffness σ carrying `F_dahl`.
    pub fn stored_energy(&self) -> f64 {
        0.5 * self.f * self.f / self.p.sigma
    }

    /// `P_diss = F·v − dE/dt = F·v − F_dahl·Ḟ_dahl/σ` (W), which is
    /// `F_dahl·v·(1 − |y|^α·sgn y) + F_offset·v` with
    /// `y = 1 − F_dahl/Fc·sgn v`: the law's part is never negative (it
    /// loads when `|y| < 1` and unloads when `y > 1`); the offset's
    /// `F_offset·v` has the sign of the motion.
    pub fn dissipated_power(&self, v: f64) -> f64 {
        self.force() * v - self.f * self.force_rate(self.f, v) / self.p.sigma
    }

    /// Equivalent bristle deflection `z = F_dahl/σ` (m).
    pub fn z(&self) -> f64 {
        self.f / self.p.sigma
    }

    /// The right-hand side of the law in time for any state `f`
    /// (`F_dahl`, without the offset):
    /// `dF/dt = σ·|1 − (F/Fc)·sgn v|^α·sgn(1 − (F/Fc)·sgn v)·v` (Sun et al.
    /// 2016 eq. 2–3; docs/models.md "Dahl"); the offset being constant,
    /// also the rate of the output. A pure function, for
    /// integrating the law together with other equations (the monolithic
    /// reference solutions); [`Dahl::step`] integrates it exactly in
    /// displacement instead.
    pub fn force_rate(&self, f: f64, v: f64) -> f64 {
        if v == 0.0 {
            return 0.0;
        }
        let y = 1.0 - f / self.p.fc * v.signum();
        self.p.sigma * self.shape(y) * v
    }

    /// `|y|^α·sgn(y)`, the shape of the law (`y` itself for α = 1).
    #[inline]
    fn shape(&self, y: f64) -> f64 {
        if self.p.alpha == 1.0 {
            y
        } else {
            y.abs().powf(self.p.alpha) * y.signum()
        }
    }

    /// The partial derivatives `(∂Ḟ/∂F, ∂Ḟ/∂v)` of [`Dahl::force_rate`]
    /// at `(f, v)` (`f` the state `F_dahl`; the offset, constant, changes
    /// neither), in closed form: with `s = sgn v`, `y = 1 − F·s/Fc`,
    /// `Ḟ = σ·|y|^α·sgn(y)·v`, so `∂Ḟ/∂F = −σ·α·|y|^(α−1)·|v|/Fc` and,
    /// `y` being constant in `v` for one sign, `∂Ḟ/∂v = σ·|y|^α·sgn(y)`.
    /// At `v = 0` the rate is 0 for every `F` (`∂Ḟ/∂F = 0`) and has a kink
    /// in `v` (`y` jumps from `1 + F/Fc` to `1 − F/Fc`): `∂Ḟ/∂v` is the
    /// mean of the two one-sided slopes, the limit of central
    /// differences. For α < 1 at `y = 0` (sliding, reached in finite
    /// distance) `∂Ḟ/∂F` is infinite.
    pub fn force_rate_partials(&self, f: f64, v: f64) -> (f64, f64) {
        let p = &self.p;
        if v == 0.0 {
            let forward = p.sigma * self.shape(1.0 - f / p.fc);
            let backward = p.sigma * self.shape(1.0 + f / p.fc);
            return (0.0, 0.5 * (forward + backward));
        }
        let y = 1.0 - f / p.fc * v.signum();
        let slope = if p.alpha == 1.0 {
            1.0
        } else {
            p.alpha * y.abs().powf(p.alpha - 1.0)
        };
        (-p.sigma * slope * v.abs() / p.fc, p.sigma * self.shape(y))
    }

    /// `true` when moving (`v ≠ 0`) with `sgn(v)·F_dahl ≥ 0.99·Fc`.
    pub fn sliding(&self, v: f64) -> bool {
        v != 0.0 && v.signum() * self.f >= 0.99 * self.p.fc
    }

    /// Advances over `[0, h]` with velocity `v(τ) = v.value + v.slope·τ`.
    /// The step is split at the zero crossing of `v`; on each one-sign piece
    /// the displacement `Δx` is exact and the update
    /// (`y = 1 − F·s/Fc`, `u = |Δx|`, `k = σu/Fc`):
    /// - α = 1: `|y| ← |y|·e^(−k)`,
    /// - α < 1: `|y| ← (|y|^(1−α) − (1−α)k)^(1/(1−α))`, clamped at 0,
    /// - α > 1: `|y| ← (|y|^(1−α) + (α−1)k)^(−1/(α−1))`,
    ///
    /// is the exact solution of `d|y|/du = −(σ/Fc)|y|^α`, evaluated in
    /// increment form (`expm1`/`ln_1p`) so small steps lose no digits.
    pub fn step(&mut self, v: Ramp, h: f64) {
        let p = self.p;
        let f = &mut self.f;
        each_one_sign_displacement(v, h, |s, u| *f = advance(&p, *f, s, u));
    }

    // The state: the force of the law F_dahl, any finite value.
    one_value_state!("Dahl", "F_dahl", f);
}

/// Exact Dahl update of `F_dahl` over a displacement `u ≥ 0` in direction `s = ±1`.
fn advance(p: &DahlParams, f: f64, s: f64, u: f64) -> f64 {
    let y = 1.0 - f * s / p.fc;
    if y == 0.0 || u <= 0.0 {
        return f;
    }
    let ay = y.abs();
    let k = p.sigma * u / p.fc;
    let a = p.alpha;
    // Increment of |y| (≤ 0).
    let d_ay = if a == 1.0 {
        ay * (-k).exp_m1()
    } else if a < 1.0 {
        let c = (1.0 - a) * k * ay.powf(a - 1.0);
        if c >= 1.0 {
            -ay
        } else {
            ay * ((-c).ln_1p() / (1.0 - a)).exp_m1()
        }
    } else {
        let c = (a - 1.0) * k * ay.powf(a - 1.0);
        ay * (-c.ln_1p() / (a - 1.0)).exp_m1()
    };
    if d_ay.is_nan() || d_ay <= -ay {
        // Reached y = 0 (or underflowed there): fully developed sliding.
        return s * p.fc;
    }
    f - s * p.fc * y.signum() * d_ay
}

#[cfg(test)]
mod tests {
    use super::*;

    fn closed_form(p: &DahlParams, x: f64) -> f64 {
        p.fc * -(-p.sigma * x / p.fc).exp_m1()
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(1e-300)
    }

    #[test]
    fn defaults_are_sun_2016_table_7_and_validation_names_the_parameter() {
        let p = DahlParams::default();
        assert_eq!((p.sigma, p.fc, p.alpha), (87_750.0, 2.0, 1.0));
        let e = Dahl::new(DahlParams { fc: -1.0, ..p }).unwrap_err();
        assert_eq!(e.name, "Fc");
        assert!(Dahl::new(DahlParams { alpha: 0.0, ..p }).is_err());
        assert!(Dahl::new(DahlParams {
            sigma: f64::NAN,
            ..p
        })
        .is_err());
    }

    /// The offset shifts the output and nothing else: driven alike, a law
    /// with `F_offset = c` has the state of one without, bit for bit, and
    /// the force `F_dahl + c`, at rest (`F = c` relaxed, `F_dahl + c` once
    /// loaded and stopped) as in motion, for every α and both directions;
    /// the rate, its partials and `sliding` are those of the state. A
    /// non-finite offset is refused, named.
    #[test]
    fn offset_shifts_the_force_and_leaves_the_law_alone() {
        assert_eq!(DahlParams::default().f_offset, 0.0);
        for alpha in [0.5, 1.0, 2.5] {
            let plain = DahlParams {
                alpha,
                ..DahlParams::default()
            };
            for c in [-0.7, 3.1648] {
                let p = DahlParams {
                    f_offset: c,
                    ..plain
                };
                let mut a = Dahl::new(p).unwrap();
                let mut b = Dahl::new(plain).unwrap();
                // relaxed at rest: the offset alone
                assert_eq!((a.force(), a.dahl_force()), (c, 0.0));
                let x_sat = 4.0 * p.fc / p.sigma;
                for (v, h) in [
                    (Ramp::constant(1e-3), 0.3 * x_sat / 1e-3),
                    (Ramp::new(2e-3, -5e-3), 1.0),
                    (Ramp::constant(0.0), 0.5),
                    (Ramp::constant(-1e-4), 10.0 * x_sat / 1e-4),
                ] {
                    a.step(v, h);
                    b.step(v, h);
                    assert_eq!(a.dahl_force().to_bits(), b.force().to_bits());
                    assert_eq!(a.force(), b.force() + c, "alpha {alpha}, c {c}");
                    assert_eq!(a.force_of(a.dahl_force()), a.force());
                    assert_eq!(a.z(), b.z());
                    for w in [-1e-3, 0.0, 2e-3] {
                        assert_eq!(a.sliding(w), b.sliding(w));
                        let f = a.dahl_force();
                        assert_eq!(a.force_rate(f, w), b.force_rate(f, w));
                        assert_eq!(a.force_rate_partials(f, w), b.force_rate_partials(f, w));
                    }
                }
                // saturated backward (α ≤ 1 gets there within the
                // distance; α > 1 only approaches it): the level -Fc moved
                // by the offset
                if alpha <= 1.0 {
                    assert!((a.force() - (c - p.fc)).abs() < 1e-12 * p.fc);
                    assert!(a.sliding(-1.0));
                }
                // stopped, loaded: state plus offset, and it stays there
                a.state_from_slice(&[0.8]).unwrap();
                a.step(Ramp::constant(0.0), 1.0);
                assert_eq!(a.force(), 0.8 + c);
            }
        }
        for offset in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let e = Dahl::new(DahlParams {
                f_offset: offset,
                ..DahlParams::default()
            })
            .unwrap_err();
            assert_eq!(e.name, "F_offset");
            assert!(e.to_string().contains("F_offset"), "{e}");
        }
    }

    #[test]
    fn constant_velocity_follows_the_closed_form_for_any_step() {
        let p = DahlParams::default();
        let x_end = 5.0 * p.fc / p.sigma;
        for &h in &[1e-7, 1e-5, 1e-3, 1e-1, 1.0] {
            for &n in &[37usize, 2000] {
                let v = x_end / (n as f64 * h);
                let mut d = Dahl::new(p).unwrap();
                for k in 1..=n {
                    d.step(Ramp::constant(v), h);
                    let x = v * h * k as f64;
                    let e = rel(d.force(), closed_form(&p, x));
                    assert!(e < 1e-9, "h {h} n {n} k {k}: rel err {e}");
                }
            }
        }
        // Many tiny steps: 1e5 steps of 1e-7 s.
        let mut d = Dahl::new(p).unwrap();
        let v = 1e-3;
        for k in 1..=100_000u32 {
            d.step(Ramp::constant(v), 1e-7);
            if k % 997 == 0 {
                let x = v * 1e-7 * f64::from(k);
                assert!(rel(d.force(), closed_form(&p, x)) < 1e-9);
            }
        }
    }

    #[test]
    fn ramped_velocity_follows_the_closed_form() {
        let p = DahlParams::default();
        for &h in &[1e-7, 1e-4, 1e-2, 1.0] {
            let n = 500;
            let t_end = n as f64 * h;
            // x(t) = a t²/2 reaches 4 Fc/σ at t_end.
            let a = 2.0 * 4.0 * p.fc / p.sigma / (t_end * t_end);
            let mut d = Dahl::new(p).unwrap();
            for k in 0..n {
                let t = k as f64 * h;
                d.step(Ramp::new(a * t, a), h);
                let t1 = (k + 1) as f64 * h;
                let e = rel(d.force(), closed_form(&p, 0.5 * a * t1 * t1));
                assert!(e < 1e-9, "h {h} k {k}: {e}");
            }
        }
        // Negative direction mirrors.
        let mut d = Dahl::new(p).unwrap();
        d.step(Ramp::new(0.0, -2e-5), 1.0);
        assert!(rel(-d.force(), closed_form(&p, 1e-5)) < 1e-12);
    }

    /// RK4 on dF/dx with `m` steps over `[0, x]` from `f0`, direction `s`.
    fn rk4(p: &DahlParams, f0: f64, s: f64, x: f64, m: usize) -> f64 {
        let rhs = |f: f64| {
            let y = 1.0 - f * s / p.fc;
            s * p.sigma * y.abs().powf(p.alpha) * y.signum()
        };
        let dx = x / m as f64;
        let mut f = f0;
        for _ in 0..m {
            let k1 = rhs(f);
            let k2 = rhs(f + 0.5 * dx * k1);
            let k3 = rhs(f + 0.5 * dx * k2);
            let k4 = rhs(f + dx * k3);
            f += dx / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        f
    }

    #[test]
    fn general_alpha_matches_a_fine_rk4_reference() {
        for &alpha in &[0.3, 0.5, 0.8, 1.0, 1.5, 2.0, 3.0] {
            let p = DahlParams {
                alpha,
                ..DahlParams::default()
            };
            // Stop before y = 0 so the reference ODE stays smooth (α < 1
            // reaches sliding in finite distance).
            let x_end = 0.6 * p.fc / p.sigma;
            let mut d = Dahl::new(p).unwrap();
            let n = 40;
            let v = x_end / n as f64; // h = 1 s
            let mut reference = 0.0;
            for k in 1..=n {
                d.step(Ramp::constant(v), 1.0);
                reference = rk4(&p, reference, 1.0, v, 4000);
                let e = rel(d.force(), reference);
                assert!(e < 1e-8, "alpha {alpha} k {k}: {e}");
            }
            // And back the other way from there.
            let f0 = d.force();
            d.step(Ramp::constant(-x_end), 0.5);
            let reference = rk4(&p, f0, -1.0, 0.5 * x_end, 100_000);
            assert!(
                (d.force() - reference).abs() < 1e-8 * p.fc,
                "alpha {alpha} back"
            );
        }
    }

    #[test]
    fn sub_unit_alpha_reaches_fc_in_finite_distance() {
        let p = DahlParams {
            alpha: 0.5,
            ..DahlParams::default()
        };
        // |y|^(1/2) = 1 − (1/2)(σ/Fc)x → y = 0 at x = 2Fc/σ.
        let mut d = Dahl::new(p).unwrap();
        d.step(Ramp::constant(2.0 * p.fc / p.sigma * 1.0001), 1.0);
        assert_eq!(d.force(), p.fc);
        assert!(d.sliding(1.0) && !d.sliding(-1.0) && !d.sliding(0.0));
    }

    #[test]
    fn reversal_unloads_with_twice_the_distance_of_loading() {
        let p = DahlParams::default();
        let mut d = Dahl::new(p).unwrap();
        // Slide forward to saturation, then reverse: y starts at 2.
        d.step(Ramp::constant(1.0), 1.0);
        assert!((d.force() - p.fc).abs() < 1e-15);
        assert!(d.sliding(1.0));
        let x = 1e-5;
        d.step(Ramp::constant(-x), 1.0);
        let expect = -p.fc + 2.0 * p.fc * (-p.sigma * x / p.fc).exp();
        assert!(rel(d.force(), expect) < 1e-12);
        // A ramp through zero: forward 1e-5 then back 1e-5 in one step.
        let mut e = Dahl::new(p).unwrap();
        // v = 2e-5·(1 − 2τ) over [0, 1]: +5e-6 then −5e-6.
        e.step(Ramp::new(2e-5, -4e-5), 1.0);
        let f1 = closed_form(&p, 5e-6);
        let expect = -p.fc + (f1 + p.fc) * (-p.sigma * 5e-6 / p.fc).exp();
        assert!(
            (e.force() - expect).abs() < 1e-12,
            "{} vs {}",
            e.force(),
            expect
        );
        // Unloading is stiffer (slope σ(1 + F/Fc) > σ(1 − F/Fc)), so the same
        // distance back overshoots below zero: hysteresis.
        assert!(e.force() < 0.0, "hysteresis: {}", e.force());
    }

    #[test]
    fn force_rate_is_the_derivative_of_the_exact_update() {
        // α = 1 and motion from rest: F = Fc(1 − e^(−σx/Fc)), so
        // dF/dt = v·σ·e^(−σx/Fc) = σ·(1 − F/Fc)·v.
        let p = DahlParams::default();
        let d = Dahl::new(p).unwrap();
        for &x in &[0.0, 1e-6, 2e-5, 1e-4] {
            let f = closed_form(&p, x);
            let v = 3e-3;
            let expect = v * p.sigma * (-p.sigma * x / p.fc).exp();
            assert!(rel(d.force_rate(f, v), expect) < 1e-12, "x {x}");
        }
        assert_eq!(d.force_rate(0.5, 0.0), 0.0);
        // Every α, both directions, loading and unloading (y > 1), and
        // beyond Fc (y < 0): a tiny exact step moves F by the rate·h.
        for &alpha in &[0.5, 1.0, 2.5] {
            let p = DahlParams {
                alpha,
                ..DahlParams::default()
            };
            let mut d = Dahl::new(p).unwrap();
            for &(f, v) in &[(0.3, 1e-3), (0.3, -1e-3), (-1.5, 2e-3), (1.9, -5e-4)] {
                d.state_from_slice(&[f]).unwrap();
                let rate = d.force_rate(f, v);
                let h = 1e-9;
                d.step(Ramp::constant(v), h);
                let fd = (d.force() - f) / h;
                assert!(
                    (fd - rate).abs() <= 1e-5 * rate.abs(),
                    "alpha {alpha}, F {f}, v {v}: {fd} vs {rate}"
                );
            }
        }
        // Beyond the Coulomb level (reachable only by setting the state),
        // the rate pulls F back: sgn(1 − F/Fc·sgn v) < 0.
        let d = Dahl::new(p).unwrap();
        assert!(d.force_rate(2.5 * p.fc, 1e-3) < 0.0);
    }

    /// The closed-form partials of the rate against central differences of
    /// the rate itself, for several α, both directions, loading and
    /// unloading; at v = 0, the mean of the two sides.
    #[test]
    fn force_rate_partials_match_differences_of_the_rate() {
        for &alpha in &[0.5, 1.0, 2.5] {
            let p = DahlParams {
                alpha,
                ..DahlParams::default()
            };
            let d = Dahl::new(p).unwrap();
            for &(f, v) in &[
                (0.3, 1e-3),
                (0.3, -1e-3),
                (-1.5, 2e-3),
                (1.9, -5e-4),
                (0.7, 0.0),
            ] {
                let (df, dv) = d.force_rate_partials(f, v);
                let hf = 1e-7 * p.fc;
                let fd_f = (d.force_rate(f + hf, v) - d.force_rate(f - hf, v)) / (2.0 * hf);
                let hv = 1e-9;
                let fd_v = (d.force_rate(f, v + hv) - d.force_rate(f, v - hv)) / (2.0 * hv);
                assert!(
                    (df - fd_f).abs() <= 1e-6 * fd_f.abs().max(1.0),
                    "alpha {alpha}, F {f}, v {v}: {df} vs {fd_f}"
                );
                assert!(
                    (dv - fd_v).abs() <= 1e-6 * fd_v.abs(),
                    "alpha {alpha}, F {f}, v {v}: {dv} vs {fd_v}"
                );
            }
        }
    }

    #[test]
    fn state_round_trip_and_finite_for_all_step_sizes() {
        let p = DahlParams {
            alpha: 0.7,
            ..DahlParams::default()
        };
        let mut d = Dahl::new(p).unwrap();
        d.step(Ramp::new(1e-4, -3e-3), 0.1);
        let mut e = Dahl::new(p).unwrap();
        e.state_from_slice(&d.state_to_vec()).unwrap();
        for &h in &[1e-7, 1e-3, 1.0] {
            for &(v, a) in &[(1.0, -3.0), (-1e3, 5e3), (0.0, 0.0), (1e-12, 1e6)] {
                d.step(Ramp::new(v, a), h);
                e.step(Ramp::new(v, a), h);
                assert!(d.force().is_finite() && d.force().abs() <= p.fc * (1.0 + 1e-12));
                assert_eq!(d.force().to_bits(), e.force().to_bits());
            }
        }
        assert!(e.state_from_slice(&[1.0, 2.0]).is_err());
        assert!(e.state_from_slice(&[f64::INFINITY]).is_err());
    }

    /// A refused state is named as before the messages moved out of line;
    /// the slice writer writes what the vector writer appends.
    #[test]
    fn refused_states_are_named_and_written_states_agree() {
        let mut d = Dahl::new(DahlParams::default()).unwrap();
        let err = d.state_from_slice(&[f64::INFINITY]).unwrap_err();
        assert_eq!(err, "Dahl state F_dahl = inf is not finite");
        let err = d.state_from_slice(&[1.0, 2.0]).unwrap_err();
        assert_eq!(err, "Dahl state has 1 value, got 2");
        d.state_from_slice(&[0.25]).unwrap();
        let mut s = vec![f64::NAN; d.state_len()];
        d.write_state_into(&mut s);
        assert_eq!(s, d.state_to_vec());
    }
}
