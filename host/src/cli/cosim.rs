//! `fricsim cosim`: connect FMUs given on the command line, co-simulate
//! with a fixed macro step, write a CSV and a plot, print a summary.

use super::isolated::{json, Ending};
use fricsim::inputs::{ExternalInputs, InputTable};
use fricsim::isolate::child::Child;
use fricsim::master::{simulate_streaming, MasterAlgorithm, NoObserver, Observer, Streamed};
use fricsim::output_file::OutputFile;
use fricsim::results::ResultWriter;
use fricsim::run::StartValue;
use fricsim::system::{Experiment, RecordedType, System};
use fricsim::writer_thread::on_writer_thread;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct CosimArgs {
    /// A component: name=path.fmu (repeat).
    #[arg(long = "fmu", required = true)]
    pub fmus: Vec<String>,
    /// A start value: component.variable=value (repeat), read as the
    /// variable's type and checked as `run --set` checks it (causality,
    /// type, min and max) before any FMU is instantiated.
    #[arg(long = "set")]
    pub parameters: Vec<String>,
    /// A connection: component.output->component.input (repeat).
    #[arg(long = "connect")]
    pub connections: Vec<String>,
    /// Master algorithm: jacobi, gauss-seidel, gauss-seidel-interpolated,
    /// newton (strong coupling), newton-interpolated (strong coupling, inputs
    /// ramped over the step), adaptive (strong coupling, adaptive macro
    /// steps), fixed-point (strong coupling, for comparison).
    #[arg(long, default_value = "jacobi")]
    pub master: String,
    /// Communication step in seconds: the master steps the FMUs by it,
    /// except that `adaptive` chooses its macro steps inside it and the
    /// strong-coupling masters halve a step that does not converge.
    #[arg(long, default_value_t = 1e-4)]
    pub step: f64,
    /// Stop time in seconds.
    #[arg(long, default_value_t = 1.0)]
    pub stop: f64,
    /// External inputs: CSV with `time` first, then component.variable
    /// columns for unconnected inputs, interpolated linearly in time: an
    /// FMU that can interpolate inputs is given each one's slope over the
    /// step, and a recorded row holds the inputs of its own time (see
    /// --input-hold; as in `fricsim run --input`).
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Hold each --input value over the macro step, as FMPy's
    /// simulate_fmu does.
    #[arg(long = "input-hold", requires = "input")]
    pub input_hold: bool,
    /// Result file: CSV, or MAT v4 in the Dymola/OpenModelica layout if
    /// it ends in .mat.
    #[arg(long, default_value = "out/result.csv")]
    pub out: PathBuf,
    /// Plot of the chosen signals (.png or .svg) [default: no plot].
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Signals to plot, as component.variable (default: all).
    #[arg(long = "plot-signal")]
    pub plot_signals: Vec<String>,
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

pub fn run(a: &CosimArgs) -> Result<(), String> {
    let parsed = parse(a)?;
    // the result file is claimed before the FMUs are opened
    let output = claim_output(a, &parsed)?;
    if a.isolate {
        return run_isolated(a, output);
    }
    let (mut system, mut master, plan) = build(a, &parsed)?;
    let mut inputs = external_inputs(a, &system)?;
    let sink = CosimSink::new(a, output, &system.columns(), &plan);
    let started = std::time::Instant::now();
    // the result written on a thread of its own while the run steps on
    let (run, sink) = on_writer_thread(sink, |front| {
        simulate_streaming(
            &mut system,
            master.as_mut(),
            0.0,
            a.step,
            a.stop,
            inputs.as_mut(),
            front,
        )
    });
    let run = run.map_err(|e| e.to_string())?;
    let wall = started.elapsed().as_secs_f64();
    conclude(a, sink, &plan, &run, master.report(), wall)
}

/// `--isolate`, the parent: the rows the child computes written to the
/// result file claimed before it started.
fn run_isolated(a: &CosimArgs, output: OutputFile) -> Result<(), String> {
    let isolated = super::isolated::run_isolated(a.step_timeout, |columns, plan: &CosimPlan| {
        Ok(CosimSink::new(a, output, columns, plan))
    })?;
    let ended = isolated.ending.ended();
    let run = Streamed {
        columns: isolated.columns,
        rows: isolated.rows,
        error: isolated.error,
        ended,
        // (the child printed its own warnings)
        warnings: Vec::new(),
    };
    conclude(
        a,
        isolated.sink,
        &isolated.plan,
        &run,
        isolated.ending.master_report,
        isolated.ending.wall,
    )
}

/// `--isolate`, the child: build the system and run it, the rows going
/// to the parent.
pub fn child(a: &CosimArgs, link: &mut Child) -> Result<(), String> {
    let parsed = parse(a)?;
    let (mut system, mut master, plan) = build(a, &parsed)?;
    let mut inputs = external_inputs(a, &system)?;
    link.started(&mut system, json(&plan)?)?;
    let started = std::time::Instant::now();
    let run = link
        .simulate_streaming(
            &mut system,
            master.as_mut(),
            0.0,
            a.step,
            a.stop,
            inputs.as_mut(),
        )
        .map_err(|e| e.to_string())?;
    // on the standard error the parent shares
    super::print_warnings(&run.warnings);
    let ending = Ending {
        master_report: master.report(),
        wall: started.elapsed().as_secs_f64(),
        ended: run.ended.clone().map(|e| (e.instance, e.time)),
    };
    link.finished(&run, json(ending)?)
}

/// The `--input` table bound to the system's unconnected inputs,
/// interpolated unless `--input-hold`; without `--input`, no observer.
fn external_inputs(a: &CosimArgs, system: &System) -> Result<Box<dyn Observer>, String> {
    let Some(path) = &a.input else {
        return Ok(Box::new(NoObserver));
    };
    let bound = ExternalInputs::bind(InputTable::read(path)?, system)?;
    Ok(Box::new(if a.input_hold {
        bound
    } else {
        bound.with_slopes(a.step)
    }))
}

/// What the summary and the plot need to know of a run (sent by an
/// isolated run's child to its parent).
#[derive(serde::Serialize, serde::Deserialize)]
pub struct CosimPlan {
    pub master: String,
    pub signals: Vec<String>,
    /// The type of each column.
    pub types: Vec<RecordedType>,
}

/// The options read: components, parameters, connections.
pub struct Parsed<'a> {
    components: Vec<(String, &'a Path)>,
    parameters: Vec<(String, StartValue)>,
    connections: Vec<(String, String)>,
}

/// Check and read the options.
fn parse(a: &CosimArgs) -> Result<Parsed<'_>, String> {
    if !(a.step.is_finite() && a.step > 0.0) {
        return Err(format!("--step must be > 0, got {}", a.step));
    }
    if !(a.stop.is_finite() && a.stop > 0.0) {
        return Err(format!("--stop must be > 0, got {}", a.stop));
    }
    let components = a
        .fmus
        .iter()
        .map(|s| {
            s.split_once('=')
                .map(|(n, p)| (n.to_string(), Path::new(p)))
                .ok_or(format!("--fmu expects name=path.fmu, got `{s}`"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    // read as each variable's type and checked against it when the FMUs
    // are open (`open_with_start_values`)
    let parameters = a
        .parameters
        .iter()
        .map(|s| {
            let (k, v) = s
                .split_once('=')
                .ok_or(format!("--set expects component.variable=value, got `{s}`"))?;
            Ok((k.to_string(), StartValue::Text(v.to_string())))
        })
        .collect::<Result<Vec<_>, String>>()?;
    let connections = a
        .connections
        .iter()
        .map(|s| {
            s.split_once("->")
                .map(|(f, t)| (f.trim().to_string(), t.trim().to_string()))
                .ok_or(format!("--connect expects out.port->in.port, got `{s}`"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Parsed {
        components,
        parameters,
        connections,
    })
}

/// The result file `--out`, claimed.
fn claim_output(a: &CosimArgs, parsed: &Parsed) -> Result<OutputFile, String> {
    let mut inputs: Vec<(&str, &Path)> = parsed
        .components
        .iter()
        .map(|(_, p)| ("the FMU", *p))
        .collect();
    inputs.extend(a.input.as_deref().map(|p| ("the --input table", p)));
    inputs.extend(a.plot.as_deref().map(|p| ("the plot", p)));
    OutputFile::create(&a.out, &inputs).map_err(|e| e.to_string())
}

/// The system built from the options, its master.
fn build(
    a: &CosimArgs,
    parsed: &Parsed,
) -> Result<(System, Box<dyn MasterAlgorithm>, CosimPlan), String> {
    // the FMUs are told the stop time, as `run` and FMPy tell them
    let (fmus, parameters) =
        fricsim::run::open_with_start_values(&parsed.components, &parsed.parameters)?;
    let mut system = System::from_fmus(
        fmus,
        &parameters,
        &parsed.connections,
        Experiment::stepped(0.0, a.step, a.stop),
    )
    .map_err(|e| e.to_string())?;
    system.set_call_time_limit(super::call_time_limit(a.step_timeout)?);
    // every output, Integer and Boolean ones too, as `run` records them
    system.record_discrete_outputs();
    let master = fricsim::master::by_name(&a.master)?;
    super::print_warnings(system.warnings());
    let signals = if a.plot_signals.is_empty() {
        system.columns()
    } else {
        a.plot_signals.clone()
    };
    let plan = CosimPlan {
        master: master.name().to_string(),
        signals,
        types: system.column_types(),
    };
    Ok((system, master, plan))
}

/// Where the rows go: the result file, and the plotted columns kept.
pub struct CosimSink {
    writer: ResultWriter,
    /// A signal that cannot be plotted, reported once the result is
    /// written.
    plot_error: Option<String>,
}

impl CosimSink {
    fn new(a: &CosimArgs, output: OutputFile, columns: &[String], plan: &CosimPlan) -> CosimSink {
        let mut writer = ResultWriter::new(output, columns);
        writer.whole_number_columns(&plan.types);
        let plot_error = match a.plot {
            Some(_) => writer.keep_columns(columns, &plan.signals).err(),
            None => None,
        };
        CosimSink { writer, plot_error }
    }
}

impl fricsim::master::RowSink for CosimSink {
    fn write(&mut self, times: &[f64], rows: &fricsim::rows::Rows) -> Result<(), String> {
        self.writer.write(times, rows)
    }
    fn stop_requested(&self) -> Option<String> {
        self.writer.stop_requested()
    }
}

/// After the run: the result file ended, the plot, the summary.
pub fn conclude(
    a: &CosimArgs,
    sink: CosimSink,
    plan: &CosimPlan,
    run: &Streamed,
    master_report: Option<String>,
    wall: f64,
) -> Result<(), String> {
    let CosimSink { writer, plot_error } = sink;
    super::print_warnings(&run.warnings);
    let kept = writer.kept();
    let stats = writer.stats.clone();
    writer
        .finish(run.error.as_deref())
        .map_err(|e| e.to_string())?;
    if let Some(e) = plot_error {
        return Err(e);
    }
    if let (Some(plot), Some(kept)) = (&a.plot, &kept) {
        fricsim::plot::plot_signals(
            kept,
            &plan.signals,
            plot,
            &format!("fricsim cosim ({})", plan.master),
        )?;
    }
    println!(
        "{} macro steps of {} s with {}, {} columns, {:.3} s wall time",
        run.rows.saturating_sub(1),
        a.step,
        plan.master,
        run.columns.len(),
        wall
    );
    for (k, c) in run.columns.iter().enumerate() {
        let (lo, hi) = (stats.min[k], stats.max[k]);
        println!("  {c:<24} min {lo:>12.5e}  max {hi:>12.5e}");
    }
    if let Some(report) = master_report {
        print!("{report}");
    }
    if let Some(ended) = &run.ended {
        println!("{ended}");
    }
    println!("wrote {}", a.out.display());
    if let Some(p) = &a.plot {
        println!("wrote {}", p.display());
    }
    match &run.error {
        Some(e) => Err(format!(
            "run INCOMPLETE (results up to the failure are in {}): {e}",
            a.out.display()
        )),
        None => Ok(()),
    }
}
