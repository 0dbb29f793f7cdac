"""BENCHMARKS.md, "Sweeps from Python and on a Dask cluster": a sweep of
POINTS runs of the stick-slip benchmark (examples/stick_slip.ssd, STOP s
at its step of 1e-4 s) in one process on 1 and 2 threads, and as Dask
tasks on a LocalCluster of 2 worker processes of one thread each, with
the default chunking and with one point per task (the cost of a task).

    .venv/bin/python scripts/bench-python-sweep.py [POINTS] [STOP]
"""

import sys
import time
from pathlib import Path

import numpy as np
from distributed import Client, LocalCluster

import fricsim

ROOT = Path(__file__).resolve().parent.parent
SYSTEM = ROOT / "examples" / "stick_slip.ssd"


def timed(f):
    t = time.perf_counter()
    result = f()
    return time.perf_counter() - t, result


def main():
    points = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    stop = float(sys.argv[2]) if len(sys.argv) > 2 else 0.5
    grid = {"friction.Fs": list(np.linspace(1.5, 2.5, points))}
    fricsim.sweep(SYSTEM, {"friction.Fs": [1.5]}, stop=stop)  # FMUs unpacked and loaded once
    one, local = timed(lambda: fricsim.sweep(SYSTEM, grid, stop=stop, threads=1))
    two, _ = timed(lambda: fricsim.sweep(SYSTEM, grid, stop=stop, threads=2))
    run = local["wall_s"].mean()
    print(f"{points} runs of {stop} s ({int(stop / 1e-4)} steps each), {run * 1e3:.2f} ms per run inside the host")
    print(f"one process, 1 thread:   {one:7.2f} s")
    print(f"one process, 2 threads:  {two:7.2f} s   efficiency {one / (2 * two):.0%}")
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as client:
        fricsim.sweep(SYSTEM, {"friction.Fs": [1.5, 1.6]}, stop=stop, client=client, points_per_task=1)  # warm
        dask, remote = timed(lambda: fricsim.sweep(SYSTEM, grid, stop=stop, client=client))
        per_task = -(-points // (fricsim._distributed.TASKS_PER_THREAD * 2))
        single, _ = timed(lambda: fricsim.sweep(SYSTEM, grid, stop=stop, client=client, points_per_task=1))
        # Dask's own cost: as many tasks that do nothing
        noop, _ = timed(lambda: client.gather([client.submit(abs, -i, pure=False) for i in range(points)]))
    same = all(
        np.array_equal(local[c].to_numpy().view(np.uint64), remote[c].to_numpy().view(np.uint64))
        for c in local.columns if c.startswith(("final:", "rms:"))
    )
    # what a task costs the host: the .ssp opened (unpacked, its FMUs
    # loaded and checked) for a run of one step
    packed = Path(fricsim._distributed._local_system(fricsim._distributed._payload(SYSTEM, False)))
    opens = [timed(lambda: fricsim._native.sweep(str(packed), ["friction.Fs"], [[1.5]], stop=1e-4, threads=1))[0] for _ in range(20)]
    setup = float(np.median(opens))
    print(f"Dask, 2 processes, {per_task} points/task: {dask:7.2f} s   efficiency {one / (2 * dask):.0%}   rows equal to one process bit for bit: {same}")
    print(f"Dask, 2 processes, 1 point/task:  {single:7.2f} s   efficiency {one / (2 * single):.0%}")
    overhead = (2 * single - one) / points
    print(f"cost of a task (2 x wall - one-thread wall) / tasks: {overhead * 1e3:.2f} ms; the host opening the .ssp: {setup * 1e3:.2f} ms")
    print(f"{points} Dask tasks that do nothing: {noop:.2f} s, {noop / points * 1e3:.2f} ms per task")


if __name__ == "__main__":
    main()
