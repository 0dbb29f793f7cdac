//! The C edge of FMI 3.0: each `fmi3…` function of
//! [`export_fmi3!`](crate::export_fmi3) calls one function here, which
//! checks the instance pointer against the FMI 3.0 instances, the state
//! table ([`crate::state_machine`], the `fmi3…` rows), null pointers and
//! lengths, then runs the same [`Instance`] method as FMI 2.0, inside
//! `catch_unwind` ([`crate::exports`]).

use super::{event_indicator_vr, time_vr};
use crate::exports::{
    both_usable, call_named, create, free_instance_of, in_slice, out_slice, recent_instance,
    LiveSet, Request, FMI3_LIVE,
};
use crate::ffi::fmi2Status;
use crate::instance::Instance;
use crate::logger::{Callback, Logger};
use crate::model::ModelFactory;
use crate::serialize::Snapshot;
use crate::state_machine::allowed_mask;
use crate::variables::VarType;
use std::os::raw::c_char;
use types::*;

/// The C types of the FMI 3.0 exports.
pub mod types {
    pub use fmi3_types::*;

    /// A C `bool` passed by value, read as its byte: any non-zero byte is
    /// true (a byte other than 0 or 1 in a Rust `bool` would be undefined
    /// behaviour, and an importer's mistake must not be).
    pub type BoolByte = u8;
}

/// Why the clock functions refuse.
pub const NO_CLOCKS: &str = "this FMU has no clocks (no <Clock> variables, no Scheduled Execution)";
/// Why the configuration mode functions refuse.
pub const NO_STRUCTURAL: &str = "this FMU has no structural parameters, so no Configuration Mode";
/// Why `fmi3EnterStepMode` refuses.
pub const NO_EVENT_MODE: &str =
    "this FMU has no Event Mode in Co-Simulation (hasEventMode=\"false\"): it stays in Step Mode";
/// Why the per-element dependency functions refuse.
pub const NO_PER_ELEMENT: &str =
    "this FMU gives its dependencies in the model description only (providesPerElementDependencies=\"false\")";

/// Which interface `fmi3Instantiate…` asked for.
pub enum Interface {
    ModelExchange,
    CoSimulation {
        event_mode_used: BoolByte,
        early_return_allowed: BoolByte,
        intermediate_update: fmi3IntermediateUpdateCallback,
    },
    ScheduledExecution,
}

/// The importer's `fmi3IntermediateUpdateCallback` of a Co-Simulation
/// instance, with its environment and whether it allowed early returns
/// (FMI 3.0 section 4.2.2): each stick/slip switch inside a step is
/// reported to it ([`IntermediateUpdate::report`]).
pub struct IntermediateUpdate {
    callback: unsafe extern "C" fn(
        fmi3InstanceEnvironment,
        fmi3Float64,
        fmi3Boolean,
        fmi3Boolean,
        fmi3Boolean,
        fmi3Boolean,
        *mut fmi3Boolean,
        *mut fmi3Float64,
    ),
    environment: fmi3InstanceEnvironment,
    early_return_allowed: bool,
}

// The environment pointer belongs to the importer, which calls into the
// instance (and so is called back) from one thread at a time.
unsafe impl Send for IntermediateUpdate {}

impl IntermediateUpdate {
    /// Report a switch at `time`; the time to end the step at if the
    /// importer asks for an early return (allowed at instantiation), the
    /// switch itself if its time is not a number.
    pub fn report(&self, time: f64) -> Option<f64> {
        // the answer is read as bytes: any non-zero byte is true
        let mut requested: u8 = 0;
        let mut early_time = time;
        // SAFETY: the importer's callback, with the arguments of FMI 3.0
        // section 4.2.2; the two out-pointers are ours and live across
        // the call (a byte for the bool).
        unsafe {
            (self.callback)(
                self.environment,
                time,
                false, // no intermediate variables to set
                false, // none to get: the FMU declares none
                true,  // the switch ends a stretch of the step
                self.early_return_allowed,
                &mut requested as *mut u8 as *mut fmi3Boolean,
                &mut early_time,
            );
        }
        (self.early_return_allowed && requested != 0).then_some(if early_time.is_finite() {
            early_time
        } else {
            time
        })
    }
}

fn status(s: fmi2Status) -> fmi3Status {
    // the same values, OK 0 to Fatal 4 (this layer never returns Pending)
    s as fmi3Status
}

/// Run `body` on the FMI 3.0 instance behind `c` if the state table allows
/// the call now (`mask`, of the function's row): the FMI 3.0 side of
/// [`crate::exports::call_allowed`] (an instance of FMI 2.0 is not one of
/// FMI 3.0's, and is refused). Errors are logged as `function: message`.
///
/// # Safety
/// `c` is only dereferenced if it is a live FMI 3.0 instance of this
/// library.
#[inline(always)]
unsafe fn call_mask(
    c: fmi3Instance,
    function: &'static str,
    mask: u32,
    body: impl FnOnce(&mut Instance) -> Result<fmi2Status, String>,
) -> fmi3Status {
    let live: &'static LiveSet = &FMI3_LIVE;
    status(unsafe { call_named(live, c, move || function, mask, body) })
}

/// [`call_mask`] of the function named by the literal, under its own row
/// of the state table (or the row `$row`), the mask computed at compile
/// time.
macro_rules! call {
    ($c:expr, $function:literal, $body:expr) => {
        call_mask($c, $function, const { allowed_mask($function) }, $body)
    };
    ($c:expr, $function:expr, row $row:literal, $body:expr) => {
        call_mask($c, $function, const { allowed_mask($row) }, $body)
    };
}

fn ok() -> Result<fmi2Status, String> {
    Ok(fmi2Status::fmi2OK)
}

pub fn version() -> *const c_char {
    fmi3Version.as_ptr()
}

/// `fmi3Instantiate…`: the instantiation token picks the model from
/// `registry`.
///
/// # Safety
/// Pointer arguments are NULL or valid per the FMI contract.
#[allow(clippy::too_many_arguments)]
pub unsafe fn instantiate(
    registry: &'static [ModelFactory],
    interface: Interface,
    instance_name: fmi3String,
    token: fmi3String,
    resource_path: fmi3String,
    logging_on: BoolByte,
    environment: fmi3InstanceEnvironment,
    log: fmi3LogMessageCallback,
) -> fmi3Instance {
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let function = match interface {
            Interface::ModelExchange => "fmi3InstantiateModelExchange",
            Interface::CoSimulation { .. } => "fmi3InstantiateCoSimulation",
            Interface::ScheduledExecution => "fmi3InstantiateScheduledExecution",
        };
        let name = unsafe { crate::exports::c_str(instance_name, "instanceName") };
        let mut logger = Logger::new(
            Callback::Fmi3(log),
            environment,
            name.as_deref().unwrap_or("?"),
            logging_on != 0,
        );
        let mut intermediate_update = None;
        let model_exchange = match interface {
            Interface::ModelExchange => true,
            Interface::CoSimulation {
                event_mode_used, ..
            } if event_mode_used != 0 => {
                logger.error(&format!(
                    "{function}: eventModeUsed = true, but this FMU has no Event Mode in Co-Simulation (hasEventMode=\"false\" in its model description)"
                ));
                return std::ptr::null_mut();
            }
            // switches inside a step go to the importer's callback, if it
            // gave one; an early return only if it allowed them
            Interface::CoSimulation {
                early_return_allowed,
                intermediate_update: callback,
                ..
            } => {
                intermediate_update = callback.map(|callback| IntermediateUpdate {
                    callback,
                    environment,
                    early_return_allowed: early_return_allowed != 0,
                });
                false
            }
            Interface::ScheduledExecution => {
                logger.error(&format!(
                    "{function}: this FMU offers Co-Simulation and Model Exchange, not Scheduled Execution (no <ScheduledExecution> element in its model description)"
                ));
                return std::ptr::null_mut();
            }
        };
        // FMI 3.0 passes the resources as a path (section 2.3.1), NULL if
        // the FMU has none
        let directory = if resource_path.is_null() {
            Err("resourcePath is NULL".to_string())
        } else {
            unsafe { crate::exports::c_str(resource_path, "resourcePath") }
                .map(|dir| (format!("resourcePath \"{dir}\""), dir))
        };
        let request = Request {
            function,
            registry,
            name,
            token,
            token_name: "instantiationToken",
            model_exchange,
            directory,
            fmi3: true,
            intermediate_update,
        };
        unsafe { create(request, logger, &FMI3_LIVE) }
    }));
    outcome.unwrap_or(std::ptr::null_mut())
}

/// # Safety
/// `c` is checked against the live FMI 3.0 instances before use.
pub unsafe fn free_instance(c: fmi3Instance) {
    unsafe { free_instance_of(&FMI3_LIVE, "fmi3FreeInstance", c) }
}

/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn set_debug_logging(
    c: fmi3Instance,
    on: BoolByte,
    n: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    unsafe {
        call!(c, "fmi3SetDebugLogging", |inst| {
            let cats = in_slice(categories, n, "categories[]")?;
            if cats.is_empty() {
                inst.logger.set_all(on != 0);
                return ok();
            }
            let names = cats
                .iter()
                .enumerate()
                .map(|(i, s)| crate::exports::c_str(*s, &format!("categories[{i}]")))
                .collect::<Result<Vec<_>, _>>()?;
            inst.logger.set_categories(on != 0, &names)?;
            ok()
        })
    }
}

/// `fmi3EnterInitializationMode`: FMI 2.0's `fmi2SetupExperiment` and
/// `fmi2EnterInitializationMode` in one call.
///
/// # Safety
/// See [`call`].
pub unsafe fn enter_initialization_mode(
    c: fmi3Instance,
    _tolerance_defined: BoolByte,
    _tolerance: f64,
    start: f64,
    stop_defined: BoolByte,
    stop: f64,
) -> fmi3Status {
    unsafe {
        call!(c, "fmi3EnterInitializationMode", |inst| {
            inst.setup_experiment(start, (stop_defined != 0).then_some(stop))?;
            inst.enter_initialization_mode()?;
            ok()
        })
    }
}

macro_rules! simple_call {
    ($fn_name:ident, $fmi:literal, $method:ident) => {
        /// # Safety
        /// See [`call`].
        pub unsafe fn $fn_name(c: fmi3Instance) -> fmi3Status {
            unsafe { call!(c, $fmi, |inst| inst.$method().map(|_| fmi2Status::fmi2OK)) }
        }
    };
}
simple_call!(
    exit_initialization_mode,
    "fmi3ExitInitializationMode",
    exit_initialization_mode
);
simple_call!(terminate, "fmi3Terminate", terminate);
simple_call!(reset, "fmi3Reset", reset);
simple_call!(
    enter_continuous_time_mode,
    "fmi3EnterContinuousTimeMode",
    enter_continuous_time_mode
);

/// `fmi3EnterEventMode`: Model Exchange only (a Co-Simulation instance of
/// this layer has no Event Mode).
///
/// # Safety
/// See [`call`].
pub unsafe fn enter_event_mode(c: fmi3Instance) -> fmi3Status {
    unsafe {
        call!(c, "fmi3EnterEventMode", row "fmi3Unsupported", |inst| {
            if !inst.is_model_exchange() {
                return Err(NO_EVENT_MODE.into());
            }
            if !crate::state_machine::is_allowed("fmi3EnterEventMode", inst.state) {
                return Err(format!(
                    "illegal call sequence: not allowed in state {}",
                    inst.state_name()
                ));
            }
            inst.enter_event_mode()?;
            ok()
        })
    }
}

/// A function of what this FMU does not offer: refused, naming why.
///
/// # Safety
/// See [`call`].
pub unsafe fn unsupported(
    c: fmi3Instance,
    function: &'static str,
    why: &'static str,
) -> fmi3Status {
    unsafe { call!(c, function, row "fmi3Unsupported", |_| Err(why.to_string())) }
}

/// Whether `vr` is a scalar of FMI 3.0, not an array whose one value
/// reference stands for several values (a value reference past the table
/// is left to the general path, which the fast paths' own checks send it
/// to).
#[inline(always)]
fn is_scalar(inst: &Instance, vr: u32) -> bool {
    match inst.fmi3_layout {
        Some(layout) if layout.has_arrays => layout.variable_of(vr).is_none_or(|v| v.len == 1),
        _ => true,
    }
}

/// The table's value references of the FMI 3.0 value references `vrs`
/// of a get or set of `n_values` values: `vrs` itself when the model has
/// no arrays, else each array as its elements, in `buffer`
/// ([`crate::fmi3::arrays::Layout::expand`]). `n_values` must be their
/// number.
fn table_vrs<'a>(
    inst: &Instance,
    vrs: &'a [u32],
    n_values: usize,
    buffer: &'a mut Vec<u32>,
) -> Result<&'a [u32], String> {
    let table = match inst.fmi3_layout {
        Some(layout) if layout.has_arrays => {
            layout.expand(vrs, buffer)?;
            &buffer[..]
        }
        _ => vrs,
    };
    if table.len() == n_values {
        return Ok(table);
    }
    Err(if table.len() == vrs.len() {
        format!(
            "nValues = {n_values} for {} value references of scalars: they must be equal",
            vrs.len()
        )
    } else {
        format!(
            "nValues = {n_values}, but the {} value references hold {} values (an array counts its elements)",
            vrs.len(),
            table.len()
        )
    })
}

/// Read one value of a variable FMI 3.0 adds to the table: `time`, or an
/// event indicator (Model Exchange).
fn get_added(inst: &mut Instance, vr: u32) -> Result<f64, String> {
    let info = inst.info;
    if vr == time_vr(info) {
        return Ok(inst.time);
    }
    let ni = info.model_exchange.map_or(0, |me| me.event_indicators);
    let first = event_indicator_vr(info, 0);
    if (first..first + ni as u32).contains(&vr) {
        if !inst.is_model_exchange() {
            return Err(format!(
                "value reference {vr} is event indicator {} of Model Exchange: this instance is a Co-Simulation one",
                vr - first
            ));
        }
        let mut z = vec![0.0; ni];
        inst.get_event_indicators(&mut z)?;
        return Ok(z[(vr - first) as usize]);
    }
    Err(format!(
        "unknown value reference {vr} ({} has value references 0..={})",
        info.model_name,
        first + ni as u32 - 1
    ))
}

/// Values of type `t` into `out`: the table's through [`Instance::get`],
/// `time` and the event indicators (Float64) from the instance.
fn get_values(inst: &mut Instance, t: VarType, vrs: &[u32], out: &mut [f64]) -> Result<(), String> {
    let n_table = inst.info.variables.len() as u32;
    if vrs.iter().all(|&vr| vr < n_table) || t != VarType::Real {
        return inst.get(t, vrs, out);
    }
    for (o, &vr) in out.iter_mut().zip(vrs) {
        if vr < n_table {
            let mut x = [0.0];
            inst.get(t, &[vr], &mut x)?;
            *o = x[0];
        } else {
            *o = get_added(inst, vr)?;
        }
    }
    Ok(())
}

/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn get_float64(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    n: usize,
    value: *mut f64,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call!(c, "fmi3GetFloat64", |inst| {
            let vrs = in_slice(vr, n, "valueReferences[]")?;
            let mut buffer = Vec::new();
            let vrs = table_vrs(inst, vrs, n_values, &mut buffer)?;
            let out = out_slice(value, n_values, "values[]")?;
            get_values(inst, VarType::Real, vrs, out)?;
            ok()
        })
    }
}

/// `fmi3GetInt32` and `fmi3GetBoolean`: the values as `f64` (how the
/// instance keeps every variable), converted.
///
/// # Safety
/// See [`call`] and [`in_slice`].
unsafe fn get_converted<T>(
    c: fmi3Instance,
    (function, mask): (&'static str, u32),
    t: VarType,
    (vr, n): (*const fmi3ValueReference, usize),
    (value, n_values): (*mut T, usize),
    convert: fn(f64) -> T,
) -> fmi3Status {
    // The step loop's case, one scalar whose reading runs none of the
    // model's code (`Instance::get_plain`: a master recording a flag after
    // its fmi3GetFloat64 has brought the outputs up to date), as
    // `fmi2GetBoolean` takes it; anything else takes the general path.
    if n == 1 && n_values == 1 && both_usable(vr, value) {
        // SAFETY: non-null and aligned, one element (FMI contract)
        let vr = unsafe { *vr };
        // SAFETY: as `call`
        if let Some((admitted, inst)) = unsafe { recent_instance(&FMI3_LIVE, c, mask) } {
            let x = if is_scalar(inst, vr) {
                inst.get_plain(t, vr)
            } else {
                None
            };
            drop(admitted);
            if let Some(x) = x {
                // SAFETY: non-null and aligned, one element (FMI contract)
                unsafe { *value = convert(x) };
                return fmi3OK;
            }
        }
    }
    unsafe {
        call_mask(c, function, mask, |inst| {
            let vrs = in_slice(vr, n, "valueReferences[]")?;
            let mut buffer = Vec::new();
            let vrs = table_vrs(inst, vrs, n_values, &mut buffer)?;
            let out = out_slice(value, n_values, "values[]")?;
            // through a stack buffer, a chunk at a time: a master records
            // a Boolean or Int32 output at every step, and allocates
            // nothing for it
            const CHUNK: usize = 32;
            let mut reals = [0.0; CHUNK];
            for (vrs, out) in vrs.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
                let reals = &mut reals[..vrs.len()];
                inst.get(t, vrs, reals)?;
                for (o, &x) in out.iter_mut().zip(reals.iter()) {
                    *o = convert(x);
                }
            }
            ok()
        })
    }
}

/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn get_int32(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    n: usize,
    value: *mut fmi3Int32,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        get_converted(
            c,
            ("fmi3GetInt32", const { allowed_mask("fmi3GetInt32") }),
            VarType::Integer,
            (vr, n),
            (value, n_values),
            |x| x as fmi3Int32,
        )
    }
}

/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn get_boolean(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    n: usize,
    value: *mut fmi3Boolean,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        get_converted(
            c,
            ("fmi3GetBoolean", const { allowed_mask("fmi3GetBoolean") }),
            VarType::Boolean,
            (vr, n),
            (value, n_values),
            |x| x != 0.0,
        )
    }
}

/// Why a set of `vr`, a variable FMI 3.0 adds to the table, is refused.
fn set_added(inst: &Instance, vr: u32) -> String {
    if vr == time_vr(inst.info) {
        return format!(
            "value reference {vr} is the independent variable time, which is never set (it is given by fmi3EnterInitializationMode, fmi3DoStep and fmi3SetTime)"
        );
    }
    match get_added_name(inst, vr) {
        Some(name) => format!("value reference {vr} ({name}) is computed by the FMU, never set"),
        None => format!(
            "unknown value reference {vr} ({} has value references 0..={})",
            inst.info.model_name,
            inst.info.variables.len() - 1
        ),
    }
}

/// The name of an event indicator variable, if `vr` is one.
fn get_added_name(inst: &Instance, vr: u32) -> Option<String> {
    let ni = inst.info.model_exchange.map_or(0, |me| me.event_indicators);
    let first = event_indicator_vr(inst.info, 0);
    (first..first + ni as u32)
        .contains(&vr)
        .then(|| super::model_description::event_indicator_name(vr - first))
}

/// `fmi3SetFloat64`, `fmi3SetInt32`, `fmi3SetBoolean`: the values as
/// `f64`, through [`Instance::set`].
///
/// # Safety
/// See [`call`] and [`in_slice`].
unsafe fn set_converted<T: Copy>(
    c: fmi3Instance,
    (function, mask): (&'static str, u32),
    t: VarType,
    (vr, n): (*const fmi3ValueReference, usize),
    (value, n_values): (*const T, usize),
    convert: fn(T) -> f64,
) -> fmi3Status {
    unsafe {
        call_mask(c, function, mask, |inst| {
            let vrs = in_slice(vr, n, "valueReferences[]")?;
            let mut buffer = Vec::new();
            let vrs = table_vrs(inst, vrs, n_values, &mut buffer)?;
            let n_table = inst.info.variables.len() as u32;
            if let Some(&vr) = vrs.iter().find(|&&vr| vr >= n_table) {
                return Err(set_added(inst, vr));
            }
            let values: Vec<f64> = in_slice(value, n_values, "values[]")?
                .iter()
                .map(|x| convert(*x))
                .collect();
            inst.set(t, vrs, &values)?;
            ok()
        })
    }
}

/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn set_float64(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    n: usize,
    value: *const f64,
    n_values: usize,
) -> fmi3Status {
    // The step loop's case, one scalar set without a check of the model's
    // (`Instance::set_real_plain`), before the general path, as
    // `fmi2SetReal` takes it: it calls nothing and cannot fail or panic,
    // so it needs no `catch_unwind`. Anything else, or any doubt, takes
    // the general path, nothing changed.
    const ALLOWED: u32 = allowed_mask("fmi3SetFloat64");
    if n == 1 && n_values == 1 && both_usable(vr, value) {
        // SAFETY: non-null and aligned, one element each (FMI contract)
        let (vr, value) = unsafe { (*vr, *value) };
        // SAFETY: as `call`
        if let Some((admitted, inst)) = unsafe { recent_instance(&FMI3_LIVE, c, ALLOWED) } {
            let done = is_scalar(inst, vr) && inst.set_real_plain(vr, value);
            drop(admitted);
            if done {
                return fmi3OK;
            }
        }
    }
    unsafe {
        set_converted(
            c,
            ("fmi3SetFloat64", const { allowed_mask("fmi3SetFloat64") }),
            VarType::Real,
            (vr, n),
            (value, n_values),
            |x| x,
        )
    }
}

/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn set_int32(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    n: usize,
    value: *const fmi3Int32,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        set_converted(
            c,
            ("fmi3SetInt32", const { allowed_mask("fmi3SetInt32") }),
            VarType::Integer,
            (vr, n),
            (value, n_values),
            |x| x as f64,
        )
    }
}

/// # Safety
/// See [`call`] and [`in_slice`]; the Booleans are read as bytes.
pub unsafe fn set_boolean(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    n: usize,
    value: *const fmi3Boolean,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        set_converted(
            c,
            ("fmi3SetBoolean", const { allowed_mask("fmi3SetBoolean") }),
            VarType::Boolean,
            (vr, n),
            (value as *const u8, n_values),
            |x| if x != 0 { 1.0 } else { 0.0 },
        )
    }
}

/// A get or set of a type these models have no variable of (String,
/// Float32, the integers other than Int32, Binary, Clock): any value
/// reference is refused, naming its variable and type.
///
/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn other_type(
    c: fmi3Instance,
    function: &'static str,
    type_name: &'static str,
    vr: *const fmi3ValueReference,
    n: usize,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call!(c, function, row "fmi3GetOther", |inst| {
            let _ = n_values;
            let vrs = in_slice(vr, n, "valueReferences[]")?;
            let Some(&first) = vrs.first() else {
                return ok();
            };
            let what = match inst.info.variable(first) {
                Some(v) => format!(
                    "value reference {first} ({}) is a {} variable, not {type_name}",
                    v.name,
                    super::model_description::type_name(v.var_type)
                ),
                None if first == time_vr(inst.info) => {
                    format!("value reference {first} (time) is a Float64 variable, not {type_name}")
                }
                None => format!("unknown value reference {first}"),
            };
            Err(format!(
                "{what}: {} has no {type_name} variables",
                inst.info.model_name
            ))
        })
    }
}

/// # Safety
/// See [`call`]; `state` is NULL or points to an `fmi3FMUState`.
pub unsafe fn get_fmu_state(c: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status {
    unsafe {
        call!(c, "fmi3GetFMUState", |inst| {
            let slot = out_slice(state, 1, "FMUState")?;
            slot[0] = inst.save_snapshot(slot[0] as usize)? as fmi3FMUState;
            ok()
        })
    }
}

/// # Safety
/// See [`call`]; `state` is checked against this instance's saved states.
pub unsafe fn set_fmu_state(c: fmi3Instance, state: fmi3FMUState) -> fmi3Status {
    unsafe {
        call!(c, "fmi3SetFMUState", |inst| {
            if state.is_null() {
                return Err("argument FMUState is NULL".into());
            }
            inst.restore_saved(state as usize)?;
            ok()
        })
    }
}

/// # Safety
/// See [`call`]; `state` is NULL or points to an `fmi3FMUState`.
pub unsafe fn free_fmu_state(c: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status {
    unsafe {
        call!(c, "fmi3FreeFMUState", |inst| {
            let slot = out_slice(state, 1, "FMUState")?;
            if slot[0].is_null() {
                return ok();
            }
            inst.free_snapshot(slot[0] as usize)?;
            slot[0] = std::ptr::null_mut();
            ok()
        })
    }
}

/// # Safety
/// See [`call`].
pub unsafe fn serialized_fmu_state_size(
    c: fmi3Instance,
    state: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    unsafe {
        call!(c, "fmi3SerializedFMUStateSize", |inst| {
            let out = out_slice(size, 1, "size")?;
            out[0] = inst.saved_snapshot(state as usize)?.to_bytes().len();
            ok()
        })
    }
}

/// # Safety
/// See [`call`] and [`out_slice`].
pub unsafe fn serialize_fmu_state(
    c: fmi3Instance,
    state: fmi3FMUState,
    bytes: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    unsafe {
        call!(c, "fmi3SerializeFMUState", |inst| {
            let data = inst.saved_snapshot(state as usize)?.to_bytes();
            if size != data.len() {
                return Err(format!(
                    "size = {size} but the serialized state is {} bytes (ask fmi3SerializedFMUStateSize)",
                    data.len()
                ));
            }
            let out = out_slice(bytes, size, "serializedState[]")?;
            out.copy_from_slice(&data);
            ok()
        })
    }
}

/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn deserialize_fmu_state(
    c: fmi3Instance,
    bytes: *const fmi3Byte,
    size: usize,
    state: *mut fmi3FMUState,
) -> fmi3Status {
    unsafe {
        call!(c, "fmi3DeserializeFMUState", |inst| {
            let slot = out_slice(state, 1, "FMUState")?;
            let reuse = slot[0] as usize;
            if reuse != 0 {
                inst.saved_snapshot(reuse)?;
            }
            let data = in_slice(bytes, size, "serializedState[]")?;
            let snap = Snapshot::from_bytes(data, inst.info.guid, inst.n_values())?;
            slot[0] = inst.store_snapshot(snap, reuse) as fmi3FMUState;
            ok()
        })
    }
}

/// The arrays of a derivative call, each with its length.
type Arrays<T> = (*const T, usize);

/// `fmi3GetDirectionalDerivative`: `sensitivity = J·seed`, `J` the
/// partial derivatives of the unknowns by the knowns, as FMI 2.0's
/// [`Instance::directional_derivative`] (after a step: the step's
/// sensitivity).
///
/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn get_directional_derivative(
    c: fmi3Instance,
    unknowns: Arrays<fmi3ValueReference>,
    knowns: Arrays<fmi3ValueReference>,
    seed: Arrays<f64>,
    sensitivity: (*mut f64, usize),
) -> fmi3Status {
    unsafe { derivative(c, false, unknowns, knowns, seed, sensitivity) }
}

/// `fmi3GetAdjointDerivative`: `sensitivity = seedᵀ·J` (FMI 3.0 section
/// 2.2.11), one column of `J` per known from
/// [`Instance::directional_derivative`].
///
/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn get_adjoint_derivative(
    c: fmi3Instance,
    unknowns: Arrays<fmi3ValueReference>,
    knowns: Arrays<fmi3ValueReference>,
    seed: Arrays<f64>,
    sensitivity: (*mut f64, usize),
) -> fmi3Status {
    unsafe { derivative(c, true, unknowns, knowns, seed, sensitivity) }
}

/// The two derivative calls: the arrays checked and expanded to the
/// table's scalars, then `J·seed` or, for the adjoint, `seedᵀ·J`.
///
/// # Safety
/// See [`call`] and [`in_slice`].
unsafe fn derivative(
    c: fmi3Instance,
    adjoint: bool,
    (unknown, n_unknown): Arrays<fmi3ValueReference>,
    (known, n_known): Arrays<fmi3ValueReference>,
    (seed, n_seed): Arrays<f64>,
    (sensitivity, n_sensitivity): (*mut f64, usize),
) -> fmi3Status {
    let (function, mask) = if adjoint {
        (
            "fmi3GetAdjointDerivative",
            const { allowed_mask("fmi3GetAdjointDerivative") },
        )
    } else {
        (
            "fmi3GetDirectionalDerivative",
            const { allowed_mask("fmi3GetDirectionalDerivative") },
        )
    };
    unsafe {
        call_mask(c, function, mask, |inst| {
            let unknowns = in_slice(unknown, n_unknown, "unknowns[]")?;
            let knowns = in_slice(known, n_known, "knowns[]")?;
            let (mut u, mut k) = (Vec::new(), Vec::new());
            let (unknowns, knowns) = elements(inst, (unknowns, &mut u), (knowns, &mut k))?;
            derivative_lengths(unknowns.len(), knowns.len(), n_seed, n_sensitivity, adjoint)?;
            let seeds = in_slice(seed, n_seed, "seed[]")?;
            let out = out_slice(sensitivity, n_sensitivity, "sensitivity[]")?;
            if !adjoint {
                inst.directional_derivative(unknowns, knowns, seeds, out)?;
                return ok();
            }
            if let Some((k, s)) = seeds.iter().enumerate().find(|(_, s)| !s.is_finite()) {
                return Err(format!("seed[{k}] must be finite but was {s}"));
            }
            let mut column = vec![0.0; unknowns.len()];
            for (o, &k) in out.iter_mut().zip(knowns) {
                inst.directional_derivative(unknowns, &[k], &[1.0], &mut column)?;
                *o = column
                    .iter()
                    .zip(seeds)
                    .filter(|(_, s)| **s != 0.0)
                    .map(|(d, s)| d * s)
                    .sum();
            }
            ok()
        })
    }
}

/// The unknowns and knowns of a derivative call as the table's scalars
/// (an array as its elements).
fn elements<'a>(
    inst: &Instance,
    (unknowns, u): (&'a [u32], &'a mut Vec<u32>),
    (knowns, k): (&'a [u32], &'a mut Vec<u32>),
) -> Result<(&'a [u32], &'a [u32]), String> {
    match inst.fmi3_layout {
        Some(layout) if layout.has_arrays => {
            layout.expand(unknowns, u)?;
            layout.expand(knowns, k)?;
            Ok((&u[..], &k[..]))
        }
        _ => Ok((unknowns, knowns)),
    }
}

/// The lengths of a derivative call: the seed has one value per element
/// of the knowns (of the unknowns for the adjoint), the sensitivity one
/// per element of the unknowns (of the knowns).
fn derivative_lengths(
    n_unknown: usize,
    n_known: usize,
    n_seed: usize,
    n_sensitivity: usize,
    adjoint: bool,
) -> Result<(), String> {
    let (seeds_for, sensitivities_for) = if adjoint {
        (("unknowns", n_unknown), ("knowns", n_known))
    } else {
        (("knowns", n_known), ("unknowns", n_unknown))
    };
    if n_seed != seeds_for.1 {
        return Err(format!(
            "nSeed = {n_seed} but the {} hold {} values (an array counts its elements)",
            seeds_for.0, seeds_for.1
        ));
    }
    if n_sensitivity != sensitivities_for.1 {
        return Err(format!(
            "nSensitivity = {n_sensitivity} but the {} hold {} values (an array counts its elements)",
            sensitivities_for.0, sensitivities_for.1
        ));
    }
    Ok(())
}

/// # Safety
/// See [`call`] and [`in_slice`].
pub unsafe fn get_output_derivatives(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    n: usize,
    order: *const fmi3Int32,
    value: *mut f64,
    n_values: usize,
) -> fmi3Status {
    unsafe {
        call!(c, "fmi3GetOutputDerivatives", |inst| {
            // (outputs are scalars: no array to expand)
            if n != n_values {
                return Err(format!(
                    "nValues = {n_values} for {n} value references of scalars: they must be equal"
                ));
            }
            let vrs = in_slice(vr, n, "valueReferences[]")?;
            let orders = in_slice(order, n, "orders[]")?;
            let out = out_slice(value, n, "values[]")?;
            inst.get_output_derivatives(vrs, orders, out)?;
            ok()
        })
    }
}

/// `fmi3DoStep`: the step of FMI 2.0's `fmi2DoStep`, with each stick/slip
/// switch inside it reported to the importer's intermediate-update
/// callback if it gave one
/// ([`Instance::do_step_locating_switches`]); it ends early at a switch
/// if the importer asks (`earlyReturn`, `lastSuccessfulTime` the switch).
/// No event and no termination: these FMUs have no Event Mode in
/// Co-Simulation and run as long as they are stepped.
///
/// # Safety
/// See [`call`]; the flags and the time are written through after the
/// checks.
pub unsafe fn do_step(
    c: fmi3Instance,
    t: f64,
    h: f64,
    flags: [*mut fmi3Boolean; 3],
    last_successful_time: *mut f64,
) -> fmi3Status {
    unsafe {
        call!(c, "fmi3DoStep", |inst| {
            let names = ["eventHandlingNeeded", "terminateSimulation", "earlyReturn"];
            for (flag, name) in flags.iter().zip(names) {
                out_slice(*flag, 1, name)?;
            }
            let last = out_slice(last_successful_time, 1, "lastSuccessfulTime")?;
            let outcome = match inst.intermediate_update.take() {
                None => inst.do_step(t, h).map(|_| None),
                Some(update) => {
                    let outcome =
                        inst.do_step_locating_switches(t, h, &mut |time| update.report(time));
                    inst.intermediate_update = Some(update);
                    outcome
                }
            };
            // written whatever the outcome: the time the FMU reached
            last[0] = inst.time;
            for flag in flags {
                *flag = false;
            }
            let [_, _, early_return] = flags;
            *early_return = matches!(outcome, Ok(Some(_)));
            outcome.map(|_| fmi2Status::fmi2OK)
        })
    }
}

/// # Safety
/// See [`call`].
pub unsafe fn evaluate_discrete_states(c: fmi3Instance) -> fmi3Status {
    // no discrete states outside events: nothing to evaluate
    unsafe { call!(c, "fmi3EvaluateDiscreteStates", |_| ok()) }
}

/// `fmi3UpdateDiscreteStates`: the event iteration of FMI 2.0's
/// `fmi2NewDiscreteStates`, settled in one pass.
///
/// # Safety
/// See [`call`]; every pointer is checked before any is written.
pub unsafe fn update_discrete_states(
    c: fmi3Instance,
    flags: [*mut fmi3Boolean; 5],
    next_event_time: *mut f64,
) -> fmi3Status {
    unsafe {
        call!(c, "fmi3UpdateDiscreteStates", |inst| {
            let names = [
                "discreteStatesNeedUpdate",
                "terminateSimulation",
                "nominalsOfContinuousStatesChanged",
                "valuesOfContinuousStatesChanged",
                "nextEventTimeDefined",
            ];
            for (flag, name) in flags.iter().zip(names) {
                out_slice(*flag, 1, name)?;
            }
            let next = out_slice(next_event_time, 1, "nextEventTime")?;
            let changed = inst.new_discrete_states()?;
            let [need_update, terminate, nominals, values, time_defined] = flags;
            *need_update = false;
            *terminate = false;
            *nominals = false;
            *values = changed;
            *time_defined = false;
            next[0] = 0.0;
            ok()
        })
    }
}

/// # Safety
/// See [`call`]; the two flags are checked before they are written.
pub unsafe fn completed_integrator_step(
    c: fmi3Instance,
    enter_event_mode: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
) -> fmi3Status {
    unsafe {
        call!(c, "fmi3CompletedIntegratorStep", |_| {
            let enter = out_slice(enter_event_mode, 1, "enterEventMode")?;
            let terminate = out_slice(terminate_simulation, 1, "terminateSimulation")?;
            // no step events: nothing to do after an accepted step
            enter[0] = false;
            terminate[0] = false;
            ok()
        })
    }
}

/// # Safety
/// See [`call`].
pub unsafe fn set_time(c: fmi3Instance, time: f64) -> fmi3Status {
    unsafe {
        call!(c, "fmi3SetTime", |inst| {
            inst.set_time(time)?;
            ok()
        })
    }
}

/// # Safety
/// See [`call`] and [`in_slice`]; `nx` is checked against the model's
/// number of states before `x` is read.
pub unsafe fn set_continuous_states(c: fmi3Instance, x: *const f64, nx: usize) -> fmi3Status {
    unsafe {
        call!(c, "fmi3SetContinuousStates", |inst| {
            inst.check_nx(nx)?;
            let x = in_slice(x, nx, "continuousStates[]")?;
            inst.set_continuous_states(x)?;
            ok()
        })
    }
}

/// The state-sized reads of Model Exchange.
pub enum StateArray {
    Derivatives,
    EventIndicators,
    States,
    Nominals,
}

/// `fmi3GetContinuousStateDerivatives`, `fmi3GetEventIndicators`,
/// `fmi3GetContinuousStates`, `fmi3GetNominalsOfContinuousStates`: the
/// length checked before `out` is written.
///
/// # Safety
/// See [`call`] and [`out_slice`].
pub unsafe fn get_state_array(
    c: fmi3Instance,
    array: StateArray,
    out: *mut f64,
    n: usize,
) -> fmi3Status {
    // (each mask computed at compile time: CVode asks for the derivatives
    // at every evaluation of the right-hand side)
    let (function, mask) = match array {
        StateArray::Derivatives => (
            "fmi3GetContinuousStateDerivatives",
            const { allowed_mask("fmi3GetContinuousStateDerivatives") },
        ),
        StateArray::EventIndicators => (
            "fmi3GetEventIndicators",
            const { allowed_mask("fmi3GetEventIndicators") },
        ),
        StateArray::States => (
            "fmi3GetContinuousStates",
            const { allowed_mask("fmi3GetContinuousStates") },
        ),
        StateArray::Nominals => (
            "fmi3GetNominalsOfContinuousStates",
            const { allowed_mask("fmi3GetNominalsOfContinuousStates") },
        ),
    };
    unsafe {
        call_mask(c, function, mask, |inst| {
            match array {
                StateArray::EventIndicators => inst.check_ni(n)?,
                _ => inst.check_nx(n)?,
            }
            let out = out_slice(out, n, "values[]")?;
            match array {
                StateArray::Derivatives => inst.get_derivatives(out)?,
                StateArray::EventIndicators => inst.get_event_indicators(out)?,
                StateArray::States => inst.get_continuous_states(out)?,
                StateArray::Nominals => inst.get_nominals(out)?,
            }
            ok()
        })
    }
}

/// `fmi3GetNumberOfEventIndicators`, `fmi3GetNumberOfContinuousStates`.
///
/// # Safety
/// See [`call`] and [`out_slice`].
pub unsafe fn get_number_of(c: fmi3Instance, function: &'static str, n: *mut usize) -> fmi3Status {
    unsafe {
        // (rare calls: the mask looked up by name)
        call_mask(c, function, allowed_mask(function), |inst| {
            let out = out_slice(n, 1, "n")?;
            let me = inst.info.model_exchange;
            out[0] = if function == "fmi3GetNumberOfEventIndicators" {
                me.map_or(0, |me| me.event_indicators)
            } else {
                me.map_or(0, |me| me.states.len())
            };
            ok()
        })
    }
}
