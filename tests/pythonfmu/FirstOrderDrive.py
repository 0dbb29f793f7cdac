"""A velocity drive with first-order lag and load droop, exported with
pythonfmu (pinned in tests/requirements.txt) by tests/test_foreign_fmu.py:

    tau * dv/dt = v_cmd(t) - F/b - v,    v_cmd(t) = v_amp * sin(2*pi*f*t)

F (the friction force on the driven contact) and v_cmd are held over a
communication step, which is solved exactly: v relaxes exponentially to
v_cmd - F/b. Connected to a friction FMU through v -> friction.v and
friction.F -> F it sweeps the contact back and forth."""

import math

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class FirstOrderDrive(Fmi2Slave):

    author = "friction-fmu tests"
    description = "Velocity drive with first-order lag and load droop (pythonfmu)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.tau = 0.02
        self.b = 1000.0
        self.v_amp = 0.01
        self.f = 2.0
        self.F = 0.0
        self.v = 0.0
        self.v_cmd = 0.0
        for name in ("tau", "b", "v_amp", "f"):
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed))
        self.register_variable(Real("F", causality=Fmi2Causality.input))
        self.register_variable(Real("v", causality=Fmi2Causality.output))
        self.register_variable(Real("v_cmd", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        self.v_cmd = self.v_amp * math.sin(2.0 * math.pi * self.f * current_time)
        target = self.v_cmd - self.F / self.b
        self.v = target + (self.v - target) * math.exp(-step_size / self.tau)
        return True
