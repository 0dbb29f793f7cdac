//! A system file as the monolithic reference sees it ([`fricsim_reference`]):
//! used by `fricsim reference` and by the accuracy table
//! (`bench/src/bin/accuracy_table.rs`), so that both solve the same system.

use crate::ssp::{SystemFile, Value as SspValue};
use fricsim_reference::{ComponentSpec, SystemSpec, Value};

/// The system file as plain data for the reference: model name and GUID
/// of each component's FMU, the parameter values bound to it (component
/// bindings, then system bindings, so that these take precedence), and the
/// connections from output to input. The file is checked against its FMUs
/// first, as for `fricsim run`.
pub fn spec(file: &SystemFile) -> Result<SystemSpec, String> {
    let checked = file.check().map_err(|e| e.to_string())?;
    let components = checked
        .fmus
        .iter()
        .map(|(name, fmu)| {
            let d = fmu.description();
            let parameters = file
                .parameters
                .iter()
                .filter(|p| &p.component == name)
                .map(|p| {
                    let v = match &p.value {
                        SspValue::Real(x) => Value::Real(*x),
                        SspValue::Integer(i) => Value::Integer(i64::from(*i)),
                        SspValue::Boolean(b) => Value::Boolean(*b),
                        SspValue::String(s) => Value::String(s.clone()),
                    };
                    (p.variable.clone(), v)
                })
                .collect();
            ComponentSpec {
                name: name.clone(),
                model_name: d.model_name.clone(),
                guid: Some(d.guid.clone()),
                parameters,
            }
        })
        .collect();
    let connections = checked
        .connections
        .iter()
        .map(|c| (c.from.clone(), c.to.clone()))
        .collect();
    Ok(SystemSpec {
        components,
        connections,
    })
}
