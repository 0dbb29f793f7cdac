//! `fricsim-core`: the co-simulation core of `fricsim`. A system of FMUs
//! read from an SSP file ([`ssp`]) and built with checked connections
//! ([`system`]), stepped by a master algorithm ([`master`]: Jacobi,
//! Gauss–Seidel, strong coupling) on the communication points of
//! [`time_grid`], with inputs from a table ([`inputs`]),
//! its rows recorded ([`rows`]) and written as CSV or MAT files, the
//! format chosen in one place ([`formats`]; [`results`], [`csvfile`],
//! [`matfile`], [`output_file`], on a second core:
//! [`writer_thread`]), a run stopped cleanly by a signal ([`signals`]) or
//! isolated in a child process ([`isolate`]); sweeps ([`sweep`]), plots
//! ([`plot`]), comparisons of result files ([`compare`]) and the monolithic
//! reference solutions ([`mod@reference`]). The FMUs are imported by
//! `fricsim-fmi`, here [`fmu`].

pub mod compare;
pub mod csvfile;
/// The FMU importer, the crate `fricsim-fmi` (`host/fmi`).
pub use fricsim_fmi as fmu;
pub use fricsim_fmi::error;
pub mod formats;
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
pub use fricsim_fmi::stale;
pub mod sweep;
pub mod system;
pub mod time_grid;
pub mod writer_thread;

pub use error::{ArchiveProblem, FmuError};
