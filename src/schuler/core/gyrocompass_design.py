"""The KPI manual's gyrocompass loop design: the gains c_Gamma, c_a from a time constant T and damping zeta.

The KPI manual's gyrocompassing loop (its simplified model (1.19)) has the
characteristic polynomial (1.20) p^2 + c_Gamma p + c_a U_eta, with
U_eta = Omega cos L the horizontal Earth rate at latitude L. The manual (end of
its Sec. 2) designs it by matching this to a second-order loop of time constant T
and damping zeta, T^2 p^2 + 2 T zeta p + 1 = 0:

    c_Gamma = 2 zeta / T,    c_a = 1 / (T^2 U_eta),

so omega0^2 = c_a U_eta = 1 / T^2 and h = c_Gamma / 2 = zeta / T. Its design
example takes "often T = 30 s, zeta = 0.8" (:data:`DESIGN_TIME_CONSTANT`,
:data:`DESIGN_DAMPING`). Back from the gains (:func:`loop_design`):
T = 1 / sqrt(U_eta c_a), zeta = c_Gamma / (2 sqrt(U_eta c_a)).

Every gyrocompass that uses the design takes it from here: the platform loop of
``schuler align`` (:mod:`schuler.gyrocompassing`), its nonlinear form
(:mod:`schuler.navigate.alignment`), the strapdown gyrocompass of
:mod:`schuler.alignment.gyrocompass` (the same loop with c_Gamma = -c1 g,
c_a = c2 g of the control law (1.6)) and the mission's alignment stage. SI
throughout: T in s, gains in 1/s, latitude in rad.

Source: Meleshko, V. V. (compiler), "Physical gyrocompassing of a semi-analytic
INS", KPI laboratory manual (:data:`schuler.references.KPI_LAB_MANUAL`), Sec. 2:
control law (1.6), models (1.17)-(1.19), characteristic equation (1.20).

Examples
--------
>>> c_gamma, c_a = loop_gains(np.radians(50.0), DESIGN_TIME_CONSTANT, DESIGN_DAMPING)
>>> round(c_gamma, 4), round(c_a, 2)
(0.0533, 23.7)
>>> time_constant, damping = loop_design(np.radians(50.0), c_gamma, c_a)
>>> round(time_constant, 9), round(damping, 9)
(30.0, 0.8)
"""

from __future__ import annotations

import numpy as np

from schuler.core.earth import EARTH_RATE
from schuler.core.geometry import horizontal_earth_rate
from schuler.exceptions import InvalidParameter

DESIGN_TIME_CONSTANT = 30.0
"""T of the KPI manual's design example, s ("often T = 30 s, zeta = 0.8")."""

DESIGN_DAMPING = 0.8
"""zeta of the KPI manual's design example, plain number."""


def _pair(first, second):
    """Two results broadcast together: floats when scalar, else arrays of one shape."""
    shape = np.broadcast_shapes(np.shape(first), np.shape(second))
    if not shape:
        return float(first), float(second)
    return np.broadcast_to(first, shape).copy(), np.broadcast_to(second, shape).copy()


def loop_gains(latitude, time_constant, damping, earth_rate: float = EARTH_RATE):
    """The gains (c_Gamma, c_a) of the loop of time constant T and damping zeta: 2 zeta / T, 1 / (T^2 U_eta).

    Parameters
    ----------
    latitude : float or array_like
        Latitude L, rad (U_eta = Omega cos L; at the poles there is no design).
    time_constant : float or array_like
        T, s (finite, > 0).
    damping : float or array_like
        zeta, plain number (finite, > 0: zeta <= 0 is no stable loop).
    earth_rate : float
        Earth rotation rate Omega, rad/s.

    Returns
    -------
    c_gamma, c_a : float or ndarray
        Gains of the level and azimuth channels, 1/s: floats for scalar inputs, else arrays of the
        broadcast shape.

    Raises
    ------
    InvalidParameter
        ``time_constant`` or ``damping`` not finite and positive.
    NotObservable
        At a pole (:func:`~schuler.core.geometry.horizontal_earth_rate`).

    Notes
    -----
    T^2 p^2 + 2 T zeta p + 1 = 0 divided by T^2 and matched to (1.20),
    p^2 + c_Gamma p + c_a U_eta = 0: c_Gamma = 2 zeta / T and c_a U_eta = 1 / T^2
    (the KPI manual, end of Sec. 2).

    Examples
    --------
    >>> c_gamma, c_a = loop_gains(np.radians([0.0, 60.0]), 30.0, 0.8)
    >>> c_gamma.round(4).tolist(), c_a.round(1).tolist()
    ([0.0533, 0.0533], [15.2, 30.5])
    """
    T = np.asarray(time_constant, dtype=float)
    zeta = np.asarray(damping, dtype=float)
    bad = ~(np.isfinite(T) & (T > 0.0))
    if np.any(bad):
        raise InvalidParameter("time_constant", f"{float(T[bad].flat[0]):g} s: must be finite and > 0")
    bad = ~(np.isfinite(zeta) & (zeta > 0.0))
    if np.any(bad):
        raise InvalidParameter("damping", f"{float(zeta[bad].flat[0]):g}: must be finite and > 0 "
                               "(zeta <= 0 is no stable loop)")
    U_eta = horizontal_earth_rate(latitude, earth_rate)
    return _pair(2.0 * zeta / T, 1.0 / (T**2 * U_eta))


def loop_design(latitude, c_gamma, c_a, earth_rate: float = EARTH_RATE):
    """The time constant T and damping zeta of the loop with gains (c_Gamma, c_a): the inverse of :func:`loop_gains`.

    Parameters
    ----------
    latitude : float or array_like
        Latitude L, rad.
    c_gamma : float or array_like
        Level gain c_Gamma, 1/s.
    c_a : float or array_like
        Azimuth gain c_a, 1/s (> 0; otherwise T and zeta are NaN: the loop has no such design, and numpy warns).
    earth_rate : float
        Earth rotation rate Omega, rad/s.

    Returns
    -------
    time_constant : float or ndarray
        T = 1 / omega0, s, with omega0 = sqrt(c_a U_eta).
    damping : float or ndarray
        zeta = c_Gamma / (2 omega0), plain number: below 1 the loop oscillates, above it is aperiodic.

    Raises
    ------
    NotObservable
        At a pole (:func:`~schuler.core.geometry.horizontal_earth_rate`).

    Examples
    --------
    The printed pair of the manual's example (0.08, 22) at the latitude where c_a = 22 holds for T = 30 s
    is aperiodic:

    >>> T, zeta = loop_design(np.radians(46.16), 0.08, 22.0)
    >>> round(T, 1), round(zeta, 2)
    (30.0, 1.2)
    """
    omega0 = np.sqrt(np.asarray(c_a, dtype=float) * horizontal_earth_rate(latitude, earth_rate))
    return _pair(1.0 / omega0, np.asarray(c_gamma, dtype=float) / (2.0 * omega0))
