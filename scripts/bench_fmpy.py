#!/usr/bin/env python3
"""FMPy's side of BENCHMARKS.md's speed table: the same co-simulation as
`fricsim run`, driven from Python by FMPy's low-level FMU2Slave API.

The system comes as JSON on stdin (written by the `speed-table` program,
host/src/bin/speed_table.rs, from the same system file it runs itself):

    {"components": [{"name": "rig", "fmu": "dist/Rig1D.fmu",
                     "parameters": {"m": 1.0, ...}}, ...],
     "connections": [["rig", "v", "friction", "v"], ...],
     "step": 1e-4, "stop": 20.0, "master": "jacobi" | "newton",
     "rtol": 1e-8, "atol": [1e-13, 1e-10]}   (newton: atol per connection)

Every component's Real outputs are recorded at every communication point,
as the host does. Prints one JSON object: the wall time of initialization
and stepping (s), the number of steps, the final value of every recorded
output, and, for newton, the iteration and Jacobian counts.

Masters, as host/src/master/ implements them:

- jacobi: at each communication point every connected output is read,
  then every input set, then every FMU stepped over [t, t + h].
- newton: strong coupling. The unknowns are the connected inputs U, held
  over the step; stepping every FMU from its state at t gives the outputs
  Y(U); Newton solves R(U) = U − Y(U) = 0 with J = ∂Y/∂U from
  fmi2GetDirectionalDerivative after the step, (I − J)·ΔU = −R, rolling the
  FMUs back with fmi2SetFMUstate between iterations, until
  |R_k| ≤ atol_k + rtol·max(|U_k|, |Y_k|) (the host's rtol 1e-8 and
  atol 1e-10 times the input's nominal, given in the spec).
"""

import json
import shutil
import sys
import tempfile
import time

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

MAX_ITERATIONS = 50


class Component:
    """One FMU instance with its variables by name."""

    def __init__(self, spec, workdir):
        self.name = spec["name"]
        md = read_model_description(spec["fmu"])
        self.variables = {v.name: v for v in md.modelVariables}
        unzipped = extract(spec["fmu"], unzipdir=f"{workdir}/{self.name}")
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                             modelIdentifier=md.coSimulation.modelIdentifier,
                             instanceName=self.name)
        self.parameters = spec["parameters"]
        self.outputs = [v.valueReference for v in md.modelVariables
                        if v.causality == "output" and v.type == "Real"]
        self.output_names = [v.name for v in md.modelVariables
                             if v.causality == "output" and v.type == "Real"]

    def vr(self, name):
        return self.variables[name].valueReference

    def set_parameters(self):
        for name, value in self.parameters.items():
            v = self.variables[name]
            if v.type == "Real":
                self.fmu.setReal([v.valueReference], [value])
            elif v.type in ("Integer", "Enumeration"):
                self.fmu.setInteger([v.valueReference], [int(value)])
            elif v.type == "Boolean":
                self.fmu.setBoolean([v.valueReference], [value != 0])
            else:
                self.fmu.setString([v.valueReference], [str(value)])


def run(spec):
    workdir = tempfile.mkdtemp(prefix="bench_fmpy_")
    try:
        components = [Component(c, workdir) for c in spec["components"]]
        by_name = {c.name: c for c in components}
        # (output component, output vr, input component, input vr)
        links = [(by_name[a], by_name[a].vr(x), by_name[b], by_name[b].vr(y))
                 for a, x, b, y in spec["connections"]]
        h, stop, master = spec["step"], spec["stop"], spec["master"]
        n = int(round(stop / h))

        started = time.perf_counter()
        for c in components:
            c.fmu.instantiate()
            c.fmu.setupExperiment(startTime=0.0)
            c.fmu.enterInitializationMode()
            c.set_parameters()

        def propagate():
            values = [src.fmu.getReal([out])[0] for src, out, _, _ in links]
            for (_, _, dst, inp), value in zip(links, values):
                dst.fmu.setReal([inp], [value])

        propagate()
        for c in components:
            c.fmu.exitInitializationMode()
        propagate()
        rows = [[x for c in components for x in c.fmu.getReal(c.outputs)]]
        counts = {"iterations": 0, "jacobians": 0}
        # newton's interface values: the inputs as the FMUs hold them now
        u = np.array([src.fmu.getReal([out])[0] for src, out, _, _ in links])
        for i in range(n):
            t = i * h
            if master == "jacobi":
                propagate()
                for c in components:
                    c.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            elif master == "newton":
                u = newton_step(components, links, u, t, h, counts,
                                spec["rtol"], np.array(spec["atol"]))
            else:
                raise SystemExit(f"unknown master {master}")
            rows.append([x for c in components for x in c.fmu.getReal(c.outputs)])
        wall = time.perf_counter() - started

        final = {f"{c.name}.{name}": value
                 for c, names in ((c, c.output_names) for c in components)
                 for name, value in zip(names, c.fmu.getReal(c.outputs))}
        for c in components:
            c.fmu.terminate()
            c.fmu.freeInstance()
        return {"wall": wall, "steps": n, "rows": len(rows), "final": final, **counts}
    finally:
        shutil.rmtree(workdir, ignore_errors=True)


def newton_step(components, links, u, t, h, counts, rtol, atol):
    """One strongly coupled macro step from the interface values `u`."""
    states = [c.fmu.getFMUstate() for c in components]
    for iteration in range(1, MAX_ITERATIONS + 1):
        if iteration > 1:
            for c, s in zip(components, states):
                c.fmu.setFMUstate(s)
        for k, (_, _, dst, inp) in enumerate(links):
            dst.fmu.setReal([inp], [u[k]])
        for c in components:
            c.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        y = np.array([src.fmu.getReal([out])[0] for src, out, _, _ in links])
        tolerance = atol + rtol * np.maximum(np.abs(u), np.abs(y))
        if np.all(np.abs(u - y) <= tolerance):
            counts["iterations"] += iteration
            for c, s in zip(components, states):
                c.fmu.freeFMUstate(s)
            return u
        # J[k, j] = ∂Y_k/∂U_j, from the component that owns output k and input j
        jac = np.zeros((len(links), len(links)))
        for j, (_, _, dst, inp) in enumerate(links):
            for k, (src, out, _, _) in enumerate(links):
                if src is dst:
                    jac[k, j] = dst.fmu.getDirectionalDerivative([out], [inp], [1.0])[0]
        counts["jacobians"] += 1
        u = u + np.linalg.solve(np.eye(len(links)) - jac, y - u)
    raise SystemExit(f"newton did not converge at t = {t}")


if __name__ == "__main__":
    json.dump(run(json.load(sys.stdin)), sys.stdout)
    print()
