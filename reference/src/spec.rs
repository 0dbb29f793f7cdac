//! A system of this project's models as plain data: components (model name,
//! GUID, parameter values by FMU variable name) and connections
//! `component.output → component.input`. The host fills it from an SSP file;
//! tests and other tools can write it directly.

use fmi_export::{Causality, Model, ModelInfo, Values, VarType};
use std::fmt;

/// A parameter (or input start) value, as a system file gives it.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Real(f64),
    Integer(i64),
    Boolean(bool),
    String(String),
}

impl Value {
    fn describe(&self) -> String {
        match self {
            Value::Real(x) => format!("Real {x}"),
            Value::Integer(i) => format!("Integer {i}"),
            Value::Boolean(b) => format!("Boolean {b}"),
            Value::String(s) => format!("String \"{s}\""),
        }
    }
}

/// One component: its instance name, the FMU's model name and (when known)
/// GUID, and the parameter values set on it.
#[derive(Clone, Debug, PartialEq)]
pub struct ComponentSpec {
    pub name: String,
    pub model_name: String,
    pub guid: Option<String>,
    pub parameters: Vec<(String, Value)>,
}

impl ComponentSpec {
    pub fn new(name: &str, model_name: &str) -> Self {
        ComponentSpec {
            name: name.to_string(),
            model_name: model_name.to_string(),
            guid: None,
            parameters: Vec::new(),
        }
    }

    pub fn real(mut self, name: &str, value: f64) -> Self {
        self.parameters.push((name.to_string(), Value::Real(value)));
        self
    }

    pub fn integer(mut self, name: &str, value: i64) -> Self {
        self.parameters
            .push((name.to_string(), Value::Integer(value)));
        self
    }

    pub fn boolean(mut self, name: &str, value: bool) -> Self {
        self.parameters
            .push((name.to_string(), Value::Boolean(value)));
        self
    }
}

/// Components and connections (`("rig.v", "friction.v")`: output first).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SystemSpec {
    pub components: Vec<ComponentSpec>,
    pub connections: Vec<(String, String)>,
}

impl SystemSpec {
    pub fn connect(mut self, from: &str, to: &str) -> Self {
        self.connections.push((from.to_string(), to.to_string()));
        self
    }
}

/// Why a system cannot be mapped onto a monolithic reference model; the
/// message names the component (or connection) and the reason.
#[derive(Clone, Debug, PartialEq)]
pub struct MapError(pub String);

impl fmt::Display for MapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for MapError {}

/// The models a reference exists for, with the FMU adapters' variable
/// tables (the single source of their names, start values and parameter
/// semantics).
pub(crate) fn known_model(model_name: &str) -> Option<(&'static ModelInfo, Box<dyn Model>)> {
    if !SUPPORTED.contains(&model_name) {
        return None;
    }
    rig_fmu::REGISTRY
        .iter()
        .chain(friction_fmu::REGISTRY.iter())
        .find(|f| f.info.model_name == model_name)
        .map(|f| (f.info, (f.create)()))
}

/// Model names a reference can be built for.
pub const SUPPORTED: [&str; 6] = ["Rig1D", "Rig2D", "LuGre", "Dahl", "Bristle", "Bristle2D"];

/// A component recognised as one of our models: its parameter and input
/// start values set as the FMU would hold them after initialisation, and an
/// in-process instance of the FMU's model used to compute the output
/// columns from a state.
pub(crate) struct Component {
    pub name: String,
    pub info: &'static ModelInfo,
    pub values: Values,
    pub model: Box<dyn Model>,
    /// The recorded variables (name, value reference): the Real outputs in
    /// variable-table order, then any recorded besides them.
    pub columns: Vec<(&'static str, u32)>,
}

impl Component {
    /// Recognises the model (name, and GUID when given), applies the
    /// parameter values by name and initialises the model, which checks
    /// them exactly as the FMU does.
    pub fn from_spec(spec: &ComponentSpec) -> Result<Component, MapError> {
        let name = &spec.name;
        let Some((info, mut model)) = known_model(&spec.model_name) else {
            return Err(MapError(format!(
                "component `{name}`: model `{}` has no monolithic reference (supported: Rig1D with LuGre or Dahl; Rig1D with m = 0, c = 0 and Bristle; Rig2D with Bristle2D)",
                spec.model_name
            )));
        };
        if let Some(guid) = &spec.guid {
            if guid != info.guid {
                return Err(MapError(format!(
                    "component `{name}`: model `{}` has GUID {guid}, not the GUID {} of this project's {} FMU, so its equations are unknown",
                    spec.model_name, info.guid, info.model_name
                )));
            }
        }
        let mut values = Values::from_start(info.variables);
        for (pname, value) in &spec.parameters {
            let Some(var) = info.variables.iter().find(|v| v.name == pname) else {
                return Err(MapError(format!(
                    "component `{name}` ({}): no variable `{pname}`",
                    info.model_name
                )));
            };
            if !matches!(var.causality, Causality::Parameter | Causality::Input) {
                return Err(MapError(format!(
                    "component `{name}` ({}): `{pname}` is not a parameter or input",
                    info.model_name
                )));
            }
            let number = match (var.var_type, value) {
                (VarType::Real, Value::Real(x)) => Some(*x),
                (VarType::Real, Value::Integer(i)) => Some(*i as f64),
                (VarType::Integer, Value::Integer(i)) if i32::try_from(*i).is_ok() => {
                    Some(*i as f64)
                }
                (VarType::Boolean, Value::Boolean(b)) => Some(if *b { 1.0 } else { 0.0 }),
                _ => None,
            };
            let Some(number) = number else {
                return Err(MapError(format!(
                    "component `{name}` ({}): `{pname}` is {:?}, cannot take {}",
                    info.model_name,
                    var.var_type,
                    value.describe()
                )));
            };
            values.set(var.vr, number);
        }
        model
            .initialize(&values)
            .map_err(|e| MapError(format!("component `{name}` ({}): {e}", info.model_name)))?;
        let columns = info
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output && v.var_type == VarType::Real)
            .map(|v| (v.name, v.vr))
            .collect();
        Ok(Component {
            name: name.clone(),
            info,
            values,
            model,
            columns,
        })
    }

    /// Value reference of a variable by name.
    pub fn vr(&self, variable: &str) -> Option<u32> {
        self.info
            .variables
            .iter()
            .find(|v| v.name == variable)
            .map(|v| v.vr)
    }

    /// Records the Real variable `variable` (an input, a parameter) after
    /// the outputs, as `fricsim run --record` does.
    pub fn record(&mut self, variable: &str) -> Result<(), MapError> {
        let Some(var) = self.info.variables.iter().find(|v| v.name == variable) else {
            return Err(MapError(format!(
                "cannot record `{}.{variable}`: {} has no variable `{variable}`",
                self.name, self.info.model_name
            )));
        };
        if var.var_type != VarType::Real {
            return Err(MapError(format!(
                "cannot record `{}.{variable}`: it is a {:?} variable; only Real variables are recorded",
                self.name, var.var_type
            )));
        }
        if !self.columns.iter().any(|(n, _)| *n == variable) {
            self.columns.push((var.name, var.vr));
        }
        Ok(())
    }

    /// Outputs for a state and input values: restores `state` into the
    /// model, sets `inputs` (by value reference) and evaluates.
    pub fn outputs(&mut self, state: &[f64], inputs: &[(u32, f64)]) -> Result<Values, String> {
        self.model.restore_state(state)?;
        let mut values = self.values.clone();
        for &(vr, x) in inputs {
            values.set(vr, x);
        }
        self.model.compute_outputs(&mut values);
        Ok(values)
    }
}
