//! The friction model that `fricsim diagnose` refits, and its library of
//! candidate effects. Every effect is a feature of the LuGre FMU
//! (`fmu-src/friction-laws/src/lugre.rs`), so adding one changes the
//! friction FMU's parameters, not a formula on the side:
//!
//! | effect | LuGre feature | free parameters |
//! | --- | --- | --- |
//! | `viscous` | σ2·v | σ2 |
//! | `stribeck` | g(v) = Fc + (Fs − Fc)·exp(−(v/vs)²) | Fs/Fc − 1, vs |
//! | `presliding` | finite σ0: ż = v − σ0·|v|·z/g(v), hysteresis over Fc/σ0 | σ0 |
//! | `position_dependent` | levels × a piecewise-linear scale of x | the scales at K knots |
//! | `direction_dependent` | Fc_neg, Fs_neg (and scale_neg) for v < 0 | Fc_neg (or the negative scales) |
//! | `normal_load` | normal-force form: F ∝ the input Fn | (the levels, per newton of Fn) |
//! | `offset` | a constant force F_offset on the contact, at rest too | F_offset |
//! | `direction_dependent_viscous` | sigma2_neg instead of σ2 for v < 0 | σ2, sigma2_neg |
//!
//! **One signature, several explanations.** In steady sliding an offset,
//! direction-dependent levels and direction-dependent viscous friction all
//! make the friction differ between the two directions (the EMPS models of
//! Janot, Gautier, Brunot 2019 weigh exactly these): they are the
//! [`Effect::ASYMMETRY`] family, tried side by side, and the diagnosis
//! names the one the held-out data prefer, with how strongly they separate
//! it from the others.
//!
//! **Added or re-sized.** Every effect whose nominal can already hold it
//! (viscous with σ2 > 0, Stribeck with Fs > Fc, presliding with a finite
//! σ0) is a candidate all the same: for a nominal that has it, the
//! candidate frees its parameters from their nominal values (re-sizes it),
//! so that a nominal off from the data only in that effect is diagnosed as
//! such instead of being absorbed by the baseline refit, which frees the
//! levels only ([`FrictionModel::freed`]). Whether a nominal has
//! presliding is decided from the data: its presliding distance Fc/σ0
//! against the position resolution the measurements show
//! ([`Context::position_resolution`]).
//!
//! **σ1 follows σ0.** Wherever σ0 is fitted, σ1 moves with it at a
//! constant damping ratio of the bristle-mass oscillation
//! (σ1 ∝ √σ0, ζ = σ1 / (2·√(σ0·m)) held at the nominal's): a presliding
//! re-sized from a stiff to a soft contact (or back) keeps its damping
//! instead of becoming over- or under-damped by orders of magnitude
//! (Canudas de Wit et al. 1995 choose σ1 that way, near critical).
//!
//! **One place.** What the diagnosis knows of an effect is here: its name
//! and wording ([`Effect::name`], [`Effect::meaning`]), whether the force
//! the data imply shows it ([`Effect::force_shows`]), what the data must
//! hold for it to be tried ([`Effect::shown_by_data`]), the number its
//! interval is taken of ([`Effect::change`]), its parameters, its neutral
//! start and grid of starts ([`FrictionModel::with`],
//! [`FrictionModel::starts`]), how it is taken out again
//! ([`FrictionModel::without`]) and what it frees
//! ([`FrictionModel::free`]). docs/development.md lists the few places
//! outside this file a new effect goes into.
//!
//! Parameters are fitted through transforms that keep them physical:
//! levels, stiffness, speeds and scales are `exp(θ)` (> 0), the Stribeck
//! excess `Fs/Fc − 1` is `exp(θ)` (Fs > Fc), σ2 is `exp(θ)` (> 0).

use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;

/// A physically named effect of the candidate library.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Effect {
    Viscous,
    Stribeck,
    Presliding,
    PositionDependent,
    DirectionDependent,
    NormalLoad,
    Offset,
    DirectionDependentViscous,
}

impl Effect {
    pub const ALL: [Effect; 8] = [
        Effect::Viscous,
        Effect::Stribeck,
        Effect::Presliding,
        Effect::PositionDependent,
        Effect::DirectionDependent,
        Effect::NormalLoad,
        Effect::Offset,
        Effect::DirectionDependentViscous,
    ];

    /// The effects that explain one signature, a friction that differs
    /// between the directions of sliding, in the library's order of
    /// preference when the data do not separate them.
    pub const ASYMMETRY: [Effect; 3] = [
        Effect::DirectionDependent,
        Effect::Offset,
        Effect::DirectionDependentViscous,
    ];

    /// Effects whose signatures overlap without being one force: a
    /// Stribeck curve (a level that is higher just out of the stick and
    /// falls with speed) and presliding (a contact of another stiffness,
    /// which takes the force over another travel after each reversal)
    /// both change how the contact leaves the stick, and on coarse data
    /// either can take much of the other's gain. Before one of such a pair
    /// is accepted while the other also passes the round's test, each is
    /// fitted after the other, and the one that still adds is kept
    /// (`diagnose::OverlapCheck`).
    pub const OVERLAPPING: [(Effect, Effect); 1] = [(Effect::Stribeck, Effect::Presliding)];

    /// The effect whose signature overlaps `self`'s
    /// ([`Effect::OVERLAPPING`]), if any.
    pub fn overlapping(self) -> Option<Effect> {
        Effect::OVERLAPPING.iter().find_map(|&(a, b)| {
            if a == self {
                Some(b)
            } else if b == self {
                Some(a)
            } else {
                None
            }
        })
    }

    /// The family of explanations `self` belongs to ([`Effect::ASYMMETRY`]),
    /// if any.
    pub fn family(self) -> Option<&'static [Effect]> {
        Effect::ASYMMETRY
            .contains(&self)
            .then_some(&Effect::ASYMMETRY[..])
    }

    pub fn name(self) -> &'static str {
        match self {
            Effect::Viscous => "viscous",
            Effect::Stribeck => "stribeck",
            Effect::Presliding => "presliding",
            Effect::PositionDependent => "position_dependent",
            Effect::DirectionDependent => "direction_dependent",
            Effect::NormalLoad => "normal_load",
            Effect::Offset => "offset",
            Effect::DirectionDependentViscous => "direction_dependent_viscous",
        }
    }

    pub fn from_name(name: &str) -> Result<Effect, String> {
        Effect::ALL
            .into_iter()
            .find(|e| e.name() == name)
            .ok_or_else(|| {
                format!(
                    "unknown effect `{name}` (known: {})",
                    Effect::ALL.map(|e| e.name()).join(", ")
                )
            })
    }

    /// What the effect is, in words, for the report.
    pub fn meaning(self) -> &'static str {
        match self {
            Effect::Viscous => "friction growing with speed (sigma2*v)",
            Effect::Stribeck => "break-away above the sliding level, decaying with speed",
            Effect::Presliding => {
                "elastic micro-displacement and hysteresis before gross sliding (finite sigma0)"
            }
            Effect::PositionDependent => "friction levels varying along the travel",
            Effect::DirectionDependent => "different friction levels for the two directions",
            Effect::NormalLoad => "friction levels proportional to the measured normal force",
            Effect::Offset => "a constant force on the contact, at rest as in motion (F_offset)",
            Effect::DirectionDependentViscous => {
                "different viscous friction for the two directions (sigma2_neg for v < 0)"
            }
        }
    }

    /// Whether the force the data imply can show the effect: presliding's
    /// hysteresis lives in the stick, which the force fits leave out, so
    /// an addition with it is fitted by output error through
    /// co-simulation.
    pub fn force_shows(self) -> bool {
        self != Effect::Presliding
    }

    /// Whether data can show the effect at all, to be tried: a normal
    /// load needs a measured normal force (`normal_force_measured`), a
    /// position dependence some travel.
    pub fn shown_by_data(self, normal_force_measured: bool, context: &Context) -> bool {
        match self {
            Effect::NormalLoad => normal_force_measured,
            Effect::PositionDependent => context.travel > 1e-9,
            _ => true,
        }
    }

    /// What the effect adds to model `m`, as one number whose "no change"
    /// is 0, when it has one: for an interval that holds 0, the data do
    /// not resolve the effect ([`crate::intervals`]). Direction-dependent
    /// levels: Fc_neg − Fc; direction-dependent viscous friction:
    /// sigma2_neg − sigma2; an offset: F_offset; Stribeck: Fs − Fc;
    /// viscous: σ2 − its `nominal` value.
    pub fn change(self, nominal: &FrictionModel, m: &FrictionModel) -> Option<f64> {
        Some(match self {
            Effect::DirectionDependent => m.fc_neg - m.fc,
            Effect::DirectionDependentViscous => m.sigma2_neg - m.sigma2,
            Effect::Offset => m.f_offset,
            Effect::Stribeck => m.fs - m.fc,
            Effect::Viscous => m.sigma2 - nominal.sigma2,
            _ => return None,
        })
    }

    /// The name of [`Effect::change`]'s quantity, for the report.
    pub fn change_name(self) -> Option<&'static str> {
        Some(match self {
            Effect::DirectionDependent => "Fc_neg - Fc",
            Effect::DirectionDependentViscous => "sigma2_neg - sigma2",
            Effect::Offset => "F_offset",
            Effect::Stribeck => "Fs - Fc",
            Effect::Viscous => "sigma2 - nominal sigma2",
            _ => return None,
        })
    }
}

impl fmt::Display for Effect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Without a measured position to judge from, a presliding distance Fc/σ0
/// below this is a stiff (Coulomb-like) law: presliding counts as absent.
pub const STIFF_PRESLIDING_DISTANCE: f64 = 1e-6;

/// Knots of the position table when `position_dependent` is added.
pub const DEFAULT_POSITION_KNOTS: usize = 6;

/// The LuGre parameters that diagnose reads, fits and writes back (SI
/// units; per newton of normal force in the normal-force form).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FrictionModel {
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub stribeck_exponent: f64,
    pub sigma0: f64,
    pub sigma1: f64,
    pub sigma2: f64,
    pub fc_neg: f64,
    pub fs_neg: f64,
    pub direction_dependent: bool,
    pub normal_force_form: bool,
    pub position_dependent: bool,
    /// A constant force on the contact (N, not per newton).
    pub f_offset: f64,
    /// `sigma2_neg` for v < 0.
    pub direction_dependent_viscous: bool,
    pub sigma2_neg: f64,
    /// Table positions (m) and scales (only the first `x_table.len()` are
    /// used; empty when not position-dependent).
    pub x_table: Vec<f64>,
    pub scale_pos: Vec<f64>,
    pub scale_neg: Vec<f64>,
    /// The effects whose parameters are fitted (added or re-sized by the
    /// diagnosis): the levels are always free, an effect's own parameters
    /// only once it is here. Empty for the nominal as given.
    pub freed: BTreeSet<Effect>,
}

/// The largest factor a position table's scale may take the level by,
/// up or down (a level 100 times another along one travel is no
/// position dependence of one contact). Unbounded, a knot that few
/// samples reach was fitted to 6e-8 on one record, a level of nothing
/// there, and the LuGre FMU took its largest number of sub-steps on every
/// step of each co-simulation of it (minutes for a 16 s record).
pub const MAX_SCALE: f64 = 100.0;

/// The LuGre parameter names diagnose reads from the nominal FMU.
pub const READ_PARAMETERS: [&str; 9] = [
    "Fc",
    "Fs",
    "vs",
    "stribeck_exponent",
    "sigma0",
    "sigma1",
    "sigma2",
    "Fc_neg",
    "Fs_neg",
];

impl FrictionModel {
    /// From the values of the nominal friction FMU's parameters: the Reals
    /// of [`READ_PARAMETERS`], the flags and the table.
    pub fn from_values(values: &BTreeMap<String, f64>) -> Result<FrictionModel, String> {
        let get = |name: &str| {
            values
                .get(name)
                .copied()
                .ok_or_else(|| format!("the friction FMU has no parameter `{name}`"))
        };
        let flag = |name: &str| get(name).map(|x| x != 0.0);
        let mut m = FrictionModel {
            fc: get("Fc")?,
            fs: get("Fs")?,
            vs: get("vs")?,
            stribeck_exponent: get("stribeck_exponent")?,
            sigma0: get("sigma0")?,
            sigma1: get("sigma1")?,
            sigma2: get("sigma2")?,
            fc_neg: get("Fc_neg")?,
            fs_neg: get("Fs_neg")?,
            direction_dependent: flag("direction_dependent")?,
            normal_force_form: flag("normal_force_form")?,
            position_dependent: flag("position_dependent")?,
            f_offset: values.get("F_offset").copied().unwrap_or(0.0),
            direction_dependent_viscous: values
                .get("direction_dependent_viscous")
                .is_some_and(|&x| x != 0.0),
            sigma2_neg: values.get("sigma2_neg").copied().unwrap_or(0.0),
            x_table: Vec::new(),
            scale_pos: Vec::new(),
            scale_neg: Vec::new(),
            freed: BTreeSet::new(),
        };
        if m.position_dependent {
            let n = get("n_table")? as usize;
            for i in 1..=n {
                m.x_table.push(get(&format!("x_table[{i}]"))?);
                m.scale_pos.push(get(&format!("scale_pos[{i}]"))?);
                m.scale_neg.push(get(&format!("scale_neg[{i}]"))?);
            }
        }
        if !m.direction_dependent {
            m.fc_neg = m.fc;
            m.fs_neg = m.fs;
        }
        if !m.direction_dependent_viscous {
            m.sigma2_neg = m.sigma2;
        }
        Ok(m)
    }

    /// Whether `effect` is part of the model already.
    pub fn has(&self, effect: Effect) -> bool {
        match effect {
            Effect::Viscous => self.sigma2 > 0.0,
            Effect::Stribeck => self.fs > self.fc * (1.0 + 1e-9),
            Effect::Presliding => self.fc / self.sigma0 >= STIFF_PRESLIDING_DISTANCE,
            Effect::PositionDependent => self.position_dependent,
            Effect::DirectionDependent => self.direction_dependent,
            Effect::NormalLoad => self.normal_force_form,
            Effect::Offset => self.f_offset != 0.0,
            Effect::DirectionDependentViscous => self.direction_dependent_viscous,
        }
    }

    /// The effects of the library the model has.
    pub fn effects(&self) -> Vec<Effect> {
        Effect::ALL.into_iter().filter(|e| self.has(*e)).collect()
    }

    /// Whether the model has `effect` as the data can see it: for
    /// presliding, a presliding distance Fc/σ0 at least the position
    /// resolution of the measurements (finer, and it is a stiff contact
    /// for these data); the others as [`FrictionModel::has`].
    pub fn shows(&self, effect: Effect, context: &Context) -> bool {
        match effect {
            Effect::Presliding => self.presliding_distance() >= context.position_resolution,
            e => self.has(e),
        }
    }

    /// Fc/σ0 (m; per newton cancels in the normal-force form).
    pub fn presliding_distance(&self) -> f64 {
        self.fc / self.sigma0
    }

    /// Whether `effect` can be tried on this model: not yet freed, and for
    /// the structural effects (position, direction, normal load, offset,
    /// direction-dependent viscous friction, the last only where there is
    /// viscous friction to split) not yet part of it; viscous, Stribeck
    /// and presliding are re-sized when the model has them.
    pub fn can_try(&self, effect: Effect) -> bool {
        !self.freed.contains(&effect)
            && match effect {
                Effect::Viscous | Effect::Stribeck | Effect::Presliding => true,
                // a viscous term to split by direction: without one, the
                // candidate would be viscous friction and its asymmetry at
                // once, and win over viscous alone for the viscous part
                Effect::DirectionDependentViscous => self.has(Effect::Viscous) && !self.has(effect),
                e => !self.has(e),
            }
    }

    /// Every level (Fc, Fs, and those of the negative direction) times
    /// `factor`, the Stribeck ratio kept: a start of the levels' refit.
    pub fn scaled_levels(&self, factor: f64) -> FrictionModel {
        let mut m = self.clone();
        for x in [&mut m.fc, &mut m.fs, &mut m.fc_neg, &mut m.fs_neg] {
            *x *= factor;
        }
        m
    }

    /// The model with the levels (Fc, Fs, Fc_neg, Fs_neg, the position
    /// scales when both have the same table) of `other`.
    pub fn with_levels_of(&self, other: &FrictionModel) -> FrictionModel {
        let mut m = self.clone();
        m.fc = other.fc;
        m.fs = other.fs;
        m.fc_neg = other.fc_neg;
        m.fs_neg = other.fs_neg;
        if m.x_table == other.x_table {
            m.scale_pos = other.scale_pos.clone();
            m.scale_neg = other.scale_neg.clone();
        }
        m
    }

    /// σ0 set to `sigma0`, with σ1 scaled by √(σ0 ratio): the damping ratio
    /// of the bristle-mass oscillation held (module doc).
    pub fn with_sigma0(&self, sigma0: f64) -> FrictionModel {
        let mut m = self.clone();
        m.sigma1 = self.sigma1 * (sigma0 / self.sigma0).sqrt();
        m.sigma0 = sigma0;
        m
    }

    /// The model with `effect` switched on at a neutral start (it changes
    /// nothing yet, or very little, until fitted): σ2 small, Fs just above
    /// Fc with vs from `context`, σ0 giving a presliding distance of a
    /// thousandth of the travel, unit scales on knots spread over the
    /// travel, equal levels for both directions, levels per unit of the
    /// mean normal force.
    ///
    /// When the model shows the effect already (viscous, Stribeck,
    /// presliding), it is only freed, at its present values: re-sized.
    pub fn with(&self, effect: Effect, context: &Context) -> FrictionModel {
        let mut m = self.clone();
        m.freed.insert(effect);
        if matches!(
            effect,
            Effect::Viscous | Effect::Stribeck | Effect::Presliding
        ) && self.shows(effect, context)
        {
            return m;
        }
        match effect {
            Effect::Viscous => m.sigma2 = 1e-3 * m.fc / context.speed_scale,
            Effect::Stribeck => {
                m.fs = m.fc * 1.01;
                m.fs_neg = m.fc_neg * 1.01;
                m.vs = 0.1 * context.speed_scale;
            }
            Effect::Presliding => m = m.with_sigma0(m.fc / (1e-3 * context.travel)),
            Effect::PositionDependent => {
                let k = context.position_knots.max(2);
                m.position_dependent = true;
                m.x_table = (0..k)
                    .map(|i| {
                        context.x_min + (context.x_max - context.x_min) * i as f64 / (k - 1) as f64
                    })
                    .collect();
                m.scale_pos = vec![1.0; k];
                m.scale_neg = vec![1.0; k];
            }
            Effect::DirectionDependent => {
                m.direction_dependent = true;
                m.fc_neg = m.fc;
                m.fs_neg = m.fs;
                m.scale_neg = m.scale_pos.clone();
            }
            Effect::NormalLoad => m = m.per_newton(context.mean_normal_force),
            // starts at no offset: the fit finds its sign
            Effect::Offset => m.f_offset = 0.0,
            // (tried only on a model with viscous friction, [`Self::can_try`])
            Effect::DirectionDependentViscous => {
                m.direction_dependent_viscous = true;
                m.sigma2_neg = m.sigma2;
            }
        }
        m
    }

    /// Starting models for adding `effect` to this model: a grid over the
    /// nonlinear parameters (Stribeck velocity and excess, presliding distance).
    pub fn starts(&self, effect: Effect, context: &Context) -> Vec<FrictionModel> {
        let base = self.with(effect, context);
        match effect {
            Effect::Stribeck => {
                // re-sized: from its own values too
                let mut s = if self.has(Effect::Stribeck) {
                    vec![base.clone()]
                } else {
                    Vec::new()
                };
                for vs in [0.03, 0.1, 0.3, 1.0] {
                    for excess in [0.05, 0.2] {
                        let mut m = base.clone();
                        m.vs = vs * context.speed_scale;
                        m.fs = m.fc * (1.0 + excess);
                        m.fs_neg = m.fc_neg * (1.0 + excess);
                        s.push(m);
                    }
                }
                s
            }
            // presliding distances Fc/σ0 from half the position resolution the
            // data show to 3 % of the travel, and the model's own (σ1 following
            // σ0, [`FrictionModel::with_sigma0`])
            Effect::Presliding => {
                let r = context.position_resolution;
                let mut s = vec![base.clone()];
                for d in [0.5 * r, 2.0 * r, 8.0 * r, 32.0 * r, 128.0 * r, 512.0 * r]
                    .into_iter()
                    .chain([1e-2 * context.travel, 3e-2 * context.travel])
                {
                    s.push(base.with_sigma0(base.fc / d));
                }
                s
            }
            Effect::Viscous => {
                let mut s = vec![base.clone()];
                for r in [0.01, 0.1] {
                    let mut m = base.clone();
                    m.sigma2 += r * m.fc / context.speed_scale;
                    s.push(m);
                }
                s
            }
            _ => vec![base],
        }
    }

    /// The model with `effect` taken out again: its parameters as they
    /// were in `before` (the model it was added to), its switch off, and
    /// its parameters no longer fitted; the levels keep what they carried
    /// (a position table's mean scale, the normal force it was per
    /// newton of). `None` when a later effect rests on it (viscous
    /// friction under direction-dependent viscous friction) or it is not
    /// part of the model.
    pub fn without(
        &self,
        effect: Effect,
        before: &FrictionModel,
        context: &Context,
    ) -> Option<FrictionModel> {
        if !self.freed.contains(&effect)
            || (effect == Effect::Viscous && self.direction_dependent_viscous)
        {
            return None;
        }
        let mut m = self.clone();
        m.freed.remove(&effect);
        match effect {
            Effect::Viscous => {
                m.sigma2 = before.sigma2;
                m.sigma2_neg = before.sigma2_neg;
            }
            Effect::Stribeck => {
                m.fs = m.fc * before.fs / before.fc;
                m.fs_neg = m.fc_neg * before.fs_neg / before.fc_neg;
                m.vs = before.vs;
            }
            Effect::Presliding => {
                m.sigma0 = before.sigma0;
                m.sigma1 = before.sigma1;
            }
            Effect::PositionDependent => {
                let mean = |s: &[f64]| s.iter().sum::<f64>() / s.len().max(1) as f64;
                let (pos, neg) = (mean(&m.scale_pos), mean(&m.scale_neg));
                m.fc *= pos;
                m.fs *= pos;
                m.fc_neg *= neg;
                m.fs_neg *= neg;
                m.position_dependent = false;
                m.x_table.clear();
                m.scale_pos.clear();
                m.scale_neg.clear();
            }
            Effect::DirectionDependent => {
                m.direction_dependent = false;
                m.fc_neg = m.fc;
                m.fs_neg = m.fs;
                m.scale_neg = m.scale_pos.clone();
            }
            Effect::NormalLoad => {
                let n = context.mean_normal_force;
                m = m.per_newton(1.0 / n);
                m.normal_force_form = false;
            }
            Effect::Offset => m.f_offset = before.f_offset,
            Effect::DirectionDependentViscous => {
                m.direction_dependent_viscous = false;
                m.sigma2_neg = m.sigma2;
            }
        }
        Some(m)
    }

    /// The normal-force form with the same force at a normal force `n`:
    /// every level and coefficient per newton of the input Fn.
    pub fn per_newton(&self, n: f64) -> FrictionModel {
        let mut m = self.clone();
        m.normal_force_form = true;
        for x in [
            &mut m.fc,
            &mut m.fs,
            &mut m.fc_neg,
            &mut m.fs_neg,
            &mut m.sigma0,
            &mut m.sigma1,
            &mut m.sigma2,
            &mut m.sigma2_neg,
        ] {
            *x /= n;
        }
        m
    }

    /// Whether adding `a` and `b` together brings parameters that neither
    /// brings alone (an interaction: with both position and direction, one
    /// position table per direction). Without one, the pair is the sum of
    /// two single additions, which the singles round has already tried.
    pub fn interact(&self, a: Effect, b: Effect, context: &Context) -> bool {
        let n = |m: &FrictionModel| m.free().len() as isize;
        let n0 = n(self);
        let (na, nb) = (n(&self.with(a, context)), n(&self.with(b, context)));
        let nab = n(&self.with(a, context).with(b, context));
        nab - n0 > (na - n0) + (nb - n0)
    }

    /// The free parameters of this model (the levels and those of every
    /// effect freed, [`FrictionModel::freed`]), as transformed coordinates
    /// θ.
    pub fn free(&self) -> Vec<Free> {
        let mut f = Vec::new();
        // levels: carried by the scales when position-dependent (a common
        // factor of Fc and the scales could not be told apart)
        if self.position_dependent {
            for i in 0..self.x_table.len() {
                f.push(Free::ScalePos(i));
                if self.direction_dependent {
                    f.push(Free::ScaleNeg(i));
                }
            }
        } else {
            f.push(Free::Fc);
            if self.direction_dependent {
                f.push(Free::FcNeg);
            }
        }
        // direction-dependent viscous friction frees both coefficients
        let viscous_asymmetry = self.freed.contains(&Effect::DirectionDependentViscous);
        if self.freed.contains(&Effect::Viscous) || viscous_asymmetry {
            f.push(Free::Sigma2);
        }
        if viscous_asymmetry {
            f.push(Free::Sigma2Neg);
        }
        if self.freed.contains(&Effect::Offset) {
            f.push(Free::Offset);
        }
        if self.freed.contains(&Effect::Stribeck) {
            f.push(Free::StribeckExcess);
            f.push(Free::Vs);
        }
        if self.freed.contains(&Effect::Presliding) {
            f.push(Free::Sigma0);
        }
        f
    }

    /// θ of the free parameters.
    pub fn theta(&self, free: &[Free]) -> Vec<f64> {
        free.iter()
            .map(|p| match p {
                Free::Fc => self.fc.ln(),
                Free::FcNeg => self.fc_neg.ln(),
                Free::Sigma2 => self.sigma2.max(1e-300).ln(),
                Free::Sigma2Neg => self.sigma2_neg.max(1e-300).ln(),
                // linear (either sign), in units of this model's Fc
                Free::Offset => self.f_offset / self.offset_unit(),
                Free::StribeckExcess => (self.fs / self.fc - 1.0).max(1e-12).ln(),
                Free::Vs => self.vs.ln(),
                Free::Sigma0 => self.sigma0.ln(),
                Free::ScalePos(i) => self.scale_pos[*i].ln(),
                Free::ScaleNeg(i) => self.scale_neg[*i].ln(),
            })
            .collect()
    }

    /// The model at θ (the Stribeck excess applies to both directions).
    pub fn at(&self, free: &[Free], theta: &[f64]) -> FrictionModel {
        let mut m = self.clone();
        let excess = (self.fs / self.fc - 1.0).max(0.0);
        let mut new_excess = excess;
        for (p, &t) in free.iter().zip(theta) {
            let x = t.clamp(-700.0, 700.0).exp();
            match p {
                Free::Offset => m.f_offset = t * self.offset_unit(),
                Free::Sigma2Neg => m.sigma2_neg = x,
                Free::Fc => m.fc = x,
                Free::FcNeg => m.fc_neg = x,
                Free::Sigma2 => m.sigma2 = x,
                Free::StribeckExcess => new_excess = x,
                Free::Vs => m.vs = x,
                Free::Sigma0 => {
                    m.sigma1 = self.sigma1 * (x / self.sigma0).sqrt();
                    m.sigma0 = x;
                }
                Free::ScalePos(i) => m.scale_pos[*i] = x.clamp(1.0 / MAX_SCALE, MAX_SCALE),
                Free::ScaleNeg(i) => m.scale_neg[*i] = x.clamp(1.0 / MAX_SCALE, MAX_SCALE),
            }
        }
        if !m.direction_dependent {
            m.fc_neg = m.fc;
        }
        if !m.direction_dependent_viscous {
            m.sigma2_neg = m.sigma2;
        }
        m.fs = m.fc * (1.0 + new_excess);
        m.fs_neg = m.fc_neg * (1.0 + new_excess);
        m
    }

    /// The unit of the offset's fitted coordinate: the Coulomb level in
    /// newtons (at the mean normal force of 1 N in the normal-force form).
    fn offset_unit(&self) -> f64 {
        self.fc.abs().max(1e-12)
    }

    /// `(variable, value)` of the LuGre FMU for this model.
    pub fn parameters(&self) -> Vec<(String, f64)> {
        let mut p = vec![
            ("Fc".to_string(), self.fc),
            ("Fs".to_string(), self.fs),
            ("vs".to_string(), self.vs),
            ("stribeck_exponent".to_string(), self.stribeck_exponent),
            ("sigma0".to_string(), self.sigma0),
            ("sigma1".to_string(), self.sigma1),
            ("sigma2".to_string(), self.sigma2),
            ("Fc_neg".to_string(), self.fc_neg),
            ("Fs_neg".to_string(), self.fs_neg),
            (
                "direction_dependent".to_string(),
                f64::from(u8::from(self.direction_dependent)),
            ),
            (
                "normal_force_form".to_string(),
                f64::from(u8::from(self.normal_force_form)),
            ),
            (
                "position_dependent".to_string(),
                f64::from(u8::from(self.position_dependent)),
            ),
        ];
        p.push(("F_offset".to_string(), self.f_offset));
        p.push((
            "direction_dependent_viscous".to_string(),
            f64::from(u8::from(self.direction_dependent_viscous)),
        ));
        p.push(("sigma2_neg".to_string(), self.sigma2_neg));
        if self.position_dependent {
            p.push(("n_table".to_string(), self.x_table.len() as f64));
            for i in 0..self.x_table.len() {
                p.push((format!("x_table[{}]", i + 1), self.x_table[i]));
                p.push((format!("scale_pos[{}]", i + 1), self.scale_pos[i]));
                p.push((format!("scale_neg[{}]", i + 1), self.scale_neg[i]));
            }
        }
        p
    }

    /// The LuGre FMU variables that carry `effect` in this model (their
    /// values are in [`FrictionModel::parameters`]): what a user sets in
    /// the FMU to reproduce it.
    pub fn effect_variables(&self, effect: Effect) -> Vec<String> {
        let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let with_neg = |pos: &str, neg: &str| {
            if self.direction_dependent {
                names(&[pos, neg])
            } else {
                names(&[pos])
            }
        };
        match effect {
            Effect::Viscous => names(&["sigma2"]),
            Effect::Offset => names(&["F_offset"]),
            Effect::DirectionDependentViscous => {
                names(&["direction_dependent_viscous", "sigma2", "sigma2_neg"])
            }
            Effect::Stribeck => {
                let mut v = with_neg("Fs", "Fs_neg");
                v.extend(names(&["Fc", "vs"]));
                v
            }
            Effect::Presliding => names(&["sigma0", "sigma1"]),
            Effect::DirectionDependent => names(&["Fc", "Fc_neg", "Fs", "Fs_neg"]),
            Effect::NormalLoad => with_neg("Fc", "Fc_neg"),
            Effect::PositionDependent => {
                let mut v = with_neg("Fc", "Fc_neg");
                for i in 1..=self.x_table.len() {
                    v.push(format!("x_table[{i}]"));
                    v.push(format!("scale_pos[{i}]"));
                    if self.direction_dependent {
                        v.push(format!("scale_neg[{i}]"));
                    }
                }
                v
            }
        }
    }

    /// The parameters that describe `effect` in this model, for the report
    /// (name, value, unit).
    pub fn effect_parameters(&self, effect: Effect) -> Vec<(String, f64, &'static str)> {
        let level = if self.normal_force_form { "N/N" } else { "N" };
        match effect {
            Effect::Viscous => vec![("sigma2".into(), self.sigma2, "N.s/m")],
            Effect::Stribeck => vec![
                ("Fs".into(), self.fs, level),
                ("Fs_minus_Fc".into(), self.fs - self.fc, level),
                ("vs".into(), self.vs, "m/s"),
            ],
            Effect::Presliding => vec![
                ("sigma0".into(), self.sigma0, "N/m"),
                ("sigma1".into(), self.sigma1, "N.s/m"),
                ("presliding_distance".into(), self.fc / self.sigma0, "m"),
            ],
            Effect::PositionDependent => {
                let mut v = Vec::new();
                for i in 0..self.x_table.len() {
                    v.push((format!("x_table[{}]", i + 1), self.x_table[i], "m"));
                    v.push((
                        format!("Fc_pos_at[{}]", i + 1),
                        self.fc * self.scale_pos[i],
                        level,
                    ));
                    if self.direction_dependent {
                        v.push((
                            format!("Fc_neg_at[{}]", i + 1),
                            self.fc_neg * self.scale_neg[i],
                            level,
                        ));
                    }
                }
                v
            }
            Effect::DirectionDependent => vec![
                ("Fc".into(), self.fc, level),
                ("Fc_neg".into(), self.fc_neg, level),
                ("Fc_neg_minus_Fc".into(), self.fc_neg - self.fc, level),
            ],
            Effect::NormalLoad => vec![
                ("Fc_per_N".into(), self.fc, "N/N"),
                ("Fc_neg_per_N".into(), self.fc_neg, "N/N"),
            ],
            Effect::Offset => vec![("F_offset".into(), self.f_offset, "N")],
            Effect::DirectionDependentViscous => {
                let unit = if self.normal_force_form {
                    "s/m"
                } else {
                    "N.s/m"
                };
                vec![
                    ("sigma2".into(), self.sigma2, unit),
                    ("sigma2_neg".into(), self.sigma2_neg, unit),
                    (
                        "sigma2_neg_minus_sigma2".into(),
                        self.sigma2_neg - self.sigma2,
                        unit,
                    ),
                ]
            }
        }
    }

    /// The steady sliding force's magnitude at velocity `v`, position `x`
    /// and normal force `fn_`: LuGre's g(v) + σ2(v)·|v| with its levels and
    /// viscous coefficient for that direction and position (docs/models.md,
    /// "LuGre"), the level times `fn_` in the normal-force form, plus the offset
    /// along the direction of motion (the force is sgn(v)·that). What an effect changes in it is the
    /// effect's signature along the states ([`super::localise::attribute`]).
    pub fn sliding_level(&self, v: f64, x: f64, fn_: f64) -> f64 {
        let positive = v >= 0.0;
        let (fc, fs) = if positive || !self.direction_dependent {
            (self.fc, self.fs)
        } else {
            (self.fc_neg, self.fs_neg)
        };
        let ratio = if fc != 0.0 { fs / fc } else { 1.0 };
        let decay = (-(v.abs() / self.vs.max(1e-300)).powf(self.stribeck_exponent)).exp();
        let g = self.level(positive, x) * (1.0 + (ratio - 1.0) * decay);
        let n = if self.normal_force_form { fn_ } else { 1.0 };
        let sigma2 = if positive || !self.direction_dependent_viscous {
            self.sigma2
        } else {
            self.sigma2_neg
        };
        let along = if positive { 1.0 } else { -1.0 };
        g * n + sigma2 * v.abs() + along * self.f_offset
    }

    /// Coulomb level for direction `positive` at position `x` (per unit Fn
    /// in the normal-force form): Fc or Fc_neg times the table's scale.
    pub fn level(&self, positive: bool, x: f64) -> f64 {
        let base = if positive || !self.direction_dependent {
            self.fc
        } else {
            self.fc_neg
        };
        if !self.position_dependent {
            return base;
        }
        let scales = if positive || !self.direction_dependent {
            &self.scale_pos
        } else {
            &self.scale_neg
        };
        base * crate::inputs::interpolate(x, &self.x_table, scales, false)
    }
}

#[cfg(test)]
impl FrictionModel {
    /// For tests: a Coulomb law (Fs = Fc, no viscous term, one level for
    /// both directions) with bristle stiffness `sigma0` and damping
    /// `sigma1`, as [`FrictionModel::from_values`] reads it from an FMU.
    pub fn coulomb_for_tests(fc: f64, sigma0: f64, sigma1: f64) -> FrictionModel {
        FrictionModel::from_values(&BTreeMap::from([
            ("Fc".to_string(), fc),
            ("Fs".to_string(), fc),
            ("vs".to_string(), 0.01),
            ("sigma0".to_string(), sigma0),
            ("sigma1".to_string(), sigma1),
            ("sigma2".to_string(), 0.0),
            ("stribeck_exponent".to_string(), 2.0),
            ("Fc_neg".to_string(), fc),
            ("Fs_neg".to_string(), fc),
            ("direction_dependent".to_string(), 0.0),
            ("normal_force_form".to_string(), 0.0),
            ("position_dependent".to_string(), 0.0),
        ]))
        .expect("every parameter is given")
    }
}

/// A free parameter, fitted as θ = ln(value) (or ln(Fs/Fc − 1)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Free {
    Fc,
    FcNeg,
    Sigma2,
    StribeckExcess,
    Vs,
    Sigma0,
    ScalePos(usize),
    ScaleNeg(usize),
    /// The viscous coefficient for v < 0 (ln).
    Sigma2Neg,
    /// The offset, linear in units of the start's Fc.
    Offset,
}

/// What the neutral starts of the effects depend on: the data's ranges.
#[derive(Clone, Debug)]
pub struct Context {
    /// RMS speed (m/s).
    pub speed_scale: f64,
    pub x_min: f64,
    pub x_max: f64,
    /// max(x_max − x_min, 1e-9).
    pub travel: f64,
    /// Mean normal force (N), 1 when not measured.
    pub mean_normal_force: f64,
    pub position_knots: usize,
    /// The smallest position change the measurements resolve (m): the
    /// encoder's step or the noise, whichever is larger
    /// ([`super::quality::resolution`]); [`STIFF_PRESLIDING_DISTANCE`]
    /// when the position is not measured.
    pub position_resolution: f64,
    /// The smallest displacement one reading registers (m): the encoder's
    /// count, or the resolution when the position is not quantised
    /// ([`super::quality::step`]); [`STIFF_PRESLIDING_DISTANCE`] when the
    /// position is not measured.
    pub position_step: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_position_and_direction_interact() {
        let m = FrictionModel::coulomb_for_tests(5.0, 1e7, 0.0);
        let context = Context {
            speed_scale: 0.1,
            x_min: 0.0,
            x_max: 0.27,
            travel: 0.27,
            mean_normal_force: 1.0,
            position_knots: 6,
            position_resolution: 1e-6,
            position_step: 1e-6,
        };
        let mut interacting = Vec::new();
        for (i, &a) in Effect::ALL.iter().enumerate() {
            for &b in &Effect::ALL[i + 1..] {
                if m.interact(a, b, &context) {
                    interacting.push((a, b));
                }
            }
        }
        assert_eq!(
            interacting,
            [(Effect::PositionDependent, Effect::DirectionDependent)]
        );
    }
}
