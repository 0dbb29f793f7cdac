//! Model Exchange (FMI 2.0.4 §3) on an [`Instance`]: the continuous
//! states, their derivatives, event indicators and nominals, the event
//! iteration and the directional derivatives of the right-hand side, each
//! checked as the Co-Simulation calls are (lengths, finiteness, value
//! references) with the reason in the error. The state table
//! ([`crate::state_machine::ME_ALLOWED`]) has already decided that the call
//! is allowed, which also means the instance is a Model Exchange one.
//!
//! Nothing here runs for a Co-Simulation instance but the directional
//! derivatives of the states a Co-Simulation model lists
//! ([`crate::ModelInfo::co_simulation_states`]): its other calls never
//! reach this module.

use super::Instance;
use crate::model::Ode;
use crate::state_machine::State;
use crate::variables::{Causality, ModelExchange, VarType};

impl Instance {
    /// Make this new instance a Model Exchange one, in state
    /// [`State::MeInstantiated`]: its model came from
    /// [`crate::ModelFactory::create_model_exchange`] and answers
    /// [`crate::Model::ode`], its description declares the states.
    pub fn make_model_exchange(&mut self) -> Result<(), String> {
        let info = self.info;
        let me = info
            .model_exchange
            .ok_or_else(|| format!("{} declares no Model Exchange interface", info.model_name))?;
        // (no continuous states is allowed: a law whose force follows from
        // its inputs takes part in Model Exchange by its event indicators)
        if self.model.ode().is_none() || me.states.is_empty() && me.event_indicators == 0 {
            return Err(format!(
                "{} has no Model Exchange model in this binary",
                info.model_name
            ));
        }
        self.model_exchange = true;
        self.state = State::MeInstantiated;
        Ok(())
    }

    /// Whether this instance was created for Model Exchange.
    pub fn is_model_exchange(&self) -> bool {
        self.model_exchange
    }

    /// The Model Exchange declaration of the model (present: checked at
    /// instantiation).
    fn me(&self) -> ModelExchange {
        self.info
            .model_exchange
            .expect("a Model Exchange instance has a Model Exchange declaration")
    }

    fn ode(&self) -> &dyn Ode {
        self.model
            .ode()
            .expect("a Model Exchange instance's model answers ode()")
    }

    /// `n` (the length the importer passed, named `what`) must be the
    /// model's number of `things`, `expected`.
    fn check_count(
        &self,
        what: &str,
        n: usize,
        expected: usize,
        things: &str,
    ) -> Result<(), String> {
        if n == expected {
            return Ok(());
        }
        Err(format!(
            "{what} = {n}, but {} has {expected} {things}",
            self.info.model_name
        ))
    }

    /// The number of continuous states must be `nx`.
    pub fn check_nx(&self, nx: usize) -> Result<(), String> {
        let expected = self.me().states.len();
        let things = if expected == 1 {
            "continuous state"
        } else {
            "continuous states"
        };
        self.check_count("nx", nx, expected, things)
    }

    /// The number of event indicators must be `ni`.
    pub fn check_ni(&self, ni: usize) -> Result<(), String> {
        let expected = self.me().event_indicators;
        let things = if expected == 1 {
            "event indicator"
        } else {
            "event indicators"
        };
        self.check_count("ni", ni, expected, things)
    }

    /// The model initialized with the current parameters (before
    /// `fmi2ExitInitializationMode`, as reading an output does).
    fn ensure_initialized(&mut self) -> Result<(), String> {
        if self.initialized {
            return Ok(());
        }
        self.ensure_outputs()
    }

    // ---- modes ----------------------------------------------------------

    pub fn enter_event_mode(&mut self) -> Result<(), String> {
        self.state = State::EventMode;
        Ok(())
    }

    pub fn enter_continuous_time_mode(&mut self) -> Result<(), String> {
        self.state = State::ContinuousTimeMode;
        Ok(())
    }

    /// `fmi2NewDiscreteStates`: the model's event iteration at the current
    /// state and inputs ([`Ode::event_update`]); whether the continuous
    /// states changed. One iteration always settles it: the models switch
    /// what the event switches and need no second pass.
    pub fn new_discrete_states(&mut self) -> Result<bool, String> {
        let values = &self.values;
        let changed = self
            .model
            .ode_mut()
            .expect("a Model Exchange instance's model answers ode()")
            .event_update(values);
        self.outputs_dirty = true;
        self.step_state_current = false;
        Ok(changed)
    }

    /// `fmi2SetTime`: the models are autonomous (time enters through the
    /// inputs only), so time is kept for the FMU state and the log.
    pub fn set_time(&mut self, t: f64) -> Result<(), String> {
        if !t.is_finite() {
            return Err(format!("time must be finite but was {t}"));
        }
        self.time = t;
        Ok(())
    }

    // ---- states and right-hand side --------------------------------------

    /// `fmi2SetContinuousStates` of `x` (of length nx, checked): every
    /// value finite, else refused naming the state, nothing changed.
    pub fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        let me = self.me();
        if let Some((k, value)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            let name = self.info.variables[me.states[k].state as usize].name;
            return Err(format!("x[{k}] ({name}) must be finite but was {value}"));
        }
        self.model
            .ode_mut()
            .expect("a Model Exchange instance's model answers ode()")
            .set_continuous_states(x)?;
        self.outputs_dirty = true;
        self.step_state_current = false;
        Ok(())
    }

    /// `fmi2GetContinuousStates` into `out` (of length nx, checked).
    pub fn get_continuous_states(&mut self, out: &mut [f64]) -> Result<(), String> {
        self.ensure_initialized()?;
        self.ode().continuous_states(out);
        Ok(())
    }

    /// `fmi2GetDerivatives` into `out` (of length nx, checked): the
    /// model's right-hand side ([`crate::Model::derivatives`]); refused, naming
    /// the derivative, where it is not finite.
    pub fn get_derivatives(&mut self, out: &mut [f64]) -> Result<(), String> {
        self.ensure_initialized()?;
        self.model.derivatives(&self.values, out);
        if out.iter().all(|d| d.is_finite()) {
            return Ok(());
        }
        let me = self.me();
        let (k, d) = out
            .iter()
            .enumerate()
            .find(|(_, d)| !d.is_finite())
            .expect("one is not finite");
        Err(format!(
            "{} evaluates to {d}: the parameters, inputs or states are out of the model's range",
            self.info.variables[me.states[k].derivative as usize].name
        ))
    }

    /// `fmi2GetEventIndicators` into `out` (of length ni, checked).
    pub fn get_event_indicators(&mut self, out: &mut [f64]) -> Result<(), String> {
        self.ensure_initialized()?;
        self.ode().event_indicators(&self.values, out);
        match out.iter().position(|z| !z.is_finite()) {
            None => Ok(()),
            Some(k) => Err(format!(
                "event indicator {k} evaluates to {}: the parameters, inputs or states are out of the model's range",
                out[k]
            )),
        }
    }

    /// `fmi2GetNominalsOfContinuousStates` into `out` (of length nx,
    /// checked), from the parameters set so far; 1 for a state whose
    /// nominal is not a positive finite number (parameters not yet valid).
    pub fn get_nominals(&mut self, out: &mut [f64]) -> Result<(), String> {
        self.ode().nominals(&self.values, out);
        for n in out.iter_mut() {
            if !(n.is_finite() && *n > 0.0) {
                *n = 1.0;
            }
        }
        Ok(())
    }

    // ---- directional derivatives -----------------------------------------

    /// `fmi2GetDirectionalDerivative` of a Model Exchange instance, or of
    /// a Co-Simulation one asked with its listed states
    /// ([`Instance::asks_state_partials`]): `dv_unknown = J·dv_known`
    /// (the knowns with their seeds) with `J` the partial derivatives of
    /// state derivatives and Real outputs (`unknowns`) with respect to
    /// continuous states and Real inputs (`knowns`) at the current point,
    /// each given by the model in closed form ([`Ode::partial_derivative`];
    /// in Co-Simulation [`crate::Model::state_partial_derivative`]).
    pub(super) fn state_directional_derivative(
        &mut self,
        unknowns: &[u32],
        (knowns, dv_known): (&[u32], &[f64]),
        dv_unknown: &mut [f64],
    ) -> Result<(), String> {
        let info = self.info;
        // unknowns: derivatives or outputs; knowns: states or inputs
        let role = |vr: u32, known: bool| -> Result<(), String> {
            let v = self.variable_of_type(vr, VarType::Real)?;
            let (fits, what, neither) = if known {
                let fits = info.is_state(vr) || v.causality == Causality::Input;
                (fits, "known", "a continuous state nor an input")
            } else {
                let fits = info.is_derivative(vr) || v.causality == Causality::Output;
                (fits, "unknown", "a state derivative nor an output")
            };
            match fits {
                true => Ok(()),
                false => Err(format!(
                    "{what} {} (value reference {vr}) is neither {neither}",
                    v.name
                )),
            }
        };
        unknowns.iter().try_for_each(|&u| role(u, false))?;
        knowns.iter().try_for_each(|&k| role(k, true))?;
        if let Some((&k, dv)) = knowns.iter().zip(dv_known).find(|(_, dv)| !dv.is_finite()) {
            let name = self.info.variables[k as usize].name;
            return Err(format!(
                "seed dvKnown for {name} must be finite but was {dv}"
            ));
        }
        self.ensure_initialized()?;
        let values = &self.values;
        let name = |vr: u32| info.variables[vr as usize].name;
        let partial = |u: u32, k: u32| -> Result<f64, String> {
            match self.model.ode() {
                Some(ode) => ode.partial_derivative(values, u, k).ok_or_else(|| {
                    format!(
                        "the partial derivative of {} with respect to {} is not available",
                        name(u),
                        name(k)
                    )
                }),
                None => self.model.state_partial_derivative(values, u, k),
            }
        };
        for (out, &u) in dv_unknown.iter_mut().zip(unknowns) {
            // Σ ∂u/∂k·dv_k over the seeds that move (an infinite partial
            // times a zero seed would be NaN)
            *out = knowns
                .iter()
                .zip(dv_known)
                .filter(|(_, dv)| **dv != 0.0)
                .try_fold(0.0, |acc, (&k, &dv)| {
                    Ok::<_, String>(acc + partial(u, k)? * dv)
                })?;
        }
        self.check_finite(unknowns, dv_unknown, "the directional derivative of ")
    }
}
