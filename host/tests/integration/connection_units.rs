//! Units of connections, the same in `run` (SSP files) and `cosim`
//! (System::build): FMI 2.0 and SSP 1.0 leave units optional, so a
//! variable without a unit connects to any unit, with a warning naming
//! both sides; two different declared units are refused, naming both
//! (fricsim does not convert units). Before, `run` refused a unitless
//! output driving an input with a unit (no third-party FMU without units
//! could drive ours from an SSP file), and `cosim` checked no units at all.

use crate::common;
use common::assert_message;
use fricsim::ssp::SystemFile;
use fricsim::system::System;
use std::path::{Path, PathBuf};

/// `dist/Rig1D.fmu` with no unit on its output `v`, as `dir/Unitless.fmu`.
fn rig_without_velocity_unit(dir: &Path) -> PathBuf {
    common::repacked("Rig1D", &dir.join("Unitless.fmu"), |text| {
        let at = text
            .find("<ScalarVariable name=\"v\"")
            .expect("Rig1D has v");
        let unit = at + text[at..].find("<Real unit=\"m/s\"/>").unwrap();
        format!("{}<Real/>{}", &text[..unit], &text[unit + 18..])
    })
}

fn ssd(rig: &Path, rig_v_connector: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="units"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
  <ssd:System name="units">
    <ssd:Elements>
      <ssd:Component name="rig" source="{rig}">
        <ssd:Connectors>
          <ssd:Connector name="F" kind="input"><ssc:Real unit="N"/></ssd:Connector>
          {rig_v_connector}
        </ssd:Connectors>
      </ssd:Component>
      <ssd:Component name="friction" source="{lugre}">
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
</ssd:SystemStructureDescription>
"#,
        rig = rig.display(),
        lugre = common::lugre_fmu().display(),
    )
}

#[test]
fn a_unitless_output_drives_an_input_with_a_unit_with_a_warning_in_run() {
    let dir = tempfile::tempdir().unwrap();
    let rig = rig_without_velocity_unit(dir.path());
    let path = dir.path().join("units.ssd");
    std::fs::write(
        &path,
        ssd(
            &rig,
            r#"<ssd:Connector name="v" kind="output"><ssc:Real/></ssd:Connector>"#,
        ),
    )
    .unwrap();
    let system = SystemFile::open(&path).unwrap().build(0.0).unwrap();
    assert_eq!(system.warnings().len(), 1, "{:?}", system.warnings());
    assert_message(
        &system.warnings()[0],
        &[
            "connection rig.v -> friction.v",
            "`rig.v` declares no unit",
            "`m/s`",
        ],
    );

    // The command says it on stderr and runs.
    let out = dir.path().join("out.csv");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_fricsim"))
        .args(["run", "-q", "--stop", "0.01", "--step", "1e-3", "--out"])
        .arg(&out)
        .arg(&path)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: connection rig.v -> friction.v: `rig.v` declares no unit"),
        "{stderr}"
    );
    assert!(out.exists());
}

#[test]
fn cosim_checks_units_as_run_does() {
    let dir = tempfile::tempdir().unwrap();
    let rig = common::repository().join("dist/Rig1D.fmu");
    let lugre = common::lugre_fmu();
    let components = [
        ("rig".to_string(), rig.as_path()),
        ("friction".to_string(), lugre.as_path()),
    ];
    // rig.x (m) into friction.v (m/s): refused, both units named
    let err = System::build(
        &components,
        &[],
        &[
            ("rig.x".into(), "friction.v".into()),
            ("friction.F".into(), "rig.F".into()),
        ],
    )
    .err()
    .expect("m into m/s is refused");
    assert_message(
        &err,
        &[
            "connection rig.x -> friction.v",
            "unit mismatch",
            "`rig.x` has unit `m`",
            "`friction.v` has unit `m/s`",
        ],
    );
    // The same units connect without a word; a unitless side with a warning.
    let same = System::build(
        &components,
        &[],
        &[
            ("rig.v".into(), "friction.v".into()),
            ("friction.F".into(), "rig.F".into()),
        ],
    )
    .unwrap();
    assert!(same.warnings().is_empty(), "{:?}", same.warnings());
    let unitless = rig_without_velocity_unit(dir.path());
    let components = [
        ("rig".to_string(), unitless.as_path()),
        ("friction".to_string(), lugre.as_path()),
    ];
    let system = System::build(
        &components,
        &[],
        &[
            ("rig.v".into(), "friction.v".into()),
            ("friction.F".into(), "rig.F".into()),
        ],
    )
    .unwrap();
    assert_eq!(system.warnings().len(), 1, "{:?}", system.warnings());
}
