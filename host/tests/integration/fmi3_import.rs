//! FMI 3.0 Co-Simulation import (`fricsim_fmi::Fmi3Instance` and the
//! system's FMI 3.0 components) against the FMI 3.0 test FMUs written by
//! hand in C (`tests/c/fmi3`): the bouncing ball against its closed form,
//! FMU state got, set and serialized, misuse turned into errors with the
//! FMU's own messages, and a system of FMI 3.0 and FMI 2.0 components
//! under every master.
//! (The same FMUs against FMPy: tests/test_fmi3_import.py.)

use crate::common::{assert_message, c_fmu3, lugre_fmu};
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

// ---- FMI 3.0 arrays: Gains (tests/c/fmi3/gains.c) --------------------------

fn gains() -> (TempDir, PathBuf) {
    let dir = TempDir::new().unwrap();
    let fmu = c_fmu3("gains.c", "gains.xml", "Gains", dir.path());
    (dir, fmu)
}

/// The value references of the variables `names` of `fmu` (elements by
/// their names, `k[2]`).
fn vrs_of(fmu: &Fmu, names: &[&str]) -> Vec<u32> {
    names
        .iter()
        .map(|n| fmu.description().variable(n).unwrap().value_reference)
        .collect()
}

/// Gains in step mode from t = 0 with its start values.
fn stepping_gains(fmu: &Fmu) -> Fmi3Instance {
    let mut g = fmu.instantiate_fmi3("g").unwrap();
    g.enter_initialization_mode(0.0, None).unwrap();
    g.exit_initialization_mode().unwrap();
    g
}

/// Each array is its elements, named `k[1]`, `A[1,2]`, with their own
/// start values and value references from 2³¹, which are none of the
/// FMU's; each element of an output array is an output, depending on the
/// elements of the arrays its array depends on; `fricsim info` lists
/// them so.
#[test]
fn an_fmi3_array_fmu_is_read_as_its_elements() {
    let (_dir, path) = gains();
    let fmu = Fmu::open(&path).unwrap();
    let d = fmu.description();
    let arrays: Vec<(&str, Vec<usize>)> = d
        .arrays
        .iter()
        .map(|a| (a.name.as_str(), a.dimensions.clone()))
        .collect();
    assert_eq!(
        arrays,
        [
            ("k", vec![3]),
            ("u", vec![3]),
            ("enable", vec![3]),
            ("A", vec![2, 3]),
            ("offset", vec![2]),
            ("y", vec![3]),
            ("yd", vec![3]),
            ("z", vec![2, 3]),
            ("count", vec![2]),
            ("positive", vec![3])
        ]
    );
    // 2 scalars and 34 elements
    assert_eq!(d.variables.len(), 36);
    let starts: Vec<String> = [
        "A[1,1]",
        "A[1,3]",
        "A[2,3]",
        "u[2]",
        "offset[2]",
        "enable[3]",
    ]
    .iter()
    .map(|n| d.variable(n).unwrap().kind.start_text().unwrap())
    .collect();
    assert_eq!(starts, ["1.0", "0.5", "-1.0", "-1.0", "20", "false"]);
    let elements: Vec<u32> = d
        .variables
        .iter()
        .filter(|v| v.element.is_some())
        .map(|v| v.value_reference)
        .collect();
    assert_eq!(elements, ((1 << 31)..(1 << 31) + 34).collect::<Vec<u32>>());
    assert_eq!(vrs_of(&fmu, &["time", "total"]), [0, 11]);

    let index = |name: &str| d.variable(name).unwrap().index;
    let output = |name: &str| {
        d.outputs
            .iter()
            .find(|o| o.index == index(name))
            .unwrap_or_else(|| panic!("{name} is not an output"))
            .dependencies
            .clone()
    };
    assert_eq!(d.outputs.len(), 3 + 3 + 6 + 2 + 3 + 1);
    let u = ["u[1]", "u[2]", "u[3]"].map(index).to_vec();
    assert_eq!(output("yd[2]"), Some(u.clone()));
    assert_eq!(output("total"), Some(u));
    assert_eq!(output("z[2,1]"), Some(vec![]));

    let info = std::process::Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("info")
        .arg(&path)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(info.status.success(), "{text}");
    let row = |name: &str| row_in(&text, name);
    assert_eq!(
        row("A[2,3]")[..5],
        ["A[2,3]", "parameter", "fixed", "Float64", "-1.0"]
    );
    assert_eq!(
        row("offset[2]")[..5],
        ["offset[2]", "parameter", "fixed", "Int32", "20"]
    );
    assert_eq!(
        row("positive[3]")[..4],
        ["positive[3]", "output", "discrete", "Boolean"]
    );
    let arrays = &text[text.find("Arrays (above as their elements)").unwrap()..];
    assert_eq!(
        row_in(arrays, "A"),
        ["A", "Float64", "2", "×", "3", "A[1,1]", "…", "A[2,3]"]
    );
    assert_eq!(
        row_in(arrays, "offset"),
        ["offset", "Int32", "2", "offset[1]", "…", "offset[2]"]
    );
}

/// Elements are read through their arrays, each array whole once per
/// call (Gains refuses a call whose nValues is not its arrays' sizes),
/// in calls that mix them with scalars; an element is set by setting its
/// array whole, the other elements as the FMU holds them: from the start
/// values before initialization, as read from the FMU after it (here
/// after an FMU state was restored behind the copy's back), and from the
/// start values again after a reset.
#[test]
fn array_elements_are_got_and_set_through_their_whole_arrays() {
    let (_dir, path) = gains();
    let fmu = Fmu::open(&path).unwrap();
    let vr = |name: &str| vrs_of(&fmu, &[name])[0];
    let mut g = fmu.instantiate_fmi3("g").unwrap();
    // before initialization, where the FMU may not be asked
    g.set_real(&[vr("k[2]")], &[5.0]).unwrap();
    g.set_boolean(&[vr("enable[3]")], &[true]).unwrap();
    g.enter_initialization_mode(0.0, None).unwrap();
    g.set_real(&[vr("A[2,3]")], &[7.0]).unwrap();
    g.set_integer(&[vr("offset[2]")], &[-5]).unwrap();
    let mut got = [0.0; 6];
    let names = ["k[1]", "k[2]", "time", "k[3]", "A[2,3]", "A[1,3]"];
    g.get_real(&vrs_of(&fmu, &names), &mut got).unwrap();
    assert_eq!(got, [1.0, 5.0, 0.0, 3.0, 7.0, 0.5]);
    g.exit_initialization_mode().unwrap();

    let h = 0.5;
    g.do_step_with(0.0, h, Rollback::Possible).unwrap();
    // y[i] = enable[i]·k[i]·u[i]·h, u = (0.5, -1, 2), k = (1, 5, 3)
    let names = ["total", "y[3]", "time", "z[2,3]", "y[1]", "z[1,1]", "yd[2]"];
    let mut got = [0.0; 7];
    g.get_real(&vrs_of(&fmu, &names), &mut got).unwrap();
    assert_eq!(got, [1.5, 3.0, h, 21.0, 0.25, 0.25, -5.0]);
    let mut counts = [0; 3];
    g.get_integer(
        &vrs_of(&fmu, &["count[2]", "offset[1]", "count[1]"]),
        &mut counts,
    )
    .unwrap();
    assert_eq!(counts, [-3, 10, 11]);
    let mut flags = [0; 4];
    let names = ["positive[3]", "positive[2]", "enable[1]", "positive[1]"];
    g.get_boolean_raw(&vrs_of(&fmu, &names), &mut flags)
        .unwrap();
    assert_eq!(flags, [1, 0, 1, 1]);

    // the FMU's u restored behind the copy: a set of u[2] keeps what
    // the FMU holds in u[1] and u[3]
    let u = vrs_of(&fmu, &["u[1]", "u[2]", "u[3]"]);
    g.set_real(&u, &[1.0, 2.0, 3.0]).unwrap();
    let saved = g.get_state().unwrap();
    g.set_real(&u, &[4.0, 5.0, 6.0]).unwrap();
    g.set_state(&saved).unwrap();
    g.set_real(&[u[1]], &[9.0]).unwrap();
    let mut now = [0.0; 3];
    g.get_real(&u, &mut now).unwrap();
    assert_eq!(now, [1.0, 9.0, 3.0]);

    // after a reset the FMU holds the start values again
    g.reset().unwrap();
    g.set_real(&[u[0]], &[8.0]).unwrap();
    g.enter_initialization_mode(0.0, None).unwrap();
    g.get_real(&u, &mut now).unwrap();
    assert_eq!(now, [8.0, -1.0, 2.0]);
    let mut k = [0.0; 3];
    g.get_real(&vrs_of(&fmu, &["k[1]", "k[2]", "k[3]"]), &mut k)
        .unwrap();
    assert_eq!(k, [1.0, 2.0, 3.0]);
}

/// `fmi3GetDirectionalDerivative` with elements among the knowns and the
/// unknowns (as the arrays, seeded and picked): equal to the central
/// differences of steps from one saved FMU state.
#[test]
fn directional_derivatives_of_array_elements_equal_differences_of_steps() {
    let (_dir, path) = gains();
    let fmu = Fmu::open(&path).unwrap();
    let mut g = stepping_gains(&fmu);
    let unknowns = vrs_of(
        &fmu,
        &["y[1]", "z[2,2]", "yd[2]", "total", "y[3]", "z[1,1]"],
    );
    let knowns = vrs_of(&fmu, &["u[1]", "u[2]"]);
    let seed = [1.0, 2.0];
    g.do_step_with(0.0, 0.5, Rollback::Possible).unwrap();
    let saved = g.get_state().unwrap();
    let (h, eps) = (0.2, 1e-3);
    let mut step_from_saved = |du: f64| {
        g.set_state(&saved).unwrap();
        g.set_real(&knowns, &[0.5 + du * seed[0], -1.0 + du * seed[1]])
            .unwrap();
        g.do_step_with(0.5, h, Rollback::Possible).unwrap();
        let mut out = vec![0.0; unknowns.len()];
        g.get_real(&unknowns, &mut out).unwrap();
        out
    };
    let (up, down) = (step_from_saved(eps), step_from_saved(-eps));
    step_from_saved(0.0);
    let mut d = vec![f64::NAN; unknowns.len()];
    g.get_directional_derivative(&unknowns, &knowns, &seed, &mut d)
        .unwrap();
    // the closed form: dy[1] = k[1]·h, dy[2] = k[2]·h·2, d yd[2] = k[2]·2,
    // d total = k[1] + k[2]·2, y[3] not seeded, z[1,1] = A[1,1]·dy[1]
    let exact = [h, 2.0 * h * 2.0, 4.0, 1.0 + 4.0, 0.0, h];
    for k in 0..unknowns.len() {
        let difference = (up[k] - down[k]) / (2.0 * eps);
        assert!(
            (d[k] - difference).abs() <= 1e-9 * difference.abs().max(1.0)
                && (d[k] - exact[k]).abs() <= 1e-12,
            "unknown {k}: {} vs difference {difference}, exact {}",
            d[k],
            exact[k]
        );
    }
}

/// What is misused is refused with a message that says what: an array
/// named without an index, an element past the end, a value an element
/// cannot hold, lengths that do not match.
#[test]
fn misused_arrays_are_refused_with_clear_errors() {
    let (_dir, path) = gains();
    let fmu = Fmu::open(&path).unwrap();
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_fricsim"))
            .args(["cosim", "--fmu"])
            .arg(format!("g={}", path.display()))
            .args(["--step", "0.1", "--stop", "1", "--out"])
            .arg(_dir.path().join("misuse.csv"))
            .args(args)
            .output()
            .unwrap();
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let e = run(&["--set", "g.k=2"]);
    assert!(
        e.contains("`g` has no variable `k`; `k` is an FMI 3.0 array of 3 elements, which are variables one by one: `k[1]` … `k[3]`"),
        "{e}"
    );
    let e = run(&["--set", "g.A[3,1]=2"]);
    assert!(e.contains("`g` has no variable `A[3,1]`"), "{e}");
    let e = run(&["--set", "g.offset[1]=2.5"]);
    assert!(
        e.contains("cannot set `g.offset[1]` to \"2.5\": not an Integer value"),
        "{e}"
    );
    let e = run(&["--connect", "g.yd->g.u[1]"]);
    assert!(
        e.contains("has no variable `yd`; `yd` is an FMI 3.0 array"),
        "{e}"
    );

    let mut g = stepping_gains(&fmu);
    let u = vrs_of(&fmu, &["u[1]", "u[2]"]);
    let e = g.get_real(&u, &mut [0.0]).unwrap_err();
    assert!(matches!(e, FmuError::LengthMismatch { .. }), "{e}");
    let e = g.set_real(&u, &[1.0]).unwrap_err();
    assert!(matches!(e, FmuError::LengthMismatch { .. }), "{e}");
    // a value the FMU refuses: its message, for the array
    let e = g.set_real(&u[..1], &[f64::NAN]).unwrap_err();
    assert!(
        e.to_string()
            .contains("fmi3SetFloat64: value reference 2 set to nan"),
        "{e}"
    );
}

/// A system of two Gains in an SSP file, connected element to element
/// (a 2-D one among them), with parameters set per element by name (a
/// Real, an Integer and a Boolean), run by `fricsim run`, records each
/// element in a column of its own (a 2-D name quoted in the CSV header)
/// and follows the closed form under the Jacobi and the Newton master.
#[test]
fn a_system_connects_and_sets_array_elements_by_name() {
    let (dir, path) = gains();
    let ssd = dir.path().join("gains.ssd");
    std::fs::write(
        &ssd,
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="gains"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssd:System name="gains">
    <ssd:Elements>
      <ssd:Component name="src" source="{fmu}">
        <ssd:Connectors>
          <ssd:Connector name="yd[2]" kind="output"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="z[2,3]" kind="output"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="src">
                <ssv:Parameters>
                  <ssv:Parameter name="k[2]"><ssv:Real value="3"/></ssv:Parameter>
                  <ssv:Parameter name="enable[3]"><ssv:Boolean value="true"/></ssv:Parameter>
                  <ssv:Parameter name="offset[2]"><ssv:Integer value="7"/></ssv:Parameter>
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
      </ssd:Component>
      <ssd:Component name="dst" source="{fmu}">
        <ssd:Connectors>
          <ssd:Connector name="u[1]" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="u[3]" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="A[1,1]" kind="parameter"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="dst">
                <ssv:Parameters>
                  <ssv:Parameter name="A[1,1]"><ssv:Real value="2"/></ssv:Parameter>
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="src" startConnector="yd[2]" endElement="dst" endConnector="u[1]"/>
      <ssd:Connection startElement="src" startConnector="z[2,3]" endElement="dst" endConnector="u[3]"/>
    </ssd:Connections>
  </ssd:System>
</ssd:SystemStructureDescription>
"#,
            fmu = path.display()
        ),
    )
    .unwrap();
    for master in ["jacobi", "newton"] {
        let out = dir.path().join(format!("{master}.csv"));
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_fricsim"))
            .arg("run")
            .arg(&ssd)
            .args(["--step", "0.1", "--stop", "1", "--master", master, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(run.status.success(), "{master}: {stderr}");
        let text = std::fs::read_to_string(&out).unwrap();
        let header = text.lines().next().unwrap();
        assert!(header.contains(r#","dst.z[1,1]","#), "{header}");
        let columns = header_fields(header);
        let rows: Vec<Vec<f64>> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 11, "{master}");
        let column = |name: &str| {
            let k = columns
                .iter()
                .position(|c| c == name)
                .unwrap_or_else(|| panic!("no {name} in {columns:?}"));
            rows.iter().map(|r| r[k]).collect::<Vec<f64>>()
        };
        for (i, row) in rows.iter().enumerate() {
            let t = row[0];
            let steps = i as f64;
            let expect = [
                // src: k = (1, 3, 3), every integrator on
                ("src.y[2]", -3.0 * t),
                ("src.y[3]", 6.0 * t),
                ("src.z[2,3]", -6.0 * t),
                ("src.count[2]", 7.0 + 2.0 * steps),
                // dst: u[1] = src.yd[2] = -3 from the start, A[1,1] = 2
                ("dst.y[1]", -3.0 * t),
                ("dst.z[1,1]", -6.0 * t),
                ("dst.count[2]", 20.0 + 2.0 * steps),
                ("dst.y[3]", 0.0),
            ];
            for (name, value) in expect {
                let got = column(name)[i];
                assert!(
                    (got - value).abs() <= 1e-12,
                    "{master}: {name} at t = {t}: {got} vs {value}"
                );
            }
        }
    }
}

/// The words of the first line of `text` that starts with `name`.
fn row_in<'a>(text: &'a str, name: &str) -> Vec<&'a str> {
    text.lines()
        .find(|l| l.trim_start().starts_with(&format!("{name} ")))
        .unwrap_or_else(|| panic!("no row {name} in\n{text}"))
        .split_whitespace()
        .collect()
}

/// The fields of a CSV header line, a quoted one unquoted (RFC 4180).
fn header_fields(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(String::new()),
            (c, _) => fields.last_mut().unwrap().push(c),
        }
    }
    fields
}

// ---- every FMI 3.0 type: Feedthrough (tests/c/fmi3/feedthrough.c) ------------

fn feedthrough() -> (TempDir, PathBuf) {
    let dir = TempDir::new().unwrap();
    let fmu = c_fmu3(
        "feedthrough.c",
        "feedthrough.xml",
        "Feedthrough",
        dir.path(),
    );
    (dir, fmu)
}

/// Each FMI 3.0 type is read and written through its own getter and
/// setter (Feedthrough refuses any other), as the core's kind that holds
/// it: the floats and the integers an `i32` cannot hold as Real, the
/// narrower integers and Enumeration as Integer; what goes in comes out.
#[test]
fn every_fmi3_type_is_fed_through_as_the_kind_that_holds_it() {
    use fricsim::fmu::model_description::Fmi3Type;
    let (_dir, path) = feedthrough();
    let fmu = Fmu::open(&path).unwrap();
    let d = fmu.description();
    for (name, t, kind) in [
        ("Float32_input", Fmi3Type::Float32, "Real"),
        ("UInt32_input", Fmi3Type::UInt32, "Real"),
        ("Int64_output", Fmi3Type::Int64, "Real"),
        ("UInt64_input", Fmi3Type::UInt64, "Real"),
        ("Int8_output", Fmi3Type::Int8, "Integer"),
        ("UInt16_input", Fmi3Type::UInt16, "Integer"),
        ("Enumeration_input", Fmi3Type::Enumeration, "Enumeration"),
        ("Float32_array_input[2]", Fmi3Type::Float32, "Real"),
    ] {
        let v = d.variable(name).unwrap();
        assert_eq!((v.fmi3_type, v.kind.type_name()), (Some(t), kind), "{name}");
        assert_eq!(t.kind_name(), kind);
    }
    let vr = |names: &[&str]| vrs_of(&fmu, names);
    let mut f = fmu.instantiate_fmi3("f").unwrap();
    // set before initialization, and in it
    f.set_real(
        &vr(&[
            "UInt32_input",
            "Float32_input",
            "Int64_input",
            "Float64_input",
        ]),
        &[4e9, 0.1, -(2f64.powi(53)), 0.2],
    )
    .unwrap();
    f.enter_initialization_mode(0.0, None).unwrap();
    f.set_integer(
        &vr(&[
            "Int8_input",
            "Enumeration_input",
            "UInt16_input",
            "Int32_input",
        ]),
        &[-5, 3, 65535, 7],
    )
    .unwrap();
    f.set_real(
        &vr(&["UInt64_input", "Float32_array_input[2]"]),
        &[2f64.powi(53), 7.25],
    )
    .unwrap();
    f.set_boolean(&vr(&["Boolean_input"]), &[false]).unwrap();
    f.exit_initialization_mode().unwrap();
    f.do_step_with(0.0, 0.25, Rollback::Never).unwrap();
    let names = [
        "Float32_output",
        "UInt32_output",
        "Int64_output",
        "UInt64_output",
        "Float64_output",
        "Float32_array_output[1]",
        "Float32_array_output[2]",
    ];
    let mut reals = [0.0; 7];
    f.get_real(&vr(&names), &mut reals).unwrap();
    assert_eq!(
        reals,
        [
            f64::from(0.1f32),
            4e9,
            -(2f64.powi(53)),
            2f64.powi(53),
            0.2,
            1.5,
            7.25
        ]
    );
    let names = [
        "Int8_output",
        "UInt8_output",
        "Int16_output",
        "UInt16_output",
        "Int32_output",
        "Enumeration_output",
    ];
    let mut integers = [0; 6];
    f.get_integer(&vr(&names), &mut integers).unwrap();
    assert_eq!(integers, [-5, 255, -32768, 65535, 7, 3]);
    let mut flag = [true];
    f.get_boolean(&vr(&["Boolean_output"]), &mut flag).unwrap();
    assert_eq!(flag, [false]);

    // a value the type cannot hold is refused, naming the variable, the
    // value and the type's range, before anything is set
    let e = f
        .set_real(&vr(&["Float64_input", "UInt32_input"]), &[9.0, 3.5])
        .unwrap_err();
    assert!(matches!(e, FmuError::ValueConversion { .. }), "{e}");
    assert_message(
        &e,
        &[
            "fmi3SetUInt32 for instance \"f\"",
            "variable \"UInt32_input\" (UInt32) cannot be set to 3.5",
            "whole numbers from 0 to 4294967295",
        ],
    );
    let mut x = [0.0];
    f.get_real(&vr(&["Float64_output"]), &mut x).unwrap();
    assert_eq!(x, [0.2], "nothing was set");
    let e = f.set_integer(&vr(&["UInt8_input"]), &[300]).unwrap_err();
    assert_message(
        &e,
        &[
            "variable \"UInt8_input\" (UInt8) cannot be set to 300",
            "whole numbers from 0 to 255",
        ],
    );
    let e = f.set_real(&vr(&["Float32_input"]), &[1e39]).unwrap_err();
    assert_message(&e, &["cannot be set to 1e39", "up to ±3.4028235e38"]);
    let e = f.set_real(&vr(&["Int64_input"]), &[1e19]).unwrap_err();
    assert_message(&e, &["(Int64) cannot be set to 1e19"]);
}

/// A 64-bit value no `f64` holds (the UInt64 output 2⁵³ + 1, from
/// Feedthrough with FEEDTHROUGH_ODD_UINT64 set) stops the run with a
/// message naming the variable and the value, rather than recording a
/// rounded number.
#[test]
fn a_64_bit_value_an_f64_cannot_hold_stops_the_run_naming_it() {
    let (dir, path) = feedthrough();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .args(["cosim", "--fmu"])
        .arg(format!("f={}", path.display()))
        .args(["--step", "0.25", "--stop", "1", "--out"])
        .arg(dir.path().join("odd.csv"))
        .env("FEEDTHROUGH_ODD_UINT64", "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "fmi3GetUInt64 for instance \"f\": variable \"UInt64_output\" (UInt64) has the value \
             9007199254740993, which fricsim cannot hold exactly"
        ),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// A binary that leaves out the getter and setter of a type its model
/// description has variables of (SpringMass built without them, with a
/// UInt8 parameter added to its description) is refused when it is
/// loaded, naming the functions; without such variables it loads.
#[test]
fn a_binary_without_the_functions_of_its_types_is_refused_when_loaded() {
    let dir = TempDir::new().unwrap();
    let source = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/c/fmi3");
    let xml = std::fs::read_to_string(source.join("spring_mass.xml")).unwrap();
    let build = |name: &str, description: &str| {
        let root = dir.path().join(name);
        let binaries = root.join("binaries/x86_64-linux");
        std::fs::create_dir_all(&binaries).unwrap();
        std::fs::write(root.join("modelDescription.xml"), description).unwrap();
        crate::common::compile_shared(
            &source.join("spring_mass.c"),
            &binaries.join("SpringMass.so"),
            &["-DOFFERS_EVERY_TYPE"],
        );
        let fmu = dir.path().join(format!("{name}.fmu"));
        crate::common::zip_dir(&root, &fmu);
        fmu
    };
    assert!(Fmu::open(build("plain", &xml)).is_ok());
    let with_uint8 = xml.replace(
        "</ModelVariables>",
        r#"<UInt8 name="n" valueReference="20" causality="parameter" variability="fixed" start="1"/></ModelVariables>"#,
    );
    let e = Fmu::open(build("uint8", &with_uint8)).unwrap_err();
    assert_message(
        &e,
        &[
            "modelDescription.xml declares variables of type UInt8",
            "the binary does not export fmi3GetUInt8, fmi3SetUInt8",
        ],
    );
}

/// Our LuGre as FMI 3.0 (`dist/fmi3/`, whose tables `x_table`,
/// `scale_pos`, `scale_neg` are arrays of 32) takes its table elements by
/// the names of the FMI 2.0 LuGre (`x_table[2]`, each a scalar there) and
/// runs the position-dependent law with them to the same bits.
#[test]
fn our_fmi3_lugre_takes_table_elements_by_the_fmi2_names() {
    use fricsim::system::ParameterValue;
    let dist = crate::common::repository().join("dist");
    let parameters: Vec<(String, ParameterValue)> = [
        ("l.position_dependent", 1.0),
        ("l.n_table", 3.0),
        ("l.x_table[2]", 0.05),
        ("l.x_table[3]", 0.2),
        ("l.scale_pos[2]", 3.0),
        ("l.scale_pos[3]", 0.5),
        ("l.v", 0.01),
        ("l.x", 0.07),
    ]
    .iter()
    .map(|(p, x)| (p.to_string(), ParameterValue::Number(*x)))
    .collect();
    let mut runs = Vec::new();
    for fmu in [dist.join("LuGre.fmu"), dist.join("fmi3/LuGre.fmu")] {
        let fmus = vec![("l".to_string(), Fmu::open(&fmu).unwrap())];
        let fmi3 = fmus[0].1.description().is_fmi3();
        let mut system = System::from_fmus(fmus, &parameters, &[], 0.0).unwrap();
        let run = simulate(&mut system, by_name("jacobi").unwrap().as_mut(), 1e-3, 0.2).unwrap();
        assert!(run.error.is_none(), "{:?}", run.error);
        runs.push((fmi3, columns(&run, &["l.F", "l.z"])));
    }
    assert_eq!((runs[0].0, runs[1].0), (false, true));
    assert_eq!(runs[1].1, runs[0].1, "FMI 3.0 differs from FMI 2.0");
    // the table took: at x = 0.07 the scale is 3 + (0.5 - 3)·0.02/0.15
    let f = *runs[1].1[0].last().unwrap();
    let scale = 3.0 + (0.5 - 3.0) * 0.02 / 0.15;
    assert!((f - scale).abs() < 0.01 * scale, "F = {f}, scale {scale}");
}

/// An SSP connector names the SSP type of an FMI 3.0 variable
/// (`ssc:Real` for Float32 and Float64, `ssc:Integer` for every integer
/// width), not the core's kind that holds it: an `Int64` held as a Real
/// is refused as `ssc:Real` and accepted as `ssc:Integer`, and a
/// `Float32` is a `ssc:Real`.
#[test]
fn ssp_connectors_name_the_fmi3_type_class_not_the_holding_kind() {
    let (dir, path) = feedthrough();
    let check = |connectors: &str| {
        let ssd = dir.path().join("types.ssd");
        std::fs::write(
            &ssd,
            format!(
                r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="types"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
  <ssd:System name="types">
    <ssd:Elements>
      <ssd:Component name="ft" source="{fmu}">
        <ssd:Connectors>
{connectors}
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
  </ssd:System>
</ssd:SystemStructureDescription>
"#,
                fmu = path.display()
            ),
        )
        .unwrap();
        fricsim::ssp::SystemFile::open(&ssd)
            .map_err(|e| e.to_string())
            .and_then(|f| f.check().map(|_| ()).map_err(|e| e.to_string()))
    };
    let connector = |name: &str, kind: &str, ty: &str| {
        format!(
            r#"          <ssd:Connector name="{name}" kind="{kind}"><ssc:{ty}/></ssd:Connector>"#
        )
    };
    for (name, kind, right, wrong) in [
        ("Int64_output", "output", "Integer", "Real"),
        ("UInt32_input", "input", "Integer", "Real"),
        ("Int8_output", "output", "Integer", "Real"),
        ("Float32_input", "input", "Real", "Integer"),
        ("Float64_output", "output", "Real", "Integer"),
    ] {
        assert_eq!(
            check(&connector(name, kind, right)),
            Ok(()),
            "{name} as ssc:{right}"
        );
        let message = check(&connector(name, kind, wrong)).unwrap_err();
        let ty = name.split('_').next().unwrap();
        assert!(
            message.contains(&format!("the connector is ssc:{wrong}, but `{name}`"))
                && message.ends_with(&format!("is {ty}")),
            "{name} as ssc:{wrong}: {message}"
        );
    }
}
