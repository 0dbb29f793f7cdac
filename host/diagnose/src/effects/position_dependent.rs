//! `position_dependent`: the levels times a piecewise-linear scale of the
//! position x, on [`Context::position_knots`] knots spread over the
//! travel. Fitted as the scales at the knots, which then carry the levels
//! (a common factor of Fc and the scales could not be told apart).

use super::{level_unit, with_neg, EffectSpec};
use crate::model::{Context, FrictionModel};

pub struct PositionDependent;

impl EffectSpec for PositionDependent {
    fn name(&self) -> &'static str {
        "position_dependent"
    }

    fn meaning(&self) -> &'static str {
        "friction levels varying along the travel"
    }

    /// Only where the data have some travel.
    fn shown_by_data(&self, _normal_force_measured: bool, context: &Context) -> bool {
        context.travel > 1e-9
    }

    fn switch(&self) -> Option<&'static str> {
        Some("position_dependent")
    }

    fn has(&self, m: &FrictionModel) -> bool {
        m.position_dependent
    }

    /// Unit scales on knots spread evenly over the travel.
    fn start(&self, m: &mut FrictionModel, context: &Context) {
        let k = context.position_knots.max(2);
        m.position_dependent = true;
        m.x_table = (0..k)
            .map(|i| context.x_min + (context.x_max - context.x_min) * i as f64 / (k - 1) as f64)
            .collect();
        m.scale_pos = vec![1.0; k];
        m.scale_neg = vec![1.0; k];
    }

    /// The levels take the table's mean scale.
    fn take_out(&self, m: &mut FrictionModel, _before: &FrictionModel, _context: &Context) {
        let mean = |s: &[f64]| s.iter().sum::<f64>() / s.len().max(1) as f64;
        let (pos, neg) = (mean(&m.scale_pos), mean(&m.scale_neg));
        m.fc *= pos;
        m.fs *= pos;
        m.fc_neg *= neg;
        m.fs_neg *= neg;
        m.position_dependent = false;
        m.x_table.clear();
        m.scale_pos.clear();
        m.scale_neg.clear();
    }

    fn variables(&self, m: &FrictionModel) -> Vec<String> {
        let mut v = with_neg(m, "Fc", "Fc_neg");
        for i in 1..=m.x_table.len() {
            v.push(format!("x_table[{i}]"));
            v.push(format!("scale_pos[{i}]"));
            if m.direction_dependent {
                v.push(format!("scale_neg[{i}]"));
            }
        }
        v
    }

    fn parameters(&self, m: &FrictionModel) -> Vec<(String, f64, &'static str)> {
        let level = level_unit(m);
        let mut v = Vec::new();
        for i in 0..m.x_table.len() {
            v.push((format!("x_table[{}]", i + 1), m.x_table[i], "m"));
            v.push((
                format!("Fc_pos_at[{}]", i + 1),
                m.fc * m.scale_pos[i],
                level,
            ));
            if m.direction_dependent {
                v.push((
                    format!("Fc_neg_at[{}]", i + 1),
                    m.fc_neg * m.scale_neg[i],
                    level,
                ));
            }
        }
        v
    }
}
