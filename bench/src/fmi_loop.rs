//! The smallest Jacobi co-simulation of two FMUs one could write by hand:
//! the FMUs' FMI 2.0 functions called straight through the C ABI, from the
//! importer's raw table ([`fricsim_fmi::fmi2::Functions`] of the binary
//! the [`Fmu`] loaded: plain function pointers, as `dlsym` gives them), no
//! checks but each call's status, every output recorded at every step. It is what the host's
//! stepping is measured against in BENCHMARKS.md: the same FMUs, the same
//! scheme and calls, without the host's bookkeeping.
//!
//! Every output is recorded, as the host records them: a component's Real
//! outputs in one `fmi2GetReal`, then its Integer outputs in one
//! `fmi2GetInteger` and its Boolean ones in one `fmi2GetBoolean` (where it
//! has any), as whole numbers.
//!
//! The scheme is the host's Jacobi (`fricsim_core::master::jacobi`): at each
//! communication point every component gets its connected inputs from the
//! row recorded there, then steps; the row at the next point is read from
//! every output. Rows go into a buffer of [`fricsim_core::master::CHUNK_STEPS`]
//! rows used again once full, as `fricsim run` hands its rows on.

use fricsim_core::master::{step_count, CHUNK_STEPS};
use fricsim_fmi::fmi2::*;
use fricsim_fmi::model_description::{Causality, VariableKind};
use fricsim_fmi::Fmu;
use std::ffi::CString;
use std::time::Instant;

/// The logger's five fixed arguments (see [`print_message`]).
type FixedArgumentsLogger =
    unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String);
/// The logger as FMI 2.0 declares it, variadic.
type VariadicLogger = unsafe extern "C" fn(
    fmi2ComponentEnvironment,
    fmi2String,
    fmi2Status,
    fmi2String,
    fmi2String,
    ...
);

/// The importer's logger: the message printed on stderr as it comes, its
/// `%` arguments not expanded. FMI 2.0 declares it variadic (§2.1.5),
/// which stable Rust cannot define; a function of the five fixed
/// arguments is called alike on x86-64 (the caller sets up the variadic
/// part, which this one does not read).
unsafe extern "C" fn print_message(
    _: fmi2ComponentEnvironment,
    instance: fmi2String,
    status: fmi2Status,
    _: fmi2String,
    message: fmi2String,
) {
    let text = |s: fmi2String| match s.is_null() {
        true => String::new(),
        // SAFETY: a C string from the FMU, valid during the call
        false => unsafe { std::ffi::CStr::from_ptr(s) }
            .to_string_lossy()
            .into_owned(),
    };
    eprintln!("{} (status {status}): {}", text(instance), text(message));
}

/// One instance: its functions, its pointer, where its outputs go in a
/// row, and its connected input with the row column it comes from.
struct Unit {
    f: Functions,
    c: fmi2Component,
    outputs: Vec<fmi2ValueReference>,
    integers: Vec<fmi2ValueReference>,
    booleans: Vec<fmi2ValueReference>,
    first_column: usize,
    input: Option<(fmi2ValueReference, usize)>,
}

impl Drop for Unit {
    fn drop(&mut self) {
        // SAFETY: `c` came from this library's fmi2Instantiate
        unsafe { (self.f.free_instance)(self.c) }
    }
}

fn ok(status: fmi2Status, call: &str) -> Result<(), String> {
    match status {
        0 => Ok(()),
        s => Err(format!("{call} returned status {s}")),
    }
}

/// The most Integer or Boolean outputs a component may have here (read
/// through a stack buffer).
const DISCRETE_MAX: usize = 16;

/// A Jacobi run of `components` (name, FMU) from 0 to `stop` in steps of
/// `h`, each `(from, to)` of `connections` an output `component.variable`
/// driving an input: the wall time of initialization and stepping, s, and
/// the last row: every output of every component, in order, by name
/// (`component.variable`).
pub fn jacobi_run(
    components: &[(&str, &Fmu)],
    connections: &[(&str, &str)],
    h: f64,
    stop: f64,
) -> Result<(f64, Vec<(String, f64)>), String> {
    let callbacks = CallbackFunctions {
        // SAFETY: see `print_message`
        logger: Some(unsafe {
            std::mem::transmute::<FixedArgumentsLogger, VariadicLogger>(print_message)
        }),
        allocate_memory: Some(libc_calloc),
        free_memory: Some(libc_free),
        step_finished: None,
        component_environment: std::ptr::null_mut(),
    };
    let mut units = Vec::new();
    let mut width = 0;
    let mut columns = Vec::new();
    for (name, fmu) in components {
        let d = fmu.description();
        let outputs: Vec<_> = d
            .variables
            .iter()
            .filter(|v| {
                v.causality == Causality::Output && matches!(v.kind, VariableKind::Real { .. })
            })
            .collect();
        let of_kind = |integer: bool| -> Vec<_> {
            d.variables
                .iter()
                .filter(|v| {
                    v.causality == Causality::Output
                        && match v.kind {
                            VariableKind::Integer { .. } | VariableKind::Enumeration { .. } => {
                                integer
                            }
                            VariableKind::Boolean { .. } => !integer,
                            _ => false,
                        }
                })
                .collect()
        };
        let (integers, booleans) = (of_kind(true), of_kind(false));
        for v in outputs.iter().chain(&integers).chain(&booleans) {
            columns.push(format!("{name}.{}", v.name));
        }
        let c_name = CString::new(*name).map_err(|e| e.to_string())?;
        let guid = CString::new(d.guid.as_str()).map_err(|e| e.to_string())?;
        let resources = CString::new(format!("file://{}/resources", fmu.dir().display()))
            .map_err(|e| e.to_string())?;
        // (`components` borrow the FMUs, which keep their binaries loaded
        // for the whole run)
        let f = *fmu
            .library()
            .functions()
            .ok_or_else(|| format!("{name}: the hand-written loop calls FMI 2.0 FMUs only"))?;
        // SAFETY: valid C strings and callbacks that outlive the instance
        let c = unsafe {
            (f.instantiate)(
                c_name.as_ptr(),
                1, // fmi2CoSimulation
                guid.as_ptr(),
                resources.as_ptr(),
                &callbacks,
                0,
                0,
            )
        };
        if c.is_null() {
            return Err(format!("fmi2Instantiate of {name} failed"));
        }
        units.push(Unit {
            f,
            c,
            outputs: outputs.iter().map(|v| v.value_reference).collect(),
            integers: integers.iter().map(|v| v.value_reference).collect(),
            booleans: booleans.iter().map(|v| v.value_reference).collect(),
            first_column: width,
            input: None,
        });
        if integers.len().max(booleans.len()) > DISCRETE_MAX {
            return Err(format!(
                "{name} has more than {DISCRETE_MAX} Integer or Boolean outputs"
            ));
        }
        width += outputs.len() + integers.len() + booleans.len();
    }
    for (from, to) in connections {
        let column = columns
            .iter()
            .position(|c| c == from)
            .ok_or_else(|| format!("no output {from}"))?;
        let (name, variable) = to.split_once('.').ok_or("component.variable")?;
        let k = components
            .iter()
            .position(|(n, _)| *n == name)
            .ok_or_else(|| format!("no component {name}"))?;
        let vr = components[k]
            .1
            .variable(variable)
            .map_err(|e| e.to_string())?
            .value_reference;
        units[k].input = Some((vr, column));
    }
    // SAFETY (every call below): live instances of their own libraries,
    // arrays as long as the counts given
    unsafe {
        for u in &units {
            ok(
                (u.f.setup_experiment)(u.c, 0, 0.0, 0.0, 1, stop),
                "fmi2SetupExperiment",
            )?;
            ok(
                (u.f.enter_initialization_mode)(u.c),
                "fmi2EnterInitializationMode",
            )?;
        }
    }
    let clock = Instant::now();
    let n = step_count(0.0, h, stop);
    let chunk = CHUNK_STEPS.min(n) + 1;
    let mut rows = vec![0.0; chunk * width];
    let mut times = vec![0.0; chunk];
    let sample = |units: &[Unit], row: &mut [f64]| -> Result<(), String> {
        for u in units {
            let (n, ni, nb) = (u.outputs.len(), u.integers.len(), u.booleans.len());
            let out = &mut row[u.first_column..u.first_column + n + ni + nb];
            let (reals, discrete) = out.split_at_mut(n);
            let mut buffer = [0; DISCRETE_MAX];
            unsafe {
                ok(
                    (u.f.get_real)(u.c, u.outputs.as_ptr(), n, reals.as_mut_ptr()),
                    "fmi2GetReal",
                )?;
                if ni > 0 {
                    ok(
                        (u.f.get_integer)(u.c, u.integers.as_ptr(), ni, buffer.as_mut_ptr()),
                        "fmi2GetInteger",
                    )?;
                    for (x, i) in discrete[..ni].iter_mut().zip(buffer) {
                        *x = f64::from(i);
                    }
                }
                if nb > 0 {
                    ok(
                        (u.f.get_boolean)(u.c, u.booleans.as_ptr(), nb, buffer.as_mut_ptr()),
                        "fmi2GetBoolean",
                    )?;
                    for (x, b) in discrete[ni..].iter_mut().zip(buffer) {
                        *x = f64::from(b);
                    }
                }
            }
        }
        Ok(())
    };
    let set_inputs = |units: &[Unit], row: &[f64]| -> Result<(), String> {
        for u in units {
            if let Some((vr, column)) = u.input {
                unsafe { ok((u.f.set_real)(u.c, &vr, 1, &row[column]), "fmi2SetReal")? };
            }
        }
        Ok(())
    };
    // initialization as the host's: inputs set before and after leaving it
    sample(&units, &mut rows[..width])?;
    set_inputs(&units, &rows[..width])?;
    for u in &units {
        unsafe {
            ok(
                (u.f.exit_initialization_mode)(u.c),
                "fmi2ExitInitializationMode",
            )?
        };
    }
    sample(&units, &mut rows[..width])?;
    let mut held = 1; // rows in the buffer
    for i in 0..n {
        let t = i as f64 * h;
        let (done, next) = rows.split_at_mut(held * width);
        let row = &done[(held - 1) * width..];
        for u in &units {
            if let Some((vr, column)) = u.input {
                unsafe { ok((u.f.set_real)(u.c, &vr, 1, &row[column]), "fmi2SetReal")? };
            }
            // noSetFMUStatePriorToCurrentPoint false, as the host calls it
            unsafe { ok((u.f.do_step)(u.c, t, h, 0), "fmi2DoStep")? };
        }
        sample(&units, &mut next[..width])?;
        times[held] = (i + 1) as f64 * h;
        held += 1;
        if held == chunk {
            // the rows handed on; the last stays for the next step
            rows.copy_within((held - 1) * width..held * width, 0);
            held = 1;
        }
    }
    let wall = clock.elapsed().as_secs_f64();
    std::hint::black_box(&times);
    let last = &rows[(held - 1) * width..held * width];
    Ok((
        wall,
        columns.into_iter().zip(last.iter().copied()).collect(),
    ))
}

unsafe extern "C" fn libc_calloc(count: usize, size: usize) -> *mut std::ffi::c_void {
    libc::calloc(count, size)
}

unsafe extern "C" fn libc_free(p: *mut std::ffi::c_void) {
    libc::free(p)
}
