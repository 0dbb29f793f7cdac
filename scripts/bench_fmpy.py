#!/usr/bin/env python3
"""FMPy's side of BENCHMARKS.md's speed table: the same co-simulation as
`fricsim run`, driven from Python by FMPy's low-level FMU2Slave API.

The system comes as JSON on stdin (written by the `speed-table` program,
bench/src/bin/speed_table.rs, from the same system file it runs itself):

    {"components": [{"name": "rig", "fmu": "dist/Rig1D.fmu",
                     "parameters": {"m": 1.0, ...}}, ...],
     "connections": [["rig", "v", "friction", "v"], ...],
     "step": 1e-4, "stop": 20.0, "master": "jacobi" | "newton",
     "rtol": 1e-8, "atol": [1e-13, 1e-10]}   (newton: atol per connection)

Every component's outputs are recorded at every communication point, as
the host does: its Real outputs in one fmi2GetReal, then its Integer
outputs in one fmi2GetInteger and its Boolean outputs in one
fmi2GetBoolean (where it has any), as whole numbers. Prints one JSON object: the wall time of initialization
and stepping (s; the instances are made and their parameters set before
the clock starts, as the host builds its system before its own), the
number of steps, the final value of every recorded output, and, for
newton, the iteration and Jacobian counts.

Masters, as host/core/src/master/ implements them, with the same FMI calls in
the same order as the host makes them, so that the comparison is of the
two callers, not of two call sequences:

- jacobi: at each communication point, component by component in the
  system's order, the component's connected inputs are set in one
  fmi2SetReal from the outputs recorded there (no output is read twice),
  then it is stepped over [t, t + h].
- newton: strong coupling. The unknowns are the connected inputs U, held
  over the step; stepping every FMU from its state at t gives the outputs
  Y(U); Newton solves R(U) = U − Y(U) = 0 with J = ∂Y/∂U from
  fmi2GetDirectionalDerivative after the step, (I − J)·ΔU = −R, rolling the
  FMUs back with fmi2SetFMUstate between iterations, until
  |R_k| ≤ atol_k + rtol·max(|U_k|, |Y_k|) (the host's rtol 1e-8 and
  atol 1e-10 times the input's nominal, given in the spec). As the host:
  the state at t is saved with fmi2GetFMUstate into the same FMU state
  every step (FMI 2.0 updates a state passed in), and the first iteration
  of a step sets no input, the FMUs holding the last accepted U already.
  The arithmetic of a step is on Python floats (a few numbers: NumPy's
  per-call cost would be most of it), the linear solve with NumPy.
"""

import json
import shutil
import sys
import tempfile
import time
from ctypes import byref

import numpy as np
from fmpy.fmi2 import fmi2FMUstate
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
        # Integer (and Enumeration) and Boolean outputs, read after the
        # Real ones as the host reads them
        self.integers = [v.valueReference for v in md.modelVariables
                         if v.causality == "output" and v.type in ("Integer", "Enumeration")]
        self.booleans = [v.valueReference for v in md.modelVariables
                         if v.causality == "output" and v.type == "Boolean"]

    def record(self):
        """This component's part of a recorded row."""
        row = self.fmu.getReal(self.outputs)
        if self.integers:
            row += [float(i) for i in self.fmu.getInteger(self.integers)]
        if self.booleans:
            row += [float(b) for b in self.fmu.getBoolean(self.booleans)]
        return row

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

        # as the host's system is built (instantiated, parameters set)
        # before its clock starts
        for c in components:
            c.fmu.instantiate()
            c.fmu.setupExperiment(startTime=0.0)
            c.fmu.enterInitializationMode()
            c.set_parameters()
        started = time.perf_counter()

        # per component, in the system's order: its connected inputs and
        # the links that feed them (one fmi2SetReal per component, as the
        # host sets them)
        feeds = [(c, [inp for _, _, dst, inp in links if dst is c],
                  [k for k, (_, _, dst, _) in enumerate(links) if dst is c])
                 for c in components]

        def propagate():
            values = [src.fmu.getReal([out])[0] for src, out, _, _ in links]
            for c, inputs, ks in feeds:
                if inputs:
                    c.fmu.setReal(inputs, [values[k] for k in ks])

        propagate()
        for c in components:
            c.fmu.exitInitializationMode()
        propagate()
        rows = [[x for c in components for x in c.record()]]
        # where each link's output is in a recorded row
        first, k = {}, 0
        for c in components:
            first[c.name] = k
            k += len(c.outputs) + len(c.integers) + len(c.booleans)
        columns = [first[src.name] + src.outputs.index(out) for src, out, _, _ in links]
        # per component: its inputs and the recorded columns they take
        steps = [(c, inputs, [columns[k] for k in ks]) for c, inputs, ks in feeds]
        counts = {"iterations": 0, "jacobians": 0}
        newton = None
        if master == "newton":
            newton = Newton(components, links, spec["rtol"], spec["atol"], counts)
        elif master != "jacobi":
            raise SystemExit(f"unknown master {master}")
        for i in range(n):
            t = i * h
            if newton is None:
                row = rows[-1]
                for c, inputs, cols in steps:
                    if inputs:
                        c.fmu.setReal(inputs, [row[k] for k in cols])
                    c.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            else:
                newton.step(t, h)
            rows.append([x for c in components for x in c.record()])
        wall = time.perf_counter() - started
        if newton is not None:
            newton.free()

        final = {f"{c.name}.{name}": value
                 for c, names in ((c, c.output_names) for c in components)
                 for name, value in zip(names, c.fmu.getReal(c.outputs))}
        for c in components:
            c.fmu.terminate()
            c.fmu.freeInstance()
        return {"wall": wall, "steps": n, "rows": len(rows), "final": final, **counts}
    finally:
        shutil.rmtree(workdir, ignore_errors=True)


class Newton:
    """Strong coupling: one FMU state per component, updated in place."""

    def __init__(self, components, links, rtol, atol, counts):
        self.components, self.links = components, links
        self.rtol, self.atol, self.counts = rtol, atol, counts
        self.states = [fmi2FMUstate() for _ in components]
        # the interface values: the connected outputs as the FMUs give them
        # now (the inputs do not hold them yet)
        self.u = [src.fmu.getReal([out])[0] for src, out, _, _ in links]
        self.holds_u = False

    def free(self):
        for c, s in zip(self.components, self.states):
            c.fmu.freeFMUstate(s)

    def step(self, t, h):
        """One strongly coupled macro step from the interface values."""
        components, links, u = self.components, self.links, self.u
        n = len(links)
        for c, s in zip(components, self.states):
            c.fmu.fmi2GetFMUstate(c.fmu.component, byref(s))
        for iteration in range(1, MAX_ITERATIONS + 1):
            if iteration > 1:
                for c, s in zip(components, self.states):
                    c.fmu.setFMUstate(s)
            if iteration > 1 or not self.holds_u:
                for k, (_, _, dst, inp) in enumerate(links):
                    dst.fmu.setReal([inp], [u[k]])
            for c in components:
                c.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            y = [src.fmu.getReal([out])[0] for src, out, _, _ in links]
            if all(abs(uk - yk) <= a + self.rtol * max(abs(uk), abs(yk))
                   for uk, yk, a in zip(u, y, self.atol)):
                self.counts["iterations"] += iteration
                self.u, self.holds_u = u, True
                return
            # J[k, j] = ∂Y_k/∂U_j, from the component that owns output k and input j
            jac = np.zeros((n, n))
            for j, (_, _, dst, inp) in enumerate(links):
                for k, (src, out, _, _) in enumerate(links):
                    if src is dst:
                        jac[k, j] = dst.fmu.getDirectionalDerivative([out], [inp], [1.0])[0]
            self.counts["jacobians"] += 1
            du = np.linalg.solve(np.eye(n) - jac, [yk - uk for uk, yk in zip(u, y)])
            u = [uk + d for uk, d in zip(u, du.tolist())]
        raise SystemExit(f"newton did not converge at t = {t}")


if __name__ == "__main__":
    json.dump(run(json.load(sys.stdin)), sys.stdout)
    print()
