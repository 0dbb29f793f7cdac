//! One FMU instance: the FMI 2.0 CS semantics in safe Rust. Every method
//! returns `Result`; the message names the problem and the value, and the C
//! edge (`exports`) prefixes the function name and logs it.
//!
//! Errors caused by the caller's arguments (an unknown value reference, NaN,
//! a wrong communication point, …) change nothing: the instance stays in its
//! state and can be used further. Only a failure inside a model step moves it
//! to `Error`, and a panic to `Fatal`.

use crate::ffi::fmi2Status;
use crate::logger::Logger;
use crate::model::Model;
use crate::serialize::Snapshot;
use crate::state_machine::State;
use crate::values::Indices;
use crate::variables::{Causality, ModelInfo, VarType, Variable};
use crate::Values;

mod model_exchange;
mod switches;

pub use switches::RESOLUTION as SWITCH_RESOLUTION;

/// Relative tolerance on communication points (time is taken from the
/// master at every step, never summed inside the FMU).
const TIME_TOLERANCE: f64 = 1e-9;
/// Relative size of finite-difference perturbations, times the larger of
/// |u| and the input's nominal value.
const FD_RELATIVE_STEP: f64 = 1e-6;

pub struct Instance {
    pub info: &'static ModelInfo,
    pub name: String,
    pub logger: Logger,
    pub state: State,
    model: Box<dyn Model>,
    values: Values,
    /// `du/dt` per value reference (non-zero for inputs only).
    slopes: Vec<f64>,
    /// Whether a slope may be non-zero (false: every input is held over the
    /// next step, and the step need not look at the slopes).
    sloped: bool,
    /// Value references of the inputs, the values a step changes (by
    /// their slopes).
    inputs: Indices,
    /// Bumped whenever a value other than an input may have changed (a
    /// parameter set, a reset, a state with other parameters restored): a
    /// snapshot taken at the same version has the same parameters.
    parameters_version: u64,
    outputs_dirty: bool,
    initialized: bool,
    pub time: f64,
    start_time: f64,
    stop_time: Option<f64>,
    /// The last step, kept for directional derivatives: the state, inputs
    /// and slopes before it, and its length. Valid until an input changes.
    replay: Replay,
    scratch: Scratch,
    /// FMU states handed out by `fmi2GetFMUstate` / `fmi2DeSerializeFMUstate`,
    /// by address, so that a pointer we did not create is refused.
    /// (A short list: a master keeps one or two. Boxed: the address of the
    /// box is the handle given out, and must not move with the list.)
    #[allow(clippy::vec_box)]
    saved_states: Vec<Box<Snapshot>>,
    /// The model state saved after the last step (checked for finiteness
    /// there), unless the model answers [`Model::state_is_finite`] itself;
    /// while [`Instance::step_state_current`] it is also the state
    /// the next step starts from, which that step keeps for its replay
    /// without asking the model again.
    step_state: Vec<f64>,
    /// Whether the model state is still the one in `step_state`: cleared by
    /// everything that gives the model another state (initialization, a
    /// reset, a restored FMU state).
    step_state_current: bool,
    /// The model's [`Model::needs_step_replay`], asked once (a property of
    /// the model, not of its state).
    needs_step_replay: bool,
    /// The model's [`Model::state_len`], asked again after each
    /// `initialize` (a property of the model and its parameters), or
    /// [`VEC_STATE`] ([`save_model_state`]).
    state_len: usize,
    /// The model's [`Model::supplies_partial_derivatives`], asked once.
    supplies_partial_derivatives: bool,
    /// The model's [`Model::supplies_step_derivatives`], asked once.
    supplies_step_derivatives: bool,
    /// Per value reference, what the hot paths check ([`flag`]): the type,
    /// the causality, when it may be set. One byte per variable, so that a
    /// get or set validates its value references with one load each; the
    /// messages still come from the table.
    flags: Vec<u8>,
    /// Per value reference, the scale of a finite-difference perturbation
    /// besides |u|: the variable's nominal value, else 1 (from the table,
    /// once; a NaN nominal, which `f64::max` would pass over, as -inf,
    /// which `>` passes over).
    nominals: Box<[f64]>,
    /// The last list of value references [`Instance::get`] found valid for
    /// type `.0`, and whether it holds an output (`.2`): a master reads the
    /// same list at every step, and comparing it is cheaper than checking
    /// it again (lists of [`Instance::REMEMBERED`] or more values).
    checked_get: (VarType, Vec<u32>, bool),
    /// Instantiated for Model Exchange (`fmi2ModelExchange`): its states
    /// are those of the Model Exchange machine, its model answers
    /// [`Model::ode`].
    model_exchange: bool,
    /// Created through the FMI 3.0 interface (`fmi3Instantiate…`): its
    /// messages name FMI 3.0's functions and states.
    pub fmi3: bool,
    /// FMI 3.0 Co-Simulation: the importer's intermediate-update callback,
    /// to which each stick/slip switch inside a step is reported
    /// ([`Instance::do_step_locating_switches`]).
    pub intermediate_update: Option<crate::fmi3::exports::IntermediateUpdate>,
    /// FMI 3.0: the variables as FMI 3.0 declares them, the table's
    /// numbered scalars as arrays ([`crate::fmi3::arrays`]).
    pub fmi3_layout: Option<&'static crate::fmi3::arrays::Layout>,
}

/// Bits of [`Instance::flags`].
mod flag {
    pub const REAL: u8 = 1 << 0;
    pub const INTEGER: u8 = 1 << 1;
    pub const BOOLEAN: u8 = 1 << 2;
    pub const OUTPUT: u8 = 1 << 3;
    pub const INPUT: u8 = 1 << 4;
    /// May be set before and in initialization mode.
    pub const SETTABLE_BEFORE_INIT: u8 = 1 << 5;
    /// May be set in step mode.
    pub const SETTABLE_IN_STEP: u8 = 1 << 6;
    /// Bit 7 of a settable variable: a value set is checked beyond
    /// finiteness, against the declared `min`/`max` of the variable, or
    /// by the model ([`crate::Model::input_checked`]) for an input. Tested
    /// only once the byte has the settable bits, which an output's never
    /// has.
    pub const CHECKED: u8 = 1 << 7;
    /// Bit 7 of an output: it has no direct feedthrough (no `depends_on`),
    /// a function of the model state alone, which [`Instance::get`] of it
    /// alone computes by itself, cheaper than every output. Tested only
    /// with [`OUTPUT`].
    ///
    /// [`Instance::get`]: crate::instance::Instance::get
    pub const STATE_OUTPUT: u8 = 1 << 7;
}

/// The type bit of `t` in [`Instance::flags`].
fn type_flag(t: VarType) -> u8 {
    match t {
        VarType::Real => flag::REAL,
        VarType::Integer => flag::INTEGER,
        VarType::Boolean => flag::BOOLEAN,
    }
}

fn flags_of(v: &Variable) -> u8 {
    if v.causality == Causality::Local {
        // A state derivative or a local state, computed when read: without
        // its type bit, so that the hot paths send it to the checks, which
        // bring the outputs (with the local states) and the derivatives up
        // to date ([`Instance::refresh_derivatives`]); never settable.
        return 0;
    }
    let mut f = type_flag(v.var_type);
    if v.causality == Causality::Output {
        f |= flag::OUTPUT;
        if v.depends_on.is_empty() {
            f |= flag::STATE_OUTPUT;
        }
    }
    if v.causality == Causality::Input {
        f |= flag::INPUT;
    }
    if v.settable_before_init() {
        f |= flag::SETTABLE_BEFORE_INIT;
    }
    if v.settable_in_step_mode() {
        f |= flag::SETTABLE_IN_STEP;
    }
    f
}

/// Buffers of [`Instance::directional_derivative`], kept between calls.
struct Scratch {
    /// The values of the evaluations (made with the instance).
    values: Values,
    /// The parameter version `values` holds the parameters of.
    parameters_version: u64,
    /// A copy of the model, made after its last `initialize`, on which
    /// the last step is replayed: the instance's own model keeps its state,
    /// so it need not be saved and put back around the replays. (The copy
    /// starts each replay with `restore_state`, which restores the complete
    /// state; `initialize` drops it, as the parameters may have changed.)
    model: Option<Box<dyn Model>>,
    /// The slopes of a replayed step, one per variable as
    /// [`Instance::slopes`] (all zero between calls).
    slopes: Vec<f64>,
}

struct Replay {
    valid: bool,
    model_state: Vec<f64>,
    /// Value and slope of each of [`Instance::inputs`] before the step
    /// (nothing else changes in a step: a parameter set since invalidates
    /// the replay), unless `held`.
    inputs: Vec<f64>,
    slopes: Vec<f64>,
    /// Every input was held over the step (no slope): the inputs before it
    /// are the inputs now (setting another value invalidates the replay),
    /// and `inputs`, `slopes` were not written.
    held: bool,
    h: f64,
}

fn type_name(t: VarType) -> &'static str {
    match t {
        VarType::Real => "Real",
        VarType::Integer => "Integer",
        VarType::Boolean => "Boolean",
    }
}

impl Instance {
    pub fn new(
        info: &'static ModelInfo,
        model: Box<dyn Model>,
        name: &str,
        logger: Logger,
    ) -> Self {
        let values = Values::from_start(info.variables);
        let n = values.len();
        let flags = info
            .variables
            .iter()
            .map(|v| {
                let settable = matches!(v.causality, Causality::Input | Causality::Parameter);
                let bounded = settable && (v.min.is_some() || v.max.is_some());
                let checked =
                    bounded || (v.causality == Causality::Input && model.input_checked(v.vr));
                flags_of(v) | if checked { flag::CHECKED } else { 0 }
            })
            .collect();
        let needs_step_replay = model.needs_step_replay();
        let state_len = model.state_len().unwrap_or(VEC_STATE);
        let supplies_partial_derivatives = model.supplies_partial_derivatives();
        let supplies_step_derivatives = model.supplies_step_derivatives();
        let inputs: Vec<u32> = info
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Input)
            .map(|v| v.vr)
            .collect();
        let nominals = info
            .variables
            .iter()
            .map(|v| match v.nominal {
                Some(n) if n.is_nan() => f64::NEG_INFINITY,
                n => n.unwrap_or(1.0),
            })
            .collect();
        let scratch_values = values.clone();
        Instance {
            info,
            name: name.to_string(),
            logger,
            state: State::Instantiated,
            model,
            values,
            slopes: vec![0.0; n],
            sloped: false,
            outputs_dirty: true,
            initialized: false,
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            replay: Replay {
                valid: false,
                model_state: Vec::new(),
                inputs: vec![0.0; inputs.len()],
                slopes: vec![0.0; inputs.len()],
                held: false,
                h: 0.0,
            },
            inputs: Indices::new(inputs),
            parameters_version: 0,
            scratch: Scratch {
                values: scratch_values,
                parameters_version: u64::MAX,
                model: None,
                slopes: vec![0.0; n],
            },
            saved_states: Vec::new(),
            step_state: Vec::new(),
            step_state_current: false,
            needs_step_replay,
            state_len,
            supplies_partial_derivatives,
            supplies_step_derivatives,
            flags,
            nominals,
            checked_get: (VarType::Real, Vec::new(), false),
            model_exchange: false,
            fmi3: false,
            intermediate_update: None,
            fmi3_layout: None,
        }
    }

    /// The name of the instance's state in the terms of the interface it
    /// was created through (FMI 3.0 calls Co-Simulation's `StepComplete`
    /// `StepMode`).
    pub fn state_name(&self) -> &'static str {
        match self.state {
            State::StepComplete if self.fmi3 => "StepMode",
            s => s.name(),
        }
    }

    fn variable(&self, vr: u32) -> Result<&'static Variable, String> {
        self.info.variable(vr).ok_or_else(|| {
            format!(
                "unknown value reference {vr} ({} has value references 0..={})",
                self.info.model_name,
                self.info.variables.len().saturating_sub(1)
            )
        })
    }

    fn variable_of_type(&self, vr: u32, t: VarType) -> Result<&'static Variable, String> {
        let v = self.variable(vr)?;
        if v.var_type != t {
            return Err(format!(
                "value reference {vr} ({}) is a {} variable, not {}",
                v.name,
                type_name(v.var_type),
                type_name(t)
            ));
        }
        Ok(v)
    }

    // ---- set-up ---------------------------------------------------------

    pub fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Result<(), String> {
        if !start.is_finite() {
            return Err(format!("startTime must be finite but was {start}"));
        }
        if let Some(stop) = stop {
            if !(stop.is_finite() && stop >= start) {
                return Err(format!(
                    "stopTime must be finite and >= startTime = {start} but was {stop}"
                ));
            }
        }
        self.start_time = start;
        self.time = start;
        self.stop_time = stop;
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> Result<(), String> {
        self.state = if self.model_exchange {
            State::MeInitializationMode
        } else {
            State::InitializationMode
        };
        self.time = self.start_time;
        self.outputs_dirty = true;
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> Result<(), String> {
        self.step_state_current = false;
        self.initialize_model()?;
        self.model.compute_outputs(&mut self.values);
        self.outputs_dirty = false;
        self.initialized = true;
        self.replay.valid = false;
        // (Model Exchange: the initial event iteration follows, FMI 2.0.4
        // §3.2.3)
        self.state = if self.model_exchange {
            State::EventMode
        } else {
            State::StepComplete
        };
        Ok(())
    }

    pub fn terminate(&mut self) -> Result<(), String> {
        self.state = if self.model_exchange {
            State::MeTerminated
        } else {
            State::Terminated
        };
        Ok(())
    }

    pub fn reset(&mut self) -> Result<(), String> {
        self.step_state_current = false;
        self.values = Values::from_start(self.info.variables);
        self.parameters_version += 1;
        self.slopes.iter_mut().for_each(|s| *s = 0.0);
        self.sloped = false;
        self.outputs_dirty = true;
        self.initialized = false;
        self.replay.valid = false;
        self.time = 0.0;
        self.start_time = 0.0;
        self.stop_time = None;
        self.state = if self.model_exchange {
            State::MeInstantiated
        } else {
            State::Instantiated
        };
        Ok(())
    }

    /// [`Model::initialize`] with the current values; the replay copy of the
    /// model ([`Scratch::model`]) is dropped with the old parameters.
    fn initialize_model(&mut self) -> Result<(), String> {
        self.scratch.model = None;
        let result = self.model.initialize(&self.values);
        // (asked whatever the outcome: the model has the state length of
        // the parameters it now holds)
        self.state_len = self.model.state_len().unwrap_or(VEC_STATE);
        result
    }

    /// Recompute the outputs if an input or parameter changed since the last
    /// computation. In initialization mode this validates the parameters.
    #[inline(always)]
    fn ensure_outputs(&mut self) -> Result<(), String> {
        if self.outputs_dirty {
            if !self.initialized {
                self.initialize_for_outputs()?;
            }
            self.model.compute_outputs(&mut self.values);
            self.outputs_dirty = false;
        }
        Ok(())
    }

    /// The initialization part of [`Instance::ensure_outputs`] (before
    /// `fmi2ExitInitializationMode` only).
    #[cold]
    #[inline(never)]
    fn initialize_for_outputs(&mut self) -> Result<(), String> {
        self.step_state_current = false;
        self.initialize_model()
    }

    // ---- get / set ------------------------------------------------------

    /// Read values of type `t` into `out` (already checked: same length).
    /// Inlined into `fmi2GetReal` (one function frame less per call); the
    /// check of a list of value references is out of line.
    #[inline(always)]
    pub fn get(&mut self, t: VarType, vrs: &[u32], out: &mut [f64]) -> Result<(), String> {
        let outputs = if let [vr] = vrs {
            // one value (a master reading a connected output)
            let f = self.flags.get(*vr as usize).copied().unwrap_or(0);
            if f & type_flag(t) == 0 {
                self.variable_of_type(*vr, t)?;
                // of type `t` but without its bit: a state derivative or
                // a local state
                self.refresh_derivatives()?;
            }
            let state_output = flag::OUTPUT | flag::STATE_OUTPUT;
            if f & state_output == state_output && self.outputs_dirty && self.initialized {
                // An output of the state alone (a velocity a strongly
                // coupled master reads after each trial step): computed by
                // itself, the other outputs stay to be computed when read.
                self.model.compute_outputs_of(&mut self.values, vrs);
                false
            } else {
                f & flag::OUTPUT != 0
            }
        } else if vrs.len() >= Self::REMEMBERED
            && self.checked_get.0 == t
            && same_list(&self.checked_get.1, vrs)
        {
            self.checked_get.2
        } else {
            self.check_get(t, vrs)?
        };
        if outputs {
            self.ensure_outputs()?;
        }
        let data = self.values.as_slice();
        debug_assert_eq!(data.len(), self.flags.len());
        // SAFETY: every vr was found in `flags` above (a known value
        // reference: `flags.get(vr)` had the type bit, and a list in
        // `checked_get` passed `check_get`), and `values` has one entry
        // per variable, as `flags` (both built from `info.variables`;
        // reset and restore keep the length).
        if unsafe { gather(data, vrs, out) } {
            Ok(())
        } else {
            self.check_finite(vrs, out, "")
        }
    }

    /// [`Instance::get`] of one value in the case that runs none of the
    /// model's code: a known variable of type `t`, not an output or with
    /// the outputs up to date. Its value then; else `None`, nothing
    /// changed, and the caller takes `get`, which checks, computes and
    /// reports. Calls nothing and cannot panic (the index is checked), so
    /// that `fmi2GetBoolean` and `fmi2GetInteger` can take it before their
    /// `catch_unwind`.
    #[inline(always)]
    pub fn get_plain(&self, t: VarType, vr: u32) -> Option<f64> {
        let f = self.flags.get(vr as usize).copied().unwrap_or(0);
        if f & type_flag(t) == 0 || (f & flag::OUTPUT != 0 && self.outputs_dirty) {
            return None;
        }
        // (`values` has one entry per variable, as `flags`)
        let x = self.values.as_slice().get(vr as usize).copied()?;
        x.is_finite().then_some(x)
    }

    /// Lists at least this long that [`Instance::get`] found valid are
    /// remembered: comparing is cheaper than checking again.
    const REMEMBERED: usize = 2;

    /// Check a list of value references of [`Instance::get`] (known, of type
    /// `t`) and remember it; whether it holds an output. A list with a
    /// state derivative has the derivatives brought up to date here, and is
    /// not remembered (it comes here each time).
    #[inline(never)]
    fn check_get(&mut self, t: VarType, vrs: &[u32]) -> Result<bool, String> {
        // One flag byte per value reference: known, of type `t`, an output?
        let want = type_flag(t);
        let mut wrong = false;
        let mut flags = 0;
        for &vr in vrs {
            let f = self.flags.get(vr as usize).copied().unwrap_or(0);
            wrong |= f & want == 0;
            flags |= f;
        }
        if wrong {
            for vr in vrs {
                self.variable_of_type(*vr, t)?;
            }
            // every one of type `t`, but one without its bit: a derivative
            // or a local state
            self.refresh_derivatives()?;
            return Ok(true);
        }
        let outputs = flags & flag::OUTPUT != 0;
        if vrs.len() >= Self::REMEMBERED {
            let remembered = &mut self.checked_get;
            remembered.0 = t;
            remembered.1.clear();
            remembered.1.extend_from_slice(vrs);
            remembered.2 = outputs;
        }
        Ok(outputs)
    }

    /// The outputs (with the local states) and the `der(…)` variables
    /// brought up to date, for a read of a derivative or a local state
    /// (which [`Instance::get`] then reads as any value).
    #[cold]
    #[inline(never)]
    fn refresh_derivatives(&mut self) -> Result<(), String> {
        self.ensure_outputs()?;
        self.compute_derivatives();
        Ok(())
    }

    /// The values of the `der(…)` variables ([`Model::derivatives`]) at the
    /// current state and inputs (the model initialized).
    fn compute_derivatives(&mut self) {
        let states = self.info.continuous_states();
        if states.is_empty() {
            return;
        }
        let mut dx = vec![0.0; states.len()];
        self.model.derivatives(&self.values, &mut dx);
        for (s, d) in states.iter().zip(dx) {
            self.values.set(s.derivative, d);
        }
    }

    /// Values handed to the importer with `fmi2OK` are never NaN or
    /// infinite: parameters and inputs are each finite, but together they
    /// may overflow (a stiffness of 1e300 times a displacement). Such a
    /// result is refused with `fmi2Error`, naming the variable.
    fn check_finite(&self, vrs: &[u32], values: &[f64], what: &str) -> Result<(), String> {
        match vrs.iter().zip(values).find(|(_, v)| !v.is_finite()) {
            None => Ok(()),
            Some((vr, v)) => Err(format!(
                "{what}{} (value reference {vr}) evaluates to {v}: the parameters or inputs are out of the model's range",
                self.info.variables[*vr as usize].name
            )),
        }
    }

    /// Check, then set, values of type `t`: all or nothing.
    #[inline]
    pub fn set(&mut self, t: VarType, vrs: &[u32], values: &[f64]) -> Result<(), String> {
        if let ([vr], [value]) = (vrs, values) {
            return self.set_one(t, *vr, *value);
        }
        self.set_many(t, vrs, values)
    }

    /// Whether the instance is in step mode, and the flags a variable of
    /// type `t` needs to be set now.
    #[inline]
    fn settable(&self, t: VarType) -> (bool, u8) {
        // (the state table allows a set in these states and in step,
        // event and continuous-time mode only)
        let in_step_mode = self.state as u32 & crate::state_machine::BEFORE_INITIALIZATION == 0;
        let when = if in_step_mode {
            flag::SETTABLE_IN_STEP
        } else {
            flag::SETTABLE_BEFORE_INIT
        };
        (in_step_mode, type_flag(t) | when)
    }

    /// [`Instance::set`] of one value (a master sets an input per
    /// connection): the same checks and effects, without the loops.
    /// Inlined into `fmi2SetReal`: one function frame less per call.
    #[inline(always)]
    fn set_one(&mut self, t: VarType, vr: u32, value: f64) -> Result<(), String> {
        let (in_step_mode, want) = self.settable(t);
        let f = self.flags.get(vr as usize).copied().unwrap_or(0);
        if f & want != want || !value.is_finite() {
            self.check_set(t, &[vr], &[value], in_step_mode)?;
        } else if f & flag::CHECKED != 0 {
            self.check_value(vr, value)?;
        }
        let stored = self.store_one(f, vr, value);
        // (a value reference that passed the checks has a value: `flags`
        // and `values` have one entry per variable)
        assert!(stored, "value reference {vr} has no value");
        Ok(())
    }

    /// The effects of [`Instance::set`] of variable `vr`, of flag byte `f`,
    /// to `value`, which passed every check; `false`, and nothing changed,
    /// if `vr` has no value.
    #[inline(always)]
    fn store_one(&mut self, f: u8, vr: u32, value: f64) -> bool {
        if vr as usize >= self.values.len() {
            return false;
        }
        // SAFETY: just checked
        unsafe { self.store_unchecked(f, vr, value) };
        true
    }

    /// [`Instance::store_one`] without the check of `vr`.
    ///
    /// # Safety
    /// `vr` has a value: it is below `values.len()`.
    #[inline(always)]
    unsafe fn store_unchecked(&mut self, f: u8, vr: u32, value: f64) {
        // SAFETY: the caller's
        let slot = unsafe { self.values.as_mut_slice().get_unchecked_mut(vr as usize) };
        let input = f & flag::INPUT != 0;
        if !input || *slot != value {
            self.replay.valid = false;
        }
        if !input {
            self.parameters_version += 1;
        }
        *slot = value;
        self.outputs_dirty = true;
    }

    /// [`Instance::set`] of one Real value in the step loop's case only: a
    /// known variable settable now, a finite value, no check of the
    /// model's to ask. Then the effects of `set` and `true`; else `false`,
    /// nothing changed, and the caller takes `set`, which checks again and
    /// reports. Calls nothing and cannot panic (every index is checked), so
    /// that `fmi2SetReal` can take it before its `catch_unwind`.
    #[inline(always)]
    pub fn set_real_plain(&mut self, vr: u32, value: f64) -> bool {
        let (_, want) = self.settable(VarType::Real);
        let f = self.flags.get(vr as usize).copied().unwrap_or(0);
        // (bit 7 is CHECKED in a settable variable's byte)
        if f & want != want || f & flag::CHECKED != 0 || !value.is_finite() {
            return false;
        }
        debug_assert_eq!(self.values.len(), self.flags.len());
        // SAFETY: `f` is not 0, so `vr` is a known value reference (found
        // in `flags`), and `values` has one entry per variable, as `flags`
        // (both built from `info.variables`; reset and restore keep the
        // length)
        unsafe { self.store_unchecked(f, vr, value) };
        true
    }

    #[inline(never)]
    fn set_many(&mut self, t: VarType, vrs: &[u32], values: &[f64]) -> Result<(), String> {
        // The usual case in one pass over the flag bytes: known, of type
        // `t`, settable now, finite; the inputs the model checks get its
        // own check.
        let (in_step_mode, want) = self.settable(t);
        let mut fine = true;
        let mut any = 0;
        for (&vr, value) in vrs.iter().zip(values) {
            let f = self.flags.get(vr as usize).copied().unwrap_or(0);
            fine &= f & want == want && value.is_finite();
            any |= f;
        }
        if !fine {
            self.check_set(t, vrs, values, in_step_mode)?;
        } else if any & flag::CHECKED != 0 {
            for (&vr, &value) in vrs.iter().zip(values) {
                if self.flags[vr as usize] & flag::CHECKED != 0 {
                    self.check_value(vr, value)?;
                }
            }
        }
        let mut invalidates = false;
        for (&vr, &value) in vrs.iter().zip(values) {
            let input = self.flags[vr as usize] & flag::INPUT != 0;
            invalidates |= !input || self.values.real(vr) != value;
            if !input {
                self.parameters_version += 1;
            }
            self.values.set(vr, value);
        }
        if invalidates {
            self.replay.valid = false;
        }
        if !vrs.is_empty() {
            self.outputs_dirty = true;
        }
        Ok(())
    }

    /// The model's check of input `vr` = `value`, as an FMI message.
    #[inline]
    /// The checks of a finite value set into variable `vr` beyond its
    /// type and causality: the declared `min`/`max` of the model
    /// description, for every parameter and input whether or not the
    /// model's options use it (a value outside them is refused when set,
    /// not when an option that reads it is switched on later); then the
    /// model's own check of an input.
    fn check_value(&self, vr: u32, value: f64) -> Result<(), String> {
        let v = &self.info.variables[vr as usize];
        if let Some(min) = v.min.filter(|min| value < *min) {
            return Err(self.input_refused(vr, value, format!("below its declared min = {min}")));
        }
        if let Some(max) = v.max.filter(|max| value > *max) {
            return Err(self.input_refused(vr, value, format!("above its declared max = {max}")));
        }
        if v.causality != Causality::Input {
            return Ok(());
        }
        match self.model.check_input(vr, value) {
            Ok(()) => Ok(()),
            Err(e) => Err(self.input_refused(vr, value, e)),
        }
    }

    #[cold]
    #[inline(never)]
    fn input_refused(&self, vr: u32, value: f64, why: String) -> String {
        format!(
            "{} (value reference {vr}) = {value}: {why}",
            self.info.variables[vr as usize].name
        )
    }

    /// Every check of [`Instance::set`], value by value, with the message
    /// of the first that fails.
    #[cold]
    #[inline(never)]
    fn check_set(
        &self,
        t: VarType,
        vrs: &[u32],
        values: &[f64],
        in_step_mode: bool,
    ) -> Result<(), String> {
        for (vr, value) in vrs.iter().zip(values) {
            let v = self.variable_of_type(*vr, t)?;
            let allowed = if in_step_mode {
                v.settable_in_step_mode()
            } else {
                v.settable_before_init()
            };
            if !allowed {
                let what = match v.causality {
                    Causality::Output => "an output".to_string(),
                    Causality::Parameter => {
                        "a fixed parameter, which cannot change after initialization".to_string()
                    }
                    _ => format!("{:?}", v.causality).to_lowercase(),
                };
                return Err(format!(
                    "cannot set {} (value reference {vr}) in state {}: it is {what}",
                    v.name,
                    self.state.name()
                ));
            }
            if !value.is_finite() {
                return Err(format!(
                    "{} (value reference {vr}) must be finite but was {value}",
                    v.name
                ));
            }
            if matches!(v.causality, Causality::Input | Causality::Parameter) {
                self.check_value(*vr, *value)?;
            }
        }
        Ok(())
    }

    pub fn set_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        slopes: &[f64],
    ) -> Result<(), String> {
        for ((vr, order), slope) in vrs.iter().zip(orders).zip(slopes) {
            let v = self.variable_of_type(*vr, VarType::Real)?;
            if v.causality != Causality::Input {
                return Err(format!("{} (value reference {vr}) is not an input", v.name));
            }
            if *order != 1 {
                return Err(format!(
                    "derivative order {order} for {} is not supported (only order 1: inputs are interpolated linearly)",
                    v.name
                ));
            }
            if !slope.is_finite() {
                return Err(format!(
                    "derivative of {} must be finite but was {slope}",
                    v.name
                ));
            }
        }
        for (vr, slope) in vrs.iter().zip(slopes) {
            self.slopes[*vr as usize] = *slope;
            self.sloped |= *slope != 0.0;
        }
        if !vrs.is_empty() {
            self.replay.valid = false;
        }
        Ok(())
    }

    pub fn get_output_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        out: &mut [f64],
    ) -> Result<(), String> {
        let max_order = self.info.capabilities.max_output_derivative_order as i32;
        for (vr, order) in vrs.iter().zip(orders) {
            let v = self.variable_of_type(*vr, VarType::Real)?;
            if v.causality != Causality::Output {
                return Err(format!(
                    "{} (value reference {vr}) is not an output",
                    v.name
                ));
            }
            if *order < 1 || *order > max_order {
                return Err(format!(
                    "derivative order {order} for {} is outside 1..={max_order}",
                    v.name
                ));
            }
        }
        self.ensure_outputs()?;
        for (o, vr) in out.iter_mut().zip(vrs) {
            *o = self
                .model
                .output_derivative(&self.values, &self.slopes, *vr)
                .ok_or_else(|| {
                    format!(
                        "{} has no time derivative in this model",
                        self.info.variables[*vr as usize].name
                    )
                })?;
        }
        self.check_finite(vrs, out, "the derivative of ")
    }

    // ---- stepping -------------------------------------------------------

    #[inline]
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<fmi2Status, String> {
        // h > 0 and finite, in one comparison: the bits of the positive
        // finite doubles, from the least subnormal to f64::MAX, are the
        // integers 1 ..= f64::MAX.to_bits(), in order; 0 is 0, and a sign
        // bit (a negative h or -0), an infinity or a NaN make them larger
        if h.to_bits().wrapping_sub(1) >= f64::MAX.to_bits() {
            return Err(step_size_refused(h));
        }
        // self.time is finite
        let scale = self.time.abs();
        let tolerance = TIME_TOLERANCE * if scale > 1.0 { scale } else { 1.0 };
        // (a NaN t is not on time either)
        let on_time = (t - self.time).abs() <= tolerance;
        if !on_time {
            return Err(self.communication_point_refused(t));
        }
        // FMI 2.0 §2.1.6: with a stop time defined, a step that would
        // compute past it is refused (nothing changes)
        if let Some(stop) = self.stop_time {
            if t + h > stop + TIME_TOLERANCE * stop.abs().max(1.0) {
                return Err(format!(
                    "the step from {t} by {h} ends at {}, past stopTime = {stop} defined by {} (an FMU must not compute past it: FMI 2.0 section 2.1.6, FMI 3.0 section 2.3.2)",
                    t + h,
                    if self.fmi3 { "fmi3EnterInitializationMode" } else { "fmi2SetupExperiment" }
                ));
            }
        }
        let replay = self.needs_step_replay;
        if replay {
            if self.step_state_current {
                // the state after the last step is the state now
                std::mem::swap(&mut self.replay.model_state, &mut self.step_state);
            } else {
                save_model_state(&*self.model, self.state_len, &mut self.replay.model_state);
            }
            self.replay.held = !self.sloped;
            if self.sloped {
                for (k, &vr) in self.inputs.iter().enumerate() {
                    self.replay.inputs[k] = self.values.real(vr);
                    self.replay.slopes[k] = self.slopes[vr as usize];
                }
            }
            self.replay.h = h;
        }
        self.step_state_current = false;
        if let Err(e) = self.model.do_step(&self.values, &self.slopes, h) {
            self.state = State::Error;
            return Err(step_failed(t, h, e));
        }
        // A step that overflowed (finite but extreme parameters or inputs)
        // is a failed step too: the state is no longer meaningful. A model
        // that can tell says so without a copy of its state; else the state
        // is saved and scanned (and kept: the next step's replay starts
        // from it).
        match self.model.state_is_finite() {
            Some(true) => {}
            Some(false) => {
                self.state = State::Error;
                return Err(self.state_overflowed(t, h));
            }
            None => {
                save_model_state(&*self.model, self.state_len, &mut self.step_state);
                if !all_finite(&self.step_state) {
                    self.state = State::Error;
                    return Err(self.state_overflowed(t, h));
                }
                self.step_state_current = true;
            }
        }
        // Inputs as the FMU saw them at the end of the step (u + du·h); the
        // slopes apply to one step only.
        if self.sloped {
            advance_inputs(&self.inputs, &mut self.values, &mut self.slopes, h);
            self.sloped = false;
        }
        self.replay.valid = replay;
        self.time = t + h;
        self.outputs_dirty = true;
        Ok(fmi2Status::fmi2OK)
    }

    /// Why [`Instance::do_step`] refused `currentCommunicationPoint` `t`.
    #[cold]
    #[inline(never)]
    fn communication_point_refused(&self, t: f64) -> String {
        format!(
            "expected currentCommunicationPoint = {} but was {t} (difference {:e})",
            self.time,
            t - self.time
        )
    }

    /// Why the step from `t` over `h` failed although the model accepted
    /// it: its state is no longer finite.
    #[cold]
    #[inline(never)]
    fn state_overflowed(&self, t: f64, h: f64) -> String {
        let mut state = Vec::new();
        save_model_state(&*self.model, self.state_len, &mut state);
        let x = state.iter().find(|x| !x.is_finite()).copied();
        format!(
            "step from t = {t} over h = {h} failed: the model state became {}: the parameters or inputs are out of the model's range",
            x.unwrap_or(f64::NAN)
        )
    }

    // ---- directional derivatives ----------------------------------------

    /// `dv_unknown = J · dv_known` with J = ∂outputs/∂inputs.
    ///
    /// Right after `fmi2DoStep` (no input changed since) J is the
    /// sensitivity of the outputs at the new communication point to the
    /// inputs held over that step, state change included: what a strongly
    /// coupled master needs. Otherwise (before the first step, or after new
    /// inputs were set) it is the direct-feedthrough derivative at the
    /// current state. A model may supply J itself, at any time
    /// ([`Model::partial_derivative`]) or after a step with every input
    /// held ([`Model::step_partial_derivative`]); else it is obtained by
    /// central differences along `dv_known`, replaying the step from the
    /// saved pre-step state.
    #[inline(always)]
    pub fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<(), String> {
        if let Some(result) = self.held_step_one(unknowns, knowns, dv_known, dv_unknown) {
            return result;
        }
        self.directional_general(unknowns, knowns, dv_known, dv_unknown)
    }

    /// The perturbation ε along a seed `dv ≠ 0` of input `k` that moves the
    /// input by [`FD_RELATIVE_STEP`] of its scale max(|u|, nominal): what
    /// the central differences use, and the half-width `ε·|dv|` a model's
    /// step sensitivity is asked over. (`max` as a comparison: |u| is
    /// finite, a NaN nominal is -inf in `nominals`, so ε is never NaN.)
    #[inline(always)]
    fn perturbation(&self, k: u32, dv: f64) -> f64 {
        let (u, nominal) = (self.values.real(k).abs(), self.nominals[k as usize]);
        let scale = if u > nominal { u } else { nominal };
        FD_RELATIVE_STEP * scale / dv.abs()
    }

    /// [`Instance::directional_derivative`] in the case of a strongly
    /// coupled master, one output by one input with a non-zero seed right
    /// after a step that held every input, from the model's step
    /// sensitivity: the checks and the arithmetic of
    /// [`Instance::directional_general`] for that case (the same value
    /// reference checks through the flag bytes, the same perturbation `ε`,
    /// the same sum, the same finiteness check and message), written out
    /// for one entry without the loops. `None` (nothing done, nothing
    /// written) in any other case, which the general path takes.
    #[inline(always)]
    fn held_step_one(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Option<Result<(), String>> {
        let ([u], [k], [dv], [out]) = (unknowns, knowns, dv_known, &mut *dv_unknown) else {
            return None;
        };
        let (u, k, dv) = (*u, *k, *dv);
        let fu = self.flags.get(u as usize).copied().unwrap_or(0);
        let fk = self.flags.get(k as usize).copied().unwrap_or(0);
        let (output, input) = (flag::REAL | flag::OUTPUT, flag::REAL | flag::INPUT);
        let usual = fu & output == output
            && fk & input == input
            && dv.is_finite()
            && dv != 0.0
            && self.initialized
            && !self.supplies_partial_derivatives
            && self.supplies_step_derivatives
            && self.replay.valid
            && self.replay.held;
        if !usual {
            return None;
        }
        // ε as the general path's loop makes it from its one known; an
        // infinite one (all zero there) is left to it
        let eps = self.perturbation(k, dv);
        if !eps.is_finite() {
            return None;
        }
        let spread = eps * dv.abs();
        let h = self.replay.h;
        let Some(d) = self
            .model
            .step_partial_derivative(&self.values, u, k, h, spread)
        else {
            // the model does not give it here: the differences, as the
            // general path after `step_analytic`
            return Some(self.differences_checked(unknowns, knowns, dv_known, eps, dv_unknown));
        };
        // (the general path's sum from 0: 0 + d·dv, which is +0 where d·dv is -0)
        let mut acc = 0.0;
        acc += d * dv;
        *out = acc;
        if acc.is_finite() {
            return Some(Ok(()));
        }
        Some(self.check_finite(unknowns, dv_unknown, "the directional derivative of "))
    }

    /// [`Instance::directional_derivative`] outside
    /// [`Instance::held_step_one`]'s case: the arguments checked, then
    /// [`Instance::directional_checked`] (out of line: the usual case's
    /// frame stays small).
    #[inline(never)]
    fn directional_general(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<(), String> {
        if self.model_exchange || self.asks_state_partials(unknowns, knowns) {
            return self.state_directional_derivative(unknowns, (knowns, dv_known), dv_unknown);
        }
        let is_parameter = |vr: &u32| {
            self.variable(*vr)
                .is_ok_and(|v| v.causality == Causality::Parameter)
        };
        if knowns.iter().any(is_parameter) {
            return self.parameter_directional(unknowns, knowns, dv_known, dv_unknown);
        }
        // the usual case through the flag bytes, else the messages below
        let has = |vr: u32, bits: u8| {
            self.flags
                .get(vr as usize)
                .is_some_and(|f| f & bits == bits)
        };
        let fine = unknowns
            .iter()
            .all(|&vr| has(vr, flag::REAL | flag::OUTPUT))
            && knowns
                .iter()
                .zip(dv_known)
                .all(|(&vr, dv)| has(vr, flag::REAL | flag::INPUT) && dv.is_finite());
        if !fine {
            self.check_directional(unknowns, knowns, dv_known, Causality::Input)?;
        }
        self.directional_checked(unknowns, knowns, dv_known, dv_unknown)
    }

    /// Whether a call of a Co-Simulation instance asks for the
    /// continuous-time partial derivatives of the states it lists
    /// ([`crate::ModelInfo::co_simulation_states`]): a state among the
    /// knowns or a state derivative among the unknowns. (Outputs by inputs
    /// alone stay the step sensitivity a strongly coupled master takes.)
    fn asks_state_partials(&self, unknowns: &[u32], knowns: &[u32]) -> bool {
        let info = self.info;
        !info.co_simulation_states.is_empty()
            && (knowns.iter().any(|&k| info.is_state(k))
                || unknowns.iter().any(|&u| info.is_derivative(u)))
    }

    /// [`Instance::directional_derivative`] with Real parameters as the
    /// knowns: `dv_unknown = Σ ∂output/∂parameter · seed`, the parameter
    /// sensitivities the model carries along its trajectory
    /// ([`crate::Model::parameter_sensitivity`]), after initialization.
    /// Inputs and parameters are not mixed in one call (a step
    /// sensitivity and a trajectory sensitivity are different things).
    #[inline(never)]
    fn parameter_directional(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<(), String> {
        self.check_directional(unknowns, knowns, dv_known, Causality::Parameter)?;
        if !self.initialized {
            return Err(
                "parameter sensitivities are available once the FMU is initialized (fmi2ExitInitializationMode)".into(),
            );
        }
        for (out, u) in dv_unknown.iter_mut().zip(unknowns) {
            let mut acc = 0.0;
            for (k, dv) in knowns.iter().zip(dv_known) {
                if *dv != 0.0 {
                    acc += self.model.parameter_sensitivity(&self.values, *u, *k)? * dv;
                }
            }
            *out = acc;
        }
        self.check_finite(unknowns, dv_unknown, "the directional derivative of ")
    }

    /// The checks of [`Instance::directional_derivative`], value by value,
    /// with the message of the first that fails: every unknown a Real
    /// output, every known a Real of causality `knowns_are` (inputs: the
    /// step sensitivity; parameters: the parameter sensitivity), every
    /// seed finite.
    fn check_directional(
        &self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        knowns_are: Causality,
    ) -> Result<(), String> {
        for vr in unknowns {
            let v = self.variable_of_type(*vr, VarType::Real)?;
            if v.causality != Causality::Output {
                return Err(format!(
                    "unknown {} (value reference {vr}) is not an output",
                    v.name
                ));
            }
        }
        for (vr, dv) in knowns.iter().zip(dv_known) {
            let v = self.variable_of_type(*vr, VarType::Real)?;
            if v.causality != knowns_are {
                let what = if knowns_are == Causality::Input {
                    "an input"
                } else {
                    "a parameter: the knowns of one call are all inputs (the step sensitivity) or all parameters (the parameter sensitivity)"
                };
                return Err(format!(
                    "known {} (value reference {vr}) is not {what}",
                    v.name
                ));
            }
            if !dv.is_finite() {
                return Err(format!(
                    "seed dvKnown for {} must be finite but was {dv}",
                    v.name
                ));
            }
        }
        Ok(())
    }

    /// [`Instance::directional_derivative`] once the arguments are checked.
    fn directional_checked(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> Result<(), String> {
        // Analytic where the model provides every entry (written as it
        // goes: the differences below overwrite every entry otherwise),
        // from the current values, outputs included.
        if self.supplies_partial_derivatives {
            self.ensure_outputs()?;
            if self.analytic(unknowns, knowns, dv_known, dv_unknown) {
                return self.check_finite(unknowns, dv_unknown, "the directional derivative of ");
            }
        }
        // The differences compute the outputs they need on a copy of the
        // values: the model needs only to be initialized (which, before
        // `fmi2ExitInitializationMode`, computing the outputs does).
        if !self.initialized {
            self.ensure_outputs()?;
        }

        // Perturbation ε along dv_known, sized so that no input moves by more
        // than FD_RELATIVE_STEP of its scale.
        let mut eps = f64::INFINITY;
        for (k, dv) in knowns.iter().zip(dv_known) {
            if *dv != 0.0 {
                let e = self.perturbation(*k, *dv);
                if e < eps {
                    eps = e;
                }
            }
        }
        if !eps.is_finite() {
            dv_unknown.iter_mut().for_each(|d| *d = 0.0);
            return Ok(());
        }
        // Right after a step with every input held, the model's own step
        // sensitivities where it gives every entry (written as it goes:
        // the differences below overwrite every entry otherwise).
        if self.supplies_step_derivatives
            && self.replay.valid
            && self.replay.held
            && self.step_analytic(unknowns, knowns, dv_known, eps, dv_unknown)
        {
            if all_finite(dv_unknown) {
                return Ok(());
            }
            return self.check_finite(unknowns, dv_unknown, "the directional derivative of ");
        }
        self.differences_checked(unknowns, knowns, dv_known, eps, dv_unknown)
    }

    /// [`Instance::central_differences`] with perturbation `eps` into
    /// `dv_unknown`, checked finite.
    #[inline(never)]
    fn differences_checked(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        eps: f64,
        dv_unknown: &mut [f64],
    ) -> Result<(), String> {
        if self.central_differences(knowns, dv_known, eps, unknowns, dv_unknown)? {
            Ok(())
        } else {
            self.check_finite(unknowns, dv_unknown, "the directional derivative of ")
        }
    }

    /// `dv_unknown = J · dv_known` from the model's own partial derivatives,
    /// if it supplies every entry (else `false`, `dv_unknown` partly
    /// written).
    #[inline(never)]
    fn analytic(
        &self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        dv_unknown: &mut [f64],
    ) -> bool {
        for (out, u) in dv_unknown.iter_mut().zip(unknowns) {
            let mut acc = 0.0;
            for (k, dv) in knowns.iter().zip(dv_known) {
                match self.model.partial_derivative(&self.values, *u, *k) {
                    Some(d) => acc += d * dv,
                    None => return false,
                }
            }
            *out = acc;
        }
        true
    }

    /// `dv_unknown = J · dv_known` with J the model's step sensitivities
    /// ([`Model::step_partial_derivative`]) of the last step, which held
    /// every input, if it gives every entry (else `false`, `dv_unknown`
    /// partly written). Input `k` is asked with the half-width `eps·|dv_k|`
    /// over which [`Instance::central_differences`] would move it (a known
    /// with a zero seed moves nothing there and adds nothing here).
    #[inline(never)]
    fn step_analytic(
        &self,
        unknowns: &[u32],
        knowns: &[u32],
        dv_known: &[f64],
        eps: f64,
        dv_unknown: &mut [f64],
    ) -> bool {
        let h = self.replay.h;
        for (out, &u) in dv_unknown.iter_mut().zip(unknowns) {
            let mut acc = 0.0;
            for (&k, &dv) in knowns.iter().zip(dv_known) {
                if dv == 0.0 {
                    continue;
                }
                let spread = eps * dv.abs();
                match self
                    .model
                    .step_partial_derivative(&self.values, u, k, h, spread)
                {
                    Some(d) => acc += d * dv,
                    None => return false,
                }
            }
            *out = acc;
        }
        true
    }

    /// `out = (y(u + eps·dv) - y(u - eps·dv)) / (2·eps)` for the outputs
    /// `unknowns` and the inputs `knowns`: after a step, with the step
    /// replayed from its saved start on the replay copy of the model
    /// ([`Scratch::model`]; the instance's model is not touched), else at
    /// the current state. The scratch values are brought to the instance's
    /// once for both evaluations, and `out` holds the first until the
    /// second is subtracted. Whether every entry of `out` is finite. No
    /// allocation once the replay copy exists.
    fn central_differences(
        &mut self,
        knowns: &[u32],
        dv: &[f64],
        eps: f64,
        unknowns: &[u32],
        out: &mut [f64],
    ) -> Result<bool, String> {
        // (the instance's fields borrowed once, beside the scratch ones:
        // nothing is read through `self` again after a model call)
        let current = self.values.as_slice();
        let scratch = &mut self.scratch;
        let values = &mut scratch.values;
        if scratch.parameters_version == self.parameters_version {
            // the same parameters as last time: only the inputs differ (the
            // outputs are recomputed below)
            self.inputs.copy(values.as_mut_slice(), current);
        } else {
            values.copy_from_slice(current);
            scratch.parameters_version = self.parameters_version;
        }
        // Each pass sets the knowns from the unperturbed inputs (the
        // instance's, or the replayed step's): the models write outputs
        // only, so the other inputs stay as set above.
        let mut finite = true;
        let passes = [eps, -eps];
        if !self.replay.valid {
            for (pass, eps) in passes.into_iter().enumerate() {
                perturb(values, current, knowns, dv, eps);
                self.model.compute_outputs_of(values, unknowns);
                finite = difference(pass, eps, values, unknowns, out);
            }
            return Ok(finite);
        }
        // Every slope is zero between calls; those of the inputs are set
        // here when the step had any (and zero again when done). Held
        // inputs: the values now (set above) are the values before the
        // step.
        let replay = &self.replay;
        let inputs = &self.inputs;
        let slopes = &mut scratch.slopes[..];
        let model = scratch
            .model
            .get_or_insert_with(|| self.model.clone_model());
        for (pass, eps) in passes.into_iter().enumerate() {
            if replay.held {
                perturb(values, current, knowns, dv, eps);
            } else {
                for (k, &vr) in inputs.iter().enumerate() {
                    values.set(vr, replay.inputs[k]);
                    slopes[vr as usize] = replay.slopes[k];
                }
                for (&k, d) in knowns.iter().zip(dv) {
                    values.set(k, values.real(k) + eps * d);
                }
            }
            let replayed = model
                .restore_state(&replay.model_state)
                .and_then(|()| model.do_step(values, slopes, replay.h));
            if !replay.held {
                // the inputs at the end of the step; every slope zero again
                advance_inputs(inputs, values, slopes, replay.h);
            }
            replayed?;
            model.compute_outputs_of(values, unknowns);
            finite = difference(pass, eps, values, unknowns, out);
        }
        Ok(finite)
    }

    // ---- FMU states -----------------------------------------------------

    /// Restore `snap` (one of this instance's saved states): all or nothing.
    pub fn restore(&mut self, snap: &Snapshot) -> Result<(), String> {
        if self.same_parameters(snap) {
            return self.restore_same_parameters(SnapshotAt::Given(snap));
        }
        self.step_state_current = false;
        self.restore_other(snap)?;
        self.restored(snap.sloped, snap.initialized, snap.time, snap.state);
        Ok(())
    }

    /// The usual rollback: `snap`, taken with the parameters the instance
    /// has now, restored where it lies (given, or in the saved list, which
    /// the restore does not write and so may lend the snapshot).
    #[inline(always)]
    fn restore_same_parameters(&mut self, at: SnapshotAt<'_>) -> Result<(), String> {
        let snap = match at {
            SnapshotAt::Given(snap) => snap,
            SnapshotAt::Saved(i) => &*self.saved_states[i],
        };
        self.step_state_current = false;
        restore_in_place(
            &mut *self.model,
            &mut self.values,
            &mut self.slopes,
            &self.inputs,
            self.sloped,
            snap,
        )?;
        let (sloped, initialized, time, state) =
            (snap.sloped, snap.initialized, snap.time, snap.state);
        self.restored(sloped, initialized, time, state);
        Ok(())
    }

    /// Whether `snap` is the usual rollback of a master: a state this
    /// instance took since its parameters last changed (only those carry
    /// its current parameter version; a deserialized one has u64::MAX), so
    /// of this model, with the same sizes, and the GUID and parameter
    /// checks of [`Instance::restore_other`] would pass: restored by
    /// [`restore_in_place`].
    #[inline(always)]
    fn same_parameters(&self, snap: &Snapshot) -> bool {
        self.initialized && snap.initialized && snap.parameters_version == self.parameters_version
    }

    /// What every successful [`Instance::restore`] sets last, from the
    /// snapshot's fields.
    #[inline(always)]
    fn restored(&mut self, sloped: bool, initialized: bool, time: f64, state: State) {
        self.sloped = sloped;
        self.initialized = initialized;
        self.time = time;
        self.state = state;
        self.replay.valid = false;
        self.outputs_dirty = true;
    }

    /// The model state and values of [`Instance::restore`] for any other
    /// snapshot: deserialized, taken before a parameter was set, or before
    /// initialization.
    #[inline(never)]
    fn restore_other(&mut self, snap: &Snapshot) -> Result<(), String> {
        // (the GUID is our own `info.guid` for every snapshot this library
        // made or read: the address compares equal, the text is the fallback)
        let same_guid = std::ptr::eq(snap.guid, self.info.guid) || snap.guid == self.info.guid;
        if !same_guid || snap.values.len() != self.values.len() {
            return Err(format!(
                "the FMU state belongs to GUID {}, not this FMU ({})",
                snap.guid, self.info.guid
            ));
        }
        if snap.state.is_model_exchange() != self.model_exchange {
            let interface = |me: bool| {
                if me {
                    "Model Exchange"
                } else {
                    "Co-Simulation"
                }
            };
            return Err(format!(
                "the FMU state was taken by a {} instance (state {}), this is a {} instance",
                interface(snap.state.is_model_exchange()),
                snap.state.name(),
                interface(self.model_exchange)
            ));
        }
        let same_parameters = self.initialized
            && self.info.variables.iter().all(|v| {
                v.causality != Causality::Parameter
                    || self.values.real(v.vr) == snap.values[v.vr as usize]
            });
        if snap.initialized && same_parameters {
            self.model
                .restore_state(&snap.model_state)
                .map_err(state_refused)?;
            self.values.copy_from_slice(&snap.values);
        } else {
            let previous = self.values.clone();
            self.values.copy_from_slice(&snap.values);
            self.parameters_version += 1;
            if snap.initialized {
                let result = self
                    .initialize_model()
                    .and_then(|_| self.model.restore_state(&snap.model_state));
                if let Err(e) = result {
                    // Lose nothing: put the previous values and model back.
                    self.values = previous;
                    if self.initialized {
                        let _ = self.initialize_model();
                    }
                    return Err(state_refused(e));
                }
            }
        }
        self.slopes.copy_from_slice(&snap.slopes);
        Ok(())
    }

    /// `fmi2GetFMUstate`: save the current state into the snapshot at
    /// `reuse` (which must be one of this instance's) in place, reusing its
    /// buffers, or into a new one if `reuse` is 0; returns its address.
    #[inline]
    pub fn save_snapshot(&mut self, reuse: usize) -> Result<usize, String> {
        let reused = match reuse {
            0 => None,
            _ => Some(self.saved_index(reuse)?),
        };
        self.ensure_outputs()?;
        let i = reused.unwrap_or_else(|| self.new_snapshot());
        // (written in its box in the list, the instance's fields borrowed
        // one by one beside it)
        let snap = &mut *self.saved_states[i];
        snap.state = self.state;
        snap.initialized = self.initialized;
        snap.time = self.time;
        if snap.parameters_version == self.parameters_version {
            // A snapshot this instance took with the same parameters (so of
            // the same sizes): only the inputs and their slopes can differ
            // (outputs are recomputed after a restore), the slopes not if
            // both sides have none.
            self.inputs.copy(&mut snap.values, self.values.as_slice());
            if self.sloped || snap.sloped {
                self.inputs.copy(&mut snap.slopes, &self.slopes);
            }
        } else {
            copy_all(snap, &self.values, &self.slopes, self.parameters_version);
        }
        snap.sloped = self.sloped;
        if self.initialized {
            save_model_state(&*self.model, self.state_len, &mut snap.model_state);
        } else {
            snap.model_state.clear();
        }
        Ok(snap as *const Snapshot as usize)
    }

    /// The current state as a snapshot of its own, not kept by the
    /// instance.
    pub fn snapshot(&mut self) -> Result<Snapshot, String> {
        let address = self.save_snapshot(0)?;
        Ok(*self.take_snapshot(address)?)
    }

    /// A new, empty snapshot of this model at the end of
    /// [`Instance::saved_states`] (once per master, which then reuses it);
    /// its index.
    #[inline(never)]
    fn new_snapshot(&mut self) -> usize {
        self.saved_states.push(Box::new(Snapshot {
            guid: self.info.guid,
            state: self.state,
            initialized: false,
            time: 0.0,
            values: Vec::new(),
            slopes: Vec::new(),
            sloped: false,
            model_state: Vec::new(),
            // (no version: `save_snapshot` copies every value)
            parameters_version: u64::MAX,
        }));
        self.saved_states.len() - 1
    }

    /// `fmi2SetFMUstate`: restore the saved snapshot at `address`.
    #[inline]
    pub fn restore_saved(&mut self, address: usize) -> Result<(), String> {
        let i = self.saved_index(address)?;
        let snap = &*self.saved_states[i];
        if !self.same_parameters(snap) {
            return self.restore_saved_other(i);
        }
        self.restore_same_parameters(SnapshotAt::Saved(i))
    }

    /// [`Instance::restore_saved`] of any other of the saved snapshots, at
    /// `i`: out of the list for a moment (no copy; the box, and so the
    /// address, stays the same).
    #[inline(never)]
    fn restore_saved_other(&mut self, i: usize) -> Result<(), String> {
        let snap = self.saved_states.swap_remove(i);
        let result = self.restore(&snap);
        self.saved_states.push(snap);
        result
    }

    /// Where the snapshot at `address` is in [`Instance::saved_states`].
    fn saved_index(&self, address: usize) -> Result<usize, String> {
        self.saved_states
            .iter()
            .position(|b| &**b as *const Snapshot as usize == address)
            .ok_or_else(|| {
                format!(
                    "FMUstate {address:#x} was not created by this instance (or was already freed)"
                )
            })
    }

    /// The saved snapshot at `address`, out of the list for a moment (no
    /// copy; the box, and so the address, stays the same: put it back with
    /// `saved_states.push`).
    fn take_snapshot(&mut self, address: usize) -> Result<Box<Snapshot>, String> {
        let i = self.saved_index(address)?;
        Ok(self.saved_states.swap_remove(i))
    }

    /// Keep a snapshot and return its address (the `fmi2FMUstate`).
    pub fn store_snapshot(&mut self, snap: Snapshot, reuse: usize) -> usize {
        if let Ok(i) = self.saved_index(reuse) {
            *self.saved_states[i] = snap;
            return reuse;
        }
        let boxed = Box::new(snap);
        let address = &*boxed as *const Snapshot as usize;
        self.saved_states.push(boxed);
        address
    }

    pub fn saved_snapshot(&self, address: usize) -> Result<&Snapshot, String> {
        let i = self.saved_index(address)?;
        Ok(&self.saved_states[i])
    }

    pub fn free_snapshot(&mut self, address: usize) -> Result<(), String> {
        self.take_snapshot(address).map(|_| ())
    }

    pub fn n_values(&self) -> usize {
        self.values.len()
    }

    pub fn values(&self) -> &Values {
        &self.values
    }
}

/// [`Instance::state_len`] of a model without [`Model::state_len`], which
/// writes its state with [`Model::save_state`] only: no buffer has this
/// length.
const VEC_STATE: usize = usize::MAX;

/// Where [`Instance::restore_same_parameters`] finds its snapshot.
enum SnapshotAt<'a> {
    /// Given by the caller.
    Given(&'a Snapshot),
    /// At this index of the instance's saved list.
    Saved(usize),
}

/// The complete state of `model` into `out`, replacing what it held, with
/// `len` the model's [`Instance::state_len`]. The usual case is one
/// comparison: a buffer of the state's length (sized by an earlier save,
/// the length changing with the parameters only) is written in place by
/// [`Model::write_state_into`]; the other cases are out of line.
#[inline(always)]
fn save_model_state(model: &dyn Model, len: usize, out: &mut Vec<f64>) {
    if out.len() == len {
        model.write_state_into(out);
    } else {
        save_model_state_resized(model, len, out);
    }
}

/// [`save_model_state`] into a buffer of another length: sized to the
/// state and written into, or, for a model without `state_len`, appended
/// by [`Model::save_state`] (every time).
#[cold]
#[inline(never)]
fn save_model_state_resized(model: &dyn Model, len: usize, out: &mut Vec<f64>) {
    if len == VEC_STATE {
        out.clear();
        model.save_state(out);
    } else {
        out.resize(len, 0.0);
        model.write_state_into(out);
    }
}

/// After a step of length `h`, inputs stand at `u + du·h`; slopes reset.
fn advance_inputs(inputs: &[u32], values: &mut Values, slopes: &mut [f64], h: f64) {
    for &vr in inputs {
        let s = &mut slopes[vr as usize];
        if *s != 0.0 {
            values.set(vr, values.real(vr) + *s * h);
            *s = 0.0;
        }
    }
}

/// `values[k] = from[k] + eps·dv` for each known `k`: the perturbed
/// inputs of a pass of [`Instance::central_differences`].
#[inline(always)]
fn perturb(values: &mut Values, from: &[f64], knowns: &[u32], dv: &[f64], eps: f64) {
    for (&k, d) in knowns.iter().zip(dv) {
        values.set(k, from[k as usize] + eps * d);
    }
}

/// Evaluation `pass` of [`Instance::central_differences`], with `values`
/// at `u + e·dv`: the first (`e = ε`) keeps `y₊` in `out`, the second
/// (`e = -ε`, so `-2·e` is exactly `2·ε`) turns it into `(y₊ - y₋) / (2·ε)`.
/// Whether every entry written is finite (as [`all_finite`]).
#[inline(always)]
fn difference(pass: usize, eps: f64, values: &Values, unknowns: &[u32], out: &mut [f64]) -> bool {
    let mut zero = 0.0;
    for (o, &u) in out.iter_mut().zip(unknowns) {
        let y = values.real(u);
        *o = if pass == 0 {
            y
        } else {
            (*o - y) / (-2.0 * eps)
        };
        zero += *o * 0.0;
    }
    zero == 0.0
}

/// Every value and slope into `snap`, taken at parameter version `version`
/// ([`Instance::save_snapshot`] of a new snapshot, or of one taken with
/// other parameters or deserialized).
#[cold]
#[inline(never)]
fn copy_all(snap: &mut Snapshot, values: &Values, slopes: &[f64], version: u64) {
    snap.parameters_version = version;
    snap.values.clear();
    snap.values.extend_from_slice(values.as_slice());
    snap.slopes.clear();
    snap.slopes.extend_from_slice(slopes);
}

/// The model state and inputs of the usual rollback
/// ([`Instance::same_parameters`]): the model takes the state or refuses
/// it unchanged, then only the inputs (and their slopes, unless neither
/// side has any: `sloped` is the instance's) differ; the outputs are
/// recomputed. The instance's parts are borrowed one by one, so that
/// `snap` may be one of its own saved states.
#[inline(always)]
fn restore_in_place(
    model: &mut dyn Model,
    values: &mut Values,
    slopes: &mut [f64],
    inputs: &Indices,
    sloped: bool,
    snap: &Snapshot,
) -> Result<(), String> {
    model
        .restore_state(&snap.model_state)
        .map_err(state_refused)?;
    inputs.copy(values.as_mut_slice(), &snap.values);
    if sloped || snap.sloped {
        inputs.copy(slopes, &snap.slopes);
    }
    Ok(())
}

/// Why [`Instance::restore`] failed: the model refused the state.
#[cold]
#[inline(never)]
fn state_refused(why: String) -> String {
    format!("cannot restore the FMU state: {why}")
}

/// Why [`Instance::do_step`] refused the step size `h`.
#[cold]
#[inline(never)]
fn step_size_refused(h: f64) -> String {
    format!("communicationStepSize must be finite and > 0 but was {h}")
}

/// The message of a step the model refused with `why`.
#[cold]
#[inline(never)]
fn step_failed(t: f64, h: f64, why: String) -> String {
    format!("step from t = {t} over h = {h} failed: {why}")
}

/// `out[k] = data[vrs[k]]` for each `k` (of the shorter of `out` and
/// `vrs`); whether every value copied is finite (as [`all_finite`]). Two
/// at a time, checked in two lanes, the last pair overlapping the one
/// before for an odd length (the same value copied and counted twice):
/// no loop for a remainder.
///
/// # Safety
/// Every entry of `vrs` is an index of `data`.
#[inline(always)]
unsafe fn gather(data: &[f64], vrs: &[u32], out: &mut [f64]) -> bool {
    let n = out.len().min(vrs.len());
    // SAFETY (each access): `k` and `k + 1` below `n`, so within `vrs`
    // and `out`; `vrs[k]` within `data` (the caller's)
    let at = |k: usize| unsafe { *data.get_unchecked(*vrs.get_unchecked(k) as usize) };
    if n < 2 {
        return match n {
            0 => true,
            _ => {
                let x = at(0);
                unsafe { *out.get_unchecked_mut(0) = x };
                x * 0.0 == 0.0
            }
        };
    }
    let to = out.as_mut_ptr();
    let mut lanes = [0.0; 2];
    let mut pair = |k: usize| {
        let x = [at(k), at(k + 1)];
        unsafe { *(to.add(k) as *mut [f64; 2]) = x };
        lanes[0] += x[0] * 0.0;
        lanes[1] += x[1] * 0.0;
    };
    let mut k = 0;
    while k + 2 < n {
        pair(k);
        k += 2;
    }
    pair(n - 2);
    lanes[0] + lanes[1] == 0.0
}

/// Whether lists `a` and `b` of value references are equal; a list of two
/// (the outputs of a friction law, say) compared inline, which is cheaper
/// than the call to `memcmp` that compares longer ones.
#[inline(always)]
fn same_list(a: &[u32], b: &[u32]) -> bool {
    match (a, b) {
        ([a0, a1], [b0, b1]) => (a0 ^ b0) | (a1 ^ b1) == 0,
        _ => a == b,
    }
}

/// No NaN or infinity in `values`: `x·0` is 0 for every finite `x` and NaN
/// otherwise, and a sum with a NaN is NaN. Summed two at a time in two
/// lanes (the order does not change whether a NaN is among the terms),
/// the last pair overlapping the one before for an odd length (an entry
/// counted twice changes nothing): a model state of a few values takes
/// no loop for the remainder.
#[inline]
fn all_finite(values: &[f64]) -> bool {
    let n = values.len();
    if n < 2 {
        return values.first().is_none_or(|x| x * 0.0 == 0.0);
    }
    let mut lanes = [0.0; 2];
    let mut add = |k: usize| {
        let pair = &values[k..k + 2];
        lanes[0] += pair[0] * 0.0;
        lanes[1] += pair[1] * 0.0;
    };
    let mut k = 0;
    while k + 2 < n {
        add(k);
        k += 2;
    }
    add(n - 2);
    lanes[0] + lanes[1] == 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`all_finite`] of every length up to 9 (no remainder, an odd one,
    /// the one-value path, the empty list), with a NaN or an infinity at
    /// each place, alone or with others, and with finite extremes only.
    #[test]
    fn all_finite_finds_every_non_finite_entry() {
        for n in 0..10 {
            let finite: Vec<f64> = (0..n)
                .map(|k| match k % 4 {
                    0 => f64::MAX,
                    1 => -0.0,
                    2 => f64::MIN_POSITIVE / 4.0,
                    _ => -1.5e300,
                })
                .collect();
            assert!(all_finite(&finite), "{finite:?}");
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for k in 0..n {
                    let mut values = finite.clone();
                    values[k] = bad;
                    assert!(!all_finite(&values), "{values:?}");
                    values[n - 1 - k] = -bad;
                    assert!(!all_finite(&values), "{values:?}");
                }
            }
        }
    }

    /// [`gather`] of lists of every length up to 9 (no remainder, an odd
    /// one, one value, none), in any order and with repeated entries,
    /// copies exactly `data[vrs[k]]` into `out[k]` and nothing else, and
    /// finds a NaN or an infinity at any place of the list.
    #[test]
    fn gather_copies_each_value_and_finds_every_non_finite_one() {
        let data: Vec<f64> = (0..12).map(|k| k as f64 * 1.5 - 4.0).collect();
        for n in 0..10u32 {
            let vrs: Vec<u32> = (0..n).map(|k| (k * 7 + n) % 6 * 2).collect();
            let mut out = vec![f64::NAN; n as usize + 1];
            // SAFETY: every entry of `vrs` is below 12 (and one of six:
            // repeated in lists longer than six)
            assert!(unsafe { gather(&data, &vrs, &mut out[..n as usize]) });
            let expected: Vec<f64> = vrs.iter().map(|&vr| data[vr as usize]).collect();
            assert_eq!(out[..n as usize], expected[..], "{vrs:?}");
            assert!(out[n as usize].is_nan(), "written past the list");
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for &vr in &vrs {
                    let mut data = data.clone();
                    data[vr as usize] = bad;
                    // SAFETY: as above
                    assert!(!unsafe { gather(&data, &vrs, &mut out) }, "{vrs:?}");
                }
            }
        }
    }
}
