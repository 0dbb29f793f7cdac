//! Running a model in process, without the C ABI: the reference the FMU is
//! compared against (FMPy through the C ABI must give the same numbers).

use fmi_export::{Causality, Model, ModelInfo, Values};

/// Inputs at each communication point: `time[n]`, and per input its value
/// and slope `du/dt` at that point (slope 0 when not interpolated).
pub struct InputTable {
    pub time: Vec<f64>,
    pub inputs: Vec<(u32, Vec<f64>, Vec<f64>)>,
}

/// Outputs at every communication point, `rows[n][k]` for output `k` of
/// `info` in table order.
pub struct OutputTable {
    pub names: Vec<&'static str>,
    pub time: Vec<f64>,
    pub rows: Vec<Vec<f64>>,
}

/// Simulate `model` over the communication points of `table` with
/// `parameters` (value reference, value): set the inputs at `t[n]`, step to
/// `t[n+1]`, read the outputs, exactly as a co-simulation master does.
pub fn simulate(
    mut model: Box<dyn Model>,
    parameters: &[(u32, f64)],
    table: &InputTable,
) -> Result<OutputTable, String> {
    let info: &'static ModelInfo = model.info();
    let mut values = Values::from_start(info.variables);
    for (vr, v) in parameters {
        values.set(*vr, *v);
    }
    let outputs: Vec<u32> = info
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .map(|v| v.vr)
        .collect();
    let mut slopes = vec![0.0; values.len()];
    let apply = |n: usize, values: &mut Values, slopes: &mut [f64]| {
        for (vr, u, du) in &table.inputs {
            values.set(*vr, u[n]);
            slopes[*vr as usize] = du[n];
        }
    };
    apply(0, &mut values, &mut slopes);
    model.initialize(&values)?;
    model.compute_outputs(&mut values);
    let mut out = OutputTable {
        names: outputs
            .iter()
            .map(|vr| info.variables[*vr as usize].name)
            .collect(),
        time: vec![table.time[0]],
        rows: vec![outputs.iter().map(|vr| values.real(*vr)).collect()],
    };
    for n in 0..table.time.len().saturating_sub(1) {
        apply(n, &mut values, &mut slopes);
        let h = table.time[n + 1] - table.time[n];
        model.do_step(&values, &slopes, h)?;
        for (vr, _, _) in &table.inputs {
            let s = &mut slopes[*vr as usize];
            values.set(*vr, values.real(*vr) + *s * h);
            *s = 0.0;
        }
        model.compute_outputs(&mut values);
        out.time.push(table.time[n + 1]);
        out.rows
            .push(outputs.iter().map(|vr| values.real(*vr)).collect());
    }
    Ok(out)
}
