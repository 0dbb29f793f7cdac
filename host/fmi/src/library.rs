//! The FMU's shared library (FMI 2.0.4 §2.4: `binaries/<platform>/
//! <modelIdentifier>.so`) loaded with libloading, and its FMI 2.0
//! Co-Simulation functions (§2.1, §4.2) resolved into typed pointers.
//!
//! Every function of the common and co-simulation API is required; the
//! optional groups (FMU state §2.1.8, directional derivatives §2.1.9, input
//! and output derivatives §4.2.1) are resolved only when the model
//! description declares the capability, and then they must be there.

use super::model_description::ModelDescription;
use crate::error::FmuError;
use fmi2_types::*;
use std::ffi::CStr;
use std::path::{Path, PathBuf};

/// The only platform this host loads.
pub const PLATFORM: &str = "linux64";

macro_rules! functions {
    (
        required { $($field:ident: $ty:ty = $symbol:literal,)* }
        optional { $($ofield:ident: $oty:ty = $osymbol:literal,)* }
    ) => {
        /// The FMI functions of one loaded binary. The optional ones are
        /// `None` when the model description does not declare them.
        /// (`fmi2GetStatus` & co. are required by the standard but only
        /// meaningful for asynchronous steps, which this host does not use.)
        #[derive(Clone, Copy)]
        #[allow(dead_code)]
        pub(crate) struct Functions {
            $(pub $field: $ty,)*
            $(pub $ofield: Option<$oty>,)*
        }

        impl Functions {
            /// Resolve all functions, or name every missing required one.
            fn resolve(library: &libloading::Library) -> Result<Functions, Vec<&'static str>> {
                $(let $field = lookup::<$ty>(library, $symbol);)*
                let missing: Vec<&'static str> =
                    [$(($symbol, $field.is_none()),)*].into_iter().filter(|(_, m)| *m).map(|(s, _)| s).collect();
                if !missing.is_empty() {
                    return Err(missing);
                }
                Ok(Functions {
                    $($field: $field.expect("checked above"),)*
                    $($ofield: lookup::<$oty>(library, $osymbol),)*
                })
            }
        }
    };
}

functions! {
    required {
        get_types_platform: fmi2GetTypesPlatformTYPE = "fmi2GetTypesPlatform",
        get_version: fmi2GetVersionTYPE = "fmi2GetVersion",
        set_debug_logging: fmi2SetDebugLoggingTYPE = "fmi2SetDebugLogging",
        instantiate: fmi2InstantiateTYPE = "fmi2Instantiate",
        free_instance: fmi2FreeInstanceTYPE = "fmi2FreeInstance",
        setup_experiment: fmi2SetupExperimentTYPE = "fmi2SetupExperiment",
        enter_initialization_mode: fmi2ComponentTYPE = "fmi2EnterInitializationMode",
        exit_initialization_mode: fmi2ComponentTYPE = "fmi2ExitInitializationMode",
        terminate: fmi2ComponentTYPE = "fmi2Terminate",
        reset: fmi2ComponentTYPE = "fmi2Reset",
        get_real: fmi2GetRealTYPE = "fmi2GetReal",
        get_integer: fmi2GetIntegerTYPE = "fmi2GetInteger",
        get_boolean: fmi2GetBooleanTYPE = "fmi2GetBoolean",
        get_string: fmi2GetStringTYPE = "fmi2GetString",
        set_real: fmi2SetRealTYPE = "fmi2SetReal",
        set_integer: fmi2SetIntegerTYPE = "fmi2SetInteger",
        set_boolean: fmi2SetBooleanTYPE = "fmi2SetBoolean",
        set_string: fmi2SetStringTYPE = "fmi2SetString",
        do_step: fmi2DoStepTYPE = "fmi2DoStep",
        cancel_step: fmi2ComponentTYPE = "fmi2CancelStep",
        get_status: fmi2GetStatusTYPE = "fmi2GetStatus",
        get_real_status: fmi2GetRealStatusTYPE = "fmi2GetRealStatus",
        get_integer_status: fmi2GetIntegerStatusTYPE = "fmi2GetIntegerStatus",
        get_boolean_status: fmi2GetBooleanStatusTYPE = "fmi2GetBooleanStatus",
        get_string_status: fmi2GetStringStatusTYPE = "fmi2GetStringStatus",
    }
    optional {
        get_fmu_state: fmi2GetFMUstateTYPE = "fmi2GetFMUstate",
        set_fmu_state: fmi2SetFMUstateTYPE = "fmi2SetFMUstate",
        free_fmu_state: fmi2FreeFMUstateTYPE = "fmi2FreeFMUstate",
        serialized_fmu_state_size: fmi2SerializedFMUstateSizeTYPE = "fmi2SerializedFMUstateSize",
        serialize_fmu_state: fmi2SerializeFMUstateTYPE = "fmi2SerializeFMUstate",
        deserialize_fmu_state: fmi2DeSerializeFMUstateTYPE = "fmi2DeSerializeFMUstate",
        get_directional_derivative: fmi2GetDirectionalDerivativeTYPE = "fmi2GetDirectionalDerivative",
        set_real_input_derivatives: fmi2SetRealInputDerivativesTYPE = "fmi2SetRealInputDerivatives",
        get_real_output_derivatives: fmi2GetRealOutputDerivativesTYPE = "fmi2GetRealOutputDerivatives",
    }
}

/// The address of `symbol`, if the library exports it.
fn lookup<T: Copy>(library: &libloading::Library, symbol: &str) -> Option<T> {
    // SAFETY: `T` is the function type the FMI standard gives this symbol;
    // the pointer is only used while `library` is loaded (`Library` keeps
    // both together).
    unsafe { library.get::<T>(symbol) }.ok().map(|s| *s)
}

/// A loaded FMU binary. The function pointers stay valid as long as this
/// value lives.
pub struct Library {
    pub(crate) functions: Functions,
    path: PathBuf,
    version: String,
    types_platform: String,
    // Declared last: unloaded after everything else is dropped.
    _library: libloading::Library,
}

impl std::fmt::Debug for Library {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Library")
            .field("path", &self.path)
            .field("version", &self.version)
            .finish_non_exhaustive()
    }
}

impl Library {
    /// Load `binaries/linux64/<modelIdentifier>.so` of the FMU unpacked in
    /// `dir` and resolve its functions against the capabilities `description`
    /// declares.
    pub fn load(dir: &Path, description: &ModelDescription) -> Result<Library, FmuError> {
        let identifier = &description.co_simulation.model_identifier;
        let relative = format!("binaries/{PLATFORM}/{identifier}.so");
        let path = dir.join(&relative);
        if !path.is_file() {
            return Err(FmuError::MissingBinary {
                platform: PLATFORM,
                expected: relative,
                found: platforms(dir),
            });
        }
        Library::load_file(&path, description)
    }

    /// Load the shared library at `path` (see [`Library::load`]).
    pub fn load_file(path: &Path, description: &ModelDescription) -> Result<Library, FmuError> {
        use libloading::os::unix::{Library as UnixLibrary, RTLD_LOCAL, RTLD_NOW};
        // RTLD_NOW: an unresolved dependency fails here, not in mid-run.
        // SAFETY: loading runs the library's initialisers; importing an FMU
        // means trusting its binary to that extent.
        let library: libloading::Library =
            unsafe { UnixLibrary::open(Some(path), RTLD_NOW | RTLD_LOCAL) }
                .map_err(|e| FmuError::LoadLibrary {
                    path: path.to_path_buf(),
                    message: with_execution_tool_hint(error_chain(&e), description),
                })?
                .into();
        let mut functions =
            Functions::resolve(&library).map_err(|symbols| FmuError::MissingFunctions {
                path: path.to_path_buf(),
                symbols,
            })?;
        check_capabilities(&mut functions, description, path)?;

        // SAFETY: both functions take no arguments and return a static string.
        let version = unsafe { c_text((functions.get_version)()) };
        if version.as_bytes() != fmi2Version.to_bytes() {
            return Err(FmuError::WrongFmiVersion {
                path: path.to_path_buf(),
                found: version,
            });
        }
        let types_platform = unsafe { c_text((functions.get_types_platform)()) };
        Ok(Library {
            functions,
            path: path.to_path_buf(),
            version,
            types_platform,
            _library: library,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// What `fmi2GetVersion()` returned ("2.0").
    pub fn version(&self) -> &str {
        &self.version
    }

    /// What `fmi2GetTypesPlatform()` returned ("default" for standard FMUs).
    pub fn types_platform(&self) -> &str {
        &self.types_platform
    }
}

/// Each optional group must be exported if its capability is declared, and
/// is not used (set to `None`) if it is not.
fn check_capabilities(
    f: &mut Functions,
    d: &ModelDescription,
    path: &Path,
) -> Result<(), FmuError> {
    let cs = &d.co_simulation;
    // (capability, declared, [(function, exported)])
    type Group = (&'static str, bool, Vec<(&'static str, bool)>);
    let groups: [Group; 5] = [
        (
            "canGetAndSetFMUstate=\"true\"",
            cs.can_get_and_set_fmu_state,
            vec![
                ("fmi2GetFMUstate", f.get_fmu_state.is_some()),
                ("fmi2SetFMUstate", f.set_fmu_state.is_some()),
                ("fmi2FreeFMUstate", f.free_fmu_state.is_some()),
            ],
        ),
        (
            "canSerializeFMUstate=\"true\"",
            cs.can_serialize_fmu_state,
            vec![
                (
                    "fmi2SerializedFMUstateSize",
                    f.serialized_fmu_state_size.is_some(),
                ),
                ("fmi2SerializeFMUstate", f.serialize_fmu_state.is_some()),
                ("fmi2DeSerializeFMUstate", f.deserialize_fmu_state.is_some()),
            ],
        ),
        (
            "providesDirectionalDerivative=\"true\"",
            cs.provides_directional_derivative,
            vec![(
                "fmi2GetDirectionalDerivative",
                f.get_directional_derivative.is_some(),
            )],
        ),
        (
            "canInterpolateInputs=\"true\"",
            cs.can_interpolate_inputs,
            vec![(
                "fmi2SetRealInputDerivatives",
                f.set_real_input_derivatives.is_some(),
            )],
        ),
        (
            "maxOutputDerivativeOrder > 0",
            cs.max_output_derivative_order > 0,
            vec![(
                "fmi2GetRealOutputDerivatives",
                f.get_real_output_derivatives.is_some(),
            )],
        ),
    ];
    for (capability, declared, symbols) in groups {
        let missing: Vec<&'static str> = symbols
            .iter()
            .filter(|(_, present)| !present)
            .map(|(s, _)| *s)
            .collect();
        if declared && !missing.is_empty() {
            return Err(FmuError::MissingCapabilityFunctions {
                path: path.to_path_buf(),
                capability,
                symbols: missing,
            });
        }
    }
    if !cs.can_get_and_set_fmu_state {
        (f.get_fmu_state, f.set_fmu_state, f.free_fmu_state) = (None, None, None);
    }
    if !cs.can_serialize_fmu_state {
        (
            f.serialized_fmu_state_size,
            f.serialize_fmu_state,
            f.deserialize_fmu_state,
        ) = (None, None, None);
    }
    if !cs.provides_directional_derivative {
        f.get_directional_derivative = None;
    }
    if !cs.can_interpolate_inputs {
        f.set_real_input_derivatives = None;
    }
    if cs.max_output_derivative_order == 0 {
        f.get_real_output_derivatives = None;
    }
    Ok(())
}

/// An error and its sources, e.g. "dlopen failed: <dlerror text>".
fn error_chain(e: &dyn std::error::Error) -> String {
    let mut message = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        message.push_str(": ");
        message.push_str(&s.to_string());
        source = s.source();
    }
    message
}

/// A binary that cannot be loaded on its own often belongs to an FMU that
/// declares `needsExecutionTool="true"` (e.g. one exported by pythonfmu,
/// whose binary expects the Python runtime to be loaded already): say so.
fn with_execution_tool_hint(message: String, description: &ModelDescription) -> String {
    if description.co_simulation.needs_execution_tool {
        format!(
            "{message} (the FMU declares needsExecutionTool=\"true\": its binary needs the runtime of the tool it was exported from{}, loaded into this process)",
            description
                .generation_tool
                .as_deref()
                .map(|t| format!(", {t}"))
                .unwrap_or_default()
        )
    } else {
        message
    }
}

/// A C string returned by the FMU, or "" for null.
///
/// # Safety
/// `s` is null or a NUL-terminated string valid for the call.
pub(crate) unsafe fn c_text(s: *const std::os::raw::c_char) -> String {
    if s.is_null() {
        String::new()
    } else {
        unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned()
    }
}

/// The platform folders under `binaries/` of the FMU unpacked in `dir`, sorted.
pub fn platforms(dir: &Path) -> Vec<String> {
    let mut found: Vec<String> = std::fs::read_dir(dir.join("binaries"))
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .filter(|e| e.path().is_dir())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    found.sort();
    found
}
