//! The C types of the FMI 3.0 standard (`fmi3PlatformTypes.h`,
//! `fmi3FunctionTypes.h`; FMI 3.0.1 §2.2), written from the standard's
//! text for both sides of the C ABI: the importer (`fricsim`, host/fmi)
//! and, when it exists, the FMI 3.0 exporter of this repository. Types and
//! constants only: no code, no dependencies, `no_std`.
//!
//! As in `fmi2-types`, every status crosses the ABI as a plain `c_int`
//! ([`fmi3Status`]): an importer must accept whatever integer an FMU
//! returns. `fmi3Boolean` is C's `bool`; an importer that reads Booleans
//! an FMU wrote (values, `fmi3DoStep`'s flags) should read them as bytes
//! (any non-zero byte is true), since a byte other than 0 or 1 in a Rust
//! `bool` is undefined behaviour.
#![no_std]
#![allow(non_camel_case_types, non_snake_case, non_upper_case_globals)]

use core::ffi::{c_char, c_int, c_void, CStr};

/// `fmi3Version` (§2.2.5): what `fmi3GetVersion` returns.
pub const fmi3Version: &CStr = c"3.0";

pub type fmi3Instance = *mut c_void;
pub type fmi3InstanceEnvironment = *mut c_void;
pub type fmi3FMUState = *mut c_void;
pub type fmi3ValueReference = u32;
pub type fmi3Float32 = f32;
pub type fmi3Float64 = f64;
pub type fmi3Int8 = i8;
pub type fmi3UInt8 = u8;
pub type fmi3Int16 = i16;
pub type fmi3UInt16 = u16;
pub type fmi3Int32 = i32;
pub type fmi3UInt32 = u32;
pub type fmi3Int64 = i64;
pub type fmi3UInt64 = u64;
/// C's `bool` (see the crate's note on reading one an FMU wrote).
pub type fmi3Boolean = bool;
pub type fmi3Char = c_char;
pub type fmi3String = *const fmi3Char;
pub type fmi3Byte = u8;
pub type fmi3Binary = *const fmi3Byte;
pub type fmi3Clock = bool;
/// `fmi3DependencyKind` (§2.2.10), an enumeration passed as `int`.
pub type fmi3DependencyKind = c_int;

pub const fmi3True: fmi3Boolean = true;
pub const fmi3False: fmi3Boolean = false;

/// An `fmi3Status` as it crosses the ABI (§2.2.3), ordered by severity:
/// [`fmi3OK`] … [`fmi3Fatal`]; any other value is a broken FMU. (FMI 3.0
/// has no `Pending`: FMI 2.0's asynchronous steps are gone.)
pub type fmi3Status = c_int;
pub const fmi3OK: fmi3Status = 0;
pub const fmi3Warning: fmi3Status = 1;
pub const fmi3Discard: fmi3Status = 2;
pub const fmi3Error: fmi3Status = 3;
pub const fmi3Fatal: fmi3Status = 4;

/// `fmi3IntervalQualifier` (§2.2.9, clocks).
pub type fmi3IntervalQualifier = c_int;
pub const fmi3IntervalNotYetKnown: fmi3IntervalQualifier = 0;
pub const fmi3IntervalUnchanged: fmi3IntervalQualifier = 1;
pub const fmi3IntervalChanged: fmi3IntervalQualifier = 2;

/// The importer's logger (§2.2.4): not variadic in FMI 3.0, the message
/// is formatted by the FMU.
pub type fmi3LogMessageCallback =
    Option<unsafe extern "C" fn(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String)>;

/// Co-Simulation's intermediate update (§4.2.2): the FMU tells the
/// importer about a point inside `fmi3DoStep` (the last two arguments are
/// the importer's answer: return early, and when).
pub type fmi3IntermediateUpdateCallback = Option<
    unsafe extern "C" fn(
        fmi3InstanceEnvironment,
        fmi3Float64,
        fmi3Boolean,
        fmi3Boolean,
        fmi3Boolean,
        fmi3Boolean,
        *mut fmi3Boolean,
        *mut fmi3Float64,
    ),
>;

pub type fmi3ClockUpdateCallback = Option<unsafe extern "C" fn(fmi3InstanceEnvironment)>;
pub type fmi3LockPreemptionCallback = Option<unsafe extern "C" fn()>;
pub type fmi3UnlockPreemptionCallback = Option<unsafe extern "C" fn()>;

// ---- §2.2.5 inquire version, set debug logging -------------------------
pub type fmi3GetVersionTYPE = unsafe extern "C" fn() -> *const c_char;
pub type fmi3SetDebugLoggingTYPE =
    unsafe extern "C" fn(fmi3Instance, fmi3Boolean, usize, *const fmi3String) -> fmi3Status;

// ---- §2.3.1 creation and destruction ------------------------------------
pub type fmi3InstantiateModelExchangeTYPE = unsafe extern "C" fn(
    fmi3String,
    fmi3String,
    fmi3String,
    fmi3Boolean,
    fmi3Boolean,
    fmi3InstanceEnvironment,
    fmi3LogMessageCallback,
) -> fmi3Instance;
pub type fmi3InstantiateCoSimulationTYPE = unsafe extern "C" fn(
    fmi3String,
    fmi3String,
    fmi3String,
    fmi3Boolean,
    fmi3Boolean,
    fmi3Boolean,
    fmi3Boolean,
    *const fmi3ValueReference,
    usize,
    fmi3InstanceEnvironment,
    fmi3LogMessageCallback,
    fmi3IntermediateUpdateCallback,
) -> fmi3Instance;
pub type fmi3FreeInstanceTYPE = unsafe extern "C" fn(fmi3Instance);

// ---- §2.3.2–§2.3.6 the states ------------------------------------------
/// `fmi3EnterInitializationMode(instance, toleranceDefined, tolerance,
/// startTime, stopTimeDefined, stopTime)`: FMI 2.0's
/// `fmi2SetupExperiment` and `fmi2EnterInitializationMode` in one.
pub type fmi3EnterInitializationModeTYPE = unsafe extern "C" fn(
    fmi3Instance,
    fmi3Boolean,
    fmi3Float64,
    fmi3Float64,
    fmi3Boolean,
    fmi3Float64,
) -> fmi3Status;
/// `fmi3ExitInitializationMode`, `fmi3EnterEventMode`, `fmi3Terminate`,
/// `fmi3Reset`, `fmi3EnterStepMode`, …: the instance alone.
pub type fmi3InstanceTYPE = unsafe extern "C" fn(fmi3Instance) -> fmi3Status;

// ---- §2.2.6 getting and setting values ----------------------------------
/// `fmi3Get<Type>(instance, valueReferences, nValueReferences, values,
/// nValues)`: `nValues` counts array elements, so it may exceed
/// `nValueReferences`.
pub type GetTYPE<T> = unsafe extern "C" fn(
    fmi3Instance,
    *const fmi3ValueReference,
    usize,
    *mut T,
    usize,
) -> fmi3Status;
/// `fmi3Set<Type>(instance, valueReferences, nValueReferences, values,
/// nValues)`.
pub type SetTYPE<T> = unsafe extern "C" fn(
    fmi3Instance,
    *const fmi3ValueReference,
    usize,
    *const T,
    usize,
) -> fmi3Status;
pub type fmi3GetFloat64TYPE = GetTYPE<fmi3Float64>;
pub type fmi3SetFloat64TYPE = SetTYPE<fmi3Float64>;
pub type fmi3GetInt32TYPE = GetTYPE<fmi3Int32>;
pub type fmi3SetInt32TYPE = SetTYPE<fmi3Int32>;
pub type fmi3GetBooleanTYPE = GetTYPE<fmi3Boolean>;
pub type fmi3SetBooleanTYPE = SetTYPE<fmi3Boolean>;
pub type fmi3GetStringTYPE = GetTYPE<fmi3String>;
pub type fmi3SetStringTYPE = SetTYPE<fmi3String>;

// ---- §2.2.7 FMU state ---------------------------------------------------
pub type fmi3GetFMUStateTYPE = unsafe extern "C" fn(fmi3Instance, *mut fmi3FMUState) -> fmi3Status;
pub type fmi3SetFMUStateTYPE = unsafe extern "C" fn(fmi3Instance, fmi3FMUState) -> fmi3Status;
pub type fmi3FreeFMUStateTYPE = unsafe extern "C" fn(fmi3Instance, *mut fmi3FMUState) -> fmi3Status;
pub type fmi3SerializedFMUStateSizeTYPE =
    unsafe extern "C" fn(fmi3Instance, fmi3FMUState, *mut usize) -> fmi3Status;
pub type fmi3SerializeFMUStateTYPE =
    unsafe extern "C" fn(fmi3Instance, fmi3FMUState, *mut fmi3Byte, usize) -> fmi3Status;
pub type fmi3DeserializeFMUStateTYPE =
    unsafe extern "C" fn(fmi3Instance, *const fmi3Byte, usize, *mut fmi3FMUState) -> fmi3Status;

// ---- §2.2.11 partial derivatives ----------------------------------------
/// `fmi3GetDirectionalDerivative(instance, unknowns, nUnknowns, knowns,
/// nKnowns, seed, nSeed, sensitivity, nSensitivity)`; the adjoint
/// (`fmi3GetAdjointDerivative`) has the same signature.
pub type fmi3GetDirectionalDerivativeTYPE = unsafe extern "C" fn(
    fmi3Instance,
    *const fmi3ValueReference,
    usize,
    *const fmi3ValueReference,
    usize,
    *const fmi3Float64,
    usize,
    *mut fmi3Float64,
    usize,
) -> fmi3Status;
pub type fmi3GetAdjointDerivativeTYPE = fmi3GetDirectionalDerivativeTYPE;

// ---- §4.2 Co-Simulation -------------------------------------------------
/// `fmi3GetOutputDerivatives(instance, valueReferences, nValueReferences,
/// orders, values, nValues)`.
pub type fmi3GetOutputDerivativesTYPE = unsafe extern "C" fn(
    fmi3Instance,
    *const fmi3ValueReference,
    usize,
    *const fmi3Int32,
    *mut fmi3Float64,
    usize,
) -> fmi3Status;
/// `fmi3DoStep(instance, currentCommunicationPoint, communicationStepSize,
/// noSetFMUStatePriorToCurrentPoint, eventHandlingNeeded,
/// terminateSimulation, earlyReturn, lastSuccessfulTime)`.
pub type fmi3DoStepTYPE = unsafe extern "C" fn(
    fmi3Instance,
    fmi3Float64,
    fmi3Float64,
    fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Float64,
) -> fmi3Status;

// ---- §3.2 Model Exchange -------------------------------------------------
/// `fmi3UpdateDiscreteStates(instance, discreteStatesNeedUpdate,
/// terminateSimulation, nominalsOfContinuousStatesChanged,
/// valuesOfContinuousStatesChanged, nextEventTimeDefined, nextEventTime)`.
pub type fmi3UpdateDiscreteStatesTYPE = unsafe extern "C" fn(
    fmi3Instance,
    *mut fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Float64,
) -> fmi3Status;
pub type fmi3SetTimeTYPE = unsafe extern "C" fn(fmi3Instance, fmi3Float64) -> fmi3Status;
pub type fmi3SetContinuousStatesTYPE =
    unsafe extern "C" fn(fmi3Instance, *const fmi3Float64, usize) -> fmi3Status;
/// `fmi3GetContinuousStateDerivatives`, `fmi3GetEventIndicators`,
/// `fmi3GetContinuousStates`, `fmi3GetNominalsOfContinuousStates`: an
/// array and its length.
pub type fmi3GetFloat64ArrayTYPE =
    unsafe extern "C" fn(fmi3Instance, *mut fmi3Float64, usize) -> fmi3Status;
pub type fmi3CompletedIntegratorStepTYPE = unsafe extern "C" fn(
    fmi3Instance,
    fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Boolean,
) -> fmi3Status;
