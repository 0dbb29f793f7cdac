//! The main job's scenario: the 1995 LuGre stick-slip benchmark
//! (m = 1 kg, k = 2 N/m, pulled at 0.1 m/s; Canudas de Wit parameters) as
//! Rig1D.fmu + LuGre.fmu under the Jacobi master at 1e-4 s, against the
//! reference figures of docs/models.md (Radau IIA, rtol 1e-10): period 6.3627 s,
//! peak friction 1.4766 N, peak velocity 0.3698 m/s, each within 0.5 %;
//! velocity first above 0.05 m/s at t = 7.540 s.

use fricsim::master::{gauss_seidel::GaussSeidel, jacobi::Jacobi, simulate, MasterAlgorithm};
use fricsim::system::System;
use std::path::Path;

fn dist(name: &str) -> std::path::PathBuf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../dist")
        .join(name);
    assert!(p.exists(), "{} is missing: run ./build-fmu.sh", p.display());
    p
}

/// The two components of every system here: `rig` and `friction`.
fn components() -> [(String, std::path::PathBuf); 2] {
    [
        ("rig".to_string(), dist("Rig1D.fmu")),
        ("friction".to_string(), dist("LuGre.fmu")),
    ]
}

fn as_refs(c: &[(String, std::path::PathBuf)]) -> Vec<(String, &Path)> {
    c.iter().map(|(n, p)| (n.clone(), p.as_path())).collect()
}

fn stick_slip_system() -> System {
    let owned = components();
    let components = as_refs(&owned);
    let connections = [
        ("rig.v".to_string(), "friction.v".to_string()),
        ("friction.F".to_string(), "rig.F".to_string()),
    ];
    System::build(&components, &[], &connections).unwrap()
}

#[test]
fn gauss_seidel_steps_the_rig_first() {
    // rig.v is a state (no feedthrough from rig.F); friction.F depends on v
    assert_eq!(GaussSeidel::order(&stick_slip_system()), vec![0, 1]);
}

#[test]
fn gauss_seidel_reproduces_the_benchmark_and_differs_from_jacobi() {
    let mut peaks = Vec::new();
    let masters: [Box<dyn MasterAlgorithm>; 3] = [
        Box::new(Jacobi::default()),
        Box::new(GaussSeidel::new(false)),
        Box::new(GaussSeidel::new(true)),
    ];
    for mut master in masters {
        let mut system = stick_slip_system();
        let run = simulate(&mut system, master.as_mut(), 1e-4, 12.0).unwrap();
        let kf = run.columns.iter().position(|c| c == "friction.F").unwrap();
        let peak = run.rows.iter().fold(0.0f64, |m, r| m.max(r[kf]));
        assert!(
            (peak - 1.4766).abs() <= 0.005 * 1.4766,
            "{}: peak friction {peak}",
            master.name()
        );
        peaks.push(peak);
    }
    assert!(
        peaks[0] != peaks[1] && peaks[1] != peaks[2],
        "masters gave identical results: {peaks:?}"
    );
}

#[test]
fn lugre_stick_slip_benchmark_matches_the_reference() {
    let mut system = stick_slip_system();
    let run = simulate(&mut system, &mut Jacobi::default(), 1e-4, 30.0).unwrap();
    assert!(run.error.is_none());
    let col = |name: &str| run.columns.iter().position(|c| c == name).unwrap();
    let (kv, kf) = (col("rig.v"), col("friction.F"));
    let v: Vec<f64> = run.rows.iter().map(|r| r[kv]).collect();
    let f: Vec<f64> = run.rows.iter().map(|r| r[kf]).collect();

    // instants where v crosses 0.05 m/s upward: the start of each slip
    let crossings: Vec<f64> = (1..v.len())
        .filter(|&i| v[i - 1] < 0.05 && v[i] >= 0.05)
        .map(|i| {
            let s = (0.05 - v[i - 1]) / (v[i] - v[i - 1]);
            run.time[i - 1] + s * (run.time[i] - run.time[i - 1])
        })
        .collect();
    assert!(
        crossings.len() >= 3,
        "expected periodic stick-slip, got crossings {crossings:?}"
    );
    let first = crossings[0];
    assert!(
        (first - 7.540).abs() <= 0.005 * 7.540,
        "first slip at {first} s, reference 7.540 s"
    );
    let period = crossings[crossings.len() - 1] - crossings[crossings.len() - 2];
    assert!(
        (period - 6.3627).abs() <= 0.005 * 6.3627,
        "period {period} s, reference 6.3627 s"
    );
    let peak_f = f.iter().fold(0.0f64, |m, x| m.max(*x));
    let peak_v = v.iter().fold(0.0f64, |m, x| m.max(*x));
    assert!(
        (peak_f - 1.4766).abs() <= 0.005 * 1.4766,
        "peak friction {peak_f} N, reference 1.4766 N"
    );
    assert!(
        (peak_v - 0.3698).abs() <= 0.005 * 0.3698,
        "peak velocity {peak_v} m/s, reference 0.3698 m/s"
    );
}

#[test]
fn configuration_errors_name_the_problem() {
    let owned = components();
    let components = as_refs(&owned);
    let cases = [
        (("rig.nope", "friction.v"), "has no variable `nope`"),
        (("rig.v", "friction.F"), "`friction.F` is not an input"),
        (("rig.F", "friction.v"), "`rig.F` is not an output"),
        (("ghost.v", "friction.v"), "no component `ghost`"),
    ];
    for ((from, to), needle) in cases {
        let err = System::build(&components, &[], &[(from.to_string(), to.to_string())])
            .err()
            .expect("must fail");
        assert!(err.to_string().contains(needle), "{from}->{to}: {err}");
    }
    let missing = [("rig".to_string(), Path::new("no/such.fmu"))];
    let err = System::build(&missing, &[], &[]).err().expect("must fail");
    assert!(err.to_string().contains("no/such.fmu"), "{err}");
}

/// An FMU that returns fmi2Error mid-run: the run stops, the rows computed
/// so far are kept, and the report names the instance, the call and the
/// FMU's own message. (The rig's spring force drives LuGre's normal
/// force: a 1 kg mass on a 1 N/m spring to a fixed point, from x = -0.01 m
/// at 0.1 m/s, so F_spring = -x = 0.01*cos t - 0.1*sin t turns negative at
/// t = atan(0.1) = 0.0997 s, which LuGre refuses. A force into a force:
/// the host refuses connections of different units.)
#[test]
fn an_fmu_error_mid_run_keeps_the_results_so_far() {
    let owned = components();
    let components = as_refs(&owned);
    let parameters = [
        ("rig.x0".to_string(), -0.01),
        ("rig.k".to_string(), 1.0),
        ("rig.v_a".to_string(), 0.0),
        ("rig.v0".to_string(), 0.1),
    ];
    let connections = [
        ("rig.v".to_string(), "friction.v".to_string()),
        ("rig.F_spring".to_string(), "friction.Fn".to_string()),
    ];
    let mut system = System::build(&components, &parameters, &connections).unwrap();
    let run = simulate(&mut system, &mut Jacobi::default(), 1e-3, 1.0).unwrap();
    let error = run.error.expect("the run must stop");
    assert!(
        error.contains("friction") && error.contains("fmi2SetReal") && error.contains("Fn"),
        "{error}"
    );
    // F_spring turns negative after t = 0.0997 s: about 100 rows kept
    assert!(
        (95..=105).contains(&run.rows.len()),
        "kept {} rows",
        run.rows.len()
    );
    assert_eq!(run.rows.len(), run.time.len());
}
