"""The trajectory as the linear error model sees it: means of its kinematics over each step.

The psi-angle model's coefficients (latitude, height, velocity, specific force)
and the sensor errors' coupling (body-to-NED rotation, body angular rate and
specific force, which scale-factor errors multiply) change along the path; the
covariance analysis freezes them at their means over each step, the first
Magnus term, as :func:`schuler.navigation_errors.three_d.propagate_along` does.
The means are trapezoidal averages of the kinematics on ``substeps`` points
per step.

Position is not an input of a trajectory (:mod:`schuler.navigate.trajectory`):
latitude and height are integrated from the velocity, L' = v_N / (R_N + h),
h' = -v_D (Groves 2013, eq. (5.56) without its longitude line), by the
trapezoidal rule with the radius at the step's mean latitude. The specific
force follows from the navigation equation (Groves 2013, eq. (5.54)),
f^n = v' - g^n + (2 omega_ie + omega_en) x v, and the body rate from
[omega_nb^b x] = C_n^b dC_b^n/dt: omega_ib^b = C_n^b (omega_ie + omega_en) + omega_nb^b.

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
Artech House, 2013, Sec. 5.4.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from schuler.core.attitude import dcm_from_quaternion
from schuler.core.earth import EARTH_RATE, earth_rate_ned, gravity_ned, radii_of_curvature, transport_rate_ned

SUBSTEPS = 8
"""Points per step of the trapezoidal means (the coefficients change little within a minute)."""


@dataclass(frozen=True)
class StepCoefficients:
    """Means over each of K steps (SI): the inputs of the psi-angle model and of the sensor coupling.

    Attributes
    ----------
    time : ndarray (K + 1,)
        Step boundaries, s.
    latitude, height : ndarray (K,)
    velocity_ned, specific_force_ned : ndarray (K, 3)
    body_to_ned : ndarray (K, 3, 3)
        C_b^n.
    body_rate, body_specific_force : ndarray (K, 3)
        omega_ib^b (rad/s) and f^b (m/s^2).
    """

    time: np.ndarray
    latitude: np.ndarray
    height: np.ndarray
    velocity_ned: np.ndarray
    specific_force_ned: np.ndarray
    body_to_ned: np.ndarray
    body_rate: np.ndarray
    body_specific_force: np.ndarray


def _step_means(values: np.ndarray, steps: int, substeps: int) -> np.ndarray:
    shaped = values.reshape(steps * substeps + 1, -1)
    inner = shaped[:-1].reshape(steps, substeps, -1)
    ends = shaped[substeps::substeps]
    means = (inner.sum(axis=1) - 0.5 * inner[:, 0] + 0.5 * ends) / substeps
    return means.reshape((steps, *values.shape[1:]))


def step_coefficients(trajectory, latitude: float, height: float, duration: float, step: float,
                      substeps: int = SUBSTEPS, rate: float = EARTH_RATE) -> StepCoefficients:
    """The trajectory's kinematics averaged over each step of ``step`` s (``duration`` a whole number of steps).

    Parameters
    ----------
    trajectory : Stationary, GreatCircle or WaypointProfile
        A trajectory of :mod:`schuler.navigate.trajectory`: ``kinematics(time)`` gives the NED velocity (m/s)
        and the attitude quaternion q_bn.
    latitude : float
        Latitude L of the start point, rad.
    height : float
        Height h of the start point, m.
    duration : float
        Length of the analysis, s (rounded to whole steps).
    step : float
        Step over which the coefficients are frozen, s.
    substeps : int
        Points per step of the trapezoidal means, number of.
    rate : float
        Earth rate Omega, rad/s.

    Returns
    -------
    StepCoefficients
        Means over each of K = round(duration / step) steps, SI.

    Examples
    --------
    At rest the specific force holds the vehicle against gravity (with its centrifugal part):

    >>> from schuler.navigate.trajectory import Stationary
    >>> c = step_coefficients(Stationary(latitude=0.7), 0.7, 0.0, 600.0, 60.0)
    >>> c.latitude.shape, bool(np.allclose(c.specific_force_ned, -gravity_ned(0.7, 0.0), rtol=0, atol=1e-12))
    ((10,), True)
    """
    steps = int(round(duration / step))
    time = np.arange(steps * substeps + 1) * (step / substeps)
    velocity, quaternion = trajectory.kinematics(time)
    lat = np.full(time.size, float(latitude))
    hgt = height - np.concatenate([[0.0], np.cumsum(0.5 * (velocity[1:, 2] + velocity[:-1, 2]) * np.diff(time))])
    for _ in range(2):
        radius_north, _ = radii_of_curvature(0.5 * (lat[1:] + lat[:-1]))
        rate_north = 0.5 * (velocity[1:, 0] + velocity[:-1, 0]) / (radius_north + 0.5 * (hgt[1:] + hgt[:-1]))
        lat = latitude + np.concatenate([[0.0], np.cumsum(rate_north * np.diff(time))])
    omega = earth_rate_ned(lat, rate)
    rho = transport_rate_ned(lat, hgt, velocity[:, 0], velocity[:, 1])
    force_ned = (np.gradient(velocity, time, axis=0) - gravity_ned(lat, hgt)
                 + np.cross(2.0 * omega + rho, velocity))
    C = dcm_from_quaternion(quaternion)
    turn = np.einsum("kji,kjl->kil", C, np.gradient(C, time, axis=0))
    body_turn = np.stack([turn[:, 2, 1], turn[:, 0, 2], turn[:, 1, 0]], axis=-1)
    body_rate = np.einsum("kji,kj->ki", C, omega + rho) + body_turn
    body_force = np.einsum("kji,kj->ki", C, force_ned)
    def mean(values):
        return _step_means(values, steps, substeps)

    return StepCoefficients(time=np.arange(steps + 1) * step, latitude=mean(lat), height=mean(hgt),
                            velocity_ned=mean(velocity), specific_force_ned=mean(force_ned), body_to_ned=mean(C),
                            body_rate=mean(body_rate), body_specific_force=mean(body_force))
