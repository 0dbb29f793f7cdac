"""Every FMU passes FMPy's validation and declares the variables that
scripts and other tools rely on (issue 2)."""

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from conftest import MODELS, fmu_path

EXPECTED = {
    "Dahl": {"input": {"v"}, "output": {"F", "z", "sliding"}, "parameter": {"sigma", "Fc", "alpha"}},
    "LuGre": {"input": {"v", "x", "Fn"}, "output": {"F", "z", "sliding"},
              "parameter": {"sigma0", "sigma1", "sigma2", "Fc", "Fs", "vs", "stribeck_exponent", "vd",
                            "direction_dependent", "Fc_neg", "Fs_neg", "normal_force_form",
                            "position_dependent", "n_table"}},
    "ResetIntegrator": {"input": {"v"}, "output": {"F", "z", "sliding"}, "parameter": {"sigma0", "sigma1", "a", "z0"}},
    "Bristle": {"input": {"x"}, "output": {"F", "n_connected", "sliding"},
                "parameter": {"sigma_ini", "delta_max", "x_rel", "n_bristles", "c", "mu_c", "Fn", "seed"}},
    "Bristle2D": {"input": {"v1", "v2"}, "output": {"F1", "F2", "z1", "z2", "sliding"},
                  "parameter": {"sigma01", "sigma02", "sigma11", "sigma12", "a1", "a2", "z0", "av"}},
}


@pytest.mark.parametrize("name", MODELS)
def test_validate_fmu_reports_no_problems(name):
    assert validate_fmu(str(fmu_path(name))) == []


@pytest.mark.parametrize("name", MODELS)
def test_declared_variables_and_capabilities(name):
    md = read_model_description(str(fmu_path(name)))
    by_causality = {}
    for v in md.modelVariables:
        by_causality.setdefault(v.causality, set()).add(v.name)
    for causality, names in EXPECTED[name].items():
        missing = names - by_causality.get(causality, set())
        assert not missing, f"{name} lacks {causality}s {missing}"
    cs = md.coSimulation
    assert cs.modelIdentifier == name
    assert cs.canHandleVariableCommunicationStepSize
    assert cs.canInterpolateInputs
    assert cs.canGetAndSetFMUstate
    assert cs.canSerializeFMUstate
    assert cs.providesDirectionalDerivative
    assert cs.maxOutputDerivativeOrder == 1
    if name == "LuGre":
        assert sum(1 for v in md.modelVariables if v.name.startswith("x_table[")) >= 16
    for v in md.modelVariables:
        if v.type == "Real" and v.causality in ("input", "output", "parameter") and v.name not in (
                "alpha", "a", "a1", "a2", "stribeck_exponent", "mu_c") and not v.name.startswith("scale_"):
            assert v.unit, f"{name}.{v.name} has no unit"
