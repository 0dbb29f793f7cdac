//! An imported FMU ([`Fmu`]: unpacked files, model description, loaded
//! binary) and its instances ([`Instance`]: the FMI 2.0 Co-Simulation API of
//! FMI 2.0.4 §2.1 and §4.2 as safe methods, each a call through FMI 2.0's
//! raw table, [`crate::fmi2::Functions`], with the checks around it).
//!
//! Every FMU call returns `Result<Status, FmuError>`: `fmi2OK` and
//! `fmi2Warning` are `Ok` (a warning is in the log), `fmi2Discard`,
//! `fmi2Error`, `fmi2Fatal` and `fmi2Pending` become [`FmuError::Call`] with
//! the function, the instance, the status and what the instance logged during
//! the call. Slice lengths are checked before the FMU sees a pointer. The
//! value-access and step functions do not allocate unless they fail.

use super::archive::{unpack, UnpackOptions};
use super::guard::{c_string, not_supported, same_length, Guard};
use super::instance3::Fmi3Instance;
use super::library::{c_text, Api, Declared, Library};
use super::logger::{fricsim_fmi2_logger, Log, Sink};
use super::model_description::{ModelDescription, ScalarVariable, ValueReference};
use super::Status;
use crate::blackbox::CallRecorder;
use crate::error::FmuError;
use crate::fmi2::*;
use std::mem::ManuallyDrop;
use std::os::raw::c_void;
use std::path::{Path, PathBuf};
use std::ptr::null_mut;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tempfile::TempDir;

/// The name of `fmi2DoStep` in errors (both halves of [`Instance::do_step`]).
const DO_STEP: &str = "fmi2DoStep";
/// Booleans are converted to `fmi2Boolean` through a stack buffer this long.
const BOOLEAN_CHUNK: usize = 64;

extern "C" {
    fn calloc(count: usize, size: usize) -> *mut c_void;
    fn free(pointer: *mut c_void);
}

unsafe extern "C" fn allocate_memory(count: usize, size: usize) -> *mut c_void {
    // SAFETY: C's calloc, as §2.1.5 asks of allocateMemory.
    unsafe { calloc(count, size) }
}

unsafe extern "C" fn free_memory(pointer: *mut c_void) {
    // SAFETY: `pointer` came from `allocate_memory` (or is null).
    unsafe { free(pointer) }
}

/// An imported FMU. Cloning is cheap and shares everything; the unpacked
/// files and the binary stay until the last clone and instance are dropped.
#[derive(Clone, Debug)]
pub struct Fmu {
    shared: Arc<Shared>,
}

#[derive(Debug)]
struct Shared {
    // Dropped in this order: the binary is unloaded before its files go.
    library: Library,
    description: ModelDescription,
    log: Log,
    dir: FmuDir,
}

#[derive(Debug)]
enum FmuDir {
    /// Unpacked by us; removed on drop.
    Temporary(TempDir),
    /// Given by the caller; left alone.
    External(PathBuf),
}

impl FmuDir {
    fn path(&self) -> &Path {
        match self {
            FmuDir::Temporary(t) => t.path(),
            FmuDir::External(p) => p,
        }
    }
}

impl Fmu {
    /// Unpack the `.fmu` at `path` with the default limits (only what
    /// running it reads: [`UnpackOptions::skip_unused`]), parse its model
    /// description and load its binary.
    pub fn open(path: impl AsRef<Path>) -> Result<Fmu, FmuError> {
        let options = UnpackOptions {
            skip_unused: true,
            ..UnpackOptions::default()
        };
        Fmu::open_with(path, &options)
    }

    /// [`Fmu::open`] with explicit unpacking limits. A refused model
    /// description or binary is reported as [`FmuError::InFmu`], naming
    /// the archive (archive errors name it already).
    pub fn open_with(path: impl AsRef<Path>, options: &UnpackOptions) -> Result<Fmu, FmuError> {
        let dir = unpack(path.as_ref(), options)?;
        Fmu::load(FmuDir::Temporary(dir)).map_err(|e| FmuError::InFmu {
            path: path.as_ref().to_path_buf(),
            source: Box::new(e),
        })
    }

    /// An FMU already unpacked in `dir` (not removed on drop).
    pub fn from_dir(dir: impl AsRef<Path>) -> Result<Fmu, FmuError> {
        Fmu::load(FmuDir::External(dir.as_ref().to_path_buf()))
    }

    fn load(dir: FmuDir) -> Result<Fmu, FmuError> {
        let description = ModelDescription::from_file(&dir.path().join("modelDescription.xml"))?;
        let library = Library::load(dir.path(), &description)?;
        Ok(Fmu {
            shared: Arc::new(Shared {
                library,
                description,
                log: Log::new(),
                dir,
            }),
        })
    }

    pub fn description(&self) -> &ModelDescription {
        &self.shared.description
    }

    /// The variable called `name` (look it up once, then use its
    /// `value_reference`).
    pub fn variable(&self, name: &str) -> Result<&ScalarVariable, FmuError> {
        self.shared.description.variable(name)
    }

    /// The messages of all instances of this FMU.
    pub fn log(&self) -> &Log {
        &self.shared.log
    }

    /// Where the FMU is unpacked.
    pub fn dir(&self) -> &Path {
        self.shared.dir.path()
    }

    pub fn library(&self) -> &Library {
        &self.shared.library
    }

    /// A new co-simulation instance called `name` of an FMI 2.0 FMU (see
    /// [`Instance::instantiate`]).
    pub fn instantiate(&self, name: &str) -> Result<Instance, FmuError> {
        Instance::instantiate(self, name)
    }

    /// A new co-simulation instance called `name` of an FMI 3.0 FMU (see
    /// [`Fmi3Instance::instantiate`]).
    pub fn instantiate_fmi3(&self, name: &str) -> Result<Fmi3Instance, FmuError> {
        Fmi3Instance::instantiate(self, name)
    }
}

/// A snapshot of an instance's state (`fmi2FMUstate`, §2.1.8). It belongs to
/// the instance that made it, which frees it with
/// [`Instance::free_state`] or when the instance is dropped.
#[derive(Debug)]
pub struct FmuState {
    pointer: *mut c_void,
    owner: u64,
}

impl FmuState {
    pub(crate) fn new(pointer: *mut c_void, owner: u64) -> FmuState {
        FmuState { pointer, owner }
    }

    pub(crate) fn pointer(&self) -> *mut c_void {
        self.pointer
    }

    pub(crate) fn set_pointer(&mut self, pointer: *mut c_void) {
        self.pointer = pointer;
    }

    /// The id of the instance that made it.
    pub(crate) fn owner(&self) -> u64 {
        self.owner
    }
}

/// Whether a master may restore a state saved before the end of the step
/// it asks for ([`Instance::do_step_with`]):
/// `noSetFMUStatePriorToCurrentPoint` of `fmi2DoStep` is true for `Never`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rollback {
    /// The step may be undone (`fmi2SetFMUstate` to an earlier state): an
    /// iterating master's steps.
    Possible,
    /// The step is final: no state from before its end is restored.
    Never,
}

static NEXT_INSTANCE_ID: AtomicU64 = AtomicU64::new(1);

/// A new instance id, unique in the process (of either FMI version).
pub(crate) fn next_instance_id() -> u64 {
    NEXT_INSTANCE_ID.fetch_add(1, Ordering::Relaxed)
}

/// One FMU instance in co-simulation mode. Dropping it frees its states and
/// calls `fmi2FreeInstance` — unless a call returned `fmi2Fatal`, after which
/// §2.1.3 allows no further call and the instance is leaked.
pub struct Instance {
    /// FMI 2.0's raw table, copied from the library: each call is one
    /// indirect call through it.
    functions: Functions,
    /// The optional groups the FMU declares: the others are refused.
    declared: Declared,
    component: fmi2Component,
    /// What every call goes through (logging, statuses, time limit, black
    /// box), shared with FMI 3.0's instance; it holds the logger's sink.
    guard: Guard,
    /// The callbacks: the FMU may keep a pointer to them until it is freed
    /// (and forever after `fmi2Fatal`).
    callbacks: ManuallyDrop<Box<CallbackFunctions>>,
    states: Vec<fmi2FMUstate>,
}

impl std::fmt::Debug for Instance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Instance")
            .field("name", &self.guard.name)
            .field("model", &self.guard.fmu.description().model_name)
            .field("states", &self.states.len())
            .field("fatal", &self.guard.fatal)
            .finish_non_exhaustive()
    }
}

/// `file:///…` URI of a directory (§2.1.5 `fmuResourceLocation`), with
/// every byte outside the unreserved set and `/` percent-encoded.
fn file_uri(path: &Path) -> String {
    use std::os::unix::ffi::OsStrExt;
    let mut uri = String::from("file://");
    for &b in path.as_os_str().as_bytes() {
        if b.is_ascii_alphanumeric() || b"/-._~".contains(&b) {
            uri.push(b as char);
        } else {
            uri.push_str(&format!("%{b:02X}"));
        }
    }
    uri
}

impl Instance {
    /// `fmi2Instantiate` in co-simulation mode, not visible, with debug
    /// logging off (errors are still logged; see [`Instance::set_debug_logging`]).
    pub fn instantiate(fmu: &Fmu, name: &str) -> Result<Instance, FmuError> {
        let description = fmu.description();
        let name_c = c_string("the instance name", name)?;
        let guid = c_string("the GUID", &description.guid)?;
        let resources = c_string(
            "the resource location",
            &file_uri(&fmu.dir().join("resources")),
        )?;
        let id = next_instance_id();
        let sink = Box::new(Sink::new(fmu.log().clone(), name, id));
        let callbacks = Box::new(CallbackFunctions {
            logger: Some(fricsim_fmi2_logger),
            allocate_memory: Some(allocate_memory),
            free_memory: Some(free_memory),
            step_finished: None,
            component_environment: &*sink as *const Sink as *mut c_void,
        });
        let Api::Fmi2(functions) = fmu.shared.library.api else {
            return Err(FmuError::WrongInstanceType {
                model: description.model_name.clone(),
                fmi_version: description.fmi_version.clone(),
            });
        };
        let declared = fmu.shared.library.declared;
        // SAFETY: all strings are NUL-terminated and outlive the call; the
        // callbacks and their environment live as long as the instance.
        let component = unsafe {
            (functions.instantiate)(
                name_c.as_ptr(),
                fmi2CoSimulation,
                guid.as_ptr(),
                resources.as_ptr(),
                &*callbacks,
                fmi2False,
                fmi2False,
            )
        };
        if component.is_null() {
            return Err(FmuError::Instantiate {
                instance: name.to_string(),
                messages: fmu.log().messages_since(&sink, 0, 0),
            });
        }
        Ok(Instance {
            functions,
            declared,
            component,
            guard: Guard::new(fmu, name, id, sink),
            callbacks: ManuallyDrop::new(callbacks),
            states: Vec::new(),
        })
    }

    pub fn name(&self) -> &str {
        &self.guard.name
    }

    /// A count that moves with every call that may change a value of the
    /// instance (every FMI call but the `fmi2Get…` ones): while it stands
    /// still, `fmi2GetReal` answers as it did, and a value read since can
    /// be used again instead of asking the FMU once more.
    pub fn changes(&self) -> u64 {
        self.guard.changes
    }

    pub fn fmu(&self) -> &Fmu {
        &self.guard.fmu
    }

    /// A time limit on every later FMI call of this instance (`None`: no
    /// limit). A call that returns after the limit fails with
    /// [`FmuError::TimeLimit`], and a watchdog reports a call still running
    /// past it on stderr; a running call is never interrupted (see
    /// [`super::watchdog`]).
    pub fn set_call_time_limit(&mut self, limit: Option<Duration>) {
        self.guard.set_call_time_limit(limit);
    }

    /// Record every later FMI call of this instance in an isolated run's
    /// black box (`None`: no longer), so that the parent process can name
    /// the call the FMU crashed or hung in ([`crate::blackbox`]).
    pub fn set_black_box(&mut self, recorder: Option<CallRecorder>) {
        self.guard.set_black_box(recorder);
    }

    #[inline(always)]
    fn begin(&mut self, function: &'static str) -> Result<u64, FmuError> {
        self.guard.begin(function)
    }

    #[inline(always)]
    fn finish(
        &mut self,
        function: &'static str,
        mark: u64,
        raw: fmi2Status,
    ) -> Result<Status, FmuError> {
        self.guard.finish(function, mark, raw)
    }

    /// One FMI call through the guard ([`Guard::call`]) on this instance's
    /// component.
    #[inline(always)]
    fn call(
        &mut self,
        function: &'static str,
        ffi: impl FnOnce(fmi2Component) -> Result<fmi2Status, FmuError>,
    ) -> Result<Status, FmuError> {
        self.guard.call(function, self.component, ffi)
    }

    /// `fmi2SetDebugLogging`: switch the named log categories (all if empty).
    pub fn set_debug_logging(&mut self, on: bool, categories: &[&str]) -> Result<Status, FmuError> {
        const F: &str = "fmi2SetDebugLogging";
        let mark = self.begin(F)?;
        let owned = categories
            .iter()
            .map(|c| c_string("a log category", c))
            .collect::<Result<Vec<_>, _>>()?;
        let pointers: Vec<fmi2String> = owned.iter().map(|c| c.as_ptr()).collect();
        let on = if on { fmi2True } else { fmi2False };
        // SAFETY: `pointers` holds `len` valid strings for the call.
        let raw = unsafe {
            (self.functions.set_debug_logging)(
                self.component,
                on,
                pointers.len(),
                pointers.as_ptr(),
            )
        };
        self.finish(F, mark, raw)
    }

    /// `fmi2SetupExperiment` without tolerance; `stop` = `None` leaves the
    /// stop time undefined.
    pub fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Result<Status, FmuError> {
        const F: &str = "fmi2SetupExperiment";
        let mark = self.begin(F)?;
        let (stop_defined, stop) = match stop {
            Some(s) => (fmi2True, s),
            None => (fmi2False, 0.0),
        };
        // SAFETY: plain values.
        let raw = unsafe {
            (self.functions.setup_experiment)(
                self.component,
                fmi2False,
                0.0,
                start,
                stop_defined,
                stop,
            )
        };
        self.finish(F, mark, raw)
    }

    fn component_call(
        &mut self,
        function: &'static str,
        f: impl FnOnce(fmi2Component) -> fmi2Status,
    ) -> Result<Status, FmuError> {
        let mark = self.begin(function)?;
        let raw = f(self.component);
        self.finish(function, mark, raw)
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization_mode(&mut self) -> Result<Status, FmuError> {
        let f = self.functions.enter_initialization_mode;
        // SAFETY: the component is live.
        self.component_call("fmi2EnterInitializationMode", |c| unsafe { f(c) })
    }

    /// `fmi2ExitInitializationMode`.
    pub fn exit_initialization_mode(&mut self) -> Result<Status, FmuError> {
        let f = self.functions.exit_initialization_mode;
        // SAFETY: the component is live.
        self.component_call("fmi2ExitInitializationMode", |c| unsafe { f(c) })
    }

    /// `fmi2Terminate`.
    pub fn terminate(&mut self) -> Result<Status, FmuError> {
        let f = self.functions.terminate;
        // SAFETY: the component is live.
        self.component_call("fmi2Terminate", |c| unsafe { f(c) })
    }

    /// `fmi2Reset`: back to the state after instantiation.
    pub fn reset(&mut self) -> Result<Status, FmuError> {
        let f = self.functions.reset;
        // SAFETY: the component is live.
        let status = self.component_call("fmi2Reset", |c| unsafe { f(c) })?;
        self.guard.failed = false;
        Ok(status)
    }

    /// Whether a call has returned `fmi2Error` or `fmi2Fatal` since
    /// instantiation or the last successful `fmi2Reset`: the instance is
    /// then in FMI 2.0's error state, where `fmi2Terminate` is not allowed
    /// (only `fmi2Reset` and `fmi2FreeInstance`).
    pub fn has_failed(&self) -> bool {
        self.guard.failed
    }

    /// `fmi2CancelStep` (§4.2.2).
    pub fn cancel_step(&mut self) -> Result<Status, FmuError> {
        let f = self.functions.cancel_step;
        // SAFETY: the component is live.
        self.component_call("fmi2CancelStep", |c| unsafe { f(c) })
    }

    /// `fmi2GetReal`: `values[i]` = value of `vrs[i]`. Does not allocate.
    #[inline] // a hot path of every master
    pub fn get_real(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [f64],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi2GetReal";
        let f = self.functions.get_real;
        self.call(F, |component| {
            same_length(F, "values", vrs.len(), values.len())?;
            // SAFETY: both arrays hold `vrs.len()` elements.
            Ok(unsafe { f(component, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()) })
        })
    }

    /// `fmi2SetReal`. Does not allocate.
    #[inline] // a hot path of every master
    pub fn set_real(&mut self, vrs: &[ValueReference], values: &[f64]) -> Result<Status, FmuError> {
        const F: &str = "fmi2SetReal";
        let f = self.functions.set_real;
        self.call(F, |component| {
            same_length(F, "values", vrs.len(), values.len())?;
            // SAFETY: both arrays hold `vrs.len()` elements.
            Ok(unsafe { f(component, vrs.as_ptr(), vrs.len(), values.as_ptr()) })
        })
    }

    /// `fmi2GetInteger`. Does not allocate (a recorded Integer output is
    /// read at every step: the path of [`Instance::get_real`]).
    #[inline]
    pub fn get_integer(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [i32],
    ) -> Result<Status, FmuError> {
        let f = self.functions.get_integer;
        self.get_c_ints("fmi2GetInteger", f, vrs, values)
    }

    /// `fmi2GetBoolean` into `fmi2Boolean`s as the FMU writes them (0 is
    /// false, anything else true). Does not allocate (a recorded Boolean
    /// output is read at every step: the path of [`Instance::get_real`]).
    #[inline]
    pub fn get_boolean_raw(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [fmi2Boolean],
    ) -> Result<Status, FmuError> {
        let f = self.functions.get_boolean;
        self.get_c_ints("fmi2GetBoolean", f, vrs, values)
    }

    /// `fmi2GetInteger` or `fmi2GetBoolean` (`function`, `f`): both write
    /// C ints, and have one signature.
    #[inline(always)]
    fn get_c_ints(
        &mut self,
        function: &'static str,
        f: fmi2GetIntegerTYPE,
        vrs: &[ValueReference],
        values: &mut [i32],
    ) -> Result<Status, FmuError> {
        self.call(function, |component| {
            same_length(function, "values", vrs.len(), values.len())?;
            // SAFETY: both arrays hold `vrs.len()` elements.
            Ok(unsafe { f(component, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()) })
        })
    }

    /// `fmi2SetInteger`. Does not allocate.
    pub fn set_integer(
        &mut self,
        vrs: &[ValueReference],
        values: &[i32],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi2SetInteger";
        let mark = self.begin(F)?;
        same_length(F, "values", vrs.len(), values.len())?;
        // SAFETY: both arrays hold `vrs.len()` elements.
        let raw = unsafe {
            (self.functions.set_integer)(self.component, vrs.as_ptr(), vrs.len(), values.as_ptr())
        };
        self.finish(F, mark, raw)
    }

    /// `fmi2GetBoolean`. Does not allocate (converts through a stack buffer).
    pub fn get_boolean(
        &mut self,
        vrs: &[ValueReference],
        values: &mut [bool],
    ) -> Result<Status, FmuError> {
        same_length("fmi2GetBoolean", "values", vrs.len(), values.len())?;
        let mut status = Status::Ok;
        for (vrs, values) in vrs
            .chunks(BOOLEAN_CHUNK)
            .zip(values.chunks_mut(BOOLEAN_CHUNK))
        {
            let mut buffer = [fmi2False; BOOLEAN_CHUNK];
            let buffer = &mut buffer[..vrs.len()];
            status = worst(status, self.get_boolean_raw(vrs, buffer)?);
            for (value, &b) in values.iter_mut().zip(buffer.iter()) {
                *value = b != fmi2False;
            }
        }
        Ok(status)
    }

    /// `fmi2SetBoolean`. Does not allocate.
    pub fn set_boolean(
        &mut self,
        vrs: &[ValueReference],
        values: &[bool],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi2SetBoolean";
        let mark = self.begin(F)?;
        same_length(F, "values", vrs.len(), values.len())?;
        let mut status = Status::Ok;
        for (vrs, values) in vrs.chunks(BOOLEAN_CHUNK).zip(values.chunks(BOOLEAN_CHUNK)) {
            let mut buffer = [fmi2False; BOOLEAN_CHUNK];
            for (b, value) in buffer.iter_mut().zip(values) {
                *b = if *value { fmi2True } else { fmi2False };
            }
            // SAFETY: `vrs` and `buffer` hold at least `vrs.len()` elements.
            let raw = unsafe {
                (self.functions.set_boolean)(
                    self.component,
                    vrs.as_ptr(),
                    vrs.len(),
                    buffer.as_ptr(),
                )
            };
            status = worst(status, self.finish(F, mark, raw)?);
        }
        Ok(status)
    }

    /// `fmi2GetString`: the strings are copied out at once (the FMU's
    /// pointers are only valid until its next call).
    pub fn get_string(&mut self, vrs: &[ValueReference]) -> Result<Vec<String>, FmuError> {
        const F: &str = "fmi2GetString";
        let mark = self.begin(F)?;
        let mut pointers: Vec<fmi2String> = vec![std::ptr::null(); vrs.len()];
        // SAFETY: both arrays hold `vrs.len()` elements.
        let raw = unsafe {
            (self.functions.get_string)(
                self.component,
                vrs.as_ptr(),
                vrs.len(),
                pointers.as_mut_ptr(),
            )
        };
        self.finish(F, mark, raw)?;
        // SAFETY: the FMU returned NUL-terminated strings (or null).
        Ok(pointers.into_iter().map(|p| unsafe { c_text(p) }).collect())
    }

    /// `fmi2SetString`.
    pub fn set_string(
        &mut self,
        vrs: &[ValueReference],
        values: &[&str],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi2SetString";
        let mark = self.begin(F)?;
        same_length(F, "values", vrs.len(), values.len())?;
        let owned = values
            .iter()
            .map(|v| c_string("a string value", v))
            .collect::<Result<Vec<_>, _>>()?;
        let pointers: Vec<fmi2String> = owned.iter().map(|c| c.as_ptr()).collect();
        // SAFETY: both arrays hold `vrs.len()` elements, the strings outlive the call.
        let raw = unsafe {
            (self.functions.set_string)(self.component, vrs.as_ptr(), vrs.len(), pointers.as_ptr())
        };
        self.finish(F, mark, raw)
    }

    /// `fmi2DoStep` from communication point `t` over `h`, with
    /// `noSetFMUStatePriorToCurrentPoint = false`: the caller may still
    /// restore a state saved before `t + h` ([`Rollback::Possible`]; see
    /// [`Instance::do_step_with`]). Does not allocate unless it fails.
    ///
    /// `fmi2Discard` means the FMU completed only part of the step (§4.2.2).
    /// The error then also says how far it got and whether it wants
    /// the simulation to end, asked through `fmi2GetRealStatus
    /// (fmi2LastSuccessfulTime)` and `fmi2GetBooleanStatus(fmi2Terminated)`,
    /// or why the FMU could not say.
    #[inline]
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<Status, FmuError> {
        self.do_step_with(t, h, Rollback::Possible)
    }

    /// [`Instance::do_step`], telling the FMU whether a state from before
    /// the step's end may still be restored: `rollback` is
    /// `noSetFMUStatePriorToCurrentPoint` (FMI 2.0.4 §4.2.2), true for
    /// [`Rollback::Never`]. A master that only goes forward (Jacobi,
    /// Gauss–Seidel: FMPy's `simulate_fmu` passes true too) says
    /// `Never`, so that an FMU may drop what it keeps for rollbacks;
    /// one that iterates a step (`newton`) says `Possible`.
    #[inline] // the hot path is a few instructions; the rest is in `step_failed`
    pub fn do_step_with(&mut self, t: f64, h: f64, rollback: Rollback) -> Result<Status, FmuError> {
        self.guard.record_step_time(t);
        let f = self.functions.do_step;
        let no_set_prior = match rollback {
            Rollback::Possible => fmi2False,
            Rollback::Never => fmi2True,
        };
        match self.call(DO_STEP, |component| {
            // SAFETY: plain values.
            Ok(unsafe { f(component, t, h, no_set_prior) })
        }) {
            Err(e) => self.step_failed(e),
            ok => ok,
        }
    }

    /// [`Instance::do_step`] that failed: a discarded step explained.
    #[cold]
    #[inline(never)]
    fn step_failed(&mut self, mut e: FmuError) -> Result<Status, FmuError> {
        if let FmuError::Call {
            status: Status::Discard,
            messages,
            ..
        } = &mut e
        {
            messages.push(self.discard_report());
        }
        Err(e)
    }

    /// After `fmi2DoStep` returned `fmi2Discard`: how far the step got and
    /// whether the FMU asks to end the simulation, in words.
    fn discard_report(&mut self) -> String {
        let reached = match self.last_successful_time() {
            Ok(time) => {
                format!("the FMU completed the step only up to t = {time} (fmi2LastSuccessfulTime)")
            }
            Err(e) => format!("fmi2LastSuccessfulTime is not available ({e})"),
        };
        let terminated = match self.terminated() {
            Ok(true) => "it asks to end the simulation (fmi2Terminated = true)".to_string(),
            Ok(false) => "it does not ask to end the simulation (fmi2Terminated = false): the step could be retried with a smaller step from a saved FMU state".to_string(),
            Err(e) => format!("fmi2Terminated is not available ({e})"),
        };
        format!("{reached}; {terminated}")
    }

    /// `fmi2GetRealStatus(fmi2LastSuccessfulTime)`: where a discarded step stopped.
    pub fn last_successful_time(&mut self) -> Result<f64, FmuError> {
        const F: &str = "fmi2GetRealStatus";
        let mark = self.begin(F)?;
        let mut time = f64::NAN;
        // SAFETY: `time` is a valid out-pointer.
        let raw = unsafe {
            (self.functions.get_real_status)(self.component, fmi2LastSuccessfulTime, &mut time)
        };
        self.finish(F, mark, raw)?;
        Ok(time)
    }

    /// `fmi2GetBooleanStatus(fmi2Terminated)`: whether the FMU wants to stop.
    pub fn terminated(&mut self) -> Result<bool, FmuError> {
        const F: &str = "fmi2GetBooleanStatus";
        let mark = self.begin(F)?;
        let mut value = fmi2False;
        // SAFETY: `value` is a valid out-pointer.
        let raw = unsafe {
            (self.functions.get_boolean_status)(self.component, fmi2Terminated, &mut value)
        };
        self.finish(F, mark, raw)?;
        Ok(value != fmi2False)
    }

    /// `fmi2SetRealInputDerivatives` (§4.2.1): `values[i]` is the
    /// `orders[i]`-th time derivative of input `vrs[i]`.
    pub fn set_real_input_derivatives(
        &mut self,
        vrs: &[ValueReference],
        orders: &[i32],
        values: &[f64],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi2SetRealInputDerivatives";
        if !self.declared.input_derivatives {
            return Err(not_supported(F, "canInterpolateInputs=\"true\""));
        }
        let f = self.functions.set_real_input_derivatives;
        let mark = self.begin(F)?;
        same_length(F, "orders", vrs.len(), orders.len())?;
        same_length(F, "values", vrs.len(), values.len())?;
        // SAFETY: all arrays hold `vrs.len()` elements.
        let raw = unsafe {
            f(
                self.component,
                vrs.as_ptr(),
                vrs.len(),
                orders.as_ptr(),
                values.as_ptr(),
            )
        };
        self.finish(F, mark, raw)
    }

    /// `fmi2GetRealOutputDerivatives` (§4.2.3).
    pub fn get_real_output_derivatives(
        &mut self,
        vrs: &[ValueReference],
        orders: &[i32],
        values: &mut [f64],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi2GetRealOutputDerivatives";
        if !self.declared.output_derivatives {
            return Err(not_supported(F, "maxOutputDerivativeOrder > 0"));
        }
        let f = self.functions.get_real_output_derivatives;
        let mark = self.begin(F)?;
        same_length(F, "orders", vrs.len(), orders.len())?;
        same_length(F, "values", vrs.len(), values.len())?;
        // SAFETY: all arrays hold `vrs.len()` elements.
        let raw = unsafe {
            f(
                self.component,
                vrs.as_ptr(),
                vrs.len(),
                orders.as_ptr(),
                values.as_mut_ptr(),
            )
        };
        self.finish(F, mark, raw)
    }

    /// `fmi2GetDirectionalDerivative` (§2.1.9): `out` = ∂unknowns/∂knowns · `seed`.
    #[inline] // a hot path of the strong-coupling master
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[ValueReference],
        knowns: &[ValueReference],
        seed: &[f64],
        out: &mut [f64],
    ) -> Result<Status, FmuError> {
        const F: &str = "fmi2GetDirectionalDerivative";
        if !self.declared.directional_derivative {
            return Err(not_supported(F, "providesDirectionalDerivative=\"true\""));
        }
        let f = self.functions.get_directional_derivative;
        self.call(F, |component| {
            same_length(F, "seed", knowns.len(), seed.len())?;
            same_length(F, "out", unknowns.len(), out.len())?;
            // SAFETY: each array holds as many elements as its length argument says.
            Ok(unsafe {
                f(
                    component,
                    unknowns.as_ptr(),
                    unknowns.len(),
                    knowns.as_ptr(),
                    knowns.len(),
                    seed.as_ptr(),
                    out.as_mut_ptr(),
                )
            })
        })
    }

    fn own(&self, function: &'static str, state: &FmuState) -> Result<(), FmuError> {
        self.guard.own(function, state.owner)
    }

    /// `f` if its group is `declared`, else [`FmuError::NotSupported`].
    fn state_function<T>(
        &self,
        function: &'static str,
        f: T,
        declared: bool,
        capability: &'static str,
    ) -> Result<T, FmuError> {
        if declared {
            Ok(f)
        } else {
            Err(not_supported(function, capability))
        }
    }

    /// `fmi2GetFMUstate` into a new state.
    pub fn get_state(&mut self) -> Result<FmuState, FmuError> {
        const F: &str = "fmi2GetFMUstate";
        let f = self.state_function(
            F,
            self.functions.get_fmu_state,
            self.declared.fmu_state,
            "canGetAndSetFMUstate=\"true\"",
        )?;
        let mark = self.begin(F)?;
        let mut pointer: fmi2FMUstate = null_mut();
        // SAFETY: `pointer` is a valid out-pointer, null asks for a new state.
        let raw = unsafe { f(self.component, &mut pointer) };
        self.finish(F, mark, raw)?;
        let pointer = self.guard.not_null(F, pointer)?;
        self.states.push(pointer);
        Ok(FmuState {
            pointer,
            owner: self.guard.id,
        })
    }

    /// `fmi2GetFMUstate` into an existing state (the FMU may reuse its memory).
    #[inline] // a hot path of the strong-coupling master
    pub fn update_state(&mut self, state: &mut FmuState) -> Result<Status, FmuError> {
        const F: &str = "fmi2GetFMUstate";
        let f = self.state_function(
            F,
            self.functions.get_fmu_state,
            self.declared.fmu_state,
            "canGetAndSetFMUstate=\"true\"",
        )?;
        self.own(F, state)?;
        let before = state.pointer;
        match self.call(F, |component| {
            // SAFETY: `state.pointer` is a live state of this instance.
            Ok(unsafe { f(component, &mut state.pointer) })
        }) {
            // the usual case: updated in place
            Ok(status) if state.pointer == before => Ok(status),
            result => self.updated_elsewhere(before, state.pointer, result),
        }
    }

    /// The rest of [`Instance::update_state`] when the call failed or the
    /// FMU put the state elsewhere: the list of states to free follows it.
    #[cold]
    #[inline(never)]
    fn updated_elsewhere(
        &mut self,
        before: fmi2FMUstate,
        now: fmi2FMUstate,
        result: Result<Status, FmuError>,
    ) -> Result<Status, FmuError> {
        if now != before {
            if let Some(slot) = self.states.iter_mut().find(|p| **p == before) {
                *slot = now;
            }
        }
        result
    }

    /// `fmi2SetFMUstate`: continue from `state`.
    #[inline(always)] // a hot path of the strong-coupling master
    pub fn set_state(&mut self, state: &FmuState) -> Result<Status, FmuError> {
        const F: &str = "fmi2SetFMUstate";
        let f = self.state_function(
            F,
            self.functions.set_fmu_state,
            self.declared.fmu_state,
            "canGetAndSetFMUstate=\"true\"",
        )?;
        self.own(F, state)?;
        let pointer = state.pointer;
        self.call(F, |component| {
            // SAFETY: `state.pointer` is a live state of this instance.
            Ok(unsafe { f(component, pointer) })
        })
    }

    /// `fmi2FreeFMUstate`.
    pub fn free_state(&mut self, state: FmuState) -> Result<Status, FmuError> {
        const F: &str = "fmi2FreeFMUstate";
        let f = self.state_function(
            F,
            self.functions.free_fmu_state,
            self.declared.fmu_state,
            "canGetAndSetFMUstate=\"true\"",
        )?;
        self.own(F, &state)?;
        let mark = self.begin(F)?;
        if let Some(i) = self.states.iter().position(|p| *p == state.pointer) {
            self.states.swap_remove(i);
        }
        let mut pointer = state.pointer;
        // SAFETY: `pointer` is a live state of this instance, freed once.
        let raw = unsafe { f(self.component, &mut pointer) };
        self.finish(F, mark, raw)
    }

    /// `fmi2SerializedFMUstateSize` + `fmi2SerializeFMUstate`.
    pub fn serialize_state(&mut self, state: &FmuState) -> Result<Vec<u8>, FmuError> {
        const CAPABILITY: &str = "canSerializeFMUstate=\"true\"";
        const SIZE: &str = "fmi2SerializedFMUstateSize";
        const F: &str = "fmi2SerializeFMUstate";
        let size_f = self.state_function(
            SIZE,
            self.functions.serialized_fmu_state_size,
            self.declared.serialize_fmu_state,
            CAPABILITY,
        )?;
        let f = self.state_function(
            F,
            self.functions.serialize_fmu_state,
            self.declared.serialize_fmu_state,
            CAPABILITY,
        )?;
        self.own(F, state)?;
        let mark = self.begin(SIZE)?;
        let mut size = 0usize;
        // SAFETY: `state.pointer` is a live state of this instance.
        let raw = unsafe { size_f(self.component, state.pointer, &mut size) };
        self.finish(SIZE, mark, raw)?;
        let mut bytes = vec![0u8; size];
        let mark = self.begin(F)?;
        // SAFETY: `bytes` holds `size` bytes.
        let raw = unsafe {
            f(
                self.component,
                state.pointer,
                bytes.as_mut_ptr().cast(),
                size,
            )
        };
        self.finish(F, mark, raw)?;
        Ok(bytes)
    }

    /// `fmi2DeSerializeFMUstate` into a new state of this instance.
    pub fn deserialize_state(&mut self, bytes: &[u8]) -> Result<FmuState, FmuError> {
        const F: &str = "fmi2DeSerializeFMUstate";
        let f = self.state_function(
            F,
            self.functions.deserialize_fmu_state,
            self.declared.serialize_fmu_state,
            "canSerializeFMUstate=\"true\"",
        )?;
        let mark = self.begin(F)?;
        let mut pointer: fmi2FMUstate = null_mut();
        // SAFETY: `bytes` holds `bytes.len()` bytes; `pointer` is a valid out-pointer.
        let raw = unsafe {
            f(
                self.component,
                bytes.as_ptr().cast(),
                bytes.len(),
                &mut pointer,
            )
        };
        self.finish(F, mark, raw)?;
        let pointer = self.guard.not_null(F, pointer)?;
        self.states.push(pointer);
        Ok(FmuState {
            pointer,
            owner: self.guard.id,
        })
    }
}

/// The more severe of two successful statuses.
fn worst(a: Status, b: Status) -> Status {
    if a == Status::Warning || b == Status::Warning {
        Status::Warning
    } else {
        Status::Ok
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        if self.guard.fatal {
            // §2.1.3: after fmi2Fatal no function may be called, not even
            // fmi2FreeInstance. The FMU may still hold the callbacks and the
            // sink, so both are leaked with it.
            return;
        }
        if self.declared.fmu_state {
            let free_state = self.functions.free_fmu_state;
            for mut pointer in self.states.drain(..) {
                // SAFETY: each pointer is a live state of this instance.
                unsafe { free_state(self.component, &mut pointer) };
            }
        }
        // SAFETY: the component is live and not used after this.
        unsafe { (self.functions.free_instance)(self.component) };
        // SAFETY: the FMU is freed; nothing refers to these any more.
        unsafe {
            ManuallyDrop::drop(&mut self.callbacks);
            self.guard.drop_sink();
        }
    }
}
