"""fricsim.sweep and fricsim.diagnose_many as tasks of a Dask cluster: a
LocalCluster of two worker processes, each running the host's Rust library
in its own process. The rows equal the single-process ones bit for bit,
also when a worker is killed mid-sweep (Dask retries its tasks on a new
one), and a point the FMU refuses is a row with its error."""

import os
import signal
import tempfile
import threading
from pathlib import Path

import distributed
import numpy as np
import pytest

import fricsim
from fricsim._distributed import _local_system, _payload

ROOT = __import__("pathlib").Path(__file__).resolve().parent.parent
STICK_SLIP = ROOT / "examples" / "stick_slip.ssd"
EMPS = ROOT / "examples" / "emps_nominal.ssd"
EMPS_TRAIN = ROOT / "examples" / "data" / "emps_train.csv"
EMPS_TEST = ROOT / "examples" / "data" / "emps_test_pulses.csv"


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def same_rows(a, b):
    """Every column but the wall time equal bit for bit (NaN where NaN),
    the errors equal."""
    assert list(a.columns) == list(b.columns)
    assert len(a) == len(b)
    for c in a.columns:
        if c in ("wall_s", "error"):
            continue
        x, y = a[c].to_numpy(dtype=np.float64), b[c].to_numpy(dtype=np.float64)
        assert np.array_equal(x.view(np.uint64), y.view(np.uint64)), c
    assert list(a["error"]) == list(b["error"])


GRID = {"friction.Fs": [1.5, 1.75, 2.0], "rig.k": [2.0, 3.0]}


def test_the_cluster_sweep_equals_the_local_sweep(client):
    local = fricsim.sweep(STICK_SLIP, GRID, stop=4.0)
    remote = fricsim.sweep(STICK_SLIP, GRID, stop=4.0, client=client, points_per_task=2)
    same_rows(local, remote)
    assert local["error"].isna().all()
    # the grid: every combination, the first parameter slowest
    assert list(remote["friction.Fs"]) == [1.5, 1.5, 1.75, 1.75, 2.0, 2.0]
    assert list(remote["rig.k"]) == [2.0, 3.0] * 3
    # 4 s at the file's step of 1e-4 s, start included
    assert remote["points"].eq(40001).all()


def test_a_point_the_fmu_refuses_is_an_error_row_on_the_cluster(client):
    grid = {"friction.sigma0": [1e5, -1.0, 1e6]}
    remote = fricsim.sweep(STICK_SLIP, grid, stop=1.0, client=client, points_per_task=1)
    local = fricsim.sweep(STICK_SLIP, grid, stop=1.0)
    same_rows(local, remote)
    assert remote["error"][0] is None and remote["error"][2] is None
    assert "sigma0" in remote["error"][1] and "below its declared min" in remote["error"][1]
    assert np.isnan(remote["final:friction.F"][1])


def test_a_sweep_survives_a_killed_worker(client):
    grid = {"friction.Fs": list(np.linspace(1.5, 2.5, 24)), "rig.k": [2.0]}
    local = fricsim.sweep(STICK_SLIP, grid, stop=3.0)
    result = {}

    def sweep():
        result["frame"] = fricsim.sweep(STICK_SLIP, grid, stop=3.0, client=client, points_per_task=1)

    pids = client.run(os.getpid)
    runner = threading.Thread(target=sweep)
    runner.start()
    # once the first worker runs a task (it has written the system to its
    # folder), kill that worker's process
    victim = sorted(pids)[0]
    temp = Path(tempfile.gettempdir())

    def folders_of(pid):
        return list(temp.glob(f"fricsim-worker-{pid}-*"))

    while not (client.processing().get(victim) and folders_of(pids[victim])):
        assert runner.is_alive(), "the sweep ended before the worker ran a task"
        threading.Event().wait(0.01)
    os.kill(pids[victim], signal.SIGKILL)
    runner.join(timeout=600)
    assert not runner.is_alive()
    same_rows(local, result["frame"])
    assert result["frame"]["error"].isna().all()
    # the nanny started a new worker process in its place
    client.wait_for_workers(2, timeout=60)
    now = client.run(os.getpid)
    assert pids[victim] not in now.values()
    # the killed worker had written the system to its folder (above); the
    # next folder a worker makes on this machine removes it (here, if the
    # new worker has not yet made one for a retried task), and not the
    # folders of workers that run
    client.run(_local_system, _payload(STICK_SLIP, shared_path=False))
    assert folders_of(pids[victim]) == []
    for pid in now.values():
        assert folders_of(pid)


def test_diagnose_many_on_the_cluster_equals_diagnose(client, tmp_path):
    options = {"candidates": ["direction_dependent"], "polish": False}
    pairs = [
        (EMPS, EMPS_TRAIN, EMPS_TEST),
        (EMPS, tmp_path / "missing.csv"),
        (EMPS, [EMPS_TRAIN, EMPS_TEST]),
    ]
    (tmp_path / "missing.csv").write_text("time,rig.x\n")
    remote = fricsim.diagnose_many(pairs, client=client, **options)
    alone = fricsim.diagnose(EMPS, EMPS_TRAIN, EMPS_TEST, out=tmp_path / "alone", **options)
    both = fricsim.diagnose(EMPS, [EMPS_TRAIN, EMPS_TEST], out=tmp_path / "both", **options)
    assert list(remote["data"]) == [
        str(EMPS_TRAIN),
        str(tmp_path / "missing.csv"),
        f"{EMPS_TRAIN} + {EMPS_TEST}",
    ]
    # several records travel to a worker and give the same diagnosis
    records = remote.iloc[2]
    assert records["error"] is None and records["report"]["folds"] == 2
    assert records["final_rms"] == both.final_rms
    assert records["report"]["effects"] == both.report["effects"]
    assert records["report"]["data"] == both.report["data"]
    first = remote.iloc[0]
    assert first["error"] is None
    assert first["effects"] == alone.effect_names == ["direction_dependent"]
    assert first["final_rms"] == alone.final_rms and first["nominal_rms"] == alone.nominal_rms
    assert first["report"]["effects"] == alone.report["effects"]
    assert first["refitted_ssp"][:2] == b"PK"
    # the dataset with no rows fails alone, with the host's message
    assert "missing.csv" in remote.iloc[1]["error"]
