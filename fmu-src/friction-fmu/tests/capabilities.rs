//! The capabilities every friction FMU declares, checked through the C ABI:
//! directional derivatives against finite differences (and LuGre's, after
//! a held step, against the law's closed form), FMU states that
//! reproduce a run bit for bit (in memory and serialized, in a fresh
//! instance), step-size independence with interpolated inputs, output
//! derivatives, and invalid parameters (issue 2).

mod common;
use common::{Fmu, LUGRE_TABLE};
use friction_laws::lugre::{HeldInput, LuGre, LuGreInputs};
use friction_laws::Ramp;
use std::f64::consts::PI;

/// An input signal: its name and its value at time t.
type Signal = (&'static str, fn(f64) -> f64);
/// An invalid-parameter case: model, assignments, text the message must contain.
type BadCase<'a> = (&'a str, &'a [(&'a str, f64)], &'a str);
/// Parameters set by name.
type Params = &'static [(&'static str, f64)];

/// A driving input for each model.
fn drive(model: &str) -> Vec<Signal> {
    match model {
        "Dahl" | "ResetIntegrator" | "BlimanSorine" | "ElastoPlastic" => {
            vec![("v", |t| 1e-3 * (2.0 * PI * t).sin())]
        }
        // pre-sliding and gross sliding with reversals
        "MaxwellSlip" | "GMS" => vec![("v", |t| 5e-4 * (2.0 * PI * t).sin() + 1e-4)],
        // through the band at both ends, F_app above Fs in part
        "Classical" => vec![
            ("v", |t| 2e-5 * (2.0 * PI * t).sin()),
            ("F_app", |t| 3.0 * (3.0 * PI * t).cos()),
        ],
        "LuGre" => vec![
            ("v", |t| 2e-3 * (2.0 * PI * t).sin()),
            ("x", |t| 0.4 + 0.1 * t),
        ],
        "Bristle" => vec![("x", |t| 5e-8 * (2.0 * PI * t).sin())],
        "Bristle2D" => vec![
            ("v1", |t| 1e-3 * (2.0 * PI * t).cos()),
            ("v2", |t| 5e-4 * (2.0 * PI * t).sin()),
        ],
        _ => unreachable!(),
    }
}

fn params(model: &str) -> &'static [(&'static str, f64)] {
    if model == "LuGre" {
        LUGRE_TABLE
    } else {
        &[]
    }
}

const MODELS: [&str; 10] = [
    "Dahl",
    "LuGre",
    "ResetIntegrator",
    "Bristle",
    "Bristle2D",
    "Classical",
    "BlimanSorine",
    "ElastoPlastic",
    "MaxwellSlip",
    "GMS",
];

fn outputs(model: &str) -> &'static [&'static str] {
    match model {
        "Bristle2D" => &["F1", "F2", "z1", "z2"],
        "Bristle" => &["F"],
        "Classical" => &["F", "P_diss"],
        "BlimanSorine" => &["F", "x1", "x2", "P_diss", "E_stored"],
        "ElastoPlastic" => &["F", "z", "P_diss", "E_stored"],
        "MaxwellSlip" | "GMS" => &["F", "P_diss", "E_stored"],
        _ => &["F", "z"],
    }
}

fn run(fmu: &mut Fmu, steps: usize, h: f64, record: &mut Vec<u64>) {
    let model = fmu.model;
    for _ in 0..steps {
        for (name, f) in drive(model) {
            fmu.set(name, f(fmu.t));
        }
        fmu.step(h);
        for o in outputs(model) {
            record.push(fmu.get(o).to_bits());
        }
    }
}

#[test]
fn restored_states_reproduce_the_run_bit_for_bit() {
    for model in MODELS {
        common::assert_state_round_trip(model, params(model), run);
    }
}

/// J = ∂F(t+h)/∂u (u held over the step) from the FMU, against central
/// differences computed outside it by rolling back with fmi2SetFMUstate.
fn check_step_sensitivity(
    model: &'static str,
    params: &[(&str, f64)],
    output: &str,
    input: &str,
    warmup: &[(&str, f64)],
    h: f64,
) {
    let mut fmu = Fmu::new(model, params);
    for _ in 0..200 {
        for (name, value) in warmup {
            fmu.set(name, *value);
        }
        fmu.step(h);
    }
    let (j, fd) = fmu.step_sensitivity(output, input, h);
    let scale = fd.abs().max(1e-12);
    assert!(
        (j - fd).abs() <= 1e-4 * scale,
        "{model} d{output}/d{input}: FMU {j:e}, finite differences {fd:e}"
    );
}

#[test]
fn directional_derivatives_agree_with_finite_differences() {
    let h = 1e-3;
    // LuGre sticking (the σ0·h term dominates) and sliding
    check_step_sensitivity("LuGre", &[], "F", "v", &[("v", 1e-5)], h);
    check_step_sensitivity("LuGre", &[], "F", "v", &[("v", 5e-2)], h);
    check_step_sensitivity(
        "LuGre",
        LUGRE_TABLE,
        "F",
        "x",
        &[("v", 5e-2), ("x", 0.3)],
        h,
    );
    check_step_sensitivity("Dahl", &[], "F", "v", &[("v", 1e-4)], h);
    check_step_sensitivity("Dahl", &[("F_offset", -0.4)], "F", "v", &[("v", -1e-4)], h);
    check_step_sensitivity("ResetIntegrator", &[], "F", "v", &[("v", 1e-6)], h);
    check_step_sensitivity("BlimanSorine", &[], "F", "v", &[("v", 1e-4)], h);
    check_step_sensitivity("BlimanSorine", &[], "F", "v", &[("v", -3e-3)], h);
    check_step_sensitivity("Classical", &[], "F", "v", &[("v", 4e-4)], h);
    // sticking elastically, in the transition, sliding
    check_step_sensitivity("ElastoPlastic", &[], "F", "v", &[("v", 1e-6)], h);
    check_step_sensitivity("ElastoPlastic", &[], "F", "v", &[("v", 1e-5)], h);
    check_step_sensitivity("ElastoPlastic", &[], "F", "v", &[("v", -5e-2)], h);
    check_step_sensitivity("Classical", &[], "P_diss", "v", &[("v", -2e-3)], h);
    // all elements sticking, and gross sliding (every element slipping)
    check_step_sensitivity("MaxwellSlip", &[], "F", "v", &[("v", 1e-6)], h);
    check_step_sensitivity("GMS", &[], "F", "v", &[("v", 1e-6)], h);
    check_step_sensitivity("GMS", &[], "F", "v", &[("v", -5e-2)], h);
    // with the micro-damping: sticking, on the Stribeck curve, gross sliding
    for v in [1e-6, 2e-3, -5e-2] {
        check_step_sensitivity("GMS", &[("sigma1", 30.0)], "F", "v", &[("v", v)], h);
    }
    check_step_sensitivity(
        "Classical",
        &[],
        "F",
        "F_app",
        &[("v", 1e-6), ("F_app", 1.5)],
        h,
    );
    check_step_sensitivity(
        "Bristle2D",
        &[],
        "F1",
        "v2",
        &[("v1", 1e-2), ("v2", 5e-3)],
        h,
    );
    check_step_sensitivity(
        "Bristle2D",
        &[],
        "F2",
        "v2",
        &[("v1", 1e-6), ("v2", 1e-6)],
        h,
    );
}

/// LuGre with every option: `LUGRE_TABLE`'s position table (and one for
/// v < 0), direction-dependent levels, a Stribeck exponent ≠ 2,
/// velocity-dependent micro-damping and the normal-force form.
fn lugre_options() -> Vec<(&'static str, f64)> {
    let mut p = LUGRE_TABLE.to_vec();
    p.extend([
        ("direction_dependent", 1.0),
        ("Fc_neg", 0.7),
        ("Fs_neg", 1.9),
        ("stribeck_exponent", 1.4),
        ("vd", 2e-3),
        ("normal_force_form", 1.0),
        ("scale_neg[1]", 1.2),
        ("scale_neg[2]", 0.9),
        ("scale_neg[3]", 1.1),
    ]);
    p
}

/// The law the LuGre FMU runs with `params` set (by name).
fn lugre_law(params: &[(&str, f64)]) -> LuGre {
    let info = &*friction_fmu::lugre::INFO;
    let mut values = fmi_export::Values::from_start(info.variables);
    for (name, value) in params {
        let v = info.variables.iter().find(|v| v.name == *name).unwrap();
        values.set(v.vr, *value);
    }
    LuGre::new(friction_fmu::lugre::LuGreFmu::params(&values)).unwrap()
}

/// After a step with every input held, LuGre's directional derivatives of
/// F and z with respect to v, x and Fn are the law's closed form
/// (`LuGre::held_step_sensitivity`, asked with the spread the differences
/// would use) bit for bit, sticking and sliding, both directions; and
/// they agree with differences taken outside the FMU.
#[test]
fn lugre_held_step_derivatives_are_the_laws_closed_form() {
    let h = 1e-4;
    let mut compared = 0;
    let options = lugre_options();
    for params in [&[][..], &options] {
        for (v, x, fn_) in [
            (2e-3, 0.2, 3.0),
            (-4e-4, 0.7, 3.0),
            (1e-6, 0.05, 25.0),
            (-0.05, 2.0, 1.0),
        ] {
            let mut fmu = Fmu::new("LuGre", params);
            for _ in 0..30 {
                fmu.set("v", v);
                fmu.set("x", x);
                fmu.set("Fn", fn_);
                fmu.step(h);
            }
            let mut law = lugre_law(params);
            law.set_z(fmu.get("z"));
            let held = LuGreInputs {
                v: Ramp::constant(v),
                x: Ramp::constant(x),
                fn_: Ramp::constant(fn_),
            };
            law.step(&held, h);
            fmu.step(h);
            for (input, u, which) in [
                ("v", v, HeldInput::V),
                ("x", x, HeldInput::X),
                ("Fn", fn_, HeldInput::Fn),
            ] {
                let spread = 1e-6 * u.abs().max(fmu.var(input).nominal.unwrap());
                let want = law
                    .held_step_sensitivity(which, v, x, fn_, h, spread)
                    .unwrap();
                for (output, want) in [("F", want.force), ("z", want.z)] {
                    let got = fmu.directional_derivative(output, input);
                    assert_eq!(
                        got.to_bits(),
                        (0.0 + want).to_bits(),
                        "d{output}/d{input} at v {v}: {got:e} vs {want:e}"
                    );
                    compared += 1;
                }
            }
            let (j, fd) = fmu.step_sensitivity("F", "v", h);
            assert!(
                (j - fd).abs() <= 1e-6 * fd.abs(),
                "dF/dv at v {v}: {j:e} vs {fd:e}"
            );
        }
    }
    assert_eq!(compared, 2 * 4 * 3 * 2);
}

/// Where LuGre's closed form declines (|v| within the spread of the
/// differences: the kink of |v| at 0) and after a step with input slopes,
/// the directional derivative is the layer's central differences of the
/// replayed step, bit for bit as before.
#[test]
fn lugre_directional_derivatives_fall_back_to_the_differences() {
    let h = 1e-4;
    let mut fmu = Fmu::new("LuGre", &lugre_options());
    for k in 0..30 {
        fmu.set("v", 1e-4 * (k as f64).sin());
        fmu.set("x", 0.3);
        fmu.step(h);
    }
    // |v| ≤ 1e-6·nominal (1e-3): the differences straddle v = 0
    for v in [4e-10, -1e-9, 0.0] {
        fmu.set("v", v);
        for output in ["F", "z"] {
            let (j, fd) = fmu.step_derivative_and_differences(output, "v", h);
            assert_eq!(j.to_bits(), fd.to_bits(), "d{output}/dv at v {v}");
        }
    }
    // a step with slopes: not the held update
    fmu.set("v", 2e-3);
    for (input, slope) in [("v", 0.5), ("x", 1e-2), ("Fn", -2.0)] {
        fmu.set_slope(input, slope);
        let (j, fd) = fmu.step_derivative_and_differences("F", "v", h);
        assert_eq!(j.to_bits(), fd.to_bits(), "slope on {input}");
        fmu.set("v", 2e-3);
    }
    // held again: the closed form, which the differences approach
    let (j, fd) = fmu.step_derivative_and_differences("F", "v", h);
    assert!((j - fd).abs() <= 1e-6 * fd.abs(), "{j:e} vs {fd:e}");
    assert_ne!(j.to_bits(), fd.to_bits());
}

#[test]
fn bristle_stiffness_agrees_with_finite_differences() {
    // ∂F/∂x of the displacement-driven law is its tangent stiffness.
    let mut fmu = Fmu::new("Bristle", &[("seed", 3.0)]);
    let mut x = 0.0;
    for _ in 0..20 {
        x += 1e-9;
        fmu.set("x", x);
        fmu.step(1e-3);
    }
    let j = fmu.directional_derivative("F", "x");
    let (t0, s0) = (fmu.t, fmu.state());
    let delta = 1e-15;
    let mut f_at = |u: f64| {
        fmu.restore(s0, t0);
        fmu.set("x", u);
        fmu.get("F")
    };
    // One-sided, in the direction of motion: the law is hysteretic, and a
    // backward perturbation is a reversal (bristles reconnect, F jumps).
    let fd = (f_at(x + delta) - f_at(x)) / delta;
    assert!(
        (j - fd).abs() <= 1e-6 * fd.abs(),
        "FMU {j:e}, finite differences {fd:e}"
    );
    assert!(j > 0.0);
}

/// The same smooth velocity history, communicated every 1e-5 s and every
/// 1e-2 s with first-order interpolation: F agrees at the common points to
/// 1e-3 of the force scale.
#[test]
fn step_size_independence_with_interpolated_inputs() {
    let v = |t: f64| 2e-3 * (2.0 * PI * t).sin() + 1e-3 * (PI * t).sin();
    for (model, scale) in [("LuGre", 1.5), ("Dahl", 2.0)] {
        let sample = |h: f64| -> Vec<f64> {
            let fmu = Fmu::new(model, &[]);
            let n = (2.0 / h).round() as usize;
            let every = (1e-2 / h).round() as usize;
            let mut out = Vec::new();
            for k in 0..n {
                let t = k as f64 * h;
                fmu.set("v", v(t));
                fmu.set_slope("v", (v(t + h) - v(t)) / h);
                assert_eq!(unsafe { common::fmi2DoStep(fmu.c, t, h, 0) }, common::OK);
                if (k + 1) % every == 0 {
                    out.push(fmu.get("F"));
                }
            }
            out
        };
        let fine = sample(1e-5);
        let coarse = sample(1e-2);
        assert_eq!(fine.len(), coarse.len());
        let worst = fine
            .iter()
            .zip(&coarse)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            worst <= 1e-3 * scale,
            "{model}: worst difference {worst:e} N"
        );
        // the history drives the law through sticking and sliding
        let peak = fine.iter().fold(0.0f64, |m, f| m.max(f.abs()));
        assert!(peak > 0.5 * scale, "{model}: peak {peak}");
    }
}

/// dF/dt from fmi2GetRealOutputDerivatives against a short forward step
/// with the input moving at the slope that was declared. GMS with its
/// micro-damping, whose `Σ σ_i·ż_i` moves with the forces and with `v`:
/// some elements slipping, some sticking.
#[test]
fn output_derivatives_agree_with_a_short_step() {
    let damped: Params = &[("sigma1", 40.0)];
    let cases: [(&str, Params, &str, f64, f64); 8] = [
        ("LuGre", &[], "v", 1e-4, 3e-3),
        ("Dahl", &[], "v", 1e-4, 2e-3),
        ("ResetIntegrator", &[], "v", 1e-6, 1e-4),
        ("Bristle", &[], "x", 1e-9, 1e-8),
        ("LuGre", &[], "v", 2e-2, -0.5),
        ("GMS", damped, "v", 2e-2, -0.5),
        ("GMS", damped, "v", -1.5e-3, 0.3),
        ("GMS", &[], "v", 1.5e-3, 0.3),
    ];
    for (model, params, input, u, slope) in cases {
        let mut fmu = Fmu::new(model, params);
        for _ in 0..5 {
            fmu.set(input, u);
            fmu.step(1e-4);
        }
        fmu.set(input, u);
        fmu.set_slope(input, slope);
        let rate = fmu.output_derivative("F");
        let f0 = fmu.get("F");
        let dt = 1e-8;
        fmu.step(dt);
        let fd = (fmu.get("F") - f0) / dt;
        println!(
            "{model} {params:?} at {u}: dF/dt {rate:e}, short step {fd:e}, {:.1e} apart",
            (rate - fd).abs() / fd.abs()
        );
        assert!(
            (rate - fd).abs() <= 1e-3 * fd.abs().max(1e-9),
            "{model} {params:?}: dF/dt {rate:e}, short step {fd:e}"
        );
    }
}

/// Dahl's offset in Co-Simulation: an instance with `F_offset = c` driven
/// as one without has the same state (`F_dahl`, `z`, `sliding`, the
/// derivative) bit for bit and the force shifted by `c` exactly: `F = c`
/// relaxed at the start, `F_dahl + c` at rest after a load and in motion,
/// with interpolated inputs too. The force's output derivative and its
/// step sensitivity are the plain instance's (the offset is constant), and
/// the output derivative is the slope of a short step. A non-finite offset
/// is refused when set, named with its value.
#[test]
fn dahl_offset_shifts_the_force_and_not_its_derivatives() {
    let c = -3.1648;
    let mut plain = Fmu::new("Dahl", &[("alpha", 0.7)]);
    let mut shifted = Fmu::new("Dahl", &[("alpha", 0.7), ("F_offset", c)]);
    assert_eq!((shifted.get("F"), shifted.get("F_dahl")), (c, 0.0));
    let v = |t: f64| 1e-3 * (2.0 * PI * t / 0.02).sin();
    let h = 1e-4;
    for k in 0..600 {
        let t = k as f64 * h;
        // a sine through two reversals, then at rest from t = 0.03 on
        let (value, slope) = if t < 0.03 {
            (v(t), (v(t + h) - v(t)) / h)
        } else {
            (0.0, 0.0)
        };
        for fmu in [&mut plain, &mut shifted] {
            fmu.set("v", value);
            fmu.set_slope("v", slope);
        }
        if k % 50 == 7 {
            let rate = shifted.output_derivative("F");
            assert_eq!(rate, plain.output_derivative("F"), "t {t}");
            let f0 = shifted.get("F");
            let (s0, t0) = (shifted.state(), shifted.t);
            shifted.step(1e-9);
            let fd = (shifted.get("F") - f0) / 1e-9;
            assert!(
                (rate - fd).abs() <= 1e-3 * fd.abs().max(1e-6),
                "t {t}: dF/dt {rate:e}, short step {fd:e}"
            );
            shifted.restore(s0, t0);
            shifted.set("v", value);
            shifted.set_slope("v", slope);
        }
        plain.step(h);
        shifted.step(h);
        let state = shifted.get("F_dahl");
        assert_eq!(state.to_bits(), plain.get("F_dahl").to_bits(), "t {t}");
        assert_eq!(shifted.get("F"), plain.get("F") + c, "t {t}");
        assert_eq!(shifted.get("F"), state + c, "t {t}");
        for name in ["z", "der(F_dahl)"] {
            assert_eq!(
                shifted.get(name).to_bits(),
                plain.get(name).to_bits(),
                "{name}"
            );
        }
        assert_eq!(shifted.get_any("sliding"), plain.get_any("sliding"));
    }
    // at rest, loaded: the state plus the offset, and it stays there
    let state = shifted.get("F_dahl");
    assert!(state.abs() > 0.1, "loaded: {state}");
    shifted.step(0.5);
    assert_eq!(shifted.get("F"), state + c);
    // the step sensitivity after a held step: the offset cancels (to the
    // rounding of the layer's differences of a force shifted by c)
    for fmu in [&mut plain, &mut shifted] {
        fmu.set("v", -2e-4);
    }
    let (j, fd) = shifted.step_sensitivity("F", "v", 1e-3);
    let (j0, _) = plain.step_sensitivity("F", "v", 1e-3);
    assert!((j - j0).abs() <= 1e-8 * j0.abs(), "{j:e} {j0:e}");
    assert!((j - fd).abs() <= 1e-4 * fd.abs(), "{j:e} {fd:e}");
    // not finite: refused when set, named
    for bad in [f64::NAN, f64::INFINITY] {
        let fmu = Fmu::instantiated("Dahl", &[]);
        assert_eq!(
            fmu.set_any("F_offset", bad),
            fmi_export::ffi::fmi2Status::fmi2Error
        );
        let m = common::last_error();
        assert!(
            m.contains("F_offset (value reference 9) must be finite but was"),
            "{m}"
        );
        assert_eq!(fmu.get("F_offset"), 0.0);
    }
}

/// GMS's micro-damping in Co-Simulation (value reference 412, after the
/// arrays). Sticking throughout (2e-7 m, below every element's slip
/// deflection): `F = Σ k_i·x + σ1·v + σ2·v` to 1e-12, and the step
/// sensitivity `∂F(t + h)/∂v = Σ k_i·h + σ1 + σ2`. In gross sliding, the
/// velocity raised from 5e-4 to 5e-3 m/s (the level falls from 1.39 to 1
/// N and every slipping element relaxes to it), `F − Σ F_element[i] −
/// σ2·v` is `Σ σ_i·C·(α_i − F_i/s)/k_i` from the element forces the FMU
/// outputs, and it vanishes as the forces reach their levels.
#[test]
fn gms_micro_damping_adds_sigma_i_times_the_deflection_rates() {
    assert_eq!(
        friction_fmu::maxwell_slip::vr::SIGMA1,
        412,
        "sigma1 is appended after the arrays"
    );
    let (sigma1, sigma2) = (30.0, 0.4);
    let h = 1e-3;
    let total_k = 1e5;
    for v in [1e-6, -1e-6] {
        let mut fmu = Fmu::new("GMS", &[("sigma1", sigma1)]);
        for _ in 0..200 {
            fmu.set("v", v);
            fmu.step(h);
        }
        assert_eq!(fmu.get_any("n_slipping"), 0.0);
        let x = v * h * 200.0;
        let want = total_k * x + sigma1 * v + sigma2 * v;
        let f = fmu.get("F");
        let error = (f - want).abs() / want.abs();
        println!("GMS sticking at {v}: F {f:e}, relative error {error:e}");
        assert!(error <= 1e-12, "F {f}, want {want}");
        let (j, fd) = fmu.step_sensitivity("F", "v", h);
        let want = total_k * h + sigma1 + sigma2;
        println!("GMS sticking at {v}: dF/dv {j}, closed form {want}, differences {fd}");
        assert!((j - want).abs() <= 1e-6 * want, "{j} {want}");
        assert!((fd - want).abs() <= 1e-6 * want, "{fd} {want}");
    }
    let mut fmu = Fmu::new("GMS", &[("sigma1", sigma1)]);
    for _ in 0..100 {
        fmu.set("v", 5e-4);
        fmu.step(h);
    }
    assert_eq!(fmu.get_any("n_slipping"), 10.0);
    let v = 5e-3;
    let s = 1.0 + 0.5 * (-25.0f64).exp();
    let damping = |fmu: &Fmu| {
        let (mut sum, mut want) = (0.0, 0.0);
        for i in 1..=10 {
            let (k, alpha) = (fmu.get(&format!("k[{i}]")), fmu.get(&format!("alpha[{i}]")));
            let f = fmu.get(&format!("F_element[{i}]"));
            sum += f;
            want += sigma1 * k / total_k * fmu.get("C") * (alpha - f / s) / k;
        }
        (fmu.get("F") - sum - sigma2 * v, want)
    };
    let mut worst: f64 = 0.0;
    let mut first = 0.0;
    for j in 0..50 {
        fmu.set("v", v);
        fmu.step(h);
        let (got, want) = damping(&fmu);
        if j == 0 {
            first = want;
        }
        worst = worst.max((got - want).abs() / want.abs());
    }
    println!("GMS gross sliding: damping from {first:e} N, worst relative error {worst:e}");
    assert!(first < -1e-2, "{first}");
    assert!(worst <= 1e-9, "{worst:e}");
    for _ in 0..1000 {
        fmu.step(h);
    }
    let (got, _) = damping(&fmu);
    assert!(got.abs() <= 1e-12, "{got:e}");
}

#[test]
fn invalid_parameters_are_refused_with_name_and_value() {
    // Outside the bounds the model description declares: refused when set.
    let when_set: &[BadCase] = &[
        ("Dahl", &[("sigma", -2.0)], "sigma (value reference 4) = -2"),
        ("ResetIntegrator", &[("z0", -1e-4)], "z0 (value reference"),
        (
            "Bristle",
            &[("delta_max", -1.0)],
            "delta_max (value reference",
        ),
        (
            "Bristle2D",
            &[("sigma11", -1.0)],
            "sigma11 (value reference",
        ),
        (
            "GMS",
            &[("sigma1", -2.0)],
            "sigma1 (value reference 412) = -2",
        ),
    ];
    for (model, bad, needle) in when_set {
        common::refused_when_set(model, bad, needle);
    }
    // not finite: refused when set, named with its value
    for bad in [f64::NAN, f64::INFINITY] {
        let fmu = Fmu::instantiated("GMS", &[]);
        assert_eq!(
            fmu.set_any("sigma1", bad),
            fmi_export::ffi::fmi2Status::fmi2Error
        );
        let m = common::last_error();
        assert!(
            m.contains(&format!(
                "sigma1 (value reference 412) must be finite but was {bad}"
            )),
            "{m}"
        );
        assert_eq!(fmu.get("sigma1"), 0.0);
    }
    // Within them, but not a valid model (Fc > 0, Fs >= Fc, a table of at
    // least two increasing points, ...): refused at initialization.
    let cases: &[BadCase] = &[
        ("Dahl", &[("Fc", 0.0)], "Fc = 0"),
        ("LuGre", &[("sigma0", 0.0)], "sigma0 = 0"),
        ("LuGre", &[("Fs", 0.9)], "Fs = 0.9"),
        (
            "LuGre",
            &[("direction_dependent", 1.0), ("Fs_neg", 0.5)],
            "Fs_neg = 0.5",
        ),
        (
            "LuGre",
            &[("position_dependent", 1.0), ("n_table", 1.0)],
            "n_table = 1",
        ),
        (
            "LuGre",
            &[
                ("position_dependent", 1.0),
                ("n_table", 2.0),
                ("x_table[2]", 0.0),
            ],
            "x_table",
        ),
        (
            "Bristle",
            &[("count_from_load", 0.0), ("n_bristles", 0.0)],
            "n_bristles = 0",
        ),
        (
            "Bristle",
            &[("stiffness_from_load", 0.0), ("sigma_ini", 0.0)],
            "sigma_ini = 0",
        ),
        ("Classical", &[("Fs", 1.0)], "Fs = 1: must be >= Fc = 1.284"),
        ("Classical", &[("dv", 0.0)], "dv = 0"),
        (
            "BlimanSorine",
            &[("f2", 20.0)],
            "f1 = 19.875: must be > f2 = 20",
        ),
        ("BlimanSorine", &[("eta", 1.0)], "eta = 1: must be < 1"),
        (
            "ElastoPlastic",
            &[("z_ba", 2e-5)],
            "z_ba = 0.00002: must be < Fc/sigma0 = 0.00001",
        ),
        ("MaxwellSlip", &[("n_elements", 101.0)], "n_elements = 101"),
        ("MaxwellSlip", &[("W[3]", 0.0)], "W = 0: element 3"),
        ("GMS", &[("alpha[1]", 0.5)], "must sum to 1"),
        ("GMS", &[("C", 0.0)], "C = 0"),
        (
            "BlimanSorine",
            &[("from_reference_points", 1.0), ("x_e", 3.63e-4)],
            "from_reference_points: invalid parameter x_e = 0.000363: no solution",
        ),
    ];
    for (model, bad, needle) in cases {
        common::refused_at_initialization(model, bad, needle);
    }
}
