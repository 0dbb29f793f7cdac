"""Bad input through FMPy: parameters outside their declared min/max are
refused when set, other invalid parameters at
fmi2ExitInitializationMode, NaN/inf inputs, unknown value references and
calls in the wrong state return fmi2Error, each with a logged message that
names the function and the value; the instance stays usable."""

import math

import pytest
from fmpy.fmi1 import FMICallException

# Within the declared bounds, but no valid model: refused at initialization.
INVALID_PARAMETERS = [
    ("Dahl", {"sigma": 0.0}, "sigma"),
    ("LuGre", {"Fc": 1.0, "Fs": 0.5}, "Fs"),
    ("LuGre", {"vs": 0.0}, "vs"),
    ("ResetIntegrator", {"z0": 0.0}, "z0"),
    ("Bristle", {"delta_max": 0.0}, "delta_max"),
    ("Bristle", {"count_from_load": False, "n_bristles": 0}, "n_bristles"),
    ("Bristle2D", {"z0": 0.0}, "z0"),
]
# Outside the min/max of the model description: refused when set, also when
# the options in force do not read the parameter (LuGre's Fc_neg and
# scale_neg with direction_dependent off).
OUT_OF_BOUNDS = [
    ("Dahl", "alpha", -1.0),
    ("LuGre", "sigma0", -1.0),
    ("LuGre", "Fc_neg", -0.5),
    ("LuGre", "sigma2_neg", -1.0),
    ("LuGre", "scale_neg[3]", -1.0),
    ("ResetIntegrator", "sigma0", -5.0),
    ("Bristle2D", "sigma02", -1.0),
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


@pytest.mark.parametrize("model,parameter,value", OUT_OF_BOUNDS)
def test_parameter_outside_its_declared_bounds_refused_when_set(instance, model, parameter, value):
    inst = instance(model)
    variable = next(v for v in inst.md.modelVariables if v.name == parameter)
    low = float(variable.min) if variable.min is not None else -math.inf
    high = float(variable.max) if variable.max is not None else math.inf
    assert not low <= value <= high, "the case must lie outside the declared bounds"
    inst.fmu.setupExperiment(startTime=0.0)
    inst.fmu.enterInitializationMode()
    before = inst.fmu.getReal([inst.vr[parameter]])[0]
    with pytest.raises(FMICallException) as e:
        inst.fmu.setReal([inst.vr[parameter]], [value])
    assert e.value.status == 3  # fmi2Error
    message = inst.last_error()
    assert message.startswith(f"fmi2SetReal: {parameter} (value reference {inst.vr[parameter]}) = "), message
    assert "declared min" in message or "declared max" in message, message
    # nothing changed, and the instance initialises
    assert inst.fmu.getReal([inst.vr[parameter]])[0] == before
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
