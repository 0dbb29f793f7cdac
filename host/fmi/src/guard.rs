//! What every call of an imported instance goes through, whatever its FMI
//! version ([`crate::Instance`] for FMI 2.0, [`crate::Fmi3Instance`] for
//! FMI 3.0): the refusal after a fatal status, the log mark that finds
//! the messages of one call, the status turned into a `Result` (with the
//! messages in the error), the optional time limit and black box, and the
//! count of calls that may change the instance. The statuses of both
//! versions are the same integers (OK 0 … Fatal 4); a call's name
//! ("fmi2DoStep", "fmi3DoStep") says in errors which one it was.

use super::logger::Sink;
use super::watchdog::Watched;
use super::{Fmu, Status};
use crate::blackbox::CallRecorder;
use crate::error::FmuError;
use std::ffi::CString;
use std::mem::ManuallyDrop;
use std::os::raw::{c_int, c_void};
use std::sync::Arc;
use std::time::Duration;

/// Error messages logged earlier are shown when a call logged nothing.
const EARLIER_MESSAGES: usize = 3;

/// The state of an instance that its calls share (see the module).
pub(crate) struct Guard {
    pub(crate) fmu: Fmu,
    pub(crate) name: String,
    /// Unique in the process: the owner of the instance's FMU states and
    /// the sender of its log messages.
    pub(crate) id: u64,
    /// The logger's environment: the FMU may keep a pointer to it until it
    /// is freed (and forever after a fatal status).
    pub(crate) sink: ManuallyDrop<Box<Sink>>,
    pub(crate) fatal: bool,
    /// A call returned Error or Fatal since instantiation or the last
    /// reset: the instance is in the error state, from which neither
    /// version allows `Terminate`.
    pub(crate) failed: bool,
    /// `fatal`, a time limit or a black box set: every call goes through
    /// [`Guard::begin_guarded`], the rest skip these checks with one test.
    guarded: bool,
    /// The time limit on each call, if one is set.
    limit: Option<Arc<Watched>>,
    /// Where each call is recorded, in an isolated run.
    black_box: Option<CallRecorder>,
    /// Calls made so far that may have changed a value of the instance
    /// (every call but the getters').
    pub(crate) changes: u64,
}

impl Guard {
    pub(crate) fn new(fmu: &Fmu, name: &str, id: u64, sink: Box<Sink>) -> Guard {
        Guard {
            fmu: fmu.clone(),
            name: name.to_string(),
            id,
            sink: ManuallyDrop::new(sink),
            fatal: false,
            failed: false,
            guarded: false,
            limit: None,
            black_box: None,
            changes: 0,
        }
    }

    pub(crate) fn set_call_time_limit(&mut self, limit: Option<Duration>) {
        self.limit = limit.map(|l| Watched::new(&self.name, l));
        self.guarded = self.fatal || self.limit.is_some() || self.black_box.is_some();
    }

    pub(crate) fn set_black_box(&mut self, recorder: Option<CallRecorder>) {
        self.black_box = recorder;
        self.guarded = self.fatal || self.limit.is_some() || self.black_box.is_some();
    }

    /// The communication point of the step that begins, in the black box.
    #[inline]
    pub(crate) fn record_step_time(&self, t: f64) {
        if self.guarded {
            self.record_step_time_guarded(t);
        }
    }

    #[cold]
    #[inline(never)]
    fn record_step_time_guarded(&self, t: f64) {
        if let Some(b) = &self.black_box {
            b.at_time(t);
        }
    }

    /// A state made by instance `owner` may be given to this one only if
    /// it is this one.
    pub(crate) fn own(&self, function: &'static str, owner: u64) -> Result<(), FmuError> {
        if owner == self.id {
            Ok(())
        } else {
            Err(FmuError::ForeignState {
                function,
                instance: self.name.clone(),
            })
        }
    }

    /// The FMU state pointer the call `function` returned, or an error if
    /// it is null.
    pub(crate) fn not_null(
        &self,
        function: &'static str,
        pointer: *mut c_void,
    ) -> Result<*mut c_void, FmuError> {
        if pointer.is_null() {
            Err(FmuError::NullPointer {
                function,
                instance: self.name.clone(),
                what: "FMU state",
            })
        } else {
            Ok(pointer)
        }
    }

    /// Refuse any call after `fmi2Fatal`; otherwise the log mark before the
    /// call (and the call's clock started, under a time limit). Every call
    /// but a getter's counts as a change ([`Guard::changes`]).
    #[inline]
    pub(crate) fn begin(&mut self, function: &'static str) -> Result<u64, FmuError> {
        self.count_change(function);
        if self.guarded {
            return self.begin_guarded(function);
        }
        Ok(self.sink.mark())
    }

    /// A call of `function` moves [`Guard::changes`] unless it is a
    /// getter (`function` is a constant: the test folds away).
    #[inline(always)]
    fn count_change(&mut self, function: &'static str) {
        // "fmi2Get…", "fmi3Get…"
        if !function.get(4..).is_some_and(|f| f.starts_with("Get")) {
            self.changes = self.changes.wrapping_add(1);
        }
    }

    /// [`Guard::begin`] after `fmi2Fatal` or under a time limit.
    #[cold]
    #[inline(never)]
    fn begin_guarded(&mut self, function: &'static str) -> Result<u64, FmuError> {
        if self.fatal {
            return Err(FmuError::AfterFatal {
                function,
                instance: self.name.clone(),
            });
        }
        if let Some(w) = &self.limit {
            w.start(function);
        }
        if let Some(b) = &self.black_box {
            b.enter(function);
        }
        Ok(self.sink.mark())
    }

    /// The status of a call as a `Result`: `fmi2OK`/`fmi3OK` (0) without a time limit
    /// at once, anything else through [`Guard::finish_checked`].
    #[inline]
    pub(crate) fn finish(
        &mut self,
        function: &'static str,
        mark: u64,
        raw: c_int,
    ) -> Result<Status, FmuError> {
        if raw == 0 && !self.guarded {
            return Ok(Status::Ok);
        }
        self.finish_checked(function, mark, raw)
    }

    /// One FMI call, [`Guard::begin`] and [`Guard::finish`] in one:
    /// `ffi` checks its arguments (it may refuse, after the check for
    /// `fmi2Fatal` as with `begin`) and calls the FMU on the instance pointer.
    /// Whether the instance is guarded is asked once, before the call, and
    /// each case has a path of its own: the unguarded one takes `fmi2OK`
    /// at once, without reading the instance again after the call (one
    /// path through `begin` holds more across the call: measured, a few
    /// instructions more per call).
    #[inline(always)]
    pub(crate) fn call(
        &mut self,
        function: &'static str,
        instance: *mut c_void,
        ffi: impl FnOnce(*mut c_void) -> Result<c_int, FmuError>,
    ) -> Result<Status, FmuError> {
        self.count_change(function);
        if self.guarded {
            let mark = self.begin_guarded(function)?;
            let raw = ffi(instance)?;
            return self.finish_checked(function, mark, raw);
        }
        let mark = self.sink.mark();
        match ffi(instance)? {
            0 => Ok(Status::Ok), // fmi2OK, fmi3OK
            raw => self.finish_checked(function, mark, raw),
        }
    }

    #[cold]
    #[inline(never)]
    fn finish_checked(
        &mut self,
        function: &'static str,
        mark: u64,
        raw: c_int,
    ) -> Result<Status, FmuError> {
        if let Some(b) = &self.black_box {
            b.leave();
        }
        let overtime = self.limit.as_ref().and_then(|w| w.stop());
        let status = Status::from_raw(raw);
        if let (Some((elapsed, limit)), Status::Ok | Status::Warning) = (overtime, status) {
            return Err(FmuError::TimeLimit {
                function,
                instance: self.name.clone(),
                elapsed: elapsed.as_secs_f64(),
                limit: limit.as_secs_f64(),
            });
        }
        match status {
            Status::Ok => Ok(Status::Ok),
            Status::Warning => {
                if self.sink.mark() == mark {
                    self.sink.record(
                        Status::Warning,
                        "fricsim",
                        format!("{function} returned {}Warning", &function[..4]),
                    );
                }
                Ok(Status::Warning)
            }
            status => {
                if matches!(status, Status::Error | Status::Fatal) {
                    self.failed = true;
                }
                if status == Status::Fatal {
                    self.fatal = true;
                    self.guarded = true;
                }
                Err(FmuError::Call {
                    function,
                    instance: self.name.clone(),
                    status,
                    messages: self
                        .fmu
                        .log()
                        .messages_since(&self.sink, mark, EARLIER_MESSAGES),
                })
            }
        }
    }
}

// ---- argument checks both instance types make before calling the FMU ----

/// The error of a call the FMU does not declare, made only when needed.
#[cold]
pub(crate) fn not_supported(function: &'static str, capability: &'static str) -> FmuError {
    FmuError::NotSupported {
        function,
        capability,
    }
}

pub(crate) fn same_length(
    function: &'static str,
    what: &'static str,
    expected: usize,
    found: usize,
) -> Result<(), FmuError> {
    if expected == found {
        Ok(())
    } else {
        Err(FmuError::LengthMismatch {
            function,
            what,
            expected,
            found,
        })
    }
}

pub(crate) fn c_string(what: &'static str, value: &str) -> Result<CString, FmuError> {
    CString::new(value).map_err(|_| FmuError::NulInString {
        what,
        value: value.to_string(),
    })
}

/// The logger's environment, the sink, is dropped with the instance
/// unless the FMU may still hold it (after a fatal status).
impl Guard {
    /// Drop the sink; only once the FMU is freed.
    ///
    /// # Safety
    /// The FMU holding a pointer to the sink has been freed.
    pub(crate) unsafe fn drop_sink(&mut self) {
        // SAFETY: the caller's contract.
        unsafe { ManuallyDrop::drop(&mut self.sink) }
    }
}
