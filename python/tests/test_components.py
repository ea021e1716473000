"""The shipped components as processes: the Python cart-pole and the Python LQR controller in
one ring, this test playing the launcher and a perfect observer (x̂_k = x_k); the trajectory
equals the same loop computed here, bit for bit, and the pendulum is balanced."""

import os
import time

import numpy as np

from conftest import COMPONENTS
from test_run import DT, Launched, base_config

import cartpole
import lqr
from uio_component import Signals
from uio_component.wire import Bus

PARAMS = {"cart_mass": 1.0, "pole_mass": 0.1, "length": 0.5, "gravity": 9.81, "substeps": 4}
A, B, E = cartpole.linearisation(1.0, 0.1, 0.5, 9.81)
MODEL = {"A": A.tolist(), "B": B.tolist(), "C": [[1.0, 0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]], "D": [],
         "E": E.tolist(), "x0": [0.0, 0.0, 0.1, 0.0]}
SIGNALS = {"disturbances": [{"kind": "sine", "amplitude": 1.0, "frequency_hz": 0.5}], "measurement_disturbances": [],
           "inputs": [{"kind": "step", "time": 0.5, "before": 0.0, "after": 0.5}]}
LQR = {"Q": [100.0, 10.0, 100.0, 1.0], "R": 1.0, "track": [[1.0, 0.0, 0.0, 0.0]]}


def reference_loop(K):
    """The same loop in this process: x_{k+1} = RK4(x_k, u_k + w_k), u_k = N r_k − K x_k."""
    gain, pre = lqr.design(A, B, np.diag(LQR["Q"]), np.eye(1) * LQR["R"], LQR["track"])
    sig = Signals(SIGNALS, DT)
    x, xs = (0.0, 0.0, 0.1, 0.0), []
    for k in range(K + 1):
        xs.append(x)
        u = float((pre @ sig.r(k) - gain @ np.array(x))[0])
        x = cartpole.rk4(x, u + float(sig.w(k)[0]), DT / 4, 4, *cartpole.parameters(PARAMS))
    return np.array(xs)


def test_python_plant_and_python_lqr_in_one_ring(run_space):
    K = 3000
    bus = Bus(run_space["prefix"], run_space["root"], "launcher")
    # The launcher creates every service first; the test is the observer the ring goes through.
    observer = bus.outlet("observer/uio", 4)
    plant_in = bus.inlet("plant", 10)
    control_in = bus.inlet("controller", 1)
    plant = Launched(run_space, base_config(
        run_space, "plant", "plant", {"service": "plant", "len": 10},
        [{"service": "observer/uio", "len": 4, "lag": 0}, {"service": "controller", "len": 1, "lag": 0}],
        K, model=MODEL, signals=SIGNALS, params=PARAMS), os.path.join(COMPONENTS, "cartpole.py"))
    controller = Launched(run_space, base_config(
        run_space, "controller", "controller", {"service": "controller", "len": 1},
        [{"service": "observer/uio", "len": 4, "lag": 0}],
        K, model=MODEL, signals=SIGNALS, params=LQR), os.path.join(COMPONENTS, "lqr.py"))
    assert plant.ready() == b"ready\n" and controller.ready() == b"ready\n"
    plant.go()
    controller.go()
    sample, u = np.zeros(10), np.zeros(1)
    xs, us = [], []
    start = time.monotonic()
    for k in range(K):
        plant_in.take(k, sample, 10.0)
        xs.append(sample[:4].copy())
        observer.send(k, k * DT, 0, sample[:4].copy())
        control_in.take(k, u, 10.0)
        us.append(u[0])
    per_step = (time.monotonic() - start) / K
    plant_in.take(K, sample, 10.0)
    xs.append(sample[:4].copy())
    assert plant.finish()[0] == 0
    code, _, stderr = controller.finish()
    assert code == 0, stderr
    assert "eig(A − BK)" in stderr
    bus.close()
    xs = np.array(xs)
    np.testing.assert_array_equal(xs, reference_loop(K))  # bit for bit
    assert np.max(np.abs(xs[:, 2])) < 0.15 and abs(xs[-1, 2]) < 0.05  # balanced
    print(f"ring of two Python components and this test: {per_step * 1e6:.0f} µs per step")
