//! The diagnosis as a pipeline of stages, each taking what the one before
//! gave ([`crate::diagnose_records`] calls them in this order):
//!
//! 1. [`load`]: the system built, the data records and the held-out
//!    records read, inspected and joined, the set-up around the friction
//!    component found ([`load::Loaded`]);
//! 2. [`force`]: the friction force the data imply, or the law's states
//!    along the nominal co-simulation when it cannot be estimated (every
//!    fit then by output error) ([`force::ForceEvidence`]);
//! 3. [`split`]: the folds, which samples fit and which score
//!    ([`split::Split`]); with the above it makes the [`problem::Problem`]
//!    the later stages read, whose methods score a model ([`scoring`]) and
//!    fit one ([`fitting`]);
//! 4. [`baseline`]: the nominal as given scored, its levels refitted and
//!    kept only when they pass the acceptance rule
//!    ([`baseline::Baseline`]);
//! 5. [`rounds`]: the candidate rounds, with the re-examination of the
//!    effects accepted before ([`rounds::Search`]); which of several
//!    explanations of one signature the data prefer is in
//!    `rounds/explanations.rs`, whether the data resolve a candidate's
//!    change in `rounds/resolution.rs`;
//! 6. [`refine`]: each accepted model refined on the output error (called
//!    by the rounds for every accepted model);
//! 7. [`memory`]: whether the held-out data prefer GMS's pre-sliding
//!    memory to LuGre's ([`crate::memory`]); the nominal moved to GMS
//!    when they do;
//! 8. [`summary`]: the intervals, the floor, the localisation, the
//!    report's figures: the [`crate::Diagnosis`].
//!
//! The tests that decide are in [`crate::acceptance`]. The time limit
//! ([`crate::budget`], carried in the [`problem::Problem`]) is checked by
//! the fits before each co-simulation and by the stages before each step
//! that costs: past it, the round in progress is not decided and the
//! steps after it are skipped, each named in the report.

pub(crate) mod baseline;
pub(crate) mod fitting;
pub(crate) mod force;
pub(crate) mod load;
pub(crate) mod memory;
pub(crate) mod problem;
pub(crate) mod refine;
pub(crate) mod rounds;
pub(crate) mod scoring;
pub(crate) mod split;
pub(crate) mod summary;

use crate::model::FrictionModel;
use crate::problem::FrictionData;
use crate::sim::FrictionSim;

/// The friction force of `model` after each interval of `d`
/// ([`FrictionSim::run`]).
pub(crate) fn run_force(
    sim: &mut FrictionSim,
    model: &FrictionModel,
    d: &FrictionData,
) -> Result<Vec<f64>, String> {
    sim.run(model, d)
        .map_err(|e| format!("friction FMU along the data: {e}"))
}
