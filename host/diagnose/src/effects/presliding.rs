//! `presliding`: a finite bristle stiffness σ0, ż = v − σ0·|v|·z/g(v):
//! elastic micro-displacement and hysteresis over the presliding distance
//! Fc/σ0 before gross sliding. Fitted as σ0, with σ1 following it at a
//! constant damping ratio ([`FrictionModel::with_sigma0`]).
//!
//! Its hysteresis lives in the stick, which the force fits leave out: an
//! addition with it is fitted by output error through co-simulation.
//! Whether a nominal has it is decided from the data: its presliding
//! distance against the position resolution the measurements show.

use super::{names, EffectSpec};
use crate::model::{Context, Free, FrictionModel, STIFF_PRESLIDING_DISTANCE};

pub struct Presliding;

impl EffectSpec for Presliding {
    fn name(&self) -> &'static str {
        "presliding"
    }

    fn meaning(&self) -> &'static str {
        "elastic micro-displacement and hysteresis before gross sliding (finite sigma0)"
    }

    fn force_shows(&self) -> bool {
        false
    }

    fn has(&self, m: &FrictionModel) -> bool {
        m.fc / m.sigma0 >= STIFF_PRESLIDING_DISTANCE
    }

    /// A presliding distance Fc/σ0 at least the position resolution of
    /// the measurements (finer, and it is a stiff contact for these data).
    fn shows(&self, m: &FrictionModel, context: &Context) -> bool {
        m.presliding_distance() >= context.position_resolution
    }

    fn resized(&self) -> bool {
        true
    }

    /// σ0 giving a presliding distance of a thousandth of the travel.
    fn start(&self, m: &mut FrictionModel, context: &Context) {
        *m = m.with_sigma0(m.fc / (1e-3 * context.travel));
    }

    /// Presliding distances Fc/σ0 from half the position resolution the
    /// data show to 3 % of the travel, and the model's own (σ1 following
    /// σ0, [`FrictionModel::with_sigma0`]).
    fn starts(
        &self,
        _current: &FrictionModel,
        base: &FrictionModel,
        context: &Context,
    ) -> Vec<FrictionModel> {
        let r = context.position_resolution;
        let mut s = vec![base.clone()];
        for d in [0.5 * r, 2.0 * r, 8.0 * r, 32.0 * r, 128.0 * r, 512.0 * r]
            .into_iter()
            .chain([1e-2 * context.travel, 3e-2 * context.travel])
        {
            s.push(base.with_sigma0(base.fc / d));
        }
        s
    }

    fn frees(&self) -> &'static [Free] {
        &[Free::Sigma0]
    }

    fn take_out(&self, m: &mut FrictionModel, before: &FrictionModel, _context: &Context) {
        m.sigma0 = before.sigma0;
        m.sigma1 = before.sigma1;
    }

    fn variables(&self, _m: &FrictionModel) -> Vec<String> {
        names(&["sigma0", "sigma1"])
    }

    fn parameters(&self, m: &FrictionModel) -> Vec<(String, f64, &'static str)> {
        vec![
            ("sigma0".into(), m.sigma0, "N/m"),
            ("sigma1".into(), m.sigma1, "N.s/m"),
            ("presliding_distance".into(), m.fc / m.sigma0, "m"),
        ]
    }

    /// A change of the presliding distance Fc/σ0 that moves the mass by
    /// less than [`PRESLIDING_RESOLVED`] encoder steps: at a reversal the
    /// force on the contact swings from −Fc to +Fc through the bristles,
    /// which carry the mass 2·Fc/σ0 before it slides, so two contacts
    /// whose presliding distances differ by Δ hold it 2·Δ apart at the end
    /// of that stick. A smaller difference is one the encoder does not
    /// register as a displacement, and a better score can only come from
    /// something else the change of σ0 happens to offset (the
    /// co-simulation's step error in the stick, a missing level or
    /// Stribeck term), not from presliding.
    fn unresolved(
        &self,
        current: &FrictionModel,
        candidate: &FrictionModel,
        context: &Context,
    ) -> Option<String> {
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
}

/// A change of the presliding displacement at a reversal below this many
/// encoder steps is not resolved by the data ([`EffectSpec::unresolved`]).
pub const PRESLIDING_RESOLVED: f64 = 1.0;

/// The presliding displacement at a reversal, in presliding distances
/// Fc/σ0: the bristles go from −Fc/σ0 to +Fc/σ0 ([`EffectSpec::unresolved`]).
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
        let context = Context::encoder_for_tests();
        let resolved = |before: f64, after: f64| {
            let (b, a) = (
                nominal.with_sigma0(10.0 / before),
                nominal.with_sigma0(10.0 / after),
            );
            Presliding.unresolved(&b, &a, &context).is_none()
        };
        // 0.1 µm -> 0.8 µm: 1.4 µm more at each reversal
        assert!(resolved(1e-7, 8e-7));
        // stiffened from 0.47 µm to nothing: 0.94 µm
        assert!(!resolved(4.7e-7, 1e-9));
        // both soft, re-sized by 0.3 µm: 0.6 µm
        assert!(!resolved(5e-6, 5.3e-6));
        assert!(resolved(5e-6, 6e-6));
    }
}
