#!/usr/bin/env python3
"""An LQR state-feedback controller on an observer's estimate (PROTOCOL.md §7, `[controller]`).

From the scenario's design model (A, B) and the weights in `params` it computes, with scipy,
the continuous-time LQR gain

    P = care(A, B, Q, R)   (scipy.linalg.solve_continuous_are),   K = R⁻¹ Bᵀ P,

which minimises ∫ xᵀQx + uᵀRu dt, and applies u_k = N r_k − K x̂_k at every sample, x̂_k being
the estimate of the observer the scenario names (`reads[0]`, n values) and r_k the [[input]]
signals at t_k (the configuration's `signals.inputs`; else the `r` field of a plant sample it
reads; else 0). Without `track`, N = I (u = r − K x̂, as the built-in controller); with
`track` = rows of C_t (one per input), N = −(C_t (A − BK)⁻¹ B)⁻¹ gives z = C_t x unit DC gain
from r.

`params`: `Q` (n×n rows, or a list of n diagonal weights), `R` (l×l rows, a list of l diagonal
weights, or a number for l = 1), optional `track`. At 1 kHz the continuous gain applied to
samples held over a step behaves like the sampled design; `uio-launcher design` does not see this
controller, so its closed-loop poles are printed on stderr at start (eig(A − BK)).
"""

from __future__ import annotations

import os
import sys

import numpy as np
from scipy.linalg import solve_continuous_are

try:
    import uio_component
except ImportError:  # run from a checkout without `pip install ./python`
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
    import uio_component

from uio_component import Signals


def weight(value, size, name):
    """A weight matrix from rows, a diagonal list or a number."""
    a = np.atleast_1d(np.array(value, dtype=np.float64))
    if a.ndim == 1:
        if a.size == 1 and size > 1:
            a = np.full(size, a[0])
        a = np.diag(a)
    if a.shape != (size, size):
        raise ValueError(f"{name} must be {size}×{size} (or {size} diagonal weights)")
    return a


def design(A, B, Q, R, track=None):
    """(K, N) of the LQR design, N the reference prefilter (I without `track`)."""
    P = solve_continuous_are(A, B, Q, R)
    K = np.linalg.solve(R, B.T @ P)
    l = B.shape[1]
    if track is None:
        N = np.eye(l)
    else:
        Ct = np.atleast_2d(np.array(track, dtype=np.float64))
        if Ct.shape != (l, A.shape[0]):
            raise ValueError(f"track must have {l} row(s) of {A.shape[0]}")
        N = -np.linalg.inv(Ct @ np.linalg.solve(A - B @ K, B))
    return K, N


def setup(config):
    """The gain, the prefilter and where r comes from."""
    model = config.model
    if model is None:
        raise ValueError("the configuration has no model")
    if not config.reads or config.reads[0].len != model.n:
        raise ValueError(f"reads[0] must be the observer's estimate ({model.n} values)")
    if config.publishes.len != model.l:
        raise ValueError(f"publishes.len is {config.publishes.len}, the model has {model.l} input(s)")
    params = config.params or {}
    Q = weight(params.get("Q", 1.0), model.n, "Q")
    R = weight(params.get("R", 1.0), model.l, "R")
    K, N = design(model.A, model.B, Q, R, params.get("track"))
    poles = np.linalg.eigvals(model.A - model.B @ K)
    print(f"{config.name}: LQR K = {np.array2string(K, precision=4)}, eig(A − BK) = "
          f"{np.array2string(np.sort_complex(poles), precision=3)}", file=sys.stderr)
    signals = Signals(config.signals, config.dt)
    r_read = next(((i, r) for i, r in enumerate(config.reads) if "r" in r.fields), None)
    return {"K": K, "N": N, "signals": signals if len(signals.inputs) == model.l else None,
            "r_read": r_read, "l": model.l}


def step(k, inputs, st):
    """u_k = N r_k − K x̂_k."""
    if st["signals"] is not None:
        r = st["signals"].r(k)
    elif st["r_read"] is not None:
        i, read = st["r_read"]
        r = read.field(inputs[i], "r")
    else:
        r = np.zeros(st["l"])
    return st["N"] @ r - st["K"] @ inputs[0]


if __name__ == "__main__":
    uio_component.run(step, setup)
