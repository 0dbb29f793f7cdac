//! FMUs that fail mid-run: BeltOscillator (a C FMU written by hand, see
//! tests/c/belt_oscillator) coupled with the repository's LuGre.fmu, told
//! to fail at its 10th fmi2DoStep with fmi2Discard, fmi2Error or fmi2Fatal,
//! or to return fmi2OK with a NaN state.
//! The run stops, the rows of the completed communication points are kept,
//! and the report names the instance, the call and the status; a discarded
//! step also says how far the FMU got (fmi2LastSuccessfulTime) and whether
//! it asks to end (fmi2Terminated); after fmi2Fatal the FMU is never called
//! again, not even by fmi2FreeInstance; after fmi2Error it is not asked to
//! fmi2Terminate (not allowed in the error state), only freed. The same through `fricsim cosim`,
//! whose CSV keeps the rows so far and ends with an `# INCOMPLETE` line.
//! A step that takes too long (0.6 s of sleep in the FMU) under a time
//! limit (`--step-timeout`) is reported the same way, naming the instance,
//! the call, its duration and the limit; the watchdog says so on stderr
//! while the call is still running.

use crate::belt;
use crate::common;

use belt::Counters;
use fricsim::master::{gauss_seidel::GaussSeidel, jacobi::Jacobi, simulate, MasterAlgorithm, Run};
use fricsim::system::System;
use fricsim::FmuError;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

/// 2^-10 s: communication points and half steps are exact binary numbers.
const H: f64 = 1.0 / 1024.0;
/// The call of fmi2DoStep that fails; the 9 steps before it complete.
const FAULT_STEP: usize = 10;

struct Rig {
    _dir: TempDir,
    belt: PathBuf,
    lugre: PathBuf,
}

fn rig() -> Rig {
    let dir = tempfile::tempdir().unwrap();
    let belt = belt::build_fmu(dir.path());
    Rig {
        _dir: dir,
        belt,
        lugre: common::lugre_fmu(),
    }
}

/// rig = BeltOscillator, friction = LuGre, coupled through the slip
/// velocity and the friction force; the rig fails as `fault` says.
fn coupled(rig: &Rig, fault: i32, terminates: bool) -> System {
    let components = [
        ("rig".to_string(), rig.belt.as_path()),
        ("friction".to_string(), rig.lugre.as_path()),
    ];
    let parameters = [
        ("rig.fault".to_string(), fault as f64),
        ("rig.fault_step".to_string(), FAULT_STEP as f64),
        ("rig.fault_terminates".to_string(), terminates as i32 as f64),
        // start sliding: the body at rest on the moving belt
        ("rig.v0".to_string(), 0.0),
    ];
    let connections = [
        ("rig.v".to_string(), "friction.v".to_string()),
        ("friction.F".to_string(), "rig.F".to_string()),
    ];
    System::build(&components, &parameters, &connections).unwrap()
}

/// The run stopped in the step from t = 9·H, keeping the rows at 0, H, …, 9·H.
fn assert_stopped_at_the_fault(run: &Run) -> &str {
    let error = run.error.as_deref().expect("the run must stop");
    assert_eq!(run.rows.len(), FAULT_STEP, "{error}");
    assert_eq!(run.time.len(), FAULT_STEP);
    assert_eq!(*run.time.last().unwrap(), (FAULT_STEP - 1) as f64 * H);
    assert!(
        error.starts_with(&format!("at t = {}: ", (FAULT_STEP - 1) as f64 * H)),
        "{error}"
    );
    // the rows kept are real results: the belt drags the body along
    let kv = run.columns.iter().position(|c| c == "rig.v").unwrap();
    let kf = run.columns.iter().position(|c| c == "friction.F").unwrap();
    let last = run.rows.last().unwrap();
    assert!(last.iter().all(|x| x.is_finite()), "{last:?}");
    assert!(last[kv] < 0.0 && last[kf] < 0.0, "{last:?}");
    error
}

fn masters() -> [Box<dyn MasterAlgorithm>; 3] {
    [
        Box::new(Jacobi::default()),
        Box::new(GaussSeidel::new(false)),
        Box::new(GaussSeidel::new(true)),
    ]
}

#[test]
fn a_discarded_step_says_how_far_the_fmu_got_and_that_it_does_not_ask_to_end() {
    let rig = rig();
    for mut master in masters() {
        let mut system = coupled(&rig, belt::DISCARD, false);
        let run = simulate(&mut system, master.as_mut(), H, 1.0).unwrap();
        let error = assert_stopped_at_the_fault(&run);
        let t = (FAULT_STEP - 1) as f64 * H;
        for part in [
            "fmi2DoStep failed for instance \"rig\" with fmi2Discard".to_string(),
            format!("fault injected at step {FAULT_STEP}"),
            format!(
                "the FMU completed the step only up to t = {} (fmi2LastSuccessfulTime)",
                t + H / 2.0
            ),
            "it does not ask to end the simulation (fmi2Terminated = false)".to_string(),
        ] {
            assert!(error.contains(part.as_str()), "{}: {error}", master.name());
        }
        assert!(!error.contains("friction"), "{error}");
        // a discard is not fatal: the instance is freed with the system
        let counters = Counters::of(&system.components[0].fmu);
        assert_eq!(counters.live_instances(), 1);
        drop(system);
        assert_eq!(counters.live_instances(), 0);
        assert_eq!(counters.calls_after_fatal(), 0);
    }
}

/// A discarded step of an FMU that asks to end the simulation
/// (fmi2Terminated = true) is the run's normal end, as in FMPy: no error,
/// the last row at the FMU's fmi2LastSuccessfulTime, half-way through
/// the step.
#[test]
fn a_discarded_step_that_asks_to_end_ends_the_run_normally() {
    let rig = rig();
    for mut master in masters() {
        let mut system = coupled(&rig, belt::DISCARD, true);
        let run = simulate(&mut system, master.as_mut(), H, 1.0).unwrap();
        assert_eq!(run.error, None, "{}", master.name());
        assert_eq!(run.rows.len(), FAULT_STEP + 1);
        assert_eq!(run.time.len(), FAULT_STEP + 1);
        let end = (FAULT_STEP - 1) as f64 * H + H / 2.0;
        assert_eq!(*run.time.last().unwrap(), end);
        let kx = run.columns.iter().position(|c| c == "rig.x").unwrap();
        let (before, last) = (&run.rows[FAULT_STEP - 1], &run.rows[FAULT_STEP]);
        // the rig moved on by the half step it completed
        assert!(last[kx].is_finite() && last[kx] != before[kx], "{last:?}");
    }
}

#[test]
fn an_error_mid_run_stops_the_run_and_the_instance_is_still_freed() {
    let rig = rig();
    for mut master in masters() {
        let mut system = coupled(&rig, belt::ERROR, false);
        let run = simulate(&mut system, master.as_mut(), H, 1.0).unwrap();
        let error = assert_stopped_at_the_fault(&run);
        for part in [
            "fmi2DoStep failed for instance \"rig\" with fmi2Error",
            "fault injected at step 10",
        ] {
            assert!(error.contains(part), "{}: {error}", master.name());
        }
        assert!(!error.contains("fmi2LastSuccessfulTime"), "{error}");
        // the rig is in the error state, where FMI 2.0 allows no
        // fmi2Terminate (BeltOscillator refuses it): only LuGre is ended
        assert!(run.warnings.is_empty(), "{:?}", run.warnings);
        let counters = Counters::of(&system.components[0].fmu);
        drop(system);
        assert_eq!(counters.live_instances(), 0);
    }
}

#[test]
fn after_fatal_the_fmu_is_not_called_again_not_even_to_free_it() {
    let rig = rig();
    for mut master in masters() {
        let mut system = coupled(&rig, belt::FATAL, false);
        let counters = Counters::of(&system.components[0].fmu);
        let live_before = counters.live_instances();
        let run = simulate(&mut system, master.as_mut(), H, 1.0).unwrap();
        let error = assert_stopped_at_the_fault(&run);
        for part in [
            "fmi2DoStep failed for instance \"rig\" with fmi2Fatal",
            "fault injected at step 10",
        ] {
            assert!(error.contains(part), "{}: {error}", master.name());
        }
        // the host refuses further calls itself
        let e = system.components[0]
            .instance
            .get_real(&[belt::X], &mut [0.0])
            .unwrap_err();
        assert!(
            matches!(
                e,
                FmuError::AfterFatal {
                    function: "fmi2GetReal",
                    ..
                }
            ),
            "{e}"
        );
        // the other component is unaffected
        let mut f = [f64::NAN];
        let lugre_f = system.components[1]
            .fmu
            .variable("F")
            .unwrap()
            .value_reference;
        system.components[1]
            .instance
            .get_real(&[lugre_f], &mut f)
            .unwrap();
        assert!(f[0].is_finite());
        drop(system);
        assert_eq!(counters.calls_after_fatal(), 0, "{}", master.name());
        // never freed: the FMU may not be called after fmi2Fatal
        assert_eq!(counters.live_instances(), live_before, "{}", master.name());
    }
}

#[test]
fn a_nan_output_stops_the_run_and_names_the_fmu_that_produced_it() {
    // fault 1: the 10th step returns fmi2OK, but the rig's state is NaN.
    // Without the host's check the NaN would reach LuGre's input, and the
    // run would fail there, blaming the friction FMU.
    let rig = rig();
    let mut system = coupled(&rig, belt::NAN_STATE, false);
    let run = simulate(&mut system, &mut Jacobi::default(), H, 1.0).unwrap();
    let error = assert_stopped_at_the_fault(&run);
    let expected = format!(
        "non-finite outputs from instance \"rig\" (rig.x = NaN, rig.v = NaN, rig.a = NaN) after fmi2DoStep to t = {}",
        FAULT_STEP as f64 * H
    );
    assert!(error.contains(&expected), "{error}");
    assert!(!error.contains("friction"), "{error}");
}

#[test]
fn a_windowed_run_that_stops_keeps_the_times_of_its_last_rows() {
    // as a sweep's run: the rows before the failure, the last of them
    // only, each at its time; with a window of 10 the row of the NaN
    // folds the window and is then dropped
    let rig = rig();
    for fault in [belt::ERROR, belt::NAN_STATE] {
        let mut system = coupled(&rig, fault, false);
        let full = simulate(&mut system, &mut Jacobi::default(), H, 1.0).unwrap();
        assert_stopped_at_the_fault(&full);
        let width = full.rows.width();
        for window in [2, 3, 4, 9, 10, 11] {
            let mut system = coupled(&rig, fault, false);
            system.keep_last_rows(Some(window));
            let run = simulate(&mut system, &mut Jacobi::default(), H, 1.0).unwrap();
            assert_eq!(run.error, full.error, "window {window}");
            assert_eq!(run.rows.rows_pushed(), FAULT_STEP, "window {window}");
            let first = run.rows.rows_folded();
            assert!(run.rows.len() <= window, "window {window}");
            assert_eq!(run.time.len(), run.rows.len(), "window {window}");
            assert_eq!(run.time, full.time[first..], "window {window}");
            assert_eq!(run.rows.as_flat(), &full.rows.as_flat()[first * width..]);
            assert_eq!(*run.time.last().unwrap(), (FAULT_STEP - 1) as f64 * H);
        }
    }
}

/// `fricsim cosim` with the rig failing: exit status 1, the message on
/// stderr, the CSV with the rows so far.
fn cosim(rig: &Rig, fault: i32, out: &Path) -> (Option<i32>, String) {
    cosim_with(rig, fault, out, &[])
}

fn cosim_with(rig: &Rig, fault: i32, out: &Path, extra: &[&str]) -> (Option<i32>, String) {
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("cosim")
        .args(extra)
        .arg("--fmu")
        .arg(format!("rig={}", rig.belt.display()))
        .arg("--fmu")
        .arg(format!("friction={}", rig.lugre.display()))
        .args([
            "--connect",
            "rig.v->friction.v",
            "--connect",
            "friction.F->rig.F",
        ])
        .args(["--set", &format!("rig.fault={fault}")])
        .args(["--set", &format!("rig.fault_step={FAULT_STEP}")])
        .args(["--set", "rig.fault_terminates=false", "--set", "rig.v0=0"])
        .args(["--step", &H.to_string(), "--stop", "0.5"])
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    (
        output.status.code(),
        String::from_utf8(output.stderr).unwrap(),
    )
}

#[test]
fn fricsim_cosim_exits_nonzero_names_the_failure_and_keeps_the_rows_so_far() {
    let rig = rig();
    let dir = tempfile::tempdir().unwrap();
    for (fault, status, extra) in [
        (belt::DISCARD, "fmi2Discard", "fmi2LastSuccessfulTime"),
        (belt::ERROR, "fmi2Error", "fault injected at step 10"),
        (belt::FATAL, "fmi2Fatal", "fault injected at step 10"),
        (
            belt::NAN_STATE,
            "",
            "non-finite outputs from instance \"rig\" (rig.x = NaN",
        ),
    ] {
        let out = dir.path().join(format!("fault{fault}.csv"));
        let (code, stderr) = cosim(&rig, fault, &out);
        assert_eq!(code, Some(1), "{stderr}");
        let failed = if status.is_empty() {
            "after fmi2DoStep to t = 0.009765625".to_string()
        } else {
            format!("fmi2DoStep failed for instance \"rig\" with {status}")
        };
        for part in ["run INCOMPLETE", &failed, extra, out.to_str().unwrap()] {
            assert!(stderr.contains(part), "missing {part:?} in {stderr}");
        }
        assert!(!stderr.contains("panicked"), "{stderr}");
        // the FMU prints "FMI VIOLATION" if it is called after fmi2Fatal
        assert!(!stderr.contains("FMI VIOLATION"), "{stderr}");

        // header, the rows so far, and a comment that marks the file
        let csv = std::fs::read_to_string(&out).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        // every output, the Boolean friction.sliding too, as run records them
        assert_eq!(
            lines[0],
            "time,rig.x,rig.v,rig.a,friction.F,friction.z,friction.P_diss,friction.E_stored,friction.sliding"
        );
        assert_eq!(lines.len(), 1 + FAULT_STEP + 1, "{csv}");
        let marker = lines[FAULT_STEP + 1];
        assert!(
            marker.starts_with("# INCOMPLETE: the run stopped early: at t = 0.0087890625: ")
                && marker.contains(&failed),
            "{marker}"
        );
        let last: Vec<f64> = lines[FAULT_STEP]
            .split(',')
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(last[0], (FAULT_STEP - 1) as f64 * H);
        assert!(last.iter().all(|x| x.is_finite()), "{csv}");
    }
}

#[test]
fn a_step_over_the_time_limit_stops_the_run_naming_the_instance_and_the_call() {
    let rig = rig();
    for mut master in masters() {
        let mut system = coupled(&rig, belt::SLOW, false);
        system.set_call_time_limit(Some(std::time::Duration::from_millis(200)));
        let run = simulate(&mut system, master.as_mut(), H, 1.0).unwrap();
        let error = assert_stopped_at_the_fault(&run);
        for part in [
            "fmi2DoStep for instance \"rig\" took 0.6",
            "longer than the limit of 0.2 s (--step-timeout)",
        ] {
            assert!(error.contains(part), "{}: {error}", master.name());
        }
        // A slow step is not an FMU error: the instance is freed as usual.
        let counters = Counters::of(&system.components[0].fmu);
        drop(system);
        assert_eq!(counters.live_instances(), 0);
    }
    // Without a limit the same run completes.
    let mut system = coupled(&rig, belt::SLOW, false);
    let run = simulate(&mut system, &mut Jacobi::default(), H, 20.0 * H).unwrap();
    assert!(run.error.is_none(), "{:?}", run.error);
    assert_eq!(run.rows.len(), 21);
}

#[test]
fn fricsim_cosim_step_timeout_reports_the_slow_call_while_it_runs_and_keeps_the_rows() {
    let rig = rig();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("slow.csv");
    let (code, stderr) = cosim_with(&rig, belt::SLOW, &out, &["--step-timeout", "0.2"]);
    assert_eq!(code, Some(1), "{stderr}");
    for part in [
        // the watchdog, while the call is running
        "instance \"rig\" has been in fmi2DoStep for more than the limit of 0.2 s",
        // the run's report, after it returned
        "run INCOMPLETE",
        "fmi2DoStep for instance \"rig\" took 0.6",
    ] {
        assert!(stderr.contains(part), "missing {part:?} in {stderr}");
    }
    let csv = std::fs::read_to_string(&out).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 1 + FAULT_STEP + 1, "{csv}");
    assert!(lines[FAULT_STEP + 1].starts_with("# INCOMPLETE"), "{csv}");
    // A limit that is not a positive number is refused.
    let (code, stderr) = cosim_with(&rig, 0, &out, &["--step-timeout=0"]);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("--step-timeout must be a positive number"),
        "{stderr}"
    );
}
