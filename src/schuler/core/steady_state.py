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
  X(0) = I, Y(0) = P0, solved exactly by matrix exponentials over pieces of each grid step short enough
  that no mode grows by more than e^4, restarted from (I, P_k) at every piece, so that X never grows
  (Kailath, Sayed and Hassibi 2000, Sec. 16.4);
* the fixed-gain loop's covariance over time, the differential Lyapunov equation
  (:func:`loop_covariance_history`), and its Monte Carlo with truth and estimate simulated together
  (:func:`loop_monte_carlo`);
* for which noise a fixed single-output gain is the Kalman gain (:func:`noise_ratios_for_gain`, the
  return-difference identity), and a bias state's model (:func:`bias_state`).

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

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from schuler.exceptions import InvalidParameter, renamed_keywords


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
    poles = np.linalg.eigvals(closed)
    # a pole within the eigenvalues' rounding (a few eps ||A - K C||) of the axis is no steady state either: its
    # Lyapunov solution is rounding noise; a slow pole beside fast ones (12 decades apart in a Kalman loop) is one
    if np.max(poles.real) >= -16.0 * np.finfo(float).eps * max(float(np.linalg.norm(closed, 1)), 1e-300):
        raise InvalidParameter("gain", "the loop A - K C is not stable (or within rounding of it): it has no "
                                       "steady error")
    P = scipy.linalg.solve_continuous_lyapunov(closed, -(Q + K @ R @ K.T))
    P = (P + P.T) / 2
    if not np.all(np.isfinite(P)) or np.linalg.eigvalsh(P).min() < -1e-9 * np.abs(P).max():
        raise InvalidParameter("gain", "the loop is too close to unstable for a steady error covariance")
    return P


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
    t = _times(t_s)
    P = np.atleast_2d(np.asarray(P0, dtype=float)).copy()
    # an exact diagonal change of state units, x = S x~ with S = sqrt(P0_ii + Q_ii 1 s): states of very different
    # sizes (radians beside m/s beside rad/s biases) keep X well conditioned (1e-15 instead of 1e-6 relative)
    scale = np.sqrt(np.abs(np.diag(P)) + np.abs(np.diag(Q)) * 1.0)
    scale = np.where(scale > 0, scale, 1.0)
    A = A * scale[None, :] / scale[:, None]
    C = C * scale[None, :]
    Q = Q / np.multiply.outer(scale, scale)
    P = P / np.multiply.outer(scale, scale)
    CRC = C.T @ scipy.linalg.solve(R, C, assume_a="pos")
    hamiltonian = np.block([[-A.T, CRC], [(Q + Q.T) / 2, A]])
    # a step is cut so that no mode of the Hamiltonian grows by more than e^4 over a piece: X stays regular
    rate = float(np.max(np.abs(np.linalg.eigvals(hamiltonian))))
    out = np.empty((t.size, n, n))
    previous = 0.0
    cache: dict[float, np.ndarray] = {}
    for k, time in enumerate(t):
        step = time - previous
        pieces = max(1, math.ceil(step * rate / 4.0))
        key = round(step / pieces, 12)
        if step > 0 and key not in cache:
            cache[key] = scipy.linalg.expm(hamiltonian * (step / pieces))
        for _ in range(pieces if step > 0 else 0):
            E = cache[key]
            X = E[:n, :n] + E[:n, n:] @ P
            Y = E[n:, :n] + E[n:, n:] @ P
            P = np.linalg.solve(X.T, Y.T).T
            P = (P + P.T) / 2
        out[k] = P
        previous = time
    return out * np.multiply.outer(scale, scale)


def _joint_loop(A, K, C, Q, R) -> tuple[np.ndarray, np.ndarray]:
    """The truth x and the fixed-gain estimate x_hat as one system d/dt [x; x_hat] = F [x; x_hat] + noise."""
    n = A.shape[0]
    F = np.block([[A, np.zeros((n, n))], [K @ C, A - K @ C]])
    W = np.zeros((2 * n, 2 * n))
    W[:n, :n] = (Q + Q.T) / 2
    W[n:, n:] = K @ R @ K.T
    return F, W


def loop_covariance_history(A, K, C, Q, R, P0, t_s) -> np.ndarray:
    """Error covariance P(t) of the fixed-gain loop of :func:`loop_error_covariance` from P(0) = P0.

    It solves the differential Lyapunov equation P' = (A - K C) P + P (A - K C)^T + Q + K R K^T exactly per step:
    P_{k+1} = Phi P_k Phi^T + Q_d with Phi, Q_d from Van Loan's block exponential
    (:func:`schuler.core.propagation.discretise_noise`). It needs no stable loop: an undamped loop's error grows.

    Parameters
    ----------
    A : array_like, shape (n, n)
        System matrix, 1/s.
    K : array_like, shape (n, m)
        The loop's gain, state units per measurement unit per second.
    C : array_like, shape (m, n)
        Measurement matrix, measurement units per state unit.
    Q : array_like, shape (n, n)
        PSD of the process noise, (state units)^2/s.
    R : array_like, shape (m, m)
        PSD of the measurement noise, (measurement units)^2 s.
    P0 : array_like, shape (n, n)
        Error covariance at t = 0, (state units)^2.
    t_s : array_like, shape (k,)
        Increasing times from 0, s.

    Returns
    -------
    ndarray, shape (k, n, n)
        P at each time, (state units)^2.

    Examples
    --------
    A random walk (PSD 4) never measured (gain 0): P grows as 4 t.

    >>> P = loop_covariance_history([[0.0]], [[0.0]], [[1.0]], [[4.0]], [[1.0]], [[0.0]], [0.0, 2.5])
    >>> [round(float(p), 12) for p in P[:, 0, 0]]
    [0.0, 10.0]
    """
    from schuler.core.propagation import discretise_noise

    A, C, Q, R = _system(A, C, Q, R)
    K = np.atleast_2d(np.asarray(K, dtype=float)).reshape(A.shape[0], C.shape[0])
    t = _times(t_s)
    closed = A - K @ C
    W = (Q + Q.T) / 2 + K @ R @ K.T
    P = np.atleast_2d(np.asarray(P0, dtype=float)).copy()
    out = np.empty((t.size,) + P.shape)
    previous = 0.0
    cache: dict[float, tuple[np.ndarray, np.ndarray]] = {}
    for k, time in enumerate(t):
        step = time - previous
        if step > 0:
            key = round(step, 12)
            if key not in cache:
                cache[key] = discretise_noise(closed, W, step)
            Phi, Qd = cache[key]
            P = Phi @ P @ Phi.T + Qd
            P = (P + P.T) / 2
        out[k] = P
        previous = time
    return out


def _times(t_s) -> np.ndarray:
    t = np.asarray(t_s, dtype=float).ravel()
    if t.size == 0 or t[0] < 0 or np.any(np.diff(t) < 0) or not np.all(np.isfinite(t)):
        raise InvalidParameter("t_s", "times must be finite and increasing from 0 s")
    return t


@renamed_keywords(duration_s="duration", step_s="step")
def loop_monte_carlo(A, K, C, Q, R, P0, duration: float, step: float, members: int, seed: int) -> np.ndarray:
    """Errors x_hat - x of the fixed-gain loop at ``duration`` over seeded Monte Carlo members.

    Truth and estimate are simulated together, d/dt [x; x_hat] = [[A, 0], [K C, A - K C]] [x; x_hat] +
    [w; K v] (w of PSD Q, v of PSD R: the estimate sees z = C x + v), discretised exactly (Van Loan,
    :func:`schuler.core.propagation.discretise_noise`) and vectorised across the members; x starts from
    N(0, P0) and x_hat from 0. Its sample covariance tests :func:`loop_error_covariance` and
    :func:`loop_covariance_history` without using them.

    Parameters
    ----------
    A : array_like, shape (n, n)
        System matrix, 1/s.
    K : array_like, shape (n, m)
        The loop's gain, state units per measurement unit per second.
    C : array_like, shape (m, n)
        Measurement matrix, measurement units per state unit.
    Q : array_like, shape (n, n)
        PSD of the process noise, (state units)^2/s.
    R : array_like, shape (m, m)
        PSD of the measurement noise, (measurement units)^2 s.
    P0 : array_like, shape (n, n)
        Covariance of the truth at t = 0, (state units)^2.
    duration : float
        Simulated time, s (> 0).
    step : float
        Step of the exact discretisation, s (> 0; the result does not depend on it).
    members : int
        Number of members (>= 2).
    seed : int
        Seed of the random generator.

    Returns
    -------
    ndarray, shape (members, n)
        The errors x_hat - x at the end, state units.

    Examples
    --------
    >>> e = loop_monte_carlo([[0.0]], [[2.0]], [[1.0]], [[4.0]], [[1.0]], [[0.0]], 10.0, 0.5, 4000, 1)
    >>> bool(abs(e.var() / 2.0 - 1.0) < 0.1)   # the optimal gain's steady variance sqrt(q r) = 2
    True
    """
    A, C, Q, R = _system(A, C, Q, R)
    n = A.shape[0]
    K = np.atleast_2d(np.asarray(K, dtype=float)).reshape(n, C.shape[0])
    if not (np.isfinite(duration) and np.isfinite(step) and duration > 0 and step > 0):
        raise InvalidParameter("duration_s", "duration and step must be finite and > 0 s")
    if int(members) < 2:
        raise InvalidParameter("members", f"needs at least 2 members, got {members!r}")
    from schuler.core.propagation import discretise_noise

    steps = max(1, int(np.ceil(duration / step - 1e-9)))
    F, W = _joint_loop(A, K, C, Q, R)
    Phi, Qd = discretise_noise(F, W, duration / steps)
    # a factor of the (possibly singular) step covariance: eigenvectors scaled by the roots of their eigenvalues
    values, vectors = np.linalg.eigh(Qd)
    root = vectors * np.sqrt(np.clip(values, 0.0, None))
    values0, vectors0 = np.linalg.eigh((np.atleast_2d(np.asarray(P0, dtype=float)) + 0.0).reshape(n, n))
    root0 = vectors0 * np.sqrt(np.clip(values0, 0.0, None))
    rng = np.random.default_rng(seed)
    z = np.zeros((int(members), 2 * n))
    z[:, :n] = rng.standard_normal((int(members), n)) @ root0.T
    for _ in range(steps):
        z = z @ Phi.T + rng.standard_normal(z.shape) @ root.T
    return z[:, n:] - z[:, :n]


@renamed_keywords(correlation_time_s="correlation_time")
def bias_state(sigma: float, correlation_time: float, rate_random_walk: float = 0.0) -> tuple[float, float]:
    """Decay rate and PSD of a bias state b' = -b / T + w: a first-order Gauss-Markov process plus a random walk.

    Spec 07: a Gauss-Markov bias of steady standard deviation sigma and correlation time T has PSD
    q = 2 sigma^2 / T; a rate random walk K adds K^2. With sigma = 0 the state is the random walk alone
    (no decay).

    Parameters
    ----------
    sigma : float
        Steady standard deviation of the Gauss-Markov part, bias units (rad/s or m/s^2); >= 0.
    correlation_time : float
        T, s (> 0).
    rate_random_walk : float
        K, bias units per sqrt(s); >= 0.

    Returns
    -------
    (float, float)
        The decay rate 1/T (0 without a Gauss-Markov part), 1/s, and the PSD q, (bias units)^2/s.

    Examples
    --------
    >>> bias_state(2.0, 100.0), bias_state(0.0, 100.0, 0.1)
    ((0.01, 0.08), (0.0, 0.010000000000000002))
    """
    values = (sigma, correlation_time, rate_random_walk)
    if not all(np.isfinite(v) and v >= 0 for v in values) or correlation_time <= 0:
        raise InvalidParameter("bias", f"sigma, K must be finite and >= 0 and T > 0 s, got {values}")
    decay = 1.0 / correlation_time if sigma > 0 else 0.0
    return decay, 2.0 * sigma**2 * decay + rate_random_walk**2


def _mirrored(poly: np.ndarray) -> np.ndarray:
    """Coefficients of p(-s) from those of p(s) (highest power first)."""
    powers = np.arange(poly.size - 1, -1, -1)
    return poly * np.where(powers % 2, -1.0, 1.0)


def noise_ratios_for_gain(A, C, K, noise_inputs) -> np.ndarray:
    """For which noise a single-output loop's fixed gain K is the steady-state Kalman gain: the PSD ratios q_i / r.

    With white noises of PSD q_i entering through the columns g_i of ``noise_inputs`` and one measurement of
    PSD r, the optimal loop's characteristic polynomial Delta(s) = det(sI - A + K C) obeys the return-difference
    identity Delta(s) Delta(-s) = a(s) a(-s) + sum_i (q_i / r) n_i(s) n_i(-s), with a(s) = det(sI - A) and
    n_i(s) = C adj(sI - A) g_i = det(sI - A + g_i C) - a(s) (Kailath, Sayed and Hassibi 2000, Sec. 16.5; spec 07).
    Solved for the q_i / r; gains with no non-negative solution are optimal for no such noise. For an observable
    pair (A, C), Delta fixes K, so the answer is unique up to r.

    Parameters
    ----------
    A : array_like, shape (n, n)
        System matrix, 1/s.
    C : array_like, shape (1, n)
        Measurement matrix, measurement units per state unit.
    K : array_like, shape (n, 1)
        The loop's gain, state units per measurement unit per second.
    noise_inputs : array_like, shape (n, k)
        Columns g_i: how each noise enters the state derivatives, state units per second per noise unit.

    Returns
    -------
    ndarray, shape (k,)
        q_i / r, (noise units)^2 / (measurement units)^2 / s^2.

    Raises
    ------
    InvalidParameter
        When the loop is not stable, or the identity has no solution with q_i >= 0 (the return-difference
    condition |1 + L(jw)| >= 1 fails).

    Examples
    --------
    The random walk measured in white noise: gain k is optimal for q / r = k^2.

    >>> noise_ratios_for_gain([[0.0]], [[1.0]], [[3.0]], [[1.0]]).round(12).tolist()
    [9.0]
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    C = np.atleast_2d(np.asarray(C, dtype=float))
    n = A.shape[0]
    K = np.asarray(K, dtype=float).reshape(n, 1)
    G = np.asarray(noise_inputs, dtype=float).reshape(n, -1)
    if C.shape != (1, n):
        raise InvalidParameter("loop", f"one measurement is needed: C has shape {C.shape}")
    if np.max(np.linalg.eigvals(A - K @ C).real) >= 0:
        raise InvalidParameter("gain", "the loop A - K C is not stable: no Kalman filter has these gains")
    a = np.poly(A)
    delta = np.poly(A - K @ C)
    target: np.ndarray = np.polysub(np.polymul(delta, _mirrored(delta)), np.polymul(a, _mirrored(a)))
    basis = []
    for g in G.T:
        numerator = np.polysub(np.poly(A - np.outer(g, C[0])), a)
        product = np.polymul(numerator, _mirrored(numerator))
        basis.append(np.concatenate([np.zeros(2 * n + 1 - product.size), product]))
    target = np.concatenate([np.zeros(2 * n + 1 - target.size), target])
    M = np.array(basis).T[::2]  # the identity holds in s^2: the odd powers vanish on both sides
    target = target[::2]
    # what the cancellation in the target is made of: its rounding, and the weight of each power in the solve
    size = (np.polymul(np.abs(delta), np.abs(delta)) + np.polymul(np.abs(a), np.abs(a)))[::2]
    scale = np.maximum(np.max(np.abs(M), axis=1), size * 1e-12) + 1e-300
    ratios = np.linalg.lstsq(M / scale[:, None], target / scale, rcond=None)[0]
    tolerance = 1e-8 * (size + np.abs(M) @ np.abs(ratios))
    negative = ratios < -1e-9 * max(1e-300, float(np.max(np.abs(ratios))))
    if np.any(np.abs(M @ ratios - target) > tolerance) or np.any(negative):
        raise InvalidParameter("gain", f"the gains {K.ravel().tolist()} are optimal for no noise of this model: the "
                                       "return-difference condition |1 + L(jw)| >= 1 fails")
    return np.clip(ratios, 0.0, None)
