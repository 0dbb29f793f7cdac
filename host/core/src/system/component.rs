//! A component's FMU instance, behind one type: [`ComponentInstance`].
//!
//! This is the one place of the core that calls an FMU instance, FMI 2.0
//! ([`fricsim_fmi::Instance`]) or FMI 3.0 ([`fricsim_fmi::Fmi3Instance`]),
//! for the system and, through [`super::coupling`], for the masters. Each
//! method is one `match` on the FMI version (static dispatch, inlined:
//! the per-step calls of the Jacobi master and the strong-coupling
//! iterations go through here); the system and the masters name no
//! version. Value references are the model description's: an FMI 3.0
//! instance takes its arrays as their elements and every FMI 3.0 type as
//! the kind that holds it (`Float64`, `Float32`, … as Real; `Int8` …
//! `Int32` and `Enumeration` as Integer; see
//! [`crate::fmu::model_description::Fmi3Type::kind_name`]), and finds
//! where the FMU holds each.
//!
//! The [`ComponentInstance::initialize`] call is FMI 2.0's
//! `fmi2SetupExperiment` + `fmi2EnterInitializationMode` (after
//! `fmi2Reset`, to start over); FMI 3.0 has one call for both,
//! `fmi3EnterInitializationMode`, which takes the start and stop times.
//! A step after which an FMI 3.0 FMU asks to end the simulation
//! (`fmi3DoStep`'s `terminateSimulation`) becomes
//! [`FmuError::EndedSimulation`], which the run's loop takes for the
//! normal end of the run, as it takes FMI 2.0's discarded step with
//! `fmi2Terminated`.

use crate::fmu::blackbox::CallRecorder;
use crate::fmu::{Fmi3Instance, FmuState, Instance, Rollback, ValueReference};
use crate::FmuError;
use std::time::Duration;

/// A component's instance, of the FMI version of its FMU.
pub enum ComponentInstance {
    /// An FMI 2.0 Co-Simulation instance.
    Fmi2(Instance),
    /// An FMI 3.0 Co-Simulation instance.
    Fmi3(Fmi3Instance),
}

impl ComponentInstance {
    /// The FMI 2.0 instance, for the code that still calls one directly
    /// (the diagnosis reads variables of any type, the integration tests
    /// drive instances by hand): `None` for another FMI version.
    pub fn fmi2(&mut self) -> Option<&mut Instance> {
        match self {
            ComponentInstance::Fmi2(i) => Some(i),
            ComponentInstance::Fmi3(_) => None,
        }
    }

    /// One more per call that could change the instance
    /// ([`Instance::changes`]).
    #[inline(always)]
    pub fn changes(&self) -> u64 {
        match self {
            ComponentInstance::Fmi2(i) => i.changes(),
            ComponentInstance::Fmi3(i) => i.changes(),
        }
    }

    #[inline(always)]
    pub fn get_real(&mut self, vrs: &[ValueReference], values: &mut [f64]) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.get_real(vrs, values).map(drop),
            ComponentInstance::Fmi3(i) => i.get_real(vrs, values).map(drop),
        }
    }

    #[inline(always)]
    pub fn set_real(&mut self, vrs: &[ValueReference], values: &[f64]) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.set_real(vrs, values).map(drop),
            ComponentInstance::Fmi3(i) => i.set_real(vrs, values).map(drop),
        }
    }

    #[inline]
    pub fn get_integer(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [i32],
    ) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.get_integer(vrs, values).map(drop),
            ComponentInstance::Fmi3(i) => i.get_integer(vrs, values).map(drop),
        }
    }

    /// Booleans as the FMU gives them (non-zero: true).
    #[inline]
    pub fn get_boolean_raw(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [i32],
    ) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.get_boolean_raw(vrs, values).map(drop),
            ComponentInstance::Fmi3(i) => i.get_boolean_raw(vrs, values).map(drop),
        }
    }

    pub fn get_boolean(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [bool],
    ) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.get_boolean(vrs, values).map(drop),
            ComponentInstance::Fmi3(i) => i.get_boolean(vrs, values).map(drop),
        }
    }

    pub fn set_integer(&mut self, vrs: &[ValueReference], values: &[i32]) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.set_integer(vrs, values).map(drop),
            ComponentInstance::Fmi3(i) => i.set_integer(vrs, values).map(drop),
        }
    }

    pub fn set_boolean(&mut self, vrs: &[ValueReference], values: &[bool]) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.set_boolean(vrs, values).map(drop),
            ComponentInstance::Fmi3(i) => i.set_boolean(vrs, values).map(drop),
        }
    }

    pub fn set_string(&mut self, vrs: &[ValueReference], values: &[&str]) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.set_string(vrs, values).map(drop),
            ComponentInstance::Fmi3(i) => i.set_string(vrs, values).map(drop),
        }
    }

    /// Set the time derivatives of the Real inputs `vrs`, of the orders
    /// `orders`, to `values`.
    #[inline]
    pub fn set_real_input_derivatives(
        &mut self,
        vrs: &[ValueReference],
        orders: &[i32],
        values: &[f64],
    ) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => {
                i.set_real_input_derivatives(vrs, orders, values).map(drop)
            }
            // FMI 3.0 Co-Simulation has no input derivatives (its
            // description never declares canInterpolateInputs to fricsim)
            ComponentInstance::Fmi3(_) => Err(FmuError::NotSupported {
                function: "fmi2SetRealInputDerivatives",
                capability: "input derivatives, which FMI 3.0 Co-Simulation does not have",
            }),
        }
    }

    /// Step from `t` over `h` ([`Instance::do_step_with`]). A step the
    /// FMU discards because it ends the simulation stays an error here
    /// (`fmi2Discard`), which the run's loop tells apart
    /// ([`ComponentInstance::terminated_at`]); an FMI 3.0 step that asks
    /// to end the simulation is [`FmuError::EndedSimulation`].
    #[inline(always)]
    pub fn do_step(&mut self, t: f64, h: f64, rollback: Rollback) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.do_step_with(t, h, rollback).map(drop),
            ComponentInstance::Fmi3(i) => {
                let outcome = i.do_step_with(t, h, rollback)?;
                if outcome.terminate_simulation {
                    return Err(FmuError::EndedSimulation {
                        function: "fmi3DoStep",
                        instance: i.name().to_string(),
                        time: outcome.last_successful_time,
                    });
                }
                Ok(())
            }
        }
    }

    /// If the instance has ended the simulation: the time it got to
    /// (FMI 2.0: `fmi2GetBooleanStatus(fmi2Terminated)`, then
    /// `fmi2LastSuccessfulTime`). `None` when it has not, or when either
    /// question fails.
    pub fn terminated_at(&mut self) -> Option<f64> {
        match self {
            ComponentInstance::Fmi2(i) => {
                if !i.terminated().ok()? {
                    return None;
                }
                i.last_successful_time().ok()
            }
            ComponentInstance::Fmi3(i) => {
                let step = i.last_step()?;
                step.terminate_simulation
                    .then_some(step.last_successful_time)
            }
        }
    }

    #[inline(always)]
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[ValueReference],
        knowns: &[ValueReference],
        seed: &[f64],
        out: &mut [f64],
    ) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i
                .get_directional_derivative(unknowns, knowns, seed, out)
                .map(drop),
            ComponentInstance::Fmi3(i) => i
                .get_directional_derivative(unknowns, knowns, seed, out)
                .map(drop),
        }
    }

    pub fn get_state(&mut self) -> Result<FmuState, FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.get_state(),
            ComponentInstance::Fmi3(i) => i.get_state(),
        }
    }

    #[inline]
    pub fn update_state(&mut self, state: &mut FmuState) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.update_state(state).map(drop),
            ComponentInstance::Fmi3(i) => i.update_state(state).map(drop),
        }
    }

    #[inline(always)]
    pub fn set_state(&mut self, state: &FmuState) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.set_state(state).map(drop),
            ComponentInstance::Fmi3(i) => i.set_state(state).map(drop),
        }
    }

    /// Set up the experiment from `start` (to `stop`, if given) and enter
    /// initialization mode; with `reset`, reset the instance first (to
    /// start over with an instance that has run).
    pub fn initialize(
        &mut self,
        reset: bool,
        start: f64,
        stop: Option<f64>,
    ) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => {
                if reset {
                    i.reset()?;
                }
                i.setup_experiment(start, stop)?;
                i.enter_initialization_mode().map(drop)
            }
            ComponentInstance::Fmi3(i) => {
                if reset {
                    i.reset()?;
                }
                i.enter_initialization_mode(start, stop).map(drop)
            }
        }
    }

    pub fn exit_initialization_mode(&mut self) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.exit_initialization_mode().map(drop),
            ComponentInstance::Fmi3(i) => i.exit_initialization_mode().map(drop),
        }
    }

    /// Whether a call has failed (`fmi2Error` or `fmi2Fatal`): the
    /// instance then allows no more than a reset and being freed.
    pub fn has_failed(&self) -> bool {
        match self {
            ComponentInstance::Fmi2(i) => i.has_failed(),
            ComponentInstance::Fmi3(i) => i.has_failed(),
        }
    }

    pub fn terminate(&mut self) -> Result<(), FmuError> {
        match self {
            ComponentInstance::Fmi2(i) => i.terminate().map(drop),
            ComponentInstance::Fmi3(i) => i.terminate().map(drop),
        }
    }

    /// A time limit on each FMI call ([`crate::fmu::watchdog`]).
    pub fn set_call_time_limit(&mut self, limit: Option<Duration>) {
        match self {
            ComponentInstance::Fmi2(i) => i.set_call_time_limit(limit),
            ComponentInstance::Fmi3(i) => i.set_call_time_limit(limit),
        }
    }

    /// Record each call in the black box of an isolated run
    /// ([`crate::isolate`]).
    pub fn set_black_box(&mut self, recorder: Option<CallRecorder>) {
        match self {
            ComponentInstance::Fmi2(i) => i.set_black_box(recorder),
            ComponentInstance::Fmi3(i) => i.set_black_box(recorder),
        }
    }
}
