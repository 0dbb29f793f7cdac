"""Sweeps and batch diagnoses, in this process or as tasks of a Dask
cluster (``client=dask.distributed.Client(...)``: local processes, SSH,
Kubernetes, Slurm through dask-jobqueue).

On a cluster the system file travels to the workers as the bytes of an
``.ssp`` (a ``.ssd`` is packed first, with its FMUs), once per worker: it
is the result of a task of its own, which the sweep's tasks depend on, so
that Dask recomputes it, like any lost result, on a worker that replaces
one that died. Each worker writes it to a temporary file once and runs the
host's Rust library in its own process, one chunk of points per task.
Dask does the scheduling, the data transfer and the retries of the tasks
of a worker that died; a point whose run fails is a row with its error.
"""

from __future__ import annotations

import hashlib
import itertools
import os
import shutil
import tempfile
import atexit
from pathlib import Path
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

import numpy as np

from . import _native
from ._tables import table_columns

PathLike = Union[str, os.PathLike]

#: Points per Dask task when not given: enough tasks for every worker
#: thread to get several (so that a slow or lost task is a small part of
#: the work), few enough that Dask's cost per task (about a millisecond of
#: the scheduler's and the worker's time, BENCHMARKS.md) stays small
#: against the runs.
TASKS_PER_THREAD = 4


def _points(grid: Any) -> tuple[list, list]:
    """The parameter names and the points of ``grid``: a mapping of
    ``component.variable`` to a list of values (every combination, the
    first name varying slowest, as ``fricsim sweep``), or a DataFrame
    (structured array) of sample points, one per row."""
    if isinstance(grid, Mapping):
        names = [str(k) for k in grid]
        axes = [[float(v) for v in np.atleast_1d(grid[k])] for k in grid]
        return names, [list(p) for p in itertools.product(*axes)]
    names, columns = table_columns(grid)
    return names, [list(p) for p in zip(*(c.tolist() for c in columns))]


def sweep(
    system: PathLike,
    grid: Any,
    stop: Optional[float] = None,
    step: Optional[float] = None,
    master: Optional[str] = None,
    seeds: Optional[int] = None,
    client: Any = None,
    *,
    start: Optional[float] = None,
    seed_params: Sequence[str] = (),
    threads: Optional[int] = None,
    points_per_task: Optional[int] = None,
    shared_path: bool = False,
):
    """``fricsim sweep``: one run of ``system`` per point of ``grid``,
    summarised in a pandas DataFrame, one row per run: the parameters,
    ``points`` (communication points reached), ``wall_s``, then
    ``final:<column>`` and ``rms:<column>`` of every recorded column, and
    ``error`` (None, or why the run failed or stopped early).

    ``seeds=N`` also runs every point with the seeds 1..N of every
    component's ``seed`` parameter (or of ``seed_params``). Without
    ``client`` the runs go to ``threads`` threads of this process (default:
    every core); with a ``dask.distributed.Client`` they are Dask tasks of
    ``points_per_task`` points each. ``shared_path=True`` sends the workers
    the system's path (a file system they share) instead of its bytes.
    """
    names, points = _points(grid)
    if seeds is not None:
        if seeds < 1:
            raise ValueError(f"seeds must be at least 1, got {seeds}")
        ports = list(seed_params) or _native.seed_ports(os.fspath(system))
        if not ports:
            raise _native.FricsimError(
                f"seeds: no component of {system} has a `seed` parameter; "
                "name one with seed_params=['component.variable']"
            )
        names = names + ports
        points = [
            p + [float(s)] * len(ports) for p in points for s in range(1, seeds + 1)
        ]
    settings = dict(start=start, stop=stop, step=step, master=master)
    if client is None:
        rows = _native.sweep(
            os.fspath(system), names, points, threads=threads or os.cpu_count() or 1, **settings
        )
    else:
        rows = _sweep_on(client, system, names, points, settings, points_per_task, shared_path)
    return _frame(names, points, rows)


def _frame(names: list, points: list, rows: list):
    """The DataFrame of a sweep: the columns of the first run that recorded
    any; a run with other columns (or none) leaves its values empty."""
    import pandas as pd

    columns = next((r[0] for r in rows if r[0]), [])
    table: dict = {n: [p[k] for p in points] for k, n in enumerate(names)}
    table["points"] = [r[3] for r in rows]
    table["wall_s"] = [r[4] for r in rows]
    for kind, at in (("final", 1), ("rms", 2)):
        for k, c in enumerate(columns):
            table[f"{kind}:{c}"] = [
                r[at][k] if r[0] == columns else np.nan for r in rows
            ]
    # object, so that a run without error holds None (not NaN)
    table["error"] = pd.Series([r[5] for r in rows], dtype=object)
    return pd.DataFrame(table)


def _payload(system: PathLike, shared_path: bool) -> Union[str, tuple]:
    """What travels to the workers: the path (a shared file system), or
    ``(file name, bytes of the .ssp, the path as the caller gave it, the
    bytes' SHA-256)``, hashed here once rather than by every task."""
    label = os.fspath(system)
    system = Path(system)
    if shared_path:
        return os.fspath(system.resolve())
    if system.suffix.lower() == ".ssp":
        data = system.read_bytes()
        return (system.name, data, label, hashlib.sha256(data).hexdigest())
    with tempfile.TemporaryDirectory(prefix="fricsim-pack-") as tmp:
        packed = Path(tmp) / (system.stem + ".ssp")
        _native.pack(os.fspath(system), os.fspath(packed))
        data = packed.read_bytes()
        return (packed.name, data, label, hashlib.sha256(data).hexdigest())


def _as_given(message: Optional[str], payload, local: str) -> Optional[str]:
    """A message of a worker with the system named as the caller named it
    (not by the worker's temporary copy): the same text as a run of the
    caller's file in this process."""
    if message is None or isinstance(payload, str):
        return message
    label = payload[2]
    if label.lower().endswith(".ssd"):
        message = message.replace(f"{local}!/SystemStructure.ssd", label)
    return message.replace(local, label)


def _carry(payload):
    """The payload as a task's result (recomputed by Dask if lost)."""
    return payload


#: The systems this worker process has written: hash of the bytes -> path.
_WRITTEN: dict = {}

#: A worker's folders are ``fricsim-worker-<pid>-XXXXXXXX`` in the
#: temporary directory: the pid tells a later worker whether the process
#: that made one still runs.
_FOLDER_PREFIX = "fricsim-worker-"


def _local_system(payload) -> str:
    """A path to the system of ``payload`` in this process: the shared
    path, or the bytes written once to a temporary file (removed when the
    process exits; the folders of killed workers go when a worker makes
    its own)."""
    if isinstance(payload, str):
        return payload
    name, data, _, key = payload
    path = _WRITTEN.get(key)
    if path is None or not os.path.exists(path):
        # a worker removes its own folder when it exits, but not when it
        # is killed (Dask's nanny kills one past its memory limit): the
        # folders of workers that no longer run go here
        _native.remove_folders_of_gone_processes(tempfile.gettempdir(), _FOLDER_PREFIX)
        folder = tempfile.mkdtemp(prefix=f"{_FOLDER_PREFIX}{os.getpid()}-")
        atexit.register(shutil.rmtree, folder, True)
        path = os.path.join(folder, name)
        with open(path, "wb") as f:
            f.write(data)
        _WRITTEN[key] = path
    return path


def _sweep_task(payload, names: list, points: list, settings: dict) -> list:
    """One chunk of a sweep, in a worker: the rows, or an error row per
    point when the chunk cannot run at all."""
    local = "?"
    try:
        local = _local_system(payload)
        rows = _native.sweep(local, names, points, threads=1, **settings)
        return [(*r[:5], _as_given(r[5], payload, local)) for r in rows]
    except Exception as e:  # a failing chunk is rows that say so
        error = _as_given(f"{type(e).__name__}: {e}", payload, local)
        return [([], [], [], 0, 0.0, error) for _ in points]


def _sweep_on(client, system, names, points, settings, per_task, shared_path) -> list:
    if per_task is None:
        threads = sum(client.nthreads().values()) or 1
        per_task = max(1, -(-len(points) // (TASKS_PER_THREAD * threads)))
    if per_task < 1:
        raise ValueError(f"points_per_task must be at least 1, got {per_task}")
    # the names of the system's parameters are checked here, once, before
    # any task is sent: a bad name is an error of the call, not of a row
    _native.sweep(os.fspath(system), names, [], **settings)
    payload = client.submit(_carry, _payload(system, shared_path), pure=False)
    chunks = [points[i : i + per_task] for i in range(0, len(points), per_task)]
    futures = [
        client.submit(_sweep_task, payload, names, chunk, settings, pure=False)
        for chunk in chunks
    ]
    return [row for rows in client.gather(futures) for row in rows]


def _diagnose_task(payload, data, heldout, options: dict) -> dict:
    """One diagnosis, in a worker: the report's main figures, the report
    itself and the refitted system's bytes, or the error; the files named
    as the caller named them."""
    from . import diagnose

    renames = []
    try:
        system = _local_system(payload)
        renames.append((system, payload))
        with tempfile.TemporaryDirectory(prefix="fricsim-diagnose-") as tmp:
            local_data = _materialise(data, Path(tmp) / "data", renames)
            local_heldout = None
            if heldout is not None:
                local_heldout = _materialise(heldout, Path(tmp) / "heldout", renames)
            d = diagnose(system, local_data, local_heldout, out=Path(tmp) / "out", **options)
            refitted = d.refitted_system.read_bytes()
        report = d.report
        for key in ("system", "data", "heldout"):
            if isinstance(report.get(key), str):
                report[key] = _renamed(report[key], renames)
        return {
            "effects": d.effect_names,
            "nominal_rms": d.nominal_rms,
            "final_rms": d.final_rms,
            "floor_rms": d.floor_rms,
            "unexplained": d.unexplained,
            "wall_seconds": d.wall_seconds,
            "time_limit_reached": d.time_limit["reached"],
            "report": report,
            "refitted_ssp": refitted,
            "error": None,
        }
    except Exception as e:  # one failing dataset is a row that says so
        return {"error": _renamed(f"{type(e).__name__}: {e}", renames)}


def _renamed(message: str, renames: list) -> str:
    for local, payload in renames:
        message = _as_given(message, payload, os.fspath(local))
    return message


def _materialise(table, stem: Path, renames: list):
    """A dataset sent as ``("csv", bytes, name)`` written to ``STEM.csv``;
    a DataFrame as it is; a list of records each so (``STEM-1.csv``, ...)."""
    if isinstance(table, list):
        return [
            _materialise(t, stem.with_name(f"{stem.name}-{i + 1}"), renames)
            for i, t in enumerate(table)
        ]
    if isinstance(table, tuple) and table[0] == "csv":
        path = stem.with_suffix(".csv")
        path.write_bytes(table[1])
        renames.append((path, (None, None, table[2], None)))
        return path
    return table


def _dataset(table):
    """A dataset as it travels: a CSV file's bytes and name, a DataFrame as
    it is; several records (a list or tuple of them) as a list."""
    if isinstance(table, (list, tuple)):
        return [_dataset(t) for t in table]
    if isinstance(table, (str, os.PathLike)):
        return ("csv", Path(table).read_bytes(), os.fspath(table))
    return table


def _label(table) -> str:
    """A dataset's name in the result: its path, its type, or the names of
    its records joined by ``+``."""
    if isinstance(table, (list, tuple)):
        return " + ".join(_label(t) for t in table)
    return os.fspath(table) if isinstance(table, (str, os.PathLike)) else type(table).__name__


def diagnose_many(
    pairs: Iterable[Sequence[Any]],
    client: Any = None,
    shared_path: bool = False,
    **options: Any,
):
    """``fricsim diagnose`` on many datasets: ``pairs`` holds
    ``(system, data)`` or ``(system, data, heldout)``, each dataset a CSV
    path or a DataFrame, or a list of them (several records); ``options`` as :func:`fricsim.diagnose`
    (``time_limit`` bounds each diagnosis). With a
    Dask ``client`` each diagnosis is a task on the cluster, else they run
    here one after the other. Returns a DataFrame, one row per pair: the
    system and data, the effects found, the held-out RMS before and after
    and its floor, whether a residual stays unexplained, the wall time,
    whether the diagnosis reached its ``time_limit`` (then its report's
    ``time_limit`` says what it left out),
    the whole report (a dict), the refitted system (bytes of an ``.ssp``)
    and ``error``."""
    import pandas as pd

    pairs = [tuple(p) for p in pairs]
    for p in pairs:
        if len(p) not in (2, 3):
            raise ValueError(f"a pair is (system, data) or (system, data, heldout), got {len(p)} items")
    payloads: dict = {}
    tasks = []
    for p in pairs:
        system = os.fspath(p[0])
        if system not in payloads:
            payloads[system] = _payload(system, shared_path)
        heldout = _dataset(p[2]) if len(p) == 3 and p[2] is not None else None
        tasks.append((system, _dataset(p[1]), heldout))
    if client is None:
        results = [_diagnose_task(payloads[s], d, h, options) for s, d, h in tasks]
    else:
        carried = {s: client.submit(_carry, b, pure=False) for s, b in payloads.items()}
        futures = [
            client.submit(_diagnose_task, carried[s], d, h, options, pure=False)
            for s, d, h in tasks
        ]
        results = client.gather(futures)
    rows = []
    for p, r in zip(pairs, results):
        label = _label(p[1])
        rows.append({"system": os.fspath(p[0]), "data": label, **r})
    frame = pd.DataFrame(rows)
    # object, so that a diagnosis without error holds None (not NaN)
    frame["error"] = pd.Series([r.get("error") for r in results], dtype=object)
    return frame
