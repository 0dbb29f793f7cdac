//! Result files survive whatever ends a run (docs/user-guide.md, "Result
//! files are written safely"): `fricsim run` and `cosim` write to a
//! temporary file beside the result and rename it into place.
//!
//! * SIGINT and SIGTERM stop the run between chunks: the rows so far are
//!   put in place ending in `# INCOMPLETE: … interrupted by SIGINT`, the
//!   exit status is 130 or 143, no temporary directory is left (the runs
//!   get an empty `TMPDIR` of their own, whose entries are counted while
//!   they run and after).
//! * SIGKILL mid-run leaves the previous result byte for byte; the next
//!   run at that path removes the killed run's temporary file, and the
//!   folders it unpacked its FMUs into.
//! * A second writer of a path being written is refused at once naming
//!   the first one's pid; the first one's result is whole.
//! * `--out` naming an input (the .ssd, an .ssv, an FMU, the `--input`
//!   table, the plot) is refused naming both; the input is unchanged.
//! * A write error (a file size limit, `RLIMIT_FSIZE`, standing in for a
//!   full disk) leaves the previous result byte for byte, names the path,
//!   and leaves no temporary file.
//! * An FMU failing mid-run puts its rows so far, marked, in place of the
//!   previous result.

use crate::belt;
use crate::common;

use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// How long a test waits for a run to reach a point before it gives up
/// (a limit against hanging, not a measurement).
const PATIENCE: Duration = Duration::from_secs(120);

/// A folder with copies of Rig1D.fmu and LuGre.fmu, `rig.ssv`, and
/// `system.ssd` coupling them (the stick-slip benchmark's rig and law),
/// an `--input` table, and an empty `tmp/` for the runs' `TMPDIR`.
struct Setup {
    dir: tempfile::TempDir,
}

impl Setup {
    fn new() -> Setup {
        let dir = tempfile::tempdir().unwrap();
        let dist = common::repository().join("dist");
        for fmu in ["Rig1D.fmu", "LuGre.fmu"] {
            std::fs::copy(dist.join(fmu), dir.path().join(fmu)).unwrap();
        }
        std::fs::write(dir.path().join("rig.ssv"), SSV).unwrap();
        std::fs::write(dir.path().join("system.ssd"), SSD).unwrap();
        std::fs::write(
            dir.path().join("inputs.csv"),
            "time,friction.Fn\n0,1\n1,1\n",
        )
        .unwrap();
        std::fs::create_dir(dir.path().join("tmp")).unwrap();
        Setup { dir }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// `fricsim run system.ssd --step 1e-4 ARGS`, `TMPDIR` = `tmp/`.
    fn run(&self, args: &[&str]) -> Command {
        let mut c = Command::new(env!("CARGO_BIN_EXE_fricsim"));
        c.arg("run")
            .arg(self.path("system.ssd"))
            .args(["--step", "1e-4", "--quiet"])
            .args(args)
            .env("TMPDIR", self.path("tmp"))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        c
    }

    /// A result of a short run at `out`, as a previous result to keep.
    fn previous_result(&self, out: &Path) -> Vec<u8> {
        let o = self
            .run(&["--stop", "0.05", "--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", text(&o.stderr));
        std::fs::read(out).unwrap()
    }

    /// The entries of the runs' `TMPDIR`.
    fn temporary_entries(&self) -> usize {
        std::fs::read_dir(self.path("tmp")).unwrap().count()
    }
}

const SSV: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssv:ParameterSet version="1.0" name="rig_1995" xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssv:Parameters>
    <ssv:Parameter name="m"><ssv:Real value="1" unit="kg"/></ssv:Parameter>
    <ssv:Parameter name="k"><ssv:Real value="2" unit="N/m"/></ssv:Parameter>
  </ssv:Parameters>
</ssv:ParameterSet>
"#;

const SSD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="crash"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssd:System name="crash">
    <ssd:Elements>
      <ssd:Component name="rig" source="Rig1D.fmu">
        <ssd:Connectors>
          <ssd:Connector name="F" kind="input"><ssc:Real unit="N"/></ssd:Connector>
          <ssd:Connector name="v" kind="output"><ssc:Real unit="m/s"/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings><ssd:ParameterBinding source="rig.ssv"/></ssd:ParameterBindings>
      </ssd:Component>
      <ssd:Component name="friction" source="LuGre.fmu">
        <ssd:Connectors>
          <ssd:Connector name="v" kind="input"><ssc:Real unit="m/s"/></ssd:Connector>
          <ssd:Connector name="F" kind="output"><ssc:Real unit="N"/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="rig" startConnector="v" endElement="friction" endConnector="v"/>
      <ssd:Connection startElement="friction" startConnector="F" endElement="rig" endConnector="F"/>
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="1"/>
</ssd:SystemStructureDescription>
"#;

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Wait until `ready` holds, polling; panics after [`PATIENCE`].
fn wait_for(what: &str, mut ready: impl FnMut() -> bool) {
    let started = Instant::now();
    while !ready() {
        assert!(started.elapsed() < PATIENCE, "gave up waiting for {what}");
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// The temporary file a run writes `out` through.
fn partial_of(out: &Path, pid: u32) -> PathBuf {
    let name = out.file_name().unwrap().to_str().unwrap();
    out.with_file_name(format!(".{name}.fricsim-partial-{pid}"))
}

/// The other files of `out`'s directory besides the results `keep`.
fn leftovers(dir: &Path, keep: &[&str]) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !keep.contains(&n.as_str()))
        .collect()
}

/// A long run at `out` (10⁶ s of steps of 1e-4 s: it does not end by
/// itself within the test) whose temporary file has had its first chunk.
fn long_run(setup: &Setup, out: &Path) -> Child {
    let child = setup
        .run(&["--stop", "1e6", "--out", out.to_str().unwrap()])
        .spawn()
        .unwrap();
    let partial = partial_of(out, child.id());
    wait_for("the first chunk of rows", || {
        std::fs::metadata(&partial).is_ok_and(|m| m.len() > 0)
    });
    child
}

/// Wait for `child` to end, killing it after [`PATIENCE`].
fn wait_output(mut child: Child) -> Output {
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > PATIENCE {
            let _ = child.kill();
            panic!("the run did not stop");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    child.wait_with_output().unwrap()
}

fn send(child: &Child, signal: i32) {
    // SAFETY: a signal to our own child process
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
}

/// The data rows of a result CSV (after the header, before a `#` line):
/// each with the header's number of fields, times strictly increasing.
/// Returns their number and the last line.
fn check_rows(csv: &str) -> (usize, String) {
    let mut lines = csv.lines();
    let width = lines.next().expect("a header").split(',').count();
    let mut rows = 0;
    let mut last_time = f64::NEG_INFINITY;
    let mut last = String::new();
    for line in lines {
        last = line.to_string();
        if line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        assert_eq!(fields.len(), width, "a cut row: {line}");
        let t: f64 = fields[0].parse().unwrap();
        assert!(t > last_time, "time goes from {last_time} back to {t}");
        for f in &fields {
            f.parse::<f64>().unwrap();
        }
        last_time = t;
        rows += 1;
    }
    assert!(csv.ends_with('\n'), "the file ends mid-line");
    (rows, last)
}

/// `fricsim cosim` of BeltOscillator (`rig`) and LuGre at steps of 1e-4 s
/// to `stop`, the rig's `fault` at its 5000th step, `TMPDIR` = `tmp/`.
fn belt_cosim(setup: &Setup, rig: &Path, fault: i32, stop: f64, out: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_fricsim"));
    c.arg("cosim")
        .arg("--fmu")
        .arg(format!("rig={}", rig.display()))
        .arg("--fmu")
        .arg(format!("friction={}", setup.path("LuGre.fmu").display()))
        .args([
            "--connect",
            "rig.v->friction.v",
            "--connect",
            "friction.F->rig.F",
        ])
        .args([
            "--set",
            &format!("rig.fault={fault}"),
            "--set",
            "rig.fault_step=5000",
        ])
        .args(["--step", "1e-4", "--stop", &stop.to_string()])
        .arg("--out")
        .arg(out)
        .env("TMPDIR", setup.path("tmp"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    c
}

/// `out/` holds the result `r.csv` and nothing else: no temporary file,
/// no lock file.
fn assert_only_the_result(setup: &Setup) {
    assert_eq!(
        leftovers(&setup.path("out"), &["r.csv"]),
        Vec::<String>::new()
    );
}

#[test]
fn sigint_and_sigterm_put_the_rows_so_far_in_place_marked_and_remove_temporary_directories() {
    for (signal, name, status) in [
        (libc::SIGINT, "SIGINT", 130),
        (libc::SIGTERM, "SIGTERM", 143),
    ] {
        let setup = Setup::new();
        let out = setup.path("out/r.csv");
        let previous = setup.previous_result(&out);
        assert_eq!(setup.temporary_entries(), 0);
        let child = long_run(&setup, &out);
        // the run unpacked its two FMUs into TMPDIR
        assert_eq!(setup.temporary_entries(), 2, "{name}");
        send(&child, signal);
        let o = wait_output(child);
        let stderr = text(&o.stderr);
        assert_eq!(o.status.code(), Some(status), "{name}: {stderr}");
        assert!(
            stderr.contains(&format!("interrupted by {name}")),
            "{stderr}"
        );
        assert!(stderr.contains(out.to_str().unwrap()), "{stderr}");
        let csv = std::fs::read_to_string(&out).unwrap();
        assert_ne!(csv.as_bytes(), previous.as_slice());
        let (rows, last) = check_rows(&csv);
        // more than the first chunk of 4096 steps, and far from the end
        assert!(rows > 4096 && rows < 10_000_000_000, "{rows} rows");
        assert_eq!(
            last,
            format!("# INCOMPLETE: the run stopped early: interrupted by {name}")
        );
        assert_eq!(setup.temporary_entries(), 0, "{name}: TMPDIR not empty");
        assert_only_the_result(&setup);
    }
}

#[test]
fn sigkill_mid_run_leaves_the_previous_result_and_the_next_run_cleans_up() {
    let setup = Setup::new();
    let out = setup.path("out/r.csv");
    let previous = setup.previous_result(&out);
    let child = long_run(&setup, &out);
    let pid = child.id();
    let partial = partial_of(&out, pid);
    send(&child, libc::SIGKILL);
    let o = wait_output(child);
    assert_eq!(o.status.code(), None, "killed by a signal");
    assert_eq!(
        std::fs::read(&out).unwrap(),
        previous,
        "the previous result changed"
    );
    // the traces: the temporary file, named as one (and the lock file),
    // and the two folders the killed run unpacked its FMUs into, named
    // with its pid
    assert!(partial.exists());
    let folders = std::fs::read_dir(setup.path("tmp"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect::<Vec<_>>();
    let killed = format!("fricsim-fmu-{pid}-");
    assert_eq!(folders.len(), 2, "{folders:?}");
    assert!(
        folders.iter().all(|f| f.starts_with(&killed)),
        "{folders:?}"
    );
    // beside them, a folder of a process that runs (this test's) and one
    // without a pid, which are not the next run's to remove
    let alive = format!("fricsim-fmu-{}-alive", std::process::id());
    for kept in [alive.as_str(), "fricsim-fmu-nopid"] {
        std::fs::create_dir(setup.path("tmp").join(kept)).unwrap();
    }
    // the killed run's lock does not block the next run, which removes the
    // killed run's temporary file and folders
    let again = setup.previous_result(&out);
    assert_eq!(again, previous, "the same run, the same bytes");
    assert!(!partial.exists());
    let mut left = std::fs::read_dir(setup.path("tmp"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect::<Vec<_>>();
    left.sort();
    assert_eq!(left, [alive.as_str(), "fricsim-fmu-nopid"]);
    assert_only_the_result(&setup);
}

#[test]
fn a_second_writer_of_the_same_path_is_refused_and_the_first_result_is_whole() {
    let setup = Setup::new();
    let rig = belt::build_fmu(setup.dir.path());
    let out = setup.path("out/r.csv");
    // the first writer: 6000 steps, of which the 5000th sleeps 0.6 s
    let first = belt_cosim(&setup, &rig, belt::SLOW, 0.6, &out)
        .spawn()
        .unwrap();
    let pid = first.id();
    // the lock on the lock file, taken by that pid (/proc/locks); the
    // file itself stays empty (no data block to write out and free)
    let lock = setup.path("out/.r.csv.fricsim-lock");
    wait_for("the lock", || {
        std::fs::read_to_string("/proc/locks").is_ok_and(|locks| {
            locks
                .lines()
                .any(|l| l.contains("FLOCK") && l.split_whitespace().any(|f| f == pid.to_string()))
        })
    });
    assert_eq!(std::fs::metadata(&lock).unwrap().len(), 0);
    let second = setup
        .run(&["--stop", "0.05", "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    let first = wait_output(first);
    let stderr = text(&second.stderr);
    assert_eq!(second.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "{} is being written by another fricsim run (pid {pid})",
            out.display()
        )),
        "{stderr}"
    );
    assert!(first.status.success(), "{}", text(&first.stderr));
    let csv = std::fs::read_to_string(&out).unwrap();
    let (rows, last) = check_rows(&csv);
    assert_eq!(rows, 6001, "{last}");
    assert!(!last.starts_with('#'));
    assert_only_the_result(&setup);
}

#[test]
fn an_out_that_is_an_input_is_refused_naming_both_and_the_input_is_unchanged() {
    let setup = Setup::new();
    for (input, what, extra) in [
        ("system.ssd", "the system file", vec![]),
        ("rig.ssv", "the parameter file", vec![]),
        ("LuGre.fmu", "the FMU", vec![]),
        ("inputs.csv", "the --input table", vec!["--input"]),
        ("plot.png", "the plot", vec!["--plot"]),
    ] {
        let path = setup.path(input);
        let before = std::fs::read(&path).ok();
        let mut args: Vec<&str> = extra.clone();
        if !extra.is_empty() {
            args.push(path.to_str().unwrap());
        }
        // the same file under another spelling
        let spelled = setup.dir.path().join("tmp/..").join(input);
        args.extend(["--out", spelled.to_str().unwrap()]);
        let o = setup.run(&args).output().unwrap();
        let stderr = text(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{input}: {stderr}");
        for part in [
            &format!("the result file {}", spelled.display()),
            &format!("is {what} {}", path.display()),
        ] {
            assert!(
                stderr.contains(part.as_str()),
                "{input}: {part} not in {stderr}"
            );
        }
        assert_eq!(std::fs::read(&path).ok(), before, "{input} changed");
    }
    // cosim too
    let lugre = setup.path("LuGre.fmu");
    let before = std::fs::read(&lugre).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .arg("cosim")
        .arg("--fmu")
        .arg(format!("friction={}", lugre.display()))
        .arg("--out")
        .arg(&lugre)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(
        text(&o.stderr).contains("is the FMU"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(std::fs::read(&lugre).unwrap(), before);
    assert_eq!(setup.temporary_entries(), 0);
}

#[test]
fn a_write_error_leaves_the_previous_result_names_the_path_and_no_temporary_file() {
    let setup = Setup::new();
    let out = setup.path("out/r.csv");
    let previous = setup.previous_result(&out);
    // files may grow to 1 MB (the unpacked FMU binaries are 650 kB), the
    // result of 10 s would take several: the write that passes the limit
    // fails with EFBIG (SIGXFSZ ignored, as setrlimit(2) describes)
    let mut run = setup.run(&["--stop", "10", "--out", out.to_str().unwrap()]);
    // SAFETY: only async-signal-safe calls between fork and exec
    unsafe {
        run.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: 1 << 20,
                rlim_max: 1 << 20,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            Ok(())
        });
    }
    let o = run.output().unwrap();
    let stderr = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    for part in [
        &format!("{}: File too large", out.display()),
        "the file at that path was left as it was",
    ] {
        assert!(stderr.contains(part), "{part} not in {stderr}");
    }
    assert_eq!(std::fs::read(&out).unwrap(), previous);
    assert_only_the_result(&setup);
    assert_eq!(setup.temporary_entries(), 0);
}

#[test]
fn an_fmu_failing_mid_run_puts_its_rows_so_far_marked_in_place() {
    let setup = Setup::new();
    let rig = belt::build_fmu(setup.dir.path());
    let out = setup.path("out/r.csv");
    let previous = setup.previous_result(&out);
    // fmi2Error at the 5000th step: past the first chunk of rows
    let o = belt_cosim(&setup, &rig, belt::ERROR, 1.0, &out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    let csv = std::fs::read_to_string(&out).unwrap();
    assert_ne!(csv.as_bytes(), previous.as_slice());
    let (rows, last) = check_rows(&csv);
    assert_eq!(rows, 5000);
    assert!(
        last.starts_with("# INCOMPLETE: the run stopped early: at t = 0.4999"),
        "{last}"
    );
    assert!(last.contains("fault injected at step 5000"), "{last}");
    assert_only_the_result(&setup);
    assert_eq!(setup.temporary_entries(), 0);
}
