#!/usr/bin/env python3
"""EMPS beside its published analysis (Janot, Gautier, Brunot 2019), on the
paper's own definitions, for the models of this repository written as
systems and for the model `fricsim diagnose` returns.

Usage (after ./build-fmu.sh; numpy and scipy from the project's venv):

    .venv/bin/python scripts/emps-beside-paper.py [--out DIR] [--markdown FILE]

For each model and each record (training: emps_train.csv, cross-test:
emps_test_pulses.csv) it gives

- the inverse-model force error (the paper's IDIM figure): the actuator
  force tau = gtau*vir against the force the model's inverse dynamics
  predict from the measured position, M*q'' + F(q', q), with q' and q''
  from the position filtered by a zero-phase 4th-order Butterworth low-pass
  at 100 Hz (the paper's filter; it decimates too, which is not done here),
  tau filtered the same way;
- the closed-loop errors of `fricsim run SYSTEM --input INPUTS` at the
  data's 1 ms step (inputs interpolated over each step, fricsim's
  default): position qm and force gtau*vir, where the simulated vir is the
  controller output plus the pulses.

Every error is the paper's relative error 100*||y - y_hat||/||y|| over the
whole record. The diagnosed models are the `refitted.ssp` of
`fricsim diagnose examples/emps_nominal.ssd emps_train.csv --heldout
emps_test_pulses.csv` (fitted on the training record, as the paper fits)
and of `fricsim diagnose examples/emps_nominal.ssd emps_train.csv
emps_test_pulses.csv` (fitted on both records, each held out in turn),
run here.
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy.signal import butter, filtfilt

ROOT = Path(__file__).resolve().parent.parent
FRICSIM = ROOT / "target/release/fricsim"
DATA = ROOT / "examples/data"
GTAU = 35.15065188
RECORDS = {"training": "emps_train.csv", "cross-test (pulses)": "emps_test_pulses.csv"}

# the paper's own figures (Janot, Gautier, Brunot 2019), where it gives them:
# (inverse-model force training, cross-test; closed-loop position and force
# training, pulses), in per cent
PAPER = {
    "symmetric + offset (published)": (4.08, 5.98, 0.0138, 5.85, 0.0080, 8.94),
    "asymmetric (published)": (3.11, None, None, None, None, None),
}


def read_csv(path):
    lines = [line for line in Path(path).read_text().splitlines() if not line.startswith("#")]
    header = lines[0].split(",")
    values = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    return {name: values[:, k] for k, name in enumerate(header)}


def relative_error(y, y_hat):
    return 100.0 * np.linalg.norm(y - y_hat) / np.linalg.norm(y)


def friction_force(p, v, x):
    """The LuGre FMU's steady force for a stiff contact (sigma0 -> inf: the
    bristle deflection follows the sliding level), with the model's levels,
    Stribeck curve, position table, viscous terms and offset."""
    negative = v < 0
    dd = p.get("direction_dependent", False)
    fc = np.where(negative & dd, p["fc_neg"], p["fc"])
    fs = np.where(negative & dd, p["fs_neg"], p["fs"])
    if p.get("position_dependent", False) and p.get("x_table"):
        scale_pos = np.interp(x, p["x_table"], p["scale_pos"])
        scale_neg = np.interp(x, p["x_table"], p["scale_neg"]) if dd else scale_pos
        scale = np.where(negative, scale_neg, scale_pos)
    else:
        scale = 1.0
    decay = np.exp(-np.abs(v / p["vs"]) ** p["stribeck_exponent"])
    level = scale * (fc + (fs - fc) * decay)
    sigma2 = np.where(negative & p.get("direction_dependent_viscous", False), p.get("sigma2_neg", p["sigma2"]), p["sigma2"])
    return np.sign(v) * level + sigma2 * v + p.get("f_offset", 0.0)


def inverse_model_error(mass, p, data):
    t = data["time"]
    dt = np.median(np.diff(t))
    b, a = butter(4, 100.0 / (0.5 / dt))
    q = filtfilt(b, a, data["rig.x"])
    v = np.gradient(q, t)
    acc = np.gradient(v, t)
    vir = data["rig.u_ctrl"] + data["rig.F_ext"] / GTAU
    tau = filtfilt(b, a, GTAU * vir)
    tau_hat = mass * acc + friction_force(p, v, q)
    # the filter's edges are left out, as a decimating filter leaves them
    keep = slice(100, len(t) - 100)
    return relative_error(tau[keep], tau_hat[keep])


def closed_loop_errors(system, data, inputs, out):
    subprocess.run([str(FRICSIM), "run", str(system), "--input", str(inputs), "--step", "1e-3",
                    "--start", repr(float(data["time"][0])), "--stop", repr(float(data["time"][-1])),
                    "--out", str(out), "--quiet"], check=True, stdout=subprocess.DEVNULL)
    sim = read_csv(out)
    t = data["time"]
    x_hat = np.interp(t, sim["time"], sim["rig.x"])
    u_hat = np.interp(t, sim["time"], sim["rig.u_ctrl"])
    pulses = data["rig.F_ext"] / GTAU
    vir, vir_hat = data["rig.u_ctrl"] + pulses, u_hat + pulses
    return relative_error(data["rig.x"], x_hat), relative_error(GTAU * vir, GTAU * vir_hat)


def parameters_of_ssd(path):
    """(mass, friction parameters named as report.json's final_model)."""
    import xml.etree.ElementTree as ET

    ns = {"ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues"}
    root = ET.parse(path).getroot()
    values = {}
    for component in root.iter("{http://ssp-standard.org/SSP1/SystemStructureDescription}Component"):
        for parameter in component.iter("{%s}Parameter" % ns["ssv"]):
            child = list(parameter)[0]
            raw = child.get("value")
            values[(component.get("name"), parameter.get("name"))] = raw == "true" if raw in ("true", "false") else float(raw)
    f = lambda name, default=None: values.get(("friction", name), default)
    p = {"fc": f("Fc"), "fs": f("Fs", f("Fc")), "vs": f("vs", 1e-3), "stribeck_exponent": f("stribeck_exponent", 2.0),
         "sigma2": f("sigma2"), "direction_dependent": f("direction_dependent", False),
         "direction_dependent_viscous": f("direction_dependent_viscous", False), "sigma2_neg": f("sigma2_neg", 0.0),
         "f_offset": f("F_offset", 0.0)}
    p["fc_neg"] = f("Fc_neg", p["fc"]) if p["direction_dependent"] else p["fc"]
    p["fs_neg"] = f("Fs_neg", p["fs"]) if p["direction_dependent"] else p["fs"]
    return values[("rig", "m")], p


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "out/emps-beside-paper")
    parser.add_argument("--markdown", type=Path, help="write the table here as well")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    data = {name: read_csv(DATA / f) for name, f in RECORDS.items()}
    inputs = {}
    for name, f in RECORDS.items():
        path = args.out / f"{Path(f).stem}-inputs.csv"
        d = data[name]
        path.write_text("time,rig.x_ref,rig.F_ext\n" + "".join(
            f"{t!r},{r!r},{e!r}\n" for t, r, e in zip(d["time"].tolist(), d["rig.x_ref"].tolist(), d["rig.F_ext"].tolist())))
        inputs[name] = path

    def diagnose(name, *records):
        out = args.out / name
        subprocess.run([str(FRICSIM), "diagnose", str(ROOT / "examples/emps_nominal.ssd"), *map(str, records),
                        "--out", str(out)], check=True, stdout=subprocess.DEVNULL)
        return out, json.loads((out / "report.json").read_text())

    diagnosis, report = diagnose("diagnosis", DATA / "emps_train.csv", "--heldout", DATA / "emps_test_pulses.csv")
    both, both_report = diagnose("diagnosis-both-records", DATA / "emps_train.csv", DATA / "emps_test_pulses.csv")
    nominal_mass, _ = parameters_of_ssd(ROOT / "examples/emps_nominal.ssd")

    def named(r):
        return " + ".join(e["name"] for e in r["effects"]) or "nothing named"

    models = [
        ("nominal (Coulomb + viscous, no offset)", ROOT / "examples/emps_nominal.ssd", parameters_of_ssd(ROOT / "examples/emps_nominal.ssd")),
        ("symmetric + offset (published)", ROOT / "examples/emps_symmetric_2019.ssd", parameters_of_ssd(ROOT / "examples/emps_symmetric_2019.ssd")),
        ("asymmetric (published)", ROOT / "examples/emps_asymmetric_2019.ssd", parameters_of_ssd(ROOT / "examples/emps_asymmetric_2019.ssd")),
        (f"diagnosed on training ({named(report)})", diagnosis / "refitted.ssp", (nominal_mass, report["final_model"])),
        (f"diagnosed on both records ({named(both_report)})", both / "refitted.ssp", (nominal_mass, both_report["final_model"])),
    ]
    rows = []
    for label, system, (mass, p) in models:
        idim = [inverse_model_error(mass, p, data[r]) for r in RECORDS]
        closed = [closed_loop_errors(system, data[r], inputs[r], args.out / f"{system.stem}-{k}.csv")
                  for k, r in enumerate(RECORDS)]
        rows.append((label, idim, closed))

    def cell(ours, paper):
        text = f"{ours:.3g}" if ours < 0.1 else f"{ours:.2f}"
        return text if paper is None else f"{text} ({paper})"

    lines = [
        "| model | inverse-model force, training | inverse-model force, cross-test | closed-loop position, training | closed-loop force, training | closed-loop position, pulses | closed-loop force, pulses |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for label, idim, closed in rows:
        paper = PAPER.get(label, (None,) * 6)
        ours = (idim[0], idim[1], closed[0][0], closed[0][1], closed[1][0], closed[1][1])
        lines.append(f"| {label} | " + " | ".join(cell(o, q) for o, q in zip(ours, paper)) + " |")
    text = "\n".join(lines) + "\n"
    print(text)
    print(json.dumps({label: {"inverse_model": idim, "closed_loop": closed} for label, idim, closed in rows}))
    if args.markdown:
        args.markdown.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
