"""The independent simulator's third friction law: the single-state
elasto-plastic law (Dupont, Hayward, Armstrong and Altpeter 2002) of
tests/independent/lugre_rig.c (law=elastoplastic), checked alone on a
prescribed motion (plant=prescribed) against what the law implies in
closed form, then in the rig; the actuator's drive=hold; and the case
kind whose truth it is (cases.MEMORY_KINDS: presliding_drift).

The law (lugre_rig.c's header): z' = v − α(z, v)·σ0·|v|·z/g(v), F = σ0·z
+ σ1·z' + σ2·v, g the Stribeck curve, with w = sgn(v)·z and w_ss = g/σ0:
α = 0 for w ≤ z_ba, ½·sin(π·(w − (w_ss + z_ba)/2)/(w_ss − z_ba)) + ½ up to
w_ss, 1 past it. Here Fc = 1 N, Fs = 1.5 N, σ0 = 1e4 N/m (Fc/σ0 = 100
µm), vs = 0.1 m/s.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent / "independent"))
import cases  # noqa: E402

FC, FS, VS, SIGMA0 = 1.0, 1.5, 0.1, 1e4


def stribeck(v: float) -> float:
    return FC + (FS - FC) * math.exp(-((v / VS) ** 2))


def alpha(z: float, v: float, z_ba: float) -> float:
    """α(z, v) as Dupont et al. 2002 define it (the module docstring)."""
    w, w_ss = math.copysign(1.0, v) * z, stribeck(v) / SIGMA0
    if w <= z_ba:
        return 0.0
    if w >= w_ss:
        return 1.0
    return 0.5 * math.sin(math.pi * (w - 0.5 * (w_ss + z_ba)) / (w_ss - z_ba)) + 0.5


def prescribed(path, speed, law="elastoplastic", z_ba=None, sample=1e-3, sigma1=0.0, sigma2=0.0, extra=()):
    """Run the law on the prescribed path (turning points, m) at `speed`
    (m/s, one or one per segment): rows (t, x, F)."""
    speeds = speed if isinstance(speed, (list, tuple)) else [speed] * (len(path) - 1)
    duration = sum(abs(b - a) / v for a, b, v in zip(path, path[1:], speeds))
    args = [str(cases.simulator()), "plant=prescribed", f"law={law}", f"Fc={FC!r}", f"Fs={FS!r}", f"vs={VS!r}",
            f"sigma0={SIGMA0!r}", f"sigma1={sigma1!r}", f"sigma2={sigma2!r}",
            "path=" + ",".join(repr(p) for p in path), "speed=" + ",".join(repr(v) for v in speeds),
            f"duration={duration!r}", f"sample={sample!r}", *extra]
    if z_ba is not None:
        args.append(f"z_ba={z_ba!r}")
    out = subprocess.run(args, capture_output=True, text=True, check=True).stdout.splitlines()
    assert out[0] == "time,true_x,true_F"
    return [tuple(map(float, line.split(","))) for line in out[1:]]


def test_below_break_away_the_law_is_elastic_and_does_not_drift():
    """Inside the elastic range (z_ba = 60 µm): 0 → a, then 10 cycles a →
    a/3 → a (a = 45 µm, a bias, as a force held below break-away with a
    dither makes), 1 mm/s, σ1 = 10 N·s/m, σ2 = 0.5 N·s/m. The deflection
    follows the position, z = x, so F = σ0·x + (σ1 + σ2)·v at every sample
    and the tenth cycle is the first again, sample by sample: both to
    5e-12 of the largest force (0.46 N), what rounding leaves (measured
    2.2e-12 relative: z summed over 1.2e5 steps of 10 µs and written to 12
    digits; with h_max = 1e-4 it is 0).

    LuGre in the same motion creeps: its force at x = a falls from cycle
    to cycle: 0.3967 N after the first loading, 0.3183 N after the second
    (−0.078 N, 7.8 % of Fc), 0.1634 N after the eleventh (−0.233 N in
    all): asserted to fall by more than 0.05·Fc from the first to the
    second and 0.1·Fc to the last."""
    a, speed, sigma1, sigma2 = 45e-6, 1e-3, 10.0, 0.5
    cycles = 10
    path = [0.0] + [a, a / 3] * cycles + [a]
    rows = prescribed(path, speed, z_ba=60e-6, sigma1=sigma1, sigma2=sigma2)
    up, cycle = round(a / speed / 1e-3), round(2 * (2 * a / 3) / speed / 1e-3)  # 45 and 60 samples
    assert len(rows) == up + cycles * cycle + 1
    worst = 0.0
    for i, (t, x, F) in enumerate(rows):
        if i % (cycle // 2) == up % (cycle // 2):  # a turning point (the first: none)
            continue
        rising = i < up or (i - up) % cycle >= cycle // 2
        v = speed if rising else -speed
        worst = max(worst, abs(F - (SIGMA0 * x + (sigma1 + sigma2) * v)))
    largest = max(abs(F) for _, _, F in rows)
    assert worst <= 5e-12 * largest, worst
    first, last = rows[up:up + cycle], rows[up + (cycles - 1) * cycle:up + cycles * cycle]
    assert all(abs(x1 - x2) < 1e-15 for (_, x1, _), (_, x2, _) in zip(first, last))
    assert max(abs(F1 - F2) for (_, _, F1), (_, _, F2) in zip(first, last)) <= 5e-12 * largest

    # the force a sample before each top (rising, x = a − 1 µm)
    lugre = prescribed(path, speed, law="lugre", sigma1=sigma1, sigma2=sigma2)
    top = [lugre[up - 1 + i * cycle][2] for i in range(cycles + 1)]
    assert top[0] - top[1] > 0.05 * FC and top[0] - top[-1] > 0.1 * FC, top
    # and the elasto-plastic ones stay where they were
    ep_top = [rows[up - 1 + i * cycle][2] for i in range(cycles + 1)]
    assert max(ep_top) - min(ep_top) <= 5e-12 * largest, ep_top


@pytest.mark.parametrize("z_ba_share", [0.0, 0.5, 0.9])
def test_steady_sliding_is_on_the_stribeck_curve(z_ba_share):
    """Sliding 30·w_ss at constant speed (vs/10, vs and 3·vs, each way),
    σ1 = 10, σ2 = 0.5: the force ends on g(v) + σ2·v, z_ba = 0, 0.5 and
    0.9 of Fc/σ0. Near w_ss, α = 1 − O((w_ss − w)²), so z approaches w_ss
    as LuGre's does, as exp(−u/w_ss): after 30·w_ss it is e^-30 ≈ 1e-13
    of the way off. Tolerance 1e-9·Fc (measured 4.6e-12 N: the force is
    written to 12 digits)."""
    z_ba = z_ba_share * FC / SIGMA0
    worst = 0.0
    for v in (VS / 10, VS, 3 * VS):
        distance = 30 * stribeck(v) / SIGMA0
        for sign in (1, -1):
            rows = prescribed([0.0, sign * distance], v, z_ba=z_ba, sample=distance / v / 100, sigma1=10.0,
                              sigma2=0.5)
            F = rows[-2][2]  # the last sample in motion (the path's end stops it)
            worst = max(worst, abs(F - sign * (stribeck(v) + 0.5 * v)))
    assert worst <= 1e-9 * FC, worst


def sine_zone_distance(z: float, z_ba: float, w_ss: float) -> float:
    """The distance u at which loading from z = 0 at constant speed reaches
    the deflection z in (z_ba, w_ss): dz/du = 1 − α·z/w_ss, so u = z_ba +
    ∫ dζ/(1 − α(ζ)·ζ/w_ss) from z_ba (Gauss–Legendre, 40 points on each of
    40 pieces)."""
    nodes, weights = np.polynomial.legendre.leggauss(40)
    edges = np.linspace(z_ba, z, 41)
    total = 0.0
    for lo, hi in zip(edges, edges[1:]):
        zeta = 0.5 * (hi - lo) * nodes + 0.5 * (hi + lo)
        a = 0.5 * np.sin(np.pi * (zeta - 0.5 * (w_ss + z_ba)) / (w_ss - z_ba)) + 0.5
        total += 0.5 * (hi - lo) * float(np.sum(weights / (1 - a * zeta / w_ss)))
    return z_ba + total


@pytest.mark.parametrize("z_ba_share", [0.0, 0.6])
def test_loading_unloading_and_relaxation_in_closed_form(z_ba_share):
    """Three closed forms along one path, σ1 = σ2 = 0 (so F = σ0·z), z_ba
    = 0 and 0.6·Fc/σ0:

    - loading from z = 0 at vs/10 over 6·w_ss: z = u (the distance) up to
      z_ba, then z(u) from u = z_ba + ∫ dζ/(1 − α(ζ)·ζ/w_ss), checked where
      dz/du > 1e-3 (where the quadrature of that integral holds);
    - at 3·vs (g about Fc, w_ss below w): α = 1 throughout, LuGre's
      relaxation z = w_ss + (z1 − w_ss)·exp(−u/w_ss) from z1 over 5·w_ss;
    - reversed at 3·vs: unloading is elastic, z = z2 − u, until −z
      reaches z_ba (the elastic range on the other side): over z2 + z_ba,
      also for z_ba = 0, where LuGre would not be elastic.

    Tolerance 1e-9·Fc on σ0·z (measured at most 8.5e-12 N, the force
    written to 12 digits; the quadrature's own error is below 1e-15 N).
    The sine is checked at every 50th sample (of 1 µs), the rest at every
    one."""
    z_ba = z_ba_share * FC / SIGMA0
    v1, v2 = VS / 10, 3 * VS
    w1, w2 = stribeck(v1) / SIGMA0, stribeck(v2) / SIGMA0
    d1, d2 = 6 * w1, 5 * w2
    # the reversal at 3·vs goes back z2 + z_ba (z2 ≈ w2), a little short
    d3 = 0.999 * (w2 + z_ba)
    path = [0.0, d1, d1 + d2, d1 + d2 - d3]
    speeds = [v1, v2, v2]
    t1, t2 = d1 / v1, d1 / v1 + d2 / v2
    rows = prescribed(path, speeds, z_ba=z_ba, sample=1e-6)
    worst = {"elastic loading": 0.0, "sine": 0.0, "relaxation": 0.0, "unloading": 0.0}
    checked = dict.fromkeys(worst, 0)
    # the relaxation and the unloading from the first sample of each
    # (clear of the turning point by two samples): (u, z) there
    ref = {}
    for i, (t, x, F) in enumerate(rows):
        z = F / SIGMA0
        if t < t1 - 2e-6:
            u = x
            if u <= z_ba:
                err, part = abs(z - u), "elastic loading"
            elif i % 50 == 0 and 1 - alpha(z, v1, z_ba) * z / w1 > 1e-3:  # every 50th: the quadrature
                slope = 1 - alpha(z, v1, z_ba) * z / w1
                err, part = abs(sine_zone_distance(z, z_ba, w1) - u) * slope, "sine"
            else:
                continue
        elif t1 + 2e-6 < t < t2 - 2e-6:
            part, u = "relaxation", x - d1
            u0, z0 = ref.setdefault(part, (u, z))
            err = abs(z - (w2 + (z0 - w2) * math.exp(-(u - u0) / w2)))
        elif t > t2 + 2e-6:
            part, u = "unloading", d1 + d2 - x
            u0, z0 = ref.setdefault(part, (u, z))
            err = abs(z - (z0 - (u - u0)))
        else:
            continue
        worst[part] = max(worst[part], SIGMA0 * err)
        checked[part] += 1
    z1, z2 = ref["relaxation"][1], ref["unloading"][1]
    # the relaxation started above w_ss (α = 1 throughout) and ended near it
    assert z1 > w2 * 1.4 and abs(z2 - w2) < 0.01 * w2
    assert checked["sine"] > 1000 and checked["relaxation"] > 1000 and checked["unloading"] > 300, checked
    if z_ba > 0:
        assert checked["elastic loading"] > 1000, checked
    assert max(worst.values()) <= 1e-9 * FC, worst
    # LuGre on the same path is not elastic on the way back: with z_ba = 0
    # its unloading departs from z2 − u by a measurable amount
    if z_ba == 0:
        lugre = [(d1 + d2 - x, F / SIGMA0) for t, x, F in prescribed(path, speeds, law="lugre", sample=1e-6)
                 if t > t2 + 2e-6]
        (u0, z0), off = lugre[0], 0.0
        off = max(abs(z - (z0 - (u - u0))) for u, z in lugre)
        assert SIGMA0 * off > 0.1 * FC, off


#: A rig with the elasto-plastic law as a presliding_drift case has it:
#: 0.5 mm of presliding, damping ratio 0.5, a dither on a sine drive.
RIG_EP = ["m=1.07", "k=1650", "Fc=1.513", "Fs=1.857", "vs=0.0309", "sigma0=3026", "sigma1=56.9",
          "sigma2=1.74", "amp=0.077", "period=4.64", "dither_amp=3e-4", "dither_period=0.3",
          "law=elastoplastic", "duration=5", "truth=1"]


@pytest.mark.parametrize("z_ba_share", [0.0, 0.5, 0.99])
def test_the_simulator_converges_with_the_elastoplastic_law(z_ba_share):
    """Halving the step (step_fraction and h_max) moves the noise-free
    position by far less than the 1 µm encoder step: below 1e-8 m
    (measured 2.8e-12 to 3.6e-12 m for z_ba 0, 0.5 and 0.99 of Fc/σ0: the
    last makes the sine of α 5 µm wide, which the step's limit resolves),
    and with a stiffer contact (σ0 = 1e5, 15 µm of presliding; measured
    3.3e-12 to 9.8e-12 m). The positions are written to 12 digits (some
    1e-13 m at 0.1 m), so this is the rounding's scale: the law's
    branches (α is continuous with its slope) need no location."""
    sim = cases.simulator()

    def run(args, k):
        out = subprocess.run([str(sim), *args, f"step_fraction={0.5 / 2 ** k}", f"h_max={1e-5 / 2 ** k}"],
                             capture_output=True, text=True, check=True).stdout.splitlines()
        return [float(line.split(",")[3]) for line in out[1:]]

    soft = RIG_EP + [f"z_ba={z_ba_share * 1.513 / 3026!r}"]
    stiff = [a for a in RIG_EP if not a.startswith(("sigma0=", "sigma1="))]
    stiff += ["sigma0=1e5", "sigma1=327", f"z_ba={z_ba_share * 1.513 / 1e5!r}"]
    for args in (soft, stiff):
        a, b = run(args, 0), run(args, 1)
        assert len(a) == len(b) == 5001
        assert max(abs(x - y) for x, y in zip(a, b)) < 1e-8
        # and the law was exercised: the mass moved by centimetres
        assert max(a) - min(a) > 0.01


def test_the_law_refuses_what_it_does_not_take():
    sim = cases.simulator()
    for extra in (["z_ba=2e-4"], ["z_ba=-1e-6"], ["z_ba=1e-5", "Fc_neg=1.2"],
                  ["z_ba=1e-5", "x_table=-1,1", "scale=1,1.1"], ["law=plastic"]):
        proc = subprocess.run([str(sim), "law=elastoplastic", "Fc=1", "Fs=1.5", "sigma0=1e4", "duration=0.01",
                               *extra], capture_output=True, text=True)
        assert proc.returncode == 2 and proc.stderr.startswith("lugre_rig: "), (extra, proc.stderr)


def test_the_hold_drive():
    """drive=hold: between given positions by u − sin(2πu)/(2π), at rest
    before the first time and after the last, the dither only in the
    flagged intervals, faded in and out over a dither period."""
    sim = cases.simulator()
    ts, xs, flags, amp, period = [0.2, 0.7, 1.9, 2.4], [0.0, 3e-3, 3e-3, -1e-3], [0, 1, 0], 2e-4, 0.3
    out = subprocess.run([str(sim), "drive=hold", "duration=3", "resolution=0", "k=100", "sigma0=1e4",
                          f"dither_amp={amp!r}", f"dither_period={period!r}",
                          "hold_t=" + ",".join(map(repr, ts)), "hold_x=" + ",".join(map(repr, xs)),
                          "hold_dither=" + ",".join(map(str, flags))],
                         capture_output=True, text=True, check=True).stdout.splitlines()

    def expected(t):
        if t <= ts[0]:
            return xs[0]
        if t >= ts[-1]:
            return xs[-1]
        i = max(j for j in range(len(ts) - 1) if ts[j] <= t)
        u = (t - ts[i]) / (ts[i + 1] - ts[i])
        x = xs[i] + (xs[i + 1] - xs[i]) * (u - math.sin(2 * math.pi * u) / (2 * math.pi))
        if flags[i]:
            tau, left = t - ts[i], ts[i + 1] - t
            e = (0.5 * (1 - math.cos(math.pi * tau / period)) if tau < period else 1.0) * \
                (0.5 * (1 - math.cos(math.pi * left / period)) if left < period else 1.0)
            x += amp * e * math.sin(2 * math.pi * tau / period)
        return x

    rows = [tuple(map(float, line.split(",")[:2])) for line in out[1:]]
    assert len(rows) == 3001
    # to the 9 significant digits written
    assert max(abs(a - expected(t)) for t, a in rows) < 1e-11
    # the dither is there, in the hold only
    assert max(abs(a - 3e-3) for t, a in rows if 0.7 <= t <= 1.9) > 0.9 * amp
    refused = subprocess.run([str(sim), "drive=hold", "hold_t=0,1,1", "hold_x=0,1,2"], capture_output=True, text=True)
    assert refused.returncode == 2 and "drive=hold" in refused.stderr


def cycle_means(x: list[float], start: int, end: int, per: int) -> list[float]:
    """The mean of x over each whole dither cycle of a hold [start, end)
    (samples), leaving out the first two (faded in, and the mass's
    transient after it) and the last (faded out)."""
    return [sum(x[start + i * per:start + (i + 1) * per]) / per for i in range(2, (end - start) // per - 1)]


def test_a_presliding_drift_case(tmp_path):
    """The case kind: its data and nominal are made as for any Rig1D case;
    the truth is elasto-plastic with the nominal's LuGre parameters and
    z_ba 0.5-0.9 of Fc/σ0; the drive holds the friction force at its
    levels, 0.5-0.65 of the elastic limit σ0·z_ba, of both signs (each
    hold's mean within 1e-3·Fc of its level: measured 2.3e-5·Fc at most,
    seeds 1-6 6.8e-5·Fc) and below the limit throughout (below 0.95 of it:
    measured 0.85 at most, seeds 1-6 too). In the holds the truth does not
    drift: the mean position over a dither cycle, from the third to the
    last but one, moves by less than 1 nm (measured 2e-15 m, seeds 1-6
    8e-12 m at most), while LuGre, run by the same simulator on the same
    drive, creeps by more than 20 µm in every hold (seed 1: 231-551 µm;
    seeds 1-6: 53-871 µm); and the mass slides by centimetres between
    them. Over the whole record the LuGre nominal's position departs from
    the truth's by more than 20 µm RMS (seeds 1-6: 393.5, 332.0, 211.8,
    713.4, 339.0 and 118.7 µm)."""
    assert "presliding_drift" not in cases.KINDS and "presliding_drift" in cases.MEMORY_KINDS
    assert cases.EXPECTED["presliding_drift"] == "elastic_presliding"
    case = cases.draw("presliding_drift", 0.1, 1)
    data, ssd = cases.make(case, tmp_path)
    nom, tru = case.nominal, case.truth
    fc = nom["Fc"]
    assert tru["law"] == "elastoplastic" and 0.5 <= tru["z_ba"] * nom["sigma0"] / fc <= 0.9
    assert all(tru[k] == nom[k] for k in ("Fc", "Fs", "vs", "sigma0", "sigma1", "sigma2"))
    assert 3e-4 <= fc / nom["sigma0"] <= 1e-3
    assert case.drive["drive"] == "hold"
    text = ssd.read_text()
    assert "LuGre.fmu" in text and "Rig1D.fmu" in text and "ElastoPlastic" not in text
    assert data.read_text().splitlines()[0] == "time,rig.x_act_in,rig.x"

    truth = cases.read_columns(tmp_path / f"{case.name}.truth.csv")
    x, F = truth["true_x"], truth["true_F"]
    nominal = tmp_path / "nominal.csv"
    cases.run_simulator(case, nom, nominal, truth=True)
    xn = cases.read_columns(nominal)["true_x"]
    limit = nom["sigma0"] * tru["z_ba"]
    per = round(case.drive["dither_period"] / case.sample)
    holds = case._holds
    assert len(holds) >= 4 and {math.copysign(1, level) for _, _, level in holds} == {-1, 1}
    for start, end, level in holds:
        i0, i1 = round(start / case.sample), round(end / case.sample)
        assert 0.5 <= abs(level) / limit <= 0.65
        assert abs(sum(F[i0:i1]) / (i1 - i0) - level) < 1e-3 * fc
        assert max(abs(f) for f in F[i0:i1]) < 0.95 * limit
        means, lugre = cycle_means(x, i0, i1, per), cycle_means(xn, i0, i1, per)
        assert abs(means[-1] - means[0]) < 1e-9, means
        assert abs(lugre[-1] - lugre[0]) > 20e-6, lugre
    # the slides between the holds: centimetres, faster than vs
    v = [(b - a) / case.sample for a, b in zip(x, x[1:])]
    assert max(x) - min(x) > 0.01 and sum(abs(s) > 2 * nom["vs"] for s in v) > 1000
    assert cases.rms(a - b for a, b in zip(x, xn)) > 20e-6
