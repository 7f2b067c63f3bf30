"""Every random error of N calibration procedures, drawn from addressed random streams.

The error budget (:mod:`~schuler.drift_calibration.error_budget`) gives standard
deviations; :func:`draw_errors` turns them into the errors of N procedures
(Monte Carlo members or sweep cases). Each number depends only on the study's
seed, its stream, the member's global number and its index within the member
(:class:`~schuler.core.random.RandomStreams`), so results never depend on how
the members are cut into chunks.

Levels, as the errors physically change (see the budget's notes):

* per procedure: command-sensor scale error and integrator offset (one per
  channel), +/- pulse amplitude and duration mismatch and pulse tilt (one
  generator), the latitude error, the error of the loop time constant used to
  compensate the loop lag;
* per platform position k: the turn error (none at the first position, which
  defines A0) and the levelling residual of each channel's axis;
* per cycle (channel c, position k, cycle m): the initial sensor angle and the
  base sway angle and rate;
* inside each cycle: white sensor noise and gyro angle random walk, standard
  normal samples held over the steps of each phase (one series per member,
  laid out as channel, position, cycle, phase, kind, step).

Example
-------
>>> from schuler.core.random import RandomStreams
>>> sigmas = {"turn_angle_error": 1e-5}
>>> e = draw_errors(sigmas, RandomStreams(0), np.arange(3), channels=2, positions=2, cycles=1, samples=40)
>>> e.turn_error.shape, bool(np.all(e.turn_error[:, 0] == 0.0)), e.noise is None
((3, 2), True, True)
>>> later = draw_errors(sigmas, RandomStreams(0), np.arange(1, 3), channels=2, positions=2, cycles=1, samples=40)
>>> bool(np.array_equal(e.turn_error[1:], later.turn_error))
True
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from schuler.core.random import RandomStreams

_PREFIX = "calibrate/"
"""Stream names are prefixed so that they never coincide with a scenario's parameter draws."""


@dataclass(frozen=True)
class ProcedureErrors:
    """The random errors of N procedures with C channels, K positions and M cycles (SI arrays).

    Attributes
    ----------
    sensor_scale_error, integrator_offset : ndarray, shape (N, C)
        Relative error kappa of K1 (dimensionless) and integrator input offset (rad) of each channel.
    amplitude_mismatch, duration_mismatch, tilt : ndarray, shape (N,)
        epsilon, delta and the pulse-top tilt of the pulse generator (dimensionless).
    latitude_error : ndarray, shape (N,)
        Error of the latitude entered, rad.
    lag_compensation_error : ndarray, shape (N,)
        Relative error of the loop time constant used for the lag compensation.
    turn_error : ndarray, shape (N, K)
        Error of each platform turn, rad (zero at the first position).
    elevation : ndarray, shape (N, C, K)
        Levelling residual of each channel's axis at each position, rad.
    initial_angle, sway_angle : ndarray, shape (N, C, K, M)
        Command-sensor angle and base sway angle at the start of each cycle, rad.
    sway_rate : ndarray, shape (N, C, K, M)
        Base sway rate at the start of each cycle, rad/s.
    sensor_noise_density, angle_random_walk : ndarray, shape (N,)
        rad/sqrt(Hz) and rad/sqrt(s).
    noise : ndarray, shape (N, C, K, M, 2, 2, S), or None
        Standard normal samples of each cycle (phase, kind: rate then sensor, step);
        None when both densities are zero.
    """

    sensor_scale_error: np.ndarray
    integrator_offset: np.ndarray
    amplitude_mismatch: np.ndarray
    duration_mismatch: np.ndarray
    tilt: np.ndarray
    latitude_error: np.ndarray
    lag_compensation_error: np.ndarray
    turn_error: np.ndarray
    elevation: np.ndarray
    initial_angle: np.ndarray
    sway_angle: np.ndarray
    sway_rate: np.ndarray
    sensor_noise_density: np.ndarray
    angle_random_walk: np.ndarray
    noise: np.ndarray | None

    @property
    def members(self) -> int:
        return self.amplitude_mismatch.shape[0]

    @classmethod
    def zero(cls, members: int, channels: int, positions: int, cycles: int) -> ProcedureErrors:
        """No errors: the error-free procedure.

        Parameters
        ----------
        members : int
            Number of procedures (Monte Carlo members).
        channels, positions, cycles : int
            Number of gyro channels measured, of platform positions and of cycles per position.
        """
        return draw_errors({}, None, np.zeros(members, dtype=np.int64), channels=channels, positions=positions,
                           cycles=cycles, samples=0)


def draw_errors(budget: Mapping[str, np.ndarray], streams: RandomStreams | None, members, *, channels: int,
                positions: int, cycles: int, samples: int) -> ProcedureErrors:
    """Draw the errors of ``len(members)`` procedures.

    Parameters
    ----------
    budget : mapping
        Standard deviations (and noise densities) by the field names of
        :class:`~schuler.drift_calibration.error_budget.ErrorBudget`, each a
        scalar or an array (N,) in SI; a missing item is zero. ``sway_frequency``
        (Hz) sets the spread of the sway rate, omega_s times the sway angle's.
    streams : RandomStreams or None
        Where the numbers come from; None gives the error-free procedure.
    members : array_like of int, shape (N,)
        Global member numbers: the addresses of the draws.
    channels, positions, cycles : int
        C, K and M of the procedure: the number of channels, of positions and of cycles.
    samples : int
        S, noise samples per phase (``cycle_grid(shape, steps).size - 1``).

    Returns
    -------
    ProcedureErrors
    """
    members = np.asarray(members, dtype=np.int64)
    n, c, k, m = members.size, channels, positions, cycles

    def sigma(name: str) -> np.ndarray:
        return np.broadcast_to(np.asarray(budget.get(name, 0.0), dtype=float), (n,))

    def normal(name: str, shape: tuple[int, ...], spread: np.ndarray) -> np.ndarray:
        width = math.prod(shape)
        if streams is None or width == 0:
            return np.zeros((n, *shape))
        draws = streams.normal(_PREFIX + name, members, width).reshape(n, *shape)
        return spread.reshape(n, *([1] * len(shape))) * draws

    sway_omega = 2.0 * math.pi * np.broadcast_to(np.asarray(budget.get("sway_frequency", 0.0), dtype=float), (n,))
    turn_error = normal("turn_angle_error", (k,), sigma("turn_angle_error"))
    turn_error[:, 0] = 0.0  # the first position defines A0
    sensor_density, walk = sigma("sensor_noise_density"), sigma("angle_random_walk")
    noise = None
    if streams is not None and samples > 0 and (np.any(sensor_density > 0) or np.any(walk > 0)):
        series = streams.normal_series(_PREFIX + "cycle_noise", members, 0, c * k * m * 4 * samples)
        noise = series.reshape(n, c, k, m, 2, 2, samples)
    return ProcedureErrors(
        sensor_scale_error=normal("sensor_scale_error", (c,), sigma("sensor_scale_error")),
        integrator_offset=normal("integrator_offset", (c,), sigma("integrator_offset")),
        amplitude_mismatch=normal("amplitude_mismatch", (), sigma("amplitude_mismatch")),
        duration_mismatch=normal("duration_mismatch", (), sigma("duration_mismatch")),
        tilt=normal("pulse_asymmetry", (), sigma("pulse_asymmetry")),
        latitude_error=normal("latitude_error", (), sigma("latitude_error")),
        lag_compensation_error=normal("lag_compensation_error", (), sigma("lag_compensation_error")),
        turn_error=turn_error,
        elevation=normal("levelling_residual", (c, k), sigma("levelling_residual")),
        initial_angle=normal("initial_angle", (c, k, m), sigma("initial_angle")),
        sway_angle=normal("sway_angle", (c, k, m), sigma("sway_amplitude")),
        sway_rate=normal("sway_rate", (c, k, m), sway_omega * sigma("sway_amplitude")),
        sensor_noise_density=np.array(sensor_density),
        angle_random_walk=np.array(walk),
        noise=noise,
    )
