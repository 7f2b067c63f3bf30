"""The gyro vertical on the contract: ``SYSTEM`` (``schuler vertical``).

Source: Drozdovich, "On an inertial method of measuring velocities" (1959)
(:data:`schuler.references.DROZDOVICH_1959`). The pieces:
:mod:`~schuler.gyro_vertical.evaluation` (parameters, outputs, ``evaluate``),
:mod:`~schuler.gyro_vertical.actions` (``friction``),
:mod:`~schuler.gyro_vertical.optimal` (``optimal``: the seed beside the Kalman loop; its library functions
are exported here),
:mod:`~schuler.gyro_vertical.reproduction` (``reproduce``, ``report``),
:mod:`~schuler.gyro_vertical.results` (the result types, ``figures`` and ``data_files``).

Examples
--------
>>> import math
>>> r = SYSTEM.run(latitude=math.radians(60), earth="drozdovich", duration=6 * 3600.0)
>>> round(r.steady_velocity_error_y_m_s, 3), round(r.split_period_fast_s / 60, 2)
(0.557, 82.45)
"""

from __future__ import annotations

from functools import partial

from schuler.contract import System
from schuler.core.geometry import grid_points
from schuler.gyro_vertical.actions import FRICTION
from schuler.gyro_vertical.evaluation import (
    FIDELITIES,
    GRID_NAMES,
    OUTPUTS,
    PARAMETERS,
    evaluate,
    member_bytes,
)
from schuler.gyro_vertical.optimal import (
    OPTIMAL,
    level_gains,
    level_gains_from_period,
    level_noise_ratios,
    level_period_damping,
    optimal,
    vertical_loop,
)
from schuler.gyro_vertical.reproduction import report, reproduce
from schuler.gyro_vertical.results import VerticalResult, data_files, figures
from schuler.imu.instrument import apply_options, instrument_options
from schuler.params import Case, ParameterSet
from schuler.references import DROZDOVICH_1959

SECONDS_PER_POINT = 2e-5
"""Time of one output point of one case's simulation, s (48 h at 10 s, 17,281 points: 0.33 s; one thread of a busy
2-core machine)."""


def member_seconds(case: Case) -> float:
    """Time one case takes, s: its output points times :data:`SECONDS_PER_POINT`.

    Parameters
    ----------
    case : Case
        A validated case (SI values: ``duration`` and ``output_step`` s).
    """
    return SECONDS_PER_POINT * grid_points(case["duration"], case["output_step"], names=GRID_NAMES)


SYSTEM = System(
    name="vertical",
    title="Gyro vertical with integral correction measuring velocity",
    reference=DROZDOVICH_1959.citation,
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    reproduce=reproduce,
    reproduce_parameters=ParameterSet((), owner="vertical reproduce"),
    figures=figures,
    data_files=data_files,
    result_type=VerticalResult,
    report=report,
    fidelities=FIDELITIES,
    actions=(FRICTION, OPTIMAL),
    member_bytes=member_bytes,
    member_seconds=member_seconds,
    guide="vertical",
    instrument=partial(apply_options, "vertical"),
    instrument_parameters=instrument_options("vertical"),
)

__all__ = ["SYSTEM", "level_gains", "level_gains_from_period", "level_noise_ratios", "level_period_damping", "optimal",
           "vertical_loop"]
