"""What ``schuler align run`` returns and writes: :class:`AlignmentResult` and :func:`write_files`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

from schuler.gyrocompassing.simulation import CaseRun
from schuler.reproduction import Reproduction
from schuler.results import Result, RunResult
from schuler.units import to_unit


@dataclass
class AlignmentResult(RunResult):
    """One gyrocompassing case: accuracy, time, constraint check (every output of the system's ``evaluate``).

    Angles in rad, times in s, gains in 1/s; ``render()`` shows arcmin and arcsec.
    Outputs computed only by the simulation are None with ``fidelity="closed"``.
    ``run`` and ``simplified_run`` hold the histories of the model and of (1.19)
    (not in ``to_dict``).
    """

    model: str
    fidelity: str
    azimuth_error_rad: float
    azimuth_error_analytic_rad: float
    full_minus_simplified_rad: float
    level_error_beta_rad: float
    level_error_beta_analytic_rad: float
    azimuth_error_sigma_rad: float
    azimuth_error_sigma_simplified_rad: float
    settling_time_s: float
    settling_time_simulated_s: float
    regime: str
    c_gamma: float
    c_a: float
    design_time_constant_s: float
    design_damping: float
    max_abs_delta_rad: float
    max_abs_beta_rad: float
    max_abs_delta_rate_rad_s: float
    constraints_ok: bool | None
    constraint_violations: list
    simulated_duration_s: float
    run: CaseRun | None = field(default=None, repr=False)
    simplified_run: CaseRun | None = field(default=None, repr=False)

    units: ClassVar[dict[str, str]] = {"c_gamma": "1/s", "c_a": "1/s", "design_damping": "1"}

    def render(self):
        from rich.console import Group
        from rich.table import Table

        def angle(value, unit="arcmin", digits=4):
            return "-" if value is None or math.isnan(value) else f"{_clean(to_unit(value, unit), digits)} {unit}"

        def seconds(value):
            if value is None or math.isnan(value):
                return "-"
            return "not settled" if math.isinf(value) else f"{value:.5g} s"

        table = Table(title=f"Gyrocompassing, {self.model} model ({self.fidelity})", show_header=True)
        table.add_column("quantity")
        table.add_column("value", justify="right")
        constraint = ("not checked (closed form)" if self.constraints_ok is None
                      else "ok" if self.constraints_ok else "; ".join(self.constraint_violations))
        rows = [
            (f"azimuth error ({'simulated' if self.fidelity == 'simulated' else 'closed-form'} steady state)",
             angle(self.azimuth_error_rad)),
            ("azimuth error, analytic (1.21)", angle(self.azimuth_error_analytic_rad)),
            ("full model minus (1.21)", angle(self.full_minus_simplified_rad, "arcsec", 3)),
            ("level error beta", angle(self.level_error_beta_rad)),
            ("level error beta, analytic (1.25)", angle(self.level_error_beta_analytic_rad)),
            ("settling time, analytic", f"{seconds(self.settling_time_s)} ({self.regime})"),
            ("settling time, simulated 1 % band", seconds(self.settling_time_simulated_s)),
            ("c_Gamma, c_a", f"{self.c_gamma:.4g} 1/s, {self.c_a:.4g} 1/s"),
            ("T, zeta", f"{self.design_time_constant_s:.4g} s, {self.design_damping:.3g}"),
            ("constraints (0.4 rad, 0.01 rad, 0.2 rad/s)", constraint),
        ]
        if self.monte_carlo is not None:
            stats = self.monte_carlo.statistics["azimuth_error_rad"]
            rows += [
                (f"Monte Carlo ({self.monte_carlo.members} members): mean, std",
                 f"{angle(stats['mean'])}, {angle(stats['std'])}"),
                ("analytic 1-sigma: model, (1.21)",
                 f"{angle(self.azimuth_error_sigma_rad)}, {angle(self.azimuth_error_sigma_simplified_rad)}"),
            ]
        for name, value in rows:
            table.add_row(name, value)
        return Group(table)


def _clean(value: float, digits: int) -> str:
    """A number for people: no negative zero."""
    text = f"{float(value):.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0 else text


def write_files(result: Result, out_dir: Path) -> list[Path]:
    """Figures (PNG and SVG) and CSV of a run, a Monte Carlo or the reproduction.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or an action returned.
    out_dir : Path
        Folder for the figures (PNG, SVG) and data files (CSV); created if missing.
    """
    import pandas as pd

    from schuler.gyrocompassing import plots
    from schuler.io import write_dataframe_csv

    out_dir = Path(out_dir)
    if isinstance(result, Reproduction):
        return plots.write_figures({"align_reproduction_time_history": plots.time_history(result.data)}, out_dir)
    if not isinstance(result, AlignmentResult):
        raise TypeError(f"align writes no files for {type(result).__name__}")
    figures = {}
    files: list[Path] = []
    run = result.run
    if run is not None:
        runs = {f"{result.model} model": run}
        if result.model != "simplified" and result.simplified_run is not None:
            runs["simplified model (1.19)"] = result.simplified_run
        figures["align_time_history"] = plots.time_history(runs)
        figures["align_phase_trajectory"] = plots.phase_trajectory(runs)
        columns = {"t_s": run.time, "delta_rad": run.delta, "beta_rad": run.beta, "delta_rate_rad_s": run.delta_rate}
        # the level angles of the full models (None on the simplified one)
        level = {"alpha_rad": run.alpha, "mu_rad": run.mu, "nu_rad": run.nu}
        columns.update({name: values for name, values in level.items() if values is not None})
        files.append(write_dataframe_csv(pd.DataFrame(columns), out_dir / "align_time_history.csv"))
    if result.monte_carlo is not None:
        samples = to_unit(result.monte_carlo.samples["azimuth_error_rad"], "arcmin")
        stats = result.monte_carlo.statistics["azimuth_error_rad"]
        figures["align_monte_carlo"] = plots.monte_carlo_histogram(
            samples, float(to_unit(result.azimuth_error_sigma_rad, "arcmin")),
            float(to_unit(stats["mean"], "arcmin")), result.model)
    return plots.write_figures(figures, out_dir) + files
