//! Model Exchange of the FMUs we ship (`dist/*.fmu`, built by
//! `build-fmu.sh`), through the C functions of the packaged binary loaded
//! with libloading, as a careless importer would call them: every function
//! in every state against the standard's table, NULL arrays, numbers of
//! states and event indicators that are not the model's, NaN states and
//! times, invalid component pointers, and the Co-Simulation instances and
//! FMUs that must refuse Model Exchange. As in `misuse.rs`, each refused
//! call returns `fmi2Error`, logs one message naming the function and the
//! value or state, and leaves the instance usable.
//!
//! The table below is written from FMI 2.0.4 §3.2.3 (the Model Exchange
//! state machine; where the standard's table leaves room, the masks of the
//! Modelica Reference FMUs), independently of the FMUs' own table in
//! `fmi-export/src/state_machine.rs`.

use crate::fmi;
use fmi::*;
use std::os::raw::c_int;
use std::ptr::{null, null_mut};

/// The Model Exchange states an importer reaches with our FMUs (an
/// instance of this library never enters `error` in Model Exchange: every
/// failure is a refused call).
#[derive(Clone, Copy, Debug, PartialEq)]
enum St {
    Instantiated,
    InitializationMode,
    EventMode,
    ContinuousTimeMode,
    Terminated,
}
use St::*;

const STATES: [St; 5] = [
    Instantiated,
    InitializationMode,
    EventMode,
    ContinuousTimeMode,
    Terminated,
];
const AFTER_INSTANTIATION: &[St] = &[
    InitializationMode,
    EventMode,
    ContinuousTimeMode,
    Terminated,
];

/// FMI 2.0.4 §3.2.3: for each probed function, the states (of the five
/// above) in which a Model Exchange instance may call it: the Model
/// Exchange functions first, the Co-Simulation ones (in none) last.
const ALLOWED: &[(&str, &[St])] = &[
    ("fmi2EnterEventMode", &[EventMode, ContinuousTimeMode]),
    ("fmi2NewDiscreteStates", &[EventMode]),
    ("fmi2EnterContinuousTimeMode", &[EventMode]),
    ("fmi2CompletedIntegratorStep", &[ContinuousTimeMode]),
    ("fmi2SetTime", &[EventMode, ContinuousTimeMode]),
    ("fmi2SetContinuousStates", &[ContinuousTimeMode]),
    ("fmi2GetEventIndicators", AFTER_INSTANTIATION),
    ("fmi2GetContinuousStates", AFTER_INSTANTIATION),
    (
        "fmi2GetDerivatives",
        &[EventMode, ContinuousTimeMode, Terminated],
    ),
    (
        "fmi2GetNominalsOfContinuousStates",
        &[Instantiated, EventMode, ContinuousTimeMode, Terminated],
    ),
    // the functions of both interfaces
    ("fmi2Terminate", &[EventMode, ContinuousTimeMode]),
    ("fmi2Reset", &STATES),
    ("fmi2GetReal", AFTER_INSTANTIATION),
    ("fmi2GetBoolean", AFTER_INSTANTIATION),
    (
        "fmi2SetReal",
        &[
            Instantiated,
            InitializationMode,
            EventMode,
            ContinuousTimeMode,
        ],
    ),
    (
        "fmi2SetInteger",
        &[Instantiated, InitializationMode, EventMode],
    ),
    ("fmi2GetFMUstate", &STATES),
    ("fmi2GetDirectionalDerivative", AFTER_INSTANTIATION),
    ("fmi2SetDebugLogging", &STATES),
    ("fmi2SetupExperiment", &[Instantiated]),
    ("fmi2EnterInitializationMode", &[Instantiated]),
    ("fmi2ExitInitializationMode", &[InitializationMode]),
    // Co-Simulation only
    ("fmi2DoStep", &[]),
    ("fmi2SetRealInputDerivatives", &[]),
    ("fmi2GetRealOutputDerivatives", &[]),
    ("fmi2GetRealStatus", &[]),
];

struct Fixture {
    loaded: Loaded,
}

impl Fixture {
    fn new(name: &str) -> Fixture {
        Fixture {
            loaded: load_shipped(name),
        }
    }
    fn name(&self) -> &str {
        &self.loaded.model.name
    }
    fn nx(&self) -> usize {
        self.loaded.model.states
    }
    fn ni(&self) -> usize {
        self.loaded.model.event_indicators
    }
    fn input(&self) -> Vr {
        self.loaded.model.first("Real", "input").unwrap().vr
    }
    fn output(&self) -> Vr {
        self.loaded.model.first("Real", "output").unwrap().vr
    }

    /// A Model Exchange instance driven into `state`.
    fn instance_in(&self, state: St) -> Instance {
        let model = &self.loaded.model;
        let i = Instance::of_type(self.loaded.api, "me", &model.guid, false, MODEL_EXCHANGE)
            .unwrap_or_else(|log| panic!("{}: {:?}", self.name(), log.take_errors()));
        let m = self.loaded.me_api;
        let steps: &[&dyn Fn(&Instance) -> Status] = match state {
            Instantiated => &[],
            InitializationMode => &[&|i| i.setup(0.0), &Instance::enter_init],
            EventMode => &[
                &|i| i.setup(0.0),
                &Instance::enter_init,
                &Instance::exit_init,
            ],
            ContinuousTimeMode => &[
                &|i| i.setup(0.0),
                &Instance::enter_init,
                &Instance::exit_init,
                &|i| unsafe { (m.enter_continuous_time_mode)(i.c) },
            ],
            Terminated => &[
                &|i| i.setup(0.0),
                &Instance::enter_init,
                &Instance::exit_init,
                &Instance::terminate,
            ],
        };
        for step in steps {
            assert_eq!(step(&i), OK, "{:?}", i.log.take_errors());
        }
        i.log.take();
        i
    }

    fn states(&self, i: &Instance) -> Vec<f64> {
        let mut x = vec![f64::NAN; self.nx()];
        let s = unsafe { (self.loaded.me_api.get_continuous_states)(i.c, x.as_mut_ptr(), x.len()) };
        assert_eq!(s, OK, "{:?}", i.log.take_errors());
        x
    }

    /// Call `function` on `i` with arguments that are valid apart from the
    /// state; its status. The Model Exchange functions here, the others as
    /// `misuse.rs` calls them ([`call_function`]).
    fn call(&self, i: &Instance, function: &str) -> Status {
        let (m, c) = (self.loaded.me_api, i.c);
        let (nx, ni) = (self.nx(), self.ni());
        let mut x = vec![0.0; nx];
        let mut z = vec![0.0; ni];
        let mut flag = 0 as c_int;
        // SAFETY: every pointer is valid for the length passed.
        unsafe {
            match function {
                "fmi2EnterEventMode" => (m.enter_event_mode)(c),
                "fmi2NewDiscreteStates" => (m.new_discrete_states)(c, &mut EventInfo::default()),
                "fmi2EnterContinuousTimeMode" => (m.enter_continuous_time_mode)(c),
                "fmi2CompletedIntegratorStep" => {
                    (m.completed_integrator_step)(c, 1, &mut flag, &mut 0)
                }
                "fmi2SetTime" => (m.set_time)(c, 0.0),
                "fmi2SetContinuousStates" => (m.set_continuous_states)(c, x.as_ptr(), nx),
                "fmi2GetEventIndicators" => (m.get_event_indicators)(c, z.as_mut_ptr(), ni),
                "fmi2GetContinuousStates" => (m.get_continuous_states)(c, x.as_mut_ptr(), nx),
                "fmi2GetDerivatives" => (m.get_derivatives)(c, x.as_mut_ptr(), nx),
                "fmi2GetNominalsOfContinuousStates" => {
                    (m.get_nominals_of_continuous_states)(c, x.as_mut_ptr(), nx)
                }
                other => call_function(i, other, self.input(), self.output(), 0.0),
            }
        }
    }

    /// The rest of a normal Model Exchange run from `state`: one event,
    /// some evaluations of an integrator, termination; every call must
    /// succeed ("the instance stays usable").
    fn finish_run(&self, i: &Instance, state: St) {
        let m = self.loaded.me_api;
        let mut steps: Vec<&str> = match state {
            Instantiated => vec![
                "fmi2SetupExperiment",
                "fmi2EnterInitializationMode",
                "fmi2ExitInitializationMode",
            ],
            InitializationMode => vec!["fmi2ExitInitializationMode"],
            EventMode => vec![],
            ContinuousTimeMode => vec!["fmi2EnterEventMode"],
            Terminated => vec![
                "fmi2Reset",
                "fmi2SetupExperiment",
                "fmi2EnterInitializationMode",
                "fmi2ExitInitializationMode",
            ],
        };
        steps.extend([
            "fmi2NewDiscreteStates",
            "fmi2EnterContinuousTimeMode",
            "fmi2SetTime",
            "fmi2GetContinuousStates",
            "fmi2SetContinuousStates",
            "fmi2GetDerivatives",
            "fmi2GetEventIndicators",
            "fmi2CompletedIntegratorStep",
            "fmi2GetReal",
            "fmi2Terminate",
        ]);
        for function in steps {
            let s = self.call(i, function);
            assert_eq!(
                s,
                OK,
                "{}: {function} of the run continued from {state:?}: {:?}",
                self.name(),
                i.log.take_errors()
            );
        }
        let mut dx = vec![f64::NAN; self.nx()];
        assert_eq!(
            unsafe { (m.get_derivatives)(i.c, dx.as_mut_ptr(), dx.len()) },
            OK
        );
        assert!(dx.iter().all(|d| d.is_finite()), "{}: {dx:?}", self.name());
    }
}

#[test]
fn exactly_the_ode_laws_offer_model_exchange() {
    for &name in SHIPPED.iter() {
        let f = Fixture::new(name);
        let me = f.loaded.model_exchange.as_deref();
        assert_eq!(
            me,
            SHIPPED_MODEL_EXCHANGE.contains(&name).then_some(name),
            "{name}"
        );
        let expected_states = match name {
            "Bristle2D" | "BlimanSorine" => 2,
            "Dahl" | "LuGre" | "ResetIntegrator" | "ElastoPlastic" => 1,
            // every element's force, 100 declared (FMI 2.0 fixes the number)
            "MaxwellSlip" | "GMS" => 100,
            // listed for Co-Simulation (its linearization), no Model
            // Exchange interface
            "Rig1D" => 2,
            _ => 0,
        };
        assert_eq!(f.nx(), expected_states, "{name}");
        // every Model Exchange law has event indicators, Classical only them
        assert_eq!(f.ni() > 0, SHIPPED_MODEL_EXCHANGE.contains(&name), "{name}");
    }
}

#[test]
fn every_function_in_every_model_exchange_state_follows_the_standard_table() {
    let (mut refused, mut accepted) = (0, 0);
    for &name in SHIPPED_MODEL_EXCHANGE.iter() {
        let (r, a) = check_state_table(&Fixture::new(name), ALLOWED, &STATES);
        refused += r;
        accepted += a;
    }
    let n = SHIPPED_MODEL_EXCHANGE.len();
    assert_eq!(refused + accepted, n * ALLOWED.len() * 5);
    assert!(refused > n * 50, "{refused} refused calls");
}

impl StateProbe<St> for Fixture {
    fn name(&self) -> String {
        Fixture::name(self).to_string()
    }
    fn instance_in(&self, state: St) -> Instance {
        Fixture::instance_in(self, state)
    }
    fn call(&self, i: &Instance, function: &str) -> Status {
        Fixture::call(self, i, function)
    }
    /// (the standard's names; the FMUs add "(Model Exchange)" to the
    /// ones Co-Simulation has too)
    fn state_word(&self, state: St) -> String {
        format!("{state:?}")
    }
    fn finish_run(&self, i: &Instance, state: St) {
        Fixture::finish_run(self, i, state)
    }
}

/// A refused call: what it is, the call, what the message must contain.
type Case = (
    &'static str,
    fn(&Fixture, &Instance) -> Status,
    &'static str,
);

#[test]
fn nulls_wrong_lengths_and_nan_are_refused_and_change_nothing() {
    let cases: &[Case] = &[
        (
            "fmi2SetContinuousStates",
            |f, i| unsafe { (f.loaded.me_api.set_continuous_states)(i.c, null(), f.nx()) },
            "x[] is NULL",
        ),
        (
            "fmi2SetContinuousStates",
            |f, i| unsafe {
                let x = vec![0.0; f.nx() + 1];
                (f.loaded.me_api.set_continuous_states)(i.c, x.as_ptr(), x.len())
            },
            "continuous state",
        ),
        (
            "fmi2SetContinuousStates",
            |f, i| unsafe {
                let x = vec![f64::NAN; f.nx()];
                (f.loaded.me_api.set_continuous_states)(i.c, x.as_ptr(), x.len())
            },
            "must be finite but was NaN",
        ),
        (
            "fmi2SetContinuousStates",
            |f, i| unsafe {
                let mut x = vec![0.0; f.nx()];
                x[f.nx() - 1] = f64::NEG_INFINITY;
                (f.loaded.me_api.set_continuous_states)(i.c, x.as_ptr(), x.len())
            },
            "-inf",
        ),
        (
            "fmi2GetDerivatives",
            |f, i| unsafe { (f.loaded.me_api.get_derivatives)(i.c, null_mut(), f.nx()) },
            "derivatives[] is NULL",
        ),
        (
            "fmi2GetDerivatives",
            |f, i| unsafe {
                let mut dx = vec![0.0; 4];
                (f.loaded.me_api.get_derivatives)(i.c, dx.as_mut_ptr(), 4)
            },
            "nx = 4",
        ),
        (
            "fmi2GetDerivatives",
            |f, i| unsafe { (f.loaded.me_api.get_derivatives)(i.c, null_mut(), 1 << 40) },
            "nx = 1099511627776",
        ),
        (
            "fmi2GetEventIndicators",
            |f, i| unsafe {
                let mut z = vec![0.0; f.ni() + 2];
                (f.loaded.me_api.get_event_indicators)(i.c, z.as_mut_ptr(), z.len())
            },
            "event indicator",
        ),
        (
            "fmi2GetEventIndicators",
            |f, i| unsafe { (f.loaded.me_api.get_event_indicators)(i.c, null_mut(), f.ni()) },
            "eventIndicators[] is NULL",
        ),
        (
            "fmi2GetContinuousStates",
            |f, i| unsafe { (f.loaded.me_api.get_continuous_states)(i.c, null_mut(), f.nx()) },
            "x[] is NULL",
        ),
        (
            "fmi2GetNominalsOfContinuousStates",
            |f, i| unsafe {
                (f.loaded.me_api.get_nominals_of_continuous_states)(i.c, [0.0; 3].as_mut_ptr(), 3)
            },
            "nx = 3",
        ),
        (
            "fmi2SetTime",
            |f, i| unsafe { (f.loaded.me_api.set_time)(i.c, f64::NAN) },
            "time must be finite",
        ),
        (
            "fmi2CompletedIntegratorStep",
            |f, i| unsafe {
                (f.loaded.me_api.completed_integrator_step)(i.c, 1, null_mut(), &mut 0)
            },
            "enterEventMode is NULL",
        ),
        (
            "fmi2GetDirectionalDerivative",
            |f, i| unsafe {
                // an input as the unknown
                let vr = [f.input()];
                (i.api.get_directional_derivative)(
                    i.c,
                    vr.as_ptr(),
                    1,
                    vr.as_ptr(),
                    1,
                    [1.0].as_ptr(),
                    [0.0].as_mut_ptr(),
                )
            },
            "neither a state derivative nor an output",
        ),
    ];
    for &name in SHIPPED_MODEL_EXCHANGE.iter() {
        let f = Fixture::new(name);
        let i = f.instance_in(ContinuousTimeMode);
        // a state of its own, to see it kept
        let x: Vec<f64> = (0..f.nx()).map(|k| 1e-6 * (k as f64 + 1.0)).collect();
        assert_eq!(
            unsafe { (f.loaded.me_api.set_continuous_states)(i.c, x.as_ptr(), x.len()) },
            OK
        );
        // the cases that need a state; a law without continuous states
        // (Classical) takes NULL for its arrays of none, as the standard
        // allows an array of length 0 to be
        let needs_a_state = [
            "x[] is NULL",
            "must be finite but was NaN",
            "-inf",
            "derivatives[] is NULL",
        ];
        if f.nx() == 0 {
            let api = &f.loaded.me_api;
            unsafe {
                assert_eq!((api.get_continuous_states)(i.c, null_mut(), 0), OK);
                assert_eq!((api.set_continuous_states)(i.c, std::ptr::null(), 0), OK);
                assert_eq!((api.get_derivatives)(i.c, null_mut(), 0), OK);
                assert_eq!(
                    (api.get_nominals_of_continuous_states)(i.c, null_mut(), 0),
                    OK
                );
            }
        }
        for (function, case, text) in cases {
            if f.nx() == 0 && needs_a_state.contains(text) {
                continue;
            }
            let context = format!("{name}: {function} ({text})");
            assert_eq!(case(&f, &i), ERROR, "{context}");
            assert_logged(&i, &context, &[function, text]);
            assert_eq!(f.states(&i), x, "{context}: the states changed");
        }
        // in event mode: a NULL event info, and states that cannot be set
        unsafe {
            assert_eq!((f.loaded.me_api.enter_event_mode)(i.c), OK);
            assert_eq!(
                (f.loaded.me_api.new_discrete_states)(i.c, null_mut()),
                ERROR
            );
            assert_logged(
                &i,
                name,
                &["fmi2NewDiscreteStates", "fmi2eventInfo is NULL"],
            );
        }
        f.finish_run(&i, EventMode);
    }
}

#[test]
fn a_null_foreign_or_freed_component_is_refused_by_every_model_exchange_function() {
    for &name in SHIPPED_MODEL_EXCHANGE.iter() {
        let f = Fixture::new(name);
        let m = f.loaded.me_api;
        let freed = f.instance_in(ContinuousTimeMode);
        let freed_c = freed.c;
        drop(freed);
        let mut not_an_instance = [0u64; 64];
        let foreign = not_an_instance.as_mut_ptr() as Component;
        for c in [null_mut(), foreign, freed_c] {
            let mut x = [0.0; 2];
            let (mut a, mut b) = (0, 0);
            // SAFETY: the component is invalid on purpose; every other
            // pointer is valid.
            let statuses = unsafe {
                [
                    (m.enter_event_mode)(c),
                    (m.new_discrete_states)(c, &mut EventInfo::default()),
                    (m.enter_continuous_time_mode)(c),
                    (m.completed_integrator_step)(c, 1, &mut a, &mut b),
                    (m.set_time)(c, 0.0),
                    (m.set_continuous_states)(c, x.as_ptr(), f.nx()),
                    (m.get_derivatives)(c, x.as_mut_ptr(), f.nx()),
                    (m.get_event_indicators)(c, x.as_mut_ptr(), f.ni()),
                    (m.get_continuous_states)(c, x.as_mut_ptr(), f.nx()),
                    (m.get_nominals_of_continuous_states)(c, x.as_mut_ptr(), f.nx()),
                ]
            };
            for (k, s) in statuses.iter().enumerate() {
                assert_eq!(*s, ERROR, "{name}: call {k} with component {c:p}");
            }
            assert_eq!(x, [0.0; 2], "{name}: written through an invalid component");
        }
        assert_eq!(
            not_an_instance, [0u64; 64],
            "the foreign memory was written"
        );
        let i = f.instance_in(Instantiated);
        f.finish_run(&i, Instantiated);
    }
}

/// Every shipped FMU's Co-Simulation instance refuses each Model Exchange
/// function as an illegal call, naming its state, and steps on; the FMUs
/// without a Model Exchange interface export the functions all the same
/// (one library for every model) and refuse to be instantiated for it
/// (`misuse.rs`, `a_refused_instantiation_says_why`).
#[test]
fn co_simulation_instances_refuse_the_model_exchange_functions() {
    let model_exchange_only = &ALLOWED[..10];
    assert_eq!(model_exchange_only[0].0, "fmi2EnterEventMode");
    for &name in SHIPPED.iter() {
        let f = Fixture::new(name);
        let i = f.loaded.instance("cs");
        assert_eq!(i.initialize(), OK);
        for (function, _) in model_exchange_only {
            // (the lengths the model's own are, or 1 for a model without states)
            let status = f.call(&i, function);
            assert_eq!(
                status, ERROR,
                "{name}: {function} on a Co-Simulation instance"
            );
            assert_logged(
                &i,
                function,
                &[function, "not allowed in state StepComplete"],
            );
        }
        assert_eq!(
            i.do_step(0.0, 1e-3),
            OK,
            "{name}: {:?}",
            i.log.take_errors()
        );
    }
}
