//! Bad and odd samples in a measurement file, found before anything is
//! fitted, reported with their line, column and value, and kept out of the
//! fits and the scores:
//!
//! - **spike**: one sample far off both neighbours. Its second difference
//!   `y[k-1] − 2·y[k] + y[k+1]` exceeds [`SPIKE_FACTOR`] times the local
//!   scale of the second differences (their median absolute value over
//!   [`LOCAL_WINDOW`] samples around, leaving out the three it affects,
//!   over 0.6745; at least the column's quantisation step), so a fast but
//!   smooth transient, whose neighbours curve as much, is not one; and its
//!   neighbours' second differences are of the opposite sign (a spike of
//!   height S makes S, −2S, S), so a kink, which makes one alone, is not
//!   one either;
//! - **dropout**: two or more rows identical in every column to the row
//!   before while time advances, after a column that changed on every one
//!   of the rows before, which then jumps by at least twice its usual
//!   change: a logger that repeated its last row and caught up;
//! - **gap**: a time step more than [`GAP_FACTOR`] times the median;
//! - **saturation**: a column sitting at its extreme value (largest or
//!   smallest) in runs of at least [`SATURATION_RUN`] samples, and
//!   [`SATURATION_RUN_FACTOR`] times its median run of equal values (a
//!   column held in steps, a table, sits at every value a while), that it
//!   reaches or leaves at speed (a step of at least [`SATURATION_KINK`]
//!   times its resolution on the sample before or after: a kink, not the
//!   smooth arrival of a signal that parks there), for at least
//!   [`SATURATION_SHARE`] of the file: a clipped sensor or converter.
//!
//! Spikes and dropouts are repaired by linear interpolation between the
//! good neighbours (the co-simulation needs its inputs, the inverse
//! dynamics a position without jumps) and, like saturated samples, left out
//! of every score and of the force fits (with the smoothing window around
//! them); a gap's interval is left out of the force fits.
//!
//! [`resolution`] estimates what a position channel resolves: its
//! quantisation step and its noise.

use serde::Serialize;

/// A spike's second difference is at least this many local scales.
pub const SPIKE_FACTOR: f64 = 20.0;
/// A spike's neighbours' second differences are of the opposite sign and
/// at least this fraction of its own (half, for a clean spike).
pub const SPIKE_FLANK: f64 = 0.25;
/// Samples around a spike whose second differences set the local scale.
pub const LOCAL_WINDOW: usize = 41;
/// A time step this many times the median is a gap.
pub const GAP_FACTOR: f64 = 1.5;
/// Shortest run at an extreme value that counts toward saturation.
pub const SATURATION_RUN: usize = 10;
/// A saturated run is at least this many times the column's median run of
/// equal values.
pub const SATURATION_RUN_FACTOR: f64 = 5.0;
/// A saturated run is reached or left by a step of at least this many
/// resolutions of the column (its quantisation step, twice its noise).
pub const SATURATION_KINK: f64 = 5.0;
/// A column whose resolution (quantisation step, noise) is at most this
/// fraction of its range has neither: it is computed, not measured, and
/// is not checked for saturation.
pub const NOISE_FREE: f64 = 1e-12;
/// Share of the samples at the extreme for a column to be saturated.
pub const SATURATION_SHARE: f64 = 0.005;
/// At most this share of a file's samples may be flagged.
pub const MAX_FLAGGED_SHARE: f64 = 0.5;
/// Findings listed one by one per kind (the rest are counted).
const LISTED: usize = 20;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    Spike,
    Dropout,
    Gap,
    Saturation,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Spike => "spike",
            Kind::Dropout => "dropout",
            Kind::Gap => "gap",
            Kind::Saturation => "saturation",
        }
    }
}

/// One finding.
#[derive(Clone, Debug, Serialize)]
pub struct Finding {
    pub kind: Kind,
    /// The column (`time` for a gap).
    pub column: String,
    /// Line in the file (1 is the header).
    pub line: u64,
    pub time: f64,
    /// The value found (a gap: its length in seconds).
    pub value: f64,
    /// Samples it covers.
    pub samples: usize,
    /// The file, when several records were joined ([`Quality::append`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
}

impl Finding {
    /// One line: `FILE: line N: ...` (without the file when `file` is
    /// empty; the finding's own file when it has one).
    pub fn describe(&self, file: &str) -> String {
        let file = self.file.as_deref().unwrap_or(file);
        let file = if file.is_empty() {
            String::new()
        } else {
            format!("{file}: ")
        };
        match self.kind {
            Kind::Gap => format!(
                "{file}line {}: gap of {} s in `time` before t = {} s",
                self.line, self.value, self.time
            ),
            Kind::Spike => format!(
                "{file}line {}: spike in `{}`: {} at t = {} s",
                self.line, self.column, self.value, self.time
            ),
            Kind::Dropout => format!(
                "{file}line {}: dropout: {} rows repeat the row before (every column held at t = {} s, `{}` = {})",
                self.line, self.samples, self.time, self.column, self.value
            ),
            Kind::Saturation => format!(
                "{file}line {}: `{}` saturated at {} ({} samples at that value, from t = {} s)",
                self.line, self.column, self.value, self.samples, self.time
            ),
        }
    }
}

/// What the inspection found, per file.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Quality {
    /// The first findings of each kind.
    pub findings: Vec<Finding>,
    /// How many findings of each kind, and samples left out.
    pub spikes: usize,
    pub dropouts: usize,
    pub gaps: usize,
    pub saturated: usize,
    pub excluded_samples: usize,
    /// Per row: left out of scores and fits.
    #[serde(skip)]
    pub excluded: Vec<bool>,
    /// Per row: the interval that ends at it spans a gap.
    #[serde(skip)]
    pub after_gap: Vec<bool>,
}

impl Quality {
    fn note(&mut self, f: Finding) {
        let count = match f.kind {
            Kind::Spike => &mut self.spikes,
            Kind::Dropout => &mut self.dropouts,
            Kind::Gap => &mut self.gaps,
            Kind::Saturation => &mut self.saturated,
        };
        *count += 1;
        if *count <= LISTED {
            self.findings.push(f);
        }
    }

    pub fn total(&self) -> usize {
        self.spikes + self.dropouts + self.gaps + self.saturated
    }

    /// Append the findings and rows of another record (`file`), after
    /// these rows (several records joined, [`super::problem::Measured::join`]).
    pub fn append(&mut self, other: Quality, file: &str) {
        self.findings
            .extend(other.findings.into_iter().map(|mut f| {
                f.file.get_or_insert_with(|| file.to_string());
                f
            }));
        self.spikes += other.spikes;
        self.dropouts += other.dropouts;
        self.gaps += other.gaps;
        self.saturated += other.saturated;
        self.excluded_samples += other.excluded_samples;
        self.excluded.extend(other.excluded);
        self.after_gap.extend(other.after_gap);
    }
}

/// The median of the positive sample spacings (a file always has one:
/// [`super::problem::Measured::read`] requires time to advance).
pub fn median_spacing(time: &[f64]) -> f64 {
    let mut dt: Vec<f64> = time
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .collect();
    dt.sort_by(f64::total_cmp);
    dt.get(dt.len() / 2).copied().unwrap_or(f64::INFINITY)
}

fn median(mut x: Vec<f64>) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let mid = x.len() / 2;
    *x.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// The quantisation step of a column: the smallest positive change between
/// samples when most changes are whole multiples of it (within 1 %), else
/// 0 (not quantised, or too finely to tell).
pub fn quantum(y: &[f64]) -> f64 {
    let d: Vec<f64> = y
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0)
        .collect();
    let Some(q) = d.iter().copied().min_by(f64::total_cmp) else {
        return 0.0;
    };
    let whole = d
        .iter()
        .filter(|&&x| {
            let r = x / q;
            (r - r.round()).abs() < 0.01 * r.max(1.0)
        })
        .count();
    if whole as f64 >= 0.9 * d.len() as f64 && d.len() >= 10 {
        q
    } else {
        0.0
    }
}

/// The white-noise standard deviation of a column from its second
/// differences (σ·√6 for white noise; median absolute value / 0.6745,
/// robust to the signal's own curvature and to outliers).
pub fn noise_sigma(y: &[f64]) -> f64 {
    let d2: Vec<f64> = y
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
        .collect();
    median(d2) / 0.6745 / 6f64.sqrt()
}

/// What a position channel resolves: the larger of its quantisation step
/// and twice its noise (m).
pub fn resolution(y: &[f64]) -> f64 {
    quantum(y).max(2.0 * noise_sigma(y))
}

/// The smallest displacement a single reading of a position channel
/// registers: its quantisation step (an encoder's count), or its
/// resolution when it is not quantised (m).
pub fn step(y: &[f64]) -> f64 {
    let q = quantum(y);
    if q > 0.0 {
        q
    } else {
        resolution(y)
    }
}

/// Inspect `time` and the `columns` (name, values; `lines[k]` the file line
/// of row k), repair spikes and dropouts in place, and return what was
/// found.
pub fn inspect(time: &[f64], columns: &mut [(String, Vec<f64>)], lines: &[u64]) -> Quality {
    let n = time.len();
    let mut q = Quality {
        excluded: vec![false; n],
        after_gap: vec![false; n],
        ..Quality::default()
    };
    let line = |k: usize| lines.get(k).copied().unwrap_or(k as u64 + 2);

    // gaps
    let spacing = median_spacing(time);
    for k in 1..n {
        let dt = time[k] - time[k - 1];
        if dt > GAP_FACTOR * spacing {
            q.after_gap[k] = true;
            q.note(Finding {
                kind: Kind::Gap,
                column: "time".into(),
                line: line(k),
                time: time[k],
                value: dt,
                samples: 1,
                file: None,
            });
        }
    }

    // dropouts: every column repeated, after steady change, then a jump
    let same =
        |a: usize, b: usize, cols: &[(String, Vec<f64>)]| cols.iter().all(|(_, y)| y[a] == y[b]);
    let mut k = 1;
    while k < n {
        if !(time[k] > time[k - 1] && same(k, k - 1, columns)) {
            k += 1;
            continue;
        }
        let start = k;
        while k < n && time[k] > time[k - 1] && same(k, k - 1, columns) {
            k += 1;
        }
        let (len, end) = (k - start, k);
        if len >= 2 && start >= 6 && end < n {
            // a column that changed on each of the 5 rows before and jumps
            // after the run by twice its usual change
            let moving = columns.iter().find(|(_, y)| {
                let before: Vec<f64> = (start - 5..start)
                    .map(|j| (y[j] - y[j - 1]).abs())
                    .collect();
                let usual = median(before.clone());
                before.iter().all(|d| *d > 0.0) && (y[end] - y[end - 1]).abs() >= 2.0 * usual
            });
            if let Some((name, y)) = moving {
                q.note(Finding {
                    kind: Kind::Dropout,
                    column: name.clone(),
                    line: line(start),
                    time: time[start],
                    value: y[start],
                    samples: len,
                    file: None,
                });
                for (_, y) in columns.iter_mut() {
                    let (a, b) = (y[start - 1], y[end]);
                    for j in start..end {
                        let u = (time[j] - time[start - 1]) / (time[end] - time[start - 1]);
                        y[j] = a + u * (b - a);
                    }
                }
                q.excluded[start..end].iter_mut().for_each(|e| *e = true);
            }
        }
    }

    // spikes, column by column (twice: a second pass finds a spike that
    // sat beside another)
    for (name, y) in columns.iter_mut() {
        let step = quantum(y);
        for _ in 0..2 {
            let d2: Vec<f64> = (0..n)
                .map(|k| {
                    if k == 0 || k + 1 >= n {
                        0.0
                    } else {
                        y[k - 1] - 2.0 * y[k] + y[k + 1]
                    }
                })
                .collect();
            let half = LOCAL_WINDOW / 2;
            let mut found = Vec::new();
            for k in 1..n.saturating_sub(1) {
                // not across an event (a repeated time: a table's step)
                if time[k] <= time[k - 1] || time[k + 1] <= time[k] {
                    continue;
                }
                let lo = k.saturating_sub(half).max(1);
                let hi = (k + half).min(n - 2);
                let local: Vec<f64> = (lo..=hi)
                    .filter(|&j| j + 1 < k || j > k + 1)
                    .map(|j| d2[j].abs())
                    .collect();
                let scale = (median(local) / 0.6745).max(step).max(f64::MIN_POSITIVE);
                // a spike of height S at k makes the second differences
                // (S, −2S, S) at k−1, k, k+1; a kink (a clipped or
                // triangular signal) makes one alone, and is not a spike
                let flanked =
                    |j: usize| d2[j] * d2[k] < 0.0 && d2[j].abs() >= SPIKE_FLANK * d2[k].abs();
                if d2[k].abs() > SPIKE_FACTOR * scale
                    && d2[k].abs() >= d2[k - 1].abs()
                    && d2[k].abs() >= d2[k + 1].abs()
                    && (k < 2 || flanked(k - 1))
                    && (k + 2 >= n || flanked(k + 1))
                {
                    found.push(k);
                }
            }
            if found.is_empty() {
                break;
            }
            for &k in &found {
                q.note(Finding {
                    kind: Kind::Spike,
                    column: name.clone(),
                    line: line(k),
                    time: time[k],
                    value: y[k],
                    samples: 1,
                    file: None,
                });
                let u =
                    (time[k] - time[k - 1]) / (time[k + 1] - time[k - 1]).max(f64::MIN_POSITIVE);
                y[k] = y[k - 1] + u * (y[k + 1] - y[k - 1]);
                q.excluded[k] = true;
            }
        }
    }

    // saturation: runs at a column's extreme value
    for (name, y) in columns.iter() {
        let (lo, hi) = y
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        if lo >= hi {
            continue; // a constant column is a setting, not a clipped one
        }
        // a column without noise or quantisation (a computed command: the
        // reference a controller followed) sits at its extreme because it
        // was told to, a constant-velocity run (the standard friction
        // experiment) reached by a ramp, not because a converter clipped it
        let res = resolution(y);
        if res <= NOISE_FREE * (hi - lo) {
            continue;
        }
        let kink = SATURATION_KINK * res.max(f64::MIN_POSITIVE);
        // a column held in steps (a table, a setting) sits at every value
        // for a while: a clipped signal sits at its extreme far longer
        // than at its other values
        let mut run_lengths = Vec::new();
        let mut start = 0;
        for k in 1..=n {
            if k == n || y[k] != y[start] {
                run_lengths.push((k - start) as f64);
                start = k;
            }
        }
        let usual_run = median(run_lengths);
        for extreme in [hi, lo] {
            let mut runs = Vec::new();
            let mut k = 0;
            while k < n {
                if y[k] == extreme {
                    let s = k;
                    while k < n && y[k] == extreme {
                        k += 1;
                    }
                    let arrives = s >= 1 && (y[s] - y[s - 1]).abs() >= kink;
                    let leaves = k < n && (y[k] - y[k - 1]).abs() >= kink;
                    let long = (k - s) as f64 >= SATURATION_RUN_FACTOR * usual_run;
                    if k - s >= SATURATION_RUN && long && (arrives || leaves) {
                        runs.push((s, k));
                    }
                } else {
                    k += 1;
                }
            }
            let total: usize = runs.iter().map(|(s, e)| e - s).sum();
            if total as f64 >= SATURATION_SHARE * n as f64 {
                for &(s, e) in &runs {
                    q.excluded[s..e].iter_mut().for_each(|x| *x = true);
                }
                q.note(Finding {
                    kind: Kind::Saturation,
                    column: name.clone(),
                    line: line(runs[0].0),
                    time: time[runs[0].0],
                    value: extreme,
                    samples: total,
                    file: None,
                });
            }
        }
    }
    q.excluded_samples = q.excluded.iter().filter(|&&e| e).count();
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth record quantised to 1 µm, with stick-slip-like fast
    /// stretches: nothing is flagged.
    fn record(n: usize) -> (Vec<f64>, Vec<(String, Vec<f64>)>) {
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let x: Vec<f64> = time
            .iter()
            .map(|t| {
                let s = 0.03 * (6.0 * t).sin() + 0.002 * (t * 40.0).tanh();
                (s / 1e-6).round() * 1e-6
            })
            .collect();
        let a: Vec<f64> = time
            .iter()
            .map(|t| ((0.04 * (6.0 * t + 0.3).sin()) / 1e-6).round() * 1e-6)
            .collect();
        (time, vec![("rig.x_act_in".into(), a), ("rig.x".into(), x)])
    }

    #[test]
    fn clean_record_has_no_finding() {
        let (time, mut cols) = record(5000);
        let before = cols.clone();
        let q = inspect(&time, &mut cols, &[]);
        assert_eq!(q.total(), 0, "{:?}", q.findings);
        assert_eq!(cols[1].1, before[1].1);
        assert!((quantum(&cols[1].1) - 1e-6).abs() < 1e-12);
    }

    #[test]
    fn spikes_dropouts_gaps_and_saturation_are_found_with_their_lines() {
        let (mut time, mut cols) = record(5000);
        let clean = cols[1].1[1234];
        cols[1].1[1234] *= 10.0; // a 10× spike
        cols[1].1[3000] = 1e6; // a wild one
        for k in 2001..2005 {
            // a dropout: four rows repeat row 2000
            for (_, y) in cols.iter_mut() {
                y[k] = y[2000];
            }
        }
        for t in time.iter_mut().skip(4000) {
            *t += 0.05; // a gap before row 4000
        }
        for y in cols[0].1.iter_mut() {
            *y = y.min(0.03); // clipped: its kinks are not spikes
        }
        let lines: Vec<u64> = (0..5000).map(|k| k as u64 + 2).collect();
        let q = inspect(&time, &mut cols, &lines);
        let spikes: Vec<u64> = q
            .findings
            .iter()
            .filter(|f| f.kind == Kind::Spike)
            .map(|f| f.line)
            .collect();
        assert_eq!(spikes, [1236, 3002], "{:?}", q.findings);
        assert!((cols[1].1[1234] - clean).abs() < 5e-6, "repaired");
        let drop = q.findings.iter().find(|f| f.kind == Kind::Dropout).unwrap();
        assert_eq!((drop.line, drop.samples), (2003, 4));
        let gap = q.findings.iter().find(|f| f.kind == Kind::Gap).unwrap();
        assert_eq!(gap.line, 4002);
        assert!((gap.value - 0.051).abs() < 1e-9);
        assert_eq!(q.gaps, 1);
        assert!(
            q.findings
                .iter()
                .any(|f| f.kind == Kind::Saturation && f.column == "rig.x_act_in"),
            "{:?}",
            q.findings
        );
        assert!(q.excluded[1234] && q.excluded[3000] && q.excluded[2002]);
        assert!(!q.excluded[1000]);
    }

    #[test]
    fn saturation_at_the_extreme_is_found() {
        let (time, mut cols) = record(5000);
        let cap = 0.02;
        for y in cols[1].1.iter_mut() {
            *y = y.min(cap);
        }
        let q = inspect(&time, &mut cols, &[]);
        let s: Vec<&Finding> = q
            .findings
            .iter()
            .filter(|f| f.kind == Kind::Saturation)
            .collect();
        assert_eq!(s.len(), 1, "{:?}", q.findings);
        assert_eq!((s[0].column.as_str(), s[0].value), ("rig.x", cap));
        assert!(q.excluded_samples >= s[0].samples);
    }

    /// A drive that ramps smoothly to its largest value and parks there is
    /// not a clipped one.
    #[test]
    fn a_signal_parked_at_its_extreme_is_not_saturated() {
        let n = 5000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let y: Vec<f64> = time
            .iter()
            .map(|&t| {
                let u = (t / 2.0).min(1.0);
                ((0.02 * (0.5 - 0.5 * (std::f64::consts::PI * u).cos())) / 1e-6).round() * 1e-6
            })
            .collect();
        let mut cols = vec![("rig.x_act_in".to_string(), y)];
        let q = inspect(&time, &mut cols, &[]);
        assert_eq!(q.saturated, 0, "{:?}", q.findings);
    }

    /// A computed velocity reference of constant-velocity plateaus joined
    /// by linear ramps (as a test rig's motion controller commands them)
    /// is not clipped, though it reaches its extremes with a kink; the same
    /// reference measured (quantised) and clipped below its plateau is.
    #[test]
    fn a_computed_reference_at_its_extreme_is_not_saturated() {
        let n = 16000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let plateaus = [(1.0, 0.05), (0.5, 0.15), (0.5, -0.15), (1.0, -0.05)];
        let v_ref = |t: f64| {
            let tau = t.rem_euclid(3.0);
            let mut t0 = 0.0;
            for (i, &(length, v)) in plateaus.iter().enumerate() {
                if tau < t0 + length {
                    let previous = plateaus[(i + 3) % 4].1;
                    return previous + (v - previous) * ((tau - t0) / 0.05).min(1.0);
                }
                t0 += length;
            }
            plateaus[3].1
        };
        let v: Vec<f64> = time.iter().map(|&t| v_ref(t)).collect();
        // with the position measured through a 1 µm encoder beside it
        let mut x = vec![0.1];
        for k in 1..n {
            x.push(x[k - 1] + 0.5e-3 * (v[k - 1] + v[k]));
        }
        let encoder: Vec<f64> = x.iter().map(|&x| (x / 1e-6).round() * 1e-6).collect();
        let mut cols = vec![
            ("rig.v_ref".to_string(), v.clone()),
            ("rig.x".to_string(), encoder),
        ];
        let q = inspect(&time, &mut cols, &[]);
        assert_eq!(q.total(), 0, "{:?}", q.findings);
        assert_eq!(cols[0].1, v, "nothing repaired");
        // measured through a converter of 1e-4 m/s that clips at 0.12
        let clipped: Vec<f64> = v
            .iter()
            .map(|&x| (x.clamp(-0.12, 0.12) / 1e-4).round() * 1e-4)
            .collect();
        let mut cols = vec![("rig.v".to_string(), clipped)];
        let q = inspect(&time, &mut cols, &[]);
        assert!(q.saturated >= 1, "{:?}", q.findings);
    }

    #[test]
    fn resolution_of_a_quantised_and_of_a_noisy_channel() {
        let y: Vec<f64> = (0..2000)
            .map(|k| ((0.01 * (k as f64 * 0.01).sin()) / 5e-6).round() * 5e-6)
            .collect();
        assert!((resolution(&y) - 5e-6).abs() < 1e-12);
        // white noise of 2e-6 without quantisation: resolution ≈ 4e-6
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let nd = Normal::new(0.0, 2e-6).unwrap();
        let z: Vec<f64> = (0..20000)
            .map(|k| 0.01 * (k as f64 * 1e-3).sin() + nd.sample(&mut rng))
            .collect();
        let r = resolution(&z);
        assert!((r - 4e-6).abs() < 0.3e-6, "{r}");
    }
}
