"""libcosim (the Open Simulation Platform's co-simulation library, through
libcosimpy, pinned in requirements.txt) runs our example archives
dist/*.ssp and records what `fricsim run --master jacobi` records, to 1e-9
relative.

libcosim reads the .ssp itself (its own SSP parser, FMI Library, its
fixed-step master); nothing of ours but the FMUs and the archive is in its
run. Its fixed-step algorithm is a Jacobi scheme: every FMU steps from t,
then every connection is transferred, and the initial values are
propagated in initialization mode before fmi2ExitInitializationMode and
once after it, as fricsim's `jacobi` does. Its time is an integer count of
nanoseconds: it passes each FMU the communication point k·h_ns·1e-9 and
the step as the difference of two such points, where fricsim passes
start + k·h and h. Those differ in the last bits, so the runs agree to
about 1e-13 (1e-9 relative at worst, for an acceleration under a stiff
controller) and not bit for bit. On the step 2^-9 s = 1 953 125 ns both
representations are exact and the runs agree bit for bit: that is tested
too, and shows the schemes are the same.

Examples left out, with the reason:
- emps_nominal, emps_symmetric_2019, emps_asymmetric_2019,
  slider_breakaway: driven by measured data through
  `fricsim run --input`, which an SSP file does not carry;
- stick_slip_sigma1e7: its friction component has two ParameterBindings
  (the .ssv, then the stiffer contact), and libcosim applies only the
  first binding of a component; tested below: libcosim runs it as
  stick_slip (the .ssv alone);
- stick_slip_fmi3: its FMUs are FMI 3.0, which libcosim 0.11 does not
  import (stick_slip, the same system in FMI 2.0, is run).
"""

import ctypes
import re
import subprocess
import zipfile

import numpy as np
import pytest
from libcosimpy.CosimEnums import CosimVariableCausality, CosimVariableType
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy._internal import libcosimc

from conftest import DIST, ROOT

FRICSIM = ROOT / "target" / "release" / "fricsim"

# example: stop time (None: the file's DefaultExperiment stopTime), cut to
# keep the suite short where the run is long
RUNS = {
    "stick_slip": 9.0,  # the first slip is at 7.54 s
    "classical_stick_slip": 4.0,  # stuck again at 2.97 s
    "dahl_velocity": None,
    "lugre_step_force": None,
    "hidden_effect_rig": None,
    "piezo_push": None,
    "piezo_relaxation": None,
    "slider_drift": None,
    "planar_decay": None,
    "planar_spiral": None,
    "planar_stick_slip": None,
    "planar_dither": 1.0,  # 40 000 steps of 25 µs
    "reset_integrator_stick_slip": 7.0,  # breaks away at 5.51 s
    "elasto_plastic_hold": None,
    "presliding_memory": None,
    "bliman_sorine_loops": None,
}
# (stick_slip_fmi3: libcosim 0.11 has no FMI 3.0 import; its FMI 2.0 twin,
# stick_slip, is run)
LEFT_OUT = {"emps_nominal", "emps_symmetric_2019", "emps_asymmetric_2019", "slider_breakaway",
            "stick_slip_sigma1e7", "stick_slip_fmi3"}


def archive(name):
    path = DIST / f"{name}.ssp"
    assert path.exists(), f"{path} is missing: run ./build-fmu.sh"
    return path


def experiment(name):
    """The step of our annotation and the DefaultExperiment stop time."""
    with zipfile.ZipFile(archive(name)) as z:
        ssd = z.read("SystemStructure.ssd").decode()
    step = float(re.search(r'<fricsim:Simulation[^>]*\bstepSize="([^"]+)"', ssd).group(1))
    stop = float(re.search(r'<ssd:DefaultExperiment[^>]*\bstopTime="([^"]+)"', ssd).group(1))
    return step, stop


def real_samples(observer, slave, reference, from_step, count):
    """Samples of a time series observer, by libcosim's C API:
    libcosimpy's `time_series_real_samples` trims its result by the number
    of zero step numbers, so it drops the last sample whenever the first
    is step 0 (the initial values)."""
    # a handle of our own on the library libcosimpy loaded: its function
    # objects, and so their argument types, are not libcosimpy's
    get = ctypes.CDLL(libcosimc()._name).cosim_observer_slave_get_real_samples
    get.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_uint32, ctypes.c_int64, ctypes.c_size_t,
                    ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_int64), ctypes.POINTER(ctypes.c_int64)]
    get.restype = ctypes.c_int64
    values = (ctypes.c_double * count)()
    steps = (ctypes.c_int64 * count)()
    times = (ctypes.c_int64 * count)()
    got = get(ctypes.cast(observer.ptr(), ctypes.c_void_p), slave, reference, from_step, count, values, steps, times)
    assert got >= 0, "libcosim refused to give the samples"
    return np.array(times[:got]), np.array(steps[:got]), np.array(values[:got])


def run_libcosim(ssp, step_ns, n):
    """Every Real output of every component of `ssp` after initialization
    and after each of `n` steps of `step_ns` nanoseconds."""
    log_output_level(CosimLogLevel.WARNING)
    execution = CosimExecution.from_ssp_file(str(ssp), step_size=step_ns)
    observer = CosimObserver.create_time_series(buffer_size=n + 1)
    assert execution.add_observer(observer)
    columns = []
    for slave in execution.slave_infos():
        for v in execution.slave_variables(slave.index):
            if v.causality == CosimVariableCausality.OUTPUT.value and v.type == CosimVariableType.REAL.value:
                assert observer.start_time_series(slave.index, v.reference, CosimVariableType.REAL)
                columns.append((f"{slave.name.decode()}.{v.name.decode()}", slave.index, v.reference))
    assert execution.simulate_until(n * step_ns)
    result, time = {}, None
    for name, slave, reference in columns:
        times, steps, values = real_samples(observer, slave, reference, 0, n + 1)
        assert list(steps) == list(range(n + 1)), f"{name}: steps {steps[:3]}…{steps[-3:]}"
        result[name] = values
        time = times * 1e-9
    return time, result


def run_fricsim(ssp, step, n, tmp_path):
    out = tmp_path / f"{ssp.stem}.csv"
    subprocess.run([str(FRICSIM), "run", str(ssp), "--master", "jacobi", "--step", repr(step),
                    "--stop", repr(n * step), "--out", str(out), "--quiet"], check=True, capture_output=True)
    header = out.read_text().splitlines()[0].split(",")
    data = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    # fricsim run records the Integer and Boolean outputs too (the laws'
    # `sliding`, Classical's `stuck`, the bristle model's `n_connected`,
    # the elasto-plastic law's `elastic`, the element laws' `n_slipping`);
    # the libcosim runs here record the Real ones, which are compared
    discrete = (".sliding", ".stuck", ".n_connected", ".elastic", ".n_slipping")
    return data[:, 0], {c: data[:, k] for k, c in enumerate(header) if k > 0 and not c.endswith(discrete)}


def relative_differences(ours, theirs):
    assert set(ours) == set(theirs)
    return {c: float(np.max(np.abs(ours[c] - theirs[c])) / max(np.max(np.abs(ours[c])), 1e-300)) for c in ours}


def test_the_lists_cover_every_example():
    examples = {p.stem for p in (ROOT / "examples").glob("*.ssd")}
    assert set(RUNS) | LEFT_OUT == examples and not set(RUNS) & LEFT_OUT


@pytest.mark.parametrize("name", RUNS)
def test_libcosim_equals_fricsim_jacobi(name, tmp_path):
    step, stop = experiment(name)
    stop = RUNS[name] or stop
    n = round(stop / step)
    step_ns = round(step * 1e9)
    assert step_ns * 1e-9 == step
    t_lc, libcosim = run_libcosim(archive(name), step_ns, n)
    t_fs, fricsim = run_fricsim(archive(name), step, n, tmp_path)
    assert len(t_fs) == len(t_lc) == n + 1
    assert np.max(np.abs(t_fs - t_lc)) <= 1e-12 * max(t_fs[-1], 1.0)
    assert all(np.all(np.isfinite(v)) for v in fricsim.values())
    differences = relative_differences(fricsim, libcosim)
    worst = max(differences, key=differences.get)
    assert differences[worst] <= 1e-9, f"{worst}: relative difference {differences[worst]:.3e}"


@pytest.mark.parametrize("name", ["stick_slip", "dahl_velocity", "planar_stick_slip", "piezo_push"])
def test_libcosim_equals_fricsim_bit_for_bit_on_a_dyadic_step(name, tmp_path):
    """h = 2^-9 s: libcosim's k·h_ns·1e-9 and fricsim's k·h are the same
    double, and so is every step size: the runs are the same bit for bit."""
    step_ns, n = 1_953_125, 5120  # 10 s
    step = step_ns * 1e-9
    assert step == 2.0 ** -9
    _, libcosim = run_libcosim(archive(name), step_ns, n)
    _, fricsim = run_fricsim(archive(name), step, n, tmp_path)
    assert set(fricsim) == set(libcosim)
    unequal = [c for c in fricsim if not np.array_equal(fricsim[c], libcosim[c])]
    assert not unequal, f"not bit for bit: {unequal}"
    # and the run is not at rest
    assert max(np.ptp(v) for v in fricsim.values()) > 0.0


def test_libcosim_applies_only_the_first_parameter_binding(tmp_path):
    """stick_slip_sigma1e7 binds lugre_1995.ssv, then sigma0 = 1e7 N/m and
    sigma1 = 3162 N.s/m inline. libcosim's run of it is fricsim's run of
    stick_slip (the .ssv alone, the same rig), not of stick_slip_sigma1e7."""
    step, _ = experiment("stick_slip_sigma1e7")
    n = round(9.0 / step)
    step_ns = round(step * 1e9)
    _, libcosim = run_libcosim(archive("stick_slip_sigma1e7"), step_ns, n)
    _, as_stick_slip = run_fricsim(archive("stick_slip"), step, n, tmp_path)
    _, as_written = run_fricsim(archive("stick_slip_sigma1e7"), step, n, tmp_path)
    assert max(relative_differences(as_stick_slip, libcosim).values()) <= 1e-9
    # the deflection is about a hundred times smaller with sigma0 = 1e7
    z_written, z_libcosim = np.max(np.abs(as_written["friction.z"])), np.max(np.abs(libcosim["friction.z"]))
    assert 50 < z_libcosim / z_written < 200
