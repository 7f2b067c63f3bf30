"""The linearised 3-D INS error model on a rotating spherical Earth, in psi-angle form.

Beyond Bollay (1966), whose single channel is this model's non-rotating limit.
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

On WGS-84 (:func:`wgs84_psi_angle_model`) the same equations hold with the
ellipsoid's radii of curvature in the transport rate, normal gravity with its
gradient in delta_g (north and east channels see g / (R_N + h) and g / (R_E + h);
the vertical -dg/dh ~ 2 g / a), and any specific force f: along a trajectory
the coefficients change, and :func:`propagate_along` freezes them over each
step (their means over the step) and propagates exactly within it.

Examples
--------
>>> import numpy as np
>>> model = psi_angle_model(np.radians(45.0), 6.371e6, 9.80665, 7.292115e-5)
>>> model.n_states
7
"""

from __future__ import annotations

import numpy as np

from schuler.core.attitude import skew
from schuler.core.earth import (
    EARTH_RATE,
    NORTH_GRAVITY_PER_HEIGHT,
    WGS84_ECCENTRICITY_SQUARED,
    WGS84_FLATTENING,
    WGS84_GAMMA_EQUATOR,
    WGS84_SEMI_MAJOR_AXIS,
    WGS84_SOMIGLIANA_K,
    earth_rate_ned,
    gravity_height_coefficient,
    gravity_ned,
    normal_gravity,
    radii_of_curvature,
    transport_rate_ned,
)
from schuler.core.lti import StateSpace, zoh_discretize
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


def wgs84_gravity_gradient(latitude, height) -> np.ndarray:
    """d delta_g / d delta_r on WGS-84: the error of computed gravity per metre of position error, 1/s^2.

    With delta_r = ((R_N + h) dL, (R_E + h) cos L dlambda, -dh) and gravity
    g^n(L, h) = (g_N, 0, g_D) (Groves 2013, eqs. (2.134), (2.139), (2.140)), the
    computed gravity resolved in the computed frame differs from the true one by

        delta_g = dg^n/dL dL + dg^n/dh dh + delta_theta x g^n,
        delta_theta = (dlambda cos L, -dL, -dlambda sin L)

    (delta_theta: the computed frame's turn from the true one). On a sphere this
    is -(g/R) diag(1, 1, -2).

    Parameters
    ----------
    latitude, height : array_like, shape (K,)
        rad, m.

    Returns
    -------
    ndarray, shape (K, 3, 3)

    Examples
    --------
    >>> G = wgs84_gravity_gradient(np.radians([45.0]), [0.0])[0]
    >>> round(float(G[0, 0]) * 6.3674e6 / 9.8062, 3), round(float(G[2, 2]) * 6.3781e6 / 9.8062 / 2, 3)
    (-1.0, 1.003)
    """
    L = np.atleast_1d(np.asarray(latitude, dtype=float))
    h = np.broadcast_to(np.asarray(height, dtype=float), L.shape)
    R_N, R_E = radii_of_curvature(L)
    s, c = np.sin(L), np.cos(L)
    g_N, _, g_D = np.moveaxis(gravity_ned(L, h), -1, 0)
    a = WGS84_SEMI_MAJOR_AXIS
    w = 1.0 - WGS84_ECCENTRICITY_SQUARED * s**2
    g0 = normal_gravity(L)
    dg0 = WGS84_GAMMA_EQUATOR * s * c * (2.0 * WGS84_SOMIGLIANA_K / np.sqrt(w)
                                         + (1.0 + WGS84_SOMIGLIANA_K * s**2) * WGS84_ECCENTRICITY_SQUARED / w**1.5)
    k1 = gravity_height_coefficient(L)
    height_factor = 1.0 - k1 * h + 3.0 * h**2 / a**2
    dgD_dL = dg0 * height_factor + g0 * h * (8.0 * WGS84_FLATTENING / a) * s * c
    dgD_dh = g0 * (-k1 + 6.0 * h / a**2)
    dgN_dL = 2.0 * NORTH_GRAVITY_PER_HEIGHT * h * np.cos(2.0 * L)
    dgN_dh = NORTH_GRAVITY_PER_HEIGHT * np.sin(2.0 * L)
    G = np.zeros((L.size, 3, 3))
    G[:, 0, 0] = (dgN_dL - g_D) / (R_N + h)
    G[:, 0, 2] = -dgN_dh
    G[:, 1, 1] = -(g_D + g_N * np.tan(L)) / (R_E + h)
    G[:, 2, 0] = (dgD_dL + g_N) / (R_N + h)
    G[:, 2, 2] = -dgD_dh
    return G


def wgs84_error_matrices(latitude, height, velocity_ned, specific_force_ned, rate: float = EARTH_RATE,
                         vertical_channel: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Psi-angle error matrices on WGS-84 at K points of a trajectory: F (K, n, n), G (K, n, 6).

    The module's equations with the WGS-84 Earth rate, transport rate
    (Groves 2013, eqs. (2.123), (5.44)), gravity gradient
    (:func:`wgs84_gravity_gradient`) and the given specific force:

        delta_r' = -rho x delta_r + delta_v
        delta_v' = -(2 Omega + rho) x delta_v + f x psi + delta_g(delta_r) + nabla
        psi'     = -(Omega + rho) x psi + epsilon

    Parameters
    ----------
    latitude, height : array_like, shape (K,)
        rad (|L| < 90 deg), m.
    velocity_ned : array_like, shape (K, 3)
        Ground velocity, m/s.
    specific_force_ned : array_like, shape (K, 3)
        f in NED, m/s^2 (at rest about (0, 0, -g)).
    rate : float
        Omega, rad/s.
    vertical_channel : bool
        Keep delta_r_D, delta_v_D (pure inertial). Without it the height is held
        (delta_r_D = 0, as by an ideal altimeter), which in psi-angle variables
        leaves delta_v_D = rho_N delta_r_E - rho_E delta_r_N (zero at rest).

    Returns
    -------
    F : ndarray, shape (K, n, n)
    G : ndarray, shape (K, n, 6)
        States and inputs as :func:`psi_angle_model` (n = 9 or 7).
    """
    L = np.atleast_1d(np.asarray(latitude, dtype=float))
    if not np.all(np.isfinite(L)) or np.any(np.abs(L) >= np.pi / 2):
        raise InvalidParameter("latitude", "must be finite and strictly between -90 and 90 deg")
    h = np.broadcast_to(np.asarray(height, dtype=float), L.shape)
    v = np.broadcast_to(np.asarray(velocity_ned, dtype=float), (L.size, 3))
    f = np.broadcast_to(np.asarray(specific_force_ned, dtype=float), (L.size, 3))
    for name, array in (("height", h), ("velocity_ned", v), ("specific_force_ned", f)):
        if not np.all(np.isfinite(array)):
            raise InvalidParameter(name, "contains NaN or infinite values")
    omega = earth_rate_ned(L, rate)
    rho = transport_rate_ned(L, h, v[:, 0], v[:, 1])
    F = np.zeros((L.size, 9, 9))
    F[:, 0:3, 0:3] = -skew(rho)
    F[:, 0:3, 3:6] = np.eye(3)
    F[:, 3:6, 0:3] = wgs84_gravity_gradient(L, h)
    F[:, 3:6, 3:6] = -skew(2.0 * omega + rho)
    F[:, 3:6, 6:9] = skew(f)
    F[:, 6:9, 6:9] = -skew(omega + rho)
    G = np.zeros((L.size, 9, 6))
    G[:, 3:6, 0:3] = np.eye(3)
    G[:, 6:9, 3:6] = np.eye(3)
    if vertical_channel:
        return F, G
    # Height held (delta_r_D = 0): delta_r_D' = 0 makes the psi-frame vertical velocity error
    # delta_v_D = rho_N delta_r_E - rho_E delta_r_N (the true velocity resolved in the computed
    # frame), not zero; substitute it where delta_v_D acts.
    F[:, :, 1] += F[:, :, 5] * rho[:, None, 0]
    F[:, :, 0] -= F[:, :, 5] * rho[:, None, 1]
    keep = [0, 1, 3, 4, 6, 7, 8]
    return F[:, keep][:, :, keep], G[:, keep]


def wgs84_psi_angle_model(latitude: float, height: float = 0.0, velocity_ned=(0.0, 0.0, 0.0), specific_force_ned=None,
                          rate: float = EARTH_RATE, vertical_channel: bool = False) -> StateSpace:
    """The psi-angle error model on WGS-84 at one point (:func:`wgs84_error_matrices`).

    Parameters
    ----------
    latitude : float
        rad.
    height : float
        m.
    velocity_ned : array_like, shape (3,)
        m/s.
    specific_force_ned : array_like, shape (3,), optional
        m/s^2; default: the specific force of steady flight at the velocity,
        -g^n + (2 Omega + rho) x v.
    rate : float
        rad/s.
    vertical_channel : bool

    Returns
    -------
    StateSpace
        States and inputs as :func:`psi_angle_model`.

    Examples
    --------
    The Schuler modes at 45 deg, split by the Foucault rate Omega sin L:

    >>> m = wgs84_psi_angle_model(np.radians(45.0))
    >>> periods = 2 * np.pi / np.unique(np.abs(m.eigenvalues().imag).round(12))[-2:] / 60
    >>> [round(float(p), 1) for p in periods]
    [88.0, 81.0]
    """
    v = np.asarray(velocity_ned, dtype=float)
    if specific_force_ned is None:
        rho = transport_rate_ned(latitude, height, v[0], v[1])
        specific_force_ned = -gravity_ned(latitude, height) + np.cross(2.0 * earth_rate_ned(latitude, rate) + rho, v)
    F, G = wgs84_error_matrices([latitude], [height], v[None], np.asarray(specific_force_ned)[None], rate,
                                vertical_channel)
    axes = _AXES if vertical_channel else _AXES[:2]
    return StateSpace(
        F[0], G[0],
        states=tuple(f"position_error_{a}" for a in axes) + tuple(f"velocity_error_{a}" for a in axes)
        + tuple(f"psi_{a}" for a in _AXES),
        inputs=tuple(f"accelerometer_error_{a}" for a in _AXES) + tuple(f"drift_{a}" for a in _AXES),
        state_units=("m",) * len(axes) + ("m/s",) * len(axes) + ("rad",) * 3,
    )


def propagate_along(time, latitude, height, velocity_ned, specific_force_ned, initial_state, inputs=None,
                    rate: float = EARTH_RATE, vertical_channel: bool = False) -> np.ndarray:
    """Propagate the WGS-84 psi-angle model along a trajectory, coefficients frozen over each step.

    On each step [t_k, t_k+1] the coefficients (and inputs) are the values given
    for that step (best: their means over it); within the step the model is
    propagated exactly by the engine's zero-order-hold discretisation
    (:func:`schuler.core.lti.zoh_discretize`). The error against the exact
    time-varying solution is of third order in the step per step (the mean
    coefficient is the first Magnus term).

    Parameters
    ----------
    time : array_like, shape (K + 1,)
        Strictly increasing times, s.
    latitude, height : array_like, shape (K,)
        Per step, rad and m.
    velocity_ned, specific_force_ned : array_like, shape (K, 3)
        Per step, m/s and m/s^2.
    initial_state : array_like, shape (n,) or (N, n)
        States as :func:`psi_angle_model` at ``time[0]``, SI.
    inputs : array_like, shape (6,), (K, 6) or (N, K, 6), optional
        nabla (m/s^2) and epsilon (rad/s) in NED, per step.
    rate : float
        rad/s.
    vertical_channel : bool

    Returns
    -------
    ndarray, shape (K + 1, n) or (N, K + 1, n)

    Examples
    --------
    >>> t = np.linspace(0.0, 600.0, 11)
    >>> x = propagate_along(t, np.full(10, 0.7), np.zeros(10), np.zeros((10, 3)), [[0, 0, -9.8]] * 10,
    ...                     [0, 0, 0.1, 0, 0, 0, 0])
    >>> x.shape
    (11, 7)
    """
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)):
        raise InvalidParameter("time", "must be a strictly increasing 1-D array of at least two finite times")
    F, G = wgs84_error_matrices(latitude, height, velocity_ned, specific_force_ned, rate, vertical_channel)
    K, n = F.shape[0], F.shape[-1]
    if K != t.size - 1:
        raise InvalidParameter("latitude", f"needs one value per step ({t.size - 1}), got {K}")
    dt = np.diff(t)[:, None, None]
    Ad, Bd = zoh_discretize(F * dt, G * dt, 1.0)
    x0 = np.asarray(initial_state, dtype=float)
    if x0.shape[-1] != n or x0.ndim > 2:
        raise InvalidParameter("initial_state", f"expected shape ({n},) or (N, {n}), got {x0.shape}")
    u = np.zeros(6) if inputs is None else np.asarray(inputs, dtype=float)
    if u.shape[-1] != 6 or not np.all(np.isfinite(u)):
        raise InvalidParameter("inputs",
                               f"expected finite values of shape (6,), ({K}, 6) or (N, {K}, 6), got {u.shape}")
    u = np.broadcast_to(u, (*x0.shape[:-1], K, 6)) if u.ndim < 3 else u
    out = np.empty((*x0.shape[:-1], K + 1, n))
    x = x0.copy()
    out[..., 0, :] = x
    for k in range(K):
        x = x @ Ad[k].T + u[..., k, :] @ Bd[k].T
        out[..., k + 1, :] = x
    return out
