//! The position table's resolution. `position_dependent` is added on
//! [`crate::Options::position_knots`] knots spread evenly over the
//! travel; the friction along a real guide need not bend at those knots.
//! When the rounds end with a table in the model, it is offered twice as
//! many intervals ([`FrictionModel::with_finer_table`], 2k − 1 knots, the
//! coarser table exactly representable in the finer), refitted, and kept
//! when it passes the test that admitted the effect against the coarser
//! one (p below the same threshold, the same minimum gain, a drop beyond
//! the co-simulation's step error); repeated while the table has at most
//! `--max-position-knots` knots (at most the FMU's
//! [`crate::model::MAX_TABLE_POINTS`]). The effects accepted after the
//! table, beside the coarser one, are then examined again against the
//! finer (`reexamine`, in the rounds' module): one that the finer table
//! explains is taken out.
//!
//! Why: with a hidden 10 % position dependence on the Rig1D rig (seed 1
//! of the independent suite, the truth's five knots not among the six of
//! the table), the six-knot table left a held-out RMS of 30 times the
//! floor of noise and step error, structured along the travel; a
//! Stribeck curve re-sized beside it (vs up by 5 %) then gained 29 % of
//! the held-out mean square at p = 2e-6 and was named, an effect the
//! data did not hold. With 16 knots the same data left the table at 1.5
//! times the floor and named nothing else.
//!
//! Why at the end and not as soon as the table is accepted: a table can
//! be a stand-in (a viscous term differing by direction, on a record whose
//! fast plateaus lie at the ends of the travel, is first explained by a
//! table), and a finer stand-in explains more of the true effect. Made
//! finer at once, a 21-knot table took that record's held-out RMS to
//! 0.015, the viscous terms were never named, and the table stayed
//! (`host/tests/integration/diagnose_reexamine.rs`). At the end, a
//! stand-in table has already been taken out by the re-examination that
//! follows each round.

use super::Search;
use crate::acceptance::{drop_beyond_step_error, nested_test, Acceptance};
use crate::model::{Effect, FrictionModel};
use crate::stages::problem::Problem;
use crate::stages::refine::{polish_whole, refine_folds, Polishing};
use crate::system::System;
use crate::{fmu_values, TableStep};

/// When the rounds' model has a position table: the table made finer
/// while the data ask for it ([the module](self)); each finer table
/// tried is recorded on the effect ([`crate::FoundEffect::table`]), and a
/// kept one becomes the current model. Returns the index of the first
/// effect accepted after the table when a finer table was kept (those
/// after it are to be examined again), `None` otherwise.
pub(super) fn resolve_position_table(
    p: &Problem,
    system: &mut System,
    s: &mut Search,
    group: &[usize],
    polishing: &mut Polishing,
) -> Result<Option<usize>, String> {
    let Some(i) = s
        .effects
        .iter()
        .position(|e| e.name == Effect::PositionDependent)
    else {
        return Ok(None);
    };
    let mut kept_any = false;
    let done = |kept: bool| -> Result<Option<usize>, String> { Ok(kept.then_some(i + 1)) };
    let rule = Acceptance {
        threshold: s.effects[i].threshold,
        min_gain: p.options.min_gain,
    };
    let by_output_error = s.accepted_as[i].by_output_error;
    let itself = |m: &FrictionModel| vec![m.clone()];
    let added = [Effect::PositionDependent];
    loop {
        let max = p.options.max_position_knots;
        let finer: Option<Vec<FrictionModel>> =
            s.folds.iter().map(|m| m.with_finer_table(max)).collect();
        let (Some(finer), Some(finer_whole)) = (finer, s.current.with_finer_table(max)) else {
            return done(kept_any);
        };
        let knots = finer_whole.x_table.len();
        let what = || format!("the position table at {knots} knots");
        if p.budget.skip_if_expired(what) {
            return done(kept_any);
        }
        p.budget
            .progress()
            .stage(format!("the position table at {knots} knots"));
        let (fits, cut) = p.budget.cut_short(what, || {
            p.fit_folds_any(&itself, &finer, &added, by_output_error)
        });
        if cut {
            return done(kept_any);
        }
        let fits = fits?;
        let mut evaluations = fits.evaluations;
        // a finer table whose co-simulation fails is not kept
        let Ok(mut scored) = p.score(system, &fits.models) else {
            return done(kept_any);
        };
        let mut models = fits.models;
        // refined on the output error as the coarser table was when it
        // was accepted, so that the two compare as fitted alike
        if p.options.polish {
            let r = refine_folds(p, system, models, scored);
            polishing.cosimulations += r.evaluations;
            evaluations += r.evaluations;
            (models, scored) = (r.models, r.scored);
        }
        let (gain, p_value) = nested_test(&s.scored, &scored, &p.scales, group)?;
        let kept = rule.passes(gain, p_value)
            && drop_beyond_step_error(&s.scored, scored.rms(), s.step_error);
        s.effects[i].table.push(TableStep {
            knots,
            heldout_rms_before: s.scored.rms(),
            heldout_rms: scored.rms(),
            gain,
            p_value,
            fit_evaluations: evaluations,
            kept,
        });
        if !kept {
            return done(kept_any);
        }
        kept_any = true;
        let whole = p.fit_whole_any(&[finer_whole], &models, &added, by_output_error)?;
        let whole = if p.options.polish {
            polish_whole(p, whole, &models, polishing)
        } else {
            whole
        };
        let before = &s.accepted_as[i].before;
        let effect = &mut s.effects[i];
        effect.parameters = super::effect_parameters(&whole, Effect::PositionDependent);
        effect.variables = fmu_values(
            &p.setup.friction_fmu,
            &whole.effect_variables(Effect::PositionDependent),
            before,
            &whole,
        );
        // the held-out RMS after the round: the last effect accepted in it
        if let Some(last) = s.effects.last_mut() {
            last.rms_after = scored.rms();
        }
        s.current = whole;
        s.folds = models;
        s.fine = None;
        s.scored = scored;
    }
}

#[cfg(test)]
mod tests {
    use crate::model::{Context, Effect, FrictionModel, MAX_TABLE_POINTS};

    /// The finer table is the same function of the position in either
    /// direction (the coarser one exactly representable in it), on twice
    /// as many intervals, and none is offered past the limit.
    #[test]
    fn a_finer_table_leaves_the_model_unchanged() {
        let context = Context::encoder_for_tests();
        let mut m = FrictionModel::coulomb_for_tests(10.0, 1e8, 0.0)
            .with(Effect::PositionDependent, &context);
        m.direction_dependent = true;
        m.fc_neg = 9.0;
        m.scale_pos = vec![1.1, 0.9, 1.0, 1.3, 0.8, 1.05];
        m.scale_neg = vec![0.95, 1.2, 0.85, 1.0, 1.1, 0.9];
        let finer = m.with_finer_table(MAX_TABLE_POINTS).expect("11 knots fit");
        assert_eq!(finer.x_table.len(), 11);
        assert_eq!(finer.scale_neg.len(), 11);
        for i in 0..=400 {
            // beyond both ends too: the table holds its end values
            let x = -0.05 + 0.3 * f64::from(i) / 400.0;
            for positive in [true, false] {
                let (a, b) = (m.level(positive, x), finer.level(positive, x));
                assert!((a - b).abs() <= 1e-12 * a, "x = {x}: {a} != {b}");
            }
        }
        let finest = finer
            .with_finer_table(MAX_TABLE_POINTS)
            .expect("21 knots fit");
        assert_eq!(finest.x_table.len(), 21);
        assert!(
            finest.with_finer_table(MAX_TABLE_POINTS).is_none(),
            "41 > 32"
        );
        assert!(m.with_finer_table(10).is_none(), "11 > 10");
        let plain = FrictionModel::coulomb_for_tests(10.0, 1e8, 0.0);
        assert!(plain.with_finer_table(MAX_TABLE_POINTS).is_none());
    }
}
