//! Whether the data resolve a candidate's change: a presliding distance
//! re-sized by less than the encoder registers, or a re-sized effect whose
//! own parameters hardly moved, is not named whatever its score.

use crate::model::{Context, Effect, FrictionModel};

/// A presliding candidate whose change of the presliding distance Fc/σ0
/// moves the mass by less than [`PRESLIDING_RESOLVED`] encoder steps: at
/// a reversal the force on the contact swings from −Fc to +Fc through the
/// bristles, which carry the mass 2·Fc/σ0 before it slides, so two
/// contacts whose presliding distances differ by Δ hold it 2·Δ apart at
/// the end of that stick. A smaller difference is one the encoder does
/// not register as a displacement, and a better score can only come from
/// something else the change of σ0 happens to offset (the co-simulation's
/// step error in the stick, a missing level or Stribeck term), not from
/// presliding. Returns the reason, or `None` when the change is resolved.
pub(super) fn unresolved_presliding(
    added: &[Effect],
    current: &FrictionModel,
    candidate: &FrictionModel,
    context: &Context,
) -> Option<String> {
    if !added.contains(&Effect::Presliding) {
        return None;
    }
    let (before, after) = (
        current.presliding_distance(),
        candidate.presliding_distance(),
    );
    let swing = PRESLIDING_SWING * (after - before).abs();
    (swing < PRESLIDING_RESOLVED * context.position_step).then(|| {
        format!(
            "presliding distance {before:.3e} m -> {after:.3e} m: the mass moves {swing:.3e} m differently at a reversal, below {PRESLIDING_RESOLVED} x the encoder step of the data ({:.3e} m): not resolved",
            context.position_step
        )
    })
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

/// A change of the presliding displacement at a reversal below this many
/// encoder steps is not resolved by the data (`unresolved_presliding`).
pub const PRESLIDING_RESOLVED: f64 = 1.0;

/// The presliding displacement at a reversal, in presliding distances
/// Fc/σ0: the bristles go from −Fc/σ0 to +Fc/σ0 (`unresolved_presliding`).
pub const PRESLIDING_SWING: f64 = 2.0;

#[cfg(test)]
mod tests {
    use super::*;

    /// Presliding is resolved when the re-sized contact moves the mass at a
    /// reversal by at least one encoder step, whatever the noise.
    #[test]
    fn presliding_is_resolved_by_its_displacement_at_a_reversal() {
        let values = [
            ("Fc", 10.0),
            ("Fs", 10.0),
            ("vs", 0.01),
            ("sigma0", 1e8),
            ("sigma1", 0.0),
            ("sigma2", 0.0),
            ("stribeck_exponent", 2.0),
            ("Fc_neg", 10.0),
            ("Fs_neg", 10.0),
            ("direction_dependent", 0.0),
            ("normal_force_form", 0.0),
            ("position_dependent", 0.0),
        ];
        let nominal = FrictionModel::from_values(
            &values
                .iter()
                .map(|(k, v)| (k.to_string(), *v))
                .collect::<std::collections::BTreeMap<_, _>>(),
        )
        .unwrap();
        // a 1 µm encoder with 1.2 µm of noise
        let context = Context {
            speed_scale: 0.1,
            x_min: 0.0,
            x_max: 0.2,
            travel: 0.2,
            mean_normal_force: 100.0,
            position_knots: 6,
            position_resolution: 2.4e-6,
            position_step: 1e-6,
        };
        let resolved = |before: f64, after: f64| {
            let (b, a) = (
                nominal.with_sigma0(10.0 / before),
                nominal.with_sigma0(10.0 / after),
            );
            unresolved_presliding(&[Effect::Presliding], &b, &a, &context).is_none()
        };
        // 0.1 µm -> 0.8 µm: 1.4 µm more at each reversal
        assert!(resolved(1e-7, 8e-7));
        // stiffened from 0.47 µm to nothing: 0.94 µm
        assert!(!resolved(4.7e-7, 1e-9));
        // both soft, re-sized by 0.3 µm: 0.6 µm
        assert!(!resolved(5e-6, 5.3e-6));
        assert!(resolved(5e-6, 6e-6));
        // not presliding: nothing to judge
        assert!(unresolved_presliding(&[Effect::Viscous], &nominal, &nominal, &context).is_none());
    }
}
