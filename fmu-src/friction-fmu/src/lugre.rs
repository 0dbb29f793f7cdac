//! `LuGre.fmu`: the LuGre law (Canudas de Wit et al. 1995; Sun et al. 2016
//! eq. 9–12; docs/models.md "LuGre") with the extensions the slider of
//! Thimmalapura 2004 and the tribometer of Dion et al. 2013 need:
//! velocity-dependent micro-damping, direction-dependent levels,
//! position-dependent levels (a table of scale factors over `x`), and the
//! normal-force form. In Model Exchange, with every option, the deflection
//! `z` is the continuous state and `dz/dt` ([`LuGre::z_rate`]) its
//! derivative.

use crate::{param_err, sliding_velocity_input};
use fmi_export::{
    Capabilities, ContinuousState, DefaultExperiment, Model, ModelExchange, ModelInfo, Ode, Values,
    Variable,
};
use friction_laws::lugre::parameter_sensitivity::Parameter;
use friction_laws::lugre::{HeldInput, LuGre, LuGreInputs, LuGreParams, TABLE_POINTS};
use friction_laws::Ramp;
use std::sync::LazyLock;

pub mod vr {
    pub const V: u32 = 0;
    pub const X: u32 = 1;
    pub const FN: u32 = 2;
    pub const F: u32 = 3;
    pub const Z: u32 = 4;
    pub const SLIDING: u32 = 5;
    pub const SIGMA0: u32 = 6;
    pub const SIGMA1: u32 = 7;
    pub const SIGMA2: u32 = 8;
    pub const FC: u32 = 9;
    pub const FS: u32 = 10;
    pub const VS: u32 = 11;
    pub const STRIBECK_EXPONENT: u32 = 12;
    pub const VD: u32 = 13;
    pub const DIRECTION_DEPENDENT: u32 = 14;
    pub const FC_NEG: u32 = 15;
    pub const FS_NEG: u32 = 16;
    pub const NORMAL_FORCE_FORM: u32 = 17;
    pub const POSITION_DEPENDENT: u32 = 18;
    pub const N_TABLE: u32 = 19;
    /// `x_table[i]`, i = 1..=32, at `X_TABLE + i - 1`.
    pub const X_TABLE: u32 = 20;
    pub const SCALE_POS: u32 = X_TABLE + super::TABLE_POINTS as u32;
    pub const SCALE_NEG: u32 = SCALE_POS + super::TABLE_POINTS as u32;
    /// `der(z)`, after the tables.
    pub const DER_Z: u32 = SCALE_NEG + super::TABLE_POINTS as u32;
    /// The parameters added after the first version, after `der(z)`.
    pub const DIRECTION_DEPENDENT_VISCOUS: u32 = DER_Z + 1;
    pub const SIGMA2_NEG: u32 = DER_Z + 2;
    pub const F_OFFSET: u32 = DER_Z + 3;
    pub const PARAMETER_SENSITIVITIES: u32 = DER_Z + 4;
    /// The energy outputs, added last.
    pub const P_DISS: u32 = DER_Z + 5;
    pub const E_STORED: u32 = DER_Z + 6;
}

const INPUTS: &[u32] = &[vr::V, vr::X, vr::FN];

fn variables() -> Vec<Variable> {
    let d = LuGreParams::default();
    let mut v = vec![
        sliding_velocity_input(vr::V),
        Variable::input(
            vr::X,
            "x",
            0.0,
            "m",
            0.1,
            "Position along the travel (used when position_dependent)",
        ),
        Variable::input(
            vr::FN,
            "Fn",
            1.0,
            "N",
            1.0,
            "Normal force (used when normal_force_form), >= 0",
        ),
        Variable::output(
            vr::F,
            "F",
            "N",
            "Friction force F = sigma0*z + sigma1(v)*dz/dt + sigma2*v + F_offset",
            INPUTS,
        )
        .with_state_dependencies(&[vr::Z]),
        Variable::output(vr::Z, "z", "m", "Mean bristle deflection", &[])
            .with_state_dependencies(&[vr::Z]),
        Variable::boolean_output(
            vr::SLIDING,
            "sliding",
            "True when moving and sigma0*|z| has reached 99 % of g(v)",
            INPUTS,
        )
        .with_state_dependencies(&[vr::Z]),
        Variable::parameter(
            vr::SIGMA0,
            "sigma0",
            d.sigma0,
            "N/m",
            "Bristle stiffness (per unit Fn, 1/m, in the normal-force form)",
        )
        .with_min(0.0),
        Variable::parameter(
            vr::SIGMA1,
            "sigma1",
            d.sigma1,
            "N.s/m",
            "Bristle damping (per unit Fn, s/m, in the normal-force form)",
        )
        .with_min(0.0),
        Variable::parameter(
            vr::SIGMA2,
            "sigma2",
            d.sigma2,
            "N.s/m",
            "Viscous friction, for v >= 0 when direction_dependent_viscous (per unit Fn, s/m, in the normal-force form)",
        )
        .with_min(0.0),
        Variable::parameter(
            vr::FC,
            "Fc",
            d.fc,
            "N",
            "Coulomb level for v >= 0 (friction coefficient mu_d in the normal-force form)",
        )
        .with_min(0.0),
        Variable::parameter(
            vr::FS,
            "Fs",
            d.fs,
            "N",
            "Static (break-away) level for v >= 0, >= Fc (mu_s in the normal-force form)",
        )
        .with_min(0.0),
        Variable::parameter(vr::VS, "vs", d.vs, "m/s", "Stribeck velocity").with_min(0.0),
        Variable::parameter(
            vr::STRIBECK_EXPONENT,
            "stribeck_exponent",
            d.stribeck_exponent,
            "",
            "Stribeck exponent delta in exp(-|v/vs|^delta)",
        )
        .with_min(0.0),
        Variable::parameter(
            vr::VD,
            "vd",
            d.vd,
            "m/s",
            "Micro-damping decay velocity: sigma1(v) = sigma1*exp(-(v/vd)^2); 0 = constant sigma1",
        )
        .with_min(0.0),
        Variable::boolean_parameter(
            vr::DIRECTION_DEPENDENT,
            "direction_dependent",
            false,
            "Use Fc_neg, Fs_neg and scale_neg for v < 0",
        ),
        Variable::parameter(
            vr::FC_NEG,
            "Fc_neg",
            d.fc_neg,
            "N",
            "Coulomb level for v < 0 (when direction_dependent)",
        )
        .with_min(0.0),
        Variable::parameter(
            vr::FS_NEG,
            "Fs_neg",
            d.fs_neg,
            "N",
            "Static level for v < 0, >= Fc_neg (when direction_dependent)",
        )
        .with_min(0.0),
        Variable::boolean_parameter(
            vr::NORMAL_FORCE_FORM,
            "normal_force_form",
            false,
            "Normal-force form (Dion et al. 2013): stiffness, damping and levels are per unit normal force Fn",
        ),
        Variable::boolean_parameter(
            vr::POSITION_DEPENDENT,
            "position_dependent",
            false,
            "Scale Fc and Fs by a piecewise-linear table over the input x",
        ),
        Variable::integer_parameter(
            vr::N_TABLE,
            "n_table",
            d.n_table as i32,
            "Number of table points used (2..32)",
        ),
    ];
    let names = |base: &str| -> Vec<&'static str> {
        (1..=TABLE_POINTS)
            .map(|i| &*Box::leak(format!("{base}[{i}]").into_boxed_str()))
            .collect()
    };
    for (i, name) in names("x_table").into_iter().enumerate() {
        v.push(Variable::parameter(
            vr::X_TABLE + i as u32,
            name,
            d.x_table[i],
            "m",
            "Table position (strictly increasing over the points used)",
        ));
    }
    for (i, name) in names("scale_pos").into_iter().enumerate() {
        v.push(
            Variable::parameter(
                vr::SCALE_POS + i as u32,
                name,
                d.scale_pos[i],
                "",
                "Scale factor on Fc and Fs at x_table[i], v >= 0",
            )
            .with_min(0.0),
        );
    }
    for (i, name) in names("scale_neg").into_iter().enumerate() {
        v.push(
            Variable::parameter(
                vr::SCALE_NEG + i as u32,
                name,
                d.scale_neg[i],
                "",
                "Scale factor on Fc_neg and Fs_neg at x_table[i], v < 0 (when direction_dependent)",
            )
            .with_min(0.0),
        );
    }
    v.push(Variable::derivative(
        vr::DER_Z,
        "der(z)",
        "m/s",
        "dz/dt = v - sigma0*|v|*z/g(v): the derivative of the continuous state z (Model Exchange)",
        // (x moves the level when position_dependent; Fn never enters)
        &[vr::V, vr::X],
        &[vr::Z],
    ));
    v.push(Variable::boolean_parameter(
        vr::DIRECTION_DEPENDENT_VISCOUS,
        "direction_dependent_viscous",
        false,
        "Use sigma2_neg instead of sigma2 for v < 0 (the asymmetric viscous friction of Janot, Gautier, Brunot 2019)",
    ));
    v.push(
        Variable::parameter(
            vr::SIGMA2_NEG,
            "sigma2_neg",
            d.sigma2_neg,
            "N.s/m",
            "Viscous friction for v < 0 (when direction_dependent_viscous; per unit Fn, s/m, in the normal-force form)",
        )
        .with_min(0.0),
    );
    v.push(Variable::parameter(
        vr::F_OFFSET,
        "F_offset",
        d.f_offset,
        "N",
        "Constant force on the contact, added to F at rest and in motion (the offset of Janot, Gautier, Brunot 2019); not scaled by Fn",
    ));
    v.push(Variable::boolean_parameter(
        vr::PARAMETER_SENSITIVITIES,
        "parameter_sensitivities",
        false,
        "Carry dz/dp along the run (Co-Simulation): fmi2GetDirectionalDerivative of F or z with Real parameters as the knowns then gives dF/dp, dz/dp (all parameters but x_table; for fitting)",
    ));
    v.push(
        Variable::output(
            vr::P_DISS,
            "P_diss",
            "W",
            "Power the contact dissipates, F*v - sigma0*z*dz/dt*[Fn] = (sigma0^2*|v|*z^2/g + sigma1*v*dz/dt + sigma2*v^2)*[Fn] + F_offset*v; with F, E_stored: int F*v dt = int P_diss dt + delta E_stored at a constant Fn",
            INPUTS,
        )
        .with_state_dependencies(&[vr::Z]),
    );
    v.push(
        Variable::output(
            vr::E_STORED,
            "E_stored",
            "J",
            "Elastic energy of the bristles, sigma0*z^2/2*[Fn] ([Fn]: the normal force in the normal-force form, else 1)",
            &[vr::FN],
        )
        .with_state_dependencies(&[vr::Z]),
    );
    v
}

pub static INFO: LazyLock<ModelInfo> = LazyLock::new(|| {
    ModelInfo {
    model_name: "LuGre",
    model_identifier: "LuGre",
    guid: "{cc09ec7b-20f5-4798-9c84-4aa863242977}",
    description: "LuGre friction: dz/dt = v - sigma0*|v|*z/g(v), g(v) = Fc + (Fs - Fc)*exp(-|v/vs|^delta), F = sigma0*z + sigma1(v)*dz/dt + sigma2*v + F_offset; exact exponential update for piecewise-constant inputs. Defaults: Canudas de Wit et al. 1995.",
    source: "Canudas de Wit et al. 1995; Sun et al. 2016 eq. 9-12; Dion et al. 2013 eq. 1 (normal-force form); Thimmalapura 2004 eq. 2.8-2.9 and Table I (position and direction dependence); Janot, Gautier, Brunot 2019 (offset, direction-dependent viscous friction). See docs/models.md.",
    variables: Box::leak(variables().into_boxed_slice()),
    default_experiment: DefaultExperiment { start_time: 0.0, stop_time: 1.0, step_size: 1e-3 },
    capabilities: Capabilities::FULL,
    co_simulation_states: &[],
    model_exchange: Some(ModelExchange {
        states: &[ContinuousState { state: vr::Z, derivative: vr::DER_Z }],
        event_indicators: 1,
        states_jump_at_events: false,
    }),
}
});

#[derive(Clone, Debug)]
pub struct LuGreFmu {
    law: LuGre,
}

impl Default for LuGreFmu {
    fn default() -> Self {
        LuGreFmu {
            law: LuGre::new(LuGreParams::default()).expect("default parameters are valid"),
        }
    }
}

impl LuGreFmu {
    pub fn params(values: &Values) -> LuGreParams {
        let table = |base: u32| -> [f64; TABLE_POINTS] {
            std::array::from_fn(|i| values.real(base + i as u32))
        };
        LuGreParams {
            sigma0: values.real(vr::SIGMA0),
            sigma1: values.real(vr::SIGMA1),
            sigma2: values.real(vr::SIGMA2),
            direction_dependent_viscous: values.boolean(vr::DIRECTION_DEPENDENT_VISCOUS),
            sigma2_neg: values.real(vr::SIGMA2_NEG),
            f_offset: values.real(vr::F_OFFSET),
            fc: values.real(vr::FC),
            fs: values.real(vr::FS),
            vs: values.real(vr::VS),
            stribeck_exponent: values.real(vr::STRIBECK_EXPONENT),
            vd: values.real(vr::VD),
            direction_dependent: values.boolean(vr::DIRECTION_DEPENDENT),
            fc_neg: values.real(vr::FC_NEG),
            fs_neg: values.real(vr::FS_NEG),
            normal_force_form: values.boolean(vr::NORMAL_FORCE_FORM),
            position_dependent: values.boolean(vr::POSITION_DEPENDENT),
            n_table: values.integer(vr::N_TABLE).max(0) as usize,
            x_table: table(vr::X_TABLE),
            scale_pos: table(vr::SCALE_POS),
            scale_neg: table(vr::SCALE_NEG),
        }
    }

    fn inputs(values: &Values) -> (f64, f64, f64) {
        let [v, x, fn_] = Self::input_entries(values.as_slice());
        (v, x, fn_)
    }

    /// The entries of v, x and Fn in a table indexed by value reference
    /// (the values, or their slopes): the inputs are value references
    /// 0, 1, 2, so one length check covers the three.
    #[inline]
    fn input_entries(table: &[f64]) -> [f64; 3] {
        const _: () = assert!(vr::V == 0 && vr::X == 1 && vr::FN == 2);
        match table {
            [v, x, fn_, ..] => [*v, *x, *fn_],
            _ => unreachable!("a value table holds every variable"),
        }
    }
}

impl Model for LuGreFmu {
    fn info(&self) -> &'static ModelInfo {
        &INFO
    }

    fn initialize(&mut self, values: &Values) -> Result<(), String> {
        if values.integer(vr::N_TABLE) < 2 || values.integer(vr::N_TABLE) > TABLE_POINTS as i32 {
            return Err(format!(
                "invalid parameter n_table = {}: must be in 2..={TABLE_POINTS}",
                values.integer(vr::N_TABLE)
            ));
        }
        self.law = LuGre::new(Self::params(values)).map_err(param_err)?;
        if values.boolean(vr::PARAMETER_SENSITIVITIES) {
            self.law.carry_parameter_sensitivities();
        }
        Ok(())
    }

    fn check_input(&self, input: u32, value: f64) -> Result<(), String> {
        if input == vr::FN && value < 0.0 {
            return Err("the normal force must be >= 0".into());
        }
        Ok(())
    }

    /// (the normal force only, as `check_input`)
    fn input_checked(&self, input: u32) -> bool {
        input == vr::FN
    }

    fn compute_outputs(&self, values: &mut Values) {
        let (v, x, fn_) = Self::inputs(values);
        let (force, sliding, power) = self.law.outputs(v, x, fn_);
        values.set(vr::F, force);
        values.set(vr::Z, self.law.z());
        values.set_boolean(vr::SLIDING, sliding);
        values.set(vr::P_DISS, power);
        values.set(vr::E_STORED, self.law.stored_energy(fn_));
    }

    /// The outputs asked for only (a directional derivative wants F, and
    /// need not find out whether the body slides): each as
    /// [`Model::compute_outputs`] computes it.
    fn compute_outputs_of(&self, values: &mut Values, outputs: &[u32]) {
        let (v, x, fn_) = Self::inputs(values);
        for &output in outputs {
            match output {
                vr::F => values.set(vr::F, self.law.force(v, x, fn_)),
                vr::Z => values.set(vr::Z, self.law.z()),
                vr::SLIDING => values.set_boolean(vr::SLIDING, self.law.sliding(v, x, fn_)),
                vr::P_DISS => values.set(vr::P_DISS, self.law.dissipated_power(v, x, fn_)),
                vr::E_STORED => values.set(vr::E_STORED, self.law.stored_energy(fn_)),
                _ => {}
            }
        }
    }

    fn do_step(&mut self, values: &Values, slopes: &[f64], h: f64) -> Result<(), String> {
        let [v, x, fn_] = Self::input_entries(values.as_slice());
        let [dv, dx, dfn] = Self::input_entries(slopes);
        let inputs = LuGreInputs {
            v: Ramp::new(v, dv),
            x: Ramp::new(x, dx),
            fn_: Ramp::new(fn_, dfn),
        };
        self.law.step(&inputs, h);
        Ok(())
    }

    fmi_export::delegate_state!(law);

    /// Directional derivatives by replaying the step (or, after a held
    /// step, from the closed form below): no partial derivatives.
    fn supplies_partial_derivatives(&self) -> bool {
        false
    }

    /// ∂F/∂u and ∂z/∂u (u = v, x, Fn) after a held step: the law's
    /// closed form of the exact held update
    /// ([`LuGre::held_step_sensitivity`]), which declines at the kinks of
    /// the step map (|v| ≤ spread, a table point or Fn = 0 within the
    /// spread). `sliding` is not differentiable: `None`.
    fn step_partial_derivative(
        &self,
        values: &Values,
        output: u32,
        input: u32,
        h: f64,
        spread: f64,
    ) -> Option<f64> {
        let input = match input {
            vr::V => HeldInput::V,
            vr::X => HeldInput::X,
            vr::FN => HeldInput::Fn,
            _ => return None,
        };
        if output != vr::F && output != vr::Z {
            return None;
        }
        let (v, x, fn_) = Self::inputs(values);
        let d = self
            .law
            .held_step_sensitivity(input, v, x, fn_, h, spread)?;
        Some(if output == vr::F { d.force } else { d.z })
    }

    fn supplies_step_derivatives(&self) -> bool {
        true
    }

    /// `∂F/∂p` and `∂z/∂p` along the run, for every Real parameter but
    /// the table positions ([`LuGre::force_sensitivity`]), when the
    /// parameter `parameter_sensitivities` is on.
    fn parameter_sensitivity(
        &self,
        values: &Values,
        output: u32,
        parameter: u32,
    ) -> Result<f64, String> {
        let name = |vr: u32| {
            INFO.variables
                .iter()
                .find(|v| v.vr == vr)
                .map_or("?", |v| v.name)
        };
        let Some(p) = carried_parameter(parameter) else {
            return Err(format!(
                "no sensitivity to {} (value reference {parameter}) is carried: only to the Real parameters but x_table",
                name(parameter)
            ));
        };
        if !self.law.carries_parameter_sensitivities() {
            return Err(
                "parameter sensitivities are not carried: set the parameter parameter_sensitivities = true before fmi2ExitInitializationMode".into(),
            );
        }
        let (v, x, fn_) = Self::inputs(values);
        let d = match output {
            vr::F => self.law.force_sensitivity(p, v, x, fn_),
            vr::Z => self.law.z_sensitivity(p),
            _ => {
                return Err(format!(
                    "no parameter sensitivity of {} (value reference {output}): only of F and z",
                    name(output)
                ))
            }
        };
        d.ok_or_else(|| "parameter sensitivities are not carried".into())
    }

    /// dz/dt from the state equation; dF/dt = σ0·ż + σ1·z̈ + σ2(v)·v̇ with
    /// z̈ = v̇ − σ0·d(|v|·z/g)/dt, for constant σ1 and x, Fn at rest (the
    /// general case is not offered: `None`; nor at v = 0 with a
    /// direction-dependent σ2, whose kink is there). The offset is
    /// constant.
    fn output_derivative(&self, values: &Values, slopes: &[f64], output: u32) -> Option<f64> {
        let (v, x, fn_) = Self::inputs(values);
        let z_dot = self.law.z_dot(v, x, fn_);
        match output {
            vr::Z => Some(z_dot),
            vr::F => {
                let p = Self::params(values);
                let moving_levels = slopes[vr::X as usize] != 0.0 || slopes[vr::FN as usize] != 0.0;
                if p.vd != 0.0 || p.normal_force_form || moving_levels {
                    return None;
                }
                let sigma2 = if !p.direction_dependent_viscous || v > 0.0 {
                    p.sigma2
                } else if v < 0.0 {
                    p.sigma2_neg
                } else {
                    return None;
                };
                let a = slopes[vr::V as usize];
                let g = self.law.g(v, x, fn_);
                let dv = 1e-7 * v.abs().max(p.vs);
                let g_prime =
                    (self.law.g(v + dv, x, fn_) - self.law.g(v - dv, x, fn_)) / (2.0 * dv);
                let z = self.law.z();
                let d_abs_v = v.signum() * a;
                let z_ddot = a - p.sigma0
                    * (d_abs_v * z / g + v.abs() * z_dot / g - v.abs() * z * g_prime * a / (g * g));
                Some(p.sigma0 * z_dot + p.sigma1 * z_ddot + sigma2 * a)
            }
            _ => None,
        }
    }

    /// `dz/dt` at the current deflection and inputs: the law's state
    /// equation, which its step integrates exactly for held inputs.
    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        let (v, x, fn_) = Self::inputs(values);
        dx[0] = self.law.z_dot(v, x, fn_);
    }

    fmi_export::ode_is_self!();
}

/// The parameter of value reference `vr` as a [`Parameter`] whose
/// sensitivity the law carries; `None` for any other variable.
fn carried_parameter(vr: u32) -> Option<Parameter> {
    let table =
        |base: u32| (vr >= base && vr < base + TABLE_POINTS as u32).then(|| (vr - base) as usize);
    Some(match vr {
        vr::SIGMA0 => Parameter::Sigma0,
        vr::SIGMA1 => Parameter::Sigma1,
        vr::SIGMA2 => Parameter::Sigma2,
        vr::SIGMA2_NEG => Parameter::Sigma2Neg,
        vr::F_OFFSET => Parameter::FOffset,
        vr::FC => Parameter::Fc,
        vr::FS => Parameter::Fs,
        vr::VS => Parameter::Vs,
        vr::STRIBECK_EXPONENT => Parameter::StribeckExponent,
        vr::VD => Parameter::Vd,
        vr::FC_NEG => Parameter::FcNeg,
        vr::FS_NEG => Parameter::FsNeg,
        _ => {
            if let Some(i) = table(vr::SCALE_POS) {
                Parameter::ScalePos(i)
            } else {
                Parameter::ScaleNeg(table(vr::SCALE_NEG)?)
            }
        }
    })
}

/// Model Exchange: the state is `z`; the one event indicator is `v`, where
/// `|v|` (and, direction-dependent, the levels) switch; no discrete state,
/// so an event changes nothing.
impl Ode for LuGreFmu {
    /// `z` (never the parameter sensitivities, which only a step carries).
    fn continuous_states(&self, x: &mut [f64]) {
        x[0] = self.law.z();
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        match x {
            [z] if z.is_finite() => {
                self.law.set_z(*z);
                Ok(())
            }
            _ => Err(format!(
                "LuGre continuous state must be one finite z, got {x:?}"
            )),
        }
    }

    fn event_indicators(&self, values: &Values, z: &mut [f64]) {
        z[0] = values.real(vr::V);
    }

    /// `z` on the scale of the largest steady deflection
    /// ([`LuGreParams::deflection_scale`], Fs/σ0 by default).
    fn nominals(&self, values: &Values, nominal: &mut [f64]) {
        nominal[0] = Self::params(values).deflection_scale();
    }

    fn event_update(&mut self, _values: &Values) -> bool {
        false
    }

    /// The law's closed forms ([`LuGre::rate_partials`],
    /// [`LuGre::force_partials`]) for `der(z)` and `F`; the output `z` is
    /// the state.
    fn partial_derivative(&self, values: &Values, unknown: u32, known: u32) -> Option<f64> {
        let (v, x, fn_) = Self::inputs(values);
        let z = self.law.z();
        let by = match unknown {
            vr::DER_Z => {
                let r = self.law.rate_partials(z, v, x);
                [r.z, r.v, r.x, 0.0]
            }
            vr::F => {
                let f = self.law.force_partials(z, v, x, fn_);
                [f.z, f.v, f.x, f.fn_]
            }
            vr::Z => [1.0, 0.0, 0.0, 0.0],
            // P = F·v − σ0·z·ż·φ(Fn), E = σ0·z²/2·φ(Fn)
            vr::P_DISS => {
                let f = self.law.force_partials(z, v, x, fn_);
                let r = self.law.rate_partials(z, v, x);
                let zd = self.law.z_rate(z, v, x, fn_);
                let s0 = self.law.params().sigma0;
                let phi = self.law.normal_force_factor(fn_);
                [
                    f.z * v - s0 * phi * (zd + z * r.z),
                    f.v * v + self.law.force(v, x, fn_) - s0 * phi * z * r.v,
                    f.x * v - s0 * phi * z * r.x,
                    f.fn_ * v - s0 * self.law.fn_factor_slope(fn_) * z * zd,
                ]
            }
            vr::E_STORED => {
                let s0 = self.law.params().sigma0;
                [
                    s0 * z * self.law.normal_force_factor(fn_),
                    0.0,
                    0.0,
                    0.5 * s0 * z * z * self.law.fn_factor_slope(fn_),
                ]
            }
            _ => return None,
        };
        match known {
            vr::Z => Some(by[0]),
            vr::V => Some(by[1]),
            vr::X => Some(by[2]),
            vr::FN => Some(by[3]),
            _ => None,
        }
    }
}
