//! Running a system file: what `fricsim run` does, as a library call.
//!
//! [`RunOptions`] says what to change from the system file; anything left
//! out comes from the file (its `DefaultExperiment` and our annotation),
//! else from defaults, as on the command line. [`PreparedRun::new`]
//! checks the options against the file and its FMUs and builds the
//! system; [`PreparedRun::run`] runs it, handing the recorded rows to any
//! [`RowSink`] as they are computed, and returns the [`RunOutcome`].
//!
//! ```no_run
//! use fricsim_core::output_file::OutputFile;
//! use fricsim_core::results::ResultWriter;
//! use fricsim_core::run::{PreparedRun, RunOptions, StartValue};
//! use fricsim_core::ssp::SystemFile;
//! let file = SystemFile::open("dist/stick_slip.ssp").map_err(|e| e.to_string())?;
//! let options = RunOptions {
//!     stop: Some(5.0),
//!     start_values: vec![("friction.Fs".into(), StartValue::Real(2.0))],
//!     output_interval: Some(1e-2),
//!     ..RunOptions::default()
//! };
//! let out = OutputFile::create("out/stick_slip.csv".as_ref(), &file.files_read())
//!     .map_err(|e| e.to_string())?;
//! let prepared = PreparedRun::new(&file, &options)?;
//! let mut csv = ResultWriter::new(out, &prepared.columns());
//! let outcome = prepared.run(&mut csv, None)?;
//! csv.finish(outcome.error.as_deref()).map_err(|e| e.to_string())?;
//! println!("{} rows, {:?}", outcome.rows, outcome.error);
//! # Ok::<(), String>(())
//! ```

use crate::fmu::model_description::{Causality, Initial, Variability, VariableKind};
use crate::fmu::{Fmu, ScalarVariable};
use crate::inputs::{ExternalInputs, InputTable};
use crate::master::{
    by_name, simulate_streaming, step_count, Ended, MasterAlgorithm, Observer, RowSink, Rows,
};
use crate::results::ColumnStats;
use crate::ssp::{SystemFile, Value};
use crate::system::{Experiment, ParameterValue, RecordedType, System};
use crate::FmuError;
use std::time::Duration;

/// What a run changes from its system file. `None` and empty lists leave
/// the file's settings (or the defaults) in force.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Start time in seconds [default: DefaultExperiment startTime, else 0].
    pub start: Option<f64>,
    /// Stop time in seconds [default: DefaultExperiment stopTime].
    pub stop: Option<f64>,
    /// Communication step in seconds [default: the file's stepSize
    /// annotation].
    pub step: Option<f64>,
    /// Master algorithm, one of [`crate::master::NAMES`] [default: the
    /// file's annotation, else jacobi].
    pub master: Option<String>,
    /// Start values `(component.variable, value)`, set after the system
    /// file's own parameter bindings, in order: a later value for the same
    /// variable wins. Checked first (see [`check_start_value`]).
    pub start_values: Vec<(String, StartValue)>,
    /// Record every `output_interval` seconds instead of at every
    /// communication point: a whole multiple of the step. The start, every
    /// k-th point and the last point are recorded.
    pub output_interval: Option<f64>,
    /// Variables `component.variable` to record besides the outputs (and
    /// those of the file's annotation).
    pub record: Vec<String>,
    /// External inputs: a table of unconnected inputs over time,
    /// interpolated linearly. Each continuous input is given its slope
    /// over the step when its FMU can interpolate inputs, and a recorded
    /// row holds the inputs at its own time
    /// ([`ExternalInputs::with_slopes`]), unless [`RunOptions::hold_inputs`].
    pub inputs: Option<InputTable>,
    /// Hold each external input over the macro step, as FMPy's
    /// `simulate_fmu` does (for parity with it): no slopes, and a row
    /// recorded at a communication point holds the inputs of the step
    /// that ended there.
    pub hold_inputs: bool,
    /// A time limit on each FMI call (see [`crate::fmu::watchdog`]).
    pub call_time_limit: Option<Duration>,
}

/// A start value as given: typed, or text to be read as the variable's
/// declared type ([`StartValue::Text`], what the command line gives).
#[derive(Clone, Debug, PartialEq)]
pub enum StartValue {
    Real(f64),
    Integer(i64),
    Boolean(bool),
    String(String),
    /// Read as the variable's type: a number for a Real, a whole number
    /// for an Integer or an Enumeration, `true`/`false`/`1`/`0` for a
    /// Boolean, the text itself for a String.
    Text(String),
}

/// The time grid `(start, stop, step)` of a run of `file`: the given
/// values where there are some, else the file's `DefaultExperiment` and
/// stepSize annotation (start defaults to 0).
pub fn time_grid(
    file: &SystemFile,
    start: Option<f64>,
    stop: Option<f64>,
    step: Option<f64>,
) -> Result<(f64, f64, f64), String> {
    let start = match start {
        Some(s) if !s.is_finite() => return Err(format!("--start must be finite, got {s}")),
        Some(s) => s,
        None => file.start_time.unwrap_or(0.0),
    };
    let stop = stop.or(file.stop_time).ok_or_else(|| {
        format!(
            "{}: no stop time: give --stop or <ssd:DefaultExperiment stopTime=\"…\">",
            file.ssd
        )
    })?;
    if !(stop.is_finite() && stop > start) {
        return Err(format!(
            "the stop time {stop} must be after the start time {start}"
        ));
    }
    let step = step.or(file.settings.step_size).ok_or_else(|| {
        format!(
            "{}: no step size: give --step or the stepSize of the fricsim annotation (see docs/user-guide.md, \"Our annotation\")",
            file.ssd
        )
    })?;
    if !(step.is_finite() && step > 0.0) {
        return Err(format!("--step must be a positive number, got {step}"));
    }
    Ok((start, stop, step))
}

/// The start values of an SSP parameter-value file (`.ssv`) at `path`,
/// naming `component.variable` of `file`'s system, in file order.
pub fn start_values_file(
    file: &SystemFile,
    path: &std::path::Path,
) -> Result<Vec<(String, StartValue)>, String> {
    let values = file
        .parameter_values_file(path)
        .map_err(|e| e.to_string())?;
    Ok(values
        .into_iter()
        .map(|p| {
            let value = match p.value {
                Value::Real(x) => StartValue::Real(x),
                Value::Integer(i) => StartValue::Integer(i.into()),
                Value::Boolean(b) => StartValue::Boolean(b),
                Value::String(s) => StartValue::String(s),
            };
            (format!("{}.{}", p.component, p.variable), value)
        })
        .collect())
}

/// A run checked and set up: the system built with its start values, the
/// master chosen, the inputs bound. [`PreparedRun::run`] runs it.
pub struct PreparedRun {
    system: System,
    master: Box<dyn MasterAlgorithm>,
    inputs: Option<ExternalInputs>,
    start: f64,
    stop: f64,
    step: f64,
    /// Communication points per recorded row ([`RunOptions::output_interval`]).
    every: usize,
}

impl PreparedRun {
    /// Check `options` against `file` and its FMUs and build the system.
    pub fn new(file: &SystemFile, options: &RunOptions) -> Result<PreparedRun, String> {
        let (start, stop, step) = time_grid(file, options.start, options.stop, options.step)?;
        let every = output_every(options.output_interval, step)?;
        let master = by_name(
            &options
                .master
                .clone()
                .unwrap_or_else(|| file.settings.master_or_default()),
        )?;
        let checked = file.check().map_err(|e| e.to_string())?;
        let start_values = check_start_values(&checked.fmus, &options.start_values)?;
        // the FMUs are told the stop time, as FMPy tells them
        let mut system = file
            .instantiate(
                &checked,
                Experiment::stepped(start, step, stop),
                &start_values,
            )
            .map_err(|e| e.to_string())?;
        system.set_call_time_limit(options.call_time_limit);
        system.record_discrete_outputs();
        for s in &options.record {
            system.record(s).map_err(|e| e.to_string())?;
        }
        let inputs = match &options.inputs {
            Some(table) => {
                let bound = ExternalInputs::bind(table.clone(), &system)?;
                Some(if options.hold_inputs {
                    bound
                } else {
                    bound.with_slopes(step)
                })
            }
            None => None,
        };
        Ok(PreparedRun {
            system,
            master,
            inputs,
            start,
            stop,
            step,
            every,
        })
    }

    /// The recorded columns, `component.variable`, after `time`.
    pub fn columns(&self) -> Vec<String> {
        self.system.columns()
    }

    /// The type of each column of [`PreparedRun::columns`]: Integer and
    /// Boolean columns hold whole numbers (see
    /// [`crate::csvfile::CsvFile::whole_number_columns`]).
    pub fn column_types(&self) -> Vec<RecordedType> {
        self.system.column_types()
    }

    /// `(start, stop, step)`, as resolved.
    pub fn time_grid(&self) -> (f64, f64, f64) {
        (self.start, self.stop, self.step)
    }

    /// The number of macro steps from start to stop.
    pub fn steps(&self) -> usize {
        step_count(self.start, self.step, self.stop)
    }

    /// The master algorithm's name.
    pub fn master_name(&self) -> &'static str {
        self.master.name()
    }

    /// What building the system noticed and accepted, one sentence each.
    pub fn warnings(&self) -> &[String] {
        self.system.warnings()
    }

    /// The system, to record more variables or look at its components
    /// before the run.
    pub fn system_mut(&mut self) -> &mut System {
        &mut self.system
    }

    /// Run from start to stop, handing the recorded rows to `sink` as
    /// they come; `progress(done, total)`, if given, is told of the macro
    /// steps as they complete (every 256 steps and at the last). Without
    /// progress and external inputs the run takes its loop without any
    /// call between steps ([`Observer::between_steps`]). An FMU that fails
    /// in initialization is an `Err`; a failure after it is the outcome's
    /// [`RunOutcome::error`], with the rows up to it handed on.
    pub fn run(
        self,
        sink: &mut dyn RowSink,
        progress: Option<&mut dyn FnMut(usize, usize)>,
    ) -> Result<RunOutcome, String> {
        let every = self.every;
        self.run_recording(sink, progress, None, every)
    }

    /// [`PreparedRun::run`] with the rows written on a thread of their own
    /// ([`crate::writer_thread`]): the sink (and the output interval's
    /// picking, and the summary) works on one chunk while the run computes
    /// the next, on a second core. The same rows reach the sink in the
    /// same order; an error of the sink or its request to stop reaches the
    /// run a chunk or two later than on one thread.
    pub fn run_with_writer_thread(
        self,
        sink: &mut (dyn RowSink + Send),
        progress: Option<&mut dyn FnMut(usize, usize)>,
    ) -> Result<RunOutcome, String> {
        let recorder = Recorder::new(sink, self.every, self.system.columns().len());
        let (outcome, mut recorder) = crate::writer_thread::on_writer_thread(recorder, |front| {
            self.run_streaming(front, progress, None)
        });
        Ok(outcome?.recorded_by(&mut recorder))
    }

    /// The communication points per recorded row: 1, or the output
    /// interval over the step.
    pub fn output_every(&self) -> usize {
        self.every
    }

    /// Run as [`PreparedRun::run`] does, with `observer` told of each
    /// step before the run's own (external inputs, progress), and every
    /// communication point handed to `sink` whatever the output interval:
    /// for a caller that picks the rows itself, later, with a
    /// [`Recorder`] of [`PreparedRun::output_every`] (an isolated run's
    /// child sends every row to its parent, which records them).
    pub fn run_observed(
        self,
        sink: &mut dyn RowSink,
        progress: Option<&mut dyn FnMut(usize, usize)>,
        observer: &mut dyn Observer,
    ) -> Result<RunOutcome, String> {
        self.run_recording(sink, progress, Some(observer), 1)
    }

    fn run_recording(
        self,
        sink: &mut dyn RowSink,
        progress: Option<&mut dyn FnMut(usize, usize)>,
        observer: Option<&mut dyn Observer>,
        every: usize,
    ) -> Result<RunOutcome, String> {
        let mut recorder = Recorder::new(sink, every, self.system.columns().len());
        let outcome = self.run_streaming(&mut recorder, progress, observer)?;
        Ok(outcome.recorded_by(&mut recorder))
    }

    /// The run, every communication point handed to `sink`; the outcome's
    /// rows and summary are left to the [`Recorder`] that picks the rows
    /// ([`RunOutcome::recorded_by`]).
    fn run_streaming(
        mut self,
        sink: &mut dyn RowSink,
        progress: Option<&mut dyn FnMut(usize, usize)>,
        observer: Option<&mut dyn Observer>,
    ) -> Result<RunOutcome, String> {
        let started = std::time::Instant::now();
        let mut watch = Watch {
            inputs: self.inputs.take(),
            progress,
            observer,
        };
        let streamed = simulate_streaming(
            &mut self.system,
            self.master.as_mut(),
            self.start,
            self.step,
            self.stop,
            &mut watch,
            sink,
        )
        .map_err(|e| format!("initialization failed: {e}"))?;
        Ok(RunOutcome {
            stats: ColumnStats::new(streamed.columns.len()),
            columns: streamed.columns,
            rows: 0,
            steps: streamed.rows.saturating_sub(1),
            error: streamed.error,
            ended: streamed.ended,
            master_report: self.master.report(),
            wall_time: started.elapsed().as_secs_f64(),
            warnings: streamed.warnings,
        })
    }
}

/// Build and run `file` with `options` into `sink`, in one call.
pub fn run(
    file: &SystemFile,
    options: &RunOptions,
    sink: &mut dyn RowSink,
) -> Result<RunOutcome, String> {
    PreparedRun::new(file, options)?.run(sink, None)
}

/// What a run did.
#[derive(Clone, Debug)]
pub struct RunOutcome {
    /// The recorded columns, `component.variable`, after `time`.
    pub columns: Vec<String>,
    /// Rows handed to the sink.
    pub rows: usize,
    /// Macro steps completed.
    pub steps: usize,
    /// Why the run stopped before its stop time, if it did: an FMU's
    /// failure, the sink's error or its request to stop.
    pub error: Option<String>,
    /// The component that ended the simulation before the stop time, if
    /// one did: a normal end (FMI 2.0.4 §4.2.3, see [`Ended`]), its last
    /// row recorded at the time it reached.
    pub ended: Option<Ended>,
    /// Each column's least, greatest and last value over the rows
    /// recorded, and the rows' first and last times.
    pub stats: ColumnStats,
    /// What the master algorithm has to say (iterations, rejections).
    pub master_report: Option<String>,
    /// Wall-clock time of the run, in seconds.
    pub wall_time: f64,
    /// Instances that refused `fmi2Terminate` after the last step, one
    /// sentence each ([`crate::system::System::terminate`]): the rows
    /// stand, the command warns.
    pub warnings: Vec<String>,
}

impl RunOutcome {
    /// The outcome with the rows `recorder` passed on and their summary,
    /// once the run has ended: the last point passed on if it was not
    /// ([`Recorder::finish`]), whose error, if any, becomes the run's.
    fn recorded_by<S: RowSink>(mut self, recorder: &mut Recorder<S>) -> RunOutcome {
        if let Err(e) = recorder.finish() {
            self.error.get_or_insert(e);
        }
        self.rows = recorder.stats.rows;
        self.stats = recorder.stats.clone();
        self
    }
}

/// The external inputs, the progress callback and the caller's observer
/// ([`PreparedRun::run_observed`]), consulted by the run.
struct Watch<'p, 'o> {
    inputs: Option<ExternalInputs>,
    progress: Option<&'p mut dyn FnMut(usize, usize)>,
    observer: Option<&'o mut dyn Observer>,
}

impl Observer for Watch<'_, '_> {
    /// Nothing to do between steps without external inputs, progress or
    /// an observer that has something to do.
    fn between_steps(&self) -> bool {
        self.inputs.is_some()
            || self.progress.is_some()
            || self.observer.as_ref().is_some_and(|o| o.between_steps())
    }

    fn before_step(&mut self, system: &mut System, t: f64, init: bool) -> Result<(), FmuError> {
        if let Some(o) = &mut self.observer {
            o.before_step(system, t, init)?;
        }
        match &mut self.inputs {
            Some(i) => i.before_step(system, t, init),
            None => Ok(()),
        }
    }

    fn at_communication_point(&mut self, system: &mut System, t: f64) -> Result<(), FmuError> {
        if let Some(o) = &mut self.observer {
            o.at_communication_point(system, t)?;
        }
        match &mut self.inputs {
            Some(i) => i.at_communication_point(system, t),
            None => Ok(()),
        }
    }

    fn after_step(&mut self, done: usize, total: usize) {
        if let Some(o) = &mut self.observer {
            o.after_step(done, total);
        }
        // every 256 steps keeps even the callback out of the step loop's cost
        if let Some(progress) = &mut self.progress {
            if done.is_multiple_of(256) || done == total {
                progress(done, total);
            }
        }
    }
}

/// The communication points per recorded row for an output interval of
/// `interval` over steps of `step`: the interval must be a whole multiple
/// of the step, up to rounding (a relative 1e-9).
pub fn output_every(interval: Option<f64>, step: f64) -> Result<usize, String> {
    let Some(interval) = interval else {
        return Ok(1);
    };
    if !(interval.is_finite() && interval > 0.0) {
        return Err(format!(
            "--output-interval must be a positive number of seconds, got {interval}"
        ));
    }
    let k = (interval / step).round();
    if k < 1.0 || ((k * step - interval) / interval).abs() > 1e-9 || k > usize::MAX as f64 {
        return Err(format!(
            "--output-interval {interval} s is not a whole multiple of the step {step} s (it is {} steps)",
            interval / step
        ));
    }
    Ok(k as usize)
}

/// A sink between a run and the caller's `sink`: passes on the start,
/// every `every`-th communication point and the last one (see
/// [`RunOptions::output_interval`]), and sums up what it passes on in
/// [`ColumnStats`]. [`PreparedRun::run`] records through one; a caller of
/// [`PreparedRun::run_observed`] may record the rows it is handed with
/// one of its own, with the same result.
pub struct Recorder<S: RowSink> {
    sink: S,
    every: usize,
    /// Communication points seen so far.
    seen: usize,
    /// What was passed on.
    pub stats: ColumnStats,
    /// The last point seen, if it was not passed on: passed on by
    /// [`Recorder::finish`], the run having ended there.
    pending: Option<(f64, Rows)>,
    /// The rows picked from a chunk (`every > 1`).
    picked: Rows,
    picked_times: Vec<f64>,
}

impl<S: RowSink> Recorder<S> {
    /// A recorder of rows `width` wide into `sink`, of every `every`-th
    /// communication point ([`PreparedRun::output_every`]).
    pub fn new(sink: S, every: usize, width: usize) -> Recorder<S> {
        Recorder {
            sink,
            every: every.max(1),
            seen: 0,
            stats: ColumnStats::new(width),
            pending: None,
            picked: Rows::new(width),
            picked_times: Vec::new(),
        }
    }

    /// Pass on the last point of the run if it was not: call it once the
    /// run has ended, completed or not.
    pub fn finish(&mut self) -> Result<(), String> {
        if let Some((t, row)) = self.pending.take() {
            self.sink.write(&[t], &row)?;
            self.stats.add(&[t], &row);
        }
        Ok(())
    }

    /// The caller's sink.
    pub fn into_inner(self) -> S {
        self.sink
    }
}

impl<S: RowSink> RowSink for Recorder<S> {
    fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String> {
        let first = self.seen;
        self.seen += times.len();
        if self.every == 1 {
            self.sink.write(times, rows)?;
            self.stats.add(times, rows);
            return Ok(());
        }
        self.picked = Rows::new(self.stats.min.len());
        self.picked_times.clear();
        for (j, (t, row)) in times.iter().zip(rows).enumerate() {
            if (first + j).is_multiple_of(self.every) {
                self.picked.push_row(row);
                self.picked_times.push(*t);
            }
        }
        let last_row = times.len().checked_sub(1).and_then(|i| rows.get(i));
        self.pending = match (times.last(), last_row) {
            (Some(&t), Some(row)) if !(self.seen - 1).is_multiple_of(self.every) => {
                Some((t, Rows::from_rows(row.len(), [row])))
            }
            _ => None,
        };
        if !self.picked_times.is_empty() {
            self.sink.write(&self.picked_times, &self.picked)?;
            self.stats.add(&self.picked_times, &self.picked);
        }
        Ok(())
    }

    fn stop_requested(&self) -> Option<String> {
        self.sink.stop_requested()
    }
}

/// Named FMUs, opened, and start values checked against them.
pub type OpenedWithStartValues = (Vec<(String, Fmu)>, Vec<(String, ParameterValue)>);

/// Open each `(name, fmu path)` and check each start value
/// `(component.variable, value)` against its FMU ([`check_start_value`]),
/// before anything is instantiated: what `fricsim cosim` builds its
/// system from ([`System::from_fmus`]), so that its `--set` is held to the
/// same rules as `run`'s.
pub fn open_with_start_values(
    components: &[(String, &std::path::Path)],
    start_values: &[(String, StartValue)],
) -> Result<OpenedWithStartValues, String> {
    let fmus = components
        .iter()
        .map(|(name, path)| Ok((name.clone(), Fmu::open(path).map_err(|e| e.to_string())?)))
        .collect::<Result<Vec<_>, String>>()?;
    let checked = check_start_values(&fmus, start_values)?;
    Ok((fmus, checked))
}

/// Each start value `(component.variable, value)` checked against the
/// variable it names among the FMUs ([`check_start_value`]).
fn check_start_values(
    fmus: &[(String, Fmu)],
    start_values: &[(String, StartValue)],
) -> Result<Vec<(String, ParameterValue)>, String> {
    start_values
        .iter()
        .map(|(port, value)| {
            let var = variable_of(fmus, port)?;
            Ok((port.clone(), check_start_value(port, var, value)?))
        })
        .collect()
}

/// The variable `component.variable` among the opened FMUs.
fn variable_of<'a>(fmus: &'a [(String, Fmu)], port: &str) -> Result<&'a ScalarVariable, String> {
    let (c, v) = port
        .split_once('.')
        .ok_or_else(|| format!("start value `{port}`: not of the form component.variable"))?;
    let (_, fmu) = fmus.iter().find(|(n, _)| n == c).ok_or_else(|| {
        let names: Vec<&str> = fmus.iter().map(|(n, _)| n.as_str()).collect();
        format!(
            "start value `{port}`: no component `{c}` (components: {})",
            names.join(", ")
        )
    })?;
    fmu.variable(v).map_err(|_| {
        format!(
            "start value `{port}`: `{c}` has no variable `{v}`{}",
            fmu.description().array_hint(v)
        )
    })
}

/// `value` for the variable `var` (named `port`) as it will be set: the
/// variable may be given a value before initialization (FMI 2.0.4 §2.2.7:
/// not a constant, an independent variable or a calculated parameter; an
/// output or a local only with `initial="exact"` or `"approx"`), the
/// value is of its type (or text that reads as it) and within its
/// declared `min` and `max`.
pub fn check_start_value(
    port: &str,
    var: &ScalarVariable,
    value: &StartValue,
) -> Result<ParameterValue, String> {
    let shown = match value {
        StartValue::Real(x) => format!("{x}"),
        StartValue::Integer(i) => format!("{i}"),
        StartValue::Boolean(b) => format!("{b}"),
        StartValue::String(s) | StartValue::Text(s) => format!("\"{s}\""),
    };
    let refuse = |why: String| format!("cannot set `{port}` to {shown}: {why}");
    let settable = var.variability != Variability::Constant
        && match var.causality {
            Causality::Parameter | Causality::Input => true,
            Causality::Output | Causality::Local => {
                matches!(var.initial, Some(Initial::Exact | Initial::Approx))
            }
            Causality::CalculatedParameter | Causality::Independent => false,
        };
    if !settable {
        return Err(refuse(format!(
            "it has causality \"{}\", variability \"{}\" and initial \"{}\"; FMI 2.0 lets only parameters, inputs and variables with initial=\"exact\" or \"approx\" be set before initialization (FMI 2.0.4 §2.2.7)",
            var.causality,
            var.variability,
            var.initial.map_or("(default)", |i| i.as_str())
        )));
    }
    let type_name = var.kind.type_name();
    let article = if type_name.starts_with(['E', 'I']) {
        "an"
    } else {
        "a"
    };
    let not_of_type = || Err(refuse(format!("not {article} {type_name} value")));
    match &var.kind {
        VariableKind::Real { min, max, .. } => {
            let x = match value {
                StartValue::Real(x) => *x,
                StartValue::Integer(i) => *i as f64,
                StartValue::Text(t) => match t.trim().parse::<f64>() {
                    Ok(x) => x,
                    Err(_) => return not_of_type(),
                },
                _ => return not_of_type(),
            };
            if !x.is_finite() {
                return Err(refuse("not a finite number".to_string()));
            }
            within(
                x,
                min.unwrap_or(f64::NEG_INFINITY),
                max.unwrap_or(f64::INFINITY),
            )
            .map_err(refuse)?;
            Ok(ParameterValue::Number(x))
        }
        VariableKind::Integer { min, max, .. } | VariableKind::Enumeration { min, max, .. } => {
            let i: i64 = match value {
                StartValue::Integer(i) => *i,
                StartValue::Real(x) if x.fract() == 0.0 && x.abs() < 1e18 => *x as i64,
                StartValue::Text(t) => match t.trim().parse::<i64>() {
                    Ok(i) => i,
                    Err(_) => return not_of_type(),
                },
                _ => return not_of_type(),
            };
            let (lo, hi) = (
                min.map_or(i32::MIN as i64, i64::from),
                max.map_or(i32::MAX as i64, i64::from),
            );
            within(i, lo, hi).map_err(refuse)?;
            Ok(ParameterValue::Number(i as f64))
        }
        VariableKind::Boolean { .. } => {
            let b = match value {
                StartValue::Boolean(b) => *b,
                StartValue::Text(t) => match t.trim() {
                    "true" | "1" => true,
                    "false" | "0" => false,
                    _ => {
                        return Err(refuse(
                            "not a Boolean value (true, false, 1 or 0)".to_string(),
                        ))
                    }
                },
                _ => return not_of_type(),
            };
            Ok(ParameterValue::Number(if b { 1.0 } else { 0.0 }))
        }
        VariableKind::String { .. } => match value {
            StartValue::String(s) | StartValue::Text(s) => Ok(ParameterValue::Text(s.clone())),
            _ => not_of_type(),
        },
    }
}

/// `x` within `[lo, hi]`, else why not.
fn within<T: PartialOrd + std::fmt::Display>(x: T, lo: T, hi: T) -> Result<(), String> {
    if x < lo {
        Err(format!("below the declared min = {lo}"))
    } else if x > hi {
        Err(format!("above the declared max = {hi}"))
    } else {
        Ok(())
    }
}
