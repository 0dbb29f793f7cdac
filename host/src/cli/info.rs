//! `fricsim info FMU`: what `fmpy info` shows — the model, its
//! capabilities, the default experiment and a table of all variables (an
//! FMI 3.0 array as its elements, `k[1]`, …, which a table of the arrays
//! after it sums up), each with its type in its FMI version. Only
//! the model description is unpacked (every entry of the archive is
//! checked, no other written, no binary loaded), so FMUs for other
//! platforms can be inspected too.

use fricsim::fmu::archive::{unpack, UnpackOptions};
use fricsim::fmu::library::platforms;
use fricsim::fmu::ModelDescription;
use fricsim::FmuError;
use std::fmt::Write;
use std::path::Path;

pub fn run(path: &Path) -> Result<(), FmuError> {
    let options = UnpackOptions {
        description_only: true,
        ..UnpackOptions::default()
    };
    let dir = unpack(path, &options)?;
    let description = ModelDescription::from_file(&dir.path().join("modelDescription.xml"))?;
    print!("{}", render(&description, &platforms(dir.path())));
    Ok(())
}

fn or_dash(value: Option<impl ToString>) -> String {
    value
        .map(|v| v.to_string())
        .unwrap_or_else(|| "-".to_string())
}

/// The report, as printed.
pub fn render(d: &ModelDescription, platforms: &[String]) -> String {
    let mut out = String::new();
    let w = &mut out;
    let _ = writeln!(w, "\nModel Info\n");
    let rows = [
        ("FMI Version", d.fmi_version.clone()),
        (
            "FMI Type",
            match &d.model_exchange {
                None => "Co-Simulation".to_string(),
                Some(_) => "Co-Simulation (fricsim's), Model Exchange".to_string(),
            },
        ),
        ("Model Name", d.model_name.clone()),
        ("Model Identifier", d.co_simulation.model_identifier.clone()),
        ("GUID", d.guid.clone()),
        ("Description", or_dash(d.description.as_deref())),
        ("Generation Tool", or_dash(d.generation_tool.as_deref())),
        (
            "Generation Date",
            or_dash(d.generation_date_and_time.as_deref()),
        ),
        (
            "Platforms",
            if platforms.is_empty() {
                "-".to_string()
            } else {
                platforms.join(", ")
            },
        ),
        ("Variables", d.variables.len().to_string()),
    ];
    for (key, value) in rows {
        let _ = writeln!(w, "  {key:<18} {value}");
    }

    let cs = &d.co_simulation;
    let _ = writeln!(w, "\nCapabilities\n");
    // each version's spelling; FMI 3.0 Co-Simulation has no input
    // derivatives (canInterpolateInputs)
    let fmi3 = d.is_fmi3();
    let mut capabilities = vec![(
        "canHandleVariableCommunicationStepSize",
        cs.can_handle_variable_communication_step_size.to_string(),
    )];
    if !fmi3 {
        capabilities.push((
            "canInterpolateInputs",
            cs.can_interpolate_inputs.to_string(),
        ));
    }
    capabilities.extend([
        (
            "maxOutputDerivativeOrder",
            cs.max_output_derivative_order.to_string(),
        ),
        (
            if fmi3 {
                "canGetAndSetFMUState"
            } else {
                "canGetAndSetFMUstate"
            },
            cs.can_get_and_set_fmu_state.to_string(),
        ),
        (
            if fmi3 {
                "canSerializeFMUState"
            } else {
                "canSerializeFMUstate"
            },
            cs.can_serialize_fmu_state.to_string(),
        ),
        (
            if fmi3 {
                "providesDirectionalDerivatives"
            } else {
                "providesDirectionalDerivative"
            },
            cs.provides_directional_derivative.to_string(),
        ),
    ]);
    for (key, value) in capabilities {
        let _ = writeln!(w, "  {key:<40} {value}");
    }

    let _ = writeln!(w, "\nDefault Experiment\n");
    match &d.default_experiment {
        None => {
            let _ = writeln!(w, "  -");
        }
        Some(e) => {
            for (key, value) in [
                ("Start Time", e.start_time),
                ("Stop Time", e.stop_time),
                ("Tolerance", e.tolerance),
                ("Step Size", e.step_size),
            ] {
                let _ = writeln!(
                    w,
                    "  {key:<18} {}",
                    or_dash(value.map(|v| format!("{v:?}")))
                );
            }
        }
    }

    let _ = writeln!(w, "\nVariables\n");
    let mut table = vec![[
        "Name".to_string(),
        "Causality".to_string(),
        "Variability".to_string(),
        "Type".to_string(),
        "Start".to_string(),
        "Unit".to_string(),
        "Description".to_string(),
    ]];
    for v in &d.variables {
        table.push([
            v.name.clone(),
            v.causality.to_string(),
            v.variability.to_string(),
            v.type_name().to_string(),
            v.kind.start_text().unwrap_or_default(),
            v.kind.unit().unwrap_or_default().to_string(),
            v.description.clone().unwrap_or_default(),
        ]);
    }
    let mut widths = [0usize; 6];
    for row in &table {
        for (width, cell) in widths.iter_mut().zip(row) {
            *width = (*width).max(cell.chars().count());
        }
    }
    for row in &table {
        let mut line = String::from(" ");
        for (width, cell) in widths.iter().zip(row) {
            let _ = write!(line, " {cell:<width$}");
        }
        let _ = write!(line, " {}", row[6]);
        let _ = writeln!(w, "{}", line.trim_end());
    }
    arrays(w, d);
    out
}

/// FMI 3.0's arrays, which the variables list element by element: name,
/// type, dimensions and the first and last element.
fn arrays(w: &mut String, d: &ModelDescription) {
    if d.arrays.is_empty() {
        return;
    }
    let _ = writeln!(
        w,
        "
Arrays (above as their elements)
"
    );
    let mut table = vec![[
        "Name".to_string(),
        "Type".to_string(),
        "Dimensions".to_string(),
        "Elements".to_string(),
    ]];
    for a in &d.arrays {
        let elements = &d.variables[a.first_index - 1..][..a.len()];
        table.push([
            a.name.clone(),
            a.value_type.to_string(),
            a.dimensions
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(" × "),
            match (elements.first(), elements.last()) {
                (Some(first), Some(last)) => format!("{} … {}", first.name, last.name),
                _ => "none".to_string(),
            },
        ]);
    }
    let mut widths = [0usize; 3];
    for row in &table {
        for (width, cell) in widths.iter_mut().zip(row) {
            *width = (*width).max(cell.chars().count());
        }
    }
    for row in &table {
        let mut line = String::from(" ");
        for (width, cell) in widths.iter().zip(row) {
            let _ = write!(line, " {cell:<width$}");
        }
        let _ = writeln!(w, "{} {}", line, row[3]);
    }
}
