//! Figures of a stick-slip run, as docs/models.md ("Reference figures")
//! states them for the LuGre benchmark: the first time the
//! velocity exceeds 0.05 m/s (the first slip), the period (between the last
//! two such instants), and the peaks of the friction force and the
//! velocity.

/// Times at which `v` crosses `level` upward (`v[i−1] < level ≤ v[i]`),
/// interpolated linearly between samples.
pub fn upward_crossings(t: &[f64], v: &[f64], level: f64) -> Vec<f64> {
    (1..v.len().min(t.len()))
        .filter(|&i| v[i - 1] < level && v[i] >= level)
        .map(|i| {
            let s = (level - v[i - 1]) / (v[i] - v[i - 1]);
            t[i - 1] + s * (t[i] - t[i - 1])
        })
        .collect()
}

/// Largest value of `y` and its time, refined by the parabola through the
/// sample at the maximum and its two neighbours (equally spaced samples).
pub fn peak(t: &[f64], y: &[f64]) -> Option<(f64, f64)> {
    let n = y.len().min(t.len());
    let i = (0..n).max_by(|&a, &b| y[a].total_cmp(&y[b]))?;
    if i == 0 || i + 1 >= n {
        return Some((t[i], y[i]));
    }
    let (a, b, c) = (y[i - 1], y[i], y[i + 1]);
    let curvature = a - 2.0 * b + c;
    if curvature >= 0.0 {
        return Some((t[i], b));
    }
    // Vertex of the parabola through (−1, a), (0, b), (1, c).
    let s = 0.5 * (a - c) / curvature;
    let h = 0.5 * (t[i + 1] - t[i - 1]);
    Some((t[i] + s * h, b - 0.25 * (a - c) * s))
}

/// The stick-slip figures of one run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StickSlip {
    /// First upward crossing of the slip threshold (s).
    pub first_slip: f64,
    /// Time between the last two upward crossings (s).
    pub period: f64,
    /// Largest friction force (N) and largest velocity (m/s).
    pub peak_force: f64,
    pub peak_velocity: f64,
    /// Number of upward crossings.
    pub slips: usize,
}

/// The figures from sampled `t`, velocity and friction force; `None` with
/// fewer than two slips.
pub fn stick_slip(t: &[f64], v: &[f64], f: &[f64], threshold: f64) -> Option<StickSlip> {
    let c = upward_crossings(t, v, threshold);
    if c.len() < 2 {
        return None;
    }
    Some(StickSlip {
        first_slip: c[0],
        period: c[c.len() - 1] - c[c.len() - 2],
        peak_force: peak(t, f)?.1,
        peak_velocity: peak(t, v)?.1,
        slips: c.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossings_and_peaks_of_known_signals() {
        // v = sin(2πt) sampled at 1e-3: crossings of 0.5 upward at t = 1/12 + k.
        let t: Vec<f64> = (0..=3000).map(|i| i as f64 * 1e-3).collect();
        let v: Vec<f64> = t
            .iter()
            .map(|t| (2.0 * std::f64::consts::PI * t).sin())
            .collect();
        let c = upward_crossings(&t, &v, 0.5);
        assert_eq!(c.len(), 3);
        for (k, ck) in c.iter().enumerate() {
            assert!((ck - (1.0 / 12.0 + k as f64)).abs() < 1e-6, "{ck}");
        }
        // The parabola recovers the peak 1 at t = 0.25 between samples.
        let shifted: Vec<f64> = t.iter().map(|t| t + 3.7e-4).collect();
        let (tp, yp) = peak(&shifted[..1000], &v[..1000]).unwrap();
        assert!((yp - 1.0).abs() < 1e-9, "{yp}");
        assert!(((tp - 3.7e-4) - 0.25).abs() < 1e-6, "{tp}");
        let s = stick_slip(&t, &v, &v, 0.5).unwrap();
        assert_eq!(s.slips, 3);
        assert!((s.period - 1.0).abs() < 1e-6);
        assert!(stick_slip(&t[..500], &v[..500], &v[..500], 0.5).is_none());
        // A maximum at the end is taken as sampled.
        assert_eq!(peak(&[0.0, 1.0], &[1.0, 2.0]), Some((1.0, 2.0)));
        assert_eq!(peak(&[], &[]), None);
    }
}
