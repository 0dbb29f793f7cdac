//! `offset`: a constant force F_offset on the contact, at rest as in
//! motion. Fitted linearly (either sign) in units of the model's Fc. In
//! steady sliding it is one of the [`Effect::ASYMMETRY`] family.
//!
//! [`Effect::ASYMMETRY`]: super::Effect::ASYMMETRY

use super::{names, EffectSpec};
use crate::model::{Context, Free, FrictionModel};

pub struct Offset;

impl EffectSpec for Offset {
    fn name(&self) -> &'static str {
        "offset"
    }

    fn meaning(&self) -> &'static str {
        "a constant force on the contact, at rest as in motion (F_offset)"
    }

    /// F_offset.
    fn change(&self, _nominal: &FrictionModel, m: &FrictionModel) -> Option<f64> {
        Some(m.f_offset)
    }

    fn change_name(&self) -> Option<&'static str> {
        Some("F_offset")
    }

    fn has(&self, m: &FrictionModel) -> bool {
        m.f_offset != 0.0
    }

    /// No offset: the fit finds its sign.
    fn start(&self, m: &mut FrictionModel, _context: &Context) {
        m.f_offset = 0.0;
    }

    fn frees(&self) -> &'static [Free] {
        &[Free::Offset]
    }

    fn take_out(&self, m: &mut FrictionModel, before: &FrictionModel, _context: &Context) {
        m.f_offset = before.f_offset;
    }

    fn variables(&self, _m: &FrictionModel) -> Vec<String> {
        names(&["F_offset"])
    }

    fn parameters(&self, m: &FrictionModel) -> Vec<(String, f64, &'static str)> {
        vec![("F_offset".into(), m.f_offset, "N")]
    }
}
