//! Calls into one instance from two threads at once, through the C ABI of
//! the friction FMU library. FMI 2.0 leaves them undefined; the FMU must
//! refuse the second call with `fmi2Error` and a message, and go on
//! unharmed, instead of running both on one state (which corrupted the
//! heap before the instance guard: a double free in `fmi2GetFMUstate`).

mod common;
use common::*;
use fmi_export::ffi::*;
use std::ffi::{c_void, CStr, CString};
use std::os::raw::{c_char, c_int};
use std::ptr::{null, null_mut};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// The messages logged, by every thread, in order: instance name, status,
/// message.
static MESSAGES: Mutex<Vec<(String, c_int, String)>> = Mutex::new(Vec::new());
/// Set by the test: the logger holds the thread that logs a message
/// containing "must be finite" until [`OTHER_DONE`].
static HOLD_ON_NAN: AtomicBool = AtomicBool::new(false);
/// The held thread is inside its call (in the logger).
static HELD: AtomicBool = AtomicBool::new(false);
/// The other thread has made its calls: the held one may return.
static OTHER_DONE: AtomicBool = AtomicBool::new(false);

extern "C" fn shared_log(
    _e: *mut c_void,
    name: *const c_char,
    status: c_int,
    _c: *const c_char,
    message: *const c_char,
) {
    // SAFETY: the FMU passes NUL-terminated strings.
    let (n, m) = unsafe { (CStr::from_ptr(name), CStr::from_ptr(message)) };
    let (n, m) = (
        n.to_string_lossy().into_owned(),
        m.to_string_lossy().into_owned(),
    );
    let hold = m.contains("must be finite") && HOLD_ON_NAN.load(Ordering::SeqCst);
    MESSAGES.lock().unwrap().push((n, status, m));
    if hold {
        HELD.store(true, Ordering::SeqCst);
        while !OTHER_DONE.load(Ordering::SeqCst) {
            std::thread::yield_now();
        }
    }
}

/// An fmi2Component that may cross threads (the point of the test).
#[derive(Clone, Copy)]
struct Shared(fmi2Component);
// SAFETY: the FMU's own guard is what is being tested.
unsafe impl Send for Shared {}
unsafe impl Sync for Shared {}

const V: u32 = 0; // LuGre input v (checked below by name)
const F: u32 = 3; // LuGre output F

/// A LuGre instance named `name` in step mode, logging into [`MESSAGES`].
fn lugre(name: &str) -> Shared {
    let info = friction_fmu::models()
        .into_iter()
        .find(|m| m.model_name == "LuGre")
        .unwrap();
    assert_eq!(info.variables[V as usize].name, "v");
    assert_eq!(info.variables[F as usize].name, "F");
    let guid = CString::new(info.guid).unwrap();
    let name = CString::new(name).unwrap();
    unsafe {
        let c = fmi2Instantiate(
            name.as_ptr(),
            fmi2CoSimulation,
            guid.as_ptr(),
            null(),
            callbacks_logging_to(shared_log),
            0,
            0,
        );
        assert!(!c.is_null());
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        Shared(c)
    }
}

/// `steps` steps of 1e-4 s at v = 1e-3 m/s from `t`, then the force.
fn run(c: Shared, t: f64, steps: usize) -> f64 {
    let mut f = f64::NAN;
    for k in 0..steps {
        unsafe {
            assert_eq!(fmi2SetReal(c.0, &V, 1, &1e-3), OK);
            assert_eq!(fmi2DoStep(c.0, t + k as f64 * 1e-4, 1e-4, 1), OK);
            assert_eq!(fmi2GetReal(c.0, &F, 1, &mut f), OK);
        }
    }
    f
}

/// The refusals logged by the instance named `name`.
fn refusals(name: &str) -> usize {
    MESSAGES
        .lock()
        .unwrap()
        .iter()
        .filter(|(n, _, m)| n == name && m.contains("another thread is inside a call"))
        .count()
}

/// One thread is held inside a call (its logger does not return); every
/// call the other makes meanwhile is refused, with a message naming the
/// function, and changes nothing: afterwards the instance steps on bit for
/// bit as one that was never touched by the second thread.
#[test]
fn a_call_while_another_runs_is_refused_and_changes_nothing() {
    let shared = lugre("held");
    let untouched = lugre("untouched");
    assert_eq!(run(shared, 0.0, 10), run(untouched, 0.0, 10));

    HOLD_ON_NAN.store(true, Ordering::SeqCst);
    let held = std::thread::spawn(move || {
        let shared = shared; // (the whole Shared, not its pointer field)
        unsafe { fmi2SetReal(shared.0, &V, 1, &f64::NAN) }
    });
    while !HELD.load(Ordering::SeqCst) {
        std::thread::yield_now();
    }
    let mut state: fmi2FMUstate = null_mut();
    let mut f = 0.0;
    let statuses = unsafe {
        [
            ("fmi2DoStep", fmi2DoStep(shared.0, 10.0 * 1e-4, 1e-4, 1)),
            ("fmi2SetReal", fmi2SetReal(shared.0, &V, 1, &5.0)),
            ("fmi2GetReal", fmi2GetReal(shared.0, &F, 1, &mut f)),
            ("fmi2GetFMUstate", fmi2GetFMUstate(shared.0, &mut state)),
            ("fmi2Reset", fmi2Reset(shared.0)),
        ]
    };
    // Freeing it now would pull the state from under the held call: the
    // instance stays, and the refusal is logged.
    unsafe { fmi2FreeInstance(shared.0) };
    OTHER_DONE.store(true, Ordering::SeqCst);
    HOLD_ON_NAN.store(false, Ordering::SeqCst);
    assert_eq!(
        held.join().unwrap(),
        fmi2Status::fmi2Error,
        "NaN is refused"
    );

    for (function, status) in statuses {
        assert_eq!(status, fmi2Status::fmi2Error, "{function}");
    }
    assert!(state.is_null(), "no state was handed out");
    assert_eq!(f, 0.0, "nothing was written to the caller's array");
    let log = MESSAGES.lock().unwrap().clone();
    for function in [
        "fmi2DoStep",
        "fmi2SetReal",
        "fmi2GetReal",
        "fmi2GetFMUstate",
        "fmi2Reset",
        "fmi2FreeInstance",
    ] {
        assert!(
            log.iter().any(|(n, status, m)| n == "held"
                && *status == 3
                && m.starts_with(&format!("{function}: refused: another thread"))),
            "no refusal of {function} logged in {log:#?}"
        );
    }
    assert_eq!(refusals("held"), 6);
    assert_eq!(refusals("untouched"), 0);

    // The instance is alive and where it was: it steps on as the untouched one.
    assert_eq!(
        run(shared, 10.0 * 1e-4, 20),
        run(untouched, 10.0 * 1e-4, 20)
    );
    unsafe {
        fmi2FreeInstance(shared.0);
        fmi2FreeInstance(untouched.0);
    }
}

/// Two threads calling one instance as fast as they can: every call
/// returns fmi2OK or fmi2Error (no crash, no fmi2Fatal), every fmi2Error is
/// a refusal with its message, and every state handed out is freed once.
#[test]
fn two_threads_hammering_one_instance_never_corrupt_it() {
    let shared = lugre("hammered");
    let errors = AtomicUsize::new(0);
    std::thread::scope(|scope| {
        for k in 0..2 {
            let errors = &errors;
            scope.spawn(move || {
                let shared = shared; // (the whole Shared, not its pointer field)
                for i in 0..20_000 {
                    let v = (k * 20_000 + i) as f64 * 1e-6;
                    let mut state: fmi2FMUstate = null_mut();
                    let mut f = 0.0;
                    let statuses = unsafe {
                        let get = fmi2GetFMUstate(shared.0, &mut state);
                        let set = fmi2SetReal(shared.0, &V, 1, &v);
                        let read = fmi2GetReal(shared.0, &F, 1, &mut f);
                        let free = if get == OK {
                            // a refusal here leaves it to be freed again
                            let mut free = fmi2FreeFMUstate(shared.0, &mut state);
                            while free != OK {
                                errors.fetch_add(1, Ordering::SeqCst);
                                assert_eq!(free, fmi2Status::fmi2Error);
                                free = fmi2FreeFMUstate(shared.0, &mut state);
                            }
                            free
                        } else {
                            OK
                        };
                        [get, set, read, free]
                    };
                    for status in statuses {
                        match status {
                            fmi2Status::fmi2OK => {}
                            fmi2Status::fmi2Error => {
                                errors.fetch_add(1, Ordering::SeqCst);
                            }
                            other => panic!("status {other:?}"),
                        }
                    }
                    assert!(f.is_finite());
                }
            });
        }
    });
    let errors = errors.load(Ordering::SeqCst);
    assert_eq!(
        refusals("hammered"),
        errors,
        "every error is a logged refusal"
    );
    // Still whole: it steps, and a state round-trips.
    let f = run(shared, 0.0, 10);
    assert!(f.is_finite());
    unsafe { fmi2FreeInstance(shared.0) };
}
