//! What `fricsim diagnose` works on: the measurements checked against the
//! system, the friction component, and the friction force the data imply.
//!
//! **Measurements** (a CSV): `time` first, then columns named
//! `component.variable`. A column naming an unconnected input drives it
//! (interpolated as `fricsim run --input` does); a column naming an output
//! is a measured channel, compared with the simulation.
//!
//! **Friction force implied by the data**, on each sample interval
//! `[t_k, t_k+1]`:
//! - measured directly when `friction.F` is a column;
//! - otherwise by inverse dynamics of the Rig1D the friction acts on
//!   (Sun et al. 2016, eq. 15; the EMPS benchmark's inverse dynamic model), from
//!   its equation `m·ẍ = k·(x_a − x) − c·ẋ + F_ext − F + F_d(t) + F_ctrl`:
//!   `F = k·(x_a − x) − c·ẋ + F_ext + F_d(t) + G·u_ctrl − m·ẍ`, with x
//!   from the measured `rig.x` smoothed by a Savitzky–Golay filter (local
//!   quadratic), ẋ its difference over the interval, ẍ the central
//!   difference of ẋ, and the controller's effort `u_ctrl` measured.
//!
//! The friction law's inputs on the interval (slip velocity v, position x,
//! normal force Fn) come from their columns, or from the smoothed position
//! when they are connected to the rig's `v` and `x`.

use super::model::{Context, FrictionModel};
use super::quality::{self, Quality};
use crate::fmu::model_description::{Causality, VariableKind};
use crate::fmu::Fmu;
use crate::inputs::InputTable;
use crate::ssp::SystemFile;
use crate::system::{ComponentInstance, System};
use std::collections::BTreeMap;
use std::path::Path;

/// Fewest samples diagnose accepts in a file.
pub const MIN_SAMPLES: usize = 50;

/// A measurement file checked against the system.
#[derive(Clone, Debug)]
pub struct Measured {
    pub label: String,
    pub time: Vec<f64>,
    /// Columns that drive unconnected inputs.
    pub inputs: Vec<(String, Vec<f64>)>,
    /// Measured output channels.
    pub outputs: Vec<(String, Vec<f64>)>,
    /// Spikes, dropouts, gaps and saturation found in the file (spikes and
    /// dropouts already repaired in the columns above), and the rows left
    /// out of scores and fits ([`super::quality`]).
    pub quality: Quality,
    /// The records (files) joined into these rows: one for a single file
    /// ([`Measured::join`]).
    pub records: Vec<Record>,
}

/// One record of several measured on the same system (a training run and
/// a run with pulses, constant-velocity runs, break-away tests), joined
/// into one [`Measured`] by [`Measured::join`]: its rows follow the
/// previous record's after one sample spacing, so that the joined times
/// increase and every time-based split (held-out blocks, folds) works on
/// them as on one file, while each record is co-simulated from its own
/// start, with its own initial state and inputs, in its own time.
#[derive(Clone, Debug)]
pub struct Record {
    pub label: String,
    /// Its rows in the joined data.
    pub rows: std::ops::Range<usize>,
    /// Added to the record's own times to place it on the joined time line.
    pub offset: f64,
    /// The record's own times, as read (exactly: the joined times less
    /// the offset may differ in the last bit).
    pub time: Vec<f64>,
    /// What the inspection found in the record ([`super::quality`]).
    pub quality: Quality,
}

impl Measured {
    /// Read `path` and sort its columns into inputs and measured outputs of
    /// `system`; refuse unknown columns, columns that are neither, too few
    /// samples, a time that does not increase overall, and a file with no
    /// output to compare.
    pub fn read(path: &Path, system: &System) -> Result<Measured, String> {
        let mut table = InputTable::read(path)?;
        let shown = path.display().to_string();
        let quality = quality::inspect(&table.time, &mut table.columns, &table.lines);
        if quality.excluded_samples as f64 > quality::MAX_FLAGGED_SHARE * table.time.len() as f64 {
            let first: Vec<String> = quality
                .findings
                .iter()
                .take(5)
                .map(|f| f.describe(&shown))
                .collect();
            return Err(format!(
                "{shown}: too damaged for a diagnosis: {} of its {} samples are flagged ({} spikes, {} dropouts, {} saturated columns); first: {}",
                quality.excluded_samples,
                table.time.len(),
                quality.spikes,
                quality.dropouts,
                quality.saturated,
                first.join("; ")
            ));
        }
        if table.time.len() < MIN_SAMPLES {
            return Err(format!(
                "{shown}: {} samples; diagnose needs at least {MIN_SAMPLES}",
                table.time.len()
            ));
        }
        let (t0, t1) = (table.time[0], table.time[table.time.len() - 1]);
        if t1 <= t0 {
            return Err(format!(
                "{shown}: time does not advance (from {t0} to {t1} s)"
            ));
        }
        let mut inputs = Vec::new();
        let mut outputs = Vec::new();
        for (name, values) in table.columns {
            let (i, var) = system.port(&name).map_err(|e| {
                format!(
                    "{shown}: column `{name}` names no variable of the system: {e}; {}",
                    known_columns(system)
                )
            })?;
            if !matches!(var.kind, VariableKind::Real { .. }) {
                return Err(format!(
                    "{shown}: column `{name}` is a {} variable; only Real variables can be measured or driven",
                    var.kind.type_name()
                ));
            }
            let connected = system
                .connections
                .iter()
                .any(|c| c.to == (i, var.value_reference));
            match var.causality {
                Causality::Input if !connected => inputs.push((name, values)),
                Causality::Output => outputs.push((name, values)),
                Causality::Input => {
                    return Err(format!(
                        "{shown}: column `{name}` is an input driven by a connection; it can be neither set from the data nor compared (measure the output it comes from); {}",
                        known_columns(system)
                    ))
                }
                other => {
                    return Err(format!(
                        "{shown}: column `{name}` has causality \"{other}\": it cannot be compared with the simulation; {}",
                        known_columns(system)
                    ))
                }
            }
        }
        if outputs.is_empty() {
            return Err(format!(
                "{shown}: no column names an output of the system, so nothing can be compared; {}",
                known_columns(system)
            ));
        }
        Ok(Measured {
            label: shown.clone(),
            records: vec![Record {
                label: shown,
                rows: 0..table.time.len(),
                offset: 0.0,
                time: table.time.clone(),
                quality: quality.clone(),
            }],
            time: table.time,
            inputs,
            outputs,
            quality,
        })
    }

    /// Several records of the same system as one: the same input and
    /// output columns (refused otherwise, naming both files' columns), each
    /// record's rows after the previous one's, its times shifted to follow
    /// them by one sample spacing ([`Record`]). One record is returned as
    /// it is.
    pub fn join(mut parts: Vec<Measured>) -> Result<Measured, String> {
        if parts.len() <= 1 {
            return parts
                .pop()
                .ok_or_else(|| "no measurements given".to_string());
        }
        let names = |m: &Measured| -> (Vec<String>, Vec<String>) {
            (
                m.inputs.iter().map(|(n, _)| n.clone()).collect(),
                m.outputs.iter().map(|(n, _)| n.clone()).collect(),
            )
        };
        let first = names(&parts[0]);
        for p in &parts[1..] {
            let these = names(p);
            if these != first {
                return Err(format!(
                    "{} has the inputs {:?} and outputs {:?}, but {} has the inputs {:?} and outputs {:?}; records diagnosed together must have the same columns",
                    p.label, these.0, these.1, parts[0].label, first.0, first.1
                ));
            }
        }
        let mut joined = Measured {
            label: parts
                .iter()
                .map(|p| p.label.as_str())
                .collect::<Vec<_>>()
                .join(" + "),
            time: Vec::new(),
            inputs: first.0.iter().map(|n| (n.clone(), Vec::new())).collect(),
            outputs: first.1.iter().map(|n| (n.clone(), Vec::new())).collect(),
            quality: Quality::default(),
            records: Vec::new(),
        };
        for p in parts {
            let offset = match joined.time.last() {
                None => 0.0,
                Some(&end) => end + quality::median_spacing(&p.time) - p.time[0],
            };
            let start = joined.time.len();
            joined.time.extend(p.time.iter().map(|t| t + offset));
            for (to, (_, from)) in joined.inputs.iter_mut().zip(&p.inputs) {
                to.1.extend_from_slice(from);
            }
            for (to, (_, from)) in joined.outputs.iter_mut().zip(&p.outputs) {
                to.1.extend_from_slice(from);
            }
            joined.quality.append(p.quality.clone(), &p.label);
            joined.records.push(Record {
                label: p.label,
                rows: start..joined.time.len(),
                offset,
                time: p.time,
                quality: p.quality,
            });
        }
        Ok(joined)
    }

    /// Record `i` alone, in its own time.
    pub fn record(&self, i: usize) -> Measured {
        let r = &self.records[i];
        let rows = r.rows.clone();
        let cut = |cols: &[(String, Vec<f64>)]| -> Vec<(String, Vec<f64>)> {
            cols.iter()
                .map(|(n, v)| (n.clone(), v[rows.clone()].to_vec()))
                .collect()
        };
        Measured {
            label: r.label.clone(),
            time: r.time.clone(),
            inputs: cut(&self.inputs),
            outputs: cut(&self.outputs),
            quality: r.quality.clone(),
            records: vec![Record {
                label: r.label.clone(),
                rows: 0..rows.len(),
                offset: 0.0,
                time: r.time.clone(),
                quality: r.quality.clone(),
            }],
        }
    }

    /// The record holding row `k`.
    pub fn record_of(&self, k: usize) -> usize {
        self.records
            .iter()
            .position(|r| r.rows.contains(&k))
            .unwrap_or(self.records.len() - 1)
    }

    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.inputs
            .iter()
            .chain(&self.outputs)
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The input columns as a table for [`crate::inputs::ExternalInputs`].
    pub fn input_table(&self) -> InputTable {
        InputTable {
            path: self.label.clone().into(),
            time: self.time.clone(),
            columns: self.inputs.clone(),
            lines: Vec::new(),
        }
    }
}

/// `outputs: a, b; unconnected inputs: c` for messages.
fn known_columns(system: &System) -> String {
    let mut outs = Vec::new();
    let mut ins = Vec::new();
    for (i, c) in system.components.iter().enumerate() {
        for v in &c.fmu.description().variables {
            if !matches!(v.kind, VariableKind::Real { .. }) {
                continue;
            }
            let port = format!("{}.{}", c.name, v.name);
            match v.causality {
                Causality::Output => outs.push(port),
                Causality::Input
                    if !system
                        .connections
                        .iter()
                        .any(|k| k.to == (i, v.value_reference)) =>
                {
                    ins.push(port)
                }
                _ => {}
            }
        }
    }
    format!(
        "columns may be outputs ({}) or unconnected inputs ({})",
        outs.join(", "),
        if ins.is_empty() {
            "none".to_string()
        } else {
            ins.join(", ")
        }
    )
}

/// The value of any scalar variable as a number (Booleans 0/1).
pub fn read_value(instance: &mut ComponentInstance, fmu: &Fmu, name: &str) -> Result<f64, String> {
    let var = fmu.variable(name).map_err(|e| e.to_string())?;
    let vr = var.value_reference;
    let fail = |e: crate::FmuError| format!("reading `{name}`: {e}");
    Ok(match var.kind {
        VariableKind::Real { .. } => {
            let mut x = [0.0];
            instance.get_real(&[vr], &mut x).map_err(fail)?;
            x[0]
        }
        VariableKind::Integer { .. } | VariableKind::Enumeration { .. } => {
            let mut x = [0];
            instance.get_integer(&[vr], &mut x).map_err(fail)?;
            x[0] as f64
        }
        VariableKind::Boolean { .. } => {
            let mut x = [false];
            instance.get_boolean(&[vr], &mut x).map_err(fail)?;
            f64::from(u8::from(x[0]))
        }
        VariableKind::String { .. } => return Err(format!("`{name}` is a String")),
    })
}

/// Where the friction law's inputs and force come from on each interval.
#[derive(Clone, Debug)]
pub struct FrictionData {
    /// Interval start times and lengths (intervals of zero length, the
    /// events of the file, are left out).
    pub t: Vec<f64>,
    pub h: Vec<f64>,
    /// Index of the interval's end sample in the file.
    pub end: Vec<usize>,
    pub v: Vec<f64>,
    pub x: Vec<f64>,
    pub fn_: Vec<f64>,
    /// Friction force implied by the data.
    pub f: Vec<f64>,
    /// How the force was obtained, in words.
    pub source: String,
    /// What the measured position resolves (m, [`quality::resolution`]),
    /// when the law's position comes from a measured column.
    pub position_resolution: Option<f64>,
    /// The smallest displacement one reading of that column registers (m,
    /// [`quality::step`]): its encoder's count.
    pub position_step: Option<f64>,
    /// Whether a normal force is measured (and varies).
    pub normal_force_measured: bool,
    /// Whether the interval's force is trusted for fitting: not within the
    /// smoothing window of the file's ends, where the Savitzky–Golay fit
    /// shrinks to nothing and the acceleration is one-sided, so that an
    /// experiment that starts with a transient does not leave one estimate
    /// of hundreds of newtons in the fit; and not where the contact sticks
    /// (|v| below [`STICK_SPEED_FRACTION`] of the RMS speed), where the
    /// force is whatever balances the rig, not the law's level, and a law
    /// driven by the (noisy, near-zero) estimated velocity cannot follow it.
    /// The co-simulation scores cover these intervals too.
    pub trusted: Vec<bool>,
    /// The first interval of each record ([`Record`]): the friction law
    /// starts again from rest there (`[0]` for one file).
    pub record_starts: Vec<usize>,
}

impl FrictionData {
    /// No interval yet, of one record, obtained as `source` says.
    pub(crate) fn empty(source: String) -> FrictionData {
        FrictionData {
            t: Vec::new(),
            h: Vec::new(),
            end: Vec::new(),
            v: Vec::new(),
            x: Vec::new(),
            fn_: Vec::new(),
            f: Vec::new(),
            source,
            position_resolution: None,
            position_step: None,
            normal_force_measured: false,
            trusted: Vec::new(),
            record_starts: vec![0],
        }
    }

    /// `one` of each record of `data` (of `data` itself when it is one
    /// record), joined ([`FrictionData::join`]); an error names its record.
    pub(crate) fn per_record(
        data: &Measured,
        mut one: impl FnMut(&Measured) -> Result<FrictionData, String>,
    ) -> Result<FrictionData, String> {
        if data.records.len() == 1 {
            return one(data);
        }
        let parts = (0..data.records.len())
            .map(|i| {
                let record = data.record(i);
                one(&record).map_err(|e| format!("{}: {e}", record.label))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(FrictionData::join(parts, data))
    }

    /// The friction data of each record of `data`, joined as its rows are
    /// ([`Measured::join`]): times on the joined time line, sample indices
    /// into the joined rows.
    fn join(parts: Vec<FrictionData>, data: &Measured) -> FrictionData {
        let min = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let mut joined = FrictionData::empty(String::new());
        joined.record_starts.clear();
        for (part, record) in parts.into_iter().zip(&data.records) {
            joined.record_starts.push(joined.t.len());
            joined.t.extend(part.t.iter().map(|t| t + record.offset));
            joined
                .end
                .extend(part.end.iter().map(|k| k + record.rows.start));
            joined.h.extend(part.h);
            joined.v.extend(part.v);
            joined.x.extend(part.x);
            joined.fn_.extend(part.fn_);
            joined.f.extend(part.f);
            joined.trusted.extend(part.trusted);
            if joined.source.is_empty() {
                joined.source = part.source;
            }
            joined.position_resolution = min(joined.position_resolution, part.position_resolution);
            joined.position_step = min(joined.position_step, part.position_step);
            joined.normal_force_measured |= part.normal_force_measured;
        }
        joined
    }
}

/// The system around the friction FMU.
pub struct Setup {
    /// Index of the friction component in the system.
    pub friction: usize,
    pub friction_name: String,
    pub friction_fmu: Fmu,
    /// Nominal friction parameters.
    pub nominal: FrictionModel,
    /// Rig parameters by name (empty without a rig).
    pub rig: Option<(String, BTreeMap<String, f64>)>,
    /// Macro step of the co-simulation.
    pub step: f64,
    pub master: String,
    /// Whether the co-simulations reuse each step's Newton Jacobian for
    /// the next ([`crate::master::strong::StrongCoupling::reuse_jacobian`]):
    /// on the output-error path, whose fits run hundreds of them; the
    /// Rig1D path's (fewer) take a new one at every step, as `fricsim run`
    /// does.
    pub reuse_jacobian: bool,
}

/// Rig1D parameters used by the inverse dynamics.
const RIG_PARAMETERS: [&str; 17] = [
    "m",
    "c",
    "k",
    "x_a0",
    "v_a",
    "act_amp",
    "act_freq",
    "actuator",
    "F_step",
    "t_step",
    "drive_amp",
    "drive_freq",
    "control",
    "ctrl_gain",
    "v_surface",
    "dither_amp",
    "F_ext",
];

impl Setup {
    /// Find the friction component (the one LuGre FMU) and the rig its
    /// force acts on, and read their parameters from a freshly built system.
    pub fn new(
        file: &SystemFile,
        system: &mut System,
        step: f64,
        master: &str,
    ) -> Result<Setup, String> {
        let lugre: Vec<usize> = (0..system.components.len())
            .filter(|&i| system.components[i].fmu.description().model_name == "LuGre")
            .collect();
        let friction = match lugre.as_slice() {
            [i] => *i,
            [] => {
                let models: Vec<String> = system
                    .components
                    .iter()
                    .map(|c| format!("{} ({})", c.name, c.fmu.description().model_name))
                    .collect();
                return Err(format!(
                    "{}: diagnose refits a LuGre friction FMU (its features are the candidate effects), and the system has none: {}",
                    file.ssd,
                    models.join(", ")
                ));
            }
            _ => {
                return Err(format!(
                    "{}: {} LuGre components; diagnose refits exactly one",
                    file.ssd,
                    lugre.len()
                ))
            }
        };
        let fmu = system.components[friction].fmu.clone();
        let name = system.components[friction].name.clone();
        let mut values = BTreeMap::new();
        for v in &fmu.description().variables {
            if v.causality == Causality::Parameter {
                let x = read_value(&mut system.components[friction].instance, &fmu, &v.name)?;
                values.insert(v.name.clone(), x);
            }
        }
        let nominal = FrictionModel::from_values(&values)?;
        // the rig: the component whose input F the friction force drives
        let f_vr = fmu
            .variable("F")
            .map_err(|e| e.to_string())?
            .value_reference;
        let rig = match system
            .connections
            .iter()
            .find(|c| c.from == (friction, f_vr))
        {
            Some(c) => {
                let r = c.to.0;
                let rfmu = system.components[r].fmu.clone();
                if rfmu.description().model_name != "Rig1D" {
                    None
                } else {
                    let mut p = BTreeMap::new();
                    for n in RIG_PARAMETERS {
                        p.insert(
                            n.to_string(),
                            read_value(&mut system.components[r].instance, &rfmu, n)?,
                        );
                    }
                    Some((system.components[r].name.clone(), p))
                }
            }
            None => None,
        };
        Ok(Setup {
            reuse_jacobian: false,
            friction,
            friction_name: name,
            friction_fmu: fmu,
            nominal,
            rig,
            step,
            master: master.to_string(),
        })
    }

    /// The port (`component.variable`) that drives the friction FMU's input
    /// `var` through a connection, if one does.
    pub fn input_source(&self, system: &System, var: &str) -> Option<String> {
        let vr = self.friction_fmu.variable(var).ok()?.value_reference;
        system
            .connections
            .iter()
            .find(|c| c.to == (self.friction, vr))
            .map(|c| {
                let from = &system.components[c.from.0];
                let name = from
                    .fmu
                    .description()
                    .variables
                    .iter()
                    .find(|v| v.value_reference == c.from.1 && v.causality == Causality::Output)
                    .map_or("?".to_string(), |v| v.name.clone());
                format!("{}.{}", from.name, name)
            })
    }

    /// Whether the force the data imply can be estimated: measured as
    /// `friction.F`, or by the inverse dynamics of a Rig1D the friction
    /// acts on. Otherwise diagnose fits by output error alone
    /// ([`super::sim::friction_data_simulated`]); the reason when not.
    pub fn force_estimable(&self, data: &Measured) -> Result<(), String> {
        let f = &self.friction_name;
        if data.column(&format!("{f}.F")).is_some() || self.rig.is_some() {
            Ok(())
        } else {
            Err(format!(
                "`{f}.F` is not measured and its force does not act on a Rig1D whose inverse dynamics diagnose knows"
            ))
        }
    }

    /// The friction force and law inputs the data imply, on every interval
    /// (of each record on its own: the smoothing and the differences do
    /// not reach across from one record into the next).
    pub fn friction_data(
        &self,
        system: &System,
        data: &Measured,
        smooth: f64,
    ) -> Result<FrictionData, String> {
        FrictionData::per_record(data, |record| {
            self.record_friction_data(system, record, smooth)
        })
    }

    /// [`Setup::friction_data`] of one record.
    fn record_friction_data(
        &self,
        system: &System,
        data: &Measured,
        smooth: f64,
    ) -> Result<FrictionData, String> {
        let f = &self.friction_name;
        let port_source = |var: &str| self.input_source(system, var);
        let time = &data.time;
        let n = time.len();
        // intervals of positive length
        let mut t = Vec::new();
        let mut h = Vec::new();
        let mut end = Vec::new();
        for k in 0..n - 1 {
            if time[k + 1] > time[k] {
                t.push(time[k]);
                h.push(time[k + 1] - time[k]);
                end.push(k + 1);
            }
        }
        let m = t.len();
        let start_of = |j: usize| end[j] - 1;

        // the rig's smoothed position, when measured
        let rig_x: Option<Vec<f64>> = self.rig.as_ref().and_then(|(r, _)| {
            data.column(&format!("{r}.x"))
                .map(|x| savitzky_golay(x, window_half_width(time, smooth)))
        });
        let velocity_of = |xs: &[f64]| -> Vec<f64> {
            (0..m)
                .map(|j| (xs[end[j]] - xs[start_of(j)]) / h[j])
                .collect()
        };
        let law_input = |var: &str| -> Result<Vec<f64>, String> {
            let port = format!("{f}.{var}");
            if let Some(col) = data.column(&port) {
                return Ok((0..m).map(|j| col[start_of(j)]).collect());
            }
            match port_source(var) {
                Some(src) => {
                    let (rig, _) = self
                        .rig
                        .as_ref()
                        .ok_or_else(|| format!("`{port}` comes from `{src}`, which is not a Rig1D diagnose can reconstruct"))?;
                    let xs = rig_x.as_ref().ok_or_else(|| {
                        format!(
                            "`{port}` comes from `{src}`: measure `{rig}.x` (or give `{port}` as a column)"
                        )
                    })?;
                    if src == format!("{rig}.v") || src == format!("{rig}.v_body") {
                        Ok(velocity_of(xs))
                    } else if src == format!("{rig}.x") || src == format!("{rig}.x_rel") {
                        Ok((0..m)
                            .map(|j| 0.5 * (xs[start_of(j)] + xs[end[j]]))
                            .collect())
                    } else {
                        Err(format!("`{port}` comes from `{src}`, which diagnose cannot reconstruct from the data"))
                    }
                }
                None => {
                    let start = match &self
                        .friction_fmu
                        .variable(var)
                        .map_err(|e| e.to_string())?
                        .kind
                    {
                        VariableKind::Real { start, .. } => start.unwrap_or(0.0),
                        _ => 0.0,
                    };
                    Ok(vec![start; m])
                }
            }
        };
        let v = law_input("v")?;
        let x = law_input("x")?;
        let position_column = data.column(&format!("{f}.x")).or_else(|| {
            self.rig
                .as_ref()
                .and_then(|(r, _)| data.column(&format!("{r}.x")))
        });
        let position_resolution = position_column.map(quality::resolution);
        let position_step = position_column.map(quality::step);
        let fn_ = law_input("Fn")?;
        let normal_force_measured = data.column(&format!("{f}.Fn")).is_some()
            && fn_.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
                > fn_.iter().cloned().fold(f64::INFINITY, f64::min);

        let (force, source, trusted) = if let Some(col) = data.column(&format!("{f}.F")) {
            (
                (0..m).map(|j| col[end[j]]).collect(),
                format!("measured `{f}.F`"),
                (0..m)
                    .map(|j| !data.quality.excluded[end[j]] && !data.quality.after_gap[end[j]])
                    .collect(),
            )
        } else {
            let (force, source) =
                self.inverse_dynamics(data, rig_x.as_deref(), &t, &h, &end, &v)?;
            // one more sample for the central difference of the velocities
            let edge = window_half_width(time, smooth) + 1;
            let stuck = STICK_SPEED_FRACTION * rms(&v);
            let near_bad = near_flagged(&data.quality, edge);
            let trusted = (0..m)
                .map(|j| {
                    start_of(j) >= edge
                        && end[j] + edge < n
                        && v[j].abs() >= stuck
                        && !near_bad[end[j]]
                        && !near_bad[start_of(j)]
                })
                .collect();
            (force, source, trusted)
        };
        Ok(FrictionData {
            t,
            h,
            end,
            v,
            x,
            fn_,
            f: force,
            source,
            position_resolution,
            position_step,
            normal_force_measured,
            trusted,
            record_starts: vec![0],
        })
    }

    /// F = k·(x_a − x) − c·ẋ + F_ext + F_d(t) + G·u_ctrl − m·ẍ on each interval.
    #[allow(clippy::too_many_arguments)]
    fn inverse_dynamics(
        &self,
        data: &Measured,
        xs: Option<&[f64]>,
        t: &[f64],
        h: &[f64],
        end: &[usize],
        v: &[f64],
    ) -> Result<(Vec<f64>, String), String> {
        let f = &self.friction_name;
        let Some((rig, p)) = &self.rig else {
            return Err(format!(
                "cannot estimate the friction force from the data: measure `{f}.F`, or connect `{f}.F` to a Rig1D whose position is measured"
            ));
        };
        let xs = xs.ok_or_else(|| {
            format!("cannot estimate the friction force: measure `{rig}.x` (for the inverse dynamics of `{rig}`) or `{f}.F`")
        })?;
        if p["v_surface"] != 0.0 || p["dither_amp"] != 0.0 {
            return Err(format!(
                "cannot estimate the friction force: `{rig}` has a moving surface (v_surface = {}, dither_amp = {}), which diagnose's inverse dynamics does not model",
                p["v_surface"], p["dither_amp"]
            ));
        }
        let control = p["control"] != 0.0;
        let u = if control {
            Some(data.column(&format!("{rig}.u_ctrl")).ok_or_else(|| {
                format!("cannot estimate the friction force: `{rig}` runs its controller (control = {}), so its effort `{rig}.u_ctrl` must be measured", p["control"])
            })?)
        } else {
            None
        };
        let f_ext = data.column(&format!("{rig}.F_ext"));
        let x_act_in = data.column(&format!("{rig}.x_act_in"));
        if p["k"] != 0.0 && p["actuator"] != 0.0 && x_act_in.is_none() {
            return Err(format!(
                "cannot estimate the friction force: `{rig}` has a spring (k = {}) to an actuator point from its input, so `{rig}.x_act_in` must be a column",
                p["k"]
            ));
        }
        let m = t.len();
        let mid = |col: &[f64], j: usize| 0.5 * (col[end[j] - 1] + col[end[j]]);
        let mut force = Vec::with_capacity(m);
        for j in 0..m {
            let tm = t[j] + 0.5 * h[j];
            // acceleration: central difference of the interval velocities
            let (jl, jr) = (j.saturating_sub(1), (j + 1).min(m - 1));
            let a = if jr > jl {
                (v[jr] - v[jl]) / (0.5 * (h[jl] + h[jr]) * (jr - jl) as f64)
            } else {
                0.0
            };
            let x = 0.5 * (xs[end[j] - 1] + xs[end[j]]);
            let x_a = if p["actuator"] != 0.0 {
                x_act_in.map_or(0.0, |c| mid(c, j))
            } else {
                p["x_a0"]
                    + p["v_a"] * tm
                    + p["act_amp"] * (std::f64::consts::TAU * p["act_freq"] * tm).sin()
            };
            let drive = if tm >= p["t_step"] { p["F_step"] } else { 0.0 }
                + p["drive_amp"] * (std::f64::consts::TAU * p["drive_freq"] * tm).sin();
            let ext = f_ext.map_or(p["F_ext"], |c| mid(c, j));
            let ctrl = u.map_or(0.0, |c| p["ctrl_gain"] * mid(c, j));
            force.push(p["k"] * (x_a - x) - p["c"] * v[j] + ext + drive + ctrl - p["m"] * a);
        }
        let mut how = format!(
            "inverse dynamics of `{rig}` (m = {} kg) from the measured `{rig}.x`",
            p["m"]
        );
        if control {
            how.push_str(&format!(
                " and effort `{rig}.u_ctrl` (gain {} N/V)",
                p["ctrl_gain"]
            ));
        }
        Ok((force, how))
    }

    /// The ranges that set the neutral starts of the candidates.
    pub fn context(&self, d: &FrictionData, position_knots: usize) -> Context {
        let speed_scale = (d.v.iter().map(|v| v * v).sum::<f64>() / d.v.len() as f64)
            .sqrt()
            .max(1e-9);
        let x_min = d.x.iter().cloned().fold(f64::INFINITY, f64::min);
        let x_max = d.x.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let mean_fn = d.fn_.iter().sum::<f64>() / d.fn_.len() as f64;
        Context {
            speed_scale,
            x_min,
            x_max,
            travel: (x_max - x_min).max(1e-9),
            mean_normal_force: if mean_fn > 0.0 { mean_fn } else { 1.0 },
            position_knots,
            position_resolution: d
                .position_resolution
                .filter(|r| *r > 0.0)
                .unwrap_or(super::model::STIFF_PRESLIDING_DISTANCE),
            position_step: d
                .position_step
                .filter(|r| *r > 0.0)
                .unwrap_or(super::model::STIFF_PRESLIDING_DISTANCE),
        }
    }
}

/// Rows within `edge` samples of a flagged row (spike, dropout,
/// saturation) or of a gap: the smoothing window and the acceleration's
/// difference reach them.
fn near_flagged(q: &Quality, edge: usize) -> Vec<bool> {
    let n = q.excluded.len();
    let mut near = vec![false; n];
    for k in 0..n {
        if q.excluded[k] || q.after_gap[k] {
            let lo = k.saturating_sub(edge + 1);
            let hi = (k + edge + 1).min(n - 1);
            near[lo..=hi].iter_mut().for_each(|x| *x = true);
        }
    }
    near
}

/// Below this fraction of the RMS speed, an interval of inverse-dynamics
/// data counts as sticking (see [`FrictionData::trusted`]).
pub const STICK_SPEED_FRACTION: f64 = 0.01;

fn rms(x: &[f64]) -> f64 {
    (x.iter().map(|v| v * v).sum::<f64>() / x.len().max(1) as f64).sqrt()
}

/// Half-width (samples) of a smoothing window of `seconds` at the file's
/// median sample spacing.
fn window_half_width(time: &[f64], seconds: f64) -> usize {
    if seconds <= 0.0 {
        return 0;
    }
    ((0.5 * seconds / quality::median_spacing(time)).round() as usize).min(time.len() / 4)
}

/// Savitzky–Golay smoothing (local quadratic, window 2·w + 1), with the
/// window shrunk symmetrically near the ends:
/// `c_j = (3·(3w² + 3w − 1) − 15·j²) / ((2w + 1)(4w² + 4w − 3))`.
pub fn savitzky_golay(y: &[f64], w: usize) -> Vec<f64> {
    let n = y.len();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let w = w.min(i).min(n - 1 - i);
        if w == 0 {
            out.push(y[i]);
            continue;
        }
        let wf = w as f64;
        let norm = (2.0 * wf + 1.0) * (4.0 * wf * wf + 4.0 * wf - 3.0);
        let mut s = 0.0;
        for j in -(w as i64)..=(w as i64) {
            let c = (3.0 * (3.0 * wf * wf + 3.0 * wf - 1.0) - 15.0 * (j * j) as f64) / norm;
            s += c * y[(i as i64 + j) as usize];
        }
        out.push(s);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::savitzky_golay;

    #[test]
    fn savitzky_golay_keeps_quadratics_and_averages_noise() {
        let y: Vec<f64> = (0..50)
            .map(|i| 0.5 * (i as f64).powi(2) - 3.0 * i as f64 + 1.0)
            .collect();
        let s = savitzky_golay(&y, 5);
        for (a, b) in y.iter().zip(&s) {
            assert!((a - b).abs() < 1e-9 * a.abs().max(1.0), "{a} {b}");
        }
        // alternating noise of ±1 is reduced well below 1 inside
        let z: Vec<f64> = (0..50)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let s = savitzky_golay(&z, 5);
        assert!(s[10..40].iter().all(|x| x.abs() < 0.3), "{s:?}");
    }
}
