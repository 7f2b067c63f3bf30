"""Covariance analysis of an aided mission: every error source carried through the aided filter's closed loop.

The filter is ``schuler aided``'s error-state filter (spec 07;
:mod:`schuler.aided.error_state`, 21 states: position, velocity and attitude
errors, residual gyro and accelerometer biases and scale factors), with the
mission's IMU model (:func:`filter_model`): each bias and scale factor a
random constant of the 1-sigma calibration leaves
(:attr:`~schuler.mission.setup.MissionSetup.constant_sigmas`), the angle and
velocity random walks white. The analysis has two passes.

1. **Nominal run.** Along the trajectory without any error (the solution is
   the truth) the filter's own covariance P_f gives the gains. Each
   covariance step k of Delta (``covariance_interval``) has F held at the
   trajectory's means over the step (:mod:`schuler.mission.coefficients`)
   and the exact transition and process noise of Van Loan 1978
   (:func:`schuler.aided.error_state.transition`'s discretisation):
   Phi_k = e^(F Delta), Q_k = int_0^Delta e^(F s) G Q_c G^T e^(F^T s) ds.
   At the end of a step where measurements fall (GNSS fixes at j / ``gnss_rate``
   outside the outages; on the drive zero-velocity updates inside its stops,
   odometer and non-holonomic constraint: every epoch on the step grid,
   :mod:`schuler.mission.aiding_measurements`) they are one stacked update,
   H the blocks' rows of :mod:`schuler.aided.measurements` (lever arms
   included) and R = blockdiag(R_b), K = P_f H^T (H P_f H^T + R)^-1 (spec 07;
   Groves 2013, Sec. 3.2). The filter starts from the diagonal of the true
   initial covariance (what ``schuler aided``'s ``Start`` accepts).

2. **Sources through the closed loop.** Each independent source i (every
   constant source of :mod:`schuler.mission.setup`, the two random walks,
   each measurement's noise: ``gnss_position_noise``, ``gnss_velocity_noise``,
   ``zupt_noise``, ``odometer_noise``, ``nhc_noise``) has its own initial
   covariance P_i(0), process noise Q_i,k and measurement noise R_i (one of
   them non-zero; a measurement's R_i is its block R_b, zero elsewhere), and
   is propagated with the nominal gains (Joseph form, valid for any gain):

       P_i <- Phi_k P_i Phi_k^T + Q_i,k,
       P_i <- (I - K H) P_i (I - K H)^T + K R_i K^T   (at an update).

   A constant source j of 1-sigma sigma_j has P_j(0) = x_j x_j^T with x_j its
   state: its own bias or scale-factor state sigma_j and the position and
   attitude errors the alignment makes of it
   (:func:`schuler.mission.stages.initial_state_map`; the filter's attitude
   state is phi = psi + delta_theta, spec 07); a random walk's P(0) is what
   it leaves through the alignment (:func:`schuler.mission.stages.alignment_noise`).
   The recursion is linear in (P(0), Q, R) for fixed gains, so
   sum_i P_i is the covariance of the true error (the filter's own P_f
   differs by the correlations of P(0) it is not given), each source's
   variance of an output adds, its share is its fraction, and switching a
   source off removes exactly its share. The sources are a leading axis of
   one stack: one pass over the steps.

Outputs are those of :mod:`schuler.mission.covariance` on the filter's states:
position north and east, velocity north and east (the filter's velocity
error) and heading error -phi_D, at every covariance step before its update. An
outage's end is ``schuler aided``'s (:func:`schuler.aided.analysis.outage_drift`):
the last covariance step before the epoch that ends it.

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
Artech House, 2013, Sec. 3.2 and ch. 14.
C. F. Van Loan, "Computing integrals involving the matrix exponential", IEEE Transactions on
Automatic Control 23(3), 395-404, 1978.
P. S. Maybeck, *Stochastic Models, Estimation, and Control*, vol. 1, Academic Press, 1979, Sec. 6.8
(covariance analysis of a filter's error budget, source by source).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from schuler.aided.error_state import (
    ACCEL_BIAS,
    ACCEL_SCALE,
    ATTITUDE,
    GYRO_BIAS,
    GYRO_SCALE,
    ErrorProcess,
    FilterModel,
    NavigationPoint,
    noise_input,
    system_matrix,
)
from schuler.core.attitude import dcm_from_quaternion
from schuler.core.earth import EARTH_RATE, radii_of_curvature
from schuler.core.propagation import discretise_noise
from schuler.exceptions import InvalidParameter
from schuler.mission.aiding_measurements import MeasurementBlock, measurement_blocks
from schuler.mission.coefficients import step_coefficients
from schuler.mission.covariance import OUTPUT_CHANNELS, CovarianceBudget
from schuler.mission.setup import AXES, CONSTANT_SOURCES, SOURCES, WHITE_SOURCES, Aiding, MissionSetup
from schuler.mission.stages import alignment_noise, initial_state_map

STATES = 21
"""Error states of the aided filter (:mod:`schuler.aided.error_state`)."""

MAX_STEPS = 100_000
"""Largest number of covariance steps of one analysis (memory: steps x sources x 9 x 9 doubles)."""

_SENSOR_STATES = {"gyro_bias": GYRO_BIAS, "accel_bias": ACCEL_BIAS, "gyro_scale_factor": GYRO_SCALE,
                  "accel_scale_factor": ACCEL_SCALE}


def filter_model(setup: MissionSetup) -> FilterModel:
    """The aided filter's IMU model of a mission: random-constant biases and scale factors, white random walks.

    Parameters
    ----------
    setup : MissionSetup
        The mission: its 1-sigma calibration residuals (rad/s, m/s^2, plain-number scale factors) and its angle
        (rad/sqrt(s)) and velocity (m/s/sqrt(s)) random walks per body axis.

    Returns
    -------
    FilterModel
        21 states; each triad a random constant (:class:`~schuler.aided.error_state.ErrorProcess`) of the
        mission's 1-sigma.
    """
    sigma = dict(zip(CONSTANT_SOURCES, setup.constant_sigmas))

    def triad(family: str) -> ErrorProcess:
        return ErrorProcess("constant", np.array([sigma[f"{family}_{axis}"] for axis in AXES]))

    return FilterModel(setup.gyro_random_walk, setup.accel_random_walk, triad("gyro_bias"), triad("accel_bias"),
                       triad("gyro_scale_factor"), triad("accel_scale_factor"))


def attitude_from_psi(x0: np.ndarray, latitude: float, height: float) -> np.ndarray:
    """The attitude error phi = psi + delta_theta of psi-model states (..., 9), rad, NED.

    delta_theta = (dr_E / (R_E + h), -dr_N / (R_N + h), -dr_E tan L / (R_E + h)) (:mod:`schuler.navigate.linear`).

    Parameters
    ----------
    x0 : ndarray
        Psi-model states, shape (..., n): position errors north, east first (m), psi last three (rad).
    latitude : float
        L, rad.
    height : float
        h, m.

    Returns
    -------
    ndarray
        phi, shape (..., 3), rad.
    """
    radius_north, radius_east = radii_of_curvature(latitude)
    north, east = x0[..., 0], x0[..., 1]
    delta_theta = np.stack([east / (radius_east + height), -north / (radius_north + height),
                            -east * math.tan(latitude) / (radius_east + height)], axis=-1)
    return x0[..., -3:] + delta_theta


def initial_states(setup: MissionSetup, body_to_ned: np.ndarray) -> np.ndarray:
    """The filter state each constant source starts with at its 1-sigma: shape (n_constant, 21).

    Parameters
    ----------
    setup : MissionSetup
        The mission (alignment, latitude in rad, height in m, the sources' 1-sigma in SI).
    body_to_ned : ndarray
        C_b^n at the start, shape (3, 3), plain numbers (direction cosines).

    Returns
    -------
    ndarray
        Position (m), velocity (m/s), attitude phi (rad), bias (rad/s, m/s^2) and scale-factor (1) errors.
    """
    psi_model = initial_state_map(setup, body_to_ned, 9)
    x = np.zeros((len(CONSTANT_SOURCES), STATES))
    x[:, :6] = psi_model[:, :6]
    x[:, ATTITUDE] = attitude_from_psi(psi_model, setup.latitude, setup.height)
    for j, name in enumerate(CONSTANT_SOURCES):
        family, _, axis = name.rpartition("_")
        if family in _SENSOR_STATES:
            x[j, _SENSOR_STATES[family].start + AXES.index(axis)] = 1.0
    return x * setup.constant_sigmas[:, None]


@dataclass(frozen=True)
class AidedBudget:
    """An aided mission's covariance analysis: the budget over the steps and each outage's end.

    Attributes
    ----------
    budget : CovarianceBudget
        Every source's variance of every output channel at every covariance step, SI^2 (sources:
        :data:`~schuler.mission.setup.SOURCES` then the aiding's measurement-noise sources,
        :attr:`~schuler.mission.setup.Aiding.sources`).
    outages : list of dict
        Per outage: ``start_s``, ``duration_s`` (s), ``end_index`` (the step of its end) and
        ``horizontal_error_sigma_m`` (m) and ``shares`` ({source: fraction of the north + east variance}).
    filter_sigma : ndarray (K + 1,)
        The nominal filter's own horizontal 1-sigma at each step, m (what it believes, given the diagonal of the
        initial covariance).
    start_sigma : ndarray (21,)
        The filter's initial 1-sigma, in the states' units.
    """

    budget: CovarianceBudget
    outages: list[dict]
    filter_sigma: np.ndarray
    start_sigma: np.ndarray


def _steps(setup: MissionSetup, aiding: Aiding) -> int:
    """Number of covariance steps of the mission, refused unless whole and at most :data:`MAX_STEPS`."""
    step = aiding.covariance_interval
    steps = setup.duration / step
    if abs(steps - round(steps)) > 1e-9 * steps:
        raise InvalidParameter("covariance_interval", f"the duration {setup.duration:g} s must be a whole number of "
                                                      f"covariance steps of {step:g} s")
    if round(steps) > MAX_STEPS:
        raise InvalidParameter("covariance_interval", f"{round(steps)} steps exceed {MAX_STEPS}: use a longer one")
    return int(round(steps))


@dataclass(frozen=True)
class _Update:
    """The measurements due at the end of one covariance step, stacked: H (m, 21), R (m, m), and each block's rows
    and noise source (its index in the stack of sources, its R)."""

    H: np.ndarray
    R: np.ndarray
    parts: list[tuple[int, slice, np.ndarray]]


def _updates(blocks: list[MeasurementBlock], source_index: dict[str, int]) -> dict[int, _Update]:
    """The stacked update of every step at whose end a measurement falls, the blocks in their order."""
    due: dict[int, list[tuple[MeasurementBlock, int]]] = {}
    for block in blocks:
        for row, step in enumerate(block.steps):
            due.setdefault(int(step), []).append((block, row))
    out = {}
    for step, rows in due.items():
        H = np.concatenate([block.H[row] for block, row in rows])
        R = np.zeros((H.shape[0], H.shape[0]))
        parts, first = [], 0
        for block, _ in rows:
            m = block.R.shape[0]
            R[first:first + m, first:first + m] = block.R
            parts.append((source_index[block.source], slice(first, first + m), block.R))
            first += m
        out[step] = _Update(H, R, parts)
    return out


def aided_budget(setup: MissionSetup, disabled: tuple[str, ...] = ()) -> AidedBudget:
    """The error budget of an aided mission: every source carried through the filter's closed loop (module doc).

    Parameters
    ----------
    setup : MissionSetup
        The mission, SI, with its :class:`~schuler.mission.setup.Aiding`.
    disabled : tuple of str
        Sources switched off (their P(0), Q or R set to zero); the nominal gains stay those of the whole model.

    Returns
    -------
    AidedBudget
        The budget at every covariance step and each outage's end.
    """
    aiding = setup.aiding
    if aiding is None:
        raise InvalidParameter("aiding", "the mission has no aiding: use schuler.mission.covariance")
    sources = SOURCES + aiding.sources
    unknown = set(disabled) - set(sources)
    if unknown:
        raise InvalidParameter("disabled", f"unknown sources {sorted(unknown)}; choose from {', '.join(sources)}")
    steps = _steps(setup, aiding)
    dt = aiding.covariance_interval
    trajectory = setup.trajectory()
    coefficients = step_coefficients(trajectory, setup.latitude, setup.height, steps * dt, dt)
    model = filter_model(setup)
    point = NavigationPoint(coefficients.latitude, coefficients.height, coefficients.velocity_ned,
                            coefficients.body_to_ned, coefficients.body_specific_force, coefficients.body_rate)
    F = system_matrix(model, point, EARTH_RATE)
    Phi, Q_gyro = discretise_noise(F, noise_input(dataclasses.replace(model, velocity_random_walk=0.0),
                                                  coefficients.body_to_ned), dt)
    _, Q_accel = discretise_noise(F, noise_input(dataclasses.replace(model, angle_random_walk=0.0),
                                                 coefficients.body_to_ned), dt)
    on = np.array([name not in disabled for name in sources], dtype=float)

    start_rotation = dcm_from_quaternion(trajectory.kinematics(np.array([0.0]))[1])[0]
    P = np.zeros((1 + len(sources), STATES, STATES))
    x = initial_states(setup, start_rotation)
    P[1:1 + len(CONSTANT_SOURCES)] = x[:, :, None] * x[:, None, :]
    white = {name: 1 + SOURCES.index(name) for name in WHITE_SOURCES}
    for name, covariance in alignment_noise(setup, start_rotation, 9).items():
        P[white[name], 6:9, 6:9] = covariance[6:9, 6:9]
    start_sigma = np.sqrt(np.diag(P[1:1 + len(SOURCES)].sum(axis=0)))
    P[0] = np.diag(start_sigma**2)
    P[1:] *= on[:, None, None]
    true_initial = P[1:].sum(axis=0)

    updates = _updates(measurement_blocks(setup, model, coefficients, steps),
                       {name: 1 + i for i, name in enumerate(sources)})
    stored = np.empty((steps + 1, P.shape[0], 9, 9))
    stored[0] = P[:, :9, :9]
    gyro, accel = white["gyro_random_walk"], white["accel_random_walk"]
    identity = np.eye(STATES)
    for k in range(steps):
        P = Phi[k] @ P @ Phi[k].T
        P[0] += Q_gyro[k] + Q_accel[k]
        P[gyro] += on[gyro - 1] * Q_gyro[k]
        P[accel] += on[accel - 1] * Q_accel[k]
        stored[k + 1] = P[:, :9, :9]
        update = updates.get(k + 1)
        if update is not None:
            PHt = P[0] @ update.H.T
            gain = np.linalg.solve(update.H @ PHt + update.R, PHt.T).T
            A = identity - gain @ update.H
            P = A @ P @ A.T
            P[0] += gain @ update.R @ gain.T
            for index, rows, R in update.parts:
                P[index] += on[index - 1] * (gain[:, rows] @ R @ gain[:, rows].T)
    P0 = stored[:, 0]
    variance = _channels(stored[:, 1:], coefficients)
    budget = CovarianceBudget(time=np.arange(steps + 1) * dt, sources=sources, variance=variance,
                              initial_state=np.zeros((len(sources), 9)), initial_covariance=true_initial[:9, :9],
                              states=9)
    return AidedBudget(budget, _outages(budget, aiding), np.sqrt(P0[:, 0, 0] + P0[:, 1, 1]), start_sigma)


def _channels(stored: np.ndarray, coefficients) -> dict[str, np.ndarray]:
    """Each source's variance of :data:`~schuler.mission.covariance.OUTPUT_CHANNELS` at every step, (K + 1, S)."""
    rows = {"position_north": 0, "position_east": 1, "velocity_north": 3, "velocity_east": 4, "heading": 8}
    return {channel: stored[:, :, rows[channel], rows[channel]] for channel in OUTPUT_CHANNELS}


def _outages(budget: CovarianceBudget, aiding: Aiding) -> list[dict]:
    """Each outage's end (the last step before the epoch that ends it): its 1-sigma and every source's share."""
    out = []
    for start, duration in aiding.outages:
        end = start + duration
        index = max(int(np.searchsorted(budget.time, end - 1e-9)) - 1, 0)
        horizontal = budget.horizontal()[index]
        out.append({"start_s": float(start), "duration_s": float(duration), "end_index": index,
                    "horizontal_error_sigma_m": float(math.sqrt(horizontal.sum())),
                    "shares": budget.shares(index)})
    return out
