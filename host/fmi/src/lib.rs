//! The FMU importer: FMI 2.0 and FMI 3.0 Co-Simulation FMUs built by anyone.
//!
//! - [`archive`]: the `.fmu` zip unpacked safely into a temporary directory;
//! - [`model_description`]: `modelDescription.xml` parsed and validated
//!   into types that name no FMI version ([`model_description::fmi2`]
//!   reads FMI 2.0's, [`model_description::fmi3`] FMI 3.0's, its arrays
//!   as their elements);
//! - [`fmi2`], [`fmi3`]: each version's raw layer, the binary's functions
//!   as a table of typed pointers with no checks (FMI 2.0's is also used by
//!   the misuse tests, the fuzz targets and the benchmarks' hand-written
//!   loop), both built by one macro (`function_table.rs`);
//! - [`library`]: the binary (`linux64`, FMI 3.0's `x86_64-linux`)
//!   loaded and its functions resolved into the table of its version;
//! - [`logger`]: the FMU's log messages (callbacks in `logger.c` for FMI
//!   2.0, whose logger is variadic, and in Rust for FMI 3.0);
//! - [`instance`]: [`Fmu`] and its FMI 2.0 [`Instance`]s, the safe API;
//!   [`instance3`]: FMI 3.0's [`Fmi3Instance`], which also takes the
//!   elements of arrays and the types the core holds in another kind to
//!   where the FMU holds them (`instance3/values.rs`); both call through
//!   one guard (`guard.rs`: statuses, messages, time limit, black box);
//! - [`watchdog`]: the optional time limit on each call.
//!
//! The C types of the standards are those of `fmi2-types` and
//! `fmi3-types`: the exporter of this repository (`fmi-export`) uses the
//! first too; the host depends on these crates alone, not on the
//! exporter. How FMI 3.0 came in and what is still to come: the crate's
//! README.

#[macro_use]
mod function_table;

pub mod archive;
pub mod blackbox;
pub mod error;
pub mod fmi2;
pub mod fmi3;
mod guard;
pub mod instance;
pub mod instance3;
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
pub use instance3::{Fmi3Instance, StepOutcome};
pub use library::Library;
pub use logger::{Log, LogMessage};
pub use model_description::{
    Array, Causality, CoSimulation, DefaultExperiment, Fmi3Type, Initial, ModelDescription,
    ScalarVariable, ValueReference, Variability, Variable, VariableKind,
};
pub use status::Status;
