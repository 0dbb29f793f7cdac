//! `fmi2SetFMUstate` of a state the instance took with its current
//! parameters (restored in place, the snapshot left in the instance's
//! list): a model state the model refuses (taken in state Error, after a
//! step that overflowed) is refused with the model's reason and changes
//! nothing; a good one restores the instance, out of Error, and the run
//! continues as from the snapshot.

mod common;
use common::*;
use fmi_export::ffi::*;
use std::ptr::null_mut;

#[test]
fn a_refused_state_changes_nothing_and_a_good_one_restores() {
    let mut fmu = Fmu::new("Rig1D", &[("k", 1e-300)]);
    fmu.set("F", 1.0);
    fmu.step(1e-3);
    let good = fmu.state();
    let t_good = fmu.t;
    let x_good = fmu.get("x");
    // a force of -1e300 on a stiffness of 1e-300 over a long step
    fmu.set("F", -1e300);
    let status = unsafe { fmi2DoStep(fmu.c, fmu.t, 1e10, 0) };
    assert_eq!(status, fmi2Status::fmi2Error);
    assert!(
        last_error().contains("the model state became"),
        "{}",
        last_error()
    );
    let mut bad = null_mut();
    assert_eq!(unsafe { fmi2GetFMUstate(fmu.c, &mut bad) }, OK);
    // refused, and still in Error (no step allowed), nothing restored
    assert_eq!(
        unsafe { fmi2SetFMUstate(fmu.c, bad) },
        fmi2Status::fmi2Error
    );
    let m = last_error();
    assert!(
        m.starts_with(
            "fmi2SetFMUstate: cannot restore the FMU state: Rig1D state must be 4 finite numbers"
        ),
        "{m}"
    );
    assert_eq!(
        unsafe { fmi2DoStep(fmu.c, fmu.t, 1e-3, 0) },
        fmi2Status::fmi2Error
    );
    assert!(
        last_error().contains("illegal call sequence"),
        "{}",
        last_error()
    );
    // the good state restores, and the run goes on from it
    fmu.restore(good, t_good);
    assert_eq!(fmu.get("x"), x_good);
    assert_eq!(fmu.get("F"), 1.0);
    fmu.step(1e-3);
    let mut again = Fmu::new("Rig1D", &[("k", 1e-300)]);
    again.set("F", 1.0);
    again.step(1e-3);
    again.step(1e-3);
    assert_eq!(fmu.get("x").to_bits(), again.get("x").to_bits());
    for mut s in [good, bad] {
        assert_eq!(unsafe { fmi2FreeFMUstate(fmu.c, &mut s) }, OK);
    }
}
