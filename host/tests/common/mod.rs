//! Helpers shared by the integration tests: the C stub FMU (compiled with
//! `cc` at test time), zipping a directory, and the repository's LuGre.fmu.
//! The tests of bench/ (the BENCHMARKS.md programs) include this file by
//! path too, so paths here are relative to the workspace, not to host/.
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use tempfile::TempDir;

/// The stub FMU's C source.
pub const STUB_SOURCE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../host/tests/c/stub_fmu.c");

/// Compile C `source` into the shared library `out` with extra `flags`.
pub fn compile_shared(source: &Path, out: &Path, flags: &[&str]) {
    let output = Command::new("cc")
        .args([
            "-shared",
            "-fPIC",
            "-fvisibility=hidden",
            "-O1",
            "-Wall",
            "-Wextra",
        ])
        .args(flags)
        .arg("-o")
        .arg(out)
        .arg(source)
        .arg("-lm")
        .output()
        .expect("running cc");
    assert!(
        output.status.success(),
        "cc failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// The stub's model description; `capabilities` is spliced into `<CoSimulation>`.
pub fn stub_description(capabilities: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Stub" guid="{{stub}}" generationTool="hand-written C">
  <CoSimulation modelIdentifier="Stub" {capabilities}/>
  <UnitDefinitions><Unit name="m"/></UnitDefinitions>
  <ModelVariables>
    <ScalarVariable name="u" valueReference="0" causality="input"><Real start="0" unit="m"/></ScalarVariable>
    <ScalarVariable name="y" valueReference="1" causality="output"><Real unit="m"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="2" dependencies="1"/></Outputs></ModelStructure>
</fmiModelDescription>
"#
    )
}

/// An unpacked stub FMU: description with `capabilities`, binary compiled
/// with `flags`.
pub fn stub_fmu_dir(capabilities: &str, flags: &[&str]) -> TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("modelDescription.xml"),
        stub_description(capabilities),
    )
    .unwrap();
    let binaries = dir.path().join("binaries/linux64");
    std::fs::create_dir_all(&binaries).unwrap();
    compile_shared(Path::new(STUB_SOURCE), &binaries.join("Stub.so"), flags);
    dir
}

/// The FMU `dist/<name>.fmu` of this repository with `edit` applied to its
/// model description, zipped into `out`. The edit must change something.
pub fn repacked(name: &str, out: &Path, edit: impl Fn(&str) -> String) -> PathBuf {
    let unpacked = fricsim_fmi::archive::unpack(
        &repository().join("dist").join(format!("{name}.fmu")),
        &fricsim_fmi::archive::UnpackOptions::default(),
    )
    .unwrap();
    let md = unpacked.path().join("modelDescription.xml");
    let text = std::fs::read_to_string(&md).unwrap();
    let edited = edit(&text);
    assert_ne!(edited, text, "the edit changed nothing");
    std::fs::write(&md, edited).unwrap();
    zip_dir(unpacked.path(), out);
    out.to_path_buf()
}

/// An FMU written by hand in C: compile `source_dir/c_file` into
/// `binaries/linux64/<identifier>.so`, zip it with
/// `source_dir/modelDescription.xml` into `dir/<identifier>.fmu`.
pub fn c_fmu(source_dir: &Path, c_file: &str, identifier: &str, dir: &Path) -> PathBuf {
    c_fmu_as(
        &source_dir.join("modelDescription.xml"),
        &source_dir.join(c_file),
        identifier,
        "linux64",
        dir,
    )
}

/// An FMI 3.0 Co-Simulation FMU from the C file `c_file` and the model
/// description `description` in `host/tests/c/fmi3`, as [`c_fmu`] makes an
/// FMI 2.0 one: `dir/<identifier>.fmu`, its binary in `x86_64-linux`.
pub fn c_fmu3(c_file: &str, description: &str, identifier: &str, dir: &Path) -> PathBuf {
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/c/fmi3");
    c_fmu_as(
        &source.join(description),
        &source.join(c_file),
        identifier,
        "x86_64-linux",
        dir,
    )
}

/// `dir/<identifier>.fmu` of `description` and the compiled `source`,
/// its binary in `binaries/<platform>`.
fn c_fmu_as(
    description: &Path,
    source: &Path,
    identifier: &str,
    platform: &str,
    dir: &Path,
) -> PathBuf {
    let root = dir.join(identifier);
    let binaries = root.join("binaries").join(platform);
    std::fs::create_dir_all(&binaries).unwrap();
    std::fs::copy(description, root.join("modelDescription.xml")).unwrap();
    compile_shared(source, &binaries.join(format!("{identifier}.so")), &[]);
    let fmu = dir.join(format!("{identifier}.fmu"));
    zip_dir(&root, &fmu);
    fmu
}

/// Zip the files below `dir` into `out`.
pub fn zip_dir(dir: &Path, out: &Path) {
    fn add(zip: &mut zip::ZipWriter<std::fs::File>, root: &Path, dir: &Path) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path
                .strip_prefix(root)
                .unwrap()
                .to_str()
                .unwrap()
                .to_string();
            if path.is_dir() {
                add(zip, root, &path);
            } else {
                zip.start_file(name, zip::write::SimpleFileOptions::default())
                    .unwrap();
                zip.write_all(&std::fs::read(&path).unwrap()).unwrap();
            }
        }
    }
    let mut zip = zip::ZipWriter::new(std::fs::File::create(out).unwrap());
    add(&mut zip, dir, dir);
    zip.finish().unwrap();
}

/// The repository root (the workspace).
pub fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// `dist/LuGre.fmu`, built with `build-fmu.sh` if it is not there yet.
pub fn lugre_fmu() -> PathBuf {
    static BUILT: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    BUILT
        .get_or_init(|| {
            let fmu = repository().join("dist/LuGre.fmu");
            if fmu.is_file() {
                return Ok(fmu);
            }
            let output = Command::new(repository().join("build-fmu.sh"))
                .current_dir(repository())
                .output();
            match output {
                Err(e) => Err(format!("cannot run build-fmu.sh: {e}")),
                Ok(o) if !o.status.success() || !fmu.is_file() => Err(format!(
                    "build-fmu.sh did not produce {}:\n{}",
                    fmu.display(),
                    String::from_utf8_lossy(&o.stderr)
                )),
                Ok(_) => Ok(fmu),
            }
        })
        .clone()
        .unwrap_or_else(|e| panic!("{e}"))
}

/// Assert that `error`'s message (an error or any text) contains every one of `parts`.
pub fn assert_message(error: &dyn std::fmt::Display, parts: &[&str]) {
    let message = error.to_string();
    for part in parts {
        assert!(
            message.contains(part),
            "message {message:?} does not contain {part:?}"
        );
    }
}

/// The cells of the first markdown table row after `heading` whose first
/// cell is `label` or starts with `label` and a space.
pub fn table_row<'a>(text: &'a str, heading: &str, label: &str) -> Vec<&'a str> {
    let after = &text[text
        .find(heading)
        .unwrap_or_else(|| panic!("no {heading:?} in\n{text}"))..];
    let line = after
        .lines()
        .find(|l| l.starts_with(&format!("| {label} ")))
        .unwrap_or_else(|| panic!("no row {label:?} after {heading:?} in\n{text}"));
    line.trim_matches('|').split('|').map(str::trim).collect()
}
