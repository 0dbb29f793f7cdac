//! `fmi2SetReal` of one value (a master's connection, taken on a fast path
//! before the general one) refuses everything the general path refuses,
//! with the same messages, changing nothing; an accepted value has the
//! same effects as a set through a list; calls are still logged. The same
//! of `fmi2GetBoolean` and `fmi2GetInteger` of one value. And the FMU
//! states and replayed steps follow a bristle count changed by a reset
//! (the model's state length changes with it).

mod common;
use common::*;
use fmi_export::ffi::*;
use std::ptr::{null, null_mut};

const ERR: fmi2Status = fmi2Status::fmi2Error;

fn set_one(fmu: &Fmu, vr: u32, x: f64) -> fmi2Status {
    unsafe { fmi2SetReal(fmu.c, &vr, 1, &x) }
}

#[test]
fn one_value_is_checked_as_a_list_is_and_nothing_changes_on_error() {
    let mut fmu = Fmu::new("LuGre", &[]);
    let variables = fmu.variables;
    let var = |name| variables.iter().find(|v| v.name == name).expect(name).vr;
    let (v, fn_, f, sigma0) = (var("v"), var("Fn"), var("F"), var("sigma0"));
    fmu.set("v", 1e-3);
    fmu.step(1e-3);
    let force = fmu.get("F");
    let unchanged = |fmu: &Fmu| {
        assert_eq!(fmu.get("v"), 1e-3);
        assert_eq!(fmu.get("Fn"), 1.0);
        assert_eq!(fmu.get("sigma0"), 1e5);
        assert_eq!(fmu.get("F").to_bits(), force.to_bits());
    };
    let refused = [
        (
            fn_,
            -1.0,
            "Fn (value reference 2) = -1: the normal force must be >= 0",
        ),
        (
            v,
            f64::NAN,
            "v (value reference 0) must be finite but was NaN",
        ),
        (
            v,
            f64::INFINITY,
            "v (value reference 0) must be finite but was inf",
        ),
        (
            sigma0,
            2e5,
            "cannot set sigma0 (value reference 6) in state StepComplete",
        ),
        (
            f,
            1.0,
            "cannot set F (value reference 3) in state StepComplete",
        ),
        (10_000, 1.0, "unknown value reference 10000"),
    ];
    for (vr, x, needle) in refused {
        assert_eq!(set_one(&fmu, vr, x), ERR, "{needle}");
        let m = last_error();
        assert!(m.starts_with("fmi2SetReal: ") && m.contains(needle), "{m}");
        unchanged(&fmu);
    }
    let buffer = [0.0f64; 2];
    // SAFETY: one byte into a live buffer, read by nobody (refused first)
    let misaligned = unsafe { (buffer.as_ptr() as *const u8).add(1) } as *const f64;
    let arrays = [
        (null(), &1.0 as *const f64, "argument vr[] is NULL"),
        (&v as *const u32, null(), "argument value[] is NULL"),
        (&v as *const u32, misaligned, "is not aligned"),
    ];
    for (vrs, values, needle) in arrays {
        assert_eq!(unsafe { fmi2SetReal(fmu.c, vrs, 1, values) }, ERR);
        assert!(last_error().contains(needle), "{}", last_error());
        unchanged(&fmu);
    }

    // Accepted: the same effects as a set through a list (the general
    // path), the replayed step of the directional derivative included.
    let mut other = Fmu::new("LuGre", &[]);
    other.set("v", 1e-3);
    other.step(1e-3);
    for (k, u) in [2e-3, 2e-3, -5e-4, 0.0].into_iter().enumerate() {
        assert_eq!(set_one(&fmu, v, u), OK);
        let (vrs, us) = ([v, var("x")], [u, 0.0]);
        assert_eq!(
            unsafe { fmi2SetReal(other.c, vrs.as_ptr(), 2, us.as_ptr()) },
            OK
        );
        assert_eq!(fmu.get("v"), u);
        // direct feedthrough: F follows v at once, and so does its
        // derivative (no longer the last step's, unless v is unchanged)
        assert_eq!(fmu.get("F").to_bits(), other.get("F").to_bits(), "{k}");
        let (d, e) = (
            fmu.directional_derivative("F", "v"),
            other.directional_derivative("F", "v"),
        );
        assert_eq!(d.to_bits(), e.to_bits(), "{k}");
        fmu.step(1e-3);
        other.step(1e-3);
        assert_eq!(fmu.get("F").to_bits(), other.get("F").to_bits(), "{k}");
        let (d, e) = (
            fmu.directional_derivative("F", "v"),
            other.directional_derivative("F", "v"),
        );
        assert_eq!(d.to_bits(), e.to_bits(), "{k}");
    }

    // Calls are logged on the fast path's input too.
    let categories = [c"logCalls".as_ptr()];
    assert_eq!(
        unsafe { fmi2SetDebugLogging(fmu.c, 1, 1, categories.as_ptr()) },
        OK
    );
    LOG.with(|l| l.borrow_mut().clear());
    assert_eq!(set_one(&fmu, v, 1e-3), OK);
    assert!(
        LOG.with(|l| l.borrow().iter().any(|(_, m)| m.starts_with("fmi2SetReal"))),
        "no call logged"
    );
    // Not in a state that allows it.
    assert_eq!(unsafe { fmi2Terminate(fmu.c) }, OK);
    assert_eq!(set_one(&fmu, v, 3e-3), ERR);
    let m = last_error();
    assert!(m.contains("fmi2SetReal: illegal call sequence"), "{m}");
    assert_eq!(fmu.get("v"), 1e-3);
}

/// Drive `fmu` by `steps` steps of x(t), reading F and ∂F/∂x after each.
fn drive(fmu: &mut Fmu, steps: usize, record: &mut Vec<u64>) {
    let h = 1e-3;
    for _ in 0..steps {
        let x = 5e-8 * (std::f64::consts::TAU * fmu.t).sin();
        fmu.set("x", x);
        fmu.step(h);
        record.push(fmu.get("F").to_bits());
        record.push(fmu.directional_derivative("F", "x").to_bits());
    }
}

#[test]
fn states_and_replays_follow_a_bristle_count_changed_by_a_reset() {
    // 10 bristles, with a state taken; then reset to 40
    let mut a = Fmu::new("Bristle", &[("n_bristles", 10.0)]);
    drive(&mut a, 300, &mut Vec::new());
    let mut saved = a.state();
    unsafe {
        assert_eq!(fmi2Reset(a.c), OK);
        assert_eq!(fmi2SetupExperiment(a.c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(fmi2EnterInitializationMode(a.c), OK);
    }
    a.t = 0.0;
    a.set("n_bristles", 40.0);
    assert_eq!(a.exit_initialization(), OK, "{}", last_error());
    // ... runs as an instance made with 40
    let mut b = Fmu::new("Bristle", &[("n_bristles", 40.0)]);
    let (mut run_a, mut run_b) = (Vec::new(), Vec::new());
    drive(&mut a, 400, &mut run_a);
    drive(&mut b, 400, &mut run_b);
    assert_eq!(run_a, run_b);
    // the 10-bristle state reused for a 40-bristle one, restored, rerun
    assert_eq!(unsafe { fmi2GetFMUstate(a.c, &mut saved) }, OK);
    let t = a.t;
    let (mut first, mut again) = (Vec::new(), Vec::new());
    drive(&mut a, 600, &mut first);
    a.restore(saved, t);
    drive(&mut a, 600, &mut again);
    assert_eq!(first, again);
    let mut continued = Vec::new();
    drive(&mut b, 600, &mut continued);
    assert_eq!(first, continued);
    let mut s = saved;
    assert_eq!(unsafe { fmi2FreeFMUstate(a.c, &mut s) }, OK);
    assert_eq!(s, null_mut());
}

/// `fmi2GetBoolean` and `fmi2GetInteger` of one value (a master recording
/// a flag, taken on a fast path when no model code has to run) give what
/// a read through a list gives, before and after the outputs are brought
/// up to date by `fmi2GetReal`; what the general path refuses is refused
/// alike.
#[test]
fn one_flag_read_is_the_value_a_list_read_gives() {
    let mut first = Fmu::new("LuGre", &[]);
    let mut second = Fmu::new("LuGre", &[]);
    let sliding = first.var("sliding").vr;
    let n_table = first.var("n_table").vr;
    let read_one = |fmu: &Fmu| {
        let mut b = -1;
        assert_eq!(unsafe { fmi2GetBoolean(fmu.c, &sliding, 1, &mut b) }, OK);
        b
    };
    let read_list = |fmu: &Fmu| {
        let (vrs, mut b) = ([sliding, sliding], [-1; 2]);
        assert_eq!(
            unsafe { fmi2GetBoolean(fmu.c, vrs.as_ptr(), 2, b.as_mut_ptr()) },
            OK
        );
        assert_eq!(b[0], b[1]);
        b[0]
    };
    let mut seen = [false; 2];
    for k in 0..400 {
        // sticking, then sliding, then back
        let v = if (100..300).contains(&k) { 0.5 } else { 1e-6 };
        for fmu in [&mut first, &mut second] {
            fmu.set("v", v);
            fmu.step(1e-3);
        }
        // outputs not yet computed (the general path computes them) on
        // one, computed by fmi2GetReal first on the other
        let before = read_one(&first);
        first.get("F");
        second.get("F");
        let after = read_one(&second);
        assert_eq!(before, after, "step {k}");
        assert_eq!(after, read_list(&second), "step {k}");
        seen[after as usize] = true;
        let mut n = -1;
        assert_eq!(unsafe { fmi2GetInteger(second.c, &n_table, 1, &mut n) }, OK);
        assert_eq!(n as f64, second.get_any("n_table"));
    }
    assert_eq!(seen, [true, true], "both sticking and sliding were read");
    // a Real variable, an unknown value reference, NULL: refused
    let (f, unknown, mut b) = (first.var("F").vr, 1_000_000, 0);
    assert_eq!(unsafe { fmi2GetBoolean(first.c, &f, 1, &mut b) }, ERR);
    assert!(last_error().contains("not Boolean"), "{}", last_error());
    assert_eq!(unsafe { fmi2GetBoolean(first.c, &unknown, 1, &mut b) }, ERR);
    assert!(
        last_error().contains("unknown value reference"),
        "{}",
        last_error()
    );
    assert_eq!(
        unsafe { fmi2GetBoolean(first.c, &sliding, 1, null_mut()) },
        ERR
    );
}
