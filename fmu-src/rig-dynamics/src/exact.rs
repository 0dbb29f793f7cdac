//! The exact step of the rigs' linear second-order systems under a forcing
//! that is a polynomial of degree two or less in time over the step.
//!
//! Between events a rig is `y' = L·y + e₂·g(s)`, `y = (x, ẋ)`, with a
//! linear part `L` fixed by the parameters and a forcing `g` (an
//! acceleration) that, with the inputs linear over the step and the
//! prescribed signals ramps and steps, is a polynomial of degree ≤ 2 in the
//! time `s` since the start of the step (degree 2: the controller's
//! integral of a ramped velocity reference). Variation of constants gives
//! the state after a step of length `h`:
//!
//! ```text
//! y(h) = e^{hL}·y(0) + ∫₀ʰ e^{(h−s)L}·e₂·g(s) ds
//!      = e^{hL}·y(0) + Σ_k g_k·k!·h^{k+1}·φ_{k+1}(hL)·e₂,   g(s) = Σ_k g_k·s^k,
//! ```
//!
//! with `φ₁(Z) = (e^Z − I)·Z⁻¹`, `φ_{k+1}(Z) = (φ_k(Z) − I/k!)·Z⁻¹` (the
//! φ-functions of exponential integrators; Hochbruck and Ostermann 2010).
//! They come from one matrix exponential: for the 5×5 block matrix
//!
//! ```text
//! W = | hL  e₂  0  0 |        e^W = | e^{hL}  φ₁(hL)e₂  φ₂(hL)e₂  φ₃(hL)e₂ |
//!     | 0   0   1  0 |              | 0       1         1         1/2      |
//!     | 0   0   0  1 |              | …                                   |
//!     | 0   0   0  0 |
//! ```
//!
//! (Saad 1992; Sidje 1998), computed by nalgebra's scaling-and-squaring
//! Padé exponential. The forcing enters through its values at three
//! points of the step, the 3-point Gauss–Legendre nodes, all inside the
//! step (so a drive step at the step's end is not sampled) and the
//! best-conditioned: each sample's weight vector is the Lagrange basis
//! polynomial of its node integrated against `e^{(h−s)L}·e₂`. For `hL → 0`
//! the weights tend to `h·(5, 8, 5)/18·e₂`, the Gauss–Legendre quadrature
//! weights.
//!
//! The step is exact for any `h` (no sub-steps and no step-size limit: the
//! matrix exponential is the solution operator, stable whatever the
//! stiffness), to the rounding of `e^W` and of the sums.

use nalgebra::SMatrix;

/// The 3-point Gauss–Legendre nodes on [0, 1]: 1/2 ∓ √15/10 and 1/2.
pub(crate) const NODES: [f64; 3] = [
    0.5 - 0.387_298_334_620_741_7, // √15/10 (the f64 nearest)
    0.5,
    0.5 + 0.387_298_334_620_741_7,
];

/// Step lengths within this fraction of the length an [`ExactStep`] was
/// formed for are taken with it and a second-order correction
/// ([`ExactStep::advance`]): an importer's step lengths are differences of
/// communication times, `t_{n+1} − t_n`, which vary by the rounding of `t`
/// (a few 1e-12 of 1e-4 s at t = 20 s), and forming the step again for
/// each would cost a matrix exponential per step. The correction's error
/// is of the order of (δ/h)³ of the step's change, below 1e-18 of it.
const NEAR: f64 = 1e-6;

/// The exact step of `y' = L·y + e₂·g(s)` over one step length `h`, for
/// any `y(0)` and any quadratic `g` given by its samples at the
/// [`NODES`]: formed once per step length (a matrix exponential), applied
/// at every step (about twenty multiplications).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ExactStep {
    /// The step length it was formed for (NaN: not formed yet).
    pub(crate) h: f64,
    /// The linear part L.
    linear: [[f64; 2]; 2],
    /// The scale of the forcing samples (1/m).
    scale: f64,
    /// The transition matrix e^{hL}.
    transition: [[f64; 2]; 2],
    /// The weight vector of the forcing sample at each node.
    weights: [[f64; 2]; 3],
    /// The forcing at the end of the step from the samples, g(h) = Σ_j
    /// ℓ_j(1)·g_j (the Lagrange basis at σ = 1), times the scale.
    at_end: [f64; 3],
    /// Its rate there, g'(h) = Σ_j ℓ_j'(1)·g_j/h, times the scale.
    rate_at_end: [f64; 3],
}

/// The largest sum of `|h·L|` entries an exponential is formed for: its
/// tenth power stays finite (a rig beyond it, `h·k/m > 1e25`, has no
/// meaningful step).
const MAX_NORM: f64 = 1e25;

impl ExactStep {
    /// Not formed for any step length: [`ExactStep::h`] is NaN.
    pub(crate) const UNFORMED: ExactStep = ExactStep {
        h: f64::NAN,
        linear: [[0.0; 2]; 2],
        scale: 0.0,
        transition: [[0.0; 2]; 2],
        weights: [[0.0; 2]; 3],
        at_end: [0.0; 3],
        rate_at_end: [0.0; 3],
    };

    /// Formed for step length `h` and linear part `l`; the samples of
    /// the forcing will be scaled by `scale` (a `1/m` that turns a force
    /// into an acceleration, folded into the weights).
    pub(crate) fn new(h: f64, l: [[f64; 2]; 2], scale: f64) -> Self {
        let mut w = SMatrix::<f64, 5, 5>::zeros();
        for r in 0..2 {
            for c in 0..2 {
                w[(r, c)] = h * l[r][c];
            }
        }
        let norm: f64 = w.iter().map(|x| x.abs()).sum();
        if norm.is_nan() || norm > MAX_NORM {
            // h·L overflowed (e.g. k/m = 1e300/1e-300) or is so large
            // that the powers nalgebra's exponential estimates its scaling
            // from (up to the tenth) overflow: it would then square 2^64
            // times. The step comes out NaN, which the FMU layer refuses
            // as a non-finite state.
            return ExactStep {
                h,
                linear: l,
                scale,
                transition: [[f64::NAN; 2]; 2],
                weights: [[f64::NAN; 2]; 3],
                at_end: [f64::NAN; 3],
                rate_at_end: [f64::NAN; 3],
            };
        }
        w[(1, 2)] = 1.0;
        w[(2, 3)] = 1.0;
        w[(3, 4)] = 1.0;
        let e = w.exp();
        let transition = [[e[(0, 0)], e[(0, 1)]], [e[(1, 0)], e[(1, 1)]]];
        // φ_k(hL)·e₂ for k = 1, 2, 3
        let phi = [2, 3, 4].map(|c| [e[(0, c)], e[(1, c)]]);
        // The node's Lagrange basis polynomial in σ = s/h,
        // ℓ_j(σ) = a₀ + a₁σ + a₂σ², integrates to
        // h·(a₀·φ₁ + a₁·φ₂ + 2·a₂·φ₃)·e₂ (∫₀ʰ e^{(h−s)L} s^k ds = k!·h^{k+1}·φ_{k+1}(hL)).
        let basis: [[f64; 3]; 3] = std::array::from_fn(|j| {
            let (a, b) = match j {
                0 => (NODES[1], NODES[2]),
                1 => (NODES[0], NODES[2]),
                _ => (NODES[0], NODES[1]),
            };
            let d = (NODES[j] - a) * (NODES[j] - b);
            [a * b / d, -(a + b) / d, 1.0 / d]
        });
        let weights = basis.map(|[a0, a1, a2]| {
            let k = h * scale;
            [0, 1].map(|r| k * (a0 * phi[0][r] + a1 * phi[1][r] + 2.0 * a2 * phi[2][r]))
        });
        let at_end = basis.map(|[a0, a1, a2]| scale * (a0 + a1 + a2));
        let rate_at_end = basis.map(|[_, a1, a2]| scale * (a1 + 2.0 * a2) / h);
        ExactStep {
            h,
            linear: l,
            scale,
            transition,
            weights,
            at_end,
            rate_at_end,
        }
    }

    /// Whether a step of length `len` is taken with this one
    /// (within [`NEAR`] of its length; never when not formed).
    #[inline]
    pub(crate) fn covers(&self, len: f64) -> bool {
        (len - self.h).abs() <= NEAR * self.h
    }

    /// `y(len)` from `y(0) = y` and the forcing samples `g` (before the
    /// scale) at the nodes of this step's length `h` (at `NODES[j]·h`, not
    /// `·len`), for a `len` it [covers](ExactStep::covers): the exact step
    /// over `h`, then `y(len) = y(h) + δ·y'(h) + δ²/2·y''(h)`, `δ = len −
    /// h`, with `y' = L·y + e₂·g` and `y'' = L·y' + e₂·g'` at `h` (the
    /// error is of order δ³).
    #[inline]
    pub(crate) fn advance(&self, y: [f64; 2], g: [f64; 3], len: f64) -> [f64; 2] {
        let (t, w) = (&self.transition, &self.weights);
        let end = [0, 1].map(|r| {
            t[r][0] * y[0] + t[r][1] * y[1] + w[0][r] * g[0] + w[1][r] * g[1] + w[2][r] * g[2]
        });
        let (e, d) = (&self.at_end, &self.rate_at_end);
        let forcing = e[0] * g[0] + e[1] * g[1] + e[2] * g[2];
        let rate = d[0] * g[0] + d[1] * g[1] + d[2] * g[2];
        self.corrected(end, forcing, rate, len - self.h)
    }

    /// `y + δ·y' + δ²/2·y''` for `y' = L·y + e₂·g`, `y'' = L·y' + e₂·ġ`.
    #[inline]
    fn corrected(&self, y: [f64; 2], g: f64, rate: f64, delta: f64) -> [f64; 2] {
        let l = &self.linear;
        let d1 = [
            l[0][0] * y[0] + l[0][1] * y[1],
            l[1][0] * y[0] + l[1][1] * y[1] + g,
        ];
        let d2 = [
            l[0][0] * d1[0] + l[0][1] * d1[1],
            l[1][0] * d1[0] + l[1][1] * d1[1] + rate,
        ];
        let half = 0.5 * delta;
        [
            y[0] + delta * (d1[0] + half * d2[0]),
            y[1] + delta * (d1[1] + half * d2[1]),
        ]
    }

    /// `∂y(len)/∂u` of [`ExactStep::advance`] for a unit forcing `u`
    /// held over the step (every sample `g_j = u`; before the scale):
    /// the sum of the weights corrected as [`ExactStep::advance`] corrects
    /// (`Σ_j ℓ_j(1) = 1`, `Σ_j ℓ_j'(1) = 0`); for `len = h`,
    /// `h·φ₁(hL)·e₂` times the scale.
    pub(crate) fn held_response(&self, len: f64) -> [f64; 2] {
        let w = &self.weights;
        let sum = [0, 1].map(|r| w[0][r] + w[1][r] + w[2][r]);
        self.corrected(sum, self.scale, 0.0, len - self.h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear part that overflows (k/m = inf, or so large that its tenth
    /// power does) forms a NaN step at once (nalgebra's exponential would
    /// square 2^64 times).
    #[test]
    fn an_overflowing_linear_part_gives_nan_not_a_hang() {
        for k in [f64::INFINITY, 1e40, 1e300] {
            let step = ExactStep::new(1.0, [[0.0, 1.0], [-k, 0.0]], 1.0);
            let got = step.advance([0.3, 0.0], [0.0; 3], 1.0);
            assert!(got.iter().all(|x| x.is_nan()), "{got:?}");
        }
    }

    /// Linear parts from a slow undamped oscillator to stiff damping, a
    /// critically damped and a free mass, at small and large steps,
    /// against closed forms evaluated independently: the free mass
    /// (`L` nilpotent: polynomials), and for the others the solution of
    /// `ÿ + c·ẏ + k·y = g(s)` by its characteristic roots, with a forcing
    /// `g(s) = g₀ + g₁s + g₂s²` whose particular solution is a quadratic.
    #[test]
    fn step_matches_closed_forms() {
        // (k, c): ẍ = −k·x − c·ẋ + g
        let cases = [
            (0.0, 0.0),
            (2.0, 0.0),
            (40.0, 0.6),
            (1.0e4, 200.0), // critically damped
            (2.0e4, 1.0e3), // the controlled axis: roots −20.4, −979.6
            (8.5e6, 3.2e3), // stiff, underdamped
        ];
        let (g0, g1, g2) = (0.7, -3.0, 11.0);
        let g = |s: f64| g0 + g1 * s + g2 * s * s;
        let (x0, v0) = (0.3, -1.7);
        for (k, c) in cases {
            let l = [[0.0, 1.0], [-k, -c]];
            for h in [1e-6, 1e-4, 1e-2, 0.3] {
                let step = ExactStep::new(h, l, 1.0);
                let got = step.advance([x0, v0], NODES.map(|n| g(n * h)), h);
                let want = closed_form(k, c, (g0, g1, g2), (x0, v0), h);
                for r in 0..2 {
                    let scale = want[r].abs().max(1.0);
                    assert!(
                        (got[r] - want[r]).abs() <= 1e-13 * scale,
                        "k {k} c {c} h {h}: {got:?} vs {want:?}"
                    );
                }
            }
        }
    }

    /// ẍ + c·ẋ + k·x = g₀ + g₁s + g₂s² from (x0, v0), at s = h.
    fn closed_form(k: f64, c: f64, g: (f64, f64, f64), y0: (f64, f64), h: f64) -> [f64; 2] {
        let (g0, g1, g2) = g;
        let (x0, v0) = y0;
        if k == 0.0 && c == 0.0 {
            // integrate the polynomial twice
            let x = x0 + v0 * h + g0 * h * h / 2.0 + g1 * h.powi(3) / 6.0 + g2 * h.powi(4) / 12.0;
            let v = v0 + g0 * h + g1 * h * h / 2.0 + g2 * h.powi(3) / 3.0;
            return [x, v];
        }
        // particular solution p(s) = p0 + p1 s + p2 s²: k·p2 = g2,
        // k·p1 + 2c·p2 = g1, k·p0 + c·p1 + 2·p2 = g0
        let p2 = g2 / k;
        let p1 = (g1 - 2.0 * c * p2) / k;
        let p0 = (g0 - c * p1 - 2.0 * p2) / k;
        let (p, dp) = (p0 + p1 * h + p2 * h * h, p1 + 2.0 * p2 * h);
        // homogeneous part from (x0 − p0, v0 − p1)
        let (a, b) = (x0 - p0, v0 - p1);
        let disc = c * c / 4.0 - k;
        let (x, v) = if disc.abs() <= 1e-12 * k {
            // double root r = −c/2
            let r = -c / 2.0;
            let e = (r * h).exp();
            let (c1, c2) = (a, b - r * a);
            (e * (c1 + c2 * h), e * (r * (c1 + c2 * h) + c2))
        } else if disc > 0.0 {
            let s = disc.sqrt();
            let (r1, r2) = (-c / 2.0 + s, -c / 2.0 - s);
            let c2 = (b - r1 * a) / (r2 - r1);
            let c1 = a - c2;
            let (e1, e2) = ((r1 * h).exp(), (r2 * h).exp());
            (c1 * e1 + c2 * e2, c1 * r1 * e1 + c2 * r2 * e2)
        } else {
            let (sigma, w) = (-c / 2.0, (-disc).sqrt());
            let e = (sigma * h).exp();
            let (cs, sn) = ((w * h).cos(), (w * h).sin());
            let c2 = (b - sigma * a) / w;
            (
                e * (a * cs + c2 * sn),
                e * (sigma * (a * cs + c2 * sn) + w * (-a * sn + c2 * cs)),
            )
        };
        [x + p, v + dp]
    }

    /// A step of a length near the formed one (the rounding of
    /// communication times, and up to [`NEAR`]) with the second-order
    /// correction equals the step formed for that length, to 1e-13 of the
    /// state and of the held response; a length further off is not covered,
    /// nor any by an unformed step.
    #[test]
    fn near_lengths_are_corrected_to_the_exact_step() {
        let g = |s: f64| 0.4 - 2.0 * s + 30.0 * s * s;
        for (l, h) in [
            ([[0.0, 1.0], [-2.0, 0.0]], 1e-4),
            ([[0.0, 1.0], [-2.0e4, -1.0e3]], 1e-3),
            ([[0.0, 1.0], [-8.5e6, -3.2e3]], 1e-4),
        ] {
            let formed = ExactStep::new(h, l, 0.5);
            for len in [h * (1.0 + 3e-12), h * (1.0 - 7e-10), h * (1.0 + 0.9e-6)] {
                assert!(formed.covers(len));
                let own = ExactStep::new(len, l, 0.5);
                let y = [0.3, -1.7];
                let got = formed.advance(y, NODES.map(|n| g(n * h)), len);
                let want = own.advance(y, NODES.map(|n| g(n * len)), len);
                let (hg, hw) = (formed.held_response(len), own.held_response(len));
                for r in 0..2 {
                    assert!(
                        (got[r] - want[r]).abs() <= 1e-13 * want[r].abs().max(1.0),
                        "{l:?} {len}: {got:?} vs {want:?}"
                    );
                    assert!(
                        (hg[r] - hw[r]).abs() <= 1e-13 * hw[r].abs(),
                        "{l:?} {len}: {hg:?} vs {hw:?}"
                    );
                }
            }
            assert!(!formed.covers(h * (1.0 + 2e-6)));
            assert!(!formed.covers(h * 0.5));
            assert!(!ExactStep::UNFORMED.covers(h));
        }
    }

    /// For a small `hL` the weights are the 3-point Gauss–Legendre
    /// quadrature weights `h·(5, 8, 5)/18` on the velocity, and the held
    /// response is `(h²/2, h)`.
    #[test]
    fn small_steps_weigh_the_samples_as_gauss_legendre() {
        let h = 1e-7;
        let step = ExactStep::new(h, [[0.0, 1.0], [-2.0, 0.0]], 1.0);
        for (w, q) in step.weights.iter().zip([5.0, 8.0, 5.0]) {
            assert!((w[1] - h * q / 18.0).abs() <= 1e-12 * h, "{w:?}");
        }
        let held = step.held_response(h);
        assert!((held[0] - h * h / 2.0).abs() <= 1e-9 * h * h, "{held:?}");
        assert!((held[1] - h).abs() <= 1e-12 * h, "{held:?}");
    }
}
