"""The truth of a trajectory at any times, and the odometer and barometer simulated from it.

:func:`truth_at` streams :class:`~schuler.navigate.truth.TruthGenerator` and gives the truth at sorted times in
[0, duration], not only at IMU samples: velocity and attitude come exactly from the trajectory's
``kinematics(t)`` (the truth's velocity and attitude at the samples are those values), the position by cubic
Hermite interpolation between the two neighbouring samples with the velocity as its derivative
(dL/dt = v_N / (R_N + h), dlambda/dt = v_E / ((R_E + h) cos L), dh/dt = -v_D). Its error is
dt^4 / 384 max|d^4 r / dt^4| plus the truth's own trapezoid rounding between samples (against the truth at
skipped samples of the drive: 1.2e-9 m with nodes at 100 Hz). The body's rate omega_nb^b comes from central
differences of the attitude (step :data:`RATE_STEP_S`, error step^2 |d^2 omega / dt^2| / 6, 3e-8 rad/s in the
drive's turns).

A point at the body lever arm l (m, x forward, y right, z down; spec 07) is at r + C_b^n l and moves at
v + C_b^n (omega_ib x l) - (omega_ie + omega_en) x C_b^n l = v + C_b^n (omega_nb x l). The NED offset
C_b^n l is mapped to latitude, longitude and height with R_N + h and (R_E + h) cos L, as the filter maps it;
that map is first order (its neglect is |l|^2 / (2 R), 8e-8 m for a 1-m arm), and the velocity is its exact
derivative (the Earth-referenced velocity of the point differs from it by omega_en x C_b^n l, below 5e-6 m/s
per metre of arm at 30 m/s).

Epochs are stamped time_offset + j / rate (:func:`epoch_schedule`); the noise of epoch j of a member is drawn
from :class:`~schuler.core.random.RandomStreams` at the address (seed, stream, member, j), so that a member's
draws depend on nothing else. ``streams=None`` gives noise-free data.

Default noises: odometer :data:`DEFAULT_ODOMETER_SIGMA_M_S`, barometer :data:`DEFAULT_BAROMETER_SIGMA_M`
(1-sigma per epoch); the odometer's scale error and the barometer's bias are given constants, default 0.

Examples
--------
>>> from schuler.navigate.trajectory import GreatCircle
>>> path = GreatCircle(latitude=0.5, longitude=0.0, height=0.0, heading=0.0, speed=10.0, duration=2.0)
>>> truth = truth_at(path, 2.0, [0.55, 1.25], imu_rate=10.0)
>>> [round(float(v), 9) for v in truth.velocity_ned_m_s[:, 0]]
[10.0, 10.0]
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.core.attitude import conjugate, dcm_from_quaternion, quaternion_multiply, rotation_vector_from_quaternion
from schuler.core.earth import EARTH_RATE, radii_of_curvature
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.navigate.truth import DEFAULT_CHUNK, TruthGenerator

DEFAULT_ODOMETER_SIGMA_M_S = 0.05
"""Default 1-sigma of the simulated odometer's white noise per epoch, m/s."""

DEFAULT_BAROMETER_SIGMA_M = 0.5
"""Default 1-sigma of the simulated barometer's white noise per epoch, m."""

LARGEST_LEVER_ARM_M = 30.0
"""Largest lever arm accepted, m: a longer one is most likely in cm or mm."""

RATE_STEP_S = 1e-3
"""Step of the central differences giving omega_nb^b from the trajectory's attitude, s."""


def vector3(value, name: str) -> np.ndarray:
    """Three finite numbers as an array, or a one-line error naming ``name``.

    Parameters
    ----------
    value : array_like
        Three numbers, any unit (returned as given).
    name : str
        The input's name in the message.

    Returns
    -------
    ndarray, shape (3,)
        The numbers, as given.
    """
    array = np.asarray(value, dtype=float).reshape(-1)
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        raise InvalidParameter(name, f"must be three finite numbers, got {value!r}")
    return array


def positive(value, name: str) -> float:
    """A finite number > 0, or a one-line error naming ``name``.

    Parameters
    ----------
    value : float
        The number, any unit (returned as given).
    name : str
        The input's name in the message.

    Returns
    -------
    float
        The number, as given.
    """
    number = float(value)
    if not (math.isfinite(number) and number > 0):
        raise InvalidParameter(name, f"must be finite and > 0, got {value!r}")
    return number


def draws(streams: RandomStreams, stream: str, member: int, index: np.ndarray) -> np.ndarray:
    """Standard normals of one member at epoch indices (a window of its addressed series), shape (n,).

    Parameters
    ----------
    streams : RandomStreams
        The study's random numbers.
    stream : str
        Stream name.
    member : int
        Member number, index >= 0.
    index : ndarray of int, shape (n,)
        Epoch indices, increasing.

    Returns
    -------
    ndarray
        Standard normal numbers, dimensionless.
    """
    if isinstance(member, bool) or not isinstance(member, int | np.integer) or member < 0:
        raise InvalidParameter("member", f"must be a whole number >= 0, got {member!r}")
    series = streams.normal_series(stream, [member], int(index[0]), int(index[-1]) + 1)[0]
    return series[index - index[0]]


@dataclass(frozen=True, eq=False)
class EpochTruth:
    """The truth of a trajectory at given times (IMU position, velocity, attitude and body rate).

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Times since the start, s.
    latitude_rad, longitude_rad, height_m : ndarray, shape (n,)
        IMU position, rad and m.
    velocity_ned_m_s : ndarray, shape (n, 3)
        Ground velocity, m/s.
    quaternion : ndarray, shape (n, 4)
        Attitude q_bn.
    body_rate_rad_s : ndarray, shape (n, 3)
        omega_nb^b, the body's rate relative to NED in body axes, rad/s.
    """

    t_s: np.ndarray
    latitude_rad: np.ndarray
    longitude_rad: np.ndarray
    height_m: np.ndarray
    velocity_ned_m_s: np.ndarray
    quaternion: np.ndarray
    body_rate_rad_s: np.ndarray

    def at_lever_arm(self, lever_arm_m) -> tuple[np.ndarray, np.ndarray]:
        """Position (lat rad, lon rad, h m; shape (n, 3)) and NED velocity (m/s, (n, 3)) of a point at a lever arm.

        Parameters
        ----------
        lever_arm_m : array_like, shape (3,)
            The point in body axes from the IMU, m (x forward, y right, z down).

        Returns
        -------
        position, velocity : ndarray
            Latitude, longitude (rad), height (m), shape (n, 3); v_N, v_E, v_D (m/s), shape (n, 3).
        """
        arm = vector3(lever_arm_m, "lever_arm")
        if np.linalg.norm(arm) > LARGEST_LEVER_ARM_M:
            raise InvalidParameter("lever_arm", f"{arm.tolist()} is longer than {LARGEST_LEVER_ARM_M:g} m: metres "
                                                "are expected (is it in cm or mm?)")
        C = dcm_from_quaternion(self.quaternion)
        offset = C @ arm
        velocity = self.velocity_ned_m_s + np.einsum("nij,nj->ni", C, np.cross(self.body_rate_rad_s, arm))
        return offset_position(self.latitude_rad, self.longitude_rad, self.height_m, offset), velocity


def offset_position(latitude, longitude, height, offset_ned) -> np.ndarray:
    """Latitude, longitude, height moved by small NED offsets, first order (the filter's own map), shape (n, 3).

    Parameters
    ----------
    latitude, longitude : ndarray, shape (n,)
        rad.
    height : ndarray, shape (n,)
        m.
    offset_ned : ndarray, shape (n, 3)
        North, east, down offsets, m.

    Returns
    -------
    ndarray, shape (n, 3)
        Latitude, longitude (rad), height (m).
    """
    R_N, R_E = radii_of_curvature(latitude)
    return np.stack([latitude + offset_ned[:, 0] / (R_N + height),
                     longitude + offset_ned[:, 1] / ((R_E + height) * np.cos(latitude)),
                     height - offset_ned[:, 2]], axis=1)


def _position_rates(position: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """dL/dt, dlambda/dt, dh/dt from positions (n, 3) and NED velocities (n, 3)."""
    L, h = position[:, 0], position[:, 2]
    R_N, R_E = radii_of_curvature(L)
    return np.stack([velocity[:, 0] / (R_N + h), velocity[:, 1] / ((R_E + h) * np.cos(L)), -velocity[:, 2]], axis=1)


def interpolate_positions(t_nodes, positions, velocities, t) -> np.ndarray:
    """Cubic Hermite interpolation of positions between nodes, the velocity giving the derivative.

    Parameters
    ----------
    t_nodes : array_like, shape (m,)
        Node times, s, strictly increasing.
    positions : array_like, shape (m, 3)
        Latitude, longitude (rad), height (m) at the nodes.
    velocities : array_like, shape (m, 3)
        v_N, v_E, v_D at the nodes, m/s.
    t : array_like, shape (n,)
        Times within [t_nodes[0], t_nodes[-1]], s.

    Returns
    -------
    ndarray, shape (n, 3)
        Latitude, longitude (rad), height (m) at ``t``.
    """
    nodes = np.asarray(t_nodes, dtype=float)
    p = np.asarray(positions, dtype=float)
    t = np.asarray(t, dtype=float)
    if t.size and (t.min() < nodes[0] or t.max() > nodes[-1]):
        raise InvalidParameter("t", f"times must lie within [{nodes[0]:g}, {nodes[-1]:g}] s")
    slopes = _position_rates(p, np.asarray(velocities, dtype=float))
    k = np.clip(np.searchsorted(nodes, t, side="right") - 1, 0, nodes.size - 2)
    span = (nodes[k + 1] - nodes[k])[:, None]
    u = ((t - nodes[k]) / span[:, 0])[:, None]
    u2, u3 = u * u, u * u * u
    return ((2 * u3 - 3 * u2 + 1) * p[k] + (u3 - 2 * u2 + u) * span * slopes[k]
            + (3 * u2 - 2 * u3) * p[k + 1] + (u3 - u2) * span * slopes[k + 1])


def body_rate(trajectory, t) -> np.ndarray:
    """omega_nb^b of a trajectory at times t by central differences of its attitude, rad/s, shape (n, 3).

    Parameters
    ----------
    trajectory : Trajectory
        An object with ``kinematics(t) -> (velocity (n, 3), q_bn (n, 4))``.
    t : array_like, shape (n,)
        Times, s.

    Returns
    -------
    ndarray, shape (n, 3)
        rad/s, body axes.
    """
    t = np.asarray(t, dtype=float)
    _, before = trajectory.kinematics(t - RATE_STEP_S)
    _, after = trajectory.kinematics(t + RATE_STEP_S)
    return rotation_vector_from_quaternion(quaternion_multiply(conjugate(before), after)) / (2.0 * RATE_STEP_S)


def truth_at(trajectory, duration: float, t, *, imu_rate: float = 100.0, earth_rate: float = EARTH_RATE,
             chunk_size: int = DEFAULT_CHUNK) -> EpochTruth:
    """The truth of a trajectory at sorted times in [0, duration], streamed from its IMU-rate truth.

    Parameters
    ----------
    trajectory : Trajectory
        A trajectory of :mod:`schuler.navigate.trajectory` (or :func:`schuler.navigate.drive.drive`).
    duration : float
        s, a whole number of IMU intervals.
    t : array_like, shape (n,)
        Times since the start, s, non-decreasing, within [0, duration].
    imu_rate : float
        Rate of the truth's samples, Hz (the IMU's).
    earth_rate : float
        Omega, rad/s.
    chunk_size : int
        IMU samples per streamed block, number of.

    Returns
    -------
    EpochTruth
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    if t.size and (np.any(np.diff(t) < 0) or t[0] < 0 or t[-1] > duration * (1 + 1e-12)):
        raise InvalidParameter("t", f"times must be sorted within [0, {duration:g}] s")
    generator = TruthGenerator(trajectory, duration, imu_rate, earth_rate)
    positions = np.empty((t.size, 3))
    node_t, node_p, node_v = 0.0, generator.initial_position, generator.initial_velocity
    done = 0
    for chunk in generator.chunks(chunk_size):
        if done == t.size:
            break
        times = np.concatenate([[node_t], (chunk.start + 1 + np.arange(chunk.positions.shape[0])) * generator.dt])
        stop = done + int(np.searchsorted(t[done:], times[-1], side="right"))
        if stop > done:
            positions[done:stop] = interpolate_positions(times, np.vstack([node_p, chunk.positions]),
                                                         np.vstack([node_v, chunk.velocities]),
                                                         np.clip(t[done:stop], times[0], times[-1]))
        done = stop
        node_t, node_p, node_v = times[-1], chunk.positions[-1], chunk.velocities[-1]
    positions[done:] = node_p  # times past the last sample by rounding only (within 1e-12 of the duration)
    velocity, quaternion = trajectory.kinematics(t)
    return EpochTruth(t, positions[:, 0], positions[:, 1], positions[:, 2], velocity, quaternion,
                      body_rate(trajectory, t))


def epoch_schedule(rate_hz: float, duration: float, *, latency: float = 0.0,
                   time_offset: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Epoch indices j and stamps time_offset + j / rate in (0, duration] whose true time stamp - latency >= 0.

    Parameters
    ----------
    rate_hz : float
        Epoch rate, Hz (> 0).
    duration : float
        Length of the data, s.
    latency : float
        Stamp delay, s (>= 0).
    time_offset : float
        Stamp of epoch 0, s, in [0, 1 / rate): epochs need not fall on IMU samples.

    Returns
    -------
    index, stamps : ndarray
        Epoch indices (the addresses of their random draws), number of; stamps, s.
    """
    rate = positive(rate_hz, "rate")
    if not (math.isfinite(latency) and 0.0 <= latency <= 10.0):
        raise InvalidParameter("latency", f"must lie in [0, 10] s, got {latency!r}")
    if not (math.isfinite(time_offset) and 0.0 <= time_offset < 1.0 / rate):
        raise InvalidParameter("time_offset", f"must lie in [0, {1.0 / rate:g}) s, got {time_offset!r}")
    index = np.arange(math.floor((duration - time_offset) * rate * (1 + 1e-12)) + 1)
    stamps = time_offset + index / rate
    keep = (stamps > 0) & (stamps - latency >= 0) & (stamps <= duration * (1 + 1e-12))
    return index[keep], stamps[keep]




@dataclass(frozen=True, eq=False)
class OdometerRecord:
    """Odometer epochs: the forward speed of the wheel point.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Epoch times, s.
    speed_m_s : ndarray, shape (n,)
        Measured forward speed, m/s.
    sigma_m_s : float
        1-sigma of the white noise, m/s.
    """

    t_s: np.ndarray
    speed_m_s: np.ndarray
    sigma_m_s: float


@dataclass(frozen=True, eq=False)
class BarometerRecord:
    """Barometric heights.

    Attributes
    ----------
    t_s : ndarray, shape (n,)
        Epoch times, s.
    height_m : ndarray, shape (n,)
        Measured height, m.
    sigma_m : float
        1-sigma of the white noise, m.
    """

    t_s: np.ndarray
    height_m: np.ndarray
    sigma_m: float


def _noise(streams: RandomStreams | None, stream: str, member: int, index: np.ndarray, sigma: float) -> np.ndarray:
    if streams is None or not index.size:
        return np.zeros(index.size)
    return draws(streams, stream, member, index) * sigma


def simulate_odometer(trajectory, duration: float, *, imu_rate: float = 100.0, rate: float = 10.0,
                      lever_arm=(0.0, 0.0, 0.0), scale_factor_error: float = 0.0,
                      sigma: float = DEFAULT_ODOMETER_SIGMA_M_S, streams: RandomStreams | None = None,
                      member: int = 0, earth_rate: float = EARTH_RATE) -> OdometerRecord:
    """Simulated odometer: (1 + scale error) times the wheel point's forward speed, plus white noise.

    The wheel point's velocity in body axes is C_n^b v + omega_nb^b x l_odo (spec 07; the vehicle frame is the
    body frame: no mounting angles); its x component is the speed measured.

    Parameters
    ----------
    trajectory : Trajectory
        A trajectory of :mod:`schuler.navigate.trajectory`.
    duration : float
        s.
    imu_rate : float
        Rate of the truth's samples, Hz.
    rate : float
        Odometer epoch rate, Hz.
    lever_arm : array_like, shape (3,)
        Wheel contact point from the IMU in body axes, m.
    scale_factor_error : float
        Constant relative scale error (measured - true) / true, dimensionless.
    sigma : float
        1-sigma of the white noise per epoch, m/s (>= 0).
    streams : RandomStreams, optional
        None: no noise.
    member : int
        Member number, index.
    earth_rate : float
        Omega, rad/s.

    Returns
    -------
    OdometerRecord
    """
    if not (math.isfinite(sigma) and sigma >= 0) or not (math.isfinite(scale_factor_error)
                                                         and abs(scale_factor_error) < 0.5):
        raise InvalidParameter("odometer", f"sigma {sigma!r} must be >= 0 and the scale error within +/-0.5")
    index, stamps = epoch_schedule(rate, duration)
    truth = truth_at(trajectory, duration, stamps, imu_rate=imu_rate, earth_rate=earth_rate)
    arm = vector3(lever_arm, "lever_arm")
    C = dcm_from_quaternion(truth.quaternion)
    body_velocity = np.einsum("nji,nj->ni", C, truth.velocity_ned_m_s) + np.cross(truth.body_rate_rad_s, arm)
    speed = (1.0 + scale_factor_error) * body_velocity[:, 0] + _noise(streams, "odometer", member, index, sigma)
    return OdometerRecord(stamps, speed, float(sigma))


def simulate_barometer(trajectory, duration: float, *, imu_rate: float = 100.0, rate: float = 1.0,
                       bias: float = 0.0, sigma: float = DEFAULT_BAROMETER_SIGMA_M,
                       streams: RandomStreams | None = None, member: int = 0,
                       earth_rate: float = EARTH_RATE) -> BarometerRecord:
    """Simulated barometric height: the IMU's true height plus a constant bias and white noise.

    Parameters
    ----------
    trajectory : Trajectory
        A trajectory of :mod:`schuler.navigate.trajectory`.
    duration : float
        s.
    imu_rate : float
        Rate of the truth's samples, Hz.
    rate : float
        Barometer epoch rate, Hz.
    bias : float
        Constant height error (measured - true), m.
    sigma : float
        1-sigma of the white noise per epoch, m (>= 0).
    streams : RandomStreams, optional
        None: no noise.
    member : int
        Member number, index.
    earth_rate : float
        Omega, rad/s.

    Returns
    -------
    BarometerRecord
    """
    if not (math.isfinite(sigma) and sigma >= 0) or not (math.isfinite(bias) and abs(bias) <= 1e4):
        raise InvalidParameter("barometer", f"sigma {sigma!r} must be >= 0 and the bias within 10 km")
    index, stamps = epoch_schedule(rate, duration)
    truth = truth_at(trajectory, duration, stamps, imu_rate=imu_rate, earth_rate=earth_rate)
    height = truth.height_m + bias + _noise(streams, "barometer", member, index, sigma)
    return BarometerRecord(stamps, height, float(sigma))
