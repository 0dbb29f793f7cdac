"""FMI 3.0 Co-Simulation FMUs imported by fricsim, against FMPy.

Two FMUs written by hand in C for these tests against the FMI 3.0
standard (host/tests/c/fmi3, like the Modelica Reference-FMUs of the same
names, which cannot be fetched from these machines):

- BouncingBall: Float64 height and velocity, an Int32 count of bounces, a
  Boolean `resting`, a String parameter; each bounce is found inside
  fmi3DoStep in closed form;
- Stair: an Int32 counter one higher every second, a Boolean and a
  Float64 output, and at the top (t = 9) fmi3DoStep sets
  terminateSimulation;
- SpringMass: the stick-slip rig of Canudas de Wit et al. 1995 with the
  friction force as its Float64 input.

`fricsim cosim` of each must record exactly the rows FMPy's simulate_fmu
records (FMPy's FMI 3.0 Co-Simulation loop), and an FMI 3.0 FMU and an FMI
2.0 one must work in one system: LuGre.fmu (FMI 2.0) driven by the FMI 3.0
BouncingBall equals LuGre.fmu driven by the ball's recorded velocity."""

import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

from conftest import DIST, ROOT
from test_foreign_fmu import cosim, fricsim

C_FMI3 = ROOT / "host" / "tests" / "c" / "fmi3"


def compile_fmu(work, source, description, identifier, platform):
    """``work/<identifier>.fmu`` from a C file and its model description."""
    library = work / f"{identifier}-{platform}.so"
    subprocess.run(["cc", "-shared", "-fPIC", "-fvisibility=hidden", "-O1", "-Wall", "-Wextra",
                    "-o", str(library), str(source), "-lm"],
                   check=True, capture_output=True, text=True)
    fmu = work / f"{identifier}.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        z.write(description, "modelDescription.xml")
        z.write(library, f"binaries/{platform}/{identifier}.so")
    return fmu


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    work = tmp_path_factory.mktemp("fmi3")
    return {
        "ball": compile_fmu(work, C_FMI3 / "bouncing_ball.c", C_FMI3 / "bouncing_ball.xml",
                            "BouncingBall", "x86_64-linux"),
        "stair": compile_fmu(work, C_FMI3 / "stair.c", C_FMI3 / "stair.xml", "Stair",
                             "x86_64-linux"),
        "rig": compile_fmu(work, C_FMI3 / "spring_mass.c", C_FMI3 / "spring_mass.xml",
                           "SpringMass", "x86_64-linux"),
    }


@pytest.mark.parametrize("name", ["ball", "stair", "rig"])
def test_fmpy_validates_the_fmi3_test_fmus(fmus, name):
    assert validate_fmu(str(fmus[name])) == []


def test_the_bouncing_ball_in_fricsim_equals_simulate_fmu(fmus, tmp_path):
    expected = simulate_fmu(str(fmus["ball"]), stop_time=3, step_size=0.01, output_interval=0.01)
    process, header, rows = cosim([("ball", fmus["ball"])], {}, [], 0.01, 3, tmp_path / "ball.csv")
    assert process.returncode == 0, process.stdout + process.stderr
    assert header == ["time", "ball.h", "ball.v", "ball.bounces", "ball.resting"]
    assert len(rows) == len(expected) == 301
    np.testing.assert_array_equal(rows[:, 0], expected["time"])
    for column, name in enumerate(["h", "v", "bounces", "resting"], start=1):
        np.testing.assert_allclose(rows[:, column], expected[name].astype(float), rtol=1e-12,
                                   atol=1e-15, err_msg=name)
    # it bounced, and came to rest, in both
    assert expected["bounces"][-1] == rows[-1, 3] > 5
    assert expected["resting"][-1] and rows[-1, 4] == 1


def test_the_fmi3_stair_ends_the_run_where_fmpy_ends_it(fmus, tmp_path):
    expected = simulate_fmu(str(fmus["stair"]), stop_time=10, step_size=0.5, output_interval=0.5)
    process, header, rows = cosim([("stair", fmus["stair"])], {}, [], 0.5, 10, tmp_path / "s.csv")
    assert process.returncode == 0, process.stdout + process.stderr
    assert "stair ended the simulation at t = 9" in process.stdout, process.stdout
    assert header == ["time", "stair.height", "stair.counter", "stair.even"]
    assert expected["time"][-1] == rows[-1, 0] == 9.0
    np.testing.assert_array_equal(rows[:, 0], expected["time"])
    np.testing.assert_array_equal(rows[:, 1], expected["height"])
    np.testing.assert_array_equal(rows[:, 2], expected["counter"])
    np.testing.assert_array_equal(rows[:, 3], expected["even"].astype(float))


def test_an_fmi3_fmu_drives_an_fmi2_fmu_as_a_recorded_input_does(fmus, tmp_path):
    """One system of both versions: the FMI 3.0 BouncingBall drives the
    velocity input of LuGre.fmu (FMI 2.0). The friction force equals that
    of LuGre.fmu alone driven by the ball's recorded velocity, held over
    each step (`--input-hold`: what the Jacobi master gives a connected
    input), at every row."""
    lugre = DIST / "LuGre.fmu"
    process, header, rows = cosim([("ball", fmus["ball"]), ("lugre", lugre)], {},
                                  [("ball", "v", "lugre", "v")], 0.01, 3, tmp_path / "mixed.csv")
    assert process.returncode == 0, process.stdout + process.stderr
    v, force = rows[:, header.index("ball.v")], rows[:, header.index("lugre.F")]
    assert np.abs(force).max() > 0.5  # the ball's speed makes friction

    recorded = tmp_path / "v.csv"
    np.savetxt(recorded, np.column_stack([rows[:, 0], v]), delimiter=",",
               header="time,lugre.v", comments="", fmt="%.17g")
    alone = tmp_path / "alone.csv"
    args = ["cosim", "--fmu", f"lugre={lugre}", "--input", recorded, "--input-hold",
            "--step", "0.01", "--stop", "3", "--out", alone]
    process = fricsim(*args)
    assert process.returncode == 0, process.stdout + process.stderr
    header_alone = alone.read_text().splitlines()[0].split(",")
    rows_alone = np.loadtxt(alone, delimiter=",", skiprows=1, ndmin=2)
    np.testing.assert_array_equal(rows_alone[:, 0], rows[:, 0])
    np.testing.assert_allclose(rows_alone[:, header_alone.index("lugre.F")], force, rtol=1e-12,
                               atol=1e-12)


def test_an_isolated_run_and_the_python_package_record_the_same_rows(fmus, tmp_path):
    """`--isolate` (the FMUs in a child process) and `fricsim.run` of the
    Python package load FMI 3.0 FMUs as `fricsim cosim` does."""
    import fricsim as package

    plain = tmp_path / "plain.csv"
    process, header, rows = cosim([("ball", fmus["ball"]), ("stair", fmus["stair"])], {}, [],
                                  0.5, 10, plain)
    assert process.returncode == 0, process.stdout + process.stderr
    isolated = tmp_path / "isolated.csv"
    args = ["cosim", "--fmu", f"ball={fmus['ball']}", "--fmu", f"stair={fmus['stair']}",
            "--step", "0.5", "--stop", "10", "--out", isolated, "--isolate"]
    process = fricsim(*args)
    assert process.returncode == 0, process.stdout + process.stderr
    assert isolated.read_text() == plain.read_text()

    ssd = tmp_path / "both.ssd"
    ssd.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="both"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription">
  <ssd:System name="both">
    <ssd:Elements>
      <ssd:Component name="ball" source="{fmus['ball']}"/>
      <ssd:Component name="stair" source="{fmus['stair']}"/>
    </ssd:Elements>
  </ssd:System>
</ssd:SystemStructureDescription>
""")
    result = package.run(ssd, step=0.5, stop=10)
    assert list(result.dtype.names) == header
    np.testing.assert_array_equal(np.column_stack([result[c] for c in header]), rows)


def test_an_fmi3_fmu_with_an_input_equals_simulate_fmu(fmus, tmp_path):
    """SpringMass driven by a measured force (``--input``, held over each
    step as FMPy holds it) records FMPy's rows, to 1e-12."""
    t = np.linspace(0.0, 5.0, 501)
    force = np.rec.fromarrays([t, 0.4 * np.sin(2.0 * t)], names=["time", "F"])
    expected = simulate_fmu(str(fmus["rig"]), stop_time=5, step_size=0.01, output_interval=0.01,
                            input=force)
    table = tmp_path / "force.csv"
    np.savetxt(table, np.column_stack([t, force["F"]]), delimiter=",", header="time,rig.F",
               comments="", fmt="%.17g")
    out = tmp_path / "rig.csv"
    args = ["cosim", "--fmu", f"rig={fmus['rig']}", "--input", table, "--input-hold",
            "--step", "0.01", "--stop", "5", "--out", out]
    process = fricsim(*args)
    assert process.returncode == 0, process.stdout + process.stderr
    header = out.read_text().splitlines()[0].split(",")
    rows = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    np.testing.assert_array_equal(rows[:, 0], expected["time"])
    for name in ["x", "v"]:
        column = rows[:, header.index(f"rig.{name}")]
        assert np.abs(expected[name]).max() > 0.05
        np.testing.assert_allclose(column, expected[name], rtol=1e-12, atol=1e-14, err_msg=name)


SWEPT = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="swept"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription">
  <ssd:System name="swept">
    <ssd:Elements>
      <ssd:Component name="rig" source="{rig}">
        <ssd:Connectors>
          <ssd:Connector name="v" kind="output"/>
          <ssd:Connector name="F" kind="input"/>
          <ssd:Connector name="k" kind="parameter"/>
        </ssd:Connectors>
      </ssd:Component>
      <ssd:Component name="friction" source="{lugre}">
        <ssd:Connectors>
          <ssd:Connector name="v" kind="input"/>
          <ssd:Connector name="F" kind="output"/>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="rig" startConnector="v" endElement="friction" endConnector="v"/>
      <ssd:Connection startElement="friction" startConnector="F" endElement="rig" endConnector="F"/>
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="5"/>
</ssd:SystemStructureDescription>
"""


def test_a_sweep_over_an_fmi3_parameter_equals_single_runs(fmus, tmp_path):
    """`fricsim sweep` sets an FMI 3.0 component's parameter in each run:
    the final values of each run equal `fricsim cosim --set` of that
    value, with the Newton master (FMI 3.0 directional derivatives and
    FMU state)."""
    ssd = tmp_path / "swept.ssd"
    ssd.write_text(SWEPT.format(rig=fmus["rig"], lugre=DIST / "LuGre.fmu"))
    table = tmp_path / "sweep.csv"
    process = fricsim("sweep", ssd, "--param", "rig.k=1,4", "--step", "1e-3", "--master",
                      "newton", "--out", table)
    assert process.returncode == 0, process.stdout + process.stderr
    swept = np.genfromtxt(table, delimiter=",", names=True, dtype=None, encoding="utf-8")
    finals = []
    for k in [1.0, 4.0]:
        out = tmp_path / f"k{k}.csv"
        process = fricsim("cosim", "--fmu", f"rig={fmus['rig']}", "--fmu",
                          f"friction={DIST / 'LuGre.fmu'}", "--connect", "rig.v->friction.v",
                          "--connect", "friction.F->rig.F", "--set", f"rig.k={k}", "--master",
                          "newton", "--step", "1e-3", "--stop", "5", "--out", out)
        assert process.returncode == 0, process.stdout + process.stderr
        header = out.read_text().splitlines()[0].split(",")
        last = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)[-1]
        finals.append(last[header.index("rig.x")])
    np.testing.assert_array_equal(swept["rigk"], [1.0, 4.0])
    np.testing.assert_allclose(swept["finalrigx"], finals, rtol=1e-12)
    # the stiffer spring breaks the contact loose within 5 s, the softer does not
    assert finals[1] > 100 * finals[0]
