"""The truth and the ideal IMU of a trajectory, by inverse mechanization, chunk by chunk.

For each IMU interval [t_{k-1}, t_k] (t_k = k dt) the generator evaluates the
trajectory's velocity and attitude at t_k, advances the position with the
navigation algorithm's own trapezoid update, and solves the algorithm's
attitude and velocity steps backwards for the angle and velocity increments
(dtheta_k, dv_k): see :mod:`schuler.navigate._kernels`. Integrating these ideal
increments with the forward algorithm returns the truth to rounding (the
tests state the floor), whatever the trajectory.

The work is streamed: :meth:`TruthGenerator.chunks` yields consecutive blocks
of samples, so a 48-hour run at 100 Hz never holds more than one block.

Examples
--------
>>> from schuler.navigate.trajectory import Stationary
>>> imu = ideal_imu(Stationary(latitude=np.radians(45.0)), duration=1.0, imu_rate=10.0)
>>> rate = imu.angular_rate_rad_s.mean(axis=0)
>>> bool(np.allclose(rate, [5.15627e-05, 0.0, -5.15627e-05], atol=1e-10))
True
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from schuler.core.earth import EARTH_RATE
from schuler.exceptions import InvalidParameter
from schuler.navigate import _kernels
from schuler.results import Result

DEFAULT_CHUNK = 65_536
"""IMU samples per streamed block."""


def sample_count(duration: float, imu_rate: float) -> int:
    """Number of IMU intervals in ``duration`` at ``imu_rate``; refuses a non-integer count.

    Parameters
    ----------
    duration : float
        Simulated time, s (> 0), a whole number of IMU intervals (to 1e-6 of the count).
    imu_rate : float
        IMU sample rate, Hz, in (0, 100000].

    Returns
    -------
    int
        Number of IMU intervals.

    Raises
    ------
    InvalidParameter
        Naming ``imu_rate`` or ``duration`` when out of range or not a whole number of intervals.

    Examples
    --------
    >>> sample_count(3600.0, 100.0)
    360000
    """
    if not (np.isfinite(imu_rate) and 0.0 < imu_rate <= 1.0e5):
        raise InvalidParameter("imu_rate", f"must lie in (0, 100000] Hz, got {imu_rate!r}")
    if not (np.isfinite(duration) and duration > 0):
        raise InvalidParameter("duration", f"must be finite and > 0, got {duration!r}")
    count = duration * imu_rate
    if abs(count - round(count)) > 1e-6 * max(1.0, count) or round(count) < 1:
        raise InvalidParameter("duration", f"{duration:g} s is not a whole number of IMU intervals at "
                                           f"{imu_rate:g} Hz")
    return round(count)


@dataclass
class TruthChunk:
    """One block of truth and ideal IMU: intervals ``start`` to ``start + n - 1`` (global indices).

    Attributes
    ----------
    start : int
        Index of the first interval; its end is sample ``start + 1``.
    increments : ndarray, shape (n, 6)
        Ideal angle (rad) and velocity (m/s) increments, body axes.
    nav_increments : ndarray, shape (n, 6)
        NED frame rotation zeta (rad) and NED specific-force increment (m/s) of each interval.
    positions : ndarray, shape (n, 3)
        Latitude, longitude (rad), height (m) at the end of each interval.
    velocities : ndarray, shape (n, 3)
        v_N, v_E, v_D (m/s) at the end of each interval.
    quaternions : ndarray, shape (n, 4)
        q_bn at the end of each interval.
    """

    start: int
    increments: np.ndarray
    nav_increments: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    quaternions: np.ndarray


class TruthGenerator:
    """Streams the truth and the ideal IMU of a trajectory.

    Parameters
    ----------
    trajectory : object
        Any object with ``latitude``, ``longitude``, ``height`` (start, rad and m)
        and ``kinematics(t) -> (velocity_ned (n, 3), q_bn (n, 4))``
        (:mod:`schuler.navigate.trajectory`).
    duration : float
        s; a whole number of IMU intervals.
    imu_rate : float
        Hz.
    earth_rate : float
        Omega, rad/s (0 for a non-rotating Earth).
    """

    def __init__(self, trajectory, duration: float, imu_rate: float, earth_rate: float = EARTH_RATE):
        if not (np.isfinite(earth_rate) and 0.0 <= earth_rate < 1e-3):
            raise InvalidParameter("earth_rate", f"must lie in [0, 1e-3) rad/s, got {earth_rate!r}")
        self.trajectory = trajectory
        self.n_samples = sample_count(duration, imu_rate)
        self.dt = 1.0 / imu_rate
        self.earth_rate = float(earth_rate)
        velocity, quaternion = trajectory.kinematics(np.array([0.0]))
        self.initial_velocity = velocity[0].copy()
        self.initial_quaternion = quaternion[0].copy()
        self.initial_position = np.array([trajectory.latitude, trajectory.longitude, trajectory.height], float)

    def initial_state(self) -> np.ndarray:
        """The truth's navigation state at t = 0 (no previous increments, no extrapolation)."""
        state = np.zeros(_kernels.STATE_SIZE)
        state[_kernels.LAT:_kernels.HGT + 1] = self.initial_position
        state[_kernels.SIN_LAT] = np.sin(self.initial_position[0])
        state[_kernels.COS_LAT] = np.cos(self.initial_position[0])
        state[_kernels.VEL:_kernels.VEL + 3] = self.initial_velocity
        state[_kernels.VEL_PREV:_kernels.VEL_PREV + 3] = self.initial_velocity
        state[_kernels.QUAT:_kernels.QUAT + 4] = self.initial_quaternion
        return state

    def chunks(self, chunk_size: int = DEFAULT_CHUNK) -> Iterator[TruthChunk]:
        """Consecutive blocks of at most ``chunk_size`` intervals covering the whole duration.

        Parameters
        ----------
        chunk_size : int
            Largest number of IMU intervals per block (>= 1): it bounds the memory held at once.

        Returns
        -------
        Iterator of TruthChunk
            The truth and ideal increments of each block in turn, SI.

        Raises
        ------
        InvalidParameter
            ``chunk_size`` is not a whole number >= 1 (checked at the call, before any block is made).
        """
        if isinstance(chunk_size, bool) or not isinstance(chunk_size, int | np.integer) or chunk_size < 1:
            raise InvalidParameter("chunk_size", f"must be a whole number of IMU intervals >= 1, got {chunk_size!r}")
        return self._blocks(int(chunk_size))

    def _blocks(self, chunk_size: int) -> Iterator[TruthChunk]:
        state = self.initial_state()
        for start in range(0, self.n_samples, chunk_size):
            stop = min(start + chunk_size, self.n_samples)
            times = np.arange(start, stop + 1) * self.dt
            velocities, quaternions = self.trajectory.kinematics(times)
            n = stop - start
            increments = np.empty((n, 6))
            nav_increments = np.empty((n, 6))
            positions = np.empty((n, 3))
            _kernels.inverse_steps(self.dt, np.ascontiguousarray(quaternions), np.ascontiguousarray(velocities),
                                   state, increments, positions, nav_increments, self.earth_rate)
            if np.any(np.abs(positions[:, 0]) > np.radians(89.0)):
                raise InvalidParameter("trajectory", "the path comes within 1 deg of a pole, where NED is singular")
            yield TruthChunk(start, increments, nav_increments, positions, velocities[1:], quaternions[1:])


@dataclass
class IdealImu(Result):
    """Truth and ideal IMU of a trajectory at every IMU sample.

    Rates are the increments divided by the interval: the mean angular rate
    and specific force over each interval (the IMU a rate-output sensor would
    give at the interval's middle). Row k belongs to the interval ending at
    ``t_s[k]``; the truth arrays are the values at ``t_s[k]``.
    """

    interval_s: float
    t_s: np.ndarray
    angle_increment_rad: np.ndarray
    velocity_increment_m_s: np.ndarray
    latitude_rad: np.ndarray
    longitude_rad: np.ndarray
    height_m: np.ndarray
    velocity_ned_m_s: np.ndarray
    quaternion: np.ndarray = field(repr=False)

    units: ClassVar[dict[str, str]] = {"quaternion": "q_bn, scalar first"}

    @property
    def angular_rate_rad_s(self) -> np.ndarray:
        """Mean angular rate over each interval, body axes, rad/s."""
        return self.angle_increment_rad / self.interval_s

    @property
    def specific_force_m_s2(self) -> np.ndarray:
        """Mean specific force over each interval, body axes, m/s^2."""
        return self.velocity_increment_m_s / self.interval_s


def ideal_imu(trajectory, duration: float, imu_rate: float = 100.0, earth_rate: float = EARTH_RATE) -> IdealImu:
    """The ideal IMU and the truth of a trajectory at every sample (held in memory: for short runs).

    Parameters
    ----------
    trajectory : Stationary, GreatCircle or WaypointProfile
        A trajectory of :mod:`schuler.navigate.trajectory`.
    duration : float
        s, a whole number of IMU intervals.
    imu_rate : float
        Hz.
    earth_rate : float
        rad/s.

    Returns
    -------
    IdealImu
    """
    generator = TruthGenerator(trajectory, duration, imu_rate, earth_rate)
    if generator.n_samples > 5_000_000:
        raise InvalidParameter("duration", f"{generator.n_samples} samples are too many to hold; "
                                           "navigate() streams them instead")
    parts = list(generator.chunks())
    stack = np.concatenate
    positions = stack([p.positions for p in parts])
    increments = stack([p.increments for p in parts])
    return IdealImu(
        interval_s=generator.dt,
        t_s=np.arange(1, generator.n_samples + 1) * generator.dt,
        angle_increment_rad=increments[:, :3],
        velocity_increment_m_s=increments[:, 3:],
        latitude_rad=positions[:, 0],
        longitude_rad=positions[:, 1],
        height_m=positions[:, 2],
        velocity_ned_m_s=stack([p.velocities for p in parts]),
        quaternion=stack([p.quaternions for p in parts]),
    )
