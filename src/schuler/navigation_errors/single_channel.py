"""One horizontal channel of a Schuler-tuned INS: five error sources, flat and spherical Earth.

Bollay (1966) (Bollay, "The Story of 84 Minutes"): the platform is levelled by the
computed distance, phi = x / R, so a position error x sees the restoring
acceleration -(g/R) x and obeys

    x'' + (g/R) x = g theta_1(t) + Delta_a,    theta_1 = Delta_theta + epsilon t,

with x(0) = 0 and x'(0) = Delta_V (the source's equations (1) and (3), teaching
note numbering; solutions (2) and (4); Problems 1-3). The flat Earth is the
limit R -> infinity: x'' = g theta_1 + Delta_a.

Frame and signs: x is the position error along the channel's axis (Bollay's
x, m), positive in the direction the error source pushes it: a platform tilt
Delta_theta about the channel's cross axis (Bollay's Delta_theta_y), a gyro drift
rate epsilon about that axis, an accelerometer reading high by Delta_a, an
initial velocity error Delta_V along x all make x grow positive. The platform's
tilt from the local vertical is theta_1 - x / R.

The azimuth misalignment Delta_theta_z is no Schuler-loop error: the vehicle
flies a great circle turned by Delta_theta_z, and the cross-track distance y
after a range r = V t is R sin(r / R) Delta_theta_z (flat Earth: r Delta_theta_z),
the solution of the great-circle (Jacobi) equation y'' + (V/R)^2 y = 0 with
y(0) = 0, y'(0) = V Delta_theta_z.

Closed forms (omega = omega_s = sqrt(g / R)):

=============  ======================  =================================================
source         flat Earth              spherical Earth
=============  ======================  =================================================
tilt           g Delta_theta t^2 / 2   R Delta_theta (1 - cos omega t)
velocity       Delta_V t               (Delta_V / omega) sin omega t
accelerometer  Delta_a t^2 / 2         (Delta_a / omega^2) (1 - cos omega t) = k R (...)
drift          epsilon g t^3 / 6       (R epsilon / omega) (omega t - sin omega t)
azimuth        V t Delta_theta_z       R sin(V t / R) Delta_theta_z
=============  ======================  =================================================

To reproduce the source, pass the loop's effective gravity omega^2 R with
omega = 2 pi / 5060 s (:attr:`schuler.core.earth.BOLLAY.effective_gravity`).

Examples
--------
>>> from schuler.core.earth import BOLLAY, FOOT
>>> x = spherical_error("drift", 4.84813681109536e-08, 10120.0, BOLLAY.radius, BOLLAY.effective_gravity)
>>> round(float(x) / FOOT)
10259
"""

from __future__ import annotations

import numpy as np

from schuler.core.lti import StateSpace, simulate
from schuler.exceptions import InvalidParameter

SOURCES: tuple[str, ...] = ("tilt", "velocity", "accelerometer", "drift", "azimuth")
"""The five error sources of Bollay (1966), Problems 1-3."""

_SCHULER_SOURCES = ("tilt", "velocity", "accelerometer", "drift")


def check_source(source: str) -> str:
    """Return ``source`` if it is one of :data:`SOURCES`, else raise InvalidParameter.

    Parameters
    ----------
    source : str
        Name of an error source.
    """
    if source not in SOURCES:
        raise InvalidParameter("source", f"{source!r} is not one of {', '.join(SOURCES)}")
    return source


def _positive(value, name: str):
    array = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(array)) or np.any(array <= 0):
        raise InvalidParameter(name, f"must be finite and > 0, got {value!r}")
    return array


def _finite(value, name: str, nonnegative: bool = False):
    array = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(array)):
        raise InvalidParameter(name, "must be finite")
    if nonnegative and np.any(array < 0):
        raise InvalidParameter(name, f"must be >= 0, got {value!r}")
    return array


def one_minus_cos(x):
    """1 - cos x without cancellation near 0 (= 2 sin^2(x/2)).

    Parameters
    ----------
    x : float or ndarray
        Angle, rad.

    Examples
    --------
    >>> float(one_minus_cos(1e-8))
    5e-17
    """
    return 2.0 * np.sin(0.5 * np.asarray(x, dtype=float)) ** 2


def x_minus_sin(x):
    """x - sin x, by its Taylor series where the subtraction would cancel (|x| < 0.25).

    Parameters
    ----------
    x : float or ndarray
        Angle, rad.

    Examples
    --------
    >>> float(x_minus_sin(1e-3))
    1.66666658333e-10
    """
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 0.25
    x2 = x * x
    # Horner form of x^3/3! - x^5/5! + ... - x^11/11! (truncation < 1e-14 relative at 0.25)
    series = x * x2 * (1 / 6 - x2 * (1 / 120 - x2 * (1 / 5040 - x2 * (1 / 362880 - x2 / 39916800))))
    return np.where(small, series, x - np.sin(x))


def flat_error(source: str, magnitude, time, gravity, speed=0.0):
    """Position error of the flat-Earth (unlevelled) INS, m.

    Parameters
    ----------
    source : {"tilt", "velocity", "accelerometer", "drift", "azimuth"}
    magnitude : float or ndarray
        Size of the error, SI: Delta_theta (rad) for ``tilt``, Delta_V (m/s) for
        ``velocity``, Delta_a (m/s^2) for ``accelerometer``, epsilon (rad/s) for
        ``drift``, Delta_theta_z (rad) for ``azimuth``.
    time : float or ndarray
        Time since launch t, s (>= 0).
    gravity : float or ndarray
        g, m/s^2 (> 0).
    speed : float or ndarray
        Vehicle speed V, m/s (``azimuth`` only).

    Returns
    -------
    ndarray
        Position error (cross-track for ``azimuth``), m; numpy broadcasting of
        the arguments.

    Notes
    -----
    Bollay (1966), Problem 1 solutions: g Delta_theta t^2/2, Delta_V t, Delta_a t^2/2,
    epsilon g t^3/6, range x Delta_theta_z.

    Examples
    --------
    >>> round(float(flat_error("velocity", 0.3048, 10120.0, 9.81)) / 0.3048)
    10120
    """
    check_source(source)
    t = _finite(time, "time", nonnegative=True)
    m = _finite(magnitude, "magnitude")
    g = _positive(gravity, "gravity")
    if source == "tilt":
        return g * m * t**2 / 2.0
    if source == "velocity":
        return m * t * np.ones_like(g)
    if source == "accelerometer":
        return m * t**2 / 2.0 * np.ones_like(g)
    if source == "drift":
        return m * g * t**3 / 6.0
    return _finite(speed, "speed", nonnegative=True) * t * m * np.ones_like(g)


def spherical_error(source: str, magnitude, time, radius, gravity, speed=0.0):
    """Position error of the Schuler-tuned INS on a spherical Earth, m.

    Parameters
    ----------
    source : {"tilt", "velocity", "accelerometer", "drift", "azimuth"}
    magnitude : float or ndarray
        Size of the error, SI (see :func:`flat_error`).
    time : float or ndarray
        t, s (>= 0).
    radius : float or ndarray
        Earth radius R, m (> 0).
    gravity : float or ndarray
        g, m/s^2 (> 0); omega_s = sqrt(g / R).
    speed : float or ndarray
        V, m/s (``azimuth`` only).

    Returns
    -------
    ndarray
        Position error, m (broadcast shape of the arguments).

    Notes
    -----
    Bollay (1966), solutions (2) and (4) and Problem 2: R Delta_theta (1 - cos wt),
    (Delta_V/w) sin wt, (Delta_a/w^2)(1 - cos wt), (R epsilon/w)(wt - sin wt),
    R sin(r/R) Delta_theta_z with r = V t.

    Examples
    --------
    >>> from schuler.core.earth import BOLLAY, FOOT
    >>> round(float(spherical_error("velocity", FOOT, 1265.0, BOLLAY.radius, BOLLAY.effective_gravity)) / FOOT)
    805
    """
    check_source(source)
    t = _finite(time, "time", nonnegative=True)
    m = _finite(magnitude, "magnitude")
    R = _positive(radius, "radius")
    g = _positive(gravity, "gravity")
    omega = np.sqrt(g / R)
    phase = omega * t
    if source == "tilt":
        return R * m * one_minus_cos(phase)
    if source == "velocity":
        return m / omega * np.sin(phase)
    if source == "accelerometer":
        return m / omega**2 * one_minus_cos(phase)
    if source == "drift":
        return R * m / omega * x_minus_sin(phase)
    V = _finite(speed, "speed", nonnegative=True)
    return R * np.sin(V * t / R) * m * np.ones_like(g)


def maximum_error(source: str, magnitude, duration, radius, gravity, speed=0.0, earth: str = "spherical"):
    """Largest |position error| over 0 <= t <= duration, m, in closed form.

    Parameters
    ----------
    source : str
        One of :data:`SOURCES`.
    magnitude, radius, gravity, speed : float or ndarray
        As in :func:`spherical_error` (SI).
    duration : float or ndarray
        End of the interval, s (>= 0).
    earth : {"spherical", "flat"}

    Returns
    -------
    ndarray
        The maximum, m. Flat-Earth errors and the spherical drift error grow
        monotonically, so their maximum is at ``duration``; the Schuler
        oscillations peak at omega t = pi (tilt, accelerometer: 2 R Delta_theta,
        2 Delta_a / omega^2) or pi/2 (velocity: Delta_V / omega), the azimuth
        error at r / R = pi / 2 (R Delta_theta_z).

    Examples
    --------
    >>> from schuler.core.earth import BOLLAY, FOOT
    >>> round(float(maximum_error("tilt", 1.7453292519943296e-4, 10120.0, BOLLAY.radius,
    ...                            BOLLAY.effective_gravity)) / FOOT)
    7299
    """
    if earth == "flat":
        return np.abs(flat_error(source, magnitude, duration, gravity, speed))
    if earth != "spherical":
        raise InvalidParameter("earth", f"{earth!r} is not flat or spherical")
    check_source(source)
    D = _finite(duration, "duration", nonnegative=True)
    size = np.abs(_finite(magnitude, "magnitude"))
    R = _positive(radius, "radius")
    g = _positive(gravity, "gravity")
    omega = np.sqrt(g / R)
    phase = omega * D
    if source in ("tilt", "accelerometer"):
        amplitude = R * size if source == "tilt" else size / omega**2
        return amplitude * np.where(phase < np.pi, one_minus_cos(phase), 2.0)
    if source == "velocity":
        return size / omega * np.where(phase < np.pi / 2, np.sin(phase), 1.0)
    if source == "drift":
        return R * size / omega * x_minus_sin(phase)
    angle = _finite(speed, "speed", nonnegative=True) * D / R
    return R * size * np.where(angle < np.pi / 2, np.sin(angle), 1.0)


def channel_model(radius: float, gravity: float) -> StateSpace:
    """State-space model of one Schuler-tuned channel (Bollay (1966), equations (1), (3)).

    States: ``position_error`` x (m), ``velocity_error`` x' (m/s),
    ``drift_angle`` theta_1 (rad: the platform's rotation by initial tilt and gyro
    drift, before the levelling feedback). Inputs: ``accelerometer_error``
    Delta_a (m/s^2), ``drift_rate`` epsilon (rad/s). Outputs: the states and
    ``tilt`` = theta_1 - x / R, the platform's tilt from the local vertical (rad).

    x' = v,  v' = g theta_1 - (g/R) x + Delta_a,  theta_1' = epsilon.

    Parameters
    ----------
    radius : float
        R, m (> 0); ``numpy.inf`` gives the flat Earth (no levelling feedback).
    gravity : float
        g, m/s^2 (> 0).

    Examples
    --------
    >>> import numpy as np
    >>> model = channel_model(6.371e6, 9.80665)
    >>> np.allclose(sorted(model.eigenvalues().imag), [-np.sqrt(9.80665 / 6.371e6), 0, np.sqrt(9.80665 / 6.371e6)])
    True
    """
    g = float(_positive(gravity, "gravity"))
    R = float(np.asarray(radius, dtype=float))
    if np.isnan(R) or R <= 0:
        raise InvalidParameter("radius", f"must be > 0, got {radius!r}")
    restoring = 0.0 if np.isinf(R) else g / R
    inverse_radius = 0.0 if np.isinf(R) else 1.0 / R
    A = [[0.0, 1.0, 0.0], [-restoring, 0.0, g], [0.0, 0.0, 0.0]]
    B = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    C = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-inverse_radius, 0.0, 1.0]]
    return StateSpace(
        A, B, C,
        states=("position_error", "velocity_error", "drift_angle"),
        inputs=("accelerometer_error", "drift_rate"),
        outputs=("position_error", "velocity_error", "drift_angle", "tilt"),
        state_units=("m", "m/s", "rad"),
        output_units=("m", "m/s", "rad", "rad"),
    )


def azimuth_model(radius: float, speed: float) -> StateSpace:
    """Cross-track separation of two great circles: y'' + (V/R)^2 y = 0.

    States ``cross_track_error`` y (m) and ``cross_track_rate`` y' (m/s); start
    at y = 0, y' = V Delta_theta_z. ``radius = numpy.inf`` gives straight lines.

    Parameters
    ----------
    radius : float
        R, m (> 0, may be inf).
    speed : float
        V, m/s (>= 0).

    Examples
    --------
    >>> azimuth_model(6.371e6, 800.0).n_states
    2
    """
    R = float(np.asarray(radius, dtype=float))
    if np.isnan(R) or R <= 0:
        raise InvalidParameter("radius", f"must be > 0, got {radius!r}")
    V = float(_finite(speed, "speed", nonnegative=True))
    curvature = 0.0 if np.isinf(R) else (V / R) ** 2
    return StateSpace(
        [[0.0, 1.0], [-curvature, 0.0]],
        states=("cross_track_error", "cross_track_rate"),
        state_units=("m", "m/s"),
    )


def simulate_error(source: str, magnitude: float, time, radius: float, gravity: float, speed: float = 0.0):
    """Position error of one source by exact simulation of the error equations, m.

    Integrates :func:`channel_model` (or :func:`azimuth_model`) with the
    linear-systems engine (matrix exponential, exact for these constant inputs),
    so it must match :func:`spherical_error` (or :func:`flat_error` with
    ``radius = numpy.inf``) to rounding.

    Parameters
    ----------
    source : str
        One of :data:`SOURCES`.
    magnitude : float
        Size of the error, SI (see :func:`flat_error`).
    time : array_like
        Strictly increasing times from 0, s.
    radius : float
        R, m (inf for the flat Earth).
    gravity : float
        g, m/s^2.
    speed : float
        V, m/s (``azimuth``).

    Returns
    -------
    ndarray, shape (n_time,)

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0.0, 5000.0, 6)
    >>> x = simulate_error("accelerometer", 1e-3, t, 6.371e6, 9.80665)
    >>> bool(np.allclose(x, spherical_error("accelerometer", 1e-3, t, 6.371e6, 9.80665)))
    True
    """
    check_source(source)
    size = float(_finite(magnitude, "magnitude"))
    if source == "azimuth":
        response = simulate(azimuth_model(radius, speed), time, initial_state=[0.0, speed * size])
        return response["cross_track_error"]
    initial = {"tilt": [0.0, 0.0, size], "velocity": [0.0, size, 0.0]}.get(source, [0.0, 0.0, 0.0])
    inputs = {"accelerometer": [size, 0.0], "drift": [0.0, size]}.get(source, [0.0, 0.0])
    response = simulate(channel_model(radius, gravity), time, initial_state=initial, inputs=inputs)
    return response["position_error"]
