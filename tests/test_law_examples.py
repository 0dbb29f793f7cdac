"""The example systems of the laws beyond LuGre (examples/*.ssd), run as a
user runs them (`fricsim run`), each against the property it shows:

- reset_integrator_stick_slip: the reset integrator of Haessig and
  Friedland (1991) breaks away at its peak (1 + a)·σ0·z0 and slides at
  σ0·z0;
- elasto_plastic_hold: under a force oscillating below break-away LuGre
  creeps forward on every cycle and the elasto-plastic law of Dupont et
  al. (2002) does not;
- presliding_memory: the pre-sliding loop of Maxwell-slip has the area of
  Iwan's (1966) closed form; GMS's loop is retraced cycle after cycle and
  its area is the work its P_diss reports;
- bliman_sorine_loops: the two-element law's force stays within the loop
  its parameters set and settles at f1 − f2 in sliding.

libcosim runs the same archives (tests/test_libcosim.py)."""

import subprocess

import numpy as np
import pytest

from conftest import ROOT

FRICSIM = ROOT / "target" / "release" / "fricsim"
trapezoid = np.trapezoid if hasattr(np, "trapezoid") else np.trapz


def run(name, tmp_path):
    assert FRICSIM.exists(), f"{FRICSIM} is missing: run ./build-fmu.sh"
    out = tmp_path / f"{name}.csv"
    done = subprocess.run([str(FRICSIM), "run", str(ROOT / "examples" / f"{name}.ssd"), "--out", str(out),
                           "--quiet"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    header = out.read_text().splitlines()[0].split(",")
    data = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    return {c: data[:, k] for k, c in enumerate(header)}


def cycles(t, first, last):
    """Masks of the whole 1 s cycles [k, k + 1] for k = first..last-1."""
    return [(t >= k - 1e-9) & (t <= k + 1 + 1e-9) for k in range(first, last)]


def test_the_reset_integrator_breaks_away_at_its_peak_and_slides_at_its_level(tmp_path):
    r = run("reset_integrator_stick_slip", tmp_path)
    sigma0, z0, a, k, v_a = 1e4, 1e-4, 0.1, 2.0, 0.1  # the FMU's defaults, the rig of the file
    sliding = r["friction.sliding"] > 0.5
    first = np.argmax(sliding)
    assert sliding.any()
    # quasi-statically k·(v_a·t − z0) = (1 + a)·σ0·z0; the body's inertia
    # on the bristle delays it by milliseconds
    t_quasi_static = ((1 + a) * sigma0 * z0 / k + z0) / v_a
    assert abs(r["time"][first] - t_quasi_static) <= 0.002 * t_quasi_static, r["time"][first]
    peak = np.max(r["friction.F"][:first + 1])
    assert abs(peak - (1 + a) * sigma0 * z0) <= 0.01 * (1 + a) * sigma0 * z0, peak
    # held at the limit, the strain does not move: F = σ0·z0 exactly
    assert np.max(np.abs(r["friction.F"][sliding] - sigma0 * z0)) <= 1e-9


def test_the_elasto_plastic_law_holds_where_lugre_creeps(tmp_path):
    """Dupont, Hayward, Armstrong and Altpeter (2002): the same force,
    0.5 + 0.4·sin 2πt N below the 1 N level, on two masses; x sampled once a
    cycle at the same phase."""
    r = run("elasto_plastic_hold", tmp_path)
    t = r["time"]
    at = [int(np.argmin(np.abs(t - k))) for k in range(1, 11)]
    lugre = np.diff(r["rig_lugre.x"][at])
    held = np.diff(r["rig_ep.x"][at])
    # LuGre creeps forward by the same few micrometres every cycle
    assert np.all(lugre > 5e-6), lugre
    assert np.ptp(lugre) <= 0.01 * np.mean(lugre), lugre
    # the elasto-plastic contact is elastic all along and comes back
    assert np.all(r["elastoplastic.elastic"] > 0.5)
    assert np.max(np.abs(held)) <= 1e-3 * np.mean(lugre), held
    assert np.max(np.abs(r["rig_ep.x"])) <= 0.9 / 1e5 * 1.01  # F_drive/σ0 at most


def test_presliding_loops_have_the_area_of_their_dissipation(tmp_path):
    r = run("presliding_memory", tmp_path)
    t = r["time"]
    # Maxwell-slip's defaults: ten elements of 1e4 N/m, W_i = i/55 N
    k = np.full(10, 1e4)
    w = np.arange(1, 11) / 55.0
    gms_areas = []
    for m in cycles(t, 1, 5):
        x, f = r["rig_ms.x"][m], r["maxwell_slip.F"][m]
        half_width = np.ptp(x) / 2
        slipping = k * half_width > w
        assert 2 <= slipping.sum() < 10, slipping  # some elements slip, not all
        closed = np.sum(4 * w[slipping] * (half_width - w[slipping] / k[slipping]))
        area = trapezoid(f, x)
        assert abs(area - closed) <= 0.01 * closed, (area, closed)
        # GMS: its loop's area is what its P_diss adds up to over the cycle
        x, f = r["rig_gms.x"][m], r["gms.F"][m]
        area = trapezoid(f, x)
        dissipated = trapezoid(r["gms.P_diss"][m], t[m])
        assert area > 0
        assert abs(dissipated - area) <= 0.03 * area, (dissipated, area)
        gms_areas.append(area)
    assert np.ptp(gms_areas) <= 0.01 * np.mean(gms_areas), gms_areas
    # the elements break loose one after another: never all at once
    assert 0 < np.max(r["gms.n_slipping"]) < 10
    assert 0 < np.max(r["maxwell_slip.n_slipping"]) < 10


def test_bliman_sorine_settles_at_its_coulomb_level_and_stays_within_its_loop(tmp_path):
    r = run("bliman_sorine_loops", tmp_path)
    f1, f2, peak = 19.875, 17.8227, 2.5017013870499  # Sun et al. 2016, Table 8, trial 6; the loop's peak
    f = r["friction.F"]
    assert np.max(np.abs(f)) <= peak * (1 + 1e-6)
    # slides in both directions, at f1 − f2
    sliding = r["friction.sliding"] > 0.5
    assert np.any(sliding & (r["rig.v"] > 0)) and np.any(sliding & (r["rig.v"] < 0))
    assert np.max(np.abs(np.abs(f[sliding]) - (f1 - f2))) <= 0.011 * (f1 - f2)
    # over the run the power it reports adds up with the change of its
    # stored energy to the work done on it, to the sampling of F·v
    t = r["time"]
    work = trapezoid(f * r["rig.v"], t)
    stored = r["friction.E_stored"][-1] - r["friction.E_stored"][0]
    dissipated = trapezoid(r["friction.P_diss"], t)
    assert work > 0
    assert abs(work - dissipated - stored) <= 0.02 * work, (work, dissipated, stored)


@pytest.mark.parametrize("name", ["reset_integrator_stick_slip", "elasto_plastic_hold", "presliding_memory",
                                  "bliman_sorine_loops"])
def test_every_output_is_finite(name, tmp_path):
    r = run(name, tmp_path)
    assert all(np.all(np.isfinite(v)) for v in r.values())
