//! Reset-integrator friction, 1-D (Haessig & Friedland 1991; the base of the
//! 2-D model of Wijata et al. 2016; docs/models.md "Reset integrator").
//!
//! `ż = 0` if (`v > 0` and `z ≥ z0`) or (`v < 0` and `z ≤ −z0`), else `ż = v`;
//! `F = (1 + a(z))·σ0·z + σ1·ż`, `a(z) = a` for `|z| < z0`, else 0.
//! Sliding level `Fc = σ0·z0`, break-away peak `Fs = (1 + a)·σ0·z0`.

use crate::error::{require_non_negative, require_positive};
use crate::interval::{displacement, one_sign_pieces, sign_on};
use crate::state::one_value_state;
use crate::{ParamError, Ramp};

/// Reset-integrator parameters: stiffness `sigma0` (N/m), damping `sigma1`
/// (N·s/m), stiction gradient `a` (–), stiction range `z0` (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResetParams {
    pub sigma0: f64,
    pub sigma1: f64,
    pub a: f64,
    pub z0: f64,
}

impl Default for ResetParams {
    /// Wijata et al. 2016, numerical set in 1-D: σ0 = 1e4 N/m,
    /// σ1 = 74.15 N·s/m, a = 0.1, z0 = 1e-4 m.
    fn default() -> Self {
        ResetParams {
            sigma0: 1e4,
            sigma1: 74.15,
            a: 0.1,
            z0: 1e-4,
        }
    }
}

impl ResetParams {
    /// σ0 > 0, σ1 ≥ 0, a ≥ 0 (a break-away peak not below the sliding
    /// level; the equations only need a > −1), z0 > 0, all finite.
    pub fn validate(&self) -> Result<(), ParamError> {
        require_positive("sigma0", self.sigma0)?;
        require_non_negative("sigma1", self.sigma1)?;
        require_non_negative("a", self.a)?;
        require_positive("z0", self.z0)?;
        Ok(())
    }
}

/// Reset-integrator state: the bristle strain `z` (m).
#[derive(Clone, Debug)]
pub struct ResetIntegrator {
    p: ResetParams,
    z: f64,
}

impl ResetIntegrator {
    /// Relaxed state `z = 0` with validated parameters.
    pub fn new(p: ResetParams) -> Result<Self, ParamError> {
        p.validate()?;
        Ok(ResetIntegrator { p, z: 0.0 })
    }

    pub fn params(&self) -> &ResetParams {
        &self.p
    }

    pub fn z(&self) -> f64 {
        self.z
    }

    /// Sets the strain (any finite value; `|z| > z0` is held until the motion
    /// brings it back).
    pub fn set_z(&mut self, z: f64) {
        self.z = z;
    }

    /// The limit the strain is at: `+1` at or beyond `z0`, `−1` at or
    /// beyond `−z0`, 0 inside the range. The equations below take it as an
    /// argument, so that an integrator can hold it as a discrete state
    /// between events (Model Exchange), where `z` is kept at the limit
    /// only to the last bit.
    pub fn contact(&self) -> i8 {
        if self.z >= self.p.z0 {
            1
        } else if self.z <= -self.p.z0 {
            -1
        } else {
            0
        }
    }

    /// `ż = 0` when saturated (`v > 0, z ≥ z0` or `v < 0, z ≤ −z0`), else `v`.
    pub fn z_dot(&self, v: f64) -> f64 {
        self.z_rate(v, self.contact())
    }

    /// The state equation with the contact given: `ż = 0` when the limit
    /// the strain is at holds it (`contact·v > 0`: moving outward), else
    /// `v`.
    pub fn z_rate(&self, v: f64, contact: i8) -> f64 {
        if Self::held(v, contact) {
            0.0
        } else {
            v
        }
    }

    /// Whether the limit `contact` holds the strain moving at `v`.
    #[inline]
    fn held(v: f64, contact: i8) -> bool {
        f64::from(contact) * v > 0.0
    }

    /// `F = (1 + a(z))·σ0·z + σ1·ż(v)`, `a(z) = a` inside `|z| < z0`, else 0.
    pub fn force(&self, v: f64) -> f64 {
        self.force_of(self.z, v, self.contact())
    }

    /// The output equation for any strain and contact: the stiction
    /// gradient `a` acts inside the range only (`contact = 0`).
    pub fn force_of(&self, z: f64, v: f64, contact: i8) -> f64 {
        let gain = if contact == 0 { 1.0 + self.p.a } else { 1.0 };
        gain * self.p.sigma0 * z + self.p.sigma1 * self.z_rate(v, contact)
    }

    /// Saturated and moving outward: `ż = 0` and the force is `σ0·z0·sgn v`.
    pub fn sliding(&self, v: f64) -> bool {
        Self::held(v, self.contact())
    }

    /// [`ResetIntegrator::sliding`] with the contact given.
    pub fn sliding_of(&self, v: f64, contact: i8) -> bool {
        Self::held(v, contact)
    }

    /// The elastic energy held in the bristle (J), `(1 + a)·σ0·z²/2`: the
    /// potential of the elastic force the strain moves against inside the
    /// range. Held at the limit the strain does not move and the energy
    /// stays `(1 + a)·σ0·z0²/2`: the drop of the force from `(1 + a)·σ0·z0`
    /// to `σ0·z0` there loses no energy, and its rise on the reversal gains
    /// none. (A strain set beyond the range only comes back: with the force
    /// `σ0·z` there, `P_diss = −a·σ0·z·v + σ1·v²` is still not negative.)
    pub fn stored_energy_of(&self, z: f64) -> f64 {
        0.5 * self.energy_stiffness() * z * z
    }

    /// [`ResetIntegrator::stored_energy_of`] at the law's strain.
    pub fn stored_energy(&self) -> f64 {
        self.stored_energy_of(self.z)
    }

    /// `(1 + a)·σ0`, the stiffness of [`ResetIntegrator::stored_energy_of`].
    fn energy_stiffness(&self) -> f64 {
        (1.0 + self.p.a) * self.p.sigma0
    }

    /// `P_diss = F·v − dE/dt = F·v − E'(z)·ż` (W) for any strain, velocity
    /// and contact: `σ1·v²` inside the range, `σ0·z0·|v|` held at a limit,
    /// never negative.
    pub fn dissipated_power_of(&self, z: f64, v: f64, contact: i8) -> f64 {
        self.force_of(z, v, contact) * v - self.energy_stiffness() * z * self.z_rate(v, contact)
    }

    /// [`ResetIntegrator::dissipated_power_of`] at the law's strain.
    pub fn dissipated_power(&self, v: f64) -> f64 {
        self.dissipated_power_of(self.z, v, self.contact())
    }

    /// `(∂P/∂z, ∂P/∂v, ∂E/∂z)` of the energy outputs for a given contact,
    /// from [`ResetIntegrator::partials`]: `P = F·v − E'(z)·ż`.
    pub fn energy_partials(&self, z: f64, v: f64, contact: i8) -> (f64, f64, f64) {
        let (_, dzd_dv, df_dz, df_dv) = self.partials(v, contact);
        let curvature = self.energy_stiffness();
        let slope = curvature * z;
        let z_dot = self.z_rate(v, contact);
        (
            df_dz * v - curvature * z_dot,
            df_dv * v + self.force_of(z, v, contact) - slope * dzd_dv,
            slope,
        )
    }

    /// The partial derivatives of [`ResetIntegrator::z_rate`] and
    /// [`ResetIntegrator::force_of`] at strain `z`, velocity `v` and
    /// contact `contact`: `(∂ż/∂z, ∂ż/∂v, ∂F/∂z, ∂F/∂v)`. `ż` is `v` or 0,
    /// constant in `z` for a given contact: `∂ż/∂z = 0`, `∂ż/∂v` = 1
    /// unless held (0); at `v = 0` at a limit (held on one side of `v = 0`
    /// only) the mean of the two sides, ½. `F = (1 + a(contact))·σ0·z +
    /// σ1·ż`: `∂F/∂z = (1 + a(contact))·σ0`, `∂F/∂v = σ1·∂ż/∂v`.
    pub fn partials(&self, v: f64, contact: i8) -> (f64, f64, f64, f64) {
        let p = &self.p;
        let dzd_dv = if v == 0.0 && contact != 0 {
            0.5
        } else if Self::held(v, contact) {
            0.0
        } else {
            1.0
        };
        let gain = if contact == 0 { 1.0 + p.a } else { 1.0 };
        (0.0, dzd_dv, gain * p.sigma0, p.sigma1 * dzd_dv)
    }

    /// Two switching functions, each changing sign where `ż` switches
    /// between `v` and 0 (Model Exchange's event indicators), for strain
    /// `z`, velocity `v` and contact `contact`: for the upper limit `z0 −
    /// z` while not at it (it reaches 0 when the strain does) and `−v` at
    /// it (negative while it holds the strain, 0 when the motion reverses
    /// and releases it); for the lower limit likewise `z + z0` and `v`.
    /// Each is positive while its limit does not hold the strain and
    /// negative while it does.
    pub fn switching_functions(&self, z: f64, v: f64, contact: i8) -> [f64; 2] {
        let z0 = self.p.z0;
        let upper = if contact == 1 { -v } else { z0 - z };
        let lower = if contact == -1 { v } else { z + z0 };
        [upper, lower]
    }

    /// The strain and contact after an event at strain `z`, velocity `v`,
    /// contact `contact`: a strain that reached a limit moving outward is
    /// put on it (an integrator carries it a little past; the exact
    /// update [`ResetIntegrator::step`] stops it there) and held; a held
    /// strain whose motion turned inward is released, at the limit; a
    /// held one stays on its limit (to the last bit).
    pub fn at_event(&self, z: f64, v: f64, contact: i8) -> (f64, i8) {
        let z0 = self.p.z0;
        let limit = |c: i8| f64::from(c) * z0;
        match contact {
            0 if z >= z0 && v > 0.0 => (z0, 1),
            0 if z <= -z0 && v < 0.0 => (-z0, -1),
            0 => (z, 0),
            c if f64::from(c) * v < 0.0 => (limit(c), 0),
            c => (limit(c), c),
        }
    }

    /// Exact update over `[0, h]` for ramped `v`: split at the zero crossing;
    /// on each one-sign piece with exact displacement `Δx`,
    /// `v > 0: z ← max(z, min(z + Δx, z0))`, `v < 0: z ← min(z, max(z + Δx, −z0))`
    /// (a strain already beyond the range is held, not pulled back).
    pub fn step(&mut self, v: Ramp, h: f64) {
        if h.is_nan() || h <= 0.0 {
            return;
        }
        let (pieces, n) = one_sign_pieces(v, h);
        let z0 = self.p.z0;
        for &(a, b) in &pieces[..n] {
            let s = sign_on(v, a, b);
            let dx = displacement(v, a, b);
            if s > 0.0 {
                if self.z < z0 {
                    self.z = (self.z + dx).min(z0);
                }
            } else if s < 0.0 && self.z > -z0 {
                self.z = (self.z + dx).max(-z0);
            }
        }
    }

    // The state: the bristle strain z, any finite value.
    one_value_state!("reset-integrator", "z", z);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn energy_is_stored_inside_and_dissipated_at_the_limit() {
        let p = ResetParams::default();
        let mut r = ResetIntegrator::new(p).unwrap();
        let v = 1e-3;
        r.step(Ramp::constant(v), 0.05);
        // inside: E = (1 + a)·σ0·z²/2, only the damper dissipates
        let z = r.z();
        assert!(rel(r.stored_energy(), 0.5 * (1.0 + p.a) * p.sigma0 * z * z) < 1e-15);
        assert!(rel(r.dissipated_power(v), p.sigma1 * v * v) < 1e-12);
        // held at the limit: E stays, F·v = σ0·z0·v is all dissipated
        r.step(Ramp::constant(v), 0.1);
        let held = 0.5 * (1.0 + p.a) * p.sigma0 * p.z0 * p.z0;
        assert_eq!(r.stored_energy(), held);
        assert!(rel(r.dissipated_power(v), p.sigma0 * p.z0 * v) < 1e-15);
        // reversing: the force rises back to (1 + a)·σ0·z, no energy made
        assert!(r.dissipated_power(-v) > 0.0);
        // the partials against differences
        for (z, c) in [(0.3 * p.z0, 0), (p.z0, 1), (-p.z0, -1), (1.2 * p.z0, 1)] {
            for v in [2e-3, -3e-3] {
                let (pz, pv, ez) = r.energy_partials(z, v, c);
                let dz = 1e-6 * p.z0;
                let (up, down) = (z + dz, z - dz);
                let span = up - down;
                let fd_pz =
                    (r.dissipated_power_of(up, v, c) - r.dissipated_power_of(down, v, c)) / span;
                let fd_pv = (r.dissipated_power_of(z, v + 1e-6, c)
                    - r.dissipated_power_of(z, v - 1e-6, c))
                    / 2e-6;
                let fd_ez = (r.stored_energy_of(up) - r.stored_energy_of(down)) / span;
                assert!(
                    (pz - fd_pz).abs() <= 1e-6 * pz.abs().max(1.0),
                    "{pz} {fd_pz}"
                );
                assert!(
                    (pv - fd_pv).abs() <= 1e-6 * pv.abs().max(1.0),
                    "{pv} {fd_pv}"
                );
                assert!(
                    (ez - fd_ez).abs() <= 1e-6 * ez.abs().max(1e-3),
                    "{ez} {fd_ez}"
                );
            }
        }
    }

    #[test]
    fn break_away_peak_then_sliding_level() {
        let p = ResetParams {
            sigma1: 0.0,
            ..ResetParams::default()
        };
        let (fs, fc) = ((1.0 + p.a) * p.sigma0 * p.z0, p.sigma0 * p.z0);
        let v = 1e-3;
        let mut r = ResetIntegrator::new(p).unwrap();
        // Steps of 1e-3 s (1e-6 m); the force grows as (1 + a)σ0·v·t.
        let mut peak: f64 = 0.0;
        for k in 1..=99 {
            r.step(Ramp::constant(v), 1e-3);
            let f = r.force(v);
            assert!(rel(f, (1.0 + p.a) * p.sigma0 * v * 1e-3 * k as f64) < 1e-12);
            peak = peak.max(f);
            assert!(!r.sliding(v));
        }
        // The last pre-sliding instant approaches the peak arbitrarily closely.
        r.step(Ramp::constant(v), (p.z0 - r.z()) / v * (1.0 - 1e-12));
        assert!(rel(r.force(v), fs) < 1e-9, "{} vs {}", r.force(v), fs);
        assert!(peak <= fs);
        r.step(Ramp::constant(v), 1e-3);
        assert_eq!(r.z(), p.z0);
        assert!(r.sliding(v));
        assert_eq!(r.force(v), fc);
        for _ in 0..100 {
            r.step(Ramp::constant(v), 1e-3);
            assert_eq!(r.force(v), fc);
        }
        // Stop: stays stuck at the level, a = 0 on the boundary.
        assert_eq!(r.force(0.0), fc);
        assert!(!r.sliding(0.0));
        // Reverse: leaves the boundary at once with ż = v.
        assert_eq!(r.z_dot(-v), -v);
    }

    #[test]
    fn big_steps_are_exact() {
        let p = ResetParams::default();
        let mut r = ResetIntegrator::new(p).unwrap();
        r.step(Ramp::constant(5e-5), 1.0);
        assert_eq!(r.z(), 5e-5);
        r.step(Ramp::constant(10.0), 1.0);
        assert_eq!(r.z(), p.z0);
        // Ramp from −3e-4 to +1e-4 m/s over 1 s: v(τ) = −3e-4 + 4e-4·τ is zero
        // at τ = 0.75, Δx− = −1.125e-4 m, then Δx+ = 1.25e-5 m.
        r.step(Ramp::new(-3e-4, 4e-4), 1.0);
        let expect = (p.z0 - 1.125e-4_f64).max(-p.z0) + 1.25e-5;
        assert!((r.z() - expect).abs() < 1e-18, "{} vs {expect}", r.z());
        // Far enough back to saturate at −z0, then forward again.
        r.step(Ramp::new(-3e-4, 1e-4), 2.0); // Δx = −4e-4
        assert_eq!(r.z(), -p.z0);
        r.step(Ramp::constant(3e-5), 1.0);
        assert!((r.z() - (-p.z0 + 3e-5)).abs() < 1e-19);
        // Same motion in 1e5 small steps gives the same strain.
        let mut q = ResetIntegrator::new(p).unwrap();
        q.set_z(p.z0);
        let h = 1e-5;
        for k in 0..100_000 {
            let t = k as f64 * h;
            q.step(Ramp::new(-3e-4 + 4e-4 * t, 4e-4), h);
        }
        assert!((q.z() - expect).abs() < 1e-14);
    }

    #[test]
    fn validation_and_state_round_trip() {
        let p = ResetParams::default();
        assert_eq!(
            ResetIntegrator::new(ResetParams { a: -0.5, ..p })
                .unwrap_err()
                .name,
            "a"
        );
        assert_eq!(
            ResetIntegrator::new(ResetParams { z0: 0.0, ..p })
                .unwrap_err()
                .name,
            "z0"
        );
        let mut r = ResetIntegrator::new(p).unwrap();
        r.step(Ramp::new(1e-4, -1e-3), 0.37);
        let mut q = ResetIntegrator::new(p).unwrap();
        q.state_from_slice(&r.state_to_vec()).unwrap();
        for &h in &[1e-7, 1e-2, 1.0] {
            for &(v, a) in &[(1.0, -3.0), (-1e3, 5e3), (0.0, 0.0)] {
                r.step(Ramp::new(v, a), h);
                q.step(Ramp::new(v, a), h);
                assert!(r.force(v).is_finite());
                assert_eq!(r.z().to_bits(), q.z().to_bits());
            }
        }
        assert!(q.state_from_slice(&[]).is_err());
    }

    /// A refused state is named as before the messages moved out of line;
    /// the slice writer writes what the vector writer appends.
    #[test]
    fn refused_states_are_named_and_written_states_agree() {
        let mut r = ResetIntegrator::new(ResetParams::default()).unwrap();
        let err = r.state_from_slice(&[f64::NAN]).unwrap_err();
        assert_eq!(err, "reset-integrator state z = NaN is not finite");
        let err = r.state_from_slice(&[]).unwrap_err();
        assert_eq!(err, "reset-integrator state has 1 value, got 0");
        r.state_from_slice(&[1e-7]).unwrap();
        let mut s = vec![f64::NAN; r.state_len()];
        r.write_state_into(&mut s);
        assert_eq!(s, r.state_to_vec());
    }

    /// The switching functions change sign exactly where `ż` switches
    /// (reaching ±z0 moving outward, reversing while held), an event puts
    /// an overshoot back on the limit and holds it, and releases it when
    /// the motion turns; the contact-given equations are the state's; the
    /// partials match differences of `z_rate` and `force_of`.
    #[test]
    fn switching_functions_events_and_partials() {
        let p = ResetParams::default();
        let mut r = ResetIntegrator::new(p).unwrap();
        let z0 = p.z0;
        let v = 2e-3;
        // inside: both positive; the upper one is z0 − z
        let z = 0.4 * z0;
        assert_eq!(r.switching_functions(z, v, 0), [z0 - z, z + z0]);
        assert_eq!(r.z_rate(v, 0), v);
        // an integrator's step past the limit: the indicator has changed
        // sign; the event stops the strain there and holds it
        let past = z0 * (1.0 + 1e-9);
        assert!(r.switching_functions(past, v, 0)[0] < 0.0);
        assert_eq!(r.at_event(past, v, 0), (z0, 1));
        assert_eq!(r.switching_functions(z0, v, 1)[0], -v);
        assert_eq!(r.z_rate(v, 1), 0.0);
        // held a bit below the limit (an integrator's last bit): still held
        let below = z0 * (1.0 - 1e-16);
        assert_eq!(r.z_rate(v, 1), 0.0);
        assert_eq!(r.at_event(below, v, 1), (z0, 1));
        // the reversal releases it: positive again, ż = v, at the limit
        assert!(r.switching_functions(z0, -v, 1)[0] > 0.0);
        assert_eq!(r.at_event(below, -v, 1), (z0, 0));
        assert_eq!(r.z_rate(-v, 0), -v);
        // the lower limit mirrors it
        assert!(r.switching_functions(-past, -v, 0)[1] < 0.0);
        assert_eq!(r.at_event(-past, -v, 0), (-z0, -1));
        assert_eq!(r.z_rate(-v, -1), 0.0);
        assert_eq!(r.at_event(-z0, v, -1), (-z0, 0));
        // beyond the range moving inward, and inside: nothing changes
        assert_eq!(r.at_event(past, -v, 0), (past, 0));
        assert_eq!(r.at_event(z, v, 0), (z, 0));
        // the state's contact gives the state's equations
        for (z, c) in [(z, 0), (z0, 1), (-z0, -1), (past, 1), (-0.99 * z0, 0)] {
            r.set_z(z);
            assert_eq!(r.contact(), c);
            for v in [v, -v, 0.0] {
                assert_eq!(r.z_dot(v), r.z_rate(v, c));
                assert_eq!(r.force(v), r.force_of(z, v, c));
                assert_eq!(r.sliding(v), r.sliding_of(v, c));
            }
        }
        // partials against differences, inside and held (and ½ at v = 0
        // at a limit, the mean of the two sides)
        for &(z, v, c) in &[
            (0.3 * z0, 1e-3, 0),
            (-0.2 * z0, -1e-3, 0),
            (z0, 1e-3, 1),
            (-z0, 1e-3, -1),
            (z0, 0.0, 1),
        ] {
            let (dzd_dz, dzd_dv, df_dz, df_dv) = r.partials(v, c);
            let (h, hz) = (1e-9, 1e-12);
            let fd_v = (r.z_rate(v + h, c) - r.z_rate(v - h, c)) / (2.0 * h);
            let fdf_v = (r.force_of(z, v + h, c) - r.force_of(z, v - h, c)) / (2.0 * h);
            let fdf_z = (r.force_of(z + hz, v, c) - r.force_of(z - hz, v, c)) / (2.0 * hz);
            assert_eq!(dzd_dz, 0.0);
            assert!(
                (dzd_dv - fd_v).abs() < 1e-9,
                "z {z} v {v}: {dzd_dv} vs {fd_v}"
            );
            assert!((df_dv - fdf_v).abs() < 1e-6 * p.sigma1, "z {z} v {v}");
            assert!((df_dz - fdf_z).abs() < 1e-6 * p.sigma0, "z {z} v {v}");
        }
    }
}
