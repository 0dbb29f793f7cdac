//! What a killed run leaves behind, and its removal by a later run.
//!
//! A run killed with SIGKILL, or one whose process crashes, runs no
//! destructor: its temporary result file (`.<name>.fricsim-partial-<pid>`,
//! the host's result files, `fricsim_core::output_file`) and the folders its FMUs were unpacked into
//! (`fricsim-fmu-<pid>-XXXXXX` in the temporary directory,
//! [`crate::archive`]) stay. Both names carry the pid of the process
//! that made them, so a later run can tell which ones belong to a process
//! that no longer runs and remove them. A process that still runs, or
//! whose pid cannot be checked (another user's: `kill` answers `EPERM`),
//! keeps its files.

use std::path::Path;

/// Whether no process has the id `pid` (`kill(pid, 0)` fails with
/// `ESRCH`, kill(2)).
pub fn process_gone(pid: libc::pid_t) -> bool {
    // SAFETY: signal 0 sends nothing, it only checks the pid
    pid > 0
        && unsafe { libc::kill(pid, 0) } != 0
        && std::io::Error::last_os_error().raw_os_error() == Some(libc::ESRCH)
}

/// The pid in `name` if it is `<prefix><pid>` or `<prefix><pid>-<rest>`.
pub fn pid_in(name: &str, prefix: &str) -> Option<libc::pid_t> {
    let rest = name.strip_prefix(prefix)?;
    let digits = rest.find('-').map_or(rest, |end| &rest[..end]);
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse().ok()
}

/// Remove the entries of `dir` named `<prefix><pid>…` ([`pid_in`]) whose
/// process no longer runs, with `remove` (a file or a folder); errors are
/// ignored (the entry stays for the next run).
pub fn remove_left_by_gone_processes(
    dir: &Path,
    prefix: &str,
    remove: fn(&Path) -> std::io::Result<()>,
) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let gone = name
            .to_str()
            .and_then(|n| pid_in(n, prefix))
            .is_some_and(process_gone);
        if gone {
            let _ = remove(&entry.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pid_is_read_from_both_forms_of_name() {
        assert_eq!(
            pid_in(".r.csv.fricsim-partial-4242", ".r.csv.fricsim-partial-"),
            Some(4242)
        );
        assert_eq!(pid_in("fricsim-fmu-17-a8Xk2q", "fricsim-fmu-"), Some(17));
        // the folders of earlier versions, without a pid
        assert_eq!(pid_in("fricsim-fmu-a8Xk2q", "fricsim-fmu-"), None);
        assert_eq!(pid_in("fricsim-fmu--3-x", "fricsim-fmu-"), None);
        assert_eq!(pid_in("fricsim-fmu-", "fricsim-fmu-"), None);
        assert_eq!(pid_in("other-17", "fricsim-fmu-"), None);
    }

    #[test]
    fn a_running_process_is_not_gone() {
        assert!(!process_gone(std::process::id() as libc::pid_t));
        // pid 0 and negative pids name process groups, never "gone"
        assert!(!process_gone(0));
        assert!(!process_gone(-1));
    }
}
