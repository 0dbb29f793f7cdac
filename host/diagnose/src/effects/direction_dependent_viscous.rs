//! `direction_dependent_viscous`: sigma2_neg instead of σ2 for v < 0.
//! Tried only on a model with viscous friction to split; frees both
//! coefficients. One of the [`Effect::ASYMMETRY`] family.
//!
//! [`Effect::ASYMMETRY`]: super::Effect::ASYMMETRY

use super::{names, Effect, EffectSpec};
use crate::model::{Context, Free, FrictionModel};

pub struct DirectionDependentViscous;

impl EffectSpec for DirectionDependentViscous {
    fn name(&self) -> &'static str {
        "direction_dependent_viscous"
    }

    fn meaning(&self) -> &'static str {
        "different viscous friction for the two directions (sigma2_neg for v < 0)"
    }

    /// sigma2_neg − sigma2.
    fn change(&self, _nominal: &FrictionModel, m: &FrictionModel) -> Option<f64> {
        Some(m.sigma2_neg - m.sigma2)
    }

    fn change_name(&self) -> Option<&'static str> {
        Some("sigma2_neg - sigma2")
    }

    fn switch(&self) -> Option<&'static str> {
        Some("direction_dependent_viscous")
    }

    fn has(&self, m: &FrictionModel) -> bool {
        m.direction_dependent_viscous
    }

    /// A viscous term to split by direction: without one, the candidate
    /// would be viscous friction and its asymmetry at once, and win over
    /// viscous alone for the viscous part.
    fn can_try(&self, m: &FrictionModel) -> bool {
        m.has(Effect::Viscous) && !self.has(m)
    }

    /// sigma2_neg = σ2.
    fn start(&self, m: &mut FrictionModel, _context: &Context) {
        m.direction_dependent_viscous = true;
        m.sigma2_neg = m.sigma2;
    }

    fn frees(&self) -> &'static [Free] {
        &[Free::Sigma2, Free::Sigma2Neg]
    }

    fn take_out(&self, m: &mut FrictionModel, _before: &FrictionModel, _context: &Context) {
        m.direction_dependent_viscous = false;
        m.sigma2_neg = m.sigma2;
    }

    fn variables(&self, _m: &FrictionModel) -> Vec<String> {
        names(&["direction_dependent_viscous", "sigma2", "sigma2_neg"])
    }

    fn parameters(&self, m: &FrictionModel) -> Vec<(String, f64, &'static str)> {
        let unit = if m.normal_force_form { "s/m" } else { "N.s/m" };
        vec![
            ("sigma2".into(), m.sigma2, unit),
            ("sigma2_neg".into(), m.sigma2_neg, unit),
            (
                "sigma2_neg_minus_sigma2".into(),
                m.sigma2_neg - m.sigma2,
                unit,
            ),
        ]
    }
}
