//! `fricsim diagnose SYSTEM DATA1 DATA2 …`: several records of one system
//! fitted together, each co-simulated from its own start with its own
//! inputs, and (without `--heldout`) each held out in turn. EMPS (Janot,
//! Gautier, Brunot 2019) has two records, a training run and a run with
//! force pulses; the paper fits on the first and cross-tests on the second.

use super::common::repository;
use fricsim::diagnose::problem::{Measured, Setup};
use fricsim::diagnose::sim::{co_simulate_with, system_parameters};
use fricsim::ssp::SystemFile;
use std::path::Path;
use std::process::Command;

fn emps(record: &str) -> std::path::PathBuf {
    repository().join("examples/data").join(record)
}

/// Two records joined co-simulate exactly as each alone: the second
/// starts from its own initial state at its own time with its own inputs
/// (not from where the first ended), and its samples are numbered after
/// the first's. Also: the joined time line increases, and each record
/// comes back out of the join as it was read.
#[test]
fn joined_records_co_simulate_each_from_its_own_start() {
    let file = SystemFile::open(repository().join("examples/emps_nominal.ssd")).unwrap();
    let mut system = file.build(0.0).unwrap();
    let a = Measured::read(&emps("emps_train.csv"), &system).unwrap();
    let b = Measured::read(&emps("emps_test_pulses.csv"), &system).unwrap();
    let joined = Measured::join(vec![a.clone(), b.clone()]).unwrap();
    assert_eq!(joined.records.len(), 2);
    assert_eq!(joined.time.len(), a.time.len() + b.time.len());
    assert!(
        joined.time.windows(2).all(|w| w[1] > w[0]),
        "the joined times must increase"
    );
    for (i, alone) in [&a, &b].into_iter().enumerate() {
        let back = joined.record(i);
        assert_eq!(back.time, alone.time, "record {i}: times");
        assert_eq!(back.outputs, alone.outputs, "record {i}: outputs");
        assert_eq!(back.inputs, alone.inputs, "record {i}: inputs");
    }
    let setup = Setup::new(&file, &mut system, 1e-3, "jacobi").unwrap();
    let params = system_parameters(&file, &setup, &setup.nominal);
    let run = |system: &mut _, data: &Measured, records: Option<&[usize]>| {
        co_simulate_with(system, &params, data, records, "jacobi", 1e-3, false).unwrap()
    };
    let (ra, rb) = (run(&mut system, &a, None), run(&mut system, &b, None));
    let both = run(&mut system, &joined, None);
    let offset = a.time.len();
    let expected: Vec<usize> = ra
        .samples
        .iter()
        .copied()
        .chain(rb.samples.iter().map(|k| k + offset))
        .collect();
    assert_eq!(both.samples, expected);
    for c in 0..both.channels.len() {
        let alone: Vec<f64> = ra.residuals[c]
            .iter()
            .chain(&rb.residuals[c])
            .copied()
            .collect();
        assert_eq!(both.residuals[c], alone, "channel {}", both.channels[c]);
    }
    // the second record alone, numbered as rows of the joined data
    let second = run(&mut system, &joined, Some(&[1]));
    assert_eq!(second.samples, expected[ra.samples.len()..]);
    assert_eq!(second.residuals[0], rb.residuals[0]);
}

/// Records diagnosed together must measure the same channels; a file
/// with other columns is refused with both files' columns named.
#[test]
fn records_with_other_columns_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let other = dir.path().join("other.csv");
    let mut text = String::from("time,rig.x_ref,rig.x\n");
    for k in 0..200 {
        text.push_str(&format!("{},0,0\n", k as f64 * 1e-3));
    }
    std::fs::write(&other, text).unwrap();
    let out = dir.path().join("out");
    let result = Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("diagnose")
        .arg(repository().join("examples/emps_nominal.ssd"))
        .arg(emps("emps_train.csv"))
        .arg(&other)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(!result.status.success());
    assert!(
        stderr.contains("other.csv")
            && stderr.contains("emps_train.csv")
            && stderr.contains("rig.u_ctrl")
            && stderr.contains("same columns"),
        "{stderr}"
    );
    assert!(!out.exists());
    // holding out each record in turn needs two of them
    let result = Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("diagnose")
        .arg(repository().join("examples/emps_nominal.ssd"))
        .arg(emps("emps_train.csv"))
        .args(["--cross-validate", "records", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(!result.status.success());
    assert!(stderr.contains("needs at least two records"), "{stderr}");
    assert!(!out.exists());
}

/// EMPS with both records, each held out in turn (the model fitted on
/// the training record scores the pulses record and the other way
/// round), and the reported model fitted on both, as a user runs it:
/// `fricsim diagnose examples/emps_nominal.ssd emps_train.csv
/// emps_test_pulses.csv`. It names the direction dependence of the
/// viscous friction, at the published asymmetric model's coefficients
/// within 5 % (Fv+ = 166.7, Fv− = 240.4 N·s/m), resolved; writes one
/// input file and one rerun command per record; and the reported model
/// rerun by `fricsim run` on each record follows the actuator force at
/// least as closely as the published symmetric model with its offset.
#[test]
fn emps_both_records_each_held_out_in_turn() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("emps");
    let result = Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("diagnose")
        .arg(repository().join("examples/emps_nominal.ssd"))
        .arg(emps("emps_train.csv"))
        .arg(emps("emps_test_pulses.csv"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["folds"], 2, "{}", json["heldout"]);
    let heldout = json["heldout"].as_str().unwrap();
    assert!(heldout.contains("each of the 2 records"), "{heldout}");
    // every sample of both records is scored, by the model not fitted on it
    assert!(
        json["heldout_samples"].as_u64().unwrap() > 49_000,
        "{}",
        json["heldout_samples"]
    );
    let effect = &json["effects"][0];
    assert_eq!(effect["name"], "direction_dependent_viscous", "{effect}");
    assert_eq!(effect["change"]["resolved"], true, "{effect}");
    let value = |name: &str| {
        json["changes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["name"] == name)
            .unwrap_or_else(|| panic!("no change of {name}"))["after"]
            .as_f64()
            .unwrap()
    };
    for (name, published) in [("sigma2", 166.7061), ("sigma2_neg", 240.4236)] {
        let fitted = value(name);
        assert!(
            (fitted / published - 1.0).abs() < 0.05,
            "{name}: fitted {fitted}, published {published}"
        );
    }
    assert!(
        json["final_rms"].as_f64().unwrap() < json["baseline_rms"].as_f64().unwrap(),
        "{json}"
    );
    // one input file and one rerun command per record, over its own span
    let rerun: Vec<&str> = json["rerun"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(rerun.len(), 2, "{rerun:?}");
    let symmetric = repository().join("examples/emps_symmetric_2019.ssd");
    for (i, record) in ["emps_train.csv", "emps_test_pulses.csv"]
        .into_iter()
        .enumerate()
    {
        let inputs = out.join(format!("inputs-{}.csv", i + 1));
        assert!(rerun[i].contains(inputs.to_str().unwrap()), "{}", rerun[i]);
        let measured = super::emps::read_table(&emps(record));
        let written = super::emps::read_table(&inputs);
        assert_eq!(written.time, measured.time, "{record}: its own times");
        let words: Vec<&str> = rerun[i].split_whitespace().collect();
        super::emps::fricsim_run(&words[2..]);
        assert!(out.join(format!("rerun-{}.csv", i + 1)).exists());
        let error = |system: &Path| {
            super::emps::closed_loop_force_error(system, record, "1e-3", &[], dir.path())
        };
        let (diagnosed, published) = (error(&out.join("refitted.ssp")), error(&symmetric));
        assert!(
            diagnosed <= published,
            "{record}: diagnosed {diagnosed:.3} %, published symmetric + offset {published:.3} %"
        );
    }
}
