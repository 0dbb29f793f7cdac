//! Messages to the importer's logger, by category, honouring `loggingOn`
//! and `fmi2SetDebugLogging`.

use crate::ffi::{fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status};
use crate::variables::LOG_CATEGORIES;
use fmi3_types::fmi3LogMessageCallback;
use std::ffi::CString;

/// The importer's logging function, of the interface the instance was
/// created through: FMI 2.0's is variadic and takes the instance name,
/// FMI 3.0's (`fmi3LogMessageCallback`) takes a finished message.
#[derive(Clone, Copy)]
pub enum Callback {
    Fmi2(fmi2CallbackLogger),
    Fmi3(fmi3LogMessageCallback),
}

/// What it takes to send a message to the importer: its callback, its
/// environment pointer and the instance's name.
#[derive(Clone)]
pub struct Reporter {
    callback: Callback,
    environment: fmi2ComponentEnvironment,
    instance_name: CString,
}

// The environment pointer belongs to the importer, which guarantees that it
// may be used from the thread that calls into the instance (a refused
// concurrent call reports from its own thread, as any call does).
unsafe impl Send for Reporter {}
unsafe impl Sync for Reporter {}

impl Reporter {
    /// Send `message` with `status` in `category`, whether or not the
    /// category is enabled (the caller decides).
    pub fn send(&self, status: fmi2Status, category: usize, message: &str) {
        if let Callback::Fmi3(Some(callback)) = self.callback {
            let category_c = to_cstring(LOG_CATEGORIES[category].0);
            let message_c = to_cstring(message);
            // SAFETY: the importer supplied this callback for exactly this
            // use (FMI 3.0 section 2.3.1); both strings are NUL-terminated
            // and outlive the call. The statuses of FMI 2.0 and 3.0 have the
            // same values (OK 0 to Fatal 4).
            unsafe {
                callback(
                    self.environment,
                    status as i32,
                    category_c.as_ptr(),
                    message_c.as_ptr(),
                );
            }
        }
        if let Callback::Fmi2(Some(callback)) = self.callback {
            let category_c = to_cstring(LOG_CATEGORIES[category].0);
            // The message is the format string, with every '%' doubled: C
            // importers that run it through vsnprintf print it unchanged, and
            // importers that print it as is (FMPy's ctypes logger is not
            // variadic) show it readable. No argument is ever consumed.
            let message_c = to_cstring(&message.replace('%', "%%"));
            // SAFETY: the importer supplied this callback for exactly this
            // use; every string is NUL-terminated and outlives the call, and
            // the format contains no conversion that would read an argument.
            unsafe {
                callback(
                    self.environment,
                    self.instance_name.as_ptr(),
                    status as i32,
                    category_c.as_ptr(),
                    message_c.as_ptr(),
                );
            }
        }
    }

    /// An error, category `logStatusError`.
    pub fn error(&self, message: &str) {
        self.send(fmi2Status::fmi2Error, CATEGORY_ERROR, message);
    }
}

pub struct Logger {
    reporter: Reporter,
    /// One flag per entry of [`LOG_CATEGORIES`].
    enabled: [bool; 4],
    /// The last message of status Error or Fatal (for tests and for the
    /// host's reports; the importer receives it through the callback).
    pub last_error: Option<String>,
}

pub const CATEGORY_ERROR: usize = 0;
pub const CATEGORY_FATAL: usize = 1;
pub const CATEGORY_WARNING: usize = 2;
pub const CATEGORY_CALLS: usize = 3;

impl Logger {
    pub fn new(
        callback: Callback,
        environment: fmi2ComponentEnvironment,
        instance_name: &str,
        logging_on: bool,
    ) -> Self {
        let mut logger = Logger {
            reporter: Reporter {
                callback,
                environment,
                instance_name: to_cstring(instance_name),
            },
            enabled: [true, true, false, false],
            last_error: None,
        };
        logger.set_all(logging_on);
        logger
    }

    /// `loggingOn` with no categories: errors always stay on (they are not
    /// debug logging), the debug categories follow the flag.
    pub fn set_all(&mut self, on: bool) {
        self.enabled[CATEGORY_WARNING] = on;
        self.enabled[CATEGORY_CALLS] = on;
    }

    /// `fmi2SetDebugLogging` with explicit categories: each named category
    /// (including the error ones) is switched to `on`.
    pub fn set_categories(&mut self, on: bool, categories: &[String]) -> Result<(), String> {
        let mut indices = Vec::with_capacity(categories.len());
        for c in categories {
            match LOG_CATEGORIES.iter().position(|(name, _)| name == c) {
                Some(i) => indices.push(i),
                None => {
                    let known: Vec<&str> = LOG_CATEGORIES.iter().map(|(n, _)| *n).collect();
                    return Err(format!(
                        "unknown log category \"{c}\" (known: {})",
                        known.join(", ")
                    ));
                }
            }
        }
        for i in indices {
            self.enabled[i] = on;
        }
        Ok(())
    }

    pub fn is_enabled(&self, category: usize) -> bool {
        self.enabled[category]
    }

    /// Whether calls are logged (category `logCalls`).
    #[inline]
    pub fn logs_calls(&self) -> bool {
        self.enabled[CATEGORY_CALLS]
    }

    pub fn log(&mut self, status: fmi2Status, category: usize, message: &str) {
        if matches!(status, fmi2Status::fmi2Error | fmi2Status::fmi2Fatal) {
            self.last_error = Some(message.to_string());
        }
        if self.enabled[category] {
            self.reporter.send(status, category, message);
        }
    }

    /// A copy of what sends the messages, for a thread that must not touch
    /// this logger.
    pub fn reporter(&self) -> Reporter {
        self.reporter.clone()
    }

    pub fn error(&mut self, message: &str) {
        self.log(fmi2Status::fmi2Error, CATEGORY_ERROR, message);
    }

    pub fn fatal(&mut self, message: &str) {
        self.log(fmi2Status::fmi2Fatal, CATEGORY_FATAL, message);
    }

    pub fn warning(&mut self, message: &str) {
        self.log(fmi2Status::fmi2Warning, CATEGORY_WARNING, message);
    }

    #[inline]
    pub fn call(&mut self, message: impl FnOnce() -> String) {
        if self.enabled[CATEGORY_CALLS] {
            let m = message();
            self.log(fmi2Status::fmi2OK, CATEGORY_CALLS, &m);
        }
    }
}

/// A C string from any Rust string: interior NULs become spaces.
pub fn to_cstring(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).expect("NULs were replaced")
}
