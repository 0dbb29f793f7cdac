"""The independent hidden-effect suite of `fricsim diagnose`.

Each case (see cases.py) is simulated by the independent simulator,
diagnosed with the defaults as a user would (`fricsim diagnose SYSTEM.ssd
DATA.csv --out DIR`), and scored from its report.json:

- named right: the effects found are exactly the hidden one (none for a
  null case);
- size: the fitted size of the hidden effect against the truth (relative
  error; presliding: σ0);
- interval: whether the report's 95 % interval of the hidden effect
  (what it adds, or presliding's sigma0) holds the truth;
- never worse: the final held-out RMS against the given model's;
- a report was written.

Usage: python3 tests/independent/suite.py [--quick] [--out DIR]
       [--seeds N] [--jobs N] [--fricsim BINARY] [--update BENCHMARKS.md]
       [--any-plant] [--only KIND,...] [--versus OLD_FRICSIM [--versus-dist OLD_DIST]]
--any-plant runs the any-plant cases instead (cases.PLANT_KINDS: every
effect on each plant that is not Rig1D, at 10 % and 5 %; the null and
presliding, whose size the magnitude does not set, at 10 %; no coarse
or bad-data rows).
--only presliding_memory (cases.MEMORY_KINDS, in no default grid) runs
those kinds too, seeds 1..N at the label 10 %: a GMS truth against a
LuGre nominal, a change of structure no effect of the library is, so
they count as named right only if the diagnosis names it. Likewise
--only presliding_drift: an elasto-plastic truth (no drift below
break-away) against a LuGre nominal, named right as
`elastic_presliding`.
--versus OLD_FRICSIM diagnoses each case with an older build as well, in
turn with this one on the same data (the old first), and writes a
before/after table: the effects found, the size error, the final/given
RMS and the time of each case, and both summaries. With --versus-dist
OLD_DIST the older build runs each system with its own FMUs (its dist/).
Writes DIR/suite.json and DIR/suite.md; with --update, the table between
the "independent-suite" markers of BENCHMARKS.md ("any-plant" with
--any-plant).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import cases  # noqa: E402

FRICSIM = cases.ROOT / "target" / "release" / "fricsim"


def corrupt(data: Path) -> list[tuple[int, str]]:
    """Spikes and a dropout put into a file in place; returns the (line,
    kind) of each, lines counted from 1 at the header."""
    lines = data.read_text().splitlines()
    n = len(lines) - 1
    marks = []

    def set_x(row: int, f):
        t, a, x = lines[row].split(",")
        lines[row] = f"{t},{a},{f(float(x)):.9g}"

    set_x(n // 5, lambda x: 10 * x if abs(x) > 1e-3 else x + 0.05)
    marks.append((n // 5 + 1, "spike"))
    set_x(n // 3, lambda x: 1e6)
    marks.append((n // 3 + 1, "spike"))
    # a dropout: five rows repeat the row before while the actuator moves
    # (placed where it moves fastest)
    cols = [row.split(",") for row in lines[1:]]
    speed = [abs(float(cols[k + 1][1]) - float(cols[k][1])) for k in range(n - 1)]
    k0 = max(range(n // 2, 2 * n // 3), key=lambda k: speed[k])
    for r in range(k0 + 1, k0 + 6):
        t = lines[r + 1].split(",")[0]
        lines[r + 1] = ",".join([t] + lines[k0 + 1].split(",")[1:])
    marks.append((k0 + 3, "dropout"))
    data.write_text("\n".join(lines) + "\n")
    return marks


#: The state whose bins should explain each effect's change (the report's
#: "Where: the change depends on ...", report.json effects[].where.explained_by).
EXPLAINING_STATE = {
    "viscous": "velocity",
    "stribeck": "velocity",
    "direction_dependent": "direction",
    "position_dependent": "position",
    "presliding": "displacement_since_reversal",
    "presliding_memory": "displacement_since_reversal",
}


def effect_size(case: cases.Case, report: dict, x: list[float], v: list[float]) -> tuple[str, float, float] | None:
    """(quantity, truth, fitted) of the hidden effect, when it was named;
    `x`, `v` the true position and velocity along the experiment (the
    magnitudes are defined along it: cases.size_hidden_effect)."""
    expected = cases.EXPECTED[case.kind]
    found = [e for e in report["effects"] if e["name"] == expected]
    if not found:
        return None
    p = found[-1]["parameters"]
    final = report["final_model"]
    nom, tru = case.nominal, case.truth
    if expected == "viscous":
        return ("added sigma2", tru["sigma2"] - nom["sigma2"], final["sigma2"] - nom["sigma2"])
    if expected == "stribeck":
        # what the Stribeck term adds along the experiment, RMS (the
        # magnitude's own measure: Fs − Fc and vs trade off)
        def term(excess, vs):
            return cases.rms(excess * math.exp(-((x / vs) ** 2)) for x in v)

        return (
            "RMS Stribeck term",
            term(tru["Fs"] - tru["Fc"], tru["vs"]),
            term(final["fs"] - final["fc"], final["vs"]),
        )
    if expected == "direction_dependent":
        return ("Fc_neg - Fc", tru["Fc_neg"] - tru["Fc"], final["fc_neg"] - final["fc"])
    if expected == "presliding":
        return ("sigma0", tru["sigma0"], p["sigma0"])
    if expected == "position_dependent":
        xs, scales = case.table
        fx, fs = final["x_table"], final["scale_pos"]

        def interp(x, xt, yt):
            if x <= xt[0]:
                return yt[0]
            for i in range(1, len(xt)):
                if x <= xt[i]:
                    u = (x - xt[i - 1]) / (xt[i] - xt[i - 1])
                    return yt[i - 1] + u * (yt[i] - yt[i - 1])
            return yt[-1]

        # along the experiment, as the magnitude is defined: the table's
        # knots differ from the truth's, so how the positions are weighted
        # matters (a uniform grid over the table gave 11 % on one case
        # whose level change along the experiment is 6 % off)
        truth = cases.rms((interp(p, xs, scales) - 1) * nom["Fc"] for p in x)
        fitted = cases.rms(interp(p, fx, fs) * final["fc"] - nom["Fc"] for p in x)
        return ("RMS level change along the experiment", truth, fitted)
    return None


def interval_check(case: cases.Case, report: dict) -> dict | None:
    """Whether the report's 95 % interval of the hidden effect holds the
    truth, when the effect was named and has an interval: what the effect
    adds (viscous: sigma2 over the nominal's; direction dependence:
    Fc_neg - Fc; Stribeck: Fs - Fc; report.json effects[].change), or for
    presliding sigma0 (changes[])."""
    expected = cases.EXPECTED[case.kind]
    named = [e for e in report["effects"] if e["name"] == expected]
    if not named:
        return None
    nom, tru = case.nominal, case.truth
    truths = {
        "viscous": tru["sigma2"] - nom["sigma2"],
        "direction_dependent": tru.get("Fc_neg", tru["Fc"]) - tru["Fc"],
        "stribeck": tru["Fs"] - tru["Fc"],
    }
    change = named[-1].get("change") or {}
    if expected in truths and change.get("interval"):
        quantity, truth, interval = change["quantity"], truths[expected], change["interval"]
    elif expected == "presliding":
        interval = next((c["interval"] for c in report["changes"] if c["name"] == "sigma0" and c.get("interval")), None)
        if interval is None:
            return None
        quantity, truth = "sigma0", tru["sigma0"]
    else:
        return None
    low, high = interval
    return {"quantity": quantity, "truth": truth, "interval": [low, high], "holds": low <= truth <= high}


def run_case(
    case: cases.Case, work: Path, bad_data: bool = False, extra: tuple = (), timeout: float | None = None
) -> dict:
    """Make, diagnose and score one case; `timeout`: seconds after which
    the diagnosis is stopped and the case recorded as timed out."""
    started = time.time()
    data, ssd = cases.make(case, work)
    marks = corrupt(data) if bad_data else []
    return diagnose_case(case, work, data, ssd, marks, bad_data, extra, timeout, FRICSIM, "", started)


def diagnose_case(
    case: cases.Case,
    work: Path,
    data: Path,
    ssd: Path,
    marks: list,
    bad_data: bool,
    extra: tuple,
    timeout: float | None,
    fricsim: Path,
    tag: str,
    started: float,
) -> dict:
    """Diagnose a made case with `fricsim` and score it (`tag`: a suffix of
    its output directory, to keep two builds' outputs apart)."""
    out = work / f"out-{case.name}{'-bad' if bad_data else ''}{tag}"
    (out / "report.json").unlink(missing_ok=True)  # none left from an earlier run
    argv = [str(fricsim), "diagnose", str(ssd), str(data), "--out", str(out), *extra]
    command_started = time.time()
    try:
        proc = subprocess.run(argv, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        proc = subprocess.CompletedProcess(argv, None, "", f"stopped after {timeout:g} s (--case-timeout)")
    row = {
        "case": case.name + (" (spikes, dropout)" if bad_data else ""),
        "kind": case.kind,
        "coarse": case.coarse,
        "magnitude": case.magnitude,
        "seed": case.seed,
        "bad_data": bad_data,
        "rig": case.rig,
        "drive": case.drive,
        "nominal": case.nominal,
        "truth": case.truth,
        "report": (out / "report.json").exists(),
        "exit": proc.returncode,
        "stderr": proc.stderr[-2000:],
        "timed_out": proc.returncode is None,
        "command_seconds": time.time() - command_started,
    }
    if not row["report"]:
        row["seconds"] = time.time() - started
        return row
    report = json.loads((out / "report.json").read_text())
    found = [e["name"] for e in report["effects"]]
    final_rms = report["final_rms"]
    # the nominal moved from LuGre to another law (GMS, elasto-plastic)
    # names that law's effect, and the moved model is the final one
    moved = [m for m in report.get("memory", []) if m["outcome"] == "moved"]
    if moved:
        # the effects found under LuGre that the move explains are not named
        found = [f for f in found if f not in moved[0].get("explains", [])] + [moved[0]["effect"]]
        final_rms = moved[0]["heldout_rms"]
    expected = cases.EXPECTED[case.kind]
    row.update(
        found=found,
        named_right=found == ([expected] if expected else []),
        never_wrong=all(f == expected for f in found),
        given_rms=report["nominal_rms"],
        final_rms=final_rms,
        floor_rms=report["floor_rms"],
        unexplained=report["unexplained"],
        refit_kept=report["refit"]["kept"],
        moved_to=moved[0]["law"] if moved else None,
        never_worse=final_rms <= 1.05 * report["nominal_rms"],
        diagnose_seconds=report["wall_seconds"],
    )
    tx = cases.read_columns(work / f"{case.name}.truth.csv")["true_x"]
    v = [(b - a) / case.sample for a, b in zip(tx, tx[1:])]
    size = effect_size(case, report, tx[1:], v)
    named = [e for e in report["effects"] if e["name"] == expected]
    if named:
        explained = named[-1]["where"]["explained_by"]
        row["localised_as"] = explained[0]["state"] if explained else "none"
        row["localised_right"] = row["localised_as"] == EXPLAINING_STATE.get(expected)
    if size:
        q, truth, fitted = size
        row["size"] = {"quantity": q, "truth": truth, "fitted": fitted,
                       "relative_error": abs(fitted - truth) / abs(truth)}
    interval = interval_check(case, report)
    if interval:
        row["interval"] = interval
    if bad_data:
        q = report["data_quality"]["data"]
        flagged = {(f["line"], f["kind"]) for f in q["findings"]}
        row["bad_samples_found"] = all(
            any(kind == k and abs(line - l) <= 3 for (l, k) in flagged) for line, kind in marks
        )
        row["flagged"] = q["excluded_samples"]
    row["seconds"] = time.time() - started
    return row


#: Seeds of the coarse rows: the first two were looked at while the
#: choice between overlapping explanations was built, the others were not.
COARSE_SEEDS = (1, 2, 21, 22, 23)


def magnitudes(kind: str, quick: bool) -> list[float]:
    """The magnitudes a kind is run at: 10 % and 5 % (10 % only when
    `quick`); the null and presliding at 10 % alone, since the magnitude
    does not set their truth (cases.size_hidden_effect) and would only
    repeat the same case under another name."""
    effect = cases.effect_of(kind)
    if quick or effect == "none" or effect.startswith("presliding"):
        return [0.1]
    return [0.1, 0.05]


def grid(seeds: int, quick: bool, coarse: bool = True) -> list[tuple[cases.Case, bool]]:
    out = []
    for seed in range(1, seeds + 1):
        for kind in cases.KINDS:
            for mag in magnitudes(kind, quick):
                out.append((cases.draw(kind, mag, seed), False))
        out.append((cases.draw("none", 0.1, 100 + seed), True))
        for kind in cases.GRID_PLANT_KINDS + cases.DAHL_KINDS:
            out.append((cases.draw(kind, 0.1, seed), False))
    if coarse:
        for seed in COARSE_SEEDS:
            for kind in cases.COARSE_KINDS:
                out.append((cases.draw(kind, 0.1, seed, coarse=True), False))
    return out


def any_plant_grid(seeds: int, quick: bool, first_seed: int = 1) -> list[tuple[cases.Case, bool]]:
    """The any-plant cases (issue 43): each kind of cases.PLANT_KINDS at
    its magnitudes, `seeds` seeds from `first_seed` on."""
    return [
        (cases.draw(kind, mag, seed), False)
        for seed in range(first_seed, first_seed + seeds)
        for kind in cases.PLANT_KINDS
        for mag in magnitudes(kind, quick)
    ]


def run_case_versus(case: cases.Case, work: Path, extra: tuple, timeout: float | None, old: Path,
                    old_dist: Path | None = None) -> dict:
    """Make one case and diagnose it with the build `old` and then with
    this one (FRICSIM), in turn on the same data: the row of this build,
    with the old build's row under "before". With `old_dist`, the old
    build runs the system with that build's FMUs (its dist/) instead of
    this one's."""
    data, ssd = cases.make(case, work)
    old_ssd = ssd
    if old_dist is not None:
        old_ssd = ssd.with_name(ssd.stem + "-before.ssd")
        old_ssd.write_text(ssd.read_text().replace(str(cases.ROOT / "dist") + "/", str(old_dist) + "/"))
    before = diagnose_case(case, work, data, old_ssd, [], False, extra, timeout, old, "-before", time.time())
    row = diagnose_case(case, work, data, ssd, [], False, extra, timeout, FRICSIM, "", time.time())
    row["before"] = before
    return row


def seconds_of(r: dict) -> float:
    """What the user waited for: the whole `fricsim diagnose` command,
    a fresh process (report and plots written)."""
    return r["command_seconds"]


def times(rows: list[dict]) -> dict:
    """Median and maximum diagnosis time and the cases over 60 s."""
    ts = sorted(seconds_of(r) for r in rows)
    n = len(ts)
    median = (ts[(n - 1) // 2] + ts[n // 2]) / 2 if n else float("nan")
    return {"median_seconds": median, "max_seconds": ts[-1] if n else float("nan"),
            "over_60_s": sum(1 for t in ts if t > 60), "cases": n,
            "timed_out": sum(1 for r in rows if r.get("timed_out"))}


def versus_table(rows: list[dict]) -> str:
    """Before → after, per case: the effects found, the size error, the
    final/given RMS and the time; then both summaries and times."""
    def found(r):
        if not r["report"]:
            return "timed out" if r.get("timed_out") else "NO REPORT"
        return (", ".join(r["found"]) or "none") + ("" if r["named_right"] else " ✗")

    def size(r):
        return f"{100 * r['size']['relative_error']:.1f} %" if "size" in r else ""

    def ratio(r):
        return f"{r['final_rms'] / r['given_rms']:.3f}" if r["report"] else ""

    lines = [
        "| case | found before | found after | size error before → after | final / given RMS before → after | time (s) before → after |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        b = r["before"]
        lines.append(
            f"| {r['case']} | {found(b)} | {found(r)} | {size(b)} → {size(r)} | {ratio(b)} → {ratio(r)} "
            f"| {seconds_of(b):.1f} → {seconds_of(r):.1f} |"
        )
    lines.append("")
    sb, sa = summarise([r["before"] for r in rows]), summarise(rows)
    for k in ("named_right_10pct", "named_right_5pct", "clean_null_no_claim", "never_worse", "sized_within_10pct",
              "reports_written"):
        lines.append(f"- {k.replace('_', ' ')}: {sb[k][0]}/{sb[k][1]} before, {sa[k][0]}/{sa[k][1]} after")
    tb, ta = times([r["before"] for r in rows]), times(rows)
    lines.append(
        f"- time: median {tb['median_seconds']:.1f} s before, {ta['median_seconds']:.1f} s after; "
        f"longest {tb['max_seconds']:.1f} s before, {ta['max_seconds']:.1f} s after; over 60 s: "
        f"{tb['over_60_s']}/{tb['cases']} before, {ta['over_60_s']}/{ta['cases']} after; stopped by --case-timeout: "
        f"{tb['timed_out']} before, {ta['timed_out']} after"
    )
    return "\n".join(lines) + "\n"


def summarise(rows: list[dict]) -> dict:
    def share(sel, key):
        xs = [r for r in rows if sel(r)]
        ok = sum(1 for r in xs if r.get(key))
        return ok, len(xs)

    def effect(m):
        return lambda r: (cases.EXPECTED[r["kind"]] and abs(r["magnitude"] - m) < 1e-9
                          and not r["bad_data"] and not r.get("coarse"))

    sized = [r for r in rows if "size" in r and not r.get("coarse")]
    fine = [r for r in rows if not r.get("coarse")]
    coarse = [r for r in rows if r.get("coarse")]
    return {
        "named_right_10pct": share(effect(0.1), "named_right"),
        "named_right_5pct": share(effect(0.05), "named_right"),
        "clean_null_no_claim": share(lambda r: cases.EXPECTED[r["kind"]] is None and not r["bad_data"]
                                     and not r.get("coarse"), "named_right"),
        "bad_data_no_claim": share(lambda r: r["bad_data"], "named_right"),
        "bad_data_found": share(lambda r: r["bad_data"], "bad_samples_found"),
        "never_worse": share(lambda r: True, "never_worse"),
        "reports_written": share(lambda r: True, "report"),
        "sized_within_10pct": (sum(1 for r in sized if r["size"]["relative_error"] <= 0.1), len(sized)),
        "localised_right": share(lambda r: "localised_right" in r, "localised_right"),
        "interval_holds_truth": (sum(1 for r in fine if r.get("interval", {}).get("holds")),
                                 sum(1 for r in fine if "interval" in r)),
        "coarse_200hz_10um_never_a_wrong_effect": (sum(1 for r in coarse if r.get("never_wrong")), len(coarse)),
        "coarse_200hz_10um_named_right": (sum(1 for r in coarse if r.get("named_right")), len(coarse)),
    }


def table(rows: list[dict], summary: dict) -> str:
    lines = [
        "| case | drive | found (the state its change depends on) | size: truth → fitted (error) | final / given RMS | floor | time (s) |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        if not r["report"]:
            lines.append(f"| {r['case']} | {r['drive'].get('drive', r['drive'].get('plant'))} | NO REPORT: {r['stderr'].strip().splitlines()[-1] if r['stderr'].strip() else ''} | | | | |")
            continue
        size = r.get("size")
        s = f"{size['quantity']}: {size['truth']:.4g} → {size['fitted']:.4g} ({100 * size['relative_error']:.1f} %)" if size else ""
        if "interval" in r:
            iv = r["interval"]
            s += (f"; 95 % interval of {iv['quantity']} [{iv['interval'][0]:.4g}, {iv['interval'][1]:.4g}] "
                  f"{'holds' if iv['holds'] else 'MISSES'} the truth {iv['truth']:.4g}")
        found = ", ".join(r["found"]) or "none"
        if "localised_as" in r:
            found += f" (on {r['localised_as'].replace('_', ' ')})"
        mark = "" if r["named_right"] else " ✗"
        lines.append(
            f"| {r['case']} | {r['drive'].get('drive', r['drive'].get('plant'))} | {found}{mark} | {s} | {r['final_rms'] / r['given_rms']:.3f} | {r['floor_rms']:.2e} | {r['diagnose_seconds']:.1f} |"
        )
    lines.append("")
    for k, (a, b) in summary.items():
        lines.append(f"- {k.replace('_', ' ')}: {a}/{b}")
    return "\n".join(lines) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="10 %% only")
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=cases.ROOT / "out" / "independent-suite")
    ap.add_argument("--only", default="", help="comma list of kinds (cases.MEMORY_KINDS too, which no default grid has)")
    ap.add_argument("--update", type=Path, help="rewrite the table between the markers of this file")
    ap.add_argument(
        "--render-only",
        action="store_true",
        help="run nothing: render OUT/suite.json (of an earlier run with the same --seeds) again",
    )
    ap.add_argument("--diagnose-arg", action="append", default=[], help="passed on to fricsim diagnose (repeat)")
    ap.add_argument("--fricsim", type=Path, help="the fricsim binary to diagnose with (default: this build's)")
    ap.add_argument(
        "--case-timeout", type=float, help="stop a diagnosis after this many seconds (recorded as timed out, no report)"
    )
    ap.add_argument("--no-coarse", action="store_true", help="leave out the 200 Hz / 10 µm rows")
    ap.add_argument("--coarse-only", action="store_true", help="only the 200 Hz / 10 µm rows")
    ap.add_argument(
        "--any-plant",
        action="store_true",
        help="run the any-plant cases instead (every effect on each plant that is not Rig1D)",
    )
    ap.add_argument(
        "--versus",
        type=Path,
        metavar="OLD_FRICSIM",
        help="diagnose every case with this older build too, in turn with this one on the same data, and "
        "write a before/after table (with --update: between the \"any-plant\" markers when --any-plant)",
    )
    ap.add_argument(
        "--versus-dist",
        type=Path,
        metavar="OLD_DIST",
        help="with --versus: the older build's FMUs (its dist/ folder), which its runs use instead of this one's",
    )
    ap.add_argument(
        "--first-seed",
        type=int,
        default=1,
        help="with --any-plant: the first seed (seeds FIRST.. FIRST+SEEDS-1), e.g. seeds not looked at while "
        "the diagnosis was changed",
    )
    args = ap.parse_args()
    global FRICSIM
    if args.fricsim:
        FRICSIM = args.fricsim.resolve()
    todo = (any_plant_grid(args.seeds, args.quick, args.first_seed) if args.any_plant
            else grid(args.seeds, args.quick, coarse=not args.no_coarse))
    if args.only:
        keep = args.only.split(",")
        todo = [(c, b) for c, b in todo if c.kind in keep]
        # the kinds of no default grid, when named
        todo += [(cases.draw(kind, 0.1, seed), False) for kind in keep if kind in cases.MEMORY_KINDS
                 for seed in range(1, args.seeds + 1)]
    if args.coarse_only:
        todo = [(c, b) for c, b in todo if c.coarse]
    args.out.mkdir(parents=True, exist_ok=True)
    if args.render_only:
        rows = json.loads((args.out / "suite.json").read_text())["cases"]
    elif args.versus:
        old = args.versus.resolve()
        with ThreadPoolExecutor(args.jobs) as pool:
            rows = list(
                pool.map(
                    lambda cb: run_case_versus(cb[0], args.out / "cases", tuple(args.diagnose_arg),
                                               args.case_timeout, old,
                                               args.versus_dist.resolve() if args.versus_dist else None),
                    [cb for cb in todo if not cb[1]],
                )
            )
    else:
        with ThreadPoolExecutor(args.jobs) as pool:
            rows = list(
                pool.map(
                    lambda cb: run_case(cb[0], args.out / "cases", cb[1], tuple(args.diagnose_arg), args.case_timeout),
                    todo,
                )
            )
    for r in rows:
        print(r["case"], r.get("found"), r.get("size", {}).get("relative_error"), r.get("final_rms", 0) / max(r.get("given_rms", 1), 1e-300), file=sys.stderr)
    summary = summarise(rows)
    if args.versus or (rows and "before" in rows[0]):
        summary["before"] = summarise([r["before"] for r in rows])
        summary["times"] = times(rows)
        summary["times_before"] = times([r["before"] for r in rows])
        text = versus_table(rows)
    else:
        text = table(rows, summary)
    (args.out / "suite.json").write_text(json.dumps({"summary": summary, "cases": rows}, indent=1))
    (args.out / "suite.md").write_text(text)
    print(text)
    if args.update:
        import platform

        cpu = "unknown CPU"
        try:
            for line in open("/proc/cpuinfo"):
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
        except OSError:
            pass
        seconds = sum(r.get("diagnose_seconds", 0) for r in rows)
        flags = (f"{' --quick' if args.quick else ''}{' --any-plant' if args.any_plant else ''}"
                 f"{f' --first-seed {args.first_seed}' if args.first_seed != 1 else ''}"
                 f"{' --versus OLD' if args.versus else ''}"
                 f"{f' --case-timeout {args.case_timeout:g}' if args.case_timeout else ''}")
        head = (
            f"Generated {time.strftime('%Y-%m-%d')} by `python3 tests/independent/suite.py --seeds {args.seeds}"
            f" --jobs {args.jobs}{flags}` on {cpu}, {os.cpu_count()} cores, {platform.system().lower()} "
            f"{platform.machine()}, {args.jobs} cases at a time; diagnose took {seconds:.0f} s for {len(rows)} cases.\n\n"
        )
        marker = "any-plant" if args.any_plant else "independent-suite"
        begin, end = f"<!-- {marker}: begin", f"<!-- {marker}: end -->"
        doc = args.update.read_text()
        i, j = doc.index(begin), doc.index(end)
        i = doc.index("\n", i) + 1
        args.update.write_text(doc[:i] + head + text + doc[j:])
    return 0


if __name__ == "__main__":
    sys.exit(main())
