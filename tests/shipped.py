"""The FMUs this project ships, as `modelDescription/shipped.txt` lists them
(rendered from the registries by `cargo run -p fmu-packager -- render`, and
checked against them by fmu-packager's tests): every test that goes over
the shipped FMUs reads them from here, so that a new law is tested
everywhere or a table of per-model details fails, naming it."""

from pathlib import Path

LIST = Path(__file__).resolve().parent.parent / "modelDescription" / "shipped.txt"


def _read() -> list[tuple[str, str, set[str]]]:
    rows = []
    for line in LIST.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        name, kind, *interfaces = line.split()
        rows.append((name, kind, set(interfaces)))
    return rows


_ROWS = _read()
#: Every shipped FMU: the friction laws, then the rigs.
SHIPPED = [name for name, _, _ in _ROWS]
#: The friction laws.
LAWS = [name for name, kind, _ in _ROWS if kind == "law"]
#: The rig-dynamics FMUs.
RIGS = [name for name, kind, _ in _ROWS if kind == "rig"]
#: The FMUs offered for Model Exchange too.
MODEL_EXCHANGE = [name for name, _, interfaces in _ROWS if "me" in interfaces]


def covers(table: dict, names: list[str], what: str) -> None:
    """Fail naming the shipped models a per-model `table` leaves out."""
    missing = [n for n in names if n not in table]
    assert not missing, f"{what} has no entry for {missing}: add one (modelDescription/shipped.txt lists them)"
