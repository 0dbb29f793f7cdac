//! `stribeck`: a break-away level Fs above the sliding level Fc, decaying
//! with speed, g(v) = Fc + (Fs − Fc)·exp(−(v/vs)²). Fitted as the excess
//! Fs/Fc − 1 (> 0, the same for both directions) and vs.

use super::{with_neg, EffectSpec};
use crate::model::{Context, Free, FrictionModel};

pub struct Stribeck;

impl EffectSpec for Stribeck {
    fn name(&self) -> &'static str {
        "stribeck"
    }

    fn meaning(&self) -> &'static str {
        "break-away above the sliding level, decaying with speed"
    }

    /// Fs − Fc.
    fn change(&self, _nominal: &FrictionModel, m: &FrictionModel) -> Option<f64> {
        Some(m.fs - m.fc)
    }

    fn change_name(&self) -> Option<&'static str> {
        Some("Fs - Fc")
    }

    fn has(&self, m: &FrictionModel) -> bool {
        m.fs > m.fc * (1.0 + 1e-9)
    }

    fn resized(&self) -> bool {
        true
    }

    /// Fs just above Fc, vs a tenth of the data's RMS speed.
    fn start(&self, m: &mut FrictionModel, context: &Context) {
        m.fs = m.fc * 1.01;
        m.fs_neg = m.fc_neg * 1.01;
        m.vs = 0.1 * context.speed_scale;
    }

    /// A grid over vs and the excess (and, re-sized, its own values too).
    fn starts(
        &self,
        current: &FrictionModel,
        base: &FrictionModel,
        context: &Context,
    ) -> Vec<FrictionModel> {
        let mut s = if self.has(current) {
            vec![base.clone()]
        } else {
            Vec::new()
        };
        for vs in [0.03, 0.1, 0.3, 1.0] {
            for excess in [0.05, 0.2] {
                let mut m = base.clone();
                m.vs = vs * context.speed_scale;
                m.fs = m.fc * (1.0 + excess);
                m.fs_neg = m.fc_neg * (1.0 + excess);
                s.push(m);
            }
        }
        s
    }

    fn frees(&self) -> &'static [Free] {
        &[Free::StribeckExcess, Free::Vs]
    }

    /// The Stribeck ratios and vs of `before`, on the present levels.
    fn take_out(&self, m: &mut FrictionModel, before: &FrictionModel, _context: &Context) {
        m.fs = m.fc * before.fs / before.fc;
        m.fs_neg = m.fc_neg * before.fs_neg / before.fc_neg;
        m.vs = before.vs;
    }

    fn variables(&self, m: &FrictionModel) -> Vec<String> {
        let mut v = with_neg(m, "Fs", "Fs_neg");
        v.extend(super::names(&["Fc", "vs"]));
        v
    }

    fn parameters(&self, m: &FrictionModel) -> Vec<(String, f64, &'static str)> {
        let level = super::level_unit(m);
        vec![
            ("Fs".into(), m.fs, level),
            ("Fs_minus_Fc".into(), m.fs - m.fc, level),
            ("vs".into(), m.vs, "m/s"),
        ]
    }
}
