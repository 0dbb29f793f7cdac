//! The output directory of `fricsim diagnose`: `report.json`, `report.md`,
//! `report.html` (self-contained, [`super::html`]) with its figures also as
//! PNG ([`super::figures`]), `refitted.ssp` (the system with the refitted
//! friction parameters, runnable by `fricsim run` and FMPy) and
//! `inputs.csv` (the data's input columns, to rerun it). Everything is written into a temporary sibling directory first
//! and renamed into place at the end, so a failure leaves nothing half
//! written.

use super::memory::{moved, LawCheck, LawModel, MemoryOutcome, OtherLaw};
use super::Diagnosis;
use crate::ssp::SystemFile;
use quick_xml::events::{BytesEnd, BytesStart, Event};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Write every output into `out` (replacing an earlier diagnose output
/// there; refusing any other existing directory).
pub fn write(d: &Diagnosis, file: &SystemFile, friction: &str, out: &Path) -> Result<(), String> {
    if out.exists() && !out.join("report.json").exists() {
        return Err(format!(
            "{}: exists and is not an earlier diagnose output (no report.json); choose another directory",
            out.display()
        ));
    }
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    let tmp = tempfile::Builder::new()
        .prefix(".diagnose-")
        .tempdir_in(parent)
        .map_err(|e| {
            format!(
                "{}: cannot create a temporary directory: {e}",
                parent.display()
            )
        })?;
    let dir = tmp.path();
    let mut d = d.clone();
    d.rerun = rerun_commands(&d, out);
    let d = &d;
    let json = serde_json::to_string_pretty(d).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("report.json"), json + "\n").map_err(|e| e.to_string())?;
    std::fs::write(dir.join("report.md"), markdown(d)).map_err(|e| e.to_string())?;
    let figures = super::figures::draw_all(d, dir)?;
    for (inputs, name, _) in input_files(d) {
        write_inputs(inputs, &dir.join(name))?;
    }
    write_ssp(
        file,
        friction,
        &d.final_model.parameters(),
        &dir.join("refitted.ssp"),
    )?;
    if let Some((m, fitted, path)) =
        moved(&d.memory).and_then(|m| Some((m, m.fitted.as_ref()?, m.fmu.as_ref()?)))
    {
        let moved = super::memory::moved_to(file, friction, path)?;
        let name = format!("refitted-{}.ssp", m.law.file_tag());
        write_ssp(&moved, friction, &fitted.parameters(), &dir.join(name))?;
    }
    std::fs::write(
        dir.join("report.html"),
        super::html::page(d, &figures, &d.rerun, d.min_gain),
    )
    .map_err(|e| e.to_string())?;
    if out.exists() {
        std::fs::remove_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    }
    let kept: PathBuf = tmp.keep();
    std::fs::rename(&kept, out).map_err(|e| format!("{}: {e}", out.display()))?;
    Ok(())
}

/// The sentence on the effects a move explains (empty when none).
fn explained(m: &LawCheck) -> String {
    if m.explains.is_empty() {
        return String::new();
    }
    let law = m.law.model_name();
    let names: Vec<&str> = m.explains.iter().map(|e| e.name()).collect();
    if m.from_baseline {
        return format!(
            " It was fitted from the baseline, before the effects found under LuGre ({}): fitted from the final LuGre model it did not pass, so they are taken as its signature and not named.",
            names.join(", ")
        );
    }
    match m.explains_p_value {
        Some(p) => format!(
            " The effects found under LuGre ({}) stood in for it: {law} fitted from the baseline, before them, predicts the held-out data as well as from the final model (p = {p:.2e} that the final model's start does better), so it starts from the baseline and they are not named.",
            names.join(", ")
        ),
        None => format!(
            " The pre-sliding stiffness found under LuGre ({}) is {law}'s own σ0, fitted again by the move: not named apart.",
            names.join(", ")
        ),
    }
}

/// What the checks of the other laws found, one sentence each.
pub fn memory_words(checks: &[LawCheck]) -> String {
    let mut words = Vec::new();
    for m in checks {
        let name = m.law.model_name();
        let compared = || {
            format!(
                "held-out RMS {:.5} with LuGre, {:.5} with {name} ({} of the mean square, p = {:.2e}, threshold {:.2e})",
                m.lugre_heldout_rms,
                m.heldout_rms,
                pct(m.lugre_heldout_rms.powi(2), m.heldout_rms.powi(2)),
                m.p_value,
                m.threshold
            )
        };
        words.push(match m.outcome {
            MemoryOutcome::Moved => format!(
                "**{}** (`{}`): the held-out data prefer {} to LuGre's pre-sliding: {}. The nominal moves to {name}: {}.",
                match m.law {
                    OtherLaw::Gms => "Pre-sliding memory",
                    OtherLaw::ElastoPlastic => "Elastic pre-sliding",
                },
                m.effect,
                m.law.words(),
                compared(),
                m.fitted.as_ref().map_or(String::new(), LawModel::describe)
            ) + &explained(m),
            MemoryOutcome::Kept => format!(
                "{name} (with the final model's levels as its start) does not replace LuGre: {}.{}",
                compared(),
                m.reason.as_ref().map_or(String::new(), |r| format!(" {}.", r.trim_end_matches('.')))
            ),
            MemoryOutcome::NotTried => format!(
                "{name} was not tried: {}.",
                m.reason.as_deref().unwrap_or("no reason recorded").trim_end_matches('.')
            ),
        });
    }
    words.join(" ")
}

/// The relative change from `before` to `after`, signed, in per cent
/// ("n/a" without a positive `before` or a finite `after`).
pub(super) fn pct(before: f64, after: f64) -> String {
    if before > 0.0 && after.is_finite() {
        format!("{:+.1} %", 100.0 * (after - before) / before)
    } else {
        "n/a".into()
    }
}

/// The readable report.
pub fn markdown(d: &Diagnosis) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Diagnosis of {}\n", d.system);
    let _ = writeln!(s, "- measurements: {} ({} samples)", d.data, d.samples);
    let _ = writeln!(
        s,
        "- held out: {} ({} samples compared)",
        d.heldout, d.heldout_samples
    );
    let _ = writeln!(s, "- friction force from the data: {}", d.force_source);
    let _ = writeln!(
        s,
        "- co-simulation: {} at {} s; {:.2} s wall time, {} co-simulations",
        d.master, d.step, d.wall_seconds, d.cosimulations
    );
    let _ = writeln!(s, "- output-error Jacobian: {}", d.output_jacobian);
    let _ = writeln!(s, "- time limit: {}\n", time_limit_words(&d.time_limit));
    let _ = writeln!(s, "## Result\n");
    if let Some(sentence) = d.time_limit.sentence() {
        let _ = writeln!(s, "**Time limit reached.** {sentence}\n");
    }
    for note in &d.notes {
        let _ = writeln!(s, "Note: {}.\n", note.trim_end_matches('.'));
    }
    if d.effects.is_empty() && d.time_limit.reached {
        let _ = writeln!(
            s,
            "No effect was accepted before the time limit was reached (not every candidate was decided on)."
        );
    } else if d.effects.is_empty() {
        let _ = writeln!(
            s,
            "No effect of the library improves the model significantly on the held-out data."
        );
    } else {
        let names: Vec<String> = d
            .effects
            .iter()
            .map(|e| format!("**{}** ({})", e.name.name(), e.action))
            .collect();
        let _ = writeln!(
            s,
            "Missing or mis-sized effect(s), in the order found: {}.",
            names.join(", ")
        );
    }
    let _ = writeln!(
        s,
        "\nHeld-out RMS error (each channel divided by its standard deviation, then averaged in the mean square):\n\n| model | held-out RMS | against the given model |\n| --- | --- | --- |\n| nominal as given | {:.5} | |\n| nominal, levels refitted | {} | {} |\n| final | {:.5} | {} |",
        d.nominal_rms,
        if d.refit.heldout_rms.is_finite() {
            format!("{:.5}", d.refit.heldout_rms)
        } else if d.refit.unfinished {
            "not finished".into()
        } else {
            "failed".into()
        },
        match (&d.refit.failure, d.refit.kept) {
            _ if d.refit.unfinished => {
                "not kept: the time limit was reached before the refit finished".into()
            }
            (Some(e), _) => format!("not kept: its co-simulation failed ({})", e.replace('|', "/")),
            (None, true) => format!(
                "{}; kept as the baseline (p = {:.2e} < {:.2e})",
                pct(d.nominal_rms, d.refit.heldout_rms),
                d.refit.p_value,
                d.refit.threshold
            ),
            (None, false) => format!(
                "{}; not kept (p = {:.2e}, threshold {:.2e}): the baseline is the nominal as given",
                pct(d.nominal_rms, d.refit.heldout_rms),
                d.refit.p_value,
                d.refit.threshold
            ),
        },
        d.final_rms,
        pct(d.nominal_rms, d.final_rms),
    );
    if let Some(m) = moved(&d.memory) {
        let _ = writeln!(
            s,
            "| final, moved to {} | {:.5} | {} |",
            m.law.model_name(),
            m.heldout_rms,
            pct(d.nominal_rms, m.heldout_rms)
        );
    }
    let _ = writeln!(s, "\n{}", memory_words(&d.memory));
    let _ = writeln!(
        s,
        "\nFloor: measurement noise and quantisation {:.5}, the co-simulation's step error {:.5}, together {:.5}.",
        d.noise_floor_rms, d.step_error_rms, d.floor_rms
    );
    if d.unexplained {
        let _ = writeln!(
            s,
            "\n**Unexplained**: the final error is more than {} times the floor and {}. The remaining residual is largest in: {}.",
            super::UNEXPLAINED_FACTOR,
            if d.time_limit.reached {
                "the diagnosis stopped at the time limit before it could try every candidate"
            } else {
                "no candidate of the library reduces it significantly"
            },
            d.residual_pattern.strongest
        );
    } else {
        let _ = writeln!(
            s,
            "\nThe final error is within {} times the floor: nothing unexplained remains.",
            super::UNEXPLAINED_FACTOR
        );
    }
    for (what, q) in std::iter::once(("data", &d.data_quality.data)).chain(
        d.data_quality
            .heldout
            .as_ref()
            .map(|q| ("held-out data", q)),
    ) {
        if q.total() == 0 {
            continue;
        }
        let _ = writeln!(
            s,
            "\n**Bad samples in the {what}**: {} spikes, {} dropouts, {} gaps, {} saturated columns; {} samples left out of the fits and scores (spikes and dropouts repaired by interpolation for the inputs and the inverse dynamics).\n",
            q.spikes, q.dropouts, q.gaps, q.saturated, q.excluded_samples
        );
        for f in &q.findings {
            let _ = writeln!(s, "- {}", f.describe(""));
        }
    }
    if !d.fallbacks.is_empty() {
        let _ = writeln!(s, "\n**Co-simulation fallbacks**:\n");
        for f in &d.fallbacks {
            let _ = writeln!(s, "- {f}");
        }
    }
    let _ = writeln!(s, "\n| channel | scale | nominal RMS | baseline RMS | final RMS |\n| --- | --- | --- | --- | --- |");
    for c in &d.channels {
        let _ = writeln!(
            s,
            "| `{}` | {:.4e} | {:.4e} | {:.4e} | {:.4e} |",
            c.name, c.scale, c.nominal_rms, c.baseline_rms, c.final_rms
        );
    }
    for (k, e) in d.effects.iter().enumerate() {
        let _ = writeln!(
            s,
            "\n## {}. `{}` ({}): {}\n",
            k + 1,
            e.name.name(),
            e.action,
            e.meaning
        );
        let _ = writeln!(
            s,
            "Held-out RMS {:.5} → {:.5} ({}); p = {:.2e} < {:.2e}.\n",
            e.rms_before,
            e.rms_after,
            pct(e.rms_before, e.rms_after),
            e.p_value,
            e.threshold
        );
        let _ = writeln!(s, "{}\n", where_line(&e.where_));
        if let Some(line) = change_line(e) {
            let _ = writeln!(s, "{line}\n");
        }
        if let Some(line) = table_line(e) {
            let _ = writeln!(s, "{line}\n");
        }
        if !e.alternatives.is_empty() {
            let _ = writeln!(
                s,
                "Other explanations of the same signature, fitted in the same round (p: one-sided, that `{}` explains the held-out data better, by the signed-rank test of their squared errors per group; separated: p below the round's threshold and mean squares further apart than the co-simulation's step error squared):\n\n| explanation | held-out RMS | p | separated | passed itself |\n| --- | --- | --- | --- | --- |",
                e.name.name()
            );
            for a in &e.alternatives {
                let _ = writeln!(
                    s,
                    "| `{}` | {:.5} | {:.2e} | {} | {} |",
                    a.name,
                    a.heldout_rms,
                    a.p_value,
                    if a.separated { "yes" } else { "no" },
                    if a.passed { "yes" } else { "no" }
                );
            }
            let _ = writeln!(s);
        }
        let _ = writeln!(
            s,
            "| LuGre variable | unit | before | after |\n| --- | --- | --- | --- |"
        );
        for v in &e.variables {
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {} |",
                v.name, v.unit, v.before, v.after
            );
        }
    }
    if !d.changes.is_empty() {
        let _ = writeln!(
            s,
            "\n## What changed\n\nThe friction component's parameters in `refitted.ssp` against the nominal file; the 95 % interval of each fitted one from the output error of the training data, its residuals clustered in {} runs of consecutive samples (docs/diagnose.md, \"Intervals\"):\n\n| variable | unit | nominal | refitted | 95 % interval |\n| --- | --- | --- | --- | --- |",
            d.groups
        );
        for v in &d.changes {
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {} | {} |",
                v.name,
                v.unit,
                v.before,
                v.after,
                v.interval.map_or("".to_string(), |[low, high]| format!(
                    "[{low:.6e}, {high:.6e}]"
                ))
            );
        }
    }
    let _ = writeln!(s, "\n## Candidates tried\n");
    let _ = writeln!(
        s,
        "Each candidate is the current model with one effect added (or, for viscous, Stribeck and presliding when the model has them, re-sized; or two that interact), refitted; p is the one-sided p-value of Clark and West's test for nested models on the held-out samples (per sample 2·e₀·(ŷ₁ − ŷ₀), averaged per group, Wilcoxon's signed-rank test), against α = {} divided by the hypotheses of the round (one per candidate; the offset, direction-dependent levels and direction-dependent viscous friction, three explanations of one signature, count as one, and the one the held-out data prefer is named); the mean square must also drop by at least 2 % and by more than the co-simulation's step error squared. A round of pairs follows a round in which no single effect was accepted.\n",
        d.alpha
    );
    for (r, round) in d.rounds.iter().enumerate() {
        let _ = writeln!(
            s,
            "Round {} ({} candidates; p must be below {:.2e}):\n\n| candidate | held-out RMS | drop of the mean square | p | beyond the step error | force RMS (N, training) | fit runs |\n| --- | --- | --- | --- | --- | --- | --- |",
            r + 1,
            round.len(),
            d.round_thresholds[r]
        );
        for c in round {
            if let Some(why) = &c.failure {
                let _ = writeln!(
                    s,
                    "| `{}` | rejected: its co-simulation failed ({}) | | | | {:.4} | {} |",
                    c.name,
                    why.replace('|', "/"),
                    c.force_rms,
                    c.fit_evaluations
                );
                continue;
            }
            let _ = writeln!(
                s,
                "| `{}` | {:.5} | {:.1} % | {:.2e} | {} | {:.4} | {} |",
                c.name,
                c.heldout_rms,
                100.0 * c.gain,
                c.p_value,
                match &c.unresolved {
                    Some(why) => format!("no: {why}"),
                    None if c.beyond_step_error => "yes".into(),
                    None => "no".into(),
                },
                c.force_rms,
                c.fit_evaluations
            );
        }
        let _ = writeln!(s);
    }
    if let Some(r) = d.time_limit.round {
        let _ = writeln!(
            s,
            "Round {r} was in progress when the time limit was reached and is not decided. Unfinished (neither accepted nor rejected): {}.\n",
            d.time_limit.unfinished_list(|c| format!("`{c}`"))
        );
        if !d.time_limit.finished.is_empty() {
            let _ = writeln!(
                s,
                "Its candidates that finished, against the current model (not decided on):\n\n| candidate | held-out RMS | drop of the mean square | p | fit runs |\n| --- | --- | --- | --- | --- |"
            );
            for c in &d.time_limit.finished {
                let _ = writeln!(
                    s,
                    "| `{}` | {:.5} | {:.1} % | {:.2e} | {} |",
                    c.name,
                    c.heldout_rms,
                    100.0 * c.gain,
                    c.p_value,
                    c.fit_evaluations
                );
            }
            let _ = writeln!(s);
        }
    }
    let _ = writeln!(
        s,
        "## Where the baseline and the final model disagree with the data\n"
    );
    let _ = writeln!(s, "Friction residual (force the data imply minus the law's force along the measured states), held-out data.\n");
    let _ = writeln!(s, "| state | bin | samples | baseline mean (N) | baseline RMS (N) | final mean (N) | final RMS (N) |\n| --- | --- | --- | --- | --- | --- | --- |");
    for (b, a) in d.baseline_pattern.bins.iter().zip(&d.residual_pattern.bins) {
        let _ = writeln!(
            s,
            "| {} | {} | {:.0} % | {:+.4} | {:.4} | {:+.4} | {:.4} |",
            b.state,
            b.bin,
            100.0 * b.share,
            b.mean,
            b.rms,
            a.mean,
            a.rms
        );
    }
    let _ = writeln!(s, "\nThe same with figures: `report.html`; the figures as PNG: `gap.png` (held-out error per round), `fit.png` (measured, given, final and residuals against time), `law.png` (force against velocity), `levels.png` (position dependence), `residual.png` (friction residual binned against the states). The refitted system: `refitted.ssp`, rerun (with the master and step the diagnosis co-simulated with, so that the results are the co-simulations scored here) by");
    for command in &d.rerun {
        let _ = writeln!(s, "\n    {command}");
    }
    s
}

/// `600 s, not reached`, `0.5 s, REACHED (...)`, `none`: the time limit
/// in a few words.
pub fn time_limit_words(t: &super::TimeLimit) -> String {
    match (t.seconds, t.reached) {
        (None, _) => "none".into(),
        (Some(x), false) => format!("{x} s, not reached"),
        (Some(x), true) => format!("{x} s, REACHED: the diagnosis stopped early (see the Result)"),
    }
}

/// `What it adds: Fc_neg - Fc = 6.37 N, 95 % interval [6.12, 6.62]:
/// resolved.` for an effect with a change ([`super::FoundEffect::change`]).
pub fn change_line(e: &super::FoundEffect) -> Option<String> {
    let c = e.change.as_ref()?;
    Some(match (c.interval, c.resolved) {
        (Some([low, high]), Some(resolved)) => format!(
            "What it adds: {} = {:.4} ± {:.2} (95 % interval [{low:.4}, {high:.4}]): {}.",
            c.quantity,
            c.value,
            0.5 * (high - low),
            if resolved {
                "resolved"
            } else {
                "NOT RESOLVED, the interval holds no change"
            }
        ),
        _ => format!(
            "What it adds: {} = {:.4} (no interval could be formed).",
            c.quantity, c.value
        ),
    })
}

/// ` The data do not separate it from offset (held-out RMS 0.0778, p = 4.0e-1): …` and the
/// like: how the effect stands against the other explanations of its
/// signature ([`super::Alternative`]), empty when it has none.
/// The position table made finer after `e` was accepted
/// ([`super::FoundEffect::table`]), one step after another; `None` when
/// no finer table was tried.
pub fn table_line(e: &super::FoundEffect) -> Option<String> {
    let first = e.table.first()?;
    let mut line = format!(
        "Position table made finer while the data ask for it: {} knots",
        first.knots.div_ceil(2)
    );
    for t in &e.table {
        let _ = write!(
            line,
            " → {} knots (held-out RMS {:.3e} → {:.3e}, p = {:.1e}, {})",
            t.knots,
            t.heldout_rms_before,
            t.heldout_rms,
            t.p_value,
            if t.kept { "kept" } else { "not kept" }
        );
    }
    line.push('.');
    Some(line)
}

pub fn alternatives_line(e: &super::FoundEffect) -> String {
    let mut s = overlap_line(e);
    if e.alternatives.is_empty() {
        return s;
    }
    let (apart, close): (Vec<_>, Vec<_>) = e.alternatives.iter().partition(|a| a.separated);
    let list = |v: &[&super::Alternative]| {
        v.iter()
            .map(|a| {
                format!(
                    "{} (held-out RMS {:.4}, p = {:.1e})",
                    a.name, a.heldout_rms, a.p_value
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    if !apart.is_empty() {
        let _ = write!(s, " The data prefer it to {}.", list(&apart));
    }
    if !close.is_empty() {
        let _ = write!(
            s,
            " The data do not separate it from {}: named first in the library's order.",
            list(&close)
        );
    }
    s
}

/// The overlap check of an effect in words ([`super::OverlapCheck`]), or
/// nothing.
fn overlap_line(e: &super::FoundEffect) -> String {
    let Some(o) = &e.overlap else {
        return String::new();
    };
    let preferred = if o.encompasses {
        format!(
            "alone the data do not separate them (p = {:.1e}), but this one encompasses {other}",
            o.p_separated,
            other = o.other
        )
    } else {
        format!("the data prefer this one (p = {:.1e})", o.p_separated)
    };
    format!(
        " {other} passed too, and the two overlap: {preferred}; fitted together, it adds {:.1} % to {other} (p = {:.1e}) and {other} adds {:.1} % to it (p = {:.1e}).",
        100.0 * o.gain_after_other,
        o.p_after_other,
        100.0 * o.other_gain_after,
        o.other_p_after,
        other = o.other
    )
}

/// The "Where" of an effect in words: the state its change depends on,
/// how much of the improvement that state explains (and the others), and
/// its strongest bin.
pub fn where_line(w: &super::localise::Where) -> String {
    let words = |state: &str| state.replace('_', " ");
    let mut s = String::from("Where: ");
    if let Some((first, rest)) = w.explained_by.split_first() {
        let _ = write!(
            s,
            "the change depends on {}: its bins explain {:.0} % of its variation",
            words(first.state),
            100.0 * first.share
        );
        if !rest.is_empty() {
            let others: Vec<String> = rest
                .iter()
                .map(|a| format!("{} {:.0} %", words(a.state), 100.0 * a.share))
                .collect();
            let _ = write!(s, " ({})", others.join(", "));
        }
        s.push_str("; ");
    }
    let _ = write!(
        s,
        "{} {} holds {:.0} % of the improvement in {:.0} % of the samples.",
        words(w.state),
        w.bin,
        100.0 * w.share_of_improvement,
        100.0 * w.share_of_samples
    );
    s
}

type Fail = String;

/// The input files of a report, with the result file of their rerun:
/// `inputs.csv` (`rerun.csv`) of the training record and
/// `heldout-inputs.csv` (`rerun-heldout.csv`) of a held-out file; with
/// several records, numbered in their order (`inputs-1.csv`,
/// `rerun-1.csv`, ...).
pub fn input_files(d: &Diagnosis) -> Vec<(&super::InputColumns, String, String)> {
    let mut files = Vec::new();
    for (records, inputs, result) in [
        (&d.measured_inputs, "inputs", "rerun"),
        (&d.heldout_inputs, "heldout-inputs", "rerun-heldout"),
    ] {
        for (i, record) in records.iter().enumerate() {
            let n = if records.len() == 1 {
                String::new()
            } else {
                format!("-{}", i + 1)
            };
            files.push((
                record,
                format!("{inputs}{n}.csv"),
                format!("{result}{n}.csv"),
            ));
        }
    }
    files
}

/// `fricsim run DIR/refitted.ssp --input DIR/inputs.csv …` over each
/// training record and each held-out file ([`input_files`]): each with
/// the diagnosis's master, step and the record's time span, so that the
/// run is the co-simulation the report scored (the inputs interpolated
/// over each step, as the diagnosis gives them).
///
/// With the nominal moved to another law, the same for its
/// `refitted-<law>.ssp` after them (results `rerun-<law>….csv`).
pub fn rerun_commands(d: &Diagnosis, out: &Path) -> Vec<String> {
    let mut systems = vec![("refitted.ssp".to_string(), String::new())];
    if let Some(m) = moved(&d.memory) {
        let tag = m.law.file_tag();
        systems.push((format!("refitted-{tag}.ssp"), format!("-{tag}")));
    }
    systems
        .into_iter()
        .flat_map(|(ssp, tag)| {
            input_files(d)
                .into_iter()
                .map(move |((time, _), inputs, result)| {
                    let (start, stop) = (time[0], *time.last().unwrap_or(&time[0]));
                    let result = result.replacen("rerun", &format!("rerun{tag}"), 1);
                    format!(
                        "fricsim run {} --input {} --master {} --step {:?} --start {start:?} --stop {stop:?} --out {}",
                        out.join(&ssp).display(),
                        out.join(inputs).display(),
                        d.master,
                        d.step,
                        out.join(result).display()
                    )
                })
        })
        .collect()
}

/// A data file's input columns (what drives the system), for
/// `fricsim run refitted.ssp --input inputs.csv`.
fn write_inputs(inputs: &super::InputColumns, path: &Path) -> Result<(), Fail> {
    let (time, columns) = inputs;
    let mut text = String::from("time");
    for (name, _) in columns {
        text.push(',');
        text.push_str(name);
    }
    text.push('\n');
    for (k, t) in time.iter().enumerate() {
        let _ = write!(text, "{t:?}");
        for (_, values) in columns {
            let _ = write!(text, ",{:?}", values[k]);
        }
        text.push('\n');
    }
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// The refitted system: the nominal ssd with every `source` made absolute,
/// the friction component's parameter bindings replaced by one inline set
/// (its nominal values with the refitted ones over them), packed into a
/// self-contained `.ssp` by [`crate::ssp::pack::pack`].
///
/// `file` may have the friction component on another FMU than the ssd's
/// (the nominal moved to GMS, [`SystemFile::with_component_source`]): its
/// source is then the file's, and the connectors the file dropped are
/// left out with their connections. `refitted`: the friction FMU's
/// parameters by name.
fn write_ssp(
    file: &SystemFile,
    friction: &str,
    refitted: &[(String, f64)],
    out: &Path,
) -> Result<(), Fail> {
    let ssd = file.ssd_path();
    let text = std::fs::read_to_string(&ssd).map_err(|e| format!("{}: {e}", ssd.display()))?;
    // values: the nominal component's, then the refitted ones
    let mut values: Vec<(String, String, String)> = Vec::new(); // (name, type, value)
    let mut put = |name: &str, ty: &str, value: String| {
        values.retain(|(n, _, _)| n != name);
        values.push((name.to_string(), ty.to_string(), value));
    };
    for p in file.parameters.iter().filter(|p| p.component == friction) {
        let (ty, v) = match &p.value {
            crate::ssp::Value::Real(x) => ("Real", format!("{x:e}")),
            crate::ssp::Value::Integer(i) => ("Integer", i.to_string()),
            crate::ssp::Value::Boolean(b) => ("Boolean", b.to_string()),
            crate::ssp::Value::String(s) => ("String", s.clone()),
        };
        put(&p.variable, ty, v);
    }
    for (name, x) in refitted {
        let x = *x;
        // the effects' switches are Booleans ([`crate::effects::EffectSpec::switch`])
        if crate::effects::Effect::switches().any(|s| s == name) {
            put(name, "Boolean", (x != 0.0).to_string());
        } else if name == "n_table" || name == "n_elements" {
            put(name, "Integer", (x as i64).to_string());
        } else {
            put(name, "Real", format!("{x:e}"));
        }
    }
    // the friction component's connectors in the file (all of the ssd's
    // unless it moved to another FMU)
    let kept: Vec<&str> = file
        .components
        .iter()
        .find(|c| c.name == friction)
        .map(|c| c.connectors.iter().map(|c| c.name.as_str()).collect())
        .unwrap_or_default();
    let dropped_connector =
        |e: &BytesStart| attr(e, "name").is_some_and(|n| !kept.contains(&n.as_str()));
    let dropped_connection = |e: &BytesStart| {
        [
            ("startElement", "startConnector"),
            ("endElement", "endConnector"),
        ]
        .iter()
        .any(|(element, connector)| {
            attr(e, element).as_deref() == Some(friction)
                && attr(e, connector).is_some_and(|n| !kept.contains(&n.as_str()))
        })
    };

    let mut reader = quick_xml::Reader::from_str(&text);
    let mut writer = quick_xml::Writer::new(Vec::new());
    let fail =
        |e: &dyn std::fmt::Display| format!("{}: rewriting for refitted.ssp: {e}", ssd.display());
    let mut in_friction = false;
    let mut skip_depth = 0usize;
    let mut prefix = String::new();
    loop {
        let event = reader.read_event().map_err(|e| fail(&e))?;
        if skip_depth > 0 {
            match &event {
                Event::Start(_) => skip_depth += 1,
                Event::End(_) => skip_depth -= 1,
                Event::Eof => break,
                _ => {}
            }
            continue;
        }
        match event {
            Event::Eof => break,
            // the friction component's own bindings are replaced
            Event::Start(e) if in_friction && local(e.name().as_ref()) == "ParameterBindings" => {
                skip_depth = 1;
            }
            Event::Empty(e) if in_friction && local(e.name().as_ref()) == "ParameterBindings" => {}
            // connectors and connections of an FMU the friction no longer is
            Event::Start(e)
                if (in_friction
                    && local(e.name().as_ref()) == "Connector"
                    && dropped_connector(&e))
                    || (local(e.name().as_ref()) == "Connection" && dropped_connection(&e)) =>
            {
                skip_depth = 1;
            }
            Event::Empty(e)
                if (in_friction
                    && local(e.name().as_ref()) == "Connector"
                    && dropped_connector(&e))
                    || (local(e.name().as_ref()) == "Connection" && dropped_connection(&e)) => {}
            Event::Start(e) => {
                let e = absolute_source(file, &e).map_err(|m| fail(&m))?;
                if local(e.name().as_ref()) == "Component" {
                    let name = attr(&e, "name");
                    in_friction = name.as_deref() == Some(friction);
                    let full = e.name().as_ref().to_string();
                    prefix = full.strip_suffix("Component").unwrap_or("").to_string();
                }
                writer.write_event(Event::Start(e)).map_err(|e| fail(&e))?;
            }
            Event::Empty(e) => {
                let e = absolute_source(file, &e).map_err(|m| fail(&m))?;
                writer.write_event(Event::Empty(e)).map_err(|e| fail(&e))?;
            }
            Event::End(e) => {
                if local(e.name().as_ref()) == "Component" && in_friction {
                    write_bindings(&mut writer, &prefix, &values).map_err(|e| fail(&e))?;
                    in_friction = false;
                }
                writer.write_event(Event::End(e)).map_err(|e| fail(&e))?;
            }
            other => writer.write_event(other).map_err(|e| fail(&e))?,
        }
    }
    let dir = out.parent().unwrap_or(Path::new("."));
    let tmp_ssd = dir.join("refitted.ssd");
    std::fs::write(&tmp_ssd, writer.into_inner()).map_err(|e| e.to_string())?;
    let packed = crate::ssp::pack::pack(&tmp_ssd, out).map_err(|e| e.to_string());
    let _ = std::fs::remove_file(&tmp_ssd);
    packed
}

fn local(name: &str) -> &str {
    name.rsplit(':').next().unwrap_or("")
}

fn attr(e: &BytesStart, key: &str) -> Option<String> {
    e.attributes()
        .flatten()
        .find(|a| a.key.as_ref() == key)
        .and_then(|a| {
            a.normalized_value(quick_xml::XmlVersion::Implicit1_0)
                .ok()
                .map(|v| v.into_owned())
        })
}

/// A copy of `e` with its `source` attribute resolved to an absolute path.
fn absolute_source(file: &SystemFile, e: &BytesStart) -> Result<BytesStart<'static>, String> {
    let name = e.name().as_ref().to_string();
    let mut copy = BytesStart::new(name);
    for a in e.attributes() {
        let a = a.map_err(|err| err.to_string())?;
        let key = a.key.as_ref().to_string();
        let value = a
            .normalized_value(quick_xml::XmlVersion::Implicit1_0)
            .map_err(|err| err.to_string())?
            .into_owned();
        if key == "source" {
            // a component's source as the file holds it now (a Dahl
            // friction moved to LuGre), else as written
            let component = (local(e.name().as_ref()) == "Component")
                .then(|| attr(e, "name"))
                .flatten()
                .and_then(|n| file.components.iter().find(|c| c.name == n));
            let path = match component {
                Some(c) if c.source_text != value => c.source.clone(),
                _ => file.resolve(&value)?,
            };
            let path = std::fs::canonicalize(&path).unwrap_or(path);
            copy.push_attribute((key.as_str(), path.to_string_lossy().as_ref()));
        } else {
            copy.push_attribute((key.as_str(), value.as_str()));
        }
    }
    Ok(copy)
}

fn write_bindings(
    w: &mut quick_xml::Writer<Vec<u8>>,
    prefix: &str,
    values: &[(String, String, String)],
) -> Result<(), quick_xml::Error> {
    let start = |n: &str| BytesStart::new(n.to_string());
    let tag = |n: &str| format!("{prefix}{n}");
    w.write_event(Event::Start(start(&tag("ParameterBindings"))))?;
    w.write_event(Event::Start(start(&tag("ParameterBinding"))))?;
    w.write_event(Event::Start(start(&tag("ParameterValues"))))?;
    let mut set = start("ssv:ParameterSet");
    set.push_attribute(("version", "1.0"));
    set.push_attribute(("name", "refitted_by_fricsim_diagnose"));
    set.push_attribute((
        "xmlns:ssv",
        "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    ));
    w.write_event(Event::Start(set))?;
    w.write_event(Event::Start(start("ssv:Parameters")))?;
    for (name, ty, value) in values {
        let mut p = start("ssv:Parameter");
        p.push_attribute(("name", name.as_str()));
        w.write_event(Event::Start(p))?;
        let mut v = start(&format!("ssv:{ty}"));
        v.push_attribute(("value", value.as_str()));
        w.write_event(Event::Empty(v))?;
        w.write_event(Event::End(BytesEnd::new("ssv:Parameter")))?;
    }
    w.write_event(Event::End(BytesEnd::new("ssv:Parameters")))?;
    w.write_event(Event::End(BytesEnd::new("ssv:ParameterSet")))?;
    w.write_event(Event::End(BytesEnd::new(tag("ParameterValues"))))?;
    w.write_event(Event::End(BytesEnd::new(tag("ParameterBinding"))))?;
    w.write_event(Event::End(BytesEnd::new(tag("ParameterBindings"))))?;
    Ok(())
}
