//! `normal_load`: the normal-force form, friction proportional to the
//! measured input Fn (every level and coefficient per newton of it).
//! Fitted through the levels, per newton.

use super::{with_neg, EffectSpec};
use crate::model::{Context, FrictionModel};

pub struct NormalLoad;

impl EffectSpec for NormalLoad {
    fn name(&self) -> &'static str {
        "normal_load"
    }

    fn meaning(&self) -> &'static str {
        "friction levels proportional to the measured normal force"
    }

    /// Only with a measured normal force.
    fn shown_by_data(&self, normal_force_measured: bool, _context: &Context) -> bool {
        normal_force_measured
    }

    fn switch(&self) -> Option<&'static str> {
        Some("normal_force_form")
    }

    fn has(&self, m: &FrictionModel) -> bool {
        m.normal_force_form
    }

    /// The same force at the mean normal force of the data.
    fn start(&self, m: &mut FrictionModel, context: &Context) {
        *m = m.per_newton(context.mean_normal_force);
    }

    /// Back to newtons at the mean normal force.
    fn take_out(&self, m: &mut FrictionModel, _before: &FrictionModel, context: &Context) {
        let n = context.mean_normal_force;
        *m = m.per_newton(1.0 / n);
        m.normal_force_form = false;
    }

    fn variables(&self, m: &FrictionModel) -> Vec<String> {
        with_neg(m, "Fc", "Fc_neg")
    }

    fn parameters(&self, m: &FrictionModel) -> Vec<(String, f64, &'static str)> {
        vec![
            ("Fc_per_N".into(), m.fc, "N/N"),
            ("Fc_neg_per_N".into(), m.fc_neg, "N/N"),
        ]
    }
}
