//! Raw access to the FMI 2.0 C functions of an FMU binary (Co-Simulation,
//! and Model Exchange in [`MeApi`]: the importer's raw layer,
//! `fricsim_fmi::fmi2`), for
//! tests that misuse them on purpose (`misuse.rs`, `fuzz_bounded.rs`,
//! `parallel_instances.rs`) and for the fuzz targets in `fuzz/` (which
//! include this file with `#[path]` and fill [`Api`] from the exports linked
//! into the fuzzer, so that the FMU code is instrumented).
//!
//! Unlike the host's safe importer, nothing here checks anything: every
//! pointer, length and call order is the caller's choice.
#![allow(dead_code, clippy::missing_safety_doc)]

pub mod sequence;

use fricsim_fmi::fmi2;
use std::ffi::{c_void, CStr, CString};
use std::os::raw::{c_char, c_int};
use std::path::Path;
use std::ptr::{null, null_mut};
use std::sync::Mutex;

pub type Component = fmi2::fmi2Component;
pub type FmuState = fmi2::fmi2FMUstate;
pub type Vr = fmi2::fmi2ValueReference;
/// `fmi2Status` as the C `int` it is.
pub type Status = fmi2::fmi2Status;

pub const OK: Status = fmi2::fmi2OK;
pub const WARNING: Status = fmi2::fmi2Warning;
pub const DISCARD: Status = fmi2::fmi2Discard;
pub const ERROR: Status = fmi2::fmi2Error;
pub const FATAL: Status = fmi2::fmi2Fatal;

/// `fmi2CallbackFunctions`, any field of which may be null.
pub type Callbacks = fmi2::CallbackFunctions;
/// `fmi2EventInfo`.
pub type EventInfo = fmi2::fmi2EventInfo;

/// Every function of the FMI 2.0 Co-Simulation API (FMI 2.0.4 §2.1,
/// §4.2) as a typed pointer: the importer's raw table.
pub type Api = fmi2::Functions;

/// The functions Model Exchange adds (FMI 2.0.4 §3.2) as typed pointers.
pub type MeApi = fmi2::ModelExchangeFunctions;

/// The importer's logger, declared without the variadic tail: the FMUs
/// call it with a format and no arguments, so the ABI is the same on
/// x86-64 (as with ctypes loggers).
type LoggerFn =
    unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char);
/// The logger as FMI 2.0 declares it, variadic.
type VariadicLogger =
    unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char, ...);

// ---- the model description, reduced to what the probes need ---------------

/// A scalar variable: value reference, name, type (`Real`, `Integer`,
/// `Boolean`, `String`), causality, variability and start value.
#[derive(Clone, Debug)]
pub struct Var {
    pub vr: Vr,
    pub name: String,
    pub type_name: &'static str,
    pub causality: &'static str,
    pub variability: &'static str,
    pub start: Option<f64>,
}

/// One FMU as a probe sees it.
#[derive(Clone, Debug)]
pub struct Model {
    pub name: String,
    pub guid: String,
    pub vars: Vec<Var>,
    pub log_categories: Vec<String>,
    /// Continuous states (variables that are the `derivative` of one) and
    /// event indicators, for Model Exchange (0 without it).
    pub states: usize,
    pub event_indicators: usize,
}

impl Model {
    /// From a `modelDescription.xml` (parsed by the host's parser).
    pub fn from_description(md: &fricsim_fmi::ModelDescription) -> Model {
        use fricsim_fmi::VariableKind as K;
        Model {
            name: md.model_name.clone(),
            guid: md.guid.clone(),
            vars: md
                .variables
                .iter()
                .map(|v| Var {
                    vr: v.value_reference,
                    name: v.name.clone(),
                    type_name: v.kind.type_name(),
                    causality: v.causality.as_str(),
                    variability: v.variability.as_str(),
                    start: match &v.kind {
                        K::Real { start, .. } => *start,
                        K::Integer { start, .. } | K::Enumeration { start, .. } => {
                            start.map(f64::from)
                        }
                        K::Boolean { start } => start.map(|b| b as i32 as f64),
                        K::String { .. } => None,
                    },
                })
                .collect(),
            log_categories: md.log_categories.iter().map(|c| c.name.clone()).collect(),
            states: md
                .variables
                .iter()
                .filter(|v| {
                    matches!(
                        v.kind,
                        K::Real {
                            derivative: Some(_),
                            ..
                        }
                    )
                })
                .count(),
            event_indicators: md.number_of_event_indicators as usize,
        }
    }

    pub fn with(&self, type_name: &str, causality: &str) -> Vec<&Var> {
        self.vars
            .iter()
            .filter(|v| v.type_name == type_name && v.causality == causality)
            .collect()
    }

    pub fn first(&self, type_name: &str, causality: &str) -> Option<&Var> {
        self.with(type_name, causality).into_iter().next()
    }

    /// A value reference no variable has.
    pub fn unknown_vr(&self) -> Vr {
        self.vars.iter().map(|v| v.vr).max().unwrap_or(0) + 1000
    }
}

// ---- a logger that keeps every message, per instance ----------------------

/// One message the FMU logged.
#[derive(Clone, Debug)]
pub struct Message {
    pub instance: String,
    pub status: c_int,
    pub category: String,
    /// The text as a C importer prints it (`%%` → `%`).
    pub text: String,
}

/// The messages of one instance (its `componentEnvironment`).
#[derive(Default)]
pub struct Log {
    pub messages: Mutex<Vec<Message>>,
}

impl Log {
    pub fn take(&self) -> Vec<Message> {
        std::mem::take(&mut *self.messages.lock().unwrap())
    }

    /// The text of every message of status Error or Fatal, taken.
    pub fn take_errors(&self) -> Vec<String> {
        self.take()
            .into_iter()
            .filter(|m| m.status >= ERROR)
            .map(|m| m.text)
            .collect()
    }
}

unsafe extern "C" fn record(
    environment: *mut c_void,
    instance: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    let text = |p: *const c_char| {
        if p.is_null() {
            "<NULL>".to_string()
        } else {
            // SAFETY: the FMU passes NUL-terminated strings.
            unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
        }
    };
    if environment.is_null() {
        return;
    }
    // SAFETY: every instance is created with a `Log` that outlives it.
    let log = unsafe { &*(environment as *const Log) };
    log.messages.lock().unwrap().push(Message {
        instance: text(instance),
        status,
        category: text(category),
        text: text(message).replace("%%", "%"),
    });
}

// ---- an instance --------------------------------------------------------

/// An instance with its logger; freed on drop. Every call is raw: the
/// status is returned, never checked.
pub struct Instance {
    pub api: Api,
    pub c: Component,
    pub log: Box<Log>,
    _callbacks: Box<Callbacks>,
}

// The instance is only used by one thread at a time (moved, not shared).
unsafe impl Send for Instance {}

pub const MODEL_EXCHANGE: c_int = 0;
pub const CO_SIMULATION: c_int = 1;

impl Instance {
    /// `fmi2Instantiate` with a recording logger; if it returned NULL, the
    /// log with the FMU's reason instead.
    pub fn new(api: Api, name: &str, guid: &str, logging_on: bool) -> Result<Instance, Box<Log>> {
        Instance::of_type(api, name, guid, logging_on, CO_SIMULATION)
    }

    /// [`Instance::new`] for `fmu_type` ([`MODEL_EXCHANGE`] or
    /// [`CO_SIMULATION`]).
    pub fn of_type(
        api: Api,
        name: &str,
        guid: &str,
        logging_on: bool,
        fmu_type: c_int,
    ) -> Result<Instance, Box<Log>> {
        let log = Box::<Log>::default();
        let callbacks = Box::new(Callbacks {
            // SAFETY: see `LoggerFn`
            logger: Some(unsafe { std::mem::transmute::<LoggerFn, VariadicLogger>(record) }),
            allocate_memory: None,
            free_memory: None,
            step_finished: None,
            component_environment: &*log as *const Log as *mut c_void,
        });
        let name = CString::new(name).unwrap();
        let guid = CString::new(guid).unwrap();
        let resources = CString::new("file:///tmp").unwrap();
        // SAFETY: valid strings and callbacks that outlive the instance.
        let c = unsafe {
            (api.instantiate)(
                name.as_ptr(),
                fmu_type,
                guid.as_ptr(),
                resources.as_ptr(),
                &*callbacks,
                0,
                logging_on as c_int,
            )
        };
        if c.is_null() {
            return Err(log);
        }
        Ok(Instance {
            api,
            c,
            log,
            _callbacks: callbacks,
        })
    }

    pub fn setup(&self, start: f64) -> Status {
        unsafe { (self.api.setup_experiment)(self.c, 0, 0.0, start, 0, 0.0) }
    }
    pub fn enter_init(&self) -> Status {
        unsafe { (self.api.enter_initialization_mode)(self.c) }
    }
    pub fn exit_init(&self) -> Status {
        unsafe { (self.api.exit_initialization_mode)(self.c) }
    }
    pub fn terminate(&self) -> Status {
        unsafe { (self.api.terminate)(self.c) }
    }
    pub fn reset(&self) -> Status {
        unsafe { (self.api.reset)(self.c) }
    }
    pub fn do_step(&self, t: f64, h: f64) -> Status {
        unsafe { (self.api.do_step)(self.c, t, h, 1) }
    }
    pub fn set_real(&self, vrs: &[Vr], values: &[f64]) -> Status {
        assert_eq!(vrs.len(), values.len());
        unsafe { (self.api.set_real)(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
    }
    pub fn get_real(&self, vrs: &[Vr]) -> (Status, Vec<f64>) {
        let mut out = vec![f64::NAN; vrs.len()];
        let s = unsafe { (self.api.get_real)(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        (s, out)
    }
    pub fn set_integer(&self, vrs: &[Vr], values: &[c_int]) -> Status {
        unsafe { (self.api.set_integer)(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
    }
    pub fn set_boolean(&self, vrs: &[Vr], values: &[c_int]) -> Status {
        unsafe { (self.api.set_boolean)(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
    }
    pub fn set_debug_logging(&self, on: bool, categories: &[&str]) -> Status {
        let owned: Vec<CString> = categories
            .iter()
            .map(|c| CString::new(*c).unwrap())
            .collect();
        let pointers: Vec<*const c_char> = owned.iter().map(|c| c.as_ptr()).collect();
        let p = if pointers.is_empty() {
            null()
        } else {
            pointers.as_ptr()
        };
        unsafe { (self.api.set_debug_logging)(self.c, on as c_int, pointers.len(), p) }
    }

    /// `fmi2GetFMUstate` into a fresh state (NULL on failure).
    pub fn get_state(&self) -> (Status, FmuState) {
        let mut s: FmuState = null_mut();
        let status = unsafe { (self.api.get_fmu_state)(self.c, &mut s) };
        (status, s)
    }
    pub fn free_state(&self, mut s: FmuState) -> Status {
        unsafe { (self.api.free_fmu_state)(self.c, &mut s) }
    }

    /// The current FMU state, serialized.
    pub fn serialize(&self) -> Vec<u8> {
        let (status, s) = self.get_state();
        assert_eq!(status, OK, "fmi2GetFMUstate: {:?}", self.log.take_errors());
        let mut size = 0usize;
        assert_eq!(
            unsafe { (self.api.serialized_fmu_state_size)(self.c, s, &mut size) },
            OK
        );
        let mut bytes = vec![0u8; size];
        assert_eq!(
            unsafe {
                (self.api.serialize_fmu_state)(self.c, s, bytes.as_mut_ptr() as *mut c_char, size)
            },
            OK
        );
        self.free_state(s);
        bytes
    }

    /// `fmi2DeSerializeFMUstate` of `bytes`, then `fmi2SetFMUstate` if it
    /// was accepted; the status of the first call that did not return OK.
    pub fn restore(&self, bytes: &[u8]) -> Status {
        let mut s: FmuState = null_mut();
        let status = unsafe {
            (self.api.deserialize_fmu_state)(
                self.c,
                bytes.as_ptr() as *const c_char,
                bytes.len(),
                &mut s,
            )
        };
        if status != OK {
            assert!(s.is_null(), "a refused state must not be handed out");
            return status;
        }
        let set = unsafe { (self.api.set_fmu_state)(self.c, s) };
        self.free_state(s);
        set
    }

    /// setup, enter and exit initialization mode at t = 0.
    pub fn initialize(&self) -> Status {
        self.setup(0.0).max(self.enter_init()).max(self.exit_init())
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        unsafe { (self.api.free_instance)(self.c) }
    }
}

/// The single error `i` logged since the last check, which must contain
/// every one of `parts`.
pub fn assert_logged(i: &Instance, context: &str, parts: &[&str]) {
    let errors = i.log.take_errors();
    assert_eq!(
        errors.len(),
        1,
        "{context}: expected one error, got {errors:?}"
    );
    for part in parts {
        assert!(
            errors[0].contains(part),
            "{context}: {:?} does not contain {part:?}",
            errors[0]
        );
    }
}

/// Call `function` (any function of the Co-Simulation API that takes an
/// instance) on `i` with arguments that are valid apart from the state:
/// `input` and `output` are value references of a Real input and output,
/// `start` the input's start value. Its status (FMU states it creates are
/// freed).
pub fn call_function(i: &Instance, function: &str, input: Vr, output: Vr, start: f64) -> Status {
    let a = i.api;
    let c = i.c;
    let input = [input];
    let output = [output];
    let mut real = [0.0f64];
    let mut int = [0 as c_int];
    let mut string: [*const c_char; 1] = [null()];
    let order = [1 as c_int];
    // SAFETY: every pointer is valid for the length passed.
    unsafe {
        match function {
            "fmi2SetDebugLogging" => i.set_debug_logging(true, &[]),
            "fmi2SetupExperiment" => i.setup(0.0),
            "fmi2EnterInitializationMode" => i.enter_init(),
            "fmi2ExitInitializationMode" => i.exit_init(),
            "fmi2Terminate" => i.terminate(),
            "fmi2Reset" => i.reset(),
            "fmi2GetReal" => (a.get_real)(c, output.as_ptr(), 1, real.as_mut_ptr()),
            "fmi2GetInteger" => (a.get_integer)(c, null(), 0, int.as_mut_ptr()),
            "fmi2GetBoolean" => (a.get_boolean)(c, null(), 0, int.as_mut_ptr()),
            "fmi2GetString" => (a.get_string)(c, null(), 0, string.as_mut_ptr()),
            "fmi2SetReal" => {
                let start = [start];
                (a.set_real)(c, input.as_ptr(), 1, start.as_ptr())
            }
            "fmi2SetInteger" => (a.set_integer)(c, null(), 0, null()),
            "fmi2SetBoolean" => (a.set_boolean)(c, null(), 0, null()),
            "fmi2SetString" => (a.set_string)(c, null(), 0, null()),
            "fmi2GetFMUstate" => {
                let (s, st) = i.get_state();
                i.free_state(st);
                s
            }
            "fmi2SetFMUstate" => {
                let (s, st) = i.get_state();
                assert_eq!(s, OK);
                let set = (a.set_fmu_state)(c, st);
                i.free_state(st);
                set
            }
            "fmi2FreeFMUstate" => {
                let (s, st) = i.get_state();
                assert_eq!(s, OK);
                i.free_state(st)
            }
            "fmi2SerializedFMUstateSize" => {
                let (_, st) = i.get_state();
                let mut size = 0;
                let s = (a.serialized_fmu_state_size)(c, st, &mut size);
                i.free_state(st);
                s
            }
            "fmi2SerializeFMUstate" => {
                let (_, st) = i.get_state();
                let mut size = 0;
                (a.serialized_fmu_state_size)(c, st, &mut size);
                // as large as the FMU says (GMS's state, with its 400
                // element variables, is over 6 kB)
                let mut bytes = vec![0u8; size];
                let s = (a.serialize_fmu_state)(c, st, bytes.as_mut_ptr() as _, size);
                i.free_state(st);
                s
            }
            "fmi2DeSerializeFMUstate" => {
                let bytes = i.serialize();
                let mut st = null_mut();
                let s = (a.deserialize_fmu_state)(c, bytes.as_ptr() as _, bytes.len(), &mut st);
                if !st.is_null() {
                    i.free_state(st);
                }
                s
            }
            "fmi2GetDirectionalDerivative" => {
                let dv = [1.0];
                (a.get_directional_derivative)(
                    c,
                    output.as_ptr(),
                    1,
                    input.as_ptr(),
                    1,
                    dv.as_ptr(),
                    real.as_mut_ptr(),
                )
            }
            "fmi2SetRealInputDerivatives" => {
                let slope = [0.0];
                (a.set_real_input_derivatives)(c, input.as_ptr(), 1, order.as_ptr(), slope.as_ptr())
            }
            "fmi2GetRealOutputDerivatives" => {
                (a.get_real_output_derivatives)(c, null(), 0, order.as_ptr(), real.as_mut_ptr())
            }
            "fmi2DoStep" => i.do_step(0.0, 1e-3),
            "fmi2CancelStep" => (a.cancel_step)(c),
            "fmi2GetStatus" => (a.get_status)(c, 0, int.as_mut_ptr()),
            "fmi2GetRealStatus" => (a.get_real_status)(c, 2, real.as_mut_ptr()),
            "fmi2GetIntegerStatus" => (a.get_integer_status)(c, 0, int.as_mut_ptr()),
            "fmi2GetBooleanStatus" => (a.get_boolean_status)(c, 3, int.as_mut_ptr()),
            "fmi2GetStringStatus" => (a.get_string_status)(c, 1, string.as_mut_ptr()),
            other => panic!("no probe for {other}"),
        }
    }
}

/// A fixture for [`check_state_table`]: an FMU that can be driven into
/// each of the states `S` of a state machine and called there.
pub trait StateProbe<S: Copy + PartialEq + std::fmt::Debug> {
    /// The FMU's name, for messages.
    fn name(&self) -> String;
    /// A fresh instance in `state`.
    fn instance_in(&self, state: S) -> Instance;
    /// `function` called on `i` with arguments valid apart from the state.
    fn call(&self, i: &Instance, function: &str) -> Status;
    /// The FMUs' word for `state` in their messages.
    fn state_word(&self, state: S) -> String;
    /// The rest of a normal run from `state`: every call must succeed.
    fn finish_run(&self, i: &Instance, state: S);
}

/// Every function of `table` (with the states of `states` in which the
/// standard allows it) called in every one of `states`: an allowed call
/// returns less than fmi2Error; any other returns fmi2Error, logs one
/// message naming the function, "not allowed in state" and the state, and
/// changes nothing (the run goes on from that state). The numbers of
/// refused and accepted calls.
pub fn check_state_table<S: Copy + PartialEq + std::fmt::Debug>(
    f: &impl StateProbe<S>,
    table: &[(&str, &[S])],
    states: &[S],
) -> (usize, usize) {
    let (mut refused, mut accepted) = (0, 0);
    let name = f.name();
    for (function, allowed) in table {
        for &state in states {
            let i = f.instance_in(state);
            let status = f.call(&i, function);
            let context = format!("{name}: {function} in {state:?}");
            if allowed.contains(&state) {
                assert!(
                    status < ERROR,
                    "{context} is allowed but returned {status}: {:?}",
                    i.log.take_errors()
                );
                accepted += 1;
            } else {
                assert_eq!(status, ERROR, "{context} must be refused");
                let word = f.state_word(state);
                assert_logged(&i, &context, &[function, "not allowed in state", &word]);
                f.finish_run(&i, state);
                refused += 1;
            }
        }
    }
    (refused, accepted)
}

// ---- the shipped FMUs ------------------------------------------------------

/// The FMUs `build-fmu.sh` writes into `dist/`: the one list of them,
/// `modelDescription/shipped.txt` (rendered from the registries; checked
/// against them by fmu-packager's tests).
pub static SHIPPED: std::sync::LazyLock<Vec<&'static str>> =
    std::sync::LazyLock::new(|| shipped_where(|_| true));

/// The shipped FMUs offered for Model Exchange too.
pub static SHIPPED_MODEL_EXCHANGE: std::sync::LazyLock<Vec<&'static str>> =
    std::sync::LazyLock::new(|| shipped_where(|interfaces| interfaces.contains(&"me")));

/// The names of `modelDescription/shipped.txt` whose interfaces pass `keep`.
fn shipped_where(keep: impl Fn(&[&str]) -> bool) -> Vec<&'static str> {
    let path = repository().join("modelDescription").join("shipped.txt");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let text: &'static str = Box::leak(text.into_boxed_str());
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .filter_map(|l| {
            let fields: Vec<&str> = l.split_whitespace().collect();
            keep(fields.get(2..).unwrap_or(&[])).then_some(fields[0])
        })
        .collect()
}

/// A shipped FMU unpacked by the host's importer and its binary loaded.
pub struct Loaded {
    pub model: Model,
    pub api: Api,
    pub me_api: MeApi,
    /// The `modelIdentifier` of its `ModelExchange` element, if it has one.
    pub model_exchange: Option<String>,
    _library: libloading::Library,
    _dir: tempfile::TempDir,
}

/// The repository root.
pub fn repository() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap()
}

/// Unpack `dist/<name>.fmu` and load its binary (run `./build-fmu.sh` first).
pub fn load_shipped(name: &str) -> Loaded {
    let fmu = repository().join("dist").join(format!("{name}.fmu"));
    assert!(
        fmu.is_file(),
        "{} is missing: run ./build-fmu.sh first",
        fmu.display()
    );
    let dir = fricsim_fmi::archive::unpack(&fmu, &Default::default()).unwrap();
    let md =
        fricsim_fmi::ModelDescription::from_file(&dir.path().join("modelDescription.xml")).unwrap();
    let identifier = &md.co_simulation.model_identifier;
    let so = dir
        .path()
        .join("binaries/linux64")
        .join(format!("{identifier}.so"));
    // SAFETY: our own FMU binary.
    let library = unsafe { libloading::Library::new(&so) }.unwrap();
    // SAFETY: an FMI 2.0 binary, kept loaded in `Loaded` with the tables.
    let (api, me_api) = unsafe { (Api::load(&library), MeApi::load(&library)) };
    let (api, me_api) = match (api, me_api) {
        (Ok(api), Ok(me_api)) => (api, me_api),
        (api, me_api) => panic!(
            "{}: missing {:?} {:?}",
            so.display(),
            api.err(),
            me_api.err()
        ),
    };
    for symbol in Api::OPTIONAL {
        assert!(api.exports(symbol), "{}: {symbol} missing", so.display());
    }
    Loaded {
        model: Model::from_description(&md),
        api,
        me_api,
        model_exchange: md.model_exchange.clone(),
        _library: library,
        _dir: dir,
    }
}

impl Loaded {
    pub fn instance(&self, name: &str) -> Instance {
        Instance::new(self.api, name, &self.model.guid, false)
            .unwrap_or_else(|log| panic!("fmi2Instantiate failed: {:?}", log.take()))
    }
}

// ---- a seeded generator (no dependency, same stream everywhere) -----------

/// SplitMix64.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }
    pub fn bytes(&mut self, n: usize) -> Vec<u8> {
        (0..n).map(|_| self.next_u64() as u8).collect()
    }
}
