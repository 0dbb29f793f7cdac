//! What a model provides to the FMI layer. Models are plain Rust: they never
//! see a pointer, a C string or an FMI status.

use crate::{ModelInfo, Values};

/// A co-simulation model: parameters and inputs come in through [`Values`],
/// outputs go out through it, the state lives in the implementor.
///
/// Communication-step semantics: at a communication point the importer sets
/// the inputs `u(t)` (and optionally their slopes `du/dt`), then
/// `do_step(h)` advances the state to `t + h` with `u(t + τ) = u(t) + du·τ`.
/// Outputs are a function of the state and the *current* inputs, so an
/// output with direct feedthrough changes as soon as an input is set.
pub trait Model: Send {
    fn info(&self) -> &'static ModelInfo;

    /// Read and validate the parameters, and reset the state to its initial
    /// value. Called when outputs are first needed in initialization mode
    /// and again at `fmi2ExitInitializationMode`. The error names the
    /// parameter and its value.
    fn initialize(&mut self, values: &Values) -> Result<(), String>;

    /// Physical checks of an input value beyond finiteness (e.g. a normal
    /// force must not be negative).
    fn check_input(&self, _vr: u32, _value: f64) -> Result<(), String> {
        Ok(())
    }

    /// Whether [`Model::check_input`] may refuse a value of input `vr`:
    /// `false` lets the layer skip the call when the input is set. Asked
    /// once per input, when the instance is created. The default, `true`,
    /// is right for every model; one that overrides `check_input` answers
    /// `true` for each input it checks.
    fn input_checked(&self, _vr: u32) -> bool {
        true
    }

    /// Write every output into `values` from the state and the current
    /// inputs, and the value of every continuous state declared as a local
    /// variable ([`crate::Variable::state`]), and nothing else: the layer
    /// keeps inputs and parameters in `values` across calls.
    fn compute_outputs(&self, values: &mut Values);

    /// Write at least the outputs `outputs` (value references of outputs)
    /// into `values`, each bit for bit as [`Model::compute_outputs`] does,
    /// for directional derivatives and for a read of one output of the
    /// state alone (no `depends_on`), which need only these; the other
    /// outputs (and local states) may be left as they are, inputs and
    /// parameters must be. By default every output.
    fn compute_outputs_of(&self, values: &mut Values, outputs: &[u32]) {
        let _ = outputs;
        self.compute_outputs(values);
    }

    /// Advance the state over `h` seconds. `slopes[vr]` is `du/dt` of input
    /// `vr` (zero when not set).
    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String>;

    /// Append the complete state to `out` (cleared by the caller).
    fn save_state(&self, out: &mut Vec<f64>);

    /// The number of values of the state, if the model writes it into a
    /// slice with [`Model::write_state_into`]; `None` (the default) makes
    /// the layer use [`Model::save_state`]. A property of the model and its
    /// parameters (a number of bristles, say), not of the state: asked
    /// after every `initialize`, not per step.
    fn state_len(&self) -> Option<usize> {
        None
    }

    /// Write the complete state into `out`, of `state_len()` values: the
    /// values [`Model::save_state`] appends, bit for bit, without a vector
    /// to grow. Called only if `state_len` answers; a model that answers
    /// overrides this (the default goes through `save_state`, and
    /// allocates).
    fn write_state_into(&self, out: &mut [f64]) {
        let mut state = Vec::with_capacity(out.len());
        self.save_state(&mut state);
        out.copy_from_slice(&state);
    }

    /// Whether the state after a step is finite, if the model can tell
    /// without its state being copied: `Some(answer)`, which must equal a
    /// scan of what [`Model::save_state`] writes. `None` (the default)
    /// makes the layer save the state after every step and scan it, which
    /// costs a copy of the whole state per step: a model with a large
    /// state (the bristle model's `2·N` values) answers from what it
    /// knows. Called after every step.
    fn state_is_finite(&self) -> Option<bool> {
        None
    }

    /// Restore a state written by `save_state` of the same model.
    fn restore_state(&mut self, state: &[f64]) -> Result<(), String>;

    fn clone_model(&self) -> Box<dyn Model>;

    /// `∂ output / ∂ input` computed by the model itself. `None` lets the
    /// layer differentiate the last step numerically by replaying it.
    fn partial_derivative(&self, _values: &Values, _output: u32, _input: u32) -> Option<f64> {
        None
    }

    /// Whether `partial_derivative` may answer `Some` at all: a model whose
    /// `partial_derivative` is the default returns `false`, and the layer
    /// differentiates without asking it per entry. Asked once, when the
    /// instance is created.
    fn supplies_partial_derivatives(&self) -> bool {
        true
    }

    /// The step sensitivity `∂ output(t + h) / ∂ input` of the last step,
    /// computed by the model itself: called right after a step of length
    /// `h` over which every input was held at its value in `values` (no
    /// slopes, nothing set since), with the model in the state after it.
    /// With the step map `x⁺ = Φ_h(x, u)` and the output equation
    /// `y = g(x, u)`, it is
    ///
    /// ```text
    /// ∂y/∂u = ∂g/∂x(x⁺, u) · ∂Φ_h/∂u(x, u) + ∂g/∂u(x⁺, u),
    /// ```
    ///
    /// the state change over the step and the direct feedthrough together:
    /// what the layer otherwise obtains by central differences of the
    /// replayed step, `(y(u + δ) − y(u − δ)) / 2δ`, with the input moved by
    /// `δ = spread`. `None` lets those differences decide: for any
    /// output/input pair the model has no closed form for, and wherever
    /// the step map is not smooth over `[u − spread, u + spread]` (a kink
    /// such as `|v|` at 0, where the differences average the two sides).
    /// Asked only if [`Model::supplies_step_derivatives`].
    fn step_partial_derivative(
        &self,
        _values: &Values,
        _output: u32,
        _input: u32,
        _h: f64,
        _spread: f64,
    ) -> Option<f64> {
        None
    }

    /// Whether [`Model::step_partial_derivative`] may answer `Some` at
    /// all: `false` (the default) and the layer never asks it. Asked once,
    /// when the instance is created.
    fn supplies_step_derivatives(&self) -> bool {
        false
    }

    /// `∂output/∂parameter` along the trajectory since initialization (the
    /// parameter's sensitivity, carried by the model through its steps),
    /// at the current state and inputs: what `fmi2GetDirectionalDerivative`
    /// gives for a Real parameter as a known, an extension of this
    /// project's FMUs for fitting (a standard importer never asks). `Err`
    /// says why not (by default: the model carries none).
    fn parameter_sensitivity(
        &self,
        _values: &Values,
        _output: u32,
        _parameter: u32,
    ) -> Result<f64, String> {
        Err("this FMU carries no parameter sensitivities".into())
    }

    /// Whether the layer must keep a copy of the pre-step state so that it can
    /// replay the step for directional derivatives. Models whose
    /// `partial_derivative` covers every output/input pair return `false`.
    /// Asked once, when the instance is created.
    fn needs_step_replay(&self) -> bool {
        true
    }

    /// First time derivative of an output at the current point, with the
    /// inputs moving at `slopes`. `None` when this output has none.
    fn output_derivative(&self, _values: &Values, _slopes: &[f64], _output: u32) -> Option<f64> {
        None
    }

    /// Whether the model reads files from the FMU's `resources/`
    /// directory. If it does, `fmi2Instantiate` refuses a
    /// `fmuResourceLocation` that names no directory
    /// ([`crate::resource_location`]) and passes the directory to
    /// [`Model::set_resource_dir`]; if not (the default, and every model of
    /// this project), any location is accepted and only logged. Asked once,
    /// when the instance is created.
    fn needs_resources(&self) -> bool {
        false
    }

    /// The FMU's `resources/` directory, as a path of the platform the
    /// binary runs on; called once, right after creation, on a model that
    /// [`Model::needs_resources`].
    fn set_resource_dir(&mut self, _dir: &str) {}

    /// For a model with continuous states ([`ModelInfo::model_exchange`]):
    /// their time derivatives `ẋ = f(x, u)` at the current state and the
    /// inputs in `values`, one per state in the declared order, into `dx`.
    /// The values of the `der(…)` variables, in either interface, and the
    /// right-hand side `fmi2GetDerivatives` gives in Model Exchange: the
    /// law's equations, the ones its step integrates. The default writes
    /// nothing (a model without continuous states).
    fn derivatives(&self, _values: &Values, _dx: &mut [f64]) {}

    /// `∂unknown/∂known` of a Co-Simulation model that lists continuous
    /// states ([`crate::ModelInfo::co_simulation_states`]), at its current
    /// state and the inputs in `values`: `unknown` a state derivative or a
    /// Real output, `known` a listed state or a Real input (value
    /// references, checked), continuous-time partial derivatives as in
    /// Model Exchange. `Err` says why the model does not give it (a mode
    /// without those states, say); the default gives none.
    fn state_partial_derivative(
        &self,
        _values: &Values,
        unknown: u32,
        known: u32,
    ) -> Result<f64, String> {
        Err(format!(
            "the model gives no partial derivative of value reference {unknown} with respect to {known}"
        ))
    }

    /// The Model Exchange part of a model instantiated for it
    /// ([`ModelFactory::create_model_exchange`]); `None` (the default) for
    /// a Co-Simulation model.
    fn ode(&self) -> Option<&dyn Ode> {
        None
    }

    /// [`Model::ode`], mutable.
    fn ode_mut(&mut self) -> Option<&mut dyn Ode> {
        None
    }
}

/// What a model adds for Model Exchange (FMI 2.0.4 §3): its continuous
/// states, event indicators and their nominal scales, what happens at an
/// event, and the partial derivatives of its right-hand side and outputs.
/// The right-hand side itself is [`Model::derivatives`]. States are in the
/// order of [`crate::ModelExchange::states`]; the layer checks every
/// length, pointer and number before calling these.
pub trait Ode {
    /// The continuous states `x` into `x`.
    fn continuous_states(&self, x: &mut [f64]);

    /// Take the continuous states `x` (finite). `Err` (nothing changed)
    /// for a state the model cannot take.
    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String>;

    /// The event indicators at the current state and inputs into `z`:
    /// functions that change sign where the law switches.
    fn event_indicators(&self, values: &Values, z: &mut [f64]);

    /// Nominal magnitudes of the states (> 0), from the parameters in
    /// `values` (also before initialization).
    fn nominals(&self, values: &Values, nominal: &mut [f64]);

    /// The event iteration at the current state and inputs
    /// (`fmi2NewDiscreteStates`): switch what the law switches at this
    /// event. Whether the continuous states changed.
    fn event_update(&mut self, values: &Values) -> bool;

    /// `∂unknown/∂known` at the current state and inputs: `unknown` a
    /// state derivative or a Real output, `known` a continuous state or a
    /// Real input (value references). `None` where the model does not give
    /// it (the call is refused).
    fn partial_derivative(&self, values: &Values, unknown: u32, known: u32) -> Option<f64>;
}

/// An entry of the binary's model registry: the GUID picks the model.
pub struct ModelFactory {
    pub info: &'static ModelInfo,
    pub create: fn() -> Box<dyn Model>,
    /// A model for Model Exchange, whose [`Model::ode`] answers; `None`
    /// for a model offered as Co-Simulation only.
    pub create_model_exchange: Option<fn() -> Box<dyn Model>>,
}

/// The `Model` methods of the state for a law with `state_len` /
/// `write_state_into` / `state_is_finite` / `state_from_slice` held in
/// field `$law` of a `Clone` model (`save_state` appends what
/// `write_state_into` writes; `state_is_finite` answers after every step
/// without a copy of the state):
/// write `fmi_export::delegate_state!(law);` inside the `impl Model`.
#[macro_export]
macro_rules! delegate_state {
    ($law:ident) => {
        fn save_state(&self, out: &mut Vec<f64>) {
            let start = out.len();
            out.resize(start + self.$law.state_len(), 0.0);
            self.$law.write_state_into(&mut out[start..]);
        }

        fn state_len(&self) -> Option<usize> {
            Some(self.$law.state_len())
        }

        fn write_state_into(&self, out: &mut [f64]) {
            self.$law.write_state_into(out);
        }

        fn state_is_finite(&self) -> Option<bool> {
            Some(self.$law.state_is_finite())
        }

        fn restore_state(&mut self, state: &[f64]) -> Result<(), String> {
            self.$law.state_from_slice(state)
        }

        fn clone_model(&self) -> Box<dyn $crate::Model> {
            Box::new(self.clone())
        }
    };
}

/// [`Model::ode`] and [`Model::ode_mut`] of a model that implements
/// [`Ode`] itself: write `fmi_export::ode_is_self!();` inside its
/// `impl Model`.
#[macro_export]
macro_rules! ode_is_self {
    () => {
        fn ode(&self) -> Option<&dyn $crate::Ode> {
            Some(self)
        }

        fn ode_mut(&mut self) -> Option<&mut dyn $crate::Ode> {
            Some(self)
        }
    };
}

/// [`Ode::continuous_states`] and [`Ode::set_continuous_states`] for a
/// model whose continuous states are the whole state of the law in field
/// `$law` (its `write_state_into` and `state_from_slice`, as
/// [`delegate_state!`](crate::delegate_state) uses them): write
/// `fmi_export::delegate_continuous_states!(law);` inside the `impl Ode`.
#[macro_export]
macro_rules! delegate_continuous_states {
    ($law:ident) => {
        fn continuous_states(&self, x: &mut [f64]) {
            self.$law.write_state_into(x);
        }

        fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
            self.$law.state_from_slice(x)
        }
    };
}
