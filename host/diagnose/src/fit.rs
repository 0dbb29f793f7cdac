//! Fitting a friction model: Levenberg–Marquardt (the `levenberg-marquardt`
//! crate, MINPACK's algorithm) on the transformed parameters θ (see
//! [`super::model`]). Two objectives:
//!
//! - [`fit`]: the law's force against the force the data imply, each
//!   residual vector one run of the friction FMU along the training
//!   intervals (milliseconds); starting points of the nonlinear parameters
//!   (Stribeck velocity, presliding stiffness) from a small grid. The
//!   Jacobian comes from the FMU's parameter sensitivities, one run for
//!   every column ([`force_jacobian`]), where the FMU carries them (this
//!   project's LuGre.fmu); by forward differences in θ otherwise;
//! - [`polish`]: the whole system's outputs against the measured channels
//!   on the training data (output error), each residual vector one
//!   co-simulation; a few iterations from the force fit, for the effects
//!   whose signature the force estimate cannot see (what happens while the
//!   contact sticks). The Jacobian from the output sensitivities carried
//!   along one co-simulation ([`crate::tangent`]) where the plant lists its
//!   states and is linear; by forward differences in θ otherwise.

use super::model::{Free, FrictionModel};
use super::problem::FrictionData;
use super::sim::FrictionSim;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};

/// Residual of a parameter set the FMU refuses (relative to the force scale).
const REFUSED: f64 = 1e3;

/// Step of the forward differences in θ (θ is a logarithm: a relative step).
const DIFF_STEP: f64 = 1e-5;

/// Step of the forward differences of [`polish`]: larger, because a
/// co-simulation's outputs carry the master's iteration tolerance.
pub(crate) const POLISH_DIFF_STEP: f64 = 1e-3;

/// The fewest free parameters for which the force fit takes its Jacobian
/// from the FMU's parameter sensitivities rather than differences. A run
/// of LuGre.fmu costs about 90 ns per interval; carrying the
/// sensitivities adds as much again, and each `∂F/∂p` read through
/// `fmi2GetDirectionalDerivative` about 60 ns per interval: one run with
/// the sensitivities costs about 2 + 0.6·k plain runs against the k of
/// the differences, and the whole EMPS diagnosis (candidates of 2–4 free
/// parameters) took 4–8 % longer with the sensitivities for every fit.
const SENSITIVITIES_FROM: usize = 5;

/// The fit's result.
pub struct Fitted {
    pub model: FrictionModel,
    /// RMS of (law − data) force on the training intervals (N); for
    /// [`polish`], the RMS of the normalised output residuals.
    pub rms: f64,
    pub evaluations: usize,
}

/// Residuals of a batch of models (one vector per model, `None` when it
/// cannot be evaluated: the FMU refuses the parameters, the run fails; a
/// shorter batch stops the fit).
/// A batch is the columns of one forward-difference Jacobian, which an
/// evaluator may run in parallel.
pub type Residuals<'a> = ResidualsOf<'a, FrictionModel>;

/// [`Residuals`] of models of any kind (the fit of another law than
/// LuGre, [`crate::memory`]).
pub type ResidualsOf<'a, M> = dyn FnMut(&[M]) -> Vec<Option<DVector<f64>>> + 'a;

/// The Jacobian of the residuals in θ at `coordinates.at(θ)` from one
/// evaluation, when the evaluator can give it (`None`: differences).
pub type ExactJacobian<'a, C = Freed> = dyn FnMut(&C, &[f64]) -> Option<DMatrix<f64>> + 'a;

/// What a fit moves: the coordinates θ of a model (transformed so that
/// every θ is a physical model) and the model at θ.
pub trait Coordinates {
    type Model: Clone;
    /// θ of the start.
    fn theta(&self) -> Vec<f64>;
    /// The model at `theta`.
    fn at(&self, theta: &[f64]) -> Self::Model;
}

/// A LuGre model and the parameters a fit frees ([`FrictionModel::free`]).
pub struct Freed {
    pub model: FrictionModel,
    pub free: Vec<Free>,
}

impl Coordinates for Freed {
    type Model = FrictionModel;
    fn theta(&self) -> Vec<f64> {
        self.model.theta(&self.free)
    }
    fn at(&self, theta: &[f64]) -> FrictionModel {
        self.model.at(&self.free, theta)
    }
}

struct Problem<'a, 'r, C: Coordinates> {
    coordinates: C,
    theta: DVector<f64>,
    residual: &'r mut ResidualsOf<'a, C::Model>,
    /// Where the Jacobian comes from when not from differences.
    exact: Option<&'r mut ExactJacobian<'a, C>>,
    /// Length of the residual vector (for the refusal vector).
    len: usize,
    diff_step: f64,
    evaluations: usize,
    /// What the evaluations cost against `budget`: one each, and an exact
    /// Jacobian as many as the differences it stands in for (so that a
    /// budget is a number of iterations, whichever way the Jacobian came).
    charged: usize,
    /// Stop evaluating (and make LM stop) once this much is charged.
    budget: usize,
    residuals: Option<DVector<f64>>,
    /// The lowest cost seen and its θ: the result, whatever LM reports.
    best: Option<(f64, Vec<f64>)>,
}

impl<C: Coordinates> Problem<'_, '_, C> {
    /// The residuals at each θ of `thetas` (one batch), or `None` when the
    /// budget is spent.
    fn residuals_at(&mut self, thetas: &[Vec<f64>]) -> Option<Vec<DVector<f64>>> {
        if self.charged + thetas.len() > self.budget {
            return None;
        }
        self.evaluations += thetas.len();
        self.charged += thetas.len();
        let models: Vec<C::Model> = thetas.iter().map(|t| self.coordinates.at(t)).collect();
        let results = (self.residual)(&models);
        // an evaluator that gives fewer has stopped (the diagnosis's time
        // limit): so does the fit, with the best seen
        if results.len() != thetas.len() {
            return None;
        }
        let mut out = Vec::with_capacity(thetas.len());
        for (theta, r) in thetas.iter().zip(results) {
            let r = r
                .filter(|r| r.iter().all(|x| x.is_finite()))
                .unwrap_or_else(|| {
                    DVector::from_element(self.len, REFUSED / (self.len as f64).sqrt())
                });
            let cost = r.norm_squared();
            if self.best.as_ref().is_none_or(|(c, _)| cost < *c) {
                self.best = Some((cost, theta.clone()));
            }
            out.push(r);
        }
        Some(out)
    }
}

/// A wrapper whose `residuals` and `jacobian` run the simulations (the
/// crate's trait takes `&self`, the simulations need `&mut`).
struct Fit<'a, 'r, C: Coordinates>(std::cell::RefCell<Problem<'a, 'r, C>>);

impl<C: Coordinates> LeastSquaresProblem<f64, Dyn, Dyn> for Fit<'_, '_, C> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        let p = self.0.get_mut();
        p.theta = x.clone();
        p.residuals = None;
    }

    fn params(&self) -> DVector<f64> {
        self.0.borrow().theta.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let mut p = self.0.borrow_mut();
        if p.residuals.is_none() {
            let theta: Vec<f64> = p.theta.iter().copied().collect();
            p.residuals = p.residuals_at(&[theta]).and_then(|mut r| r.pop());
        }
        p.residuals.clone()
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let r0 = self.residuals()?;
        let mut p = self.0.borrow_mut();
        let theta: Vec<f64> = p.theta.iter().copied().collect();
        if p.charged + theta.len() <= p.budget {
            let Problem {
                exact, coordinates, ..
            } = &mut *p;
            if let Some(jacobian) = exact.as_mut().and_then(|j| j(coordinates, &theta)) {
                p.evaluations += 1;
                p.charged += theta.len();
                return Some(jacobian);
            }
        }
        let steps: Vec<f64> = theta
            .iter()
            .map(|t| p.diff_step * t.abs().max(1.0))
            .collect();
        let shifted: Vec<Vec<f64>> = (0..theta.len())
            .map(|j| {
                let mut t = theta.clone();
                t[j] += steps[j];
                t
            })
            .collect();
        let columns = p.residuals_at(&shifted)?;
        let mut jac = DMatrix::zeros(r0.len(), theta.len());
        for (j, r) in columns.into_iter().enumerate() {
            jac.set_column(j, &((r - &r0) / steps[j]));
        }
        Some(jac)
    }
}

/// Minimise `residual` over the coordinates θ of `coordinates`, from
/// theirs, with at most `budget` evaluations; the best model seen, its
/// cost and the count.
fn minimise<'a, C: Coordinates>(
    coordinates: C,
    residual: &mut ResidualsOf<'a, C::Model>,
    exact: Option<&mut ExactJacobian<'a, C>>,
    diff_step: f64,
    budget: usize,
) -> (C::Model, f64, usize) {
    let theta0 = coordinates.theta();
    let mut problem = Problem {
        theta: DVector::from_vec(theta0.clone()),
        coordinates,
        residual,
        exact,
        len: 1,
        diff_step,
        evaluations: 0,
        charged: 0,
        budget,
        residuals: None,
        best: None,
    };
    match problem.residuals_at(std::slice::from_ref(&theta0)) {
        // kept: LM asks for the start's residuals first
        Some(mut r) => {
            problem.len = r[0].len();
            problem.residuals = r.pop();
        }
        None => {
            let start = problem.coordinates.at(&theta0);
            return (start, f64::INFINITY, problem.evaluations);
        }
    }
    let (result, _report) = LevenbergMarquardt::new()
        .with_patience(12)
        .with_ftol(1e-8)
        .with_xtol(1e-8)
        .minimize(Fit(std::cell::RefCell::new(problem)));
    let p = result.0.into_inner();
    let (cost, theta) = p.best.unwrap_or((f64::INFINITY, theta0));
    (p.coordinates.at(&theta), cost, p.evaluations)
}

/// The force-fit residuals of `model`: (law − data) / (√n · scale) on the
/// intervals `train`.
pub fn force_residuals(
    sim: &mut FrictionSim,
    data: &FrictionData,
    train: &[usize],
    scale: f64,
    model: &FrictionModel,
) -> Option<DVector<f64>> {
    let norm = (train.len() as f64).sqrt() * scale;
    let f = sim.run(model, data).ok()?;
    Some(DVector::from_iterator(
        train.len(),
        train.iter().map(|&j| (f[j] - data.f[j]) / norm),
    ))
}

/// `∂p/∂θ_j` of the FMU parameters `p` of `base.at(free, θ)`
/// ([`FrictionModel::parameters`]) for the parameters that move with θ:
/// their names and rows. By central differences of the map, which is
/// arithmetic (exponentials of θ, σ1 following √σ0), not a simulation:
/// with a step of 1e-6 they are exact to about 1e-10.
pub(crate) fn parameter_map(
    base: &FrictionModel,
    free: &[Free],
    theta: &[f64],
) -> Vec<(String, Vec<f64>)> {
    let at = |t: &[f64]| base.at(free, t).parameters();
    let names = at(theta);
    let mut rows = vec![vec![0.0; theta.len()]; names.len()];
    for j in 0..theta.len() {
        let step = 1e-6 * theta[j].abs().max(1.0);
        let (mut up, mut down) = (theta.to_vec(), theta.to_vec());
        up[j] += step;
        down[j] -= step;
        let (pu, pd) = (at(&up), at(&down));
        for (i, row) in rows.iter_mut().enumerate() {
            row[j] = (pu[i].1 - pd[i].1) / (2.0 * step);
        }
    }
    names
        .into_iter()
        .zip(rows)
        .filter(|(_, row)| row.iter().any(|&d| d != 0.0))
        .map(|((name, _), row)| (name, row))
        .collect()
}

/// The Jacobian in θ of the force-fit residuals ([`force_residuals`]) at
/// `base.at(free, θ)` from one run of the friction FMU with its parameter
/// sensitivities ([`FrictionSim::run_with_sensitivities`]) and the chain
/// rule through the parameter map (`parameter_map`): `∂r_k/∂θ_j = Σ_i ∂F_k/∂p_i · ∂p_i/∂θ_j
/// / (√n·scale)`. `None` when the FMU carries no sensitivities (or not for
/// a parameter that moves) or the run fails.
pub fn force_jacobian(
    sim: &mut FrictionSim,
    data: &FrictionData,
    train: &[usize],
    scale: f64,
    (base, free, theta): (&FrictionModel, &[Free], &[f64]),
) -> Option<DMatrix<f64>> {
    if !sim.has_sensitivities() {
        return None;
    }
    let map = parameter_map(base, free, theta);
    let names: Vec<String> = map.iter().map(|(n, _)| n.clone()).collect();
    let model = base.at(free, theta);
    let mut wanted = vec![false; data.t.len()];
    for &k in train {
        wanted[k] = true;
    }
    let s = sim
        .run_with_sensitivities(&model, data, &names, &wanted)
        .ok()?;
    let norm = (train.len() as f64).sqrt() * scale;
    let mut jac = DMatrix::<f64>::zeros(train.len(), theta.len());
    for ((_, row), column) in map.iter().zip(&s.columns) {
        for (j, &dp) in row.iter().enumerate() {
            if dp != 0.0 {
                for (r, &k) in train.iter().enumerate() {
                    jac[(r, j)] += column[k] * dp / norm;
                }
            }
        }
    }
    jac.iter().all(|x| x.is_finite()).then_some(jac)
}

/// Fit the free parameters of `model` to `data` on the intervals `train`,
/// from the best of `starts` (models with the same free parameters).
pub fn fit(
    starts: &[FrictionModel],
    sim: &mut FrictionSim,
    data: &FrictionData,
    train: &[usize],
) -> Fitted {
    let scale = starts[0].fc.abs().max(1e-12) * starts[0].normal_scale(data);
    let mut evaluations = 0;
    // the best start by cost
    let mut best: Option<(f64, &FrictionModel)> = None;
    for s in starts {
        let cost =
            force_residuals(sim, data, train, scale, s).map_or(f64::INFINITY, |r| r.norm_squared());
        evaluations += 1;
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, s));
        }
    }
    let start = best.map(|(_, s)| s).unwrap_or(&starts[0]).clone();
    let sim = std::cell::RefCell::new(sim);
    let mut residual = |models: &[FrictionModel]| {
        models
            .iter()
            .map(|m| force_residuals(&mut sim.borrow_mut(), data, train, scale, m))
            .collect()
    };
    let mut exact = |c: &Freed, theta: &[f64]| {
        if c.free.len() < SENSITIVITIES_FROM {
            return None;
        }
        force_jacobian(
            &mut sim.borrow_mut(),
            data,
            train,
            scale,
            (&c.model, &c.free, theta),
        )
    };
    let free = start.free();
    let (model, cost, n) = minimise(
        Freed { model: start, free },
        &mut residual,
        Some(&mut exact),
        DIFF_STEP,
        usize::MAX,
    );
    Fitted {
        model,
        // the residuals are divided by √n·scale
        rms: cost.sqrt() * scale,
        evaluations: evaluations + n,
    }
}

/// Refine `start` on an output-error objective (`residual`: one
/// co-simulation per model, already normalised), with at most `budget`
/// co-simulations, or as many iterations as those would make: an exact
/// Jacobian (`exact`: the output sensitivities carried along one
/// co-simulation, [`crate::tangent`]; differences where it gives none)
/// counts as the differences it replaces. Returns `start` itself when
/// nothing better was found.
pub fn polish<'a>(
    start: &FrictionModel,
    residual: &mut Residuals<'a>,
    exact: Option<&mut ExactJacobian<'a>>,
    budget: usize,
) -> Fitted {
    let coordinates = Freed {
        model: start.clone(),
        free: start.free(),
    };
    let (model, cost, evaluations) =
        minimise(coordinates, residual, exact, POLISH_DIFF_STEP, budget);
    Fitted {
        model,
        rms: cost.sqrt(),
        evaluations,
    }
}

/// [`polish`] of a model of any kind: `residual` minimised over the
/// coordinates θ from theirs, with at most `budget` co-simulations; the
/// best model seen, its cost and the count.
pub fn polish_any<C: Coordinates>(
    coordinates: C,
    residual: &mut ResidualsOf<'_, C::Model>,
    budget: usize,
) -> (C::Model, f64, usize) {
    minimise(coordinates, residual, None, POLISH_DIFF_STEP, budget)
}

impl FrictionModel {
    /// The factor that turns a level into newtons: the mean normal force
    /// in the normal-force form, else 1.
    fn normal_scale(&self, data: &FrictionData) -> f64 {
        if self.normal_force_form {
            (data.fn_.iter().sum::<f64>() / data.fn_.len().max(1) as f64).max(1e-12)
        } else {
            1.0
        }
    }
}
