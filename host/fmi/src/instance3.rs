//! An FMI 3.0 Co-Simulation instance ([`Fmi3Instance`]): FMI 3.0.1 §2.3
//! and §4 as safe methods, each a call through FMI 3.0's raw table
//! ([`crate::fmi3::Functions`]) and through the same guard (`guard.rs`) as FMI
//! 2.0's [`crate::Instance`] (statuses as `Result`, the log messages of a
//! failed call in its error, the refusal after `fmi3Fatal`, the time limit
//! and black box). What differs from FMI 2.0:
//!
//! - `fmi3InstantiateCoSimulation` is made without event mode and
//!   without early return (the FMU handles its events inside `fmi3DoStep`
//!   and completes each step, as an FMI 2.0 one does), and with the
//!   resources as a file path, not a URI;
//! - the start and stop times go to `fmi3EnterInitializationMode`
//!   ([`Fmi3Instance::enter_initialization_mode`]); FMI 2.0's
//!   `fmi2SetupExperiment` is gone;
//! - `fmi3DoStep` answers more than a status ([`StepOutcome`]): whether
//!   the FMU asks to end the simulation (`terminateSimulation`), and the
//!   time it got to; FMI 2.0 asks these with `fmi2GetBooleanStatus` and
//!   `fmi2GetRealStatus` after a discarded step;
//! - `fmi3Boolean` is C's `bool`: Booleans the FMU writes are read as
//!   bytes (any non-zero byte is true), never as a Rust `bool`.
//!
//! Two ways to name values: the methods named by FMI 3.0's types
//! (`get_float64`, `set_float64`, `get_int32`, `set_int32`,
//! `get_string`, `set_string`) pass the FMU's own value references of
//! scalars on as they are; those named by the core's kinds (`get_real`,
//! `set_real`, `get_integer`, `set_integer`, `get_boolean_raw`,
//! `get_boolean`, `set_boolean`) and `get_directional_derivative` take the
//! value references of the model description as fricsim reads it, where
//! an array is its elements and a variable may be of any FMI 3.0 type
//! that the core's kind holds, and reach each where the FMU holds it
//! (`values.rs`).

use super::guard::{c_string, not_supported, same_length, Guard};
use super::instance::{FmuState, Rollback};
use super::library::{c_text, Api, Declared};
use super::logger::{fricsim_fmi3_logger, Sink};
use super::model_description::ValueReference;
use super::{Fmu, Status};
use crate::blackbox::CallRecorder;
use crate::error::FmuError;
use crate::fmi3::*;
use std::os::raw::c_void;
use std::ptr::null_mut;
use std::time::Duration;

mod values;
pub(crate) use values::optional_functions;

/// The name of `fmi3DoStep` in errors.
const DO_STEP: &str = "fmi3DoStep";
/// Booleans are read through a stack buffer of bytes this long.
const BOOLEAN_CHUNK: usize = 64;

/// What `fmi3DoStep` answered besides its status (FMI 3.0.1 §4.2.1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutcome {
    pub status: Status,
    /// `eventHandlingNeeded` (only meaningful with event mode, which
    /// fricsim does not use: recorded, not acted on).
    pub event_handling_needed: bool,
    /// `terminateSimulation`: the FMU asks to end the simulation.
    pub terminate_simulation: bool,
    /// `earlyReturn`: the FMU stopped before the step's end (it may not,
    /// since the instance is made without early return).
    pub early_return: bool,
    /// `lastSuccessfulTime`: where the FMU got to.
    pub last_successful_time: f64,
}

/// One FMI 3.0 instance in Co-Simulation mode. Dropping it frees its
/// states and calls `fmi3FreeInstance`, unless a call returned
/// `fmi3Fatal` (after which no call is allowed and the instance is leaked).
pub struct Fmi3Instance {
    functions: Functions,
    declared: Declared,
    instance: fmi3Instance,
    guard: Guard,
    states: Vec<fmi3FMUState>,
    /// The last `fmi3DoStep`'s answer (`None` before the first step).
    last_step: Option<StepOutcome>,
    /// Where the description's variables are in the FMU: array elements,
    /// the types the core holds in another (`values.rs`).
    layout: values::Layout,
    /// Whether the FMU may be asked for its values (FMI 3.0.1 §2.3.3: from
    /// initialization mode on, not just after instantiation or a reset).
    values_readable: bool,
}

impl std::fmt::Debug for Fmi3Instance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fmi3Instance")
            .field("name", &self.guard.name)
            .field("model", &self.guard.fmu.description().model_name)
            .field("states", &self.states.len())
            .field("fatal", &self.guard.fatal)
            .finish_non_exhaustive()
    }
}

impl Fmi3Instance {
    /// `fmi3InstantiateCoSimulation`: not visible, debug logging off,
    /// without event mode, early return or intermediate update.
    pub fn instantiate(fmu: &Fmu, name: &str) -> Result<Fmi3Instance, FmuError> {
        let description = fmu.description();
        let Api::Fmi3(functions) = fmu.library().api else {
            return Err(FmuError::WrongInstanceType {
                model: description.model_name.clone(),
                fmi_version: description.fmi_version.clone(),
            });
        };
        let declared = fmu.library().declared;
        let name_c = c_string("the instance name", name)?;
        let token = c_string("the instantiation token", &description.guid)?;
        // §2.3.1: an absolute path with a trailing separator
        let mut resources = fmu.dir().join("resources").to_string_lossy().into_owned();
        resources.push('/');
        let resources = c_string("the resource path", &resources)?;
        let id = super::instance::next_instance_id();
        let sink = Box::new(Sink::new(fmu.log().clone(), name, id));
        // SAFETY: all strings are NUL-terminated and outlive the call; the
        // sink lives as long as the instance (and longer after fmi3Fatal).
        let instance = unsafe {
            (functions.instantiate_co_simulation)(
                name_c.as_ptr(),
                token.as_ptr(),
                resources.as_ptr(),
                false,
                false,
                false,
                false,
                std::ptr::null(),
                0,
                &*sink as *const Sink as *mut c_void,
                Some(fricsim_fmi3_logger),
                None,
            )
        };
        if instance.is_null() {
            return Err(FmuError::Instantiate {
                instance: name.to_string(),
                messages: fmu.log().messages_since(&sink, 0, 0),
            });
        }
        Ok(Fmi3Instance {
            functions,
            declared,
            instance,
            guard: Guard::new(fmu, name, id, sink),
            states: Vec::new(),
            last_step: None,
            layout: values::Layout::new(description),
            values_readable: false,
        })
    }

    pub fn name(&self) -> &str {
        &self.guard.name
    }

    pub fn fmu(&self) -> &Fmu {
        &self.guard.fmu
    }

    /// As [`crate::Instance::changes`].
    pub fn changes(&self) -> u64 {
        self.guard.changes
    }

    /// As [`crate::Instance::set_call_time_limit`].
    pub fn set_call_time_limit(&mut self, limit: Option<Duration>) {
        self.guard.set_call_time_limit(limit);
    }

    /// As [`crate::Instance::set_black_box`].
    pub fn set_black_box(&mut self, recorder: Option<CallRecorder>) {
        self.guard.set_black_box(recorder);
    }

    /// Whether a call has returned `fmi3Error` or `fmi3Fatal` since
    /// instantiation or the last successful `fmi3Reset`.
    pub fn has_failed(&self) -> bool {
        self.guard.failed
    }

    #[inline(always)]
    fn call(
        &mut self,
        function: &'static str,
        ffi: impl FnOnce(fmi3Instance) -> Result<fmi3Status, FmuError>,
    ) -> Result<Status, FmuError> {
        self.guard.call(function, self.instance, ffi)
    }

    /// `fmi3SetDebugLogging`: switch the named log categories (all if empty).
    pub fn set_debug_logging(&mut self, on: bool, categories: &[&str]) -> Result<Status, FmuError> {
        let owned = categories
            .iter()
            .map(|c| c_string("a log category", c))
            .collect::<Result<Vec<_>, _>>()?;
        let pointers: Vec<fmi3String> = owned.iter().map(|c| c.as_ptr()).collect();
        let f = self.functions.set_debug_logging;
        // SAFETY: `pointers` holds `len` valid strings for the call.
        self.call("fmi3SetDebugLogging", |i| {
            Ok(unsafe { f(i, on, pointers.len(), pointers.as_ptr()) })
        })
    }

    /// `fmi3EnterInitializationMode` from `start` (to `stop`, if given),
    /// tolerance undefined.
    pub fn enter_initialization_mode(
        &mut self,
        start: f64,
        stop: Option<f64>,
    ) -> Result<Status, FmuError> {
        let f = self.functions.enter_initialization_mode;
        let (stop_defined, stop) = match stop {
            Some(s) => (true, s),
            None => (false, 0.0),
        };
        // SAFETY: plain values.
        let status = self.call("fmi3EnterInitializationMode", |i| {
            Ok(unsafe { f(i, false, 0.0, start, stop_defined, stop) })
        })?;
        self.values_readable = true;
        Ok(status)
    }

    /// `fmi3ExitInitializationMode`: without event mode, the instance is
    /// then in step mode.
    pub fn exit_initialization_mode(&mut self) -> Result<Status, FmuError> {
        let f = self.functions.exit_initialization_mode;
        // SAFETY: the instance is live.
        self.call("fmi3ExitInitializationMode", |i| Ok(unsafe { f(i) }))
    }

    /// `fmi3Terminate`.
    pub fn terminate(&mut self) -> Result<Status, FmuError> {
        let f = self.functions.terminate;
        // SAFETY: the instance is live.
        self.call("fmi3Terminate", |i| Ok(unsafe { f(i) }))
    }

    /// `fmi3Reset`: back to the state after instantiation.
    pub fn reset(&mut self) -> Result<Status, FmuError> {
        let f = self.functions.reset;
        // SAFETY: the instance is live.
        let status = self.call("fmi3Reset", |i| Ok(unsafe { f(i) }))?;
        self.guard.failed = false;
        self.last_step = None;
        self.values_readable = false;
        self.layout.restart();
        Ok(status)
    }

    /// `fmi3GetFloat64` of the FMU's own scalars, as they are: `values[i]`
    /// = value of `vrs[i]` (the description's Real variables, array
    /// elements and other types included: [`Fmi3Instance::get_real`]).
    #[inline]
    pub fn get_float64(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [f64],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi3GetFloat64";
        let f = self.functions.get_float64;
        self.call(F, |i| {
            same_length(F, "values", vrs.len(), values.len())?;
            // SAFETY: both arrays hold `vrs.len()` elements (scalars).
            Ok(unsafe {
                f(
                    i,
                    vrs.as_ptr(),
                    vrs.len(),
                    values.as_mut_ptr(),
                    values.len(),
                )
            })
        })
    }

    /// `fmi3SetFloat64` of the FMU's own scalars, as they are
    /// ([`Fmi3Instance::set_real`] for any Real variable).
    #[inline]
    pub fn set_float64(
        &mut self,
        vrs: &[ValueReference],
        values: &[f64],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi3SetFloat64";
        let f = self.functions.set_float64;
        self.call(F, |i| {
            same_length(F, "values", vrs.len(), values.len())?;
            // SAFETY: both arrays hold `vrs.len()` elements (scalars).
            Ok(unsafe { f(i, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len()) })
        })
    }

    /// `fmi3GetInt32` of the FMU's own scalars, as they are
    /// ([`Fmi3Instance::get_integer`] for any Integer variable).
    #[inline]
    pub fn get_int32(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [i32],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi3GetInt32";
        let f = self.functions.get_int32;
        self.call(F, |i| {
            same_length(F, "values", vrs.len(), values.len())?;
            // SAFETY: both arrays hold `vrs.len()` elements (scalars).
            Ok(unsafe {
                f(
                    i,
                    vrs.as_ptr(),
                    vrs.len(),
                    values.as_mut_ptr(),
                    values.len(),
                )
            })
        })
    }

    /// `fmi3SetInt32` of the FMU's own scalars, as they are
    /// ([`Fmi3Instance::set_integer`] for any Integer variable).
    pub fn set_int32(
        &mut self,
        vrs: &[ValueReference],
        values: &[i32],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi3SetInt32";
        let f = self.functions.set_int32;
        self.call(F, |i| {
            same_length(F, "values", vrs.len(), values.len())?;
            // SAFETY: both arrays hold `vrs.len()` elements (scalars).
            Ok(unsafe { f(i, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len()) })
        })
    }

    /// `fmi3GetBoolean` of the FMU's scalars, each as a C int (0 false, 1
    /// true). Does not allocate: the FMU writes bytes into a stack buffer.
    #[inline]
    fn get_boolean_bytes(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [i32],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi3GetBoolean";
        same_length(F, "values", vrs.len(), values.len())?;
        let f = self.functions.get_boolean;
        let mut status = Status::Ok;
        for (vrs, values) in vrs
            .chunks(BOOLEAN_CHUNK)
            .zip(values.chunks_mut(BOOLEAN_CHUNK))
        {
            let mut bytes = [0u8; BOOLEAN_CHUNK];
            let bytes = &mut bytes[..vrs.len()];
            // SAFETY: `bytes` holds `vrs.len()` one-byte C bools, read
            // back as bytes below (never as a Rust bool).
            let s = self.call(F, |i| {
                Ok(unsafe {
                    f(
                        i,
                        vrs.as_ptr(),
                        vrs.len(),
                        bytes.as_mut_ptr().cast::<bool>(),
                        bytes.len(),
                    )
                })
            })?;
            if s == Status::Warning {
                status = Status::Warning;
            }
            for (value, &b) in values.iter_mut().zip(bytes.iter()) {
                *value = i32::from(b != 0);
            }
        }
        Ok(status)
    }

    /// The Boolean values of the description's variables `vrs` (scalars or
    /// array elements, [`Fmi3Instance::get_boolean_raw`]).
    pub fn get_boolean(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [bool],
    ) -> Result<Status, FmuError> {
        let mut raw = vec![0; vrs.len()];
        same_length("fmi3GetBoolean", "values", vrs.len(), values.len())?;
        let status = self.get_boolean_raw(vrs, &mut raw)?;
        for (value, r) in values.iter_mut().zip(raw) {
            *value = r != 0;
        }
        Ok(status)
    }

    /// `fmi3SetBoolean` of the FMU's scalars.
    fn set_boolean_scalars(
        &mut self,
        vrs: &[ValueReference],
        values: &[bool],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi3SetBoolean";
        let f = self.functions.set_boolean;
        self.call(F, |i| {
            same_length(F, "values", vrs.len(), values.len())?;
            // SAFETY: both arrays hold `vrs.len()` elements; a Rust bool is a valid C bool.
            Ok(unsafe { f(i, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len()) })
        })
    }

    /// `fmi3GetString` of scalars (fricsim reads no String arrays): copied out at once (the FMU's pointers
    /// are only valid until its next call).
    pub fn get_string(&mut self, vrs: &[ValueReference]) -> Result<Vec<String>, FmuError> {
        const F: &str = "fmi3GetString";
        let f = self.functions.get_string;
        let mut pointers: Vec<fmi3String> = vec![std::ptr::null(); vrs.len()];
        self.call(F, |i| {
            // SAFETY: both arrays hold `vrs.len()` elements.
            Ok(unsafe {
                f(
                    i,
                    vrs.as_ptr(),
                    vrs.len(),
                    pointers.as_mut_ptr(),
                    pointers.len(),
                )
            })
        })?;
        // SAFETY: the FMU returned NUL-terminated strings (or null).
        Ok(pointers.into_iter().map(|p| unsafe { c_text(p) }).collect())
    }

    /// `fmi3SetString` of scalars.
    pub fn set_string(
        &mut self,
        vrs: &[ValueReference],
        values: &[&str],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi3SetString";
        same_length(F, "values", vrs.len(), values.len())?;
        let owned = values
            .iter()
            .map(|v| c_string("a string value", v))
            .collect::<Result<Vec<_>, _>>()?;
        let pointers: Vec<fmi3String> = owned.iter().map(|c| c.as_ptr()).collect();
        let f = self.functions.set_string;
        self.call(F, |i| {
            // SAFETY: both arrays hold `vrs.len()` elements; the strings outlive the call.
            Ok(unsafe {
                f(
                    i,
                    vrs.as_ptr(),
                    vrs.len(),
                    pointers.as_ptr(),
                    pointers.len(),
                )
            })
        })
    }

    /// `fmi3DoStep` from `t` over `h`; `rollback` is
    /// `noSetFMUStatePriorToCurrentPoint` as for FMI 2.0
    /// ([`crate::Instance::do_step_with`]). The answer besides the status
    /// is kept ([`Fmi3Instance::last_step`]) also when the step fails, so
    /// that a discarded step can say how far it got. A successful step
    /// that returned early, or whose `lastSuccessfulTime` is not `t + h`,
    /// is [`FmuError::EarlyReturn`] unless it ends the simulation: the
    /// instance is made without early return, and FMPy refuses it too.
    #[inline]
    pub fn do_step_with(
        &mut self,
        t: f64,
        h: f64,
        rollback: Rollback,
    ) -> Result<StepOutcome, FmuError> {
        self.guard.record_step_time(t);
        let f = self.functions.do_step;
        let no_set_prior = rollback == Rollback::Never;
        // bytes for the FMU's bools (see the module)
        let (mut event, mut terminate, mut early) = (0u8, 0u8, 0u8);
        let mut reached = f64::NAN;
        let result = self.call(DO_STEP, |i| {
            // SAFETY: every out-pointer is valid for the call.
            Ok(unsafe {
                f(
                    i,
                    t,
                    h,
                    no_set_prior,
                    (&mut event as *mut u8).cast::<bool>(),
                    (&mut terminate as *mut u8).cast::<bool>(),
                    (&mut early as *mut u8).cast::<bool>(),
                    &mut reached,
                )
            })
        });
        let outcome = |status| StepOutcome {
            status,
            event_handling_needed: event != 0,
            terminate_simulation: terminate != 0,
            early_return: early != 0,
            last_successful_time: reached,
        };
        match result {
            Ok(status) => {
                let o = outcome(status);
                self.last_step = Some(o);
                // made without early return: a step that ends elsewhere
                // than t + h (and does not end the simulation) broke the
                // contract, and its outputs are not those of t + h
                let complete = !o.early_return
                    && (o.last_successful_time - (t + h)).abs() <= 1e-9 * (t + h).abs().max(h);
                if !complete && !o.terminate_simulation {
                    return Err(self.early_return(t, h, o));
                }
                Ok(o)
            }
            Err(mut e) => {
                let status = e.status().unwrap_or(Status::Error);
                let o = outcome(status);
                self.last_step = Some(o);
                if let FmuError::Call {
                    status: Status::Discard,
                    messages,
                    ..
                } = &mut e
                {
                    messages.push(format!(
                        "the FMU completed the step only up to t = {reached} (lastSuccessfulTime); {}",
                        if o.terminate_simulation {
                            "it asks to end the simulation (terminateSimulation = true)"
                        } else {
                            "it does not ask to end the simulation (terminateSimulation = false)"
                        }
                    ));
                }
                Err(e)
            }
        }
    }

    #[cold]
    fn early_return(&self, t: f64, h: f64, o: StepOutcome) -> FmuError {
        FmuError::EarlyReturn {
            instance: self.guard.name.clone(),
            from: t,
            step: h,
            early_return: o.early_return,
            reached: o.last_successful_time,
        }
    }

    /// What the last `fmi3DoStep` answered, if a step was made.
    pub fn last_step(&self) -> Option<StepOutcome> {
        self.last_step
    }

    /// `fmi3GetDirectionalDerivative` of the FMU's own value references
    /// (an array's value reference takes or gives all its elements: `seed`
    /// and `out` are as long as the elements of `knowns` and `unknowns`);
    /// the public method is [`Fmi3Instance::get_directional_derivative`].
    #[inline]
    fn directional_derivative_of(
        &mut self,
        unknowns: &[ValueReference],
        knowns: &[ValueReference],
        seed: &[f64],
        out: &mut [f64],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi3GetDirectionalDerivative";
        let f = self.functions.get_directional_derivative;
        self.call(F, |i| {
            // SAFETY: each array holds as many elements as its length argument says.
            Ok(unsafe {
                f(
                    i,
                    unknowns.as_ptr(),
                    unknowns.len(),
                    knowns.as_ptr(),
                    knowns.len(),
                    seed.as_ptr(),
                    seed.len(),
                    out.as_mut_ptr(),
                    out.len(),
                )
            })
        })
    }

    fn state_declared(&self, function: &'static str) -> Result<(), FmuError> {
        if self.declared.fmu_state {
            Ok(())
        } else {
            Err(not_supported(function, "canGetAndSetFMUState=\"true\""))
        }
    }

    /// `fmi3GetFMUState` into a new state.
    pub fn get_state(&mut self) -> Result<FmuState, FmuError> {
        const F: &str = "fmi3GetFMUState";
        self.state_declared(F)?;
        let f = self.functions.get_fmu_state;
        let mut pointer: fmi3FMUState = null_mut();
        // SAFETY: `pointer` is a valid out-pointer, null asks for a new state.
        self.call(F, |i| Ok(unsafe { f(i, &mut pointer) }))?;
        let pointer = self.guard.not_null(F, pointer)?;
        self.states.push(pointer);
        Ok(FmuState::new(pointer, self.guard.id))
    }

    /// `fmi3GetFMUState` into an existing state (the FMU may reuse its memory).
    #[inline]
    pub fn update_state(&mut self, state: &mut FmuState) -> Result<Status, FmuError> {
        const F: &str = "fmi3GetFMUState";
        self.state_declared(F)?;
        self.guard.own(F, state.owner())?;
        let f = self.functions.get_fmu_state;
        let before = state.pointer();
        let mut pointer = before;
        // SAFETY: `pointer` is a live state of this instance.
        let result = self.call(F, |i| Ok(unsafe { f(i, &mut pointer) }));
        if pointer != before {
            if let Some(slot) = self.states.iter_mut().find(|p| **p == before) {
                *slot = pointer;
            }
            state.set_pointer(pointer);
        }
        result
    }

    /// `fmi3SetFMUState`: continue from `state`.
    #[inline]
    pub fn set_state(&mut self, state: &FmuState) -> Result<Status, FmuError> {
        const F: &str = "fmi3SetFMUState";
        self.state_declared(F)?;
        self.guard.own(F, state.owner())?;
        let f = self.functions.set_fmu_state;
        let pointer = state.pointer();
        // SAFETY: `pointer` is a live state of this instance.
        self.call(F, |i| Ok(unsafe { f(i, pointer) }))
    }

    /// `fmi3FreeFMUState`.
    pub fn free_state(&mut self, state: FmuState) -> Result<Status, FmuError> {
        const F: &str = "fmi3FreeFMUState";
        self.state_declared(F)?;
        self.guard.own(F, state.owner())?;
        if let Some(i) = self.states.iter().position(|p| *p == state.pointer()) {
            self.states.swap_remove(i);
        }
        let f = self.functions.free_fmu_state;
        let mut pointer = state.pointer();
        // SAFETY: `pointer` is a live state of this instance, freed once.
        self.call(F, |i| Ok(unsafe { f(i, &mut pointer) }))
    }

    /// `fmi3SerializedFMUStateSize` + `fmi3SerializeFMUState`.
    pub fn serialize_state(&mut self, state: &FmuState) -> Result<Vec<u8>, FmuError> {
        const F: &str = "fmi3SerializeFMUState";
        if !self.declared.serialize_fmu_state {
            return Err(not_supported(F, "canSerializeFMUState=\"true\""));
        }
        self.guard.own(F, state.owner())?;
        let (size_f, f) = (
            self.functions.serialized_fmu_state_size,
            self.functions.serialize_fmu_state,
        );
        let pointer = state.pointer();
        let mut size = 0usize;
        // SAFETY: `pointer` is a live state of this instance.
        self.call("fmi3SerializedFMUStateSize", |i| {
            Ok(unsafe { size_f(i, pointer, &mut size) })
        })?;
        let mut bytes = vec![0u8; size];
        // SAFETY: `bytes` holds `size` bytes.
        self.call(F, |i| {
            Ok(unsafe { f(i, pointer, bytes.as_mut_ptr(), size) })
        })?;
        Ok(bytes)
    }

    /// `fmi3DeserializeFMUState` into a new state of this instance.
    pub fn deserialize_state(&mut self, bytes: &[u8]) -> Result<FmuState, FmuError> {
        const F: &str = "fmi3DeserializeFMUState";
        if !self.declared.serialize_fmu_state {
            return Err(not_supported(F, "canSerializeFMUState=\"true\""));
        }
        let f = self.functions.deserialize_fmu_state;
        let mut pointer: fmi3FMUState = null_mut();
        // SAFETY: `bytes` holds `bytes.len()` bytes; `pointer` is a valid out-pointer.
        self.call(F, |i| {
            Ok(unsafe { f(i, bytes.as_ptr(), bytes.len(), &mut pointer) })
        })?;
        let pointer = self.guard.not_null(F, pointer)?;
        self.states.push(pointer);
        Ok(FmuState::new(pointer, self.guard.id))
    }
}

impl Drop for Fmi3Instance {
    fn drop(&mut self) {
        if self.guard.fatal {
            // §2.3.1: after fmi3Fatal no function may be called, not even
            // fmi3FreeInstance; the FMU may still hold the sink.
            return;
        }
        if self.declared.fmu_state {
            let free_state = self.functions.free_fmu_state;
            for mut pointer in self.states.drain(..) {
                // SAFETY: each pointer is a live state of this instance.
                unsafe { free_state(self.instance, &mut pointer) };
            }
        }
        // SAFETY: the instance is live and not used after this.
        unsafe { (self.functions.free_instance)(self.instance) };
        // SAFETY: the FMU is freed; nothing refers to the sink any more.
        unsafe { self.guard.drop_sink() };
    }
}
