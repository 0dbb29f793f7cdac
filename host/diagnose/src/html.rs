//! `report.html`: the diagnosis for a person with five minutes, in one
//! self-contained file (figures inline as SVG, styles inline, no script, no
//! network), in the order a reader needs it: the verdict, the gap
//! shrinking, where, the physics, the candidates tried and the data
//! problems, and what changed in the system.

use super::figures::Figure;
use super::report::{pct as percent, where_line};
use super::{CandidateScore, Diagnosis, FmuValue, UNEXPLAINED_FACTOR};
use std::fmt::Write as _;

/// `text` with the characters HTML gives a meaning escaped.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

const STYLE: &str = "
body { font-family: system-ui, -apple-system, 'Segoe UI', sans-serif; margin: 0; color: #1d1d1f; background: #fafafa; }
main { max-width: 1150px; margin: 0 auto; padding: 1.5em 2em 4em; background: #fff; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { border-bottom: 2px solid #ddd; padding-bottom: 0.2em; margin-top: 2em; }
.meta { color: #555; font-size: 0.92em; }
.verdict { font-size: 1.15em; padding: 0.8em 1em; border-radius: 6px; }
.verdict.found { background: #e8f1fd; border-left: 6px solid #1e5ac8; }
.verdict.clean { background: #e9f6e9; border-left: 6px solid #2e8b2e; }
.verdict.open { background: #fdf0e6; border-left: 6px solid #d97a1a; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.92em; }
th, td { border: 1px solid #ddd; padding: 0.3em 0.6em; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
figure { margin: 1em 0; }
figure svg { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption { color: #444; font-size: 0.9em; margin-top: 0.3em; }
code { background: #f3f3f3; padding: 0 0.25em; border-radius: 3px; }
.pass { color: #1b7a1b; font-weight: 600; }
.fail { color: #777; }
";

fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        format!("{x}")
    } else if (1e-3..1e5).contains(&x.abs()) {
        format!("{:.5}", x)
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{x:.4e}")
    }
}

fn with_unit(x: f64, unit: &str) -> String {
    if unit.is_empty() {
        number(x)
    } else {
        format!("{} {}", number(x), escape(unit))
    }
}

/// What a variable became, in words: "Fc_neg = 23.5 N (was 17.2 N)".
fn variable_change(v: &FmuValue) -> String {
    if v.before == v.after {
        format!(
            "<code>{}</code> = {}",
            escape(&v.name),
            with_unit(v.after, &v.unit)
        )
    } else {
        format!(
            "<code>{}</code> = {} (was {})",
            escape(&v.name),
            with_unit(v.after, &v.unit),
            with_unit(v.before, &v.unit)
        )
    }
}

/// Why a candidate was not accepted, or that it passed.
fn outcome(c: &CandidateScore, threshold: f64, min_gain: f64) -> (bool, String) {
    if let Some(f) = &c.failure {
        return (false, format!("its co-simulation failed: {f}"));
    }
    if let Some(u) = &c.unresolved {
        return (false, u.clone());
    }
    if c.p_value >= threshold {
        return (
            false,
            format!("p = {:.2e} is not below {:.2e}", c.p_value, threshold),
        );
    }
    if c.gain < min_gain {
        return (
            false,
            format!(
                "the mean square drops by less than {:.0} %",
                100.0 * min_gain
            ),
        );
    }
    if !c.beyond_step_error {
        return (
            false,
            "the drop is within the co-simulation's step error".into(),
        );
    }
    if let Some((gain, p)) = c.fine_step {
        if p >= threshold || gain < min_gain {
            return (
                false,
                format!(
                    "the gain does not survive a finer step (drop {:.1} %, p = {p:.2e})",
                    100.0 * gain
                ),
            );
        }
    }
    (true, "passes every test".into())
}

fn figure(out: &mut String, f: &Figure) {
    let _ = writeln!(
        out,
        "<figure id=\"figure-{}\">{}<figcaption>{} (also <code>{}.png</code>)</figcaption></figure>",
        f.name,
        strip_declaration(&f.svg),
        escape(&f.caption),
        f.name
    );
}

/// An SVG document as an inline element: without an XML declaration.
fn strip_declaration(svg: &str) -> &str {
    match svg.find("<svg") {
        Some(i) => &svg[i..],
        None => svg,
    }
}

/// The page. `rerun` are the commands that rerun the refitted system.
pub fn page(d: &Diagnosis, figures: &[Figure], rerun: &[String], min_gain: f64) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>Diagnosis of {}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<main>\n",
        escape(&d.system)
    );
    let _ = write!(
        s,
        "<header>\n<h1>Diagnosis of <code>{}</code></h1>\n<p class=\"meta\">Measurements: <code>{}</code> ({} samples). Held out: {} ({} samples compared). Friction force: {}. Co-simulation: {} at {} s. {:.1} s wall time, {} co-simulations. Output-error Jacobian: {}. Time limit: {}.</p>\n</header>\n",
        escape(&d.system),
        escape(&d.data),
        d.samples,
        escape(&d.heldout),
        d.heldout_samples,
        escape(&d.force_source),
        escape(&d.master),
        number(d.step),
        d.wall_seconds,
        d.cosimulations,
        escape(&d.output_jacobian),
        escape(&super::report::time_limit_words(&d.time_limit))
    );
    verdict(&mut s, d);
    let by_name = |name: &str| figures.iter().find(|f| f.name == name);

    s.push_str("<section id=\"gap\">\n<h2>The gap shrinking</h2>\n");
    if let Some(f) = by_name("gap") {
        figure(&mut s, f);
    }
    s.push_str("</section>\n");

    s.push_str("<section id=\"where\">\n<h2>Where</h2>\n");
    if d.effects.is_empty() {
        let _ = writeln!(
            s,
            "<p>No effect was added. The residual is largest in: {}.</p>",
            escape(if d.residual_pattern.strongest.is_empty() {
                "no bin stands out"
            } else {
                &d.residual_pattern.strongest
            })
        );
    } else {
        s.push_str("<ol>\n");
        for e in &d.effects {
            let _ = writeln!(
                s,
                "<li><strong>{}</strong>: {}{} {} {}</li>",
                escape(e.name.name()),
                escape(&where_line(&e.where_)),
                escape(&super::report::alternatives_line(e)),
                escape(&super::report::change_line(e).unwrap_or_default()),
                escape(&super::report::table_line(e).unwrap_or_default())
            );
        }
        s.push_str("</ol>\n");
    }
    if let Some(f) = by_name("fit") {
        figure(&mut s, f);
    }
    s.push_str("</section>\n");

    s.push_str("<section id=\"physics\">\n<h2>The physics</h2>\n");
    for name in ["law", "levels", "residual"] {
        if let Some(f) = by_name(name) {
            figure(&mut s, f);
        }
    }
    s.push_str("</section>\n");

    candidates(&mut s, d, min_gain);
    changes(&mut s, d, rerun);
    s.push_str("</main>\n</body>\n</html>\n");
    s
}

fn verdict(s: &mut String, d: &Diagnosis) {
    s.push_str("<section id=\"verdict\">\n<h2>Verdict</h2>\n");
    if let Some(sentence) = d.time_limit.sentence() {
        let _ = writeln!(
            s,
            "<p class=\"verdict open\" id=\"time-limit\"><strong>Time limit reached.</strong> {}</p>",
            escape(&sentence)
        );
    }
    let (class, text) = match (d.effects.is_empty(), d.unexplained) {
        (true, _) if d.time_limit.reached => (
            "open",
            "No effect was accepted before the time limit was reached.".to_string(),
        ),
        (true, false) => (
            "clean",
            "No missing effect: the model as given explains these data down to the floor."
                .to_string(),
        ),
        (true, true) => (
            "open",
            "No effect of the library explains the discrepancy: the error stays above the floor."
                .to_string(),
        ),
        (false, unexplained) => {
            let names: Vec<String> = d
                .effects
                .iter()
                .map(|e| format!("{} ({})", e.name.name(), e.action))
                .collect();
            (
                if unexplained { "open" } else { "found" },
                format!(
                    "Found, in this order: {}. {}",
                    names.join(", "),
                    if unexplained {
                        "Part of the error remains unexplained."
                    } else {
                        "What remains is at the floor."
                    }
                ),
            )
        }
    };
    let _ = writeln!(s, "<p class=\"verdict {class}\">{}</p>", escape(&text));
    if !d.effects.is_empty() {
        s.push_str("<ol>\n");
        for e in &d.effects {
            let changed: Vec<String> = e.variables.iter().map(variable_change).collect();
            let _ = writeln!(
                s,
                "<li><strong>{}</strong> ({}): {}. {}. Held-out RMS {} → {} ({}), p = {:.2e}.</li>",
                escape(e.name.name()),
                e.action,
                escape(e.meaning),
                changed.join(", "),
                number(e.rms_before),
                number(e.rms_after),
                percent(e.rms_before, e.rms_after),
                e.p_value
            );
        }
        s.push_str("</ol>\n");
    }
    s.push_str(
        "<table>\n<tr><th>model</th><th>held-out RMS</th><th>against the given model</th></tr>\n",
    );
    let _ = writeln!(
        s,
        "<tr><td>as given</td><td class=\"num\">{}</td><td></td></tr>",
        number(d.nominal_rms)
    );
    let refit = &d.refit;
    let note = match (&refit.failure, refit.kept) {
        _ if refit.unfinished => {
            "the time limit was reached before the refit finished: the baseline is the model as given".to_string()
        }
        (Some(f), _) => {
            format!("its co-simulation failed ({f}): the baseline is the model as given")
        }
        (None, true) => format!(
            "kept as the baseline (p = {:.2e} < {:.2e})",
            refit.p_value, refit.threshold
        ),
        (None, false) => format!(
            "not kept (p = {:.2e}, threshold {:.2e}): the baseline is the model as given",
            refit.p_value, refit.threshold
        ),
    };
    let _ = writeln!(
        s,
        "<tr><td>levels refitted</td><td class=\"num\">{}</td><td>{}; {}</td></tr>",
        number(refit.heldout_rms),
        percent(d.nominal_rms, refit.heldout_rms),
        escape(&note)
    );
    let _ = writeln!(
        s,
        "<tr><td><strong>final</strong></td><td class=\"num\"><strong>{}</strong></td><td>{}</td></tr>",
        number(d.final_rms),
        percent(d.nominal_rms, d.final_rms)
    );
    if let Some(m) = crate::memory::moved(&d.memory) {
        let _ = writeln!(
            s,
            "<tr><td><strong>final, moved to {}</strong></td><td class=\"num\"><strong>{}</strong></td><td>{}</td></tr>",
            m.law.model_name(),
            number(m.heldout_rms),
            percent(d.nominal_rms, m.heldout_rms)
        );
    }
    let _ = writeln!(s, "</table>");
    // the report's words, its emphasis as HTML
    let words = escape(&super::report::memory_words(&d.memory));
    let mut html = String::new();
    for (i, part) in words.split("**").enumerate() {
        if i % 2 == 1 {
            let _ = write!(html, "<strong>{part}</strong>");
        } else {
            html.push_str(part);
        }
    }
    let _ = writeln!(s, "<p>{}</p>", html.replace('`', ""));
    let _ = writeln!(
        s,
        "<p>Floor: measurement noise and quantisation {}, the co-simulation's step error {}, together {}. {}</p>",
        number(d.noise_floor_rms),
        number(d.step_error_rms),
        number(d.floor_rms),
        if d.unexplained {
            format!(
                "<strong>Unexplained</strong>: the final error is more than {UNEXPLAINED_FACTOR} times the floor. The residual is largest in: {}.",
                escape(&d.residual_pattern.strongest)
            )
        } else {
            format!("Nothing is unexplained: the final error is within {UNEXPLAINED_FACTOR} times the floor.")
        }
    );
    let _ = writeln!(
        s,
        "<p class=\"meta\">RMS figures are held-out, each measured channel divided by its standard deviation.</p>\n</section>"
    );
}

fn candidates(s: &mut String, d: &Diagnosis, min_gain: f64) {
    s.push_str("<section id=\"candidates\">\n<h2>Candidates tried</h2>\n");
    let _ = writeln!(
        s,
        "<p>Each round fits every candidate (an effect added, or re-sized when the model has it) and scores it on the held-out data against the current model; of those that pass every test, the best is accepted and the next round starts from it.</p>"
    );
    for (r, round) in d.rounds.iter().enumerate() {
        let threshold = d.round_thresholds[r];
        let _ = writeln!(
            s,
            "<h3>Round {} ({} candidates; p must be below {:.2e})</h3>\n<table>\n<tr><th>candidate</th><th>held-out RMS</th><th>drop of the mean square</th><th>p</th><th>outcome</th></tr>",
            r + 1,
            round.len(),
            threshold
        );
        for c in round {
            let (pass, why) = outcome(c, threshold, min_gain);
            let _ = writeln!(
                s,
                "<tr><td><code>{}</code></td><td class=\"num\">{}</td><td class=\"num\">{:.1} %</td><td class=\"num\">{:.2e}</td><td class=\"{}\">{}</td></tr>",
                escape(&c.name),
                number(c.heldout_rms),
                100.0 * c.gain,
                c.p_value,
                if pass { "pass" } else { "fail" },
                escape(&why)
            );
        }
        s.push_str("</table>\n");
    }
    if let Some(r) = d.time_limit.round {
        let _ = writeln!(
            s,
            "<h3>Round {r} (in progress when the time limit was reached: not decided)</h3>\n<p>Unfinished, neither accepted nor rejected: {}.</p>",
            d.time_limit
                .unfinished_list(|c| format!("<code>{}</code>", escape(c)))
        );
        if !d.time_limit.finished.is_empty() {
            s.push_str("<table>\n<tr><th>finished candidate</th><th>held-out RMS</th><th>drop of the mean square</th><th>p</th></tr>\n");
            for c in &d.time_limit.finished {
                let _ = writeln!(
                    s,
                    "<tr><td><code>{}</code></td><td class=\"num\">{}</td><td class=\"num\">{:.1} %</td><td class=\"num\">{:.2e}</td></tr>",
                    escape(&c.name),
                    number(c.heldout_rms),
                    100.0 * c.gain,
                    c.p_value
                );
            }
            s.push_str("</table>\n");
        }
    }
    s.push_str("<h3>Data problems</h3>\n");
    let mut files = vec![(&d.data, &d.data_quality.data)];
    if let Some(h) = &d.data_quality.heldout {
        files.push((&d.heldout, h));
    }
    let mut any = false;
    for (file, q) in files {
        if q.findings.is_empty() {
            continue;
        }
        any = true;
        let _ = writeln!(
            s,
            "<p>In <code>{}</code>: {} spikes, {} dropouts, {} gaps, {} saturated samples; {} samples left out of fits and scores.</p>\n<ul>",
            escape(file),
            q.spikes,
            q.dropouts,
            q.gaps,
            q.saturated,
            q.excluded_samples
        );
        for f in &q.findings {
            let _ = writeln!(s, "<li>{}</li>", escape(&f.describe(file)));
        }
        s.push_str("</ul>\n");
    }
    if !any {
        s.push_str("<p>None found: no spikes, dropouts, gaps or saturation.</p>\n");
    }
    s.push_str("</section>\n");
}

fn changes(s: &mut String, d: &Diagnosis, rerun: &[String]) {
    let _ = writeln!(
        s,
        "<section id=\"changes\">\n<h2>What changed</h2>\n<p>The friction component <code>{}</code>'s parameters in the refitted system, against the nominal file:</p>",
        escape(&d.friction_component)
    );
    if d.changes.is_empty() {
        s.push_str("<p>None: the refitted system is the nominal one.</p>\n");
    } else {
        s.push_str("<table>\n<tr><th>variable</th><th>unit</th><th>nominal</th><th>refitted</th><th>change</th></tr>\n");
        for v in &d.changes {
            let _ = writeln!(
                s,
                "<tr><td><code>{}</code></td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}{}</td><td class=\"num\">{}</td></tr>",
                escape(&v.name),
                escape(&v.unit),
                number(v.before),
                number(v.after),
                v.interval.map_or(String::new(), |[low, high]| format!(
                    " ± {}",
                    number(0.5 * (high - low))
                )),
                if v.before != 0.0 {
                    format!("{:+.1} %", 100.0 * (v.after - v.before) / v.before.abs())
                } else {
                    "–".into()
                }
            );
        }
        s.push_str("</table>\n");
    }
    s.push_str("<p>Rerun the refitted system (on the training inputs, then on the held-out file's, with the master and step the diagnosis used: the results are the co-simulations scored here):</p>\n<ul>\n");
    for command in rerun {
        let _ = writeln!(s, "<li><code>{}</code></li>", escape(command));
    }
    s.push_str("</ul>\n");
    for (title, lines) in [
        ("Notes", &d.notes),
        ("Co-simulation fallbacks", &d.fallbacks),
    ] {
        if !lines.is_empty() {
            let _ = writeln!(s, "<h3>{title}</h3>\n<ul>");
            for l in lines {
                let _ = writeln!(s, "<li>{}</li>", escape(l));
            }
            s.push_str("</ul>\n");
        }
    }
    s.push_str("</section>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped() {
        assert_eq!(escape("a<b & \"c\"'"), "a&lt;b &amp; &quot;c&quot;&#39;");
    }

    #[test]
    fn an_svg_document_becomes_an_element() {
        assert_eq!(
            strip_declaration("<?xml version=\"1.0\"?>\n<svg width=\"1\"></svg>"),
            "<svg width=\"1\"></svg>"
        );
    }
}
