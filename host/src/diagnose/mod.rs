//! `fricsim diagnose`: where simulation and measurement disagree, which
//! physical effect is missing, the model with it added and refitted, and
//! the error on data the fit did not see.
//!
//! The workflow (README "Diagnosing a model against measurements"):
//! 1. co-simulate the nominal system with the measured inputs and compare
//!    it with the measured channels ([`sim::co_simulate`]); estimate the
//!    friction force the data imply ([`problem`]);
//! 2. refit the nominal friction parameters ([`fit`]) and take the
//!    refitted nominal model as the baseline;
//! 3. for every effect of the library ([`model::Effect`]) the model lacks:
//!    add it, refit its parameters together with the nominal ones, and
//!    co-simulate the whole system on the held-out data;
//! 4. accept the candidate with the lowest held-out error only if it beats
//!    the current model significantly: a one-sided paired t-test on the
//!    held-out squared residuals in [`Options::groups`] consecutive groups,
//!    at level α divided by the number of candidates tried in the round
//!    (Bonferroni), and by at least [`Options::min_gain`] of the mean
//!    square. Extra parameters that only fit noise do not carry over to
//!    held-out data, so they are not rewarded;
//! 5. repeat from 3 while a candidate is accepted;
//! 6. call the remaining discrepancy "unexplained" when its held-out RMS
//!    is more than twice the measurement-noise floor estimated from the
//!    data, and say where it lies ([`localise`]).

pub mod fit;
pub mod localise;
pub mod model;
pub mod problem;
pub mod report;
pub mod sim;
pub mod suite;
pub mod synthetic;

use model::{Effect, FrictionModel};
use problem::{FrictionData, Measured, Setup};
use rayon::prelude::*;
use serde::Serialize;
use sim::{co_simulate, system_parameters, ChannelResiduals, FrictionSim};
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
    /// Groups of consecutive held-out samples in the paired test.
    pub groups: usize,
    /// At most this many effects.
    pub max_effects: usize,
    /// Refine each accepted model on the output error of the training
    /// data ([`fit::polish`], [`POLISH_ITERATIONS`]).
    pub polish: bool,
    /// Equal time blocks the data are cut into when no held-out file is
    /// given; every third, from the second on, is held out.
    pub blocks: usize,
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
        }
    }
}

/// Held-out blocks when no separate held-out file is given: the data are
/// cut into [`Options::blocks`] equal time blocks (default
/// [`SPLIT_BLOCKS`]), and every third block, from the second on, is held
/// out (a third of the data, spread over the whole experiment).
pub const SPLIT_BLOCKS: usize = 30;

/// Levenberg–Marquardt iterations (one Jacobian each) of the output-error
/// refinement of an accepted model ([`fit::polish`]).
pub const POLISH_ITERATIONS: usize = 3;

/// Whether time block `b` is held out.
pub fn held_out_block(b: usize) -> bool {
    b % 3 == 1
}

/// A file's time span cut into equal blocks (at least 3), every third held
/// out ([`held_out_block`]).
#[derive(Clone, Copy, Debug)]
pub struct Blocks {
    t0: f64,
    t1: f64,
    pub count: usize,
}

impl Blocks {
    pub fn new(time: &[f64], count: usize) -> Blocks {
        Blocks {
            t0: time.first().copied().unwrap_or(0.0),
            t1: time.last().copied().unwrap_or(0.0),
            count: count.max(3),
        }
    }

    /// Whether the block holding time `t` is held out.
    pub fn held_out(&self, t: f64) -> bool {
        let b = ((t - self.t0) / (self.t1 - self.t0) * self.count as f64) as usize;
        held_out_block(b.min(self.count - 1))
    }

    /// The positions of a co-simulation's samples (of the file with
    /// `time`) that are held out (`held`) or used for training.
    fn picker<'a>(self, time: &[f64], held: bool) -> Picker<'a> {
        let time = time.to_vec();
        Box::new(move |r: &ChannelResiduals| {
            (0..r.samples.len())
                .filter(|&s| self.held_out(time[r.samples[s]]) == held)
                .collect()
        })
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
    /// RMS of the law's force against the force the data imply (N), training.
    pub force_rms: f64,
    pub fit_evaluations: usize,
    /// Why its co-simulation failed (then it is rejected).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
}

/// An accepted effect.
#[derive(Clone, Debug, Serialize)]
pub struct FoundEffect {
    pub name: Effect,
    pub meaning: &'static str,
    /// Its parameters after the refit: name → value.
    pub parameters: serde_json::Map<String, serde_json::Value>,
    pub rms_before: f64,
    pub rms_after: f64,
    pub p_value: f64,
    /// p must be below this (α over the candidates of the round).
    pub threshold: f64,
    /// Where the improvement is concentrated.
    #[serde(rename = "where")]
    pub where_: localise::Where,
}

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
    /// Held-out RMS of the nominal model with its parameters refitted.
    pub baseline_rms: f64,
    /// Held-out RMS of the final model.
    pub final_rms: f64,
    pub effects: Vec<FoundEffect>,
    /// Every candidate tried, per round.
    pub rounds: Vec<Vec<CandidateScore>>,
    pub unexplained: bool,
    /// Held-out RMS of the measurement noise estimated from the data
    /// (normalised like the others).
    pub noise_floor_rms: f64,
    /// Where the remaining discrepancy lies (the localisation of the final
    /// residual).
    pub residual_pattern: localise::Localisation,
    /// Localisation of the baseline's residual.
    pub baseline_pattern: localise::Localisation,
    pub nominal_model: FrictionModel,
    pub baseline_model: FrictionModel,
    pub final_model: FrictionModel,
    pub samples: usize,
    pub heldout_samples: usize,
    /// Family-wise significance level.
    pub alpha: f64,
    pub wall_seconds: f64,
    /// Of which the output-error refinement of accepted models took this
    /// long, in this many co-simulations.
    pub polish_seconds: f64,
    pub polish_cosimulations: usize,
    pub step: f64,
    pub master: String,
    #[serde(skip)]
    pub plots: PlotData,
}

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
type Picker<'a> = Box<dyn Fn(&ChannelResiduals) -> Vec<usize> + Sync + 'a>;

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
    pub residual_before: Vec<f64>,
    pub residual_after: Vec<f64>,
}

/// The held-out part: residual samples and friction intervals.
struct HeldOut<'a> {
    data: &'a Measured,
    friction: &'a FrictionData,
    /// Positions (into `ChannelResiduals::samples`) that are held out.
    samples: Picker<'a>,
    /// Intervals of `friction` that are held out.
    intervals: Vec<usize>,
}

/// Run the workflow on `system` with the measurements `data` (and a
/// separate held-out file, else the held-out blocks of `data`).
pub fn diagnose(
    file: &SystemFile,
    data_path: &Path,
    heldout_path: Option<&Path>,
    options: &Options,
) -> Result<Diagnosis, String> {
    let started = Instant::now();
    let mut system = file.build(0.0).map_err(|e| e.to_string())?;
    let train = Measured::read(data_path, &system)?;
    let heldout_file = match heldout_path {
        Some(p) => {
            let h = Measured::read(p, &system)?;
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
        None => None,
    };
    let step = match file.settings.step_size {
        Some(h) => h,
        None => problem::median_spacing(&train.time),
    };
    let master = file.settings.master_or_default();
    let setup = Setup::new(file, &mut system, step, &master)?;
    let d_train = setup.friction_data(&system, &train, options.smooth)?;
    let d_held = match &heldout_file {
        Some(h) => Some(setup.friction_data(&system, h, options.smooth)?),
        None => None,
    };

    // which samples and intervals train and which are held out
    let blocks = Blocks::new(&train.time, options.blocks);
    let split = heldout_file.is_none();
    let train_intervals: Vec<usize> = (0..d_train.t.len())
        .filter(|&j| d_train.trusted[j] && (!split || !blocks.held_out(d_train.t[j])))
        .collect();
    let held = match (&heldout_file, &d_held) {
        (Some(h), Some(dh)) => HeldOut {
            data: h,
            friction: dh,
            samples: Box::new(|r: &ChannelResiduals| (0..r.samples.len()).collect()),
            intervals: (0..dh.t.len()).filter(|&j| dh.trusted[j]).collect(),
        },
        _ => HeldOut {
            data: &train,
            friction: &d_train,
            samples: blocks.picker(&train.time, true),
            intervals: (0..d_train.t.len())
                .filter(|&j| d_train.trusted[j] && blocks.held_out(d_train.t[j]))
                .collect(),
        },
    };
    if train_intervals.len() < problem::MIN_SAMPLES / 2 || held.intervals.len() < options.groups {
        return Err(format!(
            "{}: too few samples to fit ({}) and hold out ({})",
            train.label,
            train_intervals.len(),
            held.intervals.len()
        ));
    }

    // channel scales: the standard deviation of each measured channel
    let scales: Vec<f64> = train
        .outputs
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
        .collect();

    let context = setup.context(&d_train, options.position_knots);
    let score =
        |system: &mut crate::system::System, model: &FrictionModel| -> Result<Scored, String> {
            let params = system_parameters(file, &setup, model);
            let r = co_simulate(system, &params, &setup, held.data)?;
            if let Some(e) = &r.incomplete {
                return Err(format!("the co-simulation stopped early: {e}"));
            }
            let picked = (held.samples)(&r);
            let q_all = r.squared(&scales);
            let q: Vec<f64> = picked.iter().map(|&s| q_all[s]).collect();
            Ok(Scored {
                residuals: r,
                picked,
                q,
            })
        };

    // the output error on the training samples, for [`fit::polish`]
    let train_samples: Picker = match &heldout_file {
        Some(_) => Box::new(|r: &ChannelResiduals| (0..r.samples.len()).collect()),
        None => blocks.picker(&train.time, false),
    };
    let polish = |model: &FrictionModel| -> fit::Fitted {
        let train_residuals = |m: &FrictionModel| -> Option<nalgebra::DVector<f64>> {
            // a system of its own (an FMU instance stays on its thread)
            let mut system = file.build(0.0).ok()?;
            let params = system_parameters(file, &setup, m);
            let r = co_simulate(&mut system, &params, &setup, &train).ok()?;
            if r.incomplete.is_some() {
                return None;
            }
            let picked = train_samples(&r);
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
        let mut residual = |models: &[FrictionModel]| -> Vec<Option<nalgebra::DVector<f64>>> {
            models.par_iter().map(train_residuals).collect()
        };
        let budget = POLISH_ITERATIONS * (model.free().len() + 1) + 1;
        fit::polish(model, &mut residual, budget)
    };

    // nominal as given, then refitted
    let mut sim = FrictionSim::new(&setup.friction_fmu)?;
    let nominal_scored =
        score(&mut system, &setup.nominal).map_err(|e| format!("the nominal system: {e}"))?;
    let baseline_fit = fit::fit(
        std::slice::from_ref(&setup.nominal),
        &mut sim,
        &d_train,
        &train_intervals,
    );
    let baseline_model = baseline_fit.model.clone();
    let baseline_scored = score(&mut system, &baseline_model)
        .map_err(|e| format!("the refitted nominal system: {e}"))?;

    let mut current = baseline_model.clone();
    let mut current_scored = baseline_scored.clone();
    let mut effects = Vec::new();
    let mut rounds = Vec::new();
    let (mut polish_seconds, mut polish_runs) = (0.0, 0);
    // one round: fit and score each addition (one effect, or two at once)
    let try_round =
        |current: &FrictionModel, additions: &[Vec<Effect>]| -> Result<Vec<Tried>, String> {
            additions
                .par_iter()
                .map(|added| {
                    let mut sim = FrictionSim::new(&setup.friction_fmu)?;
                    let (last, first) = added.split_last().expect("an addition has an effect");
                    let mut base = current.clone();
                    for &e in first {
                        base = base.with(e, &context);
                    }
                    let starts = starts(&base, *last, &context);
                    let fitted = fit::fit(&starts, &mut sim, &d_train, &train_intervals);
                    let mut system = file.build(0.0).map_err(|e| e.to_string())?;
                    // a candidate whose co-simulation fails is rejected, not fatal
                    let scored = score(&mut system, &fitted.model);
                    Ok(Tried {
                        added: added.clone(),
                        model: fitted.model.clone(),
                        force_rms: fitted.rms,
                        evaluations: fitted.evaluations,
                        scored,
                    })
                })
                .collect()
        };
    while effects.len() < options.max_effects {
        let missing: Vec<Effect> = options
            .candidates
            .iter()
            .copied()
            .filter(|&e| !current.has(e))
            .filter(|&e| e != Effect::NormalLoad || d_train.normal_force_measured)
            .filter(|&e| e != Effect::PositionDependent || context.travel > 1e-9)
            .collect();
        if missing.is_empty() {
            break;
        }
        // single effects first; when none is accepted, pairs (an effect
        // may show only together with another: levels that depend on
        // position differently in each direction)
        let singles: Vec<Vec<Effect>> = missing.iter().map(|&e| vec![e]).collect();
        let mut pairs = Vec::new();
        if effects.len() + 2 <= options.max_effects {
            for (i, &a) in missing.iter().enumerate() {
                for &b in &missing[i + 1..] {
                    pairs.push(vec![a, b]);
                }
            }
        }
        let mut accepted = None;
        let mut singles_tried = Vec::new();
        for additions in [singles, pairs] {
            if additions.is_empty() {
                continue;
            }
            let tried = try_round(&current, &additions)?;
            let threshold = options.alpha / additions.len() as f64;
            let mut round = Vec::new();
            for t in &tried {
                let (heldout_rms, gain, p_value, failure) = match &t.scored {
                    Ok(scored) => {
                        let (gain, p) = paired_test(&current_scored.q, &scored.q, options.groups);
                        (mean(&scored.q).sqrt(), gain, p, None)
                    }
                    Err(e) => (f64::INFINITY, f64::NEG_INFINITY, 1.0, Some(e.clone())),
                };
                round.push(CandidateScore {
                    name: label(&t.added),
                    heldout_rms,
                    gain,
                    p_value,
                    force_rms: t.force_rms,
                    fit_evaluations: t.evaluations,
                    failure,
                });
            }
            let best = (0..round.len())
                .min_by(|&i, &j| round[i].heldout_rms.total_cmp(&round[j].heldout_rms));
            rounds.push(round.clone());
            if let Some(k) =
                best.filter(|&k| round[k].p_value < threshold && round[k].gain >= options.min_gain)
            {
                accepted = Some((tried, k, round[k].p_value, threshold));
                break;
            }
            singles_tried = tried;
        }
        let Some((mut tried, k, p_value, threshold)) = accepted else {
            break;
        };
        let t = tried.swap_remove(k);
        let (mut model, mut scored) = match t.scored {
            Ok(s) => (t.model, s),
            Err(e) => return Err(format!("accepted {} without a score: {e}", label(&t.added))),
        };
        // refine the accepted model on the output error of the training data
        let polish_started = Instant::now();
        let polished = if options.polish {
            polish(&model)
        } else {
            fit::Fitted {
                model: model.clone(),
                rms: f64::NAN,
                evaluations: 0,
            }
        };
        polish_seconds += polish_started.elapsed().as_secs_f64();
        polish_runs += polished.evaluations;
        if polished.evaluations > 0 && polished.model != model {
            // kept unrefined if the refined model's co-simulation fails
            if let Ok(s) = score(&mut system, &polished.model) {
                model = polished.model;
                scored = s;
            }
        }
        // the intermediate model of a pair: its first effect alone, as fitted in the singles round
        let mut steps: Vec<(Effect, FrictionModel, Scored)> = Vec::new();
        if t.added.len() == 2 {
            if let Some(single) = singles_tried.iter().find(|s| s.added == [t.added[0]]) {
                if let Ok(single_scored) = &single.scored {
                    steps.push((t.added[0], single.model.clone(), single_scored.clone()));
                }
            }
        }
        steps.push((*t.added.last().expect("an effect"), model, scored));
        for (effect, model, scored) in steps {
            let where_ = localise::where_improved(
                held.friction,
                &held.intervals,
                &run_force(&mut sim, &current, held.friction)?,
                &run_force(&mut sim, &model, held.friction)?,
            );
            effects.push(FoundEffect {
                name: effect,
                meaning: effect.meaning(),
                parameters: effect_parameters(&model, effect),
                rms_before: mean(&current_scored.q).sqrt(),
                rms_after: mean(&scored.q).sqrt(),
                p_value,
                threshold,
                where_,
            });
            current = model;
            current_scored = scored;
        }
    }

    // the remaining discrepancy against the noise floor
    let noise = noise_floor(held.data, &current_scored, &scales);
    let final_rms = mean(&current_scored.q).sqrt();
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
            None => format!(
                "every third of {} equal time blocks of {} (blocks 2, 5, 8, ...)",
                blocks.count, train.label
            ),
        },
        force_source: d_train.source.clone(),
        friction_component: setup.friction_name.clone(),
        channels,
        nominal_rms: mean(&nominal_scored.q).sqrt(),
        baseline_rms: mean(&baseline_scored.q).sqrt(),
        final_rms,
        unexplained: final_rms > 2.0 * noise,
        noise_floor_rms: noise,
        residual_pattern,
        baseline_pattern,
        effects,
        rounds,
        nominal_model: setup.nominal.clone(),
        baseline_model,
        final_model: current,
        samples: train.time.len(),
        heldout_samples: current_scored.q.len(),
        alpha: options.alpha,
        wall_seconds: started.elapsed().as_secs_f64(),
        polish_seconds,
        polish_cosimulations: polish_runs,
        step,
        master,
        plots,
    })
}

/// One addition fitted and scored.
struct Tried {
    added: Vec<Effect>,
    model: FrictionModel,
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
struct Scored {
    residuals: ChannelResiduals,
    /// Held-out positions into `residuals.samples`.
    picked: Vec<usize>,
    /// Normalised squared residual per held-out sample.
    q: Vec<f64>,
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
            let mut s = Vec::new();
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
        Effect::Presliding => [1e-4, 1e-3, 1e-2, 3e-2]
            .iter()
            .map(|&d| {
                let mut m = base.clone();
                m.sigma0 = m.fc / (d * context.travel);
                m
            })
            .collect(),
        Effect::Viscous => [0.01, 0.1]
            .iter()
            .map(|&r| {
                let mut m = base.clone();
                m.sigma2 = r * m.fc / context.speed_scale;
                m
            })
            .collect(),
        _ => vec![base],
    }
}

/// One-sided paired test that `after` has a lower mean than `before`:
/// the differences are averaged over `groups` consecutive groups (so that
/// correlated neighbours count once), then Student's t with groups − 1
/// degrees of freedom. Returns (relative drop of the mean, p-value).
pub fn paired_test(before: &[f64], after: &[f64], groups: usize) -> (f64, f64) {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    let n = before.len().min(after.len());
    let g = groups.clamp(2, n.max(2));
    let mut d = Vec::with_capacity(g);
    for k in 0..g {
        let (a, b) = (k * n / g, (k + 1) * n / g);
        if b > a {
            d.push((a..b).map(|i| before[i] - after[i]).sum::<f64>() / (b - a) as f64);
        }
    }
    let mb = mean(&before[..n]);
    let gain = if mb > 0.0 {
        (mb - mean(&after[..n])) / mb
    } else {
        0.0
    };
    let m = mean(&d);
    let sd = (d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (d.len() as f64 - 1.0)).sqrt();
    if sd.is_nan() || sd <= 0.0 {
        return (gain, if m > 0.0 { 0.0 } else { 1.0 });
    }
    let t = m / (sd / (d.len() as f64).sqrt());
    let p = match StudentsT::new(0.0, 1.0, d.len() as f64 - 1.0) {
        Ok(dist) => 1.0 - dist.cdf(t),
        Err(_) => 1.0,
    };
    (gain, p)
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
        q += (sigma / scales[c]).powi(2);
    }
    (q / scales.len().max(1) as f64).sqrt()
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
    PlotData {
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
