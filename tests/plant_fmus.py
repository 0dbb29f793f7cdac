"""Shared by the tests of the plant FMUs (the hand-written C ones,
host/tests/c/two_mass_drive and host/tests/c/servo_axis, both on
host/tests/c/common/linear_plant.h, and the shipped Rig1D): an instance
opened with FMPy with its messages collected, and the step's outputs and
Jacobian read through it."""

from __future__ import annotations

import sys
from pathlib import Path

from conftest import add_logger_proxy
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, calloc, free

sys.path.insert(0, str(Path(__file__).resolve().parent / "independent"))
import two_mass_fmu  # noqa: E402


def open_plant(tmp_path, plant, initialize=True):
    """Build the plant's FMU into tmp_path and yield (slave, value
    references by name, the logged (status, message) list, model
    description), instantiated and (when `initialize`) initialised."""
    yield from open_fmu(tmp_path, two_mass_fmu.build(tmp_path, plant), initialize=initialize)


def open_fmu(tmp_path, fmu, parameters=None, initialize=True):
    """Yield (slave, value references by name, the logged (status,
    message) list, model description) of the FMU file `fmu`, instantiated
    with logging on, its `parameters` (name: value) set, and (when
    `initialize`) initialised; terminated and freed afterwards."""
    md = read_model_description(str(fmu))
    variables = {v.name: v for v in md.modelVariables}
    vr = {n: v.valueReference for n, v in variables.items()}
    messages = []

    def logger(env, instance, status, category, message):
        messages.append((status, message.decode()))

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    add_logger_proxy(callbacks)
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu), unzipdir=str(tmp_path / "unzipped")),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="drive")
    slave.instantiate(callbacks=callbacks, loggingOn=True)
    if initialize:
        slave.setupExperiment(startTime=0.0)
        for name, value in (parameters or {}).items():
            if variables[name].type == "Integer":
                slave.setInteger([vr[name]], [value])
            else:
                slave.setReal([vr[name]], [value])
        slave.enterInitializationMode()
        slave.exitInitializationMode()
    yield slave, vr, messages, md
    if initialize:
        slave.terminate()
    slave.freeInstance()


def jacobian(slave, vr, outputs, inputs):
    """{(output, input): d output / d input} from the directional derivatives."""
    return {(o, i): slave.getDirectionalDerivative([vr[o]], [vr[i]], [1.0])[0] for o in outputs for i in inputs}


def stepped_outputs(slave, vr, state, t, h, inputs, outputs):
    """The outputs after one step of `h` from the FMUstate `state` with the
    `inputs` (name: value) held."""
    slave.setFMUstate(state)
    slave.setReal([vr[n] for n in inputs], list(inputs.values()))
    slave.doStep(t, h)
    return dict(zip(outputs, slave.getReal([vr[o] for o in outputs])))
