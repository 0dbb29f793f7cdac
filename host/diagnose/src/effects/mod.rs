//! The candidate effects of the diagnosis, one file each: everything the
//! diagnosis knows of an effect is in its file, as an [`EffectSpec`].
//!
//! | effect | file | LuGre feature | free parameters |
//! | --- | --- | --- | --- |
//! | `viscous` | `viscous.rs` | σ2·v | σ2 |
//! | `stribeck` | `stribeck.rs` | g(v) = Fc + (Fs − Fc)·exp(−(v/vs)²) | Fs/Fc − 1, vs |
//! | `presliding` | `presliding.rs` | finite σ0: ż = v − σ0·|v|·z/g(v), hysteresis over Fc/σ0 | σ0 |
//! | `position_dependent` | `position_dependent.rs` | levels × a piecewise-linear scale of x | the scales at K knots |
//! | `direction_dependent` | `direction_dependent.rs` | Fc_neg, Fs_neg (and scale_neg) for v < 0 | Fc_neg (or the negative scales) |
//! | `normal_load` | `normal_load.rs` | normal-force form: F ∝ the input Fn | (the levels, per newton of Fn) |
//! | `offset` | `offset.rs` | a constant force F_offset on the contact, at rest too | F_offset |
//! | `direction_dependent_viscous` | `direction_dependent_viscous.rs` | sigma2_neg instead of σ2 for v < 0 | σ2, sigma2_neg |
//!
//! **Adding an effect**: a variant of [`Effect`], in [`Effect::ALL`] and
//! [`FIT_ORDER`] (a test fails naming it when it is missing from
//! either), its file here with its [`EffectSpec`], and its arm in
//! [`Effect::spec`] (the compiler names it). Its LuGre parameters go on
//! [`FrictionModel`] (the physics); the
//! hidden-effect generator (`fricsim-hidden-effects`) names it by its
//! exhaustive matches, and `every_effect_has_its_test` asks for its
//! case. The CLI help and `refitted.ssp`'s Booleans read the table.

use crate::model::{Context, Free, FrictionModel};
use serde::Serialize;
use std::fmt;

mod direction_dependent;
mod direction_dependent_viscous;
mod normal_load;
mod offset;
mod position_dependent;
mod presliding;
mod stribeck;
mod viscous;

pub use presliding::{PRESLIDING_RESOLVED, PRESLIDING_SWING};

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

/// The order in which the effects' own coordinates follow the levels'
/// among the fitted parameters ([`FrictionModel::free`]): not the order of
/// [`Effect::ALL`], and the fits depend on it (the same optimum is
/// reached by another path when the coordinates are permuted). A new
/// effect goes at its end.
pub const FIT_ORDER: [Effect; 8] = [
    Effect::Viscous,
    Effect::DirectionDependentViscous,
    Effect::Offset,
    Effect::Stribeck,
    Effect::Presliding,
    Effect::PositionDependent,
    Effect::DirectionDependent,
    Effect::NormalLoad,
];

/// Everything the diagnosis knows of one effect. Each effect implements
/// it in its own file of this module; [`Effect`]'s and
/// [`FrictionModel`]'s methods of the same names dispatch to it.
pub trait EffectSpec: Sync {
    /// Its name on the command line and in the report.
    fn name(&self) -> &'static str;

    /// What the effect is, in words, for the report and the CLI help.
    fn meaning(&self) -> &'static str;

    /// Whether the force the data imply can show the effect (else an
    /// addition with it is fitted by output error through co-simulation).
    fn force_shows(&self) -> bool {
        true
    }

    /// Whether data can show the effect at all, to be tried.
    fn shown_by_data(&self, _normal_force_measured: bool, _context: &Context) -> bool {
        true
    }

    /// What the effect adds to model `m`, as one number whose "no change"
    /// is 0, when it has one ([`Effect::change`]).
    fn change(&self, _nominal: &FrictionModel, _m: &FrictionModel) -> Option<f64> {
        None
    }

    /// The name of [`EffectSpec::change`]'s quantity, for the report.
    fn change_name(&self) -> Option<&'static str> {
        None
    }

    /// The Boolean parameter of the LuGre FMU that switches the effect
    /// on, if any (written as a Boolean into `refitted.ssp`).
    fn switch(&self) -> Option<&'static str> {
        None
    }

    /// Whether the effect is part of model `m` already.
    fn has(&self, m: &FrictionModel) -> bool;

    /// Whether `m` has the effect as the data can see it.
    fn shows(&self, m: &FrictionModel, _context: &Context) -> bool {
        self.has(m)
    }

    /// Whether a model that has the effect can have it re-sized (its
    /// parameters freed from their values) rather than only added to a
    /// model without it.
    fn resized(&self) -> bool {
        false
    }

    /// Whether the effect can be tried on `m`, which has not freed it yet:
    /// by default when `m` lacks it, always when it is re-sized.
    fn can_try(&self, m: &FrictionModel) -> bool {
        self.resized() || !self.has(m)
    }

    /// Switches the effect on in `m` at a neutral start (it changes
    /// nothing yet, or very little, until fitted).
    fn start(&self, m: &mut FrictionModel, context: &Context);

    /// The starting models of a fit that adds the effect to `current`,
    /// `base` being `current` with the effect at its neutral start.
    fn starts(
        &self,
        _current: &FrictionModel,
        base: &FrictionModel,
        _context: &Context,
    ) -> Vec<FrictionModel> {
        vec![base.clone()]
    }

    /// The fitted coordinates the effect adds to the levels' once freed
    /// (shared ones are counted once, in [`FIT_ORDER`]).
    fn frees(&self) -> &'static [Free] {
        &[]
    }

    /// Whether the effect can be taken out of `m` (no later effect rests
    /// on it).
    fn can_take_out(&self, _m: &FrictionModel) -> bool {
        true
    }

    /// Takes the effect out of `m` again: its parameters as they were in
    /// `before` (the model it was added to), its switch off; the levels
    /// keep what they carried.
    fn take_out(&self, m: &mut FrictionModel, before: &FrictionModel, context: &Context);

    /// The LuGre FMU variables that carry the effect in `m`.
    fn variables(&self, m: &FrictionModel) -> Vec<String>;

    /// The parameters that describe the effect in `m`, for the report
    /// (name, value, unit).
    fn parameters(&self, m: &FrictionModel) -> Vec<(String, f64, &'static str)>;

    /// Why the change from `current` to `candidate` that adds or re-sizes
    /// the effect is below what the data resolve, or `None`.
    fn unresolved(
        &self,
        _current: &FrictionModel,
        _candidate: &FrictionModel,
        _context: &Context,
    ) -> Option<String> {
        None
    }
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

    /// What the diagnosis knows of the effect: its file of this module.
    pub fn spec(self) -> &'static dyn EffectSpec {
        match self {
            Effect::Viscous => &viscous::Viscous,
            Effect::Stribeck => &stribeck::Stribeck,
            Effect::Presliding => &presliding::Presliding,
            Effect::PositionDependent => &position_dependent::PositionDependent,
            Effect::DirectionDependent => &direction_dependent::DirectionDependent,
            Effect::NormalLoad => &normal_load::NormalLoad,
            Effect::Offset => &offset::Offset,
            Effect::DirectionDependentViscous => {
                &direction_dependent_viscous::DirectionDependentViscous
            }
        }
    }

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
        self.spec().name()
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
        self.spec().meaning()
    }

    /// Whether the force the data imply can show the effect: presliding's
    /// hysteresis lives in the stick, which the force fits leave out, so
    /// an addition with it is fitted by output error through
    /// co-simulation.
    pub fn force_shows(self) -> bool {
        self.spec().force_shows()
    }

    /// Whether data can show the effect at all, to be tried: a normal
    /// load needs a measured normal force (`normal_force_measured`), a
    /// position dependence some travel.
    pub fn shown_by_data(self, normal_force_measured: bool, context: &Context) -> bool {
        self.spec().shown_by_data(normal_force_measured, context)
    }

    /// What the effect adds to model `m`, as one number whose "no change"
    /// is 0, when it has one: for an interval that holds 0, the data do
    /// not resolve the effect ([`crate::intervals`]). Direction-dependent
    /// levels: Fc_neg − Fc; direction-dependent viscous friction:
    /// sigma2_neg − sigma2; an offset: F_offset; Stribeck: Fs − Fc;
    /// viscous: σ2 − its `nominal` value.
    pub fn change(self, nominal: &FrictionModel, m: &FrictionModel) -> Option<f64> {
        self.spec().change(nominal, m)
    }

    /// The name of [`Effect::change`]'s quantity, for the report.
    pub fn change_name(self) -> Option<&'static str> {
        self.spec().change_name()
    }

    /// The LuGre Boolean parameters that switch effects on
    /// ([`EffectSpec::switch`]).
    pub fn switches() -> impl Iterator<Item = &'static str> {
        Effect::ALL.into_iter().filter_map(|e| e.spec().switch())
    }

    /// The effects with their meanings, one a line (`name: meaning`), for
    /// the command line's help.
    pub fn help_list() -> String {
        Effect::ALL
            .map(|e| format!("{}: {}", e.name(), e.meaning()))
            .join("\n")
    }
}

impl fmt::Display for Effect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Variable names as owned strings.
fn names(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// `pos`, and `neg` too when `m` has direction-dependent levels.
fn with_neg(m: &FrictionModel, pos: &str, neg: &str) -> Vec<String> {
    if m.direction_dependent {
        names(&[pos, neg])
    } else {
        names(&[pos])
    }
}

/// The unit of a friction level in `m`: per newton of normal force in the
/// normal-force form.
fn level_unit(m: &FrictionModel) -> &'static str {
    if m.normal_force_form {
        "N/N"
    } else {
        "N"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_order_holds_every_effect_once() {
        for effect in Effect::ALL {
            let n = FIT_ORDER.iter().filter(|&&e| e == effect).count();
            assert_eq!(n, 1, "{effect} is {n} times in FIT_ORDER");
        }
    }

    #[test]
    fn every_effect_is_in_all_once_by_its_own_name() {
        for (i, a) in Effect::ALL.iter().enumerate() {
            for b in &Effect::ALL[i + 1..] {
                assert_ne!(a, b);
                assert_ne!(a.name(), b.name());
            }
            // serde's name, which report.json holds, is the effect's name
            assert_eq!(
                serde_json::to_string(a).unwrap(),
                format!("\"{}\"", a.name())
            );
        }
    }
}
