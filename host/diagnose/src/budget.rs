//! The diagnosis's time limit and what it shows of its progress.
//!
//! - `Budget` (crate-private, carried in the diagnosis's `Problem`): the
//!   deadline set by [`crate::Options::time_limit`] from the start of the
//!   diagnosis, the steps skipped or cut short because of it, the round
//!   that was in progress when it was reached, and the co-simulations run.
//!   The fits check it before each co-simulation (`Budget::stop_here`)
//!   and the stages before each step that costs
//!   (`Budget::skip_if_expired`), so the diagnosis ends soon after the
//!   limit and says what it left out ([`TimeLimit`], `report.json`'s
//!   `time_limit`).
//! - [`Progress`]: counters the diagnosis updates and a caller reads while
//!   it runs ([`Progress::snapshot`]), from another thread; the
//!   diagnosis itself prints nothing. `fricsim diagnose` and the Python
//!   package render them as one line on a terminal.

use crate::{CandidateScore, Options};
use serde::Serialize;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// The time limit of `fricsim diagnose`, the Python package and
/// [`Options::default`], in seconds of wall time.
pub const DEFAULT_TIME_LIMIT: f64 = 600.0;

/// Check a time limit in seconds: a positive number (infinity: none).
/// `Some(seconds)` when finite, `None` for no limit; the error names the
/// value.
pub fn check_time_limit(seconds: f64) -> Result<Option<f64>, String> {
    if seconds.is_nan() || seconds <= 0.0 {
        return Err(format!(
            "time limit {seconds}: must be a positive number of seconds (inf for none)"
        ));
    }
    Ok(seconds.is_finite().then_some(seconds))
}

/// What `report.json`'s `time_limit` says: the limit, whether it was
/// reached, and then what the diagnosis left out.
#[derive(Clone, Debug, Default, Serialize)]
pub struct TimeLimit {
    /// The limit in seconds of wall time (`None`: no limit).
    pub seconds: Option<f64>,
    /// The diagnosis reached the limit and stopped or shortened work
    /// because of it (then `unfinished` or `skipped` says what).
    pub reached: bool,
    /// The round that was in progress when the limit was reached
    /// (1-based, as in `rounds`); it was not decided: nothing of it was
    /// accepted, and it is not among `rounds`.
    pub round: Option<usize>,
    /// The candidates of that round whose fit or score did not finish
    /// within the limit: neither accepted nor rejected.
    pub unfinished: Vec<String>,
    /// The candidates of that round that did finish, with their scores
    /// against the current model (not decided on).
    pub finished: Vec<CandidateScore>,
    /// The steps skipped, or cut short, because the limit was reached, in
    /// the order the diagnosis came to them.
    pub skipped: Vec<String>,
}

impl TimeLimit {
    /// The candidates of the round the limit cut short, each written by
    /// `code` (Markdown or HTML) and joined with commas; what to say when
    /// there are none.
    pub fn unfinished_list(&self, code: impl Fn(&str) -> String) -> String {
        if self.unfinished.is_empty() {
            return "none (the round's decision was cut short)".to_string();
        }
        self.unfinished
            .iter()
            .map(|c| code(c))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The report's sentence when the limit was reached (`None`
    /// otherwise): what was left out, for report.md, report.html and the
    /// command's summary.
    pub fn sentence(&self) -> Option<String> {
        if !self.reached {
            return None;
        }
        let mut s = format!(
            "The diagnosis stopped at its time limit of {} s and reports what it had established by then (the baseline and the effects accepted before).",
            self.seconds.map_or("?".to_string(), |x| format!("{x}"))
        );
        if let Some(r) = self.round {
            s.push_str(&format!(" Round {r} was in progress and is not decided"));
            if !self.unfinished.is_empty() {
                s.push_str(&format!(
                    ": unfinished (neither accepted nor rejected): {}",
                    self.unfinished.join(", ")
                ));
            }
            if !self.finished.is_empty() {
                let names: Vec<&str> = self.finished.iter().map(|c| c.name.as_str()).collect();
                s.push_str(&format!("; finished, not decided on: {}", names.join(", ")));
            }
            s.push('.');
        }
        if !self.skipped.is_empty() {
            s.push_str(&format!(
                " Skipped or cut short: {}.",
                self.skipped.join("; ")
            ));
        }
        s.push_str(" A larger time limit (--time-limit) gives the whole diagnosis.");
        Some(s)
    }
}

/// The diagnosis's clock and time limit ([the module](self)).
pub(crate) struct Budget {
    deadline: Option<Instant>,
    reached: AtomicBool,
    /// Deadline checks inside a fit that stopped it ([`Budget::stop_here`]).
    cuts: AtomicUsize,
    report: Mutex<TimeLimit>,
    progress: Progress,
}

impl Budget {
    /// The clock started now, with the limit and the progress counters of
    /// `options` (counters of its own when the caller gave none).
    pub(crate) fn new(options: &Options) -> Budget {
        let started = Instant::now();
        let limit = options.time_limit.filter(|s| s.is_finite() && *s > 0.0);
        let progress = options.progress.clone().unwrap_or_default();
        progress.start(started, limit);
        Budget {
            // a limit beyond what an Instant can hold is none
            deadline: limit.and_then(|s| started.checked_add(Duration::try_from_secs_f64(s).ok()?)),
            reached: AtomicBool::new(false),
            cuts: AtomicUsize::new(0),
            report: Mutex::new(TimeLimit {
                seconds: limit,
                ..TimeLimit::default()
            }),
            progress,
        }
    }

    /// Whether the limit has passed (and then, from now on, reached).
    pub(crate) fn expired(&self) -> bool {
        if self.reached.load(Ordering::Relaxed) {
            return true;
        }
        let passed = self.deadline.is_some_and(|d| Instant::now() >= d);
        if passed {
            self.reached.store(true, Ordering::Relaxed);
        }
        passed
    }

    /// Inside a fit, before a co-simulation: whether to stop (the limit
    /// has passed); counted, so that a step can tell it was cut
    /// ([`Budget::cut_short`]).
    pub(crate) fn stop_here(&self) -> bool {
        let stop = self.expired();
        if stop {
            self.cuts.fetch_add(1, Ordering::Relaxed);
        }
        stop
    }

    /// Whether the limit has passed; if so, `what` is recorded as skipped.
    pub(crate) fn skip_if_expired(&self, what: impl FnOnce() -> String) -> bool {
        let expired = self.expired();
        if expired {
            self.skip(what());
        }
        expired
    }

    /// Record `what` as skipped or cut short.
    pub(crate) fn skip(&self, what: String) {
        let mut r = self.lock();
        if !r.skipped.contains(&what) {
            r.skipped.push(what);
        }
    }

    /// Run `f`, and record `what` as cut short when a fit in it stopped
    /// at the limit; returns its result and whether it was cut.
    pub(crate) fn cut_short<T>(
        &self,
        what: impl FnOnce() -> String,
        f: impl FnOnce() -> T,
    ) -> (T, bool) {
        let before = self.cuts.load(Ordering::Relaxed);
        let out = f();
        let cut = self.cuts.load(Ordering::Relaxed) != before;
        if cut {
            self.skip(format!("{} (cut short)", what()));
        }
        (out, cut)
    }

    /// The round `round` (1-based) stopped by the limit: its `unfinished`
    /// candidates and the scores of the `finished` ones.
    pub(crate) fn round_stopped(
        &self,
        round: usize,
        unfinished: Vec<String>,
        finished: Vec<CandidateScore>,
    ) {
        let mut r = self.lock();
        r.round = Some(round);
        r.unfinished = unfinished;
        r.finished = finished;
    }

    /// `report.json`'s `time_limit`.
    pub(crate) fn time_limit(&self) -> TimeLimit {
        let mut r = self.lock().clone();
        r.reached =
            self.reached.load(Ordering::Relaxed) && (r.round.is_some() || !r.skipped.is_empty());
        r
    }

    pub(crate) fn progress(&self) -> &Progress {
        &self.progress
    }

    /// One co-simulation started (counted for the progress and the
    /// report).
    pub(crate) fn cosimulation(&self) {
        self.progress
            .0
            .cosimulations
            .fetch_add(1, Ordering::Relaxed);
    }

    /// The co-simulations counted so far.
    pub(crate) fn cosimulations(&self) -> usize {
        self.progress.0.cosimulations.load(Ordering::Relaxed)
    }

    fn lock(&self) -> MutexGuard<'_, TimeLimit> {
        self.report.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Counters of a running diagnosis that its caller reads
/// ([`Progress::snapshot`]) while it runs, from another thread: the
/// diagnosis updates them and prints nothing. Give a clone in
/// [`Options::progress`]; clones share the counters.
#[derive(Clone, Default)]
pub struct Progress(Arc<Shared>);

impl std::fmt::Debug for Progress {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("Progress").field(&self.snapshot()).finish()
    }
}

#[derive(Default)]
struct Shared {
    cosimulations: AtomicUsize,
    state: Mutex<State>,
}

#[derive(Default)]
struct State {
    started: Option<Instant>,
    limit: Option<f64>,
    stage: String,
    round: Option<usize>,
    round_started: Option<Instant>,
    candidates: usize,
    done: usize,
    active: Vec<String>,
}

/// The progress of a diagnosis at one moment.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    /// What it is doing ("scoring the nominal", "round 2", ...).
    pub stage: String,
    /// The candidate round in progress (1-based), if any.
    pub round: Option<usize>,
    /// Candidates being fitted or scored now.
    pub active: Vec<String>,
    /// Candidates of the round done, and in the round.
    pub done: usize,
    pub candidates: usize,
    /// Co-simulations run so far.
    pub cosimulations: usize,
    /// Wall time since the diagnosis started.
    pub elapsed: Duration,
    /// An estimate of the time left in the round: its candidates not done
    /// times the wall time per candidate done so far (none before the
    /// first is done).
    pub round_left: Option<Duration>,
    /// The time limit (s).
    pub limit: Option<f64>,
}

impl Snapshot {
    /// The progress as one line, what matters first (a terminal may cut
    /// its end): `round 2 (single effects); 412 co-simulations, 35 s
    /// elapsed; 3 of 9 candidates done, about 40 s left in this round
    /// (estimate); fitting viscous, stribeck; time limit 600 s, 565 s to
    /// go`.
    pub fn line(&self) -> String {
        let mut s = if self.stage.is_empty() {
            "starting".to_string()
        } else {
            self.stage.clone()
        };
        s.push_str(&format!(
            "; {} co-simulation{}, {} elapsed",
            self.cosimulations,
            if self.cosimulations == 1 { "" } else { "s" },
            seconds(self.elapsed)
        ));
        if self.round.is_some() && self.candidates > 0 {
            s.push_str(&format!(
                "; {} of {} candidates done",
                self.done.min(self.candidates),
                self.candidates
            ));
            if let Some(left) = self.round_left {
                s.push_str(&format!(
                    ", about {} left in this round (estimate)",
                    seconds(left)
                ));
            }
        }
        if !self.active.is_empty() {
            s.push_str(&format!("; fitting {}", self.active.join(", ")));
        }
        if let Some(limit) = self.limit {
            let to_go = Duration::try_from_secs_f64(limit)
                .map_or(Duration::ZERO, |l| l.saturating_sub(self.elapsed));
            s.push_str(&format!("; time limit {limit} s, {} to go", seconds(to_go)));
        }
        s
    }
}

/// `0.4 s`, `35 s`, `4 min 10 s`.
fn seconds(d: Duration) -> String {
    let s = d.as_secs();
    if s < 10 {
        format!("{:.1} s", d.as_secs_f64())
    } else if s < 60 {
        format!("{s} s")
    } else {
        format!("{} min {} s", s / 60, s % 60)
    }
}

impl Progress {
    /// Fresh counters.
    pub fn new() -> Progress {
        Progress::default()
    }

    /// The progress now.
    pub fn snapshot(&self) -> Snapshot {
        let st = self.state();
        let now = Instant::now();
        let left = self.round_left(&st, now);
        Snapshot {
            stage: st.stage.clone(),
            round: st.round,
            active: st.active.clone(),
            done: st.done,
            candidates: st.candidates,
            cosimulations: self.0.cosimulations.load(Ordering::Relaxed),
            elapsed: st.started.map_or(Duration::ZERO, |t| now - t),
            round_left: left,
            limit: st.limit,
        }
    }

    /// Say what the diagnosis (or its caller: "writing the report") is
    /// doing now; ends a round.
    pub fn stage(&self, stage: impl Into<String>) {
        let mut st = self.state();
        st.stage = stage.into();
        st.round = None;
        st.round_started = None;
        st.candidates = 0;
        st.done = 0;
        st.active.clear();
    }

    fn start(&self, started: Instant, limit: Option<f64>) {
        self.0.cosimulations.store(0, Ordering::Relaxed);
        let mut st = self.state();
        *st = State {
            started: Some(started),
            limit,
            ..State::default()
        };
    }

    /// Round `round` (1-based) of `candidates` starts.
    pub(crate) fn round(&self, round: usize, kind: &str, candidates: usize) {
        self.stage(format!("round {round} ({kind})"));
        let mut st = self.state();
        st.round = Some(round);
        st.round_started = Some(Instant::now());
        st.candidates = candidates;
    }

    /// Candidate `name` is being fitted and scored.
    pub(crate) fn candidate_started(&self, name: &str) {
        self.state().active.push(name.to_string());
    }

    /// Candidate `name` is done.
    pub(crate) fn candidate_done(&self, name: &str) {
        let mut st = self.state();
        if let Some(k) = st.active.iter().position(|a| a == name) {
            st.active.remove(k);
        }
        st.done += 1;
    }

    fn round_left(&self, st: &State, now: Instant) -> Option<Duration> {
        let started = st.round_started?;
        if st.done == 0 || st.done >= st.candidates {
            return None;
        }
        let per = (now - started).as_secs_f64() / st.done as f64;
        Duration::try_from_secs_f64(per * (st.candidates - st.done) as f64).ok()
    }

    fn state(&self) -> MutexGuard<'_, State> {
        self.0.state.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_time_limit_must_be_positive_and_infinity_is_none() {
        assert_eq!(check_time_limit(2.5), Ok(Some(2.5)));
        assert_eq!(check_time_limit(f64::INFINITY), Ok(None));
        for bad in [0.0, -1.0, f64::NAN, f64::NEG_INFINITY] {
            let e = check_time_limit(bad).unwrap_err();
            assert!(e.contains(&format!("{bad}")), "{e}");
        }
    }

    #[test]
    fn a_budget_expires_once_and_stays_expired() {
        let options = Options {
            time_limit: Some(1e-9),
            ..Options::default()
        };
        let b = Budget::new(&options);
        std::thread::sleep(Duration::from_millis(2));
        assert!(b.stop_here());
        let (_, cut) = b.cut_short(|| "a fit".into(), || b.stop_here());
        assert!(cut);
        assert!(b.skip_if_expired(|| "a step".into()));
        let t = b.time_limit();
        assert!(t.reached);
        assert_eq!(t.skipped, ["a fit (cut short)", "a step"]);
        assert!(t.sentence().unwrap().contains("a step"));
        let none = Budget::new(&Options {
            time_limit: None,
            ..Options::default()
        });
        assert!(!none.expired() && !none.time_limit().reached);
        assert_eq!(none.time_limit().sentence(), None);
    }

    #[test]
    fn the_progress_line_names_the_round_and_estimates_what_is_left() {
        let progress = Progress::new();
        let options = Options {
            progress: Some(progress.clone()),
            ..Options::default()
        };
        let b = Budget::new(&options);
        b.progress().round(2, "single effects", 3);
        b.progress().candidate_started("viscous");
        b.progress().candidate_started("stribeck");
        b.cosimulation();
        b.progress().candidate_done("viscous");
        let s = progress.snapshot();
        assert_eq!(s.round, Some(2));
        assert_eq!(s.active, ["stribeck"]);
        assert_eq!((s.done, s.candidates, s.cosimulations), (1, 3, 1));
        assert!(s.round_left.is_some());
        let line = s.line();
        for part in [
            "round 2",
            "fitting stribeck",
            "1 of 3 candidates done",
            "1 co-simulation,",
            "(estimate)",
            "time limit 600 s",
        ] {
            assert!(line.contains(part), "{part}: {line}");
        }
    }
}
