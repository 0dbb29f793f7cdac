"""Misuse of every shipped FMU through FMPy (the Rust twin is
host/tests/integration/misuse.rs): every FMI 2.0 Co-Simulation function called in every
reachable state in which the standard (FMI 2.0.4 section 4.2.4) does not
allow it, NULL arrays, unknown value references, fixed parameters after
initialization, NaN and +-inf for every real input and parameter, wrong
communication points and step sizes, truncated, corrupted and foreign
serialized states. Each case, generated from the tables below, must raise
fmi2Error (never crash), log a message naming the function and the value or
state, and leave the instance usable: the run continues from where it was."""

import ctypes
import math

import pytest
from fmpy.fmi1 import FMICallException

from shipped import SHIPPED

STATES = ["Instantiated", "InitializationMode", "StepComplete", "Terminated"]
# The calls that take each fresh instance to a state.
TO_STATE = {
    "Instantiated": [],
    "InitializationMode": ["setup", "enter"],
    "StepComplete": ["setup", "enter", "exit"],
    "Terminated": ["setup", "enter", "exit", "terminate"],
}
# The rest of a normal run from each state: "usable" means these succeed.
CONTINUE = {
    "Instantiated": ["setup", "enter", "exit", "step", "terminate"],
    "InitializationMode": ["exit", "step", "terminate"],
    "StepComplete": ["step", "terminate"],
    "Terminated": ["reset", "setup", "enter", "exit", "step", "terminate"],
}
ALL = set(STATES)
BEFORE_STEPPING = {"Instantiated", "InitializationMode", "StepComplete"}
AFTER_INSTANTIATED = {"InitializationMode", "StepComplete", "Terminated"}
# FMI 2.0.4 section 4.2.4: the states (of the four above) where each function may be called.
ALLOWED = {
    "fmi2SetDebugLogging": ALL,
    "fmi2SetupExperiment": {"Instantiated"},
    "fmi2EnterInitializationMode": {"Instantiated"},
    "fmi2ExitInitializationMode": {"InitializationMode"},
    "fmi2Terminate": {"StepComplete"},
    "fmi2Reset": ALL,
    "fmi2GetReal": AFTER_INSTANTIATED,
    "fmi2GetInteger": AFTER_INSTANTIATED,
    "fmi2GetBoolean": AFTER_INSTANTIATED,
    "fmi2SetReal": BEFORE_STEPPING,
    "fmi2SetInteger": BEFORE_STEPPING,
    "fmi2SetBoolean": BEFORE_STEPPING,
    "fmi2GetFMUstate": ALL,
    "fmi2GetDirectionalDerivative": AFTER_INSTANTIATED,
    "fmi2SetRealInputDerivatives": BEFORE_STEPPING,
    "fmi2GetRealOutputDerivatives": {"StepComplete", "Terminated"},
    "fmi2DoStep": {"StepComplete"},
    "fmi2CancelStep": set(),
    "fmi2GetStatus": {"StepComplete", "Terminated"},
    "fmi2GetRealStatus": {"StepComplete", "Terminated"},
    "fmi2GetBooleanStatus": {"StepComplete", "Terminated"},
}


def lifecycle(inst, name):
    f = inst.fmu
    return {
        "setup": lambda: f.setupExperiment(startTime=0.0),
        "enter": f.enterInitializationMode,
        "exit": f.exitInitializationMode,
        "step": lambda: f.doStep(0.0, 1e-3),
        "terminate": f.terminate,
        "reset": f.reset,
    }[name]()


def first(inst, causality):
    return next(v for v in inst.md.modelVariables if v.causality == causality and v.type == "Real")


def probe(inst, function):
    """`function` with arguments valid apart from the state."""
    f, c = inst.fmu, inst.fmu.component
    u, y = first(inst, "input"), first(inst, "output")
    status = ctypes.c_int()
    real = ctypes.c_double()
    calls = {
        "fmi2SetDebugLogging": lambda: f.setDebugLogging(True, []),
        "fmi2SetupExperiment": lambda: f.setupExperiment(startTime=0.0),
        "fmi2EnterInitializationMode": f.enterInitializationMode,
        "fmi2ExitInitializationMode": f.exitInitializationMode,
        "fmi2Terminate": f.terminate,
        "fmi2Reset": f.reset,
        "fmi2GetReal": lambda: f.getReal([y.valueReference]),
        "fmi2GetInteger": lambda: f.fmi2GetInteger(c, None, 0, None),
        "fmi2GetBoolean": lambda: f.fmi2GetBoolean(c, None, 0, None),
        "fmi2SetReal": lambda: f.setReal([u.valueReference], [float(u.start or 0.0)]),
        "fmi2SetInteger": lambda: f.fmi2SetInteger(c, None, 0, None),
        "fmi2SetBoolean": lambda: f.fmi2SetBoolean(c, None, 0, None),
        "fmi2GetFMUstate": lambda: f.freeFMUstate(f.getFMUstate()),
        "fmi2GetDirectionalDerivative": lambda: f.getDirectionalDerivative(
            [y.valueReference], [u.valueReference], [1.0]),
        "fmi2SetRealInputDerivatives": lambda: f.setRealInputDerivatives([u.valueReference], [1], [0.0]),
        "fmi2GetRealOutputDerivatives": lambda: f.fmi2GetRealOutputDerivatives(c, None, 0, None, None),
        "fmi2DoStep": lambda: f.doStep(0.0, 1e-3),
        "fmi2CancelStep": f.cancelStep,
        "fmi2GetStatus": lambda: f.fmi2GetStatus(c, 0, ctypes.byref(status)),
        "fmi2GetRealStatus": lambda: f.fmi2GetRealStatus(c, 2, ctypes.byref(real)),
        "fmi2GetBooleanStatus": lambda: f.fmi2GetBooleanStatus(c, 3, ctypes.byref(status)),
    }
    calls[function]()


def refused(inst, call, *parts):
    """`call` raises fmi2Error, and one error message names every part."""
    inst.messages.clear()
    with pytest.raises(FMICallException) as e:
        call()
    assert e.value.status == 3, e.value
    errors = [m for s, _, m in inst.messages if s >= 3]
    assert len(errors) == 1, inst.messages
    for part in parts:
        assert part in errors[0], (part, errors[0])


def in_state(instance, name, state):
    inst = instance(name)
    for call in TO_STATE[state]:
        lifecycle(inst, call)
    return inst


def finish(inst, state):
    for call in CONTINUE[state]:
        lifecycle(inst, call)
    y = first(inst, "output").valueReference
    assert math.isfinite(inst.fmu.getReal([y])[0])


CASES = [(m, fn, s) for m in SHIPPED for fn, ok in ALLOWED.items() for s in STATES if s not in ok]


@pytest.mark.parametrize("model,function,state", CASES)
def test_call_in_a_state_the_standard_forbids(instance, model, function, state):
    inst = in_state(instance, model, state)
    refused(inst, lambda: probe(inst, function), function, "not allowed in state", state)
    finish(inst, state)


@pytest.mark.parametrize("model", SHIPPED)
def test_calls_the_standard_allows_succeed(instance, model):
    for state in STATES:
        for function, ok in ALLOWED.items():
            if state in ok:
                inst = in_state(instance, model, state)
                probe(inst, function)  # raises on fmi2Error


@pytest.mark.parametrize("model", SHIPPED)
def test_null_arrays_unknown_references_and_fixed_parameters(instance, model):
    inst = in_state(instance, model, "StepComplete")
    f, c = inst.fmu, inst.fmu.component
    y = first(inst, "output").valueReference
    vr = (ctypes.c_uint * 1)(y)
    out = (ctypes.c_double * 1)()
    refused(inst, lambda: f.fmi2GetReal(c, None, 1, out), "fmi2GetReal", "NULL")
    refused(inst, lambda: f.fmi2GetReal(c, vr, 1, None), "fmi2GetReal", "NULL")
    refused(inst, lambda: f.fmi2SetReal(c, vr, 1, None), "fmi2SetReal", "NULL")
    refused(inst, lambda: f.fmi2SetReal(c, vr, 1 << 40, out), "fmi2SetReal", "length of")
    unknown = max(v.valueReference for v in inst.md.modelVariables) + 1000
    refused(inst, lambda: f.getReal([unknown]), "fmi2GetReal", str(unknown))
    refused(inst, lambda: f.setReal([unknown], [0.0]), "fmi2SetReal", str(unknown))
    for p in (v for v in inst.md.modelVariables if v.causality == "parameter"):
        assert p.variability == "fixed", p.name
        setter = {"Real": f.setReal, "Integer": f.setInteger, "Boolean": f.setBoolean}[p.type]
        start = {"Real": float, "Integer": int, "Boolean": bool}[p.type](p.start)
        refused(inst, lambda: setter([p.valueReference], [start]), "fmi2Set", p.name, "StepComplete")
    finish(inst, "StepComplete")


@pytest.mark.parametrize("model", SHIPPED)
def test_nan_and_infinities_for_every_real_input_and_parameter(instance, model):
    inst = in_state(instance, model, "InitializationMode")
    f = inst.fmu
    for v in inst.md.modelVariables:
        if v.type != "Real" or v.causality not in ("input", "parameter"):
            continue
        before = f.getReal([v.valueReference])
        for bad, text in ((math.nan, "NaN"), (math.inf, "inf"), (-math.inf, "-inf")):
            refused(inst, lambda: f.setReal([v.valueReference], [bad]), "fmi2SetReal", v.name, text)
            assert f.getReal([v.valueReference]) == before or math.isnan(before[0])
    finish(inst, "InitializationMode")


STEP_CASES = [
    (0.0, 0.0, "communicationStepSize"),
    (0.0, -1e-3, "-0.001"),
    (0.0, math.nan, "NaN"),
    (0.0, math.inf, "inf"),
    (0.5, 1e-3, "0.5"),
    (-1e-3, 1e-3, "currentCommunicationPoint"),
]


@pytest.mark.parametrize("model", SHIPPED)
def test_wrong_communication_points_and_step_sizes(instance, model):
    inst = in_state(instance, model, "StepComplete")
    for t, h, text in STEP_CASES:
        refused(inst, lambda: inst.fmu.doStep(t, h), "fmi2DoStep", text)
    finish(inst, "StepComplete")


@pytest.mark.parametrize("model", SHIPPED)
def test_no_step_past_a_defined_stop_time(instance, model):
    """FMI 2.0 section 2.1.6: fmi2DoStep past the stopTime that
    fmi2SetupExperiment defined returns fmi2Error, and the instance is
    left where it was: the step up to the stop time still works."""
    inst = instance(model)
    inst.fmu.setupExperiment(startTime=0.0, stopTime=0.01)
    inst.fmu.enterInitializationMode()
    inst.fmu.exitInitializationMode()
    inst.fmu.doStep(0.0, 0.005)
    refused(inst, lambda: inst.fmu.doStep(0.005, 0.01), "fmi2DoStep", "past stopTime = 0.01")
    inst.fmu.doStep(0.005, 0.005)
    y = first(inst, "output").valueReference
    assert math.isfinite(inst.fmu.getReal([y])[0])
    inst.fmu.terminate()


def serialized(instance, model):
    inst = in_state(instance, model, "StepComplete")
    for k in range(3):
        inst.fmu.doStep(k * 1e-3, 1e-3)
    state = inst.fmu.getFMUstate()
    data = inst.fmu.serializeFMUstate(state)
    inst.fmu.freeFMUstate(state)
    return bytes(data)


def deserialize(inst, data):
    state = inst.fmu.deSerializeFMUstate(data)
    inst.fmu.setFMUstate(state)
    inst.fmu.freeFMUstate(state)


@pytest.mark.parametrize("model", SHIPPED)
def test_truncated_corrupted_and_foreign_states(instance, model):
    # The states first: FMPy's logger proxy (addLoggerProxy) keeps one
    # logger for the whole process, the last registered, so the instance
    # whose messages are checked is opened last.
    own = serialized(instance, model)
    foreign = {other: serialized(instance, other) for other in SHIPPED if other != model}
    inst = in_state(instance, model, "StepComplete")
    for n in range(0, len(own), 7):
        refused(inst, lambda: deserialize(inst, own[:n]), "fmi2DeSerializeFMUstate")
    for k in range(0, len(own), 5):
        bad = bytearray(own)
        bad[k] ^= 0x20
        refused(inst, lambda: deserialize(inst, bytes(bad)), "fmi2DeSerializeFMUstate")
    for data in foreign.values():
        refused(inst, lambda: deserialize(inst, data), "fmi2DeSerializeFMUstate", "GUID")
    deserialize(inst, own)
    inst.fmu.doStep(3e-3, 1e-3)


@pytest.mark.parametrize("model", SHIPPED)
def test_log_categories_switch_on_and_off(instance, model):
    inst = in_state(instance, model, "StepComplete")
    categories = [c.name for c in inst.md.logCategories] if hasattr(inst.md, "logCategories") else None
    f = inst.fmu
    inst.messages.clear()
    f.doStep(0.0, 1e-3)
    assert inst.messages == []  # loggingOn = false: nothing but errors
    f.setDebugLogging(True, ["logCalls"])
    f.doStep(1e-3, 1e-3)
    assert inst.messages and all(cat == "logCalls" for _, cat, _ in inst.messages), inst.messages
    f.setDebugLogging(False, ["logCalls", "logStatusError"])
    inst.messages.clear()
    with pytest.raises(FMICallException):
        f.doStep(1.0, 1e-3)
    assert inst.messages == []  # errors switched off too
    f.setDebugLogging(True, ["logStatusError"])
    refused(inst, lambda: f.setDebugLogging(True, ["noSuchCategory"]), "fmi2SetDebugLogging",
            "noSuchCategory", "logCalls")
    if categories is not None:
        assert categories == ["logStatusError", "logStatusFatal", "logStatusWarning", "logCalls"]
