//! `fmu-package`: render the model descriptions, check the checked-in ones,
//! and package FMUs. Used by `build-fmu.sh`.

use clap::{Parser, Subcommand};
use fmu_packager::{all_models, description_path, package, render};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(about = "Render model descriptions and package FMUs")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write <dir>/<Name>.xml for every model from its variable table.
    Render {
        #[arg(default_value = "modelDescription")]
        dir: PathBuf,
    },
    /// Fail if any checked-in <dir>/<Name>.xml differs from the rendering.
    Check {
        #[arg(default_value = "modelDescription")]
        dir: PathBuf,
    },
    /// Print the variable tables of docs/fmu-reference.md (Markdown).
    VariablesMd,
    /// Package every model: <out>/<Name>.fmu from the shared library.
    Build {
        /// Directory with the built cdylibs (lib<crate>.so).
        #[arg(long, default_value = "target/release")]
        lib_dir: PathBuf,
        #[arg(long, default_value = "dist")]
        out: PathBuf,
    },
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Render { dir } => {
            std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            for info in all_models() {
                let path = description_path(&dir, info);
                std::fs::write(&path, render(info)?)
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                println!("wrote {}", path.display());
            }
        }
        Command::Check { dir } => {
            let mut stale = Vec::new();
            for info in all_models() {
                let path = description_path(&dir, info);
                let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
                if on_disk != render(info)? {
                    stale.push(path.display().to_string());
                }
            }
            if !stale.is_empty() {
                return Err(format!(
                    "model descriptions differ from the code: {} (run `cargo run -p fmu-packager -- render`)",
                    stale.join(", ")
                ));
            }
            println!("model descriptions match the code");
        }
        Command::VariablesMd => print!("{}", fmu_packager::variables_markdown()),
        Command::Build { lib_dir, out } => {
            for info in all_models() {
                let lib = lib_dir.join(format!("lib{}.so", fmu_packager::library_of(info)));
                println!("wrote {}", package(info, &lib, &out)?.display());
            }
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fmu-package: {e}");
            ExitCode::FAILURE
        }
    }
}
