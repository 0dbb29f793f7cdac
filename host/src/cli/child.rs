//! The hidden subcommand `isolated-child`: the child process of `fricsim
//! run --isolate` and `cosim --isolate`, started by fricsim itself. It
//! runs the command as it does in-process ([`super::run::child`],
//! [`super::cosim::child`]), the rows and the outcome going to the parent
//! ([`super::isolated`]). The one module that names the commands that can
//! run isolated; nothing but `main` uses it.

use super::cosim::CosimArgs;
use super::run::RunArgs;
use fricsim::isolate::child::Child;
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

/// The commands that can run isolated, with their own options.
#[derive(clap::Subcommand)]
pub enum ChildCommand {
    Run(RunArgs),
    Cosim(CosimArgs),
}

/// The child: run as the command does in-process, the rows and the
/// outcome going to the parent.
pub fn child(a: &ChildArgs) -> Result<(), String> {
    let mut link = Child::connect(&a.run_dir)?;
    let ran = match &a.command {
        ChildCommand::Run(args) => super::run::child(args, &mut link),
        ChildCommand::Cosim(args) => super::cosim::child(args, &mut link),
    };
    match ran {
        Ok(()) => Ok(()),
        Err(e) => link.failed(e),
    }
}
