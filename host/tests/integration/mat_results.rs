//! MAT v4 result files (`--out NAME.mat`, `fricsim::matfile`): the same
//! run written as CSV and as MAT reads back the same numbers bit for bit;
//! a run that stops early keeps its rows and says why in both formats;
//! `fricsim compare` gives the same figures on either format; `fricsim
//! diagnose`'s reader (`InputTable`) reads the same table from both.

use crate::belt;
use crate::common;

use fricsim::compare::{compare, ResultFile};
use fricsim::inputs::InputTable;
use std::path::Path;
use std::process::Command;

/// `fricsim ARGS`: its exit status, stdout and stderr.
fn fricsim(args: &[&str]) -> (Option<i32>, String, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .current_dir(common::repository())
        .args(args)
        .output()
        .unwrap();
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// `fricsim run examples/stick_slip.ssd` for 2 s (unless `extra` says).
fn run_stick_slip(out: &Path, extra: &[&str]) {
    let stop = if extra.contains(&"--stop") {
        vec![]
    } else {
        vec!["--stop", "2"]
    };
    let mut args = vec!["run", "examples/stick_slip.ssd"];
    args.extend(stop);
    args.extend(["--quiet", "--out", out.to_str().unwrap()]);
    args.extend_from_slice(extra);
    let (code, stdout, stderr) = fricsim(&args);
    assert_eq!(code, Some(0), "{stdout}{stderr}");
}

fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|x| x.to_bits()).collect()
}

/// The two files hold the same columns, times and values, bit for bit.
fn assert_same_table(csv: &ResultFile, mat: &ResultFile) {
    assert_eq!(csv.columns, mat.columns);
    assert_eq!(bits(&csv.time), bits(&mat.time));
    for (k, name) in csv.columns.iter().enumerate() {
        assert_eq!(bits(&csv.values[k]), bits(&mat.values[k]), "{name}");
    }
}

#[test]
fn a_run_written_as_mat_reads_back_as_its_csv_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    for master in ["jacobi", "newton"] {
        let csv_path = dir.path().join(format!("{master}.csv"));
        let mat_path = dir.path().join(format!("{master}.mat"));
        run_stick_slip(&csv_path, &["--master", master]);
        run_stick_slip(&mat_path, &["--master", master]);
        let csv = ResultFile::read(&csv_path).unwrap();
        let mat = ResultFile::read(&mat_path).unwrap();
        assert_eq!(csv.time.len(), 20_001);
        assert_same_table(&csv, &mat);
        assert_eq!((&csv.incomplete, &mat.incomplete), (&None, &None));
        // the layout's size: the header matrices, then 8 bytes per number
        // of data_2 and nothing after it
        let size = std::fs::metadata(&mat_path).unwrap().len() as usize;
        let data = 8 * (1 + csv.columns.len()) * csv.time.len();
        let head = size - data;
        assert!((400..2000).contains(&head), "{head} bytes before data_2");
    }
}

#[test]
fn compare_gives_the_same_figures_on_mat_as_on_csv() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name);
    run_stick_slip(&path("jacobi.csv"), &[]);
    run_stick_slip(&path("jacobi.mat"), &[]);
    // a reference on another grid, so that compare interpolates
    for out in ["newton.csv", "newton.mat"] {
        run_stick_slip(&path(out), &["--master", "newton", "--step", "3e-4"]);
    }
    let read = |name: &str| ResultFile::read(&path(name)).unwrap();
    let by_csv = compare(&read("jacobi.csv"), &read("newton.csv"), &[]).unwrap();
    let by_mat = compare(&read("jacobi.mat"), &read("newton.mat"), &[]).unwrap();
    assert!(by_csv.interpolated);
    assert_eq!(by_csv, by_mat);
    let force = by_csv
        .signals
        .iter()
        .find(|s| s.name == "friction.F")
        .unwrap();
    assert!(force.rms > 0.0, "{by_csv}");
    // and the command prints the same table for either, or both mixed
    let table = |result: &str, reference: &str| {
        let (code, stdout, stderr) = fricsim(&[
            "compare",
            path(result).to_str().unwrap(),
            path(reference).to_str().unwrap(),
        ]);
        assert_eq!(code, Some(0), "{stderr}");
        stdout
            .lines()
            .skip_while(|l| !l.contains("rel. RMS"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let csv_table = table("jacobi.csv", "newton.csv");
    assert!(csv_table.contains("friction.F"), "{csv_table}");
    assert_eq!(csv_table, table("jacobi.mat", "newton.mat"));
    assert_eq!(csv_table, table("jacobi.mat", "newton.csv"));
}

#[test]
fn a_run_that_stops_early_keeps_its_rows_and_says_why_in_the_mat_file() {
    let dir = tempfile::tempdir().unwrap();
    let belt = belt::build_fmu(dir.path());
    let lugre = common::lugre_fmu();
    let mut tables = Vec::new();
    for out in ["fault.csv", "fault.mat"] {
        let out = dir.path().join(out);
        let (code, _, stderr) = fricsim(&[
            "cosim",
            "--fmu",
            &format!("rig={}", belt.display()),
            "--fmu",
            &format!("friction={}", lugre.display()),
            "--connect",
            "rig.v->friction.v",
            "--connect",
            "friction.F->rig.F",
            "--set",
            &format!("rig.fault={}", belt::ERROR),
            "--set",
            "rig.fault_step=10",
            "--set",
            "rig.v0=0",
            "--step",
            "0.0009765625",
            "--stop",
            "0.5",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, Some(1), "{stderr}");
        assert!(stderr.contains("run INCOMPLETE"), "{stderr}");
        tables.push(ResultFile::read(&out).unwrap());
    }
    let (csv, mat) = (&tables[0], &tables[1]);
    assert_eq!(csv.time.len(), 10);
    assert_same_table(csv, mat);
    let note = mat.incomplete.as_deref().expect("the MAT file says why");
    assert!(
        note.starts_with("the run stopped early: at t = 0.0087890625: ")
            && note.contains("fault injected at step 10"),
        "{note}"
    );
    assert_eq!(csv.incomplete, mat.incomplete);
    let (code, stdout, _) = fricsim(&[
        "compare",
        mat.path.to_str().unwrap(),
        csv.path.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0));
    assert!(
        stdout.contains("INCOMPLETE run: the run stopped early"),
        "{stdout}"
    );
}

#[test]
fn diagnose_and_run_input_read_the_same_table_from_mat_as_from_csv() {
    let dir = tempfile::tempdir().unwrap();
    let (csv_path, mat_path) = (dir.path().join("r.csv"), dir.path().join("r.mat"));
    run_stick_slip(&csv_path, &["--stop", "0.5"]);
    run_stick_slip(&mat_path, &["--stop", "0.5"]);
    let csv = InputTable::read(&csv_path).unwrap();
    let mat = InputTable::read(&mat_path).unwrap();
    assert_eq!(bits(&csv.time), bits(&mat.time));
    assert_eq!(csv.columns.len(), mat.columns.len());
    for ((a, x), (b, y)) in csv.columns.iter().zip(&mat.columns) {
        assert_eq!(a, b);
        assert_eq!(bits(x), bits(y), "{a}");
    }
    // the rows' positions for messages: lines from 2, as the CSV's
    assert_eq!(csv.lines, mat.lines);
    // a file that is not MAT is refused naming it
    let fake = dir.path().join("fake.mat");
    std::fs::copy(&csv_path, &fake).unwrap();
    let e = InputTable::read(&fake).unwrap_err();
    assert!(
        e.contains(fake.to_str().unwrap()) && e.contains("not a MAT v4 file"),
        "{e}"
    );
}
