"""TwoMassDrive.fmu (host/tests/c/two_mass_drive, a hand-written C FMU that is
not made by this project's exporter), imported with FMPy: its directional
derivatives are the step sensitivity right after fmi2DoStep and the direct
feedthrough otherwise, checked against finite differences taken outside the
FMU by state rollback; bad arguments are refused with a logged reason; and
fricsim's Newton master takes its Jacobian from them."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from plant_fmus import open_plant
from plant_fmus import jacobian as plant_jacobian
from plant_fmus import stepped_outputs as plant_stepped_outputs

sys.path.insert(0, str(Path(__file__).resolve().parent / "independent"))
import cases  # noqa: E402

OUTPUTS = ["x_m", "x_l", "v", "a"]
INPUTS = ["u", "F"]


@pytest.fixture
def drive(tmp_path):
    yield from open_plant(tmp_path, "two_mass")


def jacobian(slave, vr):
    return plant_jacobian(slave, vr, OUTPUTS, INPUTS)


def stepped_outputs(slave, vr, state, t, h, inputs):
    return plant_stepped_outputs(slave, vr, state, t, h, {n: inputs[n] for n in INPUTS}, OUTPUTS)


def test_directional_derivatives_are_the_step_sensitivity_after_a_step(drive):
    slave, vr, _, md = drive
    assert md.coSimulation.providesDirectionalDerivative
    h, t = 1e-3, 0.0
    inputs = {"u": 3.0, "F": -1.0}
    # a few steps first, so the state is not at rest
    for _ in range(20):
        slave.setReal([vr[n] for n in INPUTS], [inputs[n] for n in INPUTS])
        slave.doStep(t, h)
        t += h
    state = slave.getFMUstate()
    stepped_outputs(slave, vr, state, t, h, inputs)
    analytic = jacobian(slave, vr)
    # central differences outside the FMU, by rolling back the state; the
    # plant is linear, so they are exact up to rounding
    delta = 1e-2
    for i in INPUTS:
        up = stepped_outputs(slave, vr, state, t, h, {**inputs, i: inputs[i] + delta})
        down = stepped_outputs(slave, vr, state, t, h, {**inputs, i: inputs[i] - delta})
        for o in OUTPUTS:
            fd = (up[o] - down[o]) / (2 * delta)
            scale = max(abs(fd), 1e-9)
            assert abs(analytic[(o, i)] - fd) <= 1e-7 * scale, (o, i, analytic[(o, i)], fd)
    # F acts on the load: over one step it moves the load more than the motor
    assert analytic[("x_l", "F")] < 0 and abs(analytic[("x_l", "F")]) > abs(analytic[("x_m", "F")])
    # the plant is linear: the same from another state and other inputs
    stepped_outputs(slave, vr, state, t, h, {"u": -5.0, "F": 2.0})
    assert jacobian(slave, vr) == pytest.approx(analytic, rel=1e-12, abs=1e-300)
    slave.freeFMUstate(state)


def test_directional_derivatives_are_the_feedthrough_once_an_input_is_set(drive):
    slave, vr, _, _ = drive
    m_l = slave.getReal([vr["m_l"]])[0]
    before = jacobian(slave, vr)
    slave.setReal([vr["F"]], [0.5])
    slave.doStep(0.0, 1e-3)
    after_step = jacobian(slave, vr)
    slave.setReal([vr["F"]], [0.7])
    after_set = jacobian(slave, vr)
    for j in (before, after_set):
        assert j[("a", "F")] == pytest.approx(-1.0 / m_l, rel=1e-15)
        assert all(v == 0.0 for k, v in j.items() if k != ("a", "F"))
    assert after_step[("x_l", "F")] != 0.0
    # seeds add linearly: (u, F) with seeds (2, 3)
    slave.doStep(1e-3, 1e-3)
    combined = slave.getDirectionalDerivative([vr["x_l"]], [vr["u"], vr["F"]], [2.0, 3.0])[0]
    single = jacobian(slave, vr)
    assert combined == pytest.approx(2 * single[("x_l", "u")] + 3 * single[("x_l", "F")], rel=1e-12)


def test_states_and_their_partial_derivatives(drive):
    """The continuous states are listed (ModelStructure/Derivatives) and
    readable, and with a state among the knowns or a derivative among the
    unknowns the directional derivatives are the continuous-time partial
    derivatives (FMI 2.0 §2.1.9), what fricsim's output sensitivities are
    built from: here the equations of the file's header by hand."""
    slave, vr, messages, md = drive
    derivatives = [v for v in md.modelVariables if v.derivative is not None]
    assert sorted(v.name for v in derivatives) == ["der(v)", "der(v_m)", "der(x_l)", "der(x_m)"]
    assert sorted(v.derivative.name for v in derivatives) == ["v", "v_m", "x_l", "x_m"]
    slave.setReal([vr["u"], vr["F"]], [3.0, 0.5])
    for k in range(20):
        slave.doStep(k * 1e-3, 1e-3)
    x_m, v_m, x_l, v, a, dx_m, dv_m, dx_l, dv = slave.getReal(
        [vr[n] for n in ["x_m", "v_m", "x_l", "v", "a", "der(x_m)", "der(v_m)", "der(x_l)", "der(v)"]])
    assert v_m != 0.0 and dx_m == v_m and dx_l == v and dv == a
    m_m, m_l, k_b, c_b, c_m = 0.5, 2.0, 2e4, 20.0, 1.0
    assert dv_m == pytest.approx((3.0 - k_b * (x_m - x_l) - c_b * (v_m - v) - c_m * v_m) / m_m, rel=1e-12)

    def partial(unknown, known):
        return slave.getDirectionalDerivative([vr[unknown]], [vr[known]], [1.0])[0]

    assert partial("der(v)", "x_m") == pytest.approx(k_b / m_l, rel=1e-15)
    assert partial("der(v)", "v") == pytest.approx(-c_b / m_l, rel=1e-15)
    assert partial("der(v_m)", "v_m") == pytest.approx(-(c_b + c_m) / m_m, rel=1e-15)
    assert partial("der(x_m)", "v_m") == 1.0
    assert partial("der(v)", "F") == pytest.approx(-1.0 / m_l, rel=1e-15)
    assert partial("der(v_m)", "u") == pytest.approx(1.0 / m_m, rel=1e-15)
    # an output by a state: continuous too (a = der(v))
    assert partial("a", "x_l") == pytest.approx(-k_b / m_l, rel=1e-15)
    # a state or derivative is read, never set
    for name in ["v_m", "der(v)"]:
        with pytest.raises(Exception):
            slave.setReal([vr[name]], [1.0])
    assert any("state or state derivative v_m" in m for s, m in messages if s >= 3), messages


@pytest.mark.parametrize(
    "unknown,known,seed,message",
    [
        ("m_l", "F", 1.0, "is not an output"),
        ("x_l", "m_l", 1.0, "is not an input"),
        ("x_l", "F", float("nan"), "is not finite"),
    ],
)
def test_bad_directional_derivative_calls_are_refused_with_a_reason(drive, unknown, known, seed, message):
    slave, vr, messages, _ = drive
    with pytest.raises(Exception):
        slave.getDirectionalDerivative([vr[unknown]], [vr[known]], [seed])
    assert any(message in m for s, m in messages if s >= 3), messages


def test_fricsims_newton_master_uses_them(tmp_path):
    case = cases.draw("two_mass_viscous", 0.1, 7)
    data, ssd = cases.make(case, tmp_path)
    rows = data.read_text().splitlines()
    inputs = tmp_path / "u.csv"
    inputs.write_text("\n".join(",".join(r.split(",")[:2]) for r in rows[:2001]) + "\n")
    fricsim = cases.ROOT / "target" / "release" / "fricsim"
    run = subprocess.run(
        [str(fricsim), "run", str(ssd), "--input", str(inputs), "--master", "newton", "--out", str(tmp_path / "r.csv")],
        capture_output=True, text=True,
    )
    assert run.returncode == 0, run.stderr
    report = run.stdout + run.stderr
    assert "Jacobian of drive: directional derivatives (checked against finite differences)" in report, report
