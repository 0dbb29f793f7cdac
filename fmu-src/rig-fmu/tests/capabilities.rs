//! The rig FMUs through the C ABI: directional derivatives of the outputs
//! with respect to the friction input against finite differences by state
//! rollback (and Rig1D's, after a held step in the plain mode, against the
//! rig's closed form), FMU states that reproduce a run bit for bit (in memory and
//! serialized, in a fresh instance), output derivatives, the EMPS loop's
//! command, Rig2D's free oscillation, and invalid parameters.

mod common;
use common::{last_error, Fmu};
use rig_dynamics::rig1d::{Rig1D, Rig1DParams};
use rig_dynamics::signals::Sinusoid;
use std::f64::consts::PI;

/// A case: model, parameter assignments (by name), and an output name or
/// the text an error message must contain.
type Case<'a> = (&'a str, &'a [(&'a str, f64)], &'a str);

/// Directional derivatives against finite differences: the rigs are
/// linear in F, so both are exact up to rounding, and they must agree to
/// `tol` relative plus the rounding of the differences: an output y is
/// differenced over a perturbation of 1e-6·max(|u|, nominal) inside the
/// FMU (1e-5 in the test), which loses ~ε·|y|/δ; the bound allows ten
/// times that. `tol` = 1e-6 except for the stiff EMPS loop (below).
fn assert_close(what: &str, (j, fd, y, delta): (f64, f64, f64, f64), tol: f64) {
    let rounding = 10.0 * f64::EPSILON * y.abs() / delta;
    assert!(
        (j - fd).abs() <= tol * fd.abs() + rounding,
        "{what}: FMU {j:e}, finite differences {fd:e} (output {y:e})"
    );
}

/// (J, FD, output, FMU's perturbation) for `output`/`input` after 200
/// warm-up steps of `h` with the inputs `warmup`.
fn sensitivity(
    model: &'static str,
    params: &[(&str, f64)],
    warmup: &[(&str, f64)],
    output: &str,
    input: &str,
    h: f64,
) -> (f64, f64, f64, f64) {
    let mut fmu = Fmu::new(model, params);
    for _ in 0..200 {
        for (name, value) in warmup {
            fmu.set(name, *value);
        }
        fmu.step(h);
    }
    with_scale(&mut fmu, output, input, h)
}

/// `Fmu::step_sensitivity` with the output's value and the FMU's
/// perturbation size.
fn with_scale(fmu: &mut Fmu, output: &str, input: &str, h: f64) -> (f64, f64, f64, f64) {
    let delta = 1e-6 * fmu.get(input).abs().max(fmu.var(input).nominal.unwrap());
    let (j, fd) = fmu.step_sensitivity(output, input, h);
    (j, fd, fmu.get(output), delta)
}

const EMPS: &[(&str, f64)] = &[
    ("m", 95.11),
    ("c", 203.5),
    ("k", 0.0),
    ("v_a", 0.0),
    ("control", 2.0),
    ("ctrl_kp", 243.45 * 160.18),
    ("ctrl_kd", 243.45),
    ("ctrl_ff", 0.0),
    ("ctrl_gain", 35.15065188),
    ("ctrl_u_max", 10.0),
];

#[test]
fn step_sensitivities_to_the_friction_force_agree_with_finite_differences() {
    let friction = [("F", 0.3), ("F_ext", 0.1)];
    for h in [1e-3, 5e-2] {
        // the stick-slip benchmark rig: ∂v/∂F ≈ −h/m, ∂x/∂F ≈ −h²/2m
        for output in ["v", "x", "x_rel", "a", "F_app"] {
            let r = sensitivity("Rig1D", &[], &friction, output, "F", h);
            assert_close(&format!("Rig1D d{output}/dF, h = {h}"), r, 1e-6);
        }
        let (j, ..) = sensitivity("Rig1D", &[], &friction, "v", "F", h);
        assert!((j + h).abs() <= 1e-3 * h, "dv/dF = {j:e}, about -h/m");
        // the EMPS loop, tracking a small step (in the linear band) and, at
        // h = 1e-3, 0.2 s into a 1 m step (saturated: the command sits at
        // -10 V, no feedback). Its stiffness G·Kp = 1.4e6 N/m on 95 kg makes
        // the step's own rounding (forces ~ G·Kp·|x|) the limit: 1e-4.
        for (target, command) in [(1e-4, None), (-1.0, Some(-10.0))] {
            if command.is_some() && h > 1e-3 {
                continue;
            }
            let warm = [("F", 20.0), ("F_ext", 0.1), ("x_ref", target)];
            for output in ["v", "x", "F_app"] {
                let mut fmu = Fmu::new("Rig1D", EMPS);
                for _ in 0..200 {
                    for (name, value) in warm {
                        fmu.set(name, value);
                    }
                    fmu.step(h);
                }
                let u = fmu.get("u_ctrl");
                match command {
                    Some(c) => assert_eq!(u, c),
                    None => assert!(u.abs() < 10.0, "u_ctrl = {u}"),
                }
                let r = with_scale(&mut fmu, output, "F", h);
                assert_close(&format!("EMPS d{output}/dF, x_ref = {target}"), r, 1e-4);
            }
        }
        // Rig2D: each axis feels its own friction component only
        let forces = [("F1", 0.2), ("F2", -0.1)];
        for (output, input) in [("v1", "F1"), ("x2", "F2"), ("a2", "F2"), ("x1_rel", "F1")] {
            let r = sensitivity("Rig2D", &[], &forces, output, input, h);
            assert_close(&format!("Rig2D d{output}/d{input}"), r, 1e-6);
        }
        let (j, fd, ..) = sensitivity("Rig2D", &[], &forces, "v1", "F2", h);
        assert_eq!((j, fd), (0.0, 0.0));
    }
}

/// A fallback case: parameter assignments, step, input.
type Fallback<'a> = (&'a [(&'a str, f64)], f64, &'a str);

/// Rig1D's outputs.
const RIG1D_OUTPUTS: [&str; 11] = [
    "x", "v", "a", "F_spring", "x_act", "x_rel", "v_body", "F_drive", "u_ctrl", "F_ctrl", "F_app",
];

/// A damped Rig1D on a moving, dithered surface: the plain mode.
const PLAIN: &[(&str, f64)] = &[
    ("c", 0.3),
    ("v_surface", 0.01),
    ("dither_amp", 1e-4),
    ("dither_freq", 30.0),
];

/// After a held step in the plain mode (one exact step, linear in the
/// forces, at any step length: ω·h from 1.4e-4 to 0.07), Rig1D's
/// directional derivatives with respect to F and F_ext are the rig's
/// closed form (`Rig1D::held_step_sensitivity`) bit for bit, every output,
/// and agree with differences outside the FMU. F_app has no direct
/// feedthrough from F (its derivative is the state's change alone) and
/// one of +1 from F_ext.
#[test]
fn rig1d_held_step_derivatives_are_the_rigs_closed_form() {
    let p = Rig1DParams {
        c: 0.3,
        v_surface: 0.01,
        dither: Sinusoid::new(1e-4, 30.0),
        ..Rig1DParams::default()
    };
    for h in [1e-4, 1e-2, 0.05] {
        let mut fmu = Fmu::new("Rig1D", PLAIN);
        for k in 0..30 {
            fmu.set("F", 0.3 * (k as f64).sin());
            fmu.set("F_ext", 0.1);
            fmu.step(h);
        }
        let d = Rig1D::new(p).unwrap().held_step_sensitivity(h).unwrap();
        let by_f = [
            d.x,
            d.xd,
            d.acceleration,
            d.spring_force,
            0.0,
            d.x,
            d.xd,
            0.0,
            0.0,
            0.0,
            d.applied_force,
        ];
        for (input, sign) in [("F", 1.0), ("F_ext", -1.0)] {
            for (output, want) in RIG1D_OUTPUTS.iter().zip(by_f) {
                let got = fmu.directional_derivative(output, input);
                let want = match (*output, input) {
                    ("F_app", "F") => want,
                    ("F_app", _) => 1.0 - want,
                    _ => 0.0 + sign * want,
                };
                assert_eq!(
                    got.to_bits(),
                    want.to_bits(),
                    "h {h}: d{output}/d{input} {got:e} vs {want:e}"
                );
            }
        }
        // −k·∂x/∂F − c·∂ẋ/∂F: c·h/m + k·h²/2m for a short step (what
        // the held F changed of the damper and spring forces)
        if h <= 1e-4 {
            let short = p.c * h / p.m + p.k * h * h / (2.0 * p.m);
            assert!(
                (d.applied_force - short).abs() <= 1e-3 * short,
                "{:e} vs {short:e}",
                d.applied_force
            );
        }
        let pairs = [
            ("v", "F"),
            ("x", "F"),
            ("a", "F"),
            ("F_app", "F"),
            ("F_app", "F_ext"),
        ];
        for (output, input) in pairs {
            let r = with_scale(&mut fmu, output, input, h);
            assert_close(&format!("Rig1D d{output}/d{input}, h = {h}"), r, 1e-6);
        }
    }
}

/// Where the rig has no closed form (a mode other than the plain one;
/// other inputs) and after a step with input slopes,
/// the directional derivative is the layer's central differences of the
/// replayed step, bit for bit as before.
#[test]
fn rig1d_directional_derivatives_fall_back_to_the_differences() {
    let cases: [Fallback; 4] = [
        // the built-in drive force is not the plain mode
        (&[("drive_amp", 0.5), ("drive_freq", 1.0)], 1e-3, "F"),
        // nor the controller
        (&[("control", 1.0), ("ctrl_kp", 40.0)], 1e-3, "F_ext"),
        // nor the actuator point from its input
        (&[("actuator", 1.0)], 1e-3, "x_act_in"),
        // an input other than the forces (here without effect)
        (PLAIN, 1e-3, "x_ref"),
    ];
    for (params, h, input) in cases {
        let mut fmu = Fmu::new("Rig1D", params);
        for k in 0..30 {
            fmu.set(input, 0.3 * (k as f64).sin());
            fmu.step(h);
        }
        for output in ["v", "x", "a", "F_app"] {
            let (j, fd) = fmu.step_derivative_and_differences(output, input, h);
            assert_eq!(j.to_bits(), fd.to_bits(), "{params:?}: d{output}/d{input}");
        }
    }
    // the plain mode with slopes on the forces
    let mut fmu = Fmu::new("Rig1D", PLAIN);
    for (input, slope) in [("F", 2.0), ("F_ext", -1.0)] {
        fmu.set(input, 0.2);
        fmu.set_slope(input, slope);
        let (j, fd) = fmu.step_derivative_and_differences("v", "F", 1e-3);
        assert_eq!(j.to_bits(), fd.to_bits(), "slope on {input}");
    }
    // held again: the closed form, which the differences approach
    fmu.set("F", 0.2);
    fmu.set("F_ext", 0.2);
    let (j, fd) = fmu.step_derivative_and_differences("v", "F", 1e-3);
    assert!((j - fd).abs() <= 1e-6 * fd.abs(), "{j:e} vs {fd:e}");
    assert_ne!(j.to_bits(), fd.to_bits());
}

/// Quasi-static mode (Appels & Herder): x = x_act + (F_ext − F)/k, so
/// ∂x/∂F = −1/k at every instant — before any step (feedthrough only) and
/// after one.
#[test]
fn quasi_static_position_feeds_through_minus_one_over_k() {
    let k = 116.04e3;
    let params = [("m", 0.0), ("c", 0.0), ("k", k), ("v_a", 8.25e-8)];
    let mut fmu = Fmu::new("Rig1D", &params);
    fmu.set("F", 0.05);
    let before = fmu.directional_derivative("x", "F");
    assert!(
        (before + 1.0 / k).abs() <= 1e-6 / k,
        "before a step: {before:e}"
    );
    for _ in 0..10 {
        fmu.step(1e-2);
    }
    let r = with_scale(&mut fmu, "x", "F", 1e-2);
    assert_close("quasi-static dx/dF", r, 1e-6);
    let j = r.0;
    assert!((j + 1.0 / k).abs() <= 1e-6 / k, "after a step: {j:e}");
    assert_eq!(fmu.directional_derivative("v", "F"), 0.0);
    // damped quasi-static: c·ẋ = k(x_a − x) − F; over h, ∂x/∂F = −(1 − e^(−kh/c))/k
    let (k, c, h) = (50.0, 2.0, 1e-2);
    let r = sensitivity(
        "Rig1D",
        &[("m", 0.0), ("c", c), ("k", k)],
        &[("F", 0.3)],
        "x",
        "F",
        h,
    );
    assert_close("damped quasi-static dx/dF", r, 1e-6);
    let j = r.0;
    let exact = -(1.0 - (-k * h / c).exp()) / k;
    assert!(
        (j - exact).abs() <= 1e-8 * exact.abs(),
        "{j:e} vs {exact:e}"
    );
}

/// Run with time-varying inputs (interpolated), recording every output.
fn run(fmu: &mut Fmu, steps: usize, h: f64, record: &mut Vec<u64>) {
    let (inputs, outputs): (&[&str], &[&str]) = if fmu.model == "Rig1D" {
        (
            &["F", "F_ext", "x_act_in", "x_ref"],
            &[
                "x", "v", "a", "F_spring", "x_act", "x_rel", "v_body", "F_drive", "u_ctrl",
                "F_ctrl", "F_app",
            ],
        )
    } else {
        (
            &["F1", "F2", "F_ext1", "F_ext2"],
            &["v1", "v2", "x1", "x2", "x1_rel", "x2_rel", "a1", "a2"],
        )
    };
    for _ in 0..steps {
        for (i, name) in inputs.iter().enumerate() {
            let w = 2.0 * PI * (1.0 + i as f64);
            let u = |t: f64| 0.1 * (w * t).sin() + 0.01 * i as f64;
            fmu.set(name, u(fmu.t));
            fmu.set_slope(name, (u(fmu.t + h) - u(fmu.t)) / h);
        }
        fmu.step(h);
        for o in outputs {
            record.push(fmu.get(o).to_bits());
        }
    }
}

#[test]
fn restored_states_reproduce_the_run_bit_for_bit() {
    let rig1d = [
        ("m", 2.0),
        ("c", 30.0),
        ("k", 100.0),
        ("actuator", 1.0),
        ("dither_amp", 1e-3),
        ("dither_freq", 15.0),
        ("F_step", 0.8),
        ("t_step", 0.4123),
        ("drive_amp", 0.5),
        ("drive_freq", 1.0),
        ("control", 2.0),
        ("ctrl_kp", 400.0),
        ("ctrl_kd", 20.0),
        ("ctrl_ki", 100.0),
        ("ctrl_u_max", 0.05),
    ];
    let rig2d = [
        ("c1", 0.3),
        ("vs2", 0.01),
        ("dither_amp2", 1e-3),
        ("dither_freq2", 20.0),
    ];
    common::assert_state_round_trip("Rig1D", &rig1d, run);
    common::assert_state_round_trip("Rig2D", &rig2d, run);
}

/// Output derivatives against a short step with the declared input slopes.
#[test]
fn output_derivatives_agree_with_a_short_step() {
    let cases: [Case; 7] = [
        ("Rig1D", &[("dither_amp", 1e-3), ("dither_freq", 5.0)], "x"),
        ("Rig1D", &[("dither_amp", 1e-3), ("dither_freq", 5.0)], "v"),
        (
            "Rig1D",
            &[("dither_amp", 1e-3), ("dither_freq", 5.0)],
            "x_rel",
        ),
        (
            "Rig1D",
            &[("drive_amp", 1.0), ("drive_freq", 2.0)],
            "F_drive",
        ),
        ("Rig1D", &[("m", 0.0), ("k", 50.0)], "x"),
        (
            "Rig2D",
            &[("dither_amp1", 1e-3), ("dither_freq1", 5.0)],
            "v1",
        ),
        ("Rig2D", &[], "x2_rel"),
    ];
    for (model, params, output) in cases {
        let mut fmu = Fmu::new(model, params);
        let input = if model == "Rig1D" { "F" } else { "F1" };
        for _ in 0..5 {
            fmu.set(input, 0.2);
            fmu.step(1e-3);
        }
        fmu.set(input, 0.2);
        fmu.set_slope(input, 3.0);
        let rate = fmu.output_derivative(output);
        let y0 = fmu.get(output);
        let dt = 1e-7;
        fmu.step(dt);
        let fd = (fmu.get(output) - y0) / dt;
        assert!(
            (rate - fd).abs() <= 1e-4 * fd.abs().max(1e-9),
            "{model}.{output}: rate {rate:e}, short step {fd:e}"
        );
    }
}

/// The EMPS loop through the FMU: u_ctrl is the benchmark's control law
/// vir = sat(kv·(kp·(qg − qm) − q̇m), ±10 V) of the outputs x = qm and
/// v_body = q̇m, and F_ctrl = gtau·vir.
#[test]
fn emps_command_is_the_benchmark_control_law() {
    let mut fmu = Fmu::new("Rig1D", EMPS);
    let (kp, kv, gtau) = (160.18, 243.45, 35.15065188);
    let mut saturated = 0;
    for n in 0..2000 {
        let t = n as f64 * 1e-3;
        let qg = 0.02 * (2.0 * PI * t).sin();
        fmu.set("x_ref", qg);
        fmu.set("F", 20.39 * fmu.get("v_body").signum());
        let vir = fmu.get("u_ctrl");
        let law = (kv * (kp * (qg - fmu.get("x")) - fmu.get("v_body"))).clamp(-10.0, 10.0);
        assert!((vir - law).abs() <= 1e-12 * 10.0, "t = {t}: {vir} vs {law}");
        assert!((fmu.get("F_ctrl") - gtau * vir).abs() <= 1e-12 * gtau * 10.0);
        saturated += usize::from(vir.abs() == 10.0);
        fmu.step(1e-3);
    }
    assert!(saturated > 0, "the case should reach the saturation");
}

/// Wijata et al.'s oscillator without friction through the FMU: x_i(t) =
/// x_i(0)·cos ωt + v_i(0)/ω·sin ωt, ω = 10 rad/s, in both axes.
#[test]
fn rig2d_free_oscillation_through_the_fmu() {
    let mut fmu = Fmu::new("Rig2D", &[]);
    let w = 10.0;
    for _ in 0..1000 {
        fmu.step(1e-3);
    }
    let t = fmu.t;
    for (x, v0) in [("x1", -0.8), ("x2", 0.8)] {
        let exact = 0.08 * (w * t).cos() + v0 / w * (w * t).sin();
        assert!(
            (fmu.get(x) - exact).abs() <= 1e-8 * 0.113,
            "{x}: {} vs {exact}",
            fmu.get(x)
        );
    }
}

#[test]
fn invalid_parameters_are_refused_with_name_and_value() {
    // Outside the bounds the model description declares: refused when set,
    // the value unchanged, and the instance initialises.
    let when_set: &[Case] = &[
        ("Rig1D", &[("m", -1.0)], "m (value reference 7) = -1"),
        ("Rig1D", &[("actuator", 3.0)], "actuator (value reference"),
        ("Rig1D", &[("control", 5.0)], "control (value reference"),
        ("Rig1D", &[("ctrl_ff", 1.5)], "ctrl_ff (value reference"),
        (
            "Rig1D",
            &[("ctrl_u_max", -10.0)],
            "ctrl_u_max (value reference",
        ),
        (
            "Rig1D",
            &[("dither_freq", -1.0)],
            "dither_freq (value reference",
        ),
        ("Rig2D", &[("k1", -5.0)], "k1 (value reference"),
        (
            "Rig2D",
            &[("dither_freq2", -3.0)],
            "dither_freq2 (value reference",
        ),
    ];
    for (model, bad, needle) in when_set {
        let fmu = common::refused_when_set(model, bad, needle);
        assert_eq!(fmu.exit_initialization(), common::OK, "{}", last_error());
    }
    // Within them, but not a valid rig (a mass of 0; a controller on a
    // rig without a mass): refused at initialization.
    let cases: &[Case] = &[
        ("Rig1D", &[("m", 0.0), ("control", 1.0)], "control = 1"),
        ("Rig2D", &[("m", 0.0)], "m = 0"),
    ];
    for (model, bad, needle) in cases {
        let fmu = common::refused_at_initialization(model, bad, needle);
        // fixed and called again, the instance initialises
        fmu.set_any(bad[0].0, 0.0);
        fmu.set("m", 1.0);
        assert_eq!(fmu.exit_initialization(), common::OK, "{}", last_error());
    }
    // NaN never reaches the model: fmi2SetReal refuses it, naming the value
    let fmu = Fmu::instantiated("Rig1D", &[]);
    assert_ne!(fmu.set_any("k", f64::NAN), common::OK);
    assert!(last_error().contains("NaN"), "{}", last_error());
}
