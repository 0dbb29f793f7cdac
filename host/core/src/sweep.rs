//! Parameter sweeps (`fricsim sweep`): many independent runs of one system
//! file, one per point of a parameter grid (and per random seed), spread
//! over the cores with rayon.
//!
//! Each run instantiates its own [`crate::system::System`] from the FMUs
//! opened once ([`SystemFile::instantiate`], the grid point's values set
//! after the file's own), co-simulates it exactly as `fricsim run` does
//! ([`simulate_with`]) and keeps a summary: the final value and the RMS
//! over the communication points of every recorded column, and the wall
//! time. Runs share nothing but the parsed file, so they scale with the
//! cores; a run that fails is a row that says so, not the end of the sweep.

use crate::csvfile::push_number;
use crate::master::{by_name, simulate_with, NoObserver};
use crate::output_file::{OutputError, OutputFile};
use crate::ssp::{CheckedSystem, SystemFile};
use crate::system::{Experiment, ParameterValue};
use rayon::prelude::*;
use std::io::Write as _;
use std::time::Instant;

/// One swept variable: `component.variable` and its values.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    pub port: String,
    pub values: Vec<f64>,
}

impl Axis {
    /// `component.variable=v1,v2,…` (the `--param` syntax).
    pub fn parse(text: &str) -> Result<Axis, String> {
        let (port, list) = text.split_once('=').ok_or_else(|| {
            format!("--param `{text}`: expected component.variable=value,value,…")
        })?;
        let port = port.trim();
        if !port.contains('.') {
            return Err(format!(
                "--param `{text}`: `{port}` is not of the form component.variable"
            ));
        }
        let values = list
            .split(',')
            .map(|v| {
                v.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| format!("--param `{text}`: `{v}` is not a finite number"))
            })
            .collect::<Result<Vec<f64>, String>>()?;
        Ok(Axis {
            port: port.to_string(),
            values,
        })
    }
}

/// Every combination of the axes' values (the first axis varies slowest),
/// as `(component.variable, value)` lists; one empty point without axes.
pub fn grid(axes: &[Axis]) -> Vec<Vec<(String, f64)>> {
    let mut points = vec![Vec::new()];
    for axis in axes {
        points = points
            .into_iter()
            .flat_map(|point| {
                axis.values.iter().map(move |&v| {
                    let mut p = point.clone();
                    p.push((axis.port.clone(), v));
                    p
                })
            })
            .collect();
    }
    points
}

/// Refuse, before anything runs, an axis whose `component.variable` the
/// system does not have, or that is not a parameter or an input.
pub fn check_axes(file: &SystemFile, axes: &[Axis]) -> Result<(), String> {
    use crate::fmu::model_description::Causality;
    let checked = file.check().map_err(|e| e.to_string())?;
    for axis in axes {
        let (component, variable) = axis.port.split_once('.').unwrap_or(("", &axis.port));
        let Some((_, fmu)) = checked.fmus.iter().find(|(n, _)| n == component) else {
            let names: Vec<&str> = checked.fmus.iter().map(|(n, _)| n.as_str()).collect();
            return Err(format!(
                "`{}`: no component `{component}` (components: {})",
                axis.port,
                names.join(", ")
            ));
        };
        let var = fmu.variable(variable).map_err(|_| {
            format!(
                "`{}`: `{component}` has no variable `{variable}`{}",
                axis.port,
                fmu.description().array_hint(variable)
            )
        })?;
        if !matches!(var.causality, Causality::Parameter | Causality::Input) {
            return Err(format!(
                "`{}` is not a parameter or an input: it cannot be swept",
                axis.port
            ));
        }
    }
    Ok(())
}

/// The seed variables of a system file: every component's parameter
/// called `seed` (the Bristle FMU's realisation seed), as
/// `component.seed`.
pub fn seed_ports(file: &SystemFile) -> Result<Vec<String>, String> {
    let checked = file.check().map_err(|e| e.to_string())?;
    Ok(checked
        .fmus
        .iter()
        .filter(|(_, fmu)| fmu.variable("seed").is_ok())
        .map(|(name, _)| format!("{name}.seed"))
        .collect())
}

/// Rows a sweep's run keeps ([`crate::system::System::keep_last_rows`]),
/// and with them their times only ([`crate::master::Run::time`]): about
/// 100 kB for a dozen columns, where a 20 s run at 1e-4 s would hold
/// 19 MB of rows and 1.6 MB of times; each fold of the window's rows into
/// the RMS sums reads rows still in the cache.
const SWEEP_WINDOW: usize = 1024;

/// What a sweep runs: the grid points, the time grid and the master.
pub struct Plan {
    pub points: Vec<Vec<(String, f64)>>,
    pub start: f64,
    pub stop: f64,
    pub step: f64,
    pub master: String,
}

/// The summary of one run.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The grid point: `(component.variable, value)`.
    pub point: Vec<(String, f64)>,
    /// Recorded columns, and per column the final value and the RMS
    /// `√(Σ y_i² / n)` over the communication points reached.
    pub columns: Vec<String>,
    pub last: Vec<f64>,
    pub rms: Vec<f64>,
    /// Communication points reached (steps + 1).
    pub points: usize,
    /// Wall time of building and running the system, s.
    pub wall: f64,
    /// Why the run stopped early or could not start.
    pub error: Option<String>,
}

/// Build and co-simulate `file` at one grid point: new instances of the
/// FMUs of `checked` where they may be instantiated more than once per
/// process, else the file built from scratch (its FMUs unpacked and loaded
/// again, a separate copy of each binary).
pub fn run_point(
    file: &SystemFile,
    checked: &CheckedSystem,
    plan: &Plan,
    point: &[(String, f64)],
) -> Outcome {
    let clock = Instant::now();
    let overrides: Vec<(String, ParameterValue)> = point
        .iter()
        .map(|(k, v)| (k.clone(), ParameterValue::Number(*v)))
        .collect();
    let mut outcome = Outcome {
        point: point.to_vec(),
        columns: Vec::new(),
        last: Vec::new(),
        rms: Vec::new(),
        points: 0,
        wall: 0.0,
        error: None,
    };
    // told to each instance, as `fricsim run` tells it
    let experiment = Experiment::stepped(plan.start, plan.step, plan.stop);
    let run = by_name(&plan.master).and_then(|mut master| {
        let once_per_process = checked.fmus.iter().any(|(_, fmu)| {
            fmu.description()
                .co_simulation
                .can_be_instantiated_only_once_per_process
        });
        let mut system = if once_per_process {
            file.build_with(experiment, &overrides)
        } else {
            file.instantiate(checked, experiment, &overrides)
        }
        .map_err(|e| e.to_string())?;
        // a summary is all a sweep keeps: no run holds its whole table
        system.keep_last_rows(Some(SWEEP_WINDOW));
        simulate_with(
            &mut system,
            master.as_mut(),
            plan.start,
            plan.step,
            plan.stop,
            &mut NoObserver,
        )
        .map_err(|e| format!("initialization failed: {e}"))
    });
    match run {
        Ok(run) => {
            let points = run.rows.rows_pushed();
            let n = points.max(1) as f64;
            outcome.last = run.rows.last().map(<[f64]>::to_vec).unwrap_or_default();
            // each column summed in row order, the rows folded out of the
            // window included
            let squares = run.rows.square_sums();
            outcome.rms = squares.iter().map(|s| (s / n).sqrt()).collect();
            outcome.points = points;
            outcome.columns = run.columns;
            outcome.error = run.error;
            // the rows stand: a warning, as `fricsim run` gives
            for w in &run.warnings {
                let at: Vec<String> = point.iter().map(|(k, v)| format!("{k} = {v}")).collect();
                eprintln!("warning: at {}: {w}", at.join(", "));
            }
        }
        Err(e) => outcome.error = Some(e),
    }
    outcome.wall = clock.elapsed().as_secs_f64();
    outcome
}

/// Every point of `plan` on a pool of `threads` threads (rayon), in the
/// order of the points.
pub fn run_all(file: &SystemFile, plan: &Plan, threads: usize) -> Result<Vec<Outcome>, String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| format!("cannot start {threads} threads: {e}"))?;
    let checked = file.check().map_err(|e| e.to_string())?;
    Ok(pool.install(|| {
        plan.points
            .par_iter()
            .map(|point| run_point(file, &checked, plan, point))
            .collect()
    }))
}

/// The table: `run`, one column per swept variable, `status` (`ok` or the
/// error), `points`, `wall_s`, then `final:<column>` and `rms:<column>` for
/// every recorded column (those of the first run that has any); numbers
/// as a result file writes them ([`crate::csvfile`]). CSV alone: its
/// `status` column is text ([`crate::formats::ResultFormat::holds_text`]).
/// Written through `out` ([`OutputFile`]): put in place whole or not at
/// all.
pub fn write_table(outcomes: &[Outcome], mut out: OutputFile) -> Result<(), OutputError> {
    // a write error is kept by the OutputFile and reported by commit
    let _ = out
        .write_all(&table_text(outcomes))
        .and_then(|()| out.flush());
    out.commit()
}

/// The text of [`write_table`]'s table.
fn table_text(outcomes: &[Outcome]) -> Vec<u8> {
    let ports: Vec<&str> = outcomes
        .first()
        .map(|o| o.point.iter().map(|(k, _)| k.as_str()).collect())
        .unwrap_or_default();
    let columns: &[String] = outcomes
        .iter()
        .find(|o| !o.columns.is_empty())
        .map(|o| o.columns.as_slice())
        .unwrap_or(&[]);
    let mut header = vec!["run".to_string()];
    header.extend(ports.iter().map(|p| p.to_string()));
    header.extend(["status".into(), "points".into(), "wall_s".into()]);
    header.extend(columns.iter().map(|c| format!("final:{c}")));
    header.extend(columns.iter().map(|c| format!("rms:{c}")));
    let mut text = header
        .iter()
        .map(|h| crate::csvfile::header_field(h))
        .collect::<Vec<_>>()
        .join(",")
        .into_bytes();
    text.push(b'\n');
    let mut digits = zmij::Buffer::new();
    for (i, o) in outcomes.iter().enumerate() {
        text.extend_from_slice(itoa::Buffer::new().format(i + 1).as_bytes());
        for (_, v) in &o.point {
            text.push(b',');
            push_number(&mut text, &mut digits, *v);
        }
        let status = match &o.error {
            None => "ok".to_string(),
            // one CSV field: no commas, quotes or line breaks
            Some(e) => format!("failed: {}", e.replace([',', '"', '\n', '\r'], " ")),
        };
        text.extend_from_slice(format!(",{status},{},{:.6}", o.points, o.wall).as_bytes());
        let same = o.columns == columns;
        for values in [&o.last, &o.rms] {
            for k in 0..columns.len() {
                text.push(b',');
                if let Some(x) = values.get(k).filter(|_| same) {
                    push_number(&mut text, &mut digits, *x);
                }
            }
        }
        text.push(b'\n');
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_parse_and_the_grid_is_their_product() {
        let a = Axis::parse("friction.sigma0=1e4, 1e5,1e6").unwrap();
        assert_eq!(a.port, "friction.sigma0");
        assert_eq!(a.values, vec![1e4, 1e5, 1e6]);
        let b = Axis::parse("rig.k=2,4").unwrap();
        let g = grid(&[a, b]);
        assert_eq!(g.len(), 6);
        assert_eq!(
            g[1],
            vec![
                ("friction.sigma0".to_string(), 1e4),
                ("rig.k".to_string(), 4.0)
            ]
        );
        assert_eq!(grid(&[]), vec![Vec::new()]);
        assert!(Axis::parse("sigma0=1")
            .unwrap_err()
            .contains("component.variable"));
        assert!(Axis::parse("a.b=1,x").unwrap_err().contains("`x`"));
        assert!(Axis::parse("a.b").unwrap_err().contains("expected"));
    }
}
