"""A first-principles 3-D plant: a gyro-stabilised platform on the rotating Earth.

Used to prove the sign chain of the procedure (round trip): nothing here uses
the apparent-drift formulas (3) or the reading formula (11).

Model
-----
Site frame ENU (x east, y north, z up), rotating with the Earth at
``Omega_s = Omega (0, cos phi, sin phi)``. The platform attitude is the
direction-cosine matrix C (platform axes -> site axes). The platform is held by
its gyros: its *inertial* angular rate in platform axes is the measured
channel's gyro drift plus the torquer precession ``(K_M/H) i(t)`` about that
axis, while ideal correction loops hold the other axes to the base (their
inertial rate equals the Earth rate's component). Relative to the site,

    C' = C [omega_ps x],   omega_ps = omega_pi - C^T Omega_s.

The command angle sensor of channel X reads the inner gimbal angle of a
Z-Y-X (azimuth, pitch, roll) suspension, ``atan2(C[2,1], C[2,2])``, and of
channel Y the middle one, ``-asin(C[2,0])``; the integrator state is
``W' = s(t) * angle`` (V / K1). The initial attitude is the level platform at
azimuth A0 (its Y axis A0 clockwise from north), optionally tilted.

Integration: scipy.integrate.solve_ivp (DOP853) piecewise between the pulse
knots and the switch instant, so every discontinuity is a segment boundary;
rtol = 1e-12 and atol = 1e-15 keep the integrated angle (~1e-3 rad s) accurate
to ~1e-12 relative, far below the 1e-8 the round trip asserts.

Example
-------
>>> import numpy as np
>>> from schuler.drift_calibration.pulses import rectangular
>>> reading = plant_reading(np.radians(45), np.radians(30), own_drift=0.0, channel="x",
...                         k1=1.0, tau=5.0, pulse_rate=1e-4, shape=rectangular())
>>> round(float(-reading / 25.0 / (7.292115e-5 * np.cos(np.radians(45)) * 0.5)), 8)   # Omega cos(phi) sin(A0)
1.0
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from schuler.core.attitude import skew
from schuler.core.earth import EARTH_RATE
from schuler.core.geometry import earth_rate_north_up
from schuler.drift_calibration.pulses import PulseShape
from schuler.exceptions import SimulationError


def _rotation_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _rotation_y(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rotation_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def initial_attitude(azimuth: float, pitch: float = 0.0, roll: float = 0.0) -> np.ndarray:
    """C (platform -> ENU) of a platform whose Y axis points at ``azimuth`` (clockwise from north), rad.

    Parameters
    ----------
    azimuth : float
        Azimuth of the platform Y axis, clockwise from north, rad.
    pitch, roll : float
        Turns about the platform Y axis and X axis (small tilts), rad.

    Examples
    --------
    >>> np.round(initial_attitude(np.pi / 2) @ [0.0, 1.0, 0.0], 12) + 0.0   # Y axis east
    array([1., 0., 0.])
    """
    return _rotation_z(-azimuth) @ _rotation_y(pitch) @ _rotation_x(roll)


def plant_reading(
    latitude: float,
    azimuth: float,
    *,
    own_drift: float,
    channel: str,
    k1: float,
    tau: float,
    pulse_rate: float,
    shape: PulseShape,
    pitch: float = 0.0,
    roll: float = 0.0,
    earth_rate: float = EARTH_RATE,
) -> float:
    """Integrator reading Delta U of one cycle on the 3-D plant, V.

    Parameters
    ----------
    latitude, azimuth : float
        Site latitude phi and platform azimuth A0 (of its Y axis, clockwise from north), rad.
    own_drift : float
        Own drift of the measured channel's gyro (inertial rate about its +axis), rad/s.
    channel : {"x", "y"}
        The measured platform axis.
    k1 : float
        Command-sensor gain, V/rad.
    tau : float
        Pulse duration, s.
    pulse_rate : float
        (K_M / H) * amplitude: torquer precession rate of a unit shape, rad/s.
    shape : PulseShape
    pitch, roll : float
        Initial tilts about the platform Y and X axes, rad.
    earth_rate : float
        Omega, rad/s.
    """
    axis = 0 if channel == "x" else 1
    north, up = earth_rate_north_up(latitude, earth_rate)
    earth = np.array([0.0, north, up])  # ENU
    attitude = initial_attitude(azimuth, pitch, roll)

    def gimbal_angle(c: np.ndarray) -> float:
        return math.atan2(c[2, 1], c[2, 2]) if axis == 0 else -math.asin(c[2, 0])

    def derivative(t, y, switch, current):
        c = y[:9].reshape(3, 3)
        earth_platform = c.T @ earth
        inertial = earth_platform.copy()  # correction loops hold the other axes to the base
        inertial[axis] = own_drift + pulse_rate * current(t)
        relative = inertial - earth_platform
        return np.concatenate([(c @ skew(relative)).ravel(), [switch * gimbal_angle(c)]])

    state = np.concatenate([attitude.ravel(), [0.0]])
    for phase, (switch, sign) in enumerate(((1.0, 1.0), (-1.0, -1.0))):
        start = phase * tau
        for j, (a, b) in enumerate(zip(shape.knots[:-1], shape.knots[1:])):
            # the segment's own linear law, so a jump at a knot is never straddled or sampled
            def current(t, j=j, a=a, sign=sign, start=start):
                return sign * (shape.start_values[j] + shape.slopes[j] * ((t - start) / tau - a))

            solution = solve_ivp(derivative, (start + a * tau, start + b * tau), state, method="DOP853",
                                 rtol=1e-12, atol=1e-15, args=(switch, current))
            if not solution.success:
                raise SimulationError(f"plant integration failed: {solution.message}")
            state = solution.y[:, -1]
    return float(k1 * state[-1])
