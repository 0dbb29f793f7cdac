//! `Model::write_state_into` writes into a slice of `Model::state_len`
//! values exactly what `Model::save_state` appends to a vector, for every
//! rig, at the start and along a run.

use fmi2_cs::{Causality, Model, Values};

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

#[test]
fn every_rig_writes_its_saved_state_into_a_slice() {
    for factory in rig_fmu::REGISTRY.iter() {
        let info = factory.info;
        let mut model = (factory.create)();
        let mut values = Values::from_start(info.variables);
        model.initialize(&values).unwrap();
        let name = info.model_name;
        assert_writers_agree(&*model, &format!("{name} at the start"));
        let inputs: Vec<u32> = info.reals_of(Causality::Input).collect();
        let slopes = vec![0.0; values.len()];
        let h = 1e-3;
        for k in 0..1000 {
            let u = 0.5 * (std::f64::consts::TAU * k as f64 * h).sin();
            for &vr in &inputs {
                values.set(vr, u);
            }
            model.do_step(&values, &slopes, h).unwrap();
            if k % 100 == 7 {
                assert_writers_agree(&*model, &format!("{name} after step {k}"));
            }
        }
    }
}
