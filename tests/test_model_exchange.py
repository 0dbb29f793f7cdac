"""Model Exchange: the friction FMUs integrated by the importer's own
solver (issue 22).

- Dahl under a prescribed velocity, by FMPy's `simulate_fmu(...,
  fmi_type='ModelExchange', solver='CVode')`, against Dahl's closed form.
- The LuGre stick-slip benchmark of `examples/stick_slip.ssd` (Canudas de
  Wit et al. 1995: a 1 kg mass on a 2 N/m spring pulled at 0.1 m/s) with
  LuGre.fmu in Model Exchange and the rig's mass-spring ODE in Python, the
  combined state integrated by CVode (`fmpy.sundials`, BDF), against the
  monolithic reference (`fricsim reference`, Radau IIA at rtol 1e-10) and
  the reference figures of docs/models.md.
- The reset integrator: the event indicators cross zero where the strain
  reaches its limits and where a reversal releases it, at the times the
  closed form gives, and CVode's result equals the Co-Simulation FMU's.
- The 2-D bristle sliding on its boundary under a turning slip velocity:
  CVode's result equals the Co-Simulation FMU's.
"""

from ctypes import POINTER, c_double, c_int, c_uint32
import math
import shutil
import subprocess

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Model, FMU2Slave
from fmpy.fmi3 import FMU3Model
from fmpy.sundials import CVodeSolver

from conftest import DIST, ROOT, fmu_path

FRICSIM = ROOT / "target" / "release" / "fricsim"


class _NoInput:
    """FMPy's solver applies its input object in the root function; the
    runs here set their inputs themselves."""

    def apply(self, time, **kwargs):
        pass


class Fmi3Model:
    """An FMI 3.0 Model Exchange FMU (FMPy's `FMU3Model`) behind the calls
    `MeRun` makes of FMI 2.0's `FMU2Model`, each mapped to its FMI 3.0
    function: the same run drives either version."""

    def __init__(self, md, unzipdir):
        # (FMPy keeps the instantiation token as `guid`)
        self.fmu = FMU3Model(guid=md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=md.modelExchange.modelIdentifier, instanceName="me")
        self.start = 0.0

    def __getattr__(self, name):
        # instantiate, exitInitializationMode, enterEventMode, setTime, ...
        return getattr(self.fmu, name)

    def setupExperiment(self, startTime):
        self.start = startTime

    def enterInitializationMode(self):
        self.fmu.enterInitializationMode(startTime=self.start)

    def setReal(self, vr, values):
        self.fmu.setFloat64(vr, values)

    def getReal(self, vr):
        return self.fmu.getFloat64(vr)

    def newDiscreteStates(self):
        return self.fmu.updateDiscreteStates()

    def getDerivatives(self, px, n):
        self.fmu.getContinuousStateDerivatives(px, n)


class MeRun:
    """An FMU in Model Exchange (FMPy's `FMU2Model`) integrated by CVode
    together with states of its environment: the combined state is
    `[environment states..., FMU states...]`. `inputs(t, xe)` gives the
    FMU's inputs from the time and the environment states, `rhs(t, xe, y)`
    the environment's derivatives from its states and the FMU's outputs
    `y` (by name). Events (the FMU's indicators) go through event mode and
    `fmi2NewDiscreteStates`, then CVode restarts; each is recorded as
    (time, roots, indicators after the event)."""

    def __init__(self, name, tmp_path, parameters, inputs, outputs, x0=(), nominals=(), rhs=None,
                 rtol=1e-9, path=None):
        path = str(path or fmu_path(name))
        self.md = read_model_description(path)
        assert self.md.modelExchange is not None, f"{name} has no Model Exchange interface"
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.unzipdir = extract(path, unzipdir=str(tmp_path / f"{name}_me"))
        if self.md.fmiVersion == "3.0":
            self.fmu = Fmi3Model(self.md, self.unzipdir)
        else:
            self.fmu = FMU2Model(guid=self.md.guid, unzipDirectory=self.unzipdir,
                                 modelIdentifier=self.md.modelExchange.modelIdentifier,
                                 instanceName="me")
        self.inputs, self.outputs, self.rhs = inputs, list(outputs), rhs
        self.ne = len(x0)
        self.nf = self.md.numberOfContinuousStates
        self.nz = self.md.numberOfEventIndicators
        self.extra_nominals = np.array(nominals, dtype=float)
        self.t = 0.0
        self.x = np.zeros(self.ne + self.nf)
        self.x[:self.ne] = x0
        self.buffer = np.zeros(self.nf)
        self.events = []
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for k, v in parameters.items():
            if isinstance(v, bool):
                self.fmu.setBoolean([self.vr[k]], [v])
            else:
                self.fmu.setReal([self.vr[k]], [v])
        self._set_inputs()
        self.fmu.exitInitializationMode()
        self._event_iteration()
        self.fmu.enterContinuousTimeMode()
        self._read_fmu_states()
        self.rtol = rtol

    def _pointer(self, array):
        return array.ctypes.data_as(POINTER(c_double))

    def _set_inputs(self):
        for k, v in self.inputs(self.t, self.x[:self.ne]).items():
            self.fmu.setReal([self.vr[k]], [v])

    def _read_fmu_states(self):
        self.fmu.getContinuousStates(self._pointer(self.buffer), self.nf)
        self.x[self.ne:] = self.buffer

    def _event_iteration(self):
        changed = False
        while True:
            needed, terminate, _, values_changed, _, _ = self.fmu.newDiscreteStates()
            assert not terminate
            changed |= bool(values_changed)
            if not needed:
                return changed

    # the callbacks of fmpy.sundials.CVodeSolver
    def set_time(self, t):
        self.t = t
        self.fmu.setTime(t)

    def set_x(self, px, n):
        self.x[:] = np.ctypeslib.as_array(px, (n,))
        self.buffer[:] = self.x[self.ne:]
        self.fmu.setContinuousStates(self._pointer(self.buffer), self.nf)
        self._set_inputs()

    def get_x(self, px, n):
        np.ctypeslib.as_array(px, (n,))[:] = self.x

    def get_dx(self, pdx, n):
        dx = np.ctypeslib.as_array(pdx, (n,))
        self.fmu.getDerivatives(self._pointer(self.buffer), self.nf)
        dx[self.ne:] = self.buffer
        if self.ne:
            dx[:self.ne] = self.rhs(self.t, self.x[:self.ne], self.output_values())

    def get_z(self, pz, nz):
        self.fmu.getEventIndicators(pz, nz)

    def get_nominals(self, pn, n):
        nominal = np.ctypeslib.as_array(pn, (n,))
        self.fmu.getNominalsOfContinuousStates(self._pointer(self.buffer), self.nf)
        nominal[self.ne:] = self.buffer
        nominal[:self.ne] = self.extra_nominals

    def output_values(self):
        values = self.fmu.getReal([self.vr[o] for o in self.outputs])
        return dict(zip(self.outputs, values))

    def indicators(self):
        z = np.zeros(self.nz)
        self.fmu.getEventIndicators(self._pointer(z), self.nz)
        return z

    def run(self, times):
        """The environment states and FMU outputs at `times`."""
        solver = CVodeSolver(nx=self.ne + self.nf, nz=self.nz, get_x=self.get_x, set_x=self.set_x,
                             get_dx=self.get_dx, get_z=self.get_z, get_nominals=self.get_nominals,
                             set_time=self.set_time, input=_NoInput(), startTime=times[0],
                             maxStep=0.01, relativeTolerance=self.rtol, maxNumSteps=100000)
        rows = [self._row()]
        t = times[0]
        for t_next in times[1:]:
            while True:
                root, roots, t = solver.step(t, t_next)
                self.set_time(t)
                self.set_x(self._pointer(self.x), len(self.x))
                # no step events (completedIntegratorStepNotNeeded), but it must say so
                assert self.fmu.completedIntegratorStep() == (False, False)
                if root:
                    self.fmu.enterEventMode()
                    self._event_iteration()
                    self.fmu.enterContinuousTimeMode()
                    self._read_fmu_states()
                    self.events.append((t, roots.copy(), self.indicators(), self.x.copy()))
                    solver.reset(t)
                if math.isclose(t, t_next, rel_tol=0, abs_tol=1e-12) or t >= t_next:
                    break
            rows.append(self._row())
        del solver
        return np.array(rows)

    def _row(self):
        return np.concatenate([self.x[:self.ne], list(self.output_values().values())])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
        shutil.rmtree(self.unzipdir, ignore_errors=True)


def co_simulation(name, tmp_path, inputs, outputs, stop, step):
    """The FMU in Co-Simulation (FMPy's `FMU2Slave`) with each input moving
    linearly over a step from its value at the step's start to its value
    at the end (`fmi2SetRealInputDerivatives`, the interpolation the FMUs
    integrate exactly); `outputs` at every step. (FMPy's own
    `simulate_fmu(..., set_input_derivatives=True)` takes exactly nine
    inputs in 0.3.32.)"""
    md = read_model_description(str(fmu_path(name)))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipdir = extract(str(fmu_path(name)), unzipdir=str(tmp_path / f"{name}_cs"))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=name, instanceName="cs")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    names = list(inputs(0.0))
    fmu.setReal([vr[n] for n in names], list(inputs(0.0).values()))
    fmu.exitInitializationMode()
    n = round(stop / step)
    rows = [fmu.getReal([vr[o] for o in outputs])]
    order = (c_int * len(names))(*([1] * len(names)))
    refs = (c_uint32 * len(names))(*[vr[k] for k in names])
    for i in range(n):
        t, t_next = i * step, (i + 1) * step
        now, then = inputs(t), inputs(t_next)
        fmu.setReal([vr[k] for k in names], [now[k] for k in names])
        slopes = (c_double * len(names))(*[(then[k] - now[k]) / step for k in names])
        fmu.fmi2SetRealInputDerivatives(fmu.component, refs, len(names), order, slopes)
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=step)
        rows.append(fmu.getReal([vr[o] for o in outputs]))
    fmu.terminate()
    fmu.freeInstance()
    shutil.rmtree(unzipdir, ignore_errors=True)
    return np.array(rows)


# ---- Dahl ---------------------------------------------------------------------

def dahl_closed_form(t, sigma, fc, alpha, v0, t_reversal):
    """Dahl's force under v = +v0, then -v0 from `t_reversal` on, from
    F = 0 (Dahl 1968; Sun et al. 2016, eq. 2-3; docs/models.md "Dahl"): in
    the displacement u travelled in one direction, y = 1 - F*s/Fc obeys
    dy/du = -(sigma/Fc)*y^alpha, so y = y0*exp(-sigma*u/Fc) for alpha = 1
    and 1/y = 1/y0 + sigma*u/Fc for alpha = 2."""
    def relax(y0, u):
        if alpha == 1.0:
            return y0 * np.exp(-sigma * u / fc)
        assert alpha == 2.0
        return 1.0 / (1.0 / y0 + sigma * u / fc)
    forward = np.minimum(t, t_reversal) * v0
    f = fc * (1.0 - relax(1.0, forward))
    f1 = fc * (1.0 - relax(1.0, t_reversal * v0))
    back = np.maximum(t - t_reversal, 0.0) * v0
    # after the reversal s = -1: y = 1 + F/Fc, from y1 = 1 + F1/Fc
    f_back = fc * (relax(1.0 + f1 / fc, back) - 1.0)
    return np.where(t <= t_reversal, f, f_back)


@pytest.mark.parametrize("alpha,offset", [(1.0, 0.0), (2.0, 0.0), (1.0, -3.1648)])
def test_dahl_model_exchange_follows_the_closed_form(alpha, offset):
    """The state is the force of the law F_dahl; the output F = F_dahl +
    F_offset is the closed form shifted by the offset (from F = F_offset at
    the start)."""
    sigma, fc, v0, t1 = 87750.0, 2.0, 1e-4, 1.0  # Sun et al. 2016, Table 7; 8.8 Fc/sigma each way
    signal = np.rec.fromarrays([np.array([0.0, t1, t1, 2.0]), np.array([v0, v0, -v0, -v0])],
                               names=["time", "v"])
    errors = {}
    for rtol in (1e-6, 1e-9):
        r = simulate_fmu(str(fmu_path("Dahl")), fmi_type="ModelExchange", solver="CVode",
                         stop_time=2.0, output_interval=0.01, input=signal, relative_tolerance=rtol,
                         start_values={"alpha": alpha, "F_offset": offset},
                         output=["F", "z", "F_dahl", "der(F_dahl)"])
        expected = dahl_closed_form(r["time"], sigma, fc, alpha, v0, t1)
        errors[rtol] = np.max(np.abs(r["F_dahl"] - expected))
        assert r["F_dahl"][0] == 0.0 and r["F"][0] == offset
        assert np.array_equal(r["F"], r["F_dahl"] + offset)
        assert np.allclose(r["z"], r["F_dahl"] / sigma, rtol=1e-15, atol=0)
    # within 1e-6 of Fc at rtol 1e-9; and the error is the integrator's:
    # it shrinks with the tolerance
    assert errors[1e-9] <= 1e-6 * fc, errors
    assert errors[1e-9] < errors[1e-6] / 100, errors
    # both branches covered: most of the way to +Fc before the reversal
    # (0.998 Fc for alpha = 1, 0.81 Fc for alpha = 2), past -Fc/2 at the end
    assert r["F_dahl"][r["time"] <= t1].max() > 0.8 * fc
    assert r["F_dahl"][-1] < -0.5 * fc


# ---- the LuGre stick-slip benchmark ---------------------------------------------

def stick_slip_figures(t, v, f, threshold=0.05):
    """First slip (v first above `threshold`), period (between the last two
    such crossings), peak friction force and peak velocity, as
    host/tests/integration/stick_slip.rs and docs/models.md state them."""
    up = [t[i - 1] + (threshold - v[i - 1]) / (v[i] - v[i - 1]) * (t[i] - t[i - 1])
          for i in range(1, len(v)) if v[i - 1] < threshold <= v[i]]
    assert len(up) >= 3, f"expected periodic stick-slip, got slips at {up}"

    def peak(y):
        i = int(np.argmax(y))
        a, b, c = y[i - 1], y[i], y[i + 1]
        s = 0.5 * (a - c) / (a - 2 * b + c)
        return b - 0.25 * (a - c) * s
    return {"first slip": up[0], "period": up[-1] - up[-2], "peak force": peak(f),
            "peak velocity": peak(v)}


@pytest.fixture(scope="module")
def stick_slip_reference(tmp_path_factory):
    """`fricsim reference` of examples/stick_slip.ssd (the monolithic
    Radau IIA solution, rtol 1e-10) over 30 s (three slips, as
    host/tests/integration/stick_slip.rs runs it) at 1e-3 s: time, rig.v,
    friction.F."""
    assert FRICSIM.exists(), f"{FRICSIM} is missing: run ./build-fmu.sh"
    out = tmp_path_factory.mktemp("reference") / "stick_slip_reference.csv"
    subprocess.run([str(FRICSIM), "reference", str(DIST / "stick_slip.ssp"), "--step", "1e-3",
                    "--stop", "30", "--out", str(out)], check=True, capture_output=True, text=True)
    data = np.genfromtxt(out, delimiter=",", names=True, comments="#")
    return data["time"], data["rigv"], data["frictionF"]


@pytest.mark.parametrize("fmi_version", ["2.0", "3.0"])
def test_lugre_stick_slip_in_model_exchange_matches_the_monolithic_reference(tmp_path, fmi_version,
                                                                               stick_slip_reference):
    """LuGre.fmu and its FMI 3.0 twin, dist/fmi3/LuGre.fmu, each in Model
    Exchange under CVode."""
    m, k, c, v_a = 1.0, 2.0, 0.0, 0.1  # the rig of examples/stick_slip.ssd (Rig1D's defaults)

    def rig(t, xe, y):
        x, v = xe
        return [v, (k * (v_a * t - x) - c * v - y["F"]) / m]

    # LuGre at its defaults, the 1995 parameters of examples/lugre_1995.ssv
    path = fmu_path("LuGre") if fmi_version == "2.0" else DIST / "fmi3" / "LuGre.fmu"
    run = MeRun("LuGre", tmp_path, {}, inputs=lambda t, xe: {"v": xe[1]}, outputs=["F", "z"],
                x0=[0.0, 0.0], nominals=[1.0, 0.1], rhs=rig, rtol=1e-9, path=path)
    assert run.md.fmiVersion == fmi_version
    times = np.round(np.arange(0, 30001) * 1e-3, 10)
    rows = run.run(times)
    run.close()
    v, f = rows[:, 1], rows[:, 2]
    figures = stick_slip_figures(times, v, f)
    # docs/models.md, "Reference figures": the monolithic solution's
    published = {"first slip": 7.540, "period": 6.3627, "peak force": 1.4766, "peak velocity": 0.3698}
    for name, value in published.items():
        assert abs(figures[name] - value) <= 0.005 * value, f"{name}: {figures[name]} vs {value}"
    # against the reference run itself, sample by sample
    t_ref, v_ref, f_ref = stick_slip_reference
    assert np.array_equal(np.round(t_ref, 10), times)
    reference = stick_slip_figures(t_ref, v_ref, f_ref)
    for name in published:
        assert abs(figures[name] - reference[name]) <= 0.005 * reference[name], name
    rms = np.sqrt(np.mean((f - f_ref) ** 2)) / (f_ref.max() - f_ref.min())
    assert rms <= 0.005, f"RMS difference of the friction force {rms:.2e} of its range"
    # LuGre's one indicator is v: events where the velocity changes sign
    assert run.events, "no velocity reversal was located"
    for t, roots, z, _ in run.events:
        assert roots[0] != 0


# ---- the reset integrator --------------------------------------------------------

def test_reset_integrator_events_at_the_limits_and_model_exchange_equals_co_simulation(tmp_path):
    z0, sigma0 = 1e-4, 1e4  # defaults (Wijata et al. 2016 in 1-D)
    amplitude, omega = 2e-3, 2 * math.pi * 2.0

    def v(t):
        return amplitude * math.sin(omega * t)

    run = MeRun("ResetIntegrator", tmp_path, {}, inputs=lambda t, xe: {"v": v(t)},
                outputs=["z", "F"], rtol=1e-10)
    times = np.round(np.arange(0, 1001) * 1e-3, 10)
    rows = run.run(times)
    run.close()
    # z = (A/w)(1 - cos wt) reaches z0 at t*; the reversal at t = 1/4 s
    # releases it; the way back reaches -z0 after a travel of 2 z0, the next
    # reversal at 1/2 s releases it, and so on (period 1/2 s)
    t_hit = math.acos(1 - z0 * omega / amplitude) / omega
    t_back = math.acos(1 - 2 * z0 * omega / amplitude) / omega
    expected = [(t_hit, 0), (0.25, 0), (0.25 + t_back, 1), (0.5, 1),
                (0.5 + t_back, 0), (0.75, 0), (0.75 + t_back, 1)]  # (the release at 1 s ends the run)
    events = [e for e in run.events if e[0] < 0.999]
    located = [(t, int(np.flatnonzero(roots)[0])) for t, roots, _, _ in events]
    assert len(located) == len(expected), f"{located} vs {expected}"
    for (t, indicator), (t_expected, which) in zip(located, expected):
        assert indicator == which, (located, expected)
        assert abs(t - t_expected) <= 1e-7, (t, t_expected)
    # at each hit the strain is on its limit and held there: the indicator
    # negative; at each release positive (the reversal) and moving again
    for (t, roots, z, x), (_, which) in zip(events, expected):
        limit = z0 if which == 0 else -z0
        direction = np.sign(roots[which])
        if direction < 0:  # hit: the indicator went from + to -
            assert x[0] == limit
            assert z[which] < 0
        else:  # released
            assert z[which] >= 0
    # the Co-Simulation FMU, exact for inputs ramped over each step
    cs = co_simulation("ResetIntegrator", tmp_path, lambda t: {"v": v(t)}, ["z", "F"], 1.0, 1e-5)
    cs = cs[::100]
    z_difference = np.max(np.abs(rows[:, 0] - cs[:, 0]))
    f_difference = np.max(np.abs(rows[:, 1] - cs[:, 1]))
    assert z_difference <= 1e-6 * z0, z_difference
    assert f_difference <= 1e-6 * sigma0 * z0, f_difference
    assert rows[:, 0].max() == z0 and rows[:, 0].min() == -z0


# ---- the 2-D bristle ----------------------------------------------------------------

def test_bristle2d_sliding_on_the_boundary_equals_co_simulation(tmp_path):
    """A slip velocity of 5 mm/s turning once a second: the bristle reaches
    the boundary of the stiction disc (an event) and slides on it, its
    deflection lagging the turning slip direction. CVode on Model Exchange
    (the contact state switched at the event) against the Co-Simulation
    FMU. (FMPy's `simulate_fmu` sets a varying input in the root function
    only, not in the right-hand side, so these runs set it themselves.)"""
    z0, speed, omega = 1e-4, 5e-3, 2 * math.pi

    def slip(t):
        return {"v1": speed * math.cos(omega * t), "v2": speed * math.sin(omega * t)}

    outputs = ["z1", "z2", "F1", "F2"]
    run = MeRun("Bristle2D", tmp_path, {}, inputs=lambda t, xe: slip(t), outputs=outputs,
                rtol=1e-10)
    times = np.round(np.arange(0, 2001) * 1e-3, 10)
    me = run.run(times)
    run.close()
    # one event: reaching the boundary (z0/speed = 20 ms in), sliding after
    assert len(run.events) == 1 and abs(run.events[0][0] - z0 / speed) < 1e-3, run.events
    radius = np.hypot(me[:, 0], me[:, 1])
    sliding = times > 0.021
    assert np.max(np.abs(radius[sliding] - z0)) <= 1e-6 * z0, "left the boundary"
    cs = co_simulation("Bristle2D", tmp_path, slip, outputs, 2.0, 1e-5)[::100]
    for k, (name, scale) in enumerate(zip(outputs, (z0, z0, 1.0, 1.0))):
        difference = np.max(np.abs(me[:, k] - cs[:, k]))
        assert difference <= 1e-5 * scale, f"{name}: {difference}"


# ---- Bliman-Sorine --------------------------------------------------------------------

def test_bliman_sorine_events_at_the_reversals_and_model_exchange_equals_co_simulation(tmp_path):
    """Sun et al. 2016's trial 6 (v = 5e-3*sin(2t/3) m/s, Table 8's
    parameters, the defaults) in Model Exchange: the one event indicator,
    v, crosses zero at the reversals t = 1.5*pi*n; CVode's force equals the
    Co-Simulation FMU's (exact in displacement for inputs ramped over each
    step) and settles at the Coulomb level f1 - f2 before each reversal."""
    amplitude, omega, stop = 5e-3, 2 / 3, 12.0

    def v(t):
        return {"v": amplitude * math.sin(omega * t)}

    outputs = ["x1", "x2", "F"]
    run = MeRun("BlimanSorine", tmp_path, {}, inputs=lambda t, xe: v(t), outputs=outputs, rtol=1e-10)
    times = np.round(np.arange(0, 1201) * 1e-2, 10)
    me = run.run(times)
    run.close()
    located = [e[0] for e in run.events]
    expected = [1.5 * math.pi, 3.0 * math.pi]
    assert len(located) == len(expected), located
    for t, t_expected in zip(located, expected):
        assert abs(t - t_expected) <= 1e-7, (t, t_expected)
    cs = co_simulation("BlimanSorine", tmp_path, v, outputs, stop, 1e-4)[::100]
    fs = 2.5017
    assert np.max(np.abs(me[:, 2] - cs[:, 2])) <= 1e-6 * fs
    fc = 19.875 - 17.8227
    before = [int(round(t_expected / 1e-2)) - 1 for t_expected in expected]
    for k, s in zip(before, (1, -1)):
        assert abs(me[k, 2] - s * fc) <= 1e-6 * fc, (times[k], me[k, 2])


# ---- elasto-plastic ---------------------------------------------------------------------

def creep_in_model_exchange(name, tmp_path):
    """A 1 kg mass pushed by 0.5 Fc + 0.4 Fc sin(2 pi t) (below break-away,
    Fc = 1 N at the defaults) against the law in Model Exchange, the mass
    and the law integrated together by CVode: how far the mass moves from
    the end of the first cycle to the end of the fifth (the same phase, so
    the elastic deflection cancels), and the events located."""
    fc = 1.0

    def mass(t, xe, y):
        x, v = xe
        return [v, 0.5 * fc + 0.4 * fc * math.sin(2 * math.pi * t) - y["F"]]

    run = MeRun(name, tmp_path, {}, inputs=lambda t, xe: {"v": xe[1]}, outputs=["F", "z"],
                x0=[0.0, 0.0], nominals=[1e-5, 1e-3], rhs=mass, rtol=1e-10)
    times = np.arange(0, 6) * 1.0
    rows = run.run(times)
    run.close()
    return rows[5, 0] - rows[1, 0], run.events


def test_elasto_plastic_does_not_creep_where_lugre_does_in_model_exchange(tmp_path):
    """Dupont et al. 2002's point, through an importer's solver: LuGre
    creeps a little at every cycle of a force below break-away, the
    elasto-plastic law (LuGre's parameters, z_ba = 0.95 Fc/sigma0) does
    not (less than 1e-3 of LuGre's creep)."""
    lugre, _ = creep_in_model_exchange("LuGre", tmp_path)
    elasto_plastic, events = creep_in_model_exchange("ElastoPlastic", tmp_path)
    assert lugre > 1e-6, lugre
    assert abs(elasto_plastic) < 1e-3 * lugre, (elasto_plastic, lugre)
    # the push stays below 0.9 Fc < sigma0 z_ba: the deflection never
    # reaches z_ba, so no indicator but v's can change sign
    assert all(not any(roots[1:]) for _, roots, _, _ in events), events


def test_elasto_plastic_model_exchange_equals_co_simulation(tmp_path):
    """Under v = 2e-3 sin(2 pi t) (elastic, transition and plastic zones,
    reversals), CVode's force and deflection equal the Co-Simulation
    FMU's (exact in the elastic and plastic zones, the transition under a
    tolerance) with inputs ramped over 1e-5 s steps."""
    def v(t):
        return {"v": 2e-3 * math.sin(2 * math.pi * t)}

    outputs = ["z", "F"]
    run = MeRun("ElastoPlastic", tmp_path, {}, inputs=lambda t, xe: v(t), outputs=outputs, rtol=1e-10)
    times = np.round(np.arange(0, 1001) * 1e-3, 10)
    me = run.run(times)
    run.close()
    # break-away reached, in both directions: indicators z - z_ba and z + z_ba
    crossed = {int(np.flatnonzero(roots)[0]) for _, roots, _, _ in run.events}
    assert {1, 2} <= crossed, crossed
    cs = co_simulation("ElastoPlastic", tmp_path, v, outputs, 1.0, 1e-5)[::100]
    z_scale, f_scale = 1.5e-5, 1.5
    assert np.max(np.abs(me[:, 0] - cs[:, 0])) <= 1e-6 * z_scale
    assert np.max(np.abs(me[:, 1] - cs[:, 1])) <= 1e-5 * f_scale


@pytest.mark.parametrize("name, amplitude", [("MaxwellSlip", 2e-4), ("GMS", 2e-3)])
def test_element_laws_events_at_each_switch_and_model_exchange_equals_co_simulation(name, amplitude,
                                                                                     tmp_path):
    """Maxwell-slip in pre-sliding loops that slip every element (path
    amplitude 3.2e-5 m against 1.8e-5 m to slip them all), GMS through
    gross sliding and the Stribeck curve: CVode with an event at each
    element's stick/slip switch and at each reversal gives the
    Co-Simulation FMU's force (exact, or exact for held inputs, over
    1e-5 s steps)."""
    def v(t):
        return {"v": amplitude * math.sin(2 * math.pi * t)}

    outputs = ["F", "E_stored"]
    run = MeRun(name, tmp_path, {}, inputs=lambda t, xe: v(t), outputs=outputs, rtol=1e-10)
    times = np.round(np.arange(0, 1501) * 1e-3, 10)
    me = run.run(times)
    run.close()
    # every element reached its slip level (indicators 1..10), and v's
    # sign changes (indicator 0) stuck them again
    crossed = {int(k) for _, roots, _, _ in run.events for k in np.flatnonzero(roots)}
    assert set(range(0, 11)) <= crossed, crossed
    assert not crossed - set(range(0, 11)), crossed
    cs = co_simulation(name, tmp_path, v, outputs, 1.5, 1e-5)[::100]
    level = 1.0 if name == "MaxwellSlip" else 1.5
    error = np.max(np.abs(me[:, 0] - cs[:, 0])) / level
    print(f"{name}: Model Exchange - Co-Simulation, {error:.2e} of the level")
    assert error <= (1e-7 if name == "MaxwellSlip" else 1e-5), error


# ---- the classical law: events only ----------------------------------------------

def spring_mass_slide(m, k, c, fc, v_a, t0, x0, v0):
    """The closed form of a mass on a spring pulled at `v_a`, sliding
    forward against Coulomb + viscous friction `fc + c·v` (Sun et al. 2016
    eq. 1):  m·x'' + c·x' + k·x = k·v_a·t − fc, from (t0, x0, v0), an
    underdamped oscillation about x_p(t) = v_a·t − (fc + c·v_a)/k. Gives
    the functions x(t) and v(t)."""
    w0 = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = w0 * math.sqrt(1 - zeta ** 2)
    a = x0 - (v_a * t0 - (fc + c * v_a) / k)     # displacement from x_p
    b = (v0 - v_a + zeta * w0 * a) / wd          # so that x'(t0) = v0

    def x(t):
        s = t - t0
        return v_a * t - (fc + c * v_a) / k + np.exp(-zeta * w0 * s) * (a * np.cos(wd * s) + b * np.sin(wd * s))

    def v(t):
        s = t - t0
        e = np.exp(-zeta * w0 * s)
        return v_a + e * ((-zeta * w0 * a + wd * b) * np.cos(wd * s) + (-zeta * w0 * b - wd * a) * np.sin(wd * s))

    return x, v


@pytest.mark.parametrize("fmi_version", ["2.0", "3.0"])
def test_classical_stick_slip_events_follow_the_closed_form(tmp_path, fmi_version):
    """Classical.fmu in Model Exchange (no continuous states, four event
    indicators) on a 1 kg mass pulled through a 2 N/m spring at 0.1 m/s,
    the mass's ODE in Python, CVode at rtol 1e-10. With vs = 0 (Coulomb +
    viscous, Sun et al. 2016 eq. 1) every phase has a closed form, and the
    events must fall where it puts them:
    - stuck from rest until the spring force reaches Fs: t = Fs/(k·v_a);
    - breaking away under F = Fs until v = dv: t − t_b = √(2·m·dv/(k·v_a))
      to first order (the spring force grows as k·v_a·(t − t_b));
    - sliding: the damped oscillation of `spring_mass_slide` from the state
      at that event, sample by sample, until v falls back to dv, where the
      closed form's own crossing is;
    - stuck again (F = F_app, the net force zero: the mass creeps at the
      velocity it entered with) until F_app reaches Fs again."""
    m, k, v_a = 1.0, 2.0, 0.1
    fc, fs, sigma2, dv = 1.0, 1.5, 0.4, 1e-5
    parameters = {"Fc": fc, "Fs": fs, "vs": 0.0, "sigma2": sigma2, "dv": dv}

    def rig(t, xe, y):
        x, v = xe
        return [v, (k * (v_a * t - x) - y["F"]) / m]

    path = fmu_path("Classical") if fmi_version == "2.0" else DIST / "fmi3" / "Classical.fmu"
    run = MeRun("Classical", tmp_path, parameters,
                inputs=lambda t, xe: {"v": xe[1], "F_app": k * (v_a * t - xe[0])},
                outputs=["F", "F_app"], x0=[0.0, 0.0], nominals=[1.0, 0.1], rhs=rig, rtol=1e-10,
                path=path)
    assert run.md.fmiVersion == fmi_version
    assert run.nf == 0 and run.nz == 4
    times = np.round(np.arange(0, 20001) * 1e-3, 10)
    rows = run.run(times)
    run.close()
    x, v, f = rows[:, 0], rows[:, 1], rows[:, 2]
    # (time, which indicator crossed, state after) in order
    events = [(t, int(np.flatnonzero(roots)[0]), xe) for t, roots, _, xe in run.events]
    kinds = [i for _, i, _ in events]

    # 1. stuck from rest: x does not move, F = F_app, until F_app = Fs
    t_break = fs / (k * v_a)
    assert kinds[0] == 2, f"first event: indicator {kinds[0]} ({events[:3]})"
    assert abs(events[0][0] - t_break) < 1e-7, f"break-away at {events[0][0]}, closed form {t_break}"
    before = times < t_break - 1e-3
    assert np.max(np.abs(x[before])) == 0.0 and np.max(np.abs(v[before])) == 0.0
    np.testing.assert_allclose(f[before], k * v_a * times[before], rtol=0, atol=1e-12)

    # 2. breaking away under Fs until v = dv
    t_slide, kind, (x1, v1) = events[1]
    assert kind == 0 and abs(v1 - dv) < 1e-12
    t_leave = t_break + math.sqrt(2 * m * dv / (k * v_a))
    assert abs(t_slide - t_leave) < 1e-3 * (t_leave - t_break), f"{t_slide} vs {t_leave}"

    # 3. sliding: the closed form from the state at the event
    x_cf, v_cf = spring_mass_slide(m, k, sigma2, fc, v_a, t_slide, x1, v1)
    t_stick, kind, (x2, v2) = next(e for e in events[2:] if e[1] == 0)
    assert kind == 0 and abs(v2 - dv) < 1e-12
    slide = (times > t_slide) & (times < t_stick)
    assert slide.sum() > 1000, "the slide is too short to check"
    assert np.max(np.abs(x[slide] - x_cf(times[slide]))) < 1e-7
    assert np.max(np.abs(v[slide] - v_cf(times[slide]))) < 1e-7
    np.testing.assert_allclose(f[slide], fc + sigma2 * v[slide], rtol=0, atol=1e-9)
    # the closed form's own crossing of dv on the way down
    grid = np.linspace(t_slide + 0.5, t_stick + 0.5, 200001)
    falling = np.flatnonzero((v_cf(grid[:-1]) >= dv) & (v_cf(grid[1:]) < dv))
    lo, hi = grid[falling[0]], grid[falling[0] + 1]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if v_cf(mid) >= dv else (lo, mid)
    assert abs(t_stick - lo) < 1e-7, f"re-stick at {t_stick}, closed form {lo}"

    # 4. stuck again, creeping at the velocity it entered with, until
    #    F_app = k·(v_a·t − x) reaches Fs again
    f_app2 = k * (v_a * t_stick - x2)
    assert abs(f_app2) < fs, f"the contact re-sticks with F_app = {f_app2}"
    t_break2 = t_stick + (fs - f_app2) / (k * (v_a - v2))
    t_next, kind, _ = next(e for e in events if e[0] > t_stick + 1e-9 and e[1] in (2, 3))
    assert kind == 2 and abs(t_next - t_break2) < 1e-6, f"{t_next} vs {t_break2}"
    stuck = (times > t_stick + 1e-3) & (times < t_break2 - 1e-3)
    assert stuck.sum() > 100
    np.testing.assert_allclose(v[stuck], v2, rtol=0, atol=1e-12)
    np.testing.assert_allclose(f[stuck], rows[stuck, 3], rtol=0, atol=1e-12)  # F = F_app
