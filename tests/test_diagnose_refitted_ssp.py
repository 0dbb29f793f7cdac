"""`fricsim diagnose` writes the refitted system as an SSP archive that FMPy
runs as well as `fricsim run` does: FMPy's reader (`fmpy.ssp.ssd.read_ssd`,
schema-validated) reads it, the friction parameters it binds are the
report's final model (the direction-dependent viscous friction EMPS
gains), and FMPy driving the archive's FMUs with fricsim's Jacobi loop
equals `fricsim run refitted.ssp` to 1e-9 relative."""

import json

import numpy as np
from fmpy.ssp.ssd import read_ssd

from conftest import ROOT
from test_run_ssp import assert_close, fmpy_jacobi_from_ssp, fricsim, read_csv

STOP = 0.5


def test_refitted_emps_system_runs_in_fmpy_with_the_fitted_parameters(tmp_path):
    out = tmp_path / "diagnosis"
    fricsim(
        "diagnose",
        ROOT / "examples" / "emps_nominal.ssd",
        ROOT / "examples" / "data" / "emps_train.csv",
        "--heldout",
        ROOT / "examples" / "data" / "emps_test_pulses.csv",
        "--out",
        out,
    )
    report = json.loads((out / "report.json").read_text())
    assert [e["name"] for e in report["effects"]][:1] == ["direction_dependent_viscous"]
    final = report["final_model"]
    ssp = out / "refitted.ssp"

    # the parameters FMPy reads for the friction component (the last
    # binding of a name wins, as in fricsim)
    ssd = read_ssd(str(ssp))
    friction = next(c for c in ssd.system.elements if c.name == report["friction_component"])
    bound = {}
    for binding in friction.parameterBindings:
        for parameter_set in binding.parameterValues:
            for p in parameter_set.parameters:
                bound[p.name] = p.value
    expected = {"Fc": final["fc"], "sigma2": final["sigma2"], "sigma2_neg": final["sigma2_neg"]}
    for i, (x, s) in enumerate(zip(final["x_table"], final["scale_pos"])):
        expected[f"x_table[{i + 1}]"] = x
        expected[f"scale_pos[{i + 1}]"] = s
    for name, value in expected.items():
        assert name in bound, f"refitted.ssp binds no {name}"
        assert abs(float(bound[name]) - value) <= 1e-12 * abs(value), (name, bound[name], value)
    assert bound["direction_dependent_viscous"] in ("true", "1", True)

    # the same run in both importers
    run = tmp_path / "run.csv"
    fricsim("run", ssp, "--stop", STOP, "--out", run, "--quiet")
    header, ours = read_csv(run)
    names, theirs = fmpy_jacobi_from_ssp(ssp, report["step"], STOP, tmp_path)
    assert header == names
    assert ours.shape == theirs.shape
    for k, name in enumerate(names):
        assert_close(name, ours[:, k], theirs[:, k])
    assert np.max(np.abs(theirs[:, names.index("friction.F")])) > 0
