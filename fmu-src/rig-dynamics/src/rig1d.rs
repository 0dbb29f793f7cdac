//! One-degree-of-freedom rig (MODELS.md, "Rigs in the seeds"): a mass `m`
//! with viscous damping `c` to ground, a spring `k` to an actuator point
//! `x_a(t)`, an external force, and the friction force applied as −F:
//!
//! m·ẍ = k·(x_a(t) − x) − c·ẋ + F_ext − F,  slip velocity v = ẋ − v_surface.
//!
//! The actuator point is prescribed: `x_a(t) = x_a0 + v_a·t` (the spring
//! pulled at constant speed of the 1995 stick-slip benchmark, the piezo ramp
//! of seed 000). F and F_ext vary linearly over a step (first-order input
//! interpolation). Integration: 2-stage Gauss–Legendre (order 4, A-stable),
//! sub-stepped so that ω·h_sub ≤ 0.02 (ω² = k/m + (c/2m)²), which makes the
//! error per natural period far below 1e-10 relative.
//!
//! m = 0 selects the quasi-static force balance of seed 000:
//! 0 = k·(x_a − x) − c·ẋ + F_ext − F; with c = 0 the position follows the
//! forces directly, x = x_a + (F_ext − F)/k (direct feedthrough from F).

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rig1DParams {
    pub m: f64,
    pub c: f64,
    pub k: f64,
    /// Actuator point at t = 0 and its speed.
    pub x_a0: f64,
    pub v_a: f64,
    /// Belt (surface) speed: the slip velocity is ẋ − v_surface.
    pub v_surface: f64,
    pub x0: f64,
    pub v0: f64,
}

impl Default for Rig1DParams {
    /// The 1995 stick-slip benchmark: m = 1 kg, k = 2 N/m, pulled at 0.1 m/s.
    fn default() -> Self {
        Rig1DParams {
            m: 1.0,
            c: 0.0,
            k: 2.0,
            x_a0: 0.0,
            v_a: 0.1,
            v_surface: 0.0,
            x0: 0.0,
            v0: 0.0,
        }
    }
}

impl Rig1DParams {
    pub fn validate(&self) -> Result<(), String> {
        let named = [
            ("m", self.m),
            ("c", self.c),
            ("k", self.k),
            ("x_a0", self.x_a0),
            ("v_a", self.v_a),
            ("v_surface", self.v_surface),
            ("x0", self.x0),
            ("v0", self.v0),
        ];
        for (name, value) in named {
            if !value.is_finite() {
                return Err(format!(
                    "invalid parameter {name} = {value}: must be finite"
                ));
            }
        }
        for (name, value) in [("m", self.m), ("c", self.c), ("k", self.k)] {
            if value < 0.0 {
                return Err(format!("invalid parameter {name} = {value}: must be >= 0"));
            }
        }
        if self.m == 0.0 && self.k == 0.0 && self.c == 0.0 {
            return Err(
                "invalid parameters m = 0, k = 0, c = 0: a massless rig needs a spring or a damper"
                    .into(),
            );
        }
        Ok(())
    }
}

#[derive(Clone, Debug)]
pub struct Rig1D {
    p: Rig1DParams,
    /// Time since the start (the actuator law depends on it).
    t: f64,
    x: f64,
    xd: f64,
}

impl Rig1D {
    pub fn new(p: Rig1DParams) -> Result<Self, String> {
        p.validate()?;
        Ok(Rig1D {
            p,
            t: 0.0,
            x: p.x0,
            xd: p.v0,
        })
    }

    pub fn params(&self) -> &Rig1DParams {
        &self.p
    }

    pub fn actuator_position(&self, t: f64) -> f64 {
        self.p.x_a0 + self.p.v_a * t
    }

    /// Position; in the quasi-static mode with c = 0 it follows the forces.
    pub fn position(&self, friction: f64, f_ext: f64) -> f64 {
        if self.p.m == 0.0 && self.p.c == 0.0 {
            self.actuator_position(self.t) + (f_ext - friction) / self.p.k
        } else {
            self.x
        }
    }

    /// Body velocity ẋ (quasi-static with c = 0: the actuator speed plus the
    /// rate of the force balance, which needs force rates: `df`, `dfe`).
    pub fn velocity(&self, friction_rate: f64, f_ext_rate: f64) -> f64 {
        if self.p.m == 0.0 && self.p.c == 0.0 {
            self.p.v_a + (f_ext_rate - friction_rate) / self.p.k
        } else {
            self.xd
        }
    }

    pub fn slip_velocity(&self, friction_rate: f64, f_ext_rate: f64) -> f64 {
        self.velocity(friction_rate, f_ext_rate) - self.p.v_surface
    }

    /// Spring force on the body, k·(x_a − x).
    pub fn spring_force(&self, friction: f64, f_ext: f64) -> f64 {
        self.p.k * (self.actuator_position(self.t) - self.position(friction, f_ext))
    }

    pub fn acceleration(&self, friction: f64, f_ext: f64) -> f64 {
        if self.p.m == 0.0 {
            return 0.0;
        }
        (self.spring_force(friction, f_ext) - self.p.c * self.xd + f_ext - friction) / self.p.m
    }

    pub fn time(&self) -> f64 {
        self.t
    }

    /// Advance by `h` with friction F(τ) = f0 + df·τ and F_ext(τ) = e0 + de·τ.
    pub fn step(&mut self, f0: f64, df: f64, e0: f64, de: f64, h: f64) {
        let p = self.p;
        if p.m == 0.0 {
            if p.c == 0.0 {
                // pure force balance: nothing to integrate
            } else {
                // c·ẋ = k(x_a − x) + F_ext − F: linear first order, exact
                // integration by sub-stepped Gauss–Legendre as below.
                self.integrate(
                    h,
                    |t, x, _xd, tau| {
                        let rhs =
                            p.k * (p.x_a0 + p.v_a * t - x) + (e0 + de * tau) - (f0 + df * tau);
                        (rhs / p.c, 0.0)
                    },
                    true,
                );
            }
            self.t += h;
            return;
        }
        self.integrate(
            h,
            |t, x, xd, tau| {
                let force =
                    p.k * (p.x_a0 + p.v_a * t - x) - p.c * xd + (e0 + de * tau) - (f0 + df * tau);
                (xd, force / p.m)
            },
            false,
        );
        self.t += h;
    }

    /// Gauss–Legendre 2-stage on (x, ẋ) for a linear right-hand side `f`,
    /// solved exactly (the stage equations are linear: solved by a fixed
    /// number of Newton-free iterations would lose A-stability, so we solve
    /// the 4×4 stage system directly from the linear map's columns).
    fn integrate(
        &mut self,
        h: f64,
        f: impl Fn(f64, f64, f64, f64) -> (f64, f64),
        first_order: bool,
    ) {
        let p = self.p;
        let omega = if first_order {
            p.k / p.c.max(f64::MIN_POSITIVE)
        } else {
            (p.k / p.m + (p.c / (2.0 * p.m)).powi(2)).sqrt() + p.c / (2.0 * p.m)
        };
        let n = ((omega * h / 0.02).ceil() as usize).clamp(1, 1_000_000);
        let hs = h / n as f64;
        let s3 = 3f64.sqrt() / 6.0;
        let (c1, c2) = (0.5 - s3, 0.5 + s3);
        let a = [[0.25, 0.25 - s3], [0.25 + s3, 0.25]];
        for i in 0..n {
            let tau0 = i as f64 * hs;
            let t0 = self.t + tau0;
            let (x, xd) = (self.x, self.xd);
            // Stage derivatives K = (k1x, k1v, k2x, k2v) solve K = f(stage(K)):
            // f is affine in the stage values, so K = b + M·K; build b and M
            // by evaluating f, then solve (I − M)K = b.
            let stage = |kv: &[f64; 4], j: usize| -> (f64, f64) {
                let sx = x + hs * (a[j][0] * kv[0] + a[j][1] * kv[2]);
                let sv = xd + hs * (a[j][0] * kv[1] + a[j][1] * kv[3]);
                let cj = if j == 0 { c1 } else { c2 };
                f(t0 + cj * hs, sx, sv, tau0 + cj * hs)
            };
            let eval = |kv: &[f64; 4]| -> [f64; 4] {
                let (a0, a1) = stage(kv, 0);
                let (b0, b1) = stage(kv, 1);
                [a0, a1, b0, b1]
            };
            let b = eval(&[0.0; 4]);
            let mut m = [[0.0; 4]; 4];
            for col in 0..4 {
                let mut e = [0.0; 4];
                e[col] = 1.0;
                let fe = eval(&e);
                for row in 0..4 {
                    m[row][col] = fe[row] - b[row];
                }
            }
            let mut lhs = [[0.0; 4]; 4];
            for r in 0..4 {
                for c in 0..4 {
                    lhs[r][c] = if r == c { 1.0 } else { 0.0 } - m[r][c];
                }
            }
            let kv = solve4(lhs, b);
            self.x = x + hs * 0.5 * (kv[0] + kv[2]);
            self.xd = if first_order {
                0.5 * (kv[0] + kv[2])
            } else {
                xd + hs * 0.5 * (kv[1] + kv[3])
            };
        }
    }

    pub fn state_to_vec(&self) -> Vec<f64> {
        vec![self.t, self.x, self.xd]
    }

    pub fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
        match s {
            [t, x, xd] if t.is_finite() && x.is_finite() && xd.is_finite() => {
                (self.t, self.x, self.xd) = (*t, *x, *xd);
                Ok(())
            }
            _ => Err(format!("Rig1D state must be 3 finite numbers, got {s:?}")),
        }
    }
}

/// Gaussian elimination with partial pivoting for a 4×4 system.
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> [f64; 4] {
    for col in 0..4 {
        let pivot = (col..4)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..4 {
            let f = a[row][col] / a[col][col];
            let pivot_row = a[col];
            for (target, source) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *target -= f * source;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 4];
    for row in (0..4).rev() {
        let s: f64 = (row + 1..4).map(|c| a[row][c] * x[c]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Free damped oscillator from x0, no friction, actuator at rest:
    /// x(t) = e^(−ζωn t)(x0 cos ωd t + (ζωn x0/ωd) sin ωd t).
    #[test]
    fn damped_oscillator_matches_the_closed_form() {
        let p = Rig1DParams {
            m: 0.5,
            c: 0.3,
            k: 20.0,
            x_a0: 0.0,
            v_a: 0.0,
            x0: 0.01,
            ..Default::default()
        };
        let wn = (p.k / p.m).sqrt();
        let zeta = p.c / (2.0 * (p.k * p.m).sqrt());
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        for h in [1e-4f64, 1e-3, 1e-2, 0.1] {
            let mut rig = Rig1D::new(p).unwrap();
            let n = (5.0 / h).round() as usize;
            let mut worst: f64 = 0.0;
            for i in 1..=n {
                rig.step(0.0, 0.0, 0.0, 0.0, h);
                let t = i as f64 * h;
                let exact = (-zeta * wn * t).exp()
                    * (p.x0 * (wd * t).cos() + zeta * wn * p.x0 / wd * (wd * t).sin());
                worst = worst.max((rig.position(0.0, 0.0) - exact).abs());
            }
            assert!(worst <= 1e-8 * p.x0, "h = {h}: worst error {worst:e}");
        }
    }

    /// Spring pulled at constant speed, no friction, from rest:
    /// x(t) = v_a·(t − sin(ωt)/ω).
    #[test]
    fn ramp_response_matches_the_closed_form() {
        let p = Rig1DParams::default();
        let w = (p.k / p.m).sqrt();
        let mut rig = Rig1D::new(p).unwrap();
        let h = 1e-3;
        for i in 1..=10_000 {
            rig.step(0.0, 0.0, 0.0, 0.0, h);
            let t = i as f64 * h;
            let exact = p.v_a * (t - (w * t).sin() / w);
            assert!(
                (rig.position(0.0, 0.0) - exact).abs() <= 1e-8 * exact.abs().max(1e-3),
                "t = {t}"
            );
        }
    }

    #[test]
    fn quasi_static_force_balance_and_validation() {
        let p = Rig1DParams {
            m: 0.0,
            c: 0.0,
            k: 116.04e3,
            v_a: 8.25e-8,
            ..Default::default()
        };
        let mut rig = Rig1D::new(p).unwrap();
        rig.step(0.0, 0.0, 0.0, 0.0, 1.0);
        assert_eq!(rig.position(0.1, 0.0), 8.25e-8 - 0.1 / 116.04e3);
        let bad = Rig1DParams {
            m: -1.0,
            ..Default::default()
        };
        assert!(Rig1D::new(bad).unwrap_err().contains("m = -1"));
    }
}
