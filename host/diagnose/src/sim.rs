//! The two simulations diagnose runs, both through the FMUs:
//!
//! - [`FrictionSim`]: the friction FMU alone, driven along the measured
//!   states (v, x, Fn held over each sample interval), giving the friction
//!   force the law predicts there. This is what the fits minimise against
//!   the force the data imply: thousands of runs, one FMU, no coupling.
//! - [`co_simulate`]: the whole system with the measured inputs, as
//!   `fricsim run` runs it, sampled at the measured times: the residuals on
//!   the measured channels that the RMS figures and the significance test
//!   use.

use super::model::FrictionModel;
use super::problem::{FrictionData, Measured, Setup};
use crate::fmu::model_description::VariableKind;
use crate::fmu::{Fmu, Instance, Rollback, ValueReference};
use crate::inputs::ExternalInputs;
use crate::master::{by_name, by_name_reusing_jacobians, simulate_with};
use crate::ssp::SystemFile;
use crate::system::{ParameterValue, System};
use crate::tangent::Coupling;
use nalgebra::DMatrix;

/// A parameter's value reference and type in the friction FMU.
#[derive(Clone, Copy)]
enum Slot {
    Real(ValueReference),
    Integer(ValueReference),
    Boolean(ValueReference),
}

/// Where parameter `name` of `fmu` is set, and with which type.
fn slot(fmu: &Fmu, name: &str) -> Result<Slot, String> {
    let v = fmu.variable(name).map_err(|e| e.to_string())?;
    Ok(match v.kind {
        VariableKind::Real { .. } => Slot::Real(v.value_reference),
        VariableKind::Boolean { .. } => Slot::Boolean(v.value_reference),
        _ => Slot::Integer(v.value_reference),
    })
}

/// The friction FMU driven along the data.
pub struct FrictionSim {
    fmu: Fmu,
    instance: Instance,
    inputs: [ValueReference; 3],
    force: ValueReference,
    /// The Boolean parameter `parameter_sensitivities`, when the FMU has it
    /// (this project's LuGre.fmu): it then carries `∂F/∂p` along a run.
    sensitivities: Option<ValueReference>,
}

/// What [`FrictionSim::run_record_with`] fills with `∂F/∂p`: the
/// parameters' value references, the intervals wanted, their columns.
type SensitivityColumns<'a> = (&'a [ValueReference], &'a [bool], &'a mut Vec<Vec<f64>>);

/// The friction force along the data and its parameter sensitivities:
/// `columns[j][k]` = `∂F/∂p_j` after interval `k` (0 where not asked for).
pub struct ForceSensitivities {
    pub force: Vec<f64>,
    pub columns: Vec<Vec<f64>>,
}

impl FrictionSim {
    pub fn new(fmu: &Fmu) -> Result<FrictionSim, String> {
        let instance = fmu
            .instantiate("diagnose-friction")
            .map_err(|e| e.to_string())?;
        let vr = |n: &str| -> Result<ValueReference, String> {
            Ok(fmu.variable(n).map_err(|e| e.to_string())?.value_reference)
        };
        Ok(FrictionSim {
            fmu: fmu.clone(),
            instance,
            inputs: [vr("v")?, vr("x")?, vr("Fn")?],
            force: vr("F")?,
            sensitivities: vr("parameter_sensitivities").ok(),
        })
    }

    /// Whether the FMU carries parameter sensitivities.
    pub fn has_sensitivities(&self) -> bool {
        self.sensitivities.is_some()
    }

    /// [`FrictionSim::run`] with `∂F/∂p` for each parameter of
    /// `parameters` (FMU names) after each interval `k` with `wanted[k]`,
    /// from one run: the FMU carries `∂z/∂p` through its steps and gives
    /// `∂F/∂p` through `fmi2GetDirectionalDerivative` with the parameter
    /// as the known (one call per parameter and interval, asked only where
    /// wanted). An error when the FMU carries none.
    pub fn run_with_sensitivities(
        &mut self,
        model: &FrictionModel,
        d: &FrictionData,
        parameters: &[String],
        wanted: &[bool],
    ) -> Result<ForceSensitivities, String> {
        if self.sensitivities.is_none() {
            return Err("the friction FMU carries no parameter sensitivities".into());
        }
        let vrs = parameters
            .iter()
            .map(|n| {
                Ok(self
                    .fmu
                    .variable(n)
                    .map_err(|e| e.to_string())?
                    .value_reference)
            })
            .collect::<Result<Vec<_>, String>>()?;
        let mut out = ForceSensitivities {
            force: Vec::with_capacity(d.t.len()),
            columns: vec![Vec::with_capacity(d.t.len()); vrs.len()],
        };
        for (r, &first) in d.record_starts.iter().enumerate() {
            let last = d.record_starts.get(r + 1).copied().unwrap_or(d.t.len());
            self.run_record_with(
                model,
                d,
                first..last,
                &mut out.force,
                Some((&vrs, wanted, &mut out.columns)),
            )?;
        }
        Ok(out)
    }

    /// The friction force after each interval of `d` for `model`; an error
    /// when the FMU refuses the parameters or a step. The law starts from
    /// rest at the first interval of each record (`d.record_starts`).
    pub fn run(&mut self, model: &FrictionModel, d: &FrictionData) -> Result<Vec<f64>, String> {
        let mut out = Vec::with_capacity(d.t.len());
        for (r, &first) in d.record_starts.iter().enumerate() {
            let last = d.record_starts.get(r + 1).copied().unwrap_or(d.t.len());
            self.run_record_with(model, d, first..last, &mut out, None)?;
        }
        Ok(out)
    }

    /// [`FrictionSim::run`] over the intervals `range` (one record), from
    /// rest, appending the forces to `out` and, with `sensitivities`
    /// (parameters' value references, the intervals wanted, their
    /// columns), `∂F/∂p`.
    fn run_record_with(
        &mut self,
        model: &FrictionModel,
        d: &FrictionData,
        range: std::ops::Range<usize>,
        out: &mut Vec<f64>,
        mut sensitivities: Option<SensitivityColumns<'_>>,
    ) -> Result<(), String> {
        let fail = |e: crate::FmuError| e.to_string();
        let i = &mut self.instance;
        i.reset().map_err(fail)?;
        let t0 = d.t.get(range.start).copied().unwrap_or(0.0);
        i.setup_experiment(t0, None).map_err(fail)?;
        i.enter_initialization_mode().map_err(fail)?;
        for (name, value) in model.parameters() {
            match slot(&self.fmu, &name)? {
                Slot::Real(vr) => i.set_real(&[vr], &[value]),
                Slot::Integer(vr) => i.set_integer(&[vr], &[value as i32]),
                Slot::Boolean(vr) => i.set_boolean(&[vr], &[value != 0.0]),
            }
            .map_err(fail)?;
        }
        if let Some(vr) = self.sensitivities {
            i.set_boolean(&[vr], &[sensitivities.is_some()])
                .map_err(fail)?;
        }
        if !range.is_empty() {
            let k = range.start;
            i.set_real(&self.inputs, &[d.v[k], d.x[k], d.fn_[k]])
                .map_err(fail)?;
        }
        i.exit_initialization_mode().map_err(fail)?;
        let mut f = [0.0];
        for k in range {
            i.set_real(&self.inputs, &[d.v[k], d.x[k], d.fn_[k]])
                .map_err(fail)?;
            i.do_step_with(d.t[k], d.h[k], Rollback::Never)
                .map_err(fail)?;
            i.get_real(&[self.force], &mut f).map_err(fail)?;
            out.push(f[0]);
            if let Some((vrs, wanted, columns)) = sensitivities.as_mut() {
                let mut df = [0.0];
                for (vr, column) in vrs.iter().zip(columns.iter_mut()) {
                    if wanted[k] {
                        i.get_directional_derivative(&[self.force], &[*vr], &[1.0], &mut df)
                            .map_err(fail)?;
                    }
                    column.push(if wanted[k] { df[0] } else { 0.0 });
                }
            }
        }
        // the FMI 2.0 end of a run (§4.2.4); the next run resets
        i.terminate().map_err(fail)?;
        Ok(())
    }
}

/// Residuals of one co-simulation on the measured channels, at the
/// measured times (repeated times compare the first row only).
#[derive(Clone, Debug)]
pub struct ChannelResiduals {
    /// Channel names.
    pub channels: Vec<String>,
    /// Sample indices (into the file) compared.
    pub samples: Vec<usize>,
    /// `values[c][s]`: simulated value of channel c at sample s.
    pub simulated: Vec<Vec<f64>>,
    /// `residuals[c][s]`: measured − simulated.
    pub residuals: Vec<Vec<f64>>,
    /// Set when the run stopped early (the samples after it are missing).
    pub incomplete: Option<String>,
}

impl ChannelResiduals {
    /// No sample yet of the channels `channels` (to append to).
    pub fn empty(channels: &[String]) -> ChannelResiduals {
        ChannelResiduals {
            channels: channels.to_vec(),
            samples: Vec::new(),
            simulated: vec![Vec::new(); channels.len()],
            residuals: vec![Vec::new(); channels.len()],
            incomplete: None,
        }
    }

    /// Per sample: mean over channels of (residual / scale)².
    pub fn squared(&self, scales: &[f64]) -> Vec<f64> {
        (0..self.samples.len())
            .map(|s| {
                self.residuals
                    .iter()
                    .zip(scales)
                    .map(|(r, sc)| (r[s] / sc).powi(2))
                    .sum::<f64>()
                    / scales.len() as f64
            })
            .collect()
    }
}

/// The parameters of the nominal system with the friction component's
/// replaced by `model`'s.
pub fn system_parameters(
    file: &SystemFile,
    setup: &Setup,
    model: &FrictionModel,
) -> Vec<(String, ParameterValue)> {
    system_parameters_with(file, &setup.friction_name, model.parameters())
}

/// The parameters of the system `file` with the component `friction`'s
/// set to `friction_parameters` (its FMU's names).
pub fn system_parameters_with(
    file: &SystemFile,
    friction: &str,
    friction_parameters: Vec<(String, f64)>,
) -> Vec<(String, ParameterValue)> {
    use crate::ssp::Value;
    let mut p: Vec<(String, ParameterValue)> = file
        .parameters
        .iter()
        .map(|d| {
            let v = match &d.value {
                Value::Real(x) => ParameterValue::Number(*x),
                Value::Integer(i) => ParameterValue::Number(*i as f64),
                Value::Boolean(b) => ParameterValue::Number(f64::from(u8::from(*b))),
                Value::String(s) => ParameterValue::Text(s.clone()),
            };
            (format!("{}.{}", d.component, d.variable), v)
        })
        .collect();
    for (name, value) in friction_parameters {
        p.push((format!("{friction}.{name}"), ParameterValue::Number(value)));
    }
    p
}

/// Co-simulate `system` (restarted with `parameters`) over the file's time
/// span with its inputs, and compare with its measured channels (the rows
/// [`super::quality`] left out are not compared).
pub fn co_simulate(
    system: &mut System,
    parameters: &[(String, ParameterValue)],
    setup: &Setup,
    data: &Measured,
) -> Result<ChannelResiduals, String> {
    co_simulate_with(
        system,
        parameters,
        data,
        None,
        &setup.master,
        setup.step,
        setup.reuse_jacobian,
    )
}

/// A co-simulation that did not complete is tried again, in this order:
/// the system's master at a quarter of its step, the step-size-controlled
/// strong coupling (`adaptive`), Newton at a quarter step, Gauss–Seidel at
/// a quarter step (the first that completes is used; each is a different
/// way through a hard stretch: a shorter step, a step that adapts, another
/// coupling). Returns the residuals and, when a fallback was needed, what
/// failed and what ran instead.
pub fn co_simulate_robust(
    system: &mut System,
    parameters: &[(String, ParameterValue)],
    setup: &Setup,
    data: &Measured,
    records: Option<&[usize]>,
) -> Result<(ChannelResiduals, Option<String>), String> {
    let mut failures = Vec::new();
    for (master, step) in &fallback_tries(setup) {
        let outcome = co_simulate_with(
            system,
            parameters,
            data,
            records,
            master,
            *step,
            setup.reuse_jacobian,
        )
        .and_then(|r| match &r.incomplete {
            Some(e) => Err(format!("stopped early: {e}")),
            None => Ok(r),
        });
        match outcome {
            Ok(r) => {
                let note = (!failures.is_empty()).then(|| {
                    format!(
                        "{}; ran with {master} at {step} s instead",
                        failures.join("; ")
                    )
                });
                return Ok((r, note));
            }
            Err(e) => failures.push(format!("{master} at {step} s: {e}")),
        }
    }
    Err(format!(
        "no co-simulation completed ({})",
        failures.join("; ")
    ))
}

/// Run `system` (restarted with `parameters`) over the file's time span
/// with its inputs, with `master` at macro step `step`.
pub fn run_on(
    system: &mut System,
    parameters: &[(String, ParameterValue)],
    data: &Measured,
    master: &str,
    step: f64,
    reuse_jacobian: bool,
) -> Result<crate::master::Run, String> {
    let start = data.time[0];
    let stop = *data.time.last().unwrap_or(&start);
    system
        .restart(start, parameters)
        .map_err(|e| format!("setting up the co-simulation: {e}"))?;
    let mut inputs = ExternalInputs::bind(data.input_table(), system)?.with_slopes(step);
    // (LuGre's step has one solution: a Jacobian reused from the step
    // before lands on the same interface values, within the tolerance)
    let mut master = if reuse_jacobian {
        by_name_reusing_jacobians(master)?
    } else {
        by_name(master)?
    };
    simulate_with(system, master.as_mut(), start, step, stop, &mut inputs)
        .map_err(|e| format!("co-simulation: {e}"))
}

/// The (master, step) pairs a co-simulation is tried with, in order
/// ([`co_simulate_robust`]).
pub fn fallback_tries(setup: &Setup) -> Vec<(String, f64)> {
    let h = setup.step;
    let mut tries: Vec<(String, f64)> = vec![
        (setup.master.clone(), h),
        (setup.master.clone(), h / 4.0),
        ("adaptive".into(), h),
        ("newton".into(), h / 4.0),
        ("gauss-seidel".into(), h / 4.0),
    ];
    let mut seen = Vec::new();
    tries.retain(|t| {
        let new = !seen.contains(t);
        seen.push(t.clone());
        new
    });
    tries
}

/// [`co_simulate`] with a given master and macro step. Several records
/// ([`Measured::join`]) are co-simulated one after the other, each from
/// its own start with its own inputs, and their residuals joined (a record
/// that stops early leaves the records after it out, and says so);
/// `records`: only these (indices into `data.records`, in order), the
/// samples still numbered as rows of the whole `data`.
pub fn co_simulate_with(
    system: &mut System,
    parameters: &[(String, ParameterValue)],
    data: &Measured,
    records: Option<&[usize]>,
    master: &str,
    step: f64,
    reuse_jacobian: bool,
) -> Result<ChannelResiduals, String> {
    if data.records.len() == 1 {
        return co_simulate_record(system, parameters, data, master, step, reuse_jacobian);
    }
    let all: Vec<usize> = (0..data.records.len()).collect();
    let mut joined: Option<ChannelResiduals> = None;
    for &i in records.unwrap_or(&all) {
        let record = &data.records[i];
        let r = co_simulate_record(
            system,
            parameters,
            &data.record(i),
            master,
            step,
            reuse_jacobian,
        )?;
        let j = joined.get_or_insert_with(|| ChannelResiduals::empty(&r.channels));
        j.samples
            .extend(r.samples.iter().map(|k| k + record.rows.start));
        for c in 0..r.channels.len() {
            j.simulated[c].extend_from_slice(&r.simulated[c]);
            j.residuals[c].extend_from_slice(&r.residuals[c]);
        }
        if let Some(e) = r.incomplete {
            j.incomplete = Some(format!("{}: {e}", record.label));
            break;
        }
    }
    joined.ok_or_else(|| "no record to co-simulate".to_string())
}

/// [`co_simulate_with`] of one record.
fn co_simulate_record(
    system: &mut System,
    parameters: &[(String, ParameterValue)],
    data: &Measured,
    master: &str,
    step: f64,
    reuse_jacobian: bool,
) -> Result<ChannelResiduals, String> {
    let run = run_on(system, parameters, data, master, step, reuse_jacobian)?;
    compare(&run, data, step)
}

/// The residuals of the measured channels of `data` against `run` (a
/// co-simulation of its time span at macro step `step`).
fn compare(
    run: &crate::master::Run,
    data: &Measured,
    step: f64,
) -> Result<ChannelResiduals, String> {
    let mut samples = Vec::new();
    for (k, &t) in data.time.iter().enumerate() {
        let repeated = (k > 0 && data.time[k - 1] == t) || data.quality.excluded[k];
        let reached = run.time.last().is_some_and(|&last| t <= last + 1e-9 * step);
        if !repeated && reached {
            samples.push(k);
        }
    }
    let mut simulated = Vec::new();
    let mut residuals = Vec::new();
    for (name, values) in &data.outputs {
        let col = run
            .columns
            .iter()
            .position(|c| c == name)
            .ok_or_else(|| format!("the co-simulation does not record `{name}`"))?;
        let series: Vec<f64> = run.rows.iter().map(|r| r[col]).collect();
        let mut cursor = crate::inputs::Cursor::default();
        let sim: Vec<f64> = samples
            .iter()
            .map(|&k| {
                let time = data.time[k];
                crate::inputs::interpolate_from(&mut cursor, time, &run.time, &series, false)
            })
            .collect();
        residuals.push(
            samples
                .iter()
                .zip(&sim)
                .map(|(&k, s)| values[k] - s)
                .collect(),
        );
        simulated.push(sim);
    }
    Ok(ChannelResiduals {
        channels: data.outputs.iter().map(|(n, _)| n.clone()).collect(),
        samples,
        simulated,
        residuals,
        incomplete: run.error.clone(),
    })
}

/// The system's parameters and the friction law's values (its FMU's
/// names) of one co-simulation.
pub type SystemAndFriction<'a> = (&'a [(String, ParameterValue)], &'a [(String, f64)]);

/// [`co_simulate_with`] at the diagnosis's master and step (no fallback),
/// with the sensitivities of the simulated channels to the friction
/// parameters `parameters` (the law FMU's names) carried along each
/// record's co-simulation ([`Coupling::sensitivities`]): per channel, a
/// row per compared sample (as the residuals' `samples`), a column per
/// parameter. `friction`: the law's values (`FrictionModel::parameters`).
pub fn co_simulate_with_sensitivities(
    system: &mut System,
    (system_parameters, friction): SystemAndFriction<'_>,
    setup: &Setup,
    data: &Measured,
    records: Option<&[usize]>,
    coupling: &Coupling,
    parameters: &[String],
) -> Result<(ChannelResiduals, Vec<DMatrix<f64>>), String> {
    let all: Vec<usize> = (0..data.records.len().max(1)).collect();
    let mut joined: Option<(ChannelResiduals, Vec<Vec<f64>>)> = None;
    let channels: Vec<String> = data.outputs.iter().map(|(n, _)| n.clone()).collect();
    for &i in records.unwrap_or(&all) {
        let owned;
        let (record, first) = if data.records.len() <= 1 {
            (data, 0)
        } else {
            owned = data.record(i);
            (&owned, data.records[i].rows.start)
        };
        let run = run_on(
            system,
            system_parameters,
            record,
            &setup.master,
            setup.step,
            setup.reuse_jacobian,
        )?;
        if let Some(e) = &run.error {
            return Err(format!("stopped early: {e}"));
        }
        let r = compare(&run, record, setup.step)?;
        let by_row =
            coupling.sensitivities((&run, &setup.master), friction, parameters, &channels)?;
        let (residuals, rows) = joined.get_or_insert_with(|| {
            (
                ChannelResiduals::empty(&r.channels),
                vec![Vec::new(); channels.len()],
            )
        });
        // at each compared sample, interpolated between the run's rows
        // as the simulated channels are ([`compare`]): the derivative of
        // the interpolated output
        for (c, m) in by_row.iter().enumerate() {
            let columns: Vec<Vec<f64>> = (0..parameters.len())
                .map(|j| {
                    let series: Vec<f64> = m.column(j).iter().copied().collect();
                    let mut cursor = crate::inputs::Cursor::default();
                    r.samples
                        .iter()
                        .map(|&k| {
                            crate::inputs::interpolate_from(
                                &mut cursor,
                                record.time[k],
                                &run.time,
                                &series,
                                false,
                            )
                        })
                        .collect()
                })
                .collect();
            for s in 0..r.samples.len() {
                rows[c].extend(columns.iter().map(|column| column[s]));
            }
        }
        residuals
            .samples
            .extend(r.samples.iter().map(|k| k + first));
        for c in 0..r.channels.len() {
            residuals.simulated[c].extend_from_slice(&r.simulated[c]);
            residuals.residuals[c].extend_from_slice(&r.residuals[c]);
        }
    }
    let (residuals, rows) = joined.ok_or_else(|| "no record to co-simulate".to_string())?;
    let n = residuals.samples.len();
    let by_sample = rows
        .into_iter()
        .map(|values| DMatrix::from_row_slice(n, parameters.len(), &values))
        .collect();
    Ok((residuals, by_sample))
}

/// The friction law's inputs and force along a co-simulation of the
/// nominal system with the data's inputs: for a plant whose inverse
/// dynamics diagnose does not know (not a Rig1D) and no measured
/// friction force. The force is then not estimated from the data: every
/// fit goes by output error through co-simulation, and these series
/// only set the candidates' starting ranges (speeds, travel) and the
/// states the report bins the change of the force by. `why` says why
/// the force could not be estimated.
pub fn friction_data_simulated(
    setup: &Setup,
    file: &SystemFile,
    system: &mut System,
    data: &Measured,
    why: &str,
) -> Result<FrictionData, String> {
    FrictionData::per_record(data, |record| {
        record_friction_data_simulated(setup, file, system, record, why)
    })
}

/// [`friction_data_simulated`] of one record.
fn record_friction_data_simulated(
    setup: &Setup,
    file: &SystemFile,
    system: &mut System,
    data: &Measured,
    why: &str,
) -> Result<FrictionData, String> {
    let params = system_parameters(file, setup, &setup.nominal);
    // tried as every co-simulation of the diagnosis is
    let mut failures = Vec::new();
    let mut completed = None;
    for (master, step) in fallback_tries(setup) {
        match run_on(system, &params, data, &master, step, setup.reuse_jacobian) {
            Ok(run) if run.error.is_none() => {
                completed = Some(run);
                break;
            }
            Ok(run) => failures.push(format!(
                "{master} at {step} s: stopped early: {}",
                run.error.unwrap_or_default()
            )),
            Err(e) => failures.push(format!("{master} at {step} s: {e}")),
        }
    }
    let run = completed.ok_or_else(|| {
        format!(
            "the nominal system as given cannot be co-simulated: no co-simulation completed ({})",
            failures.join("; ")
        )
    })?;
    let f = &setup.friction_name;
    let series = |port: &str| -> Option<Vec<f64>> {
        let col = run.columns.iter().position(|c| c == port)?;
        Some(run.rows.iter().map(|r| r[col]).collect())
    };
    let law_input = |var: &str| -> Vec<f64> {
        let port = format!("{f}.{var}");
        if let Some(col) = data.column(&port) {
            return col.to_vec();
        }
        let simulated = setup.input_source(system, var).and_then(|src| series(&src));
        match simulated {
            Some(s) => {
                let mut cursor = crate::inputs::Cursor::default();
                data.time
                    .iter()
                    .map(|&t| crate::inputs::interpolate_from(&mut cursor, t, &run.time, &s, false))
                    .collect()
            }
            None => vec![0.0; data.time.len()],
        }
    };
    let (v, x, fn_) = (law_input("v"), law_input("x"), law_input("Fn"));
    let force = series(&format!("{f}.F"))
        .ok_or_else(|| format!("the co-simulation does not record `{f}.F`"))?;
    let n = data.time.len();
    let mut d = FrictionData {
        position_resolution: setup
            .input_source(system, "x")
            .and_then(|src| data.column(&src))
            .map(crate::quality::resolution),
        position_step: setup
            .input_source(system, "x")
            .and_then(|src| data.column(&src))
            .map(crate::quality::step),
        normal_force_measured: data.column(&format!("{f}.Fn")).is_some()
            && fn_.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
                > fn_.iter().cloned().fold(f64::INFINITY, f64::min),
        ..FrictionData::empty(format!(
            "not estimated ({why}): every fit is by output error through co-simulation of the whole system"
        ))
    };
    let mut force_cursor = crate::inputs::Cursor::default();
    for k in 0..n - 1 {
        if data.time[k + 1] > data.time[k] {
            d.t.push(data.time[k]);
            d.h.push(data.time[k + 1] - data.time[k]);
            d.end.push(k + 1);
            d.v.push(v[k]);
            d.x.push(x[k]);
            d.fn_.push(fn_[k]);
            d.f.push(crate::inputs::interpolate_from(
                &mut force_cursor,
                data.time[k + 1],
                &run.time,
                &force,
                false,
            ));
            d.trusted
                .push(!data.quality.excluded[k + 1] && !data.quality.after_gap[k + 1]);
        }
    }
    Ok(d)
}
