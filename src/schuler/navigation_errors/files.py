"""The figures and data files of ``schuler errors``: :func:`figures` and :func:`data_files`.

:func:`figures` draws the figures of any result of the system (run, reproduce,
vertical, period, plot, three-d); :func:`data_files` writes the tables that are
not a run's histories as CSV, the unit in each column name (``t_s``,
``unaided_m``). Figures show feet (Bollay's unit) for Problem 3 and metres for
runs of other cases.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from schuler.io import write_dataframe_csv
from schuler.navigation_errors import plots
from schuler.navigation_errors.effective_period import (
    effective_schuler_period,
    flight_gravity,
)
from schuler.navigation_errors.inputs import SOURCE_DEFAULTS, SOURCE_UNITS
from schuler.navigation_errors.results import (
    PeriodResult,
    Problem3Curves,
    Problem3Figures,
    VerticalChannelResult,
)
from schuler.navigation_errors.single_channel import SOURCES
from schuler.navigation_errors.three_d_run import ThreeDResult
from schuler.reproduction import Reproduction
from schuler.results import Result, SystemResult

PERIOD_CURVE_POINTS = 400
"""Speeds of the period figure between rest and 99.9 % of the orbital speed."""


def figures(result: Result) -> dict[str, Any]:
    """The figures of any ``schuler errors`` result, file stem -> Figure ({} for a result without figures).

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned.
    """
    if isinstance(result, Reproduction):
        return problem3_figures(result.data)
    if isinstance(result, Problem3Figures):
        return problem3_figures(result.curves)
    if isinstance(result, SystemResult):
        return _run_figures(result)
    if isinstance(result, VerticalChannelResult):
        return {"errors_vertical_run": plots.plot_vertical(
            result.t_s, result.unaided_m, {f"baro-aided, order {result.order}": result.aided_m}, "m",
            "Vertical channel: pure inertial vs baro-aided")}
    if isinstance(result, PeriodResult):
        speeds, periods = _period_curve(result)
        return {"errors_period": plots.plot_period(speeds, periods, result.speed_m_s, result.orbital_speed_m_s,
                                                   "Effective Schuler period in level flight")}
    if isinstance(result, ThreeDResult):
        return _three_d_figures(result)
    return {}


def data_files(result: Result, out_dir: Path) -> list[Path]:
    """The CSV files of a result beside its histories: the tables of Problems 3 and 4 and of the actions.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned.
    out_dir : Path
        Folder the files are written into (created if missing).

    Returns
    -------
    list of Path
        The files written (none for a run: its histories are its CSV).
    """
    import pandas as pd

    out_dir = Path(out_dir)
    if isinstance(result, (Reproduction, Problem3Figures)):
        return problem3_tables(result.data if isinstance(result, Reproduction) else result.curves, out_dir)
    if isinstance(result, VerticalChannelResult):
        return [write_dataframe_csv(result.to_dataframe(), out_dir / "errors_vertical_run.csv")]
    if isinstance(result, PeriodResult):
        speeds, periods = _period_curve(result)
        return [write_dataframe_csv(pd.DataFrame({"speed_m_s": speeds, "period_s": periods}),
                                    out_dir / "errors_period.csv")]
    if isinstance(result, ThreeDResult):
        return [write_dataframe_csv(result.to_dataframe(), out_dir / "errors_three_d.csv")]
    return []


def problem3_figures(curves: Problem3Curves) -> dict[str, Any]:
    """Problem 3's figures (each source, flat vs spherical; the log overview) and Problem 4's.

    Parameters
    ----------
    curves : Problem3Curves
        The curves to draw (SI: times in s, errors in m; the figures show them in ft).

    Returns
    -------
    dict of str to Figure
        ``errors_<source>`` per source, ``errors_overview`` and ``errors_vertical``.
    """
    drawn = {}
    for source in SOURCES:
        drawn[f"errors_{source}"] = plots.plot_flat_vs_spherical(
            curves.t_s, curves.flat_m[source], curves.spherical_m[source], "ft",
            f"Problem 3: {plots.SOURCE_TITLES[source]} ({SOURCE_DEFAULTS[source]:g} {SOURCE_UNITS[source]})",
            simulated=(curves.t_simulated_s, curves.simulated_m[source]),
        )
    drawn["errors_overview"] = plots.plot_overview(curves.t_s, curves.flat_m, curves.spherical_m, "ft",
                                                   "Problem 3: all five error sources, flat vs spherical Earth")
    drawn["errors_vertical"] = plots.plot_vertical(curves.vertical_t_s, curves.vertical_unaided_m,
                                                   curves.vertical_aided_m, "ft",
                                                   "Problem 4: hover with an accelerometer reading 1e-4 g low")
    return drawn


def problem3_tables(curves: Problem3Curves, out_dir: Path) -> list[Path]:
    """The data of Problem 3's and Problem 4's figures: ``errors_problem3.csv``, ``errors_problem4.csv``.

    Parameters
    ----------
    curves : Problem3Curves
        The curves (SI: times in s, errors in m).
    out_dir : Path
        Folder the files are written into (created if missing).

    Returns
    -------
    list of Path
        The two files written (columns in s and m).
    """
    import pandas as pd

    columns = {"t_s": curves.t_s}
    for source in SOURCES:
        columns[f"{source}_flat_m"] = curves.flat_m[source]
        columns[f"{source}_spherical_m"] = curves.spherical_m[source]
    vertical = {"t_s": curves.vertical_t_s, "unaided_m": curves.vertical_unaided_m}
    vertical.update({f"aided_order_{k + 2}_m": v for k, v in enumerate(curves.vertical_aided_m.values())})
    return [write_dataframe_csv(pd.DataFrame(columns), Path(out_dir) / "errors_problem3.csv"),
            write_dataframe_csv(pd.DataFrame(vertical), Path(out_dir) / "errors_problem4.csv")]


def _run_figures(result: SystemResult) -> dict[str, Any]:
    stem = f"errors_run_{result.source}"
    histories = result.histories[stem]
    unit = "ft" if result.earth == "bollay" else "m"
    simulated = (histories.time, histories["simulated_m"]) if "simulated_m" in histories else None
    return {stem: plots.plot_flat_vs_spherical(histories.time, histories["flat_m"], histories["spherical_m"], unit,
                                               f"{plots.SOURCE_TITLES[result.source]}: flat vs spherical Earth",
                                               simulated=simulated)}


def _period_curve(result: PeriodResult) -> tuple[np.ndarray, np.ndarray]:
    speeds = np.linspace(0.0, 0.999 * result.orbital_speed_m_s, PERIOD_CURVE_POINTS)
    return speeds, effective_schuler_period(result.radius_m,
                                            flight_gravity(result.gravity_m_s2, speeds, result.path_radius_m))


def _three_d_figures(result: ThreeDResult) -> dict[str, Any]:
    unit = "m"
    latitude = np.degrees(result.latitude_rad)
    return {
        "errors_three_d": plots.plot_three_d(result.t_s, result.states, unit,
                                             f"3-D psi-angle errors at {latitude:.4g} deg"),
        "errors_three_d_track": plots.plot_foucault(result.t_s, result.states["position_error_north"],
                                                    result.states["position_error_east"], unit,
                                                    f"Horizontal position error at {latitude:.4g} deg"),
    }
