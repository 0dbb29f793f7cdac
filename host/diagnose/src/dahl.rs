//! A Dahl nominal: diagnose's candidate effects are features of the LuGre
//! FMU, and Dahl has none of them (no Stribeck curve, no viscous term, no
//! direction or position dependence). A system whose friction component is
//! a Dahl FMU is therefore moved to LuGre before the diagnosis, with Dahl's
//! levels as the start: `Fc` kept, `Fs = Fc`, `σ0 = σ` (Dahl's rest
//! stiffness), `σ1 = σ2 = 0`. With Dahl's shape exponent α = 1 this LuGre
//! is Dahl's law exactly (both are `ż = v − σ·|v|·z/Fc`, `F = σ·z`; Dahl
//! 1968, Canudas de Wit et al. 1995); with another α the presliding curve's
//! shape differs, and the report says so. Dahl's offset force `F_offset`
//! (on its output, the Dahl state starting at 0) is LuGre's `F_offset`
//! (added to its force, z starting at 0): the same.

use crate::ssp::{ParameterDef, SystemFile, Value};
use std::path::{Path, PathBuf};

/// When the system's friction component is a Dahl FMU (and no LuGre is
/// there): rewrite `file` in place to use `LuGre.fmu` instead (`lugre`, or
/// the `LuGre.fmu` beside the Dahl FMU), and return what was done, for the
/// report. `None` when there is nothing to move.
pub fn move_to_lugre(
    file: &mut SystemFile,
    lugre: Option<&Path>,
) -> Result<Option<String>, String> {
    let mut system = file.build(0.0).map_err(|e| e.to_string())?;
    let model = |i: usize| system.components[i].fmu.description().model_name.clone();
    let n = system.components.len();
    if (0..n).any(|i| model(i) == "LuGre") {
        return Ok(None);
    }
    let dahl: Vec<usize> = (0..n).filter(|&i| model(i) == "Dahl").collect();
    let i = match dahl.as_slice() {
        [] => return Ok(None),
        [i] => *i,
        _ => {
            return Err(format!(
                "{}: {} Dahl components; diagnose moves exactly one to LuGre",
                file.ssd,
                dahl.len()
            ))
        }
    };
    let name = system.components[i].name.clone();
    let fmu = system.components[i].fmu.clone();
    let mut value =
        |v: &str| super::problem::read_value(&mut system.components[i].instance, &fmu, v);
    let (sigma, fc, alpha) = (value("sigma")?, value("Fc")?, value("alpha")?);
    // (a Dahl FMU built before the offset existed has none)
    let offset = match fmu.variable("F_offset") {
        Ok(_) => value("F_offset")?,
        Err(_) => 0.0,
    };
    let def = file
        .components
        .iter_mut()
        .find(|c| c.name == name)
        .ok_or_else(|| format!("{}: no component `{name}` in the file", file.ssd))?;
    let path: PathBuf = match lugre {
        Some(p) => p.to_path_buf(),
        None => def.source.with_file_name("LuGre.fmu"),
    };
    if !path.is_file() {
        return Err(format!(
            "{}: the friction component `{name}` is a Dahl FMU; diagnose moves it to LuGre (whose features are the candidate effects) and needs LuGre.fmu: {} does not exist (give --lugre PATH)",
            file.ssd,
            path.display()
        ));
    }
    def.source_text = path.display().to_string();
    def.source = path.clone();
    file.parameters.retain(|p| {
        !(p.component == name
            && ["sigma", "alpha", "Fc", "F_offset"].contains(&p.variable.as_str()))
    });
    for (variable, x) in [
        ("Fc", fc),
        ("Fs", fc),
        ("sigma0", sigma),
        ("sigma1", 0.0),
        ("sigma2", 0.0),
        ("F_offset", offset),
    ] {
        file.parameters.push(ParameterDef {
            component: name.clone(),
            variable: variable.into(),
            value: Value::Real(x),
            unit: None,
            location: "moved from Dahl by fricsim diagnose".into(),
        });
    }
    let shape = if alpha == 1.0 {
        "which is Dahl's law exactly (alpha = 1)".to_string()
    } else {
        format!(
            "whose presliding curve is Dahl's with alpha = 1, not the nominal's alpha = {alpha}"
        )
    };
    Ok(Some(format!(
        "the nominal friction `{name}` is a Dahl FMU (sigma = {sigma} N/m, Fc = {fc} N, F_offset = {offset} N); the effects it cannot express are added by moving it to LuGre ({}) with Dahl's levels as the start: Fc = {fc} N, Fs = Fc, sigma0 = sigma, sigma1 = sigma2 = 0, F_offset = {offset} N, {shape}",
        path.display()
    )))
}
