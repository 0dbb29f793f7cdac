//! The force fit's Jacobian from LuGre.fmu's parameter sensitivities (one
//! run of the FMU with `parameter_sensitivities = true`, `∂F/∂p` through
//! `fmi2GetDirectionalDerivative` with the parameters as knowns) against
//! central differences of whole runs, on data from the Rig1D rig (Rig1D.fmu
//! and LuGre.fmu, 10 s at 1 ms): a 1 kg mass on a 2 N/m spring driven by
//! a 3 N sinusoidal force at 0.5 Hz against the friction of Canudas de Wit
//! et al. 1995, which sticks, slips and reverses.

use crate::common;
use fricsim::diagnose::fit;
use fricsim::diagnose::model::{Effect, FrictionModel};
use fricsim::diagnose::problem::FrictionData;
use fricsim::diagnose::sim::FrictionSim;
use fricsim::fmu::Fmu;
use fricsim::master::{jacobi::Jacobi, simulate};
use fricsim::system::System;
use nalgebra::DMatrix;
use std::collections::BTreeSet;
use std::path::Path;

/// The rig's velocity, position and friction force every 1 ms over 10 s,
/// as the intervals of a force fit (the force scaled by 1.1, so that the
/// fit has a residual to reduce).
fn rig1d_data() -> FrictionData {
    let rig = common::repository().join("dist/Rig1D.fmu");
    let lugre = common::lugre_fmu();
    let components = [
        ("rig".to_string(), rig.as_path()),
        ("friction".to_string(), lugre.as_path()),
    ];
    let connections = [
        ("rig.v".to_string(), "friction.v".to_string()),
        ("rig.x".to_string(), "friction.x".to_string()),
        ("friction.F".to_string(), "rig.F".to_string()),
    ];
    let components: Vec<(String, &Path)> =
        components.iter().map(|(n, p)| (n.clone(), *p)).collect();
    let parameters = [
        ("rig.v_a".to_string(), 0.0),
        ("rig.drive_amp".to_string(), 3.0),
        ("rig.drive_freq".to_string(), 0.5),
    ];
    let mut system = System::build(&components, &parameters, &connections).unwrap();
    let run = simulate(&mut system, &mut Jacobi::default(), 1e-3, 10.0).unwrap();
    assert!(run.error.is_none());
    let col = |name: &str| -> Vec<f64> {
        let c = run.columns.iter().position(|c| c == name).unwrap();
        run.rows.iter().map(|r| r[c]).collect()
    };
    let (v, x, f) = (col("rig.v"), col("rig.x"), col("friction.F"));
    let reversals = v.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
    assert!(reversals >= 8, "{reversals} reversals");
    let n = run.time.len() - 1;
    FrictionData {
        t: run.time[..n].to_vec(),
        h: (0..n).map(|k| run.time[k + 1] - run.time[k]).collect(),
        end: (1..=n).collect(),
        v: v[..n].to_vec(),
        x: x[..n].to_vec(),
        fn_: vec![1.0; n],
        f: f[1..].iter().map(|f| 1.1 * f).collect(),
        source: "the stick-slip benchmark on Rig1D".into(),
        position_resolution: None,
        position_step: None,
        normal_force_measured: false,
        trusted: vec![true; n],
        record_starts: vec![0],
    }
}

/// LuGre with every effect whose parameters the diagnosis frees: a
/// position table over the travel with levels by direction, Stribeck,
/// presliding, viscous friction by direction and an offset.
fn everything_free(d: &FrictionData) -> FrictionModel {
    let (lo, hi) =
        d.x.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
    let knots = 5;
    let freed: BTreeSet<Effect> = [
        Effect::Stribeck,
        Effect::Presliding,
        Effect::Viscous,
        Effect::DirectionDependentViscous,
        Effect::Offset,
        Effect::PositionDependent,
        Effect::DirectionDependent,
    ]
    .into_iter()
    .collect();
    FrictionModel {
        fc: 1.0,
        fs: 1.5,
        vs: 1e-3,
        stribeck_exponent: 2.0,
        sigma0: 1e5,
        sigma1: 1e5_f64.sqrt(),
        sigma2: 0.4,
        fc_neg: 0.9,
        fs_neg: 1.35,
        direction_dependent: true,
        normal_force_form: false,
        position_dependent: true,
        f_offset: 0.02,
        direction_dependent_viscous: true,
        sigma2_neg: 0.5,
        x_table: (0..knots)
            .map(|i| lo + (hi - lo) * i as f64 / (knots - 1) as f64)
            .collect(),
        scale_pos: (0..knots).map(|i| 1.0 + 0.05 * i as f64).collect(),
        scale_neg: (0..knots).map(|i| 1.0 - 0.04 * i as f64).collect(),
        freed,
    }
}

/// Every column of the Jacobian from the sensitivities equals central
/// differences of whole runs (step 1e-6 in θ, a relative step of the
/// parameter) to 1e-6 of the column's norm (measured: at most 4e-8,
/// for a scale of the table; 1e-10 for σ2); the free coordinates cover
/// every kind the diagnosis fits (scales of both tables, Stribeck excess
/// and velocity, σ0 with σ1 following, σ2 of both directions, offset).
#[test]
fn force_jacobian_from_sensitivities_equals_differences_on_rig1d() {
    let d = rig1d_data();
    let model = everything_free(&d);
    let fmu = Fmu::open(common::lugre_fmu()).unwrap();
    let mut sim = FrictionSim::new(&fmu).unwrap();
    assert!(sim.has_sensitivities());
    let train: Vec<usize> = (0..d.t.len()).filter(|k| k % 3 != 0).collect();
    let scale = 1.0;
    let free = model.free();
    assert!(free.len() >= 16, "{free:?}");
    let theta = model.theta(&free);
    let exact = fit::force_jacobian(&mut sim, &d, &train, scale, (&model, &free, &theta))
        .expect("a Jacobian from the sensitivities");
    let mut residual =
        |t: &[f64]| fit::force_residuals(&mut sim, &d, &train, scale, &model.at(&free, t)).unwrap();
    let mut differenced = DMatrix::<f64>::zeros(train.len(), free.len());
    for j in 0..free.len() {
        let step = 1e-6 * theta[j].abs().max(1.0);
        let (mut up, mut down) = (theta.clone(), theta.clone());
        up[j] += step;
        down[j] -= step;
        differenced.set_column(j, &((residual(&up) - residual(&down)) / (2.0 * step)));
    }
    for (j, p) in free.iter().enumerate() {
        let (a, b) = (exact.column(j), differenced.column(j));
        let error = (a - b).norm() / b.norm();
        assert!(b.norm() > 0.0, "{p:?}: the column is zero");
        assert!(
            error <= 1e-6,
            "{p:?}: the sensitivities' column differs from the differences by {error:.2e} of its norm"
        );
    }
}

/// Asked for the sensitivity to a parameter it does not carry, or with
/// the sensitivities off, LuGre.fmu refuses with a message that says why.
#[test]
fn parameter_sensitivities_refuse_clearly() {
    use fricsim::fmu::Rollback;
    let fmu = Fmu::open(common::lugre_fmu()).unwrap();
    let vr = |n: &str| fmu.variable(n).unwrap().value_reference;
    let mut i = fmu.instantiate("probe").unwrap();
    i.setup_experiment(0.0, None).unwrap();
    i.enter_initialization_mode().unwrap();
    i.exit_initialization_mode().unwrap();
    i.set_real(&[vr("v")], &[0.01]).unwrap();
    i.do_step_with(0.0, 1e-3, Rollback::Never).unwrap();
    let mut out = [0.0];
    let off = i
        .get_directional_derivative(&[vr("F")], &[vr("Fc")], &[1.0], &mut out)
        .unwrap_err()
        .to_string();
    assert!(off.contains("parameter_sensitivities = true"), "{off}");

    let mut i = fmu.instantiate("probe-on").unwrap();
    i.setup_experiment(0.0, None).unwrap();
    i.enter_initialization_mode().unwrap();
    i.set_boolean(&[vr("parameter_sensitivities")], &[true])
        .unwrap();
    i.exit_initialization_mode().unwrap();
    i.set_real(&[vr("v")], &[0.01]).unwrap();
    i.do_step_with(0.0, 1e-3, Rollback::Never).unwrap();
    let table = i
        .get_directional_derivative(&[vr("F")], &[vr("x_table[2]")], &[1.0], &mut out)
        .unwrap_err()
        .to_string();
    assert!(table.contains("x_table[2]"), "{table}");
    let mixed = i
        .get_directional_derivative(&[vr("F")], &[vr("Fc"), vr("v")], &[1.0, 1.0], &mut out)
        .unwrap_err()
        .to_string();
    assert!(
        mixed.contains("all inputs") && mixed.contains("all parameters"),
        "{mixed}"
    );
    // the sensitivity of F to F_offset is 1, to Fc after 1 ms of sliding
    // from rest ∂F/∂Fc > 0
    i.get_directional_derivative(&[vr("F")], &[vr("F_offset")], &[1.0], &mut out)
        .unwrap();
    assert_eq!(out[0], 1.0);
}
