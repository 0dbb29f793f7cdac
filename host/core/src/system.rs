//! A co-simulated system: named FMU instances, parameter values and
//! connections from outputs to inputs, checked when built.
//!
//! Uses the importer ([`crate::fmu`]), [`crate::rows`] and
//! [`crate::time_grid`]; it knows nothing of the masters, which step it
//! through the methods of [`coupling`] (and `System::step_jacobi`,
//! [`System::propagate`] and the recording here), never through its
//! fields (the master module uses this one, never the reverse).

pub mod component;
pub mod coupling;

pub use component::ComponentInstance;

use crate::fmu::model_description::{Causality, VariableKind};
use crate::fmu::{Fmu, Rollback, ValueReference};
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
    /// Its instance, of its FMU's FMI version: the one type the system
    /// and the masters call ([`component`]).
    pub instance: ComponentInstance,
    /// The recorded variables (name, value reference), one column each in
    /// this order: the Real ones (the outputs, then those recorded by
    /// [`System::record`]), then the Integer and Enumeration ones, then
    /// the Boolean ones.
    pub outputs: Vec<(String, ValueReference)>,
    /// The value references of the Real ones of `outputs`, in order:
    /// [`System::sample`] reads them in one `fmi2GetReal` call.
    output_vrs: Vec<ValueReference>,
    /// The Integer (and Enumeration) ones, read with `fmi2GetInteger`.
    integer_vrs: Vec<ValueReference>,
    /// The Boolean ones, read with `fmi2GetBoolean`.
    boolean_vrs: Vec<ValueReference>,
    /// The component's connected inputs, in connection order:
    /// [`System::propagate`] sets them in one `fmi2SetReal`, from the
    /// next `inputs.len()` values it has read (see [`System::plan`]).
    inputs: Vec<ValueReference>,
    /// Where the values of `inputs` start in a recorded row, if they are
    /// there one after the other in the same order (see
    /// [`System::step_jacobi`]); 0 without inputs.
    first_column: usize,
    /// Its [`ComponentInstance::changes`] when [`System::sample`] read
    /// the last row, [`NOT_READ`] where that row cannot be used (none
    /// read, or discarded): while the count stands there, the row holds what
    /// `fmi2GetReal` would answer for the outputs it recorded.
    sampled: u64,
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
    /// The rows [`System::sample`] read.
    recording: Recording,
    /// Where each connected input reads its value, one per connection:
    /// the inputs of the first component that has any (in connection
    /// order), then those of the next, as the components'
    /// [`Component::inputs`] follow one another.
    sources: Vec<Source>,
    /// Room for the values of `sources`, for the Jacobi master's step
    /// ([`System::step_jacobi`]).
    values: Vec<f64>,
    /// Whether every connected input reads a recorded output and each
    /// component's inputs are read from one run of a row's columns (from
    /// [`Component::first_column`] on): then, while the last row read can
    /// be used for every component, [`System::step_jacobi`] sets the
    /// inputs straight from that row.
    direct: bool,
    /// What the build noticed and accepted (a connection between a
    /// variable with a unit and one without, say), for the command to
    /// show: [`System::warnings`].
    warnings: Vec<String>,
}

/// The units of a connection `from -> to`, as the FMUs declare them.
/// FMI 2.0 and SSP 1.0 leave units optional: a side without one connects
/// to any unit, with a warning (`Ok(Some(warning))`); two different
/// declared units are refused, since fricsim does not convert them.
pub fn connection_units(
    from: &str,
    from_unit: Option<&str>,
    to: &str,
    to_unit: Option<&str>,
) -> Result<Option<String>, String> {
    match (from_unit, to_unit) {
        (Some(a), Some(b)) if a != b => Err(format!(
            "unit mismatch: `{from}` has unit `{a}`, `{to}` has unit `{b}` (fricsim does not convert units; connect quantities of the same unit)"
        )),
        (None, Some(u)) | (Some(u), None) => {
            let unitless = if from_unit.is_none() { from } else { to };
            Ok(Some(format!(
                "connection {from} -> {to}: `{unitless}` declares no unit, the other side `{u}`: connected as is (units are optional in FMI and SSP; make sure the value is in {u})"
            )))
        }
        _ => Ok(None),
    }
}

/// What [`System::sample`] has read: one row of every component's
/// recorded outputs per call (with each component's
/// [`ComponentInstance::changes`] then in [`Component::sampled`], so that [`System::propagate`] can take
/// an output from the last row instead of asking the FMU again while the
/// component has seen no call that could have changed it).
struct Recording {
    rows: Rows,
    /// Rows kept at most ([`System::keep_last_rows`]); `None`: every row.
    window: Option<usize>,
}

/// In [`Component::sampled`]: the last row is not to be used. A count
/// that [`ComponentInstance::changes`] does not reach (one more per FMI call).
const NOT_READ: u64 = u64::MAX;

/// In [`Source::column`]: the output is not recorded (no row has it).
const NOT_RECORDED: usize = usize::MAX;

/// Forget the last row's reading: no value is taken from it any more.
fn forget_sampled(components: &mut [Component]) {
    for c in components {
        c.sampled = NOT_READ;
    }
}

/// Read every component's recorded outputs into `row`, one `fmi2GetReal`
/// per component, one after the other (`row` holds as many values as
/// they have; Integer and Boolean ones after the Real ones, see
/// [`read_discrete`]), and note each component's
/// [`ComponentInstance::changes`] then.
#[inline(always)] // into the run's loop
fn read_outputs(components: &mut [Component], row: &mut [f64]) -> Result<(), FmuError> {
    let mut rest = row;
    for c in components {
        let (values, after) = rest.split_at_mut(c.outputs.len());
        let (reals, discrete) = values.split_at_mut(c.output_vrs.len());
        c.instance.get_real(&c.output_vrs, reals)?;
        if !discrete.is_empty() {
            read_discrete(c, discrete)?;
        }
        c.sampled = c.instance.changes();
        rest = after;
    }
    Ok(())
}

/// Values read at a time by [`read_discrete`] (on the stack).
const DISCRETE_CHUNK: usize = 32;

/// Read a component's recorded Integer and Boolean variables into
/// `values` (as many as it has), as numbers: each Integer exactly (an
/// `i32` is an `f64` exactly), a Boolean as 0 or 1.
#[inline(never)]
fn read_discrete(c: &mut Component, values: &mut [f64]) -> Result<(), FmuError> {
    if let ([], [vr], [x]) = (&c.integer_vrs[..], &c.boolean_vrs[..], &mut *values) {
        // one Boolean (a friction law's `sliding`): no buffer to clear
        let mut b = [0];
        c.instance
            .get_boolean_raw(std::slice::from_ref(vr), &mut b)?;
        *x = f64::from(u8::from(b[0] != 0));
        return Ok(());
    }
    let (integers, booleans) = values.split_at_mut(c.integer_vrs.len());
    for (vrs, values) in c
        .integer_vrs
        .chunks(DISCRETE_CHUNK)
        .zip(integers.chunks_mut(DISCRETE_CHUNK))
    {
        let mut buffer = [0i32; DISCRETE_CHUNK];
        c.instance.get_integer(vrs, &mut buffer[..vrs.len()])?;
        for (x, i) in values.iter_mut().zip(buffer) {
            *x = f64::from(i);
        }
    }
    for (vrs, values) in c
        .boolean_vrs
        .chunks(DISCRETE_CHUNK)
        .zip(booleans.chunks_mut(DISCRETE_CHUNK))
    {
        let mut buffer = [0; DISCRETE_CHUNK];
        c.instance.get_boolean_raw(vrs, &mut buffer[..vrs.len()])?;
        for (x, b) in values.iter_mut().zip(buffer) {
            *x = f64::from(u8::from(b != 0));
        }
    }
    Ok(())
}

/// Which of the recorded types a variable of kind `kind` is, if it is
/// one: Real, Integer (Enumeration too) or Boolean; a String is not
/// recorded.
fn recorded_type(kind: &VariableKind) -> Option<RecordedType> {
    match kind {
        VariableKind::Real { .. } => Some(RecordedType::Real),
        VariableKind::Integer { .. } | VariableKind::Enumeration { .. } => {
            Some(RecordedType::Integer)
        }
        VariableKind::Boolean { .. } => Some(RecordedType::Boolean),
        VariableKind::String { .. } => None,
    }
}

/// The type of a recorded column: a Real, or a whole number (an Integer,
/// an Enumeration, or a Boolean as 0 or 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum RecordedType {
    Real,
    Integer,
    Boolean,
}

impl Component {
    /// Record `(name, vr)` of type `ty`: in its place among the columns
    /// (Real, then Integer, then Boolean, see [`Component::outputs`]).
    fn add_recorded(&mut self, name: &str, vr: ValueReference, ty: RecordedType) {
        let (at, vrs) = match ty {
            RecordedType::Real => (self.output_vrs.len(), &mut self.output_vrs),
            RecordedType::Integer => (
                self.output_vrs.len() + self.integer_vrs.len(),
                &mut self.integer_vrs,
            ),
            RecordedType::Boolean => (self.outputs.len(), &mut self.boolean_vrs),
        };
        vrs.push(vr);
        self.outputs.insert(at, (name.to_string(), vr));
    }

    /// The type of each recorded column, in column order.
    fn column_types(&self) -> impl Iterator<Item = RecordedType> {
        std::iter::repeat_n(RecordedType::Real, self.output_vrs.len())
            .chain(std::iter::repeat_n(
                RecordedType::Integer,
                self.integer_vrs.len(),
            ))
            .chain(std::iter::repeat_n(
                RecordedType::Boolean,
                self.boolean_vrs.len(),
            ))
    }
}

/// Read every connected output, one per `sources`, into `values` (as
/// many). An output recorded in `last` (the last row read) of a component
/// that has seen no call since that row was read ([`Component::sampled`])
/// is taken from the row; any other is asked for with `fmi2GetReal`.
#[inline(always)] // into the Jacobi master's step
fn gather(
    components: &mut [Component],
    last: &[f64],
    sources: &[Source],
    values: &mut [f64],
) -> Result<(), FmuError> {
    for (slot, source) in values.iter_mut().zip(sources) {
        let from = &mut components[source.component];
        *slot = match last.get(source.column) {
            Some(&x) if from.sampled == from.instance.changes() => x,
            _ => {
                let mut x = [0.0];
                from.instance.get_real(&[source.output], &mut x)?;
                x[0]
            }
        };
    }
    Ok(())
}

/// Set the values [`gather`] read: each component's connected inputs in
/// one `fmi2SetReal` from the next `inputs.len()` of `values`, component
/// after component; with `step = Some((t, h))`, each component stepped
/// from `t` over `h` right after its inputs are set (the Jacobi master).
#[inline(always)] // `step` is a constant at each call
fn set_gathered(
    components: &mut [Component],
    mut values: &[f64],
    step: Option<(f64, f64)>,
) -> Result<(), FmuError> {
    for c in components {
        let (now, rest) = values.split_at(c.inputs.len());
        if !now.is_empty() {
            c.instance.set_real(&c.inputs, now)?;
        }
        values = rest;
        if let Some((t, h)) = step {
            c.instance.do_step(t, h, Rollback::Never)?;
        }
    }
    Ok(())
}

/// The output a connected input reads.
struct Source {
    /// The source component and output.
    component: usize,
    output: ValueReference,
    /// The output's column in a recorded row; [`NOT_RECORDED`] if it is
    /// not recorded.
    column: usize,
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
/// variable's type (Real as is; Integer only if it is a whole number that
/// an `i32` holds, else refused; Boolean non-zero = true); text sets a
/// String variable. (An FMI 3.0 variable's own type may hold less, a
/// UInt8 300 say: its instance refuses it, naming it.)
#[derive(Clone, Debug, PartialEq)]
pub enum ParameterValue {
    Number(f64),
    Text(String),
}

/// The experiment each instance is told of by `fmi2SetupExperiment`: it
/// starts at `start` and, if `stop` is given, ends there (FMI 2.0.4
/// §2.1.6: the FMU may rely on it and must not compute past it). A start
/// time alone converts into one without a stop time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Experiment {
    pub start: f64,
    pub stop: Option<f64>,
}

impl From<f64> for Experiment {
    fn from(start: f64) -> Experiment {
        Experiment { start, stop: None }
    }
}

impl Experiment {
    /// A run from `start` in macro steps of `step` towards `stop`, as the
    /// masters step it ([`crate::time_grid::step_count`]): its stop time is
    /// the last communication point, `start + n·step`, which the last
    /// step reaches exactly (FMPy tells the FMUs its stop time too; a
    /// `stop` that is not a whole number of steps from `start` would
    /// otherwise be short of the last point or past it).
    pub fn stepped(start: f64, step: f64, stop: f64) -> Experiment {
        let n = crate::time_grid::step_count(start, step, stop);
        Experiment {
            start,
            stop: Some(crate::time_grid::communication_time(start, step, n)),
        }
    }
}

impl System {
    /// Open and instantiate each `(name, fmu path)`, set the parameters
    /// (`component.variable`, value), connect `(output port, input port)`;
    /// the experiment starts at t = 0, with no stop time.
    pub fn build(
        components: &[(String, &Path)],
        parameters: &[(String, f64)],
        connections: &[(String, String)],
    ) -> Result<System, SystemError> {
        System::build_for(components, parameters, connections, 0.0)
    }

    /// [`System::build`] for `experiment`: its start, and its stop time if
    /// it has one.
    pub fn build_for(
        components: &[(String, &Path)],
        parameters: &[(String, f64)],
        connections: &[(String, String)],
        experiment: impl Into<Experiment>,
    ) -> Result<System, SystemError> {
        let mut fmus = Vec::with_capacity(components.len());
        for (name, path) in components {
            fmus.push((name.clone(), Fmu::open(path)?));
        }
        let parameters: Vec<(String, ParameterValue)> = parameters
            .iter()
            .map(|(k, v)| (k.clone(), ParameterValue::Number(*v)))
            .collect();
        System::from_fmus(fmus, &parameters, connections, experiment)
    }

    /// Instantiate already opened FMUs `(name, fmu)`, connect
    /// `(output port, input port)`, set up the experiment (its start, and
    /// its stop if given: a start time alone has none), enter
    /// initialization mode and set the parameters (`component.variable`,
    /// value) there, in order (a later value for the same variable wins).
    pub fn from_fmus(
        fmus: Vec<(String, Fmu)>,
        parameters: &[(String, ParameterValue)],
        connections: &[(String, String)],
        experiment: impl Into<Experiment>,
    ) -> Result<System, SystemError> {
        let experiment = experiment.into();
        let mut list: Vec<Component> = Vec::new();
        for (name, fmu) in fmus {
            if list.iter().any(|c| c.name == name) {
                return Err(SystemError::Invalid(format!(
                    "component name `{name}` is used twice"
                )));
            }
            let instance = if fmu.description().is_fmi3() {
                ComponentInstance::Fmi3(fmu.instantiate_fmi3(&name)?)
            } else {
                ComponentInstance::Fmi2(fmu.instantiate(&name)?)
            };
            let outputs: Vec<(String, ValueReference, RecordedType)> = fmu
                .description()
                .variables
                .iter()
                .filter(|v| v.causality == Causality::Output)
                .filter_map(|v| Some((v.name.clone(), v.value_reference, recorded_type(&v.kind)?)))
                .filter(|(_, _, ty)| *ty == RecordedType::Real)
                .collect();
            let mut component = Component {
                name,
                fmu,
                instance,
                output_vrs: Vec::new(),
                integer_vrs: Vec::new(),
                boolean_vrs: Vec::new(),
                outputs: Vec::new(),
                inputs: Vec::new(),
                first_column: 0,
                sampled: NOT_READ,
            };
            for (name, vr, ty) in outputs {
                component.add_recorded(&name, vr, ty);
            }
            list.push(component);
        }
        let mut system = System {
            components: list,
            connections: Vec::new(),
            recording: Recording {
                rows: Rows::new(0),
                window: None,
            },
            sources: Vec::new(),
            values: Vec::new(),
            direct: false,
            warnings: Vec::new(),
        };
        for (from, to) in connections {
            let (fi, fv) = find(&system.components, from)?;
            let (ti, tv) = find(&system.components, to)?;
            let out = system.components[fi].fmu.variable(&fv).map_err(|_| {
                SystemError::Invalid(format!(
                    "connection {from} -> {to}: `{}` has no variable `{fv}`{}",
                    system.components[fi].name,
                    system.components[fi].fmu.description().array_hint(&fv)
                ))
            })?;
            let inp = system.components[ti].fmu.variable(&tv).map_err(|_| {
                SystemError::Invalid(format!(
                    "connection {from} -> {to}: `{}` has no variable `{tv}`{}",
                    system.components[ti].name,
                    system.components[ti].fmu.description().array_hint(&tv)
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
            match connection_units(from, out.kind.unit(), to, inp.kind.unit()) {
                Ok(warning) => system.warnings.extend(warning),
                Err(e) => {
                    return Err(SystemError::Invalid(format!(
                        "connection {from} -> {to}: {e}"
                    )))
                }
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
            c.instance
                .initialize(false, experiment.start, experiment.stop)?;
        }
        system.set_parameters(parameters)?;
        Ok(system)
    }

    /// What the build noticed and accepted, one sentence each (a command
    /// prints them as warnings).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// End the simulation of every instance with `fmi2Terminate`, as an
    /// FMI 2.0 co-simulation master does after its last step (§4.2.4; FMPy
    /// and libcosim do the same): an FMU may finish its work there (close
    /// a file or a connection, check a final condition). An instance in
    /// the error state (a call returned `fmi2Error` or `fmi2Fatal`) is
    /// left out: FMI 2.0 allows it only `fmi2Reset` and
    /// `fmi2FreeInstance`. Each instance that refuses is named, with its
    /// status and messages, in the list returned; the others are still
    /// terminated. [`System::restart`] (`fmi2Reset`) makes the instances
    /// ready for another run.
    pub fn terminate(&mut self) -> Vec<String> {
        let mut refused = Vec::new();
        for c in &mut self.components {
            if c.instance.has_failed() {
                continue;
            }
            if let Err(e) = c.instance.terminate() {
                refused.push(format!(
                    "the run's rows are complete, but the FMU did not end cleanly: {e}"
                ));
            }
        }
        refused
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
            c.instance.initialize(true, start, None)?;
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
                SystemError::Invalid(format!(
                    "`{port}`: `{}` has no variable `{v}`{}",
                    c.name,
                    c.fmu.description().array_hint(&v)
                ))
            })?;
            let vr = var.value_reference;
            match (&var.kind, value) {
                (VariableKind::Real { .. }, &ParameterValue::Number(x)) => {
                    c.instance.set_real(&[vr], &[x])?
                }
                (
                    VariableKind::Integer { .. } | VariableKind::Enumeration { .. },
                    &ParameterValue::Number(x),
                ) => {
                    // not truncated: 2.5 is no Integer value
                    if x.fract() != 0.0 || !(f64::from(i32::MIN)..=f64::from(i32::MAX)).contains(&x)
                    {
                        return Err(SystemError::Invalid(format!(
                            "`{port}` is an Integer variable; it cannot be set to {x}, which is not a 32-bit integer"
                        )));
                    }
                    c.instance.set_integer(&[vr], &[x as i32])?
                }
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
    /// `fmi2SetReal`, component after component. An output recorded in
    /// the last row [`System::sample`] read, of a component that has seen
    /// no call since that could have changed it, is taken from that row
    /// instead of being asked for again. `buffer` is room for the values,
    /// one per connection.
    pub fn propagate(&mut self, buffer: &mut [f64]) -> Result<(), FmuError> {
        let last = self.recording.rows.last().unwrap_or_default();
        gather(&mut self.components, last, &self.sources, buffer)?;
        set_gathered(&mut self.components, &buffer[..self.sources.len()], None)
    }

    /// The Jacobi master's step from `t` over `h`: [`System::propagate`]
    /// (every value read before any is set), and each component's
    /// `fmi2DoStep` right after its inputs are set, in one pass over the
    /// components (the components step independently of one another on
    /// the values of the communication point, so it does not matter that
    /// one has stepped before the next one's inputs are set). Inlined into
    /// the run's loop.
    ///
    /// The usual case: every input reads a recorded output, each
    /// component's from consecutive columns, and no component has seen a
    /// call since the last row was read (nothing happened between the
    /// steps). Then that row holds every value to be set, at the same
    /// time: the inputs are set from it, with no copy. `sampled`: the
    /// caller knows the last row to have been read right before, with no
    /// call since ([`System::sample`] notes every component's count as it
    /// reads it), and the counts need not be compared.
    #[inline(always)]
    pub(crate) fn step_jacobi(&mut self, t: f64, h: f64, sampled: bool) -> Result<(), FmuError> {
        let last = self.recording.rows.last().unwrap_or_default();
        let unchanged = |c: &Component| c.sampled == c.instance.changes();
        debug_assert!(!sampled || self.components.iter().all(unchanged));
        if self.direct && (sampled || self.components.iter().all(unchanged)) {
            // every component sampled into the last row since the plan
            // (which forgets the samples before it): a row of the planned
            // width, holding every column the inputs read
            for c in &mut self.components {
                let start = c.first_column;
                let now = &last[start..start + c.inputs.len()];
                if !now.is_empty() {
                    c.instance.set_real(&c.inputs, now)?;
                }
                c.instance.do_step(t, h, Rollback::Never)?;
            }
            return Ok(());
        }
        gather(&mut self.components, last, &self.sources, &mut self.values)?;
        set_gathered(&mut self.components, &self.values, Some((t, h)))
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
            width += c.outputs.len();
        }
        // per component, its connected inputs in connection order; their
        // sources one after the other in the same order
        self.sources.clear();
        self.direct = true;
        for to in 0..self.components.len() {
            let first = self.sources.len();
            let mut inputs = Vec::new();
            for connection in self.connections.iter().filter(|c| c.to.0 == to) {
                let (from, output) = connection.from;
                let column = self.components[from]
                    .output_vrs
                    .iter()
                    .position(|vr| *vr == output)
                    .map_or(NOT_RECORDED, |i| offsets[from] + i);
                inputs.push(connection.to.1);
                self.sources.push(Source {
                    component: from,
                    output,
                    column,
                });
            }
            // the columns of its inputs' values, if they follow one another
            let start = self.sources.get(first).map_or(0, |s| s.column);
            let consecutive = self.sources[first..]
                .iter()
                .enumerate()
                .all(|(k, s)| s.column != NOT_RECORDED && s.column == start + k);
            self.direct &= consecutive;
            let c = &mut self.components[to];
            c.first_column = if consecutive { start } else { 0 };
            c.inputs = inputs;
        }
        self.values = vec![0.0; self.sources.len()];
        forget_sampled(&mut self.components);
        let recording = &mut self.recording;
        if recording.rows.width() != width {
            recording.rows = Rows::new(width);
        }
    }

    /// Record the variable `component.variable` too (an input, a
    /// parameter, a local): a Real after the component's Real columns, an
    /// Integer (or Enumeration) or a Boolean after its columns of that type
    /// ([`Component::outputs`]); recording one that is already recorded
    /// changes nothing.
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
                "cannot record `{port}`: `{c}` has no variable `{v}`{}",
                component.fmu.description().array_hint(v)
            ))
        })?;
        let Some(ty) = recorded_type(&var.kind) else {
            return Err(SystemError::Invalid(format!(
                "cannot record `{port}`: it is a {} variable; only Real, Integer, Enumeration and Boolean variables are recorded",
                var.kind.type_name()
            )));
        };
        if !component.outputs.iter().any(|(n, _)| n == v) {
            let vr = var.value_reference;
            component.add_recorded(v, vr, ty);
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
        let var = self.components[i].fmu.variable(v).map_err(|_| {
            SystemError::Invalid(format!(
                "`{port}`: `{c}` has no variable `{v}`{}",
                self.components[i].fmu.description().array_hint(v)
            ))
        })?;
        Ok((i, var))
    }

    /// Record every component's Integer, Enumeration and Boolean outputs
    /// too (a system records its Real outputs from the start), as FMPy
    /// records every output: `fricsim run` and [`crate::run`] do.
    pub fn record_discrete_outputs(&mut self) {
        for c in &mut self.components {
            let discrete: Vec<(String, ValueReference, RecordedType)> = c
                .fmu
                .description()
                .variables
                .iter()
                .filter(|v| v.causality == Causality::Output)
                .filter_map(|v| Some((v.name.clone(), v.value_reference, recorded_type(&v.kind)?)))
                .filter(|(name, _, ty)| {
                    *ty != RecordedType::Real && !c.outputs.iter().any(|(n, _)| n == name)
                })
                .collect();
            for (name, vr, ty) in discrete {
                c.add_recorded(&name, vr, ty);
            }
        }
        self.plan();
    }

    /// The type of each column of [`System::columns`], in order: the
    /// Integer and Boolean ones hold whole numbers (a Boolean 0 or 1).
    pub fn column_types(&self) -> Vec<RecordedType> {
        self.components
            .iter()
            .flat_map(Component::column_types)
            .collect()
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
        forget_sampled(&mut self.components);
    }

    /// [`System::start_recording`] of every row, whatever
    /// [`System::keep_last_rows`] says: for a run that hands its rows on
    /// as it goes (the masters' `simulate_streaming`).
    pub(crate) fn start_streamed_recording(&mut self, rows: usize) {
        let width = self.recording.rows.width();
        self.recording.rows = Rows::with_capacity(width, rows);
        forget_sampled(&mut self.components);
    }

    /// Hand over the rows read so far and record on into `next` (an
    /// empty table of the same width), starting from a copy of the last
    /// row, which the next step reads its inputs from: what
    /// [`Rows::keep_last`] does, but the other rows are given to
    /// the caller instead of dropped (to be written on another thread).
    pub(crate) fn swap_recording(&mut self, mut next: Rows) -> Rows {
        debug_assert!(next.is_empty() && next.width() == self.recording.rows.width());
        if let Some(last) = self.recording.rows.last() {
            next.push_row(last);
        }
        std::mem::replace(&mut self.recording.rows, next)
    }

    /// Let the recordings started from now on keep only their last
    /// `window` rows (at least 2), the others summed into
    /// [`Rows::square_sums`] and counted in [`Rows::rows_pushed`]: for runs
    /// of which only a summary is kept (`fricsim sweep`). Such a run keeps
    /// the times of those rows only (a run's `time`). `None`
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
    pub fn sample(&mut self) -> Result<(), FmuError> {
        self.sample_with(|_| ())
    }

    /// [`System::sample`], inlined into the run's loop (once per macro
    /// step, whatever the master): what `look` finds in the new row.
    #[inline(always)]
    pub(crate) fn sample_with<R>(&mut self, look: impl FnOnce(&[f64]) -> R) -> Result<R, FmuError> {
        let row = self.recording.rows.push_zeros();
        if let Err(e) = read_outputs(&mut self.components, row) {
            self.recording.rows.pop();
            forget_sampled(&mut self.components); // nothing sampled to reuse
            return Err(e);
        }
        Ok(look(row))
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
        forget_sampled(&mut self.components);
    }

    /// The rows read so far; the recording starts over empty.
    pub fn take_recording(&mut self) -> Rows {
        let width = self.recording.rows.width();
        forget_sampled(&mut self.components);
        std::mem::replace(&mut self.recording.rows, Rows::new(width))
    }
}
