"""The mission study on the contract: ``SYSTEM`` (``schuler mission``).

The pieces: :mod:`~schuler.mission.evaluation` (parameters, outputs,
``evaluate`` with histories), :mod:`~schuler.mission.plots` (``figures``),
:mod:`~schuler.mission.reproduction` (``reproduce``, ``report``),
:mod:`~schuler.mission.results` (the result type, rendered as a budget).

Examples
--------
>>> r = SYSTEM.run(imu="navigation", trajectory="stationary", duration=3600.0)
>>> round(sum(r.budget.values()), 6), list(r.figures())
(1.0, ['mission_budget'])
"""

from __future__ import annotations

from schuler.contract import System
from schuler.mission.evaluation import OUTPUTS, PARAMETERS, evaluate, member_bytes
from schuler.mission.plots import figures
from schuler.mission.reproduction import SOURCE, report, reproduce
from schuler.mission.results import MissionResult
from schuler.params import Case

SECONDS_PER_SAMPLE = 8e-7
"""Time of one IMU interval of one member's mission, s (the default 2-h cruise at 2 Hz: 11 ms per member over 20
members; 4 h: 23 ms; one thread, quiet 2-core machine)."""


SECONDS_PER_FILTER_STEP = 6e-5
"""Time of one covariance step of one aided member's filter, s (the 1-h tactical drive at 1-s steps: 191 s for
1000 members; the 2-h navigation-grade flight at 5-s steps: 75 s; one core)."""


def member_seconds(case: Case) -> float:
    """Time one member takes, s: its IMU intervals (duration x rate) times :data:`SECONDS_PER_SAMPLE`, and aided
    its filter's covariance steps (duration / covariance interval) times :data:`SECONDS_PER_FILTER_STEP`.

    Parameters
    ----------
    case : Case
        A validated case (SI values: ``duration`` and ``covariance_interval`` s, ``imu_rate`` Hz, ``aiding``).
    """
    inertial = SECONDS_PER_SAMPLE * case["duration"] * case["imu_rate"]
    if case["aiding"] is None:
        return inertial
    return inertial + SECONDS_PER_FILTER_STEP * case["duration"] / case["covariance_interval"]


SYSTEM = System(
    name="mission",
    title="An inertial system's life: calibrate, align, navigate, with an error budget",
    reference=SOURCE,
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    reproduce=reproduce,
    figures=figures,
    result_type=MissionResult,
    report=report,
    random_terms=True,
    member_bytes=member_bytes,
    member_seconds=member_seconds,
    guide="mission",
)

__all__ = ["SYSTEM"]
