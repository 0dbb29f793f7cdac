//! `fricsim diagnose --time-limit SECONDS`: a diagnosis that reaches its
//! limit still writes its report, exits 0, and says in report.json
//! (`time_limit`), report.md, report.html and its summary what it left
//! out; a candidate it did not finish is neither accepted nor reported
//! as tried; a limit it does not reach leaves the diagnosis as it was and
//! says so; a limit that is not a positive number is refused naming it.
//! The slider table (Thimmalapura 2004, 781 samples) takes several
//! seconds to diagnose in full.

use super::common::repository;
use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

fn diagnose(out: &Path, args: &[&str]) -> Output {
    let r = repository();
    Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("diagnose")
        .arg(r.join("examples/slider_breakaway.ssd"))
        .arg(r.join("examples/data/slider_breakaway.csv"))
        .arg("--out")
        .arg(out)
        .args(args)
        .output()
        .expect("running fricsim diagnose")
}

fn read_report(out: &Path) -> (Value, String, String) {
    let json = std::fs::read_to_string(out.join("report.json")).expect("report.json");
    let md = std::fs::read_to_string(out.join("report.md")).expect("report.md");
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    (
        serde_json::from_str(&json).expect("report.json parses"),
        md,
        html,
    )
}

fn names(list: &Value) -> Vec<String> {
    list.as_array()
        .expect("an array")
        .iter()
        .map(|v| v.as_str().expect("a name").to_string())
        .collect()
}

/// A limit far below what the diagnosis needs: exit status 0, every
/// report file written, `time_limit.reached` with what was left out, the
/// sentence in report.md, report.html and on stdout; no unfinished
/// candidate among the effects or the rounds' candidates, and no
/// candidate of the round in progress among the effects.
#[test]
fn a_time_limit_reached_still_writes_a_report_that_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("diagnosis");
    let run = diagnose(&out, &["--time-limit", "0.5", "-q"]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stdout}\n{stderr}");
    let (report, md, html) = read_report(&out);
    assert!(out.join("refitted.ssp").exists());
    let t = &report["time_limit"];
    assert_eq!(t["seconds"], 0.5, "{t:#}");
    assert_eq!(t["reached"], true, "{t:#}");
    let unfinished = names(&t["unfinished"]);
    let skipped = names(&t["skipped"]);
    assert!(!unfinished.is_empty() || !skipped.is_empty(), "{t:#}");
    let effects: Vec<String> = report["effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["name"].as_str().unwrap().to_string())
        .collect();
    let tried: Vec<String> = report["rounds"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|r| r.as_array().unwrap())
        .map(|c| c["name"].as_str().unwrap().to_string())
        .collect();
    for name in &unfinished {
        assert!(
            !effects.contains(name) && !tried.contains(name),
            "{name} is unfinished, yet among the effects {effects:?} or the candidates decided on {tried:?}"
        );
    }
    if !unfinished.is_empty() {
        assert!(t["round"].is_u64(), "the round in progress: {t:#}");
    }
    for c in t["finished"].as_array().unwrap() {
        let name = c["name"].as_str().unwrap().to_string();
        assert!(
            !effects.contains(&name),
            "{name} of an undecided round accepted"
        );
    }
    assert_eq!(
        report["cosimulations"].as_u64().map(|n| n > 0),
        Some(true),
        "{}",
        report["cosimulations"]
    );
    for (what, text) in [("report.md", &md), ("report.html", &html)] {
        assert!(text.contains("Time limit reached"), "{what}:\n{text}");
        for name in unfinished.iter().chain(&skipped) {
            assert!(
                text.contains(name.as_str())
                    || text.contains(&fricsim::diagnose::html::escape(name)),
                "{what} does not name {name}"
            );
        }
    }
    assert!(stdout.contains("TIME LIMIT REACHED"), "{stdout}");
    // -q: no progress line (and stderr is a pipe here anyway)
    assert!(!stderr.contains("elapsed"), "{stderr}");
}

/// A limit the diagnosis stays within: not reached, nothing skipped,
/// and the report says the limit and that it was not reached.
#[test]
fn a_time_limit_not_reached_is_said_and_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("diagnosis");
    let run = diagnose(
        &out,
        &[
            "--time-limit",
            "600",
            "--candidate",
            "viscous",
            "--no-polish",
        ],
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let (report, md, html) = read_report(&out);
    let t = &report["time_limit"];
    assert_eq!(t["seconds"], 600.0, "{t:#}");
    assert_eq!(t["reached"], false, "{t:#}");
    assert!(t["round"].is_null(), "{t:#}");
    for list in ["unfinished", "finished", "skipped"] {
        assert_eq!(t[list].as_array().map(Vec::len), Some(0), "{list}: {t:#}");
    }
    assert_eq!(report["refit"]["unfinished"], false);
    assert!(md.contains("- time limit: 600 s, not reached"), "{md}");
    for (what, text) in [
        ("report.md", &md),
        ("report.html", &html),
        ("stdout", &stdout.to_string()),
    ] {
        assert!(!text.contains("Time limit reached"), "{what}");
        assert!(!text.contains("TIME LIMIT"), "{what}");
    }
}

/// 0, a negative number, NaN, minus infinity and a word are refused
/// before anything runs, naming the value; nothing is written.
#[test]
fn a_time_limit_that_is_not_a_positive_number_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("diagnosis");
    for bad in ["0", "-1", "-0.5", "NaN", "-inf", "soon", ""] {
        let run = diagnose(&out, &["--time-limit", bad]);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "--time-limit {bad:?} was accepted");
        assert!(
            stderr.contains(&format!("'{bad}'")) && stderr.contains("--time-limit"),
            "--time-limit {bad:?}: {stderr}"
        );
        assert!(
            !out.exists(),
            "--time-limit {bad:?} wrote {}",
            out.display()
        );
    }
}
