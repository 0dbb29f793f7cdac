//! The diagnosis's [`Progress`] drawn as one line on stderr while it
//! runs (feature `progress-line`, with `indicatif`): what `fricsim
//! diagnose` and the Python package's `fricsim.diagnose` show on a
//! terminal. The rest of the crate prints nothing.

use crate::budget::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::Duration;

/// Run `work` with `progress` shown as one line on stderr after `label`,
/// redrawn in place five times a second and cleared at the end; not drawn
/// with `quiet` or when stderr is not a terminal (a pipe, a notebook,
/// pytest's capture).
pub fn with_progress_line<T>(
    label: &str,
    quiet: bool,
    progress: &Progress,
    work: impl FnOnce() -> Result<T, String>,
) -> Result<T, String> {
    if quiet || !std::io::stderr().is_terminal() {
        return work();
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(&format!("{{spinner}} {label}: {{wide_msg}}"))
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    let (stop, stopped) = std::sync::mpsc::channel::<()>();
    let drawn = &bar;
    let out = std::thread::scope(|scope| {
        scope.spawn(move || loop {
            drawn.set_message(progress.snapshot().line());
            drawn.tick();
            match stopped.recv_timeout(Duration::from_millis(200)) {
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => continue,
                _ => break,
            }
        });
        let out = work();
        drop(stop);
        out
    });
    bar.finish_and_clear();
    out
}
