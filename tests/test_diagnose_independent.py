"""`fricsim diagnose` on data it has never seen: datasets made by an
independent simulator (tests/independent/lugre_rig.c: plain C, its own
integrator, no code shared with the FMUs), run as a user would (the
defaults, the CLI), one case of each kind that once failed: nominal =
truth, a stiff nominal against millimetre presliding, a soft nominal
against a stiff truth, an effect at 5 %, spikes and a dropout in the data,
a plant that is not Rig1D, a Dahl nominal, a GMS and an elasto-plastic
truth against a LuGre nominal. The full grid (more seeds, every
effect at 10 % and 5 %) is `python3 tests/independent/suite.py`, whose
table is in BENCHMARKS.md."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent / "independent"))
import cases  # noqa: E402
import suite  # noqa: E402

def check(row: dict) -> None:
    """The figures every case must meet."""
    assert suite.FRICSIM.exists(), "needs target/release/fricsim and dist/: run ./build-fmu.sh"
    assert row["report"], f"{row['case']}: no report: {row['stderr']}"
    assert row["named_right"], f"{row['case']}: found {row['found']}"
    assert row["never_worse"], (
        f"{row['case']}: final held-out RMS {row['final_rms']} > 1.05 x the given model's {row['given_rms']}"
    )
    if "size" in row:
        assert row["size"]["relative_error"] <= 0.10, f"{row['case']}: {row['size']}"
    if "localised_right" in row:
        assert row["localised_right"], f"{row['case']}: its change put on {row['localised_as']}"
    if not row["found"]:
        assert not row["unexplained"], f"{row['case']}: nothing named, yet 'unexplained'"


@pytest.mark.parametrize(
    "kind,magnitude,seed",
    [
        ("none", 0.1, 7),
        ("presliding_stiff_nominal", 0.1, 7),
        ("presliding_soft_nominal", 0.1, 8),
        ("direction_dependent", 0.05, 7),
        ("viscous", 0.05, 9),
        ("dahl_viscous", 0.1, 7),
        # an elasto-plastic truth: LuGre creeps under the held force,
        # the truth does not; the nominal moves to the elasto-plastic law
        ("presliding_drift", 0.1, 1),
        # the rounds name a Stribeck curve for the elasto-plastic
        # signature; the law fitted from the final model misses the
        # threshold, fitted from the baseline it passes and explains it
        ("presliding_drift", 0.1, 12),
        # GMS beats LuGre refitted at its stiffness by 42 % at p = 0.024:
        # evidence enough once it has passed against the final model
        ("presliding_memory", 0.1, 2),
    ],
)
def test_case_from_the_independent_simulator(kind, magnitude, seed, tmp_path):
    check(suite.run_case(cases.draw(kind, magnitude, seed), tmp_path))


def test_spikes_and_a_dropout_are_found_and_change_nothing(tmp_path):
    row = suite.run_case(cases.draw("none", 0.1, 107), tmp_path, bad_data=True)
    check(row)
    assert row["bad_samples_found"], "a spike or the dropout was not reported at its line"
    assert row["flagged"] >= 7  # two spikes and five repeated rows


def test_a_plant_that_is_not_rig1d_is_diagnosed_by_output_error(tmp_path):
    row = suite.run_case(cases.draw("two_mass_viscous", 0.1, 7), tmp_path)
    check(row)
    assert "size" in row


def test_coarse_data_a_stribeck_curve_is_not_taken_for_presliding(tmp_path):
    """200 Hz through a 10 µm encoder, a hidden 10 % Stribeck curve on a
    rig driven by a triangle: the force the data imply shows little of it,
    and before the two competed on equal terms presliding (an output-error
    fit) gained 72 % while Stribeck's force fit gained nothing, presliding
    was refused as unresolved and position dependence was named. Now
    Stribeck is fitted by output error too, is named, and the report says
    how it stands to presliding."""
    row = suite.run_case(cases.draw("stribeck", 0.1, 3, coarse=True), tmp_path)
    assert row["report"], row["stderr"]
    assert row["found"] == ["stribeck"], row["found"]
    assert row["never_worse"]
    report = (tmp_path / f"out-{row['case']}" / "report.json").read_text()
    overlap = json.loads(report)["effects"][0]["overlap"]
    assert overlap["other"] == "presliding" and overlap["p_separated"] < 0.01, overlap


def test_coarse_data_two_explanations_not_separated_name_neither(tmp_path):
    """The same contract, another rig: presliding scores better than the
    hidden Stribeck curve on held-out data (the old rule named presliding),
    but the data do not separate the two: neither is named, nothing else
    stands in for them, and the report's notes say why."""
    row = suite.run_case(cases.draw("stribeck", 0.1, 7, coarse=True), tmp_path)
    assert row["report"], row["stderr"]
    assert row["found"] == [], row["found"]
    assert row["never_worse"]
    notes = json.loads((tmp_path / f"out-{row['case']}" / "report.json").read_text())["notes"]
    assert any("do not separate them" in n and "neither is named" in n for n in notes), notes


def test_a_stiffer_contact_is_named_when_presliding_encompasses_stribeck(tmp_path):
    """The open-loop two-mass drive, a soft LuGre nominal, the truth a
    stiffer LuGre contact (seed 1): presliding and a Stribeck curve both
    pass round 1 and the held-out data alone do not separate them, but
    fitted together presliding adds to the Stribeck curve and the Stribeck
    curve adds nothing to presliding (not even at the 5 % level):
    presliding encompasses it and is named (before: neither). Its size is
    not asserted: σ0 comes out 61 % below the truth, the pre-sliding
    distance (10-25 µm) against masses drifting over metres."""
    case = cases.draw("two_mass_presliding_soft_nominal", 0.1, 1)
    row = suite.run_case(case, tmp_path)
    assert row["report"], row["stderr"]
    assert row["found"] == ["presliding"], row["found"]
    assert row["never_worse"]
    report = json.loads((tmp_path / f"out-{case.name}" / "report.json").read_text())
    overlap = report["effects"][0]["overlap"]
    assert overlap["other"] == "stribeck" and overlap["encompasses"], overlap
    assert overlap["p_separated"] >= report["round_thresholds"][0], overlap
    assert overlap["other_p_after"] >= 0.05, overlap


def test_a_law_that_only_resizes_lugres_presliding_is_not_moved_to(tmp_path):
    """The same record with only `normal_load` as a candidate, which
    these data cannot show (no normal force is measured): no round runs,
    and the final LuGre model is the soft nominal with its levels. The
    elasto-plastic law, its σ0 fitted freely, beats that LuGre model on
    the held-out data (once it was moved to and `elastic_presliding`
    named), but LuGre refitted from the law's own levels and stiffness
    does as well, so the nominal stays LuGre and the report says why."""
    case = cases.draw("two_mass_presliding_soft_nominal", 0.1, 1)
    row = suite.run_case(case, tmp_path, extra=("--candidate", "normal_load"))
    assert row["report"], row["stderr"]
    report = json.loads((tmp_path / f"out-{case.name}" / "report.json").read_text())
    memory = {m["law"]: m for m in report["memory"]}
    assert all(m["outcome"] != "moved" for m in memory.values()), memory
    ep = memory["elasto_plastic"]
    # it beat the final LuGre model: the check against LuGre at its
    # stiffness was needed, and LuGre there did as well
    assert ep["heldout_rms"] < 0.5 * ep["lugre_heldout_rms"], ep
    resized = ep["lugre_at_law_stiffness"]
    assert resized["p_value"] >= ep["threshold"], resized
    assert resized["heldout_rms"] <= 1.1 * ep["heldout_rms"], resized
    assert "re-sized" in ep["reason"], ep
    assert report["rounds"] == [] and row["found"] == [], row["found"]


def test_an_effect_is_not_set_aside_for_levels_that_gain_nothing(tmp_path):
    """The servo axis, a stiff nominal against a softer presliding truth
    (seed 6): presliding takes the held-out RMS from 0.074 to 4e-5, and
    against its levels refitted alone its gain of 100 % sits in few
    enough groups that p = 0.14. Those levels gain nothing on the current
    model, so the gain is not theirs: presliding is named and sized
    (before, it was set aside and nothing named). Where the change is put
    (`localised_as`) is not asserted: on this closed-loop plant it is put
    on the velocity."""
    row = suite.run_case(cases.draw("servo_presliding_stiff_nominal", 0.1, 6), tmp_path)
    assert row["report"], row["stderr"]
    assert row["found"] == ["presliding"], row["found"]
    assert row["never_worse"]
    assert row["size"]["relative_error"] <= 0.10, row["size"]


def test_a_stribeck_peak_stood_in_for_by_the_levels_is_named(tmp_path):
    """The two-mass drive with a 10 % Stribeck peak hidden (seed 3): the
    levels refitted alone rise 22 % to stand in for it, and from that
    model re-sized the curve stopped at 0.18 held-out RMS after the
    screen's three iterations while a position table reached 0.055 and
    was named. From its five best starts (one of them the given levels)
    the curve is named and sized."""
    row = suite.run_case(cases.draw("two_mass_stribeck", 0.1, 3), tmp_path)
    check(row)
    assert row["found"] == ["stribeck"], row["found"]


def test_direction_dependent_levels_are_not_taken_for_an_offset(tmp_path):
    """The two-mass drive with a 10 % direction dependence hidden (seed
    3): an offset is the same force wherever the contact slides, and,
    fitted in ln Fc and ln Fc_neg, the levels by direction overshot and
    lost to it (held-out RMS 0.0135 against 0.0013). Fitted as the mean
    level and the asymmetry they reach the truth, the data do not
    separate the two, and the levels are named as the family's first.
    Where the change is put (`localised_as`) is not asserted: on this
    record its bins by speed explain 48 % of it, by direction 43 %."""
    row = suite.run_case(cases.draw("two_mass_direction_dependent", 0.1, 3), tmp_path)
    assert row["report"], row["stderr"]
    assert row["found"] == ["direction_dependent"], row["found"]
    assert row["never_worse"]
    assert row["size"]["relative_error"] <= 0.05, row["size"]


def test_an_effect_whose_size_holds_zero_is_not_named(tmp_path):
    """The servo axis with a 10 % position dependence hidden (seed 4),
    the table kept at six knots (--max-position-knots 6): it cannot
    follow the truth's five knots, and a viscous term then gains 8.5 %
    of the held-out mean square at p = 5e-6; its σ2 has the interval
    [-1.7, 2.2] N·s/m, which holds 0, so it is set aside and the table
    alone is named."""
    case = cases.draw("servo_position_dependent", 0.1, 4)
    row = suite.run_case(case, tmp_path, extra=("--max-position-knots", "6"))
    check(row)
    assert row["found"] == ["position_dependent"], row["found"]
    report = json.loads((tmp_path / f"out-{case.name}" / "report.json").read_text())
    reasons = [c.get("unresolved") or "" for r in report["rounds"] for c in r if c["name"] == "viscous"]
    assert any("holds 0" in why for why in reasons), reasons


@pytest.mark.parametrize("kind,seed", [("position_dependent", 1), ("servo_position_dependent", 4)])
def test_the_position_table_is_made_as_fine_as_the_data_ask(kind, seed, tmp_path):
    """A 10 % position dependence hidden on Rig1D (seed 1) and on the
    servo axis (seed 4), the truth's five knots not among the six the
    table is added with. Kept at six knots, the table left a held-out
    RMS of 30 times the floor of noise and step error on Rig1D, and a
    Stribeck curve re-sized beside it (vs up by 5 %) was named; on the
    servo axis a viscous term passed and had to be set aside (the test
    above). Now, when the rounds end, the table is doubled (11, then 21
    knots) while the finer one passes the test that admitted the effect:
    the table alone is named, and the residual ends within twice the
    floor."""
    case = cases.draw(kind, 0.1, seed)
    row = suite.run_case(case, tmp_path)
    check(row)
    assert row["found"] == ["position_dependent"], row["found"]
    report = json.loads((tmp_path / f"out-{case.name}" / "report.json").read_text())
    (effect,) = report["effects"]
    steps = [(t["knots"], t["kept"]) for t in effect["table"]]
    assert steps == [(11, True), (21, True)], effect["table"]
    assert sum(1 for k in effect["parameters"] if k.startswith("x_table[")) == 21
    assert report["final_rms"] <= 2 * report["floor_rms"], (report["final_rms"], report["floor_rms"])


def test_a_gms_contact_moves_the_nominal_to_gms(tmp_path):
    """A contact whose truth is GMS (the independent simulator's `law=gms`:
    nonlocal pre-sliding memory, a dithered actuator making reversals
    inside pre-sliding) and a LuGre nominal with its levels: the diagnosis
    names the pre-sliding memory, moves the nominal to GMS by the
    acceptance rule, and the GMS system it writes (refitted-gms.ssp) runs
    in `fricsim run` and follows the measured position closer than the
    refitted LuGre system does. (On the LuGre cases above, the same check
    keeps LuGre: `check` would see the extra name.)"""
    case = cases.draw("presliding_memory", 0.1, 1)
    row = suite.run_case(case, tmp_path)
    check(row)
    out = tmp_path / f"out-{case.name}"
    report = json.loads((out / "report.json").read_text())
    memory = {m["law"]: m for m in report["memory"]}
    gms = memory["gms"]
    assert gms["outcome"] == "moved", memory
    assert gms["p_value"] < gms["threshold"] and gms["gain"] >= report["min_gain"], gms
    assert gms["heldout_rms"] < 0.5 * gms["lugre_heldout_rms"], gms
    assert memory["elasto_plastic"]["outcome"] != "moved", memory
    assert "Pre-sliding memory" in (out / "report.md").read_text()
    measured = cases.read_columns(tmp_path / f"{case.name}.csv")["rig.x"]
    errors = {}
    for command in report["rerun"]:
        subprocess.run(command.split(), check=True, capture_output=True,
                       executable=str(suite.FRICSIM))
        result = Path(command.split()[-1])
        x = cases.read_columns(result)["rig.x"]
        errors[result.name] = cases.rms(a - b for a, b in zip(x, measured))
    assert set(errors) == {"rerun.csv", "rerun-gms.csv"}, errors
    assert errors["rerun-gms.csv"] < 0.5 * errors["rerun.csv"], errors


def test_the_simulator_converges():
    """Halving the simulator's step moves the noise-free position by far less
    than the 1 µm encoder step."""
    sim = cases.simulator()
    args = ["m=1.07", "k=1650", "Fc=1.513", "Fs=1.857", "vs=0.0309", "sigma0=5e6",
            "sigma1=4218", "sigma2=1.74", "amp=0.077", "period=4.64", "duration=5", "truth=1"]

    def run(fraction):
        out = subprocess.run([str(sim), *args, f"step_fraction={fraction}"], capture_output=True,
                             text=True, check=True).stdout.splitlines()
        return [float(line.split(",")[3]) for line in out[1:]]

    a, b = run(0.5), run(0.25)
    assert max(abs(x - y) for x, y in zip(a, b)) < 1e-9


def test_the_simulator_refuses_bad_arguments():
    sim = cases.simulator()
    r = subprocess.run([str(sim), "m=-1"], capture_output=True, text=True)
    assert r.returncode == 2 and "must be positive" in r.stderr
    r = subprocess.run([str(sim), "mass=1"], capture_output=True, text=True)
    assert r.returncode == 2 and "unknown key `mass`" in r.stderr
