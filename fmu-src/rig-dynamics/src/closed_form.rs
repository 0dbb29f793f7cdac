//! Closed-form solutions of the linear rigs, for the tests: the
//! independent references the Gauss–Legendre integration is checked
//! against (nothing here shares code with it).

/// m·ẍ + c·ẋ + k·x = f0 + f1·t + a·sin(Ωt) + b·cos(Ωt), underdamped
/// (k > 0, c² < 4mk), from x(0) = x0, ẋ(0) = v0.
#[derive(Clone, Copy, Debug, Default)]
pub struct Forced {
    pub m: f64,
    pub c: f64,
    pub k: f64,
    pub f0: f64,
    pub f1: f64,
    pub a: f64,
    pub b: f64,
    pub omega: f64,
}

impl Forced {
    /// (x(t), ẋ(t)). Particular solution p0 + p1·t + A·sin Ωt + B·cos Ωt
    /// with k·p1 = f1, k·p0 + c·p1 = f0, and
    /// (k − mΩ²)·A − cΩ·B = a, cΩ·A + (k − mΩ²)·B = b; plus the free
    /// response e^(−σt)(C1 cos ωd t + C2 sin ωd t), σ = c/2m,
    /// ωd = √(k/m − σ²), fitted to the initial state.
    pub fn at(&self, x0: f64, v0: f64, t: f64) -> (f64, f64) {
        let (m, c, k, w) = (self.m, self.c, self.k, self.omega);
        let p1 = self.f1 / k;
        let p0 = (self.f0 - c * p1) / k;
        let q = k - m * w * w;
        let d = q * q + (c * w) * (c * w);
        let (ah, bh) = if d > 0.0 {
            (
                (q * self.a + c * w * self.b) / d,
                (q * self.b - c * w * self.a) / d,
            )
        } else {
            (0.0, 0.0)
        };
        let sigma = c / (2.0 * m);
        let wd = (k / m - sigma * sigma).sqrt();
        assert!(wd > 0.0, "closed form is for the underdamped case");
        let c1 = x0 - p0 - bh;
        let c2 = (v0 - p1 - ah * w + sigma * c1) / wd;
        let e = (-sigma * t).exp();
        let (s, co) = (wd * t).sin_cos();
        let x = e * (c1 * co + c2 * s) + p0 + p1 * t + ah * (w * t).sin() + bh * (w * t).cos();
        let xd = e * ((-sigma * c1 + wd * c2) * co + (-sigma * c2 - wd * c1) * s)
            + p1
            + ah * w * (w * t).cos()
            - bh * w * (w * t).sin();
        (x, xd)
    }
}

/// m·ẍ + c·ẋ = f (constant), c > 0, from (x0, v0): the free mass with a
/// damper under a constant force (a saturated controller, k = 0).
pub fn constant_force_on_damped_mass(
    m: f64,
    c: f64,
    f: f64,
    x0: f64,
    v0: f64,
    t: f64,
) -> (f64, f64) {
    let vinf = f / c;
    let e = (-c * t / m).exp();
    let x = x0 + vinf * t + (v0 - vinf) * (m / c) * (1.0 - e);
    (x, vinf + (v0 - vinf) * e)
}

/// Largest |a − b| over two equally long series.
pub fn worst(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Largest |a|.
pub fn peak(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, x| m.max(x.abs()))
}
