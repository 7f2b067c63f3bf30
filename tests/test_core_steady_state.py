"""The steady-state Kalman-Bucy gain, the fixed-gain loop's error and the time-varying Riccati solution."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from schuler.core.steady_state import loop_error_covariance, riccati_solution, steady_state_gain
from schuler.exceptions import InvalidParameter


def _second_order(q_rate, q_position, r):
    # position-velocity random walks measured in position: the classical alpha-beta loop
    A = np.array([[0.0, 1.0], [0.0, 0.0]])
    C = np.array([[1.0, 0.0]])
    Q = np.diag([q_position, q_rate])
    return A, C, Q, np.array([[r]])


def test_random_walk_closed_form():
    f = steady_state_gain([[0.0]], [[1.0]], [[9.0]], [[4.0]])
    assert f.gain[0, 0] == pytest.approx(1.5, rel=1e-12)
    assert f.covariance[0, 0] == pytest.approx(6.0, rel=1e-12)
    assert f.poles[0].real == pytest.approx(-1.5, rel=1e-12)


def test_second_order_closed_form():
    # q_position = 0: K = (sqrt(2) w, w^2) with w = (q/r)^(1/4): natural frequency w, damping 1/sqrt(2)
    q, r = 0.01, 4.0
    f = steady_state_gain(*_second_order(q, 0.0, r))
    omega = (q / r) ** 0.25
    assert f.gain[:, 0] == pytest.approx([np.sqrt(2) * omega, omega**2], rel=1e-10)


@settings(max_examples=40, deadline=None)
@given(st.floats(1e-4, 1e2), st.floats(0.0, 1e1), st.floats(1e-2, 1e2), st.floats(0.2, 5.0), st.floats(0.2, 5.0))
def test_optimal_gain_is_no_worse_than_any_other(q_rate, q_position, r, scale_1, scale_2):
    A, C, Q, R = _second_order(q_rate, q_position, r)
    f = steady_state_gain(A, C, Q, R)
    optimal = loop_error_covariance(A, f.gain, C, Q, R)
    np.testing.assert_allclose(optimal, f.covariance, rtol=1e-7, atol=1e-12 * np.abs(f.covariance).max())
    other = loop_error_covariance(A, f.gain * np.array([[scale_1], [scale_2]]), C, Q, R)
    # the optimal covariance is smallest in the matrix sense: other - optimal is positive semi-definite
    assert np.linalg.eigvalsh(other - optimal).min() >= -1e-9 * np.abs(optimal).max()


def test_riccati_converges_to_the_steady_state():
    A, C, Q, R = _second_order(0.01, 0.1, 4.0)
    f = steady_state_gain(A, C, Q, R)
    t = np.linspace(0.0, 400.0, 801)
    P = riccati_solution(A, C, Q, R, np.diag([100.0, 1.0]), t)
    np.testing.assert_allclose(P[-1], f.covariance, rtol=1e-9)
    # against a fine explicit integration over the first second
    dt, Pe = 1e-5, np.diag([100.0, 1.0])
    CRC = C.T @ C / R[0, 0]
    for _ in range(100_000):
        Pe = Pe + dt * (A @ Pe + Pe @ A.T - Pe @ CRC @ Pe + Q)
    np.testing.assert_allclose(riccati_solution(A, C, Q, R, np.diag([100.0, 1.0]), [0.0, 1.0])[-1], Pe, rtol=2e-3)


def test_degenerate_and_unstable_are_refused():
    # a constant state never measured: no stabilising solution
    with pytest.raises(InvalidParameter, match="Gauss-Markov"):
        steady_state_gain([[0.0, 0.0], [0.0, 0.0]], [[1.0, 0.0]], np.diag([1.0, 0.0]), [[1.0]])
    with pytest.raises(InvalidParameter, match="not stable"):
        loop_error_covariance([[1.0]], [[0.5]], [[1.0]], [[1.0]], [[1.0]])
    with pytest.raises(InvalidParameter, match="positive definite"):
        steady_state_gain([[0.0]], [[1.0]], [[1.0]], [[0.0]])
