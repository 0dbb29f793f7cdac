//! `fmu-package`: render the model descriptions, check the checked-in ones,
//! and package FMUs. Used by `build-fmu.sh`.

use clap::{Parser, Subcommand};
use fmu_packager::{
    all_models, description_path_version, package_version, render_version, FmiVersion, Platform,
};
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
    /// Write <dir>/<Name>.xml (FMI 2.0) and <dir>/fmi3/<Name>.xml (FMI 3.0)
    /// for every model from its variable table, and <dir>/shipped.txt, the
    /// list of shipped models.
    Render {
        #[arg(default_value = "modelDescription")]
        dir: PathBuf,
    },
    /// Fail if any checked-in <dir>/<Name>.xml, <dir>/fmi3/<Name>.xml or
    /// <dir>/shipped.txt differs from the rendering.
    Check {
        #[arg(default_value = "modelDescription")]
        dir: PathBuf,
    },
    /// Print the variable tables of docs/fmu-reference.md (Markdown).
    VariablesMd,
    /// Package every model: <out>/<Name>.fmu (FMI 2.0) and
    /// <out>/fmi3/<Name>.fmu (FMI 3.0) from the same shared libraries.
    Build {
        /// PLATFORM=DIR: binaries/PLATFORM/ of every FMU from the cdylibs
        /// built for it in DIR (lib<crate>.so for linux32/64, <crate>.dll
        /// for win32/64, lib<crate>.dylib for darwin32/64). Repeat for
        /// several platforms, e.g. --platform linux64=target/release
        /// --platform win64=target/x86_64-pc-windows-gnu/release.
        #[arg(
            long = "platform",
            value_name = "PLATFORM=DIR",
            default_value = "linux64=target/release"
        )]
        platforms: Vec<Platform>,
        #[arg(long, default_value = "dist")]
        out: PathBuf,
    },
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Render { dir } => {
            for version in FmiVersion::ALL {
                let sub = dir.join(version.subdirectory());
                std::fs::create_dir_all(&sub).map_err(|e| format!("{}: {e}", sub.display()))?;
                for info in all_models() {
                    let path = description_path_version(&dir, info, version);
                    std::fs::write(&path, render_version(info, version)?)
                        .map_err(|e| format!("{}: {e}", path.display()))?;
                    println!("wrote {}", path.display());
                }
            }
            let path = fmu_packager::shipped_list_path(&dir);
            std::fs::write(&path, fmu_packager::shipped_list())
                .map_err(|e| format!("{}: {e}", path.display()))?;
            println!("wrote {}", path.display());
        }
        Command::Check { dir } => {
            let mut stale = Vec::new();
            for version in FmiVersion::ALL {
                for info in all_models() {
                    let path = description_path_version(&dir, info, version);
                    let on_disk = std::fs::read_to_string(&path).unwrap_or_default();
                    if on_disk != render_version(info, version)? {
                        stale.push(path.display().to_string());
                    }
                }
            }
            let path = fmu_packager::shipped_list_path(&dir);
            if std::fs::read_to_string(&path).unwrap_or_default() != fmu_packager::shipped_list() {
                stale.push(path.display().to_string());
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
        Command::Build { platforms, out } => {
            let names: Vec<&str> = platforms.iter().map(|p| p.name).collect();
            for version in FmiVersion::ALL {
                // FMI 3.0 names a platform by its processor too: a folder
                // without a tuple (darwin64: Intel or Arm?) is left out of
                // the FMI 3.0 FMUs, and they are not written without any
                let platforms: Vec<Platform> = match version {
                    FmiVersion::Fmi2 => platforms.clone(),
                    FmiVersion::Fmi3 => platforms
                        .iter()
                        .filter(|p| fmu_packager::fmi3_platform(p.name).is_some())
                        .cloned()
                        .collect(),
                };
                if platforms.is_empty() {
                    println!(
                        "no FMI 3.0 FMUs: none of {} has an FMI 3.0 platform tuple",
                        names.join(", ")
                    );
                    continue;
                }
                let names: Vec<&str> = platforms.iter().map(|p| p.name).collect();
                for info in all_models() {
                    println!(
                        "wrote {} ({})",
                        package_version(info, &platforms, &out, version)?.display(),
                        names.join(", ")
                    );
                }
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
