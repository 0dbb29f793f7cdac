//! Gauss–Seidel: components step one after another over the same macro
//! step; a component takes the outputs at `t + h` of those already stepped.
//! The order follows the connection graph: a component whose connected
//! outputs have no direct feedthrough from its inputs (a mass whose velocity
//! is a state) goes before the components it feeds. With `interpolate`, an
//! input fed by an already-stepped component moves linearly from its value
//! at `t` to the one at `t + h` (`fmi2SetRealInputDerivatives`), where the
//! receiving FMU declares `canInterpolateInputs`.

use super::MasterAlgorithm;
use crate::fmu::Rollback;
use crate::system::System;
use crate::FmuError;

pub struct GaussSeidel {
    pub interpolate: bool,
    order: Vec<usize>,
    at_t: Vec<f64>,
}

impl GaussSeidel {
    pub fn new(interpolate: bool) -> Self {
        GaussSeidel {
            interpolate,
            order: Vec::new(),
            at_t: Vec::new(),
        }
    }

    /// Stepping order: repeatedly take the first remaining component whose
    /// inputs come only from components already ordered, or else (a loop)
    /// the first remaining one whose connected outputs do not depend on its
    /// inputs directly, or else the first remaining one.
    pub fn order(system: &System) -> Vec<usize> {
        let n = system.component_count();
        let mut order = Vec::with_capacity(n);
        let mut placed = vec![false; n];
        while order.len() < n {
            let ready = (0..n).find(|&c| {
                !placed[c]
                    && system
                        .connections()
                        .iter()
                        .filter(|k| k.to.0 == c)
                        .all(|k| placed[k.from.0] || k.from.0 == c)
            });
            let no_feedthrough = || {
                (0..n).find(|&c| {
                    !placed[c]
                        && system
                            .connections()
                            .iter()
                            .filter(|k| k.from.0 == c)
                            .all(|k| !system.has_feedthrough(c, k.from.1))
                })
            };
            let next = ready
                .or_else(no_feedthrough)
                .or_else(|| (0..n).find(|&c| !placed[c]))
                .expect("one remains");
            placed[next] = true;
            order.push(next);
        }
        order
    }
}

impl MasterAlgorithm for GaussSeidel {
    fn name(&self) -> &'static str {
        if self.interpolate {
            "gauss-seidel (interpolated inputs)"
        } else {
            "gauss-seidel"
        }
    }

    fn step(&mut self, system: &mut System, t: f64, h: f64) -> Result<(), FmuError> {
        if self.order.len() != system.component_count() {
            self.order = Self::order(system);
        }
        // every connected output at t, before anything steps
        let n = system.connections().len();
        self.at_t.resize(n, 0.0);
        for k in 0..n {
            let (from, output) = system.connections()[k].from;
            let mut x = [0.0];
            system.get_real(from, &[output], &mut x)?;
            self.at_t[k] = x[0];
        }
        let mut stepped = vec![false; system.component_count()];
        for &comp in &self.order {
            let can_interpolate = system.co_simulation(comp).can_interpolate_inputs;
            for k in 0..n {
                let c = &system.connections()[k];
                if c.to.0 != comp {
                    continue;
                }
                let ((source, output), input) = (c.from, c.to.1);
                let mut now = [self.at_t[k]];
                if stepped[source] {
                    system.get_real(source, &[output], &mut now)?;
                }
                if stepped[source] && self.interpolate && can_interpolate {
                    system.set_real(comp, &[input], &[self.at_t[k]])?;
                    system.set_real_input_derivatives(
                        comp,
                        &[input],
                        &[1],
                        &[(now[0] - self.at_t[k]) / h],
                    )?;
                } else {
                    system.set_real(comp, &[input], &now)?;
                }
            }
            // Gauss–Seidel only goes forward: the step is final
            system.do_step(comp, t, h, Rollback::Never)?;
            stepped[comp] = true;
        }
        Ok(())
    }
}
