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
    /// Connect FMUs and co-simulate them with a fixed communication step
    /// (Jacobi by default), writing a CSV (time first, component.variable columns) and,
    /// with --plot, a plot.
    Cosim(cli::cosim::CosimArgs),
    /// Co-simulate a system file (SSP 1.0: an .ssp archive or a .ssd) with
    /// a fixed communication step, writing a CSV, a summary and, with --plot, a
    /// plot.
    Run(cli::run::RunArgs),
    /// Pack a .ssd and the files its sources point at (FMUs, .ssv) into a
    /// self-contained .ssp archive (sources become resources/<file name>).
    Pack {
        /// The system file (.ssd).
        ssd: PathBuf,
        /// The archive to write (.ssp).
        out: PathBuf,
    },
    /// Co-simulation error of a result CSV against a reference CSV: relative
    /// RMS and largest absolute error per common signal.
    Compare(cli::compare::CompareArgs),
    /// Monolithic reference solution of a system of this project's FMUs
    /// (Rig1D with LuGre, Dahl or Bristle; Rig2D with Bristle2D): the same
    /// equations in one process at tight tolerance, written as the same
    /// CSV as `run`.
    Reference(cli::reference::ReferenceArgs),
    // Where a system and measurements disagree: names the missing friction
    // effect, adds it to the LuGre FMU, refits, ...: the text, with the
    // effects of the library named, is `cli::diagnose::about`.
    #[command(about = cli::diagnose::about())]
    Diagnose(cli::diagnose::DiagnoseArgs),
    /// Run a system once per point of a parameter grid (and per random
    /// seed), in parallel on all cores; writes one CSV row per run with the
    /// parameters, final values, RMS values and wall time.
    Sweep(cli::sweep::SweepArgs),
    /// The child process of `run --isolate` (started by fricsim itself).
    #[command(name = "isolated-child", hide = true)]
    IsolatedChild(cli::child::ChildArgs),
}

fn main() -> ExitCode {
    // Die quietly on a closed pipe (`fricsim run … | head`), as command-line
    // tools do, instead of panicking in println!.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any
    // thread is started.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let args = Args::parse();
    // the commands that stream a run to a result file stop between chunks
    // on SIGINT/SIGTERM and put the rows so far in place (an isolated
    // run's child too: it stops there and its parent puts them in place)
    if matches!(
        args.command,
        Command::Run(_) | Command::Cosim(_) | Command::IsolatedChild(_)
    ) {
        if let Err(e) = fricsim::signals::stop_on_termination() {
            eprintln!("fricsim: cannot catch SIGINT and SIGTERM: {e}");
            return ExitCode::FAILURE;
        }
    }
    let result = match args.command {
        Command::Info { fmu } => cli::info::run(&fmu).map_err(|e| e.to_string()),
        Command::Cosim(args) => cli::cosim::run(&args),
        Command::Run(args) => cli::run::run(&args),
        Command::Pack { ssd, out } => fricsim::ssp::pack(&ssd, &out)
            .map(|()| println!("wrote {}", out.display()))
            .map_err(|e| e.to_string()),
        Command::Compare(args) => cli::compare::run(&args),
        Command::Reference(args) => cli::reference::run(&args),
        Command::Diagnose(args) => cli::diagnose::run(&args),
        Command::Sweep(args) => cli::sweep::run(&args),
        Command::IsolatedChild(args) => cli::child::child(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fricsim: {e}");
            // stopped by a signal: 128 + its number, as a shell reports it
            match fricsim::signals::received() {
                Some((signal, _)) => ExitCode::from((128 + signal) as u8),
                None => ExitCode::FAILURE,
            }
        }
    }
}
