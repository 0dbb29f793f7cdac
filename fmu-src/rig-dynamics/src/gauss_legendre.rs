//! The 2-stage Gauss–Legendre Runge–Kutta method (order 4, A-stable,
//! symplectic) for the rigs' affine second-order systems in (x, ẋ).

const S3: f64 = 0.288_675_134_594_812_87; // √3/6 (the f64 nearest)
/// Stage nodes c₁, c₂ = 1/2 ∓ √3/6.
pub(crate) const C: [f64; 2] = [0.5 - S3, 0.5 + S3];
/// Butcher matrix a_ij.
#[cfg(test)]
const A: [[f64; 2]; 2] = [[0.25, 0.25 - S3], [0.25 + S3, 0.25]];

/// Stage derivatives K = (k1x, k1v, k2x, k2v) of one step of length `hs`
/// from (x, ẋ), for a right-hand side `f(j, x, ẋ)` at stage j (its
/// time-dependent part is the caller's, evaluated at t₀ + c_j·hs). `f` must
/// be affine in (x, ẋ): then the stage equations K = f(stages(K)) are
/// linear, K = b + M·K; b and M are built by evaluating f, and (I − M)K = b
/// is solved directly (no fixed-point iteration, which would lose
/// A-stability). The new state is x + hs·(K₀ + K₂)/2, ẋ + hs·(K₁ + K₃)/2.
#[cfg(test)]
pub(crate) fn stage_derivatives(
    x: f64,
    xd: f64,
    hs: f64,
    f: impl Fn(usize, f64, f64) -> (f64, f64),
) -> [f64; 4] {
    let stage = |kv: &[f64; 4], j: usize| -> (f64, f64) {
        let sx = x + hs * (A[j][0] * kv[0] + A[j][1] * kv[2]);
        let sv = xd + hs * (A[j][0] * kv[1] + A[j][1] * kv[3]);
        f(j, sx, sv)
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
    solve4(lhs, b)
}

/// `(K₀ + K₂, K₁ + K₃)`, the sums the new state takes from
/// [`stage_derivatives`], in closed form for a right-hand side whose linear
/// part is known, `f(j, x, ẋ) = L·(x, ẋ) + c_j` (the rigs between events),
/// from `b = (f(0, x, ẋ), f(1, x, ẋ))`, the right-hand side at the start
/// state, which is also what [`stage_derivatives`] starts from.
///
/// With `P = hs·L` the stage equations are `K¹ = b¹ + P(a₁₁K¹ + a₁₂K²)`,
/// `K² = b² + P(a₂₁K¹ + a₂₂K²)`. For Gauss–Legendre `a₁₁ = a₂₂ = 1/4`,
/// `a₂₁ − 1/4 = 1/4 − a₁₂ = √3/6`, so the sum `S = K¹ + K²` and the
/// difference `D = K¹ − K²` satisfy `S − P·S/2 − (√3/6)·P·D = b¹ + b²` and
/// `D + (√3/6)·P·S = b¹ − b²`; eliminating `D`:
///
/// ```text
/// (I − P/2 + P²/12)·S = (b¹ + b²) + (√3/6)·P·(b¹ − b²),
/// ```
///
/// a 2×2 system (`I − P/2 + P²/12` is the denominator of the method's
/// stability function, regular for every `P` whose eigenvalues have no
/// positive real part). The same method as [`stage_derivatives`]; the
/// arithmetic differs by rounding.
#[inline]
pub(crate) fn linear_stage_sums(hs: f64, l: [[f64; 2]; 2], b: [f64; 4]) -> [f64; 2] {
    StageSolver::new(hs, l).sums(b)
}

/// [`linear_stage_sums`] for one step length `hs` and linear part `L`,
/// for many right-hand sides: `P = hs·L` and the matrix
/// `Q = I − P/2 + P²/12` with its determinant are formed once, and each
/// [`StageSolver::sums`] does the rest, operation for operation as
/// [`linear_stage_sums`] does it (the results are the same to the bit).
/// The rigs step with the same `hs` and `L` step after step, so forming
/// `Q` was most of a step's arithmetic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StageSolver {
    /// The step length the solver was formed for.
    pub(crate) hs: f64,
    p: [[f64; 2]; 2],
    q: [[f64; 2]; 2],
    det: f64,
}

impl StageSolver {
    #[inline]
    pub(crate) fn new(hs: f64, l: [[f64; 2]; 2]) -> Self {
        let p = [[hs * l[0][0], hs * l[0][1]], [hs * l[1][0], hs * l[1][1]]];
        let p2 = [
            [
                p[0][0] * p[0][0] + p[0][1] * p[1][0],
                p[0][0] * p[0][1] + p[0][1] * p[1][1],
            ],
            [
                p[1][0] * p[0][0] + p[1][1] * p[1][0],
                p[1][0] * p[0][1] + p[1][1] * p[1][1],
            ],
        ];
        const TWELFTH: f64 = 1.0 / 12.0;
        let q = [
            [
                1.0 - 0.5 * p[0][0] + TWELFTH * p2[0][0],
                -0.5 * p[0][1] + TWELFTH * p2[0][1],
            ],
            [
                -0.5 * p[1][0] + TWELFTH * p2[1][0],
                1.0 - 0.5 * p[1][1] + TWELFTH * p2[1][1],
            ],
        ];
        let det = q[0][0] * q[1][1] - q[0][1] * q[1][0];
        StageSolver { hs, p, q, det }
    }

    /// The stage sums `S` for the right-hand sides `b = (b¹, b²)`:
    /// `Q·S = (b¹ + b²) + (√3/6)·P·(b¹ − b²)` by Cramer's rule.
    #[inline]
    pub(crate) fn sums(&self, b: [f64; 4]) -> [f64; 2] {
        let (p, q, det) = (&self.p, &self.q, self.det);
        let (sum, diff) = ([b[0] + b[2], b[1] + b[3]], [b[0] - b[2], b[1] - b[3]]);
        let r = [
            sum[0] + S3 * (p[0][0] * diff[0] + p[0][1] * diff[1]),
            sum[1] + S3 * (p[1][0] * diff[0] + p[1][1] * diff[1]),
        ];
        [
            (q[1][1] * r[0] - q[0][1] * r[1]) / det,
            (q[0][0] * r[1] - q[1][0] * r[0]) / det,
        ]
    }
}

/// Gaussian elimination with partial pivoting for a 4×4 system.
#[cfg(test)]
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> [f64; 4] {
    for col in 0..4 {
        let pivot = (col..4)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
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

    /// The stage equations `(I − M)·K = b` as one 4×4 system with `M`
    /// built from `L` (stage j's state is `(x, ẋ) + hs·Σ_i a_ji·K^i`).
    fn stage_solve(hs: f64, l: [[f64; 2]; 2], b: [f64; 4]) -> [f64; 4] {
        let mut lhs = [[0.0; 4]; 4];
        for j in 0..2 {
            for i in 0..2 {
                for (r, row) in l.iter().enumerate() {
                    lhs[2 * j + r][2 * i] = -hs * A[j][i] * row[0];
                    lhs[2 * j + r][2 * i + 1] = -hs * A[j][i] * row[1];
                }
            }
        }
        for (k, row) in lhs.iter_mut().enumerate() {
            row[k] += 1.0;
        }
        solve4(lhs, b)
    }

    /// The closed form against the stage equations solved in rational
    /// arithmetic (`(K₀ + K₂, K₁ + K₃)`, rounded once to f64; Python's
    /// `fractions` on the same f64 inputs), for linear parts from a slow
    /// oscillator to stiff damping and a first-order lag, at small and large
    /// steps; against the 4×4 solve, to its rounding, which grows with
    /// `hs·‖L‖` (in the stiff cases the closed form is the more exact); and
    /// against [`stage_derivatives`], which differences `f` for `M`, to the
    /// digits that differencing leaves.
    #[test]
    fn closed_form_sums_match_the_stage_solve() {
        let parts = [
            [[0.0, 1.0], [-2.0, 0.0]],
            [[0.0, 1.0], [-40.0, -0.6]],
            [[0.0, 1.0], [-8.5e6, -3.2e3]],
            [[-2.0e3, 0.0], [0.0, 0.0]],
        ];
        let exact: [[[f64; 2]; 4]; 4] = [
            [
                [-1.650002543374762, -2.199997628309987],
                [-1.6502543284581936, -2.1997628094497768],
                [-1.6753420089431155, -2.176065969311854],
                [-2.314059995293575, -1.308909289813013],
            ],
            [
                [-1.650012923354727, -22.959944812048498],
                [-1.6512921280640271, -22.9544795283818],
                [-1.7770953290200875, -22.391449986148572],
                [-2.9736896515208815, 0.00925531280001366],
            ],
            [
                [-4.191844245344577, -5080969.814923835],
                [-229.3740495812536, -4293022.2606168175],
                [-25.33818991499473, 55929.93777327984],
                [-0.024586118190009873, 64.98647872450648],
            ],
            [
                [-1197.0518274674203, -1.0],
                [-1085.9617805586265, -1.0],
                [-26.865408758687135, -1.0],
                [-0.03239971119942875, -1.0],
            ],
        ];
        for (l, exact) in parts.into_iter().zip(exact) {
            for (hs, exact) in [1e-6, 1e-4, 1e-2, 0.3].into_iter().zip(exact) {
                let (x, xd) = (0.3, -1.7);
                let c = [[0.25, -3.0], [1.5, 2.0]];
                let f = |j: usize, sx: f64, sv: f64| {
                    (
                        l[0][0] * sx + l[0][1] * sv + c[j][0],
                        l[1][0] * sx + l[1][1] * sv + c[j][1],
                    )
                };
                let ((a0, a1), (b0, b1)) = (f(0, x, xd), f(1, x, xd));
                let b = [a0, a1, b0, b1];
                let sums = linear_stage_sums(hs, l, b);
                let k = stage_solve(hs, l, b);
                let differenced = stage_derivatives(x, xd, hs, f);
                let norm = l.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
                let rhs = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (r, got) in sums.iter().enumerate() {
                    // rounding of the result, and of the sum of terms of the
                    // right-hand side's size where the result cancels
                    let tolerance = 4.0 * f64::EPSILON * exact[r].abs().max(rhs);
                    assert!(
                        (got - exact[r]).abs() <= tolerance,
                        "L {l:?} hs {hs}: {got} vs {} exactly",
                        exact[r]
                    );
                    // the 4×4 solve's rounding: of its largest unknown,
                    // times the conditioning of I − M
                    let want = k[r] + k[r + 2];
                    let largest = k.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                    let scale = largest * (1.0 + hs * norm);
                    assert!(
                        (got - want).abs() <= 1e-14 * scale,
                        "L {l:?} hs {hs}: {got} vs {want}"
                    );
                    let rough = differenced[r] + differenced[r + 2];
                    assert!(
                        (got - rough).abs() <= 1e-9 * (want.abs() + 1.0),
                        "L {l:?} hs {hs}: {got} vs {rough} (differenced)"
                    );
                }
            }
        }
    }
}
