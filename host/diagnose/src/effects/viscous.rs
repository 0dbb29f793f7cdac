//! `viscous`: friction growing with speed, σ2·v.

use super::{names, EffectSpec};
use crate::model::{Context, Free, FrictionModel};

pub struct Viscous;

impl EffectSpec for Viscous {
    fn name(&self) -> &'static str {
        "viscous"
    }

    fn meaning(&self) -> &'static str {
        "friction growing with speed (sigma2*v)"
    }

    /// σ2 − its `nominal` value.
    fn change(&self, nominal: &FrictionModel, m: &FrictionModel) -> Option<f64> {
        Some(m.sigma2 - nominal.sigma2)
    }

    fn change_name(&self) -> Option<&'static str> {
        Some("sigma2 - nominal sigma2")
    }

    fn has(&self, m: &FrictionModel) -> bool {
        m.sigma2 > 0.0
    }

    fn resized(&self) -> bool {
        true
    }

    /// σ2 small: a thousandth of Fc at the data's RMS speed.
    fn start(&self, m: &mut FrictionModel, context: &Context) {
        m.sigma2 = 1e-3 * m.fc / context.speed_scale;
    }

    /// The neutral start, and σ2 raised by r = 1 %, 3 %, 10 % and 30 % of
    /// Fc at the RMS speed, each also with the levels lowered by r: a
    /// level refitted without the viscous term rises to stand in for it
    /// (Fc + σ2·v at the data's speeds), and a start that keeps that level
    /// begins on the wrong side of a narrow valley. Output-error fits,
    /// which take only a few iterations from the best start, needed
    /// it: on the open-loop two-mass drive with a hidden 5 % viscous term
    /// (seed 3), the baseline raised Fc by 5.8 %, the best of the old
    /// starts (r = 1 %, 10 %, levels kept) reached σ2 = 0.0035 against a
    /// truth of 0.11, and a position table was named instead.
    fn starts(
        &self,
        _current: &FrictionModel,
        base: &FrictionModel,
        context: &Context,
    ) -> Vec<FrictionModel> {
        let mut s = vec![base.clone()];
        for r in [0.01, 0.03, 0.1, 0.3] {
            let sigma2 = base.sigma2 + r * base.fc / context.speed_scale;
            for levels in [1.0, 1.0 - r] {
                let mut m = base.scaled_levels(levels);
                m.sigma2 = sigma2;
                s.push(m);
            }
        }
        s
    }

    fn frees(&self) -> &'static [Free] {
        &[Free::Sigma2]
    }

    /// Not under direction-dependent viscous friction, which splits it.
    fn can_take_out(&self, m: &FrictionModel) -> bool {
        !m.direction_dependent_viscous
    }

    fn take_out(&self, m: &mut FrictionModel, before: &FrictionModel, _context: &Context) {
        m.sigma2 = before.sigma2;
        m.sigma2_neg = before.sigma2_neg;
    }

    fn variables(&self, _m: &FrictionModel) -> Vec<String> {
        names(&["sigma2"])
    }

    fn parameters(&self, m: &FrictionModel) -> Vec<(String, f64, &'static str)> {
        vec![("sigma2".into(), m.sigma2, "N.s/m")]
    }
}
