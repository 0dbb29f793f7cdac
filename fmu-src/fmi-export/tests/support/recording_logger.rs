//! A logger that records every message the FMU sends (status, category,
//! message), for the tests that call the exported functions of a toy
//! model (`fmi-export/tests/c_abi.rs`, `resource_location.rs`). Included with
//! `#[path]`.

use fmi_export::ffi::{fmi2CallbackFunctions, fmi2String};
use std::cell::RefCell;
use std::ffi::{c_void, CStr};
use std::os::raw::{c_char, c_int};
use std::ptr::null_mut;

// The FMU calls the logger synchronously on the calling thread, and each
// test runs on its own thread: a thread-local log keeps tests apart.
thread_local! {
    static LOG: RefCell<Vec<(i32, String, String)>> = const { RefCell::new(Vec::new()) };
}

pub fn log_snapshot() -> Vec<(i32, String, String)> {
    LOG.with(|l| l.borrow().clone())
}

pub fn log_clear() {
    LOG.with(|l| l.borrow_mut().clear());
}

extern "C" fn record(
    _env: *mut c_void,
    _name: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    // SAFETY: the FMU passes NUL-terminated strings.
    let (c, m) = unsafe { (CStr::from_ptr(category), CStr::from_ptr(message)) };
    LOG.with(|l| {
        l.borrow_mut().push((
            status,
            c.to_string_lossy().into(),
            m.to_string_lossy().into(),
        ))
    });
}

pub fn callbacks() -> fmi2CallbackFunctions {
    // SAFETY: on x86-64 and aarch64 a non-variadic function with these five
    // arguments can be called through the variadic pointer type (the FMU
    // passes no variadic arguments); this is what ctypes importers do.
    let logger = unsafe {
        std::mem::transmute::<
            *const (),
            unsafe extern "C" fn(*mut c_void, fmi2String, c_int, fmi2String, fmi2String, ...),
        >(record as *const ())
    };
    fmi2CallbackFunctions {
        logger: Some(logger),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: null_mut(),
    }
}
