"""An FMU that ends the simulation, in fricsim and in FMPy.

Stair (host/tests/c/stair, written by hand in C like the Modelica Reference
FMU Stair): an Integer output `counter` one higher every second, a Boolean
output `even`, a Real output `height`; at t = 9 its fmi2DoStep returns
fmi2Discard with fmi2Terminated = true. FMPy's simulate_fmu takes that for
the normal end and records the row at fmi2LastSuccessfulTime; `fricsim run`
must record the same rows (times and values exactly), exit with status 0,
and write the Integer and Boolean columns as integers."""

import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import simulate_fmu

from conftest import ROOT

FRICSIM = ROOT / "target" / "release" / "fricsim"
STAIR_SOURCE = ROOT / "host" / "tests" / "c" / "stair"

SSD = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="stair"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
  <ssd:System name="stair">
    <ssd:Elements><ssd:Component name="stair" source="Stair.fmu"/></ssd:Elements>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="10">
    <ssd:Annotations>
      <ssc:Annotation type="org.friction-fmu.fricsim">
        <fricsim:Simulation xmlns:fricsim="urn:friction-fmu:fricsim:1" stepSize="0.25"/>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""


@pytest.fixture(scope="module")
def stair(tmp_path_factory):
    """Stair.fmu, compiled and zipped from the C source, and a system file
    of it (steps of 0.25 s up to 10 s)."""
    work = tmp_path_factory.mktemp("stair")
    library = work / "Stair.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-fvisibility=hidden", "-O1", "-Wall", "-Wextra",
                    "-o", str(library), str(STAIR_SOURCE / "stair.c"), "-lm"],
                   check=True, capture_output=True, text=True)
    fmu = work / "Stair.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        z.write(STAIR_SOURCE / "modelDescription.xml", "modelDescription.xml")
        z.write(library, "binaries/linux64/Stair.so")
    (work / "stair.ssd").write_text(SSD)
    return work


def test_fricsim_records_the_rows_fmpy_records_up_to_the_end_at_t_9(stair):
    expected = simulate_fmu(str(stair / "Stair.fmu"), fmi_type="CoSimulation", stop_time=10,
                            step_size=0.25, output_interval=0.25)
    out = stair / "stair.csv"
    run = subprocess.run([str(FRICSIM), "run", str(stair / "stair.ssd"), "--out", str(out), "--quiet"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "stair ended the simulation at t = 9" in run.stdout, run.stdout
    text = out.read_text()
    assert "INCOMPLETE" not in text
    header = text.splitlines()[0].split(",")
    assert header == ["time", "stair.height", "stair.counter", "stair.even"]
    got = np.genfromtxt(out, delimiter=",", names=True)

    # FMPy ends at t = 9 with the row there, as fricsim does
    assert expected["time"][-1] == 9.0
    np.testing.assert_array_equal(got["time"], expected["time"])
    np.testing.assert_array_equal(got["stairheight"], expected["height"])
    np.testing.assert_array_equal(got["staircounter"], expected["counter"])
    np.testing.assert_array_equal(got["staireven"], expected["even"].astype(int))
    assert expected["counter"][-1] == 10

    # Integer and Boolean columns are whole numbers in the file: `10,1`
    assert text.splitlines()[-1] == "9.0,10.0,10,1"


def trace_of(trace):
    """The lines Stair wrote to ``trace`` (STAIR_TRACE), the file then removed."""
    lines = trace.read_text().splitlines() if trace.exists() else []
    trace.unlink(missing_ok=True)
    return lines


def test_fricsim_sets_up_and_ends_the_instance_as_fmpy_does(stair, monkeypatch):
    """FMPy's simulate_fmu tells the instance the stop time in
    fmi2SetupExperiment and, after the last step, calls fmi2Terminate, then
    fmi2FreeInstance (FMI 2.0 section 4.2.4); `fricsim run` makes the same
    calls in the same phases with the same stop time. Stair traces them
    with its phase (1 = instantiated, 8 = stepFailed after its discarded
    last step, 16 = terminated)."""
    trace = stair / "trace.txt"
    trace.unlink(missing_ok=True)
    monkeypatch.setenv("STAIR_TRACE", str(trace))
    simulate_fmu(str(stair / "Stair.fmu"), fmi_type="CoSimulation", stop_time=10, step_size=0.25)
    by_fmpy = trace_of(trace)
    run = subprocess.run([str(FRICSIM), "run", str(stair / "stair.ssd"), "--out",
                          str(stair / "traced.csv"), "--quiet"], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    assert by_fmpy == ["fmi2SetupExperiment phase=1 t=0 stop=10",
                       "fmi2Terminate phase=8 t=9", "fmi2FreeInstance phase=16 t=9"]
    assert trace_of(trace) == by_fmpy


def test_the_python_package_warns_of_a_refused_fmi2terminate(stair, monkeypatch):
    """fricsim.run returns every row and gives a FricsimWarning naming the
    instance and its message when fmi2Terminate fails, as `fricsim run`
    prints a warning."""
    import fricsim

    monkeypatch.setenv("STAIR_TERMINATE_FAILS", "the final check failed")
    with pytest.warns(fricsim.FricsimWarning, match="fmi2Terminate failed for instance \"stair\"") as caught:
        result = fricsim.run(stair / "stair.ssd")
    assert "the final check failed" in str(caught[0].message)
    assert len(result) == 37 and result["time"][-1] == 9.0
