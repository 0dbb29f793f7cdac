//! The communication step size of `fmi2DoStep`: every positive finite
//! size is taken, down to the least subnormal and up to `f64::MAX`; zero,
//! negative, infinite and NaN sizes are refused with the message, and the
//! instance stays where it was.

use fmi_export::instance::Instance;
use fmi_export::{Model, ModelInfo, Values, Variable};

#[path = "support/toy_instance.rs"]
mod toy_instance;
use toy_instance::{initialized, toy_info};

/// `ṡ = 0`: any step size leaves a finite state.
#[derive(Clone)]
struct Still {
    info: &'static ModelInfo,
    s: f64,
}

impl Model for Still {
    fn info(&self) -> &'static ModelInfo {
        self.info
    }
    fn initialize(&mut self, _: &Values) -> Result<(), String> {
        Ok(())
    }
    fn compute_outputs(&self, v: &mut Values) {
        v.set(1, self.s);
    }
    fn do_step(&mut self, _: &Values, _: &[f64], _: f64) -> Result<(), String> {
        Ok(())
    }
    toy_instance::one_value_toy_state!();
}

fn instance() -> Instance {
    let info = toy_info(
        "Still",
        vec![
            Variable::input(0, "u", 0.0, "", 1.0, "input"),
            Variable::output(1, "y", "", "the state", &[]),
        ],
    );
    initialized(info, Box::new(Still { info, s: 0.0 }))
}

#[test]
fn every_positive_finite_step_size_and_no_other() {
    for h in [
        f64::from_bits(1),
        f64::MIN_POSITIVE,
        1e-4,
        1.0,
        1e300,
        f64::MAX,
    ] {
        let mut fmu = instance();
        fmu.do_step(0.0, h)
            .unwrap_or_else(|e| panic!("h = {h:e}: {e}"));
        assert_eq!(fmu.time, h);
    }
    let mut fmu = instance();
    for h in [
        0.0,
        -0.0,
        -f64::from_bits(1),
        -1e-4,
        f64::MIN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        -f64::NAN,
        f64::from_bits(0x7ff0_0000_0000_0001),
        f64::from_bits(u64::MAX),
    ] {
        let e = fmu.do_step(0.0, h).unwrap_err();
        assert_eq!(
            e,
            format!("communicationStepSize must be finite and > 0 but was {h}"),
            "{h:e}"
        );
        assert_eq!(fmu.time, 0.0);
    }
    // and the instance steps on
    fmu.do_step(0.0, 0.5).unwrap();
    assert_eq!(fmu.time, 0.5);
}

/// FMI 2.0 §2.1.6: with a stop time defined by fmi2SetupExperiment, a step
/// that would compute past it returns an error naming both times and
/// changes nothing; steps up to it (within rounding) are taken.
#[test]
fn no_step_past_a_defined_stop_time() {
    let info = toy_info(
        "Still",
        vec![
            Variable::input(0, "u", 0.0, "", 1.0, "input"),
            Variable::output(1, "y", "", "the state", &[]),
        ],
    );
    let logger = fmi_export::logger::Logger::new(
        fmi_export::logger::Callback::Fmi2(None),
        std::ptr::null_mut(),
        "probe",
        false,
    );
    let mut fmu = Instance::new(info, Box::new(Still { info, s: 0.0 }), "probe", logger);
    fmu.setup_experiment(0.0, Some(1.0)).unwrap();
    fmu.enter_initialization_mode().unwrap();
    fmu.exit_initialization_mode().unwrap();
    // ten steps of 0.1 end at 0.9999999999999999: on the stop time
    let mut t = 0.0;
    for _ in 0..10 {
        fmu.do_step(t, 0.1).unwrap();
        t += 0.1;
    }
    let e = fmu.do_step(fmu.time, 0.1).unwrap_err();
    assert!(e.contains("past stopTime = 1"), "{e}");
    assert!((fmu.time - 1.0).abs() < 1e-12, "{}", fmu.time);
    // refused, not failed: an instance without a stop time steps on
    let mut open = instance();
    open.do_step(0.0, 2.0).unwrap();
}
