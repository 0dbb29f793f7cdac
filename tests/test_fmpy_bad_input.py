"""Bad input through FMPy (issue 2): invalid parameters are refused at
fmi2ExitInitializationMode, NaN/inf inputs, unknown value references and
calls in the wrong state return fmi2Error, each with a logged message that
names the function and the value; the instance stays usable."""

import math

import pytest
from fmpy.fmi1 import FMICallException

INVALID_PARAMETERS = [
    ("Dahl", {"sigma": 0.0}, "sigma"),
    ("Dahl", {"alpha": -1.0}, "alpha"),
    ("LuGre", {"sigma0": -1.0}, "sigma0"),
    ("LuGre", {"Fc": 1.0, "Fs": 0.5}, "Fs"),
    ("LuGre", {"vs": 0.0}, "vs"),
    ("ResetIntegrator", {"z0": 0.0}, "z0"),
    ("ResetIntegrator", {"sigma0": -5.0}, "sigma0"),
    ("Bristle", {"delta_max": 0.0}, "delta_max"),
    ("Bristle", {"count_from_load": False, "n_bristles": 0}, "n_bristles"),
    ("Bristle2D", {"z0": 0.0}, "z0"),
    ("Bristle2D", {"sigma02": -1.0}, "sigma02"),
]


def set_values(inst, values):
    for name, value in values.items():
        vr = inst.vr[name]
        if isinstance(value, bool):
            inst.fmu.setBoolean([vr], [value])
        elif isinstance(value, int):
            inst.fmu.setInteger([vr], [value])
        else:
            inst.fmu.setReal([vr], [value])


@pytest.mark.parametrize("model,values,parameter", INVALID_PARAMETERS)
def test_invalid_parameter_refused_at_exit_initialization(instance, model, values, parameter):
    inst = instance(model)
    inst.fmu.setupExperiment(startTime=0.0)
    inst.fmu.enterInitializationMode()
    set_values(inst, values)
    with pytest.raises(FMICallException) as e:
        inst.fmu.exitInitializationMode()
    assert e.value.status == 3  # fmi2Error
    message = inst.last_error()
    assert "fmi2ExitInitializationMode" in message
    assert parameter in message, message
    # the value is named too (e.g. "z0 = 0")
    assert f"{parameter} = " in message, message
    # nothing is lost: fix the parameter and initialise
    inst.fmu.reset()
    inst.fmu.setupExperiment(startTime=0.0)
    inst.fmu.enterInitializationMode()
    inst.fmu.exitInitializationMode()
    inst.fmu.doStep(0.0, 1e-3)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("model,input_name", [("Dahl", "v"), ("LuGre", "v"), ("LuGre", "Fn"),
                                              ("ResetIntegrator", "v"), ("Bristle", "x"),
                                              ("Bristle2D", "v2")])
def test_non_finite_input_refused_and_instance_usable(instance, model, input_name, bad):
    inst = instance(model)
    inst.fmu.setupExperiment(startTime=0.0)
    inst.fmu.enterInitializationMode()
    inst.fmu.exitInitializationMode()
    vr = inst.vr[input_name]
    inst.fmu.setReal([vr], [1e-4 if input_name != "Fn" else 2.0])
    with pytest.raises(FMICallException) as e:
        inst.fmu.setReal([vr], [bad])
    assert e.value.status == 3
    message = inst.last_error()
    assert "fmi2SetReal" in message and input_name in message and str(bad).lower() in message.lower(), message
    # the previous value is kept and the instance steps on
    assert inst.fmu.getReal([vr]) == [1e-4 if input_name != "Fn" else 2.0]
    inst.fmu.doStep(0.0, 1e-3)


def test_unknown_value_reference(instance):
    inst = instance("LuGre")
    inst.fmu.setupExperiment(startTime=0.0)
    inst.fmu.enterInitializationMode()
    inst.fmu.exitInitializationMode()
    with pytest.raises(FMICallException):
        inst.fmu.getReal([99999])
    assert "fmi2GetReal" in inst.last_error() and "99999" in inst.last_error()
    with pytest.raises(FMICallException):
        inst.fmu.setReal([4242], [1.0])
    assert "fmi2SetReal" in inst.last_error() and "4242" in inst.last_error()


def test_wrong_state_calls(instance):
    inst = instance("Dahl")
    with pytest.raises(FMICallException):
        inst.fmu.doStep(0.0, 1e-3)
    assert "fmi2DoStep" in inst.last_error() and "Instantiated" in inst.last_error()
    inst.fmu.setupExperiment(startTime=0.0)
    inst.fmu.enterInitializationMode()
    inst.fmu.exitInitializationMode()
    with pytest.raises(FMICallException):
        inst.fmu.enterInitializationMode()
    assert "fmi2EnterInitializationMode" in inst.last_error()
    # a fixed parameter cannot change after initialisation
    with pytest.raises(FMICallException):
        inst.fmu.setReal([inst.vr["sigma"]], [1.0])
    assert "sigma" in inst.last_error()
    # still usable
    inst.fmu.doStep(0.0, 1e-3)


def test_wrong_communication_point_and_step(instance):
    inst = instance("ResetIntegrator")
    inst.fmu.setupExperiment(startTime=0.0)
    inst.fmu.enterInitializationMode()
    inst.fmu.exitInitializationMode()
    with pytest.raises(FMICallException):
        inst.fmu.doStep(0.5, 1e-3)
    assert "currentCommunicationPoint" in inst.last_error() and "0.5" in inst.last_error()
    for h in (0.0, -1e-3, math.nan):
        with pytest.raises(FMICallException):
            inst.fmu.doStep(0.0, h)
        assert "communicationStepSize" in inst.last_error()
    inst.fmu.doStep(0.0, 1e-3)
    inst.fmu.doStep(1e-3, 1e-3)


def test_logging_switch(instance):
    inst = instance("LuGre", logging_on=True)
    inst.fmu.setupExperiment(startTime=0.0)
    assert any(c == "logCalls" and "fmi2SetupExperiment" in m for _, c, m in inst.messages)
    inst.fmu.setDebugLogging(False, [])
    n = len(inst.messages)
    inst.fmu.enterInitializationMode()
    assert len(inst.messages) == n
    with pytest.raises(FMICallException):
        inst.fmu.setDebugLogging(True, ["noSuchCategory"])
    assert "noSuchCategory" in inst.last_error()
