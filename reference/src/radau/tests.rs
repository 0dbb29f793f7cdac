//! The integrator against problems with closed-form solutions and against
//! published reference values, each with an explicit tolerance.

use super::*;

/// `y' = f(t, y)` from a closure.
struct Closure<F: Fn(f64, &[f64], &mut [f64])> {
    n: usize,
    f: F,
}

impl<F: Fn(f64, &[f64], &mut [f64])> OdeSystem for Closure<F> {
    fn dim(&self) -> usize {
        self.n
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        (self.f)(t, y, dydt)
    }
}

fn grid(t_end: f64, n: usize) -> Vec<f64> {
    (1..=n).map(|i| t_end * i as f64 / n as f64).collect()
}

#[test]
fn tableau_is_radau_iia_order_5() {
    let tab = Tableau::new();
    for i in 0..3 {
        let row: f64 = tab.a[i].iter().sum();
        assert!((row - tab.c[i]).abs() < 1e-15, "row {i}: {row}");
    }
    // Quadrature order 5: Σ b_j c_j^(k−1) = 1/k for k = 1..5 (b = last row).
    for k in 1..=5 {
        let s: f64 = (0..3).map(|j| tab.a[2][j] * tab.c[j].powi(k - 1)).sum();
        assert!((s - 1.0 / k as f64).abs() < 1e-15, "k {k}: {s}");
    }
    // γ0 = 1/γ is an eigenvalue of A: det(A − γ0·I) = 0.
    let a = DMatrix::from_fn(3, 3, |i, j| tab.a[i][j]);
    let shifted = &a - DMatrix::identity(3, 3) / tab.gamma;
    assert!(shifted.determinant().abs() < 1e-15);
    assert!((tab.gamma - 3.637_834_252_744_496).abs() < 1e-14);
}

/// x'' + 2ζω·x' + ω²·x = 0, x(0) = 1, x'(0) = 0 (ζ = 0.1, ω = 2π):
/// x = e^(−ζωt)·(cos ωd t + ζω/ωd·sin ωd t), ωd = ω√(1 − ζ²).
fn damped_oscillator_error(rtol: f64) -> (f64, RadauStats) {
    let (zeta, w) = (0.1, 2.0 * std::f64::consts::PI);
    let sys = Closure {
        n: 2,
        f: move |_t, y: &[f64], d: &mut [f64]| {
            d[0] = y[1];
            d[1] = -2.0 * zeta * w * y[1] - w * w * y[0];
        },
    };
    let wd = w * (1.0 - zeta * zeta).sqrt();
    // Few output times, so that the step size control, not the output grid,
    // sets the steps.
    let t_out = grid(5.0, 10);
    let sol = solve(
        &sys,
        0.0,
        &[1.0, 0.0],
        &t_out,
        &RadauOptions::new(rtol, rtol),
    )
    .unwrap();
    let mut worst: f64 = 0.0;
    for (t, y) in sol.t.iter().zip(&sol.y) {
        let e = (-zeta * w * t).exp();
        let x = e * ((wd * t).cos() + zeta * w / wd * (wd * t).sin());
        let v = -e * w * w / wd * (wd * t).sin();
        worst = worst.max((y[0] - x).abs()).max((y[1] - v).abs() / w);
    }
    (worst, sol.stats)
}

#[test]
fn damped_oscillator_at_rtol_1e_10() {
    let (err, stats) = damped_oscillator_error(1e-10);
    // Amplitude 1: the global error is of the order of rtol (observed
    // 1.1e-10).
    assert!(err < 5e-10, "error {err:e} at rtol 1e-10");
    assert_eq!(stats.rejected, 0, "{stats:?}");
    // Tolerance proportionality: each factor 100 in rtol buys between one
    // and three digits, and the error stays within 10·rtol.
    let errors: Vec<f64> = [1e-6, 1e-8, 1e-10, 1e-12]
        .iter()
        .map(|&rtol| {
            let (e, _) = damped_oscillator_error(rtol);
            assert!(e < 10.0 * rtol, "rtol {rtol:e}: error {e:e}");
            e
        })
        .collect();
    for w in errors.windows(2) {
        assert!(w[1] < w[0] / 10.0 && w[1] > w[0] / 1000.0, "{errors:?}");
    }
}

#[test]
fn outputs_land_exactly_on_the_requested_times() {
    let sys = Closure {
        n: 1,
        f: |_t, y: &[f64], d: &mut [f64]| d[0] = -y[0],
    };
    let t_out = [0.0, 1e-9, 0.1, 0.30000000000000004, 2.5, 7.0];
    let sol = solve(&sys, 0.0, &[1.0], &t_out, &RadauOptions::new(1e-10, 1e-12)).unwrap();
    assert_eq!(sol.t, t_out);
    assert_eq!(sol.y[0], vec![1.0]);
    for (t, y) in sol.t.iter().zip(&sol.y) {
        assert!((y[0] - (-t).exp()).abs() < 1e-10, "t {t}");
    }
}

/// y' = A·y with eigenvalues −1 (eigenvector (1, 1)) and −1e6 ((1, −1)):
/// A = [[−(1 + μ)/2, (μ − 1)/2], [(μ − 1)/2, −(1 + μ)/2]], μ = 1e6;
/// y(0) = (2, 0) gives y = e^(−t)·(1, 1) + e^(−μt)·(1, −1).
#[test]
fn stiff_linear_system_with_eigenvalues_minus_1_and_minus_1e6() {
    let mu = 1e6;
    let (p, q) = (-(1.0 + mu) / 2.0, (mu - 1.0) / 2.0);
    let sys = Closure {
        n: 2,
        f: move |_t, y: &[f64], d: &mut [f64]| {
            d[0] = p * y[0] + q * y[1];
            d[1] = q * y[0] + p * y[1];
        },
    };
    // Through the fast transient (t ~ 1e-6) and the slow decay.
    let mut t_out: Vec<f64> = (0..=12).map(|k| 1e-7 * 2f64.powi(k)).collect();
    t_out.extend(grid(10.0, 100));
    let sol = solve(
        &sys,
        0.0,
        &[2.0, 0.0],
        &t_out,
        &RadauOptions::new(1e-10, 1e-12),
    )
    .unwrap();
    for (t, y) in sol.t.iter().zip(&sol.y) {
        let (slow, fast) = ((-t).exp(), (-mu * t).exp());
        let exact = [slow + fast, slow - fast];
        for k in 0..2 {
            let e = (y[k] - exact[k]).abs();
            assert!(e < 2e-10 * exact[k].abs().max(1e-2), "t {t} y{k}: {e:e}");
        }
    }
    // A-stable and stiffly accurate: steps follow the slow mode, not the
    // fast one (an explicit method would need ~1e7 steps over 10 s).
    assert!(sol.stats.accepted < 2000, "{:?}", sol.stats);
}

/// Prothero–Robinson: y' = −μ·(y − cos t) − sin t, y(0) = 2, μ = 1e6;
/// y = cos t + e^(−μt) (stiff, time-dependent forcing: the stage order
/// matters).
#[test]
fn prothero_robinson() {
    let mu = 1e6;
    let sys = Closure {
        n: 1,
        f: move |t, y: &[f64], d: &mut [f64]| d[0] = -mu * (y[0] - t.cos()) - t.sin(),
    };
    let t_out = grid(10.0, 200);
    let sol = solve(&sys, 0.0, &[2.0], &t_out, &RadauOptions::new(1e-10, 1e-10)).unwrap();
    let worst = sol
        .t
        .iter()
        .zip(&sol.y)
        .map(|(t, y)| (y[0] - t.cos() - (-mu * t).exp()).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-10, "worst {worst:e}");
}

/// Van der Pol, μ = 1000 in the scaled form of the IVP test set (Mazzia &
/// Magherini, problem VDPOL): y1' = y2, y2' = ((1 − y1²)·y2 − y1)/ε,
/// ε = 1e-6, y(0) = (2, 0); reference at t = 2 computed with RADAU at
/// rtol = atol = 1.1e-18: y1 = 1.706167732170483, y2 = −0.8928097010247975.
#[test]
fn van_der_pol_mu_1000_against_the_test_set_reference() {
    let eps = 1e-6;
    let sys = Closure {
        n: 2,
        f: move |_t, y: &[f64], d: &mut [f64]| {
            d[0] = y[1];
            d[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / eps;
        },
    };
    let reference = [1.706_167_732_170_483, -0.892_809_701_024_797_5];
    let run = |rtol: f64| {
        let sol = solve(
            &sys,
            0.0,
            &[2.0, 0.0],
            &[2.0],
            &RadauOptions::new(rtol, rtol),
        )
        .unwrap();
        let y = &sol.y[0];
        let err = (0..2)
            .map(|k| (y[k] - reference[k]).abs() / (1.0 + reference[k].abs()))
            .fold(0.0, f64::max);
        (err, sol.stats)
    };
    let (err, stats) = run(1e-10);
    // Observed 2.5e-11.
    assert!(err < 1e-9, "mixed error {err:e} at rtol 1e-10, {stats:?}");
    let (coarse, _) = run(1e-6);
    assert!(coarse > 10.0 * err, "{coarse:e} vs {err:e}");
}

/// Robertson's chemical kinetics (IVP test set, problem ROBER):
/// y1' = −0.04·y1 + 1e4·y2·y3, y2' = 0.04·y1 − 1e4·y2·y3 − 3e7·y2²,
/// y3' = 3e7·y2², y(0) = (1, 0, 0); reference at t = 1e11:
/// (0.2083340149701255e-7, 0.8333360770334713e-13, 0.9999999791665050).
#[test]
fn robertson_to_1e11_against_the_test_set_reference() {
    let sys = Closure {
        n: 3,
        f: |_t, y: &[f64], d: &mut [f64]| {
            d[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
            d[2] = 3e7 * y[1] * y[1];
            d[1] = -d[0] - d[2];
        },
    };
    let reference = [
        0.208_334_014_970_125_5e-7,
        0.833_336_077_033_471_3e-13,
        0.999_999_979_166_505,
    ];
    let opts = RadauOptions::new(1e-10, 1e-10).with_atol(vec![1e-16, 1e-20, 1e-16]);
    let sol = solve(&sys, 0.0, &[1.0, 0.0, 0.0], &[1e11], &opts).unwrap();
    let y = &sol.y[0];
    for k in 0..3 {
        // Observed 1.1e-8 for y1 and y2 (of 2e-8 and 8e-14), 1e-14 for y3.
        let rel = (y[k] - reference[k]).abs() / reference[k];
        assert!(rel < 5e-8, "y{k} = {:e}, rel error {rel:e}", y[k]);
    }
    // Mass is conserved: Σ y' = 0.
    assert!((y.iter().sum::<f64>() - 1.0).abs() < 1e-12);
}

#[test]
fn invalid_inputs_are_refused_with_the_reason() {
    let sys = Closure {
        n: 2,
        f: |_t, y: &[f64], d: &mut [f64]| d.copy_from_slice(y),
    };
    let ok = RadauOptions::new(1e-8, 1e-8);
    let msg = |r: Result<Solution, RadauError>| match r.unwrap_err() {
        RadauError::InvalidInput(m) => m,
        e => panic!("unexpected {e:?}"),
    };
    assert!(msg(solve(&sys, 0.0, &[1.0], &[1.0], &ok)).contains("2 states"));
    assert!(msg(solve(&sys, 0.0, &[f64::NAN, 0.0], &[1.0], &ok)).contains("y0[0]"));
    assert!(msg(solve(&sys, 0.0, &[1.0, 0.0], &[1.0, 1.0], &ok)).contains("t_out[1]"));
    assert!(msg(solve(&sys, 0.0, &[1.0, 0.0], &[-1.0], &ok)).contains("t_out[0]"));
    assert!(msg(solve(&sys, 0.0, &[1.0, 0.0], &[], &ok)).contains("no output"));
    let bad_rtol = RadauOptions::new(0.0, 1e-8);
    assert!(msg(solve(&sys, 0.0, &[1.0, 0.0], &[1.0], &bad_rtol)).contains("rtol"));
    let bad_atol = ok.clone().with_atol(vec![1e-8, 1e-8, 1e-8]);
    assert!(msg(solve(&sys, 0.0, &[1.0, 0.0], &[1.0], &bad_atol)).contains("atol"));
}

#[test]
fn failures_stop_with_the_time_reached() {
    // Blows up at t = 1: y' = y², y(0) = 1, y = 1/(1 − t).
    let blow_up = Closure {
        n: 1,
        f: |_t, y: &[f64], d: &mut [f64]| d[0] = y[0] * y[0],
    };
    match solve(
        &blow_up,
        0.0,
        &[1.0],
        &[2.0],
        &RadauOptions::new(1e-8, 1e-8),
    ) {
        Err(RadauError::StepSizeTooSmall { t, .. })
        | Err(RadauError::NotFinite { t })
        | Err(RadauError::TooManySteps { t, .. }) => {
            assert!(t > 0.99 && t < 1.001, "stopped at {t}")
        }
        other => panic!("expected a failure near t = 1, got {other:?}"),
    }
    // Step limit.
    let decay = Closure {
        n: 1,
        f: |t, _y: &[f64], d: &mut [f64]| d[0] = (100.0 * t).sin(),
    };
    let mut few = RadauOptions::new(1e-10, 1e-10);
    few.max_steps = 5;
    assert!(matches!(
        solve(&decay, 0.0, &[0.0], &[10.0], &few),
        Err(RadauError::TooManySteps { max_steps: 5, .. })
    ));
    // A right-hand side that is NaN beyond t = 0.5.
    let nan = Closure {
        n: 1,
        f: |t, _y: &[f64], d: &mut [f64]| d[0] = if t > 0.5 { f64::NAN } else { 1.0 },
    };
    match solve(&nan, 0.0, &[0.0], &[1.0], &RadauOptions::new(1e-8, 1e-8)) {
        Err(RadauError::NotFinite { t }) | Err(RadauError::StepSizeTooSmall { t, .. }) => {
            assert!((t - 0.5).abs() < 1e-6, "stopped at {t}")
        }
        other => panic!("expected NotFinite near 0.5, got {other:?}"),
    }
}

/// y1' = |y2|, y2' = cos t, y(0) = 0: y2 = sin t, and y1 = ∫|sin t| =
/// 2k + 1 − cos(t − kπ) for t ∈ [kπ, (k+1)π]: a kink of f at each zero of y2.
struct AbsSine {
    switching: bool,
}

impl OdeSystem for AbsSine {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[1].abs();
        d[1] = t.cos();
    }
    fn switching_count(&self) -> usize {
        usize::from(self.switching)
    }
    fn switching(&self, _t: f64, y: &[f64], g: &mut [f64]) {
        g[0] = y[1];
    }
}

#[test]
fn kinks_at_sign_changes_of_a_switching_function() {
    let exact = |t: f64| {
        let k = (t / std::f64::consts::PI).floor();
        2.0 * k + 1.0 - (t - k * std::f64::consts::PI).cos()
    };
    let t_out = [10.0, 20.0];
    let run = |switching: bool| {
        let sol = solve(
            &AbsSine { switching },
            0.0,
            &[0.0, 0.0],
            &t_out,
            &RadauOptions::new(1e-10, 1e-10),
        )
        .unwrap();
        let err = sol
            .t
            .iter()
            .zip(&sol.y)
            .map(|(t, y)| (y[0] - exact(*t)).abs())
            .fold(0.0, f64::max);
        (err, sol.stats)
    };
    let (with, stats) = run(true);
    let (without, plain) = run(false);
    // Observed 1.6e-10 with the six kinks located, 3e-7 without.
    assert!(with < 1e-9, "{with:e}");
    assert_eq!(stats.switches, 6, "{stats:?}");
    assert!(without > 1e-8, "{without:e}");
    assert_eq!(plain.switches, 0);
}

/// A ball dropped from 1 m (y'' = −g) bouncing with restitution e = 0.9:
/// the integration stops at each impact (switching function y), the
/// caller reverses the velocity and continues. Impact times in closed
/// form: t1 = √(2/g), then flights of 2·e^k·v1/g, v1 = g·t1.
#[test]
fn solve_until_switch_stops_at_each_event_for_the_caller() {
    struct Ball;
    impl OdeSystem for Ball {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&self, _t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = y[1];
            d[1] = -9.81;
        }
        fn switching_count(&self) -> usize {
            1
        }
        fn switching(&self, _t: f64, y: &[f64], g: &mut [f64]) {
            g[0] = y[0];
        }
    }
    let (g, e): (f64, f64) = (9.81, 0.9);
    let t1 = (2.0 / g).sqrt();
    let mut exact = vec![t1];
    for k in 1..6 {
        exact.push(exact[k - 1] + 2.0 * e.powi(k as i32) * g * t1 / g);
    }
    let t_out: Vec<f64> = (1..=60).map(|i| i as f64 * 0.1).collect();
    let opts = RadauOptions::new(1e-10, 1e-10);
    let (mut t, mut y) = (0.0, vec![1.0, 0.0]);
    let mut impacts = Vec::new();
    let mut outputs = 0;
    while impacts.len() < 6 {
        let rest: Vec<f64> = t_out.iter().copied().filter(|&s| s > t).collect();
        let end = solve_until_switch(&Ball, t, &y, &rest, &opts, |_, yi| {
            outputs += 1;
            assert!(yi[0] > -1e-9);
        })
        .unwrap();
        assert!(end.switched, "stopped at {} without an impact", end.t);
        impacts.push(end.t);
        (t, y) = (end.t, vec![0.0, -e * end.y[1]]);
    }
    for (k, (a, b)) in impacts.iter().zip(&exact).enumerate() {
        // The flight is a parabola, which the collocation polynomial holds
        // exactly: the impacts are exact to round-off (observed 4e-16 s).
        assert!((a - b).abs() < 1e-12, "impact {k}: {a} vs {b}");
    }
    assert!(outputs > 30, "{outputs} outputs between the impacts");
}
