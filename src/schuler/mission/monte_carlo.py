"""Monte Carlo of the nonlinear INS over a mission, members drawn from the covariance analysis's sources.

Each member draws every constant source of :mod:`schuler.mission.setup` once
(normal, its 1-sigma) and the alignment's noise-limited residuals from the
covariance they leave (:func:`schuler.mission.stages.alignment_noise`); its
initial errors are the same linear map of its draws as in the covariance
analysis (:func:`schuler.mission.stages.initial_state_map`), turned into
roll, pitch and heading errors of the computed attitude
C_computed = exp(-[phi x]) C_true. Its sensors carry the drawn biases and
scale factors (:class:`schuler.navigate.errors.ConstantSensorErrors`) and white noise of
the error model's angle and velocity random walks per axis
(:class:`schuler.navigate.errors.WhiteNoise`, the IMU layer's white-noise streams).
The strapdown INS then runs along the trajectory
(:func:`schuler.navigate.mechanization.navigate`), batched over members.

A reduced IMU rate is allowed: the white noise enters as increments of
standard deviation N sqrt(dt), exact at any rate, and the smooth trajectories
need no high rate (the covariance analysis has none either).

Every draw is addressed by (seed, stream, member) (:mod:`schuler.core.random`):
the members do not depend on how a Monte Carlo is cut into chunks.
"""

from __future__ import annotations

import numpy as np

from schuler.core.attitude import (
    dcm_from_quaternion,
    euler_from_quaternion,
    quaternion_from_rotation_vector,
    quaternion_multiply,
    wrap_angle,
)
from schuler.core.earth import EARTH_RATE, radii_of_curvature
from schuler.core.random import RandomStreams
from schuler.mission.setup import CONSTANT_SOURCES, MissionSetup
from schuler.mission.stages import alignment_noise, initial_state_map
from schuler.navigate.errors import ConstantSensorErrors, InitialErrors, WhiteNoise
from schuler.navigate.mechanization import navigate
from schuler.navigate.results import NavigationResult

SCALE_FACTOR_LIMIT = 0.1
"""Largest scale-factor error a member flies with (the navigate layer's limit); larger draws are clipped."""


def member_draws(setup: MissionSetup, members, streams: RandomStreams, n_states: int,
                 start_rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each member's constant sources (N, n_sources, SI) and initial psi-model state (N, n_states).

    Parameters
    ----------
    setup : MissionSetup
        The mission: the 1-sigma of every source, SI.
    members : array_like of int
        Global member numbers, shape (N,).
    streams : RandomStreams
        The Monte Carlo's addressed random streams (``mission/<source>`` and ``mission/alignment/...``).
    n_states : int
        Number of states of the psi-angle model, 7 or 9.
    start_rotation : ndarray
        C_b^n at the start, shape (3, 3), plain numbers (direction cosines).

    Returns
    -------
    draws, x0 : ndarray
        Drawn values of :data:`~schuler.mission.setup.CONSTANT_SOURCES`, shape (N, n_sources), SI (rad/s,
        m/s^2, plain-number scale factors, rad, m); initial states, shape (N, n_states), m, m/s and rad
        (including the alignment's noise-limited residuals).
    """
    members = np.asarray(members, dtype=np.int64)
    unit = np.stack([streams.normal(f"mission/{name}", members) for name in CONSTANT_SOURCES], axis=1)
    draws = unit * setup.constant_sigmas
    x0 = draws @ (initial_state_map(setup, start_rotation, n_states))
    for name, covariance in alignment_noise(setup, start_rotation, n_states).items():
        values, vectors = np.linalg.eigh(covariance)
        factor = vectors * np.sqrt(np.clip(values, 0.0, None))
        noise = np.stack([streams.normal(f"mission/alignment/{name}/{i}", members) for i in range(n_states)], axis=1)
        x0 = x0 + noise @ factor.T
    return draws, x0


def initial_errors(x0: np.ndarray, setup: MissionSetup, start_quaternion: np.ndarray) -> InitialErrors:
    """The navigate layer's initial errors of psi-model states x0 (N, n) at rest (velocity error zero).

    Parameters
    ----------
    x0 : ndarray
        Psi-model states, shape (N, n): position errors north, east first (m), psi last three (rad, NED).
    setup : MissionSetup
        The mission: latitude (rad) and height (m) of the start.
    start_quaternion : ndarray
        True attitude q_bn at the start, shape (4,), plain numbers (unit quaternion, Hamilton, scalar first).

    Returns
    -------
    InitialErrors
        Position errors north and east (m) and roll, pitch, heading errors (rad) of the computed attitude,
        errors = computed - true.
    """
    L, h = setup.latitude, setup.height
    radius_north, radius_east = radii_of_curvature(L)
    north, east = x0[:, 0], x0[:, 1]
    delta_theta = np.stack([east / (radius_east + h), -north / (radius_north + h),
                            -east * np.tan(L) / (radius_east + h)], axis=1)
    phi = x0[:, -3:] + delta_theta
    computed = quaternion_multiply(quaternion_from_rotation_vector(-phi), start_quaternion)
    angles = euler_from_quaternion(computed) - euler_from_quaternion(start_quaternion)[None, :]
    return InitialErrors(position_error_north=north, position_error_east=east,
                         roll_error=wrap_angle(angles[:, 0]), pitch_error=angles[:, 1],
                         heading_error=wrap_angle(angles[:, 2]))


def run_members(setup: MissionSetup, members, streams: RandomStreams, imu_rate: float,
                output_step: float | None = None) -> NavigationResult:
    """The nonlinear INS of the given members (global numbers), batched: their error histories.

    Parameters
    ----------
    setup : MissionSetup
        The mission: trajectory, duration, vertical channel and the sources' sigmas, SI.
    members : array_like of int
        Global member numbers, shape (N,).
    streams : RandomStreams
        The Monte Carlo's addressed random streams.
    imu_rate : float
        IMU rate of the strapdown INS, Hz.
    output_step : float, optional
        Step of the error histories, s (not set: the mission's ``output_step``).

    Returns
    -------
    NavigationResult
        Each member's navigation errors along the trajectory, SI (computed - true).
    """
    members = np.asarray(members, dtype=np.int64)
    trajectory = setup.trajectory()
    start_quaternion = trajectory.kinematics(np.array([0.0]))[1][0]
    n = 9 if setup.vertical_channel == "free" else 7
    draws, x0 = member_draws(setup, members, streams, n, dcm_from_quaternion(start_quaternion))
    return navigate(trajectory, setup.duration, imu_rate=imu_rate, output_step=output_step or setup.output_step,
                    mode="strapdown", vertical_channel=setup.vertical_channel,
                    initial_errors=initial_errors(x0, setup, start_quaternion), sensor_errors=sensor_errors(draws),
                    noise=white_noise(setup, streams), member_ids=members,
                    earth_rate=EARTH_RATE)


def sensor_errors(draws: np.ndarray) -> ConstantSensorErrors:
    """The members' constant sensor errors from their draws of the constant sources.

    Parameters
    ----------
    draws : ndarray
        Drawn values of :data:`~schuler.mission.setup.CONSTANT_SOURCES`, shape (N, n_sources), SI (rad/s, m/s^2,
        plain-number scale factors).

    Returns
    -------
    ConstantSensorErrors
        Biases and scale factors per member, body axes; scale factors clipped to +/- :data:`SCALE_FACTOR_LIMIT`.
    """
    column = {name: i for i, name in enumerate(CONSTANT_SOURCES)}

    def triad(family: str) -> np.ndarray:
        values = np.stack([draws[:, column[f"{family}_{axis}"]] for axis in "xyz"], axis=1)
        if "scale_factor" in family:
            # the navigate layer accepts |S| <= 0.1: a consumer IMU's 3 % draws past it beyond 3.3 sigma
            values = np.clip(values, -SCALE_FACTOR_LIMIT, SCALE_FACTOR_LIMIT)
        return values

    return ConstantSensorErrors(gyro_bias=triad("gyro_bias"), accel_bias=triad("accel_bias"),
                                gyro_scale_factor=triad("gyro_scale_factor"),
                                accel_scale_factor=triad("accel_scale_factor"))


def white_noise(setup: MissionSetup, streams: RandomStreams) -> WhiteNoise | None:
    """The members' angle and velocity random walks (None when the instrument has none).

    Parameters
    ----------
    setup : MissionSetup
        The mission: N per body axis, rad/sqrt(s) and m/s/sqrt(s).
    streams : RandomStreams
        The Monte Carlo's addressed random streams (their seed keys the noise).

    Returns
    -------
    WhiteNoise or None
        The noise, addressed by (seed, sensor axis, member, IMU interval).
    """
    noisy = np.any(setup.gyro_random_walk) or np.any(setup.accel_random_walk)
    return WhiteNoise(setup.gyro_random_walk, setup.accel_random_walk, streams.seed) if noisy else None


def final_horizontal_errors(result: NavigationResult) -> np.ndarray:
    """Each member's final horizontal position error sqrt(north^2 + east^2), m.

    Parameters
    ----------
    result : NavigationResult
        The members' error histories (position errors north and east, m).

    Returns
    -------
    ndarray
        Shape (N,), m.
    """
    return np.hypot(np.atleast_2d(result.position_error_north_m)[:, -1],
                    np.atleast_2d(result.position_error_east_m)[:, -1])
