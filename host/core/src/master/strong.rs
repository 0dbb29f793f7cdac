//! Strong coupling: each macro step is iterated until the interface agrees.
//!
//! Unknowns are the connected input values `U` (one per connection), held
//! over the step `[t, t + h]`. Stepping every component from its state at
//! `t` with inputs `U` gives the connected outputs `Y(U)` at `t + h`; the
//! coupling equations are
//!
//! ```text
//! R(U) = U − Y(U) = 0.
//! ```
//!
//! Holding the end-of-step values over the step is the interface analogue
//! of implicit Euler: a stiff contact (a 1e5–1e7 N/m bristle against a
//! mass) stays stable at macro steps far above its period, and a
//! direct-feedthrough loop (a quasi-static rig against a displacement-driven
//! friction law) becomes an algebraic equation solved at every step.
//!
//! * **Newton**: `(I − J)·ΔU = −R`, `J = ∂Y/∂U`. Columns of `J` come from
//!   `fmi2GetDirectionalDerivative` right after `fmi2DoStep` (the step
//!   sensitivity, as this project's FMUs provide it) or from finite
//!   differences: the component is rolled back with `fmi2SetFMUstate` and
//!   stepped again with one input perturbed. In `Auto` mode the directional
//!   derivatives of each component are checked against finite differences
//!   once, at its first Jacobian; an FMU whose `fmi2GetDirectionalDerivative`
//!   gives something else (the FMI 2.0 text only promises the
//!   direct-feedthrough partials) is then differenced.
//! * **Fixed point**: `U ← Y(U)` (Gauss–Jacobi waveform iteration), kept for
//!   comparison: it diverges when the loop gain |∂Y/∂U| exceeds one.
//!
//! * **Interpolated inputs** ([`StrongCoupling::interpolate`]): each input
//!   ramps linearly over the step from its value at `t` to `U`
//!   (`fmi2SetRealInputDerivatives`) instead of holding `U`: the interface
//!   analogue of the trapezoidal rule, second order in h where the hold is
//!   first order. The FMU's directional derivative is the sensitivity to a
//!   held input, not to the end of a ramp, so these components are
//!   differenced.
//!
//! Between iterations every component is restored to its state at `t`
//! (`fmi2GetFMUstate` / `fmi2SetFMUstate`): every FMU must declare
//! `canGetAndSetFMUstate`, and the first step refuses, naming the instance,
//! before anything is stepped. Calls that would change nothing are left out
//! (the FMU's change count, [`System::changes`], tells): a
//! state is not saved again while the FMU is still in it, and the first
//! iterate of a step, the last accepted U the FMUs were stepped on, is not
//! set again while they have seen nothing but getters since.
//!
//! An FMU without directional derivatives is differenced. A step that does
//! not converge is an error carrying the residual
//! ([`FmuError::NotConverged`]), never accepted. A step converges when
//! `|R_k| ≤ atol_k + rtol·max(|U_k|, |Y_k|)` for every connection, with
//! `atol_k = atol·nominal_k` from the input variable's nominal (default 1).

use super::MasterAlgorithm;
use crate::fmu::{FmuState, Rollback, ValueReference};
use crate::system::System;
use crate::FmuError;
use nalgebra::DMatrix;

/// How many past residual norms the non-monotone line search compares with.
const NONMONOTONE_MEMORY: usize = 4;

/// How an iteration updates the interface values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Update {
    Newton,
    FixedPoint,
}

/// Where Newton's Jacobian columns come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JacobianSource {
    /// `fmi2GetDirectionalDerivative` after the step.
    Directional,
    /// Rollback and a perturbed step per input.
    FiniteDifference,
    /// Directional where the FMU provides it and it agrees with finite
    /// differences at the first check; finite differences otherwise.
    Auto,
}

/// Error control of the macro step (see [`StrongCoupling::step_control`]):
/// a step is accepted when the estimated hold error of every connection is
/// at most `atol·nominal + rtol·max|U|` (the largest magnitude of that
/// connection so far); the next step is h·clamp(0.9/err,
/// 0.2, 2) (the estimate is first order in h), never below `h_min` nor
/// above the communication interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepControl {
    pub rtol: f64,
    pub atol: f64,
    pub h_min: f64,
}

/// Counters of a strongly coupled run, for the convergence report.
#[derive(Clone, Debug, Default)]
pub struct ConvergenceReport {
    /// Steps solved (macro steps, or parts of one after a split).
    pub steps: usize,
    /// Every iteration, those of rejected attempts included.
    pub iterations: usize,
    /// Most iterations a solved step needed.
    pub max_iterations: usize,
    /// Steps that needed exactly `k + 1` iterations, for k < 8; the last
    /// bin counts 8 or more.
    pub histogram: [usize; 8],
    pub jacobians: usize,
    /// Newton directions taken with the Jacobian of an earlier step
    /// ([`StrongCoupling::reuse_jacobian`]) instead of a new one.
    pub jacobians_reused: usize,
    /// Extra `fmi2DoStep` calls spent on finite differences.
    pub difference_steps: usize,
    /// Newton steps shortened because the residual did not decrease.
    pub backtracks: usize,
    /// Steps rolled back: split in two after Newton failed (fixed steps),
    /// or retried smaller (adaptive steps: error too large or Newton failed).
    pub rejected: usize,
    /// Adaptive steps accepted, and the smallest and largest of them.
    pub accepted: usize,
    pub smallest_step: f64,
    pub largest_step: f64,
    /// Largest `|R_k| / tolerance_k` of an accepted step (≤ 1).
    pub worst_accepted: f64,
    /// Per component: how its Jacobian columns were obtained.
    pub jacobian_of: Vec<(String, &'static str)>,
}

impl std::fmt::Display for ConvergenceReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mean = self.iterations as f64 / self.steps.max(1) as f64;
        writeln!(
            f,
            "strong coupling: {} steps solved ({} rejected and halved), {} iterations (mean {mean:.2}, max {}), {} Jacobians ({} reused), {} backtracks, {} extra steps for finite differences",
            self.steps, self.rejected, self.iterations, self.max_iterations, self.jacobians, self.jacobians_reused, self.backtracks, self.difference_steps
        )?;
        let bins: Vec<String> = self
            .histogram
            .iter()
            .enumerate()
            .filter(|(_, n)| **n > 0)
            .map(|(k, n)| {
                if k == 7 {
                    format!("≥8: {n}")
                } else {
                    format!("{}: {n}", k + 1)
                }
            })
            .collect();
        writeln!(f, "  iterations per step: {}", bins.join(", "))?;
        if self.accepted > 0 {
            writeln!(
                f,
                "  adaptive macro steps: {} accepted, {} rejected, from {:.3e} s to {:.3e} s",
                self.accepted, self.rejected, self.smallest_step, self.largest_step
            )?;
        }
        writeln!(
            f,
            "  largest accepted mismatch: {:.3} of the tolerance",
            self.worst_accepted
        )?;
        for (name, how) in &self.jacobian_of {
            writeln!(f, "  Jacobian of {name}: {how}")?;
        }
        Ok(())
    }
}

/// Per component: its index lists into the connection table, its saved
/// state, and where its Jacobian columns come from. Kept together so that
/// the loops of a step walk one list, by component index.
struct Ports {
    /// Connections whose input belongs to the component.
    inputs: Vec<usize>,
    /// The component's value references of `inputs`, in order.
    input_vrs: Vec<ValueReference>,
    /// Connections whose output belongs to the component.
    outputs: Vec<usize>,
    output_vrs: Vec<ValueReference>,
    /// The values of `output_vrs` as last read (one `fmi2GetReal` per
    /// component instead of one per connection).
    output_values: Vec<f64>,
    /// When `outputs` are consecutive connections `k0, k0 + 1, …` (a
    /// component with one output, say): `k0`. Their values are then read
    /// straight into place, without `output_values`.
    consecutive_outputs: Option<usize>,
    /// Where the component's Jacobian columns come from (Auto: decided
    /// at the first Jacobian).
    columns: Columns,
    /// Why the component is differenced, when that is decided up front.
    differenced: &'static str,
    /// The convergence report says how the component's columns are
    /// obtained (its entry is no longer "not needed").
    reported: bool,
    /// Inputs ramp linearly over the step from their value at `t` to `U`
    /// (`fmi2SetRealInputDerivatives`) instead of holding `U`.
    ramped: bool,
    /// The component's state at the start of the step being solved.
    state: Option<FmuState>,
    /// The component's change count ([`System::changes`])
    /// when its state was last saved into `state` or restored from there.
    /// While the count stands still, the FMU is in that saved state, and
    /// saving it again would change nothing (the step after a split, the
    /// retry of a rejected adaptive step).
    in_saved_state: Option<u64>,
    /// With held inputs: the change count right after the component was
    /// stepped on `u` in the iteration that converged. While the count
    /// stands still (nothing but `fmi2Get…` calls since: the recorded
    /// sample, the state saved), its inputs still hold `u`, which is also
    /// the first iterate of the next step, and setting them again would
    /// change nothing.
    holds_u: Option<u64>,
}

impl Ports {
    /// Set the component's inputs from `u` (one value per connection):
    /// held, or `ramped` from `start` at `t` to `u` at `t + h`.
    #[inline(always)] // hot: every iteration of every step
    fn set_inputs(
        &self,
        system: &mut System,
        c: usize,
        u: &[f64],
        start: &[f64],
        h: f64,
    ) -> Result<(), FmuError> {
        if self.ramped {
            return self.set_ramped_inputs(system, c, u, start, h);
        }
        for (&k, &vr) in self.inputs.iter().zip(&self.input_vrs) {
            system.set_real(c, &[vr], &[u[k]])?;
        }
        Ok(())
    }

    /// [`Ports::set_inputs`] of a component whose inputs ramp.
    #[inline(never)]
    fn set_ramped_inputs(
        &self,
        system: &mut System,
        c: usize,
        u: &[f64],
        start: &[f64],
        h: f64,
    ) -> Result<(), FmuError> {
        for (&k, &vr) in self.inputs.iter().zip(&self.input_vrs) {
            system.set_real(c, &[vr], &[start[k]])?;
            system.set_real_input_derivatives(c, &[vr], &[1], &[(u[k] - start[k]) / h])?;
        }
        Ok(())
    }

    /// Read the component's connected outputs into `out` (one value per
    /// connection), with one `fmi2GetReal` for all of them.
    #[inline(always)] // hot: every iteration of every step
    fn read_outputs(
        &mut self,
        system: &mut System,
        c: usize,
        out: &mut [f64],
    ) -> Result<(), FmuError> {
        if self.outputs.is_empty() {
            return Ok(());
        }
        if let Some(first) = self.consecutive_outputs {
            let values = &mut out[first..first + self.outputs.len()];
            system.get_real(c, &self.output_vrs, values)?;
            return Ok(());
        }
        system.get_real(c, &self.output_vrs, &mut self.output_values)?;
        for (&k, &y) in self.outputs.iter().zip(&self.output_values) {
            out[k] = y;
        }
        Ok(())
    }

    /// Save the component's state at the start of the step into `state`
    /// (`fmi2GetFMUstate`), unless it is the saved one already.
    #[inline] // hot: every step
    fn save_state(&mut self, system: &mut System, c: usize) -> Result<(), FmuError> {
        match &mut self.state {
            Some(_) if self.in_saved_state == Some(system.changes(c)) => return Ok(()),
            Some(state) => {
                system.update_state(c, state)?;
            }
            None => self.state = Some(system.get_state(c)?),
        }
        // fmi2GetFMUstate is a getter: the count has not moved
        self.in_saved_state = Some(system.changes(c));
        Ok(())
    }

    /// Roll the component back to its saved state (`fmi2SetFMUstate`).
    #[inline(always)] // hot: every iteration after the first
    fn restore(&mut self, system: &mut System, c: usize) -> Result<(), FmuError> {
        let state = self.state.as_ref().expect("saved before stepping");
        match system.set_state(c, state) {
            Ok(()) => {
                self.in_saved_state = Some(system.changes(c));
                Ok(())
            }
            Err(e) => {
                // after a failed fmi2SetFMUstate the FMU's state is unknown
                self.in_saved_state = None;
                Err(e)
            }
        }
    }
}

/// Where one component's columns of ∂Y/∂U come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Columns {
    /// It has none: no connected inputs, or no connected outputs.
    None,
    /// `fmi2GetDirectionalDerivative` after the step.
    Directional,
    /// Finite differences (rollback and a perturbed step per input).
    Differenced,
    /// Auto: directional derivatives, to be checked against finite
    /// differences at the first Jacobian.
    Unchecked,
}

/// The last few residual norms of a step's Newton base points, oldest
/// first (at most [`NONMONOTONE_MEMORY`]; a new one pushes the oldest
/// out), kept in place of a vector so that nothing is allocated or moved
/// through the heap.
#[derive(Clone, Copy, Debug, Default)]
struct RecentNorms {
    norms: [f64; NONMONOTONE_MEMORY],
    len: usize,
}

impl RecentNorms {
    fn clear(&mut self) {
        self.len = 0;
    }

    fn push(&mut self, norm: f64) {
        if self.len == NONMONOTONE_MEMORY {
            self.norms.copy_within(1.., 0);
            self.len -= 1;
        }
        self.norms[self.len] = norm;
        self.len += 1;
    }

    /// The largest, 0 if there are none (NaNs are passed over, as
    /// `f64::max` does), taken oldest first.
    fn max(&self) -> f64 {
        self.norms[..self.len].iter().copied().fold(0.0, f64::max)
    }
}

pub struct StrongCoupling {
    pub update: Update,
    pub jacobian: JacobianSource,
    pub rtol: f64,
    pub atol: f64,
    pub max_iterations: usize,
    /// How many times a macro step may be halved when Newton fails.
    pub max_splits: usize,
    /// Ramp the inputs over the step from their values at `t` to `U`
    /// where the receiving FMU can interpolate inputs (second order in h,
    /// like the trapezoidal rule) instead of holding `U` (first order,
    /// like implicit Euler).
    pub interpolate: bool,
    /// Start each step's Newton iteration with the Jacobian of the last
    /// step of the same size instead of a new one (a simplified Newton
    /// method, as stiff integrators reuse theirs): a new Jacobian is taken
    /// as soon as a step made with the old one does not converge, at the
    /// point it reached, or back at the start when it made the residual
    /// worse. The converged interface values meet the same tolerance; a
    /// Jacobian costs every component a directional derivative (for a
    /// plant like the two-mass drive of the tests, two more integrations
    /// of its step) or a rolled-back step per input. Off by default: on a
    /// law with many branches (the random bristles of Appels and Herder,
    /// reconnecting when released) the other path of the iteration can
    /// end on another branch within the tolerance (a relaxation of
    /// 1.04e-8 m where the new-Jacobian run gives 1.10e-8 m and the paper's
    /// mean 1.12e-8 m); `fricsim diagnose` turns it on for the
    /// co-simulations of its output-error fits of LuGre.
    pub reuse_jacobian: bool,
    /// The step size the Jacobian in `jac` was taken at, when it may be
    /// reused.
    jacobian_step: Option<f64>,
    /// Whether every FMU accepts varying step sizes (else no halving).
    variable_steps: bool,
    /// U at the start of the step being solved (restored on a split).
    accepted: Vec<f64>,
    /// Adaptive macro steps inside each communication interval, if set.
    pub step_control: Option<StepControl>,
    /// The step the controller proposes next.
    h_next: Option<f64>,
    /// Largest |U_k| so far, per connection (scale of the error control).
    range: Vec<f64>,
    report: ConvergenceReport,
    ports: Vec<Ports>,
    nominal: Vec<f64>,
    /// The interface values U; between steps, the last accepted ones.
    u: Vec<f64>,
    started: bool,
    y: Vec<f64>,
    column: Vec<f64>,
    // Work space of a step, kept so that a step allocates nothing:
    /// J = ∂Y/∂U, n × n. Only the blocks of the components' own inputs
    /// and outputs are ever written: every entry outside them is zero.
    jac: DMatrix<f64>,
    /// I − J, factorised in place.
    newton_matrix: DMatrix<f64>,
    /// One component's directional derivatives.
    derivative: Vec<f64>,
    /// U perturbed for a finite difference.
    perturbed: Vec<f64>,
    /// The line search's base point, the Newton direction, and the last
    /// NONMONOTONE_MEMORY base residual norms.
    base: Vec<f64>,
    direction: Vec<f64>,
    history: RecentNorms,
}

impl StrongCoupling {
    pub fn new(update: Update, jacobian: JacobianSource) -> Self {
        StrongCoupling {
            update,
            jacobian,
            rtol: 1e-8,
            atol: 1e-10,
            max_iterations: 50,
            max_splits: 10,
            interpolate: false,
            reuse_jacobian: false,
            jacobian_step: None,
            variable_steps: false,
            accepted: Vec::new(),
            step_control: None,
            h_next: None,
            range: Vec::new(),
            report: ConvergenceReport {
                smallest_step: f64::INFINITY,
                ..Default::default()
            },
            ports: Vec::new(),
            nominal: Vec::new(),
            u: Vec::new(),
            started: false,
            y: Vec::new(),
            column: Vec::new(),
            jac: DMatrix::zeros(0, 0),
            newton_matrix: DMatrix::zeros(0, 0),
            derivative: Vec::new(),
            perturbed: Vec::new(),
            base: Vec::new(),
            direction: Vec::new(),
            history: RecentNorms::default(),
        }
    }

    pub fn convergence(&self) -> &ConvergenceReport {
        &self.report
    }

    /// What every component must offer, checked at the first step before
    /// anything is stepped: the error names the instance and the capability.
    fn check_capabilities(&self, system: &System) -> Result<(), FmuError> {
        let refuse = |c: usize, capability, reason| {
            Err(FmuError::MissingCapability {
                master: self.name(),
                instance: system.component_name(c).to_string(),
                model: system.model_name(c).to_string(),
                capability,
                reason,
            })
        };
        let connections = system.connections();
        if connections.is_empty() {
            return Ok(()); // nothing to iterate: every step is taken once
        }
        for c in 0..system.component_count() {
            let cs = system.co_simulation(c);
            if !cs.can_get_and_set_fmu_state {
                return refuse(
                    c,
                    "canGetAndSetFMUstate=\"true\"",
                    "every macro step is iterated from the state at its start (fmi2GetFMUstate / fmi2SetFMUstate); jacobi or gauss-seidel need no rollback",
                );
            }
            if self.step_control.is_some() && !cs.can_handle_variable_communication_step_size {
                return refuse(
                    c,
                    "canHandleVariableCommunicationStepSize=\"true\"",
                    "adaptive macro steps change the step size; newton keeps it fixed",
                );
            }
            let has_loop_inputs = connections.iter().any(|k| k.to.0 == c)
                && connections.iter().any(|k| k.from.0 == c);
            if self.update == Update::Newton
                && self.jacobian == JacobianSource::Directional
                && has_loop_inputs
                && !cs.provides_directional_derivative
            {
                return refuse(
                    c,
                    "providesDirectionalDerivative=\"true\"",
                    "its Jacobian was asked for from fmi2GetDirectionalDerivative; the automatic choice differences it instead",
                );
            }
        }
        Ok(())
    }

    fn prepare(&mut self, system: &System) -> Result<(), FmuError> {
        self.check_capabilities(system)?;
        let connections = system.connections();
        let n = connections.len();
        self.ports = (0..system.component_count())
            .map(|c| {
                let cs = system.co_simulation(c);
                let outputs: Vec<usize> = (0..n).filter(|&k| connections[k].from.0 == c).collect();
                let inputs: Vec<usize> = (0..n).filter(|&k| connections[k].to.0 == c).collect();
                let ramped = self.interpolate && cs.can_interpolate_inputs;
                let (columns, differenced) = match self.jacobian {
                    _ if inputs.is_empty() || outputs.is_empty() => (Columns::None, ""),
                    _ if ramped => (
                        Columns::Differenced,
                        "finite differences (rollback): its inputs ramp over the step, and fmi2GetDirectionalDerivative gives the sensitivity to held inputs",
                    ),
                    JacobianSource::Directional => (Columns::Directional, ""),
                    JacobianSource::FiniteDifference => {
                        (Columns::Differenced, "finite differences (rollback)")
                    }
                    JacobianSource::Auto if cs.provides_directional_derivative => {
                        (Columns::Unchecked, "")
                    }
                    JacobianSource::Auto => (
                        Columns::Differenced,
                        "finite differences (rollback): the FMU does not provide directional derivatives (providesDirectionalDerivative=\"false\")",
                    ),
                };
                Ports {
                    input_vrs: inputs.iter().map(|&k| connections[k].to.1).collect(),
                    inputs,
                    output_vrs: outputs.iter().map(|&k| connections[k].from.1).collect(),
                    output_values: vec![0.0; outputs.len()],
                    consecutive_outputs: outputs
                        .first()
                        .copied()
                        .filter(|_| outputs.windows(2).all(|k| k[1] == k[0] + 1)),
                    outputs,
                    columns,
                    differenced,
                    reported: false,
                    ramped,
                    state: None,
                    in_saved_state: None,
                    holds_u: None,
                }
            })
            .collect();
        self.nominal = connections
            .iter()
            .map(|k| {
                system
                    .input_nominal(k.to.0, k.to.1)
                    .filter(|x| x.is_finite() && *x > 0.0)
                    .unwrap_or(1.0)
            })
            .collect();
        self.variable_steps = (0..system.component_count()).all(|c| {
            system
                .co_simulation(c)
                .can_handle_variable_communication_step_size
        });
        let most_outputs = self.ports.iter().map(|p| p.outputs.len()).max();
        self.derivative = vec![0.0; most_outputs.unwrap_or(0)];
        self.jac = DMatrix::zeros(n, n);
        self.newton_matrix = DMatrix::zeros(n, n);
        self.u = vec![0.0; n];
        self.accepted = vec![0.0; n];
        self.base = vec![0.0; n];
        self.direction = vec![0.0; n];
        self.range = vec![0.0; n];
        self.started = false;
        self.y = vec![0.0; n];
        self.report.jacobian_of = (0..system.component_count())
            .map(|c| (system.component_name(c).to_string(), "not needed"))
            .collect();
        Ok(())
    }

    /// Save every component's state at the start of the step
    /// ([`Ports::save_state`]).
    fn save_states(&mut self, system: &mut System) -> Result<(), FmuError> {
        for (c, ports) in self.ports.iter_mut().enumerate() {
            ports.save_state(system, c)?;
        }
        Ok(())
    }

    /// Roll every component back to its saved state ([`Ports::restore`]).
    fn restore_all(&mut self, system: &mut System) -> Result<(), FmuError> {
        for (c, ports) in self.ports.iter_mut().enumerate() {
            ports.restore(system, c)?;
        }
        Ok(())
    }

    /// The Newton direction at U, every component just stepped on it:
    /// `(I − J)·ΔU = Y − U` solved into `direction`, or where I − J is
    /// singular the fixed-point direction `Y − U`.
    /// The Newton direction at the current U (every component just
    /// stepped on it), with a new Jacobian or, `reuse`, the one in `jac`.
    fn newton_direction(
        &mut self,
        system: &mut System,
        t: f64,
        h: f64,
        reuse: bool,
    ) -> Result<(), FmuError> {
        if reuse {
            self.report.jacobians_reused += 1;
        } else {
            self.jacobian(system, t, h)?;
            self.jacobian_step = Some(h);
        }
        // (I − J)·ΔU = Y − U (over the slices: the matrix iterators cost
        // more than the few entries)
        let n = self.u.len();
        let a = self.newton_matrix.as_mut_slice();
        // the diagonal: every (n + 1)-th entry of the column-major slice
        let mut diagonal = 0;
        for (i, (a, j)) in a.iter_mut().zip(self.jac.as_slice()).enumerate() {
            *a = -j;
            if i == diagonal {
                *a += 1.0;
                diagonal += n + 1;
            }
        }
        for ((d, y), u) in self.direction.iter_mut().zip(&self.y).zip(&self.u) {
            *d = y - u;
        }
        if !solve_in_place(&mut self.newton_matrix, &mut self.direction) {
            // I − J singular: the fixed-point direction.
            for ((d, y), u) in self.direction.iter_mut().zip(&self.y).zip(&self.u) {
                *d = y - u;
            }
        }
        Ok(())
    }

    /// Columns of ∂Y/∂U for the inputs of component `c` into `self.jac`, by
    /// rolling back and stepping with one input perturbed by
    /// δ = √ε·max(|U_j|, nominal_j).
    fn difference_columns(
        &mut self,
        system: &mut System,
        c: usize,
        t: f64,
        h: f64,
    ) -> Result<(), FmuError> {
        for i in 0..self.ports[c].inputs.len() {
            let j = self.ports[c].inputs[i];
            let delta = f64::EPSILON.sqrt() * self.u[j].abs().max(self.nominal[j]);
            self.ports[c].restore(system, c)?;
            self.perturbed.clone_from(&self.u);
            self.perturbed[j] += delta;
            self.ports[c].set_inputs(system, c, &self.perturbed, &self.accepted, h)?;
            system.do_step(c, t, h, Rollback::Possible)?;
            self.report.difference_steps += 1;
            self.column.clone_from(&self.y);
            self.ports[c].read_outputs(system, c, &mut self.column)?;
            for &k in &self.ports[c].outputs {
                self.jac[(k, j)] = (self.column[k] - self.y[k]) / delta;
            }
        }
        Ok(())
    }

    /// Columns of ∂Y/∂U for the inputs of component `c` into `self.jac`, from
    /// `fmi2GetDirectionalDerivative`, called right after the step.
    #[inline(always)] // hot: at every Jacobian
    fn directional_columns(&mut self, system: &mut System, c: usize) -> Result<(), FmuError> {
        let ports = &self.ports[c];
        let rows = self.jac.nrows();
        for (&j, &known) in ports.inputs.iter().zip(&ports.input_vrs) {
            if let Some(first) = ports.consecutive_outputs {
                // straight into place: rows first.. of column j
                let start = first + j * rows;
                let column = &mut self.jac.as_mut_slice()[start..start + ports.outputs.len()];
                system.get_directional_derivative(
                    c,
                    &ports.output_vrs,
                    &[known],
                    &[1.0],
                    column,
                )?;
                continue;
            }
            // (sized for the component with the most outputs in `prepare`)
            let out = &mut self.derivative[..ports.outputs.len()];
            system.get_directional_derivative(c, &ports.output_vrs, &[known], &[1.0], out)?;
            for (&k, d) in ports.outputs.iter().zip(out.iter()) {
                self.jac[(k, j)] = *d;
            }
        }
        Ok(())
    }

    /// ∂Y/∂U into `self.jac`, with every component stepped on `self.u`
    /// just before. Leaves components that were differenced in a perturbed
    /// state (the next iteration restores them).
    fn jacobian(&mut self, system: &mut System, t: f64, h: f64) -> Result<(), FmuError> {
        self.report.jacobians += 1;
        // Directional derivatives first: they need the step just taken.
        for c in 0..system.component_count() {
            match self.ports[c].columns {
                Columns::Directional => self.directional_columns(system, c)?,
                Columns::Unchecked => {
                    // Auto: an FMU whose call fails is differenced instead.
                    if self.directional_columns(system, c).is_err() {
                        self.ports[c].columns = Columns::Differenced;
                        let how = "finite differences (fmi2GetDirectionalDerivative failed)";
                        self.describe(c, how);
                    }
                }
                Columns::None | Columns::Differenced => {}
            }
        }
        for c in 0..system.component_count() {
            match self.ports[c].columns {
                Columns::None => {}
                Columns::Directional => {
                    if !self.ports[c].reported {
                        self.describe(c, "directional derivatives");
                    }
                }
                Columns::Differenced => {
                    self.difference_columns(system, c, t, h)?;
                    if !self.ports[c].reported {
                        self.describe(c, self.ports[c].differenced);
                    }
                }
                Columns::Unchecked => {
                    // Auto: compare with finite differences once.
                    let directional = self.jac.clone();
                    self.difference_columns(system, c, t, h)?;
                    let mut agree = true;
                    for &j in &self.ports[c].inputs {
                        for &k in &self.ports[c].outputs {
                            let (a, b) = (directional[(k, j)], self.jac[(k, j)]);
                            let scale = a.abs().max(b.abs()).max(1e-300);
                            if (a - b).abs() > 1e-3 * scale + 1e-12 {
                                agree = false;
                            }
                        }
                    }
                    if agree {
                        self.ports[c].columns = Columns::Directional;
                        self.describe(
                            c,
                            "directional derivatives (checked against finite differences)",
                        );
                        self.jac = directional;
                    } else {
                        self.ports[c].columns = Columns::Differenced;
                        self.describe(c, "finite differences (directional derivatives disagreed)");
                    }
                }
            }
        }
        Ok(())
    }

    /// Say in the convergence report how component `c`'s Jacobian columns
    /// are obtained (its entry is "not needed" until then).
    fn describe(&mut self, c: usize, how: &'static str) {
        self.report.jacobian_of[c].1 = how;
        self.ports[c].reported = true;
    }
}

impl MasterAlgorithm for StrongCoupling {
    fn name(&self) -> &'static str {
        match (self.update, self.interpolate) {
            (Update::Newton, false) => "strong coupling (Newton)",
            (Update::Newton, true) => "strong coupling (Newton, interpolated inputs)",
            (Update::FixedPoint, false) => "strong coupling (fixed point)",
            (Update::FixedPoint, true) => "strong coupling (fixed point, interpolated inputs)",
        }
    }

    fn step(&mut self, system: &mut System, t: f64, h: f64) -> Result<(), FmuError> {
        if self.ports.len() != system.component_count() {
            self.prepare(system)?;
        }
        match self.step_control {
            Some(control) if !system.connections().is_empty() => {
                self.adaptive_step(system, t, h, control)
            }
            _ => self.step_or_split(system, t, h, 0),
        }
    }

    fn report(&self) -> Option<String> {
        Some(self.report.to_string())
    }
}

impl StrongCoupling {
    /// Cover the communication interval `[t, t + big_h]` with macro steps
    /// chosen by the error estimate of [`StepControl`]; the last one ends
    /// exactly at `t + big_h`.
    fn adaptive_step(
        &mut self,
        system: &mut System,
        t: f64,
        big_h: f64,
        control: StepControl,
    ) -> Result<(), FmuError> {
        if !control.h_min.is_finite() || control.h_min <= 0.0 {
            return Err(FmuError::NotConverged {
                time: t,
                step: control.h_min,
                iterations: 0,
                connection: "(step control: h_min must be > 0)".into(),
                mismatch: f64::NAN,
                input: f64::NAN,
                output: f64::NAN,
                tolerance: f64::NAN,
                residual: f64::NAN,
            });
        }
        let end = t + big_h;
        let mut now = t;
        let mut h = self.h_next.unwrap_or(big_h).min(big_h);
        self.ensure_started(system)?;
        while now < end {
            // Take the rest if it is within reach, never leave a sliver.
            let rest = end - now;
            let last = h >= rest || rest - h < control.h_min;
            let step = if last { rest } else { h };
            let start = self.u.clone();
            let solved = self.solve(system, now, step);
            let estimate = match &solved {
                Ok(()) => Some(self.hold_error(&start, control)),
                Err(FmuError::NotConverged { .. }) => None,
                Err(_) => return solved,
            };
            match estimate {
                Some(error) if error <= 1.0 || step <= control.h_min => {
                    self.report.accepted += 1;
                    self.report.smallest_step = self.report.smallest_step.min(step);
                    self.report.largest_step = self.report.largest_step.max(step);
                    now = if last { end } else { now + step };
                    // first-order estimate: error ∝ h
                    let grow = if error > 0.0 { 0.9 / error } else { 2.0 };
                    if !last || step >= h {
                        h = (step * grow.clamp(0.2, 1.5)).clamp(control.h_min, big_h);
                    }
                }
                _ => {
                    // Rejected (too large an error, or Newton failed): roll
                    // back to `now` and retry with a smaller step.
                    if step <= control.h_min {
                        return solved;
                    }
                    self.report.rejected += 1;
                    self.restore_all(system)?;
                    self.u.copy_from_slice(&start);
                    let shrink = match estimate {
                        Some(error) => (0.9 / error).clamp(0.2, 0.5),
                        None => 0.25,
                    };
                    h = (step * shrink).max(control.h_min);
                }
            }
        }
        self.h_next = Some(h);
        Ok(())
    }

    /// Local error of holding the interface over the step: the held value
    /// U(t + h) differs from the interface's true course, which moves from
    /// U(t) to U(t + h), by half the change on average. Scaled by the
    /// tolerance of [`StepControl`], largest over the connections.
    ///
    /// The relative part is taken of the largest magnitude the connection
    /// has had so far (`range`), not of its current value: a slip velocity
    /// passing through zero at a stick would otherwise ask for steps of
    /// nanoseconds.
    fn hold_error(&mut self, start: &[f64], control: StepControl) -> f64 {
        let mut worst: f64 = 0.0;
        for (k, &u0) in start.iter().enumerate() {
            self.range[k] = self.range[k].max(self.u[k].abs()).max(u0.abs());
            let tolerance = control.atol * self.nominal[k] + control.rtol * self.range[k];
            let error = 0.5 * (self.u[k] - u0).abs() / tolerance;
            if error.is_nan() || error > worst {
                worst = error;
            }
        }
        worst
    }

    #[inline] // at every step, and only the first does anything
    fn ensure_started(&mut self, system: &mut System) -> Result<(), FmuError> {
        if self.started {
            return Ok(());
        }
        self.start(system)
    }

    /// U from the outputs at the start of the run.
    #[cold]
    #[inline(never)]
    fn start(&mut self, system: &mut System) -> Result<(), FmuError> {
        for (c, ports) in self.ports.iter_mut().enumerate() {
            ports.read_outputs(system, c, &mut self.u)?;
        }
        self.started = true;
        Ok(())
    }

    /// Solve the step; if Newton fails, roll back and cover `[t, t + h]`
    /// with two half steps (recursively, at most `max_splits` times deep).
    /// The communication grid of the run is unchanged: the halves happen
    /// inside one macro step.
    #[inline] // into every step; the split itself is out of line
    fn step_or_split(
        &mut self,
        system: &mut System,
        t: f64,
        h: f64,
        depth: usize,
    ) -> Result<(), FmuError> {
        match self.solve(system, t, h) {
            Err(e @ FmuError::NotConverged { .. }) => self.split(system, t, h, depth, e),
            other => other,
        }
    }

    /// [`StrongCoupling::step_or_split`] after Newton failed on `[t, t + h]`
    /// with `e`.
    #[cold]
    #[inline(never)]
    fn split(
        &mut self,
        system: &mut System,
        t: f64,
        h: f64,
        depth: usize,
        e: FmuError,
    ) -> Result<(), FmuError> {
        if depth >= self.max_splits || !self.variable_steps {
            return Err(e);
        }
        self.report.rejected += 1;
        self.report.iterations += self.max_iterations;
        self.restore_all(system)?;
        self.u.copy_from_slice(&self.accepted);
        self.step_or_split(system, t, 0.5 * h, depth + 1)?;
        self.step_or_split(system, t + 0.5 * h, 0.5 * h, depth + 1)
    }

    fn solve(&mut self, system: &mut System, t: f64, h: f64) -> Result<(), FmuError> {
        let n = system.connections().len();
        if n == 0 {
            system.do_step_all(t, h, Rollback::Possible)?;
            self.report.steps += 1;
            return Ok(());
        }
        self.save_states(system)?;
        // Predictor: the interface values the FMUs hold now (the last
        // accepted U; at the first step, the outputs at t). Not the outputs:
        // a hysteretic law reads an input a rounding error below its last
        // one as a reversal.
        self.ensure_started(system)?;
        self.accepted.copy_from_slice(&self.u);
        // Damped Newton: from the base point `base` (where the Jacobian was
        // taken) try U = base + λ·direction, halving λ while the scaled
        // residual norm is not below the largest of the last
        // NONMONOTONE_MEMORY base norms (a non-monotone Armijo test, 1e-4;
        // Grippo, Lampariello & Lucidi 1986). Full steps may raise the
        // residual for a while (break-away on a Stribeck curve needs that),
        // but a cycle — Newton bouncing across the jump a hysteretic law
        // makes at a reversal — is cut by halving.
        let mut has_base = false;
        // whether the base point's direction used the Jacobian of an
        // earlier step, and whether that may still be tried
        let mut base_reused = false;
        let mut may_reuse = self.reuse_jacobian;
        self.history.clear();
        let mut lambda = 1.0;
        let mut last_norm = f64::INFINITY;
        for iteration in 1..=self.max_iterations {
            for (c, ports) in self.ports.iter_mut().enumerate() {
                // (only a converged iteration leaves a mark, for the next step)
                let holds_u = ports.holds_u.take() == Some(system.changes(c));
                if iteration > 1 {
                    ports.restore(system, c)?;
                } else if holds_u {
                    // the first iterate is the last accepted U, still set
                    continue;
                }
                ports.set_inputs(system, c, &self.u, &self.accepted, h)?;
            }
            system.do_step_all(t, h, Rollback::Possible)?;
            for (c, ports) in self.ports.iter_mut().enumerate() {
                ports.read_outputs(system, c, &mut self.y)?;
            }
            // (which connection is the worst is asked only if the step fails)
            let mut worst = 0.0;
            let mut norm = 0.0;
            for ((&nominal, &u), &y) in self.nominal.iter().zip(&self.u).zip(&self.y) {
                let ratio = scaled_mismatch(self.atol, self.rtol, nominal, u, y);
                norm += ratio * ratio;
                // a NaN is the worst, and stays it: nothing compares greater
                if ratio.is_nan() || ratio > worst {
                    worst = ratio;
                }
            }
            let norm = norm.sqrt();
            last_norm = norm;
            if worst <= 1.0 {
                self.report.steps += 1;
                self.report.iterations += iteration;
                self.report.max_iterations = self.report.max_iterations.max(iteration);
                self.report.histogram[(iteration - 1).min(7)] += 1;
                self.report.worst_accepted = self.report.worst_accepted.max(worst);
                // Every component was just stepped on U; a ramped one has
                // moved its inputs along the ramp.
                for (c, ports) in self.ports.iter_mut().enumerate() {
                    ports.holds_u = (!ports.ramped).then(|| system.changes(c));
                }
                return Ok(());
            }
            if iteration == self.max_iterations {
                break;
            }
            match self.update {
                Update::FixedPoint => self.u.copy_from_slice(&self.y),
                Update::Newton => {
                    if has_base && base_reused {
                        if !norm.is_finite() {
                            // the reused Jacobian led where an FMU gives
                            // no number: back to the base point, and a new
                            // Jacobian there at the next iteration
                            self.u.copy_from_slice(&self.base);
                            base_reused = false;
                            may_reuse = false;
                            has_base = false;
                            continue;
                        }
                        may_reuse = false;
                        // not converged: a new base point here, with a
                        // new Jacobian (below); the line search starts
                        // from it
                        has_base = false;
                        self.history.clear();
                    } else if has_base {
                        let reference = self.history.max();
                        let sufficient =
                            norm.is_finite() && norm <= (1.0 - 1e-4 * lambda) * reference;
                        if !sufficient && lambda > 1.0 / 1024.0 {
                            lambda *= 0.5;
                            self.report.backtracks += 1;
                            for ((u, b), d) in
                                self.u.iter_mut().zip(&self.base).zip(&self.direction)
                            {
                                *u = b + lambda * d;
                            }
                            continue;
                        }
                    }
                    // New base point: the components were just stepped on U.
                    // The Jacobian of an earlier step only for the first.
                    // (a step of the time grid, t_k+1 − t_k, may differ
                    // from the last in its last bits)
                    let same_step = self
                        .jacobian_step
                        .is_some_and(|s| (s - h).abs() <= 1e-9 * h.abs());
                    let reuse = may_reuse && !has_base && same_step;
                    self.newton_direction(system, t, h, reuse)?;
                    base_reused = reuse;
                    self.base.copy_from_slice(&self.u);
                    has_base = true;
                    self.history.push(norm);
                    lambda = 1.0;
                    for (u, d) in self.u.iter_mut().zip(&self.direction) {
                        *u += d;
                    }
                }
            }
        }
        // The connection of the worst mismatch of the last iteration (the
        // first of equal ones, the last NaN), on the U and Y it was found
        // on; the first if there was no iteration.
        let mut worst = (0.0, 0);
        if self.max_iterations > 0 {
            let interface = self.nominal.iter().zip(&self.u).zip(&self.y);
            for (k, ((&nominal, &u), &y)) in interface.enumerate() {
                let ratio = scaled_mismatch(self.atol, self.rtol, nominal, u, y);
                if ratio.is_nan() || ratio > worst.0 {
                    worst = (ratio, k);
                }
            }
        }
        let k = worst.1;
        Err(FmuError::NotConverged {
            time: t,
            step: h,
            iterations: self.max_iterations,
            connection: system.connections()[k].label.clone(),
            mismatch: (self.u[k] - self.y[k]).abs(),
            input: self.u[k],
            output: self.y[k],
            tolerance: self.atol * self.nominal[k]
                + self.rtol * self.u[k].abs().max(self.y[k].abs()),
            residual: last_norm,
        })
    }
}

/// `|R_k| = |U_k − Y_k|` over its tolerance `atol·nominal_k +
/// rtol·max(|U_k|, |Y_k|)`: at most 1 where the step has converged.
#[inline(always)]
fn scaled_mismatch(atol: f64, rtol: f64, nominal: f64, u: f64, y: f64) -> f64 {
    let tolerance = atol * nominal + rtol * u.abs().max(y.abs());
    (u - y).abs() / tolerance
}

/// Solve `a·x = b` in place (`b` becomes `x`, `a` is overwritten) by
/// Gaussian elimination with partial pivoting. False when `a` is singular
/// (a zero pivot) or `x` is not finite. For the few interface unknowns of a
/// co-simulation step it needs no work space, where a general LU allocates.
fn solve_in_place(a: &mut DMatrix<f64>, b: &mut [f64]) -> bool {
    let n = b.len();
    if a.shape() != (n, n) {
        return false;
    }
    let m = a.as_mut_slice();
    match (
        <&mut [f64; 4]>::try_from(&mut *m),
        <&mut [f64; 2]>::try_from(&mut *b),
    ) {
        (Ok(m), Ok(b)) => solve_two(m, b),
        _ => eliminate(m, b),
    }
}

/// [`solve_in_place`] of `n` unknowns, `m` the `n × n` matrix column-major
/// ((row, col) at row + col·n).
fn eliminate(m: &mut [f64], b: &mut [f64]) -> bool {
    let n = b.len();
    for col in 0..n {
        // the largest magnitude, the last of equal ones (as max_by)
        let mut pivot = col;
        for row in col + 1..n {
            if m[row + col * n]
                .abs()
                .total_cmp(&m[pivot + col * n].abs())
                .is_ge()
            {
                pivot = row;
            }
        }
        let p = m[pivot + col * n];
        if p == 0.0 || !p.is_finite() {
            return false;
        }
        if pivot != col {
            for k in 0..n {
                m.swap(pivot + k * n, col + k * n);
            }
            b.swap(pivot, col);
        }
        for row in col + 1..n {
            let factor = m[row + col * n] / m[col + col * n];
            for k in col..n {
                m[row + k * n] -= factor * m[col + k * n];
            }
            b[row] -= factor * b[col];
        }
    }
    for row in (0..n).rev() {
        let mut sum = b[row];
        for k in row + 1..n {
            sum -= m[row + k * n] * b[k];
        }
        b[row] = sum / m[row + row * n];
    }
    b.iter().all(|x| x.is_finite())
}

/// [`eliminate`] for two unknowns (one connection each way, the usual
/// loop), written out: the same operations on the same values in the
/// same order, so the same bits, without the loops and index checks.
fn solve_two(m: &mut [f64; 4], b: &mut [f64; 2]) -> bool {
    // column 0: row 1 is the pivot if it is at least as large
    let swap = m[1].abs().total_cmp(&m[0].abs()).is_ge();
    let p = if swap { m[1] } else { m[0] };
    if p == 0.0 || !p.is_finite() {
        return false;
    }
    if swap {
        m.swap(0, 1);
        m.swap(2, 3);
        b.swap(0, 1);
    }
    let factor = m[1] / m[0];
    m[1] -= factor * m[0];
    m[3] -= factor * m[2];
    b[1] -= factor * b[0];
    // column 1
    if m[3] == 0.0 || !m[3].is_finite() {
        return false;
    }
    b[1] /= m[3];
    b[0] = (b[0] - m[2] * b[1]) / m[0];
    b.iter().all(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recent_norms_keep_what_a_vector_of_the_last_few_keeps() {
        // the vector it replaces: remove the oldest when full, then push
        let mut vector: Vec<f64> = Vec::new();
        let mut recent = RecentNorms::default();
        let values = [
            3.0,
            f64::NAN,
            0.5,
            7.0,
            f64::INFINITY,
            2.0,
            0.0,
            f64::NAN,
            1e-300,
            4.0,
            9.0,
            1.0,
            f64::NAN,
            f64::NAN,
            f64::NAN,
            f64::NAN,
            0.25,
        ];
        for (i, &x) in values.iter().enumerate() {
            if i % 7 == 6 {
                vector.clear();
                recent.clear();
            }
            if vector.len() == NONMONOTONE_MEMORY {
                vector.remove(0);
            }
            vector.push(x);
            recent.push(x);
            assert_eq!(recent.len, vector.len());
            for (a, b) in recent.norms[..recent.len].iter().zip(&vector) {
                assert_eq!(a.to_bits(), b.to_bits(), "{vector:?}");
            }
            let max = vector.iter().copied().fold(0.0, f64::max);
            assert_eq!(recent.max().to_bits(), max.to_bits(), "{vector:?}");
        }
        recent.clear();
        assert_eq!(recent.max(), 0.0);
    }

    #[test]
    fn gaussian_elimination_pivots_and_refuses_singular_systems() {
        // a zero in the first pivot position needs a row swap
        let mut a = DMatrix::from_row_slice(3, 3, &[0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 2.0, 0.0, 3.0]);
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|k| a[(i, k)] * x[k]).sum())
            .collect();
        assert!(solve_in_place(&mut a, &mut b));
        for (got, want) in b.iter().zip(x) {
            assert!((got - want).abs() < 1e-14, "{b:?}");
        }
        let mut singular = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
        assert!(!solve_in_place(&mut singular, &mut [1.0, 1.0]));
    }

    #[test]
    fn two_unknowns_give_the_bits_of_the_general_elimination() {
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            3.5e-7,
            -2.25,
            1e300,
            f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NAN,
            0.1,
            -7.0 / 3.0,
        ];
        let mut cases = 0;
        for (i, &a) in values.iter().enumerate() {
            for (j, &b) in values.iter().enumerate() {
                for &c in &values[(i + j) % 4..] {
                    for &d in &values[(i * j) % 5..] {
                        let (m, rhs) = ([a, b, c, d], [c - a, b + d]);
                        let (mut m1, mut b1, mut m2, mut b2) = (m, rhs, m, rhs);
                        let ok = eliminate(&mut m1, &mut b1);
                        assert_eq!(solve_two(&mut m2, &mut b2), ok, "{m:?} {rhs:?}");
                        if ok {
                            assert_eq!(b1.map(f64::to_bits), b2.map(f64::to_bits), "{m:?} {rhs:?}");
                        }
                        cases += 1;
                    }
                }
            }
        }
        assert!(cases > 1000);
    }
}
