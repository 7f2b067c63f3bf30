"""Accuracy limits of self-alignment at rest: what sensor errors leave, whatever the method.

Conventions: NED, body x forward / y right / z down, level body at heading psi
(C_b^n = R_z(psi)); sensor biases are measured - true in body axes, errors are
computed - true. East components of a body vector b: b_E = sin(psi) b_x + cos(psi) b_y.

Static limits (first order; spec 06 "Alignment at rest"; Groves 2013, sec. 14.2;
Titterton and Weston 2004, sec. 10.3):

    roll error    = -b_ay / g
    pitch error   =  b_ax / g
    heading error = -b_gE / (Omega cos L) + b_aE tan(L) / g

A gyro bias is indistinguishable from the Earth rate at rest and an
accelerometer bias from a tilt: no method at rest removes these terms.

Random-walk limit: white gyro noise of density N (angle random walk, rad/sqrt(s))
averaged over T seconds leaves the east rate uncertain by N / sqrt(T), so

    sigma_psi = k N_E / (Omega cos L sqrt(T))

with k = 1 for the mean-rate (coarse) estimate and asymptotically for the
Kalman filter, and k = 2 / sqrt(3) for the two-vector inertial-frame method
(:data:`RANDOM_WALK_FACTOR`, derived in :func:`random_walk_factor`). A loop
with a fixed bandwidth (the gyrocompass) does not average indefinitely: its
stationary noise follows from its transfer function
(:func:`gyrocompass_noise`).

Correspondence with schuler align: the strapdown gyrocompass loop's error equations
are the KPI manual's full model (1.18) under the mapping drift = epsilon = -C b_g
(``drift_east = -b_gE``, ``drift_north = -b_gN``, ``drift_up = b_gD``),
eps_beta = -b_aN / g, eps_alpha = b_aE / g, and heading error = delta (see
:func:`kpi_equivalent_inputs`); the dominant terms of (1.21),
delta_y = drift_east / (U cos phi) + c_Gamma drift_up / (c_a U cos phi), are the
heading limit's gyro term and the loop's own small term.

Examples
--------
>>> import math
>>> deg_h = math.radians(1.0) / 3600
>>> _, _, heading = static_errors(math.radians(45.0), 0.0, [0.0, 0.01 * deg_h, 0.0], [0.0, 0.0, 0.0])
>>> round(float(math.degrees(heading) * 60), 2)   # 0.01 deg/h east at 45 deg N: -0.01 / (15.04 cos 45) rad
-3.23
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.exceptions import InvalidParameter, NotObservable

METHODS = ("coarse", "inertial_frame", "kalman", "gyrocompass")
"""The self-alignment methods, in the order they are reported."""

RANDOM_WALK_FACTOR = {"coarse": 1.0, "inertial_frame": 2.0 / math.sqrt(3.0), "kalman": 1.0}
"""k of sigma_psi = k N_E / (Omega cos L sqrt(T)) for the methods that average over the whole window."""

MAX_LATITUDE = math.radians(89.0)
"""Beyond this latitude the horizontal Earth rate is too small to find north from."""


def horizontal_rate(latitude) -> np.ndarray:
    """Omega cos L, rad/s; refuses latitudes beyond :data:`MAX_LATITUDE` (azimuth unobservable).

    Parameters
    ----------
    latitude : float or array_like
        Latitude L, rad (any shape).

    Returns
    -------
    ndarray
        Horizontal Earth rate, rad/s, same shape.

    Raises
    ------
    NotObservable
        A latitude not finite or beyond +/- :data:`MAX_LATITUDE`.
    """
    latitude = np.asarray(latitude, dtype=float)
    if np.any(~np.isfinite(latitude)) or np.any(np.abs(latitude) > MAX_LATITUDE):
        raise NotObservable(f"latitude: {np.degrees(np.max(np.abs(latitude))):g} deg is beyond +/-"
                            f"{math.degrees(MAX_LATITUDE):g} deg: the horizontal Earth rate is too small for heading")
    return EARTH_RATE * np.cos(latitude)


def east_component(heading, body_vector) -> np.ndarray:
    """b_E = sin(psi) b_x + cos(psi) b_y of body vectors (..., 3) of a level body at heading psi.

    Parameters
    ----------
    heading : float or array_like
        Heading psi of the level body, rad (broadcast against the leading dimensions).
    body_vector : array_like of shape (..., 3)
        Vector in body axes x fwd, y right, z down, any unit (e.g. a gyro bias in rad/s).

    Returns
    -------
    ndarray of shape (...)
        Its east component, in the vector's unit.
    """
    b = np.asarray(body_vector, dtype=float)
    heading = np.asarray(heading, dtype=float)
    return np.sin(heading) * b[..., 0] + np.cos(heading) * b[..., 1]



def static_errors(latitude, heading, gyro_bias, accel_bias, gravity=STANDARD_GRAVITY):
    """First-order roll, pitch and heading errors (computed - true, rad) from constant biases.

    Parameters
    ----------
    latitude : float or ndarray
        L, rad.
    heading : float or ndarray
        True heading psi of the level body, rad.
    gyro_bias : array_like (..., 3)
        b_g, measured - true, body axes, rad/s.
    accel_bias : array_like (..., 3)
        b_a, measured - true, body axes, m/s^2.
    gravity : float
        g, m/s^2.

    Returns
    -------
    roll, pitch, heading : ndarray
        -b_ay / g, b_ax / g, -b_gE / (Omega cos L) + b_aE tan(L) / g (see the module notes).
    """
    rate = horizontal_rate(latitude)
    gyro_bias = np.asarray(gyro_bias, dtype=float)
    accel_bias = np.asarray(accel_bias, dtype=float)
    heading_error = (-east_component(heading, gyro_bias) / rate
                     + east_component(heading, accel_bias) * np.tan(latitude) / gravity)
    return -accel_bias[..., 1] / gravity, accel_bias[..., 0] / gravity, heading_error


def heading_random_walk(latitude, gyro_random_walk_east, duration) -> np.ndarray:
    """The random-walk limit sigma_psi = N_E / (Omega cos L sqrt(T)), rad.

    Parameters
    ----------
    latitude : float or ndarray
        L, rad.
    gyro_random_walk_east : float or ndarray
        Angle random walk N of the east-pointing gyro channel, rad/sqrt(s).
    duration : float or ndarray
        Alignment time T, s (> 0).

    Examples
    --------
    >>> import math
    >>> n = math.radians(0.002) / 60    # 0.002 deg/sqrt(h) (navigation grade)
    >>> round(float(math.degrees(heading_random_walk(math.radians(34.2), n, 300.0)) * 60), 3)   # arcmin
    1.915
    """
    duration = np.asarray(duration, dtype=float)
    if np.any(~(duration > 0)):
        raise InvalidParameter("duration", "must be > 0 s")
    return np.asarray(gyro_random_walk_east, dtype=float) / (horizontal_rate(latitude) * np.sqrt(duration))


def random_walk_factor(method: str) -> float:
    """k of the random-walk limit for ``method`` (coarse, inertial_frame, kalman).

    Parameters
    ----------
    method : {"coarse", "inertial_frame", "kalman"}
        The alignment method.

    Returns
    -------
    float
        k, plain number.

    Raises
    ------
    InvalidParameter
        A method without a random-walk factor (the gyrocompass: :func:`gyrocompass_noise`).

    Notes
    -----
    Coarse alignment takes the mean rate over T: sigma = N / sqrt(T), k = 1.
    The inertial-frame method (TRIAD on the integrated specific force at T/2 and
    T) sees the north tilt through X = int_0^T phi - 2 int_0^{T/2} phi of the
    gyro-propagated attitude error phi = N W (W a Wiener process); X = N int k dW
    with k(s) = s on [0, T/2] and T - s on [T/2, T], so var X = N^2 T^3 / 12, and
    the heading follows from X / (Omega cos L T^2 / 4): k = 4 / sqrt(12) = 2 / sqrt(3).
    A Kalman filter with the true noise model reaches the mean-rate limit, k = 1.
    """
    if method not in RANDOM_WALK_FACTOR:
        raise InvalidParameter("method", f"{method!r} has no random-walk factor; choose from "
                               f"{', '.join(RANDOM_WALK_FACTOR)}")
    return RANDOM_WALK_FACTOR[method]


def gyrocompass_error_model(latitude, c_gamma, c_a, gravity=STANDARD_GRAVITY):
    """The gyrocompass loop's linear error model phi' = A phi + B u, NED tilt/heading errors phi (rad).

    Parameters
    ----------
    latitude : float
        L, rad.
    c_gamma, c_a : float
        Level and azimuth gains, 1/s.
    gravity : float
        g, m/s^2.

    Returns
    -------
    A : ndarray (3, 3)
        1/s.
    B : ndarray (3, 6)
        Inputs u = (b_gN, b_gE, b_gD, b_aN, b_aE, b_aD): gyro rates (rad/s) and specific
        forces (m/s^2) resolved in NED, measured - true (white noise or biases alike).

    Notes
    -----
    From phi' = -omega_ie x phi - C b_g + u_c (the psi-angle equation, spec 06) with the
    loop's commanded rate u_c = (c_gamma f_E / g, -c_gamma f_N / g, -c_a f_N / g) and the
    sensed level specific force f_N = g phi_y + b_aN, f_E = -g phi_x + b_aE:

        phi_x' = -c_gamma (phi_x - b_aE / g) - Omega sin L phi_y - b_gN
        phi_y' = -c_gamma (phi_y + b_aN / g) + Omega sin L phi_x + Omega cos L phi_z - b_gE
        phi_z' = -c_a (phi_y + b_aN / g) - Omega cos L phi_y - b_gD

    For a level body at heading psi, C^_b^n = (I - [phi x]) C_b^n = C_b^n (I - [C^T phi x]):
    roll error = -(cos psi phi_x + sin psi phi_y), pitch error = sin psi phi_x - cos psi phi_y,
    heading error = -phi_z.
    """
    rate = float(horizontal_rate(latitude))
    vertical = EARTH_RATE * math.sin(latitude)
    A = np.array([[-c_gamma, -vertical, 0.0],
                  [vertical, -c_gamma, rate],
                  [0.0, -(c_a + rate), 0.0]])
    B = np.zeros((3, 6))
    B[0, 0], B[0, 4] = -1.0, c_gamma / gravity
    B[1, 1], B[1, 3] = -1.0, -c_gamma / gravity
    B[2, 2], B[2, 3] = -1.0, -c_a / gravity
    return A, B


def gyrocompass_noise(latitude, c_gamma, c_a, gyro_random_walk, accel_random_walk, gravity=STANDARD_GRAVITY):
    """Stationary 1-sigma of the gyrocompass loop's north tilt, east tilt and heading from white noise, rad.

    Parameters
    ----------
    latitude : float
        L, rad.
    c_gamma, c_a : float
        Level and azimuth gains, 1/s.
    gyro_random_walk : array_like (3,)
        N of the gyros resolved north, east, down, rad/sqrt(s).
    accel_random_walk : array_like (3,)
        N of the accelerometers resolved north, east, down, m/s/sqrt(s).
    gravity : float
        g, m/s^2.

    Notes
    -----
    The stationary covariance P of :func:`gyrocompass_error_model` driven by white
    inputs of intensities Q = diag(N^2) solves A P + P A^T + B Q B^T = 0 (Lyapunov).
    Its heading part is, to leading order, through
    phi_z D(s) = (Omega cos L + c_a) n_E - (s + c_gamma) n_D + (Omega cos L c_gamma - c_a s) a_N
    (D = s^2 + c_gamma s + omega0^2, omega0^2 = Omega cos L (c_a + Omega cos L)):
    sigma^2 = N_E^2 (c_a + Omega cos L)^2 / (2 omega0^2 c_gamma) + ..., i.e. the loop
    averages the east gyro noise over about 2 c_gamma / omega0^2 = 4 zeta T seconds.
    """
    from scipy.linalg import solve_continuous_lyapunov

    A, B = gyrocompass_error_model(latitude, c_gamma, c_a, gravity)
    intensity = np.diag(np.concatenate([np.asarray(gyro_random_walk, dtype=float) ** 2,
                                        np.asarray(accel_random_walk, dtype=float) ** 2]))
    P = solve_continuous_lyapunov(A, -B @ intensity @ B.T)
    return tuple(float(math.sqrt(max(P[i, i], 0.0))) for i in range(3))


def gyrocompass_steady_state(latitude, c_gamma, c_a, gyro_bias_ned, accel_bias_ned, gravity=STANDARD_GRAVITY):
    """The loop's steady NED errors phi = -A^-1 B u for constant biases; heading error = -phi_z (rad).

    To first order the heading error is -b_gE / (Omega cos L) + c_gamma b_gD / (c_a Omega cos L)
    + tan(L) (b_aE / g - b_gN / c_gamma): the static limit plus the loop's own terms, the
    KPI manual's (1.21) and the alpha U_z coupling of its full model (1.18).

    Parameters
    ----------
    latitude : float
        Latitude L, rad.
    c_gamma, c_a : float
        Level and azimuth gains, 1/s.
    gyro_bias_ned : array_like (3,)
        C_b^n b_g, gyro bias (measured - true) resolved north, east, down, rad/s.
    accel_bias_ned : array_like (3,)
        C_b^n b_a, accelerometer bias (measured - true) resolved north, east, down, m/s^2.
    gravity : float
        g, m/s^2.

    Returns
    -------
    ndarray (3,)
        Steady phi = (phi_N, phi_E, phi_D), rad (heading error = -phi_D).
    """
    A, B = gyrocompass_error_model(latitude, c_gamma, c_a, gravity)
    u = np.concatenate([np.asarray(gyro_bias_ned, dtype=float), np.asarray(accel_bias_ned, dtype=float)])
    return -np.linalg.solve(A, B @ u)


def kpi_equivalent_inputs(gyro_bias_ned, accel_bias_ned, gravity=STANDARD_GRAVITY) -> dict[str, float]:
    """schuler align's inputs (KPI manual (1.18)) that give the strapdown gyrocompass loop's equations exactly.

    Parameters
    ----------
    gyro_bias_ned, accel_bias_ned : array_like (3,)
        C_b^n b_g (rad/s) and C_b^n b_a (m/s^2), measured - true.
    gravity : float
        g, m/s^2.

    Returns
    -------
    dict
        ``drift_east`` = -b_gE, ``drift_north`` = -b_gN, ``drift_up`` = b_gD (the platform drift
        epsilon = -C b_g, up component -epsilon_D), ``eps_beta`` = -b_aN / g, ``eps_alpha`` = b_aE / g;
        then delta = heading error, beta = -phi_E, alpha = -phi_N (module notes).
    """
    b_g = np.asarray(gyro_bias_ned, dtype=float)
    b_a = np.asarray(accel_bias_ned, dtype=float)
    return {"drift_east": float(-b_g[1]), "drift_north": float(-b_g[0]), "drift_up": float(b_g[2]),
            "eps_beta": float(-b_a[0] / gravity), "eps_alpha": float(b_a[1] / gravity)}


def effective_bias_sigma(errors, gravity: float = STANDARD_GRAVITY) -> tuple[np.ndarray, np.ndarray]:
    """1-sigma of the constant error each sensor shows at rest and level, body axes: (gyro rad/s, accel m/s^2).

    At rest the inputs are constant, so every constant error term acts as a bias:
    turn-on bias b, bias instability B (counted as a further constant of 1-sigma B:
    over an alignment window it moves little), misalignment and scale factor times
    the input (accelerometers: M_i3 g on x and y, S_3 g on z; gyros: up to Omega times
    the row of M and S), and the gyros' g-sensitivity G_i3 g.

    Parameters
    ----------
    errors : ErrorModel
        Per-axis 1-sigma values (:mod:`schuler.imu.error_model`).
    gravity : float
        g, m/s^2.
    """
    gyro, accel = errors.gyro, errors.accel
    gyro_var = (gyro.bias**2 + gyro.bias_instability**2 + (gyro.g_sensitivity[:, 2] * gravity) ** 2
                + EARTH_RATE**2 * ((gyro.misalignment**2).sum(axis=1) + gyro.scale_factor**2))
    accel_input = np.array([accel.misalignment[0, 2], accel.misalignment[1, 2], accel.scale_factor[2]]) * gravity
    accel_var = accel.bias**2 + accel.bias_instability**2 + accel_input**2
    return np.sqrt(gyro_var), np.sqrt(accel_var)


def kalman_level_noise(gyro_random_walk: float, accel_random_walk: float, velocity_noise: float,
                       update_interval: float, gravity: float = STANDARD_GRAVITY, sway: float = 0.0) -> float:
    """Steady 1-sigma of the tilt error left by zero-velocity updates while the gyro noise walks it, rad.

    Parameters
    ----------
    gyro_random_walk, accel_random_walk : float
        N (rad/sqrt(s)) of the gyro turning this tilt and N_a (m/s/sqrt(s)) of the accelerometer it tilts.
    velocity_noise : float
        The filter's zero-velocity measurement noise sigma_v, m/s (its design value).
    update_interval : float
        dt, s.
    gravity : float
        g, m/s^2.
    sway : float
        The actual 1-sigma velocity of the body at the updates, m/s (0 for a body truly at rest).

    Returns
    -------
    float
        The actual tilt error after an update, once the gain is steady.

    Notes
    -----
    Per level axis, dv' = g phi + w_a and phi' = w_g (intensities N_a^2, N^2), sampled every dt:
    Phi = [[1, g dt], [0, 1]], Q_d = [[N_a^2 dt + g^2 N^2 dt^3 / 3, g N^2 dt^2 / 2], [g N^2 dt^2 / 2, N^2 dt]],
    H = [1, 0]. The filter's steady gain K follows from the discrete Riccati equation with R = sigma_v^2.
    A body that does not sway gives an exact zero-velocity measurement, so the actual error covariance
    is the filter's with the true R (Joseph form; Gelb, Applied Optimal Estimation, MIT Press, 1974,
    sec. 7.1): P = Phi A P A^T Phi^T + Phi K R_true K^T Phi^T + Q_d with A = I - K H, solved as a
    Lyapunov equation. With sigma_v = 1 cm/s at a tactical grade the filter states 10-15 % more than it
    makes (tests/test_alignment_monte_carlo.py).
    """
    from scipy.linalg import solve_discrete_are, solve_discrete_lyapunov

    dt, n_g, n_a = update_interval, max(gyro_random_walk, 1e-30), max(accel_random_walk, 1e-30)
    Phi = np.array([[1.0, gravity * dt], [0.0, 1.0]])
    Q = np.array([[n_a**2 * dt + gravity**2 * n_g**2 * dt**3 / 3.0, gravity * n_g**2 * dt**2 / 2.0],
                  [gravity * n_g**2 * dt**2 / 2.0, n_g**2 * dt]])
    H = np.array([[1.0, 0.0]])
    prior = solve_discrete_are(Phi.T, H.T, Q, np.array([[velocity_noise**2]]))
    gain = prior @ H.T / (H @ prior @ H.T + velocity_noise**2)
    closed = np.eye(2) - gain @ H
    driven = Q + Phi @ gain @ gain.T @ Phi.T * sway**2
    actual_prior = solve_discrete_lyapunov(Phi @ closed, driven)
    actual = closed @ actual_prior @ closed.T + gain @ gain.T * sway**2
    return float(math.sqrt(max(actual[1, 1], 0.0)))


@dataclass(frozen=True)
class AccuracyLimit:
    """1-sigma accuracy of one method for one error model and window (rad).

    ``*_bias_rad`` is what constant biases (and bias instability counted as a
    constant) leave; ``*_noise_rad`` what white noise leaves over the window;
    ``roll_rad`` ... the root sum of squares.
    """

    method: str
    roll_bias_rad: float
    pitch_bias_rad: float
    heading_bias_rad: float
    roll_noise_rad: float
    pitch_noise_rad: float
    heading_noise_rad: float

    @property
    def roll_rad(self) -> float:
        return math.hypot(self.roll_bias_rad, self.roll_noise_rad)

    @property
    def pitch_rad(self) -> float:
        return math.hypot(self.pitch_bias_rad, self.pitch_noise_rad)

    @property
    def heading_rad(self) -> float:
        return math.hypot(self.heading_bias_rad, self.heading_noise_rad)


def _sigma_east(heading: float, sigma_xyz) -> float:
    s = np.asarray(sigma_xyz, dtype=float)
    return math.sqrt((math.sin(heading) * s[0]) ** 2 + (math.cos(heading) * s[1]) ** 2)


def _sigma_north(heading: float, sigma_xyz) -> float:
    s = np.asarray(sigma_xyz, dtype=float)
    return math.sqrt((math.cos(heading) * s[0]) ** 2 + (math.sin(heading) * s[1]) ** 2)


def accuracy_limit(method: str, errors, *, latitude: float, heading: float, duration: float,
                   gravity: float = STANDARD_GRAVITY, c_gamma: float | None = None, c_a: float | None = None,
                   velocity_noise: float = 0.01, update_interval: float = 1.0) -> AccuracyLimit:
    """The 1-sigma limit of ``method`` for sensor errors ``errors`` over a window of ``duration`` s.

    Parameters
    ----------
    method : {"coarse", "inertial_frame", "kalman", "gyrocompass"}
    errors : ErrorModel
        The sensors' errors, body axes (:mod:`schuler.imu.error_model`): their constant part
        at rest (:func:`effective_bias_sigma`) and white noise N (``random_walk``).
    latitude, heading : float
        Site latitude and (approximate) true heading of the level body, rad.
    duration : float
        Alignment window T, s.
    gravity : float
        g, m/s^2.
    c_gamma, c_a : float
        The gyrocompass loop's gains, 1/s (``method="gyrocompass"`` only).
    velocity_noise, update_interval : float
        The Kalman filter's zero-velocity noise (m/s) and update interval (s) (``method="kalman"``).

    Returns
    -------
    AccuracyLimit
        Bias part from :func:`static_errors` for independent axes, noise part from
        :func:`random_walk_factor` (or :func:`gyrocompass_noise`); the coarse level noise is
        N_a / (g sqrt(T)), the Kalman filter's its tracking noise (:func:`kalman_level_noise`); the
        inertial-frame level noise adds the gyro-propagated tilt (north N sqrt(2 T / 3), east N sqrt(T / 6))
        and takes its specific-force direction over T / 2 (sqrt(2) N_a / (g sqrt(T))), and its bias part the
        gyro drift to the window's end: (3/4) b_gN T in the north tilt, b_gD T / 2 in heading.
    """
    if method not in METHODS:
        raise InvalidParameter("method", f"{method!r} is not one of {', '.join(METHODS)}")
    if not (math.isfinite(duration) and duration > 0):
        raise InvalidParameter("duration", f"must be finite and > 0 s, got {duration!r}")
    rate = float(horizontal_rate(latitude))
    tan_l = math.tan(latitude)
    gyro_b, accel_b = effective_bias_sigma(errors, gravity)
    roll_bias, pitch_bias = accel_b[1] / gravity, accel_b[0] / gravity
    heading_bias = math.hypot(_sigma_east(heading, gyro_b) / rate, _sigma_east(heading, accel_b) * tan_l / gravity)
    n_g, n_a = errors.gyro.random_walk, errors.accel.random_walk
    if method == "gyrocompass":
        if c_gamma is None or c_a is None:
            raise InvalidParameter("c_gamma", "the gyrocompass limit needs the loop gains c_gamma and c_a")
        gyro_ned = [_sigma_north(heading, n_g), _sigma_east(heading, n_g), n_g[2]]
        accel_ned = [_sigma_north(heading, n_a), _sigma_east(heading, n_a), n_a[2]]
        north_tilt, east_tilt, heading_noise = gyrocompass_noise(latitude, c_gamma, c_a, gyro_ned, accel_ned, gravity)
        # body roll and pitch at heading psi mix the north and east tilts
        roll_noise = math.hypot(math.cos(heading) * north_tilt, math.sin(heading) * east_tilt)
        pitch_noise = math.hypot(math.sin(heading) * north_tilt, math.cos(heading) * east_tilt)
        return AccuracyLimit(method, roll_bias, pitch_bias, heading_bias, roll_noise, pitch_noise, heading_noise)
    k = random_walk_factor(method)
    heading_noise = k * _sigma_east(heading, n_g) / (rate * math.sqrt(duration))
    accel_share = _sigma_east(heading, n_a) * tan_l / (gravity * math.sqrt(duration))
    if method == "inertial_frame":
        # its estimate of C_b^n(0) rests on the specific force over the window, then the gyros carry it to the end:
        # the north tilt drifts by (3/4) b_gN T (the east one is absorbed with the heading) and the heading by
        # b_gD T / 2 (tests/test_alignment.py); a level body at heading psi sees the north tilt in roll and pitch
        north_drift = 0.75 * _sigma_north(heading, gyro_b) * duration
        roll_bias = math.hypot(roll_bias, math.cos(heading) * north_drift)
        pitch_bias = math.hypot(pitch_bias, math.sin(heading) * north_drift)
        heading_bias = math.hypot(heading_bias, gyro_b[2] * duration / 2.0)
        # tilt noise carried by the gyros to the window's end, impulse responses of the method (u = s / T,
        # before | after u = 1/2): north k = 2u | 1 (var 2T/3), east k = -u | 3u - 2 (var T/6: the heading
        # takes up the rest; tests/test_alignment.py)
        north = _sigma_north(heading, n_g) * math.sqrt(2.0 * duration / 3.0)
        east = _sigma_east(heading, n_g) * math.sqrt(duration / 6.0)
        c, s = math.cos(heading), math.sin(heading)
        level_accel = math.sqrt(2.0) / (gravity * math.sqrt(duration))
        roll_noise = math.sqrt((c * north) ** 2 + (s * east) ** 2 + (level_accel * n_a[1]) ** 2)
        pitch_noise = math.sqrt((s * north) ** 2 + (c * east) ** 2 + (level_accel * n_a[0]) ** 2)
    elif method == "kalman":
        heading_noise = math.hypot(heading_noise, accel_share)
        roll_noise = kalman_level_noise(n_g[0], n_a[1], velocity_noise, update_interval, gravity)
        pitch_noise = kalman_level_noise(n_g[1], n_a[0], velocity_noise, update_interval, gravity)
    else:
        heading_noise = math.hypot(heading_noise, accel_share)
        roll_noise = n_a[1] / (gravity * math.sqrt(duration))
        pitch_noise = n_a[0] / (gravity * math.sqrt(duration))
    return AccuracyLimit(method, roll_bias, pitch_bias, heading_bias, roll_noise, pitch_noise, heading_noise)
