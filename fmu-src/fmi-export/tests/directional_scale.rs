//! The perturbation of a directional derivative by central differences is
//! ε = 1e-6·max(|u|, nominal)/|dv| (`f64::max`, so a NaN nominal leaves
//! |u|; no nominal means 1), whatever the layer keeps per input: checked
//! bit for bit on a linear toy, whose derivative by differences shows ε in
//! its last bits.

use fmi_export::instance::Instance;
use fmi_export::{Model, ModelInfo, Values, Variable};

#[path = "support/toy_instance.rs"]
mod toy_instance;
use toy_instance::{initialized, toy_info};

const U: u32 = 0;
const Y: u32 = 1;
const K: u32 = 2;

/// y = k·u, no state.
#[derive(Clone)]
struct Linear {
    info: &'static ModelInfo,
    k: f64,
}

impl Model for Linear {
    fn info(&self) -> &'static ModelInfo {
        self.info
    }
    fn initialize(&mut self, v: &Values) -> Result<(), String> {
        self.k = v.real(K);
        Ok(())
    }
    fn compute_outputs(&self, v: &mut Values) {
        v.set(Y, self.k * v.real(U));
    }
    fn do_step(&mut self, _: &Values, _: &[f64], _: f64) -> Result<(), String> {
        Ok(())
    }
    fn save_state(&self, _: &mut Vec<f64>) {}
    fn restore_state(&mut self, _: &[f64]) -> Result<(), String> {
        Ok(())
    }
    fn clone_model(&self) -> Box<dyn Model> {
        Box::new(self.clone())
    }
}

/// An initialized instance of the toy with input nominal `nominal`
/// (`None`: not declared).
fn instance(nominal: Option<f64>) -> Instance {
    let mut u = Variable::input(U, "u", 0.0, "", 1.0, "input");
    u.nominal = nominal;
    let info = toy_info(
        "Linear",
        vec![
            u,
            Variable::output(Y, "y", "", "k*u", &[U]),
            Variable::parameter(K, "k", 3.0, "", "gain"),
        ],
    );
    initialized(info, Box::new(Linear { info, k: 0.0 }))
}

#[test]
fn the_perturbation_scales_with_the_larger_of_the_input_and_its_nominal() {
    let k = 3.0;
    let nominals = [
        None,
        Some(f64::NAN),
        Some(0.5),
        Some(2.0),
        Some(10.0),
        Some(1e-300),
        Some(0.0),
    ];
    for nominal in nominals {
        for (u, dv) in [(2.0, 1.0), (-2.0, 3.0), (0.7, -0.25), (1e-3, 1e3)] {
            let mut fmu = instance(nominal);
            fmu.set(fmi_export::VarType::Real, &[U], &[u]).unwrap();
            let mut d = [f64::NAN];
            fmu.directional_derivative(&[Y], &[U], &[dv], &mut d)
                .unwrap();
            // the layer's differences, written out
            let scale = u.abs().max(nominal.unwrap_or(1.0));
            let eps = 1e-6 * scale / dv.abs();
            let y = |e: f64| k * (u + e * dv);
            let expected = (y(eps) - y(-eps)) / (-2.0 * -eps);
            assert_eq!(
                d[0].to_bits(),
                expected.to_bits(),
                "nominal {nominal:?}, u = {u}, dv = {dv}: {} vs {expected}",
                d[0]
            );
        }
    }
}
