//! The output sensitivities the output-error fits of `fricsim diagnose`
//! take their Jacobian from (`fricsim::diagnose::tangent`): carried along
//! one co-simulation of the two-mass drive of the tests (TwoMassDrive, a
//! hand-written C FMU that lists its states and gives their partial
//! derivatives) with LuGre.fmu on the load, against central differences of
//! whole co-simulations, for every kind of parameter a diagnosis frees:
//! the levels, the Stribeck curve, the bristle stiffness, the viscous
//! coefficient, the levels by direction and the position table. And what
//! the sensitivities do not cover says why: Rig1D lists no states.

use crate::common;
use fricsim::diagnose::model::FrictionModel;
use fricsim::diagnose::problem::Measured;
use fricsim::diagnose::sim::{run_on, system_parameters_with};
use fricsim::diagnose::tangent::Coupling;
use fricsim::master::Run;
use fricsim::ssp::SystemFile;
use std::path::{Path, PathBuf};

/// Macro step (s) and length (s) of the co-simulations.
const H: f64 = 1e-3;
const STOP: f64 = 3.0;

/// A plant of the tests: its folder, C file, identifier, the input the
/// data drive, its outputs compared.
struct Plant {
    folder: &'static str,
    identifier: &'static str,
    input: &'static str,
    outputs: &'static [&'static str],
}

/// TwoMassDrive: the motor force u from the data; it holds its inputs
/// over each step.
const TWO_MASS: Plant = Plant {
    folder: "two_mass_drive",
    identifier: "TwoMassDrive",
    input: "u",
    outputs: &["x_m", "x_l", "v", "a"],
};

/// ServoAxis: a PD position loop on the motor, its reference r from the
/// data, the controller's force u an output; it interpolates its inputs,
/// so that under `newton-interpolated` the friction force ramps over each
/// step.
const SERVO: Plant = Plant {
    folder: "servo_axis",
    identifier: "ServoAxis",
    input: "r",
    outputs: &["x_m", "x_l", "v", "a", "u"],
};

/// `plant` with LuGre on the load, connected v, x_l and F, Newton at
/// [`H`]; the data: the plant's input a sum of two sines that makes the
/// load stick, slip both ways and reverse, and the channels compared
/// (x_m, x_l, a, friction.F; their values do not matter here).
fn system(dir: &Path, plant: &Plant) -> (SystemFile, PathBuf) {
    let fmu = common::c_fmu(
        &common::repository().join("host/tests/c").join(plant.folder),
        &format!("{}.c", plant.folder),
        plant.identifier,
        dir,
    );
    let lugre = common::lugre_fmu();
    let ssd = dir.join("plant.ssd");
    let connectors: String = [(plant.input, "input"), ("F", "input")]
        .into_iter()
        .chain(plant.outputs.iter().map(|o| (*o, "output")))
        .map(|(n, kind)| {
            format!(r#"<ssd:Connector name="{n}" kind="{kind}"><ssc:Real/></ssd:Connector>"#)
        })
        .collect();
    std::fs::write(
        &ssd,
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="plant"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
  <ssd:System name="plant">
    <ssd:Elements>
      <ssd:Component name="drive" source="{}">
        <ssd:Connectors>{connectors}</ssd:Connectors>
      </ssd:Component>
      <ssd:Component name="friction" source="{}">
        <ssd:Connectors>
          <ssd:Connector name="v" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="x" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="F" kind="output"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="drive" startConnector="v" endElement="friction" endConnector="v"/>
      <ssd:Connection startElement="drive" startConnector="x_l" endElement="friction" endConnector="x"/>
      <ssd:Connection startElement="friction" startConnector="F" endElement="drive" endConnector="F"/>
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="{STOP}">
    <ssd:Annotations>
      <ssc:Annotation type="org.friction-fmu.fricsim">
        <fricsim:Simulation xmlns:fricsim="urn:friction-fmu:fricsim:1" stepSize="{H}" master="newton"/>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"#,
            fmu.display(),
            lugre.display()
        ),
    )
    .unwrap();
    let data = dir.join("data.csv");
    let mut text = format!(
        "time,drive.{},drive.x_m,drive.x_l,drive.a,friction.F\n",
        plant.input
    );
    // a force of a few newtons on the motor, or a reference of a few
    // millimetres for the servo loop (its gain 4000 N/m)
    let amplitude = if plant.input == "r" { 1e-3 } else { 1.0 };
    let n = (STOP / H).round() as usize;
    for k in 0..=n {
        let t = k as f64 * H;
        let u = amplitude
            * (3.0 * (2.0 * std::f64::consts::PI * 0.7 * t).sin()
                + 0.8 * (2.0 * std::f64::consts::PI * 2.3 * t).sin());
        // channels: anything smooth (their values are not compared here)
        text.push_str(&format!("{t:?},{u:?},{:?},{:?},0,0\n", 1e-3 * t, 1e-3 * t));
    }
    std::fs::write(&data, text).unwrap();
    (SystemFile::open(&ssd).unwrap(), data)
}

/// LuGre with every kind of parameter a diagnosis frees in use: a
/// Stribeck peak, viscous friction, levels by direction and a position
/// table over the travel.
fn model() -> FrictionModel {
    FrictionModel {
        fc: 1.0,
        fs: 1.4,
        vs: 5e-3,
        stribeck_exponent: 2.0,
        sigma0: 2e4,
        sigma1: 2.0 * (2e4_f64 * 2.0).sqrt(),
        sigma2: 3.0,
        fc_neg: 0.9,
        fs_neg: 1.3,
        direction_dependent: true,
        normal_force_form: false,
        position_dependent: true,
        f_offset: 0.0,
        direction_dependent_viscous: false,
        sigma2_neg: 3.0,
        x_table: vec![-0.05, -0.01, 0.03, 0.07],
        scale_pos: vec![1.0, 1.1, 0.9, 1.05],
        scale_neg: vec![1.0, 0.95, 1.1, 1.0],
        freed: Default::default(),
    }
}

/// The recorded series `name` of `run`.
fn series(run: &Run, name: &str) -> Vec<f64> {
    let k = run.columns.iter().position(|c| c == name).unwrap();
    run.rows.iter().map(|r| r[k]).collect()
}

/// `model` with its FMU parameter `name` multiplied by `factor`.
fn with(model: &FrictionModel, name: &str, factor: f64) -> Vec<(String, f64)> {
    model
        .parameters()
        .into_iter()
        .map(|(n, v)| if n == name { (n, v * factor) } else { (n, v) })
        .collect()
}

/// Held inputs (`newton`): every step of the law is its exact held
/// update, and the co-simulation is smooth in the parameters at the scale
/// of the differences: they agree to 1e-4 of each column's size
/// (measured: 2e-5 or better).
#[test]
fn carried_sensitivities_equal_central_differences_held_inputs() {
    sensitivities_against_differences(&TWO_MASS, "newton", &[1e-4], 1e-4);
}

/// The diagnosis's own master (`newton-interpolated`): the law, which
/// interpolates its inputs, takes v and x as ramps over each step, and
/// the two-mass drive, which does not, holds the force. The
/// co-simulation is rougher in the parameters here: its differences at
/// a relative step of 1e-4 still move with the step for the levels
/// (stick-slip events that shift by a step; up to 9 % off on the force),
/// at 1e-5 the master's tolerance shows (up to 8e-3 off on vs): the
/// carried column agrees to 3e-3 of its size with the closer of the two
/// (measured: 9e-4 or better).
#[test]
fn carried_sensitivities_equal_central_differences_ramped_inputs() {
    sensitivities_against_differences(&TWO_MASS, "newton-interpolated", &[1e-4, 1e-5], 3e-3);
}

/// The servo axis interpolates its inputs too: the friction force ramps
/// over each step into it as well (the plant's response to both ends of
/// the ramp, `Γ₀` and `Γ₁`), and its controller's force is a channel.
#[test]
fn carried_sensitivities_equal_central_differences_on_a_servo_axis() {
    sensitivities_against_differences(&SERVO, "newton-interpolated", &[1e-4, 1e-5], 3e-3);
    sensitivities_against_differences(&SERVO, "newton", &[1e-4], 1e-4);
}

/// Every parameter's sensitivity of every channel, carried along one
/// co-simulation with `master`, against central differences of whole
/// co-simulations at each relative step of `steps`: the closest within
/// `tolerance` of the column's size.
fn sensitivities_against_differences(plant: &Plant, master: &str, steps: &[f64], tolerance: f64) {
    let dir = tempfile::tempdir().unwrap();
    let (file, data_path) = system(dir.path(), plant);
    let mut system = file.build(0.0).unwrap();
    let data = Measured::read(&data_path, &system).unwrap();
    let model = model();
    let friction = system
        .components
        .iter()
        .position(|c| c.name == "friction")
        .unwrap();
    let base = system_parameters_with(&file, "friction", model.parameters());
    let coupling = Coupling::new(&system, friction, &base, (&data.time, &data.inputs)).unwrap();
    // as the diagnosis runs it: each step's Newton Jacobian reused
    let run = run_on(&mut system, &base, &data, master, H, true).unwrap();
    assert!(run.error.is_none(), "{:?}", run.error);
    // the load sticks, slips and reverses in this run
    let v = series(&run, "drive.v");
    let reversals = v.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
    assert!(reversals >= 2, "{reversals} reversals");
    let parameters = [
        "Fc",
        "Fs",
        "vs",
        "sigma0",
        "sigma1",
        "sigma2",
        "Fc_neg",
        "Fs_neg",
        "scale_pos[2]",
        "scale_neg[3]",
    ]
    .map(String::from);
    let channels: Vec<String> = ["drive.x_m", "drive.x_l", "drive.a", "friction.F"]
        .into_iter()
        .chain(
            plant
                .outputs
                .iter()
                .copied()
                .filter(|o| *o == "u")
                .map(|_| "drive.u"),
        )
        .map(String::from)
        .collect();
    let carried = coupling
        .sensitivities((&run, master), &model.parameters(), &parameters, &channels)
        .unwrap();
    for (j, name) in parameters.iter().enumerate() {
        let value = model
            .parameters()
            .into_iter()
            .find(|(n, _)| n == name)
            .unwrap()
            .1;
        // per step: the differenced series of each channel
        let differenced: Vec<Vec<Vec<f64>>> = steps
            .iter()
            .map(|&eps| {
                let mut runs = Vec::new();
                for factor in [1.0 + eps, 1.0 - eps] {
                    let p = system_parameters_with(&file, "friction", with(&model, name, factor));
                    let r = run_on(&mut system, &p, &data, master, H, true).unwrap();
                    assert!(r.error.is_none());
                    runs.push(r);
                }
                channels
                    .iter()
                    .map(|channel| {
                        let (up, down) = (series(&runs[0], channel), series(&runs[1], channel));
                        up.iter()
                            .zip(&down)
                            .map(|(u, d)| (u - d) / (2.0 * eps * value))
                            .collect()
                    })
                    .collect()
            })
            .collect();
        for (c, channel) in channels.iter().enumerate() {
            let column = carried[c].column(j);
            let mut closest = f64::INFINITY;
            for by_step in &differenced {
                let d = &by_step[c];
                let size = d.iter().map(|x| x * x).sum::<f64>().sqrt();
                assert!(size > 0.0, "{channel} does not move with {name}");
                let off = d
                    .iter()
                    .zip(column.iter())
                    .map(|(d, s)| (d - s) * (d - s))
                    .sum::<f64>()
                    .sqrt();
                closest = closest.min(off / size);
            }
            println!("{} {master}: ∂{channel}/∂{name}: carried off by {closest:.2e} of the differences' size", plant.identifier);
            assert!(
                closest <= tolerance,
                "{} {master}: ∂{channel}/∂{name}: carried off by {closest:.3e} of the differences' size",
                plant.identifier
            );
        }
    }
}

/// The plant's step gain from its continuous-time partial derivatives
/// (`C·Γ + d`, through the matrix exponential) equals the step
/// sensitivity the FMU itself gives right after a step (its RK4
/// sub-steps run on a unit input): two routes to one number, within the
/// RK4's error.
#[test]
fn the_linearization_agrees_with_the_plants_own_step_sensitivity() {
    let dir = tempfile::tempdir().unwrap();
    let (file, _) = system(dir.path(), &TWO_MASS);
    let system = file.build(0.0).unwrap();
    let friction = system
        .components
        .iter()
        .position(|c| c.name == "friction")
        .unwrap();
    let base = system_parameters_with(&file, "friction", model().parameters());
    let coupling = Coupling::new(&system, friction, &base, (&[], &[])).unwrap();
    let drive = &system.components[1 - friction];
    let mut instance = drive.fmu.instantiate("step-gain").unwrap();
    instance.setup_experiment(0.0, None).unwrap();
    instance.enter_initialization_mode().unwrap();
    instance.exit_initialization_mode().unwrap();
    let vr = |n: &str| drive.fmu.variable(n).unwrap().value_reference;
    instance.set_real(&[vr("F")], &[0.5]).unwrap();
    instance.do_step(0.0, H).unwrap();
    for output in ["x_m", "x_l", "v", "a"] {
        let mut own = [0.0];
        instance
            .get_directional_derivative(&[vr(output)], &[vr("F")], &[1.0], &mut own)
            .unwrap();
        let gain = coupling.step_gain(H, output).unwrap();
        println!(
            "{output}: {gain:e} from the partial derivatives, {:e} from the FMU",
            own[0]
        );
        // the FMU's RK4 (sub-steps of 1e-4 s) against the exact exponential
        assert!(
            (gain - own[0]).abs() <= 1e-5 * own[0].abs(),
            "{output}: {gain:e} from the partial derivatives, {:e} from the FMU",
            own[0]
        );
    }
}

/// Rig1D lists no continuous states: its output sensitivities are not
/// carried, and the coupling says so (the fits difference).
#[test]
fn a_plant_without_states_is_not_covered_and_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let ssd = dir.path().join("rig.ssd");
    std::fs::write(
        &ssd,
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="rig"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
  <ssd:System name="rig">
    <ssd:Elements>
      <ssd:Component name="rig" source="{}">
        <ssd:Connectors>
          <ssd:Connector name="F" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="v" kind="output"><ssc:Real/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
      <ssd:Component name="friction" source="{}">
        <ssd:Connectors>
          <ssd:Connector name="v" kind="input"><ssc:Real/></ssd:Connector>
          <ssd:Connector name="F" kind="output"><ssc:Real/></ssd:Connector>
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
            common::repository().join("dist/Rig1D.fmu").display(),
            common::lugre_fmu().display()
        ),
    )
    .unwrap();
    let file = SystemFile::open(&ssd).unwrap();
    let system = file.build(0.0).unwrap();
    let why = Coupling::new(&system, 1, &[], (&[], &[])).err().unwrap();
    assert!(why.contains("lists no continuous states"), "{why}");
}
