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
    /// The value references of `outputs`, in order: [`System::sample`]
    /// reads them in one `fmi2GetReal` call.
    output_vrs: Vec<ValueReference>,
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
    /// The last row [`System::sample`] read, for [`System::propagate`].
    sampled: Sampled,
}

/// The outputs [`System::sample`] read last: the row, where each
/// component's outputs start in it, and each component's
/// [`Instance::changes`] then (`u64::MAX`: nothing read).
#[derive(Default)]
struct Sampled {
    row: Vec<f64>,
    offsets: Vec<usize>,
    changes: Vec<u64>,
    /// Per connection, where its output was in the component's outputs
    /// last time (checked before use).
    positions: Vec<usize>,
}

impl Sampled {
    /// Output `vr` of component `c` as sampled, if `c` has seen no call
    /// since that could have changed it; `k` is the connection it is for.
    fn value(
        &mut self,
        components: &[Component],
        k: usize,
        c: usize,
        vr: ValueReference,
    ) -> Option<f64> {
        let component = components.get(c)?;
        if self.changes.get(c) != Some(&component.instance.changes()) {
            return None;
        }
        if self.positions.len() <= k {
            self.positions.resize(k + 1, 0);
        }
        let known = self.positions[k];
        let i = if component.output_vrs.get(known) == Some(&vr) {
            known
        } else {
            let i = component.output_vrs.iter().position(|v| *v == vr)?;
            self.positions[k] = i;
            i
        };
        self.row.get(self.offsets.get(c)? + i).copied()
    }
}

fn split_port(port: &str) -> Result<(&str, &str), SystemError> {
    port.split_once('.').ok_or_else(|| {
        SystemError::Invalid(format!("`{port}` is not of the form component.variable"))
    })
}

/// The component index and variable name of `component.variable`.
fn find(list: &[Component], port: &str) -> Result<(usize, String), SystemError> {
    let (c, v) = split_port(port)?;
    let i = list.iter().position(|x| x.name == c).ok_or_else(|| {
        let names: Vec<&str> = list.iter().map(|x| x.name.as_str()).collect();
        SystemError::Invalid(format!(
            "`{port}`: no component `{c}` (components: {})",
            names.join(", ")
        ))
    })?;
    Ok((i, v.to_string()))
}

/// A value for [`System::from_fmus`]: a number is converted to the
/// variable's type (Real as is, Integer rounded toward zero, Boolean
/// non-zero = true); text sets a String variable.
#[derive(Clone, Debug, PartialEq)]
pub enum ParameterValue {
    Number(f64),
    Text(String),
}

impl System {
    /// Open and instantiate each `(name, fmu path)`, set the parameters
    /// (`component.variable`, value), connect `(output port, input port)`;
    /// the experiment starts at t = 0.
    pub fn build(
        components: &[(String, &Path)],
        parameters: &[(String, f64)],
        connections: &[(String, String)],
    ) -> Result<System, SystemError> {
        let mut fmus = Vec::with_capacity(components.len());
        for (name, path) in components {
            fmus.push((name.clone(), Fmu::open(path)?));
        }
        let parameters: Vec<(String, ParameterValue)> = parameters
            .iter()
            .map(|(k, v)| (k.clone(), ParameterValue::Number(*v)))
            .collect();
        System::from_fmus(fmus, &parameters, connections, 0.0)
    }

    /// Instantiate already opened FMUs `(name, fmu)`, connect
    /// `(output port, input port)`, set up the experiment at `start`, enter
    /// initialization mode and set the parameters (`component.variable`,
    /// value) there, in order (a later value for the same variable wins).
    pub fn from_fmus(
        fmus: Vec<(String, Fmu)>,
        parameters: &[(String, ParameterValue)],
        connections: &[(String, String)],
        start: f64,
    ) -> Result<System, SystemError> {
        let mut list: Vec<Component> = Vec::new();
        for (name, fmu) in fmus {
            if list.iter().any(|c| c.name == name) {
                return Err(SystemError::Invalid(format!(
                    "component name `{name}` is used twice"
                )));
            }
            let instance = fmu.instantiate(&name)?;
            let outputs: Vec<(String, ValueReference)> = fmu
                .description()
                .variables
                .iter()
                .filter(|v| {
                    v.causality == Causality::Output && matches!(v.kind, VariableKind::Real { .. })
                })
                .map(|v| (v.name.clone(), v.value_reference))
                .collect();
            list.push(Component {
                name,
                fmu,
                instance,
                output_vrs: outputs.iter().map(|(_, vr)| *vr).collect(),
                outputs,
            });
        }
        let mut system = System {
            components: list,
            connections: Vec::new(),
            sampled: Sampled::default(),
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
            c.instance.setup_experiment(start, None)?;
            c.instance.enter_initialization_mode()?;
        }
        system.set_parameters(parameters)?;
        Ok(system)
    }

    /// Start over at `start` with the same instances: `fmi2Reset` each,
    /// set up the experiment, enter initialization mode and set the
    /// parameters as [`System::from_fmus`] does. Cheaper than building the
    /// system again (no unpacking, no loading); for repeated runs such as
    /// the fits of `fricsim diagnose`.
    pub fn restart(
        &mut self,
        start: f64,
        parameters: &[(String, ParameterValue)],
    ) -> Result<(), SystemError> {
        for c in &mut self.components {
            c.instance.reset()?;
            c.instance.setup_experiment(start, None)?;
            c.instance.enter_initialization_mode()?;
        }
        self.set_parameters(parameters)
    }

    /// Set `(component.variable, value)` in order, in initialization mode.
    fn set_parameters(
        &mut self,
        parameters: &[(String, ParameterValue)],
    ) -> Result<(), SystemError> {
        for (port, value) in parameters {
            let (i, v) = find(&self.components, port)?;
            let c = &mut self.components[i];
            let var = c.fmu.variable(&v).map_err(|_| {
                SystemError::Invalid(format!("`{port}`: `{}` has no variable `{v}`", c.name))
            })?;
            let vr = var.value_reference;
            match (&var.kind, value) {
                (VariableKind::Real { .. }, &ParameterValue::Number(x)) => {
                    c.instance.set_real(&[vr], &[x])?
                }
                (
                    VariableKind::Integer { .. } | VariableKind::Enumeration { .. },
                    &ParameterValue::Number(x),
                ) => c.instance.set_integer(&[vr], &[x as i32])?,
                (VariableKind::Boolean { .. }, &ParameterValue::Number(x)) => {
                    c.instance.set_boolean(&[vr], &[x != 0.0])?
                }
                (VariableKind::String { .. }, ParameterValue::Text(text)) => {
                    c.instance.set_string(&[vr], &[text.as_str()])?
                }
                (kind, _) => {
                    return Err(SystemError::Invalid(format!(
                        "`{port}` is a {} variable; it cannot be set to {value:?}",
                        kind.type_name()
                    )))
                }
            };
        }
        Ok(())
    }

    /// A time limit on each FMI call of every component (`None`: none);
    /// see [`crate::fmu::watchdog`] for what it can and cannot do.
    pub fn set_call_time_limit(&mut self, limit: Option<std::time::Duration>) {
        for c in &mut self.components {
            c.instance.set_call_time_limit(limit);
        }
    }

    /// Copy every connected output to its input. An output read by the
    /// last [`System::sample`], of a component that has seen no call since
    /// that could have changed it, is taken from that row instead of being
    /// asked for again.
    pub fn propagate(&mut self, buffer: &mut [f64]) -> Result<(), FmuError> {
        for (k, c) in self.connections.iter().enumerate() {
            let (from, vr) = c.from;
            buffer[k] = match self.sampled.value(&self.components, k, from, vr) {
                Some(x) => x,
                None => {
                    let mut x = [0.0];
                    self.components[from].instance.get_real(&[vr], &mut x)?;
                    x[0]
                }
            };
        }
        for (k, c) in self.connections.iter().enumerate() {
            self.components[c.to.0]
                .instance
                .set_real(&[c.to.1], &[buffer[k]])?;
        }
        Ok(())
    }

    /// Record the Real variable `component.variable` too (an input, a
    /// parameter, a local), after the component's outputs; recording one
    /// that is already recorded changes nothing.
    pub fn record(&mut self, port: &str) -> Result<(), SystemError> {
        let (c, v) = split_port(port)?;
        let names: Vec<&str> = self.components.iter().map(|x| x.name.as_str()).collect();
        let Some(i) = self.components.iter().position(|x| x.name == c) else {
            return Err(SystemError::Invalid(format!(
                "cannot record `{port}`: no component `{c}` (components: {})",
                names.join(", ")
            )));
        };
        let component = &mut self.components[i];
        let var = component.fmu.variable(v).map_err(|_| {
            SystemError::Invalid(format!(
                "cannot record `{port}`: `{c}` has no variable `{v}`"
            ))
        })?;
        if !matches!(var.kind, VariableKind::Real { .. }) {
            return Err(SystemError::Invalid(format!(
                "cannot record `{port}`: it is a {} variable; only Real variables are recorded",
                var.kind.type_name()
            )));
        }
        if !component.outputs.iter().any(|(n, _)| n == v) {
            component.outputs.push((v.to_string(), var.value_reference));
            component.output_vrs.push(var.value_reference);
        }
        Ok(())
    }

    /// The component index and the variable of `component.variable`.
    pub fn port(&self, port: &str) -> Result<(usize, &crate::fmu::ScalarVariable), SystemError> {
        let (c, v) = split_port(port)?;
        let i = self
            .components
            .iter()
            .position(|x| x.name == c)
            .ok_or_else(|| {
                let names: Vec<&str> = self.components.iter().map(|x| x.name.as_str()).collect();
                SystemError::Invalid(format!(
                    "`{port}`: no component `{c}` (components: {})",
                    names.join(", ")
                ))
            })?;
        let var = self.components[i]
            .fmu
            .variable(v)
            .map_err(|_| SystemError::Invalid(format!("`{port}`: `{c}` has no variable `{v}`")))?;
        Ok((i, var))
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

    /// Append every recorded output to `row`: one `fmi2GetReal` per
    /// component.
    pub fn sample(&mut self, row: &mut Vec<f64>) -> Result<(), FmuError> {
        let start = row.len();
        let sampled = &mut self.sampled;
        sampled.offsets.clear();
        sampled.changes.clear();
        for c in &mut self.components {
            let from = row.len();
            sampled.offsets.push(from - start);
            row.resize(from + c.output_vrs.len(), 0.0);
            if let Err(e) = c.instance.get_real(&c.output_vrs, &mut row[from..]) {
                sampled.changes.clear(); // nothing sampled to reuse
                return Err(e);
            }
            sampled.changes.push(c.instance.changes());
        }
        sampled.row.clear();
        sampled.row.extend_from_slice(&row[start..]);
        Ok(())
    }
}
