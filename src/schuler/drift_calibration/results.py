"""What ``schuler calibrate run`` returns and writes: :class:`CalibrationResult` and :func:`write_files`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from schuler.reproduction import Reproduction
from schuler.results import Result, RunResult
from schuler.units import to_unit


@dataclass(frozen=True)
class CycleHistory:
    """One measurement cycle of the nominal case, for figures and files.

    Attributes
    ----------
    time : ndarray
        Time since the start of the cycle, s.
    platform_angle : ndarray
        Platform angle alpha_X relative to the base, rad.
    sensor_signal : ndarray
        Command-sensor signal U, V.
    integrator_output : ndarray
        Integrator output, V s (its final value is the reading Delta U of (11)).
    """

    time: np.ndarray
    platform_angle: np.ndarray
    sensor_signal: np.ndarray
    integrator_output: np.ndarray


@dataclass
class CalibrationResult(RunResult):
    """One calibration procedure: estimated and true drifts and azimuth (every output of ``evaluate``).

    Rates in rad/s, angles in rad, times in s; ``render()`` shows deg/h, deg and
    arcmin. The ``true_*`` fields are the case's values, the others what the
    procedure estimated; errors are estimated - true. In single-axis mode the
    Y gyro is not measured (its estimate and error are NaN, null in JSON).
    """

    mode: str
    positions: int
    cycles: int
    true_drift_x_rad_s: float
    true_drift_y_rad_s: float
    true_earth_rate_component_rad_s: float
    true_azimuth_rad: float
    drift_x_rad_s: float
    drift_y_rad_s: float
    drift_x_error_rad_s: float
    drift_y_error_rad_s: float
    relative_drift_error: float
    earth_rate_component_rad_s: float
    azimuth_rad: float
    azimuth_alternative_rad: float
    azimuth_error_rad: float
    asin_saturated: bool
    cycle_time_s: float
    procedure_time_s: float
    cycle_history: CycleHistory | None = field(default=None, repr=False)

    units: ClassVar[dict[str, str]] = {"relative_drift_error": "1", "positions": "1", "cycles": "1"}

    def render(self):
        from rich.console import Group
        from rich.table import Table

        single = self.mode == "single-axis"
        table = Table(title=f"Drift calibration ({self.mode}, {self.positions} positions, "
                            f"{self.cycles} cycle{'s' if self.cycles > 1 else ''} each)", show_header=False)
        table.add_column("quantity")
        table.add_column("value", justify="right")
        rows = [
            ("estimated drift X", _shown(self.drift_x_rad_s, "deg/h", 6)),
            ("true drift X", _shown(self.true_drift_x_rad_s, "deg/h", 6)),
            ("estimated drift Y", "not measured (single-axis)" if single else _shown(self.drift_y_rad_s, "deg/h", 6)),
            ("true drift Y", _shown(self.true_drift_y_rad_s, "deg/h", 6)),
            ("estimated omega_X0 = Omega cos(phi) sin(A0)", _shown(self.earth_rate_component_rad_s, "deg/h", 6)),
            ("true omega_X0", _shown(self.true_earth_rate_component_rad_s, "deg/h", 6)),
            ("estimated azimuth A0", _shown(self.azimuth_rad, "deg", 6)),
            # one channel at two positions gives only sin(A0): two azimuths fit it
            *([("other asin branch (180 deg - A0)", _shown(self.azimuth_alternative_rad, "deg", 6))]
              if single and self.positions == 2 else []),
            ("true azimuth A0", _shown(self.true_azimuth_rad, "deg", 6)),
            ("drift error X (estimated - true)", _shown(self.drift_x_error_rad_s, "deg/h", 6)),
            ("azimuth error (estimated - true)", _shown(self.azimuth_error_rad, "arcmin", 4)),
            ("cycle time 2 tau, procedure time", f"{self.cycle_time_s:g} s, {self.procedure_time_s:g} s"),
        ]
        if self.asin_saturated:
            rows.append(("asin argument", "beyond 1, clipped (azimuth near 90 or 270 deg)"))
        mc = self.monte_carlo
        if mc is not None:
            stats = mc.statistics
            rows += [
                (f"Monte Carlo ({mc.members} members, seed {mc.seed}): mean |relative drift error|",
                 _shown(stats["relative_drift_error"]["mean"], "%", 4, fixed=False)),
                ("RMS drift error X" + ("" if single else ", Y"),
                 ", ".join(_shown(stats[name]["rms"], "deg/h", 3, fixed=False) for name in
                           (("drift_x_error_rad_s",) if single else ("drift_x_error_rad_s", "drift_y_error_rad_s")))),
                ("RMS azimuth error, mean", ", ".join(_shown(stats["azimuth_error_rad"][key], "arcmin", 4, fixed=False)
                                                      for key in ("rms", "mean"))),
            ]
        for name, value in rows:
            table.add_row(name, value)
        return Group(table)


def _shown(value, unit: str, digits: int, fixed: bool = True) -> str:
    """An SI value in a display unit for people: fixed or significant digits, no negative zero, '-' for none."""
    if value is None or not math.isfinite(value):
        return "-"
    number = float(to_unit(value, unit))
    text = f"{number:.{digits}f}" if fixed else f"{number:.{digits}g}"
    if text.startswith("-") and float(text) == 0:
        text = text[1:]
    return f"{text} {unit}"


def write_files(result: Result, out_dir: Path) -> list[Path]:
    """Figures (PNG and SVG) and CSV data of a run, its Monte Carlo, or the reproduction.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned.
    out_dir : Path
        Folder for the figures (PNG, SVG) and data files (CSV); created if missing.
    """
    import pandas as pd

    from schuler.drift_calibration import plots
    from schuler.io import save_figure_formats, write_dataframe_csv

    out_dir = Path(out_dir)
    files: list[Path] = []
    if isinstance(result, Reproduction):
        samples = result.data["samples"]
        files += save_figure_formats(plots.plot_histograms(samples, result.data["title"]),
                                     out_dir / "calibrate_reproduction_monte_carlo")
        files.append(write_dataframe_csv(pd.DataFrame(result.data["summary"]),
                                         out_dir / "calibrate_reproduction_summary.csv"))
        return files
    if not isinstance(result, CalibrationResult):
        raise TypeError(f"calibrate writes no files for {type(result).__name__}")
    history = result.cycle_history
    if history is not None:
        files += save_figure_formats(plots.plot_cycle(history), out_dir / "calibrate_cycle")
        files.append(write_dataframe_csv(pd.DataFrame({
            "t_s": history.time, "platform_angle_rad": history.platform_angle,
            "sensor_signal_V": history.sensor_signal, "integrator_output_V_s": history.integrator_output,
        }), out_dir / "calibrate_cycle.csv"))
    if result.monte_carlo is not None:
        samples = {name: result.monte_carlo.samples[name] for name in
                   ("drift_x_error_rad_s", "drift_y_error_rad_s", "azimuth_error_rad", "relative_drift_error")}
        title = f"Monte Carlo, {result.monte_carlo.members} members ({result.mode})"
        files += save_figure_formats(plots.plot_histograms(samples, title), out_dir / "calibrate_monte_carlo")
        files.append(write_dataframe_csv(pd.DataFrame(samples), out_dir / "calibrate_monte_carlo.csv"))
    return files
