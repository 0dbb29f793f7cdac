//! Radau IIA of order 5 (3 stages), adaptive, for stiff ODEs `y' = f(t, y)`.
//!
//! The method and its implementation follow Hairer & Wanner, *Solving
//! Ordinary Differential Equations II* (2nd ed., Springer 1996), §IV.5 and
//! §IV.8, and their code RADAU5:
//!
//! - collocation at `c = ((4 − √6)/10, (4 + √6)/10, 1)` (Table IV.5.6);
//!   stiffly accurate, so `y1 = y0 + Z3`;
//! - the stage increments `Z` solve `Z = h·(A ⊗ I)·F(Z)` by simplified
//!   Newton iterations with the iteration matrix `I − h·(A ⊗ J)`, one LU
//!   factorisation (nalgebra, partial pivoting) per step size and Jacobian.
//!   RADAU5 diagonalises `A⁻¹` to solve one real and one complex `n × n`
//!   system instead; for the few states of a friction rig the `3n × 3n`
//!   system is as cheap and has no transformation to get wrong. The
//!   convergence test is RADAU5's (rate θ, `η·‖ΔZ‖ ≤ κ·tol`, at most 7
//!   iterations, step reduction when convergence is predicted too slow);
//! - the embedded error estimate of eq. (IV.8.19–8.20):
//!   `err = (γ/h·I − J)⁻¹·(f(t0, y0) + (e1·Z1 + e2·Z2 + e3·Z3)/h)`,
//!   `γ = 1/γ0` the real eigenvalue of `A⁻¹`, `e = (−(13 + 7√6), −13 + 7√6, −1)/3`,
//!   with the second, filtered estimate after a rejected or the first step;
//! - step size control `h_new = h·fac·err^(−1/4)` with the safety factor
//!   reduced by the Newton iteration count, and Gustafsson's predictive
//!   controller (eq. IV.8.25);
//! - starting values for Newton from the collocation polynomial of the
//!   previous step (RADAU5's `CONT`).
//!
//! Tolerances: as RADAU5 does, the user's `rtol` (and `atol`) are mapped to
//! `rtol' = 0.1·rtol^(2/3)`, `atol' = atol·rtol'/rtol` before use, because
//! the local error estimate is that of an order-3 embedded formula while
//! the solution is of order 5: with this mapping the *global* error is of
//! the order of the requested `rtol` (checked in the tests on problems with
//! closed-form or published reference solutions).
//!
//! Output: [`solve`] lands a step exactly on every requested output time
//! (no interpolation), so output values have the accuracy of step ends.
//!
//! Non-smooth right-hand sides: the error estimate assumes a smooth `f`
//! over the step. Where `f` has a kink (friction laws: `|v|` and `sgn v` at
//! `v = 0`), the system declares switching functions
//! ([`OdeSystem::switching`]); an accepted step over which one changes sign
//! is redone to end on the sign change, located on the step's collocation
//! polynomial by bisection, with a fresh Jacobian after it (the test
//! `kinks_at_sign_changes_of_a_switching_function`: error 1.6e-10 instead of
//! 3e-7 at rtol 1e-10 on `y1' = |y2|`).

use nalgebra::{DMatrix, DVector};
use std::fmt;

/// A system of ODEs `y' = f(t, y)`.
pub trait OdeSystem {
    /// Number of states.
    fn dim(&self) -> usize;
    /// `dydt = f(t, y)`.
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]);
    /// Writes `∂f/∂y` into `jac` (`dim × dim`) and returns `true`, or
    /// returns `false` (the default) to have it computed by forward
    /// differences.
    fn jacobian(&self, t: f64, y: &[f64], jac: &mut DMatrix<f64>) -> bool {
        let _ = (t, y, jac);
        false
    }
    /// Number of switching functions (default 0).
    fn switching_count(&self) -> usize {
        0
    }
    /// Switching functions `g(t, y)`: where one changes sign the
    /// right-hand side has a kink or a jump (e.g. `|v|` at `v = 0`). A step
    /// never straddles a sign change: it is shortened to end on it.
    fn switching(&self, t: f64, y: &[f64], g: &mut [f64]) {
        let _ = (t, y, g);
    }
}

/// Tolerances and limits of [`solve`].
#[derive(Clone, Debug, PartialEq)]
pub struct RadauOptions {
    /// Relative tolerance (> 0).
    pub rtol: f64,
    /// Absolute tolerance: one value for every component, or one per
    /// component (each > 0).
    pub atol: Vec<f64>,
    /// Initial step size; default `1e-6·(t_end − t0)`.
    pub h0: Option<f64>,
    /// Largest step size; default `t_end − t0`.
    pub h_max: Option<f64>,
    /// Most step attempts (accepted + rejected).
    pub max_steps: usize,
}

impl RadauOptions {
    /// `rtol`, one `atol` for all components, 10⁷ steps at most.
    pub fn new(rtol: f64, atol: f64) -> Self {
        RadauOptions {
            rtol,
            atol: vec![atol],
            h0: None,
            h_max: None,
            max_steps: 10_000_000,
        }
    }

    /// With one absolute tolerance per component.
    pub fn with_atol(mut self, atol: Vec<f64>) -> Self {
        self.atol = atol;
        self
    }

    pub fn with_h_max(mut self, h_max: f64) -> Self {
        self.h_max = Some(h_max);
        self
    }

    pub fn with_h0(mut self, h0: f64) -> Self {
        self.h0 = Some(h0);
        self
    }
}

/// Work counters of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RadauStats {
    pub accepted: usize,
    pub rejected: usize,
    pub rhs_evaluations: usize,
    pub jacobians: usize,
    pub factorisations: usize,
    pub newton_iterations: usize,
    /// Steps shortened to end on a sign change of a switching function.
    pub switches: usize,
}

impl RadauStats {
    /// Adds the counts of another run (the segments of one solution).
    pub fn add(&mut self, other: &RadauStats) {
        self.accepted += other.accepted;
        self.rejected += other.rejected;
        self.rhs_evaluations += other.rhs_evaluations;
        self.jacobians += other.jacobians;
        self.factorisations += other.factorisations;
        self.newton_iterations += other.newton_iterations;
        self.switches += other.switches;
    }
}

/// Why [`solve`] stopped.
#[derive(Clone, Debug, PartialEq)]
pub enum RadauError {
    /// Bad tolerances, output times or initial state.
    InvalidInput(String),
    /// The step size fell below the resolution of `t`.
    StepSizeTooSmall {
        t: f64,
        h: f64,
    },
    TooManySteps {
        t: f64,
        max_steps: usize,
    },
    /// The right-hand side kept returning NaN or ±∞.
    NotFinite {
        t: f64,
    },
    /// The iteration matrix stayed singular.
    Singular {
        t: f64,
    },
}

impl fmt::Display for RadauError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RadauError::InvalidInput(m) => write!(f, "invalid input: {m}"),
            RadauError::StepSizeTooSmall { t, h } => {
                write!(f, "step size {h:e} too small at t = {t}")
            }
            RadauError::TooManySteps { t, max_steps } => {
                write!(f, "more than {max_steps} steps before t = {t}")
            }
            RadauError::NotFinite { t } => {
                write!(f, "the right-hand side is not finite near t = {t}")
            }
            RadauError::Singular { t } => write!(f, "singular iteration matrix at t = {t}"),
        }
    }
}

impl std::error::Error for RadauError {}

/// States at the requested output times.
#[derive(Clone, Debug)]
pub struct Solution {
    pub t: Vec<f64>,
    pub y: Vec<Vec<f64>>,
    pub stats: RadauStats,
}

/// Unit round-off as RADAU5 uses it.
const UROUND: f64 = 1e-16;
/// Most Newton iterations per step.
const NIT: usize = 7;
/// Safety factor of the step size control.
const SAFE: f64 = 0.9;
/// Step size ratio bounds: `h_new/h ∈ [1/FACL, 1/FACR]`.
const FACL: f64 = 5.0;
const FACR: f64 = 1.0 / 8.0;
/// Recompute the Jacobian after an accepted step when θ exceeded this.
const THET: f64 = 0.001;
/// Keep the step size (and the factorisation) when `h_new/h ∈ [QUOT1, QUOT2]`.
const QUOT1: f64 = 1.0;
const QUOT2: f64 = 1.2;

/// The Radau IIA (order 5) coefficients.
struct Tableau {
    c: [f64; 3],
    a: [[f64; 3]; 3],
    /// `e/3` of the error estimate: `dd = (−(13 + 7√6), −13 + 7√6, −1)/3`.
    dd: [f64; 3],
    /// `γ = 1/γ0`, the real eigenvalue of `A⁻¹`;
    /// `γ0 = (6 + 81^(1/3) − 9^(1/3))/30`.
    gamma: f64,
}

impl Tableau {
    fn new() -> Self {
        let s6 = 6f64.sqrt();
        Tableau {
            c: [(4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0],
            a: [
                [
                    (88.0 - 7.0 * s6) / 360.0,
                    (296.0 - 169.0 * s6) / 1800.0,
                    (-2.0 + 3.0 * s6) / 225.0,
                ],
                [
                    (296.0 + 169.0 * s6) / 1800.0,
                    (88.0 + 7.0 * s6) / 360.0,
                    (-2.0 - 3.0 * s6) / 225.0,
                ],
                [(16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0],
            ],
            dd: [
                -(13.0 + 7.0 * s6) / 3.0,
                (-13.0 + 7.0 * s6) / 3.0,
                -1.0 / 3.0,
            ],
            gamma: 30.0 / (6.0 + 81f64.cbrt() - 9f64.cbrt()),
        }
    }
}

/// Integrates from `(t0, y0)` and returns the state at each time of
/// `t_out` (strictly increasing, `t_out[0] ≥ t0`; a first time equal to
/// `t0` returns `y0`).
pub fn solve<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    opts: &RadauOptions,
) -> Result<Solution, RadauError> {
    let mut t = Vec::with_capacity(t_out.len());
    let mut y = Vec::with_capacity(t_out.len());
    let stats = solve_with(sys, t0, y0, t_out, opts, |ti, yi| {
        t.push(ti);
        y.push(yi.to_vec());
    })?;
    Ok(Solution { t, y, stats })
}

/// As [`solve`], handing each output `(t, y)` to `out` as it is reached
/// instead of storing it.
pub fn solve_with<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    opts: &RadauOptions,
    out: impl FnMut(f64, &[f64]),
) -> Result<RadauStats, RadauError> {
    Ok(drive(sys, t0, y0, t_out, opts, out, false)?.stats)
}

/// Where [`solve_until_switch`] stopped.
#[derive(Clone, Debug)]
pub struct SegmentEnd {
    pub t: f64,
    pub y: Vec<f64>,
    /// Stopped on a sign change of a switching function (else at the last
    /// output time).
    pub switched: bool,
    pub stats: RadauStats,
}

/// As [`solve_with`], but returns after the first step that ends on a sign
/// change of a switching function (the outputs up to it handed to `out`),
/// so that the caller can change the equations there (a hybrid system's
/// mode) and continue with the remaining output times.
pub fn solve_until_switch<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    opts: &RadauOptions,
    out: impl FnMut(f64, &[f64]),
) -> Result<SegmentEnd, RadauError> {
    drive(sys, t0, y0, t_out, opts, out, true)
}

/// Integrates through the output times, optionally stopping at the first
/// step that ends on a switch.
fn drive<S: OdeSystem + ?Sized>(
    sys: &S,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    opts: &RadauOptions,
    mut out: impl FnMut(f64, &[f64]),
    stop_on_switch: bool,
) -> Result<SegmentEnd, RadauError> {
    check_inputs(sys.dim(), t0, y0, t_out, opts)?;
    let t_end = *t_out.last().expect("checked non-empty");
    let mut run = Run::new(sys, opts, t0, y0, t_end);
    for &target in t_out {
        if target == t0 {
            out(t0, y0);
            continue;
        }
        if run.advance_to(target, stop_on_switch)? {
            out(run.t, run.y.as_slice());
        }
        if stop_on_switch && run.switched {
            break;
        }
    }
    Ok(SegmentEnd {
        t: run.t,
        y: run.y.as_slice().to_vec(),
        switched: stop_on_switch && run.switched,
        stats: run.stats,
    })
}

fn check_inputs(
    n: usize,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    opts: &RadauOptions,
) -> Result<(), RadauError> {
    let bad = |m: String| Err(RadauError::InvalidInput(m));
    if n == 0 || y0.len() != n {
        return bad(format!(
            "the system has {n} states but the initial state has {}",
            y0.len()
        ));
    }
    if let Some(i) = y0.iter().position(|v| !v.is_finite()) {
        return bad(format!("initial state y0[{i}] = {} is not finite", y0[i]));
    }
    if !t0.is_finite() {
        return bad(format!("t0 = {t0} is not finite"));
    }
    if t_out.is_empty() {
        return bad("no output times".into());
    }
    let mut prev = t0;
    for (i, &ti) in t_out.iter().enumerate() {
        let ok = ti.is_finite() && (ti > prev || (i == 0 && ti == t0));
        if !ok {
            return bad(format!(
                "output time t_out[{i}] = {ti} is not finite or not after {prev}"
            ));
        }
        prev = ti;
    }
    if !(opts.rtol.is_finite() && opts.rtol > 0.0 && opts.rtol < 1.0) {
        return bad(format!("rtol = {} must be in (0, 1)", opts.rtol));
    }
    if !(opts.atol.len() == 1 || opts.atol.len() == n) {
        return bad(format!(
            "atol has {} values; give 1 or {n}",
            opts.atol.len()
        ));
    }
    if let Some(a) = opts.atol.iter().find(|a| !(a.is_finite() && **a > 0.0)) {
        return bad(format!("atol = {a} must be finite and > 0"));
    }
    for (name, v) in [("h0", opts.h0), ("h_max", opts.h_max)] {
        if let Some(v) = v {
            if !(v.is_finite() && v > 0.0) {
                return bad(format!("{name} = {v} must be finite and > 0"));
            }
        }
    }
    Ok(())
}

/// The integrator's state between output times.
struct Run<'a, S: OdeSystem + ?Sized> {
    sys: &'a S,
    tab: Tableau,
    n: usize,
    /// Internal tolerances (RADAU5's mapping of the user's).
    rtol: f64,
    atol: Vec<f64>,
    fnewt: f64,
    h_max: f64,
    max_steps: usize,
    stats: RadauStats,
    t: f64,
    y: DVector<f64>,
    /// f(t, y).
    f0: DVector<f64>,
    /// Proposed next step size.
    h: f64,
    jac: DMatrix<f64>,
    /// The Jacobian was evaluated at the current (t, y).
    jac_current: bool,
    /// LU of `I − h·(A ⊗ J)` for `lu_h`, and of `γ/h·I − J`.
    lu: Option<(f64, nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>)>,
    lu_err: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    /// Collocation polynomial of the last accepted step (RADAU5 `CONT`):
    /// divided differences `cont[0..3]` and its step size.
    cont: [DVector<f64>; 3],
    h_old: f64,
    first: bool,
    reject: bool,
    theta: f64,
    faccon: f64,
    /// Gustafsson controller memory.
    h_acc: f64,
    err_acc: f64,
    /// Switching functions at (t, y).
    g: Vec<f64>,
    /// The last accepted step ended on or past a sign change of one.
    switched: bool,
}

impl<'a, S: OdeSystem + ?Sized> Run<'a, S> {
    fn new(sys: &'a S, opts: &RadauOptions, t0: f64, y0: &[f64], t_end: f64) -> Self {
        let n = y0.len();
        // RADAU5: rtol' = 0.1·rtol^(2/3), atol' = atol·rtol'/rtol.
        let rtol = 0.1 * opts.rtol.powf(2.0 / 3.0);
        let quot = rtol / opts.rtol;
        let atol = (0..n)
            .map(|i| opts.atol[if opts.atol.len() == 1 { 0 } else { i }] * quot)
            .collect();
        let fnewt = (10.0 * UROUND / rtol).max(0.03f64.min(rtol.sqrt()));
        let span = t_end - t0;
        let h_max = opts.h_max.unwrap_or(span).min(span);
        let h = opts.h0.unwrap_or(1e-6 * span).min(h_max);
        let y = DVector::from_column_slice(y0);
        let mut run = Run {
            sys,
            tab: Tableau::new(),
            n,
            rtol,
            atol,
            fnewt,
            h_max,
            max_steps: opts.max_steps,
            stats: RadauStats::default(),
            t: t0,
            y,
            f0: DVector::zeros(n),
            h,
            jac: DMatrix::zeros(n, n),
            jac_current: false,
            lu: None,
            lu_err: None,
            cont: [DVector::zeros(n), DVector::zeros(n), DVector::zeros(n)],
            h_old: h,
            first: true,
            reject: false,
            theta: THET,
            faccon: 1.0,
            h_acc: h,
            err_acc: 1e-2,
            g: vec![0.0; sys.switching_count()],
            switched: false,
        };
        run.f0 = run.eval(t0, &run.y.clone());
        if !run.g.is_empty() {
            let mut g = std::mem::take(&mut run.g);
            sys.switching(t0, y0, &mut g);
            run.g = g;
        }
        run
    }

    fn eval(&mut self, t: f64, y: &DVector<f64>) -> DVector<f64> {
        let mut d = DVector::zeros(self.n);
        self.sys.rhs(t, y.as_slice(), d.as_mut_slice());
        self.stats.rhs_evaluations += 1;
        d
    }

    /// `atol_i + rtol·|y_i|`.
    /// `atol_i + rtol·|y_i|`.
    fn scale(&self) -> DVector<f64> {
        DVector::from_iterator(
            self.n,
            (0..self.n).map(|i| self.atol[i] + self.rtol * self.y[i].abs()),
        )
    }

    fn update_jacobian(&mut self) {
        let n = self.n;
        let mut jac = DMatrix::zeros(n, n);
        if !self.sys.jacobian(self.t, self.y.as_slice(), &mut jac) {
            // Forward differences, RADAU5's increment √(u·max(1e-5, |y_k|)).
            let mut yp = self.y.clone();
            for k in 0..n {
                let ysafe = yp[k];
                let delta = (UROUND * ysafe.abs().max(1e-5)).sqrt();
                yp[k] = ysafe + delta;
                let fk = self.eval(self.t, &yp);
                for i in 0..n {
                    jac[(i, k)] = (fk[i] - self.f0[i]) / delta;
                }
                yp[k] = ysafe;
            }
        }
        self.jac = jac;
        self.jac_current = true;
        self.stats.jacobians += 1;
        self.lu = None;
        self.lu_err = None;
    }

    /// Factorises `I − h·(A ⊗ J)` and `γ/h·I − J` for step `h`.
    fn factorise(&mut self, h: f64) -> Result<(), RadauError> {
        let n = self.n;
        let mut m = DMatrix::zeros(3 * n, 3 * n);
        for bi in 0..3 {
            for bj in 0..3 {
                let a = self.tab.a[bi][bj];
                for i in 0..n {
                    for j in 0..n {
                        let delta = if bi == bj && i == j { 1.0 } else { 0.0 };
                        m[(bi * n + i, bj * n + j)] = delta - h * a * self.jac[(i, j)];
                    }
                }
            }
        }
        let lu = m.lu();
        let mut e = -self.jac.clone();
        for i in 0..n {
            e[(i, i)] += self.tab.gamma / h;
        }
        let lu_err = e.lu();
        self.stats.factorisations += 1;
        if !lu.is_invertible() || !lu_err.is_invertible() {
            return Err(RadauError::Singular { t: self.t });
        }
        self.lu = Some((h, lu));
        self.lu_err = Some(lu_err);
        Ok(())
    }

    /// Advances until `t == target` exactly.
    /// With `stop_on_switch`, returns `false` after a step that ends on
    /// (or just past) a sign change of a switching function before the
    /// target, else `true` on reaching it.
    fn advance_to(&mut self, target: f64, stop_on_switch: bool) -> Result<bool, RadauError> {
        while self.t < target {
            // Stretch by 0.01 % to land on the target rather than leave a
            // sliver (RADAU5 does the same at the end of the interval).
            let unclipped = self.h.min(self.h_max);
            let (h, clipped) = if self.t + 1.0001 * unclipped >= target {
                (target - self.t, true)
            } else {
                (unclipped, false)
            };
            let (h_used, h_next) = self.step(h)?;
            if clipped && h_used == h {
                self.t = target;
                // A step shortened to hit the target does not shrink the
                // next one below what the controller proposed before it.
                self.h = h_next.max(unclipped);
            } else {
                self.h = h_next;
            }
            if stop_on_switch && self.switched && self.t < target {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// One accepted step of size at most `h` (reduced after rejections);
    /// returns the step size taken and the proposed next one.
    fn step(&mut self, mut h: f64) -> Result<(f64, f64), RadauError> {
        let n = self.n;
        // The step has been shortened to end on a sign change of a
        // switching function (and not shortened further since).
        let mut to_switch = false;
        let tab_c = self.tab.c;
        let tab_a = self.tab.a;
        loop {
            if self.stats.accepted + self.stats.rejected >= self.max_steps {
                return Err(RadauError::TooManySteps {
                    t: self.t,
                    max_steps: self.max_steps,
                });
            }
            if h.abs() <= 10.0 * UROUND * self.t.abs().max(1e-300) || h < 1e-300 {
                return Err(RadauError::StepSizeTooSmall { t: self.t, h });
            }
            if !self.jac_current && (self.first || self.jac_is_stale()) {
                self.update_jacobian();
            }
            let refactor = match &self.lu {
                // The iteration matrix need not be exact: a step size that
                // differs in the last digits (output times) reuses it.
                Some((hl, _)) => (hl / h - 1.0).abs() > 1e-9,
                None => true,
            };
            if refactor {
                self.factorise(h)?;
            }
            let scal = self.scale();
            // Starting values: zero, or the previous collocation polynomial.
            let mut z: [DVector<f64>; 3] = if self.first {
                [DVector::zeros(n), DVector::zeros(n), DVector::zeros(n)]
            } else {
                let c3q = h / self.h_old;
                let (c1m1, c2m1) = (tab_c[0] - 1.0, tab_c[1] - 1.0);
                let extrapolate = |cq: f64| {
                    (&self.cont[0] + (&self.cont[1] + &self.cont[2] * (cq - c1m1)) * (cq - c2m1))
                        * cq
                };
                [
                    extrapolate(tab_c[0] * c3q),
                    extrapolate(tab_c[1] * c3q),
                    extrapolate(c3q),
                ]
            };
            self.faccon = self.faccon.max(UROUND).powf(0.8);
            let mut theta = self.theta.abs();
            let mut dyno_old = 0.0;
            let mut thq_old = 0.0;
            let mut newt = 0;
            let outcome = loop {
                if newt >= NIT {
                    break NewtonOutcome::Failed;
                }
                newt += 1;
                let mut fz = Vec::with_capacity(3);
                for (j, zj) in z.iter().enumerate() {
                    let yj = &self.y + zj;
                    fz.push(self.eval(self.t + tab_c[j] * h, &yj));
                }
                if fz.iter().any(|f| f.iter().any(|v| !v.is_finite())) {
                    break NewtonOutcome::NotFinite;
                }
                // Residual R_i = −Z_i + h·Σ_j a_ij·F_j.
                let mut r = DVector::zeros(3 * n);
                for i in 0..3 {
                    for k in 0..n {
                        let s: f64 = (0..3).map(|j| tab_a[i][j] * fz[j][k]).sum();
                        r[i * n + k] = -z[i][k] + h * s;
                    }
                }
                self.stats.newton_iterations += 1;
                let lu = &self.lu.as_ref().expect("factorised").1;
                if !lu.solve_mut(&mut r) {
                    return Err(RadauError::Singular { t: self.t });
                }
                let mut sum = 0.0;
                for i in 0..3 {
                    for k in 0..n {
                        let q = r[i * n + k] / scal[k];
                        sum += q * q;
                    }
                }
                let dyno = (sum / (3 * n) as f64).sqrt();
                if !dyno.is_finite() {
                    break NewtonOutcome::NotFinite;
                }
                if newt > 1 && newt < NIT {
                    let thq = dyno / dyno_old;
                    theta = if newt == 2 {
                        thq
                    } else {
                        (thq * thq_old).sqrt()
                    };
                    thq_old = thq;
                    if theta < 0.99 {
                        self.faccon = theta / (1.0 - theta);
                        let dyth =
                            self.faccon * dyno * theta.powi((NIT - 1 - newt) as i32) / self.fnewt;
                        if dyth >= 1.0 {
                            let qnewt = dyth.clamp(1e-4, 20.0);
                            let hhfac = 0.8 * qnewt.powf(-1.0 / (4.0 + (NIT - 1 - newt) as f64));
                            break NewtonOutcome::TooSlow(hhfac);
                        }
                    } else {
                        break NewtonOutcome::Failed;
                    }
                }
                dyno_old = dyno.max(UROUND);
                for i in 0..3 {
                    for k in 0..n {
                        z[i][k] += r[i * n + k];
                    }
                }
                if self.faccon * dyno <= self.fnewt {
                    break NewtonOutcome::Converged;
                }
            };
            self.theta = theta;
            match outcome {
                NewtonOutcome::Converged => {}
                NewtonOutcome::TooSlow(hhfac) => {
                    h *= hhfac;
                    to_switch = false;
                    self.reject = true;
                    self.refresh_after_failure();
                    continue;
                }
                NewtonOutcome::Failed | NewtonOutcome::NotFinite => {
                    if matches!(outcome, NewtonOutcome::NotFinite) && h < 1e-12 * self.h_max {
                        return Err(RadauError::NotFinite { t: self.t });
                    }
                    h *= 0.5;
                    to_switch = false;
                    self.reject = true;
                    self.refresh_after_failure();
                    continue;
                }
            }
            // Error estimate (IV.8.19–8.20).
            let err = self.error_estimate(h, &z, &scal);
            let fac = SAFE.min(SAFE * (1.0 + 2.0 * NIT as f64) / (newt + 2 * NIT) as f64);
            let mut quot = FACR.max(FACL.min(err.powf(0.25) / fac));
            let mut h_new = h / quot;
            if err < 1.0 {
                // Accepted. Gustafsson's predictive controller.
                if self.stats.accepted >= 1 {
                    let facgus = (self.h_acc / h) * (err * err / self.err_acc).powf(0.25) / SAFE;
                    let facgus = FACR.max(FACL.min(facgus));
                    quot = quot.max(facgus);
                    h_new = h / quot;
                }
                // Collocation polynomial (divided differences, RADAU5's
                // CONT): u(s) = y1 + s·(d1 + (s − c2 + 1)·(d2 + (s − c1 + 1)·d3)),
                // s = (t − t1)/h ∈ [−1, 0].
                let (c1, c2) = (tab_c[0], tab_c[1]);
                let (c1m1, c2m1, c1mc2) = (c1 - 1.0, c2 - 1.0, c1 - c2);
                let d1 = (&z[1] - &z[2]) / c2m1;
                let ak = (&z[0] - &z[1]) / c1mc2;
                let acont3 = (&ak - &z[0] / c1) / c2;
                let d2 = (&ak - &d1) / c1m1;
                let d3 = &d2 - acont3;
                let y1 = &self.y + &z[2];
                let mut g1 = vec![0.0; self.g.len()];
                if !g1.is_empty() {
                    self.sys.switching(self.t + h, y1.as_slice(), &mut g1);
                    let cont = [&d1, &d2, &d3];
                    if let Some(theta) = self.first_switch(h, &y1, cont, &g1) {
                        // Redo the step up to the sign change.
                        self.stats.switches += 1;
                        h *= theta;
                        self.lu = None;
                        to_switch = true;
                        continue;
                    }
                }
                self.h_acc = h;
                self.err_acc = err.max(1e-2);
                self.stats.accepted += 1;
                // Ends on a sign change: past it, or shortened to it.
                let switched = to_switch
                    || self
                        .g
                        .iter()
                        .zip(&g1)
                        .any(|(a, b)| a * b < 0.0 || (*a != 0.0 && *b == 0.0));
                self.g = g1;
                self.cont = [d1, d2, d3];
                self.h_old = h;
                self.y = y1;
                self.t += h;
                let y = self.y.clone();
                self.f0 = self.eval(self.t, &y);
                self.jac_current = false;
                self.first = false;
                if switched {
                    // Past a kink: a fresh Jacobian for the next step.
                    self.theta = 1.0;
                }
                self.switched = switched;
                h_new = h_new.min(self.h_max);
                if self.reject {
                    h_new = h_new.min(h);
                }
                self.reject = false;
                let qt = h_new / h;
                if self.theta <= THET && (QUOT1..=QUOT2).contains(&qt) {
                    // Keep h and the factorisation.
                    h_new = h;
                }
                return Ok((h, h_new));
            }
            // Rejected.
            self.stats.rejected += 1;
            self.reject = true;
            to_switch = false;
            if self.first {
                h *= 0.1;
            } else {
                h = h_new;
            }
            self.refresh_after_failure();
        }
    }

    /// When a switching function changes sign over the step `[t, t + h]`
    /// (strictly: from non-zero to the other sign or to zero), the fraction
    /// `θ ∈ (0, 1)` of the step at which the first one does, located on the
    /// collocation polynomial by bisection; `None` when none does, or when
    /// the change lies within 1e-6 of the step (or 1000 ulps of `t`) from
    /// either end (it began or ends on it, within the polynomial's accuracy:
    /// a kink that close to an end costs an error of order (1e-6·h)²).
    fn first_switch(
        &self,
        h: f64,
        y1: &DVector<f64>,
        cont: [&DVector<f64>; 3],
        g1: &[f64],
    ) -> Option<f64> {
        let (c1m1, c2m1) = (self.tab.c[0] - 1.0, self.tab.c[1] - 1.0);
        let at = |theta: f64, g: &mut [f64]| {
            let s = theta - 1.0;
            let u = y1 + (cont[0] + (cont[1] + cont[2] * (s - c1m1)) * (s - c2m1)) * s;
            self.sys.switching(self.t + theta * h, u.as_slice(), g);
        };
        let changed = |a: f64, b: f64| a != 0.0 && (a * b < 0.0 || b == 0.0);
        if !self.g.iter().zip(g1).any(|(a, b)| changed(*a, *b)) {
            return None;
        }
        // Bisection for the earliest sign change of any component.
        let (mut lo, mut hi) = (0.0, 1.0);
        let mut g = vec![0.0; g1.len()];
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            at(mid, &mut g);
            if self.g.iter().zip(&g).any(|(a, b)| changed(*a, *b)) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        // Too close to an end to be worth a separate step: a thousand ulps
        // of t from the end; from the start also a fraction 1e-6 of the
        // step (the previous step was ended on this sign change, and the
        // polynomial's root only just missed it).
        let ulps = 1e3 * f64::EPSILON * self.t.abs().max(f64::MIN_POSITIVE);
        (hi * h > ulps.max(1e-6 * h) && (1.0 - hi) * h > ulps).then_some(hi)
    }

    /// After a failed attempt: a fresh Jacobian if the current one is not,
    /// else only a new factorisation (forced by the new step size).
    fn refresh_after_failure(&mut self) {
        if !self.jac_current {
            self.update_jacobian();
        }
        self.lu = None;
    }

    /// The Jacobian is re-evaluated after an accepted step when the last
    /// Newton iteration converged slowly (θ > 0.001).
    fn jac_is_stale(&self) -> bool {
        self.theta > THET
    }

    fn error_estimate(&mut self, h: f64, z: &[DVector<f64>; 3], scal: &DVector<f64>) -> f64 {
        let dd = self.tab.dd;
        let f2 = (&z[0] * dd[0] + &z[1] * dd[1] + &z[2] * dd[2]) / h;
        let mut cont = &f2 + &self.f0;
        let lu = self.lu_err.as_ref().expect("factorised");
        lu.solve_mut(&mut cont);
        let n = self.n as f64;
        let norm = |c: &DVector<f64>| {
            let s: f64 = c
                .iter()
                .zip(scal.iter())
                .map(|(v, s)| (v / s).powi(2))
                .sum();
            (s / n).sqrt().max(1e-10)
        };
        let mut err = norm(&cont);
        if err >= 1.0 && (self.first || self.reject) {
            // Filtered estimate: f evaluated at y0 + err.
            let yp = &self.y + &cont;
            let f1 = self.eval(self.t, &yp);
            let mut cont2 = f1 + &f2;
            let lu = self.lu_err.as_ref().expect("factorised");
            lu.solve_mut(&mut cont2);
            err = norm(&cont2);
        }
        if err.is_finite() {
            err
        } else {
            f64::INFINITY
        }
    }
}

enum NewtonOutcome {
    Converged,
    /// Predicted not to converge within the iteration limit: step factor.
    TooSlow(f64),
    Failed,
    NotFinite,
}

#[cfg(test)]
mod tests;
