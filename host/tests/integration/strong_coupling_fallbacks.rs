//! Strong coupling with FMUs that lack what it uses best: an FMU without
//! directional derivatives runs by finite differences (rollback and a
//! perturbed step), and the convergence report says so; an FMU without
//! `canGetAndSetFMUstate` (nothing to roll back to) is refused at the first
//! step, before anything is stepped, naming the instance and the
//! capability; a step that does not converge stops the run with the
//! residual, and is never accepted.
//!
//! The FMUs without a capability are the repository's, repackaged in a
//! temporary folder with the capability turned off in modelDescription.xml
//! (the host then does not even resolve the functions), and BeltOscillator,
//! a hand-written C FMU that declares neither (tests/c/belt_oscillator).

use crate::belt;
use crate::common;

use fricsim::master::strong::{JacobianSource, StrongCoupling, Update};
use fricsim::master::{by_name, jacobi::Jacobi, simulate, MasterAlgorithm, Run};
use fricsim::system::System;
use fricsim::FmuError;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::Command;
use tempfile::TempDir;

fn dist(name: &str) -> PathBuf {
    let p = common::repository().join("dist").join(name);
    assert!(p.exists(), "{} is missing: run ./build-fmu.sh", p.display());
    p
}

/// `dist/<name>` copied into `dir` with `attribute="true"` turned into
/// `attribute="false"` in its model description (which must declare it).
fn without(dir: &Path, name: &str, attributes: &[&str]) -> PathBuf {
    let from = dist(name);
    let mut archive = zip::ZipArchive::new(std::fs::File::open(&from).unwrap()).unwrap();
    let out = dir.join(name);
    let mut zip = zip::ZipWriter::new(std::fs::File::create(&out).unwrap());
    for i in 0..archive.len() {
        let mut entry = archive.by_index(i).unwrap();
        let entry_name = entry.name().unwrap().to_string();
        let mut bytes = Vec::new();
        entry.read_to_end(&mut bytes).unwrap();
        if entry_name == "modelDescription.xml" {
            let mut text = String::from_utf8(bytes).unwrap();
            for a in attributes {
                let on = format!("{a}=\"true\"");
                assert!(text.contains(&on), "{name} does not declare {on}");
                text = text.replace(&on, &format!("{a}=\"false\""));
            }
            bytes = text.into_bytes();
        }
        if entry.is_dir() {
            zip.add_directory(entry_name, zip::write::SimpleFileOptions::default())
                .unwrap();
        } else {
            zip.start_file(entry_name, zip::write::SimpleFileOptions::default())
                .unwrap();
            zip.write_all(&bytes).unwrap();
        }
    }
    zip.finish().unwrap();
    out
}

/// The 1995 stick-slip benchmark: Rig1D and a LuGre FMU (defaults are the
/// benchmark's), `rig.v → friction.v`, `friction.F → rig.F`.
fn stick_slip(lugre: &Path) -> System {
    let rig = dist("Rig1D.fmu");
    System::build(
        &[
            ("rig".to_string(), rig.as_path()),
            ("friction".to_string(), lugre),
        ],
        &[],
        &[
            ("rig.v".to_string(), "friction.v".to_string()),
            ("friction.F".to_string(), "rig.F".to_string()),
        ],
    )
    .unwrap()
}

fn column(run: &Run, name: &str) -> Vec<f64> {
    let k = run.columns.iter().position(|c| c == name).unwrap();
    run.rows.iter().map(|r| r[k]).collect()
}

/// Largest difference between two runs' column, relative to its largest
/// magnitude.
fn relative_difference(a: &Run, b: &Run, name: &str) -> f64 {
    let (x, y) = (column(a, name), column(b, name));
    assert_eq!(x.len(), y.len(), "{name}: runs of different length");
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = x
        .iter()
        .zip(&y)
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    worst / scale
}

#[test]
fn newton_differences_a_lugre_without_directional_derivatives_and_says_so() {
    let dir = TempDir::new().unwrap();
    let lugre = without(dir.path(), "LuGre.fmu", &["providesDirectionalDerivative"]);

    // The host sees the capability off: no fmi2GetDirectionalDerivative.
    let mut plain = stick_slip(&lugre);
    let friction = &mut plain.components[1];
    assert!(
        !friction
            .fmu
            .description()
            .co_simulation
            .provides_directional_derivative
    );
    let e = friction
        .instance
        .get_directional_derivative(&[0], &[0], &[1.0], &mut [0.0])
        .unwrap_err();
    assert!(matches!(e, FmuError::NotSupported { .. }), "{e}");

    // `newton` (automatic Jacobian source) runs by finite differences.
    let mut master = by_name("newton").unwrap();
    let fd = simulate(&mut stick_slip(&lugre), master.as_mut(), 1e-3, 9.0).unwrap();
    assert!(fd.error.is_none(), "{:?}", fd.error);
    let report = master.report().unwrap();
    common::assert_message(
        &report,
        &[
            "Jacobian of friction: finite differences (rollback): the FMU does not provide directional derivatives (providesDirectionalDerivative=\"false\")",
            // the rig still has them, checked once against differences
            "Jacobian of rig: directional derivatives (checked against finite differences)",
        ],
    );
    let count_before = |what: &str| -> usize {
        report
            .split(what)
            .next()
            .and_then(|s| s.rsplit(' ').next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("no count before `{what}` in {report}"))
    };
    let (jacobians, extra) = (count_before(" Jacobians"), count_before(" extra steps"));
    // one extra step per Jacobian for the friction's one input (the rig's
    // single check adds one): more than the check alone
    assert!(
        jacobians > 10 && extra >= jacobians,
        "{jacobians} Jacobians, {extra} extra steps: {report}"
    );

    // Directional derivatives from the original FMUs give the same run.
    let mut dd = StrongCoupling::new(Update::Newton, JacobianSource::Directional);
    let reference = simulate(&mut stick_slip(&dist("LuGre.fmu")), &mut dd, 1e-3, 9.0).unwrap();
    assert_eq!(dd.convergence().difference_steps, 0);
    assert!(reference.error.is_none(), "{:?}", reference.error);
    for name in ["friction.F", "rig.v", "rig.x"] {
        let d = relative_difference(&fd, &reference, name);
        assert!(d <= 1e-6, "{name}: runs differ by {d:e} of the scale");
    }
    // and the runs did go through stick and slip (peak friction of the
    // benchmark near 1.4766 N, first slip at 7.54 s)
    let peak = column(&fd, "friction.F").into_iter().fold(0.0f64, f64::max);
    assert!((peak / 1.4766 - 1.0).abs() < 5e-3, "peak friction {peak}");
}

#[test]
fn directional_derivatives_demanded_of_an_fmu_without_them_are_refused_by_name() {
    let dir = TempDir::new().unwrap();
    let lugre = without(dir.path(), "LuGre.fmu", &["providesDirectionalDerivative"]);
    let mut system = stick_slip(&lugre);
    let mut master = StrongCoupling::new(Update::Newton, JacobianSource::Directional);
    let run = simulate(&mut system, &mut master, 1e-3, 1.0).unwrap();
    let error = run.error.expect("refused");
    common::assert_message(
        &error,
        &[
            "at t = 0:",
            "instance \"friction\" (model LuGre)",
            "providesDirectionalDerivative=\"true\"",
        ],
    );
    assert_eq!(run.rows.len(), 1);
}

/// Nothing was stepped: every instance is still at t = 0 (the time our
/// FMUs and BeltOscillator report as `fmi2LastSuccessfulTime`, which FMI
/// 2.0 lets a master ask after `fmi2Terminate`, where the run left them)
/// and the outputs are those of the initial row.
fn assert_nothing_stepped(system: &mut System, run: &Run) {
    system.sample().unwrap();
    let now = system.recorded().last().unwrap();
    assert_eq!(now, &run.rows[0], "outputs changed: something was stepped");
    for c in &mut system.components {
        let reached = c
            .instance
            .fmi2()
            .expect("FMI 2.0")
            .last_successful_time()
            .unwrap_or_else(|e| panic!("{}: {e}", c.name));
        assert_eq!(reached, 0.0, "{} is no longer at t = 0", c.name);
    }
}

#[test]
fn newton_refuses_belt_oscillator_without_fmu_state_before_stepping_naming_it() {
    let dir = TempDir::new().unwrap();
    let belt = belt::build_fmu(dir.path());
    let lugre = dist("LuGre.fmu");
    let system = || {
        System::build(
            &[
                ("belt".to_string(), belt.as_path()),
                ("friction".to_string(), lugre.as_path()),
            ],
            &[("belt.v0".to_string(), 0.0)],
            &[
                ("belt.v".to_string(), "friction.v".to_string()),
                ("friction.F".to_string(), "belt.F".to_string()),
            ],
        )
        .unwrap()
    };
    for name in ["newton", "newton-interpolated", "fixed-point", "adaptive"] {
        let mut s = system();
        let mut master = by_name(name).unwrap();
        let run = simulate(&mut s, master.as_mut(), 1e-3, 0.1).unwrap();
        let error = run.error.clone().expect("refused");
        common::assert_message(
            &error,
            &[
                "at t = 0:",
                "strong coupling",
                "cannot run instance \"belt\" (model BeltOscillator)",
                "canGetAndSetFMUstate=\"true\"",
                "fmi2GetFMUstate",
            ],
        );
        assert_eq!(run.rows.len(), 1, "{name}: only the initial point");
        assert_nothing_stepped(&mut s, &run);
    }
    // A master that needs no rollback runs the same system.
    let run = simulate(&mut system(), &mut Jacobi::default(), 1e-3, 0.1).unwrap();
    assert!(run.error.is_none(), "{:?}", run.error);
    assert_eq!(run.rows.len(), 101);
}

#[test]
fn newton_refuses_a_lugre_without_fmu_state_even_when_it_comes_second() {
    // The rig (first) could save its state; the check still comes before
    // any state is taken or any step made, and names the second instance.
    let dir = TempDir::new().unwrap();
    let lugre = without(
        dir.path(),
        "LuGre.fmu",
        &["canGetAndSetFMUstate", "canSerializeFMUstate"],
    );
    let mut system = stick_slip(&lugre);
    let mut master = by_name("newton").unwrap();
    let run = simulate(&mut system, master.as_mut(), 1e-3, 0.1).unwrap();
    let error = run.error.clone().expect("refused");
    common::assert_message(
        &error,
        &[
            "cannot run instance \"friction\" (model LuGre)",
            "canGetAndSetFMUstate=\"true\"",
        ],
    );
    assert!(!error.contains("\"rig\""), "{error}");
    assert_nothing_stepped(&mut system, &run);
}

#[test]
fn fricsim_run_says_which_capability_is_missing_and_exits_nonzero() {
    // The same through the command line: a system file whose LuGre has no
    // FMU state, run with --master newton.
    let dir = TempDir::new().unwrap();
    let lugre = without(
        dir.path(),
        "LuGre.fmu",
        &["canGetAndSetFMUstate", "canSerializeFMUstate"],
    );
    std::fs::copy(dist("Rig1D.fmu"), dir.path().join("Rig1D.fmu")).unwrap();
    let example = common::repository().join("examples");
    std::fs::copy(
        example.join("lugre_1995.ssv"),
        dir.path().join("lugre_1995.ssv"),
    )
    .unwrap();
    let ssd = std::fs::read_to_string(example.join("stick_slip.ssd"))
        .unwrap()
        .replace("../dist/", "");
    std::fs::write(dir.path().join("system.ssd"), ssd).unwrap();
    assert!(lugre.starts_with(dir.path()));
    let out = dir.path().join("result.csv");
    let stderr = failing_run(
        &dir.path().join("system.ssd"),
        &["--master", "newton", "--step", "1e-3", "--stop", "0.1"],
        &out,
    );
    common::assert_message(
        &stderr,
        &[
            "INCOMPLETE",
            "cannot run instance \"friction\" (model LuGre)",
            "canGetAndSetFMUstate=\"true\"",
        ],
    );
    let csv = std::fs::read_to_string(&out).unwrap();
    assert_eq!(
        csv.lines().filter(|l| !l.starts_with('#')).count(),
        2,
        "{csv}"
    );
}

#[test]
fn adaptive_refuses_an_fmu_with_fixed_communication_steps_newton_runs_it() {
    let dir = TempDir::new().unwrap();
    let lugre = without(
        dir.path(),
        "LuGre.fmu",
        &["canHandleVariableCommunicationStepSize"],
    );
    let mut system = stick_slip(&lugre);
    let mut adaptive = by_name("adaptive").unwrap();
    let run = simulate(&mut system, adaptive.as_mut(), 1e-2, 1.0).unwrap();
    common::assert_message(
        &run.error.clone().expect("refused"),
        &[
            "cannot run instance \"friction\" (model LuGre)",
            "canHandleVariableCommunicationStepSize=\"true\"",
        ],
    );
    assert_nothing_stepped(&mut system, &run);
    // newton keeps the step fixed: it runs (without step halving)
    let mut newton = by_name("newton").unwrap();
    let run = simulate(&mut stick_slip(&lugre), newton.as_mut(), 1e-3, 1.0).unwrap();
    assert!(run.error.is_none(), "{:?}", run.error);
}

/// The number after `key` in `text` (e.g. "still differs by 1.5e-3").
fn number_after(text: &str, key: &str) -> f64 {
    let rest = text
        .split(key)
        .nth(1)
        .unwrap_or_else(|| panic!("{key:?} not in {text}"));
    let token: String = rest
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | '-' | '+'))
        .collect();
    token
        .parse()
        .unwrap_or_else(|_| panic!("no number after {key:?} in {text}"))
}

#[test]
fn a_step_that_does_not_converge_stops_the_run_with_its_residual() {
    // Three iterations and no step halving: as the first slip of the
    // benchmark nears (7.3-7.6 s, h = 1e-2 s) Newton needs more.
    let mut system = stick_slip(&dist("LuGre.fmu"));
    let mut master = StrongCoupling::new(Update::Newton, JacobianSource::Auto);
    master.max_iterations = 3;
    master.max_splits = 0;
    let run = simulate(&mut system, &mut master, 1e-2, 20.0).unwrap();
    let error = run.error.clone().expect("a step must fail to converge");
    common::assert_message(
        &error,
        &[
            "strong coupling did not converge",
            "(step ",
            "after 3 iterations",
            "still differs by",
            "tolerance",
            "scaled residual norm",
            "the step is not accepted",
        ],
    );
    assert!(
        error.contains("friction.F -> rig.F") || error.contains("rig.v -> friction.v"),
        "{error}"
    );
    // the macro step, t_k+1 − t_k of the 1e-2 s grid
    let step = number_after(&error, "(step");
    assert!((step - 1e-2).abs() < 1e-12, "{error}");
    // The residual reported is above its tolerance, and the norm above 1.
    let mismatch = number_after(&error, "still differs by");
    let tolerance = number_after(&error, "tolerance");
    let norm = number_after(&error, "scaled residual norm");
    assert!(mismatch > tolerance && tolerance > 0.0, "{error}");
    assert!(norm > 1.0, "{error}");
    // The run stopped there: the failed step is not in the result, and the
    // rows kept end at the communication point the step started from.
    let failed_at = number_after(&error, "did not converge at t =");
    let last = *run.time.last().unwrap();
    assert!(run.rows.len() < 2001, "the run went on after the failure");
    assert!((last - failed_at).abs() < 1e-9, "{last} vs {error}");
    assert!(last > 1.0, "failed too early to be the slip: {error}");
    // Every step accepted before met the tolerance.
    assert!(master.convergence().worst_accepted <= 1.0);
}

#[test]
fn step_halving_rescues_what_three_iterations_cannot_and_says_so() {
    // The same limit with halving allowed: the run completes, the report
    // counts the rejected (halved) steps, and every accepted one converged.
    let mut system = stick_slip(&dist("LuGre.fmu"));
    let mut master = StrongCoupling::new(Update::Newton, JacobianSource::Auto);
    master.max_iterations = 3;
    let run = simulate(&mut system, &mut master, 1e-2, 20.0).unwrap();
    assert!(run.error.is_none(), "{:?}", run.error);
    let report = master.convergence();
    assert!(report.rejected > 0, "{report:?}");
    assert!(report.worst_accepted <= 1.0);
    assert!(report.max_iterations <= 3);
    assert!(master.report().unwrap().contains("rejected and halved"));
}

#[test]
fn fixed_point_divergence_through_the_command_line_reports_the_residual() {
    let dir = TempDir::new().unwrap();
    let out = dir.path().join("result.csv");
    let stderr = failing_run(
        &common::repository().join("examples/piezo_push.ssd"),
        &["--master", "fixed-point", "--stop", "1"],
        &out,
    );
    common::assert_message(
        &stderr,
        &[
            "INCOMPLETE",
            "did not converge",
            "still differs by",
            "tolerance",
        ],
    );
    let csv = std::fs::read_to_string(&out).unwrap();
    assert!(csv.contains("# INCOMPLETE"), "{csv}");
}

#[test]
fn interpolated_inputs_are_differenced_and_the_report_says_why() {
    let mut master = by_name("newton-interpolated").unwrap();
    assert_eq!(
        master.name(),
        "strong coupling (Newton, interpolated inputs)"
    );
    let run = simulate(
        &mut stick_slip(&dist("LuGre.fmu")),
        master.as_mut(),
        1e-3,
        1.0,
    )
    .unwrap();
    assert!(run.error.is_none(), "{:?}", run.error);
    common::assert_message(
        &master.report().unwrap(),
        &["Jacobian of friction: finite differences (rollback): its inputs ramp over the step"],
    );
}

/// `fricsim run SYSTEM ARGS --out OUT`, which must exit with status 1;
/// its standard error.
fn failing_run(system: &Path, args: &[&str], out: &Path) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("run")
        .arg(system)
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    stderr
}
