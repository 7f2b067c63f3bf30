"""Steady-state and time-varying Kalman-Bucy gains of linear loops, and the error of any fixed-gain loop.

For a linear time-invariant loop x' = A x + w (white, PSD Q) observed as z = C x + v (white, PSD R),
errors = estimate - true (spec 07, "Steady-state gains"):

* the Kalman-Bucy filter's covariance obeys the Riccati equation
  P' = A P + P A^T - P C^T R^-1 C P + Q; its steady state solves the continuous algebraic Riccati
  equation (ARE), the gain is K = P C^T R^-1 (:func:`steady_state_gain`, scipy's
  ``solve_continuous_are`` with the dual arguments A^T, C^T);
* any fixed gain K gives the loop x_hat' = A x_hat + K (z - C x_hat), whose error e obeys
  e' = (A - K C) e - w + K v; its steady covariance solves the Lyapunov equation
  (A - K C) P + P (A - K C)^T + Q + K R K^T = 0 (:func:`loop_error_covariance`);
* the time-varying gain from an initial covariance P0 (:func:`riccati_solution`): with
  P = Y X^-1 the Riccati equation is the linear system d/dt [X; Y] = [[-A^T, C^T R^-1 C], [Q, A]] [X; Y],
  X(0) = I, Y(0) = P0, solved exactly by one matrix exponential per grid step and restarted from
  (I, P_k) at every step, so that X never grows (Kailath, Sayed and Hassibi 2000, Sec. 16.4).

A constant bias makes the ARE degenerate (it is unobservable from, or indistinguishable from, another
state); model it as a random walk or a Gauss-Markov process in A and Q and add the constant bias's
error deterministically.

References
----------
R. E. Kalman and R. S. Bucy, "New results in linear filtering and prediction theory", *Trans. ASME,
J. Basic Eng.* 83(1), 1961.
T. Kailath, A. H. Sayed and B. Hassibi, *Linear Estimation*, Prentice Hall, 2000, ch. 16.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from schuler.exceptions import InvalidParameter


def _system(A, C, Q, R) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    A = np.atleast_2d(np.asarray(A, dtype=float))
    C = np.atleast_2d(np.asarray(C, dtype=float))
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    R = np.atleast_2d(np.asarray(R, dtype=float))
    n, m = A.shape[0], C.shape[0]
    if A.shape != (n, n) or C.shape != (m, n) or Q.shape != (n, n) or R.shape != (m, m):
        raise InvalidParameter("loop", f"shapes do not fit: A {A.shape}, C {C.shape}, Q {Q.shape}, R {R.shape}")
    if not all(np.all(np.isfinite(M)) for M in (A, C, Q, R)):
        raise InvalidParameter("loop", "A, C, Q and R must be finite")
    if np.any(np.linalg.eigvalsh((R + R.T) / 2) <= 0):
        raise InvalidParameter("measurement_noise", "the measurement noise R must be positive definite")
    return A, C, Q, R


@dataclass(frozen=True)
class SteadyStateFilter:
    """The steady-state Kalman-Bucy filter of a loop.

    Attributes
    ----------
    gain : ndarray, shape (n, m)
        K = P C^T R^-1, (state units) / (measurement units).
    covariance : ndarray, shape (n, n)
        P, the ARE's stabilising solution, (state units)^2.
    poles : ndarray, shape (n,)
        Eigenvalues of A - K C, 1/s (complex).
    """

    gain: np.ndarray
    covariance: np.ndarray
    poles: np.ndarray


def steady_state_gain(A, C, Q, R) -> SteadyStateFilter:
    """The steady-state Kalman-Bucy gain and error covariance of x' = A x + w, z = C x + v.

    Parameters
    ----------
    A : array_like, shape (n, n)
        System matrix, 1/s (state units per state unit per second).
    C : array_like, shape (m, n)
        Measurement matrix, measurement units per state unit.
    Q : array_like, shape (n, n)
        PSD of the process noise w, (state units)^2/s.
    R : array_like, shape (m, m)
        PSD of the measurement noise v, (measurement units)^2 s; positive definite.

    Returns
    -------
    SteadyStateFilter

    Raises
    ------
    InvalidParameter
        When the ARE has no stabilising solution (a state neither observed nor driven stably: a constant
        bias; model it as a random walk or Gauss-Markov process).

    Examples
    --------
    A random walk (PSD q) measured in white noise (PSD r) has K = sqrt(q / r) and P = sqrt(q r):

    >>> f = steady_state_gain([[0.0]], [[1.0]], [[4.0]], [[1.0]])
    >>> float(f.gain[0, 0]), float(f.covariance[0, 0])
    (2.0, 2.0)
    """
    A, C, Q, R = _system(A, C, Q, R)
    try:
        P = scipy.linalg.solve_continuous_are(A.T, C.T, (Q + Q.T) / 2, R)
    except (np.linalg.LinAlgError, ValueError) as error:
        raise InvalidParameter("loop", f"the Riccati equation has no stabilising solution ({error}); a constant "
                                       "state must be modelled as a random walk or a Gauss-Markov process") from None
    P = (P + P.T) / 2
    K = scipy.linalg.solve(R, C @ P, assume_a="pos").T
    return SteadyStateFilter(K, P, np.linalg.eigvals(A - K @ C))


def loop_error_covariance(A, K, C, Q, R) -> np.ndarray:
    """Steady error covariance of the fixed-gain loop x_hat' = A x_hat + K (z - C x_hat) (module docstring).

    Parameters
    ----------
    A : array_like, shape (n, n)
        System matrix, 1/s.
    K : array_like, shape (n, m)
        The loop's gain, state units per measurement unit per second (so that K C is in 1/s).
    C : array_like, shape (m, n)
        Measurement matrix, measurement units per state unit.
    Q : array_like, shape (n, n)
        PSD of the process noise, (state units)^2/s.
    R : array_like, shape (m, m)
        PSD of the measurement noise, (measurement units)^2 s.

    Returns
    -------
    ndarray, shape (n, n)
        P solving (A - K C) P + P (A - K C)^T + Q + K R K^T = 0, (state units)^2.

    Raises
    ------
    InvalidParameter
        When A - K C is not stable (the loop has no steady state).

    Examples
    --------
    The random walk above with the optimal gain 2 has P = 2; with gain 1, (4 + 1) / 2:

    >>> float(loop_error_covariance([[0.0]], [[1.0]], [[1.0]], [[4.0]], [[1.0]])[0, 0])
    2.5
    """
    A, C, Q, R = _system(A, C, Q, R)
    K = np.atleast_2d(np.asarray(K, dtype=float)).reshape(A.shape[0], C.shape[0])
    closed = A - K @ C
    if np.max(np.linalg.eigvals(closed).real) >= 0:
        raise InvalidParameter("gain", "the loop A - K C is not stable: it has no steady error")
    P = scipy.linalg.solve_continuous_lyapunov(closed, -(Q + K @ R @ K.T))
    return (P + P.T) / 2


def riccati_solution(A, C, Q, R, P0, t_s) -> np.ndarray:
    """The Kalman-Bucy covariance P(t) from P(0) = P0 at the times ``t_s`` (module docstring: exact per step).

    Parameters
    ----------
    A : array_like, shape (n, n)
        System matrix, 1/s.
    C : array_like, shape (m, n)
        Measurement matrix, measurement units per state unit.
    Q : array_like, shape (n, n)
        PSD of the process noise, (state units)^2/s.
    R : array_like, shape (m, m)
        PSD of the measurement noise, (measurement units)^2 s.
    P0 : array_like, shape (n, n)
        Covariance at t = 0, (state units)^2.
    t_s : array_like, shape (k,)
        Increasing times from 0, s.

    Returns
    -------
    ndarray, shape (k, n, n)
        P at each time; the gain is P C^T R^-1.

    Examples
    --------
    The random walk converges to its steady P = 2 from P0 = 0:

    >>> P = riccati_solution([[0.0]], [[1.0]], [[4.0]], [[1.0]], [[0.0]], [0.0, 0.5, 20.0])
    >>> [round(float(p), 6) for p in P[:, 0, 0]]
    [0.0, 1.523188, 2.0]
    """
    A, C, Q, R = _system(A, C, Q, R)
    n = A.shape[0]
    t = np.asarray(t_s, dtype=float).ravel()
    if t.size == 0 or t[0] < 0 or np.any(np.diff(t) < 0):
        raise InvalidParameter("t_s", "times must be increasing from 0 s")
    CRC = C.T @ scipy.linalg.solve(R, C, assume_a="pos")
    hamiltonian = np.block([[-A.T, CRC], [(Q + Q.T) / 2, A]])
    P = np.atleast_2d(np.asarray(P0, dtype=float)).copy()
    out = np.empty((t.size, n, n))
    previous = 0.0
    cache: dict[float, np.ndarray] = {}
    for k, time in enumerate(t):
        step = time - previous
        if step > 0:
            key = round(step, 12)
            E = cache.get(key)
            if E is None:
                E = cache[key] = scipy.linalg.expm(hamiltonian * step)
            X = E[:n, :n] + E[:n, n:] @ P
            Y = E[n:, :n] + E[n:, n:] @ P
            P = np.linalg.solve(X.T, Y.T).T
            P = (P + P.T) / 2
        out[k] = P
        previous = time
    return out
