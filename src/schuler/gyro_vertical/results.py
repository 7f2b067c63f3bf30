"""What ``schuler vertical`` returns and writes: :class:`VerticalResult`, :class:`FrictionResult`, :func:`write_files`.

Fields are SI with the unit in the name (``velocity_error_y_mean_m_s``,
``split_period_fast_s``); ``render()`` shows arcmin, minutes and hours. The
histories for figures and files are kept out of ``to_dict``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from schuler.reproduction import Reproduction
from schuler.results import Result, RunResult
from schuler.units import to_unit


def _shown(value: float | None, unit: str = "", digits: int = 5, scale: float = 0.0) -> str:
    """A number for people in ``unit`` (SI in): '-' when missing, no negative zero.

    Values below 1e-12 of ``scale`` (the largest of their row) are rounding noise and shown as 0.

    >>> _shown(-2.7e-17, "", scale=1e-3), _shown(0.0013765, "arcmin", 4)
    ('0', '4.732')
    """
    if value is None or math.isnan(value):
        return "-"
    if math.isinf(value):
        return "none (infinite)"
    if abs(value) <= 1e-12 * scale:
        return "0"
    number = float(to_unit(value, unit)) if unit else float(value)
    text = f"{number:.{digits}g}"
    return text[1:] if text.startswith("-") and float(text) == 0 else text


@dataclass
class VerticalResult(RunResult):
    """One gyro-vertical case: every output of the system's ``evaluate`` and the histories behind them.

    With ``fidelity="closed"`` the outputs only a simulation gives are NaN and
    ``analysis`` is None; ``quasi_steady`` holds the forced motion (26) and the
    quasi-steady error (29) along the path in both fidelities.
    """

    fidelity: str
    end_time_s: float
    final_latitude_rad: float
    transport_coriolis_x_m_s2: float
    transport_coriolis_y_m_s2: float
    steady_tilt_alpha_rad: float
    steady_tilt_beta_rad: float
    steady_velocity_error_x_m_s: float
    steady_velocity_error_y_m_s: float
    quasi_steady_velocity_error_x_mean_m_s: float
    quasi_steady_velocity_error_y_mean_m_s: float
    velocity_error_x_mean_m_s: float
    velocity_error_y_mean_m_s: float
    velocity_error_x_rms_m_s: float
    velocity_error_y_rms_m_s: float
    velocity_error_x_max_abs_m_s: float
    velocity_error_y_max_abs_m_s: float
    velocity_error_x_final_m_s: float
    velocity_error_y_final_m_s: float
    tilt_alpha_max_abs_rad: float
    tilt_beta_max_abs_rad: float
    schuler_period_s: float
    split_period_fast_s: float
    split_period_slow_s: float
    beat_period_s: float
    fitted_period_fast_s: float
    fitted_period_slow_s: float
    tilt_oscillation_amplitude_m_s: float
    method: str
    nfev: int
    n_steps: int
    fitted_amplitudes_m_s: list[float] | None
    analysis: Any = field(default=None, repr=False)
    quasi_steady: Any = field(default=None, repr=False)

    units: ClassVar[dict[str, str]] = {"nfev": "1", "n_steps": "1"}

    def render(self):
        from rich.console import Group
        from rich.table import Table

        table = Table(title=f"Gyro vertical with integral correction ({self.fidelity})")
        for heading, justify in (("quantity", "left"), ("x", "right"), ("y", "right"), ("unit", "left")):
            table.add_column(heading, justify=justify)  # type: ignore[arg-type]
        rows = [
            ("W* (21) at the start", self.transport_coriolis_x_m_s2, self.transport_coriolis_y_m_s2, "m/s^2", ""),
            ("forced tilts alpha_r, beta_r at the start", self.steady_tilt_alpha_rad, self.steady_tilt_beta_rad,
             "arcmin", "arcmin"),
            ("slowly-varying error (29) at the start", self.steady_velocity_error_x_m_s,
             self.steady_velocity_error_y_m_s, "m/s", ""),
            ("quasi-steady error (29), mean", self.quasi_steady_velocity_error_x_mean_m_s,
             self.quasi_steady_velocity_error_y_mean_m_s, "m/s", ""),
            (f"velocity error: mean ({'simulated' if self.fidelity == 'simulated' else '(29)'})",
             self.velocity_error_x_mean_m_s, self.velocity_error_y_mean_m_s, "m/s", ""),
            ("velocity error: rms", self.velocity_error_x_rms_m_s, self.velocity_error_y_rms_m_s, "m/s", ""),
            ("velocity error: max |.|", self.velocity_error_x_max_abs_m_s, self.velocity_error_y_max_abs_m_s,
             "m/s", ""),
            ("velocity error: final", self.velocity_error_x_final_m_s, self.velocity_error_y_final_m_s, "m/s", ""),
            ("max |tilt| (alpha, beta)", self.tilt_alpha_max_abs_rad, self.tilt_beta_max_abs_rad, "arcmin",
             "arcmin"),
            ("split Schuler periods (27), fast and slow", self.split_period_fast_s, self.split_period_slow_s,
             "min", "min"),
            ("split Schuler periods fitted to the simulation", self.fitted_period_fast_s,
             self.fitted_period_slow_s, "min", "min"),
        ]
        for name, x, y, unit, convert in rows:
            scale = max((abs(v) for v in (x, y) if math.isfinite(v)), default=0.0)
            table.add_row(name, _shown(x, convert, scale=scale), _shown(y, convert, scale=scale), unit)
        beat = "none (omega_2 = 0)" if math.isinf(self.beat_period_s) else f"{_shown(self.beat_period_s, 'h', 4)} h"
        solver = (f"{self.method}: {self.n_steps} steps, {self.nfev} evaluations" if self.fidelity == "simulated"
                  else self.method)
        table.caption = (f"{_shown(self.end_time_s, 'h', 4)} h, final latitude "
                         f"{_shown(self.final_latitude_rad, 'deg', 6)} deg, Schuler period "
                         f"{_shown(self.schuler_period_s, 'min', 4)} min, beat period {beat}; {solver}")
        parts = [table]
        if self.monte_carlo is not None:
            parts.append(self.monte_carlo.render())
        return Group(*parts)


@dataclass
class FrictionResult(Result):
    """Coulomb friction (30)-(32): the stick phases, the static errors and the growth of the slip.

    ``friction_x_rad_s`` is q_1 = M_fr,x / H (outer gimbal axis x, the alpha axis),
    ``friction_y_rad_s`` q_2 (inner axis y, the beta axis); the dead zone of the
    static velocity errors is R q on each axis (32, with the factor R).
    """

    friction_x_rad_s: float
    friction_y_rad_s: float
    dead_zone_x_m_s: float
    dead_zone_y_m_s: float
    stick_intervals: int
    switches: int
    max_static_velocity_error_x_m_s: float
    max_static_velocity_error_y_m_s: float
    velocity_error_x_max_abs_m_s: float
    velocity_error_y_max_abs_m_s: float
    growth_rate_x_m_s2: float
    growth_rate_y_m_s2: float
    end_time_s: float
    nfev: int
    response: Any = field(default=None, repr=False)

    units: ClassVar[dict[str, str]] = {"stick_intervals": "1", "switches": "1", "nfev": "1"}

    def render(self):
        from rich.table import Table

        table = Table(title="Gyro vertical: Coulomb friction in the gimbal bearings (30)-(32)")
        for heading, justify in (("quantity", "left"), ("x", "right"), ("y", "right"), ("unit", "left")):
            table.add_column(heading, justify=justify)  # type: ignore[arg-type]
        rows = [
            ("friction over angular momentum q = M_fr / H", self.friction_x_rad_s, self.friction_y_rad_s, "deg/h"),
            ("dead zone R q (32)", self.dead_zone_x_m_s, self.dead_zone_y_m_s, "m/s"),
            ("largest static velocity error", self.max_static_velocity_error_x_m_s,
             self.max_static_velocity_error_y_m_s, "m/s"),
            ("largest |velocity error|", self.velocity_error_x_max_abs_m_s, self.velocity_error_y_max_abs_m_s, "m/s"),
            ("growth of the slip amplitude 2 q sqrt(g R) / pi", self.growth_rate_x_m_s2, self.growth_rate_y_m_s2,
             "m/s per h"),
        ]
        for name, x, y, unit in rows:
            convert = {"deg/h": "deg/h", "m/s per h": "m/s/h"}.get(unit, "")
            table.add_row(name, _shown(x, convert), _shown(y, convert), unit)
        table.caption = (f"{_shown(self.end_time_s, 'h', 4)} h: {self.stick_intervals} stick intervals, "
                         f"{self.switches} stick/slip switches, {self.nfev} evaluations")
        return table


def write_files(result: Result, out_dir: Path) -> list[Path]:
    """Figures (PNG and SVG) and CSV data of a run, of the friction action or of the reproduction.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned.
    out_dir : Path
        Folder for the figures (PNG, SVG) and data files (CSV); created if missing.
    """
    out_dir = Path(out_dir)
    if isinstance(result, Reproduction):
        data = result.data
        files = _analysis_files(data["example"], out_dir, "vertical_example", compensated=data["compensated"])
        return files + _friction_files(data["friction"], out_dir)
    if isinstance(result, VerticalResult):
        files = (_analysis_files(result.analysis, out_dir, "vertical") if result.analysis is not None
                 else _quasi_steady_files(result.quasi_steady, out_dir))
        return files + (_monte_carlo_files(result.monte_carlo, out_dir) if result.monte_carlo is not None else [])
    if isinstance(result, FrictionResult):
        return _friction_files(result, out_dir)
    raise TypeError(f"vertical writes no files for {type(result).__name__}")


def _analysis_files(analysis, out_dir: Path, prefix: str, compensated=None) -> list[Path]:
    """Tilts, velocity errors and (for long enough runs) the spectrum; the histories as CSV."""
    import pandas as pd

    from schuler.gyro_vertical import plots
    from schuler.io import save_figure_formats, write_dataframe_csv

    r, q = analysis.response, analysis.quasi_steady
    table = pd.DataFrame({
        "time_s": r.time, "alpha_rad": r.alpha, "beta_rad": r.beta, "latitude_rad": r.latitude,
        "measured_velocity_x_m_s": r.measured_velocity_x, "measured_velocity_y_m_s": r.measured_velocity_y,
        "true_velocity_x_m_s": r.true_velocity_x, "true_velocity_y_m_s": r.true_velocity_y,
        "velocity_error_x_m_s": r.velocity_error_x, "velocity_error_y_m_s": r.velocity_error_y,
        "quasi_steady_velocity_error_x_m_s": q.dv_x, "quasi_steady_velocity_error_y_m_s": q.dv_y,
    })
    files = [write_dataframe_csv(table, out_dir / f"{prefix}_timeseries.csv")]
    files += save_figure_formats(plots.plot_tilts(analysis), out_dir / f"{prefix}_tilts")
    files += save_figure_formats(plots.plot_velocity_errors(analysis, compensated),
                                 out_dir / f"{prefix}_velocity_errors")
    if analysis.spectrum is not None:
        files += save_figure_formats(plots.plot_spectrum(analysis), out_dir / f"{prefix}_spectrum")
    return files


def _monte_carlo_files(summary, out_dir: Path) -> list[Path]:
    """Histograms of the members' systematic velocity errors."""
    from schuler.gyro_vertical import plots
    from schuler.io import save_figure_formats

    figure = plots.plot_monte_carlo(summary.samples["velocity_error_x_mean_m_s"],
                                    summary.samples["velocity_error_y_mean_m_s"])
    return save_figure_formats(figure, out_dir / "vertical_monte_carlo")


def _quasi_steady_files(quasi, out_dir: Path) -> list[Path]:
    """The forced motion (26) and the quasi-steady error (29) of a closed-form run."""
    import pandas as pd

    from schuler.gyro_vertical import plots
    from schuler.io import save_figure_formats, write_dataframe_csv

    table = pd.DataFrame({
        "time_s": quasi.time, "alpha_r_rad": quasi.alpha_r, "beta_r_rad": quasi.beta_r,
        "quasi_steady_velocity_error_x_m_s": quasi.dv_x, "quasi_steady_velocity_error_y_m_s": quasi.dv_y,
        "slowly_varying_velocity_error_x_m_s": quasi.slow_dv_x, "slowly_varying_velocity_error_y_m_s": quasi.slow_dv_y,
        "transport_coriolis_x_m_s2": quasi.W_star_x, "transport_coriolis_y_m_s2": quasi.W_star_y,
    })
    files = [write_dataframe_csv(table, out_dir / "vertical_quasi_steady.csv")]
    return files + save_figure_formats(plots.plot_quasi_steady(quasi), out_dir / "vertical_quasi_steady")


def _friction_files(result: FrictionResult, out_dir: Path) -> list[Path]:
    """The friction figure, the histories and the stick intervals as CSV."""
    import pandas as pd

    from schuler.gyro_vertical import plots
    from schuler.io import save_figure_formats, write_dataframe_csv

    response = result.response
    histories = pd.DataFrame({
        "time_s": response.time, "alpha_rad": response.alpha, "beta_rad": response.beta,
        "velocity_error_x_m_s": response.velocity_error_x, "velocity_error_y_m_s": response.velocity_error_y,
    })
    errors = np.asarray(response.stick_velocity_errors).reshape(-1, 4)
    intervals = np.asarray(response.stick_intervals).reshape(-1, 2)
    stick = pd.DataFrame({
        "start_s": intervals[:, 0], "end_s": intervals[:, 1],
        "velocity_error_x_at_start_m_s": errors[:, 0], "velocity_error_y_at_start_m_s": errors[:, 1],
        "velocity_error_x_at_end_m_s": errors[:, 2], "velocity_error_y_at_end_m_s": errors[:, 3],
    })
    files = [write_dataframe_csv(histories, out_dir / "vertical_friction.csv"),
             write_dataframe_csv(stick, out_dir / "vertical_friction_stick_intervals.csv")]
    radius = result.dead_zone_x_m_s / result.friction_x_rad_s  # q_1 = R q_1 / R > 0: the dead zone is positive
    figure = plots.plot_friction(response, (result.friction_x_rad_s, result.friction_y_rad_s), radius)
    return files + save_figure_formats(figure, out_dir / "vertical_friction")
