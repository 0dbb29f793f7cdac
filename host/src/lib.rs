//! `fricsim`: a co-simulation host for FMI 2.0 Co-Simulation FMUs.
//!
//! The host imports FMUs that anyone built. Importing is [`fmu`], the
//! crate `fricsim-fmi` (`host/fmi`), which links against no FMU of this
//! repository, only against the FMI 2.0 C ABI (the types of `fmi2-types`):
//! the `.fmu` archive is unpacked with limits and path checks, its
//! `modelDescription.xml` is parsed and validated, its `linux64` binary is
//! loaded and every FMI function resolved, and each [`fmu::Instance`] wraps
//! the C API in safe methods that turn every non-OK status into an
//! [`FmuError`] carrying what the FMU logged. (`fricsim-core` links the
//! laws through `fricsim-reference`, for the monolithic reference
//! solutions of `fricsim reference`, never to co-simulate.)
//!
//! The crates, each usable on its own:
//!
//! - `fricsim-fmi` (`host/fmi`): the importer, here [`fmu`];
//! - `fricsim-core` (`host/core`): systems, masters, inputs, result files,
//!   isolation, sweeps, plots ([`system`], [`master`], [`results`], ...);
//! - `fricsim-diagnose` (`host/diagnose`): the diagnosis, here
//!   [`diagnose`];
//! - this crate, `fricsim`: the `fricsim` binary, and the modules of the
//!   crates above under the paths they had when they were one crate.
//!
//! The diagnosis's generated test data are `fricsim-hidden-effects`
//! (`host/hidden-effects`), which the binary does not contain.
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

pub use fricsim_core::{
    compare, csvfile, error, fmu, formats, inputs, isolate, master, matfile, output_file, plot,
    reference, results, rows, run, signals, ssp, stale, sweep, system, time_grid, writer_thread,
};
pub use fricsim_core::{ArchiveProblem, FmuError};
/// The diagnosis, the crate `fricsim-diagnose` (`host/diagnose`).
pub use fricsim_diagnose as diagnose;
