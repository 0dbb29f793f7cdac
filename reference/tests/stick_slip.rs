//! The monolithic reference of Rig1D (m > 0) with LuGre and Dahl: the LuGre
//! stick-slip benchmark against docs/models.md, "Reference figures",
//! convergence in the tolerance, consistency of the output columns, and the
//! Dahl coupling against the law's exact update in displacement.

use fricsim_reference::metrics;
use fricsim_reference::{ComponentSpec, ReferenceModel, SystemSpec, Table, RTOL};
use friction_laws::dahl::{Dahl, DahlParams};
use friction_laws::lugre::{LuGre, LuGreParams};
use friction_laws::Ramp;

/// The 1995 benchmark rig (m = 1 kg, k = 2 N/m, pulled at 0.1 m/s) with
/// `law` as component `friction`, connected as in examples/stick_slip.ssd.
fn system(law: ComponentSpec) -> SystemSpec {
    let rig = ComponentSpec::new("rig", "Rig1D")
        .real("m", 1.0)
        .real("k", 2.0)
        .real("c", 0.0)
        .real("v_a", 0.1);
    coupled(rig, law)
}

/// `rig` and `law` connected `rig.v → friction.v`, `friction.F → rig.F`.
fn coupled(rig: ComponentSpec, law: ComponentSpec) -> SystemSpec {
    SystemSpec {
        components: vec![rig, law],
        connections: Vec::new(),
    }
    .connect("rig.v", "friction.v")
    .connect("friction.F", "rig.F")
}

/// LuGre with Canudas de Wit's 1995 parameters, written out.
fn lugre_1995() -> ComponentSpec {
    ComponentSpec::new("friction", "LuGre")
        .real("sigma0", 1e5)
        .real("sigma1", 1e5f64.sqrt())
        .real("sigma2", 0.4)
        .real("Fc", 1.0)
        .real("Fs", 1.5)
        .real("vs", 1e-3)
}

fn run(spec: &SystemSpec, h: f64, t_end: f64, rtol: f64) -> Table {
    let mut m = ReferenceModel::from_spec(spec).unwrap();
    let n = (t_end / h).round() as usize;
    let times: Vec<f64> = (0..=n).map(|i| i as f64 * h).collect();
    m.solve(0.0, &times, rtol).unwrap().0
}

fn col(t: &Table, name: &str) -> Vec<f64> {
    t.column(name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", t.columns))
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn lugre_benchmark_reproduces_the_reference_results_to_the_digits_given() {
    let t = run(&system(lugre_1995()), 1e-4, 30.0, RTOL);
    let s = metrics::stick_slip(&t.time, &col(&t, "rig.v"), &col(&t, "friction.F"), 0.05)
        .expect("periodic stick-slip");
    eprintln!("reference figures: {s:?}");
    // docs/models.md, "Reference figures": first slip 7.540 s, period 6.3627 s, peak friction
    // 1.4766 N, peak velocity 0.3698 m/s: each within half a unit of the
    // last digit given. Observed 7.5403975, 6.3627198, 1.4765729, 0.3698160.
    assert!((s.first_slip - 7.540).abs() <= 5e-4, "{s:?}");
    assert!((s.period - 6.3627).abs() <= 5e-5, "{s:?}");
    assert!((s.peak_force - 1.4766).abs() <= 5e-5, "{s:?}");
    assert!((s.peak_velocity - 0.3698).abs() <= 5e-5, "{s:?}");
    assert_eq!(s.slips, 4);
    // Periodic from the first slip on: every interval between slips is the
    // period.
    let c = metrics::upward_crossings(&t.time, &col(&t, "rig.v"), 0.05);
    for w in c.windows(2) {
        assert!((w[1] - w[0] - s.period).abs() < 1e-8, "{c:?}");
    }
}

#[test]
fn lugre_reference_agrees_with_a_hundred_times_tighter_tolerance() {
    let spec = system(lugre_1995());
    let a = run(&spec, 1e-4, 30.0, RTOL);
    let b = run(&spec, 1e-4, 30.0, 1e-2 * RTOL);
    // Observed 4e-11 m, 7e-11 m/s, 2e-8 N, 8e-14 m. F is the most
    // sensitive column: σ0·z and σ1·ż nearly cancel in sliding, and the
    // velocity oscillates through zero as each stick begins (without the
    // switching function at v = 0 the difference in F is 1.7e-7 N).
    assert!(max_diff(&col(&a, "rig.x"), &col(&b, "rig.x")) < 1e-9);
    assert!(max_diff(&col(&a, "rig.v"), &col(&b, "rig.v")) < 1e-9);
    assert!(max_diff(&col(&a, "friction.F"), &col(&b, "friction.F")) < 1e-7);
    assert!(max_diff(&col(&a, "friction.z"), &col(&b, "friction.z")) < 1e-12);
}

#[test]
fn lugre_columns_are_the_fmus_outputs_and_consistent_with_the_equations() {
    let spec = system(ComponentSpec::new("friction", "LuGre"));
    let t = run(&spec, 1e-3, 12.0, RTOL);
    // Every Real output of both FMUs, in variable-table order.
    assert_eq!(
        &t.columns[..5],
        ["rig.x", "rig.v", "rig.a", "rig.F_spring", "rig.x_act"]
    );
    assert!(t
        .columns
        .iter()
        .all(|c| c.starts_with("rig.") || c.starts_with("friction.")));
    assert_eq!(
        &t.columns[t.columns.len() - 4..],
        [
            "friction.F",
            "friction.z",
            "friction.P_diss",
            "friction.E_stored"
        ]
    );
    let (x, v, a) = (col(&t, "rig.x"), col(&t, "rig.v"), col(&t, "rig.a"));
    let (spring, xa) = (col(&t, "rig.F_spring"), col(&t, "rig.x_act"));
    let (f, z) = (col(&t, "friction.F"), col(&t, "friction.z"));
    let law = {
        let mut l = LuGre::new(LuGreParams::default()).unwrap();
        l.set_z(0.0);
        l
    };
    for i in 0..t.time.len() {
        let ti = t.time[i];
        assert_eq!(xa[i], 0.1 * ti, "x_act at {ti}");
        assert!(
            (spring[i] - 2.0 * (xa[i] - x[i])).abs() < 1e-15,
            "F_spring at {ti}"
        );
        // m·a = F_spring − F (m = 1, c = 0, no drive, no controller).
        assert!((a[i] - (spring[i] - f[i])).abs() < 1e-14, "a at {ti}");
        // F = σ0·z + σ1·ż + σ2·v from the law's own output equation.
        assert_eq!(f[i], law.force_of(z[i], v[i], 0.0, 1.0), "F at {ti}");
    }
    // a = dv/dt: central differences agree to O(h²) away from the steep
    // transitions (relative to the largest acceleration).
    let a_max = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut agree = 0;
    for i in 1..t.time.len() - 1 {
        let dv = (v[i + 1] - v[i - 1]) / (t.time[i + 1] - t.time[i - 1]);
        if (dv - a[i]).abs() < 1e-3 * a_max {
            agree += 1;
        }
    }
    assert!(
        agree as f64 > 0.99 * t.time.len() as f64,
        "{agree} of {}",
        t.time.len()
    );
}

#[test]
fn dahl_reference_equals_the_exact_update_along_its_own_path() {
    // Dahl is rate-independent: F after a displacement increment of one
    // sign is given in closed form (Dahl::step), independently of the
    // time integration. Driven by the reference's own x(t) samples, it
    // must reproduce the reference's F (v ≥ 0 throughout: no reversal
    // inside a sample interval).
    let t = run(
        &system(ComponentSpec::new("friction", "Dahl")),
        1e-3,
        20.0,
        RTOL,
    );
    let (x, v, f) = (col(&t, "rig.x"), col(&t, "rig.v"), col(&t, "friction.F"));
    assert!(v.iter().all(|&v| v >= 0.0));
    let mut dahl = Dahl::new(DahlParams::default()).unwrap();
    let mut worst: f64 = 0.0;
    for k in 1..x.len() {
        let h = t.time[k] - t.time[k - 1];
        dahl.step(Ramp::constant((x[k] - x[k - 1]) / h), h);
        worst = worst.max((dahl.force() - f[k]).abs());
    }
    // Observed 5.4e-10 of Fc = 2 N (2e-12 with steps of 1e-4 s).
    assert!(worst < 2e-9, "worst {worst:e}");
    // The force has reached the Coulomb level: F → Fc in steady sliding.
    assert!((f[f.len() - 1] - 2.0).abs() < 1e-6, "{}", f[f.len() - 1]);
    assert!(col(&t, "friction.z")
        .iter()
        .zip(&f)
        .all(|(z, f)| (z * 87_750.0 - f).abs() < 1e-12));
}

/// Dahl's offset is a constant force on the body: the rig with a Dahl
/// contact of `F_offset = c` moves as the rig with a plain one and the
/// external force `F_ext = −c`, and its force column is the plain one's
/// plus `c` (`z = F_dahl/σ` unchanged), from `F = c` at the start.
#[test]
fn dahl_offset_is_a_constant_force_on_the_body() {
    for c in [0.3, -0.45] {
        let offset = run(
            &system(ComponentSpec::new("friction", "Dahl").real("F_offset", c)),
            1e-3,
            5.0,
            RTOL,
        );
        let rig = ComponentSpec::new("rig", "Rig1D")
            .real("m", 1.0)
            .real("k", 2.0)
            .real("c", 0.0)
            .real("v_a", 0.1)
            .real("F_ext", -c);
        let pushed = run(
            &coupled(rig, ComponentSpec::new("friction", "Dahl")),
            1e-3,
            5.0,
            RTOL,
        );
        let f = col(&offset, "friction.F");
        assert_eq!(f[0], c);
        let shifted: Vec<f64> = col(&pushed, "friction.F").iter().map(|f| f + c).collect();
        // The two right-hand sides differ in rounding only, which the
        // solver's steps carry to its tolerance: observed 1.8e-9 N (F),
        // 1.7e-13 m (x), 2.1e-14 m (z = F_dahl/σ), 5.5e-12 m/s (v).
        let bounds = [
            ("friction.F", 1e-8),
            ("rig.x", 1e-12),
            ("friction.z", 1e-13),
            ("rig.v", 1e-10),
        ];
        for (column, bound) in bounds {
            let a = col(&offset, column);
            let b = match column {
                "friction.F" => shifted.clone(),
                _ => col(&pushed, column),
            };
            let d = max_diff(&a, &b);
            assert!(d < bound, "c {c}: {column} differs by {d:e}");
        }
    }
}

#[test]
fn recorded_inputs_and_parameters_follow_the_outputs_they_are_connected_to() {
    let mut m = ReferenceModel::from_spec(&system(lugre_1995())).unwrap();
    m.record("friction.v").unwrap();
    m.record("rig.F").unwrap();
    m.record("friction.sigma0").unwrap();
    m.record("friction.v").unwrap(); // twice: once
    let e = m.record("friction.sliding").unwrap_err().0;
    assert!(e.contains("only Real variables"), "{e}");
    let e = m.record("friction.nothing").unwrap_err().0;
    assert!(e.contains("no variable `nothing`"), "{e}");
    let e = m.record("belt.v").unwrap_err().0;
    assert!(e.contains("no component `belt`"), "{e}");
    let cols = m.columns();
    let k = cols.iter().position(|c| c == "rig.F").unwrap();
    assert_eq!(cols[k - 1], "rig.F_app", "after the rig's outputs");
    assert_eq!(
        &cols[cols.len() - 6..],
        [
            "friction.F",
            "friction.z",
            "friction.P_diss",
            "friction.E_stored",
            "friction.v",
            "friction.sigma0"
        ]
    );
    let times: Vec<f64> = (0..=900).map(|i| i as f64 * 0.01).collect();
    let t = m.solve(0.0, &times, RTOL).unwrap().0;
    assert_eq!(col(&t, "friction.v"), col(&t, "rig.v"));
    assert_eq!(col(&t, "rig.F"), col(&t, "friction.F"));
    assert!(col(&t, "friction.sigma0").iter().all(|&s| s == 1e5));
}

#[test]
fn lugre_pre_sliding_settles_with_the_bristles_at_f_over_sigma0() {
    // docs/models.md, "Reference figures": with Sun et al. 2016's parameters a step force below break-away
    // settles at x = F/σ0 (14.9 µm at 1 N). At rest the LuGre force is
    // σ0·z, so the bristle deflection z settles at F/σ0 exactly; the
    // body's x equals it only while F ≪ Fs: on the way, ż = v − σ0·|v|·z/g
    // lags x, and at 1 N (Fs = 2.35 N) the body settles at 21.5 µm. The
    // step comes at t = 0.05 s, inside the run: the integration restarts
    // there, so the jump is taken exactly.
    let sigma0 = 66_967.231;
    let settle = |force: f64| {
        let rig = ComponentSpec::new("rig", "Rig1D")
            .real("m", 1.0)
            .real("k", 0.0)
            .real("c", 0.0)
            .real("v_a", 0.0)
            .real("F_step", force)
            .real("t_step", 0.05);
        let law = ComponentSpec::new("friction", "LuGre")
            .real("sigma0", sigma0)
            .real("sigma1", 2.0 * f64::sqrt(sigma0) - 173.0)
            .real("sigma2", 173.0)
            .real("Fc", 1.284)
            .real("Fs", 2.35)
            .real("vs", 1.139_75e-3);
        let t = run(&coupled(rig, law), 1e-3, 0.5, RTOL);
        let (x, z, drive) = (
            col(&t, "rig.x"),
            col(&t, "friction.z"),
            col(&t, "rig.F_drive"),
        );
        let before = (0.05f64 / 1e-3).round() as usize - 1;
        assert_eq!(
            (x[before], drive[before], drive[before + 1]),
            (0.0, 0.0, force)
        );
        let last = x.len() - 1;
        assert!(
            (z[last] - force / sigma0).abs() < 1e-6 * force / sigma0,
            "{}",
            z[last]
        );
        assert!(col(&t, "rig.v")[last].abs() < 1e-9);
        x[last]
    };
    // Small force: x = F/σ0 to 0.3 % (the lag is a factor 1 + F/(2·Fs)).
    let small = settle(0.01);
    assert!((small * sigma0 / 0.01 - 1.0).abs() < 3e-3, "{small}");
    // 1 N: well beyond 14.9 µm (observed 21.5 µm).
    let one = settle(1.0);
    assert!(one > 1.3 / sigma0 && one < 1.6 / sigma0, "{one}");
}
