//! A co-simulated system: named FMU instances, parameter values and
//! connections from outputs to inputs, checked when built.

use crate::fmu::model_description::{Causality, VariableKind};
use crate::fmu::{Fmu, Instance, ValueReference};
use crate::FmuError;
use std::path::Path;

/// A configuration error, naming the component, the variable and the rule.
#[derive(Debug, thiserror::Error)]
pub enum SystemError {
    #[error("{0}")]
    Invalid(String),
    #[error(transparent)]
    Fmu(#[from] FmuError),
}

pub struct Component {
    pub name: String,
    pub fmu: Fmu,
    pub instance: Instance,
    /// Real outputs (name, value reference), recorded every step.
    pub outputs: Vec<(String, ValueReference)>,
}

impl Component {
    /// Whether output `vr` depends directly on an input (its model-structure
    /// dependencies name an input; an absent attribute counts as yes).
    pub fn has_feedthrough(&self, vr: ValueReference) -> bool {
        let d = self.fmu.description();
        let Some(var) = d
            .variables
            .iter()
            .find(|v| v.value_reference == vr && v.causality == Causality::Output)
        else {
            return true;
        };
        match d.outputs.iter().find(|u| u.index == var.index) {
            Some(u) => match &u.dependencies {
                None => true,
                Some(deps) => deps.iter().any(|i| {
                    d.variables
                        .get(i - 1)
                        .is_some_and(|v| v.causality == Causality::Input)
                }),
            },
            None => true,
        }
    }
}

/// `from.component.output → to.component.input`, by component index.
#[derive(Clone, Debug)]
pub struct Connection {
    pub from: (usize, ValueReference),
    pub to: (usize, ValueReference),
    pub label: String,
}

pub struct System {
    pub components: Vec<Component>,
    pub connections: Vec<Connection>,
}

fn split_port(port: &str) -> Result<(&str, &str), SystemError> {
    port.split_once('.').ok_or_else(|| {
        SystemError::Invalid(format!("`{port}` is not of the form component.variable"))
    })
}

impl System {
    /// Open and instantiate each `(name, fmu path)`, set the parameters
    /// (`component.variable`, value), connect `(output port, input port)`.
    pub fn build(
        components: &[(String, &Path)],
        parameters: &[(String, f64)],
        connections: &[(String, String)],
    ) -> Result<System, SystemError> {
        let mut list: Vec<Component> = Vec::new();
        for (name, path) in components {
            if list.iter().any(|c| &c.name == name) {
                return Err(SystemError::Invalid(format!(
                    "component name `{name}` is used twice"
                )));
            }
            let fmu = Fmu::open(path)?;
            let instance = fmu.instantiate(name)?;
            let outputs = fmu
                .description()
                .variables
                .iter()
                .filter(|v| {
                    v.causality == Causality::Output && matches!(v.kind, VariableKind::Real { .. })
                })
                .map(|v| (v.name.clone(), v.value_reference))
                .collect();
            list.push(Component {
                name: name.clone(),
                fmu,
                instance,
                outputs,
            });
        }
        let find = |list: &[Component], port: &str| -> Result<(usize, String), SystemError> {
            let (c, v) = split_port(port)?;
            let i = list.iter().position(|x| x.name == c).ok_or_else(|| {
                let names: Vec<&str> = list.iter().map(|x| x.name.as_str()).collect();
                SystemError::Invalid(format!(
                    "`{port}`: no component `{c}` (components: {})",
                    names.join(", ")
                ))
            })?;
            Ok((i, v.to_string()))
        };
        let mut system = System {
            components: list,
            connections: Vec::new(),
        };
        for (from, to) in connections {
            let (fi, fv) = find(&system.components, from)?;
            let (ti, tv) = find(&system.components, to)?;
            let out = system.components[fi].fmu.variable(&fv).map_err(|_| {
                SystemError::Invalid(format!(
                    "connection {from} -> {to}: `{}` has no variable `{fv}`",
                    system.components[fi].name
                ))
            })?;
            let inp = system.components[ti].fmu.variable(&tv).map_err(|_| {
                SystemError::Invalid(format!(
                    "connection {from} -> {to}: `{}` has no variable `{tv}`",
                    system.components[ti].name
                ))
            })?;
            if out.causality != Causality::Output {
                return Err(SystemError::Invalid(format!(
                    "connection {from} -> {to}: `{from}` is not an output"
                )));
            }
            if inp.causality != Causality::Input {
                return Err(SystemError::Invalid(format!(
                    "connection {from} -> {to}: `{to}` is not an input"
                )));
            }
            if !matches!(out.kind, VariableKind::Real { .. })
                || !matches!(inp.kind, VariableKind::Real { .. })
            {
                return Err(SystemError::Invalid(format!(
                    "connection {from} -> {to}: only Real variables can be connected"
                )));
            }
            if system
                .connections
                .iter()
                .any(|c| c.to == (ti, inp.value_reference))
            {
                return Err(SystemError::Invalid(format!(
                    "connection {from} -> {to}: `{to}` is already connected"
                )));
            }
            system.connections.push(Connection {
                from: (fi, out.value_reference),
                to: (ti, inp.value_reference),
                label: format!("{from} -> {to}"),
            });
        }
        for c in &mut system.components {
            c.instance.setup_experiment(0.0, None)?;
            c.instance.enter_initialization_mode()?;
        }
        for (port, value) in parameters {
            let (i, v) = find(&system.components, port)?;
            let c = &mut system.components[i];
            let var = c.fmu.variable(&v).map_err(|_| {
                SystemError::Invalid(format!("`{port}`: `{}` has no variable `{v}`", c.name))
            })?;
            let vr = var.value_reference;
            match var.kind {
                VariableKind::Real { .. } => c.instance.set_real(&[vr], &[*value])?,
                VariableKind::Integer { .. } => c.instance.set_integer(&[vr], &[*value as i32])?,
                VariableKind::Boolean { .. } => c.instance.set_boolean(&[vr], &[*value != 0.0])?,
                _ => {
                    return Err(SystemError::Invalid(format!(
                        "`{port}` is not a Real, Integer or Boolean variable"
                    )))
                }
            };
        }
        Ok(system)
    }

    /// Copy every connected output to its input.
    pub fn propagate(&mut self, buffer: &mut [f64]) -> Result<(), FmuError> {
        for (k, c) in self.connections.iter().enumerate() {
            let mut x = [0.0];
            self.components[c.from.0]
                .instance
                .get_real(&[c.from.1], &mut x)?;
            buffer[k] = x[0];
        }
        for (k, c) in self.connections.iter().enumerate() {
            self.components[c.to.0]
                .instance
                .set_real(&[c.to.1], &[buffer[k]])?;
        }
        Ok(())
    }

    /// Column names `component.output`, in recording order.
    pub fn columns(&self) -> Vec<String> {
        self.components
            .iter()
            .flat_map(|c| {
                c.outputs
                    .iter()
                    .map(move |(n, _)| format!("{}.{n}", c.name))
            })
            .collect()
    }

    /// Append every recorded output to `row`.
    pub fn sample(&mut self, row: &mut Vec<f64>) -> Result<(), FmuError> {
        for c in &mut self.components {
            for (_, vr) in &c.outputs {
                let mut x = [0.0];
                c.instance.get_real(&[*vr], &mut x)?;
                row.push(x[0]);
            }
        }
        Ok(())
    }
}
