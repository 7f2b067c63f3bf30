"""Shared geometry: angle constants, the Earth rate in a level frame, time grids.

Every system needs the same few primitives; they live here once, in SI, on plain
floats and arrays (no units library).

* Angle constants :data:`DEGREE`, :data:`ARCMIN`, :data:`ARCSEC` (rad per unit)
  and :data:`DEG_PER_HOUR` (rad/s per deg/h), for source constants and tests; user
  input goes through :mod:`schuler.units`.
* The Earth rate at latitude L: Omega (cos L) towards north and Omega (sin L)
  up (:func:`earth_rate_north_up`), its components in a level frame turned to an
  azimuth (:func:`level_frame_earth_rate`), and the horizontal rate
  Omega cos L where north is to be found from it (:func:`horizontal_earth_rate`,
  which refuses the poles).
* One time-grid rule (:func:`time_grid`, :func:`time_grids`), its point count
  sized before anything is allocated (:func:`grid_points`), and one test of
  uniform spacing (:func:`uniform_step`). Every system's output times follow it.

Frames: the level frame is NED-like: x horizontal at an azimuth measured from
north clockwise seen from above (towards east), y horizontal 90 deg to the
right of x, z down. A source's frame with z up maps onto it by naming the
axes: e.g. a platform whose y axis points at azimuth A and whose z is up has
(y, x, -z) = the level frame at A.

Examples
--------
>>> round(1.0 / ARCSEC)   # arcseconds in a radian
206265
>>> x, y, z = level_frame_earth_rate(0.0, np.pi / 2)   # x east on the equator
>>> [round(float(c / EARTH_RATE), 12) + 0.0 for c in (x, y, z)]
[0.0, -1.0, 0.0]
>>> time_grid(100.0, 30.0)
array([  0.,  30.,  60.,  90., 100.])
"""

from __future__ import annotations

import math

import numpy as np

from schuler.core.earth import EARTH_RATE
from schuler.exceptions import InvalidParameter, NotObservable

DEGREE = math.pi / 180.0
"""One degree, rad."""

ARCMIN = DEGREE / 60.0
"""One minute of arc, rad."""

ARCSEC = ARCMIN / 60.0
"""One second of arc, rad."""

DEG_PER_HOUR = DEGREE / 3600.0
"""One degree per hour, rad/s (the unit of gyro drift)."""

POLE_TOLERANCE = 1e-9
"""|cos(latitude)| below this counts as the pole: within about 1e-9 rad (0.2 milliarcsec)."""

GRID_TOLERANCE = 1e-9
"""A duration within this fraction of a step of a whole number of steps ends the grid on that step."""

MAX_GRID_POINTS = 10_000_000
"""Default limit of :func:`time_grid`: 80 MB per float channel (refused beyond, not allocated)."""


def _latitude(latitude) -> np.ndarray:
    """The latitude as a float array; InvalidParameter unless finite and within [-90, 90] deg."""
    phi = np.asarray(latitude, dtype=float)
    if not np.all(np.isfinite(phi)):
        raise InvalidParameter("latitude", "must be a finite number")
    # a latitude converted from degrees may overshoot 90 deg by an ulp
    if np.any(np.abs(phi) > math.pi / 2 * (1.0 + 1e-15)):
        worst = float(np.max(np.abs(phi)))
        raise InvalidParameter("latitude", f"{math.degrees(worst):g} deg: must lie in [-90, 90] deg")
    return phi


def earth_rate_north_up(latitude, earth_rate: float = EARTH_RATE):
    """Earth rate at a latitude: Omega cos L towards north and Omega sin L up, rad/s.

    Parameters
    ----------
    latitude : float or ndarray
        Geodetic (or, on a sphere, geocentric) latitude L, rad, in [-pi/2, pi/2].
    earth_rate : float
        Earth rotation rate Omega, rad/s.

    Returns
    -------
    north, up : ndarray
        Omega cos L and Omega sin L (shape of ``latitude``), rad/s.

    Raises
    ------
    InvalidParameter
        For a non-finite latitude or one beyond +-90 deg.

    Notes
    -----
    The Earth's rotation vector is Omega along the polar axis; in the local level
    frame at latitude L the polar axis has the direction (cos L) n + (sin L) u
    (n north, u up) [1]_; the gyrocompassing source writes the same as
    U_eta = U cos(phi), U_zeta = U sin(phi) [2]_.

    References
    ----------
    .. [1] P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated
       Navigation Systems*, 2nd ed., Artech House, 2013, ch. 2 (Earth rotation
       resolved in the local navigation frame).
    .. [2] KPI laboratory manual on physical gyrocompassing of a semi-analytic
       platform INS (the KPI manual), Sec. 2.

    Examples
    --------
    >>> north, up = earth_rate_north_up(np.radians(30.0), 1.0)
    >>> round(float(north), 12), round(float(up), 12)
    (0.866025403784, 0.5)
    """
    phi = _latitude(latitude)
    return earth_rate * np.cos(phi), earth_rate * np.sin(phi)


def level_frame_earth_rate(latitude, azimuth, earth_rate: float = EARTH_RATE):
    """Earth-rate components in a level frame whose x axis points at ``azimuth``, rad/s.

    Parameters
    ----------
    latitude : float or ndarray
        Latitude L, rad.
    azimuth : float or ndarray
        Azimuth psi of the frame's x axis, rad, from north clockwise seen from
        above (towards east). Broadcast against ``latitude``.
    earth_rate : float
        Earth rotation rate Omega, rad/s.

    Returns
    -------
    x, y, z : ndarray
        Components along x (horizontal, at psi), y (horizontal, at psi + 90 deg:
        to the right) and z (down), rad/s:
        x = Omega cos L cos psi, y = -Omega cos L sin psi, z = -Omega sin L.

    Notes
    -----
    The horizontal part Omega cos L points north; projected on a horizontal axis
    at azimuth psi it gives Omega cos L cos psi, and on the axis at psi + 90 deg
    Omega cos L cos(psi + 90 deg) = -Omega cos L sin psi. At psi = 0 this is the
    navigation-frame Earth rate (Omega cos L, 0, -Omega sin L) of NED mechanisations
    (Groves 2013, ch. 2).

    Examples
    --------
    A platform with y at azimuth A and z up (the gyrocompassing source's x_g y_g z):
    its (y, x, -z) axes are the level frame at A, so U_x = -Omega cos L sin A:

    >>> A = np.radians(30.0)
    >>> u_y, u_x, minus_u_z = level_frame_earth_rate(0.0, A, 1.0)
    >>> round(float(u_x), 12), round(float(u_y), 12)
    (-0.5, 0.866025403784)
    """
    north, up = earth_rate_north_up(latitude, earth_rate)
    psi = np.asarray(azimuth, dtype=float)
    if not np.all(np.isfinite(psi)):
        raise InvalidParameter("azimuth", "must be a finite number")
    x = north * np.cos(psi)
    return x, -north * np.sin(psi), np.broadcast_to(-up, x.shape).copy()


def horizontal_earth_rate(latitude, earth_rate: float = EARTH_RATE):
    """Horizontal Earth rate Omega_h = Omega cos L, where north is to be found from it, rad/s.

    The quantity every north finder measures (U_eta of gyrocompassing, Omega_h of
    the ground gyrocompass, Omega cos(phi) of drift calibration). It vanishes at
    the poles, where azimuth is not observable.

    Parameters
    ----------
    latitude : float or ndarray
        Latitude L, rad.
    earth_rate : float
        Earth rotation rate Omega, rad/s (> 0).

    Returns
    -------
    float or ndarray
        Omega cos L, rad/s: a float for a scalar latitude.

    Raises
    ------
    NotObservable
        Where Omega cos L < 1e-9 Omega (:data:`POLE_TOLERANCE`): at a pole; the
        message starts with ``"latitude: "`` and names the latitude.
    InvalidParameter
        For a non-finite latitude, one beyond +-90 deg, or a non-positive Omega.

    Examples
    --------
    >>> round(horizontal_earth_rate(np.radians(60.0)) * 1e5, 4)
    3.6461
    >>> horizontal_earth_rate(np.pi / 2)
    Traceback (most recent call last):
    ...
    schuler.exceptions.NotObservable: latitude: 90 deg: no horizontal Earth rate, azimuth (north) is not observable
    """
    if not (math.isfinite(earth_rate) and earth_rate > 0.0):
        raise InvalidParameter("earth_rate", f"{earth_rate:g} rad/s: must be finite and > 0")
    north, _ = earth_rate_north_up(latitude, earth_rate)
    pole = north < POLE_TOLERANCE * earth_rate
    if np.any(pole):
        at_pole = float(np.asarray(latitude, dtype=float)[pole].flat[0]) if north.ndim else float(latitude)
        raise NotObservable(
            f"latitude: {math.degrees(at_pole):g} deg: no horizontal Earth rate, azimuth (north) is not observable"
        )
    return float(north) if north.ndim == 0 else north


def grid_points(duration, step, *, names: tuple[str, str] = ("duration", "step"), max_points: float = math.inf):
    """Number of points :func:`time_grid` gives for each (duration, step), without building the grids.

    The count is checked before anything is allocated; it is a float (exact
    below 2^53), so that an absurd grid can be sized, and refused by a memory
    check such as :func:`schuler.memory.require`, rather than overflow an integer.

    Parameters
    ----------
    duration : float or array_like
        Length of each grid, s (> 0).
    step : float or array_like
        Time step of each grid, s (> 0, at most its ``duration``); broadcast against ``duration``.
    names : (str, str)
        The caller's names of the duration and the step, used in error messages.
    max_points : float
        Largest count accepted, in number of points (default: no limit).

    Returns
    -------
    float or ndarray
        The number of points: a float for scalar inputs, else an array of the broadcast shape.

    Raises
    ------
    InvalidParameter
        For a non-finite or non-positive duration or step, a step longer than
        the duration, or a count above ``max_points``.

    Examples
    --------
    >>> grid_points(2.0, 0.5), grid_points(1.0, 0.3), grid_points(1e9, 1e-3)
    (5.0, 5.0, 1000000000001.0)
    >>> grid_points([10.0, 10.5], 1.0)
    array([11., 12.])
    """
    duration_name, step_name = names
    durations, steps = np.broadcast_arrays(np.asarray(duration, dtype=float), np.asarray(step, dtype=float))
    bad = ~(np.isfinite(durations) & (durations > 0.0))
    if np.any(bad):
        raise InvalidParameter(duration_name, f"{float(durations[bad].flat[0]):g} s: must be finite and > 0")
    bad = ~(np.isfinite(steps) & (steps > 0.0))
    if np.any(bad):
        raise InvalidParameter(step_name, f"{float(steps[bad].flat[0]):g} s: must be finite and > 0")
    with np.errstate(over="ignore"):  # an overflowing count is refused below
        ratio = durations / steps
    bad = ratio < 1.0 - GRID_TOLERANCE
    if np.any(bad):
        raise InvalidParameter(
            step_name, f"{steps[bad].flat[0]:g} s is longer than the {duration_name} {durations[bad].flat[0]:g} s"
        )
    whole = np.rint(ratio)
    # within 1e-9 step of a whole number of steps, allowing for the rounding of the division itself
    with np.errstate(invalid="ignore"):
        on_step = np.abs(ratio - whole) <= GRID_TOLERANCE + 4.0 * np.finfo(float).eps * ratio
    counts = np.where(on_step, whole + 1.0, np.floor(ratio) + 2.0)
    if not np.all(counts <= max_points):
        worst = int(np.argmax(counts))
        raise InvalidParameter(
            step_name,
            f"{steps.flat[worst]:g} s over {durations.flat[worst]:g} s gives {counts.flat[worst]:,.0f} points; "
            f"at most {max_points:,} (use a longer step)",
        )
    return float(counts) if counts.ndim == 0 else counts


def time_grid(duration: float, step: float, *, names: tuple[str, str] = ("duration", "step"),
              max_points: int = MAX_GRID_POINTS) -> np.ndarray:
    """Output times 0, step, 2 step, ..., ending exactly on ``duration``, s.

    The rule: the grid is k step for k = 0, 1, ...; when ``duration`` is within
    1e-9 of a step (:data:`GRID_TOLERANCE`, plus the rounding of duration / step)
    of a whole number of steps, that last point is set to ``duration`` itself
    (moving it by at most that much); otherwise ``duration`` follows the last
    whole step as a shorter final step.

    Parameters
    ----------
    duration : float
        Length of the grid, s (> 0).
    step : float
        Time step, s (> 0, at most ``duration``).
    names : (str, str)
        The caller's names of the duration and the step, used in error messages.
    max_points : int
        Largest grid accepted, in number of points; a longer one is refused before allocation.

    Returns
    -------
    ndarray, shape (n,)
        Increasing times from 0.0 to ``duration``, n >= 2.

    Raises
    ------
    InvalidParameter
        For a non-finite or non-positive duration or step, a step longer than
        the duration, or more than ``max_points`` points.

    Examples
    --------
    >>> time_grid(2.0, 0.5)
    array([0. , 0.5, 1. , 1.5, 2. ])
    >>> time_grid(1.0, 0.3)
    array([0. , 0.3, 0.6, 0.9, 1. ])
    >>> float(time_grid(0.3, 0.1)[-1])   # 0.3 / 0.1 = 2.9999999999999996: on a step
    0.3
    """
    count = int(grid_points(duration, step, names=names, max_points=max_points))
    grid = float(step) * np.arange(count, dtype=float)
    grid[-1] = duration
    return grid


def time_grids(durations, steps, *, names: tuple[str, str] = ("duration", "step"),
               max_points: int = MAX_GRID_POINTS):
    """:func:`time_grid` for many cases at once, padded to the longest grid.

    Parameters
    ----------
    durations, steps : array_like, shape (N,)
        Per case, s (broadcast together).
    names : (str, str)
        As in :func:`time_grid`.
    max_points : int
        Largest padded array accepted, in number of points (N times the longest grid).

    Returns
    -------
    time : ndarray, shape (N, n_max)
        Case k's grid in its first ``valid[k].sum()`` entries, then zeros.
    valid : ndarray of bool, shape (N, n_max)
        True on each case's own grid points.

    Examples
    --------
    >>> time, valid = time_grids([2.0, 1.0], [1.0, 0.3])
    >>> time[0][valid[0]], time[1][valid[1]]
    (array([0., 1., 2.]), array([0. , 0.3, 0.6, 0.9, 1. ]))
    """
    durations, steps = np.broadcast_arrays(np.atleast_1d(np.asarray(durations, dtype=float)),
                                           np.atleast_1d(np.asarray(steps, dtype=float)))
    counts = grid_points(durations, steps, names=names, max_points=max_points).astype(np.int64)
    n_max = int(counts.max())
    if n_max * counts.size > max_points:
        raise InvalidParameter(names[1], f"{counts.size} grids of up to {n_max:,} points exceed {max_points:,} points")
    k = np.arange(n_max)
    valid = k < counts[:, None]
    time = np.where(valid, steps[:, None] * k, 0.0)
    time[np.arange(counts.size), counts - 1] = durations
    return time, valid


def uniform_step(time) -> float | None:
    """The step of a uniformly spaced time grid, or None if the steps differ, s.

    Steps count as equal when each is within 1e-12 of the mean step plus a few
    rounding units of the largest time: the steps of ``np.linspace`` and of
    ``step * np.arange(n)`` scatter by ulps of the times, not of the step. A grid
    from :func:`time_grid` whose duration is not a whole number of steps has a
    shorter last step and is not uniform.

    Parameters
    ----------
    time : array_like, shape (n,)
        Increasing times, s (n >= 2).

    Returns
    -------
    float or None
        (t[-1] - t[0]) / (n - 1) when the grid is uniform.

    Examples
    --------
    >>> uniform_step(np.linspace(0.0, 48 * 3600.0, 17281))
    10.0
    >>> uniform_step(time_grid(1.0, 0.3)) is None
    True
    """
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 2:
        return None
    steps = np.diff(t)
    step = float(t[-1] - t[0]) / steps.size
    tolerance = 1e-12 * abs(step) + 8.0 * np.finfo(float).eps * max(abs(float(t[0])), abs(float(t[-1])))
    return step if bool(np.all(np.abs(steps - step) <= tolerance)) else None
