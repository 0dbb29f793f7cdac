//! FMI 3.0 Co-Simulation import (`fricsim_fmi::Fmi3Instance` and the
//! system's FMI 3.0 components) against the FMI 3.0 test FMUs written by
//! hand in C (`tests/c/fmi3`): the bouncing ball against its closed form,
//! FMU state got, set and serialized, misuse turned into errors with the
//! FMU's own messages, and a system of FMI 3.0 and FMI 2.0 components
//! under every master.
//! (The same FMUs against FMPy: tests/test_fmi3_import.py.)

use crate::common::{c_fmu3, lugre_fmu};
use fricsim::fmu::{Fmi3Instance, Fmu, Rollback};
use fricsim::master::{by_name, simulate};
use fricsim::system::System;
use fricsim::FmuError;
use std::path::PathBuf;
use tempfile::TempDir;

const H: u32 = 1;
const V: u32 = 2;
const G: u32 = 3;
const BOUNCES: u32 = 6;
const RESTING: u32 = 7;
const LABEL: u32 = 8;

fn ball() -> (TempDir, PathBuf) {
    let dir = TempDir::new().unwrap();
    let fmu = c_fmu3(
        "bouncing_ball.c",
        "bouncing_ball.xml",
        "BouncingBall",
        dir.path(),
    );
    (dir, fmu)
}

/// An instance in step mode from t = 0.
fn stepping(fmu: &Fmu) -> Fmi3Instance {
    let mut ball = fmu.instantiate_fmi3("ball").unwrap();
    ball.enter_initialization_mode(0.0, Some(3.0)).unwrap();
    ball.exit_initialization_mode().unwrap();
    ball
}

/// The ball's height, velocity and bounces at `t` from h0 = 1, v0 = 0,
/// computed here from the bounce times: the k-th bounce leaves at
/// u_k = e^k·g·t1 (t1 = √(2·h0/g) the first), the next comes 2·u_k/g
/// later; the ball rests once u_k < v_min.
fn closed_form(t: f64, g: f64, e: f64, v_min: f64) -> (f64, f64, i32) {
    let t1 = (2.0 / g).sqrt();
    if t < t1 {
        return (1.0 - 0.5 * g * t * t, -g * t, 0);
    }
    let (mut start, mut u, mut bounces) = (t1, e * g * t1, 1);
    loop {
        if u < v_min {
            return (0.0, 0.0, bounces);
        }
        let next = start + 2.0 * u / g;
        if t < next {
            let s = t - start;
            return (u * s - 0.5 * g * s * s, u - g * s, bounces);
        }
        start = next;
        u *= e;
        bounces += 1;
    }
}

#[test]
fn the_bouncing_ball_follows_its_closed_form_with_the_bounces_inside_the_steps() {
    let (_dir, path) = ball();
    let fmu = Fmu::open(&path).unwrap();
    assert!(fmu.description().is_fmi3());
    assert_eq!(fmu.library().version(), "3.0");
    for h in [0.5, 0.01, 0.013] {
        let mut ball = stepping(&fmu);
        let mut t = 0.0;
        let mut bounced = 0;
        while t < 3.0 {
            let outcome = ball.do_step_with(t, h, Rollback::Never).unwrap();
            assert!(!outcome.terminate_simulation && !outcome.early_return);
            assert_eq!(outcome.last_successful_time, t + h);
            t += h;
            let mut hv = [0.0; 2];
            ball.get_float64(&[H, V], &mut hv).unwrap();
            let mut n = [0];
            ball.get_int32(&[BOUNCES], &mut n).unwrap();
            let (h_exact, v_exact, n_exact) = closed_form(t, 9.81, 0.7, 0.1);
            assert!(
                (hv[0] - h_exact).abs() < 1e-9,
                "h at t = {t}, step {h}: {hv:?} vs {h_exact}"
            );
            assert!(
                (hv[1] - v_exact).abs() < 1e-9,
                "v at t = {t}, step {h}: {hv:?} vs {v_exact}"
            );
            assert_eq!(n[0], n_exact, "bounces at t = {t}, step {h}");
            bounced = n[0];
        }
        let mut resting = [0];
        ball.get_boolean_raw(&[RESTING], &mut resting).unwrap();
        assert!(
            bounced > 5 && resting[0] == 1,
            "step {h}: {bounced} bounces"
        );
        assert_eq!(ball.get_string(&[LABEL]).unwrap(), ["ball"]);
    }
}

#[test]
fn fmu_state_is_restored_and_serialized() {
    let (_dir, path) = ball();
    let fmu = Fmu::open(&path).unwrap();
    let mut ball = stepping(&fmu);
    let h_at = |ball: &mut Fmi3Instance| {
        let mut hv = [0.0; 2];
        ball.get_float64(&[H, V], &mut hv).unwrap();
        hv
    };
    ball.do_step_with(0.0, 0.3, Rollback::Possible).unwrap();
    let mut saved = ball.get_state().unwrap();
    ball.do_step_with(0.3, 0.4, Rollback::Possible).unwrap();
    let after = h_at(&mut ball);
    ball.set_state(&saved).unwrap();
    ball.do_step_with(0.3, 0.4, Rollback::Possible).unwrap();
    assert_eq!(h_at(&mut ball), after);

    // serialized at 0.7, stepped on, restored from the bytes
    ball.update_state(&mut saved).unwrap();
    let bytes = ball.serialize_state(&saved).unwrap();
    ball.do_step_with(0.7, 0.5, Rollback::Possible).unwrap();
    let later = h_at(&mut ball);
    let restored = ball.deserialize_state(&bytes).unwrap();
    ball.set_state(&restored).unwrap();
    assert_eq!(h_at(&mut ball), after);
    ball.do_step_with(0.7, 0.5, Rollback::Possible).unwrap();
    assert_eq!(h_at(&mut ball), later);
    ball.free_state(saved).unwrap();
    ball.free_state(restored).unwrap();
}

#[test]
fn misuse_is_an_fmi3_error_with_the_fmus_message() {
    let (_dir, path) = ball();
    let fmu = Fmu::open(&path).unwrap();

    // FMI 2.0's instance type is refused for an FMI 3.0 FMU
    let e = fmu.instantiate("two").unwrap_err();
    assert!(matches!(e, FmuError::WrongInstanceType { .. }), "{e}");
    assert!(e.to_string().contains("FMI 3.0 FMU"), "{e}");

    // a step before initialization: the FMU refuses and says why
    let mut ball = fmu.instantiate_fmi3("early").unwrap();
    let e = ball.do_step_with(0.0, 0.1, Rollback::Never).unwrap_err();
    let text = e.to_string();
    for part in [
        "fmi3DoStep failed",
        "\"early\"",
        "fmi3Error",
        "not allowed in phase",
    ] {
        assert!(text.contains(part), "missing {part:?} in {text}");
    }
    assert!(ball.has_failed());

    // an invalid parameter is refused where it is checked, naming it
    let mut ball = fmu.instantiate_fmi3("negative").unwrap();
    ball.enter_initialization_mode(0.0, None).unwrap();
    ball.set_float64(&[G], &[-1.0]).unwrap();
    let e = ball.exit_initialization_mode().unwrap_err();
    assert!(e.to_string().contains("g = -1: must be positive"), "{e}");

    // NaN, and a value reference of no Float64 variable
    let mut ball = fmu.instantiate_fmi3("nan").unwrap();
    ball.enter_initialization_mode(0.0, None).unwrap();
    let e = ball.set_float64(&[H], &[f64::NAN]).unwrap_err();
    assert!(
        e.to_string().contains("value reference 1 set to nan"),
        "{e}"
    );
    let mut ball = stepping(&fmu);
    let e = ball.get_float64(&[BOUNCES], &mut [0.0]).unwrap_err();
    assert!(
        e.to_string()
            .contains("no Float64 variable has value reference 6"),
        "{e}"
    );

    // lengths are checked before the FMU sees a pointer
    let e = ball.get_float64(&[H, V], &mut [0.0]).unwrap_err();
    assert!(matches!(e, FmuError::LengthMismatch { .. }), "{e}");

    // an FMI 3.0 instance of an FMI 2.0 FMU is refused
    let lugre = Fmu::open(lugre_fmu()).unwrap();
    let e = lugre.instantiate_fmi3("three").unwrap_err();
    assert!(matches!(e, FmuError::WrongInstanceType { .. }), "{e}");
}

/// An FMI 3.0 ball drives LuGre.fmu (FMI 2.0) under the Jacobi,
/// Gauss-Seidel and Newton masters (the last saves the components' FMU
/// states to iterate a step): the ball's columns are those of the Jacobi
/// run (it has no input, so no master changes its path), every run ends
/// at the stop time, and the ball's speed makes friction.
#[test]
fn a_mixed_system_runs_under_every_master_with_the_fmi3_ball_rolled_back() {
    let (_dir, path) = ball();
    let connections = [("ball.v".to_string(), "lugre.v".to_string())];
    let mut runs = Vec::new();
    for master in ["jacobi", "gauss-seidel", "newton"] {
        let fmus = vec![
            ("ball".to_string(), Fmu::open(&path).unwrap()),
            ("lugre".to_string(), Fmu::open(lugre_fmu()).unwrap()),
        ];
        let mut system = System::from_fmus(fmus, &[], &connections, 0.0).unwrap();
        let run = simulate(&mut system, by_name(master).unwrap().as_mut(), 0.01, 2.0).unwrap();
        assert!(run.error.is_none(), "{master}: {:?}", run.error);
        assert_eq!(run.time.len(), 201, "{master}");
        runs.push((master, run));
    }
    let column = |run: &fricsim::master::Run, name: &str| -> Vec<f64> {
        let k = run.columns.iter().position(|c| c == name).unwrap();
        (0..run.time.len()).map(|i| run.rows[i][k]).collect()
    };
    let (_, jacobi) = &runs[0];
    for (master, run) in &runs[1..] {
        for name in ["ball.h", "ball.v"] {
            assert_eq!(column(run, name), column(jacobi, name), "{master}: {name}");
        }
        let f = column(run, "lugre.F");
        assert!(
            f.iter().any(|f| f.abs() > 0.5),
            "{master}: friction from the ball's speed"
        );
    }
}
