"""Tables from Python (pandas DataFrames, numpy structured arrays) as the
CSV files the host reads: ``time`` first, then ``component.variable``
columns, every number with 17 significant digits, which an IEEE double
parses back from exactly."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np


def table_columns(table: Any) -> tuple[list, list]:
    """The column names and the columns (float64 arrays) of a DataFrame
    (a ``time`` index counts as its first column) or a structured array."""
    if isinstance(table, np.ndarray) and table.dtype.names:
        names = list(table.dtype.names)
        return names, [np.asarray(table[n], dtype=np.float64) for n in names]
    if hasattr(table, "columns") and hasattr(table, "to_numpy"):
        if "time" not in table.columns and getattr(table.index, "name", None) == "time":
            table = table.reset_index()
        names = [str(c) for c in table.columns]
        return names, [table[c].to_numpy(dtype=np.float64) for c in table.columns]
    raise TypeError(
        "expected a CSV path, a pandas DataFrame or a numpy structured array, "
        f"got {type(table).__name__}"
    )


def write_table_csv(table: Any, path: Path) -> None:
    """Write ``table`` to ``path`` as CSV."""
    names, columns = table_columns(table)
    if not names or names[0] != "time":
        raise ValueError(
            f"the first column must be `time`, found `{names[0] if names else ''}`"
        )
    matrix = np.column_stack(columns) if columns else np.empty((0, 0))
    np.savetxt(path, matrix, fmt="%.17g", delimiter=",", header=",".join(names), comments="")
