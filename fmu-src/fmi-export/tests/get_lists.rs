//! [`Instance::get`] of lists of value references, which the layer
//! remembers once checked (a master reads the same list at every step)
//! and compares at the next call: whatever the lists and their order —
//! the same list again, a list of two differing in one entry, a reversed
//! list, a repeated value reference, lists that are runs of consecutive
//! value references and lists that are not — each read gives exactly the
//! values of its own list, and a list that is not valid or holds a
//! non-finite value is refused with the message naming the variable,
//! also right after a valid list was remembered.

use fmi_export::instance::Instance;
use fmi_export::{Model, ModelInfo, Values, VarType, Variable};

#[path = "support/toy_instance.rs"]
mod toy_instance;
use toy_instance::{initialized, toy_info};

const U: u32 = 0;
/// The outputs `y1` … `y6` have value references 1 ..= 6.
const OUTPUTS: usize = 6;
const C: u32 = 7;
const N: u32 = 8;
/// `y_k = SCALE[k] · u + c + s`: with `u` = 1e150, `y4` and `y5`
/// overflow to infinity, the others stay finite.
const SCALE: [f64; OUTPUTS + 1] = [0.0, 1.0, 2.0, 1e100, 1e200, 1e300, 4.0];

/// `ṡ = u`, `y_k = SCALE[k]·u + c + s`, and an integer output `n`.
#[derive(Clone)]
struct Toy {
    info: &'static ModelInfo,
    c: f64,
    s: f64,
}

impl Model for Toy {
    fn info(&self) -> &'static ModelInfo {
        self.info
    }
    fn initialize(&mut self, v: &Values) -> Result<(), String> {
        self.c = v.real(C);
        self.s = 0.0;
        Ok(())
    }
    fn compute_outputs(&self, v: &mut Values) {
        let u = v.real(U);
        for (k, scale) in SCALE.iter().enumerate().skip(1) {
            v.set(k as u32, scale * u + self.c + self.s);
        }
        v.set_integer(N, 7);
    }
    fn do_step(&mut self, v: &Values, _: &[f64], h: f64) -> Result<(), String> {
        self.s += v.real(U) * h;
        Ok(())
    }
    toy_instance::one_value_toy_state!();
}

const NAMES: [&str; OUTPUTS + 1] = ["", "y1", "y2", "y3", "y4", "y5", "y6"];

/// An initialized instance of the toy (`c` = 0.25).
fn instance() -> Instance {
    let mut variables = vec![Variable::input(U, "u", 0.5, "", 1.0, "input")];
    for (k, name) in NAMES.iter().enumerate().skip(1) {
        variables.push(Variable::output(k as u32, name, "", "scaled u", &[U]));
    }
    variables.push(Variable::parameter(C, "c", 0.25, "", "offset"));
    variables.push(Variable::integer_output(N, "n", "a count", &[]));
    let info = toy_info("Lists", variables);
    let model = Box::new(Toy {
        info,
        c: 0.0,
        s: 0.0,
    });
    initialized(info, model)
}

/// What `get` of `vrs` must give after the toy stepped to `s` with input
/// `u`: each value by itself.
fn expected(vrs: &[u32], u: f64, s: f64) -> Vec<f64> {
    vrs.iter()
        .map(|&vr| match vr {
            U => u,
            C => 0.25,
            k => SCALE[k as usize] * u + 0.25 + s,
        })
        .collect()
}

fn get(fmu: &mut Instance, vrs: &[u32]) -> Result<Vec<f64>, String> {
    let mut out = vec![f64::NAN; vrs.len()];
    fmu.get(VarType::Real, vrs, &mut out).map(|()| out)
}

/// Lists of every kind, each read twice in a row (checked, then
/// remembered) and then all again in another order, with the input and
/// the state changed in between: every read gives its own list's values,
/// bit for bit.
#[test]
fn every_list_reads_its_own_values() {
    let lists: Vec<Vec<u32>> = vec![
        vec![1, 2],
        vec![1, 3],
        vec![2, 1],
        vec![1, 1],
        vec![3, 4],
        vec![1, 2, 3, 4, 5, 6],
        vec![1, 2, 3, 5, 6],
        vec![6, 5, 4, 3, 2, 1],
        vec![2, 2, 2, 2, 2],
        vec![1, 2, 3, 1, 2, 3, 4],
        vec![0, 7, 1],
        vec![7, 0],
        vec![6],
        vec![],
    ];
    let mut fmu = instance();
    let (mut u, mut s, h) = (0.5, 0.0, 0.125);
    for round in 0..3 {
        let order: Vec<&Vec<u32>> = match round {
            1 => lists.iter().rev().collect(),
            _ => lists.iter().collect(),
        };
        for vrs in order {
            for _ in 0..2 {
                assert_eq!(get(&mut fmu, vrs).unwrap(), expected(vrs, u, s), "{vrs:?}");
            }
            // a new input (the outputs follow it at the next read) and a
            // step (a new state)
            u += 0.375;
            fmu.set(VarType::Real, &[U], &[u]).unwrap();
            assert_eq!(get(&mut fmu, vrs).unwrap(), expected(vrs, u, s), "{vrs:?}");
            fmu.do_step(fmu.time, h).unwrap();
            s += u * h;
        }
    }
}

/// A list that differs from the remembered one in one entry, its last or
/// its first, is checked as any new list: an unknown value reference or
/// one of another type is refused with its message, and the remembered
/// list still reads right afterwards.
#[test]
fn a_changed_list_is_checked_again() {
    let mut fmu = instance();
    for (good, bad, why) in [
        (vec![1, 2], vec![1, 99], "unknown value reference 99"),
        (vec![1, 2], vec![99, 2], "unknown value reference 99"),
        (
            vec![1, 2],
            vec![1, N],
            "value reference 8 (n) is a Integer variable, not Real",
        ),
        (
            vec![1, 2, 3, 4, 5, 6],
            vec![1, 2, 3, 4, 5, 99],
            "unknown value reference 99",
        ),
        (
            vec![1, 2, 3, 4, 5, 6],
            vec![N, 2, 3, 4, 5, 6],
            "value reference 8 (n) is a Integer variable, not Real",
        ),
    ] {
        assert_eq!(get(&mut fmu, &good).unwrap(), expected(&good, 0.5, 0.0));
        assert_eq!(get(&mut fmu, &good).unwrap(), expected(&good, 0.5, 0.0));
        let e = get(&mut fmu, &bad).unwrap_err();
        assert!(e.contains(why), "{bad:?}: {e}");
        assert_eq!(get(&mut fmu, &good).unwrap(), expected(&good, 0.5, 0.0));
    }
}

/// A non-finite value in a list, remembered or not, is refused naming the
/// first non-finite variable in the list's order.
#[test]
fn a_non_finite_value_names_the_first_in_the_list() {
    let mut fmu = instance();
    for (vrs, name) in [
        (vec![3, 4], "y4"),
        (vec![5, 4], "y5"),
        (vec![1, 2, 3, 4, 5, 6], "y4"),
        (vec![6, 5, 4, 3, 2, 1], "y5"),
        (vec![1, 2, 3, 6, 5], "y5"),
        (vec![4], "y4"),
    ] {
        fmu.set(VarType::Real, &[U], &[0.5]).unwrap();
        // checked and remembered with finite values, then read again
        // with an input that makes some of them overflow
        assert_eq!(get(&mut fmu, &vrs).unwrap(), expected(&vrs, 0.5, 0.0));
        fmu.set(VarType::Real, &[U], &[1e150]).unwrap();
        for _ in 0..2 {
            let e = get(&mut fmu, &vrs).unwrap_err();
            let vr = NAMES.iter().position(|n| *n == name).unwrap();
            assert!(
                e.starts_with(&format!("{name} (value reference {vr}) evaluates to inf")),
                "{vrs:?}: {e}"
            );
        }
        // the finite ones alone still read
        let finite: Vec<u32> = vrs.iter().copied().filter(|&k| k != 4 && k != 5).collect();
        assert_eq!(
            get(&mut fmu, &finite).unwrap(),
            expected(&finite, 1e150, 0.0)
        );
    }
}
