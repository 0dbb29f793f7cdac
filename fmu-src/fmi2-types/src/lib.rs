//! The C types of the FMI 2.0 standard (`fmi2TypesPlatform.h`,
//! `fmi2FunctionTypes.h`; FMI 2.0.4 §2.1.2–§2.1.5, §3.2 and §4.2), written once
//! for both sides of the C ABI: the exporter (`fmi-export`, which the FMUs of
//! this repository are built on) and the importer (`fricsim`, host/), which
//! imports FMUs built by anyone and so depends on this crate, not on the
//! exporter. Types and constants only: no code, no dependencies, `no_std`.
//!
//! Every status crosses the ABI as a plain `c_int` ([`fmi2Status`]), as
//! the C `enum` does: an importer must accept whatever integer an FMU
//! returns, and an out-of-range value in a `#[repr(C)] enum` would be
//! undefined behaviour. An exporter, which only ever returns values it
//! made, may use an enum of its own on its side of the ABI (`fmi-export`
//! does, checked against [`fmi2OK`] … [`fmi2Pending`] at compile time).
#![no_std]
#![allow(non_camel_case_types, non_snake_case, non_upper_case_globals)]

use core::ffi::{c_char, c_int, c_uint, c_void, CStr};

/// `fmi2TypesPlatform` (§2.1.2): what `fmi2GetTypesPlatform` returns for
/// the types of this crate.
pub const fmi2TypesPlatform: &CStr = c"default";
/// `fmi2Version` (§2.1.4): what `fmi2GetVersion` returns.
pub const fmi2Version: &CStr = c"2.0";

pub type fmi2Component = *mut c_void;
pub type fmi2ComponentEnvironment = *mut c_void;
pub type fmi2FMUstate = *mut c_void;
pub type fmi2ValueReference = c_uint;
pub type fmi2Real = f64;
pub type fmi2Integer = c_int;
pub type fmi2Boolean = c_int;
pub type fmi2Char = c_char;
pub type fmi2String = *const fmi2Char;
pub type fmi2Byte = c_char;

pub const fmi2True: fmi2Boolean = 1;
pub const fmi2False: fmi2Boolean = 0;

/// An `fmi2Status` as it crosses the ABI (§2.1.3), ordered by severity:
/// [`fmi2OK`] … [`fmi2Pending`]; any other value is a broken FMU.
pub type fmi2Status = c_int;
pub const fmi2OK: fmi2Status = 0;
pub const fmi2Warning: fmi2Status = 1;
pub const fmi2Discard: fmi2Status = 2;
pub const fmi2Error: fmi2Status = 3;
pub const fmi2Fatal: fmi2Status = 4;
pub const fmi2Pending: fmi2Status = 5;

pub type fmi2Type = c_int;
pub const fmi2ModelExchange: fmi2Type = 0;
pub const fmi2CoSimulation: fmi2Type = 1;

pub type fmi2StatusKind = c_int;
pub const fmi2DoStepStatus: fmi2StatusKind = 0;
pub const fmi2PendingStatus: fmi2StatusKind = 1;
pub const fmi2LastSuccessfulTime: fmi2StatusKind = 2;
pub const fmi2Terminated: fmi2StatusKind = 3;

/// The importer's logger (§2.1.5). Variadic in C: stable Rust can call it
/// but cannot define it (fricsim's is written in C, `logger.c`).
pub type fmi2CallbackLogger = Option<
    unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        ...
    ),
>;
pub type fmi2CallbackAllocateMemory = Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>;
pub type fmi2CallbackFreeMemory = Option<unsafe extern "C" fn(*mut c_void)>;
pub type fmi2StepFinished = Option<unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2Status)>;

#[repr(C)]
pub struct fmi2CallbackFunctions {
    pub logger: fmi2CallbackLogger,
    pub allocateMemory: fmi2CallbackAllocateMemory,
    pub freeMemory: fmi2CallbackFreeMemory,
    pub stepFinished: fmi2StepFinished,
    pub componentEnvironment: fmi2ComponentEnvironment,
}

// Function types (fmi2FunctionTypes.h), common part (§2.1).
pub type fmi2GetTypesPlatformTYPE = unsafe extern "C" fn() -> *const c_char;
pub type fmi2GetVersionTYPE = unsafe extern "C" fn() -> *const c_char;
pub type fmi2SetDebugLoggingTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2Boolean, usize, *const fmi2String) -> fmi2Status;
pub type fmi2InstantiateTYPE = unsafe extern "C" fn(
    fmi2String,
    fmi2Type,
    fmi2String,
    fmi2String,
    *const fmi2CallbackFunctions,
    fmi2Boolean,
    fmi2Boolean,
) -> fmi2Component;
pub type fmi2FreeInstanceTYPE = unsafe extern "C" fn(fmi2Component);
pub type fmi2SetupExperimentTYPE = unsafe extern "C" fn(
    fmi2Component,
    fmi2Boolean,
    fmi2Real,
    fmi2Real,
    fmi2Boolean,
    fmi2Real,
) -> fmi2Status;
pub type fmi2ComponentTYPE = unsafe extern "C" fn(fmi2Component) -> fmi2Status;
pub type fmi2GetRealTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *mut fmi2Real,
) -> fmi2Status;
pub type fmi2GetIntegerTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *mut fmi2Integer,
) -> fmi2Status;
pub type fmi2GetBooleanTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *mut fmi2Boolean,
) -> fmi2Status;
pub type fmi2GetStringTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *mut fmi2String,
) -> fmi2Status;
pub type fmi2SetRealTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Real,
) -> fmi2Status;
pub type fmi2SetIntegerTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Integer,
) -> fmi2Status;
pub type fmi2SetBooleanTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Boolean,
) -> fmi2Status;
pub type fmi2SetStringTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2String,
) -> fmi2Status;

// FMU state (§2.1.8).
pub type fmi2GetFMUstateTYPE = unsafe extern "C" fn(fmi2Component, *mut fmi2FMUstate) -> fmi2Status;
pub type fmi2SetFMUstateTYPE = unsafe extern "C" fn(fmi2Component, fmi2FMUstate) -> fmi2Status;
pub type fmi2FreeFMUstateTYPE =
    unsafe extern "C" fn(fmi2Component, *mut fmi2FMUstate) -> fmi2Status;
pub type fmi2SerializedFMUstateSizeTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2FMUstate, *mut usize) -> fmi2Status;
pub type fmi2SerializeFMUstateTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2FMUstate, *mut fmi2Byte, usize) -> fmi2Status;
pub type fmi2DeSerializeFMUstateTYPE =
    unsafe extern "C" fn(fmi2Component, *const fmi2Byte, usize, *mut fmi2FMUstate) -> fmi2Status;

// Directional derivatives (§2.1.9).
pub type fmi2GetDirectionalDerivativeTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2ValueReference,
    usize,
    *const fmi2Real,
    *mut fmi2Real,
) -> fmi2Status;

// Co-simulation (§4.2).
pub type fmi2SetRealInputDerivativesTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Integer,
    *const fmi2Real,
) -> fmi2Status;
pub type fmi2GetRealOutputDerivativesTYPE = unsafe extern "C" fn(
    fmi2Component,
    *const fmi2ValueReference,
    usize,
    *const fmi2Integer,
    *mut fmi2Real,
) -> fmi2Status;
pub type fmi2DoStepTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean) -> fmi2Status;
pub type fmi2GetStatusTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2StatusKind, *mut fmi2Status) -> fmi2Status;
pub type fmi2GetRealStatusTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2StatusKind, *mut fmi2Real) -> fmi2Status;
pub type fmi2GetIntegerStatusTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2StatusKind, *mut fmi2Integer) -> fmi2Status;
pub type fmi2GetBooleanStatusTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2StatusKind, *mut fmi2Boolean) -> fmi2Status;
pub type fmi2GetStringStatusTYPE =
    unsafe extern "C" fn(fmi2Component, fmi2StatusKind, *mut fmi2String) -> fmi2Status;

// Model Exchange (§3.2).

/// `fmi2EventInfo` (§3.2.2): what `fmi2NewDiscreteStates` reports.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct fmi2EventInfo {
    pub newDiscreteStatesNeeded: fmi2Boolean,
    pub terminateSimulation: fmi2Boolean,
    pub nominalsOfContinuousStatesChanged: fmi2Boolean,
    pub valuesOfContinuousStatesChanged: fmi2Boolean,
    pub nextEventTimeDefined: fmi2Boolean,
    pub nextEventTime: fmi2Real,
}

pub type fmi2EnterEventModeTYPE = unsafe extern "C" fn(fmi2Component) -> fmi2Status;
pub type fmi2NewDiscreteStatesTYPE =
    unsafe extern "C" fn(fmi2Component, *mut fmi2EventInfo) -> fmi2Status;
pub type fmi2EnterContinuousTimeModeTYPE = unsafe extern "C" fn(fmi2Component) -> fmi2Status;
pub type fmi2CompletedIntegratorStepTYPE = unsafe extern "C" fn(
    fmi2Component,
    fmi2Boolean,
    *mut fmi2Boolean,
    *mut fmi2Boolean,
) -> fmi2Status;
pub type fmi2SetTimeTYPE = unsafe extern "C" fn(fmi2Component, fmi2Real) -> fmi2Status;
pub type fmi2SetContinuousStatesTYPE =
    unsafe extern "C" fn(fmi2Component, *const fmi2Real, usize) -> fmi2Status;
pub type fmi2GetDerivativesTYPE =
    unsafe extern "C" fn(fmi2Component, *mut fmi2Real, usize) -> fmi2Status;
pub type fmi2GetEventIndicatorsTYPE =
    unsafe extern "C" fn(fmi2Component, *mut fmi2Real, usize) -> fmi2Status;
pub type fmi2GetContinuousStatesTYPE =
    unsafe extern "C" fn(fmi2Component, *mut fmi2Real, usize) -> fmi2Status;
pub type fmi2GetNominalsOfContinuousStatesTYPE =
    unsafe extern "C" fn(fmi2Component, *mut fmi2Real, usize) -> fmi2Status;
