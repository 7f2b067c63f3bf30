"""The navigation-error system on the contract: ``SYSTEM`` (``schuler errors``).

Source: Bollay (1966), "The Story of 84 Minutes" (:data:`schuler.references.BOLLAY_1966`).
The pieces: :mod:`~schuler.navigation_errors.evaluation` (``run``'s parameters,
outputs, ``evaluate``), :mod:`~schuler.navigation_errors.reproduction`
(``reproduce``, ``report``, the ``plot`` action), :mod:`~schuler.navigation_errors.actions`
(``vertical``, ``period``), :mod:`~schuler.navigation_errors.three_d_run` (``three-d``),
:mod:`~schuler.navigation_errors.optimal` (``optimal``: the baro loop's gains beside the Kalman filter's)
and :mod:`~schuler.navigation_errors.files` (``figures``, ``data_files``).

Examples
--------
>>> r = SYSTEM.run(source="velocity", magnitude=0.3048, earth="bollay")
>>> round(r.max_spherical_m / 0.3048)
805
"""

from __future__ import annotations

from functools import partial

from schuler.contract import Action, System
from schuler.imu.instrument import apply_options, instrument_options
from schuler.navigation_errors.actions import (
    PERIOD_PARAMETERS,
    VERTICAL_PARAMETERS,
    period,
    vertical,
)
from schuler.navigation_errors.evaluation import (
    FIDELITIES,
    OUTPUTS,
    PARAMETERS,
    evaluate,
    member_bytes,
)
from schuler.navigation_errors.files import data_files, figures
from schuler.navigation_errors.optimal import OPTIMAL, baro_loop, optimal
from schuler.navigation_errors.reproduction import (
    PLOT_PARAMETERS,
    plot,
    report,
    reproduce,
)
from schuler.navigation_errors.results import ErrorRunResult
from schuler.navigation_errors.three_d_run import THREE_D_PARAMETERS, three_d
from schuler.params import Case
from schuler.references import BOLLAY_1966

ACTIONS = (
    Action("vertical", "Vertical channel: pure-inertial divergence (Problem 4) vs a baro-aided loop.\n\n"
           "The altitude error of a vertical accelerometer with a bias (measured - true along up) diverges as "
           "cosh(sqrt(2) omega_s t); a second- or third-order baro-aided loop (critically damped at tau, or "
           "explicit gains) holds it. Figures and CSV with --out.", vertical, VERTICAL_PARAMETERS),
    Action("period", "Effective Schuler period under vertical thrust and in fast level flight.\n\n"
           "T = 2 pi sqrt(R / g_eff): g_eff = n g under a thrust of n times the weight, g - V^2 / r in level "
           "flight at speed V (Bollay's footnote). The period-versus-speed figure with --out.", period,
           PERIOD_PARAMETERS),
    Action("plot", "Problem 3's curves: each error source flat vs spherical, the overview, Problem 4.\n\n"
           "Prints the largest errors; --out DIR writes the figures (PNG, SVG) and their data (CSV).", plot,
           PLOT_PARAMETERS),
    Action("three-d", "The 3-D psi-angle error model on the rotating Earth (beyond the source).\n\n"
           "Stationary or constant-velocity vehicle at a latitude: platform drifts in the level frame "
           "(-(gyro bias), deg/h), accelerometer biases in the level frame (measured - true), initial velocity "
           "and attitude errors; Schuler, Foucault and 24-hour modes. Figures and CSV with --out.", three_d,
           THREE_D_PARAMETERS),
    OPTIMAL,
)
"""The commands of ``schuler errors`` beyond ``run`` and ``reproduce``."""

MEMBER_SECONDS = 1.5e-5
"""Time of one member, s: the closed forms are vectorised and one simulation serves every member of a grid
(1000 members of the default case: 15 ms; one thread, quiet 2-core machine)."""


def member_seconds(case: Case) -> float:
    """Time one member takes, s (:data:`MEMBER_SECONDS`, whatever the case).

    Parameters
    ----------
    case : Case
        A validated case (SI values).
    """
    return MEMBER_SECONDS


SYSTEM = System(
    name="errors",
    title="Schuler-tuned INS error propagation",
    reference=BOLLAY_1966.citation,
    parameters=PARAMETERS,
    outputs=OUTPUTS,
    evaluate=evaluate,
    reproduce=reproduce,
    figures=figures,
    data_files=data_files,
    result_type=ErrorRunResult,
    report=report,
    fidelities=FIDELITIES,
    actions=ACTIONS,
    member_bytes=member_bytes,
    member_seconds=member_seconds,
    guide="errors",
    instrument=partial(apply_options, "errors"),
    instrument_parameters=instrument_options("errors"),
)

__all__ = ["ACTIONS", "SYSTEM", "baro_loop", "optimal"]
