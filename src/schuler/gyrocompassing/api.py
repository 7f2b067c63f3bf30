"""The gyrocompassing system on the contract: ``SYSTEM`` (``schuler align``).

Source: Meleshko, KPI lab manual (:data:`schuler.references.KPI_LAB_MANUAL`).
The pieces: :mod:`~schuler.gyrocompassing.evaluation` (parameters, outputs,
``evaluate``), :mod:`~schuler.gyrocompassing.reproduction`
(``reproduce``, ``report``), :mod:`~schuler.gyrocompassing.results` (how a
result renders, its figures and data files).

Examples
--------
>>> import math
>>> r = SYSTEM.run(latitude=math.radians(50), drift_east=math.radians(0.01) / 3600)
>>> round(math.degrees(r.azimuth_error_analytic_rad) * 60, 3)
3.556
"""

from __future__ import annotations

from functools import partial

from schuler.alignment.commands import ALIGN_COMPARE
from schuler.contract import System
from schuler.gyrocompassing.case import DEFAULT_DURATION
from schuler.gyrocompassing.evaluation import FIDELITIES, OUTPUTS, PARAMETERS, evaluate, member_bytes
from schuler.gyrocompassing.optimal_run import OPTIMAL, optimal
from schuler.gyrocompassing.reproduction import report, reproduce
from schuler.gyrocompassing.results import AlignmentRun, data_files, figures
from schuler.imu.instrument import apply_options, instrument_options
from schuler.params import Case
from schuler.references import KPI_LAB_MANUAL

SECONDS_PER_MEMBER = 1e-4
SECONDS_PER_POINT = 3e-8
"""Time of one member, s: a fixed part and one per output point (default case, 7,200 points: 0.22 ms; 20,000 s at
1 s: 0.60 ms; one thread, quiet 2-core machine)."""


def member_seconds(case: Case) -> float:
    """Time one member takes, s (a duration not set counts as the usual automatic 2 h).

    Parameters
    ----------
    case : Case
        A validated case (SI values: ``duration`` and ``output_step`` s).
    """
    duration = case["duration"] or DEFAULT_DURATION
    return SECONDS_PER_MEMBER + SECONDS_PER_POINT * duration / case["output_step"]


SYSTEM = System(
    name="align",
    title="Physical gyrocompassing of a semi-analytic platform INS",
    reference=KPI_LAB_MANUAL.citation,
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    reproduce=reproduce,
    figures=figures,
    data_files=data_files,
    result_type=AlignmentRun,
    report=report,
    fidelities=FIDELITIES,
    actions=(ALIGN_COMPARE, OPTIMAL),
    random_terms=True,
    member_bytes=member_bytes,
    member_seconds=member_seconds,
    guide="align",
    instrument=partial(apply_options, "align"),
    instrument_parameters=instrument_options("align"),
)

__all__ = ["SYSTEM", "optimal"]
