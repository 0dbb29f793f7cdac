//! `fricsim run --isolate`: the FMUs in a child process. BeltOscillator
//! (tests/c/belt_oscillator) coupled with LuGre.fmu, told to end or block
//! the process at its 10th fmi2DoStep: a write through a null pointer
//! (SIGSEGV), abort() (SIGABRT), exit(0), a step that hangs (stopped by
//! --step-timeout). Each time fricsim survives, exits non-zero, keeps the
//! rows of the 10 communication points before the fault (bit for bit
//! those of the run in-process), ends the file with `# INCOMPLETE` naming
//! the instance, the call, the time and the cause, and leaves nothing in
//! the temporary directory. A run that goes well gives the in-process
//! run's file byte for byte.

use crate::belt;
use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// 2^-10 s: communication points are exact binary numbers.
const H: f64 = 1.0 / 1024.0;
/// The call of fmi2DoStep that fails: the step from 9·H.
const FAULT_STEP: usize = 10;
const STOP: f64 = 64.0 * H;

/// A system file: instance `belt` = BeltOscillator failing as `fault`
/// says at step 10, `friction` = LuGre, Jacobi at H.
fn system_file(dir: &Path, belt: &Path, fault: i32) -> PathBuf {
    let text = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="belt_lugre"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssd:System name="belt_lugre">
    <ssd:Elements>
      <ssd:Component name="belt" source="{belt}">
        <ssd:Connectors>
          <ssd:Connector name="F" kind="input"><ssc:Real unit="N"/></ssd:Connector>
          <ssd:Connector name="v" kind="output"><ssc:Real unit="m/s"/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name="belt"><ssv:Parameters>
            <ssv:Parameter name="v0"><ssv:Real value="0"/></ssv:Parameter>
            <ssv:Parameter name="fault"><ssv:Integer value="{fault}"/></ssv:Parameter>
            <ssv:Parameter name="fault_step"><ssv:Integer value="{FAULT_STEP}"/></ssv:Parameter>
          </ssv:Parameters></ssv:ParameterSet>
        </ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>
      </ssd:Component>
      <ssd:Component name="friction" source="{lugre}">
        <ssd:Connectors>
          <ssd:Connector name="v" kind="input"><ssc:Real unit="m/s"/></ssd:Connector>
          <ssd:Connector name="F" kind="output"><ssc:Real unit="N"/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="belt" startConnector="v" endElement="friction" endConnector="v"/>
      <ssd:Connection startElement="friction" startConnector="F" endElement="belt" endConnector="F"/>
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="{STOP}">
    <ssd:Annotations>
      <ssc:Annotation type="org.friction-fmu.fricsim">
        <fricsim:Simulation xmlns:fricsim="urn:friction-fmu:fricsim:1" stepSize="{H}"/>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"#,
        belt = belt.display(),
        lugre = common::lugre_fmu().display(),
    );
    let path = dir.join(format!("belt_lugre_{fault}.ssd"));
    std::fs::write(&path, text).unwrap();
    path
}

/// `fricsim run SYSTEM --out OUT ARGS` with TMPDIR `tmp`.
fn fricsim_run(system: &Path, out: &Path, tmp: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("run")
        .arg(system)
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .args(args)
        .env("TMPDIR", tmp)
        .current_dir(common::repository())
        .output()
        .unwrap()
}

/// A fresh, empty directory for TMPDIR.
fn empty_dir(parent: &Path, name: &str) -> PathBuf {
    let dir = parent.join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn entries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

struct Rig {
    dir: tempfile::TempDir,
    belt: PathBuf,
    /// The in-process run without a fault: header and rows.
    reference: Vec<String>,
}

fn rig() -> Rig {
    let dir = tempfile::tempdir().unwrap();
    let belt = belt::build_fmu(dir.path());
    let system = system_file(dir.path(), &belt, 0);
    let out = dir.path().join("in_process.csv");
    let tmp = empty_dir(dir.path(), "tmp_reference");
    let run = fricsim_run(&system, &out, &tmp, &[]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let reference: Vec<String> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect();
    // header + 65 communication points
    assert_eq!(reference.len(), 66);
    Rig {
        dir,
        belt,
        reference,
    }
}

/// Run the belt isolated with `fault`: the result file's lines and the
/// error on stderr, after checking the exit status, the rows kept and that
/// the temporary directory is left empty.
fn crashed_run(rig: &Rig, fault: i32, args: &[&str]) -> (String, String) {
    let system = system_file(rig.dir.path(), &rig.belt, fault);
    let out = rig.dir.path().join(format!("isolated_{fault}.csv"));
    let tmp = empty_dir(rig.dir.path(), &format!("tmp_{fault}"));
    let mut all = vec!["--isolate"];
    all.extend_from_slice(args);
    let run = fricsim_run(&system, &out, &tmp, &all);
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    let text = std::fs::read_to_string(&out).unwrap_or_else(|e| panic!("{e}: {stderr}"));
    let lines: Vec<&str> = text.lines().collect();
    // the header and the rows at 0, H, …, 9·H, each bit for bit as in-process
    assert_eq!(lines.len(), 1 + FAULT_STEP + 1, "{text}");
    assert_eq!(lines[..=FAULT_STEP], rig.reference[..=FAULT_STEP], "{text}");
    let last = lines[FAULT_STEP + 1];
    assert!(last.starts_with("# INCOMPLETE: "), "{last}");
    assert!(
        entries(&tmp).is_empty(),
        "left in TMPDIR: {:?}",
        entries(&tmp)
    );
    (last.to_string(), stderr)
}

#[test]
fn a_crash_keeps_the_rows_before_it_and_names_the_instance_the_call_and_the_cause() {
    let rig = rig();
    let t = (FAULT_STEP - 1) as f64 * H;
    for (fault, cause) in [
        (
            belt::SEGFAULT,
            "crashed in fmi2DoStep at t = 0.0087890625 s: the FMU process was killed by signal 11 (SIGSEGV)",
        ),
        (
            belt::ABORT,
            "crashed in fmi2DoStep at t = 0.0087890625 s: the FMU process was killed by signal 6 (SIGABRT)",
        ),
        (
            belt::EXIT_0,
            "ended the process in fmi2DoStep at t = 0.0087890625 s: the FMU process exited with status 0 before the run finished",
        ),
    ] {
        assert_eq!(t, 0.0087890625);
        let (last, stderr) = crashed_run(&rig, fault, &[]);
        let expected = format!("instance \"belt\" {cause}");
        assert!(last.contains(&expected), "{last}\nnot: {expected}");
        assert!(stderr.contains(&expected), "{stderr}");
        assert!(stderr.contains("run INCOMPLETE (the 10 rows"), "{stderr}");
    }
}

#[test]
fn a_hung_call_is_stopped_by_the_step_timeout_and_named() {
    let rig = rig();
    let (last, stderr) = crashed_run(&rig, belt::HANG, &["--step-timeout", "0.3"]);
    let expected = "instance \"belt\" was in fmi2DoStep at t = 0.0087890625 s for more than the \
                    limit of 0.3 s (--step-timeout): the FMU process was killed (SIGKILL)";
    assert!(last.contains(expected), "{last}");
    assert!(stderr.contains(expected), "{stderr}");
    // the in-process watchdog's "cannot be interrupted" does not apply
    assert!(!stderr.contains("cannot be interrupted"), "{stderr}");
}

#[test]
fn a_run_that_goes_well_is_the_in_process_run_byte_for_byte() {
    let rig = rig();
    let system = system_file(rig.dir.path(), &rig.belt, 0);
    let out = rig.dir.path().join("isolated.csv");
    let tmp = empty_dir(rig.dir.path(), "tmp_isolated");
    let run = fricsim_run(&system, &out, &tmp, &["--isolate"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let isolated = std::fs::read_to_string(&out).unwrap();
    assert_eq!(isolated.lines().collect::<Vec<_>>(), rig.reference);
    assert!(entries(&tmp).is_empty(), "{:?}", entries(&tmp));

    // the stick-slip example (200 001 rows, many chunks and ring turns)
    let example = common::repository().join("examples/stick_slip.ssd");
    let mut files = Vec::new();
    for (name, args) in [("in_process", &[][..]), ("isolated", &["--isolate"][..])] {
        let out = rig.dir.path().join(format!("stick_slip_{name}.csv"));
        let tmp = empty_dir(rig.dir.path(), &format!("tmp_stick_slip_{name}"));
        let run = fricsim_run(&example, &out, &tmp, args);
        let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        assert!(stdout.contains("200000 of 200000 macro steps"), "{stdout}");
        assert!(entries(&tmp).is_empty(), "{:?}", entries(&tmp));
        files.push(std::fs::read(&out).unwrap());
    }
    assert_eq!(files[0].len(), files[1].len());
    assert!(files[0] == files[1], "the isolated stick-slip CSV differs");
}

#[test]
fn an_error_before_the_run_is_reported_once_as_in_process() {
    let rig = rig();
    let system = system_file(rig.dir.path(), &rig.belt, 0);
    let mut messages = Vec::new();
    for args in [&["--step=-1"][..], &["--step=-1", "--isolate"][..]] {
        let out = rig.dir.path().join("never.csv");
        let tmp = empty_dir(rig.dir.path(), "tmp_refused");
        let run = fricsim_run(&system, &out, &tmp, args);
        assert_eq!(run.status.code(), Some(1));
        assert!(!out.exists());
        assert!(entries(&tmp).is_empty(), "{:?}", entries(&tmp));
        messages.push(String::from_utf8_lossy(&run.stderr).into_owned());
    }
    assert_eq!(
        messages[0],
        "fricsim: --step must be a positive number, got -1\n"
    );
    assert_eq!(messages[0], messages[1]);
}

#[test]
fn fricsim_cosim_isolate_survives_a_crash_the_same_way() {
    let rig = rig();
    let out = rig.dir.path().join("cosim.csv");
    let tmp = empty_dir(rig.dir.path(), "tmp_cosim");
    let run = Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("cosim")
        .arg(format!("--fmu=belt={}", rig.belt.display()))
        .arg(format!("--fmu=friction={}", common::lugre_fmu().display()))
        .args(["--set", &format!("belt.fault={}", belt::SEGFAULT)])
        .args(["--set", &format!("belt.fault_step={FAULT_STEP}")])
        .args(["--set", "belt.v0=0"])
        .args([
            "--connect",
            "belt.v->friction.v",
            "--connect",
            "friction.F->belt.F",
        ])
        .arg(format!("--step={H}"))
        .arg(format!("--stop={STOP}"))
        .arg("--out")
        .arg(&out)
        .arg("--isolate")
        .env("TMPDIR", &tmp)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    let text = std::fs::read_to_string(&out).unwrap_or_else(|e| panic!("{e}: {stderr}"));
    let lines: Vec<&str> = text.lines().collect();
    // cosim records the same columns: the rows equal run's in-process rows
    assert_eq!(lines[..=FAULT_STEP], rig.reference[..=FAULT_STEP], "{text}");
    assert_eq!(
        lines[FAULT_STEP + 1..],
        [
            "# INCOMPLETE: the run stopped early: instance \"belt\" crashed in fmi2DoStep at \
          t = 0.0087890625 s: the FMU process was killed by signal 11 (SIGSEGV)"
        ]
    );
    assert!(entries(&tmp).is_empty(), "{:?}", entries(&tmp));
}

#[test]
fn output_interval_start_values_and_whole_numbers_are_as_in_process_byte_for_byte() {
    let rig = rig();
    let system = system_file(rig.dir.path(), &rig.belt, 0);
    // every 3rd of the 65 points (0, 3·H, …, 63·H) and the last (64·H);
    // a start value; an Integer column
    let interval = (3.0 * H).to_string();
    let args = [
        "--output-interval",
        &interval,
        "--set",
        "friction.Fs=1.25",
        "--record",
        "belt.fault_step",
    ];
    for ext in ["csv", "mat"] {
        let mut files = Vec::new();
        for isolate in [false, true] {
            let name = format!("interval_{isolate}.{ext}");
            let out = rig.dir.path().join(&name);
            let tmp = empty_dir(rig.dir.path(), &format!("tmp_{name}"));
            let mut all = args.to_vec();
            if isolate {
                all.push("--isolate");
            }
            let run = fricsim_run(&system, &out, &tmp, &all);
            assert!(
                run.status.success(),
                "{}",
                String::from_utf8_lossy(&run.stderr)
            );
            let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
            assert!(stdout.contains("64 of 64 macro steps"), "{stdout}");
            assert!(entries(&tmp).is_empty(), "{:?}", entries(&tmp));
            files.push(std::fs::read(&out).unwrap());
        }
        if ext == "csv" {
            let text = String::from_utf8_lossy(&files[0]).into_owned();
            let lines: Vec<&str> = text.lines().collect();
            assert_eq!(lines.len(), 1 + 22 + 1, "{text}");
            let k = lines[0]
                .split(',')
                .position(|c| c == "belt.fault_step")
                .unwrap_or_else(|| panic!("{}", lines[0]));
            for line in &lines[1..] {
                assert_eq!(line.split(',').nth(k), Some("10"), "{line}");
            }
        }
        assert!(files[0] == files[1], "the isolated .{ext} differs");
    }

    // a crash at step 10 with every 4th point: 0, 4·H, 8·H and the last
    // point the parent received, 9·H, as a failing run in-process
    let interval = (4.0 * H).to_string();
    let failing = system_file(rig.dir.path(), &rig.belt, belt::SEGFAULT);
    let out = rig.dir.path().join("interval_crash.csv");
    let tmp = empty_dir(rig.dir.path(), "tmp_interval_crash");
    let run = fricsim_run(
        &failing,
        &out,
        &tmp,
        &["--isolate", "--output-interval", &interval],
    );
    let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("run INCOMPLETE (the 4 rows"), "{stderr}");
    let text = std::fs::read_to_string(&out).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let expected: Vec<&str> = [0, 1, 5, 9, 10]
        .iter()
        .map(|&i| rig.reference[i].as_str())
        .collect();
    assert_eq!(lines[..5], expected[..], "{text}");
    assert_eq!(lines.len(), 6, "{text}");
    assert!(lines[5].starts_with("# INCOMPLETE: "), "{}", lines[5]);
    assert!(entries(&tmp).is_empty(), "{:?}", entries(&tmp));
}
