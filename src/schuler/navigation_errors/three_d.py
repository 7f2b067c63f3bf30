"""The linearised 3-D INS error model on a rotating spherical Earth, in psi-angle form.

Beyond source 002, whose single channel is this model's non-rotating limit.
Frame: local-level North-East-Down (n frame) of the computed position; Earth
rate Omega_n = Omega (cos L, 0, -sin L), transport rate
rho = (V_E / R, -V_N / R, -V_E tan L / R) for a vehicle flying at constant
north and east speeds (V_N, V_E) at latitude L. The psi-angle form (Benson 1975)
writes the errors in the computer frame:

    delta_r' = -rho x delta_r + delta_v
    delta_v' = -(2 Omega_n + rho) x delta_v + f x psi + delta_g + nabla
    psi'     = -(Omega_n + rho) x psi + epsilon

with delta_r the position error (m; delta_r_N = R delta_L,
delta_r_E = R cos L delta_lambda), delta_v the velocity error (m/s), psi the
platform attitude error (rad, rotation of the platform from the computer frame),
nabla the accelerometer errors (m/s^2), epsilon the gyro drift rates (rad/s),
f = -g e_D + (2 Omega_n + rho) x v the specific force holding the path, and
delta_g = -omega_s^2 (delta_r_N, delta_r_E, -2 delta_r_D) the error of computed
gravity (omega_s^2 = g / R). With these signs a positive psi_E (or a drift
epsilon_E) makes a positive north error, as Bollay's Delta_theta_y makes a
positive Delta_S_x.

The coefficients are constant for a stationary vehicle and for flight along a
parallel (V_N = 0); with V_N != 0 the latitude changes and the model holds with
coefficients frozen at L (valid for times short against the time the latitude
takes to change appreciably).

Modes of the stationary vehicle (horizontal channels; the psi equation is
autonomous, so the model is block-triangular): the Earth-rate mode 0, +/- i Omega
(the 24-hour mode) and the Schuler modes split by Foucault's rotation,
+/- i (sqrt(omega_s^2 + Omega_z^2) +/- Omega_z), Omega_z = Omega sin L.

Examples
--------
>>> import numpy as np
>>> model = psi_angle_model(np.radians(45.0), 6.371e6, 9.80665, 7.292115e-5)
>>> model.n_states
7
"""

from __future__ import annotations

import numpy as np

from schuler.core.lti import StateSpace
from schuler.core.rotation import skew
from schuler.exceptions import InvalidParameter

_AXES = ("north", "east", "down")


def psi_angle_model(
    latitude: float,
    radius: float,
    gravity: float,
    rate: float,
    velocity_north: float = 0.0,
    velocity_east: float = 0.0,
    vertical_channel: bool = False,
) -> StateSpace:
    """State-space psi-angle error model (equations in the module docstring).

    Parameters
    ----------
    latitude : float
        L, rad, |L| < pi/2 (the transport rate has tan L).
    radius : float
        R, m (> 0).
    gravity : float
        g, m/s^2 (> 0); omega_s^2 = g / R.
    rate : float
        Earth rate Omega, rad/s (>= 0; 0 for the non-rotating Earth).
    velocity_north, velocity_east : float
        Vehicle's constant ground speed components V_N, V_E, m/s.
    vertical_channel : bool
        Include delta_r_D, delta_v_D (pure inertial: unstable, eigenvalues near
        +/- sqrt(2) omega_s). Without it (default) the vertical errors are held
        at zero, as by an altimeter, and the horizontal modes are exact.

    Returns
    -------
    StateSpace
        States ``position_error_{north,east[,down]}`` (m),
        ``velocity_error_{north,east[,down]}`` (m/s), ``psi_{north,east,down}``
        (rad); inputs ``accelerometer_error_{north,east,down}`` (m/s^2) and
        ``drift_{north,east,down}`` (rad/s).

    Examples
    --------
    >>> import numpy as np
    >>> m = psi_angle_model(0.5, 6.371e6, 9.80665, 0.0)
    >>> bool(np.allclose(m.eigenvalues().real, 0.0))
    True
    """
    L = float(latitude)
    if not np.isfinite(L) or abs(L) >= np.pi / 2:
        raise InvalidParameter("latitude", f"must lie strictly between -90 and 90 deg, got {np.degrees(L):g} deg")
    R, g = float(radius), float(gravity)
    if not (np.isfinite(R) and R > 0):
        raise InvalidParameter("radius", f"must be finite and > 0, got {radius!r}")
    if not (np.isfinite(g) and g > 0):
        raise InvalidParameter("gravity", f"must be finite and > 0, got {gravity!r}")
    if not (np.isfinite(rate) and rate >= 0):
        raise InvalidParameter("rate", f"must be finite and >= 0, got {rate!r}")
    for name, value in (("velocity_north", velocity_north), ("velocity_east", velocity_east)):
        if not np.isfinite(value):
            raise InvalidParameter(name, "must be finite")
    earth_rate = rate * np.array([np.cos(L), 0.0, -np.sin(L)])
    transport = np.array([velocity_east / R, -velocity_north / R, -velocity_east * np.tan(L) / R])
    velocity = np.array([velocity_north, velocity_east, 0.0])
    specific_force = np.array([0.0, 0.0, -g]) + np.cross(2.0 * earth_rate + transport, velocity)
    omega_squared = g / R

    F = np.zeros((9, 9))
    F[0:3, 0:3] = -skew(transport)
    F[0:3, 3:6] = np.eye(3)
    F[3:6, 0:3] = -omega_squared * np.diag([1.0, 1.0, -2.0])
    F[3:6, 3:6] = -skew(2.0 * earth_rate + transport)
    F[3:6, 6:9] = skew(specific_force)
    F[6:9, 6:9] = -skew(earth_rate + transport)
    G = np.zeros((9, 6))
    G[3:6, 0:3] = np.eye(3)
    G[6:9, 3:6] = np.eye(3)

    keep = list(range(9)) if vertical_channel else [0, 1, 3, 4, 6, 7, 8]
    axes = _AXES if vertical_channel else _AXES[:2]
    states = (
        tuple(f"position_error_{a}" for a in axes)
        + tuple(f"velocity_error_{a}" for a in axes)
        + tuple(f"psi_{a}" for a in _AXES)
    )
    units = ("m",) * len(axes) + ("m/s",) * len(axes) + ("rad",) * 3
    return StateSpace(
        F[np.ix_(keep, keep)],
        G[keep],
        states=states,
        inputs=tuple(f"accelerometer_error_{a}" for a in _AXES) + tuple(f"drift_{a}" for a in _AXES),
        state_units=units,
    )


def stationary_modes(latitude: float, radius: float, gravity: float, rate: float) -> np.ndarray:
    """Exact eigenvalues of the stationary horizontal psi-angle model, rad/s.

    0, +/- i Omega (Earth-rate mode) and +/- i (sqrt(omega_s^2 + Omega_z^2) +/- Omega_z)
    (Schuler modes split by the Foucault rate Omega_z = Omega sin L).

    Parameters
    ----------
    latitude : float
        L, rad.
    radius, gravity, rate : float
        R (m), g (m/s^2), Omega (rad/s).

    Returns
    -------
    ndarray of complex, shape (7,)

    >>> modes = stationary_modes(0.0, 6.371e6, 9.80665, 7.292115e-5)
    >>> round(float(modes.imag.max()) * 1e3, 6)
    1.240671
    """
    omega_z = rate * np.sin(latitude)
    split = np.sqrt(gravity / radius + omega_z**2)
    magnitudes = [0.0, rate, rate, split + omega_z, split + omega_z, split - omega_z, split - omega_z]
    signs = [1, 1, -1, 1, -1, 1, -1]
    return 1j * np.array(signs) * np.array(magnitudes)


def foucault_velocity_response(time, velocity_error_north: float, latitude: float, radius: float, gravity: float,
                               rate: float):
    """Position error of a stationary INS after an initial north velocity error, m.

    In complex form z = delta_r_N + i delta_r_E the horizontal psi-angle
    equations read z'' - 2 i Omega_z z' + omega_s^2 z = 0, so from z(0) = 0,
    z'(0) = delta_V:

        z = (delta_V / W) sin(W t) exp(i Omega_z t),  W = sqrt(omega_s^2 + Omega_z^2):

    the Schuler oscillation whose plane turns at the Foucault rate Omega_z
    (clockwise seen from above in the northern hemisphere).

    Parameters
    ----------
    time : array_like
        t, s.
    velocity_error_north : float
        delta_V, m/s.
    latitude, radius, gravity, rate : float
        L (rad), R (m), g (m/s^2), Omega (rad/s).

    Returns
    -------
    north, east : ndarray
        delta_r_N and delta_r_E, m.

    >>> n, e = foucault_velocity_response([0.0], 1.0, 0.8, 6.371e6, 9.80665, 7.292115e-5)
    >>> float(n[0]), float(e[0])
    (0.0, 0.0)
    """
    t = np.asarray(time, dtype=float)
    omega_z = rate * np.sin(latitude)
    split = np.sqrt(gravity / radius + omega_z**2)
    z = velocity_error_north / split * np.sin(split * t) * np.exp(1j * omega_z * t)
    return z.real, z.imag
