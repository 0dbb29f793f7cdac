//! The 2-stage Gauss–Legendre Runge–Kutta method (order 4, A-stable,
//! symplectic) for the rigs' affine second-order systems in (x, ẋ).

const S3: f64 = 0.288_675_134_594_812_87; // √3/6 (the f64 nearest)
/// Stage nodes c₁, c₂ = 1/2 ∓ √3/6.
pub(crate) const C: [f64; 2] = [0.5 - S3, 0.5 + S3];
/// Butcher matrix a_ij.
const A: [[f64; 2]; 2] = [[0.25, 0.25 - S3], [0.25 + S3, 0.25]];

/// Stage derivatives K = (k1x, k1v, k2x, k2v) of one step of length `hs`
/// from (x, ẋ), for a right-hand side `f(j, x, ẋ)` at stage j (its
/// time-dependent part is the caller's, evaluated at t₀ + c_j·hs). `f` must
/// be affine in (x, ẋ): then the stage equations K = f(stages(K)) are
/// linear, K = b + M·K; b and M are built by evaluating f, and (I − M)K = b
/// is solved directly (no fixed-point iteration, which would lose
/// A-stability). The new state is x + hs·(K₀ + K₂)/2, ẋ + hs·(K₁ + K₃)/2.
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

/// Gaussian elimination with partial pivoting for a 4×4 system.
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
