//! Everything that can go wrong when importing and running an FMU. Each
//! variant carries the values needed to say what failed and where; the
//! message is written once, here.

use crate::Status;
use std::path::PathBuf;
use thiserror::Error;

/// Why an archive was refused (see [`crate::archive`]).
#[derive(Debug, Error)]
pub enum ArchiveProblem {
    #[error("not a readable zip archive: {0}")]
    NotAZip(String),
    #[error("the entry name contains a `..` component (path traversal)")]
    ParentComponent,
    #[error("the entry name is an absolute path")]
    AbsolutePath,
    #[error("the entry name has a Windows drive prefix")]
    DrivePrefix,
    #[error("the entry name contains a NUL character")]
    NulInName,
    #[error("the entry is a symbolic link")]
    Symlink,
    #[error("the entry name occurs more than once")]
    Duplicate,
    #[error("the entry unpacks to more than the limit of {limit} bytes")]
    EntryTooLarge { limit: u64 },
    #[error("the archive unpacks to more than the limit of {limit} bytes in total")]
    TotalTooLarge { limit: u64 },
    #[error("the archive has {count} entries, more than the limit of {limit}")]
    TooManyEntries { count: usize, limit: usize },
    #[error("the archive has no modelDescription.xml at its root")]
    MissingModelDescription,
    #[error("the archive has no {name} at its root")]
    MissingRootEntry { name: String },
    #[error("cannot read the entry: {0}")]
    Corrupt(String),
    #[error("cannot write the entry: {0}")]
    Write(std::io::Error),
}

/// Errors of the importer. Display gives a complete, one-line message.
#[derive(Debug, Error)]
pub enum FmuError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// The `.fmu` at `path` was unpacked, but its model description or its
    /// binary was refused for the reason in `source`.
    #[error("{}: {source}", path.display())]
    InFmu {
        path: PathBuf,
        #[source]
        source: Box<FmuError>,
    },

    /// An archive was refused; `entry` names the offending entry if there is one.
    #[error("{path}: {}{problem}", entry.as_ref().map(|e| format!("entry \"{e}\": ")).unwrap_or_default())]
    Archive {
        path: PathBuf,
        entry: Option<String>,
        problem: ArchiveProblem,
    },

    /// modelDescription.xml is not well-formed XML or does not match the
    /// FMI 2.0 schema; `line` and `column` (1-based) locate the problem.
    #[error("modelDescription.xml:{line}:{column}: {message}")]
    XmlSyntax {
        line: usize,
        column: usize,
        message: String,
    },

    #[error(
        "modelDescription.xml: fmiVersion is \"{found}\", but only FMI 2.0 and 3.0 are supported"
    )]
    UnsupportedFmiVersion { found: String },

    /// An instance of one FMI version asked of an FMU of another (e.g.
    /// [`crate::Instance`], FMI 2.0's, of an FMI 3.0 FMU).
    #[error("model \"{model}\" is an FMI {fmi_version} FMU: instantiate it with the instance type of that version (Fmu::instantiate for FMI 2.0, Fmu::instantiate_fmi3 for FMI 3.0)")]
    WrongInstanceType { model: String, fmi_version: String },

    #[error("modelDescription.xml: not a co-simulation FMU (it has no <CoSimulation> element)")]
    NotCoSimulation,

    /// The description is well-formed but breaks a rule of the standard;
    /// `location` says where (e.g. `variable "F" (index 4)`).
    #[error("modelDescription.xml: {location}: {message}")]
    InvalidModelDescription { location: String, message: String },

    #[error(
        "FMU has no binary for {platform}: expected {expected}; it has: {}",
        list_or_none(found)
    )]
    MissingBinary {
        platform: &'static str,
        expected: String,
        found: Vec<String>,
    },

    #[error("cannot load {path} as a shared library: {message}")]
    LoadLibrary { path: PathBuf, message: String },

    #[error("{path} does not export the required FMI functions: {}", symbols.join(", "))]
    MissingFunctions {
        path: PathBuf,
        symbols: Vec<&'static str>,
    },

    #[error("{path}: modelDescription.xml declares {capability}, but the binary does not export {}", symbols.join(", "))]
    MissingCapabilityFunctions {
        path: PathBuf,
        capability: &'static str,
        symbols: Vec<&'static str>,
    },

    #[error("{path}: fmi{}GetVersion() returned \"{found}\", expected \"{expected}\"", &expected[..1])]
    WrongFmiVersion {
        path: PathBuf,
        expected: &'static str,
        found: String,
    },

    #[error("no variable named \"{name}\" in model {model}")]
    UnknownVariable { name: String, model: String },

    #[error("{function} is not available: the FMU does not declare {capability}")]
    NotSupported {
        function: &'static str,
        capability: &'static str,
    },

    #[error(
        "fmi2Instantiate failed for instance \"{instance}\"{}",
        log_suffix(messages)
    )]
    Instantiate {
        instance: String,
        messages: Vec<String>,
    },

    /// A call took longer than the limit set with
    /// [`Instance::set_call_time_limit`](crate::Instance::set_call_time_limit)
    /// (`--step-timeout`); its result is not used.
    #[error(
        "{function} for instance \"{instance}\" took {elapsed:.3} s, longer than the limit of {limit} s (--step-timeout); its result is not used"
    )]
    TimeLimit {
        function: &'static str,
        instance: String,
        elapsed: f64,
        limit: f64,
    },

    /// An FMU function returned Discard, Error, Fatal or Pending;
    /// `messages` are what the instance logged during the call.
    #[error(
        "{function} failed for instance \"{instance}\" with {}{}",
        status.named_for(function),
        log_suffix(messages)
    )]
    Call {
        function: &'static str,
        instance: String,
        status: Status,
        messages: Vec<String>,
    },

    /// A step after which the FMU asks to end the simulation (FMI 3.0's
    /// `terminateSimulation`): the normal end of a run, not a failure, for
    /// a master that takes it so.
    #[error("{instance} asks to end the simulation at t = {time} ({function} returned terminateSimulation = true)")]
    EndedSimulation {
        function: &'static str,
        instance: String,
        time: f64,
    },

    /// `fmi3DoStep` ended before the step's end without being allowed to
    /// (the instance was made with `earlyReturnAllowed = false`), or said
    /// it did: the FMU broke the standard's contract (FMI 3.0.1 §4.2.1).
    #[error("fmi3DoStep of instance \"{instance}\" from t = {from} over {step} returned early (earlyReturn = {early_return}, lastSuccessfulTime = {reached}), which fricsim does not allow (earlyReturnAllowed = false): the step's results cannot be used")]
    EarlyReturn {
        instance: String,
        from: f64,
        step: f64,
        early_return: bool,
        reached: f64,
    },

    #[error("{function} refused for instance \"{instance}\": an earlier call returned {}Fatal, so the FMU may not be called again", &function[..4])]
    AfterFatal {
        function: &'static str,
        instance: String,
    },

    #[error("{function}: {what} has length {found}, expected {expected}")]
    LengthMismatch {
        function: &'static str,
        what: &'static str,
        expected: usize,
        found: usize,
    },

    /// An FMI 3.0 value that the variable's type and the core's kind do
    /// not both hold (a `UInt8` set to 300, an `Int64` beyond what an
    /// `f64` holds exactly): refused, not rounded or wrapped.
    #[error("{function} for instance \"{instance}\": variable {variable} ({type_name}) {problem}")]
    ValueConversion {
        function: &'static str,
        instance: String,
        /// `"name"` in quotes, or `with value reference …`.
        variable: String,
        type_name: &'static str,
        problem: String,
    },

    #[error("{function}: the FMU state belongs to another instance than \"{instance}\"")]
    ForeignState {
        function: &'static str,
        instance: String,
    },

    #[error("{function} for instance \"{instance}\" returned success but a null {what}")]
    NullPointer {
        function: &'static str,
        instance: String,
        what: &'static str,
    },

    #[error("strong coupling did not converge at t = {time} (step {step}) after {iterations} iterations: {connection} still differs by {mismatch:e} (input {input:e}, output {output:e}; tolerance {tolerance:e}, scaled residual norm {residual:e}); the step is not accepted")]
    NotConverged {
        time: f64,
        step: f64,
        iterations: usize,
        /// The connection with the largest mismatch relative to its tolerance.
        connection: String,
        /// `|U_k − Y_k|` of that connection.
        mismatch: f64,
        input: f64,
        output: f64,
        /// Its tolerance `atol·nominal + rtol·max(|U_k|, |Y_k|)`.
        tolerance: f64,
        /// Euclidean norm over all connections of `|U_k − Y_k| / tolerance_k`.
        residual: f64,
    },

    #[error("{master} cannot run instance \"{instance}\" (model {model}): its FMU does not declare {capability}: {reason}")]
    MissingCapability {
        master: &'static str,
        instance: String,
        model: String,
        capability: &'static str,
        reason: &'static str,
    },

    #[error("{what} must not contain a NUL character: {value:?}")]
    NulInString { what: &'static str, value: String },
}

impl FmuError {
    /// The status of a failed FMU call, if this error is one.
    pub fn status(&self) -> Option<Status> {
        match self {
            FmuError::Call { status, .. } => Some(*status),
            _ => None,
        }
    }
}

fn list_or_none(items: &[String]) -> String {
    if items.is_empty() {
        "no binaries".to_string()
    } else {
        items.join(", ")
    }
}

fn log_suffix(messages: &[String]) -> String {
    if messages.is_empty() {
        " (the FMU logged nothing)".to_string()
    } else {
        format!(": {}", messages.join(" | "))
    }
}
