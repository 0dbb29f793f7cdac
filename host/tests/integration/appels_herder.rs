//! Appels and Herder (TU Delft): the piezo push of the 0.352 kg
//! block through k = 116.04e3 N/m, quasi-static rig (Rig1D, m = 0) against
//! the pre-sliding bristle law (Bristle.fmu, defaults: the paper's), run from
//! `examples/piezo_push.ssd` and `examples/piezo_relaxation.ssd`
//! through the host.
//!
//! The paper's results (docs/models.md, "Reference figures" and "Pre-sliding bristle model"): sliding
//! at σ_ini·δmax = μc·m·g; the transition to sliding completed within
//! 2·δmax of body displacement; after the load is removed the block is
//! pulled back (relaxation), by at most one bristle's largest deflection,
//! and more after a longer pre-sliding displacement (measured slope ≈ 0.30).
//! The rig–bristle loop is algebraic (both sides direct feedthrough, loop
//! gain σ_ini/k ≈ 120): the newton master solves it, jacobi cannot.

use crate::paper_examples;
use fricsim::master::{by_name, simulate};
use paper_examples::*;

const K: f64 = 116.04e3;
const V_A: f64 = 8.25e-8;
/// Bristle.fmu's defaults (Appels and Herder's parameters).
const MU_C: f64 = 0.0633;
const FN: f64 = 0.352 * 9.81;
const DELTA_MAX: f64 = 1.5584e-8;
const X_REL: f64 = 4.4206e-9;

fn level() -> f64 {
    MU_C * FN
}

/// σ_ini = μc·Fn/δmax (stiffness_from_load).
fn sigma_ini() -> f64 {
    level() / DELTA_MAX
}

fn index(t: f64, h: f64) -> usize {
    (t / h).round() as usize
}

/// The zero-load position on the reloading line after a release at sample
/// `i` (the block reloads with the stiffness `s` of all bristles, exactly
/// linear): `x[i] − F[i]/s`, and `s`.
fn zero_load_position(x: &[f64], f: &[f64], i: usize) -> (f64, f64) {
    let s = (f[i + 1] - f[i]) / (x[i + 1] - x[i]);
    (x[i] - f[i] / s, s)
}

#[test]
fn the_push_slides_at_mu_c_m_g_after_a_transition_within_two_delta_max() {
    let file = example("piezo_push.ssd");
    assert_eq!(settings(&file).1, "newton");
    assert_eq!(bound(&file, "rig.k"), K);
    assert_eq!(bound(&file, "rig.v_a"), V_A);
    let run = run(&file);
    let (x, f, xa) = (
        column(&run, "rig.x"),
        column(&run, "friction.F"),
        column(&run, "rig.x_act"),
    );
    // The loop is closed: k·(x_a − x) = F with the friction block's output.
    for i in 0..x.len() {
        let balance = K * (xa[i] - x[i]) - f[i];
        assert!(
            balance.abs() <= 1e-7 * f[i].abs().max(1e-3),
            "t = {}: k(x_a − x) − F = {balance:e}",
            run.time[i]
        );
    }
    // Sliding at μc·m·g = 0.21858 N (the paper: within 1 %; here exact).
    let end = *f.last().unwrap();
    assert!((end / level() - 1.0).abs() < 1e-9, "sliding force {end}");
    // All bristles connected at first: F = σ_ini·x.
    assert!(
        (f[1] / x[1] / sigma_ini() - 1.0).abs() < 1e-6,
        "initial stiffness {:e}",
        f[1] / x[1]
    );
    // The transition is nonlinear: the stiffness only falls as bristles
    // disconnect, from σ_ini to 0 in sliding.
    let onset = f
        .iter()
        .position(|&v| v >= level() * (1.0 - 1e-12))
        .expect("the block reaches sliding");
    let mut stiffness = f64::INFINITY;
    for i in 1..=onset {
        let s = (f[i] - f[i - 1]) / (x[i] - x[i - 1]);
        assert!(s <= stiffness * (1.0 + 1e-6), "stiffness rises at {i}");
        stiffness = s;
    }
    assert!(
        stiffness < 0.5 * sigma_ini(),
        "last pre-sliding stiffness {stiffness:e}"
    );
    // Sliding begins between samples onset − 1 and onset, within 2·δmax.
    assert!(x[onset - 1] < x[onset]);
    assert!(
        x[onset] <= 2.0 * DELTA_MAX,
        "sliding reached at x = {:e} > 2·δmax = {:e}",
        x[onset],
        2.0 * DELTA_MAX
    );
    println!(
        "piezo push: sliding at {:.6} N (μc·m·g = {:.6} N), reached between x = {:.4e} and {:.4e} m (2·δmax = {:.4e} m), t = {} s",
        end,
        level(),
        x[onset - 1],
        x[onset],
        2.0 * DELTA_MAX,
        run.time[onset]
    );
}

#[test]
fn the_push_equals_the_monolithic_reference() {
    // The checked quantities are converged: the exact roots of the force
    // balance at the same times (fricsim reference) agree to rounding.
    let file = example("piezo_push.ssd");
    let (h, _, stop) = settings(&file);
    let run = run(&file);
    let table = reference(&file, h, stop);
    for name in ["rig.x", "friction.F"] {
        let (a, b) = (column(&run, name), table.column(name).unwrap());
        assert_eq!(a.len(), b.len());
        let worst = a
            .iter()
            .zip(&b)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(
            worst <= 1e-12 * max_abs(&b),
            "{name}: differs from the reference by {worst:e}"
        );
    }
}

#[test]
fn jacobi_breaks_the_force_balance_of_the_piezo_loop() {
    // Jacobi gives the rig the friction force of the previous step: with a
    // loop gain of about 120 the block is thrown back and forth and the
    // friction force takes both signs under a push in one direction.
    let file = example("piezo_push.ssd");
    let run = run_with(&file, "jacobi", 1e-2, 1.0);
    let (x, f, xa) = (
        column(&run, "rig.x"),
        column(&run, "friction.F"),
        column(&run, "rig.x_act"),
    );
    let worst = (0..x.len())
        .map(|i| (K * (xa[i] - x[i]) - f[i]).abs())
        .fold(0.0, f64::max);
    assert!(
        worst > 0.5 * level(),
        "jacobi kept the balance to {worst:e} N"
    );
    let min = f.iter().copied().fold(f64::INFINITY, f64::min);
    assert!(
        min < -0.5 * level(),
        "friction never reversed: min F = {min}"
    );
}

#[test]
fn removing_the_load_in_sliding_pulls_the_block_back_by_delta_max_minus_x_rel() {
    let file = example("piezo_relaxation.ssd");
    let (h, master, stop) = settings(&file);
    assert_eq!(master, "newton");
    let t_release = bound(&file, "rig.t_step");
    assert_eq!(bound(&file, "rig.F_step"), -level());
    let relaxation_at = |h: f64| {
        let run = run_with(&file, "newton", h, stop);
        let (x, f) = (column(&run, "rig.x"), column(&run, "friction.F"));
        let i = index(t_release, h);
        // Sliding when released (the load removed is the sliding force).
        assert!((f[i - 1] / level() - 1.0).abs() < 1e-9, "F = {}", f[i - 1]);
        // Pulled back, then reloaded by the moving actuator with the
        // stiffness of all bristles (all reconnected); the difference
        // quotient over one step (7e-12 m) carries newton's interface
        // tolerance (1e-8 of x = 6e-15 m, of which 1e-2 is used).
        assert!(x[i] < x[i - 1], "not pulled back");
        let (x0, s) = zero_load_position(&x, &f, i);
        assert!(
            (s / sigma_ini() - 1.0).abs() < 1e-4,
            "reloading stiffness {s:e}"
        );
        // ...until it slides again.
        assert!((f.last().unwrap() / level() - 1.0).abs() < 1e-9);
        x[i - 1] - x0
    };
    let relaxation = relaxation_at(h);
    // The paper's settling (eqs. 11–13, no bristle connected): the block
    // comes back by the mean deflection of the reconnected bristles,
    // δmax − mean|r|, r ~ Normal(x_rel, x_rel/3): δmax − x_rel on average;
    // the mean of N = 109 draws scatters by (x_rel/3)/√109 = 1.3 % of that.
    let expected = DELTA_MAX - X_REL;
    assert!(
        (relaxation / expected - 1.0).abs() < 0.05,
        "relaxation {relaxation:e} m, δmax − x_rel = {expected:e} m"
    );
    assert!(relaxation < DELTA_MAX);
    // Converged: the relaxation does not depend on the macro step.
    let finer = relaxation_at(h / 2.0);
    assert!(
        (finer / relaxation - 1.0).abs() < 1e-3,
        "h: {relaxation:e}, h/2: {finer:e}"
    );
    // The monolithic reference (which releases at t⁻ = 30 s, one actuator
    // increment later) gives the same relaxation from its turning point.
    let table = reference(&file, h, t_release + 2.0 * h);
    let (x, f) = (
        table.column("rig.x").unwrap(),
        table.column("friction.F").unwrap(),
    );
    let i = index(t_release, h);
    let (x0, _) = zero_load_position(&x, &f, i);
    let turning = reference(&example("piezo_push.ssd"), h, t_release)
        .column("rig.x")
        .unwrap()[i];
    let reference_relaxation = turning - x0;
    assert!(
        (reference_relaxation / relaxation - 1.0).abs() < 1e-6,
        "reference {reference_relaxation:e}, co-simulation {relaxation:e}"
    );
    println!(
        "piezo relaxation after sliding: {relaxation:.5e} m (h/2: {finer:.5e}, reference {reference_relaxation:.5e}; δmax − x_rel = {expected:.5e}, δmax = {DELTA_MAX:e})"
    );
}

#[test]
fn relaxation_grows_with_the_pre_sliding_displacement() {
    // The paper's Experiments 3: push into pre-sliding, remove the load,
    // measure how far the block comes back. Releases every second of the
    // push up to the onset of sliding (about 23 s), each with the load of
    // that instant removed by a drive-force step, solved by the monolithic
    // reference: a property of the law. (Co-simulated with newton, the
    // releases at 20, 21 and 22 s fail: see the ignored test below.)
    let push = example("piezo_push.ssd");
    let h = settings(&push).0;
    let pushed = run(&push);
    let (x_push, f_push) = (column(&pushed, "rig.x"), column(&pushed, "friction.F"));
    let mut points = Vec::new();
    for second in 1..=22 {
        let t = f64::from(second);
        let i = index(t, h);
        assert!(f_push[i] < level() * (1.0 - 1e-9), "sliding at {t} s");
        let mut file = example("piezo_relaxation.ssd");
        set_real(&mut file, "rig.t_step", t);
        set_real(&mut file, "rig.F_step", -f_push[i]);
        let table = reference(&file, h, t + 2.0 * h);
        let (x, f) = (
            table.column("rig.x").unwrap(),
            table.column("friction.F").unwrap(),
        );
        let (x0, s) = zero_load_position(&x, &f, i);
        assert!((s / sigma_ini() - 1.0).abs() < 1e-6);
        let (displacement, relaxation) = (x_push[i], x_push[i] - x0);
        // Backwards, and never more than the push itself.
        assert!(relaxation > 0.0 && relaxation <= displacement * (1.0 + 1e-9));
        points.push((displacement, relaxation));
    }
    // Before the first bristle disconnects the contact is elastic: the
    // block comes all the way back.
    let (d0, r0) = points[0];
    assert!(
        (r0 / d0 - 1.0).abs() < 1e-6,
        "first release {r0:e} of {d0:e}"
    );
    // The trend is growth (single releases scatter with the random
    // reconnection): least-squares slope of relaxation on displacement,
    // over all releases and over the second half of the pre-sliding range.
    let slope = |pts: &[(f64, f64)]| {
        let n = pts.len() as f64;
        let (mx, my) = (
            pts.iter().map(|p| p.0).sum::<f64>() / n,
            pts.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
        sxy / sxx
    };
    let all = slope(&points);
    let late: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|p| p.0 >= DELTA_MAX / 2.0)
        .collect();
    let late_slope = slope(&late);
    assert!(all > 0.0 && all < 1.0, "slope {all}");
    assert!(late_slope > 0.0 && late_slope < all, "slope {late_slope}");
    for (d, r) in &points {
        println!("pre-sliding displacement {d:.4e} m: relaxation {r:.4e} m");
    }
    println!(
        "least-squares slope: {all:.3} over all releases, {late_slope:.3} for displacements ≥ δmax/2 (the paper, measured: ≈ 0.30)"
    );
}

/// The co-simulated counterpart of the reference scan above: the same
/// releases through the host with the newton master. Each release either
/// lands on the backward branch of stiffness σ_ini, as the reference does,
/// or is reported as not converged with its residual; never a wrong answer
/// accepted in silence.
///
/// Known limitation: at 20, 21 and 22 s newton does not converge. The root
/// lies about 1.1e-8 m behind the turning point, on the backward branch; the
/// first Newton step uses the forward stiffness n_c·σb at the turning point
/// (47 bristles at 20 s) and goes about 3e-8 m back, into reverse sliding,
/// and the line search does not recover. Halving the step does not help,
/// since the jump of the load does not shrink with the step.
#[test]
fn newton_solves_or_reports_every_pre_sliding_release() {
    let push = example("piezo_push.ssd");
    let h = settings(&push).0;
    let pushed = run(&push);
    let f_push = column(&pushed, "friction.F");
    let mut solved = 0;
    for second in 1..=22 {
        let t = f64::from(second);
        let i = index(t, h);
        let mut file = example("piezo_relaxation.ssd");
        set_real(&mut file, "rig.t_step", t);
        set_real(&mut file, "rig.F_step", -f_push[i]);
        let mut system = file.build(0.0).unwrap_or_else(|e| panic!("{e}"));
        let mut master = by_name("newton").unwrap();
        let run = simulate(&mut system, master.as_mut(), h, t + 2.0 * h).unwrap();
        match &run.error {
            None => {
                let (x, f) = (column(&run, "rig.x"), column(&run, "friction.F"));
                assert!(x[i] < x[i - 1], "release at {t} s: not pulled back");
                let (_, s) = zero_load_position(&x, &f, i);
                assert!((s / sigma_ini() - 1.0).abs() < 1e-4, "release at {t} s");
                solved += 1;
            }
            Some(e) => {
                assert!(
                    e.contains("did not converge") && e.contains("still differs by"),
                    "release at {t} s: {e}"
                );
            }
        }
    }
    // 19 of the 22 today (see above); fewer means a regression.
    assert!(solved >= 19, "newton solved {solved} of 22 releases");
}
