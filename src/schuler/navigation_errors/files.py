"""The one writer of ``schuler errors`` figures and data: :func:`write_files`.

Every figure is written as PNG and SVG, every history as CSV with the unit in
each column name (``t_s``, ``spherical_m``); files are written atomically
(:mod:`schuler.io`). Figures show feet (Bollay's unit) for Problem 3 and metres
for runs of other cases.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from schuler.io import save_figure_formats, write_dataframe_csv
from schuler.navigation_errors import plots
from schuler.navigation_errors.effective_period import (
    effective_schuler_period,
    flight_gravity,
)
from schuler.navigation_errors.inputs import SOURCE_DEFAULTS, SOURCE_UNITS
from schuler.navigation_errors.results import (
    ErrorRunResult,
    PeriodResult,
    Problem3Curves,
    Problem3Figures,
    VerticalResult,
)
from schuler.navigation_errors.single_channel import SOURCES
from schuler.navigation_errors.three_d_run import ThreeDResult
from schuler.reproduction import Reproduction
from schuler.results import Result

PERIOD_CURVE_POINTS = 400
"""Speeds of the period figure between rest and 99.9 % of the orbital speed."""


def write_files(result: Result, out_dir: Path, formats=("png", "svg")) -> list[Path]:
    """Figures and CSV of any ``schuler errors`` result (run, reproduce, vertical, period, plot, three-d).

    Parameters
    ----------
    result : Result
        What a command returned.
    out_dir : Path
        Folder (created if missing).
    formats : tuple of str
        Figure formats.

    Returns
    -------
    list of Path
        The files written.
    """
    out_dir = Path(out_dir)
    if isinstance(result, Reproduction):
        return write_problem3(result.data, out_dir, formats)
    if isinstance(result, Problem3Figures):
        return write_problem3(result.curves, out_dir, formats)
    if isinstance(result, ErrorRunResult):
        return _write_run(result, out_dir, formats)
    if isinstance(result, VerticalResult):
        return _write_vertical(result, out_dir, formats)
    if isinstance(result, PeriodResult):
        return _write_period(result, out_dir, formats)
    if isinstance(result, ThreeDResult):
        return _write_three_d(result, out_dir, formats)
    raise TypeError(f"errors writes no files for {type(result).__name__}")


def write_problem3(curves: Problem3Curves, out_dir: Path, formats=("png", "svg")) -> list[Path]:
    """Problem 3's figures (each source, flat vs spherical; the log overview), Problem 4's, and their CSV.

    Parameters
    ----------
    curves : Problem3Curves
        The curves to draw (SI: times in s, errors in m; the figures show them in ft).
    out_dir : Path
        Folder the files are written into (created if missing).
    formats : tuple of str
        Figure file formats (extensions such as ``"png"``, ``"svg"``).

    Returns
    -------
    list of Path
        The files written: per source, the overview and Problem 4 one figure per format, then
        ``errors_problem3.csv`` and ``errors_problem4.csv`` (columns in s and m).
    """
    import pandas as pd

    paths = []
    for source in SOURCES:
        fig = plots.plot_flat_vs_spherical(
            curves.t_s, curves.flat_m[source], curves.spherical_m[source], "ft",
            f"Problem 3: {plots.SOURCE_TITLES[source]} ({SOURCE_DEFAULTS[source]:g} {SOURCE_UNITS[source]})",
            simulated=(curves.t_simulated_s, curves.simulated_m[source]),
        )
        paths += save_figure_formats(fig, out_dir / f"errors_{source}", formats)
    fig = plots.plot_overview(curves.t_s, curves.flat_m, curves.spherical_m, "ft",
                              "Problem 3: all five error sources, flat vs spherical Earth")
    paths += save_figure_formats(fig, out_dir / "errors_overview", formats)
    fig = plots.plot_vertical(curves.vertical_t_s, curves.vertical_unaided_m, curves.vertical_aided_m, "ft",
                              "Problem 4: hover with an accelerometer reading 1e-4 g low")
    paths += save_figure_formats(fig, out_dir / "errors_vertical", formats)
    columns = {"t_s": curves.t_s}
    for source in SOURCES:
        columns[f"{source}_flat_m"] = curves.flat_m[source]
        columns[f"{source}_spherical_m"] = curves.spherical_m[source]
    paths.append(write_dataframe_csv(pd.DataFrame(columns), out_dir / "errors_problem3.csv"))
    vertical = {"t_s": curves.vertical_t_s, "unaided_m": curves.vertical_unaided_m}
    vertical.update({f"aided_order_{k + 2}_m": v for k, v in enumerate(curves.vertical_aided_m.values())})
    paths.append(write_dataframe_csv(pd.DataFrame(vertical), out_dir / "errors_problem4.csv"))
    return paths


def _write_run(result: ErrorRunResult, out_dir: Path, formats) -> list[Path]:
    import pandas as pd

    unit = "ft" if result.earth == "bollay" else "m"
    simulated = None if result.simulated_m is None else (result.t_s, result.simulated_m)
    fig = plots.plot_flat_vs_spherical(result.t_s, result.flat_m, result.spherical_m, unit,
                                       f"{plots.SOURCE_TITLES[result.source]}: flat vs spherical Earth",
                                       simulated=simulated)
    stem = f"errors_run_{result.source}"
    paths = save_figure_formats(fig, out_dir / stem, formats)
    columns = {"t_s": result.t_s, "flat_m": result.flat_m, "spherical_m": result.spherical_m}
    if result.simulated_m is not None:
        columns["simulated_m"] = result.simulated_m
    paths.append(write_dataframe_csv(pd.DataFrame(columns), out_dir / f"{stem}.csv"))
    return paths


def _write_vertical(result: VerticalResult, out_dir: Path, formats) -> list[Path]:
    import pandas as pd

    fig = plots.plot_vertical(result.t_s, result.unaided_m, {f"baro-aided, order {result.order}": result.aided_m},
                              "m", "Vertical channel: pure inertial vs baro-aided")
    paths = save_figure_formats(fig, out_dir / "errors_vertical_run", formats)
    frame = pd.DataFrame({"t_s": result.t_s, "unaided_m": result.unaided_m, "closed_form_m": result.closed_form_m,
                          "aided_m": result.aided_m})
    paths.append(write_dataframe_csv(frame, out_dir / "errors_vertical_run.csv"))
    return paths


def _write_period(result: PeriodResult, out_dir: Path, formats) -> list[Path]:
    import pandas as pd

    speeds = np.linspace(0.0, 0.999 * result.orbital_speed_m_s, PERIOD_CURVE_POINTS)
    periods = effective_schuler_period(result.radius_m,
                                       flight_gravity(result.gravity_m_s2, speeds, result.path_radius_m))
    fig = plots.plot_period(speeds, periods, result.speed_m_s, result.orbital_speed_m_s,
                            "Effective Schuler period in level flight")
    paths = save_figure_formats(fig, out_dir / "errors_period", formats)
    paths.append(write_dataframe_csv(pd.DataFrame({"speed_m_s": speeds, "period_s": periods}),
                                     out_dir / "errors_period.csv"))
    return paths


def _write_three_d(result: ThreeDResult, out_dir: Path, formats) -> list[Path]:
    import pandas as pd

    unit = "m"
    latitude = np.degrees(result.latitude_rad)
    paths = save_figure_formats(
        plots.plot_three_d(result.t_s, result.histories, unit, f"3-D psi-angle errors at {latitude:.4g} deg"),
        out_dir / "errors_three_d", formats)
    paths += save_figure_formats(
        plots.plot_foucault(result.t_s, result.histories["position_error_north"],
                            result.histories["position_error_east"], unit,
                            f"Horizontal position error at {latitude:.4g} deg"),
        out_dir / "errors_three_d_track", formats)
    columns = {"t_s": result.t_s}
    for name, history in result.histories.items():
        column = name.replace("psi_", "attitude_error_")
        columns[f"{column}_{result.state_units[name].replace('/', '_')}"] = history
    paths.append(write_dataframe_csv(pd.DataFrame(columns), out_dir / "errors_three_d.csv"))
    return paths
