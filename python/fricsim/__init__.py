"""fricsim from Python: the co-simulation host of friction-fmu as a library.

The work is done by the host's Rust library (``fricsim._native``, built by
maturin from ``python/src/lib.rs``) with the GIL released; this package
gives it Python's types:

- :func:`info` — an FMU's model description as a :class:`ModelInfo`;
- :func:`run` — a system file co-simulated, as a numpy structured array
  with ``time`` first (FMPy's convention; ``pandas.DataFrame(result)``
  works), the same numbers as ``fricsim run``'s CSV bit for bit;
- :func:`sweep` — a parameter grid, one DataFrame row per run, on the
  cores of this machine or as tasks of a Dask cluster (``client=``);
- :func:`diagnose` and :func:`diagnose_many` — ``fricsim diagnose`` on
  one dataset, or on many as Dask tasks.

Every error of the host raises :class:`FricsimError` (a ``RuntimeError``)
with the host's message: the file and line, the instance, the FMI call.
What ``fricsim run`` prints as a warning (an instance that refused
``fmi2Terminate`` after the last step) is a :class:`FricsimWarning`.
Ctrl-C stops a run cleanly and raises ``KeyboardInterrupt``.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np

from . import _native
from ._native import FricsimError
from ._tables import write_table_csv

__all__ = [
    "FricsimError",
    "FricsimWarning",
    "ModelInfo",
    "Variable",
    "Diagnosis",
    "info",
    "run",
    "sweep",
    "diagnose",
    "diagnose_many",
]

PathLike = Union[str, os.PathLike]


class FricsimWarning(RuntimeWarning):
    """What ``fricsim run`` prints as a warning: the rows stand (an
    instance that refused ``fmi2Terminate`` after the last step)."""


@dataclass(frozen=True)
class Variable:
    """One ScalarVariable of a model description (FMI 2.0.4 §2.2.7)."""

    name: str
    value_reference: int
    causality: str
    variability: str
    type: str
    start: Optional[str]
    unit: Optional[str]
    description: Optional[str]


@dataclass(frozen=True)
class ModelInfo:
    """What ``fricsim info`` shows: the model, its Co-Simulation
    capabilities (FMI 2.0.4 §4.3.1), the default experiment (§2.2.5) and
    the variables."""

    fmi_version: str
    model_name: str
    guid: str
    description: Optional[str]
    generation_tool: Optional[str]
    generation_date_and_time: Optional[str]
    model_identifier: str
    model_exchange: Optional[str]
    platforms: list
    capabilities: dict
    default_experiment: Optional[dict]
    variables: list = field(repr=False)

    def variable(self, name: str) -> Variable:
        """The variable called ``name``."""
        for v in self.variables:
            if v.name == name:
                return v
        raise KeyError(f"{self.model_name} has no variable `{name}`")


def info(fmu: PathLike) -> ModelInfo:
    """The model description of ``fmu`` (the archive is read, its binary
    not loaded, so FMUs for other platforms can be inspected too)."""
    d = json.loads(_native.info(os.fspath(fmu)))
    d["variables"] = [Variable(**v) for v in d["variables"]]
    return ModelInfo(**d)


def run(
    system: PathLike,
    start_values: Optional[Mapping[str, Any]] = None,
    start: Optional[float] = None,
    stop: Optional[float] = None,
    step: Optional[float] = None,
    master: Optional[str] = None,
    output_interval: Optional[float] = None,
    input: Any = None,
    record: Sequence[str] = (),
    step_timeout: Optional[float] = None,
    input_hold: bool = False,
) -> np.ndarray:
    """Co-simulate the system file ``system`` (``.ssd`` or ``.ssp``) as
    ``fricsim run`` does, and return its rows as a numpy structured array:
    ``time``, then one field per recorded ``component.variable``.

    ``start_values`` maps ``component.variable`` to a value set after the
    file's own parameter values (numbers; text for String variables).
    ``start``, ``stop``, ``step`` and ``master`` default to the file's
    ``DefaultExperiment`` and annotation; ``output_interval`` (a whole
    multiple of the step) records every k-th communication point only. ``input`` is a CSV path, a
    structured array or a DataFrame with ``time`` first and a column per
    unconnected input, interpolated linearly in time: an FMU that can
    interpolate inputs is given each one's slope over the step, and a row
    holds the inputs of its own time. ``input_hold=True`` holds each input
    over the step instead, as FMPy's ``simulate_fmu`` does (``fricsim run
    --input-hold``). ``record`` names further Real variables to record. ``step_timeout``
    limits each FMI call, in seconds.

    A run that stops early raises :class:`FricsimError`; the rows up to the
    failure are its ``result`` attribute. An instance that refuses
    ``fmi2Terminate`` after the last step gives a :class:`FricsimWarning`
    naming it; the rows stand.
    """
    values = list((start_values or {}).items())
    with _as_csv_paths("fricsim-input-", input=input) as paths:
        columns, data, error, refused = _native.run(
            os.fspath(system),
            start=start,
            stop=stop,
            step=step,
            master=master,
            start_values=values,
            output_interval=output_interval,
            record=list(record),
            input=paths["input"],
            step_timeout=step_timeout,
            input_hold=input_hold,
        )
    dtype = np.dtype([(c, np.float64) for c in columns])
    result = np.frombuffer(data, dtype=dtype).copy()
    for message in refused:
        warnings.warn(message, FricsimWarning, stacklevel=2)
    if error is not None:
        failure = FricsimError(
            f"run INCOMPLETE (the {len(result)} rows up to the failure are in "
            f"the exception's result): {error}"
        )
        failure.result = result
        raise failure
    return result


def _as_csv(table: Any, path: Path) -> str:
    """A CSV path as given, else ``table`` (DataFrame, structured array)
    written to ``path`` with every number exactly."""
    if isinstance(table, (str, os.PathLike)):
        return os.fspath(table)
    write_table_csv(table, path)
    return os.fspath(path)


@contextlib.contextmanager
def _as_csv_paths(prefix: str, **tables: Any):
    """Each of ``tables`` as a CSV path (``None`` stays ``None``): a path
    as given; a DataFrame or structured array written, every number
    exactly, as ``NAME.csv`` in a temporary directory that is made only
    when some table needs it and removed on the way out. With paths only,
    nothing is created: Python code between the call and the host (where
    Ctrl-C would land) stays as short as it can be, and an interrupted
    call leaves no directory behind."""
    if all(t is None or isinstance(t, (str, os.PathLike)) for t in tables.values()):
        yield {k: None if t is None else os.fspath(t) for k, t in tables.items()}
        return
    with tempfile.TemporaryDirectory(prefix=prefix) as tmp:
        yield {
            k: None if t is None else _as_csv(t, Path(tmp) / f"{k}.csv")
            for k, t in tables.items()
        }


def _records(tables: Any) -> list:
    """One record (a path, a DataFrame, a structured array) or a list or
    tuple of them, as a list; an empty list is refused."""
    records = list(tables) if isinstance(tables, (list, tuple)) else [tables]
    if not records:
        raise ValueError("diagnose: no measurements given (an empty list of records)")
    if any(r is None for r in records):
        raise ValueError("diagnose: a record is None")
    return records


class Diagnosis:
    """The result of :func:`diagnose`: the fields of ``report.json`` as
    attributes (``effects``, ``nominal_rms``, ``final_rms``,
    ``floor_rms``, ``unexplained``, …, and the whole of it as ``report``),
    and the paths of what was written: ``out``, ``report_html``,
    ``report_json``, ``report_md``, ``refitted_system``. In Jupyter it
    shows as ``report.md``."""

    def __init__(self, report: dict, out: Path):
        self.report = report
        self.out = out
        self.report_html = out / "report.html"
        self.report_json = out / "report.json"
        self.report_md = out / "report.md"
        moved = self.moved_to
        # the system of the law the nominal moved to, when it moved
        self.refitted_system = (
            out / f"refitted-{moved['law'].replace('_', '')}.ssp" if moved else out / "refitted.ssp"
        )

    def __getattr__(self, name: str) -> Any:
        report = self.__dict__.get("report", {})
        if name in report:
            return report[name]
        raise AttributeError(f"the diagnosis has no field `{name}`")

    @property
    def moved_to(self) -> Optional[dict]:
        """The check of the other law the nominal moved to (GMS or the
        elasto-plastic law: an entry of ``report["memory"]``), or None
        when LuGre stayed."""
        return next((m for m in self.report.get("memory", []) if m["outcome"] == "moved"), None)

    @property
    def effect_names(self) -> list:
        """The effects found, in the order they were added; when the
        nominal moved to another law, that law's effect
        (``presliding_memory``, ``elastic_presliding``) last, without the
        effects the move explains."""
        names = [e["name"] for e in self.report["effects"]]
        moved = self.moved_to
        if moved:
            names = [n for n in names if n not in moved.get("explains", [])] + [moved["effect"]]
        return names

    @property
    def final_heldout_rms(self) -> float:
        """The held-out RMS of the model the diagnosis ends with: the
        other law's when the nominal moved to it, else ``final_rms``."""
        moved = self.moved_to
        return moved["heldout_rms"] if moved else self.report["final_rms"]

    def __repr__(self) -> str:
        found = ", then ".join(self.effect_names) or "no missing effect"
        return (
            f"<Diagnosis of {self.report['system']}: {found}; held-out RMS "
            f"{self.report['nominal_rms']:.5f} -> {self.final_heldout_rms:.5f}; "
            f"{self.report_html}>"
        )

    def _repr_markdown_(self) -> str:
        return self.report_md.read_text()


def diagnose(
    system: PathLike,
    data: Any,
    heldout: Any = None,
    out: Optional[PathLike] = None,
    **options: Any,
) -> Diagnosis:
    """``fricsim diagnose``: which friction effect the system misses
    against the measurements ``data`` (a CSV path or a DataFrame with
    ``time`` first and ``component.variable`` columns, or a list of them:
    several records of the same system, one model fitted to all, each
    record co-simulated from its own start), scored on ``heldout`` (same
    kinds) or, without it, on each record in turn (several records) or
    held-out blocks of ``data``.

    ``out`` is the output directory (default
    ``out/<system name>-diagnosis``); ``options`` are those of the command
    with underscores: ``candidates`` (list of effect names),
    ``position_knots``, ``max_position_knots``, ``alpha``, ``smooth``, ``blocks``,
    ``cross_validate`` ("auto", "always", "never", "records"), ``polish``,
    ``master``, ``lugre``, ``time_limit`` (seconds of wall time, default
    600, ``math.inf`` for none: past it the diagnosis starts no new work
    and reports what it has, ``report["time_limit"]`` saying what was left
    out) and ``quiet`` (no progress line on stderr, which is drawn only
    when stderr is a terminal)."""
    system = Path(system)
    if out is None:
        out = Path("out") / f"{system.stem}-diagnosis"
    known = {
        "candidates",
        "position_knots",
        "max_position_knots",
        "alpha",
        "smooth",
        "blocks",
        "cross_validate",
        "polish",
        "master",
        "lugre",
        "time_limit",
        "quiet",
    }
    unknown = sorted(set(options) - known)
    if unknown:
        raise TypeError(
            f"diagnose: unknown option(s) {', '.join(unknown)} "
            f"(known: {', '.join(sorted(known))})"
        )
    if "lugre" in options and options["lugre"] is not None:
        options["lugre"] = os.fspath(options["lugre"])
    data_records = _records(data)
    heldout_records = [] if heldout is None else _records(heldout)
    tables = {f"data{i}": t for i, t in enumerate(data_records)}
    tables.update({f"heldout{i}": t for i, t in enumerate(heldout_records)})
    with _as_csv_paths("fricsim-data-", **tables) as paths:
        report = _native.diagnose(
            os.fspath(system),
            [paths[f"data{i}"] for i in range(len(data_records))],
            os.fspath(out),
            heldout=[paths[f"heldout{i}"] for i in range(len(heldout_records))],
            **options,
        )
    return Diagnosis(json.loads(report), Path(out))


from ._distributed import diagnose_many, sweep  # noqa: E402  (uses the above)
