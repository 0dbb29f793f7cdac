//! Prescribed signals of the rigs: sinusoids a·sin(2π f t) for the actuator
//! (the imposed displacement of Dion et al. 2013, a piezo), the drive force
//! (the 1 Hz sine drive of Thimmalapura 2004), the surface dither (Wijata et
//! al. 2016: d = A·sin(ωt)) and the controller's velocity reference (Sun et
//! al. 2016: v = ±1e-3·sin(t/k) m/s).

use std::f64::consts::PI;

/// `amp·sin(2π·freq·t)`; amplitude 0 switches it off (its value is then an
/// exact 0.0, so adding an inactive sinusoid changes no bit).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sinusoid {
    pub amp: f64,
    /// Frequency in Hz (ω = 2π·freq).
    pub freq: f64,
}

impl Sinusoid {
    pub const OFF: Sinusoid = Sinusoid {
        amp: 0.0,
        freq: 0.0,
    };

    pub fn new(amp: f64, freq: f64) -> Self {
        Sinusoid { amp, freq }
    }

    pub fn omega(&self) -> f64 {
        2.0 * PI * self.freq
    }

    pub fn is_active(&self) -> bool {
        self.amp != 0.0
    }

    /// Angular frequency when active, else 0 (for the sub-step rule).
    pub fn active_omega(&self) -> f64 {
        if self.is_active() {
            self.omega()
        } else {
            0.0
        }
    }

    /// s(t) = amp·sin(ωt).
    pub fn value(&self, t: f64) -> f64 {
        if self.is_active() {
            self.amp * (self.omega() * t).sin()
        } else {
            0.0
        }
    }

    /// ds/dt = amp·ω·cos(ωt).
    pub fn rate(&self, t: f64) -> f64 {
        if self.is_active() {
            let w = self.omega();
            self.amp * w * (w * t).cos()
        } else {
            0.0
        }
    }

    /// d²s/dt² = −amp·ω²·sin(ωt).
    pub fn acceleration(&self, t: f64) -> f64 {
        if self.is_active() {
            let w = self.omega();
            -self.amp * w * w * (w * t).sin()
        } else {
            0.0
        }
    }

    /// ∫₀ᵗ s dτ = (amp/ω)·(1 − cos ωt) = (2·amp/ω)·sin²(ωt/2) (the second
    /// form keeps its precision for small ωt); 0 when ω = 0.
    pub fn integral(&self, t: f64) -> f64 {
        let w = self.omega();
        if self.is_active() && w != 0.0 {
            let s = (0.5 * w * t).sin();
            2.0 * self.amp / w * s * s
        } else {
            0.0
        }
    }

    /// Finite amplitude, finite non-negative frequency; the error names
    /// `<prefix>_amp` / `<prefix>_freq`.
    pub fn validate(&self, amp_name: &str, freq_name: &str) -> Result<(), String> {
        crate::check_finite(amp_name, self.amp)?;
        crate::check_non_negative(freq_name, self.freq)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_and_integral_are_consistent() {
        let s = Sinusoid::new(0.3, 1.7);
        let (t, d) = (0.37, 1e-6);
        let num_rate = (s.value(t + d) - s.value(t - d)) / (2.0 * d);
        assert!((num_rate - s.rate(t)).abs() < 1e-8);
        let num_acc = (s.rate(t + d) - s.rate(t - d)) / (2.0 * d);
        assert!((num_acc - s.acceleration(t)).abs() < 1e-6);
        let num_int = (s.integral(t + d) - s.integral(t - d)) / (2.0 * d);
        assert!((num_int - s.value(t)).abs() < 1e-8);
        assert_eq!(Sinusoid::OFF.value(1.0).to_bits(), 0.0f64.to_bits());
        assert_eq!(Sinusoid::new(1.0, 0.0).integral(3.0), 0.0);
    }
}
