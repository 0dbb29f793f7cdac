//! GMS and Maxwell-slip at their largest size, 100 elements, through the C
//! ABI: each of the ten default elements split into ten identical ones
//! (stiffness and slip level or weight divided by ten) is the same contact,
//! so the force, the stored energy and the dissipated power equal the
//! ten-element run's, and ten times as many elements slip. A wrong index,
//! a table cut short or an element skipped at the array's end would show.

mod common;
use common::Fmu;
use std::f64::consts::PI;

/// The law's default elements (`k[i]` and the named second array), each
/// split into `copies` identical ones.
fn split_elements(law: &'static str, second: &str, copies: usize) -> Vec<(String, f64)> {
    let fmu = Fmu::new(law, &[]);
    let n = fmu.get_any("n_elements") as usize;
    let mut params = vec![("n_elements".to_string(), (n * copies) as f64)];
    for i in 1..=n {
        let (k, w) = (
            fmu.get(&format!("k[{i}]")),
            fmu.get(&format!("{second}[{i}]")),
        );
        for c in 0..copies {
            let j = (i - 1) * copies + c + 1;
            params.push((format!("k[{j}]"), k / copies as f64));
            params.push((format!("{second}[{j}]"), w / copies as f64));
        }
    }
    params
}

/// Force, stored energy, dissipated power and slipping count at each step
/// of `v = 2e-3·sin(2πt)` over two cycles (the elements load, slip and
/// reverse), 20 000 steps per cycle.
fn run(law: &'static str, params: &[(String, f64)]) -> Vec<[f64; 4]> {
    let params: Vec<(&str, f64)> = params.iter().map(|(n, v)| (n.as_str(), *v)).collect();
    let mut fmu = Fmu::new(law, &params);
    let h = 1.0 / 20_000.0;
    (0..40_000)
        .map(|k| {
            let t = (k as f64 + 0.5) * h;
            fmu.set("v", 2e-3 * (2.0 * PI * t).sin());
            fmu.step(h);
            [
                fmu.get("F"),
                fmu.get("E_stored"),
                fmu.get("P_diss"),
                fmu.get_any("n_slipping"),
            ]
        })
        .collect()
}

fn hundred_elements_are_the_ten_split(law: &'static str, second: &str) {
    let ten = run(law, &split_elements(law, second, 1));
    let hundred_params = split_elements(law, second, 10);
    assert_eq!(hundred_params[0], ("n_elements".to_string(), 100.0));
    let hundred = run(law, &hundred_params);
    let level = ten.iter().map(|r| r[0].abs()).fold(0.0, f64::max);
    let most_energy = ten.iter().map(|r| r[1]).fold(0.0, f64::max);
    let most_power = ten.iter().map(|r| r[2].abs()).fold(0.0, f64::max);
    let mut all_slipped = false;
    for (k, (a, b)) in ten.iter().zip(&hundred).enumerate() {
        assert!(
            (a[0] - b[0]).abs() <= 1e-9 * level,
            "{law} step {k}: F {} against {}",
            b[0],
            a[0]
        );
        assert!(
            (a[1] - b[1]).abs() <= 1e-9 * most_energy,
            "{law} step {k}: E_stored"
        );
        assert!(
            (a[2] - b[2]).abs() <= 1e-9 * most_power,
            "{law} step {k}: P_diss"
        );
        assert_eq!(b[3], 10.0 * a[3], "{law} step {k}: slipping elements");
        all_slipped |= a[3] == 10.0;
    }
    // the run reached gross sliding: every element slipped at some point
    assert!(all_slipped, "{law}: never all elements slipping");
}

#[test]
fn gms_with_a_hundred_elements_is_the_ten_split() {
    hundred_elements_are_the_ten_split("GMS", "alpha");
}

#[test]
fn maxwell_slip_with_a_hundred_elements_is_the_ten_split() {
    hundred_elements_are_the_ten_split("MaxwellSlip", "W");
}

/// GMS from rest at a constant velocity, one step of `h`: element i
/// sticks (`F_i = k_i·v·t`) until it reaches its share of the Stribeck
/// curve at `t_i = α_i·s(v)/(k_i·v)`, where it stays (its attraction
/// `C·(α_i − F_i/s(v))` is 0 there). The FMU locates each switch inside the
/// step: after one step the force is the closed form whichever elements
/// switched in it, not `k_i·v·h` for each (a switch taken at the step's
/// end would give that).
#[test]
fn gms_switches_inside_one_step_where_the_closed_form_puts_them() {
    let probe = Fmu::new("GMS", &[]);
    let n = probe.get_any("n_elements") as usize;
    let (fc, fs, vs, delta, sigma2) = (
        probe.get("Fc"),
        probe.get("Fs"),
        probe.get("vs"),
        probe.get("stribeck_exponent"),
        probe.get("sigma2"),
    );
    let k: Vec<f64> = (1..=n).map(|i| probe.get(&format!("k[{i}]"))).collect();
    let alpha: Vec<f64> = (1..=n).map(|i| probe.get(&format!("alpha[{i}]"))).collect();
    for v in [1e-4, -3e-4, 2e-3] {
        let s = fc + (fs - fc) * (-(v / vs).abs().powf(delta)).exp();
        let switch: Vec<f64> = (0..n).map(|i| alpha[i] * s / (k[i] * v.abs())).collect();
        let last = switch.iter().cloned().fold(0.0, f64::max);
        let first = switch.iter().cloned().fold(f64::INFINITY, f64::min);
        // a step before any switch, one with some switched, one past all
        for h in [0.5 * first, 0.5 * (first + last), 2.0 * last] {
            let mut fmu = Fmu::new("GMS", &[]);
            fmu.set("v", v);
            fmu.step(h);
            let expected: f64 = (0..n)
                .map(|i| v.signum() * (k[i] * v.abs() * h).min(alpha[i] * s))
                .sum::<f64>()
                + sigma2 * v;
            let slipping = switch.iter().filter(|&&t| t <= h).count();
            assert!(
                (fmu.get("F") - expected).abs() <= 1e-9 * fs,
                "v = {v}, h = {h:.3e}: F = {} against {expected}",
                fmu.get("F")
            );
            assert_eq!(
                fmu.get_any("n_slipping") as usize,
                slipping,
                "v = {v}, h = {h:.3e}"
            );
        }
    }
}
