"""Rig1D.fmu lists its continuous states, the position x and the body
velocity v_body (ModelStructure/Derivatives, with der(x) and der(v_body)),
imported with FMPy: with a state among the knowns or a derivative among the
unknowns its directional derivatives are the continuous-time partial
derivatives (FMI 2.0 section 2.1.9), here against the rig's equations by
hand (docs/models.md, Rig1D); outputs by inputs alone stay the step
sensitivity a strongly coupled master takes; a saturated controller adds
nothing; the quasi-static mode (m = 0) refuses them with the reason."""

from __future__ import annotations

from pathlib import Path

import pytest
from plant_fmus import open_fmu

RIG1D = Path(__file__).resolve().parent.parent / "dist" / "Rig1D.fmu"

# the controller on an input reference: PD on the position, PI on the
# velocity (the integral xi of v_ref - v_body), a spring and damping too
M, C, K = 1.5, 0.5, 10.0
KP, KD, KI, FF, GAIN = 4000.0, 60.0, 2e4, 0.7, 1.3
LOOP = {"m": M, "c": C, "k": K, "control": 2, "ctrl_kp": KP, "ctrl_kd": KD, "ctrl_ki": KI,
        "ctrl_ff": FF, "ctrl_gain": GAIN}


def stepped(slave, vr, inputs, steps=20, h=1e-3):
    """`steps` steps of `h` with `inputs` (name: value) held."""
    slave.setReal([vr[n] for n in inputs], list(inputs.values()))
    for k in range(steps):
        slave.doStep(k * h, h)


@pytest.fixture
def loop(tmp_path):
    yield from open_fmu(tmp_path, RIG1D, LOOP)


def test_the_states_are_listed_and_read(loop):
    slave, vr, _, md = loop
    derivatives = {v.name: v.derivative.name for v in md.modelVariables if v.derivative is not None}
    assert derivatives == {"der(x)": "x", "der(v_body)": "v_body"}
    assert sorted(u.variable.name for u in md.derivatives) == ["der(v_body)", "der(x)"]
    stepped(slave, vr, {"F": 0.4, "x_ref": 1e-3, "v_ref": 2e-3})
    v_body, a, dx, dv = slave.getReal([vr[n] for n in ["v_body", "a", "der(x)", "der(v_body)"]])
    assert v_body != 0.0 and dx == v_body and dv == a


def test_partial_derivatives_are_the_equations_by_hand(loop):
    slave, vr, _, _ = loop
    stepped(slave, vr, {"F": 0.4, "x_ref": 1e-3, "v_ref": 2e-3})
    u = slave.getReal([vr["u_ctrl"]])[0]
    assert u != 0.0  # the loop works, unsaturated (no u_max)

    def partial(unknown, known):
        return slave.getDirectionalDerivative([vr[unknown]], [vr[known]], [1.0])[0]

    # m*a = k*(x_a - x) - c*v_body + F_ext - F + G*u, u = Kp*(x_ref - x)
    # + Kd*(ff*v_ref - v_body) + Ki*xi, xi = integral(v_ref) - (x - x0)
    assert partial("der(v_body)", "x") == pytest.approx((-K - GAIN * (KP + KI)) / M, rel=1e-14)
    assert partial("der(v_body)", "v_body") == pytest.approx((-C - GAIN * KD) / M, rel=1e-14)
    assert partial("der(v_body)", "F") == pytest.approx(-1.0 / M, rel=1e-14)
    assert partial("der(v_body)", "F_ext") == pytest.approx(1.0 / M, rel=1e-14)
    assert partial("der(v_body)", "x_ref") == pytest.approx(GAIN * KP / M, rel=1e-14)
    assert partial("der(v_body)", "v_ref") == pytest.approx(GAIN * KD * FF / M, rel=1e-14)
    assert partial("der(x)", "v_body") == 1.0 and partial("der(x)", "x") == 0.0
    # outputs by a state: continuous too
    assert partial("u_ctrl", "x") == pytest.approx(-(KP + KI), rel=1e-14)
    assert partial("F_ctrl", "v_body") == pytest.approx(-GAIN * KD, rel=1e-14)
    assert partial("F_app", "x") == pytest.approx(-K - GAIN * (KP + KI), rel=1e-14)
    assert partial("v", "v_body") == 1.0 and partial("x_rel", "x") == 1.0
    # a call with a state known and an input known: the sum of both
    both = slave.getDirectionalDerivative([vr["der(v_body)"]], [vr["x"], vr["F"]], [2.0, 3.0])[0]
    assert both == pytest.approx(2 * partial("der(v_body)", "x") + 3 * partial("der(v_body)", "F"), rel=1e-14)


def test_outputs_by_inputs_alone_stay_the_step_sensitivity(loop):
    """No state among the knowns, no derivative among the unknowns: the
    step sensitivity right after a step (what fricsim's Newton master
    reads), not the continuous partial (which is 0 for v by F)."""
    slave, vr, _, _ = loop
    stepped(slave, vr, {"F": 0.4, "x_ref": 1e-3, "v_ref": 2e-3})
    step = slave.getDirectionalDerivative([vr["v"]], [vr["F"]], [1.0])[0]
    continuous = slave.getDirectionalDerivative([vr["der(x)"]], [vr["F"]], [1.0])[0]
    assert continuous == 0.0
    # over h = 1 ms the force moves the velocity by about -h/m
    assert step == pytest.approx(-1e-3 / M, rel=0.2)


def test_a_saturated_controller_adds_nothing(tmp_path):
    # one instance, terminated and freed when the loop resumes the generator
    for slave, vr, _, _ in open_fmu(tmp_path, RIG1D, {**LOOP, "ctrl_u_max": 0.05}):
        stepped(slave, vr, {"F": 0.4, "x_ref": 1e-2, "v_ref": 0.0}, steps=5)
        assert abs(slave.getReal([vr["u_ctrl"]])[0]) == pytest.approx(0.05, rel=1e-12)
        partial = slave.getDirectionalDerivative([vr["der(v_body)"]], [vr["x"]], [1.0])[0]
        assert partial == pytest.approx(-K / M, rel=1e-14)
        assert slave.getDirectionalDerivative([vr["u_ctrl"]], [vr["x"]], [1.0])[0] == 0.0


def test_the_quasi_static_mode_refuses_them_and_states_are_never_set(tmp_path):
    for slave, vr, messages, _ in open_fmu(tmp_path, RIG1D, {"m": 0.0, "c": 1.0}):
        with pytest.raises(Exception):
            slave.getDirectionalDerivative([vr["der(x)"]], [vr["x"]], [1.0])
        assert any("quasi-static mode (m = 0)" in m for s, m in messages if s >= 3), messages
        for name in ["der(x)", "der(v_body)"]:
            with pytest.raises(Exception):
                slave.setReal([vr[name]], [1.0])
