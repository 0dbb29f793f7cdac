//! A co-simulated system: named FMU instances, parameter values and
//! connections from outputs to inputs, checked when built.

use crate::fmu::model_description::{Causality, VariableKind};
use crate::fmu::{Fmu, Instance, ValueReference};
use crate::rows::Rows;
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
    /// The connections, fixed when the system is built (what
    /// [`System::propagate`] does is planned from them then).
    pub connections: Vec<Connection>,
    /// The rows [`System::sample`] read, and how [`System::propagate`]
    /// finds a connected output in the last one.
    recording: Recording,
    /// The connections grouped by the component they lead to, in the order
    /// in which those components first appear in `connections`: one
    /// `fmi2SetReal` per component sets all its connected inputs.
    targets: Vec<Target>,
    /// Where each input of `targets` reads its value, one after the other
    /// in the same order (one per connection).
    sources: Vec<Source>,
}

/// What [`System::sample`] has read: one row of every component's
/// recorded outputs per call, and each component's [`Instance::changes`]
/// when the last row was read, so that [`System::propagate`] can take an
/// output from that row instead of asking the FMU again while the
/// component has seen no call that could have changed it.
struct Recording {
    rows: Rows,
    /// Rows kept at most ([`System::keep_last_rows`]); `None`: every row.
    window: Option<usize>,
    /// Per component, its [`Instance::changes`] when the last row was read;
    /// [`NOT_READ`] where the last row cannot be used (none read, or
    /// discarded).
    changes: Vec<u64>,
}

/// In [`Recording::changes`]: the last row is not to be used. A count
/// that [`Instance::changes`] does not reach (one more per FMI call).
const NOT_READ: u64 = u64::MAX;

impl Recording {
    /// Output `column` of `last` (the last row), if component `c` has seen
    /// no call since it was read that could have changed it.
    #[inline]
    fn value(&self, last: &[f64], component: &Component, c: usize, column: usize) -> Option<f64> {
        if self.changes[c] != component.instance.changes() {
            return None;
        }
        last.get(column).copied()
    }

    /// Forget the last row's reading: no value is taken from it any more.
    fn invalidate(&mut self) {
        self.changes.fill(NOT_READ);
    }
}

/// The connected inputs of one component, for [`System::propagate`].
struct Target {
    /// The component the inputs belong to.
    component: usize,
    /// Its connected inputs, in connection order; their sources are the
    /// next `inputs.len()` entries of [`System::sources`].
    inputs: Vec<ValueReference>,
}

/// The output a connected input reads.
struct Source {
    /// The source component and output.
    component: usize,
    output: ValueReference,
    /// The output's column in a recorded row, if it is recorded.
    column: Option<usize>,
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
            recording: Recording {
                rows: Rows::new(0),
                window: None,
                changes: Vec::new(),
            },
            targets: Vec::new(),
            sources: Vec::new(),
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
        system.plan();
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

    /// Copy every connected output to its input: first every value is
    /// read, then each component's connected inputs are set in one
    /// `fmi2SetReal`. An output recorded in the last row [`System::sample`]
    /// read, of a component that has seen no call since that could have
    /// changed it, is taken from that row instead of being asked for again.
    /// `buffer` is room for the values, one per connection.
    pub fn propagate(&mut self, buffer: &mut [f64]) -> Result<(), FmuError> {
        self.propagate_inline(buffer)
    }

    /// [`System::propagate`] inlined into the caller: the Jacobi master's
    /// step, where the call itself is a fair share of the host's work (the
    /// run's start calls the one above).
    #[inline(always)]
    pub(crate) fn propagate_inline(&mut self, buffer: &mut [f64]) -> Result<(), FmuError> {
        let recording = &self.recording;
        let last = recording.rows.last().unwrap_or_default();
        for (slot, source) in buffer.iter_mut().zip(&self.sources) {
            let from = &mut self.components[source.component];
            let known = source
                .column
                .and_then(|column| recording.value(last, from, source.component, column));
            *slot = match known {
                Some(x) => x,
                None => {
                    let mut x = [0.0];
                    from.instance.get_real(&[source.output], &mut x)?;
                    x[0]
                }
            };
        }
        let mut values = &buffer[..self.sources.len()];
        for target in &self.targets {
            let (now, rest) = values.split_at(target.inputs.len());
            self.components[target.component]
                .instance
                .set_real(&target.inputs, now)?;
            values = rest;
        }
        Ok(())
    }

    /// Work out, from the components' recorded outputs and the
    /// connections, what [`System::propagate`] sets and where it reads;
    /// start the recording over if a row is now of another width. Called
    /// when the system is built and whenever a recorded variable is added.
    fn plan(&mut self) {
        let mut offsets = Vec::with_capacity(self.components.len());
        let mut width = 0;
        for c in &self.components {
            offsets.push(width);
            width += c.output_vrs.len();
        }
        // connection order within each target, targets in order of first
        // appearance
        let mut order: Vec<usize> = Vec::new();
        for connection in &self.connections {
            if !order.contains(&connection.to.0) {
                order.push(connection.to.0);
            }
        }
        self.targets.clear();
        self.sources.clear();
        for to in order {
            let mut inputs = Vec::new();
            for connection in self.connections.iter().filter(|c| c.to.0 == to) {
                let (from, output) = connection.from;
                let column = self.components[from]
                    .output_vrs
                    .iter()
                    .position(|vr| *vr == output)
                    .map(|i| offsets[from] + i);
                inputs.push(connection.to.1);
                self.sources.push(Source {
                    component: from,
                    output,
                    column,
                });
            }
            self.targets.push(Target {
                component: to,
                inputs,
            });
        }
        let recording = &mut self.recording;
        recording.changes = vec![NOT_READ; self.components.len()];
        if recording.rows.width() != width {
            recording.rows = Rows::new(width);
        }
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
            self.plan();
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

    /// Start a new recording with room for `rows` rows (the rows read so
    /// far are dropped); with [`System::keep_last_rows`] set below `rows`,
    /// a [`Rows::windowed`] one.
    pub fn start_recording(&mut self, rows: usize) {
        let recording = &mut self.recording;
        let width = recording.rows.width();
        recording.rows = match recording.window {
            Some(window) if window < rows => Rows::windowed(width, window),
            _ => Rows::with_capacity(width, rows),
        };
        recording.invalidate();
    }

    /// Let the recordings started from now on keep only their last
    /// `window` rows (at least 2), the others summed into
    /// [`Rows::square_sums`] and counted in [`Rows::rows_pushed`]: for runs
    /// of which only a summary is kept (`fricsim sweep`). Such a run keeps
    /// the times of those rows only ([`crate::master::Run::time`]). `None`
    /// (the default): every row is kept.
    ///
    /// # Panics
    /// If `window` is below 2.
    pub fn keep_last_rows(&mut self, window: Option<usize>) {
        if let Some(w) = window {
            assert!(w >= 2, "a window of {w} rows: at least 2");
        }
        self.recording.window = window;
    }

    /// Read every recorded output into a new row of the recording, one
    /// `fmi2GetReal` per component, in [`System::columns`] order. If a
    /// call fails, no row is added.
    #[inline(always)] // into the run's loop: once per macro step, whatever the master
    pub fn sample(&mut self) -> Result<(), FmuError> {
        let recording = &mut self.recording;
        let row = recording.rows.push_zeros();
        let mut from = 0;
        for (c, changes) in self.components.iter_mut().zip(&mut recording.changes) {
            let to = from + c.output_vrs.len();
            if let Err(e) = c.instance.get_real(&c.output_vrs, &mut row[from..to]) {
                recording.rows.pop();
                recording.invalidate(); // nothing sampled to reuse
                return Err(e);
            }
            *changes = c.instance.changes();
            from = to;
        }
        Ok(())
    }

    /// The rows read so far: one per [`System::sample`] since the
    /// recording started.
    pub fn recorded(&self) -> &Rows {
        &self.recording.rows
    }

    /// Drop the last row read (one that is not to be kept, such as a row
    /// with a NaN); [`System::propagate`] then asks the FMUs again.
    pub fn discard_last_sample(&mut self) {
        self.recording.rows.pop();
        self.recording.invalidate();
    }

    /// The rows read so far; the recording starts over empty.
    pub fn take_recording(&mut self) -> Rows {
        let width = self.recording.rows.width();
        self.recording.invalidate();
        std::mem::replace(&mut self.recording.rows, Rows::new(width))
    }
}
