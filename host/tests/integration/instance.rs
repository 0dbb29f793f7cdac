//! The safe instance API against the C stub FMU (tests/c/stub_fmu.c): values,
//! steps, statuses turned into errors with the FMU's own messages, the
//! variadic logger (formatting and long messages), and freeing.

use crate::common;

use common::stub_fmu_dir;
use fricsim::fmu::{Fmu, Rollback, Status};
use fricsim::master::{by_name, simulate};
use fricsim::system::System;
use fricsim::FmuError;
use tempfile::TempDir;

const U: u32 = 0;
const Y: u32 = 1;

fn stub() -> (TempDir, Fmu) {
    let dir = stub_fmu_dir("", &[]);
    let fmu = Fmu::from_dir(dir.path()).unwrap();
    (dir, fmu)
}

/// How many stub instances are alive, asked from the loaded stub itself
/// (dlopen of the same path returns the same library).
fn live_instances(fmu: &Fmu) -> i32 {
    // SAFETY: the stub exports `int stub_live_instances(void)`.
    unsafe {
        let library = libloading::Library::new(fmu.library().path()).unwrap();
        let f: libloading::Symbol<unsafe extern "C" fn() -> i32> =
            library.get("stub_live_instances").unwrap();
        f()
    }
}

/// How many `fmi2DoStep` calls the loaded stub has seen with
/// `noSetFMUStatePriorToCurrentPoint` = `no_prior`, all instances together.
fn steps_with(fmu: &Fmu, no_prior: bool) -> i32 {
    // SAFETY: the stub exports `int stub_steps(int)`.
    unsafe {
        let library = libloading::Library::new(fmu.library().path()).unwrap();
        let f: libloading::Symbol<unsafe extern "C" fn(i32) -> i32> =
            library.get("stub_steps").unwrap();
        f(i32::from(no_prior))
    }
}

/// `noSetFMUStatePriorToCurrentPoint` (FMI 2.0.4 §4.2.2): true from the
/// masters that only go forward, as FMPy's `simulate_fmu` passes it, so
/// that an FMU may drop what it keeps for rollbacks; false from
/// `Instance::do_step`, and from `do_step_with(Rollback::Possible)`.
#[test]
fn forward_masters_tell_the_fmu_no_state_is_restored() {
    let (dir, fmu) = stub();
    for master in ["jacobi", "gauss-seidel", "gauss-seidel-interpolated"] {
        let fmus = ["a", "b"].map(|name| (name.to_string(), Fmu::from_dir(dir.path()).unwrap()));
        let connections = [("a.y".to_string(), "b.u".to_string())];
        let mut system = System::from_fmus(fmus.into(), &[], &connections, 0.0).unwrap();
        let before = (steps_with(&fmu, false), steps_with(&fmu, true));
        let run = simulate(&mut system, by_name(master).unwrap().as_mut(), 0.1, 1.0).unwrap();
        assert_eq!(run.time.len(), 11, "{master}");
        assert_eq!(
            (steps_with(&fmu, false), steps_with(&fmu, true)),
            (before.0, before.1 + 20),
            "{master}: every step of both instances final"
        );
    }
    let mut a = fmu.instantiate("a").unwrap();
    a.setup_experiment(0.0, None).unwrap();
    a.enter_initialization_mode().unwrap();
    a.exit_initialization_mode().unwrap();
    let before = (steps_with(&fmu, false), steps_with(&fmu, true));
    a.do_step(0.0, 0.5).unwrap();
    a.do_step_with(0.5, 0.5, Rollback::Possible).unwrap();
    a.do_step_with(1.0, 0.5, Rollback::Never).unwrap();
    assert_eq!(
        (steps_with(&fmu, false), steps_with(&fmu, true)),
        (before.0 + 2, before.1 + 1)
    );
}

#[test]
fn values_and_steps() {
    let (_dir, fmu) = stub();
    assert_eq!(fmu.variable("u").unwrap().value_reference, U);
    assert_eq!(fmu.variable("y").unwrap().value_reference, Y);
    let mut a = fmu.instantiate("a").unwrap();
    assert_eq!(a.name(), "a");
    a.setup_experiment(0.0, Some(1.0)).unwrap();
    a.enter_initialization_mode().unwrap();
    a.exit_initialization_mode().unwrap();
    assert_eq!(a.set_real(&[U], &[1.25]).unwrap(), Status::Ok);
    a.do_step(0.0, 0.5).unwrap();
    let mut out = [0.0; 2];
    a.get_real(&[U, Y], &mut out).unwrap();
    assert_eq!(out, [1.25, 2.5]);
    assert_eq!(a.last_successful_time().unwrap(), 0.5);
    assert!(!a.terminated().unwrap());
    a.terminate().unwrap();
    a.reset().unwrap();
    a.get_real(&[Y], &mut out[..1]).unwrap();
    assert_eq!(out[0], 0.0);
    assert!(
        fmu.log().messages().is_empty(),
        "{:?}",
        fmu.log().messages()
    );
}

#[test]
fn a_failed_call_carries_function_instance_status_and_the_fmus_message() {
    let (_dir, fmu) = stub();
    let mut a = fmu.instantiate("left wheel").unwrap();
    a.set_real(&[U], &[3.0]).unwrap();
    let e = a.set_real(&[U], &[f64::NAN]).unwrap_err();
    match &e {
        FmuError::Call {
            function,
            instance,
            status,
            messages,
        } => {
            assert_eq!(
                (*function, instance.as_str(), *status),
                ("fmi2SetReal", "left wheel", Status::Error)
            );
            // Formatted by logger.c from "%s (vr %u) must not be NaN".
            assert_eq!(messages, &["fmi2SetReal: u (vr 0) must not be NaN"]);
        }
        other => panic!("{other}"),
    }
    assert_eq!(e.status(), Some(Status::Error));
    assert_eq!(
        e.to_string(),
        "fmi2SetReal failed for instance \"left wheel\" with fmi2Error: fmi2SetReal: u (vr 0) must not be NaN"
    );
    // The log has it too, attributed to the instance.
    let log = fmu.log().messages_of("left wheel");
    assert_eq!(log.len(), 1);
    assert_eq!(
        (log[0].status, log[0].category.as_str()),
        (Status::Error, "logError")
    );
    assert_eq!(
        log[0].to_string(),
        "[left wheel] fmi2Error [logError]: fmi2SetReal: u (vr 0) must not be NaN"
    );

    // The instance is still usable; a later error shows its own message only.
    let e = a.get_real(&[7], &mut [0.0]).unwrap_err();
    assert!(
        e.to_string()
            .ends_with("fmi2GetReal: unknown value reference 7"),
        "{e}"
    );

    // Discard is an error too.
    let e = a.do_step(0.0, 0.0).unwrap_err();
    assert_eq!(e.status(), Some(Status::Discard));
    assert!(e.to_string().contains("step size h = 0 must be > 0"), "{e}");
}

#[test]
fn a_warning_is_ok_and_a_long_message_is_not_truncated() {
    let (_dir, fmu) = stub();
    let mut a = fmu.instantiate("a").unwrap();
    assert_eq!(a.set_real(&[U], &[12345.0]).unwrap(), Status::Warning);
    let log = fmu.log().messages_of("a");
    assert_eq!(log.len(), 1);
    assert_eq!(log[0].status, Status::Warning);
    assert_eq!(log[0].message.len(), 3000);
    assert!(log[0].message.starts_with("xxxx") && log[0].message.ends_with("END"));
}

#[test]
fn messages_are_kept_per_instance() {
    let (_dir, fmu) = stub();
    let mut a = fmu.instantiate("a").unwrap();
    let mut b = fmu.instantiate("b").unwrap();
    a.set_real(&[U], &[f64::NAN]).unwrap_err();
    let e = b.set_real(&[9], &[1.0]).unwrap_err();
    assert!(
        e.to_string().contains("cannot set value reference 9"),
        "{e}"
    );
    assert!(
        !e.to_string().contains("NaN"),
        "a's message leaked into b's error: {e}"
    );
    assert_eq!(fmu.log().messages_of("a").len(), 1);
    assert_eq!(fmu.log().messages_of("b").len(), 1);
    fmu.log().clear();
    assert!(fmu.log().messages().is_empty());
}

#[test]
fn instantiation_failure_reports_the_fmus_message() {
    let dir = stub_fmu_dir("", &[]);
    let xml = std::fs::read_to_string(dir.path().join("modelDescription.xml")).unwrap();
    std::fs::write(
        dir.path().join("modelDescription.xml"),
        xml.replace("{stub}", "{other}"),
    )
    .unwrap();
    let fmu = Fmu::from_dir(dir.path()).unwrap();
    let e = fmu.instantiate("x").unwrap_err();
    assert!(matches!(&e, FmuError::Instantiate { .. }), "{e}");
    assert_eq!(
        e.to_string(),
        "fmi2Instantiate failed for instance \"x\": fmi2Instantiate: wrong GUID {other} or type 1"
    );
}

#[test]
fn arguments_are_checked_before_the_fmu_sees_them() {
    let (_dir, fmu) = stub();
    let mut a = fmu.instantiate("a").unwrap();
    let e = a.get_real(&[U, Y], &mut [0.0]).unwrap_err();
    assert!(
        matches!(
            e,
            FmuError::LengthMismatch {
                function: "fmi2GetReal",
                expected: 2,
                found: 1,
                ..
            }
        ),
        "{e}"
    );
    let e = a.set_real(&[U], &[1.0, 2.0]).unwrap_err();
    assert!(
        e.to_string()
            .contains("fmi2SetReal: values has length 2, expected 1"),
        "{e}"
    );
    // Capabilities the stub does not declare.
    let e = a.get_state().unwrap_err();
    assert_eq!(
        e.to_string(),
        "fmi2GetFMUstate is not available: the FMU does not declare canGetAndSetFMUstate=\"true\""
    );
    assert!(matches!(
        a.get_directional_derivative(&[Y], &[U], &[1.0], &mut [0.0]),
        Err(FmuError::NotSupported { .. })
    ));
    assert!(matches!(
        a.set_real_input_derivatives(&[U], &[1], &[1.0]),
        Err(FmuError::NotSupported { .. })
    ));
    assert!(matches!(
        a.get_real_output_derivatives(&[Y], &[1], &mut [0.0]),
        Err(FmuError::NotSupported { .. })
    ));
    // Names with NUL cannot be passed to C.
    assert!(matches!(
        fmu.instantiate("a\0b"),
        Err(FmuError::NulInString { .. })
    ));
}

#[test]
fn drop_frees_the_instance_but_not_after_fatal() {
    let (_dir, fmu) = stub();
    let base = live_instances(&fmu);
    let a = fmu.instantiate("a").unwrap();
    let mut b = fmu.instantiate("b").unwrap();
    assert_eq!(live_instances(&fmu), base + 2);
    drop(a);
    assert_eq!(live_instances(&fmu), base + 1);

    b.set_real(&[U], &[-1.0]).unwrap();
    let e = b.do_step(0.0, 0.1).unwrap_err();
    assert_eq!(e.status(), Some(Status::Fatal));
    assert!(e.to_string().contains("u = -1 breaks everything"), "{e}");
    let e = b.get_real(&[Y], &mut [0.0]).unwrap_err();
    assert!(
        matches!(
            e,
            FmuError::AfterFatal {
                function: "fmi2GetReal",
                ..
            }
        ),
        "{e}"
    );
    drop(b);
    // §2.1.3: no call after fmi2Fatal, not even fmi2FreeInstance.
    assert_eq!(live_instances(&fmu), base + 1);
}

#[test]
fn an_instance_outlives_its_fmu_handle() {
    let (_dir, fmu) = stub();
    let mut a = fmu.instantiate("a").unwrap();
    drop(fmu);
    a.set_real(&[U], &[2.0]).unwrap();
    a.do_step(0.0, 1.0).unwrap();
    let mut y = [0.0];
    a.get_real(&[Y], &mut y).unwrap();
    assert_eq!(y, [4.0]);
    assert_eq!(a.fmu().description().model_name, "Stub");
}
