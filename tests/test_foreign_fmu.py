"""fricsim on FMUs this project did not build.

- BeltOscillator: an FMI 2.0 Co-Simulation FMU written by hand in C with its
  own modelDescription.xml (host/tests/c/belt_oscillator), compiled with the
  system C compiler and zipped here.
- FirstOrderDrive: exported by pythonfmu (pinned in requirements.txt) from
  tests/pythonfmu/FirstOrderDrive.py. Its binary does not link libpython: it
  expects the Python runtime in the process (needsExecutionTool="true"), as
  FMPy provides it. fricsim runs it when libpython is preloaded, and names
  the reason when it is not.

fricsim must equal FMPy to 1e-9 relative: simulate_fmu for one FMU, the
FMU2Slave Jacobi loop of test_host_vs_fmpy.py for an FMU coupled with our
LuGre.fmu or Dahl.fmu."""

import math
import os
import re
import subprocess
import sys
import sysconfig
import zipfile
from ctypes import byref
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import (FMU2Slave, calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free, printLogMessage)
from fmpy.logging import addLoggerProxy
from fmpy.validation import validate_fmu

from conftest import ROOT, fmu_path

FRICSIM = ROOT / "target" / "release" / "fricsim"
BELT_SOURCE = ROOT / "host" / "tests" / "c" / "belt_oscillator"
DRIVE_SCRIPT = Path(__file__).resolve().parent / "pythonfmu" / "FirstOrderDrive.py"


@pytest.fixture(scope="module")
def belt(tmp_path_factory):
    """BeltOscillator.fmu, compiled and zipped from the C source."""
    work = tmp_path_factory.mktemp("belt")
    library = work / "BeltOscillator.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-fvisibility=hidden", "-O1", "-Wall", "-Wextra",
                    "-o", str(library), str(BELT_SOURCE / "belt_oscillator.c"), "-lm"],
                   check=True, capture_output=True, text=True)
    fmu = work / "BeltOscillator.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        z.write(BELT_SOURCE / "modelDescription.xml", "modelDescription.xml")
        z.write(library, "binaries/linux64/BeltOscillator.so")
    return fmu


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    """FirstOrderDrive.fmu, exported by pythonfmu."""
    work = tmp_path_factory.mktemp("drive")
    subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(DRIVE_SCRIPT), "-d", str(work)],
                   check=True, capture_output=True, text=True)
    fmu = work / "FirstOrderDrive.fmu"
    assert fmu.is_file()
    return fmu


@pytest.fixture(scope="module")
def python_runtime():
    """The environment that gives fricsim the Python runtime a pythonfmu
    binary expects: libpython preloaded."""
    libpython = Path(sysconfig.get_config_var("LIBDIR") or "") / (sysconfig.get_config_var("LDLIBRARY") or "")
    if not sysconfig.get_config_var("Py_ENABLE_SHARED") or not libpython.is_file():
        pytest.skip(f"this Python has no shared libpython ({libpython}) to preload")
    return dict(os.environ, LD_PRELOAD=str(libpython))


# FMPy's logging proxy keeps one logger for the whole process (a static in
# fmpy/logging), set by the latest addLoggerProxy call: after a test whose
# logger is gone, an FMU logging through FMPy's default callbacks would call
# freed memory. A test that makes an FMU log passes its own logger and then
# leaves this one, which lives as long as the module, in place.
_LASTING = fmi2CallbackFunctions()
_LASTING.logger = fmi2CallbackLoggerTYPE(printLogMessage)
_LASTING.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
_LASTING.freeMemory = fmi2CallbackFreeMemoryTYPE(free)


def simulate_logged(fmu, **kwargs):
    """simulate_fmu with the FMU's log messages collected: (result, messages)."""
    messages = []

    def logger(env, instance, status, category, message):
        messages.append((status, category.decode(), message.decode()))

    try:
        return simulate_fmu(str(fmu), logger=logger, **kwargs), messages
    finally:
        addLoggerProxy(byref(_LASTING))


def fricsim(*args, env=None):
    return subprocess.run([str(FRICSIM), *map(str, args)], capture_output=True, text=True, env=env)


def cosim(components, parameters, connections, step, stop, out, env=None):
    """`fricsim cosim`; returns the process and the CSV (header, rows)."""
    args = ["cosim"]
    for name, path in components:
        args += ["--fmu", f"{name}={path}"]
    for port, value in parameters.items():
        args += ["--set", f"{port}={str(value).lower() if isinstance(value, bool) else repr(value)}"]
    for a, o, b, i in connections:
        args += ["--connect", f"{a}.{o}->{b}.{i}"]
    args += ["--step", repr(step), "--stop", repr(stop), "--out", out]
    process = fricsim(*args, env=env)
    assert "panicked" not in process.stderr, process.stderr
    if not out.exists():
        return process, None, None
    header = out.read_text().splitlines()[0].split(",")
    return process, header, np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)


def fmpy_jacobi(components, parameters, connections, step, stop, tmp_path):
    """FMPy's FMU2Slave driving `components` with fricsim's Jacobi scheme:
    parameters set in initialization mode, outputs copied to inputs before
    exitInitializationMode, after it, and before every step; every
    output recorded at every communication point (Integer and Boolean
    ones as numbers, after the Real ones of their component)."""
    fmus = {}
    for name, path in components:
        md = read_model_description(str(path))
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(path), unzipdir=str(tmp_path / name)),
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        variables = {v.name: v for v in md.modelVariables}
        # the Real outputs, then the Integer and Boolean ones, as fricsim
        # records them
        outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
        outputs += [v for v in md.modelVariables if v.causality == "output" and v.type in ("Integer", "Boolean")]
        fmus[name] = (fmu, variables, outputs)
    for port, value in parameters.items():
        name, variable = port.split(".", 1)
        fmu, variables, _ = fmus[name]
        v = variables[variable]
        setter = {"Real": fmu.setReal, "Integer": fmu.setInteger, "Boolean": fmu.setBoolean}[v.type]
        setter([v.valueReference], [{"Real": float, "Integer": int, "Boolean": bool}[v.type](value)])

    def propagate():
        values = [fmus[a][0].getReal([fmus[a][1][o].valueReference])[0] for a, o, _, _ in connections]
        for (_, _, b, i), x in zip(connections, values):
            fmus[b][0].setReal([fmus[b][1][i].valueReference], [x])

    def read(fmu, v):
        getter = {"Real": fmu.getReal, "Integer": fmu.getInteger, "Boolean": fmu.getBoolean}[v.type]
        return float(getter([v.valueReference])[0])

    def sample():
        return [read(fmu, v) for fmu, _, outputs in fmus.values() for v in outputs]

    propagate()
    for fmu, _, _ in fmus.values():
        fmu.exitInitializationMode()
    propagate()
    rows = [[0.0] + sample()]
    for i in range(round(stop / step)):
        t, t_next = i * step, (i + 1) * step
        propagate()
        for fmu, _, _ in fmus.values():
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=t_next - t)
        rows.append([t_next] + sample())
    for fmu, _, _ in fmus.values():
        fmu.terminate()
        fmu.freeInstance()
    return np.array(rows)


def assert_equal_to_1e9(names, ours, theirs):
    assert ours.shape == theirs.shape, (ours.shape, theirs.shape)
    for k, name in enumerate(names):
        scale = max(np.max(np.abs(theirs[:, k])), 1e-300)
        err = np.max(np.abs(ours[:, k] - theirs[:, k])) / scale
        assert err <= 1e-9, f"{name}: relative difference {err:.3e}"


# ---- BeltOscillator, the hand-written C FMU ----------------------------------------

def test_belt_oscillator_passes_fmpy_validation(belt):
    assert validate_fmu(str(belt)) == []


def info_rows(fmu):
    """`fricsim info`'s variable table as {name: tokens}."""
    process = fricsim("info", fmu)
    assert process.returncode == 0, process.stderr
    table = process.stdout.split("\nVariables\n", 1)[1].strip().splitlines()
    assert table[0].split()[:6] == ["Name", "Causality", "Variability", "Type", "Start", "Unit"]
    return process.stdout, {line.split()[0]: line.split() for line in table[1:]}


@pytest.mark.parametrize("which", ["belt", "drive"])
def test_fricsim_info_lists_every_variable(which, request):
    fmu = request.getfixturevalue(which)
    md = read_model_description(str(fmu))
    stdout, rows = info_rows(fmu)
    assert f"Model Identifier   {md.coSimulation.modelIdentifier}" in stdout
    assert f"Generation Tool    {md.generationTool}" in stdout
    assert set(rows) == {v.name for v in md.modelVariables}
    for v in md.modelVariables:
        tokens = rows[v.name]
        assert tokens[1:4] == [v.causality, v.variability, v.type], tokens
        rest = tokens[4:]
        if v.start is not None:
            if v.type == "Boolean":
                assert rest[0] == str(v.start).lower(), tokens
            else:
                assert float(rest[0]) == float(v.start), tokens
            rest = rest[1:]
        if v.unit:
            assert rest[0] == v.unit, tokens


BELT_ALONE = {"rig.F": 0.5, "rig.c": 0.2, "rig.x0": 0.01, "rig.v0": 0.05, "rig.v_belt": 0.1}


def damped_oscillator(t, m, k, c, force, x0, v0):
    """Closed form of m x'' + c x' + k x = -force (underdamped): x and x'."""
    x_eq = -force / k
    w0 = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = w0 * math.sqrt(1 - zeta ** 2)
    a = x0 - x_eq
    b = (v0 + zeta * w0 * a) / wd
    decay = np.exp(-zeta * w0 * t)
    x = x_eq + decay * (a * np.cos(wd * t) + b * np.sin(wd * t))
    xd = decay * ((b * wd - zeta * w0 * a) * np.cos(wd * t) - (a * wd + zeta * w0 * b) * np.sin(wd * t))
    return x, xd


def test_belt_oscillator_alone_equals_simulate_fmu_and_the_closed_form(belt, tmp_path):
    step, stop = 1e-3, 2.0
    process, header, ours = cosim([("rig", belt)], BELT_ALONE, [], step, stop, tmp_path / "belt.csv")
    assert process.returncode == 0, process.stderr
    assert header == ["time", "rig.x", "rig.v", "rig.a"]
    start_values = {k.split(".", 1)[1]: v for k, v in BELT_ALONE.items()}
    result = simulate_fmu(str(belt), fmi_type="CoSimulation", stop_time=stop, output_interval=step,
                          start_values=start_values)
    theirs = np.column_stack([result[n] for n in ("time", "x", "v", "a")])
    assert_equal_to_1e9(header, ours, theirs)

    # and the FMU is right: RK4 in 1e-4 s sub-steps against the closed form
    t = ours[:, 0]
    x, xd = damped_oscillator(t, m=1.0, k=10.0, c=0.2, force=0.5, x0=0.01, v0=0.05)
    for k, exact in [(1, x), (2, xd - 0.1)]:
        err = np.max(np.abs(ours[:, k] - exact)) / np.max(np.abs(exact))
        assert err <= 1e-9, f"{header[k]}: {err:.3e} from the closed form"


def test_belt_oscillator_with_lugre_equals_fmpy_jacobi(belt, tmp_path):
    # body starts moving with the belt (stick); the spring breaks it away
    # at about k x = Fs (1.5 N at x = 0.15 m, t = 1.5 s), then it slips
    components = [("rig", belt), ("friction", fmu_path("LuGre"))]
    parameters = {"rig.k": 10.0, "rig.v_belt": 0.1, "rig.v0": 0.1}
    connections = [("rig", "v", "friction", "v"), ("friction", "F", "rig", "F")]
    step, stop = 1e-4, 3.0
    process, header, ours = cosim(components, parameters, connections, step, stop, tmp_path / "c.csv")
    assert process.returncode == 0, process.stderr
    assert header == ["time", "rig.x", "rig.v", "rig.a", "friction.F", "friction.z", "friction.P_diss",
                      "friction.E_stored", "friction.sliding"]
    theirs = fmpy_jacobi(components, parameters, connections, step, stop, tmp_path)
    assert_equal_to_1e9(header, ours, theirs)
    # the comparison covers stick and slip
    t, v = theirs[:, 0], theirs[:, header.index("rig.v")]
    assert np.max(np.abs(v[(t > 0.2) & (t < 1.3)])) < 1e-3
    assert np.min(v[t > 1.3]) < -0.05


def test_a_discarded_step_ends_the_run_where_fmpy_ends_it(belt, tmp_path):
    # fault 2 at the 50th step: the FMU completes only half of the step from
    # t = 0.049 and asks to end (fmi2Terminated). FMPy records that
    # half-step as its last row and stops; so does fricsim (FMI 2.0.4
    # 4.2.3): a normal end, exit status 0, the same 51 rows.
    parameters = {"rig.fault": 2, "rig.fault_step": 50, "rig.fault_terminates": True}
    step, stop = 1e-3, 1.0
    out = tmp_path / "discard.csv"
    process, header, ours = cosim([("rig", belt)], parameters, [], step, stop, out)
    assert process.returncode == 0, process.stderr
    assert "rig ended the simulation at t = 0.0495" in process.stdout, process.stdout
    assert "INCOMPLETE" not in out.read_text()

    start_values = {k.split(".", 1)[1]: v for k, v in parameters.items()}
    result, messages = simulate_logged(belt, fmi_type="CoSimulation", stop_time=stop, output_interval=step,
                                       start_values=start_values)
    assert [(s, c) for s, c, _ in messages] == [(2, "logStatusDiscard")], messages
    assert "fault injected at step 50" in messages[0][2]
    theirs = np.column_stack([result[n] for n in ("time", "x", "v", "a")])
    assert len(theirs) == 51 and len(ours) == 51
    assert ours[-1, 0] == theirs[-1, 0] == pytest.approx(0.0495, rel=1e-12)
    assert_equal_to_1e9(header, ours, theirs)


# ---- FirstOrderDrive, exported by pythonfmu --------------------------------------

def test_pythonfmu_export_has_one_known_validation_problem(drive):
    # pythonfmu 0.7.0 leaves out ModelStructure/InitialUnknowns, which FMI
    # 2.0 requires for outputs with initial="calculated"
    problems = validate_fmu(str(drive))
    assert len(problems) == 1 and "InitialUnknowns" in problems[0], problems


def test_fricsim_names_the_missing_python_runtime(drive, tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
    out = tmp_path / "drive.csv"
    process, _, _ = cosim([("drive", drive)], {}, [], 1e-3, 0.1, out, env=env)
    assert process.returncode == 1
    for part in ["FirstOrderDrive.so", "undefined symbol", 'needsExecutionTool="true"', "PythonFMU 0.7.0"]:
        assert part in process.stderr, process.stderr
    assert not out.exists()


def test_pythonfmu_drive_alone_equals_simulate_fmu(drive, python_runtime, tmp_path):
    step, stop = 1e-3, 0.5
    process, header, ours = cosim([("drive", drive)], {"drive.F": 0.5, "drive.tau": 0.05}, [], step, stop,
                                  tmp_path / "drive.csv", env=python_runtime)
    assert process.returncode == 0, process.stderr
    assert header == ["time", "drive.v", "drive.v_cmd"]
    result = simulate_fmu(str(drive), fmi_type="CoSimulation", stop_time=stop, output_interval=step,
                          start_values={"F": 0.5, "tau": 0.05})
    theirs = np.column_stack([result[n] for n in ("time", "v", "v_cmd")])
    assert_equal_to_1e9(header, ours, theirs)
    assert np.max(theirs[:, 1]) > 0.005  # it moved


def test_pythonfmu_drive_with_dahl_equals_fmpy_jacobi(drive, python_runtime, tmp_path):
    components = [("drive", drive), ("friction", fmu_path("Dahl"))]
    parameters = {"friction.Fc": 2.0}
    connections = [("drive", "v", "friction", "v"), ("friction", "F", "drive", "F")]
    step, stop = 1e-4, 1.0
    process, header, ours = cosim(components, parameters, connections, step, stop, tmp_path / "c.csv",
                                  env=python_runtime)
    assert process.returncode == 0, process.stderr
    assert header == ["time", "drive.v", "drive.v_cmd", "friction.F", "friction.z", "friction.P_diss",
                      "friction.E_stored", "friction.sliding"]
    theirs = fmpy_jacobi(components, parameters, connections, step, stop, tmp_path)
    assert_equal_to_1e9(header, ours, theirs)
    # the drive sweeps the contact both ways: Dahl's force reaches both levels
    force = theirs[:, header.index("friction.F")]
    assert force.max() > 0.99 * 2.0 and force.min() < -0.99 * 2.0
