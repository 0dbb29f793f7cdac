#!/usr/bin/env python3
"""Two builds of fricsim timed on the commands a user waits for, in turns.

For a change meant to move no figure (a restructuring), this shows that
it did not: each command below is run as a fresh process by the old and
the new binary in turns (old, new, old, new, ...), so that a slow spell of
the machine weighs on both sides and not on their ratio. Reported per
command: the median wall time with its range, the ratio new/old, and the
peak resident memory of each (from the kernel's accounting of the child,
`wait4`). Each pair of result files is also compared byte for byte
(`scripts/compare-builds.sh` compares every example).

Usage: scripts/bench-builds.py OLD_FRICSIM NEW_FRICSIM [--turns N]
                               [--update BENCHMARKS.md]
Writes the table to stdout and, with --update, between the `builds`
markers of the file. Run it on an otherwise idle machine.
"""

from __future__ import annotations

import argparse
import datetime
import filecmp
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# (what it is, the arguments after the binary; OUT is replaced by the
# result path of each side)
COMMANDS = [
    (
        "`run` stick-slip, Jacobi, CSV (200 001 rows)",
        ["run", "-q", "examples/stick_slip.ssd", "--out", "OUT.csv"],
    ),
    (
        "`run` stick-slip, Jacobi, MAT",
        ["run", "-q", "examples/stick_slip.ssd", "--out", "OUT.mat"],
    ),
    (
        "`run` stick-slip, strong coupling (newton)",
        ["run", "-q", "examples/stick_slip.ssd", "--master", "newton", "--out", "OUT.csv"],
    ),
    (
        "`sweep` stick-slip, 8 values of sigma0",
        [
            "sweep",
            "examples/stick_slip.ssd",
            "--param",
            "friction.sigma0=1e4,3e4,1e5,3e5,1e6,3e6,1e7,3e7",
            "--out",
            "OUT-sweep.csv",
        ],
    ),
    (
        "`diagnose` EMPS, one record",
        ["diagnose", "examples/emps_nominal.ssd", "examples/data/emps_train.csv", "--out", "OUT"],
    ),
]


def timed(argv: list[str]) -> tuple[float, float]:
    """Wall seconds and peak resident MiB of one fresh process."""
    start = time.perf_counter()
    proc = subprocess.Popen(argv, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    err = proc.stderr.read().decode() if proc.stderr else ""
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        sys.exit(f"{' '.join(argv)}: exit {proc.returncode}\n{err}")
    return wall, usage.ru_maxrss / 1024


def same_outputs(a: Path, b: Path) -> bool:
    if a.is_dir():
        # a diagnosis: its report without the timings, the other files as
        # they are
        import json

        def strip(v):
            if isinstance(v, dict):
                return {k: strip(x) for k, x in v.items() if not k.endswith("_seconds") and k != "rerun"}
            if isinstance(v, list):
                return [strip(x) for x in v]
            return v

        ra, rb = (strip(json.loads((d / "report.json").read_text())) for d in (a, b))
        return ra == rb
    if a.name.endswith("-sweep.csv"):
        # a sweep's table: its wall_s column is each run's own time
        import csv

        def rows(path):
            return [{k: v for k, v in r.items() if k != "wall_s"} for r in csv.DictReader(open(path))]

        return rows(a) == rows(b)
    return filecmp.cmp(a, b, shallow=False)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    ap.add_argument("--turns", type=int, default=7)
    ap.add_argument("--update", type=Path, help="rewrite the table between the `builds` markers of this file")
    ap.add_argument("--label-old", default="old")
    ap.add_argument("--label-new", default="new")
    args = ap.parse_args()
    work = ROOT / "target" / "bench-builds"
    work.mkdir(parents=True, exist_ok=True)
    binaries = {"old": args.old.resolve(), "new": args.new.resolve()}
    load_start = os.getloadavg()[0]
    started = time.time()
    rows = []
    for what, tail in COMMANDS:
        walls = {"old": [], "new": []}
        rss = {"old": [], "new": []}
        outs = {}
        for turn in range(args.turns + 1):
            for side in ("old", "new"):
                out = work / side
                outs[side] = Path(str(out) + (tail[-1][3:] if tail[-1].startswith("OUT") else ""))
                argv = [str(binaries[side])] + [str(out) + t[3:] if t.startswith("OUT") else t for t in tail]
                wall, mib = timed(argv)
                if turn > 0:  # the first turn warms the file cache, not counted
                    walls[side].append(wall)
                    rss[side].append(mib)
        med = {s: statistics.median(walls[s]) for s in walls}
        rows.append(
            (
                what,
                med,
                {s: (min(walls[s]), max(walls[s])) for s in walls},
                {s: max(rss[s]) for s in rss},
                same_outputs(outs["old"], outs["new"]),
            )
        )
        print(f"{what}: old {med['old']*1e3:.0f} ms, new {med['new']*1e3:.0f} ms", file=sys.stderr)
    load_end = os.getloadavg()[0]
    lines = [
        f"Generated {datetime.date.today()} by `scripts/bench-builds.py OLD NEW --turns {args.turns}` on "
        f"{platform.machine()} with {os.cpu_count()} cores; old = {args.label_old}, new = {args.label_new}; "
        f"{args.turns} turns in alternation after one not counted; {time.time() - started:.0f} s in all; "
        f"load average {load_start:.2f} at the start, {load_end:.2f} at the end.",
        "",
        "| command (a fresh process) | old: median (min–max) | new: median (min–max) | new/old | peak memory old / new | outputs |",
        "|---|---|---|---|---|---|",
    ]
    for what, med, span, peak, same in rows:
        fmt = lambda s: f"{med[s]*1e3:.0f} ms ({span[s][0]*1e3:.0f}–{span[s][1]*1e3:.0f})"  # noqa: E731
        lines.append(
            f"| {what} | {fmt('old')} | {fmt('new')} | {med['new']/med['old']:.3f} | "
            f"{peak['old']:.0f} / {peak['new']:.0f} MiB | {'the same' if same else 'DIFFERENT'} |"
        )
    text = "\n".join(lines) + "\n"
    print(text)
    if args.update:
        begin, end = "<!-- builds: begin", "<!-- builds: end -->"
        doc = args.update.read_text()
        i, j = doc.index(begin), doc.index(end)
        i = doc.index("\n", i) + 1
        args.update.write_text(doc[:i] + text + doc[j:])
    return 0 if all(r[4] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
