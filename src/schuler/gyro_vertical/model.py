"""Gyro vertical with integral correction measuring velocity (Drozdovich 1959).

A gyroscope in a Cardan suspension, spin axis near the vertical, carries two
accelerometers on its housing. Their signals are integrated, and the integrator
outputs drive the gyro's torquers (the "integral correction", eq. (6)). Tuned to
the Schuler condition k = H/R (11) the vertical has no ballistic deviation and
the integrator outputs are the components of the vehicle's velocity.

Frames and signs
----------------
* The horizontal frame ``o x0 y0 z0`` (z0 up), its azimuth theta, the velocity
  angle gamma and the Earth and transport rates in it are those of the path
  (:mod:`schuler.gyro_vertical.trajectory`).
* Tilts: alpha about x (outer gimbal), beta about y (inner gimbal). To first order
  the spin axis is (beta, -alpha, 1) in (x0, y0, z0); the accelerometer on x reads
  W_x - g beta and the one on y reads W_y + g alpha (the integrands of (6)).

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
>>> frozen = GreatCircleTrajectory.from_source(latitude=np.radians(60), speed=10.0, frozen=True)
>>> moving = GreatCircleTrajectory.from_source(latitude=np.radians(60), speed=10.0)
>>> t = np.linspace(0.0, 3600.0, 3)
>>> [GyroVertical(path, DROZDOVICH.gravity).simulate(t).method for path in (frozen, moving)]
['exact', 'DOP853']
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from schuler.core.earth import STANDARD_GRAVITY
from schuler.core.lti import StateSpace, simulate
from schuler.exceptions import InvalidParameter, SimulationError
from schuler.gyro_vertical.trajectory import (
    GreatCircleTrajectory,
    Kinematics,
    check_finite,
    transport_coriolis_acceleration,
)

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
        kappa = k R / H, dimensionless (1 is the Schuler condition (11)).

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
        The trajectory's kinematics at the times wanted (SI: velocities m/s, rates rad/s).
    radius : float or ndarray
        R, m.
    schuler_tuning : float or ndarray
        kappa = k R / H, dimensionless (1: the Schuler condition (11)).
    earth_rate_compensation, transport_coriolis_compensation : bool or ndarray of bool
        Apply the torques (8); subtract W* (21) from the accelerometer signals. Flags (dimensionless), one
        per member when arrays.
    accelerometer_bias : pair of float or ndarray
        (b_x, b_y), m/s^2.
    gyro_drift : pair of float or ndarray
        (eps_x, eps_y), rad/s.

    Returns
    -------
    f_x, f_y : ndarray
        Specific-force inputs, m/s^2, broadcast to a common shape (times, or members).
    e_x, e_y : ndarray
        Angular-rate inputs, rad/s, same shape.

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
                check_finite(name, value)

    @property
    def radius(self) -> float:
        return self.trajectory.radius

    def forcing(self, kinematics: Kinematics):
        """Error-model inputs (f_x, f_y, e_x, e_y) along a trajectory (see :func:`forcing`).

        Parameters
        ----------
        kinematics : Kinematics
            The trajectory's kinematics at the times wanted (SI).
        """
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

        Parameters
        ----------
        t : float
            Time, s.
        state : ndarray, shape (4,)
            (alpha, beta) in rad and (V_x, V_y) in m/s.
        kinematics : Kinematics
            The trajectory's kinematics at ``t`` (SI).

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
            kinematics = path.piece_kinematics(index)

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
