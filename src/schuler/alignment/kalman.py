"""Kalman fine alignment at rest: attitude, velocity, gyro and accelerometer bias states, zero-velocity updates.

States (NED, psi-angle form; spec 06 "Linear error model"; Groves 2013, sec. 14.2.4):
x = (phi, dv, b_g, b_a), phi the small rotation of the computed frame
(C^_b^n = (I - [phi x]) C_b^n), dv the velocity error (m/s), b_g and b_a the
residual gyro (rad/s) and accelerometer (m/s^2) biases (measured - true)
resolved in NED -- at rest C b is as constant as b:

    phi' = -omega_ie x phi - b_g + w_g
    dv'  = f^n x phi - 2 omega_ie x dv + b_a + w_a
    b_g' = w_bg,  b_a' = w_ba

Resolving the biases in NED rather than body axes keeps the model independent of
the computed heading: with body-axis states, F holds the computed C, and every
heading correction of a few degrees turns the modelled bias directions and makes
the unobservable bias/attitude split look partly observable (the covariance then
claims 10-25 % better heading and level than the errors show at tactical grade).
The mechanisation subtracts C^T b from the samples.

The body is at rest, so the computed velocity is the measurement of dv
(z = v, H = [0 I 0 0], noise ``velocity_noise`` for sway). The mechanisation
(:func:`~schuler.alignment._kernels.navigate_at_rest`) runs at the sample rate;
the filter predicts and updates every ``update_interval`` with the exact
Phi = expm(F dt) and Q_d = integral expm(F s) G Q G^T expm(F^T s) ds of the core's
Van Loan discretisation (:func:`~schuler.core.propagation.discretise_noise`, as every
Kalman filter of the project), and feeds every estimate back (closed loop): C <- exp([phi x]) C, v <- v - dv,
biases into the compensation.

Batched across records: the filter's matrices are ``(m, 12, 12)`` arrays and
every step is one ``matmul`` over the members; the mechanisation is one numba
call per update for all members. The filter starts from inertial-frame alignment
over ``initial_window`` seconds (:func:`~schuler.alignment.inertial.start_attitude`:
coarse alignment over a short disturbed window can be off by tens of degrees, even
180, which no linear filter recovers from); its initial covariance holds the start's error from
the biases, correlated with the bias states (:func:`coarse_error_map`), and the
noise part of its static limit inflated tenfold (the filter reads those samples again).

References
----------
Groves, P. D., Principles of GNSS, Inertial, and Multisensor Integrated Navigation
Systems, 2nd ed., Artech House, 2013, sec. 14.2.
Titterton, D. H.; Weston, J. L., Strapdown Inertial Navigation Technology, 2nd ed.,
IET, 2004, sec. 10.3.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.alignment import _kernels
from schuler.alignment.data import MethodEstimate, StaticBatch
from schuler.alignment.inertial import start_attitude
from schuler.alignment.limits import accuracy_limit, effective_bias_sigma
from schuler.core.attitude import dcm_from_euler, dcm_from_rotation_vector, euler_from_dcm, orthonormalise, skew
from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY, earth_rate_ned
from schuler.core.propagation import discretise_noise
from schuler.exceptions import InvalidParameter, renamed_keywords

STATES = 12
INFLATION = 10.0
"""Factor on the initial attitude variance: the coarse start uses samples the filter reads again."""


@dataclass(frozen=True)
class KalmanTuning:
    """The filter's noise model, SI, body axes (each a length-3 array).

    Attributes
    ----------
    gyro_random_walk, accel_random_walk : ndarray
        N, rad/sqrt(s) and m/s/sqrt(s).
    gyro_bias, accel_bias : ndarray
        Initial 1-sigma of the biases, rad/s and m/s^2.
    gyro_bias_walk, accel_bias_walk : ndarray
        Random walk of the biases, rad/s/sqrt(s) and m/s^2/sqrt(s).
    velocity_noise : float
        1-sigma of the zero-velocity measurement (sway of the body at rest), m/s.
    """

    gyro_random_walk: np.ndarray
    accel_random_walk: np.ndarray
    gyro_bias: np.ndarray
    accel_bias: np.ndarray
    gyro_bias_walk: np.ndarray
    accel_bias_walk: np.ndarray
    velocity_noise: float

    @classmethod
    @renamed_keywords(window_s="window")
    def from_model(cls, model, velocity_noise: float = 0.01, window: float = 600.0,
                   gravity: float = STANDARD_GRAVITY) -> KalmanTuning:
        """From an :class:`~schuler.imu.error_model.ErrorModel`: N, the constant error at rest
        (:func:`~schuler.alignment.limits.effective_bias_sigma`), and a bias walk that lets the bias
        instability B build up over ``window`` (q = B^2 / window).

        Parameters
        ----------
        model : ErrorModel
            The sensors' per-axis 1-sigma errors, SI, body axes.
        velocity_noise : float
            1-sigma of the zero-velocity measurement, m/s (> 0).
        window : float
            Time over which the bias instability builds up in the bias walk, s (finite, > 0).
        gravity : float
            g at the site, m/s^2 (for the g-dependent constant errors).

        Returns
        -------
        KalmanTuning
            The filter's noise model (body axes, SI).

        Raises
        ------
        InvalidParameter
            ``velocity_noise`` or ``window`` not finite and positive.
        """
        if not (math.isfinite(velocity_noise) and velocity_noise > 0):
            raise InvalidParameter("velocity_noise", f"must be finite and > 0 m/s, got {velocity_noise!r}")
        if not (math.isfinite(window) and window > 0):
            raise InvalidParameter("window", f"must be finite and > 0 s, got {window!r}")
        gyro, accel = model.gyro, model.accel
        gyro_bias, accel_bias = effective_bias_sigma(model, gravity)
        return cls(np.asarray(gyro.random_walk, dtype=float), np.asarray(accel.random_walk, dtype=float),
                   gyro_bias, accel_bias, gyro.bias_instability / math.sqrt(window),
                   accel.bias_instability / math.sqrt(window), float(velocity_noise))


def coarse_error_map(latitude: float, gravity: float) -> np.ndarray:
    """d phi / d(b_g^n, b_a^n) (3, 6): the start's attitude error from constant biases resolved in NED.

    Any alignment at rest (coarse, inertial frame) zeroes the sensed level specific force and east rate in the
    computed frame: g phi_E + b_aN = 0, -g phi_N + b_aE = 0 and
    Omega cos L phi_D + Omega sin L phi_N = b_gE, so phi_N = b_aE / g, phi_E = -b_aN / g,
    phi_D = b_gE / (Omega cos L) - tan(L) b_aE / g (the static limits of :mod:`.limits`).

    Parameters
    ----------
    latitude : float
        Latitude L, rad.
    gravity : float
        Gravity g at the site, m/s^2.

    Returns
    -------
    ndarray of shape (3, 6)
        M with phi = M (b_gN, b_gE, b_gD, b_aN, b_aE, b_aD): phi in rad (NED), columns 0-2 in s
        (rad per rad/s of gyro bias), columns 3-5 in s^2/m (rad per m/s^2 of accelerometer bias).
    """
    rate = EARTH_RATE * math.cos(latitude)
    M = np.zeros((3, 6))
    M[0, 4] = 1.0 / gravity
    M[1, 3] = -1.0 / gravity
    M[2, 1] = 1.0 / rate
    M[2, 4] = -math.tan(latitude) / gravity
    return M


def _resolved(sigma_body, heading: np.ndarray) -> np.ndarray:
    """Covariance (m, 3, 3) in NED of independent body-axis errors of 1-sigma ``sigma_body``, level at ``heading``."""
    rotation = dcm_from_euler(0.0, 0.0, heading)
    return rotation @ np.diag(np.asarray(sigma_body, dtype=float) ** 2) @ np.swapaxes(rotation, -1, -2)


def _initial_covariance(model, tuning: KalmanTuning, batch: StaticBatch, heading: np.ndarray,
                        initial_window_s: float) -> np.ndarray:
    """P0 (m, 12, 12): the start's error is M b (correlated with the bias states) plus its noise, inflated.

    The noise part is the larger of the start's limits at headings 0 and 90 deg (the axes' noise may differ),
    the same for every record: a record's estimate does not depend on the others of its batch.
    """
    limits = [accuracy_limit("inertial_frame", model, latitude=batch.latitude_rad, heading=psi,
                             duration=initial_window_s, gravity=batch.gravity) for psi in (0.0, math.pi / 2)]
    tilt_noise = max(max(limit.roll_noise_rad, limit.pitch_noise_rad) for limit in limits)
    heading_noise = max(limit.heading_noise_rad for limit in limits)
    biases = np.zeros((heading.size, 6, 6))
    biases[:, 0:3, 0:3] = _resolved(tuning.gyro_bias, heading)
    biases[:, 3:6, 3:6] = _resolved(tuning.accel_bias, heading)
    M = coarse_error_map(batch.latitude_rad, batch.gravity)
    P = np.zeros((heading.size, STATES, STATES))
    P[:, 0:3, 0:3] = M @ biases @ M.T + INFLATION * np.diag(
        [tilt_noise**2, tilt_noise**2, heading_noise**2])
    P[:, 0:3, 6:12] = M @ biases
    P[:, 6:12, 0:3] = np.swapaxes(P[:, 0:3, 6:12], 1, 2)
    P[:, 3:6, 3:6] = np.eye(3) * tuning.velocity_noise**2
    P[:, 6:12, 6:12] = biases
    return P


def _error_model(C: np.ndarray, gravity: float, omega: np.ndarray):
    """F (12, 12) and the noise input G (m, 12, 12) of the error model at rest.

    The specific force in F is the modelled one at rest, (0, 0, -g): the measured
    mean carries the accelerometer noise, and with it f x phi would make the heading
    look observable through noise.
    """
    F = np.zeros((STATES, STATES))
    W = skew(omega)
    F[0:3, 0:3] = -W
    F[0:3, 6:9] = -np.eye(3)
    F[3:6, 0:3] = skew(np.array([0.0, 0.0, -gravity]))
    F[3:6, 3:6] = -2.0 * W
    F[3:6, 9:12] = np.eye(3)
    G = np.zeros((C.shape[0], STATES, STATES))
    G[:, 0:3, 0:3] = -C
    G[:, 3:6, 3:6] = C
    G[:, 6:9, 6:9] = C
    G[:, 9:12, 9:12] = C
    return F, G


def attitude_sigma(P: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """1-sigma of roll, pitch, heading (m, 3) from the covariance of phi (m, >=3, >=3) at the given headings.

    roll error = -(cos psi phi_N + sin psi phi_E), pitch error = sin psi phi_N - cos psi phi_E,
    heading error = -phi_D (level body).

    Parameters
    ----------
    P : ndarray of shape (m, >=3, >=3)
        State covariance whose leading 3 x 3 block is that of phi (NED), rad^2.
    heading : ndarray of shape (m,)
        Heading psi of each level body, rad.

    Returns
    -------
    ndarray of shape (m, 3)
        1-sigma of roll, pitch and heading errors, rad.
    """
    c, s = np.cos(heading), np.sin(heading)
    J = np.zeros(heading.shape + (3, 3))
    J[..., 0, 0], J[..., 0, 1] = -c, -s
    J[..., 1, 0], J[..., 1, 1] = s, -c
    J[..., 2, 2] = -1.0
    cov = J @ P[..., 0:3, 0:3] @ np.swapaxes(J, -1, -2)
    return np.sqrt(np.maximum(np.diagonal(cov, axis1=-2, axis2=-1), 0.0))


@renamed_keywords(update_interval_s="update_interval", initial_window_s="initial_window", history_step_s="history_step")
def align_kalman(batch: StaticBatch, model, *, velocity_noise: float = 0.01, update_interval: float = 1.0,
                 initial_window: float = 30.0, history_step: float = 1.0) -> MethodEstimate:
    """Kalman fine alignment of every record of ``batch`` at once.

    Parameters
    ----------
    batch : StaticBatch
    model : ErrorModel
        The sensors' error model: the filter's noise and bias statistics (:meth:`KalmanTuning.from_model`).
    velocity_noise : float
        1-sigma of the zero-velocity measurement, m/s.
    update_interval : float
        Time between filter updates, s (rounded to whole samples).
    initial_window : float
        Inertial-frame alignment over the first seconds gives the start (shortened to the window if longer).
    history_step : float
        Step of the histories, s (rounded to whole updates).

    Returns
    -------
    MethodEstimate
        With the filter's 1-sigma of roll, pitch and heading (final and over time).
    """
    if not (math.isfinite(update_interval) and update_interval > 0):
        raise InvalidParameter("update_interval", f"must be finite and > 0 s, got {update_interval!r}")
    dt = batch.sample_interval_s
    per_update = max(1, int(round(update_interval / dt)))
    tuning = KalmanTuning.from_model(model, velocity_noise, gravity=batch.gravity)
    head = batch.head(initial_window)
    C = start_attitude(head)
    heading0 = euler_from_dcm(C)[2]
    m = batch.members
    P = _initial_covariance(model, tuning, batch, heading0, head.duration_s)
    omega = earth_rate_ned(batch.latitude_rad)
    gravity = np.array([0.0, 0.0, batch.gravity])
    velocity = np.zeros((m, 3))
    gyro_bias, accel_bias = np.zeros((m, 3)), np.zeros((m, 3))   # NED-resolved estimates
    previous = np.zeros((m, 6))
    intensity = np.diag(np.concatenate([tuning.gyro_random_walk**2, tuning.accel_random_walk**2,
                                        tuning.gyro_bias_walk**2, tuning.accel_bias_walk**2]))
    R = np.eye(3) * tuning.velocity_noise**2
    bounds = np.append(np.arange(0, batch.samples, per_update), batch.samples)
    record_every = max(1, int(round(history_step / (per_update * dt))))
    times, angles, sigmas = [], [], []
    for step, (start, stop) in enumerate(zip(bounds[:-1], bounds[1:])):
        span = (stop - start) * dt
        to_body = np.swapaxes(C, 1, 2)
        _kernels.navigate_at_rest(batch.gyro_increment, batch.accel_increment, int(start), int(stop), dt, C, velocity,
                                  np.einsum("mij,mj->mi", to_body, gyro_bias),
                                  np.einsum("mij,mj->mi", to_body, accel_bias), omega, gravity, previous)
        F, G = _error_model(C, batch.gravity, omega)
        Phi, Q = discretise_noise(F, G @ intensity @ np.swapaxes(G, 1, 2), span)
        P = Phi @ P @ np.swapaxes(Phi, -1, -2) + Q
        S = P[:, 3:6, 3:6] + R
        gain = np.swapaxes(np.linalg.solve(S, np.swapaxes(P[:, :, 3:6], 1, 2)), 1, 2)
        x = np.einsum("mij,mj->mi", gain, velocity)
        P = P - gain @ S @ np.swapaxes(gain, 1, 2)
        P = 0.5 * (P + np.swapaxes(P, 1, 2))
        C = orthonormalise(dcm_from_rotation_vector(x[:, 0:3]) @ C)
        velocity -= x[:, 3:6]
        gyro_bias += x[:, 6:9]
        accel_bias += x[:, 9:12]
        if (step + 1) % record_every == 0 or stop == batch.samples:
            roll, pitch, heading = euler_from_dcm(C)
            times.append(stop * dt)
            angles.append(np.stack([roll, pitch, heading], axis=1))
            sigmas.append(attitude_sigma(P, heading))
    history = np.stack(angles, axis=1)
    sigma_history = np.stack(sigmas, axis=1)
    return MethodEstimate("kalman", history[:, -1, 0], history[:, -1, 1], history[:, -1, 2], sigma_history[:, -1],
                          np.asarray(times), history[..., 0], history[..., 1], history[..., 2], sigma_history)
