//! The FMI 2.0 state machines as tables: for each function, the set of
//! instance states in which it may be called, one table for Co-Simulation
//! (FMI 2.0.4 §4.2.4) and one for Model Exchange (§3.2.3), with the same
//! masks as the Modelica Reference FMUs.
//!
//! The two machines have states of their own, even where the standard
//! gives them the same name (a Model Exchange instance is never in the
//! Co-Simulation `Instantiated`, but in [`State::MeInstantiated`]): a
//! function's mask is the union of its two masks, so one test of the
//! instance's state decides both whether the call is allowed now and
//! whether it belongs to the interface the instance was created for (a
//! Co-Simulation function on a Model Exchange instance is refused, and
//! the reverse).

/// Instance states, as bits so that a set of states is one integer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum State {
    Instantiated = 1 << 0,
    InitializationMode = 1 << 1,
    StepComplete = 1 << 2,
    StepInProgress = 1 << 3,
    StepFailed = 1 << 4,
    StepCanceled = 1 << 5,
    Terminated = 1 << 6,
    Error = 1 << 7,
    Fatal = 1 << 8,
    // Model Exchange (§3.2.3), in the third byte: a mask of both machines
    // is then tested with one 32-bit test of the state, as a mask of the
    // first byte alone was (one in the first two bytes takes a 16-bit
    // load and a test, an instruction more in every call)
    MeInstantiated = 1 << 16,
    MeInitializationMode = 1 << 17,
    EventMode = 1 << 18,
    ContinuousTimeMode = 1 << 19,
    MeTerminated = 1 << 20,
}

impl State {
    pub fn name(self) -> &'static str {
        match self {
            State::Instantiated => "Instantiated",
            State::InitializationMode => "InitializationMode",
            State::StepComplete => "StepComplete",
            State::StepInProgress => "StepInProgress",
            State::StepFailed => "StepFailed",
            State::StepCanceled => "StepCanceled",
            State::Terminated => "Terminated",
            State::Error => "Error",
            State::Fatal => "Fatal",
            State::MeInstantiated => "Instantiated (Model Exchange)",
            State::MeInitializationMode => "InitializationMode (Model Exchange)",
            State::EventMode => "EventMode",
            State::ContinuousTimeMode => "ContinuousTimeMode",
            State::MeTerminated => "Terminated (Model Exchange)",
        }
    }

    /// Whether this is a state of the Model Exchange machine.
    pub fn is_model_exchange(self) -> bool {
        self as u32 & ME_STATES != 0
    }

    pub fn to_u32(self) -> u32 {
        self as u32
    }

    pub fn from_u32(bits: u32) -> Option<State> {
        [
            State::Instantiated,
            State::InitializationMode,
            State::StepComplete,
            State::StepInProgress,
            State::StepFailed,
            State::StepCanceled,
            State::Terminated,
            State::Error,
            State::Fatal,
            State::MeInstantiated,
            State::MeInitializationMode,
            State::EventMode,
            State::ContinuousTimeMode,
            State::MeTerminated,
        ]
        .into_iter()
        .find(|s| *s as u32 == bits)
    }
}

use State::*;

const fn mask(states: &[State]) -> u32 {
    let mut m = 0;
    let mut i = 0;
    while i < states.len() {
        m |= states[i] as u32;
        i += 1;
    }
    m
}

const ANY_LIVE: u32 = mask(&[
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    Terminated,
    Error,
]);
const AFTER_INSTANTIATE: u32 = mask(&[
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    Terminated,
    Error,
]);

/// The states of the Model Exchange machine.
const ME_STATES: u32 = mask(&[
    MeInstantiated,
    MeInitializationMode,
    EventMode,
    ContinuousTimeMode,
    MeTerminated,
]);

/// States before initialization ends, of both machines: a variable is set
/// there under the rules of initialization, anywhere else under those of
/// simulation ([`crate::Variable::settable_in_step_mode`]).
pub const BEFORE_INITIALIZATION: u32 = mask(&[
    Instantiated,
    InitializationMode,
    MeInstantiated,
    MeInitializationMode,
]);

/// Co-Simulation: `(function, allowed states)`. Functions named in
/// neither table take no instance.
pub const ALLOWED: &[(&str, u32)] = &[
    ("fmi2SetDebugLogging", ANY_LIVE | StepInProgress as u32),
    ("fmi2FreeInstance", ANY_LIVE),
    ("fmi2SetupExperiment", Instantiated as u32),
    ("fmi2EnterInitializationMode", Instantiated as u32),
    ("fmi2ExitInitializationMode", InitializationMode as u32),
    ("fmi2Terminate", mask(&[StepComplete, StepFailed])),
    ("fmi2Reset", ANY_LIVE),
    ("fmi2GetReal", AFTER_INSTANTIATE),
    ("fmi2GetInteger", AFTER_INSTANTIATE),
    ("fmi2GetBoolean", AFTER_INSTANTIATE),
    ("fmi2GetString", AFTER_INSTANTIATE),
    (
        "fmi2SetReal",
        mask(&[Instantiated, InitializationMode, StepComplete]),
    ),
    (
        "fmi2SetInteger",
        mask(&[Instantiated, InitializationMode, StepComplete]),
    ),
    (
        "fmi2SetBoolean",
        mask(&[Instantiated, InitializationMode, StepComplete]),
    ),
    (
        "fmi2SetString",
        mask(&[Instantiated, InitializationMode, StepComplete]),
    ),
    ("fmi2GetFMUstate", ANY_LIVE),
    ("fmi2SetFMUstate", ANY_LIVE),
    ("fmi2FreeFMUstate", ANY_LIVE),
    ("fmi2SerializedFMUstateSize", ANY_LIVE),
    ("fmi2SerializeFMUstate", ANY_LIVE),
    ("fmi2DeSerializeFMUstate", ANY_LIVE),
    ("fmi2GetDirectionalDerivative", AFTER_INSTANTIATE),
    (
        "fmi2SetRealInputDerivatives",
        mask(&[Instantiated, InitializationMode, StepComplete]),
    ),
    (
        "fmi2GetRealOutputDerivatives",
        mask(&[StepComplete, StepFailed, StepCanceled, Terminated, Error]),
    ),
    ("fmi2DoStep", StepComplete as u32),
    ("fmi2CancelStep", StepInProgress as u32),
    (
        "fmi2GetStatus",
        mask(&[StepComplete, StepInProgress, StepFailed, Terminated]),
    ),
    (
        "fmi2GetRealStatus",
        mask(&[StepComplete, StepInProgress, StepFailed, Terminated]),
    ),
    (
        "fmi2GetIntegerStatus",
        mask(&[StepComplete, StepInProgress, StepFailed, Terminated]),
    ),
    (
        "fmi2GetBooleanStatus",
        mask(&[StepComplete, StepInProgress, StepFailed, Terminated]),
    ),
    (
        "fmi2GetStringStatus",
        mask(&[StepComplete, StepInProgress, StepFailed, Terminated]),
    ),
    // ---- FMI 3.0 Co-Simulation (FMI 3.0 section 4.3.1), on the same
    // states: StepMode is StepComplete, and an instance of this layer
    // never enters Event Mode, Configuration Mode or Intermediate Update
    // Mode in Co-Simulation (it offers none of them)
    ("fmi3SetDebugLogging", ANY_LIVE),
    ("fmi3FreeInstance", ANY_LIVE),
    ("fmi3EnterInitializationMode", Instantiated as u32),
    ("fmi3ExitInitializationMode", InitializationMode as u32),
    ("fmi3Terminate", mask(&[StepComplete, StepFailed])),
    ("fmi3Reset", ANY_LIVE),
    ("fmi3GetFloat64", AFTER_INSTANTIATE),
    ("fmi3GetInt32", AFTER_INSTANTIATE),
    ("fmi3GetBoolean", AFTER_INSTANTIATE),
    ("fmi3GetOther", ANY_LIVE),
    (
        "fmi3SetFloat64",
        mask(&[Instantiated, InitializationMode, StepComplete]),
    ),
    (
        "fmi3SetInt32",
        mask(&[Instantiated, InitializationMode, StepComplete]),
    ),
    (
        "fmi3SetBoolean",
        mask(&[Instantiated, InitializationMode, StepComplete]),
    ),
    ("fmi3GetFMUState", ANY_LIVE),
    ("fmi3SetFMUState", ANY_LIVE),
    ("fmi3FreeFMUState", ANY_LIVE),
    ("fmi3SerializedFMUStateSize", ANY_LIVE),
    ("fmi3SerializeFMUState", ANY_LIVE),
    ("fmi3DeserializeFMUState", ANY_LIVE),
    ("fmi3GetDirectionalDerivative", AFTER_INSTANTIATE),
    ("fmi3GetAdjointDerivative", AFTER_INSTANTIATE),
    (
        "fmi3GetOutputDerivatives",
        mask(&[StepComplete, StepFailed, StepCanceled, Terminated, Error]),
    ),
    ("fmi3DoStep", StepComplete as u32),
    // what this layer does not offer: refused by name in any state
    ("fmi3Unsupported", ANY_LIVE),
];

const ME_ANY_LIVE: u32 = mask(&[
    MeInstantiated,
    MeInitializationMode,
    EventMode,
    ContinuousTimeMode,
    MeTerminated,
]);
const ME_AFTER_INSTANTIATE: u32 = mask(&[
    MeInitializationMode,
    EventMode,
    ContinuousTimeMode,
    MeTerminated,
]);

/// Model Exchange (FMI 2.0.4 §3.2.3): `(function, allowed states)`. An
/// instance of this layer never enters an error state in Model Exchange
/// (every failure is a refused call that changes nothing), so no function
/// is listed for one.
pub const ME_ALLOWED: &[(&str, u32)] = &[
    ("fmi2SetDebugLogging", ME_ANY_LIVE),
    ("fmi2FreeInstance", ME_ANY_LIVE),
    ("fmi2SetupExperiment", MeInstantiated as u32),
    ("fmi2EnterInitializationMode", MeInstantiated as u32),
    ("fmi2ExitInitializationMode", MeInitializationMode as u32),
    ("fmi2Terminate", mask(&[EventMode, ContinuousTimeMode])),
    ("fmi2Reset", ME_ANY_LIVE),
    ("fmi2GetReal", ME_AFTER_INSTANTIATE),
    ("fmi2GetInteger", ME_AFTER_INSTANTIATE),
    ("fmi2GetBoolean", ME_AFTER_INSTANTIATE),
    ("fmi2GetString", ME_AFTER_INSTANTIATE),
    // Real inputs also in continuous-time mode; the others at events only
    (
        "fmi2SetReal",
        mask(&[
            MeInstantiated,
            MeInitializationMode,
            EventMode,
            ContinuousTimeMode,
        ]),
    ),
    (
        "fmi2SetInteger",
        mask(&[MeInstantiated, MeInitializationMode, EventMode]),
    ),
    (
        "fmi2SetBoolean",
        mask(&[MeInstantiated, MeInitializationMode, EventMode]),
    ),
    (
        "fmi2SetString",
        mask(&[MeInstantiated, MeInitializationMode, EventMode]),
    ),
    ("fmi2GetFMUstate", ME_ANY_LIVE),
    ("fmi2SetFMUstate", ME_ANY_LIVE),
    ("fmi2FreeFMUstate", ME_ANY_LIVE),
    ("fmi2SerializedFMUstateSize", ME_ANY_LIVE),
    ("fmi2SerializeFMUstate", ME_ANY_LIVE),
    ("fmi2DeSerializeFMUstate", ME_ANY_LIVE),
    ("fmi2GetDirectionalDerivative", ME_AFTER_INSTANTIATE),
    ("fmi2EnterEventMode", mask(&[EventMode, ContinuousTimeMode])),
    ("fmi2NewDiscreteStates", EventMode as u32),
    ("fmi2EnterContinuousTimeMode", EventMode as u32),
    ("fmi2CompletedIntegratorStep", ContinuousTimeMode as u32),
    ("fmi2SetTime", mask(&[EventMode, ContinuousTimeMode])),
    ("fmi2SetContinuousStates", ContinuousTimeMode as u32),
    ("fmi2GetEventIndicators", ME_AFTER_INSTANTIATE),
    ("fmi2GetContinuousStates", ME_AFTER_INSTANTIATE),
    (
        "fmi2GetDerivatives",
        mask(&[EventMode, ContinuousTimeMode, MeTerminated]),
    ),
    (
        "fmi2GetNominalsOfContinuousStates",
        mask(&[MeInstantiated, EventMode, ContinuousTimeMode, MeTerminated]),
    ),
    // ---- FMI 3.0 Model Exchange (FMI 3.0 section 3.3.1)
    ("fmi3SetDebugLogging", ME_ANY_LIVE),
    ("fmi3FreeInstance", ME_ANY_LIVE),
    ("fmi3EnterInitializationMode", MeInstantiated as u32),
    ("fmi3ExitInitializationMode", MeInitializationMode as u32),
    ("fmi3Terminate", mask(&[EventMode, ContinuousTimeMode])),
    ("fmi3Reset", ME_ANY_LIVE),
    ("fmi3GetFloat64", ME_AFTER_INSTANTIATE),
    ("fmi3GetInt32", ME_AFTER_INSTANTIATE),
    ("fmi3GetBoolean", ME_AFTER_INSTANTIATE),
    ("fmi3GetOther", ME_ANY_LIVE),
    (
        "fmi3SetFloat64",
        mask(&[
            MeInstantiated,
            MeInitializationMode,
            EventMode,
            ContinuousTimeMode,
        ]),
    ),
    (
        "fmi3SetInt32",
        mask(&[MeInstantiated, MeInitializationMode, EventMode]),
    ),
    (
        "fmi3SetBoolean",
        mask(&[MeInstantiated, MeInitializationMode, EventMode]),
    ),
    ("fmi3GetFMUState", ME_ANY_LIVE),
    ("fmi3SetFMUState", ME_ANY_LIVE),
    ("fmi3FreeFMUState", ME_ANY_LIVE),
    ("fmi3SerializedFMUStateSize", ME_ANY_LIVE),
    ("fmi3SerializeFMUState", ME_ANY_LIVE),
    ("fmi3DeserializeFMUState", ME_ANY_LIVE),
    ("fmi3GetDirectionalDerivative", ME_AFTER_INSTANTIATE),
    ("fmi3GetAdjointDerivative", ME_AFTER_INSTANTIATE),
    ("fmi3EnterEventMode", mask(&[EventMode, ContinuousTimeMode])),
    ("fmi3UpdateDiscreteStates", EventMode as u32),
    (
        "fmi3EvaluateDiscreteStates",
        mask(&[MeInitializationMode, EventMode, ContinuousTimeMode]),
    ),
    ("fmi3EnterContinuousTimeMode", EventMode as u32),
    ("fmi3CompletedIntegratorStep", ContinuousTimeMode as u32),
    ("fmi3SetTime", mask(&[EventMode, ContinuousTimeMode])),
    ("fmi3SetContinuousStates", ContinuousTimeMode as u32),
    ("fmi3GetEventIndicators", ME_AFTER_INSTANTIATE),
    ("fmi3GetContinuousStates", ME_AFTER_INSTANTIATE),
    (
        "fmi3GetContinuousStateDerivatives",
        mask(&[EventMode, ContinuousTimeMode, MeTerminated]),
    ),
    (
        "fmi3GetNominalsOfContinuousStates",
        mask(&[MeInstantiated, EventMode, ContinuousTimeMode, MeTerminated]),
    ),
    ("fmi3GetNumberOfEventIndicators", ME_ANY_LIVE),
    ("fmi3GetNumberOfContinuousStates", ME_ANY_LIVE),
    ("fmi3Unsupported", ME_ANY_LIVE),
];

/// The mask of `function` in `table`, `None` if it is not there.
const fn find(table: &[(&str, u32)], function: &str) -> Option<u32> {
    let mut i = 0;
    while i < table.len() {
        if same_name(table[i].0, function) {
            return Some(table[i].1);
        }
        i += 1;
    }
    None
}

/// The allowed-state mask of `function`: its Co-Simulation and its Model
/// Exchange mask together (the states of the two machines are distinct
/// bits). Panics on a name in neither table (a programming error caught
/// by the tests, never by an importer). A `const fn`, so that the exports
/// resolve their masks at compile time
/// (`const { allowed_mask("fmi2DoStep") }`) and no call compares strings.
pub const fn allowed_mask(function: &str) -> u32 {
    match (find(ALLOWED, function), find(ME_ALLOWED, function)) {
        (None, None) => panic!("function not in the state tables"),
        (cs, me) => unwrap_or_zero(cs) | unwrap_or_zero(me),
    }
}

/// `m.unwrap_or(0)` for `const fn`.
const fn unwrap_or_zero(m: Option<u32>) -> u32 {
    match m {
        Some(m) => m,
        None => 0,
    }
}

/// `a == b` for `const fn`.
const fn same_name(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

pub fn is_allowed(function: &str, state: State) -> bool {
    allowed_mask(function) & state as u32 != 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn do_step_only_in_step_complete() {
        assert!(is_allowed("fmi2DoStep", StepComplete));
        for s in [
            Instantiated,
            InitializationMode,
            Terminated,
            Error,
            StepFailed,
        ] {
            assert!(!is_allowed("fmi2DoStep", s), "{s:?}");
        }
    }

    /// The two machines share no state (but `Fatal`, where nothing is
    /// allowed): a Co-Simulation function is refused in every Model
    /// Exchange state, and the reverse.
    #[test]
    fn the_two_machines_allow_nothing_of_each_other() {
        for (f, m) in ALLOWED {
            assert_eq!(m & ME_STATES, 0, "{f}");
            assert_eq!(m & Fatal as u32, 0, "{f}");
        }
        for (f, m) in ME_ALLOWED {
            assert_eq!(m & !ME_STATES, 0, "{f}");
        }
        for f in [
            "fmi2DoStep",
            "fmi2SetRealInputDerivatives",
            "fmi2GetRealStatus",
        ] {
            for s in [MeInstantiated, EventMode, ContinuousTimeMode, MeTerminated] {
                assert!(!is_allowed(f, s), "{f} in {s:?}");
            }
        }
        for f in ["fmi2SetTime", "fmi2GetDerivatives", "fmi2NewDiscreteStates"] {
            for s in [
                Instantiated,
                InitializationMode,
                StepComplete,
                Terminated,
                Error,
            ] {
                assert!(!is_allowed(f, s), "{f} in {s:?}");
            }
        }
        assert!(is_allowed("fmi2GetReal", EventMode) && is_allowed("fmi2GetReal", StepComplete));
        assert!(ContinuousTimeMode.is_model_exchange() && !StepComplete.is_model_exchange());
    }

    #[test]
    fn state_bits_round_trip() {
        for s in [
            Instantiated,
            StepComplete,
            Terminated,
            Fatal,
            EventMode,
            MeTerminated,
        ] {
            assert_eq!(State::from_u32(s.to_u32()), Some(s));
        }
        assert_eq!(State::from_u32(3), None);
    }
}
