//! A communication step of every friction FMU — set the inputs, step, get
//! the outputs, as a master's loop does through `fmi2SetReal`,
//! `fmi2DoStep`, `fmi2GetReal` — does not allocate once the first step has
//! sized the instance's buffers (the pre-step state kept for directional
//! derivatives included). A counting global allocator sees every
//! allocation of the thread that steps the FMU.

use fmi_export::instance::Instance;
use fmi_export::logger::Logger;
use fmi_export::{Causality, VarType};

#[path = "../../fmi-export/tests/support/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::{allocations, Counting};

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn set_step_get_do_not_allocate_in_any_friction_fmu() {
    for factory in friction_fmu::REGISTRY.iter() {
        let info = factory.info;
        let logger = Logger::new(
            fmi_export::logger::Callback::Fmi2(None),
            std::ptr::null_mut(),
            "probe",
            false,
        );
        let mut fmu = Instance::new(info, (factory.create)(), "probe", logger);
        // every Real input but LuGre's normal force (which must stay >= 0)
        let of = |causality| -> Vec<u32> {
            info.reals_of(causality)
                .filter(|&vr| info.variables[vr as usize].name != "Fn")
                .collect()
        };
        let (inputs, outputs) = (of(Causality::Input), of(Causality::Output));
        fmu.setup_experiment(0.0, None).unwrap();
        fmu.enter_initialization_mode().unwrap();
        fmu.exit_initialization_mode().unwrap();
        let (mut u, mut y) = (vec![0.0; inputs.len()], vec![0.0; outputs.len()]);
        let h = 1e-3;
        // a 1 Hz sinusoid of a few bristle ranges: stick, slip and reversals
        let amplitude = if info.model_name == "Bristle" {
            5e-8
        } else {
            1e-3
        };
        let mut step = |fmu: &mut Instance, k: usize| {
            let t = k as f64 * h;
            u.fill(amplitude * (std::f64::consts::TAU * t).sin());
            fmu.set(VarType::Real, &inputs, &u).unwrap();
            fmu.do_step(t, h).unwrap();
            fmu.get(VarType::Real, &outputs, &mut y).unwrap();
        };
        step(&mut fmu, 0); // sizes the buffers
        let before = allocations();
        for k in 1..2000 {
            step(&mut fmu, k);
        }
        let made = allocations() - before;
        // the counter works: a snapshot (fmi2GetFMUstate) allocates
        let counted = allocations();
        let snapshot = fmu.snapshot().unwrap();
        assert!(allocations() > counted);
        drop(snapshot);
        // the bristle law allocates at a reversal with disconnected
        // bristles only (its sorted offsets are rebuilt): twice a period
        let allowed = if info.model_name == "Bristle" {
            2 * 2 * 3
        } else {
            0
        };
        assert!(
            made <= allowed,
            "{}: {made} allocations in 1999 steps",
            info.model_name
        );
    }
}
