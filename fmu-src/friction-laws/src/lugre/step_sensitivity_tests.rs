//! [`LuGre::held_step_sensitivity`] against central differences of the
//! real step map: a copy of the law before the step is stepped with the
//! input moved by ±d and ±2d (held), and its outputs differenced with the
//! fourth-order stencil `(−y(2d) + 8y(d) − 8y(−d) + y(−2d)) / 12d`.

use super::*;

/// A law of parameters `p` in deflection `z`, stepped over `h` with the
/// inputs `(v, x, fn_)` held; its outputs `(z, F)` after the step.
fn stepped(p: &LuGreParams, z: f64, (v, x, fn_): (f64, f64, f64), h: f64) -> (LuGre, f64, f64) {
    let mut law = LuGre::new(*p).unwrap();
    law.set_z(z);
    law.step(
        &LuGreInputs {
            v: Ramp::constant(v),
            x: Ramp::constant(x),
            fn_: Ramp::constant(fn_),
        },
        h,
    );
    let force = law.force(v, x, fn_);
    let z = law.z();
    (law, z, force)
}

/// The inputs with `input` moved by `d`.
fn moved(input: HeldInput, (v, x, fn_): (f64, f64, f64), d: f64) -> (f64, f64, f64) {
    match input {
        HeldInput::V => (v + d, x, fn_),
        HeldInput::X => (v, x + d, fn_),
        HeldInput::Fn => (v, x, fn_ + d),
    }
}

/// `(∂z⁺/∂u, ∂F⁺/∂u)` by the stencil over `d`, and the rounding of the
/// differences: ten times ε/d of each output's scale, which is that of the
/// terms the step adds (`z⁺ = zss + (z − zss)·E` rounds to ε·|zss|, of
/// the order of `level/σ0` however small `z⁺`, and `F` to σ0 times that).
fn differenced(
    p: &LuGreParams,
    z: f64,
    u: (f64, f64, f64),
    h: f64,
    input: HeldInput,
    d: f64,
    level: f64,
) -> ([f64; 2], [f64; 2]) {
    let at = |k: f64| {
        let (_, z, f) = stepped(p, z, moved(input, u, k * d), h);
        [z, f]
    };
    let (a, b, c, e) = (at(2.0), at(1.0), at(-1.0), at(-2.0));
    let diff = |i: usize| (-a[i] + 8.0 * b[i] - 8.0 * c[i] + e[i]) / (12.0 * d);
    let fn_factor = if p.normal_force_form {
        u.2 + 2.0 * d
    } else {
        1.0
    };
    let scale = [level / p.sigma0, level * fn_factor];
    let noise = |i: usize| 10.0 * f64::EPSILON * b[i].abs().max(c[i].abs()).max(scale[i]) / d;
    ([diff(0), diff(1)], [noise(0), noise(1)])
}

/// Checks the closed form against the differences for every deflection
/// before the step in `zs` (fractions of the sliding deflection g/σ0),
/// every velocity in `vs` and step in `hs`, with respect to `input`, at
/// position `x` and normal force `fn_`; `d` from the velocity, Stribeck
/// and step scales. Returns how many cases were compared.
fn check(p: &LuGreParams, input: HeldInput, x: f64, fn_: f64, vs: &[f64], hs: &[f64]) -> usize {
    let mut cases = 0;
    let level = LuGre::new(*p).unwrap().g(1e-12, x, 1.0);
    for &v in vs {
        for &h in hs {
            for frac in [0.0, 0.4, -0.7, 0.99, -0.99] {
                let z = frac * level / p.sigma0;
                let u = (v, x, fn_);
                let (law, ..) = stepped(p, z, u, h);
                let got = law
                    .held_step_sensitivity(input, v, x, fn_, h, 0.0)
                    .unwrap_or_else(|| panic!("{input:?}: no answer at v {v}, h {h}"));
                // the scales the step map bends over: the speed itself, the
                // Stribeck velocity, the speed at which λh changes by one
                let d = 1e-3
                    * match input {
                        HeldInput::V => v.abs().min(p.vs).min(p.fc / (p.sigma0 * h)),
                        HeldInput::X => 1e-2,
                        HeldInput::Fn => fn_,
                    };
                let (want, noise) = differenced(p, z, u, h, input, d, level);
                for (k, (name, got)) in [("z", got.z), ("F", got.force)].into_iter().enumerate() {
                    assert!(
                        (got - want[k]).abs() <= 1e-7 * want[k].abs() + noise[k],
                        "{input:?} d{name}: {got:e} vs differences {:e} (noise {:e}) at v {v}, z {z:e}, h {h}, x {x}, Fn {fn_}",
                        want[k],
                        noise[k]
                    );
                }
                cases += 1;
            }
        }
    }
    cases
}

/// Speeds from deep in the stick (λh ≪ 1) to far above vs, both
/// directions.
const SPEEDS: [f64; 10] = [
    1e-7, -1e-7, 2e-5, -2e-5, 4e-4, -7e-4, 3e-3, -3e-3, 0.2, -0.05,
];
/// Steps from the host's to a coarse one (λh from 1e-5 to beyond 1e3).
const STEPS: [f64; 3] = [1e-5, 1e-4, 1e-2];

fn varied() -> LuGreParams {
    let mut p = LuGreParams {
        direction_dependent: true,
        fc_neg: 0.7,
        fs_neg: 1.9,
        direction_dependent_viscous: true,
        sigma2_neg: 1.3,
        f_offset: -0.25,
        stribeck_exponent: 1.4,
        vd: 2e-3,
        normal_force_form: true,
        position_dependent: true,
        n_table: 4,
        ..LuGreParams::default()
    };
    p.x_table[..4].copy_from_slice(&[0.0, 0.1, 0.3, 0.6]);
    p.scale_pos[..4].copy_from_slice(&[1.0, 2.0, 0.5, 0.8]);
    p.scale_neg[..4].copy_from_slice(&[1.5, 1.0, 1.2, 0.6]);
    p
}

#[test]
fn velocity_sensitivity_matches_differences_of_the_step() {
    let mut cases = 0;
    // the benchmark's parameters (δ = 2, constant σ1, one level)
    let plain = LuGreParams::default();
    cases += check(&plain, HeldInput::V, 0.0, 1.0, &SPEEDS, &STEPS);
    // Sun et al. 2016's brass on steel
    cases += check(
        &LuGreParams::sun_2016(),
        HeldInput::V,
        0.0,
        1.0,
        &SPEEDS,
        &STEPS,
    );
    // every option: direction-dependent levels and viscous friction, an
    // offset, δ = 1.4, σ1(v), Fn = 25,
    // inside a table segment and beyond its ends
    let p = varied();
    for x in [0.05, 0.2, -1.0, 2.0] {
        cases += check(&p, HeldInput::V, x, 25.0, &SPEEDS, &STEPS);
    }
    // δ = 2 with the other options, and δ < 1
    for delta in [2.0, 0.6] {
        let q = LuGreParams {
            stribeck_exponent: delta,
            ..p
        };
        cases += check(&q, HeldInput::V, 0.45, 3.0, &SPEEDS, &STEPS);
    }
    assert_eq!(cases, 8 * SPEEDS.len() * STEPS.len() * 5);
}

#[test]
fn position_and_normal_force_sensitivities_match_differences_of_the_step() {
    let p = varied();
    let mut cases = 0;
    for x in [0.05, 0.2, 0.45, -1.0, 2.0] {
        cases += check(&p, HeldInput::X, x, 25.0, &SPEEDS, &STEPS);
        cases += check(&p, HeldInput::Fn, x, 25.0, &SPEEDS, &STEPS);
    }
    assert_eq!(cases, 10 * SPEEDS.len() * STEPS.len() * 5);
    // without the options the force does not depend on x or Fn
    let plain = LuGreParams::default();
    for input in [HeldInput::X, HeldInput::Fn] {
        let (law, ..) = stepped(&plain, 1e-6, (1e-3, 0.3, 4.0), 1e-4);
        let d = law.held_step_sensitivity(input, 1e-3, 0.3, 4.0, 1e-4, 1e-9);
        assert_eq!(d, Some(StepSensitivity { z: 0.0, force: 0.0 }));
    }
}

/// Where the step map has a kink within the spread, or no step was taken
/// (v = 0), the differences decide: `None`.
#[test]
fn no_answer_at_a_kink_within_the_spread() {
    let p = varied();
    let sens = |input: HeldInput, (v, x, fn_): (f64, f64, f64), spread: f64| {
        let (law, ..) = stepped(&p, 2e-6, (v, x, fn_), 1e-4);
        law.held_step_sensitivity(input, v, x, fn_, 1e-4, spread)
    };
    // |v| at 0
    for v in [0.0, -0.0, 1e-9, -1e-9, 2e-9] {
        assert_eq!(sens(HeldInput::V, (v, 0.2, 1.0), 2e-9), None, "v {v}");
    }
    assert!(sens(HeldInput::V, (3e-9, 0.2, 1.0), 2e-9).is_some());
    assert_eq!(sens(HeldInput::V, (f64::NAN, 0.2, 1.0), 0.0), None);
    // a table point within the spread of x, the end points included
    for x in [0.1, 0.1 + 0.9e-7, 0.1 - 0.9e-7, 0.0, 0.6 + 5e-8] {
        assert_eq!(sens(HeldInput::X, (1e-3, x, 1.0), 1e-7), None, "x {x}");
    }
    assert!(sens(HeldInput::X, (1e-3, 0.1 + 2e-7, 1.0), 1e-7).is_some());
    // at v = 0 nothing moves: ∂/∂x is 0
    let at_rest = sens(HeldInput::X, (0.0, 0.2, 1.0), 1e-7);
    assert_eq!(at_rest, Some(StepSensitivity { z: 0.0, force: 0.0 }));
    // max(Fn, 0) at 0
    for fn_ in [0.0, 1e-7] {
        assert_eq!(sens(HeldInput::Fn, (1e-3, 0.2, fn_), 1e-7), None);
    }
    assert!(sens(HeldInput::Fn, (1e-3, 0.2, 2e-7), 1e-7).is_some());
}

/// The level of the sensitivity is the step's, bit for bit, and its slope
/// is the derivative of the level.
#[test]
fn level_and_slope_are_the_level_and_its_derivative() {
    let p = varied();
    for delta in [2.0, 1.4, 0.6] {
        let law = LuGre::new(LuGreParams {
            stribeck_exponent: delta,
            ..p
        })
        .unwrap();
        for w in [1e-7, 3e-4, 1e-3, 4e-3, 0.1, 1e3] {
            for (dir, x) in [(1.0, 0.2), (-1.0, 0.2), (-1.0, 5.0)] {
                let (g, slope, unscaled) = law.level_and_slope(w, dir, x);
                assert_eq!(g.to_bits(), law.g_unit_computed(w, dir, x).to_bits());
                assert_eq!(g.to_bits(), (law.scale(dir, x) * unscaled).to_bits());
                let d = 1e-4 * w.min(p.vs);
                let fd = (law.g_unit_computed(w + d, dir, x) - law.g_unit_computed(w - d, dir, x))
                    / (2.0 * d);
                let noise = 10.0 * f64::EPSILON * g / d;
                assert!(
                    (slope - fd).abs() <= 1e-6 * fd.abs() + noise,
                    "δ {delta} w {w}: {slope:e} vs {fd:e}"
                );
            }
        }
    }
}
