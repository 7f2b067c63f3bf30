"""Closed forms of gyrocompassing (the KPI manual): steady state, transient, settling time.

All functions take SI floats or arrays (broadcast together) and return arrays:
angles in rad, rates in rad/s, gains c_gamma and c_a in 1/s, times in s.
Symbols follow the source: c_gamma (c_Gamma), c_a, U_eta = U cos(phi),
h = c_gamma / 2, omega0^2 = c_a U_eta. U_eta is the core's
:func:`~schuler.core.geometry.horizontal_earth_rate`: every closed form here
raises :class:`~schuler.exceptions.NotObservable` at the poles, where it vanishes.
"""

from __future__ import annotations

import numpy as np

from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.core.geometry import earth_rate_north_up, horizontal_earth_rate

SETTLING_DECREMENTS = 5.0
"""Settling time = 5 time constants of the slowest mode (the KPI manual: t = 5 / h)."""


def accelerometer_tilts(azimuth, accel_error_x, accel_error_y, gravity=STANDARD_GRAVITY):
    """Accelerometer errors as tilts: eps_beta = Delta a_eta / g and eps_alpha, rad.

    eps_beta = eps_y cos A - eps_x sin A, eps_alpha = -(eps_x cos A + eps_y sin A)
    with eps_x = Delta a_x / g, eps_y = Delta a_y / g: (1.17) rotated by (1.11).
    The source's closing line prints eps_beta = (Delta a_x sin A + Delta a_y cos A) / g,
    with the wrong sign on Delta a_x.

    Parameters
    ----------
    azimuth : float or ndarray
        A, rad.
    accel_error_x, accel_error_y : float or ndarray
        Delta a_x, Delta a_y, m/s^2.
    gravity : float
        g, m/s^2.

    Examples
    --------
    >>> eps_beta, eps_alpha = accelerometer_tilts(0.0, 0.0, 9.80665e-4)
    >>> round(float(eps_beta), 12), round(float(eps_alpha), 12)
    (0.0001, 0.0)
    """
    A = np.asarray(azimuth, dtype=float)
    eps_x = np.asarray(accel_error_x, dtype=float) / gravity
    eps_y = np.asarray(accel_error_y, dtype=float) / gravity
    return eps_y * np.cos(A) - eps_x * np.sin(A), -(eps_x * np.cos(A) + eps_y * np.sin(A))


def steady_state(latitude, c_gamma, c_a, drift_east=0.0, drift_up=0.0, latitude_error=0.0, eps_beta=0.0,
                 earth_rate=EARTH_RATE):
    """Steady state of the simplified model (1.19): azimuth (1.21) and level (1.25) errors.

    delta_y = c_gamma / (c_a U cos phi) dw_dz - (c_gamma / c_a) dphi + dw_dxi / (U cos phi)
    beta_y  = -eps_beta + (dw_dz - U cos(phi) dphi) / c_a

    The azimuth error does not depend on the accelerometer errors (they shift
    only beta_y); the dominant term is dw_dxi / (U cos phi).

    Parameters
    ----------
    latitude : float or ndarray
        phi, rad.
    c_gamma, c_a : float or ndarray
        Gains, 1/s.
    drift_east : float or ndarray
        Residual drift about the east axis, dw_dxi = dw_dx cos A + dw_dy sin A, rad/s.
    drift_up : float or ndarray
        Residual drift about the vertical, dw_dz, rad/s.
    latitude_error : float or ndarray
        dphi, rad.
    eps_beta : float or ndarray
        Accelerometer error about the east axis, Delta a_eta / g, rad.
    earth_rate : float
        U, rad/s.

    Returns
    -------
    delta_y, beta_y : ndarray
        rad.

    Examples
    --------
    0.01 deg/h residual east drift at 50 deg latitude:

    >>> delta_y, _ = steady_state(np.radians(50), 0.0533, 23.7, drift_east=np.radians(0.01) / 3600)
    >>> round(float(np.degrees(delta_y) * 60), 3)
    3.556
    """
    U_eta = horizontal_earth_rate(latitude, earth_rate)
    c_gamma = np.asarray(c_gamma, dtype=float)
    c_a = np.asarray(c_a, dtype=float)
    dphi = np.asarray(latitude_error, dtype=float)
    delta_y = c_gamma / (c_a * U_eta) * drift_up - c_gamma / c_a * dphi + np.asarray(drift_east, dtype=float) / U_eta
    beta_y = -np.asarray(eps_beta, dtype=float) + (drift_up - U_eta * dphi) / c_a
    return delta_y, beta_y


def full_steady_state(latitude, c_gamma, c_a, drift_east=0.0, drift_north=0.0, drift_up=0.0, latitude_error=0.0,
                      eps_beta=0.0, eps_alpha=0.0, earth_rate=EARTH_RATE):
    """Steady state of the full model (1.18) (identical for (1.17) corrected), in closed form.

    Setting the derivatives of (1.18) to zero and solving from the third line up:

        beta  = (dw_dz - dU_z - c_a eps_beta) / (c_a + U_eta)
        alpha = (dU_eta - dw_deta - beta U_z) / c_gamma - eps_alpha
        delta = (c_gamma (beta + eps_beta) + dw_dxi - alpha U_z) / U_eta

    with dU_z = U cos(phi) dphi, dU_eta = -U sin(phi) dphi. Unlike (1.21), the
    azimuth error now feels the accelerometers through alpha U_z: about
    eps_alpha tan(phi) (e.g. 100 micro-g gives 24.6 arcsec at 50 deg); and the
    latitude error tilts alpha by dU_eta / c_gamma, adding U_z^2 dphi / (c_gamma U_eta)
    to (1.21)'s -(c_gamma / c_a) dphi (at 50 deg, T = 30 s, zeta = 0.8: +0.075 vs
    -0.135 arcsec per arcmin).

    Parameters
    ----------
    latitude : float or ndarray
        phi, rad.
    c_gamma, c_a : float or ndarray
        Gains, 1/s.
    drift_east, drift_north, drift_up : float or ndarray
        Residual drifts dw_dxi, dw_deta, dw_dz, rad/s.
    latitude_error : float or ndarray
        dphi, rad.
    eps_beta, eps_alpha : float or ndarray
        Accelerometer errors about the east and north axes over g, rad.
    earth_rate : float
        U, rad/s.

    Returns
    -------
    delta, beta, alpha : ndarray
        rad.

    Examples
    --------
    >>> d, b, a = full_steady_state(np.radians(50), 0.0533, 23.7, eps_alpha=1e-4)
    >>> round(float(np.degrees(d) * 3600), 1)
    24.6
    """
    U_eta = horizontal_earth_rate(latitude, earth_rate)
    _, U_z = earth_rate_north_up(latitude, earth_rate)
    c_gamma = np.asarray(c_gamma, dtype=float)
    c_a = np.asarray(c_a, dtype=float)
    dphi = np.asarray(latitude_error, dtype=float)
    eps_beta = np.asarray(eps_beta, dtype=float)
    beta = (drift_up - U_eta * dphi - c_a * eps_beta) / (c_a + U_eta)
    alpha = (-U_z * dphi - np.asarray(drift_north, dtype=float) - beta * U_z) / c_gamma - eps_alpha
    delta = (c_gamma * (beta + eps_beta) + drift_east - alpha * U_z) / U_eta
    return delta, beta, alpha


def azimuth_error_sigma(latitude, c_gamma, c_a, sigma_drift_east=0.0, sigma_drift_up=0.0, sigma_latitude_error=0.0,
                        earth_rate=EARTH_RATE):
    """Analytic 1-sigma of the azimuth error (1.21) for independent zero-mean errors, rad.

    sigma_delta^2 = (sigma_xi / U_eta)^2 + (c_gamma sigma_z / (c_a U_eta))^2 + (c_gamma sigma_phi / c_a)^2.
    Accelerometer errors do not enter the simplified model's azimuth error.

    Parameters
    ----------
    latitude : float or ndarray
        phi, rad.
    c_gamma, c_a : float or ndarray
        Gains, 1/s.
    sigma_drift_east, sigma_drift_up : float or ndarray
        1-sigma of the residual drifts dw_dxi and dw_dz, rad/s.
    sigma_latitude_error : float or ndarray
        1-sigma of dphi, rad.
    earth_rate : float
        U, rad/s.

    Examples
    --------
    >>> s = azimuth_error_sigma(np.radians(50), 0.0533, 23.7, sigma_drift_east=np.radians(0.01) / 3600)
    >>> round(float(np.degrees(s) * 60), 3)
    3.556
    """
    U_eta = horizontal_earth_rate(latitude, earth_rate)
    ratio = np.asarray(c_gamma, dtype=float) / np.asarray(c_a, dtype=float)
    return np.sqrt(
        (np.asarray(sigma_drift_east) / U_eta) ** 2
        + (ratio * np.asarray(sigma_drift_up) / U_eta) ** 2
        + (ratio * np.asarray(sigma_latitude_error)) ** 2
    )


def steady_state_gain_matrix(A, B) -> np.ndarray:
    """Steady-state gains G = -A^{-1} B of a stable linear model (x_ss = G u), batched.

    Parameters
    ----------
    A : ndarray, shape (..., n, n)
        State matrix, SI (1/s).
    B : ndarray, shape (..., n, m)
        Input matrix, SI.

    Examples
    --------
    >>> steady_state_gain_matrix(np.array([[-2.0]]), np.array([[1.0]]))
    array([[0.5]])
    """
    return -np.linalg.solve(A, B)


def settling_time(c_gamma, c_a, latitude, earth_rate=EARTH_RATE) -> np.ndarray:
    """Gyrocompassing time t = 5 / h (oscillatory, critical) or 5 / (h - sqrt(h^2 - omega0^2)) (aperiodic), s.

    h = c_gamma / 2, omega0^2 = c_a U_eta. The aperiodic formula is the source's
    corrected: it prints 5 / (-h + sqrt(h^2 - omega0^2)), which is negative; the
    slow root p = -h + sqrt(h^2 - omega0^2) decays with time constant
    1 / (h - sqrt(h^2 - omega0^2)). Both forms meet at h = omega0.

    Parameters
    ----------
    c_gamma, c_a : float or ndarray
        Gains, 1/s.
    latitude : float or ndarray
        phi, rad.
    earth_rate : float
        U, rad/s.

    Examples
    --------
    >>> round(float(settling_time(2 * 0.8 / 30, 1 / (900 * 7.292115e-5), 0.0)), 2)
    187.5
    """
    h = np.asarray(c_gamma, dtype=float) / 2.0
    omega0_sq = np.asarray(c_a, dtype=float) * horizontal_earth_rate(latitude, earth_rate)
    excess = np.maximum(h**2 - omega0_sq, 0.0)
    # h - sqrt(h^2 - w0^2) written as w0^2 / (h + sqrt(...)) to keep precision when h >> w0
    slow = np.where(h**2 > omega0_sq, omega0_sq / (h + np.sqrt(excess)), h)
    return SETTLING_DECREMENTS / slow


def transient(time, delta0, delta_rate0, delta_y, c_gamma, c_a, latitude, earth_rate=EARTH_RATE) -> np.ndarray:
    """Solution of (1.20) delta'' + c_gamma delta' + c_a U_eta delta = const, tending to delta_y.

    Oscillatory (omega0 > h), (1.22)::

        delta = e^(-h t) [(delta0 - delta_y) cos(w t) + (delta'0 + h (delta0 - delta_y)) / w sin(w t)] + delta_y,
        w = sqrt(omega0^2 - h^2).

    Aperiodic (h > omega0), (1.24)::

        delta = C1 e^(p1 t) + C2 e^(p2 t) + delta_y,
        p1,2 = -h +- sqrt(h^2 - omega0^2), C2 = (delta'0 - (delta0 - delta_y) p1) / (p2 - p1),
        C1 = delta0 - delta_y - C2 (printed with "delta_2" for delta_y).

    Critical (h = omega0)::

        delta = (C1 + C2 t) e^(-h t) + delta_y, C1 = delta0 - delta_y,
        C2 = delta'0 + h (delta0 - delta_y) (printed with delta'0 in place of delta0).

    The same form holds for beta with its own initial values and beta_y (1.25).

    Parameters
    ----------
    time : ndarray
        t, s (shape (n_time,)).
    delta0, delta_rate0, delta_y : float
        Initial value (rad), initial rate (rad/s) and steady state (rad).
    c_gamma, c_a : float
        Gains, 1/s.
    latitude : float
        phi, rad.
    earth_rate : float
        U, rad/s.

    Examples
    --------
    >>> t = np.array([0.0, 1e4])
    >>> np.round(transient(t, 0.01, 0.0, 0.001, 0.0533, 23.7, 0.87), 12)
    array([0.01 , 0.001])
    """
    t = np.asarray(time, dtype=float)
    h = float(c_gamma) / 2.0
    omega0_sq = float(c_a) * float(horizontal_earth_rate(latitude, earth_rate))
    offset = delta0 - delta_y
    discriminant = h**2 - omega0_sq
    # critical when the roots coincide to rounding: both other forms divide by their difference
    if abs(discriminant) <= 1e-12 * h**2:
        return (offset + (delta_rate0 + h * offset) * t) * np.exp(-h * t) + delta_y
    if discriminant < 0:
        w = np.sqrt(-discriminant)
        return np.exp(-h * t) * (offset * np.cos(w * t) + (delta_rate0 + h * offset) / w * np.sin(w * t)) + delta_y
    root = np.sqrt(discriminant)
    p1, p2 = -h + root, -h - root
    C2 = (delta_rate0 - offset * p1) / (p2 - p1)
    return (offset - C2) * np.exp(p1 * t) + C2 * np.exp(p2 * t) + delta_y


def band_settling_time(time, signal, final, initial, band=0.01) -> np.ndarray:
    """Time after which ``signal`` stays within ``band`` x |initial - final| of ``final``.

    Parameters
    ----------
    time : ndarray, shape (n_time,)
        s.
    signal : ndarray, shape (n_time,) or (N, n_time)
        The transient, in any unit.
    final, initial : float or ndarray, shape () or (N,)
        Reference steady value and initial value, in the signal's unit.
    band : float
        Relative half-width of the band (0.01: 1 %).

    Returns
    -------
    ndarray
        The time of the first sample after the last one outside the band, s
        (0 if never outside, inf if still outside at the end).

    Examples
    --------
    >>> t = np.arange(5.0)
    >>> float(band_settling_time(t, np.array([1.0, 0.5, 0.02, 0.005, 0.0]), 0.0, 1.0))
    3.0
    """
    t = np.asarray(time, dtype=float)
    x = np.asarray(signal, dtype=float)
    final = np.asarray(final, dtype=float)[..., None]
    width = band * np.abs(np.asarray(initial, dtype=float)[..., None] - final)
    outside = np.abs(x - final) > width
    n = t.size
    any_outside = outside.any(axis=-1)
    last = n - 1 - np.argmax(outside[..., ::-1], axis=-1)
    settled = np.where(any_outside, t[np.minimum(last + 1, n - 1)], t[0])
    return np.where(any_outside & (last == n - 1), np.inf, settled)
