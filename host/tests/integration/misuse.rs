//! Misuse of every FMU we ship (`dist/*.fmu`, built by `build-fmu.sh`),
//! through the C functions of the packaged binary loaded with libloading,
//! as a careless or hostile importer would call them.
//!
//! Each case is generated from a table and checks three things: the status
//! the standard documents (`fmi2Error`; never a crash), a logged message
//! naming the function and the offending value or state, and that the
//! instance is still usable afterwards (a following valid call sequence runs
//! to the end), as FMI 2.0.4 §2.1.3 asks for `fmi2Error` when "the FMU
//! can be further used".
//!
//! The state table below is written from FMI 2.0.4 §4.2.4 (the state
//! machine of the Co-Simulation calling sequence), independently of the
//! FMUs' own table in `fmi-export/src/state_machine.rs`.

use crate::fmi;
use fmi::*;
use std::os::raw::c_int;
use std::ptr::{null, null_mut};

/// The states of FMI 2.0.4 §4.2.4 an importer can reach with our FMUs
/// (`stepInProgress`, `stepFailed` and `stepCanceled` need asynchronous or
/// failing steps, `error`/`fatal` a failing model: the toy model of
/// `fmi-export/tests/c_abi.rs` covers those).
#[derive(Clone, Copy, Debug, PartialEq)]
enum St {
    Instantiated,
    InitializationMode,
    StepComplete,
    Terminated,
}
use St::*;

const STATES: [St; 4] = [Instantiated, InitializationMode, StepComplete, Terminated];

impl St {
    /// The name the FMUs use in their messages.
    fn name(self) -> &'static str {
        match self {
            Instantiated => "Instantiated",
            InitializationMode => "InitializationMode",
            StepComplete => "StepComplete",
            Terminated => "Terminated",
        }
    }
}

/// FMI 2.0.4 §4.2.4: for each function that takes an instance, the states
/// (of the four above) in which it may be called. "x" in the standard's
/// table. `fmi2FreeInstance` is allowed in all four and is not probed.
const ALLOWED: &[(&str, &[St])] = &[
    ("fmi2SetDebugLogging", &STATES),
    ("fmi2SetupExperiment", &[Instantiated]),
    ("fmi2EnterInitializationMode", &[Instantiated]),
    ("fmi2ExitInitializationMode", &[InitializationMode]),
    ("fmi2Terminate", &[StepComplete]),
    ("fmi2Reset", &STATES),
    (
        "fmi2GetReal",
        &[InitializationMode, StepComplete, Terminated],
    ),
    (
        "fmi2GetInteger",
        &[InitializationMode, StepComplete, Terminated],
    ),
    (
        "fmi2GetBoolean",
        &[InitializationMode, StepComplete, Terminated],
    ),
    (
        "fmi2GetString",
        &[InitializationMode, StepComplete, Terminated],
    ),
    (
        "fmi2SetReal",
        &[Instantiated, InitializationMode, StepComplete],
    ),
    (
        "fmi2SetInteger",
        &[Instantiated, InitializationMode, StepComplete],
    ),
    (
        "fmi2SetBoolean",
        &[Instantiated, InitializationMode, StepComplete],
    ),
    (
        "fmi2SetString",
        &[Instantiated, InitializationMode, StepComplete],
    ),
    ("fmi2GetFMUstate", &STATES),
    ("fmi2SetFMUstate", &STATES),
    ("fmi2FreeFMUstate", &STATES),
    ("fmi2SerializedFMUstateSize", &STATES),
    ("fmi2SerializeFMUstate", &STATES),
    ("fmi2DeSerializeFMUstate", &STATES),
    (
        "fmi2GetDirectionalDerivative",
        &[InitializationMode, StepComplete, Terminated],
    ),
    (
        "fmi2SetRealInputDerivatives",
        &[Instantiated, InitializationMode, StepComplete],
    ),
    ("fmi2GetRealOutputDerivatives", &[StepComplete, Terminated]),
    ("fmi2DoStep", &[StepComplete]),
    ("fmi2CancelStep", &[]),
    ("fmi2GetStatus", &[StepComplete, Terminated]),
    ("fmi2GetRealStatus", &[StepComplete, Terminated]),
    ("fmi2GetIntegerStatus", &[StepComplete, Terminated]),
    ("fmi2GetBooleanStatus", &[StepComplete, Terminated]),
    ("fmi2GetStringStatus", &[StepComplete, Terminated]),
];

struct Fixture {
    loaded: Loaded,
}

impl Fixture {
    fn model(&self) -> &Model {
        &self.loaded.model
    }
    fn input(&self) -> &Var {
        self.model().first("Real", "input").unwrap()
    }
    fn output(&self) -> &Var {
        self.model().first("Real", "output").unwrap()
    }

    /// A fresh instance driven into `state`.
    fn instance_in(&self, state: St) -> Instance {
        let i = self.loaded.instance("misuse");
        let steps: &[fn(&Instance) -> Status] = match state {
            Instantiated => &[],
            InitializationMode => &[|i| i.setup(0.0), Instance::enter_init],
            StepComplete => &[|i| i.setup(0.0), Instance::enter_init, Instance::exit_init],
            Terminated => &[
                |i| i.setup(0.0),
                Instance::enter_init,
                Instance::exit_init,
                Instance::terminate,
            ],
        };
        for step in steps {
            assert_eq!(step(&i), OK, "{:?}", i.log.take_errors());
        }
        i.log.take();
        i
    }

    /// Call `function` on `i` with arguments that are valid apart from the
    /// state; returns its status (FMU states it creates are freed).
    fn call(&self, i: &Instance, function: &str) -> Status {
        let start = self.input().start.unwrap_or(0.0);
        call_function(i, function, self.input().vr, self.output().vr, start)
    }

    /// The rest of a normal run from `state`: every call must succeed. This
    /// is what "the instance stays usable" means in the checks below.
    fn finish_run(&self, i: &Instance, state: St) {
        let steps: &[fn(&Instance) -> Status] = match state {
            Instantiated => &[
                |i| i.setup(0.0),
                Instance::enter_init,
                Instance::exit_init,
                |i| i.do_step(0.0, 1e-3),
                Instance::terminate,
            ],
            InitializationMode => &[
                Instance::exit_init,
                |i| i.do_step(0.0, 1e-3),
                Instance::terminate,
            ],
            StepComplete => &[|i| i.do_step(0.0, 1e-3), Instance::terminate],
            Terminated => &[
                Instance::reset,
                |i| i.setup(0.0),
                Instance::enter_init,
                Instance::exit_init,
                |i| i.do_step(0.0, 1e-3),
                Instance::terminate,
            ],
        };
        for (k, step) in steps.iter().enumerate() {
            let s = step(i);
            assert_eq!(
                s,
                OK,
                "{}: call {k} of the run continued from {state:?} failed: {:?}",
                self.model().name,
                i.log.take_errors()
            );
        }
        let (s, y) = i.get_real(&[self.output().vr]);
        assert!(
            s == OK && y[0].is_finite(),
            "{}: output {y:?}",
            self.model().name
        );
    }
}

fn fixtures() -> Vec<Fixture> {
    SHIPPED
        .iter()
        .map(|name| Fixture {
            loaded: load_shipped(name),
        })
        .collect()
}

#[test]
fn every_function_in_every_state_follows_the_standard_table() {
    let (mut refused, mut accepted) = (0, 0);
    let fixtures = fixtures();
    for f in &fixtures {
        let (r, a) = check_state_table(f, ALLOWED, &STATES);
        refused += r;
        accepted += a;
    }
    // every shipped FMU × 30 functions × 4 states
    let n = fixtures.len();
    assert_eq!(n, SHIPPED.len());
    assert_eq!(refused + accepted, n * ALLOWED.len() * 4);
    assert!(refused > n * 40, "{refused} refused calls");
}

impl StateProbe<St> for Fixture {
    fn name(&self) -> String {
        self.model().name.clone()
    }
    fn instance_in(&self, state: St) -> Instance {
        Fixture::instance_in(self, state)
    }
    fn call(&self, i: &Instance, function: &str) -> Status {
        Fixture::call(self, i, function)
    }
    fn state_word(&self, state: St) -> String {
        state.name().to_string()
    }
    fn finish_run(&self, i: &Instance, state: St) {
        Fixture::finish_run(self, i, state)
    }
}

#[test]
fn a_null_foreign_or_freed_component_is_refused_by_every_function() {
    for f in fixtures() {
        let a = f.loaded.api;
        let freed = f.loaded.instance("freed");
        let freed_c = freed.c;
        drop(freed);
        let mut not_an_instance = [0u64; 64];
        let foreign = not_an_instance.as_mut_ptr() as Component;
        for c in [null_mut(), foreign, freed_c] {
            let mut real = [0.0];
            let mut int = [0];
            let mut st = null_mut();
            let mut size = 0usize;
            let vr = [0 as Vr];
            let order = [1];
            let mut string = [null()];
            // SAFETY: the component is invalid on purpose; every other
            // pointer is valid.
            let statuses = unsafe {
                [
                    (a.set_debug_logging)(c, 1, 0, null()),
                    (a.setup_experiment)(c, 0, 0.0, 0.0, 0, 0.0),
                    (a.enter_initialization_mode)(c),
                    (a.exit_initialization_mode)(c),
                    (a.terminate)(c),
                    (a.reset)(c),
                    (a.get_real)(c, vr.as_ptr(), 1, real.as_mut_ptr()),
                    (a.get_integer)(c, vr.as_ptr(), 1, int.as_mut_ptr()),
                    (a.get_boolean)(c, vr.as_ptr(), 1, int.as_mut_ptr()),
                    (a.get_string)(c, vr.as_ptr(), 1, string.as_mut_ptr()),
                    (a.set_real)(c, vr.as_ptr(), 1, real.as_ptr()),
                    (a.set_integer)(c, vr.as_ptr(), 1, int.as_ptr()),
                    (a.set_boolean)(c, vr.as_ptr(), 1, int.as_ptr()),
                    (a.set_string)(c, vr.as_ptr(), 1, string.as_ptr()),
                    (a.get_fmu_state)(c, &mut st),
                    (a.set_fmu_state)(c, st),
                    (a.free_fmu_state)(c, &mut st),
                    (a.serialized_fmu_state_size)(c, st, &mut size),
                    (a.serialize_fmu_state)(c, st, null_mut(), 0),
                    (a.deserialize_fmu_state)(c, null(), 0, &mut st),
                    (a.get_directional_derivative)(
                        c,
                        vr.as_ptr(),
                        1,
                        vr.as_ptr(),
                        1,
                        real.as_ptr(),
                        real.as_mut_ptr(),
                    ),
                    (a.set_real_input_derivatives)(
                        c,
                        vr.as_ptr(),
                        1,
                        order.as_ptr(),
                        real.as_ptr(),
                    ),
                    (a.get_real_output_derivatives)(
                        c,
                        vr.as_ptr(),
                        1,
                        order.as_ptr(),
                        real.as_mut_ptr(),
                    ),
                    (a.do_step)(c, 0.0, 1e-3, 1),
                    (a.cancel_step)(c),
                    (a.get_status)(c, 0, int.as_mut_ptr()),
                    (a.get_real_status)(c, 2, real.as_mut_ptr()),
                    (a.get_integer_status)(c, 0, int.as_mut_ptr()),
                    (a.get_boolean_status)(c, 3, int.as_mut_ptr()),
                    (a.get_string_status)(c, 1, string.as_mut_ptr()),
                ]
            };
            for (k, s) in statuses.iter().enumerate() {
                assert_eq!(
                    *s,
                    ERROR,
                    "{}: call {k} with component {c:p}",
                    f.model().name
                );
            }
            assert!(st.is_null());
            // SAFETY: freeing an unknown pointer must be a no-op.
            unsafe { (a.free_instance)(c) };
        }
        assert_eq!(
            not_an_instance, [0u64; 64],
            "the foreign memory was written"
        );
        // The library still works after all that.
        let i = f.instance_in(StepComplete);
        f.finish_run(&i, StepComplete);
    }
}

/// A refused call with bad arrays: `(function, call, text the message must contain)`.
type ArrayCase = (&'static str, fn(&Instance, Vr) -> Status, &'static str);

#[test]
fn null_arrays_and_implausible_lengths_are_refused() {
    let cases: &[ArrayCase] = &[
        (
            "fmi2GetReal",
            |i, _| unsafe { (i.api.get_real)(i.c, null(), 1, [0.0].as_mut_ptr()) },
            "NULL",
        ),
        (
            "fmi2GetReal",
            |i, vr| unsafe { (i.api.get_real)(i.c, [vr].as_ptr(), 1, null_mut()) },
            "NULL",
        ),
        (
            "fmi2SetReal",
            |i, _| unsafe { (i.api.set_real)(i.c, null(), 2, [0.0; 2].as_ptr()) },
            "NULL",
        ),
        (
            "fmi2SetReal",
            |i, vr| unsafe { (i.api.set_real)(i.c, [vr].as_ptr(), 1, null()) },
            "NULL",
        ),
        (
            "fmi2SetReal",
            |i, vr| unsafe { (i.api.set_real)(i.c, [vr].as_ptr(), usize::MAX, [0.0].as_ptr()) },
            "length of",
        ),
        (
            "fmi2GetReal",
            |i, vr| unsafe { (i.api.get_real)(i.c, [vr].as_ptr(), 1 << 40, [0.0].as_mut_ptr()) },
            "length of",
        ),
        (
            "fmi2GetInteger",
            |i, _| unsafe { (i.api.get_integer)(i.c, null(), 1, [0].as_mut_ptr()) },
            "NULL",
        ),
        (
            "fmi2SetBoolean",
            |i, _| unsafe { (i.api.set_boolean)(i.c, null(), 1, [0].as_ptr()) },
            "NULL",
        ),
        (
            "fmi2SetDebugLogging",
            |i, _| unsafe { (i.api.set_debug_logging)(i.c, 1, 2, null()) },
            "NULL",
        ),
        (
            "fmi2SetDebugLogging",
            |i, _| unsafe { (i.api.set_debug_logging)(i.c, 1, 1, [null()].as_ptr()) },
            "NULL",
        ),
        (
            "fmi2GetFMUstate",
            |i, _| unsafe { (i.api.get_fmu_state)(i.c, null_mut()) },
            "NULL",
        ),
        (
            "fmi2DeSerializeFMUstate",
            |i, _| unsafe { (i.api.deserialize_fmu_state)(i.c, null(), 10, &mut null_mut()) },
            "NULL",
        ),
        (
            "fmi2SerializedFMUstateSize",
            |i, _| unsafe { (i.api.serialized_fmu_state_size)(i.c, null_mut(), &mut 0) },
            "state",
        ),
        (
            "fmi2GetDirectionalDerivative",
            |i, vr| unsafe {
                (i.api.get_directional_derivative)(
                    i.c,
                    [vr].as_ptr(),
                    1,
                    null(),
                    1,
                    [1.0].as_ptr(),
                    [0.0].as_mut_ptr(),
                )
            },
            "NULL",
        ),
        (
            "fmi2SetRealInputDerivatives",
            |i, vr| unsafe {
                (i.api.set_real_input_derivatives)(i.c, [vr].as_ptr(), 1, null(), [0.0].as_ptr())
            },
            "NULL",
        ),
        (
            "fmi2GetStatus",
            |i, _| unsafe { (i.api.get_status)(i.c, 0, null_mut()) },
            "NULL",
        ),
    ];
    for f in fixtures() {
        let i = f.instance_in(StepComplete);
        for (function, case, text) in cases {
            let vr = f.output().vr;
            let context = format!("{}: {function} ({text})", f.model().name);
            assert_eq!(case(&i, vr), ERROR, "{context}");
            assert_logged(&i, &context, &[function, text]);
        }
        f.finish_run(&i, StepComplete);
    }
}

#[test]
fn unknown_value_references_and_wrong_types_are_refused_naming_the_reference() {
    for f in fixtures() {
        let i = f.instance_in(StepComplete);
        let m = f.model();
        for vr in [m.unknown_vr(), Vr::MAX] {
            let text = vr.to_string();
            assert_eq!(i.get_real(&[vr]).0, ERROR);
            assert_logged(&i, "get", &["fmi2GetReal", &text]);
            assert_eq!(i.set_real(&[f.input().vr, vr], &[0.0, 0.0]), ERROR);
            assert_logged(&i, "set", &["fmi2SetReal", &text]);
            assert_eq!(i.set_integer(&[vr], &[1]), ERROR);
            assert_logged(&i, "set int", &["fmi2SetInteger", &text]);
        }
        // A Real read as an Integer or Boolean.
        let vr = f.output().vr;
        assert_eq!(i.set_integer(&[vr], &[1]), ERROR);
        assert_logged(&i, "type", &["fmi2SetInteger", &f.output().name]);
        let mut out = [0];
        assert_eq!(
            unsafe { (i.api.get_boolean)(i.c, [vr].as_ptr(), 1, out.as_mut_ptr()) },
            ERROR
        );
        assert_logged(&i, "type", &["fmi2GetBoolean", &f.output().name]);
        f.finish_run(&i, StepComplete);
    }
}

#[test]
fn parameters_cannot_change_after_initialization_and_outputs_never() {
    for f in fixtures() {
        let m = f.model();
        let i = f.instance_in(StepComplete);
        let parameters: Vec<&Var> = m
            .vars
            .iter()
            .filter(|v| v.causality == "parameter")
            .collect();
        assert!(!parameters.is_empty());
        for p in parameters {
            // Our FMUs declare no tunable parameter (checked here, so a
            // tunable one added later gets its own case).
            assert_eq!(p.variability, "fixed", "{}", p.name);
            let start = p.start.unwrap_or(0.0);
            let status = match p.type_name {
                "Real" => i.set_real(&[p.vr], &[start]),
                "Integer" => i.set_integer(&[p.vr], &[start as c_int]),
                "Boolean" => i.set_boolean(&[p.vr], &[start as c_int]),
                other => panic!("{other} parameter {}", p.name),
            };
            let context = format!("{}: set {} after initialization", m.name, p.name);
            assert_eq!(status, ERROR, "{context}");
            assert_logged(&i, &context, &["fmi2Set", &p.name, "StepComplete"]);
        }
        for o in m.with("Real", "output") {
            assert_eq!(i.set_real(&[o.vr], &[0.0]), ERROR);
            assert_logged(&i, "output", &["fmi2SetReal", &o.name, "output"]);
        }
        f.finish_run(&i, StepComplete);
    }
}

/// Non-finite values: each is refused by `fmi2SetReal`, naming the variable
/// and the value, and the variable keeps its value.
#[test]
fn nan_and_infinities_are_refused_for_every_real_input_and_parameter() {
    let mut cases = 0;
    for f in fixtures() {
        let m = f.model();
        // Parameters in initialization mode (where they may be set and read).
        let i = f.instance_in(InitializationMode);
        for causality in ["parameter", "input"] {
            for v in m.with("Real", causality) {
                let (_, before) = i.get_real(&[v.vr]);
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    let context = format!("{}: {} = {bad}", m.name, v.name);
                    assert_eq!(i.set_real(&[v.vr], &[bad]), ERROR, "{context}");
                    assert_logged(&i, &context, &["fmi2SetReal", &v.name, &bad.to_string()]);
                    let (_, after) = i.get_real(&[v.vr]);
                    assert_eq!(before[0].to_bits(), after[0].to_bits(), "{context}");
                    cases += 1;
                }
            }
        }
        f.finish_run(&i, InitializationMode);
        // Inputs again in step mode, and their derivatives.
        let i = f.instance_in(StepComplete);
        for v in m.with("Real", "input") {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let context = format!("{}: {} = {bad} in step mode", m.name, v.name);
                assert_eq!(i.set_real(&[v.vr], &[bad]), ERROR, "{context}");
                assert_logged(&i, &context, &["fmi2SetReal", &v.name, &bad.to_string()]);
                let status = unsafe {
                    (i.api.set_real_input_derivatives)(
                        i.c,
                        [v.vr].as_ptr(),
                        1,
                        [1].as_ptr(),
                        [bad].as_ptr(),
                    )
                };
                assert_eq!(status, ERROR, "{context}");
                assert_logged(
                    &i,
                    &context,
                    &["fmi2SetRealInputDerivatives", &v.name, &bad.to_string()],
                );
                cases += 1;
            }
        }
        f.finish_run(&i, StepComplete);
    }
    assert!(cases > 300, "{cases}");
}

#[test]
fn wrong_communication_points_and_step_sizes_are_refused() {
    // (t, h, text the message must contain)
    let cases: &[(f64, f64, &str)] = &[
        (0.0, 0.0, "communicationStepSize"),
        (0.0, -1e-3, "-0.001"),
        (0.0, f64::NAN, "NaN"),
        (0.0, f64::INFINITY, "inf"),
        (0.0, f64::NEG_INFINITY, "-inf"),
        (0.5, 1e-3, "0.5"),
        (-1e-3, 1e-3, "currentCommunicationPoint"),
        (f64::NAN, 1e-3, "NaN"),
        (1e-3, 1e-3, "0.001"),
    ];
    for f in fixtures() {
        let i = f.instance_in(StepComplete);
        for (t, h, text) in cases {
            let context = format!("{}: fmi2DoStep(t = {t}, h = {h})", f.model().name);
            assert_eq!(i.do_step(*t, *h), ERROR, "{context}");
            assert_logged(&i, &context, &["fmi2DoStep", text]);
        }
        // A step that goes back in time after a real step.
        assert_eq!(i.do_step(0.0, 1e-3), OK);
        assert_eq!(i.do_step(0.0, 1e-3), ERROR);
        assert_logged(
            &i,
            "repeat",
            &["fmi2DoStep", "expected currentCommunicationPoint = 0.001"],
        );
        assert_eq!(i.do_step(1e-3, 1e-3), OK);
        // Setting up an experiment with a non-finite start time.
        let fresh = f.instance_in(Instantiated);
        for bad in [f64::NAN, f64::INFINITY] {
            assert_eq!(fresh.setup(bad), ERROR);
            assert_logged(&fresh, "setup", &["fmi2SetupExperiment", &bad.to_string()]);
        }
        f.finish_run(&fresh, Instantiated);
    }
}

#[test]
fn truncated_corrupted_and_foreign_serialized_states_are_refused() {
    let fixtures = fixtures();
    // One serialized state of each FMU after a few steps.
    let states: Vec<Vec<u8>> = fixtures
        .iter()
        .map(|f| {
            let i = f.instance_in(StepComplete);
            for k in 0..5 {
                assert_eq!(i.do_step(k as f64 * 1e-3, 1e-3), OK);
            }
            i.serialize()
        })
        .collect();
    for (k, f) in fixtures.iter().enumerate() {
        let name = &f.model().name;
        let i = f.instance_in(StepComplete);
        let own = &states[k];
        // Every truncation.
        for n in 0..own.len() {
            assert_eq!(
                i.restore(&own[..n]),
                ERROR,
                "{name}: {n} of {} bytes",
                own.len()
            );
            assert_logged(&i, "truncated", &["fmi2DeSerializeFMUstate"]);
        }
        // Every byte changed.
        for b in 0..own.len() {
            let mut bad = own.clone();
            bad[b] ^= 0x5a;
            assert_eq!(i.restore(&bad), ERROR, "{name}: byte {b} changed");
            assert_logged(&i, "corrupted", &["fmi2DeSerializeFMUstate"]);
        }
        // One byte too many.
        let mut long = own.clone();
        long.push(0);
        assert_eq!(i.restore(&long), ERROR, "{name}: trailing byte");
        assert_logged(&i, "long", &["fmi2DeSerializeFMUstate"]);
        // The state of every other FMU (LuGre's into Dahl, and so on).
        for (j, other) in states.iter().enumerate() {
            if j == k {
                continue;
            }
            let context = format!("{} state into {name}", fixtures[j].model().name);
            assert_eq!(i.restore(other), ERROR, "{context}");
            assert_logged(&i, &context, &["fmi2DeSerializeFMUstate", "GUID"]);
        }
        // Still usable, and the genuine state restores: the next step
        // continues from t = 5 ms.
        assert_eq!(i.restore(own), OK, "{name}: {:?}", i.log.take_errors());
        assert_eq!(
            i.do_step(5e-3, 1e-3),
            OK,
            "{name}: {:?}",
            i.log.take_errors()
        );
    }
}

#[test]
fn a_refused_instantiation_says_why() {
    for f in fixtures() {
        let a = f.loaded.api;
        // Unknown GUID.
        let log = Instance::new(a, "bad", "{00000000-0000-0000-0000-000000000000}", false)
            .err()
            .expect("an unknown GUID must be refused");
        let m = log.take_errors();
        assert!(
            m.len() == 1 && m[0].contains("fmi2Instantiate") && m[0].contains("00000000-0000"),
            "{m:?}"
        );
        // Model Exchange where the FMU has no <ModelExchange> element: refused, naming it.
        if f.loaded.model_exchange.is_none() {
            let log = Instance::of_type(a, "me", &f.model().guid, false, MODEL_EXCHANGE)
                .err()
                .expect("Model Exchange must be refused");
            let m = log.take_errors();
            assert!(
                m.len() == 1 && m[0].contains("fmuType = 0") && m[0].contains(&f.model().name),
                "{m:?}"
            );
        }
        // NULL name, NULL GUID, NULL callbacks, fmuType 7: NULL, no crash.
        let guid = std::ffi::CString::new(f.model().guid.clone()).unwrap();
        let name = c"x";
        let callbacks = Callbacks {
            logger: None,
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: null_mut(),
        };
        unsafe {
            for (n, t, g, cb) in [
                (null(), 0, guid.as_ptr(), &callbacks as *const _),
                (null(), 1, guid.as_ptr(), &callbacks as *const _),
                (name.as_ptr(), 1, null(), &callbacks as *const _),
                (name.as_ptr(), 1, guid.as_ptr(), null()),
                (name.as_ptr(), 7, guid.as_ptr(), &callbacks as *const _),
            ] {
                let c = (a.instantiate)(n, t, g, null(), cb, 0, 0);
                assert!(c.is_null(), "{}: instantiated anyway", f.model().name);
            }
        }
    }
}

#[test]
fn debug_logging_honours_categories_and_logging_on() {
    for f in fixtures() {
        let m = f.model();
        assert_eq!(
            m.log_categories,
            [
                "logStatusError",
                "logStatusFatal",
                "logStatusWarning",
                "logCalls"
            ],
            "{}",
            m.name
        );
        // loggingOn = false: errors only.
        let i = f.instance_in(StepComplete);
        assert_eq!(i.do_step(0.0, 1e-3), OK);
        assert!(i.log.take().is_empty());
        assert_eq!(i.do_step(1.0, 1e-3), ERROR);
        let log = i.log.take();
        assert!(
            log.len() == 1 && log[0].category == "logStatusError" && log[0].instance == "misuse"
        );
        // logCalls only.
        assert_eq!(i.set_debug_logging(true, &["logCalls"]), OK);
        assert_eq!(i.do_step(1e-3, 1e-3), OK);
        let log = i.log.take();
        assert!(
            !log.is_empty() && log.iter().all(|m| m.category == "logCalls"),
            "{log:?}"
        );
        assert!(log.iter().any(|m| m.text.contains("fmi2DoStep")), "{log:?}");
        // Errors switched off too: a refused call logs nothing, still refused.
        assert_eq!(
            i.set_debug_logging(false, &["logCalls", "logStatusError"]),
            OK
        );
        i.log.take(); // the switching call itself, logged under logCalls
        assert_eq!(i.do_step(1.0, 1e-3), ERROR);
        assert!(i.log.take().is_empty());
        // All debug categories on at once, then an unknown category refused
        // with the known ones listed.
        assert_eq!(i.set_debug_logging(true, &[]), OK);
        assert_eq!(i.set_debug_logging(true, &["logStatusError"]), OK);
        i.log.take();
        assert_eq!(i.set_debug_logging(true, &["logEverything"]), ERROR);
        let log = i.log.take();
        let error = log.iter().find(|m| m.status == ERROR).expect("an error");
        assert!(
            error.text.contains("fmi2SetDebugLogging")
                && error.text.contains("logEverything")
                && error.text.contains("logCalls"),
            "{error:?}"
        );
        // loggingOn = true at instantiation: calls are logged from the start.
        let on = Instance::new(f.loaded.api, "verbose", &m.guid, true)
            .ok()
            .unwrap();
        assert_eq!(on.setup(0.0), OK);
        let log = on.log.take();
        assert!(
            log.iter()
                .any(|m| m.category == "logCalls" && m.text.contains("fmi2SetupExperiment")),
            "{log:?}"
        );
    }
}
