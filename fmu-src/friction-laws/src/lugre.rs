//! LuGre friction (Canudas de Wit et al. 1995; Sun et al. 2016 eq. 9–12;
//! Dion et al. 2013 eq. 1; Thimmalapura 2004 eq. 2.8–2.9; docs/models.md
//! "LuGre").
//!
//! `ż = v − σ0·|v|·z / g(v)`, `g(v) = Fc + (Fs − Fc)·exp(−|v/vs|^δ)`,
//! `F = σ0·z + σ1(v)·ż + σ2·v + F_offset`, `σ1(v) = σ1·exp(−(v/vd)²)`
//! (vd = 0: constant).
//!
//! `F_offset` is a constant force on the contact (0 by default), which
//! acts at rest as in motion: the offset term of the EMPS reference model
//! (Janot, Gautier, Brunot 2019), not a level of the law (it is not
//! scaled by the normal force).
//!
//! Options:
//! - direction-dependent levels: `Fc_neg`, `Fs_neg` (and `scale_neg`) for
//!   `v < 0` (Thimmalapura 2004);
//! - direction-dependent viscous friction: `sigma2_neg` instead of σ2 for
//!   `v < 0` (the asymmetric EMPS model of Janot, Gautier, Brunot 2019:
//!   Fv+ and Fv−);
//! - position-dependent levels: `Fc` and `Fs` multiplied by a scale factor
//!   piecewise-linear in the position input `x`, constant beyond the table
//!   ends (Thimmalapura 2004);
//! - normal-force form (Dion et al. 2013): `σ0, σ1, σ2, Fc, Fs` are per
//!   unit normal force and the force is multiplied by the input `Fn`; the
//!   ratio `σ0/g` and hence the `z` dynamics do not depend on `Fn`.
//!
//! At constant inputs `ż` is linear in `z` with rate `λ = σ0·|v|/g`, so
//! `z ← zss + (z − zss)·e^(−λh)`, `zss = g·sgn(v)/σ0`, is exact for any `h`.

use crate::error::{require_non_negative, require_positive};
use crate::interval::{one_sign_pieces, sign_on};
use crate::{ParamError, Ramp};

/// Capacity of the position table.
pub const TABLE_POINTS: usize = 32;

/// Most sub-steps per one-sign piece of a step.
const MAX_SUBSTEPS: usize = 10_000;
/// Largest relative change of `|v| + vs` per sub-step.
const KAPPA_V: f64 = 1e-3;
/// Largest relative change of the level scale factor per sub-step.
const KAPPA_X: f64 = 1e-3;

/// LuGre parameters (SI units). In the normal-force form the stiffnesses,
/// dampings and levels are per newton of normal force.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LuGreParams {
    /// Bristle stiffness σ0 (N/m).
    pub sigma0: f64,
    /// Micro-damping σ1 (N·s/m).
    pub sigma1: f64,
    /// Viscous coefficient σ2 (N·s/m), for `v ≥ 0` when the viscous
    /// friction is direction-dependent.
    pub sigma2: f64,
    /// Use `sigma2_neg` instead of σ2 for `v < 0`.
    pub direction_dependent_viscous: bool,
    /// Viscous coefficient for `v < 0` (N·s/m).
    pub sigma2_neg: f64,
    /// Constant force on the contact (N), at rest and in motion.
    pub f_offset: f64,
    /// Coulomb level Fc (N), for `v ≥ 0` when direction-dependent.
    pub fc: f64,
    /// Static (break-away) level Fs ≥ Fc (N).
    pub fs: f64,
    /// Stribeck velocity vs (m/s).
    pub vs: f64,
    /// Stribeck exponent δ (–).
    pub stribeck_exponent: f64,
    /// Micro-damping decay velocity vd (m/s); 0 = constant σ1.
    pub vd: f64,
    /// Use `fc_neg`, `fs_neg` (and `scale_neg`) for `v < 0`.
    pub direction_dependent: bool,
    pub fc_neg: f64,
    pub fs_neg: f64,
    /// Multiply the force by the normal-force input (Dion et al. 2013 form).
    pub normal_force_form: bool,
    /// Scale Fc and Fs by the position table.
    pub position_dependent: bool,
    /// Number of table points used (2..=32).
    pub n_table: usize,
    /// Table positions (m), strictly increasing over the first `n_table`.
    pub x_table: [f64; TABLE_POINTS],
    /// Scale factors (> 0) on Fc, Fs at `x_table` (both directions, or
    /// `v ≥ 0` when direction-dependent).
    pub scale_pos: [f64; TABLE_POINTS],
    /// Scale factors for `v < 0` when direction-dependent.
    pub scale_neg: [f64; TABLE_POINTS],
}

impl Default for LuGreParams {
    /// Canudas de Wit et al. 1995 benchmark: σ0 = 1e5 N/m, σ1 = √1e5 N·s/m,
    /// σ2 = 0.4 N·s/m, Fc = 1 N, Fs = 1.5 N, vs = 1e-3 m/s, δ = 2, vd = 0;
    /// negative levels equal to the positive ones, options off, table
    /// x = 0..1 m evenly over 32 points with unit scales.
    fn default() -> Self {
        let mut x_table = [0.0; TABLE_POINTS];
        for (i, x) in x_table.iter_mut().enumerate() {
            *x = i as f64 / (TABLE_POINTS - 1) as f64;
        }
        LuGreParams {
            sigma0: 1e5,
            sigma1: 1e5_f64.sqrt(),
            sigma2: 0.4,
            direction_dependent_viscous: false,
            sigma2_neg: 0.4,
            f_offset: 0.0,
            fc: 1.0,
            fs: 1.5,
            vs: 1e-3,
            stribeck_exponent: 2.0,
            vd: 0.0,
            direction_dependent: false,
            fc_neg: 1.0,
            fs_neg: 1.5,
            normal_force_form: false,
            position_dependent: false,
            n_table: TABLE_POINTS,
            x_table,
            scale_pos: [1.0; TABLE_POINTS],
            scale_neg: [1.0; TABLE_POINTS],
        }
    }
}

impl LuGreParams {
    /// Sun et al. 2016 (brass on steel, m ≈ 1 kg): Table 6 static part
    /// (Fc = 1.284 N, Fs = 2.35 N, vs = 1.13975e-3 m/s, σ2 = 173 N·s/m),
    /// σ0 = 66 967.231 N/m (Table 9), σ1 = 2√σ0 − σ2 ≈ 344.56 N·s/m (eq. 24,
    /// critical damping with m = 1).
    pub fn sun_2016() -> Self {
        let sigma0 = 66_967.231;
        let sigma2 = 173.0;
        LuGreParams {
            sigma0,
            sigma1: 2.0 * f64::sqrt(sigma0) - sigma2,
            sigma2,
            fc: 1.284,
            fs: 2.35,
            vs: 1.139_75e-3,
            fc_neg: 1.284,
            fs_neg: 2.35,
            ..LuGreParams::default()
        }
    }

    /// The largest steady deflection `g/σ0` the parameters allow (the
    /// larger static level, times the largest scale of the position table
    /// when it is used): the magnitude of `z`, for an integrator's
    /// tolerance. Of any parameters, valid or not.
    pub fn deflection_scale(&self) -> f64 {
        let mut level = self.fs;
        if self.direction_dependent {
            level = level.max(self.fs_neg);
        }
        if self.position_dependent {
            let n = self.n_table.clamp(2, TABLE_POINTS);
            let mut scale = self.scale_pos[..n].iter().cloned().fold(0.0, f64::max);
            if self.direction_dependent {
                scale = self.scale_neg[..n].iter().cloned().fold(scale, f64::max);
            }
            level *= scale;
        }
        level / self.sigma0
    }

    /// σ0 > 0, σ1 ≥ 0, σ2 ≥ 0, Fc > 0, Fs ≥ Fc, vs > 0, δ > 0, vd ≥ 0, all
    /// finite; the negative levels likewise when direction-dependent; the
    /// table (2..=32 points, strictly increasing, scales > 0) when
    /// position-dependent.
    pub fn validate(&self) -> Result<(), ParamError> {
        require_positive("sigma0", self.sigma0)?;
        require_non_negative("sigma1", self.sigma1)?;
        require_non_negative("sigma2", self.sigma2)?;
        if self.direction_dependent_viscous {
            require_non_negative("sigma2_neg", self.sigma2_neg)?;
        }
        crate::error::require_finite("F_offset", self.f_offset)?;
        require_positive("Fc", self.fc)?;
        require_at_least("Fs", self.fs, "Fc", self.fc)?;
        require_positive("vs", self.vs)?;
        require_positive("stribeck_exponent", self.stribeck_exponent)?;
        require_non_negative("vd", self.vd)?;
        if self.direction_dependent {
            require_positive("Fc_neg", self.fc_neg)?;
            require_at_least("Fs_neg", self.fs_neg, "Fc_neg", self.fc_neg)?;
        }
        if self.position_dependent {
            let n = self.n_table;
            if !(2..=TABLE_POINTS).contains(&n) {
                return Err(ParamError::new(
                    "n_table",
                    n as f64,
                    format!("must be in 2..={TABLE_POINTS}"),
                ));
            }
            for i in 0..n {
                let x = self.x_table[i];
                if !x.is_finite() {
                    return Err(ParamError::new(
                        "x_table",
                        x,
                        format!("x_table[{}] must be finite", i + 1),
                    ));
                }
                if i > 0 && x <= self.x_table[i - 1] {
                    return Err(ParamError::new(
                        "x_table",
                        x,
                        format!(
                            "x_table[{}] must be > x_table[{}] = {} (strictly increasing)",
                            i + 1,
                            i,
                            self.x_table[i - 1]
                        ),
                    ));
                }
                check_scale("scale_pos", self.scale_pos[i], i)?;
                if self.direction_dependent {
                    check_scale("scale_neg", self.scale_neg[i], i)?;
                }
            }
        }
        Ok(())
    }
}

fn require_at_least(
    name: &'static str,
    value: f64,
    other: &str,
    bound: f64,
) -> Result<(), ParamError> {
    if value.is_finite() && value >= bound {
        Ok(())
    } else {
        Err(ParamError::new(
            name,
            value,
            format!("must be >= {other} = {bound}"),
        ))
    }
}

fn check_scale(name: &'static str, s: f64, i: usize) -> Result<(), ParamError> {
    if s.is_finite() && s > 0.0 {
        Ok(())
    } else {
        Err(ParamError::new(
            name,
            s,
            format!("{name}[{}] must be finite and > 0", i + 1),
        ))
    }
}

/// Instantaneous inputs over a step: velocity `v` (m/s), position `x` (m,
/// used by the position table) and normal force `fn_` (N, used in the
/// normal-force form; negative values count as 0).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LuGreInputs {
    pub v: Ramp,
    pub x: Ramp,
    pub fn_: Ramp,
}

/// The input a step sensitivity ([`LuGre::held_step_sensitivity`]) is
/// taken with respect to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeldInput {
    /// The sliding velocity `v`.
    V,
    /// The position `x` (the level table).
    X,
    /// The normal force `Fn`.
    Fn,
}

/// `∂z⁺/∂u` and `∂F⁺/∂u` after a held step ([`LuGre::held_step_sensitivity`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSensitivity {
    /// Of the deflection `z` (m per unit of the input).
    pub z: f64,
    /// Of the force `F` (N per unit of the input).
    pub force: f64,
}

/// `λ` and its slopes ([`LuGre::rate_constant`]).
#[derive(Clone, Copy, Debug)]
struct RateConstant {
    lambda: f64,
    by_v: f64,
    by_x: f64,
}

/// `∂ż/∂z`, `∂ż/∂v`, `∂ż/∂x` ([`LuGre::rate_partials`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RatePartials {
    pub z: f64,
    pub v: f64,
    pub x: f64,
}

/// `∂F/∂z`, `∂F/∂v`, `∂F/∂x`, `∂F/∂Fn` ([`LuGre::force_partials`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForcePartials {
    pub z: f64,
    pub v: f64,
    pub x: f64,
    pub fn_: f64,
}

/// LuGre state: the mean bristle deflection `z` (m).
#[derive(Clone, Debug)]
pub struct LuGre {
    p: LuGreParams,
    z: f64,
    /// Largest relative slope of the scale tables (1/m), 0 without table.
    table_rate: f64,
    /// The Stribeck level of the last step's inputs, which the outputs
    /// after the step ask for again (not state: a function of the
    /// parameters and its key).
    level: Level,
    /// `∂z/∂p`, when asked for ([`LuGre::carry_parameter_sensitivities`]).
    sens: Option<Box<parameter_sensitivity::Sensitivities>>,
}

/// `g_unit(w, dir, x)` for one (w, dir < 0, x); `w` NaN: empty.
#[derive(Clone, Copy, Debug)]
struct Level {
    w: f64,
    negative: bool,
    x: f64,
    g: f64,
}

impl Level {
    const EMPTY: Level = Level {
        w: f64::NAN,
        negative: false,
        x: f64::NAN,
        g: f64::NAN,
    };
}

impl LuGre {
    /// Relaxed state `z = 0` with validated parameters.
    pub fn new(p: LuGreParams) -> Result<Self, ParamError> {
        p.validate()?;
        let mut table_rate: f64 = 0.0;
        if p.position_dependent {
            let n = p.n_table;
            let mut tables = vec![&p.scale_pos];
            if p.direction_dependent {
                tables.push(&p.scale_neg);
            }
            for s in tables {
                let min = s[..n].iter().cloned().fold(f64::INFINITY, f64::min);
                for i in 1..n {
                    let slope = (s[i] - s[i - 1]).abs() / (p.x_table[i] - p.x_table[i - 1]);
                    table_rate = table_rate.max(slope / min);
                }
            }
        }
        Ok(LuGre {
            p,
            z: 0.0,
            table_rate,
            level: Level::EMPTY,
            sens: None,
        })
    }

    pub fn params(&self) -> &LuGreParams {
        &self.p
    }

    pub fn z(&self) -> f64 {
        self.z
    }

    /// Sets the deflection (any finite value).
    pub fn set_z(&mut self, z: f64) {
        self.z = z;
    }

    /// Normal-force multiplier: `max(Fn, 0)` in the normal-force form, else 1.
    fn fn_factor(&self, fn_: f64) -> f64 {
        if self.p.normal_force_form {
            fn_.max(0.0)
        } else {
            1.0
        }
    }

    /// Position scale factor: piecewise-linear interpolation of the table
    /// for direction `dir` (`< 0` uses `scale_neg` when direction-dependent),
    /// constant beyond the ends; 1 without the table (decided here, inline,
    /// so that a law without a table does not call out for its 1).
    #[inline(always)]
    fn scale(&self, dir: f64, x: f64) -> f64 {
        if !self.p.position_dependent {
            return 1.0;
        }
        self.table_scale(dir, x)
    }

    /// [`LuGre::scale`] with the table.
    fn table_scale(&self, dir: f64, x: f64) -> f64 {
        let p = &self.p;
        let n = p.n_table.clamp(2, TABLE_POINTS);
        let s = if dir < 0.0 && p.direction_dependent {
            &p.scale_neg
        } else {
            &p.scale_pos
        };
        let xs = &p.x_table[..n];
        if x.is_nan() || x <= xs[0] {
            return s[0];
        }
        if x >= xs[n - 1] {
            return s[n - 1];
        }
        // First index with xs[i] > x, in 1..n.
        let i = xs.partition_point(|&xi| xi <= x);
        let w = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
        s[i - 1] + w * (s[i] - s[i - 1])
    }

    /// Stribeck level per unit normal force for speed `w = |v|`, direction
    /// `dir` and position `x`: `Fc' + (Fs' − Fc')·exp(−(w/vs)^δ)`.
    fn g_unit(&self, w: f64, dir: f64, x: f64) -> f64 {
        let l = &self.level;
        if w == l.w && (dir < 0.0) == l.negative && (x == l.x || !self.p.position_dependent) {
            return l.g;
        }
        self.g_unit_computed(w, dir, x)
    }

    /// Whether the Stribeck term of direction `dir` is 0 to the last bit
    /// at `w = |v|`: no term (Fs = Fc), or an exponent beyond
    /// [`EXP_NEG_ZERO_BEYOND`] (no exponential taken to tell; the few
    /// exponents just below it whose `exp` rounds to 0 count as not 0,
    /// which costs sub-steps, not accuracy).
    fn stribeck_vanishes(&self, w: f64, dir: f64) -> bool {
        let (fc, fs, e) = self.stribeck_terms(w, dir);
        fs == fc || e > EXP_NEG_ZERO_BEYOND
    }

    /// [`LuGre::g_unit`] without [`LuGre::level`].
    fn g_unit_computed(&self, w: f64, dir: f64, x: f64) -> f64 {
        let (fc, fs, e) = self.stribeck_terms(w, dir);
        // Without a Stribeck term (Fs = Fc: Dahl's level, as `diagnose`
        // starts a Dahl nominal moved to LuGre) (Fs − Fc)·e^(−e) is 0
        // exactly, and the exponential is not taken.
        let stribeck = if fs == fc {
            0.0
        } else {
            (fs - fc) * exp_neg(e)
        };
        self.scale(dir, x) * (fc + stribeck)
    }

    /// The levels `(Fc', Fs')` of direction `dir` and the exponent
    /// `e = (w/vs)^δ` of the Stribeck term `exp(−e)`.
    #[inline(always)]
    fn stribeck_terms(&self, w: f64, dir: f64) -> (f64, f64, f64) {
        let p = &self.p;
        let (fc, fs) = if dir < 0.0 && p.direction_dependent {
            (p.fc_neg, p.fs_neg)
        } else {
            (p.fc, p.fs)
        };
        let r = w / p.vs;
        let e = if p.stribeck_exponent == 2.0 {
            r * r
        } else {
            r.powf(p.stribeck_exponent)
        };
        (fc, fs, e)
    }

    /// For `w > 0`: the level per unit normal force `g = scale·G(w)` of
    /// [`LuGre::g_unit`] (bit for bit), its slope `∂g/∂w`, and `G(w)`, the
    /// level before the position scale. With `e = (w/vs)^δ`,
    /// `G = Fc' + (Fs' − Fc')·e^(−e)` and
    /// `∂g/∂w = −scale·(Fs' − Fc')·e^(−e)·δ·e/w` (`d e/d w = δ·e/w`).
    fn level_and_slope(&self, w: f64, dir: f64, x: f64) -> (f64, f64, f64) {
        let (fc, fs, e) = self.stribeck_terms(w, dir);
        let decay = exp_neg(e);
        let scale = self.scale(dir, x);
        let unscaled = fc + (fs - fc) * decay;
        // (e^(−e) is 0 far above vs, where e·δ/w may overflow)
        let slope = if decay == 0.0 {
            0.0
        } else {
            -scale * (fs - fc) * decay * (self.p.stribeck_exponent * e / w)
        };
        (scale * unscaled, slope, unscaled)
    }

    /// `∂scale/∂x` of the position table of direction `dir` at `x`: the
    /// slope of the table segment `x` lies in, 0 beyond the ends; `None`
    /// where a table point lies in `[x − spread, x + spread]` (a kink of the
    /// piecewise-linear scale).
    fn scale_slope(&self, dir: f64, x: f64, spread: f64) -> Option<f64> {
        let p = &self.p;
        let n = p.n_table.clamp(2, TABLE_POINTS);
        let xs = &p.x_table[..n];
        if xs.iter().any(|&xi| (xi - x).abs() <= spread) || x.is_nan() {
            return None;
        }
        if x < xs[0] || x > xs[n - 1] {
            return Some(0.0);
        }
        let s = if dir < 0.0 && p.direction_dependent {
            &p.scale_neg
        } else {
            &p.scale_pos
        };
        let i = xs.partition_point(|&xi| xi <= x);
        Some((s[i] - s[i - 1]) / (xs[i] - xs[i - 1]))
    }

    /// Stribeck level `g(v)` (N) with the direction, position and
    /// normal-force scaling (docs/models.md "LuGre"; Thimmalapura 2004 for
    /// the levels; Dion et al. 2013 for the `Fn` factor). At `v = 0` the
    /// positive-direction levels are used.
    pub fn g(&self, v: f64, x: f64, fn_: f64) -> f64 {
        self.g_unit(v.abs(), v, x) * self.fn_factor(fn_)
    }

    /// Steady-state (Stribeck) force `Fss = g(v)·sgn v + σ2·v` (σ2 per unit
    /// `Fn` in the normal-force form); Sun et al. 2016 eq. 12.
    /// The offset `F_offset` is added; at `v = 0`, where a contact at rest
    /// may carry any force up to its break-away level, the offset alone is
    /// returned.
    pub fn steady_force(&self, v: f64, x: f64, fn_: f64) -> f64 {
        if v == 0.0 {
            return self.p.f_offset;
        }
        (self.g_unit(v.abs(), v, x) * v.signum() + self.sigma2_at(v) * v) * self.fn_factor(fn_)
            + self.p.f_offset
    }

    /// The viscous coefficient for velocity `v`: `sigma2_neg` for `v < 0`
    /// when the viscous friction is direction-dependent, else σ2.
    #[inline(always)]
    fn sigma2_at(&self, v: f64) -> f64 {
        if v < 0.0 && self.p.direction_dependent_viscous {
            self.p.sigma2_neg
        } else {
            self.p.sigma2
        }
    }

    /// `∂(σ2(v)·v)/∂v`: σ2 of the direction of `v`, and at `v = 0`, where
    /// a direction-dependent coefficient has a kink, the mean of the two
    /// one-sided slopes (the limit of central differences).
    #[inline]
    fn viscous_slope(&self, v: f64) -> f64 {
        if v == 0.0 && self.p.direction_dependent_viscous {
            0.5 * (self.p.sigma2 + self.p.sigma2_neg)
        } else {
            self.sigma2_at(v)
        }
    }

    /// `ż = v − σ0·|v|·z/g(v)` at the current state (independent of `Fn`:
    /// the ratio σ0/g is per unit normal force).
    pub fn z_dot(&self, v: f64, x: f64, fn_: f64) -> f64 {
        self.z_rate(self.z, v, x, fn_)
    }

    /// The right-hand side of the state equation for any deflection `z`:
    /// `ż = v − σ0·|v|·z/g(v)` (Sun et al. 2016 eq. 10–11; docs/models.md
    /// "LuGre"), with the direction and position scaling of `g`; independent
    /// of `Fn`. A pure function, for integrating the law together with other
    /// equations (the monolithic reference solutions).
    pub fn z_rate(&self, z: f64, v: f64, x: f64, fn_: f64) -> f64 {
        let _ = fn_;
        if v == 0.0 {
            return 0.0;
        }
        self.z_rate_at_level(z, v, self.g_unit(v.abs(), v, x))
    }

    /// [`LuGre::z_rate`] for `v ≠ 0` at the Stribeck level `g` = g(v).
    #[inline]
    fn z_rate_at_level(&self, z: f64, v: f64, g: f64) -> f64 {
        v - self.p.sigma0 * v.abs() * z / g
    }

    /// Micro-damping `σ1(v) = σ1·exp(−(v/vd)²)`, constant when `vd = 0`.
    fn sigma1_at(&self, v: f64) -> f64 {
        if self.p.vd > 0.0 {
            let r = v / self.p.vd;
            self.p.sigma1 * (-r * r).exp()
        } else {
            self.p.sigma1
        }
    }

    /// `F = (σ0·z + σ1(v)·ż + σ2·v)·[Fn]` at the current state and the given
    /// instantaneous inputs (direct feedthrough of `v`; Sun et al. 2016
    /// eq. 9, Dion et al. 2013 eq. 1).
    pub fn force(&self, v: f64, x: f64, fn_: f64) -> f64 {
        self.force_of(self.z, v, x, fn_)
    }

    /// The output equation for any deflection `z`:
    /// `F = (σ0·z + σ1(v)·ż + σ2·v)·[Fn]` with `ż` from [`LuGre::z_rate`]
    /// (Sun et al. 2016 eq. 9, Dion et al. 2013 eq. 1). Pure, like
    /// [`LuGre::z_rate`].
    pub fn force_of(&self, z: f64, v: f64, x: f64, fn_: f64) -> f64 {
        let zd = self.z_rate(z, v, x, fn_);
        self.force_at_rate(z, v, zd, fn_)
    }

    /// The output equation with the deflection rate `zd` given:
    /// `(σ0·z + σ1(v)·ż + σ2(v)·v)·φ(Fn) + F_offset`.
    #[inline]
    fn force_at_rate(&self, z: f64, v: f64, zd: f64, fn_: f64) -> f64 {
        self.force_per_unit(z, v, zd) * self.fn_factor(fn_) + self.p.f_offset
    }

    /// `σ0·z + σ1(v)·ż + σ2(v)·v`: the force per unit normal force in the
    /// normal-force form, without the offset.
    #[inline]
    fn force_per_unit(&self, z: f64, v: f64, zd: f64) -> f64 {
        self.p.sigma0 * z + self.sigma1_at(v) * zd + self.sigma2_at(v) * v
    }

    /// The elastic energy of the bristles, `σ0·z²/2·φ(Fn)` (J; `φ = Fn`
    /// in the normal-force form, else 1).
    pub fn stored_energy(&self, fn_: f64) -> f64 {
        0.5 * self.p.sigma0 * self.z * self.z * self.fn_factor(fn_)
    }

    /// `P_diss = F·v − σ0·z·ż·φ(Fn)` (W): the power the contact
    /// dissipates at a constant normal force, `∫F·v dt = ∫P_diss dt +
    /// ΔE_stored` (a changing `Fn` changes `E_stored` at constant `z`,
    /// work of the normal force that is in neither). It is
    /// `(σ0²·|v|·z²/g + σ1·ż·v + σ2·v²)·φ + F_offset·v`.
    pub fn dissipated_power(&self, v: f64, x: f64, fn_: f64) -> f64 {
        self.outputs(v, x, fn_).2
    }

    /// `dφ/dFn`: 1 for `Fn > 0` in the normal-force form, ½ at its kink
    /// `Fn = 0`, else 0 (as [`LuGre::force_partials`] takes it).
    pub fn fn_factor_slope(&self, fn_: f64) -> f64 {
        if !self.p.normal_force_form || fn_ < 0.0 {
            0.0
        } else if fn_ > 0.0 {
            1.0
        } else {
            0.5
        }
    }

    /// `φ(Fn)`: `max(Fn, 0)` in the normal-force form, else 1.
    pub fn normal_force_factor(&self, fn_: f64) -> f64 {
        self.fn_factor(fn_)
    }

    /// `true` when moving with the bristles at the sliding level:
    /// `v ≠ 0` and `sgn(v)·σ0·z ≥ 0.99·g(v)`.
    pub fn sliding(&self, v: f64, x: f64, fn_: f64) -> bool {
        let _ = fn_;
        v != 0.0 && self.sliding_at_level(v, self.g_unit(v.abs(), v, x))
    }

    /// [`LuGre::sliding`] for `v ≠ 0` at the Stribeck level `g` = g(v).
    #[inline]
    fn sliding_at_level(&self, v: f64, g: f64) -> bool {
        v.signum() * self.p.sigma0 * self.z >= 0.99 * g
    }

    /// [`LuGre::force`] and [`LuGre::sliding`] at once, the Stribeck level
    /// looked up once for both (an FMU's outputs are computed together);
    /// the same operations as the two, so the same results.
    pub fn force_and_sliding(&self, v: f64, x: f64, fn_: f64) -> (f64, bool) {
        let (force, sliding, _) = self.outputs(v, x, fn_);
        (force, sliding)
    }

    /// The force, whether sliding, and `P_diss` ([`LuGre::dissipated_power`])
    /// at once, from one evaluation of the Stribeck level.
    #[inline]
    pub fn outputs(&self, v: f64, x: f64, fn_: f64) -> (f64, bool, f64) {
        if v == 0.0 {
            return (self.force_at_rate(self.z, v, 0.0, fn_), false, 0.0);
        }
        let g = self.g_unit(v.abs(), v, x);
        let zd = self.z_rate_at_level(self.z, v, g);
        let force = self.force_at_rate(self.z, v, zd, fn_);
        let power = force * v - self.p.sigma0 * self.z * zd * self.fn_factor(fn_);
        (force, self.sliding_at_level(v, g), power)
    }

    /// Steady deflection `zss = g·s/σ0` for speed `w`, direction `s`.
    fn zss(&self, w: f64, s: f64, x: f64) -> f64 {
        self.g_unit(w, s, x) * s / self.p.sigma0
    }

    /// Advances `z` over `[0, h]`.
    ///
    /// Constant inputs: the exact update `z ← zss + (z − zss)·e^(−λh)`.
    /// Ramped inputs: the step is split exactly at the zero crossing of `v`,
    /// then into sub-steps on which `|v| + vs` changes by at most 0.1 % and the
    /// level scale factor by at most 0.1 % (at most 10 000 per piece), ending
    /// exactly where `x(t)` passes a table point. On each sub-step
    /// the rate `λ = σ0|v|/g` is taken at the midpoint and `zss` varies
    /// linearly between its end-point values, which the linear ODE
    /// `ż = −λ(z − zss(τ))` integrates exactly:
    /// `z ← zss_b + (z − zss_a)·e^(−λh) − (zss_b − zss_a)·(1 − e^(−λh))/(λh)`.
    /// This reduces to the exact constant-input update and, unlike freezing
    /// `zss` at the midpoint too, stays second-order accurate when `λh ≫ 1`
    /// (sliding), where `z` tracks `zss(v(t))`. A piece over which the
    /// level is constant (no Stribeck term, or one that is 0 there; no
    /// position table in use) is one sub-step, which is then exact. `Fn`
    /// does not enter.
    pub fn step(&mut self, inp: &LuGreInputs, h: f64) {
        if h.is_nan() || h <= 0.0 {
            return;
        }
        if inp.v.slope == 0.0 && (inp.x.slope == 0.0 || !self.p.position_dependent) {
            self.step_held(inp.v.value, inp.x.value, h);
            return;
        }
        let (pieces, n) = one_sign_pieces(inp.v, h);
        for &(a, b) in &pieces[..n] {
            let s = sign_on(inp.v, a, b);
            if s != 0.0 && b > a {
                self.integrate_piece(inp, a, b, s);
            }
        }
    }

    /// [`LuGre::step`] with `v` and the level constant over the step: the
    /// exact update `z ← zss + (z − zss)·e^(−λh)`, the arithmetic of the
    /// general path (one piece, one sub-step, `zss` the same at both ends)
    /// without what it does not need. The level is kept for the outputs.
    fn step_held(&mut self, v: f64, x: f64, h: f64) {
        if v == 0.0 || v.is_nan() {
            return;
        }
        let s = if v > 0.0 { 1.0 } else { -1.0 };
        let w = v.abs();
        let g = self.g_unit(w, s, x);
        self.level = Level {
            w,
            negative: s < 0.0,
            x,
            g,
        };
        let zss = g * s / self.p.sigma0;
        let lambda = self.p.sigma0 * w / g;
        let before = self.z;
        self.z = zss + (self.z - zss) * exp_neg(lambda * h);
        if let Some(sens) = self.sens.as_deref_mut() {
            let at = parameter_sensitivity::Point { w, x };
            sens.sub_step(&self.p, s, before, (at, at, at), h);
        }
    }

    /// The step sensitivity of the outputs `z` and `F` after a step of
    /// length `h` over which the inputs `v`, `x`, `Fn` were held (the exact
    /// update of [`LuGre::step`] with constant inputs), with respect to one
    /// of those inputs: `∂z⁺/∂u` and `∂F⁺/∂u`, the state change over the
    /// step and the direct feedthrough together. `self` is the state after
    /// that step. `None` where the step map is not smooth over
    /// `[u − spread, u + spread]` (`u = v`: `|v| ≤ spread`, the kink of
    /// `|v|` at 0, or `v` NaN; `u = x`: a point of the position table in
    /// that interval; `u = Fn` in the normal-force form: `Fn ≤ spread`, the
    /// kink of `max(Fn, 0)`).
    ///
    /// The held update (Sun et al. 2016 eq. 10–11 at constant inputs,
    /// integrated exactly): with `w = |v|`, `s = sgn v`, `g = g(w, s, x)`
    /// the level per unit `Fn` (direction and position scale included),
    ///
    /// ```text
    /// zss = s·g/σ0,   λ = σ0·w/g,   E = e^(−λh),   z⁺ = zss + (z − zss)·E,
    /// ```
    ///
    /// and the output (Sun et al. 2016 eq. 9, Dion et al. 2013 eq. 1)
    /// `F⁺ = (σ0·z⁺ + σ1(v)·ż⁺ + σ2·v)·φ(Fn)`, `ż⁺ = v − λ·z⁺`,
    /// `σ1(v) = σ1·e^(−(v/vd)²)`, `φ(Fn) = max(Fn, 0)` (1 outside the
    /// normal-force form). Differentiating, with `z⁺ − zss = (z − zss)·E`
    /// (so the pre-step `z` is not needed):
    ///
    /// ```text
    /// ∂z⁺/∂u = (∂zss/∂u)·(1 − E) − h·(∂λ/∂u)·(z⁺ − zss)
    /// ∂ż⁺/∂u = [u = v] − (∂λ/∂u)·z⁺ − λ·∂z⁺/∂u
    /// ∂F⁺/∂u = (σ0·∂z⁺/∂u + σ1′(v)·ż⁺·[u = v] + σ1(v)·∂ż⁺/∂u + σ2(v)·[u = v])·φ
    /// ```
    ///
    /// with, for `u = v` (`g′ = ∂g/∂w`, [`LuGre::level_and_slope`]):
    /// `∂zss/∂v = g′/σ0`, `∂λ/∂v = σ0·s·(g − w·g′)/g²`,
    /// `σ1′(v) = −2·v/vd²·σ1(v)`; for `u = x` (`g = scale(x)·G(w)`):
    /// `∂g/∂x = scale′(x)·G`, `∂zss/∂x = s·∂g/∂x/σ0`, `∂λ/∂x = −λ·∂g/∂x/g`;
    /// for `u = Fn`: `∂z⁺/∂Fn = 0`, `∂F⁺/∂Fn = (F⁺ − F_offset)/φ` (φ′ = 1
    /// for `Fn > 0`; the offset is not scaled by `Fn`). σ2(v) is the
    /// viscous coefficient of the direction of `v` (`sigma2_neg` for
    /// `v < 0` when direction-dependent). At `v = 0` the step changes
    /// nothing and `F = σ0·z·φ + F_offset`: `∂/∂x` is 0.
    pub fn held_step_sensitivity(
        &self,
        input: HeldInput,
        v: f64,
        x: f64,
        fn_: f64,
        h: f64,
        spread: f64,
    ) -> Option<StepSensitivity> {
        let p = &self.p;
        let zero = StepSensitivity { z: 0.0, force: 0.0 };
        let z = self.z;
        let x_slope = match input {
            HeldInput::Fn => {
                if !p.normal_force_form {
                    return Some(zero);
                }
                if fn_.is_nan() || fn_ <= spread {
                    return None;
                }
                let zd = self.z_rate(z, v, x, fn_);
                return Some(StepSensitivity {
                    z: 0.0,
                    force: self.force_per_unit(z, v, zd),
                });
            }
            HeldInput::V => {
                if v.is_nan() || v.abs() <= spread {
                    return None;
                }
                0.0
            }
            HeldInput::X => {
                if v.is_nan() {
                    return None;
                }
                if !p.position_dependent || v == 0.0 {
                    return Some(zero);
                }
                self.scale_slope(v, x, spread)?
            }
        };
        let by_v = input == HeldInput::V;
        let s = if v > 0.0 { 1.0 } else { -1.0 };
        let w = v.abs();
        let (g, dg_dw, unscaled) = self.level_and_slope(w, s, x);
        let sigma0 = p.sigma0;
        let zss = g * s / sigma0;
        let dg_dx = x_slope * unscaled;
        let rate = self.rate_constant(w, s, g, dg_dw, dg_dx);
        let lambda = rate.lambda;
        let lh = lambda * h;
        // 1 − E, exact for small λh too (1 to the last bit beyond λh = 40)
        let settled = if lh > 40.0 { 1.0 } else { -(-lh).exp_m1() };
        let (dzss, dlambda) = if by_v {
            (dg_dw / sigma0, rate.by_v)
        } else {
            (s * dg_dx / sigma0, rate.by_x)
        };
        let dz = dzss * settled - h * dlambda * (z - zss);
        let direct = if by_v { 1.0 } else { 0.0 };
        let dzd = direct - dlambda * z - lambda * dz;
        let s1 = self.sigma1_at(v);
        let mut df = sigma0 * dz + s1 * dzd;
        if by_v {
            let zd = self.z_rate_at_level(z, v, g);
            df += self.sigma1_slope(v, s1) * zd + self.sigma2_at(v);
        }
        Some(StepSensitivity {
            z: dz,
            force: df * self.fn_factor(fn_),
        })
    }

    /// The rate `λ = σ0·w/g` of the state equation `ż = v − λ·z` (for
    /// `w = |v| > 0`, direction `s`, level `g` with slope `dg_dw` in `w`
    /// and `dg_dx` in `x`) and its slopes `∂λ/∂v = σ0·s·(g − w·g′)/g²`
    /// and `∂λ/∂x = −λ·(∂g/∂x)/g`: what the step sensitivities
    /// ([`LuGre::held_step_sensitivity`]) and the partial derivatives of
    /// the right-hand side ([`LuGre::rate_partials`]) are made of.
    #[inline]
    fn rate_constant(&self, w: f64, s: f64, g: f64, dg_dw: f64, dg_dx: f64) -> RateConstant {
        let sigma0 = self.p.sigma0;
        let lambda = sigma0 * w / g;
        RateConstant {
            lambda,
            by_v: sigma0 * s * (g - w * dg_dw) / (g * g),
            by_x: -lambda * dg_dx / g,
        }
    }

    /// `σ1′(v) = −2·v/vd²·σ1(v)` of [`LuGre::sigma1_at`], with `s1` =
    /// σ1(v); 0 for constant σ1 (vd = 0).
    #[inline]
    fn sigma1_slope(&self, v: f64, s1: f64) -> f64 {
        let vd = self.p.vd;
        if vd > 0.0 {
            -2.0 * v / (vd * vd) * s1
        } else {
            0.0
        }
    }

    /// The mean of the one-sided slopes `∂scale/∂x` of the position table
    /// of direction `dir` at `x`: the slope of the segment `x` lies in
    /// (0 beyond the ends), the mean of the two segments at a table point
    /// (where the piecewise-linear scale has a kink; what central
    /// differences converge to); 0 without the table.
    fn scale_slope_mean(&self, dir: f64, x: f64) -> f64 {
        let p = &self.p;
        if !p.position_dependent || x.is_nan() {
            return 0.0;
        }
        let n = p.n_table.clamp(2, TABLE_POINTS);
        let xs = &p.x_table[..n];
        let s = if dir < 0.0 && p.direction_dependent {
            &p.scale_neg
        } else {
            &p.scale_pos
        };
        // segment k lies between points k − 1 and k (0 and n: beyond the ends)
        let slope = |k: usize| {
            if k == 0 || k >= n {
                0.0
            } else {
                (s[k] - s[k - 1]) / (xs[k] - xs[k - 1])
            }
        };
        let right = xs.partition_point(|&xi| xi <= x);
        let left = xs.partition_point(|&xi| xi < x);
        0.5 * (slope(left) + slope(right))
    }

    /// The partial derivatives of the state equation's right-hand side
    /// [`LuGre::z_rate`] at `(z, v, x)` in closed form (it does not depend
    /// on `Fn`). With `ż = v − λ·z`, `λ = σ0·|v|/g` ([`Self::rate_constant`]):
    /// `∂ż/∂z = −λ`, `∂ż/∂v = 1 − z·∂λ/∂v`, `∂ż/∂x = −z·∂λ/∂x` (the slope
    /// of the position table: [`Self::scale_slope_mean`]). At `v = 0`,
    /// where `|v|` has its kink, `ż = 0` for every `z` and `x`, and
    /// `∂ż/∂v` is the mean of the one-sided slopes `1 − s·σ0·z/g(0, s)`
    /// (`s = ±1`; the levels may differ by direction).
    pub fn rate_partials(&self, z: f64, v: f64, x: f64) -> RatePartials {
        let sigma0 = self.p.sigma0;
        if v == 0.0 {
            let forward = 1.0 - sigma0 * z / self.g_unit(0.0, 1.0, x);
            let backward = 1.0 + sigma0 * z / self.g_unit(0.0, -1.0, x);
            return RatePartials {
                z: 0.0,
                v: 0.5 * (forward + backward),
                x: 0.0,
            };
        }
        let s = if v > 0.0 { 1.0 } else { -1.0 };
        let w = v.abs();
        let (g, dg_dw, unscaled) = self.level_and_slope(w, s, x);
        let dg_dx = self.scale_slope_mean(s, x) * unscaled;
        let rate = self.rate_constant(w, s, g, dg_dw, dg_dx);
        RatePartials {
            z: -rate.lambda,
            v: 1.0 - z * rate.by_v,
            x: -z * rate.by_x,
        }
    }

    /// The partial derivatives of the output equation [`LuGre::force_of`]
    /// at `(z, v, x, Fn)` in closed form: with
    /// `F = (σ0·z + σ1(v)·ż + σ2·v)·φ(Fn)` and the partials of `ż` from
    /// [`LuGre::rate_partials`], `∂F/∂z = (σ0 + σ1·∂ż/∂z)·φ`,
    /// `∂F/∂v = (σ1′·ż + σ1·∂ż/∂v + σ2)·φ`, `∂F/∂x = σ1·∂ż/∂x·φ` and, in
    /// the normal-force form, `∂F/∂Fn = F/φ` for `Fn > 0`, 0 for `Fn < 0`
    /// and half of it at the kink `Fn = 0` (0 outside that form).
    pub fn force_partials(&self, z: f64, v: f64, x: f64, fn_: f64) -> ForcePartials {
        let p = &self.p;
        let rate = self.rate_partials(z, v, x);
        let zd = self.z_rate(z, v, x, fn_);
        let s1 = self.sigma1_at(v);
        let phi = self.fn_factor(fn_);
        let by_fn = if !p.normal_force_form || fn_ < 0.0 {
            0.0
        } else {
            let per_unit = self.force_per_unit(z, v, zd);
            if fn_ > 0.0 {
                per_unit
            } else {
                0.5 * per_unit
            }
        };
        ForcePartials {
            z: (p.sigma0 + s1 * rate.z) * phi,
            v: (self.sigma1_slope(v, s1) * zd + s1 * rate.v + self.viscous_slope(v)) * phi,
            x: s1 * rate.x * phi,
            fn_: by_fn,
        }
    }

    /// Sub-stepped integration over `[a, b]` on which `sgn v = s ≠ 0`.
    fn integrate_piece(&mut self, inp: &LuGreInputs, a: f64, b: f64, s: f64) {
        let v = inp.v;
        let x = inp.x;
        let min_len = (b - a) / MAX_SUBSTEPS as f64;
        let rate_x = self.table_rate * x.slope.abs();
        let vs = self.p.vs;
        // Times in (a, b) at which x(t) passes a table point (kinks of the
        // scale factor), in increasing order; sub-steps end exactly there.
        let mut kinks = [0.0; TABLE_POINTS];
        let mut n_kinks = 0;
        if self.p.position_dependent && x.slope != 0.0 {
            let n = self.p.n_table.clamp(2, TABLE_POINTS);
            for j in 0..n {
                let i = if x.slope > 0.0 { j } else { n - 1 - j };
                let tk = (self.p.x_table[i] - x.value) / x.slope;
                if tk > a && tk < b {
                    kinks[n_kinks] = tk;
                    n_kinks += 1;
                }
            }
        }
        // A level constant over the piece (no Stribeck term, or one that is
        // 0 to the last bit at both ends and so between them, |v| being
        // monotone on a one-sign piece; the scale fixed): zss is constant
        // and λ = σ0·|v|/g linear in t, so one sub-step, whose midpoint λ
        // integrates λ exactly, is the exact solution
        // z = zss + (z − zss)·e^(−∫λ).
        let level_constant = (!self.p.position_dependent || x.slope == 0.0)
            && self.stribeck_vanishes(v.at(a).abs(), s)
            && self.stribeck_vanishes(v.at(b).abs(), s);
        let mut next_kink = 0;
        let mut t = a;
        let mut zss_a = self.zss(v.at(t).abs(), s, x.at(t));
        let mut z = self.z;
        let mut count = 0;
        while t < b {
            count += 1;
            while next_kink < n_kinks && kinks[next_kink] <= t {
                next_kink += 1;
            }
            let end = if next_kink < n_kinks {
                kinks[next_kink]
            } else {
                b
            };
            let rest = end - t;
            let mut len = rest;
            if count < MAX_SUBSTEPS && !level_constant {
                let rate = (v.slope.abs() / (v.at(t).abs() + vs) / KAPPA_V).max(rate_x / KAPPA_X);
                if rate * rest > 1.0 {
                    len = (1.0 / rate).max(min_len);
                }
            }
            let t1 = if len >= rest { end } else { t + len };
            let hs = t1 - t;
            let tm = 0.5 * (t + t1);
            let wm = v.at(tm).abs();
            let lambda = self.p.sigma0 * wm / self.g_unit(wm, s, x.at(tm));
            let zss_b = self.zss(v.at(t1).abs(), s, x.at(t1));
            let (decay, phi) = decay_and_mean(lambda * hs);
            if let Some(sens) = self.sens.as_deref_mut() {
                let point = |t: f64| parameter_sensitivity::Point {
                    w: v.at(t).abs(),
                    x: x.at(t),
                };
                sens.sub_step(&self.p, s, z, (point(t), point(tm), point(t1)), hs);
            }
            z = zss_b + (z - zss_a) * decay - (zss_b - zss_a) * phi;
            zss_a = zss_b;
            t = t1;
        }
        self.z = z;
    }

    // The state: the mean bristle deflection z, any finite value, and,
    // when they are carried, ∂z/∂p after it (parameter_sensitivity.rs).

    /// The number of values of the state: 1, or 1 + the number of
    /// parameters when their sensitivities are carried.
    #[inline]
    pub fn state_len(&self) -> usize {
        match &self.sens {
            None => 1,
            Some(_) => 1 + parameter_sensitivity::PARAMETERS,
        }
    }

    /// The state `[z, ∂z/∂p…]` into `out`, of [`Self::state_len`] values.
    #[inline]
    pub fn write_state_into(&self, out: &mut [f64]) {
        match &self.sens {
            None => out.copy_from_slice(&[self.z]),
            Some(sens) => {
                out[0] = self.z;
                out[1..].copy_from_slice(&sens.dz);
            }
        }
    }

    /// Whether `z` (and every carried sensitivity) is finite.
    #[inline]
    pub fn state_is_finite(&self) -> bool {
        self.z.is_finite()
            && self
                .sens
                .as_ref()
                .is_none_or(|s| s.dz.iter().all(|d| d.is_finite()))
    }

    /// The same state as a new vector.
    pub fn state_to_vec(&self) -> Vec<f64> {
        let mut v = vec![0.0; self.state_len()];
        self.write_state_into(&mut v);
        v
    }

    /// Restores `[z]`, or `[z, ∂z/∂p…]` when the sensitivities are carried
    /// (any finite values).
    #[inline]
    pub fn state_from_slice(&mut self, s: &[f64]) -> Result<(), String> {
        match self.sens.as_deref_mut() {
            None => self.z = crate::state::one_finite_value(s, "LuGre", "z")?,
            Some(sens) => {
                if s.len() != 1 + parameter_sensitivity::PARAMETERS
                    || !s.iter().all(|x| x.is_finite())
                {
                    return Err(format!(
                        "LuGre state with parameter sensitivities has {} finite values, got {} ({})",
                        1 + parameter_sensitivity::PARAMETERS,
                        s.len(),
                        if s.iter().all(|x| x.is_finite()) { "all finite" } else { "not all finite" }
                    ));
                }
                self.z = s[0];
                sens.dz.copy_from_slice(&s[1..]);
            }
        }
        Ok(())
    }
}

/// The two factors of a sub-step's update over `lh = λ·hs ≥ 0`:
/// `e^(−lh)` and `φ = (1 − e^(−lh))/lh` (the mean of `e^(−λτ)` over the
/// sub-step; 1 at `lh = 0`), both to within a few units in the last place,
/// from one call of libm: beyond `lh = 0.5`, `1 − e^(−lh) ≥ 0.39` is taken
/// from `e^(−lh)` with no cancellation to speak of (and is 1 to the last
/// bit beyond `lh = 40`); below, `e^(−lh) − 1` comes from `exp_m1`, which
/// keeps `φ` exact for small `lh`, and `e^(−lh)` is 1 plus it. (A NaN `lh`
/// gives a NaN decay, as `exp` would.)
#[inline]
fn decay_and_mean(lh: f64) -> (f64, f64) {
    if lh > 0.5 {
        let decay = exp_neg(lh);
        (decay, (1.0 - decay) / lh)
    } else if lh > 0.0 {
        let decay_m1 = (-lh).exp_m1();
        (1.0 + decay_m1, -decay_m1 / lh)
    } else {
        (exp_neg(lh), 1.0)
    }
}

/// Beyond this [`exp_neg`] is 0 without calling `exp`, which would give
/// 0 too: `e^(−745.2)` is below half the least subnormal (4.9e-324).
/// (`exp` already rounds to 0 from about 745.13.)
const EXP_NEG_ZERO_BEYOND: f64 = 745.2;

/// `e^(−a)` for `a ≥ 0`, with 0 beyond the smallest subnormal (a > 745.2,
/// where `exp` returns 0 anyway) without libm's slow underflow path, which
/// a stiff contact (σ0|v|h/g in the thousands) or a Stribeck term far above
/// vs would otherwise take at every step.
#[inline]
fn exp_neg(a: f64) -> f64 {
    if a > EXP_NEG_ZERO_BEYOND {
        0.0
    } else {
        (-a).exp()
    }
}

pub mod parameter_sensitivity;

#[cfg(test)]
mod step_sensitivity_tests;

#[cfg(test)]
mod tests {
    use super::*;

    fn inputs(v: Ramp) -> LuGreInputs {
        LuGreInputs {
            v,
            x: Ramp::constant(0.0),
            fn_: Ramp::constant(1.0),
        }
    }

    fn stribeck(p: &LuGreParams, v: f64) -> f64 {
        v.signum() * (p.fc + (p.fs - p.fc) * (-(v / p.vs).powi(2)).exp()) + p.sigma2 * v
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// The sub-step factors from one call of libm equal the two-call
    /// forms `e^(−lh)` and `−expm1(−lh)/lh` (each within an ulp) to a few
    /// ulp, from where `1 − e^(−lh)` would lose every digit (lh = 1e-14)
    /// to where the decay underflows.
    #[test]
    fn decay_and_mean_match_their_two_call_forms() {
        assert_eq!(decay_and_mean(0.0), (1.0, 1.0));
        assert!(decay_and_mean(f64::NAN).0.is_nan());
        let mut lh = 1e-14;
        while lh < 1e3 {
            let (decay, mean) = decay_and_mean(lh);
            let (decay_ref, mean_ref) = (exp_neg(lh), -(-lh).exp_m1() / lh);
            if decay_ref > 0.0 {
                assert!(
                    rel(decay, decay_ref) <= 4.5e-16,
                    "lh = {lh}: {decay} against {decay_ref}"
                );
            } else {
                assert_eq!(decay, 0.0, "lh = {lh}");
            }
            assert!(
                rel(mean, mean_ref) <= 1e-15,
                "lh = {lh}: {mean} against {mean_ref}"
            );
            lh *= 1.37;
        }
    }

    /// Without a Stribeck term (Fs = Fc) the level is Fc, bit for bit, as
    /// the formula with the exponential gives it; with one, the term is
    /// there.
    #[test]
    fn level_without_a_stribeck_term_is_fc_exactly() {
        let mut p = LuGreParams::default();
        p.fs = p.fc;
        let law = LuGre::new(p).unwrap();
        for w in [1e-9, 1e-3, p.vs, 0.37, 50.0] {
            let e = (w / p.vs).powi(2);
            let with_exponential = p.fc + (p.fs - p.fc) * exp_neg(e);
            assert_eq!(
                law.g_unit_computed(w, 1.0, 0.0).to_bits(),
                with_exponential.to_bits()
            );
        }
        let stribeck = LuGre::new(LuGreParams::default()).unwrap();
        let p = LuGreParams::default();
        assert!(stribeck.g_unit_computed(p.vs, 1.0, 0.0) > p.fc);
    }

    /// `force_and_sliding` is `force` and `sliding` bit for bit: at rest,
    /// both directions, in stick and in slip, with direction-dependent
    /// levels, micro-damping and the normal-force form.
    #[test]
    fn force_and_sliding_is_force_and_sliding() {
        let plain = LuGreParams::sun_2016();
        let varied = LuGreParams {
            direction_dependent: true,
            fc_neg: 0.8 * plain.fc,
            fs_neg: 0.9 * plain.fs,
            vd: 0.02,
            normal_force_form: true,
            ..plain
        };
        for p in [plain, varied] {
            let mut law = LuGre::new(p).unwrap();
            for z in [0.0, 2e-6, -5e-6, 1e-4, -1e-4] {
                law.set_z(z);
                for v in [0.0, -0.0, 1e-9, -1e-9, 1e-3, -1e-3, 0.05, -0.5, 3.0] {
                    for fn_ in [1.0, 25.0] {
                        let (f, sliding) = law.force_and_sliding(v, 0.0, fn_);
                        let expected = law.force(v, 0.0, fn_);
                        assert_eq!(f.to_bits(), expected.to_bits(), "z {z}, v {v}");
                        assert_eq!(sliding, law.sliding(v, 0.0, fn_), "z {z}, v {v}");
                        // P_diss = F·v − σ0·z·ż·φ(Fn), from the same level
                        let zd = law.z_rate(z, v, 0.0, fn_);
                        let phi = if p.normal_force_form { fn_ } else { 1.0 };
                        let power = expected * v - p.sigma0 * z * zd * phi;
                        let got = law.dissipated_power(v, 0.0, fn_);
                        assert!((got - power).abs() <= 1e-15 * (expected * v).abs().max(1e-300));
                    }
                }
            }
        }
    }

    #[test]
    fn parameter_sets_and_validation() {
        let p = LuGreParams::sun_2016();
        assert!((p.sigma1 - 344.56).abs() < 0.01, "{}", p.sigma1);
        assert!(LuGre::new(p).is_ok());
        assert!(LuGre::new(LuGreParams::default()).is_ok());
        let e = LuGre::new(LuGreParams { fs: 1.0, ..p }).unwrap_err();
        assert_eq!(e.name, "Fs");
        assert!(e.rule.contains(">= Fc = 1.284"), "{}", e.rule);
        let bad = |q: LuGreParams| LuGre::new(q).unwrap_err().name;
        assert_eq!(bad(LuGreParams { sigma0: 0.0, ..p }), "sigma0");
        assert_eq!(bad(LuGreParams { sigma1: -1.0, ..p }), "sigma1");
        assert_eq!(
            bad(LuGreParams {
                sigma2: f64::NAN,
                ..p
            }),
            "sigma2"
        );
        assert_eq!(bad(LuGreParams { fc: 0.0, ..p }), "Fc");
        assert_eq!(bad(LuGreParams { vs: 0.0, ..p }), "vs");
        assert_eq!(
            bad(LuGreParams {
                stribeck_exponent: 0.0,
                ..p
            }),
            "stribeck_exponent"
        );
        assert_eq!(bad(LuGreParams { vd: -1.0, ..p }), "vd");
        let dd = LuGreParams {
            direction_dependent: true,
            ..p
        };
        assert_eq!(bad(LuGreParams { fc_neg: -1.0, ..dd }), "Fc_neg");
        assert_eq!(bad(LuGreParams { fs_neg: 1.0, ..dd }), "Fs_neg");
        let pd = LuGreParams {
            position_dependent: true,
            ..dd
        };
        assert_eq!(bad(LuGreParams { n_table: 1, ..pd }), "n_table");
        assert_eq!(bad(LuGreParams { n_table: 33, ..pd }), "n_table");
        let mut q = pd;
        q.x_table[4] = q.x_table[3];
        let e = LuGre::new(q).unwrap_err();
        assert_eq!(e.name, "x_table");
        assert!(e.rule.contains("x_table[5]"), "{}", e.rule);
        q.n_table = 4; // the bad point is no longer used
        assert!(LuGre::new(q).is_ok());
        let mut q = pd;
        q.scale_neg[0] = 0.0;
        assert_eq!(bad(q), "scale_neg");
        q.direction_dependent = false; // scale_neg unused
        assert!(LuGre::new(q).is_ok());
        q.scale_pos[31] = -1.0;
        assert_eq!(bad(q), "scale_pos");
    }

    #[test]
    fn steady_force_follows_the_stribeck_curve() {
        let p = LuGreParams::sun_2016();
        let mut worst: f64 = 0.0;
        for i in 0..20 {
            // ±1e-5 … ±1e-1 m/s, ten log-spaced speeds per sign.
            let w = 1e-5 * 10f64.powf(4.0 * (i % 10) as f64 / 9.0);
            let v = if i < 10 { w } else { -w };
            let mut l = LuGre::new(p).unwrap();
            l.step(&inputs(Ramp::constant(v)), 1e3);
            let f = l.force(v, 0.0, 1.0);
            let e = rel(f, stribeck(&p, v));
            worst = worst.max(e);
            assert!(e < 1e-6, "v {v}: {f} vs {}", stribeck(&p, v));
            assert!((l.steady_force(v, 0.0, 1.0) - stribeck(&p, v)).abs() < 1e-12);
            assert!(l.sliding(v, 0.0, 1.0) && !l.sliding(-v, 0.0, 1.0));
        }
        assert!(worst < 1e-6);
    }

    #[test]
    fn small_displacement_is_elastic() {
        let p = LuGreParams::sun_2016();
        let mut l = LuGre::new(p).unwrap();
        // 1e-8 m in 1 ms, then at rest: F = σ0·z ≈ σ0·x.
        let x = 1e-8;
        l.step(&inputs(Ramp::constant(x / 1e-3)), 1e-3);
        assert!(rel(l.force(0.0, 0.0, 1.0), p.sigma0 * x) < 1e-3);
        assert!(!l.sliding(x / 1e-3, 0.0, 1.0));
        // 1e-7 m: the exact solution z = zss(1 − e^(−σ0 x/g)).
        let mut l = LuGre::new(p).unwrap();
        let v = 1e-4;
        l.step(&inputs(Ramp::constant(v)), 1e-3);
        let g = l.g(v, 0.0, 1.0);
        let expect = g / p.sigma0 * -(-p.sigma0 * 1e-7 / g).exp_m1();
        assert!(rel(l.z(), expect) < 1e-12);
        assert!(rel(l.z(), 1e-7) < 3e-3);
    }

    /// Fine RK4 of `ż = v(t) − σ0|v(t)|z/g(v(t), x(t))` on a piecewise-linear
    /// input, `m` sub-steps per communication step.
    fn rk4(l: &LuGre, z0: f64, inp: &LuGreInputs, h: f64, m: usize) -> f64 {
        let f = |t: f64, z: f64| {
            let v = inp.v.at(t);
            if v == 0.0 {
                return 0.0;
            }
            v - l.p.sigma0 * v.abs() * z / l.g_unit(v.abs(), v, inp.x.at(t))
        };
        let dt = h / m as f64;
        let mut z = z0;
        for k in 0..m {
            let t = k as f64 * dt;
            let k1 = f(t, z);
            let k2 = f(t + 0.5 * dt, z + 0.5 * dt * k1);
            let k3 = f(t + 0.5 * dt, z + 0.5 * dt * k2);
            let k4 = f(t + dt, z + dt * k3);
            z += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        z
    }

    fn check_against_rk4(p: LuGreParams, h: f64, n: usize, vel: impl Fn(f64) -> f64) {
        let mut l = LuGre::new(p).unwrap();
        let mut r = LuGre::new(p).unwrap();
        let mut x = 0.0;
        let scale = p.fs;
        let mut worst: f64 = 0.0;
        for k in 0..n {
            let t = k as f64 * h;
            let (v0, v1) = (vel(t), vel(t + h));
            let inp = LuGreInputs {
                v: Ramp::new(v0, (v1 - v0) / h),
                x: Ramp::new(x, v0),
                fn_: Ramp::constant(1.0),
            };
            x += 0.5 * (v0 + v1) * h;
            l.step(&inp, h);
            // Reference sub-step 1e-6 s or finer.
            let m = ((h / 1e-6).ceil() as usize).max(20);
            let zr = rk4(&r, r.z, &inp, h, m);
            r.set_z(zr);
            let (fl, fr) = (l.force(v1, x, 1.0), r.force(v1, x, 1.0));
            worst = worst.max((fl - fr).abs() / scale);
        }
        assert!(worst < 1e-6, "h {h}: worst force error {worst:e} of Fs");
    }

    #[test]
    fn ramped_inputs_match_a_fine_rk4_reference() {
        let p = LuGreParams::default();
        // Through the Stribeck region and zero crossings, slow and fast.
        let slow = |t: f64| 5e-3 * (2.0 * std::f64::consts::PI * t).sin();
        check_against_rk4(p, 1e-2, 150, slow);
        check_against_rk4(p, 0.25, 6, slow);
        let fast = |t: f64| 0.2 * (3.0 * t).sin() + 0.05;
        check_against_rk4(p, 0.1, 20, fast);
        // With position- and direction-dependent levels.
        let mut q = LuGreParams::sun_2016();
        q.direction_dependent = true;
        q.fc_neg = 1.0;
        q.fs_neg = 2.0;
        q.position_dependent = true;
        q.n_table = 5;
        for i in 0..5 {
            q.x_table[i] = -1e-3 + 5e-4 * i as f64;
            q.scale_pos[i] = 1.0 + 0.3 * (i as f64).sin();
            q.scale_neg[i] = 1.0 + 0.2 * (i as f64).cos();
        }
        check_against_rk4(q, 2e-2, 60, |t| 3e-3 * (5.0 * t).sin());
    }

    /// With a level constant over a ramped step (Fs = Fc, or a speed far
    /// above vs where the Stribeck term is 0), the step is the closed form
    /// z = zss + (z0 − zss)·e^(−σ0/g·∫|v|) in one sub-step; it also matches
    /// the RK4 reference through zero crossings.
    #[test]
    fn ramped_inputs_at_a_constant_level_take_the_closed_form() {
        let mut p = LuGreParams::default();
        p.fs = p.fc;
        check_against_rk4(p, 1e-2, 150, |t| {
            5e-3 * (2.0 * std::f64::consts::PI * t).sin()
        });
        let fast = LuGreParams::default();
        // (v0, v1): from rest upward with Fs = Fc; 30·vs and more with the
        // default Stribeck term (e^(−900) = 0)
        for (params, v0, v1, g) in [(p, 1e-4, 2e-2, p.fc), (fast, 30.0 * fast.vs, 0.5, fast.fc)] {
            let h = 1e-3;
            let mut law = LuGre::new(params).unwrap();
            law.set_z(0.2 * g / params.sigma0);
            let z0 = law.z;
            law.step(&inputs(Ramp::new(v0, (v1 - v0) / h)), h);
            let zss = g / params.sigma0;
            let travel = 0.5 * (v0 + v1) * h;
            let closed = zss + (z0 - zss) * (-params.sigma0 / g * travel).exp();
            assert!(rel(law.z, closed) < 1e-13, "{} against {closed}", law.z);
        }
    }

    #[test]
    fn step_size_independence_on_smooth_input() {
        let p = LuGreParams::default();
        let vel = |t: f64| 0.01 * (std::f64::consts::PI * t).sin() + 2e-3 * (7.0 * t).cos();
        let run = |h: f64, n: usize| {
            let mut l = LuGre::new(p).unwrap();
            let mut out = Vec::new();
            let per_sample = (1e-2 / h).round() as usize;
            for k in 0..n {
                let t = k as f64 * h;
                let (v0, v1) = (vel(t), vel(t + h));
                l.step(&inputs(Ramp::new(v0, (v1 - v0) / h)), h);
                if (k + 1) % per_sample == 0 {
                    out.push(l.force(v1, 0.0, 1.0));
                }
            }
            out
        };
        let fine = run(1e-5, 200_000);
        let coarse = run(1e-2, 200);
        assert_eq!(fine.len(), coarse.len());
        let worst = fine
            .iter()
            .zip(&coarse)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-3 * p.fs, "worst {worst}");
    }

    #[test]
    fn direction_position_and_normal_force_scale_the_steady_force() {
        let mut p = LuGreParams {
            direction_dependent: true,
            fc_neg: 0.8,
            fs_neg: 1.1,
            position_dependent: true,
            n_table: 3,
            normal_force_form: true,
            ..LuGreParams::default()
        };
        p.x_table[..3].copy_from_slice(&[0.0, 0.1, 0.3]);
        p.scale_pos[..3].copy_from_slice(&[1.0, 2.0, 0.5]);
        p.scale_neg[..3].copy_from_slice(&[1.5, 1.0, 1.0]);
        let fn_ = 40.0;
        for &(v, x, scale) in &[
            (2e-3, 0.05, 1.5),
            (2e-3, 0.2, 1.25),
            (2e-3, -1.0, 1.0),
            (2e-3, 5.0, 0.5),
            (-2e-3, 0.05, 1.25),
            (-2e-3, 0.3, 1.0),
        ] {
            let (fc, fs) = if v > 0.0 {
                (p.fc, p.fs)
            } else {
                (p.fc_neg, p.fs_neg)
            };
            let level = scale * (fc + (fs - fc) * (-(v / p.vs).powi(2)).exp());
            let expect = fn_ * (level * v.signum() + p.sigma2 * v);
            let mut l = LuGre::new(p).unwrap();
            let inp = LuGreInputs {
                v: Ramp::constant(v),
                x: Ramp::constant(x),
                fn_: Ramp::constant(fn_),
            };
            l.step(&inp, 10.0);
            assert!(rel(l.force(v, x, fn_), expect) < 1e-9, "v {v} x {x}");
            assert!(rel(l.steady_force(v, x, fn_), expect) < 1e-12);
            assert!(rel(l.g(v, x, fn_), fn_ * level) < 1e-12);
            // z is independent of Fn; Fn = 0 gives F = 0.
            assert!(rel(l.z(), level * v.signum() / p.sigma0) < 1e-9);
            assert_eq!(l.force(v, x, 0.0), 0.0);
            assert_eq!(l.force(v, x, -5.0), 0.0);
        }
    }

    #[test]
    fn velocity_dependent_micro_damping() {
        let p = LuGreParams {
            vd: 1e-3,
            ..LuGreParams::default()
        };
        let l = LuGre::new(p).unwrap();
        // z = 0: ż = v, F = σ1·e^(−(v/vd)²)·v + σ2·v.
        let v = 2e-3;
        let expect = p.sigma1 * (-4.0f64).exp() * v + p.sigma2 * v;
        assert!(rel(l.force(v, 0.0, 1.0), expect) < 1e-14);
    }

    /// Every option on: direction-dependent levels, a three-point position
    /// table for each direction, decaying micro-damping, the normal-force
    /// form.
    fn every_option() -> LuGreParams {
        let mut p = LuGreParams {
            direction_dependent: true,
            fc_neg: 0.7,
            fs_neg: 1.2,
            position_dependent: true,
            n_table: 3,
            vd: 2e-3,
            normal_force_form: true,
            ..LuGreParams::default()
        };
        p.x_table[..3].copy_from_slice(&[0.0, 0.1, 0.3]);
        p.scale_pos[..3].copy_from_slice(&[1.0, 2.0, 0.5]);
        p.scale_neg[..3].copy_from_slice(&[1.5, 1.0, 1.0]);
        p
    }

    #[test]
    fn pure_right_hand_side_matches_the_state_methods_and_the_stepper() {
        let p = every_option();
        let mut l = LuGre::new(p).unwrap();
        for &(z, v, x, fn_) in &[
            (3e-6, 1e-3, 0.05, 2.0),
            (-1e-5, -4e-3, 0.2, 1.0),
            (1e-5, 0.3, -1.0, 0.5),
            (2e-6, 0.0, 0.1, 3.0),
        ] {
            l.set_z(z);
            assert_eq!(
                l.z_rate(z, v, x, fn_).to_bits(),
                l.z_dot(v, x, fn_).to_bits()
            );
            assert_eq!(
                l.force_of(z, v, x, fn_).to_bits(),
                l.force(v, x, fn_).to_bits()
            );
            // ż = v − σ0|v|z/g, written out.
            let g = l.g(v, x, 1.0);
            let expect = if v == 0.0 {
                0.0
            } else {
                v - p.sigma0 * v.abs() * z / g
            };
            assert!((l.z_rate(z, v, x, fn_) - expect).abs() <= 1e-15 * v.abs().max(1e-12));
            // The exact stepper over a tiny step moves z by ż·h to first order.
            let h = 1e-9;
            let inp = LuGreInputs {
                v: Ramp::constant(v),
                x: Ramp::constant(x),
                fn_: Ramp::constant(fn_),
            };
            let mut m = l.clone();
            m.step(&inp, h);
            let fd = (m.z() - z) / h;
            let rate = l.z_rate(z, v, x, fn_);
            assert!(
                (fd - rate).abs() <= 1e-5 * rate.abs().max(1e-9),
                "v {v}: {fd} vs {rate}"
            );
        }
    }

    /// The closed-form partials of the right-hand side and of the force
    /// against central differences of `z_rate` and `force_of` themselves:
    /// every option (direction- and position-dependent levels, normal-force
    /// form, decaying micro-damping, Stribeck exponents 2, 1.4 and 0.6),
    /// stick and slip, both directions; at v = 0, at a table point and at
    /// Fn = 0 (kinks) the mean of the two sides, as the differences give.
    /// The offset adds a constant to the force, at rest as in motion, and
    /// leaves the bristle dynamics alone; `sigma2_neg` takes σ2's place for
    /// v < 0 only. Closed forms: a contact sliding steadily at v carries
    /// `g(v)·sgn v + σ2(v)·v + F_offset`; at rest with deflection z it
    /// carries `σ0·z + F_offset`.
    #[test]
    fn offset_and_direction_dependent_viscous_friction_in_closed_form() {
        let plain = LuGreParams::default();
        let p = LuGreParams {
            direction_dependent_viscous: true,
            sigma2_neg: 3.0,
            f_offset: -0.2,
            ..plain
        };
        for v in [-0.05, -2e-3, 1e-3, 0.05] {
            let mut a = LuGre::new(p).unwrap();
            let mut b = LuGre::new(plain).unwrap();
            // long enough to reach the steady deflection (λ·h ≫ 1)
            a.step(&inputs(Ramp::constant(v)), 10.0);
            b.step(&inputs(Ramp::constant(v)), 10.0);
            assert_eq!(a.z(), b.z(), "the offset and σ2 leave z alone, v {v}");
            let sigma2 = if v < 0.0 { 3.0 } else { plain.sigma2 };
            let g = plain.fc + (plain.fs - plain.fc) * (-(v / plain.vs).powi(2)).exp();
            let expect = g * v.signum() + sigma2 * v - 0.2;
            assert!(rel(a.force(v, 0.0, 1.0), expect) < 1e-12, "v {v}");
            assert!(rel(a.steady_force(v, 0.0, 1.0), expect) < 1e-12, "v {v}");
        }
        let mut rest = LuGre::new(p).unwrap();
        rest.set_z(4e-6);
        let expect = p.sigma0 * 4e-6 - 0.2;
        assert!(rel(rest.force(0.0, 0.0, 1.0), expect) < 1e-12);
        assert_eq!(rest.steady_force(0.0, 0.0, 1.0), -0.2);
        // off, sigma2_neg is not used and not checked
        let off = LuGreParams {
            sigma2_neg: -1.0,
            ..plain
        };
        assert!(LuGre::new(off).is_ok());
        let bad = |q: LuGreParams| LuGre::new(q).unwrap_err().name;
        assert_eq!(
            bad(LuGreParams {
                direction_dependent_viscous: true,
                ..off
            }),
            "sigma2_neg"
        );
        for offset in [f64::NAN, f64::INFINITY] {
            assert_eq!(
                bad(LuGreParams {
                    f_offset: offset,
                    ..plain
                }),
                "F_offset"
            );
        }
        // the normal-force form scales the law, not the offset
        let per_newton = LuGreParams {
            normal_force_form: true,
            ..p
        };
        let mut l = LuGre::new(per_newton).unwrap();
        l.step(&inputs(Ramp::constant(-0.05)), 10.0);
        let f1 = l.force(-0.05, 0.0, 1.0);
        let f3 = l.force(-0.05, 0.0, 3.0);
        assert!(rel(f3 + 0.2, 3.0 * (f1 + 0.2)) < 1e-12, "{f1} {f3}");
    }

    #[test]
    fn rate_and_force_partials_match_differences() {
        let options = every_option();
        let sets = [
            LuGreParams::default(),
            LuGreParams::sun_2016(),
            options,
            LuGreParams {
                stribeck_exponent: 1.4,
                ..options
            },
            LuGreParams {
                stribeck_exponent: 0.6,
                ..LuGreParams::default()
            },
            // direction-dependent viscous friction (a kink of σ2(v)·v at
            // v = 0, where central differences give the mean slope) and an
            // offset, which ∂F/∂Fn must leave out
            LuGreParams {
                direction_dependent_viscous: true,
                sigma2_neg: 2.5,
                f_offset: -0.3,
                ..options
            },
        ];
        let points = [
            (3e-6, 1e-3, 0.05, 2.0),
            (-1e-5, -4e-3, 0.2, 1.0),
            (1e-5, 0.3, -1.0, 0.5),
            (1.4e-5, 2e-4, 0.15, 1.0),
            (2e-6, 0.0, 0.05, 3.0),
            (-5e-6, 0.0, 0.2, 1.0),
            (4e-6, 2e-3, 0.1, 1.0),
            (4e-6, -2e-3, 0.0, 0.0),
        ];
        let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-6 * b.abs().max(scale);
        for p in sets {
            let l = LuGre::new(p).unwrap();
            for &(z, v, x, fn_) in &points {
                let r = l.rate_partials(z, v, x);
                let f = l.force_partials(z, v, x, fn_);
                let (hz, hv, hx, hf) = (1e-12, 1e-9, 1e-7, 1e-7);
                let dz = |g: &dyn Fn(f64, f64, f64, f64) -> f64| {
                    (g(z + hz, v, x, fn_) - g(z - hz, v, x, fn_)) / (2.0 * hz)
                };
                let dv = |g: &dyn Fn(f64, f64, f64, f64) -> f64| {
                    (g(z, v + hv, x, fn_) - g(z, v - hv, x, fn_)) / (2.0 * hv)
                };
                let dx = |g: &dyn Fn(f64, f64, f64, f64) -> f64| {
                    (g(z, v, x + hx, fn_) - g(z, v, x - hx, fn_)) / (2.0 * hx)
                };
                let dfn = |g: &dyn Fn(f64, f64, f64, f64) -> f64| {
                    (g(z, v, x, fn_ + hf) - g(z, v, x, fn_ - hf)) / (2.0 * hf)
                };
                let rate = |z, v, x, fn_| l.z_rate(z, v, x, fn_);
                let force = |z, v, x, fn_| l.force_of(z, v, x, fn_);
                let at = format!("z {z}, v {v}, x {x}, Fn {fn_} of {p:?}");
                // each compared on the scale of its terms (rounding in the
                // differences is relative to them, not to a small sum)
                let lambda = p.sigma0 * v.abs() / p.fc.min(p.fc_neg);
                let by_x = z.abs() * lambda * 20.0;
                let checks = [
                    ("dz/dz", r.z, dz(&rate), lambda),
                    ("dz/dv", r.v, dv(&rate), 1.0),
                    ("dz/dx", r.x, dx(&rate), by_x),
                    ("dF/dz", f.z, dz(&force), p.sigma0 * fn_.max(1.0)),
                    ("dF/dv", f.v, dv(&force), p.sigma1 * fn_.max(1.0)),
                    ("dF/dx", f.x, dx(&force), p.sigma1 * by_x * fn_.max(1.0)),
                    ("dF/dFn", f.fn_, dfn(&force), 1.0),
                ];
                for (what, closed, differences, scale) in checks {
                    assert!(
                        close(closed, differences, scale),
                        "{what}: {closed} vs {differences} at {at}"
                    );
                }
            }
        }
        // A table point is a kink of the level: at it, the mean of the two
        // segments' slopes (2−1)/0.1 and (0.5−2)/0.2 of `scale_pos`.
        let l = LuGre::new(options).unwrap();
        let near = |a: f64, b: f64| (a - b).abs() <= 1e-12;
        assert!(near(l.scale_slope_mean(1.0, 0.1), 0.5 * (10.0 + -7.5)));
        assert!(near(l.scale_slope_mean(1.0, 0.05), 10.0));
        assert!(near(l.scale_slope_mean(-1.0, 0.05), -5.0));
        assert_eq!(l.scale_slope_mean(1.0, 0.5), 0.0);
        assert!(near(l.scale_slope_mean(1.0, 0.0), 5.0));
    }

    #[test]
    fn state_round_trip_and_finite_for_all_step_sizes() {
        let p = LuGreParams::sun_2016();
        let mut a = LuGre::new(p).unwrap();
        a.step(&inputs(Ramp::new(1e-3, -0.1)), 0.3);
        let mut b = LuGre::new(p).unwrap();
        b.state_from_slice(&a.state_to_vec()).unwrap();
        for &h in &[1e-7, 1e-4, 1e-1, 1.0] {
            for &(v, s) in &[
                (1.0, -3.0),
                (-1e3, 5e3),
                (0.0, 0.0),
                (1e-12, 1e6),
                (0.0, -1e-9),
            ] {
                let inp = LuGreInputs {
                    v: Ramp::new(v, s),
                    x: Ramp::new(1.0, v),
                    fn_: Ramp::new(3.0, -1.0),
                };
                a.step(&inp, h);
                b.step(&inp, h);
                assert!(a.z().is_finite() && a.force(v, 1.0, 3.0).is_finite());
                assert!(a.z().abs() <= p.fs / p.sigma0 * (1.0 + 1e-9));
                assert_eq!(a.z().to_bits(), b.z().to_bits());
            }
        }
        assert!(b.state_from_slice(&[f64::NAN]).is_err());
        assert!(b.state_from_slice(&[0.0, 0.0]).is_err());
    }

    /// A refused state is named as before the messages moved out of line;
    /// the slice writer writes what the vector writer appends.
    #[test]
    fn refused_states_are_named_and_written_states_agree() {
        let mut l = LuGre::new(LuGreParams::default()).unwrap();
        let err = l.state_from_slice(&[f64::NAN]).unwrap_err();
        assert_eq!(err, "LuGre state z = NaN is not finite");
        let err = l.state_from_slice(&[0.0, 0.0]).unwrap_err();
        assert_eq!(err, "LuGre state has 1 value, got 2");
        l.state_from_slice(&[1e-6]).unwrap();
        let mut s = vec![f64::NAN; l.state_len()];
        l.write_state_into(&mut s);
        assert_eq!(s, l.state_to_vec());
    }
}
