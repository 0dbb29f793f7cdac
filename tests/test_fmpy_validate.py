"""Every FMU passes FMPy's validation (its model description against the
schema, the model structure including the Model Exchange part: states,
derivatives and their dependencies) and declares the variables and
interfaces that scripts and other tools rely on (issues 2 and 22)."""

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

import shipped
from conftest import MODELS, fmu_path

# the rig FMUs (the mechanical side), validated like the friction laws
RIGS = shipped.RIGS

# the FMUs with a Model Exchange interface: their states, in order, and
# their number of event indicators
MODEL_EXCHANGE_STATES = {"Dahl": (["F_dahl"], 1), "LuGre": (["z"], 1), "ResetIntegrator": (["z"], 2),
                  "Bristle2D": (["z1", "z2"], 1), "BlimanSorine": (["x1", "x2"], 1),
                  "ElastoPlastic": (["z"], 5),
                  "MaxwellSlip": ([f"F_element[{i}]" for i in range(1, 101)], 101),
                  "GMS": ([f"F_element[{i}]" for i in range(1, 101)], 101),
                  # no continuous states: its switches are its events
                  "Classical": ([], 4)}

EXPECTED = {
    "Dahl": {"input": {"v"}, "output": {"F", "z", "sliding", "P_diss", "E_stored"}, "parameter": {"sigma", "Fc", "alpha", "F_offset"},
             "local": {"F_dahl", "der(F_dahl)"}},
    "LuGre": {"input": {"v", "x", "Fn"}, "output": {"F", "z", "sliding", "P_diss", "E_stored"},
              "parameter": {"sigma0", "sigma1", "sigma2", "Fc", "Fs", "vs", "stribeck_exponent", "vd",
                            "direction_dependent", "Fc_neg", "Fs_neg", "normal_force_form",
                            "position_dependent", "n_table", "direction_dependent_viscous", "sigma2_neg",
                            "F_offset"}},
    "ResetIntegrator": {"input": {"v"}, "output": {"F", "z", "sliding", "P_diss", "E_stored"},
                        "parameter": {"sigma0", "sigma1", "a", "z0"}},
    "Bristle": {"input": {"x"}, "output": {"F", "n_connected", "sliding", "P_diss", "E_stored"},
                "parameter": {"sigma_ini", "delta_max", "x_rel", "n_bristles", "c", "mu_c", "Fn", "seed"}},
    "Bristle2D": {"input": {"v1", "v2"}, "output": {"F1", "F2", "z1", "z2", "sliding", "P_diss", "E_stored"},
                  "parameter": {"sigma01", "sigma02", "sigma11", "sigma12", "a1", "a2", "z0", "av"}},
    "Classical": {"input": {"v", "F_app"}, "output": {"F", "stuck", "P_diss", "E_stored"},
                  "parameter": {"Fc", "Fs", "vs", "delta", "sigma2", "dv"}},
    "BlimanSorine": {"input": {"v"}, "output": {"F", "sliding", "P_diss", "E_stored"},
                     "parameter": {"f1", "f2", "eps_f", "eta", "from_reference_points", "Fs_ref", "Fc_ref",
                                   "x_e", "x_p"},
                     "local": {"x1", "x2", "der(x1)", "der(x2)"}},
    "ElastoPlastic": {"input": {"v"}, "output": {"F", "z", "elastic", "P_diss", "E_stored"},
                      "parameter": {"sigma0", "sigma1", "sigma2", "Fc", "Fs", "vs", "stribeck_exponent", "z_ba"}},
    "MaxwellSlip": {"input": {"v"}, "output": {"F", "P_diss", "E_stored", "n_slipping"},
                    "parameter": {"sigma2", "n_elements"} | {f"k[{i}]" for i in range(1, 101)}
                    | {f"W[{i}]" for i in range(1, 101)}},
    "GMS": {"input": {"v"}, "output": {"F", "P_diss", "E_stored", "n_slipping"},
            "parameter": {"sigma1", "sigma2", "n_elements", "Fc", "Fs", "vs", "stribeck_exponent", "C"}
            | {f"k[{i}]" for i in range(1, 101)} | {f"alpha[{i}]" for i in range(1, 101)}},
    "Rig1D": {"input": {"F", "F_ext", "x_act_in", "x_ref", "v_ref"},
              "output": {"x", "v", "a", "F_spring", "x_act", "x_rel", "v_body", "F_drive", "u_ctrl", "F_ctrl",
                         "F_app"},
              "parameter": {"m", "c", "k", "x_a0", "v_a", "v_surface", "x0", "v0", "actuator", "act_amp",
                            "act_freq", "dither_amp", "dither_freq", "F_step", "t_step", "drive_amp",
                            "drive_freq", "control", "ref_x0", "ref_v0", "ref_v_amp", "ref_freq", "ctrl_kp",
                            "ctrl_kd", "ctrl_ki", "ctrl_ff", "ctrl_gain", "ctrl_u_max"}},
    "Rig2D": {"input": {"F1", "F2", "F_ext1", "F_ext2"},
              "output": {"v1", "v2", "x1", "x2", "x1_rel", "x2_rel", "a1", "a2"},
              "parameter": {"m", "k1", "k2", "c1", "c2", "x1_0", "x2_0", "v1_0", "v2_0", "vs1", "vs2",
                            "dither_amp1", "dither_freq1", "dither_amp2", "dither_freq2"}},
}


def test_the_tables_cover_every_shipped_fmu():
    shipped.covers(EXPECTED, shipped.SHIPPED, "EXPECTED")
    shipped.covers(MODEL_EXCHANGE_STATES, shipped.MODEL_EXCHANGE, "MODEL_EXCHANGE_STATES")


@pytest.mark.parametrize("name", MODELS + RIGS)
def test_validate_fmu_reports_no_problems(name):
    assert validate_fmu(str(fmu_path(name))) == []


@pytest.mark.parametrize("name", MODELS + RIGS)
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
    # Model Exchange beside Co-Simulation, same binary, for the laws that
    # are ODEs (issue 22) and the classical law (events only); the bristle
    # law and the rigs are Co-Simulation only
    me = md.modelExchange
    if name in shipped.MODEL_EXCHANGE:
        states, indicators = MODEL_EXCHANGE_STATES[name]
        assert me is not None and me.modelIdentifier == name
        assert me.canGetAndSetFMUstate and me.canSerializeFMUstate and me.providesDirectionalDerivative
        assert [d.variable.derivative.name for d in md.derivatives] == states
        assert [d.variable.name for d in md.derivatives] == [f"der({s})" for s in states]
        assert md.numberOfContinuousStates == len(states)
        assert md.numberOfEventIndicators == indicators
    else:
        assert me is None and md.numberOfEventIndicators == 0
        # Rig1D lists its states for Co-Simulation (for a linearization;
        # tests/test_rig1d_states.py), the others none
        listed = [d.variable.derivative.name for d in md.derivatives]
        assert listed == (["x", "v_body"] if name == "Rig1D" else []), listed
    for v in md.modelVariables:
        if v.type == "Real" and v.causality in ("input", "output", "parameter") and v.name not in (
                "alpha", "a", "a1", "a2", "stribeck_exponent", "mu_c", "ctrl_ff", "delta", "eta") and not v.name.startswith(("scale_", "alpha[")):
            assert v.unit, f"{name}.{v.name} has no unit"
