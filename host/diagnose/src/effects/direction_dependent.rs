//! `direction_dependent`: the levels Fc_neg, Fs_neg (and the position
//! table's scale_neg) for v < 0. Fitted as Fc_neg (or the negative
//! scales), among the levels. One of the [`Effect::ASYMMETRY`] family.
//!
//! [`Effect::ASYMMETRY`]: super::Effect::ASYMMETRY

use super::{level_unit, names, EffectSpec};
use crate::model::{Context, FrictionModel};

pub struct DirectionDependent;

impl EffectSpec for DirectionDependent {
    fn name(&self) -> &'static str {
        "direction_dependent"
    }

    fn meaning(&self) -> &'static str {
        "different friction levels for the two directions"
    }

    /// Fc_neg − Fc.
    fn change(&self, _nominal: &FrictionModel, m: &FrictionModel) -> Option<f64> {
        Some(m.fc_neg - m.fc)
    }

    fn change_name(&self) -> Option<&'static str> {
        Some("Fc_neg - Fc")
    }

    fn switch(&self) -> Option<&'static str> {
        Some("direction_dependent")
    }

    fn has(&self, m: &FrictionModel) -> bool {
        m.direction_dependent
    }

    /// Equal levels for both directions.
    fn start(&self, m: &mut FrictionModel, _context: &Context) {
        m.direction_dependent = true;
        m.fc_neg = m.fc;
        m.fs_neg = m.fs;
        m.scale_neg = m.scale_pos.clone();
    }

    fn take_out(&self, m: &mut FrictionModel, _before: &FrictionModel, _context: &Context) {
        m.direction_dependent = false;
        m.fc_neg = m.fc;
        m.fs_neg = m.fs;
        m.scale_neg = m.scale_pos.clone();
    }

    fn variables(&self, _m: &FrictionModel) -> Vec<String> {
        names(&["Fc", "Fc_neg", "Fs", "Fs_neg"])
    }

    fn parameters(&self, m: &FrictionModel) -> Vec<(String, f64, &'static str)> {
        let level = level_unit(m);
        vec![
            ("Fc".into(), m.fc, level),
            ("Fc_neg".into(), m.fc_neg, level),
            ("Fc_neg_minus_Fc".into(), m.fc_neg - m.fc, level),
        ]
    }
}
