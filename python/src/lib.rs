//! `fricsim._native`: the host's library (`fricsim`, `host/`) as a CPython
//! extension module, through PyO3. The Python package `fricsim`
//! (`python/fricsim/`) wraps these functions into its public calls
//! (numpy arrays, pandas DataFrames, dataclasses, Dask); here each one
//! does the work in Rust with the GIL released (`Python::allow_threads`),
//! and every error becomes a `fricsim.FricsimError` (a `RuntimeError`)
//! carrying the host's message: the file and line, the instance, the call.
//!
//! Ctrl-C: Python's signal handler only sets a flag while Rust runs. A run
//! hands its rows on in chunks ([`fricsim_core::master::simulate_streaming`]);
//! between chunks it takes the GIL for a moment and calls
//! `Python::check_signals` (PyErr_CheckSignals), and on KeyboardInterrupt
//! asks the run to stop ([`RowSink::stop_requested`]): the instances are
//! freed and the unpacked FMUs removed as on any early stop, then the
//! KeyboardInterrupt is raised.

use fricsim_diagnose::model::Effect;
use fricsim_diagnose::progress_line::with_progress_line;
use fricsim_diagnose::{
    diagnose_and_write, CrossValidate, Options, Progress,
};
use fricsim_fmi::archive::{unpack, UnpackOptions};
use fricsim_fmi::library::platforms;
use fricsim_fmi::ModelDescription;
use fricsim_core::inputs::InputTable;
use fricsim_core::master::{by_name, RowSink};
use fricsim_core::rows::Rows;
use fricsim_core::run::{time_grid, PreparedRun, RunOptions, StartValue};
use fricsim_core::ssp::SystemFile;
use fricsim_core::sweep::{check_axes, run_all, Axis, Plan};
use fricsim_fmi::FmuError;
use pyo3::create_exception;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use serde_json::json;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::time::Duration;

create_exception!(
    fricsim,
    FricsimError,
    PyRuntimeError,
    "An error of the fricsim host: its message names the file and line, the instance and the FMI call."
);

fn host_error(message: impl Into<String>) -> PyErr {
    FricsimError::new_err(message.into())
}

/// A start value from Python, typed as Python types it: `bool`, `int`,
/// `float`, `str` (checked against the variable's type by
/// [`fricsim_core::run::check_start_value`]).
#[derive(FromPyObject)]
enum Value {
    Boolean(bool),
    Integer(i64),
    Real(f64),
    Text(String),
}

impl From<Value> for StartValue {
    fn from(value: Value) -> StartValue {
        match value {
            Value::Boolean(b) => StartValue::Boolean(b),
            Value::Integer(i) => StartValue::Integer(i),
            Value::Real(x) => StartValue::Real(x),
            Value::Text(s) => StartValue::String(s),
        }
    }
}

/// `fricsim.info`: the model description of an FMU (the archive and its
/// `modelDescription.xml` only; the binary is not loaded), as JSON.
#[pyfunction]
fn info(py: Python<'_>, fmu: PathBuf) -> PyResult<String> {
    py.allow_threads(|| -> Result<String, FmuError> {
        let dir = unpack(&fmu, &UnpackOptions::default())?;
        let d = ModelDescription::from_file(&dir.path().join("modelDescription.xml"))?;
        Ok(description_json(&d, &platforms(dir.path())).to_string())
    })
    .map_err(|e| host_error(e.to_string()))
}

fn description_json(d: &ModelDescription, platforms: &[String]) -> serde_json::Value {
    let cs = &d.co_simulation;
    let variables: Vec<serde_json::Value> = d
        .variables
        .iter()
        .map(|v| {
            json!({
                "name": v.name,
                "value_reference": v.value_reference,
                "causality": v.causality.to_string(),
                "variability": v.variability.to_string(),
                // the FMU's own type name: `Float64`, `Int16`, … in FMI 3.0
                "type": v.type_name(),
                "start": v.kind.start_text(),
                "unit": v.kind.unit(),
                "description": v.description,
            })
        })
        .collect();
    let experiment = d.default_experiment.as_ref().map(|e| {
        json!({
            "start_time": e.start_time,
            "stop_time": e.stop_time,
            "tolerance": e.tolerance,
            "step_size": e.step_size,
        })
    });
    json!({
        "fmi_version": d.fmi_version,
        "model_name": d.model_name,
        "guid": d.guid,
        "description": d.description,
        "generation_tool": d.generation_tool,
        "generation_date_and_time": d.generation_date_and_time,
        "model_identifier": cs.model_identifier,
        "model_exchange": d.model_exchange,
        "platforms": platforms,
        "capabilities": {
            "can_handle_variable_communication_step_size": cs.can_handle_variable_communication_step_size,
            "can_interpolate_inputs": cs.can_interpolate_inputs,
            "max_output_derivative_order": cs.max_output_derivative_order,
            "can_be_instantiated_only_once_per_process": cs.can_be_instantiated_only_once_per_process,
            "can_get_and_set_fmu_state": cs.can_get_and_set_fmu_state,
            "can_serialize_fmu_state": cs.can_serialize_fmu_state,
            "provides_directional_derivative": cs.provides_directional_derivative,
        },
        "default_experiment": experiment,
        "variables": variables,
    })
}

/// The rows of a run, `time` then the columns, row after row; between
/// chunks, a look for Ctrl-C.
struct Collect {
    values: Vec<f64>,
    interrupt: RefCell<Option<PyErr>>,
}

impl RowSink for Collect {
    fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String> {
        self.values.reserve(times.len() * (rows.width() + 1));
        for (t, row) in times.iter().zip(rows) {
            self.values.push(*t);
            self.values.extend_from_slice(row);
        }
        Ok(())
    }

    fn stop_requested(&self) -> Option<String> {
        // the signal handler of Python ran in C and set a flag; this runs
        // the Python handler (KeyboardInterrupt for SIGINT)
        let signal = Python::with_gil(|py| py.check_signals()).err()?;
        self.interrupt.replace(Some(signal));
        Some("interrupted".to_string())
    }
}

/// What `run` hands back: the column names (`time` first), the rows, and
/// why the run stopped early, if it did, and the warnings of its end
/// (instances that refused `fmi2Terminate`).
type RunResult = (Vec<String>, Vec<f64>, Option<String>, Vec<String>);

/// [`RunResult`] as `fricsim.run` hands it to Python: the rows as the
/// bytes of their f64 values.
type PyRunResult = (Vec<String>, Py<PyBytes>, Option<String>, Vec<String>);

/// `fricsim.run`: co-simulate a system file exactly as `fricsim run` does
/// (one code path: [`fricsim_core::run::PreparedRun`]), returning the rows
/// instead of writing a CSV.
#[pyfunction]
#[pyo3(signature = (system, start=None, stop=None, step=None, master=None, start_values=Vec::new(), output_interval=None, record=Vec::new(), input=None, step_timeout=None, input_hold=false))]
#[allow(clippy::too_many_arguments)]
fn run(
    py: Python<'_>,
    system: PathBuf,
    start: Option<f64>,
    stop: Option<f64>,
    step: Option<f64>,
    master: Option<String>,
    start_values: Vec<(String, Value)>,
    output_interval: Option<f64>,
    record: Vec<String>,
    input: Option<PathBuf>,
    step_timeout: Option<f64>,
    input_hold: bool,
) -> PyResult<PyRunResult> {
    let call_time_limit = match step_timeout {
        None => None,
        Some(s) if s.is_finite() && s > 0.0 && s < 1e9 => Some(Duration::from_secs_f64(s)),
        Some(s) => {
            return Err(host_error(format!(
                "step_timeout must be a positive number of seconds, got {s}"
            )))
        }
    };
    let start_values = start_values
        .into_iter()
        .map(|(k, v)| (k, StartValue::from(v)))
        .collect();
    let (columns, values, error, warnings) =
        py.allow_threads(move || -> Result<RunResult, PyErr> {
            let file = SystemFile::open(&system).map_err(|e| host_error(e.to_string()))?;
            let options = RunOptions {
                start,
                stop,
                step,
                master,
                start_values,
                output_interval,
                record,
                inputs: match &input {
                    Some(path) => Some(InputTable::read(path).map_err(host_error)?),
                    None => None,
                },
                hold_inputs: input_hold,
                call_time_limit,
            };
            let prepared = PreparedRun::new(&file, &options).map_err(host_error)?;
            let mut sink = Collect {
                values: Vec::new(),
                interrupt: RefCell::new(None),
            };
            let outcome = prepared.run(&mut sink, None).map_err(host_error)?;
            if let Some(signal) = sink.interrupt.into_inner() {
                return Err(signal);
            }
            let mut columns = vec!["time".to_string()];
            columns.extend(outcome.columns);
            Ok((columns, sink.values, outcome.error, outcome.warnings))
        })?;
    let bytes: Vec<u8> = values.iter().flat_map(|x| x.to_ne_bytes()).collect();
    Ok((columns, PyBytes::new(py, &bytes).unbind(), error, warnings))
}

/// One run of a sweep: the recorded columns, their final and RMS values,
/// the communication points reached, the wall time and the error.
type SweepRow = (Vec<String>, Vec<f64>, Vec<f64>, usize, f64, Option<String>);

/// `fricsim.sweep` (one process): every point, each a list of values of
/// `names` (`component.variable`), run as `fricsim sweep` runs it, on
/// `threads` threads.
#[pyfunction]
#[pyo3(signature = (system, names, points, start=None, stop=None, step=None, master=None, threads=1))]
#[allow(clippy::too_many_arguments)]
fn sweep(
    py: Python<'_>,
    system: PathBuf,
    names: Vec<String>,
    points: Vec<Vec<f64>>,
    start: Option<f64>,
    stop: Option<f64>,
    step: Option<f64>,
    master: Option<String>,
    threads: usize,
) -> PyResult<Vec<SweepRow>> {
    if let Some(p) = points.iter().find(|p| p.len() != names.len()) {
        return Err(host_error(format!(
            "a point has {} values for the {} parameters {}",
            p.len(),
            names.len(),
            names.join(", ")
        )));
    }
    py.allow_threads(move || -> Result<Vec<SweepRow>, String> {
        let file = SystemFile::open(&system).map_err(|e| e.to_string())?;
        let (start, stop, step) = time_grid(&file, start, stop, step)?;
        let master = master.unwrap_or_else(|| file.settings.master_or_default());
        by_name(&master)?; // refused before anything runs
        let axes: Vec<Axis> = names
            .iter()
            .enumerate()
            .map(|(k, port)| Axis {
                port: port.clone(),
                values: points.iter().map(|p| p[k]).collect(),
            })
            .collect();
        check_axes(&file, &axes)?;
        let plan = Plan {
            points: points
                .iter()
                .map(|p| names.iter().cloned().zip(p.iter().copied()).collect())
                .collect(),
            start,
            stop,
            step,
            master,
        };
        let outcomes = run_all(&file, &plan, threads)?;
        Ok(outcomes
            .into_iter()
            .map(|o| (o.columns, o.last, o.rms, o.points, o.wall, o.error))
            .collect())
    })
    .map_err(host_error)
}

/// `fricsim.diagnose`: `fricsim diagnose` on a system and measurement
/// files (one record or several), the outputs written into `out`; the
/// report (`report.json`'s content) as JSON. `time_limit`: seconds
/// (default [`fricsim_diagnose::DEFAULT_TIME_LIMIT`], infinity: none);
/// the progress line on stderr when it is a terminal, unless `quiet`.
#[pyfunction]
#[pyo3(signature = (system, data, out, heldout=Vec::new(), candidates=Vec::new(), position_knots=None, max_position_knots=None, alpha=None, smooth=None, blocks=None, cross_validate=None, polish=true, master=None, lugre=None, time_limit=None, quiet=false))]
#[allow(clippy::too_many_arguments)]
fn diagnose(
    py: Python<'_>,
    system: PathBuf,
    data: Vec<PathBuf>,
    out: PathBuf,
    heldout: Vec<PathBuf>,
    candidates: Vec<String>,
    position_knots: Option<usize>,
    max_position_knots: Option<usize>,
    alpha: Option<f64>,
    smooth: Option<f64>,
    blocks: Option<usize>,
    cross_validate: Option<String>,
    polish: bool,
    master: Option<String>,
    lugre: Option<PathBuf>,
    time_limit: Option<f64>,
    quiet: bool,
) -> PyResult<String> {
    py.allow_threads(move || -> Result<String, String> {
        let defaults = Options::default();
        let progress = Progress::new();
        let mut options = Options {
            position_knots: position_knots.unwrap_or(defaults.position_knots),
            max_position_knots: max_position_knots.unwrap_or(defaults.max_position_knots),
            alpha: alpha.unwrap_or(defaults.alpha),
            smooth: smooth.unwrap_or(defaults.smooth),
            blocks: blocks.unwrap_or(defaults.blocks),
            polish,
            master,
            time_limit: match time_limit {
                None => defaults.time_limit,
                Some(s) => fricsim_diagnose::budget::check_time_limit(s)?,
            },
            progress: Some(progress.clone()),
            cross_validate: match cross_validate.as_deref() {
                None | Some("auto") => CrossValidate::Auto,
                Some("always") => CrossValidate::Always,
                Some("never") => CrossValidate::Never,
                Some("records") => CrossValidate::Records,
                Some(other) => {
                    return Err(format!(
                        "cross_validate `{other}`: one of auto, always, never, records"
                    ))
                }
            },
            ..defaults
        };
        options.check()?;
        if !candidates.is_empty() {
            options.candidates = candidates
                .iter()
                .map(|c| Effect::from_name(c))
                .collect::<Result<_, _>>()?;
        }
        let mut file = SystemFile::open(&system).map_err(|e| e.to_string())?;
        let moved = fricsim_diagnose::dahl::move_to_lugre(&mut file, lugre.as_deref())?;
        let d = with_progress_line("fricsim.diagnose", quiet, &progress, || {
            diagnose_and_write(&file, (&data, &heldout), &options, moved, &out)
        })?;
        serde_json::to_string(&d).map_err(|e| e.to_string())
    })
    .map_err(host_error)
}

/// The seed variables of a system (`component.seed` of every component
/// that has a `seed` parameter), for `fricsim.sweep(..., seeds=N)`.
#[pyfunction]
fn seed_ports(py: Python<'_>, system: PathBuf) -> PyResult<Vec<String>> {
    py.allow_threads(|| {
        let file = SystemFile::open(&system).map_err(|e| e.to_string())?;
        fricsim_core::sweep::seed_ports(&file)
    })
    .map_err(host_error)
}

/// `fricsim.pack`: a `.ssd` and the files it points at into one `.ssp`
/// (what travels to the workers of a Dask cluster).
#[pyfunction]
fn pack(py: Python<'_>, ssd: PathBuf, out: PathBuf) -> PyResult<()> {
    py.allow_threads(|| fricsim_core::ssp::pack(Path::new(&ssd), &out))
        .map_err(|e| host_error(e.to_string()))
}

/// The folders `<prefix><pid>-…` in `dir` whose process no longer runs,
/// removed ([`fricsim_core::stale`], as `fricsim run` removes the FMU folders
/// of a killed run): the folders of killed Dask workers.
#[pyfunction]
fn remove_folders_of_gone_processes(dir: PathBuf, prefix: &str) {
    fricsim_core::stale::remove_left_by_gone_processes(&dir, prefix, |p| std::fs::remove_dir_all(p));
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("FricsimError", m.py().get_type::<FricsimError>())?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(pack, m)?)?;
    m.add_function(wrap_pyfunction!(remove_folders_of_gone_processes, m)?)?;
    m.add_function(wrap_pyfunction!(seed_ports, m)?)?;
    Ok(())
}
