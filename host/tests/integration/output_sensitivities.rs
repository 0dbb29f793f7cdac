//! The output sensitivities the output-error fits of `fricsim diagnose`
//! take their Jacobian from (`fricsim::diagnose::tangent`): carried along
//! one co-simulation of the two-mass drive of the tests (TwoMassDrive, a
//! hand-written C FMU that lists its states and gives their partial
//! derivatives) with LuGre.fmu on the load, against central differences of
//! whole co-simulations, for every kind of parameter a diagnosis frees:
//! the levels, the Stribeck curve, the bristle stiffness, the viscous
//! coefficient, the levels by direction and the position table; the same
//! on the servo axis of the tests and on Rig1D (a spring the data pull,
//! and its own controller). And what the sensitivities do not cover says
//! why: a plant that lists no states, one that is not linear.

use crate::common;
use fricsim::diagnose::model::FrictionModel;
use fricsim::diagnose::problem::Measured;
use fricsim::diagnose::sim::{run_on, system_parameters_with};
use fricsim::diagnose::tangent::Coupling;
use fricsim::fmu::model_description::VariableKind;
use fricsim::master::Run;
use fricsim::ssp::SystemFile;
use fricsim::system::ParameterValue;
use std::path::{Path, PathBuf};

/// Macro step (s) and length (s) of the co-simulations.
const H: f64 = 1e-3;
const STOP: f64 = 3.0;

/// Where a plant's FMU comes from: a C folder of host/tests/c compiled
/// for the test (folder, identifier), or a shipped FMU of dist/.
enum PlantFmu {
    C(&'static str, &'static str),
    Shipped(&'static str),
}

/// A plant of the tests: its FMU, its name in messages, the inputs the
/// data drive (each the signal of [`signal`] or, `true`, its rate), the
/// scale of that signal, its outputs connected (the first the law's `v`,
/// the second its `x`), the channels compared, and its parameters as
/// system-file values (`<ssv:Real value=…/>` and the like).
struct Plant {
    fmu: PlantFmu,
    name: &'static str,
    inputs: &'static [(&'static str, bool)],
    amplitude: f64,
    outputs: &'static [&'static str],
    channels: &'static [&'static str],
    parameters: &'static [(&'static str, &'static str)],
}

/// TwoMassDrive: the motor force u from the data; it holds its inputs
/// over each step.
const TWO_MASS: Plant = Plant {
    fmu: PlantFmu::C("two_mass_drive", "TwoMassDrive"),
    name: "TwoMassDrive",
    inputs: &[("u", false)],
    amplitude: 1.0,
    outputs: &["v", "x_l", "x_m", "a"],
    channels: &["x_m", "x_l", "a"],
    parameters: &[],
};

/// ServoAxis: a PD position loop on the motor, its reference r from the
/// data (a few millimetres; its gain 4000 N/m), the controller's force u
/// an output; it interpolates its inputs, so that under
/// `newton-interpolated` the friction force ramps over each step.
const SERVO: Plant = Plant {
    fmu: PlantFmu::C("servo_axis", "ServoAxis"),
    name: "ServoAxis",
    inputs: &[("r", false)],
    amplitude: 1e-3,
    outputs: &["v", "x_l", "x_m", "a", "u"],
    channels: &["x_m", "x_l", "a", "u"],
    parameters: &[],
};

/// Rig1D as the diagnosis's Rig1D cases have it: a mass on a spring whose
/// far end the data move (`actuator` = 1, `x_act_in`), a few millimetres
/// against k = 2000 N/m; it interpolates its inputs and steps exactly.
const RIG_SPRING: Plant = Plant {
    fmu: PlantFmu::Shipped("Rig1D.fmu"),
    name: "Rig1D (spring)",
    inputs: &[("x_act_in", false)],
    amplitude: 1e-3,
    outputs: &["v", "x", "a", "F_spring"],
    channels: &["x", "a", "F_spring"],
    parameters: &[
        ("m", r#"<ssv:Real value="1.0"/>"#),
        ("k", r#"<ssv:Real value="2000.0"/>"#),
        ("actuator", r#"<ssv:Integer value="1"/>"#),
    ],
};

/// Rig1D driven by its controller on a reference from the data
/// (`control` = 2: x_ref and v_ref = its rate), u = Kp·(x_ref − x) +
/// Kd·(v_ref − ẋ) + Ki·ξ with the integral ξ of the velocity error (a
/// function of the position: ξ = ∫v_ref dt − (x − x0)), unsaturated;
/// stepped by sub-stepped Gauss–Legendre.
const RIG_LOOP: Plant = Plant {
    fmu: PlantFmu::Shipped("Rig1D.fmu"),
    name: "Rig1D (loop)",
    inputs: &[("x_ref", false), ("v_ref", true)],
    amplitude: 1e-3,
    outputs: &["v", "x", "a", "u_ctrl"],
    channels: &["x", "a", "u_ctrl"],
    parameters: LOOP_PARAMETERS,
};

const LOOP_PARAMETERS: &[(&str, &str)] = &[
    ("m", r#"<ssv:Real value="1.0"/>"#),
    ("k", r#"<ssv:Real value="0.0"/>"#),
    ("control", r#"<ssv:Integer value="2"/>"#),
    ("ctrl_kp", r#"<ssv:Real value="4000.0"/>"#),
    ("ctrl_kd", r#"<ssv:Real value="60.0"/>"#),
    ("ctrl_ki", r#"<ssv:Real value="20000.0"/>"#),
    ("ctrl_ff", r#"<ssv:Real value="1.0"/>"#),
    ("ctrl_gain", r#"<ssv:Real value="1.0"/>"#),
];

/// The data's input signal at `t` and its rate: a sum of two sines that
/// makes the load stick, slip both ways and reverse.
fn signal(amplitude: f64, t: f64) -> (f64, f64) {
    let w = |f: f64| 2.0 * std::f64::consts::PI * f;
    (
        amplitude * (3.0 * (w(0.7) * t).sin() + 0.8 * (w(2.3) * t).sin()),
        amplitude * (3.0 * w(0.7) * (w(0.7) * t).cos() + 0.8 * w(2.3) * (w(2.3) * t).cos()),
    )
}

/// `plant` with LuGre on its first output's contact, connected v, x and
/// F, Newton at [`H`]; the data: the plant's inputs from [`signal`], and
/// the channels compared (their values do not matter here).
fn system(dir: &Path, plant: &Plant) -> (SystemFile, PathBuf) {
    let fmu = match plant.fmu {
        PlantFmu::C(folder, identifier) => common::c_fmu(
            &common::repository().join("host/tests/c").join(folder),
            &format!("{folder}.c"),
            identifier,
            dir,
        ),
        PlantFmu::Shipped(file) => common::repository().join("dist").join(file),
    };
    let lugre = common::lugre_fmu();
    let ssd = dir.join("plant.ssd");
    let connectors: String = plant
        .inputs
        .iter()
        .map(|(n, _)| (*n, "input"))
        .chain([("F", "input")])
        .chain(plant.outputs.iter().map(|o| (*o, "output")))
        .map(|(n, kind)| {
            format!(r#"<ssd:Connector name="{n}" kind="{kind}"><ssc:Real/></ssd:Connector>"#)
        })
        .collect();
    let parameters = if plant.parameters.is_empty() {
        String::new()
    } else {
        let values: String = plant
            .parameters
            .iter()
            .map(|(n, v)| format!(r#"<ssv:Parameter name="{n}">{v}</ssv:Parameter>"#))
            .collect();
        format!(
            r#"<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" name="drive"><ssv:Parameters>{values}</ssv:Parameters></ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>"#
        )
    };
    let (v, x) = (plant.outputs[0], plant.outputs[1]);
    std::fs::write(
        &ssd,
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="plant"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues">
  <ssd:System name="plant">
    <ssd:Elements>
      <ssd:Component name="drive" source="{}">
        <ssd:Connectors>{connectors}</ssd:Connectors>
        {parameters}
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
      <ssd:Connection startElement="drive" startConnector="{v}" endElement="friction" endConnector="v"/>
      <ssd:Connection startElement="drive" startConnector="{x}" endElement="friction" endConnector="x"/>
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
    let mut text = String::from("time");
    for (name, _) in plant.inputs {
        text.push_str(&format!(",drive.{name}"));
    }
    for channel in plant.channels {
        text.push_str(&format!(",drive.{channel}"));
    }
    text.push_str(",friction.F\n");
    let n = (STOP / H).round() as usize;
    for k in 0..=n {
        let t = k as f64 * H;
        let (value, rate) = signal(plant.amplitude, t);
        text.push_str(&format!("{t:?}"));
        for (_, is_rate) in plant.inputs {
            text.push_str(&format!(",{:?}", if *is_rate { rate } else { value }));
        }
        // channels: anything smooth (their values are not compared here)
        for _ in 0..=plant.channels.len() {
            text.push_str(&format!(",{:?}", 1e-3 * t));
        }
        text.push('\n');
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
    let v = series(&run, &format!("drive.{}", plant.outputs[0]));
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
    let channels: Vec<String> = plant
        .channels
        .iter()
        .map(|c| format!("drive.{c}"))
        .chain(["friction.F".to_string()])
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
            println!("{} {master}: ∂{channel}/∂{name}: carried off by {closest:.2e} of the differences' size", plant.name);
            assert!(
                closest <= tolerance,
                "{} {master}: ∂{channel}/∂{name}: carried off by {closest:.3e} of the differences' size",
                plant.name
            );
        }
    }
}

/// Rig1D lists its states too (the position and the body velocity, with
/// their continuous-time partial derivatives): the diagnosis's Rig1D
/// cases, a mass on a spring whose far end the data move, carry their
/// output sensitivities, under both masters (Rig1D interpolates its
/// inputs; it steps exactly here).
#[test]
fn carried_sensitivities_equal_central_differences_on_rig1d() {
    sensitivities_against_differences(&RIG_SPRING, "newton-interpolated", &[1e-4, 1e-5], 3e-3);
    sensitivities_against_differences(&RIG_SPRING, "newton", &[1e-4], 1e-4);
}

/// Rig1D under its own controller (PD on the position, PI on the
/// velocity), whose integral is a function of the position: the command
/// is a channel.
#[test]
fn carried_sensitivities_equal_central_differences_on_rig1d_with_its_controller() {
    sensitivities_against_differences(&RIG_LOOP, "newton-interpolated", &[1e-4, 1e-5], 3e-3);
}

/// The Jacobi master (the one EMPS's system file asks for): explicit,
/// each component stepping on the other's outputs at the step's start,
/// held. The co-simulation's differences at a relative step of 1e-4 move
/// with the step on the two-mass drive (its acceleration, through the
/// force, 6.7e-3 off for Fc); the closest of 1e-4, 1e-5 and 1e-6 agrees
/// within 1e-5 of each column's size (measured: 4.4e-7 or better).
#[test]
fn carried_sensitivities_equal_central_differences_under_jacobi() {
    sensitivities_against_differences(&TWO_MASS, "jacobi", &[1e-4, 1e-5, 1e-6], 1e-5);
    sensitivities_against_differences(&RIG_LOOP, "jacobi", &[1e-4, 1e-5, 1e-6], 1e-5);
}

/// The plant's step gain from its continuous-time partial derivatives
/// (`C·Γ + d`, through the matrix exponential) equals the step
/// sensitivity the FMU itself gives right after a step: two routes to one
/// number, within the error of the plant's own integration (TwoMassDrive:
/// RK4 sub-steps of 1e-4 s run on a unit input; Rig1D: its exact step,
/// or, under the controller, sub-stepped Gauss–Legendre, differenced by
/// the FMU's replay of the step).
#[test]
fn the_linearization_agrees_with_the_plants_own_step_sensitivity() {
    for plant in [&TWO_MASS, &RIG_SPRING, &RIG_LOOP] {
        linearization_against_step_sensitivity(plant);
    }
}

fn linearization_against_step_sensitivity(plant: &Plant) {
    let dir = tempfile::tempdir().unwrap();
    let (file, _) = system(dir.path(), plant);
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
    let vr = |n: &str| drive.fmu.variable(n).unwrap().value_reference;
    for (name, value) in &base {
        if let Some(p) = name.strip_prefix("drive.") {
            let ParameterValue::Number(x) = value else {
                unreachable!("no text parameters here")
            };
            match drive.fmu.variable(p).unwrap().kind {
                VariableKind::Real { .. } => instance.set_real(&[vr(p)], &[*x]),
                _ => instance.set_integer(&[vr(p)], &[*x as i32]),
            }
            .unwrap();
        }
    }
    instance.enter_initialization_mode().unwrap();
    instance.exit_initialization_mode().unwrap();
    instance.set_real(&[vr("F")], &[0.5]).unwrap();
    instance.do_step(0.0, H).unwrap();
    for output in plant.outputs {
        let mut own = [0.0];
        instance
            .get_directional_derivative(&[vr(output)], &[vr("F")], &[1.0], &mut own)
            .unwrap();
        let gain = coupling.step_gain(H, output).unwrap();
        println!(
            "{} {output}: {gain:e} from the partial derivatives, {:e} from the FMU",
            plant.name, own[0]
        );
        assert!(
            (gain - own[0]).abs() <= 1e-5 * own[0].abs().max(1e-12),
            "{} {output}: {gain:e} from the partial derivatives, {:e} from the FMU",
            plant.name,
            own[0]
        );
    }
}

/// The check that the plant is linear and time-invariant refuses one
/// that is not: Rig1D whose controller saturates (|u| ≤ 0.1 N, reached
/// for a few steps along the data's reference): its partial derivatives
/// change where the command saturates, so its sensitivities are
/// differenced, and the coupling says why.
#[test]
fn a_plant_whose_partial_derivatives_move_is_not_covered() {
    let parameters: Vec<(&str, &str)> = LOOP_PARAMETERS
        .iter()
        .copied()
        .chain([("ctrl_u_max", r#"<ssv:Real value="0.1"/>"#)])
        .collect();
    let saturating = Plant {
        name: "Rig1D (saturating loop)",
        parameters: Box::leak(parameters.into_boxed_slice()),
        ..RIG_LOOP
    };
    let dir = tempfile::tempdir().unwrap();
    let (file, data_path) = system(dir.path(), &saturating);
    let system = file.build(0.0).unwrap();
    let data = Measured::read(&data_path, &system).unwrap();
    let base = system_parameters_with(&file, "friction", model().parameters());
    let friction = 1;
    // at its start (before any input) the loop is linear: the same plant
    // with no data is covered
    Coupling::new(&system, friction, &base, (&[], &[])).unwrap();
    let why = Coupling::new(&system, friction, &base, (&data.time, &data.inputs))
        .err()
        .unwrap();
    assert!(why.contains("is not linear and time-invariant"), "{why}");
}

/// A plant that lists no continuous states (BeltOscillator of the tests):
/// its output sensitivities are not carried, and the coupling says so
/// (the fits difference).
#[test]
fn a_plant_without_states_is_not_covered_and_says_why() {
    const BELT: Plant = Plant {
        fmu: PlantFmu::C("belt_oscillator", "BeltOscillator"),
        name: "BeltOscillator",
        inputs: &[],
        amplitude: 0.0,
        outputs: &["v", "x", "a"],
        channels: &["x"],
        parameters: &[],
    };
    let dir = tempfile::tempdir().unwrap();
    let (file, _) = system(dir.path(), &BELT);
    let system = file.build(0.0).unwrap();
    let why = Coupling::new(&system, 1, &[], (&[], &[])).err().unwrap();
    assert!(why.contains("lists no continuous states"), "{why}");
}
