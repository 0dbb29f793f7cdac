//! The subcommands of the `fricsim` binary (not part of the library): one
//! module per subcommand, and here the options and helpers they share.
//! The dependencies go one way: [`isolated`] (what `run --isolate` and
//! `cosim --isolate` share) is below [`run`] and [`cosim`], which use it;
//! [`child`] (the hidden `isolated-child`) is above them, and only `main`
//! uses it.

pub mod child;
pub mod compare;
pub mod cosim;
pub mod diagnose;
pub mod info;
pub mod isolated;
pub mod reference;
pub mod run;
pub mod sweep;

use fricsim::ssp::SystemFile;
use std::path::{Path, PathBuf};

/// `--start`, `--stop`, `--step` of the commands that co-simulate a
/// system file (`run`, `sweep`), resolved by [`fricsim::run::time_grid`]. (`reference`
/// has its own, since there `--step` is only the output interval.)
#[derive(clap::Args)]
pub struct GridArgs {
    /// Start time in seconds [default: DefaultExperiment startTime, else 0].
    #[arg(long)]
    pub start: Option<f64>,
    /// Stop time in seconds [default: DefaultExperiment stopTime].
    #[arg(long)]
    pub stop: Option<f64>,
    /// Communication step in seconds: the results are sampled once per
    /// step, and the master steps the FMUs by it, except that `adaptive`
    /// chooses its macro steps inside it and the strong-coupling masters
    /// halve a step that does not converge [default: the file's stepSize
    /// annotation].
    #[arg(long)]
    pub step: Option<f64>,
}

impl GridArgs {
    /// `(start, stop, step)` from these options, else from `file`.
    pub fn resolve(&self, file: &SystemFile) -> Result<(f64, f64, f64), String> {
        fricsim::run::time_grid(file, self.start, self.stop, self.step)
    }
}

/// The master algorithm's name: `--master` if given, else the file's
/// annotation, else jacobi (`fricsim run`, `fricsim sweep`).
pub fn master_name(option: &Option<String>, file: &SystemFile) -> String {
    option
        .clone()
        .unwrap_or_else(|| file.settings.master_or_default())
}

/// `out/<system file stem><suffix>.csv`, the default result file.
pub fn default_out(system: &Path, suffix: &str) -> PathBuf {
    let stem = system
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "system".to_string());
    PathBuf::from("out").join(format!("{stem}{suffix}.csv"))
}

/// `--step-timeout SECONDS` as a duration: a positive, finite number.
pub fn call_time_limit(seconds: Option<f64>) -> Result<Option<std::time::Duration>, String> {
    match seconds {
        None => Ok(None),
        Some(s) if s.is_finite() && s > 0.0 && s < 1e9 => {
            Ok(Some(std::time::Duration::from_secs_f64(s)))
        }
        Some(s) => Err(format!(
            "--step-timeout must be a positive number of seconds, got {s}"
        )),
    }
}

/// What a built system noticed and accepted, on stderr, one line each.
pub fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}
