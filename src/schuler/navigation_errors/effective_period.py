"""Effective Schuler period under thrust or fast level flight (Bollay (1966), footnote).

The levelling loop's period is T = 2 pi sqrt(R / g_eff), where g_eff is the
specific force along the vertical that the accelerometers feel and R the radius
the platform is levelled with:

a) vertical thrust of n times the weight: g_eff = n g0, so T = T0 / sqrt(n)
   (n = 9: 84.4 / 3 = 28 min);
b) level flight at speed V along a path of radius of curvature r:
   g_eff = g - V^2 / r, so T -> infinity as V approaches the orbital speed
   V_c = sqrt(g r).

Examples
--------
>>> from schuler.core.earth import MEAN_RADIUS, STANDARD_GRAVITY
>>> T0 = effective_schuler_period(MEAN_RADIUS, STANDARD_GRAVITY)
>>> round(float(T0 / effective_schuler_period(MEAN_RADIUS, thrust_gravity(9, STANDARD_GRAVITY))), 12)
3.0
"""

from __future__ import annotations

import numpy as np

from schuler.exceptions import InvalidParameter


def _check(value, name: str, positive: bool = True):
    array = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(array)) or np.any(array <= 0 if positive else array < 0):
        raise InvalidParameter(name, f"must be finite and {'> 0' if positive else '>= 0'}, got {value!r}")
    return array


def thrust_gravity(thrust_factor, gravity):
    """g_eff = n g0 for a vertical thrust of n times the weight (footnote, case a), m/s^2.

    Parameters
    ----------
    thrust_factor : float or ndarray
        n (> 0), a ratio of thrust to weight.
    gravity : float or ndarray
        g0, m/s^2 (> 0).

    Examples
    --------
    >>> float(thrust_gravity(9, 9.80665))
    88.25985
    """
    return _check(thrust_factor, "thrust_factor") * _check(gravity, "gravity")


def flight_gravity(gravity, speed, path_radius):
    """g_eff = g - V^2 / r for level flight at speed V on a path of radius r (case b), m/s^2.

    Parameters
    ----------
    gravity : float or ndarray
        g, m/s^2 (> 0).
    speed : float or ndarray
        V, m/s (>= 0).
    path_radius : float or ndarray
        r, m (> 0).

    Returns
    -------
    ndarray
        g_eff, m/s^2; zero at the orbital speed and negative above it.

    >>> float(flight_gravity(9.81, orbital_speed(9.81, 6.4e6), 6.4e6))
    0.0
    """
    return _check(gravity, "gravity") - _check(speed, "speed", positive=False) ** 2 / _check(path_radius, "path_radius")


def orbital_speed(gravity, path_radius):
    """V_c = sqrt(g r), m/s: the speed at which g_eff vanishes.

    Parameters
    ----------
    gravity : float or ndarray
        g, m/s^2 (> 0).
    path_radius : float or ndarray
        r, radius of the flight path about the Earth's centre, m (> 0).

    Examples
    --------
    >>> round(float(orbital_speed(9.80665, 6.371e6)))
    7904
    """
    return np.sqrt(_check(gravity, "gravity") * _check(path_radius, "path_radius"))


def effective_schuler_period(radius, effective_gravity):
    """T = 2 pi sqrt(R / g_eff), s; infinite where g_eff <= 0 (no restoring force).

    Parameters
    ----------
    radius : float or ndarray
        R, m (> 0).
    effective_gravity : float or ndarray
        g_eff, m/s^2. At or above the orbital speed g_eff <= 0: the loop has no
        restoring acceleration and the period is returned as ``inf``.

    Examples
    --------
    >>> float(effective_schuler_period(6.4e6, 0.0))
    inf
    """
    R = _check(radius, "radius")
    g_eff = np.asarray(effective_gravity, dtype=float)
    if np.any(np.isnan(g_eff)):
        raise InvalidParameter("effective_gravity", "must not be NaN")
    safe = np.where(g_eff > 0, g_eff, 1.0)
    return np.where(g_eff > 0, 2.0 * np.pi * np.sqrt(R / safe), np.inf)
