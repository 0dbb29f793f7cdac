//! Output sensitivities: the Jacobian of the co-simulated channels with
//! respect to the friction law's parameters, carried along one
//! co-simulation, where forward differences take one more co-simulation of
//! the whole record per free parameter.
//!
//! **What it covers.** A system of two components, the friction law (this
//! project's LuGre.fmu) and a plant FMU (FMI 2.0) that lists its
//! continuous states (`ModelStructure/Derivatives`) and provides
//! directional derivatives, co-simulated by the strong-coupling master
//! (`newton`, or `newton-interpolated` as the diagnosis runs it) or by
//! the Jacobi master (EMPS's system file asks for it). The
//! plant must be linear and time-invariant in its state and the friction
//! force (the masses, springs, dampers and linear controllers of a
//! drive): its partial derivatives are compared along a run of it alone
//! with the data's inputs, and a plant whose derivatives move is not
//! covered. Its other inputs come from the data and do not move with the
//! parameters. Anything else is differenced, as before, and
//! [`Coupling::new`] or [`Coupling::sensitivities`] says why.
//!
//! **The plant.** Its continuous-time partial derivatives, from
//! `fmi2GetDirectionalDerivative` with the states as knowns (FMI 2.0
//! §2.1.9; Co-Simulation as Model Exchange), `A = ∂der/∂x`, `b = ∂der/∂F`,
//! `C = ∂y/∂x`, `d = ∂y/∂F`, give the response over a step `h` to a change
//! `δx` of the state and `δF` of the friction force (held over the step,
//! or ramping from `δF₀` to `δF₁` for a plant that interpolates its
//! inputs):
//!
//! ```text
//! δx⁺ = Φ·δx + Γ·δF  (held),   δx⁺ = Φ·δx + Γ₀·δF₀ + Γ₁·δF₁  (ramped),   δy⁺ = C·δx⁺ + d·δF₁,
//! ```
//!
//! `Φ = e^(A·h)`, `Γ = ∫₀ʰ e^(A·s) ds·b`, `Γ₁ = ∫₀ʰ e^(A·(h−s))·b·s/h ds`,
//! `Γ₀ = Γ − Γ₁`: one exponential of an augmented matrix (Van Loan 1978).
//!
//! **The law.** LuGre replayed in-process along the interface values the
//! co-simulation converged to (the same code as LuGre.fmu), each step
//! from the deflection the FMU recorded at its start, its force checked
//! against the FMU's (another law is not followed). It carries `∂z/∂p`
//! through each step (`friction_laws::lugre::parameter_sensitivity`)
//! along inputs that do not move; here they move, through the plant, and
//! the step's partial derivatives in its inputs at both ends of the
//! step, `q = ∂z⁺/∂(v₀, x₀, v₁, x₁)` (central differences of the law's own
//! step, in-process), and its output's, `∂F/∂(z, v, x)` (closed form), add
//! their share:
//!
//! ```text
//! δz⁺ = [carried] + q_v0·δv₀ + q_x0·δx₀ + q_v1·δv₁ + q_x1·δx₁,
//! δF₁ = f_p + F_z·(q_v0·δv₀ + q_x0·δx₀) + s_v·δv₁ + s_x·δx₁,   s_u = F_z·q_u1 + F_u,
//! ```
//!
//! `f_p` the force's sensitivity along the inputs (`force_sensitivity`);
//! with held inputs the start is the end (`v₀ = v₁`).
//!
//! **The coupling.** The master solves `U = Y(U)` at every step: the law's
//! inputs `v`, `x_c` at the step's end are the plant's outputs there, and
//! the plant's force input the law's force there. With the plant's free
//! response `a = C·(Φ·δx + Γ₀·δF₀)` and its gain `g = C·Γ₁ + d` (`Γ`
//! held), `δv₁ = a_v + g_v·δF₁` (and `δx_c` alike), so that for each
//! parameter and step
//!
//! ```text
//! δF₁ = (f_p + F_z·(q_v0·δv₀ + q_x0·δx₀) + s_v·a_v + s_x·a_x) / (1 − s_v·g_v − s_x·g_x).
//! ```
//!
//! **The Jacobi master** is explicit: each component steps on the other's
//! outputs at the step's start, held, and its outputs at the end are read
//! with those inputs still set. With `δv₀`, `δx_c₀`, `δF₀` the
//! sensitivities recorded at the step's start,
//!
//! ```text
//! δz⁺ = [carried] + q_v·δv₀ + q_x·δx_c₀,   δF₁ = f_p + s_v·δv₀ + s_x·δx_c₀,
//! δx⁺ = Φ·δx + Γ·δF₀,   δy₁ = C·δx⁺ + d·δF₀,
//! ```
//!
//! the law's partials taken at the held inputs (`v₀ = v₁`).
//!
//! Against central differences of whole co-simulations on the two-mass
//! drive of the tests: within 2e-5 of each column's size with held
//! inputs, 1e-3 with ramped ones; on Rig1D within 4e-6, 1.2e-4 under its
//! own controller (host/tests/integration/output_sensitivities.rs).

use crate::fmu::model_description::{Causality, VariableKind};
use crate::fmu::{Fmu, ValueReference};
use crate::master::Run;
use crate::system::{ParameterValue, System};
use friction_laws::lugre::parameter_sensitivity::Parameter;
use friction_laws::lugre::{LuGre, LuGreInputs, LuGreParams, TABLE_POINTS};
use friction_laws::Ramp;
use nalgebra::{DMatrix, DVector};

/// One step in this many may be replayed with another force than the
/// FMU gave ([`REPLAY_TOLERANCE`]): the steps the master halved, which
/// the replay takes whole from the FMU's deflection at their start (their
/// sensitivity is then that of the whole step). More, and the law is
/// another one.
const MISMATCHED_STEPS: usize = 100;

/// The friction force the in-process law gives may differ from the FMU's
/// by this much (relative to the Coulomb level plus the force): the
/// master's tolerance on the interface (`rtol` 1e-8) times the law's
/// slope in `v`. A step the master halved (its Newton iteration failed
/// at the full step) differs by more: 6e-5 of the force in a stick, 1.2 N
/// at a reversal, seen on a two-mass drive ([`MISMATCHED_STEPS`]).
const REPLAY_TOLERANCE: f64 = 1e-3;

/// The plant and the law of a system whose output sensitivities can be
/// carried, and the plant's linearization.
pub struct Coupling {
    plant_name: String,
    friction_name: String,
    /// The plant's Real outputs (names), the rows of `c` and `d`.
    outputs: Vec<String>,
    /// The plant output the law's `v` reads (a row of `c`).
    v_from: usize,
    /// The plant output the law's `x` reads, if connected.
    x_from: Option<usize>,
    a: DMatrix<f64>,
    b: DVector<f64>,
    c: DMatrix<f64>,
    d: DVector<f64>,
    /// Whether the plant and the law can interpolate their inputs
    /// (`canInterpolateInputs`): under `newton-interpolated` their inputs
    /// then ramp over each step.
    plant_interpolates: bool,
    law_interpolates: bool,
    /// The law's parameters that no fit moves: the FMU's start values
    /// with the system file's values for the friction component.
    law_defaults: Vec<(String, f64)>,
}

/// The plant's response over one step of length `h`.
struct Discrete {
    h: f64,
    /// `Φ = e^(A·h)`.
    phi: DMatrix<f64>,
    /// `Γ`: to the force held over the step.
    gamma: DVector<f64>,
    /// `Γ₀`, `Γ₁`: to the force at the start and at the end of a ramp
    /// over the step (`Γ₀ + Γ₁ = Γ`).
    gamma_start: DVector<f64>,
    gamma_end: DVector<f64>,
    /// The outputs at the end of the step per unit force there, held
    /// over the step (`C·Γ + d`) or at the end of a ramp (`C·Γ₁ + d`).
    gain_held: DVector<f64>,
    gain_ramped: DVector<f64>,
}

impl Coupling {
    /// The coupling of `system` (its component `friction` the law) with
    /// the plant's parameters from `parameters` (`component.name`), the
    /// plant linearized at its initial state at the first of `time`, and
    /// again along a run of the plant alone with the inputs `inputs`
    /// (`component.input` columns at `time`, the friction force 0): a
    /// plant whose partial derivatives change there is not linear and
    /// time-invariant, and is not covered. An error that says why the
    /// system is not covered.
    pub fn new(
        system: &System,
        friction: usize,
        parameters: &[(String, ParameterValue)],
        (time, inputs): (&[f64], &[(String, Vec<f64>)]),
    ) -> Result<Coupling, String> {
        if system.components.len() != 2 {
            return Err(format!(
                "the system has {} components; output sensitivities cover a plant and the friction law",
                system.components.len()
            ));
        }
        let plant = 1 - friction;
        let (plant_c, friction_c) = (&system.components[plant], &system.components[friction]);
        let plant_fmu = &plant_c.fmu;
        let law_fmu = &friction_c.fmu;
        let name_of = |fmu: &Fmu, vr: ValueReference, causality: Causality| {
            fmu.description()
                .variables
                .iter()
                .find(|v| v.value_reference == vr && v.causality == causality)
                .map(|v| v.name.clone())
        };
        let outputs: Vec<(String, ValueReference)> = plant_fmu
            .description()
            .variables
            .iter()
            .filter(|v| {
                v.causality == Causality::Output && matches!(v.kind, VariableKind::Real { .. })
            })
            .map(|v| (v.name.clone(), v.value_reference))
            .collect();
        let (mut force_input, mut v_from, mut x_from) = (None, None, None);
        for conn in &system.connections {
            if conn.from.0 == friction && conn.to.0 == plant {
                if name_of(law_fmu, conn.from.1, Causality::Output).as_deref() != Some("F") {
                    return Err(format!(
                        "the connection {} is not the law's force",
                        conn.label
                    ));
                }
                if force_input.replace(conn.to.1).is_some() {
                    return Err("the law's force drives more than one plant input".into());
                }
            } else if conn.from.0 == plant && conn.to.0 == friction {
                let row = outputs
                    .iter()
                    .position(|(_, vr)| *vr == conn.from.1)
                    .ok_or_else(|| {
                        format!("the connection {} is not from a Real output", conn.label)
                    })?;
                match name_of(law_fmu, conn.to.1, Causality::Input).as_deref() {
                    Some("v") => v_from = Some(row),
                    Some("x") => x_from = Some(row),
                    other => {
                        return Err(format!(
                            "the law's input {} is driven by the plant; sensitivities carry v and x only",
                            other.unwrap_or("?")
                        ))
                    }
                }
            }
        }
        let force_input = force_input.ok_or("the law's force drives no plant input")?;
        let v_from = v_from.ok_or("the law's v is not a plant output")?;
        // the states: the variables a `derivative` attribute points to
        let vars = &plant_fmu.description().variables;
        let (mut states, mut derivatives) = (Vec::new(), Vec::new());
        for v in vars {
            if let VariableKind::Real {
                derivative: Some(i),
                ..
            } = v.kind
            {
                let state = vars
                    .get(i.wrapping_sub(1))
                    .ok_or_else(|| format!("derivative=\"{i}\" of {} is not a variable", v.name))?;
                states.push(state.value_reference);
                derivatives.push(v.value_reference);
            }
        }
        if states.is_empty() {
            return Err(format!(
                "the plant {} lists no continuous states (ModelStructure/Derivatives)",
                plant_c.name
            ));
        }
        if !plant_fmu
            .description()
            .co_simulation
            .provides_directional_derivative
        {
            return Err(format!(
                "the plant {} does not provide directional derivatives",
                plant_c.name
            ));
        }
        let (a, b, c, d) = linearize(
            plant_fmu,
            &plant_c.name,
            parameters,
            (time, inputs),
            (&states, &derivatives),
            (
                &outputs.iter().map(|(_, vr)| *vr).collect::<Vec<_>>(),
                force_input,
            ),
        )?;
        // the law's values that fits do not move: its FMU's start values,
        // then the system file's
        let mut law_defaults: Vec<(String, f64)> = law_fmu
            .description()
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Parameter)
            .filter_map(|v| match &v.kind {
                VariableKind::Real { start, .. } => Some((v.name.clone(), (*start)?)),
                VariableKind::Integer { start, .. } => Some((v.name.clone(), f64::from((*start)?))),
                VariableKind::Boolean { start } => {
                    Some((v.name.clone(), f64::from(u8::from((*start)?))))
                }
                _ => None,
            })
            .collect();
        let prefix = format!("{}.", friction_c.name);
        law_defaults.extend(parameters.iter().filter_map(|(n, v)| match v {
            ParameterValue::Number(x) => Some((n.strip_prefix(&prefix)?.to_string(), *x)),
            ParameterValue::Text(_) => None,
        }));
        Ok(Coupling {
            plant_name: plant_c.name.clone(),
            friction_name: friction_c.name.clone(),
            outputs: outputs.into_iter().map(|(n, _)| n).collect(),
            v_from,
            x_from,
            a,
            b,
            c,
            d,
            plant_interpolates: plant_fmu.description().co_simulation.can_interpolate_inputs,
            law_interpolates: law_fmu.description().co_simulation.can_interpolate_inputs,
            law_defaults,
        })
    }

    /// The plant's response over a step of `h` (Van Loan 1978): with
    /// `M = [[A, b, 0], [0, 0, 1], [0, 0, 0]]`,
    /// `e^(M·h) = [[Φ, Γ, Θ], [0, 1, h], [0, 0, 1]]`, `Θ = ∫₀ʰ e^(A·(h−s))·b·s ds`,
    /// and a force ramping from `F₀` to `F₁` moves the state by
    /// `Γ·F₀ + Θ·(F₁ − F₀)/h`: `Γ₁ = Θ/h`, `Γ₀ = Γ − Γ₁`.
    fn discrete(&self, h: f64) -> Discrete {
        let n = self.a.nrows();
        let mut m = DMatrix::<f64>::zeros(n + 2, n + 2);
        m.view_mut((0, 0), (n, n)).copy_from(&(&self.a * h));
        m.view_mut((0, n), (n, 1)).copy_from(&(&self.b * h));
        m[(n, n + 1)] = h;
        let e = m.exp();
        let phi = e.view((0, 0), (n, n)).into_owned();
        let gamma: DVector<f64> = e.view((0, n), (n, 1)).column(0).into_owned();
        let theta: DVector<f64> = e.view((0, n + 1), (n, 1)).column(0).into_owned();
        let gamma_end = theta / h;
        let gamma_start = &gamma - &gamma_end;
        let gain_held = &self.c * &gamma + &self.d;
        let gain_ramped = &self.c * &gamma_end + &self.d;
        Discrete {
            h,
            phi,
            gamma,
            gamma_start,
            gamma_end,
            gain_held,
            gain_ramped,
        }
    }

    /// The plant output `name`'s response at the end of a step of `h` to
    /// a unit friction force held over it, from rest: `C·Γ + d` (what the
    /// plant's own step sensitivity is). `None`
    /// for a name that is not a Real output of the plant.
    pub fn step_gain(&self, h: f64, name: &str) -> Option<f64> {
        let i = self.outputs.iter().position(|o| o == name)?;
        Some(self.discrete(h).gain_held[i])
    }

    /// The law's parameters for the friction values `friction`
    /// (`FrictionModel::parameters`, the FMU's names) over the defaults.
    fn law_parameters(&self, friction: &[(String, f64)]) -> Result<LuGreParams, String> {
        let mut p = LuGreParams::default();
        for (name, value) in self.law_defaults.iter().chain(friction) {
            set_lugre(&mut p, name, *value);
        }
        p.validate().map_err(|e| e.to_string())?;
        Ok(p)
    }

    /// The sensitivities `∂(channel)/∂p` along `run` (a co-simulation of the
    /// system with the friction values `friction`, by the master `master`)
    /// of each channel of `channels` (`component.variable`: a plant output
    /// or the law's `F`) to each parameter of `parameters` (the law FMU's
    /// names): one matrix per channel, a row per row of the run, a column
    /// per parameter. An error where the run cannot be followed (the law
    /// replayed in-process gives another force than the FMU did, another
    /// master) or a name is not covered.
    pub fn sensitivities(
        &self,
        (run, master): (&Run, &str),
        friction: &[(String, f64)],
        parameters: &[String],
        channels: &[String],
    ) -> Result<Vec<DMatrix<f64>>, String> {
        // the inputs of a component that can interpolate them ramp over
        // each step from their value at its start (newton-interpolated);
        // else they are held at the step's end values (newton), or, by
        // the Jacobi master, at its start values
        let (interpolated, jacobi) = match master {
            "newton" => (false, false),
            "newton-interpolated" => (true, false),
            "jacobi" => (false, true),
            other => {
                return Err(format!(
                    "the master {other} is not covered (newton, newton-interpolated and jacobi are)"
                ))
            }
        };
        let (law_ramps, plant_ramps) = (
            interpolated && self.law_interpolates,
            interpolated && self.plant_interpolates,
        );
        let law_params = self.law_parameters(friction)?;
        if law_params.normal_force_form {
            return Err("the normal-force form is not covered".into());
        }
        let carried: Vec<Parameter> = parameters
            .iter()
            .map(|n| parameter(n).ok_or_else(|| format!("no sensitivity to {n} is carried")))
            .collect::<Result<_, _>>()?;
        enum Channel {
            Plant(usize),
            Force,
        }
        let channel_of: Vec<Channel> = channels
            .iter()
            .map(|name| {
                if *name == format!("{}.F", self.friction_name) {
                    return Ok(Channel::Force);
                }
                name.strip_prefix(&format!("{}.", self.plant_name))
                    .and_then(|v| self.outputs.iter().position(|o| o == v))
                    .map(Channel::Plant)
                    .ok_or_else(|| {
                        format!("the channel {name} is not a plant output or the law's force")
                    })
            })
            .collect::<Result<_, String>>()?;
        let column = |name: String| -> Result<Vec<f64>, String> {
            let k = run
                .columns
                .iter()
                .position(|c| *c == name)
                .ok_or_else(|| format!("the run does not record {name}"))?;
            Ok(run.rows.iter().map(|r| r[k]).collect())
        };
        let v = column(format!("{}.{}", self.plant_name, self.outputs[self.v_from]))?;
        let x = match self.x_from {
            Some(i) => column(format!("{}.{}", self.plant_name, self.outputs[i]))?,
            None => vec![0.0; v.len()],
        };
        let force = column(format!("{}.F", self.friction_name))?;
        // the FMU's deflection after each step: each replayed step starts
        // from it
        let deflection = column(format!("{}.z", self.friction_name))?;
        let mut mismatched = 0usize;
        let rows = run.time.len();
        let n_p = carried.len();
        let mut out: Vec<DMatrix<f64>> = vec![DMatrix::zeros(rows, n_p); channels.len()];
        let mut law = LuGre::new(law_params).map_err(|e| e.to_string())?;
        law.carry_parameter_sensitivities();
        // the same law without the sensitivities, for its input partials
        let mut probe = LuGre::new(law_params).map_err(|e| e.to_string())?;
        let n = self.a.nrows();
        let mut dx = DMatrix::<f64>::zeros(n, n_p);
        // δv, δx_c, δF at the row the step starts from (0 at the start:
        // the initial state does not depend on the law's parameters)
        let (mut dv, mut dxc, mut df) = (vec![0.0; n_p], vec![0.0; n_p], vec![0.0; n_p]);
        let mut discrete: Option<Discrete> = None;
        let level = law_params.fc.abs().max(law_params.fs.abs()).max(1e-12);
        for k in 0..rows.saturating_sub(1) {
            let h = run.time[k + 1] - run.time[k];
            if h <= 0.0 {
                for o in out.iter_mut() {
                    let previous = o.row(k).into_owned();
                    o.set_row(k + 1, &previous);
                }
                continue;
            }
            if discrete
                .as_ref()
                .is_none_or(|d| (d.h - h).abs() > 1e-12 * h)
            {
                discrete = Some(self.discrete(h));
            }
            let dsc = discrete.as_ref().expect("set above");
            // the law's inputs over the step: from the start values to the
            // end values, or held at the end values (at the start values
            // by the Jacobi master)
            let (v1, x1) = if jacobi {
                (v[k], x[k])
            } else {
                (v[k + 1], x[k + 1])
            };
            let (v0, x0) = if law_ramps { (v[k], x[k]) } else { (v1, x1) };
            let inputs = |v0: f64, x0: f64, v1: f64, x1: f64| LuGreInputs {
                v: Ramp::new(v0, (v1 - v0) / h),
                x: Ramp::new(x0, (x1 - x0) / h),
                fn_: Ramp::constant(1.0),
            };
            // the step from the FMU's z (the carried ∂z/∂p stay the law's)
            law.set_z(deflection[k]);
            // ∂z⁺/∂(v0, v1, x0, x1) by central differences of the law's
            // own step (in-process, from the same z)
            probe.set_z(law.z());
            let z_after = |v0: f64, x0: f64, v1: f64, x1: f64| {
                let mut p = probe.clone();
                p.step(&inputs(v0, x0, v1, x1), h);
                p.z()
            };
            let dv_step = 1e-7 * v0.abs().max(v1.abs()).max(1e-9);
            let dx_step = 1e-7 * x0.abs().max(x1.abs()).max(1e-6);
            let by = |f: &dyn Fn(f64) -> f64, d: f64| (f(d) - f(-d)) / (2.0 * d);
            // held: the one value moves both ends
            let moves_start = if law_ramps { 0.0 } else { 1.0 };
            let q_v1 = by(&|d| z_after(v0 + moves_start * d, x0, v1 + d, x1), dv_step);
            let q_x1 = if self.x_from.is_some() {
                by(&|d| z_after(v0, x0 + moves_start * d, v1, x1 + d), dx_step)
            } else {
                0.0
            };
            let (q_v0, q_x0) = if law_ramps {
                (
                    by(&|d| z_after(v0 + d, x0, v1, x1), dv_step),
                    if self.x_from.is_some() {
                        by(&|d| z_after(v0, x0 + d, v1, x1), dx_step)
                    } else {
                        0.0
                    },
                )
            } else {
                (0.0, 0.0)
            };
            law.step(&inputs(v0, x0, v1, x1), h);
            let replayed = law.force(v1, x1, 1.0);
            if (replayed - force[k + 1]).abs() > REPLAY_TOLERANCE * (level + force[k + 1].abs()) {
                // a step the master halved, or another law
                mismatched += 1;
                if mismatched > 1 + rows / MISMATCHED_STEPS {
                    return Err(format!(
                        "the law replayed in-process differs from the FMU at {mismatched} steps (at t = {} s: {replayed} N, the FMU {} N)",
                        run.time[k + 1],
                        force[k + 1]
                    ));
                }
            }
            let partials = law.force_partials(law.z(), v1, x1, 1.0);
            // δF⁺ = K + s_v·δv⁺ + s_x·δx_c⁺
            let s_v = partials.z * q_v1 + partials.v;
            let s_x = if self.x_from.is_some() {
                partials.z * q_x1 + partials.x
            } else {
                0.0
            };
            let gain = if plant_ramps {
                &dsc.gain_ramped
            } else {
                &dsc.gain_held
            };
            let g_v = gain[self.v_from];
            let g_x = self.x_from.map_or(0.0, |i| gain[i]);
            let denominator = 1.0 - s_v * g_v - s_x * g_x;
            for (j, &p) in carried.iter().enumerate() {
                let f_p = law
                    .force_sensitivity(p, v1, x1, 1.0)
                    .ok_or("the law carries no parameter sensitivities")?;
                if jacobi {
                    // explicit: the law stepped on the plant's outputs at
                    // the start, the plant on the law's force there
                    let f_end = f_p + s_v * dv[j] + s_x * dxc[j];
                    law.add_to_z_sensitivity(p, q_v1 * dv[j] + q_x1 * dxc[j]);
                    let state = &dsc.phi * dx.column(j) + &dsc.gamma * df[j];
                    let outputs = &self.c * &state + &self.d * df[j];
                    for (o, ch) in out.iter_mut().zip(&channel_of) {
                        o[(k + 1, j)] = match ch {
                            Channel::Force => f_end,
                            Channel::Plant(i) => outputs[*i],
                        };
                    }
                    dx.set_column(j, &state);
                    let x_end = self.x_from.map_or(0.0, |i| outputs[i]);
                    (dv[j], dxc[j], df[j]) = (outputs[self.v_from], x_end, f_end);
                    continue;
                }
                // the plant's free response: its state, and the force at
                // the start of a ramp
                let mut free = &dsc.phi * dx.column(j);
                if plant_ramps {
                    free += &dsc.gamma_start * df[j];
                }
                let response = &self.c * &free;
                let a_v = response[self.v_from];
                let a_x = self.x_from.map_or(0.0, |i| response[i]);
                let known = f_p + partials.z * (q_v0 * dv[j] + q_x0 * dxc[j]);
                let f_end = (known + s_v * a_v + s_x * a_x) / denominator;
                let (v_end, x_end) = (a_v + g_v * f_end, a_x + g_x * f_end);
                law.add_to_z_sensitivity(
                    p,
                    q_v0 * dv[j] + q_v1 * v_end + q_x0 * dxc[j] + q_x1 * x_end,
                );
                let state = free
                    + if plant_ramps {
                        &dsc.gamma_end * f_end
                    } else {
                        &dsc.gamma * f_end
                    };
                for (o, ch) in out.iter_mut().zip(&channel_of) {
                    o[(k + 1, j)] = match ch {
                        Channel::Force => f_end,
                        Channel::Plant(i) => (self.c.row(*i) * &state)[0] + self.d[*i] * f_end,
                    };
                }
                dx.set_column(j, &state);
                (dv[j], dxc[j], df[j]) = (v_end, x_end, f_end);
            }
        }
        if out.iter().any(|o| o.iter().any(|x| !x.is_finite())) {
            return Err("a sensitivity is not finite".into());
        }
        Ok(out)
    }
}

/// `A`, `b`, `C`, `d` of a plant ([`linearize`]).
type Linearization = (DMatrix<f64>, DVector<f64>, DMatrix<f64>, DVector<f64>);

/// `A`, `b`, `C`, `d` of the plant `fmu` (the component `name`, its
/// parameters from `parameters`) at its initial state at the first of
/// `time`, from its directional derivatives: the states and derivatives
/// `(states, derivatives)`, the outputs and the force input
/// `(outputs, force)`. Asked with the derivatives among the unknowns, so
/// that every answer is the continuous-time partial derivative (FMI 2.0
/// §2.1.9). Then the plant is run alone through `time` with its inputs
/// from `inputs` (held over each step, the force 0), and the partial
/// derivatives asked again after every step: an error if they moved by
/// more than 1e-9 of their largest entry (a controller that saturates for
/// a few steps is seen). The run is the plant's, not the co-simulation's:
/// a plant that leaves its linear range only under the friction force is
/// not seen.
fn linearize(
    fmu: &Fmu,
    name: &str,
    parameters: &[(String, ParameterValue)],
    (time, inputs): (&[f64], &[(String, Vec<f64>)]),
    (states, derivatives): (&[ValueReference], &[ValueReference]),
    (outputs, force): (&[ValueReference], ValueReference),
) -> Result<Linearization, String> {
    let fail = |e: crate::FmuError| format!("linearizing the plant {name}: {e}");
    let start = time.first().copied().unwrap_or(0.0);
    let mut i = fmu.instantiate("diagnose-linearize").map_err(fail)?;
    i.setup_experiment(start, None).map_err(fail)?;
    i.enter_initialization_mode().map_err(fail)?;
    let prefix = format!("{name}.");
    for (n, value) in parameters {
        let (Some(var), ParameterValue::Number(x)) = (n.strip_prefix(&prefix), value) else {
            continue;
        };
        let v = fmu.variable(var).map_err(|e| e.to_string())?;
        let vr = [v.value_reference];
        match v.kind {
            VariableKind::Real { .. } => i.set_real(&vr, &[*x]),
            VariableKind::Boolean { .. } => i.set_boolean(&vr, &[*x != 0.0]),
            _ => i.set_integer(&vr, &[*x as i32]),
        }
        .map_err(fail)?;
    }
    // the plant's own inputs from the data
    let mut driven: Vec<(ValueReference, &[f64])> = Vec::new();
    for (n, column) in inputs {
        if let Some(var) = n.strip_prefix(&prefix) {
            let vr = fmu
                .variable(var)
                .map_err(|e| e.to_string())?
                .value_reference;
            driven.push((vr, column.as_slice()));
        }
    }
    let set_inputs = |i: &mut crate::fmu::Instance, k: usize| -> Result<(), String> {
        for (vr, column) in &driven {
            i.set_real(&[*vr], &[column[k]]).map_err(fail)?;
        }
        Ok(())
    };
    if !time.is_empty() {
        set_inputs(&mut i, 0)?;
    }
    i.exit_initialization_mode().map_err(fail)?;
    let (n, m) = (states.len(), outputs.len());
    let unknowns: Vec<ValueReference> = derivatives.iter().chain(outputs).copied().collect();
    let partials = |i: &mut crate::fmu::Instance| -> Result<DMatrix<f64>, String> {
        // column j: ∂(derivatives, outputs)/∂(state j); the last, ∂/∂F
        let mut all = DMatrix::<f64>::zeros(n + m, n + 1);
        let mut column = vec![0.0; n + m];
        for (j, &known) in states.iter().chain([&force]).enumerate() {
            i.get_directional_derivative(&unknowns, &[known], &[1.0], &mut column)
                .map_err(fail)?;
            all.set_column(j, &DVector::from_column_slice(&column));
        }
        Ok(all)
    };
    let at_start = partials(&mut i)?;
    if at_start.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "the plant {name}'s directional derivatives are not finite"
        ));
    }
    let largest = at_start.amax().max(f64::MIN_POSITIVE);
    for k in 0..time.len().saturating_sub(1) {
        if time[k + 1] <= time[k] {
            continue;
        }
        set_inputs(&mut i, k)?;
        i.do_step(time[k], time[k + 1] - time[k]).map_err(fail)?;
        let moved = (partials(&mut i)? - &at_start).amax();
        if moved.is_nan() || moved > 1e-9 * largest {
            return Err(format!(
                "the plant {name} is not linear and time-invariant: its partial derivatives moved by {moved:e} (of {largest:e}) at t = {} s",
                time[k + 1]
            ));
        }
    }
    let _ = i.terminate();
    let a = at_start.view((0, 0), (n, n)).into_owned();
    let b = at_start.view((0, n), (n, 1)).column(0).into_owned();
    let c = at_start.view((n, 0), (m, n)).into_owned();
    let d = at_start.view((n, n), (m, 1)).column(0).into_owned();
    Ok((a, b, c, d))
}

/// The carried sensitivity of the LuGre FMU parameter `name`.
fn parameter(name: &str) -> Option<Parameter> {
    let indexed = |prefix: &str| -> Option<usize> {
        let i: usize = name.strip_prefix(prefix)?.strip_suffix(']')?.parse().ok()?;
        (1..=TABLE_POINTS).contains(&i).then_some(i - 1)
    };
    Some(match name {
        "sigma0" => Parameter::Sigma0,
        "sigma1" => Parameter::Sigma1,
        "sigma2" => Parameter::Sigma2,
        "sigma2_neg" => Parameter::Sigma2Neg,
        "F_offset" => Parameter::FOffset,
        "Fc" => Parameter::Fc,
        "Fs" => Parameter::Fs,
        "vs" => Parameter::Vs,
        "stribeck_exponent" => Parameter::StribeckExponent,
        "vd" => Parameter::Vd,
        "Fc_neg" => Parameter::FcNeg,
        "Fs_neg" => Parameter::FsNeg,
        _ => {
            if let Some(i) = indexed("scale_pos[") {
                Parameter::ScalePos(i)
            } else {
                Parameter::ScaleNeg(indexed("scale_neg[")?)
            }
        }
    })
}

/// Set the LuGre FMU parameter `name` in `p` (names it does not have
/// are left: the law's outputs' switches, say).
fn set_lugre(p: &mut LuGreParams, name: &str, value: f64) {
    let flag = value != 0.0;
    let table = |prefix: &str| -> Option<usize> {
        let i: usize = name.strip_prefix(prefix)?.strip_suffix(']')?.parse().ok()?;
        (1..=TABLE_POINTS).contains(&i).then_some(i - 1)
    };
    match name {
        "sigma0" => p.sigma0 = value,
        "sigma1" => p.sigma1 = value,
        "sigma2" => p.sigma2 = value,
        "direction_dependent_viscous" => p.direction_dependent_viscous = flag,
        "sigma2_neg" => p.sigma2_neg = value,
        "F_offset" => p.f_offset = value,
        "Fc" => p.fc = value,
        "Fs" => p.fs = value,
        "vs" => p.vs = value,
        "stribeck_exponent" => p.stribeck_exponent = value,
        "vd" => p.vd = value,
        "direction_dependent" => p.direction_dependent = flag,
        "Fc_neg" => p.fc_neg = value,
        "Fs_neg" => p.fs_neg = value,
        "normal_force_form" => p.normal_force_form = flag,
        "position_dependent" => p.position_dependent = flag,
        "n_table" => p.n_table = value as usize,
        _ => {
            if let Some(i) = table("x_table[") {
                p.x_table[i] = value;
            } else if let Some(i) = table("scale_pos[") {
                p.scale_pos[i] = value;
            } else if let Some(i) = table("scale_neg[") {
                p.scale_neg[i] = value;
            }
        }
    }
}
