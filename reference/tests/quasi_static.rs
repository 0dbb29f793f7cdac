//! The quasi-static rig (m = 0, c = 0) with the bristle law of Appels and Herder:
//! the reference is the exact root of the force balance at every output
//! time, the bristle state advanced monotonically from root to root.

use fricsim_reference::quasi_static::{BristleInput, QuasiStaticBristle};
use fricsim_reference::{ComponentSpec, ReferenceModel, SystemSpec, Table, RTOL};
use friction_laws::bristle::{Bristle, BristleParams};
use rig_dynamics::rig1d::{Rig1D, Rig1DInputs, Rig1DParams};
use rig_dynamics::signals::Sinusoid;

/// Appels and Herder: k = 116.04e3 N/m, piezo ramp 8.25e-8 m/s, quasi-static.
const K: f64 = 116.04e3;
const V_A: f64 = 8.25e-8;

fn piezo_push(rig: ComponentSpec) -> SystemSpec {
    SystemSpec {
        components: vec![rig, ComponentSpec::new("bristle", "Bristle")],
        connections: Vec::new(),
    }
    .connect("rig.x_rel", "bristle.x")
    .connect("bristle.F", "rig.F")
}

fn piezo_rig() -> ComponentSpec {
    ComponentSpec::new("rig", "Rig1D")
        .real("m", 0.0)
        .real("c", 0.0)
        .real("k", K)
        .real("v_a", V_A)
}

fn run(spec: &SystemSpec, h: f64, t_end: f64) -> Table {
    let mut m = ReferenceModel::from_spec(spec).unwrap();
    assert!(
        m.description().contains("quasi-static"),
        "{}",
        m.description()
    );
    let n = (t_end / h).round() as usize;
    let times: Vec<f64> = (0..=n).map(|i| i as f64 * h).collect();
    let (table, stats) = m.solve(0.0, &times, RTOL).unwrap();
    assert!(stats.is_none(), "no time integration");
    table
}

fn col(t: &Table, name: &str) -> Vec<f64> {
    t.column(name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", t.columns))
}

/// The paper's sliding level μc·m·g (0.352 kg).
fn level() -> f64 {
    0.0633 * 0.352 * 9.81
}

#[test]
fn piezo_push_is_the_root_of_the_force_balance_at_every_output() {
    let t = run(&piezo_push(piezo_rig()), 0.05, 30.0);
    // the bristle's outputs follow the rig's, F first
    let first_bristle = t.columns.iter().position(|c| c.starts_with("bristle."));
    assert_eq!(
        first_bristle.map(|i| t.columns[i].as_str()),
        Some("bristle.F")
    );
    let (x, x_rel, xa) = (col(&t, "rig.x"), col(&t, "rig.x_rel"), col(&t, "rig.x_act"));
    let (v, a, f) = (col(&t, "rig.v"), col(&t, "rig.a"), col(&t, "bristle.F"));
    // The rig's own output equation: x = x_a + (F_ext − F)/k with the
    // reported F. The bristle replayed independently along the reported
    // x_rel gives the reported F: together, the root of k·(x_a − x) = F(x).
    let mut replay = Bristle::new(BristleParams::default()).unwrap();
    let mut worst: f64 = 0.0;
    for i in 0..t.time.len() {
        assert!((x[i] - (xa[i] - f[i] / K)).abs() <= 1e-15 * xa[i].abs().max(1e-9));
        assert_eq!(x[i], x_rel[i], "no surface motion");
        assert_eq!(a[i], 0.0);
        replay.move_to(x_rel[i]);
        worst = worst.max((replay.force() - f[i]).abs());
        if i > 0 {
            assert!(
                f[i] >= f[i - 1],
                "monotone push, monotone force at {}",
                t.time[i]
            );
        }
    }
    assert!(worst <= 1e-12 * level(), "worst {worst:e}");
    // Gross sliding at the end at the paper's level μc·m·g, reached within
    // a pre-sliding displacement of 2·δmax.
    let last = t.time.len() - 1;
    assert!((f[last] - level()).abs() < 1e-12 * level(), "{}", f[last]);
    let first_sliding = (0..t.time.len()).find(|&i| f[i] == f[last]).unwrap();
    assert!(
        x_rel[first_sliding] <= 2.0 * 1.5584e-8,
        "{}",
        x_rel[first_sliding]
    );
    // Velocity: ẋ = k·v_a/(k + n_c·σb): the actuator's speed once sliding,
    // far less while all bristles are connected (σ_ini = μc·m·g/δmax).
    assert!((v[last] - V_A).abs() < 1e-15 * V_A);
    let sigma_ini = level() / 1.5584e-8;
    let stuck = K * V_A / (K + sigma_ini);
    assert!((v[1] - stuck).abs() < 1e-9 * stuck, "{} vs {stuck}", v[1]);
}

/// The solver itself, with access to the bristle state at each output.
fn piezo(rig: Rig1DParams) -> QuasiStaticBristle {
    QuasiStaticBristle {
        rig: Rig1D::new(rig).unwrap(),
        bristle: Bristle::new(BristleParams::default()).unwrap(),
        inputs: Rig1DInputs::default(),
        input: BristleInput::Relative,
    }
}

#[test]
fn all_bristles_connected_gives_the_closed_form_of_two_springs_in_series() {
    let qs = piezo(Rig1DParams {
        m: 0.0,
        c: 0.0,
        k: K,
        v_a: V_A,
        ..Rig1DParams::default()
    });
    let n = qs.bristle.n_bristles();
    let sigma_ini = qs.bristle.params().sigma_ini;
    // The initial deflections sum to zero up to round-off.
    let f0 = qs.bristle.force();
    assert!(f0.abs() < 1e-12 * level());
    let taus: Vec<f64> = (0..=300).map(|i| i as f64 * 0.01).collect();
    let mut linear = 0;
    qs.solve(&taus, |p, b| {
        // k·(v_a·t − ξ) = F0 + σ_ini·ξ while every bristle is connected.
        if b.n_connected() == n {
            let exact = (V_A * p.tau * K - f0) / (K + sigma_ini);
            assert!(
                (p.xi - exact).abs() <= 1e-12 * exact.abs() + 1e-25,
                "t {}",
                p.tau
            );
            linear += 1;
        }
        assert!(!p.held, "held at {} xi {} f {}", p.tau, p.xi, p.force);
        let r = qs.free_position(p.tau);
        assert!(
            (r - p.xi - p.force / K).abs() <= 1e-12 * level() / K,
            "t {}",
            p.tau
        );
    });
    assert!(linear > 10 && linear < taus.len(), "{linear} linear points");
}

#[test]
fn a_reversal_holds_the_body_until_the_spring_has_crossed_the_force_drop() {
    // The actuator oscillates: 3e-6 m (beyond sliding, 1.9e-6 m of spring
    // deflection) at 0.02 Hz, so it turns at t = 12.5 s and 37.5 s.
    let spec = piezo_push(
        ComponentSpec::new("rig", "Rig1D")
            .real("m", 0.0)
            .real("c", 0.0)
            .real("k", K)
            .real("v_a", 0.0)
            .real("act_amp", 3e-6)
            .real("act_freq", 0.02),
    );
    let t = run(&spec, 0.01, 50.0);
    let (x, f) = (col(&t, "rig.x_rel"), col(&t, "bristle.F"));
    let at = |time: f64| (time / 0.01).round() as usize;
    // Sliding forward before the first turn, backward before the second.
    assert!((f[at(12.0)] - level()).abs() < 1e-12);
    assert!((f[at(37.0)] + level()).abs() < 1e-12);
    // After the turn the body holds still while the force falls from the
    // sliding level through the reconnection drop, then unloads.
    let turn = at(12.5);
    // (x_rel is the rig's x_a + (F_ext − F)/k: constant up to round-off.)
    let held: Vec<usize> = (turn..at(20.0))
        .take_while(|&i| (x[i] - x[turn]).abs() <= 1e-12 * x[turn].abs())
        .collect();
    // R must travel the drop over k: A·ω²·δt²/2 = σ_ini·x_rel/k gives
    // δt ≈ 4.7 s near the crest.
    assert!(
        held.len() > 300 && held.len() < 700,
        "held for {} samples",
        held.len()
    );
    let after = held[held.len() - 1] + 1;
    let drop = f[turn] - f[after];
    // The drop is σb·Σ|r| with |r| ~ x_rel = 4.42e-9 m: about σ_ini·x_rel.
    let sigma_ini = level() / 1.5584e-8;
    assert!(
        drop > 0.5 * sigma_ini * 4.4206e-9 && drop < 1.5 * sigma_ini * 4.4206e-9,
        "{drop}"
    );
    for w in held.windows(2) {
        assert!(f[w[1]] < f[w[0]], "the balance force falls while held");
    }
    // Everywhere but in the holds (at both turns), the bristle replayed
    // along x_rel gives the reported force; in a hold x stays (up to
    // round-off) while F moves inside the drop.
    let mut replay = Bristle::new(BristleParams::default()).unwrap();
    let mut holds = 0;
    for i in 0..t.time.len() {
        let still = i > 0 && (x[i] - x[i - 1]).abs() <= 1e-12 * x[i].abs();
        if still && f[i] != f[i - 1] {
            holds += 1;
            let (lo, hi) = (f[i].min(replay.force()), f[i].max(replay.force()));
            assert!(hi - lo < 1.5 * sigma_ini * 4.4206e-9, "t {}", t.time[i]);
            continue;
        }
        replay.move_to(x[i]);
        assert!(
            (replay.force() - f[i]).abs() < 1e-12 * level(),
            "t {}",
            t.time[i]
        );
    }
    assert!(holds > 2 * 300, "{holds} held samples");
}

#[test]
fn turning_points_between_outputs_are_visited() {
    // Outputs every 25 s miss the turns of a 0.02 Hz actuator at 12.5 s
    // and 37.5 s; the hysteresis (the state after the turns) must not.
    let rig = Rig1DParams {
        m: 0.0,
        c: 0.0,
        k: K,
        v_a: 0.0,
        act_sine: Sinusoid::new(3e-6, 0.02),
        ..Rig1DParams::default()
    };
    let qs = piezo(rig);
    let mut coarse = Vec::new();
    qs.solve(&[0.0, 25.0, 50.0], |p, _| coarse.push(p.force));
    let mut fine = Vec::new();
    let taus: Vec<f64> = (0..=5000).map(|i| i as f64 * 0.01).collect();
    qs.solve(&taus, |p, _| {
        if p.tau == 25.0 || p.tau == 50.0 {
            fine.push(p.force)
        }
    });
    assert_eq!(fine.len(), 2);
    for k in 0..2 {
        assert!(
            (coarse[k + 1] - fine[k]).abs() < 1e-12 * level(),
            "{coarse:?} {fine:?}"
        );
    }
    // At t = 25 s the actuator is back at 0 after sliding forward: the
    // force is negative (unloading past zero), not the virgin 0.
    assert!(coarse[1] < -0.5 * level(), "{coarse:?}");
}
