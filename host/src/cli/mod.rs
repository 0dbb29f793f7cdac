//! The subcommands of the `fricsim` binary (not part of the library).

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
/// system file (`run`, `sweep`), resolved by [`time_grid`]. (`reference`
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
        time_grid(file, self.start, self.stop, self.step)
    }
}

/// The master algorithm's name: `--master` if given, else the file's
/// annotation, else jacobi (`fricsim run`, `fricsim sweep`).
pub fn master_name(option: &Option<String>, file: &SystemFile) -> String {
    option
        .clone()
        .unwrap_or_else(|| file.settings.master_or_default())
}

/// The time grid of a run of `file`: `--start`, `--stop` and `--step` where
/// given, else the file's `DefaultExperiment` and stepSize annotation
/// (start defaults to 0). Shared by `fricsim run` and `fricsim reference`,
/// so that both produce the same times.
pub fn time_grid(
    file: &SystemFile,
    start: Option<f64>,
    stop: Option<f64>,
    step: Option<f64>,
) -> Result<(f64, f64, f64), String> {
    let start = match start {
        Some(s) if !s.is_finite() => return Err(format!("--start must be finite, got {s}")),
        Some(s) => s,
        None => file.start_time.unwrap_or(0.0),
    };
    let stop = stop.or(file.stop_time).ok_or_else(|| {
        format!(
            "{}: no stop time: give --stop or <ssd:DefaultExperiment stopTime=\"…\">",
            file.ssd
        )
    })?;
    if !(stop.is_finite() && stop > start) {
        return Err(format!(
            "the stop time {stop} must be after the start time {start}"
        ));
    }
    let step = step.or(file.settings.step_size).ok_or_else(|| {
        format!(
            "{}: no step size: give --step or the stepSize of the fricsim annotation (see docs/user-guide.md, \"Our annotation\")",
            file.ssd
        )
    })?;
    if !(step.is_finite() && step > 0.0) {
        return Err(format!("--step must be a positive number, got {step}"));
    }
    Ok((start, stop, step))
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
