"""What ``schuler vertical`` returns and draws: :class:`VerticalResult`, :class:`FrictionResult`, :func:`figures`.

Fields are SI with the unit in the name (``velocity_error_y_mean_m_s``,
``split_period_fast_s``); ``render()`` shows arcmin, minutes and hours. The
histories for figures and files are kept out of ``to_dict``; :func:`data_files`
writes the tables that are not a run's histories.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from schuler.reproduction import Reproduction
from schuler.results import Result, SystemResult
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


@dataclass(kw_only=True)
class VerticalResult(SystemResult):
    """What ``SYSTEM.run`` returns: every output of the system's ``evaluate``, the extras and the histories.

    With ``fidelity="closed"`` the outputs only a simulation gives are NaN and
    the histories are ``vertical_quasi_steady``, the forced motion (26) and the
    quasi-steady error (29) along the path; simulated, ``vertical_timeseries``.
    """

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

    def to_dataframe(self):
        """The histories, one row per time: ``time_s``, the tilts (rad) and the velocity errors (m/s)."""
        import pandas as pd

        r = self.response
        return pd.DataFrame({"time_s": r.time, "alpha_rad": r.alpha, "beta_rad": r.beta,
                             "velocity_error_x_m_s": r.velocity_error_x, "velocity_error_y_m_s": r.velocity_error_y})

    def stick_frame(self):
        """The stick intervals, one row each: start and end (s), the velocity errors there (m/s)."""
        import pandas as pd

        errors = np.asarray(self.response.stick_velocity_errors).reshape(-1, 4)
        intervals = np.asarray(self.response.stick_intervals).reshape(-1, 2)
        return pd.DataFrame({
            "start_s": intervals[:, 0], "end_s": intervals[:, 1],
            "velocity_error_x_at_start_m_s": errors[:, 0], "velocity_error_y_at_start_m_s": errors[:, 1],
            "velocity_error_x_at_end_m_s": errors[:, 2], "velocity_error_y_at_end_m_s": errors[:, 3],
        })

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


def figures(result: Result) -> dict[str, Any]:
    """The figures of a run, of the friction action or of the reproduction, file stem -> Figure.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned ({} for any other result).
    """
    from schuler.gyro_vertical import plots

    if isinstance(result, Reproduction):
        data = result.data
        return {**_analysis_figures(data["example"], "vertical_example", data["compensated"]),
                **figures(data["friction"])}
    if isinstance(result, FrictionResult):
        radius = result.dead_zone_x_m_s / result.friction_x_rad_s  # q_1 = R q_1 / R > 0: the dead zone is positive
        return {"vertical_friction": plots.plot_friction(result.response,
                                                         (result.friction_x_rad_s, result.friction_y_rad_s), radius)}
    if not isinstance(result, SystemResult):
        return {}
    if "vertical_timeseries" in result.histories:
        drawn = _analysis_figures(_analysis_of(result), "vertical")
    else:
        drawn = {"vertical_quasi_steady": plots.plot_quasi_steady(_quasi_steady_of(result))}
    if result.monte_carlo is not None:
        samples = result.monte_carlo.samples
        drawn["vertical_monte_carlo"] = plots.plot_monte_carlo(samples["velocity_error_x_mean_m_s"],
                                                               samples["velocity_error_y_mean_m_s"])
    return drawn


def data_files(result: Result, out_dir: Path) -> list[Path]:
    """The CSV files beside a run's histories: the reproduction's example and the friction action's tables.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned.
    out_dir : Path
        Folder for the CSV files (created if missing).
    """
    from schuler.io import write_dataframe_csv

    out_dir = Path(out_dir)
    if isinstance(result, Reproduction):
        table = _timeseries_frame(result.data["example"])
        return [write_dataframe_csv(table, out_dir / "vertical_example_timeseries.csv"),
                *data_files(result.data["friction"], out_dir)]
    if isinstance(result, FrictionResult):
        return [write_dataframe_csv(result.to_dataframe(), out_dir / "vertical_friction.csv"),
                write_dataframe_csv(result.stick_frame(), out_dir / "vertical_friction_stick_intervals.csv")]
    return []


def _analysis_figures(analysis, prefix: str, compensated=None) -> dict[str, Any]:
    """Tilts, velocity errors and (for long enough runs) the spectrum."""
    from schuler.gyro_vertical import plots

    drawn = {f"{prefix}_tilts": plots.plot_tilts(analysis),
             f"{prefix}_velocity_errors": plots.plot_velocity_errors(analysis, compensated)}
    if analysis.spectrum is not None:
        drawn[f"{prefix}_spectrum"] = plots.plot_spectrum(analysis)
    return drawn


def _timeseries_frame(analysis):
    """A simulation's histories as the CSV ``--out`` writes them (``time_s`` first)."""
    from schuler.gyro_vertical.evaluation import FIDELITIES, run_histories

    [histories] = run_histories(FIDELITIES[0], analysis)[0].values()
    return histories.to_dataframe().reset_index()


def _analysis_of(result: SystemResult):
    """The run's simulation with its forced motion and spectrum, from its histories (for the figures)."""
    from schuler.gyro_vertical.evaluation import build_model
    from schuler.gyro_vertical.model import VerticalResponse
    from schuler.gyro_vertical.quasi_steady import analyse_response

    h = result.histories["vertical_timeseries"]
    response = VerticalResponse(
        time=h.time, alpha=h["alpha_rad"], beta=h["beta_rad"], measured_velocity_x=h["measured_velocity_x_m_s"],
        measured_velocity_y=h["measured_velocity_y_m_s"], true_velocity_x=h["true_velocity_x_m_s"],
        true_velocity_y=h["true_velocity_y_m_s"], latitude=h["latitude_rad"], method=result.method,
        nfev=result.nfev, n_steps=result.n_steps)
    return analyse_response(build_model(result.parameters), response, fit_modes_too=False)


def _quasi_steady_of(result: SystemResult):
    """The closed-form run's forced motion and quasi-steady error, from its histories."""
    from schuler.gyro_vertical.quasi_steady import QuasiSteady

    h = result.histories["vertical_quasi_steady"]
    return QuasiSteady(time=h.time, alpha_r=h["alpha_r_rad"], beta_r=h["beta_r_rad"],
                       dv_x=h["quasi_steady_velocity_error_x_m_s"], dv_y=h["quasi_steady_velocity_error_y_m_s"],
                       slow_dv_x=h["slowly_varying_velocity_error_x_m_s"],
                       slow_dv_y=h["slowly_varying_velocity_error_y_m_s"],
                       W_star_x=h["transport_coriolis_x_m_s2"], W_star_y=h["transport_coriolis_y_m_s2"])
