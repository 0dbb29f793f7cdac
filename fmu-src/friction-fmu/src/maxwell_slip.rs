//! `MaxwellSlip.fmu` and `GMS.fmu`: `N` elasto-slide elements in parallel
//! (docs/models.md "Maxwell-slip and GMS"). Maxwell-slip (Lampaert,
//! Swevers, Al-Bender 2002) slides each element at a constant force
//! `W_i`; the Generalized Maxwell-Slip model (Al-Bender, Lampaert,
//! Swevers 2005) at its share `α_i` of the Stribeck curve, with an
//! attraction `C` that gives frictional lag. Co-Simulation only for
//! now: Maxwell-slip's update is exact, GMS's exact for a held velocity
//! with every element's switch located inside the step.
//!
//! The element arrays are `k[i]` and `W[i]` (or `alpha[i]`), `i` =
//! 1..=100; `n_elements` says how many are used.

use crate::{input_ramp, param_err, sliding_velocity_input};
use fmi2_cs::{Capabilities, DefaultExperiment, Model, ModelInfo, Values, Variable};
use friction_laws::maxwell_slip::{Gms, GmsParams, MaxwellSlip, MaxwellSlipParams, MAX_ELEMENTS};
use std::sync::LazyLock;

/// Value references: 0..=6 shared by both FMUs, 7..=11 GMS's curve, then
/// the arrays (at [`Layout`]'s bases: value references are the positions
/// in the variable table, so each FMU's arrays follow its last scalar).
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
}

/// Where an FMU's arrays start: `k[i]`, i = 1..=100, at `k + i − 1`;
/// `W[i]` (Maxwell-slip) or `alpha[i]` (GMS) at `second + i − 1`.
#[derive(Clone, Copy)]
pub struct Layout {
    pub k: u32,
    pub second: u32,
}

pub const MAXWELL_SLIP_LAYOUT: Layout = Layout {
    k: vr::N_ELEMENTS + 1,
    second: vr::N_ELEMENTS + 1 + MAX_ELEMENTS as u32,
};

pub const GMS_LAYOUT: Layout = Layout {
    k: vr::C + 1,
    second: vr::C + 1 + MAX_ELEMENTS as u32,
};

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
            "Friction force F = sum of the element forces F_i + sigma2*v, resisting positive motion (the rig applies -F)",
            &[vr::V],
        ),
        Variable::output(
            vr::P_DISS,
            "P_diss",
            "W",
            leak(format!(
                "Power the contact dissipates, F*v - dE_stored/dt: the slipping elements' share plus sigma2*v^2{}",
                if law == "GMS" {
                    " (a slipping element attracted faster than the motion loads it returns energy: P_diss can be negative for a while)"
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
    v
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
    ModelInfo {
        model_name: "MaxwellSlip",
        model_identifier: "MaxwellSlip",
        guid: "{6a1f0c3e-8d27-4b95-b4e1-3f9c27d85a10}",
        description: "Maxwell-slip friction: n elasto-slide elements in parallel, F = sum F_i + sigma2*v; element i sticks (dF_i/dt = k[i]*v) until |F_i| = W[i], then slides at +-W[i] until the motion reverses. Rate-independent, with nonlocal memory (minor loops are wiped out).",
        source: "Lampaert, Swevers, Al-Bender 2002; Iwan 1966; Al-Bender, Lampaert, Swevers 2005. Default elements ours (LuGre's 1995 sigma0 and Fc). See docs/models.md.",
        variables: Box::leak(variables.into_boxed_slice()),
        default_experiment: EXPERIMENT,
        capabilities: Capabilities::FULL,
        model_exchange: None,
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
    ModelInfo {
        model_name: "GMS",
        model_identifier: "GMS",
        guid: "{d4e8b2a7-19c6-4f03-9a5d-7e2c61b0f8d9}",
        description: "Generalized Maxwell-Slip friction: n elasto-slide elements in parallel, F = sum F_i + sigma2*v; element i sticks (dF_i/dt = k[i]*v) until sgn(v)*F_i = alpha[i]*s(v), then slips with dF_i/dt = C*(sgn(v)*alpha[i] - F_i/s(v)) until the motion reverses. Pre-sliding hysteresis with nonlocal memory, Stribeck, frictional lag.",
        source: "Al-Bender, Lampaert, Swevers 2005; Lampaert, Swevers, Al-Bender 2002. Default elements and C ours, on LuGre's 1995 levels. See docs/models.md.",
        variables: Box::leak(variables.into_boxed_slice()),
        default_experiment: EXPERIMENT,
        capabilities: Capabilities::FULL,
        model_exchange: None,
    }
});

#[derive(Clone, Debug)]
pub struct MaxwellSlipFmu {
    law: MaxwellSlip,
}

impl Default for MaxwellSlipFmu {
    fn default() -> Self {
        MaxwellSlipFmu {
            law: MaxwellSlip::new(MaxwellSlipParams::default())
                .expect("default parameters are valid"),
        }
    }
}

impl Model for MaxwellSlipFmu {
    fn info(&self) -> &'static ModelInfo {
        &MAXWELL_SLIP_INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        check_count(values)?;
        let (k, w) = element_arrays(values, MAXWELL_SLIP_LAYOUT);
        let p = MaxwellSlipParams {
            k,
            w,
            sigma2: values.real(vr::SIGMA2),
        };
        self.law = MaxwellSlip::new(p).map_err(param_err)?;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let v = values.real(vr::V);
        values.set(vr::F, self.law.force(v));
        values.set(vr::P_DISS, self.law.dissipated_power(v));
        values.set(vr::E_STORED, self.law.stored_energy());
        values.set_integer(vr::N_SLIPPING, self.law.slipping_count(v) as i32);
    }

    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        self.law.step(input_ramp(values, slopes, vr::V), h);
        Ok(())
    }

    fmi2_cs::delegate_state!(law);

    /// Directional derivatives of a step by replaying it (the step
    /// moves the element forces with `v`).
    fn supplies_partial_derivatives(&self) -> bool {
        false
    }

    /// `dF/dt = Σ Ḟ_i + σ2·dv/dt`.
    fn output_derivative(&self, values: &Values, slopes: &[f64], output: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let elements: f64 = (0..self.law.params().k.len())
            .map(|i| self.law.element_rate(i, v))
            .sum();
        (output == vr::F).then(|| elements + self.law.params().sigma2 * slopes[vr::V as usize])
    }
}

#[derive(Clone, Debug)]
pub struct GmsFmu {
    law: Gms,
}

impl Default for GmsFmu {
    fn default() -> Self {
        GmsFmu {
            law: Gms::new(GmsParams::default()).expect("default parameters are valid"),
        }
    }
}

impl Model for GmsFmu {
    fn info(&self) -> &'static ModelInfo {
        &GMS_INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
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
            sigma2: values.real(vr::SIGMA2),
        };
        self.law = Gms::new(p).map_err(param_err)?;
        Ok(())
    }

    fn compute_outputs(&self, values: &mut Values) {
        let v = values.real(vr::V);
        values.set(vr::F, self.law.force(v));
        values.set(vr::P_DISS, self.law.dissipated_power(v));
        values.set(vr::E_STORED, self.law.stored_energy());
        values.set_integer(vr::N_SLIPPING, self.law.slipping_count() as i32);
    }

    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        self.law.step(input_ramp(values, slopes, vr::V), h);
        Ok(())
    }

    fmi2_cs::delegate_state!(law);

    /// Directional derivatives of a step by replaying it.
    fn supplies_partial_derivatives(&self) -> bool {
        false
    }

    /// `dF/dt = Σ Ḟ_i + σ2·dv/dt`.
    fn output_derivative(&self, values: &Values, slopes: &[f64], output: u32) -> Option<f64> {
        let v = values.real(vr::V);
        let elements: f64 = (0..self.law.params().k.len())
            .map(|i| self.law.element_rate(i, v))
            .sum();
        (output == vr::F).then(|| elements + self.law.params().sigma2 * slopes[vr::V as usize])
    }
}
