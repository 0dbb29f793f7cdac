//! `fricsim run --isolate` and `cosim --isolate`, the parent's side and
//! what both sides share: the FMUs in a child process
//! ([`fricsim::isolate`]). The parent claims the result file before the
//! child starts, writes the rows, the plot and the summary as the command
//! does in-process; the child (the hidden subcommand `isolated-child`,
//! the module `child`) builds the system and runs it. Used by `run` and
//! `cosim`; names neither of them.

use fricsim::isolate::parent;
use fricsim::master::{Ended, RowSink};
use serde::{de::DeserializeOwned, Serialize};

/// What the child adds when the run ends.
#[derive(serde::Serialize, serde::Deserialize, Default)]
pub struct Ending {
    pub master_report: Option<String>,
    /// Seconds the run took in the child.
    pub wall: f64,
    /// The instance that ended the run before its stop time and the time
    /// it reached ([`Ended`]), if one did.
    pub ended: Option<(String, f64)>,
}

impl Ending {
    pub fn ended(&self) -> Option<Ended> {
        self.ended
            .clone()
            .map(|(instance, time)| Ended { instance, time })
    }
}

/// An isolated run as the parent saw it end.
pub struct Isolated<P, S> {
    /// What the child sent when the run started.
    pub plan: P,
    /// The sink, with every row the child sent.
    pub sink: S,
    pub columns: Vec<String>,
    /// Rows received (every communication point the child completed).
    pub rows: usize,
    /// Why the run stopped before its end: the host's error or the
    /// child's death.
    pub error: Option<String>,
    pub ending: Ending,
}

/// `--isolate`: start the child with this process's own arguments; when
/// it has started, `make_sink(columns, plan)` makes the sink of its rows.
pub fn run_isolated<P: DeserializeOwned, S: RowSink>(
    step_timeout: Option<f64>,
    make_sink: impl FnOnce(&[String], &P) -> Result<S, String>,
) -> Result<Isolated<P, S>, String> {
    let limit = super::call_time_limit(step_timeout)?;
    let args: Vec<_> = std::env::args_os().skip(1).collect();
    let started = std::time::Instant::now();
    let outcome = parent::run_isolated(&args, limit, |columns, plan| {
        let plan: P = serde_json::from_value(plan.clone()).map_err(|e| e.to_string())?;
        make_sink(columns, &plan)
    })?;
    if let Some(message) = &outcome.failed {
        return Err(message.clone());
    }
    let error = outcome.error();
    let (Some(sink), Some(Ok(plan))) = (
        outcome.sink,
        outcome.started.map(serde_json::from_value::<P>),
    ) else {
        return Err(format!(
            "the run did not start: {}",
            error.unwrap_or_else(|| "the FMU process ended".to_string())
        ));
    };
    let ending = match outcome.finished.map(|f| serde_json::from_value(f.2)) {
        Some(Ok(ending)) => ending,
        _ => Ending {
            wall: started.elapsed().as_secs_f64(),
            ..Ending::default()
        },
    };
    Ok(Isolated {
        plan,
        sink,
        columns: outcome.columns,
        rows: outcome.rows,
        error,
        ending,
    })
}

/// `value` as the JSON of a message to the parent.
pub fn json(value: impl Serialize) -> Result<serde_json::Value, String> {
    serde_json::to_value(value).map_err(|e| e.to_string())
}
