//! `fricsim-bench`: the programs that measure the host for BENCHMARKS.md,
//! kept out of the product (`fricsim`, host/), which they use as a library:
//!
//! - `speed-table` (scripts/bench.sh): the speed tables, the monolithic
//!   limit included (the laws and the rig stepped in one loop, no FMI);
//! - `accuracy-table` (scripts/accuracy-table.sh): the accuracy table;
//! - `hidden-effect-suite` (scripts/hidden-effect-suite.sh): the
//!   hidden-effect suite of `fricsim diagnose`;
//! - `benches/speed.rs`: criterion's statistics for single figures.
//!
//! This library is what they share: replacing the generated part of a
//! markdown file between two markers, naming the machine and the date of a
//! measurement, and the workloads of the speed figures.

use std::path::Path;

pub mod fmi_loop;

/// Replace the text between the markers `begin` and `end` of `path` with
/// `block` (which holds the markers), keeping the rest; a missing file is
/// created with a title, a file without the markers is refused. With no
/// `block`, only check that this can be done.
pub fn splice(path: &Path, begin: &str, end: &str, block: Option<&str>) -> Result<(), String> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            format!("# Benchmarks\n\n{begin}\n{end}\n")
        }
        Err(e) => return Err(format!("{}: {e}", path.display())),
    };
    let generated = marked(path, &text, begin, end)?;
    let Some(block) = block else {
        return Ok(());
    };
    let mut out = String::with_capacity(text.len() + block.len());
    out.push_str(&text[..generated.start]);
    out.push_str(block.trim_end_matches('\n'));
    out.push_str(&text[generated.end..]);
    std::fs::write(path, out).map_err(|e| format!("{}: {e}", path.display()))
}

/// The generated part of `path`, from the marker `begin` through the
/// marker `end`, as [`splice`] writes it: what a published table is read
/// from. A missing file or missing markers are refused.
pub fn generated_part(path: &Path, begin: &str, end: &str) -> Result<String, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let generated = marked(path, &text, begin, end)?;
    Ok(text[generated].to_string())
}

/// Where in `text` (the contents of `path`) the generated part is: from
/// the marker `begin` through the marker `end`.
fn marked(
    path: &Path,
    text: &str,
    begin: &str,
    end: &str,
) -> Result<std::ops::Range<usize>, String> {
    let (Some(b), Some(e)) = (text.find(begin), text.find(end)) else {
        return Err(format!(
            "{}: the markers `{begin}` and `{end}` are missing: add them where the table goes",
            path.display()
        ));
    };
    if e < b {
        return Err(format!(
            "{}: the end marker comes before the begin marker",
            path.display()
        ));
    }
    Ok(b..e + end.len())
}

/// The options every BENCHMARKS.md program has: where the repository is
/// and which file to update.
#[derive(clap::Args, Debug)]
pub struct TableFileArgs {
    /// The repository root, where examples/ and dist/ are
    /// [default: the workspace this program was built from].
    #[arg(long)]
    pub root: Option<std::path::PathBuf>,
    /// Write the tables between the markers of this file (created if
    /// missing) instead of stdout.
    #[arg(long)]
    pub update: Option<std::path::PathBuf>,
}

impl TableFileArgs {
    /// `--root`, else the workspace the program was built from.
    pub fn root(&self) -> std::path::PathBuf {
        self.root
            .clone()
            .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
    }
}

/// The exit of a BENCHMARKS.md program: its error on stderr, named.
pub fn exit_code(program: &str, result: Result<(), String>) -> std::process::ExitCode {
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{program}: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// CPU model (from /proc/cpuinfo), cores the process may use, OS.
pub fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism()
        .map(|n| n.get().to_string())
        .unwrap_or_else(|_| "?".into());
    format!(
        "{model}, {cores} cores, {} {}",
        std::env::consts::OS,
        std::env::consts::ARCH
    )
}

/// Today's date (UTC), YYYY-MM-DD, from the system clock (civil-from-days,
/// H. Hinnant's algorithm).
pub fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs() as i64)
        .unwrap_or(0);
    let z = secs.div_euclid(86_400) + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}")
}

/// The command line a table records: `variable` when the script that ran
/// the program set it (the script names itself), else the program's own.
pub fn command_line(variable: &str, program: &str) -> String {
    std::env::var(variable).unwrap_or_else(|_| {
        std::iter::once(program.to_string())
            .chain(std::env::args().skip(1))
            .collect::<Vec<_>>()
            .join(" ")
    })
}

// ---- workloads shared by `speed-table` and the criterion benches ---------

/// An input signal `u(t) = A·sin(2π·t + φ)`: (name, A, φ).
pub type Sinusoid = (&'static str, f64, f64);

/// A benchmarked FMU: the row's label, the model, its inputs, the outputs
/// read every step, and for the element laws (Maxwell-slip, GMS) the
/// number of elements (`None`: the FMU's default set).
pub struct DrivenFmu {
    pub label: &'static str,
    pub model: &'static str,
    pub inputs: &'static [Sinusoid],
    pub outputs: &'static [&'static str],
    pub elements: Option<usize>,
}

const fn driven(
    model: &'static str,
    inputs: &'static [Sinusoid],
    outputs: &'static [&'static str],
) -> DrivenFmu {
    DrivenFmu {
        label: model,
        model,
        inputs,
        outputs,
        elements: None,
    }
}

/// The friction FMUs of dist/ and how a benchmark drives them: inputs
/// through stick and slip at the default parameters.
pub const FRICTION_FMUS: &[DrivenFmu] = &[
    driven("Dahl", &[("v", 1e-3, 0.0)], &["F"]),
    driven("LuGre", &[("v", 1e-3, 0.0)], &["F"]),
    driven("ResetIntegrator", &[("v", 1e-3, 0.0)], &["F"]),
    // 3·δmax = 4.7e-8 m of Appels and Herder: loads to sliding, reverses twice a period
    driven("Bristle", &[("x", 4.7e-8, 0.0)], &["F"]),
    driven(
        "Bristle2D",
        &[("v1", 1e-3, 0.0), ("v2", 1e-3, std::f64::consts::FRAC_PI_2)],
        &["F1", "F2"],
    ),
    // through the zero-velocity band twice a period, the applied force
    // (3 N) above the static level (2.35 N) in part of it
    driven(
        "Classical",
        &[
            ("v", 1e-3, 0.0),
            ("F_app", 3.0, std::f64::consts::FRAC_PI_2),
        ],
        &["F"],
    ),
    driven("BlimanSorine", &[("v", 1e-3, 0.0)], &["F"]),
    driven("ElastoPlastic", &[("v", 1e-3, 0.0)], &["F"]),
    driven("MaxwellSlip", &[("v", 1e-3, 0.0)], &["F"]),
    DrivenFmu {
        label: "MaxwellSlip, 100 elements",
        elements: Some(100),
        ..driven("MaxwellSlip", &[("v", 1e-3, 0.0)], &["F"])
    },
    driven("GMS", &[("v", 1e-3, 0.0)], &["F"]),
    DrivenFmu {
        label: "GMS, 100 elements",
        elements: Some(100),
        ..driven("GMS", &[("v", 1e-3, 0.0)], &["F"])
    },
];

/// The element laws' parameters for `n` elements: `n_elements` and `n`
/// even elements of the default initial stiffness 1e5 N/m
/// ([`friction_laws::maxwell_slip::even_elements`]) up to the FMU's level
/// (GMS: weights `alpha[i]` of `Fs`; Maxwell-slip: slip forces `W[i]`
/// summing to its default Coulomb level).
fn set_elements(
    instance: &mut fricsim_fmi::Instance,
    fmu: &fricsim_fmi::Fmu,
    model: &str,
    n: usize,
) -> Result<(), String> {
    let vr = |name: &str| {
        fmu.variable(name)
            .map(|v| v.value_reference)
            .map_err(|e| e.to_string())
    };
    // the defaults from the model description (no value can be read
    // before initialization)
    let start = |name: &str| -> Result<f64, String> {
        match &fmu.variable(name).map_err(|e| e.to_string())?.kind {
            fricsim_fmi::VariableKind::Real { start: Some(x), .. } => Ok(*x),
            fricsim_fmi::VariableKind::Integer { start: Some(x), .. } => Ok(f64::from(*x)),
            _ => Err(format!("{model}: no start value for {name}")),
        }
    };
    let gms = model == "GMS";
    let level = if gms {
        start("Fs")?
    } else {
        let n0 = start("n_elements")? as usize;
        (1..=n0)
            .map(|i| start(&format!("W[{i}]")))
            .sum::<Result<f64, String>>()?
    };
    let (k, w) = friction_laws::maxwell_slip::even_elements(n, 1e5, level);
    instance
        .set_integer(&[vr("n_elements")?], &[n as i32])
        .map_err(|e| e.to_string())?;
    for i in 0..n {
        let second = if gms {
            (format!("alpha[{}]", i + 1), w[i] / level)
        } else {
            (format!("W[{}]", i + 1), w[i])
        };
        instance
            .set_real(
                &[vr(&format!("k[{}]", i + 1))?, vr(&second.0)?],
                &[k[i], second.1],
            )
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// One initialised instance of a friction FMU of [`FRICTION_FMUS`] and its
/// resolved value references: [`FmuStepper::step`] is one communication
/// step through the C ABI (`fmi2SetReal`, `fmi2DoStep`, `fmi2GetReal`).
pub struct FmuStepper {
    instance: fricsim_fmi::Instance,
    inputs: &'static [Sinusoid],
    input_vrs: Vec<fricsim_fmi::ValueReference>,
    output_vrs: Vec<fricsim_fmi::ValueReference>,
    u: Vec<f64>,
    /// The outputs after the last step.
    pub y: Vec<f64>,
}

impl FmuStepper {
    /// Instantiate the `index`-th model of [`FRICTION_FMUS`] from `fmu`,
    /// initialised at t = 0 with its default parameters.
    pub fn new(fmu: &fricsim_fmi::Fmu, index: usize) -> Result<FmuStepper, String> {
        let driven = &FRICTION_FMUS[index];
        let (model, inputs, outputs) = (driven.model, driven.inputs, driven.outputs);
        let vr = |name: &str| {
            fmu.variable(name)
                .map(|v| v.value_reference)
                .map_err(|e| e.to_string())
        };
        let input_vrs = inputs
            .iter()
            .map(|(n, _, _)| vr(n))
            .collect::<Result<Vec<_>, _>>()?;
        let output_vrs = outputs.iter().map(|n| vr(n)).collect::<Result<_, _>>()?;
        let mut instance = fmu.instantiate(model).map_err(|e| e.to_string())?;
        if let Some(n) = driven.elements {
            set_elements(&mut instance, fmu, model, n)?;
        }
        instance
            .setup_experiment(0.0, None)
            .and_then(|_| instance.enter_initialization_mode())
            .and_then(|_| instance.exit_initialization_mode())
            .map_err(|e| e.to_string())?;
        Ok(FmuStepper {
            instance,
            inputs,
            input_vrs,
            output_vrs,
            u: vec![0.0; inputs.len()],
            y: vec![0.0; outputs.len()],
        })
    }

    /// Set the inputs at `t`, step to `t + h`, read the outputs.
    pub fn step(&mut self, t: f64, h: f64) -> Result<(), fricsim_fmi::FmuError> {
        for (x, (_, a, phase)) in self.u.iter_mut().zip(self.inputs) {
            *x = a * (std::f64::consts::TAU * t + phase).sin();
        }
        self.instance.set_real(&self.input_vrs, &self.u)?;
        self.instance.do_step(t, h)?;
        self.instance.get_real(&self.output_vrs, &mut self.y)?;
        Ok(())
    }
}

/// Increments of the bristle curves.
pub const INCREMENTS: usize = 1000;

/// Increment `k` (1 ..= [`INCREMENTS`]) of the bristle curve with one
/// reversal: 0 → 3·δmax in the first half, back to −3·δmax in the second.
pub fn bristle_curve_point(k: usize, delta_max: f64) -> f64 {
    let half = INCREMENTS / 2;
    if k <= half {
        3.0 * delta_max * k as f64 / half as f64
    } else {
        3.0 * delta_max * (1.0 - 2.0 * (k - half) as f64 / half as f64)
    }
}

/// The bristle curve with one reversal on `bristle`; the sum of the
/// forces (to keep the work from being optimised away).
pub fn bristle_curve(bristle: &mut friction_laws::bristle::Bristle) -> f64 {
    let delta_max = bristle.params().delta_max;
    let mut sum = 0.0;
    for k in 1..=INCREMENTS {
        bristle.move_to(bristle_curve_point(k, delta_max));
        sum += bristle.force();
    }
    sum
}

/// `/proc/loadavg`'s one-minute load average (NaN where there is none):
/// how busy the machine was around a measurement.
pub fn load_average() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|t| t.split_whitespace().next().and_then(|x| x.parse().ok()))
        .unwrap_or(f64::NAN)
}
