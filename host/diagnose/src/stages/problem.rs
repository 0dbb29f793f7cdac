//! The diagnosis problem as the later stages see it: the system and its
//! set-up, the data records and the held-out records, their friction
//! data, the split into folds, the channel scales and the model context.
//! What the stages after the split do with it (score a model, fit one)
//! are its methods: [`super::scoring`] and [`super::fitting`].
//!
//! Built once from the outputs of stages 1 to 3 ([`Problem::new`]), then
//! only read (shared by the parallel fits).

use super::force::ForceEvidence;
use super::split::{Picker, Split};
use crate::budget::Budget;
use crate::model::Context;
use crate::problem::{FrictionData, Measured, Setup};
use crate::ssp::SystemFile;
use crate::tangent::Coupling;
use crate::{Options, FINE_STEP_DIVISOR};
use std::sync::atomic::AtomicUsize;
use std::sync::OnceLock;

/// What every stage after the split reads.
pub(crate) struct Problem<'a> {
    pub(crate) file: &'a SystemFile,
    pub(crate) options: &'a Options,
    /// The friction component, its rig, the master and step.
    pub(crate) setup: Setup,
    /// The data records, which the models are fitted on.
    pub(crate) data: Measured,
    /// The held-out records, when given.
    pub(crate) heldout_records: Option<Measured>,
    /// The friction data of both, and whether fits are by output error
    /// alone.
    pub(crate) force: ForceEvidence,
    pub(crate) split: Split,
    /// The standard deviation of each measured channel of the data
    /// records (1 for a constant one): residuals are divided by it.
    pub(crate) scales: Vec<f64>,
    /// The ranges the candidates start from ([`Setup::context`]).
    pub(crate) context: Context,
    /// Every sample of every data record (the model fitted on all of
    /// them).
    pub(crate) every_sample: Picker,
    /// The time limit and the progress counters ([`Budget`]).
    pub(crate) budget: &'a Budget,
    /// The output sensitivities of the output-error fits
    /// ([`crate::tangent`]), set at their first use.
    pub(crate) sensitivities: Sensitivities,
}

/// Whether the output-error fits take their Jacobian from the output
/// sensitivities ([`crate::tangent`]) and, if not, why.
#[derive(Default)]
pub(crate) struct Sensitivities {
    /// The system's coupling, or why it is not covered.
    pub(crate) coupling: OnceLock<Result<Coupling, String>>,
    /// Jacobians carried, and those differenced after all.
    pub(crate) carried: AtomicUsize,
    pub(crate) differenced: AtomicUsize,
    /// Why the first of those was differenced.
    pub(crate) first_failure: OnceLock<String>,
}

impl<'a> Problem<'a> {
    /// The problem of the loaded records ([`super::load::Loaded`]), their
    /// friction data and split, under `budget`.
    pub(crate) fn new(
        file: &'a SystemFile,
        options: &'a Options,
        setup: Setup,
        (data, heldout_records): (Measured, Option<Measured>),
        force: ForceEvidence,
        split: Split,
        budget: &'a Budget,
    ) -> Problem<'a> {
        let scales = channel_scales(&data);
        let context = setup.context(&force.data, options.position_knots);
        Problem {
            file,
            options,
            setup,
            data,
            heldout_records,
            force,
            split,
            scales,
            context,
            every_sample: Picker::all(),
            budget,
            sensitivities: Sensitivities::default(),
        }
    }

    /// The records the models are scored on: the held-out records when
    /// given, else the data records (each sample scored by a fold that
    /// was not fitted on it).
    pub(crate) fn scored_data(&self) -> &Measured {
        self.heldout_records.as_ref().unwrap_or(&self.data)
    }

    /// The friction data of [`Problem::scored_data`].
    pub(crate) fn scored_friction(&self) -> &FrictionData {
        self.force.heldout.as_ref().unwrap_or(&self.force.data)
    }

    /// The finer step of the step-error estimate and of the check that a
    /// gain survives a finer step.
    pub(crate) fn fine_step(&self) -> f64 {
        self.setup.step / FINE_STEP_DIVISOR
    }
}

/// Channel scales: the standard deviation of each measured channel (1 for
/// a constant one).
pub(crate) fn channel_scales(data: &Measured) -> Vec<f64> {
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
