"""ServoAxis.fmu (host/tests/c/servo_axis, a hand-written C FMU on
host/tests/c/common/linear_plant.h: a motor driving a carriage through a
belt spring under a PD position controller, friction on the carriage),
imported with FMPy: it passes FMPy's validation; driven by the reference
and the friction force of a run of the independent simulator
(tests/independent/lugre_rig.c, plant=servo), it follows that run's
motion and controller force; its directional derivatives are the step
sensitivity after a step and the direct feedthrough otherwise, against
finite differences by state rollback; misuse is refused with fmi2Error
and a logged reason."""

from __future__ import annotations

import ctypes
import math
import subprocess
import sys
from pathlib import Path

import pytest
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu
from plant_fmus import jacobian, open_plant, stepped_outputs

sys.path.insert(0, str(Path(__file__).resolve().parent / "independent"))
import cases  # noqa: E402
import two_mass_fmu  # noqa: E402

OUTPUTS = ["x_m", "x_l", "v", "a", "u"]
INPUTS = ["r", "F"]

#: A drive train and loop like the suite's servo cases (cases._draw), and a
#: soft LuGre contact with a Stribeck peak, so that the carriage sticks at
#: its reversals and the friction force stays smooth enough to be handed
#: to the FMU sample by sample.
RIG = {"m": 2.0, "k": 3e4, "c": 15.0, "m_m": 0.4, "c_m": 1.2, "Kp": 8000.0, "Kd": 200.0}
FRICTION = {"Fc": 2.0, "Fs": 2.6, "vs": 0.01, "sigma0": 1e5, "sigma1": 2 * 0.7 * math.sqrt(1e5 * 2.0), "sigma2": 5.0}
#: the FMU's parameters for RIG
PARAMETERS = {"m_m": 0.4, "m_l": 2.0, "k_g": 3e4, "c_g": 15.0, "c_m": 1.2, "Kp": 8000.0, "Kd": 200.0}


@pytest.fixture
def axis(tmp_path):
    yield from open_plant(tmp_path, "servo")


def test_fmpy_validates_it(tmp_path):
    fmu = two_mass_fmu.build(tmp_path, "servo")
    assert validate_fmu(str(fmu)) == []


def simulator_run(h: float, duration: float) -> dict[str, list[float]]:
    """The independent simulator's noise-free run (no encoder: resolution
    0), sampled every h."""
    args = [str(cases.simulator())]
    args += [f"{k}={v!r}" for k, v in {**RIG, **FRICTION}.items()]
    args += ["plant=servo", "drive=sines", "amp=0.03", "period=2.5", f"duration={duration}", f"sample={h}",
             "resolution=0", "seed=3", "truth=1"]
    lines = subprocess.run(args, capture_output=True, text=True, check=True).stdout.splitlines()
    names = lines[0].split(",")
    rows = [[float(x) for x in line.split(",")] for line in lines[1:]]
    return {n: [r[i] for r in rows] for i, n in enumerate(names)}


def test_it_follows_the_independent_simulator(tmp_path):
    """The simulator integrates the same loop with the friction force
    computed inside (LuGre); the FMU gets that force and the reference
    sample by sample, each ramped to the next sample over a step of 0.1 ms
    (fmi2SetRealInputDerivatives, as fricsim gives a data input), in
    sub-steps of 10 µs. Over 2 s with sticking and slipping, both
    positions agree to 1e-8 m (1 % of the suite's 1 µm encoder step; they
    differ by the force's ramp between samples: 2.0e-9 m) and the
    controller's force, with the reference the FMU moved to the next
    sample itself, to 1e-5 of its range (2.1e-6)."""
    h, duration = 1e-4, 2.0
    sim = simulator_run(h, duration)
    v = [(b - a) / h for a, b in zip(sim["true_x"], sim["true_x"][1:])]
    stuck = sum(1 for x in v if abs(x) < 1e-4) / len(v)
    assert 0.01 < stuck < 0.5, stuck  # the run sticks and slips
    gen = open_plant(tmp_path, "servo", initialize=False)
    slave, vr, _, _ = next(gen)
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.setReal([vr[n] for n in PARAMETERS], list(PARAMETERS.values()))
    slave.setReal([vr["h_max"]], [h / 10])
    slave.exitInitializationMode()
    r, F = sim["drive.r"], sim["true_F"]
    worst = {"x_m": 0.0, "x_l": 0.0, "u": 0.0}
    for k in range(len(r) - 1):
        slave.setReal([vr["r"], vr["F"]], [r[k], F[k]])
        slave.setRealInputDerivatives([vr["r"], vr["F"]], [1, 1], [(r[k + 1] - r[k]) / h, (F[k + 1] - F[k]) / h])
        slave.doStep(k * h, h)
        x_m, x_l, u = slave.getReal([vr["x_m"], vr["x_l"], vr["u"]])
        worst["x_m"] = max(worst["x_m"], abs(x_m - sim["drive.x_m"][k + 1]))
        worst["x_l"] = max(worst["x_l"], abs(x_l - sim["true_x"][k + 1]))
        worst["u"] = max(worst["u"], abs(u - sim["drive.u"][k + 1]))
    # the step ended with the inputs at the next sample
    assert slave.getReal([vr["r"], vr["F"]]) == pytest.approx([r[-1], F[-1]], rel=1e-9, abs=1e-12)
    slave.terminate()
    u_range = max(sim["drive.u"]) - min(sim["drive.u"])
    assert worst["x_m"] < 1e-8 and worst["x_l"] < 1e-8, worst
    assert worst["u"] < 1e-5 * u_range, (worst, u_range)
    gen.close()


def test_directional_derivatives_are_the_step_sensitivity_after_a_step(axis):
    slave, vr, _, md = axis
    assert md.coSimulation.providesDirectionalDerivative
    h, t = 1e-3, 0.0
    # a few steps along a ramp first, so the state is not at rest
    for _ in range(30):
        slave.setReal([vr["r"], vr["F"]], [0.02 * t, 1.5])
        slave.doStep(t, h)
        t += h
    state = slave.getFMUstate()
    inputs = {"r": 0.02 * t, "F": 1.5}
    stepped_outputs(slave, vr, state, t, h, inputs, OUTPUTS)
    analytic = jacobian(slave, vr, OUTPUTS, INPUTS)
    # central differences outside the FMU by rolling back the state: the
    # loop is linear, so they are exact up to rounding
    for i, delta in (("r", 1e-4), ("F", 1e-2)):
        up = stepped_outputs(slave, vr, state, t, h, {**inputs, i: inputs[i] + delta}, OUTPUTS)
        down = stepped_outputs(slave, vr, state, t, h, {**inputs, i: inputs[i] - delta}, OUTPUTS)
        for o in OUTPUTS:
            fd = (up[o] - down[o]) / (2 * delta)
            assert abs(analytic[(o, i)] - fd) <= 1e-6 * max(abs(fd), 1e-9), (o, i, analytic[(o, i)], fd)
    # over one step the reference moves the motor (and u) more than the
    # carriage, the friction the carriage more than the motor
    assert analytic[("x_m", "r")] > analytic[("x_l", "r")] > 0
    assert analytic[("x_l", "F")] < 0 and abs(analytic[("x_l", "F")]) > abs(analytic[("x_m", "F")])
    # the same from another state and other inputs
    stepped_outputs(slave, vr, state, t, h, {"r": -0.01, "F": -2.0}, OUTPUTS)
    assert jacobian(slave, vr, OUTPUTS, INPUTS) == pytest.approx(analytic, rel=1e-12, abs=1e-300)
    slave.freeFMUstate(state)


def test_directional_derivatives_are_the_feedthrough_before_a_step_or_once_an_input_is_set(axis):
    slave, vr, _, _ = axis
    kp, m_l = slave.getReal([vr["Kp"], vr["m_l"]])
    before = jacobian(slave, vr, OUTPUTS, INPUTS)
    slave.setReal([vr["r"]], [1e-3])
    slave.doStep(0.0, 1e-3)
    after_step = jacobian(slave, vr, OUTPUTS, INPUTS)
    slave.setReal([vr["F"]], [0.7])
    after_set = jacobian(slave, vr, OUTPUTS, INPUTS)
    for j in (before, after_set):
        assert j[("u", "r")] == kp
        assert j[("a", "F")] == pytest.approx(-1.0 / m_l, rel=1e-15)
        assert all(v == 0.0 for k, v in j.items() if k not in (("u", "r"), ("a", "F"))), j
    assert after_step[("x_m", "r")] != 0.0 and after_step[("u", "r")] != kp


def refused(messages, call, text):
    """`call` returns fmi2Error, and the error logged says `text`."""
    messages.clear()
    with pytest.raises(FMICallException) as e:
        call()
    assert e.value.status == 3
    assert any(text in m for s, m in messages if s >= 3), messages


def test_null_arrays_nan_and_calls_out_of_order_are_refused(axis):
    slave, vr, messages, _ = axis
    c, out = slave.component, (ctypes.c_double * 1)()
    refs = (ctypes.c_uint * 1)(vr["x_l"])
    refused(messages, lambda: slave.fmi2GetReal(c, None, 1, out), "NULL")
    refused(messages, lambda: slave.fmi2SetReal(c, refs, 1, None), "NULL")
    refused(messages, lambda: slave.fmi2GetDirectionalDerivative(c, None, 1, refs, 1, out, out), "NULL")
    refused(messages, lambda: slave.fmi2GetFMUstate(c, None), "NULL")
    refused(messages, lambda: slave.setReal([vr["r"]], [math.nan]), "is not finite")
    refused(messages, lambda: slave.setReal([vr["F"]], [math.inf]), "is not finite")
    refused(messages, lambda: slave.getDirectionalDerivative([vr["x_l"]], [vr["r"]], [math.nan]), "is not finite")
    refused(messages, lambda: slave.getDirectionalDerivative([vr["x_l"]], [vr["Kp"]], [1.0]),
            "is not an input (r, F)")
    refused(messages, lambda: slave.getDirectionalDerivative([vr["r"]], [vr["F"]], [1.0]),
            "is not an output (x_m, x_l, v, a, u)")
    refused(messages, lambda: slave.setReal([vr["u"]], [1.0]), "not a settable Real")
    refused(messages, lambda: slave.setRealInputDerivatives([vr["r"]], [2], [1.0]), "derivative order 2 of r")
    refused(messages, lambda: slave.setRealInputDerivatives([vr["Kp"]], [1], [1.0]), "is not an input (r, F)")
    refused(messages, lambda: slave.setRealInputDerivatives([vr["F"]], [1], [math.nan]), "is not finite")
    refused(messages, lambda: slave.fmi2SetRealInputDerivatives(c, refs, 1, None, out), "NULL")
    refused(messages, lambda: slave.setReal([vr["Kp"]], [1.0]), "fixed after initialization")
    refused(messages, lambda: slave.doStep(0.5, 1e-3), "expected currentCommunicationPoint")
    refused(messages, lambda: slave.enterInitializationMode(), "illegal call sequence")
    # a refused call changed nothing: the loop still steps from rest
    slave.doStep(0.0, 1e-3)
    assert slave.getReal([vr["x_l"]]) == [0.0]


def test_parameters_out_of_range_and_steps_before_initialization_are_refused(tmp_path):
    gen = open_plant(tmp_path, "servo", initialize=False)
    slave, vr, messages, _ = next(gen)
    refused(messages, lambda: slave.doStep(0.0, 1e-3), "illegal call sequence")
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    slave.setReal([vr["Kd"]], [-1.0])
    refused(messages, lambda: slave.exitInitializationMode(), "parameter Kd = -1 is out of range")
    slave.setReal([vr["Kd"]], [200.0])
    slave.exitInitializationMode()
    slave.terminate()
    gen.close()
