//! Stage 6, the refinement: an accepted model's fold models, and the
//! model reported, refined on the output error of their fit samples
//! ([`fit::polish`](crate::fit::polish), [`crate::POLISH_ITERATIONS`]).
//! The fold models are kept unrefined if a refined one's co-simulation
//! fails, or if the refinement raises the held-out error (it fits the
//! fit samples' noise): a reference worse than the fits it came from
//! would let every candidate of the next round pass for undoing it. The
//! reported model is refined too, unless its folds' refinement was not
//! kept.
//!
//! Past the time limit ([`crate::budget`]) the refinement is skipped; one
//! the limit cuts short keeps what it reached (the refined fold models
//! only if they score no worse), and the report says so.
//!
//! Takes the [`Problem`], the accepted [`Fitted`] models and the running
//! [`Polishing`] account; gives the refined [`Fitted`]. Called by the
//! candidate rounds for every accepted model and for a model an effect
//! was taken out of.

use super::problem::Problem;
use crate::acceptance::{mean, Scored};
use crate::model::FrictionModel;
use crate::system::System;
use crate::POLISH_ITERATIONS;
use rayon::prelude::*;
use std::time::Instant;

/// A model as fitted: one per fold, their score, and the model reported.
pub(crate) struct Fitted {
    pub(crate) folds: Vec<FrictionModel>,
    pub(crate) scored: Scored,
    pub(crate) whole: FrictionModel,
}

/// What the refinements cost.
#[derive(Default)]
pub(crate) struct Polishing {
    /// Co-simulations run.
    pub(crate) cosimulations: usize,
    pub(crate) seconds: f64,
}

/// Refine `fitted` ([the module](self)).
pub(crate) fn refine(
    p: &Problem,
    system: &mut System,
    fitted: Fitted,
    polishing: &mut Polishing,
) -> Fitted {
    const WHAT: &str = "the refinement on the output error of an accepted model";
    if p.budget.skip_if_expired(|| WHAT.into()) {
        return fitted;
    }
    p.budget
        .progress()
        .stage("refining the accepted model on the output error");
    let started = Instant::now();
    let (refined, _) = p.budget.cut_short(
        || WHAT.into(),
        || refine_in_time(p, system, fitted, polishing),
    );
    polishing.seconds += started.elapsed().as_secs_f64();
    refined
}

/// [`refine`], with the time limit checked by the fits.
fn refine_in_time(
    p: &Problem,
    system: &mut System,
    fitted: Fitted,
    polishing: &mut Polishing,
) -> Fitted {
    let Fitted {
        folds: models,
        scored,
        whole,
    } = fitted;
    let FoldsRefined {
        models,
        scored,
        kept,
        evaluations,
    } = refine_folds(p, system, models, scored);
    polishing.cosimulations += evaluations;
    let whole = if !kept && p.split.folds.len() > 1 {
        whole
    } else {
        polish_whole(p, whole, &models, polishing)
    };
    Fitted {
        folds: models,
        scored,
        whole,
    }
}

/// The model reported, `whole`, refined on the output error of every
/// sample as its fold models `folds` were on their fit samples; with one
/// fold, that fold's refined model.
pub(crate) fn polish_whole(
    p: &Problem,
    whole: FrictionModel,
    folds: &[FrictionModel],
    polishing: &mut Polishing,
) -> FrictionModel {
    if p.split.folds.len() == 1 {
        return folds[0].clone();
    }
    let polished = p.polish(&whole, &p.every_sample, POLISH_ITERATIONS);
    polishing.cosimulations += polished.evaluations;
    polished.model
}

/// Fold models refined on the output error of their fit samples, and
/// their score.
pub(crate) struct FoldsRefined {
    pub(crate) models: Vec<FrictionModel>,
    pub(crate) scored: Scored,
    /// Whether the refined models were kept: their co-simulation ran and
    /// their held-out error is not above the unrefined models'.
    pub(crate) kept: bool,
    /// Co-simulations of the refinement.
    pub(crate) evaluations: usize,
}

/// `models` (one per fold, scored as `scored`) refined on each fold's fit
/// samples for [`POLISH_ITERATIONS`] iterations, and scored again; the
/// unrefined ones are kept when the refined ones fail or score worse on
/// the held-out data.
pub(crate) fn refine_folds(
    p: &Problem,
    system: &mut System,
    models: Vec<FrictionModel>,
    scored: Scored,
) -> FoldsRefined {
    let polished: Vec<crate::fit::Fitted> = p
        .split
        .folds
        .par_iter()
        .zip(&models)
        .map(|(fold, m)| p.polish(m, &fold.fits, POLISH_ITERATIONS))
        .collect();
    let evaluations = polished.iter().map(|p| p.evaluations).sum::<usize>();
    let refined: Vec<FrictionModel> = polished.into_iter().map(|p| p.model).collect();
    let (models, scored, kept) = if refined == models {
        (models, scored, true)
    } else {
        match p.score(system, &refined) {
            Ok(s) if mean(&s.q) <= mean(&scored.q) => (refined, s, true),
            _ => (models, scored, false),
        }
    };
    FoldsRefined {
        models,
        scored,
        kept,
        evaluations,
    }
}
