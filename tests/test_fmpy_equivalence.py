"""FMPy's `simulate_fmu` (the FMU through the C ABI, loaded by the reference
importer) equals an in-process Rust run of the same law to 1e-12 relative
(issue 2). The in-process run gets exactly the inputs FMPy applied, computed
with FMPy's own interpolation routine."""

import numpy as np
import pytest
from fmpy import simulate_fmu

import shipped
from conftest import applied_inputs, fmu_path, run_in_process

STOP = 2.0
STEP = 1e-3
T_SIGNAL = np.linspace(0.0, STOP, 401)


def signal(**columns):
    names = ["time"] + list(columns)
    data = [T_SIGNAL] + [np.asarray(c, dtype=float) for c in columns.values()]
    return np.rec.fromarrays(data, names=names)


w = 2 * np.pi
CASES = {
    # Sun et al. 2016's velocity trial: v = 1e-3*sin(t/k) style, here one cycle a second
    "Dahl": (signal(v=5e-3 * np.sin(w * T_SIGNAL)), {"alpha": 1.5}),
    # LuGre with every extension on: direction- and position-dependent levels
    "LuGre": (signal(v=2e-3 * np.sin(w * T_SIGNAL), x=0.3 + 0.2 * np.sin(0.5 * w * T_SIGNAL),
                     Fn=1.0 + 0.5 * np.cos(w * T_SIGNAL)),
              {"direction_dependent": True, "Fc_neg": 0.8, "Fs_neg": 1.2, "position_dependent": True,
               "n_table": 4, "x_table[1]": 0.0, "x_table[2]": 0.25, "x_table[3]": 0.5, "x_table[4]": 1.0,
               "scale_pos[1]": 1.0, "scale_pos[2]": 1.2, "scale_pos[3]": 0.9, "scale_pos[4]": 1.1,
               "scale_neg[1]": 0.9, "scale_neg[2]": 1.0, "scale_neg[3]": 1.3, "scale_neg[4]": 1.0,
               "vd": 5e-3}),
    "ResetIntegrator": (signal(v=1e-3 * np.sin(w * T_SIGNAL)), {}),
    # bristle: +-5e-8 m, beyond the 2*delta_max pre-sliding range, with reversals
    "Bristle": (signal(x=5e-8 * np.sin(w * T_SIGNAL)), {"seed": 7}),
    "Bristle2D": (signal(v1=1e-3 * np.cos(w * T_SIGNAL), v2=5e-4 * np.sin(w * T_SIGNAL)), {}),
    # through the zero-velocity band twice a cycle, the applied force above Fs in part
    "Classical": (signal(v=2e-3 * np.sin(w * T_SIGNAL), F_app=3.0 * np.cos(1.5 * w * T_SIGNAL)), {}),
    # Sun et al. 2016's Bliman-Sorine trials: sinusoidal velocity, here one cycle a second
    "BlimanSorine": (signal(v=5e-3 * np.sin(w * T_SIGNAL)), {}),
    # through the elastic, transition and plastic zones, with reversals
    "ElastoPlastic": (signal(v=2e-3 * np.sin(w * T_SIGNAL)), {}),
    # pre-sliding loops and gross sliding, reversals every half cycle
    "MaxwellSlip": (signal(v=2e-4 * np.sin(w * T_SIGNAL)), {}),
    "GMS": (signal(v=2e-3 * np.sin(w * T_SIGNAL)), {"n_elements": 4, "alpha[1]": 0.1, "alpha[2]": 0.2,
                                                    "alpha[3]": 0.3, "alpha[4]": 0.4}),
}
# outputs that are zero by definition (documented in the model description)
ZERO_BY_DEFINITION = {("Classical", "E_stored")}


def fmu2slave_interpolated(name, sig, parameters, tmp_path):
    """FMPy's FMU2Slave driven by a loop like simulate_fmu's, but setting the
    input slopes with fmi2SetRealInputDerivatives. (simulate_fmu's own
    set_input_derivatives=True is unusable in FMPy 0.3.32: it allocates a
    derivative buffer of exactly 9 entries, so any other number of inputs
    fails.)"""
    from ctypes import c_int, c_uint32, c_double
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.simulation import apply_start_values, Input

    md = read_model_description(str(fmu_path(name)))
    vr = {v.name: v for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu_path(name)), unzipdir=str(tmp_path / "x")),
                    modelIdentifier=name, instanceName="interp")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    apply_start_values(fmu, md, dict(parameters))
    fmu.enterInitializationMode()
    names = sig.dtype.names[1:]
    table = np.array([sig[n] for n in names])
    vrs = (c_uint32 * len(names))(*[vr[n].valueReference for n in names])
    order = (c_int * len(names))(*([1] * len(names)))
    outputs = [v for v in md.modelVariables if v.causality == "output"]

    def apply(t, derivatives):
        v, d = Input.interpolate(time=t, t=sig["time"], table=table, discrete=False, after_event=True)
        fmu.setReal(list(vrs), [float(x) for x in v])
        if derivatives:
            fmu.fmi2SetRealInputDerivatives(fmu.component, vrs, len(names), order,
                                            (c_double * len(names))(*[float(x) for x in d]))

    def sample(t):
        row = [t]
        for v in outputs:
            get = {"Real": fmu.getReal, "Integer": fmu.getInteger, "Boolean": fmu.getBoolean}[v.type]
            row.append(float(get([v.valueReference])[0]))
        return row

    apply(0.0, False)
    fmu.exitInitializationMode()
    rows = [sample(0.0)]
    n_steps = round(STOP / STEP)
    for n in range(n_steps):
        t = 0.0 + n * STEP
        t_next = 0.0 + (n + 1) * STEP
        apply(t, True)
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=t_next - t)
        rows.append(sample(t_next))
    fmu.terminate()
    fmu.freeInstance()
    return np.rec.fromrecords(rows, names=["time"] + [v.name for v in outputs])


@pytest.mark.parametrize("set_input_derivatives", [False, True], ids=["held", "interpolated"])
@pytest.mark.parametrize("name", list(CASES))
def test_fmpy_equals_in_process_run(name, set_input_derivatives, tmp_path):
    sig, parameters = CASES[name]
    if set_input_derivatives:
        result = fmu2slave_interpolated(name, sig, parameters, tmp_path)
    else:
        result = simulate_fmu(str(fmu_path(name)), fmi_type="CoSimulation", start_time=0.0, stop_time=STOP,
                              output_interval=STEP, input=sig, start_values=parameters)
    times = [float(t) for t in result["time"]]
    # FMPy's communication points are start + n*step; check that assumption
    assert times == [0.0 + n * STEP for n in range(len(times))]
    columns, slopes = applied_inputs(sig, times, set_input_derivatives)
    reference = run_in_process(name, times, columns, slopes, parameters, tmp_path)
    assert len(reference) == len(result)
    for output in reference.dtype.names[1:]:
        ours = reference[output]
        fmpy_ = result[output].astype(float)
        scale = max(np.max(np.abs(ours)), 1e-300)
        err = np.max(np.abs(ours - fmpy_)) / scale
        assert err <= 1e-12, f"{name}.{output}: relative difference {err:.3e}"
        # the run must exercise the law, not sit at zero
        if (name, output) in ZERO_BY_DEFINITION:
            assert np.max(np.abs(ours)) == 0, f"{name}.{output} is not zero"
        else:
            assert np.max(np.abs(ours)) > 0, f"{name}.{output} is identically zero"


def test_interpolated_inputs_change_the_result():
    """Guard for the test above: with slopes the run differs from held
    inputs (so the derivative path is really exercised)."""
    sig, parameters = CASES["LuGre"]
    times = [n * STEP for n in range(round(STOP / STEP) + 1)]
    held, _ = applied_inputs(sig, times, False)
    _, slopes = applied_inputs(sig, times, True)
    assert max(abs(s) for s in slopes["v"]) > 0


def test_every_shipped_law_has_a_case():
    shipped.covers(CASES, shipped.LAWS, "CASES")
