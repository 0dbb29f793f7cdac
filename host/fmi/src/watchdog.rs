//! A time limit on each FMI call of an instance (`fricsim run/cosim
//! --step-timeout SECONDS`).
//!
//! What it can do: every call made through [`Instance`](super::Instance)
//! is timed; a call that returns after the limit is treated as failed (its
//! result is not used, the run stops with the rows so far, marked
//! incomplete, and the report names the instance, the call, its duration and
//! the limit). While a call is still running past the limit, a watchdog
//! thread says so on stderr at once, naming the instance and the call, so a
//! hung FMU is identified even if it never returns.
//!
//! What it cannot do: interrupt the call. The FMU runs in the host's thread
//! and address space; there is no safe way to stop a thread in the middle of
//! foreign code (killing it would leave the FMU's locks and memory in an
//! unknown state). A call that never returns keeps fricsim waiting until it
//! is interrupted (Ctrl-C), and the results of that run are then lost.
//! `--isolate` runs the FMUs in a child process, which the parent kills
//! when a call passes the limit (the host's process isolation, `fricsim_core::isolate`).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock, Weak};
use std::time::{Duration, Instant};

/// How often the watchdog looks at the running calls.
const POLL: Duration = Duration::from_millis(20);

/// Whether a call past its limit is reported on stderr (see
/// [`report_on_stderr`]).
static REPORT: AtomicBool = AtomicBool::new(true);

/// Report a call still running past its limit on stderr (the default), or
/// not: in an isolated run the parent process stops such a call and says
/// so itself (the host's process isolation, `fricsim_core::isolate`).
pub fn report_on_stderr(on: bool) {
    REPORT.store(on, Ordering::Relaxed);
}

/// The call an instance is in, if any.
struct Running {
    function: &'static str,
    started: Instant,
    reported: bool,
}

/// The time limit of one instance and the call it is in.
pub(crate) struct Watched {
    instance: String,
    limit: Duration,
    running: Mutex<Option<Running>>,
}

fn registry() -> &'static Mutex<Vec<Weak<Watched>>> {
    static REGISTRY: OnceLock<Mutex<Vec<Weak<Watched>>>> = OnceLock::new();
    REGISTRY.get_or_init(|| {
        std::thread::Builder::new()
            .name("fricsim-watchdog".into())
            .spawn(watch)
            .expect("starting the watchdog thread");
        Mutex::new(Vec::new())
    })
}

/// The watchdog thread: report each call that runs past its limit, once.
fn watch() {
    loop {
        std::thread::sleep(POLL);
        let mut list = registry().lock().unwrap_or_else(|e| e.into_inner());
        list.retain(|w| w.strong_count() > 0);
        for w in list.iter().filter_map(Weak::upgrade) {
            let mut running = w.running.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(r) = running.as_mut() {
                if !r.reported && r.started.elapsed() > w.limit {
                    r.reported = true;
                    if !REPORT.load(Ordering::Relaxed) {
                        continue;
                    }
                    eprintln!(
                        "fricsim: instance \"{}\" has been in {} for more than the limit of {} s \
                         (--step-timeout); the run stops when the call returns (a running call \
                         cannot be interrupted: Ctrl-C ends fricsim)",
                        w.instance,
                        r.function,
                        w.limit.as_secs_f64()
                    );
                }
            }
        }
    }
}

impl Watched {
    pub(crate) fn new(instance: &str, limit: Duration) -> Arc<Watched> {
        let w = Arc::new(Watched {
            instance: instance.to_string(),
            limit,
            running: Mutex::new(None),
        });
        registry()
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(Arc::downgrade(&w));
        w
    }

    /// A call begins (no allocation).
    pub(crate) fn start(&self, function: &'static str) {
        *self.running.lock().unwrap_or_else(|e| e.into_inner()) = Some(Running {
            function,
            started: Instant::now(),
            reported: false,
        });
    }

    /// The call returned: its duration if that was over the limit.
    pub(crate) fn stop(&self) -> Option<(Duration, Duration)> {
        let running = self
            .running
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take();
        let elapsed = running?.started.elapsed();
        (elapsed > self.limit).then_some((elapsed, self.limit))
    }
}
