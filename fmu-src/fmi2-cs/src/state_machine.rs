//! The FMI 2.0 Co-Simulation state machine as one table: for each function,
//! the set of instance states in which it may be called (FMI 2.0.4 §4.2.4;
//! the same masks as the Modelica Reference FMUs).

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
        }
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

/// `(function, allowed states)`. Functions not named here take no instance.
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
];

/// The allowed-state mask of `function`; panics on a name not in the table
/// (a programming error caught by the tests, never by an importer). A
/// `const fn`, so that the exports resolve their masks at compile time
/// (`const { allowed_mask("fmi2DoStep") }`) and no call compares strings.
pub const fn allowed_mask(function: &str) -> u32 {
    let mut i = 0;
    while i < ALLOWED.len() {
        if same_name(ALLOWED[i].0, function) {
            return ALLOWED[i].1;
        }
        i += 1;
    }
    panic!("function not in the state table")
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

    #[test]
    fn state_bits_round_trip() {
        for s in [Instantiated, StepComplete, Terminated, Fatal] {
            assert_eq!(State::from_u32(s.to_u32()), Some(s));
        }
        assert_eq!(State::from_u32(3), None);
    }
}
