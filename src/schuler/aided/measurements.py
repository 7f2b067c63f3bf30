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

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*,
2nd ed., Artech House, 2013, Sec. 14.2.3 (lever arms).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from schuler.aided.error_state import ATTITUDE, GYRO_BIAS, GYRO_SCALE, POSITION, VELOCITY
from schuler.core.attitude import skew
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
    if n_states == 21:
        H[:, :, GYRO_SCALE] = coupling * solution.angular_rate[:, None, :]
    return residual, H
