//! `hidden-effect-suite`: run `fricsim diagnose` on cases that hide known
//! effects ([`fricsim_hidden_effects::suite`]) and print, per case and in sum,
//! how often the right effect is named, how close its fitted size is to
//! the truth and how far the held-out error drops.
//!
//! ```text
//! hidden-effect-suite --case viscous --case none --magnitude 0.1 --seeds 3
//! hidden-effect-suite --all --magnitude 0.1 --magnitude 0.05 --seeds 5 --json out/suite.json
//! ```

use clap::Parser;
use fricsim_diagnose::model::Effect;
use fricsim_diagnose::Options;
use fricsim_hidden_effects::suite::{export_case, run_case, CaseResult, CaseSpec, SIZE_TOLERANCE};
use std::path::PathBuf;

#[derive(Parser)]
#[command(about = "Diagnose generated data with hidden effects and score the outcome")]
struct Args {
    /// A case: an effect name, two joined by `+`, or `none` (repeat).
    #[arg(long = "case")]
    cases: Vec<String>,
    /// Every single effect at every magnitude, the pair
    /// direction_dependent+viscous at the first magnitude, and null cases.
    #[arg(long)]
    all: bool,
    /// Null cases (nothing hidden) with --all [default: --seeds].
    #[arg(long)]
    null_seeds: Option<u64>,
    /// Magnitudes (fraction of Fc; repeat).
    #[arg(long = "magnitude")]
    magnitudes: Vec<f64>,
    /// Noise seeds per case (1, 2, ...).
    #[arg(long, default_value_t = 1)]
    seeds: u64,
    /// Length of each experiment (s).
    #[arg(long, default_value_t = 12.0)]
    duration: f64,
    /// The nominal system.
    #[arg(long, default_value = "examples/hidden_effect_rig.ssd")]
    system: PathBuf,
    /// Write every case's result as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Do not diagnose: write each case's data, the friction data diagnose
    /// derives from it and its truth into this directory (the input of
    /// scripts/sindy-baseline.py).
    #[arg(long)]
    export: Option<PathBuf>,
}

fn parse_case(s: &str) -> Result<Vec<Effect>, String> {
    if s == "none" {
        return Ok(Vec::new());
    }
    s.split('+').map(Effect::from_name).collect()
}

fn main() {
    if let Err(e) = run() {
        eprintln!("hidden-effect-suite: {e}");
        std::process::exit(1);
    }
}

/// The grid of cases: (hidden, magnitude, seed).
fn grid(a: &Args) -> Result<Vec<CaseSpec>, String> {
    let magnitudes = if a.magnitudes.is_empty() {
        vec![0.1]
    } else {
        a.magnitudes.clone()
    };
    let mut hidden: Vec<Vec<Effect>> = a
        .cases
        .iter()
        .map(|c| parse_case(c))
        .collect::<Result<_, _>>()?;
    if a.all {
        hidden.extend(Effect::ALL.iter().map(|&e| vec![e]));
    }
    let mut cases = Vec::new();
    for h in &hidden {
        // a null case does not depend on the magnitude: once per seed
        let mags: &[f64] = if h.is_empty() {
            &magnitudes[..1]
        } else {
            &magnitudes
        };
        for &magnitude in mags {
            for seed in 1..=a.seeds {
                cases.push(CaseSpec {
                    hidden: h.clone(),
                    magnitude,
                    seed,
                });
            }
        }
    }
    if a.all {
        for seed in 1..=a.seeds {
            cases.push(CaseSpec {
                hidden: vec![Effect::DirectionDependent, Effect::Viscous],
                magnitude: magnitudes[0],
                seed,
            });
        }
        for seed in 1..=a.null_seeds.unwrap_or(a.seeds) {
            cases.push(CaseSpec {
                hidden: Vec::new(),
                magnitude: magnitudes[0],
                seed,
            });
        }
    }
    if cases.is_empty() {
        return Err("no case: give --case NAME or --all".into());
    }
    Ok(cases)
}

fn run() -> Result<(), String> {
    let a = Args::parse();
    let cases = grid(&a)?;
    let options = Options::default();
    if let Some(dir) = &a.export {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for case in &cases {
            export_case(&a.system, case, a.duration, &options, dir)?;
            eprintln!("exported {} {} {}", case.label(), case.magnitude, case.seed);
        }
        return Ok(());
    }
    let work = tempfile::tempdir().map_err(|e| e.to_string())?;
    let mut results: Vec<CaseResult> = Vec::new();
    println!(
        "| hidden | magnitude | seed | found | named right | size error | baseline RMS | final RMS | drop | noise | drop against the truth | s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for case in &cases {
        let r = run_case(&a.system, case, a.duration, &options, work.path())?;
        let found: Vec<&str> = r.found.iter().map(|e| e.name()).collect();
        let sizes: Vec<String> = r
            .sizes
            .iter()
            .map(|s| format!("{} {:.1} %", s.quantity, 100.0 * s.relative_error))
            .collect();
        println!(
            "| {} | {} | {} | {} | {} | {} | {:.5} | {:.5} | {:.2} | {:.5} | {:.1} | {:.1} |",
            case.label(),
            case.magnitude,
            case.seed,
            if found.is_empty() {
                "-".to_string()
            } else {
                found.join(", ")
            },
            if r.named_right { "yes" } else { "NO" },
            if sizes.is_empty() {
                "-".to_string()
            } else {
                sizes.join("; ")
            },
            r.baseline_rms,
            r.final_rms,
            r.heldout_drop,
            r.noise_floor_rms,
            r.truth_drop,
            r.seconds
        );
        results.push(r);
    }
    println!();
    for line in summary(&results) {
        println!("{line}");
    }
    if let Some(path) = &a.json {
        let text = serde_json::to_string_pretty(&results).map_err(|e| e.to_string())?;
        std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    Ok(())
}

/// The rates, per kind of case: single effects per magnitude, pairs, null.
fn summary(results: &[CaseResult]) -> Vec<String> {
    let count =
        |v: &[&CaseResult], f: &dyn Fn(&CaseResult) -> bool| v.iter().filter(|r| f(r)).count();
    let mut lines = Vec::new();
    let mut magnitudes: Vec<f64> = results.iter().map(|r| r.case.magnitude).collect();
    magnitudes.sort_by(|a, b| b.total_cmp(a));
    magnitudes.dedup();
    for &m in &magnitudes {
        let single: Vec<&CaseResult> = results
            .iter()
            .filter(|r| r.case.magnitude == m && r.case.hidden.len() == 1)
            .collect();
        if !single.is_empty() {
            lines.push(format!(
                "one effect at {m}: named right {}/{}, effect size within {:.0} % {}/{}, held-out RMS drop >= 2x {}/{} (against the noise-free truth {}/{}), an effect invented {}/{}",
                count(&single, &|r| r.named_right),
                single.len(),
                100.0 * SIZE_TOLERANCE,
                count(&single, &|r| r.sizes_within),
                single.len(),
                count(&single, &|r| r.heldout_drop >= 2.0),
                single.len(),
                count(&single, &|r| r.truth_drop >= 2.0),
                single.len(),
                count(&single, &|r| r.found.iter().any(|e| !r.case.hidden.contains(e))),
                single.len(),
            ));
        }
        let pairs: Vec<&CaseResult> = results
            .iter()
            .filter(|r| r.case.magnitude == m && r.case.hidden.len() == 2)
            .collect();
        if !pairs.is_empty() {
            lines.push(format!(
                "two effects at {m}: both named (and nothing else) {}/{}, sizes within {:.0} % {}/{}",
                count(&pairs, &|r| r.named_right),
                pairs.len(),
                100.0 * SIZE_TOLERANCE,
                count(&pairs, &|r| r.sizes_within),
                pairs.len(),
            ));
        }
    }
    let null: Vec<&CaseResult> = results
        .iter()
        .filter(|r| r.case.hidden.is_empty())
        .collect();
    if !null.is_empty() {
        lines.push(format!(
            "nothing hidden: an effect claimed {}/{}",
            count(&null, &|r| !r.found.is_empty()),
            null.len()
        ));
    }
    lines
}
