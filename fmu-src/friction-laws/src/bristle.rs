//! Pre-sliding bristle model (Appels & Herder, TU Delft; their Matlab code
//! `Initial_bristle_placement.m`, `New_model.m`, `New_model_hysteresis.m` in
//! Appendix C; docs/models.md "Pre-sliding bristle model").
//!
//! A static, position-driven model: `N` bristles of stiffness
//! `σb = σ_ini/N` with random pre-deflections `δi`.
//! - Initialisation (the paper's code): `δi ~ Normal(0, (2/3)·δmax)`, settle by
//!   subtracting the mean; a bristle with `|δi| > δmax` is redrawn, the set
//!   settled again and the check restarted, until all are connected.
//! - Realisation: moving by `dx` adds `dx` to every connected bristle; one
//!   reaching `|δi| ≥ δmax` disconnects and keeps contributing the constant
//!   `±σb·δmax` (sign of its direction).
//!   `F = σb·(Σ_connected δi + (n₊ − n₋)·δmax)`; all disconnected:
//!   `F = σ_ini·δmax = μc·Fn` (the Coulomb level).
//! - Reversal (derived here, see below): when the motion reverses,
//!   before the reverse increment is applied every disconnected bristle
//!   reconnects at `δ = s·(δmax − |r|)`, `s` its disconnection sign,
//!   `r ~ Normal(x_rel, x_rel/3)` (the paper's eq. 13 and
//!   `New_model_hysteresis.m`, "reconnected in the direction that leads to
//!   a decrease in strain").
//!
//! The paper triggers reconnection when the actuation force is removed and
//! then lets the body settle; driven by an imposed displacement the body
//! cannot settle, so here the reconnection happens at a reversal of the
//! imposed motion and no settling shift is applied (the imposed position
//! stays the input). This gives a force drop of `σb·Σ|r|` at the reversal
//! point, after which the contact unloads with the full stiffness `σ_ini`.
//!
//! Data layout: the bristles in contact are kept as offsets `d` sorted
//! ascending with one common shift `X = x − x_ref` (`δi = di + X`), and
//! their prefix sums. Moving in one direction disconnects bristles from one
//! end only (the top for `dx > 0`, the bottom for `dx < 0`), so a monotone
//! move costs a binary search plus the bristles that disconnect, and the
//! force is `O(1)` from the prefix sums. A reversal rebuilds the sorted
//! offsets (`O(N + k log k)` for `k` reconnecting bristles). Each bristle's
//! relaxation `|r|` is drawn when it disconnects, so evaluating a tentative
//! move ([`Bristle::force_at`]) needs no random numbers.

use crate::error::require_positive;
use crate::rng::Rng;
use crate::{ParamError, Ramp};

/// Values of the state before the bristles' (see [`Bristle::write_state_into`]).
const STATE_HEAD: usize = 16;

/// Largest bristle count accepted (memory guard: 3 `f64` per bristle).
pub const MAX_BRISTLES: usize = 10_000_000;

/// Parameters of the pre-sliding bristle model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BristleParams {
    /// Initial (total) tangential stiffness σ_ini (N/m).
    pub sigma_ini: f64,
    /// Deflection at which a bristle disconnects, δmax (m).
    pub delta_max: f64,
    /// Number of bristles N.
    pub n_bristles: usize,
    /// Mean reconnection relaxation μ2 = x_rel (m); standard deviation x_rel/3.
    pub x_rel: f64,
    /// Seed of the random realisation.
    pub seed: u64,
}

impl BristleParams {
    /// Parameters from the load, as the paper's code does:
    /// `N = round(c·μc·Fn)`, `σ_ini = μc·Fn/δmax` (so the sliding level is
    /// `σ_ini·δmax = μc·Fn`).
    pub fn from_load(
        c: f64,
        mu_c: f64,
        normal_force: f64,
        delta_max: f64,
        x_rel: f64,
        seed: u64,
    ) -> Self {
        let n = (c * mu_c * normal_force).round();
        // Out-of-range counts map to 0 or beyond the maximum and fail
        // validation with the computed number.
        let n_bristles = if n.is_finite() && n >= 0.0 {
            if n > MAX_BRISTLES as f64 {
                MAX_BRISTLES + 1
            } else {
                n as usize
            }
        } else {
            0
        };
        BristleParams {
            sigma_ini: mu_c * normal_force / delta_max,
            delta_max,
            n_bristles,
            x_rel,
            seed,
        }
    }

    /// σ_ini > 0, δmax > 0, 1 ≤ N ≤ 10⁷, 0 ≤ x_rel < δmax, all finite.
    pub fn validate(&self) -> Result<(), ParamError> {
        require_positive("sigma_ini", self.sigma_ini)?;
        require_positive("delta_max", self.delta_max)?;
        if self.n_bristles < 1 || self.n_bristles > MAX_BRISTLES {
            return Err(ParamError::new(
                "n_bristles",
                self.n_bristles as f64,
                format!("must be in 1..={MAX_BRISTLES}"),
            ));
        }
        if !(self.x_rel.is_finite() && self.x_rel >= 0.0 && self.x_rel < self.delta_max) {
            return Err(ParamError::new(
                "x_rel",
                self.x_rel,
                format!("must be >= 0 and < delta_max = {}", self.delta_max),
            ));
        }
        Ok(())
    }
}

impl Default for BristleParams {
    /// Appels & Herder (Table 3, Simulation 1): m = 0.352 kg, g = 9.81 m/s²,
    /// c = 500, μc = 0.0633, δmax = 1.5584e-8 m, x_rel = 4.4206e-9 m,
    /// random seed 1, through [`BristleParams::from_load`] (N = 109,
    /// σ_ini ≈ 1.4026e7 N/m).
    fn default() -> Self {
        BristleParams::from_load(500.0, 0.0633, 0.352 * 9.81, 1.5584e-8, 4.4206e-9, 1)
    }
}

/// Result of evaluating a (possibly tentative) configuration.
struct Eval {
    force: f64,
    n_connected: usize,
    /// The elastic energy held after the move (J).
    energy: f64,
}

/// Pre-sliding bristle model state.
#[derive(Clone, Debug)]
pub struct Bristle {
    p: BristleParams,
    sigma_b: f64,
    rng: Rng,
    /// Internal (last imposed) position.
    x: f64,
    /// Position at which the offsets `d` were taken.
    x_ref: f64,
    /// Direction of the last non-zero move: 1, −1, or 0 before any move.
    dir: i8,
    /// Offsets, sorted ascending; `d[lo..hi]` are connected.
    d: Vec<f64>,
    /// `prefix[k] = d[0] + … + d[k−1]`, summed in order.
    prefix: Vec<f64>,
    /// Pre-drawn relaxation `|r|` of each disconnected position.
    relax: Vec<f64>,
    lo: usize,
    hi: usize,
    /// The elastic energy held in the bristles (J),
    /// `σb/2·(Σ_connected δi² + n_disconnected·δmax²)`, carried along each
    /// move (recomputed at each reversal, where the offsets are rebuilt
    /// anyway).
    energy: f64,
    /// The mean power dissipated over the last [`Bristle::step`] (W).
    step_power: f64,
    /// Buffers a reversal rebuilds the offsets in, kept so that repeated
    /// reversals of many bristles allocate (and fault in) no new memory.
    work: Workspace,
}

/// Spare buffers of [`Bristle::move_to`]'s reversal (boxed, so that a
/// bristle model stays small until its first reversal). Not part of the
/// state: a clone starts without.
#[derive(Debug, Default)]
struct Workspace(Option<Box<Buffers>>);

impl Clone for Workspace {
    fn clone(&self) -> Self {
        Workspace(None)
    }
}

#[derive(Debug, Default)]
struct Buffers {
    back: Vec<f64>,
    keys: Vec<u64>,
    scratch: Vec<u64>,
    d: Vec<f64>,
    prefix: Vec<f64>,
}

/// Sort `v` ascending in the order of [`f64::total_cmp`], with the same
/// result as `v.sort_unstable_by(f64::total_cmp)` (a sorted sequence of
/// numbers is unique, bit for bit), in `O(N)`: a least-significant-digit
/// radix sort, 8 bits per pass, on the keys `total_cmp` compares (the bits
/// with the sign bit flipped for positive numbers, all bits flipped for
/// negative ones), skipping the digits every key shares (the high ones, for
/// deflections of one magnitude). A comparison sort takes most of the
/// reversal's time from about 10⁴ bristles on; short slices use it still.
fn sort_total(v: &mut [f64], keys: &mut Vec<u64>, scratch: &mut Vec<u64>) {
    if v.len() < 256 {
        v.sort_unstable_by(f64::total_cmp);
        return;
    }
    let key = |x: f64| {
        let b = x.to_bits();
        if b >> 63 == 1 {
            !b
        } else {
            b | (1 << 63)
        }
    };
    keys.clear();
    keys.extend(v.iter().map(|&x| key(x)));
    scratch.clear();
    scratch.resize(keys.len(), 0);
    // the histograms of all eight digits in one pass
    let mut counts = [[0usize; 256]; 8];
    for k in keys.iter() {
        for (pass, c) in counts.iter_mut().enumerate() {
            c[((k >> (8 * pass)) & 0xff) as usize] += 1;
        }
    }
    for (pass, c) in counts.iter_mut().enumerate() {
        if c.contains(&keys.len()) {
            continue; // every key has this digit: the pass would not move anything
        }
        let shift = 8 * pass;
        let mut start = 0;
        for count in c.iter_mut() {
            let n = *count;
            *count = start;
            start += n;
        }
        for &k in keys.iter() {
            let digit = ((k >> shift) & 0xff) as usize;
            scratch[c[digit]] = k;
            c[digit] += 1;
        }
        std::mem::swap(keys, scratch);
    }
    for (x, &k) in v.iter_mut().zip(keys.iter()) {
        let b = if k >> 63 == 1 { k & !(1 << 63) } else { !k };
        *x = f64::from_bits(b);
    }
}

fn prefix_sums(d: &[f64]) -> Vec<f64> {
    let mut p = Vec::with_capacity(d.len() + 1);
    prefix_sums_into(d, &mut p);
    p
}

/// `p[k] = d[0] + … + d[k−1]`, summed in order, into `p` (cleared first).
fn prefix_sums_into(d: &[f64], p: &mut Vec<f64>) {
    p.clear();
    let mut s = 0.0;
    p.push(s);
    for &v in d {
        s += v;
        p.push(s);
    }
}

impl Bristle {
    /// Places the bristles as the paper's `Initial_bristle_placement.m`.
    pub fn new(p: BristleParams) -> Result<Self, ParamError> {
        p.validate()?;
        let n = p.n_bristles;
        let mut rng = Rng::new(p.seed);
        let mut d = initial_placement(&mut rng, n, p.delta_max);
        sort_total(&mut d, &mut Vec::new(), &mut Vec::new());
        let prefix = prefix_sums(&d);
        let mut b = Bristle {
            p,
            sigma_b: p.sigma_ini / n as f64,
            rng,
            x: 0.0,
            x_ref: 0.0,
            dir: 0,
            d,
            prefix,
            relax: vec![0.0; n],
            lo: 0,
            hi: n,
            energy: 0.0,
            step_power: 0.0,
            work: Workspace::default(),
        };
        b.energy = b.energy_from_scratch();
        Ok(b)
    }

    /// `σb/2·(Σ_connected δi² + n_disconnected·δmax²)` by summing over the
    /// bristles, `O(N)`. A disconnected bristle keeps its deflection
    /// `±δmax` (it keeps pulling with `σb·δmax`): it holds its energy while
    /// it slides, as an elasto-slide element does.
    fn energy_from_scratch(&self) -> f64 {
        self.energy_of(&self.d, self.lo, self.hi, self.x - self.x_ref)
    }

    /// [`Bristle::energy_from_scratch`] for the offsets `d` with `lo..hi`
    /// connected at shift `shift`.
    fn energy_of(&self, d: &[f64], lo: usize, hi: usize, shift: f64) -> f64 {
        let connected: f64 = d[lo..hi]
            .iter()
            .map(|&di| (di + shift) * (di + shift))
            .sum();
        let disconnected = (self.p.n_bristles - (hi - lo)) as f64;
        let dm = self.p.delta_max;
        0.5 * self.sigma_b * (connected + disconnected * dm * dm)
    }

    /// The energy the reversal reconnection releases: each disconnected
    /// bristle drops from `δmax` to `δmax − |r|`, losing
    /// `σb/2·(δmax² − (δmax − |r|)²)` (J) at once, at rest: an impulse of
    /// dissipation no instantaneous power can carry.
    fn reconnection_loss(&self) -> f64 {
        let dm = self.p.delta_max;
        let n = self.p.n_bristles;
        let lost: f64 = (self.hi..n)
            .chain(0..self.lo)
            .map(|k| {
                let r = self.relax[k];
                r * (2.0 * dm - r)
            })
            .sum();
        0.5 * self.sigma_b * lost
    }

    /// The change of the stored energy and the energy dissipated by a
    /// monotone move in direction `s` from shift `xa` to `xb` that takes
    /// the connected range `range` of the offsets `d` to `cut`:
    /// - a bristle still connected stores `σb/2·((d + xb)² − (d + xa)²)`,
    ///   summed in `O(1)` from the prefix sums as
    ///   `σb/2·(xb − xa)·(2·Σd + n·(xa + xb))`;
    /// - one that disconnects on the way stores up to `σb/2·δmax²` and
    ///   then slides from its disconnection shift `s·δmax − d` to `xb`
    ///   against `σb·δmax`;
    /// - one disconnected before (all on the side `s`: a reversal
    ///   reconnects the others) slides all of `|xb − xa|`.
    ///
    /// The work done, `∫F dx`, is the sum of the two.
    #[allow(clippy::too_many_arguments)]
    fn monotone_energy(
        &self,
        d: &[f64],
        prefix: &[f64],
        range: (usize, usize),
        cut: (usize, usize),
        xa: f64,
        xb: f64,
        s: i8,
    ) -> (f64, f64) {
        let (sb, dm) = (self.sigma_b, self.p.delta_max);
        let (lo, hi) = range;
        let (new_lo, new_hi) = cut;
        // Each term only where it has bristles: a move of the order of
        // f64::MAX (a host may send one) overflows `xb − xa`, and the
        // still-connected shifts are within 2·δmax of each other.
        let still = new_hi - new_lo;
        let mut stored = if still > 0 {
            let sum = prefix[new_hi] - prefix[new_lo];
            0.5 * sb * (xb - xa) * (2.0 * sum + still as f64 * (xa + xb))
        } else {
            0.0
        };
        let before = self.p.n_bristles - (hi - lo);
        let mut dissipated = if before > 0 {
            sb * dm * before as f64 * (xb - xa).abs()
        } else {
            0.0
        };
        let sign = f64::from(s);
        for &dk in d[lo..new_lo].iter().chain(&d[new_hi..hi]) {
            let at_start = dk + xa;
            stored += 0.5 * sb * (dm * dm - at_start * at_start);
            dissipated += sb * dm * (sign * (xb + dk) - dm).max(0.0);
        }
        (stored, dissipated)
    }

    pub fn params(&self) -> &BristleParams {
        &self.p
    }

    /// Internal position `x` (the last imposed displacement).
    pub fn position(&self) -> f64 {
        self.x
    }

    pub fn n_bristles(&self) -> usize {
        self.p.n_bristles
    }

    pub fn n_connected(&self) -> usize {
        self.hi - self.lo
    }

    /// Fully sliding: every bristle disconnected.
    pub fn sliding(&self) -> bool {
        self.n_connected() == 0
    }

    /// The Coulomb level `σ_ini·δmax` (= μc·Fn with [`BristleParams::from_load`]).
    pub fn sliding_level(&self) -> f64 {
        self.p.sigma_ini * self.p.delta_max
    }

    /// `F = σ_ini·δmax·(n₊ − n₋)/N + σb·Σ_connected δi` at the internal
    /// position (all disconnected in one direction gives exactly `±σ_ini·δmax`).
    pub fn force(&self) -> f64 {
        self.force_of(&self.prefix, self.lo, self.hi, self.x - self.x_ref)
    }

    fn force_of(&self, prefix: &[f64], lo: usize, hi: usize, shift: f64) -> f64 {
        let n = self.p.n_bristles;
        let nc = hi - lo;
        let net = (n - hi) as f64 - lo as f64;
        let connected = (prefix[hi] - prefix[lo]) + nc as f64 * shift;
        self.p.sigma_ini * self.p.delta_max * (net / n as f64) + self.sigma_b * connected
    }

    /// Connected range after a monotone move to shift `X` in direction `s`
    /// from the range `lo..hi` of `d`.
    fn cut(&self, d: &[f64], lo: usize, hi: usize, shift: f64, s: i8) -> (usize, usize) {
        let dm = self.p.delta_max;
        if s > 0 {
            (lo, lo + d[lo..hi].partition_point(|&di| di + shift < dm))
        } else {
            (lo + d[lo..hi].partition_point(|&di| di + shift <= -dm), hi)
        }
    }

    /// Deflections of all bristles at the internal position after the
    /// reversal reconnection (`s·(δmax − |r|)` for the disconnected ones),
    /// sorted ascending, and their prefix sums.
    fn reconnected(&self) -> (Vec<f64>, Vec<f64>) {
        let mut work = Buffers::default();
        self.reconnected_into(&mut work);
        (work.d, work.prefix)
    }

    /// [`Bristle::reconnected`] into the buffers of `work` (`d`, `prefix`;
    /// the others are scratch).
    fn reconnected_into(&self, work: &mut Buffers) {
        let n = self.p.n_bristles;
        let dm = self.p.delta_max;
        let shift = self.x - self.x_ref;
        let back = &mut work.back;
        back.clear();
        back.extend(
            (self.hi..n)
                .map(|k| dm - self.relax[k])
                .chain((0..self.lo).map(|k| -(dm - self.relax[k]))),
        );
        sort_total(back, &mut work.keys, &mut work.scratch);
        let out = &mut work.d;
        out.clear();
        out.reserve(n);
        let mut i = self.lo;
        let mut j = 0;
        while i < self.hi || j < back.len() {
            let take_connected =
                j >= back.len() || (i < self.hi && (self.d[i] + shift).total_cmp(&back[j]).is_le());
            if take_connected {
                out.push(self.d[i] + shift);
                i += 1;
            } else {
                out.push(back[j]);
                j += 1;
            }
        }
        prefix_sums_into(out, &mut work.prefix);
    }

    /// Direction of a move to `x` and whether it reverses with bristles to
    /// reconnect.
    fn classify(&self, x: f64) -> (i8, bool) {
        if !x.is_finite() {
            return (0, false);
        }
        let dx = x - self.x;
        let s = if dx > 0.0 {
            1
        } else if dx < 0.0 {
            -1
        } else {
            0
        };
        let reversal =
            s != 0 && self.dir != 0 && s != self.dir && self.n_connected() < self.p.n_bristles;
        (s, reversal)
    }

    fn evaluate(&self, x: f64) -> Eval {
        let (s, reversal) = self.classify(x);
        if s == 0 {
            return Eval {
                force: self.force(),
                n_connected: self.n_connected(),
                energy: self.energy,
            };
        }
        if reversal {
            let (d, prefix) = self.reconnected();
            let shift = x - self.x;
            let n = d.len();
            let (lo, hi) = self.cut(&d, 0, n, shift, s);
            let (stored, _) = self.monotone_energy(&d, &prefix, (0, n), (lo, hi), 0.0, shift, s);
            Eval {
                force: self.force_of(&prefix, lo, hi, shift),
                n_connected: hi - lo,
                // as the move computes it: from scratch after the reconnection
                energy: self.energy_of(&d, 0, n, 0.0) + stored,
            }
        } else {
            let shift = x - self.x_ref;
            let (lo, hi) = self.cut(&self.d, self.lo, self.hi, shift, s);
            let range = (self.lo, self.hi);
            let from = self.x - self.x_ref;
            let (stored, _) =
                self.monotone_energy(&self.d, &self.prefix, range, (lo, hi), from, shift, s);
            Eval {
                force: self.force_of(&self.prefix, lo, hi, shift),
                n_connected: hi - lo,
                energy: self.energy + stored,
            }
        }
    }

    /// The force if the body moved from the internal position to `x` now,
    /// without changing the state; bit-identical to
    /// `{ let mut b = self.clone(); b.move_to(x); b.force() }`.
    /// `O(log N)` for a continuation in the same direction, `O(N)` on a
    /// reversal.
    pub fn force_at(&self, x: f64) -> f64 {
        self.evaluate(x).force
    }

    /// Number of connected bristles after moving to `x` (pure, like
    /// [`Bristle::force_at`]).
    pub fn n_connected_at(&self, x: f64) -> usize {
        self.evaluate(x).n_connected
    }

    /// Tangent stiffness `dF/dx = n_connected·σb` after moving to `x`.
    pub fn stiffness_at(&self, x: f64) -> f64 {
        self.evaluate(x).n_connected as f64 * self.sigma_b
    }

    /// The elastic energy held in the bristles (J) at the internal
    /// position: `σb/2·(Σ_connected δi² + n_disconnected·δmax²)`, `O(1)`.
    pub fn stored_energy(&self) -> f64 {
        self.energy
    }

    /// [`Bristle::stored_energy`] after moving to `x` (pure, like
    /// [`Bristle::force_at`]; `O(1)` plus the bristles that disconnect, `O(N)`
    /// on a reversal).
    pub fn stored_energy_at(&self, x: f64) -> f64 {
        self.evaluate(x).energy
    }

    /// The force, the number of connected bristles and the stored energy
    /// after moving to `x`, from one evaluation (pure, like
    /// [`Bristle::force_at`]).
    pub fn outputs_at(&self, x: f64) -> (f64, usize, f64) {
        let e = self.evaluate(x);
        (e.force, e.n_connected, e.energy)
    }

    /// The mean power dissipated over the last [`Bristle::step`] (W):
    /// `(∫F dx − ΔE)/h` of the step, the sliding of the disconnected
    /// bristles and the impulsive loss of each reversal's reconnection.
    /// Never negative; 0 before the first step.
    pub fn step_power(&self) -> f64 {
        self.step_power
    }

    /// Moves the body to `x` (see the module documentation). Allocates only
    /// on a reversal with disconnected bristles.
    pub fn move_to(&mut self, x: f64) {
        self.move_and_dissipate(x);
    }

    /// [`Bristle::move_to`], returning the energy the move dissipated (J).
    fn move_and_dissipate(&mut self, x: f64) -> f64 {
        let (s, reversal) = self.classify(x);
        if s == 0 {
            return 0.0;
        }
        let mut dissipated = 0.0;
        if reversal {
            dissipated += self.reconnection_loss();
            let mut work = self.work.0.take().unwrap_or_default();
            self.reconnected_into(&mut work);
            // the new offsets in, the old buffers kept as the next spares
            std::mem::swap(&mut self.d, &mut work.d);
            std::mem::swap(&mut self.prefix, &mut work.prefix);
            self.work.0 = Some(work);
            self.x_ref = self.x;
            self.lo = 0;
            self.hi = self.p.n_bristles;
            self.energy = self.energy_from_scratch();
        }
        self.dir = s;
        let from = self.x - self.x_ref;
        self.x = x;
        let shift = self.x - self.x_ref;
        let (lo, hi) = self.cut(&self.d, self.lo, self.hi, shift, s);
        let range = (self.lo, self.hi);
        let (stored, slid) =
            self.monotone_energy(&self.d, &self.prefix, range, (lo, hi), from, shift, s);
        self.energy += stored;
        dissipated += slid;
        // Pre-draw the relaxation of each newly disconnected bristle, in
        // position order.
        for k in (self.lo..lo).chain(hi..self.hi) {
            self.relax[k] = draw_relax(&mut self.rng, self.p.x_rel, self.p.delta_max);
        }
        self.lo = lo;
        self.hi = hi;
        if !(self.energy.is_finite() && dissipated.is_finite()) {
            // a move of the order of f64::MAX: what the bristles hold is
            // still finite, what they dissipate may not be
            self.energy = self.energy_from_scratch();
            dissipated = dissipated.min(f64::MAX);
        }
        dissipated
    }

    /// Step with the imposed displacement `x(τ)`: `move_to(x.value)` then
    /// `move_to(x.at(h))`. The model is static (rate-independent) and a
    /// ramp is monotone, so the two end points determine the result. The
    /// energy the two moves dissipate, over `h`, is
    /// [`Bristle::step_power`].
    pub fn step(&mut self, x: Ramp, h: f64) {
        let dissipated = self.move_and_dissipate(x.value) + self.move_and_dissipate(x.at(h));
        self.step_power = if h > 0.0 {
            (dissipated / h).min(f64::MAX)
        } else {
            0.0
        };
    }

    /// Whether every value of the state ([`Bristle::write_state_into`]) is
    /// finite, in `O(1)`: the answer of a full scan, bit for bit, without
    /// reading the `2·N` bristle values. They are finite by construction:
    /// - `x` changes only in [`Bristle::move_to`], and only to a finite
    ///   position ([`Bristle::classify`] ignores a non-finite one); `x_ref`
    ///   is only ever set to `x`; `dir`, `lo`, `hi`, `N` and the generator
    ///   words are small integers;
    /// - an offset is written only by the placement (`|δi| ≤ δmax`) and by a
    ///   reversal, as `di + X` for a bristle still connected at the shift
    ///   `X = x − x_ref` (so `|di + X| < δmax`) or as `±(δmax − |r|)`;
    /// - a relaxation `|r|` is drawn in `[0, δmax)`.
    ///
    /// So the state is finite exactly when the two positions are (always,
    /// by the first point; checked all the same, as a guard against a
    /// change breaking the argument). The FMU layer asks this after every
    /// step instead of copying and scanning the state, which cost 20 times
    /// the step itself at 100 000 bristles.
    pub fn state_is_finite(&self) -> bool {
        self.x.is_finite()
            && self.x_ref.is_finite()
            && self.energy.is_finite()
            && self.step_power.is_finite()
    }

    /// The number of values of the state: `16 + 2·N`.
    pub fn state_len(&self) -> usize {
        STATE_HEAD + self.d.len() + self.relax.len()
    }

    /// The state `[x, x_ref, dir, lo, hi, N, rng (8 values: the four 64-bit
    /// words as 32-bit halves, exact integers), energy, step power,
    /// d[0..N], relax[0..N]]` into `out`, of [`Bristle::state_len`] values.
    /// Lossless (the energy carried along the moves is kept, not recomputed,
    /// so a restored run continues bit for bit); every value is finite.
    pub fn write_state_into(&self, out: &mut [f64]) {
        assert_eq!(out.len(), self.state_len(), "bristle state length");
        let (head, rest) = out.split_at_mut(STATE_HEAD);
        let (d, relax) = rest.split_at_mut(self.d.len());
        head[..6].copy_from_slice(&[
            self.x,
            self.x_ref,
            f64::from(self.dir),
            self.lo as f64,
            self.hi as f64,
            self.p.n_bristles as f64,
        ]);
        for (pair, w) in head[6..14].chunks_exact_mut(2).zip(self.rng.state()) {
            pair.copy_from_slice(&[(w >> 32) as f64, (w & 0xffff_ffff) as f64]);
        }
        head[14..].copy_from_slice(&[self.energy, self.step_power]);
        d.copy_from_slice(&self.d);
        relax.copy_from_slice(&self.relax);
    }

    /// The same state as a new vector.
    pub fn state_to_vec(&self) -> Vec<f64> {
        let mut v = vec![0.0; self.state_len()];
        self.write_state_into(&mut v);
        v
    }

    /// Restores a state written by [`Bristle::write_state_into`] for the same
    /// number of bristles.
    pub fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
        let n = self.p.n_bristles;
        let head = STATE_HEAD;
        if s.len() != head + 2 * n {
            return Err(format!(
                "bristle state for {n} bristles has {} values, got {}",
                head + 2 * n,
                s.len()
            ));
        }
        let int = |v: f64, max: f64, what: &str| -> Result<u64, String> {
            if v.is_finite() && v >= 0.0 && v <= max && v.fract() == 0.0 {
                Ok(v as u64)
            } else {
                Err(format!("bristle state {what} = {v} is invalid"))
            }
        };
        let (x, x_ref) = (s[0], s[1]);
        if !x.is_finite() || !x_ref.is_finite() {
            return Err(format!("bristle state positions {x}, {x_ref} not finite"));
        }
        let dir = match s[2] {
            1.0 => 1,
            -1.0 => -1,
            0.0 => 0,
            v => return Err(format!("bristle state dir = {v} is invalid")),
        };
        let lo = int(s[3], n as f64, "lo")? as usize;
        let hi = int(s[4], n as f64, "hi")? as usize;
        if lo > hi {
            return Err(format!("bristle state lo = {lo} > hi = {hi}"));
        }
        if int(s[5], f64::MAX, "N")? != n as u64 {
            return Err(format!("bristle state is for {} bristles, not {n}", s[5]));
        }
        let mut words = [0u64; 4];
        for (i, w) in words.iter_mut().enumerate() {
            let hi_w = int(s[6 + 2 * i], 4_294_967_295.0, "rng word")?;
            let lo_w = int(s[7 + 2 * i], 4_294_967_295.0, "rng word")?;
            *w = (hi_w << 32) | lo_w;
        }
        let (energy, step_power) = (s[14], s[15]);
        if !(energy.is_finite() && step_power.is_finite() && step_power >= 0.0) {
            return Err(format!(
                "bristle state energy {energy} and step power {step_power} must be finite, the power >= 0"
            ));
        }
        let d = &s[head..head + n];
        let relax = &s[head + n..];
        if d.iter().any(|v| !v.is_finite()) || d.windows(2).any(|w| w[0] > w[1]) {
            return Err("bristle state offsets must be finite and sorted".into());
        }
        if relax
            .iter()
            .any(|r| !(r.is_finite() && *r >= 0.0 && *r < self.p.delta_max))
        {
            return Err("bristle state relaxations must be in [0, delta_max)".into());
        }
        self.x = x;
        self.x_ref = x_ref;
        self.dir = dir;
        self.lo = lo;
        self.hi = hi;
        self.rng = Rng::from_state(words);
        self.d = d.to_vec();
        self.prefix = prefix_sums(&self.d);
        self.relax = relax.to_vec();
        self.energy = energy;
        self.step_power = step_power;
        Ok(())
    }
}

/// `|r|`, `r ~ Normal(x_rel, x_rel/3)`, redrawn while `|r| ≥ δmax` (which
/// would reconnect a bristle already beyond its range; probability < 1e-13
/// for the paper's numbers).
fn draw_relax(rng: &mut Rng, x_rel: f64, delta_max: f64) -> f64 {
    for _ in 0..100 {
        let r = rng.normal(x_rel, x_rel / 3.0).abs();
        if r < delta_max {
            return r;
        }
    }
    x_rel
}

/// The paper's `Initial_bristle_placement.m`: `δi ~ Normal(0, (2/3)δmax)`,
/// subtract the mean; scan the bristles in order and at the first with
/// `|δq| > δmax` redraw it, subtract the new mean from all and restart the
/// scan, until all are within `δmax`.
///
/// Implemented in `O(N)` expected time with a lazy common shift
/// (`δi = raw_i − shift`) and running extremes of the already-checked
/// prefix, so a restart only rescans when an earlier bristle has really left
/// the range; the sequence of draws and checks is the paper's. The number of
/// redraws is bounded (`100·N + 1000`, about 0.15·N are needed); should it
/// ever be exhausted the remaining deflections are clamped into the range.
fn initial_placement(rng: &mut Rng, n: usize, delta_max: f64) -> Vec<f64> {
    let sd = 2.0 / 3.0 * delta_max;
    let nf = n as f64;
    let mut raw: Vec<f64> = (0..n).map(|_| rng.normal(0.0, sd)).collect();
    let mut sum: f64 = raw.iter().sum();
    let mut shift = sum / nf;
    let mut q = 0;
    let (mut pmax, mut pmin) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut redraws = 0usize;
    let limit = 100 * n + 1000;
    while q < n {
        let delta = raw[q] - shift;
        if delta.abs() <= delta_max {
            pmax = pmax.max(raw[q]);
            pmin = pmin.min(raw[q]);
            q += 1;
            continue;
        }
        if redraws >= limit {
            break;
        }
        redraws += 1;
        let new_raw = rng.normal(0.0, sd) + shift;
        sum += new_raw - raw[q];
        raw[q] = new_raw;
        // Settle: subtract the mean deflection, i.e. shift = mean(raw).
        shift = sum / nf;
        if pmax - shift > delta_max || pmin - shift < -delta_max {
            // Restart from the first bristle now out of range.
            let j = raw[..q]
                .iter()
                .position(|&r| (r - shift).abs() > delta_max)
                .unwrap_or(q);
            q = j;
            pmax = raw[..j].iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            pmin = raw[..j].iter().cloned().fold(f64::INFINITY, f64::min);
        }
    }
    let mut d: Vec<f64> = raw.iter().map(|&r| r - shift).collect();
    // Final exact settle of the round-off in the running sum.
    let mean = d.iter().sum::<f64>() / nf;
    for v in d.iter_mut() {
        *v = (*v - mean).clamp(-delta_max, delta_max);
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn radix_sort_gives_what_the_comparison_sort_gives() {
        let mut rng = Rng::new(7);
        for n in [0, 1, 255, 256, 1000, 5000] {
            let mut v: Vec<f64> = (0..n)
                .map(|i| match i % 7 {
                    0 => -0.0,
                    1 => 0.0,
                    2 => 1.5e-8,
                    _ => rng.normal(0.0, 1e-8),
                })
                .collect();
            let mut expected = v.clone();
            expected.sort_unstable_by(f64::total_cmp);
            sort_total(&mut v, &mut Vec::new(), &mut Vec::new());
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&v), bits(&expected), "{n} values");
        }
    }

    #[test]
    fn default_is_appels_herder_and_validation() {
        let p = BristleParams::default();
        assert_eq!(p.n_bristles, 109);
        assert!(rel(p.sigma_ini * p.delta_max, 0.0633 * 0.352 * 9.81) < 1e-15);
        let bad = |q: BristleParams| Bristle::new(q).unwrap_err().name;
        assert_eq!(bad(BristleParams { n_bristles: 0, ..p }), "n_bristles");
        assert_eq!(
            bad(BristleParams {
                sigma_ini: 0.0,
                ..p
            }),
            "sigma_ini"
        );
        assert_eq!(
            bad(BristleParams {
                delta_max: -1.0,
                ..p
            }),
            "delta_max"
        );
        assert_eq!(bad(BristleParams { x_rel: 2e-8, ..p }), "x_rel");
        assert_eq!(bad(BristleParams { x_rel: -1e-9, ..p }), "x_rel");
        assert_eq!(
            bad(BristleParams::from_load(500.0, 0.06, 0.0, 1e-8, 1e-9, 1)),
            "sigma_ini"
        );
        assert!(Bristle::new(BristleParams { x_rel: 0.0, ..p }).is_ok());
    }

    #[test]
    fn initial_placement_is_settled_and_connected() {
        for seed in 0..20 {
            let p = BristleParams {
                seed,
                ..BristleParams::default()
            };
            let b = Bristle::new(p).unwrap();
            assert_eq!(b.n_connected(), p.n_bristles);
            assert!(b.d.iter().all(|d| d.abs() <= p.delta_max));
            assert!(b.force().abs() < 1e-12 * b.sliding_level());
        }
        // The spread: standard deviation a bit below (2/3)δmax (tails cut).
        let p = BristleParams::from_load(500.0, 0.0633, 200.0, 1.5584e-8, 4.4206e-9, 7);
        let b = Bristle::new(p).unwrap();
        let n = b.d.len() as f64;
        let sd = (b.d.iter().map(|d| d * d).sum::<f64>() / n).sqrt() / p.delta_max;
        assert!(sd > 0.45 && sd < 0.62, "sd/δmax = {sd}");
    }

    #[test]
    fn slides_at_the_coulomb_level_within_two_delta_max() {
        for &mass in &[0.352, 0.419, 0.459, 0.522, 0.563, 0.690] {
            let fn_ = mass * 9.81;
            let p = BristleParams::from_load(500.0, 0.0633, fn_, 1.5584e-8, 4.4206e-9, 1);
            let mut b = Bristle::new(p).unwrap();
            let dm = p.delta_max;
            let mut last = 0.0;
            let mut k = 0;
            while !b.sliding() {
                k += 1;
                b.move_to(k as f64 * 0.01 * dm);
                assert!(b.force() >= last, "force is monotone in monotone motion");
                last = b.force();
            }
            assert!(
                k as f64 * 0.01 * dm <= 2.0 * dm * (1.0 + 1e-12),
                "slid at {k}"
            );
            assert!(rel(b.force(), 0.0633 * fn_) < 1e-9);
            assert_eq!(b.force(), b.sliding_level());
            b.move_to(1.0);
            assert_eq!(b.force(), b.sliding_level());
            // Backward sliding mirrors it.
            let mut c = Bristle::new(p).unwrap();
            c.move_to(-2.0 * dm);
            assert!(c.sliding());
            assert!(rel(c.force(), -0.0633 * fn_) < 1e-9);
        }
    }

    #[test]
    fn reversal_relaxes_with_the_initial_stiffness() {
        let p = BristleParams::default();
        let mut b = Bristle::new(p).unwrap();
        let dm = p.delta_max;
        b.move_to(3.0 * dm);
        assert!(b.sliding());
        let level = b.sliding_level();
        let eps = 1e-3 * dm;
        let f1 = b.force_at(3.0 * dm - eps);
        assert!(f1 < level, "below the sliding level after reversal");
        // Mean relaxation drop ≈ σ_ini·x_rel.
        let drop = (level - f1) / (p.sigma_ini * p.x_rel);
        assert!(drop > 0.7 && drop < 1.3, "drop {drop}");
        assert!(rel(b.stiffness_at(3.0 * dm - eps), p.sigma_ini) < 1e-12);
        b.move_to(3.0 * dm - eps);
        assert_eq!(b.n_connected(), p.n_bristles);
        let f2 = b.force_at(3.0 * dm - 2.0 * eps);
        assert!(
            rel(f1 - f2, p.sigma_ini * eps) < 1e-6,
            "{} vs {}",
            f1 - f2,
            p.sigma_ini * eps
        );
        // Unloading further eventually slides backwards at −level.
        b.move_to(-dm);
        assert!(b.sliding());
        assert!(rel(b.force(), -level) < 1e-9);
    }

    #[test]
    fn seeds_give_reproducible_realisations() {
        let path = [0.5, 1.2, 0.7, 2.5, 1.9, -3.0, 0.2];
        let run = |seed: u64| {
            let p = BristleParams {
                seed,
                ..BristleParams::default()
            };
            let mut b = Bristle::new(p).unwrap();
            let mut out = Vec::new();
            for &x in &path {
                for k in 1..=20 {
                    b.move_to(b.position() + (x * p.delta_max - b.position()) * k as f64 / 20.0);
                    out.push(b.force().to_bits());
                }
            }
            (out, b.sliding_level())
        };
        let (a, la) = run(1);
        let (b, _) = run(1);
        let (c, lc) = run(2);
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_eq!(la, lc);
    }

    /// Random walk with reversals of random size, some stopping exactly.
    fn random_path(seed: u64, steps: usize, dm: f64) -> Vec<f64> {
        let mut r = Rng::new(seed);
        let mut x = 0.0;
        let mut out = Vec::new();
        for _ in 0..steps {
            let u = r.uniform();
            let scale = if u < 0.3 {
                0.05
            } else if u < 0.8 {
                0.5
            } else {
                3.0
            };
            x += (r.uniform() - 0.45) * scale * dm;
            if r.uniform() < 0.05 {
                out.push(x); // repeated position: no move
            }
            out.push(x);
        }
        out
    }

    #[test]
    fn force_at_equals_clone_and_move_bit_for_bit() {
        for seed in 0..8 {
            let n_scale = [1.0, 30.0][seed as usize % 2];
            let p =
                BristleParams::from_load(500.0, 0.0633, 3.45 * n_scale, 1.5584e-8, 4.4206e-9, seed);
            let mut b = Bristle::new(p).unwrap();
            let mut probe = Rng::new(100 + seed);
            let mut reversals = 0;
            for &x in &random_path(seed, 400, p.delta_max) {
                if b.n_connected() < p.n_bristles && (x - b.position()) * f64::from(b.dir) < 0.0 {
                    reversals += 1;
                }
                // Probe a few tentative targets around the next one.
                for _ in 0..3 {
                    let xt = x + (probe.uniform() - 0.5) * p.delta_max;
                    let mut c = b.clone();
                    c.move_to(xt);
                    assert_eq!(b.force_at(xt).to_bits(), c.force().to_bits());
                    assert_eq!(b.stiffness_at(xt), c.n_connected() as f64 * b.sigma_b);
                    assert_eq!(b.n_connected_at(xt), c.n_connected());
                }
                let mut c = b.clone();
                c.move_to(x);
                assert_eq!(b.force_at(x).to_bits(), c.force().to_bits());
                b.move_to(x);
                assert_eq!(b.force().to_bits(), c.force().to_bits());
                assert!(b.force().abs() <= b.sliding_level() * (1.0 + 1e-12));
            }
            assert!(
                reversals > 20,
                "only {reversals} reversals with disconnected bristles"
            );
        }
    }

    /// The paper's algorithm on a plain array (per-bristle deflection and
    /// disconnection sign), for comparison with the sorted representation.
    /// With `x_rel = 0` the reconnection point `s·δmax` needs no draws.
    struct Naive {
        delta: Vec<f64>,
        sign: Vec<f64>, // 0 = connected
        dir: f64,
        x: f64,
        dm: f64,
        sigma_b: f64,
        /// Energy dissipated so far: `σb·δmax` times each disconnected
        /// bristle's slide.
        dissipated: f64,
    }

    impl Naive {
        fn move_to(&mut self, x: f64) {
            let dx = x - self.x;
            if dx == 0.0 {
                return;
            }
            if self.dir != 0.0 && dx * self.dir < 0.0 {
                for (d, s) in self.delta.iter_mut().zip(self.sign.iter_mut()) {
                    if *s != 0.0 {
                        *d = *s * self.dm;
                        *s = 0.0;
                    }
                }
            }
            self.dir = dx.signum();
            self.x = x;
            let slide = self.sigma_b * self.dm;
            for (d, s) in self.delta.iter_mut().zip(self.sign.iter_mut()) {
                if *s == 0.0 {
                    *d += dx;
                    if d.abs() >= self.dm && *d * self.dir > 0.0 {
                        self.dissipated += slide * (d.abs() - self.dm);
                        *s = self.dir;
                        *d = self.dir * self.dm;
                    }
                } else {
                    self.dissipated += slide * dx.abs();
                }
            }
        }

        fn energy(&self) -> f64 {
            0.5 * self.sigma_b * self.delta.iter().map(|d| d * d).sum::<f64>()
        }

        fn force(&self) -> f64 {
            self.sigma_b * self.delta.iter().sum::<f64>()
        }
    }

    #[test]
    fn agrees_with_a_plain_per_bristle_implementation() {
        for seed in 0..4 {
            let p = BristleParams::from_load(500.0, 0.0633, 20.0, 1.5584e-8, 0.0, seed);
            let mut b = Bristle::new(p).unwrap();
            let mut naive = Naive {
                delta: b.d.clone(),
                sign: vec![0.0; p.n_bristles],
                dir: 0.0,
                x: 0.0,
                dm: p.delta_max,
                sigma_b: b.sigma_b,
                dissipated: 0.0,
            };
            // the energy scale: all bristles at δmax
            let full = 0.5 * p.sigma_ini * p.delta_max * p.delta_max;
            let mut dissipated = 0.0;
            for &x in &random_path(10 + seed, 500, p.delta_max) {
                let tentative = b.stored_energy_at(x);
                b.step(Ramp::constant(x), 1.0);
                dissipated += b.step_power();
                naive.move_to(x);
                let n_conn = naive.sign.iter().filter(|s| **s == 0.0).count();
                assert_eq!(b.n_connected(), n_conn);
                // Offsets accumulate round-off differently: 1e-9 of the level.
                assert!((b.force() - naive.force()).abs() < 1e-9 * b.sliding_level());
                assert!((b.stored_energy() - naive.energy()).abs() < 1e-9 * full);
                assert!((dissipated - naive.dissipated).abs() < 1e-9 * full.max(naive.dissipated));
                assert_eq!(tentative.to_bits(), b.stored_energy().to_bits());
            }
        }
    }

    #[test]
    fn state_round_trip_continues_bit_for_bit() {
        let p = BristleParams::default();
        let mut a = Bristle::new(p).unwrap();
        let path = random_path(5, 300, p.delta_max);
        for &x in &path[..150] {
            a.move_to(x);
        }
        let saved = a.state_to_vec();
        assert!(saved.iter().all(|v| v.is_finite()));
        let mut b = Bristle::new(BristleParams { seed: 99, ..p }).unwrap();
        b.state_from_slice(&saved).unwrap();
        for &x in &path[150..] {
            a.move_to(x);
            b.move_to(x);
            assert_eq!(a.force().to_bits(), b.force().to_bits());
        }
        assert_eq!(a.state_to_vec().len(), b.state_to_vec().len());
        assert!(a
            .state_to_vec()
            .iter()
            .zip(b.state_to_vec())
            .all(|(u, v)| u.to_bits() == v.to_bits()));
        assert!(b.state_from_slice(&saved[1..]).is_err());
        let mut bad = saved.clone();
        bad[2] = 0.5;
        assert!(b.state_from_slice(&bad).is_err());
    }

    #[test]
    fn a_reversal_reconnection_dissipates_what_the_bristles_lose() {
        let p = BristleParams::default();
        let mut b = Bristle::new(p).unwrap();
        // into gross sliding, then one reversal of a tenth of δmax
        b.step(Ramp::constant(3.0 * p.delta_max), 1.0);
        assert!(b.sliding());
        let full = 0.5 * p.sigma_ini * p.delta_max * p.delta_max;
        assert!((b.stored_energy() - full).abs() < 1e-12 * full);
        let (e0, f0, x0) = (b.stored_energy(), b.force(), b.position());
        let x1 = x0 - 0.1 * p.delta_max;
        b.step(Ramp::constant(x1), 0.5);
        // ∫F dx over the move, finely, on a clone from the reconnected state
        let mut c = Bristle::new(p).unwrap();
        c.step(Ramp::constant(3.0 * p.delta_max), 1.0);
        let n = 10_000;
        let mut work = 0.0;
        let mut prev = (x0, f0);
        for k in 1..=n {
            let x = x0 + (x1 - x0) * k as f64 / n as f64;
            c.move_to(x);
            let f = c.force();
            // the first increment starts after the reconnection drop, whose
            // force is not read: its end point alone (error ~ σ_ini·dx²)
            let f_start = if k == 1 { f } else { prev.1 };
            work += 0.5 * (f_start + f) * (x - prev.0);
            prev = (x, f);
        }
        let balance = work - b.step_power() * 0.5 - (b.stored_energy() - e0);
        assert!(balance.abs() < 1e-6 * full, "{balance:e} J of {full:e}");
        assert!(b.step_power() > 0.0);
    }

    #[test]
    fn state_is_finite_answers_as_a_full_scan() {
        // random walks around δmax, then the extremes a host may send: huge
        // positions of either sign (x − x_ref overflows), NaN and infinities
        // (ignored), each followed by reversals
        let p = BristleParams {
            n_bristles: 2000,
            ..BristleParams::default()
        };
        let extremes = [
            1e300,
            -1e300,
            f64::MAX,
            -f64::MAX,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            1e-8,
            -1e-8,
        ];
        for seed in 0..3 {
            let mut b = Bristle::new(BristleParams { seed, ..p }).unwrap();
            let path = random_path(20 + seed, 400, p.delta_max);
            for &x in path.iter().chain(&extremes).chain(&path) {
                b.move_to(x);
                let scanned = b.state_to_vec().iter().all(|v| v.is_finite());
                assert!(
                    scanned,
                    "a non-finite state after a move to {x}: {:?}",
                    &b.state_to_vec()[..16]
                );
                assert_eq!(b.state_is_finite(), scanned);
            }
        }
    }

    #[test]
    fn step_moves_through_the_ramp_end_points() {
        let p = BristleParams::default();
        let mut a = Bristle::new(p).unwrap();
        let mut b = Bristle::new(p).unwrap();
        a.step(Ramp::new(0.0, 1e-8), 1.0);
        b.move_to(1e-8);
        assert_eq!(a.force().to_bits(), b.force().to_bits());
        for &h in &[1e-7, 1e-3, 1.0] {
            a.step(Ramp::new(a.position(), -3e-8), h);
            assert!(a.force().is_finite());
        }
    }

    #[test]
    fn many_bristles_monotone_increments_are_cheap() {
        let p = BristleParams {
            n_bristles: 100_000,
            ..BristleParams::default()
        };
        let mut b = Bristle::new(p).unwrap();
        let t = std::time::Instant::now();
        for k in 1..=1000 {
            b.move_to(k as f64 * 2.2 * p.delta_max / 1000.0);
            let _ = b.force_at(b.position() + 1e-12);
        }
        assert!(b.sliding());
        // Generous bound for unoptimised test builds.
        assert!(t.elapsed().as_millis() < 2000, "{:?}", t.elapsed());
    }
}
