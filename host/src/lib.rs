//! `fricsim`: a co-simulation host for FMI 2.0 Co-Simulation FMUs.
//!
//! The host imports FMUs that anyone built — it does not link against the
//! FMUs of this repository, only against the FMI 2.0 C ABI. Importing is
//! [`fmu`]: the `.fmu` archive is unpacked with limits and path checks, its
//! `modelDescription.xml` is parsed and validated, its `linux64` binary is
//! loaded and every FMI function resolved, and each [`fmu::Instance`] wraps
//! the C API in safe methods that turn every non-OK status into an
//! [`FmuError`] carrying what the FMU logged.
//!
//! ```no_run
//! use fricsim::fmu::Fmu;
//! let fmu = Fmu::open("dist/LuGre.fmu")?;
//! let (v, f) = (fmu.variable("v")?.value_reference, fmu.variable("F")?.value_reference);
//! let mut lugre = fmu.instantiate("lugre")?;
//! lugre.setup_experiment(0.0, None)?;
//! lugre.enter_initialization_mode()?;
//! lugre.exit_initialization_mode()?;
//! lugre.set_real(&[v], &[1e-3])?;
//! lugre.do_step(0.0, 1e-3)?;
//! let mut force = [0.0];
//! lugre.get_real(&[f], &mut force)?;
//! # Ok::<(), fricsim::FmuError>(())
//! ```

pub mod compare;
pub mod error;
pub mod fmu;
pub mod inputs;
pub mod isolate;
pub mod master;
pub mod matfile;
pub mod output_file;
pub mod plot;
pub mod reference;
pub mod results;
pub mod rows;
pub mod run;
pub mod signals;
pub mod ssp;
pub mod stale;
pub mod sweep;
pub mod system;
pub mod writer_thread;

pub use error::{ArchiveProblem, FmuError};
pub mod diagnose;
