"""The host against FMPy (issue 3): FMPy's FMU2Slave drives the same two
FMUs (Rig1D + LuGre, the stick-slip benchmark) with the same fixed macro
step and the same Jacobi scheme in a Python loop; `fricsim cosim` must give
the same time series to 1e-9 relative."""

import subprocess

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from conftest import ROOT, fmu_path

FRICSIM = ROOT / "target" / "release" / "fricsim"
STEP = 1e-4
STOP = 9.0  # the first slip is at 7.54 s
CONNECTIONS = [("rig", "v", "friction", "v"), ("friction", "F", "rig", "F")]
DISCRETE = ("Integer", "Boolean")


def fmpy_jacobi(tmp_path):
    components = {}
    for name, model in [("rig", "Rig1D"), ("friction", "LuGre")]:
        md = read_model_description(str(fmu_path(model)))
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu_path(model)), unzipdir=str(tmp_path / name)),
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        vr = {v.name: v.valueReference for v in md.modelVariables}
        # fricsim records each component's Real outputs, then its Integer
        # and Boolean ones (as whole numbers), as FMPy records every output
        outputs = [v.name for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
        outputs += [v.name for v in md.modelVariables if v.causality == "output" and v.type in DISCRETE]
        types = {v.name: v.type for v in md.modelVariables}
        components[name] = (fmu, vr, outputs, types)

    def propagate():
        values = [components[a][0].getReal([components[a][1][o]])[0] for a, o, _, _ in CONNECTIONS]
        for (_, _, b, i), x in zip(CONNECTIONS, values):
            components[b][0].setReal([components[b][1][i]], [x])

    def read(c, o):
        fmu, vr, _, types = components[c]
        getter = {"Real": fmu.getReal, "Integer": fmu.getInteger, "Boolean": fmu.getBoolean}[types[o]]
        return float(getter([vr[o]])[0])

    def sample():
        return [read(c, o) for c in ("rig", "friction") for o in components[c][2]]

    propagate()
    for fmu, *_ in components.values():
        fmu.exitInitializationMode()
    propagate()
    columns = [f"{c}.{o}" for c in ("rig", "friction") for o in components[c][2]]
    rows = [[0.0] + sample()]
    n = round(STOP / STEP)
    for i in range(n):
        t, t_next = i * STEP, (i + 1) * STEP
        propagate()
        for fmu, *_ in components.values():
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=t_next - t)
        rows.append([t_next] + sample())
    for fmu, *_ in components.values():
        fmu.terminate()
        fmu.freeInstance()
    return ["time"] + columns, np.array(rows)


def test_fricsim_jacobi_equals_fmpy_jacobi(tmp_path):
    out = tmp_path / "fricsim.csv"
    subprocess.run([str(FRICSIM), "cosim", "--fmu", f"rig={fmu_path('Rig1D')}", "--fmu",
                    f"friction={fmu_path('LuGre')}", "--connect", "rig.v->friction.v", "--connect",
                    "friction.F->rig.F", "--step", repr(STEP), "--stop", repr(STOP), "--out", str(out)],
                   check=True, capture_output=True, text=True)
    header = out.read_text().splitlines()[0].split(",")
    ours = np.loadtxt(out, delimiter=",", skiprows=1)
    names, theirs = fmpy_jacobi(tmp_path)
    assert header == names
    assert ours.shape == theirs.shape
    for k, name in enumerate(names):
        scale = max(np.max(np.abs(theirs[:, k])), 1e-300)
        err = np.max(np.abs(ours[:, k] - theirs[:, k])) / scale
        assert err <= 1e-9, f"{name}: relative difference {err:.3e}"
    # the run reaches sliding (the comparison covers stick and slip), and
    # the Boolean output says so in both
    v = theirs[:, names.index("rig.v")]
    assert v.max() > 0.05
    sliding = ours[:, names.index("friction.sliding")]
    assert set(np.unique(sliding)) == {0.0, 1.0}
