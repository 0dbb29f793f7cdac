//! Fitting a friction model to the force the data imply: Levenberg–
//! Marquardt (the `levenberg-marquardt` crate, MINPACK's algorithm) on
//! the transformed parameters θ (see [`super::model`]), each residual a
//! run of the friction FMU along the training intervals, the Jacobian by
//! forward differences in θ. Starting points of the nonlinear parameters
//! (Stribeck velocity, presliding stiffness) come from a small grid.

use super::model::{Free, FrictionModel};
use super::problem::FrictionData;
use super::sim::FrictionSim;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};

/// Residual of a parameter set the FMU refuses (relative to the force scale).
const REFUSED: f64 = 1e3;

/// Step of the forward differences in θ (θ is a logarithm: a relative step).
const DIFF_STEP: f64 = 1e-5;

/// The fit's result.
pub struct Fitted {
    pub model: FrictionModel,
    /// RMS of (law − data) force on the training intervals (N).
    pub rms: f64,
    pub evaluations: usize,
}

struct Problem<'a> {
    base: FrictionModel,
    free: Vec<Free>,
    theta: DVector<f64>,
    sim: &'a mut FrictionSim,
    data: &'a FrictionData,
    train: &'a [usize],
    scale: f64,
    evaluations: usize,
    residuals: Option<DVector<f64>>,
}

impl Problem<'_> {
    fn residuals_at(&mut self, theta: &[f64]) -> DVector<f64> {
        self.evaluations += 1;
        let model = self.base.at(&self.free, theta);
        let norm = (self.train.len() as f64).sqrt() * self.scale;
        match self.sim.run(&model, self.data) {
            Ok(f) => DVector::from_iterator(
                self.train.len(),
                self.train.iter().map(|&j| (f[j] - self.data.f[j]) / norm),
            ),
            Err(_) => DVector::from_element(self.train.len(), REFUSED / norm),
        }
    }
}

/// A wrapper whose `residuals` and `jacobian` run the simulations (the
/// crate's trait takes `&self`, the FMU needs `&mut`).
struct Fit<'a>(std::cell::RefCell<Problem<'a>>);

impl LeastSquaresProblem<f64, Dyn, Dyn> for Fit<'_> {
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
            let r = p.residuals_at(&theta);
            p.residuals = Some(r);
        }
        p.residuals.clone()
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let r0 = self.residuals()?;
        let mut p = self.0.borrow_mut();
        let theta: Vec<f64> = p.theta.iter().copied().collect();
        let mut jac = DMatrix::zeros(r0.len(), theta.len());
        for j in 0..theta.len() {
            let mut t = theta.clone();
            let step = DIFF_STEP * t[j].abs().max(1.0);
            t[j] += step;
            let r = p.residuals_at(&t);
            jac.set_column(j, &((r - &r0) / step));
        }
        Some(jac)
    }
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
        let free = s.free();
        let mut p = Problem {
            base: s.clone(),
            theta: DVector::from_vec(s.theta(&free)),
            free,
            sim,
            data,
            train,
            scale,
            evaluations: 0,
            residuals: None,
        };
        let theta: Vec<f64> = p.theta.iter().copied().collect();
        let cost = p.residuals_at(&theta).norm_squared();
        evaluations += p.evaluations;
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, s));
        }
    }
    let start = best.map(|(_, s)| s).unwrap_or(&starts[0]).clone();
    let free = start.free();
    let problem = Problem {
        theta: DVector::from_vec(start.theta(&free)),
        base: start.clone(),
        free: free.clone(),
        sim,
        data,
        train,
        scale,
        evaluations: 0,
        residuals: None,
    };
    let (result, report) = LevenbergMarquardt::new()
        .with_patience(12)
        .with_ftol(1e-8)
        .with_xtol(1e-8)
        .minimize(Fit(std::cell::RefCell::new(problem)));
    let p = result.0.into_inner();
    evaluations += p.evaluations;
    let theta: Vec<f64> = p.theta.iter().copied().collect();
    let model = start.at(&free, &theta);
    let model = if report.objective_function.is_finite() {
        model
    } else {
        start
    };
    let rms = match p.sim.run(&model, data) {
        Ok(f) => (train
            .iter()
            .map(|&j| (f[j] - data.f[j]).powi(2))
            .sum::<f64>()
            / train.len().max(1) as f64)
            .sqrt(),
        Err(_) => f64::INFINITY,
    };
    Fitted {
        model,
        rms,
        evaluations: evaluations + 1,
    }
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
