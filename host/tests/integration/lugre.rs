//! End to end against the repository's `dist/LuGre.fmu` (built with
//! `build-fmu.sh` if missing): steady state, state save/restore, NaN input,
//! derivatives, and `fricsim info`.

use crate::common;

use fricsim::fmu::{Fmu, Instance, Status};
use fricsim::FmuError;

/// Communication step and number of steps: 1 s at 1 ms.
const H: f64 = 1e-3;
const STEPS: u32 = 1000;

struct Lugre {
    fmu: Fmu,
    v: u32,
    f: u32,
}

fn lugre() -> Lugre {
    let fmu = Fmu::open(common::lugre_fmu()).unwrap();
    let v = fmu.variable("v").unwrap().value_reference;
    let f = fmu.variable("F").unwrap().value_reference;
    Lugre { fmu, v, f }
}

fn initialized(fmu: &Fmu, name: &str) -> Instance {
    let mut i = fmu.instantiate(name).unwrap();
    i.setup_experiment(0.0, None).unwrap();
    i.enter_initialization_mode().unwrap();
    i.exit_initialization_mode().unwrap();
    i
}

/// Steps `n` from step `first` (t = first·h, counted not summed) with
/// v(t) = `velocity(t)`, returning F after each step.
fn run(l: &Lugre, i: &mut Instance, first: u32, n: u32, velocity: impl Fn(f64) -> f64) -> Vec<f64> {
    let mut forces = Vec::with_capacity(n as usize);
    let mut f = [0.0];
    for k in first..first + n {
        let t = k as f64 * H;
        i.set_real(&[l.v], &[velocity(t)]).unwrap();
        assert_eq!(i.do_step(t, H).unwrap(), Status::Ok);
        i.get_real(&[l.f], &mut f).unwrap();
        forces.push(f[0]);
    }
    forces
}

/// LuGre steady state (Canudas de Wit et al. 1995, eq. 9–12 of Sun et al. 2016):
/// Fss(v) = Fc + (Fs − Fc)·exp(−(v/vs)²) + σ2·v; at v = vs = 1e-3 with the
/// default parameters Fc = 1, Fs = 1.5, σ2 = 0.4.
#[test]
fn the_force_reaches_the_steady_state() {
    let l = lugre();
    let d = l.fmu.description();
    let start = |name: &str| d.variable(name).unwrap().kind.start_text().unwrap();
    assert_eq!(
        (start("Fc"), start("Fs"), start("sigma2"), start("vs")),
        ("1.0".into(), "1.5".into(), "0.4".into(), "0.001".into())
    );

    let mut i = initialized(&l.fmu, "lugre");
    let forces = run(&l, &mut i, 0, STEPS, |_| 1e-3);
    let expected = 1.0 + (1.5 - 1.0) * (-1.0f64).exp() + 0.4 * 1e-3;
    let last = *forces.last().unwrap();
    assert!(
        ((last - expected) / expected).abs() < 1e-6,
        "F = {last}, Fss = {expected}"
    );
    // It approaches: the first steps are far from it.
    assert!((forces[0] - expected).abs() > 0.1, "F(h) = {}", forces[0]);
    i.terminate().unwrap();
}

#[test]
fn get_and_set_state_reproduce_a_continuation_bit_for_bit() {
    let l = lugre();
    let velocity = |t: f64| 2e-3 * (2.0 * std::f64::consts::PI * 3.0 * t).sin();
    let mut i = initialized(&l.fmu, "lugre");
    run(&l, &mut i, 0, 300, velocity);
    let state = i.get_state().unwrap();
    let first = run(&l, &mut i, 300, 300, velocity);
    i.set_state(&state).unwrap();
    let again = run(&l, &mut i, 300, 300, velocity);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&first), bits(&again));

    // Through bytes, into another instance.
    let bytes = i.serialize_state(&state).unwrap();
    assert!(!bytes.is_empty());
    let mut other = initialized(&l.fmu, "other");
    let restored = other.deserialize_state(&bytes).unwrap();
    other.set_state(&restored).unwrap();
    let elsewhere = run(&l, &mut other, 300, 300, velocity);
    assert_eq!(bits(&first), bits(&elsewhere));

    // A state belongs to its instance.
    let e = other.set_state(&state).unwrap_err();
    assert!(matches!(e, FmuError::ForeignState { .. }), "{e}");
    i.free_state(state).unwrap();
    other.free_state(restored).unwrap();

    // update_state reuses a state.
    let mut s = i.get_state().unwrap();
    run(&l, &mut i, 600, 10, velocity);
    i.update_state(&mut s).unwrap();
    let a = run(&l, &mut i, 610, 10, velocity);
    i.set_state(&s).unwrap();
    assert_eq!(bits(&a), bits(&run(&l, &mut i, 610, 10, velocity)));
}

#[test]
fn a_nan_input_is_an_error_naming_the_variable() {
    let l = lugre();
    let mut i = initialized(&l.fmu, "lugre");
    let e = i.set_real(&[l.v], &[f64::NAN]).unwrap_err();
    let FmuError::Call {
        function,
        instance,
        status,
        messages,
    } = &e
    else {
        panic!("{e}")
    };
    assert_eq!(
        (*function, instance.as_str(), *status),
        ("fmi2SetReal", "lugre", Status::Error)
    );
    // The FMU's log message names the variable.
    assert!(
        messages.iter().any(|m| m.contains("v (value reference")),
        "{messages:?}"
    );
    assert!(
        e.to_string()
            .contains("v (value reference 0) must be finite but was NaN"),
        "{e}"
    );
    assert!(!l.fmu.log().messages_of("lugre").is_empty());
    // The refused value changed nothing.
    run(&l, &mut i, 0, 10, |_| 1e-3);
}

#[test]
fn derivatives_agree_with_finite_differences() {
    let l = lugre();
    let mut i = initialized(&l.fmu, "lugre");
    run(&l, &mut i, 0, 50, |_| 1e-3);
    let v0 = 1e-3;
    let dv = 1e-9;
    let force_at = |i: &mut Instance, v: f64| {
        i.set_real(&[l.v], &[v]).unwrap();
        let mut f = [0.0];
        i.get_real(&[l.f], &mut f).unwrap();
        f[0]
    };
    let fd = (force_at(&mut i, v0 + dv) - force_at(&mut i, v0 - dv)) / (2.0 * dv);
    force_at(&mut i, v0);
    let mut dfdv = [0.0];
    i.get_directional_derivative(&[l.f], &[l.v], &[1.0], &mut dfdv)
        .unwrap();
    assert!(
        ((dfdv[0] - fd) / fd).abs() < 1e-4,
        "dF/dv = {}, finite difference {fd}",
        dfdv[0]
    );

    i.set_real_input_derivatives(&[l.v], &[1], &[0.0]).unwrap();
    let mut dfdt = [f64::NAN];
    i.get_real_output_derivatives(&[l.f], &[1], &mut dfdt)
        .unwrap();
    assert!(dfdt[0].is_finite());
}

#[test]
fn fricsim_info_lists_the_variables() {
    let fmu = common::lugre_fmu();
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("info")
        .arg(&fmu)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let stdout = String::from_utf8(output.stdout).unwrap();
    for expected in [
        "Model Name         LuGre",
        "FMI Version        2.0",
        "canGetAndSetFMUstate",
        "Step Size          0.001",
    ] {
        assert!(
            stdout.contains(expected),
            "missing {expected:?} in\n{stdout}"
        );
    }
    let sigma0 = stdout
        .lines()
        .find(|l| l.split_whitespace().next() == Some("sigma0"))
        .expect("a line for sigma0");
    let columns: Vec<&str> = sigma0.split_whitespace().collect();
    assert_eq!(
        &columns[..6],
        ["sigma0", "parameter", "fixed", "Real", "100000.0", "N/m"]
    );
}

#[test]
fn fricsim_reports_errors_without_panicking() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.fmu");
    std::fs::write(&bad, b"not a zip").unwrap();
    for path in [bad.clone(), dir.path().join("missing.fmu")] {
        let output = std::process::Command::new(env!("CARGO_BIN_EXE_fricsim"))
            .arg("info")
            .arg(&path)
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(1));
        let stderr = String::from_utf8(output.stderr).unwrap();
        assert!(
            stderr.starts_with("fricsim: ") && stderr.contains(path.to_str().unwrap()),
            "{stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}
