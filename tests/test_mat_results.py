"""`fricsim run --out NAME.mat`: the MAT v4 result file, read by
`scipy.io.loadmat` in the Dymola/OpenModelica trajectory layout, holds the
same numbers, bit for bit, as the CSV of the same run (which parses back
exactly); a run that stops early keeps its rows and says why in an
`incomplete` text matrix.
"""

import subprocess

import numpy as np
import scipy.io

from conftest import ROOT

FRICSIM = ROOT / "target" / "release" / "fricsim"


def fricsim(*args, check=True):
    assert FRICSIM.exists(), f"{FRICSIM} is missing: run ./build-fmu.sh"
    result = subprocess.run([str(FRICSIM), *map(str, args)], capture_output=True, text=True, cwd=ROOT)
    if check:
        assert result.returncode == 0, result.stderr
    return result


def strings(matrix):
    """The strings of a binTrans text matrix: one per column."""
    return ["".join(column).rstrip() for column in matrix.T]


def trajectory(path):
    """names, time, values (one column per variable) as DyMat reads a
    binTrans file: dataInfo row 0 the matrix, row 1 the signed column."""
    mat = scipy.io.loadmat(path, chars_as_strings=False)
    aclass = ["".join(row).rstrip() for row in mat["Aclass"]]
    assert aclass == ["Atrajectory", "1.1", "", "binTrans"]
    names = strings(mat["name"])
    info = mat["dataInfo"]
    data = mat["data_2"]
    assert data.dtype == np.float64
    assert names[0] == "time" and list(info[:, 0]) == [0, 1, 0, -1]
    assert strings(mat["description"])[0] == "Time in [s]"
    time = data[0]
    columns = {}
    for k, name in enumerate(names[1:], start=1):
        assert info[0, k] == 2, name
        columns[name] = data[info[1, k] - 1]
    assert list(mat["data_1"][0]) == [time[0], time[-1]]
    return names[1:], time, columns, mat


def read_csv(path):
    lines = path.read_text().splitlines()
    names = lines[0].split(",")
    rows = [line for line in lines[1:] if not line.startswith("#")]
    table = np.array([[float(x) for x in row.split(",")] for row in rows])
    notes = [line for line in lines if line.startswith("# INCOMPLETE: ")]
    return names[1:], table[:, 0], {n: table[:, k + 1] for k, n in enumerate(names[1:])}, notes


def test_loadmat_reads_the_csv_of_the_same_run_bit_for_bit(tmp_path):
    for master in ["jacobi", "newton"]:
        csv_path, mat_path = tmp_path / f"{master}.csv", tmp_path / f"{master}.mat"
        for out in (csv_path, mat_path):
            fricsim("run", "examples/stick_slip.ssd", "--stop", "2", "--master", master, "--quiet", "--out", out)
        names, time, columns, mat = trajectory(mat_path)
        csv_names, csv_time, csv_columns, notes = read_csv(csv_path)
        assert names == csv_names and notes == []
        assert len(time) == 20001
        assert np.array_equal(time.view(np.uint64), csv_time.view(np.uint64))
        for name in names:
            assert np.array_equal(columns[name].view(np.uint64), csv_columns[name].view(np.uint64)), name
        assert "incomplete" not in mat


def test_a_run_that_stops_early_says_why_in_the_mat_file(tmp_path):
    # a spring of 1e308 N/m on a mass of 1e-300 kg: the rig's state
    # overflows in the first step, which Rig1D refuses (fmi2Error); the
    # row at t = 0 stays
    results = {}
    for out in ("early.csv", "early.mat"):
        path = tmp_path / out
        r = fricsim(
            "cosim", "--fmu", "rig=dist/Rig1D.fmu", "--fmu", "friction=dist/LuGre.fmu",
            "--connect", "rig.v->friction.v", "--connect", "friction.F->rig.F",
            "--set", "rig.k=1e308", "--set", "rig.m=1e-300",
            "--step", "1e-3", "--stop", "1", "--out", path, check=False,
        )
        assert r.returncode == 1, r.stdout + r.stderr
        assert "run INCOMPLETE" in r.stderr
        results[out] = path
    names, time, columns, mat = trajectory(results["early.mat"])
    csv_names, csv_time, csv_columns, notes = read_csv(results["early.csv"])
    assert list(time) == [0.0]
    assert np.array_equal(time, csv_time)
    for name in names:
        assert np.array_equal(columns[name].view(np.uint64), csv_columns[name].view(np.uint64)), name
    note = "".join(mat["incomplete"][0])
    assert note.startswith("the run stopped early: at t = 0: fmi2DoStep failed for instance \"rig\"")
    assert notes == ["# INCOMPLETE: " + note]
