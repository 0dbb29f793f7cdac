//! The rounds at the time limit ([`crate::budget`]): a candidate not
//! started before the limit, or whose fit and score ended after it, is
//! unfinished; a round with an unfinished candidate is not decided:
//! nothing of it is accepted, its candidates are not reported as
//! rejected, and the search ends (the report's `time_limit` names the
//! unfinished ones and scores the finished ones).

use super::{candidate_score, label, Outcome, Search, Tried};
use crate::model::Effect;
use crate::stages::problem::Problem;

impl Tried {
    /// `added`, not started: the time limit had passed.
    pub(super) fn not_started(added: &[Effect], by_output_error: bool) -> Tried {
        Tried {
            by_output_error,
            added: added.to_vec(),
            models: Vec::new(),
            force_rms: f64::NAN,
            evaluations: 0,
            scored: Err("not started: the time limit was reached".into()),
            set_aside: None,
            unfinished: true,
        }
    }
}

/// When a candidate of `tried` is unfinished: the round (the next of
/// `s`) recorded as stopped by the time limit, and the outcome that ends
/// the search; `None` when every candidate finished.
pub(super) fn stopped(
    p: &Problem,
    s: &Search,
    tried: &[Tried],
    group: &[usize],
) -> Result<Option<Outcome>, String> {
    if !tried.iter().any(|t| t.unfinished) {
        return Ok(None);
    }
    stop(p, s, tried, group).map(Some)
}

/// The round (the next of `s`) recorded as stopped by the time limit:
/// the unfinished candidates of `tried` named, the finished ones scored.
pub(super) fn stop(
    p: &Problem,
    s: &Search,
    tried: &[Tried],
    group: &[usize],
) -> Result<Outcome, String> {
    let unfinished = tried
        .iter()
        .filter(|t| t.unfinished)
        .map(|t| label(&t.added))
        .collect();
    let finished = tried
        .iter()
        .filter(|t| !t.unfinished)
        .map(|t| candidate_score(p, s, t, group))
        .collect::<Result<Vec<_>, String>>()?;
    p.budget
        .round_stopped(s.rounds.len() + 1, unfinished, finished);
    Ok(Outcome::Stopped)
}
