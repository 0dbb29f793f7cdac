//! `fricsim diagnose` with a plant that is not Rig1D: BeltOscillator
//! (tests/c/belt_oscillator, a hand-written C FMU: a mass on a moving belt
//! held by a spring) with the repository's LuGre.fmu. Diagnose has no
//! inverse dynamics for it, so every fit goes by output error through
//! co-simulation of the whole system; a viscous term hidden in the data is
//! named and sized. When the nominal system itself cannot be co-simulated
//! (the plant fails at its 500th step, every fallback too), the diagnosis
//! ends with a message naming the time, the component and the call.

use crate::belt;
use crate::common;

use fricsim::diagnose::model::Effect;
use fricsim::diagnose::{diagnose, Options};
use fricsim::master::{by_name, simulate};
use fricsim::ssp::SystemFile;
use std::fmt::Write as _;
use std::path::Path;

/// Communication step of the system (s): the data are every tenth row.
const H: f64 = 1e-4;
const STOP: f64 = 10.0;
/// The viscous coefficient hidden in the data (N·s/m).
const SIGMA2: f64 = 2.0;

/// BeltOscillator + LuGre (σ2 given; the rig failing with `fault` at step
/// `fault_step` when that is not 0), Gauss–Seidel at [`H`].
fn system_file(
    dir: &Path,
    name: &str,
    belt: &Path,
    sigma2: f64,
    fault: (i32, usize),
) -> SystemFile {
    let lugre = common::lugre_fmu();
    let text = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="{name}"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssd:System name="{name}">
    <ssd:Elements>
      <ssd:Component name="rig" source="{belt}">
        <ssd:Connectors>
          <ssd:Connector name="F" kind="input"><ssc:Real unit="N"/></ssd:Connector>
          <ssd:Connector name="v" kind="output"><ssc:Real unit="m/s"/></ssd:Connector>
          <ssd:Connector name="x" kind="output"><ssc:Real unit="m"/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name="rig"><ssv:Parameters>
            <ssv:Parameter name="v0"><ssv:Real value="0"/></ssv:Parameter>
            <ssv:Parameter name="fault"><ssv:Integer value="{fault}"/></ssv:Parameter>
            <ssv:Parameter name="fault_step"><ssv:Integer value="{fault_step}"/></ssv:Parameter>
          </ssv:Parameters></ssv:ParameterSet>
        </ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>
      </ssd:Component>
      <ssd:Component name="friction" source="{lugre}">
        <ssd:Connectors>
          <ssd:Connector name="v" kind="input"><ssc:Real unit="m/s"/></ssd:Connector>
          <ssd:Connector name="x" kind="input"><ssc:Real unit="m"/></ssd:Connector>
          <ssd:Connector name="F" kind="output"><ssc:Real unit="N"/></ssd:Connector>
        </ssd:Connectors>
        <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name="friction"><ssv:Parameters>
            <ssv:Parameter name="sigma2"><ssv:Real value="{sigma2}"/></ssv:Parameter>
          </ssv:Parameters></ssv:ParameterSet>
        </ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="rig" startConnector="v" endElement="friction" endConnector="v"/>
      <ssd:Connection startElement="rig" startConnector="x" endElement="friction" endConnector="x"/>
      <ssd:Connection startElement="friction" startConnector="F" endElement="rig" endConnector="F"/>
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="{STOP}">
    <ssd:Annotations>
      <ssc:Annotation type="org.friction-fmu.fricsim">
        <fricsim:Simulation xmlns:fricsim="urn:friction-fmu:fricsim:1" stepSize="{H}" master="gauss-seidel"/>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"#,
        belt = belt.display(),
        lugre = lugre.display(),
        fault = fault.0,
        fault_step = fault.1,
    );
    let path = dir.join(format!("{name}.ssd"));
    std::fs::write(&path, text).unwrap();
    SystemFile::open(&path).unwrap()
}

/// The truth co-simulated, its position read every 1 ms through a 1 µm
/// encoder: `time,rig.x`.
fn measurements(truth: &SystemFile, out: &Path) {
    let mut system = truth.build(0.0).unwrap();
    let mut master = by_name("gauss-seidel-interpolated").unwrap();
    let run = simulate(&mut system, master.as_mut(), H, STOP).unwrap();
    assert!(run.error.is_none(), "{:?}", run.error);
    let kx = run.columns.iter().position(|c| c == "rig.x").unwrap();
    let mut csv = String::from("time,rig.x\n");
    for (i, row) in run.rows.iter().enumerate().step_by(10) {
        let x = (row[kx] / 1e-6).round() * 1e-6;
        writeln!(csv, "{},{x:e}", run.time[i]).unwrap();
    }
    std::fs::write(out, csv).unwrap();
}

#[test]
fn a_viscous_term_is_found_by_output_error_on_a_plant_that_is_not_rig1d() {
    let dir = tempfile::tempdir().unwrap();
    let belt = belt::build_fmu(dir.path());
    let truth = system_file(dir.path(), "truth", &belt, SIGMA2, (0, 0));
    let nominal = system_file(dir.path(), "nominal", &belt, 0.0, (0, 0));
    let data = dir.path().join("data.csv");
    measurements(&truth, &data);
    let options = Options {
        candidates: vec![Effect::Viscous, Effect::DirectionDependent],
        ..Options::default()
    };
    let d = diagnose(&nominal, &data, None, &options).unwrap();
    assert!(
        d.force_source.starts_with("not estimated"),
        "{}",
        d.force_source
    );
    let names: Vec<Effect> = d.effects.iter().map(|e| e.name).collect();
    assert_eq!(names, [Effect::Viscous], "{:?}", d.rounds);
    let fitted = d.final_model.sigma2;
    assert!(
        (fitted - SIGMA2).abs() <= 0.1 * SIGMA2,
        "sigma2 {fitted} against {SIGMA2}"
    );
    assert!(
        d.final_rms < d.nominal_rms,
        "{} {}",
        d.final_rms,
        d.nominal_rms
    );
    assert!(
        !d.unexplained,
        "final {} floor {}",
        d.final_rms, d.floor_rms
    );
}

#[test]
fn a_nominal_system_that_cannot_run_ends_the_diagnosis_naming_time_component_and_call() {
    let dir = tempfile::tempdir().unwrap();
    let belt = belt::build_fmu(dir.path());
    let truth = system_file(dir.path(), "truth", &belt, SIGMA2, (0, 0));
    let data = dir.path().join("data.csv");
    measurements(&truth, &data);
    // fmi2Error at the plant's 500th fmi2DoStep, whatever the step
    let broken = system_file(dir.path(), "broken", &belt, 0.0, (belt::ERROR, 500));
    let e = diagnose(&broken, &data, None, &Options::default()).unwrap_err();
    for part in [
        "the nominal system as given cannot be co-simulated",
        "fmi2DoStep failed for instance \"rig\"",
        "at t = ",
        "gauss-seidel-interpolated at 0.0001 s",
        "adaptive at 0.0001 s",
    ] {
        assert!(e.contains(part), "`{part}` not in: {e}");
    }
}

/// A co-simulation that does not complete is tried again with a quarter
/// step, then with the other masters, and the first that completes is used
/// and reported: here the system's master cannot even be made (an unknown
/// name), and the strong couplings cannot roll BeltOscillator back (it
/// cannot get and set its state), so the chain ends at Gauss–Seidel.
#[test]
fn a_failed_co_simulation_falls_back_to_the_next_master_and_says_so() {
    use fricsim::diagnose::problem::{Measured, Setup};
    use fricsim::diagnose::sim::{co_simulate_robust, system_parameters};
    let dir = tempfile::tempdir().unwrap();
    let belt = belt::build_fmu(dir.path());
    let truth = system_file(dir.path(), "truth", &belt, SIGMA2, (0, 0));
    let data = dir.path().join("data.csv");
    measurements(&truth, &data);
    let mut system = truth.build(0.0).unwrap();
    let measured = Measured::read(&data, &system).unwrap();
    let setup = Setup::new(&truth, &mut system, 1e-3, "no-such-master").unwrap();
    let params = system_parameters(&truth, &setup, &setup.nominal);
    let (r, note) = co_simulate_robust(&mut system, &params, &setup, &measured, None).unwrap();
    assert!(r.incomplete.is_none());
    assert_eq!(r.samples.len(), measured.time.len());
    let note = note.expect("a fallback was used");
    for part in [
        "no-such-master at 0.001 s: unknown master algorithm `no-such-master`",
        "no-such-master at 0.00025 s",
        "adaptive at 0.001 s: stopped early",
        "canGetAndSetFMUstate",
        "ran with gauss-seidel at 0.00025 s instead",
    ] {
        assert!(note.contains(part), "`{part}` not in: {note}");
    }
    // the rows the fallback gives are the system's: close to the data
    let worst = r.residuals[0].iter().fold(0f64, |a, x| a.max(x.abs()));
    assert!(worst < 1e-3, "largest residual {worst} m");
}
