"""LuGre.fmu's parameter sensitivities read by FMPy, an importer that is not
this project's: with `parameter_sensitivities = true`,
fmi2GetDirectionalDerivative of F with a parameter as the known equals
central differences of two FMPy runs with that parameter moved, along a
velocity through both directions with the position table and the
direction-dependent levels on. With the parameter off, the same call fails
with fmi2Error (FMPy raises) and the FMU says how to turn it on."""

from __future__ import annotations

import math

import pytest
from conftest import add_logger_proxy, fmu_path
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, calloc, free

H = 1e-3
STEPS = 1500
PARAMETERS = {
    "direction_dependent": True,
    "position_dependent": True,
    "n_table": 4,
    "x_table[1]": -0.01,
    "x_table[2]": 0.0,
    "x_table[3]": 0.01,
    "x_table[4]": 0.02,
    "scale_pos[2]": 1.1,
    "scale_neg[3]": 0.9,
    "Fc_neg": 0.8,
    "Fs_neg": 1.2,
    "vs": 4e-3,
    "sigma0": 2e4,
    "sigma1": 100.0,
}
# the parameters checked, and the size of their moves (relative)
CHECKED = ["Fc", "Fs", "vs", "sigma0", "sigma1", "sigma2", "Fc_neg", "scale_pos[2]", "scale_neg[3]", "F_offset"]


def velocity(k):
    t = k * H
    return 0.02 * math.sin(7 * t) + 0.004 * math.sin(53 * t), 0.015 * math.sin(5 * t)


@pytest.fixture(scope="module")
def unzipped(tmp_path_factory):
    fmu = fmu_path("LuGre")
    return fmu, read_model_description(str(fmu)), extract(str(fmu), unzipdir=str(tmp_path_factory.mktemp("lugre")))


def run(unzipped, values, sensitivities=False, messages=None):
    """Forces every 100 steps and, unless `sensitivities` is None, dF/dp
    of CHECKED there (read whether carried or not)."""
    fmu, md, directory = unzipped
    vr = {v.name: v.valueReference for v in md.modelVariables}

    def logger(env, instance, status, category, message):
        if messages is not None:
            messages.append(message.decode())

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    add_logger_proxy(callbacks)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=directory, modelIdentifier="LuGre", instanceName="lugre")
    slave.instantiate(callbacks=callbacks, loggingOn=True)
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    for name, value in values.items():
        if isinstance(value, bool):
            slave.setBoolean([vr[name]], [value])
        elif name == "n_table":
            slave.setInteger([vr[name]], [value])
        else:
            slave.setReal([vr[name]], [value])
    slave.setBoolean([vr["parameter_sensitivities"]], [bool(sensitivities)])
    slave.exitInitializationMode()
    forces, sens = [], []
    try:
        for k in range(STEPS):
            v, x = velocity(k)
            slave.setReal([vr["v"], vr["x"]], [v, x])
            slave.doStep(k * H, H)
            if k % 100 == 99:
                forces.append(slave.getReal([vr["F"]])[0])
                if sensitivities is not None:
                    sens.append([slave.getDirectionalDerivative([vr["F"]], [vr[p]], [1.0])[0] for p in CHECKED])
    finally:
        slave.terminate()
        slave.freeInstance()
    return forces, sens


def default(md, name):
    return float(next(v for v in md.modelVariables if v.name == name).start)


def test_fmpy_reads_sensitivities_that_equal_differences(unzipped):
    md = unzipped[1]
    _, sens = run(unzipped, PARAMETERS, sensitivities=True)
    for j, name in enumerate(CHECKED):
        base = PARAMETERS.get(name, None)
        base = default(md, name) if base is None else base
        d = 1e-6 * max(abs(base), 1e-3 if name == "vs" else 1.0)
        up, _ = run(unzipped, {**PARAMETERS, name: base + d}, sensitivities=None)
        down, _ = run(unzipped, {**PARAMETERS, name: base - d}, sensitivities=None)
        for i, row in enumerate(sens):
            fd = (up[i] - down[i]) / (2 * d)
            scale = max(abs(base), 1e-3)
            # per unit relative change of the parameter, forces of about 1 N
            assert abs(row[j] - fd) * scale <= 1e-7, (name, i, row[j], fd)
    # they are not all zero: the run slides both ways over the table
    assert max(abs(r[CHECKED.index("Fc_neg")]) for r in sens) > 0.1
    assert max(abs(r[CHECKED.index("scale_pos[2]")]) for r in sens) > 0.1


def test_with_sensitivities_off_the_call_fails_and_says_why(unzipped):
    messages = []
    with pytest.raises(Exception):
        run(unzipped, PARAMETERS, sensitivities=False, messages=messages)
    assert any("parameter_sensitivities = true" in m for m in messages), messages
