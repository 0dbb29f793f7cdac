//! `fricsim reference SYSTEM.ssp|SYSTEM.ssd`: the monolithic reference
//! solution of a system of this project's FMUs ([`fricsim_reference`]):
//! the same friction law and rig equations, from the physics crates,
//! solved together in one process at tight tolerance, written as the same
//! CSV (`time` first, the columns of `fricsim run`) at the same times
//! (`start + i·step`). The yardstick for co-simulation error: compare with
//! `fricsim compare RESULT.csv REFERENCE.csv`.
//!
//! The system file is checked against its FMUs as for `fricsim run`; the
//! components are recognised by model name and GUID, their parameters taken
//! from the file's bindings. Systems without a monolithic model are refused
//! with a message naming the component or connection.

use fricsim::master::{step_count, Rows, Run};
use fricsim::reference::spec;
use fricsim::ssp::SystemFile;
use fricsim_reference::{ReferenceModel, Table, RTOL};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct ReferenceArgs {
    /// The system: an .ssp archive or a SystemStructure .ssd file.
    pub system: PathBuf,
    /// Start time in seconds [default: DefaultExperiment startTime, else 0].
    #[arg(long)]
    pub start: Option<f64>,
    /// Stop time in seconds [default: DefaultExperiment stopTime].
    #[arg(long)]
    pub stop: Option<f64>,
    /// Output interval in seconds: one row every step, at the times of
    /// `fricsim run` with the same --step; the solver chooses its own steps
    /// and never steps across an output time [default: the file's stepSize
    /// annotation].
    #[arg(long)]
    pub step: Option<f64>,
    /// Result file: CSV, or MAT v4 if it ends in .mat (as `fricsim run`)
    /// [default: out/<file name>_reference.csv].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Record a Real variable besides the outputs, component.variable
    /// (repeat), as `fricsim run --record`.
    #[arg(long = "record")]
    pub record: Vec<String>,
    /// Relative tolerance of the integrator.
    #[arg(long, default_value_t = RTOL)]
    pub rtol: f64,
    /// Solve a second time at rtol/100 and print the largest difference per
    /// column: an estimate of the reference's own error.
    #[arg(long)]
    pub check: bool,
}

pub fn run(a: &ReferenceArgs) -> Result<(), String> {
    let file = SystemFile::open(&a.system).map_err(|e| e.to_string())?;
    let (start, stop, step) = fricsim::run::time_grid(&file, a.start, a.stop, a.step)?;
    if !(a.rtol.is_finite() && a.rtol > 0.0 && a.rtol < 1.0) {
        return Err(format!("--rtol must be in (0, 1), got {}", a.rtol));
    }
    let mut model = ReferenceModel::from_spec(&spec(&file)?)
        .map_err(|e| format!("{}: no monolithic reference: {e}", file.ssd))?;
    for s in a
        .record
        .iter()
        .chain(&file.settings.record)
        .chain(&file.settings.plot)
    {
        model.record(s).map_err(|e| e.to_string())?;
    }
    let n = step_count(start, step, stop);
    let times: Vec<f64> = (0..=n).map(|i| start + i as f64 * step).collect();

    let started = std::time::Instant::now();
    let (table, stats) = model
        .solve(start, &times, a.rtol)
        .map_err(|e| format!("{}: {e}", file.ssd))?;
    let wall = started.elapsed().as_secs_f64();
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| super::default_out(&a.system, "_reference"));
    let run = Run {
        columns: table.columns.clone(),
        time: table.time.clone(),
        rows: Rows::from_rows(table.columns.len(), &table.rows),
        error: None,
        warnings: Vec::new(),
    };
    // The writer of `fricsim run`: the same format to the digit.
    let output = fricsim::output_file::OutputFile::create(&out, &file.files_read())
        .map_err(|e| e.to_string())?;
    fricsim::results::write_run(&run, output).map_err(|e| e.to_string())?;

    println!("{}: {}", file.ssd, model.description());
    print!(
        "{} rows, t = {start} … {} s every {step} s, rtol {:e}, {wall:.3} s wall time",
        table.time.len(),
        table.time[table.time.len() - 1],
        a.rtol
    );
    match stats {
        Some(s) => println!(
            "; Radau IIA: {} steps ({} rejected, {} ended on a switching point), {} Jacobians, {} LU",
            s.accepted, s.rejected, s.switches, s.jacobians, s.factorisations
        ),
        None => println!(),
    }
    if a.check {
        let tight = a.rtol / 100.0;
        let (fine, _) = model
            .solve(start, &times, tight)
            .map_err(|e| format!("{}: at rtol {tight:e}: {e}", file.ssd))?;
        print!("{}", check_report(&table, &fine, tight));
    }
    println!("wrote {}", out.display());
    Ok(())
}

/// Largest difference per column between the solution and one at a
/// tighter tolerance, absolute and relative to the column's largest value.
fn check_report(table: &Table, fine: &Table, tight: f64) -> String {
    use std::fmt::Write;
    let width = table
        .columns
        .iter()
        .map(|c| c.len())
        .max()
        .unwrap_or(6)
        .max(6);
    let mut s = format!(
        "estimated error (largest difference from the solution at rtol {tight:e}):\n  {:<width$} {:>12} {:>12}\n",
        "signal", "max |diff|", "relative"
    );
    for (k, name) in table.columns.iter().enumerate() {
        let (mut diff, mut scale) = (0.0f64, 0.0f64);
        for (a, b) in table.rows.iter().zip(&fine.rows) {
            diff = diff.max((a[k] - b[k]).abs());
            scale = scale.max(b[k].abs());
        }
        let rel = if scale > 0.0 {
            format!("{:.3e}", diff / scale)
        } else {
            "-".to_string()
        };
        let _ = writeln!(s, "  {name:<width$} {diff:>12.3e} {rel:>12}");
    }
    s
}
