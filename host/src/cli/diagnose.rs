//! `fricsim diagnose SYSTEM DATA.csv [DATA2.csv ...]`: find where the system and the
//! measurements disagree, name the missing friction effect from the
//! library, add it, refit, and show the error on held-out data
//! ([`fricsim::diagnose`]).

use fricsim::diagnose::model::Effect;
use fricsim::diagnose::progress_line::with_progress_line;
use fricsim::diagnose::{
    diagnose_and_write, report, CrossValidate, Options, Progress, DEFAULT_TIME_LIMIT,
};

/// `--cross-validate`.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum CrossValidateArg {
    Auto,
    Always,
    Never,
    Records,
}
use fricsim::output_file::same_file;
use fricsim::ssp::SystemFile;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct DiagnoseArgs {
    /// The nominal system: an .ssp archive or a SystemStructure .ssd file
    /// with one LuGre friction component.
    pub system: PathBuf,
    /// Measurements: CSV with `time` first, then `component.variable`
    /// columns, or a .mat result file; unconnected inputs drive the
    /// system, outputs are compared. Several records of the same system
    /// (the same columns) are fitted together, each co-simulated from its
    /// own start with its own inputs.
    #[arg(required = true, num_args = 1..)]
    pub data: Vec<PathBuf>,
    /// Held-out records (same channels) to score on [default: with several
    /// DATA records each held out in turn; with one, every third of 30
    /// equal time blocks of it, from the second on].
    #[arg(long, num_args = 1..)]
    pub heldout: Vec<PathBuf>,
    /// Output directory [default: out/<system name>-diagnosis].
    #[arg(long)]
    pub out: Option<PathBuf>,
    // Candidate effects to try: the help lists the effects of the library
    // with their meanings (`candidates_help`).
    #[arg(long = "candidate", help = candidates_help())]
    pub candidates: Vec<String>,
    /// Knots of the position table of position_dependent.
    #[arg(long, default_value_t = fricsim::diagnose::model::DEFAULT_POSITION_KNOTS)]
    pub position_knots: usize,
    /// The most knots the position table may be given when the rounds
    /// end with position_dependent: the knots are doubled (2k − 1) while
    /// the finer table passes the test that admitted the effect; set it
    /// to --position-knots to keep the table as added.
    #[arg(long, default_value_t = fricsim::diagnose::model::MAX_TABLE_POINTS)]
    pub max_position_knots: usize,
    /// Family-wise significance level of the acceptance test.
    #[arg(long, default_value_t = 0.01)]
    pub alpha: f64,
    /// Without --heldout: cut DATA into this many equal time blocks and
    /// hold out every third (one block per independent trial, e.g. per
    /// row of a table of break-away measurements).
    #[arg(long, default_value_t = fricsim::diagnose::SPLIT_BLOCKS)]
    pub blocks: usize,
    /// Without --heldout: score every block by three-fold cross-validation
    /// (each third of the blocks held out once), only one third, or each
    /// record in turn (records); auto holds out each record in turn when
    /// there are several, else cross-validates data of at most 5000
    /// samples.
    #[arg(long, value_enum, default_value_t = CrossValidateArg::Auto)]
    pub cross_validate: CrossValidateArg,
    /// Smoothing window of the measured position for the inverse dynamics (s).
    #[arg(long, default_value_t = 0.01)]
    pub smooth: f64,
    /// Skip the output-error refinement of accepted models (faster; the
    /// fitted parameters are those of the force fit).
    #[arg(long)]
    pub no_polish: bool,
    /// Master of the diagnosis's co-simulations [default: the system's,
    /// with its inputs interpolated: newton -> newton-interpolated,
    /// gauss-seidel -> gauss-seidel-interpolated]
    #[arg(long)]
    pub master: Option<String>,
    /// LuGre.fmu to move a Dahl nominal to [default: the LuGre.fmu beside
    /// the Dahl FMU]
    #[arg(long)]
    pub lugre: Option<PathBuf>,
    /// Wall time after which the diagnosis starts no new work (inf: no
    /// limit). A fit or co-simulation running then stops within a few
    /// co-simulations; the baseline and the effects accepted so far are
    /// kept, the round in progress is not decided (its unfinished
    /// candidates are named, neither accepted nor rejected), later steps
    /// (refinement, re-examination, step error, intervals) are skipped,
    /// and report.json (time_limit), report.md, report.html and the
    /// summary say what was left out. A report is still written and the
    /// exit status is 0.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = DEFAULT_TIME_LIMIT,
        value_parser = time_limit,
        allow_hyphen_values = true
    )]
    pub time_limit: f64,
    /// No progress line (it is shown on stderr only when stderr is a
    /// terminal: the stage or round, the candidates being fitted, the
    /// co-simulations run, the time elapsed and an estimate of what is
    /// left of the round).
    #[arg(long, short)]
    pub quiet: bool,
}

/// `--time-limit`: a positive number of seconds, or inf.
fn time_limit(text: &str) -> Result<f64, String> {
    let seconds: f64 = text.trim().parse().map_err(|_| {
        format!("`{text}` is not a number of seconds (a positive number, or inf for no limit)")
    })?;
    fricsim::diagnose::budget::check_time_limit(seconds)?;
    Ok(seconds)
}

/// The subcommand's description, naming every effect of the library
/// ([`Effect::ALL`]).
pub fn about() -> String {
    format!(
        "Where a system and measurements disagree: names the missing friction effect ({}), adds it to the LuGre FMU, refits, and reports the error on held-out data; writes report.json, report.md, plots and the refitted system",
        Effect::ALL.map(|e| e.name()).join(", ")
    )
}

/// `--candidate`'s help: every effect of the library with its meaning
/// ([`Effect::help_list`]).
fn candidates_help() -> String {
    let list = Effect::help_list()
        .lines()
        .map(|line| format!("  {line}"))
        .collect::<Vec<_>>()
        .join("\n");
    format!("Candidate effects to try (repeat) [default: all]:\n{list}")
}

pub fn run(a: &DiagnoseArgs) -> Result<(), String> {
    let mut options = Options {
        position_knots: a.position_knots,
        max_position_knots: a.max_position_knots,
        alpha: a.alpha,
        smooth: a.smooth,
        blocks: a.blocks,
        polish: !a.no_polish,
        master: a.master.clone(),
        time_limit: fricsim::diagnose::budget::check_time_limit(a.time_limit)?,
        cross_validate: match a.cross_validate {
            CrossValidateArg::Auto => CrossValidate::Auto,
            CrossValidateArg::Always => CrossValidate::Always,
            CrossValidateArg::Never => CrossValidate::Never,
            CrossValidateArg::Records => CrossValidate::Records,
        },
        ..Options::default()
    };
    options.check()?;
    if !a.candidates.is_empty() {
        options.candidates = a
            .candidates
            .iter()
            .map(|c| Effect::from_name(c))
            .collect::<Result<_, _>>()?;
    }
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| super::default_out(&a.system, "-diagnosis").with_extension(""));
    // the report directory is written whole (diagnose::report), but never
    // over one of the inputs
    let inputs = std::iter::once(("the system file", &a.system))
        .chain(a.data.iter().map(|p| ("the measured data", p)))
        .chain(a.heldout.iter().map(|p| ("the held-out data", p)))
        .chain(a.lugre.iter().map(|p| ("the LuGre FMU", p)));
    if let Some((what, input)) = inputs.into_iter().find(|(_, p)| same_file(&out, p)) {
        return Err(format!(
            "the report directory {} is {what} {}, an input of the run: choose another --out",
            out.display(),
            input.display()
        ));
    }
    let mut file = SystemFile::open(&a.system).map_err(|e| e.to_string())?;
    let moved = fricsim::diagnose::dahl::move_to_lugre(&mut file, a.lugre.as_deref())?;
    // the progress line, drawn while the diagnosis and the report's
    // writing run, and cleared before the summary is printed
    let progress = Progress::new();
    options.progress = Some(progress.clone());
    let d = with_progress_line("diagnose", a.quiet, &progress, || {
        diagnose_and_write(&file, (&a.data, &a.heldout), &options, moved, &out)
    })?;
    for note in &d.notes {
        println!("note: {note}");
    }
    let names: Vec<&str> = d.effects.iter().map(|e| e.name.name()).collect();
    println!(
        "{}: {}",
        file.ssd,
        if names.is_empty() {
            "no missing effect found".to_string()
        } else {
            format!("missing {}", names.join(", then "))
        }
    );
    for e in &d.effects {
        println!(
            "  {:<20} {:<8} held-out RMS {:.5} -> {:.5} (p = {:.1e}); where: {} {}.{}",
            e.name.name(),
            e.action,
            e.rms_before,
            e.rms_after,
            e.p_value,
            e.where_.state,
            e.where_.bin,
            fricsim::diagnose::report::alternatives_line(e)
        );
    }
    println!(
        "held-out RMS: given {:.5}, levels refitted {}, final {:.5}; floor {:.5} (noise {:.5}, step error {:.5}){}",
        d.nominal_rms,
        if d.refit.unfinished {
            "not finished (time limit)".to_string()
        } else {
            format!(
                "{:.5} ({})",
                d.refit.heldout_rms,
                if d.refit.kept { "kept" } else { "not kept" }
            )
        },
        d.final_rms,
        d.floor_rms,
        d.noise_floor_rms,
        d.step_error_rms,
        if d.unexplained {
            format!(
                "; UNEXPLAINED residual, largest in {}",
                d.residual_pattern.strongest
            )
        } else {
            String::new()
        }
    );
    for (label, q) in std::iter::once((&d.data, &d.data_quality.data))
        .chain(d.data_quality.heldout.as_ref().map(|q| (&d.heldout, q)))
    {
        if q.total() > 0 {
            eprintln!(
                "warning: {label}: {} spikes, {} dropouts, {} gaps, {} saturated columns; {} samples left out (report.md lists them)",
                q.spikes, q.dropouts, q.gaps, q.saturated, q.excluded_samples
            );
            for f in q.findings.iter().take(5) {
                eprintln!("  {}", f.describe(label));
            }
        }
    }
    for f in &d.fallbacks {
        eprintln!("note: co-simulation fallback: {f}");
    }
    if d.polish_cosimulations > 0 {
        println!(
            "refinement on the output error: {} co-simulations, {:.2} s",
            d.polish_cosimulations, d.polish_seconds
        );
    }
    if let Some(sentence) = d.time_limit.sentence() {
        println!("TIME LIMIT REACHED: {sentence}");
    }
    println!(
        "{:.2} s; wrote {}/report.html (open it in a browser), report.md, report.json, gap.png, fit.png, law.png, residual.png, refitted.ssp, {}",
        d.wall_seconds,
        out.display(),
        report::input_files(&d)
            .into_iter()
            .map(|(_, name, _)| name)
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}
