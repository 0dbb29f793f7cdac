//! The FMI 3.0 interface over the same models, [`Instance`] and state
//! machine as FMI 2.0: Co-Simulation and Model Exchange (FMI 3.0
//! sections 3 and 4).
//!
//! The two interfaces differ at the C edge only. An FMI 3.0 call is
//! checked as an FMI 2.0 one (the instance pointer against the live
//! instances of FMI 3.0, the state table, null pointers and lengths, then
//! value references, types, causality and values), runs the same
//! [`Instance`] method, and returns the same status (FMI 3.0's statuses
//! have FMI 2.0's values). What FMI 3.0 adds is here:
//!
//! - the independent variable `time` and the event indicators are
//!   variables with value references after the table's
//!   ([`time_vr`], [`event_indicator_vr`]);
//! - scalars only: every array length (`nValues`, `nSeed`, …) must equal
//!   the number of value references;
//! - `fmi3GetAdjointDerivative` (from the directional derivatives);
//! - `fmi3DoStep` reports each stick/slip switch inside the step to the
//!   importer's intermediate-update callback, and ends the step there if
//!   the importer asks (early return); its last successful time;
//! - the functions of what these FMUs do not offer (clocks, configuration
//!   mode, event mode in Co-Simulation, Scheduled Execution, types other
//!   than Float64, Int32 and Boolean) refuse by name.
//!
//! The model description comes from the same variable table
//! ([`model_description::render`]).
//!
//! [`Instance`]: crate::instance::Instance

pub mod arrays;
pub mod exports;
pub mod model_description;

use crate::ModelInfo;

/// The value reference of the independent variable `time`, which FMI 3.0
/// requires (section 2.4.7): the one after the table's.
pub fn time_vr(info: &ModelInfo) -> u32 {
    info.variables.len() as u32
}

/// The value reference of event indicator `k` (0-based) of a model with a
/// Model Exchange interface: FMI 3.0 declares event indicators as
/// variables (section 2.4.8, `<EventIndicator>`), after `time`.
pub fn event_indicator_vr(info: &ModelInfo, k: usize) -> u32 {
    time_vr(info) + 1 + k as u32
}

/// Emit every FMI 3.0 function, Co-Simulation and Model Exchange, for the
/// models in `registry` (an expression of type `&'static [ModelFactory]`).
/// Invoke once in a cdylib, beside [`export_fmi2!`](crate::export_fmi2): the
/// two interfaces' symbols do not collide, so one binary serves the FMI
/// 2.0 and the FMI 3.0 FMU of each model.
#[macro_export]
macro_rules! export_fmi3 {
    ($registry:expr) => {
        pub mod fmi3_exports {
            #![allow(non_snake_case, clippy::missing_safety_doc)]
            use super::*;
            use std::os::raw::c_char;
            use $crate::fmi3::exports as x;
            use $crate::fmi3::exports::types::*;

            #[no_mangle]
            pub extern "C" fn fmi3GetVersion() -> *const c_char {
                x::version()
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetDebugLogging(
                c: fmi3Instance,
                on: BoolByte,
                n: usize,
                cats: *const fmi3String,
            ) -> fmi3Status {
                unsafe { x::set_debug_logging(c, on, n, cats) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3InstantiateModelExchange(
                name: fmi3String,
                token: fmi3String,
                resources: fmi3String,
                _visible: BoolByte,
                logging_on: BoolByte,
                environment: fmi3InstanceEnvironment,
                log: fmi3LogMessageCallback,
            ) -> fmi3Instance {
                unsafe {
                    x::instantiate(
                        $registry,
                        x::Interface::ModelExchange,
                        name,
                        token,
                        resources,
                        logging_on,
                        environment,
                        log,
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
                name: fmi3String,
                token: fmi3String,
                resources: fmi3String,
                _visible: BoolByte,
                logging_on: BoolByte,
                event_mode_used: BoolByte,
                early_return_allowed: BoolByte,
                _required_intermediate: *const fmi3ValueReference,
                _n_required_intermediate: usize,
                environment: fmi3InstanceEnvironment,
                log: fmi3LogMessageCallback,
                intermediate_update: fmi3IntermediateUpdateCallback,
            ) -> fmi3Instance {
                unsafe {
                    x::instantiate(
                        $registry,
                        x::Interface::CoSimulation {
                            event_mode_used,
                            early_return_allowed,
                            intermediate_update,
                        },
                        name,
                        token,
                        resources,
                        logging_on,
                        environment,
                        log,
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
                name: fmi3String,
                token: fmi3String,
                resources: fmi3String,
                _visible: BoolByte,
                logging_on: BoolByte,
                environment: fmi3InstanceEnvironment,
                log: fmi3LogMessageCallback,
                _clock_update: fmi3ClockUpdateCallback,
                _lock: fmi3LockPreemptionCallback,
                _unlock: fmi3UnlockPreemptionCallback,
            ) -> fmi3Instance {
                unsafe {
                    x::instantiate(
                        $registry,
                        x::Interface::ScheduledExecution,
                        name,
                        token,
                        resources,
                        logging_on,
                        environment,
                        log,
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3FreeInstance(c: fmi3Instance) {
                unsafe { x::free_instance(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterInitializationMode(
                c: fmi3Instance,
                tolerance_defined: BoolByte,
                tolerance: fmi3Float64,
                start: fmi3Float64,
                stop_defined: BoolByte,
                stop: fmi3Float64,
            ) -> fmi3Status {
                unsafe {
                    x::enter_initialization_mode(
                        c,
                        tolerance_defined,
                        tolerance,
                        start,
                        stop_defined,
                        stop,
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3ExitInitializationMode(c: fmi3Instance) -> fmi3Status {
                unsafe { x::exit_initialization_mode(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterEventMode(c: fmi3Instance) -> fmi3Status {
                unsafe { x::enter_event_mode(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3Terminate(c: fmi3Instance) -> fmi3Status {
                unsafe { x::terminate(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3Reset(c: fmi3Instance) -> fmi3Status {
                unsafe { x::reset(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetFloat64(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                v: *mut fmi3Float64,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::get_float64(c, vr, n, v, nv) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetInt32(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                v: *mut fmi3Int32,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::get_int32(c, vr, n, v, nv) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetBoolean(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                v: *mut fmi3Boolean,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::get_boolean(c, vr, n, v, nv) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetFloat64(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                v: *const fmi3Float64,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::set_float64(c, vr, n, v, nv) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetInt32(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                v: *const fmi3Int32,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::set_int32(c, vr, n, v, nv) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetBoolean(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                v: *const fmi3Boolean,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::set_boolean(c, vr, n, v, nv) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetString(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                v: *mut fmi3String,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::other_type(c, "fmi3GetString", "String", vr, n, nv) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetString(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                v: *const fmi3String,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::other_type(c, "fmi3SetString", "String", vr, n, nv) }
            }
            $crate::fmi3_other_type!(fmi3GetFloat32, fmi3SetFloat32, fmi3Float32, "Float32");
            $crate::fmi3_other_type!(fmi3GetInt8, fmi3SetInt8, fmi3Int8, "Int8");
            $crate::fmi3_other_type!(fmi3GetUInt8, fmi3SetUInt8, fmi3UInt8, "UInt8");
            $crate::fmi3_other_type!(fmi3GetInt16, fmi3SetInt16, fmi3Int16, "Int16");
            $crate::fmi3_other_type!(fmi3GetUInt16, fmi3SetUInt16, fmi3UInt16, "UInt16");
            $crate::fmi3_other_type!(fmi3GetUInt32, fmi3SetUInt32, fmi3UInt32, "UInt32");
            $crate::fmi3_other_type!(fmi3GetInt64, fmi3SetInt64, fmi3Int64, "Int64");
            $crate::fmi3_other_type!(fmi3GetUInt64, fmi3SetUInt64, fmi3UInt64, "UInt64");
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetBinary(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                _sizes: *mut usize,
                _v: *mut fmi3Binary,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::other_type(c, "fmi3GetBinary", "Binary", vr, n, nv) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetBinary(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                _sizes: *const usize,
                _v: *const fmi3Binary,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::other_type(c, "fmi3SetBinary", "Binary", vr, n, nv) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetClock(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                _v: *mut fmi3Clock,
            ) -> fmi3Status {
                unsafe { x::other_type(c, "fmi3GetClock", "Clock", vr, n, n) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetClock(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                _v: *const fmi3Clock,
            ) -> fmi3Status {
                unsafe { x::other_type(c, "fmi3SetClock", "Clock", vr, n, n) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
                c: fmi3Instance,
                _vr: fmi3ValueReference,
                _n: *mut usize,
            ) -> fmi3Status {
                unsafe {
                    x::unsupported(c, "fmi3GetNumberOfVariableDependencies", x::NO_PER_ELEMENT)
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetVariableDependencies(
                c: fmi3Instance,
                _dependent: fmi3ValueReference,
                _element_of_dependent: *mut usize,
                _independents: *mut fmi3ValueReference,
                _element_of_independents: *mut usize,
                _kinds: *mut fmi3DependencyKind,
                _n: usize,
            ) -> fmi3Status {
                unsafe { x::unsupported(c, "fmi3GetVariableDependencies", x::NO_PER_ELEMENT) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetFMUState(
                c: fmi3Instance,
                s: *mut fmi3FMUState,
            ) -> fmi3Status {
                unsafe { x::get_fmu_state(c, s) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetFMUState(
                c: fmi3Instance,
                s: fmi3FMUState,
            ) -> fmi3Status {
                unsafe { x::set_fmu_state(c, s) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3FreeFMUState(
                c: fmi3Instance,
                s: *mut fmi3FMUState,
            ) -> fmi3Status {
                unsafe { x::free_fmu_state(c, s) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
                c: fmi3Instance,
                s: fmi3FMUState,
                size: *mut usize,
            ) -> fmi3Status {
                unsafe { x::serialized_fmu_state_size(c, s, size) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SerializeFMUState(
                c: fmi3Instance,
                s: fmi3FMUState,
                bytes: *mut fmi3Byte,
                size: usize,
            ) -> fmi3Status {
                unsafe { x::serialize_fmu_state(c, s, bytes, size) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3DeserializeFMUState(
                c: fmi3Instance,
                bytes: *const fmi3Byte,
                size: usize,
                s: *mut fmi3FMUState,
            ) -> fmi3Status {
                unsafe { x::deserialize_fmu_state(c, bytes, size, s) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
                c: fmi3Instance,
                unknowns: *const fmi3ValueReference,
                n_unknowns: usize,
                knowns: *const fmi3ValueReference,
                n_knowns: usize,
                seed: *const fmi3Float64,
                n_seed: usize,
                sensitivity: *mut fmi3Float64,
                n_sensitivity: usize,
            ) -> fmi3Status {
                unsafe {
                    x::get_directional_derivative(
                        c,
                        (unknowns, n_unknowns),
                        (knowns, n_knowns),
                        (seed, n_seed),
                        (sensitivity, n_sensitivity),
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetAdjointDerivative(
                c: fmi3Instance,
                unknowns: *const fmi3ValueReference,
                n_unknowns: usize,
                knowns: *const fmi3ValueReference,
                n_knowns: usize,
                seed: *const fmi3Float64,
                n_seed: usize,
                sensitivity: *mut fmi3Float64,
                n_sensitivity: usize,
            ) -> fmi3Status {
                unsafe {
                    x::get_adjoint_derivative(
                        c,
                        (unknowns, n_unknowns),
                        (knowns, n_knowns),
                        (seed, n_seed),
                        (sensitivity, n_sensitivity),
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterConfigurationMode(c: fmi3Instance) -> fmi3Status {
                unsafe { x::unsupported(c, "fmi3EnterConfigurationMode", x::NO_STRUCTURAL) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3ExitConfigurationMode(c: fmi3Instance) -> fmi3Status {
                unsafe { x::unsupported(c, "fmi3ExitConfigurationMode", x::NO_STRUCTURAL) }
            }
            $crate::fmi3_no_clock!(
                fmi3GetIntervalDecimal,
                *mut fmi3Float64,
                *mut fmi3IntervalQualifier
            );
            $crate::fmi3_no_clock!(
                fmi3GetIntervalFraction,
                *mut fmi3UInt64,
                *mut fmi3UInt64,
                *mut fmi3IntervalQualifier
            );
            $crate::fmi3_no_clock!(fmi3GetShiftDecimal, *mut fmi3Float64);
            $crate::fmi3_no_clock!(fmi3GetShiftFraction, *mut fmi3UInt64, *mut fmi3UInt64);
            $crate::fmi3_no_clock!(fmi3SetIntervalDecimal, *const fmi3Float64);
            $crate::fmi3_no_clock!(
                fmi3SetIntervalFraction,
                *const fmi3UInt64,
                *const fmi3UInt64
            );
            $crate::fmi3_no_clock!(fmi3SetShiftDecimal, *const fmi3Float64);
            $crate::fmi3_no_clock!(fmi3SetShiftFraction, *const fmi3UInt64, *const fmi3UInt64);
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(c: fmi3Instance) -> fmi3Status {
                unsafe { x::evaluate_discrete_states(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
                c: fmi3Instance,
                discrete_states_need_update: *mut fmi3Boolean,
                terminate_simulation: *mut fmi3Boolean,
                nominals_changed: *mut fmi3Boolean,
                values_changed: *mut fmi3Boolean,
                next_event_time_defined: *mut fmi3Boolean,
                next_event_time: *mut fmi3Float64,
            ) -> fmi3Status {
                unsafe {
                    x::update_discrete_states(
                        c,
                        [
                            discrete_states_need_update,
                            terminate_simulation,
                            nominals_changed,
                            values_changed,
                            next_event_time_defined,
                        ],
                        next_event_time,
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(c: fmi3Instance) -> fmi3Status {
                unsafe { x::enter_continuous_time_mode(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
                c: fmi3Instance,
                _no_set_prior: BoolByte,
                enter_event_mode: *mut fmi3Boolean,
                terminate_simulation: *mut fmi3Boolean,
            ) -> fmi3Status {
                unsafe { x::completed_integrator_step(c, enter_event_mode, terminate_simulation) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetTime(c: fmi3Instance, time: fmi3Float64) -> fmi3Status {
                unsafe { x::set_time(c, time) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3SetContinuousStates(
                c: fmi3Instance,
                states: *const fmi3Float64,
                nx: usize,
            ) -> fmi3Status {
                unsafe { x::set_continuous_states(c, states, nx) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(
                c: fmi3Instance,
                out: *mut fmi3Float64,
                nx: usize,
            ) -> fmi3Status {
                unsafe { x::get_state_array(c, x::StateArray::Derivatives, out, nx) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetEventIndicators(
                c: fmi3Instance,
                out: *mut fmi3Float64,
                ni: usize,
            ) -> fmi3Status {
                unsafe { x::get_state_array(c, x::StateArray::EventIndicators, out, ni) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetContinuousStates(
                c: fmi3Instance,
                out: *mut fmi3Float64,
                nx: usize,
            ) -> fmi3Status {
                unsafe { x::get_state_array(c, x::StateArray::States, out, nx) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(
                c: fmi3Instance,
                out: *mut fmi3Float64,
                nx: usize,
            ) -> fmi3Status {
                unsafe { x::get_state_array(c, x::StateArray::Nominals, out, nx) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(
                c: fmi3Instance,
                n: *mut usize,
            ) -> fmi3Status {
                unsafe { x::get_number_of(c, "fmi3GetNumberOfEventIndicators", n) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(
                c: fmi3Instance,
                n: *mut usize,
            ) -> fmi3Status {
                unsafe { x::get_number_of(c, "fmi3GetNumberOfContinuousStates", n) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3EnterStepMode(c: fmi3Instance) -> fmi3Status {
                unsafe { x::unsupported(c, "fmi3EnterStepMode", x::NO_EVENT_MODE) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3GetOutputDerivatives(
                c: fmi3Instance,
                vr: *const fmi3ValueReference,
                n: usize,
                orders: *const fmi3Int32,
                v: *mut fmi3Float64,
                nv: usize,
            ) -> fmi3Status {
                unsafe { x::get_output_derivatives(c, vr, n, orders, v, nv) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3DoStep(
                c: fmi3Instance,
                t: fmi3Float64,
                h: fmi3Float64,
                _no_set_prior: BoolByte,
                event_handling_needed: *mut fmi3Boolean,
                terminate_simulation: *mut fmi3Boolean,
                early_return: *mut fmi3Boolean,
                last_successful_time: *mut fmi3Float64,
            ) -> fmi3Status {
                unsafe {
                    x::do_step(
                        c,
                        t,
                        h,
                        [event_handling_needed, terminate_simulation, early_return],
                        last_successful_time,
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi3ActivateModelPartition(
                c: fmi3Instance,
                _clock: fmi3ValueReference,
                _time: fmi3Float64,
            ) -> fmi3Status {
                unsafe { x::unsupported(c, "fmi3ActivateModelPartition", x::NO_CLOCKS) }
            }
        }
    };
}

/// The getter and setter of an FMI 3.0 type these models have no variable
/// of ([`exports::other_type`]), for [`export_fmi3!`](crate::export_fmi3).
#[macro_export]
#[doc(hidden)]
macro_rules! fmi3_other_type {
    ($get:ident, $set:ident, $t:ty, $name:literal) => {
        #[no_mangle]
        pub unsafe extern "C" fn $get(
            c: fmi3Instance,
            vr: *const fmi3ValueReference,
            n: usize,
            _v: *mut $t,
            nv: usize,
        ) -> fmi3Status {
            unsafe { x::other_type(c, stringify!($get), $name, vr, n, nv) }
        }
        #[no_mangle]
        pub unsafe extern "C" fn $set(
            c: fmi3Instance,
            vr: *const fmi3ValueReference,
            n: usize,
            _v: *const $t,
            nv: usize,
        ) -> fmi3Status {
            unsafe { x::other_type(c, stringify!($set), $name, vr, n, nv) }
        }
    };
}

/// A clock function (FMI 3.0 section 2.2.9): these FMUs have no clocks.
#[macro_export]
#[doc(hidden)]
macro_rules! fmi3_no_clock {
    ($name:ident, $($arg:ty),+) => {
        #[no_mangle]
        pub unsafe extern "C" fn $name(
            c: fmi3Instance,
            _vr: *const fmi3ValueReference,
            _n: usize,
            $(_: $arg),+
        ) -> fmi3Status {
            unsafe { x::unsupported(c, stringify!($name), x::NO_CLOCKS) }
        }
    };
}
