"""Shared helpers for the FMPy conformance tests.

The FMUs are built by ./build-fmu.sh into dist/, the in-process reference
runner by `cargo build --release -p friction-fmu` (both done by
./run-tests.sh before pytest runs)."""

from ctypes import byref
from pathlib import Path
import shutil
import subprocess

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
from fmpy.simulation import Input

import shipped

ROOT = Path(__file__).resolve().parent.parent
DIST = ROOT / "dist"
RUN_LAW = ROOT / "target" / "release" / "run-law"
#: the friction laws (modelDescription/shipped.txt, through tests/shipped.py)
MODELS = shipped.LAWS


def fmu_path(name):
    path = DIST / f"{name}.fmu"
    assert path.exists(), f"{path} is missing: run ./build-fmu.sh"
    return path


#: Every callback structure handed to FMPy's process-wide logger proxy.
_PROXIED_CALLBACKS = []


def add_logger_proxy(callbacks):
    """FMPy's addLoggerProxy, with `callbacks` kept alive for the whole
    process: the proxy is one for the process and keeps pointing at them
    after their instance is gone, so that a later FMU2Slave's messages
    (FMPy's default logger goes through the proxy) would call freed
    memory."""
    from fmpy.logging import addLoggerProxy

    addLoggerProxy(byref(callbacks))
    _PROXIED_CALLBACKS.append(callbacks)


class CapturedInstance:
    """An FMU2Slave whose log messages are collected in `messages`."""

    def __init__(self, name, tmp_path, logging_on=False):
        from fmpy.fmi2 import calloc, free

        self.path = fmu_path(name)
        self.md = read_model_description(str(self.path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.unzipdir = extract(str(self.path), unzipdir=str(tmp_path / name))
        self.messages = []

        def logger(env, instance, status, category, message):
            self.messages.append((status, category.decode(), message.decode()))

        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(logger)
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        add_logger_proxy(self.callbacks)
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.unzipdir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="probe")
        self.fmu.instantiate(callbacks=self.callbacks, loggingOn=logging_on)

    def last_error(self):
        errors = [m for s, _, m in self.messages if s >= 3]
        assert errors, f"no error was logged; messages: {self.messages}"
        return errors[-1]

    def close(self):
        self.fmu.freeInstance()
        shutil.rmtree(self.unzipdir, ignore_errors=True)


@pytest.fixture
def instance(tmp_path):
    opened = []

    def open_(name, **kwargs):
        # Each instance unpacks into its own directory: unpacking again
        # over a binary that is loaded would rewrite it under the instance.
        parent = tmp_path / f"instance{len(opened)}"
        parent.mkdir()
        inst = CapturedInstance(name, parent, **kwargs)
        opened.append(inst)
        return inst

    yield open_
    for inst in opened:
        inst.close()


def applied_inputs(signal, times, set_input_derivatives):
    """The input values (and slopes) FMPy applies at each communication
    point, computed with FMPy's own interpolation routine."""
    names = signal.dtype.names[1:]
    table = np.array([signal[n] for n in names])
    columns = {n: [] for n in names}
    slopes = {n: [] for n in names}
    for t in times:
        v, d = Input.interpolate(time=t, t=signal["time"], table=table, discrete=False, after_event=True)
        for k, n in enumerate(names):
            columns[n].append(float(v[k]))
            slopes[n].append(float(d[k]) if set_input_derivatives else 0.0)
    return columns, slopes


def run_in_process(model, times, columns, slopes, parameters, tmp_path):
    """Run `run-law` (the model without the C ABI) and return its outputs."""
    assert RUN_LAW.exists(), f"{RUN_LAW} is missing: run cargo build --release -p friction-fmu"
    names = list(columns)
    inp = tmp_path / f"{model}_in.csv"
    out = tmp_path / f"{model}_out.csv"
    with open(inp, "w") as f:
        f.write(",".join(["time"] + names + [f"der({n})" for n in names]) + "\n")
        for i, t in enumerate(times):
            row = [t] + [columns[n][i] for n in names] + [slopes[n][i] for n in names]
            f.write(",".join(repr(float(x)) for x in row) + "\n")
    args = [str(RUN_LAW), model, str(inp), str(out)]
    args += [f"{k}={str(v).lower() if isinstance(v, bool) else repr(v)}" for k, v in parameters.items()]
    subprocess.run(args, check=True, capture_output=True, text=True)
    return np.genfromtxt(out, delimiter=",", names=True)



#: Test files whose tests share nothing (each works in its own tmp_path and
#: processes) and take long: spread test by test over the pytest-xdist
#: workers. Every other file runs whole on one worker, as `--dist loadfile`
#: has it (its module fixtures, such as the Dask cluster of
#: test_python_dask.py or the Wine prefix of test_windows_dll.py, are made
#: once).
SPREAD_FILES = {"test_diagnose_independent.py", "test_libcosim.py"}


def pytest_xdist_make_scheduler(config, log):
    """`--dist loadfile` (run-tests.sh), but the tests of SPREAD_FILES one
    by one: pytest-xdist's scope scheduling with a scope per file, and per
    test in those files. (Not `--dist loadgroup` with marks: pytest-xdist
    3.8 renames a marked test's node id, which pytest 9.2 no longer lets
    it do, so the marks group nothing.)"""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class FileOrTestScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid):
            file = nodeid.split("::", 1)[0]
            return nodeid if Path(file).name in SPREAD_FILES else file

    return FileOrTestScheduling(config, log)


def pytest_collection_modifyitems(config, items):
    """The tests of SPREAD_FILES first. run-tests.sh passes
    `--no-loadscope-reorder`, so the scheduler hands the work out in this
    order: the long single tests start at once on both workers instead of
    last (pytest-xdist's own order puts the files with the most tests
    first), when one worker could be left running the longest alone."""
    items.sort(key=lambda item: item.path.name not in SPREAD_FILES)
