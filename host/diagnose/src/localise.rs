//! Where a discrepancy lies: the friction residual (force the data imply
//! minus force the law gives, along the measured states) split by the
//! states a friction effect depends on: velocity band, direction of
//! motion, position along the travel, time since the last reversal and
//! normal load.
//!
//! Which state an accepted effect depends on ([`attribute`]): the change
//! the effect makes to the steady sliding force, averaged within the bins
//! of one state; the share of the change those bin means keep is that
//! state's share. A direction dependence keeps all of it when averaged per
//! direction and about half when averaged per speed band or position.

use super::model::FrictionModel;
use super::problem::FrictionData;
use serde::Serialize;

/// One bin of one localising state.
#[derive(Clone, Debug, Serialize)]
pub struct Bin {
    /// `velocity`, `direction`, `position`, `time_since_reversal`, `normal_load`.
    pub state: &'static str,
    /// The bin in words, with its bounds.
    pub bin: String,
    /// Share of the samples in the bin.
    pub share: f64,
    /// Mean residual (N): a systematic offset in the bin.
    pub mean: f64,
    /// RMS residual (N).
    pub rms: f64,
}

/// The residual broken down by every localising state.
#[derive(Clone, Debug, Serialize, Default)]
pub struct Localisation {
    pub bins: Vec<Bin>,
    /// The bin whose mean square most exceeds the overall one (≥ 5 % of
    /// the samples), in words.
    pub strongest: String,
}

/// Where an effect's improvement concentrates.
#[derive(Clone, Debug, Serialize)]
pub struct Where {
    pub state: &'static str,
    pub bin: String,
    /// Share of the improvement of the squared residual in the bin.
    pub share_of_improvement: f64,
    /// Share of the samples in the bin.
    pub share_of_samples: f64,
    /// The same for every bin.
    pub bins: Vec<(String, String, f64, f64)>,
    /// Which state the effect's change depends on, best first
    /// ([`attribute`]); `state`/`bin` above are the strongest bin of the
    /// first of these.
    pub explained_by: Vec<Attribution>,
    /// The time spans (s) where the effect earns its improvement: of 100
    /// runs of consecutive held-out intervals, those whose share of the
    /// improvement is at least twice their share of the samples, joined
    /// where they touch.
    pub intervals: Vec<(f64, f64)>,
}

/// Runs of consecutive `intervals` (at most [`EARNING_RUNS`], of equal
/// count) whose share of the total of `gain` is at least twice their share
/// of the intervals, as time spans, joined where they touch.
fn earning_spans(
    d: &FrictionData,
    intervals: &[usize],
    gain: &dyn Fn(usize) -> f64,
) -> Vec<(f64, f64)> {
    let total: f64 = intervals.iter().map(|&j| gain(j)).sum();
    let n = intervals.len();
    if n == 0 || total.is_nan() || total <= 0.0 {
        return Vec::new();
    }
    let runs = EARNING_RUNS.min(n);
    let mut spans: Vec<(f64, f64)> = Vec::new();
    for r in 0..runs {
        let run = &intervals[r * n / runs..(r + 1) * n / runs];
        let share = run.iter().map(|&j| gain(j)).sum::<f64>() / total;
        if share < 2.0 * run.len() as f64 / n as f64 {
            continue;
        }
        let (first, last) = (run[0], run[run.len() - 1]);
        let (t0, t1) = (d.t[first], d.t[last] + d.h[last]);
        match spans.last_mut() {
            Some(prev) if t0 <= prev.1 + 1.5 * d.h[first] => prev.1 = t1,
            _ => spans.push((t0, t1)),
        }
    }
    spans
}

/// Runs the held-out data are cut into by [`earning_spans`].
const EARNING_RUNS: usize = 100;

/// How much of an effect's improvement each state explains.
#[derive(Clone, Debug, Serialize)]
pub struct Attribution {
    /// `velocity` (its magnitude), `direction`, `position`,
    /// `displacement_since_reversal`, `normal_load`.
    pub state: &'static str,
    /// Share of the variation of the effect's change over the held-out
    /// data that the bin means of this state explain: 1 when the change
    /// depends on this state alone.
    pub share: f64,
}

/// Bins per continuous state in [`attribute`].
const ATTRIBUTION_BINS: usize = 20;

/// Metres moved since the motion last reversed, per interval (the
/// pre-sliding displacement the bristles see). A reversal is
/// where the position turns back from its furthest point by more than a
/// deadband (3 times the position resolution the data show, at least 1e-4
/// of the travel), not where the estimated velocity changes sign: while the
/// contact creeps, that sign flips with the noise and would restart the
/// count at random.
pub fn displacement_since_reversal(d: &FrictionData) -> Vec<f64> {
    let (lo, hi) =
        d.x.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
    let travel = if hi > lo { hi - lo } else { 0.0 };
    let deadband = (3.0 * d.position_resolution.unwrap_or(0.0))
        .max(1e-4 * travel)
        .max(f64::MIN_POSITIVE);
    let mut out = Vec::with_capacity(d.x.len());
    let mut origin = d.x.first().copied().unwrap_or(0.0);
    let (mut furthest, mut direction) = (origin, 0.0);
    for &x in &d.x {
        if direction == 0.0 {
            if (x - origin).abs() > deadband {
                direction = (x - origin).signum();
                furthest = x;
            }
        } else if (x - furthest) * direction > 0.0 {
            furthest = x;
        } else if (furthest - x) * direction > deadband {
            // turned back: the furthest point is the reversal
            origin = furthest;
            furthest = x;
            direction = -direction;
        }
        out.push((x - origin).abs());
    }
    out
}

/// Bin index of each of `values` among `bins` quantile bins (ties share a bin).
fn quantile_bins(values: &[f64], bins: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut out = vec![0; values.len()];
    let n = values.len().max(1);
    for (rank, &i) in order.iter().enumerate() {
        out[i] = rank * bins / n;
    }
    // equal values in one bin: the bin of the first of them
    for w in 1..order.len() {
        if values[order[w]] == values[order[w - 1]] {
            out[order[w]] = out[order[w - 1]];
        }
    }
    out
}

/// Bin index of each of `values` (≥ 0) among `bins` bins whose edges grow
/// geometrically from a ten-thousandth of the largest value to it (smaller
/// values in the first): what happens at small speeds and just after a
/// reversal, where the friction transitions live, gets bins of its own
/// instead of sharing one with a decade of larger values.
fn log_bins(values: &[f64], bins: usize) -> Vec<usize> {
    let hi = values.iter().copied().fold(0.0, f64::max);
    if hi.is_nan() || hi <= 0.0 {
        return vec![0; values.len()];
    }
    let lo = hi * 1e-4;
    let per_bin = (hi / lo).ln() / bins as f64;
    values
        .iter()
        .map(|&x| {
            if x > lo {
                (((x / lo).ln() / per_bin) as usize).min(bins - 1)
            } else {
                0
            }
        })
        .collect()
}

/// Bin index of each of `values` among `bins` equal bins over their range.
fn equal_bins(values: &[f64], bins: usize) -> Vec<usize> {
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    values
        .iter()
        .map(|&x| {
            if hi > lo {
                (((x - lo) / (hi - lo) * bins as f64) as usize).min(bins - 1)
            } else {
                0
            }
        })
        .collect()
}

/// Which state an effect's change depends on, best first. The change is
/// the model's steady sliding force (`sliding_level`, [`FrictionModel`]:
/// levels, Stribeck curve, viscous term) from `before` to `after` at each
/// held-out interval; each state's bins explain the share
/// 1 − Σ(change − its bin's mean)² / Σ(change − mean)² of its variation
/// (1: the change is a function of that state alone; a change that is the
/// same everywhere depends on none). When an effect leaves the steady
/// force nearly the same along the data (its spread under a tenth of the
/// spread of the law's force change along the data, `before_f` to
/// `after_f`: presliding, which changes only the transition after a
/// reversal), the law's force change itself, `(after_f − before_f)·sign(v)`,
/// is binned instead. Only the intervals
/// where the contact slides count (the held-out `intervals` are those).
pub fn attribute(
    d: &FrictionData,
    intervals: &[usize],
    (before, before_f): (&FrictionModel, &[f64]),
    (after, after_f): (&FrictionModel, &[f64]),
) -> Vec<Attribution> {
    let sign = |j: usize| if d.v[j] < 0.0 { -1.0 } else { 1.0 };
    let steady: Vec<f64> = intervals
        .iter()
        .map(|&j| {
            after.sliding_level(d.v[j], d.x[j], d.fn_[j])
                - before.sliding_level(d.v[j], d.x[j], d.fn_[j])
        })
        .collect();
    let dynamic: Vec<f64> = intervals
        .iter()
        .map(|&j| (after_f[j] - before_f[j]) * sign(j))
        .collect();
    // the spread about the mean: a change that is the same everywhere
    // (a level moved alone) depends on no state
    let spread = |c: &[f64]| {
        let m = c.iter().sum::<f64>() / c.len().max(1) as f64;
        c.iter().map(|x| (x - m).powi(2)).sum::<f64>()
    };
    let change = if spread(&steady) >= 0.01 * spread(&dynamic) {
        steady
    } else {
        dynamic
    };
    let total = spread(&change);
    let square: f64 = change.iter().map(|x| x * x).sum();
    // (a spread at the rounding level of the change is none)
    if total.is_nan() || total <= 1e-12 * square {
        return Vec::new();
    }
    let pick = |f: &dyn Fn(usize) -> f64| -> Vec<f64> { intervals.iter().map(|&j| f(j)).collect() };
    let since = displacement_since_reversal(d);
    let mut states: Vec<(&'static str, Vec<usize>)> = vec![
        (
            "velocity",
            log_bins(&pick(&|j| d.v[j].abs()), ATTRIBUTION_BINS),
        ),
        (
            "direction",
            intervals
                .iter()
                .map(|&j| usize::from(d.v[j] < 0.0))
                .collect(),
        ),
        ("position", equal_bins(&pick(&|j| d.x[j]), ATTRIBUTION_BINS)),
        (
            "displacement_since_reversal",
            log_bins(&pick(&|j| since[j]), ATTRIBUTION_BINS),
        ),
    ];
    if d.normal_force_measured {
        states.push((
            "normal_load",
            quantile_bins(&pick(&|j| d.fn_[j]), ATTRIBUTION_BINS),
        ));
    }
    let mut out: Vec<Attribution> = states
        .into_iter()
        .map(|(state, bin)| {
            let bins = bin.iter().max().map_or(0, |b| b + 1);
            let (mut sum, mut count) = (vec![0.0; bins], vec![0usize; bins]);
            for (k, &b) in bin.iter().enumerate() {
                sum[b] += change[k];
                count[b] += 1;
            }
            let mean: Vec<f64> = (0..bins).map(|b| sum[b] / count[b].max(1) as f64).collect();
            let left: f64 = (0..change.len())
                .map(|k| (change[k] - mean[bin[k]]).powi(2))
                .sum();
            Attribution {
                state,
                share: 1.0 - left / total,
            }
        })
        .collect();
    out.sort_by(|a, b| b.share.total_cmp(&a.share));
    out
}

/// Seconds since the velocity last changed sign, per interval.
pub fn time_since_reversal(d: &FrictionData) -> Vec<f64> {
    let mut out = Vec::with_capacity(d.t.len());
    let mut last = d.t.first().copied().unwrap_or(0.0);
    let mut sign = 0.0;
    for j in 0..d.t.len() {
        let s = d.v[j].signum();
        if d.v[j] != 0.0 && s != sign {
            if sign != 0.0 {
                last = d.t[j];
            }
            sign = s;
        }
        out.push(d.t[j] - last);
    }
    out
}

/// The bins of every state over `intervals`: each (state, label, members).
fn bins(d: &FrictionData, intervals: &[usize]) -> Vec<(&'static str, String, Vec<usize>)> {
    let mut out = Vec::new();
    let v: Vec<f64> = intervals.iter().map(|&j| d.v[j]).collect();
    let v_rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
    // velocity bands relative to the RMS speed
    let (lo, mid) = (0.05 * v_rms, 0.5 * v_rms);
    let pick = |f: &dyn Fn(usize) -> bool| -> Vec<usize> {
        intervals.iter().copied().filter(|&j| f(j)).collect()
    };
    out.push((
        "velocity",
        format!("near zero (|v| < {lo:.3e} m/s)"),
        pick(&|j| d.v[j].abs() < lo),
    ));
    out.push((
        "velocity",
        format!("low ({lo:.3e} <= |v| < {mid:.3e} m/s)"),
        pick(&|j| d.v[j].abs() >= lo && d.v[j].abs() < mid),
    ));
    out.push((
        "velocity",
        format!("high (|v| >= {mid:.3e} m/s)"),
        pick(&|j| d.v[j].abs() >= mid),
    ));
    out.push((
        "direction",
        "positive (v > 0)".into(),
        pick(&|j| d.v[j] > lo),
    ));
    out.push((
        "direction",
        "negative (v < 0)".into(),
        pick(&|j| d.v[j] < -lo),
    ));
    // position: five equal bins over the travel
    let xs: Vec<f64> = intervals.iter().map(|&j| d.x[j]).collect();
    let (x0, x1) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    if x1 > x0 {
        for k in 0..5 {
            let (a, b) = (
                x0 + (x1 - x0) * k as f64 / 5.0,
                x0 + (x1 - x0) * (k + 1) as f64 / 5.0,
            );
            out.push((
                "position",
                format!("{a:.4} to {b:.4} m"),
                pick(&|j| d.x[j] >= a && (d.x[j] < b || (k == 4 && d.x[j] <= b))),
            ));
        }
    }
    // time and displacement since reversal, normal load: quartiles
    let since = time_since_reversal(d);
    out.extend(quartiles(
        "time_since_reversal",
        intervals,
        &since,
        &|a, b| format!("{a:.3} to {b:.3} s"),
    ));
    let moved = displacement_since_reversal(d);
    out.extend(quartiles(
        "displacement_since_reversal",
        intervals,
        &moved,
        &|a, b| format!("{a:.3e} to {b:.3e} m"),
    ));
    if d.normal_force_measured {
        out.extend(quartiles("normal_load", intervals, &d.fn_, &|a, b| {
            format!("{a:.4} to {b:.4} N")
        }));
    }
    out
}

/// The quartile bins of `values` (per interval) over `intervals`: each
/// (state, label from its bounds, members); empty bins left out.
fn quartiles(
    state: &'static str,
    intervals: &[usize],
    values: &[f64],
    label: &dyn Fn(f64, f64) -> String,
) -> Vec<(&'static str, String, Vec<usize>)> {
    let mut s: Vec<f64> = intervals.iter().map(|&j| values[j]).collect();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        return Vec::new();
    }
    let q = |p: f64| s[((s.len() - 1) as f64 * p) as usize];
    let edges = [q(0.0), q(0.25), q(0.5), q(0.75), q(1.0)];
    (0..4)
        .filter(|&k| edges[k + 1] > edges[k])
        .map(|k| {
            let (a, b) = (edges[k], edges[k + 1]);
            let members = intervals
                .iter()
                .copied()
                .filter(|&j| values[j] >= a && (values[j] < b || (k == 3 && values[j] <= b)))
                .collect();
            (state, label(a, b), members)
        })
        .collect()
}

/// The residual `d.f − model` over `intervals`, by state.
pub fn localise(d: &FrictionData, intervals: &[usize], model: &[f64]) -> Localisation {
    let n = intervals.len().max(1) as f64;
    let total_ms = intervals
        .iter()
        .map(|&j| (d.f[j] - model[j]).powi(2))
        .sum::<f64>()
        / n;
    let mut out = Localisation::default();
    let mut best = (0.0, String::new());
    for (state, label, members) in bins(d, intervals) {
        if members.is_empty() {
            continue;
        }
        let m = members.len() as f64;
        let r: Vec<f64> = members.iter().map(|&j| d.f[j] - model[j]).collect();
        let mean = r.iter().sum::<f64>() / m;
        let ms = r.iter().map(|x| x * x).sum::<f64>() / m;
        let share = m / n;
        if share >= 0.05 && total_ms > 0.0 && ms / total_ms > best.0 {
            best = (
                ms / total_ms,
                format!(
                    "{state} {label}: RMS {:.4} N, {:.1}x the overall mean square, mean {mean:+.4} N, {:.0} % of the samples",
                    ms.sqrt(),
                    ms / total_ms,
                    100.0 * share
                ),
            );
        }
        out.bins.push(Bin {
            state,
            bin: label,
            share,
            mean,
            rms: ms.sqrt(),
        });
    }
    out.strongest = best.1;
    out
}

/// Where the squared friction residual dropped from `before` to `after`:
/// the state the change depends on ([`attribute`]), and within that
/// state's bins the one with the largest ratio of its share of the
/// improvement to its share of the samples (bins of at least 5 % of the
/// samples; every state's bins when no state explains the change).
pub fn where_improved(
    d: &FrictionData,
    intervals: &[usize],
    (before_model, before): (&FrictionModel, &[f64]),
    (after_model, after): (&FrictionModel, &[f64]),
) -> Where {
    let gain = |j: usize| (d.f[j] - before[j]).powi(2) - (d.f[j] - after[j]).powi(2);
    let total: f64 = intervals.iter().map(|&j| gain(j)).sum();
    let n = intervals.len().max(1) as f64;
    let explained_by = attribute(d, intervals, (before_model, before), (after_model, after));
    let state_of_change = explained_by.first().map(|a| a.state);
    let mut all = Vec::new();
    let mut best: Option<(f64, usize)> = None;
    for (state, label, members) in bins(d, intervals) {
        let share_samples = members.len() as f64 / n;
        let share_gain = if total != 0.0 {
            members.iter().map(|&j| gain(j)).sum::<f64>() / total
        } else {
            0.0
        };
        if share_samples >= 0.05 && state_of_change.is_none_or(|s| s == state) {
            let lift = share_gain / share_samples;
            if best.is_none_or(|(b, _)| lift > b) {
                best = Some((lift, all.len()));
            }
        }
        all.push((state, label, share_gain, share_samples));
    }
    let (state, bin, g, s) = match best {
        Some((_, k)) => all[k].clone(),
        None => ("none", String::new(), 0.0, 0.0),
    };
    Where {
        state,
        bin,
        share_of_improvement: g,
        share_of_samples: s,
        bins: all
            .into_iter()
            .map(|(state, label, g, s)| (state.to_string(), label, g, s))
            .collect(),
        explained_by,
        intervals: earning_spans(d, intervals, &gain),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minute of a slow sine stroke and a faster one on top, sampled at
    /// 1 kHz: every speed, both directions and the whole travel.
    fn data() -> FrictionData {
        let n = 60_000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|&t| 0.05 * (0.6 * t).sin() + 0.01 * (7.3 * t).sin())
            .collect();
        let v: Vec<f64> = t
            .iter()
            .map(|&t| 0.03 * (0.6 * t).cos() + 0.073 * (7.3 * t).cos())
            .collect();
        FrictionData {
            h: vec![1e-3; n],
            end: (1..=n).collect(),
            fn_: vec![1.0; n],
            f: vec![0.0; n],
            source: String::new(),
            position_resolution: None,
            position_step: None,
            normal_force_measured: false,
            trusted: vec![true; n],
            record_starts: vec![0],
            t,
            v,
            x,
        }
    }

    fn nominal() -> FrictionModel {
        FrictionModel::coulomb_for_tests(2.0, 1e6, 1e3)
    }

    /// The law's force along the data: the steady sliding force with the
    /// sign of v (what a stiff LuGre contact gives while sliding).
    fn force(d: &FrictionData, m: &FrictionModel) -> Vec<f64> {
        (0..d.t.len())
            .map(|j| m.sliding_level(d.v[j], d.x[j], 1.0) * d.v[j].signum())
            .collect()
    }

    fn first_state(
        d: &FrictionData,
        before: &FrictionModel,
        after: &FrictionModel,
    ) -> (&'static str, f64) {
        let all: Vec<usize> = (0..d.t.len()).collect();
        let a = attribute(
            d,
            &all,
            (before, &force(d, before)),
            (after, &force(d, after)),
        );
        (a[0].state, a[0].share)
    }

    #[test]
    fn each_effect_is_put_on_the_state_it_depends_on() {
        let d = data();
        let n = nominal();
        let mut viscous = n.clone();
        viscous.sigma2 = 5.0;
        let mut stribeck = n.clone();
        stribeck.fs = 2.6;
        stribeck.fs_neg = 2.6;
        let mut direction = n.clone();
        direction.direction_dependent = true;
        direction.fc_neg = 2.3;
        direction.fs_neg = 2.3;
        let mut position = n.clone();
        position.position_dependent = true;
        position.x_table = vec![-0.06, -0.02, 0.02, 0.06];
        position.scale_pos = vec![1.1, 0.9, 1.05, 0.95];
        position.scale_neg = position.scale_pos.clone();
        for (after, expected) in [
            (&viscous, "velocity"),
            (&stribeck, "velocity"),
            (&direction, "direction"),
            (&position, "position"),
        ] {
            let (state, share) = first_state(&d, &n, after);
            assert_eq!(state, expected);
            assert!(share > 0.9, "{expected}: {share}");
        }
    }

    #[test]
    fn a_change_of_the_transition_alone_goes_to_the_displacement_since_reversal() {
        let d = data();
        let n = nominal();
        let mut stiffer = n.clone();
        stiffer.sigma0 = 4e6;
        let all: Vec<usize> = (0..d.t.len()).collect();
        let since = displacement_since_reversal(&d);
        let before = force(&d, &n);
        // the presliding transition: a deficit that decays over 1 mm moved
        let after: Vec<f64> = (0..d.t.len())
            .map(|j| before[j] + 0.3 * (-since[j] / 1e-3).exp() * d.v[j].signum())
            .collect();
        let a = attribute(&d, &all, (&n, &before), (&stiffer, &after));
        assert_eq!(a[0].state, "displacement_since_reversal", "{a:?}");
    }

    #[test]
    fn the_displacement_since_reversal_counts_from_the_turning_point() {
        // 1 mm forwards, then 2 mm back, the estimated velocity's sign
        // flipping at every sample while the motion creeps
        let n = 3000;
        let x: Vec<f64> = (0..n)
            .map(|k| {
                let k = k as f64;
                if k < 1000.0 {
                    1e-6 * k
                } else {
                    1e-3 - 1e-6 * (k - 1000.0)
                }
            })
            .collect();
        let mut d = data();
        d.t = (0..n).map(|k| k as f64 * 1e-3).collect();
        d.h = vec![1e-3; n];
        d.v = (0..n)
            .map(|k| if k % 2 == 0 { 1e-4 } else { -1e-4 })
            .collect();
        d.fn_ = vec![1.0; n];
        d.f = vec![0.0; n];
        d.trusted = vec![true; n];
        d.end = (1..=n).collect();
        d.position_resolution = Some(1e-6);
        d.x = x;
        let moved = displacement_since_reversal(&d);
        assert!((moved[999] - 0.999e-3).abs() < 1e-12, "{}", moved[999]);
        // turned back at 1 mm (after the 3 µm deadband): counted from there
        assert!((moved[2999] - 1.999e-3).abs() < 1e-12, "{}", moved[2999]);
        assert!(moved[1500] > moved[1200], "{} {}", moved[1500], moved[1200]);
    }

    #[test]
    fn a_level_moved_alone_depends_on_no_state() {
        let d = data();
        let n = nominal();
        let mut higher = n.clone();
        higher.fc = 2.2;
        higher.fs = 2.2;
        higher.fc_neg = 2.2;
        higher.fs_neg = 2.2;
        let all: Vec<usize> = (0..d.t.len()).collect();
        let a = attribute(
            &d,
            &all,
            (&n, &force(&d, &n)),
            (&higher, &force(&d, &higher)),
        );
        assert!(a.is_empty(), "{a:?}");
    }
}
