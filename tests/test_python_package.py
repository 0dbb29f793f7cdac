"""The Python package `fricsim` (python/, installed into .venv by
scripts/setup-python-package.sh): the same numbers as the `fricsim`
command bit for bit, the host's messages in its exceptions, DataFrames
where the command takes CSV files, and Ctrl-C that stops a run cleanly."""

import csv
import math
import re
import os
import signal
import subprocess
import sys
import tempfile
import textwrap

import numpy as np
import pandas as pd
import pytest

import fricsim

ROOT = __import__("pathlib").Path(__file__).resolve().parent.parent
FRICSIM = ROOT / "target" / "release" / "fricsim"
STICK_SLIP = ROOT / "examples" / "stick_slip.ssd"
PLANAR = ROOT / "examples" / "planar_stick_slip.ssd"
EMPS = ROOT / "examples" / "emps_nominal.ssd"
EMPS_TRAIN = ROOT / "examples" / "data" / "emps_train.csv"
EMPS_TEST = ROOT / "examples" / "data" / "emps_test_pulses.csv"
SLIDER = ROOT / "examples" / "slider_breakaway.ssd"
SLIDER_DATA = ROOT / "examples" / "data" / "slider_breakaway.csv"


def cli(*args, cwd=ROOT):
    assert FRICSIM.exists(), f"{FRICSIM} is missing: cargo build --release -p fricsim"
    return subprocess.run([str(FRICSIM), *map(str, args)], cwd=cwd, capture_output=True, text=True)


def read_exact_csv(path):
    """A result CSV as column name -> float64 array, every number parsed
    by Python's float (exact for the shortest round-trip digits)."""
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    header, body = rows[0], rows[1:]
    return {name: np.array([float(r[k]) for r in body]) for k, name in enumerate(header)}


def same_bits(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


@pytest.mark.parametrize(
    "system, options",
    [
        (STICK_SLIP, {"stop": 12.0}),
        (PLANAR, {"stop": 2.0, "master": "gauss-seidel"}),
    ],
    ids=["stick_slip", "planar_stick_slip"],
)
def test_run_equals_the_command_csv_bit_for_bit(tmp_path, system, options):
    result = fricsim.run(system, **options)
    out = tmp_path / "run.csv"
    args = ["run", system, "--out", out, "--quiet", "--stop", options["stop"]]
    if "master" in options:
        args += ["--master", options["master"]]
    done = cli(*args)
    assert done.returncode == 0, done.stderr
    expected = read_exact_csv(out)
    assert list(result.dtype.names) == list(expected)
    assert result.dtype.names[0] == "time"
    assert len(result) == len(expected["time"]) > 1000
    for name in expected:
        assert same_bits(result[name], expected[name]), name
    frame = pd.DataFrame(result)
    assert list(frame.columns) == list(expected)
    assert same_bits(frame["time"].to_numpy(), expected["time"])


ALONE = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription version="1.0" name="alone"
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">
  <ssd:System name="alone">
    <ssd:Elements>
      <ssd:Component name="friction" source="{fmu}">
        <ssd:Connectors>
          <ssd:Connector name="v" kind="input"><ssc:Real unit="m/s"/></ssd:Connector>
          <ssd:Connector name="F" kind="output"><ssc:Real unit="N"/></ssd:Connector>
        </ssd:Connectors>
      </ssd:Component>
    </ssd:Elements>
  </ssd:System>
</ssd:SystemStructureDescription>
"""


def test_start_values_and_output_interval():
    base = fricsim.run(STICK_SLIP, stop=10.0)
    stickier = fricsim.run(STICK_SLIP, stop=10.0, start_values={"friction.Fs": 2.0})
    assert base["friction.F"].max() < 1.5 < stickier["friction.F"].max() <= 2.0
    # every 100th communication point of the same run (10 s at 1e-4 s)
    sparse = fricsim.run(STICK_SLIP, stop=10.0, output_interval=1e-2)
    assert len(sparse) == 1001
    for name in base.dtype.names:
        assert same_bits(sparse[name], base[name][::100]), name


def test_a_dataframe_input_equals_the_command_with_the_csv(tmp_path):
    system = tmp_path / "alone.ssd"
    system.write_text(ALONE.format(fmu=ROOT / "dist" / "LuGre.fmu"))
    t = np.linspace(0.0, 1.0, 101)
    v = 2e-3 * np.sin(2 * np.pi * t)
    table = pd.DataFrame({"time": t, "friction.v": v})
    inputs = tmp_path / "inputs.csv"
    inputs.write_text("time,friction.v\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), v.tolist())))
    out = tmp_path / "alone.csv"
    done = cli("run", system, "--stop", 1.0, "--step", 1e-3, "--input", inputs, "--out", out, "--quiet")
    assert done.returncode == 0, done.stderr
    expected = read_exact_csv(out)
    for given in (table, inputs, table.to_records(index=False)):
        result = fricsim.run(system, stop=1.0, step=1e-3, input=given)
        assert np.ptp(result["friction.F"]) > 0
        for name in expected:
            assert same_bits(result[name], expected[name]), name
    # held over each step, as the command's --input-hold, and not the same
    out_held = tmp_path / "alone_held.csv"
    done = cli("run", system, "--stop", 1.0, "--step", 1e-3, "--input", inputs, "--input-hold",
               "--out", out_held, "--quiet")
    assert done.returncode == 0, done.stderr
    expected_held = read_exact_csv(out_held)
    held = fricsim.run(system, stop=1.0, step=1e-3, input=table, input_hold=True)
    for name in expected_held:
        assert same_bits(held[name], expected_held[name]), name
    assert not same_bits(held["friction.F"], expected["friction.F"])


def test_info_is_the_model_description():
    lugre = fricsim.info(ROOT / "dist" / "LuGre.fmu")
    assert lugre.model_name == "LuGre"
    assert lugre.fmi_version == "2.0"
    assert "linux64" in lugre.platforms
    assert lugre.capabilities["can_get_and_set_fmu_state"] is True
    force = lugre.variable("F")
    assert (force.causality, force.type, force.unit) == ("output", "Real", "N")
    assert lugre.variable("sigma0").causality == "parameter"
    # an FMI 3.0 FMU's variables by their FMI 3.0 type names
    lugre3 = fricsim.info(ROOT / "dist" / "fmi3" / "LuGre.fmu")
    assert lugre3.fmi_version == "3.0"
    assert (lugre3.variable("F").type, lugre3.variable("F").unit) == ("Float64", "N")
    assert lugre3.variable("sliding").type == "Boolean"
    assert lugre3.variable("x_table[1]").type == "Float64"
    with pytest.raises(KeyError, match="no variable `nosuch`"):
        lugre.variable("nosuch")
    with pytest.raises(fricsim.FricsimError, match="nosuch.fmu"):
        fricsim.info(ROOT / "dist" / "nosuch.fmu")


def test_errors_carry_the_host_messages(tmp_path):
    broken = tmp_path / "broken.ssd"
    text = STICK_SLIP.read_text().replace("<ssd:Connections>", "<ssd:Connections><oops>", 1)
    broken.write_text(text)
    with pytest.raises(fricsim.FricsimError) as e:
        fricsim.run(broken)
    assert isinstance(e.value, RuntimeError)
    # file:line:column, then what is wrong there
    assert re.search(r"broken\.ssd:\d+:\d+: ill-formed document", str(e.value)), str(e.value)

    with pytest.raises(fricsim.FricsimError, match="nosuch"):
        fricsim.run(STICK_SLIP, stop=1.0, start_values={"friction.nosuch": 1.0})

    # the host refuses a value outside the declared range
    with pytest.raises(fricsim.FricsimError, match="friction.sigma0. to -1: below the declared min = 0"):
        fricsim.run(STICK_SLIP, stop=1.0, start_values={"friction.sigma0": -1.0})
    # the FMU refuses the value: the instance, the call and the reason
    with pytest.raises(fricsim.FricsimError) as e:
        fricsim.run(STICK_SLIP, stop=1.0, start_values={"friction.sigma0": 0.0})
    message = str(e.value)
    assert 'instance "friction"' in message and "fmi2GetReal" in message, message
    assert "invalid parameter sigma0 = 0" in message, message

    with pytest.raises(fricsim.FricsimError, match="unknown master algorithm `nosuch`"):
        fricsim.run(STICK_SLIP, stop=1.0, master="nosuch")

    with pytest.raises(fricsim.FricsimError, match="alpha 2: must be between 0 and 1"):
        fricsim.diagnose(EMPS, EMPS_TRAIN, out=tmp_path / "d", alpha=2.0)
    with pytest.raises(fricsim.FricsimError, match="unknown effect|nosuch"):
        fricsim.diagnose(EMPS, EMPS_TRAIN, out=tmp_path / "d", candidates=["nosuch"])
    with pytest.raises(TypeError, match="unknown option.*alhpa"):
        fricsim.diagnose(EMPS, EMPS_TRAIN, out=tmp_path / "d", alhpa=0.1)


def test_sweep_equals_the_command_sweep_bit_for_bit(tmp_path):
    grid = {"friction.Fs": [1.5, 2.0], "rig.k": [2.0, 3.0]}
    frame = fricsim.sweep(STICK_SLIP, grid, stop=3.0)
    out = tmp_path / "sweep.csv"
    done = cli("sweep", STICK_SLIP, "--param", "friction.Fs=1.5,2.0", "--param", "rig.k=2.0,3.0",
               "--stop", 3.0, "--out", out)
    assert done.returncode == 0, done.stderr
    expected = read_exact_csv_mixed(out)
    assert len(frame) == len(expected) == 4
    value_columns = [c for c in expected[0] if c.startswith(("final:", "rms:"))]
    assert value_columns and value_columns == [c for c in frame.columns if c.startswith(("final:", "rms:"))]
    for i, row in enumerate(expected):
        assert frame["friction.Fs"][i] == float(row["friction.Fs"])
        assert frame["points"][i] == int(row["points"])
        assert frame["error"][i] is None and row["status"] == "ok"
        for c in value_columns:
            assert same_bits(frame[c][i], float(row[c])), c


def test_a_dataframe_of_sample_points_equals_the_grid(tmp_path):
    """`grid` as a DataFrame of points (here the grid's product, in
    another order, plus a point off the grid) runs exactly those points:
    each row equals the mapping grid's row of the same point bit for bit."""
    grid = {"friction.Fs": [1.5, 2.0], "rig.k": [2.0, 3.0]}
    by_grid = fricsim.sweep(STICK_SLIP, grid, stop=1.0)
    points = pd.DataFrame({"friction.Fs": [2.0, 1.5, 1.5, 2.0, 1.75],
                           "rig.k": [3.0, 2.0, 3.0, 2.0, 2.5]})
    by_points = fricsim.sweep(STICK_SLIP, points, stop=1.0)
    assert len(by_points) == 5
    assert list(by_points["friction.Fs"]) == list(points["friction.Fs"])
    assert list(by_points["rig.k"]) == list(points["rig.k"])
    values = [c for c in by_grid.columns if c.startswith(("final:", "rms:"))]
    for i in range(4):
        fs, k = points["friction.Fs"][i], points["rig.k"][i]
        j = by_grid.index[(by_grid["friction.Fs"] == fs) & (by_grid["rig.k"] == k)][0]
        for c in values:
            assert same_bits(by_points[c][i], by_grid[c][j]), (c, fs, k)
    # the point off the grid ran too, and differs from its neighbours
    assert by_points["error"][4] is None
    assert not same_bits(by_points["final:friction.F"][4], by_points["final:friction.F"][2])


def read_exact_csv_mixed(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def test_a_point_the_fmu_refuses_is_an_error_row():
    frame = fricsim.sweep(STICK_SLIP, {"friction.sigma0": [-1.0, 1e5]}, stop=0.5)
    assert "below its declared min" in frame["error"][0]
    assert frame["error"][1] is None
    assert np.isnan(frame["final:friction.F"][0]) and np.isfinite(frame["final:friction.F"][1])
    with pytest.raises(fricsim.FricsimError, match="no variable `nosuch`"):
        fricsim.sweep(STICK_SLIP, {"friction.nosuch": [1.0]}, stop=0.5)


DIAGNOSE_OPTIONS = {"candidates": ["direction_dependent", "viscous"], "polish": False}


def test_a_dataframe_to_diagnose_equals_the_csv_path(tmp_path):
    by_path = fricsim.diagnose(EMPS, EMPS_TRAIN, EMPS_TEST, out=tmp_path / "a", **DIAGNOSE_OPTIONS)
    frame = pd.read_csv(EMPS_TRAIN, comment="#")
    heldout = pd.read_csv(EMPS_TEST, comment="#")
    by_frame = fricsim.diagnose(EMPS, frame, heldout, out=tmp_path / "b", **DIAGNOSE_OPTIONS)
    assert by_path.effect_names == by_frame.effect_names == ["direction_dependent"]
    assert by_path.report_html.exists() and by_path.refitted_system.exists()
    ignore = {"data", "heldout", "wall_seconds", "polish_seconds"}
    a = {k: v for k, v in by_path.report.items() if k not in ignore}
    b = {k: v for k, v in by_frame.report.items() if k not in ignore}
    assert a == b
    assert by_path.final_rms < by_path.nominal_rms
    # the refitted system runs
    assert len(fricsim.run(by_path.refitted_system, stop=0.5)) > 10


def test_several_records_to_diagnose_as_paths_or_dataframes(tmp_path):
    """fricsim.diagnose(system, [df1, df2]): one model fitted to both EMPS
    records, each held out in turn; a record given as a DataFrame gives
    the same report as its CSV path, and the report names both."""
    by_path = fricsim.diagnose(
        EMPS, [EMPS_TRAIN, EMPS_TEST], out=tmp_path / "a", **DIAGNOSE_OPTIONS
    )
    pulses = pd.read_csv(EMPS_TEST, comment="#")
    by_frame = fricsim.diagnose(
        EMPS, (EMPS_TRAIN, pulses), out=tmp_path / "b", **DIAGNOSE_OPTIONS
    )
    assert by_path.folds == by_frame.folds == 2
    assert "each of the 2 records" in by_path.heldout
    assert str(EMPS_TRAIN) in by_path.data and str(EMPS_TEST) in by_path.data
    ignore = {"data", "heldout", "wall_seconds", "polish_seconds", "rerun"}
    a = {k: v for k, v in by_path.report.items() if k not in ignore}
    b = {k: v for k, v in by_frame.report.items() if k not in ignore}
    assert a == b
    assert by_path.final_rms < by_path.nominal_rms
    assert (tmp_path / "a" / "inputs-1.csv").exists() and (tmp_path / "a" / "inputs-2.csv").exists()
    with pytest.raises(ValueError, match="no measurements"):
        fricsim.diagnose(EMPS, [], out=tmp_path / "c")


def test_a_nominal_moved_to_another_law_is_what_the_diagnosis_gives(tmp_path):
    """When the nominal moved from LuGre to another law (report.json's
    `memory`), `effect_names` ends with that law's effect without the
    effects the move explains, `refitted_system` is that law's system and
    the held-out RMS shown is its own; otherwise they are LuGre's."""
    report = {
        "system": "s.ssd", "nominal_rms": 0.02, "final_rms": 0.01,
        "effects": [{"name": "stribeck"}, {"name": "presliding"}],
        "memory": [
            {"law": "gms", "effect": "presliding_memory", "outcome": "kept", "heldout_rms": 0.009},
            {"law": "elasto_plastic", "effect": "elastic_presliding", "outcome": "moved",
             "heldout_rms": 0.001, "explains": ["presliding"]},
        ],
    }
    d = fricsim.Diagnosis(report, tmp_path)
    assert d.effect_names == ["stribeck", "elastic_presliding"]
    assert d.refitted_system == tmp_path / "refitted-elastoplastic.ssp"
    assert d.final_heldout_rms == 0.001 and "-> 0.00100" in repr(d)
    report["memory"][1]["outcome"] = "kept"
    d = fricsim.Diagnosis(report, tmp_path)
    assert d.effect_names == ["stribeck", "presliding"] and d.moved_to is None
    assert d.refitted_system == tmp_path / "refitted.ssp" and d.final_heldout_rms == 0.01


def test_diagnose_stops_at_its_time_limit_and_says_so(tmp_path):
    """time_limit: the slider table's diagnosis (several seconds in full)
    stopped after half a second still writes its report, whose
    time_limit says what was left out; diagnose_many passes the limit on;
    a generous limit (the default, 600 s) is not reached; a limit that is
    not a positive number is refused naming it."""
    d = fricsim.diagnose(SLIDER, SLIDER_DATA, out=tmp_path / "a", time_limit=0.5, quiet=True)
    t = d.time_limit
    assert t["reached"] is True and t["seconds"] == 0.5, t
    assert t["unfinished"] or t["skipped"], t
    assert not set(t["unfinished"]) & set(d.effect_names), t
    assert "Time limit reached" in d.report_md.read_text()
    assert d.report_html.exists() and d.refitted_system.exists()
    many = fricsim.diagnose_many([(SLIDER, SLIDER_DATA)], time_limit=0.5, quiet=True)
    assert many["error"][0] is None, many["error"][0]
    assert bool(many["time_limit_reached"][0])
    assert many["report"][0]["time_limit"]["seconds"] == 0.5
    whole = fricsim.diagnose(
        SLIDER, SLIDER_DATA, out=tmp_path / "b", candidates=["viscous"], polish=False
    )
    assert whole.time_limit["seconds"] == 600
    assert whole.time_limit["reached"] is False
    assert not whole.time_limit["skipped"] and not whole.time_limit["unfinished"]
    for bad, shown in [(0, "0"), (-1.5, "-1.5"), (float("nan"), "NaN"), (-math.inf, "-inf")]:
        with pytest.raises(fricsim.FricsimError, match=f"time limit {re.escape(shown)}: must be a positive"):
            fricsim.diagnose(SLIDER, SLIDER_DATA, out=tmp_path / "c", time_limit=bad)
    assert not (tmp_path / "c").exists()


CHILD = textwrap.dedent(
    """
    import sys, fricsim
    print("running", flush=True)
    try:
        # a run of 1e6 s recorded once a second: it goes on until stopped,
        # in little memory
        fricsim.run(sys.argv[1], stop=1e6, output_interval=1.0)
    except KeyboardInterrupt:
        print("KeyboardInterrupt", flush=True)
        sys.exit(3)
    print("finished", flush=True)
    """
)


def test_ctrl_c_stops_a_run_and_raises_keyboard_interrupt(tmp_path):
    temp = tmp_path / "tmp"
    temp.mkdir()
    # SIGINT's disposition as in a terminal: a pytest-xdist worker may run
    # with SIGINT ignored, its children inherit that, and Python installs
    # no KeyboardInterrupt handler for an ignored SIGINT (seen on CI: the
    # child's SigIgn held SIGINT, and the run went on for minutes)
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(ROOT / "dist" / "stick_slip.ssp")],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env={**os.environ, "TMPDIR": str(temp)},
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    assert child.stdout.readline().strip() == "running"
    # wait until the run has unpacked its FMUs, i.e. is inside Rust (given
    # no input table, fricsim.run makes nothing in TMPDIR itself)
    while not any(temp.iterdir()):
        assert child.poll() is None, child.stderr.read()
    child.send_signal(signal.SIGINT)
    try:
        out, err = child.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        # say what the child was doing rather than only that it did not stop
        child.kill()
        out, err = child.communicate()
        raise AssertionError(f"no stop 120 s after SIGINT; stdout {out!r}, stderr {err[-3000:]!r}, "
                             f"left in TMPDIR {sorted(p.name for p in temp.iterdir())}") from None
    assert child.returncode == 3, err
    assert out.strip() == "KeyboardInterrupt"
    assert list(temp.iterdir()) == []


def test_a_run_given_no_input_table_makes_no_temporary_directory(monkeypatch):
    """Given no input table (or a CSV path), fricsim.run goes straight to
    the host: a Ctrl-C between the call and the host would otherwise land
    in Python code that has made a directory and not yet entered the
    `with` that removes it (the test above, under load, left one about
    one time in twenty)."""

    def refuse(*args, **kwargs):
        raise AssertionError("fricsim.run made a temporary directory")

    monkeypatch.setattr(tempfile, "TemporaryDirectory", refuse)
    monkeypatch.setattr(tempfile, "mkdtemp", refuse)
    rows = fricsim.run(ROOT / "examples" / "stick_slip.ssd", stop=0.01)
    assert len(rows) == 101


def test_seeds_equal_the_command_sweep_with_seeds(tmp_path):
    piezo = ROOT / "examples" / "piezo_push.ssd"
    frame = fricsim.sweep(piezo, {}, stop=2.0, seeds=3)
    out = tmp_path / "seeds.csv"
    done = cli("sweep", piezo, "--seeds", 3, "--stop", 2.0, "--out", out)
    assert done.returncode == 0, done.stderr
    expected = read_exact_csv_mixed(out)
    assert list(frame["friction.seed"]) == [1.0, 2.0, 3.0]
    assert len(set(frame["rms:friction.F"])) == 3  # three realisations
    for i, row in enumerate(expected):
        assert same_bits(frame["rms:friction.F"][i], float(row["rms:friction.F"]))
        assert same_bits(frame["final:friction.F"][i], float(row["final:friction.F"]))


def test_the_gil_is_released_while_a_run_goes_on(tmp_path, monkeypatch):
    """Python code in another thread runs while Rust runs: this thread sees
    the run's unpacked FMUs (which exist only inside the Rust call) while
    the run's thread is still in it. With the GIL held, this thread could
    only look after the call had returned and removed them."""
    import threading

    temp = tmp_path / "tmp"
    temp.mkdir()
    monkeypatch.setenv("TMPDIR", str(temp))
    done = {}
    runner = threading.Thread(target=lambda: done.setdefault("rows", len(fricsim.run(STICK_SLIP, stop=60.0))))
    runner.start()
    seen_inside = False
    while runner.is_alive() and not seen_inside:
        seen_inside = any(temp.iterdir()) and runner.is_alive()
    runner.join()
    assert done["rows"] == 600001
    assert seen_inside
    assert list(temp.iterdir()) == []
