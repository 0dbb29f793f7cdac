//! Pre-sliding memory: LuGre's, or nonlocal (GMS).
//!
//! LuGre's force in pre-sliding is a function of one bristle state
//! (Canudas de Wit et al. 1995): after a reversal the force leaves its
//! turning point at twice the virgin stiffness and forgets every earlier
//! turning point. A contact of many asperities behaves otherwise: its
//! pre-sliding curve after a reversal is the virgin curve scaled by two
//! (Masing's rule), every element stiffness acts at once (the reversal
//! stiffness equals the virgin one), and a minor loop is wiped out when
//! the path passes its start again. The Generalized Maxwell-Slip model
//! (Al-Bender, Lampaert and Swevers 2005) has that memory, LuGre's Stribeck
//! curve in gross sliding and a frictional lag of its own (the attraction
//! `C`).
//!
//! The diagnosis moves a LuGre nominal to GMS the way it moves a Dahl
//! nominal to LuGre: with the fitted LuGre's levels as the start. The GMS
//! start has LuGre's Stribeck curve (`Fc`, `Fs`, `vs`, δ, σ2) and
//! [`GMS_ELEMENTS`] elements of equal stiffness `σ0/N` whose slip
//! distances are the quantiles of an exponential,
//! `Δ_i = −(Fs/σ0)·ln(1 − (i − ½)/N)`, with weights `α_i ∝ k_i·Δ_i`
//! (`Σα_i = 1`): its virgin curve `Σ min(k_i·x, α_i·Fs)` then has LuGre's
//! virgin stiffness `σ0·exp(−σ0·x/Fs)` in the mean and its level `Fs`, so
//! that the two laws differ in their memory, not in their curve. The fit
//! frees the levels, σ0 and `C` ([`GmsCoordinates`]).

use crate::fit::Coordinates;
use crate::model::FrictionModel;
use serde::Serialize;
use std::path::PathBuf;

/// Elements of the GMS the diagnosis tries: ten resolve the virgin
/// curve's bend to a tenth of its level, and one GMS step costs about what
/// a LuGre step does (BENCHMARKS.md, the law-step table).
pub const GMS_ELEMENTS: usize = 10;

/// Frictional-lag time constants `s/C` the GMS fit starts from (s): the
/// attraction `C = Fc/τ`.
pub const LAG_STARTS: [f64; 3] = [1e-3, 1e-2, 1e-1];

/// A GMS friction law as the diagnosis fits it (SI units).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GmsModel {
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub stribeck_exponent: f64,
    pub sigma2: f64,
    /// The elements' total stiffness `Σ k_i` (N/m): the stiffness of the
    /// virgin curve and of every reversal.
    pub sigma0: f64,
    /// The attraction `C` of a slipping element (N/s).
    pub attraction: f64,
    pub elements: usize,
}

impl GmsModel {
    /// The GMS with `lugre`'s Stribeck curve and pre-sliding stiffness and
    /// the frictional-lag time constant `lag` (s) at the Coulomb level.
    pub fn from_lugre(lugre: &FrictionModel, lag: f64) -> GmsModel {
        GmsModel {
            fc: lugre.fc,
            fs: lugre.fs.max(lugre.fc),
            vs: lugre.vs,
            stribeck_exponent: lugre.stribeck_exponent,
            sigma2: lugre.sigma2,
            sigma0: lugre.sigma0,
            attraction: lugre.fc / lag,
            elements: GMS_ELEMENTS,
        }
    }

    /// The element stiffnesses `k_i` (N/m) and weights `α_i` (`Σα_i = 1`)
    /// of [the module](self)'s exponential quantiles.
    pub fn elements(&self) -> (Vec<f64>, Vec<f64>) {
        let n = self.elements;
        let k = vec![self.sigma0 / n as f64; n];
        let slip: Vec<f64> = (0..n)
            .map(|i| -(1.0 - (i as f64 + 0.5) / n as f64).ln())
            .collect();
        let total: f64 = slip.iter().sum();
        let alpha = slip.iter().map(|d| d / total).collect();
        (k, alpha)
    }

    /// The GMS FMU's parameters (its names) for this model.
    pub fn parameters(&self) -> Vec<(String, f64)> {
        let mut p = vec![
            ("Fc".to_string(), self.fc),
            ("Fs".to_string(), self.fs),
            ("vs".to_string(), self.vs),
            ("stribeck_exponent".to_string(), self.stribeck_exponent),
            ("sigma2".to_string(), self.sigma2),
            ("C".to_string(), self.attraction),
            ("n_elements".to_string(), self.elements as f64),
        ];
        let (k, alpha) = self.elements();
        for (i, (k, a)) in k.iter().zip(&alpha).enumerate() {
            p.push((format!("k[{}]", i + 1), *k));
            p.push((format!("alpha[{}]", i + 1), *a));
        }
        p
    }

    /// The distance a relaxed contact travels before every element slips
    /// (m): the largest slip distance, `α_N·Fs/k_N`.
    pub fn presliding_distance(&self) -> f64 {
        let (k, alpha) = self.elements();
        k.iter()
            .zip(&alpha)
            .map(|(k, a)| a * self.fs / k)
            .fold(0.0, f64::max)
    }
}

/// What the GMS fit moves: `ln Fc`, `ln(Fs/Fc − 1)` when the start has a
/// Stribeck peak (else `Fs = Fc` stays), `ln σ0` and `ln C`: every θ is a
/// valid GMS (`0 < Fc ≤ Fs`, σ0 and `C` positive).
pub struct GmsCoordinates {
    pub start: GmsModel,
}

impl GmsCoordinates {
    fn stribeck(&self) -> bool {
        self.start.fs > self.start.fc * (1.0 + 1e-9)
    }
}

impl Coordinates for GmsCoordinates {
    type Model = GmsModel;

    fn theta(&self) -> Vec<f64> {
        let s = &self.start;
        let mut t = vec![s.fc.ln(), s.sigma0.ln(), s.attraction.ln()];
        if self.stribeck() {
            t.push((s.fs / s.fc - 1.0).ln());
        }
        t
    }

    fn at(&self, theta: &[f64]) -> GmsModel {
        let mut m = self.start.clone();
        m.fc = theta[0].exp();
        m.sigma0 = theta[1].exp();
        m.attraction = theta[2].exp();
        m.fs = if self.stribeck() {
            m.fc * (1.0 + theta[3].exp())
        } else {
            m.fc
        };
        m
    }
}

/// The effect's name in the report.
pub const PRESLIDING_MEMORY: &str = "presliding_memory";

/// What the check decided.
#[derive(Clone, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum MemoryOutcome {
    /// GMS predicts the held-out data better: the nominal moves to it.
    Moved,
    /// Tried; LuGre's memory stays (GMS not better by the rule).
    Kept,
    /// Not tried (`MemoryCheck::reason` says why).
    NotTried,
}

/// The check's result, for the report.
#[derive(Clone, Debug, Serialize)]
pub struct MemoryCheck {
    pub outcome: MemoryOutcome,
    /// Why it was not tried, or what failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Held-out RMS of the final LuGre model (normalised).
    pub lugre_heldout_rms: f64,
    /// Held-out RMS of the fitted GMS (normalised; NaN when not tried).
    pub gms_heldout_rms: f64,
    /// Relative drop of the held-out mean square from LuGre to GMS.
    pub gain: f64,
    /// One-sided p-value that GMS explains the held-out data better.
    pub p_value: f64,
    /// The p-value had to be below this (the family-wise α).
    pub threshold: f64,
    /// The GMS fitted on every sample (when tried).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gms: Option<GmsModel>,
    /// Where the GMS FMU was found.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gms_fmu: Option<PathBuf>,
    pub cosimulations: usize,
    pub seconds: f64,
}

impl MemoryCheck {
    pub(crate) fn not_tried(lugre_rms: f64, threshold: f64, reason: String) -> MemoryCheck {
        MemoryCheck {
            outcome: MemoryOutcome::NotTried,
            reason: Some(reason),
            lugre_heldout_rms: lugre_rms,
            gms_heldout_rms: f64::NAN,
            gain: f64::NAN,
            p_value: f64::NAN,
            threshold,
            gms: None,
            gms_fmu: None,
            cosimulations: 0,
            seconds: 0.0,
        }
    }
}

/// The system `file` with its friction component `friction` on the GMS
/// FMU at `gms` (connected by the variables GMS has: `v` and `F`).
pub fn moved_to_gms(
    file: &crate::ssp::SystemFile,
    friction: &str,
    gms: &std::path::Path,
) -> Result<crate::ssp::SystemFile, String> {
    let fmu = crate::fmu::Fmu::open(gms).map_err(|e| format!("{}: {e}", gms.display()))?;
    file.with_component_source(friction, gms, |c| fmu.variable(c).is_ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lugre() -> FrictionModel {
        let mut m = FrictionModel::coulomb_for_tests(2.0, 1e4, 0.0);
        m.fs = 2.6;
        m.vs = 0.01;
        m
    }

    /// The start's virgin curve `Σ min(k_i·x, α_i·Fs)` has LuGre's
    /// stiffness σ0 at the turning point and its level Fs once every
    /// element slips, and bends over like LuGre's `Fs·(1 − exp(−σ0·x/Fs))`
    /// (within 8 % of Fs along the way with ten elements).
    #[test]
    fn the_start_has_lugres_virgin_curve() {
        let g = GmsModel::from_lugre(&lugre(), 1e-2);
        let (k, alpha) = g.elements();
        assert_eq!(k.len(), GMS_ELEMENTS);
        assert!((alpha.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((k.iter().sum::<f64>() - g.sigma0).abs() < 1e-9 * g.sigma0);
        let virgin = |x: f64| -> f64 {
            k.iter()
                .zip(&alpha)
                .map(|(k, a)| (k * x).min(a * g.fs))
                .sum()
        };
        let d = g.fs / g.sigma0;
        // the first element slips after α_1·Fs/k_1: below it the curve is σ0·x
        let x0 = 0.5 * alpha[0] * g.fs / k[0];
        assert!((virgin(x0) - g.sigma0 * x0).abs() < 1e-12);
        assert!((virgin(g.presliding_distance()) - g.fs).abs() < 1e-12);
        let worst = (1..200)
            .map(|i| {
                let x = i as f64 * 0.03 * d;
                (virgin(x) - g.fs * (1.0 - (-x / d).exp())).abs() / g.fs
            })
            .fold(0.0, f64::max);
        assert!(worst < 0.08, "{worst}");
    }

    #[test]
    fn coordinates_round_trip_and_keep_fs_at_least_fc() {
        let c = GmsCoordinates {
            start: GmsModel::from_lugre(&lugre(), 1e-2),
        };
        let t = c.theta();
        assert_eq!(t.len(), 4);
        let back = c.at(&t);
        for (a, b) in [
            (back.fc, c.start.fc),
            (back.fs, c.start.fs),
            (back.sigma0, c.start.sigma0),
            (back.attraction, c.start.attraction),
        ] {
            assert!((a - b).abs() < 1e-12 * b);
        }
        let far = c.at(&[0.1, 3.0, -2.0, -40.0]);
        assert!(far.fs >= far.fc);
        // without a Stribeck peak Fs follows Fc
        let mut flat = lugre();
        flat.fs = flat.fc;
        let c = GmsCoordinates {
            start: GmsModel::from_lugre(&flat, 1e-2),
        };
        assert_eq!(c.theta().len(), 3);
        let m = c.at(&[1.0, 9.0, 4.0]);
        assert_eq!(m.fs, m.fc);
    }
}
