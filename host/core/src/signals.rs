//! SIGINT (Ctrl-C) and SIGTERM as a request to stop: once
//! [`stop_on_termination`] is called, the first such signal only sets a
//! flag, which a run reads between chunks of steps
//! ([`crate::master::RowSink::stop_requested`]): it stops there, its rows
//! so far are put in place marked `# INCOMPLETE: … interrupted by SIGINT`,
//! its temporary directories are removed, and the process exits with
//! 128 + the signal's number (130, 143) as a shell reports a death by that
//! signal. A second signal ends the process at once with the same status
//! (for a run stuck in an FMU call, which nothing can interrupt); it may
//! leave the run's temporary file, which the next run at that path
//! removes ([`crate::output_file`]).
//!
//! The handlers are those of the `signal-hook` crate: a signal handler
//! may only do async-signal-safe work (POSIX.1-2017 §2.4.3), and
//! signal-hook's handlers store to an atomic and nothing else, chain
//! with handlers already installed, and handle the order of the "second
//! signal ends at once" action for us.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The number of the first termination signal received (0: none).
static RECEIVED: AtomicUsize = AtomicUsize::new(0);
/// Set by the first termination signal: the next one ends the process.
static ARMED: AtomicBool = AtomicBool::new(false);

/// Catch SIGINT and SIGTERM as described in the module.
pub fn stop_on_termination() -> std::io::Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    for signal in [SIGINT, SIGTERM] {
        // the order matters: the exit is tried before the flag is set
        signal_hook::flag::register_conditional_shutdown(signal, 128 + signal, &ARMED)?;
        signal_hook::flag::register_usize(signal, &RECEIVED, signal as usize)?;
        signal_hook::flag::register(signal, &ARMED)?;
    }
    Ok(())
}

/// The termination signal received, if any: its number and its name.
pub fn received() -> Option<(i32, &'static str)> {
    match RECEIVED.load(Ordering::SeqCst) as i32 {
        0 => None,
        s => Some((
            s,
            signal_hook::low_level::signal_name(s).unwrap_or("a signal"),
        )),
    }
}

/// Why a run is to stop early, if a termination signal came:
/// `interrupted by SIGINT`.
pub fn stop_reason() -> Option<String> {
    received().map(|(_, name)| format!("interrupted by {name}"))
}
