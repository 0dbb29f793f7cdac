"""`fricsim run` against FMPy.

(a) The stick-slip example (dist/stick_slip.ssp, packed by build-fmu.sh from
    examples/stick_slip.ssd): FMPy reads the same archive with its own SSP
    reader (`fmpy.ssp.ssd.read_ssd`, which also validates it against the SSP
    1.0 schema), and FMU2Slave instances are driven in a Python loop with the
    same fixed step and Jacobi scheme, parameters from the ssd's bindings.
    FMPy's own `simulate_ssp` is not used: it starts the inputs at 0 instead
    of the initial outputs, sums time and records before the connections
    are applied, a different scheme.
(b) One FMU with an input from a CSV: `fricsim run --input` equals
    `fmpy.simulate_fmu(..., input=...)` with the same signal (inputs set at
    each communication point before the step, linear interpolation between
    samples, the value after an event at a repeated time), to 1e-9 relative.
"""

import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.ssp.ssd import read_ssd

from conftest import DIST, ROOT, fmu_path

FRICSIM = ROOT / "target" / "release" / "fricsim"
STOP = 9.0  # the first slip is at 7.54 s: the comparison covers stick and slip


def fricsim(*args):
    assert FRICSIM.exists(), f"{FRICSIM} is missing: run ./build-fmu.sh"
    result = subprocess.run([str(FRICSIM), *map(str, args)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return result


def read_csv(path):
    header = path.read_text().splitlines()[0].split(",")
    return header, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def assert_close(name, ours, theirs, rtol=1e-9):
    scale = max(np.max(np.abs(theirs)), 1e-300)
    err = np.max(np.abs(ours - theirs)) / scale
    assert err <= rtol, f"{name}: relative difference {err:.3e}"


def fmpy_jacobi_from_ssp(ssp, step, stop, tmp_path):
    """The system of `ssp` as FMPy reads it, stepped with the Jacobi scheme
    of fricsim: outputs propagated before exitInitializationMode and after
    it, then at every communication point before all FMUs step; t = n*h."""
    ssd = read_ssd(str(ssp))
    unzipped = tmp_path / "ssp"
    with zipfile.ZipFile(ssp) as z:
        z.extractall(unzipped)
    components = {}
    order = []
    types = {}
    for c in ssd.system.elements:
        path = unzipped / c.source
        md = read_model_description(str(path))
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(path), unzipdir=str(tmp_path / c.name)),
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName=c.name)
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        variables = {v.name: v for v in md.modelVariables}
        for binding in c.parameterBindings:
            for parameter_set in binding.parameterValues:
                for p in parameter_set.parameters:
                    vr = [variables[p.name].valueReference]
                    if p.type == "Real":
                        fmu.setReal(vr, [float(p.value)])
                    elif p.type == "Integer":
                        fmu.setInteger(vr, [int(p.value)])
                    elif p.type == "Boolean":
                        fmu.setBoolean(vr, [p.value in ("true", "1")])
                    else:
                        raise AssertionError(f"unexpected parameter type {p.type}")
        # fricsim's columns: per component the Real outputs, then the
        # Integer and the Boolean ones
        outputs = [v.name for kind in ("Real", "Integer", "Boolean")
                   for v in md.modelVariables if v.causality == "output" and v.type == kind]
        types[c.name] = {v.name: v.type for v in md.modelVariables}
        components[c.name] = (fmu, {n: v.valueReference for n, v in variables.items()}, outputs)
        order.append(c.name)
    kinds = {(c.name, k.name): k.kind for c in ssd.system.elements for k in c.connectors}
    links = []
    for k in ssd.system.connections:
        a, b = (k.startElement, k.startConnector), (k.endElement, k.endConnector)
        links.append((a, b) if kinds[a] == "output" else (b, a))

    def propagate():
        values = [components[c][0].getReal([components[c][1][v]])[0] for (c, v), _ in links]
        for (_, (c, v)), x in zip(links, values):
            components[c][0].setReal([components[c][1][v]], [x])

    def value(c, o):
        fmu, vr = components[c][0], [components[c][1][o]]
        get = {"Real": fmu.getReal, "Integer": fmu.getInteger, "Boolean": fmu.getBoolean}[types[c][o]]
        return float(get(vr)[0])

    def sample():
        return [value(c, o) for c in order for o in components[c][2]]

    propagate()
    for fmu, _, _ in components.values():
        fmu.exitInitializationMode()
    propagate()
    names = ["time"] + [f"{c}.{o}" for c in order for o in components[c][2]]
    rows = [[0.0] + sample()]
    for i in range(round(stop / step)):
        t, t_next = i * step, (i + 1) * step
        propagate()
        for fmu, _, _ in components.values():
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=t_next - t)
        rows.append([t_next] + sample())
    for fmu, _, _ in components.values():
        fmu.terminate()
        fmu.freeInstance()
    return names, np.array(rows)


def test_fricsim_run_of_the_stick_slip_example_equals_fmpy(tmp_path):
    ssp = DIST / "stick_slip.ssp"
    assert ssp.exists(), f"{ssp} is missing: run ./build-fmu.sh"
    out = tmp_path / "run.csv"
    # step and master come from the example's annotation, the stop time is shortened
    result = fricsim("run", ssp, "--stop", STOP, "--out", out, "--quiet")
    assert "completed" in result.stdout
    header, ours = read_csv(out)
    names, theirs = fmpy_jacobi_from_ssp(ssp, 1e-4, STOP, tmp_path)
    assert header == names
    assert ours.shape == theirs.shape
    for k, name in enumerate(names):
        assert_close(name, ours[:, k], theirs[:, k])
    v = theirs[:, names.index("rig.v")]
    assert v.max() > 0.05  # slipping happened


SINGLE = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="lugre_alone"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
  <ssd:System name="lugre_alone">
    <ssd:Elements>
      <ssd:Component name="friction" source="{fmu}"/>
    </ssd:Elements>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="2">
    <ssd:Annotations>
      <ssc:Annotation type="org.friction-fmu.fricsim">
        <fricsim:Simulation xmlns:fricsim="urn:friction-fmu:fricsim:1" stepSize="1e-3"/>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""


def sampled_velocity(tmp_path):
    """A velocity sampled every 0.05 s (the step is 1e-3 s, so most
    communication points fall between samples), with an event at t = 1 (a
    repeated time): the signal and its input CSV."""
    t = np.linspace(0.0, 2.0, 41)
    v = 2e-3 * np.sin(2 * np.pi * t)
    t = np.insert(t, 21, 1.0)
    v = np.insert(v, 21, -1e-3)
    signal = np.rec.fromarrays([t, v], names=["time", "v"])
    csv = tmp_path / "input.csv"
    csv.write_text("time,v\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), v.tolist())))
    return signal, csv


def test_fricsim_run_with_an_input_csv_held_equals_fmpy_simulate_fmu(tmp_path):
    """`--input-hold`: each input held over the step, as FMPy's
    simulate_fmu holds it."""
    fmu = fmu_path("LuGre")
    ssd = tmp_path / "lugre.ssd"
    ssd.write_text(SINGLE.format(fmu=fmu))
    signal, csv = sampled_velocity(tmp_path)

    out = tmp_path / "run.csv"
    fricsim("run", ssd, "--input", csv, "--input-hold", "--out", out, "--quiet")
    header, ours = read_csv(out)

    theirs = simulate_fmu(str(fmu), fmi_type="CoSimulation", start_time=0.0, stop_time=2.0,
                          output_interval=1e-3, input=signal)
    assert len(theirs) == len(ours)
    assert_close("time", ours[:, 0], theirs["time"])
    for name in ("F", "z"):
        assert_close(name, ours[:, header.index(f"friction.{name}")], theirs[name])
    # the input mattered: the force changes sign with the velocity
    force = theirs["F"]
    assert force.max() > 0 > force.min()


def test_fricsim_run_with_an_input_csv_interpolates_it_over_each_step(tmp_path):
    """By default each input is given its slope over the step: the run
    equals FMPy's FMU2Slave stepping the FMU with the input at t (FMPy's
    own interpolation) and the slope (v(t + h) - v(t))/h set by
    fmi2SetRealInputDerivatives, and differs from the held run."""
    from ctypes import c_double, c_int, c_uint32
    from fmpy.simulation import Input

    fmu = fmu_path("LuGre")
    ssd = tmp_path / "lugre.ssd"
    ssd.write_text(SINGLE.format(fmu=fmu))
    signal, csv = sampled_velocity(tmp_path)
    out = tmp_path / "run.csv"
    fricsim("run", ssd, "--input", csv, "--out", out, "--quiet")
    header, ours = read_csv(out)

    table = np.array([signal["v"]])
    velocity = lambda t: float(Input.interpolate(time=t, t=signal["time"], table=table, discrete=False,
                                                 after_event=True)[0][0])
    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipdir = extract(str(fmu), unzipdir=str(tmp_path / "unzipped"))
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="LuGre", instanceName="cs")
    slave.instantiate()
    slave.setupExperiment(startTime=0.0, stopTime=2.0)
    slave.enterInitializationMode()
    slave.setReal([vr["v"]], [velocity(0.0)])
    slave.exitInitializationMode()
    h, outputs = 1e-3, [vr["F"], vr["z"]]
    rows = [slave.getReal(outputs)]
    for i in range(2000):
        t, t_next = i * h, (i + 1) * h
        now = velocity(t)
        slave.setReal([vr["v"]], [now])
        slave.fmi2SetRealInputDerivatives(slave.component, (c_uint32 * 1)(vr["v"]), 1, (c_int * 1)(1),
                                          (c_double * 1)((velocity(t_next) - now) / h))
        slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        rows.append(slave.getReal(outputs))
    slave.terminate()
    slave.freeInstance()
    theirs = np.array(rows)
    assert len(theirs) == len(ours)
    for k, name in enumerate(("F", "z")):
        assert_close(name, ours[:, header.index(f"friction.{name}")], theirs[:, k])

    held = tmp_path / "held.csv"
    fricsim("run", ssd, "--input", csv, "--input-hold", "--out", held, "--quiet")
    _, held_rows = read_csv(held)
    # the force feeds the velocity through: at a row's time held, its
    # value a step old
    column = header.index("friction.F")
    assert np.max(np.abs(held_rows[:, column] - ours[:, column])) > 1e-4 * np.max(np.abs(ours[:, column]))


def test_cosim_with_an_input_csv_equals_run(tmp_path):
    """`fricsim cosim --input` applies the table as `run --input` does,
    interpolated by default and held with --input-hold."""
    fmu = fmu_path("LuGre")
    ssd = tmp_path / "lugre.ssd"
    ssd.write_text(SINGLE.format(fmu=fmu))
    _, csv = sampled_velocity(tmp_path)
    for hold in ([], ["--input-hold"]):
        run, cosim = tmp_path / "run.csv", tmp_path / "cosim.csv"
        fricsim("run", ssd, "--input", csv, *hold, "--out", run, "--quiet")
        # cosim names the columns component.variable
        named = tmp_path / "named-input.csv"
        named.write_text(csv.read_text().replace("time,v", "time,friction.v", 1))
        fricsim("cosim", "--fmu", f"friction={fmu}", "--input", named, *hold, "--step", "1e-3", "--stop", "2",
                "--out", cosim)
        header, ours = read_csv(run)
        cosim_header, theirs = read_csv(cosim)
        assert ours.shape == theirs.shape
        for name in ("F", "z"):
            column = f"friction.{name}"
            assert_close(column, theirs[:, cosim_header.index(column)], ours[:, header.index(column)], rtol=0.0)


def test_fricsim_run_reports_an_incomplete_run(tmp_path):
    """An FMU error mid-run: exit status 1, the rows so far in the CSV with
    an INCOMPLETE comment, the summary says INCOMPLETE. (LuGre refuses a
    negative normal force; the input ramps Fn below zero at t = 0.5 s.)"""
    fmu = fmu_path("LuGre")
    ssd = tmp_path / "lugre.ssd"
    ssd.write_text(SINGLE.format(fmu=fmu))
    csv = tmp_path / "input.csv"
    csv.write_text("time,v,Fn\n0,1e-3,1\n1,1e-3,-1\n")
    out = tmp_path / "run.csv"
    result = subprocess.run([str(FRICSIM), "run", str(ssd), "--input", str(csv), "--out", str(out), "--quiet"],
                            capture_output=True, text=True)
    assert result.returncode == 1
    assert "INCOMPLETE" in result.stdout and "INCOMPLETE" in result.stderr
    assert "Fn" in result.stderr
    text = out.read_text().splitlines()
    assert text[-1].startswith("# INCOMPLETE")
    rows = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    assert 450 <= len(rows) <= 520


EXAMPLES = sorted(p.stem for p in (ROOT / "examples").glob("*.ssd"))


@pytest.mark.parametrize("name", EXAMPLES)
def test_every_packed_example_is_read_by_fmpy(name):
    """FMPy's SSP reader (lxml, the SSP 1.0 schema) reads every example
    archive, and finds each component's FMU in it. Seven examples once had
    `--` inside XML comments, which fricsim accepted and lxml refuses."""
    ssp = DIST / f"{name}.ssp"
    assert ssp.exists(), f"{ssp} is missing: run ./build-fmu.sh"
    ssd = read_ssd(str(ssp))
    assert ssd.name == name
    with zipfile.ZipFile(ssp) as z:
        entries = set(z.namelist())
    sources = [c.source for c in ssd.system.elements]
    assert sources and all(s in entries for s in sources), (sources, sorted(entries))
