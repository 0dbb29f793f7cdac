//! `run-law MODEL INPUT.csv OUTPUT.csv [name=value …]`: simulate one friction
//! model in process (no C ABI) on the communication points of INPUT.csv.
//!
//! INPUT.csv: header `time,<input>,…[,der(<input>),…]`, one row per
//! communication point. OUTPUT.csv: `time,<output>,…` at the same points,
//! numbers printed so that they parse back to the same `f64`.

use friction_fmu::in_process::{simulate, InputTable};
use std::process::ExitCode;

fn run(args: &[String]) -> Result<(), String> {
    let [model_name, input, output, assignments @ ..] = args else {
        return Err("usage: run-law MODEL INPUT.csv OUTPUT.csv [name=value ...]".into());
    };
    let model = friction_fmu::create(model_name).ok_or_else(|| {
        let names: Vec<_> = friction_fmu::models()
            .iter()
            .map(|m| m.model_name)
            .collect();
        format!("unknown model {model_name} (known: {})", names.join(", "))
    })?;
    let info = model.info();
    let mut parameters = Vec::new();
    for a in assignments {
        let (name, value) = a
            .split_once('=')
            .ok_or_else(|| format!("expected name=value, got {a}"))?;
        let var = info
            .by_name(name)
            .ok_or_else(|| format!("{model_name} has no variable {name}"))?;
        let value = match value {
            "true" => 1.0,
            "false" => 0.0,
            v => v.parse::<f64>().map_err(|e| format!("{name} = {v}: {e}"))?,
        };
        parameters.push((var.vr, value));
    }

    let text = std::fs::read_to_string(input).map_err(|e| format!("{input}: {e}"))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or_else(|| format!("{input} is empty"))?
        .split(',')
        .collect();
    if header.first() != Some(&"time") {
        return Err(format!("{input}: the first column must be `time`"));
    }
    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); header.len()];
    for (i, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != header.len() {
            return Err(format!(
                "{input} line {}: {} cells, header has {}",
                i + 2,
                cells.len(),
                header.len()
            ));
        }
        for (c, cell) in columns.iter_mut().zip(cells) {
            c.push(
                cell.trim()
                    .parse()
                    .map_err(|e| format!("{input} line {}: {cell}: {e}", i + 2))?,
            );
        }
    }
    let n = columns[0].len();
    let mut table = InputTable {
        time: columns[0].clone(),
        inputs: Vec::new(),
    };
    for (k, name) in header.iter().enumerate().skip(1) {
        if name.starts_with("der(") {
            continue;
        }
        let var = info
            .by_name(name)
            .ok_or_else(|| format!("{model_name} has no input {name}"))?;
        let slope = header
            .iter()
            .position(|h| *h == format!("der({name})"))
            .map(|j| columns[j].clone())
            .unwrap_or_else(|| vec![0.0; n]);
        table.inputs.push((var.vr, columns[k].clone(), slope));
    }

    let result = simulate(model, &parameters, &table)?;
    let mut csv = format!("time,{}\n", result.names.join(","));
    for (t, row) in result.time.iter().zip(&result.rows) {
        csv.push_str(&format!("{t:?}"));
        for x in row {
            csv.push_str(&format!(",{x:?}"));
        }
        csv.push('\n');
    }
    std::fs::write(output, csv).map_err(|e| format!("{output}: {e}"))
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("run-law: {e}");
            ExitCode::FAILURE
        }
    }
}
