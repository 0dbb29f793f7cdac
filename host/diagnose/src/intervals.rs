//! 95 % intervals of the fitted friction parameters.
//!
//! The final model's free parameters θ ([`super::model::Free`]) minimise
//! the output error of the training data, `r(θ)`: the measured channels
//! minus the co-simulated ones, normalised. Their covariance is the
//! cluster-robust estimate of least squares in its jackknife form (CR3),
//!
//! ```text
//! d_g = (JᵀJ − J_gᵀJ_g)⁻¹ J_gᵀ r_g,   Σθ = (G − 1)/G · Σ_g d_g d_gᵀ
//! ```
//!
//! with `J = ∂r/∂θ` at the optimum (forward differences, one
//! co-simulation per parameter) and `g` the [`super::Options::groups`]
//! runs of consecutive training samples: `d_g` is how far one Gauss–Newton
//! step moves θ when run g is left out. The residuals of a co-simulation
//! are correlated in time (a slip mistimed by a step leaves an error for
//! many samples), so the sum of squares alone, which treats every sample
//! as independent, would give intervals far too narrow; within a run the
//! correlation is kept whole, between runs it is taken as none (clustered
//! data, Liang and Zeger 1986). The plain sandwich
//! `(JᵀJ)⁻¹ · G/(G − 1) Σ_g (J_gᵀ r_g)(J_gᵀ r_g)ᵀ · (JᵀJ)⁻¹` (CR1)
//! falls short where a few runs carry a parameter's information (the
//! negative direction of a short record, the runs that reverse); the
//! jackknife form does not (Bell and McCaffrey 2002). An FMU parameter
//! `p(θ)` (Fc, Fs, σ2, …, as the LuGre FMU takes it) gets
//! `p ± (t₀.₉₇₅,ν · √(∇pᵀ Σθ ∇p) + |∇pᵀ δθ|)` (the delta method), with
//! Student's t at the Satterthwaite degrees of freedom ν of its variance
//! estimate: G − 1 when the runs share its information evenly, about the
//! number of runs that carry it otherwise
//! ([`ThetaCovariance::interval`]; Imbens and Kolesár 2016).
//!
//! `δθ` is what the co-simulation's own step error does to the estimate,
//! which the scatter does not contain: it is the same in every run of
//! samples, a bias. With `r_f` the residuals of the same model
//! co-simulated at a [`super::FINE_STEP_DIVISOR`] times finer step, the
//! Gauss–Newton step to the fine optimum is `(JᵀJ)⁻¹ Jᵀ (r − r_f)`; taken
//! as the error of a first-order method, the whole step error's share is
//! 4/3 of it. On data from an independent simulator the scatter alone
//! gave intervals tenfold narrower than the fitted values' distance from
//! the truth in 21 of 30 cases (BENCHMARKS.md).

use super::fit::Residuals;
use super::model::{Free, FrictionModel};
use nalgebra::{DMatrix, DVector};

/// The covariance of the free parameters of a fitted model.
pub struct ThetaCovariance {
    free: Vec<Free>,
    theta: Vec<f64>,
    covariance: DMatrix<f64>,
    /// Per run g, `W_g = (JᵀJ − J_gᵀJ_g)⁻¹ J_gᵀJ_g (JᵀJ − J_gᵀJ_g)⁻¹`:
    /// how much of a quantity's variance estimate run g contributes when
    /// the residuals are independent, for the effective degrees of freedom
    /// of its interval ([`ThetaCovariance::interval`]).
    run_weights: Vec<DMatrix<f64>>,
    /// The shift of θ the co-simulation's step error makes (zero without
    /// the fine residuals).
    step_bias: DVector<f64>,
}

/// The step error's share of the step to the fine optimum for a
/// first-order co-simulation refined [`super::FINE_STEP_DIVISOR`] times:
/// e − e/4 = (3/4)·e is what the finer step removes, so e = 4/3 of it.
const STEP_BIAS_FACTOR: f64 = 4.0 / 3.0;

/// Step of the forward differences in θ: that of the output-error fit
/// (a co-simulation's outputs carry the master's iteration tolerance).
const DIFF_STEP: f64 = 1e-3;

/// Step of the differences of an FMU parameter in θ (no co-simulation:
/// the map θ → parameter is a closed form).
const MAP_STEP: f64 = 1e-7;

/// Σθ of `model` at its free parameters, from the training residuals
/// `residual` (one vector per model, `channels` entries per sample, the
/// samples in time order) clustered into `groups` runs of consecutive
/// samples, and the step error's shift from `fine`, the model's residuals
/// at a finer step (none: no shift). `None` when a co-simulation fails or
/// JᵀJ is singular (a free parameter the data do not move).
pub fn theta_covariance(
    model: &FrictionModel,
    residual: &mut Residuals<'_>,
    fine: Option<&DVector<f64>>,
    channels: usize,
    groups: usize,
) -> Option<ThetaCovariance> {
    let free = model.free();
    let theta = model.theta(&free);
    let k = free.len();
    if k == 0 || channels == 0 {
        return None;
    }
    let steps: Vec<f64> = theta.iter().map(|t| DIFF_STEP * t.abs().max(1.0)).collect();
    let mut models = vec![model.at(&free, &theta)];
    for j in 0..k {
        let mut t = theta.clone();
        t[j] += steps[j];
        models.push(model.at(&free, &t));
    }
    let mut runs = residual(&models).into_iter();
    let r0 = runs.next()??;
    let mut jacobian = DMatrix::zeros(r0.len(), k);
    for (j, r) in runs.enumerate() {
        let r = r?;
        if r.len() != r0.len() {
            return None;
        }
        jacobian.set_column(j, &((r - &r0) / steps[j]));
    }
    let information = jacobian.transpose() * &jacobian;
    let bread = information.clone().try_inverse()?;
    let samples = r0.len() / channels;
    let g = groups.clamp(2, samples.max(2));
    // the delete-one-run jackknife (one Gauss–Newton step each):
    // d_g = (JᵀJ − J_gᵀJ_g)⁻¹ J_gᵀ r_g is how far θ moves when run g is
    // left out, and Σθ = (G − 1)/G · Σ_g d_g d_gᵀ (the cluster-robust
    // estimator's CR3 form, which corrects its plain form's shortfall
    // where a few runs carry a parameter's information)
    let mut spread = DMatrix::zeros(k, k);
    let mut run_weights = Vec::with_capacity(g);
    for group in 0..g {
        let (a, b) = (
            group * samples / g * channels,
            (group + 1) * samples / g * channels,
        );
        if b <= a {
            continue;
        }
        let rows = jacobian.rows(a, b - a);
        let score: DVector<f64> = rows.transpose() * r0.rows(a, b - a);
        let own = rows.transpose() * rows;
        let without = (&information - &own).try_inverse()?;
        run_weights.push(&without * own * &without);
        let d = without * score;
        spread += &d * d.transpose();
    }
    let covariance = spread * ((g as f64 - 1.0) / g as f64);
    if !covariance.iter().all(|x| x.is_finite()) {
        return None;
    }
    let step_bias = match fine {
        Some(f) if f.len() == r0.len() => {
            &bread * (jacobian.transpose() * (&r0 - f)) * STEP_BIAS_FACTOR
        }
        _ => DVector::zeros(k),
    };
    if !step_bias.iter().all(|x| x.is_finite()) {
        return None;
    }
    Some(ThetaCovariance {
        free,
        theta,
        covariance,
        run_weights,
        step_bias,
    })
}

impl ThetaCovariance {
    /// The 95 % interval `[low, high]` of `quantity(model at θ)`, by the
    /// delta method; `None` when it does not depend on θ (a parameter the
    /// fit did not free) or is not finite.
    pub fn interval(
        &self,
        base: &FrictionModel,
        quantity: &dyn Fn(&FrictionModel) -> Option<f64>,
    ) -> Option<[f64; 2]> {
        let value = quantity(&base.at(&self.free, &self.theta))?;
        let gradient: Vec<f64> = (0..self.theta.len())
            .map(|j| {
                let h = MAP_STEP * self.theta[j].abs().max(1.0);
                let shifted = |d: f64| {
                    let mut t = self.theta.clone();
                    t[j] += d;
                    quantity(&base.at(&self.free, &t))
                };
                Some((shifted(h)? - shifted(-h)?) / (2.0 * h))
            })
            .collect::<Option<_>>()?;
        if gradient.iter().all(|g| *g == 0.0) {
            return None;
        }
        let g = DVector::from_vec(gradient);
        let variance = (g.transpose() * &self.covariance * &g)[(0, 0)];
        let bias = g.dot(&self.step_bias).abs();
        let half = self.t_quantile(&g)? * variance.max(0.0).sqrt() + bias;
        (value.is_finite() && half.is_finite()).then_some([value - half, value + half])
    }

    /// t₀.₉₇₅ for the quantity with gradient `g` in θ, with the
    /// Satterthwaite degrees of freedom of its variance estimate, a sum
    /// over the runs whose terms have (for independent residuals) the
    /// sizes `q_g = gᵀ W_g g`: ν = (Σ q_g)² / Σ q_g² (Bell and McCaffrey
    /// 2002; Imbens and Kolesár 2016). Runs that share a quantity's
    /// information evenly give ν = G; a quantity that only a few runs
    /// inform gets about as many degrees of freedom as there are of them,
    /// and a wider interval. At most G − 1, at least 1.
    fn t_quantile(&self, g: &DVector<f64>) -> Option<f64> {
        use statrs::distribution::{ContinuousCDF, StudentsT};
        let q: Vec<f64> = self
            .run_weights
            .iter()
            .map(|w| (g.transpose() * w * g)[(0, 0)].max(0.0))
            .collect();
        let (sum, squares) = (q.iter().sum::<f64>(), q.iter().map(|x| x * x).sum::<f64>());
        let most = (self.run_weights.len().max(2) - 1) as f64;
        let nu = if squares > 0.0 {
            (sum * sum / squares).clamp(1.0, most)
        } else {
            most
        };
        StudentsT::new(0.0, 1.0, nu)
            .map(|t| t.inverse_cdf(0.975))
            .ok()
    }

    /// The interval of the FMU parameter `name` ([`FrictionModel::parameters`]).
    pub fn parameter_interval(&self, base: &FrictionModel, name: &str) -> Option<[f64; 2]> {
        self.interval(base, &|m: &FrictionModel| {
            m.parameters()
                .into_iter()
                .find(|(n, _)| n == name)
                .map(|(_, x)| x)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> FrictionModel {
        FrictionModel::coulomb_for_tests(2.0, 1e7, 0.0)
    }

    /// The least-squares Fc of y = Fc·u and the 95 % interval
    /// [`theta_covariance`] gives it, the residuals clustered into `runs`
    /// equal runs.
    fn fitted_interval(u: &[f64], y: &[f64], runs: usize) -> (f64, [f64; 2]) {
        let fc =
            y.iter().zip(u).map(|(y, u)| y * u).sum::<f64>() / u.iter().map(|u| u * u).sum::<f64>();
        let mut m = model();
        m.fc = fc;
        m.fs = fc;
        let n = (u.len() as f64).sqrt();
        let mut residual = |models: &[FrictionModel]| -> Vec<Option<DVector<f64>>> {
            models
                .iter()
                .map(|m| {
                    Some(DVector::from_iterator(
                        u.len(),
                        (0..u.len()).map(|i| (y[i] - m.fc * u[i]) / n),
                    ))
                })
                .collect()
        };
        let cov = theta_covariance(&m, &mut residual, None, 1, runs).unwrap();
        (fc, cov.parameter_interval(&m, "Fc").unwrap())
    }

    /// A linear model whose residuals are known: y = Fc·u + e, with the
    /// noise e correlated within runs of 50 samples (a constant per run),
    /// fitted through the transform θ = ln Fc. The sandwich's interval of
    /// Fc covers the truth in close to 95 % of 400 draws, where the
    /// independent-sample formula (σ²·(JᵀJ)⁻¹) covers far fewer.
    #[test]
    fn clustered_intervals_cover_the_truth_at_their_level() {
        use rand::{RngExt, SeedableRng};
        use rand_distr::{Distribution, Normal};
        let truth = 2.0;
        let (runs, per_run) = (20, 50);
        let u: Vec<f64> = (0..runs * per_run)
            .map(|i| 1.0 + (i as f64 * 0.37).sin())
            .collect();
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let normal = Normal::new(0.0, 0.3).unwrap();
        let (mut covered, mut naive_covered, draws) = (0, 0, 400);
        for _ in 0..draws {
            let offsets: Vec<f64> = (0..runs).map(|_| normal.sample(&mut rng)).collect();
            let y: Vec<f64> = (0..u.len())
                .map(|i| truth * u[i] + offsets[i / per_run] + 0.01 * rng.random_range(-1.0..1.0))
                .collect();
            let (fc, [low, high]) = fitted_interval(&u, &y, runs);
            assert!(low < fc && fc < high);
            if (low..=high).contains(&truth) {
                covered += 1;
            }
            // the independent-sample interval, for contrast
            let sse: f64 = (0..u.len()).map(|i| (y[i] - fc * u[i]).powi(2)).sum();
            let se = (sse / (u.len() - 1) as f64 / u.iter().map(|u| u * u).sum::<f64>()).sqrt();
            if (truth - fc).abs() <= 1.96 * se {
                naive_covered += 1;
            }
        }
        let rate = covered as f64 / draws as f64;
        assert!((0.90..=0.99).contains(&rate), "coverage {rate}");
        assert!(
            (naive_covered as f64 / draws as f64) < 0.6,
            "{naive_covered} of {draws}"
        );
    }

    /// A parameter whose information sits in a few runs (here 3 of 20:
    /// the input is large there and small elsewhere), with errors
    /// constant over each run: the plain cluster-robust form (CR1,
    /// G/(G − 1)·Σ_g s_g s_gᵀ in the sandwich) covers the truth in
    /// fewer than 85 % of 400 draws, the delete-one-run jackknife (CR3,
    /// what [`theta_covariance`] uses) in at least 90 %.
    #[test]
    fn intervals_hold_their_level_when_a_few_runs_carry_the_information() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let truth = 2.0;
        let (runs, per_run) = (20, 50);
        let u: Vec<f64> = (0..runs * per_run)
            .map(|i| if i / per_run < 3 { 1.0 } else { 0.05 } * (1.0 + 0.5 * (i as f64 * 0.37).sin()))
            .collect();
        let uu: f64 = u.iter().map(|u| u * u).sum();
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        let normal = Normal::new(0.0, 0.3).unwrap();
        let (mut covered, mut plain_covered, draws) = (0, 0, 400);
        let t = 2.093; // t₀.₉₇₅ with 19 degrees of freedom
        for _ in 0..draws {
            let offsets: Vec<f64> = (0..runs).map(|_| normal.sample(&mut rng)).collect();
            let y: Vec<f64> = (0..u.len())
                .map(|i| truth * u[i] + offsets[i / per_run])
                .collect();
            let (fc, [low, high]) = fitted_interval(&u, &y, runs);
            if (low..=high).contains(&truth) {
                covered += 1;
            }
            // CR1 of Fc itself: G/(G − 1)·Σ_g (Σ_i∈g u_i·e_i)² / (Σ u²)²
            let scores: f64 = (0..runs)
                .map(|g| {
                    (g * per_run..(g + 1) * per_run)
                        .map(|i| u[i] * (y[i] - fc * u[i]))
                        .sum::<f64>()
                        .powi(2)
                })
                .sum();
            let se = (runs as f64 / (runs - 1) as f64 * scores).sqrt() / uu;
            if (truth - fc).abs() <= t * se {
                plain_covered += 1;
            }
        }
        let (rate, plain) = (
            covered as f64 / draws as f64,
            plain_covered as f64 / draws as f64,
        );
        assert!(rate >= 0.90, "coverage {rate} (CR1: {plain})");
        assert!(plain < 0.85, "CR1 coverage {plain} (CR3: {rate})");
    }

    /// The step error's shift: fine residuals that differ from the
    /// coarse ones as a model whose Fc is δ larger would (r_f = r − δ·u/√n
    /// for y = Fc·u) widen the interval by 4/3·|δ| (the first-order share),
    /// and identical ones by nothing.
    #[test]
    fn the_step_errors_shift_widens_the_interval_by_its_share() {
        let m = model();
        let u: Vec<f64> = (0..200).map(|i| 1.0 + (i as f64 * 0.1).cos()).collect();
        let y: Vec<f64> = (0..200)
            .map(|i| 2.0 * u[i] + 0.01 * (i as f64 * 1.7).sin())
            .collect();
        let n = (u.len() as f64).sqrt();
        let at =
            |fc: f64| DVector::from_iterator(u.len(), (0..u.len()).map(|i| (y[i] - fc * u[i]) / n));
        let mut residual = |models: &[FrictionModel]| -> Vec<Option<DVector<f64>>> {
            models.iter().map(|m| Some(at(m.fc))).collect()
        };
        let width = |fine: Option<&DVector<f64>>, residual: &mut Residuals<'_>| {
            let cov = theta_covariance(&m, residual, fine, 1, 20).unwrap();
            let [low, high] = cov.parameter_interval(&m, "Fc").unwrap();
            0.5 * (high - low)
        };
        let plain = width(None, &mut residual);
        let same = width(Some(&at(m.fc)), &mut residual);
        assert!((same - plain).abs() <= 1e-12 * plain, "{same} {plain}");
        let delta = 0.05;
        let shifted = at(m.fc) - DVector::from_iterator(u.len(), u.iter().map(|u| delta * u / n));
        let wider = width(Some(&shifted), &mut residual);
        let expect = plain + 4.0 / 3.0 * delta;
        // (the Jacobian by forward differences of 1e-3 in ln Fc is off by
        // about half of that)
        assert!(
            (wider - expect).abs() <= 2e-3 * expect,
            "{wider} against {expect}"
        );
    }

    /// A parameter the fit did not free has no interval.
    #[test]
    fn a_parameter_not_fitted_has_none() {
        let m = model();
        let mut residual = |models: &[FrictionModel]| -> Vec<Option<DVector<f64>>> {
            models
                .iter()
                .map(|m| {
                    Some(DVector::from_iterator(
                        40,
                        (0..40).map(|i| (1.0 + i as f64) * (m.fc - 2.5)),
                    ))
                })
                .collect()
        };
        let cov = theta_covariance(&m, &mut residual, None, 1, 20).unwrap();
        assert!(cov.parameter_interval(&m, "sigma2").is_none());
        assert!(cov.parameter_interval(&m, "Fc").is_some());
    }
}
