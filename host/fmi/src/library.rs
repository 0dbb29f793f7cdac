//! The FMU's shared library loaded with libloading, and its
//! Co-Simulation functions resolved into typed pointers: FMI 2.0's
//! (FMI 2.0.4 §2.4: `binaries/linux64/<modelIdentifier>.so`; §2.1, §4.2)
//! into [`crate::fmi2::Functions`], FMI 3.0's (FMI 3.0.1 §2.5.1:
//! `binaries/x86_64-linux/<modelIdentifier>.so`; §2.3, §4) into
//! [`crate::fmi3::Functions`], by the model description's `fmiVersion`.
//!
//! Every function of the common and co-simulation API the host calls is
//! required; the optional groups (FMU state, directional derivatives,
//! input and output derivatives) are used only when the model description
//! declares the capability, and then they must be there.

use super::model_description::ModelDescription;
use crate::error::FmuError;
use crate::fmi2::{fmi2Version, Functions};
use crate::fmi3;
use std::ffi::CStr;
use std::path::{Path, PathBuf};

/// The only platform this host loads, as FMI 2.0 names it.
pub const PLATFORM: &str = "linux64";
/// The same platform as FMI 3.0 names it (architecture-OS, §2.5.1.1).
pub const PLATFORM_FMI3: &str = "x86_64-linux";

/// The raw table of a binary, of its FMI version.
#[derive(Clone, Copy)]
pub(crate) enum Api {
    Fmi2(Functions),
    Fmi3(fmi3::Functions),
}

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
    pub(crate) api: Api,
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
        let platform = if description.is_fmi3() {
            PLATFORM_FMI3
        } else {
            PLATFORM
        };
        let identifier = &description.co_simulation.model_identifier;
        let relative = format!("binaries/{platform}/{identifier}.so");
        let path = dir.join(&relative);
        if !path.is_file() {
            return Err(FmuError::MissingBinary {
                platform,
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
        if description.is_fmi3() {
            return Library::resolve_fmi3(library, path, description);
        }
        // SAFETY: an FMI 2.0 binary (its version is checked below), kept
        // loaded with the table in this `Library`.
        let functions =
            unsafe { Functions::load(&library) }.map_err(|symbols| FmuError::MissingFunctions {
                path: path.to_path_buf(),
                symbols,
            })?;
        let declared =
            check_capabilities(description, path, &|s| functions.exports(s), FMI2_GROUPS)?;

        // SAFETY: both functions take no arguments and return a static string.
        let version = unsafe { c_text((functions.get_version)()) };
        if version.as_bytes() != fmi2Version.to_bytes() {
            return Err(FmuError::WrongFmiVersion {
                path: path.to_path_buf(),
                expected: "2.0",
                found: version,
            });
        }
        let types_platform = unsafe { c_text((functions.get_types_platform)()) };
        Ok(Library {
            api: Api::Fmi2(functions),
            declared,
            path: path.to_path_buf(),
            version,
            types_platform,
            _library: library,
        })
    }

    /// [`Library::load_file`] of an FMI 3.0 binary.
    fn resolve_fmi3(
        library: libloading::Library,
        path: &Path,
        description: &ModelDescription,
    ) -> Result<Library, FmuError> {
        // SAFETY: an FMI 3.0 binary (its version is checked below), kept
        // loaded with the table in this `Library`.
        let functions = unsafe { fmi3::Functions::load(&library) }.map_err(|symbols| {
            FmuError::MissingFunctions {
                path: path.to_path_buf(),
                symbols,
            }
        })?;
        let declared =
            check_capabilities(description, path, &|s| functions.exports(s), FMI3_GROUPS)?;
        check_value_types(description, path, &functions)?;
        // SAFETY: no arguments, returns a static string.
        let version = unsafe { c_text((functions.get_version)()) };
        // "3.0", or a later minor version of 3 ("3.0.1" is still "3.0"'s ABI)
        if !(version == "3.0" || version.starts_with("3.")) {
            return Err(FmuError::WrongFmiVersion {
                path: path.to_path_buf(),
                expected: "3.0",
                found: version,
            });
        }
        Ok(Library {
            api: Api::Fmi3(functions),
            declared,
            path: path.to_path_buf(),
            version,
            types_platform: String::new(),
            _library: library,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The binary's functions, raw, if it is an FMI 2.0 binary: FMI 2.0's
    /// table, valid as long as this `Library` lives. Calling them is
    /// unchecked and `unsafe`; the safe way is an
    /// [`Instance`](crate::Instance). (The hand-written FMI loop of the
    /// benchmarks calls them.) An optional function the model description
    /// does not declare may be a stand-in ([`Functions::exports`]).
    pub fn functions(&self) -> Option<&Functions> {
        match &self.api {
            Api::Fmi2(f) => Some(f),
            Api::Fmi3(_) => None,
        }
    }

    /// FMI 3.0's table, if it is an FMI 3.0 binary (see [`Library::functions`]).
    pub fn fmi3_functions(&self) -> Option<&fmi3::Functions> {
        match &self.api {
            Api::Fmi3(f) => Some(f),
            Api::Fmi2(_) => None,
        }
    }

    /// What `fmi2GetVersion()` or `fmi3GetVersion()` returned ("2.0", "3.0").
    pub fn version(&self) -> &str {
        &self.version
    }

    /// What `fmi2GetTypesPlatform()` returned ("default" for standard
    /// FMUs; "" for FMI 3.0, which has no such function).
    pub fn types_platform(&self) -> &str {
        &self.types_platform
    }
}

/// An optional group of functions: the capability that declares it, and
/// its symbols, of each FMI version.
type Group = (&'static str, fn(&Declared) -> bool, &'static [&'static str]);

const FMI2_GROUPS: &[Group] = &[
    (
        "canGetAndSetFMUstate=\"true\"",
        |d| d.fmu_state,
        &["fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate"],
    ),
    (
        "canSerializeFMUstate=\"true\"",
        |d| d.serialize_fmu_state,
        &[
            "fmi2SerializedFMUstateSize",
            "fmi2SerializeFMUstate",
            "fmi2DeSerializeFMUstate",
        ],
    ),
    (
        "providesDirectionalDerivative=\"true\"",
        |d| d.directional_derivative,
        &["fmi2GetDirectionalDerivative"],
    ),
    (
        "canInterpolateInputs=\"true\"",
        |d| d.input_derivatives,
        &["fmi2SetRealInputDerivatives"],
    ),
    (
        "maxOutputDerivativeOrder > 0",
        |d| d.output_derivatives,
        &["fmi2GetRealOutputDerivatives"],
    ),
];

const FMI3_GROUPS: &[Group] = &[
    (
        "canGetAndSetFMUState=\"true\"",
        |d| d.fmu_state,
        &["fmi3GetFMUState", "fmi3SetFMUState", "fmi3FreeFMUState"],
    ),
    (
        "canSerializeFMUState=\"true\"",
        |d| d.serialize_fmu_state,
        &[
            "fmi3SerializedFMUStateSize",
            "fmi3SerializeFMUState",
            "fmi3DeserializeFMUState",
        ],
    ),
    (
        "providesDirectionalDerivatives=\"true\"",
        |d| d.directional_derivative,
        &["fmi3GetDirectionalDerivative"],
    ),
    (
        "maxOutputDerivativeOrder > 0",
        |d| d.output_derivatives,
        &["fmi3GetOutputDerivatives"],
    ),
];

/// Each optional group must be exported (`exports`) if its capability is
/// declared; the groups declared.
fn check_capabilities(
    d: &ModelDescription,
    path: &Path,
    exports: &dyn Fn(&str) -> bool,
    groups: &[Group],
) -> Result<Declared, FmuError> {
    let cs = &d.co_simulation;
    let declared = Declared {
        fmu_state: cs.can_get_and_set_fmu_state,
        serialize_fmu_state: cs.can_serialize_fmu_state,
        directional_derivative: cs.provides_directional_derivative,
        // FMI 3.0 Co-Simulation has no input derivatives
        input_derivatives: cs.can_interpolate_inputs && !d.is_fmi3(),
        output_derivatives: cs.max_output_derivative_order > 0,
    };
    for (capability, is_declared, symbols) in groups {
        let missing: Vec<&'static str> = symbols.iter().copied().filter(|s| !exports(s)).collect();
        if is_declared(&declared) && !missing.is_empty() {
            return Err(FmuError::MissingCapabilityFunctions {
                path: path.to_path_buf(),
                capability,
                symbols: missing,
            });
        }
    }
    Ok(declared)
}

/// Each FMI 3.0 type of the description's variables whose getter and
/// setter a binary may leave out for fricsim (`Float32`, the integers but
/// `Int32`, `Enumeration` as `Int64`) must have them exported.
fn check_value_types(
    d: &ModelDescription,
    path: &Path,
    functions: &fmi3::Functions,
) -> Result<(), FmuError> {
    let mut checked = Vec::new();
    for t in d.variables.iter().filter_map(|v| v.fmi3_type) {
        if checked.contains(&t) {
            continue;
        }
        checked.push(t);
        if let Some((capability, symbols)) = crate::instance3::optional_functions(t) {
            let missing: Vec<&'static str> = symbols
                .into_iter()
                .filter(|s| !functions.exports(s))
                .collect();
            if !missing.is_empty() {
                return Err(FmuError::MissingCapabilityFunctions {
                    path: path.to_path_buf(),
                    capability,
                    symbols: missing,
                });
            }
        }
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
