//! FMI 3.0's raw layer: the C functions of an FMU binary as typed function
//! pointers (FMI 3.0.1 §2.3 common, §4 Co-Simulation in [`Functions`]),
//! with no checks at all: every pointer, length, status and call order is
//! the caller's. The counterpart of [`crate::fmi2`], built by the same
//! `function_table!` shape; the two share no functions or types.
//!
//! This is the one place that knows the FMI 3.0 symbol names. The safe
//! importer ([`crate::Fmi3Instance`]) calls through it; so may tests that
//! misuse FMUs on purpose.
//!
//! The optional functions (FMU state §2.3.7, directional derivatives
//! §2.3.11, output derivatives §4.2.3) may be missing from a binary whose
//! model description does not declare them: a missing one is
//! [`absent`](Functions::exports), and its pointer a stand-in that
//! returns `fmi3Error` without reading its arguments. The getters and
//! setters of the types other than Float64, Int32, Boolean and String are
//! optional too: the standard has every binary export them, but fricsim
//! needs them only for an FMU with variables of those types, and checks
//! that such an FMU's binary has them when it loads it
//! ([`crate::library`]). What fricsim does not call (Model Exchange,
//! Scheduled Execution, clocks, configuration mode, `Binary`) is not in
//! the table: a binary need not export it for fricsim to run it.
//!
//! The C types are those of `fmi3-types`, re-exported here.

pub use fmi3_types::*;

function_table! {
    /// The FMI 3.0 Co-Simulation API of one binary that fricsim calls.
    Functions;
    required {
        get_version: fmi3GetVersionTYPE = fmi3GetVersion,
        set_debug_logging: fmi3SetDebugLoggingTYPE = fmi3SetDebugLogging,
        instantiate_co_simulation: fmi3InstantiateCoSimulationTYPE = fmi3InstantiateCoSimulation,
        free_instance: fmi3FreeInstanceTYPE = fmi3FreeInstance,
        enter_initialization_mode: fmi3EnterInitializationModeTYPE = fmi3EnterInitializationMode,
        exit_initialization_mode: fmi3InstanceTYPE = fmi3ExitInitializationMode,
        terminate: fmi3InstanceTYPE = fmi3Terminate,
        reset: fmi3InstanceTYPE = fmi3Reset,
        get_float64: fmi3GetFloat64TYPE = fmi3GetFloat64,
        set_float64: fmi3SetFloat64TYPE = fmi3SetFloat64,
        get_int32: fmi3GetInt32TYPE = fmi3GetInt32,
        set_int32: fmi3SetInt32TYPE = fmi3SetInt32,
        get_boolean: fmi3GetBooleanTYPE = fmi3GetBoolean,
        set_boolean: fmi3SetBooleanTYPE = fmi3SetBoolean,
        get_string: fmi3GetStringTYPE = fmi3GetString,
        set_string: fmi3SetStringTYPE = fmi3SetString,
        do_step: fmi3DoStepTYPE = fmi3DoStep,
    }
    optional {
        get_fmu_state: fmi3GetFMUStateTYPE = fmi3GetFMUState(fmi3Instance, *mut fmi3FMUState),
        set_fmu_state: fmi3SetFMUStateTYPE = fmi3SetFMUState(fmi3Instance, fmi3FMUState),
        free_fmu_state: fmi3FreeFMUStateTYPE = fmi3FreeFMUState(fmi3Instance, *mut fmi3FMUState),
        serialized_fmu_state_size: fmi3SerializedFMUStateSizeTYPE =
            fmi3SerializedFMUStateSize(fmi3Instance, fmi3FMUState, *mut usize),
        serialize_fmu_state: fmi3SerializeFMUStateTYPE =
            fmi3SerializeFMUState(fmi3Instance, fmi3FMUState, *mut fmi3Byte, usize),
        deserialize_fmu_state: fmi3DeserializeFMUStateTYPE =
            fmi3DeserializeFMUState(fmi3Instance, *const fmi3Byte, usize, *mut fmi3FMUState),
        get_directional_derivative: fmi3GetDirectionalDerivativeTYPE = fmi3GetDirectionalDerivative(
            fmi3Instance,
            *const fmi3ValueReference,
            usize,
            *const fmi3ValueReference,
            usize,
            *const fmi3Float64,
            usize,
            *mut fmi3Float64,
            usize
        ),
        get_output_derivatives: fmi3GetOutputDerivativesTYPE = fmi3GetOutputDerivatives(
            fmi3Instance,
            *const fmi3ValueReference,
            usize,
            *const fmi3Int32,
            *mut fmi3Float64,
            usize
        ),
        get_float32: GetTYPE<fmi3Float32> =
            fmi3GetFloat32(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Float32, usize),
        set_float32: SetTYPE<fmi3Float32> =
            fmi3SetFloat32(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Float32, usize),
        get_int8: GetTYPE<fmi3Int8> =
            fmi3GetInt8(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Int8, usize),
        set_int8: SetTYPE<fmi3Int8> =
            fmi3SetInt8(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Int8, usize),
        get_uint8: GetTYPE<fmi3UInt8> =
            fmi3GetUInt8(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3UInt8, usize),
        set_uint8: SetTYPE<fmi3UInt8> =
            fmi3SetUInt8(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3UInt8, usize),
        get_int16: GetTYPE<fmi3Int16> =
            fmi3GetInt16(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Int16, usize),
        set_int16: SetTYPE<fmi3Int16> =
            fmi3SetInt16(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Int16, usize),
        get_uint16: GetTYPE<fmi3UInt16> =
            fmi3GetUInt16(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3UInt16, usize),
        set_uint16: SetTYPE<fmi3UInt16> =
            fmi3SetUInt16(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3UInt16, usize),
        get_uint32: GetTYPE<fmi3UInt32> =
            fmi3GetUInt32(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3UInt32, usize),
        set_uint32: SetTYPE<fmi3UInt32> =
            fmi3SetUInt32(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3UInt32, usize),
        get_int64: GetTYPE<fmi3Int64> =
            fmi3GetInt64(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3Int64, usize),
        set_int64: SetTYPE<fmi3Int64> =
            fmi3SetInt64(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3Int64, usize),
        get_uint64: GetTYPE<fmi3UInt64> =
            fmi3GetUInt64(fmi3Instance, *const fmi3ValueReference, usize, *mut fmi3UInt64, usize),
        set_uint64: SetTYPE<fmi3UInt64> =
            fmi3SetUInt64(fmi3Instance, *const fmi3ValueReference, usize, *const fmi3UInt64, usize),
    }
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
        assert!(Functions::REQUIRED.contains(&"fmi3DoStep"));
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
        for symbol in Functions::OPTIONAL {
            assert!(!f.exports(symbol), "{symbol}");
        }
        // SAFETY: a stand-in, which reads none of its arguments.
        let status = unsafe { (f.get_fmu_state)(std::ptr::null_mut(), std::ptr::null_mut()) };
        assert_eq!(status, fmi3Error);
    }
}
