//! Drives one of our FMUs through the `fmi` crate's FMI 2.0 Co-Simulation
//! import API (fmi-rs), as an importer that is not ours would.
//!
//! ```text
//! fmi-crate-drive FMU INPUT.csv OUT.csv [NAME=VALUE ...]
//! ```
//!
//! INPUT.csv has a header `time,<input>,...` and one row per communication
//! point. The FMU is unpacked and loaded by the crate, the parameters are
//! set after instantiation (Real, Integer or Boolean, by the type the
//! crate read from the model description), the experiment is set up from
//! the first to the last time of INPUT.csv (a defined stop time), and at
//! each row but the last the inputs are set and the FMU steps to the next
//! row's time. OUT.csv gets `time` and every Real, Integer and Boolean
//! (as 0/1) output the crate finds in the model description, in its
//! order, after initialization and after each step; reals are printed
//! with Rust's shortest round-trip formatting, so they are read back bit
//! for bit.
//!
//! Afterwards one step past the stop time is attempted; its outcome is
//! printed on stdout as `step past stop: <result>` (FMI 2.0 §2.1.6: it must
//! fail).

use std::{error::Error, fmt::Write as _, fs, process::ExitCode};

use fmi::{
    fmi2::{
        import::Fmi2Import,
        instance::{CoSimulation, Common, InstanceCS},
        schema::{Causality, ScalarVariableElement},
    },
    import,
    traits::{FmiImport, FmiInstance},
};

type Res<T> = Result<T, Box<dyn Error>>;

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Real,
    Integer,
    Boolean,
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        eprintln!("usage: fmi-crate-drive FMU INPUT.csv OUT.csv [NAME=VALUE ...]");
        return ExitCode::from(2);
    }
    match run(&args[0], &args[1], &args[2], &args[3..]) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fmi-crate-drive: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The input table: column names after `time`, and the rows.
fn read_input(path: &str) -> Res<(Vec<String>, Vec<Vec<f64>>)> {
    let text = fs::read_to_string(path)?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or("empty input file")?
        .split(',')
        .map(str::to_owned)
        .collect();
    if header.first().map(String::as_str) != Some("time") {
        return Err("the input's first column must be `time`".into());
    }
    let mut rows = Vec::new();
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let row = line
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<Vec<_>, _>>()?;
        if row.len() != header.len() {
            return Err(format!("row `{line}` has {} columns", row.len()).into());
        }
        rows.push(row);
    }
    if rows.len() < 2 {
        return Err("the input needs at least two rows".into());
    }
    Ok((header[1..].to_vec(), rows))
}

fn run(fmu: &str, input: &str, out: &str, assignments: &[String]) -> Res<()> {
    let (input_names, rows) = read_input(input)?;
    let import: Fmi2Import = import::from_path(fmu)?;
    let md = import.model_description();
    if md.fmi_version != "2.0" {
        return Err(format!("fmiVersion {} is not 2.0", md.fmi_version).into());
    }

    let mut input_vrs = Vec::new();
    for name in &input_names {
        let var = md.model_variable_by_name(name)?;
        if var.causality != Causality::Input || !var.is_continuous_input() {
            return Err(format!("`{name}` is not a Real input").into());
        }
        input_vrs.push(var.value_reference);
    }
    // Every Real, Integer and Boolean output, in the model description's order.
    let outputs: Vec<(String, u32, Kind)> = md
        .get_model_variables()
        .filter(|v| v.causality == Causality::Output)
        .filter_map(|v| {
            let kind = match v.elem {
                ScalarVariableElement::Real(_) => Kind::Real,
                ScalarVariableElement::Integer(_) => Kind::Integer,
                ScalarVariableElement::Boolean(_) => Kind::Boolean,
                _ => return None,
            };
            Some((v.name.clone(), v.value_reference, kind))
        })
        .collect();
    if !outputs.iter().any(|o| o.2 == Kind::Real) {
        return Err("the model description declares no Real output".into());
    }
    let vrs = |kind: Kind| -> Vec<u32> {
        outputs
            .iter()
            .filter(|o| o.2 == kind)
            .map(|o| o.1)
            .collect()
    };
    let (real_vrs, int_vrs, bool_vrs) = (vrs(Kind::Real), vrs(Kind::Integer), vrs(Kind::Boolean));

    let mut inst = import.instantiate_cs("fmi-crate", false, false)?;
    for assignment in assignments {
        let (name, value) = assignment
            .split_once('=')
            .ok_or_else(|| format!("`{assignment}` is not NAME=VALUE"))?;
        let var = md.model_variable_by_name(name)?;
        let vr = [var.value_reference];
        match &var.elem {
            ScalarVariableElement::Real(_) => inst.set_real(&vr, &[value.parse()?]),
            ScalarVariableElement::Integer(_) => inst.set_integer(&vr, &[value.parse()?]),
            ScalarVariableElement::Boolean(_) => {
                let b = match value {
                    "true" | "1" => 1,
                    "false" | "0" => 0,
                    _ => return Err(format!("`{value}` is not a Boolean").into()),
                };
                inst.set_boolean(&vr, &[b])
            }
            _ => return Err(format!("`{name}` is neither Real, Integer nor Boolean").into()),
        }
        .map_err(|e| format!("setting {name}={value}: {e}"))?;
    }

    let start = rows[0][0];
    let stop = rows[rows.len() - 1][0];
    FmiInstance::enter_initialization_mode(&mut inst, None, start, Some(stop))
        .map_err(|e| format!("fmi2SetupExperiment/fmi2EnterInitializationMode: {e}"))?;
    FmiInstance::exit_initialization_mode(&mut inst)
        .map_err(|e| format!("fmi2ExitInitializationMode: {e}"))?;

    let mut csv = String::from("time");
    for (name, _, _) in &outputs {
        write!(csv, ",{name}")?;
    }
    csv.push('\n');
    let mut reals = vec![0.0; real_vrs.len()];
    let mut ints = vec![0; int_vrs.len()];
    let mut bools = vec![0; bool_vrs.len()];
    let mut record = |inst: &mut InstanceCS, t: f64| -> Res<()> {
        inst.get_real(&real_vrs, &mut reals)?;
        if !int_vrs.is_empty() {
            inst.get_integer(&int_vrs, &mut ints)?;
        }
        if !bool_vrs.is_empty() {
            inst.get_boolean(&bool_vrs, &mut bools)?;
        }
        write!(csv, "{t:?}")?;
        let (mut r, mut i, mut b) = (reals.iter(), ints.iter(), bools.iter());
        for (_, _, kind) in &outputs {
            match kind {
                Kind::Real => write!(csv, ",{:?}", r.next().unwrap())?,
                Kind::Integer => write!(csv, ",{}", i.next().unwrap())?,
                Kind::Boolean => write!(csv, ",{}", i32::from(*b.next().unwrap() != 0))?,
            }
        }
        csv.push('\n');
        Ok(())
    };
    record(&mut inst, start)?;
    for pair in rows.windows(2) {
        let (now, next) = (&pair[0], &pair[1]);
        inst.set_real(&input_vrs, &now[1..])?;
        inst.do_step(now[0], next[0] - now[0], true)
            .map_err(|e| format!("fmi2DoStep at t = {}: {e}", now[0]))?;
        record(&mut inst, next[0])?;
    }
    fs::write(out, csv)?;

    let past = inst.do_step(stop, stop - rows[rows.len() - 2][0], true);
    println!("step past stop: {past:?}");
    if past.is_err() {
        FmiInstance::reset(&mut inst)?;
    } else {
        FmiInstance::terminate(&mut inst)?;
    }
    Ok(())
}
