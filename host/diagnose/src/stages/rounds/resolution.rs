//! Whether the data resolve a candidate's change: a change an effect
//! says the data do not resolve (a presliding distance re-sized by less
//! than the encoder registers, `effects/presliding.rs`), or a re-sized
//! effect whose own parameters hardly moved, is not named whatever its
//! score.

use crate::model::{Context, Effect, FrictionModel};

/// The first added effect whose change from `current` to `candidate`
/// the data do not resolve ([`EffectSpec::unresolved`]: presliding's
/// change of the presliding distance below an encoder step), and why, or
/// `None` when every change is resolved.
///
/// [`EffectSpec::unresolved`]: crate::effects::EffectSpec::unresolved
pub(super) fn unresolved_change(
    added: &[Effect],
    current: &FrictionModel,
    candidate: &FrictionModel,
    context: &Context,
) -> Option<String> {
    added
        .iter()
        .find_map(|e| e.spec().unresolved(current, candidate, context))
}

/// A re-sized effect (one the current model has already) whose own
/// parameters all moved by less than [`RESIZE_MIN_CHANGE`] (relative) in
/// the candidate: its gain came from the levels refitted with it, not from
/// the effect, which is then not named. Returns the reason.
pub(super) fn unmoved_resize(
    added: &[Effect],
    current: &FrictionModel,
    candidate: &FrictionModel,
    context: &Context,
) -> Option<String> {
    let [effect] = added else { return None };
    if !current.shows(*effect, context) || !current.can_try(*effect) {
        return None;
    }
    let before = current.effect_parameters(*effect);
    let after = candidate.effect_parameters(*effect);
    let moved = before.iter().zip(&after).any(|((_, a, _), (_, b, _))| {
        (b - a).abs() > RESIZE_MIN_CHANGE * a.abs().max(f64::MIN_POSITIVE)
    });
    (!moved).then(|| {
        format!(
            "re-sized by less than {:.0} %: the gain comes from the levels refitted with it",
            100.0 * RESIZE_MIN_CHANGE
        )
    })
}

/// See `unmoved_resize`.
pub const RESIZE_MIN_CHANGE: f64 = 0.05;

#[cfg(test)]
mod tests {
    use super::*;

    /// Only an effect that has a resolution of its own judges it
    /// (presliding's test is in `effects/presliding.rs`).
    #[test]
    fn an_effect_without_a_resolution_is_always_resolved() {
        let nominal = FrictionModel::coulomb_for_tests(10.0, 1e8, 0.0);
        let context = Context::encoder_for_tests();
        assert!(unresolved_change(&[Effect::Viscous], &nominal, &nominal, &context).is_none());
        assert!(unresolved_change(&[Effect::Presliding], &nominal, &nominal, &context).is_some());
    }
}
