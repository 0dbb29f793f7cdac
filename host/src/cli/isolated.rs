//! `fricsim run --isolate` and `cosim --isolate`: the FMUs in a child
//! process ([`fricsim::isolate`]). The parent writes the result, the plot
//! and the summary as `run` does; the child (the hidden subcommand
//! `isolated-child`) builds the system and runs it.

use super::run::{conclude, prepare, progress_bar, Plan, RunArgs, RunSink, Watch};
use fricsim::isolate::child::Child;
use fricsim::isolate::parent::run_isolated;
use fricsim::master::Streamed;
use std::path::PathBuf;

/// The hidden subcommand: `fricsim isolated-child --run-dir DIR <command>`.
#[derive(clap::Args)]
pub struct ChildArgs {
    /// The run's directory, made by the parent (black box, row ring).
    #[arg(long = "run-dir")]
    pub run_dir: PathBuf,
    #[command(subcommand)]
    pub command: ChildCommand,
}

/// The commands that can run isolated.
#[derive(clap::Subcommand)]
pub enum ChildCommand {
    Run(RunArgs),
}

/// What the child adds when the run ends.
#[derive(serde::Serialize, serde::Deserialize)]
struct Ending {
    master_report: Option<String>,
    /// Seconds the run took in the child.
    wall: f64,
}

/// `fricsim run --isolate`: start the child, write what it computes.
pub fn run(a: &RunArgs) -> Result<(), String> {
    let limit = super::call_time_limit(a.step_timeout)?;
    // the child gets the same arguments (`run` and its options)
    let args: Vec<_> = std::env::args_os().skip(1).collect();
    let started = std::time::Instant::now();
    let outcome = run_isolated(&args, limit, |columns, plan| {
        let plan: Plan = serde_json::from_value(plan.clone()).map_err(|e| e.to_string())?;
        Ok(RunSink::new(a, columns, &plan))
    })?;
    if let Some(message) = &outcome.failed {
        return Err(message.clone());
    }
    let error = outcome.error();
    let (Some(sink), Some(Ok(plan))) = (
        outcome.sink,
        outcome.started.map(serde_json::from_value::<Plan>),
    ) else {
        return Err(format!(
            "the run did not start: {}",
            error.unwrap_or_else(|| "the FMU process ended".to_string())
        ));
    };
    let columns = outcome.columns;
    let (master_report, wall) = match outcome.finished.map(|f| serde_json::from_value(f.2)) {
        Some(Ok(Ending {
            master_report,
            wall,
        })) => (master_report, wall),
        _ => (None, started.elapsed().as_secs_f64()),
    };
    let run = Streamed {
        columns,
        rows: outcome.rows,
        error,
    };
    conclude(a, sink, &plan, &run, master_report, wall)
}

/// The child: run as `fricsim run` does, the rows and the outcome going
/// to the parent.
pub fn child(a: &ChildArgs) -> Result<(), String> {
    let mut link = Child::connect(&a.run_dir)?;
    let ChildCommand::Run(args) = &a.command;
    match run_child(args, &mut link) {
        Ok(()) => Ok(()),
        Err(e) => link.failed(e),
    }
}

fn run_child(a: &RunArgs, link: &mut Child) -> Result<(), String> {
    let mut p = prepare(a)?;
    let plan = serde_json::to_value(&p.plan).map_err(|e| e.to_string())?;
    link.started(&mut p.system, plan)?;
    let mut watch = Watch {
        inputs: p.inputs.take(),
        bar: progress_bar(a, p.plan.n),
    };
    let started = std::time::Instant::now();
    let run = link
        .simulate_streaming(
            &mut p.system,
            p.master.as_mut(),
            p.start,
            p.plan.step,
            p.stop,
            &mut watch,
        )
        .map_err(|e| format!("initialization failed: {e}"))?;
    let ending = Ending {
        master_report: p.master.report(),
        wall: started.elapsed().as_secs_f64(),
    };
    watch.bar.finish_and_clear();
    link.finished(
        &run,
        serde_json::to_value(ending).map_err(|e| e.to_string())?,
    )
}
