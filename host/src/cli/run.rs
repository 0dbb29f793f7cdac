//! `fricsim run SYSTEM.ssp|SYSTEM.ssd`: read a system file (SSP 1.0,
//! [`fricsim::ssp`]), check it against its FMUs, co-simulate it with a
//! fixed macro step, write a CSV and optionally a plot, print a summary.
//! Settings come from the command line, else from the file
//! (`DefaultExperiment`, our annotation), else from defaults.

use fricsim::inputs::InputTable;
use fricsim::output_file::OutputFile;
use fricsim::results::ResultWriter;
use fricsim::run::{PreparedRun, RunOptions, RunOutcome};
use fricsim::ssp::SystemFile;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct RunArgs {
    /// The system: an .ssp archive or a SystemStructure .ssd file.
    pub system: PathBuf,
    #[command(flatten)]
    pub grid: super::GridArgs,
    /// Master algorithm: jacobi, gauss-seidel, gauss-seidel-interpolated,
    /// newton, newton-interpolated, adaptive, fixed-point [default: the
    /// file's annotation, else jacobi].
    #[arg(long)]
    pub master: Option<String>,
    /// Result CSV [default: out/<file name>.csv].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Plot of the chosen signals (.png or .svg) [default: no plot; the
    /// file's Plot annotation only chooses the signals].
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// A signal to plot, component.variable (repeat) [default: the file's
    /// Plot annotation, else every recorded column].
    #[arg(long = "plot-signal")]
    pub plot_signals: Vec<String>,
    /// Record a Real variable besides the outputs, component.variable
    /// (repeat): e.g. a connected input.
    #[arg(long = "record")]
    pub record: Vec<String>,
    /// External inputs: CSV with `time` first, then component.variable
    /// columns for unconnected inputs (bare names for a one-component
    /// system), interpolated linearly in time as FMPy does.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Time limit on each FMI call, in seconds: a call that takes longer
    /// stops the run (rows so far kept, marked incomplete) naming the
    /// instance and the call; a running call cannot be interrupted, a
    /// watchdog reports it on stderr when it passes the limit.
    #[arg(long = "step-timeout", value_name = "SECONDS")]
    pub step_timeout: Option<f64>,
}

pub fn run(a: &RunArgs) -> Result<(), String> {
    let file = SystemFile::open(&a.system).map_err(|e| e.to_string())?;
    // the result file is claimed before the FMUs are opened: a run that
    // would overwrite an input or another run's result stops here
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| super::default_out(&a.system, ""));
    let mut inputs = file.files_read();
    inputs.extend(a.input.as_deref().map(|p| ("the --input table", p)));
    inputs.extend(a.plot.as_deref().map(|p| ("the plot", p)));
    let output = OutputFile::create(&out, &inputs).map_err(|e| e.to_string())?;
    let plot_signals = if !a.plot_signals.is_empty() {
        a.plot_signals.clone()
    } else {
        file.settings.plot.clone()
    };
    let options = RunOptions {
        start: a.grid.start,
        stop: a.grid.stop,
        step: a.grid.step,
        master: a.master.clone(),
        record: a.record.iter().chain(&plot_signals).cloned().collect(),
        inputs: match &a.input {
            Some(path) => Some(InputTable::read(path)?),
            None => None,
        },
        call_time_limit: super::call_time_limit(a.step_timeout)?,
        ..RunOptions::default()
    };
    let prepared = PreparedRun::new(&file, &options)?;
    super::print_warnings(prepared.warnings());
    let (n, step) = (prepared.steps(), prepared.time_grid().2);
    let master = prepared.master_name();

    let bar = if a.quiet || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::with_draw_target(Some(n as u64), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{bar:40} {pos}/{len} steps, {elapsed} elapsed, {eta} left",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar
    };
    let columns = prepared.columns();
    let mut writer = ResultWriter::new(output, &columns);
    let plot_signals = if plot_signals.is_empty() {
        columns.clone()
    } else {
        plot_signals
    };
    // a plot that cannot be drawn does not hide the run or its summary
    let mut plot_error = match a.plot {
        Some(_) => writer.keep_columns(&columns, &plot_signals).err(),
        None => None,
    };
    let run = prepared.run(&mut writer, &mut |done, _| bar.set_position(done as u64))?;
    bar.finish_and_clear();

    let kept = writer.kept();
    writer
        .finish(run.error.as_deref())
        .map_err(|e| e.to_string())?;
    if let (Some(plot), Some(kept)) = (&a.plot, &kept) {
        let title = format!(
            "{} ({master})",
            if file.name.is_empty() {
                "system"
            } else {
                &file.name
            },
        );
        plot_error = fricsim::plot::plot_signals(kept, &plot_signals, plot, &title).err();
    }

    print!("{}", summary(&file, &run, n, step, master));
    if let Some(report) = &run.master_report {
        println!("{report}");
    }
    println!("wrote {}", out.display());
    if let (Some(p), None) = (&a.plot, &plot_error) {
        println!("wrote {}", p.display());
    }
    if let Some(e) = run.error {
        return Err(format!(
            "run INCOMPLETE (the {} rows up to the failure are in {}): {e}",
            run.rows,
            out.display()
        ));
    }
    match plot_error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// The summary: what ran, how long, each column's min/max/final value,
/// and whether the run completed.
fn summary(file: &SystemFile, run: &RunOutcome, n: usize, step: f64, master: &str) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let (done, stats, wall) = (run.steps, &run.stats, run.wall_time);
    let _ = writeln!(
        s,
        "{}: {} components, {} connections, {} parameter values",
        file.ssd,
        file.components.len(),
        file.connections.len(),
        file.parameters.len()
    );
    let _ = writeln!(
        s,
        "{done} of {n} macro steps of {step} s with {master} ({} to {} s), {wall:.3} s wall time: {}",
        stats.first_time.unwrap_or(0.0),
        stats.last_time.unwrap_or(0.0),
        if run.error.is_none() { "completed" } else { "INCOMPLETE" }
    );
    let width = run
        .columns
        .iter()
        .map(|c| c.len())
        .max()
        .unwrap_or(6)
        .max(6);
    let _ = writeln!(
        s,
        "  {:<width$} {:>13} {:>13} {:>13}",
        "signal", "min", "max", "final"
    );
    for (k, c) in run.columns.iter().enumerate() {
        let (lo, hi, last) = (stats.min[k], stats.max[k], stats.last[k]);
        let _ = writeln!(s, "  {c:<width$} {lo:>13.5e} {hi:>13.5e} {last:>13.5e}");
    }
    s
}
