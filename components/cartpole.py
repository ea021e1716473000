#!/usr/bin/env python3
"""A pendulum on a cart, nonlinear, as the true plant of a run (PROTOCOL.md §7, `[plant.process]`).

State x = [s, ṡ, θ, θ̇]: cart position (m), cart velocity (m/s), pendulum angle from upright
(rad, positive when the pendulum leans towards +s) and its rate (rad/s). The known input u is
the motor force on the cart (N), the unknown input w a horizontal force on the cart (N), e.g.
a push or a slope. Parameters (`params`): `cart_mass` M (kg), `pole_mass` m (kg, a point mass
at the end of a massless rod), `length` l (m, pivot to mass), `gravity` g (m/s²), `substeps`
(RK4 steps per sample period, default 4).

Equations of motion
-------------------
The mass sits at (s + l sin θ, l cos θ). With T = ½(M + m)ṡ² + m l cos θ ṡ θ̇ + ½ m l² θ̇²,
V = m g l cos θ and the force F = u + w on the cart, Lagrange's equations are

    (M + m) s̈ + m l cos θ θ̈ − m l sin θ θ̇² = F
    cos θ s̈ + l θ̈ − g sin θ = 0

and solved for the accelerations (Δ = M + m sin²θ):

    s̈ = (F + m l θ̇² sin θ − m g sin θ cos θ) / Δ
    θ̈ = ((M + m) g sin θ − cos θ (F + m l θ̇² sin θ)) / (l Δ)

Linearisation about the upright equilibrium (x = 0, F = 0)
----------------------------------------------------------
With sin θ ≈ θ, cos θ ≈ 1 and the products θ̇² θ, θ² dropped, Δ ≈ M and

    s̈ ≈ (F − m g θ) / M,        θ̈ ≈ ((M + m) g θ − F) / (M l),

so ẋ = A x + B u + E w with

    A = [[0, 1, 0,               0],      B = E = [[0        ],
         [0, 0, −m g / M,        0],               [1 / M    ],
         [0, 0, 0,               1],               [0        ],
         [0, 0, (M + m) g/(M l), 0]]               [−1/(M l) ]]

(E = B: the unknown force acts where the motor does). With M = 1, m = 0.1, l = 0.5, g = 9.81
(the shipped scenarios): A₂₃ = −0.981, A₄₃ = 21.582, B = E = [0, 1, 0, −2]ᵀ; the open loop has
the eigenvalues 0, 0, ±√21.582 = ±4.6457. `linearisation()` gives these matrices and
python/tests/test_cartpole.py checks them against finite differences of `dynamics()` and
against the scenarios' `[plant]` tables.

Outputs
-------
y = C x + D v with the scenario's C and D: the shipped scenarios measure y = [s, θ, θ̇] (cart
encoder, angle encoder, gyro). Position and angle alone would not do for a UIO: their CE = 0,
and rank CE = rank E is the decoupling condition; with θ̇ measured CE = [0, 0, −1/(M l)]ᵀ, and
(A, E, C) has no invariant zeros (the θ channel of w has none), so all four poles are free.

Sampling
--------
Over each step [t_k, t_{k+1}) the plant holds u_k (the controller's sample k; the [[input]]
signals r(t_k) without a controller) and w(t_k), and integrates the nonlinear equations with
`substeps` fixed RK4 steps. It publishes sample k of PROTOCOL.md §4:
[x_k | y_k | w(t_k) | v(t_k) | r(t_k) | u_{k−1}], the signals generated here from the
configuration's `signals`, as the built-in plant samples them.
"""

from __future__ import annotations

import math
import os
import sys

import numpy as np

try:
    import uio_component
except ImportError:  # run from a checkout without `pip install ./python`
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
    import uio_component

from uio_component import Diverged, Signals


def dynamics(x, force, M, m, l, g):
    """ẋ = f(x, F) of the cart-pole, F the total horizontal force on the cart."""
    _, sd, th, thd = x
    st, ct = math.sin(th), math.cos(th)
    delta = M + m * st * st
    push = force + m * l * thd * thd * st
    sdd = (push - m * g * st * ct) / delta
    thdd = ((M + m) * g * st - ct * push) / (l * delta)
    return (sd, sdd, thd, thdd)


def rk4(x, force, h, substeps, M, m, l, g):
    """x after `substeps` classic RK4 steps of h, the force held."""
    s0, s1, s2, s3 = x
    for _ in range(substeps):
        k1 = dynamics((s0, s1, s2, s3), force, M, m, l, g)
        k2 = dynamics((s0 + 0.5 * h * k1[0], s1 + 0.5 * h * k1[1], s2 + 0.5 * h * k1[2], s3 + 0.5 * h * k1[3]), force, M, m, l, g)
        k3 = dynamics((s0 + 0.5 * h * k2[0], s1 + 0.5 * h * k2[1], s2 + 0.5 * h * k2[2], s3 + 0.5 * h * k2[3]), force, M, m, l, g)
        k4 = dynamics((s0 + h * k3[0], s1 + h * k3[1], s2 + h * k3[2], s3 + h * k3[3]), force, M, m, l, g)
        s0 += h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0])
        s1 += h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1])
        s2 += h / 6.0 * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2])
        s3 += h / 6.0 * (k1[3] + 2.0 * k2[3] + 2.0 * k3[3] + k4[3])
    return (s0, s1, s2, s3)


def linearisation(M, m, l, g):
    """(A, B, E) of the linearisation about the upright equilibrium (module docstring)."""
    A = np.array([[0.0, 1.0, 0.0, 0.0],
                  [0.0, 0.0, -m * g / M, 0.0],
                  [0.0, 0.0, 0.0, 1.0],
                  [0.0, 0.0, (M + m) * g / (M * l), 0.0]])
    B = np.array([[0.0], [1.0 / M], [0.0], [-1.0 / (M * l)]])
    return A, B, B.copy()


def parameters(params):
    """(M, m, l, g) from `params`, checked."""
    M = float(params.get("cart_mass", 1.0))
    m = float(params.get("pole_mass", 0.1))
    l = float(params.get("length", 0.5))
    g = float(params.get("gravity", 9.81))
    if not (M > 0 and m >= 0 and l > 0 and math.isfinite(g)):
        raise ValueError("cart_mass and length must be > 0, pole_mass ≥ 0, gravity finite")
    return M, m, l, g


def setup(config):
    """Checks the scenario's sizes and prepares the state of the simulation."""
    model = config.model
    if model is None or model.n != 4 or model.l != 1 or model.q != 1:
        raise ValueError("the cart-pole has 4 states, 1 known input (the motor force) and 1 unknown input "
                         "(a force on the cart): [plant] needs A 4×4, B 4×1, E 4×1")
    if config.publishes.len != model.plant_len():
        raise ValueError(f"publishes.len is {config.publishes.len}, the plant sample holds {model.plant_len()}")
    params = config.params or {}
    M, m, l, g = parameters(params)
    substeps = int(params.get("substeps", 4))
    if substeps < 1:
        raise ValueError("substeps must be ≥ 1")
    signals = Signals(config.signals, config.dt)
    if len(signals.disturbances) != 1 or len(signals.measurement_disturbances) != model.r or len(signals.inputs) != 1:
        raise ValueError("signals: one disturbance, one input and one measurement disturbance per column of D")
    return {
        "par": (M, m, l, g),
        "substeps": substeps,
        "h": config.dt / substeps,
        "C": model.C,
        "D": model.D,
        "x": tuple(float(v) for v in model.x0),
        "signals": signals,
        "controller": config.read_index("controller"),
        "u_prev": 0.0,
        "out": np.zeros(config.publishes.len),
        "n": model.n,
        "p": model.p,
    }


def step(k, inputs, st):
    """Sample k from x_{k−1}, u_{k−1} (the controller's sample of step k − 1) and w(t_{k−1})."""
    sig = st["signals"]
    if k > 0:
        j = k - 1
        c = st["controller"]
        u = float(inputs[c][0]) if c is not None else float(sig.r(j)[0])
        w = float(sig.w(j)[0])
        st["x"] = rk4(st["x"], u + w, st["h"], st["substeps"], *st["par"])
        st["u_prev"] = u
        if not all(math.isfinite(v) for v in st["x"]):
            raise Diverged(f"the state is not finite: {st['x']}")
    x = np.array(st["x"])
    v = sig.v(k)
    y = st["C"] @ x + (st["D"] @ v if v.size else 0.0)
    out = st["out"]
    n, p = st["n"], st["p"]
    out[:n] = x
    out[n:n + p] = y
    w_k = sig.w(k)
    i = n + p
    out[i:i + 1] = w_k
    i += 1
    out[i:i + v.size] = v
    i += v.size
    out[i] = sig.r(k)[0]
    out[i + 1] = st["u_prev"]
    return out


if __name__ == "__main__":
    uio_component.run(step, setup)
