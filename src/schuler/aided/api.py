"""The aided-navigation system on the contract: ``SYSTEM`` (``schuler aided``).

The pieces: :mod:`~schuler.aided.evaluation` (parameters, outputs, ``evaluate``
with histories; on files through :mod:`~schuler.aided.files`),
:mod:`~schuler.aided.plots` (``figures``), :mod:`~schuler.aided.outputs` (the
result type keeping the navigation, and ``data_files``: ``navigation.nav`` and
``navigation.csv``), :mod:`~schuler.aided.reproduction` (``reproduce``,
``report``).

Examples
--------
>>> r = SYSTEM.run(duration=300.0, outage_start=120.0, nominal=True)
>>> r.position_error_horizontal_max_m < 1e-3, r.outages[0]["duration_s"]
(True, 60.0)
"""

from __future__ import annotations

from schuler.aided.evaluation import OUTPUTS, PARAMETERS, evaluate, member_bytes
from schuler.aided.files import is_file_case, record_samples
from schuler.aided.outputs import AidedResult, data_files
from schuler.aided.plots import figures
from schuler.aided.reproduction import SPECIFICATION, report, reproduce
from schuler.contract import System
from schuler.navigate.truth import sample_count
from schuler.params import Case

SECONDS_PER_SAMPLE = 4e-6
SECONDS_PER_MEMBER = 0.2
"""Time of one member, s: a fixed part (the drive, the filter's set-up) and one per IMU sample (the truth, the IMU
errors of the tactical grade's full model and the filter: 300-s drive at 100 Hz, 0.25 s; one core). A run on files
counts its record's samples (from the file's size)."""


def member_seconds(case: Case) -> float:
    """Time one member takes, s.

    Parameters
    ----------
    case : Case
        A validated case (SI: ``duration`` s, ``imu_rate`` Hz).
    """
    samples = record_samples(case) if is_file_case(case) else sample_count(case["duration"], case["imu_rate"])
    return SECONDS_PER_MEMBER + SECONDS_PER_SAMPLE * samples


SYSTEM = System(
    name="aided",
    title="The INS aided by GNSS in an error-state Kalman filter, through outages",
    reference=SPECIFICATION,
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    reproduce=reproduce,
    report=report,
    figures=figures,
    data_files=data_files,
    result_type=AidedResult,
    random_terms=True,
    realisation=True,
    member_bytes=member_bytes,
    member_seconds=member_seconds,
    guide="aided",
)

__all__ = ["SYSTEM"]
