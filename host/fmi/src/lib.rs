//! The FMU importer: FMI 2.0 Co-Simulation FMUs built by anyone.
//!
//! - [`archive`]: the `.fmu` zip unpacked safely into a temporary directory;
//! - [`model_description`]: `modelDescription.xml` parsed and validated
//!   into types that name no FMI version ([`model_description::fmi2`]
//!   reads FMI 2.0's);
//! - [`fmi2`]: FMI 2.0's raw layer, the binary's functions as a table of
//!   typed pointers with no checks (also used by the misuse tests, the
//!   fuzz targets and the benchmarks' hand-written loop);
//! - [`library`]: the `linux64` binary loaded and its functions resolved;
//! - [`logger`]: the FMU's log messages (callback in `logger.c`);
//! - [`instance`]: [`Fmu`] and its [`Instance`]s, the safe API;
//! - [`watchdog`]: the optional time limit on each call.
//!
//! The C types of the standard are those of `fmi2-types`, the crate the
//! exporter of this repository (`fmi2-cs`) uses too; the host depends on
//! that crate alone, not on the exporter. Where FMI 3.0 will join: the
//! crate's README.

pub mod archive;
pub mod blackbox;
pub mod error;
pub mod fmi2;
pub mod instance;
pub mod library;
pub mod logger;
pub mod model_description;
pub mod shared_memory;
pub mod stale;
mod status;
pub mod watchdog;
pub mod xml_text;

pub use archive::UnpackOptions;
pub use error::{ArchiveProblem, FmuError};
pub use instance::{Fmu, FmuState, Instance, Rollback};
pub use library::Library;
pub use logger::{Log, LogMessage};
pub use model_description::{
    Causality, CoSimulation, DefaultExperiment, Initial, ModelDescription, ScalarVariable,
    ValueReference, Variability, Variable, VariableKind,
};
pub use status::Status;
