//! `fricsim run SYSTEM.ssp|SYSTEM.ssd`: read a system file (SSP 1.0,
//! [`fricsim::ssp`]), check it against its FMUs, co-simulate it with a
//! fixed macro step, write a CSV and optionally a plot, print a summary.
//! Settings come from the command line, else from the file
//! (`DefaultExperiment`, our annotation), else from defaults.

use super::isolated::{json, Ending};
use fricsim::inputs::InputTable;
use fricsim::isolate::child::Child;
use fricsim::output_file::OutputFile;
use fricsim::results::ResultWriter;
use fricsim::run::{PreparedRun, Recorder, RunOptions, RunOutcome, StartValue};
use fricsim::ssp::SystemFile;
use fricsim::system::RecordedType;
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
    /// Record a variable besides the outputs, component.variable (repeat):
    /// e.g. a connected input. Real, Integer and Boolean variables.
    #[arg(long = "record")]
    pub record: Vec<String>,
    /// A start value, component.variable=value (repeat), read as the
    /// variable's type (Boolean: true/false/1/0); set after the system
    /// file's parameter values and --start-values, the last one winning.
    #[arg(long = "set", value_name = "COMPONENT.VARIABLE=VALUE")]
    pub set: Vec<String>,
    /// Start values from an SSP parameter-value file (.ssv) naming
    /// component.variable, set after the system file's own.
    #[arg(long = "start-values", value_name = "FILE.ssv")]
    pub start_values: Option<PathBuf>,
    /// Record every SECONDS instead of at every step: a whole multiple of
    /// the step; the last point is always recorded.
    #[arg(long = "output-interval", value_name = "SECONDS")]
    pub output_interval: Option<f64>,
    /// External inputs: CSV with `time` first, then component.variable
    /// columns for unconnected inputs (bare names for a one-component
    /// system), interpolated linearly in time: an FMU that can interpolate
    /// inputs is given each one's slope over the step, and a recorded row
    /// holds the inputs of its own time (see --input-hold).
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Hold each --input value over the macro step, as FMPy's
    /// simulate_fmu does (for parity with it): no slopes, and a row holds
    /// the inputs of the step that ended at it.
    #[arg(long = "input-hold", requires = "input")]
    pub input_hold: bool,
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

pub fn run(a: &RunArgs) -> Result<(), String> {
    let file = SystemFile::open(&a.system).map_err(|e| e.to_string())?;
    // the result file is claimed before the FMUs are opened: a run that
    // would overwrite an input or another run's result stops here
    let (out, output) = claim_output(a, &file)?;
    if a.isolate {
        return run_isolated(a, &file, out, output);
    }
    let plot_signals = plot_signals(a, &file);
    let prepared = PreparedRun::new(&file, &options(a, &file)?)?;
    super::print_warnings(prepared.warnings());
    let (n, step) = (prepared.steps(), prepared.time_grid().2);
    let master = prepared.master_name();

    let bar = progress_bar(a, n);
    let columns = prepared.columns();
    // (the run's Recorder sums the rows up)
    let mut writer = ResultWriter::new(output, &columns).summarized_elsewhere();
    writer.whole_number_columns(&prepared.column_types());
    let plot_signals = if plot_signals.is_empty() {
        columns.clone()
    } else {
        plot_signals
    };
    // a plot that cannot be drawn does not hide the run or its summary
    let plot_error = match a.plot {
        Some(_) => writer.keep_columns(&columns, &plot_signals).err(),
        None => None,
    };
    // a hidden bar (--quiet, stderr not a terminal) needs no progress
    let mut progress = |done: usize, _| bar.set_position(done as u64);
    let progress: Option<&mut dyn FnMut(usize, usize)> = if bar.is_hidden() {
        None
    } else {
        Some(&mut progress)
    };
    let run = prepared.run_with_writer_thread(&mut writer, progress)?;
    bar.finish_and_clear();
    let ran = Ran {
        out,
        plot_signals,
        plot_error,
        n,
        step,
        master: master.to_string(),
    };
    conclude(a, &file, writer, run, ran)
}

/// The result file of `--out` [default: out/<file name>.csv], claimed.
fn claim_output(a: &RunArgs, file: &SystemFile) -> Result<(PathBuf, OutputFile), String> {
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| super::default_out(&a.system, ""));
    let mut inputs = file.files_read();
    inputs.extend(a.input.as_deref().map(|p| ("the --input table", p)));
    inputs.extend(
        a.start_values
            .as_deref()
            .map(|p| ("the --start-values file", p)),
    );
    inputs.extend(a.plot.as_deref().map(|p| ("the plot", p)));
    let output = OutputFile::create(&out, &inputs).map_err(|e| e.to_string())?;
    Ok((out, output))
}

/// The signals to plot: `--plot-signal`, else the file's Plot annotation
/// (none: every column).
fn plot_signals(a: &RunArgs, file: &SystemFile) -> Vec<String> {
    if !a.plot_signals.is_empty() {
        a.plot_signals.clone()
    } else {
        file.settings.plot.clone()
    }
}

/// The run's options from the command line.
fn options(a: &RunArgs, file: &SystemFile) -> Result<RunOptions, String> {
    Ok(RunOptions {
        start: a.grid.start,
        stop: a.grid.stop,
        step: a.grid.step,
        master: a.master.clone(),
        record: a
            .record
            .iter()
            .chain(&plot_signals(a, file))
            .cloned()
            .collect(),
        start_values: start_values(file, a)?,
        output_interval: a.output_interval,
        inputs: match &a.input {
            Some(path) => Some(InputTable::read(path)?),
            None => None,
        },
        hold_inputs: a.input_hold,
        call_time_limit: super::call_time_limit(a.step_timeout)?,
    })
}

/// The progress bar of `n` steps on a terminal, else a hidden one.
fn progress_bar(a: &RunArgs, n: usize) -> ProgressBar {
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

/// What an isolated run's child tells its parent when the run starts.
#[derive(serde::Serialize, serde::Deserialize)]
struct Plan {
    /// Macro steps and their length.
    n: usize,
    step: f64,
    master: String,
    /// Communication points per recorded row ([`PreparedRun::output_every`]).
    every: usize,
    /// The type of each column.
    types: Vec<RecordedType>,
}

/// `--isolate`, the parent: the child computes every communication point,
/// the parent records them as [`PreparedRun::run`] does (the output
/// interval) into the result file claimed before the child started.
fn run_isolated(
    a: &RunArgs,
    file: &SystemFile,
    out: PathBuf,
    output: OutputFile,
) -> Result<(), String> {
    let plot_signals = plot_signals(a, file);
    let mut kept_signals = plot_signals.clone();
    let mut plot_error = None;
    let isolated = super::isolated::run_isolated(a.step_timeout, |columns, plan: &Plan| {
        let mut writer = ResultWriter::new(output, columns).summarized_elsewhere();
        writer.whole_number_columns(&plan.types);
        if kept_signals.is_empty() {
            kept_signals = columns.to_vec();
        }
        plot_error = match a.plot {
            Some(_) => writer.keep_columns(columns, &kept_signals).err(),
            None => None,
        };
        Ok(Recorder::new(writer, plan.every, columns.len()))
    })?;
    let mut recorder = isolated.sink;
    let mut error = isolated.error;
    if let Err(e) = recorder.finish() {
        error.get_or_insert(e);
    }
    let stats = recorder.stats.clone();
    let writer = recorder.into_inner();
    let run = RunOutcome {
        columns: isolated.columns,
        rows: stats.rows,
        steps: isolated.rows.saturating_sub(1),
        error,
        ended: isolated.ending.ended(),
        stats,
        master_report: isolated.ending.master_report,
        wall_time: isolated.ending.wall,
        // (the child printed its own warnings)
        warnings: Vec::new(),
    };
    let plan = isolated.plan;
    let ran = Ran {
        out,
        plot_signals: kept_signals,
        plot_error,
        n: plan.n,
        step: plan.step,
        master: plan.master,
    };
    conclude(a, file, writer, run, ran)
}

/// `--isolate`, the child: the run of [`PreparedRun`], every
/// communication point sent to the parent.
pub fn child(a: &RunArgs, link: &mut Child) -> Result<(), String> {
    let file = SystemFile::open(&a.system).map_err(|e| e.to_string())?;
    let mut prepared = PreparedRun::new(&file, &options(a, &file)?)?;
    super::print_warnings(prepared.warnings());
    let n = prepared.steps();
    let plan = Plan {
        n,
        step: prepared.time_grid().2,
        master: prepared.master_name().to_string(),
        every: prepared.output_every(),
        types: prepared.column_types(),
    };
    link.started(prepared.system_mut(), json(plan)?)?;
    let bar = progress_bar(a, n);
    let mut progress = |done: usize, _| bar.set_position(done as u64);
    let progress: Option<&mut dyn FnMut(usize, usize)> = if bar.is_hidden() {
        None
    } else {
        Some(&mut progress)
    };
    let run = link.run_prepared(prepared, progress)?;
    bar.finish_and_clear();
    // on the standard error the parent shares
    super::print_warnings(&run.warnings);
    let ending = Ending {
        master_report: run.master_report,
        wall: run.wall_time,
        ended: run.ended.map(|e| (e.instance, e.time)),
    };
    link.finished_with(run.rows, run.error, json(ending)?)
}

/// What the summary and the plot need besides the run.
struct Ran {
    out: PathBuf,
    plot_signals: Vec<String>,
    /// Why the plot cannot be drawn, if it cannot: it does not hide the
    /// run or its summary.
    plot_error: Option<String>,
    n: usize,
    step: f64,
    master: String,
}

/// After the run: the result file ended (marked incomplete if the run
/// stopped early), the plot, the summary; an error if the run is
/// incomplete.
fn conclude(
    a: &RunArgs,
    file: &SystemFile,
    writer: ResultWriter,
    run: RunOutcome,
    ran: Ran,
) -> Result<(), String> {
    let Ran {
        out,
        plot_signals,
        mut plot_error,
        n,
        step,
        master,
    } = ran;
    super::print_warnings(&run.warnings);
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

    print!("{}", summary(file, &run, n, step, &master));
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

/// `--start-values`, then `--set`, in the order they apply.
fn start_values(file: &SystemFile, a: &RunArgs) -> Result<Vec<(String, StartValue)>, String> {
    let mut values = match &a.start_values {
        Some(path) => fricsim::run::start_values_file(file, path)?,
        None => Vec::new(),
    };
    for s in &a.set {
        let (port, value) = s
            .split_once('=')
            .ok_or(format!("--set expects component.variable=value, got `{s}`"))?;
        values.push((port.trim().to_string(), StartValue::Text(value.to_string())));
    }
    Ok(values)
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
        match (&run.error, &run.ended) {
            (Some(_), _) => "INCOMPLETE".to_string(),
            (None, Some(ended)) => ended.to_string(),
            (None, None) => "completed".to_string(),
        }
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
