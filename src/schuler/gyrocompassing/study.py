"""The lab's tasks (source 003, Sec. 3) as functions: one case, sweeps, Monte Carlo, phase trajectory.

One namespace over three modules:

- :mod:`~schuler.gyrocompassing.case`: :class:`AlignmentCase` (one case or N
  cases, validation, gains), the closed forms of many cases at once
  (:func:`analytic_results`), the time grid and run length;
- :mod:`~schuler.gyrocompassing.simulation`: :func:`run_case` (one case on the
  chosen model, constraints checked over the whole run) and
  :func:`evaluate_cases` (closed form and, optionally, N cases simulated in
  chunks on :mod:`schuler.core.lti`);
- :mod:`~schuler.gyrocompassing.monte_carlo`: :func:`monte_carlo` over residual
  drifts and accelerometer errors.

The phase trajectory of task 5 is the (delta, beta) history of a
:class:`CaseRun` (plotted by :func:`schuler.gyrocompassing.plots.phase_trajectory`).
"""

from __future__ import annotations

from schuler.core.earth import EARTH_RATE
from schuler.gyrocompassing.case import (
    DEFAULT_DAMPING,
    DEFAULT_DURATION,
    DEFAULT_INITIAL_AZIMUTH_ERROR,
    DEFAULT_LATITUDE,
    DEFAULT_MAX_LATITUDE,
    DEFAULT_TIME_CONSTANT,
    DEGRADED_LATITUDE,
    MAX_DURATION,
    MAX_TIME_POINTS,
    AlignmentCase,
    DegradedAccuracyWarning,
    analytic_results,
    automatic_duration,
    check_model,
    sweep_grid,
    time_grid,
)
from schuler.gyrocompassing.monte_carlo import MonteCarloRun, monte_carlo
from schuler.gyrocompassing.simulation import (
    MAX_BETA,
    MAX_DELTA,
    MAX_DELTA_RATE,
    SETTLING_BAND,
    CaseRun,
    SimulatedCases,
    constraint_violations,
    evaluate_cases,
    run_case,
    simulate_cases,
)

__all__ = [
    "DEFAULT_DAMPING", "DEFAULT_DURATION", "DEFAULT_INITIAL_AZIMUTH_ERROR", "DEFAULT_LATITUDE",
    "DEFAULT_MAX_LATITUDE", "DEFAULT_TIME_CONSTANT", "DEGRADED_LATITUDE", "EARTH_RATE", "MAX_BETA", "MAX_DELTA",
    "MAX_DELTA_RATE", "MAX_DURATION", "MAX_TIME_POINTS", "SETTLING_BAND", "AlignmentCase", "CaseRun",
    "DegradedAccuracyWarning", "MonteCarloRun", "SimulatedCases", "analytic_results", "automatic_duration",
    "check_model", "constraint_violations", "evaluate_cases", "monte_carlo", "run_case", "simulate_cases",
    "sweep_grid", "time_grid",
]
