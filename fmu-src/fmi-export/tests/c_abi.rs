//! The C edge of the FMI layer, exercised through the exported functions
//! with a toy model: the state table, null pointers, unknown pointers,
//! panics, NaN, serialized-state corruption and logging.

use fmi_export::ffi::*;
use fmi_export::{
    Capabilities, DefaultExperiment, Model, ModelFactory, ModelInfo, Values, Variable,
};
use std::ffi::CString;
use std::os::raw::c_char;
use std::ptr::{null, null_mut};

// ---- a toy model: y = k*u + s, ds/dt = u; panics in a step when u = 13 ----

const U: u32 = 0;
const Y: u32 = 1;
const K: u32 = 2;
static VARIABLES: [Variable; 3] = [
    Variable::input(U, "u", 0.0, "", 1.0, "input"),
    Variable::output(Y, "y", "", "k*u + integral of u", &[U]),
    Variable::parameter(K, "k", 2.0, "", "gain, > 0"),
];
static INFO: ModelInfo = ModelInfo {
    model_name: "Toy",
    model_identifier: "Toy",
    guid: "{toy}",
    description: "test model",
    source: "test",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 1.0,
        step_size: 0.1,
    },
    capabilities: Capabilities::FULL,
    co_simulation_states: &[],
    model_exchange: None,
};

#[derive(Clone)]
struct Toy {
    k: f64,
    s: f64,
}

impl Model for Toy {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }
    fn initialize(&mut self, v: &Values) -> Result<(), String> {
        let k = v.real(K);
        if k <= 0.0 {
            return Err(format!("invalid parameter k = {k}: must be > 0"));
        }
        self.k = k;
        self.s = 0.0;
        Ok(())
    }
    fn compute_outputs(&self, v: &mut Values) {
        v.set(Y, self.k * v.real(U) + self.s);
    }
    fn do_step(&mut self, v: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        if v.real(U) == 13.0 {
            panic!("unlucky input");
        }
        self.s += v.real(U) * h + 0.5 * slopes[U as usize] * h * h;
        Ok(())
    }
    fn save_state(&self, out: &mut Vec<f64>) {
        out.push(self.s);
    }
    // Answered by the model, so that the layer neither copies nor scans the
    // state after a step (the rig FMUs' tests cover the layer's own scan).
    fn state_is_finite(&self) -> Option<bool> {
        Some(self.s.is_finite())
    }
    fn restore_state(&mut self, s: &[f64]) -> Result<(), String> {
        match s {
            [x] => {
                self.s = *x;
                Ok(())
            }
            _ => Err(format!("expected 1 number, got {}", s.len())),
        }
    }
    fn clone_model(&self) -> Box<dyn Model> {
        Box::new(self.clone())
    }
}

static REGISTRY: [ModelFactory; 1] = [ModelFactory {
    info: &INFO,
    create: || Box::new(Toy { k: 1.0, s: 0.0 }),
    create_model_exchange: None,
}];
fmi_export::export_fmi2!(&REGISTRY[..]);
use fmi2_exports::*;

#[path = "support/recording_logger.rs"]
mod recording_logger;
use recording_logger::{callbacks, log_clear, log_snapshot};
#[path = "support/probes.rs"]
mod probes;

fn last_error_containing(needle: &str) -> String {
    let log = log_snapshot();
    let found = log
        .iter()
        .rev()
        .find(|(s, _, m)| *s >= 3 && m.contains(needle));
    found
        .map(|(_, _, m)| m.clone())
        .unwrap_or_else(|| panic!("no error message containing {needle:?} in {log:?}"))
}

fn new_instance(name: &str) -> fmi2Component {
    let cb = Box::leak(Box::new(callbacks()));
    let name = CString::new(name).unwrap();
    let c = unsafe {
        fmi2Instantiate(
            name.as_ptr(),
            fmi2CoSimulation,
            c"{toy}".as_ptr(),
            null(),
            cb,
            0,
            0,
        )
    };
    assert!(!c.is_null());
    c
}

fn initialized(name: &str) -> fmi2Component {
    let c = new_instance(name);
    unsafe {
        assert_eq!(
            fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            fmi2Status::fmi2OK
        );
        assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2Status::fmi2OK);
    }
    c
}

fn get(c: fmi2Component, vr: u32) -> f64 {
    let mut x = f64::NAN;
    assert_eq!(
        unsafe { fmi2GetReal(c, &vr, 1, &mut x) },
        fmi2Status::fmi2OK
    );
    x
}

fn set(c: fmi2Component, vr: u32, x: f64) -> fmi2Status {
    unsafe { fmi2SetReal(c, &vr, 1, &x) }
}

const OK: fmi2Status = fmi2Status::fmi2OK;
const ERR: fmi2Status = fmi2Status::fmi2Error;

#[test]
fn lifecycle_and_feedthrough() {
    let c = initialized("life");
    assert_eq!(set(c, U, 1.5), OK);
    assert_eq!(get(c, Y), 3.0); // direct feedthrough before any step
    unsafe {
        assert_eq!(fmi2DoStep(c, 0.0, 0.5, 1), OK);
        assert_eq!(get(c, Y), 3.0 + 0.75);
        assert_eq!(fmi2Terminate(c), OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn instantiate_refuses_bad_arguments_with_a_message() {
    let cb = Box::leak(Box::new(callbacks()));
    unsafe {
        assert!(fmi2Instantiate(
            c"x".as_ptr(),
            fmi2ModelExchange,
            c"{toy}".as_ptr(),
            null(),
            cb,
            0,
            0
        )
        .is_null());
        last_error_containing("fmuType = 0");
        assert!(fmi2Instantiate(
            c"x".as_ptr(),
            fmi2CoSimulation,
            c"{nope}".as_ptr(),
            null(),
            cb,
            0,
            0
        )
        .is_null());
        last_error_containing("unknown fmuGUID {nope}");
        assert!(
            fmi2Instantiate(c"x".as_ptr(), fmi2CoSimulation, null(), null(), cb, 0, 0).is_null()
        );
        last_error_containing("fmuGUID is NULL");
        assert!(fmi2Instantiate(
            c"x".as_ptr(),
            fmi2CoSimulation,
            c"{toy}".as_ptr(),
            null(),
            null(),
            0,
            0
        )
        .is_null());
    }
}

#[test]
fn null_and_foreign_component_pointers_are_refused() {
    let mut x = 0.0;
    let vr = Y;
    let mut bogus = [0u64; 64];
    let foreign = bogus.as_mut_ptr() as fmi2Component;
    unsafe {
        assert_eq!(fmi2GetReal(null_mut(), &vr, 1, &mut x), ERR);
        assert_eq!(fmi2GetReal(foreign, &vr, 1, &mut x), ERR);
        assert_eq!(fmi2DoStep(foreign, 0.0, 0.1, 0), ERR);
        fmi2FreeInstance(foreign); // ignored, no crash
        fmi2FreeInstance(null_mut());
    }
    // a freed instance is no longer accepted (no use after free)
    let c = initialized("freed");
    unsafe {
        fmi2FreeInstance(c);
        assert_eq!(fmi2GetReal(c, &vr, 1, &mut x), ERR);
        fmi2FreeInstance(c); // double free is ignored
    }
}

#[test]
fn null_arrays_and_unknown_references() {
    let c = initialized("arrays");
    let vr = Y;
    let mut x = 0.0;
    unsafe {
        assert_eq!(fmi2GetReal(c, null(), 1, &mut x), ERR);
        last_error_containing("fmi2GetReal: argument vr[] is NULL");
        assert_eq!(fmi2GetReal(c, &vr, 1, null_mut()), ERR);
        last_error_containing("value[] is NULL");
        assert_eq!(fmi2GetReal(c, null(), 0, null_mut()), OK);
        assert_eq!(fmi2GetReal(c, &vr, usize::MAX, &mut x), ERR);
        let bad = 77u32;
        assert_eq!(fmi2GetReal(c, &bad, 1, &mut x), ERR);
        last_error_containing("unknown value reference 77");
        let mut i = 0;
        assert_eq!(fmi2GetInteger(c, &vr, 1, &mut i), ERR);
        last_error_containing("is a Real variable, not Integer");
        assert_eq!(set(c, Y, 1.0), ERR);
        last_error_containing("cannot set y");
        fmi2FreeInstance(c);
    }
}

#[test]
fn non_finite_values_are_refused_and_nothing_is_lost() {
    let c = initialized("nan");
    assert_eq!(set(c, U, 0.25), OK);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(set(c, U, bad), ERR);
        let m = last_error_containing("fmi2SetReal: u (value reference 0) must be finite");
        assert!(
            m.to_lowercase().contains(&bad.to_string().to_lowercase()),
            "{m}"
        );
        assert_eq!(get(c, U), 0.25);
    }
    // a batch with one bad value sets nothing
    let vrs = [U, U];
    let vals = [0.5, f64::NAN];
    assert_eq!(
        unsafe { fmi2SetReal(c, vrs.as_ptr(), 2, vals.as_ptr()) },
        ERR
    );
    assert_eq!(get(c, U), 0.25);
    unsafe { fmi2FreeInstance(c) };
}

#[test]
fn invalid_parameter_is_refused_at_exit_initialization() {
    let c = new_instance("param");
    unsafe {
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(set(c, K, -1.0), OK);
        assert_eq!(fmi2ExitInitializationMode(c), ERR);
        last_error_containing("fmi2ExitInitializationMode: invalid parameter k = -1");
        // still in initialization mode: fix it and go on
        assert_eq!(set(c, K, 3.0), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 0), OK);
        // a fixed parameter cannot change now
        assert_eq!(set(c, K, 4.0), ERR);
        last_error_containing("fixed parameter");
        fmi2FreeInstance(c);
    }
}

/// Every instance-taking function (Model Exchange ones too) in every
/// reachable state agrees with the state table: allowed calls do not fail
/// for state reasons, others return fmi2Error with "illegal call
/// sequence".
#[test]
fn state_table_is_enforced() {
    use fmi_export::state_machine::{is_allowed, State};
    let reach = |state: State| -> fmi2Component {
        let c = new_instance("states");
        unsafe {
            match state {
                State::Instantiated => {}
                State::InitializationMode => {
                    fmi2EnterInitializationMode(c);
                }
                State::StepComplete => {
                    fmi2EnterInitializationMode(c);
                    fmi2ExitInitializationMode(c);
                }
                State::Terminated => {
                    fmi2EnterInitializationMode(c);
                    fmi2ExitInitializationMode(c);
                    fmi2Terminate(c);
                }
                _ => unreachable!(),
            }
        }
        c
    };
    for state in [
        State::Instantiated,
        State::InitializationMode,
        State::StepComplete,
        State::Terminated,
    ] {
        for (name, probe) in probes::probes() {
            let c = reach(state);
            log_clear();
            let status = probe(c);
            let illegal = log_snapshot()
                .iter()
                .any(|(_, _, m)| m.contains("illegal call sequence"));
            if is_allowed(name, state) {
                assert!(!illegal, "{name} in {state:?} was refused as illegal");
            } else {
                assert_eq!(status, ERR, "{name} in {state:?}");
                assert!(
                    illegal,
                    "{name} in {state:?}: no 'illegal call sequence' message"
                );
            }
            unsafe { fmi2FreeInstance(c) };
        }
    }
}

#[test]
fn panic_becomes_fatal_and_never_unwinds() {
    let c = initialized("panic");
    assert_eq!(set(c, U, 13.0), OK);
    let status = unsafe { fmi2DoStep(c, 0.0, 0.1, 0) };
    assert_eq!(status, fmi2Status::fmi2Fatal);
    let log = log_snapshot();
    assert!(log.iter().any(
        |(s, _, m)| *s == 4 && m.contains("fmi2DoStep: internal error (panic): unlucky input")
    ));
    // after fatal, nothing but free is possible
    assert_eq!(unsafe { fmi2DoStep(c, 0.0, 0.1, 0) }, ERR);
    unsafe { fmi2FreeInstance(c) };
}

/// The FMU state of `c` now (a new handle) and its serialized bytes.
fn saved_and_serialized(c: fmi2Component) -> (fmi2FMUstate, Vec<c_char>) {
    unsafe {
        let mut s: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut s), OK);
        let mut size = 0;
        assert_eq!(fmi2SerializedFMUstateSize(c, s, &mut size), OK);
        let mut bytes = vec![0 as c_char; size];
        assert_eq!(fmi2SerializeFMUstate(c, s, bytes.as_mut_ptr(), size), OK);
        (s, bytes)
    }
}

#[test]
fn state_round_trip_and_corruption() {
    let c = initialized("state");
    set(c, U, 1.0);
    unsafe {
        fmi2DoStep(c, 0.0, 0.1, 0);
        let (mut s, mut bytes) = saved_and_serialized(c);
        let size = bytes.len();
        assert_eq!(
            fmi2SerializeFMUstate(c, s, bytes.as_mut_ptr(), size - 1),
            ERR
        );
        fmi2DoStep(c, 0.1, 0.1, 0);
        let y_after = get(c, Y);
        // restore the in-memory state and the deserialized one: same continuation
        assert_eq!(fmi2SetFMUstate(c, s), OK);
        fmi2DoStep(c, 0.1, 0.1, 0);
        assert_eq!(get(c, Y).to_bits(), y_after.to_bits());
        let mut d: fmi2FMUstate = null_mut();
        assert_eq!(fmi2DeSerializeFMUstate(c, bytes.as_ptr(), size, &mut d), OK);
        assert_eq!(fmi2SetFMUstate(c, d), OK);
        fmi2DoStep(c, 0.1, 0.1, 0);
        assert_eq!(get(c, Y).to_bits(), y_after.to_bits());
        // truncated and corrupted bytes are refused with a reason
        let mut e: fmi2FMUstate = null_mut();
        assert_eq!(
            fmi2DeSerializeFMUstate(c, bytes.as_ptr(), size / 2, &mut e),
            ERR
        );
        last_error_containing("fmi2DeSerializeFMUstate");
        bytes[size / 2] ^= 0x55;
        assert_eq!(
            fmi2DeSerializeFMUstate(c, bytes.as_ptr(), size, &mut e),
            ERR
        );
        last_error_containing("checksum");
        assert!(e.is_null());
        // a pointer that is not one of ours
        let mut junk = [0u64; 8];
        assert_eq!(fmi2SetFMUstate(c, junk.as_mut_ptr() as fmi2FMUstate), ERR);
        last_error_containing("was not created by this instance");
        assert_eq!(fmi2FreeFMUstate(c, &mut s), OK);
        assert!(s.is_null());
        assert_eq!(fmi2FreeFMUstate(c, &mut d), OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn state_keeps_input_slopes() {
    // A state taken with an input slope restores it (in memory and
    // serialized); the same handle reused for a state without slopes
    // restores none, though it held one before.
    let c = initialized("slopes");
    set(c, U, 1.0);
    unsafe {
        let (vr, order, slope) = (U, 1, 2.0);
        assert_eq!(fmi2SetRealInputDerivatives(c, &vr, 1, &order, &slope), OK);
        let (mut s, bytes) = saved_and_serialized(c);
        let size = bytes.len();
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 0), OK);
        let sloped = get(c, Y);
        assert_eq!(fmi2SetFMUstate(c, s), OK);
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 0), OK);
        assert_eq!(get(c, Y).to_bits(), sloped.to_bits());
        let mut d: fmi2FMUstate = null_mut();
        assert_eq!(fmi2DeSerializeFMUstate(c, bytes.as_ptr(), size, &mut d), OK);
        assert_eq!(fmi2SetFMUstate(c, d), OK);
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 0), OK);
        assert_eq!(get(c, Y).to_bits(), sloped.to_bits());
        // after the step the slope is spent: the reused handle holds none
        assert_eq!(fmi2GetFMUstate(c, &mut s), OK);
        assert_eq!(fmi2DoStep(c, 0.1, 0.1, 0), OK);
        let held = get(c, Y);
        assert_eq!(fmi2SetFMUstate(c, s), OK);
        assert_eq!(fmi2DoStep(c, 0.1, 0.1, 0), OK);
        assert_eq!(get(c, Y).to_bits(), held.to_bits());
        // and the handle that had a slope restores it over a state without
        assert_eq!(fmi2SetFMUstate(c, d), OK);
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 0), OK);
        assert_eq!(get(c, Y).to_bits(), sloped.to_bits());
        assert_eq!(fmi2FreeFMUstate(c, &mut s), OK);
        assert_eq!(fmi2FreeFMUstate(c, &mut d), OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn reused_states_take_every_value_after_deserialization_and_parameter_changes() {
    // A handle overwritten by fmi2DeSerializeFMUstate, then reused by
    // fmi2GetFMUstate, holds the state taken then (every value, not only
    // the inputs); restored after a reset with another gain, it brings its
    // gain back.
    let c = initialized("reuse");
    set(c, U, 1.0);
    unsafe {
        assert_eq!(fmi2DoStep(c, 0.0, 0.1, 0), OK);
        let (mut s, bytes) = saved_and_serialized(c);
        let size = bytes.len();
        assert_eq!(fmi2DoStep(c, 0.1, 0.1, 0), OK);
        let mut d = s;
        assert_eq!(fmi2DeSerializeFMUstate(c, bytes.as_ptr(), size, &mut d), OK);
        assert_eq!(d, s, "the handle is reused");
        set(c, U, 0.5);
        assert_eq!(fmi2GetFMUstate(c, &mut s), OK);
        assert_eq!(fmi2DoStep(c, 0.2, 0.1, 0), OK);
        let y = get(c, Y);
        assert_eq!(fmi2SetFMUstate(c, s), OK);
        assert_eq!(fmi2DoStep(c, 0.2, 0.1, 0), OK);
        assert_eq!(get(c, Y).to_bits(), y.to_bits());
        // another gain, then the state of the first
        assert_eq!(fmi2Reset(c), OK);
        assert_eq!(set(c, K, 3.0), OK);
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        assert_eq!(fmi2SetFMUstate(c, s), OK);
        assert_eq!(get(c, K), 2.0);
        assert_eq!(fmi2DoStep(c, 0.2, 0.1, 0), OK);
        assert_eq!(get(c, Y).to_bits(), y.to_bits());
        assert_eq!(fmi2FreeFMUstate(c, &mut s), OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn directional_derivative_of_the_last_step() {
    // y(t+h) = k*u + s + u*h  ⇒  ∂y/∂u over the step = k + h
    let c = initialized("jac");
    set(c, U, 0.7);
    unsafe {
        let (unknown, known, seed) = (Y, U, 1.0);
        let mut d = 0.0;
        assert_eq!(
            fmi2GetDirectionalDerivative(c, &unknown, 1, &known, 1, &seed, &mut d),
            OK
        );
        assert!((d - 2.0).abs() < 1e-8, "feedthrough {d}");
        fmi2DoStep(c, 0.0, 0.25, 0);
        assert_eq!(
            fmi2GetDirectionalDerivative(c, &unknown, 1, &known, 1, &seed, &mut d),
            OK
        );
        assert!((d - 2.25).abs() < 1e-8, "step sensitivity {d}");
        // unknown must be an output, known an input
        assert_eq!(
            fmi2GetDirectionalDerivative(c, &known, 1, &known, 1, &seed, &mut d),
            ERR
        );
        last_error_containing("is not an output");
        fmi2FreeInstance(c);
    }
}

#[test]
fn directional_derivative_follows_new_parameters() {
    // The step is replayed on a copy of the model: after a reset with
    // another gain the copy must have the new one (∂y/∂u = k + h).
    let c = initialized("jac-k");
    let (unknown, known, seed) = (Y, U, 1.0);
    let mut d = 0.0;
    unsafe {
        for k in [2.0, 3.0] {
            if k != 2.0 {
                assert_eq!(fmi2Reset(c), OK);
                assert_eq!(set(c, K, k), OK);
                assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
                assert_eq!(fmi2EnterInitializationMode(c), OK);
                assert_eq!(fmi2ExitInitializationMode(c), OK);
            }
            set(c, U, 0.7);
            assert_eq!(fmi2DoStep(c, 0.0, 0.25, 0), OK);
            let y = get(c, Y);
            assert_eq!(
                fmi2GetDirectionalDerivative(c, &unknown, 1, &known, 1, &seed, &mut d),
                OK
            );
            assert!((d - (k + 0.25)).abs() < 1e-8, "k = {k}: {d}");
            // the instance's own model kept its state
            assert_eq!(get(c, Y).to_bits(), y.to_bits());
            assert_eq!(fmi2DoStep(c, 0.25, 0.25, 0), OK);
            assert!((get(c, Y) - (k * 0.7 + 0.7 * 0.5)).abs() < 1e-12);
        }
        fmi2FreeInstance(c);
    }
}

#[test]
fn directional_derivative_repeats_exactly_with_and_without_slopes() {
    // Both perturbations of one call start from the same inputs, and a
    // second call from the same state: the same bits every time, with the
    // inputs held over the step and with an input slope (∂y/∂u = k + h
    // either way: the slope moves u by the same amount in both replays).
    let c = initialized("jac-again");
    let (unknown, known, seed) = (Y, U, 1.0);
    unsafe {
        for slope in [0.0, 0.4] {
            set(c, U, 0.7);
            let order = 1;
            assert_eq!(
                fmi2SetRealInputDerivatives(c, &known, 1, &order, &slope),
                OK
            );
            let t = if slope == 0.0 { 0.0 } else { 0.25 };
            assert_eq!(fmi2DoStep(c, t, 0.25, 0), OK);
            let y = get(c, Y);
            let (mut d1, mut d2) = (0.0, 0.0);
            for d in [&mut d1, &mut d2] {
                assert_eq!(
                    fmi2GetDirectionalDerivative(c, &unknown, 1, &known, 1, &seed, d),
                    OK
                );
            }
            assert!((d1 - 2.25).abs() < 1e-8, "slope {slope}: {d1}");
            assert_eq!(d1.to_bits(), d2.to_bits(), "slope {slope}");
            assert_eq!(get(c, Y).to_bits(), y.to_bits());
        }
        fmi2FreeInstance(c);
    }
}

#[test]
fn logging_categories() {
    let cb = Box::leak(Box::new(callbacks()));
    let c = unsafe {
        fmi2Instantiate(
            c"logged".as_ptr(),
            fmi2CoSimulation,
            c"{toy}".as_ptr(),
            null(),
            cb,
            0,
            1,
        )
    };
    log_clear();
    unsafe {
        fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0);
        assert!(log_snapshot()
            .iter()
            .any(|(_, cat, m)| cat == "logCalls" && m.contains("fmi2SetupExperiment")));
        let cats = [c"logCalls".as_ptr()];
        assert_eq!(fmi2SetDebugLogging(c, 0, 1, cats.as_ptr()), OK);
        log_clear();
        fmi2EnterInitializationMode(c);
        assert!(log_snapshot().is_empty());
        let bad = [c"logNothing".as_ptr()];
        assert_eq!(fmi2SetDebugLogging(c, 1, 1, bad.as_ptr()), ERR);
        last_error_containing("unknown log category \"logNothing\"");
        fmi2FreeInstance(c);
    }
}

/// Found by fuzzing (random call sequences against Rig2D: a stiffness of
/// 1e300 and a force of -1e300): finite parameters and inputs that
/// overflow together must not reach the importer as NaN or ±inf with
/// `fmi2OK`. The read is refused naming the output; a step whose state
/// overflows fails (state Error), and `fmi2Reset` recovers.
#[test]
fn overflowing_results_are_refused_not_returned() {
    let c = new_instance("overflow");
    unsafe {
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(set(c, K, 1e300), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        assert_eq!(set(c, U, 1e300), OK);
        let mut y = 0.0;
        assert_eq!(fmi2GetReal(c, &Y, 1, &mut y), ERR);
        let m = last_error_containing("fmi2GetReal");
        assert!(m.contains("y (value reference 1) evaluates to inf"), "{m}");
        // The state s += u·h overflows in a long step.
        assert_eq!(fmi2DoStep(c, 0.0, 1e300, 1), ERR);
        let m = last_error_containing("fmi2DoStep");
        assert!(m.contains("the model state became inf"), "{m}");
        assert_eq!(fmi2DoStep(c, 0.0, 1e-3, 1), ERR); // not in state Error
        assert_eq!(fmi2Reset(c), OK);
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        assert_eq!(set(c, U, 1.0), OK);
        assert_eq!(fmi2DoStep(c, 0.0, 1e-3, 1), OK);
        assert!(get(c, Y).is_finite());
        fmi2FreeInstance(c);
    }
}
