//! `Model::write_state_into` writes into a slice of `Model::state_len`
//! values exactly what `Model::save_state` appends to a vector, for every
//! friction model, at the start and along a run with reversals (the
//! bristle model's state changes shape then), and for bristle counts that
//! change the state's length.

use fmi2_cs::{Causality, Model, ModelFactory, Values};

/// The two writers agree bit for bit on the model's current state.
fn assert_writers_agree(model: &dyn Model, what: &str) {
    let mut saved = vec![1.5]; // save_state appends
    model.save_state(&mut saved);
    let saved = &saved[1..];
    let n = model.state_len().expect("the model writes into a slice");
    assert_eq!(n, saved.len(), "{what}: state_len");
    let mut written = vec![f64::NAN; n];
    model.write_state_into(&mut written);
    let bits = |s: &[f64]| s.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&written), bits(saved), "{what}");
}

fn check(factory: &ModelFactory, params: &[(&str, f64)], amplitude: f64) {
    let info = factory.info;
    let mut model = (factory.create)();
    let mut values = Values::from_start(info.variables);
    for (name, x) in params {
        values.set(info.by_name(name).expect(name).vr, *x);
    }
    model.initialize(&values).unwrap();
    let what = format!("{} {params:?}", info.model_name);
    assert_writers_agree(&*model, &format!("{what} at the start"));
    // every Real input but LuGre's normal force (which must stay >= 0)
    let inputs: Vec<u32> = info
        .reals_of(Causality::Input)
        .filter(|&vr| info.variables[vr as usize].name != "Fn")
        .collect();
    let slopes = vec![0.0; values.len()];
    let h = 1e-3;
    for k in 0..1500 {
        // a 1 Hz sinusoid: stick, slip and reversals
        let u = amplitude * (std::f64::consts::TAU * k as f64 * h).sin();
        for &vr in &inputs {
            values.set(vr, u);
        }
        model.do_step(&values, &slopes, h).unwrap();
        if k % 100 == 7 {
            assert_writers_agree(&*model, &format!("{what} after step {k}"));
        }
    }
}

#[test]
fn every_friction_model_writes_its_saved_state_into_a_slice() {
    for factory in friction_fmu::REGISTRY.iter() {
        if factory.info.model_name == "Bristle" {
            for n in [1.0, 7.0, 100.0] {
                check(factory, &[("n_bristles", n)], 5e-8);
            }
        } else {
            check(factory, &[], 1e-3);
        }
    }
}
