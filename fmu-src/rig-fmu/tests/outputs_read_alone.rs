//! An output of the state alone (no direct feedthrough) read by itself
//! between steps is computed by itself (`Model::compute_outputs_of`), the
//! others when next read: in every rig and friction FMU, the value read
//! alone and every output read after it are bit for bit those of an
//! instance that reads every output at once.

use fmi_export::instance::Instance;
use fmi_export::logger::Logger;
use fmi_export::{Causality, ModelFactory, VarType};

fn instance(factory: &ModelFactory) -> Instance {
    let logger = Logger::new(
        fmi_export::logger::Callback::Fmi2(None),
        std::ptr::null_mut(),
        "probe",
        false,
    );
    let mut fmu = Instance::new(factory.info, (factory.create)(), "probe", logger);
    fmu.setup_experiment(0.0, None).unwrap();
    fmu.enter_initialization_mode().unwrap();
    fmu.exit_initialization_mode().unwrap();
    fmu
}

#[test]
fn outputs_of_the_state_read_alone_are_the_full_outputs() {
    let factories = rig_fmu::REGISTRY
        .iter()
        .chain(friction_fmu::REGISTRY.iter());
    for factory in factories {
        let info = factory.info;
        // (LuGre's normal force must stay >= 0)
        let of = |causality| -> Vec<u32> {
            info.reals_of(causality)
                .filter(|&vr| info.variables[vr as usize].name != "Fn")
                .collect()
        };
        let (inputs, outputs) = (of(Causality::Input), of(Causality::Output));
        let alone: Vec<u32> = outputs
            .iter()
            .copied()
            .filter(|&o| info.variables[o as usize].depends_on.is_empty())
            .collect();
        assert!(
            !alone.is_empty() || info.model_name != "Rig1D",
            "Rig1D has outputs of the state alone"
        );
        let (mut a, mut b) = (instance(factory), instance(factory));
        let (mut ya, mut yb) = (vec![0.0; outputs.len()], vec![0.0; outputs.len()]);
        let mut u = vec![0.0; inputs.len()];
        let amplitude = if info.model_name == "Bristle" {
            5e-8
        } else {
            1e-3
        };
        let h = 1e-3;
        for k in 0..300 {
            let t = k as f64 * h;
            u.fill(amplitude * (std::f64::consts::TAU * 3.0 * t).sin());
            for fmu in [&mut a, &mut b] {
                fmu.set(VarType::Real, &inputs, &u).unwrap();
                fmu.do_step(t, h).unwrap();
            }
            let mut read_alone = Vec::new();
            for &o in &alone {
                let mut x = [f64::NAN];
                a.get(VarType::Real, &[o], &mut x).unwrap();
                read_alone.push(x[0]);
            }
            a.get(VarType::Real, &outputs, &mut ya).unwrap();
            b.get(VarType::Real, &outputs, &mut yb).unwrap();
            for (i, o) in outputs.iter().enumerate() {
                let name = info.variables[*o as usize].name;
                assert_eq!(ya[i].to_bits(), yb[i].to_bits(), "{name} at step {k}");
            }
            for (x, o) in read_alone.iter().zip(&alone) {
                let i = outputs.iter().position(|p| p == o).unwrap();
                let name = info.variables[*o as usize].name;
                assert_eq!(x.to_bits(), yb[i].to_bits(), "{name} alone at step {k}");
            }
        }
    }
}
