//! `fricsim run SYSTEM.ssp|SYSTEM.ssd`: read a system file (SSP 1.0,
//! [`fricsim::ssp`]), check it against its FMUs, co-simulate it with a
//! fixed macro step, write a CSV and optionally a plot, print a summary.
//! Settings come from the command line, else from the file
//! (`DefaultExperiment`, our annotation), else from defaults.

use fricsim::inputs::{ExternalInputs, InputTable};
use fricsim::master::{by_name, simulate_streaming, step_count, Observer, Streamed};
use fricsim::results::{ColumnStats, ResultWriter};
use fricsim::ssp::SystemFile;
use fricsim::system::System;
use fricsim::FmuError;
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
    /// Result file: CSV, or MAT v4 in the Dymola/OpenModelica layout if
    /// it ends in .mat [default: out/<file name>.csv].
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

/// The progress bar and the external inputs, consulted by the run.
struct Watch {
    inputs: Option<ExternalInputs>,
    bar: ProgressBar,
}

impl Observer for Watch {
    /// Nothing to do between steps without external inputs and with the
    /// bar hidden (`--quiet`, or stderr not a terminal): the run then
    /// takes its loop without the two calls per step.
    fn between_steps(&self) -> bool {
        self.inputs.is_some() || !self.bar.is_hidden()
    }

    fn before_step(&mut self, system: &mut System, t: f64, init: bool) -> Result<(), FmuError> {
        match &mut self.inputs {
            Some(i) => i.before_step(system, t, init),
            None => Ok(()),
        }
    }

    fn after_step(&mut self, done: usize, total: usize) {
        // drawing is rate-limited by indicatif; updating every 256 steps
        // keeps even the bookkeeping out of the step loop's cost
        if done.is_multiple_of(256) || done == total {
            self.bar.set_position(done as u64);
        }
    }
}

pub fn run(a: &RunArgs) -> Result<(), String> {
    let file = SystemFile::open(&a.system).map_err(|e| e.to_string())?;
    let (start, stop, step) = a.grid.resolve(&file)?;
    let mut master = by_name(&super::master_name(&a.master, &file))?;

    let mut system = file.build(start).map_err(|e| e.to_string())?;
    system.set_call_time_limit(super::call_time_limit(a.step_timeout)?);
    super::print_warnings(system.warnings());
    let plot_signals = if !a.plot_signals.is_empty() {
        a.plot_signals.clone()
    } else {
        file.settings.plot.clone()
    };
    for s in a.record.iter().chain(&plot_signals) {
        system.record(s).map_err(|e| e.to_string())?;
    }
    let inputs = match &a.input {
        Some(path) => Some(ExternalInputs::bind(InputTable::read(path)?, &system)?),
        None => None,
    };

    let n = step_count(start, step, stop);
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
    let mut watch = Watch { inputs, bar };
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| super::default_out(&a.system, ""));
    let columns = system.columns();
    let mut writer = ResultWriter::new(&out, &columns);
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
    let started = std::time::Instant::now();
    let run = simulate_streaming(
        &mut system,
        master.as_mut(),
        start,
        step,
        stop,
        &mut watch,
        &mut writer,
    )
    .map_err(|e| format!("initialization failed: {e}"))?;
    let elapsed = started.elapsed();
    watch.bar.finish_and_clear();

    let kept = writer.kept();
    let stats = writer.stats.clone();
    writer
        .finish(run.error.as_deref())
        .map_err(|e| format!("{}: {e}", out.display()))?;
    if let (Some(plot), Some(kept)) = (&a.plot, &kept) {
        let title = format!(
            "{} ({})",
            if file.name.is_empty() {
                "system"
            } else {
                &file.name
            },
            master.name()
        );
        plot_error = fricsim::plot::plot_signals(kept, &plot_signals, plot, &title).err();
    }

    print!(
        "{}",
        summary(
            &file,
            &run,
            &stats,
            n,
            step,
            master.name(),
            elapsed.as_secs_f64()
        )
    );
    if let Some(report) = master.report() {
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
fn summary(
    file: &SystemFile,
    run: &Streamed,
    stats: &ColumnStats,
    n: usize,
    step: f64,
    master: &str,
    wall: f64,
) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let done = run.rows.saturating_sub(1);
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
