//! Stick/slip switches located inside a Co-Simulation step, for FMI 3.0's
//! intermediate update and early return (FMI 3.0 section 4.2.2).
//!
//! A switch is where a discrete output of the law changes: LuGre's
//! `sliding`, Classical's `stuck`, the element laws' `n_slipping`, … (the
//! Integer and Boolean outputs of the variable table). The step itself is
//! the model's ordinary one, from `t` to `t + h`; only if a discrete output
//! differs at its end from its start are the switches looked for, by
//! bisection of sub-steps `[t, t + τ]` replayed from the state before the
//! step on a copy of the model. The laws' steps are exact (or
//! error-controlled) for any length, so the sub-step to `τ` is the step's
//! own trajectory up to `τ`, and each switch is found to [`RESOLUTION`] of
//! the step.
//!
//! Each switch is reported, in order, to `report`, which may ask to end the
//! step there (an early return): the instance then takes the step again
//! from its start to the switch, so that it stands at the switch exactly
//! as if the importer had asked for a step of that length.
//!
//! Found: every switch after which the discrete outputs differ from those
//! before it. Two switches that put the outputs back as they were inside
//! one stretch searched (stick, slip and stick again within what is left
//! of the step) are not seen: the step's outputs at its end are the ones
//! compared.

use super::{advance_inputs, Instance};
use crate::variables::{Causality, VarType};

/// A switch is located to this fraction of the step's length.
pub const RESOLUTION: f64 = 1e-12;
/// The most switches reported in one step.
const MAX_SWITCHES: usize = 1000;

impl Instance {
    /// The value references of the Integer and Boolean outputs (the
    /// law's stick/slip indicators), whose changes are the switches.
    pub fn discrete_outputs(&self) -> Vec<u32> {
        self.info
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output && v.var_type != VarType::Real)
            .map(|v| v.vr)
            .collect()
    }

    /// The discrete outputs now.
    fn discrete_values(&mut self, outputs: &[u32]) -> Result<Vec<f64>, String> {
        self.ensure_outputs()?;
        Ok(outputs.iter().map(|&vr| self.values.real(vr)).collect())
    }

    /// [`Instance::do_step`] from `t` over `h`, with every switch inside
    /// the step reported to `report(time)`; `report` answers the time to
    /// end the step at if the importer asks for an early return there
    /// (`None`: go on). Returns the time the step ended at before `t + h`,
    /// if it returned early (at the switch, or later if the importer asked
    /// for a later time, never past the step's end).
    pub fn do_step_locating_switches(
        &mut self,
        t: f64,
        h: f64,
        report: &mut dyn FnMut(f64) -> Option<f64>,
    ) -> Result<Option<f64>, String> {
        let outputs = self.discrete_outputs();
        if outputs.is_empty() || !self.initialized {
            self.do_step(t, h)?;
            return Ok(None);
        }
        // the instance before the step, for the replays
        let before = self.discrete_values(&outputs)?;
        let mut state = Vec::new();
        self.model.save_state(&mut state);
        let (values, slopes, sloped) = (self.values.clone(), self.slopes.clone(), self.sloped);
        self.do_step(t, h)?;
        let after = self.discrete_values(&outputs)?;
        if after == before {
            return Ok(None);
        }
        // The discrete outputs after a sub-step of `tau` from the start.
        let mut probe = self.model.clone_model();
        let inputs: Vec<u32> = self.inputs.to_vec();
        let mut outputs_at = |tau: f64| -> Result<Vec<f64>, String> {
            probe.restore_state(&state)?;
            probe.do_step(&values, &slopes, tau)?;
            let mut v = values.clone();
            let mut s = slopes.clone();
            advance_inputs(&inputs, &mut v, &mut s, tau);
            probe.compute_outputs(&mut v);
            Ok(outputs.iter().map(|&vr| v.real(vr)).collect())
        };
        let (mut from, mut outputs_from) = (0.0, before);
        for _ in 0..MAX_SWITCHES {
            if outputs_from == after {
                break;
            }
            // the first change after `from`: outputs_at(lo) = outputs_from,
            // outputs_at(hi) differs
            let (mut lo, mut hi) = (from, h);
            let mut at_hi = after.clone();
            while hi - lo > RESOLUTION * h {
                let mid = 0.5 * (lo + hi);
                let at_mid = outputs_at(mid)?;
                if at_mid == outputs_from {
                    lo = mid;
                } else {
                    hi = mid;
                    at_hi = at_mid;
                }
            }
            if let Some(end) = report(t + hi) {
                let end = (end - t).clamp(hi, h);
                if end < h {
                    // again from the start, to `end`: as a step of that length
                    self.model.restore_state(&state)?;
                    self.values = values;
                    self.slopes = slopes;
                    self.sloped = sloped;
                    self.time = t;
                    self.step_state_current = false;
                    self.outputs_dirty = true;
                    self.do_step(t, end)?;
                    return Ok(Some(t + end));
                }
            }
            (from, outputs_from) = (hi, at_hi);
        }
        Ok(None)
    }
}
