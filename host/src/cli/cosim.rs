//! `fricsim cosim`: connect FMUs given on the command line, co-simulate
//! with a fixed macro step, write a CSV and a plot, print a summary.

use fricsim::master::{simulate_streaming, NoObserver};
use fricsim::output_file::OutputFile;
use fricsim::results::ResultWriter;
use fricsim::system::System;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct CosimArgs {
    /// A component: name=path.fmu (repeat).
    #[arg(long = "fmu", required = true)]
    pub fmus: Vec<String>,
    /// A parameter: component.variable=value (repeat).
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
    /// Result CSV.
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
    /// watchdog reports it on stderr when it passes the limit.
    #[arg(long = "step-timeout", value_name = "SECONDS")]
    pub step_timeout: Option<f64>,
}

pub fn run(a: &CosimArgs) -> Result<(), String> {
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
    let parameters = a
        .parameters
        .iter()
        .map(|s| {
            let (k, v) = s
                .split_once('=')
                .ok_or(format!("--set expects component.variable=value, got `{s}`"))?;
            let v = match v {
                "true" => 1.0,
                "false" => 0.0,
                v => v.parse::<f64>().map_err(|e| format!("--set {s}: {e}"))?,
            };
            Ok((k.to_string(), v))
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
    let components: Vec<(String, &Path)> =
        components.iter().map(|(n, p)| (n.clone(), *p)).collect();
    let mut inputs: Vec<(&str, &Path)> = components.iter().map(|(_, p)| ("the FMU", *p)).collect();
    inputs.extend(a.plot.as_deref().map(|p| ("the plot", p)));
    let output = OutputFile::create(&a.out, &inputs).map_err(|e| e.to_string())?;
    let mut system =
        System::build(&components, &parameters, &connections).map_err(|e| e.to_string())?;
    system.set_call_time_limit(super::call_time_limit(a.step_timeout)?);
    let mut master = fricsim::master::by_name(&a.master)?;
    super::print_warnings(system.warnings());
    let columns = system.columns();
    let mut writer = ResultWriter::new(output, &columns);
    let signals = if a.plot_signals.is_empty() {
        columns.clone()
    } else {
        a.plot_signals.clone()
    };
    // a signal that cannot be plotted is reported once the CSV is written
    let plot_error = match a.plot {
        Some(_) => writer.keep_columns(&columns, &signals).err(),
        None => None,
    };
    let started = std::time::Instant::now();
    let run = simulate_streaming(
        &mut system,
        master.as_mut(),
        0.0,
        a.step,
        a.stop,
        &mut NoObserver,
        &mut writer,
    )
    .map_err(|e| e.to_string())?;
    let elapsed = started.elapsed();
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
            &signals,
            plot,
            &format!("fricsim cosim ({})", master.name()),
        )?;
    }
    println!(
        "{} macro steps of {} s with {}, {} columns, {:.3} s wall time",
        run.rows.saturating_sub(1),
        a.step,
        master.name(),
        run.columns.len(),
        elapsed.as_secs_f64()
    );
    for (k, c) in run.columns.iter().enumerate() {
        let (lo, hi) = (stats.min[k], stats.max[k]);
        println!("  {c:<24} min {lo:>12.5e}  max {hi:>12.5e}");
    }
    if let Some(report) = master.report() {
        print!("{report}");
    }
    println!("wrote {}", a.out.display());
    if let Some(p) = &a.plot {
        println!("wrote {}", p.display());
    }
    match run.error {
        Some(e) => Err(format!(
            "run INCOMPLETE (results up to the failure are in {}): {e}",
            a.out.display()
        )),
        None => Ok(()),
    }
}
