"""Figures of gyrocompassing: time histories (the source's Fig. 1.4), phase trajectory, sweeps, Monte Carlo.

Every function builds one matplotlib figure from results in SI and shows angles
in arcmin or arcsec; :func:`write_figures` saves figures through :mod:`schuler.io`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from schuler.io import save_figure_formats
from schuler.units import to_unit


def _figure(rows: int = 1, height: float = 3.2):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(rows, 1, figsize=(8, height * rows), sharex=rows > 1, squeeze=False)
    return fig, axes[:, 0]


def time_history(runs: dict, title: str = "Gyrocompassing: azimuth and level errors", settling_times: float = 4.0):
    """delta and beta against time for one or more runs, Fig. 1.4 style.

    The time axis spans ``settling_times`` analytic settling times (or the whole
    run if shorter), so that the transient is visible.

    Parameters
    ----------
    runs : dict
        Label -> :class:`~schuler.gyrocompassing.simulation.CaseRun` (SI).
    title : str
        Figure title.
    settling_times : float
        Span of the time axis in analytic settling times, plain number.
    """
    fig, (ax_delta, ax_beta) = _figure(2)
    for label, run in runs.items():
        shown = run.time <= max(settling_times * run.analytic["settling_time_s"], run.time[min(10, run.time.size - 1)])
        minutes = run.time[shown] / 60.0
        ax_delta.plot(minutes, to_unit(run.delta[shown], "arcmin"), label=label)
        ax_beta.plot(minutes, to_unit(run.beta[shown], "arcsec"), label=label)
        steady = run.analytic["azimuth_error_analytic_rad"]
    ax_delta.axhline(to_unit(steady, "arcmin"), color="k", ls=":", lw=0.8, label="delta_y (1.21)")
    ax_delta.set_ylabel("azimuth error delta [arcmin]")
    ax_beta.set_ylabel("level error beta [arcsec]")
    ax_beta.set_xlabel("time [min]")
    ax_delta.set_title(title)
    for axis in (ax_delta, ax_beta):
        axis.grid(True, alpha=0.3)
        axis.legend(loc="best", fontsize=8)
    fig.tight_layout()
    return fig


def phase_trajectory(runs: dict, title: str = "Phase trajectory in the (delta, beta) plane (task 5)"):
    """The platform's path in the (delta, beta) plane for one or more runs (label -> CaseRun).

    Parameters
    ----------
    runs : dict
        Label -> :class:`~schuler.gyrocompassing.simulation.CaseRun` (SI).
    title : str
        Figure title.
    """
    fig, (axis,) = _figure(1, 4.5)
    for label, run in runs.items():
        delta, beta = to_unit(run.delta, "arcmin"), to_unit(run.beta, "arcsec")
        axis.plot(delta, beta, label=label)
        axis.plot(delta[0], beta[0], "o", color=axis.lines[-1].get_color())
    axis.plot([], [], "ko", label="start")
    axis.set_xlabel("azimuth error delta [arcmin]")
    axis.set_ylabel("level error beta [arcsec]")
    axis.set_title(title)
    axis.grid(True, alpha=0.3)
    axis.legend(loc="best", fontsize=8)
    fig.tight_layout()
    return fig


def sweep_curves(x, x_label: str, columns: dict, groups=None):
    """Azimuth error and settling time against a swept parameter.

    Parameters
    ----------
    x : ndarray
        Swept values in display units.
    x_label : str
        Axis label with unit.
    columns : dict of ndarray
        Display-unit columns: ``azimuth_error_analytic_arcmin``, optional
        ``azimuth_error_arcmin`` (simulated), ``settling_time_s``, optional
        ``settling_time_simulated_s``.
    groups : sequence of str, optional
        A label per case: one curve per label (other swept parameters).
    """
    fig, (ax_error, ax_time) = _figure(2)
    groups = np.full(len(x), "") if groups is None else np.asarray(groups)
    for group in dict.fromkeys(groups.tolist()):
        chosen = groups == group
        suffix = f" {group}" if group else ""
        line, = ax_error.plot(x[chosen], columns["azimuth_error_analytic_arcmin"][chosen],
                              label=f"analytic (1.21){suffix}")
        if "azimuth_error_arcmin" in columns:
            ax_error.plot(x[chosen], columns["azimuth_error_arcmin"][chosen], "o", color=line.get_color(),
                          mfc="none", label=f"simulated{suffix}")
        line, = ax_time.plot(x[chosen], columns["settling_time_s"][chosen], label=f"analytic{suffix}")
        if "settling_time_simulated_s" in columns:
            ax_time.plot(x[chosen], columns["settling_time_simulated_s"][chosen], "o", color=line.get_color(),
                         mfc="none", label=f"simulated 1 % band{suffix}")
    ax_error.set_ylabel("azimuth error [arcmin]")
    ax_time.set_ylabel("settling time [s]")
    ax_time.set_ylim(bottom=0)
    ax_time.set_xlabel(x_label)
    ax_error.set_title("Gyrocompassing accuracy and time (task 1)")
    for axis in (ax_error, ax_time):
        axis.grid(True, alpha=0.3)
        axis.legend(loc="best", fontsize=7)
    fig.tight_layout()
    return fig


def monte_carlo_histogram(samples_arcmin, sigma_analytic_arcmin: float, mean_arcmin: float, model: str):
    """Histogram of the Monte Carlo azimuth errors with the analytic normal density beside it.

    Parameters
    ----------
    samples_arcmin : array_like
        Each member's azimuth error, arcmin.
    sigma_analytic_arcmin, mean_arcmin : float
        Standard deviation and mean of the analytic normal density, arcmin.
    model : str
        Name of the model simulated (for the legend).
    """
    fig, (axis,) = _figure(1, 4.0)
    samples = np.asarray(samples_arcmin)
    axis.hist(samples, bins=min(60, max(10, samples.size // 25)), density=True, alpha=0.6,
              label=f"simulated, {samples.size} members")
    if sigma_analytic_arcmin > 0:
        grid = np.linspace(samples.min(), samples.max(), 300)
        density = np.exp(-0.5 * ((grid - mean_arcmin) / sigma_analytic_arcmin) ** 2) / (
            sigma_analytic_arcmin * np.sqrt(2 * np.pi))
        axis.plot(grid, density, "k", label=f"analytic 1-sigma {sigma_analytic_arcmin:.3f} arcmin")
    axis.set_xlabel("azimuth error [arcmin]")
    axis.set_ylabel("probability density [1/arcmin]")
    axis.set_title(f"Monte Carlo over residual drifts and accelerometer errors ({model} model)")
    axis.grid(True, alpha=0.3)
    axis.legend(loc="best", fontsize=8)
    fig.tight_layout()
    return fig


def printed_versus_corrected(time, delta_printed, delta_corrected):
    """delta over time for the printed (1.17) third line and the corrected one, at A = 0.

    Parameters
    ----------
    time : array_like
        Time, s.
    delta_printed, delta_corrected : array_like
        Azimuth error of each model, rad.
    """
    fig, (axis,) = _figure(1, 3.6)
    hours = np.asarray(time) / 3600.0
    axis.plot(hours, to_unit(delta_printed, "deg"), label="(1.17) as printed: diverges")
    axis.plot(hours, to_unit(delta_corrected, "deg"), label="(1.17) corrected")
    axis.set_xlabel("time [h]")
    axis.set_ylabel("azimuth error delta [deg]")
    axis.set_title("Third line of (1.17) as printed vs corrected (A = 0)")
    axis.grid(True, alpha=0.3)
    axis.legend(loc="best", fontsize=8)
    fig.tight_layout()
    return fig


def write_figures(figures: dict, outdir, formats=("png", "svg")) -> list[Path]:
    """Save figures (stem -> Figure) into ``outdir`` in ``formats``; returns the paths.

    Parameters
    ----------
    figures : dict
        File stem -> matplotlib Figure.
    outdir : str or Path
        Folder to write into.
    formats : tuple of str
        File formats (suffixes).
    """
    paths = []
    for stem, fig in figures.items():
        paths += save_figure_formats(fig, Path(outdir) / stem, formats)
    return paths
