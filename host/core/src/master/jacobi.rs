//! Jacobi: every FMU steps in parallel on the inputs of the communication
//! point, held over the step (what FMPy and libcosim do).

use super::MasterAlgorithm;
use crate::system::System;
use crate::FmuError;

#[derive(Default)]
pub struct Jacobi {}

impl MasterAlgorithm for Jacobi {
    fn name(&self) -> &'static str {
        "jacobi"
    }

    #[inline(always)] // into the run's loop (see `MasterAlgorithm::as_jacobi`)
    fn step(&mut self, system: &mut System, t: f64, h: f64) -> Result<(), FmuError> {
        system.step_jacobi(t, h, false)
    }

    fn as_jacobi(&mut self) -> Option<&mut Jacobi> {
        Some(self)
    }
}
