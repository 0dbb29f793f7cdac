//! `fricsim run --isolate` and `cosim --isolate`: the FMUs in a child
//! process ([`fricsim::isolate`]). The parent writes the result, the plot
//! and the summary as the command does in-process; the child (the hidden
//! subcommand `isolated-child`) builds the system and runs it.

use super::cosim::{CosimArgs, CosimPlan, CosimSink};
use super::run::{Plan, RunArgs, RunSink, Watch};
use fricsim::isolate::child::Child;
use fricsim::isolate::parent;
use fricsim::master::{MasterAlgorithm, NoObserver, Observer, RowSink, Streamed};
use fricsim::system::System;
use fricsim::FmuError;
use serde::{de::DeserializeOwned, Serialize};
use std::path::PathBuf;
use std::time::Duration;

/// The hidden subcommand: `fricsim isolated-child --run-dir DIR <command>`.
#[derive(clap::Args)]
pub struct ChildArgs {
    /// The run's directory, made by the parent (black box, row ring).
    #[arg(long = "run-dir")]
    pub run_dir: PathBuf,
    #[command(subcommand)]
    pub command: ChildCommand,
}

/// The commands that can run isolated, with their own options.
#[derive(clap::Subcommand)]
pub enum ChildCommand {
    Run(RunArgs),
    Cosim(CosimArgs),
}

/// A run ready to start: what the child does with it.
pub struct Setup<P> {
    /// What the parent needs to write the summary and the plot.
    pub plan: P,
    pub system: System,
    pub master: Box<dyn MasterAlgorithm>,
    pub observer: Box<dyn Observer>,
    pub start: f64,
    pub step: f64,
    pub stop: f64,
}

/// A command that can run isolated: its options, in the parent and in the
/// child, say how to set the run up, where the rows go and how it ends.
pub trait Isolatable {
    type Plan: Serialize + DeserializeOwned;
    type Sink: RowSink;
    /// `--step-timeout`.
    fn call_limit(&self) -> Result<Option<Duration>, String>;
    /// The child: read the options, build the system.
    fn set_up(&self) -> Result<Setup<Self::Plan>, String>;
    /// The parent: the sink of the rows of `columns`.
    fn sink(&self, columns: &[String], plan: &Self::Plan) -> Self::Sink;
    /// The message of a run whose initialization failed.
    fn initialization_failed(&self, e: FmuError) -> String {
        format!("initialization failed: {e}")
    }
    /// The parent: the result ended, the plot, the summary.
    fn conclude(
        &self,
        sink: Self::Sink,
        plan: &Self::Plan,
        run: &Streamed,
        master_report: Option<String>,
        wall: f64,
    ) -> Result<(), String>;
}

impl Isolatable for RunArgs {
    type Plan = Plan;
    type Sink = RunSink;
    fn call_limit(&self) -> Result<Option<Duration>, String> {
        super::call_time_limit(self.step_timeout)
    }
    fn set_up(&self) -> Result<Setup<Plan>, String> {
        let p = super::run::prepare(self)?;
        Ok(Setup {
            observer: Box::new(Watch {
                inputs: p.inputs,
                bar: super::run::progress_bar(self, p.plan.n),
            }),
            step: p.plan.step,
            plan: p.plan,
            system: p.system,
            master: p.master,
            start: p.start,
            stop: p.stop,
        })
    }
    fn sink(&self, columns: &[String], plan: &Plan) -> RunSink {
        RunSink::new(self, columns, plan)
    }
    fn conclude(
        &self,
        sink: RunSink,
        plan: &Plan,
        run: &Streamed,
        master_report: Option<String>,
        wall: f64,
    ) -> Result<(), String> {
        super::run::conclude(self, sink, plan, run, master_report, wall)
    }
}

impl Isolatable for CosimArgs {
    type Plan = CosimPlan;
    type Sink = CosimSink;
    fn call_limit(&self) -> Result<Option<Duration>, String> {
        super::call_time_limit(self.step_timeout)
    }
    fn set_up(&self) -> Result<Setup<CosimPlan>, String> {
        let (system, master, plan) = super::cosim::prepare(self)?;
        Ok(Setup {
            plan,
            system,
            master,
            observer: Box::new(NoObserver),
            start: 0.0,
            step: self.step,
            stop: self.stop,
        })
    }
    fn initialization_failed(&self, e: FmuError) -> String {
        e.to_string()
    }
    fn sink(&self, columns: &[String], plan: &CosimPlan) -> CosimSink {
        CosimSink::new(self, columns, plan)
    }
    fn conclude(
        &self,
        sink: CosimSink,
        plan: &CosimPlan,
        run: &Streamed,
        master_report: Option<String>,
        wall: f64,
    ) -> Result<(), String> {
        super::cosim::conclude(self, sink, plan, run, master_report, wall)
    }
}

/// What the child adds when the run ends.
#[derive(serde::Serialize, serde::Deserialize)]
struct Ending {
    master_report: Option<String>,
    /// Seconds the run took in the child.
    wall: f64,
}

/// `--isolate`: start the child with this process's own arguments, write
/// what it computes.
pub fn run_isolated<A: Isolatable>(a: &A) -> Result<(), String> {
    let limit = a.call_limit()?;
    let args: Vec<_> = std::env::args_os().skip(1).collect();
    let started = std::time::Instant::now();
    let outcome = parent::run_isolated(&args, limit, |columns, plan| {
        let plan: A::Plan = serde_json::from_value(plan.clone()).map_err(|e| e.to_string())?;
        Ok(a.sink(columns, &plan))
    })?;
    if let Some(message) = &outcome.failed {
        return Err(message.clone());
    }
    let error = outcome.error();
    let (Some(sink), Some(Ok(plan))) = (
        outcome.sink,
        outcome.started.map(serde_json::from_value::<A::Plan>),
    ) else {
        return Err(format!(
            "the run did not start: {}",
            error.unwrap_or_else(|| "the FMU process ended".to_string())
        ));
    };
    let (master_report, wall) = match outcome.finished.map(|f| serde_json::from_value(f.2)) {
        Some(Ok(Ending {
            master_report,
            wall,
        })) => (master_report, wall),
        _ => (None, started.elapsed().as_secs_f64()),
    };
    let run = Streamed {
        columns: outcome.columns,
        rows: outcome.rows,
        error,
    };
    a.conclude(sink, &plan, &run, master_report, wall)
}

/// The child: run as the command does in-process, the rows and the
/// outcome going to the parent.
pub fn child(a: &ChildArgs) -> Result<(), String> {
    let mut link = Child::connect(&a.run_dir)?;
    let ran = match &a.command {
        ChildCommand::Run(args) => run_child(args, &mut link),
        ChildCommand::Cosim(args) => run_child(args, &mut link),
    };
    match ran {
        Ok(()) => Ok(()),
        Err(e) => link.failed(e),
    }
}

fn run_child<A: Isolatable>(a: &A, link: &mut Child) -> Result<(), String> {
    let mut s = a.set_up()?;
    let plan = serde_json::to_value(&s.plan).map_err(|e| e.to_string())?;
    link.started(&mut s.system, plan)?;
    let started = std::time::Instant::now();
    let run = link
        .simulate_streaming(
            &mut s.system,
            s.master.as_mut(),
            s.start,
            s.step,
            s.stop,
            s.observer.as_mut(),
        )
        .map_err(|e| a.initialization_failed(e))?;
    let ending = Ending {
        master_report: s.master.report(),
        wall: started.elapsed().as_secs_f64(),
    };
    drop(s.observer);
    link.finished(
        &run,
        serde_json::to_value(ending).map_err(|e| e.to_string())?,
    )
}
