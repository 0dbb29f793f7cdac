//! Master algorithms: how a macro step advances the connected FMUs.
//!
//! Uses [`crate::system`] (the components and connections it steps),
//! [`crate::rows`] and [`crate::time_grid`] (the communication points,
//! re-exported here); the system uses nothing of this module.

pub mod gauss_seidel;
pub mod jacobi;
pub mod strong;

pub use crate::rows::Rows;
use crate::system::System;
use crate::time_grid::counted;
pub use crate::time_grid::{communication_time, step_count};
use crate::FmuError;

pub trait MasterAlgorithm {
    fn name(&self) -> &'static str;
    /// Advance every component from `t` to `t + h`.
    fn step(&mut self, system: &mut System, t: f64, h: f64) -> Result<(), FmuError>;
    /// What the algorithm has to say after a run (iterations, rejections).
    fn report(&self) -> Option<String> {
        None
    }
    /// The Jacobi master, if this is it: [`simulate_with`] then runs its
    /// step inlined into the run's loop instead of calling it through the
    /// trait object at every macro step (the call and the reloading of the
    /// system after it are a fair share of the host's work in a step).
    fn as_jacobi(&mut self) -> Option<&mut jacobi::Jacobi> {
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
    configured(name, false)
}

/// [`by_name`], with the strong-coupling masters reusing each step's
/// Jacobian for the next ([`strong::StrongCoupling::reuse_jacobian`]):
/// for many co-simulations of one system with a law whose step has one
/// solution (the diagnosis's fits of LuGre).
pub fn by_name_reusing_jacobians(name: &str) -> Result<Box<dyn MasterAlgorithm>, String> {
    configured(name, true)
}

fn configured(name: &str, reuse_jacobian: bool) -> Result<Box<dyn MasterAlgorithm>, String> {
    use strong::{JacobianSource, StrongCoupling, Update};
    let strong = |update| {
        let mut master = StrongCoupling::new(update, JacobianSource::Auto);
        master.reuse_jacobian = reuse_jacobian;
        master
    };
    Ok(match name {
        "jacobi" => Box::new(jacobi::Jacobi::default()),
        "gauss-seidel" => Box::new(gauss_seidel::GaussSeidel::new(false)),
        "gauss-seidel-interpolated" => Box::new(gauss_seidel::GaussSeidel::new(true)),
        "newton" => Box::new(strong(Update::Newton)),
        "newton-interpolated" => {
            let mut master = strong(Update::Newton);
            master.interpolate = true;
            Box::new(master)
        }
        "adaptive" => {
            let mut master = strong(Update::Newton);
            master.step_control = Some(strong::StepControl {
                rtol: 1e-3,
                atol: 1e-6,
                h_min: 1e-9,
            });
            Box::new(master)
        }
        "fixed-point" => Box::new(strong(Update::FixedPoint)),
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
    /// Instances that refused `fmi2Terminate` at the end of the run
    /// ([`System::terminate`]), one sentence each: the rows stand.
    pub warnings: Vec<String>,
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
    /// Called at the communication point `t` a step has just reached,
    /// before its row is recorded: set the outside inputs that are to
    /// hold at `t` in that row (interpolated external inputs of an FMU
    /// that does not move its inputs along their slopes itself).
    fn at_communication_point(&mut self, _system: &mut System, _t: f64) -> Result<(), FmuError> {
        Ok(())
    }
    /// Called after step `done` of `total` (1-based).
    fn after_step(&mut self, _done: usize, _total: usize) {}
    /// Whether [`Observer::before_step`],
    /// [`Observer::at_communication_point`] and [`Observer::after_step`]
    /// are to be called between steps; `false` (an observer that does nothing
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
    let columns: usize = (0..system.component_count())
        .map(|c| system.recorded_names(c).count())
        .sum();
    if row.len() == columns && all_finite(row) {
        return None;
    }
    let mut instances = Vec::new();
    let mut values = Vec::new();
    let mut k = 0;
    for c in 0..system.component_count() {
        let before = values.len();
        let instance = system.component_name(c);
        for name in system.recorded_names(c) {
            let x = row.get(k).copied().unwrap_or(f64::NAN);
            k += 1;
            if !x.is_finite() {
                values.push(format!("{instance}.{name} = {x}"));
            }
        }
        if values.len() > before {
            instances.push(format!("\"{instance}\""));
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

/// [`all_finite`], cheaper when it holds (the usual case): the sum of
/// `values` is finite only if every value is, since a NaN or an infinity
/// among the terms makes the sum NaN or infinite (∞ + x = ∞ for finite x,
/// ∞ − ∞ = NaN, NaN + x = NaN). That takes one addition per value where
/// [`all_finite`] takes two operations. The converse does not hold
/// (finite values may overflow in the sum), so a sum that is not finite
/// is settled by [`all_finite`].
#[inline(always)] // into the run's loop
fn row_is_finite(values: &[f64]) -> bool {
    sum_is_finite(values) || values_are_finite(values)
}

/// [`all_finite`], out of the run's loop: the rare case.
#[cold]
#[inline(never)]
fn values_are_finite(values: &[f64]) -> bool {
    all_finite(values)
}

/// Whether the sum of `values` is finite (see [`row_is_finite`]), summed
/// in four independent lanes, as [`all_finite`] does.
#[inline(always)]
fn sum_is_finite(values: &[f64]) -> bool {
    let mut chunks = values.chunks_exact(4);
    let mut lanes = [0.0; 4];
    for chunk in &mut chunks {
        for (lane, x) in lanes.iter_mut().zip(chunk) {
            *lane += x;
        }
    }
    let rest = chunks.remainder().iter().sum::<f64>();
    let sum = lanes.iter().sum::<f64>() + rest;
    sum * 0.0 == 0.0 // 0 for a finite sum, NaN otherwise
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

/// Leave initialization mode at `start`: external inputs set, the
/// connections propagated before and after `fmi2ExitInitializationMode`.
fn initialize(
    system: &mut System,
    start: f64,
    observer: &mut dyn Observer,
) -> Result<(), FmuError> {
    let mut buffer = vec![0.0; system.connections().len()];
    observer.before_step(system, start, true)?;
    system.propagate(&mut buffer)?;
    system.exit_initialization_mode()?;
    system.propagate(&mut buffer)
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
    initialize(system, start, observer)?;
    let columns = system.columns();
    let n = step_count(start, h, stop);
    system.start_recording(n + 1);
    system.sample()?;
    let (error, ended) = Stop::split(step_range(system, master, observer, start, h, 0..n, n));
    let warnings = system.terminate();
    // the times of the rows kept follow from their number: nothing is
    // stored for them as the run steps
    let rows = system.take_recording();
    let mut time = communication_times(start, h, rows.rows_folded()..rows.rows_pushed());
    if let (Some(ended), Some(last)) = (ended, time.last_mut()) {
        *last = ended.time;
    }
    Ok(Run {
        columns,
        time,
        rows,
        error,
        warnings,
    })
}

/// Macro steps per chunk of a [`simulate_streaming`] run: the rows of a
/// chunk are handed on and dropped before the next chunk starts, so a run
/// holds at most this many rows (about 200 kB for the stick-slip
/// benchmark's six columns, which stay in the cache while they are
/// written), whatever its length.
pub const CHUNK_STEPS: usize = 4096;

/// Where the rows of a [`simulate_streaming`] run go as they are
/// computed: a result file, a summary, the columns of a plot.
pub trait RowSink {
    /// The first `times.len()` rows of `rows`, at `times`: the next
    /// communication points of the run, in order. An error stops the run
    /// (its message is the run's [`Streamed::error`]); so does a sink that
    /// asks for it ([`RowSink::stop_requested`]).
    fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String>;
    /// Why the run is to stop before its end, if it is: asked between
    /// chunks (a run interrupted by a signal stops there).
    fn stop_requested(&self) -> Option<String> {
        None
    }
    /// [`RowSink::write`] of a chunk given by value, and an empty table of
    /// the same width and room (see [`Rows::capacity`]) back, into which
    /// the run records its next rows. By default `rows` itself, emptied
    /// once written; a sink that writes on another thread
    /// ([`crate::writer_thread`]) keeps `rows` and gives back another.
    fn write_chunk(&mut self, times: Vec<f64>, mut rows: Rows) -> Result<Rows, String> {
        self.write(&times, &rows)?;
        rows.clear();
        Ok(rows)
    }
}

impl<T: RowSink + ?Sized> RowSink for &mut T {
    fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String> {
        (**self).write(times, rows)
    }
    fn stop_requested(&self) -> Option<String> {
        (**self).stop_requested()
    }
    fn write_chunk(&mut self, times: Vec<f64>, rows: Rows) -> Result<Rows, String> {
        (**self).write_chunk(times, rows)
    }
}

/// What a [`simulate_streaming`] run leaves once its rows are handed on.
pub struct Streamed {
    pub columns: Vec<String>,
    /// Rows handed to the sink: one per communication point completed.
    pub rows: usize,
    /// Why the run stopped early, if it did: an FMU's failure, the sink's
    /// error or its request to stop.
    pub error: Option<String>,
    /// The component that ended the run, if one did ([`Ended`]): a normal
    /// end, its last row recorded.
    pub ended: Option<Ended>,
    /// Instances that refused `fmi2Terminate` at the end of the run
    /// ([`System::terminate`]), one sentence each: the rows stand.
    pub warnings: Vec<String>,
}

/// A component that ended the simulation before the stop time, as FMI 2.0
/// lets a co-simulation FMU do (§4.2.3): its `fmi2DoStep` returned
/// `fmi2Discard` and `fmi2GetBooleanStatus(fmi2Terminated)` says true.
/// FMPy, like the FMI reference importer, takes that for the normal end
/// of the run and records the outputs at `fmi2LastSuccessfulTime`; so does
/// fricsim: the run's last row is there, and it is no failure. (The other
/// components keep the state they had when that FMU stopped: with the
/// Jacobi master, those after it in the system have not taken the step.)
#[derive(Clone, Debug, PartialEq)]
pub struct Ended {
    /// The instance that ended the simulation.
    pub instance: String,
    /// Its `fmi2LastSuccessfulTime`: the time of the run's last row.
    pub time: f64,
}

impl std::fmt::Display for Ended {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} ended the simulation at t = {}",
            self.instance, self.time
        )
    }
}

/// Why [`step_all`] stopped before the end of its steps.
enum Stop {
    /// A failure, in words.
    Failed(String),
    /// A component ended the simulation; its last row is recorded.
    Ended(Ended),
}

impl Stop {
    /// `(error, ended)` of a run that stopped as `stop` says.
    fn split(stop: Option<Stop>) -> (Option<String>, Option<Ended>) {
        match stop {
            None => (None, None),
            Some(Stop::Failed(e)) => (Some(e), None),
            Some(Stop::Ended(e)) => (None, Some(e)),
        }
    }
}

/// [`simulate_with`], handing the rows to `sink` as the run goes instead
/// of keeping them: every [`CHUNK_STEPS`] macro steps, the rows recorded
/// since the last chunk (but the last one, from which the connected
/// inputs are read) go to the sink and are dropped, so that the memory a
/// run takes does not grow with its length. The rows and their times are
/// those of [`simulate_with`] bit for bit. The steps run in the same loop
/// as [`simulate_with`]'s, over a chunk at a time.
pub fn simulate_streaming(
    system: &mut System,
    master: &mut dyn MasterAlgorithm,
    start: f64,
    h: f64,
    stop: f64,
    observer: &mut dyn Observer,
    sink: &mut dyn RowSink,
) -> Result<Streamed, FmuError> {
    initialize(system, start, observer)?;
    let columns = system.columns();
    let n = step_count(start, h, stop);
    system.start_streamed_recording(CHUNK_STEPS.min(n) + 1);
    system.sample()?;
    // communication points handed to the sink so far; steps done
    let mut written = 0;
    let mut done = 0;
    let mut error = None;
    let mut ended = None;
    loop {
        if error.is_none() && done < n {
            error = sink.stop_requested();
        }
        let end = if error.is_none() {
            (done + CHUNK_STEPS).min(n)
        } else {
            done
        };
        if end > done {
            (error, ended) =
                Stop::split(step_range(system, master, observer, start, h, done..end, n));
            done = end;
        }
        let last_chunk = error.is_some() || ended.is_some() || done == n;
        let held = system.recorded().len();
        // the last row stays until the run ends: the next step reads the
        // connected inputs from it
        let handing = if last_chunk { held } else { held - 1 };
        let mut times = communication_times(start, h, written..written + handing);
        if let (Some(ended), Some(last)) = (&ended, times.last_mut()) {
            *last = ended.time;
        }
        if last_chunk {
            match sink.write(&times, system.recorded()) {
                Ok(()) => written += handing,
                Err(e) => {
                    error.get_or_insert(e);
                }
            }
            break;
        }
        // the chunk goes to the sink whole; the run records on from a
        // copy of its last row in the table the sink gives back
        let chunk = system.swap_recording(Rows::new(system.recorded().width()));
        match sink.write_chunk(times, chunk) {
            Ok(next) => {
                let placeholder = system.swap_recording(next);
                debug_assert_eq!(placeholder.len(), 1);
            }
            Err(e) => {
                error.get_or_insert(e);
                break;
            }
        }
        written += handing;
    }
    system.take_recording();
    let warnings = system.terminate();
    Ok(Streamed {
        columns,
        rows: written,
        error,
        ended,
        warnings,
    })
}

/// The steps `steps` of a run of `n` from `start` (the row of the
/// communication point where they start already read), through
/// [`step_all`] in the copy that fits the master and the observer.
fn step_range(
    system: &mut System,
    master: &mut dyn MasterAlgorithm,
    observer: &mut dyn Observer,
    start: f64,
    h: f64,
    steps: std::ops::Range<usize>,
    n: usize,
) -> Option<Stop> {
    match (master.as_jacobi(), observer.between_steps()) {
        (Some(jacobi), false) => step_all::<_, false>(system, jacobi, observer, start, h, steps, n),
        (Some(jacobi), true) => step_all::<_, true>(system, jacobi, observer, start, h, steps, n),
        (None, false) => step_all::<_, false>(system, master, observer, start, h, steps, n),
        (None, true) => step_all::<_, true>(system, master, observer, start, h, steps, n),
    }
}

/// [`communication_time`] of each point of `points`, computed as
/// [`step_all`] does: `start + j·h` with the count `j` carried as a float
/// (exact: `j < 2⁵³`), so that no count is converted one by one.
#[inline(never)] // a loop of its own, apart from the run's
fn communication_times(start: f64, h: f64, points: std::ops::Range<usize>) -> Vec<f64> {
    let mut times = vec![0.0; points.len()];
    // two points at a time (counts j and j + 1, each exact), side by side
    let mut j = [points.start as f64, points.start as f64 + 1.0];
    let mut pairs = times.chunks_exact_mut(2);
    for pair in &mut pairs {
        for (t, j) in pair.iter_mut().zip(&mut j) {
            *t = start + *j * h;
            *j += 2.0;
        }
    }
    if let [t] = pairs.into_remainder() {
        *t = start + j[0] * h;
    }
    if let (0, Some(first)) = (points.start, times.first_mut()) {
        *first = start;
    }
    times
}

/// How [`step_all`] advances the system by one macro step: any master
/// through [`MasterAlgorithm::step`], the Jacobi master's step inlined.
trait Advance {
    /// [`MasterAlgorithm::step`] from `t` over `h`. `sampled`: the last
    /// row was read by [`System::sample`] right before, with no call to any
    /// component since (so that every recorded output in it is what the
    /// FMUs would answer).
    fn advance(
        &mut self,
        system: &mut System,
        t: f64,
        h: f64,
        sampled: bool,
    ) -> Result<(), FmuError>;
}

impl Advance for dyn MasterAlgorithm + '_ {
    #[inline(always)]
    fn advance(&mut self, system: &mut System, t: f64, h: f64, _: bool) -> Result<(), FmuError> {
        self.step(system, t, h)
    }
}

impl Advance for jacobi::Jacobi {
    #[inline(always)]
    fn advance(
        &mut self,
        system: &mut System,
        t: f64,
        h: f64,
        sampled: bool,
    ) -> Result<(), FmuError> {
        system.step_jacobi(t, h, sampled)
    }
}

/// The steps `steps` of the `n` of [`simulate_with`] from `start`, after
/// the row of the point where they start: a row per communication point
/// completed; why the run stopped early, if it did (a component that ends
/// the simulation, [`Ended`], leaves the row of its last successful time
/// as the last). One copy for the Jacobi master, its step inlined, one
/// for any other, called through the trait object; each in two, with and
/// without the observer's calls between the steps
/// ([`Observer::between_steps`], `BETWEEN_STEPS`).
#[inline(never)]
fn step_all<M: Advance + ?Sized, const BETWEEN_STEPS: bool>(
    system: &mut System,
    master: &mut M,
    observer: &mut dyn Observer,
    start: f64,
    h: f64,
    steps: std::ops::Range<usize>,
    n: usize,
) -> Option<Stop> {
    // t = start + i·h, each counted from the start; the step's end is the
    // next step's start, so each is computed once
    let mut t_next = counted(start, h, steps.start);
    for i in steps {
        let t = t_next;
        t_next = counted(start, h, i + 1);
        let stepped = if BETWEEN_STEPS {
            observer.before_step(system, t, false)
        } else {
            Ok(())
        }
        // without the observer, nothing comes between the row read at the
        // end of the last step (or by `simulate_with` before the first)
        // and this step
        .and_then(|()| master.advance(system, t, t_next - t, !BETWEEN_STEPS))
        .and_then(|()| {
            if BETWEEN_STEPS {
                observer.at_communication_point(system, t_next)
            } else {
                Ok(())
            }
        });
        let ended = match stepped {
            Ok(()) => None,
            Err(e) => match ended_by(system, &e) {
                Some(ended) => Some(ended),
                None => return Some(Stop::Failed(format!("at t = {t}: {e}"))),
            },
        };
        let finite = match system.sample_with(row_is_finite) {
            Ok(finite) => finite,
            Err(e) => return Some(Stop::Failed(format!("at t = {t_next}: {e}"))),
        };
        // the usual case first: a row of numbers
        if !finite {
            let row = system.recorded().last().unwrap_or_default();
            if let Some(e) = non_finite(system, row) {
                system.discard_last_sample();
                return Some(Stop::Failed(format!(
                    "at t = {t}: {e} after fmi2DoStep to t = {t_next}"
                )));
            }
        }
        if let Some(ended) = ended {
            return Some(Stop::Ended(ended));
        }
        if BETWEEN_STEPS {
            observer.after_step(i + 1, n);
        }
    }
    None
}

/// If `error` is a component's `fmi2DoStep` that returned `fmi2Discard`
/// while the component asks to end the simulation
/// (`fmi2GetBooleanStatus(fmi2Terminated)` = true): that component and
/// its `fmi2LastSuccessfulTime` ([`Ended`]). Either status call failing
/// leaves the discard a failure.
#[cold]
#[inline(never)]
fn ended_by(system: &mut System, error: &FmuError) -> Option<Ended> {
    if let FmuError::EndedSimulation { instance, time, .. } = error {
        return Some(Ended {
            instance: instance.clone(),
            time: *time,
        });
    }
    let FmuError::Call {
        function: "fmi2DoStep" | "fmi3DoStep",
        instance,
        status: crate::fmu::Status::Discard,
        ..
    } = error
    else {
        return None;
    };
    let time = system.terminated_at(instance)?;
    Some(Ended {
        instance: instance.clone(),
        time,
    })
}

#[cfg(test)]
mod tests {
    use super::{all_finite, communication_time, communication_times, row_is_finite};

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

    #[test]
    fn row_is_finite_is_all_finite_also_where_the_sum_overflows() {
        let big = [f64::MAX, f64::MAX / 2.0, -f64::MAX, 1e308, 1e308, -1e-300];
        for n in 0..14 {
            let values: Vec<f64> = (0..n).map(|i| (i as f64 - 5.5) * 1e3).collect();
            assert!(row_is_finite(&values), "{values:?}");
            for k in 0..n {
                // finite values whose sum is not: still a row of numbers
                for x in big {
                    let mut v = values.clone();
                    v[k] = x;
                    v[(k + 1) % n] = x;
                    assert_eq!(row_is_finite(&v), all_finite(&v), "{v:?}");
                    assert!(row_is_finite(&v), "{v:?}");
                }
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let mut v = values.clone();
                    v[k] = bad;
                    assert!(!row_is_finite(&v), "{v:?}");
                    // an infinity of the other sign elsewhere: ∞ − ∞ = NaN
                    v[(k + 5) % n] = if bad == f64::INFINITY {
                        f64::NEG_INFINITY
                    } else {
                        v[(k + 5) % n]
                    };
                    assert!(!row_is_finite(&v), "{v:?}");
                }
            }
        }
    }

    #[test]
    fn the_times_of_the_rows_are_their_communication_times_bit_for_bit() {
        for (start, h) in [(0.0, 1e-4), (0.0, 0.1), (1.5, 1e-3), (-2.0, 1.0 / 3.0)] {
            for points in [
                0..0,
                0..1,
                0..2,
                0..7,
                0..200_001,
                3..4,
                5..12,
                99_990..100_001,
            ] {
                let times = communication_times(start, h, points.clone());
                assert_eq!(times.len(), points.len());
                for (t, j) in times.iter().zip(points) {
                    let expected = communication_time(start, h, j);
                    assert_eq!(t.to_bits(), expected.to_bits(), "{start} + {j}·{h}");
                }
            }
        }
    }
}
