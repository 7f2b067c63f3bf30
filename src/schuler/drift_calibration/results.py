"""What ``schuler calibrate`` returns and draws: :class:`CalibrationResult`, :func:`figures`, :func:`data_files`."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from schuler.reproduction import Reproduction
from schuler.results import Result, SystemResult
from schuler.units import to_unit

MONTE_CARLO_ERRORS = ("drift_x_error_rad_s", "drift_y_error_rad_s", "azimuth_error_rad", "relative_drift_error")
"""The outputs whose members a Monte Carlo's histograms and CSV show."""


@dataclass(kw_only=True)
class CalibrationResult(SystemResult):
    """One calibration procedure, rendered as the calibration reads: estimates beside the truths.

    Rates in rad/s, angles in rad, times in s; ``render()`` shows deg/h, deg and
    arcmin. The extras ``true_*`` are the case's values, the outputs what the
    procedure estimated; errors are estimated - true. In single-axis mode the
    Y gyro is not measured (its estimate and error are NaN, null in JSON). The
    histories ``calibrate_cycle`` are one error-free measurement cycle.
    """

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


def figures(result: Result) -> dict[str, Any]:
    """The figures of a run (one cycle, its Monte Carlo's errors) or of the reproduction, by file stem.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned ({} for others).
    """
    from schuler.drift_calibration import plots

    if isinstance(result, Reproduction):
        return {"calibrate_reproduction_monte_carlo": plots.plot_histograms(result.data["samples"],
                                                                            result.data["title"])}
    if not isinstance(result, SystemResult):
        return {}
    drawn = {}
    if "calibrate_cycle" in result.histories:
        drawn["calibrate_cycle"] = plots.plot_cycle(result.histories["calibrate_cycle"])
    if result.monte_carlo is not None:
        title = f"Monte Carlo, {result.monte_carlo.members} members ({result.extras.get('mode', '')})"
        drawn["calibrate_monte_carlo"] = plots.plot_histograms(_members(result), title)
    return drawn


def data_files(result: Result, out_dir: Path) -> list[Path]:
    """The CSV files beside the histories: a Monte Carlo's members' errors, the reproduction's summary.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned.
    out_dir : Path
        Folder for the CSV files (exists: the writer made it).
    """
    import pandas as pd

    from schuler.io import write_dataframe_csv

    out_dir = Path(out_dir)
    if isinstance(result, Reproduction):
        return [write_dataframe_csv(pd.DataFrame(result.data["summary"]),
                                    out_dir / "calibrate_reproduction_summary.csv")]
    if isinstance(result, SystemResult) and result.monte_carlo is not None:
        return [write_dataframe_csv(pd.DataFrame(_members(result)), out_dir / "calibrate_monte_carlo.csv")]
    return []


def _members(result: SystemResult) -> dict[str, Any]:
    assert result.monte_carlo is not None
    return {name: result.monte_carlo.samples[name] for name in MONTE_CARLO_ERRORS}
