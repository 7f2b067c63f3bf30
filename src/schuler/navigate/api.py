"""The nonlinear INS on the contract: ``SYSTEM`` (``schuler navigate``).

The pieces: :mod:`~schuler.navigate.evaluation` (parameters, outputs,
``evaluate`` with histories), :mod:`~schuler.navigate.reproduction` (the seeds'
linear models against the nonlinear INS: ``reproduce``, ``report``),
:mod:`~schuler.navigate.results` (the result type, ``figures``, ``data_files``).

``imu`` is a grade or a spec file; ``record`` a recorded IMU file
(:mod:`~schuler.navigate.recording`): a static vehicle, its increments
navigated in place of the ideal IMU and its errors (computed - true) taken
against a stationary truth at its site and initial attitude, for its length and
at its rate; one member, so no Monte Carlo. A run without Monte Carlo is the
nominal case (no noise, an error model's constant errors at +1 sigma).

Examples
--------
>>> import math
>>> r = SYSTEM.run(latitude=math.radians(45), velocity_error_north=0.1, duration=600.0, imu_rate=10.0,
...                output_step=60.0)
>>> round(r.final_position_error_north_m, 1)   # (dV / w_s) sin(w_s t) at 45 deg
54.6
"""

from __future__ import annotations

from schuler.contract import System
from schuler.navigate import imu_noise
from schuler.navigate.evaluation import OUTPUTS, PARAMETERS, evaluate, member_bytes, setup
from schuler.navigate.reproduction import report, reproduce
from schuler.navigate.results import NavigateResult, data_files, figures
from schuler.params import Case
from schuler.references import GROVES_2013

SECONDS_PER_SAMPLE = 6e-8
NOISY_SECONDS_PER_SAMPLE = 4e-7
"""Time of one IMU interval of one member, s, with an ideal IMU and with an IMU's noise (600 s at 100 Hz, 20
members: 3.2-4.3 and 23 ms per member; one thread, quiet 2-core machine; benchmarks/bench_navigate.py asks >= 10 M
and >= 3 M member-samples/s)."""


def member_seconds(case: Case) -> float:
    """Time one member takes, s: its IMU intervals (duration x rate) at the pace of an ideal or a noisy IMU.

    Parameters
    ----------
    case : Case
        A validated case (SI values).
    """
    shared = setup(case)
    noisy = shared.model is not None and imu_noise.has_noise(shared.model)
    return (NOISY_SECONDS_PER_SAMPLE if noisy else SECONDS_PER_SAMPLE) * shared.duration * shared.imu_rate


SYSTEM = System(
    name="navigate",
    title="Nonlinear strapdown or platform INS on WGS-84",
    reference=GROVES_2013.citation,
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    reproduce=reproduce,
    figures=figures,
    data_files=data_files,
    result_type=NavigateResult,
    report=report,
    random_terms=True,
    member_bytes=member_bytes,
    member_seconds=member_seconds,
    guide="navigate",
)

__all__ = ["SYSTEM"]
