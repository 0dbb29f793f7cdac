// A small safe driver over the exported FMI 2.0 C functions of an FMU
// library, for tests that go through the real C ABI in process. Included
// (`include!`) by a test's `common` module, which first generates the
// exports with `fmi_export::export_fmi2!`, re-exports them (`pub use
// fmi2_exports::*`) and defines `fn models() -> Vec<&'static ModelInfo>`.

use fmi_export::ffi::*;
use fmi_export::{VarType, Variable};
use std::cell::RefCell;
use std::ffi::{c_void, CStr, CString};
use std::os::raw::{c_char, c_int};
use std::ptr::{null, null_mut};

thread_local! {
    pub static LOG: RefCell<Vec<(i32, String)>> = const { RefCell::new(Vec::new()) };
}

extern "C" fn record(
    _e: *mut c_void,
    _n: *const c_char,
    status: c_int,
    _c: *const c_char,
    message: *const c_char,
) {
    // SAFETY: the FMU passes NUL-terminated strings.
    let m = unsafe { CStr::from_ptr(message) }
        .to_string_lossy()
        .into_owned();
    LOG.with(|l| l.borrow_mut().push((status, m)));
}

pub fn last_error() -> String {
    LOG.with(|l| {
        l.borrow()
            .iter()
            .rev()
            .find(|(s, _)| *s >= 3)
            .map(|(_, m)| m.clone())
            .unwrap_or_default()
    })
}

pub fn callbacks() -> &'static fmi2CallbackFunctions {
    callbacks_logging_to(record)
}

/// The importer's callbacks with `log` as the logger (no memory functions).
pub fn callbacks_logging_to(
    log: extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char),
) -> &'static fmi2CallbackFunctions {
    // SAFETY: a five-argument non-variadic function called through the
    // variadic pointer type with no variadic arguments (as ctypes importers do).
    let logger = unsafe {
        std::mem::transmute::<
            *const (),
            unsafe extern "C" fn(*mut c_void, fmi2String, c_int, fmi2String, fmi2String, ...),
        >(log as *const ())
    };
    Box::leak(Box::new(fmi2CallbackFunctions {
        logger: Some(logger),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: null_mut(),
    }))
}

pub struct Fmu {
    pub c: fmi2Component,
    pub model: &'static str,
    pub variables: &'static [Variable],
    pub t: f64,
}

pub const OK: fmi2Status = fmi2Status::fmi2OK;

/// `fmi2Instantiate` of `model` for `fmu_type` with the recording logger:
/// the instance (NULL if refused, the reason in the log) and the model's
/// description.
pub fn instantiate(model: &str, fmu_type: fmi2Type) -> (fmi2Component, &'static fmi_export::ModelInfo) {
    let info = models()
        .into_iter()
        .find(|m| m.model_name == model)
        .expect("model");
    let guid = CString::new(info.guid).unwrap();
    // SAFETY: valid strings and callbacks that live for the process.
    let c = unsafe {
        fmi2Instantiate(
            c"test".as_ptr(),
            fmu_type,
            guid.as_ptr(),
            null(),
            callbacks(),
            0,
            0,
        )
    };
    (c, info)
}

impl Fmu {
    /// Instantiate `model`, set `params` (by name; booleans and integers as
    /// f64) and leave it in initialization mode.
    pub fn instantiated(model: &'static str, params: &[(&str, f64)]) -> Fmu {
        let (c, info) = instantiate(model, fmi2CoSimulation);
        assert!(!c.is_null());
        let fmu = Fmu {
            c,
            model,
            variables: info.variables,
            t: 0.0,
        };
        unsafe {
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
            assert_eq!(fmi2EnterInitializationMode(c), OK);
        }
        for (name, value) in params {
            assert_eq!(
                fmu.set_any(name, *value),
                OK,
                "{model}.{name} = {value}: {}",
                last_error()
            );
        }
        fmu
    }

    pub fn new(model: &'static str, params: &[(&str, f64)]) -> Fmu {
        let fmu = Fmu::instantiated(model, params);
        assert_eq!(
            unsafe { fmi2ExitInitializationMode(fmu.c) },
            OK,
            "{}",
            last_error()
        );
        fmu
    }

    pub fn var(&self, name: &str) -> &'static Variable {
        self.variables
            .iter()
            .find(|v| v.name == name)
            .unwrap_or_else(|| panic!("{} has no {name}", self.model))
    }

    pub fn set_any(&self, name: &str, value: f64) -> fmi2Status {
        let v = self.var(name);
        unsafe {
            match v.var_type {
                VarType::Real => fmi2SetReal(self.c, &v.vr, 1, &value),
                VarType::Integer => fmi2SetInteger(self.c, &v.vr, 1, &(value as i32)),
                VarType::Boolean => fmi2SetBoolean(self.c, &v.vr, 1, &((value != 0.0) as i32)),
            }
        }
    }

    pub fn set(&self, name: &str, value: f64) {
        assert_eq!(self.set_any(name, value), OK, "{}", last_error());
    }

    pub fn get(&self, name: &str) -> f64 {
        let v = self.var(name);
        let mut x = f64::NAN;
        assert_eq!(
            unsafe { fmi2GetReal(self.c, &v.vr, 1, &mut x) },
            OK,
            "{}",
            last_error()
        );
        x
    }

    /// The value of `name` of any type, as f64.
    pub fn get_any(&self, name: &str) -> f64 {
        let v = self.var(name);
        let status = unsafe {
            match v.var_type {
                VarType::Real => {
                    let mut x = f64::NAN;
                    (fmi2GetReal(self.c, &v.vr, 1, &mut x), x)
                }
                VarType::Integer => {
                    let mut x = 0;
                    (fmi2GetInteger(self.c, &v.vr, 1, &mut x), x as f64)
                }
                VarType::Boolean => {
                    let mut x = 0;
                    (fmi2GetBoolean(self.c, &v.vr, 1, &mut x), x as f64)
                }
            }
        };
        assert_eq!(status.0, OK, "{}", last_error());
        status.1
    }

    pub fn set_slope(&self, name: &str, slope: f64) {
        let v = self.var(name);
        assert_eq!(
            unsafe { fmi2SetRealInputDerivatives(self.c, &v.vr, 1, &1, &slope) },
            OK,
            "{}",
            last_error()
        );
    }

    pub fn step(&mut self, h: f64) {
        assert_eq!(
            unsafe { fmi2DoStep(self.c, self.t, h, 0) },
            OK,
            "{}",
            last_error()
        );
        self.t += h;
    }

    pub fn state(&self) -> fmi2FMUstate {
        let mut s = null_mut();
        assert_eq!(unsafe { fmi2GetFMUstate(self.c, &mut s) }, OK);
        s
    }

    pub fn restore(&mut self, s: fmi2FMUstate, t: f64) {
        assert_eq!(
            unsafe { fmi2SetFMUstate(self.c, s) },
            OK,
            "{}",
            last_error()
        );
        self.t = t;
    }

    pub fn serialize(&self, s: fmi2FMUstate) -> Vec<c_char> {
        let mut size = 0;
        unsafe {
            assert_eq!(fmi2SerializedFMUstateSize(self.c, s, &mut size), OK);
            let mut bytes = vec![0 as c_char; size];
            assert_eq!(
                fmi2SerializeFMUstate(self.c, s, bytes.as_mut_ptr(), size),
                OK
            );
            bytes
        }
    }

    pub fn deserialize(&self, bytes: &[c_char]) -> fmi2FMUstate {
        let mut s = null_mut();
        assert_eq!(
            unsafe { fmi2DeSerializeFMUstate(self.c, bytes.as_ptr(), bytes.len(), &mut s) },
            OK,
            "{}",
            last_error()
        );
        s
    }

    pub fn directional_derivative(&self, output: &str, input: &str) -> f64 {
        let (o, i) = (self.var(output).vr, self.var(input).vr);
        let mut d = f64::NAN;
        assert_eq!(
            unsafe { fmi2GetDirectionalDerivative(self.c, &o, 1, &i, 1, &1.0, &mut d) },
            OK,
            "{}",
            last_error()
        );
        d
    }

    /// From the current state: (J, FD) for a step of `h` with `input` held
    /// at its current value. J is the FMU's ∂output/∂input right after that
    /// step; FD the central difference computed outside the FMU by rolling
    /// back with fmi2SetFMUstate, δ = 1e-5·max(|u|, nominal). Leaves the FMU
    /// after the unperturbed step.
    pub fn step_sensitivity(&mut self, output: &str, input: &str, h: f64) -> (f64, f64) {
        let (t0, s0) = (self.t, self.state());
        let u0 = self.get(input);
        let delta = 1e-5 * u0.abs().max(self.var(input).nominal.unwrap_or(1.0));
        let mut f_at = |u: f64| {
            self.restore(s0, t0);
            self.set(input, u);
            self.step(h);
            self.get(output)
        };
        let fd = (f_at(u0 + delta) - f_at(u0 - delta)) / (2.0 * delta);
        self.restore(s0, t0);
        self.set(input, u0);
        self.step(h);
        (self.directional_derivative(output, input), fd)
    }

    /// From the current state, with the inputs (and slopes) as set: a
    /// step of `h`, then (J, FD): J the FMU's ∂output/∂input right after
    /// it, FD the layer's central differences of that step written out
    /// here (rolled back with fmi2SetFMUstate, `input` moved from its value
    /// before the step by ±ε, ε = 1e-6·max(|u|, nominal) of its value u
    /// after the step, stepped, `output` read): what the layer answers
    /// where the model gives no step sensitivity. Leaves the FMU after the
    /// unperturbed step.
    pub fn step_derivative_and_differences(
        &mut self,
        output: &str,
        input: &str,
        h: f64,
    ) -> (f64, f64) {
        let (t0, s0) = (self.t, self.state());
        let u0 = self.get(input);
        self.step(h);
        let j = self.directional_derivative(output, input);
        let nominal = self.var(input).nominal.unwrap_or(1.0);
        let eps = 1e-6 * self.get(input).abs().max(nominal);
        let mut y_at = |e: f64| {
            self.restore(s0, t0);
            self.set(input, u0 + e);
            self.step(h);
            self.get(output)
        };
        let fd = (y_at(eps) - y_at(-eps)) / (2.0 * eps);
        self.restore(s0, t0);
        self.set(input, u0);
        self.step(h);
        (j, fd)
    }

    pub fn output_derivative(&self, output: &str) -> f64 {
        let o = self.var(output).vr;
        let mut d = f64::NAN;
        assert_eq!(
            unsafe { fmi2GetRealOutputDerivatives(self.c, &o, 1, &1, &mut d) },
            OK,
            "{}",
            last_error()
        );
        d
    }

    pub fn exit_initialization(&self) -> fmi2Status {
        unsafe { fmi2ExitInitializationMode(self.c) }
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        unsafe { fmi2FreeInstance(self.c) };
    }
}

/// `run(fmu, steps, h, record)` drives a model and appends output bits.
pub type Recorder = fn(&mut Fmu, usize, f64, &mut Vec<u64>);

/// Run 300 steps of 1e-3, save the FMU state (in memory and serialized),
/// run 500 more recording every output bit; the run again from the
/// restored state in the same instance, and from the deserialized state in
/// a fresh instance, must record the same bits, and the run must move.
pub fn assert_state_round_trip(model: &'static str, params: &[(&str, f64)], run: Recorder) {
    let mut a = Fmu::new(model, params);
    run(&mut a, 300, 1e-3, &mut Vec::new());
    let t_saved = a.t;
    let saved = a.state();
    let bytes = a.serialize(saved);
    let mut original = Vec::new();
    run(&mut a, 500, 1e-3, &mut original);

    // same instance, in-memory state
    a.restore(saved, t_saved);
    let mut again = Vec::new();
    run(&mut a, 500, 1e-3, &mut again);
    assert_eq!(original, again, "{model}: in-memory state");

    // fresh instance, serialized state
    let mut b = Fmu::new(model, params);
    let s = b.deserialize(&bytes);
    b.restore(s, t_saved);
    let mut fresh = Vec::new();
    run(&mut b, 500, 1e-3, &mut fresh);
    assert_eq!(
        original, fresh,
        "{model}: serialized state in a new instance"
    );
    // the continuation really moves
    assert!(
        original.windows(2).any(|w| w[0] != w[1]),
        "{model}: nothing changed"
    );
}

/// Instantiate `model` with the invalid parameters `bad`:
/// fmi2ExitInitializationMode must return fmi2Error and log a message
/// naming itself and containing `needle` (the parameter and its value).
/// Returns the instance, still in initialization mode.
pub fn refused_at_initialization(model: &'static str, bad: &[(&str, f64)], needle: &str) -> Fmu {
    let fmu = Fmu::instantiated(model, bad);
    assert_eq!(
        fmu.exit_initialization(),
        fmi2Status::fmi2Error,
        "{model} {bad:?}"
    );
    let m = last_error();
    assert!(
        m.contains("fmi2ExitInitializationMode") && m.contains(needle),
        "{model}: {m}"
    );
    fmu
}

/// `model` with every value of `bad` but the last set (each accepted), and
/// the last refused when set, outside the bounds the model description
/// declares: `fmi2Error`, a message with `needle`, the value unchanged.
pub fn refused_when_set(model: &'static str, bad: &[(&str, f64)], needle: &str) -> Fmu {
    let (last, first) = bad.split_last().expect("a value to refuse");
    let fmu = Fmu::instantiated(model, first);
    let v = fmu.var(last.0);
    let before = fmu.get_any(last.0);
    assert_eq!(
        fmu.set_any(last.0, last.1),
        fmi2Status::fmi2Error,
        "{model} {bad:?}"
    );
    let m = last_error();
    assert!(
        m.starts_with("fmi2Set") && m.contains(needle) && m.contains("declared"),
        "{model}: {m}"
    );
    assert_eq!(fmu.get_any(last.0), before, "{model}.{}", v.name);
    fmu
}
