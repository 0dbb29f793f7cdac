//! Runs whose FMUs live in a child process (`fricsim run --isolate`,
//! `fricsim cosim --isolate`), so that an FMU that crashes the process
//! (a segmentation fault, `abort()`, `exit()`) or hangs costs the run its
//! end, not its rows, and is named.
//!
//! FMPy's remoting and libcosim's proxy put each FMU in a server process
//! of its own and make every FMI call a message; here the whole
//! simulation moves instead, as one child, so that no FMI call crosses
//! a process boundary and the numbers are those of the in-process run bit
//! for bit (the same code computes them):
//!
//! - the parent makes a temporary directory for the run, creates the
//!   [`blackbox`] file in it and starts its own binary again
//!   ([`std::env::current_exe`]) with the hidden subcommand
//!   [`CHILD_COMMAND`], the same arguments, and `TMPDIR` set to that
//!   directory, so that whatever the child unpacks is removed with it
//!   however the child ends ([`parent`]);
//! - the child builds the system and runs it as in-process, storing each
//!   row in a [`ring`] of shared memory as soon as its communication point
//!   is complete, and its instances record each FMI call in the black box
//!   ([`child`]); two [`Message`]s on a pipe (its standard output, moved
//!   away from the FMUs' `printf`) say when the run started and how it
//!   finished;
//! - the parent writes the rows, the summary and the plot. A child that
//!   dies before `Finished` (killed by a signal, or exiting, even with
//!   status 0) leaves a run marked incomplete whose reason names the
//!   instance, the FMI call, the communication point and the signal or exit
//!   status; with a time limit on each call (`--step-timeout`) the parent
//!   kills (SIGKILL) a child whose call has lasted longer.
//!
//! Linux only (`mmap`, `prctl(PR_SET_PDEATHSIG)`), as is the host.

pub use fricsim_fmi::blackbox;
pub mod child;
pub mod parent;
pub mod ring;

use serde::{Deserialize, Serialize};

/// The hidden subcommand the child runs: `fricsim isolated-child
/// --run-dir DIR <the parent's arguments>`.
pub const CHILD_COMMAND: &str = "isolated-child";
/// The black box's file in the run's directory.
const BLACK_BOX_FILE: &str = "blackbox";
/// The row ring's file in the run's directory.
const RING_FILE: &str = "rows";

/// What the child tells the parent on its pipe, one JSON line each.
#[derive(Debug, Serialize, Deserialize)]
pub enum Message {
    /// The system is built and the ring made: the columns of the rows that
    /// follow, the instances (in the black box's order), and what the
    /// command needs besides ([`serde_json::Value`] of its choosing).
    Started {
        columns: Vec<String>,
        instances: Vec<String>,
        extra: serde_json::Value,
    },
    /// The run ended after `rows` rows, completed or stopped by an error
    /// the host reported (`error`); `extra` as in `Started`.
    Finished {
        rows: usize,
        error: Option<String>,
        extra: serde_json::Value,
    },
    /// The run could not start (bad file, bad option, failed
    /// initialization): the whole message.
    Failed { message: String },
}
