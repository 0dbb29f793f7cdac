//! `fricsim reference` and `fricsim compare` on system files: the
//! reference has the columns and times of `fricsim run`, the co-simulation
//! error it measures is small but not zero, and systems without a
//! monolithic model are refused by component. The systems are written into
//! temporary directories and point at the repository's dist/*.fmu.

use crate::common;
use common::{lugre_fmu, repository};
use fricsim::compare::{compare, ResultFile};
use std::path::Path;
use std::process::Command;

/// Run fricsim; (exit status, stdout, stderr).
fn fricsim(args: &[&str]) -> (Option<i32>, String, String) {
    let output = Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .args(args)
        .output()
        .unwrap();
    (
        output.status.code(),
        String::from_utf8(output.stdout).unwrap(),
        String::from_utf8(output.stderr).unwrap(),
    )
}

fn ok(args: &[&str]) -> String {
    let (code, out, err) = fricsim(args);
    assert_eq!(code, Some(0), "{args:?}:\n{out}\n{err}");
    out
}

fn refused(args: &[&str], parts: &[&str]) {
    let (code, _, err) = fricsim(args);
    assert_eq!(code, Some(1), "{args:?}: {err}");
    assert!(
        err.starts_with("fricsim: ") && !err.contains("panicked"),
        "{err}"
    );
    for p in parts {
        assert!(err.contains(p), "`{p}` not in: {err}");
    }
}

fn dist(name: &str) -> String {
    let _ = lugre_fmu(); // builds dist/ when missing
    repository().join("dist").join(name).display().to_string()
}

/// A component: name, FMU, connectors (name, kind), Real parameters.
struct Part<'a> {
    name: &'a str,
    fmu: &'a str,
    connectors: &'a [(&'a str, &'a str)],
    parameters: &'a [(&'a str, f64)],
}

/// An ssd with `parts`, `connections` (from component, connector, to
/// component, connector), a stop time and a step size.
fn ssd(parts: &[Part], connections: &[(&str, &str, &str, &str)], stop: f64, step: f64) -> String {
    let mut s = String::from(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="test"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssd:System name="test">
    <ssd:Elements>
"#,
    );
    for p in parts {
        s += &format!(
            "      <ssd:Component name=\"{}\" source=\"{}\">\n        <ssd:Connectors>\n",
            p.name,
            dist(p.fmu)
        );
        for (c, kind) in p.connectors {
            s += &format!("          <ssd:Connector name=\"{c}\" kind=\"{kind}\"/>\n");
        }
        s += "        </ssd:Connectors>\n";
        if !p.parameters.is_empty() {
            s += "        <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>\n";
            s += "          <ssv:ParameterSet version=\"1.0\" name=\"p\"><ssv:Parameters>\n";
            for (n, v) in p.parameters {
                s += &format!(
                    "            <ssv:Parameter name=\"{n}\"><ssv:Real value=\"{v:?}\"/></ssv:Parameter>\n"
                );
            }
            s += "          </ssv:Parameters></ssv:ParameterSet>\n";
            s += "        </ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>\n";
        }
        s += "      </ssd:Component>\n";
    }
    s += "    </ssd:Elements>\n    <ssd:Connections>\n";
    for (a, b, c, d) in connections {
        s += &format!(
            "      <ssd:Connection startElement=\"{a}\" startConnector=\"{b}\" endElement=\"{c}\" endConnector=\"{d}\"/>\n"
        );
    }
    s += &format!(
        r#"    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="{stop:?}">
    <ssd:Annotations>
      <ssc:Annotation type="org.friction-fmu.fricsim">
        <fricsim:Simulation xmlns:fricsim="urn:friction-fmu:fricsim:1" stepSize="{step:?}" master="jacobi"/>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"#
    );
    s
}

/// Rig1D + `law` coupled by slip velocity and force.
fn rig_with(law: &str, rig_parameters: &[(&str, f64)], stop: f64, step: f64) -> String {
    ssd(
        &[
            Part {
                name: "rig",
                fmu: "Rig1D.fmu",
                connectors: &[("F", "input"), ("v", "output")],
                parameters: rig_parameters,
            },
            Part {
                name: "friction",
                fmu: law,
                connectors: &[("v", "input"), ("F", "output")],
                parameters: &[],
            },
        ],
        &[("rig", "v", "friction", "v"), ("friction", "F", "rig", "F")],
        stop,
        step,
    )
}

fn p(dir: &Path, name: &str) -> String {
    dir.join(name).display().to_string()
}

#[test]
fn the_reference_of_the_stick_slip_example_has_the_columns_and_times_of_run() {
    let dir = tempfile::tempdir().unwrap();
    let example = repository()
        .join("examples/stick_slip.ssd")
        .display()
        .to_string();
    let (run, reference) = (p(dir.path(), "run.csv"), p(dir.path(), "ref.csv"));
    ok(&["run", &example, "--stop", "10", "--out", &run, "-q"]);
    let out = ok(&["reference", &example, "--stop", "10", "--out", &reference]);
    assert!(
        out.contains("Rig1D `rig` (m = 1) + LuGre `friction`"),
        "{out}"
    );
    assert!(out.contains("100001 rows"), "{out}");
    let (r, f) = (
        ResultFile::read(Path::new(&run)).unwrap(),
        ResultFile::read(Path::new(&reference)).unwrap(),
    );
    // the run's columns are the reference's, then the friction law's
    // Boolean output `sliding`, which the monolithic reference has not
    assert_eq!(r.columns[..f.columns.len()], f.columns[..]);
    assert_eq!(r.columns[f.columns.len()..], ["friction.sliding"]);
    assert_eq!(r.time, f.time, "same times, bit for bit");
    // The reference slips first at 7.540 s (docs/models.md, "Reference figures").
    let v = &f.values[f.columns.iter().position(|c| c == "rig.v").unwrap()];
    let i = v.iter().position(|&v| v > 0.05).unwrap();
    assert!((f.time[i] - 7.540).abs() <= 5e-4, "{}", f.time[i]);
    // The Jacobi co-simulation at 1e-4 s is close to it, but not equal.
    let c = compare(&r, &f, &[]).unwrap();
    assert!(!c.interpolated);
    let err = |name: &str| c.signals.iter().find(|s| s.name == name).unwrap();
    for name in ["rig.x", "rig.v", "friction.F"] {
        let e = err(name).relative_rms.unwrap();
        assert!(e > 1e-7 && e < 1e-2, "{name}: relative RMS error {e:e}");
    }
    // The CLI prints the same numbers.
    let shown = ok(&["compare", &run, &reference]);
    assert!(shown.contains("same time grid, 100001 points"), "{shown}");
    let line = shown
        .lines()
        .find(|l| l.trim_start().starts_with("rig.x "))
        .unwrap();
    assert!(
        line.contains(&format!("{:.4e}", err("rig.x").relative_rms.unwrap())),
        "{line}"
    );
    // `--out ref.mat` is a MAT v4 file (not CSV text under that name) with
    // the same columns, times and values, to the last bit
    let mat = p(dir.path(), "ref.mat");
    ok(&["reference", &example, "--stop", "10", "--out", &mat]);
    assert!(
        !std::fs::read(&mat).unwrap().starts_with(b"time"),
        "CSV text"
    );
    let m = ResultFile::read(Path::new(&mat)).unwrap();
    assert_eq!(m.columns, f.columns);
    assert_eq!(m.time, f.time);
    assert_eq!(m.values, f.values);
    // Chosen signals only; a coarser result is compared by interpolation.
    let shown = ok(&["compare", &run, &reference, "--signal", "friction.F"]);
    assert!(
        shown.contains("friction.F") && !shown.contains("rig.x "),
        "{shown}"
    );
    let coarse = p(dir.path(), "coarse.csv");
    ok(&[
        "run", &example, "--stop", "10", "--step", "1e-3", "--out", &coarse, "-q",
    ]);
    let shown = ok(&["compare", &coarse, &reference]);
    assert!(
        shown.contains("interpolated linearly onto the result's 10001 times"),
        "{shown}"
    );
}

#[test]
fn dahl_and_the_quasi_static_bristle_have_references_too() {
    let dir = tempfile::tempdir().unwrap();
    // The 1995 rig on Dahl friction (Sun et al. 2016 parameters): the mass rests
    // on the Dahl stiffness σ = 87 750 N/m (ω ≈ 296 rad/s), a loop the
    // Jacobi co-simulation damps poorly. Against the reference its error
    // falls with the macro step (observed relative RMS error of F: 1.4 at
    // 1e-3 s, 0.13 at 1e-4 s, 2e-3 at 1e-5 s).
    let rig = [("m", 1.0), ("k", 2.0), ("v_a", 0.1)];
    std::fs::write(
        dir.path().join("dahl.ssd"),
        rig_with("Dahl.fmu", &rig, 2.0, 1e-3),
    )
    .unwrap();
    let system = p(dir.path(), "dahl.ssd");
    let mut errors = Vec::new();
    for step in ["1e-3", "1e-4"] {
        let (run, reference) = (p(dir.path(), "run.csv"), p(dir.path(), "ref.csv"));
        ok(&["run", &system, "--step", step, "--out", &run, "-q"]);
        let out = ok(&[
            "reference",
            &system,
            "--step",
            step,
            "--out",
            &reference,
            "--check",
        ]);
        assert!(
            out.contains("Dahl `friction`") && out.contains("estimated error"),
            "{out}"
        );
        let c = compare(
            &ResultFile::read(Path::new(&run)).unwrap(),
            &ResultFile::read(Path::new(&reference)).unwrap(),
            &["friction.F".into()],
        )
        .unwrap();
        errors.push(c.signals[0].relative_rms.unwrap());
    }
    assert!(
        errors[0] > 3.0 * errors[1] && errors[1] > 1e-6,
        "{errors:?}"
    );

    // Appels and Herder: the piezo pushes the block through a spring, quasi-statically.
    let piezo = ssd(
        &[
            Part {
                name: "rig",
                fmu: "Rig1D.fmu",
                connectors: &[("F", "input"), ("x_rel", "output")],
                parameters: &[("m", 0.0), ("c", 0.0), ("k", 116.04e3), ("v_a", 8.25e-8)],
            },
            Part {
                name: "bristle",
                fmu: "Bristle.fmu",
                connectors: &[("x", "input"), ("F", "output")],
                parameters: &[],
            },
        ],
        &[
            ("rig", "x_rel", "bristle", "x"),
            ("bristle", "F", "rig", "F"),
        ],
        30.0,
        0.01,
    );
    std::fs::write(dir.path().join("piezo.ssd"), piezo).unwrap();
    let system = p(dir.path(), "piezo.ssd");
    let reference = p(dir.path(), "piezo_ref.csv");
    let out = ok(&["reference", &system, "--out", &reference]);
    assert!(
        out.contains("quasi-static") && out.contains("3001 rows"),
        "{out}"
    );
    let f = ResultFile::read(Path::new(&reference)).unwrap();
    let force = &f.values[f.columns.iter().position(|c| c == "bristle.F").unwrap()];
    // Slides at μc·m·g by the end.
    assert!((force[force.len() - 1] - 0.0633 * 0.352 * 9.81).abs() < 1e-12);
}

#[test]
fn the_planar_oscillator_with_the_2d_bristle_has_a_reference() {
    // Wijata et al.'s oscillator (Rig2D's defaults) on the 2-D bristle law,
    // coupled per axis. The co-simulation error against the reference
    // falls about tenfold per tenfold smaller step (observed relative RMS
    // error of F1: 1.8e-2 at 1e-3 s, 1.6e-3 at 1e-4 s).
    let dir = tempfile::tempdir().unwrap();
    let system = ssd(
        &[
            Part {
                name: "rig",
                fmu: "Rig2D.fmu",
                connectors: &[
                    ("F1", "input"),
                    ("F2", "input"),
                    ("v1", "output"),
                    ("v2", "output"),
                ],
                parameters: &[],
            },
            Part {
                name: "friction",
                fmu: "Bristle2D.fmu",
                connectors: &[
                    ("v1", "input"),
                    ("v2", "input"),
                    ("F1", "output"),
                    ("F2", "output"),
                ],
                parameters: &[],
            },
        ],
        &[
            ("rig", "v1", "friction", "v1"),
            ("rig", "v2", "friction", "v2"),
            ("friction", "F1", "rig", "F1"),
            ("friction", "F2", "rig", "F2"),
        ],
        3.0,
        1e-3,
    );
    std::fs::write(dir.path().join("planar.ssd"), system).unwrap();
    let system = p(dir.path(), "planar.ssd");
    let mut errors = Vec::new();
    for step in ["1e-3", "1e-4"] {
        let (run, reference) = (p(dir.path(), "run.csv"), p(dir.path(), "ref.csv"));
        ok(&["run", &system, "--step", step, "--out", &run, "-q"]);
        let out = ok(&["reference", &system, "--step", step, "--out", &reference]);
        assert!(out.contains("Rig2D `rig` + Bristle2D `friction`"), "{out}");
        let (r, f) = (
            ResultFile::read(Path::new(&run)).unwrap(),
            ResultFile::read(Path::new(&reference)).unwrap(),
        );
        // the run's columns are the reference's, then the friction law's
        // Boolean output `sliding`, which the monolithic reference has not
        assert_eq!(r.columns[..f.columns.len()], f.columns[..]);
        assert_eq!(r.columns[f.columns.len()..], ["friction.sliding"]);
        let c = compare(&r, &f, &["friction.F1".into(), "rig.x2".into()]).unwrap();
        errors.push(c.signals[0].relative_rms.unwrap());
        assert!(c.signals[1].relative_rms.unwrap() < 1e-2);
    }
    assert!(
        errors[0] > 5.0 * errors[1] && errors[1] > 1e-6,
        "{errors:?}"
    );
}

#[test]
fn systems_without_a_monolithic_model_are_refused_by_component() {
    let dir = tempfile::tempdir().unwrap();
    let rig = [("m", 1.0)];
    std::fs::write(
        dir.path().join("reset.ssd"),
        rig_with("ResetIntegrator.fmu", &rig, 1.0, 1e-3),
    )
    .unwrap();
    refused(
        &["reference", &p(dir.path(), "reset.ssd")],
        &[
            "no monolithic reference",
            "component `friction`",
            "ResetIntegrator",
        ],
    );
    // LuGre on the quasi-static rig.
    std::fs::write(
        dir.path().join("qs.ssd"),
        rig_with("LuGre.fmu", &[("m", 0.0)], 1.0, 1e-3),
    )
    .unwrap();
    refused(
        &["reference", &p(dir.path(), "qs.ssd")],
        &["component `rig` (Rig1D): m = 0", "LuGre needs m > 0"],
    );
    // A missing file, as for run.
    refused(
        &["reference", &p(dir.path(), "none.ssd")],
        &["none.ssd", "no such file"],
    );
}

#[test]
fn compare_refuses_missing_files_and_unrelated_results() {
    let dir = tempfile::tempdir().unwrap();
    let a = p(dir.path(), "a.csv");
    let b = p(dir.path(), "b.csv");
    let c = p(dir.path(), "c.csv");
    std::fs::write(&a, "time,x.y\n0,1\n1,2\n").unwrap();
    std::fs::write(&b, "time,x.z\n0,1\n1,2\n").unwrap();
    std::fs::write(&c, "time,x.y\n0,1\n0,2\n").unwrap();
    refused(
        &["compare", &a, &p(dir.path(), "missing.csv")],
        &["missing.csv"],
    );
    refused(&["compare", &a, &b], &["no common columns", "x.y", "x.z"]);
    refused(
        &["compare", &a, &c],
        &["c.csv: line 3: time 0 does not increase"],
    );
    refused(
        &["compare", &a, &a, "--signal", "x.q"],
        &["signal `x.q`", "a.csv"],
    );
    let shown = ok(&["compare", &a, &a]);
    assert!(
        shown.contains("x.y") && shown.contains("0.0000e0"),
        "{shown}"
    );
}
