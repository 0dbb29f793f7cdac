//! Master algorithms: how a macro step advances the connected FMUs.

pub mod gauss_seidel;
pub mod jacobi;
pub mod strong;

pub use crate::rows::Rows;
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
    "newton-interpolated",
    "fixed-point",
    "adaptive",
];

/// A master algorithm by its command-line name (see [`NAMES`]).
pub fn by_name(name: &str) -> Result<Box<dyn MasterAlgorithm>, String> {
    use strong::{JacobianSource, StrongCoupling, Update};
    Ok(match name {
        "jacobi" => Box::new(jacobi::Jacobi::default()),
        "gauss-seidel" => Box::new(gauss_seidel::GaussSeidel::new(false)),
        "gauss-seidel-interpolated" => Box::new(gauss_seidel::GaussSeidel::new(true)),
        "newton" => Box::new(StrongCoupling::new(Update::Newton, JacobianSource::Auto)),
        "newton-interpolated" => {
            let mut master = StrongCoupling::new(Update::Newton, JacobianSource::Auto);
            master.interpolate = true;
            Box::new(master)
        }
        "adaptive" => {
            let mut master = StrongCoupling::new(Update::Newton, JacobianSource::Auto);
            master.step_control = Some(strong::StepControl {
                rtol: 1e-3,
                atol: 1e-6,
                h_min: 1e-9,
            });
            Box::new(master)
        }
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
    /// The time of each row: `rows[i]` is at `time[i]`, as many times as
    /// rows. In a run of [`simulate_with`] from `start` in steps of `h`,
    /// communication point `j` is at `start + j·h` ([`communication_time`]).
    pub time: Vec<f64>,
    /// `rows[i][k]`: column `k` at `time[i]`. Under
    /// [`System::keep_last_rows`] the last rows only, and `time` theirs:
    /// `rows[i]` is communication point `rows.rows_folded() + i`, so that
    /// a windowed run holds no more times than rows.
    pub rows: Rows,
    pub error: Option<String>,
}

/// Something the run consults at each communication point: external
/// inputs to set before the step, progress to show after it.
pub trait Observer {
    /// Called at `t` before `exitInitializationMode` (`initializing`) and
    /// before every step from `t`: set whatever inputs come from outside.
    fn before_step(
        &mut self,
        _system: &mut System,
        _t: f64,
        _initializing: bool,
    ) -> Result<(), FmuError> {
        Ok(())
    }
    /// Called after step `done` of `total` (1-based).
    fn after_step(&mut self, _done: usize, _total: usize) {}
    /// Whether [`Observer::before_step`] and [`Observer::after_step`] are
    /// to be called between steps; `false` (an observer that does nothing
    /// there) spares the run two calls per step. Asked once, when the run
    /// starts.
    fn between_steps(&self) -> bool {
        true
    }
}

/// An observer that does nothing.
pub struct NoObserver;
impl Observer for NoObserver {
    fn between_steps(&self) -> bool {
        false
    }
}

/// If `row` (as [`System::sample`] writes it) holds a NaN or an infinity:
/// which instances and outputs. Such a value would travel on to the
/// connected inputs and make the run fail later in another FMU, or not at
/// all; the run stops here instead, naming the FMU that produced it.
fn non_finite(system: &System, row: &[f64]) -> Option<String> {
    let columns: usize = system.components.iter().map(|c| c.outputs.len()).sum();
    if row.len() == columns && all_finite(row) {
        return None;
    }
    let mut instances = Vec::new();
    let mut values = Vec::new();
    let mut k = 0;
    for c in &system.components {
        let before = values.len();
        for (name, _) in &c.outputs {
            let x = row.get(k).copied().unwrap_or(f64::NAN);
            k += 1;
            if !x.is_finite() {
                values.push(format!("{}.{name} = {x}", c.name));
            }
        }
        if values.len() > before {
            instances.push(format!("\"{}\"", c.name));
        }
    }
    if values.is_empty() {
        return None;
    }
    Some(format!(
        "non-finite outputs from instance {} ({})",
        instances.join(", "),
        values.join(", ")
    ))
}

/// No NaN or infinity in `values`: `x·0` is ±0 for every finite `x` and
/// NaN otherwise, and a sum with a NaN is NaN. Summed in four independent
/// lanes (the order does not change whether a NaN is among the terms), so
/// that the additions need not wait for one another.
fn all_finite(values: &[f64]) -> bool {
    let mut chunks = values.chunks_exact(4);
    let mut lanes = [0.0; 4];
    for chunk in &mut chunks {
        for (lane, x) in lanes.iter_mut().zip(chunk) {
            *lane += x * 0.0;
        }
    }
    let rest = chunks.remainder().iter().fold(0.0, |sum, x| sum + x * 0.0);
    lanes.iter().sum::<f64>() + rest == 0.0
}

/// Initialise, then step with a fixed macro step `h` from 0 to `stop`;
/// time is counted (t = n·h), never summed. An FMU error, or a NaN or
/// infinite output after a step, stops the run and is reported with the
/// results so far (the rows of the communication points before it).
pub fn simulate(
    system: &mut System,
    master: &mut dyn MasterAlgorithm,
    h: f64,
    stop: f64,
) -> Result<Run, FmuError> {
    simulate_with(system, master, 0.0, h, stop, &mut NoObserver)
}

/// Number of macro steps of `h` from `start` to `stop`: the nearest whole
/// number, so that a stop time that is a multiple of the step up to rounding
/// (20 / 1e-4) is reached exactly.
pub fn step_count(start: f64, h: f64, stop: f64) -> usize {
    ((stop - start) / h).round().max(0.0) as usize
}

/// The time of communication point `j` of a run from `start` in steps of
/// `h`: `start + j·h`, counted from the start (never summed), as
/// [`simulate_with`] steps; point 0 is `start` itself.
pub fn communication_time(start: f64, h: f64, j: usize) -> f64 {
    if j == 0 {
        start
    } else {
        counted(start, h, j)
    }
}

/// `start + j·h`: where step `j` of [`simulate_with`] starts (and step
/// `j - 1` ends).
#[inline(always)]
fn counted(start: f64, h: f64, j: usize) -> f64 {
    start + j as f64 * h
}

/// [`simulate`] from `start` (t = start + n·h; the system must have been
/// set up at `start`), with `observer` consulted at each communication
/// point: as FMPy does, external inputs are applied at the start time in
/// initialization mode, then at each communication point before the step.
pub fn simulate_with(
    system: &mut System,
    master: &mut dyn MasterAlgorithm,
    start: f64,
    h: f64,
    stop: f64,
    observer: &mut dyn Observer,
) -> Result<Run, FmuError> {
    let mut buffer = vec![0.0; system.connections.len()];
    observer.before_step(system, start, true)?;
    system.propagate(&mut buffer)?;
    for c in &mut system.components {
        c.instance.exit_initialization_mode()?;
    }
    system.propagate(&mut buffer)?;
    let columns = system.columns();
    let n = step_count(start, h, stop);
    system.start_recording(n + 1);
    system.sample()?;
    let (error, time) = if system.recorded().is_windowed() {
        // nothing stored as the run steps: the times of the rows kept
        // follow from their number when it ends
        (
            step_all(system, master, observer, start, h, n, &mut ()),
            None,
        )
    } else {
        let mut time = Vec::with_capacity(n + 1);
        time.push(start);
        let error = step_all(system, master, observer, start, h, n, &mut time);
        (error, Some(time))
    };
    let rows = system.take_recording();
    let time = time.unwrap_or_else(|| {
        (rows.rows_folded()..rows.rows_pushed())
            .map(|j| communication_time(start, h, j))
            .collect()
    });
    Ok(Run {
        columns,
        time,
        rows,
        error,
    })
}

/// Where [`step_all`] puts the time of each communication point it
/// completes: a run that keeps every row stores them as it goes
/// (`Vec<f64>`), a windowed one nothing (`()`), so that neither does work
/// per step that it has no use for.
trait Times {
    fn push(&mut self, t: f64);
}

impl Times for Vec<f64> {
    #[inline(always)]
    fn push(&mut self, t: f64) {
        Vec::push(self, t);
    }
}

impl Times for () {
    #[inline(always)]
    fn push(&mut self, _: f64) {}
}

/// The `n` steps of [`simulate_with`] from `start`, after the row of
/// point 0: a row per communication point completed, its time to
/// `times`; why the run stopped early, if it did.
#[inline(always)] // the run's loop, one copy per kind of `times`
fn step_all(
    system: &mut System,
    master: &mut dyn MasterAlgorithm,
    observer: &mut dyn Observer,
    start: f64,
    h: f64,
    n: usize,
    times: &mut impl Times,
) -> Option<String> {
    let between_steps = observer.between_steps();
    // t = start + i·h, each counted from the start; the step's end is the
    // next step's start, so each is computed once
    let mut t_next = counted(start, h, 0);
    for i in 0..n {
        let t = t_next;
        t_next = counted(start, h, i + 1);
        let stepped = if between_steps {
            observer.before_step(system, t, false)
        } else {
            Ok(())
        }
        .and_then(|()| master.step(system, t, t_next - t));
        if let Err(e) = stepped {
            return Some(format!("at t = {t}: {e}"));
        }
        if let Err(e) = system.sample() {
            return Some(format!("at t = {t_next}: {e}"));
        }
        // the usual case first: a row of numbers
        let row = system.recorded().last().unwrap_or_default();
        if let Some(e) = (!all_finite(row))
            .then(|| non_finite(system, row))
            .flatten()
        {
            system.discard_last_sample();
            return Some(format!("at t = {t}: {e} after fmi2DoStep to t = {t_next}"));
        }
        times.push(t_next);
        if between_steps {
            observer.after_step(i + 1, n);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::all_finite;

    #[test]
    fn all_finite_finds_a_nan_or_infinity_anywhere() {
        for n in 0..14 {
            let mut values: Vec<f64> = (0..n).map(|i| i as f64 - 5.5).collect();
            values.iter_mut().step_by(3).for_each(|x| *x = -0.0);
            assert!(all_finite(&values), "{values:?}");
            for k in 0..n {
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut v = values.clone();
                    v[k] = bad;
                    assert!(!all_finite(&v), "{v:?}");
                }
            }
        }
        assert!(all_finite(&[f64::MAX, -f64::MAX, f64::MIN_POSITIVE]));
    }
}
