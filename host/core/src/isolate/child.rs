//! The child's side of an isolated run: the pipe to the parent, the black
//! box given to each instance, and the rows stored in the ring as soon as
//! each communication point is complete.

use super::blackbox::BlackBox;
use super::ring::RowRing;
use super::{Message, BLACK_BOX_FILE, RING_FILE};
use crate::master::{
    simulate_streaming, MasterAlgorithm, NoObserver, Observer, RowSink, Rows, Streamed,
};
use crate::run::{PreparedRun, RunOutcome};
use crate::system::System;
use crate::FmuError;
use std::cell::Cell;
use std::fs::File;
use std::io::Write;
use std::os::fd::FromRawFd;
use std::path::{Path, PathBuf};

/// The child's link to its parent.
pub struct Child {
    pipe: File,
    black_box: BlackBox,
    dir: PathBuf,
    ring: Option<RowRing>,
}

impl Child {
    /// Connect to the parent that made the run directory `dir`: die with
    /// the parent, keep standard output as the pipe of [`Message`]s and
    /// send what is printed there from now on (by an FMU, say) to standard
    /// error, map the black box.
    pub fn connect(dir: &Path) -> Result<Child, String> {
        // SAFETY: plain system calls on this process's own descriptors; the
        // duplicate of standard output is owned by the `File` alone.
        let pipe = unsafe {
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
            let fd = libc::fcntl(1, libc::F_DUPFD_CLOEXEC, 3);
            if fd < 0 || libc::dup2(2, 1) < 0 {
                return Err(format!(
                    "the isolated child cannot set up its pipe: {}",
                    std::io::Error::last_os_error()
                ));
            }
            File::from_raw_fd(fd)
        };
        crate::fmu::watchdog::report_on_stderr(false);
        let black_box = BlackBox::open(&dir.join(BLACK_BOX_FILE))
            .map_err(|e| format!("the isolated child cannot map its black box: {e}"))?;
        Ok(Child {
            pipe,
            black_box,
            dir: dir.to_path_buf(),
            ring: None,
        })
    }

    fn send(&mut self, message: &Message) -> Result<(), String> {
        let mut line = serde_json::to_vec(message).map_err(|e| e.to_string())?;
        line.push(b'\n');
        self.pipe
            .write_all(&line)
            .map_err(|e| format!("the isolated child cannot reach its parent: {e}"))
    }

    /// The system is built: give each instance the black box, make the
    /// ring for its rows and tell the parent the columns.
    pub fn started(&mut self, system: &mut System, extra: serde_json::Value) -> Result<(), String> {
        for (i, c) in system.components.iter_mut().enumerate() {
            c.instance.set_black_box(Some(self.black_box.recorder(i)));
        }
        let columns = system.columns();
        let ring = RowRing::create(&self.dir.join(RING_FILE), columns.len())
            .map_err(|e| format!("the isolated child cannot make its row ring: {e}"))?;
        self.ring = Some(ring);
        let instances = system.components.iter().map(|c| c.name.clone()).collect();
        self.send(&Message::Started {
            columns,
            instances,
            extra,
        })
    }

    /// [`simulate_streaming`], each row going to the parent as soon as its
    /// communication point is complete: the row at `t` when the step from
    /// `t` begins (so that a crash in that step loses none), the rest when
    /// the run hands its last rows on. The system must have been
    /// [`Child::started`].
    #[allow(clippy::too_many_arguments)]
    pub fn simulate_streaming(
        &mut self,
        system: &mut System,
        master: &mut dyn MasterAlgorithm,
        start: f64,
        h: f64,
        stop: f64,
        observer: &mut dyn Observer,
    ) -> Result<Streamed, FmuError> {
        let ring = self
            .ring
            .as_ref()
            .expect("Child::started makes the ring before the run");
        let sent = Sent {
            ring,
            rows: Cell::new(0),
        };
        let mut observer = SendingObserver {
            inner: observer,
            sent: &sent,
        };
        let mut sink = SendingSink {
            sent: &sent,
            handed: 0,
        };
        simulate_streaming(system, master, start, h, stop, &mut observer, &mut sink)
    }

    /// [`PreparedRun::run_observed`], each row going to the parent as
    /// [`Child::simulate_streaming`] sends them: every communication
    /// point, whatever the output interval (the parent records them with
    /// a [`crate::run::Recorder`]). The system must have been
    /// [`Child::started`] ([`PreparedRun::system_mut`]).
    pub fn run_prepared(
        &mut self,
        prepared: PreparedRun,
        progress: Option<&mut dyn FnMut(usize, usize)>,
    ) -> Result<RunOutcome, String> {
        let ring = self
            .ring
            .as_ref()
            .expect("Child::started makes the ring before the run");
        let sent = Sent {
            ring,
            rows: Cell::new(0),
        };
        let mut observer = SendingObserver {
            inner: &mut NoObserver,
            sent: &sent,
        };
        let mut sink = SendingSink {
            sent: &sent,
            handed: 0,
        };
        prepared.run_observed(&mut sink, progress, &mut observer)
    }

    /// The run ended after `rows` rows, stopped early by `error` if it
    /// was: tell the parent.
    pub fn finished_with(
        &mut self,
        rows: usize,
        error: Option<String>,
        extra: serde_json::Value,
    ) -> Result<(), String> {
        self.send(&Message::Finished { rows, error, extra })
    }

    /// The run ended: tell the parent.
    pub fn finished(&mut self, run: &Streamed, extra: serde_json::Value) -> Result<(), String> {
        self.send(&Message::Finished {
            rows: run.rows,
            error: run.error.clone(),
            extra,
        })
    }

    /// The run could not start: tell the parent why.
    pub fn failed(&mut self, message: String) -> Result<(), String> {
        self.send(&Message::Failed { message })
    }
}

/// The ring and how many rows went into it.
struct Sent<'a> {
    ring: &'a RowRing,
    rows: Cell<usize>,
}

impl Sent<'_> {
    fn push(&self, t: f64, row: &[f64]) {
        self.ring.push(t, row);
        self.rows.set(self.rows.get() + 1);
    }
}

/// The run's observer, and before each step the row at its start sent.
struct SendingObserver<'a> {
    inner: &'a mut dyn Observer,
    sent: &'a Sent<'a>,
}

impl Observer for SendingObserver<'_> {
    fn before_step(
        &mut self,
        system: &mut System,
        t: f64,
        initializing: bool,
    ) -> Result<(), FmuError> {
        if !initializing {
            if let Some(row) = system.recorded().last() {
                self.sent.push(t, row);
            }
        }
        self.inner.before_step(system, t, initializing)
    }

    fn at_communication_point(&mut self, system: &mut System, t: f64) -> Result<(), FmuError> {
        self.inner.at_communication_point(system, t)
    }

    fn after_step(&mut self, done: usize, total: usize) {
        self.inner.after_step(done, total)
    }
}

/// The rows the run hands on that the observer has not sent: the last.
struct SendingSink<'a> {
    sent: &'a Sent<'a>,
    /// Rows handed on by the run so far.
    handed: usize,
}

impl RowSink for SendingSink<'_> {
    fn write(&mut self, times: &[f64], rows: &Rows) -> Result<(), String> {
        for (j, (t, row)) in times.iter().zip(rows).enumerate() {
            if self.handed + j >= self.sent.rows.get() {
                self.sent.push(*t, row);
            }
        }
        self.handed += times.len();
        Ok(())
    }

    /// A termination signal stops the run, as in-process
    /// ([`crate::signals`]); the parent writes what came.
    fn stop_requested(&self) -> Option<String> {
        crate::signals::stop_reason()
    }
}
