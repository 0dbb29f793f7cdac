//! The Jacobi master's planned step (`System::step_jacobi`) against the
//! Jacobi master written out call by call: every connected output asked
//! for with its own `fmi2GetReal`, every input set with its own
//! `fmi2SetReal`, every output read again for the row. The planned step
//! takes the connected outputs from the last recorded row when no call
//! since could have changed them, sets a component's inputs straight from
//! that row when they are there one after the other, and steps each
//! component right after setting its inputs; whatever the plan, the rows
//! must be the same, bit for bit: with the benchmark's system, with
//! variables recorded after the system was built (the columns the plan
//! reads move), with inputs whose outputs are not in consecutive columns
//! (the general path), and with an observer that sets inputs between the
//! steps (the recorded values are then stale and must be asked for).

use fricsim::master::{communication_time, jacobi::Jacobi, simulate_with, Observer};
use fricsim::system::System;
use fricsim::FmuError;
use std::path::{Path, PathBuf};

const H: f64 = 1e-3;
const STOP: f64 = 3.0;

fn dist(name: &str) -> PathBuf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../dist")
        .join(name);
    assert!(p.exists(), "{} is missing: run ./build-fmu.sh", p.display());
    p
}

/// Rig1D (`rig`) and LuGre (`friction`) connected by `connections`
/// (`from`, `to` ports), with a faster belt so that the body slips
/// within the run.
fn system(connections: &[(&str, &str)]) -> System {
    let rig = dist("Rig1D.fmu");
    let lugre = dist("LuGre.fmu");
    let components = [
        ("rig".to_string(), rig.as_path()),
        ("friction".to_string(), lugre.as_path()),
    ];
    let connections: Vec<(String, String)> = connections
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    System::build(&components, &[("rig.v_a".to_string(), 1.0)], &connections).unwrap()
}

const STICK_SLIP: [(&str, &str); 2] = [("rig.v", "friction.v"), ("friction.F", "rig.F")];

/// What happens between the steps: `before_step` of an [`Observer`].
type Between = fn(&mut System, f64, bool);

fn nothing(_: &mut System, _: f64, _: bool) {}

/// Sets LuGre's input `v` (also connected: the connection sets it again,
/// but LuGre's `F` already follows the value set here, so the `F` of the
/// last row is stale) and the rig's unconnected `F_ext`.
fn nudge(system: &mut System, t: f64, _: bool) {
    for (port, value) in [
        ("friction.v", 0.02 * (7.0 * t).sin()),
        ("rig.F_ext", 0.1 * t),
    ] {
        let (c, var) = system.port(port).unwrap();
        let vr = var.value_reference;
        system.components[c]
            .instance
            .set_real(&[vr], &[value])
            .unwrap();
    }
}

struct Calls(Between);

impl Observer for Calls {
    fn before_step(&mut self, system: &mut System, t: f64, init: bool) -> Result<(), FmuError> {
        (self.0)(system, t, init);
        Ok(())
    }
}

/// The run of [`simulate_with`] with the Jacobi master.
fn planned(mut system: System, between: Between) -> Vec<Vec<f64>> {
    let run = simulate_with(
        &mut system,
        &mut Jacobi::default(),
        0.0,
        H,
        STOP,
        &mut Calls(between),
    )
    .unwrap();
    assert_eq!(run.error, None);
    assert_eq!(run.columns, system.columns());
    run.rows.iter().map(<[f64]>::to_vec).collect()
}

/// The same run, one FMI call per value.
fn call_by_call(mut system: System, between: Between) -> Vec<Vec<f64>> {
    let links: Vec<_> = system.connections.iter().map(|c| (c.from, c.to)).collect();
    let exchange = |system: &mut System| {
        let values: Vec<f64> = links
            .iter()
            .map(|&((c, vr), _)| {
                let mut x = [f64::NAN];
                system.components[c]
                    .instance
                    .get_real(&[vr], &mut x)
                    .unwrap();
                x[0]
            })
            .collect();
        for (&(_, (c, vr)), x) in links.iter().zip(values) {
            system.components[c].instance.set_real(&[vr], &[x]).unwrap();
        }
    };
    let sample = |system: &mut System| {
        let mut row = Vec::new();
        for c in &mut system.components {
            for &(_, vr) in &c.outputs {
                let mut x = [f64::NAN];
                c.instance.get_real(&[vr], &mut x).unwrap();
                row.push(x[0]);
            }
        }
        row
    };
    between(&mut system, 0.0, true);
    exchange(&mut system);
    for c in &mut system.components {
        c.instance.exit_initialization_mode().unwrap();
    }
    exchange(&mut system);
    let n = (STOP / H).round() as usize;
    let mut rows = vec![sample(&mut system)];
    for j in 0..n {
        let t = communication_time(0.0, H, j);
        let t_next = communication_time(0.0, H, j + 1);
        between(&mut system, t, false);
        exchange(&mut system);
        for c in &mut system.components {
            let instance = c.instance.fmi2().expect("FMI 2.0");
            instance.do_step(t, t_next - t).unwrap();
        }
        rows.push(sample(&mut system));
    }
    rows
}

/// The rows of both runs, the same bit for bit; and the body slipped.
fn assert_same(make: impl Fn() -> System, between: Between) {
    let columns = make().columns();
    let planned = planned(make(), between);
    let expected = call_by_call(make(), between);
    assert_eq!(planned.len(), expected.len());
    for (i, (a, b)) in planned.iter().zip(&expected).enumerate() {
        let bits = |r: &[f64]| r.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(a), bits(b), "row {i} of {columns:?}:\n{a:?}\n{b:?}");
    }
    let kv = columns.iter().position(|c| c == "rig.v").unwrap();
    assert!(planned.iter().any(|r| r[kv].abs() > 1e-3), "no slip");
}

#[test]
fn the_benchmark_system_steps_as_call_by_call() {
    assert_same(|| system(&STICK_SLIP), nothing);
}

#[test]
fn variables_recorded_after_the_build_move_the_columns_the_plan_reads() {
    // rig.F_ext and rig.F widen the rig's part of the row: LuGre's F,
    // read by rig.F, moves two columns on; friction.v sits after LuGre's
    // outputs
    assert_same(
        || {
            let mut s = system(&STICK_SLIP);
            s.record("rig.F_ext").unwrap();
            s.record("rig.F").unwrap();
            s.record("friction.v").unwrap();
            s
        },
        nothing,
    );
}

#[test]
fn inputs_read_from_columns_in_another_order_take_the_general_path() {
    // LuGre's inputs x and v (in connection order) from the rig's outputs
    // x and v (consecutive columns): in this order one run of columns, in
    // the other not; the rig's inputs F and F_ext from outputs of two
    // components, not. (Each connection joins ports of the same unit,
    // which System::build checks.)
    for connections in [
        [
            ("rig.x", "friction.x"),
            ("rig.v", "friction.v"),
            ("friction.F", "rig.F"),
        ],
        [
            ("rig.v", "friction.v"),
            ("rig.x", "friction.x"),
            ("friction.F", "rig.F"),
        ],
        [
            ("rig.v", "friction.v"),
            ("friction.F", "rig.F"),
            ("rig.F_spring", "rig.F_ext"),
        ],
    ] {
        assert_same(|| system(&connections), nothing);
    }
}

#[test]
fn inputs_set_between_the_steps_make_the_recorded_outputs_be_asked_for_again() {
    assert_same(|| system(&STICK_SLIP), nudge);
    assert_same(
        || {
            let mut s = system(&STICK_SLIP);
            s.record("friction.v").unwrap();
            s
        },
        nudge,
    );
}
