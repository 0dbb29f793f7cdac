//! Where a discrepancy lies: the friction residual (force the data imply
//! minus force the law gives, along the measured states) split by the
//! states a friction effect depends on: velocity band, direction of
//! motion, position along the travel, time since the last reversal and
//! normal load.

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
    // time since reversal: quartiles
    let since = time_since_reversal(d);
    let mut s: Vec<f64> = intervals.iter().map(|&j| since[j]).collect();
    s.sort_by(f64::total_cmp);
    if let (Some(&first), Some(&last)) = (s.first(), s.last()) {
        let q = |p: f64| s[((s.len() - 1) as f64 * p) as usize];
        let edges = [first, q(0.25), q(0.5), q(0.75), last];
        for k in 0..4 {
            let (a, b) = (edges[k], edges[k + 1]);
            if b > a {
                out.push((
                    "time_since_reversal",
                    format!("{a:.3} to {b:.3} s"),
                    pick(&|j| since[j] >= a && (since[j] < b || (k == 3 && since[j] <= b))),
                ));
            }
        }
    }
    if d.normal_force_measured {
        let mut f: Vec<f64> = intervals.iter().map(|&j| d.fn_[j]).collect();
        f.sort_by(f64::total_cmp);
        let q = |p: f64| f[((f.len() - 1) as f64 * p) as usize];
        let edges = [q(0.0), q(0.25), q(0.5), q(0.75), q(1.0)];
        for k in 0..4 {
            let (a, b) = (edges[k], edges[k + 1]);
            if b > a {
                out.push((
                    "normal_load",
                    format!("{a:.4} to {b:.4} N"),
                    pick(&|j| d.fn_[j] >= a && (d.fn_[j] < b || (k == 3 && d.fn_[j] <= b))),
                ));
            }
        }
    }
    out
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
/// the bin with the largest ratio of its share of the improvement to its
/// share of the samples (bins of at least 5 % of the samples).
pub fn where_improved(
    d: &FrictionData,
    intervals: &[usize],
    before: &[f64],
    after: &[f64],
) -> Where {
    let gain = |j: usize| (d.f[j] - before[j]).powi(2) - (d.f[j] - after[j]).powi(2);
    let total: f64 = intervals.iter().map(|&j| gain(j)).sum();
    let n = intervals.len().max(1) as f64;
    let mut all = Vec::new();
    let mut best: Option<(f64, usize)> = None;
    for (state, label, members) in bins(d, intervals) {
        let share_samples = members.len() as f64 / n;
        let share_gain = if total != 0.0 {
            members.iter().map(|&j| gain(j)).sum::<f64>() / total
        } else {
            0.0
        };
        if share_samples >= 0.05 {
            let lift = share_gain / share_samples;
            if best.is_none_or(|(b, _)| lift > b) {
                best = Some((lift, all.len()));
            }
        }
        all.push((state.to_string(), label, share_gain, share_samples));
    }
    let (state, bin, g, s) = match best {
        Some((_, k)) => all[k].clone(),
        None => ("none".into(), String::new(), 0.0, 0.0),
    };
    Where {
        state: match state.as_str() {
            "velocity" => "velocity",
            "direction" => "direction",
            "position" => "position",
            "time_since_reversal" => "time_since_reversal",
            "normal_load" => "normal_load",
            _ => "none",
        },
        bin,
        share_of_improvement: g,
        share_of_samples: s,
        bins: all,
    }
}
