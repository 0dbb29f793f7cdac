//! The FMI 2.0 Co-Simulation and Model Exchange interfaces, written once
//! for every model.
//!
//! A model implements [`Model`] (pure Rust, no pointers) and declares its
//! variables in a [`ModelInfo`] table; a model that is an ODE also
//! implements [`Ode`] and declares its states
//! ([`ModelInfo::model_exchange`]), and the same binary then serves both
//! interfaces. The [`export_fmi2!`] macro, invoked
//! in a `cdylib`, emits every `fmi2…` C function; each one
//!
//! 1. runs inside `catch_unwind`, so a panic becomes `fmi2Fatal` and a
//!    logged message, never unwinding into the importer;
//! 2. checks the instance pointer against the set of live instances, then
//!    the call against the state machine table ([`state_machine`]), then
//!    null pointers and lengths, then value references, types, causality and
//!    values (NaN and ±inf are refused);
//! 3. works on [`instance::Instance`] with `Result`s and turns them into a C
//!    status only at the edge, logging the function's name and the value.
//!
//! The model description is rendered from the same table
//! ([`model_description::render`]), so the XML cannot drift from the code.

pub mod exports;
pub mod ffi;
pub mod fmi3;
pub mod guard;
pub mod instance;
pub mod logger;
pub mod model;
pub mod model_description;
pub mod resource_location;
pub mod serialize;
pub mod state_machine;
pub mod values;
pub mod variables;

pub use model::{Model, ModelFactory, Ode};
pub use values::Values;
pub use variables::{
    Capabilities, Causality, ContinuousState, DefaultExperiment, Initial, ModelExchange, ModelInfo,
    VarType, Variability, Variable,
};
