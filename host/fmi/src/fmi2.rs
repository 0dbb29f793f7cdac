//! FMI 2.0's raw layer: the C functions of an FMU binary as typed function
//! pointers (FMI 2.0.4 §2.1 common, §4.2 Co-Simulation in [`Functions`],
//! §3.2 Model Exchange in [`ModelExchangeFunctions`]), with no checks at
//! all: every pointer, length, status and call order is the caller's.
//!
//! This is the one place that knows the FMI 2.0 symbol names. Who uses it:
//!
//! - the safe importer of this crate ([`crate::library`] loads a table,
//!   [`crate::Instance`] calls through it with state checks, statuses as
//!   `Result`, logging, watchdog): the only way the host calls an FMU;
//! - the tests that misuse FMUs on purpose (`host/tests/fmi`) and the fuzz
//!   targets (`fuzz/`, which fill a table from the exports linked into the
//!   fuzzer with [`Functions::from_lookup`], so the FMU code is
//!   instrumented);
//! - the hand-written FMI loop the host's stepping is measured against
//!   (`bench/src/fmi_loop.rs`).
//!
//! A table is plain data (`Copy`): calling `(functions.do_step)(c, t, h,
//! no_set_prior)` is one indirect call, as a C importer makes it. Loading
//! one is `unsafe`: the pointers are valid only while the library they
//! came from stays loaded, and only if each symbol has the signature the
//! standard gives it; both are the caller's to ensure.
//!
//! The optional functions of Co-Simulation (FMU state §2.1.8, directional
//! derivatives §2.1.9, input and output derivatives §4.2.1) may be missing
//! from a binary whose model description does not declare them: a missing
//! one is [`absent`](Functions::exports) and its pointer is a stand-in that
//! returns `fmi2Error` without reading its arguments, so that the table
//! has no `Option` to unwrap on the hot paths (the safe layer asks the
//! model description's capabilities before calling any of them).
//!
//! The C types are those of `fmi2-types`, re-exported here.
//!
//! FMI 3.0 gets a module of its own beside this one (`fmi3`, see the
//! crate's README): its functions, types and states differ, so the two
//! tables share no code, only the layout of this file.

pub use fmi2_types::*;

/// `fmi2CallbackFunctions` (§2.1.5), the callbacks given to
/// `fmi2Instantiate`: the same C struct as `fmi2-types`'s (checked at
/// compile time below) with Rust names for its fields, so that the tests
/// may build one with any field null.
#[repr(C)]
pub struct CallbackFunctions {
    /// Variadic in C; see [`fmi2CallbackLogger`].
    pub logger: fmi2CallbackLogger,
    pub allocate_memory: fmi2CallbackAllocateMemory,
    pub free_memory: fmi2CallbackFreeMemory,
    pub step_finished: fmi2StepFinished,
    pub component_environment: fmi2ComponentEnvironment,
}

// The same layout as the standard's struct, field by field.
const _: () = {
    use std::mem::{align_of, offset_of, size_of};
    type C = fmi2CallbackFunctions;
    type R = CallbackFunctions;
    assert!(size_of::<C>() == size_of::<R>() && align_of::<C>() == align_of::<R>());
    assert!(offset_of!(C, logger) == offset_of!(R, logger));
    assert!(offset_of!(C, allocateMemory) == offset_of!(R, allocate_memory));
    assert!(offset_of!(C, freeMemory) == offset_of!(R, free_memory));
    assert!(offset_of!(C, stepFinished) == offset_of!(R, step_finished));
    assert!(offset_of!(C, componentEnvironment) == offset_of!(R, component_environment));
};

/// `fmi2Instantiate`'s type (`fmi2InstantiateTYPE`) over [`CallbackFunctions`].
pub type InstantiateFn = unsafe extern "C" fn(
    fmi2String,
    fmi2Type,
    fmi2String,
    fmi2String,
    *const CallbackFunctions,
    fmi2Boolean,
    fmi2Boolean,
) -> fmi2Component;

function_table! {
    /// The FMI 2.0 Co-Simulation API of one binary (§2.1, §4.2): the
    /// common functions and those of Co-Simulation. (`fmi2GetStatus` and
    /// the other status queries are required by the standard, though only
    /// asynchronous steps, which fricsim does not make, need most of them.)
    Functions;
    required {
        get_types_platform: fmi2GetTypesPlatformTYPE = fmi2GetTypesPlatform,
        get_version: fmi2GetVersionTYPE = fmi2GetVersion,
        set_debug_logging: fmi2SetDebugLoggingTYPE = fmi2SetDebugLogging,
        instantiate: InstantiateFn = fmi2Instantiate,
        free_instance: fmi2FreeInstanceTYPE = fmi2FreeInstance,
        setup_experiment: fmi2SetupExperimentTYPE = fmi2SetupExperiment,
        enter_initialization_mode: fmi2ComponentTYPE = fmi2EnterInitializationMode,
        exit_initialization_mode: fmi2ComponentTYPE = fmi2ExitInitializationMode,
        terminate: fmi2ComponentTYPE = fmi2Terminate,
        reset: fmi2ComponentTYPE = fmi2Reset,
        get_real: fmi2GetRealTYPE = fmi2GetReal,
        get_integer: fmi2GetIntegerTYPE = fmi2GetInteger,
        get_boolean: fmi2GetBooleanTYPE = fmi2GetBoolean,
        get_string: fmi2GetStringTYPE = fmi2GetString,
        set_real: fmi2SetRealTYPE = fmi2SetReal,
        set_integer: fmi2SetIntegerTYPE = fmi2SetInteger,
        set_boolean: fmi2SetBooleanTYPE = fmi2SetBoolean,
        set_string: fmi2SetStringTYPE = fmi2SetString,
        do_step: fmi2DoStepTYPE = fmi2DoStep,
        cancel_step: fmi2ComponentTYPE = fmi2CancelStep,
        get_status: fmi2GetStatusTYPE = fmi2GetStatus,
        get_real_status: fmi2GetRealStatusTYPE = fmi2GetRealStatus,
        get_integer_status: fmi2GetIntegerStatusTYPE = fmi2GetIntegerStatus,
        get_boolean_status: fmi2GetBooleanStatusTYPE = fmi2GetBooleanStatus,
        get_string_status: fmi2GetStringStatusTYPE = fmi2GetStringStatus,
    }
    optional {
        get_fmu_state: fmi2GetFMUstateTYPE = fmi2GetFMUstate(fmi2Component, *mut fmi2FMUstate),
        set_fmu_state: fmi2SetFMUstateTYPE = fmi2SetFMUstate(fmi2Component, fmi2FMUstate),
        free_fmu_state: fmi2FreeFMUstateTYPE = fmi2FreeFMUstate(fmi2Component, *mut fmi2FMUstate),
        serialized_fmu_state_size: fmi2SerializedFMUstateSizeTYPE =
            fmi2SerializedFMUstateSize(fmi2Component, fmi2FMUstate, *mut usize),
        serialize_fmu_state: fmi2SerializeFMUstateTYPE =
            fmi2SerializeFMUstate(fmi2Component, fmi2FMUstate, *mut fmi2Byte, usize),
        deserialize_fmu_state: fmi2DeSerializeFMUstateTYPE =
            fmi2DeSerializeFMUstate(fmi2Component, *const fmi2Byte, usize, *mut fmi2FMUstate),
        get_directional_derivative: fmi2GetDirectionalDerivativeTYPE = fmi2GetDirectionalDerivative(
            fmi2Component,
            *const fmi2ValueReference,
            usize,
            *const fmi2ValueReference,
            usize,
            *const fmi2Real,
            *mut fmi2Real
        ),
        set_real_input_derivatives: fmi2SetRealInputDerivativesTYPE = fmi2SetRealInputDerivatives(
            fmi2Component,
            *const fmi2ValueReference,
            usize,
            *const fmi2Integer,
            *const fmi2Real
        ),
        get_real_output_derivatives: fmi2GetRealOutputDerivativesTYPE = fmi2GetRealOutputDerivatives(
            fmi2Component,
            *const fmi2ValueReference,
            usize,
            *const fmi2Integer,
            *mut fmi2Real
        ),
    }
}

function_table! {
    /// The functions Model Exchange adds (§3.2), for an instance made with
    /// `fmi2Instantiate(…, fmi2ModelExchange, …)` of [`Functions`]. The host
    /// co-simulates and does not load them; the tests do.
    ModelExchangeFunctions;
    required {
        enter_event_mode: fmi2EnterEventModeTYPE = fmi2EnterEventMode,
        new_discrete_states: fmi2NewDiscreteStatesTYPE = fmi2NewDiscreteStates,
        enter_continuous_time_mode: fmi2EnterContinuousTimeModeTYPE = fmi2EnterContinuousTimeMode,
        completed_integrator_step: fmi2CompletedIntegratorStepTYPE = fmi2CompletedIntegratorStep,
        set_time: fmi2SetTimeTYPE = fmi2SetTime,
        set_continuous_states: fmi2SetContinuousStatesTYPE = fmi2SetContinuousStates,
        get_derivatives: fmi2GetDerivativesTYPE = fmi2GetDerivatives,
        get_event_indicators: fmi2GetEventIndicatorsTYPE = fmi2GetEventIndicators,
        get_continuous_states: fmi2GetContinuousStatesTYPE = fmi2GetContinuousStates,
        get_nominals_of_continuous_states: fmi2GetNominalsOfContinuousStatesTYPE =
            fmi2GetNominalsOfContinuousStates,
    }
    optional {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::c_void;

    /// Stands in for every required function (never called).
    extern "C" fn required() {}

    #[test]
    fn a_table_names_every_missing_required_function_in_order() {
        // SAFETY: nothing is exported, so nothing is transmuted.
        let missing = unsafe { Functions::from_lookup(|_| std::ptr::null()) }.err();
        assert_eq!(missing.as_deref(), Some(Functions::REQUIRED));
    }

    #[test]
    fn a_missing_optional_function_is_absent_and_refuses() {
        let lookup = |symbol: &str| {
            if Functions::REQUIRED.contains(&symbol) {
                required as *const c_void
            } else {
                std::ptr::null()
            }
        };
        // SAFETY: the required functions are never called.
        let f = unsafe { Functions::from_lookup(lookup) }.ok().unwrap();
        assert!(f.exports("fmi2DoStep"));
        for symbol in Functions::OPTIONAL {
            assert!(!f.exports(symbol), "{symbol}");
        }
        assert!(!f.exports("fmi2NoSuchFunction"));
        // SAFETY: a stand-in, which reads none of its arguments.
        let status = unsafe { (f.get_fmu_state)(std::ptr::null_mut(), std::ptr::null_mut()) };
        assert_eq!(status, fmi2Error);
    }
}
