//! What the masters ([`crate::master`]) use of a [`System`]: the seam
//! between the co-simulation algorithms and the components they step.
//!
//! A master names components by index (`0..component_count()`, the
//! order of the system file) and variables by value reference, and
//! reaches them only through these methods: step one component, or every
//! one, from `t` by `h`; get and set Real values and input derivatives;
//! save and restore a component's state (the strong-coupling rollback);
//! directional derivatives; the change counter; nominal values and
//! capabilities; names for its errors and reports. None of `master/*.rs`
//! touches [`System`]'s fields or an FMU instance: when a component's
//! instance may be of another FMI version (issue 45), these methods are
//! where the versions are told apart, and the masters stay as they are.
//!
//! Every method is a thin `#[inline]` forward to the component's
//! [`super::ComponentInstance`] (static dispatch: one `match` on the FMI
//! version): the strong-coupling masters call them in
//! their per-iteration loops. The Jacobi master's step is
//! `System::step_jacobi`, in `system.rs`, beside the recording it reads.

use super::{Connection, System};
use crate::fmu::model_description::{Causality, CoSimulation, VariableKind};
use crate::fmu::{FmuState, Rollback, ValueReference};
use crate::FmuError;

impl System {
    /// How many components the system has; a master's component indices
    /// run over `0..component_count()`.
    #[inline]
    pub fn component_count(&self) -> usize {
        self.components.len()
    }

    /// The connections, by component index (fixed when the system is
    /// built).
    #[inline]
    pub fn connections(&self) -> &[Connection] {
        &self.connections
    }

    /// Component `c`'s instance name (the system file's component name).
    pub fn component_name(&self, c: usize) -> &str {
        &self.components[c].name
    }

    /// Component `c`'s model name, for errors that name the FMU.
    pub fn model_name(&self, c: usize) -> &str {
        &self.components[c].fmu.description().model_name
    }

    /// Component `c`'s recorded variables, in the order of its columns in
    /// a recorded row ([`super::Component::outputs`]).
    pub fn recorded_names(&self, c: usize) -> impl Iterator<Item = &str> {
        self.components[c].outputs.iter().map(|(n, _)| n.as_str())
    }

    /// Component `c`'s Co-Simulation capabilities.
    pub fn co_simulation(&self, c: usize) -> &CoSimulation {
        &self.components[c].fmu.description().co_simulation
    }

    /// Whether component `c`'s output `vr` depends directly on an input
    /// ([`super::Component::has_feedthrough`]).
    pub fn has_feedthrough(&self, c: usize, vr: ValueReference) -> bool {
        self.components[c].has_feedthrough(vr)
    }

    /// The nominal value of component `c`'s Real input `vr`, if its model
    /// description gives one.
    pub fn input_nominal(&self, c: usize, vr: ValueReference) -> Option<f64> {
        let d = self.components[c].fmu.description();
        d.variables
            .iter()
            .find(|v| v.value_reference == vr && v.causality == Causality::Input)
            .and_then(|v| match v.kind {
                VariableKind::Real { nominal, .. } => nominal,
                _ => None,
            })
    }

    /// Component `c`'s change count: one more per FMI call that could
    /// change it ([`super::ComponentInstance::changes`]); while it stands
    /// still, the component is as it was (only getters were called).
    #[inline(always)]
    pub fn changes(&self, c: usize) -> u64 {
        self.components[c].instance.changes()
    }

    /// Read component `c`'s Real variables `vrs` into `values`.
    #[inline(always)]
    pub fn get_real(
        &mut self,
        c: usize,
        vrs: &[ValueReference],
        values: &mut [f64],
    ) -> Result<(), FmuError> {
        self.components[c].instance.get_real(vrs, values)
    }

    /// Set component `c`'s Real variables `vrs` to `values`.
    #[inline(always)]
    pub fn set_real(
        &mut self,
        c: usize,
        vrs: &[ValueReference],
        values: &[f64],
    ) -> Result<(), FmuError> {
        self.components[c].instance.set_real(vrs, values)
    }

    /// Set the time derivatives of component `c`'s Real inputs `vrs`, of
    /// the orders `orders`, to `values` (the inputs then move along them
    /// over the next step; the component must be able to interpolate
    /// inputs, [`CoSimulation::can_interpolate_inputs`]).
    #[inline]
    pub fn set_real_input_derivatives(
        &mut self,
        c: usize,
        vrs: &[ValueReference],
        orders: &[i32],
        values: &[f64],
    ) -> Result<(), FmuError> {
        self.components[c]
            .instance
            .set_real_input_derivatives(vrs, orders, values)
    }

    /// Step component `c` from `t` over `h`; `rollback` says whether a
    /// state from before the step's end may still be restored.
    #[inline(always)]
    pub fn do_step(
        &mut self,
        c: usize,
        t: f64,
        h: f64,
        rollback: Rollback,
    ) -> Result<(), FmuError> {
        self.components[c].instance.do_step(t, h, rollback)
    }

    /// [`System::do_step`] of every component, in order; the first
    /// failure stops it.
    #[inline]
    pub fn do_step_all(&mut self, t: f64, h: f64, rollback: Rollback) -> Result<(), FmuError> {
        for c in &mut self.components {
            c.instance.do_step(t, h, rollback)?;
        }
        Ok(())
    }

    /// Component `c`'s directional derivatives: `out` (one per unknown
    /// of `unknowns`) = ∂unknowns/∂knowns · `seed`.
    #[inline(always)]
    pub fn get_directional_derivative(
        &mut self,
        c: usize,
        unknowns: &[ValueReference],
        knowns: &[ValueReference],
        seed: &[f64],
        out: &mut [f64],
    ) -> Result<(), FmuError> {
        self.components[c]
            .instance
            .get_directional_derivative(unknowns, knowns, seed, out)
    }

    /// Component `c`'s state, saved into a new [`FmuState`].
    pub fn get_state(&mut self, c: usize) -> Result<FmuState, FmuError> {
        self.components[c].instance.get_state()
    }

    /// Component `c`'s state saved into `state`, one it saved before.
    #[inline]
    pub fn update_state(&mut self, c: usize, state: &mut FmuState) -> Result<(), FmuError> {
        self.components[c].instance.update_state(state)
    }

    /// Component `c` rolled back to `state`, one it saved before.
    #[inline(always)]
    pub fn set_state(&mut self, c: usize, state: &FmuState) -> Result<(), FmuError> {
        self.components[c].instance.set_state(state)
    }

    /// Leave initialization mode, component after component; the first
    /// failure stops it.
    pub fn exit_initialization_mode(&mut self) -> Result<(), FmuError> {
        for c in &mut self.components {
            c.instance.exit_initialization_mode()?;
        }
        Ok(())
    }

    /// If the component named `instance` has ended the simulation (it
    /// says so when asked after a step it discarded, FMI 2.0 §4.2.3): the
    /// time it got to. `None` when it has not, when there is no such
    /// component, or when either question fails.
    pub fn terminated_at(&mut self, instance: &str) -> Option<f64> {
        let c = self.components.iter_mut().find(|c| c.name == instance)?;
        c.instance.terminated_at()
    }
}
