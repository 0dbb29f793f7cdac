//! The `fricsim` command line.

mod cli;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "fricsim",
    version,
    about = "Co-simulation host for FMI 2.0 Co-Simulation FMUs"
)]
struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the model description of an FMU: model, capabilities, default
    /// experiment and one line per variable.
    Info {
        /// The .fmu file.
        fmu: PathBuf,
    },
    /// Connect FMUs and co-simulate them with a fixed macro step (Jacobi),
    /// writing a CSV (time first, component.variable columns) and a plot.
    Cosim(cli::cosim::CosimArgs),
}

fn main() -> ExitCode {
    let args = Args::parse();
    let result = match args.command {
        Command::Info { fmu } => cli::info::run(&fmu).map_err(|e| e.to_string()),
        Command::Cosim(args) => cli::cosim::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fricsim: {e}");
            ExitCode::FAILURE
        }
    }
}
