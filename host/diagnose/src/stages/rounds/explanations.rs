//! One signature, several explanations: the hypotheses a round tests
//! (a family of explanations counts once, [`Effect::ASYMMETRY`]), which
//! member of a family the data prefer, how strongly they separate the
//! accepted one from the others ([`Alternative`]), and the check of two
//! overlapping effects fitted together ([`OverlapCheck`],
//! [`Effect::OVERLAPPING`]).

use super::{label, try_additions, Tried};
use crate::acceptance::{nested_test, separation_test, Acceptance, Scored};
use crate::model::Effect;
use crate::stages::problem::Problem;
use crate::{Alternative, CandidateScore, OverlapCheck};

/// The number of hypotheses a round of `additions` tests, for its
/// Bonferroni threshold: one per addition, except that the single
/// additions of one family ([`Effect::ASYMMETRY`]) test one hypothesis
/// together (the friction differs between the directions); which of them
/// explains it is decided among them afterwards ([`prefer_in_family`]).
pub(super) fn hypotheses(additions: &[Vec<Effect>]) -> usize {
    let mut families = Vec::new();
    let mut n = 0;
    for added in additions {
        match added[..] {
            [e] => match e.family() {
                // a family is known by its first member
                Some(f) if families.contains(&f[0]) => {}
                Some(f) => {
                    families.push(f[0]);
                    n += 1;
                }
                None => n += 1,
            },
            _ => n += 1,
        }
    }
    n.max(1)
}

/// Whether the held-out data separate `better` from `other`, and the
/// p-value: the one-sided [`separation_test`] below `threshold`, and
/// held-out mean squares that differ by more than the co-simulation's
/// step error squared (a smaller difference these data cannot tell from
/// the integration's error, as [`super::rank_passing`] holds for any two
/// candidates). On a two-mass drive with a 5 % direction dependence
/// hidden, an offset (held-out RMS 0.00176) was separated from the
/// levels by direction (0.00222) at p = 0.0018, below the round's 0.002,
/// though both were below the step error of 0.0038 and the difference
/// of their mean squares was 13 % of its square.
fn separated(
    better: &Scored,
    other: &Scored,
    group: &[usize],
    threshold: f64,
    step_error: f64,
) -> Result<(bool, f64), String> {
    let p_value = separation_test(better, other, group)?;
    let beyond_step_error = other.rms().powi(2) - better.rms().powi(2) > step_error.powi(2);
    Ok((p_value < threshold && beyond_step_error, p_value))
}

/// Among the passing candidates (best first), when the best is a single
/// effect of a family ([`Effect::ASYMMETRY`]): the family members that
/// passed and that the held-out data do not separate from the best
/// ([`separated`]) are equally good explanations of
/// its signature; the first of them in the family's order is moved to the
/// front (direction-dependent levels before an offset before
/// direction-dependent viscous friction). A member the data separate
/// from the others keeps its place.
pub(super) fn prefer_in_family(
    passing: &mut Vec<usize>,
    tried: &[Tried],
    group: &[usize],
    threshold: f64,
    step_error: f64,
) -> Result<(), String> {
    let Some(&best) = passing.first() else {
        return Ok(());
    };
    let (Some(family), Ok(best_scored)) = (single_family(&tried[best]), &tried[best].scored) else {
        return Ok(());
    };
    let rank = |k: usize| family.iter().position(|e| *e == tried[k].added[0]);
    let mut equally_good = Vec::new();
    for &k in passing.iter() {
        if single_family(&tried[k]) != Some(family) {
            continue;
        }
        let unseparated = k == best
            || match &tried[k].scored {
                Ok(s) => !separated(best_scored, s, group, threshold, step_error)?.0,
                Err(_) => false,
            };
        if unseparated {
            equally_good.push(k);
        }
    }
    if let Some(preferred) = equally_good.into_iter().min_by_key(|&k| rank(k)) {
        passing.retain(|&k| k != preferred);
        passing.insert(0, preferred);
    }
    Ok(())
}

/// The family of `t`'s addition when it is one effect of a family.
fn single_family(t: &Tried) -> Option<&'static [Effect]> {
    match t.added[..] {
        [e] => e.family(),
        _ => None,
    }
}

/// The other members of the accepted candidate `k`'s family tried in the
/// same round, each with how strongly the held-out data separate it from
/// `k` ([`Alternative`]).
pub(super) fn family_alternatives(
    k: usize,
    tried: &[Tried],
    round: &[CandidateScore],
    group: &[usize],
    rule: Acceptance,
    step_error: f64,
) -> Result<Vec<Alternative>, String> {
    let (Some(family), Ok(chosen)) = (single_family(&tried[k]), &tried[k].scored) else {
        return Ok(Vec::new());
    };
    (0..tried.len())
        .filter(|&j| j != k && single_family(&tried[j]) == Some(family))
        .map(|j| {
            let (separated, p_value) = match &tried[j].scored {
                Ok(s) => separated(chosen, s, group, rule.threshold, step_error)?,
                Err(_) => (true, 0.0),
            };
            let c = &round[j];
            Ok(Alternative {
                name: c.name.clone(),
                heldout_rms: c.heldout_rms,
                p_value,
                passed: c.passes(rule),
                separated,
            })
        })
        .collect()
}

/// Fit the effects of candidates `k` and `j` together, by output error,
/// from each one's fitted model (in parallel; the fit with the smaller
/// fit error is the joint model), and test the joint model against
/// each alone on the held-out data ([`OverlapCheck`]): what `k`'s effect
/// adds to `j`'s, and `j`'s to `k`'s. Both candidates are output-error
/// fits here ([`refit_overlapping_by_output_error`]), so the joint model
/// is compared with fits of its own kind. A joint fit whose co-simulation
/// fails counts as adding nothing.
pub(super) fn overlap_check(
    p: &Problem,
    tried: &[Tried],
    k: usize,
    j: usize,
    group: &[usize],
) -> Result<OverlapCheck, String> {
    let after = |base: usize, added: &[Effect]| {
        try_additions(p, &tried[base].models, &[added.to_vec()], true)
    };
    let (from_k, from_j) = rayon::join(|| after(k, &tried[j].added), || after(j, &tried[k].added));
    let joint = from_k?
        .into_iter()
        .chain(from_j?)
        .filter(|t| t.scored.is_ok())
        .min_by(|a, b| a.force_rms.total_cmp(&b.force_rms));
    let adds_to = |single: usize| match (&tried[single].scored, joint.as_ref().map(|t| &t.scored)) {
        (Ok(before), Some(Ok(after))) => nested_test(before, after, &p.scales, group),
        _ => Ok((f64::NEG_INFINITY, 1.0)),
    };
    let ((gain_after_other, p_after_other), (other_gain_after, other_p_after)) =
        (adds_to(j)?, adds_to(k)?);
    let p_separated = match (&tried[k].scored, &tried[j].scored) {
        (Ok(better), Ok(other)) => separation_test(better, other, group)?,
        _ => 1.0,
    };
    Ok(OverlapCheck {
        other: label(&tried[j].added),
        gain_after_other,
        p_after_other,
        other_gain_after,
        other_p_after,
        p_separated,
        encompasses: false,
    })
}

#[cfg(test)]
mod tests {
    use crate::acceptance::Acceptance;
    use crate::OverlapCheck;

    /// An overlap check with the figures of a report's note.
    fn check(p_separated: f64, adds: (f64, f64), other_adds: (f64, f64)) -> OverlapCheck {
        OverlapCheck {
            other: "stribeck".into(),
            gain_after_other: adds.0,
            p_after_other: adds.1,
            other_gain_after: other_adds.0,
            other_p_after: other_adds.1,
            p_separated,
            encompasses: false,
        }
    }

    const RULE: Acceptance = Acceptance {
        threshold: 2e-3,
        min_gain: 0.02,
    };

    #[test]
    fn separated_alone_is_preferred_without_encompassing() {
        let mut c = check(1e-4, (0.3, 1e-5), (0.2, 1e-5));
        assert!(c.prefers_this(RULE));
        assert!(!c.encompasses);
    }

    /// The open-loop two-mass drive with a stiffer contact hidden under a
    /// soft nominal (seed 1): presliding and Stribeck not separated alone
    /// (p = 3.6e-3), presliding adding 78.1 % to Stribeck (p = 4.1e-5),
    /// Stribeck 19.5 % to presliding (p = 0.14): presliding encompasses it.
    #[test]
    fn one_that_adds_to_the_other_and_takes_nothing_encompasses_it() {
        let mut c = check(3.6e-3, (0.781, 4.1e-5), (0.195, 0.14));
        assert!(c.prefers_this(RULE));
        assert!(c.encompasses);
    }

    /// Each adding to the other (a GMS truth, seed 3 of the pre-sliding
    /// suite: 49.3 % at p = 2.4e-5 and 67.9 % at p = 9.5e-7; a coarse
    /// record with a Stribeck curve hidden, seed 7: 26.8 % at p = 4e-4
    /// and 6.1 % at p = 0.015, above the round's threshold but below
    /// NO_EVIDENCE_LEVEL), or neither (a clean coarse record): undecided.
    #[test]
    fn both_or_neither_adding_is_undecided() {
        for mut c in [
            check(0.1, (0.493, 2.4e-5), (0.679, 9.5e-7)),
            check(0.062, (0.268, 4.3e-4), (0.061, 0.015)),
            check(0.68, (0.0, 0.23), (0.0, 0.84)),
            // significant but below the minimum gain does not count as adding
            check(0.1, (0.01, 1e-6), (0.0, 0.5)),
        ] {
            assert!(!c.prefers_this(RULE), "{c:?}");
            assert!(!c.encompasses);
        }
    }

    /// Two explanations whose errors differ at every sample, by a sure
    /// sign: separated when their mean squares are further apart than the
    /// step error squared, not when the step error could make the
    /// difference.
    #[test]
    fn a_difference_within_the_step_error_does_not_separate() {
        let n = 400;
        // one group per 20 samples
        let group: Vec<usize> = (0..n).map(|i| i / 20).collect();
        let better = crate::acceptance::tests::scored(vec![1.0e-3; n]);
        let other = crate::acceptance::tests::scored(vec![1.3e-3; n]);
        // mean squares 1.0e-6 and 1.69e-6: 0.69e-6 apart
        let (apart, p) = super::separated(&better, &other, &group, RULE.threshold, 5e-4).unwrap();
        assert!(p < 1e-5, "{p}");
        assert!(apart);
        let (apart, p_within) =
            super::separated(&better, &other, &group, RULE.threshold, 1e-3).unwrap();
        assert_eq!(p_within, p);
        assert!(!apart);
        // the other way round: never separated
        assert!(
            !super::separated(&other, &better, &group, RULE.threshold, 0.0)
                .unwrap()
                .0
        );
    }
}
