"""Analytic coarse alignment (double vector, TRIAD) from the mean specific force and angular rate.

At rest the specific force is f^n = (0, 0, -g) and the angular rate the Earth
rate omega^n = Omega (cos L, 0, -sin L) (NED). With their means over the window
measured in the body frame, TRIAD (:func:`~schuler.core.attitude.triad`)
with -f (down) as the primary vector and -f x omega (east) as the secondary
gives C_b^n: roll and pitch from the specific force alone,

    roll = atan2(-f_y, -f_z),   pitch = atan2(f_x, sqrt(f_y^2 + f_z^2)),

and the heading from the horizontal Earth rate in the levelled frame,
heading = atan2(-omega_lE', omega_lN') (Groves 2013, sec. 5.6.2; Titterton and
Weston 2004, sec. 10.2.1; spec 06). Its errors are the static limits of
:mod:`~schuler.alignment.limits` with k = 1: the estimate *is* the mean over
the window, so any angular disturbance (sway, people boarding) enters it
directly -- what the inertial-frame method avoids.

Examples
--------
>>> import math
>>> import numpy as np
>>> from schuler.imu.simulate import static_truth
>>> gyro, accel = static_truth(math.radians(45.0), math.radians(30.0))
>>> roll, pitch, heading = coarse_attitude(accel[None], gyro[None], math.radians(45.0))
>>> round(float(np.degrees(heading[0])), 9), abs(float(roll[0])) < 1e-15
(30.0, True)
"""

from __future__ import annotations

import numpy as np

from schuler.alignment.data import MethodEstimate, StaticBatch
from schuler.core.attitude import euler_from_dcm, triad
from schuler.core.earth import earth_rate_ned
from schuler.exceptions import renamed_keywords

DOWN = np.array([0.0, 0.0, 1.0])


def coarse_dcm(specific_force, angular_rate, latitude) -> np.ndarray:
    """C_b^n by TRIAD from specific force (..., 3) m/s^2 and angular rate (..., 3) rad/s, body axes.

    The primary pair is gravity's direction (-f in the body, down in NED), the
    secondary the Earth rate (``angular_rate`` in the body, Omega (cos L, 0, -sin L) in NED).

    Parameters
    ----------
    specific_force : array_like of shape (..., 3)
        Mean specific force f, m/s^2, body axes x fwd, y right, z down (about (0, 0, -g) when level).
    angular_rate : array_like of shape (..., 3)
        Mean angular rate, rad/s, body axes x, y, z.
    latitude : float or array_like
        Latitude L, rad (broadcast against the leading dimensions).

    Returns
    -------
    ndarray of shape (..., 3, 3)
        C_b^n (body to NED), plain numbers.
    """
    specific_force = np.asarray(specific_force, dtype=float)
    omega_n = np.broadcast_to(earth_rate_ned(latitude), specific_force.shape)
    return triad(-specific_force, angular_rate, np.broadcast_to(DOWN, specific_force.shape), omega_n)


def coarse_attitude(specific_force, angular_rate, latitude):
    """Roll, pitch, heading (rad) by :func:`coarse_dcm`.

    Parameters
    ----------
    specific_force : array_like of shape (..., 3)
        Mean specific force f, m/s^2, body axes x fwd, y right, z down.
    angular_rate : array_like of shape (..., 3)
        Mean angular rate, rad/s, body axes x, y, z.
    latitude : float or array_like
        Latitude L, rad.

    Returns
    -------
    roll, pitch, heading : ndarray of shape (...)
        Aerospace angles of C_b^n, rad; heading clockwise from north in (-pi, pi].
    """
    return euler_from_dcm(coarse_dcm(specific_force, angular_rate, latitude))


@renamed_keywords(history_step_s="history_step")
def align_coarse(batch: StaticBatch, history_step: float = 1.0) -> MethodEstimate:
    """Coarse alignment of every record of ``batch`` over its whole window, with the growing-window history.

    Parameters
    ----------
    batch : StaticBatch
    history_step : float
        Step of the histories, s: the attitude from the samples up to each time.

    Returns
    -------
    MethodEstimate
        No 1-sigma of its own (``sigma_rad`` None): its accuracy is the static limit.
    """
    ends = batch.history_indices(history_step)
    starts = np.concatenate([[0], ends[:-1]])
    gyro = np.add.reduceat(batch.gyro_increment, starts, axis=1).cumsum(axis=1)
    accel = np.add.reduceat(batch.accel_increment, starts, axis=1).cumsum(axis=1)
    spans = (ends * batch.sample_interval_s)[None, :, None]
    roll, pitch, heading = coarse_attitude(accel / spans, gyro / spans, batch.latitude_rad)
    return MethodEstimate("coarse", roll[:, -1], pitch[:, -1], heading[:, -1], None,
                          ends * batch.sample_interval_s, roll, pitch, heading)
