//! Planar oscillator of Wijata et al. 2016 (docs/models.md, "Rig2D", and
//! "Two-dimensional bristle", the behaviours it reports): a mass m
//! on a surface, springs k1, k2 along the axes to a fixed anchor at the
//! origin, dampers c1, c2, the friction components applied as −F1, −F2:
//!
//! m·ẍ_i = −k_i·x_i − c_i·ẋ_i + F_ext,i − F_i,  i = 1, 2,
//!
//! over a surface moving at (vs1, vs2) with dither along either axis,
//! x_s,i(t) = vs_i·t + A_i·sin(2π f_i t) (Wijata et al.: d = A·sin(ωt),
//! along x2 in their simulations, along x1 on their rig). Slip velocity
//! v_i = ẋ_i − ẋ_s,i(t), relative displacement x_i − x_s,i(t).
//!
//! The axes are coupled only through the friction block (its F1, F2 depend
//! on both slip components), so each axis is a [`Rig1D`] with a fixed
//! actuator point at 0 and the same mass, in Rig1D's plain mode: its exact
//! step (the matrix exponential of the axis's linear part, the inputs
//! linear over the step), at any step length.
//!
//! Defaults: the oscillator of Wijata et al., m = 1 kg, k1 = k2 = 100 N/m,
//! x1(0) = x2(0) = 0.08 m, v1(0) = −0.8 m/s, v2(0) = 0.8 m/s.

use crate::rig1d::{Rig1D, Rig1DInputs, Rig1DParams};
use crate::signals::Sinusoid;
use crate::{check_finite, check_non_negative};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rig2DParams {
    pub m: f64,
    pub k: [f64; 2],
    pub c: [f64; 2],
    pub x0: [f64; 2],
    /// Initial body velocities ẋ_i(0).
    pub v0: [f64; 2],
    /// Surface velocity (vs1, vs2).
    pub v_surface: [f64; 2],
    /// Surface dither per axis.
    pub dither: [Sinusoid; 2],
}

impl Default for Rig2DParams {
    /// The planar oscillator of Wijata et al. 2016.
    fn default() -> Self {
        Rig2DParams {
            m: 1.0,
            k: [100.0, 100.0],
            c: [0.0, 0.0],
            x0: [0.08, 0.08],
            v0: [-0.8, 0.8],
            v_surface: [0.0, 0.0],
            dither: [Sinusoid::OFF, Sinusoid::OFF],
        }
    }
}

impl Rig2DParams {
    /// The error names the parameter as the FMU calls it, and its value.
    pub fn validate(&self) -> Result<(), String> {
        check_finite("m", self.m)?;
        if self.m <= 0.0 {
            return Err(format!(
                "invalid parameter m = {}: must be > 0 (the planar oscillator has no quasi-static mode)",
                self.m
            ));
        }
        for i in 0..2 {
            let n = i + 1;
            check_non_negative(&format!("k{n}"), self.k[i])?;
            check_non_negative(&format!("c{n}"), self.c[i])?;
            check_finite(&format!("x{n}_0"), self.x0[i])?;
            check_finite(&format!("v{n}_0"), self.v0[i])?;
            check_finite(&format!("vs{n}"), self.v_surface[i])?;
            self.dither[i].validate(&format!("dither_amp{n}"), &format!("dither_freq{n}"))?;
        }
        Ok(())
    }

    /// The 1-D rig of axis i: spring to a fixed point at 0.
    fn axis(&self, i: usize) -> Rig1DParams {
        Rig1DParams {
            m: self.m,
            c: self.c[i],
            k: self.k[i],
            x_a0: 0.0,
            v_a: 0.0,
            v_surface: self.v_surface[i],
            dither: self.dither[i],
            x0: self.x0[i],
            v0: self.v0[i],
            ..Rig1DParams::default()
        }
    }
}

/// Inputs of both axes at one instant (or their slopes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rig2DInputs {
    pub friction: [f64; 2],
    pub f_ext: [f64; 2],
}

impl Rig2DInputs {
    /// The inputs of axis i as a 1-D rig sees them.
    pub fn axis(&self, i: usize) -> Rig1DInputs {
        Rig1DInputs {
            friction: self.friction[i],
            f_ext: self.f_ext[i],
            ..Rig1DInputs::default()
        }
    }
}

#[derive(Clone, Debug)]
pub struct Rig2D {
    p: Rig2DParams,
    axes: [Rig1D; 2],
}

impl Rig2D {
    pub fn new(p: Rig2DParams) -> Result<Self, String> {
        p.validate()?;
        Ok(Rig2D {
            p,
            axes: [Rig1D::new(p.axis(0))?, Rig1D::new(p.axis(1))?],
        })
    }

    pub fn params(&self) -> &Rig2DParams {
        &self.p
    }

    /// Axis i (0 or 1) as a 1-D rig: position, slip velocity, relative
    /// displacement, acceleration (with `Rig2DInputs::axis(i)`).
    pub fn axis(&self, i: usize) -> &Rig1D {
        &self.axes[i]
    }

    pub fn time(&self) -> f64 {
        self.axes[0].time()
    }

    /// Advance by `h` with inputs u + du·τ, τ ∈ [0, h].
    pub fn step(&mut self, u: &Rig2DInputs, du: &Rig2DInputs, h: f64) {
        for (i, axis) in self.axes.iter_mut().enumerate() {
            axis.step(&u.axis(i), &du.axis(i), h);
        }
    }

    /// The number of values of the state (both axes').
    #[inline]
    pub fn state_len(&self) -> usize {
        self.axes[0].state_len() + self.axes[1].state_len()
    }

    /// The state of both axes, one after the other, into `out`, of
    /// [`Rig2D::state_len`] values.
    #[inline]
    pub fn write_state_into(&self, out: &mut [f64]) {
        let (first, second) = out.split_at_mut(self.axes[0].state_len());
        self.axes[0].write_state_into(first);
        self.axes[1].write_state_into(second);
    }

    /// Whether the state of both axes is finite (a scan of
    /// [`Rig2D::write_state_into`], without the copy).
    #[inline]
    pub fn state_is_finite(&self) -> bool {
        self.axes.iter().all(|axis| axis.state_is_finite())
    }

    /// The same state as a new vector.
    pub fn state_to_vec(&self) -> Vec<f64> {
        let mut v = vec![0.0; self.state_len()];
        self.write_state_into(&mut v);
        v
    }

    pub fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
        if s.len() != 8 {
            return Err(format!(
                "Rig2D state must be 8 finite numbers, got {}: {s:?}",
                s.len()
            ));
        }
        let mut axes = self.axes.clone();
        axes[0].state_from_slice(&s[..4])?;
        axes[1].state_from_slice(&s[4..])?;
        self.axes = axes;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::closed_form::{peak, worst, Forced};
    use std::f64::consts::PI;

    /// Without friction each axis is a free damped oscillator:
    /// x_i(t) = e^(−σt)(C1 cos ωd t + C2 sin ωd t), checked to 1e-11 of the
    /// peak over 3 s in both axes (the exact step: rounding only, at steps
    /// up to ω·h = 1) — Wijata et al.'s undamped oscillator and an
    /// anisotropic damped one.
    #[test]
    fn free_oscillation_matches_the_closed_form_in_both_axes() {
        let anisotropic = Rig2DParams {
            m: 0.7,
            k: [100.0, 40.0],
            c: [0.5, 1.2],
            x0: [0.05, -0.02],
            v0: [0.3, 0.1],
            ..Default::default()
        };
        for p in [Rig2DParams::default(), anisotropic] {
            for h in [1e-3f64, 1e-2, 0.1] {
                let mut rig = Rig2D::new(p).unwrap();
                let n = (3.0 / h).round() as usize;
                let mut got = [vec![], vec![], vec![], vec![]];
                let mut exact = [vec![], vec![], vec![], vec![]];
                let zero = Rig2DInputs::default();
                for s in 1..=n {
                    rig.step(&zero, &zero, h);
                    let t = s as f64 * h;
                    for i in 0..2 {
                        let free = Forced {
                            m: p.m,
                            c: p.c[i],
                            k: p.k[i],
                            ..Default::default()
                        };
                        let (x, v) = free.at(p.x0[i], p.v0[i], t);
                        got[2 * i].push(rig.axis(i).position(&zero.axis(i)));
                        got[2 * i + 1].push(rig.axis(i).slip_velocity());
                        exact[2 * i].push(x);
                        exact[2 * i + 1].push(v);
                    }
                }
                for (g, e) in got.iter().zip(&exact) {
                    let err = worst(g, e);
                    assert!(err <= 1e-11 * peak(e), "{p:?}, h = {h}: error {err:e}");
                }
            }
        }
    }

    /// Surface moving at (vs1, vs2) with dither along both axes: v_i is
    /// exactly ẋ_i − vs_i − A_i·Ω_i·cos(Ω_i t), and x_i − x_s,i(t) the
    /// relative displacement; the accelerations take the friction input.
    #[test]
    fn surface_dither_in_both_axes() {
        let p = Rig2DParams {
            v_surface: [0.01, -0.02],
            dither: [Sinusoid::new(2e-3, 20.0), Sinusoid::new(1e-3, 35.0)],
            ..Default::default()
        };
        let mut rig = Rig2D::new(p).unwrap();
        let zero = Rig2DInputs::default();
        for _ in 0..777 {
            rig.step(&zero, &zero, 1e-3);
        }
        let t = rig.time();
        for i in 0..2 {
            let w = 2.0 * PI * p.dither[i].freq;
            let a = rig.axis(i);
            let vs = p.v_surface[i] + p.dither[i].amp * w * (w * t).cos();
            assert_eq!(a.slip_velocity(), a.velocity() - vs);
            let xs = p.v_surface[i] * t + p.dither[i].amp * (w * t).sin();
            let rel = a.relative_displacement(&zero.axis(i));
            assert_eq!(rel, a.position(&zero.axis(i)) - xs);
            let u = Rig2DInputs {
                friction: [0.3, -0.2],
                f_ext: [0.1, 0.05],
            };
            let acc = (-p.k[i] * a.position(&u.axis(i)) + u.f_ext[i] - u.friction[i]) / p.m;
            assert!((a.acceleration(&u.axis(i)) - acc).abs() <= 1e-15 * acc.abs());
        }
    }

    #[test]
    fn state_round_trip_and_validation() {
        let mut a = Rig2D::new(Rig2DParams::default()).unwrap();
        let u = Rig2DInputs {
            friction: [0.2, -0.1],
            f_ext: [0.0, 0.3],
        };
        let du = Rig2DInputs {
            friction: [1.0, 0.5],
            f_ext: [0.0, 0.0],
        };
        for _ in 0..10 {
            a.step(&u, &du, 1e-3);
        }
        let mut b = Rig2D::new(Rig2DParams::default()).unwrap();
        b.state_from_slice(&a.state_to_vec()).unwrap();
        for _ in 0..100 {
            a.step(&u, &du, 1e-3);
            b.step(&u, &du, 1e-3);
        }
        assert_eq!(a.state_to_vec(), b.state_to_vec());
        assert!(b.state_from_slice(&[0.0; 7]).is_err());

        let d = Rig2DParams::default();
        for (p, needle) in [
            (Rig2DParams { m: 0.0, ..d }, "m = 0"),
            (Rig2DParams { m: f64::NAN, ..d }, "m = NaN"),
            (
                Rig2DParams {
                    k: [100.0, -1.0],
                    ..d
                },
                "k2 = -1",
            ),
            (
                Rig2DParams {
                    dither: [Sinusoid::OFF, Sinusoid::new(1.0, -2.0)],
                    ..d
                },
                "dither_freq2 = -2",
            ),
        ] {
            let e = Rig2D::new(p).unwrap_err();
            assert!(e.contains(needle), "{needle}: {e}");
        }
    }
}
