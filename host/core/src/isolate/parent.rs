//! The parent's side of an isolated run: start the child, hand its rows to
//! a [`RowSink`] as they come, stop a call that lasts too long, and say
//! how the child ended.

use super::blackbox::{BlackBox, CallRecord};
use super::ring::RowRing;
use super::{Message, BLACK_BOX_FILE, CHILD_COMMAND, RING_FILE};
use crate::master::RowSink;
use std::ffi::OsString;
use std::io::BufRead;
use std::os::unix::process::ExitStatusExt;
use std::path::PathBuf;
use std::process::{Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// How often the parent looks at the ring, the pipe and the child when
/// nothing came.
const POLL: Duration = Duration::from_millis(2);

/// How an isolated run went, as the parent saw it.
pub struct Outcome<S> {
    /// The sink made when the run started, with every row the child sent.
    pub sink: Option<S>,
    /// `Started`'s columns and `extra`.
    pub columns: Vec<String>,
    pub started: Option<serde_json::Value>,
    /// `Finished`'s rows, error and `extra`, if the child got that far.
    pub finished: Option<(usize, Option<String>, serde_json::Value)>,
    /// Why the run could not start (`Failed`).
    pub failed: Option<String>,
    /// How the child ended before `Finished`: the instance, the call, the
    /// communication point, the signal or exit status (or the time limit).
    pub died: Option<String>,
    /// The rows the sink received.
    pub rows: usize,
}

impl<S> Outcome<S> {
    /// Why the run stopped before its end, if it did: the host's error
    /// or the child's death.
    pub fn error(&self) -> Option<String> {
        match (&self.died, &self.finished) {
            (Some(d), _) => Some(d.clone()),
            (None, Some((_, e, _))) => e.clone(),
            (None, None) => None,
        }
    }
}

/// Run `fricsim isolated-child --run-dir DIR ARGS` and follow it: `ARGS`
/// are the parent's own arguments (the subcommand and its options), `limit`
/// the time limit on each FMI call. When the child says the run started,
/// `make_sink(columns, extra)` makes the sink of its rows (an error there
/// stops the child).
pub fn run_isolated<S: RowSink>(
    args: &[OsString],
    limit: Option<Duration>,
    make_sink: impl FnOnce(&[String], &serde_json::Value) -> Result<S, String>,
) -> Result<Outcome<S>, String> {
    let dir = tempfile::Builder::new()
        .prefix("fricsim-isolated-")
        .tempdir()
        .map_err(|e| format!("cannot make the isolated run's directory: {e}"))?;
    let black_box = BlackBox::create(&dir.path().join(BLACK_BOX_FILE))
        .map_err(|e| format!("cannot make the isolated run's black box: {e}"))?;
    let exe = std::env::current_exe()
        .map_err(|e| format!("cannot find fricsim's own binary to start the child: {e}"))?;
    let mut child = Command::new(&exe)
        .arg(CHILD_COMMAND)
        .arg("--run-dir")
        .arg(dir.path())
        .args(args)
        .env("TMPDIR", dir.path())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|e| format!("cannot start {}: {e}", exe.display()))?;
    let pipe = child.stdout.take().expect("stdout is piped");
    let (messages, received) = mpsc::channel();
    let reader = std::thread::spawn(move || {
        for line in std::io::BufReader::new(pipe).lines() {
            let Ok(line) = line else { break };
            let message = serde_json::from_str::<Message>(&line)
                .map_err(|e| format!("the isolated child sent `{line}`: {e}"));
            if messages.send(message).is_err() {
                break;
            }
        }
    });

    let outcome = Outcome {
        sink: None,
        columns: Vec::new(),
        started: None,
        finished: None,
        failed: None,
        died: None,
        rows: 0,
    };
    let mut follow = Follow {
        outcome,
        make_sink: Some(make_sink),
        ring: None,
        ring_path: dir.path().join(RING_FILE),
        instances: Vec::new(),
        error: None,
    };
    let mut hang = Hang::default();
    let status = loop {
        let mut busy = follow.take_rows();
        while let Ok(message) = received.try_recv() {
            busy = true;
            follow.receive(message);
        }
        if let Some(e) = &follow.error {
            // the parent cannot take the rows: the child is stopped
            let _ = child.kill();
            let _ = child.wait();
            let _ = reader.join();
            return Err(e.clone());
        }
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) => {}
            Err(e) => return Err(format!("cannot follow the isolated child: {e}")),
        }
        if let Some(limit) = limit {
            if let Some(call) = hang.over(&black_box.read(), limit) {
                let _ = child.kill();
                let _ = child.wait();
                follow.outcome.died = Some(format!(
                    "{} for more than the limit of {} s (--step-timeout): the FMU process was killed (SIGKILL)",
                    where_(&call, &follow.instances, "was in"),
                    limit.as_secs_f64()
                ));
                break ExitStatus::from_raw(libc::SIGKILL);
            }
        }
        if !busy {
            std::thread::sleep(POLL);
        }
    };
    // what the child said and stored before it ended, in order: it may
    // have started, run and died between two looks
    let _ = reader.join();
    for message in received.try_iter() {
        follow.receive(message);
    }
    follow.take_rows();
    if let Some(e) = follow.error {
        return Err(e);
    }
    let mut outcome = follow.outcome;
    if let Some((rows, _, _)) = &outcome.finished {
        if *rows != outcome.rows {
            return Err(format!(
                "the isolated child ran {rows} rows but the parent received {}",
                outcome.rows
            ));
        }
    }
    if outcome.died.is_none() && outcome.finished.is_none() && outcome.failed.is_none() {
        outcome.died = Some(death(&black_box.read(), &follow.instances, status));
    }
    Ok(outcome)
}

/// What the parent has from the child so far.
struct Follow<S, F> {
    outcome: Outcome<S>,
    /// Makes the sink when the child says the run started.
    make_sink: Option<F>,
    ring: Option<RowRing>,
    ring_path: PathBuf,
    instances: Vec<String>,
    /// Why the parent cannot go on (the sink failed, the child's message
    /// or ring is unreadable).
    error: Option<String>,
}

impl<S, F> Follow<S, F>
where
    S: RowSink,
    F: FnOnce(&[String], &serde_json::Value) -> Result<S, String>,
{
    /// Take a message of the child's.
    fn receive(&mut self, message: Result<Message, String>) {
        match message {
            Ok(Message::Started {
                columns,
                instances,
                extra,
            }) => {
                self.instances = instances;
                match self.make_sink.take().map(|f| f(&columns, &extra)) {
                    Some(Ok(sink)) => self.outcome.sink = Some(sink),
                    Some(Err(e)) => self.error = Some(e),
                    None => {}
                }
                self.outcome.started = Some(extra);
                self.outcome.columns = columns;
                match RowRing::open(&self.ring_path) {
                    Ok(r) => self.ring = Some(r),
                    Err(e) => self.error = Some(format!("cannot map the child's rows: {e}")),
                }
            }
            Ok(Message::Finished { rows, error, extra }) => {
                self.outcome.finished = Some((rows, error, extra))
            }
            Ok(Message::Failed { message }) => self.outcome.failed = Some(message),
            Err(e) => self.error = Some(e),
        }
    }

    /// Hand the rows in the ring (once made) to the sink: whether there
    /// were any.
    fn take_rows(&mut self) -> bool {
        let (Some(ring), Some(sink)) = (&self.ring, &mut self.outcome.sink) else {
            return false;
        };
        let (times, rows) = ring.take();
        if times.is_empty() {
            return false;
        }
        self.outcome.rows += times.len();
        if let Err(e) = sink.write(&times, &rows) {
            self.error.get_or_insert(e);
        }
        true
    }
}

/// The call the child is in, and since when the parent has seen it.
#[derive(Default)]
struct Hang {
    seen: Option<(u64, Instant)>,
}

impl Hang {
    /// `record` if one call has lasted longer than `limit`.
    fn over(&mut self, record: &CallRecord, limit: Duration) -> Option<CallRecord> {
        if record.instance.is_none() {
            self.seen = None;
            return None;
        }
        match self.seen {
            Some((calls, since)) if calls == record.calls => {
                (since.elapsed() > limit).then(|| record.clone())
            }
            _ => {
                self.seen = Some((record.calls, Instant::now()));
                None
            }
        }
    }
}

/// `instance "belt" <verb> fmi2DoStep at t = 0.5 s`, from the black box.
fn where_(call: &CallRecord, instances: &[String], verb: &str) -> String {
    let at = match call.time {
        Some(t) if call.function == "fmi2DoStep" => format!(" at t = {t} s"),
        Some(t) => format!(" (after fmi2DoStep at t = {t} s)"),
        None => String::new(),
    };
    match call.instance {
        Some(i) => {
            let name = instances
                .get(i)
                .map(|n| format!("\"{n}\""))
                .unwrap_or_else(|| format!("number {}", i + 1));
            format!("instance {name} {verb} {}{at}", call.function)
        }
        None if call.calls == 0 => "before any FMI call".to_string(),
        None => format!(
            "outside any FMI call (the last begun: {}){at}",
            call.function
        ),
    }
}

/// Why the child ended without finishing, in words: where (from the
/// black box) and how (the signal or the exit status).
fn death(call: &CallRecord, instances: &[String], status: ExitStatus) -> String {
    let (verb, how) = match (status.signal(), status.code()) {
        (Some(s), _) => (
            "crashed in",
            format!(
                "the FMU process was killed by signal {s} ({})",
                signal_name(s)
            ),
        ),
        (None, Some(c)) => (
            "ended the process in",
            format!("the FMU process exited with status {c} before the run finished"),
        ),
        (None, None) => (
            "ended the process in",
            "the FMU process ended before the run finished".to_string(),
        ),
    };
    format!("{}: {how}", where_(call, instances, verb))
}

fn signal_name(signal: i32) -> &'static str {
    match signal {
        libc::SIGSEGV => "SIGSEGV",
        libc::SIGABRT => "SIGABRT",
        libc::SIGBUS => "SIGBUS",
        libc::SIGFPE => "SIGFPE",
        libc::SIGILL => "SIGILL",
        libc::SIGKILL => "SIGKILL",
        libc::SIGTERM => "SIGTERM",
        libc::SIGINT => "SIGINT",
        libc::SIGPIPE => "SIGPIPE",
        _ => "a signal",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn in_step(calls: u64) -> CallRecord {
        CallRecord {
            calls,
            instance: Some(1),
            function: "fmi2DoStep".into(),
            time: Some(0.5),
        }
    }

    #[test]
    fn a_death_names_the_instance_the_call_the_time_and_the_cause() {
        let names = ["rig".to_string(), "belt".to_string()];
        assert_eq!(
            death(&in_step(3), &names, ExitStatus::from_raw(libc::SIGBUS)),
            "instance \"belt\" crashed in fmi2DoStep at t = 0.5 s: the FMU process was killed by signal 7 (SIGBUS)"
        );
        // exit(3): status 3 << 8
        assert_eq!(
            death(&in_step(3), &names, ExitStatus::from_raw(3 << 8)),
            "instance \"belt\" ended the process in fmi2DoStep at t = 0.5 s: the FMU process exited with status 3 before the run finished"
        );
        let between = CallRecord {
            instance: None,
            function: "fmi2GetReal".into(),
            ..in_step(4)
        };
        assert_eq!(
            death(&between, &names, ExitStatus::from_raw(libc::SIGSEGV)),
            "outside any FMI call (the last begun: fmi2GetReal) (after fmi2DoStep at t = 0.5 s): the FMU process was killed by signal 11 (SIGSEGV)"
        );
        let never = CallRecord {
            calls: 0,
            instance: None,
            function: String::new(),
            time: None,
        };
        assert!(death(&never, &[], ExitStatus::from_raw(0)).starts_with("before any FMI call: "));
    }

    #[test]
    fn a_hang_is_one_call_lasting_past_the_limit_not_many_short_ones() {
        let mut hang = Hang::default();
        let limit = Duration::from_millis(30);
        // many calls, each seen once: never over the limit
        for calls in 0..5 {
            assert_eq!(hang.over(&in_step(calls), limit), None);
            std::thread::sleep(Duration::from_millis(10));
        }
        // the same call seen again after the limit
        assert_eq!(hang.over(&in_step(9), limit), None);
        std::thread::sleep(limit * 2);
        assert_eq!(hang.over(&in_step(9), limit), Some(in_step(9)));
        // between calls: nothing is running
        let idle = CallRecord {
            instance: None,
            ..in_step(9)
        };
        assert_eq!(hang.over(&idle, limit), None);
    }
}
