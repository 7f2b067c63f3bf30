"""Inertial-frame (i0) alignment: gravity traced in inertial space over the window gives the heading.

Two frames fixed in inertial space at the window's start: ib0, the body frame
then, and n0, the NED frame then. The gyros carry C_b^{ib0}(t) from C = I;
the specific force integrated in ib0 is v^{ib0}(t) = int_0^t C_b^{ib0} f_b dt.
In n0 the same integral is known: f^n = (0, 0, -g) turns with the Earth,
C_n^{n0}(t) = exp([omega_ie^n x] t), so

    v^{n0}(t) = [t I + (1 - cos Omega t) / Omega^2 [omega x] + (Omega t - sin Omega t) / Omega^3 [omega x]^2] f^n.

The constant C_{ib0}^{n0} = C_b^n(0) maps one onto the other; TRIAD on the
pairs at t1 = T/2 (primary) and t2 = T gives it, and
C_b^n(T) = exp(-[omega_ie x] T) C_{ib0}^{n0} C_b^{ib0}(T) (Qin Yongyuan's
inertial-frame alignment, as in PSINS ``aligni0``; Groves 2013, sec. 14.3.1;
Titterton and Weston 2004, sec. 10.4). Integrated specific force averages out
linear sway and the gyros follow angular motion: the method keeps working
when the body is disturbed, where coarse alignment's mean rate does not.

Accuracy: the static limits with the random-walk factor 2 / sqrt(3)
(:func:`~schuler.alignment.limits.random_walk_factor`).

Examples
--------
>>> import math
>>> import numpy as np
>>> from schuler.alignment.data import StaticBatch
>>> from schuler.imu.simulate import static_truth
>>> gyro, accel = static_truth(math.radians(45.0), math.radians(-120.0))
>>> n = 30_000
>>> batch = StaticBatch(np.tile(gyro * 0.01, (1, n, 1)), np.tile(accel * 0.01, (1, n, 1)), 0.01, math.radians(45.0))
>>> estimate = align_inertial(batch)
>>> round(float(np.degrees(estimate.heading_rad[0])), 6)
-120.0
"""

from __future__ import annotations

import numpy as np

from schuler.alignment import _kernels
from schuler.alignment.data import MethodEstimate, StaticBatch
from schuler.core.attitude import dcm_from_rotation_vector, euler_from_dcm, skew, triad
from schuler.core.earth import earth_rate_ned
from schuler.exceptions import renamed_keywords


def navigation_velocity(times, latitude, gravity) -> np.ndarray:
    """v^{n0}(t) = int_0^t C_n^{n0} f^n dt at rest (module notes), m/s, shape (K, 3).

    Parameters
    ----------
    times : array_like of shape (K,)
        Times t from the window's start, s.
    latitude : float
        Latitude L, rad.
    gravity : float
        Gravity g at the site, m/s^2 (f^n = (0, 0, -g)).

    Returns
    -------
    ndarray of shape (K, 3)
        Integrated specific force in the n0 frame (NED at the start), m/s.
    """
    omega = earth_rate_ned(latitude)
    rate = float(np.linalg.norm(omega))
    t = np.asarray(times, dtype=float)[:, None, None]
    W = skew(omega)
    integral = (t * np.eye(3) + (1.0 - np.cos(rate * t)) / rate**2 * W
                + (rate * t - np.sin(rate * t)) / rate**3 * (W @ W))
    return integral @ np.array([0.0, 0.0, -gravity])


def _start_and_end(batch: StaticBatch):
    ends = np.array(sorted({max(1, batch.samples // 2), batch.samples}))
    attitude = np.empty((batch.members, ends.size, 3, 3))
    velocity = np.empty((batch.members, ends.size, 3))
    _kernels.inertial_integrate(batch.gyro_increment, batch.accel_increment, ends, attitude, velocity)
    v_nav = navigation_velocity(ends * batch.sample_interval_s, batch.latitude_rad, batch.gravity)
    return triad(velocity[:, 0], velocity[:, -1], v_nav[0], v_nav[-1]), attitude[:, -1]


def net_rotation(batch: StaticBatch) -> np.ndarray:
    """The body's rotation relative to the Earth over the window, NED rotation vector (m, 3), rad.

    C_b^n(T) C_b^n(0)^T with C_b^n(T) = exp(-[omega_ie x] T) C_{ib0}^{n0} C_b^{ib0}(T): zero for a body
    at rest, the net turn of a disturbed one (a vehicle settling, people boarding). Its mean rate
    over the window is what coarse alignment takes for Earth rate: about east, it moves coarse
    alignment's heading by -(rotation_E / T) / (Omega cos L).

    Parameters
    ----------
    batch : StaticBatch
        The records (angle and velocity increments, body axes) and their site.

    Returns
    -------
    ndarray of shape (m, 3)
        Net rotation vector of each record over the window, rad, NED axes.
    """
    from scipy.spatial.transform import Rotation

    start, body = _start_and_end(batch)
    earth_turn = dcm_from_rotation_vector(-earth_rate_ned(batch.latitude_rad) * batch.duration_s)
    relative = earth_turn @ start @ body @ np.swapaxes(start, 1, 2)
    return Rotation.from_matrix(relative).as_rotvec()


def start_attitude(batch: StaticBatch) -> np.ndarray:
    """C_b^n at the start of the batch's window, (m, 3, 3): C_{ib0}^{n0} from TRIAD at T/2 and T (module notes).

    What the Kalman filter and the gyrocompass start from: unlike coarse alignment it
    keeps its heading when the body is disturbed.

    Parameters
    ----------
    batch : StaticBatch
        The records whose window gives the start (typically its first seconds, :meth:`StaticBatch.head`).

    Returns
    -------
    ndarray of shape (m, 3, 3)
        C_b^n (body to NED) of each record at the window's start, plain numbers.
    """
    return _start_and_end(batch)[0]


@renamed_keywords(history_step_s="history_step")
def align_inertial(batch: StaticBatch, history_step: float = 1.0) -> MethodEstimate:
    """Inertial-frame alignment of every record of ``batch``, with the history over the window.

    Parameters
    ----------
    batch : StaticBatch
    history_step : float
        Step of the histories, s (each point is the method run on [0, t], with t1 = t/2 rounded down).

    Returns
    -------
    MethodEstimate
        No 1-sigma of its own.
    """
    history = batch.history_indices(history_step)
    ends = np.union1d(history, [max(1, batch.samples // 2)])
    attitude = np.empty((batch.members, ends.size, 3, 3))
    velocity = np.empty((batch.members, ends.size, 3))
    _kernels.inertial_integrate(batch.gyro_increment, batch.accel_increment, ends, attitude, velocity)
    times = ends * batch.sample_interval_s
    second = np.searchsorted(ends, history)
    first = np.searchsorted(ends, history // 2, side="right") - 1
    usable = (first >= 0) & (first < second)
    first, second = first[usable], second[usable]
    v_nav = navigation_velocity(times, batch.latitude_rad, batch.gravity)
    start_attitude = triad(velocity[:, first], velocity[:, second], v_nav[first], v_nav[second])
    earth_turn = dcm_from_rotation_vector(-earth_rate_ned(batch.latitude_rad) * times[second][:, None])
    dcm = earth_turn @ start_attitude @ attitude[:, second]
    roll, pitch, heading = euler_from_dcm(dcm)
    return MethodEstimate("inertial_frame", roll[:, -1], pitch[:, -1], heading[:, -1], None, times[second], roll,
                          pitch, heading)
