"""Vehicle trajectories on WGS-84: stationary, great circle, and smooth waypoint profiles.

A trajectory gives the vehicle's start position and, at any times, its ground
velocity in NED (m/s) and its attitude as the quaternion q_bn (aerospace roll,
pitch and heading, see :mod:`schuler.core.attitude`). The position is not an input:
the truth generator (:mod:`schuler.navigate.truth`) integrates the velocity with
the navigation algorithm's own position update, so that the truth and the ideal
IMU are consistent to rounding.

* :class:`Stationary`: at rest, any attitude.
* :class:`GreatCircle`: constant speed at constant height along a geodesic of
  the surface h = const (the ellipsoid's "great circle"): Clairaut's relation on
  a surface of revolution gives the heading's rate
  psi' = V sin(psi) tan(L) / (R_E + h), integrated once (DOP853, rtol 1e-12) when
  the trajectory is built.
* :class:`WaypointProfile`: speed, heading and flight-path angle given at
  waypoint times and blended between them by the quintic smoothstep
  s(x) = 10 x^3 - 15 x^4 + 6 x^5, whose first and second derivatives vanish
  at both ends: velocity and attitude are C^2, so the ideal angular rate and
  specific force are continuous. The vehicle banks for coordinated turns,
  tan(roll) = V cos(gamma) psi' / g0, and pitches with its flight path
  (pitch = gamma). TOML input: :mod:`schuler.navigate.profile`.

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
Artech House, 2013, Sec. 2.4 (curvilinear position, radii of curvature).
A. Clairaut's relation for geodesics on surfaces of revolution: r sin(psi) = const, r the parallel's radius
(e.g. M. P. do Carmo, *Differential Geometry of Curves and Surfaces*, Prentice-Hall, 1976, Sec. 4-4).

Examples
--------
>>> path = GreatCircle(latitude=np.radians(45.0), longitude=0.0, height=0.0, heading=np.radians(30.0),
...                    speed=250.0, duration=3600.0)
>>> from schuler.core.attitude import euler_from_quaternion
>>> v, q = path.kinematics(np.array([0.0, 3600.0]))
>>> heading = euler_from_quaternion(q)[:, 2]
>>> bool(np.allclose(np.linalg.norm(v, axis=1), 250.0)), bool(heading[1] > heading[0])
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from schuler.core.attitude import quaternion_from_euler
from schuler.core.earth import STANDARD_GRAVITY, radii_of_curvature
from schuler.exceptions import InvalidParameter, SimulationError

MAX_LATITUDE = np.radians(89.0)
"""Trajectories must stay within 89 deg of the equator: NED and the transport rate are singular at the poles."""


def _finite(name: str, value) -> float:
    number = float(value)
    if not np.isfinite(number):
        raise InvalidParameter(name, f"must be a finite number, got {value!r}")
    return number


def _latitude(value) -> float:
    latitude = _finite("latitude", value)
    if abs(latitude) > MAX_LATITUDE:
        raise InvalidParameter("latitude", f"must lie within +/-89 deg (NED is singular at the poles), "
                                           f"got {np.degrees(latitude):g} deg")
    return latitude


def _height(value) -> float:
    height = _finite("height", value)
    if not -1.0e4 <= height <= 1.0e5:
        raise InvalidParameter("height", f"must lie in [-10, 100] km (the gravity model's range), got {height:g} m")
    return height


def _times(t) -> np.ndarray:
    return np.atleast_1d(np.asarray(t, dtype=float))


@dataclass(frozen=True)
class Stationary:
    """A vehicle at rest on the Earth.

    Parameters
    ----------
    latitude : float
        Geodetic latitude, rad (|L| <= 89 deg).
    longitude : float
        rad.
    height : float
        Height above the ellipsoid, m.
    roll, pitch, heading : float
        Attitude, rad.
    """

    latitude: float
    longitude: float = 0.0
    height: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    heading: float = 0.0

    def __post_init__(self):
        _latitude(self.latitude)
        _height(self.height)
        for name in ("longitude", "roll", "pitch", "heading"):
            _finite(name, getattr(self, name))

    def kinematics(self, t):
        """Velocity (n, 3) m/s NED (zero) and attitude q_bn (n, 4) at times t (s).

        Parameters
        ----------
        t : float or array_like
            Times since the start, s, shape (n,) (a scalar is one time).

        Returns
        -------
        velocity : ndarray
            Ground velocity, m/s, NED (zero), shape (n, 3).
        quaternion : ndarray
            Attitude q_bn (body x forward, y right, z down to NED), unit quaternions, scalar first,
            plain numbers, shape (n, 4).
        """
        n = _times(t).size
        return np.zeros((n, 3)), np.tile(quaternion_from_euler(self.roll, self.pitch, self.heading), (n, 1))


@dataclass(frozen=True)
class GreatCircle:
    """Constant speed and height along a geodesic (great circle) of WGS-84, level, no sideslip.

    Parameters
    ----------
    latitude, longitude : float
        Start, rad.
    height : float
        Constant height, m.
    heading : float
        Initial heading (course), rad clockwise from north.
    speed : float
        Ground speed V, m/s (>= 0).
    duration : float
        Length of the path in time, s (> 0): the heading is integrated over it.

    Raises
    ------
    InvalidParameter
        If the path comes within 1 deg of a pole.
    """

    latitude: float
    longitude: float
    height: float
    heading: float
    speed: float
    duration: float
    _solution: object = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        _latitude(self.latitude)
        _height(self.height)
        _finite("longitude", self.longitude)
        _finite("heading", self.heading)
        if not (np.isfinite(self.speed) and 0.0 <= self.speed <= 1.0e4):
            raise InvalidParameter("speed", f"must lie in [0, 10] km/s, got {self.speed!r}")
        if not (np.isfinite(self.duration) and self.duration > 0):
            raise InvalidParameter("duration", f"must be finite and > 0, got {self.duration!r}")
        V, h = float(self.speed), float(self.height)

        def rates(_t, y):
            L, psi = y
            R_N, R_E = radii_of_curvature(L)
            return [V * np.cos(psi) / (R_N + h), V * np.sin(psi) * np.tan(L) / (R_E + h)]

        def near_pole(_t, y):
            return MAX_LATITUDE - abs(y[0])

        near_pole.terminal = True
        solution = solve_ivp(rates, (0.0, float(self.duration)), [self.latitude, self.heading], method="DOP853",
                             rtol=1e-12, atol=1e-14, dense_output=True, events=near_pole)
        if solution.status == 1:
            raise InvalidParameter("heading", f"the great circle passes within 1 deg of a pole after "
                                              f"{solution.t_events[0][0]:.0f} s: NED is singular there")
        if not solution.success:
            raise SimulationError(f"great-circle heading integration failed: {solution.message}")
        object.__setattr__(self, "_solution", solution.sol)

    def kinematics(self, t):
        """Velocity (n, 3) m/s NED and attitude q_bn (n, 4) at times t in [0, duration] s.

        Parameters
        ----------
        t : float or array_like
            Times since the start, s, shape (n,) (a scalar is one time); times outside
            [0, duration] take the heading at the nearer end.

        Returns
        -------
        velocity : ndarray
            Ground velocity, m/s, NED, shape (n, 3).
        quaternion : ndarray
            Attitude q_bn (body x forward, y right, z down to NED), unit quaternions, scalar first,
            plain numbers, shape (n, 4).
        """
        t = _times(t)
        psi = self._solution(np.clip(t, 0.0, self.duration))[1]
        # level at heading psi: q = (cos psi/2, 0, 0, sin psi/2); the velocity by double angles
        cos_half, sin_half = np.cos(0.5 * psi), np.sin(0.5 * psi)
        velocity = self.speed * np.stack([1.0 - 2.0 * sin_half**2, 2.0 * sin_half * cos_half, np.zeros_like(psi)],
                                         axis=-1)
        zeros = np.zeros_like(psi)
        return velocity, np.stack([cos_half, zeros, zeros, sin_half], axis=-1)


def smoothstep(x):
    """Quintic smoothstep s = 10 x^3 - 15 x^4 + 6 x^5 on [0, 1] and its first two derivatives.

    Parameters
    ----------
    x : float or array_like
        Normalised time in [0, 1], dimensionless (clipped to it).

    Returns
    -------
    value, first, second : ndarray
        s(x), ds/dx and d^2s/dx^2, dimensionless, each of the shape of ``x``.

    Examples
    --------
    >>> [float(v) for v in smoothstep(np.array([0.5]))[0]]
    [0.5]
    """
    x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
    x2 = x * x
    value = x2 * x * (10.0 - 15.0 * x + 6.0 * x2)
    first = 30.0 * x2 * (1.0 - x) ** 2
    second = 60.0 * x * (1.0 - x) * (1.0 - 2.0 * x)
    return value, first, second


@dataclass(frozen=True)
class WaypointProfile:
    """Speed, heading and flight-path angle at waypoint times, C^2-blended between them.

    Between waypoints i and i+1 each quantity q goes from q_i to q_{i+1} along
    q_i + (q_{i+1} - q_i) s((t - t_i) / (t_{i+1} - t_i)) (:func:`smoothstep`);
    before the first and after the last waypoint it holds. Headings are not
    wrapped: the turn between two waypoints is the difference of their headings
    (350 deg -> 370 deg is a 20-deg right turn).

    Parameters
    ----------
    latitude, longitude : float
        Start position, rad.
    height : float
        Start height, m.
    times : array_like, shape (n,)
        Waypoint times, s, strictly increasing from 0.
    speeds : array_like, shape (n,)
        Ground speed V at each waypoint, m/s (>= 0).
    headings : array_like, shape (n,)
        Course psi, rad clockwise from north.
    flight_path_angles : array_like, shape (n,)
        Climb angle gamma, rad (|gamma| < 60 deg), positive up.
    name : str
        A label for reports.
    """

    latitude: float
    longitude: float
    height: float
    times: np.ndarray
    speeds: np.ndarray
    headings: np.ndarray
    flight_path_angles: np.ndarray
    name: str = "profile"

    def __post_init__(self):
        _latitude(self.latitude)
        _height(self.height)
        _finite("longitude", self.longitude)
        arrays = {}
        for key in ("times", "speeds", "headings", "flight_path_angles"):
            array = np.atleast_1d(np.asarray(getattr(self, key), dtype=float))
            if array.ndim != 1 or not np.all(np.isfinite(array)):
                raise InvalidParameter(key, "must be a 1-D sequence of finite numbers")
            arrays[key] = array
            object.__setattr__(self, key, array)
        sizes = {a.size for a in arrays.values()}
        if len(sizes) != 1 or sizes.pop() < 1:
            raise InvalidParameter("waypoint", "times, speeds, headings and flight_path_angles need one value "
                                               "per waypoint")
        if arrays["times"][0] != 0.0 or np.any(np.diff(arrays["times"]) <= 0):
            raise InvalidParameter("time", "waypoint times must start at 0 s and increase strictly")
        if np.any(arrays["speeds"] < 0) or np.any(arrays["speeds"] > 1.0e4):
            raise InvalidParameter("speed", "must lie in [0, 10] km/s")
        if np.any(np.abs(arrays["flight_path_angles"]) >= np.radians(60.0)):
            raise InvalidParameter("flight_path_angle", "must lie within +/-60 deg")

    @property
    def duration(self) -> float:
        """Time of the last waypoint, s."""
        return float(self.times[-1])

    def stationary_intervals(self) -> list[tuple[float, float]]:
        """The (start, end) times of the stops, s: consecutive waypoints both at speed zero."""
        still = (self.speeds[:-1] == 0.0) & (self.speeds[1:] == 0.0)
        return [(float(self.times[k]), float(self.times[k + 1])) for k in np.flatnonzero(still)]

    def _blend(self, values, t):
        """Value, rate and second derivative of one blended quantity at times t."""
        index = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, max(self.times.size - 2, 0))
        if self.times.size == 1:
            constant = np.full(t.shape, values[0])
            return constant, np.zeros_like(t), np.zeros_like(t)
        span = self.times[index + 1] - self.times[index]
        step = values[index + 1] - values[index]
        s, ds, dds = smoothstep((t - self.times[index]) / span)
        return values[index] + step * s, step * ds / span, step * dds / span**2

    def kinematics(self, t):
        """Velocity (n, 3) m/s NED and attitude q_bn (n, 4) at times t (s).

        Parameters
        ----------
        t : float or array_like
            Times since the start, s, shape (n,) (a scalar is one time); before the first
            and after the last waypoint the values hold.

        Returns
        -------
        velocity : ndarray
            Ground velocity, m/s, NED, shape (n, 3).
        quaternion : ndarray
            Attitude q_bn (body x forward, y right, z down to NED), unit quaternions, scalar first,
            plain numbers, shape (n, 4).
        """
        t = _times(t)
        speed, _, _ = self._blend(self.speeds, t)
        psi, psi_rate, _ = self._blend(self.headings, t)
        gamma, _, _ = self._blend(self.flight_path_angles, t)
        horizontal = speed * np.cos(gamma)
        velocity = np.stack([horizontal * np.cos(psi), horizontal * np.sin(psi), -speed * np.sin(gamma)], axis=-1)
        roll = np.arctan(horizontal * psi_rate / STANDARD_GRAVITY)
        return velocity, quaternion_from_euler(roll, gamma, psi)


def stationary_intervals(trajectory, duration: float) -> list[tuple[float, float]]:
    """The (start, end) times a trajectory is at rest within its first ``duration`` seconds, s.

    A :class:`Stationary` one is at rest throughout, a :class:`GreatCircle` never, a :class:`WaypointProfile`
    between consecutive waypoints at speed zero (and after its last waypoint when that one is at rest: its values
    hold).

    Parameters
    ----------
    trajectory : Stationary, GreatCircle or WaypointProfile
        The trajectory.
    duration : float
        The time considered, s.

    Examples
    --------
    >>> stationary_intervals(Stationary(latitude=0.5), 60.0)
    [(0.0, 60.0)]
    """
    if isinstance(trajectory, Stationary):
        return [(0.0, float(duration))]
    if not isinstance(trajectory, WaypointProfile):
        return []
    intervals = trajectory.stationary_intervals()
    if trajectory.speeds[-1] == 0.0 and duration > trajectory.duration:
        last = intervals.pop() if intervals and intervals[-1][1] == trajectory.duration else (trajectory.duration,) * 2
        intervals.append((last[0], float(duration)))
    return [(start, min(end, float(duration))) for start, end in intervals if start < duration]
