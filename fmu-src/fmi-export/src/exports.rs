//! The C edge. Each `fmi2…` function of [`export_fmi2!`](crate::export_fmi2)
//! calls one function here, which checks the instance pointer against the
//! live set, the state table, null pointers and lengths, then delegates to
//! [`Instance`] inside `catch_unwind`.

use crate::ffi::*;
use crate::guard::{Admission, Guard};
use crate::instance::Instance;
use crate::logger::{Callback, Logger, Reporter};
use crate::model::ModelFactory;
use crate::resource_location;
use crate::serialize::Snapshot;
use crate::state_machine::{allowed_mask, State};
use crate::variables::VarType;
use std::cell::UnsafeCell;
use std::collections::BTreeSet;
use std::ffi::CStr;
use std::os::raw::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// What an `fmi2Component` points to: the instance, and the guard that
/// admits one call into it at a time. The FMI standard leaves calls into
/// one instance from two threads at once undefined (FMI 2.0.4 §2.1.5); a
/// friction block must not take its importer down for it, so the second
/// call is refused with `fmi2Error` and a message instead of running on a
/// state the first is changing. From the thread the guard is biased to,
/// a call costs two plain stores and a load ([`crate::guard`]).
pub struct Slot {
    /// Admits the calls on `instance`, one at a time.
    guard: Guard,
    /// The importer's logger for a refused call, which must not touch the
    /// instance (another thread is changing it).
    refusals: Reporter,
    instance: UnsafeCell<Instance>,
}

// SAFETY: `instance` is reached only by the call the guard admitted
// (`Slot::admit`), one at a time; `refusals` is only read.
unsafe impl Sync for Slot {}

impl Slot {
    fn new(instance: Instance) -> Slot {
        Slot {
            guard: Guard::default(),
            refusals: instance.logger.reporter(),
            instance: UnsafeCell::new(instance),
        }
    }

    /// The instance, if no other call is running on it: the caller owns it
    /// until [`Slot::release`] of the admission. `None`: another thread is
    /// inside a call.
    #[inline(always)]
    fn admit(&self) -> Option<(*mut Instance, Admission)> {
        if cfg!(feature = "unguarded-instances") {
            return Some((self.instance.get(), Admission::Owner));
        }
        self.guard.admit().map(|a| (self.instance.get(), a))
    }

    #[inline(always)]
    fn release(&self, admission: Admission) {
        if !cfg!(feature = "unguarded-instances") {
            self.guard.release(admission);
        }
    }
}

/// A call refused because another thread is inside a call on the same
/// instance: logged through the copy of the logger, `fmi2Error`.
#[cold]
#[inline(never)]
fn concurrent_call(slot: &Slot, function: &str) -> fmi2Status {
    slot.refusals.error(&format!(
        "{function}: refused: another thread is inside a call on this instance \
         (FMI 2.0 leaves concurrent calls into one instance undefined; \
         call it from one thread at a time)"
    ));
    fmi2Status::fmi2Error
}

/// The instances of one interface (FMI 2.0 or FMI 3.0) this library
/// created and has not freed, by address: a pointer is used only if it is
/// in the set of the interface called, so an `fmi3Instance` passed to an
/// `fmi2…` function (or a pointer this library never made) is refused.
pub struct LiveSet {
    /// Every live instance.
    all: Mutex<BTreeSet<usize>>,
    /// Addresses found in `all` recently (0: empty), so that the step loop
    /// of a co-simulation, which calls the same few instances over and
    /// over, checks its pointer with a few loads instead of the lock.
    /// Written only with `all` locked; an address leaves it, with the lock
    /// held, before its instance is freed.
    recent: [AtomicUsize; RECENT],
    /// The slot of `recent` the next address found goes to.
    next_slot: AtomicUsize,
}

impl LiveSet {
    const fn new() -> LiveSet {
        LiveSet {
            all: Mutex::new(BTreeSet::new()),
            recent: [const { AtomicUsize::new(0) }; RECENT],
            next_slot: AtomicUsize::new(0),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, BTreeSet<usize>> {
        self.all.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Whether `c` is an instance of this set that has not been freed:
    /// from `recent`, else from `all`. (Freeing an instance while another
    /// thread is inside a call on it is a caller's error the lock never
    /// prevented either.)
    #[inline]
    fn contains(&self, c: usize) -> bool {
        self.recently_contains(c) || self.contains_locked(c)
    }

    /// Whether `c` (not 0) is in `recent`: a few loads, no lock.
    #[inline(always)]
    fn recently_contains(&self, c: usize) -> bool {
        c != 0 && self.recent.iter().any(|s| s.load(Ordering::Acquire) == c)
    }

    /// [`LiveSet::contains`] from `all`, noting a live `c` in `recent`.
    #[cold]
    #[inline(never)]
    fn contains_locked(&self, c: usize) -> bool {
        let all = self.lock();
        let found = all.contains(&c);
        if found {
            let slot = self.next_slot.fetch_add(1, Ordering::Relaxed) % RECENT;
            self.recent[slot].store(c, Ordering::Release);
        }
        drop(all);
        found
    }
}

/// The instances made by `fmi2Instantiate`.
pub static FMI2_LIVE: LiveSet = LiveSet::new();
/// The instances made by `fmi3InstantiateCoSimulation` and
/// `fmi3InstantiateModelExchange`.
pub static FMI3_LIVE: LiveSet = LiveSet::new();

/// Larger array lengths are refused outright: no model has that many
/// variables, and reading that far would only run past the caller's arrays.
pub(crate) const MAX_ARRAY_LENGTH: usize = 1 << 20;

/// Slots of [`LiveSet::recent`].
const RECENT: usize = 8;

/// A call admitted into a slot ([`Slot::admit`]): released when dropped.
pub(crate) struct Admitted<'a>(&'a Slot, Admission);

impl Drop for Admitted<'_> {
    #[inline(always)]
    fn drop(&mut self) {
        self.0.release(self.1);
    }
}

/// The instance behind `c` for a call's fast path, admitted, if `c` is in
/// [`LiveSet::recent`] of `live` (no lock), no other call is running on it, its state
/// is in `allowed` and calls are not logged; else `None`, and the call
/// takes [`call_allowed`], which checks again and reports. The instance
/// is the caller's until the [`Admitted`] is dropped; what the caller
/// does with it must not panic (there is no `catch_unwind` here).
///
/// # Safety
/// As [`call_allowed`]: `c` is dereferenced only if recently live.
#[inline(always)]
pub(crate) unsafe fn recent_instance<'a>(
    live: &'static LiveSet,
    c: fmi2Component,
    allowed: u32,
) -> Option<(Admitted<'a>, &'a mut Instance)> {
    let c = c as usize;
    if !live.recently_contains(c) {
        return None;
    }
    // SAFETY: a recently live address is a live slot, created by
    // `instantiate` and not freed.
    let slot = unsafe { &*(c as *const Slot) };
    let (instance, admission) = slot.admit()?;
    let admitted = Admitted(slot, admission);
    // SAFETY: admitted: this thread alone reaches the instance until
    // `admitted` is dropped.
    let instance = unsafe { &mut *instance };
    (allowed & instance.state as u32 != 0 && !instance.logger.logs_calls())
        .then_some((admitted, instance))
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".to_string()
    }
}

/// [`call_allowed`] of the function named by the literal, with its state
/// mask computed at compile time, and its name a constant of the cold
/// paths (the closure returning it captures nothing, so a call does not
/// store the name for them).
macro_rules! call {
    ($c:expr, $function:literal, $body:expr) => {
        call_named(
            &FMI2_LIVE,
            $c,
            || $function,
            const { crate::state_machine::allowed_mask($function) },
            $body,
        )
    };
}

/// Run `body` on the instance behind `c` if `c` is live and its state is
/// in `allowed` (the mask of `function` in the state table, resolved at
/// compile time by [`call!`]). Errors are logged as `function: message`.
///
/// # Safety
/// `c` is only dereferenced if it is in the live set, i.e. was returned by
/// `fmi2Instantiate` of this library and not yet freed.
pub unsafe fn call_allowed(
    c: fmi2Component,
    function: &'static str,
    allowed: u32,
    body: impl FnOnce(&mut Instance) -> Result<fmi2Status, String>,
) -> fmi2Status {
    unsafe { call_named(&FMI2_LIVE, c, move || function, allowed, body) }
}

/// [`call_allowed`] with the function's name from `function` (asked on the
/// paths that log only).
///
/// # Safety
/// As [`call_allowed`].
#[inline(always)]
pub(crate) unsafe fn call_named(
    live: &'static LiveSet,
    c: fmi2Component,
    function: impl Fn() -> &'static str + Copy,
    allowed: u32,
    body: impl FnOnce(&mut Instance) -> Result<fmi2Status, String>,
) -> fmi2Status {
    if c.is_null() || !live.contains(c as usize) {
        // No instance, so no logger to report to: the status says it.
        return fmi2Status::fmi2Error;
    }
    // SAFETY: live, so a slot created by `instantiate` and not freed.
    let slot = unsafe { &*(c as *const Slot) };
    let Some((instance, admission)) = slot.admit() else {
        return concurrent_call(slot, function());
    };
    // (a `move` closure: `function` and the pointer are captured by value,
    // not through a stack slot written at every call)
    let outcome = catch_unwind(AssertUnwindSafe(move || {
        // SAFETY: c is a live slot created by Box::into_raw in
        // `instantiate`, admitted: this is the only reference to its
        // instance until the closure returns or unwinds.
        let instance = unsafe { &mut *instance };
        // The step loop's case in two tests: the state allows the call and
        // call logging is off; everything else is out of line.
        if allowed & instance.state as u32 == 0 {
            return illegal_call(instance, function());
        }
        if instance.logger.logs_calls() {
            log_call(instance, function());
        }
        match body(instance) {
            Ok(status) => status,
            Err(message) => log_error(instance, function(), message),
        }
    }));
    let status = outcome.unwrap_or_else(|payload| {
        // SAFETY: as above; the closure's reference ended with the unwind.
        let instance = unsafe { &mut *instance };
        panicked(instance, function(), payload)
    });
    slot.release(admission);
    status
}

/// A call of `function` on `instance` panicked with `payload`: the
/// instance is `Fatal`, the panic logged (out of line: the calls' own code
/// keeps no registers for it).
#[cold]
#[inline(never)]
fn panicked(
    instance: &mut Instance,
    function: &str,
    payload: Box<dyn std::any::Any + Send>,
) -> fmi2Status {
    let message = panic_message(&*payload);
    let _ = catch_unwind(AssertUnwindSafe(|| {
        instance.state = State::Fatal;
        instance
            .logger
            .fatal(&format!("{function}: internal error (panic): {message}"));
    }));
    fmi2Status::fmi2Fatal
}

/// [`call_allowed`] of a function the instance's state does not allow:
/// logged, `fmi2Error`, the instance unchanged.
#[cold]
#[inline(never)]
fn illegal_call(instance: &mut Instance, function: &str) -> fmi2Status {
    instance.logger.error(&format!(
        "{function}: illegal call sequence: not allowed in state {}",
        instance.state_name()
    ));
    fmi2Status::fmi2Error
}

/// The `logCalls` line of [`call_allowed`] (debug logging only).
#[cold]
#[inline(never)]
fn log_call(instance: &mut Instance, function: &str) {
    let message = format!(
        "{function} (state {}, t = {})",
        instance.state_name(),
        instance.time
    );
    instance.logger.call(|| message);
}

/// An error of a call's body, logged as `function: message`.
#[cold]
#[inline(never)]
fn log_error(instance: &mut Instance, function: &str, message: String) -> fmi2Status {
    instance.logger.error(&format!("{function}: {message}"));
    fmi2Status::fmi2Error
}

/// A read-only C array as a slice; `n == 0` accepts NULL.
///
/// # Safety
/// When non-null, `ptr` must point to `n` readable elements (the FMI
/// contract); we check null, alignment and a plausible length.
#[inline(always)]
pub unsafe fn in_slice<'a, T>(ptr: *const T, n: usize, what: &str) -> Result<&'a [T], String> {
    if n == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() || n > MAX_ARRAY_LENGTH || !ptr.is_aligned() {
        return Err(slice_error(ptr as usize, ptr.is_null(), n, what));
    }
    // SAFETY: non-null, aligned, length bounded; validity is the caller's contract.
    Ok(unsafe { std::slice::from_raw_parts(ptr, n) })
}

/// A writable C array as a slice; `n == 0` accepts NULL.
///
/// # Safety
/// As [`in_slice`], for `n` writable elements.
#[inline(always)]
pub unsafe fn out_slice<'a, T>(ptr: *mut T, n: usize, what: &str) -> Result<&'a mut [T], String> {
    if n == 0 {
        return Ok(&mut []);
    }
    if ptr.is_null() || n > MAX_ARRAY_LENGTH || !ptr.is_aligned() {
        return Err(slice_error(ptr as usize, ptr.is_null(), n, what));
    }
    // SAFETY: as above.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, n) })
}

/// Whether `a` and `b` are both non-null and aligned for their types, as
/// [`in_slice`] and [`out_slice`] check them: the alignment bits of both
/// in one test, then each address against NULL.
#[inline(always)]
pub(crate) fn both_usable<A, B>(a: *const A, b: *const B) -> bool {
    let (a, b) = (a as usize, b as usize);
    let misaligned = (a & (std::mem::align_of::<A>() - 1)) | (b & (std::mem::align_of::<B>() - 1));
    misaligned == 0 && a != 0 && b != 0
}

/// Why [`in_slice`] or [`out_slice`] refused an array (null, too long, or
/// misaligned, checked in that order).
#[cold]
#[inline(never)]
fn slice_error(address: usize, null: bool, n: usize, what: &str) -> String {
    if null {
        format!("argument {what} is NULL but its length is {n}")
    } else if n > MAX_ARRAY_LENGTH {
        format!("length of {what} is {n}, more than the {MAX_ARRAY_LENGTH} this FMU accepts")
    } else {
        format!("argument {what} = {address:#x} is not aligned")
    }
}

/// # Safety
/// `s` is NULL or a NUL-terminated string.
pub(crate) unsafe fn c_str(s: fmi2String, what: &str) -> Result<String, String> {
    if s.is_null() {
        return Err(format!("argument {what} is NULL"));
    }
    // SAFETY: non-null and NUL-terminated by the FMI contract.
    Ok(unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
}

pub fn types_platform() -> *const c_char {
    fmi2TypesPlatform.as_ptr()
}

pub fn version() -> *const c_char {
    fmi2Version.as_ptr()
}

/// `fmi2Instantiate`: the GUID picks the model from `registry`.
///
/// # Safety
/// Pointer arguments are NULL or valid per the FMI contract.
#[allow(clippy::too_many_arguments)]
pub unsafe fn instantiate(
    registry: &'static [ModelFactory],
    instance_name: fmi2String,
    fmu_type: fmi2Type,
    guid: fmi2String,
    resource_location: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        if functions.is_null()
            || !(functions as usize).is_multiple_of(std::mem::align_of::<fmi2CallbackFunctions>())
        {
            return std::ptr::null_mut();
        }
        // SAFETY: non-null and aligned; the importer owns it for the call.
        let functions = unsafe { &*functions };
        let name = unsafe { c_str(instance_name, "instanceName") };
        let logger = Logger::new(
            Callback::Fmi2(functions.logger),
            functions.componentEnvironment,
            name.as_deref().unwrap_or("?"),
            logging_on != fmi2False,
        );
        let model_exchange = match fmu_type {
            t if t == fmi2CoSimulation => false,
            t if t == fmi2ModelExchange => true,
            other => {
                let mut logger = logger;
                logger.error(&format!(
                    "fmi2Instantiate: fmuType = {other} is neither fmi2ModelExchange (0) nor fmi2CoSimulation (1)"
                ));
                return std::ptr::null_mut();
            }
        };
        // SAFETY: NULL or NUL-terminated by the FMI contract.
        let location = unsafe { c_str(resource_location, "fmuResourceLocation") };
        let directory = match &location {
            Ok(uri) => resource_location::to_path(uri, resource_location::PathStyle::NATIVE)
                .map(|dir| (format!("fmuResourceLocation \"{uri}\""), dir))
                .map_err(|e| format!("fmuResourceLocation \"{uri}\" {e}")),
            Err(e) => Err(e.clone()),
        };
        let request = Request {
            function: "fmi2Instantiate",
            registry,
            name,
            token: guid,
            token_name: "fmuGUID",
            model_exchange,
            directory,
            fmi3: false,
            intermediate_update: None,
        };
        // SAFETY: NULL or NUL-terminated by the FMI contract.
        unsafe { create(request, logger, &FMI2_LIVE) }
    }));
    outcome.unwrap_or(std::ptr::null_mut())
}

/// What an importer asked to instantiate, in either interface's terms.
pub(crate) struct Request {
    /// `fmi2Instantiate`, `fmi3InstantiateCoSimulation`, …: the prefix of
    /// every message.
    pub function: &'static str,
    pub registry: &'static [ModelFactory],
    /// The instance name, or why it could not be read.
    pub name: Result<String, String>,
    /// The GUID (FMI 2.0) or instantiation token (FMI 3.0) that picks the
    /// model, as the importer passed it.
    pub token: fmi2String,
    /// `fmuGUID` or `instantiationToken`, for the messages.
    pub token_name: &'static str,
    pub model_exchange: bool,
    /// The FMU's `resources/` directory as a native path, with how the
    /// importer gave it (for the log); or why there is none.
    pub directory: Result<(String, String), String>,
    pub fmi3: bool,
    /// FMI 3.0 Co-Simulation: the importer's intermediate-update callback.
    pub intermediate_update: Option<crate::fmi3::exports::IntermediateUpdate>,
}

/// Create the instance `request` asks for, or log why not and return
/// NULL: the model is picked by its token from the registry, given its
/// resources if it reads any, and the instance enters `live`.
///
/// # Safety
/// `request.token` is NULL or NUL-terminated.
pub(crate) unsafe fn create(
    request: Request,
    mut logger: Logger,
    live: &'static LiveSet,
) -> fmi2Component {
    let function = request.function;
    let name = match request.name {
        Ok(n) => n,
        Err(e) => {
            logger.error(&format!("{function}: {e}"));
            return std::ptr::null_mut();
        }
    };
    let token = match unsafe { c_str(request.token, request.token_name) } {
        Ok(g) => g,
        Err(e) => {
            logger.error(&format!("{function}: {e}"));
            return std::ptr::null_mut();
        }
    };
    let registry = request.registry;
    let Some(factory) = registry.iter().find(|f| f.info.guid == token) else {
        let known: Vec<String> = registry
            .iter()
            .map(|f| format!("{} {}", f.info.model_name, f.info.guid))
            .collect();
        logger.error(&format!(
            "{function}: unknown {} {token}; this binary holds {}",
            request.token_name,
            known.join(", ")
        ));
        return std::ptr::null_mut();
    };
    let create = if request.model_exchange {
        match factory.create_model_exchange {
            Some(create) if factory.info.model_exchange.is_some() => create,
            _ => {
                let (asked, offered) = if request.fmi3 {
                    ("Model Exchange", "Co-Simulation")
                } else {
                    ("fmuType = 0 (Model Exchange)", "Co-Simulation (1)")
                };
                logger.error(&format!(
                    "{function}: {asked} is not supported by {}: it implements {offered} only (see its model description: no <ModelExchange> element)",
                    factory.info.model_name
                ));
                return std::ptr::null_mut();
            }
        }
    } else {
        factory.create
    };
    let mut model = create();
    match request.directory {
        Ok((given, dir)) => {
            logger.call(|| {
                format!(
                    "{function}: {given} is the directory \"{dir}\"{}",
                    if model.needs_resources() {
                        ""
                    } else {
                        " (not read: this model uses no resources)"
                    }
                )
            });
            if model.needs_resources() {
                model.set_resource_dir(&dir);
            }
        }
        Err(e) if model.needs_resources() => {
            logger.error(&format!(
                "{function}: {e}; {} reads its resources from there, so it needs the location of a directory",
                factory.info.model_name
            ));
            return std::ptr::null_mut();
        }
        Err(e) => {
            logger.call(|| format!("{function}: {e}; accepted: this model uses no resources"))
        }
    }
    let mut instance = Instance::new(factory.info, model, &name, logger);
    instance.fmi3 = request.fmi3;
    instance.intermediate_update = request.intermediate_update;
    if request.fmi3 {
        instance.fmi3_layout = Some(crate::fmi3::arrays::Layout::of(factory.info));
    }
    if request.model_exchange {
        if let Err(e) = instance.make_model_exchange() {
            instance.logger.error(&format!("{function}: {e}"));
            return std::ptr::null_mut();
        }
    }
    crate::guard::prepare_barrier();
    let address = Box::into_raw(Box::new(Slot::new(instance)));
    live.lock().insert(address as usize);
    address as fmi2Component
}

/// `fmi2FreeInstance`. An instance another thread is inside a call on is
/// not freed (that call would run on freed memory): the refusal is
/// logged, and the importer may free it again once the call has returned.
/// (A call that has found the instance live but not yet entered it when
/// the instance is freed is a window of a few instructions the guard does
/// not close: freeing an instance while calling it is the importer's
/// error either way.)
///
/// # Safety
/// `c` is checked against the live set before use.
pub unsafe fn free_instance(c: fmi2Component) {
    unsafe { free_instance_of(&FMI2_LIVE, "fmi2FreeInstance", c) }
}

/// [`free_instance`] of an instance of `live`.
///
/// # Safety
/// As [`free_instance`].
pub(crate) unsafe fn free_instance_of(live: &'static LiveSet, function: &str, c: fmi2Component) {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        if c.is_null() {
            return;
        }
        let mut all = live.lock();
        if !all.contains(&(c as usize)) {
            return;
        }
        // SAFETY: live, so a slot created by `instantiate` and not freed.
        let slot = unsafe { &*(c as *const Slot) };
        if slot.admit().is_none() {
            drop(all);
            concurrent_call(slot, function);
            return;
        }
        all.remove(&(c as usize));
        for recent in &live.recent {
            // only with the lock held, as every store into the slots
            if recent.load(Ordering::Acquire) == c as usize {
                recent.store(0, Ordering::Release);
            }
        }
        drop(all);
        // SAFETY: was live, so it came from Box::into_raw and is freed
        // once (removed from the live set above, under the lock); admitted,
        // so no call is running on it.
        drop(unsafe { Box::from_raw(c as *mut Slot) });
    }));
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn set_debug_logging(
    c: fmi2Component,
    on: fmi2Boolean,
    n: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SetDebugLogging", |inst| {
            let cats = in_slice(categories, n, "categories[]")?;
            if cats.is_empty() {
                inst.logger.set_all(on != fmi2False);
                return Ok(fmi2Status::fmi2OK);
            }
            let names = cats
                .iter()
                .enumerate()
                .map(|(i, s)| c_str(*s, &format!("categories[{i}]")))
                .collect::<Result<Vec<_>, _>>()?;
            inst.logger.set_categories(on != fmi2False, &names)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`].
pub unsafe fn setup_experiment(
    c: fmi2Component,
    _tolerance_defined: fmi2Boolean,
    _tolerance: f64,
    start: f64,
    stop_defined: fmi2Boolean,
    stop: f64,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SetupExperiment", |inst| {
            inst.setup_experiment(start, (stop_defined != fmi2False).then_some(stop))?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

macro_rules! simple_call {
    ($fn_name:ident, $fmi:literal, $method:ident) => {
        /// # Safety
        /// See [`call_allowed`].
        pub unsafe fn $fn_name(c: fmi2Component) -> fmi2Status {
            unsafe { call!(c, $fmi, |inst| inst.$method().map(|_| fmi2Status::fmi2OK)) }
        }
    };
}
simple_call!(
    enter_initialization_mode,
    "fmi2EnterInitializationMode",
    enter_initialization_mode
);
simple_call!(
    exit_initialization_mode,
    "fmi2ExitInitializationMode",
    exit_initialization_mode
);
simple_call!(terminate, "fmi2Terminate", terminate);
simple_call!(reset, "fmi2Reset", reset);

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn get_real(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *mut f64,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2GetReal", |inst| {
            // The checks of `in_slice` and `out_slice` (a plausible length,
            // both arrays non-null and aligned) in one test for the usual
            // call; anything else takes them one by one, with their
            // messages (and accepts NULL for no values).
            let (vrs, out) = if n != 0 && n <= MAX_ARRAY_LENGTH && both_usable(vr, value) {
                // (inside the function's `unsafe` block) non-null,
                // aligned, of a bounded length: the FMI contract
                (
                    std::slice::from_raw_parts(vr, n),
                    std::slice::from_raw_parts_mut(value, n),
                )
            } else {
                (in_slice(vr, n, "vr[]")?, out_slice(value, n, "value[]")?)
            };
            inst.get(VarType::Real, vrs, out)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn get_integer(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    unsafe {
        get_converted(
            c,
            (
                "fmi2GetInteger",
                const { crate::state_machine::allowed_mask("fmi2GetInteger") },
            ),
            VarType::Integer,
            vr,
            n,
            value,
            |x| x as fmi2Integer,
        )
    }
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn get_boolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    unsafe {
        get_converted(
            c,
            (
                "fmi2GetBoolean",
                const { crate::state_machine::allowed_mask("fmi2GetBoolean") },
            ),
            VarType::Boolean,
            vr,
            n,
            value,
            |x| (x != 0.0) as fmi2Boolean,
        )
    }
}

/// `fmi2GetInteger` and `fmi2GetBoolean`: the values as Reals (how the
/// instance keeps every variable), converted. A master that records an
/// Integer or Boolean output calls this at every step, so it takes the
/// state mask computed at compile time (as [`call!`]) and converts
/// through a stack buffer: no allocation per call.
///
/// # Safety
/// See [`call_allowed`] and [`in_slice`].
#[inline(always)]
unsafe fn get_converted<T>(
    c: fmi2Component,
    (function, allowed): (&'static str, u32),
    t: VarType,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *mut T,
    convert: fn(f64) -> T,
) -> fmi2Status {
    const CHUNK: usize = 32;
    // The step loop's case, one value whose reading runs none of the
    // model's code (`Instance::get_plain`: a master recording a flag after
    // its fmi2GetReal has brought the outputs up to date), before the
    // general path: it cannot fail or panic, so it needs neither
    // `catch_unwind` nor the general path's frame. Anything else takes
    // the general path, nothing changed.
    if n == 1 && both_usable(vr, value) {
        // SAFETY: non-null and aligned, one element (FMI contract)
        let vr = unsafe { *vr };
        // SAFETY: as `call_allowed`
        if let Some((admitted, inst)) = unsafe { recent_instance(&FMI2_LIVE, c, allowed) } {
            let x = inst.get_plain(t, vr);
            drop(admitted);
            if let Some(x) = x {
                // SAFETY: non-null and aligned, one element (FMI contract)
                unsafe { *value = convert(x) };
                return fmi2Status::fmi2OK;
            }
        }
    }
    unsafe {
        call_named(
            &FMI2_LIVE,
            c,
            move || function,
            allowed,
            |inst| {
                let vrs = in_slice(vr, n, "vr[]")?;
                let out = out_slice(value, n, "value[]")?;
                if let ([_], [o]) = (vrs, &mut *out) {
                    // one value (a recorded flag such as LuGre's `sliding`)
                    let mut x = [0.0];
                    inst.get(t, vrs, &mut x)?;
                    *o = convert(x[0]);
                    return Ok(fmi2Status::fmi2OK);
                }
                let mut buffer = [0.0; CHUNK];
                for (vrs, out) in vrs.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
                    let reals = &mut buffer[..vrs.len()];
                    inst.get(t, vrs, reals)?;
                    for (o, &x) in out.iter_mut().zip(reals.iter()) {
                        *o = convert(x);
                    }
                }
                Ok(fmi2Status::fmi2OK)
            },
        )
    }
}

/// These models have no String variables: any value reference is refused.
///
/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn get_or_set_string(
    c: fmi2Component,
    function: &'static str,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const fmi2String,
) -> fmi2Status {
    unsafe {
        // rare calls: the mask is looked up by name
        call_allowed(c, function, allowed_mask(function), |inst| {
            let vrs = in_slice(vr, n, "vr[]")?;
            in_slice(value, n, "value[]")?;
            if let Some(first) = vrs.first() {
                let what = match inst.info.variable(*first) {
                    Some(v) => format!(
                        "value reference {first} ({}) is not a String variable",
                        v.name
                    ),
                    None => format!("unknown value reference {first}"),
                };
                return Err(format!(
                    "{what}: {} has no String variables",
                    inst.info.model_name
                ));
            }
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn set_real(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const f64,
) -> fmi2Status {
    // The step loop's case, one value set without a check of the model's
    // (`Instance::set_real_plain`), before the general path: it calls
    // nothing and cannot fail or panic, so it needs neither `catch_unwind`
    // nor the general path's frame. Anything else, or any doubt, takes the
    // general path, nothing changed, which checks everything in order and
    // reports.
    const ALLOWED: u32 = crate::state_machine::allowed_mask("fmi2SetReal");
    if n == 1 && both_usable(vr, value) {
        // SAFETY: non-null and aligned, one element each (FMI contract)
        let (vr, value) = unsafe { (*vr, *value) };
        // SAFETY: as `call_allowed`
        if let Some((admitted, inst)) = unsafe { recent_instance(&FMI2_LIVE, c, ALLOWED) } {
            let done = inst.set_real_plain(vr, value);
            drop(admitted);
            if done {
                return fmi2Status::fmi2OK;
            }
        }
    }
    unsafe { set_real_general(c, vr, n, value) }
}

/// [`set_real`] with every check (out of line: the fast path above stays
/// without a frame).
///
/// # Safety
/// See [`call_allowed`] and [`in_slice`].
#[inline(never)]
unsafe fn set_real_general(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const f64,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SetReal", |inst| {
            let vrs = in_slice(vr, n, "vr[]")?;
            let values = in_slice(value, n, "value[]")?;
            inst.set(VarType::Real, vrs, values)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn set_integer(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SetInteger", |inst| {
            let vrs = in_slice(vr, n, "vr[]")?;
            let values: Vec<f64> = in_slice(value, n, "value[]")?
                .iter()
                .map(|x| *x as f64)
                .collect();
            inst.set(VarType::Integer, vrs, &values)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn set_boolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SetBoolean", |inst| {
            let vrs = in_slice(vr, n, "vr[]")?;
            let values: Vec<f64> = in_slice(value, n, "value[]")?
                .iter()
                .map(|x| if *x != 0 { 1.0 } else { 0.0 })
                .collect();
            inst.set(VarType::Boolean, vrs, &values)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`]; `state` is NULL or points to an `fmi2FMUstate`.
pub unsafe fn get_fmu_state(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    unsafe {
        call!(c, "fmi2GetFMUstate", |inst| {
            let slot = out_slice(state, 1, "FMUstate")?;
            slot[0] = inst.save_snapshot(slot[0] as usize)? as fmi2FMUstate;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`]; `state` is checked against this instance's saved states.
pub unsafe fn set_fmu_state(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SetFMUstate", |inst| {
            if state.is_null() {
                return Err("argument FMUstate is NULL".into());
            }
            inst.restore_saved(state as usize)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`]; `state` is NULL or points to an `fmi2FMUstate`.
pub unsafe fn free_fmu_state(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    unsafe {
        call!(c, "fmi2FreeFMUstate", |inst| {
            let slot = out_slice(state, 1, "FMUstate")?;
            if slot[0].is_null() {
                return Ok(fmi2Status::fmi2OK);
            }
            inst.free_snapshot(slot[0] as usize)?;
            slot[0] = std::ptr::null_mut();
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`].
pub unsafe fn serialized_fmu_state_size(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SerializedFMUstateSize", |inst| {
            let out = out_slice(size, 1, "size")?;
            out[0] = inst.saved_snapshot(state as usize)?.to_bytes().len();
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`] and [`out_slice`].
pub unsafe fn serialize_fmu_state(
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SerializeFMUstate", |inst| {
            let data = inst.saved_snapshot(state as usize)?.to_bytes();
            if size != data.len() {
                return Err(format!(
                    "size = {size} but the serialized state is {} bytes (ask fmi2SerializedFMUstateSize)",
                    data.len()
                ));
            }
            let out = out_slice(bytes as *mut u8, size, "serializedState[]")?;
            out.copy_from_slice(&data);
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn deserialize_fmu_state(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2DeSerializeFMUstate", |inst| {
            let slot = out_slice(state, 1, "FMUstate")?;
            let reuse = slot[0] as usize;
            if reuse != 0 {
                inst.saved_snapshot(reuse)?;
            }
            let data = in_slice(bytes as *const u8, size, "serializedState[]")?;
            let snap = Snapshot::from_bytes(data, inst.info.guid, inst.n_values())?;
            slot[0] = inst.store_snapshot(snap, reuse) as fmi2FMUstate;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn get_directional_derivative(
    c: fmi2Component,
    unknown: *const fmi2ValueReference,
    n_unknown: usize,
    known: *const fmi2ValueReference,
    n_known: usize,
    dv_known: *const f64,
    dv_unknown: *mut f64,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2GetDirectionalDerivative", |inst| {
            // A master's usual call, one output by one input: the checks of
            // `in_slice` and `out_slice` for one element each (non-null,
            // aligned), without building the slices through `Result`s;
            // anything else, or any doubt, takes them below.
            if n_unknown == 1
                && n_known == 1
                && !unknown.is_null()
                && unknown.is_aligned()
                && !known.is_null()
                && known.is_aligned()
                && !dv_known.is_null()
                && dv_known.is_aligned()
                && !dv_unknown.is_null()
                && dv_unknown.is_aligned()
            {
                // (inside the function's `unsafe` block) non-null and
                // aligned, one element each: the FMI contract
                let (unknowns, knowns, seeds, out) = (
                    std::slice::from_ref(&*unknown),
                    std::slice::from_ref(&*known),
                    std::slice::from_ref(&*dv_known),
                    std::slice::from_mut(&mut *dv_unknown),
                );
                inst.directional_derivative(unknowns, knowns, seeds, out)?;
                return Ok(fmi2Status::fmi2OK);
            }
            let unknowns = in_slice(unknown, n_unknown, "vUnknown_ref[]")?;
            let knowns = in_slice(known, n_known, "vKnown_ref[]")?;
            let seeds = in_slice(dv_known, n_known, "dvKnown[]")?;
            let out = out_slice(dv_unknown, n_unknown, "dvUnknown[]")?;
            inst.directional_derivative(unknowns, knowns, seeds, out)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn set_real_input_derivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    order: *const fmi2Integer,
    value: *const f64,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SetRealInputDerivatives", |inst| {
            let vrs = in_slice(vr, n, "vr[]")?;
            let orders = in_slice(order, n, "order[]")?;
            let values = in_slice(value, n, "value[]")?;
            inst.set_input_derivatives(vrs, orders, values)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`].
pub unsafe fn get_real_output_derivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    order: *const fmi2Integer,
    value: *mut f64,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2GetRealOutputDerivatives", |inst| {
            let vrs = in_slice(vr, n, "vr[]")?;
            let orders = in_slice(order, n, "order[]")?;
            let out = out_slice(value, n, "value[]")?;
            inst.get_output_derivatives(vrs, orders, out)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`].
pub unsafe fn do_step(c: fmi2Component, t: f64, h: f64, _no_set_prior: fmi2Boolean) -> fmi2Status {
    unsafe { call!(c, "fmi2DoStep", |inst| inst.do_step(t, h)) }
}

/// # Safety
/// See [`call_allowed`].
pub unsafe fn cancel_step(c: fmi2Component) -> fmi2Status {
    // Allowed only in StepInProgress, which this FMU never enters (it never
    // returns fmi2Pending); `call` reports the illegal call.
    unsafe { call!(c, "fmi2CancelStep", |_| Ok(fmi2Status::fmi2OK)) }
}

// ---- Model Exchange (FMI 2.0.4 §3.2) ---------------------------------------

simple_call!(enter_event_mode, "fmi2EnterEventMode", enter_event_mode);
simple_call!(
    enter_continuous_time_mode,
    "fmi2EnterContinuousTimeMode",
    enter_continuous_time_mode
);

/// # Safety
/// See [`call_allowed`]; `event_info` is NULL or points to an
/// `fmi2EventInfo`.
pub unsafe fn new_discrete_states(c: fmi2Component, event_info: *mut fmi2EventInfo) -> fmi2Status {
    unsafe {
        call!(c, "fmi2NewDiscreteStates", |inst| {
            let out = out_slice(event_info, 1, "fmi2eventInfo")?;
            let changed = inst.new_discrete_states()?;
            out[0] = fmi2EventInfo {
                newDiscreteStatesNeeded: fmi2False,
                terminateSimulation: fmi2False,
                nominalsOfContinuousStatesChanged: fmi2False,
                valuesOfContinuousStatesChanged: if changed { fmi2True } else { fmi2False },
                nextEventTimeDefined: fmi2False,
                nextEventTime: 0.0,
            };
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`]; the two flags are NULL or point to an
/// `fmi2Boolean` each.
pub unsafe fn completed_integrator_step(
    c: fmi2Component,
    _no_set_fmu_state_prior: fmi2Boolean,
    enter_event_mode: *mut fmi2Boolean,
    terminate_simulation: *mut fmi2Boolean,
) -> fmi2Status {
    unsafe {
        call!(c, "fmi2CompletedIntegratorStep", |_| {
            let enter = out_slice(enter_event_mode, 1, "enterEventMode")?;
            let terminate = out_slice(terminate_simulation, 1, "terminateSimulation")?;
            // no step events: nothing to do after an accepted step
            enter[0] = fmi2False;
            terminate[0] = fmi2False;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`].
pub unsafe fn set_time(c: fmi2Component, time: f64) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SetTime", |inst| {
            inst.set_time(time)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call_allowed`] and [`in_slice`]; `nx` is checked against the
/// model's number of states before `x` is read.
pub unsafe fn set_continuous_states(c: fmi2Component, x: *const f64, nx: usize) -> fmi2Status {
    unsafe {
        call!(c, "fmi2SetContinuousStates", |inst| {
            inst.check_nx(nx)?;
            let x = in_slice(x, nx, "x[]")?;
            inst.set_continuous_states(x)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// The state-sized reads of Model Exchange: `fmi2GetDerivatives`,
/// `fmi2GetContinuousStates`, `fmi2GetNominalsOfContinuousStates` (`n` =
/// nx) and `fmi2GetEventIndicators` (`n` = ni, `indicators`), the length
/// checked before `out` is written.
///
/// # Safety
/// See [`call_allowed`] and [`out_slice`].
pub unsafe fn get_state_array(
    c: fmi2Component,
    function: &'static str,
    out: *mut f64,
    n: usize,
    what: &'static str,
    indicators: bool,
    read: fn(&mut Instance, &mut [f64]) -> Result<(), String>,
) -> fmi2Status {
    unsafe {
        // (the mask looked up by name: one function for four calls)
        call_allowed(c, function, allowed_mask(function), |inst| {
            if indicators {
                inst.check_ni(n)?;
            } else {
                inst.check_nx(n)?;
            }
            let out = out_slice(out, n, what)?;
            read(inst, out)?;
            Ok(fmi2Status::fmi2OK)
        })
    }
}

/// `fmi2Get*Status`. Only `fmi2LastSuccessfulTime` (Real) and
/// `fmi2Terminated` (Boolean) are meaningful for an FMU that never returns
/// `fmi2Pending` or `fmi2Discard`; other kinds give `fmi2Discard`.
///
/// # Safety
/// See [`call_allowed`] and [`out_slice`].
pub unsafe fn get_status<T: Copy>(
    c: fmi2Component,
    function: &'static str,
    kind: fmi2StatusKind,
    value: *mut T,
    answer: impl FnOnce(&Instance, fmi2StatusKind) -> Option<T>,
) -> fmi2Status {
    unsafe {
        // rare calls: the mask is looked up by name
        call_allowed(c, function, allowed_mask(function), |inst| {
            let out = out_slice(value, 1, "value")?;
            match answer(inst, kind) {
                Some(v) => {
                    out[0] = v;
                    Ok(fmi2Status::fmi2OK)
                }
                None => {
                    inst.logger.warning(&format!(
                        "{function}: status kind {kind} is not available: this FMU completes every step synchronously"
                    ));
                    Ok(fmi2Status::fmi2Discard)
                }
            }
        })
    }
}

/// Emit every FMI 2.0 function, Co-Simulation and Model Exchange, for the
/// models in `registry` (an expression of type `&'static [ModelFactory]`).
/// Invoke once in a cdylib.
#[macro_export]
macro_rules! export_fmi2 {
    ($registry:expr) => {
        pub mod fmi2_exports {
            #![allow(non_snake_case, clippy::missing_safety_doc)]
            use super::*;
            use std::os::raw::c_char;
            use $crate::exports as x;
            use $crate::ffi::*;

            #[no_mangle]
            pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
                x::types_platform()
            }
            #[no_mangle]
            pub extern "C" fn fmi2GetVersion() -> *const c_char {
                x::version()
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetDebugLogging(
                c: fmi2Component,
                on: fmi2Boolean,
                n: usize,
                cats: *const fmi2String,
            ) -> fmi2Status {
                unsafe { x::set_debug_logging(c, on, n, cats) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Instantiate(
                name: fmi2String,
                fmu_type: fmi2Type,
                guid: fmi2String,
                resources: fmi2String,
                functions: *const fmi2CallbackFunctions,
                visible: fmi2Boolean,
                logging_on: fmi2Boolean,
            ) -> fmi2Component {
                unsafe {
                    x::instantiate(
                        $registry, name, fmu_type, guid, resources, functions, visible, logging_on,
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
                unsafe { x::free_instance(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetupExperiment(
                c: fmi2Component,
                tol_defined: fmi2Boolean,
                tol: f64,
                start: f64,
                stop_defined: fmi2Boolean,
                stop: f64,
            ) -> fmi2Status {
                unsafe { x::setup_experiment(c, tol_defined, tol, start, stop_defined, stop) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
                unsafe { x::enter_initialization_mode(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
                unsafe { x::exit_initialization_mode(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
                unsafe { x::terminate(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
                unsafe { x::reset(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetReal(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *mut fmi2Real,
            ) -> fmi2Status {
                unsafe { x::get_real(c, vr, n, v) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetInteger(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *mut fmi2Integer,
            ) -> fmi2Status {
                unsafe { x::get_integer(c, vr, n, v) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBoolean(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *mut fmi2Boolean,
            ) -> fmi2Status {
                unsafe { x::get_boolean(c, vr, n, v) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetString(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *mut fmi2String,
            ) -> fmi2Status {
                unsafe { x::get_or_set_string(c, "fmi2GetString", vr, n, v as *const fmi2String) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetReal(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *const fmi2Real,
            ) -> fmi2Status {
                unsafe { x::set_real(c, vr, n, v) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetInteger(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *const fmi2Integer,
            ) -> fmi2Status {
                unsafe { x::set_integer(c, vr, n, v) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetBoolean(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *const fmi2Boolean,
            ) -> fmi2Status {
                unsafe { x::set_boolean(c, vr, n, v) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetString(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                v: *const fmi2String,
            ) -> fmi2Status {
                unsafe { x::get_or_set_string(c, "fmi2SetString", vr, n, v) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetFMUstate(
                c: fmi2Component,
                s: *mut fmi2FMUstate,
            ) -> fmi2Status {
                unsafe { x::get_fmu_state(c, s) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetFMUstate(
                c: fmi2Component,
                s: fmi2FMUstate,
            ) -> fmi2Status {
                unsafe { x::set_fmu_state(c, s) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2FreeFMUstate(
                c: fmi2Component,
                s: *mut fmi2FMUstate,
            ) -> fmi2Status {
                unsafe { x::free_fmu_state(c, s) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
                c: fmi2Component,
                s: fmi2FMUstate,
                size: *mut usize,
            ) -> fmi2Status {
                unsafe { x::serialized_fmu_state_size(c, s, size) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SerializeFMUstate(
                c: fmi2Component,
                s: fmi2FMUstate,
                bytes: *mut fmi2Byte,
                size: usize,
            ) -> fmi2Status {
                unsafe { x::serialize_fmu_state(c, s, bytes, size) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
                c: fmi2Component,
                bytes: *const fmi2Byte,
                size: usize,
                s: *mut fmi2FMUstate,
            ) -> fmi2Status {
                unsafe { x::deserialize_fmu_state(c, bytes, size, s) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
                c: fmi2Component,
                unknown: *const fmi2ValueReference,
                n_unknown: usize,
                known: *const fmi2ValueReference,
                n_known: usize,
                dv_known: *const fmi2Real,
                dv_unknown: *mut fmi2Real,
            ) -> fmi2Status {
                unsafe {
                    x::get_directional_derivative(
                        c, unknown, n_unknown, known, n_known, dv_known, dv_unknown,
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                order: *const fmi2Integer,
                v: *const fmi2Real,
            ) -> fmi2Status {
                unsafe { x::set_real_input_derivatives(c, vr, n, order, v) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                n: usize,
                order: *const fmi2Integer,
                v: *mut fmi2Real,
            ) -> fmi2Status {
                unsafe { x::get_real_output_derivatives(c, vr, n, order, v) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2DoStep(
                c: fmi2Component,
                t: fmi2Real,
                h: fmi2Real,
                no_set_prior: fmi2Boolean,
            ) -> fmi2Status {
                unsafe { x::do_step(c, t, h, no_set_prior) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
                unsafe { x::cancel_step(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
                unsafe { x::enter_event_mode(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2NewDiscreteStates(
                c: fmi2Component,
                event_info: *mut fmi2EventInfo,
            ) -> fmi2Status {
                unsafe { x::new_discrete_states(c, event_info) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
                unsafe { x::enter_continuous_time_mode(c) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
                c: fmi2Component,
                no_set_prior: fmi2Boolean,
                enter_event_mode: *mut fmi2Boolean,
                terminate_simulation: *mut fmi2Boolean,
            ) -> fmi2Status {
                unsafe {
                    x::completed_integrator_step(
                        c,
                        no_set_prior,
                        enter_event_mode,
                        terminate_simulation,
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status {
                unsafe { x::set_time(c, time) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2SetContinuousStates(
                c: fmi2Component,
                states: *const fmi2Real,
                nx: usize,
            ) -> fmi2Status {
                unsafe { x::set_continuous_states(c, states, nx) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetDerivatives(
                c: fmi2Component,
                derivatives: *mut fmi2Real,
                nx: usize,
            ) -> fmi2Status {
                unsafe {
                    x::get_state_array(
                        c,
                        "fmi2GetDerivatives",
                        derivatives,
                        nx,
                        "derivatives[]",
                        false,
                        |i, out| i.get_derivatives(out),
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetEventIndicators(
                c: fmi2Component,
                indicators: *mut fmi2Real,
                ni: usize,
            ) -> fmi2Status {
                unsafe {
                    x::get_state_array(
                        c,
                        "fmi2GetEventIndicators",
                        indicators,
                        ni,
                        "eventIndicators[]",
                        true,
                        |i, out| i.get_event_indicators(out),
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetContinuousStates(
                c: fmi2Component,
                states: *mut fmi2Real,
                nx: usize,
            ) -> fmi2Status {
                unsafe {
                    x::get_state_array(
                        c,
                        "fmi2GetContinuousStates",
                        states,
                        nx,
                        "x[]",
                        false,
                        |i, out| i.get_continuous_states(out),
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
                c: fmi2Component,
                nominals: *mut fmi2Real,
                nx: usize,
            ) -> fmi2Status {
                unsafe {
                    x::get_state_array(
                        c,
                        "fmi2GetNominalsOfContinuousStates",
                        nominals,
                        nx,
                        "x_nominal[]",
                        false,
                        |i, out| i.get_nominals(out),
                    )
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStatus(
                c: fmi2Component,
                kind: fmi2StatusKind,
                v: *mut fmi2Status,
            ) -> fmi2Status {
                unsafe {
                    x::get_status(c, "fmi2GetStatus", kind, v, |_, k| {
                        (k == fmi2DoStepStatus).then_some(fmi2Status::fmi2OK)
                    })
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetRealStatus(
                c: fmi2Component,
                kind: fmi2StatusKind,
                v: *mut fmi2Real,
            ) -> fmi2Status {
                unsafe {
                    x::get_status(c, "fmi2GetRealStatus", kind, v, |i, k| {
                        (k == fmi2LastSuccessfulTime).then_some(i.time)
                    })
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetIntegerStatus(
                c: fmi2Component,
                kind: fmi2StatusKind,
                v: *mut fmi2Integer,
            ) -> fmi2Status {
                unsafe { x::get_status(c, "fmi2GetIntegerStatus", kind, v, |_, _| None) }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetBooleanStatus(
                c: fmi2Component,
                kind: fmi2StatusKind,
                v: *mut fmi2Boolean,
            ) -> fmi2Status {
                unsafe {
                    x::get_status(c, "fmi2GetBooleanStatus", kind, v, |_, k| {
                        (k == fmi2Terminated).then_some(fmi2False)
                    })
                }
            }
            #[no_mangle]
            pub unsafe extern "C" fn fmi2GetStringStatus(
                c: fmi2Component,
                kind: fmi2StatusKind,
                v: *mut fmi2String,
            ) -> fmi2Status {
                unsafe { x::get_status(c, "fmi2GetStringStatus", kind, v, |_, _| None) }
            }
        }
    };
}
