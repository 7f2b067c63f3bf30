"""The ground gyrocompass system on the contract: ``SYSTEM`` (``schuler north``).

Source: Fedorov, Kikot, Shtefan (2020) (:data:`schuler.references.FEDOROV_2020`).
The pieces: :mod:`~schuler.ground_gyrocompass.evaluation` (parameters, outputs,
``evaluate``), :mod:`~schuler.ground_gyrocompass.reproduction`
(``reproduce``), :mod:`~schuler.ground_gyrocompass.report` (``report``),
:mod:`~schuler.ground_gyrocompass.results` (how a run renders, the actions'
results), :mod:`~schuler.ground_gyrocompass.files` (the figures and data files),
:mod:`~schuler.ground_gyrocompass.actions` (``identify`` and ``simulate``).

Examples
--------
>>> import math
>>> r = SYSTEM.run(unknowns=2)
>>> round(math.degrees(r.north_rad), 6), abs(r.north_error_rad) < 1e-12
(-1.23, True)
>>> list(r.to_dataframe().columns), list(r.figures())
(['observed_rad', 'fitted_rad', 'residual_rad'], ['north_fit', 'north_misfit_map', 'north_error_vs_time'])
"""

from __future__ import annotations

from functools import partial

from schuler.alignment.commands import north_compare_action
from schuler.contract import System
from schuler.ground_gyrocompass.actions import ACTIONS
from schuler.ground_gyrocompass.evaluation import (
    FIDELITIES,
    OUTPUTS,
    PARAMETERS,
    evaluate,
    member_bytes,
    sample_count,
)
from schuler.ground_gyrocompass.files import data_files, figures
from schuler.ground_gyrocompass.report import report
from schuler.ground_gyrocompass.reproduction import REPRODUCE_PARAMETERS, reproduce
from schuler.ground_gyrocompass.results import NorthRun
from schuler.imu.instrument import apply_options, instrument_options
from schuler.params import Case
from schuler.references import FEDOROV_2020

SECONDS_PER_FIT = 1.3e-3
SECONDS_PER_SAMPLE = 3.3e-6
"""Time of one member, s: its fit and its record's samples (200 s at 1 s: 2.0 ms; 2000 s: 8.0 ms; one thread of a busy
2-core machine)."""


def member_seconds(case: Case) -> float:
    """Time one member takes, s: a fit plus its record's samples.

    Parameters
    ----------
    case : Case
        A validated case (SI values: ``duration`` and ``output_step`` s).
    """
    return SECONDS_PER_FIT + SECONDS_PER_SAMPLE * sample_count(case["duration"], case["output_step"])


SYSTEM = System(
    name="north",
    title="Ground gyrocompass during natural rotor run-down",
    reference=FEDOROV_2020.citation,
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    reproduce=reproduce,
    reproduce_parameters=REPRODUCE_PARAMETERS,
    figures=figures,
    data_files=data_files,
    result_type=NorthRun,
    report=report,
    fidelities=FIDELITIES,
    actions=(*ACTIONS, north_compare_action(PARAMETERS, evaluate)),
    random_terms=True,
    member_bytes=member_bytes,
    member_seconds=member_seconds,
    guide="north",
    instrument=partial(apply_options, "north"),
    instrument_parameters=instrument_options("north"),
)

__all__ = ["SYSTEM"]
