"""Monte Carlo of an aided mission: ``schuler aided``'s filter on the nonlinear INS, members drawn from the sources.

Each member draws the mission's sources as :mod:`schuler.mission.monte_carlo`
does (:func:`~schuler.mission.monte_carlo.member_draws`: the constant sources
and the alignment's noise-limited residuals, addressed by (seed, stream,
member)). Its IMU measures the trajectory's ideal increments
(:func:`schuler.navigate.truth.ideal_imu`) through its drawn errors,

    dtheta = (I + S_g) dtheta_true + b_g dt + n_g,   dv = (I + S_a) dv_true + b_a dt + n_a,

n the angle and velocity random walks' increments
(:class:`~schuler.navigate.errors.WhiteNoise`); its GNSS fixes are
``schuler aided``'s (:func:`schuler.aided.gnss.gnss_measurements`: the antenna's
truth at the lever arm, white noise at the address (seed, ``gnss/...``,
member, epoch), the outages removed). It starts where its alignment left it
(position and attitude errors of its draws, velocity error zero) and runs
:func:`schuler.aided.ekf.run_filter` with the filter model of the covariance
analysis (:func:`schuler.mission.aiding.filter_model`) and its initial
1-sigma, batched over the members, on the drive with the zero-velocity updates
at its stops and its odometer and constraint as ``schuler aided``'s sources
(:func:`schuler.mission.aiding_measurements.filter_sources`: the epochs of the
covariance analysis, each member's odometer noise at the address (seed,
``odometer``, member, epoch)); the errors and each outage's drift are
``schuler aided``'s (:func:`schuler.aided.analysis.errors`,
:func:`schuler.aided.analysis.outage_drift`).
"""

from __future__ import annotations

import numpy as np

from schuler.aided import analysis
from schuler.aided.ekf import Start, run_filter
from schuler.aided.gnss import gnss_measurements, gnss_truth
from schuler.core.attitude import dcm_from_quaternion, quaternion_from_rotation_vector, quaternion_multiply
from schuler.core.earth import EARTH_RATE, radii_of_curvature
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.mission.aiding import attitude_from_psi, filter_model
from schuler.mission.aiding_measurements import filter_sources
from schuler.mission.monte_carlo import member_draws, sensor_errors, white_noise
from schuler.mission.setup import MissionSetup
from schuler.navigate.truth import ideal_imu

OUTAGE_SLOTS = 6
"""Outages whose drift a Monte Carlo reports per member (the first ones of a case)."""


def _increments(setup: MissionSetup, truth, draws: np.ndarray, members: np.ndarray,
                streams: RandomStreams) -> np.ndarray:
    """Each member's measured increments, shape (N, n, 6): dtheta (rad) then dv (m/s), body axes."""
    sensors = sensor_errors(draws)
    dt = truth.interval_s
    out = np.empty((members.size, truth.t_s.size, 6))
    for columns, ideal, name in ((slice(0, 3), truth.angle_increment_rad, "gyro"),
                                 (slice(3, 6), truth.velocity_increment_m_s, "accel")):
        rows = sensors.rows(name, members.size)
        matrix, bias = rows[:, :9].reshape(-1, 3, 3), rows[:, 9:]
        out[..., columns] = np.einsum("mij,kj->mki", matrix, ideal) + bias[:, None, :] * dt
    noise = white_noise(setup, streams)
    if noise is not None:
        gyro, accel = noise.increments(members, 0, truth.t_s.size, dt)
        out[..., :3] += gyro
        out[..., 3:] += accel
    return out


def aided_members(setup: MissionSetup, members, streams: RandomStreams, imu_rate: float, start_sigma: np.ndarray):
    """The members' filter runs through the aided mission (module docstring), with their errors.

    Parameters
    ----------
    setup : MissionSetup
        The mission, SI, with its aiding.
    members : array_like of int
        Global member numbers, shape (N,).
    streams : RandomStreams
        The Monte Carlo's addressed random streams.
    imu_rate : float
        IMU rate of the strapdown INS, Hz (the covariance interval a whole number of its intervals).
    start_sigma : ndarray
        The filter's initial 1-sigma of its 21 states (the covariance analysis's
        :attr:`~schuler.mission.aiding.AidedBudget.start_sigma`), the states' units.

    Returns
    -------
    run : FilterRun
        The members' filter runs, solutions at every covariance step.
    errors : analysis.Errors
        Their errors against the truth (computed - true), SI.
    """
    aiding = setup.aiding
    if aiding is None:
        raise InvalidParameter("aiding", "the mission has no aiding: use schuler.mission.monte_carlo")
    members = np.asarray(members, dtype=np.int64)
    every = aiding.covariance_interval * imu_rate
    if abs(every - round(every)) > 1e-9 or round(every) < 1:
        raise InvalidParameter("imu_rate", f"the covariance interval {aiding.covariance_interval:g} s must be a whole "
                                           f"number of IMU intervals of {1.0 / imu_rate:g} s")
    trajectory = setup.trajectory()
    truth = ideal_imu(trajectory, setup.duration, imu_rate, EARTH_RATE)
    q0 = trajectory.kinematics(np.array([0.0]))[1][0]
    draws, x0 = member_draws(setup, members, streams, 9, dcm_from_quaternion(q0))
    increments = _increments(setup, truth, draws, members, streams)
    L, h = setup.latitude, setup.height
    radius_north, radius_east = radii_of_curvature(L)
    phi = attitude_from_psi(x0, L, h)
    quaternion = quaternion_multiply(quaternion_from_rotation_vector(-phi), q0)  # C_hat = exp(-[phi x]) C
    velocity = trajectory.kinematics(np.array([0.0]))[0]
    ones = np.ones(members.size)
    start = Start(L + x0[:, 0] / (radius_north + h), setup.longitude + x0[:, 1] / ((radius_east + h) * np.cos(L)),
                  h * ones, np.repeat(velocity, members.size, 0), quaternion, start_sigma[0:3], start_sigma[3:6],
                  start_sigma[6:9])
    antenna = gnss_truth(trajectory, setup.duration, imu_rate=imu_rate, gnss_rate=aiding.gnss_rate,
                         lever_arm=aiding.lever_arm, earth_rate=EARTH_RATE)
    gnss = [gnss_measurements(antenna, position_sigma=aiding.position_sigma,
                              velocity_sigma=aiding.velocity_sigma if aiding.use_velocity else None, streams=streams,
                              member=int(m), outages=aiding.outages) for m in members]
    model = filter_model(setup)
    run = run_filter(increments, truth.interval_s, start, model, gnss, lever_arm=aiding.lever_arm,
                     covariance_interval=aiding.covariance_interval, use_velocity=aiding.use_velocity,
                     output_every=int(round(every)), initial_sensor_sigma=start_sigma[9:], earth_rate=EARTH_RATE,
                     sources=filter_sources(setup, model, members, streams, imu_rate))
    rows = np.searchsorted(truth.t_s, run.t_s - 1e-9)
    true = analysis.Truth(truth.latitude_rad[rows], truth.longitude_rad[rows], truth.height_m[rows],
                          truth.velocity_ned_m_s[rows], truth.quaternion[rows])
    return run, analysis.errors(run, true)


def member_outputs(run, errors, outages) -> dict[str, np.ndarray]:
    """Each member's final horizontal error and its drift in each of the first :data:`OUTAGE_SLOTS` outages, m.

    Parameters
    ----------
    run : FilterRun
        The members' filter runs.
    errors : analysis.Errors
        Their errors against the truth, m.
    outages : sequence of (float, float)
        The outages, (start, duration), s.

    Returns
    -------
    dict of str to ndarray
        ``member_position_error_m`` and ``member_outage_<k>_horizontal_error_end_m|max_m`` (k from 1), shape (N,),
        m (0 for an outage the case does not have).
    """
    count = run.solution.shape[0]
    out = {"member_position_error_m": errors.horizontal[:, -1]}
    for k in range(1, OUTAGE_SLOTS + 1):
        for kind in ("end", "max"):
            out[f"member_outage_{k}_horizontal_error_{kind}_m"] = np.zeros(count)
    for m in range(count):
        drifts = analysis.outage_drift(analysis.member(run, m), analysis.member(errors, m), outages[:OUTAGE_SLOTS])
        for k, drift in enumerate(drifts, start=1):
            out[f"member_outage_{k}_horizontal_error_end_m"][m] = drift.horizontal_error_end_m
            out[f"member_outage_{k}_horizontal_error_max_m"][m] = drift.horizontal_error_max_m
    return out
