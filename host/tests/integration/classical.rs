//! Rig1D.fmu + Classical.fmu through the rig's applied force (docs/models.md,
//! "Classical" and "Rig1D"): `rig.v → friction.v`, `rig.F_app →
//! friction.F_app`, `friction.F → rig.F`, run from
//! `examples/classical_stick_slip.ssd` (Gauss–Seidel, the rig first, at
//! 1e-4 s).
//!
//! The rig: m = 1 kg, k = 4 N/m, c = 0.02 N·s/m to ground, the spring's end
//! pulled from x_a = 0 at v_a = 0.4 m/s, the body at rest at x = 0. The
//! contact: Coulomb + viscous friction, vs = 0 (no Stribeck term), Fc = 0.1 N,
//! Fs = 0.99 N, σ2 = 0.05 N·s/m, band dv = 1e-3 m/s.
//!
//! Closed forms, computed here independently of both FMUs:
//!
//! - stuck, the contact holds the spring force k·v_a·t until it reaches Fs:
//!   break-away at t* = Fs/(k·v_a) = 0.61875 s (mid-step on the 1e-4 s grid);
//! - then the damped linear oscillator m·ẍ + C·ẋ + k·x = k·v_a·t − F0, in two
//!   pieces: inside the band the contact holds Fs (F0 = Fs, C = c) until
//!   ẋ = dv, then it slides (F0 = Fc, C = c + σ2) until ẋ falls back to dv,
//!   where it sticks again (|F_app| < Fs there);
//! - the creep of the stuck body under the hold of F over a macro step
//!   ([`creep`]), which the co-simulation has and the continuous system not.
//!
//! Figures observed (h = 1e-4 s, Gauss–Seidel): first row not stuck 0.5
//! step after t*; the body crept 1.53e-5 m while stuck (the closed form
//! 1.53e-5 m); the slip within 7.7e-4 m/s of the closed form from rest
//! (the creep velocity, 5e-5 m/s, moves the exit from the band by 9 steps:
//! inside it the acceleration starts from zero), within 2.6e-5 m/s and
//! 1.2e-5 m of it started from the creep, within 3.3e-6 m/s and 1.4e-6 m
//! of the sliding piece started from the co-simulation's exit from the band;
//! peak velocity 0.9893 m/s against 0.9898; sticks again 0.24 step from the
//! closed form's 2.97038 s. The Jacobi master passes Classical's force on a
//! step late (it is read before Classical sees the rig's new outputs): break-away
//! 2.5 steps after t*, three times the creep. Newton (the rig's directional
//! derivatives of F_app, checked against differences) breaks away 0.5 step
//! after t* and creeps backwards; it finds no solution of the step where the
//! body sticks again (Classical's force jumps there), so it is run to 2.9 s.

use crate::paper_examples::{bound, column, example, run_with, settings};
use fricsim::master::gauss_seidel::GaussSeidel;
use fricsim::master::Run;
use fricsim::ssp::SystemFile;

const M: f64 = 1.0;
const K: f64 = 4.0;
const C: f64 = 0.02;
const V_A: f64 = 0.4;
const FC: f64 = 0.1;
const FS: f64 = 0.99;
const SIGMA2: f64 = 0.05;
const DV: f64 = 1e-3;
const H: f64 = 1e-4;

/// The example, its parameters those of the closed forms here.
fn file() -> SystemFile {
    let file = example("classical_stick_slip.ssd");
    for (port, value) in [
        ("rig.m", M),
        ("rig.k", K),
        ("rig.c", C),
        ("rig.v_a", V_A),
        ("friction.Fc", FC),
        ("friction.Fs", FS),
        ("friction.vs", 0.0),
        ("friction.sigma2", SIGMA2),
        ("friction.dv", DV),
    ] {
        assert_eq!(bound(&file, port), value, "{port}");
    }
    assert_eq!(settings(&file), (H, "gauss-seidel".to_string(), 10.0));
    file
}

/// The run of the example with `master` to `stop`, Classical's Boolean
/// `stuck` recorded too (as 0 or 1, as `fricsim run` records it).
fn run(master: &str, stop: f64) -> Run {
    let mut file = file();
    file.settings.record.push("friction.stuck".to_string());
    run_with(&file, master, H, stop)
}

/// m·ẍ + damping·ẋ + k·x = k·v_a·t − level from (t0, x0, ẋ0), underdamped:
/// x = x_p(t) + e^{−σs}·(A·cos ω_d s + B·sin ω_d s), s = t − t0, with the
/// particular solution x_p = v_a·t − (level + damping·v_a)/k.
#[derive(Clone, Copy, Debug)]
struct Piece {
    t0: f64,
    a: f64,
    b: f64,
    sigma: f64,
    omega: f64,
    level: f64,
    damping: f64,
}

impl Piece {
    fn new(level: f64, damping: f64, (t0, x0, v0): (f64, f64, f64)) -> Piece {
        let sigma = damping / (2.0 * M);
        let omega = (K / M - sigma * sigma).sqrt();
        let (y0, dy0) = (x0 - Self::particular(level, damping, t0), v0 - V_A);
        Piece {
            t0,
            a: y0,
            b: (dy0 + sigma * y0) / omega,
            sigma,
            omega,
            level,
            damping,
        }
    }

    fn particular(level: f64, damping: f64, t: f64) -> f64 {
        V_A * t - (level + damping * V_A) / K
    }

    /// (x, ẋ, ẍ) at t.
    fn at(&self, t: f64) -> (f64, f64, f64) {
        let s = t - self.t0;
        let (e, (sin, cos)) = ((-self.sigma * s).exp(), (self.omega * s).sin_cos());
        let x = Self::particular(self.level, self.damping, t) + e * (self.a * cos + self.b * sin);
        let v = V_A
            + e * ((self.b * self.omega - self.sigma * self.a) * cos
                - (self.a * self.omega + self.sigma * self.b) * sin);
        let acc = (K * V_A * t - self.level - self.damping * v - K * x) / M;
        (x, v, acc)
    }

    /// The first t in (from, from + span] where g(t) crosses 0 upward
    /// (`rising`) or downward, scanned at 1e-5 s and bisected to 1e-14 s.
    fn first_crossing(&self, g: impl Fn(f64) -> f64, from: f64, span: f64, rising: bool) -> f64 {
        let sign = if rising { 1.0 } else { -1.0 };
        let g = |t: f64| sign * g(t);
        let n = (span / 1e-5).ceil() as usize;
        let mut lo = from;
        for i in 1..=n {
            let hi = from + i as f64 * 1e-5;
            if g(lo) < 0.0 && g(hi) >= 0.0 {
                let (mut a, mut b) = (lo, hi);
                while b - a > 1e-14 {
                    let c = 0.5 * (a + b);
                    if g(c) < 0.0 {
                        a = c;
                    } else {
                        b = c;
                    }
                }
                return b;
            }
            lo = hi;
        }
        panic!("no crossing in ({from}, {})", from + span);
    }
}

/// The closed-form stick-slip cycle from break-away at t* in state
/// `(x, ẋ)`: the band piece (the contact holds Fs) until ẋ = dv at
/// `band_end`, the sliding piece until ẋ falls to dv again at `restick`,
/// its peak velocity at `peak`.
struct Cycle {
    t_star: f64,
    band: Piece,
    band_end: f64,
    slide: Piece,
    peak: f64,
    restick: f64,
}

impl Cycle {
    fn from(start: (f64, f64)) -> Cycle {
        let t_star = FS / (K * V_A);
        let band = Piece::new(FS, C, (t_star, start.0, start.1));
        let band_end = band.first_crossing(|t| band.at(t).1 - DV, t_star, 1.0, true);
        let (x1, v1, _) = band.at(band_end);
        let slide = Piece::new(FC, C + SIGMA2, (band_end, x1, v1));
        let peak = slide.first_crossing(|t| slide.at(t).2, band_end + 1e-3, 5.0, false);
        let restick = slide.first_crossing(|t| slide.at(t).1 - DV, peak, 5.0, false);
        Cycle {
            t_star,
            band,
            band_end,
            slide,
            peak,
            restick,
        }
    }

    /// (x, ẋ) at t during the slip.
    fn at(&self, t: f64) -> (f64, f64) {
        let piece = if t < self.band_end {
            &self.band
        } else {
            &self.slide
        };
        let (x, v, _) = piece.at(t);
        (x, v)
    }
}

/// The body's creep while stuck, (x, ẋ) at t, under a hold of F over each
/// macro step h that is F_app at the step's start (Gauss–Seidel with the
/// rig first): the spring force grows by k·v_a·τ over the step, unheld, so
/// the body gains k·v_a·h²/2m of velocity per step: ẋ = k·v_a·h·t/2m,
/// x = k·v_a·h·t²/4m.
fn creep(t: f64) -> (f64, f64) {
    (K * V_A * H * t * t / (4.0 * M), K * V_A * H * t / (2.0 * M))
}

/// The largest |co-simulation − closed form| of x and of ẋ over the rows
/// `rows`.
fn worst(
    rows: std::ops::Range<usize>,
    (t, x, v): (&[f64], &[f64], &[f64]),
    exact: impl Fn(f64) -> (f64, f64),
) -> (f64, f64) {
    rows.fold((0.0f64, 0.0f64), |(dx, dv), i| {
        let (xc, vc) = exact(t[i]);
        (dx.max((x[i] - xc).abs()), dv.max((v[i] - vc).abs()))
    })
}

#[test]
fn classical_on_rig1d_sticks_until_the_spring_reaches_fs_then_slips_as_the_closed_form() {
    let at_rest = Cycle::from((0.0, 0.0));
    let t_star = at_rest.t_star;
    assert!((t_star - 0.61875).abs() < 1e-15);
    let run = run("gauss-seidel", 3.2);
    let t = &run.time[..];
    let (x, v, f_app) = (
        column(&run, "rig.x"),
        column(&run, "rig.v"),
        column(&run, "rig.F_app"),
    );
    let (force, stuck) = (column(&run, "friction.F"), column(&run, "friction.stuck"));

    // F_app is the spring and damper force on the body, every row
    for i in 0..t.len() {
        let want = K * (V_A * t[i] - x[i]) - C * v[i];
        assert!(
            (f_app[i] - want).abs() <= 1e-12,
            "t = {}: F_app {} vs {want}",
            t[i],
            f_app[i]
        );
    }

    // stuck until the spring force reaches Fs, the contact holding
    // F = F_app, the body creeping as the closed form says
    let broke = stuck
        .iter()
        .position(|&s| s == 0.0)
        .expect("the body breaks away");
    let t_break = t[broke];
    assert!(
        t_break > t_star && t_break <= t_star + H,
        "break-away at {t_break} s, closed form {t_star} s (step {H})"
    );
    for i in 0..broke {
        assert_eq!(force[i], f_app[i], "t = {}: stuck, F = F_app", t[i]);
        let (xc, vc) = creep(t[i]);
        assert!(v[i].abs() < DV, "t = {}: v = {}", t[i], v[i]);
        assert!(
            (x[i] - xc).abs() <= 0.02 * xc + 1e-12 && (v[i] - vc).abs() <= 0.02 * vc + 1e-12,
            "t = {}: x = {:e}, ẋ = {:e}, creep {xc:e}, {vc:e}",
            t[i],
            x[i],
            v[i]
        );
    }
    assert!(x[broke - 1] < 2e-5, "crept {:e} m", x[broke - 1]);
    // broken away: the contact holds Fs at most
    assert_eq!(force[broke], FS);
    assert!(f_app[broke] > FS);

    // the slip, to its end where the body sticks again
    let restuck = broke
        + stuck[broke..]
            .iter()
            .position(|&s| s == 1.0)
            .expect("the body sticks again");
    let cols = (t, &x[..], &v[..]);
    // against the closed form from rest at t*: the creep velocity at
    // break-away (5e-5 m/s) leaves the band earlier, where the
    // acceleration starts from zero (by 9 steps): the force drops to Fc
    // earlier by as much
    let (dx, dv) = worst(broke..restuck, cols, |t| at_rest.at(t));
    eprintln!("from rest: {dx:e} m, {dv:e} m/s");
    assert!(
        dv <= 1.5e-3 && dx <= 1e-3,
        "from rest: {dx:e} m, {dv:e} m/s"
    );
    // started from the creep at t*: the co-simulation to its step error
    let crept = Cycle::from(creep(t_star));
    let (dx, dv) = worst(broke..restuck, cols, |t| crept.at(t));
    eprintln!("from the creep: {dx:e} m, {dv:e} m/s");
    assert!(
        dv <= 5e-5 && dx <= 2.5e-5,
        "from the creep: {dx:e} m, {dv:e} m/s"
    );
    // the sliding piece from the co-simulation's exit from the band
    let exit = broke + v[broke..].iter().position(|&v| v >= DV).unwrap();
    let slide = Piece::new(FC, C + SIGMA2, (t[exit], x[exit], v[exit]));
    let (dx, dv) = worst(exit..restuck, cols, |t| {
        let (x, v, _) = slide.at(t);
        (x, v)
    });
    eprintln!("from the exit: {dx:e} m, {dv:e} m/s");
    assert!(
        dv <= 1e-5 && dx <= 5e-6,
        "from the exit: {dx:e} m, {dv:e} m/s"
    );
    // the peak velocity and where it sticks again, against the closed form
    // from rest
    let v_peak = v[broke..restuck].iter().fold(0.0f64, |a, &b| a.max(b));
    let (_, v_peak_rest, _) = at_rest.slide.at(at_rest.peak);
    assert!(
        (v_peak - v_peak_rest).abs() <= 1e-3 * v_peak_rest && v_peak_rest > 0.98,
        "peak velocity {v_peak} vs {v_peak_rest}"
    );
    let t_restick = t[restuck];
    eprintln!(
        "break-away {} steps after t*, crept {:e} m; peak {v_peak} vs {v_peak_rest}; \
         sticks again at {t_restick} s vs {} s",
        (t_break - t_star) / H,
        x[broke - 1],
        at_rest.restick
    );
    assert!(
        (t_restick - at_rest.restick).abs() <= 2.0 * H,
        "sticks again at {t_restick} s, closed form {} s",
        at_rest.restick
    );
    // and holds there: F_app within Fs, F = F_app, the body keeping the
    // velocity it entered the band with (|v| < dv: Karnopp's contact holds
    // the velocity constant, not zero), to the end of the run
    assert_eq!(force[restuck], f_app[restuck]);
    assert!(f_app[restuck].abs() < FS);
    let last = t.len() - 1;
    assert!(stuck[restuck..].iter().all(|&s| s == 1.0));
    assert!(v[restuck..].iter().all(|v| v.abs() < DV));
    let drift = (x[last] - x[restuck]).abs();
    assert!(
        drift <= DV * (t[last] - t_restick) + creep(t[last] - t_restick).0,
        "{drift:e} m after sticking again"
    );
}

/// The other masters on the same system. Jacobi reads Classical's force
/// before Classical has seen the rig's outputs of the same point, so the
/// rig is pushed with the force of a step before: three times the creep,
/// break-away between 1.5 and 3.5 steps after t*. Newton holds the forces
/// of the step's end (its Jacobian from the rig's directional derivatives
/// of F_app, checked against differences): the body creeps backwards as
/// much as it creeps forwards under Gauss–Seidel, and breaks away within
/// the step after t*; run to 2.9 s, before the body sticks again, where
/// the iteration finds no solution (Classical's force jumps there).
#[test]
fn jacobi_lags_a_step_and_newton_breaks_away_within_one() {
    let t_star = FS / (K * V_A);
    for (master, after) in [("jacobi", 1.5..=3.5), ("newton", 0.0..=1.0)] {
        let run = run(master, 2.9);
        let (t, x, stuck) = (
            &run.time,
            column(&run, "rig.x"),
            column(&run, "friction.stuck"),
        );
        let broke = stuck.iter().position(|&s| s == 0.0).unwrap();
        let steps = (t[broke] - t_star) / H;
        eprintln!(
            "{master}: {steps} steps after t*, crept {:e} m",
            x[broke - 1]
        );
        assert!(after.contains(&steps), "{master}: {steps} steps after t*");
        let (xc, _) = creep(t[broke - 1]);
        let factor = if master == "jacobi" { 3.0 } else { -1.0 };
        assert!(
            (x[broke - 1] - factor * xc).abs() <= 0.05 * xc,
            "{master}: crept {:e} m, closed form {:e}",
            x[broke - 1],
            factor * xc
        );
    }
}

/// F_app has no direct feedthrough from the rig's F (it would make an
/// algebraic loop with Classical's F, which feeds through F_app): the
/// model structure says so, and Gauss–Seidel steps the rig first.
#[test]
fn the_applied_force_does_not_feed_through_the_friction_force() {
    let system = file().build(0.0).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(GaussSeidel::order(&system), vec![0, 1]);
}
