//! Rig2D with the 2-D bristle law (Wijata et al. 2016): the behaviours the
//! paper reports, the reference against the law's exact update along its
//! own path, and convergence in the tolerance.

use fricsim_reference::radau::RadauStats;
use fricsim_reference::{ComponentSpec, ReferenceModel, SystemSpec, Table, RTOL};
use friction_laws::bristle2d::{Bristle2D, Bristle2DParams};
use friction_laws::Ramp;

/// Rig2D (`rig`) and Bristle2D (`friction`) coupled per axis.
fn planar(rig: ComponentSpec) -> SystemSpec {
    SystemSpec {
        components: vec![rig, ComponentSpec::new("friction", "Bristle2D")],
        connections: Vec::new(),
    }
    .connect("rig.v1", "friction.v1")
    .connect("rig.v2", "friction.v2")
    .connect("friction.F1", "rig.F1")
    .connect("friction.F2", "rig.F2")
}

/// Wijata et al.'s oscillator (Rig2D's defaults): m = 1 kg, k1 = k2 = 100 N/m,
/// x(0) = (0.08, 0.08) m, v(0) = (−0.8, 0.8) m/s: the velocity is
/// perpendicular to the displacement and balances the springs, so the
/// frictionless orbit is a circle (behaviour 4).
fn oscillator() -> SystemSpec {
    planar(ComponentSpec::new("rig", "Rig2D"))
}

fn run(spec: &SystemSpec, h: f64, t_end: f64, rtol: f64) -> (Table, RadauStats) {
    let mut m = ReferenceModel::from_spec(spec).unwrap();
    assert!(m.description().contains("hybrid"), "{}", m.description());
    let n = (t_end / h).round() as usize;
    let times: Vec<f64> = (0..=n).map(|i| i as f64 * h).collect();
    let (t, s) = m.solve(0.0, &times, rtol).unwrap();
    (t, s.unwrap())
}

fn col(t: &Table, name: &str) -> Vec<f64> {
    t.column(name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", t.columns))
}

#[test]
fn the_oscillator_spirals_in_with_a_straight_line_envelope_and_sticks() {
    let (t, _) = run(&oscillator(), 1e-3, 3.0, RTOL);
    let (x1, x2) = (col(&t, "rig.x1"), col(&t, "rig.x2"));
    let (f1, f2) = (col(&t, "friction.F1"), col(&t, "friction.F2"));
    let (z1, z2) = (col(&t, "friction.z1"), col(&t, "friction.z2"));
    let z0 = 1e-4;
    assert!(z1
        .iter()
        .zip(&z2)
        .all(|(a, b)| a.hypot(*b) <= z0 * (1.0 + 1e-12)));
    // Sliding at the level σ0·z0 = 1 N against a velocity turning at
    // ω = 10 rad/s: the energy k·r² falls at F·ω·r, so the radius
    // shrinks linearly, ṙ = −F·ω/(2k) = −0.05 m/s (behaviour 1: straight
    // envelopes). Fit r(t) on 0.2 … 2 s: observed slope −0.0495 m/s,
    // largest residual 2.5 mm of the initial 113 mm.
    let pts: Vec<(f64, f64)> = (0..t.time.len())
        .filter(|&i| (0.2..=2.0).contains(&t.time[i]))
        .map(|i| (t.time[i], x1[i].hypot(x2[i])))
        .collect();
    let n = pts.len() as f64;
    let (mt, mr) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let slope = pts.iter().map(|p| (p.0 - mt) * (p.1 - mr)).sum::<f64>()
        / pts.iter().map(|p| (p.0 - mt).powi(2)).sum::<f64>();
    assert!((slope + 0.05).abs() < 0.05 * 0.03, "slope {slope}");
    let residual = pts
        .iter()
        .map(|p| (p.1 - mr - slope * (p.0 - mt)).abs())
        .fold(0.0, f64::max);
    assert!(residual < 0.05 * 0.08f64.hypot(0.08), "residual {residual}");
    // At rest in the end, held inside the stiction disc: F = −k·x, below
    // the break-away level (1 + a)·σ0·z0 = 1.1 N.
    let last = t.time.len() - 1;
    let r = z1[last].hypot(z2[last]);
    assert!(r < z0 * (1.0 - 1e-3), "|z| = {r}");
    for (f, x) in [(f1[last], x1[last]), (f2[last], x2[last])] {
        assert!((f + 100.0 * x).abs() < 1e-9, "{f} vs {}", -100.0 * x);
    }
    assert!(f1[last].hypot(f2[last]) < 1.1);
    assert!(col(&t, "rig.v1")[last].abs() < 1e-9);
}

#[test]
fn the_reference_equals_the_laws_exact_update_along_its_own_velocity() {
    // Bristle2D::step is exact for a constant slip velocity (closed-form
    // rotation on the circle) and sub-steps ramps: driven by the
    // reference's v(t) samples, piecewise linear, it must reproduce the
    // reference's forces (observed 7.5e-6 N of 1 N, at the final stick).
    let h = 1e-4;
    let (t, _) = run(&oscillator(), h, 3.0, RTOL);
    let (v1, v2) = (col(&t, "rig.v1"), col(&t, "rig.v2"));
    let (f1, f2) = (col(&t, "friction.F1"), col(&t, "friction.F2"));
    let mut law = Bristle2D::new(Bristle2DParams::default()).unwrap();
    let mut worst: f64 = 0.0;
    for k in 1..t.time.len() {
        law.step(
            Ramp::new(v1[k - 1], (v1[k] - v1[k - 1]) / h),
            Ramp::new(v2[k - 1], (v2[k] - v2[k - 1]) / h),
            h,
        );
        let f = law.force([v1[k], v2[k]]);
        worst = worst.max((f[0] - f1[k]).abs()).max((f[1] - f2[k]).abs());
    }
    assert!(worst < 5e-5, "worst {worst:e}");
}

#[test]
fn the_reference_agrees_with_a_hundred_times_tighter_tolerance() {
    let (a, stats) = run(&oscillator(), 1e-3, 3.0, RTOL);
    let (b, _) = run(&oscillator(), 1e-3, 3.0, 1e-2 * RTOL);
    let diff = |n: &str| {
        col(&a, n)
            .iter()
            .zip(&col(&b, n))
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    };
    // Observed 6e-14 m, 5e-12 m/s, 7e-10 N.
    assert!(diff("rig.x1") < 1e-11 && diff("rig.x2") < 1e-11);
    assert!(diff("rig.v1") < 1e-10 && diff("rig.v2") < 1e-10);
    assert!(diff("friction.F1") < 1e-8 && diff("friction.F2") < 1e-8);
    assert!(stats.accepted > 0);
}

#[test]
fn a_belt_drags_the_mass_into_stick_slip_along_its_direction() {
    // Behaviour 2: the surface moves at (0.03, 0.04) m/s under a mass tied
    // to the origin by equal springs; it sticks, is dragged until the
    // springs exceed the break-away level, slips back, and so on, with
    // sticking and slipping at the same instants in both axes and the
    // friction components in the ratio 0.03 : 0.04.
    let rig = ComponentSpec::new("rig", "Rig2D")
        .real("x1_0", 0.0)
        .real("x2_0", 0.0)
        .real("v1_0", 0.0)
        .real("v2_0", 0.0)
        .real("vs1", 0.03)
        .real("vs2", 0.04);
    let (t, _) = run(&planar(rig), 1e-3, 3.0, RTOL);
    let (f1, f2) = (col(&t, "friction.F1"), col(&t, "friction.F2"));
    let (v1, v2) = (col(&t, "rig.v1"), col(&t, "rig.v2"));
    let (x1, x2) = (col(&t, "rig.x1"), col(&t, "rig.x2"));
    for i in 1..t.time.len() {
        if f1[i].hypot(f2[i]) > 0.1 {
            assert!((f1[i] / f2[i] - 0.75).abs() < 1e-9, "t {}", t.time[i]);
        }
        // On the line of the belt's direction.
        assert!(
            (x1[i] * 0.04 - x2[i] * 0.03).abs() < 1e-12,
            "t {}",
            t.time[i]
        );
    }
    // Stick (slip velocity 0 … −|v_s|) alternates with slip (moving back
    // faster than the belt): count the slips.
    let speed: Vec<f64> = v1.iter().zip(&v2).map(|(a, b)| a.hypot(*b)).collect();
    let slips = (1..speed.len())
        .filter(|&i| speed[i - 1] <= 0.06 && speed[i] > 0.06)
        .count();
    assert!(slips >= 3, "{slips} slips");
    // Break-away at |k·x| = (1 + a)·σ0·z0 = 1.1 N with the body at the
    // belt's speed |v_s| = 0.05 m/s; the slip is then half an oscillation
    // about the sliding balance F/k = 0.01 m, of amplitude
    // √(0.001² + (|v_s|/ω)²), so the spring force peaks at
    // 100·(0.01 + 0.0051) = 1.51 N (observed 1.513).
    let peak = x1
        .iter()
        .zip(&x2)
        .map(|(a, b)| 100.0 * a.hypot(*b))
        .fold(0.0, f64::max);
    let expected = 100.0 * (0.01 + (1e-6f64 + 0.005f64.powi(2)).sqrt());
    assert!(
        (peak - expected).abs() < 0.01 * expected,
        "peak {peak} vs {expected}"
    );
}
