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

/// The columns `names` of `run`, row by row.
fn columns(run: &fricsim::master::Run, names: &[&str]) -> Vec<Vec<f64>> {
    names
        .iter()
        .map(|name| {
            let k = run.columns.iter().position(|c| c == name).unwrap();
            (0..run.time.len()).map(|i| run.rows[i][k]).collect()
        })
        .collect()
}

/// The stick-slip benchmark of Canudas de Wit et al. 1995 (a mass pulled
/// through a spring at 0.1 m/s against LuGre friction) as two systems:
/// all FMI 2.0 (Rig1D.fmu + LuGre.fmu) and mixed (the FMI 3.0 SpringMass
/// written in C for the tests + LuGre.fmu). Both rigs integrate exactly
/// for a held friction force, so the two systems must agree to rounding,
/// under the Jacobi master and under the Newton master (which asks the
/// FMI 3.0 rig for its step sensitivity, `fmi3GetDirectionalDerivative`,
/// and restores its FMU state while it iterates).
#[test]
fn a_fmi3_rig_with_the_fmi2_lugre_equals_the_all_fmi2_system() {
    let dir = TempDir::new().unwrap();
    let spring_mass = c_fmu3("spring_mass.c", "spring_mass.xml", "SpringMass", dir.path());
    let rig1d = crate::common::repository().join("dist/Rig1D.fmu");
    let connections = [
        ("rig.v".to_string(), "friction.v".to_string()),
        ("friction.F".to_string(), "rig.F".to_string()),
    ];
    for (master, h) in [("jacobi", 1e-4), ("newton", 1e-3)] {
        let mut runs = Vec::new();
        for rig in [&rig1d, &spring_mass] {
            let fmus = vec![
                ("rig".to_string(), Fmu::open(rig).unwrap()),
                ("friction".to_string(), Fmu::open(lugre_fmu()).unwrap()),
            ];
            let mut system = System::from_fmus(fmus, &[], &connections, 0.0).unwrap();
            let run = simulate(&mut system, by_name(master).unwrap().as_mut(), h, 10.0).unwrap();
            assert!(run.error.is_none(), "{master}: {:?}", run.error);
            runs.push(columns(&run, &["rig.x", "rig.v", "friction.F"]));
        }
        let (fmi2, mixed) = (&runs[0], &runs[1]);
        // stick-slip: the mass sticks and slips, so friction swings
        let f = &fmi2[2];
        let swing =
            f.iter().cloned().fold(f64::MIN, f64::max) - f.iter().cloned().fold(f64::MAX, f64::min);
        assert!(swing > 0.3, "{master}: friction swings {swing} N");
        for (k, name) in ["x", "v", "F"].iter().enumerate() {
            let scale = fmi2[k].iter().fold(0.0f64, |a, b| a.max(b.abs()));
            let worst = fmi2[k]
                .iter()
                .zip(&mixed[k])
                .fold(0.0f64, |a, (p, q)| a.max((p - q).abs()));
            eprintln!("{master}: {name} differs by at most {worst:.1e} (largest {scale:.2e})");
            assert!(
                worst <= 1e-9 * scale,
                "{master}: {name} differs by {worst:e} (scale {scale:e})"
            );
        }
    }
}

/// Our own FMUs as FMI 3.0 (`dist/fmi3/`, the same binary as `dist/`):
/// the stick-slip benchmark with the FMI 3.0 LuGre and the FMI 2.0 rig
/// (the reverse of the mixed system above), and with both as FMI 3.0,
/// equals the all-FMI 2.0 system to the last bit under the Jacobi and the
/// Newton master (which restores FMU states and asks for directional
/// derivatives through FMI 3.0 here).
#[test]
fn our_fmi3_fmus_in_any_mix_equal_the_all_fmi2_system() {
    let dist = crate::common::repository().join("dist");
    let fmi2 = |name: &str| dist.join(format!("{name}.fmu"));
    let fmi3 = |name: &str| dist.join("fmi3").join(format!("{name}.fmu"));
    let connections = [
        ("rig.v".to_string(), "friction.v".to_string()),
        ("friction.F".to_string(), "rig.F".to_string()),
    ];
    let systems = [
        ("FMI 2.0 rig + FMI 2.0 LuGre", fmi2("Rig1D"), fmi2("LuGre")),
        ("FMI 2.0 rig + FMI 3.0 LuGre", fmi2("Rig1D"), fmi3("LuGre")),
        ("FMI 3.0 rig + FMI 3.0 LuGre", fmi3("Rig1D"), fmi3("LuGre")),
    ];
    for (master, h) in [("jacobi", 1e-4), ("newton", 1e-3)] {
        let mut runs = Vec::new();
        for (what, rig, lugre) in &systems {
            let fmus = vec![
                ("rig".to_string(), Fmu::open(rig).unwrap()),
                ("friction".to_string(), Fmu::open(lugre).unwrap()),
            ];
            let versions: Vec<bool> = fmus
                .iter()
                .map(|(_, f)| f.description().is_fmi3())
                .collect();
            assert_eq!(
                versions,
                [what.starts_with("FMI 3.0"), what.ends_with("FMI 3.0 LuGre")],
                "{what}"
            );
            let mut system = System::from_fmus(fmus, &[], &connections, 0.0).unwrap();
            let run = simulate(&mut system, by_name(master).unwrap().as_mut(), h, 10.0).unwrap();
            assert!(run.error.is_none(), "{master}, {what}: {:?}", run.error);
            runs.push(columns(
                &run,
                &["rig.x", "rig.v", "friction.F", "friction.z"],
            ));
        }
        let f = &runs[0][2];
        let swing =
            f.iter().cloned().fold(f64::MIN, f64::max) - f.iter().cloned().fold(f64::MAX, f64::min);
        assert!(swing > 0.3, "{master}: friction swings {swing} N");
        for (k, (what, _, _)) in systems.iter().enumerate().skip(1) {
            assert_eq!(
                runs[k], runs[0],
                "{master}: {what} differs from the all-FMI 2.0 system"
            );
        }
    }
}

/// `fmi3GetDirectionalDerivative` through `Fmi3Instance`: the FMI 3.0
/// rig's step sensitivity to its input equals the central difference of
/// two steps from one saved FMU state, to 1e-7 relative; before a step
/// (and once the input is set again) it is the feedthrough, none.
#[test]
fn fmi3_directional_derivatives_equal_differences_of_steps() {
    const X: u32 = 1;
    const F: u32 = 3;
    let dir = TempDir::new().unwrap();
    let fmu = Fmu::open(c_fmu3(
        "spring_mass.c",
        "spring_mass.xml",
        "SpringMass",
        dir.path(),
    ))
    .unwrap();
    let mut rig = fmu.instantiate_fmi3("rig").unwrap();
    rig.enter_initialization_mode(0.0, None).unwrap();
    rig.exit_initialization_mode().unwrap();
    let mut d = [f64::NAN; 2];
    rig.get_directional_derivative(&[X, V], &[F], &[1.0], &mut d)
        .unwrap();
    assert_eq!(d, [0.0, 0.0], "no feedthrough before a step");
    rig.set_float64(&[F], &[0.3]).unwrap();
    rig.do_step_with(0.0, 0.5, Rollback::Possible).unwrap();
    let saved = rig.get_state().unwrap();
    let (h, eps) = (0.2, 1e-4);
    let mut step_from_saved = |force: f64| {
        rig.set_state(&saved).unwrap();
        rig.set_float64(&[F], &[force]).unwrap();
        rig.do_step_with(0.5, h, Rollback::Possible).unwrap();
        let mut xv = [0.0; 2];
        rig.get_float64(&[X, V], &mut xv).unwrap();
        xv
    };
    let (up, down) = (step_from_saved(0.3 + eps), step_from_saved(0.3 - eps));
    step_from_saved(0.3);
    rig.get_directional_derivative(&[X, V], &[F], &[2.0], &mut d)
        .unwrap();
    for k in 0..2 {
        let difference = 2.0 * (up[k] - down[k]) / (2.0 * eps);
        assert!(
            (d[k] - difference).abs() <= 1e-7 * difference.abs() && difference.abs() > 1e-3,
            "output {k}: {} vs difference {difference}",
            d[k]
        );
    }
    rig.set_float64(&[F], &[0.3]).unwrap();
    rig.get_directional_derivative(&[X, V], &[F], &[1.0], &mut d)
        .unwrap();
    assert_eq!(d, [0.0, 0.0], "the input set again: the feedthrough");
}

/// A step that returns early although the instance was made without
/// early return (a broken FMI 3.0 FMU: Stair with STAIR_EARLY_RETURN set
/// in the environment of `fricsim cosim`) stops the run with an error
/// naming the instance, the step and where the FMU got to, instead of
/// recording the half-step's values as the step's end; the rows before
/// it are kept, marked incomplete.
#[test]
fn a_step_that_returns_early_unasked_is_an_error_and_the_rows_stand() {
    let dir = TempDir::new().unwrap();
    let stair = c_fmu3("stair.c", "stair.xml", "Stair", dir.path());
    let out = dir.path().join("stair.csv");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .args(["cosim", "--fmu"])
        .arg(format!("stair={}", stair.display()))
        .args(["--step", "0.5", "--stop", "10", "--out"])
        .arg(&out)
        .env("STAIR_EARLY_RETURN", "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "{stderr}");
    for part in [
        "fmi3DoStep of instance \"stair\" from t = 0 over 0.5 returned early",
        "earlyReturn = true",
        "lastSuccessfulTime = 0.25",
    ] {
        assert!(stderr.contains(part), "missing {part:?} in {stderr}");
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
    let written = std::fs::read_to_string(&out).unwrap();
    assert!(
        written
            .starts_with("time,stair.height,stair.counter,stair.even\n0.0,1.0,1,0\n# INCOMPLETE"),
        "{written}"
    );
}
