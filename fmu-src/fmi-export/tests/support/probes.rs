//! One call of each function that takes an instance, Co-Simulation and
//! Model Exchange, with arguments that are valid apart from the state: the
//! probes of the state-table tests (`c_abi.rs` for Co-Simulation,
//! `model_exchange.rs` for Model Exchange). Included with `#[path]` into a
//! test whose crate root holds the exports of `fmi_export::export_fmi2!`. In
//! both toy models value reference 0 is an input and 1 an output; in the
//! Model Exchange toy 2 is the state and 4 its derivative.

use crate::fmi2_exports::*;
use fmi_export::ffi::*;
use std::ptr::null;

/// A function's name and a call of it.
pub type Probe = (&'static str, fn(fmi2Component) -> fmi2Status);

const INPUT: u32 = 0;
const OUTPUT: u32 = 1;
const STATE: u32 = 2;
const DERIVATIVE: u32 = 4;

pub fn probes() -> Vec<Probe> {
    vec![
        // both interfaces
        ("fmi2SetupExperiment", |c| unsafe {
            fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0)
        }),
        ("fmi2EnterInitializationMode", |c| unsafe {
            fmi2EnterInitializationMode(c)
        }),
        ("fmi2ExitInitializationMode", |c| unsafe {
            fmi2ExitInitializationMode(c)
        }),
        ("fmi2Terminate", |c| unsafe { fmi2Terminate(c) }),
        ("fmi2Reset", |c| unsafe { fmi2Reset(c) }),
        ("fmi2GetReal", |c| unsafe {
            fmi2GetReal(c, &OUTPUT, 1, &mut 0.0)
        }),
        ("fmi2SetReal", |c| unsafe {
            fmi2SetReal(c, &INPUT, 1, &0.5)
        }),
        ("fmi2SetBoolean", |c| unsafe {
            fmi2SetBoolean(c, null(), 0, null())
        }),
        ("fmi2GetDirectionalDerivative", |c| unsafe {
            fmi2GetDirectionalDerivative(c, &DERIVATIVE, 1, &STATE, 1, &1.0, &mut 0.0)
        }),
        // Co-Simulation
        ("fmi2DoStep", |c| unsafe { fmi2DoStep(c, 0.0, 0.1, 0) }),
        ("fmi2CancelStep", |c| unsafe { fmi2CancelStep(c) }),
        ("fmi2SetRealInputDerivatives", |c| unsafe {
            fmi2SetRealInputDerivatives(c, &INPUT, 1, &1, &1.0)
        }),
        ("fmi2GetRealOutputDerivatives", |c| unsafe {
            fmi2GetRealOutputDerivatives(c, &OUTPUT, 1, &1, &mut 0.0)
        }),
        ("fmi2GetRealStatus", |c| unsafe {
            fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &mut 0.0)
        }),
        // Model Exchange
        ("fmi2EnterEventMode", |c| unsafe { fmi2EnterEventMode(c) }),
        ("fmi2NewDiscreteStates", |c| unsafe {
            fmi2NewDiscreteStates(c, &mut fmi2EventInfo::default())
        }),
        ("fmi2EnterContinuousTimeMode", |c| unsafe {
            fmi2EnterContinuousTimeMode(c)
        }),
        ("fmi2CompletedIntegratorStep", |c| unsafe {
            fmi2CompletedIntegratorStep(c, 1, &mut 0, &mut 0)
        }),
        ("fmi2SetTime", |c| unsafe { fmi2SetTime(c, 0.5) }),
        ("fmi2SetContinuousStates", |c| unsafe {
            fmi2SetContinuousStates(c, [0.5].as_ptr(), 1)
        }),
        ("fmi2GetEventIndicators", |c| unsafe {
            fmi2GetEventIndicators(c, [0.0].as_mut_ptr(), 1)
        }),
        ("fmi2GetContinuousStates", |c| unsafe {
            fmi2GetContinuousStates(c, [0.0].as_mut_ptr(), 1)
        }),
        ("fmi2GetDerivatives", |c| unsafe {
            fmi2GetDerivatives(c, [0.0].as_mut_ptr(), 1)
        }),
        ("fmi2GetNominalsOfContinuousStates", |c| unsafe {
            fmi2GetNominalsOfContinuousStates(c, [0.0].as_mut_ptr(), 1)
        }),
    ]
}

/// The probes of the functions only Model Exchange has.
#[allow(dead_code)]
pub fn model_exchange_only() -> Vec<Probe> {
    probes()
        .into_iter()
        .skip_while(|(f, _)| *f != "fmi2EnterEventMode")
        .collect()
}
