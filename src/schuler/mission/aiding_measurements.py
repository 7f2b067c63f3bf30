"""The measurements of an aided mission: their epochs on the covariance grid, their H and R, the filter's sources.

Each measurement is ``schuler aided``'s, its residual delta_z = h(x_hat) - z = H delta_x + v and its H those of
:mod:`schuler.aided.measurements` (spec 07, "Measurements"; errors computed - true, psi-angle attitude):

* GNSS position of the antenna at the lever arm l, at j / ``gnss_rate`` outside the outages:
  delta_z = delta_r + [(C_b^n l) x] psi, R = diag(sigma_N^2, sigma_E^2, sigma_D^2) (source
  ``gnss_position_noise``); with ``gnss-velocity`` its velocity too,
  delta_z = delta_v + [(C_b^n (omega_ib x l)) x] psi - C_b^n [l x] (b_g + diag(omega_ib) s_g),
  R = sigma_v^2 I (``gnss_velocity_noise``);
* ``zupt``: zero velocity at k / ``zupt_rate`` inside the drive's stops (start < t <= end,
  :func:`schuler.aided.sources.stop_epochs` of
  :meth:`~schuler.navigate.drive.GroundVehicleProfile.stationary_intervals`): delta_z = delta_v,
  H = [0 I 0 ...], R = sigma_zupt^2 I (``zupt_noise``);
* ``odometer`` and ``nhc``: the wheel point at l_odo moves at v^v = C_b^v (C_n^b v + omega_nb^b x l_odo), C_b^v = I
  (the drive's IMU is aligned with the vehicle), at j / ``odometer_rate``
  (:func:`schuler.aided.epochs.epoch_schedule`, the odometer's own epochs);
  delta_z = C_n^b delta_v - C_n^b [v x] psi - [l_odo x] (b_g + diag(omega_ib) s_g), the odometer's row x
  (R = sigma_odo^2, ``odometer_noise``; the filter has no odometer scale state and the simulated odometer no
  scale error) and the constraint's rows y and z (R = sigma_nhc^2 I, ``nhc_noise``).

H is evaluated on the error-free solution, the truth: position from the covariance step's means, velocity and
attitude at the epoch, the body rate the mean of the step that ends there
(:mod:`schuler.mission.coefficients`). Every epoch falls on the covariance grid of step Delta: each
measurement's interval 1 / rate is a whole number of steps (refused otherwise, named by its rate). At a step
the measurements due are one stacked update, as :func:`schuler.aided.ekf.run_filter` stacks the sources of
one epoch: z_k = H_k delta_x + v_k with H_k the blocks' rows one under the other and
R_k = blockdiag(R_b), each block's R_b the noise of one independent source.

The Monte Carlo gives :func:`~schuler.aided.ekf.run_filter` the same measurements as sources
(:func:`filter_sources`): :func:`schuler.aided.sources.zero_velocity_source` at the same epochs, and
:func:`schuler.aided.sources.vehicle_source` on each member's odometer
(:func:`schuler.aided.epochs.simulate_odometer`). Every measurement carries the white noise of its source: the
odometer's in its speed, and, since the drive's truth is exactly at rest at a stop and without lateral or
vertical wheel velocity, the velocity at a stop and the wheel's as noise on what the zero-velocity update and
the constraint measure, delta_z = h(x_hat) - (z + v). Each draw is addressed by (seed, stream, member, epoch)
(streams ``odometer``, ``zupt/<axis>``, ``nhc/<row>``), so that a member's data do not depend on how the members
are chunked.

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
Artech House, 2013, Sec. 14.2.3 (lever arms), Sec. 15.3.2 (zero-velocity updates), Sec. 16.2 (odometer,
non-holonomic constraint).
E.-H. Shin, *Estimation Techniques for Low-Cost Inertial Navigation*, PhD thesis, University of Calgary, 2005,
Sec. 4.3 (non-holonomic constraints).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from schuler.aided import measurements, sources
from schuler.aided.epochs import draws, epoch_schedule, simulate_odometer
from schuler.aided.error_state import FilterModel
from schuler.aided.gnss import in_outages
from schuler.core.attitude import dcm_from_quaternion
from schuler.core.earth import EARTH_RATE
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.mission.coefficients import StepCoefficients
from schuler.mission.setup import Aiding, MissionSetup


@dataclass(frozen=True)
class MeasurementBlock:
    """One measurement's rows at its epochs on the covariance grid, and the noise source it adds.

    Attributes
    ----------
    source : str
        Its noise's name in the budget (``gnss_position_noise``, ``gnss_velocity_noise``, ``zupt_noise``,
        ``odometer_noise``, ``nhc_noise``).
    steps : ndarray of int, shape (k,)
        The covariance step (1 to K) at whose end each epoch falls.
    H : ndarray, shape (k, m, n)
        The block's rows of H at each epoch, measurement units per state unit.
    R : ndarray, shape (m, m)
        Its noise covariance, measurement units squared.
    """

    source: str
    steps: np.ndarray
    H: np.ndarray
    R: np.ndarray


def grid_interval(rate: float, step: float, name: str) -> int:
    """The covariance steps in one interval 1 / rate of a measurement, refused unless a whole number (>= 1).

    Parameters
    ----------
    rate : float
        The measurement's rate, Hz.
    step : float
        Covariance step Delta, s.
    name : str
        The rate's parameter, which a refusal names.

    Returns
    -------
    int
        1 / (rate Delta), number of steps.
    """
    per_epoch = 1.0 / (rate * step)
    if abs(per_epoch - round(per_epoch)) > 1e-9 or round(per_epoch) < 1:
        raise InvalidParameter(name, f"its interval {1.0 / rate:g} s must be a whole number of covariance steps of "
                                     f"{step:g} s (every epoch on the covariance grid)")
    return int(round(per_epoch))


def zupt_epochs(setup: MissionSetup) -> np.ndarray:
    """The zero-velocity updates' times: k / ``zupt_rate`` inside the drive's stops, s (on the covariance grid).

    Parameters
    ----------
    setup : MissionSetup
        An aided mission on the drive.
    """
    aiding = _aiding(setup)
    grid_interval(aiding.zupt_rate, aiding.covariance_interval, "zupt_rate")
    stops = [(start, min(end, setup.duration)) for start, end in setup.trajectory().stationary_intervals()]
    return sources.stop_epochs(stops, aiding.zupt_rate)


def vehicle_epochs(setup: MissionSetup) -> tuple[np.ndarray, np.ndarray]:
    """The odometer's and the constraint's epochs j and times j / ``odometer_rate`` in (0, duration], s.

    Parameters
    ----------
    setup : MissionSetup
        An aided mission on the drive.

    Returns
    -------
    index : ndarray of int
        j, the epochs' numbers (the addresses of their draws).
    times : ndarray
        s.
    """
    aiding = _aiding(setup)
    grid_interval(aiding.odometer_rate, aiding.covariance_interval, "odometer_rate")
    return epoch_schedule(aiding.odometer_rate, setup.duration)


def gnss_steps(setup: MissionSetup, steps: int) -> np.ndarray:
    """The covariance steps at whose ends a GNSS fix falls (j / ``gnss_rate`` outside the outages).

    Parameters
    ----------
    setup : MissionSetup
        An aided mission.
    steps : int
        K, the covariance steps of the mission.
    """
    aiding = _aiding(setup)
    every = grid_interval(aiding.gnss_rate, aiding.covariance_interval, "gnss_rate")
    fixes = np.arange(every, steps + 1, every)
    return fixes[~in_outages(fixes * aiding.covariance_interval, aiding.outages)]


def _aiding(setup: MissionSetup) -> Aiding:
    if setup.aiding is None:
        raise InvalidParameter("aiding", "the mission has no aiding")
    return setup.aiding


def _solution(coefficients: StepCoefficients, trajectory, steps: np.ndarray, dt: float) -> measurements.Solution:
    """The error-free solution at the ends of the given steps (module docstring)."""
    t = steps * dt
    velocity, quaternion = trajectory.kinematics(t)
    before = np.maximum(steps - 1, 0)  # the step that ends at the epoch: its means stand for the solution's rates
    return measurements.Solution(coefficients.latitude[before], np.zeros(t.size), coefficients.height[before],
                                 velocity, dcm_from_quaternion(quaternion), coefficients.body_rate[before])


def measurement_blocks(setup: MissionSetup, model: FilterModel, coefficients: StepCoefficients,
                       steps: int) -> list[MeasurementBlock]:
    """Every measurement of the mission's aiding on the covariance grid, in the order of its sources.

    Parameters
    ----------
    setup : MissionSetup
        An aided mission, SI.
    model : FilterModel
        The filter's states (:func:`schuler.mission.aiding.filter_model`).
    coefficients : StepCoefficients
        The trajectory's means over each of the K steps.
    steps : int
        K, number of.

    Returns
    -------
    list of MeasurementBlock
        One per source of :attr:`~schuler.mission.setup.Aiding.sources`, in that order.
    """
    aiding = _aiding(setup)
    dt = aiding.covariance_interval
    trajectory = setup.trajectory()
    n = model.size
    fixes = gnss_steps(setup, steps)
    solution = _solution(coefficients, trajectory, fixes, dt)
    zeros = np.zeros(fixes.size)
    arm = np.asarray(aiding.lever_arm, dtype=float)
    _, H = measurements.gnss_position(solution, arm, zeros, zeros, zeros, n)
    blocks = [MeasurementBlock("gnss_position_noise", fixes, H, np.diag(np.square(aiding.position_sigma)))]
    if aiding.use_velocity:
        _, H = measurements.gnss_velocity(solution, arm, solution.velocity, n, EARTH_RATE)
        blocks.append(MeasurementBlock("gnss_velocity_noise", fixes, H, np.eye(3) * aiding.velocity_sigma**2))
    if "zupt" in aiding.vehicle:
        at = np.rint(zupt_epochs(setup) / dt).astype(int)
        _, H = measurements.zero_velocity(_solution(coefficients, trajectory, at, dt), model)
        blocks.append(MeasurementBlock("zupt_noise", at, H, np.eye(3) * aiding.zupt_sigma**2))
    wheel = [name for name in ("odometer", "nhc") if name in aiding.vehicle]
    if wheel:
        at = np.rint(vehicle_epochs(setup)[1] / dt).astype(int)
        _, H = measurements.vehicle(_solution(coefficients, trajectory, at, dt), aiding.wheel_lever_arm, np.eye(3),
                                    0.0, model, earth_rate=EARTH_RATE)
        if "odometer" in wheel:
            blocks.append(MeasurementBlock("odometer_noise", at, H[:, :1], np.eye(1) * aiding.odometer_sigma**2))
        if "nhc" in wheel:
            blocks.append(MeasurementBlock("nhc_noise", at, H[:, 1:], np.eye(2) * aiding.nhc_sigma**2))
    return blocks


def _measured_with_noise(source: sources.Source, noise: np.ndarray) -> sources.Source:
    """The source with white noise v (N, k, m) on what it measures: delta_z = h(x_hat) - (z + v)."""
    def measure(j: int, context: sources.Context):
        residual, H, R = source.measure(j, context)
        return residual - noise[:, j], H, R

    return sources.Source(source.name, source.t, measure, source.components)


def _white(streams: RandomStreams, stream: str, members: np.ndarray, index: np.ndarray, sigma) -> np.ndarray:
    """Each member's white noise at the epochs' indices, one stream per component: shape (N, k, len(sigma))."""
    sigma = np.atleast_1d(np.asarray(sigma, dtype=float))
    if not index.size:
        return np.zeros((members.size, 0, sigma.size))
    return np.stack([np.stack([draws(streams, f"{stream}/{axis}", int(m), index) for axis in range(sigma.size)],
                              axis=-1) for m in members]) * sigma


def filter_sources(setup: MissionSetup, model: FilterModel, members: np.ndarray, streams: RandomStreams,
                   imu_rate: float) -> list[sources.Source]:
    """The aiding besides GNSS as :func:`schuler.aided.ekf.run_filter`'s sources, each member's data drawn.

    The drive's truth is at rest at a stop and has no lateral or vertical wheel velocity, so the velocity at a
    stop (vibration, rocking) and the wheel's (skid, suspension) enter as white noise of ``zupt_sigma`` and
    ``nhc_sigma`` on what the zero-velocity update and the constraint measure (streams ``zupt/<axis>`` and
    ``nhc/<row>``, addressed by member and epoch k of k / rate), as the odometer's noise enters its speed
    (:func:`schuler.aided.epochs.simulate_odometer`): the Monte Carlo's measurements carry the noise sources of
    the covariance analysis.

    Parameters
    ----------
    setup : MissionSetup
        An aided mission, SI.
    model : FilterModel
        The filter's states.
    members : ndarray of int
        Global member numbers (the addresses of the draws), shape (N,).
    streams : RandomStreams
        The Monte Carlo's addressed random streams.
    imu_rate : float
        Rate of the truth's samples, Hz.

    Returns
    -------
    list of Source
        ``zupt`` and ``vehicle`` (odometer and/or constraint) as the aiding names them; none for GNSS alone.
    """
    aiding = _aiding(setup)
    members = np.asarray(members, dtype=np.int64)
    built = []
    if "zupt" in aiding.vehicle:
        times = zupt_epochs(setup)
        noise = _white(streams, "zupt", members, np.rint(times * aiding.zupt_rate).astype(np.int64),
                       [aiding.zupt_sigma] * 3)
        built.append(_measured_with_noise(sources.zero_velocity_source(times, aiding.zupt_sigma, model), noise))
    if "odometer" in aiding.vehicle or "nhc" in aiding.vehicle:
        index, times = vehicle_epochs(setup)
        speed = None
        if "odometer" in aiding.vehicle:
            trajectory = setup.trajectory()
            speed = np.stack([simulate_odometer(trajectory, setup.duration, imu_rate=imu_rate,
                                                rate=aiding.odometer_rate, lever_arm=aiding.wheel_lever_arm,
                                                sigma=aiding.odometer_sigma, streams=streams,
                                                member=int(m)).speed_m_s for m in members])
        vehicle = sources.vehicle_source(times, speed, model, lever_arm=aiding.wheel_lever_arm,
                                         speed_sigma=aiding.odometer_sigma, constraint_sigma=aiding.nhc_sigma,
                                         constraint="nhc" in aiding.vehicle, earth_rate=EARTH_RATE)
        if "nhc" in aiding.vehicle:
            noise = _white(streams, "nhc", members, index, [aiding.nhc_sigma] * 2)
            if speed is not None:  # the odometer's row first, its noise in its speed
                noise = np.concatenate([np.zeros((members.size, times.size, 1)), noise], axis=-1)
            vehicle = _measured_with_noise(vehicle, noise)
        built.append(vehicle)
    return built
