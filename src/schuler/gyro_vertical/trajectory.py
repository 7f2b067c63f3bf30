"""The vehicle's path: a great circle on the rotating spherical Earth (Drozdovich 1959).

Frames and signs
----------------
* Horizontal frame ``o x0 y0 z0``: z0 up, x0 along the outer gimbal axis, y0 = z0 x x0.
  The frame moves with the vehicle along a great circle on the rotating Earth and
  keeps a constant angle to the velocity.
* theta: azimuth of x0, measured from north toward east, so that the north unit
  vector is (cos theta, sin theta) in (x0, y0). It is the source's psi + gamma
  and is used everywhere psi appears (torques (8), accelerations (19), (21)).
* gamma: the angle from x0 to the velocity, positive toward y0, so that
  (v_x, v_y) = v (cos gamma, sin gamma); constant along the path. The velocity
  course (from north toward east) is theta - gamma. The source's worked example is
  theta = 0 (x0 north, y0 west) and gamma = 90 deg (v along +y0: due west).
* Earth rate in the frame: omega_1 cos theta along x0, omega_1 sin theta along y0,
  omega_2 = Omega sin phi along z0; transport rate (-v_y / R, v_x / R, 0) (eq. (2)).
  (x0, -y0, -z0) is the core's level frame at azimuth theta
  (:func:`~schuler.core.geometry.level_frame_earth_rate`).

The absolute acceleration (19) is the sum of the transport (15), relative (16)
and Coriolis (18) parts; its horizontal transport-plus-Coriolis part W* is (21).
The model of the vertical itself is in :mod:`schuler.gyro_vertical.model`.

Examples
--------
>>> from schuler.core.earth import DROZDOVICH
>>> path = GreatCircleTrajectory.from_source(latitude=np.radians(60), speed=10.0)
>>> k = path.kinematics(0.0)
>>> round(float(transport_coriolis_acceleration(k, DROZDOVICH.radius)[0]), 5)
0.0135
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from schuler.core.earth import EARTH_RATE, MEAN_RADIUS, STANDARD_GRAVITY
from schuler.core.geometry import level_frame_earth_rate
from schuler.exceptions import InvalidParameter


def check_finite(name: str, value) -> float:
    """``value`` as a float; InvalidParameter naming ``name`` unless it is finite.

    Parameters
    ----------
    name : str
        Name used in the error message.
    value : float
        The value (any unit).
    """
    value = float(value)
    if not math.isfinite(value):
        raise InvalidParameter(name, f"must be a finite number, got {value}")
    return value


@dataclass(frozen=True)
class SpeedProfile:
    """Speed along the path, piecewise linear between knots, held after the last one.

    Parameters
    ----------
    times : array_like
        Knot times, s, strictly increasing, the first at 0.
    speeds : array_like
        Speed at each knot, m/s (>= 0).

    Examples
    --------
    >>> p = SpeedProfile([0.0, 100.0], [0.0, 10.0])
    >>> float(p.speed(50.0)), float(p.distance(100.0)), float(p.acceleration(50.0))
    (5.0, 500.0, 0.1)
    """

    times: np.ndarray
    speeds: np.ndarray
    # derived in __post_init__: the slope of each piece (0 after the last knot), m/s^2, and the
    # distance at each knot, m
    _slopes: np.ndarray = field(init=False, repr=False, compare=False)
    _distances: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        times = np.atleast_1d(np.asarray(self.times, dtype=float))
        speeds = np.atleast_1d(np.asarray(self.speeds, dtype=float))
        if times.shape != speeds.shape or times.ndim != 1:
            raise InvalidParameter("speed_profile", "needs one speed per knot time")
        if not (np.all(np.isfinite(times)) and np.all(np.isfinite(speeds))):
            raise InvalidParameter("speed_profile", "contains NaN or infinite values")
        if times[0] != 0.0 or np.any(np.diff(times) <= 0):
            raise InvalidParameter("speed_profile", "knot times must start at 0 and increase")
        if np.any(speeds < 0):
            raise InvalidParameter("speed", "must not be negative")
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "speeds", speeds)
        slopes = np.diff(speeds) / np.diff(times) if times.size > 1 else np.zeros(0)
        object.__setattr__(self, "_slopes", np.append(slopes, 0.0))
        steps = np.diff(times) * (speeds[:-1] + speeds[1:]) / 2.0
        object.__setattr__(self, "_distances", np.concatenate([[0.0], np.cumsum(steps)]))

    @classmethod
    def constant(cls, speed: float) -> SpeedProfile:
        """A constant speed, m/s.

        Parameters
        ----------
        speed : float
            Speed, m/s.
        """
        return cls(np.zeros(1), np.array([speed], dtype=float))

    def _piece(self, t):
        return np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, self.times.size - 1)

    def piece(self, index: int) -> tuple[float, float, float, float]:
        """Start time (s), distance (m), speed (m/s) and acceleration (m/s^2) of piece ``index``.

        Parameters
        ----------
        index : int
            Index of the piece.
        """
        return (float(self.times[index]), float(self._distances[index]), float(self.speeds[index]),
                float(self._slopes[index]))

    def speed(self, t):
        """Speed at time ``t`` (s), m/s.

        Parameters
        ----------
        t : float or ndarray
            Time, s.
        """
        k = self._piece(t)
        return self.speeds[k] + self._slopes[k] * (np.asarray(t) - self.times[k])

    def acceleration(self, t):
        """Along-path acceleration at ``t`` (s), m/s^2 (right-continuous at knots).

        Parameters
        ----------
        t : float or ndarray
            Time, s.
        """
        return self._slopes[self._piece(t)]

    def distance(self, t):
        """Distance travelled at ``t`` (s), m.

        Parameters
        ----------
        t : float or ndarray
            Time, s.
        """
        k = self._piece(t)
        dt = np.asarray(t) - self.times[k]
        return self._distances[k] + self.speeds[k] * dt + 0.5 * self._slopes[k] * dt**2

    @property
    def max_speed(self) -> float:
        return float(self.speeds.max())

    @property
    def is_constant(self) -> bool:
        return bool(np.all(self.speeds == self.speeds[0]))


@dataclass(frozen=True)
class Kinematics:
    """Trajectory quantities in the horizontal frame (SI): arrays over time, or floats at one time.

    :meth:`GreatCircleTrajectory.kinematics` and :func:`start_kinematics` fill it with
    arrays; :meth:`GreatCircleTrajectory.piece_kinematics` with plain floats, for an ODE
    right-hand side.

    Attributes
    ----------
    latitude : phi, rad.
    omega_1x, omega_1y : omega_1 cos theta and omega_1 sin theta, horizontal Earth
        rate along x0 and y0, rad/s.
    omega_2 : Omega sin phi, vertical Earth rate, rad/s.
    v_x, v_y : velocity relative to the Earth along x0, y0, m/s.
    a_x, a_y : relative acceleration v_x', v_y', m/s^2.
    """

    latitude: np.ndarray | float
    omega_1x: np.ndarray | float
    omega_1y: np.ndarray | float
    omega_2: np.ndarray | float
    v_x: np.ndarray | float
    v_y: np.ndarray | float
    a_x: np.ndarray | float
    a_y: np.ndarray | float


@dataclass(frozen=True)
class GreatCircleTrajectory:
    """A vehicle moving along a great circle on the rotating spherical Earth.

    Parameters
    ----------
    latitude : float
        Start latitude phi_0, rad, in [-pi/2, pi/2].
    azimuth : float
        theta_0: azimuth of x0 at the start, rad, from north toward east.
    velocity_angle : float
        gamma: angle from x0 to the velocity, rad, positive toward y0 (constant).
    speed : SpeedProfile
        Speed along the path.
    radius : float
        R, m.
    rate : float
        Earth rotation rate Omega, rad/s.
    frozen : bool
        Keep latitude, azimuth and speed at their start values (the source's
        slowly-varying assumption); the model is then time-invariant.

    Notes
    -----
    The position moves along the great circle through the start point with
    initial course chi_0 = theta_0 - gamma by the angle sigma = s(t) / R. With
    k the Earth's axis, r the position and t the direction of motion (unit
    vectors), k.r = sin phi, k.(r x t) = cos phi_0 sin chi_0 (Clairaut's
    constant), and the frame axes are x0 = t cos gamma - (r x t) sin gamma,
    y0 = r x x0, so that omega_1 cos theta = Omega k.x0 and omega_1 sin theta =
    Omega k.y0 hold without any singularity at the poles.
    """

    latitude: float
    azimuth: float = 0.0
    velocity_angle: float = math.pi / 2
    speed: SpeedProfile = field(default_factory=lambda: SpeedProfile.constant(0.0))
    radius: float = MEAN_RADIUS
    rate: float = EARTH_RATE
    frozen: bool = False

    def __post_init__(self):
        lat = check_finite("latitude", self.latitude)
        if abs(lat) > math.pi / 2 + 1e-12:
            raise InvalidParameter("latitude", f"{math.degrees(lat):g} deg is outside [-90, 90] deg")
        check_finite("azimuth", self.azimuth)
        check_finite("velocity_angle", self.velocity_angle)
        if not (self.radius > 0 and math.isfinite(self.radius)):
            raise InvalidParameter("radius", "must be positive")
        orbital = math.sqrt(STANDARD_GRAVITY * self.radius)
        if self.speed.max_speed >= orbital:
            raise InvalidParameter(
                "speed", f"{self.speed.max_speed:g} m/s is not below the orbital speed sqrt(g R) = {orbital:.0f} m/s"
            )

    @classmethod
    def from_source(cls, latitude: float, speed: float, radius: float = 6.4e6, rate: float = 7.3e-5,
                    **kwargs) -> GreatCircleTrajectory:
        """The worked example's geometry (theta = 0, v along +y0) with the source's constants.

        Parameters
        ----------
        latitude : float
            Start latitude, rad.
        speed : float
            Constant speed, m/s.
        radius : float
            R, m (the source's 6.4e6 m).
        rate : float
            Omega, rad/s (the source's 7.3e-5 1/s).
        **kwargs
            Further fields (``frozen``).
        """
        return cls(latitude, 0.0, math.pi / 2, SpeedProfile.constant(speed), radius, rate, **kwargs)

    @property
    def course(self) -> float:
        """Initial course of the velocity chi_0 = theta_0 - gamma, rad (from north toward east)."""
        return self.azimuth - self.velocity_angle

    def _geometry(self, sigma):
        phi0, chi0 = self.latitude, self.course
        kr = math.sin(phi0) * np.cos(sigma) + math.cos(phi0) * math.cos(chi0) * np.sin(sigma)
        kt = -math.sin(phi0) * np.sin(sigma) + math.cos(phi0) * math.cos(chi0) * np.cos(sigma)
        pole = math.cos(phi0) * math.sin(chi0)
        cg, sg = math.cos(self.velocity_angle), math.sin(self.velocity_angle)
        return kr, kt * cg - pole * sg, pole * cg + kt * sg

    def kinematics(self, t) -> Kinematics:
        """Latitude, Earth-rate components, velocity and acceleration at times ``t`` (s).

        Parameters
        ----------
        t : float or ndarray
            Time, s.
        """
        t = np.asarray(t, dtype=float)
        if self.frozen:
            t0 = np.zeros_like(t)
            sigma, speed, accel = t0, self.speed.speed(t0), np.zeros_like(t)
        else:
            sigma = self.speed.distance(t) / self.radius
            speed, accel = self.speed.speed(t), self.speed.acceleration(t)
        kr, kx, ky = self._geometry(sigma)
        cg, sg = math.cos(self.velocity_angle), math.sin(self.velocity_angle)
        return Kinematics(
            latitude=np.arcsin(np.clip(kr, -1.0, 1.0)),
            omega_1x=self.rate * kx,
            omega_1y=self.rate * ky,
            omega_2=self.rate * kr,
            v_x=speed * cg,
            v_y=speed * sg,
            a_x=accel * cg,
            a_y=accel * sg,
        )

    def piece_kinematics(self, index: int) -> Callable[[float], Kinematics]:
        """Scalar kinematics on piece ``index`` of the speed profile, where speed is linear in time.

        For the ODE solver's right-hand side, called once per stage: plain floats,
        no arrays. The piece is the one starting at ``speed.times[index]`` (for a
        frozen path, the start values throughout).

        Parameters
        ----------
        index : int
            Index of the speed profile's piece.

        """
        start, s0, v0, accel = self.speed.piece(index)
        if self.frozen:
            start, s0, accel = 0.0, 0.0, 0.0
        cg, sg = math.cos(self.velocity_angle), math.sin(self.velocity_angle)
        R, rate, moving = self.radius, self.rate, not self.frozen

        def kinematics(t: float) -> Kinematics:
            tau = t - start
            speed = v0 + accel * tau
            sigma = (s0 + v0 * tau + 0.5 * accel * tau * tau) / R if moving else 0.0
            kr, kx, ky = self._geometry(sigma)
            return Kinematics(math.asin(max(-1.0, min(1.0, kr))), rate * kx, rate * ky, rate * kr,
                              speed * cg, speed * sg, accel * cg, accel * sg)

        return kinematics

    @property
    def is_stationary(self) -> bool:
        """True when the frame's Earth rates and the velocity never change (time-invariant model)."""
        if self.frozen or self.speed.max_speed == 0.0:
            return True
        # along the equator due east or west the latitude stays zero and theta stays fixed
        on_equator = self.latitude == 0.0 and math.isclose(abs(math.sin(self.course)), 1.0, rel_tol=0, abs_tol=1e-15)
        return on_equator and self.speed.is_constant


def transport_coriolis_acceleration(kinematics: Kinematics, radius: float | np.ndarray):
    """Transport (centripetal) plus Coriolis horizontal acceleration W*, eq. (21), m/s^2.

    W*_x = R omega_1 omega_2 cos(psi + gamma) - 2 omega_2 v_y,
    W*_y = R omega_1 omega_2 sin(psi + gamma) + 2 omega_2 v_x,
    with psi + gamma = theta (the azimuth of x0).

    Parameters
    ----------
    kinematics : Kinematics
    radius : float or ndarray
        R, m (one per case, or one for all).

    Returns
    -------
    W_star_x, W_star_y : ndarray
        m/s^2.
    """
    k = kinematics
    return (radius * k.omega_1x * k.omega_2 - 2.0 * k.omega_2 * k.v_y,
            radius * k.omega_1y * k.omega_2 + 2.0 * k.omega_2 * k.v_x)


@dataclass(frozen=True)
class AbsoluteAcceleration:
    """Absolute acceleration of the vehicle in the horizontal frame, eqs. (15)-(19), m/s^2.

    Each part has components (x, y, z) along (x0, y0, z0).
    """

    transport: tuple
    relative: tuple
    coriolis: tuple

    @property
    def total(self) -> tuple:
        return tuple(a + b + c for a, b, c in zip(self.transport, self.relative, self.coriolis))


def absolute_acceleration(kinematics: Kinematics, radius: float) -> AbsoluteAcceleration:
    """Transport (15), relative (16) and Coriolis (18) accelerations; their sum is (19).

    Parameters
    ----------
    kinematics : Kinematics
    radius : float
        R, m.

    Notes
    -----
    Transport: Omega x (Omega x r) = (R omega_1 omega_2 cos theta,
    R omega_1 omega_2 sin theta, -R omega_1^2); relative along the great circle:
    (v_x', v_y', -v^2 / R); Coriolis 2 Omega x v = (-2 omega_2 v_y, 2 omega_2 v_x,
    2 (omega_1x v_y - omega_1y v_x)). The source writes the last as
    2 omega_1 v sin psi with its own angle convention.

    Examples
    --------
    >>> path = GreatCircleTrajectory.from_source(latitude=0.0, speed=0.0)
    >>> acc = absolute_acceleration(path.kinematics(0.0), 6.4e6)
    >>> round(float(acc.total[2]), 5)   # -R Omega^2 at the equator
    -0.03411
    """
    k, R = kinematics, radius
    omega_1_sq = k.omega_1x**2 + k.omega_1y**2
    transport = (R * k.omega_1x * k.omega_2, R * k.omega_1y * k.omega_2, -R * omega_1_sq)
    relative = (k.a_x, k.a_y, -(k.v_x**2 + k.v_y**2) / R)
    coriolis = (-2.0 * k.omega_2 * k.v_y, 2.0 * k.omega_2 * k.v_x, 2.0 * (k.omega_1x * k.v_y - k.omega_1y * k.v_x))
    return AbsoluteAcceleration(transport, relative, coriolis)



def start_kinematics(latitude, azimuth, velocity_angle, speed, rate) -> Kinematics:
    """Kinematics at the start of many paths at once (arrays of equal length, SI).

    Parameters
    ----------
    latitude, azimuth, velocity_angle : ndarray
        phi_0, theta_0, gamma, rad.
    speed : ndarray
        m/s.
    rate : ndarray or float
        Omega, rad/s.

    Examples
    --------
    >>> k = start_kinematics(np.radians([0.0, 90.0]), 0.0, np.pi / 2, 10.0, 7.3e-5)
    >>> k.omega_2.round(7).tolist(), k.v_y.tolist()
    ([0.0, 7.3e-05], [10.0, 10.0])
    """
    latitude, azimuth, velocity_angle, speed = np.broadcast_arrays(latitude, azimuth, velocity_angle, speed)
    # (x0, -y0, -z0) is the core's level frame at azimuth theta
    along_x, minus_along_y, down = level_frame_earth_rate(latitude, azimuth, rate)
    zero = np.zeros_like(speed, dtype=float)
    return Kinematics(latitude, along_x, -minus_along_y, -down,
                      speed * np.cos(velocity_angle), speed * np.sin(velocity_angle), zero, zero)
