"""The drift calibration system on the contract: ``SYSTEM`` (``schuler calibrate``).

Source: the alternating-pulse calibration article (:data:`schuler.references.PULSE_CALIBRATION`).
The pieces: :mod:`~schuler.drift_calibration.evaluation` (parameters, outputs,
``evaluate``), :mod:`~schuler.drift_calibration.reproduction`
(``reproduce``, ``report``), :mod:`~schuler.drift_calibration.results` (the
result type) and :mod:`~schuler.drift_calibration.plots` (``figures``).

Examples
--------
>>> import math
>>> r = SYSTEM.run(latitude=math.radians(70), azimuth=math.radians(80), drift_x=math.radians(0.1) / 3600)
>>> round(math.degrees(r.azimuth_rad), 6), round(math.degrees(r.drift_x_rad_s) * 3600, 9)
(80.0, 0.1)
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

from schuler.alignment.commands import calibrate_compare_action
from schuler.contract import System
from schuler.drift_calibration.evaluation import (
    OUTPUTS,
    PARAMETERS,
    evaluate,
    member_bytes,
)
from schuler.drift_calibration.reproduction import (
    REPRODUCE_PARAMETERS,
    report,
    reproduce,
)
from schuler.drift_calibration.results import CalibrationResult, data_files, figures
from schuler.imu.instrument import apply_options, instrument_options
from schuler.params import Case
from schuler.references import PULSE_CALIBRATION
from schuler.reproduction import Reproduction
from schuler.results import Result, SystemResult

SECONDS_PER_PHASE = 4e-5
"""Time of one position of one channel and cycle of a member's procedure, s (the default three-axis procedure,
2 channels x 2 positions x 1 cycle, 50 members: 0.15 ms per member; one thread, quiet 2-core machine)."""


def member_seconds(case: Case) -> float:
    """Time one member takes, s: channels x positions x cycles times :data:`SECONDS_PER_PHASE`.

    Parameters
    ----------
    case : Case
        A validated case (``mode``, ``positions``, ``cycles``).
    """
    channels = 1 if case["mode"] == "single-axis" else 2
    return SECONDS_PER_PHASE * channels * int(case["positions"]) * int(case["cycles"])


COMPARE = calibrate_compare_action(PARAMETERS, evaluate)
"""``calibrate compare``: built by :mod:`schuler.alignment`, which writes its files."""


def _files(result: Result, out_dir: Path) -> list[Path]:
    """The system's data files; a comparison's files from its own writer (the generic writer calls no action's)."""
    if COMPARE.write_files is not None and not isinstance(result, (SystemResult, Reproduction)):
        return COMPARE.write_files(result, out_dir)
    return data_files(result, out_dir)


SYSTEM = System(
    name="calibrate",
    title="Gyro drift calibration by alternating-sign torque pulses, with autonomous azimuth",
    reference=PULSE_CALIBRATION.citation,
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    reproduce=reproduce,
    reproduce_parameters=REPRODUCE_PARAMETERS,
    figures=figures,
    data_files=_files,
    result_type=CalibrationResult,
    report=report,
    actions=(COMPARE,),
    random_terms=True,
    member_bytes=member_bytes,
    member_seconds=member_seconds,
    guide="calibrate",
    instrument=partial(apply_options, "calibrate"),
    instrument_parameters=instrument_options("calibrate"),
)

__all__ = ["SYSTEM"]
