//! `fricsim sweep`: one row per grid point (and seed), the same numbers as
//! `fricsim run` for the same parameters, wrong axes refused before
//! anything runs; a sweep's run, which keeps its last rows only, keeps
//! their times only. Nothing here depends on how fast the machine is.

use crate::common;

use fricsim::master::{by_name, communication_time, simulate_with, NoObserver, Run};
use fricsim::ssp::SystemFile;
use std::path::Path;
use std::process::{Command, Output};

fn fricsim(args: &[&str]) -> Output {
    common::lugre_fmu(); // dist/ is built
    Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .args(args)
        .current_dir(common::repository())
        .output()
        .unwrap()
}

/// Header and rows of a CSV file, split at commas.
fn table(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text
        .lines()
        .map(|l| l.split(',').map(str::to_string).collect());
    let header: Vec<String> = lines.next().unwrap();
    (header, lines.collect())
}

fn column(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

#[test]
fn a_grid_gives_one_row_per_point_with_the_numbers_of_fricsim_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep.csv");
    let output = fricsim(&[
        "sweep",
        "examples/stick_slip.ssd",
        "--param",
        "friction.sigma0=1e4,1e5,1e6",
        "--param",
        "rig.k=2,4",
        "--stop",
        "0.5",
        "--threads",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains("6 runs (0 failed)"), "{stdout}");
    assert!(stdout.contains("on 2 threads"), "{stdout}");

    let (header, rows) = table(&out);
    assert_eq!(
        &header[..6],
        &[
            "run",
            "friction.sigma0",
            "rig.k",
            "status",
            "points",
            "wall_s"
        ]
    );
    for signal in ["rig.x", "rig.v", "friction.F"] {
        column(&header, &format!("final:{signal}"));
        column(&header, &format!("rms:{signal}"));
    }
    assert_eq!(rows.len(), 6);
    // the first axis varies slowest
    let grid: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r[1].parse().unwrap(), r[2].parse().unwrap()))
        .collect();
    assert_eq!(
        grid,
        vec![
            (1e4, 2.0),
            (1e4, 4.0),
            (1e5, 2.0),
            (1e5, 4.0),
            (1e6, 2.0),
            (1e6, 4.0)
        ]
    );
    for r in &rows {
        assert_eq!(r[3], "ok");
        assert_eq!(r[4], "5001");
        assert!(r[5].parse::<f64>().unwrap() > 0.0);
        assert_eq!(r.len(), header.len());
    }

    // σ0 = 1e5 N/m, k = 4 N/m as fricsim run computes it
    let run_csv = dir.path().join("run.csv");
    let output = fricsim(&[
        "run",
        "examples/stick_slip.ssd",
        "--stop",
        "0.5",
        "--out",
        run_csv.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(output.status.success());
    let (run_header, run_rows) = table(&run_csv);
    let last = run_rows.last().unwrap();
    let f = column(&header, "final:friction.F");
    // the file's own k is 2: compare the (1e5, 2) row
    let expected = &last[column(&run_header, "friction.F")];
    assert_eq!(&rows[2][f], expected, "sweep and run disagree");
    // and the RMS over all 5001 points, bit for bit, though a sweep's run
    // keeps only its last rows (the others folded into sums as it goes)
    for signal in ["rig.x", "rig.v", "friction.F", "friction.z"] {
        let k = column(&run_header, signal);
        let sum: f64 = run_rows
            .iter()
            .map(|r| r[k].parse::<f64>().unwrap())
            .fold(0.0, |s, y| s + y * y);
        let rms = (sum / run_rows.len() as f64).sqrt();
        let swept: f64 = rows[2][column(&header, &format!("rms:{signal}"))]
            .parse()
            .unwrap();
        assert_eq!(
            swept.to_bits(),
            rms.to_bits(),
            "rms:{signal}: sweep {swept}, run {rms}"
        );
    }
    // the parameters matter: k = 4 pulls harder
    let spring = column(&header, "final:rig.F_spring");
    let (k2, k4): (f64, f64) = (
        rows[2][spring].parse().unwrap(),
        rows[3][spring].parse().unwrap(),
    );
    assert!(k4 > 1.5 * k2, "F_spring {k2} (k = 2) against {k4} (k = 4)");
}

#[test]
fn seeds_run_each_bristle_realisation() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("seeds.csv");
    let output = fricsim(&[
        "sweep",
        "examples/piezo_push.ssd",
        "--seeds",
        "3",
        "--stop",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let (header, rows) = table(&out);
    let seed = column(&header, "friction.seed");
    let seeds: Vec<&str> = rows.iter().map(|r| r[seed].as_str()).collect();
    assert_eq!(seeds, ["1.0", "2.0", "3.0"]);
    // different realisations, different force histories
    let rms = column(&header, "rms:friction.F");
    let values: Vec<&str> = rows.iter().map(|r| r[rms].as_str()).collect();
    assert!(
        values[0] != values[1] && values[1] != values[2],
        "{values:?}"
    );
}

#[test]
fn wrong_axes_are_refused_before_anything_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never.csv");
    let out_arg = out.to_str().unwrap();
    for (args, message) in [
        (
            vec!["--param", "friction.sigma9=1,2"],
            "`friction` has no variable `sigma9`",
        ),
        (vec!["--param", "brake.sigma0=1"], "no component `brake`"),
        (
            vec!["--param", "friction.F=1"],
            "not a parameter or an input",
        ),
        (
            vec!["--param", "friction.sigma0=1,x"],
            "`x` is not a finite number",
        ),
        (vec!["--seeds", "2"], "no component of"),
        (vec!["--threads", "0"], "--threads must be at least 1"),
    ] {
        let mut all = vec![
            "sweep",
            "examples/stick_slip.ssd",
            "--stop",
            "0.1",
            "--out",
            out_arg,
        ];
        all.extend(args);
        let output = fricsim(&all);
        assert!(!output.status.success(), "{all:?}");
        common::assert_message(&String::from_utf8_lossy(&output.stderr), &[message]);
        assert!(!out.exists(), "{all:?} wrote a table");
    }
    // a table named .mat would be CSV text in a file that claims MAT
    let mat = dir.path().join("table.mat");
    let output = fricsim(&[
        "sweep",
        "examples/stick_slip.ssd",
        "--stop",
        "0.1",
        "--param",
        "friction.sigma0=1e5,2e5",
        "--out",
        mat.to_str().unwrap(),
    ]);
    assert!(!output.status.success());
    common::assert_message(
        &String::from_utf8_lossy(&output.stderr),
        &["table.mat", "written as CSV only"],
    );
    assert!(!mat.exists(), "a .mat sweep table was written");
}

/// The macro step of [`stick_slip`], s.
const H: f64 = 1e-4;

/// The stick-slip benchmark from `start` for `steps` macro steps of [`H`]
/// with Jacobi, keeping the last `window` rows (`None`: all).
fn stick_slip(start: f64, steps: usize, window: Option<usize>) -> Run {
    common::lugre_fmu(); // dist/ is built
    let file = SystemFile::open(common::repository().join("examples/stick_slip.ssd")).unwrap();
    let mut system = file.build(start).unwrap();
    system.keep_last_rows(window);
    let stop = start + steps as f64 * H;
    let mut master = by_name("jacobi").unwrap();
    let run = simulate_with(
        &mut system,
        master.as_mut(),
        start,
        H,
        stop,
        &mut NoObserver,
    )
    .unwrap();
    assert!(run.error.is_none(), "{:?}", run.error);
    run
}

fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn a_windowed_run_keeps_the_times_of_its_rows_only() {
    let (start, steps) = (0.25, 517);
    let full = stick_slip(start, steps, None);
    // every communication point, from the start to the stop time
    assert_eq!(full.rows.len(), steps + 1);
    assert_eq!(full.rows.rows_folded(), 0);
    assert_eq!(full.time.len(), steps + 1);
    assert_eq!(full.time[0].to_bits(), start.to_bits());
    assert_eq!(full.time[1].to_bits(), (start + H).to_bits());
    assert_eq!(
        full.time[steps].to_bits(),
        (start + steps as f64 * H).to_bits()
    );
    // the rows are at their times: the actuator point moves at 0.1 m/s
    // from where it is at the start (a row one step off would be 1e-5 m
    // off)
    let x_act = full.columns.iter().position(|c| c == "rig.x_act").unwrap();
    for (t, row) in full.time.iter().zip(&full.rows) {
        assert!(
            (row[x_act] - 0.1 * (t - start)).abs() < 1e-12,
            "x_act {} at t = {t}",
            row[x_act]
        );
    }
    // window 518 holds every row (not windowed); 517 folds once at the end
    for window in [2, 3, 7, 100, 517, 518, 1024] {
        let run = stick_slip(start, steps, Some(window));
        let kept = run.rows.len();
        assert!(kept <= window, "window {window}: {kept} rows");
        assert_eq!(run.rows.rows_pushed(), steps + 1, "window {window}");
        // no more times than rows: those of the rows kept, bit for bit
        // those of the full run at the same communication points
        let first = run.rows.rows_folded();
        assert_eq!(first + kept, steps + 1, "window {window}");
        assert_eq!(run.time.len(), kept, "window {window}");
        assert_eq!(
            bits(&run.time),
            bits(&full.time[first..]),
            "window {window}"
        );
        assert_eq!(
            run.rows.as_flat(),
            &full.rows.as_flat()[first * full.rows.width()..]
        );
        for (i, &t) in run.time.iter().enumerate() {
            assert_eq!(
                t.to_bits(),
                communication_time(start, H, first + i).to_bits()
            );
        }
        // the run ends at the stop time
        assert_eq!(
            run.time.last().unwrap().to_bits(),
            full.time[steps].to_bits(),
            "window {window}"
        );
    }
}
