//! `MaxwellSlip.fmu` and `GMS.fmu`: `N` elasto-slide elements in parallel
//! (docs/models.md "Maxwell-slip and GMS"). Maxwell-slip (Lampaert,
//! Swevers, Al-Bender 2002) slides each element at a constant force
//! `W_i`; the Generalized Maxwell-Slip model (Al-Bender, Lampaert,
//! Swevers 2005) at its share `α_i` of the Stribeck curve, with an
//! attraction `C` that gives frictional lag. In Co-Simulation,
//! Maxwell-slip's update is exact, GMS's exact for a held velocity with
//! every element's switch located inside the step. In Model Exchange the
//! element forces `F_element[i]` are the continuous states (all 100 are
//! declared, as FMI 2.0 fixes their number; those past `n_elements` stay
//! 0), each element's stick/slip switch has an event indicator, and the
//! reversal is `v`'s.
//!
//! The element arrays are `k[i]` and `W[i]` (or `alpha[i]`), `i` =
//! 1..=100; `n_elements` says how many are used. GMS's micro-damping
//! `sigma1` (each element's `σ_i·ż_i`, the total shared in proportion to
//! stiffness) came later and follows the arrays. Both FMUs are one
//! generic model, [`ElementsFmu`], over the two laws ([`ElementLaw`]).

use crate::{input_ramp, param_err, sliding_velocity_input};
use fmi_export::{
    Capabilities, ContinuousState, DefaultExperiment, Model, ModelExchange, ModelInfo, Ode, Values,
    Variable,
};
use friction_laws::maxwell_slip::{Gms, GmsParams, MaxwellSlip, MaxwellSlipParams, MAX_ELEMENTS};
use friction_laws::Ramp;
use std::sync::LazyLock;

/// Value references: 0..=6 shared by both FMUs, 7..=11 GMS's curve, then
/// the arrays (at [`Layout`]'s bases: value references are the positions
/// in the variable table, so each FMU's arrays follow its last scalar),
/// then GMS's `sigma1` (412), appended after its arrays so that no value
/// reference of the first GMS moved (FMI 3.0's `time` and event
/// indicators, which follow the table, moved up by one).
pub mod vr {
    pub const V: u32 = 0;
    pub const F: u32 = 1;
    pub const P_DISS: u32 = 2;
    pub const E_STORED: u32 = 3;
    pub const N_SLIPPING: u32 = 4;
    pub const SIGMA2: u32 = 5;
    pub const N_ELEMENTS: u32 = 6;
    /// GMS only: the Stribeck curve and the attraction.
    pub const FC: u32 = 7;
    pub const FS: u32 = 8;
    pub const VS: u32 = 9;
    pub const STRIBECK_EXPONENT: u32 = 10;
    pub const C: u32 = 11;
    /// GMS only: the total micro-damping, after GMS's four arrays.
    pub const SIGMA1: u32 = C + 1 + 4 * super::MAX_ELEMENTS as u32;
}

/// Where an FMU's arrays start (each of `MAX_ELEMENTS` values, element
/// `i` = 1..=100 at `base + i − 1`): `k[i]`; `W[i]` (Maxwell-slip) or
/// `alpha[i]` (GMS); the states `F_element[i]`; their derivatives.
#[derive(Clone, Copy)]
pub struct Layout {
    pub k: u32,
    pub second: u32,
    pub state: u32,
    pub derivative: u32,
}

impl Layout {
    const fn after(last_scalar: u32) -> Layout {
        let n = MAX_ELEMENTS as u32;
        Layout {
            k: last_scalar + 1,
            second: last_scalar + 1 + n,
            state: last_scalar + 1 + 2 * n,
            derivative: last_scalar + 1 + 3 * n,
        }
    }

    /// Element index of a state's value reference.
    fn state_index(&self, vr: u32) -> Option<usize> {
        (self.state..self.state + MAX_ELEMENTS as u32)
            .contains(&vr)
            .then(|| (vr - self.state) as usize)
    }

    /// Element index of a derivative's value reference.
    fn derivative_index(&self, vr: u32) -> Option<usize> {
        (self.derivative..self.derivative + MAX_ELEMENTS as u32)
            .contains(&vr)
            .then(|| (vr - self.derivative) as usize)
    }
}

pub const MAXWELL_SLIP_LAYOUT: Layout = Layout::after(vr::N_ELEMENTS);

pub const GMS_LAYOUT: Layout = Layout::after(vr::C);

/// The variables before the arrays.
fn common(law: &str, sigma2: f64) -> Vec<Variable> {
    let slip = if law == "GMS" {
        "alpha[i]*s(v)"
    } else {
        "W[i]"
    };
    let leak = |s: String| -> &'static str { Box::leak(s.into_boxed_str()) };
    vec![
        sliding_velocity_input(vr::V),
        Variable::output(
            vr::F,
            "F",
            "N",
            if law == "GMS" {
                "Friction force F = sum of the element forces F_i + sum of the element dampings sigma_i*dz_i/dt (sigma_i = sigma1*k[i]/sum k, dz_i/dt = v sticking, dF_i/dt/k[i] slipping) + sigma2*v, resisting positive motion (the rig applies -F)"
            } else {
                "Friction force F = sum of the element forces F_i + sigma2*v, resisting positive motion (the rig applies -F)"
            },
            &[vr::V],
        ),
        Variable::output(
            vr::P_DISS,
            "P_diss",
            "W",
            leak(format!(
                "Power the contact dissipates, F*v - dE_stored/dt: the slipping elements' share plus sigma2*v^2{}",
                if law == "GMS" {
                    ", plus the element dampings' sum of sigma_i*dz_i/dt*v (a slipping element attracted faster than the motion loads it returns energy: P_diss can be negative for a while)"
                } else {
                    " = sum over sliding elements of W[i]*|v| + sigma2*v^2, never negative"
                }
            )),
            &[vr::V],
        ),
        Variable::output(
            vr::E_STORED,
            "E_stored",
            "J",
            "Elastic energy of the elements, sum of F_i^2/(2*k[i])",
            &[],
        ),
        Variable::integer_output(
            vr::N_SLIPPING,
            "n_slipping",
            leak(format!(
                "Number of elements sliding (their force at {slip}); the others stick and load at k[i]*v"
            )),
            &[vr::V],
        ),
        Variable::parameter(vr::SIGMA2, "sigma2", sigma2, "N.s/m", "Viscous coefficient")
            .with_min(0.0),
        Variable::integer_parameter(
            vr::N_ELEMENTS,
            "n_elements",
            10,
            "Number of elements used, 1..100: k[1..n_elements] and the second array",
        ),
    ]
}

/// `k[1..=100]` and the second array, with the defaults of the first
/// `defaults.0.len()` elements (the last one repeated beyond).
fn arrays(
    at: Layout,
    second: &'static str,
    unit: &'static str,
    second_description: &'static str,
    defaults: (Vec<f64>, Vec<f64>),
) -> Vec<Variable> {
    let name = |base: &str, i: usize| -> &'static str {
        Box::leak(format!("{base}[{i}]").into_boxed_str())
    };
    let pick = |d: &[f64], i: usize| d[i.min(d.len() - 1)];
    let mut v = Vec::with_capacity(2 * MAX_ELEMENTS);
    for i in 0..MAX_ELEMENTS {
        v.push(
            Variable::parameter(
                at.k + i as u32,
                name("k", i + 1),
                pick(&defaults.0, i),
                "N/m",
                "Stiffness of element i (> 0)",
            )
            .with_min(0.0),
        );
    }
    for i in 0..MAX_ELEMENTS {
        v.push(
            Variable::parameter(
                at.second + i as u32,
                name(second, i + 1),
                pick(&defaults.1, i),
                unit,
                second_description,
            )
            .with_min(0.0),
        );
    }
    for i in 0..MAX_ELEMENTS {
        v.push(Variable::state(
            at.state + i as u32,
            name("F_element", i + 1),
            "N",
            "Force of element i, the spring k[i] between the body and the element's end on the surface (0 at the start; 0 past n_elements)",
        ));
    }
    let states: &'static [u32] = Box::leak(
        (0..MAX_ELEMENTS as u32)
            .map(|i| at.state + i)
            .collect::<Vec<_>>()
            .into_boxed_slice(),
    );
    for i in 0..MAX_ELEMENTS {
        v.push(Variable::derivative(
            at.derivative + i as u32,
            Box::leak(format!("der(F_element[{}])", i + 1).into_boxed_str()),
            "N/s",
            "dF_element[i]/dt: k[i]*v while element i sticks, its slip law while it slips (Model Exchange)",
            &[vr::V],
            &states[i..i + 1],
        ));
    }
    v
}

/// The outputs' dependencies on the states (all of them), for the
/// model structure.
fn with_states(variables: &mut [Variable], at: Layout) {
    let states: &'static [u32] = Box::leak(
        (0..MAX_ELEMENTS as u32)
            .map(|i| at.state + i)
            .collect::<Vec<_>>()
            .into_boxed_slice(),
    );
    for v in variables.iter_mut() {
        if [vr::F, vr::P_DISS, vr::E_STORED].contains(&v.vr) {
            *v = v.with_state_dependencies(states);
        }
    }
}

/// The Model Exchange declaration: 100 states, an event indicator for
/// `v` and one per element.
fn model_exchange(at: Layout) -> ModelExchange {
    let states: Vec<ContinuousState> = (0..MAX_ELEMENTS as u32)
        .map(|i| ContinuousState {
            state: at.state + i,
            derivative: at.derivative + i,
        })
        .collect();
    ModelExchange {
        states: Box::leak(states.into_boxed_slice()),
        event_indicators: 1 + MAX_ELEMENTS,
        states_jump_at_events: false,
    }
}

/// The element arrays' first `n` values.
fn element_arrays(values: &Values, at: Layout) -> (Vec<f64>, Vec<f64>) {
    let n = values.integer(vr::N_ELEMENTS).clamp(0, MAX_ELEMENTS as i32) as usize;
    let k = (0..n).map(|i| values.real(at.k + i as u32)).collect();
    let s = (0..n).map(|i| values.real(at.second + i as u32)).collect();
    (k, s)
}

/// `n_elements` outside 1..=100, refused by name (the arrays hold 100).
fn check_count(values: &Values) -> Result<(), String> {
    let n = values.integer(vr::N_ELEMENTS);
    if !(1..=MAX_ELEMENTS as i32).contains(&n) {
        return Err(format!(
            "parameter n_elements = {n}: must be between 1 and {MAX_ELEMENTS}"
        ));
    }
    Ok(())
}

const EXPERIMENT: DefaultExperiment = DefaultExperiment {
    start_time: 0.0,
    stop_time: 1.0,
    step_size: 1e-3,
};

pub static MAXWELL_SLIP_INFO: LazyLock<ModelInfo> = LazyLock::new(|| {
    let d = MaxwellSlipParams::default();
    let mut variables = common("MaxwellSlip", d.sigma2);
    variables.extend(arrays(
        MAXWELL_SLIP_LAYOUT,
        "W",
        "N",
        "Slip force of element i (> 0): the element sticks until |F_i| reaches it, then slides at it until the motion reverses",
        (d.k, d.w),
    ));
    with_states(&mut variables, MAXWELL_SLIP_LAYOUT);
    ModelInfo {
        model_name: "MaxwellSlip",
        model_identifier: "MaxwellSlip",
        guid: "{6a1f0c3e-8d27-4b95-b4e1-3f9c27d85a10}",
        description: "Maxwell-slip friction: n elasto-slide elements in parallel, F = sum F_i + sigma2*v; element i sticks (dF_i/dt = k[i]*v) until |F_i| = W[i], then slides at +-W[i] until the motion reverses. Rate-independent, with nonlocal memory (minor loops are wiped out).",
        source: "Lampaert, Swevers, Al-Bender 2002; Iwan 1966; Al-Bender, Lampaert, Swevers 2005. Default elements ours (LuGre's 1995 sigma0 and Fc). See docs/models.md.",
        variables: Box::leak(variables.into_boxed_slice()),
        default_experiment: EXPERIMENT,
        capabilities: Capabilities::FULL,
        co_simulation_states: &[],
        model_exchange: Some(model_exchange(MAXWELL_SLIP_LAYOUT)),
    }
});

pub static GMS_INFO: LazyLock<ModelInfo> = LazyLock::new(|| {
    let d = GmsParams::default();
    let mut variables = common("GMS", d.sigma2);
    variables.extend([
        Variable::parameter(vr::FC, "Fc", d.fc, "N", "Coulomb level of the Stribeck curve s(v)")
            .with_min(0.0),
        Variable::parameter(vr::FS, "Fs", d.fs, "N", "Static level, >= Fc").with_min(0.0),
        Variable::parameter(vr::VS, "vs", d.vs, "m/s", "Stribeck velocity").with_min(0.0),
        Variable::parameter(
            vr::STRIBECK_EXPONENT,
            "stribeck_exponent",
            d.delta,
            "",
            "Stribeck exponent delta in s(v) = Fc + (Fs - Fc)*exp(-|v/vs|^delta)",
        )
        .with_min(0.0),
        Variable::parameter(
            vr::C,
            "C",
            d.c,
            "N/s",
            "Attraction of a slipping element to its level, dF_i/dt = C*(sgn(v)*alpha[i] - F_i/s(v)): in gross sliding F relaxes to s(v) with the time constant s(v)/C (frictional lag)",
        )
        .with_min(0.0),
    ]);
    variables.extend(arrays(
        GMS_LAYOUT,
        "alpha",
        "",
        "Weight of element i (> 0; the n_elements weights sum to 1): the element sticks until sgn(v)*F_i reaches alpha[i]*s(v), then slips towards it until the motion reverses",
        (d.k, d.alpha),
    ));
    with_states(&mut variables, GMS_LAYOUT);
    variables.push(
        Variable::parameter(
            vr::SIGMA1,
            "sigma1",
            d.sigma1,
            "N.s/m",
            "Micro-damping, the elements' total: element i has sigma_i = sigma1*k[i]/sum k and adds sigma_i*dz_i/dt to F (dz_i/dt = v sticking, dF_i/dt/k[i] slipping); while every element sticks it adds sigma1*v",
        )
        .with_min(0.0),
    );
    ModelInfo {
        model_name: "GMS",
        model_identifier: "GMS",
        guid: "{d4e8b2a7-19c6-4f03-9a5d-7e2c61b0f8d9}",
        description: "Generalized Maxwell-Slip friction: n elasto-slide elements in parallel, F = sum (F_i + sigma_i*dz_i/dt) + sigma2*v; element i sticks (dF_i/dt = k[i]*v) until sgn(v)*F_i = alpha[i]*s(v), then slips with dF_i/dt = C*(sgn(v)*alpha[i] - F_i/s(v)) until the motion reverses. Pre-sliding hysteresis with nonlocal memory, Stribeck, frictional lag.",
        source: "Al-Bender, Lampaert, Swevers 2005; Lampaert, Swevers, Al-Bender 2002. Default elements and C ours, on LuGre's 1995 levels. See docs/models.md.",
        variables: Box::leak(variables.into_boxed_slice()),
        default_experiment: EXPERIMENT,
        capabilities: Capabilities::FULL,
        co_simulation_states: &[],
        model_exchange: Some(model_exchange(GMS_LAYOUT)),
    }
});

/// What the FMU layer needs of an element law (the two laws' methods of
/// the same names).
pub trait ElementLaw: Clone + std::fmt::Debug + Send + 'static {
    fn info() -> &'static ModelInfo;
    fn layout() -> Layout;
    fn default_law() -> Self;
    /// The law from the parameters in `values` (`n_elements` checked).
    fn from_values(values: &Values) -> Result<Self, String>;
    /// The slip level of element `i` at rest, from the parameters in
    /// `values` (a state's nominal scale).
    fn nominal(values: &Values, i: usize) -> f64;
    fn k(&self) -> &[f64];
    fn sigma2(&self) -> f64;
    /// The micro-damping per unit of element stiffness, `σ_i/k_i` (GMS:
    /// `σ1/Σ k_j`; Maxwell-slip: 0): `F` has `damping·Σ Ḟ_i`.
    fn damping(&self) -> f64;
    fn forces(&self) -> &[f64];
    fn set_forces(&mut self, f: &[f64]);
    fn step(&mut self, v: Ramp, h: f64);
    fn force(&self, v: f64) -> f64;
    fn dissipated_power(&self, v: f64) -> f64;
    fn stored_energy(&self) -> f64;
    fn slips(&self, i: usize, v: f64) -> bool;
    fn rate(&self, i: usize, v: f64) -> f64;
    fn rate_partials(&self, i: usize, v: f64) -> (f64, f64);
    fn update_modes(&mut self, v: f64) -> bool;
    fn indicator(&self, i: usize, v: f64) -> f64;
    fn state_len(&self) -> usize;
    fn write_state_into(&self, out: &mut [f64]);
    fn state_is_finite(&self) -> bool;
    fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String>;
}

/// The trait's methods that both laws have under the same names.
macro_rules! element_law_methods {
    () => {
        fn forces(&self) -> &[f64] {
            self.element_forces()
        }
        fn set_forces(&mut self, f: &[f64]) {
            self.set_element_forces(f)
        }
        fn step(&mut self, v: Ramp, h: f64) {
            Self::step(self, v, h)
        }
        fn force(&self, v: f64) -> f64 {
            Self::force(self, v)
        }
        fn dissipated_power(&self, v: f64) -> f64 {
            Self::dissipated_power(self, v)
        }
        fn stored_energy(&self) -> f64 {
            Self::stored_energy(self)
        }
        fn rate(&self, i: usize, v: f64) -> f64 {
            self.element_rate(i, v)
        }
        fn rate_partials(&self, i: usize, v: f64) -> (f64, f64) {
            self.element_rate_partials(i, v)
        }
        fn update_modes(&mut self, v: f64) -> bool {
            Self::update_modes(self, v)
        }
        fn indicator(&self, i: usize, v: f64) -> f64 {
            self.element_indicator(i, v)
        }
        fn state_len(&self) -> usize {
            Self::state_len(self)
        }
        fn write_state_into(&self, out: &mut [f64]) {
            Self::write_state_into(self, out)
        }
        fn state_is_finite(&self) -> bool {
            Self::state_is_finite(self)
        }
        fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
            Self::state_from_slice(self, s)
        }
        fn k(&self) -> &[f64] {
            &self.params().k
        }
        fn sigma2(&self) -> f64 {
            self.params().sigma2
        }
    };
}

impl ElementLaw for MaxwellSlip {
    fn info() -> &'static ModelInfo {
        &MAXWELL_SLIP_INFO
    }
    fn layout() -> Layout {
        MAXWELL_SLIP_LAYOUT
    }
    fn default_law() -> Self {
        MaxwellSlip::new(MaxwellSlipParams::default()).expect("default parameters are valid")
    }
    fn from_values(values: &Values) -> Result<Self, String> {
        check_count(values)?;
        let (k, w) = element_arrays(values, MAXWELL_SLIP_LAYOUT);
        let p = MaxwellSlipParams {
            k,
            w,
            sigma2: values.real(vr::SIGMA2),
        };
        MaxwellSlip::new(p).map_err(param_err)
    }
    fn nominal(values: &Values, i: usize) -> f64 {
        values.real(MAXWELL_SLIP_LAYOUT.second + i as u32)
    }
    fn slips(&self, i: usize, v: f64) -> bool {
        self.slipping(i, v)
    }
    fn damping(&self) -> f64 {
        0.0
    }
    element_law_methods!();
}

impl ElementLaw for Gms {
    fn info() -> &'static ModelInfo {
        &GMS_INFO
    }
    fn layout() -> Layout {
        GMS_LAYOUT
    }
    fn default_law() -> Self {
        Gms::new(GmsParams::default()).expect("default parameters are valid")
    }
    fn from_values(values: &Values) -> Result<Self, String> {
        check_count(values)?;
        let (k, alpha) = element_arrays(values, GMS_LAYOUT);
        let p = GmsParams {
            k,
            alpha,
            fc: values.real(vr::FC),
            fs: values.real(vr::FS),
            vs: values.real(vr::VS),
            delta: values.real(vr::STRIBECK_EXPONENT),
            c: values.real(vr::C),
            sigma1: values.real(vr::SIGMA1),
            sigma2: values.real(vr::SIGMA2),
        };
        Gms::new(p).map_err(param_err)
    }
    fn nominal(values: &Values, i: usize) -> f64 {
        values.real(GMS_LAYOUT.second + i as u32) * values.real(vr::FS)
    }
    fn slips(&self, i: usize, _v: f64) -> bool {
        self.slipping(i)
    }
    fn damping(&self) -> f64 {
        self.damping_per_stiffness()
    }
    element_law_methods!();
}

/// An FMU of `n` elements in parallel: `MaxwellSlip.fmu` with
/// `L = MaxwellSlip`, `GMS.fmu` with `L = Gms`.
#[derive(Clone, Debug)]
pub struct ElementsFmu<L: ElementLaw> {
    law: L,
    /// The Model Exchange states past `n_elements`: kept as the importer
    /// set them (their derivatives are 0; nothing reads them).
    unused: Vec<f64>,
}

pub type MaxwellSlipFmu = ElementsFmu<MaxwellSlip>;
pub type GmsFmu = ElementsFmu<Gms>;

impl<L: ElementLaw> Default for ElementsFmu<L> {
    fn default() -> Self {
        let law = L::default_law();
        let unused = vec![0.0; MAX_ELEMENTS - law.forces().len()];
        ElementsFmu { law, unused }
    }
}

impl<L: ElementLaw> Model for ElementsFmu<L> {
    fn info(&self) -> &'static ModelInfo {
        L::info()
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        self.law = L::from_values(values)?;
        self.unused = vec![0.0; MAX_ELEMENTS - self.law.forces().len()];
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let v = values.real(vr::V);
        values.set(vr::F, self.law.force(v));
        values.set(vr::P_DISS, self.law.dissipated_power(v));
        values.set(vr::E_STORED, self.law.stored_energy());
        let n = self.law.forces().len();
        let slipping = (0..n).filter(|&i| self.law.slips(i, v)).count();
        values.set_integer(vr::N_SLIPPING, slipping as i32);
        let at = L::layout();
        for (i, f) in self.law.forces().iter().chain(&self.unused).enumerate() {
            values.set(at.state + i as u32, *f);
        }
    }

    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        self.law.step(input_ramp(values, slopes, vr::V), h);
        Ok(())
    }

    // the law's state, then the unused Model Exchange states
    fn save_state(&self, out: &mut Vec<f64>) {
        let start = out.len();
        out.resize(start + self.law.state_len(), 0.0);
        self.law.write_state_into(&mut out[start..]);
        out.extend_from_slice(&self.unused);
    }

    fn state_len(&self) -> Option<usize> {
        Some(self.law.state_len() + self.unused.len())
    }

    fn write_state_into(&self, out: &mut [f64]) {
        let (law, unused) = out.split_at_mut(self.law.state_len());
        self.law.write_state_into(law);
        unused.copy_from_slice(&self.unused);
    }

    fn state_is_finite(&self) -> Option<bool> {
        Some(self.law.state_is_finite() && self.unused.iter().all(|x| x.is_finite()))
    }

    fn restore_state(&mut self, state: &[f64]) -> Result<(), String> {
        let n = self.law.state_len();
        let expected = n + self.unused.len();
        if state.len() != expected {
            return Err(format!(
                "state has {} values, {} expected (the law's {n} and {} unused Model Exchange states)",
                state.len(),
                expected,
                self.unused.len()
            ));
        }
        if let Some(x) = state[n..].iter().find(|x| !x.is_finite()) {
            return Err(format!("an unused Model Exchange state is {x}, not finite"));
        }
        self.law.state_from_slice(&state[..n])?;
        self.unused.copy_from_slice(&state[n..]);
        Ok(())
    }

    fn clone_model(&self) -> Box<dyn Model> {
        Box::new(self.clone())
    }

    /// Directional derivatives of a step by replaying it (the step
    /// moves the element forces with `v`).
    fn supplies_partial_derivatives(&self) -> bool {
        false
    }

    /// `dF/dt = Σ Ḟ_i + d·Σ dḞ_i/dt + σ2·dv/dt` in the current modes,
    /// `d` = [`ElementLaw::damping`] and `dḞ_i/dt = ∂Ḟ_i/∂F_i·Ḟ_i +
    /// ∂Ḟ_i/∂v·dv/dt`.
    fn output_derivative(&self, values: &Values, slopes: &[f64], output: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let slope = slopes[vr::V as usize];
        let n = self.law.forces().len();
        let elements: f64 = (0..n).map(|i| self.law.rate(i, v)).sum();
        let d = self.law.damping();
        if d == 0.0 {
            return (output == vr::F).then(|| elements + self.law.sigma2() * slope);
        }
        let damping: f64 = (0..n)
            .map(|i| {
                let (by_f, by_v) = self.law.rate_partials(i, v);
                by_f * self.law.rate(i, v) + by_v * slope
            })
            .sum();
        (output == vr::F).then(|| elements + d * damping + self.law.sigma2() * slope)
    }

    /// `Ḟ_i` in the current modes; 0 past `n_elements`.
    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        let v = values.real(vr::V);
        let n = self.law.forces().len();
        for (i, d) in dx.iter_mut().enumerate() {
            *d = if i < n { self.law.rate(i, v) } else { 0.0 };
        }
    }

    fmi_export::ode_is_self!();
}

/// Model Exchange: the states are the element forces; indicator 0 is
/// `v` (a reversal sticks the slipping elements), indicator `i` the
/// element's distance to its slip level while it sticks (1 while it
/// slips, and past `n_elements`); the event update switches the modes.
impl<L: ElementLaw> Ode for ElementsFmu<L> {
    fn continuous_states(&self, x: &mut [f64]) {
        let n = self.law.forces().len();
        x[..n].copy_from_slice(self.law.forces());
        x[n..].copy_from_slice(&self.unused);
    }

    /// The first `n_elements` states are the element forces; the others
    /// are kept as given.
    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        let n = self.law.forces().len();
        self.law.set_forces(&x[..n]);
        self.unused.copy_from_slice(&x[n..]);
        Ok(())
    }

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        let v = values.real(vr::V);
        let n = self.law.forces().len();
        z[0] = v;
        for (i, z) in z[1..].iter_mut().enumerate() {
            *z = if i < n { self.law.indicator(i, v) } else { 1.0 };
        }
    }

    /// Each element force on the scale of its slip level at rest.
    fn nominals(&self, values: &Values, nominal: &mut [f64]) {
        for (i, n) in nominal.iter_mut().enumerate() {
            *n = L::nominal(values, i);
        }
    }

    /// Switches the modes; the forces do not jump.
    fn event_update(&mut self, values: &Values) -> bool {
        self.law.update_modes(values.real(vr::V));
        false
    }

    /// In closed form: `der(F_element[i])` has `∂/∂F_i` and `∂/∂v` from
    /// the law; `F = Σ F_i + d·Σ Ḟ_i + σ2·v` (`d` =
    /// [`ElementLaw::damping`], GMS's `Σ σ_i·ż_i`); `E_stored = Σ
    /// F_i²/(2·k_i)`; `P_diss = Σ_slipping F_i·(v − Ḟ_i/k_i) + d·Σ Ḟ_i·v
    /// + σ2·v²`. Past `n_elements` every partial is 0.
    fn partial_derivative(&self, values: &Values, unknown: u32, known: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let at = L::layout();
        let n = self.law.forces().len();
        let f = self.law.forces();
        let k = self.law.k();
        // the state known: Some(i) for element i, None for v
        let by_state = match at.state_index(known) {
            Some(i) => Some(i),
            None if known == vr::V => None,
            None => return None,
        };
        if let Some(i) = at.derivative_index(unknown) {
            return Some(match by_state {
                _ if i >= n => 0.0,
                Some(j) if j != i => 0.0,
                Some(_) => self.law.rate_partials(i, v).0,
                None => self.law.rate_partials(i, v).1,
            });
        }
        let slipping = |i: usize| i < n && self.law.slips(i, v);
        // the damping d·Σ Ḟ_i (0 without): its partials by F_i (i < n) and v
        let d = self.law.damping();
        let damped = d != 0.0;
        let damping_by_f = |i: usize| d * self.law.rate_partials(i, v).0;
        let damping_by_v = || d * (0..n).map(|i| self.law.rate_partials(i, v).1).sum::<f64>();
        Some(match (unknown, by_state) {
            (vr::F, Some(i)) if damped && i < n => 1.0 + damping_by_f(i),
            (vr::F, Some(i)) => (i < n) as u8 as f64,
            (vr::F, None) if damped => self.law.sigma2() + damping_by_v(),
            (vr::F, None) => self.law.sigma2(),
            (vr::E_STORED, Some(i)) if i < n => f[i] / k[i],
            (vr::E_STORED, _) => 0.0,
            (vr::P_DISS, Some(i)) if slipping(i) => {
                let (by_f, _) = self.law.rate_partials(i, v);
                let element = v - self.law.rate(i, v) / k[i] - f[i] * by_f / k[i];
                if damped {
                    element + damping_by_f(i) * v
                } else {
                    element
                }
            }
            // a sticking element's Ḟ_i = k_i·v does not depend on F_i
            (vr::P_DISS, Some(_)) => 0.0,
            (vr::P_DISS, None) => {
                let elements: f64 = (0..n)
                    .filter(|&i| slipping(i))
                    .map(|i| f[i] * (1.0 - self.law.rate_partials(i, v).1 / k[i]))
                    .sum();
                if !damped {
                    return Some(elements + 2.0 * self.law.sigma2() * v);
                }
                let rates: f64 = (0..n).map(|i| self.law.rate(i, v)).sum();
                elements + d * rates + damping_by_v() * v + 2.0 * self.law.sigma2() * v
            }
            _ => return None,
        })
    }
}
