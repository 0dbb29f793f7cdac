//! `fricsim-diagnose`, the diagnosis of `fricsim diagnose`: where simulation and measurement disagree, which
//! physical effect is missing, the model with it added and refitted, and
//! the error on data the fit did not see.
//!
//! The workflow (docs/diagnose.md):
//! 1. co-simulate the nominal system with the measured inputs and compare
//!    it with the measured channels ([`sim::co_simulate`]); estimate the
//!    friction force the data imply ([`problem`]);
//! 2. refit the nominal friction parameters ([`fit`]) and take the
//!    refitted nominal model as the baseline;
//! 3. for every effect of the library ([`model::Effect`]) the model lacks:
//!    add it, refit its parameters together with the nominal ones, and
//!    co-simulate the whole system on the held-out data (a held-out file,
//!    one third of the time blocks, or, for short records, every block by
//!    three-fold cross-validation, [`CrossValidate`]);
//! 4. accept the candidate with the lowest held-out error only if it beats
//!    the current model significantly: Clark and West's one-sided test for
//!    nested models on the held-out samples ([`nested_test`]), grouped by
//!    held-out block or in [`Options::groups`] runs of consecutive
//!    samples, at level α divided by the number of candidates tried in the
//!    round (Bonferroni), and by at least [`Options::min_gain`] of the mean
//!    square. Extra parameters that only fit noise do not carry over to
//!    held-out data, so they are not rewarded. When no single effect is
//!    accepted, the pairs that interact ([`model::FrictionModel::interact`])
//!    are tried;
//! 5. repeat from 3 while a candidate is accepted;
//! 6. call the remaining discrepancy "unexplained" when its held-out RMS
//!    is more than twice the measurement-noise floor estimated from the
//!    data, and say where it lies ([`localise`]).

pub mod dahl;
pub mod figures;
pub mod fit;
pub mod html;
pub mod intervals;
pub mod localise;
pub mod model;
pub mod problem;
pub mod quality;
pub mod report;
pub mod sim;

// the co-simulation core's modules under the paths the diagnosis names
// them by
use fricsim_core::{fmu, inputs, master, plot, ssp, system, FmuError};

use model::{Effect, FrictionModel};
use problem::{FrictionData, Measured, Setup};
use rayon::prelude::*;
use serde::Serialize;
use sim::{
    co_simulate, co_simulate_robust, co_simulate_with, system_parameters, ChannelResiduals,
    FrictionSim,
};
use std::path::Path;
use std::time::Instant;

use crate::ssp::SystemFile;

/// Settings of the workflow.
#[derive(Clone, Debug)]
pub struct Options {
    /// Effects to try (default: the whole library).
    pub candidates: Vec<Effect>,
    /// Knots of the position table of `position_dependent`.
    pub position_knots: usize,
    /// Savitzky–Golay window for the inverse dynamics (s).
    pub smooth: f64,
    /// Family-wise significance level.
    pub alpha: f64,
    /// Smallest relative drop of the held-out mean square to accept.
    pub min_gain: f64,
    /// Groups of consecutive held-out samples in the paired test, and of
    /// training samples in the intervals ([`intervals`]).
    pub groups: usize,
    /// At most this many effects.
    pub max_effects: usize,
    /// Refine each accepted model on the output error of the training
    /// data ([`fit::polish`], [`POLISH_ITERATIONS`]).
    pub polish: bool,
    /// Equal time blocks the data are cut into when no held-out file is
    /// given; every third, from the second on, is held out.
    pub blocks: usize,
    /// Without a held-out file: hold out one phase of the blocks, or each
    /// of the three in turn ([`CrossValidate`]).
    pub cross_validate: CrossValidate,
    /// The master of the diagnosis's co-simulations (default: the system
    /// file's, with its inputs interpolated, [`diagnosis_master`]).
    pub master: Option<String>,
}

/// Without a held-out file, whether every block is scored (three-fold
/// cross-validation: each third of the blocks, `b mod 3`, is held out once,
/// the others fit), one third (`b mod 3 = 1`), or, with several records,
/// each record in turn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CrossValidate {
    /// With several records, each held out in turn ([`Self::Records`]);
    /// otherwise three folds when the data have at most
    /// [`CROSS_VALIDATE_MAX_SAMPLES`] samples (three times the fits, cheap
    /// at that size; short records need every sample's evidence), one
    /// third held out otherwise.
    Auto,
    Never,
    Always,
    /// Leave one record out: as many folds as records, each scoring one
    /// record with the model fitted on the others (the cross-test of
    /// Janot, Gautier and Brunot 2019 on EMPS's two records).
    Records,
}

/// [`CrossValidate::Auto`] cross-validates data with at most this many
/// samples (a table of break-away measurements: hundreds; a rig record at
/// 1 kHz: tens of thousands).
pub const CROSS_VALIDATE_MAX_SAMPLES: usize = 5_000;

impl Options {
    /// Refuse settings the workflow cannot use, naming the setting and its
    /// value (`fricsim diagnose` and the Python package call this first).
    pub fn check(&self) -> Result<(), String> {
        if let Some(m) = &self.master {
            crate::master::by_name(m).map_err(|e| format!("master: {e}"))?;
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err(format!("alpha {}: must be between 0 and 1", self.alpha));
        }
        if !(2..=32).contains(&self.position_knots) {
            return Err(format!(
                "position_knots {}: must be in 2..=32 (the LuGre table holds 32 points)",
                self.position_knots
            ));
        }
        if self.blocks < 3 {
            return Err(format!(
                "blocks {}: at least 3 (every third block is held out)",
                self.blocks
            ));
        }
        Ok(())
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            candidates: Effect::ALL.to_vec(),
            position_knots: model::DEFAULT_POSITION_KNOTS,
            smooth: 0.01,
            alpha: 0.01,
            min_gain: 0.02,
            groups: 20,
            max_effects: 4,
            polish: true,
            blocks: SPLIT_BLOCKS,
            cross_validate: CrossValidate::Auto,
            master: None,
        }
    }
}

/// The master the diagnosis co-simulates with: `requested` when given,
/// else the system file's with its inputs interpolated over each step
/// (`newton` → `newton-interpolated`, `gauss-seidel` →
/// `gauss-seidel-interpolated`; the others as they are). The data come
/// from a continuous system, and a master that holds each input over the
/// step is only first-order accurate: on a 1 kHz stick-slip record at a
/// 1 ms step, held inputs put the exact model 130 times the noise floor off
/// the data (slips timed to within a step), and a friction parameter
/// re-sized to offset that was named as an effect; interpolated, the exact
/// model sat at the noise floor (docs/diagnose.md).
pub fn diagnosis_master(file_master: &str, requested: Option<&str>) -> String {
    if let Some(m) = requested {
        return m.to_string();
    }
    match file_master {
        "newton" => "newton-interpolated".into(),
        "gauss-seidel" => "gauss-seidel-interpolated".into(),
        other => other.to_string(),
    }
}

/// Held-out blocks when no separate held-out file is given: the data are
/// cut into [`Options::blocks`] equal time blocks (default
/// [`SPLIT_BLOCKS`]), and every third block, from the second on, is held
/// out (a third of the data, spread over the whole experiment).
pub const SPLIT_BLOCKS: usize = 30;

/// Levenberg–Marquardt iterations (one Jacobian each) of the output-error
/// refinement of an accepted model ([`fit::polish`]); the fit stops
/// sooner when it converges. Three were too few: a Stribeck curve from the
/// force fit (whose noise near v = 0 biases Fs and vs) stayed 13 % off in
/// size and 80× the noise floor off the data.
pub const POLISH_ITERATIONS: usize = 12;

/// Levenberg–Marquardt iterations of each candidate's output-error fit
/// (presliding, or any effect when the plant gives no force estimate):
/// enough to rank candidates; the accepted one is refined further
/// ([`POLISH_ITERATIONS`]).
pub const CANDIDATE_OUTPUT_ERROR_ITERATIONS: usize = 3;

/// Whether time block `b` is held out (the phase held out by a single
/// split).
pub fn held_out_block(b: usize) -> bool {
    b % 3 == HELD_OUT_PHASE
}

/// Blocks of phase `b mod 3` = this are held out by a single split.
const HELD_OUT_PHASE: usize = 1;

/// Phases of the blocks: the folds of the cross-validation.
const PHASES: usize = 3;

/// A file's time span cut into equal blocks (at least 3), every third held
/// out ([`held_out_block`]); or, with several records each held out in
/// turn, one phase per record.
#[derive(Clone, Debug)]
pub struct Blocks {
    t0: f64,
    t1: f64,
    pub count: usize,
    /// Leave one record out: the joined start time of every record after
    /// the first (the phase of a time is its record).
    record_starts: Option<Vec<f64>>,
}

impl Blocks {
    pub fn new(time: &[f64], count: usize) -> Blocks {
        Blocks {
            t0: time.first().copied().unwrap_or(0.0),
            t1: time.last().copied().unwrap_or(0.0),
            count: count.max(3),
            record_starts: None,
        }
    }

    /// The blocks of `data` whose phases are its records
    /// ([`CrossValidate::Records`]).
    pub fn by_records(data: &Measured, count: usize) -> Blocks {
        Blocks {
            record_starts: Some(
                data.records[1..]
                    .iter()
                    .map(|r| data.time[r.rows.start])
                    .collect(),
            ),
            ..Blocks::new(&data.time, count)
        }
    }

    /// How many phases (folds of a cross-validation) there are.
    fn phases(&self) -> usize {
        self.record_starts.as_ref().map_or(PHASES, |s| s.len() + 1)
    }

    /// The block (0-based) holding time `t`.
    pub fn block(&self, t: f64) -> usize {
        let b = ((t - self.t0) / (self.t1 - self.t0) * self.count as f64) as usize;
        b.min(self.count - 1)
    }

    /// The phase (`b mod 3`) of the block holding time `t` (its record,
    /// when the records are the phases).
    pub fn phase(&self, t: f64) -> usize {
        match &self.record_starts {
            Some(starts) => starts.iter().filter(|&&s| s <= t).count(),
            None => self.block(t) % PHASES,
        }
    }

    /// Whether the block holding time `t` is held out by a single split.
    pub fn held_out(&self, t: f64) -> bool {
        self.phase(t) == HELD_OUT_PHASE
    }

    /// The positions of a co-simulation's samples (of the file with
    /// `time`) in blocks of `phase` (`held`) or of the other phases.
    fn picker<'a>(&self, time: &[f64], phase: usize, held: bool) -> Picker<'a> {
        let time = time.to_vec();
        let blocks = self.clone();
        Picker {
            pick: Box::new(move |r: &ChannelResiduals| {
                (0..r.samples.len())
                    .filter(|&s| (blocks.phase(time[r.samples[s]]) == phase) == held)
                    .collect()
            }),
            records: None,
        }
    }
}

/// One candidate tried in one round.
#[derive(Clone, Debug, Serialize)]
pub struct CandidateScore {
    /// The effect, or two joined by `+` when added together.
    pub name: String,
    /// Held-out RMS of the system with it (normalised, see `Diagnosis`).
    pub heldout_rms: f64,
    /// Relative drop of the held-out mean square.
    pub gain: f64,
    /// One-sided p-value of the paired test against the current model.
    pub p_value: f64,
    /// Why the data cannot tell the candidate from the current model, when
    /// they cannot (`unresolved_presliding`); then it is not accepted.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unresolved: Option<String>,
    /// Drop of the mean square and p-value when the current model and the
    /// candidate are co-simulated at a [`FINE_STEP_DIVISOR`] times finer
    /// step (checked for the candidates that pass at the system's step).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fine_step: Option<(f64, f64)>,
    /// Whether the held-out mean square drops by more than the current
    /// model's step error squared (`drop_beyond_step_error`).
    pub beyond_step_error: bool,
    /// RMS of the law's force against the force the data imply (N), training.
    pub force_rms: f64,
    pub fit_evaluations: usize,
    /// Why its co-simulation failed (then it is rejected).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
}

/// A LuGre FMU variable before and after a change, by the FMU's own name
/// and unit (what a user sets in the FMU).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct FmuValue {
    pub name: String,
    pub unit: String,
    pub before: f64,
    pub after: f64,
    /// The 95 % interval of `after` ([`intervals`]), for the final
    /// model's fitted parameters; `None` for a value not fitted (or no
    /// interval could be formed).
    pub interval: Option<[f64; 2]>,
}

/// `names` of the friction FMU from `before` to `after`, with the FMU's
/// units; a name `before` does not set has the FMU's start value there (a
/// name `after` does not carry is left out).
fn fmu_values(
    fmu: &crate::fmu::Fmu,
    names: &[String],
    before: &FrictionModel,
    after: &FrictionModel,
) -> Vec<FmuValue> {
    let (b, a): (
        std::collections::BTreeMap<String, f64>,
        std::collections::BTreeMap<String, f64>,
    ) = (
        before.parameters().into_iter().collect(),
        after.parameters().into_iter().collect(),
    );
    names
        .iter()
        .filter_map(|n| {
            let (unit, start) = match fmu.variable(n).ok().map(|v| &v.kind) {
                Some(crate::fmu::model_description::VariableKind::Real { unit, start, .. }) => {
                    (unit.clone().unwrap_or_default(), *start)
                }
                _ => (String::new(), None),
            };
            Some(FmuValue {
                name: n.clone(),
                unit,
                // a variable the model did not set had the FMU's start value
                before: b.get(n).copied().or(start).or(a.get(n).copied())?,
                after: *a.get(n)?,
                interval: None,
            })
        })
        .collect()
}

/// An accepted effect.
#[derive(Clone, Debug, Serialize)]
pub struct FoundEffect {
    pub name: Effect,
    /// `added` (the model lacked it) or `re-sized` (the nominal had it,
    /// at other values).
    pub action: &'static str,
    pub meaning: &'static str,
    /// Its parameters after the refit: name → value.
    pub parameters: serde_json::Map<String, serde_json::Value>,
    /// The same as LuGre FMU variables, before and after this effect.
    pub variables: Vec<FmuValue>,
    pub rms_before: f64,
    pub rms_after: f64,
    pub p_value: f64,
    /// p must be below this (α over the candidates of the round).
    pub threshold: f64,
    /// Where the improvement is concentrated.
    #[serde(rename = "where")]
    pub where_: localise::Where,
    /// The other explanations of the same signature, tried in the same
    /// round ([`Effect::ASYMMETRY`]); empty for an effect of no family.
    pub alternatives: Vec<Alternative>,
    /// When the other effect of an overlapping pair ([`Effect::OVERLAPPING`])
    /// passed in the same round: how the data separate the two, and what
    /// each adds to the other when fitted together.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub overlap: Option<OverlapCheck>,
    /// What the effect adds, as one number whose "no change" is 0
    /// ([`intervals::effect_change`]), in the final model, with its 95 %
    /// interval; `None` for an effect without such a number.
    pub change: Option<EffectChange>,
}

/// An effect accepted in an earlier round and taken out again once later
/// effects explained its gain: with them in the model, taking it out and
/// refitting the rest no longer loses what the test that admitted it asks
/// for (p below its threshold and a drop of at least `--min-gain`).
#[derive(Clone, Debug, Serialize)]
pub struct Withdrawn {
    pub name: Effect,
    /// The round that accepted it (1-based, as in `rounds`).
    pub accepted_in_round: usize,
    /// The round after whose acceptance it was re-examined and taken out.
    pub withdrawn_after_round: usize,
    /// The effects accepted in that round.
    pub explained_by: Vec<Effect>,
    /// Held-out RMS of the model with it and without it (refitted).
    pub heldout_rms_with: f64,
    pub heldout_rms_without: f64,
    /// What keeping it gains over the model without it, and the p of that
    /// gain ([`nested_test`]).
    pub gain: f64,
    pub p_value: f64,
    /// The threshold it passed when it was accepted.
    pub threshold: f64,
}

/// [`FoundEffect::change`].
#[derive(Clone, Debug, Serialize)]
pub struct EffectChange {
    pub quantity: &'static str,
    pub value: f64,
    pub interval: Option<[f64; 2]>,
    /// The interval excludes 0: the data resolve the effect. An effect
    /// whose interval holds 0 is reported as not resolved.
    pub resolved: Option<bool>,
}

/// Another explanation of an accepted effect's signature, and how strongly
/// the held-out data separate the two.
#[derive(Clone, Debug, Serialize)]
pub struct Alternative {
    pub name: String,
    pub heldout_rms: f64,
    /// One-sided p-value that the accepted effect's held-out squared error
    /// is below this one's ([`separation_test`]): below `threshold`, the
    /// data prefer the accepted one.
    pub p_value: f64,
    /// Whether this alternative passed the acceptance tests itself.
    pub passed: bool,
    /// The data separate the two: p below the round's threshold.
    pub separated: bool,
}

/// An effect and the other of its overlapping pair ([`Effect::OVERLAPPING`]),
/// both passing in one round: the one with the smaller held-out error is
/// named only when the held-out data separate it from the other
/// ([`separation_test`], the test that chooses within a family of
/// explanations); the two are also fitted together, and the joint model
/// tested against each alone ([`nested_test`]), for the report: whether
/// the other adds to it (then a later round can take it too).
#[derive(Clone, Debug, Serialize)]
pub struct OverlapCheck {
    /// The other effect of the pair.
    pub other: String,
    /// This effect added to the other (the joint model against the other
    /// alone): the relative drop of the held-out mean square and its
    /// p-value.
    pub gain_after_other: f64,
    pub p_after_other: f64,
    /// The other added to this effect.
    pub other_gain_after: f64,
    pub other_p_after: f64,
    /// One-sided p-value that this effect's held-out squared error is
    /// below the other's, each alone ([`separation_test`]): it is named
    /// only when this is below the round's threshold (the data prefer
    /// it); otherwise neither is.
    pub p_separated: f64,
}

/// Fit the effects of candidates `k` and `j` together, by output error,
/// from each one's fitted model (in parallel; the fit with the smaller
/// training error is the joint model), and test the joint model against
/// each alone on the held-out data ([`OverlapCheck`]): what `k`'s effect
/// adds to `j`'s, and `j`'s to `k`'s. Both candidates are output-error
/// fits here (see the round in [`diagnose_records`]), so the joint model
/// is compared with fits of its own kind. A joint fit whose co-simulation
/// fails counts as adding nothing.
fn overlap_check<F>(
    tried: &[Tried],
    k: usize,
    j: usize,
    try_round: &F,
    scales: &[f64],
    group: &[usize],
) -> Result<OverlapCheck, String>
where
    F: Fn(&[FrictionModel], &[Vec<Effect>], bool) -> Result<Vec<Tried>, String> + Sync,
{
    let after =
        |base: usize, added: &[Effect]| try_round(&tried[base].models, &[added.to_vec()], true);
    let (from_k, from_j) = rayon::join(|| after(k, &tried[j].added), || after(j, &tried[k].added));
    let joint = from_k?
        .into_iter()
        .chain(from_j?)
        .filter(|t| t.scored.is_ok())
        .min_by(|a, b| a.force_rms.total_cmp(&b.force_rms));
    let adds_to = |single: usize| match (&tried[single].scored, joint.as_ref().map(|t| &t.scored)) {
        (Ok(before), Some(Ok(after))) => nested_test(before, after, scales, group),
        _ => (f64::NEG_INFINITY, 1.0),
    };
    let ((gain_after_other, p_after_other), (other_gain_after, other_p_after)) =
        (adds_to(j), adds_to(k));
    let p_separated = match (&tried[k].scored, &tried[j].scored) {
        (Ok(better), Ok(other)) => separation_test(better, other, group),
        _ => 1.0,
    };
    Ok(OverlapCheck {
        other: label(&tried[j].added),
        gain_after_other,
        p_after_other,
        other_gain_after,
        other_p_after,
        p_separated,
    })
}

/// A record's time and its input columns (name, values).
pub type InputColumns = (Vec<f64>, Vec<(String, Vec<f64>)>);

/// Everything diagnose found.
#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    pub system: String,
    pub data: String,
    pub heldout: String,
    /// How the friction force was obtained from the data.
    pub force_source: String,
    /// The friction component refitted.
    pub friction_component: String,
    pub channels: Vec<ChannelSummary>,
    /// Held-out RMS of the nominal system as given (normalised).
    pub nominal_rms: f64,
    /// The nominal's levels refitted, and whether that was kept.
    pub refit: RefitDecision,
    /// Held-out RMS of the baseline: the refitted nominal when kept, else
    /// the nominal as given.
    pub baseline_rms: f64,
    /// Held-out RMS of the final model.
    pub final_rms: f64,
    pub effects: Vec<FoundEffect>,
    /// Effects accepted and later taken out because effects accepted after
    /// them explained their gain ([`Withdrawn`]).
    pub withdrawn: Vec<Withdrawn>,
    /// Every candidate tried, per round.
    pub rounds: Vec<Vec<CandidateScore>>,
    /// The p-value each round's candidates had to beat: α over the
    /// hypotheses of the round (one per candidate, one per family of
    /// explanations of one signature).
    pub round_thresholds: Vec<f64>,
    /// The final error is above [`UNEXPLAINED_FACTOR`] × `floor_rms`.
    pub unexplained: bool,
    /// Held-out RMS of the measurement noise estimated from the data, its
    /// quantisation included (normalised like the others).
    pub noise_floor_rms: f64,
    /// The co-simulation's own step error on the held-out samples (twice
    /// the RMS change of the final model's channels when the step is
    /// halved: a first-order bound).
    pub step_error_rms: f64,
    /// √(noise² + step error²): what no model of the library can go below.
    pub floor_rms: f64,
    /// Spikes, dropouts, gaps and saturation found in the files.
    pub data_quality: DataQuality,
    /// Co-simulations that needed a smaller step or another master.
    pub fallbacks: Vec<String>,
    /// What was changed in the nominal before the diagnosis (a Dahl
    /// friction moved to LuGre, [`dahl::move_to_lugre`]).
    pub notes: Vec<String>,
    /// Where the remaining discrepancy lies (the localisation of the final
    /// residual).
    pub residual_pattern: localise::Localisation,
    /// Localisation of the baseline's residual.
    pub baseline_pattern: localise::Localisation,
    pub nominal_model: FrictionModel,
    pub baseline_model: FrictionModel,
    pub final_model: FrictionModel,
    /// Every LuGre FMU parameter the final model sets differently from the
    /// nominal as given.
    pub changes: Vec<FmuValue>,
    pub samples: usize,
    pub heldout_samples: usize,
    /// Family-wise significance level.
    pub alpha: f64,
    /// The runs of consecutive samples the tests and intervals group the
    /// residuals into ([`Options::groups`]).
    pub groups: usize,
    /// Smallest relative drop of the held-out mean square accepted.
    pub min_gain: f64,
    /// Folds scored: 1 (a held-out file or one third of the blocks), 3
    /// (cross-validation, [`CrossValidate`]) or one per record (each held
    /// out in turn).
    pub folds: usize,
    pub wall_seconds: f64,
    /// Of which the output-error refinement of accepted models took this
    /// long, in this many co-simulations.
    pub polish_seconds: f64,
    pub polish_cosimulations: usize,
    pub step: f64,
    pub master: String,
    #[serde(skip)]
    pub plots: PlotData,
    /// Each data record's own time and the columns that drive inputs (for
    /// the `inputs.csv` that reruns the refitted system; `inputs-1.csv`,
    /// `inputs-2.csv`, ... for several records).
    #[serde(skip)]
    pub measured_inputs: Vec<InputColumns>,
    /// The same of the held-out records, when given
    /// (`heldout-inputs.csv`, or numbered likewise).
    #[serde(skip)]
    pub heldout_inputs: Vec<InputColumns>,
    /// The commands that rerun the refitted system on the training data's
    /// inputs and, with a held-out file, on its inputs, with the master
    /// and step the diagnosis co-simulated with: their results are the
    /// co-simulations the report scored (filled in by the report).
    pub rerun: Vec<String>,
}

/// The nominal's levels refitted (Fc, Fc_neg or the position scales, from
/// three starts) and tested against the nominal as given on the held-out
/// data by the same test as the effects: kept only when it beats the given
/// model, so that the diagnosis never ends worse than the model it was
/// given.
#[derive(Clone, Debug, Serialize)]
pub struct RefitDecision {
    pub heldout_rms: f64,
    pub gain: f64,
    pub p_value: f64,
    pub threshold: f64,
    pub kept: bool,
    /// RMS of the law's force against the force the data imply (N).
    pub force_rms: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
}

/// What [`quality::inspect`] found in each file.
#[derive(Clone, Debug, Serialize)]
pub struct DataQuality {
    pub data: quality::Quality,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heldout: Option<quality::Quality>,
}

/// The remaining error is "unexplained" above this many times the floor
/// (noise and step error).
pub const UNEXPLAINED_FACTOR: f64 = 2.0;

/// Per measured channel: RMS in its unit, nominal / baseline / final.
#[derive(Clone, Debug, Serialize)]
pub struct ChannelSummary {
    pub name: String,
    /// The scale the normalised RMS divides by (std of the channel).
    pub scale: f64,
    pub nominal_rms: f64,
    pub baseline_rms: f64,
    pub final_rms: f64,
}

/// (channel, measured, nominal, final) at the held-out samples.
pub type ChannelSeries = (String, Vec<f64>, Vec<f64>, Vec<f64>);

/// Which positions of a co-simulation's samples are held out.
/// The positions (into `ChannelResiduals::samples`) a [`Picker`] takes.
type PickFn<'a> = Box<dyn Fn(&ChannelResiduals) -> Vec<usize> + Sync + 'a>;

/// Which samples of a co-simulation a score or a fit uses (positions into
/// `ChannelResiduals::samples`), and which records must be co-simulated
/// for them (`None`: all).
struct Picker<'a> {
    pick: PickFn<'a>,
    records: Option<Vec<usize>>,
}

impl<'a> Picker<'a> {
    /// Every sample of every record.
    fn all() -> Picker<'a> {
        Picker {
            pick: Box::new(all_samples),
            records: None,
        }
    }

    /// Every sample of the records `records`.
    fn records(records: Vec<usize>) -> Picker<'a> {
        Picker {
            pick: Box::new(all_samples),
            records: Some(records),
        }
    }
}

/// Series for the plots.
#[derive(Clone, Debug, Default)]
pub struct PlotData {
    pub time: Vec<f64>,
    /// (channel, measured, nominal, final) at the held-out samples.
    pub channels: Vec<ChannelSeries>,
    /// Friction residual (N) before (baseline) and after (final) and the
    /// localising states at the held-out intervals.
    pub v: Vec<f64>,
    pub x: Vec<f64>,
    pub since_reversal: Vec<f64>,
    pub fn_: Option<Vec<f64>>,
    /// Metres moved since the last reversal, at the held-out intervals.
    pub displacement: Vec<f64>,
    /// The friction force the data imply (N), at the held-out intervals.
    pub force: Vec<f64>,
    pub residual_before: Vec<f64>,
    pub residual_after: Vec<f64>,
}

/// Every compared sample of a co-simulation.
fn all_samples(r: &ChannelResiduals) -> Vec<usize> {
    (0..r.samples.len()).collect()
}

/// The held-out part: the file scored and its friction intervals.
struct HeldOut<'a> {
    data: &'a Measured,
    friction: &'a FrictionData,
    /// Intervals of `friction` that are held out (by any fold).
    intervals: Vec<usize>,
}

/// One way of cutting the data into a part that fits and a part that is
/// scored: the held-out file, one third of the blocks, or one of the three
/// folds of a cross-validation.
struct Fold<'a> {
    /// Intervals of the training friction data the force fits use.
    train_intervals: Vec<usize>,
    /// Positions (into `ChannelResiduals::samples`) of a co-simulation of
    /// the held-out data that this fold scores.
    held: Picker<'a>,
    /// Positions of a co-simulation of the training data that this fold's
    /// output-error refinement uses.
    train: Picker<'a>,
}

/// Channel scales: the standard deviation of each measured channel (1 for
/// a constant one).
fn channel_scales(data: &Measured) -> Vec<f64> {
    data.outputs
        .iter()
        .map(|(_, v)| {
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
            if sd > 0.0 {
                sd
            } else {
                1.0
            }
        })
        .collect()
}

/// The co-simulation step: the system file's, else the data's median
/// sample spacing.
fn step_of(file: &SystemFile, data: &Measured) -> f64 {
    match file.settings.step_size {
        Some(h) => h,
        None => quality::median_spacing(&data.time),
    }
}

/// The held-out RMS of the system with `model` against `reference`, a
/// noise-free copy of the measurements `data` (same columns; the
/// hidden-effect suite's truth): its inputs drive the co-simulation, and
/// the residuals are normalised by `data`'s channel scales and taken on
/// the blocks a single split holds out, as [`diagnose`] does. This is the
/// model error alone, which, unlike the error against measurements, is not
/// bounded below by the measurement noise.
pub fn truth_rms(
    file: &SystemFile,
    data: &Path,
    reference: &Path,
    model: &FrictionModel,
    options: &Options,
) -> Result<f64, String> {
    let mut system = file.build(0.0).map_err(|e| e.to_string())?;
    let measured = Measured::read(data, &system)?;
    let truth = Measured::read(reference, &system)?;
    let setup = Setup::new(
        file,
        &mut system,
        step_of(file, &measured),
        &diagnosis_master(
            &file.settings.master_or_default(),
            options.master.as_deref(),
        ),
    )?;
    let params = system_parameters(file, &setup, model);
    let r = co_simulate(&mut system, &params, &setup, &truth)?;
    if let Some(e) = &r.incomplete {
        return Err(format!(
            "{}: the co-simulation stopped early: {e}",
            truth.label
        ));
    }
    let picked = (Blocks::new(&measured.time, options.blocks)
        .picker(&truth.time, HELD_OUT_PHASE, true)
        .pick)(&r);
    let q = r.squared(&channel_scales(&measured));
    Ok((picked.iter().map(|&k| q[k]).sum::<f64>() / picked.len().max(1) as f64).sqrt())
}

/// Run the workflow on `system` with the measurements `data` (and a
/// separate held-out file, else the held-out blocks of `data`).
pub fn diagnose(
    file: &SystemFile,
    data_path: &Path,
    heldout_path: Option<&Path>,
    options: &Options,
) -> Result<Diagnosis, String> {
    diagnose_records(
        file,
        &[data_path.to_path_buf()],
        &heldout_path
            .map(Path::to_path_buf)
            .into_iter()
            .collect::<Vec<_>>(),
        options,
    )
}

/// Run the workflow on `system` with one or several records of
/// measurements `data` (one model fitted to all of them, each record
/// co-simulated from its own start with its own inputs,
/// [`problem::Record`]), scored on the records `heldout` or, without
/// them, on held-out parts of `data` ([`Options::cross_validate`]).
pub fn diagnose_records(
    file: &SystemFile,
    data_paths: &[std::path::PathBuf],
    heldout_paths: &[std::path::PathBuf],
    options: &Options,
) -> Result<Diagnosis, String> {
    let started = Instant::now();
    let mut system = file.build(0.0).map_err(|e| e.to_string())?;
    let read_all = |paths: &[std::path::PathBuf], system: &crate::system::System| {
        paths
            .iter()
            .map(|p| Measured::read(p, system))
            .collect::<Result<Vec<_>, _>>()
            .and_then(Measured::join)
    };
    let train = read_all(data_paths, &system)?;
    let heldout_file = match heldout_paths.is_empty() {
        false => {
            let h = read_all(heldout_paths, &system)?;
            let a: Vec<&String> = train.outputs.iter().map(|(n, _)| n).collect();
            let b: Vec<&String> = h.outputs.iter().map(|(n, _)| n).collect();
            if a != b {
                return Err(format!(
                    "{}: measures {:?}, but {} measures {:?}; both files must measure the same channels",
                    h.label, b, train.label, a
                ));
            }
            Some(h)
        }
        true => None,
    };
    let step = step_of(file, &train);
    let master = diagnosis_master(
        &file.settings.master_or_default(),
        options.master.as_deref(),
    );
    let setup = Setup::new(file, &mut system, step, &master)?;
    // the force the data imply, or (any other plant, no measured force)
    // the law's states along the nominal co-simulation, and every fit by
    // output error
    let output_error_only = setup.force_estimable(&train).err();
    let friction_data = |system: &mut crate::system::System, data: &Measured| {
        match &output_error_only {
        None => setup.friction_data(system, data, options.smooth),
        Some(why) => sim::friction_data_simulated(&setup, file, system, data, why).map_err(|e| {
            format!(
                "{}: the friction force cannot be estimated from the data ({why}), and the nominal system could not be co-simulated along it to fit by output error: {e}",
                data.label
            )
        }),
    }
    };
    let d_train = friction_data(&mut system, &train)?;
    let d_held = match &heldout_file {
        Some(h) => Some(friction_data(&mut system, h)?),
        None => None,
    };

    // which samples and intervals train and which are held out
    let by_records = heldout_file.is_none()
        && train.records.len() > 1
        && matches!(
            options.cross_validate,
            CrossValidate::Auto | CrossValidate::Records
        );
    if heldout_file.is_none() && !by_records && options.cross_validate == CrossValidate::Records {
        return Err(format!(
            "{}: cross-validation by records needs at least two records (give several data files)",
            train.label
        ));
    }
    let blocks = if by_records {
        Blocks::by_records(&train, options.blocks)
    } else {
        Blocks::new(&train.time, options.blocks)
    };
    let trusted =
        |d: &FrictionData| -> Vec<usize> { (0..d.t.len()).filter(|&j| d.trusted[j]).collect() };
    let all_intervals = trusted(&d_train);
    let cross = heldout_file.is_none()
        && match options.cross_validate {
            CrossValidate::Always | CrossValidate::Records => true,
            CrossValidate::Never => false,
            CrossValidate::Auto => by_records || train.time.len() <= CROSS_VALIDATE_MAX_SAMPLES,
        };
    let (held, folds): (HeldOut, Vec<Fold>) = match (&heldout_file, &d_held) {
        (Some(h), Some(dh)) => (
            HeldOut {
                data: h,
                friction: dh,
                intervals: trusted(dh),
            },
            vec![Fold {
                train_intervals: all_intervals.clone(),
                held: Picker::all(),
                train: Picker::all(),
            }],
        ),
        _ => {
            let phases: Vec<usize> = if cross {
                (0..blocks.phases()).collect()
            } else {
                vec![HELD_OUT_PHASE]
            };
            let folds = phases
                .iter()
                .map(|&phase| Fold {
                    train_intervals: all_intervals
                        .iter()
                        .copied()
                        .filter(|&j| blocks.phase(d_train.t[j]) != phase)
                        .collect(),
                    // by records: only the records a fold scores or fits
                    // are co-simulated for it
                    held: if by_records {
                        Picker::records(vec![phase])
                    } else {
                        blocks.picker(&train.time, phase, true)
                    },
                    train: if by_records {
                        Picker::records((0..train.records.len()).filter(|&r| r != phase).collect())
                    } else {
                        blocks.picker(&train.time, phase, false)
                    },
                })
                .collect();
            let intervals = all_intervals
                .iter()
                .copied()
                .filter(|&j| phases.contains(&blocks.phase(d_train.t[j])))
                .collect();
            (
                HeldOut {
                    data: &train,
                    friction: &d_train,
                    intervals,
                },
                folds,
            )
        }
    };
    let fewest_train = folds
        .iter()
        .map(|f| f.train_intervals.len())
        .min()
        .unwrap_or(0);
    if fewest_train < problem::MIN_SAMPLES / 2 || held.intervals.len() < options.groups {
        return Err(format!(
            "{}: too few samples to fit ({}) and hold out ({})",
            train.label,
            fewest_train,
            held.intervals.len()
        ));
    }

    let scales = channel_scales(&train);

    let context = setup.context(&d_train, options.position_knots);
    // `models` (one per fold) co-simulated on the held-out data and scored
    // on its fold's samples: merged, every scored sample comes from a model
    // that was not fitted on it. `step`: None for the system's step with
    // the fallbacks of [`co_simulate_robust`], or a finer step without
    // them (for the co-simulation's own step error and for the check that
    // an improvement survives a finer step)
    let score_with = |system: &mut crate::system::System,
                      models: &[FrictionModel],
                      step: Option<f64>|
     -> Result<Scored, String> {
        let mut merged: Option<ChannelResiduals> = None;
        let mut picked = Vec::new();
        let mut notes = Vec::new();
        for (fold, model) in folds.iter().zip(models) {
            let params = system_parameters(file, &setup, model);
            let records = fold.held.records.as_deref();
            let r = match step {
                None => {
                    let (r, note) =
                        co_simulate_robust(system, &params, &setup, held.data, records)?;
                    notes.extend(note);
                    r
                }
                Some(h) => {
                    let r =
                        co_simulate_with(system, &params, held.data, records, &setup.master, h)?;
                    if let Some(e) = &r.incomplete {
                        return Err(e.clone());
                    }
                    r
                }
            };
            let mine = (fold.held.pick)(&r);
            if records.is_some() {
                // each fold co-simulated its own records, in order: their
                // samples follow the previous folds'
                let m = merged.get_or_insert_with(|| ChannelResiduals::empty(&r.channels));
                for &k in &mine {
                    picked.push(m.samples.len());
                    m.samples.push(r.samples[k]);
                    for c in 0..m.residuals.len() {
                        m.simulated[c].push(r.simulated[c][k]);
                        m.residuals[c].push(r.residuals[c][k]);
                    }
                }
                continue;
            }
            let m = merged.get_or_insert_with(|| r.clone());
            if m.samples != r.samples {
                return Err("the folds' co-simulations compared different samples".into());
            }
            for &k in &mine {
                for c in 0..m.residuals.len() {
                    m.simulated[c][k] = r.simulated[c][k];
                    m.residuals[c][k] = r.residuals[c][k];
                }
            }
            picked.extend(mine);
        }
        let residuals = merged.ok_or("no fold to score")?;
        picked.sort_unstable();
        let q_all = residuals.squared(&scales);
        let q = picked.iter().map(|&k| q_all[k]).collect();
        Ok(Scored {
            residuals,
            picked,
            q,
            fallback: (!notes.is_empty()).then(|| notes.join("; ")),
        })
    };
    let score = |system: &mut crate::system::System, models: &[FrictionModel]| {
        score_with(system, models, None)
    };
    let scored_at_step =
        |system: &mut crate::system::System, models: &[FrictionModel], step: f64| {
            score_with(system, models, Some(step))
        };
    let fine_step = setup.step / FINE_STEP_DIVISOR;
    // the co-simulation's step error of `models` scored as `scored`
    let step_error_of =
        |system: &mut crate::system::System, models: &[FrictionModel], scored: &Scored| -> f64 {
            scored_at_step(system, models, fine_step)
                .map_or(0.0, |fine| step_error_floor(scored, &fine, &scales))
        };

    // refine a model on the output error of the training samples `pick`
    // ([`fit::polish`])
    // the normalised output residuals of `m` on the training samples `pick`
    // (`step`: at that macro step instead, with the diagnosis's master and
    // no fallback)
    let train_residuals_at =
        |m: &FrictionModel, pick: &Picker, step: Option<f64>| -> Option<nalgebra::DVector<f64>> {
            // a system of its own (an FMU instance stays on its thread)
            let mut system = file.build(0.0).ok()?;
            let params = system_parameters(file, &setup, m);
            let records = pick.records.as_deref();
            let r = match step {
                None => {
                    co_simulate_robust(&mut system, &params, &setup, &train, records)
                        .ok()?
                        .0
                }
                Some(h) => {
                    co_simulate_with(&mut system, &params, &train, records, &setup.master, h)
                        .ok()?
                }
            };
            if r.incomplete.is_some() {
                return None;
            }
            let picked = (pick.pick)(&r);
            let channels = scales.len();
            let norm = ((picked.len() * channels) as f64).sqrt();
            Some(nalgebra::DVector::from_iterator(
                picked.len() * channels,
                picked.iter().flat_map(|&s| {
                    let (r, scales) = (&r, &scales);
                    (0..channels).map(move |c| r.residuals[c][s] / scales[c] / norm)
                }),
            ))
        };
    let train_residuals = |m: &FrictionModel, pick: &Picker| train_residuals_at(m, pick, None);
    let polish = |model: &FrictionModel, pick: &Picker, iterations: usize| -> fit::Fitted {
        let mut residual = |models: &[FrictionModel]| -> Vec<Option<nalgebra::DVector<f64>>> {
            models
                .par_iter()
                .map(|m| train_residuals(m, pick))
                .collect()
        };
        let budget = iterations * (model.free().len() + 1) + 1;
        fit::polish(model, &mut residual, budget)
    };
    // fit by output error alone, for an effect the force the data imply
    // cannot show (presliding: its hysteresis lives in the stick, which the
    // force fits leave out): the starts scored by co-simulating the
    // training samples `pick`, then the best refined ([`fit::polish`])
    let fit_output_error = |starts: &[FrictionModel], pick: &Picker| -> fit::Fitted {
        let costs: Vec<f64> = starts
            .par_iter()
            .map(|m| train_residuals(m, pick).map_or(f64::INFINITY, |r| r.norm_squared()))
            .collect();
        let best = (0..starts.len())
            .min_by(|&a, &b| costs[a].total_cmp(&costs[b]))
            .unwrap_or(0);
        let mut fitted = polish(&starts[best], pick, CANDIDATE_OUTPUT_ERROR_ITERATIONS);
        fitted.evaluations += starts.len();
        fitted
    };
    let every_sample = Picker::all();
    // the model reported: fitted on every training interval (the fold's
    // own model when there is one fold)
    let fit_whole = |starts: &[FrictionModel],
                     fold_models: &[FrictionModel]|
     -> Result<FrictionModel, String> {
        if folds.len() == 1 {
            return Ok(fold_models[0].clone());
        }
        let mut sim = FrictionSim::new(&setup.friction_fmu)?;
        Ok(fit::fit(starts, &mut sim, &d_train, &all_intervals).model)
    };
    // fit `starts` (per fold: built from that fold's model) on each fold by
    // output error alone ([`fit_output_error`])
    // (`also`: one more start per fold, the force fit's result when there
    // is one)
    let fit_folds_output_error = |starts: &(dyn Fn(&FrictionModel) -> Vec<FrictionModel>
                                        + Sync),
                                  base: &[FrictionModel],
                                  also: &[FrictionModel]|
     -> (Vec<FrictionModel>, f64, usize) {
        let fitted: Vec<fit::Fitted> = folds
            .iter()
            .zip(base)
            .enumerate()
            .map(|(i, (fold, b))| {
                let mut s = starts(b);
                s.extend(also.get(i).cloned());
                fit_output_error(&s, &fold.train)
            })
            .collect();
        let rms = fitted.iter().map(|f| f.rms).sum::<f64>() / fitted.len() as f64;
        let evaluations = fitted.iter().map(|f| f.evaluations).sum();
        (
            fitted.into_iter().map(|f| f.model).collect(),
            rms,
            evaluations,
        )
    };
    // fit `starts` (per fold: built from that fold's model) on each fold
    let fit_folds = |starts: &(dyn Fn(&FrictionModel) -> Vec<FrictionModel> + Sync),
                     base: &[FrictionModel]|
     -> Result<(Vec<FrictionModel>, f64, usize), String> {
        let fitted: Vec<Result<fit::Fitted, String>> = folds
            .par_iter()
            .zip(base)
            .map(|(fold, b)| {
                let mut sim = FrictionSim::new(&setup.friction_fmu)?;
                Ok(fit::fit(
                    &starts(b),
                    &mut sim,
                    &d_train,
                    &fold.train_intervals,
                ))
            })
            .collect();
        let fitted: Vec<fit::Fitted> = fitted.into_iter().collect::<Result<_, _>>()?;
        let rms = fitted.iter().map(|f| f.rms).sum::<f64>() / fitted.len() as f64;
        let evaluations = fitted.iter().map(|f| f.evaluations).sum();
        Ok((
            fitted.into_iter().map(|f| f.model).collect(),
            rms,
            evaluations,
        ))
    };

    // by output error when the force cannot show the addition (presliding)
    // or is not estimated at all (another plant), else on the force
    let by_output_error =
        |added: &[Effect]| output_error_only.is_some() || added.contains(&Effect::Presliding);
    // (`oe`: by output error whatever the addition, the force fit's result
    // as a start: an effect fitted to compete with one fitted so, see
    // [`Effect::OVERLAPPING`])
    let fit_folds_any = |starts: &(dyn Fn(&FrictionModel) -> Vec<FrictionModel> + Sync),
                         base: &[FrictionModel],
                         added: &[Effect],
                         oe: bool|
     -> Result<(Vec<FrictionModel>, f64, usize), String> {
        if output_error_only.is_some() {
            Ok(fit_folds_output_error(starts, base, &[]))
        } else if oe || by_output_error(added) {
            // the force fit's result as one more start: what the force
            // shows of the effect outside the stick
            let (forced, _, n) = fit_folds(starts, base)?;
            let (models, rms, m) = fit_folds_output_error(starts, base, &forced);
            Ok((models, rms, n + m))
        } else {
            fit_folds(starts, base)
        }
    };
    let fit_whole_any = |starts: &[FrictionModel],
                         fold_models: &[FrictionModel],
                         added: &[Effect],
                         oe: bool|
     -> Result<FrictionModel, String> {
        if (oe || by_output_error(added)) && folds.len() > 1 {
            Ok(fit_output_error(starts, &every_sample).model)
        } else {
            fit_whole(starts, fold_models)
        }
    };

    // the nominal as given: always a baseline, and the one kept unless its
    // levels refitted beat it on held-out data
    let mut sim = FrictionSim::new(&setup.friction_fmu)?;
    let nominal_folds = vec![setup.nominal.clone(); folds.len()];
    let nominal_scored = score(&mut system, &nominal_folds).map_err(|e| {
        format!(
            "the nominal system as given cannot be co-simulated on {}: {e}",
            held.data.label
        )
    })?;
    // the groups of the acceptance test: the held-out blocks when there
    // are at least `groups` of them (each block an independent trial,
    // `--blocks`), else `groups` runs of consecutive held-out samples
    let group: Vec<usize> = {
        let picked = &nominal_scored.picked;
        let n = picked.len();
        let by_block: Vec<usize> = picked
            .iter()
            .map(|&k| blocks.block(held.data.time[nominal_scored.residuals.samples[k]]))
            .collect();
        let held_blocks = 1 + by_block.windows(2).filter(|w| w[0] != w[1]).count();
        if heldout_file.is_none() && held_blocks >= options.groups {
            by_block
        } else {
            let g = options.groups.clamp(2, n.max(2));
            (0..n).map(|i| i * g / n.max(1)).collect()
        }
    };
    // the levels refitted (the effects' own parameters stay as given: an
    // effect that is off is a candidate of its own), from the nominal and
    // from levels 20 % lower and 25 % higher
    let level_starts = |m: &FrictionModel| -> Vec<FrictionModel> {
        [1.0, 0.8, 1.25].map(|f| m.scaled_levels(f)).to_vec()
    };
    let (refit_folds, refit_force_rms, _) =
        fit_folds_any(&level_starts, &nominal_folds, &[], false)?;
    let refit_model = fit_whole_any(&level_starts(&setup.nominal), &refit_folds, &[], false)?;
    let refit_scored = score(&mut system, &refit_folds);
    let refit_threshold = options.alpha;
    let nominal_step_error = step_error_of(&mut system, &nominal_folds, &nominal_scored);
    let refit = match &refit_scored {
        Ok(scored) => {
            let (gain, p_value) = nested_test(&nominal_scored, scored, &scales, &group);
            let heldout_rms = mean(&scored.q).sqrt();
            RefitDecision {
                heldout_rms,
                gain,
                p_value,
                threshold: refit_threshold,
                kept: p_value < refit_threshold
                    && gain >= options.min_gain
                    && drop_beyond_step_error(&nominal_scored, heldout_rms, nominal_step_error),
                force_rms: refit_force_rms,
                failure: None,
            }
        }
        Err(e) => RefitDecision {
            heldout_rms: f64::INFINITY,
            gain: f64::NEG_INFINITY,
            p_value: 1.0,
            threshold: refit_threshold,
            kept: false,
            force_rms: refit_force_rms,
            failure: Some(e.clone()),
        },
    };
    let (baseline_model, baseline_folds, baseline_scored) = match refit_scored {
        Ok(scored) if refit.kept => (refit_model.clone(), refit_folds, scored),
        _ => (
            setup.nominal.clone(),
            nominal_folds.clone(),
            nominal_scored.clone(),
        ),
    };

    // the current model's step error: what a quarter step changes in its
    // outputs (a drop of the error smaller than that may compensate the
    // co-simulation's step error, not physics); recomputed when the
    // current model changes
    let mut current_step_error = if refit.kept {
        step_error_of(&mut system, &baseline_folds, &baseline_scored)
    } else {
        nominal_step_error
    };
    let mut current = baseline_model.clone();
    let mut current_folds = baseline_folds;
    let mut current_scored = baseline_scored.clone();
    let mut effects: Vec<FoundEffect> = Vec::new();
    // per accepted effect: its round, the model it was added to, and
    // whether it was fitted by output error
    let mut accepted_as: Vec<(usize, FrictionModel, bool)> = Vec::new();
    let mut withdrawn: Vec<Withdrawn> = Vec::new();
    let mut rounds = Vec::new();
    let mut round_thresholds = Vec::new();
    let mut notes: Vec<String> = Vec::new();
    // the starts of an addition to a model: its first effects added
    // neutrally, the last from a grid
    // (and the same from the levels as given, when the baseline's refit
    // moved them: a refit of the levels alone may have bent them to mimic
    // the missing effect, a raised Fc standing in for a viscous term)
    let nominal_levels = setup.nominal.clone();
    let addition_starts = |added: &[Effect]| {
        let added = added.to_vec();
        let context = &context;
        let nominal_levels = &nominal_levels;
        move |m: &FrictionModel| -> Vec<FrictionModel> {
            let (last, first) = added.split_last().expect("an addition has an effect");
            let mut base = m.clone();
            for &e in first {
                base = base.with(e, context);
            }
            let mut s = starts(&base, *last, context);
            let given = base.with_levels_of(nominal_levels);
            if given != base {
                s.extend(starts(&given, *last, context));
            }
            s
        }
    };
    // one round: fit and score each addition (one effect, or two at once)
    // (`oe`: each fitted by output error, [`fit_folds_any`])
    let try_round = |current_folds: &[FrictionModel],
                     additions: &[Vec<Effect>],
                     oe: bool|
     -> Result<Vec<Tried>, String> {
        additions
            .par_iter()
            .map(|added| {
                let (models, force_rms, evaluations) =
                    fit_folds_any(&addition_starts(added), current_folds, added, oe)?;
                let mut system = file.build(0.0).map_err(|e| e.to_string())?;
                // a candidate whose co-simulation fails is rejected, not fatal
                let scored = score(&mut system, &models);
                Ok(Tried {
                    added: added.clone(),
                    by_output_error: oe || by_output_error(added),
                    models,
                    force_rms,
                    evaluations,
                    scored,
                })
            })
            .collect()
    };
    // refine accepted fold models and the reported model on the output
    // error of their training data ([`fit::polish`]); the fold models are
    // kept unrefined if a refined one's co-simulation fails, or if the
    // refinement raises the held-out error (it fits the training samples'
    // noise): a reference worse than the fits it came from would let
    // every candidate of the next round pass for undoing it. The reported
    // model is refined too, unless its folds' refinement was not kept.
    let polish_runs = std::cell::Cell::new(0usize);
    let polish_seconds = std::cell::Cell::new(0.0f64);
    let refine = |system: &mut crate::system::System,
                  models: Vec<FrictionModel>,
                  scored: Scored,
                  whole: FrictionModel|
     -> (Vec<FrictionModel>, Scored, FrictionModel) {
        let started = Instant::now();
        let polished: Vec<fit::Fitted> = folds
            .iter()
            .zip(&models)
            .map(|(fold, m)| polish(m, &fold.train, POLISH_ITERATIONS))
            .collect();
        polish_runs.set(polish_runs.get() + polished.iter().map(|p| p.evaluations).sum::<usize>());
        let refined: Vec<FrictionModel> = polished.into_iter().map(|p| p.model).collect();
        let (models, scored, kept) = if refined == models {
            (models, scored, true)
        } else {
            match score(system, &refined) {
                Ok(s) if mean(&s.q) <= mean(&scored.q) => (refined, s, true),
                _ => (models, scored, false),
            }
        };
        let whole = if folds.len() == 1 {
            models[0].clone()
        } else if !kept {
            whole
        } else {
            let p = polish(&whole, &every_sample, POLISH_ITERATIONS);
            polish_runs.set(polish_runs.get() + p.evaluations);
            p.model
        };
        polish_seconds.set(polish_seconds.get() + started.elapsed().as_secs_f64());
        (models, scored, whole)
    };
    while effects.len() < options.max_effects {
        let missing: Vec<Effect> = options
            .candidates
            .iter()
            .copied()
            .filter(|&e| current.can_try(e))
            .filter(|&e| e != Effect::NormalLoad || d_train.normal_force_measured)
            .filter(|&e| e != Effect::PositionDependent || context.travel > 1e-9)
            .filter(|&e| withdrawn.iter().all(|w| w.name != e))
            .collect();
        if missing.is_empty() {
            break;
        }
        // single effects first; when none is accepted, the pairs that
        // interact (an effect that shows only together with another:
        // levels that depend on position differently in each direction)
        let singles: Vec<Vec<Effect>> = missing.iter().map(|&e| vec![e]).collect();
        let mut pairs = Vec::new();
        if effects.len() + 2 <= options.max_effects {
            for (i, &a) in missing.iter().enumerate() {
                for &b in &missing[i + 1..] {
                    if current.interact(a, b, &context) {
                        pairs.push(vec![a, b]);
                    }
                }
            }
        }
        let mut accepted = None;
        let mut alternatives = Vec::new();
        let mut overlap: Option<OverlapCheck> = None;
        let mut undecided = false;
        let mut singles_tried = Vec::new();
        for additions in [singles, pairs] {
            if additions.is_empty() {
                continue;
            }
            let mut tried = try_round(&current_folds, &additions, false)?;
            let threshold = options.alpha / hypotheses(&additions) as f64;
            // overlapping explanations compete on equal terms: when one
            // fitted by output error (presliding, which the force the data
            // imply cannot show) passes the round's test, the other of its
            // pair is fitted by output error too (the force fit's result
            // one of its starts). On coarse data the force shows little of
            // a Stribeck curve (the stick-to-slip transition is a few
            // samples, differenced twice), and its force fit gained
            // nothing where its output-error fit gains most.
            for &(a, b) in &Effect::OVERLAPPING {
                for (fitted_oe, other) in [(a, b), (b, a)] {
                    let find = |e: Effect, oe: bool| {
                        tried
                            .iter()
                            .position(|t| t.added == [e] && t.by_output_error == oe)
                    };
                    let (Some(i), Some(j)) = (find(fitted_oe, true), find(other, false)) else {
                        continue;
                    };
                    let passes = tried[i].scored.as_ref().is_ok_and(|scored| {
                        let (gain, p) = nested_test(&current_scored, scored, &scales, &group);
                        p < threshold && gain >= options.min_gain
                    });
                    if passes {
                        if let Some(mut refit) =
                            try_round(&current_folds, &[vec![other]], true)?.pop()
                        {
                            refit.evaluations += tried[j].evaluations;
                            tried[j] = refit;
                        }
                    }
                }
            }
            let mut round = Vec::new();
            for t in &tried {
                let (heldout_rms, gain, p_value, failure) = match &t.scored {
                    Ok(scored) => {
                        let (gain, p) = nested_test(&current_scored, scored, &scales, &group);
                        (mean(&scored.q).sqrt(), gain, p, None)
                    }
                    Err(e) => (f64::INFINITY, f64::NEG_INFINITY, 1.0, Some(e.clone())),
                };
                let unresolved = t
                    .models
                    .iter()
                    .zip(current_folds.iter())
                    .find_map(|(m, c)| {
                        unresolved_presliding(&t.added, c, m, &context)
                            .or_else(|| unmoved_resize(&t.added, c, m, &context))
                    });
                round.push(CandidateScore {
                    name: label(&t.added),
                    heldout_rms,
                    gain,
                    p_value,
                    fine_step: None,
                    unresolved,
                    beyond_step_error: drop_beyond_step_error(
                        &current_scored,
                        heldout_rms,
                        current_step_error,
                    ),
                    force_rms: t.force_rms,
                    fit_evaluations: t.evaluations,
                    failure,
                });
            }
            // the passing candidates, best first; the first whose gain
            // survives a finer co-simulation step is accepted (a gain that
            // only offsets the co-simulation's step error does not)
            let mut passing: Vec<usize> = (0..round.len())
                .filter(|&k| {
                    round[k].p_value < threshold
                        && round[k].gain >= options.min_gain
                        && round[k].beyond_step_error
                        && round[k].unresolved.is_none()
                })
                .collect();
            passing.sort_by(|&i, &j| round[i].heldout_rms.total_cmp(&round[j].heldout_rms));
            // candidates whose held-out mean squares differ by less than the
            // co-simulation's step error squared cannot be told apart by
            // these data: the one with the fewest free parameters goes first
            // (a wide Stribeck curve re-sized can mimic a viscous term)
            if let Some(&first) = passing.first() {
                let best_ms = round[first].heldout_rms.powi(2);
                let free = |k: usize| tried[k].models.first().map_or(0, |m| m.free().len());
                let (mut close, far): (Vec<usize>, Vec<usize>) = passing.iter().partition(|&&k| {
                    round[k].heldout_rms.powi(2) - best_ms <= current_step_error.powi(2)
                });
                close.sort_by_key(|&k| free(k));
                close.extend(far);
                passing = close;
            }
            // one signature, several explanations: the one the data prefer
            // goes first ([`prefer_in_family`])
            prefer_in_family(&mut passing, &tried, &group, threshold);
            let mut current_fine: Option<Result<Scored, String>> = None;
            // whether candidate k's gain survives a finer co-simulation step
            let mut survives = |k: usize, round: &mut Vec<CandidateScore>| -> bool {
                let fine_current = current_fine
                    .get_or_insert_with(|| scored_at_step(&mut system, &current_folds, fine_step));
                // without a finer co-simulation the check cannot be made
                match fine_current {
                    Err(_) => true,
                    Ok(cur) => match scored_at_step(&mut system, &tried[k].models, fine_step) {
                        Err(_) => true,
                        Ok(cand) => {
                            let (gain, p) = nested_test(cur, &cand, &scales, &group);
                            round[k].fine_step = Some((gain, p));
                            p < threshold && gain >= options.min_gain
                        }
                    },
                }
            };
            let passes = |c: &CandidateScore| c.p_value < threshold && c.gain >= options.min_gain;
            let mut chosen = None;
            for k in passing {
                if !survives(k, &mut round) {
                    continue;
                }
                // an overlapping explanation that passes too: this one is
                // accepted only when the data separate it from that one
                let partner = match tried[k].added[..] {
                    [e] => e.overlapping().and_then(|o| {
                        (0..tried.len()).find(|&j| tried[j].added == [o] && passes(&round[j]))
                    }),
                    _ => None,
                };
                let Some(j) = partner else {
                    chosen = Some(k);
                    break;
                };
                let check = overlap_check(&tried, k, j, &try_round, &scales, &group)?;
                if check.p_separated < threshold {
                    overlap = Some(check);
                    chosen = Some(k);
                    break;
                }
                notes.push(format!(
                    "{} and {} both lower the held-out error in round {} (held-out RMS {:.4} and {:.4}), and the data do not separate them (p = {:.1e}, not below {:.1e}): neither is named. Fitted together, {} adds {:.1} % to {} (p = {:.1e}) and {} adds {:.1} % to {} (p = {:.1e}).",
                    label(&tried[k].added),
                    label(&tried[j].added),
                    rounds.len() + 1,
                    round[k].heldout_rms,
                    round[j].heldout_rms,
                    check.p_separated,
                    threshold,
                    label(&tried[k].added),
                    100.0 * check.gain_after_other,
                    label(&tried[j].added),
                    check.p_after_other,
                    label(&tried[j].added),
                    100.0 * check.other_gain_after,
                    label(&tried[k].added),
                    check.other_p_after,
                ));
                // the strongest evidence is one of two explanations the
                // data cannot tell apart: a weaker candidate (or a pair of
                // them) accepted now would only stand in for it, so the
                // search ends here
                undecided = true;
                break;
            }
            rounds.push(round.clone());
            round_thresholds.push(threshold);
            if let Some(k) = chosen {
                alternatives =
                    family_alternatives(k, &tried, &round, &group, threshold, options.min_gain);
                accepted = Some((tried, k, round[k].p_value, threshold));
                break;
            }
            if undecided {
                break;
            }
            singles_tried = tried;
        }
        let Some((mut tried, k, p_value, threshold)) = accepted else {
            break;
        };
        let t = tried.swap_remove(k);
        let fitted_by_output_error = t.by_output_error;
        let mut earlier = effects.len();
        let (mut models, mut scored) = match t.scored {
            Ok(s) => (t.models, s),
            Err(e) => return Err(format!("accepted {} without a score: {e}", label(&t.added))),
        };
        let mut whole = fit_whole_any(
            &addition_starts(&t.added)(&current),
            &models,
            &t.added,
            t.by_output_error,
        )?;
        // refine the accepted models on the output error of their training data
        if options.polish {
            (models, scored, whole) = refine(&mut system, models, scored, whole);
        }
        // the intermediate model of a pair: its first effect alone, as fitted in the singles round
        let mut steps: Vec<(Effect, FrictionModel, Vec<FrictionModel>, Scored)> = Vec::new();
        if t.added.len() == 2 {
            if let Some(single) = singles_tried.iter().find(|s| s.added == [t.added[0]]) {
                if let Ok(single_scored) = &single.scored {
                    let single_whole = fit_whole_any(
                        &addition_starts(&single.added)(&current),
                        &single.models,
                        &single.added,
                        single.by_output_error,
                    )?;
                    steps.push((
                        t.added[0],
                        single_whole,
                        single.models.clone(),
                        single_scored.clone(),
                    ));
                }
            }
        }
        steps.push((*t.added.last().expect("an effect"), whole, models, scored));
        for (effect, model, fold_models, scored) in steps {
            let where_ = localise::where_improved(
                held.friction,
                &held.intervals,
                (&current, &run_force(&mut sim, &current, held.friction)?),
                (&model, &run_force(&mut sim, &model, held.friction)?),
            );
            effects.push(FoundEffect {
                name: effect,
                action: if current.shows(effect, &context) {
                    "re-sized"
                } else {
                    "added"
                },
                meaning: effect.meaning(),
                parameters: effect_parameters(&model, effect),
                variables: fmu_values(
                    &setup.friction_fmu,
                    &model.effect_variables(effect),
                    &current,
                    &model,
                ),
                rms_before: mean(&current_scored.q).sqrt(),
                rms_after: mean(&scored.q).sqrt(),
                p_value,
                threshold,
                where_,
                alternatives: std::mem::take(&mut alternatives),
                overlap: overlap.take(),
                change: None,
            });
            accepted_as.push((rounds.len(), current.clone(), fitted_by_output_error));
            current = model;
            current_folds = fold_models;
            current_scored = scored;
        }
        // re-examine the effects accepted before this round: one whose
        // gain the new effects explain (taken out, the rest refitted, the
        // model loses no more than the test that admitted it asks for)
        // is taken out, so that a greedy early choice (one of two
        // explanations of a signature, taken before the better one could
        // be tried) does not stay in the model beside the better one
        let mut i = 0;
        while i < earlier {
            let effect = effects[i].name;
            let before = &accepted_as[i].1;
            let reduced: Option<Vec<FrictionModel>> = current_folds
                .iter()
                .map(|m| m.without(effect, before, &context))
                .collect();
            let (Some(reduced), Some(reduced_whole)) =
                (reduced, current.without(effect, before, &context))
            else {
                i += 1;
                continue;
            };
            let rest: Vec<Effect> = reduced_whole.freed.iter().copied().collect();
            let oe = accepted_as.iter().enumerate().any(|(j, a)| j != i && a.2);
            let from_itself = |m: &FrictionModel| vec![m.clone()];
            let (mut refitted, _, _) = fit_folds_any(&from_itself, &reduced, &rest, oe)?;
            let Ok(mut reduced_scored) = score(&mut system, &refitted) else {
                i += 1;
                continue;
            };
            let (gain, p_value) = nested_test(&reduced_scored, &current_scored, &scales, &group);
            if p_value < effects[i].threshold && gain >= options.min_gain {
                i += 1;
                continue;
            }
            let mut whole = fit_whole_any(&[reduced_whole], &refitted, &rest, oe)?;
            let w = Withdrawn {
                name: effect,
                accepted_in_round: accepted_as[i].0,
                withdrawn_after_round: rounds.len(),
                explained_by: effects[earlier..].iter().map(|e| e.name).collect(),
                heldout_rms_with: mean(&current_scored.q).sqrt(),
                heldout_rms_without: mean(&reduced_scored.q).sqrt(),
                gain,
                p_value,
                threshold: effects[i].threshold,
            };
            notes.push(format!(
                "{} (accepted in round {}) was taken out after round {}: with {} in the model, keeping it gains {:.1} % of the held-out mean square (p = {:.1e}, it needed p below {:.1e} and {:.1} %), held-out RMS {:.4} with it and {:.4} without",
                effect.name(),
                w.accepted_in_round,
                w.withdrawn_after_round,
                label(&w.explained_by),
                100.0 * gain,
                p_value,
                w.threshold,
                100.0 * options.min_gain,
                w.heldout_rms_with,
                w.heldout_rms_without,
            ));
            withdrawn.push(w);
            // the model without it refined as an accepted one is
            if options.polish {
                (refitted, reduced_scored, whole) =
                    refine(&mut system, refitted, reduced_scored, whole);
            }
            effects.remove(i);
            accepted_as.remove(i);
            earlier -= 1;
            current = whole;
            current_folds = refitted;
            current_scored = reduced_scored;
        }
        current_step_error = step_error_of(&mut system, &current_folds, &current_scored);
    }

    // 95 % intervals of the final model's fitted parameters, from the
    // output error of the training data it was refined on ([`intervals`])
    let interval_samples: &Picker = if folds.len() == 1 {
        &folds[0].train
    } else {
        &every_sample
    };
    let covariance = {
        let mut residual = |models: &[FrictionModel]| -> Vec<Option<nalgebra::DVector<f64>>> {
            models
                .par_iter()
                .map(|m| train_residuals(m, interval_samples))
                .collect()
        };
        // the same residuals with the co-simulation 4× finer: what its
        // step error moves the estimate by
        let fine = train_residuals_at(&current, interval_samples, Some(fine_step));
        intervals::theta_covariance(
            &current,
            &mut residual,
            fine.as_ref(),
            scales.len(),
            options.groups,
        )
    };
    if let Some(cov) = &covariance {
        for e in &mut effects {
            e.change = intervals::effect_change(e.name, &setup.nominal, &current).map(|value| {
                let interval = cov.interval(&current, &|m: &FrictionModel| {
                    intervals::effect_change(e.name, &setup.nominal, m)
                });
                EffectChange {
                    quantity: intervals::effect_change_name(e.name).unwrap_or(""),
                    value,
                    interval,
                    resolved: interval.map(|[low, high]| !(low <= 0.0 && 0.0 <= high)),
                }
            });
        }
    }

    // the remaining discrepancy against what no model can go below: the
    // measurement noise (and quantisation) and the co-simulation's own
    // step error
    let noise = noise_floor(held.data, &current_scored, &scales);
    let numerical = current_step_error;
    let floor = (noise * noise + numerical * numerical).sqrt();
    let final_rms = mean(&current_scored.q).sqrt();
    let mut fallbacks: Vec<String> = Vec::new();
    for (what, scored) in [
        ("the nominal as given", &nominal_scored),
        ("the final model", &current_scored),
    ] {
        if let Some(note) = &scored.fallback {
            fallbacks.push(format!("{what}: {note}"));
        }
    }
    let before_f = run_force(&mut sim, &baseline_model, held.friction)?;
    let after_f = run_force(&mut sim, &current, held.friction)?;
    let residual_pattern = localise::localise(held.friction, &held.intervals, &after_f);
    let baseline_pattern = localise::localise(held.friction, &held.intervals, &before_f);

    let channels = train
        .outputs
        .iter()
        .enumerate()
        .map(|(c, (name, _))| ChannelSummary {
            name: name.clone(),
            scale: scales[c],
            nominal_rms: channel_rms(&nominal_scored, c),
            baseline_rms: channel_rms(&baseline_scored, c),
            final_rms: channel_rms(&current_scored, c),
        })
        .collect();
    let plots = plot_data(&held, &nominal_scored, &current_scored, &before_f, &after_f);
    Ok(Diagnosis {
        system: file.ssd.clone(),
        data: train.label.clone(),
        heldout: match &heldout_file {
            Some(h) => h.label.clone(),
            None if by_records => format!(
                "each of the {} records ({}) in turn, scored by the model fitted on the others",
                train.records.len(),
                train.label
            ),
            None if cross => format!(
                "every one of {} equal time blocks of {}, by three-fold cross-validation (blocks 1, 4, 7, ..., then 2, 5, 8, ..., then 3, 6, 9, ... held out, each scored by the model fitted on the others)",
                blocks.count, train.label
            ),
            None => format!(
                "every third of {} equal time blocks of {} (blocks 2, 5, 8, ...)",
                blocks.count, train.label
            ),
        },
        force_source: d_train.source.clone(),
        friction_component: setup.friction_name.clone(),
        channels,
        nominal_rms: mean(&nominal_scored.q).sqrt(),
        refit,
        baseline_rms: mean(&baseline_scored.q).sqrt(),
        final_rms,
        unexplained: final_rms > UNEXPLAINED_FACTOR * floor,
        noise_floor_rms: noise,
        step_error_rms: numerical,
        floor_rms: floor,
        data_quality: DataQuality {
            data: train.quality.clone(),
            heldout: heldout_file.as_ref().map(|h| h.quality.clone()),
        },
        fallbacks,
        notes,
        residual_pattern,
        baseline_pattern,
        effects,
        withdrawn,
        rounds,
        round_thresholds,
        changes: {
            let names: Vec<String> = current.parameters().into_iter().map(|(n, _)| n).collect();
            let mut changes: Vec<FmuValue> =
                fmu_values(&setup.friction_fmu, &names, &setup.nominal, &current)
                    .into_iter()
                    .filter(|v| v.before != v.after)
                    .collect();
            if let Some(cov) = &covariance {
                for v in &mut changes {
                    v.interval = cov.parameter_interval(&current, &v.name);
                }
            }
            changes
        },
        nominal_model: setup.nominal.clone(),
        baseline_model,
        final_model: current,
        samples: train.time.len(),
        heldout_samples: current_scored.q.len(),
        alpha: options.alpha,
        groups: options.groups,
        min_gain: options.min_gain,
        folds: folds.len(),
        wall_seconds: started.elapsed().as_secs_f64(),
        polish_seconds: polish_seconds.get(),
        polish_cosimulations: polish_runs.get(),
        step,
        master,
        plots,
        measured_inputs: record_inputs(&train),
        heldout_inputs: heldout_file.as_ref().map(record_inputs).unwrap_or_default(),
        rerun: Vec::new(),
    })
}

/// Each record's own time and the columns that drive inputs.
fn record_inputs(data: &Measured) -> Vec<InputColumns> {
    (0..data.records.len())
        .map(|i| {
            let r = data.record(i);
            (r.time, r.inputs)
        })
        .collect()
}

/// One addition fitted and scored.
struct Tried {
    /// Fitted by output error (else on the force the data imply).
    by_output_error: bool,
    added: Vec<Effect>,
    /// One per fold.
    models: Vec<FrictionModel>,
    force_rms: f64,
    evaluations: usize,
    /// The held-out co-simulation, or why it failed.
    scored: Result<Scored, String>,
}

/// `a` or `a+b`.
fn label(added: &[Effect]) -> String {
    added.iter().map(|e| e.name()).collect::<Vec<_>>().join("+")
}

/// A co-simulation scored on the held-out samples.
#[derive(Clone)]
pub struct Scored {
    residuals: ChannelResiduals,
    /// Held-out positions into `residuals.samples`.
    picked: Vec<usize>,
    /// Normalised squared residual per held-out sample.
    q: Vec<f64>,
    /// The co-simulation needed a fallback ([`sim::co_simulate_robust`]).
    fallback: Option<String>,
}

fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len().max(1) as f64
}

fn channel_rms(s: &Scored, c: usize) -> f64 {
    (s.picked
        .iter()
        .map(|&k| s.residuals.residuals[c][k].powi(2))
        .sum::<f64>()
        / s.picked.len().max(1) as f64)
        .sqrt()
}

fn run_force(
    sim: &mut FrictionSim,
    model: &FrictionModel,
    d: &FrictionData,
) -> Result<Vec<f64>, String> {
    sim.run(model, d)
        .map_err(|e| format!("friction FMU along the data: {e}"))
}

/// Starting models for adding `effect` to `current`: a grid over the
/// nonlinear parameters (Stribeck velocity and excess, presliding distance).
fn starts(current: &FrictionModel, effect: Effect, context: &model::Context) -> Vec<FrictionModel> {
    let base = current.with(effect, context);
    match effect {
        Effect::Stribeck => {
            // re-sized: from its own values too
            let mut s = if current.has(Effect::Stribeck) {
                vec![base.clone()]
            } else {
                Vec::new()
            };
            for vs in [0.03, 0.1, 0.3, 1.0] {
                for excess in [0.05, 0.2] {
                    let mut m = base.clone();
                    m.vs = vs * context.speed_scale;
                    m.fs = m.fc * (1.0 + excess);
                    m.fs_neg = m.fc_neg * (1.0 + excess);
                    s.push(m);
                }
            }
            s
        }
        // presliding distances Fc/σ0 from half the position resolution the
        // data show to 3 % of the travel, and the model's own (σ1 following
        // σ0, [`FrictionModel::with_sigma0`])
        Effect::Presliding => {
            let r = context.position_resolution;
            let mut s = vec![base.clone()];
            for d in [0.5 * r, 2.0 * r, 8.0 * r, 32.0 * r, 128.0 * r, 512.0 * r]
                .into_iter()
                .chain([1e-2 * context.travel, 3e-2 * context.travel])
            {
                s.push(base.with_sigma0(base.fc / d));
            }
            s
        }
        Effect::Viscous => {
            let mut s = vec![base.clone()];
            for r in [0.01, 0.1] {
                let mut m = base.clone();
                m.sigma2 += r * m.fc / context.speed_scale;
                s.push(m);
            }
            s
        }
        _ => vec![base],
    }
}

/// One-sided test that the candidate (`after`, the current model with an
/// effect added: the two models are nested) predicts the held-out data
/// better than the current model (`before`). Returns (relative drop of the
/// held-out mean square, p-value).
///
/// The statistic is Clark and West's for nested models ("Approximately
/// normal tests for equal predictive accuracy in nested models", J.
/// Econometrics 138, 2007): per held-out sample
/// f = e₀² − e₁² + (ŷ₁ − ŷ₀)² = 2·e₀·(ŷ₁ − ŷ₀), with e the residuals and ŷ
/// the simulated channels, each divided by its scale and averaged over the
/// channels. When the current model is the truth, its error e₀ is noise
/// unrelated to what the candidate changes (fitted on other data), so f has
/// mean zero; the plain difference e₀² − e₁² would instead have a negative
/// mean, the candidate's extra parameters adding their estimation noise
/// (ŷ₁ − ŷ₀)² to its error, which makes that test lose power against
/// nested alternatives. f is averaged over the groups of `group`
/// (consecutive samples or blocks, so that correlated neighbours count
/// once) and the group means are tested with Wilcoxon's signed-rank test
/// ([`grouped_signed_rank_test`]): under the null hypothesis e₀ is noise
/// independent of the change, so f is symmetric about zero, which is all
/// the test assumes. Student's t on the same means ([`grouped_t_test`])
/// assumes them normal, and loses its power when the improvement sits in a
/// few groups (a stick-slip record, whose slips carry the evidence while
/// the sticks between them carry none): a candidate that removed 99.7 % of
/// the mean square scored p = 0.014 with t, far below p = 1e-5 by ranks.
/// Acceptance also requires the mean square itself to drop
/// ([`Options::min_gain`]).
pub fn nested_test(before: &Scored, after: &Scored, scales: &[f64], group: &[usize]) -> (f64, f64) {
    let n = before.q.len().min(after.q.len());
    let mb = mean(&before.q[..n]);
    let gain = if mb > 0.0 {
        (mb - mean(&after.q[..n])) / mb
    } else {
        0.0
    };
    if before.picked[..n] != after.picked[..n] {
        return (gain, 1.0);
    }
    let f: Vec<f64> = (0..n)
        .map(|i| {
            let k = before.picked[i];
            let change = (0..scales.len())
                .map(|c| {
                    let d = before.residuals.residuals[c][k] - after.residuals.residuals[c][k];
                    (d / scales[c]).powi(2)
                })
                .sum::<f64>()
                / scales.len().max(1) as f64;
            before.q[i] - after.q[i] + change
        })
        .collect();
    (
        gain,
        grouped_signed_rank_test(&f, &group[..n.min(group.len())]),
    )
}

/// The number of hypotheses a round of `additions` tests, for its
/// Bonferroni threshold: one per addition, except that the single
/// additions of one family ([`Effect::ASYMMETRY`]) test one hypothesis
/// together (the friction differs between the directions); which of them
/// explains it is decided among them afterwards ([`prefer_in_family`]).
fn hypotheses(additions: &[Vec<Effect>]) -> usize {
    let mut families = Vec::new();
    let mut n = 0;
    for added in additions {
        match added[..] {
            [e] => match e.family() {
                // a family is known by its first member
                Some(f) if families.contains(&f[0]) => {}
                Some(f) => {
                    families.push(f[0]);
                    n += 1;
                }
                None => n += 1,
            },
            _ => n += 1,
        }
    }
    n.max(1)
}

/// One-sided p-value that `better` explains the held-out data better than
/// `other`, two candidates neither of which is nested in the other (two
/// explanations of one signature): per held-out sample the difference of
/// their normalised squared errors `q_other − q_better`, averaged per
/// group and tested with Wilcoxon's signed-rank test, as the acceptance
/// test does ([`grouped_signed_rank_test`]). 1 when they were not scored
/// on the same samples.
pub fn separation_test(better: &Scored, other: &Scored, group: &[usize]) -> f64 {
    let n = better.q.len().min(other.q.len());
    if better.picked[..n] != other.picked[..n] {
        return 1.0;
    }
    let d: Vec<f64> = (0..n).map(|i| other.q[i] - better.q[i]).collect();
    grouped_signed_rank_test(&d, &group[..n.min(group.len())])
}

/// Among the passing candidates (best first), when the best is a single
/// effect of a family ([`Effect::ASYMMETRY`]): the family members that
/// passed and that the held-out data do not separate from the best
/// ([`separation_test`] at `threshold`) are equally good explanations of
/// its signature; the first of them in the family's order is moved to the
/// front (direction-dependent levels before an offset before
/// direction-dependent viscous friction). A member the data separate
/// from the others keeps its place.
fn prefer_in_family(passing: &mut Vec<usize>, tried: &[Tried], group: &[usize], threshold: f64) {
    let Some(&best) = passing.first() else {
        return;
    };
    let (Some(family), Ok(best_scored)) = (single_family(&tried[best]), &tried[best].scored) else {
        return;
    };
    let rank = |k: usize| family.iter().position(|e| *e == tried[k].added[0]);
    let preferred = passing
        .iter()
        .copied()
        .filter(|&k| single_family(&tried[k]) == Some(family))
        .filter(|&k| {
            k == best
                || tried[k]
                    .scored
                    .as_ref()
                    .is_ok_and(|s| separation_test(best_scored, s, group) >= threshold)
        })
        .min_by_key(|&k| rank(k));
    if let Some(p) = preferred {
        passing.retain(|&k| k != p);
        passing.insert(0, p);
    }
}

/// The family of `t`'s addition when it is one effect of a family.
fn single_family(t: &Tried) -> Option<&'static [Effect]> {
    match t.added[..] {
        [e] => e.family(),
        _ => None,
    }
}

/// The other members of the accepted candidate `k`'s family tried in the
/// same round, each with how strongly the held-out data separate it from
/// `k` ([`Alternative`]).
fn family_alternatives(
    k: usize,
    tried: &[Tried],
    round: &[CandidateScore],
    group: &[usize],
    threshold: f64,
    min_gain: f64,
) -> Vec<Alternative> {
    let (Some(family), Ok(chosen)) = (single_family(&tried[k]), &tried[k].scored) else {
        return Vec::new();
    };
    (0..tried.len())
        .filter(|&j| j != k && single_family(&tried[j]) == Some(family))
        .map(|j| {
            let p_value = match &tried[j].scored {
                Ok(s) => separation_test(chosen, s, group),
                Err(_) => 0.0,
            };
            let c = &round[j];
            Alternative {
                name: c.name.clone(),
                heldout_rms: c.heldout_rms,
                p_value,
                passed: c.p_value < threshold
                    && c.gain >= min_gain
                    && c.unresolved.is_none()
                    && c.beyond_step_error
                    && c.failure.is_none(),
                separated: p_value < threshold,
            }
        })
        .collect()
}

/// The means of `d` over its groups (`group[i]` labels `d[i]`; a group is
/// a run of equal labels).
fn group_means(d: &[f64], group: &[usize]) -> Vec<f64> {
    let mut means = Vec::new();
    let mut start = 0;
    for i in 1..=d.len() {
        if i == d.len() || group[i] != group[start] {
            means.push(d[start..i].iter().sum::<f64>() / (i - start) as f64);
            start = i;
        }
    }
    means
}

/// One-sided p-value that `d` is centred above zero: `d` averaged over its
/// groups, then Wilcoxon's signed-rank test of the group means (zeros
/// dropped). Exact (the distribution of W⁺ counted by dynamic programming)
/// when the ranks have no ties and there are at most
/// [`SIGNED_RANK_EXACT`] means; else the normal approximation with the
/// tie correction and a continuity correction of ½.
pub fn grouped_signed_rank_test(d: &[f64], group: &[usize]) -> f64 {
    let means: Vec<f64> = group_means(d, group)
        .into_iter()
        .filter(|m| *m != 0.0)
        .collect();
    let n = means.len();
    if n < 2 {
        return 1.0;
    }
    // ranks of |m|, ties given their average rank
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| means[a].abs().total_cmp(&means[b].abs()));
    let mut rank = vec![0.0; n];
    let mut ties = Vec::new();
    let mut i = 0;
    while i < n {
        let mut j = i + 1;
        while j < n && means[order[j]].abs() == means[order[i]].abs() {
            j += 1;
        }
        let average = (i + j + 1) as f64 / 2.0; // ranks i+1..=j
        for &k in &order[i..j] {
            rank[k] = average;
        }
        if j - i > 1 {
            ties.push((j - i) as f64);
        }
        i = j;
    }
    let w_plus: f64 = (0..n).filter(|&k| means[k] > 0.0).map(|k| rank[k]).sum();
    if ties.is_empty() && n <= SIGNED_RANK_EXACT {
        // counts[s]: subsets of the ranks 1..=n with sum s
        let total = n * (n + 1) / 2;
        let mut counts = vec![0f64; total + 1];
        counts[0] = 1.0;
        for r in 1..=n {
            for s in (r..=total).rev() {
                counts[s] += counts[s - r];
            }
        }
        let w = w_plus.round() as usize;
        let above: f64 = counts[w..].iter().sum();
        return above / 2f64.powi(n as i32);
    }
    let nf = n as f64;
    let mean_w = nf * (nf + 1.0) / 4.0;
    let var_w = nf * (nf + 1.0) * (2.0 * nf + 1.0) / 24.0
        - ties.iter().map(|t| t * t * t - t).sum::<f64>() / 48.0;
    if var_w <= 0.0 {
        return 1.0;
    }
    let z = (w_plus - mean_w - 0.5) / var_w.sqrt();
    use statrs::distribution::{ContinuousCDF, Normal};
    Normal::new(0.0, 1.0).map_or(1.0, |dist| 1.0 - dist.cdf(z))
}

/// Up to this many group means the signed-rank test is exact.
pub const SIGNED_RANK_EXACT: usize = 60;

/// One-sided p-value that the mean of `d` is positive: `d` averaged over
/// its groups (`group[i]` labels `d[i]`; a group is a run of equal
/// labels), Student's t with groups − 1 degrees of freedom.
pub fn grouped_t_test(d: &[f64], group: &[usize]) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    let means = group_means(d, group);
    if means.len() < 2 {
        return 1.0;
    }
    let m = mean(&means);
    let sd =
        (means.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (means.len() as f64 - 1.0)).sqrt();
    if sd.is_nan() || sd <= 0.0 {
        return if m > 0.0 { 0.0 } else { 1.0 };
    }
    let t = m / (sd / (means.len() as f64).sqrt());
    match StudentsT::new(0.0, 1.0, means.len() as f64 - 1.0) {
        Ok(dist) => 1.0 - dist.cdf(t),
        Err(_) => 1.0,
    }
}

/// The normalised RMS of the measurement noise, from the second
/// differences of each measured channel (white noise of σ gives
/// differences of σ·√6; the median absolute value / 0.6745 is robust to
/// the signal's own curvature and to outliers).
fn noise_floor(data: &Measured, scored: &Scored, scales: &[f64]) -> f64 {
    let mut q = 0.0;
    for (c, (_, values)) in data.outputs.iter().enumerate() {
        let idx: Vec<usize> = scored
            .picked
            .iter()
            .map(|&s| scored.residuals.samples[s])
            .collect();
        let mut d2: Vec<f64> = idx
            .windows(3)
            .filter(|w| w[1] == w[0] + 1 && w[2] == w[1] + 1)
            .map(|w| (values[w[2]] - 2.0 * values[w[1]] + values[w[0]]).abs())
            .collect();
        if d2.is_empty() {
            continue;
        }
        d2.sort_by(f64::total_cmp);
        let sigma = d2[d2.len() / 2] / 0.6745 / 6f64.sqrt();
        // a quantised channel is off by up to half its step even where
        // its second differences are zero: uniform error of step/√12
        let sigma = sigma.max(quality::quantum(values) / 12f64.sqrt());
        q += (sigma / scales[c]).powi(2);
    }
    (q / scales.len().max(1) as f64).sqrt()
}

/// A presliding candidate whose change of the presliding distance Fc/σ0
/// moves the mass by less than [`PRESLIDING_RESOLVED`] encoder steps: at
/// a reversal the force on the contact swings from −Fc to +Fc through the
/// bristles, which carry the mass 2·Fc/σ0 before it slides, so two
/// contacts whose presliding distances differ by Δ hold it 2·Δ apart at
/// the end of that stick. A smaller difference is one the encoder does
/// not register as a displacement, and a better score can only come from
/// something else the change of σ0 happens to offset (the co-simulation's
/// step error in the stick, a missing level or Stribeck term), not from
/// presliding. Returns the reason, or `None` when the change is resolved.
fn unresolved_presliding(
    added: &[Effect],
    current: &FrictionModel,
    candidate: &FrictionModel,
    context: &model::Context,
) -> Option<String> {
    if !added.contains(&Effect::Presliding) {
        return None;
    }
    let (before, after) = (
        current.presliding_distance(),
        candidate.presliding_distance(),
    );
    let swing = PRESLIDING_SWING * (after - before).abs();
    (swing < PRESLIDING_RESOLVED * context.position_step).then(|| {
        format!(
            "presliding distance {before:.3e} m -> {after:.3e} m: the mass moves {swing:.3e} m differently at a reversal, below {PRESLIDING_RESOLVED} x the encoder step of the data ({:.3e} m): not resolved",
            context.position_step
        )
    })
}

/// A re-sized effect (one the current model has already) whose own
/// parameters all moved by less than [`RESIZE_MIN_CHANGE`] (relative) in
/// the candidate: its gain came from the levels refitted with it, not from
/// the effect, which is then not named. Returns the reason.
fn unmoved_resize(
    added: &[Effect],
    current: &FrictionModel,
    candidate: &FrictionModel,
    context: &model::Context,
) -> Option<String> {
    let [effect] = added else { return None };
    if !current.shows(*effect, context) || !current.can_try(*effect) {
        return None;
    }
    let before = current.effect_parameters(*effect);
    let after = candidate.effect_parameters(*effect);
    let moved = before.iter().zip(&after).any(|((_, a, _), (_, b, _))| {
        (b - a).abs() > RESIZE_MIN_CHANGE * a.abs().max(f64::MIN_POSITIVE)
    });
    (!moved).then(|| {
        format!(
            "re-sized by less than {:.0} %: the gain comes from the levels refitted with it",
            100.0 * RESIZE_MIN_CHANGE
        )
    })
}

/// See `unmoved_resize`.
pub const RESIZE_MIN_CHANGE: f64 = 0.05;

/// A change of the presliding displacement at a reversal below this many
/// encoder steps is not resolved by the data (`unresolved_presliding`).
pub const PRESLIDING_RESOLVED: f64 = 1.0;

/// The presliding displacement at a reversal, in presliding distances
/// Fc/σ0: the bristles go from −Fc/σ0 to +Fc/σ0 (`unresolved_presliding`).
pub const PRESLIDING_SWING: f64 = 2.0;

/// Whether a candidate of held-out RMS `candidate_rms` lowers the mean
/// square of `current` by more than the square of the co-simulation's step
/// error (`step_error`, [`step_error_floor`]): at most that much of the
/// error can be the integration's, which a parameter change can partly
/// compensate.
fn drop_beyond_step_error(current: &Scored, candidate_rms: f64, step_error: f64) -> bool {
    mean(&current.q) - candidate_rms * candidate_rms > step_error * step_error
}

/// The co-simulation step is divided by this for the step-error estimate
/// and for the check that an accepted improvement survives a finer step.
pub const FINE_STEP_DIVISOR: f64 = 4.0;

/// The co-simulation's step error on the held-out samples: the RMS of the
/// normalised change of the simulated channels when the step is divided by
/// [`FINE_STEP_DIVISOR`] (4), times 4/3 (Richardson for a first-order
/// error, e(h) = (y(h) − y(h/4))·4/3; a stick-slip co-simulation converges
/// at first order, its slips timed to within a step; higher orders need
/// less).
fn step_error_floor(scored: &Scored, fine: &Scored, scales: &[f64]) -> f64 {
    let half = &fine.residuals.simulated;
    let sim = &scored.residuals.simulated;
    let q: f64 = scored
        .picked
        .iter()
        .map(|&k| {
            (0..scales.len())
                .map(|c| ((sim[c][k] - half[c][k]) / scales[c]).powi(2))
                .sum::<f64>()
                / scales.len().max(1) as f64
        })
        .sum();
    let d = FINE_STEP_DIVISOR;
    d / (d - 1.0) * (q / scored.picked.len().max(1) as f64).sqrt()
}

fn effect_parameters(
    model: &FrictionModel,
    effect: Effect,
) -> serde_json::Map<String, serde_json::Value> {
    model
        .effect_parameters(effect)
        .into_iter()
        .map(|(n, v, _)| (n, serde_json::json!(v)))
        .collect()
}

fn plot_data(
    held: &HeldOut,
    nominal: &Scored,
    last: &Scored,
    before_f: &[f64],
    after_f: &[f64],
) -> PlotData {
    let time: Vec<f64> = last
        .picked
        .iter()
        .map(|&s| held.data.time[last.residuals.samples[s]])
        .collect();
    let channels = held
        .data
        .outputs
        .iter()
        .enumerate()
        .map(|(c, (name, values))| {
            let m: Vec<f64> = last
                .picked
                .iter()
                .map(|&s| values[last.residuals.samples[s]])
                .collect();
            let nom: Vec<f64> = nominal
                .picked
                .iter()
                .map(|&s| nominal.residuals.simulated[c][s])
                .collect();
            let fin: Vec<f64> = last
                .picked
                .iter()
                .map(|&s| last.residuals.simulated[c][s])
                .collect();
            (name.clone(), m, nom, fin)
        })
        .collect();
    let d = held.friction;
    let since = localise::time_since_reversal(d);
    let moved = localise::displacement_since_reversal(d);
    PlotData {
        displacement: held.intervals.iter().map(|&j| moved[j]).collect(),
        force: held.intervals.iter().map(|&j| d.f[j]).collect(),
        time,
        channels,
        v: held.intervals.iter().map(|&j| d.v[j]).collect(),
        x: held.intervals.iter().map(|&j| d.x[j]).collect(),
        since_reversal: held.intervals.iter().map(|&j| since[j]).collect(),
        fn_: d
            .normal_force_measured
            .then(|| held.intervals.iter().map(|&j| d.fn_[j]).collect()),
        residual_before: held
            .intervals
            .iter()
            .map(|&j| d.f[j] - before_f[j])
            .collect(),
        residual_after: held
            .intervals
            .iter()
            .map(|&j| d.f[j] - after_f[j])
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// A scored run of one channel (scale 1) with these residuals.
    fn scored(residuals: Vec<f64>) -> Scored {
        let n = residuals.len();
        Scored {
            q: residuals.iter().map(|r| r * r).collect(),
            picked: (0..n).collect(),
            residuals: ChannelResiduals {
                channels: vec!["y".into()],
                samples: (0..n).collect(),
                simulated: vec![vec![0.0; n]],
                residuals: vec![residuals],
                incomplete: None,
            },
            fallback: None,
        }
    }

    /// Presliding is resolved when the re-sized contact moves the mass at a
    /// reversal by at least one encoder step, whatever the noise.
    #[test]
    fn presliding_is_resolved_by_its_displacement_at_a_reversal() {
        let values = [
            ("Fc", 10.0),
            ("Fs", 10.0),
            ("vs", 0.01),
            ("sigma0", 1e8),
            ("sigma1", 0.0),
            ("sigma2", 0.0),
            ("stribeck_exponent", 2.0),
            ("Fc_neg", 10.0),
            ("Fs_neg", 10.0),
            ("direction_dependent", 0.0),
            ("normal_force_form", 0.0),
            ("position_dependent", 0.0),
        ];
        let nominal = FrictionModel::from_values(
            &values
                .iter()
                .map(|(k, v)| (k.to_string(), *v))
                .collect::<std::collections::BTreeMap<_, _>>(),
        )
        .unwrap();
        // a 1 µm encoder with 1.2 µm of noise
        let context = model::Context {
            speed_scale: 0.1,
            x_min: 0.0,
            x_max: 0.2,
            travel: 0.2,
            mean_normal_force: 100.0,
            position_knots: 6,
            position_resolution: 2.4e-6,
            position_step: 1e-6,
        };
        let resolved = |before: f64, after: f64| {
            let (b, a) = (
                nominal.with_sigma0(10.0 / before),
                nominal.with_sigma0(10.0 / after),
            );
            unresolved_presliding(&[Effect::Presliding], &b, &a, &context).is_none()
        };
        // 0.1 µm -> 0.8 µm: 1.4 µm more at each reversal
        assert!(resolved(1e-7, 8e-7));
        // stiffened from 0.47 µm to nothing: 0.94 µm
        assert!(!resolved(4.7e-7, 1e-9));
        // both soft, re-sized by 0.3 µm: 0.6 µm
        assert!(!resolved(5e-6, 5.3e-6));
        assert!(resolved(5e-6, 6e-6));
        // not presliding: nothing to judge
        assert!(unresolved_presliding(&[Effect::Viscous], &nominal, &nominal, &context).is_none());
    }

    #[test]
    fn grouped_t_test_matches_students_t() {
        // d = 1, 2, 3, 4 in groups of one: mean 2.5, sd 1.2910, t = 3.8730,
        // 3 degrees of freedom, one-sided p = 0.0152331458 (SciPy 1.17,
        // stats.ttest_1samp([1, 2, 3, 4], 0, alternative="greater"))
        let p = grouped_t_test(&[1.0, 2.0, 3.0, 4.0], &[0, 1, 2, 3]);
        assert!((p - 0.015_233_145_8).abs() < 1e-9, "{p}");
        // groups average their members: (1, 1), (2, 2), ... is the same test
        let p2 = grouped_t_test(
            &[1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0],
            &[0, 0, 1, 1, 2, 2, 3, 3],
        );
        assert!((p2 - p).abs() < 1e-12, "{p2}");
        assert_eq!(
            grouped_t_test(&[1.0, 2.0], &[0, 0]),
            1.0,
            "one group: no test"
        );
    }

    #[test]
    fn signed_rank_test_matches_its_exact_distribution() {
        // all four positive: W+ = 10, P(W+ >= 10) = 1/16
        let p = grouped_signed_rank_test(&[1.0, 2.0, 3.0, 4.0], &[0, 1, 2, 3]);
        assert!((p - 1.0 / 16.0).abs() < 1e-15, "{p}");
        // -2 negative: W+ = 1 + 3 + 4 = 8; subsets of {1,2,3,4} summing to
        // at least 8: {1,3,4}, {2,3,4}, {1,2,3,4}: 3/16
        let p = grouped_signed_rank_test(&[1.0, -2.0, 3.0, 4.0], &[0, 1, 2, 3]);
        assert!((p - 3.0 / 16.0).abs() < 1e-15, "{p}");
        // groups average their members
        let p2 = grouped_signed_rank_test(&[1.0, 1.0, -2.0, -2.0, 3.0, 4.0], &[0, 0, 1, 1, 2, 3]);
        assert!((p2 - p).abs() < 1e-15);
        // a tie: the normal approximation (|m| = 1, 1, 2: ranks 1.5, 1.5,
        // 3, all positive: W+ = 6, mean 3, var 3.5 − 6/48 = 3.375,
        // z = 2.5/1.8371 = 1.3608, p = 0.08679)
        let p = grouped_signed_rank_test(&[1.0, 1.0, 2.0], &[0, 1, 2]);
        assert!((p - 0.086_79).abs() < 1e-4, "{p}");
        assert_eq!(grouped_signed_rank_test(&[1.0, 2.0], &[0, 0]), 1.0);
    }

    /// The improvement concentrated in a few groups (the slips of a
    /// stick-slip record), the others unchanged up to noise: the ranks see
    /// it, Student's t does not.
    #[test]
    fn signed_ranks_see_an_improvement_concentrated_in_a_few_groups() {
        let mut d = vec![0.0; 30];
        for (i, x) in d.iter_mut().enumerate() {
            *x = if i % 3 == 0 {
                100.0 * (1.0 + i as f64)
            } else {
                1e-3 * (1.0 + (i % 5) as f64)
            };
        }
        d[7] = -1e-3;
        let group: Vec<usize> = (0..30).collect();
        let rank = grouped_signed_rank_test(&d, &group);
        let t = grouped_t_test(&d, &group);
        assert!(rank < 1e-5 && t > 1e-3, "ranks {rank}, t {t}");
    }

    /// Clark–West on nested models: when the current model is the truth
    /// (its residuals pure noise) and the candidate changes the prediction
    /// by an amount fitted on other data, the test rejects at about its
    /// level; the plain difference of squared errors rejects almost never
    /// (the candidate's change adds to its error); when the candidate's
    /// change is part of the truth, Clark–West rejects.
    #[test]
    fn nested_test_holds_its_level_and_finds_a_real_change() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let noise = Normal::new(0.0, 1.0).unwrap();
        let (n, groups, trials) = (200, 20, 2000);
        let group: Vec<usize> = (0..n).map(|i| i * groups / n).collect();
        let (mut cw_null, mut plain_null, mut cw_real, mut t_null) = (0, 0, 0, 0);
        for _ in 0..trials {
            let e0: Vec<f64> = (0..n).map(|_| noise.sample(&mut rng)).collect();
            // the candidate's change: estimation noise, independent of e0
            let change: Vec<f64> = (0..n).map(|_| 0.3 * noise.sample(&mut rng)).collect();
            let before = scored(e0.clone());
            let after = scored(e0.iter().zip(&change).map(|(e, c)| e - c).collect());
            let (_, p) = nested_test(&before, &after, &[1.0], &group);
            cw_null += usize::from(p < 0.05);
            let f: Vec<f64> = (0..n).map(|i| 2.0 * e0[i] * change[i]).collect();
            t_null += usize::from(grouped_t_test(&f, &group) < 0.05);
            let plain: Vec<f64> = (0..n).map(|i| before.q[i] - after.q[i]).collect();
            plain_null += usize::from(grouped_t_test(&plain, &group) < 0.05);
            // a real effect of size 0.3 in the data, the candidate has it
            let effect: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64 * 0.37).sin()).collect();
            let e0: Vec<f64> = (0..n).map(|i| effect[i] + noise.sample(&mut rng)).collect();
            let after: Vec<f64> = (0..n).map(|i| e0[i] - effect[i]).collect();
            let (_, p) = nested_test(&scored(e0), &scored(after), &[1.0], &group);
            cw_real += usize::from(p < 0.05);
        }
        let rate = |k: usize| k as f64 / trials as f64;
        assert!(
            (0.035..=0.065).contains(&rate(cw_null)),
            "Clark–West (signed ranks) under the null: {}",
            rate(cw_null)
        );
        assert!(
            (0.035..=0.065).contains(&rate(t_null)),
            "Clark–West (Student's t) under the null: {}",
            rate(t_null)
        );
        assert!(
            rate(plain_null) < 0.02,
            "plain difference under the null: {}",
            rate(plain_null)
        );
        assert!(
            rate(cw_real) > 0.5,
            "Clark–West on a real change: {}",
            rate(cw_real)
        );
    }
}
