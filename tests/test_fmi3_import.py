"""FMI 3.0 Co-Simulation FMUs imported by fricsim, against FMPy.

FMUs written by hand in C for these tests against the FMI 3.0
standard (host/tests/c/fmi3, like the Modelica Reference-FMUs of the same
names, which cannot be fetched from these machines):

- BouncingBall: Float64 height and velocity, an Int32 count of bounces, a
  Boolean `resting`, a String parameter; each bounce is found inside
  fmi3DoStep in closed form;
- Stair: an Int32 counter one higher every second, a Boolean and a
  Float64 output, and at the top (t = 9) fmi3DoStep sets
  terminateSimulation;
- SpringMass: the stick-slip rig of Canudas de Wit et al. 1995 with the
  friction force as its Float64 input;
- Gains: FMI 3.0 arrays (Float64, Int32 and Boolean, one 2-D) as
  parameters, an input and outputs, which fricsim reads element by
  element (`k[2]`, `A[1,3]`) and FMPy as arrays;
- Feedthrough: an input of every FMI 3.0 type (Float32, the integers
  of every width, Boolean, Enumeration, and a Float32 array) fed through
  to an output, each through the getter and setter of its type.

`fricsim cosim` of each must record exactly the rows FMPy's simulate_fmu
records (FMPy's FMI 3.0 Co-Simulation loop), and an FMI 3.0 FMU and an FMI
2.0 one must work in one system: LuGre.fmu (FMI 2.0) driven by the FMI 3.0
BouncingBall equals LuGre.fmu driven by the ball's recorded velocity."""

import csv
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
        "gains": compile_fmu(work, C_FMI3 / "gains.c", C_FMI3 / "gains.xml", "Gains",
                             "x86_64-linux"),
        "feedthrough": compile_fmu(work, C_FMI3 / "feedthrough.c", C_FMI3 / "feedthrough.xml",
                                   "Feedthrough", "x86_64-linux"),
    }


@pytest.mark.parametrize("name", ["ball", "stair", "rig", "gains", "feedthrough"])
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


def read_csv(path):
    """Header (quoted names unquoted, as a CSV reader takes them) and rows."""
    with open(path, newline="") as f:
        header = next(csv.reader(f))
    return header, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def test_fmi3_arrays_in_fricsim_equal_simulate_fmu(fmus, tmp_path):
    """Gains, its arrays given element by element in fricsim and whole in
    FMPy: parameters changed in some elements (`--set g.k[2]=…`, a 2-D
    one, an Int32 and a Boolean one), the input array driven by a table
    (held over each step, as FMPy holds it), every element of every output
    array recorded: fricsim's rows are FMPy's, to 1e-12."""
    t = np.linspace(0.0, 2.0, 21)
    u = np.zeros(t.size, dtype=[("time", float), ("u", float, (3,))])
    u["time"] = t
    u["u"][:, 0] = np.sin(3.0 * t)
    u["u"][:, 1] = 1.0 - t
    u["u"][:, 2] = 0.25 * t * t
    changed = {"k[2]": -2.0, "k[3]": 4.0, "enable[3]": True, "A[2,1]": 3.5, "offset[2]": -4}
    starts = {"k": [1.0, -2.0, 4.0], "enable": [True, True, True],
              "A": [1.0, 0.0, 0.5, 3.5, 1.0, -1.0], "offset": [10, -4]}
    expected = simulate_fmu(str(fmus["gains"]), stop_time=2, step_size=0.1, output_interval=0.1,
                            input=u, start_values=starts)

    table = tmp_path / "u.csv"
    np.savetxt(table, np.column_stack([t, u["u"]]), delimiter=",",
               header="time,g.u[1],g.u[2],g.u[3]", comments="", fmt="%.17g")
    out = tmp_path / "gains.csv"
    args = ["cosim", "--fmu", f"g={fmus['gains']}", "--input", table, "--input-hold",
            "--step", "0.1", "--stop", "2", "--out", out]
    for name, value in changed.items():
        args += ["--set", f"g.{name}={str(value).lower() if isinstance(value, bool) else value}"]
    process = fricsim(*args)
    assert process.returncode == 0, process.stdout + process.stderr
    header, rows = read_csv(out)
    # every element of every output array, and the scalar, in a column
    elements = ([f"y[{i}]" for i in (1, 2, 3)] + [f"yd[{i}]" for i in (1, 2, 3)]
                + [f"z[{r},{c}]" for r in (1, 2) for c in (1, 2, 3)] + ["total"]
                + ["count[1]", "count[2]"] + [f"positive[{i}]" for i in (1, 2, 3)])
    assert header == ["time"] + [f"g.{e}" for e in elements]
    assert out.read_text().startswith('time,g.y[1],g.y[2],g.y[3],g.yd[1],g.yd[2],g.yd[3],"g.z[1,1]"')
    assert len(rows) == len(expected) == 21
    np.testing.assert_array_equal(rows[:, 0], expected["time"])
    for column, name in enumerate(elements, start=1):
        array, _, index = name.partition("[")
        values = expected[array].astype(float)
        if index:
            values = values[(slice(None), *(int(i) - 1 for i in index.rstrip("]").split(",")))]
        np.testing.assert_allclose(rows[:, column], values, rtol=1e-12, atol=1e-15, err_msg=name)
    # the changed elements took: the third integrator runs, with gain 4,
    # and the 2-D weight and the Int32 offset are the ones set
    assert rows[-1, header.index("g.y[3]")] > 0.5
    z21 = rows[:, header.index("g.z[2,1]")]
    np.testing.assert_allclose(z21, 3.5 * rows[:, header.index("g.y[1]")], rtol=1e-15)
    np.testing.assert_array_equal(rows[:, header.index("g.count[2]")], -4 + 2 * np.arange(21))


def test_an_fmi3_array_element_is_recorded_and_connected_by_name_in_the_python_package(fmus,
                                                                                      tmp_path):
    """`fricsim.run` of an SSP system connecting one Gains' output element
    to another's input element: the columns are the elements' names, and
    the connected input follows the output it is connected to."""
    import fricsim as package

    ssd = tmp_path / "pair.ssd"
    ssd.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="pair"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription">
  <ssd:System name="pair">
    <ssd:Elements>
      <ssd:Component name="a" source="{fmus['gains']}">
        <ssd:Connectors><ssd:Connector name="z[2,2]" kind="output"/></ssd:Connectors>
      </ssd:Component>
      <ssd:Component name="b" source="{fmus['gains']}">
        <ssd:Connectors><ssd:Connector name="u[2]" kind="input"/></ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="a" startConnector="z[2,2]" endElement="b" endConnector="u[2]"/>
    </ssd:Connections>
  </ssd:System>
</ssd:SystemStructureDescription>
""")
    result = package.run(ssd, step=0.1, stop=1)
    names = list(result.dtype.names)
    assert "a.z[2,2]" in names and "b.yd[2]" in names and "b.count[2]" in names
    # b.yd[2] = k[2]·u[2] = 2·a.z[2,2] (from the row before: Jacobi)
    np.testing.assert_allclose(result["b.yd[2]"][1:], 2.0 * result["a.z[2,2]"][:-1], rtol=1e-15)
    assert result["a.z[2,2]"][-1] < -1.5


def test_every_fmi3_type_fed_through_in_fricsim_equals_simulate_fmu(fmus, tmp_path):
    """Feedthrough with an input of every type set (`--set`; FMPy's start
    values), a Float32 one to a value it rounds and the 64-bit ones to
    values beyond 32 bits: fricsim records every output as FMPy does,
    exactly, the narrow integers and Booleans as whole numbers."""
    values = {
        "Float32_input": 0.3, "Float64_input": -1.25, "Int8_input": 127, "UInt8_input": 0,
        "Int16_input": -300, "UInt16_input": 40000, "Int32_input": 123456789,
        "UInt32_input": 3000000000, "Int64_input": -5000000000, "UInt64_input": 2 ** 52 + 1,
        "Boolean_input": False, "Enumeration_input": 3,
    }
    expected = simulate_fmu(str(fmus["feedthrough"]), stop_time=1, step_size=0.25,
                            output_interval=0.25,
                            start_values={**values, "Float32_array_input": [-0.1, 4.0]})
    out = tmp_path / "feedthrough.csv"
    args = ["cosim", "--fmu", f"f={fmus['feedthrough']}", "--step", "0.25", "--stop", "1",
            "--out", out, "--set", "f.Float32_array_input[1]=-0.1",
            "--set", "f.Float32_array_input[2]=4"]
    for name, value in values.items():
        args += ["--set", f"f.{name}={str(value).lower() if isinstance(value, bool) else value}"]
    process = fricsim(*args)
    assert process.returncode == 0, process.stdout + process.stderr
    header, rows = read_csv(out)
    outputs = [name.replace("_input", "_output") for name in values]
    assert sorted(header[1:]) == sorted(
        [f"f.{o}" for o in outputs] + ["f.Float32_array_output[1]", "f.Float32_array_output[2]"])
    np.testing.assert_array_equal(rows[:, 0], expected["time"])
    for name in outputs:
        column = rows[:, header.index(f"f.{name}")]
        np.testing.assert_array_equal(column, expected[name].astype(float), err_msg=name)
    for i in (1, 2):
        column = rows[:, header.index(f"f.Float32_array_output[{i}]")]
        np.testing.assert_array_equal(column,
                                      expected["Float32_array_output"][:, i - 1].astype(float))
    # what went in came out, as each type holds it (0.3 as a Float32)
    assert rows[-1, header.index("f.Float32_output")] == float(np.float32(0.3)) != 0.3
    assert rows[-1, header.index("f.UInt64_output")] == 2 ** 52 + 1
    # the narrow integers and the Booleans written as whole numbers
    text = out.read_text().splitlines()[1].split(",")
    assert text[header.index("f.Int16_output")] == "-300"
    assert text[header.index("f.Boolean_output")] == "0"
