//! `fricsim sweep SYSTEM --param component.variable=v1,v2,… [--seeds N]`:
//! one run of the system per point of the parameter grid (and per seed),
//! in parallel on all cores, summarised one row per run in a CSV
//! ([`fricsim::sweep`]).

use fricsim::formats::ResultFormat;
use fricsim::output_file::OutputFile;
use fricsim::ssp::SystemFile;
use fricsim::sweep::{check_axes, grid, run_all, seed_ports, write_table, Axis, Plan};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct SweepArgs {
    /// The system: an .ssp archive or a SystemStructure .ssd file.
    pub system: PathBuf,
    /// A swept parameter, component.variable=value,value,… (repeat: the
    /// grid is every combination).
    #[arg(long = "param")]
    pub params: Vec<String>,
    /// Also run every grid point with the random-realisation seeds 1..=N
    /// (the `seed` parameter of the Bristle FMU, or --seed-param).
    #[arg(long)]
    pub seeds: Option<u32>,
    /// The seed variable(s) for --seeds, component.variable (repeat)
    /// [default: every component's `seed` parameter].
    #[arg(long = "seed-param")]
    pub seed_params: Vec<String>,
    /// Worker threads [default: every core].
    #[arg(long)]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub grid: super::GridArgs,
    /// Master algorithm (as `fricsim run --master`) [default: the file's
    /// annotation, else jacobi].
    #[arg(long)]
    pub master: Option<String>,
    /// The table, one row per run [default: out/<file name>-sweep.csv].
    #[arg(long)]
    pub out: Option<PathBuf>,
}

pub fn run(a: &SweepArgs) -> Result<(), String> {
    let file = SystemFile::open(&a.system).map_err(|e| e.to_string())?;
    let (start, stop, step) = a.grid.resolve(&file)?;
    let master = super::master_name(&a.master, &file);
    fricsim::master::by_name(&master)?; // refused before anything runs
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| super::default_out(&a.system, "-sweep"));
    if !ResultFormat::from_path(&out).holds_text() {
        // refused before anything runs: the table has a text column
        return Err(format!(
            "--out {}: a sweep's table is written as CSV only (its `status` column is text, which MAT v4 cannot hold); give a .csv name",
            out.display()
        ));
    }
    let output = OutputFile::create(&out, &file.files_read()).map_err(|e| e.to_string())?;
    let mut axes = a
        .params
        .iter()
        .map(|p| Axis::parse(p))
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(n) = a.seeds {
        if n == 0 {
            return Err("--seeds must be at least 1".into());
        }
        let ports = if a.seed_params.is_empty() {
            seed_ports(&file)?
        } else {
            a.seed_params.clone()
        };
        if ports.is_empty() {
            return Err(format!(
                "--seeds: no component of {} has a `seed` parameter; name one with --seed-param component.variable",
                file.ssd
            ));
        }
        for port in ports {
            axes.push(Axis {
                port,
                values: (1..=n).map(f64::from).collect(),
            });
        }
    } else if !a.seed_params.is_empty() {
        return Err("--seed-param needs --seeds N".into());
    }
    check_axes(&file, &axes)?;
    let threads = match a.threads {
        Some(0) => return Err("--threads must be at least 1".into()),
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let plan = Plan {
        points: grid(&axes),
        start,
        stop,
        step,
        master,
    };
    let started = std::time::Instant::now();
    let outcomes = run_all(&file, &plan, threads)?;
    let wall = started.elapsed().as_secs_f64();
    write_table(&outcomes, output).map_err(|e| e.to_string())?;
    let failed = outcomes.iter().filter(|o| o.error.is_some()).count();
    println!(
        "{}: {} runs ({} failed) of {} s with {} on {threads} threads in {wall:.3} s wall time ({:.2} runs/s)",
        file.ssd,
        outcomes.len(),
        failed,
        stop - start,
        plan.master,
        outcomes.len() as f64 / wall
    );
    println!("wrote {}", out.display());
    if failed > 0 {
        return Err(format!(
            "{failed} of {} runs failed (see the status column)",
            outcomes.len()
        ));
    }
    Ok(())
}
