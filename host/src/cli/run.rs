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
    /// watchdog reports it on stderr when it passes the limit (with
    /// --isolate it is stopped: the FMU process is killed).
    #[arg(long = "step-timeout", value_name = "SECONDS")]
    pub step_timeout: Option<f64>,
    /// Run the FMUs in a child process (see docs/user-guide.md, "Isolated
    /// runs"), so that one that crashes (a
    /// segmentation fault, abort(), exit()) or hangs past --step-timeout
    /// costs the run its end, not its rows: the result keeps every row
    /// and is marked incomplete naming the instance, the FMI call, the
    /// time and the signal or exit status.
    #[arg(long)]
    pub isolate: bool,
}

/// The progress bar and the external inputs, consulted by the run.
pub struct Watch {
    pub inputs: Option<ExternalInputs>,
    pub bar: ProgressBar,
}

impl Drop for Watch {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

impl Observer for Watch {
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
    if a.isolate {
        return super::isolated::run_isolated(a);
    }
    let Prepared {
        plan,
        mut master,
        mut system,
        inputs,
        start,
        stop,
    } = prepare(a)?;
    let mut watch = Watch {
        inputs,
        bar: progress_bar(a, plan.n),
    };
    let columns = system.columns();
    let mut sink = RunSink::new(a, &columns, &plan);
    let started = std::time::Instant::now();
    let run = simulate_streaming(
        &mut system,
        master.as_mut(),
        start,
        plan.step,
        stop,
        &mut watch,
        &mut sink,
    )
    .map_err(|e| format!("initialization failed: {e}"))?;
    let wall = started.elapsed().as_secs_f64();
    watch.bar.finish_and_clear();
    let report = master.report();
    conclude(a, sink, &plan, &run, report, wall)
}

/// What a run is, as its summary and plot tell it (sent by an isolated
/// run's child to its parent).
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Plan {
    /// The first line of the summary: the system file and its size.
    pub system: String,
    /// The plot's title.
    pub title: String,
    pub master: String,
    /// Macro steps and their length.
    pub n: usize,
    pub step: f64,
    pub plot_signals: Vec<String>,
}

/// A run ready to start: the system built, its master and inputs.
pub struct Prepared {
    pub plan: Plan,
    pub master: Box<dyn fricsim::master::MasterAlgorithm>,
    pub system: System,
    pub inputs: Option<ExternalInputs>,
    pub start: f64,
    pub stop: f64,
}

/// Read the system file, build the system, bind the inputs.
pub fn prepare(a: &RunArgs) -> Result<Prepared, String> {
    let file = SystemFile::open(&a.system).map_err(|e| e.to_string())?;
    let (start, stop, step) = a.grid.resolve(&file)?;
    let master = by_name(&super::master_name(&a.master, &file))?;

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
    let plot_signals = if plot_signals.is_empty() {
        system.columns()
    } else {
        plot_signals
    };
    let plan = Plan {
        system: format!(
            "{}: {} components, {} connections, {} parameter values",
            file.ssd,
            file.components.len(),
            file.connections.len(),
            file.parameters.len()
        ),
        title: format!(
            "{} ({})",
            if file.name.is_empty() {
                "system"
            } else {
                &file.name
            },
            master.name()
        ),
        master: master.name().to_string(),
        n: step_count(start, step, stop),
        step,
        plot_signals,
    };
    Ok(Prepared {
        plan,
        master,
        system,
        inputs,
        start,
        stop,
    })
}

/// The progress bar of `n` steps on a terminal, else a hidden one.
pub fn progress_bar(a: &RunArgs, n: usize) -> ProgressBar {
    if a.quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(n as u64), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} steps, {elapsed} elapsed, {eta} left")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// The result file of `--out` [default: out/<file name>.csv].
pub fn out_path(a: &RunArgs) -> PathBuf {
    a.out
        .clone()
        .unwrap_or_else(|| super::default_out(&a.system, ""))
}

/// Where the rows go: the result file, and the plotted columns kept.
pub struct RunSink {
    writer: ResultWriter,
    out: PathBuf,
    /// Why the plot cannot be drawn, if it cannot: it does not hide the
    /// run or its summary.
    plot_error: Option<String>,
}

impl RunSink {
    pub fn new(a: &RunArgs, columns: &[String], plan: &Plan) -> RunSink {
        let out = out_path(a);
        let mut writer = ResultWriter::new(&out, columns);
        let plot_error = match a.plot {
            Some(_) => writer.keep_columns(columns, &plan.plot_signals).err(),
            None => None,
        };
        RunSink {
            writer,
            out,
            plot_error,
        }
    }
}

impl fricsim::master::RowSink for RunSink {
    fn write(&mut self, times: &[f64], rows: &fricsim::rows::Rows) -> Result<(), String> {
        self.writer.write(times, rows)
    }
}

/// After the run: the result file ended (marked incomplete if `run`
/// stopped early), the plot, the summary; an error if the run is
/// incomplete.
pub fn conclude(
    a: &RunArgs,
    sink: RunSink,
    plan: &Plan,
    run: &Streamed,
    master_report: Option<String>,
    wall: f64,
) -> Result<(), String> {
    let RunSink {
        writer,
        out,
        mut plot_error,
    } = sink;
    let kept = writer.kept();
    let stats = writer.stats.clone();
    writer
        .finish(run.error.as_deref())
        .map_err(|e| format!("{}: {e}", out.display()))?;
    if let (Some(plot), Some(kept)) = (&a.plot, &kept) {
        plot_error = fricsim::plot::plot_signals(kept, &plan.plot_signals, plot, &plan.title).err();
    }

    print!("{}", summary(plan, run, &stats, wall));
    if let Some(report) = master_report {
        println!("{report}");
    }
    println!("wrote {}", out.display());
    if let (Some(p), None) = (&a.plot, &plot_error) {
        println!("wrote {}", p.display());
    }
    if let Some(e) = &run.error {
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
fn summary(plan: &Plan, run: &Streamed, stats: &ColumnStats, wall: f64) -> String {
    use std::fmt::Write;
    let Plan {
        n, step, master, ..
    } = plan;
    let mut s = String::new();
    let done = run.rows.saturating_sub(1);
    let _ = writeln!(s, "{}", plan.system);
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
