//! Classical friction: Coulomb + viscous + static friction, with the
//! Stribeck curve (Sun et al. 2016 eq. 1 and 12; Thimmalapura 2004 eq.
//! 2.1–2.3), made usable in discrete time by Karnopp's zero-velocity band
//! (Karnopp 1985; docs/models.md "Classical").
//!
//! Sliding (`|v| ≥ dv`): the steady-state curve
//! `Fss(v) = sgn v·(Fc + (Fs − Fc)·e^(−|v/vs|^δ)) + σ2·v` (with `vs = 0`:
//! `Fc·sgn v + σ2·v`, Sun et al. eq. 1 without the Stribeck term).
//!
//! Inside the band (`|v| < dv`) the contact sticks and holds the force
//! `F_app` that the rest of the system applies to it, up to the static
//! level: `F = F_app` while `|F_app| ≤ Fs` (stuck), `F = Fs·sgn F_app`
//! beyond (breaking away). The law has no state: the force follows from
//! the two inputs, so a step changes nothing and the stick/slip switch is
//! where an input crosses `±dv` or `±Fs`.

use crate::error::{require_non_negative, require_positive};
use crate::ParamError;

/// Classical parameters: Coulomb level `fc` (N), static level `fs` (N),
/// Stribeck velocity `vs` (m/s, 0: no Stribeck term), Stribeck exponent
/// `delta` (–), viscous coefficient `sigma2` (N·s/m), half-width of the
/// zero-velocity band `dv` (m/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClassicalParams {
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub delta: f64,
    pub sigma2: f64,
    pub dv: f64,
}

impl Default for ClassicalParams {
    /// Sun et al. 2016, Table 6 (brass on steel, nominal): Fc = 1.284 N,
    /// Fs = 2.35 N, vs = 1.13975e-3 m/s, σ2 = 173 N·s/m, δ = 2; the band
    /// dv = 1e-5 m/s (1 % of vs).
    fn default() -> Self {
        ClassicalParams {
            fc: 1.284,
            fs: 2.35,
            vs: 1.13975e-3,
            delta: 2.0,
            sigma2: 173.0,
            dv: 1e-5,
        }
    }
}

impl ClassicalParams {
    /// `Fc > 0`, `Fs ≥ Fc`, `vs ≥ 0`, `δ > 0`, `σ2 ≥ 0`, `dv > 0`, all
    /// finite.
    pub fn validate(&self) -> Result<(), ParamError> {
        require_positive("Fc", self.fc)?;
        require_positive("Fs", self.fs)?;
        if self.fs < self.fc {
            return Err(ParamError::new(
                "Fs",
                self.fs,
                format!(
                    "must be >= Fc = {} (the static level is the higher)",
                    self.fc
                ),
            ));
        }
        require_non_negative("vs", self.vs)?;
        require_positive("delta", self.delta)?;
        require_non_negative("sigma2", self.sigma2)?;
        require_positive("dv", self.dv)?;
        Ok(())
    }
}

/// The branches of the law, between which its force jumps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Branch {
    /// Inside the band, `|F_app| ≤ Fs`: `F = F_app`.
    Stuck,
    /// Inside the band, `F_app > Fs`: `F = Fs`.
    BreakingAwayForward,
    /// Inside the band, `F_app < −Fs`: `F = −Fs`.
    BreakingAwayBackward,
    /// Outside the band: the Stribeck curve `Fss(v)`.
    Sliding,
}

impl Branch {
    /// A number for the FMU state: 0, 1, 2, 3 in the order above.
    pub fn code(self) -> f64 {
        match self {
            Branch::Stuck => 0.0,
            Branch::BreakingAwayForward => 1.0,
            Branch::BreakingAwayBackward => 2.0,
            Branch::Sliding => 3.0,
        }
    }

    /// The branch of [`Branch::code`]; `None` for any other number.
    pub fn from_code(code: f64) -> Option<Branch> {
        [
            Branch::Stuck,
            Branch::BreakingAwayForward,
            Branch::BreakingAwayBackward,
            Branch::Sliding,
        ]
        .into_iter()
        .find(|b| b.code() == code)
    }
}

/// The classical law (stateless: its parameters).
#[derive(Clone, Debug)]
pub struct Classical {
    p: ClassicalParams,
}

impl Classical {
    /// The law with validated parameters.
    pub fn new(p: ClassicalParams) -> Result<Self, ParamError> {
        p.validate()?;
        Ok(Classical { p })
    }

    pub fn params(&self) -> &ClassicalParams {
        &self.p
    }

    /// The level `g(v) = Fc + (Fs − Fc)·e^(−|v/vs|^δ)` of the Stribeck
    /// curve, `Fc` when `vs = 0`.
    fn level(&self, v: f64) -> f64 {
        let p = &self.p;
        if p.vs == 0.0 {
            p.fc
        } else {
            p.fc + (p.fs - p.fc) * (-(v.abs() / p.vs).powf(p.delta)).exp()
        }
    }

    /// The steady-state (Stribeck) curve
    /// `Fss(v) = sgn v·g(v) + σ2·v` (Sun et al. 2016 eq. 12), 0 at `v = 0`.
    pub fn steady_state(&self, v: f64) -> f64 {
        if v == 0.0 {
            return 0.0;
        }
        v.signum() * self.level(v) + self.p.sigma2 * v
    }

    /// `dFss/dv = −(Fs − Fc)·δ·(|v|/vs)^(δ−1)/vs·e^(−|v/vs|^δ) + σ2`
    /// (the same on both sides of 0).
    pub fn steady_state_slope(&self, v: f64) -> f64 {
        let p = &self.p;
        if p.vs == 0.0 {
            return p.sigma2;
        }
        let r = v.abs() / p.vs;
        -(p.fs - p.fc) * p.delta * r.powf(p.delta - 1.0) / p.vs * (-r.powf(p.delta)).exp()
            + p.sigma2
    }

    /// Whether the velocity is inside the zero-velocity band `|v| < dv`.
    #[inline]
    pub fn in_band(&self, v: f64) -> bool {
        v.abs() < self.p.dv
    }

    /// Which branch of the law the inputs are on.
    pub fn branch(&self, v: f64, f_app: f64) -> Branch {
        if !self.in_band(v) {
            Branch::Sliding
        } else if f_app.abs() <= self.p.fs {
            Branch::Stuck
        } else if f_app > 0.0 {
            Branch::BreakingAwayForward
        } else {
            Branch::BreakingAwayBackward
        }
    }

    /// The branch after an event at these inputs, coming from `from` (the
    /// branch before it): [`Classical::branch`], except that a boundary
    /// the inputs sit on exactly (`|v| = dv`, `|F_app| = Fs`) counts as
    /// crossed, away from `from`. An importer's solver stops at the
    /// boundary an indicator crossed, often exactly on it, and this is
    /// how the switch is taken there instead of missed.
    pub fn branch_after_event(&self, from: Branch, v: f64, f_app: f64) -> Branch {
        let (dv, fs) = (self.p.dv, self.p.fs);
        let breaking_away = || {
            if f_app > 0.0 {
                Branch::BreakingAwayForward
            } else {
                Branch::BreakingAwayBackward
            }
        };
        match from {
            Branch::Sliding if v.abs() > dv => Branch::Sliding,
            // entering the band (on its edge too)
            Branch::Sliding if f_app.abs() <= fs => Branch::Stuck,
            Branch::Sliding => breaking_away(),
            // leaving the band (from its edge too)
            _ if v.abs() >= dv => Branch::Sliding,
            Branch::Stuck if f_app.abs() < fs => Branch::Stuck,
            Branch::Stuck => breaking_away(),
            _ if f_app.abs() < fs => Branch::Stuck,
            _ => breaking_away(),
        }
    }

    /// The friction force: `F_app` when stuck, `Fs·sgn F_app` inside the
    /// band beyond the static level, `Fss(v)` outside the band.
    pub fn force(&self, v: f64, f_app: f64) -> f64 {
        self.force_on(self.branch(v, f_app), v, f_app)
    }

    /// The force of `branch`'s formula, wherever the inputs are: `F_app`
    /// (stuck), `±Fs` (breaking away), `Fss(v)` (sliding). A Model Exchange
    /// importer's solver evaluates the branch it was on at the last event
    /// until an event indicator stops it at the switch, so the force stays
    /// continuous within its steps (FMI 2.0.4 §3.1).
    pub fn force_on(&self, branch: Branch, v: f64, f_app: f64) -> f64 {
        match branch {
            Branch::Stuck => f_app,
            Branch::BreakingAwayForward => self.p.fs,
            Branch::BreakingAwayBackward => -self.p.fs,
            Branch::Sliding => self.steady_state(v),
        }
    }

    /// `(∂F/∂v, ∂F/∂F_app)`: `(0, 1)` stuck, `(0, 0)` breaking away,
    /// `(dFss/dv, 0)` sliding.
    pub fn force_partials(&self, v: f64, f_app: f64) -> (f64, f64) {
        self.force_partials_on(self.branch(v, f_app), v)
    }

    /// [`Classical::force_partials`] of `branch`'s formula.
    pub fn force_partials_on(&self, branch: Branch, v: f64) -> (f64, f64) {
        match branch {
            Branch::Stuck => (0.0, 1.0),
            Branch::BreakingAwayForward | Branch::BreakingAwayBackward => (0.0, 0.0),
            Branch::Sliding => (self.steady_state_slope(v), 0.0),
        }
    }

    /// The number of values of the state (0: the law has none).
    pub fn state_len(&self) -> usize {
        0
    }

    /// Writes the empty state.
    pub fn write_state_into(&self, _out: &mut [f64]) {}

    /// The empty state is finite.
    pub fn state_is_finite(&self) -> bool {
        true
    }

    /// The empty state as a vector.
    pub fn state_to_vec(&self) -> Vec<f64> {
        Vec::new()
    }

    /// Restores the empty state (any other length is refused).
    pub fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
        if s.is_empty() {
            Ok(())
        } else {
            Err(format!("Classical has no state, got {} values", s.len()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_parameter() {
        let p = ClassicalParams::default();
        for (bad, name) in [
            (ClassicalParams { fs: 1.0, ..p }, "Fs"),
            (ClassicalParams { fc: 0.0, ..p }, "Fc"),
            (ClassicalParams { vs: -1.0, ..p }, "vs"),
            (ClassicalParams { dv: 0.0, ..p }, "dv"),
            (
                ClassicalParams {
                    sigma2: f64::NAN,
                    ..p
                },
                "sigma2",
            ),
        ] {
            assert_eq!(Classical::new(bad).unwrap_err().name, name);
        }
    }

    /// The curve of Sun et al. 2016 eq. 12 at points computed by hand:
    /// `Fss(vs) = Fc + (Fs − Fc)/e + σ2·vs`, odd in `v`, `Fs` at 0+ (less
    /// the viscous term), and `Fc + σ2·v` far out; with `vs = 0` eq. 1.
    #[test]
    fn steady_state_is_the_stribeck_curve() {
        let p = ClassicalParams::default();
        let law = Classical::new(p).unwrap();
        let at_vs = p.fc + (p.fs - p.fc) / std::f64::consts::E + p.sigma2 * p.vs;
        assert!((law.steady_state(p.vs) - at_vs).abs() < 1e-12);
        assert!((law.steady_state(-p.vs) + at_vs).abs() < 1e-12);
        assert!((law.steady_state(1e-9) - p.fs).abs() < 1e-6);
        assert!((law.steady_state(0.05) - (p.fc + p.sigma2 * 0.05)).abs() < 1e-12);
        let plain = Classical::new(ClassicalParams { vs: 0.0, ..p }).unwrap();
        assert_eq!(plain.steady_state(-2e-3), -p.fc - p.sigma2 * 2e-3);
    }

    /// Inside the band the force is the applied force up to `Fs`, then
    /// `Fs` in its direction; outside it is the curve whatever the
    /// applied force.
    #[test]
    fn sticks_inside_the_band_and_breaks_away_at_fs() {
        let p = ClassicalParams::default();
        let law = Classical::new(p).unwrap();
        for v in [0.0, 0.5 * p.dv, -0.9 * p.dv] {
            assert_eq!(law.force(v, 1.7), 1.7);
            assert_eq!(law.branch(v, 1.7), Branch::Stuck);
            assert_eq!(law.force(v, -2.35), -2.35);
            assert_eq!(law.force(v, 3.0), p.fs);
            assert_eq!(law.branch(v, 3.0), Branch::BreakingAwayForward);
            assert_eq!(law.force(v, -9.0), -p.fs);
        }
        assert_eq!(law.force(2.0 * p.dv, -9.0), law.steady_state(2.0 * p.dv));
        assert_eq!(law.branch(p.dv, 0.0), Branch::Sliding);
    }

    /// An event stops on the boundary its indicator crossed: there the
    /// switch is taken, away from the branch before, where `branch` alone
    /// would keep the old one.
    #[test]
    fn a_boundary_at_an_event_counts_as_crossed() {
        let p = ClassicalParams::default();
        let law = Classical::new(p).unwrap();
        let (fs, dv) = (p.fs, p.dv);
        use Branch::*;
        // breaking away on F_app = ±Fs exactly
        assert_eq!(law.branch(0.0, fs), Stuck);
        assert_eq!(law.branch_after_event(Stuck, 0.0, fs), BreakingAwayForward);
        assert_eq!(
            law.branch_after_event(Stuck, 0.0, -fs),
            BreakingAwayBackward
        );
        // leaving the band on |v| = dv exactly
        assert_eq!(law.branch(dv * (1.0 - 1e-16), 3.0), BreakingAwayForward);
        assert_eq!(
            law.branch_after_event(BreakingAwayForward, dv, 3.0),
            Sliding
        );
        assert_eq!(law.branch_after_event(Stuck, -dv, 0.3), Sliding);
        // entering it on |v| = dv exactly: stuck, or breaking away beyond Fs
        assert_eq!(law.branch(dv, 0.3), Sliding);
        assert_eq!(law.branch_after_event(Sliding, dv, 0.3), Stuck);
        assert_eq!(
            law.branch_after_event(Sliding, -dv, -3.0),
            BreakingAwayBackward
        );
        // back below Fs while breaking away: stuck again
        assert_eq!(
            law.branch_after_event(BreakingAwayForward, 0.0, fs),
            BreakingAwayForward
        );
        assert_eq!(
            law.branch_after_event(BreakingAwayForward, 0.0, 0.9 * fs),
            Stuck
        );
        // away from every boundary it is the inputs' own branch
        for from in [Stuck, BreakingAwayForward, BreakingAwayBackward, Sliding] {
            for (v, f_app) in [
                (0.0, 1.0),
                (0.5 * dv, 5.0),
                (-0.5 * dv, -5.0),
                (3.0 * dv, 0.0),
            ] {
                assert_eq!(law.branch_after_event(from, v, f_app), law.branch(v, f_app));
            }
            assert_eq!(Branch::from_code(from.code()), Some(from));
        }
        assert_eq!(Branch::from_code(0.5), None);
    }

    #[test]
    fn partials_match_differences() {
        let law = Classical::new(ClassicalParams::default()).unwrap();
        for v in [3e-4, -1.2e-3, 4e-3] {
            let e = 1e-9;
            let fd = (law.force(v + e, 0.3) - law.force(v - e, 0.3)) / (2.0 * e);
            let (dv, dapp) = law.force_partials(v, 0.3);
            assert!((fd - dv).abs() < 1e-5 * dv.abs().max(1.0), "{fd} vs {dv}");
            assert_eq!(dapp, 0.0);
        }
        assert_eq!(law.force_partials(0.0, 1.0), (0.0, 1.0));
        assert_eq!(law.force_partials(0.0, 5.0), (0.0, 0.0));
    }
}
