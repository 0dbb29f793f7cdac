//! Sun et al. 2016: the identification trials of the ~1 kg
//! brass block, run from `examples/lugre_step_force.ssd` (LuGre, force
//! steps) and `examples/dahl_velocity.ssd` (Dahl, velocity
//! control on v = 1e-3·sin(t/k)) through the host.
//!
//! docs/models.md, "Reference figures": a step force below break-away settles at
//! x = F/σ0; Dahl follows its closed form. The second holds to 1e-4 of Fc.
//! The first holds for LuGre's bristle deflection z, not for the position
//! x: z lags x by ∫σ0·|v|·z/g(v) dt, so x exceeds F/σ0 by 13–183 % after
//! a step of 0.5–1.5 N and by 12–59 % under slow loading, where it follows
//! x = −(Fs/σ0)·ln(1 − F/Fs) (the tests check these values; the paper's
//! identification assumed z = x in pre-sliding, eq. 19–21).

use crate::paper_examples;
use paper_examples::*;

/// Sun et al.'s LuGre parameters (examples/lugre_sun2016.ssv).
const SIGMA0: f64 = 66_967.231;
const FS: f64 = 2.35;
const VS: f64 = 1.139_75e-3;
/// Sun et al. Table 7 (Dahl).
const DAHL_FC: f64 = 2.0;
const DAHL_SIGMA: f64 = 87_750.0;

fn last(run: &fricsim::master::Run, name: &str) -> f64 {
    *column(run, name).last().unwrap()
}

/// Pre-sliding position of LuGre loaded slowly to `f` (v → 0, g = Fs):
/// dz/dx = 1 − σ0·z/Fs, F = σ0·z at rest.
fn slow_loading_position(f: f64) -> f64 {
    -(FS / SIGMA0) * (1.0 - f / FS).ln()
}

#[test]
fn step_forces_settle_in_pre_sliding_with_the_bristles_at_f_over_sigma0() {
    let example_file = example("lugre_step_force.ssd");
    assert_eq!(bound(&example_file, "friction.sigma0"), SIGMA0);
    assert_eq!(bound(&example_file, "friction.Fs"), FS);
    assert_eq!(bound(&example_file, "rig.F_step"), 1.0);
    let (h, master, stop) = settings(&example_file);
    // After a step the block overshoots (the force peaks above F), so x
    // carries more of the plastic part ∫σ0·|v|·z/g dt than under slow
    // loading; the ratios x/(F/σ0) of the monolithic reference.
    for (force, ratio) in [(0.5, 1.1349), (1.0, 1.4397), (1.5, 2.8333)] {
        let mut file = example("lugre_step_force.ssd");
        set_real(&mut file, "rig.F_step", force);
        let run = run_with(&file, &master, h, stop);
        // Settled, not sliding: at rest with the friction equal to the force.
        assert!(
            last(&run, "rig.v").abs() < 1e-8,
            "v = {}",
            last(&run, "rig.v")
        );
        assert!((last(&run, "friction.F") / force - 1.0).abs() < 1e-6);
        // The bristles carry the force: z = F/σ0 (their eq. 21 for z).
        let z = last(&run, "friction.z");
        assert!((z * SIGMA0 / force - 1.0).abs() < 1e-6, "z = {z:e}");
        // The position, against the monolithic reference and at half the
        // step: converged to 0.1 %.
        let x = last(&run, "rig.x");
        let x_ref = *reference(&file, h, stop)
            .column("rig.x")
            .unwrap()
            .last()
            .unwrap();
        assert!(
            (x / x_ref - 1.0).abs() < 1e-3,
            "x = {x:e}, reference {x_ref:e}"
        );
        let x_half = last(&run_with(&file, &master, h / 2.0, stop), "rig.x");
        assert!((x_half / x - 1.0).abs() < 1e-3, "h: {x:e}, h/2: {x_half:e}");
        // The paper's x = F/σ0 does not hold for x (see the module text).
        assert!(
            (x_ref * SIGMA0 / force / ratio - 1.0).abs() < 1e-4,
            "reference x/(F/σ0) = {}",
            x_ref * SIGMA0 / force
        );
        println!(
            "step {force} N: x = {x:.5e} m (reference {x_ref:.5e}, h/2 {x_half:.5e}) = {:.4}·F/σ0; z = {z:.5e} m = F/σ0",
            x * SIGMA0 / force
        );
    }
}

/// The step-force system loaded by a quarter period of a 1/16 Hz sine
/// instead: the force rises to `peak` in 4 s (the paper's trials took about
/// 4 s to reach the set force) and the run ends at the peak.
fn slowly_loaded(peak: f64) -> fricsim::master::Run {
    let mut file = example("lugre_step_force.ssd");
    set_real(&mut file, "rig.F_step", 0.0);
    set_real(&mut file, "rig.drive_amp", peak);
    set_real(&mut file, "rig.drive_freq", 1.0 / 16.0);
    let (h, master, _) = settings(&file);
    run_with(&file, &master, h, 4.0)
}

#[test]
fn slowly_loaded_block_follows_the_pre_sliding_closed_form() {
    for force in [0.02, 0.5, 1.0, 1.5] {
        let run = slowly_loaded(force);
        let x = last(&run, "rig.x");
        let closed = slow_loading_position(force);
        assert!(
            (x / closed - 1.0).abs() < 1e-2,
            "{force} N: x = {x:e}, closed form {closed:e}"
        );
        println!(
            "slow loading to {force} N: x = {x:.5e} m, −(Fs/σ0)·ln(1 − F/Fs) = {closed:.5e} m, F/σ0 = {:.5e} m",
            force / SIGMA0
        );
    }
    // The paper's x = F/σ0 is the small-force limit: within 1 % at 0.02 N
    // (F/Fs < 2 %), after a step too.
    let x = last(&slowly_loaded(0.02), "rig.x");
    assert!((x * SIGMA0 / 0.02 - 1.0).abs() < 1e-2, "x = {x:e}");
    let mut file = example("lugre_step_force.ssd");
    set_real(&mut file, "rig.F_step", 0.02);
    let x = last(&run(&file), "rig.x");
    assert!((x * SIGMA0 / 0.02 - 1.0).abs() < 1e-2, "x = {x:e}");
}

#[test]
fn break_away_at_fs_under_slow_loading_below_it_after_a_step() {
    // Slowly loaded, the block holds at 2.3 N and slides at 2.4 N: the
    // break-away level is Fs = 2.35 N (the paper measured the block static
    // within [−2.4, 2.2] N).
    let held = slowly_loaded(2.3);
    assert!(
        last(&held, "rig.v").abs() < 0.1 * VS,
        "{}",
        last(&held, "rig.v")
    );
    assert!(last(&held, "rig.x") < 2e-4);
    let slid = slowly_loaded(2.4);
    assert!(last(&slid, "rig.v") > VS, "{}", last(&slid, "rig.v"));
    assert!(last(&slid, "rig.x") > 1e-3);
    // A step excites the block past the Stribeck velocity and breaks it
    // away below Fs (above 1.68 N on the reference): 1.5 N holds, 2.0 N
    // slides.
    for (force, slides) in [(1.5, false), (2.0, true)] {
        let mut file = example("lugre_step_force.ssd");
        set_real(&mut file, "rig.F_step", force);
        let (h, master, _) = settings(&file);
        let v = last(&run_with(&file, &master, h, 0.5), "rig.v");
        assert_eq!(v > VS, slides, "step {force} N: v = {v:e}");
    }
}

/// One Dahl trial v_ref = 1e-3·sin(t/k) over one period; returns the run.
fn dahl_trial(k: f64, h: f64) -> fricsim::master::Run {
    let mut file = example("dahl_velocity.ssd");
    set_real(
        &mut file,
        "rig.ref_freq",
        1.0 / (2.0 * std::f64::consts::PI * k),
    );
    let master = settings(&file).1;
    run_with(&file, &master, h, 2.0 * std::f64::consts::PI * k)
}

/// Largest |F − closed form| / Fc on the first two monotone branches, the
/// turning point, and the largest velocity tracking error / amplitude.
fn dahl_deviation(run: &fricsim::master::Run, k: f64) -> (f64, (f64, f64), f64) {
    let (t, x, v, f) = (
        &run.time,
        column(run, "rig.x"),
        column(run, "rig.v"),
        column(run, "friction.F"),
    );
    let tracking = t
        .iter()
        .zip(&v)
        .map(|(t, v)| (v - 1e-3 * (t / k).sin()).abs())
        .fold(0.0, f64::max)
        / 1e-3;
    // The block moves forward until v first changes sign (the reversal,
    // near t = π·k), then backward until it changes sign again (near the
    // end of the period, t = 2π·k).
    let reversal = (2..v.len())
        .find(|&i| v[i] < 0.0 && v[i - 1] >= 0.0)
        .expect("a reversal");
    let back = (reversal + 1..v.len())
        .find(|&i| v[i] > 0.0 && v[i - 1] <= 0.0)
        .unwrap_or(v.len());
    assert!(
        (t[reversal] / (std::f64::consts::PI * k) - 1.0).abs() < 1e-2,
        "reversal at {}",
        t[reversal]
    );
    assert!(
        (t[back - 1] / (2.0 * std::f64::consts::PI * k) - 1.0).abs() < 1e-2,
        "second reversal at {}",
        t[back - 1]
    );
    assert!(v[1..reversal].iter().all(|&v| v > 0.0));
    let mut worst: f64 = 0.0;
    for i in 0..reversal {
        let closed = DAHL_FC * (1.0 - (-DAHL_SIGMA * x[i] / DAHL_FC).exp());
        worst = worst.max((f[i] - closed).abs());
    }
    let (xr, fr) = (x[reversal - 1], f[reversal - 1]);
    for i in reversal..back {
        let closed = -DAHL_FC + (fr + DAHL_FC) * (-DAHL_SIGMA * (xr - x[i]) / DAHL_FC).exp();
        worst = worst.max((f[i] - closed).abs());
    }
    (worst / DAHL_FC, (xr, fr), tracking)
}

#[test]
fn dahl_velocity_trials_follow_the_closed_form() {
    let file = example("dahl_velocity.ssd");
    assert_eq!(bound(&file, "friction.sigma"), DAHL_SIGMA);
    assert_eq!(bound(&file, "friction.Fc"), DAHL_FC);
    let h = settings(&file).0;
    for k in [1.0, 2.0, 4.0, 6.0] {
        let run = dahl_trial(k, h);
        let (deviation, (xr, fr), tracking) = dahl_deviation(&run, k);
        // The paper's trials: the block follows the velocity reference (within
        // 6 % of its amplitude at k = 1, 4 % at k = 2).
        assert!(tracking < 0.1, "k = {k}: velocity off by {tracking}");
        // F(x) is the closed form (the paper: within 1 %; here 1e-3 of Fc).
        assert!(
            deviation < 1e-3,
            "k = {k}: |F − closed form| = {deviation}·Fc"
        );
        // Gross sliding reached on the first branch (F = Fc(1 − e^−σx/Fc)
        // at x_r ≈ 2·k mm).
        assert!(fr > 0.999 * DAHL_FC && (xr / (2e-3 * k) - 1.0).abs() < 0.05);
        println!(
            "Dahl trial k = {k}: |F − closed form| ≤ {deviation:.2e}·Fc, reversal at x = {xr:.4e} m, F = {fr:.6} N, velocity within {:.1} %",
            tracking * 100.0
        );
    }
    // Converged: halving the step changes F at the turning point and at
    // the end by less than 0.1 %.
    let (a, b) = (dahl_trial(2.0, h), dahl_trial(2.0, h / 2.0));
    let (_, (_, fr_a), _) = dahl_deviation(&a, 2.0);
    let (_, (_, fr_b), _) = dahl_deviation(&b, 2.0);
    assert!((fr_a / fr_b - 1.0).abs() < 1e-3);
    let (end_a, end_b) = (last(&a, "friction.F"), last(&b, "friction.F"));
    assert!((end_a / end_b - 1.0).abs() < 1e-3, "{end_a} vs {end_b}");
}
