"""Our FMUs as FMI 3.0 (issue 45): every law and rig is also shipped as
dist/fmi3/<Name>.fmu, from the same binary as dist/<Name>.fmu (the library
exports both interfaces) and the same variable table.

- FMPy validates every FMI 3.0 FMU (its schema and rules).
- FMPy's FMI 3.0 Co-Simulation run of each law, with every extension on and
  its inputs moving (the cases of test_fmpy_equivalence.py), and of each
  rig, equals its FMI 2.0 run to 1e-12 relative, every output; so does the
  Model Exchange run under CVode of every law offered for it.
- The calls an importer can get wrong are refused with fmi3Error and a
  message that names the problem, nothing changed: a call in the wrong
  state, an unknown value reference, a value of the wrong type, NaN, an
  array length that does not match, an FMI 2.0 instance passed to an FMI
  3.0 function, a step past the stop time, event mode asked of
  Co-Simulation, Scheduled Execution.
- What FMI 3.0 adds works: `time` and the event indicators are readable
  variables, the adjoint derivative is the transpose of the directional
  one, FMU states serialize and restore, fmi3DoStep reports its last
  successful time."""

import ctypes
import math
from ctypes import byref, c_bool, c_double, c_size_t, c_uint32, c_void_p

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi3 import (FMU3Model, FMU3Slave, fmi3ClockUpdateCallback, fmi3IntermediateUpdateCallback,
                        fmi3LockPreemptionCallback,
                        fmi3LogMessageCallback, fmi3UnlockPreemptionCallback)
from fmpy.simulation import apply_start_values
from fmpy.validation import validate_fmu

import shipped
from conftest import DIST, fmu_path
from test_fmpy_equivalence import CASES

FMI3 = DIST / "fmi3"


def fmi3_path(name):
    path = FMI3 / f"{name}.fmu"
    assert path.exists(), f"{path} is missing: run ./build-fmu.sh"
    return path


def elements(md):
    """The FMI 3.0 variables of `md` as the FMI 2.0 description's scalars:
    an array `x` of n as `x[1]` ... `x[n]`, `der(x)` as `der(x[1])` ...,
    each with its value reference (the array's plus its offset) and start
    value."""
    out = {}
    for v in md.modelVariables:
        if not v.shape:
            out[v.name] = (v.type, v.valueReference, v.causality, v.start)
            continue
        (n,) = v.shape
        starts = v.start.split() if v.start is not None else [None] * n
        inner = v.name[4:-1] if v.name.startswith("der(") else None
        for i in range(n):
            name = f"der({inner}[{i + 1}])" if inner else f"{v.name}[{i + 1}]"
            out[name] = (v.type, v.valueReference + i, v.causality, starts[i])
    return out


def fmi3_start_values(path, parameters):
    """FMI 2.0 start values by element name (`x_table[2]`) as FMI 3.0 ones:
    each array whose elements are named set as a whole, from its start
    values with those elements changed."""
    md = read_model_description(str(path))
    arrays = {v.name: v for v in md.modelVariables if v.shape}
    out = {}
    for name, value in parameters.items():
        base, _, index = name.partition("[")
        if base in arrays and index:
            array = out.setdefault(base, [float(x) for x in arrays[base].start.split()])
            array[int(index[:-1]) - 1] = value
        else:
            out[name] = value
    return out


def outputs_of(md):
    return [v.name for v in md.modelVariables if v.causality == "output"]


def same_rows(a, b, names):
    """The largest relative difference between the columns `names` of two
    results, and whether every column moved."""
    worst, moved = 0.0, []
    for n in names:
        x, y = a[n].astype(float), b[n].astype(float)
        assert x.shape == y.shape, n
        scale = np.maximum(np.abs(x), np.abs(y))
        d = np.abs(x - y)
        worst = max(worst, float(np.max(np.where(scale > 0, d / np.where(scale > 0, scale, 1), d))))
        moved.append(np.ptp(x) > 0)
    return worst, moved


@pytest.mark.parametrize("name", shipped.SHIPPED)
def test_fmpy_validates_every_fmi3_fmu(name):
    assert validate_fmu(str(fmi3_path(name))) == []
    md = read_model_description(str(fmi3_path(name)))
    md2 = read_model_description(str(fmu_path(name)))
    assert md.fmiVersion == "3.0" and md.coSimulation is not None
    assert (md.modelExchange is not None) == (name in shipped.MODEL_EXCHANGE)
    # the same variables, by name, type, value reference and start (time
    # and the event indicators added, numbered scalars as arrays)
    kinds = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}

    def start(x):
        return None if x is None else float(x) if x not in ("true", "false") else x == "true"
    two = {v.name: (kinds[v.type], v.valueReference, v.causality, start(v.start))
           for v in md2.modelVariables}
    three = {n: (t, vr, c, start(s)) for n, (t, vr, c, s) in elements(md).items()
             if n != "time" and not n.startswith("eventIndicator[")}
    assert three == two
    arrays = {v.name: v.shape for v in md.modelVariables if v.shape}
    expected = {"LuGre": {"x_table": (32,), "scale_pos": (32,), "scale_neg": (32,)},
                "MaxwellSlip": {"k": (100,), "W": (100,), "F_element": (100,), "der(F_element)": (100,)},
                "GMS": {"k": (100,), "alpha": (100,), "F_element": (100,), "der(F_element)": (100,)}}
    assert arrays == expected.get(name, {})
    time = [v for v in md.modelVariables if v.causality == "independent"]
    assert [v.name for v in time] == ["time"]
    assert md.numberOfEventIndicators == md2.numberOfEventIndicators
    assert md.numberOfContinuousStates == md2.numberOfContinuousStates


def run_case(name, path, fmi_type, tmp_path):
    if name in CASES:
        sig, parameters = CASES[name]
        stop, step = 2.0, 1e-3
    else:  # a rig: its default experiment, its inputs at their start values
        sig, parameters = None, {}
        md = read_model_description(str(path))
        stop = float(md.defaultExperiment.stopTime)
        step = float(md.defaultExperiment.stepSize)
    if read_model_description(str(path)).fmiVersion == "3.0":
        parameters = fmi3_start_values(path, parameters)
    kwargs = dict(fmi_type=fmi_type, stop_time=stop, output_interval=step, input=sig,
                  start_values=parameters)
    if fmi_type == "ModelExchange":
        kwargs.update(solver="CVode", relative_tolerance=1e-6, output_interval=0.01)
    return simulate_fmu(str(path), **kwargs)


@pytest.mark.parametrize("name", shipped.SHIPPED)
def test_fmi3_co_simulation_equals_fmi2(name, tmp_path):
    a = run_case(name, fmu_path(name), "CoSimulation", tmp_path)
    b = run_case(name, fmi3_path(name), "CoSimulation", tmp_path)
    names = outputs_of(read_model_description(str(fmu_path(name))))
    worst, moved = same_rows(a, b, names)
    assert worst <= 1e-12, f"{name}: FMI 3.0 and FMI 2.0 differ by {worst:.1e} relative"
    assert np.array_equal(a["time"], b["time"]) and len(a) > 100
    # a comparison of runs that do something: most outputs move
    assert sum(moved) >= len(names) / 2, f"{name}: outputs that moved: {moved}"


@pytest.mark.parametrize("name", shipped.MODEL_EXCHANGE)
def test_fmi3_model_exchange_equals_fmi2(name, tmp_path):
    a = run_case(name, fmu_path(name), "ModelExchange", tmp_path)
    b = run_case(name, fmi3_path(name), "ModelExchange", tmp_path)
    names = outputs_of(read_model_description(str(fmu_path(name))))
    worst, moved = same_rows(a, b, names)
    assert worst <= 1e-12, f"{name}: FMI 3.0 and FMI 2.0 differ by {worst:.1e} relative"
    assert sum(moved) >= len(names) / 2, f"{name}: outputs that moved: {moved}"


# ---- the C edge, probed ----------------------------------------------------------

class Probe:
    """An FMI 3.0 instance of `name` through FMPy's FMU3Slave (or
    FMU3Model), its log collected in `messages`; `status(function, *args)`
    calls a raw fmi3 function and returns its status without raising."""

    def __init__(self, name, tmp_path, model_exchange=False, **instantiate):
        self.md = read_model_description(str(fmi3_path(name)))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.unzipdir = extract(str(fmi3_path(name)), unzipdir=str(tmp_path / f"{name}3"))
        cls = FMU3Model if model_exchange else FMU3Slave
        self.fmu = cls(guid=self.md.guid, unzipDirectory=self.unzipdir,
                       modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="probe")
        self.messages = []

        def log(env, status, category, message):
            self.messages.append((status, message.decode()))
        self.fmu.instantiate(logMessage=log, **instantiate)
        self.lib = self.fmu.dll

    def status(self, function, *args):
        f = getattr(self.lib, function)
        f.restype = ctypes.c_int
        return f(*args)

    def last(self):
        return self.messages[-1][1] if self.messages else ""

    def initialize(self, stop=None):
        self.fmu.enterInitializationMode(startTime=0.0, stopTime=stop)
        self.fmu.exitInitializationMode()

    def floats(self, names):
        return self.fmu.getFloat64([self.vr[n] for n in names])

    def close(self):
        self.fmu.freeInstance()


def vrs(*refs):
    return (c_uint32 * len(refs))(*refs)


def doubles(*values):
    return (c_double * len(values))(*values)


def test_misuse_is_refused_by_name_and_changes_nothing(tmp_path):
    p = Probe("LuGre", tmp_path)
    c = p.fmu.component
    flags = [c_bool() for _ in range(3)]
    last = c_double()
    step = lambda t, h: p.status("fmi3DoStep", c, c_double(t), c_double(h), c_bool(True),
                                 *[byref(f) for f in flags], byref(last))
    # a step before initialization: the state machine refuses it
    assert step(0.0, 1e-3) == 3
    assert "fmi3DoStep: illegal call sequence: not allowed in state Instantiated" in p.last()
    p.initialize(stop=1.0)
    v, f = p.vr["v"], p.vr["F"]
    # an unknown value reference, named with the range there is
    out = doubles(0.0)
    assert p.status("fmi3GetFloat64", c, vrs(10_000), c_size_t(1), out, c_size_t(1)) == 3
    assert "unknown value reference 10000" in p.last()
    # NaN for an input: refused, naming the variable, and v keeps its value
    p.fmu.setFloat64([v], [1e-3])
    assert p.status("fmi3SetFloat64", c, vrs(v), c_size_t(1), doubles(math.nan), c_size_t(1)) == 3
    assert "NaN" in p.last() or "nan" in p.last(), p.last()
    assert p.fmu.getFloat64([v]) == [1e-3]
    # nValues other than the number of scalars
    assert p.status("fmi3GetFloat64", c, vrs(f), c_size_t(1), doubles(0, 0), c_size_t(2)) == 3
    assert "nValues = 2 for 1 value references" in p.last()
    # a Float64 read as another type, named with its real type
    assert p.status("fmi3GetFloat32", c, vrs(f), c_size_t(1), (ctypes.c_float * 1)(),
                    c_size_t(1)) == 3
    assert "(F) is a Float64 variable, not Float32" in p.last()
    assert p.status("fmi3GetInt32", c, vrs(f), c_size_t(1), (ctypes.c_int32 * 1)(), c_size_t(1)) == 3
    # NULL arrays with a non-zero length
    assert p.status("fmi3GetFloat64", c, None, c_size_t(1), out, c_size_t(1)) == 3
    assert "NULL" in p.last()
    # a parameter after initialization (fixed)
    assert p.status("fmi3SetFloat64", c, vrs(p.vr["sigma0"]), c_size_t(1), doubles(1e5),
                    c_size_t(1)) == 3
    # the independent variable is read, never set
    assert p.fmu.getFloat64([p.vr["time"]]) == [0.0]
    assert p.status("fmi3SetFloat64", c, vrs(p.vr["time"]), c_size_t(1), doubles(1.0),
                    c_size_t(1)) == 3
    assert "independent variable time" in p.last()
    # the steps that are right still run, and report where they got to
    assert step(0.0, 0.5) == 0 and last.value == 0.5
    assert [x.value for x in flags] == [False, False, False]
    assert p.fmu.getFloat64([p.vr["time"]]) == [0.5]
    # past the stop time
    assert step(0.5, 0.6) == 3
    assert "past stopTime = 1" in p.last() and "fmi3EnterInitializationMode" in p.last()
    # a communication point other than the FMU's time
    assert step(0.4, 0.1) == 3
    assert "expected currentCommunicationPoint = 0.5" in p.last()
    # NULL out-pointers of fmi3DoStep
    assert p.status("fmi3DoStep", c, c_double(0.5), c_double(0.1), c_bool(True), None,
                    byref(flags[1]), byref(flags[2]), byref(last)) == 3
    assert "eventHandlingNeeded" in p.last()
    # nothing lost: the instance steps on
    assert step(0.5, 0.5) == 0 and last.value == 1.0
    # functions of what the FMU does not offer, refused by name
    assert p.status("fmi3EnterConfigurationMode", c) == 3
    assert "no structural parameters" in p.last()
    assert p.status("fmi3EnterStepMode", c) == 3
    assert p.status("fmi3EnterEventMode", c) == 3
    assert "no Event Mode in Co-Simulation" in p.last()
    # a NULL instance
    assert p.status("fmi3DoStep", None, c_double(1.0), c_double(0.1), c_bool(True),
                    *[byref(x) for x in flags], byref(last)) == 3
    p.fmu.terminate()
    p.close()


def test_an_fmi2_instance_is_not_an_fmi3_one(tmp_path):
    """The library holds both interfaces; an instance of one passed to the
    other's functions is refused (it is in the other's set of live
    instances), and the FMI 2.0 instance still works."""
    from fmpy.fmi2 import FMU2Slave
    md2 = read_model_description(str(fmu_path("LuGre")))
    p = Probe("LuGre", tmp_path)
    # the FMI 2.0 FMU's binary is the same file: load it through its own FMU
    two = FMU2Slave(guid=md2.guid, unzipDirectory=extract(str(fmu_path("LuGre")),
                    unzipdir=str(tmp_path / "LuGre2")), modelIdentifier="LuGre", instanceName="two")
    two.instantiate()
    two.setupExperiment(startTime=0.0)
    two.enterInitializationMode()
    two.exitInitializationMode()
    lib2 = two.dll
    f = lib2.fmi3GetFloat64
    f.restype = ctypes.c_int
    out = doubles(0.0)
    assert f(c_void_p(two.component), vrs(3), c_size_t(1), out, c_size_t(1)) == 3
    g = p.lib.fmi2GetReal
    g.restype = ctypes.c_int
    assert g(c_void_p(p.fmu.component), vrs(3), c_size_t(1), out) == 3
    # both still work through their own interface
    assert two.getReal([3]) == [0.0]
    p.initialize()
    assert p.fmu.getFloat64([3]) == [0.0]
    two.terminate()
    two.freeInstance()
    p.close()


def test_instantiation_refuses_what_the_fmu_does_not_offer(tmp_path):
    md = read_model_description(str(fmi3_path("LuGre")))
    unzipdir = extract(str(fmi3_path("LuGre")), unzipdir=str(tmp_path / "u"))
    messages = []

    def log(env, status, category, message):
        messages.append(message.decode())
    cb = fmi3LogMessageCallback(log)
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="LuGre",
                    instanceName="x")
    with pytest.raises(Exception):
        fmu.instantiate(eventModeUsed=True, logMessage=log)
    assert any("eventModeUsed = true" in m for m in messages), messages
    inst = fmu.dll.fmi3InstantiateScheduledExecution
    inst.restype = c_void_p
    assert not inst(b"x", md.guid.encode(), None, c_bool(False), c_bool(False), None, cb,
                    fmi3ClockUpdateCallback(), fmi3LockPreemptionCallback(),
                    fmi3UnlockPreemptionCallback())
    assert "not Scheduled Execution" in messages[-1]
    inst = fmu.dll.fmi3InstantiateCoSimulation
    inst.restype = c_void_p
    assert not inst(b"x", b"{not-a-token}", None, c_bool(False), c_bool(False), c_bool(False),
                    c_bool(False), None, c_size_t(0), None, cb, fmi3IntermediateUpdateCallback())
    assert "unknown instantiationToken {not-a-token}" in messages[-1]
    # Rig1D has no Model Exchange interface
    md = read_model_description(str(fmi3_path("Rig1D")))
    unzipdir = extract(str(fmi3_path("Rig1D")), unzipdir=str(tmp_path / "r"))
    rig = FMU3Model(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier="Rig1D",
                    instanceName="x")
    with pytest.raises(Exception):
        rig.instantiate(logMessage=log)
    assert "Model Exchange is not supported by Rig1D" in messages[-1]


def test_adjoint_is_the_transpose_of_the_directional_derivative(tmp_path):
    p = Probe("LuGre", tmp_path)
    p.initialize()
    c = p.fmu.component
    p.fmu.setFloat64([p.vr["v"], p.vr["x"]], [2e-3, 0.1])
    p.fmu.doStep(0.0, 1e-3)
    unknowns = [p.vr["F"], p.vr["z"], p.vr["P_diss"]]
    knowns = [p.vr["v"], p.vr["x"], p.vr["Fn"]]
    jac = np.zeros((3, 3))
    for j, k in enumerate(knowns):
        out = doubles(0, 0, 0)
        assert p.status("fmi3GetDirectionalDerivative", c, vrs(*unknowns), c_size_t(3), vrs(k),
                        c_size_t(1), doubles(1.0), c_size_t(1), out, c_size_t(3)) == 0
        jac[:, j] = list(out)
    assert abs(jac[0, 0]) > 0  # dF/dv after a step
    seed = np.array([0.7, -1.3, 2.0])
    out = doubles(0, 0, 0)
    assert p.status("fmi3GetAdjointDerivative", c, vrs(*unknowns), c_size_t(3), vrs(*knowns),
                    c_size_t(3), doubles(*seed), c_size_t(3), out, c_size_t(3)) == 0
    expected = seed @ jac
    assert np.allclose(list(out), expected, rtol=1e-12, atol=1e-15 * np.abs(jac).max())
    # lengths that do not fit the scalars are refused, naming them
    assert p.status("fmi3GetAdjointDerivative", c, vrs(*unknowns), c_size_t(3), vrs(*knowns),
                    c_size_t(3), doubles(*seed), c_size_t(2), out, c_size_t(3)) == 3
    assert "nSeed = 2 but the unknowns hold 3 values" in p.last()
    p.close()


def test_arrays_are_read_and_written_whole(tmp_path):
    """LuGre's position table is three arrays of 32 in FMI 3.0 (FMI 2.0:
    96 numbered scalars): read and written as a whole through the array's
    value reference, an element's own value reference refused by name,
    and nValues counting the elements."""
    p = Probe("LuGre", tmp_path)
    c = p.fmu.component
    x_table = p.vr["x_table"]
    table = np.linspace(0.0, 0.62, 32)
    p.fmu.setFloat64([x_table], list(table))
    p.fmu.setBoolean([p.vr["position_dependent"]], [True])
    p.fmu.setInt32([p.vr["n_table"]], [32])
    scale = np.full(32, 1.0)
    scale[16:] = 2.0
    p.fmu.setFloat64([p.vr["scale_pos"], p.vr["scale_neg"]], list(scale) + list(scale))
    p.initialize()
    assert p.fmu.getFloat64([x_table], 32) == list(table)
    both = p.fmu.getFloat64([p.vr["Fc"], x_table], 33)
    assert both[1:] == list(table)
    # element 2 of the array is not an FMI 3.0 variable of its own
    out = doubles(0.0)
    assert p.status("fmi3GetFloat64", c, vrs(x_table + 1), c_size_t(1), out, c_size_t(1)) == 3
    assert "element 2 of the array x_table (value reference 20)" in p.last(), p.last()
    # nValues must count the elements
    assert p.status("fmi3GetFloat64", c, vrs(x_table), c_size_t(1), out, c_size_t(1)) == 3
    assert "hold 32 values" in p.last(), p.last()
    # the table acts: at x = 0.5 the levels are doubled, at 0.1 they are not
    forces = []
    for x in (0.1, 0.5):
        q = Probe("LuGre", tmp_path / f"x{x}")
        q.fmu.setFloat64([q.vr["x_table"]], list(table))
        q.fmu.setFloat64([q.vr["scale_pos"], q.vr["scale_neg"]], list(scale) + list(scale))
        q.fmu.setBoolean([q.vr["position_dependent"]], [True])
        q.initialize()
        q.fmu.setFloat64([q.vr["v"], q.vr["x"]], [0.05, x])
        q.fmu.doStep(0.0, 1.0)
        forces.append(q.floats(["F"])[0])
        q.close()
    assert 1.9 < (forces[1] - 0.4 * 0.05) / (forces[0] - 0.4 * 0.05) < 2.1, forces
    p.close()


def test_fmu_state_serializes_and_restores(tmp_path):
    p = Probe("LuGre", tmp_path)
    p.initialize()
    p.fmu.setFloat64([p.vr["v"]], [3e-3])
    p.fmu.doStep(0.0, 0.01)
    state = p.fmu.getFMUState()
    data = p.fmu.serializeFMUState(state)
    before = p.floats(["F", "z", "time"])
    for k in range(5):
        p.fmu.doStep(0.01 * (k + 1), 0.01)
    after = p.floats(["F", "z"])
    assert after != before[:2]
    restored = p.fmu.deserializeFMUState(data)
    p.fmu.setFMUState(restored)
    assert p.floats(["F", "z", "time"]) == before
    for k in range(5):
        p.fmu.doStep(0.01 * (k + 1), 0.01)
    assert p.floats(["F", "z"]) == after
    p.fmu.freeFMUState(state)
    p.fmu.freeFMUState(restored)
    # a foreign pointer is refused
    c = p.fmu.component
    assert p.status("fmi3SetFMUState", c, c_void_p(0x1234)) == 3
    p.close()


def test_model_exchange_event_indicators_are_variables(tmp_path):
    p = Probe("LuGre", tmp_path, model_exchange=True)
    p.fmu.enterInitializationMode(startTime=0.0)
    p.fmu.setFloat64([p.vr["v"]], [-2e-3])
    p.fmu.exitInitializationMode()
    p.fmu.updateDiscreteStates()
    p.fmu.enterContinuousTimeMode()
    n = c_size_t()
    assert p.status("fmi3GetNumberOfEventIndicators", p.fmu.component, byref(n)) == 0
    assert n.value == p.md.numberOfEventIndicators >= 1
    z = doubles(*([0.0] * n.value))
    p.fmu.getEventIndicators(z, n.value)
    names = [f"eventIndicator[{k + 1}]" for k in range(n.value)]
    assert p.floats(names) == list(z)
    # LuGre's indicator is v
    assert z[0] == -2e-3
    p.fmu.terminate()
    p.close()


# ---- intermediate update and early return ---------------------------------------

def maxwell_slip_switch_times(p, v):
    """Maxwell-slip from rest under a held velocity `v` (Lampaert, Swevers,
    Al-Bender 2002): element i sticks and loads at k_i·v until its force
    reaches W_i, so it starts to slip at W_i/(k_i·v)."""
    start = {name: s for name, (_, _, _, s) in elements(p.md).items()}
    n = int(start["n_elements"])
    return sorted(float(start[f"W[{i}]"]) / (float(start[f"k[{i}]"]) * v) for i in range(1, n + 1))


def test_each_switch_inside_a_step_is_reported_where_the_closed_form_puts_it(tmp_path):
    reported = []

    def update(env, time, set_requested, get_allowed, step_finished, can_return_early,
               early_return_requested, early_return_time):
        reported.append((time, bool(can_return_early)))

    p = Probe("MaxwellSlip", tmp_path, intermediateUpdate=update, earlyReturnAllowed=False)
    assert p.md.coSimulation.providesIntermediateUpdate
    p.initialize()
    v = 1e-3
    expected = maxwell_slip_switch_times(p, v)
    h = 1.5 * expected[-1]
    p.fmu.setFloat64([p.vr["v"]], [v])
    event, terminate, early, last = p.fmu.doStep(0.0, h)
    assert (event, terminate, early, last) == (False, False, False, h)
    times = [t for t, _ in reported]
    assert len(times) == len(expected) >= 5, (times, expected)
    for got, want in zip(times, expected):
        assert abs(got - want) <= 1e-11 * h, (got, want)
    assert not any(can for _, can in reported)  # early return not allowed at instantiation
    # every element slips at the end, as without the reports
    assert p.fmu.getInt32([p.vr["n_slipping"]]) == [len(expected)]
    p.close()


def test_early_return_at_each_switch_ends_the_step_there_and_loses_nothing(tmp_path):
    """The importer asks to end the step at every switch and steps on from
    there to the end of the original step: it sees each element begin to
    slip, one at a time, and ends where an importer that never asked
    ends."""
    def update(env, time, set_requested, get_allowed, step_finished, can_return_early,
               early_return_requested, early_return_time):
        assert can_return_early
        early_return_requested[0] = True
        early_return_time[0] = time

    split = Probe("MaxwellSlip", tmp_path / "a", intermediateUpdate=update, earlyReturnAllowed=True)
    whole = Probe("MaxwellSlip", tmp_path / "b")
    v = -2e-3
    expected = maxwell_slip_switch_times(split, abs(v))
    h = 1.25 * expected[-1]
    for p in (split, whole):
        p.initialize()
        p.fmu.setFloat64([p.vr["v"]], [v])
    t, ends, counts = 0.0, [], []
    while t < h:
        event, terminate, early, last = split.fmu.doStep(t, h - t)
        assert not event and not terminate
        if early:
            ends.append(last)
            counts.append(split.fmu.getInt32([split.vr["n_slipping"]])[0])
        else:
            assert last == h
        assert split.fmu.getFloat64([split.vr["time"]]) == [last]
        t = last
    assert len(ends) == len(expected)
    for got, want in zip(ends, expected):
        assert abs(got - want) <= 1e-11 * h, (got, want)
    # one more element slips at each early return
    assert counts == list(range(1, len(expected) + 1))
    whole.fmu.doStep(0.0, h)
    a, b = split.floats(["F", "E_stored"]), whole.floats(["F", "E_stored"])
    assert np.allclose(a, b, rtol=1e-12, atol=0), (a, b)
    split.close()
    whole.close()


def test_no_report_without_a_switch_and_none_from_a_rig(tmp_path):
    reported = []

    def update(env, time, set_requested, get_allowed, step_finished, can_return_early,
               early_return_requested, early_return_time):
        reported.append(time)
        early_return_requested[0] = True
        early_return_time[0] = time

    p = Probe("LuGre", tmp_path / "l", intermediateUpdate=update, earlyReturnAllowed=True)
    p.initialize()
    p.fmu.setFloat64([p.vr["v"]], [1e-3])
    p.fmu.doStep(0.0, 1e-4)   # still sticking
    assert reported == [] and p.fmu.getBoolean([p.vr["sliding"]]) == [False]
    _, _, early, last = p.fmu.doStep(1e-4, 0.1)  # breaks away inside the step
    assert len(reported) == 1 and 1e-4 < reported[0] < 0.1001
    assert early and last == reported[0] and p.fmu.getBoolean([p.vr["sliding"]]) == [True]
    p.close()
    rig = read_model_description(str(fmi3_path("Rig1D")))
    assert not rig.coSimulation.providesIntermediateUpdate
