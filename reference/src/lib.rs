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
//! - [`spec`]: a system as plain data (components with model names, GUIDs
//!   and parameter values; connections), and [`ReferenceModel`], which
//!   recognises one of the couplings above in it;
//! - [`metrics`]: the stick-slip figures of MODELS.md.
//!
//! Parameters are interpreted, and output columns named and computed from
//! a state, by the FMU adapters' own variable tables and `compute_outputs`
//! (`friction-fmu`, `rig-fmu`, in process), so the columns mean exactly
//! what the FMUs' outputs mean; the dynamics come from the physics crates.
#![forbid(unsafe_code)]

pub mod metrics;
pub mod quasi_static;
pub mod radau;
pub mod rig_friction;
pub mod spec;

use friction_fmu::bristle::BristleFmu;
use friction_fmu::dahl::DahlFmu;
use friction_fmu::lugre::LuGreFmu;
use friction_laws::bristle::Bristle;
use friction_laws::dahl::Dahl;
use friction_laws::lugre::LuGre;
use quasi_static::{BristleInput, QuasiStaticBristle};
use radau::{RadauError, RadauStats};
use rig_dynamics::rig1d::{Rig1D, Rig1DInputs};
use rig_fmu::rig1d::Rig1DFmu;
use rig_friction::{DynamicLaw, PositionSource, RigWithFriction, VelocitySource};
use spec::Component;
pub use spec::{ComponentSpec, MapError, SystemSpec, Value};
use std::fmt;
use std::io::Write;
use std::path::Path;

/// The relative tolerance of the reference solutions (MODELS.md: "Radau
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

    /// CSV as `fricsim run` writes it: `time` first, then the columns;
    /// numbers in Rust's shortest round-trip form, so they parse back
    /// exactly.
    pub fn write_csv(&self, path: &Path) -> std::io::Result<()> {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
        writeln!(out, "time,{}", self.columns.join(","))?;
        for (t, row) in self.time.iter().zip(&self.rows) {
            write!(out, "{t:?}")?;
            for x in row {
                write!(out, ",{x:?}")?;
            }
            writeln!(out)?;
        }
        out.flush()
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
}

/// A system of this project's FMUs mapped onto one monolithic model.
pub struct ReferenceModel {
    components: Vec<Component>,
    rig: usize,
    friction: usize,
    coupled: Coupled,
    /// Inputs set from the solution when outputs are evaluated.
    rig_force_vr: u32,
    friction_v_vr: Option<u32>,
    friction_x_vr: Option<u32>,
    description: String,
}

/// `component.variable` split at the first dot.
fn split(port: &str) -> Result<(&str, &str), MapError> {
    port.split_once('.')
        .filter(|(c, v)| !c.is_empty() && !v.is_empty())
        .ok_or_else(|| MapError(format!("`{port}` is not component.variable")))
}

impl ReferenceModel {
    /// Recognises the coupling: two components, a `Rig1D` and a friction
    /// law, connected `friction.F → rig.F` and
    /// - LuGre or Dahl (rig m > 0): `rig.v` (or `rig.v_body`) → `friction.v`,
    ///   and for LuGre optionally `rig.x` (or `rig.x_rel`) → `friction.x`;
    /// - Bristle (rig m = 0, c = 0): `rig.x` (or `rig.x_rel`) → `friction.x`.
    ///
    /// Unconnected inputs keep their start values. Anything else is refused
    /// with a message naming the component or connection.
    pub fn from_spec(spec: &SystemSpec) -> Result<ReferenceModel, MapError> {
        let names: Vec<&str> = spec.components.iter().map(|c| c.name.as_str()).collect();
        if spec.components.len() != 2 {
            return Err(MapError(format!(
                "a reference exists for a Rig1D and one friction law (2 components); this system has {}: {}",
                names.len(),
                names.join(", ")
            )));
        }
        let components = spec
            .components
            .iter()
            .map(Component::from_spec)
            .collect::<Result<Vec<_>, _>>()?;
        let rigs: Vec<usize> = (0..2)
            .filter(|&i| components[i].info.model_name == "Rig1D")
            .collect();
        let (rig, friction) = match rigs.as_slice() {
            [r] => (*r, 1 - *r),
            _ => {
                return Err(MapError(format!(
                    "a reference needs one Rig1D and one friction law; components {} are {} and {}",
                    names.join(", "),
                    components[0].info.model_name,
                    components[1].info.model_name
                )))
            }
        };
        let law = components[friction].info.model_name;
        let (rig_name, fr_name) = (&components[rig].name, &components[friction].name);

        // Connections.
        let mut force = false;
        let mut v_from: Option<String> = None;
        let mut x_from: Option<String> = None;
        for (from, to) in &spec.connections {
            let (fc, fv) = split(from)?;
            let (tc, tv) = split(to)?;
            let known = if fc == fr_name && tc == rig_name {
                fv == "F" && tv == "F"
            } else if fc == rig_name && tc == fr_name {
                match (law, tv) {
                    ("LuGre" | "Dahl", "v") => matches!(fv, "v" | "v_body"),
                    ("LuGre" | "Bristle", "x") => matches!(fv, "x" | "x_rel"),
                    _ => false,
                }
            } else {
                false
            };
            if !known {
                return Err(MapError(format!(
                    "connection {from} → {to}: not part of a coupling the reference knows (Rig1D + {law}: {})",
                    expected(law, rig_name, fr_name)
                )));
            }
            let slot = match tv {
                "F" => {
                    let seen = force;
                    force = true;
                    seen
                }
                "v" => v_from.replace(fv.to_string()).is_some(),
                _ => x_from.replace(fv.to_string()).is_some(),
            };
            if slot {
                return Err(MapError(format!("input {to} is connected twice")));
            }
        }
        let needs_v = law != "Bristle";
        let needs_x = law == "Bristle";
        if !force || (needs_v && v_from.is_none()) || (needs_x && x_from.is_none()) {
            return Err(MapError(format!(
                "components `{rig_name}` (Rig1D) and `{fr_name}` ({law}) are not coupled as the reference needs: {}",
                expected(law, rig_name, fr_name)
            )));
        }

        // Physics objects from the FMU adapters' parameter semantics.
        let rc = &components[rig];
        let rig_params = Rig1DFmu::params(&rc.values)
            .map_err(|e| MapError(format!("component `{rig_name}` (Rig1D): {e}")))?;
        let rig_obj = Rig1D::new(rig_params)
            .map_err(|e| MapError(format!("component `{rig_name}` (Rig1D): {e}")))?;
        let input = |name: &str| rc.vr(name).map_or(0.0, |vr| rc.values.real(vr));
        let inputs = Rig1DInputs {
            friction: 0.0,
            f_ext: input("F_ext"),
            x_act: input("x_act_in"),
            x_ref: input("x_ref"),
            v_ref: input("v_ref"),
        };
        let fc = &components[friction];
        let law_err = |e: String| MapError(format!("component `{fr_name}` ({law}): {e}"));
        let (m, c) = (rig_params.m, rig_params.c);
        let coupled = match law {
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
                let velocity = match v_from.as_deref() {
                    Some("v_body") => VelocitySource::Body,
                    _ => VelocitySource::Slip,
                };
                let position = match x_from.as_deref() {
                    Some("x") => PositionSource::Position,
                    Some(_) => PositionSource::Relative,
                    None => {
                        PositionSource::Constant(fc.vr("x").map_or(0.0, |vr| fc.values.real(vr)))
                    }
                };
                Coupled::Dynamic(RigWithFriction {
                    rig: rig_obj,
                    law: dynamic,
                    inputs,
                    velocity,
                    position,
                })
            }
            _ => {
                if m != 0.0 || c != 0.0 {
                    return Err(MapError(format!(
                        "component `{fr_name}` (Bristle): the reference solves the bristle law only with the quasi-static rig (m = 0, c = 0), but `{rig_name}` has m = {m}, c = {c}"
                    )));
                }
                let b = Bristle::new(BristleFmu::params(&fc.values).map_err(law_err)?)
                    .map_err(|e| law_err(e.to_string()))?;
                Coupled::QuasiStatic(QuasiStaticBristle {
                    rig: rig_obj,
                    bristle: b,
                    inputs,
                    input: match x_from.as_deref() {
                        Some("x") => BristleInput::Position,
                        _ => BristleInput::Relative,
                    },
                })
            }
        };
        let description = match &coupled {
            Coupled::Dynamic(_) => format!(
                "Rig1D `{rig_name}` (m = {m}) + {law} `{fr_name}`: one ODE system, Radau IIA"
            ),
            Coupled::QuasiStatic(_) => format!(
                "Rig1D `{rig_name}` (quasi-static, m = 0) + Bristle `{fr_name}`: exact root of the force balance at each output time"
            ),
        };
        let rig_force_vr = components[rig].vr("F").expect("Rig1D has input F");
        let friction_v_vr = v_from.as_ref().and_then(|_| components[friction].vr("v"));
        let friction_x_vr = x_from.as_ref().and_then(|_| components[friction].vr("x"));
        Ok(ReferenceModel {
            components,
            rig,
            friction,
            coupled,
            rig_force_vr,
            friction_v_vr,
            friction_x_vr,
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
                    let law_state = [y[3]];
                    let r = self.row(
                        &[tau, y[0], y[1], y[2]],
                        c.force,
                        &law_state,
                        c.v,
                        c.x,
                        false,
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
                        p.force,
                        &b.state_to_vec(),
                        f64::NAN,
                        p.xi,
                        p.held,
                    );
                    self.push(&mut table, start + p.tau, r, &mut failure);
                });
                None
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

    /// Every output column at one state: the rig's state and friction
    /// input `force`, the law's state and its inputs `v`, `x`. `held`: the
    /// bristle law is held at a reversal, where its force is the balance
    /// value `force` rather than the law's branch value.
    fn row(
        &mut self,
        rig_state: &[f64],
        force: f64,
        law_state: &[f64],
        v: f64,
        x: f64,
        held: bool,
    ) -> Result<Vec<f64>, String> {
        let mut friction_inputs = Vec::new();
        if let Some(vr) = self.friction_v_vr {
            friction_inputs.push((vr, v));
        }
        if let Some(vr) = self.friction_x_vr {
            friction_inputs.push((vr, x));
        }
        let rig_vals = self.components[self.rig]
            .outputs(rig_state, &[(self.rig_force_vr, force)])
            .map_err(|e| format!("{}: {e}", self.components[self.rig].name))?;
        let mut fr_vals = self.components[self.friction]
            .outputs(law_state, &friction_inputs)
            .map_err(|e| format!("{}: {e}", self.components[self.friction].name))?;
        if held {
            if let Some(vr) = self.components[self.friction].vr("F") {
                fr_vals.set(vr, force);
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

/// The connections a coupling needs, for messages.
fn expected(law: &str, rig: &str, fr: &str) -> String {
    match law {
        "LuGre" => format!(
            "{fr}.F → {rig}.F, {rig}.v (or v_body) → {fr}.v, optionally {rig}.x (or x_rel) → {fr}.x"
        ),
        "Dahl" => format!("{fr}.F → {rig}.F, {rig}.v (or v_body) → {fr}.v"),
        _ => format!("{fr}.F → {rig}.F, {rig}.x (or x_rel) → {fr}.x"),
    }
}
