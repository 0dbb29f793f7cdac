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

/// The most sub-steps [`each_held_substep`] cuts a ramped velocity into.
const MAX_HELD_SUBSTEPS: usize = 1000;
/// The largest relative change of `|v| + vs` over one of its sub-steps.
const KAPPA_V: f64 = 1e-3;

/// For a law whose level depends on the velocity (scale `vs`): calls
/// `advance(s, t0, t1)` on sub-steps `[t0, t1]` of each piece of `[0, h]`
/// on which `v` keeps the sign `s = ±1`, short enough that `|v| + vs`
/// changes by at most 1e-3 of itself over each (at most 1000 a piece; one
/// for a held `v`), so that the velocity can be held at its mean over a
/// sub-step. None for a non-positive or NaN `h`, none where `v` vanishes.
pub(crate) fn each_held_substep(v: Ramp, h: f64, vs: f64, mut advance: impl FnMut(f64, f64, f64)) {
    if h.is_nan() || h <= 0.0 {
        return;
    }
    let (pieces, n) = one_sign_pieces(v, h);
    for &(a, b) in &pieces[..n] {
        let s = sign_on(v, a, b);
        if s == 0.0 {
            continue;
        }
        let mut count = 1;
        if v.slope != 0.0 {
            let least = v.at(a).abs().min(v.at(b).abs()) + vs;
            let change = v.slope.abs() * (b - a);
            count = ((change / (KAPPA_V * least)).ceil() as usize).clamp(1, MAX_HELD_SUBSTEPS);
        }
        let len = (b - a) / count as f64;
        for k in 0..count {
            let t0 = a + k as f64 * len;
            let t1 = if k + 1 == count { b } else { t0 + len };
            advance(s, t0, t1);
        }
    }
}
