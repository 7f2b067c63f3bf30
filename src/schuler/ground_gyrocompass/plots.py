"""Figures of the ground gyrocompass: fit and residuals, misfit map, error against time.

Each function draws one figure and writes it through :mod:`schuler.io` (PNG and
SVG); it returns the written paths.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np

from schuler.ground_gyrocompass.grid import axis
from schuler.io import save_figure_formats

ARCSEC_PER_RAD = 180.0 * 3600.0 / math.pi
ARCMIN_PER_RAD = 180.0 * 60.0 / math.pi


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_fit(estimate, stem, formats=("png", "svg")):
    """Observed coordinate with the fitted model (arcmin) and the residuals (arcsec).

    Parameters
    ----------
    estimate : NorthEstimate
        An estimate with its record (``time`` s, ``observed`` and ``residuals`` rad).
    stem : str or Path
        Path of the files without suffix.
    formats : tuple of str
        Suffixes to write, e.g. ``("png", "svg")``.

    Returns
    -------
    list of Path
        The files written.
    """
    plt = _pyplot()
    time = estimate.time
    fitted = estimate.observed - estimate.residuals
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, height_ratios=(2, 1))
    top.plot(time, estimate.observed * ARCMIN_PER_RAD, ".", ms=3, label="observed")
    top.plot(time, fitted * ARCMIN_PER_RAD, "-", lw=1.2, label=f"fit, {estimate.unknowns} unknowns ({estimate.method})")
    top.set_ylabel("observed azimuth motion, arcmin")
    top.set_title(f"Rotor run-down: north {estimate.north_dms} from the rotor axis at release")
    top.legend(loc="upper right")  # "best" scans every point: slow (and warns) on long records
    top.grid(alpha=0.3)
    bottom.plot(time, estimate.residuals * ARCSEC_PER_RAD, ".", ms=3, color="C3")
    bottom.axhline(0.0, color="k", lw=0.6)
    bottom.set_xlabel("time since release, s")
    bottom.set_ylabel("residual, arcsec")
    bottom.grid(alpha=0.3)
    fig.tight_layout()
    return save_figure_formats(fig, stem, formats)


def plot_misfit_map(stage, stem, formats=("png", "svg"), title=None):
    """log10 of the misfit over (alpha0, alpha0_dot) of a grid stage, best cell marked.

    Parameters
    ----------
    stage : Stage
        A grid stage (:class:`~.grid.Stage`): its box (SI), best cell and misfit surface (rad^2).
    stem : str or Path
        Path of the files without suffix.
    formats : tuple of str
        Suffixes to write, e.g. ``("png", "svg")``.
    title : str, optional
        The figure's title (default: the stage's cells).

    Returns
    -------
    list of Path
        The files written.
    """
    plt = _pyplot()
    alpha0 = axis(*stage.box["alpha0"]) * ARCMIN_PER_RAD
    rate = axis(*stage.box["alpha0_dot"]) * 1e4
    fig, ax = plt.subplots(figsize=(7, 5.5))
    levels = np.log10(np.maximum(stage.surface, 1e-30))
    mesh = ax.pcolormesh(rate, alpha0, levels, shading="nearest", cmap="viridis")
    fig.colorbar(mesh, ax=ax, label="log10 misfit F, rad^2")
    best_rate, best_angle = stage.best["alpha0_dot"] * 1e4, stage.best["alpha0"] * ARCMIN_PER_RAD
    ax.plot(best_rate, best_angle, "r+", ms=14, mew=2, label="best cell")
    ax.set_xlabel("initial rate alpha0_dot, 1e-4 rad/s")
    ax.set_ylabel("initial angle alpha0, arcmin")
    # wrapped: a one-line title centred over the axes (shifted left by the colour bar) ran off the figure's edge
    ax.set_title(textwrap.fill(title or f"First grid stage ({stage.cells} cells), at the best lambda and B", 56))
    ax.legend(loc="upper right")
    fig.tight_layout()
    return save_figure_formats(fig, stem, formats)


def plot_error_vs_time(durations, series, stem, title, formats=("png", "svg")):
    """North standard error (arcsec) against the observation window.

    ``series`` is a list of (label, values in arcsec, style) drawn on a log scale.

    Parameters
    ----------
    durations : array_like (k,)
        Observation windows, s.
    series : list of (str, array_like (k,), str)
        Label, north standard error in arcsec (display unit) at each window, matplotlib format string.
    stem : str or Path
        Path of the files without suffix.
    title : str
        The figure's title.
    formats : tuple of str
        Suffixes to write, e.g. ``("png", "svg")``.

    Returns
    -------
    list of Path
        The files written.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 5))
    for label, values, style in series:
        ax.plot(durations, values, style, label=label)
    ax.set_yscale("log")
    ax.set_xlabel("observation window, s")
    ax.set_ylabel("north standard error, arcsec")
    ax.set_title(title)
    ax.grid(alpha=0.3, which="both")
    ax.legend(loc="upper right")
    fig.tight_layout()
    return save_figure_formats(fig, stem, formats)


def plot_study(study, stem, formats=("png", "svg")):
    """Monte Carlo scatter and predicted standard error of north against the window.

    Parameters
    ----------
    study : NorthErrorStudy
        A Monte Carlo study (:func:`~.monte_carlo.monte_carlo`; its errors are in arcsec, windows in s).
    stem : str or Path
        Path of the files without suffix.
    formats : tuple of str
        Suffixes to write, e.g. ``("png", "svg")``.

    Returns
    -------
    list of Path
        The files written.
    """
    series = []
    for j, noise in enumerate(study.noises_arcsec):
        series.append((f'Monte Carlo, noise {noise:g}"', study.std_error_arcsec[:, j], f"C{j}o"))
        series.append((f'predicted (Jacobian), noise {noise:g}"', study.predicted_std_arcsec[:, j], f"C{j}-"))
    title = f"Accuracy against time: {study.unknowns} unknowns, {study.members} runs per point"
    return plot_error_vs_time(study.durations_s, series, stem, title, formats)


def plot_record(time, observed, stem, title, formats=("png", "svg")):
    """An observation record: the observed coordinate (arcmin) against time.

    Parameters
    ----------
    time : ndarray (n,)
        Sample times since release, s.
    observed : ndarray (n,)
        Observed coordinate, rad (drawn in arcmin).
    stem : str or Path
        Path of the files without suffix.
    title : str
        The figure's title.
    formats : tuple of str
        Suffixes to write, e.g. ``("png", "svg")``.

    Returns
    -------
    list of Path
        The files written.
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.plot(time, observed * ARCMIN_PER_RAD, ".", ms=3)
    ax.set_xlabel("time since release, s")
    ax.set_ylabel("observed azimuth motion, arcmin")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return save_figure_formats(fig, stem, formats)


def plot_error_histogram(errors_arcsec, predicted_std_arcsec, stem, title, formats=("png", "svg")):
    """Histogram of Monte Carlo north errors (arcsec) with the normal density of the predicted standard error.

    Parameters
    ----------
    errors_arcsec : array_like
        North errors (identified - true), arcsec (display unit; non-finite ones are left out).
    predicted_std_arcsec : float
        Predicted standard error of north, arcsec (0: no density drawn).
    stem : str or Path
        Path of the files without suffix.
    title : str
        The figure's title.
    formats : tuple of str
        Suffixes to write, e.g. ``("png", "svg")``.

    Returns
    -------
    list of Path
        The files written.
    """
    plt = _pyplot()
    errors = np.asarray(errors_arcsec, dtype=float)
    errors = errors[np.isfinite(errors)]
    fig, ax = plt.subplots(figsize=(7, 5))
    ax.hist(errors, bins=max(10, min(60, errors.size // 20)), density=True, alpha=0.6, label="Monte Carlo")
    if predicted_std_arcsec > 0.0:
        x = np.linspace(-4 * predicted_std_arcsec, 4 * predicted_std_arcsec, 201)
        density = np.exp(-0.5 * (x / predicted_std_arcsec) ** 2) / (predicted_std_arcsec * math.sqrt(2 * math.pi))
        ax.plot(x, density, "k-", label=f"predicted, sigma = {predicted_std_arcsec:.3g} arcsec")
    ax.set_xlabel("north error (identified - true), arcsec")
    ax.set_ylabel("probability density, 1/arcsec")
    ax.set_title(title)
    ax.legend(loc="upper right")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return save_figure_formats(fig, stem, formats)
