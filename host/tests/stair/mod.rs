//! Stair (`tests/c/stair`): an FMI 2.0 Co-Simulation FMU written by hand
//! in C, like the Modelica Reference FMU Stair: an Integer output
//! `counter` one higher every second, a Boolean output `even`, and at the
//! top (counter = 10, t = 9) `fmi2DoStep` returns `fmi2Discard` with
//! `fmi2Terminated` = true. Compiled and zipped into a `.fmu` at test time.
#![allow(dead_code)]

use crate::common::c_fmu;
use std::path::{Path, PathBuf};

/// The folder with `stair.c` and `modelDescription.xml`.
pub const SOURCE_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/c/stair");

/// Compile the C source and zip it with its model description into
/// `dir/Stair.fmu`.
pub fn build_fmu(dir: &Path) -> PathBuf {
    c_fmu(Path::new(SOURCE_DIR), "stair.c", "Stair", dir)
}

/// A system file `dir/stair.ssd` of one component `stair` (Stair.fmu in
/// `dir`), from 0 to 10 s in steps of `step`.
pub fn system_file(dir: &Path, step: f64) -> PathBuf {
    let ssd = dir.join("stair.ssd");
    std::fs::write(
        &ssd,
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="stair"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
  <ssd:System name="stair">
    <ssd:Elements>
      <ssd:Component name="stair" source="Stair.fmu"/>
    </ssd:Elements>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="10">
    <ssd:Annotations>
      <ssc:Annotation type="org.friction-fmu.fricsim">
        <fricsim:Simulation xmlns:fricsim="urn:friction-fmu:fricsim:1" stepSize="{step}"/>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"#
        ),
    )
    .unwrap();
    ssd
}
