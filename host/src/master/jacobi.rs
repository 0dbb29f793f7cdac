//! Jacobi: every FMU steps in parallel on the inputs of the communication
//! point, held over the step (what FMPy and libcosim do).

use super::MasterAlgorithm;
use crate::system::System;
use crate::FmuError;

#[derive(Default)]
pub struct Jacobi {
    buffer: Vec<f64>,
}

impl MasterAlgorithm for Jacobi {
    fn name(&self) -> &'static str {
        "jacobi"
    }

    fn step(&mut self, system: &mut System, t: f64, h: f64) -> Result<(), FmuError> {
        self.buffer.resize(system.connections.len(), 0.0);
        system.propagate_inline(&mut self.buffer)?;
        for c in &mut system.components {
            c.instance.do_step(t, h)?;
        }
        Ok(())
    }
}
