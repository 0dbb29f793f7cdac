//! The messages FMU instances send to the importer's logger (FMI 2.0.4
//! §2.1.5, `fmi2CallbackLogger`; FMI 3.0.1 §2.3.1, `fmi3LogMessageCallback`).
//!
//! The callback itself is C (`logger.c`: it is variadic); it formats the
//! message and hands the finished string to [`fricsim_log_sink`], which
//! appends it to the [`Log`] of the instance's FMU. Each instance passes a
//! `Sink` as its `componentEnvironment`, so messages are attributed to the
//! instance that the host created, whatever name the FMU reports.

use super::Status;
use std::collections::VecDeque;
use std::ffi::CStr;
use std::fmt;
use std::os::raw::{c_char, c_int, c_void};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

extern "C" {
    /// The `fmi2CallbackLogger` given to every instance (`logger.c`).
    pub(crate) fn fricsim_fmi2_logger(
        env: *mut c_void,
        instance_name: *const c_char,
        status: c_int,
        category: *const c_char,
        message: *const c_char,
        ...
    );
}

/// The `fmi3LogMessageCallback` given to every FMI 3.0 instance (FMI
/// 3.0.1 §2.3.1): not variadic, so written in Rust; its environment is
/// the instance's [`Sink`], as for FMI 2.0, and the message goes the same
/// way ([`fricsim_log_sink`]).
///
/// # Safety
/// As [`fricsim_log_sink`]'s (with no instance name: FMI 3.0 passes none).
pub(crate) unsafe extern "C" fn fricsim_fmi3_logger(
    env: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    // SAFETY: the caller's contract.
    unsafe { fricsim_log_sink(env, std::ptr::null(), status, category, message) }
}

/// The oldest messages are dropped beyond this many.
const CAPACITY: usize = 10_000;

/// One message of an FMU instance.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LogMessage {
    /// The name the host gave the instance.
    pub instance: String,
    pub status: Status,
    pub category: String,
    pub message: String,
    /// Which instance object sent it, and its number among that instance's
    /// messages (to find the messages of one call).
    instance_id: u64,
    sequence: u64,
}

impl fmt::Display for LogMessage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "[{}] {} [{}]: {}",
            self.instance, self.status, self.category, self.message
        )
    }
}

/// The shared message buffer of one FMU (all its instances). Cloning gives
/// another handle to the same buffer.
#[derive(Clone, Debug, Default)]
pub struct Log {
    shared: Arc<Mutex<Buffer>>,
}

#[derive(Debug, Default)]
struct Buffer {
    messages: VecDeque<LogMessage>,
    echo: bool,
}

impl Log {
    pub fn new() -> Log {
        Log::default()
    }

    fn lock(&self) -> MutexGuard<'_, Buffer> {
        // A panic while holding the lock leaves the buffer consistent.
        self.shared.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Print every new message to stderr as it arrives.
    pub fn set_echo(&self, on: bool) {
        self.lock().echo = on;
    }

    /// All messages kept, oldest first.
    pub fn messages(&self) -> Vec<LogMessage> {
        self.lock().messages.iter().cloned().collect()
    }

    /// The messages of the instance called `instance`, oldest first.
    pub fn messages_of(&self, instance: &str) -> Vec<LogMessage> {
        self.lock()
            .messages
            .iter()
            .filter(|m| m.instance == instance)
            .cloned()
            .collect()
    }

    pub fn clear(&self) {
        self.lock().messages.clear();
    }

    pub(crate) fn push(&self, message: LogMessage) {
        let mut buffer = self.lock();
        if buffer.echo {
            eprintln!("{message}");
        }
        if buffer.messages.len() == CAPACITY {
            buffer.messages.pop_front();
        }
        buffer.messages.push_back(message);
    }

    /// The texts `sink` received after its message number `mark`; if there
    /// are none, up to `fallback` of its earlier ones, marked as such.
    pub(crate) fn messages_since(&self, sink: &Sink, mark: u64, fallback: usize) -> Vec<String> {
        let buffer = self.lock();
        let mine = || buffer.messages.iter().filter(|m| m.instance_id == sink.id);
        let recent: Vec<String> = mine()
            .filter(|m| m.sequence > mark)
            .map(|m| m.message.clone())
            .collect();
        if !recent.is_empty() {
            return recent;
        }
        let earlier: Vec<&LogMessage> = mine().collect();
        earlier[earlier.len().saturating_sub(fallback)..]
            .iter()
            .map(|m| format!("(earlier) {}", m.message))
            .collect()
    }
}

/// What an instance passes as `componentEnvironment`: where its messages go.
#[derive(Debug)]
pub(crate) struct Sink {
    pub log: Log,
    pub instance: String,
    pub id: u64,
    /// Number of messages received so far.
    pub count: AtomicU64,
}

impl Sink {
    pub fn new(log: Log, instance: &str, id: u64) -> Sink {
        Sink {
            log,
            instance: instance.to_string(),
            id,
            count: AtomicU64::new(0),
        }
    }

    /// The number of messages received so far (a mark for [`Log::messages_since`]).
    pub fn mark(&self) -> u64 {
        self.count.load(Ordering::Relaxed)
    }

    /// Record a message that the host itself writes about this instance.
    pub fn record(&self, status: Status, category: &str, message: String) {
        let sequence = self.count.fetch_add(1, Ordering::Relaxed) + 1;
        self.log.push(LogMessage {
            instance: self.instance.clone(),
            status,
            category: category.to_string(),
            message,
            instance_id: self.id,
            sequence,
        });
    }
}

fn text(s: *const c_char) -> String {
    if s.is_null() {
        String::new()
    } else {
        // SAFETY: the caller (logger.c, called by the FMU) passes
        // NUL-terminated strings that stay valid during the call.
        unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned()
    }
}

/// Receives every formatted message from `logger.c`.
///
/// # Safety
/// `env` is null or the `componentEnvironment` the host passed to
/// `fmi2Instantiate`, i.e. a live `Sink`; the strings are null or
/// NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn fricsim_log_sink(
    env: *mut c_void,
    instance_name: *const c_char,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    // Never unwind into C.
    let _ = catch_unwind(AssertUnwindSafe(|| {
        let status = Status::from_raw(status);
        let (category, message) = (text(category), text(message));
        if env.is_null() {
            eprintln!("[{}] {status} [{category}]: {message}", text(instance_name));
            return;
        }
        // SAFETY: see the function's contract.
        let sink = unsafe { &*(env as *const Sink) };
        sink.record(status, &category, message);
    }));
}
