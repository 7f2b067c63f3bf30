"""Covariance analysis of a mission on the psi-angle model: the error budget, source by source, in one pass.

The navigation errors obey the WGS-84 psi-angle model (spec 06;
:func:`schuler.navigation_errors.three_d.wgs84_error_matrices`)

    x' = F(t) x + G(t) u,    u = (nabla, epsilon) in NED,

with coefficients frozen at their means over each step
(:mod:`schuler.mission.coefficients`) and each step propagated exactly
(zero-order hold, :func:`schuler.core.lti.zoh_discretize`).

Every constant source j (unit 1-sigma sigma_j) enters twice, through the
initial state its alignment and calibration leave (x0_j,
:func:`schuler.mission.stages.initial_state_map`) and through the inputs it
makes during navigation (u_j(t), :func:`schuler.mission.stages.sensor_inputs`):
its contribution is the deterministic response

    x_j(t_k+1) = Phi_k x_j(t_k) + Gamma_k u_j,k,    x_j(0) = sigma_j x0_j,

and its share of the variance of an output y = r x is (r x_j)^2. A white
source (angle or velocity random walk, PSD N^2 per body axis) has its own
covariance, from what it left through the alignment (P0) and its process noise
during navigation (Van Loan 1978):

    P_k+1 = Phi_k P_k Phi_k^T + Q_k,   Q_k = int_0^dt e^(F s) G Q_c G^T e^(F^T s) ds,

Q_c = C_b^n diag(N^2) C_n^b on the input it drives. The sources are
independent, so the total variance is the sum of the contributions exactly,
and switching a source off removes exactly its own term.

Outputs y = r x (computed - true; :mod:`schuler.navigate.linear` for the
conversions): position north and east (the states), horizontal velocity
dv_true = dv_psi + v x delta_theta, delta_theta = T delta_r, and heading error
-phi_D = -psi_D + delta_r_E tan L / (R_E + h).

References
----------
C. F. Van Loan, "Computing integrals involving the matrix exponential", IEEE Transactions on
Automatic Control 23(3), 395-404, 1978.
B. A. Benson, "A comparison of two approaches to pure-inertial and Doppler-inertial error analysis",
IEEE Transactions on Aerospace and Electronic Systems AES-11(4), 447-455, 1975.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from schuler.core.attitude import dcm_from_quaternion
from schuler.core.earth import EARTH_RATE, radii_of_curvature
from schuler.exceptions import InvalidParameter
from schuler.mission.coefficients import StepCoefficients, step_coefficients
from schuler.mission.exponential import expm_stack
from schuler.mission.setup import CONSTANT_SOURCES, SOURCES, WHITE_SOURCES, MissionSetup
from schuler.mission.stages import alignment_noise, initial_state_map, sensor_inputs
from schuler.navigation_errors.three_d import wgs84_error_matrices

OUTPUT_CHANNELS = ("position_north", "position_east", "velocity_north", "velocity_east", "heading")
"""Outputs whose variance the budget splits by source (SI: m, m/s, rad)."""

LINEAR_LIMIT = np.radians(5.0)
"""Initial 1-sigma heading error above which the linear error model is warned about (second-order terms grow)."""

MAX_STEPS = 200_000
"""Largest number of steps of one analysis (memory: steps x sources x states)."""

BATCH_STEPS = 20_000
"""Mission steps (missions x steps) analysed at once: about 200 MB of step matrices and their exponentials."""


class LinearityWarning(UserWarning):
    """The alignment leaves errors too large for the linear (small-angle) model to be trusted."""


@dataclass(frozen=True)
class CovarianceBudget:
    """Variance contributions of every source to every output channel, at every step boundary.

    Attributes
    ----------
    time : ndarray (K + 1,)
        s.
    sources : tuple of str
        :data:`~schuler.mission.setup.SOURCES`.
    variance : dict of ndarray (K + 1, n_sources)
        Per channel of :data:`OUTPUT_CHANNELS`: each source's variance, SI^2.
    initial_state : ndarray (n_sources, n)
        The 1-sigma initial state of each constant source (zero rows for the white ones).
    initial_covariance : ndarray (n, n)
        Total initial covariance (what calibration and alignment leave).
    states : int
        7 (vertical channel off) or 9 (free).
    """

    time: np.ndarray
    sources: tuple[str, ...]
    variance: dict[str, np.ndarray]
    initial_state: np.ndarray
    initial_covariance: np.ndarray
    states: int

    def horizontal(self, kind: str = "position") -> np.ndarray:
        """Contributions to the horizontal variance (north + east), (K + 1, n_sources).

        Parameters
        ----------
        kind : {"position", "velocity"}
            Which horizontal error.

        Returns
        -------
        ndarray
            Each source's variance at each step boundary, shape (K + 1, n_sources): m^2 (position) or
            (m/s)^2 (velocity).
        """
        return self.variance[f"{kind}_north"] + self.variance[f"{kind}_east"]

    def sigma(self, channel: str) -> np.ndarray:
        """1-sigma history of a channel (or ``horizontal_position``, ``horizontal_velocity``).

        Parameters
        ----------
        channel : str
            One of :data:`OUTPUT_CHANNELS`, or ``horizontal_position`` / ``horizontal_velocity``.

        Returns
        -------
        ndarray
            The total 1-sigma error (all sources) at each step boundary, shape (K + 1,): m (position), m/s
            (velocity) or rad (heading).
        """
        if channel.startswith("horizontal_"):
            return np.sqrt(self.horizontal(channel.removeprefix("horizontal_")).sum(axis=1))
        return np.sqrt(self.variance[channel].sum(axis=1))

    def shares(self, index: int = -1) -> dict[str, float]:
        """Each source's share of the horizontal position-error variance at step boundary ``index`` (sum 1).

        Parameters
        ----------
        index : int
            Step boundary index into :attr:`time` (-1: the end of the mission).

        Returns
        -------
        dict of str to float
            Source -> share, plain number (all 0 when the variance is 0).
        """
        contributions = self.horizontal()[index]
        total = contributions.sum()
        if total <= 0.0:
            return {name: 0.0 for name in self.sources}
        return {name: float(value / total) for name, value in zip(self.sources, contributions)}


def _output_rows(coefficients: StepCoefficients, n: int) -> np.ndarray:
    """Rows r (K + 1, 5, n) of :data:`OUTPUT_CHANNELS` at each boundary (step k's coefficients at its end)."""
    index = np.concatenate([[0], np.arange(coefficients.latitude.size)])
    L, h, v = coefficients.latitude[index], coefficients.height[index], coefficients.velocity_ned[index]
    radius_north, radius_east = radii_of_curvature(L)
    count = index.size
    T = np.zeros((count, 3, 3))  # delta_theta = T delta_r
    T[:, 0, 1] = 1.0 / (radius_east + h)
    T[:, 1, 0] = -1.0 / (radius_north + h)
    T[:, 2, 1] = -np.tan(L) / (radius_east + h)
    v_cross = np.zeros((count, 3, 3))
    v_cross[:, 0, 1], v_cross[:, 0, 2], v_cross[:, 1, 2] = -v[:, 2], v[:, 1], -v[:, 0]
    v_cross -= np.swapaxes(v_cross, 1, 2)
    coupling = v_cross @ T
    vertical = n == 9
    position = 3 if vertical else 2
    rows = np.zeros((count, len(OUTPUT_CHANNELS), n))
    rows[:, 0, 0] = rows[:, 1, 1] = 1.0
    for channel, axis in ((2, 0), (3, 1)):
        rows[:, channel, :position] = coupling[:, axis, :position]
        rows[:, channel, position + axis] = 1.0
    rows[:, 4, n - 1] = -1.0
    rows[:, 4, 1] = np.tan(L) / (radius_east + h)
    return rows


def process_noise(F: np.ndarray, noise_input: np.ndarray, dt: float) -> np.ndarray:
    """Van Loan's discrete process noise of each step: integral of e^(F s) Qc e^(F^T s) over dt, (..., n, n).

    Parameters
    ----------
    F : ndarray
        System matrix of each step, shape (..., n, n), SI (psi-angle model: each state's rate per unit of each
        state, states in m, m/s, rad).
    noise_input : ndarray
        G Q_c G^T of each step, shape (..., n, n): the white input's PSD mapped onto the state derivatives,
        (state unit)^2 / s (e.g. rad^2/s on psi from an angle random walk N^2).
    dt : float
        Step length, s.

    Returns
    -------
    ndarray
        Q_k, shape (..., n, n), (state unit)^2, symmetrised.

    Examples
    --------
    >>> q = process_noise(np.zeros((1, 1, 1)), np.ones((1, 1, 1)), 2.0)
    >>> float(q[0, 0, 0])
    2.0
    """
    n = F.shape[-1]
    M = np.zeros((*F.shape[:-2], 2 * n, 2 * n))
    M[..., :n, :n] = -F
    M[..., :n, n:] = noise_input
    M[..., n:, n:] = np.swapaxes(F, -1, -2)
    E = expm_stack(M * dt)
    Q = np.swapaxes(E[..., n:, n:], -1, -2) @ E[..., :n, n:]
    return 0.5 * (Q + np.swapaxes(Q, -1, -2))


def covariance_budget(setup: MissionSetup, disabled: tuple[str, ...] = ()) -> CovarianceBudget:
    """The error budget of a mission: every source's variance contribution along the trajectory.

    Parameters
    ----------
    setup : MissionSetup
        The mission, SI.
    disabled : tuple of str
        Sources switched off (their sigma set to zero), e.g. to check that one
        source's share is exactly what it adds.

    Returns
    -------
    CovarianceBudget
        Every source's variance contribution to every output channel at every step boundary, SI^2.
    """
    return covariance_budgets([setup], disabled)[0]


def covariance_budgets(setups, disabled: tuple[str, ...] = ()) -> list[CovarianceBudget]:
    """The error budgets of several missions of the same duration, output step and vertical channel, batched.

    The missions may differ in everything else (instrument, stages, start point, heading, trajectory): a
    Monte Carlo whose members draw their cases gets every member's covariance in one pass over the steps,
    each step's matrix exponentials of all members at once.

    Parameters
    ----------
    setups : sequence of MissionSetup
        The missions, SI; equal ``duration`` (s), ``output_step`` (s) and ``vertical_channel``.
    disabled : tuple of str
        Sources switched off in every mission (their sigma set to zero).

    Returns
    -------
    list of CovarianceBudget
        One per mission, in order, as :func:`covariance_budget` gives it.
    """
    setups = list(setups)
    unknown = set(disabled) - set(SOURCES)
    if unknown:
        raise InvalidParameter("disabled", f"unknown sources {sorted(unknown)}; choose from {', '.join(SOURCES)}")
    if not setups:
        return []
    first = setups[0]
    if any((s.duration, s.output_step, s.vertical_channel) != (first.duration, first.output_step,
                                                               first.vertical_channel) for s in setups):
        raise InvalidParameter("setups", "a batch of budgets needs one duration, output step and vertical channel")
    steps = first.duration / first.output_step
    if abs(steps - round(steps)) > 1e-9 * steps or round(steps) < 1:
        raise InvalidParameter("output_step", f"the duration {first.duration:g} s must be a whole number of "
                                              f"output steps of {first.output_step:g} s")
    if round(steps) > MAX_STEPS:
        raise InvalidParameter("output_step", f"{round(steps)} steps exceed {MAX_STEPS}: use a longer output step")
    per_batch = max(1, BATCH_STEPS // round(steps))
    budgets = []
    for start in range(0, len(setups), per_batch):
        budgets.extend(_batch(setups[start:start + per_batch], disabled))
    return budgets


def _batch(setups: list[MissionSetup], disabled: tuple[str, ...]) -> list[CovarianceBudget]:
    """:func:`covariance_budgets` of missions validated to share their steps, all at once."""
    dt = setups[0].output_step
    vertical = setups[0].vertical_channel == "free"
    parts = [_MissionTerms.of(setup, disabled, vertical) for setup in setups]
    M, K, n = len(parts), parts[0].F.shape[0], parts[0].F.shape[-1]
    F = np.stack([part.F for part in parts])
    G = np.stack([part.G for part in parts])
    augmented = np.zeros((M, K, n + 6, n + 6))
    augmented[..., :n, :n] = F * dt
    augmented[..., :n, n:] = G * dt
    transition = expm_stack(augmented)
    Ad, Bd = transition[..., :n, :n], transition[..., :n, n:]
    Ad_T, Bd_T = np.swapaxes(Ad, -1, -2), np.swapaxes(Bd, -1, -2)
    rows = np.stack([part.rows for part in parts])
    inputs = np.stack([part.inputs for part in parts])
    constant = np.empty((M, K + 1, len(CONSTANT_SOURCES), n))
    constant[:, 0] = x = np.stack([part.x0 for part in parts])
    for k in range(K):
        x = x @ Ad_T[:, k] + inputs[:, k] @ Bd_T[:, k]
        constant[:, k + 1] = x
    projected = np.einsum("mkcn,mksn->mkcs", rows, constant)
    white = np.zeros((M, K + 1, len(OUTPUT_CHANNELS), len(WHITE_SOURCES)))
    totals = np.einsum("msi,msj->mij", constant[:, 0], constant[:, 0])
    for w, name in enumerate(WHITE_SOURCES):
        if name in disabled:
            continue
        columns = slice(3, 6) if name == "gyro_random_walk" else slice(0, 3)
        Gw = G[..., columns]
        density = np.stack([part.ned_density[name] for part in parts])
        Q = process_noise(F, Gw @ density @ np.swapaxes(Gw, -1, -2), dt)
        P = np.stack([part.initial[name] for part in parts])
        totals = totals + P
        white[:, 0, :, w] = np.einsum("mcn,mnl,mcl->mc", rows[:, 0], P, rows[:, 0])
        for k in range(K):
            P = Ad[:, k] @ P @ Ad_T[:, k] + Q[:, k]
            white[:, k + 1, :, w] = np.einsum("mcn,mnl,mcl->mc", rows[:, k + 1], P, rows[:, k + 1])
    variance = np.concatenate([projected**2, white], axis=3)
    budgets = []
    for m, (setup, part) in enumerate(zip(setups, parts)):
        heading = math.sqrt(float(np.einsum("n,nl,l->", rows[m, 0, 4], totals[m], rows[m, 0, 4])))
        if heading > LINEAR_LIMIT:
            warnings.warn(f"the {setup.alignment} alignment over {setup.alignment_duration:g} s leaves a 1-sigma "
                          f"heading error of {math.degrees(heading):.1f} deg: the small-angle error model is past "
                          "its validity (align longer, calibrate better, or take north from a ground gyrocompass)",
                          LinearityWarning, stacklevel=3)
        padded = np.zeros((len(SOURCES), n))
        padded[:len(CONSTANT_SOURCES)] = part.x0
        budgets.append(CovarianceBudget(time=part.time, sources=SOURCES,
                                        variance={name: variance[m, :, c, :] for c, name in enumerate(OUTPUT_CHANNELS)},
                                        initial_state=padded, initial_covariance=totals[m], states=n))
    return budgets


@dataclass(frozen=True)
class _MissionTerms:
    """One mission's step matrices, unit-source inputs, output rows and initial terms (SI)."""

    time: np.ndarray
    F: np.ndarray
    G: np.ndarray
    rows: np.ndarray
    x0: np.ndarray
    inputs: np.ndarray
    initial: dict[str, np.ndarray]
    ned_density: dict[str, np.ndarray]

    @classmethod
    def of(cls, setup: MissionSetup, disabled: tuple[str, ...], vertical: bool) -> _MissionTerms:
        trajectory = setup.trajectory()
        coefficients = step_coefficients(trajectory, setup.latitude, setup.height, setup.duration,
                                         setup.output_step)
        F, G = wgs84_error_matrices(coefficients.latitude, coefficients.height, coefficients.velocity_ned,
                                    coefficients.specific_force_ned, EARTH_RATE, vertical)
        n = F.shape[-1]
        sigma = setup.constant_sigmas * np.array([name not in disabled for name in CONSTANT_SOURCES])
        start_rotation = dcm_from_quaternion(trajectory.kinematics(np.array([0.0]))[1])[0]
        inputs = sensor_inputs(coefficients.body_to_ned, coefficients.body_rate,
                               coefficients.body_specific_force) * sigma[None, :, None]
        C = coefficients.body_to_ned
        ned_density = {name: C @ np.diag(density**2) @ np.swapaxes(C, 1, 2)
                       for name, density in (("gyro_random_walk", setup.gyro_random_walk),
                                             ("accel_random_walk", setup.accel_random_walk))}
        return cls(time=coefficients.time, F=F, G=G, rows=_output_rows(coefficients, n),
                   x0=initial_state_map(setup, start_rotation, n) * sigma[:, None], inputs=inputs,
                   initial=alignment_noise(setup, start_rotation, n), ned_density=ned_density)
