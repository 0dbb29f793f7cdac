//! What `fricsim info` and `fricsim cosim` say about broken inputs: a
//! missing FMU file, an archive with a path-traversal entry, a malformed or
//! truncated modelDescription.xml, no binary for this platform, a
//! connection to an unknown variable, an output connected to an output.
//! Each exits with status 1 and one line `fricsim: …` that names the file
//! or the port and the problem, writes no result file, and does not panic.
//! (The importer's own tests, archive.rs, model_description.rs, library.rs
//! and stick_slip.rs, check the same cases and more through the library.)

use crate::belt;
use crate::common;

use std::io::Write;
use std::path::PathBuf;
use std::process::Command;
use tempfile::TempDir;

struct Setup {
    dir: TempDir,
    /// BeltOscillator.fmu, a valid FMU (hand-written C, tests/c/belt_oscillator).
    belt: PathBuf,
}

fn setup() -> Setup {
    let dir = tempfile::tempdir().unwrap();
    let belt = belt::build_fmu(dir.path());
    Setup { dir, belt }
}

impl Setup {
    /// The valid FMU's model description and binary.
    fn parts(&self) -> (Vec<u8>, Vec<u8>) {
        let root = self.dir.path().join("BeltOscillator");
        (
            std::fs::read(root.join("modelDescription.xml")).unwrap(),
            std::fs::read(root.join("binaries/linux64/BeltOscillator.so")).unwrap(),
        )
    }

    /// A zip of `(name, contents)` entries called `name`.
    fn archive(&self, name: &str, entries: &[(&str, &[u8])]) -> PathBuf {
        let path = self.dir.path().join(name);
        let mut zip = zip::ZipWriter::new(std::fs::File::create(&path).unwrap());
        for (entry, bytes) in entries {
            zip.start_file(*entry, zip::write::SimpleFileOptions::default())
                .unwrap();
            zip.write_all(bytes).unwrap();
        }
        zip.finish().unwrap();
        path
    }

    fn out(&self) -> PathBuf {
        self.dir.path().join("out/result.csv")
    }
}

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

/// fricsim refused: status 1, one `fricsim: ` line holding every part.
fn assert_refused(args: &[&str], parts: &[&str]) {
    let (code, _, stderr) = fricsim(args);
    assert_eq!(code, Some(1), "{args:?}: {stderr}");
    assert!(
        stderr.starts_with("fricsim: ") && stderr.lines().count() == 1,
        "{args:?}: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    for part in parts {
        assert!(
            stderr.contains(part),
            "{args:?}: missing {part:?} in {stderr}"
        );
    }
}

/// `fricsim cosim` of `rig` = `fmu` alone.
fn cosim_alone<'a>(fmu: &'a str, out: &'a str) -> Vec<&'a str> {
    vec![
        "cosim", "--fmu", fmu, "--step", "0.001", "--stop", "0.01", "--out", out,
    ]
}

#[test]
fn a_missing_fmu_file() {
    let s = setup();
    let missing = s.dir.path().join("no-such.fmu");
    let m = missing.to_str().unwrap();
    let out = s.out();
    let o = out.to_str().unwrap();
    assert_refused(&["info", m], &[m, "No such file or directory"]);
    let rig = format!("rig={m}");
    assert_refused(&cosim_alone(&rig, o), &[m, "No such file or directory"]);
    // the second of two components
    let rig = format!("rig={}", s.belt.display());
    let other = format!("other={m}");
    assert_refused(
        &["cosim", "--fmu", &rig, "--fmu", &other, "--out", o],
        &[m, "No such file or directory"],
    );
    assert!(!out.exists());
}

#[test]
fn an_archive_with_a_path_traversal_entry() {
    let s = setup();
    let (description, binary) = s.parts();
    // from the unpack directory in the system temp dir, this would land
    // directly in the temp dir
    let escape = format!("fricsim-cli-escape-{}.txt", std::process::id());
    let entry = format!("../{escape}");
    let fmu = s.archive(
        "traversal.fmu",
        &[
            ("modelDescription.xml", &description),
            ("binaries/linux64/BeltOscillator.so", &binary),
            (&entry, b"escaped"),
        ],
    );
    let f = fmu.to_str().unwrap();
    let out = s.out();
    let needle =
        format!("entry \"{entry}\": the entry name contains a `..` component (path traversal)");
    assert_refused(&["info", f], &[f, &needle]);
    let rig = format!("rig={f}");
    assert_refused(&cosim_alone(&rig, out.to_str().unwrap()), &[f, &needle]);
    assert!(!std::env::temp_dir().join(&escape).exists());
    assert!(!out.exists());
}

#[test]
fn a_malformed_or_truncated_model_description() {
    let s = setup();
    let (description, binary) = s.parts();
    let text = String::from_utf8(description.clone()).unwrap();
    let malformed = text.replace("</ModelVariables>", "</ModelVariable>");
    // the line of `</ModelVariables>`, 1-based
    let line = text
        .lines()
        .position(|l| l.contains("</ModelVariables>"))
        .unwrap()
        + 1;
    let truncated = &description[..description.len() / 2];
    let cases: [(&str, &[u8], String); 3] = [
        (
            "malformed.fmu",
            malformed.as_bytes(),
            format!("modelDescription.xml:{line}:"),
        ),
        (
            "truncated.fmu",
            truncated,
            "not found before end of input".to_string(),
        ),
        ("empty.fmu", b"", "modelDescription.xml:".to_string()),
    ];
    let out = s.out();
    for (name, xml, needle) in cases {
        let fmu = s.archive(
            name,
            &[
                ("modelDescription.xml", xml),
                ("binaries/linux64/BeltOscillator.so", &binary),
            ],
        );
        let f = fmu.to_str().unwrap();
        assert_refused(&["info", f], &[&needle]);
        let rig = format!("rig={f}");
        // cosim names the archive: there may be several
        assert_refused(&cosim_alone(&rig, out.to_str().unwrap()), &[f, &needle]);
    }
    assert!(!out.exists());
}

#[test]
fn no_binary_for_this_platform() {
    let s = setup();
    let (description, _) = s.parts();
    let fmu = s.archive(
        "windows-only.fmu",
        &[
            ("modelDescription.xml", &description),
            ("binaries/win64/BeltOscillator.dll", b"MZ"),
        ],
    );
    let f = fmu.to_str().unwrap();
    // info reads the description only, and shows the platforms there are
    let (code, stdout, stderr) = fricsim(&["info", f]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stdout.contains("Platforms          win64\n"), "{stdout}");
    let out = s.out();
    let rig = format!("rig={f}");
    assert_refused(
        &cosim_alone(&rig, out.to_str().unwrap()),
        &[
            f,
            "FMU has no binary for linux64: expected binaries/linux64/BeltOscillator.so; it has: win64",
        ],
    );
    assert!(!out.exists());
}

/// rig = BeltOscillator, friction = LuGre, with one connection.
fn connect(s: &Setup, connection: &str, parts: &[&str]) {
    let rig = format!("rig={}", s.belt.display());
    let friction = format!("friction={}", common::lugre_fmu().display());
    let out = s.out();
    assert_refused(
        &[
            "cosim",
            "--fmu",
            &rig,
            "--fmu",
            &friction,
            "--connect",
            connection,
            "--out",
            out.to_str().unwrap(),
        ],
        parts,
    );
    assert!(!out.exists());
}

#[test]
fn a_connection_to_an_unknown_variable() {
    let s = setup();
    connect(
        &s,
        "rig.nope->friction.v",
        &["connection rig.nope -> friction.v: `rig` has no variable `nope`"],
    );
    connect(
        &s,
        "rig.v->friction.nope",
        &["connection rig.v -> friction.nope: `friction` has no variable `nope`"],
    );
    connect(
        &s,
        "rig.v->ghost.v",
        &["`ghost.v`: no component `ghost` (components: rig, friction)"],
    );
}

#[test]
fn an_output_connected_to_an_output() {
    let s = setup();
    connect(
        &s,
        "rig.v->friction.F",
        &["connection rig.v -> friction.F: `friction.F` is not an input"],
    );
    // and the reverse: an input as the source
    connect(
        &s,
        "friction.v->rig.F",
        &["connection friction.v -> rig.F: `friction.v` is not an output"],
    );
    // a parameter is not an input either
    connect(
        &s,
        "rig.v->friction.sigma0",
        &["`friction.sigma0` is not an input"],
    );
}

/// An FMI 3.0 FMU: `fricsim info` shows it (with FMI 3.0's type names);
/// co-simulating it loads its binary as FMI 3.0's, and a binary that
/// exports FMI 2.0's functions instead (here under FMI 3.0's platform
/// folder) is refused naming the FMI 3.0 functions it lacks.
#[test]
fn an_fmi3_fmu_is_shown_by_info_and_its_binary_loaded_as_fmi3() {
    let s = setup();
    let (_, binary) = s.parts();
    let description = br#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="Dahlquist" instantiationToken="{221063d2-ef4a-45e5-a57a-c4d1f8e3a3ce}">
  <CoSimulation modelIdentifier="BeltOscillator" canHandleVariableCommunicationStepSize="true"/>
  <DefaultExperiment stopTime="10" stepSize="0.1"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    <Float64 name="x" valueReference="1" causality="output" initial="exact" start="1"/>
    <Float64 name="der(x)" valueReference="2" causality="local" derivative="1"/>
    <Float64 name="k" valueReference="3" causality="parameter" variability="fixed" start="1"/>
    <Int32 name="n" valueReference="4" causality="output" start="0"/>
  </ModelVariables>
  <ModelStructure><Output valueReference="1"/><Output valueReference="4"/></ModelStructure>
</fmiModelDescription>
"#;
    let fmu = s.archive(
        "Dahlquist3.fmu",
        &[
            ("modelDescription.xml", &description[..]),
            // where FMI 3.0 keeps a Linux binary
            ("binaries/x86_64-linux/BeltOscillator.so", &binary),
        ],
    );
    let f = fmu.to_str().unwrap();
    let (code, stdout, stderr) = fricsim(&["info", f]);
    assert_eq!(code, Some(0), "{stderr}");
    for part in [
        "FMI Version        3.0",
        "Dahlquist",
        "221063d2",
        "Float64",
        "Int32",
        // FMI 3.0's spelling of the capabilities
        "canGetAndSetFMUState",
        "providesDirectionalDerivatives",
    ] {
        assert!(stdout.contains(part), "missing {part:?} in\n{stdout}");
    }
    assert!(!stdout.contains("canInterpolateInputs"), "{stdout}");
    let row = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("k "))
        .unwrap();
    assert!(
        row.contains("parameter") && row.contains("Float64"),
        "{row}"
    );
    let out = s.out();
    let rig = format!("rig={f}");
    assert_refused(
        &cosim_alone(&rig, out.to_str().unwrap()),
        &[
            f,
            "BeltOscillator.so does not export the required FMI functions",
            "fmi3GetVersion",
            "fmi3InstantiateCoSimulation",
            "fmi3DoStep",
        ],
    );
    assert!(!out.exists());
}

/// `cosim --set` is checked as `run --set` is, before any FMU is
/// instantiated: a value below the variable's `min`, one not of its type,
/// an output, and an unknown variable are each refused, naming the
/// variable and the value; nothing is written.
#[test]
fn cosim_start_values_are_checked_as_run_checks_them() {
    let s = setup();
    let friction = format!("friction={}", common::lugre_fmu().display());
    for (set, parts) in [
        (
            "friction.sigma0=-5",
            &[
                "cannot set `friction.sigma0` to \"-5\"",
                "below the declared min = 0",
            ][..],
        ),
        (
            "friction.sigma0=stiff",
            &["cannot set `friction.sigma0`", "not a Real value"],
        ),
        (
            "friction.F=2",
            &["cannot set `friction.F` to \"2\"", "causality \"output\""],
        ),
        (
            "friction.no_such=1",
            &["`friction` has no variable `no_such`"],
        ),
    ] {
        let out = s.out();
        let mut args = cosim_alone(&friction, out.to_str().unwrap());
        args.extend(["--set", set]);
        assert_refused(&args, parts);
        assert!(!out.exists(), "{set}");
    }
    // a Boolean takes true/false, and a good value runs
    let out = s.out();
    let mut args = cosim_alone(&friction, out.to_str().unwrap());
    args.extend([
        "--set",
        "friction.sigma0=1e5",
        "--set",
        "friction.parameter_sensitivities=true",
    ]);
    let (code, _, stderr) = fricsim(&args);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(out.exists());
}
