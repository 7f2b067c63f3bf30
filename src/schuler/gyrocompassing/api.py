"""The gyrocompassing system on the contract: ``SYSTEM`` (``schuler align``).

Source: Meleshko, KPI lab manual (:data:`schuler.references.KPI_LAB_MANUAL`).
The pieces: :mod:`~schuler.gyrocompassing.evaluation` (parameters, outputs,
``evaluate``, ``run_case``), :mod:`~schuler.gyrocompassing.reproduction`
(``reproduce``, ``report``), :mod:`~schuler.gyrocompassing.results` (the result
type and ``write_files``).

Examples
--------
>>> import math
>>> r = SYSTEM.run(latitude=math.radians(50), drift_east=math.radians(0.01) / 3600)
>>> round(math.degrees(r.azimuth_error_analytic_rad) * 60, 3)
3.556
"""

from __future__ import annotations

from schuler.alignment.commands import ALIGN_COMPARE
from schuler.contract import System
from schuler.gyrocompassing.evaluation import FIDELITIES, OUTPUTS, PARAMETERS, evaluate, member_bytes, run_case
from schuler.gyrocompassing.reproduction import report, reproduce
from schuler.gyrocompassing.results import write_files
from schuler.references import KPI_LAB_MANUAL

SYSTEM = System(
    name="align",
    title="Physical gyrocompassing of a semi-analytic platform INS",
    reference=KPI_LAB_MANUAL.citation,
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    run_case=run_case,
    reproduce=reproduce,
    write_files=write_files,
    report=report,
    fidelities=FIDELITIES,
    actions=(ALIGN_COMPARE,),
    random_terms=True,
    member_bytes=member_bytes,
    guide="align",
)

__all__ = ["SYSTEM"]
