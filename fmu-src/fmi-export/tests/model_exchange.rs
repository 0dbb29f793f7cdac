//! The Model Exchange side of the C edge (FMI 2.0.4 §3), through the
//! exported functions with toy models: the life cycle and the event
//! iteration, the Model Exchange state table in every reachable state, the
//! two interfaces refusing each other's functions, NULL pointers, wrong
//! numbers of states and event indicators, NaN states and times, a
//! right-hand side that is not finite, a panic, FMU states across the
//! interfaces, and directional derivatives of the right-hand side.
//!
//! The toy: `ds/dt = -k*s + u`, output `y = s + u`; one event indicator
//! `1 - s`, and at an event a state `s >= 1` is put back to 0. A
//! derivative that would use `u = 7` is NaN, and `u = 13` panics.

use fmi_export::ffi::*;
use fmi_export::{
    ContinuousState, Model, ModelExchange, ModelFactory, ModelInfo, Ode, Values, Variable,
};
use std::os::raw::c_char;
use std::ptr::{null, null_mut};

const U: u32 = 0;
const Y: u32 = 1;
const S: u32 = 2;
const K: u32 = 3;
const DER_S: u32 = 4;

static VARIABLES: [Variable; 5] = [
    Variable::input(U, "u", 0.0, "", 1.0, "input"),
    Variable::output(Y, "y", "", "s + u", &[U]).with_state_dependencies(&[S]),
    Variable::output(S, "s", "", "the state", &[]).with_state_dependencies(&[S]),
    Variable::parameter(K, "k", 2.0, "", "rate, > 0"),
    Variable::derivative(DER_S, "der(s)", "", "-k*s + u", &[U], &[S]),
];

/// The toy with a Model Exchange interface, and the same toy without one.
static ME_INFO: std::sync::LazyLock<&'static ModelInfo> = std::sync::LazyLock::new(|| {
    let me = ModelExchange {
        states: &[ContinuousState {
            state: S,
            derivative: DER_S,
        }],
        event_indicators: 1,
        states_jump_at_events: true,
    };
    toy_instance::toy_info_with("ToyMe", VARIABLES.to_vec(), Some(me))
});
static CS_INFO: std::sync::LazyLock<&'static ModelInfo> =
    std::sync::LazyLock::new(|| toy_instance::toy_info("ToyCs", VARIABLES.to_vec()));

#[derive(Clone)]
struct Toy {
    k: f64,
    s: f64,
    me: bool,
}

impl Model for Toy {
    fn info(&self) -> &'static ModelInfo {
        if self.me {
            *ME_INFO
        } else {
            *CS_INFO
        }
    }
    fn initialize(&mut self, v: &Values) -> Result<(), String> {
        self.k = v.real(K);
        self.s = 0.0;
        Ok(())
    }
    fn compute_outputs(&self, v: &mut Values) {
        v.set(Y, self.s + v.real(U));
        v.set(S, self.s);
    }
    fn do_step(&mut self, v: &Values, _slopes: &[f64], h: f64) -> Result<(), String> {
        self.s += (-self.k * self.s + v.real(U)) * h;
        Ok(())
    }
    one_value_toy_state!();
    fn derivatives(&self, v: &Values, dx: &mut [f64]) {
        let u = v.real(U);
        if u == 13.0 {
            panic!("unlucky input");
        }
        dx[0] = if u == 7.0 {
            f64::NAN
        } else {
            -self.k * self.s + u
        };
    }
    fn ode(&self) -> Option<&dyn Ode> {
        Some(self)
    }
    fn ode_mut(&mut self) -> Option<&mut dyn Ode> {
        Some(self)
    }
}

impl Ode for Toy {
    fn continuous_states(&self, x: &mut [f64]) {
        x[0] = self.s;
    }
    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        if x[0] > 1e6 {
            return Err(format!("s = {} is beyond what the toy takes", x[0]));
        }
        self.s = x[0];
        Ok(())
    }
    fn event_indicators(&self, _v: &Values, z: &mut [f64]) {
        z[0] = 1.0 - self.s;
    }
    fn nominals(&self, v: &Values, nominal: &mut [f64]) {
        nominal[0] = 1.0 / v.real(K);
    }
    fn event_update(&mut self, _v: &Values) -> bool {
        if self.s >= 1.0 {
            self.s = 0.0;
            return true;
        }
        false
    }
    fn partial_derivative(&self, _v: &Values, unknown: u32, known: u32) -> Option<f64> {
        match (unknown, known) {
            (DER_S, S) => Some(-self.k),
            (DER_S, U) | (Y, S) | (Y, U) | (S, S) => Some(1.0),
            (S, U) => Some(0.0),
            _ => None,
        }
    }
}

static REGISTRY: std::sync::LazyLock<[ModelFactory; 2]> = std::sync::LazyLock::new(|| {
    [
        ModelFactory {
            info: *ME_INFO,
            create: || {
                Box::new(Toy {
                    k: 1.0,
                    s: 0.0,
                    me: true,
                })
            },
            create_model_exchange: Some(|| {
                Box::new(Toy {
                    k: 1.0,
                    s: 0.0,
                    me: true,
                })
            }),
        },
        ModelFactory {
            info: *CS_INFO,
            create: || {
                Box::new(Toy {
                    k: 1.0,
                    s: 0.0,
                    me: false,
                })
            },
            create_model_exchange: None,
        },
    ]
});
fmi_export::export_fmi2!(&REGISTRY[..]);
use fmi2_exports::*;

// ---- the C driver's recording logger and instantiation ---------------------

#[path = "support/probes.rs"]
mod probes;
#[path = "support/toy_instance.rs"]
#[allow(dead_code)]
mod toy_instance;
use toy_instance::one_value_toy_state;

#[allow(dead_code)]
mod driver {
    pub use crate::fmi2_exports::*;
    fn models() -> Vec<&'static fmi_export::ModelInfo> {
        vec![*crate::ME_INFO, *crate::CS_INFO]
    }
    include!("support/c_driver.rs");
}

/// The errors logged since the last call, taken.
fn take_errors() -> Vec<String> {
    driver::LOG.with(|l| {
        l.borrow_mut()
            .drain(..)
            .filter(|(s, _)| *s >= 3)
            .map(|(_, m)| m)
            .collect()
    })
}

/// The one error logged since the last check, containing every part.
fn assert_logged(context: &str, parts: &[&str]) {
    let errors = take_errors();
    assert_eq!(errors.len(), 1, "{context}: {errors:?}");
    for part in parts {
        assert!(
            errors[0].contains(part),
            "{context}: {:?} lacks {part:?}",
            errors[0]
        );
    }
}

const OK: fmi2Status = fmi2Status::fmi2OK;
const ERR: fmi2Status = fmi2Status::fmi2Error;

fn instantiate(kind: fmi2Type, model: &str) -> fmi2Component {
    driver::instantiate(model, kind).0
}

use fmi_export::state_machine::State;
use State::{ContinuousTimeMode, EventMode};
/// The Model Exchange states an importer reaches (the layer's names).
const INSTANTIATED: State = State::MeInstantiated;
const INITIALIZATION_MODE: State = State::MeInitializationMode;
const TERMINATED: State = State::MeTerminated;

fn me_instance_in(state: State) -> fmi2Component {
    let c = instantiate(fmi2ModelExchange, "ToyMe");
    assert!(!c.is_null(), "{:?}", take_errors());
    unsafe {
        let steps: &[unsafe extern "C" fn(fmi2Component) -> fmi2Status] = match state {
            INSTANTIATED => &[],
            INITIALIZATION_MODE => &[fmi2EnterInitializationMode],
            EventMode => &[fmi2EnterInitializationMode, fmi2ExitInitializationMode],
            ContinuousTimeMode => &[
                fmi2EnterInitializationMode,
                fmi2ExitInitializationMode,
                fmi2EnterContinuousTimeMode,
            ],
            TERMINATED => &[
                fmi2EnterInitializationMode,
                fmi2ExitInitializationMode,
                fmi2Terminate,
            ],
            other => unreachable!("{other:?}"),
        };
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
        for step in steps {
            assert_eq!(step(c), OK, "{:?}", take_errors());
        }
    }
    take_errors();
    c
}

fn get_real(c: fmi2Component, vr: u32) -> f64 {
    let mut x = f64::NAN;
    assert_eq!(
        unsafe { fmi2GetReal(c, &vr, 1, &mut x) },
        OK,
        "{:?}",
        take_errors()
    );
    x
}

fn states(c: fmi2Component) -> f64 {
    let mut x = [f64::NAN];
    assert_eq!(
        unsafe { fmi2GetContinuousStates(c, x.as_mut_ptr(), 1) },
        OK,
        "{:?}",
        take_errors()
    );
    x[0]
}

fn derivative(c: fmi2Component) -> f64 {
    let mut dx = [f64::NAN];
    assert_eq!(
        unsafe { fmi2GetDerivatives(c, dx.as_mut_ptr(), 1) },
        OK,
        "{:?}",
        take_errors()
    );
    dx[0]
}

fn new_discrete_states(c: fmi2Component) -> fmi2EventInfo {
    let mut info = fmi2EventInfo {
        newDiscreteStatesNeeded: 7,
        terminateSimulation: 7,
        nominalsOfContinuousStatesChanged: 7,
        valuesOfContinuousStatesChanged: 7,
        nextEventTimeDefined: 7,
        nextEventTime: f64::NAN,
    };
    assert_eq!(
        unsafe { fmi2NewDiscreteStates(c, &mut info) },
        OK,
        "{:?}",
        take_errors()
    );
    info
}

/// The calling sequence of FMI 2.0.4 §3.2.3, with an event the integrator
/// finds (the indicator 1 − s crosses zero) and the state the event
/// iteration puts back.
#[test]
fn life_cycle_with_a_state_event() {
    let c = me_instance_in(INITIALIZATION_MODE);
    unsafe {
        assert_eq!(fmi2SetReal(c, &K, 1, &4.0), OK);
        assert_eq!(fmi2SetReal(c, &U, 1, &0.5), OK);
        // the initial state in initialization mode, and its nominal after
        assert_eq!(states(c), 0.0);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
        let mut nominal = [0.0];
        assert_eq!(
            fmi2GetNominalsOfContinuousStates(c, nominal.as_mut_ptr(), 1),
            OK
        );
        assert_eq!(nominal, [0.25]);
        // the initial event iteration settles at once
        let info = new_discrete_states(c);
        assert_eq!(
            (
                info.newDiscreteStatesNeeded,
                info.terminateSimulation,
                info.nominalsOfContinuousStatesChanged,
                info.valuesOfContinuousStatesChanged,
                info.nextEventTimeDefined
            ),
            (0, 0, 0, 0, 0)
        );
        assert_eq!(fmi2EnterContinuousTimeMode(c), OK);
        // an integrator's evaluations
        assert_eq!(fmi2SetTime(c, 0.1), OK);
        assert_eq!(fmi2SetContinuousStates(c, [0.75].as_ptr(), 1), OK);
        assert_eq!(derivative(c), -4.0 * 0.75 + 0.5);
        assert_eq!(get_real(c, Y), 0.75 + 0.5);
        assert_eq!(get_real(c, DER_S), -4.0 * 0.75 + 0.5);
        let mut z = [f64::NAN];
        assert_eq!(fmi2GetEventIndicators(c, z.as_mut_ptr(), 1), OK);
        assert_eq!(z, [0.25]);
        let (mut enter, mut terminate) = (7, 7);
        assert_eq!(
            fmi2CompletedIntegratorStep(c, 1, &mut enter, &mut terminate),
            OK
        );
        assert_eq!((enter, terminate), (0, 0));
        // past the event: the indicator has changed sign
        assert_eq!(fmi2SetContinuousStates(c, [1.25].as_ptr(), 1), OK);
        assert_eq!(fmi2GetEventIndicators(c, z.as_mut_ptr(), 1), OK);
        assert_eq!(z, [-0.25]);
        assert_eq!(fmi2EnterEventMode(c), OK);
        let info = new_discrete_states(c);
        assert_eq!(
            (
                info.valuesOfContinuousStatesChanged,
                info.newDiscreteStatesNeeded
            ),
            (1, 0)
        );
        assert_eq!(states(c), 0.0);
        assert_eq!(get_real(c, Y), 0.5);
        // nothing more to do at this event
        assert_eq!(new_discrete_states(c).valuesOfContinuousStatesChanged, 0);
        assert_eq!(fmi2EnterContinuousTimeMode(c), OK);
        assert_eq!(fmi2Terminate(c), OK);
        // the values stay readable after termination
        assert_eq!(derivative(c), 0.5);
        fmi2FreeInstance(c);
    }
    assert!(take_errors().is_empty());
}

/// Every probe in every Model Exchange state an importer reaches agrees
/// with the layer's Model Exchange table (the table against the standard:
/// `host/tests/integration/model_exchange.rs`, on the shipped FMUs): allowed calls
/// succeed, the others are refused with the function, "illegal call
/// sequence" and the state in the message; Co-Simulation functions in
/// none.
#[test]
fn every_function_in_every_model_exchange_state_follows_the_table() {
    let mut refused = 0;
    let cs_only = [
        "fmi2DoStep",
        "fmi2CancelStep",
        "fmi2SetRealInputDerivatives",
    ];
    for state in [
        INSTANTIATED,
        INITIALIZATION_MODE,
        EventMode,
        ContinuousTimeMode,
        TERMINATED,
    ] {
        for (function, probe) in probes::probes() {
            let c = me_instance_in(state);
            let status = probe(c);
            let context = format!("{function} in {state:?}");
            let allowed = fmi_export::state_machine::is_allowed(function, state);
            assert!(!(allowed && cs_only.contains(&function)), "{context}");
            if allowed {
                assert!(
                    status < ERR,
                    "{context} is allowed but returned {status:?}: {:?}",
                    take_errors()
                );
                take_errors();
            } else {
                assert_eq!(status, ERR, "{context} must be refused");
                let name = state.name();
                assert_logged(&context, &[function, "illegal call sequence", name]);
                refused += 1;
            }
            unsafe { fmi2FreeInstance(c) };
        }
    }
    assert!(refused > 60, "{refused}");
}

/// A Model Exchange function on a Co-Simulation instance (of a model that
/// has both) is an illegal call in every Co-Simulation state, named so.
#[test]
fn model_exchange_functions_are_refused_on_a_co_simulation_instance() {
    let c = instantiate(fmi2CoSimulation, "ToyMe");
    unsafe {
        for (when, step) in [
            ("Instantiated", None),
            (
                "InitializationMode",
                Some(fmi2EnterInitializationMode as unsafe extern "C" fn(_) -> _),
            ),
            ("StepComplete", Some(fmi2ExitInitializationMode)),
        ] {
            if let Some(step) = step {
                assert_eq!(step(c), OK);
            }
            take_errors();
            for (function, probe) in probes::model_exchange_only() {
                assert_eq!(probe(c), ERR, "{function} in {when}");
                assert_logged(function, &[function, "not allowed in state", when]);
            }
        }
        // the Co-Simulation instance still steps, and reads der(s) as a variable
        assert_eq!(fmi2SetReal(c, &U, 1, &1.0), OK);
        assert_eq!(fmi2DoStep(c, 0.0, 0.5, 0), OK);
        let s = get_real(c, S);
        assert_eq!(s, 0.5);
        assert_eq!(get_real(c, DER_S), -2.0 * 0.5 + 1.0);
        let (vrs, mut out) = ([S, DER_S, Y], [0.0; 3]);
        assert_eq!(fmi2GetReal(c, vrs.as_ptr(), 3, out.as_mut_ptr()), OK);
        assert_eq!(out, [0.5, 0.0, 1.5]);
        // a local is not settable
        assert_eq!(fmi2SetReal(c, &DER_S, 1, &1.0), ERR);
        assert_logged("set der(s)", &["cannot set der(s)", "local"]);
        fmi2FreeInstance(c);
    }
}

#[test]
fn instantiation_for_model_exchange_is_refused_with_the_reason() {
    assert!(instantiate(fmi2ModelExchange, "ToyCs").is_null());
    assert_logged(
        "CS-only",
        &["fmuType = 0", "ToyCs", "Co-Simulation (1) only"],
    );
    assert!(instantiate(7, "ToyMe").is_null());
    assert_logged("fmuType 7", &["fmuType = 7", "neither"]);
    let c = unsafe {
        fmi2Instantiate(
            c"x".as_ptr(),
            fmi2ModelExchange,
            c"{nope}".as_ptr(),
            null(),
            driver::callbacks(),
            0,
            0,
        )
    };
    assert!(c.is_null());
    assert_logged("GUID", &["unknown fmuGUID {nope}"]);
}

/// NULL arrays, numbers of states and indicators that are not the model's,
/// NaN states and times, and a right-hand side that is not finite: each
/// refused with fmi2Error and a message naming the function and the
/// value, the instance unchanged and usable.
#[test]
fn nulls_wrong_lengths_and_nan_are_refused_and_change_nothing() {
    let c = me_instance_in(ContinuousTimeMode);
    unsafe {
        assert_eq!(fmi2SetContinuousStates(c, [0.25].as_ptr(), 1), OK);
        type Case = (
            &'static str,
            fn(fmi2Component) -> fmi2Status,
            &'static [&'static str],
        );
        let cases: &[Case] = &[
            (
                "null x",
                |c| fmi2SetContinuousStates(c, null(), 1),
                &["fmi2SetContinuousStates", "x[] is NULL"],
            ),
            (
                "nx 2",
                |c| fmi2SetContinuousStates(c, [1.0, 2.0].as_ptr(), 2),
                &[
                    "fmi2SetContinuousStates",
                    "nx = 2",
                    "ToyMe has 1 continuous state",
                ],
            ),
            (
                "nx 0",
                |c| fmi2SetContinuousStates(c, null(), 0),
                &["nx = 0"],
            ),
            (
                "NaN x",
                |c| fmi2SetContinuousStates(c, [f64::NAN].as_ptr(), 1),
                &["fmi2SetContinuousStates", "x[0] (s) must be finite", "NaN"],
            ),
            (
                "inf x",
                |c| fmi2SetContinuousStates(c, [f64::INFINITY].as_ptr(), 1),
                &["x[0] (s)", "inf"],
            ),
            (
                "refused x",
                |c| fmi2SetContinuousStates(c, [2e6].as_ptr(), 1),
                &["fmi2SetContinuousStates", "beyond what the toy takes"],
            ),
            (
                "null dx",
                |c| fmi2GetDerivatives(c, null_mut(), 1),
                &["fmi2GetDerivatives", "derivatives[] is NULL"],
            ),
            (
                "nx 3",
                |c| fmi2GetDerivatives(c, [0.0; 3].as_mut_ptr(), 3),
                &["fmi2GetDerivatives", "nx = 3"],
            ),
            (
                "null z",
                |c| fmi2GetEventIndicators(c, null_mut(), 1),
                &["fmi2GetEventIndicators", "eventIndicators[] is NULL"],
            ),
            (
                "ni 2",
                |c| fmi2GetEventIndicators(c, [0.0; 2].as_mut_ptr(), 2),
                &["fmi2GetEventIndicators", "ni = 2", "1 event indicator"],
            ),
            (
                "null states",
                |c| fmi2GetContinuousStates(c, null_mut(), 1),
                &["fmi2GetContinuousStates", "x[] is NULL"],
            ),
            (
                "nominals nx",
                |c| fmi2GetNominalsOfContinuousStates(c, [0.0; 2].as_mut_ptr(), 2),
                &["fmi2GetNominalsOfContinuousStates", "nx = 2"],
            ),
            (
                "NaN time",
                |c| fmi2SetTime(c, f64::NAN),
                &["fmi2SetTime", "time must be finite", "NaN"],
            ),
            (
                "null flags",
                |c| fmi2CompletedIntegratorStep(c, 1, null_mut(), &mut 0),
                &["fmi2CompletedIntegratorStep", "enterEventMode is NULL"],
            ),
            (
                "null flag 2",
                |c| fmi2CompletedIntegratorStep(c, 1, &mut 0, null_mut()),
                &["terminateSimulation is NULL"],
            ),
            (
                "NaN dx",
                |c| {
                    assert_eq!(fmi2SetReal(c, &U, 1, &7.0), OK);
                    let s = fmi2GetDerivatives(c, [0.0].as_mut_ptr(), 1);
                    assert_eq!(fmi2SetReal(c, &U, 1, &0.0), OK);
                    s
                },
                &["fmi2GetDerivatives", "der(s) evaluates to NaN"],
            ),
            (
                "seed NaN",
                |c| fmi2GetDirectionalDerivative(c, &DER_S, 1, &S, 1, &f64::NAN, &mut 0.0),
                &["fmi2GetDirectionalDerivative", "seed", "NaN"],
            ),
            (
                "unknown input",
                |c| fmi2GetDirectionalDerivative(c, &U, 1, &S, 1, &1.0, &mut 0.0),
                &["unknown u", "neither a state derivative nor an output"],
            ),
            (
                "known output",
                |c| fmi2GetDirectionalDerivative(c, &DER_S, 1, &Y, 1, &1.0, &mut 0.0),
                &["known y", "neither a continuous state nor an input"],
            ),
            (
                "unknown vr",
                |c| fmi2GetDirectionalDerivative(c, &DER_S, 1, &99, 1, &1.0, &mut 0.0),
                &["unknown value reference 99"],
            ),
        ];
        for (what, case, parts) in cases {
            assert_eq!(case(c), ERR, "{what}");
            assert_logged(what, parts);
            // unchanged and usable
            assert_eq!(states(c), 0.25, "{what}");
            assert_eq!(derivative(c), -2.0 * 0.25, "{what}");
        }
        // in event mode the states cannot be set (only in continuous-time mode)
        assert_eq!(fmi2EnterEventMode(c), OK);
        assert_eq!(fmi2SetContinuousStates(c, [0.5].as_ptr(), 1), ERR);
        assert_logged(
            "event mode",
            &["fmi2SetContinuousStates", "not allowed in state EventMode"],
        );
        assert_eq!(fmi2NewDiscreteStates(c, null_mut()), ERR);
        assert_logged(
            "null event info",
            &["fmi2NewDiscreteStates", "fmi2eventInfo is NULL"],
        );
        assert_eq!(states(c), 0.25);
        fmi2FreeInstance(c);
    }
}

#[test]
fn a_panic_in_the_right_hand_side_is_fatal_and_contained() {
    let c = me_instance_in(ContinuousTimeMode);
    unsafe {
        assert_eq!(fmi2SetReal(c, &U, 1, &13.0), OK);
        assert_eq!(
            fmi2GetDerivatives(c, [0.0].as_mut_ptr(), 1),
            fmi2Status::fmi2Fatal
        );
        let errors = take_errors();
        assert!(
            errors
                .iter()
                .any(|m| m.contains("fmi2GetDerivatives: internal error (panic): unlucky input")),
            "{errors:?}"
        );
        assert_eq!(fmi2GetContinuousStates(c, [0.0].as_mut_ptr(), 1), ERR);
        assert_logged("after fatal", &["not allowed in state Fatal"]);
        fmi2FreeInstance(c);
    }
}

/// Directional derivatives of the right-hand side and the outputs with
/// respect to states and inputs: the model's closed forms, combined along
/// the seeds, against differences of the right-hand side taken through
/// fmi2SetContinuousStates / fmi2SetReal.
#[test]
fn directional_derivatives_of_the_right_hand_side() {
    let c = me_instance_in(ContinuousTimeMode);
    unsafe {
        assert_eq!(fmi2SetReal(c, &U, 1, &0.3), OK);
        assert_eq!(fmi2SetContinuousStates(c, [0.4].as_ptr(), 1), OK);
        let unknowns = [DER_S, Y, S];
        let knowns = [S, U];
        let mut out = [0.0; 3];
        assert_eq!(
            fmi2GetDirectionalDerivative(
                c,
                unknowns.as_ptr(),
                3,
                knowns.as_ptr(),
                2,
                [2.0, -1.0].as_ptr(),
                out.as_mut_ptr()
            ),
            OK,
            "{:?}",
            take_errors()
        );
        assert_eq!(out, [-2.0 * 2.0 - 1.0, 2.0 - 1.0, 2.0]);
        // against differences of the right-hand side
        let h = 1e-6;
        assert_eq!(fmi2SetContinuousStates(c, [0.4 + h].as_ptr(), 1), OK);
        let up = derivative(c);
        assert_eq!(fmi2SetContinuousStates(c, [0.4 - h].as_ptr(), 1), OK);
        let down = derivative(c);
        assert!(((up - down) / (2.0 * h) - -2.0).abs() < 1e-9);
        fmi2FreeInstance(c);
    }
}

/// FMU states of a Model Exchange instance restore its mode, time and
/// states; a Co-Simulation instance of the same model refuses one (and
/// the reverse), naming the interfaces.
#[test]
fn fmu_states_keep_to_their_interface() {
    let c = me_instance_in(ContinuousTimeMode);
    let cs = instantiate(fmi2CoSimulation, "ToyMe");
    unsafe {
        assert_eq!(fmi2SetTime(c, 0.3), OK);
        assert_eq!(fmi2SetContinuousStates(c, [0.6].as_ptr(), 1), OK);
        let mut saved = null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut saved), OK);
        assert_eq!(fmi2EnterEventMode(c), OK);
        assert_eq!(fmi2Terminate(c), OK);
        assert_eq!(fmi2SetFMUstate(c, saved), OK);
        // back in continuous-time mode with s = 0.6
        assert_eq!(states(c), 0.6);
        assert_eq!(fmi2SetContinuousStates(c, [0.1].as_ptr(), 1), OK);
        let mut size = 0;
        assert_eq!(fmi2SerializedFMUstateSize(c, saved, &mut size), OK);
        let mut bytes = vec![0 as c_char; size];
        assert_eq!(
            fmi2SerializeFMUstate(c, saved, bytes.as_mut_ptr(), size),
            OK
        );
        // into the Co-Simulation instance: refused when restored
        assert_eq!(fmi2EnterInitializationMode(cs), OK);
        assert_eq!(fmi2ExitInitializationMode(cs), OK);
        let mut foreign = null_mut();
        assert_eq!(
            fmi2DeSerializeFMUstate(cs, bytes.as_ptr(), size, &mut foreign),
            OK
        );
        assert_eq!(fmi2SetFMUstate(cs, foreign), ERR);
        assert_logged(
            "ME state in CS",
            &[
                "fmi2SetFMUstate",
                "taken by a Model Exchange instance",
                "this is a Co-Simulation instance",
            ],
        );
        // the Co-Simulation instance is untouched and steps on
        assert_eq!(fmi2DoStep(cs, 0.0, 0.1, 0), OK);
        // a fresh Model Exchange instance takes it
        let d = me_instance_in(INSTANTIATED);
        let mut mine = null_mut();
        assert_eq!(
            fmi2DeSerializeFMUstate(d, bytes.as_ptr(), size, &mut mine),
            OK
        );
        assert_eq!(fmi2SetFMUstate(d, mine), OK, "{:?}", take_errors());
        assert_eq!(states(d), 0.6);
        assert_eq!(fmi2SetContinuousStates(d, [0.2].as_ptr(), 1), OK);
        let mut fx = [0.0];
        let _ = fmi2GetContinuousStates(d, fx.as_mut_ptr(), 1);
        assert_eq!(fx, [0.2]);
        for (i, s) in [(c, saved), (cs, foreign), (d, mine)] {
            let mut s = s;
            assert_eq!(fmi2FreeFMUstate(i, &mut s), OK);
            fmi2FreeInstance(i);
        }
    }
}
