"""`fricsim run` of Wijata et al. 2016's planar oscillator against FMPy.

dist/planar_decay.ssp (packed by build-fmu.sh from
examples/planar_decay.ssd: Rig2D.fmu and Bristle2D.fmu connected
v1, v2 -> friction, F1, F2 -> rig, the bristle parameters from
bristle2d_wijata2016.ssv) is read by FMPy's own SSP reader
(`fmpy.ssp.ssd.read_ssd`, schema-validated, the .ssv binding resolved inside
the archive) and its FMUs are driven by FMU2Slave instances in a Python loop
with the same fixed step (1e-4 s) and Jacobi scheme as fricsim (the loop of
test_run_ssp.py). Over the whole example (3 s: about seven half-cycles of
two-dimensional sliding, then the body sticks) every recorded column equals
fricsim's to 1e-9 relative.
"""

import numpy as np

from conftest import DIST
from test_run_ssp import assert_close, fmpy_jacobi_from_ssp, fricsim, read_csv

STEP = 1e-4
STOP = 3.0


def test_fricsim_run_of_the_planar_oscillator_equals_fmpy(tmp_path):
    ssp = DIST / "planar_decay.ssp"
    assert ssp.exists(), f"{ssp} is missing: run ./build-fmu.sh"
    out = tmp_path / "run.csv"
    # step, master and stop time from the example's annotation
    result = fricsim("run", ssp, "--out", out, "--quiet")
    assert "30000 of 30000 macro steps of 0.0001 s with jacobi" in result.stdout
    header, ours = read_csv(out)
    names, theirs = fmpy_jacobi_from_ssp(ssp, STEP, STOP, tmp_path)
    assert header == names
    assert ours.shape == theirs.shape
    for k, name in enumerate(names):
        assert_close(name, ours[:, k], theirs[:, k])

    # the comparison covers what the example shows: sliding along a turning
    # direction (both force components at the sliding level 1 N) and the
    # final stick inside the stiction radius 1.1 N / 100 N/m
    f1 = theirs[:, names.index("friction.F1")]
    f2 = theirs[:, names.index("friction.F2")]
    assert f1.min() < -0.99 and f1.max() > 0.99
    assert f2.min() < -0.99 and f2.max() > 0.99
    x1 = theirs[:, names.index("rig.x1")]
    x2 = theirs[:, names.index("rig.x2")]
    assert np.hypot(x1[-1], x2[-1]) < 0.011
    v1 = theirs[:, names.index("rig.v1")]
    v2 = theirs[:, names.index("rig.v2")]
    assert np.hypot(v1[-1], v2[-1]) < 1e-6
