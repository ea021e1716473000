"""The cart-pole plant (components/cartpole.py): its hand linearisation against finite
differences of the nonlinear equations and against the scenarios' [plant] tables, the
equations against the conservation laws, and the sample it publishes."""

import math
import os

import numpy as np
import pytest
from scipy.linalg import expm

from conftest import REPO

import cartpole
from uio_component import parse_config

PARAMS = (1.0, 0.1, 0.5, 9.81)  # M, m, l, g of the shipped scenarios
SCENARIOS = ["cartpole-python-plant.toml", "cartpole-python-controller.toml"]


def f(x, force, par=PARAMS):
    return np.array(cartpole.dynamics(tuple(x), force, *par))


@pytest.mark.parametrize("par", [PARAMS, (2.0, 0.5, 1.2, 9.81), (0.3, 0.05, 0.2, 3.7)])
def test_linearisation_equals_finite_differences(par):
    A, B, E = cartpole.linearisation(*par)
    h = 1e-6
    x0 = np.zeros(4)
    A_fd = np.column_stack([(f(x0 + h * e, 0.0, par) - f(x0 - h * e, 0.0, par)) / (2 * h) for e in np.eye(4)])
    B_fd = ((f(x0, h, par) - f(x0, -h, par)) / (2 * h)).reshape(4, 1)
    np.testing.assert_allclose(A, A_fd, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(B, B_fd, rtol=1e-8, atol=1e-8)
    np.testing.assert_array_equal(E, B)  # the unknown force acts where the motor does
    assert np.all(f(x0, 0.0, par) == 0.0)  # upright is an equilibrium


def test_linearisation_by_hand_for_the_shipped_parameters():
    A, B, _ = cartpole.linearisation(*PARAMS)
    assert A[1, 2] == pytest.approx(-0.981, rel=1e-15)
    assert A[3, 2] == pytest.approx(21.582, rel=1e-15)
    assert B[:, 0].tolist() == [0.0, 1.0, 0.0, -2.0]
    assert sorted(np.linalg.eigvals(A).real) == pytest.approx([-math.sqrt(21.582), 0, 0, math.sqrt(21.582)], abs=1e-9)


@pytest.mark.parametrize("name", SCENARIOS)
def test_scenario_model_is_the_linearisation_of_its_plant(name):
    tomllib = pytest.importorskip("tomllib")
    with open(os.path.join(REPO, "scenarios", name), "rb") as fh:
        sc = tomllib.load(fh)
    plant = sc["plant"]
    assert plant["process"]["command"] == ["python3", "../components/cartpole.py"]
    params = plant["process"]["params"]
    A, B, E = cartpole.linearisation(*cartpole.parameters(params))
    np.testing.assert_allclose(np.array(plant["A"]), A, rtol=1e-12, atol=0)
    np.testing.assert_allclose(np.array(plant["B"]), B, rtol=1e-12, atol=0)
    np.testing.assert_allclose(np.array(plant["E"]), E, rtol=1e-12, atol=0)
    C = np.array(plant["C"])
    Em = np.array(plant["E"])
    # The UIO's decoupling condition rank CE = rank E.
    assert np.linalg.matrix_rank(C @ Em) == np.linalg.matrix_rank(Em) == 1


def energy_and_momentum(x, M, m, l, g):
    _, sd, th, thd = x
    T = 0.5 * (M + m) * sd ** 2 + m * l * math.cos(th) * sd * thd + 0.5 * m * l ** 2 * thd ** 2
    return T + m * g * l * math.cos(th), (M + m) * sd + m * l * math.cos(th) * thd


def test_free_motion_conserves_energy_and_horizontal_momentum():
    # A large swing (released 1 rad from upright, cart moving): the nonlinear terms matter.
    x = (0.0, 0.3, 1.0, 0.0)
    e0, p0 = energy_and_momentum(x, *PARAMS)
    for _ in range(1000):  # 1 s
        x = cartpole.rk4(x, 0.0, 0.001 / 4, 4, *PARAMS)
    e1, p1 = energy_and_momentum(x, *PARAMS)
    assert abs(e1 - e0) < 1e-9 * abs(e0)
    assert abs(p1 - p0) < 1e-12
    assert abs(x[2] - 1.0) > 0.1  # it did move


def test_a_constant_force_adds_its_impulse():
    x = (0.0, 0.0, 0.5, 0.0)
    _, p0 = energy_and_momentum(x, *PARAMS)
    for _ in range(500):
        x = cartpole.rk4(x, 2.0, 0.001 / 4, 4, *PARAMS)
    _, p1 = energy_and_momentum(x, *PARAMS)
    assert p1 - p0 == pytest.approx(2.0 * 0.5, rel=1e-10)


def test_small_motions_follow_the_linear_model():
    A, B, _ = cartpole.linearisation(*PARAMS)
    x0 = np.array([0.0, 0.0, 1e-6, 0.0])
    x = tuple(x0)
    for _ in range(500):  # 0.5 s
        x = cartpole.rk4(x, 0.0, 0.001 / 4, 4, *PARAMS)
    np.testing.assert_allclose(np.array(x), expm(A * 0.5) @ x0, rtol=1e-9, atol=1e-15)


def config(reads, steps=5, x0=(0.0, 0.0, 0.1, 0.0)):
    return parse_config({
        "protocol": 1, "run": "1x0x1", "name": "plant", "role": "plant",
        "iceoryx2": {"prefix": "uio1x0x1_", "root": "/tmp/none/"}, "wait": "yield",
        "dt": 0.001, "steps": steps,
        "publishes": {"service": "plant", "len": 4 + 3 + 1 + 0 + 2, "names": []},
        "reads": reads,
        "model": {"A": cartpole.linearisation(*PARAMS)[0].tolist(), "B": [[0.0], [1.0], [0.0], [-2.0]],
                  "C": [[1.0, 0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]], "D": [], "E": [[0.0], [1.0], [0.0], [-2.0]],
                  "x0": list(x0)},
        "signals": {"disturbances": [{"kind": "step", "time": 0.002, "before": 0.0, "after": 1.5}],
                    "measurement_disturbances": [], "inputs": [{"kind": "constant", "value": 0.25}]},
        "params": {"cart_mass": 1.0, "pole_mass": 0.1, "length": 0.5, "gravity": 9.81, "substeps": 4},
    })


def test_the_plant_sample_layout():
    cfg = config([{"service": "controller", "len": 1, "lag": 0}, {"service": "observer/uio", "len": 4, "lag": 4096}])
    st = cartpole.setup(cfg)
    inputs = [np.zeros(1), np.zeros(4)]
    out0 = cartpole.step(0, inputs, st).copy()
    # [x (4) | y = s, θ, θ̇ (3) | w (1) | v (0) | r (1) | u_{k−1} (1)]
    assert out0.tolist() == [0.0, 0.0, 0.1, 0.0, 0.0, 0.1, 0.0, 0.0, 0.25, 0.0]
    inputs[0][0] = -3.0  # u_0 from the controller
    out1 = cartpole.step(1, inputs, st).copy()
    expected = cartpole.rk4((0.0, 0.0, 0.1, 0.0), -3.0 + 0.0, 0.001 / 4, 4, *PARAMS)
    assert out1[:4].tolist() == list(expected)
    assert out1[4:7].tolist() == [expected[0], expected[2], expected[3]]
    assert out1[9] == -3.0
    inputs[0][0] = 0.0
    out2 = cartpole.step(2, inputs, st).copy()
    assert out2[7] == 1.5  # w switches on at t = 0.002 s, sample 2
    out3 = cartpole.step(3, inputs, st).copy()
    expected3 = cartpole.rk4(tuple(out2[:4]), 0.0 + 1.5, 0.001 / 4, 4, *PARAMS)
    assert out3[:4].tolist() == list(expected3)


def test_without_a_controller_the_inputs_drive_the_plant():
    st = cartpole.setup(config([{"service": "observer/uio", "len": 4, "lag": 4096}]))
    inputs = [np.zeros(4)]
    cartpole.step(0, inputs, st)
    out = cartpole.step(1, inputs, st)
    assert out[9] == 0.25
    assert out[:4].tolist() == list(cartpole.rk4((0.0, 0.0, 0.1, 0.0), 0.25, 0.001 / 4, 4, *PARAMS))


def test_wrong_sizes_are_refused():
    cfg = config([])
    bad = parse_config({**cfg.raw, "publishes": {"service": "plant", "len": 9}})
    with pytest.raises(ValueError, match="publishes.len"):
        cartpole.setup(bad)
