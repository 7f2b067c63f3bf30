"""Gyro vertical with integral correction measuring velocity (Drozdovich 1959).

A gyroscope in a Cardan suspension, spin axis near the vertical, carries two
accelerometers on its housing. Their signals are integrated, and the integrator
outputs drive the gyro's torquers (the "integral correction", eq. (6)). Tuned to
the Schuler condition k = H/R (11) the vertical has no ballistic deviation and
the integrator outputs are the components of the vehicle's velocity.

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
* Tilts: alpha about x (outer gimbal), beta about y (inner gimbal). To first order
  the spin axis is (beta, -alpha, 1) in (x0, y0, z0); the accelerometer on x reads
  W_x - g beta and the one on y reads W_y + g alpha (the integrands of (6)).
* Earth rate in the frame: omega_1 cos theta along x0, omega_1 sin theta along y0,
  omega_2 = Omega sin phi along z0; transport rate (-v_y / R, v_x / R, 0) (eq. (2)).

Equations (source numbering), nutation neglected (5): H omega_y = M_x,
-H omega_x = M_y with the linearised housing rates (2'), torques (6) with
k1 = k2 = kappa H / R (kappa = 1 is the Schuler condition (11)), compensation
torques (8) M1x = H omega_1 sin theta, M1y = -H omega_1 cos theta. The states are
the tilts and the integrator outputs V_x, V_y (measured velocity, m/s):

    beta'  = kappa V_x / R + M1x / H - (omega_1 sin theta + v_x / R) - omega_2 alpha + eps_y
    alpha' = -kappa V_y / R - M1y / H - (omega_1 cos theta - v_y / R) + omega_2 beta + eps_x
    V_x'   = W_x - g beta + b_x - C W*_x
    V_y'   = W_y + g alpha + b_y - C W*_y

with the absolute accelerations (19) W = W* + v' (transport + Coriolis (21), plus
the relative acceleration), accelerometer biases b, gyro drift rates eps and the
switch C = 1 when the computing device subtracts the transport and Coriolis terms
computed from the known trajectory (the "additional devices" of the source's
conclusions). With Delta v = V - v the error model is linear (see
:func:`error_state_space`); on a great circle omega_2 changes with latitude, so
the model is time-varying and is integrated by :func:`scipy.integrate.solve_ivp`.

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
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from schuler.core.earth import EARTH_RATE, MEAN_RADIUS, STANDARD_GRAVITY
from schuler.core.lti import StateSpace, simulate
from schuler.exceptions import InvalidParameter, SimulationError

# Tolerances of the time-varying solve (DOP853). Tilts are ~1e-3 rad and velocity
# errors ~1 m/s; a tilt error of 1e-12 rad excites a velocity oscillation of only
# 1e-12 sqrt(g R) ~ 1e-8 m/s, and rtol = 1e-10 keeps the phase error after 48 h
# (35 Schuler periods) near 1e-8 rad, far below the 0.1 % period and 1 % amplitude
# checks. Tighter settings only add steps.
RTOL = 1e-10
ATOL_TILT = 1e-12
ATOL_VELOCITY = 1e-9

STATE_NAMES = ("alpha", "beta", "velocity_error_x", "velocity_error_y")
STATE_UNITS = ("rad", "rad", "m/s", "m/s")


def _check_finite(name: str, value) -> float:
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
        """A constant speed, m/s."""
        return cls([0.0], [speed])

    def _piece(self, t):
        return np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, self.times.size - 1)

    def piece(self, index: int) -> tuple[float, float, float, float]:
        """Start time (s), distance (m), speed (m/s) and acceleration (m/s^2) of piece ``index``."""
        return (float(self.times[index]), float(self._distances[index]), float(self.speeds[index]),
                float(self._slopes[index]))

    def speed(self, t):
        """Speed at time ``t`` (s), m/s."""
        k = self._piece(t)
        return self.speeds[k] + self._slopes[k] * (np.asarray(t) - self.times[k])

    def acceleration(self, t):
        """Along-path acceleration at ``t`` (s), m/s^2 (right-continuous at knots)."""
        return self._slopes[self._piece(t)]

    def distance(self, t):
        """Distance travelled at ``t`` (s), m."""
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
    """Trajectory quantities in the horizontal frame (arrays over time, SI).

    Attributes
    ----------
    latitude : phi, rad.
    omega_1x, omega_1y : omega_1 cos theta and omega_1 sin theta, horizontal Earth
        rate along x0 and y0, rad/s.
    omega_2 : Omega sin phi, vertical Earth rate, rad/s.
    v_x, v_y : velocity relative to the Earth along x0, y0, m/s.
    a_x, a_y : relative acceleration v_x', v_y', m/s^2.
    """

    latitude: np.ndarray
    omega_1x: np.ndarray
    omega_1y: np.ndarray
    omega_2: np.ndarray
    v_x: np.ndarray
    v_y: np.ndarray
    a_x: np.ndarray
    a_y: np.ndarray


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
        lat = _check_finite("latitude", self.latitude)
        if abs(lat) > math.pi / 2 + 1e-12:
            raise InvalidParameter("latitude", f"{math.degrees(lat):g} deg is outside [-90, 90] deg")
        _check_finite("azimuth", self.azimuth)
        _check_finite("velocity_angle", self.velocity_angle)
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
        """The worked example's geometry (theta = 0, v along +y0) with the source's constants."""
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
        """Latitude, Earth-rate components, velocity and acceleration at times ``t`` (s)."""
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

    @property
    def is_stationary(self) -> bool:
        """True when the frame's Earth rates and the velocity never change (time-invariant model)."""
        if self.frozen or self.speed.max_speed == 0.0:
            return True
        # along the equator due east or west the latitude stays zero and theta stays fixed
        on_equator = self.latitude == 0.0 and math.isclose(abs(math.sin(self.course)), 1.0, rel_tol=0, abs_tol=1e-15)
        return on_equator and self.speed.is_constant


def transport_coriolis_acceleration(kinematics: Kinematics, radius: float):
    """Transport (centripetal) plus Coriolis horizontal acceleration W*, eq. (21), m/s^2.

    W*_x = R omega_1 omega_2 cos(psi + gamma) - 2 omega_2 v_y,
    W*_y = R omega_1 omega_2 sin(psi + gamma) + 2 omega_2 v_x,
    with psi + gamma = theta (the azimuth of x0).

    Parameters
    ----------
    kinematics : Kinematics
    radius : float
        R, m.

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


def error_state_space(omega_2, gravity: float, radius: float, schuler_tuning: float = 1.0) -> StateSpace:
    """Linear error model of the gyro vertical for a fixed vertical Earth rate.

    States (alpha, beta, Delta v_x, Delta v_y) in rad, rad, m/s, m/s; inputs
    (f_x, f_y, e_x, e_y): specific-force forcing W* + b (m/s^2) and rate forcing
    eps (rad/s)::

        alpha'     =  omega_2 beta - kappa Delta v_y / R + e_x
        beta'      = -omega_2 alpha + kappa Delta v_x / R + e_y
        Delta v_x' = -g beta + f_x
        Delta v_y' =  g alpha + f_y

    This is (13)/(24) written with the velocity errors (28) as states; eliminating
    them gives (25).

    Parameters
    ----------
    omega_2 : float or ndarray of shape (N,)
        Vertical Earth rate Omega sin phi, rad/s; an array makes a batch.
    gravity : float
        g, m/s^2.
    radius : float
        R, m.
    schuler_tuning : float
        kappa = k R / H (1 is the Schuler condition (11)).

    Examples
    --------
    >>> sys = error_state_space(7.3e-5 * np.sin(np.radians(60)), 9.81, 6.4e6)
    >>> w = np.sort(np.abs(sys.eigenvalues().imag))[::2]
    >>> [round(float(2 * np.pi / x / 60), 2) for x in w]
    [86.77, 82.45]
    """
    omega_2 = np.asarray(omega_2, dtype=float)
    k = schuler_tuning / radius
    A = np.zeros(omega_2.shape + (4, 4))
    A[..., 0, 1] = omega_2
    A[..., 0, 3] = -k
    A[..., 1, 0] = -omega_2
    A[..., 1, 2] = k
    A[..., 2, 1] = -gravity
    A[..., 3, 0] = gravity
    B = np.zeros(omega_2.shape + (4, 4))
    B[..., 2, 0] = 1.0
    B[..., 3, 1] = 1.0
    B[..., 0, 2] = 1.0
    B[..., 1, 3] = 1.0
    return StateSpace(A, B, states=STATE_NAMES, inputs=("f_x", "f_y", "e_x", "e_y"), state_units=STATE_UNITS)


def forcing(kinematics: Kinematics, radius, schuler_tuning=1.0, earth_rate_compensation=True,
            transport_coriolis_compensation=False, accelerometer_bias=(0.0, 0.0), gyro_drift=(0.0, 0.0)):
    """Inputs (f_x, f_y, e_x, e_y) of :func:`error_state_space` along a trajectory (vectorised).

    f = (1 - C) W* + b, m/s^2 (C = 1 when W* (21) is compensated);
    e = eps - (1 - E) omega_1 (cos theta, sin theta) + (kappa - 1)(-v_y, v_x)/R, rad/s
    (E = 1 when the torques (8) are applied): the drift, the Earth rate (8) leaves,
    and the transport rate a mistuned gain leaves.

    Parameters
    ----------
    kinematics : Kinematics
    radius : float or ndarray
        R, m.
    schuler_tuning : float or ndarray
        kappa.
    earth_rate_compensation, transport_coriolis_compensation : bool or ndarray of bool
    accelerometer_bias : pair of float or ndarray
        (b_x, b_y), m/s^2.
    gyro_drift : pair of float or ndarray
        (eps_x, eps_y), rad/s.

    Examples
    --------
    >>> k = GreatCircleTrajectory.from_source(np.radians(60), 10.0).kinematics(0.0)
    >>> [round(float(x), 5) for x in forcing(k, 6.4e6, transport_coriolis_compensation=True)]
    [0.0, 0.0, 0.0, 0.0]
    """
    k = kinematics
    W_x, W_y = transport_coriolis_acceleration(k, radius)
    keep = np.where(transport_coriolis_compensation, 0.0, 1.0)
    leak = np.where(earth_rate_compensation, 0.0, 1.0)
    mistuning = (np.asarray(schuler_tuning) - 1.0) / radius
    f_x = keep * W_x + accelerometer_bias[0]
    f_y = keep * W_y + accelerometer_bias[1]
    e_x = gyro_drift[0] - leak * k.omega_1x - mistuning * k.v_y
    e_y = gyro_drift[1] - leak * k.omega_1y + mistuning * k.v_x
    return np.broadcast_arrays(f_x, f_y, e_x, e_y)


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
    omega_1 = rate * np.cos(latitude)
    zero = np.zeros_like(speed)
    return Kinematics(latitude, omega_1 * np.cos(azimuth), omega_1 * np.sin(azimuth), rate * np.sin(latitude),
                      speed * np.cos(velocity_angle), speed * np.sin(velocity_angle), zero, zero)


@dataclass(frozen=True)
class VerticalResponse:
    """Time histories of a gyro-vertical simulation (SI).

    Attributes
    ----------
    time : s. alpha, beta : tilts, rad.
    measured_velocity_x, measured_velocity_y : integrator outputs, m/s.
    true_velocity_x, true_velocity_y : m/s. velocity_error_x, velocity_error_y :
    measured minus true, m/s. latitude : rad.
    method : "exact" (matrix exponential) or the solve_ivp method.
    nfev, n_steps : solver work (0 for the exact method; n_steps = time steps then).
    """

    time: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    measured_velocity_x: np.ndarray
    measured_velocity_y: np.ndarray
    true_velocity_x: np.ndarray
    true_velocity_y: np.ndarray
    latitude: np.ndarray
    method: str
    nfev: int
    n_steps: int

    @property
    def velocity_error_x(self) -> np.ndarray:
        return self.measured_velocity_x - self.true_velocity_x

    @property
    def velocity_error_y(self) -> np.ndarray:
        return self.measured_velocity_y - self.true_velocity_y


@dataclass(frozen=True)
class GyroVertical:
    """The gyro vertical with integral correction on a moving base.

    Parameters
    ----------
    trajectory : GreatCircleTrajectory
    gravity : float
        g, m/s^2 (gravity "neglecting the centripetal acceleration", as in (6)).
    schuler_tuning : float
        kappa = k_1 R / H = k_2 R / H; 1 satisfies the Schuler condition (11).
    earth_rate_compensation : bool
        Apply the torques (8) M1x = H omega_1 sin theta, M1y = -H omega_1 cos theta.
    transport_coriolis_compensation : bool
        Subtract the transport and Coriolis accelerations W* (21), computed from the
        known trajectory, from the accelerometer signals before integration.
    accelerometer_bias : tuple of float
        (b_x, b_y), m/s^2.
    gyro_drift : tuple of float
        (eps_x, eps_y): drift rates of the housing about x and y, rad/s.
    initial_tilt : tuple of float
        (alpha_0, beta_0), rad: the tilt at t = 0, measured from the levelled
        position when ``levelled_start`` is set, else from the geocentric vertical.
    levelled_start : bool
        Start from the position where both accelerometers read zero,
        beta = (W*_x + b_x)/g, alpha = -(W*_y + b_y)/g (after the compensation), as a
        vertical erected on its accelerometers would. Otherwise the start is the
        geocentric vertical, about 1.5e-3 rad off at mid latitudes: a Schuler
        oscillation of about 11 m/s then hides the systematic error.
    preset_integrators : bool
        Start the integrators at the true initial velocity (what (24) assumes);
        otherwise at zero.

    Examples
    --------
    >>> from schuler.core.earth import DROZDOVICH as E
    >>> path = GreatCircleTrajectory.from_source(np.radians(60), 10.0, frozen=True)
    >>> r = GyroVertical(path, E.gravity).simulate(np.linspace(0, 5000, 3))
    >>> r.method, round(float(r.velocity_error_y[0]), 6)
    ('exact', 0.0)
    """

    trajectory: GreatCircleTrajectory
    gravity: float = STANDARD_GRAVITY
    schuler_tuning: float = 1.0
    earth_rate_compensation: bool = True
    transport_coriolis_compensation: bool = False
    accelerometer_bias: tuple[float, float] = (0.0, 0.0)
    gyro_drift: tuple[float, float] = (0.0, 0.0)
    initial_tilt: tuple[float, float] = (0.0, 0.0)
    levelled_start: bool = True
    preset_integrators: bool = True

    def __post_init__(self):
        if not (self.gravity > 0 and math.isfinite(self.gravity)):
            raise InvalidParameter("gravity", "must be positive")
        if not (self.schuler_tuning > 0 and math.isfinite(self.schuler_tuning)):
            raise InvalidParameter("schuler_tuning", "must be positive")
        for name, pair in (("accelerometer_bias", self.accelerometer_bias), ("gyro_drift", self.gyro_drift),
                           ("initial_tilt", self.initial_tilt)):
            for value in pair:
                _check_finite(name, value)

    @property
    def radius(self) -> float:
        return self.trajectory.radius

    def forcing(self, kinematics: Kinematics):
        """Error-model inputs (f_x, f_y, e_x, e_y) along a trajectory (see :func:`forcing`)."""
        return forcing(kinematics, self.radius, self.schuler_tuning, self.earth_rate_compensation,
                       self.transport_coriolis_compensation, self.accelerometer_bias, self.gyro_drift)

    def initial_state(self) -> np.ndarray:
        """(alpha, beta, V_x, V_y) at t = 0 (integrator outputs, m/s)."""
        k = self.trajectory.kinematics(0.0)
        preset = 1.0 if self.preset_integrators else 0.0
        alpha, beta = self.initial_tilt
        if self.levelled_start:
            f_x, f_y, _, _ = self.forcing(k)
            alpha, beta = alpha - float(f_y) / self.gravity, beta + float(f_x) / self.gravity
        return np.array([alpha, beta, preset * float(k.v_x), preset * float(k.v_y)])

    def derivative(self, t: float, state: np.ndarray, kinematics: Kinematics) -> np.ndarray:
        """Right-hand side of the full equations for the state (alpha, beta, V_x, V_y).

        Uses (5), (2'), (6) with (11) scaled by kappa, (8) and (19); see the module notes.
        """
        k, R, g = kinematics, self.radius, self.gravity
        alpha, beta, V_x, V_y = state
        kappa = self.schuler_tuning
        W_star_x, W_star_y = transport_coriolis_acceleration(k, R)
        W_x, W_y = W_star_x + k.a_x, W_star_y + k.a_y  # (19)
        m1x = k.omega_1y if self.earth_rate_compensation else 0.0  # (8), divided by H
        m1y = -k.omega_1x if self.earth_rate_compensation else 0.0
        compensated = (W_star_x, W_star_y) if self.transport_coriolis_compensation else (0.0, 0.0)
        return np.array([
            -kappa * V_y / R - m1y - (k.omega_1x - k.v_y / R) + k.omega_2 * beta + self.gyro_drift[0],
            kappa * V_x / R + m1x - (k.omega_1y + k.v_x / R) - k.omega_2 * alpha + self.gyro_drift[1],
            W_x - g * beta + self.accelerometer_bias[0] - compensated[0],
            W_y + g * alpha + self.accelerometer_bias[1] - compensated[1],
        ])

    def simulate(self, time, method: str = "auto", initial_state=None) -> VerticalResponse:
        """Simulate the vertical on the time grid ``time`` (s, starting at 0).

        Parameters
        ----------
        time : array_like
            Increasing output times, s, ``time[0] == 0``.
        method : {"auto", "exact", "ode"}
            "exact": matrix exponential of the time-invariant error model (only for
            a stationary trajectory: at rest, frozen, or along the equator at
            constant speed); "ode": solve_ivp (DOP853) on the full equations, piece
            by piece between the speed profile's knots; "auto" picks "exact" when
            it applies.
        initial_state : array_like, optional
            (alpha, beta, V_x, V_y) at t = 0 (rad, rad, m/s, m/s) instead of
            :meth:`initial_state`.

        Raises
        ------
        InvalidParameter
            For a bad time grid or "exact" on a time-varying trajectory.
        SimulationError
            If the ODE solver fails.
        """
        t = np.asarray(time, dtype=float)
        if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)) or t[0] != 0.0 or np.any(np.diff(t) <= 0):
            raise InvalidParameter("duration", "the time grid must start at 0 and increase")
        start = self.initial_state() if initial_state is None else np.asarray(initial_state, dtype=float)
        if start.shape != (4,) or not np.all(np.isfinite(start)):
            raise InvalidParameter("initial_state", "needs four finite values (alpha, beta, V_x, V_y)")
        stationary = self.trajectory.is_stationary
        if method == "auto":
            method = "exact" if stationary else "ode"
        if method == "exact":
            if not stationary:
                raise InvalidParameter("method", "'exact' needs a time-invariant (stationary or frozen) trajectory")
            return self._simulate_exact(t, start)
        if method != "ode":
            raise InvalidParameter("method", f"{method!r} is not one of auto, exact, ode")
        return self._simulate_ode(t, start)

    def _true_velocity(self, t):
        k = self.trajectory.kinematics(t)
        return k, np.broadcast_to(k.v_x, t.shape), np.broadcast_to(k.v_y, t.shape)

    def _simulate_exact(self, t: np.ndarray, start: np.ndarray) -> VerticalResponse:
        k0 = self.trajectory.kinematics(0.0)
        system = error_state_space(float(k0.omega_2), self.gravity, self.radius, self.schuler_tuning)
        u = np.array([float(x) for x in self.forcing(k0)])
        x0 = start - [0.0, 0.0, float(k0.v_x), float(k0.v_y)]
        response = simulate(system, t, initial_state=x0, inputs=u)
        k, v_x, v_y = self._true_velocity(t)
        s = response.states
        return VerticalResponse(t, s[:, 0], s[:, 1], v_x + s[:, 2], v_y + s[:, 3], v_x, v_y,
                                np.broadcast_to(k.latitude, t.shape), "exact", 0, t.size - 1)

    def _piece_kinematics(self, index: int):
        """Scalar kinematics on one piece of the speed profile, where it is a quadratic in time."""
        path = self.trajectory
        start, s0, v0, accel = path.speed.piece(index)
        if path.frozen:
            start, s0, accel = 0.0, 0.0, 0.0
        cg, sg = math.cos(path.velocity_angle), math.sin(path.velocity_angle)
        R, rate, moving = path.radius, path.rate, not path.frozen

        def kinematics(t: float) -> Kinematics:
            tau = t - start
            speed = v0 + accel * tau
            sigma = (s0 + v0 * tau + 0.5 * accel * tau * tau) / R if moving else 0.0
            kr, kx, ky = path._geometry(sigma)
            return Kinematics(math.asin(max(-1.0, min(1.0, kr))), rate * kx, rate * ky, rate * kr,
                              speed * cg, speed * sg, accel * cg, accel * sg)

        return kinematics

    def _simulate_ode(self, t: np.ndarray, state: np.ndarray) -> VerticalResponse:
        path = self.trajectory
        knots = np.zeros(1) if path.frozen else path.speed.times
        edges = np.concatenate([knots[knots < t[-1]], [t[-1]]])
        out = np.empty((t.size, 4))
        out[0] = state
        nfev = n_steps = 0
        atol = np.array([ATOL_TILT, ATOL_TILT, ATOL_VELOCITY, ATOL_VELOCITY])
        # integrate piece by piece between the speed profile's knots, where the
        # acceleration jumps, so that the solver never steps across a discontinuity
        for index, (start, stop) in enumerate(zip(edges[:-1], edges[1:])):
            kinematics = self._piece_kinematics(index)

            def rhs(time, x, kinematics=kinematics):
                return self.derivative(time, x, kinematics(time))

            inside = (t > start) & (t <= stop)
            solution = solve_ivp(rhs, (start, stop), state, method="DOP853", dense_output=True,
                                 rtol=RTOL, atol=atol)
            if not solution.success:
                raise SimulationError(f"gyro vertical ODE solve failed: {solution.message}")
            if inside.any():  # a piece shorter than the output step may hold no output time
                out[inside] = solution.sol(t[inside]).T
            nfev += solution.nfev
            n_steps += solution.t.size - 1
            state = solution.y[:, -1]
        k, v_x, v_y = self._true_velocity(t)
        return VerticalResponse(t, out[:, 0], out[:, 1], out[:, 2], out[:, 3], v_x, v_y,
                                np.broadcast_to(k.latitude, t.shape), "DOP853", nfev, n_steps)
