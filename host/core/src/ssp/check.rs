//! Checking a parsed system file against its FMUs
//! ([`SystemFile::check`]): each component's FMU opened, and every
//! connector, connection, parameter and annotated signal checked against
//! the model descriptions (name, causality, type, unit), each refusal
//! naming the element of the system file. Uses the definitions of
//! [`super`] and the importer ([`crate::fmu`]); the connection units are
//! judged by [`crate::system::connection_units`], as the built system
//! judges them.

use super::{
    error, list, names_with, CheckedConnection, CheckedSystem, ComponentDef, ConnectionDef,
    ConnectorDef, ConnectorKind, ParameterDef, SspError, SystemFile,
};
use crate::fmu::model_description::{Causality, ScalarVariable, Variability, VariableKind};
use crate::fmu::Fmu;
use crate::FmuError;
use std::path::PathBuf;

impl SystemFile {
    /// Open each component's FMU and check the system against the model
    /// descriptions: connectors, connections, parameters, settings.
    pub fn check(&self) -> Result<CheckedSystem, SspError> {
        let fmus = self.open_fmus()?;
        let names: Vec<String> = self.components.iter().map(|c| c.name.clone()).collect();
        let mut connections: Vec<CheckedConnection> = Vec::new();
        for conn in &self.connections {
            let checked = self.check_connection(conn, &fmus, &names, &connections)?;
            connections.push(checked);
        }
        for p in &self.parameters {
            let i = fmus
                .iter()
                .position(|(n, _)| *n == p.component)
                .ok_or_else(|| {
                    error(
                        &p.location,
                        format!(
                            "no component `{}` (components: {})",
                            p.component,
                            list(&names)
                        ),
                    )
                })?;
            check_parameter(p, &self.components[i], &fmus[i].1)?;
        }
        if let Some(location) = &self.settings.location {
            for s in self.settings.plot.iter().chain(&self.settings.record) {
                check_signal(s, &fmus, &names).map_err(|m| error(location, m))?;
            }
        }
        Ok(CheckedSystem { fmus, connections })
    }

    /// Each component's FMU, opened, its connectors checked.
    fn open_fmus(&self) -> Result<Vec<(String, Fmu)>, SspError> {
        // unpacked and loaded at the same time, each on a thread of its
        // own (inflating a binary is most of an FMU's opening); the
        // errors are then taken in the components' order, as one by one
        let opened = open_all(self.components.iter().map(|c| &c.source));
        let mut fmus: Vec<(String, Fmu)> = Vec::new();
        for (c, opened) in self.components.iter().zip(opened) {
            if !c.source.is_file() {
                let shown = if self.in_archive {
                    format!("{}!/{}", self.path.display(), c.source_text)
                } else {
                    c.source.display().to_string()
                };
                return Err(error(
                    &c.location,
                    format!("component `{}`: FMU file {shown} does not exist", c.name),
                ));
            }
            let fmu = opened.map_err(|e| {
                error(
                    &c.location,
                    format!(
                        "component `{}`: cannot import {}: {e}",
                        c.name, c.source_text
                    ),
                )
            })?;
            for k in &c.connectors {
                check_connector(c, k, &fmu)?;
            }
            fmus.push((c.name.clone(), fmu));
        }
        Ok(fmus)
    }

    /// One connection against the FMUs, ordered from its output to its
    /// input: both ends are declared connectors, the kinds give a
    /// direction, both are Real with agreeing units, and the input has no
    /// other source among `before`.
    fn check_connection(
        &self,
        conn: &ConnectionDef,
        fmus: &[(String, Fmu)],
        names: &[String],
        before: &[CheckedConnection],
    ) -> Result<CheckedConnection, SspError> {
        if let Some(t) = conn.transformation {
            return Err(error(
                &conn.location,
                format!("<ssc:{t}> on a connection is not supported: connect equal quantities"),
            ));
        }
        let (si, sk) = self.connection_end(conn, &conn.start, fmus, names)?;
        let (ei, ek) = self.connection_end(conn, &conn.end, fmus, names)?;
        let port = |i: usize, k: &ConnectorDef| format!("{}.{}", self.components[i].name, k.name);
        let (from, to, (fi, fk), (ti, tk)) = match (sk.kind, ek.kind) {
            (ConnectorKind::Output, ConnectorKind::Input) => {
                (port(si, sk), port(ei, ek), (si, sk), (ei, ek))
            }
            // start and end do not imply a direction (SSP 1.0 §5.3.4)
            (ConnectorKind::Input, ConnectorKind::Output) => {
                (port(ei, ek), port(si, sk), (ei, ek), (si, sk))
            }
            (a, b) => {
                return Err(error(
                    &conn.location,
                    format!(
                    "connects {} `{}` to {} `{}`: a connection goes from an output to an input{}",
                    a.as_str(),
                    port(si, sk),
                    b.as_str(),
                    port(ei, ek),
                    if a == b && a == ConnectorKind::Output {
                        " (two outputs cannot drive each other)"
                    } else {
                        ""
                    }
                ),
                ))
            }
        };
        check_connected_quantities(conn, fmus, (&from, fi, fk), (&to, ti, tk))?;
        if let Some(first) = before.iter().find(|c| c.to == to) {
            return Err(error(
                &conn.location,
                format!(
                    "input `{to}` is already connected (from `{}` by {}): an input has one source",
                    first.from, first.location
                ),
            ));
        }
        Ok(CheckedConnection {
            from,
            to,
            location: conn.location.clone(),
        })
    }

    /// One end `(element, connector)` of `conn`: the index of its
    /// component and its declared connector.
    fn connection_end<'a>(
        &'a self,
        conn: &ConnectionDef,
        (element, connector): &(Option<String>, String),
        fmus: &[(String, Fmu)],
        names: &[String],
    ) -> Result<(usize, &'a ConnectorDef), SspError> {
        let Some(element) = element else {
            return Err(error(
                &conn.location,
                format!("connector `{connector}` of the system itself: connections to the system's own connectors are not supported (name a component in startElement/endElement)"),
            ));
        };
        let i = fmus.iter().position(|(n, _)| n == element).ok_or_else(|| {
            error(
                &conn.location,
                format!("no component `{element}` (components: {})", list(names)),
            )
        })?;
        let c = &self.components[i];
        let k = c.connector(connector).ok_or_else(|| {
            let declared: Vec<String> = c.connectors.iter().map(|k| k.name.clone()).collect();
            let hint = if fmus[i].1.variable(connector).is_ok() {
                format!("; {} has a variable `{connector}`: declare it in the component's <ssd:Connectors>", c.source_text)
            } else {
                format!(
                    "; {} has no variable `{connector}` either (inputs: {}; outputs: {})",
                    c.source_text,
                    names_with(&fmus[i].1, Causality::Input),
                    names_with(&fmus[i].1, Causality::Output)
                )
            };
            error(
                &conn.location,
                format!("component `{element}` has no connector `{connector}` (its connectors: {}){hint}", list(&declared)),
            )
        })?;
        Ok((i, k))
    }
}

/// The two ends of a connection, `(port, component index, connector)`
/// from the output to the input: both Real, their units agreeing.
fn check_connected_quantities(
    conn: &ConnectionDef,
    fmus: &[(String, Fmu)],
    (from, fi, fk): (&str, usize, &ConnectorDef),
    (to, ti, tk): (&str, usize, &ConnectorDef),
) -> Result<(), SspError> {
    let var = |i: usize, k: &ConnectorDef| {
        fmus[i]
            .1
            .variable(&k.name)
            .expect("checked with the connectors")
            .clone()
    };
    let (fv, tv) = (var(fi, fk), var(ti, tk));
    for (p, v) in [(from, &fv), (to, &tv)] {
        if !matches!(v.kind, VariableKind::Real { .. }) {
            return Err(error(
                &conn.location,
                format!(
                    "`{p}` is a {} variable: only Real variables can be connected",
                    v.kind.type_name()
                ),
            ));
        }
    }
    let unit_of = |k: &ConnectorDef, v: &ScalarVariable| {
        k.unit.clone().or_else(|| v.kind.unit().map(str::to_string))
    };
    let (fu, tu) = (unit_of(fk, &fv), unit_of(tk, &tv));
    // (a side without a unit connects with a warning, which the
    // built system carries: `System::warnings`)
    if let Err(e) = crate::system::connection_units(from, fu.as_deref(), to, tu.as_deref()) {
        return Err(error(&conn.location, e));
    }
    Ok(())
}

/// A `component.variable` of the annotation: the component exists and has
/// a variable of that name that can be recorded (not a String).
fn check_signal(signal: &str, fmus: &[(String, Fmu)], names: &[String]) -> Result<(), String> {
    let (c, v) = signal
        .split_once('.')
        .ok_or_else(|| format!("signal `{signal}` is not of the form component.variable"))?;
    let (_, fmu) = fmus.iter().find(|(n, _)| n == c).ok_or_else(|| {
        format!(
            "signal `{signal}`: no component `{c}` (components: {})",
            list(names)
        )
    })?;
    let var = fmu.variable(v).map_err(|_| {
        format!(
            "signal `{signal}`: `{c}` has no variable `{v}`{} (outputs: {}; inputs: {})",
            fmu.description().array_hint(v),
            names_with(fmu, Causality::Output),
            names_with(fmu, Causality::Input)
        )
    })?;
    if matches!(var.kind, VariableKind::String { .. }) {
        return Err(format!(
            "signal `{signal}` is a String variable; only Real, Integer, Enumeration and Boolean variables are recorded and plotted"
        ));
    }
    Ok(())
}

/// A connector against its FMU variable: it exists, the causality is the
/// kind, the type and the unit agree.
fn check_connector(c: &ComponentDef, k: &ConnectorDef, fmu: &Fmu) -> Result<(), SspError> {
    let var = fmu.variable(&k.name).map_err(|_| {
        error(
            &k.location,
            format!(
                "{} has no variable `{}`{} ({}s: {})",
                c.source_text,
                k.name,
                fmu.description().array_hint(&k.name),
                k.kind.as_str(),
                names_with(fmu, k.kind.causality())
            ),
        )
    })?;
    if var.causality != k.kind.causality() {
        return Err(error(
            &k.location,
            format!(
                "kind=\"{}\", but `{}` in {} has causality \"{}\"",
                k.kind.as_str(),
                k.name,
                c.source_text,
                var.causality
            ),
        ));
    }
    if let Some(t) = k.type_name {
        if t != var.ssp_type_name() {
            return Err(error(
                &k.location,
                format!(
                    "the connector is ssc:{t}, but `{}` in {} is {}",
                    k.name,
                    c.source_text,
                    var.type_name()
                ),
            ));
        }
    }
    if let Some(u) = &k.unit {
        match var.kind.unit() {
            Some(declared) if declared == u => {}
            declared => {
                return Err(error(
                    &k.location,
                    format!(
                        "unit mismatch: the connector has unit `{u}`, `{}` in {} declares {}",
                        k.name,
                        c.source_text,
                        declared.map_or("no unit".to_string(), |d| format!("unit `{d}`"))
                    ),
                ))
            }
        }
    }
    Ok(())
}

/// A parameter value against its FMU variable: it exists, may be set
/// before initialization (a parameter or an input, not constant), and the
/// type and unit agree.
fn check_parameter(p: &ParameterDef, c: &ComponentDef, fmu: &Fmu) -> Result<(), SspError> {
    let var = fmu.variable(&p.variable).map_err(|_| {
        error(
            &p.location,
            format!(
                "component `{}` ({}) has no variable `{}`{} (parameters: {}; inputs: {})",
                c.name,
                c.source_text,
                p.variable,
                fmu.description().array_hint(&p.variable),
                names_with(fmu, Causality::Parameter),
                names_with(fmu, Causality::Input)
            ),
        )
    })?;
    let settable = matches!(var.causality, Causality::Parameter | Causality::Input)
        && var.variability != Variability::Constant;
    if !settable {
        return Err(error(
            &p.location,
            format!(
                "`{}.{}` has causality \"{}\" and variability \"{}\": only parameters and inputs can be given values",
                c.name, p.variable, var.causality, var.variability
            ),
        ));
    }
    let expected = match &var.kind {
        VariableKind::Enumeration { .. } => "Integer",
        k => k.type_name(),
    };
    if p.value.type_name() != expected {
        return Err(error(
            &p.location,
            format!(
                "the value is ssv:{}, but `{}.{}` is {}: use <ssv:{expected}>",
                p.value.type_name(),
                c.name,
                p.variable,
                var.kind.type_name()
            ),
        ));
    }
    if let Some(u) = &p.unit {
        if var.kind.unit() != Some(u.as_str()) {
            return Err(error(
                &p.location,
                format!(
                    "unit mismatch: the value has unit `{u}`, `{}.{}` declares {} (fricsim does not convert units)",
                    c.name,
                    p.variable,
                    var.kind.unit().map_or("no unit".to_string(), |d| format!("unit `{d}`"))
                ),
            ));
        }
    }
    Ok(())
}

/// [`Fmu::open`] of each path that is a file, all at once, one thread
/// each; in the paths' order.
fn open_all<'a>(paths: impl Iterator<Item = &'a PathBuf>) -> Vec<Result<Fmu, FmuError>> {
    let open = |path: &PathBuf| {
        if path.is_file() {
            Fmu::open(path)
        } else {
            Err(FmuError::Io {
                path: path.clone(),
                source: std::io::ErrorKind::NotFound.into(),
            })
        }
    };
    let paths: Vec<&PathBuf> = paths.collect();
    if paths.len() < 2 {
        return paths.into_iter().map(open).collect();
    }
    std::thread::scope(|scope| {
        let opening: Vec<_> = paths
            .iter()
            .map(|path| scope.spawn(move || open(path)))
            .collect();
        opening
            .into_iter()
            .map(|thread| {
                thread
                    .join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            })
            .collect()
    })
}
