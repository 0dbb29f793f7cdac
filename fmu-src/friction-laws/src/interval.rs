//! Splitting a step at the zero crossing of a ramped velocity.

use crate::Ramp;

/// The step `[0, h]` cut at the strict sign change of `v` (if any) into at
/// most two sub-intervals `(start, end)` on each of which `v` keeps one sign
/// (it may be zero at an end point). Returns the pieces and their count.
pub(crate) fn one_sign_pieces(v: Ramp, h: f64) -> ([(f64, f64); 2], usize) {
    let v0 = v.value;
    let v1 = v.at(h);
    if (v0 > 0.0 && v1 < 0.0) || (v0 < 0.0 && v1 > 0.0) {
        // slope is non-zero here because the signs differ.
        let tau = (-v0 / v.slope).clamp(0.0, h);
        ([(0.0, tau), (tau, h)], 2)
    } else {
        ([(0.0, h), (h, h)], 1)
    }
}

/// Displacement `∫ v dτ` over `[a, b]`, exact for a ramp (midpoint value ×
/// length).
pub(crate) fn displacement(v: Ramp, a: f64, b: f64) -> f64 {
    v.at(0.5 * (a + b)) * (b - a)
}

/// Sign of `v` on the one-sign interval `[a, b]` (taken at its midpoint):
/// `1`, `-1`, or `0` when `v` vanishes there.
pub(crate) fn sign_on(v: Ramp, a: f64, b: f64) -> f64 {
    let m = v.at(0.5 * (a + b));
    if m > 0.0 {
        1.0
    } else if m < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// For a rate-independent law: calls `advance(s, u)` with the direction
/// `s = ±1` and the exact distance `u = |Δx|` of each piece of `[0, h]` on
/// which `v` keeps one sign (none for a non-positive or NaN `h`, none for
/// a piece where `v` vanishes).
pub(crate) fn each_one_sign_displacement(v: Ramp, h: f64, mut advance: impl FnMut(f64, f64)) {
    if h.is_nan() || h <= 0.0 {
        return;
    }
    let (pieces, n) = one_sign_pieces(v, h);
    for &(a, b) in &pieces[..n] {
        let s = sign_on(v, a, b);
        if s != 0.0 {
            advance(s, displacement(v, a, b).abs());
        }
    }
}
