//! Stage 4, the baseline and the refit: the nominal model as given scored
//! on the held-out data, the groups of the paired tests set from its
//! scored samples, and the nominal's levels refitted (Fc, Fc_neg or the
//! position scales, from three starts) and kept only when they pass the
//! acceptance rule against the nominal as given ([`RefitDecision`]), so
//! that the diagnosis never ends worse than the model it was given.
//!
//! Past the time limit ([`crate::budget`]) the refit is skipped, or not
//! kept when a fit of it stopped at the limit, and the step error is not
//! estimated (0); the nominal as given is always scored.
//!
//! Takes the [`Problem`] and the system; gives a [`Baseline`].

use super::fitting::level_starts;
use super::problem::Problem;
use crate::acceptance::{drop_beyond_step_error, nested_test, Acceptance, Scored};
use crate::model::FrictionModel;
use crate::system::System;
use crate::RefitDecision;

/// The model the candidate rounds start from, and the nominal it came
/// from.
pub(crate) struct Baseline {
    /// The nominal as given, scored.
    pub(crate) nominal_scored: Scored,
    /// The group of each scored sample in the paired tests
    /// ([`acceptance_groups`]).
    pub(crate) group: Vec<usize>,
    pub(crate) refit: RefitDecision,
    /// The refitted nominal when kept, else the nominal as given: the
    /// model reported, one per fold, and its score.
    pub(crate) model: FrictionModel,
    pub(crate) folds: Vec<FrictionModel>,
    pub(crate) scored: Scored,
    /// Its co-simulation's step error ([`Problem::step_error`]).
    pub(crate) step_error: f64,
}

/// Score the nominal, refit its levels, and keep the better.
pub(crate) fn baseline(p: &Problem, system: &mut System) -> Result<Baseline, String> {
    let nominal = &p.setup.nominal;
    let nominal_folds = vec![nominal.clone(); p.split.folds.len()];
    let nominal_scored = p.score(system, &nominal_folds).map_err(|e| {
        format!(
            "the nominal system as given cannot be co-simulated on {}: {e}",
            p.scored_data().label
        )
    })?;
    let group = acceptance_groups(p, &nominal_scored);
    let rule = Acceptance {
        threshold: p.options.alpha,
        min_gain: p.options.min_gain,
    };
    // past the time limit the refit is skipped, and one a fit of which
    // stopped at the limit is not kept (crate::budget)
    const REFIT: &str = "the refit of the nominal's levels";
    if p.budget.skip_if_expired(|| REFIT.into()) {
        return Ok(unrefitted(p, nominal_scored, group, rule, f64::NAN));
    }
    p.budget
        .progress()
        .stage("the baseline: the levels refitted");
    let (refit, cut) = p.budget.cut_short(
        || REFIT.into(),
        || -> Result<_, String> {
            let fits = p.fit_folds_any(&level_starts, &nominal_folds, &[], false)?;
            let model = p.fit_whole_any(&level_starts(nominal), &fits.models, &[], false)?;
            Ok((fits, model))
        },
    );
    let (refit_fits, refit_model) = refit?;
    if cut {
        return Ok(unrefitted(p, nominal_scored, group, rule, refit_fits.rms));
    }
    let refit_scored = p.score(system, &refit_fits.models);
    let nominal_step_error = step_error_in_time(p, system, &nominal_folds, &nominal_scored, GIVEN);
    let refit = match &refit_scored {
        Ok(scored) => {
            let (gain, p_value) = nested_test(&nominal_scored, scored, &p.scales, &group)?;
            let heldout_rms = scored.rms();
            RefitDecision {
                heldout_rms,
                gain,
                p_value,
                threshold: rule.threshold,
                kept: rule.passes(gain, p_value)
                    && drop_beyond_step_error(&nominal_scored, heldout_rms, nominal_step_error),
                force_rms: refit_fits.rms,
                failure: None,
                unfinished: false,
            }
        }
        Err(e) => RefitDecision {
            heldout_rms: f64::INFINITY,
            gain: f64::NEG_INFINITY,
            p_value: 1.0,
            threshold: rule.threshold,
            kept: false,
            force_rms: refit_fits.rms,
            failure: Some(e.clone()),
            unfinished: false,
        },
    };
    let (model, folds, scored) = match refit_scored {
        Ok(scored) if refit.kept => (refit_model, refit_fits.models, scored),
        _ => (nominal.clone(), nominal_folds, nominal_scored.clone()),
    };
    // the current model's step error: what a quarter step changes in its
    // outputs (a drop of the error smaller than that may compensate the
    // co-simulation's step error, not physics)
    let step_error = if refit.kept {
        step_error_in_time(p, system, &folds, &scored, "the refitted nominal")
    } else {
        nominal_step_error
    };
    Ok(Baseline {
        nominal_scored,
        group,
        refit,
        model,
        folds,
        scored,
        step_error,
    })
}

/// The co-simulation's step error of `folds` scored as `scored`
/// ([`Problem::step_error`]) when the time limit has not passed; else
/// skipped, and 0 (`which`: whose, for the report).
fn step_error_in_time(
    p: &Problem,
    system: &mut System,
    folds: &[FrictionModel],
    scored: &Scored,
    which: &str,
) -> f64 {
    if p.budget.skip_if_expired(|| {
        format!(
            "the co-simulation's step error of {which} (taken as 0: the floor is the noise alone)"
        )
    }) {
        0.0
    } else {
        p.step_error(system, folds, scored)
    }
}

/// The baseline when the refit was skipped or cut short by the time
/// limit: the nominal as given, the refit not kept (`force_rms`: of the
/// refit's fits, NaN when none ran), the step error skipped (the limit
/// has passed).
fn unrefitted(
    p: &Problem,
    nominal_scored: Scored,
    group: Vec<usize>,
    rule: Acceptance,
    force_rms: f64,
) -> Baseline {
    let nominal = &p.setup.nominal;
    p.budget.skip(format!(
        "the co-simulation's step error of {GIVEN} (taken as 0: the floor is the noise alone)"
    ));
    Baseline {
        refit: RefitDecision {
            heldout_rms: f64::INFINITY,
            gain: f64::NEG_INFINITY,
            p_value: 1.0,
            threshold: rule.threshold,
            kept: false,
            force_rms,
            failure: None,
            unfinished: true,
        },
        model: nominal.clone(),
        folds: vec![nominal.clone(); p.split.folds.len()],
        scored: nominal_scored.clone(),
        nominal_scored,
        group,
        step_error: 0.0,
    }
}

/// The nominal as given, in the report's list of what was skipped.
const GIVEN: &str = "the nominal as given";

/// The groups of the acceptance test: the held-out blocks when there are
/// at least [`crate::Options::groups`] of them (each block an independent
/// trial, `--blocks`), else that many runs of consecutive held-out
/// samples; one label per sample `scored` picked.
pub(crate) fn acceptance_groups(p: &Problem, scored: &Scored) -> Vec<usize> {
    let picked = &scored.picked;
    let n = picked.len();
    let time = &p.scored_data().time;
    let by_block: Vec<usize> = picked
        .iter()
        .map(|&k| p.split.blocks.block(time[scored.residuals.samples[k]]))
        .collect();
    let held_blocks = 1 + by_block.windows(2).filter(|w| w[0] != w[1]).count();
    if p.heldout_records.is_none() && held_blocks >= p.options.groups {
        by_block
    } else {
        let g = p.options.groups.clamp(2, n.max(2));
        (0..n).map(|i| i * g / n.max(1)).collect()
    }
}
