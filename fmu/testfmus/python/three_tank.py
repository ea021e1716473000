"""Test FMU three_tank: a third-party exporter's FMU (pythonfmu, FMI 2.0 CS) of a
nonlinear plant in absolute units, at a non-zero operating point.

Three tanks in series (the DTS200 arrangement): pump 1 fills tank 1, pump 2 fills tank 2,
water flows 1 -> 3 -> 2 -> out through Torricelli valves, and an unknown leak drains tank 2:

    A dh1/dt = Q1 - q13,    A dh3/dt = q13 - q32,    A dh2/dt = Q2 + q32 - q20 - leak,
    q_ij = az sn sign(h_i - h_j) sqrt(2 g |h_i - h_j|),    q20 = az sn sqrt(2 g h2).

Levels h in m, flows in m3/s. With the defaults (A = 0.0154 m2, sn = 5e-5 m2, az = 0.5) the
levels h = (0.4, 0.2, 0.3) m are an equilibrium at Q1 = 3.5028e-5, Q2 = 1.4508e-5 m3/s and no
leak. The states h1, h2, h3 (initial exact) take start values; the outputs y1..y3 measure
them. One doStep integrates with `substeps` RK4 steps (numpy arrays: the FMU's embedded Python
must import what its host's python3 imports). From t >= `fail_at` doStep raises, for the tests
of a failing FMU's log.
"""

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Real


class three_tank(Fmi2Slave):
    author = "uio-observers tests"
    description = "Three tanks in series (absolute levels in m, flows in m3/s), an unknown leak from tank 2"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.area, self.sn, self.az, self.g = 0.0154, 5e-5, 0.5, 9.81
        self.substeps, self.fail_at = 20.0, 1e300
        self.Q1 = self.Q2 = self.leak = 0.0
        self.h1, self.h2, self.h3 = 0.4, 0.2, 0.3
        self.y1, self.y2, self.y3 = self.h1, self.h2, self.h3
        fixed = dict(causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed)
        for p in ("area", "sn", "az", "g", "substeps", "fail_at"):
            self.register_variable(Real(p, **fixed))
        for u in ("Q1", "Q2", "leak"):
            self.register_variable(Real(u, causality=Fmi2Causality.input))
        for h in ("h1", "h2", "h3"):
            self.register_variable(Real(h, causality=Fmi2Causality.local, variability=Fmi2Variability.continuous,
                                        initial=Fmi2Initial.exact))
        for y in ("y1", "y2", "y3"):
            self.register_variable(Real(y, causality=Fmi2Causality.output))

    def exit_initialization_mode(self):
        self.y1, self.y2, self.y3 = self.h1, self.h2, self.h3
        return True

    def f(self, h):
        c = self.az * self.sn * np.sqrt(2 * self.g)
        q13 = c * np.sign(h[0] - h[2]) * np.sqrt(abs(h[0] - h[2]))
        q32 = c * np.sign(h[2] - h[1]) * np.sqrt(abs(h[2] - h[1]))
        q20 = c * np.sqrt(max(h[1], 0.0))
        return np.array([self.Q1 - q13, self.Q2 + q32 - q20 - self.leak, q13 - q32]) / self.area

    def do_step(self, current_time, step_size):
        if current_time >= self.fail_at:
            raise ValueError(f"three_tank: the leak sensor broke at t = {current_time} (fail_at)")
        n = int(self.substeps)
        h = step_size / n
        x = np.array([self.h1, self.h2, self.h3])
        for _ in range(n):
            k1 = self.f(x)
            k2 = self.f(x + h / 2 * k1)
            k3 = self.f(x + h / 2 * k2)
            k4 = self.f(x + h * k3)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        self.h1, self.h2, self.h3 = (float(v) for v in x)
        self.y1, self.y2, self.y3 = self.h1, self.h2, self.h3
        return True
