//! Model Exchange of the friction FMUs through the C ABI (the exports the
//! shipped library has): the right-hand side is the one the Co-Simulation
//! step integrates (the same values, bit for bit, at the same state and
//! inputs, and the slope of a tiny exact step), and the directional
//! derivatives of the derivatives and outputs with respect to states and
//! inputs, each entry the law's closed form, agree with central
//! differences of the FMU's own right-hand side and outputs taken through
//! fmi2SetContinuousStates / fmi2SetReal — for every law with a Model
//! Exchange interface and every LuGre option, in stick, slip, both
//! directions, held at a limit and sliding on the 2-D boundary.

mod common;
use common::*;
use fmi_export::ffi::*;

/// A Model Exchange instance of one of the friction FMUs.
struct Me {
    c: fmi2Component,
    info: &'static fmi_export::ModelInfo,
}

impl Me {
    /// Instantiated, `params` set, initialized, through the initial event
    /// iteration, in continuous-time mode.
    fn new(model: &str, params: &[(&str, f64)]) -> Me {
        let (c, info) = instantiate(model, fmi2ModelExchange);
        assert!(!c.is_null(), "{model}: {}", last_error());
        let me = Me { c, info };
        unsafe {
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
            assert_eq!(fmi2EnterInitializationMode(c), OK);
        }
        for (name, value) in params {
            me.set(name, *value);
        }
        unsafe {
            assert_eq!(fmi2ExitInitializationMode(c), OK, "{}", last_error());
        }
        me.event();
        me
    }

    fn vr(&self, name: &str) -> u32 {
        self.info
            .by_name(name)
            .unwrap_or_else(|| panic!("no {name}"))
            .vr
    }

    fn set(&self, name: &str, value: f64) {
        let v = self.info.by_name(name).unwrap();
        let status = unsafe {
            match v.var_type {
                fmi_export::VarType::Real => fmi2SetReal(self.c, &v.vr, 1, &value),
                fmi_export::VarType::Integer => fmi2SetInteger(self.c, &v.vr, 1, &(value as i32)),
                fmi_export::VarType::Boolean => {
                    fmi2SetBoolean(self.c, &v.vr, 1, &((value != 0.0) as i32))
                }
            }
        };
        assert_eq!(status, OK, "{name} = {value}: {}", last_error());
    }

    fn get(&self, name: &str) -> f64 {
        let mut x = f64::NAN;
        let vr = self.vr(name);
        assert_eq!(
            unsafe { fmi2GetReal(self.c, &vr, 1, &mut x) },
            OK,
            "{}",
            last_error()
        );
        x
    }

    fn get_integer(&self, name: &str) -> i32 {
        let mut x = 0;
        let vr = self.vr(name);
        assert_eq!(
            unsafe { fmi2GetInteger(self.c, &vr, 1, &mut x) },
            OK,
            "{}",
            last_error()
        );
        x
    }

    fn get_boolean(&self, name: &str) -> bool {
        let mut x = 0;
        let vr = self.vr(name);
        assert_eq!(
            unsafe { fmi2GetBoolean(self.c, &vr, 1, &mut x) },
            OK,
            "{}",
            last_error()
        );
        x != 0
    }

    fn nx(&self) -> usize {
        self.info.model_exchange.unwrap().states.len()
    }

    fn states(&self) -> Vec<f64> {
        let mut x = vec![f64::NAN; self.nx()];
        assert_eq!(
            unsafe { fmi2GetContinuousStates(self.c, x.as_mut_ptr(), x.len()) },
            OK,
            "{}",
            last_error()
        );
        x
    }

    fn set_states(&self, x: &[f64]) {
        assert_eq!(
            unsafe { fmi2SetContinuousStates(self.c, x.as_ptr(), x.len()) },
            OK,
            "{}",
            last_error()
        );
    }

    fn derivatives(&self) -> Vec<f64> {
        let mut dx = vec![f64::NAN; self.nx()];
        assert_eq!(
            unsafe { fmi2GetDerivatives(self.c, dx.as_mut_ptr(), dx.len()) },
            OK,
            "{}",
            last_error()
        );
        dx
    }

    /// An event here (the event iteration at the current state and
    /// inputs), back in continuous-time mode.
    fn event(&self) {
        unsafe {
            if fmi2EnterEventMode(self.c) != OK {
                // (right after initialization the instance is in event mode)
            }
            let mut info = fmi2EventInfo::default();
            assert_eq!(
                fmi2NewDiscreteStates(self.c, &mut info),
                OK,
                "{}",
                last_error()
            );
            assert_eq!(info.newDiscreteStatesNeeded, 0);
            assert_eq!(fmi2EnterContinuousTimeMode(self.c), OK);
        }
    }

    /// `∂unknown/∂known` from fmi2GetDirectionalDerivative with a unit seed.
    fn partial(&self, unknown: &str, known: &str) -> f64 {
        let (u, k) = (self.vr(unknown), self.vr(known));
        let mut d = f64::NAN;
        assert_eq!(
            unsafe { fmi2GetDirectionalDerivative(self.c, &u, 1, &k, 1, &1.0, &mut d) },
            OK,
            "{unknown}/{known}: {}",
            last_error()
        );
        d
    }

    /// The value of `unknown` (a derivative or an output) with `known` (a
    /// state or an input) moved to `value`, everything else as it was.
    fn value_with(&self, unknown: &str, known: &str, value: f64) -> f64 {
        let me = self.info.model_exchange.unwrap();
        let k = self.vr(known);
        let saved_states = self.states();
        let state_index = me.states.iter().position(|s| s.state == k);
        let saved_input = self.get(known);
        match state_index {
            Some(i) => {
                let mut x = saved_states.clone();
                x[i] = value;
                self.set_states(&x);
            }
            None => self.set(known, value),
        }
        let u = self.vr(unknown);
        let y = match me.states.iter().position(|s| s.derivative == u) {
            Some(i) => self.derivatives()[i],
            None => self.get(unknown),
        };
        match state_index {
            Some(_) => self.set_states(&saved_states),
            None => self.set(known, saved_input),
        }
        y
    }
}

impl Drop for Me {
    fn drop(&mut self) {
        unsafe { fmi2FreeInstance(self.c) };
    }
}

/// Every closed-form entry `∂unknown/∂known` of `me` at its current point
/// against the central difference over `±h·scale(known)`, within `rtol` of
/// the larger of the entry and `floor(unknown)` (the scale of the terms it
/// is made of, against which the differences round).
fn check_partials(
    me: &Me,
    unknowns: &[(&str, f64)],
    knowns: &[(&str, f64)],
    rtol: f64,
    context: &str,
) -> f64 {
    let mut worst: f64 = 0.0;
    for &(known, step) in knowns {
        let at = me.get(known);
        for &(unknown, floor) in unknowns {
            let closed = me.partial(unknown, known);
            let up = me.value_with(unknown, known, at + step);
            let down = me.value_with(unknown, known, at - step);
            let differences = (up - down) / (2.0 * step);
            worst = worst.max((closed - differences).abs() / closed.abs().max(floor));
            assert!(
                (closed - differences).abs() <= rtol * closed.abs().max(floor),
                "{context}: d{unknown}/d{known} = {closed}, differences {differences}"
            );
        }
    }
    worst
}

/// The state is the force of the law `F_dahl`, the output
/// `F = F_dahl + F_offset`: with an offset too.
#[test]
fn dahl_partials_match_differences() {
    for alpha in [1.0, 0.6, 2.5] {
        for offset in [0.0, -0.4] {
            let me = Me::new("Dahl", &[("alpha", alpha), ("F_offset", offset)]);
            for (f, v) in [
                (0.0, 1e-3),
                (0.8, 2e-3),
                (1.5, -1e-3),
                (-1.9, 4e-4),
                (0.6, 0.0),
            ] {
                me.set_states(&[f]);
                me.set("v", v);
                assert_eq!((me.get("F_dahl"), me.get("F")), (f, f + offset));
                let context = format!("Dahl alpha {alpha}, F_offset {offset} at F_dahl {f}, v {v}");
                check_partials(
                    &me,
                    &[
                        ("der(F_dahl)", 87750.0 * 1e-3),
                        ("F", 1.0),
                        ("z", 1e-5),
                        ("P_diss", 1e-3),
                        ("E_stored", 1e-5),
                    ],
                    &[("F_dahl", 1e-7), ("v", 1e-9)],
                    1e-6,
                    &context,
                );
            }
        }
    }
}

/// Dahl's offset in Model Exchange: two instances, with `F_offset = c` and
/// without, integrated alike by an importer's solver (explicit Euler here,
/// through a reversal and a rest), keep the same state bit for bit and
/// the same derivatives, `z` and `sliding`, and their forces differ by `c`
/// exactly: `F = c` relaxed at the start, `F_dahl + c` at rest and in
/// motion.
#[test]
fn dahl_offset_shifts_the_output_in_model_exchange() {
    let c = 3.1648;
    let plain = Me::new("Dahl", &[("alpha", 1.5)]);
    let shifted = Me::new("Dahl", &[("alpha", 1.5), ("F_offset", c)]);
    assert_eq!(shifted.states(), [0.0]);
    assert_eq!((shifted.get("F_dahl"), shifted.get("F")), (0.0, c));
    let h = 1e-5;
    for k in 0..2000 {
        let t = k as f64 * h;
        // forward, back, then at rest from t = 0.015 on
        let v = if t < 0.015 {
            2e-3 * (2.0 * std::f64::consts::PI * t / 0.01).sin()
        } else {
            0.0
        };
        plain.set("v", v);
        shifted.set("v", v);
        let (x, dx) = (shifted.states(), shifted.derivatives());
        assert_eq!(x[0].to_bits(), plain.states()[0].to_bits(), "t {t}");
        assert_eq!(dx[0].to_bits(), plain.derivatives()[0].to_bits(), "t {t}");
        assert_eq!(shifted.get("F"), plain.get("F") + c, "t {t}");
        assert_eq!(shifted.get("F"), x[0] + c, "t {t}");
        assert_eq!(shifted.get("F_dahl"), x[0], "t {t}");
        assert_eq!(shifted.get("z"), plain.get("z"), "t {t}");
        if v == 0.0 {
            assert_eq!(dx[0], 0.0, "at rest the state stays: t {t}");
        }
        plain.set_states(&[x[0] + h * dx[0]]);
        shifted.set_states(&[x[0] + h * dx[0]]);
    }
    // loaded, then at rest: the state plus the offset
    let f_rest = shifted.states()[0];
    assert!(f_rest.abs() > 0.1, "loaded: {f_rest}");
    assert_eq!(shifted.get("F"), f_rest + c);
}

/// LuGre with each option: the benchmark's parameters, direction- and
/// position-dependent levels, the normal-force form with decaying
/// micro-damping, a Stribeck exponent below 1.
#[test]
fn lugre_partials_match_differences_with_every_option() {
    let direction_and_position = [
        LUGRE_TABLE,
        &[
            ("direction_dependent", 1.0),
            ("Fc_neg", 0.7),
            ("Fs_neg", 1.2),
            ("scale_neg[1]", 0.9),
            ("scale_neg[2]", 1.0),
            ("scale_neg[3]", 1.4),
        ],
    ]
    .concat();
    let options: [&[(&str, f64)]; 4] = [
        &[],
        &direction_and_position,
        &[("normal_force_form", 1.0), ("vd", 2e-3)],
        &[("stribeck_exponent", 0.6), ("vd", 5e-3)],
    ];
    for params in options {
        let me = Me::new("LuGre", params);
        for (z, v, x, fn_) in [
            (3e-6, 1e-3, 0.3, 2.0),
            (-1e-5, -4e-3, 0.7, 1.0),
            (1.4e-5, 2e-4, 0.2, 1.0),
            (9e-6, 0.05, 0.6, 0.5),
            (2e-6, 0.0, 0.1, 3.0),
        ] {
            me.set_states(&[z]);
            me.set("v", v);
            me.set("x", x);
            me.set("Fn", fn_);
            let context = format!("LuGre {params:?} at z {z}, v {v}, x {x}, Fn {fn_}");
            let lambda = 1e5 * v.abs() / 0.7;
            check_partials(
                &me,
                &[
                    ("der(z)", (lambda * 1e-5).max(1.0)),
                    ("F", 1e5 * 3.0),
                    ("z", 1.0),
                    ("P_diss", 1e5 * 3.0 * 1e-2),
                    ("E_stored", 1.0),
                ],
                &[("z", 1e-12), ("v", 1e-9), ("x", 1e-6), ("Fn", 1e-6)],
                1e-6,
                &context,
            );
        }
    }
}

/// The reset integrator inside the range, held at each limit (caught there
/// by an event: the limit holding the strain is a discrete state) and
/// released (moving inward, after the event of the reversal).
#[test]
fn reset_integrator_partials_match_differences() {
    let me = Me::new("ResetIntegrator", &[]);
    let z0 = 1e-4;
    let past = 1.0 + 1e-9;
    for (z, v, held) in [
        (3e-5, 1e-3, false),
        (-6e-5, -2e-3, false),
        (z0 * past, 1e-3, true),
        (-z0 * past, -1e-3, true),
    ] {
        me.set_states(&[z]);
        me.set("v", v);
        me.event();
        let context = format!("ResetIntegrator at z {z}, v {v}");
        assert_eq!(me.derivatives() == [0.0], held, "{context}");
        let knowns = [("z", 1e-11), ("v", 1e-9)];
        let unknowns = [
            ("der(z)", 1.0),
            ("F", 1e4),
            ("z", 1.0),
            ("P_diss", 10.0),
            ("E_stored", 1.0),
        ];
        check_partials(&me, &unknowns, &knowns, 1e-6, &context);
        if held {
            // released by the reversal, and moving again
            me.set("v", -v);
            me.event();
            assert_eq!(me.derivatives(), [-v], "{context}");
            check_partials(&me, &unknowns, &knowns, 1e-6, &context);
        }
    }
}

/// Bliman–Sorine: the rates, the force and the energy outputs in both
/// states and `v`, on the loop and off it, at rest (the kink of `|v|`).
#[test]
fn bliman_sorine_partials_match_differences() {
    let me = Me::new("BlimanSorine", &[]);
    for (x1, x2, v) in [
        (0.0, 0.0, 1e-3),
        (12.0, -9.0, 2e-3),
        (-19.0, 17.0, 4e-4),
        (5.0, 3.0, -1e-3),
        (8.0, -6.0, 0.0),
    ] {
        me.set_states(&[x1, x2]);
        me.set("v", v);
        let context = format!("BlimanSorine at ({x1}, {x2}), v {v}");
        check_partials(
            &me,
            &[
                ("der(x1)", 1e2),
                ("der(x2)", 1e2),
                ("F", 1.0),
                ("P_diss", 1e-3),
                ("E_stored", 1e-6),
            ],
            &[("x1", 1e-6), ("x2", 1e-6), ("v", 1e-9)],
            1e-6,
            &context,
        );
    }
}

/// Elasto-plastic: elastic, in the transition, plastic, unloading, at
/// rest; the rate, the force and the energy outputs in `z` and `v`.
#[test]
fn elasto_plastic_partials_match_differences() {
    let me = Me::new("ElastoPlastic", &[]);
    for (z, v) in [
        (4e-6, 1e-3),
        (1.05e-5, 1e-3),
        (-1.1e-5, -4e-4),
        (1.3e-5, 5e-3),
        (9e-6, -2e-3),
        (6e-6, 0.0),
    ] {
        me.set_states(&[z]);
        me.set("v", v);
        let context = format!("ElastoPlastic at z {z}, v {v}");
        check_partials(
            &me,
            &[
                ("der(z)", 1.0),
                ("F", 1e3),
                ("P_diss", 1.0),
                ("E_stored", 1e-5),
            ],
            &[("z", 1e-12), ("v", 1e-10)],
            1e-5,
            &context,
        );
    }
}

/// Maxwell-slip and GMS (also with its micro-damping, whose `Σ σ_i·ż_i`
/// puts `∂Ḟ_i/∂F_i` and `∂Ḟ_i/∂v` into `F` and `P_diss`) with element 1
/// slipping (put at its level and switched by an event) and the others
/// sticking, in both directions.
#[test]
fn element_laws_partials_match_differences() {
    let models: [(&str, Params); 3] = [
        ("MaxwellSlip", &[]),
        ("GMS", &[]),
        ("GMS", &[("sigma1", 40.0)]),
    ];
    for (model, params) in models {
        for v in [2e-4, -1.5e-3] {
            let me = Me::new(model, params);
            me.set("v", v);
            let level = if model == "GMS" {
                // alpha[1]*s(v), s(v) = Fc + (Fs - Fc)*exp(-(v/vs)^2)
                (1.0 + 0.5 * (-(v / 1e-3f64).powi(2)).exp()) / 55.0
            } else {
                me.get("W[1]")
            };
            let mut x = vec![0.0; me.nx()];
            x[0] = v.signum() * level;
            x[1] = 0.3 * me.get("k[2]") * 1e-6;
            x[2] = -0.2 * me.get("k[3]") * 1e-6;
            me.set_states(&x);
            me.event();
            assert_eq!(me.get_integer("n_slipping"), 1, "{model}");
            // off the level, so that the attraction acts (GMS)
            x[0] *= 0.97;
            me.set_states(&x);
            let context = format!("{model} {params:?} at v {v}");
            let worst = check_partials(
                &me,
                &[
                    ("der(F_element[1])", 1.0),
                    ("der(F_element[2])", 1.0),
                    ("F", 1.0),
                    ("P_diss", 1e-4),
                    ("E_stored", 1e-8),
                ],
                &[("F_element[1]", 1e-6), ("F_element[2]", 1e-6), ("v", 1e-9)],
                1e-6,
                &context,
            );
            println!("{context}: worst relative difference {worst:.1e}");
        }
    }
}

/// The 2-D bristle inside the disc and sliding on its boundary (reached by
/// an event: the contact state is a discrete state), isotropic and not.
#[test]
fn bristle2d_partials_match_differences_inside_and_sliding() {
    for params in [
        &[][..],
        &[("sigma02", 5572.08), ("sigma11", 209.2), ("a2", 0.2)][..],
    ] {
        let me = Me::new("Bristle2D", params);
        let z0 = 1e-4;
        for (z, v, boundary) in [
            ([3e-5, -2e-5], [2e-3, 1e-3], false),
            ([0.6 * z0, 0.8 * z0], [2e-3, 1e-3], true),
            ([-0.28 * z0, 0.96 * z0], [-4e-3, 5e-3], true),
        ] {
            me.set("v1", v[0]);
            me.set("v2", v[1]);
            me.set_states(&z);
            me.event();
            // on the circle moving outward: sliding, the contact switched
            let sliding = {
                let vr = me.vr("sliding");
                let mut b = 0;
                assert_eq!(unsafe { fmi2GetBoolean(me.c, &vr, 1, &mut b) }, OK);
                b != 0
            };
            assert_eq!(sliding, boundary, "{params:?} z {z:?} v {v:?}");
            let context = format!("Bristle2D {params:?} at z {z:?}, v {v:?}");
            check_partials(
                &me,
                &[
                    ("der(z1)", 100.0),
                    ("der(z2)", 100.0),
                    ("F1", 1e4),
                    ("F2", 1e4),
                    ("z1", 1.0),
                    ("z2", 1.0),
                    ("P_diss", 10.0),
                    ("E_stored", 1.0),
                ],
                &[("z1", 1e-12), ("z2", 1e-12), ("v1", 1e-9), ("v2", 1e-9)],
                1e-6,
                &context,
            );
            // back inside for the next point
            me.set_states(&[0.0, 0.0]);
            me.event();
        }
    }
}

/// Parameters set by name.
type Params = &'static [(&'static str, f64)];

/// A model, its inputs, its states and the outputs compared.
type Case = (
    &'static str,
    &'static [(&'static str, f64)],
    &'static [&'static str],
    &'static [&'static str],
);

/// The Model Exchange right-hand side is the law the Co-Simulation step
/// integrates: a Co-Simulation instance driven somewhere, then a Model
/// Exchange instance put in the same state with the same inputs give the
/// same derivatives (the `der(…)` variables of the former, bit for bit)
/// and outputs, and a tiny exact Co-Simulation step moves the state by
/// the derivative.
#[test]
fn the_right_hand_side_is_the_one_the_step_integrates() {
    let cases: [Case; 6] = [
        (
            "ElastoPlastic",
            &[("v", 1e-3)],
            &["z"],
            &["F", "z", "P_diss"],
        ),
        ("Dahl", &[("v", 3e-4)], &["F_dahl"], &["F", "z"]),
        (
            "BlimanSorine",
            &[("v", -4e-4)],
            &["x1", "x2"],
            &["F", "P_diss", "E_stored"],
        ),
        ("LuGre", &[("v", 2e-3)], &["z"], &["F", "z"]),
        (
            "ResetIntegrator",
            &[("v", 1e-3)],
            &["z"],
            &["F", "z", "P_diss", "E_stored"],
        ),
        (
            "Bristle2D",
            &[("v1", 1e-3), ("v2", -5e-4)],
            &["z1", "z2"],
            &["F1", "F2", "z1", "z2", "P_diss", "E_stored"],
        ),
    ];
    for (model, inputs, states, outputs) in cases {
        let mut cs = Fmu::new(model, &[]);
        for (name, value) in inputs {
            cs.set(name, *value);
        }
        // partway: inside the stiction range for the reset integrators
        cs.step(2e-2);
        let me = Me::new(model, &[]);
        for (name, value) in inputs {
            me.set(name, *value);
        }
        let x: Vec<f64> = states.iter().map(|s| cs.get(s)).collect();
        me.set_states(&x);
        let dx = me.derivatives();
        for (k, s) in states.iter().enumerate() {
            let der = cs.get(&format!("der({s})"));
            assert_eq!(dx[k].to_bits(), der.to_bits(), "{model}: der({s})");
            assert!(dx[k] != 0.0, "{model}: der({s}) is 0, nothing tested");
        }
        for o in outputs {
            assert_eq!(me.get(o).to_bits(), cs.get(o).to_bits(), "{model}: {o}");
        }
        let h = 1e-9;
        cs.step(h);
        for (k, s) in states.iter().enumerate() {
            let slope = (cs.get(s) - x[k]) / h;
            assert!(
                (slope - dx[k]).abs() <= 1e-5 * dx[k].abs(),
                "{model}: {s} moved at {slope}, der {}",
                dx[k]
            );
        }
    }
}

/// The same for the element laws, whose modes are discrete states: a
/// Co-Simulation instance driven until some elements slip and others
/// stick, then a Model Exchange instance given its element forces and one
/// event iteration (which sets the modes from the forces) has the same
/// `der(F_element[i])` for all 100 states, bit for bit, and the same
/// outputs; a tiny step moves each force by its derivative. Then the
/// reversal: an event at `v < 0` sticks every element.
#[test]
fn element_laws_right_hand_side_is_the_one_the_step_integrates() {
    let cases: [(&str, Params, f64); 3] = [
        ("MaxwellSlip", &[], 2e-4),
        ("GMS", &[], -3e-4),
        ("GMS", &[("sigma1", 40.0)], -3e-4),
    ];
    for (model, params, v) in cases {
        let mut cs = Fmu::new(model, params);
        cs.set("v", v);
        cs.step(6e-2);
        let slipping = cs.get_any("n_slipping");
        assert!(
            slipping > 0.0 && slipping < 10.0,
            "{model}: {slipping} slip"
        );
        let me = Me::new(model, params);
        me.set("v", v);
        let names: Vec<String> = (1..=100).map(|i| format!("F_element[{i}]")).collect();
        let x: Vec<f64> = names.iter().map(|s| cs.get(s)).collect();
        me.set_states(&x);
        me.event();
        assert_eq!(me.states(), x, "{model}: the event moved a force");
        let dx = me.derivatives();
        for (k, s) in names.iter().enumerate() {
            let der = cs.get(&format!("der({s})"));
            assert_eq!(dx[k].to_bits(), der.to_bits(), "{model}: der({s})");
        }
        assert!(dx[..10].iter().any(|d| *d != 0.0), "{model}: nothing moves");
        for o in ["F", "P_diss", "E_stored"] {
            assert_eq!(me.get(o).to_bits(), cs.get(o).to_bits(), "{model}: {o}");
        }
        assert_eq!(me.get_integer("n_slipping") as f64, slipping, "{model}");
        let h = 1e-9;
        cs.step(h);
        for (k, s) in names.iter().enumerate().take(10) {
            let slope = (cs.get(s) - x[k]) / h;
            assert!(
                (slope - dx[k]).abs() <= 1e-5 * dx[k].abs().max(1e-3),
                "{model}: {s} moved at {slope}, der {}",
                dx[k]
            );
        }
        // the reversal sticks every element: each loads at k[i]*v
        me.set("v", -v);
        me.event();
        assert_eq!(me.get_integer("n_slipping"), 0, "{model}");
        let dx = me.derivatives();
        for (k, d) in dx.iter().enumerate().take(10) {
            assert_eq!(
                *d,
                cs.get(&format!("k[{}]", k + 1)) * -v,
                "{model}: element {}",
                k + 1
            );
        }
    }
}

/// At an event the reset integrator puts an overshoot of the limit back
/// on it (and says the states changed), and its two event indicators
/// change sign where the strain reaches a limit and where a reversal
/// releases it.
#[test]
fn reset_integrator_events() {
    let me = Me::new("ResetIntegrator", &[]);
    let z0 = 1e-4;
    let indicators = |me: &Me| {
        let mut z = [f64::NAN; 2];
        assert_eq!(
            unsafe { fmi2GetEventIndicators(me.c, z.as_mut_ptr(), 2) },
            OK
        );
        z
    };
    me.set("v", 1e-3);
    me.set_states(&[0.9 * z0]);
    assert!(indicators(&me)[0] > 0.0);
    assert_eq!(me.derivatives(), [1e-3]);
    // an integrator's step past the limit
    me.set_states(&[z0 * (1.0 + 1e-6)]);
    assert!(indicators(&me)[0] < 0.0);
    unsafe {
        assert_eq!(fmi2EnterEventMode(me.c), OK);
        let mut info = fmi2EventInfo::default();
        assert_eq!(fmi2NewDiscreteStates(me.c, &mut info), OK);
        assert_eq!(info.valuesOfContinuousStatesChanged, fmi2True);
        assert_eq!(fmi2EnterContinuousTimeMode(me.c), OK);
    }
    assert_eq!(me.states(), [z0]);
    assert_eq!(me.derivatives(), [0.0]);
    assert_eq!(me.get("F"), 1e4 * z0);
    assert!(indicators(&me)[0] < 0.0);
    // held, a last bit below the limit (as an integrator may leave it):
    // still held, the force still the sliding level
    me.set_states(&[z0 * (1.0 - 1e-16)]);
    assert_eq!(me.derivatives(), [0.0]);
    assert!(indicators(&me)[0] < 0.0);
    assert!((me.get("F") - 1e4 * z0).abs() <= 1e-15);
    // the reversal releases it: the indicator changes sign with v, and the
    // event lets it go from the limit
    me.set("v", -1e-3);
    assert!(indicators(&me)[0] > 0.0);
    me.event();
    assert_eq!(me.states(), [z0]);
    assert_eq!(me.derivatives(), [-1e-3]);
    assert_eq!(indicators(&me)[0], 0.0);
    // the lower limit: below it moving down
    me.set_states(&[-z0 * (1.0 + 1e-6)]);
    assert!(indicators(&me)[1] < 0.0);
    me.event();
    assert_eq!(me.states(), [-z0]);
    // released by the reversal; inside the range nothing to put back
    me.set("v", 1e-3);
    me.event();
    assert_eq!(me.derivatives(), [1e-3]);
    me.set_states(&[0.5 * z0]);
    unsafe {
        assert_eq!(fmi2EnterEventMode(me.c), OK);
        let mut info = fmi2EventInfo::default();
        assert_eq!(fmi2NewDiscreteStates(me.c, &mut info), OK);
        assert_eq!(info.valuesOfContinuousStatesChanged, fmi2False);
        assert_eq!(fmi2EnterContinuousTimeMode(me.c), OK);
    }
    // the nominal is z0
    let mut nominal = [0.0];
    assert_eq!(
        unsafe { fmi2GetNominalsOfContinuousStates(me.c, nominal.as_mut_ptr(), 1) },
        OK
    );
    assert_eq!(nominal, [z0]);
}

/// Classical in Model Exchange has no continuous states and four event
/// indicators, `v − dv`, `v + dv`, `Fs − F_app` and `Fs + F_app`, which
/// change sign exactly where its force changes branch: stuck (F = F_app),
/// breaking away (F = ±Fs) and sliding (the Stribeck curve). At each
/// point the force equals the law's, the event iteration changes nothing,
/// and the partials match central differences away from the switches.
#[test]
fn classical_indicators_mark_its_switches() {
    let me = Me::new("Classical", &[]);
    assert_eq!(me.nx(), 0);
    assert!(me.derivatives().is_empty() && me.states().is_empty());
    let (fs, dv) = (me.get("Fs"), me.get("dv"));
    let law = friction_laws::classical::Classical::new(Default::default()).unwrap();
    let indicators = |me: &Me| {
        let mut z = [f64::NAN; 4];
        assert_eq!(
            unsafe { fmi2GetEventIndicators(me.c, z.as_mut_ptr(), 4) },
            OK,
            "{}",
            last_error()
        );
        z
    };
    // (v, F_app, the branch): every sign pattern of the indicators
    for (v, f_app, stuck) in [
        (0.0, 1.0, true),
        (0.5 * dv, -2.0, true),
        (-0.9 * dv, 3.0, false),
        (0.2 * dv, -3.0, false),
        (2.0 * dv, 0.5, false),
        (-5e-3, -1.0, false),
    ] {
        me.set("v", v);
        me.set("F_app", f_app);
        me.event();
        let z = indicators(&me);
        assert_eq!(z, [v - dv, v + dv, fs - f_app, fs + f_app]);
        let in_band = z[0] < 0.0 && z[1] > 0.0;
        let holds = z[2] >= 0.0 && z[3] >= 0.0;
        assert_eq!(in_band && holds, stuck, "v {v}, F_app {f_app}");
        assert_eq!(me.get_boolean("stuck"), stuck, "v {v}, F_app {f_app}");
        assert_eq!(me.get("F"), law.force(v, f_app), "v {v}, F_app {f_app}");
        let context = format!("Classical at v {v}, F_app {f_app}");
        check_partials(
            &me,
            &[("F", 1.0), ("P_diss", 1e-3)],
            &[("v", 1e-9), ("F_app", 1e-6)],
            1e-5,
            &context,
        );
    }
    // Between events the branch of the last one holds, so the force an
    // importer's solver sees is continuous: stuck just inside the band,
    // then moved just outside it, the force is still F_app and only the
    // indicator says the edge was crossed; the event switches to the curve.
    me.set("F_app", 1.0);
    me.set("v", dv * (1.0 - 1e-9));
    me.event();
    let inside = (me.get("F"), indicators(&me)[0]);
    me.set("v", dv * (1.0 + 1e-9));
    let crossed = (me.get("F"), indicators(&me)[0]);
    me.event();
    let outside = me.get("F");
    assert!(inside.1 < 0.0 && crossed.1 > 0.0);
    assert_eq!((inside.0, crossed.0), (1.0, 1.0));
    assert!((outside - law.steady_state(dv)).abs() < 1e-9);
    // and an event exactly on the edge takes the switch (the solver stops
    // there): stuck, then v = dv exactly at an event, is sliding
    me.set("v", 0.0);
    me.event();
    me.set("v", dv);
    me.event();
    assert!(!me.get_boolean("stuck"));
    assert_eq!(me.get("F"), law.steady_state(dv));
}

/// The bristle law with random reconnection has no Model Exchange
/// interface: instantiating it for Model Exchange is refused, naming it.
#[test]
fn the_bristle_law_is_co_simulation_only() {
    let (c, info) = instantiate("Bristle", fmi2ModelExchange);
    assert!(info.model_exchange.is_none());
    assert!(c.is_null());
    let m = last_error();
    assert!(
        m.contains("Bristle") && m.contains("Co-Simulation (1) only"),
        "{m}"
    );
}
