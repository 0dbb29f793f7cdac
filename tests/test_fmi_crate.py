"""Our FMUs through the Rust `fmi` crate's importer (fmi-rs) equal FMPy
driving them the same way, bit for bit: LuGre and Dahl in several
parameter sets, and the other five FMUs once each.

`fmi-crate-drive` (tests/fmi-crate/, built by scripts/setup-fmi-crate.sh)
unpacks the FMU, parses its model description and loads its binary with the
crate (`fmi::import::from_path`, `Fmi2Import::instantiate_cs`), sets the
parameters by the types the crate read, sets up the experiment with a stop
time and steps through a prescribed input table (held inputs: the crate's
CS interface has no fmi2SetRealInputDerivatives). The same calls in the
same order with the same doubles go through FMPy's `FMU2Slave`: the outputs
must be the same doubles, every Integer and Boolean output the same, and
the output columns the ones FMPy reads from the model description, in the
same order. Both importers must also see a step past the stop time refused
(FMI 2.0 §2.1.6)."""

import math
import subprocess

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

import shipped
from conftest import ROOT, fmu_path

DRIVE = ROOT / "target" / "fmi-crate" / "debug" / "fmi-crate-drive"
H = 1e-3
N = 3000  # 3 s: two and a half periods of the velocity below

# The signals, one value per communication point: a velocity
# 0.01·sin(2π·0.8 t) m/s with a pause around t = 1.25 s (v = 0 for 0.1 s:
# the law sticks) and a slow stretch (|v| below the Stribeck velocity of
# LuGre's defaults); the position, its running sum; a normal force swinging
# about 1 N; a second velocity for the 2-D law; a force for the rigs.
def drive_table():
    rows = []
    x = 0.0
    for n in range(N + 1):
        t = n * H
        v = 0.0 if 1.2 <= t < 1.3 else 0.01 * math.sin(2 * math.pi * 0.8 * t)
        if 2.2 <= t < 2.5:
            v *= 0.05
        rows.append({"time": t, "v": v, "x": x, "Fn": 1.0 + 0.3 * math.sin(2 * math.pi * 0.5 * t),
                     "v_cos": 0.006 * math.cos(2 * math.pi * 0.8 * t), "force": 0.5 * math.sin(2 * math.pi * t)})
        x += v * H
    return rows


# case: (FMU, {input: signal}, parameters)
CASES = {
    "Dahl": ("Dahl", {"v": "v"}, {}),
    "Dahl_alpha2": ("Dahl", {"v": "v"}, {"alpha": 2.0, "Fc": 1.5, "sigma": 2.0e5}),
    "LuGre": ("LuGre", {"v": "v"}, {}),
    # every option of the law at once: Stribeck exponent, micro-damping
    # decay, levels by direction, the normal-force form (input Fn) and the
    # position table (input x, an Integer and Real table entries)
    "LuGre_all_options": ("LuGre", {"v": "v", "x": "x", "Fn": "Fn"}, {
        "stribeck_exponent": 1.4, "vd": 0.004, "direction_dependent": True, "Fc_neg": 0.8,
        "Fs_neg": 1.2, "normal_force_form": True, "position_dependent": True, "n_table": 3,
        "x_table[1]": 0.0, "x_table[2]": 0.002, "x_table[3]": 0.004,
        "scale_pos[1]": 1.0, "scale_pos[2]": 1.4, "scale_pos[3]": 0.7,
        "scale_neg[1]": 0.9, "scale_neg[2]": 1.2, "scale_neg[3]": 1.0}),
    "ResetIntegrator": ("ResetIntegrator", {"v": "v"}, {}),
    "Bristle": ("Bristle", {"x": "x"}, {"seed": 7}),
    "Bristle2D": ("Bristle2D", {"v1": "v", "v2": "v_cos"}, {}),
    "Classical": ("Classical", {"v": "v", "F_app": "force"}, {"dv": 1e-4}),
    "BlimanSorine": ("BlimanSorine", {"v": "v"}, {}),
    "ElastoPlastic": ("ElastoPlastic", {"v": "v"}, {}),
    "MaxwellSlip": ("MaxwellSlip", {"v": "v"}, {}),
    "GMS": ("GMS", {"v": "v"}, {}),
    "Rig1D": ("Rig1D", {"F": "force"}, {}),
    "Rig2D": ("Rig2D", {"F1": "force", "F2": "v_cos"}, {}),
}
FRICTION_1D = ("Dahl", "LuGre", "ResetIntegrator")

def write_input(path, inputs):
    with open(path, "w") as f:
        f.write(",".join(["time"] + list(inputs)) + "\n")
        for row in drive_table():
            f.write(",".join(repr(row[k]) for k in ["time"] + list(inputs.values())) + "\n")


def read_table(path):
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    rows = [[float(x) for x in line.split(",")] for line in lines[1:]]
    return header, np.array(rows)


def text(value):
    return str(value).lower() if isinstance(value, bool) else repr(value)


def run_fmi_crate(fmu, input_csv, out_csv, parameters):
    assert DRIVE.exists(), f"{DRIVE} is missing: run scripts/setup-fmi-crate.sh"
    args = [str(DRIVE), str(fmu), str(input_csv), str(out_csv)]
    args += [f"{k}={text(v)}" for k, v in parameters.items()]
    result = subprocess.run(args, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return result.stdout


def run_fmpy(fmu, inputs, parameters, tmp_path):
    """The driver's calls, in its order, through FMPy's FMU2Slave."""
    md = read_model_description(str(fmu))
    variables = {v.name: v for v in md.modelVariables}
    outputs = [v for v in md.modelVariables if v.causality == "output" and v.type in ("Real", "Integer", "Boolean")]
    vrs = {kind: [v.valueReference for v in outputs if v.type == kind] for kind in ("Real", "Integer", "Boolean")}
    input_vrs = [variables[n].valueReference for n in inputs]
    table = drive_table()

    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu), unzipdir=str(tmp_path / "fmpy")),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="fmpy")
    slave.instantiate()
    for name, value in parameters.items():
        var = variables[name]
        {"Real": slave.setReal, "Integer": slave.setInteger, "Boolean": slave.setBoolean}[var.type](
            [var.valueReference], [value])
    start, stop = table[0]["time"], table[-1]["time"]
    slave.setupExperiment(startTime=start, stopTime=stop)
    slave.enterInitializationMode()
    slave.exitInitializationMode()

    def record(t):
        values = {"Real": iter(slave.getReal(vrs["Real"])),
                  "Integer": iter(slave.getInteger(vrs["Integer"]) if vrs["Integer"] else []),
                  "Boolean": iter(slave.getBoolean(vrs["Boolean"]) if vrs["Boolean"] else [])}
        return [t] + [float(next(values[v.type])) for v in outputs]

    rows = [record(start)]
    for now, nxt in zip(table, table[1:]):
        slave.setReal(input_vrs, [now[signal] for signal in inputs.values()])
        slave.doStep(currentCommunicationPoint=now["time"], communicationStepSize=nxt["time"] - now["time"])
        rows.append(record(nxt["time"]))
    with pytest.raises(FMICallException):
        slave.doStep(currentCommunicationPoint=stop, communicationStepSize=table[-1]["time"] - table[-2]["time"])
    slave.reset()
    slave.freeInstance()
    return ["time"] + [v.name for v in outputs], np.array(rows)


@pytest.mark.parametrize("case", CASES)
def test_fmi_crate_equals_fmpy_bit_for_bit(case, tmp_path):
    model, inputs, parameters = CASES[case]
    fmu = fmu_path(model)
    input_csv, out_csv = tmp_path / "input.csv", tmp_path / "fmi_crate.csv"
    write_input(input_csv, inputs)

    stdout = run_fmi_crate(fmu, input_csv, out_csv, parameters)
    assert "step past stop: Err(Error)" in stdout, stdout
    header, crate = read_table(out_csv)
    fmpy_header, fmpy = run_fmpy(fmu, inputs, parameters, tmp_path)

    assert header == fmpy_header
    assert crate.shape == fmpy.shape == (N + 1, len(header))
    for k, name in enumerate(header):
        assert np.array_equal(crate[:, k], fmpy[:, k]), (
            f"{case}.{name}: first difference at row {np.flatnonzero(crate[:, k] != fmpy[:, k])[0]}")

    # The run is not trivial: every FMU's outputs move; the 1-D laws' force
    # changes sign with the velocity, their deflection holds during the
    # pause, and they both slide and stick.
    assert max(np.ptp(crate[:, k]) for k in range(1, len(header))) > 0.0
    if model in FRICTION_1D:
        force, z = crate[:, header.index("F")], crate[:, header.index("z")]
        assert force.max() > 0.5 and force.min() < -0.5
        pause = (crate[:, 0] > 1.21) & (crate[:, 0] <= 1.3)
        assert np.all(z[pause] == z[pause][0]) and z[pause][0] != 0.0
        sliding = crate[:, header.index("sliding")]
        assert sliding.max() == 1.0 and sliding.min() == 0.0


def test_fmi_crate_refuses_what_it_should(tmp_path):
    """The driver reports, through the crate, a parameter value our FMU
    refuses and a name the model description lacks (so the equality above
    is not the driver ignoring what it is given)."""
    fmu = fmu_path("LuGre")
    input_csv = tmp_path / "input.csv"
    write_input(input_csv, {"v": "v"})
    for assignment, message in [("Fs=0.5", "fmi2ExitInitializationMode: Error"), ("mu=1", "mu")]:
        result = subprocess.run([str(DRIVE), str(fmu), str(input_csv), str(tmp_path / "o.csv"), assignment],
                                capture_output=True, text=True)
        assert result.returncode != 0
        assert message in result.stderr, result.stderr


def test_every_shipped_fmu_has_a_case():
    shipped.covers({fmu for fmu, _, _ in CASES.values()}, shipped.SHIPPED, "CASES")
