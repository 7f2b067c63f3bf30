"""How an ``align`` run reads and draws: :class:`AlignmentRun` (its rendering), :func:`case_runs`, :func:`figures`."""

from __future__ import annotations

import math
import warnings
from typing import Any

from schuler.gyrocompassing.case import GyrocompassingAccuracyWarning
from schuler.gyrocompassing.evaluation import single_case
from schuler.gyrocompassing.simulation import CaseRun
from schuler.gyrocompassing.simulation import run_case as simulate_case
from schuler.reproduction import Reproduction
from schuler.results import Result, SystemResult
from schuler.units import to_unit


class AlignmentRun(SystemResult):
    """One gyrocompassing case as ``align run`` gives it; ``render()`` shows arcmin and arcsec.

    Outputs computed only by the simulation are NaN with ``fidelity="closed"``;
    ``histories["align_time_history"]`` holds the model's time histories.
    """

    def render(self):
        from rich.console import Group
        from rich.table import Table

        def angle(value, unit="arcmin", digits=4):
            return "-" if value is None or math.isnan(value) else f"{_clean(to_unit(value, unit), digits)} {unit}"

        def seconds(value):
            if value is None or math.isnan(value):
                return "-"
            return "not settled" if math.isinf(value) else f"{value:.5g} s"

        out = self.outputs
        table = Table(title=f"Gyrocompassing, {self.extras['model']} model ({self.fidelity})", show_header=True)
        table.add_column("quantity")
        table.add_column("value", justify="right")
        ok = out["constraints_ok"]
        constraint = ("not checked (closed form)" if ok is None or ok != ok
                      else "ok" if ok else "; ".join(self.extras["constraint_violations"]))
        rows = [
            (f"azimuth error ({'simulated' if self.fidelity == 'simulated' else 'closed-form'} steady state)",
             angle(out["azimuth_error_rad"])),
            ("azimuth error, analytic (1.21)", angle(out["azimuth_error_analytic_rad"])),
            ("full model minus (1.21)", angle(out["full_minus_simplified_rad"], "arcsec", 3)),
            ("level error beta", angle(out["level_error_beta_rad"])),
            ("level error beta, analytic (1.25)", angle(out["level_error_beta_analytic_rad"])),
            ("settling time, analytic", f"{seconds(out['settling_time_s'])} ({self.extras['regime']})"),
            ("settling time, simulated 1 % band", seconds(out["settling_time_simulated_s"])),
            ("c_Gamma, c_a", f"{out['c_gamma']:.4g} 1/s, {out['c_a']:.4g} 1/s"),
            ("T, zeta", f"{out['design_time_constant_s']:.4g} s, {out['design_damping']:.3g}"),
            ("constraints (0.4 rad, 0.01 rad, 0.2 rad/s)", constraint),
        ]
        if self.monte_carlo is not None:
            stats = self.monte_carlo["azimuth_error_rad"]
            rows += [
                (f"Monte Carlo ({self.monte_carlo.members} members): mean, std",
                 f"{angle(stats.mean)}, {angle(stats.std)}"),
                ("analytic 1-sigma: model, (1.21)",
                 f"{angle(out['azimuth_error_sigma_rad'])}, {angle(out['azimuth_error_sigma_simplified_rad'])}"),
            ]
        for name, value in rows:
            table.add_row(name, value)
        return Group(table)


def _clean(value: float, digits: int) -> str:
    """A number for people: no negative zero."""
    text = f"{float(value):.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0 else text


def case_runs(result: SystemResult) -> tuple[CaseRun, CaseRun] | None:
    """The run's model and (1.19) simulated in full, for figures that need more than the CSV (None: closed form).

    Parameters
    ----------
    result : SystemResult
        What ``align run`` returned; its case (``parameters``) is simulated again over its ``simulated_duration_s``.
    """
    if result.fidelity != "simulated":
        return None
    single, model = single_case(result.parameters), result.extras["model"]
    duration, step = result.outputs["simulated_duration_s"], result.parameters["output_step"]
    with warnings.catch_warnings():
        # the run has warned already: these are the same case
        warnings.simplefilter("ignore", GyrocompassingAccuracyWarning)
        run = simulate_case(single, model, duration=duration, time_step=step)
        simplified = run if model == "simplified" else simulate_case(single, "simplified", duration=duration,
                                                                     time_step=step)
    return run, simplified


def figures(result: Result) -> dict[str, Any]:
    """The figures of a run (time history, phase trajectory, Monte Carlo histogram) or of the reproduction.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or ``align compare`` returned.
    """
    from schuler.alignment.plots import comparison_figures
    from schuler.gyrocompassing import plots

    if isinstance(result, Reproduction):
        return {"align_reproduction_time_history": plots.time_history(result.data)}
    if not isinstance(result, SystemResult):
        return comparison_figures(result)
    drawn = {}
    simulated = case_runs(result)
    if simulated is not None:
        run, simplified = simulated
        model = result.extras["model"]
        runs = {f"{model} model": run}
        if model != "simplified":
            runs["simplified model (1.19)"] = simplified
        drawn["align_time_history"] = plots.time_history(runs)
        drawn["align_phase_trajectory"] = plots.phase_trajectory(runs)
    if result.monte_carlo is not None:
        samples = to_unit(result.monte_carlo.samples["azimuth_error_rad"], "arcmin")
        drawn["align_monte_carlo"] = plots.monte_carlo_histogram(
            samples, float(to_unit(result.outputs["azimuth_error_sigma_rad"], "arcmin")),
            float(to_unit(result.monte_carlo["azimuth_error_rad"].mean, "arcmin")), result.extras["model"])
    return drawn


def data_files(result: Result, out_dir) -> list:
    """The CSV of an ``align compare`` (a run's and the reproduction's files are its histories and figures).

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce`` or ``align compare`` returned.
    out_dir : Path
        Folder to write into.
    """
    from schuler.alignment.plots import comparison_data_files

    return comparison_data_files(result, out_dir)
