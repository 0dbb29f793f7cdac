//! Maxwell-slip and Generalized Maxwell-Slip (GMS) friction: `N`
//! elasto-slide elements in parallel (docs/models.md "Maxwell-slip and
//! GMS").
//!
//! Each element `i` is a spring of stiffness `k_i` whose end sticks to
//! the surface until the spring force `F_i` reaches the element's slip
//! level; the friction force is the sum, `F = Σ F_i + σ2·v`.
//!
//! - **Maxwell-slip** (Lampaert, Swevers, Al-Bender 2002, after Iwan
//!   1966): the slip level is a constant `W_i`. A sticking element follows
//!   `Ḟ_i = k_i·v`; at `|F_i| = W_i` it slides with `F_i` held at
//!   `±W_i` until the motion reverses. The law is rate-independent and
//!   its memory is that of a discrete Preisach model: a minor loop is
//!   wiped out when the path passes its start again.
//! - **GMS** (Al-Bender, Lampaert, Swevers 2005): the slip level follows
//!   the Stribeck curve, `α_i·s(v)` with `s(v) = Fc + (Fs − Fc)·e^(−|v/vs|^δ)`
//!   and `Σ α_i = 1`. A sticking element follows `Ḟ_i = k_i·v` until
//!   `sgn(v)·F_i` reaches `α_i·s(v)`; a slipping element is attracted to
//!   its level, `Ḟ_i = C·(sgn(v)·α_i − F_i/s(v))`, and sticks again when
//!   the motion reverses. (The paper writes `sgn(v)·C·(α_i − F_i/s(v))`
//!   with `F_i/s(v)` read in the direction of motion; written with the
//!   sign inside, as here, the law is odd in `v`.) `C` (N/s) sets the
//!   frictional lag: in gross sliding every element slips and
//!   `Σ F_i` relaxes to `s(v)` with the time constant `s(v)/C`. Each
//!   element has the paper's micro-viscous damping `σ_i·ż_i` on its
//!   deflection rate `ż_i = Ḟ_i/k_i` (`v` while it sticks), one total
//!   `σ1` shared in proportion to stiffness, `σ_i = σ1·k_i/Σ k_j`:
//!   `F = Σ F_i + Σ σ_i·ż_i + σ2·v`. The damping acts on the force only;
//!   the element forces move as without it.
//!
//! [`MaxwellSlip::step`] is exact: on each piece of the step where `v`
//! keeps one sign, `F_i ← clamp(F_i + k_i·Δx)`. [`Gms::step`] is exact for
//! a velocity held over the step, with each element's switch located
//! inside it: a sticking element reaches its level after
//! `(α_i·s − sgn(v)·F_i)/(k_i·|v|)` and relaxes from there by
//! `F_i(t) = sgn(v)·α_i·s + (F_i − sgn(v)·α_i·s)·e^(−C·t/s)`. A ramped
//! velocity is held at its mean over sub-steps short enough that it
//! changes by at most 1e-3 of `|v| + vs` (at most 1000 of them), so a
//! sticking element's displacement stays exact and the level's change
//! inside a sub-step is an error of second order in its length.

use crate::error::{require_non_negative, require_positive};
use crate::interval::{displacement, each_held_substep};
use crate::{ParamError, Ramp};

/// The most elements a law holds (the FMUs declare this many).
pub const MAX_ELEMENTS: usize = 100;

/// The default element set (ours, for both laws): `n` elements of equal
/// stiffness `σ0/n` whose slip deflections grow evenly, `Δ_i = i·Δ_n/n`,
/// so that the virgin curve `F(x) = Σ min(k_i·x, k_i·Δ_i)` rises with
/// the initial stiffness `σ0` and bends over to `total` at `Δ_n`. Returns
/// `(k_i, k_i·Δ_i)`.
pub fn even_elements(n: usize, sigma0: f64, total: f64) -> (Vec<f64>, Vec<f64>) {
    let k = sigma0 / n as f64;
    // Σ k·i·Δ_n/n = k·Δ_n·(n + 1)/2 = total
    let last = 2.0 * total / (k * (n as f64 + 1.0));
    let w = (1..=n).map(|i| k * i as f64 * last / n as f64).collect();
    (vec![k; n], w)
}

/// Checks `n` element stiffnesses and their second array (named `second`).
fn validate_elements(k: &[f64], second: &[f64], name: &'static str) -> Result<(), ParamError> {
    let n = k.len();
    if n == 0 || n > MAX_ELEMENTS {
        return Err(ParamError::new(
            "n_elements",
            n as f64,
            format!("must be between 1 and {MAX_ELEMENTS}"),
        ));
    }
    if second.len() != n {
        return Err(ParamError::new(
            name,
            second.len() as f64,
            format!("needs {n} values, one per element"),
        ));
    }
    for (i, (&ki, &si)) in k.iter().zip(second).enumerate() {
        if !(ki.is_finite() && ki > 0.0) {
            return Err(ParamError::new(
                "k",
                ki,
                format!("element {}: must be finite and > 0", i + 1),
            ));
        }
        if !(si.is_finite() && si > 0.0) {
            return Err(ParamError::new(
                name,
                si,
                format!("element {}: must be finite and > 0", i + 1),
            ));
        }
        if !(si / ki).is_finite() || si / ki == 0.0 {
            return Err(ParamError::new(
                name,
                si,
                format!(
                    "element {}: its slip deflection {name}/k = {} is not a positive finite number",
                    i + 1,
                    si / ki
                ),
            ));
        }
    }
    Ok(())
}

/// `Σ F_i²/(2·k_i)`.
fn spring_energy(k: &[f64], f: &[f64]) -> f64 {
    k.iter().zip(f).map(|(k, f)| 0.5 * f * f / k).sum()
}

/// Maxwell-slip parameters: element stiffnesses `k` (N/m), slip forces
/// `w` (N), one per element, and the viscous coefficient `sigma2` (N·s/m).
#[derive(Clone, Debug, PartialEq)]
pub struct MaxwellSlipParams {
    pub k: Vec<f64>,
    pub w: Vec<f64>,
    pub sigma2: f64,
}

impl Default for MaxwellSlipParams {
    /// Ten even elements ([`even_elements`]) with the initial stiffness
    /// and Coulomb level of LuGre's 1995 set (σ0 = 1e5 N/m, `Σ W_i` =
    /// Fc = 1 N), no viscous term (σ2 = 0: the law as Lampaert et al.
    /// 2002 state it, rate-independent): the whole contact slides
    /// 1.82e-5 m after a reversal.
    fn default() -> Self {
        let (k, w) = even_elements(10, 1e5, 1.0);
        MaxwellSlipParams { k, w, sigma2: 0.0 }
    }
}

impl MaxwellSlipParams {
    /// `1 ≤ n ≤ MAX_ELEMENTS`; every `k_i`, `W_i` finite and positive;
    /// `σ2 ≥ 0`.
    pub fn validate(&self) -> Result<(), ParamError> {
        validate_elements(&self.k, &self.w, "W")?;
        require_non_negative("sigma2", self.sigma2)
    }
}

/// Maxwell-slip state: the element forces `F_i` (N) and each element's
/// mode: 0 sticking, `±1` sliding in that direction (at `±W_i`).
#[derive(Clone, Debug)]
pub struct MaxwellSlip {
    p: MaxwellSlipParams,
    f: Vec<f64>,
    mode: Vec<f64>,
}

/// How close to its slip level an element must be, relative to it, for
/// a Model Exchange event to start its slip (an integrator locates the
/// crossing to its own tolerance).
const SLIP_START_TOLERANCE: f64 = 1e-9;

/// `1`, `-1` or `0` (for 0 and NaN).
fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// The mode updates of a Model Exchange event, shared by both laws: an
/// element whose force reached `level(i)` in the direction of motion
/// starts slipping; a slipping element whose motion reversed (or
/// stopped) sticks. Returns whether a mode changed.
fn update_modes(f: &[f64], mode: &mut [f64], v: f64, level: impl Fn(usize) -> f64) -> bool {
    let s = sign(v);
    let mut changed = false;
    for i in 0..f.len() {
        let next = if mode[i] != 0.0 {
            if mode[i] == s {
                s
            } else {
                0.0
            }
        } else if s != 0.0 && s * f[i] >= level(i) * (1.0 - SLIP_START_TOLERANCE) {
            s
        } else {
            0.0
        };
        changed |= next != mode[i];
        mode[i] = next;
    }
    changed
}

/// Writes forces then modes.
fn write_forces_and_modes(f: &[f64], mode: &[f64], out: &mut [f64]) {
    let n = f.len();
    out[..n].copy_from_slice(f);
    out[n..].copy_from_slice(mode);
}

/// Restores forces (finite) and modes (each 0, 1 or −1) of law `law`.
fn read_forces_and_modes(
    law: &str,
    s: &[f64],
    f: &mut [f64],
    mode: &mut [f64],
) -> Result<(), String> {
    let n = f.len();
    if s.len() != 2 * n {
        return Err(format!(
            "{law} state has {} values (a force and a mode per element), got {}",
            2 * n,
            s.len()
        ));
    }
    if let Some(i) = s[..n].iter().position(|f| !f.is_finite()) {
        return Err(format!(
            "{law} state: element {} force {} is not finite",
            i + 1,
            s[i]
        ));
    }
    if let Some(i) = s[n..].iter().position(|m| ![0.0, 1.0, -1.0].contains(m)) {
        return Err(format!(
            "{law} state: element {} mode {} is not 0 (sticking), 1 or -1 (slipping)",
            i + 1,
            s[n + i]
        ));
    }
    f.copy_from_slice(&s[..n]);
    mode.copy_from_slice(&s[n..]);
    Ok(())
}

impl MaxwellSlip {
    /// A relaxed contact (every `F_i = 0`, every element sticking) with
    /// validated parameters.
    pub fn new(p: MaxwellSlipParams) -> Result<Self, ParamError> {
        p.validate()?;
        let n = p.k.len();
        Ok(MaxwellSlip {
            p,
            f: vec![0.0; n],
            mode: vec![0.0; n],
        })
    }

    pub fn params(&self) -> &MaxwellSlipParams {
        &self.p
    }

    /// The element forces `F_i`.
    pub fn element_forces(&self) -> &[f64] {
        &self.f
    }

    /// Advances over `[0, h]` with `v(τ) = v.value + v.slope·τ`: on each
    /// one-sign piece, `F_i ← F_i + k_i·Δx` clipped at `sgn(Δx)·W_i`
    /// (exact: the law depends on the path, not on its speed); an element
    /// clipped ends the piece sliding, any other sticking.
    pub fn step(&mut self, v: Ramp, h: f64) {
        crate::interval::each_one_sign_displacement(v, h, |s, u| {
            for i in 0..self.f.len() {
                let (k, w) = (self.p.k[i], self.p.w[i]);
                let moved = self.f[i] + s * k * u;
                if s * moved >= w {
                    self.f[i] = s * w;
                    self.mode[i] = s;
                } else {
                    self.f[i] = moved;
                    self.mode[i] = 0.0;
                }
            }
        });
    }

    /// Whether element `i` slides at velocity `v`: it slid into its slip
    /// force in the direction of `v`.
    pub fn slipping(&self, i: usize, v: f64) -> bool {
        self.mode[i] != 0.0 && self.mode[i] == sign(v)
    }

    /// The number of sliding elements at velocity `v`.
    pub fn slipping_count(&self, v: f64) -> usize {
        (0..self.f.len()).filter(|&i| self.slipping(i, v)).count()
    }

    /// `F = Σ F_i + σ2·v`.
    pub fn force(&self, v: f64) -> f64 {
        self.f.iter().sum::<f64>() + self.p.sigma2 * v
    }

    /// `Ḟ_i`: `k_i·v` sticking, 0 sliding.
    pub fn element_rate(&self, i: usize, v: f64) -> f64 {
        if self.slipping(i, v) {
            0.0
        } else {
            self.p.k[i] * v
        }
    }

    /// `(∂Ḟ_i/∂F_i, ∂Ḟ_i/∂v)`: `(0, k_i)` sticking, `(0, 0)` sliding.
    pub fn element_rate_partials(&self, i: usize, v: f64) -> (f64, f64) {
        if self.slipping(i, v) {
            (0.0, 0.0)
        } else {
            (0.0, self.p.k[i])
        }
    }

    /// The elastic energy of the elements, `Σ F_i²/(2·k_i)` (J).
    pub fn stored_energy(&self) -> f64 {
        spring_energy(&self.p.k, &self.f)
    }

    /// `P_diss = F·v − dE/dt = Σ_sliding F_i·v + σ2·v²` (W), which is
    /// `Σ_sliding W_i·|v| + σ2·v²`: never negative.
    pub fn dissipated_power(&self, v: f64) -> f64 {
        let sliding: f64 = (0..self.f.len())
            .filter(|&i| self.slipping(i, v))
            .map(|i| self.f[i])
            .sum();
        sliding * v + self.p.sigma2 * v * v
    }

    /// Model Exchange event handling ([`update_modes`] at the levels
    /// `W_i`). Returns whether a mode changed.
    pub fn update_modes(&mut self, v: f64) -> bool {
        let w = &self.p.w;
        update_modes(&self.f, &mut self.mode, v, |i| w[i])
    }

    /// Model Exchange event indicator of element `i`: `W_i − |F_i|` while
    /// it sticks (zero when it reaches its slip force), 1 while it slides
    /// (its switch back is the reversal, `v`'s own indicator).
    pub fn element_indicator(&self, i: usize, _v: f64) -> f64 {
        if self.mode[i] == 0.0 {
            self.p.w[i] - self.f[i].abs()
        } else {
            1.0
        }
    }

    /// Sets the element forces (Model Exchange states: an integrator may
    /// overshoot a slip force by its tolerance, which is kept).
    pub fn set_element_forces(&mut self, f: &[f64]) {
        self.f.copy_from_slice(f);
    }

    /// The state: `n` element forces, then `n` modes.
    pub fn state_len(&self) -> usize {
        2 * self.f.len()
    }

    pub fn write_state_into(&self, out: &mut [f64]) {
        write_forces_and_modes(&self.f, &self.mode, out);
    }

    pub fn state_is_finite(&self) -> bool {
        self.f.iter().all(|f| f.is_finite())
    }

    /// Restores forces (finite) and modes (each 0, 1 or −1).
    pub fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
        read_forces_and_modes("MaxwellSlip", s, &mut self.f, &mut self.mode)
    }
}

/// GMS parameters: element stiffnesses `k` (N/m) and weights `alpha`
/// (`Σ α_i = 1`), the Stribeck curve (`fc`, `fs` N, `vs` m/s, `delta`),
/// the attraction `c` (N/s), the total micro-damping `sigma1` (N·s/m,
/// element `i`'s share `σ1·k_i/Σ k_j`) and the viscous coefficient
/// `sigma2` (N·s/m).
#[derive(Clone, Debug, PartialEq)]
pub struct GmsParams {
    pub k: Vec<f64>,
    pub alpha: Vec<f64>,
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub delta: f64,
    pub c: f64,
    pub sigma1: f64,
    pub sigma2: f64,
}

impl Default for GmsParams {
    /// Ten even elements ([`even_elements`], weights `α_i = W_i/Fs`)
    /// with LuGre's 1995 set (σ0 = 1e5 N/m, Fc = 1 N, Fs = 1.5 N,
    /// vs = 1e-3 m/s, δ = 2, σ2 = 0.4 N·s/m) and `C = 100 N/s`: a
    /// frictional-lag time constant `s(v)/C` of 10 ms at the Coulomb
    /// level. `C` and the element spread are ours. No micro-damping
    /// (σ1 = 0: the law as it was before σ1).
    fn default() -> Self {
        let (fc, fs) = (1.0, 1.5);
        let (k, w) = even_elements(10, 1e5, fs);
        GmsParams {
            k,
            alpha: w.iter().map(|w| w / fs).collect(),
            fc,
            fs,
            vs: 1e-3,
            delta: 2.0,
            c: 100.0,
            sigma1: 0.0,
            sigma2: 0.4,
        }
    }
}

/// How far `Σ α_i` may be from 1.
const WEIGHT_SUM_TOLERANCE: f64 = 1e-9;

impl GmsParams {
    /// Elements as for Maxwell-slip with `Σ α_i = 1` (to 1e-9);
    /// `0 < Fc ≤ Fs`, `vs, δ, C > 0`, `σ1, σ2 ≥ 0`.
    pub fn validate(&self) -> Result<(), ParamError> {
        validate_elements(&self.k, &self.alpha, "alpha")?;
        let sum: f64 = self.alpha.iter().sum();
        if (sum - 1.0).abs() > WEIGHT_SUM_TOLERANCE {
            return Err(ParamError::new(
                "alpha",
                sum,
                format!(
                    "the weights of the {} elements sum to {sum}, must sum to 1",
                    self.alpha.len()
                ),
            ));
        }
        require_positive("Fc", self.fc)?;
        require_positive("Fs", self.fs)?;
        if self.fs < self.fc {
            return Err(ParamError::new(
                "Fs",
                self.fs,
                format!("must be >= Fc = {}", self.fc),
            ));
        }
        require_positive("vs", self.vs)?;
        require_positive("stribeck_exponent", self.delta)?;
        require_positive("C", self.c)?;
        require_non_negative("sigma1", self.sigma1)?;
        require_non_negative("sigma2", self.sigma2)
    }
}

/// GMS state: element forces `F_i` (N) and each element's mode: 0
/// sticking, `±1` slipping in that direction.
#[derive(Clone, Debug)]
pub struct Gms {
    p: GmsParams,
    /// `σ1/Σ k_j`: element `i`'s damping is `σ_i = damping·k_i`.
    damping: f64,
    f: Vec<f64>,
    mode: Vec<f64>,
}

impl Gms {
    /// A relaxed contact (every `F_i = 0`, every element sticking).
    pub fn new(p: GmsParams) -> Result<Self, ParamError> {
        p.validate()?;
        let n = p.k.len();
        Ok(Gms {
            damping: p.sigma1 / p.k.iter().sum::<f64>(),
            p,
            f: vec![0.0; n],
            mode: vec![0.0; n],
        })
    }

    pub fn params(&self) -> &GmsParams {
        &self.p
    }

    /// The element forces `F_i`.
    pub fn element_forces(&self) -> &[f64] {
        &self.f
    }

    /// The Stribeck curve `s(v) = Fc + (Fs − Fc)·e^(−|v/vs|^δ)`.
    pub fn level(&self, v: f64) -> f64 {
        let p = &self.p;
        p.fc + (p.fs - p.fc) * (-(v.abs() / p.vs).powf(p.delta)).exp()
    }

    /// `ds/dv`.
    fn level_slope(&self, v: f64) -> f64 {
        let p = &self.p;
        if v == 0.0 {
            return 0.0;
        }
        let r = v.abs() / p.vs;
        -(p.fs - p.fc) * (-r.powf(p.delta)).exp() * p.delta * r.powf(p.delta - 1.0) / p.vs
            * v.signum()
    }

    /// Whether element `i` slips (its mode is a direction).
    pub fn slipping(&self, i: usize) -> bool {
        self.mode[i] != 0.0
    }

    /// The slip level of element `i` at rest, `α_i·Fs` (its largest).
    pub fn static_level(&self, i: usize) -> f64 {
        self.p.alpha[i] * self.p.fs
    }

    /// The number of slipping elements.
    pub fn slipping_count(&self) -> usize {
        self.mode.iter().filter(|m| **m != 0.0).count()
    }

    /// Advances over `[0, h]` with `v(τ) = v.value + v.slope·τ` (the
    /// module's documentation): pieces of one sign, sub-steps of a held
    /// mean velocity, each element exact over each sub-step.
    pub fn step(&mut self, v: Ramp, h: f64) {
        each_held_substep(v, h, self.p.vs, |s, t0, t1| {
            let dx = displacement(v, t0, t1);
            self.advance_held(s, dx / (t1 - t0), t1 - t0);
        });
    }

    /// Every element over `tau` seconds at the held velocity `v` of sign
    /// `s`: a reversal sticks the slipping elements; a sticking element
    /// loads at `k_i·v` up to its level, then slips for the rest.
    fn advance_held(&mut self, s: f64, v: f64, tau: f64) {
        let level = self.level(v);
        let rate = self.p.c / level;
        for i in 0..self.f.len() {
            let (k, target) = (self.p.k[i], s * self.p.alpha[i] * level);
            let mut left = tau;
            if self.mode[i] != 0.0 && self.mode[i] != s {
                self.mode[i] = 0.0;
            }
            if self.mode[i] == 0.0 {
                let gap = (target - self.f[i]) * s; // ≥ 0 while below the level
                let reach = gap / (k * v.abs());
                if gap > 0.0 && reach >= left {
                    self.f[i] += k * v * left;
                    continue;
                }
                if gap > 0.0 {
                    self.f[i] = target;
                    left -= reach;
                }
                self.mode[i] = s;
            }
            self.f[i] = target + (self.f[i] - target) * (-rate * left).exp();
        }
    }

    /// `F = Σ F_i + Σ σ_i·ż_i + σ2·v` ([`Gms::damping_force`]; with
    /// σ1 = 0, `Σ F_i + σ2·v` as without the term).
    pub fn force(&self, v: f64) -> f64 {
        let elements = self.f.iter().sum::<f64>();
        if self.p.sigma1 == 0.0 {
            return elements + self.p.sigma2 * v;
        }
        elements + self.damping_force(v) + self.p.sigma2 * v
    }

    /// `σ1/Σ k_j`, the damping of an element per unit of its stiffness:
    /// `σ_i = σ1·k_i/Σ k_j` (a uniform damping ratio, as LuGre's σ1
    /// relative to σ0).
    pub fn damping_per_stiffness(&self) -> f64 {
        self.damping
    }

    /// The micro-damping force `Σ σ_i·ż_i` (N) in the current modes, with
    /// `ż_i = Ḟ_i/k_i` element `i`'s deflection rate ([`Gms::element_rate`]:
    /// `v` sticking, `C·(sgn(v)·α_i − F_i/s(v))/k_i` slipping). As
    /// `σ_i/k_i = σ1/Σ k_j` for every element, it is `σ1/Σ k_j·Σ Ḟ_i`.
    pub fn damping_force(&self, v: f64) -> f64 {
        // the rates of `element_rate`, the level evaluated once
        let level = self.level(v);
        let rates: f64 = (0..self.f.len())
            .map(|i| self.rate_at_level(i, v, level))
            .sum();
        self.damping * rates
    }

    /// `Ḟ_i` in the current modes: `k_i·v` sticking,
    /// `C·(sgn(v)·α_i − F_i/s(v))` slipping.
    pub fn element_rate(&self, i: usize, v: f64) -> f64 {
        if self.mode[i] == 0.0 || v == 0.0 {
            return if self.mode[i] == 0.0 {
                self.p.k[i] * v
            } else {
                0.0
            };
        }
        self.rate_at_level(i, v, self.level(v))
    }

    /// [`Gms::element_rate`] with `s(v)` given as `level`.
    fn rate_at_level(&self, i: usize, v: f64, level: f64) -> f64 {
        if self.mode[i] == 0.0 {
            return self.p.k[i] * v;
        }
        if v == 0.0 {
            return 0.0;
        }
        self.p.c * (v.signum() * self.p.alpha[i] - self.f[i] / level)
    }

    /// `(∂Ḟ_i/∂F_i, ∂Ḟ_i/∂v)` in the current modes.
    pub fn element_rate_partials(&self, i: usize, v: f64) -> (f64, f64) {
        if self.mode[i] == 0.0 {
            return (0.0, self.p.k[i]);
        }
        if v == 0.0 {
            return (0.0, 0.0); // slipping at rest: Ḟ_i = 0 until the event sticks it
        }
        let s = self.level(v);
        (
            -self.p.c / s,
            self.p.c * self.f[i] * self.level_slope(v) / (s * s),
        )
    }

    /// Model Exchange event handling ([`update_modes`] at the levels
    /// `α_i·s(v)`). Returns whether a mode changed.
    pub fn update_modes(&mut self, v: f64) -> bool {
        let level = self.level(v);
        let alpha = &self.p.alpha;
        update_modes(&self.f, &mut self.mode, v, |i| alpha[i] * level)
    }

    /// Model Exchange event indicator of element `i`: `α_i·s(v) − |F_i|`
    /// while it sticks (zero when it reaches its level), 1 while it slips
    /// (its switch back is the reversal, `v`'s own indicator).
    pub fn element_indicator(&self, i: usize, v: f64) -> f64 {
        if self.mode[i] == 0.0 {
            self.p.alpha[i] * self.level(v) - self.f[i].abs()
        } else {
            1.0
        }
    }

    /// Sets the element forces (Model Exchange states).
    pub fn set_element_forces(&mut self, f: &[f64]) {
        self.f.copy_from_slice(f);
    }

    /// The elastic energy of the elements, `Σ F_i²/(2·k_i)` (J).
    pub fn stored_energy(&self) -> f64 {
        spring_energy(&self.p.k, &self.f)
    }

    /// `P_diss = F·v − dE/dt = Σ_slipping F_i·(v − ż_i) + Σ σ_i·ż_i·v +
    /// σ2·v²` (W), `ż_i = Ḟ_i/k_i`: a sticking element's spring takes
    /// what the motion does on it (`ż_i = v`), its damper dissipates
    /// `σ_i·v²`. A slipping element whose force is attracted faster than
    /// the motion loads it returns energy: the law dissipates over a
    /// cycle, not at every instant.
    pub fn dissipated_power(&self, v: f64) -> f64 {
        let elements: f64 = (0..self.f.len())
            .filter(|&i| self.mode[i] != 0.0)
            .map(|i| self.f[i] * (v - self.element_rate(i, v) / self.p.k[i]))
            .sum();
        if self.p.sigma1 == 0.0 {
            return elements + self.p.sigma2 * v * v;
        }
        elements + self.damping_force(v) * v + self.p.sigma2 * v * v
    }

    /// The state: `n` element forces, then `n` modes.
    pub fn state_len(&self) -> usize {
        2 * self.f.len()
    }

    pub fn write_state_into(&self, out: &mut [f64]) {
        write_forces_and_modes(&self.f, &self.mode, out);
    }

    pub fn state_is_finite(&self) -> bool {
        self.f.iter().all(|f| f.is_finite())
    }

    /// Restores forces (finite) and modes (each 0, 1 or −1).
    pub fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
        read_forces_and_modes("GMS", s, &mut self.f, &mut self.mode)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn maxwell() -> MaxwellSlip {
        MaxwellSlip::new(MaxwellSlipParams::default()).unwrap()
    }

    /// Moves a rate-independent law to position `x` (from `from`) in one
    /// held-velocity step.
    fn move_ms(l: &mut MaxwellSlip, from: f64, x: f64) {
        l.step(Ramp::constant(x - from), 1.0);
    }

    /// The virgin curve `Σ min(k_i·x, W_i)` and Masing's rule: after a
    /// reversal at `(x_r, F_r)` the curve is `F_r − 2·F_v((x_r − x)/2)`
    /// (elastic-perfectly-plastic elements in parallel, Iwan 1966).
    #[test]
    fn virgin_curve_and_masing_reversal_are_closed_forms() {
        let p = MaxwellSlipParams::default();
        let virgin = |x: f64| -> f64 {
            p.k.iter()
                .zip(&p.w)
                .map(|(k, w)| (k * x).clamp(-w, *w))
                .sum()
        };
        let mut l = maxwell();
        let mut x = 0.0;
        for i in 1..=40 {
            let next = i as f64 * 0.6e-6;
            move_ms(&mut l, x, next);
            x = next;
            assert!((l.force(0.0) - virgin(x)).abs() <= 1e-12, "{x}");
        }
        let (xr, fr) = (x, l.force(0.0));
        for i in 1..=60 {
            let next = xr - i as f64 * 0.6e-6;
            move_ms(&mut l, x, next);
            x = next;
            let want = fr - 2.0 * virgin((xr - x) / 2.0);
            assert!(
                (l.force(0.0) - want).abs() <= 1e-12,
                "{x}: {} {want}",
                l.force(0.0)
            );
        }
    }

    /// A minor loop inside pre-sliding is erased when the path passes its
    /// start again: from there the force is the one without the loop.
    #[test]
    fn minor_loops_are_wiped_out() {
        let path_with_loop = [0.0, 8e-6, 5e-6, 8e-6, 12e-6, 3e-6];
        let path_without = [0.0, 12e-6, 3e-6];
        let run = |path: &[f64]| {
            let mut l = maxwell();
            for w in path.windows(2) {
                move_ms(&mut l, w[0], w[1]);
            }
            l.force(0.0)
        };
        assert!((run(&path_with_loop) - run(&path_without)).abs() <= 1e-12);
        // inside the loop the memory shows: a different force at 7 µm
        let mut a = maxwell();
        move_ms(&mut a, 0.0, 7e-6);
        let mut b = maxwell();
        move_ms(&mut b, 0.0, 12e-6);
        move_ms(&mut b, 12e-6, 7e-6);
        assert!((a.force(0.0) - b.force(0.0)).abs() > 0.1);
    }

    #[test]
    fn maxwell_slip_energy_balances() {
        let mut l = maxwell();
        let (h, n) = (1e-4, 40_000);
        let (mut work, mut dissipated) = (0.0, 0.0);
        let e0 = l.stored_energy();
        for j in 0..n {
            let t = j as f64 * h;
            let v = Ramp::new(
                2e-4 * (6.0 * t).cos(),
                -2e-4 * 6.0 * (6.0 * (t + 0.5 * h)).sin(),
            );
            let vm = v.at(0.5 * h);
            // midpoint rule for F·v and P_diss on the state at mid-step
            let mut mid = l.clone();
            mid.step(v, 0.5 * h);
            work += mid.force(vm) * vm * h;
            dissipated += mid.dissipated_power(vm) * h;
            l.step(v, h);
        }
        let balance = work - dissipated - (l.stored_energy() - e0);
        assert!(balance.abs() <= 1e-3 * work.abs(), "{balance} of {work}");
    }

    fn gms() -> Gms {
        Gms::new(GmsParams::default()).unwrap()
    }

    /// In gross sliding every element slips and `Σ F_i` obeys
    /// `dF/dt = C·(1 − F/s(v))`: at a held velocity, `s + (F0 − s)·e^(−C·t/s)`.
    #[test]
    fn gross_sliding_relaxes_with_the_time_constant_s_over_c() {
        let mut l = gms();
        let v = 5e-3;
        l.step(Ramp::constant(v), 0.05); // every element slipping
        assert_eq!(l.slipping_count(), 10);
        let s = l.level(v);
        let f0 = l.force(v) - 0.4 * v;
        for j in 1..=20 {
            l.step(Ramp::constant(v), 1e-3);
            let t = j as f64 * 1e-3;
            let want = s + (f0 - s) * (-l.params().c * t / s).exp();
            assert!((l.force(v) - 0.4 * v - want).abs() <= 1e-12, "{t}");
        }
        // and at the Stribeck level once settled
        l.step(Ramp::constant(v), 1.0);
        assert!((l.force(v) - s - 0.4 * v).abs() <= 1e-12);
    }

    /// Under a velocity that ramps, the step equals many short held steps
    /// (the exactness of the held update, the order of the ramp's).
    #[test]
    fn ramped_steps_converge_to_fine_held_steps() {
        let ramp = Ramp::new(-2e-3, 3e-1);
        let h = 2e-2;
        let mut coarse = gms();
        coarse.step(ramp, h);
        let mut fine = gms();
        let n = 200_000;
        for j in 0..n {
            let a = j as f64 * h / n as f64;
            fine.step(
                Ramp::constant(ramp.at(a + 0.5 * h / n as f64)),
                h / n as f64,
            );
        }
        let diff = (coarse.force(0.0) - fine.force(0.0)).abs();
        assert!(diff <= 1e-6 * 1.5, "{diff}");
    }

    /// GMS in pre-sliding (far below its Stribeck velocity) is the
    /// Maxwell-slip model with `W_i = α_i·Fs`, and wipes out minor loops.
    #[test]
    fn gms_pre_sliding_wipes_out_minor_loops() {
        let path_with_loop = [0.0, 8e-6, 5e-6, 8e-6, 12e-6, 3e-6];
        let path_without = [0.0, 12e-6, 3e-6];
        // slow: 1e-8 m/s, |v/vs| = 1e-5, so s(v) = Fs to 1e-10
        let run = |path: &[f64]| {
            let mut l = gms();
            for w in path.windows(2) {
                l.step(
                    Ramp::constant((w[1] - w[0]).signum() * 1e-8),
                    (w[1] - w[0]).abs() / 1e-8,
                );
            }
            l.force(0.0)
        };
        let (a, b) = (run(&path_with_loop), run(&path_without));
        assert!((a - b).abs() <= 1e-9, "{a} {b}");
    }

    fn gms_damped(sigma1: f64) -> Gms {
        Gms::new(GmsParams {
            sigma1,
            ..GmsParams::default()
        })
        .unwrap()
    }

    /// Sticking throughout (the motion below every element's slip
    /// deflection), each element's deflection rate is `v`: the damping
    /// adds `Σ σ_i·v = σ1·v`, `F = Σ k_i·x + σ1·v + σ2·v`.
    #[test]
    fn sticking_contact_adds_sigma1_v() {
        let sigma1 = 37.5;
        for v in [3e-5, -2e-5, 4e-3] {
            let mut l = gms_damped(sigma1);
            let p = l.params().clone();
            let (h, n) = (1e-5, 30);
            // 30·1e-5·4e-3 = 1.2e-6 m, below the first element's
            // Δ_1 = α_1·Fs/k_1 = 2.7e-6 m
            for _ in 0..n {
                l.step(Ramp::constant(v), h);
            }
            assert_eq!(l.slipping_count(), 0, "{v}");
            let x = v * h * n as f64;
            let stiffness: f64 = p.k.iter().sum();
            let want = stiffness * x + sigma1 * v + p.sigma2 * v;
            let got = l.force(v);
            println!(
                "v {v}: F {got}, relative error {:e}",
                (got - want).abs() / want.abs()
            );
            assert!(
                (got - want).abs() <= 1e-12 * want.abs(),
                "{v}: {got} {want}, {:e} relative",
                (got - want).abs() / want.abs()
            );
            // the damping alone
            let d = l.damping_force(v);
            assert!((d - sigma1 * v).abs() <= 1e-12 * (sigma1 * v).abs(), "{d}");
        }
    }

    /// In gross sliding every element slips: the damping is
    /// `Σ σ_i·C·(α_i − F_i/s)/k_i` (`v > 0`), and as every element
    /// relaxes with the same time constant `s/C`, it decays as
    /// `e^(−C·t/s)` and vanishes once the forces are at their levels.
    /// (Slid into from rest at one velocity, every element reaches its
    /// level sticking and the term is 0 at once: the run slides at
    /// 5e-4 m/s, where `s` = 1.39 N, then at 5e-3 m/s, `s` = 1 N.)
    #[test]
    fn gross_sliding_damping_decays_with_the_forces() {
        let sigma1 = 50.0;
        let v = 5e-3;
        let mut l = gms_damped(sigma1);
        l.step(Ramp::constant(5e-4), 0.1); // every element slipping
        assert_eq!(l.slipping_count(), 10);
        let p = l.params().clone();
        let total_k: f64 = p.k.iter().sum();
        let s = l.level(v);
        let by_elements = |l: &Gms| -> f64 {
            let f = l.element_forces();
            (0..f.len())
                .map(|i| sigma1 * p.k[i] / total_k * p.c * (p.alpha[i] - f[i] / s) / p.k[i])
                .sum()
        };
        let d0 = by_elements(&l);
        assert!(d0 < -1e-2, "{d0}: the forces are still moving");
        let mut worst: f64 = 0.0;
        for j in 0..=20 {
            if j > 0 {
                l.step(Ramp::constant(v), 1e-3);
            }
            let want = by_elements(&l);
            let f_sum: f64 = l.element_forces().iter().sum();
            let from_force = l.force(v) - f_sum - p.sigma2 * v;
            let decayed = d0 * (-p.c * j as f64 * 1e-3 / s).exp();
            worst = worst
                .max((l.damping_force(v) - want).abs() / want.abs())
                .max((from_force - want).abs() / want.abs())
                .max((decayed - want).abs() / want.abs());
        }
        println!("damping from {d0:e} N: worst relative error {worst:e}");
        assert!(worst <= 1e-9, "{worst:e}");
        l.step(Ramp::constant(v), 1.0); // 100 time constants
        let d = l.damping_force(v);
        assert!(d.abs() <= 1e-12, "{d:e}");
        assert!((l.force(v) - s - p.sigma2 * v).abs() <= 1e-12);
    }

    /// `∫F·v dt = ∫P_diss dt + ΔE_stored` through gross sliding and
    /// reversals, without and with the micro-damping (whose `Σ σ_i·ż_i·v`
    /// is in `P_diss`).
    #[test]
    fn gms_energy_balances() {
        for sigma1 in [0.0, 50.0] {
            let mut l = gms_damped(sigma1);
            let (h, n) = (1e-5, 200_000);
            let (mut work, mut dissipated, mut damping) = (0.0, 0.0, 0.0);
            let e0 = l.stored_energy();
            for j in 0..n {
                let t = j as f64 * h;
                let v = Ramp::new(
                    2e-3 * (6.0 * t).cos(),
                    -2e-3 * 6.0 * (6.0 * (t + 0.5 * h)).sin(),
                );
                let vm = v.at(0.5 * h);
                // midpoint rule for F·v and P_diss on the state at mid-step
                let mut mid = l.clone();
                mid.step(v, 0.5 * h);
                work += mid.force(vm) * vm * h;
                dissipated += mid.dissipated_power(vm) * h;
                damping += mid.damping_force(vm) * vm * h;
                l.step(v, h);
            }
            let balance = work - dissipated - (l.stored_energy() - e0);
            println!(
                "sigma1 {sigma1}: balance {:e} of the work {work:e}, damping's share {:e}",
                balance.abs() / work.abs(),
                damping / work
            );
            assert!(balance.abs() <= 1e-5 * work.abs(), "{balance} of {work}");
            if sigma1 > 0.0 {
                // ten times the tolerance: a P_diss without the term fails
                assert!(damping > 1e-4 * work, "{damping} of {work}");
            }
        }
    }

    /// With σ1 = 0 the force and the power are the sums without the term
    /// (the law as before σ1), bit for bit.
    #[test]
    fn zero_sigma1_leaves_the_force_as_it_was() {
        let mut l = gms();
        for (v, h) in [(4e-3, 0.03), (-1e-3, 0.01), (0.0, 0.01), (2e-4, 0.002)] {
            l.step(Ramp::constant(v), h);
            let sum: f64 = l.element_forces().iter().sum();
            assert_eq!(l.force(v).to_bits(), (sum + 0.4 * v).to_bits());
            assert_eq!(l.damping_per_stiffness(), 0.0);
        }
    }

    #[test]
    fn validation_names_the_parameter_and_element() {
        let mut p = GmsParams::default();
        p.alpha[3] = 0.5;
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("alpha") && e.contains("sum to"), "{e}");
        for bad in [-1.0, f64::NAN, f64::INFINITY] {
            let p = GmsParams {
                sigma1: bad,
                ..GmsParams::default()
            };
            let e = p.validate().unwrap_err().to_string();
            assert!(e.contains(&format!("sigma1 = {bad}")), "{e}");
        }
        let mut p = MaxwellSlipParams::default();
        p.k[2] = -1.0;
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("k") && e.contains("element 3"), "{e}");
        let p = MaxwellSlipParams {
            k: vec![],
            w: vec![],
            sigma2: 0.0,
        };
        assert!(p.validate().unwrap_err().to_string().contains("n_elements"));
    }

    #[test]
    fn states_round_trip_and_refuse_bad_values() {
        let mut l = gms();
        l.step(Ramp::constant(3e-3), 0.01);
        let mut saved = vec![0.0; l.state_len()];
        l.write_state_into(&mut saved);
        let mut other = gms();
        other.state_from_slice(&saved).unwrap();
        assert_eq!(other.force(1e-3), l.force(1e-3));
        saved[15] = 0.5;
        assert!(other
            .state_from_slice(&saved)
            .unwrap_err()
            .contains("mode 0.5"));
        let mut m = maxwell();
        let e = m.state_from_slice(&[2.0; 10]).unwrap_err();
        assert!(e.contains("20 values"), "{e}");
    }
}
