//! The hot path — `set_real`, `do_step`, `get_real`, and a whole macro
//! step of the Jacobi and Newton masters — does not allocate on the host
//! side. A counting global allocator sees every Rust allocation of the
//! thread that runs the loop (the FMU binaries have their own).

mod common;

use fricsim::fmu::{Fmu, Instance};

#[path = "../../fmu-src/fmi-export/tests/support/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::{allocations, Counting};

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by 1000 steps of set, step, get.
fn allocations_in_loop(i: &mut Instance, input: u32, output: u32) -> usize {
    let mut out = [0.0];
    let before = allocations();
    for k in 0..1000u32 {
        let t = k as f64 * 1e-3;
        i.set_real(&[input], &[1e-3]).unwrap();
        i.do_step(t, 1e-3).unwrap();
        i.get_real(&[output], &mut out).unwrap();
    }
    allocations() - before
}

#[test]
fn set_step_get_do_not_allocate() {
    // The C stub.
    let dir = common::stub_fmu_dir("", &[]);
    let stub = Fmu::from_dir(dir.path()).unwrap();
    let mut a = stub.instantiate("a").unwrap();
    assert_eq!(allocations_in_loop(&mut a, 0, 1), 0);

    // The counter works: a failing call allocates its error.
    let before = allocations();
    a.set_real(&[0], &[f64::NAN]).unwrap_err();
    assert!(allocations() > before);

    // LuGre.fmu.
    let lugre = Fmu::open(common::lugre_fmu()).unwrap();
    let (v, f) = (
        lugre.variable("v").unwrap().value_reference,
        lugre.variable("F").unwrap().value_reference,
    );
    let mut i = lugre.instantiate("lugre").unwrap();
    i.setup_experiment(0.0, None).unwrap();
    i.enter_initialization_mode().unwrap();
    i.exit_initialization_mode().unwrap();
    assert_eq!(allocations_in_loop(&mut i, v, f), 0);

    // Macro steps of the stick-slip system, past the first (which sizes
    // the masters' buffers and, for Newton, checks the directional
    // derivatives against finite differences once).
    common::lugre_fmu(); // dist/ is built
    let file = fricsim::ssp::SystemFile::open(common::repository().join("examples/stick_slip.ssd"))
        .unwrap();
    for name in ["jacobi", "newton"] {
        let mut master = fricsim::master::by_name(name).unwrap();
        let mut system = file.build(0.0).unwrap();
        let mut buffer = vec![0.0; system.connections.len()];
        system.propagate(&mut buffer).unwrap();
        for c in &mut system.components {
            c.instance.exit_initialization_mode().unwrap();
        }
        let h = 1e-4;
        for k in 0..10 {
            master.step(&mut system, k as f64 * h, h).unwrap();
        }
        let before = allocations();
        for k in 10..1010 {
            master.step(&mut system, k as f64 * h, h).unwrap();
        }
        let made = allocations() - before;
        assert_eq!(made, 0, "{name}: {made} allocations in 1000 steps");
    }
}
