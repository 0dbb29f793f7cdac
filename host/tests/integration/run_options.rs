//! The options of a run (`fricsim run`, [`fricsim::run`]) and third-party
//! semantics, on Stair (tests/c/stair, like the Modelica Reference FMU):
//! an FMU that ends the simulation (`fmi2Discard` with `fmi2Terminated` =
//! true at t = 9) ends the run normally with its last row; Integer and
//! Boolean outputs are recorded exactly; start values (`--set`,
//! `--start-values`) are read by the variable's type, checked and applied
//! in order; `--output-interval` records every k-th row of the full run,
//! bit for bit, and the last; every run ends its instances with
//! `fmi2Terminate` before `fmi2FreeInstance`, and an instance that refuses
//! it is named in a warning while the rows stand.

use crate::common;
use crate::stair;

use fricsim::master::{RowSink, Rows};
use fricsim::run::{run, PreparedRun, RunOptions, StartValue};
use fricsim::ssp::SystemFile;
use std::path::{Path, PathBuf};
use std::process::Command;
use tempfile::TempDir;

/// Every row handed on.
#[derive(Default)]
struct Collect {
    time: Vec<f64>,
    rows: Vec<Vec<f64>>,
}

impl RowSink for Collect {
    fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String> {
        self.time.extend_from_slice(times);
        self.rows
            .extend(rows.iter().take(times.len()).map(<[f64]>::to_vec));
        Ok(())
    }
}

/// Stair.fmu and stair.ssd (steps of `step`) in a temporary folder.
fn stair_system(step: f64) -> (TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    stair::build_fmu(dir.path());
    let ssd = stair::system_file(dir.path(), step);
    (dir, ssd)
}

fn column(columns: &[String], name: &str) -> usize {
    columns
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name} in {columns:?}"))
}

fn fricsim(args: &[&str]) -> (Option<i32>, String, String) {
    fricsim_with(args, &[])
}

/// [`fricsim`] with environment variables set (Stair reads STAIR_TRACE and
/// STAIR_TERMINATE_FAILS).
fn fricsim_with(args: &[&str], env: &[(&str, &Path)]) -> (Option<i32>, String, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .args(args)
        .envs(env.iter().copied())
        .output()
        .unwrap();
    (
        output.status.code(),
        String::from_utf8(output.stdout).unwrap(),
        String::from_utf8(output.stderr).unwrap(),
    )
}

#[test]
fn an_fmu_that_ends_the_simulation_ends_the_run_normally_with_its_last_row() {
    let (_dir, ssd) = stair_system(0.5);
    let file = SystemFile::open(&ssd).unwrap();
    let mut rows = Collect::default();
    let outcome = run(&file, &RunOptions::default(), &mut rows).unwrap();
    assert_eq!(outcome.error, None);
    let ended = outcome.ended.expect("Stair ends the simulation");
    assert_eq!(ended.to_string(), "stair ended the simulation at t = 9");
    // t = 0, 0.5, …, 9: the row of the step that ended it is kept
    let expected_times: Vec<f64> = (0..=18).map(|j| j as f64 * 0.5).collect();
    assert_eq!(rows.time, expected_times);
    assert_eq!(outcome.rows, 19);
    let (counter, even, height) = (
        column(&outcome.columns, "stair.counter"),
        column(&outcome.columns, "stair.even"),
        column(&outcome.columns, "stair.height"),
    );
    for (t, row) in rows.time.iter().zip(&rows.rows) {
        let stair = 1.0 + t.floor();
        assert_eq!(row[counter], stair, "t = {t}");
        assert_eq!(row[even], f64::from(stair % 2.0 == 0.0), "t = {t}");
        assert_eq!(row[height], stair, "t = {t}");
    }
    assert_eq!(rows.rows.last().unwrap()[counter], 10.0);
}

#[test]
fn fricsim_run_writes_integer_and_boolean_columns_exactly_and_exits_0() {
    let (dir, ssd) = stair_system(1.0);
    let out = dir.path().join("stair.csv");
    let (code, stdout, stderr) =
        fricsim(&["run", ssd.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    assert!(
        stdout.contains("9 of 10 macro steps")
            && stdout.contains("stair ended the simulation at t = 9"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(&out).unwrap();
    assert!(!csv.contains("INCOMPLETE"), "{csv}");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "time,stair.height,stair.counter,stair.even");
    assert_eq!(lines[1], "0.0,1.0,1,0");
    assert_eq!(lines[2], "1.0,2.0,2,1");
    assert_eq!(*lines.last().unwrap(), "9.0,10.0,10,1");
    assert_eq!(lines.len(), 11);

    // isolated (--isolate): the same file, the same end
    let isolated = dir.path().join("stair_isolated.csv");
    let (code, stdout, stderr) = fricsim(&[
        "run",
        ssd.to_str().unwrap(),
        "--out",
        isolated.to_str().unwrap(),
        "--isolate",
    ]);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    assert!(
        stdout.contains("9 of 10 macro steps")
            && stdout.contains("stair ended the simulation at t = 9"),
        "{stdout}"
    );
    assert_eq!(std::fs::read_to_string(&isolated).unwrap(), csv);
}

#[test]
fn a_discard_without_terminated_stays_a_failure() {
    let (dir, ssd) = stair_system(1.0);
    let out = dir.path().join("stair.csv");
    let (code, stdout, stderr) = fricsim(&[
        "run",
        ssd.to_str().unwrap(),
        "--set",
        "stair.terminates=false",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(1), "{stdout}{stderr}");
    for part in [
        "run INCOMPLETE",
        "fmi2Discard",
        "fmi2Terminated = false",
        "at t = 8",
    ] {
        assert!(stderr.contains(part), "{part}: {stderr}");
    }
    let csv = std::fs::read_to_string(&out).unwrap();
    assert!(csv.contains("# INCOMPLETE"), "{csv}");
    assert!(csv.contains("\n8.0,9.0,9,0\n"), "{csv}");
}

/// The lines Stair wrote to `trace` (STAIR_TRACE), the file then removed.
fn take_trace(trace: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(trace).unwrap_or_default();
    let _ = std::fs::remove_file(trace);
    text.lines().map(str::to_string).collect()
}

#[test]
fn every_run_tells_the_stop_time_and_ends_its_instances_with_fmi2terminate() {
    // As FMPy's simulate_fmu does: fmi2SetupExperiment with the stop time
    // (the last communication point), and after the last step
    // fmi2Terminate, then fmi2FreeInstance (FMI 2.0 §4.2.4). Stair traces
    // the three with its phase: 1 = instantiated, 8 = stepFailed (its
    // discarded last step), 16 = terminated.
    let (dir, ssd) = stair_system(1.0);
    let trace = dir.path().join("trace.txt");
    let out = dir.path().join("stair.csv");
    let env = [("STAIR_TRACE", trace.as_path())];
    let ended = vec![
        "fmi2SetupExperiment phase=1 t=0 stop=10".to_string(),
        "fmi2Terminate phase=8 t=9".to_string(),
        "fmi2FreeInstance phase=16 t=9".to_string(),
    ];
    // `fricsim ARGS` exits with `code`; what Stair traced
    let traced = |args: &[&str], code: i32| {
        let (got, stdout, stderr) = fricsim_with(args, &env);
        assert_eq!(got, Some(code), "{args:?}: {stdout}{stderr}");
        take_trace(&trace)
    };
    let (ssd, out) = (ssd.to_str().unwrap(), out.to_str().unwrap());
    assert_eq!(traced(&["run", ssd, "--out", out], 0), ended);
    assert_eq!(traced(&["run", ssd, "--out", out, "--isolate"], 0), ended);
    // fricsim sweep: each point's instances
    let table = dir.path().join("sweep.csv");
    let sweep = ["sweep", ssd, "--param", "stair.step_height=1,2", "--out"];
    let mut lines = traced(&[&sweep[..], &[table.to_str().unwrap()]].concat(), 0);
    lines.sort();
    assert_eq!(
        lines,
        [
            "fmi2FreeInstance phase=16 t=9",
            "fmi2FreeInstance phase=16 t=9",
            "fmi2SetupExperiment phase=1 t=0 stop=10",
            "fmi2SetupExperiment phase=1 t=0 stop=10",
            "fmi2Terminate phase=8 t=9",
            "fmi2Terminate phase=8 t=9"
        ]
    );
    // a stop time that is not a whole number of steps: the last
    // communication point, which the masters reach (round(9.4 / 1) = 9
    // steps)
    let short = traced(&["run", ssd, "--stop", "9.4", "--out", out], 0);
    assert_eq!(short[0], "fmi2SetupExperiment phase=1 t=0 stop=9");
    // a run stopped by a discarded step (not an error: stepFailed, where
    // fmi2Terminate is allowed) ends its instance too
    let stopped = ["run", ssd, "--set", "stair.terminates=false", "--out", out];
    assert_eq!(traced(&stopped, 1), ended);
}

#[test]
fn an_instance_that_refuses_fmi2terminate_is_named_in_a_warning_and_the_rows_stand() {
    let (dir, ssd) = stair_system(1.0);
    let reason = dir.path().join("the final check failed");
    let out = dir.path().join("stair.csv");
    let (code, stdout, stderr) = fricsim_with(
        &["run", ssd.to_str().unwrap(), "--out", out.to_str().unwrap()],
        &[("STAIR_TERMINATE_FAILS", reason.as_path())],
    );
    assert_eq!(code, Some(0), "{stdout}{stderr}");
    for part in [
        "warning: the run's rows are complete, but the FMU did not end cleanly",
        "fmi2Terminate failed for instance \"stair\" with fmi2Error",
        "the final check failed",
    ] {
        assert!(stderr.contains(part), "{part}: {stderr}");
    }
    let csv = std::fs::read_to_string(&out).unwrap();
    assert!(!csv.contains("INCOMPLETE"), "{csv}");
    assert_eq!(csv.lines().count(), 11, "{csv}");
}

/// The time the top is reached with these `--set` and `--start-values`.
fn end_time(dir: &Path, ssd: &Path, extra: &[&str]) -> String {
    let out = dir.join("stair.csv");
    let mut args = vec!["run", ssd.to_str().unwrap(), "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let (code, stdout, stderr) = fricsim(&args);
    assert_eq!(code, Some(0), "{extra:?}: {stdout}{stderr}");
    let at = stdout
        .split("stair ended the simulation at t = ")
        .nth(1)
        .unwrap_or_else(|| panic!("{stdout}"));
    at.split_whitespace().next().unwrap().to_string()
}

#[test]
fn start_values_are_read_by_type_and_apply_in_order() {
    let (dir, ssd) = stair_system(1.0);
    let ssv = dir.path().join("start.ssv");
    std::fs::write(
        &ssv,
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ssv:ParameterSet version="1.0" name="start"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssv:Parameters>
    <ssv:Parameter name="stair.top"><ssv:Integer value="6"/></ssv:Parameter>
    <ssv:Parameter name="stair.label"><ssv:String value="from the file"/></ssv:Parameter>
  </ssv:Parameters>
</ssv:ParameterSet>
"#,
    )
    .unwrap();
    let d = dir.path();
    assert_eq!(end_time(d, &ssd, &[]), "9");
    // the counter (an output with initial="exact") starts at 5
    assert_eq!(end_time(d, &ssd, &["--set", "stair.counter=5"]), "5");
    assert_eq!(
        end_time(d, &ssd, &["--start-values", ssv.to_str().unwrap()]),
        "5"
    );
    // --set after --start-values, the last --set winning
    let both = [
        "--start-values",
        ssv.to_str().unwrap(),
        "--set",
        "stair.top=3",
        "--set",
        "stair.top=8",
        "--set",
        "stair.terminates=1",
        "--set",
        "stair.label=any text",
    ];
    assert_eq!(end_time(d, &ssd, &both), "7");
}

#[test]
fn a_start_value_that_cannot_be_set_is_refused_naming_the_variable_and_the_value() {
    let (_dir, ssd) = stair_system(1.0);
    let file = SystemFile::open(&ssd).unwrap();
    for (port, value, expected) in [
        ("stair.floor", "1", "`stair` has no variable `floor`"),
        ("lift.top", "1", "no component `lift`"),
        (
            "stair.top",
            "ten",
            "cannot set `stair.top` to \"ten\": not an Integer value",
        ),
        (
            "stair.top",
            "2.5",
            "cannot set `stair.top` to \"2.5\": not an Integer value",
        ),
        (
            "stair.top",
            "1",
            "cannot set `stair.top` to \"1\": below the declared min = 2",
        ),
        ("stair.step_height", "10.5", "above the declared max = 10"),
        ("stair.step_height", "nan", "not a finite number"),
        (
            "stair.terminates",
            "yes",
            "not a Boolean value (true, false, 1 or 0)",
        ),
        (
            "stair.height",
            "3",
            "causality \"output\", variability \"discrete\" and initial \"calculated\"",
        ),
        ("stair.end_time", "3", "causality \"calculatedParameter\""),
    ] {
        let options = RunOptions {
            start_values: vec![(port.to_string(), StartValue::Text(value.to_string()))],
            ..RunOptions::default()
        };
        let error = PreparedRun::new(&file, &options)
            .err()
            .unwrap_or_else(|| panic!("{port}={value} accepted"));
        assert!(error.contains(expected), "{port}={value}: {error}");
        assert!(error.contains(port), "{port}={value}: {error}");
    }
    // typed values from a library caller: an Integer value for a Real, a
    // whole Real for an Integer; a Boolean for an Integer is refused
    let typed = |port: &str, value: StartValue| {
        PreparedRun::new(
            &file,
            &RunOptions {
                start_values: vec![(port.to_string(), value)],
                ..RunOptions::default()
            },
        )
        .err()
    };
    assert_eq!(typed("stair.step_height", StartValue::Integer(2)), None);
    assert_eq!(typed("stair.top", StartValue::Real(4.0)), None);
    let error = typed("stair.top", StartValue::Boolean(true)).unwrap();
    assert!(error.contains("not an Integer value"), "{error}");
}

/// The rows of `file` run with `output_interval`.
fn rows_of(file: &SystemFile, stop: f64, output_interval: Option<f64>) -> Collect {
    let mut rows = Collect::default();
    let options = RunOptions {
        stop: Some(stop),
        output_interval,
        ..RunOptions::default()
    };
    let outcome = run(file, &options, &mut rows).unwrap();
    assert_eq!(outcome.error, None);
    assert_eq!(outcome.rows, rows.time.len());
    assert_eq!(outcome.stats.rows, rows.time.len());
    rows
}

/// Every `k`-th row of `full` and its last, bit for bit.
fn assert_every_kth(full: &Collect, coarse: &Collect, k: usize) {
    let mut picked: Vec<usize> = (0..full.time.len()).step_by(k).collect();
    if picked.last() != Some(&(full.time.len() - 1)) {
        picked.push(full.time.len() - 1);
    }
    assert_eq!(coarse.time.len(), picked.len());
    for (i, &j) in picked.iter().enumerate() {
        assert_eq!(coarse.time[i].to_bits(), full.time[j].to_bits(), "row {i}");
        let same = coarse.rows[i]
            .iter()
            .zip(&full.rows[j])
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "row {i} is not row {j} of the full run");
    }
}

#[test]
fn an_output_interval_records_every_kth_row_bit_for_bit_and_the_last() {
    // the stick-slip benchmark over 20 001 points: chunk boundaries
    // (every 4096 steps) that do not fall on the coarse grid, and a last
    // point that does not either (20 000 is not a multiple of 7)
    let ssp = common::repository().join("dist/stick_slip.ssp");
    let file = SystemFile::open(&ssp).unwrap();
    let full = rows_of(&file, 2.0, None);
    assert_eq!(full.time.len(), 20_001);
    let coarse = rows_of(&file, 2.0, Some(7e-4));
    assert_every_kth(&full, &coarse, 7);
    // points 0, 7, …, 19 999 and the last, 20 000
    assert_eq!(coarse.time.len(), 2857 + 1 + 1);
    let even = rows_of(&file, 2.0, Some(1e-2));
    assert_every_kth(&full, &even, 100);
    assert_eq!(even.time.len(), 201);

    // a run that an FMU ends: its last row is recorded too
    let (_dir, ssd) = stair_system(0.5);
    let stair = SystemFile::open(&ssd).unwrap();
    let full = rows_of(&stair, 10.0, None);
    let coarse = rows_of(&stair, 10.0, Some(2.0));
    assert_every_kth(&full, &coarse, 4);
    assert_eq!(coarse.time, [0.0, 2.0, 4.0, 6.0, 8.0, 9.0]);
}

#[test]
fn an_output_interval_that_is_not_a_multiple_of_the_step_is_refused_with_both() {
    let (dir, ssd) = stair_system(0.5);
    let out = dir.path().join("stair.csv");
    for (interval, expected) in [
        (
            "0.75",
            "--output-interval 0.75 s is not a whole multiple of the step 0.5 s",
        ),
        (
            "0.25",
            "--output-interval 0.25 s is not a whole multiple of the step 0.5 s",
        ),
        (
            "-1",
            "--output-interval must be a positive number of seconds, got -1",
        ),
    ] {
        let (code, stdout, stderr) = fricsim(&[
            "run",
            ssd.to_str().unwrap(),
            &format!("--output-interval={interval}"),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, Some(1), "{stdout}{stderr}");
        assert!(stderr.contains(expected), "{stderr}");
    }
    assert!(!out.exists());
}
