//! `fricsim compare RESULT.csv REFERENCE.csv [--signal NAME …]`: the
//! co-simulation error of a result against a reference (e.g. from
//! `fricsim reference`), per signal: relative RMS error, RMS error, and the
//! largest absolute error with its time ([`fricsim::compare`]).

use fricsim::compare::{compare, ResultFile};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct CompareArgs {
    /// The result to check: CSV with `time` first, then component.variable
    /// columns, or a .mat result file (as `fricsim run` writes either).
    pub result: PathBuf,
    /// The reference, in the same format (e.g. from `fricsim reference`);
    /// interpolated linearly onto the result's times if the grids differ.
    pub reference: PathBuf,
    /// Compare only this signal (repeat) [default: every column the two
    /// files have in common].
    #[arg(long = "signal")]
    pub signals: Vec<String>,
}

pub fn run(a: &CompareArgs) -> Result<(), String> {
    let result = ResultFile::read(&a.result).map_err(|e| e.to_string())?;
    let reference = ResultFile::read(&a.reference).map_err(|e| e.to_string())?;
    let c = compare(&result, &reference, &a.signals).map_err(|e| e.to_string())?;
    for (label, f) in [("result:   ", &result), ("reference:", &reference)] {
        println!(
            "{label} {} ({} rows, t = {} … {} s)",
            f.path.display(),
            f.time.len(),
            f.time[0],
            f.time[f.time.len() - 1]
        );
        if let Some(note) = &f.incomplete {
            println!("           INCOMPLETE run: {note}");
        }
    }
    if c.interpolated {
        println!(
            "time grids differ: the reference is interpolated linearly onto the result's {} times",
            c.points
        );
    } else {
        println!("same time grid, {} points", c.points);
    }
    print!("{c}");
    Ok(())
}
