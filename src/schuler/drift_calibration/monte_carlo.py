"""Monte Carlo of the whole calibration procedure over an error budget.

Draws the budget's errors (:mod:`.error_budget`) level by level inside
:func:`~schuler.drift_calibration.procedure.run_procedure`, vectorised over the
members of a chunk, and summarises the recovered drifts and azimuth.

Example
-------
>>> import numpy as np
>>> from schuler.drift_calibration.error_budget import TYPICAL
>>> from schuler.drift_calibration.pulses import rectangular
>>> stab = Stabilizer(57.3, 0.02, 0.1, 1e-3, 5.0, rectangular())
>>> s = monte_carlo(stab, np.radians(70), np.radians(80), 1e-6, trials=50, budget=TYPICAL.only("latitude_error"))
>>> s.rms_azimuth_error   # three-axis: atan2 ignores the latitude
0.0
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from schuler.core.earth import EARTH_RATE
from schuler.drift_calibration.error_budget import TYPICAL, ErrorBudget
from schuler.drift_calibration.procedure import ProcedureOutcome, run_procedure
from schuler.drift_calibration.stabilizer import Stabilizer
from schuler.exceptions import InvalidParameter


@dataclass(frozen=True)
class MonteCarloSummary:
    """Statistics of the recovered drifts and azimuth over Monte Carlo trials (SI).

    Attributes
    ----------
    trials : int
    mean_relative_drift_error, rms_relative_drift_error : float
        Mean of |omega_d error| / |omega_d| and the RMS of the signed relative
        error, over both gyros in three-axis mode (dimensionless).
    mean_drift_error, rms_drift_error : float
        Signed mean and RMS of the drift error, rad/s.
    mean_azimuth_error, rms_azimuth_error, mean_abs_azimuth_error : float
        Of the azimuth error, rad.
    drift_errors, azimuth_errors : ndarray
        Every trial's errors (rad/s, shape (trials, channels); rad, shape (trials,)).
    """

    trials: int
    mean_relative_drift_error: float
    rms_relative_drift_error: float
    mean_drift_error: float
    rms_drift_error: float
    mean_azimuth_error: float
    rms_azimuth_error: float
    mean_abs_azimuth_error: float
    drift_errors: np.ndarray = field(repr=False)
    azimuth_errors: np.ndarray = field(repr=False)


def drift_errors_of(outcome: ProcedureOutcome, drift_x, drift_y, mode: str) -> np.ndarray:
    """Recovered minus true own drifts, shape (M, channels), rad/s."""
    columns = [outcome.drift_x - drift_x]
    if mode == "three-axis":
        columns.append(outcome.drift_y - drift_y)
    return np.column_stack(columns)


def monte_carlo(
    stabilizer: Stabilizer,
    latitude: float,
    azimuth: float,
    drift_x: float,
    drift_y: float | None = None,
    *,
    budget: ErrorBudget = TYPICAL,
    trials: int = 1000,
    mode: str = "three-axis",
    positions: int = 2,
    cycles: int = 1,
    seed: int = 0,
    chunk_size: int = 2000,
    earth_rate: float = EARTH_RATE,
    steps: int = 40,
) -> MonteCarloSummary:
    """Vectorised Monte Carlo of the whole procedure over an error budget.

    The stabilizer's loop time constant is replaced by the budget's. Members are
    simulated ``chunk_size`` at a time (bounded memory), all of a chunk at once.

    Parameters
    ----------
    stabilizer : Stabilizer
    latitude, azimuth : float
        Site latitude and true azimuth A0, rad.
    drift_x, drift_y : float
        True own drifts, rad/s (drift_y defaults to drift_x; must be nonzero for relative errors).
    budget : ErrorBudget
    trials : int
        Number of simulated procedures (>= 1).
    mode, positions, cycles : as in :func:`~schuler.drift_calibration.procedure.run_procedure`.
    seed : int
        Seed of the random generator.

    Returns
    -------
    MonteCarloSummary
    """
    if trials < 1:
        raise InvalidParameter("monte_carlo", "need at least one trial")
    drift_y = drift_x if drift_y is None else drift_y
    if drift_x == 0 or drift_y == 0:
        raise InvalidParameter("drift", "relative drift errors need a nonzero drift")
    instrument = dataclasses.replace(stabilizer, loop_time_constant=budget.loop_time_constant,
                                     sway_frequency=budget.sway_frequency)
    rng = np.random.default_rng(seed)
    drift_parts, azimuth_parts = [], []
    for start in range(0, trials, chunk_size):
        count = min(chunk_size, trials - start)
        outcome = run_procedure(instrument, latitude, azimuth, drift_x, drift_y, mode=mode, positions=positions,
                                cycles=cycles, budget=budget, members=count, rng=rng, earth_rate=earth_rate,
                                steps=steps)
        drift_parts.append(drift_errors_of(outcome, drift_x, drift_y, mode))
        azimuth_parts.append(outcome.azimuth_error)
    drift_errors = np.concatenate(drift_parts)
    azimuth_errors = np.concatenate(azimuth_parts)
    truth = np.array([drift_x, drift_y][: drift_errors.shape[1]])
    relative = drift_errors / np.abs(truth)
    return MonteCarloSummary(
        trials=trials,
        mean_relative_drift_error=float(np.mean(np.abs(relative))),
        rms_relative_drift_error=float(np.sqrt(np.mean(relative**2))),
        mean_drift_error=float(np.mean(drift_errors)),
        rms_drift_error=float(np.sqrt(np.mean(drift_errors**2))),
        mean_azimuth_error=float(np.mean(azimuth_errors)),
        rms_azimuth_error=float(np.sqrt(np.mean(azimuth_errors**2))),
        mean_abs_azimuth_error=float(np.mean(np.abs(azimuth_errors))),
        drift_errors=drift_errors,
        azimuth_errors=azimuth_errors,
    )
