"""The LQR controller's design (components/lqr.py)."""

import numpy as np
import pytest
from scipy.linalg import solve_continuous_are

import cartpole
import lqr

A, B, _ = cartpole.linearisation(1.0, 0.1, 0.5, 9.81)


def test_the_gain_solves_the_riccati_equation_and_stabilises():
    Q, R = np.diag([100.0, 10.0, 100.0, 1.0]), np.eye(1)
    K, N = lqr.design(A, B, Q, R)
    P = solve_continuous_are(A, B, Q, R)
    residual = A.T @ P + P @ A - P @ B @ np.linalg.solve(R, B.T @ P) + Q
    assert np.max(np.abs(residual)) < 1e-8 * np.max(np.abs(P))
    np.testing.assert_allclose(K, np.linalg.solve(R, B.T @ P))
    assert np.all(np.linalg.eigvals(A - B @ K).real < 0)
    assert N.tolist() == [[1.0]]
    # The weights of the shipped scenario: K ≈ [−10, −10.27, −57.64, −12.63].
    np.testing.assert_allclose(K, [[-10.0, -10.2722, -57.6426, -12.6289]], atol=1e-3)


def test_the_prefilter_gives_unit_dc_gain_on_the_tracked_output():
    K, N = lqr.design(A, B, np.diag([100.0, 10.0, 100.0, 1.0]), np.eye(1), [[1.0, 0.0, 0.0, 0.0]])
    x_ss = -np.linalg.solve(A - B @ K, B @ N)  # the equilibrium for r = 1
    assert x_ss[0, 0] == pytest.approx(1.0, rel=1e-12)


def test_weights_as_rows_lists_or_numbers():
    assert lqr.weight(2.0, 1, "R").tolist() == [[2.0]]
    assert lqr.weight([1.0, 2.0], 2, "Q").tolist() == [[1.0, 0.0], [0.0, 2.0]]
    assert lqr.weight([[1.0, 0.5], [0.5, 2.0]], 2, "Q").tolist() == [[1.0, 0.5], [0.5, 2.0]]
    assert lqr.weight(3.0, 2, "Q").tolist() == [[3.0, 0.0], [0.0, 3.0]]
    with pytest.raises(ValueError):
        lqr.weight([1.0, 2.0, 3.0], 2, "Q")
