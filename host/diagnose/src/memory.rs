//! The laws a LuGre nominal may move to when its pre-sliding is not
//! LuGre's: nonlocal memory (GMS) or an elastic stick (elasto-plastic).
//!
//! **Nonlocal memory.** LuGre's force in pre-sliding is a function of one
//! bristle state (Canudas de Wit et al. 1995): after a reversal the force
//! leaves its turning point at twice the virgin stiffness and forgets
//! every earlier turning point. A contact of many asperities behaves
//! otherwise: its pre-sliding curve after a reversal is the virgin curve
//! scaled by two (Masing's rule), every element stiffness acts at once
//! (the reversal stiffness equals the virgin one), and a minor loop is
//! wiped out when the path passes its start again. The Generalized
//! Maxwell-Slip model (Al-Bender, Lampaert and Swevers 2005) has that
//! memory, LuGre's Stribeck curve in gross sliding and a frictional lag
//! of its own (the attraction `C`). The GMS start has LuGre's Stribeck
//! curve (`Fc`, `Fs`, `vs`, δ, σ2) and [`GMS_ELEMENTS`] elements of equal
//! stiffness `σ0/N` whose slip distances are the quantiles of an
//! exponential, `Δ_i = −(Fs/σ0)·ln(1 − (i − ½)/N)`, with weights
//! `α_i ∝ k_i·Δ_i` (`Σα_i = 1`): its virgin curve `Σ min(k_i·x, α_i·Fs)`
//! then has LuGre's virgin stiffness `σ0·exp(−σ0·x/Fs)` in the mean and
//! its level `Fs`, so that the two laws differ in their memory, not in
//! their curve; LuGre's σ1 is the elements' total micro-damping. The fit
//! frees the levels, σ0 (σ1 following √σ0) and `C`.
//!
//! **An elastic stick.** Under a force that oscillates below break-away,
//! LuGre creeps a little every cycle; the elasto-plastic model of Dupont,
//! Hayward, Armstrong and Altpeter 2002 is a spring below its break-away
//! deflection `z_ba` and does not. Its start is LuGre's parameters with
//! `z_ba` a fraction of `Fc/σ0` ([`ELASTIC_FRACTION_STARTS`]); the fit
//! frees the levels, σ0 (σ1 following √σ0) and that fraction.
//!
//! The diagnosis moves a LuGre nominal to one of them the way it moves a
//! Dahl nominal to LuGre: with the fitted LuGre's levels as the start
//! (`stages/memory.rs` decides).

use crate::fit::Coordinates;
use crate::model::{stribeck_curve_parameters, FrictionModel};
use serde::Serialize;
use std::path::PathBuf;

/// Elements of the GMS the diagnosis tries: ten resolve the virgin
/// curve's bend to a tenth of its level, and one GMS step costs about what
/// a LuGre step does (BENCHMARKS.md, the law-step table).
pub const GMS_ELEMENTS: usize = 10;

/// Frictional-lag time constants `s/C` the GMS fit starts from (s): the
/// attraction `C = Fc/τ`.
pub const LAG_STARTS: [f64; 3] = [1e-3, 1e-2, 1e-1];

/// The frictional-lag time constants `Fc/C` a GMS fit may reach (s).
pub const LAG_RANGE: (f64, f64) = (1e-5, 10.0);

/// Break-away deflections the elasto-plastic fit starts from, as
/// fractions of `Fc/σ0`.
pub const ELASTIC_FRACTION_STARTS: [f64; 3] = [0.5, 0.8, 0.95];

/// A law other than LuGre that the diagnosis tries.
#[derive(Clone, Copy, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum OtherLaw {
    Gms,
    ElastoPlastic,
}

impl OtherLaw {
    pub const ALL: [OtherLaw; 2] = [OtherLaw::Gms, OtherLaw::ElastoPlastic];

    /// The FMU's model name (and file stem).
    pub fn model_name(self) -> &'static str {
        match self {
            OtherLaw::Gms => "GMS",
            OtherLaw::ElastoPlastic => "ElastoPlastic",
        }
    }

    /// The effect the report names when the nominal moves to it.
    pub fn effect(self) -> &'static str {
        match self {
            OtherLaw::Gms => "presliding_memory",
            OtherLaw::ElastoPlastic => "elastic_presliding",
        }
    }

    /// What the law has that LuGre has not, and its source.
    pub fn words(self) -> &'static str {
        match self {
            OtherLaw::Gms => "nonlocal pre-sliding memory (GMS, Al-Bender, Lampaert and Swevers 2005)",
            OtherLaw::ElastoPlastic => "an elastic stick without drift below break-away (elasto-plastic, Dupont, Hayward, Armstrong and Altpeter 2002)",
        }
    }

    /// The suffix of its files in the report directory
    /// (`refitted-gms.ssp`).
    pub fn file_tag(self) -> &'static str {
        match self {
            OtherLaw::Gms => "gms",
            OtherLaw::ElastoPlastic => "elastoplastic",
        }
    }

    /// The starts of its fit from the LuGre model `lugre`.
    pub fn starts(self, lugre: &FrictionModel) -> Vec<LawModel> {
        match self {
            OtherLaw::Gms => LAG_STARTS
                .iter()
                .map(|&lag| LawModel::Gms(GmsModel::from_lugre(lugre, lag)))
                .collect(),
            OtherLaw::ElastoPlastic => ELASTIC_FRACTION_STARTS
                .iter()
                .map(|&r| LawModel::ElastoPlastic(ElastoPlasticModel::from_lugre(lugre, r)))
                .collect(),
        }
    }
}

/// A fitted model of one of the [`OtherLaw`]s.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LawModel {
    Gms(GmsModel),
    ElastoPlastic(ElastoPlasticModel),
}

impl LawModel {
    /// Its FMU's parameters by name.
    pub fn parameters(&self) -> Vec<(String, f64)> {
        match self {
            LawModel::Gms(m) => m.parameters(),
            LawModel::ElastoPlastic(m) => m.parameters(),
        }
    }

    /// `(Fc, Fs, σ0, σ1)`: its Stribeck levels, its stiffness at a
    /// reversal (GMS: the elements' total) and micro-damping, as LuGre
    /// names them.
    pub fn levels(&self) -> (f64, f64, f64, f64) {
        match self {
            LawModel::Gms(g) => (g.fc, g.fs, g.sigma0, g.sigma1),
            LawModel::ElastoPlastic(e) => (e.fc, e.fs, e.sigma0, e.sigma1),
        }
    }

    /// `lugre` with this law's levels, stiffness and micro-damping: the
    /// LuGre model closest to it, whose pre-sliding differs only by the
    /// law's memory.
    pub fn as_lugre(&self, lugre: &FrictionModel) -> FrictionModel {
        let (fc, fs, sigma0, sigma1) = self.levels();
        let mut m = lugre.clone();
        m.fc = fc;
        m.fc_neg = fc;
        m.fs = fs;
        m.fs_neg = fs;
        m.sigma0 = sigma0;
        m.sigma1 = sigma1;
        m
    }

    /// Its parameters in words, for the report.
    pub fn describe(&self) -> String {
        match self {
            LawModel::Gms(g) => format!(
                "Fc = {:.4e} N, Fs = {:.4e} N, vs = {:.4e} m/s, σ1 = {:.4e} N·s/m, σ2 = {:.4e} N·s/m, {} elements of total stiffness {:.4e} N/m (pre-sliding distance {:.3e} m), C = {:.4e} N/s (lag {:.3e} s at Fc)",
                g.fc,
                g.fs,
                g.vs,
                g.sigma1,
                g.sigma2,
                g.elements,
                g.sigma0,
                g.presliding_distance(),
                g.attraction,
                g.fc / g.attraction
            ),
            LawModel::ElastoPlastic(e) => format!(
                "Fc = {:.4e} N, Fs = {:.4e} N, vs = {:.4e} m/s, σ0 = {:.4e} N/m, σ1 = {:.4e} N·s/m, σ2 = {:.4e} N·s/m, z_ba = {:.4e} m ({:.0} % of Fc/σ0)",
                e.fc,
                e.fs,
                e.vs,
                e.sigma0,
                e.sigma1,
                e.sigma2,
                e.z_ba,
                100.0 * e.z_ba * e.sigma0 / e.fc
            ),
        }
    }
}

/// A GMS friction law as the diagnosis fits it (SI units).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GmsModel {
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub stribeck_exponent: f64,
    pub sigma2: f64,
    /// The elements' total micro-damping (N·s/m), shared in proportion
    /// to their stiffness.
    pub sigma1: f64,
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
            sigma1: lugre.sigma1,
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
        let mut p = stribeck_curve_parameters(self.fc, self.fs, self.vs, self.stribeck_exponent);
        p.extend([
            ("sigma2".to_string(), self.sigma2),
            ("sigma1".to_string(), self.sigma1),
            ("C".to_string(), self.attraction),
            ("n_elements".to_string(), self.elements as f64),
        ]);
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

/// An elasto-plastic friction law as the diagnosis fits it (SI units;
/// the FMU's parameters).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ElastoPlasticModel {
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub stribeck_exponent: f64,
    pub sigma0: f64,
    pub sigma1: f64,
    pub sigma2: f64,
    /// The break-away deflection (m), below `Fc/σ0`.
    pub z_ba: f64,
}

impl ElastoPlasticModel {
    /// LuGre's parameters with `z_ba = fraction·Fc/σ0`.
    pub fn from_lugre(lugre: &FrictionModel, fraction: f64) -> ElastoPlasticModel {
        ElastoPlasticModel {
            fc: lugre.fc,
            fs: lugre.fs.max(lugre.fc),
            vs: lugre.vs,
            stribeck_exponent: lugre.stribeck_exponent,
            sigma0: lugre.sigma0,
            sigma1: lugre.sigma1,
            sigma2: lugre.sigma2,
            z_ba: fraction * lugre.fc / lugre.sigma0,
        }
    }

    /// The FMU's parameters.
    pub fn parameters(&self) -> Vec<(String, f64)> {
        let mut p = stribeck_curve_parameters(self.fc, self.fs, self.vs, self.stribeck_exponent);
        p.extend([
            ("sigma0".to_string(), self.sigma0),
            ("sigma1".to_string(), self.sigma1),
            ("sigma2".to_string(), self.sigma2),
            ("z_ba".to_string(), self.z_ba),
        ]);
        p
    }
}

/// What a fit of an [`OtherLaw`] moves, from `start`: `ln Fc`,
/// `ln(Fs/Fc − 1)` when the start has a Stribeck peak (else `Fs = Fc`
/// stays), `ln σ0` with σ1 following `√σ0`, and the law's own: GMS's
/// `ln C` as a logit within [`LAG_RANGE`], the elasto-plastic `z_ba` as `logit(z_ba·σ0/Fc)`. Every θ is a
/// valid model (`0 < Fc ≤ Fs`, σ0 and `C` positive, `0 < z_ba < Fc/σ0`).
pub struct LawCoordinates {
    pub start: LawModel,
}

impl LawCoordinates {
    /// `(Fc, Fs, σ0, σ1)` of the start.
    fn levels(&self) -> (f64, f64, f64, f64) {
        self.start.levels()
    }

    fn stribeck(&self) -> bool {
        let (fc, fs, _, _) = self.levels();
        fs > fc * (1.0 + 1e-9)
    }

    /// `ln C` is kept strictly inside `(low, high)`: lags `Fc/C` between
    /// [`LAG_RANGE`]'s ends at the start's `Fc`. Unbounded, a fit on data
    /// that do not resolve the lag wandered to `C` = 1e11 N/s, where the
    /// cost is flat, and stopped there.
    fn attraction_range(&self) -> (f64, f64) {
        let (fc, _, _, _) = self.levels();
        ((fc / LAG_RANGE.1).ln(), (fc / LAG_RANGE.0).ln())
    }
}

impl Coordinates for LawCoordinates {
    type Model = LawModel;

    fn theta(&self) -> Vec<f64> {
        let (fc, fs, sigma0, _) = self.levels();
        let own = match &self.start {
            LawModel::Gms(g) => {
                let (low, high) = self.attraction_range();
                let r = (g.attraction.ln() - low) / (high - low);
                (r / (1.0 - r)).ln()
            }
            LawModel::ElastoPlastic(e) => {
                let r = e.z_ba * e.sigma0 / e.fc;
                (r / (1.0 - r)).ln()
            }
        };
        let mut t = vec![fc.ln(), sigma0.ln(), own];
        if self.stribeck() {
            t.push((fs / fc - 1.0).ln());
        }
        t
    }

    fn at(&self, theta: &[f64]) -> LawModel {
        let (_, _, sigma0_start, sigma1_start) = self.levels();
        let fc = theta[0].exp();
        let sigma0 = theta[1].exp();
        let sigma1 = sigma1_start * (sigma0 / sigma0_start).sqrt();
        let fs = if self.stribeck() {
            fc * (1.0 + theta[3].exp())
        } else {
            fc
        };
        match &self.start {
            LawModel::Gms(g) => LawModel::Gms(GmsModel {
                fc,
                fs,
                sigma0,
                sigma1,
                attraction: {
                    let (low, high) = self.attraction_range();
                    (low + (high - low) / (1.0 + (-theta[2]).exp())).exp()
                },
                ..g.clone()
            }),
            LawModel::ElastoPlastic(e) => {
                let r = 1.0 / (1.0 + (-theta[2]).exp());
                LawModel::ElastoPlastic(ElastoPlasticModel {
                    fc,
                    fs,
                    sigma0,
                    sigma1,
                    z_ba: r * fc / sigma0,
                    ..e.clone()
                })
            }
        }
    }
}

/// What the check of one law decided.
#[derive(Clone, Debug, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum MemoryOutcome {
    /// It predicts the held-out data better than LuGre (and better than
    /// the other laws that do): the nominal moves to it.
    Moved,
    /// Tried; LuGre stays (or another law that predicts better).
    Kept,
    /// Not tried (`LawCheck::reason` says why).
    NotTried,
}

/// The check of one law, for the report.
#[derive(Clone, Debug, Serialize)]
pub struct LawCheck {
    pub law: OtherLaw,
    /// The effect named when the nominal moves to it.
    pub effect: &'static str,
    pub outcome: MemoryOutcome,
    /// Why it was not tried or not moved to, or what failed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Held-out RMS of the final LuGre model (normalised).
    pub lugre_heldout_rms: f64,
    /// Held-out RMS of the law fitted (normalised; NaN when not tried).
    pub heldout_rms: f64,
    /// Relative drop of the held-out mean square from LuGre to the law.
    pub gain: f64,
    /// One-sided p-value that the law explains the held-out data better.
    pub p_value: f64,
    /// The p-value had to be below this (α over the laws tried).
    pub threshold: f64,
    /// The law fitted on every sample (when tried).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fitted: Option<LawModel>,
    /// Where its FMU was found.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fmu: Option<PathBuf>,
    /// The effects the rounds found under LuGre that the move explains:
    /// the law fitted from the baseline (before them) predicts the
    /// held-out data as well as from the final model (the p-value that
    /// the final model's start does better, not below α), so that it is
    /// the one moved to and they are not named.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub explains: Vec<crate::model::Effect>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub explains_p_value: Option<f64>,
    /// Fitted from the baseline (the nominal's levels refitted, before
    /// the effects the rounds found): its fit from the final LuGre model
    /// did not pass, this one did, and it explains every effect found.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub from_baseline: bool,
    /// For a law that beat the final LuGre model: LuGre refitted from the
    /// law's levels and stiffness ([`LawModel::as_lugre`]), its held-out
    /// RMS and the p-value that the law predicts better. The nominal
    /// moves only when the law beats it too: else its gain was LuGre's
    /// own pre-sliding re-sized, not the law's memory.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lugre_at_law_stiffness: Option<LugreAtLawStiffness>,
    pub cosimulations: usize,
    pub seconds: f64,
    /// Its held-out co-simulation (for the comparisons).
    #[serde(skip)]
    pub(crate) scored: Option<crate::acceptance::Scored>,
}

/// LuGre refitted from a law's levels and stiffness
/// ([`LawCheck::lugre_at_law_stiffness`]).
#[derive(Clone, Debug, Serialize)]
pub struct LugreAtLawStiffness {
    /// The law's stiffness it started from (N/m), on the first fold.
    pub sigma0: f64,
    pub heldout_rms: f64,
    /// Relative drop of the held-out mean square from it to the law.
    pub gain: f64,
    /// One-sided p-value that the law predicts the held-out data better.
    pub p_value: f64,
}

impl LawCheck {
    pub(crate) fn not_tried(
        law: OtherLaw,
        lugre_rms: f64,
        threshold: f64,
        reason: String,
    ) -> LawCheck {
        LawCheck {
            law,
            effect: law.effect(),
            outcome: MemoryOutcome::NotTried,
            reason: Some(reason),
            lugre_heldout_rms: lugre_rms,
            heldout_rms: f64::NAN,
            gain: f64::NAN,
            p_value: f64::NAN,
            threshold,
            fitted: None,
            fmu: None,
            explains: Vec::new(),
            explains_p_value: None,
            from_baseline: false,
            lugre_at_law_stiffness: None,
            cosimulations: 0,
            seconds: 0.0,
            scored: None,
        }
    }
}

/// The check the nominal moved on, if any.
pub fn moved(checks: &[LawCheck]) -> Option<&LawCheck> {
    checks.iter().find(|c| c.outcome == MemoryOutcome::Moved)
}

/// The system `file` with its friction component `friction` on the FMU at
/// `path` (connected by the variables that FMU has: `v` and `F` for GMS
/// and the elasto-plastic law).
pub fn moved_to(
    file: &crate::ssp::SystemFile,
    friction: &str,
    path: &std::path::Path,
) -> Result<crate::ssp::SystemFile, String> {
    let fmu = crate::fmu::Fmu::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    file.with_component_source(friction, path, |c| fmu.variable(c).is_ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lugre() -> FrictionModel {
        let mut m = FrictionModel::coulomb_for_tests(2.0, 1e4, 40.0);
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
    fn coordinates_round_trip_and_keep_every_model_valid() {
        for law in OtherLaw::ALL {
            for start in law.starts(&lugre()) {
                let c = LawCoordinates {
                    start: start.clone(),
                };
                let t = c.theta();
                assert_eq!(t.len(), 4);
                let back = c.at(&t);
                for ((name, a), (_, b)) in back.parameters().iter().zip(start.parameters()) {
                    assert!((a - b).abs() <= 1e-12 * b.abs(), "{name}: {a} vs {b}");
                }
                for far in [[0.1, 3.0, -30.0, -40.0], [3.0, 12.0, 30.0, 5.0]] {
                    let m = c.at(&far);
                    let p: std::collections::BTreeMap<_, _> = m.parameters().into_iter().collect();
                    assert!(p["Fs"] >= p["Fc"] && p["Fc"] > 0.0);
                    // σ1 follows √σ0
                    let sigma0 = match &m {
                        LawModel::Gms(g) => g.elements().0.iter().sum(),
                        LawModel::ElastoPlastic(e) => e.sigma0,
                    };
                    let ratio = p["sigma1"] / f64::sqrt(sigma0);
                    let (s0, s1) = (lugre().sigma0, lugre().sigma1);
                    assert!((ratio - s1 / s0.sqrt()).abs() <= 1e-9 * ratio.abs().max(1e-300));
                    if let LawModel::ElastoPlastic(e) = &m {
                        assert!(e.z_ba >= 0.0 && e.z_ba < e.fc / e.sigma0, "{e:?}");
                    }
                }
            }
        }
        // without a Stribeck peak Fs follows Fc
        let mut flat = lugre();
        flat.fs = flat.fc;
        let c = LawCoordinates {
            start: OtherLaw::Gms.starts(&flat)[0].clone(),
        };
        assert_eq!(c.theta().len(), 3);
        let p: std::collections::BTreeMap<_, _> =
            c.at(&[1.0, 9.0, 4.0]).parameters().into_iter().collect();
        assert_eq!(p["Fs"], p["Fc"]);
    }

    /// The elasto-plastic start is LuGre's parameters with z_ba the given
    /// fraction of Fc/σ0.
    #[test]
    fn the_elastoplastic_start_is_lugre_with_a_break_away() {
        let l = lugre();
        let LawModel::ElastoPlastic(e) = &OtherLaw::ElastoPlastic.starts(&l)[1] else {
            panic!("not elasto-plastic")
        };
        assert_eq!(
            (e.fc, e.fs, e.sigma0, e.sigma1),
            (l.fc, l.fs, l.sigma0, l.sigma1)
        );
        assert!((e.z_ba - ELASTIC_FRACTION_STARTS[1] * l.fc / l.sigma0).abs() < 1e-18);
    }
}
