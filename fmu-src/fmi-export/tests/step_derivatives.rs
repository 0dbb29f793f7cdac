//! A model's own step sensitivities ([`Model::step_partial_derivative`])
//! in the layer's directional derivatives: asked right after a step that
//! held every input, with the half-width the central differences would
//! move each input by, and used when every entry is answered; the
//! differences decide otherwise (a declined entry, an input set since the
//! step, input slopes over it, a model that supplies none), bit for bit
//! as before.

use fmi_export::instance::Instance;
use fmi_export::{Model, ModelInfo, Values, VarType, Variable};
use std::sync::{Arc, Mutex};

#[path = "support/toy_instance.rs"]
mod toy_instance;
use toy_instance::{initialized, toy_info};

const U: u32 = 0;
const W: u32 = 1;
const Y: u32 = 2;
const C: u32 = 3;
/// Nominal values of the inputs.
const NOMINAL_U: f64 = 0.5;
const NOMINAL_W: f64 = 2.0;

/// The value of w at which the toy's answer for w is NaN (a model's
/// arithmetic that overflowed).
const OVERFLOW: f64 = 13.0;

/// What the toy was asked: (output, input, h, spread).
type Asked = Arc<Mutex<Vec<(u32, u32, f64, f64)>>>;

/// `ṡ = u + w` (the inputs ramped with their slopes), `y = s + c·u`: over
/// a held step `∂y/∂u = h + c`, `∂y/∂w = h`. The `u` entry is declined
/// where `|u| ≤ spread` (a kink at 0, as LuGre's `|v|`); the `w` entry is
/// NaN at `w =` [`OVERFLOW`].
#[derive(Clone)]
struct Toy {
    info: &'static ModelInfo,
    s: f64,
    c: f64,
    supplies: bool,
    asked: Asked,
}

impl Model for Toy {
    fn info(&self) -> &'static ModelInfo {
        self.info
    }
    fn initialize(&mut self, v: &Values) -> Result<(), String> {
        self.c = v.real(C);
        self.s = 0.0;
        Ok(())
    }
    fn compute_outputs(&self, v: &mut Values) {
        v.set(Y, self.s + self.c * v.real(U));
    }
    fn do_step(&mut self, v: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        let rate = v.real(U) + v.real(W);
        let ramp = slopes[U as usize] + slopes[W as usize];
        self.s += h * rate + 0.5 * h * h * ramp;
        Ok(())
    }
    toy_instance::one_value_toy_state!();
    fn supplies_partial_derivatives(&self) -> bool {
        false
    }
    fn step_partial_derivative(
        &self,
        values: &Values,
        output: u32,
        input: u32,
        h: f64,
        spread: f64,
    ) -> Option<f64> {
        self.asked.lock().unwrap().push((output, input, h, spread));
        match (output, input) {
            (Y, U) if values.real(U).abs() > spread => Some(h + self.c),
            (Y, W) if values.real(W) == OVERFLOW => Some(f64::NAN),
            (Y, W) => Some(h),
            _ => None,
        }
    }
    fn supplies_step_derivatives(&self) -> bool {
        self.supplies
    }
}

/// An initialized instance of the toy (`c` = 3), and what it is asked.
fn instance(supplies: bool) -> (Instance, Asked) {
    let info = toy_info(
        "Toy",
        vec![
            Variable::input(U, "u", 0.0, "", NOMINAL_U, "input"),
            Variable::input(W, "w", 0.0, "", NOMINAL_W, "input"),
            Variable::output(Y, "y", "", "s + c*u", &[U]),
            Variable::parameter(C, "c", 3.0, "", "feedthrough"),
        ],
    );
    let asked = Asked::default();
    let model = Box::new(Toy {
        info,
        s: 0.0,
        c: 0.0,
        supplies,
        asked: asked.clone(),
    });
    (initialized(info, model), asked)
}

const H: f64 = 0.125;
const K: f64 = 3.0;

/// The instance after two steps of `H` with the inputs (u, w) held, and
/// the state before the second.
fn stepped(supplies: bool, u: f64, w: f64) -> (Instance, Asked, f64) {
    let (mut fmu, asked) = instance(supplies);
    fmu.set(VarType::Real, &[U, W], &[u, w]).unwrap();
    fmu.do_step(0.0, H).unwrap();
    let s0 = H * (u + w);
    fmu.do_step(H, H).unwrap();
    (fmu, asked, s0)
}

fn derivative(fmu: &mut Instance, knowns: &[u32], dv: &[f64]) -> f64 {
    let mut d = [f64::NAN];
    fmu.directional_derivative(&[Y], knowns, dv, &mut d)
        .unwrap();
    d[0]
}

/// The layer's central differences of the held step from `s0`, written
/// out: the inputs moved by ±eps·dv, `eps` the smallest of
/// 1e-6·max(|u_k|, nominal_k)/|dv_k|.
fn differences(s0: f64, (u, w): (f64, f64), dv: [f64; 2]) -> f64 {
    let mut eps = f64::INFINITY;
    for (x, nominal, d) in [(u, NOMINAL_U, dv[0]), (w, NOMINAL_W, dv[1])] {
        if d != 0.0 {
            eps = eps.min(1e-6 * x.abs().max(nominal) / d.abs());
        }
    }
    let y = |e: f64| {
        let (u, w) = (u + e * dv[0], w + e * dv[1]);
        let s = s0 + (H * (u + w) + 0.5 * H * H * 0.0);
        s + K * u
    };
    (y(eps) - y(-eps)) / (-2.0 * -eps)
}

#[test]
fn after_a_held_step_the_model_answers_with_the_differences_spread() {
    let (u, w) = (0.8, -0.3);
    let (mut fmu, asked, _) = stepped(true, u, w);
    // one input: the spread is the differences' ε·|dv|
    assert_eq!(derivative(&mut fmu, &[U], &[1.0]), H + K);
    let eps = 1e-6 * u.abs().max(NOMINAL_U);
    assert_eq!(*asked.lock().unwrap(), [(Y, U, H, eps)]);
    // two: ε from the input that moves most, each spread ε·|dv_k|
    asked.lock().unwrap().clear();
    let dv = [2.0, 0.5];
    let got = derivative(&mut fmu, &[U, W], &dv);
    assert_eq!(got, 0.0 + (H + K) * 2.0 + H * 0.5);
    let eps = (1e-6 * u.abs().max(NOMINAL_U) / 2.0).min(1e-6 * w.abs().max(NOMINAL_W) / 0.5);
    assert_eq!(
        *asked.lock().unwrap(),
        [(Y, U, H, eps * 2.0), (Y, W, H, eps * 0.5)]
    );
    // a zero seed moves nothing and is not asked
    asked.lock().unwrap().clear();
    assert_eq!(derivative(&mut fmu, &[U, W], &[0.0, -1.0]), -H);
    assert_eq!(asked.lock().unwrap().len(), 1);
}

#[test]
fn a_declined_entry_leaves_every_entry_to_the_differences() {
    // |u| within the spread: the u entry is declined, the w entry is not
    let (u, w) = (1e-8, 0.4);
    let (mut fmu, asked, s0) = stepped(true, u, w);
    let dv = [1.0, 1.0];
    let got = derivative(&mut fmu, &[U, W], &dv);
    assert_eq!(got.to_bits(), differences(s0, (u, w), dv).to_bits());
    assert_eq!(asked.lock().unwrap().len(), 1);
    // the same answer as from a model that supplies nothing
    let (mut plain, asked_plain, _) = stepped(false, u, w);
    assert_eq!(
        derivative(&mut plain, &[U, W], &dv).to_bits(),
        got.to_bits()
    );
    assert!(asked_plain.lock().unwrap().is_empty());
    // (the differences are the derivative to their rounding)
    assert!((got - (2.0 * H + K)).abs() < 1e-6);
}

#[test]
fn without_a_held_step_the_differences_decide() {
    let (u, w) = (0.8, -0.3);
    // an input set since the step: the feedthrough at the current state
    let (mut fmu, asked, _) = stepped(true, u, w);
    fmu.set(VarType::Real, &[U], &[0.9]).unwrap();
    let got = derivative(&mut fmu, &[U], &[1.0]);
    assert!((got - K).abs() < 1e-6, "{got}");
    assert!(asked.lock().unwrap().is_empty());
    // a step with input slopes: its replay, differenced
    let (mut fmu, asked) = instance(true);
    fmu.set(VarType::Real, &[U, W], &[u, w]).unwrap();
    fmu.do_step(0.0, H).unwrap();
    let s0 = H * (u + w);
    fmu.set_input_derivatives(&[U], &[1], &[2.0]).unwrap();
    fmu.do_step(H, H).unwrap();
    let got = derivative(&mut fmu, &[U], &[1.0]);
    assert!(asked.lock().unwrap().is_empty());
    // written out: u ramps from u ± ε to u ± ε + 2·H, y at the end
    let u_end = u + 2.0 * H;
    let eps = 1e-6 * u_end.abs().max(NOMINAL_U);
    let y = |e: f64| {
        let s = s0 + (H * ((u + e) + w) + 0.5 * H * H * 2.0);
        s + K * ((u + e) + 2.0 * H)
    };
    assert_eq!(got.to_bits(), ((y(eps) - y(-eps)) / (2.0 * eps)).to_bits());
    // the next held step: asked again
    fmu.do_step(2.0 * H, H).unwrap();
    assert_eq!(derivative(&mut fmu, &[U], &[1.0]), H + K);
    assert_eq!(asked.lock().unwrap().len(), 1);
}

/// An answer that is not finite is refused, naming the output, as the
/// differences' are.
#[test]
fn a_step_derivative_that_is_not_finite_is_refused() {
    let (mut fmu, asked, _) = stepped(true, 0.8, OVERFLOW);
    let mut d = [0.0];
    let err = fmu
        .directional_derivative(&[Y], &[W], &[1.0], &mut d)
        .unwrap_err();
    assert!(err.contains("the directional derivative of y"), "{err}");
    assert_eq!(asked.lock().unwrap().len(), 1);
}
