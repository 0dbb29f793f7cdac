//! The description and an initialized instance of a toy model, for the
//! tests of the layer on a model of their own
//! (`fmi-export/tests/directional_scale.rs`, `get_lists.rs`,
//! `step_derivatives.rs`, `step_size.rs`; its state macro also
//! `resource_location.rs`).
//! Included with `#[path]`.

use fmi_export::instance::Instance;
use fmi_export::logger::Logger;
use fmi_export::{Capabilities, DefaultExperiment, Model, ModelInfo, Variable};

/// A model description of `variables` named `name` (kept for the
/// process, as a model's static description is).
pub fn toy_info(name: &'static str, variables: Vec<Variable>) -> &'static ModelInfo {
    toy_info_with(name, variables, None)
}

/// [`toy_info`] with a Model Exchange interface `model_exchange`.
pub fn toy_info_with(
    name: &'static str,
    variables: Vec<Variable>,
    model_exchange: Option<fmi_export::ModelExchange>,
) -> &'static ModelInfo {
    Box::leak(Box::new(ModelInfo {
        model_name: name,
        model_identifier: name,
        guid: Box::leak(format!("{{{name}}}").into_boxed_str()),
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
        model_exchange,
    }))
}

/// An instance of `model` (of `info`), through initialization mode into
/// step mode at t = 0.
pub fn initialized(info: &'static ModelInfo, model: Box<dyn Model>) -> Instance {
    let logger = Logger::new(
        fmi_export::logger::Callback::Fmi2(None),
        std::ptr::null_mut(),
        "probe",
        false,
    );
    let mut fmu = Instance::new(info, model, "probe", logger);
    fmu.setup_experiment(0.0, None).unwrap();
    fmu.enter_initialization_mode().unwrap();
    fmu.exit_initialization_mode().unwrap();
    fmu
}

/// The state methods of a toy model whose state is its field `s` alone
/// (`save_state`, `restore_state`, and `clone_model` of a `Clone` model),
/// written inside its `impl Model` block. (Not every test including this
/// file has such a model.)
#[allow(unused_macros)]
macro_rules! one_value_toy_state {
    () => {
        fn save_state(&self, out: &mut Vec<f64>) {
            out.push(self.s);
        }
        fn restore_state(&mut self, s: &[f64]) -> Result<(), String> {
            self.s = s[0];
            Ok(())
        }
        fn clone_model(&self) -> Box<dyn Model> {
            Box::new(self.clone())
        }
    };
}
#[allow(unused_imports)]
pub(crate) use one_value_toy_state;
