//! Scoring a model: the fold models co-simulated on the scored data and
//! their residuals on the samples each fold scores, merged into one
//! [`Scored`]; and the co-simulation's own step error.
//!
//! Methods of [`Problem`]; take fold models (one per fold) and a system
//! to co-simulate, give a [`Scored`] (or why its co-simulation failed).

use super::problem::Problem;
use crate::acceptance::Scored;
use crate::model::FrictionModel;
use crate::sim::{co_simulate_robust, co_simulate_with, system_parameters, ChannelResiduals};
use crate::system::{ParameterValue, System};
use crate::FINE_STEP_DIVISOR;

impl Problem<'_> {
    /// `models` (one per fold) co-simulated on the scored data and scored
    /// on its fold's samples: merged, every scored sample comes from a
    /// model that was not fitted on it. `step`: `None` for the system's
    /// step with the fallbacks of [`co_simulate_robust`], or a finer step
    /// without them (for the co-simulation's own step error and for the
    /// check that an improvement survives a finer step).
    fn score_at(
        &self,
        system: &mut System,
        models: &[FrictionModel],
        step: Option<f64>,
    ) -> Result<Scored, String> {
        let parameters: Vec<_> = models
            .iter()
            .map(|m| system_parameters(self.file, &self.setup, m))
            .collect();
        self.score_parameters_at(system, &parameters, step)
    }

    /// [`Problem::score_at`] of the system's parameters, one set per fold
    /// (a system whose friction is another law than LuGre,
    /// [`crate::memory`]).
    pub(crate) fn score_parameters_at(
        &self,
        system: &mut System,
        fold_parameters: &[Vec<(String, ParameterValue)>],
        step: Option<f64>,
    ) -> Result<Scored, String> {
        let scored_data = self.scored_data();
        let mut merged: Option<ChannelResiduals> = None;
        let mut picked = Vec::new();
        let mut notes = Vec::new();
        for (fold, params) in self.split.folds.iter().zip(fold_parameters) {
            let params = params.as_slice();
            let records = fold.scores.records.as_deref();
            self.budget.cosimulation();
            let r = match step {
                None => {
                    let (r, note) =
                        co_simulate_robust(system, params, &self.setup, scored_data, records)?;
                    notes.extend(note);
                    r
                }
                Some(h) => {
                    let r = co_simulate_with(
                        system,
                        params,
                        scored_data,
                        records,
                        &self.setup.master,
                        h,
                        self.setup.reuse_jacobian,
                    )?;
                    if let Some(e) = &r.incomplete {
                        return Err(e.clone());
                    }
                    r
                }
            };
            let mine = (fold.scores.pick)(&r);
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
        let q_all = residuals.squared(&self.scales);
        let q = picked.iter().map(|&k| q_all[k]).collect();
        Ok(Scored {
            residuals,
            picked,
            q,
            fallback: (!notes.is_empty()).then(|| notes.join("; ")),
        })
    }

    /// `models` scored at the system's step, with the fallbacks.
    pub(crate) fn score(
        &self,
        system: &mut System,
        models: &[FrictionModel],
    ) -> Result<Scored, String> {
        self.score_at(system, models, None)
    }

    /// `models` scored at [`Problem::fine_step`], without fallbacks.
    pub(crate) fn score_fine(
        &self,
        system: &mut System,
        models: &[FrictionModel],
    ) -> Result<Scored, String> {
        self.score_at(system, models, Some(self.fine_step()))
    }

    /// The co-simulation's step error of `models` scored as `scored`
    /// ([`step_error_floor`]; 0 when the finer co-simulation fails).
    pub(crate) fn step_error(
        &self,
        system: &mut System,
        models: &[FrictionModel],
        scored: &Scored,
    ) -> f64 {
        self.score_fine(system, models)
            .map_or(0.0, |fine| step_error_floor(scored, &fine, &self.scales))
    }
}

/// The co-simulation's step error on the held-out samples: the RMS of the
/// normalised change of the simulated channels when the step is divided by
/// [`FINE_STEP_DIVISOR`] (4), times 4/3 (Richardson for a first-order
/// error, e(h) = (y(h) − y(h/4))·4/3; a stick-slip co-simulation converges
/// at first order, its slips timed to within a step; higher orders need
/// less).
pub(crate) fn step_error_floor(scored: &Scored, fine: &Scored, scales: &[f64]) -> f64 {
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
