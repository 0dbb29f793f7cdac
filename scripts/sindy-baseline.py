#!/usr/bin/env python3
"""Sparse-regression baseline for the hidden-effect suite of `fricsim diagnose`.

PySINDy's sequentially thresholded least squares (STLSQ) regresses the
friction force the data imply on a library of candidate terms, each term
belonging to one effect of diagnose's library. An effect is "named" when
one of its terms survives the thresholding and the nominal model does not
already have it. Input: a directory written by
`hidden-effect-suite --export DIR` (per case: the friction data diagnose
derives from the measurements, `*.friction.csv`, and the case with its
truth, `*.json`). The baseline sees exactly the data diagnose's force fits
see: the same inverse-dynamics force, the same trusted intervals (no file
edges, no sticking), the same held-out blocks.

Library (v velocity, x position, Fn normal force, s distance travelled
since the last reversal, sg = sign(v)):

    coulomb (nominal)     sg
    viscous               v
    stribeck              sg*exp(-(v/vs)^2), vs = (0.05, 0.1, 0.2, 0.4) x RMS speed
    presliding            sg*exp(-s/d), d = 1e-6 ... 1e-3 m (7 values)
    position_dependent    sg*xi, sg*xi^2, sg*xi^3, xi = (x - mean)/travel
    direction_dependent   sg*[v < 0]
    normal_load           sg*(Fn - mean)/mean

The threshold is chosen by the held-out error (the blocks diagnose holds
out), from 40 values spread between the smallest and the largest
coefficient of the unthresholded fit; columns are normalised.

Usage: scripts/sindy-baseline.py EXPORT_DIR [--json OUT.json]
(run by scripts/hidden-effect-suite.sh, which creates the venv with the
pinned PySINDy).
"""

import argparse
import glob
import json
import os
import sys
import warnings

import numpy as np
import pysindy as ps

EFFECTS = [
    "viscous",
    "stribeck",
    "presliding",
    "position_dependent",
    "direction_dependent",
    "normal_load",
]


def distance_since_reversal(v, x):
    """|x - x at the last sign change of v| for each interval."""
    s = np.zeros_like(x)
    anchor = x[0]
    sign = np.sign(v[0])
    for k in range(len(x)):
        sk = np.sign(v[k])
        if sk != 0 and sk != sign:
            anchor = x[k - 1] if k > 0 else x[k]
            sign = sk
        s[k] = abs(x[k] - anchor)
    return s


def library(d):
    """(columns, names, effect of each column)."""
    v, x, fn = d["v"], d["x"], d["Fn"]
    sg = np.sign(v)
    cols, names, effects = [sg], ["sign(v)"], ["coulomb"]
    cols.append(v)
    names.append("v")
    effects.append("viscous")
    vrms = np.sqrt(np.mean(v**2))
    for f in (0.05, 0.1, 0.2, 0.4):
        vs = f * vrms
        cols.append(sg * np.exp(-((v / vs) ** 2)))
        names.append(f"sign(v)*exp(-(v/{vs:.3g})^2)")
        effects.append("stribeck")
    s = distance_since_reversal(v, x)
    for dist in np.logspace(-6, -3, 7):
        cols.append(sg * np.exp(-s / dist))
        names.append(f"sign(v)*exp(-s/{dist:.2g})")
        effects.append("presliding")
    travel = max(x.max() - x.min(), 1e-12)
    xi = (x - x.mean()) / travel
    for p in (1, 2, 3):
        cols.append(sg * xi**p)
        names.append(f"sign(v)*xi^{p}")
        effects.append("position_dependent")
    cols.append(sg * (v < 0))
    names.append("sign(v)*[v<0]")
    effects.append("direction_dependent")
    fmean = fn.mean()
    if np.ptp(fn) > 0 and fmean != 0:
        cols.append(sg * (fn - fmean) / fmean)
        names.append("sign(v)*(Fn-mean)/mean")
        effects.append("normal_load")
    return np.column_stack(cols), names, effects


def fit(theta, f, threshold):
    model = ps.SINDy(
        feature_library=ps.IdentityLibrary(),
        optimizer=ps.STLSQ(threshold=threshold, alpha=0.0, normalize_columns=True),
    )
    model.fit(theta, t=1.0, x_dot=f[:, None])
    return model.coefficients()[0]


def diagnose_case(csv):
    d = np.genfromtxt(csv, delimiter=",", names=True)
    theta, names, effects = library(d)
    use = d["trusted"] == 1
    train = use & (d["heldout"] == 0)
    held = use & (d["heldout"] == 1)
    f = d["F"]
    # thresholds between the smallest and largest coefficient magnitudes of
    # the unthresholded fit, in the normalised columns STLSQ thresholds
    norms = np.linalg.norm(theta[train], axis=0)
    norms[norms == 0] = 1.0
    full, *_ = np.linalg.lstsq(theta[train] / norms, f[train], rcond=None)
    mags = np.abs(full[np.abs(full) > 0])
    grid = np.concatenate([[0.0], np.logspace(np.log10(mags.min()), np.log10(mags.max()), 40)])
    best = None
    for lam in grid:
        coef = fit(theta[train], f[train], lam)
        err = np.mean((theta[held] @ coef - f[held]) ** 2)
        # ties (the same support) go to the larger threshold: the sparser model
        if best is None or err < best[0] * (1 - 1e-9):
            best = (err, lam, coef)
    err, lam, coef = best
    active = {effects[i] for i in range(len(coef)) if coef[i] != 0.0}
    terms = [names[i] for i in range(len(coef)) if coef[i] != 0.0]
    return active, terms, lam, float(np.sqrt(err))


def main():
    # STLSQ warns when a threshold of the grid removes every term: expected
    warnings.filterwarnings("ignore", category=UserWarning)
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("export")
    ap.add_argument("--json", help="write every case's result here")
    a = ap.parse_args()
    cases = sorted(glob.glob(os.path.join(a.export, "*.json")))
    if not cases:
        sys.exit(f"sindy-baseline: no case in {a.export} (run hidden-effect-suite --export)")
    results = []
    print("| hidden | magnitude | seed | named (PySINDy) | named right | invented | terms |")
    print("|---|---|---|---|---|---|---|")
    for path in cases:
        with open(path) as fh:
            case = json.load(fh)
        stem = path[: -len(".json")]
        active, terms, lam, rms = diagnose_case(stem + ".friction.csv")
        nominal = set(case["nominal_effects"])
        named = sorted(e for e in active if e in EFFECTS and e not in nominal)
        hidden = sorted(case["case"]["hidden"])
        right = named == hidden
        invented = sorted(set(named) - set(hidden))
        r = {
            "hidden": hidden,
            "magnitude": case["case"]["magnitude"],
            "seed": case["case"]["seed"],
            "named": named,
            "named_right": right,
            "invented": invented,
            "terms": terms,
            "threshold": lam,
            "heldout_force_rms": rms,
        }
        results.append(r)
        print(
            f"| {case['label']} | {r['magnitude']} | {r['seed']} | {', '.join(named) or '-'} | "
            f"{'yes' if right else 'NO'} | {', '.join(invented) or '-'} | {len(terms)} |"
        )
    print()
    for mag in sorted({r["magnitude"] for r in results}, reverse=True):
        some = [r for r in results if r["magnitude"] == mag and r["hidden"]]
        null = [r for r in results if r["magnitude"] == mag and not r["hidden"]]
        if some:
            print(
                f"magnitude {mag}: named right {sum(r['named_right'] for r in some)}/{len(some)}, "
                f"invented an effect in {sum(bool(r['invented']) for r in some)}/{len(some)}"
            )
        if null:
            print(
                f"magnitude {mag}, nothing hidden: an effect claimed in "
                f"{sum(bool(r['named']) for r in null)}/{len(null)}"
            )
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(results, fh, indent=1)


if __name__ == "__main__":
    main()
