"""The mission study on the contract: ``SYSTEM`` (``schuler mission``).

The pieces: :mod:`~schuler.mission.evaluation` (parameters, outputs,
``evaluate``, ``run_case``), :mod:`~schuler.mission.reproduction` (``reproduce``,
``report``), :mod:`~schuler.mission.results` (the result type and ``write_files``).

Examples
--------
>>> r = SYSTEM.run(grade="navigation", trajectory="stationary", duration=3600.0)
>>> round(sum(r.budget.values()), 6)
1.0
"""

from __future__ import annotations

from schuler.contract import System
from schuler.mission.evaluation import OUTPUTS, PARAMETERS, evaluate, member_bytes, run_case
from schuler.mission.reproduction import SOURCE, report, reproduce
from schuler.mission.results import write_files

SYSTEM = System(
    name="mission",
    title="An inertial system's life: calibrate, align, navigate, with an error budget",
    reference=SOURCE,
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    run_case=run_case,
    reproduce=reproduce,
    write_files=write_files,
    report=report,
    random_terms=True,
    member_bytes=member_bytes,
    guide="mission",
)

__all__ = ["SYSTEM"]
