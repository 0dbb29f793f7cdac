//! Fitting a model: on the force the data imply ([`fit::fit`], on each
//! fold's fit intervals) or by output error through co-simulation of the
//! fit samples ([`fit::polish`]), per fold and for the model reported;
//! and the starts a fit begins from.
//!
//! Methods of [`Problem`]; take starts (a function from a fold's current
//! model to the models to start from) and give [`FoldFits`] or one model.

use super::problem::Problem;
use super::split::Picker;
use crate::fit::{self, Coordinates};
use crate::intervals;
use crate::model::{Effect, FrictionModel};
use crate::sim::{
    co_simulate_robust, co_simulate_with, co_simulate_with_sensitivities, system_parameters,
    FrictionSim,
};
use crate::ssp::SystemFile;
use crate::system::ParameterValue;
use crate::tangent::Coupling;
use crate::{CANDIDATE_OUTPUT_ERROR_ITERATIONS, OUTPUT_ERROR_STARTS_REFINED};
use nalgebra::{DMatrix, DVector};
use std::fmt::Write as _;
use std::sync::atomic::Ordering;

use rayon::prelude::*;

/// The models a fit starts from, built from a fold's current model.
pub(crate) type Starts<'s> = dyn Fn(&FrictionModel) -> Vec<FrictionModel> + Sync + 's;

/// One fit per fold.
pub(crate) struct FoldFits {
    /// One per fold.
    pub(crate) models: Vec<FrictionModel>,
    /// The mean over the folds of each fit's RMS ([`fit::Fitted::rms`]).
    pub(crate) rms: f64,
    pub(crate) evaluations: usize,
}

impl FoldFits {
    fn of(fitted: Vec<fit::Fitted>) -> FoldFits {
        let rms = fitted.iter().map(|f| f.rms).sum::<f64>() / fitted.len() as f64;
        let evaluations = fitted.iter().map(|f| f.evaluations).sum();
        FoldFits {
            models: fitted.into_iter().map(|f| f.model).collect(),
            rms,
            evaluations,
        }
    }
}

impl Problem<'_> {
    /// The normalised output residuals of `m` on the fit samples `pick` of
    /// the data records (`step`: at that macro step instead, with the
    /// diagnosis's master and no fallback); `None` when the co-simulation
    /// fails.
    pub(crate) fn fit_residuals(
        &self,
        m: &FrictionModel,
        pick: &Picker,
        step: Option<f64>,
    ) -> Option<DVector<f64>> {
        let params = system_parameters(self.file, &self.setup, m);
        self.fit_residuals_of(self.file, &params, pick, step)
    }

    /// [`Problem::fit_residuals`] of the system `file` with `params` (a
    /// system whose friction is another law than LuGre,
    /// [`crate::memory`]).
    pub(crate) fn fit_residuals_of(
        &self,
        file: &SystemFile,
        params: &[(String, ParameterValue)],
        pick: &Picker,
        step: Option<f64>,
    ) -> Option<DVector<f64>> {
        // past the time limit: none (the fit stops, crate::budget)
        if self.budget.stop_here() {
            return None;
        }
        self.budget.cosimulation();
        // a system of its own (an FMU instance stays on its thread)
        let mut system = file.build(0.0).ok()?;
        let records = pick.records.as_deref();
        let r = match step {
            None => {
                co_simulate_robust(&mut system, params, &self.setup, &self.data, records)
                    .ok()?
                    .0
            }
            Some(h) => co_simulate_with(
                &mut system,
                params,
                &self.data,
                records,
                &self.setup.master,
                h,
                self.setup.reuse_jacobian,
            )
            .ok()?,
        };
        if r.incomplete.is_some() {
            return None;
        }
        let picked = (pick.pick)(&r);
        let scales = &self.scales;
        let channels = scales.len();
        let norm = ((picked.len() * channels) as f64).sqrt();
        Some(DVector::from_iterator(
            picked.len() * channels,
            picked.iter().flat_map(|&s| {
                let r = &r;
                (0..channels).map(move |c| r.residuals[c][s] / scales[c] / norm)
            }),
        ))
    }

    /// The covariance of `model`'s fitted parameters from the output error
    /// of the samples `pick` ([`intervals::theta_covariance`]), with the
    /// same residuals co-simulated at the finer step for the step error's
    /// bias. `None` when a co-simulation fails or a free parameter does
    /// not move the residuals.
    pub(crate) fn covariance_on(
        &self,
        model: &FrictionModel,
        pick: &Picker,
    ) -> Option<intervals::ThetaCovariance> {
        let mut residual = |models: &[FrictionModel]| -> Vec<Option<DVector<f64>>> {
            models
                .par_iter()
                .map(|m| self.fit_residuals(m, pick, None))
                .collect()
        };
        let fine = self.fit_residuals(model, pick, Some(self.fine_step()));
        intervals::theta_covariance(
            model,
            &mut residual,
            fine.as_ref(),
            self.scales.len(),
            self.options.groups,
        )
    }

    /// Refine `model` on the output error of the fit samples `pick`, for
    /// at most `iterations` Levenberg–Marquardt iterations
    /// ([`fit::polish`]).
    pub(crate) fn polish(
        &self,
        model: &FrictionModel,
        pick: &Picker,
        iterations: usize,
    ) -> fit::Fitted {
        let mut residual = |models: &[FrictionModel]| -> Vec<Option<DVector<f64>>> {
            // past the time limit: no residuals, the fit stops with the
            // best it has (crate::budget)
            if self.budget.stop_here() {
                return Vec::new();
            }
            models
                .par_iter()
                .map(|m| self.fit_residuals(m, pick, None))
                .collect()
        };
        let budget = iterations * (model.free().len() + 1) + 1;
        let mut exact = |c: &fit::Freed, theta: &[f64]| self.output_jacobian(c, theta, pick);
        fit::polish(model, &mut residual, Some(&mut exact), budget)
    }

    /// The coupling of the system whose output sensitivities the
    /// output-error fits can carry ([`crate::tangent`]), or why not.
    pub(crate) fn coupling(&self) -> Result<&Coupling, &str> {
        self.sensitivities
            .coupling
            .get_or_init(|| {
                let system = self
                    .file
                    .build(0.0)
                    .map_err(|e| format!("building the system: {e}"))?;
                let params = system_parameters(self.file, &self.setup, &self.setup.nominal);
                Coupling::new(
                    &system,
                    self.setup.friction,
                    &params,
                    (&self.data.time, &self.data.inputs),
                )
            })
            .as_ref()
            .map_err(String::as_str)
    }

    /// Where the output-error fits took their Jacobian from, for the
    /// report ([`crate::Diagnosis::output_jacobian`]).
    pub(crate) fn output_jacobian_words(&self) -> String {
        let s = &self.sensitivities;
        let (carried, differenced) = (
            s.carried.load(Ordering::Relaxed),
            s.differenced.load(Ordering::Relaxed),
        );
        match s.coupling.get() {
            None => "no output-error fit".into(),
            Some(Err(why)) => format!("forward differences ({why})"),
            Some(Ok(_)) => {
                let mut words = format!(
                    "output sensitivities carried along one co-simulation for {carried} of {} Jacobians",
                    carried + differenced
                );
                if let Some(why) = s.first_failure.get() {
                    let _ = write!(
                        words,
                        "; forward differences for the others (the first: {why})"
                    );
                }
                words
            }
        }
    }

    /// The Jacobian of the output residuals of the fit samples `pick` in
    /// the coordinates θ of `c`, from one co-simulation that carries the
    /// output sensitivities ([`crate::tangent`]); `None` (forward
    /// differences instead) where the system is not covered or the
    /// co-simulation or the sensitivities fail (counted, with the first
    /// reason, for the report).
    fn output_jacobian(
        &self,
        c: &fit::Freed,
        theta: &[f64],
        pick: &Picker,
    ) -> Option<DMatrix<f64>> {
        let coupling = self.coupling().ok()?;
        if self.budget.stop_here() {
            return None;
        }
        let s = &self.sensitivities;
        match self.carried_jacobian(coupling, c, theta, pick) {
            Ok(jacobian) => {
                s.carried.fetch_add(1, Ordering::Relaxed);
                Some(jacobian)
            }
            Err(why) => {
                s.differenced.fetch_add(1, Ordering::Relaxed);
                let _ = s.first_failure.set(why);
                None
            }
        }
    }

    /// [`Self::output_jacobian`], or why it could not be carried.
    fn carried_jacobian(
        &self,
        coupling: &Coupling,
        c: &fit::Freed,
        theta: &[f64],
        pick: &Picker,
    ) -> Result<DMatrix<f64>, String> {
        let map = fit::parameter_map(&c.model, &c.free, theta);
        let names: Vec<String> = map.iter().map(|(n, _)| n.clone()).collect();
        let model = c.at(theta);
        let params = system_parameters(self.file, &self.setup, &model);
        self.budget.cosimulation();
        let mut system = self
            .file
            .build(0.0)
            .map_err(|e| format!("building the system: {e}"))?;
        let (r, by_sample) = co_simulate_with_sensitivities(
            &mut system,
            (&params, &model.parameters()),
            &self.setup,
            &self.data,
            pick.records.as_deref(),
            coupling,
            &names,
        )?;
        let picked = (pick.pick)(&r);
        let channels = self.scales.len();
        let norm = ((picked.len() * channels) as f64).sqrt();
        let mut jacobian = DMatrix::<f64>::zeros(picked.len() * channels, theta.len());
        for (row, &s) in picked.iter().enumerate() {
            for (ch, sens) in by_sample.iter().enumerate() {
                // residual = measured − simulated
                let scale = -1.0 / (self.scales[ch] * norm);
                for (i, (_, dp)) in map.iter().enumerate() {
                    let ds = sens[(s, i)] * scale;
                    for (j, &d) in dp.iter().enumerate() {
                        jacobian[(row * channels + ch, j)] += ds * d;
                    }
                }
            }
        }
        if jacobian.iter().all(|x| x.is_finite()) {
            Ok(jacobian)
        } else {
            Err("a sensitivity is not finite".into())
        }
    }

    /// Fit by output error alone, for an effect the force the data imply
    /// cannot show (presliding: its hysteresis lives in the stick, which
    /// the force fits leave out): the starts scored by co-simulating the
    /// fit samples `pick`, then the best refined ([`Problem::polish`]).
    ///
    /// Where the data give no force (another plant than Rig1D) the
    /// [`OUTPUT_ERROR_STARTS_REFINED`] best starts are refined for one
    /// iteration each, and the best of those for the rest of the
    /// screen's [`CANDIDATE_OUTPUT_ERROR_ITERATIONS`]; on Rig1D the best
    /// start only, for all of them (one of the starts is the force fit's
    /// result, near the optimum already).
    pub(crate) fn fit_output_error(&self, starts: &[FrictionModel], pick: &Picker) -> fit::Fitted {
        let costs: Vec<f64> = starts
            .par_iter()
            .map(|m| {
                self.fit_residuals(m, pick, None)
                    .map_or(f64::INFINITY, |r| r.norm_squared())
            })
            .collect();
        let mut order: Vec<usize> = (0..starts.len()).collect();
        order.sort_by(|&a, &b| costs[a].total_cmp(&costs[b]));
        if self.force.output_error_only.is_none() {
            order.truncate(1);
            let mut fitted =
                self.polish(&starts[order[0]], pick, CANDIDATE_OUTPUT_ERROR_ITERATIONS);
            fitted.evaluations += starts.len();
            return fitted;
        }
        // one iteration from each of the best starts, the rest of the
        // screen's iterations from the best of those
        order.truncate(OUTPUT_ERROR_STARTS_REFINED);
        let first: Vec<fit::Fitted> = order
            .par_iter()
            .map(|&k| self.polish(&starts[k], pick, 1))
            .collect();
        let mut evaluations: usize = first.iter().map(|f| f.evaluations).sum();
        let best = first
            .into_iter()
            .min_by(|a, b| a.rms.total_cmp(&b.rms))
            .expect("a fit has a start");
        let further = CANDIDATE_OUTPUT_ERROR_ITERATIONS.saturating_sub(1);
        let mut fitted = if further > 0 {
            let more = self.polish(&best.model, pick, further);
            evaluations += more.evaluations;
            if more.rms <= best.rms {
                more
            } else {
                best
            }
        } else {
            best
        };
        fitted.evaluations = evaluations + starts.len();
        fitted
    }

    /// The model reported: fitted on every fit interval (the fold's own
    /// model when there is one fold).
    fn fit_whole(
        &self,
        starts: &[FrictionModel],
        fold_models: &[FrictionModel],
    ) -> Result<FrictionModel, String> {
        if self.split.folds.len() == 1 {
            return Ok(fold_models[0].clone());
        }
        let mut sim = FrictionSim::new(&self.setup.friction_fmu)?;
        Ok(fit::fit(
            starts,
            &mut sim,
            &self.force.data,
            &self.split.fit_intervals,
        )
        .model)
    }

    /// Fit `starts` (per fold: built from that fold's model in `base`) on
    /// each fold by output error alone ([`Problem::fit_output_error`]);
    /// `also`: one more start per fold (the force fit's result, when there
    /// is one).
    fn fit_folds_output_error(
        &self,
        starts: &Starts,
        base: &[FrictionModel],
        also: &[FrictionModel],
    ) -> FoldFits {
        let fitted: Vec<fit::Fitted> = self
            .split
            .folds
            .par_iter()
            .zip(base)
            .enumerate()
            .map(|(i, (fold, b))| {
                let mut s = starts(b);
                s.extend(also.get(i).cloned());
                self.fit_output_error(&s, &fold.fits)
            })
            .collect();
        FoldFits::of(fitted)
    }

    /// Fit `starts` (per fold: built from that fold's model in `base`) on
    /// each fold's intervals of the force the data imply.
    fn fit_folds(&self, starts: &Starts, base: &[FrictionModel]) -> Result<FoldFits, String> {
        let fitted: Vec<Result<fit::Fitted, String>> = self
            .split
            .folds
            .par_iter()
            .zip(base)
            .map(|(fold, b)| {
                let mut sim = FrictionSim::new(&self.setup.friction_fmu)?;
                Ok(fit::fit(
                    &starts(b),
                    &mut sim,
                    &self.force.data,
                    &fold.fit_intervals,
                ))
            })
            .collect();
        Ok(FoldFits::of(fitted.into_iter().collect::<Result<_, _>>()?))
    }

    /// Whether the addition `added` is fitted by output error: when the
    /// force cannot show it ([`Effect::force_shows`]) or is not estimated
    /// at all (another plant); else on the force.
    pub(crate) fn by_output_error(&self, added: &[Effect]) -> bool {
        self.force.output_error_only.is_some() || added.iter().any(|e| !e.force_shows())
    }

    /// Fit `starts` on each fold, by output error or on the force as
    /// [`Problem::by_output_error`] says for `added`. `oe`: by output
    /// error whatever the addition, the force fit's result as a start (an
    /// effect fitted to compete with one fitted so, see
    /// [`Effect::OVERLAPPING`]).
    pub(crate) fn fit_folds_any(
        &self,
        starts: &Starts,
        base: &[FrictionModel],
        added: &[Effect],
        oe: bool,
    ) -> Result<FoldFits, String> {
        if self.force.output_error_only.is_some() {
            Ok(self.fit_folds_output_error(starts, base, &[]))
        } else if oe || self.by_output_error(added) {
            // the force fit's result as one more start: what the force
            // shows of the effect outside the stick
            let forced = self.fit_folds(starts, base)?;
            let by_output = self.fit_folds_output_error(starts, base, &forced.models);
            Ok(FoldFits {
                evaluations: forced.evaluations + by_output.evaluations,
                ..by_output
            })
        } else {
            self.fit_folds(starts, base)
        }
    }

    /// The model reported for fold models `fold_models` fitted as
    /// [`Problem::fit_folds_any`] fitted them: by output error on every
    /// sample, or on every fit interval of the force.
    pub(crate) fn fit_whole_any(
        &self,
        starts: &[FrictionModel],
        fold_models: &[FrictionModel],
        added: &[Effect],
        oe: bool,
    ) -> Result<FrictionModel, String> {
        if (oe || self.by_output_error(added)) && self.split.folds.len() > 1 {
            Ok(self.fit_output_error(starts, &self.every_sample).model)
        } else {
            self.fit_whole(starts, fold_models)
        }
    }

    /// The starts of an addition to a model: its first effects added
    /// neutrally, the last from a grid ([`FrictionModel::starts`]); and the same from the
    /// levels as given, when the baseline's refit moved them (a refit of
    /// the levels alone may have bent them to mimic the missing effect, a
    /// raised Fc standing in for a viscous term).
    pub(crate) fn addition_starts<'s>(
        &'s self,
        added: &[Effect],
    ) -> impl Fn(&FrictionModel) -> Vec<FrictionModel> + Sync + 's {
        let added = added.to_vec();
        let context = &self.context;
        let nominal_levels = &self.setup.nominal;
        move |m: &FrictionModel| -> Vec<FrictionModel> {
            let (last, first) = added.split_last().expect("an addition has an effect");
            let mut base = m.clone();
            for &e in first {
                base = base.with(e, context);
            }
            let mut s = base.starts(*last, context);
            let given = base.with_levels_of(nominal_levels);
            if given != base {
                s.extend(given.starts(*last, context));
            }
            s
        }
    }
}

/// The starts of the nominal's levels refitted (the effects' own
/// parameters stay as given: an effect that is off is a candidate of its
/// own): from the nominal and from levels 20 % lower and 25 % higher.
pub(crate) fn level_starts(m: &FrictionModel) -> Vec<FrictionModel> {
    [1.0, 0.8, 1.25].map(|f| m.scaled_levels(f)).to_vec()
}
