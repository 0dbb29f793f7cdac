//! The FMU's shared library (FMI 2.0.4 §2.4: `binaries/<platform>/
//! <modelIdentifier>.so`) loaded with libloading, and its FMI 2.0
//! Co-Simulation functions (§2.1, §4.2) resolved into typed pointers.
//!
//! The functions are looked up into FMI 2.0's raw table
//! ([`crate::fmi2::Functions`]). Every function of the common and
//! co-simulation API is required; the optional groups (FMU state §2.1.8,
//! directional derivatives §2.1.9, input and output derivatives §4.2.1)
//! are used only when the model description declares the capability, and
//! then they must be there.

use super::model_description::ModelDescription;
use crate::error::FmuError;
use crate::fmi2::{fmi2Version, Functions};
use std::ffi::CStr;
use std::path::{Path, PathBuf};

/// The only platform this host loads.
pub const PLATFORM: &str = "linux64";

/// The optional groups of functions the model description declares
/// (and which the binary therefore exports): a function of a group not
/// declared is refused by the instance, [`FmuError::NotSupported`], even
/// if the binary has it.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Declared {
    /// `canGetAndSetFMUstate`: `fmi2GetFMUstate`, `fmi2SetFMUstate`, `fmi2FreeFMUstate`.
    pub fmu_state: bool,
    /// `canSerializeFMUstate`: `fmi2SerializedFMUstateSize`, `fmi2SerializeFMUstate`,
    /// `fmi2DeSerializeFMUstate`.
    pub serialize_fmu_state: bool,
    /// `providesDirectionalDerivative`: `fmi2GetDirectionalDerivative`.
    pub directional_derivative: bool,
    /// `canInterpolateInputs`: `fmi2SetRealInputDerivatives`.
    pub input_derivatives: bool,
    /// `maxOutputDerivativeOrder > 0`: `fmi2GetRealOutputDerivatives`.
    pub output_derivatives: bool,
}

/// A loaded FMU binary. The function pointers stay valid as long as this
/// value lives.
pub struct Library {
    pub(crate) functions: Functions,
    pub(crate) declared: Declared,
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
        // before looking for the binary: FMI 3.0 keeps it elsewhere
        // (binaries/x86_64-linux)
        refuse_fmi3(description)?;
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
        refuse_fmi3(description)?;
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
        // SAFETY: an FMI 2.0 binary (its version is checked below), kept
        // loaded with the table in this `Library`.
        let functions =
            unsafe { Functions::load(&library) }.map_err(|symbols| FmuError::MissingFunctions {
                path: path.to_path_buf(),
                symbols,
            })?;
        let declared = check_capabilities(&functions, description, path)?;

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
            declared,
            path: path.to_path_buf(),
            version,
            types_platform,
            _library: library,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The binary's functions, raw: FMI 2.0's table, valid as long as
    /// this `Library` lives. Calling them is unchecked and `unsafe`; the
    /// safe way is an [`Instance`](crate::Instance). (The hand-written
    /// FMI loop of the benchmarks calls them.) An optional function the
    /// model description does not declare may be a stand-in
    /// ([`Functions::exports`]).
    pub fn functions(&self) -> &Functions {
        &self.functions
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

/// Each optional group must be exported if its capability is declared;
/// the groups declared.
fn check_capabilities(
    f: &Functions,
    d: &ModelDescription,
    path: &Path,
) -> Result<Declared, FmuError> {
    let cs = &d.co_simulation;
    let declared = Declared {
        fmu_state: cs.can_get_and_set_fmu_state,
        serialize_fmu_state: cs.can_serialize_fmu_state,
        directional_derivative: cs.provides_directional_derivative,
        input_derivatives: cs.can_interpolate_inputs,
        output_derivatives: cs.max_output_derivative_order > 0,
    };
    // (capability, declared, its functions)
    let groups: [(&'static str, bool, &[&'static str]); 5] = [
        (
            "canGetAndSetFMUstate=\"true\"",
            declared.fmu_state,
            &["fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate"],
        ),
        (
            "canSerializeFMUstate=\"true\"",
            declared.serialize_fmu_state,
            &[
                "fmi2SerializedFMUstateSize",
                "fmi2SerializeFMUstate",
                "fmi2DeSerializeFMUstate",
            ],
        ),
        (
            "providesDirectionalDerivative=\"true\"",
            declared.directional_derivative,
            &["fmi2GetDirectionalDerivative"],
        ),
        (
            "canInterpolateInputs=\"true\"",
            declared.input_derivatives,
            &["fmi2SetRealInputDerivatives"],
        ),
        (
            "maxOutputDerivativeOrder > 0",
            declared.output_derivatives,
            &["fmi2GetRealOutputDerivatives"],
        ),
    ];
    for (capability, declared, symbols) in groups {
        let missing: Vec<&'static str> =
            symbols.iter().copied().filter(|s| !f.exports(s)).collect();
        if declared && !missing.is_empty() {
            return Err(FmuError::MissingCapabilityFunctions {
                path: path.to_path_buf(),
                capability,
                symbols: missing,
            });
        }
    }
    Ok(declared)
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

/// An FMI 3.0 FMU is described ([`ModelDescription`] reads it) but not
/// run: its functions are `fmi3…`, with other signatures.
fn refuse_fmi3(description: &ModelDescription) -> Result<(), FmuError> {
    if description.fmi_version.trim() == "3.0" {
        return Err(FmuError::Fmi3NotRunnable {
            model: description.model_name.clone(),
        });
    }
    Ok(())
}
