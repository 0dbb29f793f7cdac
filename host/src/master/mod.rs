//! Master algorithms: how a macro step advances the connected FMUs.

pub mod gauss_seidel;
pub mod jacobi;
pub mod strong;

use crate::system::System;
use crate::FmuError;

pub trait MasterAlgorithm {
    fn name(&self) -> &'static str;
    /// Advance every component from `t` to `t + h`.
    fn step(&mut self, system: &mut System, t: f64, h: f64) -> Result<(), FmuError>;
    /// What the algorithm has to say after a run (iterations, rejections).
    fn report(&self) -> Option<String> {
        None
    }
}

/// The master algorithms by their command-line names.
pub const NAMES: &[&str] = &[
    "jacobi",
    "gauss-seidel",
    "gauss-seidel-interpolated",
    "newton",
    "fixed-point",
];

/// A master algorithm by its command-line name (see [`NAMES`]).
pub fn by_name(name: &str) -> Result<Box<dyn MasterAlgorithm>, String> {
    use strong::{JacobianSource, StrongCoupling, Update};
    Ok(match name {
        "jacobi" => Box::new(jacobi::Jacobi::default()),
        "gauss-seidel" => Box::new(gauss_seidel::GaussSeidel::new(false)),
        "gauss-seidel-interpolated" => Box::new(gauss_seidel::GaussSeidel::new(true)),
        "newton" => Box::new(StrongCoupling::new(Update::Newton, JacobianSource::Auto)),
        "fixed-point" => Box::new(StrongCoupling::new(
            Update::FixedPoint,
            JacobianSource::Auto,
        )),
        other => {
            return Err(format!(
                "unknown master algorithm `{other}` (known: {})",
                NAMES.join(", ")
            ))
        }
    })
}

/// Result of a run: column names and one row per communication point, and
/// whether it stopped early (the rows kept are those computed before).
pub struct Run {
    pub columns: Vec<String>,
    pub time: Vec<f64>,
    pub rows: Vec<Vec<f64>>,
    pub error: Option<String>,
}

/// Initialise, then step with a fixed macro step `h` to `stop`; time is
/// counted (t = n·h), never summed. An FMU error stops the run and is
/// reported with the results so far.
pub fn simulate(
    system: &mut System,
    master: &mut dyn MasterAlgorithm,
    h: f64,
    stop: f64,
) -> Result<Run, FmuError> {
    let mut buffer = vec![0.0; system.connections.len()];
    system.propagate(&mut buffer)?;
    for c in &mut system.components {
        c.instance.exit_initialization_mode()?;
    }
    system.propagate(&mut buffer)?;
    let columns = system.columns();
    let n = (stop / h).round() as usize;
    let mut run = Run {
        columns,
        time: Vec::with_capacity(n + 1),
        rows: Vec::with_capacity(n + 1),
        error: None,
    };
    let mut row = Vec::with_capacity(run.columns.len());
    system.sample(&mut row)?;
    run.time.push(0.0);
    run.rows.push(row);
    for i in 0..n {
        let t = i as f64 * h;
        let t_next = (i + 1) as f64 * h;
        if let Err(e) = master.step(system, t, t_next - t) {
            run.error = Some(format!("at t = {t}: {e}"));
            break;
        }
        let mut row = Vec::with_capacity(run.columns.len());
        system.sample(&mut row)?;
        run.time.push(t_next);
        run.rows.push(row);
    }
    Ok(run)
}
