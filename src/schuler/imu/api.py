"""The IMU layer on the contract: ``SYSTEM`` (``schuler imu``).

Sources: the grade presets' data sheets (:mod:`~schuler.imu.spec`), IEEE Std
952-1997 Annex C for the Allan-variance terms, the PSINS toolbox's
``lasergyro.imu`` for the real recording. The pieces:
:mod:`~schuler.imu.evaluation` (parameters, outputs, ``evaluate``),
:mod:`~schuler.imu.reproduction` (``reproduce``, ``report``),
:mod:`~schuler.imu.run_results` (how a run renders),
:mod:`~schuler.imu.plots` (``figures``, ``data_files``),
:mod:`~schuler.imu.actions` (``info``, ``allan``, ``simulate``).

Examples
--------
>>> r = SYSTEM.run(imu="consumer", duration=600.0)
>>> r.to_dict()["noise"]["gyro_x"]["N"] > 0, r.all_within
(True, True)
"""

from __future__ import annotations

from schuler.contract import System
from schuler.imu.actions import ACTIONS
from schuler.imu.evaluation import OUTPUTS, PARAMETERS, evaluate, member_bytes, sample_interval
from schuler.imu.plots import data_files, figures
from schuler.imu.reproduction import REPRODUCE_PARAMETERS, report, reproduce
from schuler.imu.run_results import ImuRun
from schuler.params import Case

SECONDS_PER_SAMPLE = 1.4e-6
"""Time of one six-axis sample of a member's record and its analysis, s (1 h at 100 Hz: 0.89 s per member; 600 s at
1 kHz: 0.81 s; one thread, quiet 2-core machine)."""


def member_seconds(case: Case) -> float:
    """Time one member takes, s: its samples times :data:`SECONDS_PER_SAMPLE`.

    Parameters
    ----------
    case : Case
        A validated case (SI values: ``duration`` s, ``imu_rate`` Hz, ``output_step`` s).
    """
    return SECONDS_PER_SAMPLE * max(1.0, case["duration"] / sample_interval(case["imu_rate"], case["output_step"]))


SYSTEM = System(
    name="imu",
    title="IMU recordings, spec-sheet error models and Allan variance",
    reference="IEEE Std 952-1997, \"IEEE Standard Specification Format Guide and Test Procedure for Single-Axis "
              "Interferometric Fiber Optic Gyros\", Annex C, 1998; N. El-Sheimy, H. Hou, X. Niu, \"Analysis and "
              "modeling of inertial sensors using Allan variance\", IEEE Trans. Instrum. Meas. 57(1), 2008",
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    reproduce=reproduce,
    reproduce_parameters=REPRODUCE_PARAMETERS,
    figures=figures,
    data_files=data_files,
    result_type=ImuRun,
    report=report,
    actions=ACTIONS,
    random_terms=True,
    member_bytes=member_bytes,
    member_seconds=member_seconds,
    guide="imu",
)

__all__ = ["SYSTEM"]
