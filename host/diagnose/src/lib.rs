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
//!
//! [`diagnose_records`] runs these as stages, each a module of
//! `src/stages/` with its inputs and outputs said in its docs: the data
//! read and inspected (`load`), the force estimate or the output-error
//! set-up (`force`), the split into folds (`split`), the baseline and the
//! refit (`baseline`), the candidate rounds with the re-examination
//! (`rounds`), the refinement of accepted models (`refine`), and the
//! report's figures (`summary`). The tests that decide are in
//! [`acceptance`].

pub mod acceptance;
pub mod budget;
pub mod dahl;
pub mod effects;
pub mod figures;
pub mod fit;
pub mod html;
pub mod intervals;
pub mod localise;
pub mod memory;
pub mod model;
pub mod problem;
#[cfg(feature = "progress-line")]
pub mod progress_line;
pub mod quality;
pub mod report;
pub mod sim;
mod stages;
pub mod tangent;

// the co-simulation core's modules under the paths the diagnosis names
// them by
use fricsim_core::{fmu, inputs, master, plot, ssp, system, FmuError};

pub use acceptance::{
    grouped_signed_rank_test, grouped_t_test, nested_test, separation_test, Scored,
    SIGNED_RANK_EXACT,
};
pub use budget::{Progress, Snapshot, TimeLimit, DEFAULT_TIME_LIMIT};
pub use effects::{PRESLIDING_RESOLVED, PRESLIDING_SWING};
pub use stages::rounds::RESIZE_MIN_CHANGE;
pub use stages::split::Blocks;

use budget::Budget;
use model::{Effect, FrictionModel};
use problem::{Measured, Setup};
use serde::Serialize;
use sim::FrictionSim;
use sim::{co_simulate, system_parameters};
use ssp::SystemFile;
use stages::baseline::baseline;
use stages::force::estimate_force;
use stages::load::{load, step_of, Loaded};
use stages::memory::check_memory;
use stages::problem::{channel_scales, Problem};
use stages::refine::Polishing;
use stages::rounds::search;
use stages::split::{Split, HELD_OUT_PHASE};
use stages::summary::summarise;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Settings of the workflow.
#[derive(Clone, Debug)]
pub struct Options {
    /// Effects to try (default: the whole library).
    pub candidates: Vec<Effect>,
    /// Knots of the position table of `position_dependent` when it is
    /// added.
    pub position_knots: usize,
    /// The most knots the table may be given when the rounds end with it
    /// (doubled while the data ask for it, `stages/rounds/table.rs`);
    /// equal to `position_knots` keeps the table as added.
    pub max_position_knots: usize,
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
    /// Seconds of wall time after which the diagnosis starts no new work
    /// and reports what it has ([`budget`], [`Diagnosis::time_limit`]);
    /// `None`: no limit (default [`DEFAULT_TIME_LIMIT`]).
    pub time_limit: Option<f64>,
    /// Counters the caller reads while the diagnosis runs (a progress
    /// line, [`Progress`]); the diagnosis prints nothing itself.
    pub progress: Option<Progress>,
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
        if !(2..=model::MAX_TABLE_POINTS).contains(&self.position_knots) {
            return Err(format!(
                "position_knots {}: must be in 2..={} (the LuGre table holds {} points)",
                self.position_knots,
                model::MAX_TABLE_POINTS,
                model::MAX_TABLE_POINTS
            ));
        }
        if !(self.position_knots..=model::MAX_TABLE_POINTS).contains(&self.max_position_knots) {
            return Err(format!(
                "max_position_knots {}: must be in {}..={} (at least position_knots, at most the {} points the LuGre table holds)",
                self.max_position_knots,
                self.position_knots,
                model::MAX_TABLE_POINTS,
                model::MAX_TABLE_POINTS
            ));
        }
        if let Some(s) = self.time_limit {
            budget::check_time_limit(s)?;
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
            max_position_knots: model::MAX_TABLE_POINTS,
            smooth: 0.01,
            alpha: 0.01,
            min_gain: 0.02,
            groups: 20,
            max_effects: 4,
            polish: true,
            blocks: SPLIT_BLOCKS,
            cross_validate: CrossValidate::Auto,
            master: None,
            time_limit: Some(DEFAULT_TIME_LIMIT),
            progress: None,
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

/// How many starts of a candidate's output-error fit are refined (for
/// one iteration each, then the best of them for the rest of the
/// [`CANDIDATE_OUTPUT_ERROR_ITERATIONS`]) on a plant whose friction force
/// the data do not give. The cost of a
/// start at the start is a poor guide there: after a refit of the levels
/// alone had raised Fc by 22 % to stand in for a missing Stribeck peak
/// (a two-mass drive, hidden 10 % Stribeck curve), the best-ranked of 18
/// starts (the current model re-sized) stopped at a held-out RMS of
/// 0.179 after three iterations, while the fifth-ranked (the given
/// levels, vs from the grid) reached 0.026, near the truth; refined from
/// the first, the curve lost to a position table and the wrong effect
/// was named. With five, the curve was named at 0.0014 (the floor is
/// 0.0071) in the same wall time (the later rounds it spared). One
/// iteration is enough to tell the starts apart: on four cases (that
/// Stribeck curve, levels by direction at 5 %, position tables on the
/// two-mass drive and on the servo axis) refining only the best after
/// it named the same effects at the same RMS as three iterations from
/// each, with 20–25 % fewer co-simulations.
pub const OUTPUT_ERROR_STARTS_REFINED: usize = 5;

/// Whether time block `b` is held out (the phase held out by a single
/// split).
pub fn held_out_block(b: usize) -> bool {
    b % 3 == HELD_OUT_PHASE
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
    /// they cannot (`effects/presliding.rs`); then it is not accepted.
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
pub(crate) fn fmu_values(
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
    /// ([`model::Effect::change`]), in the final model, with its 95 %
    /// interval; `None` for an effect without such a number.
    pub change: Option<EffectChange>,
    /// For `position_dependent`: each finer table tried when the rounds
    /// ended (the knots doubled while the data ask for it, see
    /// `stages/rounds/table.rs`); empty for the other effects.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub table: Vec<TableStep>,
}

/// One finer position table tried: its knots, its held-out RMS against
/// the coarser table's, the test that would keep it, and whether it was
/// kept.
#[derive(Clone, Debug, Serialize)]
pub struct TableStep {
    pub knots: usize,
    pub heldout_rms_before: f64,
    pub heldout_rms: f64,
    pub gain: f64,
    pub p_value: f64,
    pub fit_evaluations: usize,
    pub kept: bool,
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
    /// The data separate the two: p below the round's threshold, and
    /// held-out mean squares that differ by more than the co-simulation's
    /// step error squared.
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
    /// when this is below the round's threshold (the data prefer it), or
    /// when it [`OverlapCheck::encompasses`] the other; otherwise neither
    /// is.
    pub p_separated: f64,
    /// Not separated alone, but fitted together this effect adds to the
    /// other by the round's rule, and the other adds nothing to it, not
    /// even at [`NO_EVIDENCE_LEVEL`]: it holds what the other explains
    /// and more (the logic of Davidson and MacKinnon's J test for models
    /// that are not nested, 1981).
    pub encompasses: bool,
}

/// The level at which an effect fitted on top of another counts as adding
/// something to it, for [`OverlapCheck::encompasses`]. A claim that the
/// other adds *nothing* must not rest on a p-value that only misses the
/// round's Bonferroni threshold: on a coarse record with a Stribeck curve
/// hidden, presliding added 26.8 % to it (p = 4e-4) and the Stribeck curve
/// 6.1 % to presliding at p = 0.015, above the round's 2e-3 but evidence
/// all the same; at this level the two stay undecided.
pub const NO_EVIDENCE_LEVEL: f64 = 0.05;

impl OverlapCheck {
    /// Whether the effect checked is named over the other: the data
    /// separate it from the other alone, or it encompasses the other
    /// (sets [`OverlapCheck::encompasses`]).
    pub fn prefers_this(&mut self, rule: acceptance::Acceptance) -> bool {
        if self.p_separated < rule.threshold {
            return true;
        }
        let some_evidence = acceptance::Acceptance {
            threshold: NO_EVIDENCE_LEVEL.max(rule.threshold),
            ..rule
        };
        self.encompasses = rule.passes(self.gain_after_other, self.p_after_other)
            && !some_evidence.passes(self.other_gain_after, self.other_p_after);
        self.encompasses
    }
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
    /// The final error (the other law's when the nominal moved to it,
    /// `memory`) is
    /// above [`UNEXPLAINED_FACTOR`] × `floor_rms`.
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
    /// Whether the held-out data prefer another law's pre-sliding to the
    /// final LuGre model's ([`memory`]): one check per law (GMS, the
    /// elasto-plastic law), the law the nominal moved to, or why not.
    pub memory: Vec<memory::LawCheck>,
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
    /// The time limit, whether it was reached, and what was left out
    /// because of it ([`budget`]).
    pub time_limit: TimeLimit,
    /// Co-simulations run (fits, scores, refinements, intervals).
    pub cosimulations: usize,
    /// Of which the output-error refinement of accepted models took this
    /// long, in this many co-simulations.
    pub polish_seconds: f64,
    pub polish_cosimulations: usize,
    /// Where the output-error fits took their Jacobian from: the output
    /// sensitivities carried along one co-simulation ([`tangent`]), with
    /// how far the first one was from forward differences, or forward
    /// differences and why.
    pub output_jacobian: String,
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
    /// The time limit was reached before the refit finished (or started):
    /// not kept, not scored ([`Diagnosis::time_limit`]).
    pub unfinished: bool,
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
/// them, on held-out parts of `data` ([`Options::cross_validate`]): the
/// stages of `src/stages/` one after the other, each taking what the one
/// before gave.
pub fn diagnose_records(
    file: &SystemFile,
    data_paths: &[PathBuf],
    heldout_paths: &[PathBuf],
    options: &Options,
) -> Result<Diagnosis, String> {
    let started = Instant::now();
    // the clock of the time limit, and the progress counters
    let budget = Budget::new(options);
    // 1. the data read and inspected
    budget.progress().stage("reading the data");
    let Loaded {
        mut system,
        data,
        heldout_records,
        setup,
    } = load(file, data_paths, heldout_paths, options)?;
    // 2. the force the data imply, or the output-error set-up
    budget.progress().stage("the force the data imply");
    let force = estimate_force(
        file,
        &setup,
        &mut system,
        &data,
        heldout_records.as_ref(),
        options.smooth,
    )?;
    // every fit by output error: its many co-simulations reuse each
    // step's Newton Jacobian for the next (StrongCoupling::reuse_jacobian)
    let mut setup = setup;
    setup.reuse_jacobian = force.output_error_only.is_some();
    // 3. which samples fit and which score
    let split = Split::new(&data, &force.data, force.heldout.as_ref(), options)?;
    let problem = Problem::new(
        file,
        options,
        setup,
        (data, heldout_records),
        force,
        split,
        &budget,
    );
    // 4. the nominal scored, its levels refitted
    budget.progress().stage("the baseline");
    let mut sim = FrictionSim::new(&problem.setup.friction_fmu)?;
    let baseline = baseline(&problem, &mut system)?;
    // 5. and 6. the candidate rounds, each accepted model refined
    let mut polishing = Polishing::default();
    let search = search(&problem, &mut system, &mut sim, &baseline, &mut polishing)?;
    // 7. LuGre's pre-sliding against GMS's and the elasto-plastic law's
    let memory = check_memory(&problem, &baseline, &search);
    // 8. the report's figures
    budget.progress().stage("the summary");
    summarise(
        &problem,
        &mut sim,
        baseline,
        (search, memory),
        polishing,
        started,
    )
}

/// The co-simulation step is divided by this for the step-error estimate
/// and for the check that an accepted improvement survives a finer step.
pub const FINE_STEP_DIVISOR: f64 = 4.0;

/// What `fricsim diagnose` and `fricsim.diagnose` do: [`diagnose_records`],
/// the note of a Dahl nominal moved to LuGre (`moved`,
/// [`dahl::move_to_lugre`]) added to its notes, and the report written
/// into `out` ([`report::write`]); `progress` (the one in `options`, if
/// any) is told when the report is being written.
pub fn diagnose_and_write(
    file: &SystemFile,
    (data, heldout): (&[PathBuf], &[PathBuf]),
    options: &Options,
    moved: Option<String>,
    out: &Path,
) -> Result<Diagnosis, String> {
    let mut d = diagnose_records(file, data, heldout, options)?;
    if let Some(note) = moved {
        d.notes.push(note);
    }
    if let Some(progress) = &options.progress {
        progress.stage("writing the report");
    }
    report::write(&d, file, &d.friction_component, out)?;
    Ok(d)
}
