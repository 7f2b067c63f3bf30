"""Measurement models of the aided INS: the residual delta_z = h(x_hat) - z and its H (spec 07).

Errors are computed - true, C_hat = (I - [psi x]) C, so C_hat a = C a + [(C a) x] psi for any
body vector a. For a GNSS antenna at the body lever arm l (m, from the IMU to the antenna):

* position: r_ant = r + C l; the residual in NED metres (north, east, down) is
  delta_z = delta_r + [(C l) x] psi + v, with the geodetic differences scaled by R_N + h and
  (R_E + h) cos L;
* velocity: v_ant = v + C (omega_ib x l) - (omega_ie + omega_en) x C l;
  delta_z = delta_v + [(C (omega_ib x l)) x] psi - C [l x] (b_g + diag(omega_ib) s_g) + v.
  The error of the last term, -(omega_in) x [(C l) x] psi, is below 1e-4 m/s per rad of psi per
  metre of lever arm and is left out of H (not out of h).

The other measurements (spec 07, "Measurements"; the aiding states s_o and b_h of
:mod:`schuler.aided.error_state` are residual errors of the compensated data):

* zero velocity at a stop: delta_z = v_hat (true v = 0), H = [0 I 0 ...];
* zero angular rate at a stop: delta_z = omega_hat_ib^b - C_hat_n^b omega_ie^n
  = b_g + diag(omega_ib) s_g + C_n^b [omega_ie x] psi, with C_hat_n^b = C_n^b (I + [psi x]); at rest the true
  omega_ib is the Earth's rate C_hat_n^b omega_ie^n, which the scale factors' column takes (the measured rate
  there holds the residual bias: with a consumer IMU's 20 deg/s the filter would read its scale factors off the
  bias's feedback, 3 % known to 0.08 % after one stop);
* vehicle frame (non-holonomic constraint and odometer): the wheel point at l_odo (body axes, from
  the IMU) moves at v^v = C_b^v (C_n^b v + omega_nb^b x l_odo), omega_nb^b = omega_ib^b - C_n^b omega_in^n,
  C_b^v from the IMU's mounting angles (:func:`schuler.aided.measurements.mounting_matrix`). The
  constraint is v^v_y = v^v_z = 0, the odometer v^v_x = speed / (1 + s_hat_o) = v^v_x (1 + s_o). To first order
  delta_z = C_b^v C_n^b delta_v - C_b^v C_n^b [v x] psi - C_b^v [l_odo x] (b_g + diag(omega_ib) s_g)
  - speed_c s_o (odometer row); C_b^v C_n^b [omega_in x] psi (below 1e-4 m/s per rad per metre of
  arm) is left out of H, not out of h;
* barometric height: delta_z = h_hat - (h_baro - b_hat_h) = -delta_r_D - b_h.

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*,
2nd ed., Artech House, 2013, Sec. 14.2.3 (lever arms), Sec. 16.2 (odometer, non-holonomic
constraint), Sec. 15.3.2 (zero velocity and zero angular rate updates).
E.-H. Shin, *Estimation Techniques for Low-Cost Inertial Navigation*, PhD thesis, University of
Calgary, 2005, Sec. 4.3 (non-holonomic constraints).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from schuler.aided.error_state import ATTITUDE, GYRO_BIAS, GYRO_SCALE, POSITION, VELOCITY, FilterModel
from schuler.core.attitude import dcm_from_euler, skew
from schuler.core.earth import EARTH_RATE, radii_of_curvature


@dataclass(frozen=True)
class Solution:
    """The navigation solution of a batch of members at one time (SI).

    Parameters
    ----------
    latitude, longitude : ndarray, shape (N,)
        rad.
    height : ndarray, shape (N,)
        m.
    velocity : ndarray, shape (N, 3)
        NED, m/s.
    body_to_ned : ndarray, shape (N, 3, 3)
        C_b^n.
    angular_rate : ndarray, shape (N, 3)
        omega_ib^b, rad/s (the compensated gyros over the last interval).
    """

    latitude: np.ndarray
    longitude: np.ndarray
    height: np.ndarray
    velocity: np.ndarray
    body_to_ned: np.ndarray
    angular_rate: np.ndarray


def antenna_position(solution: Solution, lever_arm: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Latitude, longitude (rad) and height (m) of the antenna at body lever arm l (m), each (N,).

    Parameters
    ----------
    solution : Solution
        Where the IMU is and how the body is turned.
    lever_arm : ndarray, shape (3,)
        IMU to antenna, body axes (x forward, y right, z down), m.
    """
    offset = solution.body_to_ned @ np.asarray(lever_arm, dtype=float)
    R_N, R_E = radii_of_curvature(solution.latitude)
    h = solution.height
    return (solution.latitude + offset[:, 0] / (R_N + h),
            solution.longitude + offset[:, 1] / ((R_E + h) * np.cos(solution.latitude)),
            h - offset[:, 2])


def gnss_position(solution: Solution, lever_arm: np.ndarray, latitude, longitude, height,
                  n_states: int) -> tuple[np.ndarray, np.ndarray]:
    """Residual (N, 3) in NED metres and H (N, 3, n) of a GNSS position fix.

    Parameters
    ----------
    solution : Solution
        The navigation solution at the fix's time.
    lever_arm : ndarray, shape (3,)
        IMU to antenna, body axes, m.
    latitude, longitude : float or ndarray, shape (N,)
        Measured antenna position, rad.
    height : float or ndarray, shape (N,)
        Measured ellipsoidal height of the antenna, m.
    n_states : int
        Number of error states (15 or 21).
    """
    lat_a, lon_a, h_a = antenna_position(solution, lever_arm)
    R_N, R_E = radii_of_curvature(solution.latitude)
    h = solution.height
    residual = np.stack([(lat_a - latitude) * (R_N + h),
                         (lon_a - longitude) * (R_E + h) * np.cos(solution.latitude),
                         -(h_a - height)], axis=-1)
    H = np.zeros((residual.shape[0], 3, n_states))
    H[:, :, POSITION] = np.eye(3)
    H[:, :, ATTITUDE] = skew(solution.body_to_ned @ np.asarray(lever_arm, dtype=float))
    return residual, H


def antenna_velocity(solution: Solution, lever_arm: np.ndarray, earth_rate: float = EARTH_RATE) -> np.ndarray:
    """NED velocity of the antenna, m/s, shape (N, 3) (module docstring).

    Parameters
    ----------
    solution : Solution
        The navigation solution (its angular rate gives the lever arm's own motion).
    lever_arm : ndarray, shape (3,)
        IMU to antenna, body axes, m.
    earth_rate : float
        Omega, rad/s.
    """
    arm = np.asarray(lever_arm, dtype=float)
    L, h, v = solution.latitude, solution.height, solution.velocity
    R_N, R_E = radii_of_curvature(L)
    omega_in = np.stack([earth_rate * np.cos(L) + v[:, 1] / (R_E + h), -v[:, 0] / (R_N + h),
                         -earth_rate * np.sin(L) - v[:, 1] * np.tan(L) / (R_E + h)], axis=-1)
    C = solution.body_to_ned
    return v + np.einsum("nij,nj->ni", C, np.cross(solution.angular_rate, arm)) - np.cross(omega_in, C @ arm)


def gnss_velocity(solution: Solution, lever_arm: np.ndarray, velocity, n_states: int,
                  earth_rate: float = EARTH_RATE) -> tuple[np.ndarray, np.ndarray]:
    """Residual (N, 3) in m/s and H (N, 3, n) of a GNSS velocity (NED) at the antenna.

    Parameters
    ----------
    solution : Solution
        The navigation solution at the measurement's time.
    lever_arm : ndarray, shape (3,)
        IMU to antenna, body axes, m.
    velocity : ndarray, shape ([N,] 3)
        Measured antenna velocity, NED, m/s.
    n_states : int
        Number of error states (15 or 21).
    earth_rate : float
        Omega, rad/s.
    """
    arm = np.asarray(lever_arm, dtype=float)
    residual = antenna_velocity(solution, arm, earth_rate) - velocity
    C = solution.body_to_ned
    H = np.zeros((residual.shape[0], 3, n_states))
    H[:, :, VELOCITY] = np.eye(3)
    H[:, :, ATTITUDE] = skew(np.einsum("nij,nj->ni", C, np.cross(solution.angular_rate, arm)))
    coupling = -C @ skew(arm)
    H[:, :, GYRO_BIAS] = coupling
    if n_states >= 21:  # 15 or 21 states, then at most two aiding states
        H[:, :, GYRO_SCALE] = coupling * solution.angular_rate[:, None, :]
    return residual, H


def _transport(solution: Solution, earth_rate: float) -> np.ndarray:
    """omega_in^n = omega_ie^n + omega_en^n of the solution, rad/s, shape (N, 3)."""
    L, h, v = solution.latitude, solution.height, solution.velocity
    R_N, R_E = radii_of_curvature(L)
    return np.stack([earth_rate * np.cos(L) + v[:, 1] / (R_E + h), -v[:, 0] / (R_N + h),
                     -earth_rate * np.sin(L) - v[:, 1] * np.tan(L) / (R_E + h)], axis=-1)


def _gyro_terms(H: np.ndarray, rows: slice, coupling: np.ndarray, rate: np.ndarray, model: FilterModel) -> None:
    """H[rows] of the residual gyro errors entering through ``coupling`` (omega_hat = omega + b_g + diag(omega) s_g)."""
    H[:, rows, GYRO_BIAS] = coupling
    if model.sensor_size == 21:
        H[:, rows, GYRO_SCALE] = coupling * rate[:, None, :]


def zero_velocity(solution: Solution, model: FilterModel) -> tuple[np.ndarray, np.ndarray]:
    """Residual (N, 3) in m/s and H (N, 3, n) of a zero-velocity update at a stop (module docstring).

    Parameters
    ----------
    solution : Solution
        The navigation solution at the epoch.
    model : FilterModel
        The filter's states (their number).
    """
    H = np.zeros((solution.velocity.shape[0], 3, model.size))
    H[:, :, VELOCITY] = np.eye(3)
    return solution.velocity.copy(), H


def zero_rate(solution: Solution, mean_rate: np.ndarray, model: FilterModel,
              earth_rate: float = EARTH_RATE) -> tuple[np.ndarray, np.ndarray]:
    """Residual (N, 3) in rad/s and H (N, 3, n) of a zero-angular-rate update at a stop (module docstring).

    Parameters
    ----------
    solution : Solution
        The navigation solution at the epoch.
    mean_rate : ndarray, shape (N, 3)
        omega_hat_ib^b: the compensated gyros' mean over the window before the epoch, rad/s.
    model : FilterModel
        The filter's states.
    earth_rate : float
        Omega, rad/s.
    """
    L = solution.latitude
    omega_ie = np.stack([earth_rate * np.cos(L), np.zeros_like(L), -earth_rate * np.sin(L)], axis=-1)
    ned_to_body = np.swapaxes(solution.body_to_ned, -1, -2)
    earth_in_body = np.einsum("nij,nj->ni", ned_to_body, omega_ie)
    residual = mean_rate - earth_in_body
    H = np.zeros((L.shape[0], 3, model.size))
    H[:, :, ATTITUDE] = ned_to_body @ skew(omega_ie)
    _gyro_terms(H, slice(0, 3), np.broadcast_to(np.eye(3), (L.shape[0], 3, 3)), earth_in_body, model)
    return residual, H


def mounting_matrix(roll: float, pitch: float, heading: float) -> np.ndarray:
    """C_b^v: IMU body axes to vehicle axes from the IMU's mounting angles, shape (3, 3).

    The angles are the body's roll, pitch and heading relative to the vehicle frame (x forward, y right,
    z down), as C_b^n is built from the attitude (:func:`schuler.core.attitude.dcm_from_euler`).

    Parameters
    ----------
    roll, pitch, heading : float
        Mounting angles, rad.
    """
    return dcm_from_euler(roll, pitch, heading)


def wheel_velocity(solution: Solution, lever_arm, mounting: np.ndarray,
                   earth_rate: float = EARTH_RATE) -> np.ndarray:
    """v^v = C_b^v (C_n^b v + omega_nb^b x l_odo): the wheel point's velocity in vehicle axes, m/s, (N, 3).

    Parameters
    ----------
    solution : Solution
        The navigation solution (its angular rate: omega_ib^b).
    lever_arm : array_like, shape (3,)
        IMU to the wheel's contact point, body axes, m.
    mounting : ndarray, shape (3, 3)
        C_b^v (:func:`schuler.aided.measurements.mounting_matrix`), plain numbers.
    earth_rate : float
        Omega, rad/s.
    """
    arm = np.asarray(lever_arm, dtype=float)
    ned_to_body = np.swapaxes(solution.body_to_ned, -1, -2)
    omega_nb = solution.angular_rate - np.einsum("nij,nj->ni", ned_to_body, _transport(solution, earth_rate))
    body = np.einsum("nij,nj->ni", ned_to_body, solution.velocity) + np.cross(omega_nb, arm)
    return body @ np.asarray(mounting, dtype=float).T


def vehicle(solution: Solution, lever_arm, mounting: np.ndarray, speed, model: FilterModel, *,
            rows=(0, 1, 2), odometer_scale=0.0, earth_rate: float = EARTH_RATE) -> tuple[np.ndarray, np.ndarray]:
    """Residual (N, m) in m/s and H (N, m, n) of the odometer (row 0) and the non-holonomic constraint (rows 1, 2).

    Parameters
    ----------
    solution : Solution
        The navigation solution at the epoch.
    lever_arm : array_like, shape (3,)
        IMU to the wheel's contact point, body axes, m.
    mounting : ndarray, shape (3, 3)
        C_b^v, plain numbers.
    speed : float or ndarray, shape (N,)
        Measured odometer speed, m/s (ignored without row 0).
    model : FilterModel
        The filter's states (an ``odometer_scale`` state enters row 0).
    rows : sequence of int
        Components of v^v used, each an index: 0 the odometer, 1 and 2 the constraint.
    odometer_scale : float or ndarray, shape (N,)
        s_hat_o compensated from the speed, dimensionless.
    earth_rate : float
        Omega, rad/s.
    """
    C_bv = np.asarray(mounting, dtype=float)
    members = solution.velocity.shape[0]
    compensated = np.broadcast_to(np.asarray(speed, dtype=float) / (1.0 + np.asarray(odometer_scale, dtype=float)),
                                  (members,))
    residual = wheel_velocity(solution, lever_arm, C_bv, earth_rate)
    residual[:, 0] -= compensated
    M = C_bv @ np.swapaxes(solution.body_to_ned, -1, -2)
    H = np.zeros((members, 3, model.size))
    H[:, :, VELOCITY] = M
    H[:, :, ATTITUDE] = -M @ skew(solution.velocity)
    _gyro_terms(H, slice(0, 3), np.broadcast_to(-C_bv @ skew(np.asarray(lever_arm, dtype=float)), (members, 3, 3)),
                solution.angular_rate, model)
    index = model.aiding_states().get("odometer_scale")
    if index is not None:
        H[:, 0, index] = -compensated
    rows = list(rows)
    return residual[:, rows], H[:, rows]


def barometer(solution: Solution, height, model: FilterModel, bias=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Residual (N, 1) in m and H (N, 1, n) of a barometric height (module docstring).

    Parameters
    ----------
    solution : Solution
        The navigation solution at the epoch.
    height : float or ndarray, shape (N,)
        Measured barometric height, m.
    model : FilterModel
        The filter's states (a ``barometer_bias`` state enters).
    bias : float or ndarray, shape (N,)
        b_hat_h compensated from the measured height, m.
    """
    members = solution.height.shape[0]
    residual = (solution.height - (np.asarray(height, dtype=float) - bias))[:, None]
    H = np.zeros((members, 1, model.size))
    H[:, 0, 2] = -1.0
    index = model.aiding_states().get("barometer_bias")
    if index is not None:
        H[:, 0, index] = -1.0
    return np.broadcast_to(residual, (members, 1)).copy(), H
