"""The KPI gyrocompassing loop beside the Kalman filter of the same sensors (``schuler align optimal``).

The simplified loop (1.19) of the KPI manual (Meleshko, :data:`schuler.references.KPI_LAB_MANUAL`),
beta' = -c_Gamma (beta + eps_beta) - Delta omega_dxi + delta U_eta,
delta' = -c_a (beta + eps_beta) + Delta omega_dz - Delta U_z,
is the fixed-gain form x_hat' = A x_hat + K (z - C x_hat) of an estimator of the platform errors
x = (beta, delta) from the level accelerometer z = beta + eps_beta, with A = [[0, U_eta], [0, 0]],
C = [1, 0] and K = (c_Gamma, c_a): A - K C has the characteristic polynomial p^2 + c_Gamma p + c_a U_eta of
(1.20). The gyro drifts are split into white noise (angle random walk N, PSD N^2), a Gauss-Markov part
b (states 3 and 4 of x as b / U_eta, correlation time tau: the bias instability B as sigma = B / 0.9294 and the
IMU's Gauss-Markov terms, driven also by its rate random walk K) and a constant part c (the residual
after calibration, :func:`schuler.imu.system_inputs.align_inputs`), whose error is added
deterministically: e_ss = -(A - K C)^-1 G c for each drift, the two combined as independent 1-sigma
offsets; for the seed's gains the terms are those of (1.21),
delta_y = (c_Gamma / (c_a U_eta)) Delta omega_dz + Delta omega_dxi / U_eta (spec 07: a constant east
drift makes the Riccati equation degenerate, as it cannot be told from azimuth). The accelerometer's
white noise (velocity random walk N_a) is the measurement noise, PSD r = (N_a / g)^2.

* :func:`loop_model`: A, C, Q, R of that model for an IMU;
* the seed's loop: K = (c_Gamma, c_a, 0, 0), its error covariance from the Lyapunov equation
  (:func:`schuler.core.steady_state.loop_error_covariance`);
* the optimal loop: the steady-state Kalman-Bucy gain (:func:`schuler.core.steady_state.steady_state_gain`);
* the map gains <-> (T, zeta) (:func:`schuler.core.gyrocompass_design.loop_design`), and back, for the
  white-noise loop (bias states left out): the algebraic Riccati equation gives in closed form
  c_a = sqrt(q_delta / r), c_Gamma^2 = q_beta / r + 2 c_a U_eta, so zeta^2 = 1/2 + q_beta / (4 r omega0^2):
  a pair of gains is optimal for some noise only when zeta >= 1/sqrt(2) (spec 07's return-difference
  condition), and then for q_beta / r = c_Gamma^2 - 2 c_a U_eta, q_delta / r = c_a^2 (:func:`noise_for_gains`);
* settling time 5 / min(-Re p) over the loop's poles (the manual's 5 / h, and its corrected aperiodic
  form, for the seed's second-order loop).

References
----------
R. E. Kalman and R. S. Bucy, "New results in linear filtering and prediction theory", *Trans. ASME,
J. Basic Eng.* 83(1), 1961.
T. Kailath, A. H. Sayed and B. Hassibi, *Linear Estimation*, Prentice Hall, 2000, ch. 16 (return difference).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.core.geometry import horizontal_earth_rate
from schuler.core.gyrocompass_design import DESIGN_DAMPING, DESIGN_TIME_CONSTANT, loop_design, loop_gains
from schuler.core.steady_state import loop_error_covariance, riccati_solution, steady_state_gain
from schuler.exceptions import InvalidParameter, renamed_keywords

GAUSS_MARKOV_PEAK_RATIO = 1.893
"""tau / T at the Allan-deviation peak of a first-order Gauss-Markov process (:mod:`schuler.imu.error_model`)."""

MAX_STEP_POLES = 20.0
"""Longest step of the time-varying gain's solution, in time constants of the loop's fastest pole."""

SETTLING_FACTOR = 5.0
"""Settling time = this / the slowest pole's decay rate (the KPI manual's t = 5 / h)."""


@dataclass(frozen=True)
class LoopNoise:
    """The sensor noise of the loop, SI.

    Attributes
    ----------
    gyro_noise : float
        Angle random walk N of the horizontal (east) gyro, rad/sqrt(s).
    gyro_noise_z : float
        N of the vertical gyro, rad/sqrt(s).
    accel_noise : float
        Velocity random walk N_a of the level accelerometer, m/s/sqrt(s) (> 0).
    bias_sigma, bias_sigma_z : float
        Stationary sigma of the Gauss-Markov drift, rad/s.
    bias_random_walk, bias_random_walk_z : float
        Rate random walk K driving it as well, rad/s/sqrt(s).
    correlation_time : float
        tau of the Gauss-Markov drift, s.
    drift_east, drift_z : float
        Constant residual drifts Delta omega_dxi, Delta omega_dz, rad/s (their error is deterministic).
    """

    gyro_noise: float
    gyro_noise_z: float
    accel_noise: float
    bias_sigma: float = 0.0
    bias_sigma_z: float = 0.0
    bias_random_walk: float = 0.0
    bias_random_walk_z: float = 0.0
    correlation_time: float = 1000.0 / GAUSS_MARKOV_PEAK_RATIO
    drift_east: float = 0.0
    drift_z: float = 0.0

    def __post_init__(self):
        for name, value in vars(self).items():
            if not (math.isfinite(value) and value >= 0) and not name.startswith("drift"):
                raise InvalidParameter(name, f"must be finite and >= 0, got {value}")
        if not self.accel_noise > 0:
            raise InvalidParameter("accel_noise", "the accelerometer noise must be > 0 (it is the measurement noise)")
        if not self.correlation_time > 0:
            raise InvalidParameter("correlation_time", "must be > 0 s")


@renamed_keywords(window_s="window")
def noise_from_imu(model, window: float = 600.0, correlation_time: float | None = None) -> LoopNoise:
    """The loop's noise from an IMU error model (a grade, a spec sheet or a recording's identified terms).

    White noise: the rms N of the two horizontal gyros and accelerometers, the z gyro's N. Drift: the
    Gauss-Markov sigma sqrt(sigma_GM^2 + (B / 0.9294)^2) (the largest axis), tau the model's longest
    Gauss-Markov time, else its flicker range's upper end / 1.893; the rate random walk K. Constant part: the
    residual drift after calibration of ``align`` (:func:`schuler.imu.system_inputs.align_inputs`).

    Parameters
    ----------
    model : schuler.imu.error_model.ErrorModel
        The IMU, SI.
    window : float
        Time between the gyro calibration and the alignment, s.
    correlation_time : float, optional
        tau of the Gauss-Markov drift, s (not set: from the model).
    """
    from schuler.imu.error_model import gauss_markov_for_bias_instability
    from schuler.imu.system_inputs import align_inputs

    gyro, accel = model.gyro, model.accel
    sigma = np.sqrt(gyro.gm_sigma**2 + gauss_markov_for_bias_instability(1.0)**2 * gyro.bias_instability**2)
    if correlation_time is None:
        correlation_time = float(np.max(gyro.gm_correlation_time_s)) if np.any(gyro.gm_sigma > 0) \
            else gyro.flicker_tau_range_s[1] / GAUSS_MARKOV_PEAK_RATIO
    drift = align_inputs(model, window=window).values
    return LoopNoise(gyro_noise=float(np.hypot(*gyro.random_walk[:2]) / math.sqrt(2)),
                     gyro_noise_z=float(gyro.random_walk[2]),
                     accel_noise=float(np.hypot(*accel.random_walk[:2]) / math.sqrt(2)),
                     bias_sigma=float(np.max(sigma[:2])), bias_sigma_z=float(sigma[2]),
                     bias_random_walk=float(np.max(gyro.rate_random_walk[:2])),
                     bias_random_walk_z=float(gyro.rate_random_walk[2]), correlation_time=float(correlation_time),
                     drift_east=drift["drift_east"], drift_z=drift["drift_z"])


def loop_model(noise: LoopNoise, latitude: float, earth_rate: float = EARTH_RATE, gravity: float = STANDARD_GRAVITY):
    """A, C, Q, R and the constant-drift input G of the loop (1.19) with Gauss-Markov drift states.

    x = (beta, delta, b_xi / U_eta, b_z / U_eta) (the drifts as the azimuth they are worth, rad):
    beta' = U_eta (delta - x_3), delta' = U_eta x_4, x_3,4' = -x_3,4 / tau, plus white noise of PSD
    Q = diag(N^2, N_z^2, (2 sigma^2 / tau + K^2) / U_eta^2, (2 sigma_z^2 / tau + K_z^2) / U_eta^2);
    z = beta + eps_beta, PSD R = (N_a / g)^2.

    Parameters
    ----------
    noise : LoopNoise
        Sensor noise, SI.
    latitude : float
        phi, rad (U_eta = U cos phi; near the poles :class:`schuler.exceptions.InvalidParameter`).
    earth_rate : float
        U, rad/s.
    gravity : float
        g, m/s^2.

    Returns
    -------
    A, C, Q, R, G : ndarray
        (4, 4) 1/s, (1, 4), (4, 4) rad^2/s, (1, 1) rad^2 s, (4, 2) (constant drifts (c_xi, c_z), rad/s, to x').
    """
    U_eta = float(horizontal_earth_rate(latitude, earth_rate))
    tau = noise.correlation_time
    # the drift states in rad of azimuth (b / U_eta) keep P's entries of one size: the Riccati solutions stay exact
    A = np.array([[0.0, U_eta, -U_eta, 0.0], [0.0, 0.0, 0.0, U_eta], [0.0, 0.0, -1.0 / tau, 0.0],
                  [0.0, 0.0, 0.0, -1.0 / tau]])
    C = np.array([[1.0, 0.0, 0.0, 0.0]])
    Q = np.diag([noise.gyro_noise**2, noise.gyro_noise_z**2,
                 (2.0 * noise.bias_sigma**2 / tau + noise.bias_random_walk**2) / U_eta**2,
                 (2.0 * noise.bias_sigma_z**2 / tau + noise.bias_random_walk_z**2) / U_eta**2])
    R = np.array([[(noise.accel_noise / gravity) ** 2]])
    G = np.array([[-1.0, 0.0], [0.0, 1.0], [0.0, 0.0], [0.0, 0.0]])
    return A, C, Q, R, G


@dataclass(frozen=True)
class LoopAccuracy:
    """A loop's gains and what they give, SI (the JSON of ``align optimal``'s ``seed`` and ``optimal``)."""

    time_constant_s: float
    damping: float
    c_gamma: float
    c_a: float
    azimuth_error_sigma_rad: float
    azimuth_error_bias_rad: float
    settling_time_s: float
    bias_gains: tuple[float, float]


def loop_accuracy(gain, noise: LoopNoise, latitude: float, earth_rate: float = EARTH_RATE,
                  gravity: float = STANDARD_GRAVITY) -> LoopAccuracy:
    """The accuracy of the loop with gain K = (c_Gamma, c_a, k_bxi, k_bz): Lyapunov sigma, (1.21)-type bias, time.

    Parameters
    ----------
    gain : array_like, shape (4,) or (2,)
        c_Gamma, c_a and the gains of the drift states (b / U_eta, :func:`loop_model`), 1/s (not given: 0,
        the seed's loop).
    noise : LoopNoise
        Sensor noise, SI.
    latitude : float
        phi, rad.
    earth_rate : float
        U, rad/s.
    gravity : float
        g, m/s^2.
    """
    A, C, Q, R, G = loop_model(noise, latitude, earth_rate, gravity)
    K = np.zeros(4)
    given = np.asarray(gain, dtype=float).ravel()
    K[:given.size] = given
    P = loop_error_covariance(A, K[:, None], C, Q, R)
    closed = A - K[:, None] @ C
    # each drift's steady error on its own, combined as independent 1-sigma offsets (their signs are unknown)
    bias = np.hypot(*(-np.linalg.solve(closed, G * np.array([noise.drift_east, noise.drift_z]))).T)
    # without drift gains the drift states are the process's own, not the loop's: their poles are left out
    poles = np.linalg.eigvals(closed if np.any(K[2:]) else closed[:2, :2])
    T, zeta = loop_design(latitude, K[0], K[1], earth_rate)
    return LoopAccuracy(float(T), float(zeta), float(K[0]), float(K[1]), float(math.sqrt(P[1, 1])),
                        float(bias[1]), SETTLING_FACTOR / float(np.min(-poles.real)), (float(K[2]), float(K[3])))


def seed_accuracy(noise: LoopNoise, latitude: float, time_constant: float = DESIGN_TIME_CONSTANT,
                  damping: float = DESIGN_DAMPING, earth_rate: float = EARTH_RATE,
                  gravity: float = STANDARD_GRAVITY) -> LoopAccuracy:
    """The KPI design c_Gamma = 2 zeta / T, c_a = 1 / (T^2 U_eta) on these sensors (:func:`loop_accuracy`).

    Parameters
    ----------
    noise : LoopNoise
        Sensor noise, SI.
    latitude : float
        phi, rad.
    time_constant : float
        T, s.
    damping : float
        zeta, dimensionless.
    earth_rate : float
        U, rad/s.
    gravity : float
        g, m/s^2.
    """
    c_gamma, c_a = loop_gains(latitude, time_constant, damping, earth_rate)
    return loop_accuracy((float(c_gamma), float(c_a)), noise, latitude, earth_rate, gravity)


def optimal_accuracy(noise: LoopNoise, latitude: float, earth_rate: float = EARTH_RATE,
                     gravity: float = STANDARD_GRAVITY) -> LoopAccuracy:
    """The steady-state Kalman-Bucy filter of :func:`loop_model` (its gain from the ARE) as a loop.

    Parameters
    ----------
    noise : LoopNoise
        Sensor noise, SI.
    latitude : float
        phi, rad.
    earth_rate : float
        U, rad/s.
    gravity : float
        g, m/s^2.
    """
    A, C, Q, R, _ = loop_model(noise, latitude, earth_rate, gravity)
    return loop_accuracy(steady_state_gain(A, C, Q, R).gain[:, 0], noise, latitude, earth_rate, gravity)


def gains_for_noise(q_beta: float, q_delta: float, r: float, latitude: float, earth_rate: float = EARTH_RATE):
    """The optimal (c_Gamma, c_a) of the white-noise loop (module docstring: the ARE in closed form).

    Parameters
    ----------
    q_beta, q_delta : float
        PSD of the east and vertical gyro white noise, rad^2/s.
    r : float
        PSD of the measurement noise, rad^2 s (> 0).
    latitude : float
        phi, rad.
    earth_rate : float
        U, rad/s.

    Returns
    -------
    c_gamma, c_a : float
        1/s.

    Examples
    --------
    >>> c_gamma, c_a = gains_for_noise(*noise_for_gains(0.0533, 23.7, math.radians(50)), 1.0, math.radians(50))
    >>> round(c_gamma, 4), round(c_a, 2)
    (0.0533, 23.7)
    """
    if not r > 0 or q_beta < 0 or q_delta < 0:
        raise InvalidParameter("noise", "the PSDs must be >= 0 and the measurement noise's > 0")
    U_eta = float(horizontal_earth_rate(latitude, earth_rate))
    c_a = math.sqrt(q_delta / r)
    return math.sqrt(q_beta / r + 2.0 * c_a * U_eta), c_a


def noise_for_gains(c_gamma: float, c_a: float, latitude: float, earth_rate: float = EARTH_RATE):
    """The noise ratios (q_beta / r, q_delta / r) for which (c_Gamma, c_a) are the white-noise loop's optimum.

    Parameters
    ----------
    c_gamma, c_a : float
        Gains, 1/s.
    latitude : float
        phi, rad.
    earth_rate : float
        U, rad/s.

    Returns
    -------
    q_beta_over_r, q_delta_over_r : float
        1/s^2.

    Raises
    ------
    InvalidParameter
        When zeta < 1/sqrt(2): no noise makes the gains optimal (return-difference condition).
    """
    U_eta = float(horizontal_earth_rate(latitude, earth_rate))
    q_beta = c_gamma**2 - 2.0 * c_a * U_eta
    if not (c_a > 0 and q_beta >= 0):
        raise InvalidParameter("damping", "the gains are optimal for no noise: zeta < 1/sqrt(2) fails the "
                               "return-difference condition")
    return q_beta, c_a**2


def accuracy_versus_time_constant(noise: LoopNoise, latitude: float, time_constants, damping: float = DESIGN_DAMPING,
                                  earth_rate: float = EARTH_RATE, gravity: float = STANDARD_GRAVITY) -> np.ndarray:
    """The KPI loop's azimuth error at each T (zeta fixed): noise sigma and constant-drift error, rad.

    Parameters
    ----------
    noise : LoopNoise
        Sensor noise, SI.
    latitude : float
        phi, rad.
    time_constants : array_like
        T, s.
    damping : float
        zeta, dimensionless.
    earth_rate : float
        U, rad/s.
    gravity : float
        g, m/s^2.

    Returns
    -------
    ndarray, shape (k, 2)
        sigma and bias, rad.
    """
    rows = [seed_accuracy(noise, latitude, T, damping, earth_rate, gravity) for T in np.asarray(time_constants)]
    return np.array([(row.azimuth_error_sigma_rad, row.azimuth_error_bias_rad) for row in rows])


def best_time_constant(noise: LoopNoise, latitude: float, damping: float = DESIGN_DAMPING, bounds=(1.0, 3600.0),
                       earth_rate: float = EARTH_RATE, gravity: float = STANDARD_GRAVITY) -> float:
    """The T of the KPI loop (zeta fixed) with the least total azimuth error sqrt(sigma^2 + bias^2), s.

    Parameters
    ----------
    noise : LoopNoise
        Sensor noise, SI.
    latitude : float
        phi, rad.
    damping : float
        zeta, dimensionless.
    bounds : (float, float)
        Range of T searched, s.
    earth_rate : float
        U, rad/s.
    gravity : float
        g, m/s^2.
    """
    from scipy.optimize import minimize_scalar

    def total(log_t):
        row = seed_accuracy(noise, latitude, math.exp(log_t), damping, earth_rate, gravity)
        return math.hypot(row.azimuth_error_sigma_rad, row.azimuth_error_bias_rad)

    best = minimize_scalar(total, bounds=tuple(math.log(b) for b in bounds), method="bounded",
                           options={"xatol": 1e-6})
    return float(math.exp(best.x))


def gain_history(noise: LoopNoise, latitude: float, P0, t_s, earth_rate: float = EARTH_RATE,
                 gravity: float = STANDARD_GRAVITY) -> np.ndarray:
    """The time-varying Kalman-Bucy gain K(t) = P(t) C^T R^-1 over an alignment from P(0) = P0.

    Parameters
    ----------
    noise : LoopNoise
        Sensor noise, SI.
    latitude : float
        phi, rad.
    P0 : array_like, shape (4, 4)
        Initial covariance of the states of :func:`loop_model`, rad^2.
    t_s : array_like
        Times from 0, s.
    earth_rate : float
        U, rad/s.
    gravity : float
        g, m/s^2.

    Returns
    -------
    ndarray, shape (k, 4)
        The gain at each time, 1/s (c_Gamma, c_a, then the drift states of :func:`loop_model`).
    """
    A, C, Q, R, _ = loop_model(noise, latitude, earth_rate, gravity)
    t = np.asarray(t_s, dtype=float).ravel()
    if t.size == 0 or t[0] < 0 or np.any(np.diff(t) < 0):
        raise InvalidParameter("t_s", "times must be increasing from 0 s")
    # steps longer than a few time constants of the fastest pole overflow the exact step: solve on a finer grid
    fastest = float(np.max(np.abs(steady_state_gain(A, C, Q, R).poles)))
    step = MAX_STEP_POLES / fastest
    fine = np.unique(np.concatenate([t, np.arange(0.0, t[-1], step)]))
    P = riccati_solution(A, C, Q, R, P0, fine)[np.searchsorted(fine, t)]
    return P[:, :, 0] / R[0, 0]
