//! Stage 7 (after the candidate rounds, before the summary): whether the
//! held-out data prefer GMS's pre-sliding memory to LuGre's
//! ([`crate::memory`]). The final LuGre model's fold models are moved to
//! GMS with their levels and stiffness as the start, each fitted on its
//! fold's fit samples by output error (the memory lives in the stick,
//! which the force the data imply leaves out), scored on the held-out
//! samples as every candidate is, and compared with LuGre's score by the
//! paired test of two explanations that are not nested
//! ([`separation_test`]) under the one acceptance rule
//! ([`Acceptance`]). When it passes, the diagnosis names the effect
//! `presliding_memory` and reports the GMS that replaces LuGre.
//!
//! Tried only where the comparison means something: a LuGre model GMS can
//! hold (one level in both directions, no position table, no normal-force
//! form, no offset), pre-sliding the data resolve (the final model's
//! pre-sliding distance `Fs/σ0` at least [`RESOLVED_STEPS`] times the
//! position resolution), `GMS.fmu` beside the friction FMU, and time left.
//! Otherwise the report says which of these it lacked.
//!
//! Takes the [`Problem`] and the [`Search`]; gives a [`MemoryCheck`].

use super::baseline::acceptance_groups;
use super::problem::Problem;
use super::rounds::Search;
use super::split::Picker;
use crate::acceptance::{drop_beyond_step_error, mean, separation_test, Acceptance, Scored};
use crate::fit::{polish_any, Coordinates, ResidualsOf};
use crate::memory::{
    moved_to_gms, GmsCoordinates, GmsModel, MemoryCheck, MemoryOutcome, LAG_STARTS,
};
use crate::model::FrictionModel;
use crate::sim::system_parameters_with;
use crate::POLISH_ITERATIONS;
use nalgebra::DVector;
use rayon::prelude::*;
use std::time::Instant;

/// Pre-sliding shorter than this many position resolutions is not
/// resolved well enough to tell one memory from another.
pub const RESOLVED_STEPS: f64 = 5.0;

/// Why `m` cannot be moved to GMS, if it cannot: the LuGre features GMS
/// does not have.
fn gms_cannot_hold(m: &FrictionModel) -> Option<String> {
    let features = [
        (m.direction_dependent, "direction-dependent levels"),
        (
            m.direction_dependent_viscous,
            "direction-dependent viscous friction",
        ),
        (m.position_dependent, "a position table"),
        (m.normal_force_form, "the normal-force form"),
        (m.f_offset != 0.0, "an offset force"),
    ];
    let held: Vec<&str> = features
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, name)| *name)
        .collect();
    (!held.is_empty()).then(|| {
        format!(
            "the final LuGre model has {}, which GMS does not",
            held.join(" and ")
        )
    })
}

/// Run the check ([the module](self)).
pub(crate) fn check_memory(p: &Problem, search: &Search) -> MemoryCheck {
    let lugre_rms = search.scored.rms();
    let threshold = p.options.alpha;
    let not_tried = |reason: String| MemoryCheck::not_tried(lugre_rms, threshold, reason);
    if let Some(why) = gms_cannot_hold(&search.current) {
        return not_tried(why);
    }
    let distance = search.current.fs.max(search.current.fc) / search.current.sigma0;
    let resolution = p.context.position_resolution;
    if distance.is_nan() || distance < RESOLVED_STEPS * resolution {
        return not_tried(format!(
            "the data do not resolve pre-sliding: the final model's pre-sliding distance Fs/σ0 = {distance:.3e} m is under {RESOLVED_STEPS} times the position resolution {resolution:.3e} m"
        ));
    }
    let Some(component) = p
        .file
        .components
        .iter()
        .find(|c| c.name == p.setup.friction_name)
    else {
        return not_tried(format!(
            "no component `{}` in the system file",
            p.setup.friction_name
        ));
    };
    let gms_path = component.source.with_file_name("GMS.fmu");
    if !gms_path.is_file() {
        return not_tried(format!(
            "no GMS.fmu beside the friction FMU ({} does not exist)",
            gms_path.display()
        ));
    }
    const WHAT: &str = "the check of the pre-sliding memory (GMS against LuGre)";
    if p.budget.skip_if_expired(|| WHAT.into()) {
        return not_tried("the time limit was reached before it".into());
    }
    p.budget
        .progress()
        .stage("pre-sliding memory: GMS against LuGre");
    let started = Instant::now();
    let (outcome, cut) = p
        .budget
        .cut_short(|| WHAT.into(), || try_gms(p, search, &gms_path));
    let mut check = match outcome {
        Ok(check) => check,
        Err(e) => not_tried(format!("GMS could not be scored: {e}")),
    };
    if cut && check.outcome == MemoryOutcome::Moved {
        // a fit the limit stopped is not taken as a finding
        check.outcome = MemoryOutcome::Kept;
        check.reason = Some("the time limit stopped the GMS fit; LuGre is kept".into());
    }
    check.gms_fmu = Some(gms_path);
    check.seconds = started.elapsed().as_secs_f64();
    check
}

/// Fit GMS on each fold, score it, decide.
fn try_gms(
    p: &Problem,
    search: &Search,
    gms_path: &std::path::Path,
) -> Result<MemoryCheck, String> {
    let file = moved_to_gms(p.file, &p.setup.friction_name, gms_path)?;
    let params =
        |m: &GmsModel| system_parameters_with(&file, &p.setup.friction_name, m.parameters());
    let cosimulations = std::sync::atomic::AtomicUsize::new(0);
    // one GMS per fold, from the fold's LuGre
    let fit = |lugre: &FrictionModel, pick: &Picker| -> GmsModel {
        let residuals = |m: &GmsModel| {
            cosimulations.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            p.fit_residuals_of(&file, &params(m), pick, None)
        };
        let cost = |m: &GmsModel| residuals(m).map_or(f64::INFINITY, |r| r.norm_squared());
        let starts: Vec<GmsModel> = LAG_STARTS
            .iter()
            .map(|&lag| GmsModel::from_lugre(lugre, lag))
            .collect();
        let costs: Vec<f64> = starts.par_iter().map(cost).collect();
        let best = (0..starts.len())
            .min_by(|&a, &b| costs[a].total_cmp(&costs[b]))
            .unwrap_or(0);
        let mut residual = |models: &[GmsModel]| -> Vec<Option<DVector<f64>>> {
            if p.budget.stop_here() {
                return Vec::new();
            }
            models.par_iter().map(residuals).collect()
        };
        let residual: &mut ResidualsOf<'_, GmsModel> = &mut residual;
        let coordinates = GmsCoordinates {
            start: starts[best].clone(),
        };
        let budget = POLISH_ITERATIONS * (coordinates.theta().len() + 1) + 1;
        polish_any(coordinates, residual, budget).0
    };
    let folds: Vec<GmsModel> = p
        .split
        .folds
        .par_iter()
        .zip(&search.folds)
        .map(|(fold, lugre)| fit(lugre, &fold.fits))
        .collect();
    let whole = if folds.len() == 1 {
        folds[0].clone()
    } else {
        fit(&search.current, &p.every_sample)
    };
    let mut system = file.build(0.0).map_err(|e| e.to_string())?;
    let fold_params: Vec<_> = folds.iter().map(&params).collect();
    let scored: Scored = p.score_parameters_at(&mut system, &fold_params, None)?;
    let lugre = &search.scored;
    let group = acceptance_groups(p, lugre);
    let p_value = separation_test(&scored, lugre, &group).map_err(|e| e.to_string())?;
    let (ml, mg) = (mean(&lugre.q), mean(&scored.q));
    let gain = if ml > 0.0 { (ml - mg) / ml } else { 0.0 };
    let rule = Acceptance {
        threshold: p.options.alpha,
        min_gain: p.options.min_gain,
    };
    let moved = rule.passes(gain, p_value)
        && drop_beyond_step_error(lugre, scored.rms(), search.step_error);
    Ok(MemoryCheck {
        outcome: if moved {
            MemoryOutcome::Moved
        } else {
            MemoryOutcome::Kept
        },
        reason: None,
        lugre_heldout_rms: lugre.rms(),
        gms_heldout_rms: scored.rms(),
        gain,
        p_value,
        threshold: rule.threshold,
        gms: Some(whole),
        gms_fmu: None,
        cosimulations: cosimulations.into_inner() + p.split.folds.len(),
        seconds: 0.0,
    })
}
