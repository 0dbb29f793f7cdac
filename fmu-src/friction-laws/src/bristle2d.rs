//! Two-dimensional bristle (reset-integrator) friction after Wijata,
//! Awrejcewicz, Matej, Makowski 2016; the equations are derived in
//! docs/models.md "Two-dimensional bristle" because our copy of the paper
//! lost them.
//!
//! State: bristle deflection `z = (z1, z2)`, stiction range the disc
//! `|z| < z0`.
//! `ż = v − [|z| ≥ z0 and z·v > 0]·(z·v)·z/|z|²`;
//! `Fi = (1 + ai(|z|))·σ0i·zi + σ1i(|v|)·żi`, `ai(|z|) = ai` inside the disc,
//! 0 on its boundary, `σ1i(|v|) = σ1i·exp(−(|v|/av)²)` (av = 0: constant).
//!
//! In sliding (`|z| = z0`, `z·v > 0`) `z` stays on the circle and its angle
//! `φ` turns toward the slip direction `θ`: `dφ/dt = (|v|/z0)·sin(θ − φ)`,
//! solved in closed form by `tan((θ − φ)/2) = tan((θ − φ0)/2)·e^(−|v|t/z0)`.

use crate::error::{require_non_negative, require_positive};
use crate::{ParamError, Ramp};

/// Relative tolerance on `|z|²` for "on the boundary": a state projected onto
/// the circle counts as on it despite round-off.
const BOUNDARY_TOL: f64 = 1e-12;
/// Most sub-steps per step for ramped velocities.
const MAX_SUBSTEPS: usize = 10_000;
/// Largest relative change of the velocity vector per sub-step.
const KAPPA: f64 = 1e-3;

/// Parameters of the 2-D bristle model (SI units): stiffnesses σ01, σ02
/// (N/m), dampings σ11, σ12 (N·s/m), stiction gradients a1, a2 (–),
/// stiction radius z0 (m), damping decay speed av (m/s; 0 = constant).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bristle2DParams {
    pub sigma01: f64,
    pub sigma02: f64,
    pub sigma11: f64,
    pub sigma12: f64,
    pub a1: f64,
    pub a2: f64,
    pub z0: f64,
    pub av: f64,
}

impl Default for Bristle2DParams {
    /// Wijata et al. 2016, numerical set: σ01 = σ02 = 1e4 N/m,
    /// σ11 = σ12 = 74.15 N·s/m, a1 = a2 = 0.1, z0 = 1e-4 m, av = 1e-2 m/s.
    fn default() -> Self {
        Bristle2DParams {
            sigma01: 1e4,
            sigma02: 1e4,
            sigma11: 74.15,
            sigma12: 74.15,
            a1: 0.1,
            a2: 0.1,
            z0: 1e-4,
            av: 1e-2,
        }
    }
}

impl Bristle2DParams {
    /// Wijata et al. 2016, experimental fit: σ01 = 7293.7, σ02 = 5572.08 N/m,
    /// σ11 = 209.2, σ12 = 182.8 N·s/m, a1 = a2 = 0.2, z0 = 1e-4 m,
    /// av = 1e-2 m/s.
    pub fn experimental() -> Self {
        Bristle2DParams {
            sigma01: 7293.7,
            sigma02: 5572.08,
            sigma11: 209.2,
            sigma12: 182.8,
            a1: 0.2,
            a2: 0.2,
            z0: 1e-4,
            av: 1e-2,
        }
    }

    /// σ0i > 0, σ1i ≥ 0, ai ≥ 0, z0 > 0, av ≥ 0, all finite.
    pub fn validate(&self) -> Result<(), ParamError> {
        require_positive("sigma01", self.sigma01)?;
        require_positive("sigma02", self.sigma02)?;
        require_non_negative("sigma11", self.sigma11)?;
        require_non_negative("sigma12", self.sigma12)?;
        require_non_negative("a1", self.a1)?;
        require_non_negative("a2", self.a2)?;
        require_positive("z0", self.z0)?;
        require_non_negative("av", self.av)?;
        Ok(())
    }
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The partial derivatives of [`Bristle2D::partials`], `[i][j]` =
/// `∂(·)_i/∂(z or v)_j`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bristle2DPartials {
    /// `∂ż/∂z`.
    pub rate_z: [[f64; 2]; 2],
    /// `∂ż/∂v`.
    pub rate_v: [[f64; 2]; 2],
    /// `∂F/∂z`.
    pub force_z: [[f64; 2]; 2],
    /// `∂F/∂v`.
    pub force_v: [[f64; 2]; 2],
}

/// 2-D bristle state: deflection `z` (m), kept in the closed disc `|z| ≤ z0`.
#[derive(Clone, Debug)]
pub struct Bristle2D {
    p: Bristle2DParams,
    z: [f64; 2],
}

impl Bristle2D {
    /// Relaxed state `z = 0` with validated parameters.
    pub fn new(p: Bristle2DParams) -> Result<Self, ParamError> {
        p.validate()?;
        Ok(Bristle2D { p, z: [0.0; 2] })
    }

    pub fn params(&self) -> &Bristle2DParams {
        &self.p
    }

    pub fn z(&self) -> [f64; 2] {
        self.z
    }

    /// Sets the deflection; a value outside the stiction disc is projected
    /// radially onto its boundary (the model never leaves the closed disc).
    pub fn set_z(&mut self, z: [f64; 2]) {
        self.z = z;
        self.clamp_to_disc();
    }

    fn clamp_to_disc(&mut self) {
        let r = self.z[0].hypot(self.z[1]);
        if r > self.p.z0 {
            self.project(r);
        }
    }

    /// Puts `z` (of length `r > 0`) exactly on the circle `|z| = z0`.
    fn project(&mut self, r: f64) {
        let f = self.p.z0 / r;
        self.z = [self.z[0] * f, self.z[1] * f];
    }

    fn on_boundary(&self) -> bool {
        let z0 = self.p.z0;
        dot(self.z, self.z) >= z0 * z0 * (1.0 - BOUNDARY_TOL)
    }

    /// `ż = v − [|z| ≥ z0 and z·v > 0]·(z·v)·z/|z|²` (docs/models.md, derived).
    pub fn z_dot(&self, v: [f64; 2]) -> [f64; 2] {
        self.z_rate(self.z, v, self.on_boundary())
    }

    /// The right-hand side for any deflection `z`, with the contact state
    /// given: `ż = v − [on_boundary and z·v > 0]·(z·v)·z/|z|²`
    /// (docs/models.md, derived from Wijata et al. 2016). A pure function,
    /// for integrating the law with other equations (the monolithic
    /// reference solutions), which track `on_boundary` as a mode rather than
    /// from `|z|`.
    pub fn z_rate(&self, z: [f64; 2], v: [f64; 2], on_boundary: bool) -> [f64; 2] {
        let zv = dot(z, v);
        if on_boundary && zv > 0.0 {
            let c = zv / dot(z, z);
            [v[0] - c * z[0], v[1] - c * z[1]]
        } else {
            v
        }
    }

    /// `Fi = (1 + ai(|z|))·σ0i·zi + σ1i(|v|)·żi` with `ai` only inside the
    /// disc and `σ1i(|v|) = σ1i·exp(−(|v|/av)²)`.
    pub fn force(&self, v: [f64; 2]) -> [f64; 2] {
        self.force_of(self.z, v, self.on_boundary())
    }

    /// The output equation for any deflection `z` and contact state:
    /// `Fi = (1 + [not on_boundary]·ai)·σ0i·zi + σ1i(|v|)·żi`, `ż` from
    /// [`Bristle2D::z_rate`]. Pure, like it.
    pub fn force_of(&self, z: [f64; 2], v: [f64; 2], on_boundary: bool) -> [f64; 2] {
        let p = &self.p;
        let zd = self.z_rate(z, v, on_boundary);
        let (g1, g2) = if on_boundary {
            (1.0, 1.0)
        } else {
            (1.0 + p.a1, 1.0 + p.a2)
        };
        let damp = if p.av > 0.0 {
            let r = dot(v, v) / (p.av * p.av);
            (-r).exp()
        } else {
            1.0
        };
        [
            g1 * p.sigma01 * z[0] + p.sigma11 * damp * zd[0],
            g2 * p.sigma02 * z[1] + p.sigma12 * damp * zd[1],
        ]
    }

    /// The elastic energy held in the bristle (J),
    /// `E = Σ (1 + ai)·σ0i·zi²/2`: the potential of the elastic force the
    /// deflection moves against inside the disc. On the boundary the
    /// deflection turns along the circle, where the force has `ai = 0`: the
    /// energy it then holds stays that of the inside (for an isotropic
    /// bristle it is constant there), so the drop of the force at the
    /// boundary loses no energy and its rise on release gains none.
    pub fn stored_energy_of(&self, z: [f64; 2]) -> f64 {
        let g = self.energy_gains();
        0.5 * (g[0] * z[0] * z[0] + g[1] * z[1] * z[1])
    }

    /// [`Bristle2D::stored_energy_of`] at the law's deflection.
    pub fn stored_energy(&self) -> f64 {
        self.stored_energy_of(self.z)
    }

    /// `(1 + ai)·σ0i`, the stiffnesses of [`Bristle2D::stored_energy_of`].
    fn energy_gains(&self) -> [f64; 2] {
        [
            (1.0 + self.p.a1) * self.p.sigma01,
            (1.0 + self.p.a2) * self.p.sigma02,
        ]
    }

    /// `P_diss = F·v − dE/dt = F·v − ∇E·ż` (W) for any deflection and
    /// contact state: inside the disc `Σ σ1i(|v|)·vi²`; sliding on the
    /// boundary of an isotropic bristle `σ0·z·v + σ1(|v|)·ż·v` with
    /// `z·ż = 0`, never negative. Unequal stiffnesses along the two axes
    /// can make it negative for a while on the boundary.
    pub fn dissipated_power_of(&self, z: [f64; 2], v: [f64; 2], on_boundary: bool) -> f64 {
        let f = self.force_of(z, v, on_boundary);
        let zd = self.z_rate(z, v, on_boundary);
        let g = self.energy_gains();
        dot(f, v) - (g[0] * z[0] * zd[0] + g[1] * z[1] * zd[1])
    }

    /// [`Bristle2D::dissipated_power_of`] at the law's deflection.
    pub fn dissipated_power(&self, v: [f64; 2]) -> f64 {
        self.dissipated_power_of(self.z, v, self.on_boundary())
    }

    /// The gradients of `P_diss` and `E_stored` with respect to `z` and of
    /// `P_diss` with respect to `v`, from [`Bristle2D::partials`]:
    /// `∂P/∂zj = Σi ∂Fi/∂zj·vi − gj·żj − Σi gi·zi·∂żi/∂zj`,
    /// `∂P/∂vj = Fj + Σi ∂Fi/∂vj·vi − Σi gi·zi·∂żi/∂vj`, `∂E/∂zj = gj·zj`
    /// with `gi = (1 + ai)·σ0i`.
    pub fn energy_partials(
        &self,
        z: [f64; 2],
        v: [f64; 2],
        on_boundary: bool,
    ) -> ([f64; 2], [f64; 2], [f64; 2]) {
        let d = self.partials(z, v, on_boundary);
        let f = self.force_of(z, v, on_boundary);
        let zd = self.z_rate(z, v, on_boundary);
        let g = self.energy_gains();
        let mut p_z = [0.0; 2];
        let mut p_v = [0.0; 2];
        for j in 0..2 {
            p_z[j] = -g[j] * zd[j];
            p_v[j] = f[j];
            for i in 0..2 {
                p_z[j] += d.force_z[i][j] * v[i] - g[i] * z[i] * d.rate_z[i][j];
                p_v[j] += d.force_v[i][j] * v[i] - g[i] * z[i] * d.rate_v[i][j];
            }
        }
        (p_z, p_v, [g[0] * z[0], g[1] * z[1]])
    }

    /// Sliding: on the boundary of the stiction disc and slipping outward
    /// (`z·v > 0`).
    pub fn sliding(&self, v: [f64; 2]) -> bool {
        self.sliding_of(self.z, v, self.on_boundary())
    }

    /// [`Bristle2D::sliding`] for any deflection `z` and contact state.
    pub fn sliding_of(&self, z: [f64; 2], v: [f64; 2], on_boundary: bool) -> bool {
        on_boundary && dot(z, v) > 0.0
    }

    /// The partial derivatives of [`Bristle2D::z_rate`] and
    /// [`Bristle2D::force_of`] for a given contact state, in closed form,
    /// as matrices indexed `[i][j]` = `∂(·)_i/∂(z or v)_j`. Inside the
    /// disc (or on its boundary slipping inward) `ż = v`: `∂ż/∂z = 0`,
    /// `∂ż/∂v = I`. Sliding, `ż = v − c·z` with `c = (z·v)/|z|²`:
    /// `∂ż_i/∂v_j = δij − z_i·z_j/|z|²` and
    /// `∂ż_i/∂z_j = −c·δij − z_i·(v_j − 2·c·z_j)/|z|²`. With
    /// `Fi = gi·σ0i·zi + σ1i·d(|v|)·żi`, `d = exp(−|v|²/av²)`:
    /// `∂Fi/∂zj = gi·σ0i·δij + σ1i·d·∂żi/∂zj` and
    /// `∂Fi/∂vj = σ1i·(−2·vj/av²·d·żi + d·∂żi/∂vj)`.
    pub fn partials(&self, z: [f64; 2], v: [f64; 2], on_boundary: bool) -> Bristle2DPartials {
        let p = &self.p;
        let mut rate_z = [[0.0; 2]; 2];
        let mut rate_v = [[1.0, 0.0], [0.0, 1.0]];
        if on_boundary && dot(z, v) > 0.0 {
            let r2 = dot(z, z);
            let c = dot(z, v) / r2;
            for i in 0..2 {
                for j in 0..2 {
                    let delta = if i == j { 1.0 } else { 0.0 };
                    rate_v[i][j] = delta - z[i] * z[j] / r2;
                    rate_z[i][j] = -c * delta - z[i] * (v[j] - 2.0 * c * z[j]) / r2;
                }
            }
        }
        let zd = self.z_rate(z, v, on_boundary);
        let (damp, damp_slope) = if p.av > 0.0 {
            let d = (-dot(v, v) / (p.av * p.av)).exp();
            (d, -2.0 / (p.av * p.av) * d)
        } else {
            (1.0, 0.0)
        };
        let gains = if on_boundary {
            [1.0, 1.0]
        } else {
            [1.0 + p.a1, 1.0 + p.a2]
        };
        let sigma0 = [p.sigma01, p.sigma02];
        let sigma1 = [p.sigma11, p.sigma12];
        let mut force_z = [[0.0; 2]; 2];
        let mut force_v = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                let delta = if i == j { 1.0 } else { 0.0 };
                force_z[i][j] = gains[i] * sigma0[i] * delta + sigma1[i] * damp * rate_z[i][j];
                force_v[i][j] = sigma1[i] * (damp_slope * v[j] * zd[i] + damp * rate_v[i][j]);
            }
        }
        Bristle2DPartials {
            rate_z,
            rate_v,
            force_z,
            force_v,
        }
    }

    /// The switching function of the contact state (Model Exchange's event
    /// indicator): inside the disc `z0 − |z|`, which reaches 0 when the
    /// deflection reaches the boundary; on the boundary `−(z·v)/|z|`,
    /// negative while the slip strains the bristle outward (sliding) and
    /// 0 when it turns inward and releases it.
    pub fn switching_function(&self, z: [f64; 2], v: [f64; 2], on_boundary: bool) -> f64 {
        let r = z[0].hypot(z[1]);
        if on_boundary {
            if r > 0.0 {
                -dot(z, v) / r
            } else {
                0.0
            }
        } else {
            self.p.z0 - r
        }
    }

    /// The contact state after an event, and the deflection put back on the
    /// circle where it is on the boundary (an integrator keeps `|z| = z0`
    /// only to its tolerance, and carries it past `z0` before the event is
    /// located): reaching the boundary (`|z| ≥ z0`) or on it, the bristle
    /// is on the boundary while the slip does not turn inward (`z·v ≥ 0`,
    /// as [`Bristle2D::advance_constant`] slides), else inside. Returns the
    /// deflection and the contact state.
    pub fn at_event(&self, z: [f64; 2], v: [f64; 2], on_boundary: bool) -> ([f64; 2], bool) {
        let z0 = self.p.z0;
        let r = z[0].hypot(z[1]);
        if !(on_boundary || r >= z0) || r == 0.0 {
            return (z, false);
        }
        let f = z0 / r;
        let projected = [z[0] * f, z[1] * f];
        (projected, dot(projected, v) >= 0.0)
    }

    /// Advances over `[0, h]` with `v = (v1(τ), v2(τ))`.
    ///
    /// Constant `v`: exact (see [`Bristle2D::advance_constant`]).
    /// Ramped `v`: sub-steps on which the velocity vector changes by at most
    /// 0.1 % of `|v| + v_floor` (`v_floor = √(0.001·|dv/dt|·z0)`, so the
    /// path travelled while `|v|` is below it is small against `z0`), at most
    /// 10 000 per step, each advanced exactly with a frozen velocity: the
    /// midpoint velocity, except that in sliding its direction is taken at
    /// `τ* = hs·(1 − φ1(khs))/(1 − e^(−khs))`, `k = |v|/z0`,
    /// `φ1(x) = (1 − e^(−x))/x` (the time at which a frozen target gives the
    /// exact response of the linearised relaxation to a uniformly turning
    /// target: `hs/2` when `khs ≪ 1`, `hs − 1/k` when `khs ≫ 1`), which keeps
    /// the deflection's lag behind a turning slip direction second-order
    /// accurate also when a sub-step slides over many `z0`.
    pub fn step(&mut self, v1: Ramp, v2: Ramp, h: f64) {
        if h.is_nan() || h <= 0.0 {
            return;
        }
        let acc = v1.slope.hypot(v2.slope);
        if acc == 0.0 {
            self.advance_constant([v1.value, v2.value], h);
            return;
        }
        let v_floor = (KAPPA * acc * self.p.z0).sqrt();
        let min_len = h / MAX_SUBSTEPS as f64;
        let mut t = 0.0;
        let mut count = 0;
        while t < h {
            count += 1;
            let rest = h - t;
            let mut len = rest;
            if count < MAX_SUBSTEPS {
                let speed = v1.at(t).hypot(v2.at(t));
                let l = KAPPA * (speed + v_floor) / acc;
                if l < rest {
                    len = l.max(min_len);
                }
            }
            let t1 = if len >= rest { h } else { t + len };
            self.substep(v1, v2, t, t1);
            t = t1;
        }
    }

    fn substep(&mut self, v1: Ramp, v2: Ramp, t: f64, t1: f64) {
        let hs = t1 - t;
        let tm = 0.5 * (t + t1);
        let vm = [v1.at(tm), v2.at(tm)];
        let speed = vm[0].hypot(vm[1]);
        if speed > 0.0 && self.on_boundary() && dot(self.z, vm) >= 0.0 {
            let x = speed / self.p.z0 * hs;
            let frac = if x < 1e-4 {
                0.5 + x / 12.0
            } else {
                let one_minus_e = -(-x).exp_m1();
                (1.0 - one_minus_e / x) / one_minus_e
            };
            let ts = t + frac * hs;
            let vd = [v1.at(ts), v2.at(ts)];
            let sd = vd[0].hypot(vd[1]);
            if sd > 0.0 {
                let f = speed / sd;
                self.advance_constant([vd[0] * f, vd[1] * f], hs);
                return;
            }
        }
        self.advance_constant(vm, hs);
    }

    /// Exact advance over `h` at constant `v`: inside the disc `ż = v` up to
    /// the exact boundary hit (`|z + vτ| = z0`); on the boundary with
    /// `z·v ≥ 0` the closed-form rotation (tangential slip, `z·v = 0`
    /// included, turns outward at once); on the boundary with `z·v < 0` the
    /// straight path back into the disc.
    pub fn advance_constant(&mut self, v: [f64; 2], h: f64) {
        let speed2 = dot(v, v);
        if h.is_nan() || h <= 0.0 || speed2 == 0.0 {
            return;
        }
        let z0 = self.p.z0;
        let mut rest = h;
        for _ in 0..4 {
            let b = dot(self.z, v);
            if self.on_boundary() && b >= 0.0 {
                self.rotate(v, rest);
                return;
            }
            // Straight path z + vτ: time to reach |z| = z0.
            let c = dot(self.z, self.z) - z0 * z0;
            let disc = (b * b - speed2 * c).max(0.0);
            let tau = if b <= 0.0 {
                (-b + disc.sqrt()) / speed2
            } else {
                (-c / (b + disc.sqrt())).max(0.0)
            };
            if tau >= rest {
                self.z = [self.z[0] + v[0] * rest, self.z[1] + v[1] * rest];
                self.clamp_to_disc();
                return;
            }
            self.z = [self.z[0] + v[0] * tau, self.z[1] + v[1] * tau];
            let r = self.z[0].hypot(self.z[1]);
            if r > 0.0 {
                self.project(r);
            }
            rest -= tau;
        }
        // Round-off kept bouncing at a tangential exit: slide for the rest.
        self.rotate(v, rest);
    }

    /// Sliding on the circle for time `t` at constant `v`:
    /// `ψ = θ − φ`, `tan(ψ/2) ← tan(ψ0/2)·e^(−|v|t/z0)`, evaluated without
    /// angles (`tan(ψ0/2) = sin ψ0/(1 + cos ψ0)` with `cos ψ0 = ẑ·v̂ ≥ 0`).
    fn rotate(&mut self, v: [f64; 2], t: f64) {
        let z0 = self.p.z0;
        let speed = v[0].hypot(v[1]);
        let r = self.z[0].hypot(self.z[1]);
        if speed == 0.0 || r == 0.0 {
            return;
        }
        let vh = [v[0] / speed, v[1] / speed];
        let zh = [self.z[0] / r, self.z[1] / r];
        let cos0 = dot(zh, vh);
        let sin0 = zh[0] * vh[1] - zh[1] * vh[0];
        let q0 = sin0 / (1.0 + cos0.max(0.0));
        let q = q0 * (-speed * t / z0).exp();
        let d = 1.0 + q * q;
        let (cos_psi, sin_psi) = ((1.0 - q * q) / d, 2.0 * q / d);
        let u = [
            cos_psi * vh[0] + sin_psi * vh[1],
            cos_psi * vh[1] - sin_psi * vh[0],
        ];
        let n = u[0].hypot(u[1]);
        self.z = [z0 * u[0] / n, z0 * u[1] / n];
    }

    /// The number of values of the state (2).
    #[inline]
    pub fn state_len(&self) -> usize {
        2
    }

    /// The state `[z1, z2]` into `out`, of [`Bristle2D::state_len`] values.
    #[inline]
    pub fn write_state_into(&self, out: &mut [f64]) {
        out.copy_from_slice(&[self.z[0], self.z[1]]);
    }

    /// Whether the state is finite (a scan of
    /// [`Bristle2D::write_state_into`], without the copy).
    #[inline]
    pub fn state_is_finite(&self) -> bool {
        self.z.iter().all(|z| z.is_finite())
    }

    /// The same state as a new vector.
    pub fn state_to_vec(&self) -> Vec<f64> {
        let mut v = vec![0.0; self.state_len()];
        self.write_state_into(&mut v);
        v
    }

    /// Restores `[z1, z2]` (finite; projected into the disc like
    /// [`Bristle2D::set_z`]).
    /// (Inlined into a caller, the messages out of line.)
    #[inline]
    pub fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
        match s {
            [a, b] if a.is_finite() && b.is_finite() => {
                self.set_z([*a, *b]);
                Ok(())
            }
            _ => Err(state_refused(s)),
        }
    }
}

/// Why [`Bristle2D::state_from_slice`] refused `s`.
#[cold]
#[inline(never)]
fn state_refused(s: &[f64]) -> String {
    match s {
        [_, _] => format!("2-D bristle state {s:?} is not finite"),
        _ => format!("2-D bristle state has 2 values, got {}", s.len()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn norm(a: [f64; 2]) -> f64 {
        a[0].hypot(a[1])
    }

    #[test]
    fn energy_outputs_inside_and_on_the_boundary() {
        let p = Bristle2DParams::default();
        let b = Bristle2D::new(p).unwrap();
        let damp = |v: [f64; 2]| (-dot(v, v) / (p.av * p.av)).exp();
        // inside: only the dampers dissipate
        let (z, v) = ([3e-5, -2e-5], [1e-3, 2e-3]);
        let inside = b.dissipated_power_of(z, v, false);
        assert!((inside - p.sigma11 * damp(v) * dot(v, v)).abs() < 1e-15);
        let e = 0.5 * (1.0 + p.a1) * p.sigma01 * dot(z, z);
        assert!((b.stored_energy_of(z) - e).abs() < 1e-18);
        // sliding on the boundary of the isotropic bristle: never negative
        for k in 0..16 {
            let phi = 2.0 * PI * k as f64 / 16.0;
            let z = [p.z0 * phi.cos(), p.z0 * phi.sin()];
            let v = [2e-3 * (phi + 0.7).cos(), 2e-3 * (phi + 0.7).sin()];
            assert!(b.dissipated_power_of(z, v, true) > 0.0);
        }
        // the partials against central differences, both contact states
        for (z, on) in [([3e-5, -2e-5], false), ([6e-5, 8e-5], true)] {
            let v = [1e-3, 2e-3];
            let (p_z, p_v, e_z) = b.energy_partials(z, v, on);
            for j in 0..2 {
                let bump = |a: [f64; 2], h: f64| {
                    let mut a = a;
                    a[j] += h;
                    a
                };
                let (hz, hv) = (1e-11, 1e-9);
                let fd_pz = (b.dissipated_power_of(bump(z, hz), v, on)
                    - b.dissipated_power_of(bump(z, -hz), v, on))
                    / (2.0 * hz);
                let fd_pv = (b.dissipated_power_of(z, bump(v, hv), on)
                    - b.dissipated_power_of(z, bump(v, -hv), on))
                    / (2.0 * hv);
                let fd_ez = (b.stored_energy_of(bump(z, hz)) - b.stored_energy_of(bump(z, -hz)))
                    / (2.0 * hz);
                assert!(
                    (p_z[j] - fd_pz).abs() <= 1e-6 * p_z[j].abs().max(1.0),
                    "{p_z:?} {fd_pz}"
                );
                assert!(
                    (p_v[j] - fd_pv).abs() <= 1e-6 * p_v[j].abs().max(1.0),
                    "{p_v:?} {fd_pv}"
                );
                assert!(
                    (e_z[j] - fd_ez).abs() <= 1e-6 * e_z[j].abs().max(1e-3),
                    "{e_z:?} {fd_ez}"
                );
            }
        }
    }

    #[test]
    fn isotropic_sliding_level_in_sixteen_directions() {
        let p = Bristle2DParams::default();
        for k in 0..16 {
            let th = 2.0 * PI * k as f64 / 16.0 + 0.1;
            let v = [0.05 * th.cos(), 0.05 * th.sin()];
            let mut b = Bristle2D::new(p).unwrap();
            b.step(Ramp::constant(v[0]), Ramp::constant(v[1]), 0.1);
            assert!(b.sliding(v));
            let f = b.force(v);
            assert!(
                (norm(f) / (p.sigma01 * p.z0) - 1.0).abs() < 1e-9,
                "k {k}: {f:?}"
            );
            // Force along the slip direction.
            assert!((f[0] * v[1] - f[1] * v[0]).abs() < 1e-9 * norm(f) * norm(v));
            // Turn by 90° while sliding: stays on the circle.
            let w = [-v[1], v[0]];
            b.step(Ramp::constant(w[0]), Ramp::constant(w[1]), 1e-3);
            assert!((norm(b.z()) / p.z0 - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn anisotropic_sliding_force_lies_on_the_ellipse() {
        let p = Bristle2DParams::experimental();
        for k in 0..24 {
            let th = 2.0 * PI * k as f64 / 24.0;
            let v = [0.02 * th.cos(), 0.02 * th.sin()];
            let mut b = Bristle2D::new(p).unwrap();
            b.step(Ramp::constant(v[0]), Ramp::constant(v[1]), 1.0);
            let f = b.force(v);
            let e = (f[0] / (p.sigma01 * p.z0)).powi(2) + (f[1] / (p.sigma02 * p.z0)).powi(2);
            assert!((e - 1.0).abs() < 1e-9, "k {k}: {e}");
        }
    }

    #[test]
    fn stiction_peak_inside_the_disc() {
        let p = Bristle2DParams::default();
        let mut b = Bristle2D::new(p).unwrap();
        let v = [3e-5, 4e-5];
        // |v|·t = 0.999·z0: still sticking, F = (1 + a)σ0 z + σ1 v.
        b.step(
            Ramp::constant(v[0]),
            Ramp::constant(v[1]),
            0.999 * p.z0 / 5e-5,
        );
        assert!(!b.sliding(v));
        let damp = (-(5e-5f64 / p.av).powi(2)).exp();
        let f = b.force(v);
        let expect = (1.0 + p.a1) * p.sigma01 * 0.999 * p.z0 * 0.6 + p.sigma11 * damp * v[0];
        assert!((f[0] / expect - 1.0).abs() < 1e-12);
        b.step(Ramp::constant(v[0]), Ramp::constant(v[1]), 1.0);
        assert!(b.sliding(v));
        assert!((norm(b.force(v)) / (p.sigma01 * p.z0) - 1.0).abs() < 1e-9);
        // Reversal: leaves the boundary straight inward (ż = v).
        let w = [-v[0], -v[1]];
        assert!(!b.sliding(w));
        assert_eq!(b.z_dot(w), w);
        b.step(
            Ramp::constant(w[0]),
            Ramp::constant(w[1]),
            2.0 * p.z0 / 5e-5 * 0.5,
        );
        assert!(norm(b.z()) < 1e-12 * p.z0);
        // Crosses the disc and slides on the far side.
        b.step(Ramp::constant(w[0]), Ramp::constant(w[1]), 10.0);
        assert!(b.sliding(w));
    }

    #[test]
    fn turning_slip_direction_keeps_sliding() {
        let p = Bristle2DParams::default();
        for &(h, omega, speed) in &[
            (1e-3, 2.0 * PI, 0.1),
            (1e-2, 4.0 * PI, 0.05),
            (0.05, 6.0, 0.2),
        ] {
            let mut b = Bristle2D::new(p).unwrap();
            let vel = |t: f64| [speed * (omega * t).cos(), speed * (omega * t).sin()];
            let n = (2.0 / h) as usize;
            let transient = (5.0 * p.z0 / speed / h).ceil() as usize + 1;
            for k in 0..n {
                let t = k as f64 * h;
                let (a, c) = (vel(t), vel(t + h));
                b.step(
                    Ramp::new(a[0], (c[0] - a[0]) / h),
                    Ramp::new(a[1], (c[1] - a[1]) / h),
                    h,
                );
                if k >= transient {
                    assert!(b.sliding(c), "h {h} step {k}: stuck at z {:?}", b.z());
                    let f = b.force(c);
                    assert!((norm(f) / (p.sigma01 * p.z0) - 1.0).abs() < 0.05);
                }
            }
        }
    }

    /// Reference: exact straight motion inside the disc (the path is
    /// quadratic in time), the sliding angle by RK4 on
    /// `φ̇ = (v2 cos φ − v1 sin φ)/z0`, events located by bisection.
    struct Reference {
        z0: f64,
        inside: bool,
        z: [f64; 2],
        phi: f64,
    }

    impl Reference {
        fn z(&self) -> [f64; 2] {
            if self.inside {
                self.z
            } else {
                [self.z0 * self.phi.cos(), self.z0 * self.phi.sin()]
            }
        }

        fn phi_after(&self, phi: f64, v1: Ramp, v2: Ramp, t: f64, dt: f64) -> f64 {
            let f = |s: f64, ph: f64| (v2.at(s) * ph.cos() - v1.at(s) * ph.sin()) / self.z0;
            let k1 = f(t, phi);
            let k2 = f(t + 0.5 * dt, phi + 0.5 * dt * k1);
            let k3 = f(t + 0.5 * dt, phi + 0.5 * dt * k2);
            let k4 = f(t + dt, phi + dt * k3);
            phi + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        }

        fn advance(&mut self, v1: Ramp, v2: Ramp, t: f64, dt: f64) {
            if !self.inside {
                let c = |s: f64, ph: f64| v1.at(s) * ph.cos() + v2.at(s) * ph.sin();
                if c(t, self.phi) < 0.0 {
                    self.z = self.z();
                    self.inside = true;
                } else {
                    let ph = self.phi_after(self.phi, v1, v2, t, dt);
                    if c(t + dt, ph) >= 0.0 {
                        self.phi = ph;
                        return;
                    }
                    // Leaves the boundary inside this step.
                    let (mut lo, mut hi) = (0.0, dt);
                    for _ in 0..60 {
                        let m = 0.5 * (lo + hi);
                        if c(t + m, self.phi_after(self.phi, v1, v2, t, m)) >= 0.0 {
                            lo = m;
                        } else {
                            hi = m;
                        }
                    }
                    self.phi = self.phi_after(self.phi, v1, v2, t, lo);
                    self.z = self.z();
                    self.inside = true;
                    return self.advance(v1, v2, t + lo, dt - lo);
                }
            }
            let path = |s: f64| {
                let (a, b) = (v1.at(t), v2.at(t));
                [
                    self.z[0] + a * s + 0.5 * v1.slope * s * s,
                    self.z[1] + b * s + 0.5 * v2.slope * s * s,
                ]
            };
            let end = path(dt);
            if norm(end) < self.z0 {
                self.z = end;
                return;
            }
            let (mut lo, mut hi) = (0.0, dt);
            for _ in 0..60 {
                let m = 0.5 * (lo + hi);
                if norm(path(m)) < self.z0 {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            let zb = path(hi);
            self.inside = false;
            self.phi = zb[1].atan2(zb[0]);
            self.phi = self.phi_after(self.phi, v1, v2, t + hi, dt - hi);
        }
    }

    /// Worst deflection error (relative to z0) at the step ends over `n`
    /// steps of `h` with the velocity ramping from `vel(k).0` to `vel(k).1`.
    fn compare_with_reference(
        p: Bristle2DParams,
        h: f64,
        n: usize,
        vel: impl Fn(usize) -> ([f64; 2], [f64; 2]),
    ) -> f64 {
        let mut b = Bristle2D::new(p).unwrap();
        let mut r = Reference {
            z0: p.z0,
            inside: true,
            z: [0.0; 2],
            phi: 0.0,
        };
        let m = ((h / 2e-6).ceil() as usize).max(10);
        let dt = h / m as f64;
        let mut worst: f64 = 0.0;
        for k in 0..n {
            let (a, c) = vel(k);
            let (v1, v2) = (
                Ramp::new(a[0], (c[0] - a[0]) / h),
                Ramp::new(a[1], (c[1] - a[1]) / h),
            );
            b.step(v1, v2, h);
            for j in 0..m {
                r.advance(v1, v2, j as f64 * dt, dt);
            }
            let mut q = Bristle2D::new(p).unwrap();
            q.set_z(r.z());
            let e = norm([b.z()[0] - q.z()[0], b.z()[1] - q.z()[1]]) / p.z0;
            worst = worst.max(e);
        }
        worst
    }

    #[test]
    fn exact_step_matches_a_fine_reference() {
        let p = Bristle2DParams::default();
        // Piecewise-constant velocities: sticking, boundary hits, sliding,
        // reversals through the disc.
        let pattern = [
            [3e-3, 1e-3],
            [-2e-3, 2e-3],
            [-1e-3, -3e-3],
            [4e-3, 0.0],
            [0.0, 5e-3],
            [-4e-3, -4e-3],
        ];
        let e = compare_with_reference(p, 0.03, 6, |k| (pattern[k], pattern[k]));
        assert!(e < 1e-8, "constant velocities: {e:e}");
        // Ramped: a smooth planar slip path, sliding and sticking.
        let vel = |t: f64| [4e-3 * (3.0 * t).sin(), 3e-3 * (5.0 * t).cos()];
        let sampled = |h: f64| move |k: usize| (vel(k as f64 * h), vel((k + 1) as f64 * h));
        let e = compare_with_reference(p, 0.01, 120, sampled(0.01));
        assert!(e < 1e-6, "ramped h 0.01: {e:e}");
        let e = compare_with_reference(p, 0.1, 12, sampled(0.1));
        assert!(e < 1e-6, "ramped h 0.1: {e:e}");
        // Fast sliding with a turning direction (many z0 per sub-step).
        let vel = |t: f64| [0.5 * (0.7 * t).cos(), 0.5 * (0.7 * t).sin()];
        let e = compare_with_reference(p, 0.05, 10, |k| {
            (vel(k as f64 * 0.05), vel((k + 1) as f64 * 0.05))
        });
        assert!(e < 1e-6, "fast turning: {e:e}");
    }

    #[test]
    fn validation_state_round_trip_and_finite_for_all_steps() {
        let p = Bristle2DParams::default();
        assert_eq!(
            Bristle2D::new(Bristle2DParams { z0: 0.0, ..p })
                .unwrap_err()
                .name,
            "z0"
        );
        assert_eq!(
            Bristle2D::new(Bristle2DParams { a2: -0.1, ..p })
                .unwrap_err()
                .name,
            "a2"
        );
        assert_eq!(
            Bristle2D::new(Bristle2DParams { sigma02: -1.0, ..p })
                .unwrap_err()
                .name,
            "sigma02"
        );
        let mut a = Bristle2D::new(p).unwrap();
        a.step(Ramp::new(1e-3, -0.1), Ramp::new(-2e-3, 0.05), 0.03);
        let mut b = Bristle2D::new(p).unwrap();
        b.state_from_slice(&a.state_to_vec()).unwrap();
        for &h in &[1e-7, 1e-4, 1e-1, 1.0] {
            for &(v, s) in &[
                (1.0, -3.0),
                (-1e3, 5e3),
                (0.0, 0.0),
                (1e-12, 1e6),
                (0.0, -1e-9),
            ] {
                a.step(Ramp::new(v, s), Ramp::new(-0.5 * v, s), h);
                b.step(Ramp::new(v, s), Ramp::new(-0.5 * v, s), h);
                assert!(norm(a.z()) <= p.z0 * (1.0 + 4.0 * f64::EPSILON));
                let f = a.force([v, 0.3]);
                assert!(f[0].is_finite() && f[1].is_finite());
                assert_eq!(a.z()[0].to_bits(), b.z()[0].to_bits());
                assert_eq!(a.z()[1].to_bits(), b.z()[1].to_bits());
            }
        }
        assert!(b.state_from_slice(&[0.0]).is_err());
        assert!(b.state_from_slice(&[0.0, f64::NAN]).is_err());
        b.set_z([1.0, 0.0]);
        assert_eq!(b.z(), [p.z0, 0.0]);
    }

    #[test]
    fn pure_right_hand_side_matches_the_state_methods_and_the_exact_update() {
        let p = Bristle2DParams {
            sigma02: 8e3,
            a2: 0.3,
            ..Bristle2DParams::default()
        };
        let mut b = Bristle2D::new(p).unwrap();
        let z0 = p.z0;
        // Inside the disc, on its boundary slipping outward, and on it
        // slipping back inward.
        for &(z, v) in &[
            ([3e-5, -2e-5], [1e-3, 4e-3]),
            ([0.6 * z0, 0.8 * z0], [2e-3, 1e-3]),
            ([0.6 * z0, 0.8 * z0], [-2e-3, -1e-3]),
        ] {
            b.set_z(z);
            let on = b.on_boundary();
            assert_eq!(b.z_rate(z, v, on), b.z_dot(v));
            assert_eq!(b.force_of(z, v, on), b.force(v));
            // The exact update over a tiny step moves z by ż·h.
            let h = 1e-9;
            let mut c = b.clone();
            c.advance_constant(v, h);
            let rate = b.z_rate(z, v, on);
            for k in 0..2 {
                let fd = (c.z()[k] - z[k]) / h;
                assert!(
                    (fd - rate[k]).abs() <= 1e-6 * v[0].hypot(v[1]),
                    "{z:?} {v:?}"
                );
            }
        }
        // On the boundary the slip is tangential: z·ż = 0; the stiction
        // gradient only acts inside.
        let z = [0.6 * z0, 0.8 * z0];
        let zd = b.z_rate(z, [2e-3, 1e-3], true);
        assert!(dot(z, zd).abs() < 1e-20);
        let v0 = [0.0, 0.0];
        let inside = b.force_of(z, v0, false);
        let boundary = b.force_of(z, v0, true);
        assert!((inside[0] / boundary[0] - 1.1).abs() < 1e-12);
        assert!((inside[1] / boundary[1] - 1.3).abs() < 1e-12);
    }

    /// A refused state is named as before the messages moved out of line;
    /// the slice writer writes what the vector writer appends.
    #[test]
    fn refused_states_are_named_and_written_states_agree() {
        let mut b = Bristle2D::new(Bristle2DParams::default()).unwrap();
        let err = b.state_from_slice(&[0.0, f64::NAN]).unwrap_err();
        assert_eq!(err, "2-D bristle state [0.0, NaN] is not finite");
        let err = b.state_from_slice(&[0.0]).unwrap_err();
        assert_eq!(err, "2-D bristle state has 2 values, got 1");
        b.set_z([1e-9, -2e-9]);
        let mut s = vec![f64::NAN; b.state_len()];
        b.write_state_into(&mut s);
        assert_eq!(s, b.state_to_vec());
    }

    /// The closed-form partials against central differences of `z_rate`
    /// and `force_of` (inside, sliding, anisotropic, with and without the
    /// damping decay); the switching function's signs and the contact
    /// state after an event.
    #[test]
    fn partials_switching_function_and_events() {
        let z0 = 1e-4;
        for p in [
            Bristle2DParams::default(),
            Bristle2DParams::experimental(),
            Bristle2DParams {
                av: 0.0,
                ..Bristle2DParams::default()
            },
        ] {
            let b = Bristle2D::new(p).unwrap();
            let cases = [
                ([3e-5, -2e-5], [2e-3, 1e-3], false),
                ([z0 * 0.6, z0 * 0.8], [2e-3, 1e-3], true),
                ([-z0 * 0.28, z0 * 0.96], [-4e-3, 5e-3], true),
                ([z0, 0.0], [1e-3, 3e-3], true),
            ];
            for (z, v, on) in cases {
                let d = b.partials(z, v, on);
                for j in 0..2 {
                    let (hz, hv) = (1e-12, 1e-9);
                    let (mut zp, mut zm, mut vp, mut vm) = (z, z, v, v);
                    zp[j] += hz;
                    zm[j] -= hz;
                    vp[j] += hv;
                    vm[j] -= hv;
                    for i in 0..2 {
                        let fd =
                            |a: [f64; 2],
                             b_: [f64; 2],
                             h: f64,
                             f: &dyn Fn([f64; 2]) -> [f64; 2]| {
                                (f(a)[i] - f(b_)[i]) / (2.0 * h)
                            };
                        let rate_z = fd(zp, zm, hz, &|z| b.z_rate(z, v, on));
                        let rate_v = fd(vp, vm, hv, &|v| b.z_rate(z, v, on));
                        let force_z = fd(zp, zm, hz, &|z| b.force_of(z, v, on));
                        let force_v = fd(vp, vm, hv, &|v| b.force_of(z, v, on));
                        let at = format!("{p:?} z {z:?} v {v:?} on {on} [{i}][{j}]");
                        let scale_rate = 1e-6 * (v[0].hypot(v[1]) / z0);
                        assert!(
                            (d.rate_z[i][j] - rate_z).abs() <= scale_rate.max(1e-6 * rate_z.abs()),
                            "rate_z {at}: {} vs {rate_z}",
                            d.rate_z[i][j]
                        );
                        assert!((d.rate_v[i][j] - rate_v).abs() <= 1e-6, "rate_v {at}");
                        assert!(
                            (d.force_z[i][j] - force_z).abs() <= 1e-6 * 1e4,
                            "force_z {at}: {} vs {force_z}",
                            d.force_z[i][j]
                        );
                        assert!(
                            (d.force_v[i][j] - force_v).abs() <= 1e-6 * 300.0,
                            "force_v {at}: {} vs {force_v}",
                            d.force_v[i][j]
                        );
                    }
                }
            }
            // inside: z0 − |z| > 0; on the boundary sliding: < 0; turning inward: > 0
            assert!(b.switching_function([3e-5, 4e-5], [1.0, 0.0], false) == z0 - 5e-5);
            assert!(b.switching_function([z0, 0.0], [1e-3, 1e-3], true) < 0.0);
            assert!(b.switching_function([z0, 0.0], [-1e-3, 1e-3], true) > 0.0);
            // an event: past the boundary moving out → on it, projected;
            // on it turning inward → inside; inside → unchanged
            let (z, on) = b.at_event([1.2 * z0, 0.0], [1e-3, 0.0], false);
            assert!(on && z == [z0, 0.0]);
            let (z, on) = b.at_event([0.0, z0 * (1.0 + 1e-9)], [1e-3, -1e-3], true);
            assert!(!on && z == [0.0, z0]);
            let (z, on) = b.at_event([3e-5, 0.0], [1e-3, 0.0], false);
            assert!(!on && z == [3e-5, 0.0]);
        }
    }
}
