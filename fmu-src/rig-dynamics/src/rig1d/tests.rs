//! Rig1D against closed forms (no friction: the rig is linear), the first
//! version's arithmetic in the default mode, and parameter validation.

use super::*;
use crate::closed_form::{constant_force_on_damped_mass, peak, worst, Forced};
use std::f64::consts::PI;

/// Rel. tolerance of the closed-form comparisons (of the signal's peak)
/// where the rig integrates with sub-stepped Gauss–Legendre (a sinusoid
/// in the forcing, a saturating controller, the quasi-static mode).
const TOL: f64 = 1e-8;
/// The same where the rig steps exactly ([`ExactStep`]): the rounding
/// accumulated over up to 10 000 steps.
const EXACT_TOL: f64 = 1e-11;

fn no_inputs() -> Rig1DInputs {
    Rig1DInputs::default()
}

/// Run `rig` with inputs from `inputs(t)` (value, slope) for `n` steps of
/// `h`; returns (times, x, ẋ) after each step.
fn run(
    rig: &mut Rig1D,
    h: f64,
    n: usize,
    inputs: impl Fn(f64) -> (Rig1DInputs, Rig1DInputs),
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (mut ts, mut xs, mut vs) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..n {
        let (u, du) = inputs(i as f64 * h);
        rig.step(&u, &du, h);
        let t = (i + 1) as f64 * h;
        ts.push(t);
        xs.push(rig.position(&u.at(&du, h)));
        vs.push(rig.velocity());
    }
    (ts, xs, vs)
}

/// x and ẋ of a run against a closed form `exact(t) -> (x, ẋ)`, each to
/// `tol` of its peak.
fn assert_matches(
    what: &str,
    (ts, xs, vs): &(Vec<f64>, Vec<f64>, Vec<f64>),
    exact: impl Fn(f64) -> (f64, f64),
    tol: f64,
) {
    let (ex, ev): (Vec<f64>, Vec<f64>) = ts.iter().map(|t| exact(*t)).unzip();
    let (ix, iv) = (worst(xs, &ex), worst(vs, &ev));
    assert!(
        ix <= tol * peak(&ex),
        "{what}: x error {ix:e}, peak {:e}",
        peak(&ex)
    );
    assert!(
        iv <= tol * peak(&ev),
        "{what}: v error {iv:e}, peak {:e}",
        peak(&ev)
    );
}

/// Free damped oscillator from x0, no friction, actuator at rest:
/// x(t) = e^(−ζωn t)(x0 cos ωd t + (ζωn x0/ωd) sin ωd t).
#[test]
fn damped_oscillator_matches_the_closed_form() {
    let p = Rig1DParams {
        m: 0.5,
        c: 0.3,
        k: 20.0,
        x_a0: 0.0,
        v_a: 0.0,
        x0: 0.01,
        ..Default::default()
    };
    let wn = (p.k / p.m).sqrt();
    let zeta = p.c / (2.0 * (p.k * p.m).sqrt());
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    for h in [1e-4f64, 1e-3, 1e-2, 0.1] {
        let mut rig = Rig1D::new(p).unwrap();
        let n = (5.0 / h).round() as usize;
        let mut worst: f64 = 0.0;
        for i in 1..=n {
            rig.step(&no_inputs(), &no_inputs(), h);
            let t = i as f64 * h;
            let exact = (-zeta * wn * t).exp()
                * (p.x0 * (wd * t).cos() + zeta * wn * p.x0 / wd * (wd * t).sin());
            worst = worst.max((rig.position(&no_inputs()) - exact).abs());
        }
        assert!(worst <= EXACT_TOL * p.x0, "h = {h}: worst error {worst:e}");
    }
}

/// Spring pulled at constant speed, no friction, from rest:
/// x(t) = v_a·(t − sin(ωt)/ω).
#[test]
fn ramp_response_matches_the_closed_form() {
    let p = Rig1DParams::default();
    let w = (p.k / p.m).sqrt();
    let mut rig = Rig1D::new(p).unwrap();
    let h = 1e-3;
    for i in 1..=10_000 {
        rig.step(&no_inputs(), &no_inputs(), h);
        let t = i as f64 * h;
        let exact = p.v_a * (t - (w * t).sin() / w);
        assert!(
            (rig.position(&no_inputs()) - exact).abs() <= EXACT_TOL * exact.abs().max(1e-3),
            "t = {t}"
        );
    }
}

/// In the default mode (prescribed ramp, no drive, controller or dither)
/// the rig steps exactly: its run follows the exact solution of the
/// piecewise-affine forcing it is given (the closed form `Forced`, chained
/// from step to step from the state each reached, whose own rounding
/// accumulates over the 3000 and 700 steps) to 4e-12 of the state's size
/// (1.9e-12 and 6.8e-13 when the exact step came). The first version of
/// this file (bits recorded from it, commit 6271953) stepped with
/// Gauss–Legendre and is right to that method's truncation error: each
/// output of the rig matches it to 3e-9 of the output's largest recorded
/// value (4.7e-14 at most in the default case; in the damped one, where
/// the first version took three sub-steps of ω·h = 0.015 per step, 4.7e-10
/// in the position and 1.0e-9 in the acceleration, while the exact step
/// agrees with the closed form to 6.8e-13), so what
/// other tests compare against runs of the stick-slip benchmark still
/// holds.
#[test]
fn default_mode_is_exact_and_matches_the_first_version() {
    const BENCHMARK: [[u64; 5]; 5] = [
        [
            0xbfb02339506cc1fb,
            0xbfc0d10f90f8a059,
            0x3fdd62c3fc0167ea,
            0x3fcf7f62462f515a,
            0xbfc0d10f90f8a059,
        ],
        [
            0xbfb849b9acbd0b80,
            0xbfb893b5e76fb2b2,
            0xbfd2621447e7c3be,
            0x3fdb8105cc2114d0,
            0xbfb893b5e76fb2b2,
        ],
        [
            0xbfb7b0d6d6bf60c6,
            0x3fc8f4bacc89087c,
            0x3fd9124c9cd73282,
            0x3fe171546e01c31a,
            0x3fc8f4bacc89087c,
        ],
        [
            0x3fa584c41d1bd0aa,
            0x3fd3c710268204ff,
            0x3fe66b175fff1382,
            0x3fd95720e43e2866,
            0x3fd3c710268204ff,
        ],
        [
            0x3fd1ee9e38c6a752,
            0x3fd332a6d3088999,
            0xbfe56f3eba5bb552,
            0x3fa4494fa6c8a560,
            0x3fd332a6d3088999,
        ],
    ];
    const DAMPED: [[u64; 5]; 5] = [
        [
            0x3fbac5c517999da1,
            0xbfbfbc7d00e10625,
            0xc00a01a28ddd5f63,
            0xbff177365d800505,
            0xbfc125ec94eb645a,
        ],
        [
            0x3fc85c4bcc1b43ef,
            0xbfd75e3e0fa09fb5,
            0xc0124277339f44e8,
            0xbffd38a90362e264,
            0xbfd8021519de1059,
        ],
        [
            0x3fcbbd18cd6df5f8,
            0xbfe54aaafa0fab08,
            0xc00f379960782728,
            0xbff5fc950bd05786,
            0xbfe59c967f2e635a,
        ],
        [
            0x3fcde8930ebdc0ac,
            0xbfea0cce7385c91a,
            0xbfffb34eb63ae406,
            0xbfe77664686d14a1,
            0xbfea5eb9f8a4816c,
        ],
        [
            0x3fcc21fc2b1382f1,
            0xbfea8a2cfce2e648,
            0x3fe9198cf169321c,
            0x3fe0c6b6ffa8adf3,
            0xbfeadc1882019e9a,
        ],
    ];
    let damped = Rig1DParams {
        dither: Sinusoid::OFF,
        ..damped_on_a_moving_surface()
    };
    for (p, h, n, golden) in [
        (Rig1DParams::default(), 1e-3, 3000usize, &BENCHMARK),
        (damped, 7e-3, 700, &DAMPED),
    ] {
        let mut rig = Rig1D::new(p).unwrap();
        let mut out = Vec::new();
        let (mut x, mut v) = (p.x0, p.v0);
        let mut chained: f64 = 0.0;
        for i in 0..n {
            let t = i as f64 * h;
            let u = Rig1DInputs {
                friction: 0.5 * (7.0 * t).sin() + 0.2,
                f_ext: 0.1 * (3.0 * t).cos(),
                ..Default::default()
            };
            let du = Rig1DInputs {
                friction: 3.5 * (7.0 * t).cos(),
                f_ext: -0.3 * (3.0 * t).sin(),
                ..Default::default()
            };
            rig.step(&u, &du, h);
            // m·ẍ + c·ẋ + k·x = k·(x_a0 + v_a·t) + F_ext − F over the step
            let step = Forced {
                m: p.m,
                c: p.c,
                k: p.k,
                f0: p.k * (p.x_a0 + p.v_a * t) + u.f_ext - u.friction,
                f1: p.k * p.v_a + du.f_ext - du.friction,
                ..Default::default()
            };
            (x, v) = step.at(x, v, h);
            let scale = x.abs().max(v.abs());
            chained = chained.max((rig.x - x).abs().max((rig.xd - v).abs()) / scale);
            if (i + 1) % (n / 5) == 0 {
                let u1 = u.at(&du, h);
                out.push([
                    rig.position(&u1),
                    rig.velocity(),
                    rig.acceleration(&u1),
                    rig.spring_force(&u1),
                    rig.slip_velocity(),
                ]);
            }
        }
        assert!(chained <= 4e-12, "{p:?}: {chained:e} off the closed form");
        // each output against the first version, to 3e-9 of its largest
        // recorded value
        for column in 0..5 {
            let first: Vec<f64> = golden.iter().map(|r| f64::from_bits(r[column])).collect();
            let now: Vec<f64> = out.iter().map(|r| r[column]).collect();
            let (error, size) = (worst(&now, &first), peak(&first));
            assert!(
                error <= 3e-9 * size,
                "{p:?}, output {column}: {now:?}, first version {first:?}"
            );
        }
        assert_eq!(out.len(), golden.len());
    }
}

/// Actuator x_a = x_a0 + v_a·t + A·sin(Ωt) through the spring, from a
/// non-zero initial state: m·ẍ + c·ẋ + k·x = k·x_a(t), transient included.
#[test]
fn sine_actuator_forced_response_matches_the_closed_form() {
    let p = Rig1DParams {
        m: 0.5,
        c: 0.4,
        k: 20.0,
        x_a0: 0.002,
        v_a: 0.02,
        act_sine: Sinusoid::new(0.01, 1.3),
        x0: 0.003,
        v0: -0.01,
        ..Default::default()
    };
    let exact = Forced {
        m: p.m,
        c: p.c,
        k: p.k,
        f0: p.k * p.x_a0,
        f1: p.k * p.v_a,
        a: p.k * p.act_sine.amp,
        b: 0.0,
        omega: 2.0 * PI * p.act_sine.freq,
    };
    for h in [1e-3, 1e-2, 0.1] {
        let mut rig = Rig1D::new(p).unwrap();
        let r = run(&mut rig, h, (8.0 / h).round() as usize, |_| {
            (no_inputs(), no_inputs())
        });
        assert_matches(&format!("h = {h}"), &r, |t| exact.at(p.x0, p.v0, t), TOL);
    }
}

/// The same oscillator driven by the actuator from the input x_act_in,
/// given at each communication point with its slope: the interpolation
/// slopes are honoured (a held input would lag by half a step).
#[test]
fn actuator_input_with_slopes_matches_the_closed_form() {
    let p = Rig1DParams {
        m: 0.5,
        c: 0.4,
        k: 20.0,
        actuator: Actuator::Input,
        ..Default::default()
    };
    let (x_a0, v_a) = (0.002, 0.03);
    let exact = Forced {
        m: p.m,
        c: p.c,
        k: p.k,
        f0: p.k * x_a0,
        f1: p.k * v_a,
        ..Default::default()
    };
    let mut rig = Rig1D::new(p).unwrap();
    let r = run(&mut rig, 1e-2, 500, |t| {
        let u = Rig1DInputs {
            x_act: x_a0 + v_a * t,
            ..Default::default()
        };
        let du = Rig1DInputs {
            x_act: v_a,
            ..Default::default()
        };
        (u, du)
    });
    assert_matches("x_act_in", &r, |t| exact.at(0.0, 0.0, t), EXACT_TOL);
}

/// Drive force: a step F_step at t_step inside a communication step, plus
/// a sine or not, plus a constant F_ext input. Before t_step: the free response;
/// from t_step on: the forced response from the state reached then.
#[test]
fn drive_step_and_sine_match_the_closed_form() {
    let with_sine = Rig1DParams {
        m: 1.0,
        c: 0.5,
        k: 30.0,
        v_a: 0.0,
        x0: 0.01,
        drive: DriveForce {
            f_step: 1.5,
            t_step: 0.234_567,
            sine: Sinusoid::new(0.4, 0.9),
        },
        ..Default::default()
    };
    // the step alone: the rig steps exactly, both sides of the split
    let step_alone = Rig1DParams {
        drive: DriveForce {
            sine: Sinusoid::OFF,
            ..with_sine.drive
        },
        ..with_sine
    };
    for (p, tol) in [(with_sine, TOL), (step_alone, EXACT_TOL)] {
        assert_eq!(Rig1D::new(p).unwrap().exactly, tol == EXACT_TOL);
        drive_step(p, tol);
    }
}

fn drive_step(p: Rig1DParams, tol: f64) {
    let f_ext = -0.25;
    let omega = 2.0 * PI * p.drive.sine.freq;
    let before = Forced {
        m: p.m,
        c: p.c,
        k: p.k,
        f0: f_ext,
        a: p.drive.sine.amp,
        omega,
        ..Default::default()
    };
    let ts = p.drive.t_step;
    let (xs, vs) = before.at(p.x0, 0.0, ts);
    // after the step, in time τ = t − t_step: the sine is shifted by t_step
    let after = Forced {
        f0: f_ext + p.drive.f_step,
        a: p.drive.sine.amp * (omega * ts).cos(),
        b: p.drive.sine.amp * (omega * ts).sin(),
        ..before
    };
    let exact = |t: f64| {
        if t < ts {
            before.at(p.x0, 0.0, t)
        } else {
            after.at(xs, vs, t - ts)
        }
    };
    for h in [1e-3, 1e-2, 0.1] {
        let mut rig = Rig1D::new(p).unwrap();
        let r = run(&mut rig, h, (6.0 / h).round() as usize, |_| {
            (
                Rig1DInputs {
                    f_ext,
                    ..Default::default()
                },
                no_inputs(),
            )
        });
        assert_matches(&format!("h = {h}"), &r, exact, tol);
        assert_eq!(
            rig.drive_force(),
            p.drive.f_step + p.drive.sine.value(rig.time())
        );
    }
}

/// Built-in reference v_ref = v_r0 + V·sin(Ωt), x_ref its integral from
/// x_r0, on the plant m·ẍ + c·ẋ + k·x: the closed loop is linear,
/// m·ẍ + (c + G·Kd)·ẋ + (k + G·(Kp + Ki))·x = G·[(Kp + Ki)·x_ref + Kd·β·v_ref
/// − Ki·(x_r0 − x0)] (ξ = x_ref − x_r0 − (x − x0)), solved in closed form.
/// Position PD, velocity PI (the ±1e-3·sin(t/k) trial of Sun et al. 2016,
/// k = 2) and both together.
#[test]
fn controller_with_builtin_reference_matches_the_closed_form() {
    let base = Rig1DParams {
        m: 1.0,
        c: 2.0,
        k: 0.0,
        v_a: 0.0,
        ..Default::default()
    };
    let pd = Rig1DParams {
        control: Controller {
            mode: Control::BuiltIn,
            kp: 400.0,
            kd: 10.0,
            reference: Reference {
                x0: 0.0,
                v0: 2e-3,
                sine: Sinusoid::new(1e-3, 0.5),
            },
            ..Default::default()
        },
        ..base
    };
    let pi = Rig1DParams {
        control: Controller {
            mode: Control::BuiltIn,
            kd: 20.0,
            ki: 900.0,
            reference: Reference {
                sine: Sinusoid::new(1e-3, 1.0 / (2.0 * PI * 2.0)),
                ..Default::default()
            },
            ..Default::default()
        },
        ..base
    };
    let mixed = Rig1DParams {
        m: 1.5,
        c: 1.0,
        k: 5.0,
        x0: 0.001,
        v0: -0.002,
        control: Controller {
            mode: Control::BuiltIn,
            kp: 300.0,
            kd: 15.0,
            ki: 200.0,
            ff: 0.7,
            gain: 2.0,
            u_max: 0.0,
            reference: Reference {
                x0: 0.003,
                v0: 0.002,
                sine: Sinusoid::new(0.004, 0.8),
            },
        },
        ..base
    };
    // without the sinusoid the reference is a ramp and the rig steps
    // exactly, to rounding
    let ramp = |p: Rig1DParams| {
        let mut p = p;
        p.control.reference.sine = Sinusoid::OFF;
        p
    };
    for (name, p, tol) in [
        ("PD", pd, TOL),
        ("PI", pi, TOL),
        ("PID", mixed, TOL),
        ("PD ramp", ramp(pd), EXACT_TOL),
        ("PID ramp", ramp(mixed), EXACT_TOL),
    ] {
        let g = p.control;
        let r = g.reference;
        let w = r.sine.omega();
        let kk = g.kp + g.ki;
        // x_ref = x_r0 + v_r0·t + (V/Ω)(1 − cos Ωt)
        let sine_mean = if r.sine.is_active() {
            r.sine.amp / w
        } else {
            0.0
        };
        let exact = Forced {
            m: p.m,
            c: p.c + g.gain * g.kd,
            k: p.k + g.gain * kk,
            f0: g.gain * (kk * (r.x0 + sine_mean) + g.kd * g.ff * r.v0 - g.ki * (r.x0 - p.x0)),
            f1: g.gain * kk * r.v0,
            a: g.gain * g.kd * g.ff * r.sine.amp,
            b: -g.gain * kk * sine_mean,
            omega: w,
        };
        assert_eq!(Rig1D::new(p).unwrap().exactly, tol == EXACT_TOL);
        for h in [1e-3, 2e-2] {
            let mut rig = Rig1D::new(p).unwrap();
            let res = run(&mut rig, h, (10.0 / h).round() as usize, |_| {
                (no_inputs(), no_inputs())
            });
            assert_matches(
                &format!("{name}, h = {h}"),
                &res,
                |t| exact.at(p.x0, p.v0, t),
                tol,
            );
        }
    }
}

/// The EMPS loop (Janot et al. 2019; docs/models.md): force =
/// gtau·sat(kv·(kp·(qg − qm) − q̇m), ±10 V) on M·q̈ + Fv·q̇ = force (the
/// benchmark's rigid-body model without Coulomb friction and offset),
/// Kp = kv·kp, Kd = kv, β = 0.
fn emps(u_max: f64) -> Rig1DParams {
    let (kp, kv) = (160.18, 243.45);
    Rig1DParams {
        m: 95.11,
        c: 203.5,
        k: 0.0,
        v_a: 0.0,
        control: Controller {
            mode: Control::Input,
            kp: kv * kp,
            kd: kv,
            ki: 0.0,
            ff: 0.0,
            gain: 35.150_651_88,
            u_max,
            reference: Reference::default(),
        },
        ..Default::default()
    }
}

/// EMPS loop tracking a reference ramp qg = r·t given through x_ref with its
/// slope, unsaturated: M·q̈ + (Fv + G·Kd)·q̇ + G·Kp·q = G·Kp·r·t.
#[test]
fn emps_loop_tracking_a_ramp_matches_the_closed_form() {
    // saturating at ±10 V (sub-stepped Gauss–Legendre), and without the
    // saturation (the exact step)
    for (u_max, tol) in [(10.0, TOL), (0.0, EXACT_TOL)] {
        emps_ramp(emps(u_max), tol);
    }
}

fn emps_ramp(p: Rig1DParams, tol: f64) {
    assert_eq!(Rig1D::new(p).unwrap().exactly, tol == EXACT_TOL);
    let g = p.control;
    let r = 5e-3;
    let exact = Forced {
        m: p.m,
        c: p.c + g.gain * g.kd,
        k: g.gain * g.kp,
        f1: g.gain * g.kp * r,
        ..Default::default()
    };
    let h = 1e-3;
    let inputs = |t: f64| {
        let u = Rig1DInputs {
            x_ref: r * t,
            ..Default::default()
        };
        let du = Rig1DInputs {
            x_ref: r,
            ..Default::default()
        };
        (u, du)
    };
    let mut rig = Rig1D::new(p).unwrap();
    let res = run(&mut rig, h, 1000, inputs);
    // the case stays unsaturated: the largest command along the same run
    let mut rig = Rig1D::new(p).unwrap();
    let mut command: f64 = 0.0;
    for i in 0..1000 {
        let (u, du) = inputs(i as f64 * h);
        rig.step(&u, &du, h);
        command = command.max(rig.control_command(&u.at(&du, h)).abs());
    }
    assert!(command > 0.1 && command < 10.0, "command {command} V");
    assert_matches("EMPS ramp", &res, |t| exact.at(0.0, 0.0, t), tol);
}

/// EMPS loop, step of the reference large enough to saturate the drive
/// (kv·kp·0.01 m = 390 V ≫ 10 V): against an independent piecewise closed
/// form — saturated: M·q̈ + Fv·q̇ = ±gtau·10; linear: the closed loop —
/// with the switching instants found by bisection on the closed forms.
#[test]
fn emps_loop_saturated_step_matches_the_piecewise_closed_form() {
    let p = emps(10.0);
    let g = p.control;
    let target = 0.01;
    let u_of = |x: f64, v: f64| g.kp * (target - x) - g.kd * v;
    let piece_of = |u: f64| -> i8 {
        if u > g.u_max {
            1
        } else if u < -g.u_max {
            -1
        } else {
            0
        }
    };
    let linear = Forced {
        m: p.m,
        c: p.c + g.gain * g.kd,
        k: g.gain * g.kp,
        f0: g.gain * g.kp * target,
        ..Default::default()
    };
    let traj = |piece: i8, x0: f64, v0: f64, tau: f64| -> (f64, f64) {
        if piece == 0 {
            linear.at(x0, v0, tau)
        } else {
            let f = f64::from(piece) * g.gain * g.u_max;
            constant_force_on_damped_mass(p.m, p.c, f, x0, v0, tau)
        }
    };
    // the reference: pieces and their start (t0, x0, v0)
    let t_end = 1.0;
    let mut pieces = vec![(0.0, 0.0, 0.0, piece_of(u_of(0.0, 0.0)))];
    loop {
        let &(t0, x0, v0, piece) = pieces.last().unwrap();
        let scan = 1e-5;
        let mut tau = 0.0;
        let mut hit = None;
        while t0 + tau < t_end {
            let next = tau + scan;
            let (x, v) = traj(piece, x0, v0, next);
            let q = piece_of(u_of(x, v));
            if q != piece {
                hit = Some((tau, next, q));
                break;
            }
            tau = next;
        }
        let Some((mut a, mut b, q)) = hit else { break };
        let side = if piece == 0 { q } else { piece };
        let boundary = f64::from(side) * g.u_max;
        let g_at = |tau: f64| {
            let (x, v) = traj(piece, x0, v0, tau);
            u_of(x, v) - boundary
        };
        let ga = g_at(a);
        for _ in 0..200 {
            let c = 0.5 * (a + b);
            if (g_at(c) > 0.0) == (ga > 0.0) {
                a = c;
            } else {
                b = c;
            }
        }
        let (x, v) = traj(piece, x0, v0, b);
        pieces.push((t0 + b, x, v, if piece == 0 { q } else { 0 }));
    }
    assert!(
        pieces.len() >= 2,
        "the step must saturate and come out: {pieces:?}"
    );
    let exact = |t: f64| {
        let &(t0, x0, v0, piece) = pieces.iter().rev().find(|s| s.0 <= t).unwrap();
        traj(piece, x0, v0, t - t0)
    };
    for h in [1e-3, 1e-2] {
        let mut rig = Rig1D::new(p).unwrap();
        let res = run(&mut rig, h, (t_end / h).round() as usize, |_| {
            (
                Rig1DInputs {
                    x_ref: target,
                    ..Default::default()
                },
                no_inputs(),
            )
        });
        assert_matches(&format!("EMPS saturated step, h = {h}"), &res, exact, TOL);
    }
}

/// Moving, dithered surface x_s = v_surface·t + A·sin(Ωt): the body (no
/// friction) oscillates freely, and the outputs are v = ẋ − v_s(t) and
/// x − x_s(t) with v_s = v_surface + AΩ·cos(Ωt).
#[test]
fn surface_dither_gives_slip_velocity_and_relative_displacement() {
    let p = Rig1DParams {
        m: 0.5,
        c: 0.3,
        k: 20.0,
        v_a: 0.0,
        x0: 0.01,
        v_surface: 0.03,
        dither: Sinusoid::new(1e-3, 25.0),
        ..Default::default()
    };
    let free = Forced {
        m: p.m,
        c: p.c,
        k: p.k,
        ..Default::default()
    };
    let w = 2.0 * PI * p.dither.freq;
    let h = 1e-3;
    let mut rig = Rig1D::new(p).unwrap();
    let (mut slip, mut slip_exact, mut rel, mut rel_exact) = (vec![], vec![], vec![], vec![]);
    for i in 1..=2000 {
        rig.step(&no_inputs(), &no_inputs(), h);
        let t = i as f64 * h;
        let (x, v) = free.at(p.x0, p.v0, t);
        slip.push(rig.slip_velocity());
        slip_exact.push(v - (p.v_surface + p.dither.amp * w * (w * t).cos()));
        rel.push(rig.relative_displacement(&no_inputs()));
        rel_exact.push(x - (p.v_surface * t + p.dither.amp * (w * t).sin()));
        // exactly the difference of the body and surface velocities
        assert_eq!(
            rig.slip_velocity(),
            rig.velocity() - rig.surface_velocity(rig.time())
        );
    }
    assert!(worst(&slip, &slip_exact) <= TOL * peak(&slip_exact));
    assert!(worst(&rel, &rel_exact) <= TOL * peak(&rel_exact));
}

#[test]
fn quasi_static_force_balance_and_feedthrough() {
    let p = Rig1DParams {
        m: 0.0,
        c: 0.0,
        k: 116.04e3,
        v_a: 8.25e-8,
        ..Default::default()
    };
    let mut rig = Rig1D::new(p).unwrap();
    rig.step(&no_inputs(), &no_inputs(), 1.0);
    let f = |friction| Rig1DInputs {
        friction,
        ..Default::default()
    };
    assert_eq!(rig.position(&f(0.1)), 8.25e-8 - 0.1 / 116.04e3);
    assert_eq!(rig.velocity(), 8.25e-8);

    // Appels & Herder's piezo staircase from the input, a drive step, F_ext:
    // x = x_act_in + (F_ext − F + F_d)/k; ẋ from the slopes of the last step
    let p = Rig1DParams {
        m: 0.0,
        c: 0.0,
        k: 116.04e3,
        actuator: Actuator::Input,
        drive: DriveForce {
            f_step: 0.05,
            t_step: 0.5,
            sine: Sinusoid::OFF,
        },
        ..Default::default()
    };
    let mut rig = Rig1D::new(p).unwrap();
    let (mut x_act, h) = (0.0, 1e-2);
    for i in 0..100 {
        x_act += 0.825e-9;
        let u = Rig1DInputs {
            friction: 0.02,
            f_ext: 0.01,
            x_act,
            ..Default::default()
        };
        let du = Rig1DInputs {
            friction: 0.3,
            ..Default::default()
        };
        rig.step(&u, &du, h);
        let t = (i + 1) as f64 * h;
        let drive = if t >= 0.5 { 0.05 } else { 0.0 };
        let u1 = u.at(&du, h);
        let expected = x_act + (0.01 - u1.friction + drive) / p.k;
        assert!((rig.position(&u1) - expected).abs() <= 1e-15 * expected.abs().max(1e-9));
        assert!((rig.velocity() - (-0.3 / p.k)).abs() <= 1e-15);
    }
}

/// Quasi-static with damping, c·ẋ + k·x = k·v_a·t − F (F constant):
/// x = v_a·(t − c/k) − F/k + (x0 + F/k + v_a·c/k)·e^(−kt/c).
#[test]
fn quasi_static_damped_matches_the_closed_form() {
    let p = Rig1DParams {
        m: 0.0,
        c: 2.0,
        k: 50.0,
        v_a: 0.01,
        x0: 0.002,
        ..Default::default()
    };
    let friction = 0.3;
    let exact = |t: f64| {
        let e = (-p.k * t / p.c).exp();
        let x = p.v_a * (t - p.c / p.k) - friction / p.k
            + (p.x0 + friction / p.k + p.v_a * p.c / p.k) * e;
        let v = p.v_a - p.k / p.c * (p.x0 + friction / p.k + p.v_a * p.c / p.k) * e;
        (x, v)
    };
    for h in [1e-3, 0.1] {
        let mut rig = Rig1D::new(p).unwrap();
        let r = run(&mut rig, h, (2.0 / h).round() as usize, |_| {
            (
                Rig1DInputs {
                    friction,
                    ..Default::default()
                },
                no_inputs(),
            )
        });
        assert_matches(&format!("h = {h}"), &r, exact, TOL);
    }
}

#[test]
fn state_round_trip_reproduces_the_run_bit_for_bit() {
    let mut p = emps(10.0);
    p.dither = Sinusoid::new(1e-4, 3.0);
    p.drive.sine = Sinusoid::new(5.0, 2.0);
    let mut a = Rig1D::new(p).unwrap();
    let u = Rig1DInputs {
        x_ref: 0.01,
        friction: 20.0,
        ..Default::default()
    };
    for _ in 0..50 {
        a.step(&u, &no_inputs(), 1e-3);
    }
    let saved = a.state_to_vec();
    let mut b = Rig1D::new(p).unwrap();
    b.state_from_slice(&saved).unwrap();
    for _ in 0..200 {
        a.step(&u, &no_inputs(), 1e-3);
        b.step(&u, &no_inputs(), 1e-3);
        assert_eq!(a.state_to_vec(), b.state_to_vec());
    }
    assert!(b.state_from_slice(&[0.0, 1.0, f64::NAN, 0.0]).is_err());
    assert!(b.state_from_slice(&[0.0, 1.0]).is_err());
}

#[test]
fn invalid_parameters_are_refused_with_name_and_value() {
    let d = Rig1DParams::default();
    let cases: Vec<(Rig1DParams, &str)> = vec![
        (Rig1DParams { m: -1.0, ..d }, "m = -1"),
        (Rig1DParams { m: f64::NAN, ..d }, "m = NaN"),
        (Rig1DParams { k: -2.0, ..d }, "k = -2"),
        (
            Rig1DParams {
                v_a: f64::INFINITY,
                ..d
            },
            "v_a = inf",
        ),
        (
            Rig1DParams {
                dither: Sinusoid::new(1e-3, -5.0),
                ..d
            },
            "dither_freq = -5",
        ),
        (
            Rig1DParams {
                drive: DriveForce {
                    t_step: f64::NAN,
                    ..d.drive
                },
                ..d
            },
            "t_step = NaN",
        ),
        (
            Rig1DParams {
                control: Controller {
                    kd: -3.0,
                    ..d.control
                },
                ..d
            },
            "ctrl_kd = -3",
        ),
        (
            Rig1DParams {
                control: Controller {
                    ff: 2.0,
                    ..d.control
                },
                ..d
            },
            "ctrl_ff = 2",
        ),
        (
            Rig1DParams {
                m: 0.0,
                control: Controller {
                    mode: Control::BuiltIn,
                    ..d.control
                },
                ..d
            },
            "control = 1",
        ),
        (
            Rig1DParams {
                m: 0.0,
                k: 0.0,
                ..d
            },
            "m = 0, k = 0, c = 0",
        ),
    ];
    for (p, needle) in cases {
        let e = Rig1D::new(p).unwrap_err();
        assert!(e.contains(needle), "{needle}: {e}");
    }
    assert!(Actuator::from_code(2).unwrap_err().contains("actuator = 2"));
    assert!(Control::from_code(-1).unwrap_err().contains("control = -1"));
    for code in 0..2 {
        assert_eq!(Actuator::from_code(code).unwrap().code(), code);
    }
    for code in 0..3 {
        assert_eq!(Control::from_code(code).unwrap().code(), code);
    }
}

/// A damped rig in the plain mode, started off its rest point, on a belt
/// with a dither.
fn damped_on_a_moving_surface() -> Rig1DParams {
    Rig1DParams {
        m: 0.5,
        c: 0.3,
        k: 20.0,
        x0: 0.01,
        v0: -0.02,
        v_a: 0.05,
        x_a0: 0.001,
        v_surface: 0.01,
        dither: Sinusoid::new(1e-4, 30.0),
        ..Default::default()
    }
}

/// The plain mode's step (no controller, drive or actuator sinusoid) is
/// the general path's arithmetic, bit for bit, with ramped inputs, steps of
/// several lengths and a dither, damped and undamped.
#[test]
fn plain_step_is_the_general_step_bit_for_bit() {
    for p in [Rig1DParams::default(), damped_on_a_moving_surface()] {
        let mut plain = Rig1D::new(p).unwrap();
        let mut general = Rig1D::new(p).unwrap();
        assert!(plain.plain);
        for i in 0..2000 {
            let h = 1e-3 * (1.0 + 0.25 * (i % 3) as f64);
            let t = plain.time();
            let u = Rig1DInputs {
                friction: 0.5 * (7.0 * t).sin() + 0.2,
                f_ext: 0.1 * (3.0 * t).cos(),
                ..Default::default()
            };
            let du = Rig1DInputs {
                friction: 3.5 * (7.0 * t).cos(),
                f_ext: -0.3 * (3.0 * t).sin(),
                ..Default::default()
            };
            plain.step(&u, &du, h);
            general.step_general(&u, &du, h);
            let bits = |r: &Rig1D| {
                r.state_to_vec()
                    .iter()
                    .map(|x| x.to_bits())
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&plain), bits(&general), "step {i}");
        }
    }
}

/// A refused state is named as before the message moved out of line; the
/// slice writer writes what the vector writer appends.
#[test]
fn refused_states_are_named_and_written_states_agree() {
    let mut rig = Rig1D::new(Rig1DParams::default()).unwrap();
    let err = rig
        .state_from_slice(&[0.0, 1.0, f64::NAN, 0.0])
        .unwrap_err();
    assert_eq!(
        err,
        "Rig1D state must be 4 finite numbers, got [0.0, 1.0, NaN, 0.0]"
    );
    rig.state_from_slice(&[0.5, 1e-3, -2e-3, 0.0]).unwrap();
    let mut s = vec![f64::NAN; rig.state_len()];
    rig.write_state_into(&mut s);
    assert_eq!(s, rig.state_to_vec());
}

/// The plain step's sensitivity to a held friction force against central
/// differences of the step itself (linear in F: exact up to the rounding
/// of the differences, ten times ε·|y|/d of each output, |y| its size or
/// that of the k·x it is a difference of), damped and
/// undamped, stiff and soft, with a moving surface and F_ext, at steps
/// from ω·h = 1e-5 to 25 (the step is exact at any length); and `None` in
/// every other mode.
#[test]
fn held_step_sensitivity_to_the_friction_force_matches_differences() {
    let soft = Rig1DParams::default();
    let stiff = Rig1DParams {
        m: 0.2,
        c: 3.0,
        k: 5e4,
        x0: 1e-3,
        ..damped_on_a_moving_surface()
    };
    let mut compared = 0;
    for p in [soft, stiff] {
        let omega = Rig1D::new(p).unwrap().omega;
        for h in [1e-5, 1e-4, 1e-3, 0.0199 / omega, 0.05] {
            let mut rig = Rig1D::new(p).unwrap();
            let u = |friction: f64| Rig1DInputs {
                friction,
                f_ext: 0.1,
                ..Default::default()
            };
            // somewhere along a run
            for i in 0..50 {
                rig.step(&u(0.3 * (i as f64).sin()), &no_inputs(), h);
            }
            let before = rig.clone();
            let f = 0.4;
            rig.step(&u(f), &no_inputs(), h);
            let s = rig.held_step_sensitivity(h).expect("the plain path");
            // the step's own weights or weights formed for the length
            // asked: the same
            let mut other = rig.clone();
            other.exact = ExactStep::UNFORMED;
            assert_eq!(other.held_step_sensitivity(h), Some(s));
            // the outputs after a step with F + k·d held
            let outputs = |k: f64, d: f64| {
                let mut r = before.clone();
                let u = u(f + k * d);
                r.step(&u, &no_inputs(), h);
                [
                    r.position(&u),
                    r.velocity(),
                    r.slip_velocity(),
                    r.relative_displacement(&u),
                    r.acceleration(&u),
                    r.spring_force(&u),
                    r.applied_force(&u),
                ]
            };
            let d = 1e-3;
            let (a, b) = (outputs(1.0, d), outputs(-1.0, d));
            let got = [
                s.x,
                s.xd,
                s.xd,
                s.x,
                s.acceleration,
                s.spring_force,
                s.applied_force,
            ];
            // the size each output is rounded at: the spring force, the
            // acceleration and the applied force are differences of terms
            // of k·x
            let spring = p.k * a[0].abs().max(a[5].abs() / p.k);
            let rounded_at = [a[0], a[1], a[2], a[3], spring / p.m, spring, spring];
            for k in 0..7 {
                let fd = (a[k] - b[k]) / (2.0 * d);
                let size = a[k].abs().max(b[k].abs()).max(rounded_at[k].abs());
                let noise = 10.0 * f64::EPSILON * size / d;
                assert!(
                    (got[k] - fd).abs() <= 1e-9 * fd.abs() + noise,
                    "output {k}, h {h}: {:e} vs differences {fd:e} (noise {noise:e})",
                    got[k]
                );
                compared += 1;
            }
            // ∂ẋ⁺/∂F ≈ −h/m, ∂x⁺/∂F ≈ −h²/2m while ω·h is small
            if omega * h <= 0.02 {
                assert!((s.xd + h / p.m).abs() <= 1e-3 * h / p.m, "{s:?}");
                assert!((s.x + h * h / (2.0 * p.m)).abs() <= 1e-3 * h * h / p.m);
            }
        }
    }
    assert_eq!(compared, 2 * 5 * 7);
    // the modes that do not take the plain path
    for p in [
        Rig1DParams {
            m: 0.0,
            c: 1.0,
            ..soft
        },
        Rig1DParams {
            act_sine: Sinusoid::new(1e-3, 2.0),
            ..soft
        },
        Rig1DParams {
            drive: DriveForce {
                f_step: 0.5,
                ..Default::default()
            },
            ..soft
        },
        Rig1DParams {
            control: Controller {
                mode: Control::BuiltIn,
                kp: 10.0,
                ..Default::default()
            },
            ..soft
        },
    ] {
        let mut rig = Rig1D::new(p).unwrap();
        rig.step(&no_inputs(), &no_inputs(), 1e-4);
        assert_eq!(rig.held_step_sensitivity(1e-4), None, "{p:?}");
    }
}

/// A PID controller on its built-in sinusoidal reference, unsaturated.
fn built_in_pid() -> Controller {
    Controller {
        mode: Control::BuiltIn,
        kp: 40.0,
        kd: 3.0,
        ki: 5.0,
        ff: 0.7,
        gain: 2.0,
        u_max: 0.0,
        reference: Reference {
            x0: 0.01,
            v0: 2e-3,
            sine: Sinusoid::new(1e-3, 0.8),
        },
    }
}

/// `outputs` gives each output bit for bit as its single-output function
/// does, in every mode of the rig: the default (plain) mode, a damped rig
/// on a dithered belt, the actuator sinusoid and the actuator input, the
/// drive step (before, at and after t_step) and sinusoid, the built-in and
/// the input reference of the controller with and without saturation, the
/// quasi-static modes (c = 0: position fed through; c > 0), over states
/// reached by stepping and states set directly (signed zeros included),
/// and inputs of both signs, zeros of both signs among them.
#[test]
fn all_outputs_at_once_are_the_single_outputs_bit_for_bit() {
    let pd = built_in_pid();
    let sets = [
        Rig1DParams::default(),
        damped_on_a_moving_surface(),
        Rig1DParams {
            act_sine: Sinusoid::new(2e-3, 5.0),
            dither: Sinusoid::new(1e-4, 30.0),
            v_surface: -0.02,
            ..damped_on_a_moving_surface()
        },
        Rig1DParams {
            actuator: Actuator::Input,
            act_sine: Sinusoid::new(2e-3, 5.0), // unused with the input
            drive: DriveForce {
                f_step: 0.7,
                t_step: 0.05,
                sine: Sinusoid::new(0.3, 1.0),
            },
            ..damped_on_a_moving_surface()
        },
        Rig1DParams {
            control: pd,
            ..damped_on_a_moving_surface()
        },
        Rig1DParams {
            control: Controller { u_max: 0.05, ..pd },
            drive: DriveForce {
                f_step: -0.4,
                t_step: 0.02,
                sine: Sinusoid::OFF,
            },
            ..damped_on_a_moving_surface()
        },
        emps(10.0),
        emps(0.5),
        Rig1DParams {
            m: 0.0,
            c: 0.0,
            k: 1e3,
            v_a: 8.25e-8,
            drive: DriveForce {
                f_step: 0.5,
                t_step: 0.03,
                sine: Sinusoid::new(0.2, 3.0),
            },
            dither: Sinusoid::new(1e-6, 50.0),
            ..Default::default()
        },
        Rig1DParams {
            m: 0.0,
            c: 0.0,
            k: 1e3,
            actuator: Actuator::Input,
            ..Default::default()
        },
        Rig1DParams {
            m: 0.0,
            c: 2.0,
            k: 50.0,
            act_sine: Sinusoid::new(1e-3, 2.0),
            drive: DriveForce {
                f_step: 0.1,
                t_step: 0.0,
                sine: Sinusoid::OFF,
            },
            ..Default::default()
        },
    ];
    let bits = |y: &Rig1DOutputs| {
        [
            y.position,
            y.slip_velocity,
            y.acceleration,
            y.spring_force,
            y.actuator_position,
            y.relative_displacement,
            y.velocity,
            y.drive_force,
            y.control_command,
            y.control_force,
            y.applied_force,
        ]
        .map(f64::to_bits)
    };
    let check = |rig: &Rig1D, u: &Rig1DInputs, what: &str| {
        let single = Rig1DOutputs {
            position: rig.position(u),
            slip_velocity: rig.slip_velocity(),
            acceleration: rig.acceleration(u),
            spring_force: rig.spring_force(u),
            actuator_position: rig.actuator_position(u),
            relative_displacement: rig.relative_displacement(u),
            velocity: rig.velocity(),
            drive_force: rig.drive_force(),
            control_command: rig.control_command(u),
            control_force: rig.control_force(u),
            applied_force: rig.applied_force(u),
        };
        assert_eq!(bits(&rig.outputs(u)), bits(&single), "{what}: {u:?}");
    };
    // inputs of both signs, signed zeros, and ones that cancel
    let inputs = |k: usize| {
        let s = [0.0, -0.0, 0.3, -1.7, 1e-9, 2.5][k % 6];
        Rig1DInputs {
            friction: s,
            f_ext: [-0.0, 0.0, -0.3, 0.9, s][k % 5],
            x_act: [0.0, -0.0, 1e-3, -2e-3][k % 4],
            x_ref: [-0.0, 0.0, 0.02, -0.01][(k / 2) % 4],
            v_ref: [0.0, -0.0, 1e-3, -4e-3][(k / 3) % 4],
        }
    };
    for (n, p) in sets.iter().enumerate() {
        let mut rig = Rig1D::new(*p).unwrap();
        for i in 0..300 {
            let u = inputs(i);
            let du = Rig1DInputs {
                friction: 3.0 * (i as f64).cos(),
                f_ext: -0.5,
                x_act: 0.1,
                x_ref: 2e-3,
                v_ref: 0.01 * (i as f64).sin(),
            };
            rig.step(&u, &du, 5e-4);
            for k in 0..6 {
                check(&rig, &inputs(i + k), &format!("set {n}, step {i}"));
            }
        }
        // states set directly: zeros of both signs, the drive step's instant
        for t in [0.0, -0.0, p.drive.t_step, 0.25] {
            for (x, xd, xi) in [(0.0, 0.0, 0.0), (-0.0, -0.0, -0.0), (0.03, -0.2, 1e-3)] {
                rig.state_from_slice(&[t, x, xd, xi]).unwrap();
                for k in 0..30 {
                    check(&rig, &inputs(k), &format!("set {n}, t {t}, x {x}"));
                }
            }
        }
    }
}

/// `state_is_finite` answers as a scan of the saved state would: each of
/// the four values made NaN or infinite in turn.
#[test]
fn state_is_finite_answers_as_a_scan_of_the_state() {
    let rig = Rig1D::new(Rig1DParams::default()).unwrap();
    assert!(rig.state_is_finite());
    for k in 0..4 {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut r = rig.clone();
            match k {
                0 => r.t = bad,
                1 => r.x = bad,
                2 => r.xd = bad,
                _ => r.xi = bad,
            }
            assert!(!r.state_to_vec().iter().all(|v| v.is_finite()));
            assert!(!r.state_is_finite(), "state value {k} = {bad}");
        }
    }
}

/// F_app of a rig after stepping, against its closed form written out here
/// from the parameters and the state (`closed(rig, u)`), in a run whose
/// friction input changes at every step; at each point, F_app is the same
/// bit for bit whatever the friction input, and a contact holding
/// F = F_app leaves the body without acceleration relative to the
/// surface: m·(ẍ − a_s) = F_app − F = 0 (to the rounding of the forces,
/// `scale`). Returns how many points were compared.
fn check_applied_force(
    p: Rig1DParams,
    u_at: impl Fn(f64) -> Rig1DInputs,
    closed: impl Fn(&Rig1D, &Rig1DInputs) -> f64,
    scale: f64,
) -> usize {
    let mut rig = Rig1D::new(p).unwrap();
    let h = 1e-3;
    let mut n = 0;
    for i in 0..400 {
        let t = rig.time();
        let u = Rig1DInputs {
            friction: 0.7 * (13.0 * t).sin() - 0.2,
            ..u_at(t)
        };
        rig.step(&u, &no_inputs(), h);
        let u = u_at(rig.time());
        let f_app = rig.applied_force(&u);
        let want = closed(&rig, &u);
        assert!(
            (f_app - want).abs() <= 1e-12 * scale,
            "step {i}: F_app {f_app:e}, closed form {want:e}"
        );
        for friction in [0.0, -0.0, 1.5, -3.0, 1e6] {
            let other = rig.applied_force(&Rig1DInputs { friction, ..u });
            assert_eq!(other.to_bits(), f_app.to_bits(), "F = {friction}");
        }
        let held = Rig1DInputs {
            friction: f_app,
            ..u
        };
        let relative = rig.acceleration(&held) - rig.surface_acceleration();
        assert!(
            (p.m * relative).abs() <= 1e-12 * scale,
            "step {i}: m·(a − a_s) = {:e} with F = F_app",
            p.m * relative
        );
        n += 1;
    }
    n
}

/// F_app = k·(x_a − x) − c·ẋ + F_ext + F_d + F_ctrl − m·a_s, each term
/// written out from the parameters, in every mode with a mass: the spring
/// to a moving (ramped and sinusoidal) actuator with a damper and F_ext on
/// a belt whose dither accelerates it (the inertial term −m·a_s), the
/// actuator from its input with the drive step and sinusoid, and the
/// controller (built-in reference; input reference, saturating).
#[test]
fn applied_force_is_every_force_but_friction_with_a_mass() {
    let tau = 2.0 * PI;
    let f_ext = |t: f64| 0.3 + 0.1 * (5.0 * t).cos();
    // a_s = −A·ω²·sin ωt of the dither, written out
    let surface_acc = |p: &Rig1DParams, t: f64| {
        let w = tau * p.dither.freq;
        -p.dither.amp * w * w * (w * t).sin()
    };
    let mut compared = 0;

    // spring to a moving actuator, damper, F_ext, dithered belt
    let p = Rig1DParams {
        act_sine: Sinusoid::new(2e-3, 3.0),
        dither: Sinusoid::new(2e-4, 25.0),
        ..damped_on_a_moving_surface()
    };
    assert!(surface_acc(&p, 0.01).abs() > 1.0, "the belt accelerates");
    compared += check_applied_force(
        p,
        |t| Rig1DInputs {
            f_ext: f_ext(t),
            ..Default::default()
        },
        |rig, u| {
            let t = rig.time();
            let x_a = p.x_a0 + p.v_a * t + p.act_sine.amp * (tau * p.act_sine.freq * t).sin();
            p.k * (x_a - rig.position(u)) - p.c * rig.velocity() + u.f_ext
                - p.m * surface_acc(&p, t)
        },
        1.0,
    );

    // the actuator point from its input, with the drive force step and sine
    let p = Rig1DParams {
        actuator: Actuator::Input,
        drive: DriveForce {
            f_step: 0.6,
            t_step: 0.1234,
            sine: Sinusoid::new(0.25, 2.0),
        },
        ..damped_on_a_moving_surface()
    };
    compared += check_applied_force(
        p,
        |t| Rig1DInputs {
            f_ext: f_ext(t),
            x_act: 0.01 * t + 1e-3 * (7.0 * t).sin(),
            ..Default::default()
        },
        |rig, u| {
            let t = rig.time();
            let step = if t >= 0.1234 { 0.6 } else { 0.0 };
            let drive = step + 0.25 * (tau * 2.0 * t).sin();
            p.k * (u.x_act - rig.position(u)) - p.c * rig.velocity() + u.f_ext + drive
                - p.m * surface_acc(&p, t)
        },
        1.0,
    );

    // the controller: built-in reference (unsaturated), and the input
    // reference with saturation (the EMPS loop, stiff: its forces are
    // G·Kp·|x| ~ 1e3 N)
    let builtin = Rig1DParams {
        control: built_in_pid(),
        ..damped_on_a_moving_surface()
    };
    for (p, scale) in [(builtin, 1.0), (emps(10.0), 1e3)] {
        let input_reference = p.control.mode == Control::Input;
        let reference = move |t: f64| {
            if input_reference {
                (0.02 * (tau * t).sin(), 0.02 * tau * (tau * t).cos())
            } else {
                (0.0, 0.0)
            }
        };
        compared += check_applied_force(
            p,
            |t| {
                let (x_ref, v_ref) = reference(t);
                Rig1DInputs {
                    f_ext: f_ext(t),
                    x_ref,
                    v_ref,
                    ..Default::default()
                }
            },
            |rig, u| {
                let t = rig.time();
                let g = &p.control;
                let (x_ref, v_ref) = if input_reference {
                    (u.x_ref, u.v_ref)
                } else {
                    let r = &g.reference;
                    let w = tau * r.sine.freq;
                    (
                        r.x0 + r.v0 * t + r.sine.amp / w * (1.0 - (w * t).cos()),
                        r.v0 + r.sine.amp * (w * t).sin(),
                    )
                };
                let (x, xd) = (rig.position(u), rig.velocity());
                let command = g.kp * (x_ref - x) + g.kd * (g.ff * v_ref - xd) + g.ki * rig.xi;
                let command = if g.u_max > 0.0 {
                    command.clamp(-g.u_max, g.u_max)
                } else {
                    command
                };
                let x_a = p.x_a0 + p.v_a * t;
                p.k * (x_a - x) - p.c * xd + u.f_ext + g.gain * command - p.m * surface_acc(&p, t)
            },
            scale,
        );
    }
    assert_eq!(compared, 4 * 400);
}

/// The quasi-static rig (m = 0, c = 0), where the position follows F at
/// once: F_app = k·(x_a − x_h) + F_ext + F_d, x_h the held position (the
/// position at the start of the last step, carried with the surface), not
/// a function of F. A contact that holds F = F_app at every communication
/// point (what a stuck Classical contact does under the Jacobi master)
/// keeps the body where it was on the surface, x − x_s(t) = x0 (the held
/// position before the first step), while F_app
/// grows with the actuator: the spring force at the held position. Ramped
/// actuator and F_ext, a drive step, a dithered belt; and the piezo
/// staircase through `x_act_in`.
#[test]
fn applied_force_quasi_static_holds_the_body_where_it_was() {
    let k = 116.04e3;
    for actuator in [Actuator::Prescribed, Actuator::Input] {
        let p = Rig1DParams {
            m: 0.0,
            c: 0.0,
            k,
            actuator,
            x_a0: 2e-6,
            x0: 2e-6,
            v_a: 8.25e-8,
            v_surface: 1e-7,
            dither: Sinusoid::new(1e-8, 3.0),
            drive: DriveForce {
                f_step: 0.05,
                t_step: 0.5,
                sine: Sinusoid::OFF,
            },
            ..Default::default()
        };
        let x_act = |t: f64| match actuator {
            Actuator::Prescribed => p.x_a0 + p.v_a * t,
            // 0.825e-9 m every 10 ms from x_a0
            Actuator::Input => p.x_a0 + 0.825e-9 * (t / 1e-2 + 1e-9).floor(),
        };
        let f_ext = |t: f64| 0.01 + 0.02 * t;
        let drive = |t: f64| if t >= 0.5 { 0.05 } else { 0.0 };
        let mut rig = Rig1D::new(p).unwrap();
        // before the first step: held at x0 (here the relaxed spring)
        let x_held0 = p.x0;
        let u0 = Rig1DInputs {
            f_ext: f_ext(0.0),
            x_act: x_act(0.0),
            ..Default::default()
        };
        assert_eq!(rig.applied_force(&u0), k * (p.x_a0 - x_held0) + f_ext(0.0));
        let h = 1e-2;
        let mut force = rig.applied_force(&u0);
        for i in 0..100 {
            let t = rig.time();
            let u = Rig1DInputs {
                friction: force,
                f_ext: f_ext(t),
                x_act: x_act(t),
                ..Default::default()
            };
            // the body where the contact holds it, relative to the surface
            let relative = rig.relative_displacement(&u);
            assert!(
                (relative - x_held0).abs() <= 1e-15,
                "t = {t}: x − x_s = {relative:e}, held at {x_held0:e}"
            );
            rig.step(&u, &no_inputs(), h);
            let t = rig.time();
            let u = Rig1DInputs {
                f_ext: f_ext(t),
                x_act: x_act(t),
                ..Default::default()
            };
            force = rig.applied_force(&u);
            let x_held = x_held0 + rig.surface_position(t);
            let want = k * (x_act(t) - x_held) + f_ext(t) + drive(t);
            assert!(
                (force - want).abs() <= 1e-9 * want.abs(),
                "step {i}: F_app {force:e}, closed form {want:e}"
            );
            for friction in [0.0, 0.3, -2.0] {
                let other = rig.applied_force(&Rig1DInputs { friction, ..u });
                assert_eq!(other.to_bits(), force.to_bits());
            }
        }
        // the spring took the actuator's travel: F_app grew by k·Δx_a
        let travel = x_act(1.0) - x_act(0.0) - rig.surface_position(1.0);
        assert!(travel.abs() > 1e-9);
        let grown = force - (f_ext(1.0) + 0.05);
        assert!(
            (grown - k * travel).abs() <= 1e-9 * (k * travel).abs(),
            "{actuator:?}: {grown:e} vs k·travel {:e}",
            k * travel
        );
    }
}

/// The damped quasi-static rig (m = 0, c > 0):
/// F_app = k·(x_a − x) + F_ext + F_d − c·v_s(t), the force for which
/// c·ẋ = k·(x_a − x) + F_ext − F + F_d gives ẋ = v_s (no slip); not a
/// function of F.
#[test]
fn applied_force_quasi_static_damped_gives_no_slip() {
    let p = Rig1DParams {
        m: 0.0,
        c: 2.0,
        k: 50.0,
        v_a: 0.01,
        x0: 0.002,
        v_surface: 0.003,
        dither: Sinusoid::new(1e-4, 4.0),
        drive: DriveForce {
            f_step: 0.1,
            t_step: 0.2,
            sine: Sinusoid::new(0.05, 1.5),
        },
        ..Default::default()
    };
    let tau = 2.0 * PI;
    let compared = check_applied_force_without_mass(p, |rig, u| {
        let t = rig.time();
        let v_s = p.v_surface + 1e-4 * tau * 4.0 * (tau * 4.0 * t).cos();
        let drive = if t >= 0.2 { 0.1 } else { 0.0 } + 0.05 * (tau * 1.5 * t).sin();
        p.k * (p.v_a * t - rig.position(u)) + u.f_ext + drive - p.c * v_s
    });
    assert_eq!(compared, 300);
}

/// [`check_applied_force`] for the damped quasi-static rig, where the
/// property is of the velocity: with F = F_app the balance gives ẋ = v_s.
fn check_applied_force_without_mass(
    p: Rig1DParams,
    closed: impl Fn(&Rig1D, &Rig1DInputs) -> f64,
) -> usize {
    let mut rig = Rig1D::new(p).unwrap();
    let mut n = 0;
    for i in 0..300 {
        let t = rig.time();
        let u = Rig1DInputs {
            friction: 0.4 * (9.0 * t).cos(),
            f_ext: 0.05 * t,
            ..Default::default()
        };
        rig.step(&u, &no_inputs(), 1e-3);
        let u = Rig1DInputs {
            f_ext: 0.05 * rig.time(),
            ..Default::default()
        };
        let f_app = rig.applied_force(&u);
        let want = closed(&rig, &u);
        assert!(
            (f_app - want).abs() <= 1e-13,
            "step {i}: {f_app:e} vs {want:e}"
        );
        let other = rig.applied_force(&Rig1DInputs { friction: 7.0, ..u });
        assert_eq!(other.to_bits(), f_app.to_bits());
        let held = Rig1DInputs {
            friction: f_app,
            ..u
        };
        let slip =
            rig.quasi_static_velocity(&held, &no_inputs()) - rig.surface_velocity(rig.time());
        assert!(
            slip.abs() <= 1e-14,
            "step {i}: slip {slip:e} with F = F_app"
        );
        n += 1;
    }
    n
}

/// The outputs of `o` in a fixed order, for comparisons.
fn output_fields(o: &Rig1DOutputs) -> [f64; 11] {
    [
        o.position,
        o.slip_velocity,
        o.acceleration,
        o.spring_force,
        o.actuator_position,
        o.relative_displacement,
        o.velocity,
        o.drive_force,
        o.control_command,
        o.control_force,
        o.applied_force,
    ]
}

/// [`Rig1D::partials`] equal central differences of the outputs and of
/// (ẋ, ẍ) in every state and input, on each piece of the saturation:
/// a spring pulled through the actuator input with damping and a dither;
/// the controller on an input reference (PD on the position, PI on the
/// velocity), unsaturated and saturated. A change δ of the position
/// moves the controller's integral by −δ (ξ = ∫v_ref dt − (x − x0)).
/// The rig is affine in each, so the differences are exact to rounding.
#[test]
fn partial_derivatives_equal_differences_of_the_outputs() {
    let spring = Rig1DParams {
        m: 2.0,
        c: 3.0,
        k: 500.0,
        actuator: Actuator::Input,
        dither: Sinusoid::new(1e-4, 20.0),
        ..Rig1DParams::default()
    };
    let controller = |u_max: f64| Rig1DParams {
        m: 1.5,
        c: 0.5,
        k: 10.0,
        control: Controller {
            mode: Control::Input,
            kp: 4000.0,
            kd: 60.0,
            ki: 2e4,
            ff: 0.7,
            gain: 1.3,
            u_max,
            reference: Reference::default(),
        },
        ..Rig1DParams::default()
    };
    let knowns = [
        Known::Position,
        Known::Velocity,
        Known::Friction,
        Known::ExternalForce,
        Known::ActuatorInput,
        Known::ReferencePosition,
        Known::ReferenceVelocity,
    ];
    let u = Rig1DInputs {
        friction: 0.4,
        f_ext: -0.2,
        x_act: 2e-3,
        x_ref: 1e-3,
        v_ref: 2e-3,
    };
    // (parameters, whether the command is saturated at the state below)
    for (p, saturated) in [
        (spring, false),
        (controller(0.0), false),
        (controller(0.5), true),
    ] {
        let mut rig = Rig1D::new(p).unwrap();
        rig.step(&u, &no_inputs(), 0.013);
        (rig.x, rig.xd, rig.xi) = (-4e-4, 3e-3, 1e-4);
        let raw = rig.command_at(&rig.here(), 0.0, &u, &no_inputs());
        assert_eq!(rig.p.control.piece(raw) != 0, saturated, "command {raw}");
        for known in knowns {
            let d = rig.partials(&u, known).unwrap();
            let delta = 1e-6;
            let at = |sign: f64| {
                let (mut moved, mut inputs) = (rig.clone(), u);
                let e = sign * delta;
                match known {
                    Known::Position => (moved.x, moved.xi) = (rig.x + e, rig.xi - e),
                    Known::Velocity => moved.xd += e,
                    Known::Friction => inputs.friction += e,
                    Known::ExternalForce => inputs.f_ext += e,
                    Known::ActuatorInput => inputs.x_act += e,
                    Known::ReferencePosition => inputs.x_ref += e,
                    Known::ReferenceVelocity => inputs.v_ref += e,
                }
                let mut all = output_fields(&moved.outputs(&inputs)).to_vec();
                all.push(moved.position_rate(&inputs, &no_inputs()));
                all
            };
            let (up, down) = (at(1.0), at(-1.0));
            let mut given = output_fields(&d.outputs).to_vec();
            given.push(d.position_rate);
            for (i, ((a, b), g)) in up.iter().zip(&down).zip(&given).enumerate() {
                let differenced = (a - b) / (2.0 * delta);
                assert!(
                    (differenced - g).abs() <= 1e-6 * g.abs().max(1.0),
                    "{known:?}, entry {i}: {g} given, {differenced} differenced (saturated: {saturated})"
                );
            }
        }
    }
    // the quasi-static mode has no velocity state
    let quasi_static = Rig1D::new(Rig1DParams {
        m: 0.0,
        ..Rig1DParams::default()
    })
    .unwrap();
    let e = quasi_static.partials(&u, Known::Position).unwrap_err();
    assert!(e.contains("quasi-static mode (m = 0)"), "{e}");
}
