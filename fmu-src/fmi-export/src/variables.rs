//! The variable table: one source of truth for the C layer and the XML.

/// FMI 2.0 base type of a scalar variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    Input,
    Output,
    Local,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variability {
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Initial {
    Exact,
    Approx,
    Calculated,
}

/// One scalar variable. Its value reference is its index in the table
/// (checked by [`ModelInfo::check`]).
#[derive(Clone, Copy, Debug)]
pub struct Variable {
    pub vr: u32,
    pub name: &'static str,
    pub var_type: VarType,
    pub causality: Causality,
    pub variability: Variability,
    /// Start value (integers and booleans as exact `f64`); `None` for
    /// calculated outputs.
    pub start: Option<f64>,
    pub unit: Option<&'static str>,
    pub description: &'static str,
    pub min: Option<f64>,
    pub max: Option<f64>,
    /// Scale used for finite-difference perturbations and declared as `nominal`.
    pub nominal: Option<f64>,
    /// Outputs only: the inputs this output depends on directly (direct
    /// feedthrough), by value reference. (Also of a state derivative: the
    /// inputs it depends on.)
    pub depends_on: &'static [u32],
    /// Outputs and state derivatives of a model with continuous states
    /// ([`ModelInfo::model_exchange`]): the states they depend on, by the
    /// value reference of the state variable. Rendered with
    /// [`Variable::depends_on`] into the model structure's dependencies
    /// (FMI 2.0.4 §2.2.8: the knowns are inputs and continuous states).
    pub depends_on_states: &'static [u32],
}

impl Variable {
    const fn base(vr: u32, name: &'static str, var_type: VarType, causality: Causality) -> Self {
        Variable {
            vr,
            name,
            var_type,
            causality,
            variability: Variability::Continuous,
            start: None,
            unit: None,
            description: "",
            min: None,
            max: None,
            nominal: None,
            depends_on: &[],
            depends_on_states: &[],
        }
    }

    /// A fixed real parameter (set before initialisation, `initial="exact"`).
    pub const fn parameter(
        vr: u32,
        name: &'static str,
        start: f64,
        unit: &'static str,
        description: &'static str,
    ) -> Self {
        let mut v = Self::base(vr, name, VarType::Real, Causality::Parameter);
        v.variability = Variability::Fixed;
        v.start = Some(start);
        v.unit = if unit.is_empty() { None } else { Some(unit) };
        v.description = description;
        v
    }

    /// A fixed integer parameter.
    pub const fn integer_parameter(
        vr: u32,
        name: &'static str,
        start: i32,
        description: &'static str,
    ) -> Self {
        let mut v = Self::base(vr, name, VarType::Integer, Causality::Parameter);
        v.variability = Variability::Fixed;
        v.start = Some(start as f64);
        v.description = description;
        v
    }

    /// A fixed boolean parameter (a switch).
    pub const fn boolean_parameter(
        vr: u32,
        name: &'static str,
        start: bool,
        description: &'static str,
    ) -> Self {
        let mut v = Self::base(vr, name, VarType::Boolean, Causality::Parameter);
        v.variability = Variability::Fixed;
        v.start = Some(if start { 1.0 } else { 0.0 });
        v.description = description;
        v
    }

    /// A continuous real input with a start value.
    pub const fn input(
        vr: u32,
        name: &'static str,
        start: f64,
        unit: &'static str,
        nominal: f64,
        description: &'static str,
    ) -> Self {
        let mut v = Self::base(vr, name, VarType::Real, Causality::Input);
        v.start = Some(start);
        v.unit = if unit.is_empty() { None } else { Some(unit) };
        v.nominal = Some(nominal);
        v.description = description;
        v
    }

    /// A continuous real output, computed by the model.
    pub const fn output(
        vr: u32,
        name: &'static str,
        unit: &'static str,
        description: &'static str,
        depends_on: &'static [u32],
    ) -> Self {
        let mut v = Self::base(vr, name, VarType::Real, Causality::Output);
        v.unit = if unit.is_empty() { None } else { Some(unit) };
        v.description = description;
        v.depends_on = depends_on;
        v
    }

    /// A discrete integer output (a count).
    pub const fn integer_output(
        vr: u32,
        name: &'static str,
        description: &'static str,
        depends_on: &'static [u32],
    ) -> Self {
        let mut v = Self::base(vr, name, VarType::Integer, Causality::Output);
        v.variability = Variability::Discrete;
        v.description = description;
        v.depends_on = depends_on;
        v
    }

    /// A discrete boolean output (an indicator).
    pub const fn boolean_output(
        vr: u32,
        name: &'static str,
        description: &'static str,
        depends_on: &'static [u32],
    ) -> Self {
        let mut v = Self::base(vr, name, VarType::Boolean, Causality::Output);
        v.variability = Variability::Discrete;
        v.description = description;
        v.depends_on = depends_on;
        v
    }

    /// The time derivative of a continuous state, `der(<state>)`: a
    /// local continuous real the model computes
    /// ([`crate::Model::derivatives`]), depending on the inputs `inputs`
    /// and the states `states` (value references).
    pub const fn derivative(
        vr: u32,
        name: &'static str,
        unit: &'static str,
        description: &'static str,
        inputs: &'static [u32],
        states: &'static [u32],
    ) -> Self {
        let mut v = Self::base(vr, name, VarType::Real, Causality::Local);
        v.unit = if unit.is_empty() { None } else { Some(unit) };
        v.description = description;
        v.depends_on = inputs;
        v.depends_on_states = states;
        v
    }

    /// A continuous state that is not an output: a local continuous real
    /// whose value is the state, written by
    /// [`crate::Model::compute_outputs`] with the outputs (and, as every
    /// local, computed when read, never set: Model Exchange sets it with
    /// `fmi2SetContinuousStates`). For a model whose output is a function
    /// of the state other than the state itself.
    pub const fn state(
        vr: u32,
        name: &'static str,
        unit: &'static str,
        description: &'static str,
    ) -> Self {
        let mut v = Self::base(vr, name, VarType::Real, Causality::Local);
        v.unit = if unit.is_empty() { None } else { Some(unit) };
        v.description = description;
        v
    }

    /// The continuous states this output depends on (value references of
    /// state variables).
    pub const fn with_state_dependencies(mut self, states: &'static [u32]) -> Self {
        self.depends_on_states = states;
        self
    }

    pub const fn with_min(mut self, min: f64) -> Self {
        self.min = Some(min);
        self
    }

    pub const fn with_max(mut self, max: f64) -> Self {
        self.max = Some(max);
        self
    }

    /// The FMI 2.0 `initial` attribute implied by causality and variability.
    pub fn initial(&self) -> Option<Initial> {
        match self.causality {
            Causality::Parameter => Some(Initial::Exact),
            Causality::Output => Some(Initial::Calculated),
            Causality::Input => None,
            Causality::Local => Some(Initial::Calculated),
        }
    }

    /// May this variable be set in the instantiated / initialization mode?
    pub fn settable_before_init(&self) -> bool {
        matches!(self.causality, Causality::Parameter | Causality::Input)
    }

    /// May this variable be set after initialization (step mode)?
    pub fn settable_in_step_mode(&self) -> bool {
        self.causality == Causality::Input
            || (self.causality == Causality::Parameter && self.variability == Variability::Tunable)
    }
}

/// One continuous state of a model with a Model Exchange interface: the
/// value reference of the state variable and of its derivative.
#[derive(Clone, Copy, Debug)]
pub struct ContinuousState {
    pub state: u32,
    pub derivative: u32,
}

/// The Model Exchange interface of a model (rendered into
/// `<ModelExchange …/>`, the `derivative` attributes, `<Derivatives>` and
/// `numberOfEventIndicators`): its continuous states in the order of
/// `fmi2GetContinuousStates`, its number of event indicators, and whether
/// its states may jump at events (`reinit`).
#[derive(Clone, Copy, Debug)]
pub struct ModelExchange {
    pub states: &'static [ContinuousState],
    pub event_indicators: usize,
    pub states_jump_at_events: bool,
}

impl ModelExchange {
    /// Whether `vr` is one of the state variables.
    pub fn is_state(&self, vr: u32) -> bool {
        self.states.iter().any(|s| s.state == vr)
    }

    /// Whether `vr` is one of the derivative variables.
    pub fn is_derivative(&self, vr: u32) -> bool {
        self.states.iter().any(|s| s.derivative == vr)
    }
}

/// Co-simulation capability flags, rendered into `<CoSimulation …/>`.
#[derive(Clone, Copy, Debug)]
pub struct Capabilities {
    pub can_handle_variable_step: bool,
    pub can_interpolate_inputs: bool,
    pub max_output_derivative_order: u32,
    pub can_get_and_set_state: bool,
    pub can_serialize_state: bool,
    pub provides_directional_derivative: bool,
}

impl Capabilities {
    /// Everything this layer implements.
    pub const FULL: Capabilities = Capabilities {
        can_handle_variable_step: true,
        can_interpolate_inputs: true,
        max_output_derivative_order: 1,
        can_get_and_set_state: true,
        can_serialize_state: true,
        provides_directional_derivative: true,
    };
}

#[derive(Clone, Copy, Debug)]
pub struct DefaultExperiment {
    pub start_time: f64,
    pub stop_time: f64,
    pub step_size: f64,
}

/// Everything the C layer and the XML renderer need to know about one model.
#[derive(Debug)]
pub struct ModelInfo {
    /// `modelName` and the `.fmu` file name, e.g. `LuGre`.
    pub model_name: &'static str,
    /// `modelIdentifier`: the name of the shared library inside the FMU.
    pub model_identifier: &'static str,
    pub guid: &'static str,
    pub description: &'static str,
    /// Which papers the equations come from (author and year), appended to
    /// the model description after "Source:".
    pub source: &'static str,
    pub variables: &'static [Variable],
    pub default_experiment: DefaultExperiment,
    pub capabilities: Capabilities,
    /// The Model Exchange interface, for a model that is an ODE with its
    /// states and event indicators; `None`: Co-Simulation only.
    pub model_exchange: Option<ModelExchange>,
    /// The continuous states a Co-Simulation-only model lists in
    /// `ModelStructure/Derivatives` (FMI 2.0.4 §2.2.8 allows it for
    /// Co-Simulation: the states and their derivatives then carry the
    /// partial derivatives an importer linearizes with,
    /// `fmi2GetDirectionalDerivative` with a state among the knowns or a
    /// derivative among the unknowns, [`crate::Model::state_partial_derivative`]).
    /// Empty for a model with a Model Exchange interface, whose states are
    /// [`ModelExchange::states`].
    pub co_simulation_states: &'static [ContinuousState],
}

/// Log categories every FMU of this layer declares, in this order.
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    (
        "logStatusError",
        "Errors: invalid calls, arguments and parameters (on by default)",
    ),
    (
        "logStatusFatal",
        "Fatal errors: internal failures (on by default)",
    ),
    ("logStatusWarning", "Warnings"),
    ("logCalls", "Every FMI function call with its arguments"),
];

impl ModelInfo {
    /// The continuous states the model description lists: those of the
    /// Model Exchange interface, or those a Co-Simulation-only model lists
    /// ([`ModelInfo::co_simulation_states`]).
    pub fn continuous_states(&self) -> &'static [ContinuousState] {
        match &self.model_exchange {
            Some(me) => me.states,
            None => self.co_simulation_states,
        }
    }

    /// Whether `vr` is one of the listed state variables.
    pub fn is_state(&self, vr: u32) -> bool {
        self.continuous_states().iter().any(|s| s.state == vr)
    }

    /// Whether `vr` is one of the listed state derivatives.
    pub fn is_derivative(&self, vr: u32) -> bool {
        self.continuous_states().iter().any(|s| s.derivative == vr)
    }

    pub fn variable(&self, vr: u32) -> Option<&'static Variable> {
        self.variables.get(vr as usize)
    }

    pub fn by_name(&self, name: &str) -> Option<&'static Variable> {
        self.variables.iter().find(|v| v.name == name)
    }

    /// The value references of the Real variables of `causality`, in
    /// table order.
    pub fn reals_of(&self, causality: Causality) -> impl Iterator<Item = u32> + 'static {
        self.variables
            .iter()
            .filter(move |v| v.causality == causality && v.var_type == VarType::Real)
            .map(|v| v.vr)
    }

    /// Consistency of the table: value reference = index, unique names,
    /// start values where required, dependencies pointing at inputs.
    pub fn check(&self) -> Result<(), String> {
        let mut names = std::collections::HashSet::new();
        for (i, v) in self.variables.iter().enumerate() {
            if v.vr as usize != i {
                return Err(format!(
                    "{}: variable {} has vr {} at index {}",
                    self.model_name, v.name, v.vr, i
                ));
            }
            if !names.insert(v.name) {
                return Err(format!(
                    "{}: duplicate variable name {}",
                    self.model_name, v.name
                ));
            }
            let needs_start = matches!(v.causality, Causality::Parameter | Causality::Input);
            if needs_start != v.start.is_some() {
                return Err(format!(
                    "{}: variable {} start value presence is wrong",
                    self.model_name, v.name
                ));
            }
            for d in v.depends_on {
                match self.variable(*d) {
                    Some(dep) if dep.causality == Causality::Input => {}
                    _ => {
                        return Err(format!(
                            "{}: {} depends on vr {} which is not an input",
                            self.model_name, v.name, d
                        ))
                    }
                }
            }
            let is_state = |vr: u32| self.is_state(vr);
            if let Some(d) = v.depends_on_states.iter().find(|d| !is_state(**d)) {
                return Err(format!(
                    "{}: {} depends on vr {d} which is not a continuous state",
                    self.model_name, v.name
                ));
            }
            let is_derivative = self.is_derivative(v.vr);
            let local_kind = is_derivative || is_state(v.vr) && v.causality == Causality::Local;
            if (v.causality == Causality::Local) != local_kind {
                return Err(format!(
                    "{}: {} is {}a local variable but {}a state derivative or a state (the layer computes only derivatives and states as locals)",
                    self.model_name,
                    v.name,
                    if v.causality == Causality::Local { "" } else { "not " },
                    if local_kind { "" } else { "not " },
                ));
            }
        }
        if self.model_exchange.is_some() && !self.co_simulation_states.is_empty() {
            return Err(format!(
                "{}: lists Co-Simulation states beside a Model Exchange interface (its states are the interface's)",
                self.model_name
            ));
        }
        for s in self.continuous_states() {
            let state = self.variable(s.state);
            let derivative = self.variable(s.derivative);
            let real_continuous = |v: Option<&Variable>| {
                v.is_some_and(|v| {
                    v.var_type == VarType::Real && v.variability == Variability::Continuous
                })
            };
            if !real_continuous(state) || !real_continuous(derivative) {
                return Err(format!(
                    "{}: continuous state vr {} or its derivative vr {} is not a continuous Real variable",
                    self.model_name, s.state, s.derivative
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A table with the state variable `state` (value reference 3), its
    /// derivative and an output `y` of the state.
    fn info(state: Variable) -> ModelInfo {
        let variables = vec![
            Variable::input(0, "u", 0.0, "", 1.0, "input"),
            Variable::output(1, "y", "", "s + 1", &[]).with_state_dependencies(&[3]),
            Variable::derivative(2, "der(s)", "", "-s + u", &[0], &[3]),
            state,
        ];
        ModelInfo {
            model_name: "LocalState",
            model_identifier: "LocalState",
            guid: "{local-state}",
            description: "test model",
            source: "test",
            variables: Box::leak(variables.into_boxed_slice()),
            default_experiment: DefaultExperiment {
                start_time: 0.0,
                stop_time: 1.0,
                step_size: 0.1,
            },
            capabilities: Capabilities::FULL,
            co_simulation_states: &[],
            model_exchange: Some(ModelExchange {
                states: &[ContinuousState {
                    state: 3,
                    derivative: 2,
                }],
                event_indicators: 0,
                states_jump_at_events: false,
            }),
        }
    }

    /// A Co-Simulation-only model may list its states (rendered as Model
    /// Exchange's are: the `derivative` attribute and `<Derivatives>`,
    /// with no `<ModelExchange>` element); beside a Model Exchange
    /// interface, whose states they would be, they are refused.
    #[test]
    fn a_co_simulation_model_may_list_its_states() {
        const STATES: &[ContinuousState] = &[ContinuousState {
            state: 3,
            derivative: 2,
        }];
        let listed = ModelInfo {
            co_simulation_states: STATES,
            model_exchange: None,
            ..info(Variable::state(3, "s", "", "the state"))
        };
        listed.check().unwrap();
        assert!(listed.is_state(3) && listed.is_derivative(2) && !listed.is_state(2));
        let xml = crate::model_description::render(&listed, "test").unwrap();
        assert!(xml.contains(r#"<Real derivative="4"/>"#), "{xml}");
        assert!(
            xml.contains("<Derivatives>") && !xml.contains("<ModelExchange"),
            "{xml}"
        );
        let both = ModelInfo {
            co_simulation_states: STATES,
            ..info(Variable::state(3, "s", "", "the state"))
        };
        let e = both.check().unwrap_err();
        assert!(e.contains("beside a Model Exchange interface"), "{e}");
    }

    /// A continuous state may be a local variable (not only an output),
    /// and is then listed among the initial unknowns with its derivative
    /// and the outputs (FMI 2.0.4 §2.2.8); a local that is neither a state
    /// nor a derivative is refused.
    #[test]
    fn a_state_may_be_a_local_variable() {
        let good = info(Variable::state(3, "s", "", "the state"));
        good.check().unwrap();
        let xml = crate::model_description::render(&good, "test").unwrap();
        let var = xml.split("<!-- index 4 -->").nth(1).unwrap();
        assert!(
            var.contains(r#"name="s" valueReference="3" description="the state" causality="local" variability="continuous" initial="calculated""#),
            "{xml}"
        );
        assert!(xml.contains(r#"<Real derivative="4"/>"#), "{xml}");
        let initial = xml.split("<InitialUnknowns>").nth(1).unwrap();
        let initial = initial.split("</InitialUnknowns>").next().unwrap();
        let listed: Vec<&str> = initial
            .split("index=\"")
            .skip(1)
            .map(|s| s.split('"').next().unwrap())
            .collect();
        assert_eq!(listed, ["2", "3", "4"]);
        // a local of the table that is not a state: refused, named
        let mut stray = good.variables.to_vec();
        stray.push(Variable::state(4, "w", "", "no state"));
        let stray = ModelInfo {
            variables: Box::leak(stray.into_boxed_slice()),
            ..info(Variable::state(3, "s", "", "the state"))
        };
        let e = stray.check().unwrap_err();
        assert!(e.contains("w is a local variable but not"), "{e}");
    }
}
