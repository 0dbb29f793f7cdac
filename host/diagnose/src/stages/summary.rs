//! Stage 8, the report's figures: the 95 % intervals of the final
//! model's fitted parameters and of each effect's change
//! ([`crate::intervals`]), the remaining error against the floor no model
//! can go below (measurement noise and the co-simulation's step error),
//! where the baseline's and the final residual lie ([`localise`]), the
//! per-channel errors, the series of the plots, and the [`Diagnosis`]
//! that holds them all.
//!
//! Takes the [`Problem`], the [`Baseline`], the [`Search`] and the
//! refinements' account; gives the [`Diagnosis`].

use super::baseline::Baseline;
use super::problem::Problem;
use super::refine::Polishing;
use super::rounds::Search;
use super::run_force;
use crate::acceptance::Scored;
use crate::intervals::ThetaCovariance;
use crate::memory::{moved, LawCheck};
use crate::model::FrictionModel;
use crate::problem::{FrictionData, Measured};
use crate::sim::FrictionSim;
use crate::{
    fmu_values, localise, quality, ChannelSummary, DataQuality, Diagnosis, EffectChange, FmuValue,
    FoundEffect, InputColumns, PlotData, UNEXPLAINED_FACTOR,
};
use std::time::Instant;

/// Assemble the diagnosis; `started`: when it began (for its wall time).
pub(crate) fn summarise(
    p: &Problem,
    sim: &mut FrictionSim,
    baseline: Baseline,
    (search, memory): (Search, Vec<LawCheck>),
    polishing: Polishing,
    started: Instant,
) -> Result<Diagnosis, String> {
    let Search {
        current,
        scored: current_scored,
        step_error,
        mut effects,
        withdrawn,
        rounds,
        round_thresholds,
        notes,
        ..
    } = search;
    // the intervals: output-error co-simulations, skipped past the time
    // limit and dropped when it cut them short
    let covariance = if p.budget.skip_if_expired(|| "the 95 % intervals".into()) {
        None
    } else {
        p.budget.progress().stage("the 95 % intervals");
        match p
            .budget
            .cut_short(|| "the 95 % intervals".into(), || covariance(p, &current))
        {
            (c, false) => c,
            (_, true) => None,
        }
    };
    if let Some(cov) = &covariance {
        effect_changes(cov, &p.setup.nominal, &current, &mut effects);
    }

    // the remaining discrepancy against what no model can go below: the
    // measurement noise (and quantisation) and the co-simulation's own
    // step error
    let noise = noise_floor(p.scored_data(), &current_scored, &p.scales);
    let numerical = step_error;
    let floor = (noise * noise + numerical * numerical).sqrt();
    let final_rms = current_scored.rms();
    let mut fallbacks: Vec<String> = Vec::new();
    for (what, scored) in [
        ("the nominal as given", &baseline.nominal_scored),
        ("the final model", &current_scored),
    ] {
        if let Some(note) = &scored.fallback {
            fallbacks.push(format!("{what}: {note}"));
        }
    }
    let friction = p.scored_friction();
    let intervals = &p.split.scored_intervals;
    let before_f = run_force(sim, &baseline.model, friction)?;
    let after_f = run_force(sim, &current, friction)?;
    let residual_pattern = localise::localise(friction, intervals, &after_f);
    let baseline_pattern = localise::localise(friction, intervals, &before_f);

    let channels = p
        .data
        .outputs
        .iter()
        .enumerate()
        .map(|(c, (name, _))| ChannelSummary {
            name: name.clone(),
            scale: p.scales[c],
            nominal_rms: channel_rms(&baseline.nominal_scored, c),
            baseline_rms: channel_rms(&baseline.scored, c),
            final_rms: channel_rms(&current_scored, c),
        })
        .collect();
    let plots = plot_data(
        p,
        &baseline.nominal_scored,
        &current_scored,
        &before_f,
        &after_f,
    );
    Ok(Diagnosis {
        system: p.file.ssd.clone(),
        data: p.data.label.clone(),
        heldout: p.split.describe(
            &p.data,
            p.heldout_records.as_ref().map(|h| h.label.as_str()),
        ),
        force_source: p.force.data.source.clone(),
        friction_component: p.setup.friction_name.clone(),
        channels,
        nominal_rms: baseline.nominal_scored.rms(),
        baseline_rms: baseline.scored.rms(),
        refit: baseline.refit,
        final_rms,
        // the nominal moved to another law: what that law leaves
        unexplained: moved(&memory).map_or(final_rms, |m| m.heldout_rms)
            > UNEXPLAINED_FACTOR * floor,
        noise_floor_rms: noise,
        step_error_rms: numerical,
        floor_rms: floor,
        data_quality: DataQuality {
            data: p.data.quality.clone(),
            heldout: p.heldout_records.as_ref().map(|h| h.quality.clone()),
        },
        fallbacks,
        notes,
        residual_pattern,
        baseline_pattern,
        effects,
        withdrawn,
        rounds,
        round_thresholds,
        changes: changes(p, &current, covariance.as_ref()),
        memory,
        nominal_model: p.setup.nominal.clone(),
        baseline_model: baseline.model,
        final_model: current,
        samples: p.data.time.len(),
        heldout_samples: current_scored.q.len(),
        alpha: p.options.alpha,
        groups: p.options.groups,
        min_gain: p.options.min_gain,
        folds: p.split.folds.len(),
        wall_seconds: started.elapsed().as_secs_f64(),
        time_limit: p.budget.time_limit(),
        cosimulations: p.budget.cosimulations(),
        polish_seconds: polishing.seconds,
        polish_cosimulations: polishing.cosimulations,
        output_jacobian: p.output_jacobian_words(),
        step: p.setup.step,
        master: p.setup.master.clone(),
        plots,
        measured_inputs: record_inputs(&p.data),
        heldout_inputs: p
            .heldout_records
            .as_ref()
            .map(record_inputs)
            .unwrap_or_default(),
        rerun: Vec::new(),
    })
}

/// The covariance of the final model's fitted parameters, from the output
/// error of the fit samples it was refined on
/// ([`Problem::covariance_on`]): the one fold's, or every sample's.
fn covariance(p: &Problem, current: &FrictionModel) -> Option<ThetaCovariance> {
    let samples = if p.split.folds.len() == 1 {
        &p.split.folds[0].fits
    } else {
        &p.every_sample
    };
    p.covariance_on(current, samples)
}

/// Each effect's change from `nominal` in `current` ([`EffectChange`]),
/// with its interval from `cov`.
fn effect_changes(
    cov: &ThetaCovariance,
    nominal: &FrictionModel,
    current: &FrictionModel,
    effects: &mut [FoundEffect],
) {
    for e in effects {
        e.change = e.name.change(nominal, current).map(|value| {
            let interval = cov.interval(current, &|m: &FrictionModel| e.name.change(nominal, m));
            EffectChange {
                quantity: e.name.change_name().unwrap_or(""),
                value,
                interval,
                resolved: interval.map(|[low, high]| !(low <= 0.0 && 0.0 <= high)),
            }
        });
    }
}

/// Every LuGre FMU parameter `current` sets differently from the nominal
/// as given, with its interval from `cov`.
fn changes(p: &Problem, current: &FrictionModel, cov: Option<&ThetaCovariance>) -> Vec<FmuValue> {
    let names: Vec<String> = current.parameters().into_iter().map(|(n, _)| n).collect();
    let mut changes: Vec<FmuValue> =
        fmu_values(&p.setup.friction_fmu, &names, &p.setup.nominal, current)
            .into_iter()
            .filter(|v| v.before != v.after)
            .collect();
    if let Some(cov) = cov {
        for v in &mut changes {
            v.interval = cov.parameter_interval(current, &v.name);
        }
    }
    changes
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

/// The held-out RMS of channel `c` (in its unit).
fn channel_rms(s: &Scored, c: usize) -> f64 {
    (s.picked
        .iter()
        .map(|&k| s.residuals.residuals[c][k].powi(2))
        .sum::<f64>()
        / s.picked.len().max(1) as f64)
        .sqrt()
}

/// The normalised RMS of the measurement noise, from the second
/// differences of each measured channel (white noise of σ gives
/// differences of σ·√6; the median absolute value / 0.6745 is robust to
/// the signal's own curvature and to outliers).
pub(crate) fn noise_floor(data: &Measured, scored: &Scored, scales: &[f64]) -> f64 {
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

/// The series of the plots: the measured channels, the nominal's and the
/// final model's at the held-out samples, and the friction residual of the
/// baseline (`before_f`) and the final model (`after_f`) with the states
/// at the held-out intervals.
fn plot_data(
    p: &Problem,
    nominal: &Scored,
    last: &Scored,
    before_f: &[f64],
    after_f: &[f64],
) -> PlotData {
    let data = p.scored_data();
    let time: Vec<f64> = last
        .picked
        .iter()
        .map(|&s| data.time[last.residuals.samples[s]])
        .collect();
    let channels = data
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
    let d: &FrictionData = p.scored_friction();
    let intervals = &p.split.scored_intervals;
    let since = localise::time_since_reversal(d);
    let moved = localise::displacement_since_reversal(d);
    PlotData {
        displacement: intervals.iter().map(|&j| moved[j]).collect(),
        force: intervals.iter().map(|&j| d.f[j]).collect(),
        time,
        channels,
        v: intervals.iter().map(|&j| d.v[j]).collect(),
        x: intervals.iter().map(|&j| d.x[j]).collect(),
        since_reversal: intervals.iter().map(|&j| since[j]).collect(),
        fn_: d
            .normal_force_measured
            .then(|| intervals.iter().map(|&j| d.fn_[j]).collect()),
        residual_before: intervals.iter().map(|&j| d.f[j] - before_f[j]).collect(),
        residual_after: intervals.iter().map(|&j| d.f[j] - after_f[j]).collect(),
    }
}
