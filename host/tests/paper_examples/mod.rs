//! Helpers of the papers' scenario tests (`appels_herder.rs`,
//! `sun2016.rs`, `thimmalapura2004.rs`): open a system file of `examples/` (its sources are
//! `../dist/*.fmu`), change parameters, run it through the host with a
//! master by name as `fricsim run` does, and solve the same file with the
//! monolithic reference of `fricsim reference`.
#![allow(dead_code)]

use fricsim::master::{by_name, simulate, step_count, Run};
use fricsim::ssp::{ParameterDef, SystemFile, Value};
use fricsim_reference::{ComponentSpec, ReferenceModel, SystemSpec, Table};
use std::path::PathBuf;

pub fn repository() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `examples/<name>`, parsed; the FMUs must have been built.
pub fn example(name: &str) -> SystemFile {
    let dist = repository().join("dist/Rig1D.fmu");
    assert!(
        dist.exists(),
        "{} is missing: run ./build-fmu.sh",
        dist.display()
    );
    SystemFile::open(repository().join("examples").join(name))
        .unwrap_or_else(|e| panic!("examples/{name}: {e}"))
}

/// Bind `component.variable = value` after the file's own bindings (the
/// last binding of a variable wins, as for SSP system bindings).
pub fn set(file: &mut SystemFile, port: &str, value: Value) {
    let (component, variable) = port.split_once('.').expect("component.variable");
    file.parameters.push(ParameterDef {
        component: component.to_string(),
        variable: variable.to_string(),
        value,
        unit: None,
        location: format!("test override of {port}"),
    });
}

pub fn set_real(file: &mut SystemFile, port: &str, value: f64) {
    set(file, port, Value::Real(value));
}

/// The value bound last to `component.variable` in the file.
pub fn bound(file: &SystemFile, port: &str) -> f64 {
    let (component, variable) = port.split_once('.').expect("component.variable");
    let p = file
        .parameters
        .iter()
        .rev()
        .find(|p| p.component == component && p.variable == variable)
        .unwrap_or_else(|| panic!("{port} is not bound in {}", file.ssd));
    match p.value {
        Value::Real(x) => x,
        Value::Integer(i) => f64::from(i),
        _ => panic!("{port} is not a number"),
    }
}

/// The macro step, master and stop time of the file's annotation.
pub fn settings(file: &SystemFile) -> (f64, String, f64) {
    (
        file.settings.step_size.expect("stepSize annotation"),
        file.settings
            .master
            .clone()
            .unwrap_or_else(|| "jacobi".into()),
        file.stop_time.expect("stopTime"),
    )
}

/// Run the file with master `master` at macro step `h` until `stop`; the
/// run must complete.
pub fn run_with(file: &SystemFile, master: &str, h: f64, stop: f64) -> Run {
    let mut system = file.build(0.0).unwrap_or_else(|e| panic!("{e}"));
    let mut master = by_name(master).unwrap();
    let run = simulate(&mut system, master.as_mut(), h, stop).unwrap();
    assert!(run.error.is_none(), "{}: {:?}", file.ssd, run.error);
    run
}

/// Run the file as `fricsim run` does: its step, master and stop time.
pub fn run(file: &SystemFile) -> Run {
    let (h, master, stop) = settings(file);
    run_with(file, &master, h, stop)
}

pub fn column(run: &Run, name: &str) -> Vec<f64> {
    let k = run
        .columns
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", run.columns));
    run.rows.iter().map(|r| r[k]).collect()
}

/// The monolithic reference of the file (as `fricsim reference`) at the
/// times `i·h` up to `stop`.
pub fn reference(file: &SystemFile, h: f64, stop: f64) -> Table {
    let checked = file.check().unwrap_or_else(|e| panic!("{e}"));
    let components = checked
        .fmus
        .iter()
        .map(|(name, fmu)| {
            let d = fmu.description();
            ComponentSpec {
                name: name.clone(),
                model_name: d.model_name.clone(),
                guid: Some(d.guid.clone()),
                parameters: file
                    .parameters
                    .iter()
                    .filter(|p| &p.component == name)
                    .map(|p| {
                        let v = match &p.value {
                            Value::Real(x) => fricsim_reference::Value::Real(*x),
                            Value::Integer(i) => fricsim_reference::Value::Integer(i64::from(*i)),
                            Value::Boolean(b) => fricsim_reference::Value::Boolean(*b),
                            Value::String(s) => fricsim_reference::Value::String(s.clone()),
                        };
                        (p.variable.clone(), v)
                    })
                    .collect(),
            }
        })
        .collect();
    let spec = SystemSpec {
        components,
        connections: checked
            .connections
            .iter()
            .map(|c| (c.from.clone(), c.to.clone()))
            .collect(),
    };
    let mut model = ReferenceModel::from_spec(&spec).unwrap_or_else(|e| panic!("{e}"));
    let times: Vec<f64> = (0..=step_count(0.0, h, stop))
        .map(|i| i as f64 * h)
        .collect();
    let (table, _) = model
        .solve(0.0, &times, fricsim_reference::RTOL)
        .unwrap_or_else(|e| panic!("{e}"));
    table
}

pub fn max_abs(xs: &[f64]) -> f64 {
    xs.iter().fold(0.0, |m, x| m.max(x.abs()))
}
