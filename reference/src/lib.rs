//! Monolithic reference solutions for the friction co-simulations: the
//! friction laws (`friction-laws`) and the rig equations (`rig-dynamics`)
//! solved together in one process, without communication steps, so that
//! the difference between a co-simulation result and this solution is the
//! co-simulation error.
//!
//! - [`radau`]: the stiff integrator (Radau IIA, order 5, adaptive),
//!   checked on problems with closed-form or published solutions;
//! - [`rig_friction`]: Rig1D (m > 0) with LuGre or Dahl as one ODE system;
//! - [`quasi_static`]: the quasi-static Rig1D (m = 0) with the bristle
//!   model, solved exactly at each output time;
//! - [`planar`]: Rig2D with the 2-D bristle law, a hybrid ODE system
//!   (stick and slide modes);
//! - [`spec`]: a system as plain data (components with model names, GUIDs
//!   and parameter values; connections), and [`ReferenceModel`], which
//!   recognises one of the couplings above in it;
//! - [`metrics`]: the stick-slip figures of docs/models.md, "Reference figures".
//!
//! Parameters are interpreted, and output columns named and computed from
//! a state, by the FMU adapters' own variable tables and `compute_outputs`
//! (`friction-fmu`, `rig-fmu`, in process), so the columns mean exactly
//! what the FMUs' outputs mean; the dynamics come from the physics crates.
#![forbid(unsafe_code)]

pub mod metrics;
pub mod planar;
pub mod quasi_static;
pub mod radau;
pub mod rig_friction;
pub mod spec;

use friction_fmu::bristle::BristleFmu;
use friction_fmu::bristle2d::Bristle2DFmu;
use friction_fmu::dahl::DahlFmu;
use friction_fmu::lugre::LuGreFmu;
use friction_laws::bristle::Bristle;
use friction_laws::bristle2d::Bristle2D;
use friction_laws::dahl::Dahl;
use friction_laws::lugre::LuGre;
use planar::PlanarBristle;
use quasi_static::{BristleInput, QuasiStaticBristle};
use radau::{RadauError, RadauStats};
use rig_dynamics::rig1d::{Rig1D, Rig1DInputs};
use rig_dynamics::rig2d::Rig2D;
use rig_fmu::rig1d::Rig1DFmu;
use rig_fmu::rig2d::Rig2DFmu;
use rig_friction::{DynamicLaw, PositionSource, RigWithFriction, VelocitySource};
use spec::Component;
pub use spec::{ComponentSpec, MapError, SystemSpec, Value};
use std::fmt;

/// The relative tolerance of the reference solutions (docs/models.md, "Reference figures": "Radau
/// IIA, rtol 1e-10").
pub const RTOL: f64 = 1e-10;

/// A result table: `time` and one column per `component.output`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub columns: Vec<String>,
    pub time: Vec<f64>,
    pub rows: Vec<Vec<f64>>,
}

impl Table {
    /// The values of one column.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r[k]).collect())
    }
}

/// Why a reference solution could not be computed.
#[derive(Clone, Debug, PartialEq)]
pub enum ReferenceError {
    /// Output times not finite, or not increasing from the start time.
    Times(String),
    Integration(RadauError),
    /// A component refused the state when its outputs were evaluated.
    Outputs(String),
}

impl fmt::Display for ReferenceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReferenceError::Times(m) => write!(f, "output times: {m}"),
            ReferenceError::Integration(e) => write!(f, "integration failed: {e}"),
            ReferenceError::Outputs(m) => write!(f, "outputs: {m}"),
        }
    }
}

impl std::error::Error for ReferenceError {}

impl From<RadauError> for ReferenceError {
    fn from(e: RadauError) -> Self {
        ReferenceError::Integration(e)
    }
}

/// The coupled equations a system was recognised as.
#[derive(Clone, Debug)]
enum Coupled {
    Dynamic(RigWithFriction),
    QuasiStatic(QuasiStaticBristle),
    Planar(Box<PlanarBristle>),
}

/// A system of this project's FMUs mapped onto one monolithic model.
pub struct ReferenceModel {
    components: Vec<Component>,
    rig: usize,
    friction: usize,
    coupled: Coupled,
    /// Value references of the connected inputs, set from the solution
    /// when outputs are evaluated: the rig's friction force input(s), the
    /// law's velocity input(s) and position input, and the law's force
    /// output(s) (overridden where the law's own evaluation from its state
    /// would not see the mode).
    rig_force: Vec<u32>,
    law_velocity: Vec<u32>,
    law_position: Option<u32>,
    law_force: Vec<u32>,
    description: String,
}

/// One connection a coupling knows: into the rig (`to_rig`) or into the
/// law, the input's name, the outputs it may come from, and whether the
/// coupling needs it.
struct Link {
    to_rig: bool,
    input: &'static str,
    sources: &'static [&'static str],
    required: bool,
}

const fn link(
    to_rig: bool,
    input: &'static str,
    sources: &'static [&'static str],
    required: bool,
) -> Link {
    Link {
        to_rig,
        input,
        sources,
        required,
    }
}

/// The connections of each coupling with a reference.
fn links(rig: &str, law: &str) -> Option<&'static [Link]> {
    const FORCE: Link = link(true, "F", &["F"], true);
    const VELOCITY: Link = link(false, "v", &["v", "v_body"], true);
    static LUGRE: [Link; 3] = [FORCE, VELOCITY, link(false, "x", &["x", "x_rel"], false)];
    static DAHL: [Link; 2] = [FORCE, VELOCITY];
    static BRISTLE: [Link; 2] = [FORCE, link(false, "x", &["x", "x_rel"], true)];
    static PLANAR: [Link; 4] = [
        link(true, "F1", &["F1"], true),
        link(true, "F2", &["F2"], true),
        link(false, "v1", &["v1"], true),
        link(false, "v2", &["v2"], true),
    ];
    Some(match (rig, law) {
        ("Rig1D", "LuGre") => &LUGRE,
        ("Rig1D", "Dahl") => &DAHL,
        ("Rig1D", "Bristle") => &BRISTLE,
        ("Rig2D", "Bristle2D") => &PLANAR,
        _ => return None,
    })
}

/// `component.variable` split at the first dot.
fn split(port: &str) -> Result<(&str, &str), MapError> {
    port.split_once('.')
        .filter(|(c, v)| !c.is_empty() && !v.is_empty())
        .ok_or_else(|| MapError(format!("`{port}` is not component.variable")))
}

impl ReferenceModel {
    /// Recognises the coupling: two components, a rig and a friction law:
    /// - `Rig1D` (m > 0) with LuGre or Dahl: `friction.F → rig.F`,
    ///   `rig.v` (or `rig.v_body`) → `friction.v`, and for LuGre optionally
    ///   `rig.x` (or `rig.x_rel`) → `friction.x`;
    /// - `Rig1D` (m = 0, c = 0) with Bristle: `friction.F → rig.F`,
    ///   `rig.x` (or `rig.x_rel`) → `friction.x`;
    /// - `Rig2D` with Bristle2D: `friction.F1, F2 → rig.F1, F2`,
    ///   `rig.v1, v2 → friction.v1, v2`.
    ///
    /// Unconnected inputs keep their start values. Anything else is refused
    /// with a message naming the component or connection.
    pub fn from_spec(spec: &SystemSpec) -> Result<ReferenceModel, MapError> {
        let names: Vec<&str> = spec.components.iter().map(|c| c.name.as_str()).collect();
        if spec.components.len() != 2 {
            return Err(MapError(format!(
                "a reference exists for a rig and one friction law (2 components); this system has {}: {}",
                names.len(),
                names.join(", ")
            )));
        }
        let components = spec
            .components
            .iter()
            .map(Component::from_spec)
            .collect::<Result<Vec<_>, _>>()?;
        let is_rig = |i: usize| matches!(components[i].info.model_name, "Rig1D" | "Rig2D");
        let (rig, friction) = match (is_rig(0), is_rig(1)) {
            (true, false) => (0, 1),
            (false, true) => (1, 0),
            _ => {
                return Err(MapError(format!(
                    "a reference needs one rig (Rig1D or Rig2D) and one friction law; components {} are {} and {}",
                    names.join(", "),
                    components[0].info.model_name,
                    components[1].info.model_name
                )))
            }
        };
        let rig_model = components[rig].info.model_name;
        let law = components[friction].info.model_name;
        let (rig_name, fr_name) = (&components[rig].name, &components[friction].name);
        let Some(table) = links(rig_model, law) else {
            return Err(MapError(format!(
                "component `{fr_name}` ({law}) with {rig_model} `{rig_name}`: no monolithic reference for this pair (supported: Rig1D with LuGre, Dahl or Bristle; Rig2D with Bristle2D)"
            )));
        };
        let expected = expected(table, rig_name, fr_name);

        // Connections: each onto a link of the table, each input once.
        let mut sources: Vec<Option<String>> = vec![None; table.len()];
        for (from, to) in &spec.connections {
            let (fc, fv) = split(from)?;
            let (tc, tv) = split(to)?;
            let to_rig = fc == fr_name && tc == rig_name;
            let to_law = fc == rig_name && tc == fr_name;
            let k = table.iter().position(|l| {
                (to_rig || to_law) && l.to_rig == to_rig && l.input == tv && l.sources.contains(&fv)
            });
            let Some(k) = k else {
                return Err(MapError(format!(
                    "connection {from} → {to}: not part of a coupling the reference knows ({rig_model} + {law}: {expected})"
                )));
            };
            if sources[k].replace(fv.to_string()).is_some() {
                return Err(MapError(format!("input {to} is connected twice")));
            }
        }
        if table
            .iter()
            .zip(&sources)
            .any(|(l, s)| l.required && s.is_none())
        {
            return Err(MapError(format!(
                "components `{rig_name}` ({rig_model}) and `{fr_name}` ({law}) are not coupled as the reference needs: {expected}"
            )));
        }
        let source = |input: &str| {
            table
                .iter()
                .zip(&sources)
                .find(|(l, _)| l.input == input && !l.to_rig)
                .and_then(|(_, s)| s.as_deref())
        };
        let (v_from, x_from) = (source("v"), source("x"));

        // Physics objects from the FMU adapters' parameter semantics.
        let rc = &components[rig];
        let fc = &components[friction];
        let rig_err = |e: String| MapError(format!("component `{rig_name}` ({rig_model}): {e}"));
        let law_err = |e: String| MapError(format!("component `{fr_name}` ({law}): {e}"));
        let input = |name: &str| rc.vr(name).map_or(0.0, |vr| rc.values.real(vr));
        let (coupled, description) = if rig_model == "Rig2D" {
            let rig_obj = Rig2D::new(Rig2DFmu::params(&rc.values)).map_err(rig_err)?;
            let b = Bristle2D::new(Bristle2DFmu::params(&fc.values))
                .map_err(|e| law_err(e.to_string()))?;
            (
                Coupled::Planar(Box::new(PlanarBristle {
                    rig: rig_obj,
                    law: b,
                    f_ext: [input("F_ext1"), input("F_ext2")],
                })),
                format!(
                    "Rig2D `{rig_name}` + Bristle2D `{fr_name}`: hybrid ODE system (stick and slide modes), Radau IIA"
                ),
            )
        } else {
            let rig_params = Rig1DFmu::params(&rc.values).map_err(rig_err)?;
            let rig_obj = Rig1D::new(rig_params).map_err(rig_err)?;
            let inputs = Rig1DInputs {
                friction: 0.0,
                f_ext: input("F_ext"),
                x_act: input("x_act_in"),
                x_ref: input("x_ref"),
                v_ref: input("v_ref"),
            };
            let (m, c) = (rig_params.m, rig_params.c);
            match law {
                "LuGre" | "Dahl" => {
                    if m <= 0.0 {
                        return Err(MapError(format!(
                            "component `{rig_name}` (Rig1D): m = {m}: the quasi-static rig has a reference only with the Bristle law; {law} needs m > 0"
                        )));
                    }
                    let dynamic = if law == "LuGre" {
                        let l = LuGre::new(LuGreFmu::params(&fc.values))
                            .map_err(|e| law_err(e.to_string()))?;
                        let normal_force = fc.vr("Fn").map_or(1.0, |vr| fc.values.real(vr));
                        DynamicLaw::LuGre {
                            law: Box::new(l),
                            normal_force,
                        }
                    } else {
                        DynamicLaw::Dahl(
                            Dahl::new(DahlFmu::params(&fc.values))
                                .map_err(|e| law_err(e.to_string()))?,
                        )
                    };
                    let velocity = match v_from {
                        Some("v_body") => VelocitySource::Body,
                        _ => VelocitySource::Slip,
                    };
                    let position = match x_from {
                        Some("x") => PositionSource::Position,
                        Some(_) => PositionSource::Relative,
                        None => PositionSource::Constant(
                            fc.vr("x").map_or(0.0, |vr| fc.values.real(vr)),
                        ),
                    };
                    (
                        Coupled::Dynamic(RigWithFriction {
                            rig: rig_obj,
                            law: dynamic,
                            inputs,
                            velocity,
                            position,
                        }),
                        format!(
                            "Rig1D `{rig_name}` (m = {m}) + {law} `{fr_name}`: one ODE system, Radau IIA"
                        ),
                    )
                }
                _ => {
                    if m != 0.0 || c != 0.0 {
                        return Err(MapError(format!(
                            "component `{fr_name}` (Bristle): the reference solves the bristle law only with the quasi-static rig (m = 0, c = 0), but `{rig_name}` has m = {m}, c = {c}"
                        )));
                    }
                    let b = Bristle::new(BristleFmu::params(&fc.values).map_err(law_err)?)
                        .map_err(|e| law_err(e.to_string()))?;
                    (
                        Coupled::QuasiStatic(QuasiStaticBristle {
                            rig: rig_obj,
                            bristle: b,
                            inputs,
                            input: match x_from {
                                Some("x") => BristleInput::Position,
                                _ => BristleInput::Relative,
                            },
                        }),
                        format!(
                            "Rig1D `{rig_name}` (quasi-static, m = 0) + Bristle `{fr_name}`: exact root of the force balance at each output time"
                        ),
                    )
                }
            }
        };
        let vrs = |c: &Component, names: &[&str]| -> Vec<u32> {
            names.iter().filter_map(|n| c.vr(n)).collect()
        };
        let planar = rig_model == "Rig2D";
        let (forces, velocities): (&[&str], &[&str]) = if planar {
            (&["F1", "F2"], &["v1", "v2"])
        } else {
            (&["F"], if v_from.is_some() { &["v"] } else { &[] })
        };
        let rig_force = vrs(&components[rig], forces);
        let law_velocity = vrs(&components[friction], velocities);
        let law_force = vrs(&components[friction], forces);
        let law_position = x_from.and_then(|_| components[friction].vr("x"));
        Ok(ReferenceModel {
            components,
            rig,
            friction,
            coupled,
            rig_force,
            law_velocity,
            law_position,
            law_force,
            description,
        })
    }

    /// One line on what was recognised and how it is solved.
    pub fn description(&self) -> &str {
        &self.description
    }

    /// `component.output` for every Real output (and recorded variable),
    /// components in the order of the system: the columns of `fricsim run`.
    pub fn columns(&self) -> Vec<String> {
        self.components
            .iter()
            .flat_map(|c| {
                c.columns
                    .iter()
                    .map(move |(n, _)| format!("{}.{n}", c.name))
            })
            .collect()
    }

    /// Records the Real variable `component.variable` besides the outputs
    /// (after its component's outputs), as `fricsim run --record` does.
    pub fn record(&mut self, port: &str) -> Result<(), MapError> {
        let (c, v) = split(port)?;
        let names: Vec<&str> = self.components.iter().map(|x| x.name.as_str()).collect();
        let Some(i) = self.components.iter().position(|x| x.name == c) else {
            return Err(MapError(format!(
                "cannot record `{port}`: no component `{c}` (components: {})",
                names.join(", ")
            )));
        };
        self.components[i].record(v)
    }

    /// The solution at the absolute times `times` (increasing, the first
    /// ≥ `start`), the rigs' clocks starting at `start`.
    pub fn solve(
        &mut self,
        start: f64,
        times: &[f64],
        rtol: f64,
    ) -> Result<(Table, Option<RadauStats>), ReferenceError> {
        if !start.is_finite() {
            return Err(ReferenceError::Times(format!(
                "start {start} is not finite"
            )));
        }
        let mut prev = start;
        for (i, &t) in times.iter().enumerate() {
            if !(t.is_finite() && (t > prev || (i == 0 && t == start))) {
                return Err(ReferenceError::Times(format!(
                    "times[{i}] = {t} is not finite or not after {prev}"
                )));
            }
            prev = t;
        }
        let taus: Vec<f64> = times.iter().map(|t| t - start).collect();
        let mut table = Table {
            columns: self.columns(),
            time: Vec::with_capacity(times.len()),
            rows: Vec::with_capacity(times.len()),
        };
        let mut failure: Option<String> = None;
        let coupled = self.coupled.clone();
        let stats = match &coupled {
            Coupled::Dynamic(sys) => {
                let stats = sys.solve(&taus, rtol, |tau, y| {
                    if failure.is_some() {
                        return;
                    }
                    let c = match sys.coupling(tau, y) {
                        Ok(c) => c,
                        Err(e) => {
                            failure = Some(e);
                            return;
                        }
                    };
                    let r = self.row(
                        &[tau, y[0], y[1], y[2]],
                        &[c.force],
                        &[y[3]],
                        &[c.v],
                        c.x,
                        None,
                    );
                    self.push(&mut table, start + tau, r, &mut failure);
                })?;
                Some(stats)
            }
            Coupled::QuasiStatic(sys) => {
                sys.solve(&taus, |p, b| {
                    if failure.is_some() {
                        return;
                    }
                    let r = self.row(
                        &[p.tau, p.x, p.xd, 0.0],
                        &[p.force],
                        &b.state_to_vec(),
                        &[],
                        p.xi,
                        p.held.then_some(&[p.force][..]),
                    );
                    self.push(&mut table, start + p.tau, r, &mut failure);
                });
                None
            }
            Coupled::Planar(sys) => {
                let stats = sys.solve(&taus, rtol, |tau, y, sliding| {
                    if failure.is_some() {
                        return;
                    }
                    let c = match sys.coupling(tau, y, sliding) {
                        Ok(c) => c,
                        Err(e) => {
                            failure = Some(e);
                            return;
                        }
                    };
                    let r = self.row(
                        &[tau, y[0], y[1], 0.0, tau, y[2], y[3], 0.0],
                        &c.force,
                        &c.z,
                        &c.v,
                        f64::NAN,
                        Some(&c.force),
                    );
                    self.push(&mut table, start + tau, r, &mut failure);
                })?;
                Some(stats)
            }
        };
        match failure {
            Some(e) => Err(ReferenceError::Outputs(e)),
            None => Ok((table, stats)),
        }
    }

    fn push(
        &self,
        table: &mut Table,
        t: f64,
        row: Result<Vec<f64>, String>,
        failure: &mut Option<String>,
    ) {
        match row {
            Ok(r) => {
                table.time.push(t);
                table.rows.push(r);
            }
            Err(e) => *failure = Some(format!("t = {t}: {e}")),
        }
    }

    /// Every output column at one state: the rig's state and its friction
    /// input(s) `force`, the law's state and its inputs `v` (velocity
    /// inputs in order) and `x` (position input, if connected).
    /// `law_force`: the law's force output(s) as the coupled solution has
    /// them, where the law evaluated from its state alone would not see
    /// the mode (the bristle law held at a reversal, the 2-D law's stick or
    /// slide mode).
    fn row(
        &mut self,
        rig_state: &[f64],
        force: &[f64],
        law_state: &[f64],
        v: &[f64],
        x: f64,
        law_force: Option<&[f64]>,
    ) -> Result<Vec<f64>, String> {
        let rig_inputs: Vec<(u32, f64)> = self
            .rig_force
            .iter()
            .copied()
            .zip(force.iter().copied())
            .collect();
        let mut law_inputs: Vec<(u32, f64)> = self
            .law_velocity
            .iter()
            .copied()
            .zip(v.iter().copied())
            .collect();
        if let Some(vr) = self.law_position {
            law_inputs.push((vr, x));
        }
        let rig_vals = self.components[self.rig]
            .outputs(rig_state, &rig_inputs)
            .map_err(|e| format!("{}: {e}", self.components[self.rig].name))?;
        let mut fr_vals = self.components[self.friction]
            .outputs(law_state, &law_inputs)
            .map_err(|e| format!("{}: {e}", self.components[self.friction].name))?;
        if let Some(f) = law_force {
            for (&vr, &value) in self.law_force.iter().zip(f) {
                fr_vals.set(vr, value);
            }
        }
        let mut row = Vec::new();
        for (i, c) in self.components.iter().enumerate() {
            let vals = if i == self.rig { &rig_vals } else { &fr_vals };
            row.extend(c.columns.iter().map(|&(_, vr)| vals.real(vr)));
        }
        Ok(row)
    }
}

/// The connections a coupling needs, for messages:
/// `friction.F → rig.F, rig.v (or v_body) → friction.v, optionally …`.
fn expected(table: &[Link], rig: &str, fr: &str) -> String {
    table
        .iter()
        .map(|l| {
            let (from, to) = if l.to_rig { (fr, rig) } else { (rig, fr) };
            let alternatives: Vec<String> = l.sources[1..]
                .iter()
                .map(|s| format!(" (or {s})"))
                .collect();
            format!(
                "{}{from}.{}{} → {to}.{}",
                if l.required { "" } else { "optionally " },
                l.sources[0],
                alternatives.concat(),
                l.input
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}
