#!/usr/bin/env python3
"""Derive the measurement CSVs of examples/data/ from the published originals.

Usage: scripts/prepare-measured-data.py SOURCE_DIR

SOURCE_DIR holds the originals (emps/emps_train.csv, emps/emps_test_pulses.csv,
slider_stiction_by_position.csv; their sha256 are in examples/data/README.md).
Writes, relative to the repository root:

- examples/data/emps_train.csv, examples/data/emps_test_pulses.csv, from
  SOURCE_DIR/emps/emps_train.csv and emps_test_pulses.csv (EMPS benchmark),
  for examples/emps_nominal.ssd:
  time = t, rig.x_ref = qg, rig.F_ext = GTAU * pulses_N (0 in the training
  file), rig.x = qm, rig.u_ctrl = vir - pulses_N.
  The pulse column is a disturbance in volts of the drive command, not in
  newtons: during a pulse the measured vir jumps by +5 at the onset and
  comes back to its value without pulses while qm settles 0.128 mm ahead
  of its value without pulses, 5 V / (kv*kp); so the pulse is added to the
  controller output before vir is recorded and before the drive gain,
  force = gtau*(controller output + pulses_N). Rig1D's u_ctrl is the
  controller output, hence vir - pulses_N, and the disturbance force is
  F_ext = gtau*pulses_N (examples/data/README.md).
- examples/data/slider_breakaway.csv from SOURCE_DIR/slider_stiction_by_position.csv
  (Thimmalapura 2004, Table I), for examples/slider_breakaway.ssd:
  each table row becomes a 1 s hold at the probe speed +-PROBE_SPEED (sign =
  direction) and the row's position, sampled every 0.1 s, with the measured
  friction.F = +-DRIVE_GAIN * breakaway_input_V; positive-direction rows by
  increasing position, then negative-direction rows by decreasing position;
  consecutive holds meet at a repeated time (an event: the new row's values
  hold from that time on, no ramp between rows).

Python 3 standard library only. Values are written with repr (full
precision); each file starts with a '#' comment line naming its source.
"""

import csv
import os
import sys

# EMPS drive gain gtau (N/V), from the EMPS data set's documentation
# (Janot, Gautier, Brunot 2019; examples/data/README.md).
GTAU = 35.15065188
# Drive gain of Thimmalapura's slider (N/V), examples/slider_drift.ssd.
DRIVE_GAIN = 3.5
# Probe speed of the break-away holds (m/s).
PROBE_SPEED = 1e-4
# Samples per 1 s hold (every 0.1 s, not counting the hold's end).
SAMPLES_PER_HOLD = 10

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT_DIR = os.path.join(REPO, "examples", "data")
SCRIPT = "scripts/prepare-measured-data.py"


def read_rows(path, columns):
    """Rows of a CSV as dicts of floats, checking the header has `columns`."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in columns if c not in (reader.fieldnames or [])]
        if missing:
            sys.exit(f"{path}: missing column(s) {', '.join(missing)} (header: {reader.fieldnames})")
        rows = []
        for line, row in enumerate(reader, start=2):
            try:
                rows.append({c: float(row[c]) for c in columns})
            except (TypeError, ValueError):
                sys.exit(f"{path}:{line}: not a number in {row}")
    if not rows:
        sys.exit(f"{path}: no data rows")
    return rows


def write_csv(path, source, header, rows):
    with open(path, "w", newline="") as f:
        f.write(f"# derived from {source} by {SCRIPT}\n")
        f.write(",".join(header) + "\n")
        for row in rows:
            f.write(",".join(repr(v) for v in row) + "\n")
    print(f"wrote {os.path.relpath(path, REPO)}: {len(rows)} rows")


def prepare_emps(src_dir, name, has_pulses):
    columns = ["t", "qm", "qg", "vir"] + (["pulses_N"] if has_pulses else [])
    rows = read_rows(os.path.join(src_dir, "emps", name), columns)
    out = []
    for r in rows:
        pulse = r["pulses_N"] if has_pulses else 0.0
        out.append((r["t"], r["qg"], GTAU * pulse, r["qm"], r["vir"] - pulse))
    for a, b in zip(out, out[1:]):
        if not b[0] > a[0]:
            sys.exit(f"{name}: time not increasing at t = {b[0]!r}")
    write_csv(
        os.path.join(OUT_DIR, name),
        f"the EMPS data set (Janot et al. 2019), emps/{name}",
        ["time", "rig.x_ref", "rig.F_ext", "rig.x", "rig.u_ctrl"],
        out,
    )


def prepare_slider(src_dir):
    name = "slider_stiction_by_position.csv"
    path = os.path.join(src_dir, name)
    with open(path, newline="") as f:
        table = list(csv.DictReader(f))
    rows = {"positive": [], "negative": []}
    for line, r in enumerate(table, start=2):
        direction = r.get("direction")
        if direction not in rows:
            sys.exit(f"{path}:{line}: direction {direction!r} is neither positive nor negative")
        try:
            rows[direction].append((float(r["position_mm"]), float(r["breakaway_input_V"])))
        except (TypeError, ValueError, KeyError):
            sys.exit(f"{path}:{line}: bad row {r}")
    holds = [(+1.0, p, u) for p, u in sorted(rows["positive"])]
    holds += [(-1.0, p, u) for p, u in sorted(rows["negative"], reverse=True)]

    out = []
    for k, (sign, pos_mm, volts) in enumerate(holds):
        v = sign * PROBE_SPEED
        x = pos_mm / 1000.0
        force = sign * round(DRIVE_GAIN * volts, 12)
        # k, k + 0.1, ..., k + 1: the hold's end k + 1 is repeated by the
        # next hold's start (an event); times as (10k + j)/10, correctly rounded.
        for j in range(SAMPLES_PER_HOLD + 1):
            out.append(((SAMPLES_PER_HOLD * k + j) / SAMPLES_PER_HOLD, v, x, force))
    write_csv(
        os.path.join(OUT_DIR, "slider_breakaway.csv"),
        f"the slider table (Thimmalapura 2004, Table I), {name}",
        ["time", "friction.v", "friction.x", "friction.F"],
        out,
    )
    levels = [DRIVE_GAIN * u for _, _, u in holds]
    print(f"  {len(holds)} holds of 1 s; mean break-away force "
          f"{sum(levels) / len(levels)!r} N (the Fc = Fs of examples/slider_breakaway.ssd)")


def main():
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        sys.exit(__doc__)
    src_dir = sys.argv[1]
    if not os.path.isdir(src_dir):
        sys.exit(f"{src_dir}: no such directory (pass the directory of the originals)")
    os.makedirs(OUT_DIR, exist_ok=True)
    prepare_emps(src_dir, "emps_train.csv", has_pulses=False)
    prepare_emps(src_dir, "emps_test_pulses.csv", has_pulses=True)
    prepare_slider(src_dir)


if __name__ == "__main__":
    main()
