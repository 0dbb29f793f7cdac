//! The tests that decide: whether a candidate model predicts the held-out
//! data better than the current one ([`nested_test`]), which of two
//! explanations of one signature the data prefer ([`separation_test`]),
//! the grouped signed-rank and t tests under both, and the one acceptance
//! rule every decision of the diagnosis applies ([`Acceptance`]).
//!
//! Takes [`Scored`] co-simulations (the residuals of a model on the
//! held-out samples, normalised by the channel scales), and gives gains
//! and p-values; knows nothing of models, fits or files.

use crate::sim::ChannelResiduals;
use std::fmt;

/// A co-simulation scored on the held-out samples.
#[derive(Clone, Debug)]
pub struct Scored {
    pub(crate) residuals: ChannelResiduals,
    /// Held-out positions into `residuals.samples`.
    pub(crate) picked: Vec<usize>,
    /// Normalised squared residual per held-out sample.
    pub(crate) q: Vec<f64>,
    /// The co-simulation needed a fallback ([`crate::sim::co_simulate_robust`]).
    pub(crate) fallback: Option<String>,
}

impl Scored {
    /// The held-out RMS (normalised): √(mean of `q`).
    pub fn rms(&self) -> f64 {
        mean(&self.q).sqrt()
    }
}

/// The arithmetic mean (0 of nothing).
pub(crate) fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len().max(1) as f64
}

/// The acceptance rule: a change of the model (the refitted nominal, a
/// candidate effect, an effect kept at re-examination) stands when its
/// paired test's p-value is below `threshold` and it lowers the held-out
/// mean square by at least `min_gain` (relative, [`crate::Options::min_gain`]).
#[derive(Clone, Copy, Debug)]
pub struct Acceptance {
    /// p must be below this (α, or α over the hypotheses of a round).
    pub threshold: f64,
    pub min_gain: f64,
}

impl Acceptance {
    /// Whether a change of relative gain `gain` and p-value `p` passes.
    pub fn passes(&self, gain: f64, p: f64) -> bool {
        p < self.threshold && gain >= self.min_gain
    }
}

/// Two scores that a paired test cannot compare: they picked different
/// held-out samples (a co-simulation that reached fewer of them, or two
/// different splits). Every score of one diagnosis picks the same samples
/// (complete co-simulations of the same held-out data, through the same
/// folds), so this is a defect of the caller, reported rather than turned
/// into a p-value.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SampleMismatch {
    /// Held-out samples of each score.
    pub before: usize,
    pub after: usize,
    /// The first position at which they differ.
    pub at: usize,
}

impl fmt::Display for SampleMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "two scores picked different held-out samples ({} and {}, first different at position {}): they cannot be compared sample by sample",
            self.before, self.after, self.at
        )
    }
}

impl std::error::Error for SampleMismatch {}

impl From<SampleMismatch> for String {
    fn from(e: SampleMismatch) -> String {
        e.to_string()
    }
}

/// `Ok` when `a` and `b` scored the same held-out samples.
fn same_samples(a: &Scored, b: &Scored) -> Result<(), SampleMismatch> {
    if a.picked == b.picked {
        return Ok(());
    }
    let at = a
        .picked
        .iter()
        .zip(&b.picked)
        .position(|(x, y)| x != y)
        .unwrap_or(a.picked.len().min(b.picked.len()));
    Err(SampleMismatch {
        before: a.picked.len(),
        after: b.picked.len(),
        at,
    })
}

/// One-sided test that the candidate (`after`, the current model with an
/// effect added: the two models are nested) predicts the held-out data
/// better than the current model (`before`). Returns (relative drop of the
/// held-out mean square, p-value), or [`SampleMismatch`] when the two were
/// not scored on the same held-out samples.
///
/// The statistic is Clark and West's for nested models ("Approximately
/// normal tests for equal predictive accuracy in nested models", J.
/// Econometrics 138, 2007): per held-out sample
/// f = e₀² − e₁² + (ŷ₁ − ŷ₀)² = 2·e₀·(ŷ₁ − ŷ₀), with e the residuals and ŷ
/// the simulated channels, each divided by its scale and averaged over the
/// channels. When the current model is the truth, its error e₀ is noise
/// unrelated to what the candidate changes (fitted on other data), so f has
/// mean zero; the plain difference e₀² − e₁² would instead have a negative
/// mean, the candidate's extra parameters adding their estimation noise
/// (ŷ₁ − ŷ₀)² to its error, which makes that test lose power against
/// nested alternatives. f is averaged over the groups of `group`
/// (consecutive samples or blocks, so that correlated neighbours count
/// once) and the group means are tested with Wilcoxon's signed-rank test
/// ([`grouped_signed_rank_test`]): under the null hypothesis e₀ is noise
/// independent of the change, so f is symmetric about zero, which is all
/// the test assumes. Student's t on the same means ([`grouped_t_test`])
/// assumes them normal, and loses its power when the improvement sits in a
/// few groups (a stick-slip record, whose slips carry the evidence while
/// the sticks between them carry none): a candidate that removed 99.7 % of
/// the mean square scored p = 0.014 with t, far below p = 1e-5 by ranks.
/// Acceptance also requires the mean square itself to drop
/// ([`Acceptance`]).
pub fn nested_test(
    before: &Scored,
    after: &Scored,
    scales: &[f64],
    group: &[usize],
) -> Result<(f64, f64), SampleMismatch> {
    same_samples(before, after)?;
    let n = before.q.len();
    let mb = mean(&before.q);
    let gain = if mb > 0.0 {
        (mb - mean(&after.q)) / mb
    } else {
        0.0
    };
    let f: Vec<f64> = (0..n)
        .map(|i| {
            let k = before.picked[i];
            let change = (0..scales.len())
                .map(|c| {
                    let d = before.residuals.residuals[c][k] - after.residuals.residuals[c][k];
                    (d / scales[c]).powi(2)
                })
                .sum::<f64>()
                / scales.len().max(1) as f64;
            before.q[i] - after.q[i] + change
        })
        .collect();
    Ok((
        gain,
        grouped_signed_rank_test(&f, &group[..n.min(group.len())]),
    ))
}

/// One-sided p-value that `better` explains the held-out data better than
/// `other`, two candidates neither of which is nested in the other (two
/// explanations of one signature): per held-out sample the difference of
/// their normalised squared errors `q_other − q_better`, averaged per
/// group and tested with Wilcoxon's signed-rank test, as the acceptance
/// test does ([`grouped_signed_rank_test`]). [`SampleMismatch`] when they
/// were not scored on the same samples.
pub fn separation_test(
    better: &Scored,
    other: &Scored,
    group: &[usize],
) -> Result<f64, SampleMismatch> {
    same_samples(better, other)?;
    let n = better.q.len();
    let d: Vec<f64> = (0..n).map(|i| other.q[i] - better.q[i]).collect();
    Ok(grouped_signed_rank_test(&d, &group[..n.min(group.len())]))
}

/// The means of `d` over its groups (`group[i]` labels `d[i]`; a group is
/// a run of equal labels).
fn group_means(d: &[f64], group: &[usize]) -> Vec<f64> {
    let mut means = Vec::new();
    let mut start = 0;
    for i in 1..=d.len() {
        if i == d.len() || group[i] != group[start] {
            means.push(d[start..i].iter().sum::<f64>() / (i - start) as f64);
            start = i;
        }
    }
    means
}

/// One-sided p-value that `d` is centred above zero: `d` averaged over its
/// groups, then Wilcoxon's signed-rank test of the group means (zeros
/// dropped). Exact (the distribution of W⁺ counted by dynamic programming)
/// when the ranks have no ties and there are at most
/// [`SIGNED_RANK_EXACT`] means; else the normal approximation with the
/// tie correction and a continuity correction of ½.
pub fn grouped_signed_rank_test(d: &[f64], group: &[usize]) -> f64 {
    let means: Vec<f64> = group_means(d, group)
        .into_iter()
        .filter(|m| *m != 0.0)
        .collect();
    let n = means.len();
    if n < 2 {
        return 1.0;
    }
    // ranks of |m|, ties given their average rank
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| means[a].abs().total_cmp(&means[b].abs()));
    let mut rank = vec![0.0; n];
    let mut ties = Vec::new();
    let mut i = 0;
    while i < n {
        let mut j = i + 1;
        while j < n && means[order[j]].abs() == means[order[i]].abs() {
            j += 1;
        }
        let average = (i + j + 1) as f64 / 2.0; // ranks i+1..=j
        for &k in &order[i..j] {
            rank[k] = average;
        }
        if j - i > 1 {
            ties.push((j - i) as f64);
        }
        i = j;
    }
    let w_plus: f64 = (0..n).filter(|&k| means[k] > 0.0).map(|k| rank[k]).sum();
    if ties.is_empty() && n <= SIGNED_RANK_EXACT {
        // counts[s]: subsets of the ranks 1..=n with sum s
        let total = n * (n + 1) / 2;
        let mut counts = vec![0f64; total + 1];
        counts[0] = 1.0;
        for r in 1..=n {
            for s in (r..=total).rev() {
                counts[s] += counts[s - r];
            }
        }
        let w = w_plus.round() as usize;
        let above: f64 = counts[w..].iter().sum();
        return above / 2f64.powi(n as i32);
    }
    let nf = n as f64;
    let mean_w = nf * (nf + 1.0) / 4.0;
    let var_w = nf * (nf + 1.0) * (2.0 * nf + 1.0) / 24.0
        - ties.iter().map(|t| t * t * t - t).sum::<f64>() / 48.0;
    if var_w <= 0.0 {
        return 1.0;
    }
    let z = (w_plus - mean_w - 0.5) / var_w.sqrt();
    use statrs::distribution::{ContinuousCDF, Normal};
    Normal::new(0.0, 1.0).map_or(1.0, |dist| 1.0 - dist.cdf(z))
}

/// Up to this many group means the signed-rank test is exact.
pub const SIGNED_RANK_EXACT: usize = 60;

/// One-sided p-value that the mean of `d` is positive: `d` averaged over
/// its groups (`group[i]` labels `d[i]`; a group is a run of equal
/// labels), Student's t with groups − 1 degrees of freedom.
pub fn grouped_t_test(d: &[f64], group: &[usize]) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    let means = group_means(d, group);
    if means.len() < 2 {
        return 1.0;
    }
    let m = mean(&means);
    let sd =
        (means.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (means.len() as f64 - 1.0)).sqrt();
    if sd.is_nan() || sd <= 0.0 {
        return if m > 0.0 { 0.0 } else { 1.0 };
    }
    let t = m / (sd / (means.len() as f64).sqrt());
    match StudentsT::new(0.0, 1.0, means.len() as f64 - 1.0) {
        Ok(dist) => 1.0 - dist.cdf(t),
        Err(_) => 1.0,
    }
}

/// Whether a candidate of held-out RMS `candidate_rms` lowers the mean
/// square of `current` by more than the square of the co-simulation's step
/// error (`step_error`, [`crate::stages::scoring::step_error_floor`]): at
/// most that much of the error can be the integration's, which a parameter
/// change can partly compensate.
pub(crate) fn drop_beyond_step_error(
    current: &Scored,
    candidate_rms: f64,
    step_error: f64,
) -> bool {
    mean(&current.q) - candidate_rms * candidate_rms > step_error * step_error
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// A scored run of one channel (scale 1) with these residuals.
    pub(crate) fn scored(residuals: Vec<f64>) -> Scored {
        let n = residuals.len();
        Scored {
            q: residuals.iter().map(|r| r * r).collect(),
            picked: (0..n).collect(),
            residuals: ChannelResiduals {
                channels: vec!["y".into()],
                samples: (0..n).collect(),
                simulated: vec![vec![0.0; n]],
                residuals: vec![residuals],
                incomplete: None,
            },
            fallback: None,
        }
    }

    #[test]
    fn the_rule_needs_both_a_small_p_and_a_large_enough_gain() {
        let rule = Acceptance {
            threshold: 0.01,
            min_gain: 0.02,
        };
        assert!(rule.passes(0.02, 0.009));
        assert!(!rule.passes(0.02, 0.01), "p must be below the threshold");
        assert!(!rule.passes(0.019, 0.001), "the gain must reach min_gain");
    }

    /// Scores of different held-out samples are reported, not given p = 1.
    #[test]
    fn scores_of_different_samples_are_reported() {
        let before = scored(vec![1.0, 2.0, 3.0, 4.0]);
        let mut after = scored(vec![0.5, 1.0, 1.5, 2.0]);
        let group = [0, 1, 2, 3];
        assert!(nested_test(&before, &after, &[1.0], &group).is_ok());
        after.picked = vec![0, 1, 3, 2];
        let e = nested_test(&before, &after, &[1.0], &group).unwrap_err();
        assert_eq!(
            e,
            SampleMismatch {
                before: 4,
                after: 4,
                at: 2
            }
        );
        assert!(e.to_string().contains("different held-out samples"));
        // fewer samples: the difference is where the shorter one ends
        after.picked = vec![0, 1, 2];
        after.q.pop();
        let e = separation_test(&before, &after, &group).unwrap_err();
        assert_eq!((e.before, e.after, e.at), (4, 3, 3));
    }

    #[test]
    fn grouped_t_test_matches_students_t() {
        // d = 1, 2, 3, 4 in groups of one: mean 2.5, sd 1.2910, t = 3.8730,
        // 3 degrees of freedom, one-sided p = 0.0152331458 (SciPy 1.17,
        // stats.ttest_1samp([1, 2, 3, 4], 0, alternative="greater"))
        let p = grouped_t_test(&[1.0, 2.0, 3.0, 4.0], &[0, 1, 2, 3]);
        assert!((p - 0.015_233_145_8).abs() < 1e-9, "{p}");
        // groups average their members: (1, 1), (2, 2), ... is the same test
        let p2 = grouped_t_test(
            &[1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0],
            &[0, 0, 1, 1, 2, 2, 3, 3],
        );
        assert!((p2 - p).abs() < 1e-12, "{p2}");
        assert_eq!(
            grouped_t_test(&[1.0, 2.0], &[0, 0]),
            1.0,
            "one group: no test"
        );
    }

    #[test]
    fn signed_rank_test_matches_its_exact_distribution() {
        // all four positive: W+ = 10, P(W+ >= 10) = 1/16
        let p = grouped_signed_rank_test(&[1.0, 2.0, 3.0, 4.0], &[0, 1, 2, 3]);
        assert!((p - 1.0 / 16.0).abs() < 1e-15, "{p}");
        // -2 negative: W+ = 1 + 3 + 4 = 8; subsets of {1,2,3,4} summing to
        // at least 8: {1,3,4}, {2,3,4}, {1,2,3,4}: 3/16
        let p = grouped_signed_rank_test(&[1.0, -2.0, 3.0, 4.0], &[0, 1, 2, 3]);
        assert!((p - 3.0 / 16.0).abs() < 1e-15, "{p}");
        // groups average their members
        let p2 = grouped_signed_rank_test(&[1.0, 1.0, -2.0, -2.0, 3.0, 4.0], &[0, 0, 1, 1, 2, 3]);
        assert!((p2 - p).abs() < 1e-15);
        // a tie: the normal approximation (|m| = 1, 1, 2: ranks 1.5, 1.5,
        // 3, all positive: W+ = 6, mean 3, var 3.5 − 6/48 = 3.375,
        // z = 2.5/1.8371 = 1.3608, p = 0.08679)
        let p = grouped_signed_rank_test(&[1.0, 1.0, 2.0], &[0, 1, 2]);
        assert!((p - 0.086_79).abs() < 1e-4, "{p}");
        assert_eq!(grouped_signed_rank_test(&[1.0, 2.0], &[0, 0]), 1.0);
    }

    /// The improvement concentrated in a few groups (the slips of a
    /// stick-slip record), the others unchanged up to noise: the ranks see
    /// it, Student's t does not.
    #[test]
    fn signed_ranks_see_an_improvement_concentrated_in_a_few_groups() {
        let mut d = vec![0.0; 30];
        for (i, x) in d.iter_mut().enumerate() {
            *x = if i % 3 == 0 {
                100.0 * (1.0 + i as f64)
            } else {
                1e-3 * (1.0 + (i % 5) as f64)
            };
        }
        d[7] = -1e-3;
        let group: Vec<usize> = (0..30).collect();
        let rank = grouped_signed_rank_test(&d, &group);
        let t = grouped_t_test(&d, &group);
        assert!(rank < 1e-5 && t > 1e-3, "ranks {rank}, t {t}");
    }

    /// Clark–West on nested models: when the current model is the truth
    /// (its residuals pure noise) and the candidate changes the prediction
    /// by an amount fitted on other data, the test rejects at about its
    /// level; the plain difference of squared errors rejects almost never
    /// (the candidate's change adds to its error); when the candidate's
    /// change is part of the truth, Clark–West rejects.
    #[test]
    fn nested_test_holds_its_level_and_finds_a_real_change() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let noise = Normal::new(0.0, 1.0).unwrap();
        let (n, groups, trials) = (200, 20, 2000);
        let group: Vec<usize> = (0..n).map(|i| i * groups / n).collect();
        let (mut cw_null, mut plain_null, mut cw_real, mut t_null) = (0, 0, 0, 0);
        for _ in 0..trials {
            let e0: Vec<f64> = (0..n).map(|_| noise.sample(&mut rng)).collect();
            // the candidate's change: estimation noise, independent of e0
            let change: Vec<f64> = (0..n).map(|_| 0.3 * noise.sample(&mut rng)).collect();
            let before = scored(e0.clone());
            let after = scored(e0.iter().zip(&change).map(|(e, c)| e - c).collect());
            let (_, p) = nested_test(&before, &after, &[1.0], &group).unwrap();
            cw_null += usize::from(p < 0.05);
            let f: Vec<f64> = (0..n).map(|i| 2.0 * e0[i] * change[i]).collect();
            t_null += usize::from(grouped_t_test(&f, &group) < 0.05);
            let plain: Vec<f64> = (0..n).map(|i| before.q[i] - after.q[i]).collect();
            plain_null += usize::from(grouped_t_test(&plain, &group) < 0.05);
            // a real effect of size 0.3 in the data, the candidate has it
            let effect: Vec<f64> = (0..n).map(|i| 0.3 * (i as f64 * 0.37).sin()).collect();
            let e0: Vec<f64> = (0..n).map(|i| effect[i] + noise.sample(&mut rng)).collect();
            let after: Vec<f64> = (0..n).map(|i| e0[i] - effect[i]).collect();
            let (_, p) = nested_test(&scored(e0), &scored(after), &[1.0], &group).unwrap();
            cw_real += usize::from(p < 0.05);
        }
        let rate = |k: usize| k as f64 / trials as f64;
        assert!(
            (0.035..=0.065).contains(&rate(cw_null)),
            "Clark–West (signed ranks) under the null: {}",
            rate(cw_null)
        );
        assert!(
            (0.035..=0.065).contains(&rate(t_null)),
            "Clark–West (Student's t) under the null: {}",
            rate(t_null)
        );
        assert!(
            rate(plain_null) < 0.02,
            "plain difference under the null: {}",
            rate(plain_null)
        );
        assert!(
            rate(cw_real) > 0.5,
            "Clark–West on a real change: {}",
            rate(cw_real)
        );
    }
}
