"""Figures of the ground gyrocompass: fit and residuals, misfit map, error against time, record, histogram.

Each function draws one matplotlib figure from values in SI (angles shown in
arcmin or arcsec) and returns it; :mod:`schuler.ground_gyrocompass.files` names them and the system's
writer saves them.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np

from schuler.ground_gyrocompass.grid import axis

ARCSEC_PER_RAD = 180.0 * 3600.0 / math.pi
ARCMIN_PER_RAD = 180.0 * 60.0 / math.pi


def _figure(width: float, height: float, rows: int = 1, **options):
    """A figure outside pyplot (no backend chosen or switched) and its axes."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height))
    return fig, fig.subplots(rows, 1, **options)


def plot_fit(estimate):
    """Observed coordinate with the fitted model (arcmin) and the residuals (arcsec).

    Parameters
    ----------
    estimate : NorthEstimate or RecordFit
        A fit with its record: ``time`` s, ``observed`` and ``residuals`` rad, ``unknowns``, ``method`` and
        ``north_dms`` (:class:`~.estimate.NorthEstimate`, :class:`~schuler.ground_gyrocompass.files.RecordFit`).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    time = estimate.time
    fitted = estimate.observed - estimate.residuals
    fig, (top, bottom) = _figure(8, 6, 2, sharex=True, height_ratios=(2, 1))
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
    return fig


def plot_misfit_map(stage, title=None):
    """log10 of the misfit over (alpha0, alpha0_dot) of a grid stage, best cell marked.

    Parameters
    ----------
    stage : Stage
        A grid stage (:class:`~.grid.Stage`): its box (SI), best cell and misfit surface (rad^2).
    title : str, optional
        The figure's title (default: the stage's cells).

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    alpha0 = axis(*stage.box["alpha0"]) * ARCMIN_PER_RAD
    rate = axis(*stage.box["alpha0_dot"]) * 1e4
    fig, ax = _figure(7, 5.5)
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
    return fig


def plot_error_vs_time(durations, series, title):
    """North standard error (arcsec) against the observation window.

    ``series`` is a list of (label, values in arcsec, style) drawn on a log scale.

    Parameters
    ----------
    durations : array_like (k,)
        Observation windows, s.
    series : list of (str, array_like (k,), str)
        Label, north standard error in arcsec (display unit) at each window, matplotlib format string.
    title : str
        The figure's title.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = _figure(7, 5)
    for label, values, style in series:
        ax.plot(durations, values, style, label=label)
    ax.set_yscale("log")
    ax.set_xlabel("observation window, s")
    ax.set_ylabel("north standard error, arcsec")
    ax.set_title(title)
    ax.grid(alpha=0.3, which="both")
    ax.legend(loc="upper right")
    fig.tight_layout()
    return fig


def plot_record(time, observed, title):
    """An observation record: the observed coordinate (arcmin) against time.

    Parameters
    ----------
    time : ndarray (n,)
        Sample times since release, s.
    observed : ndarray (n,)
        Observed coordinate, rad (drawn in arcmin).
    title : str
        The figure's title.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    fig, ax = _figure(8, 4.5)
    ax.plot(time, observed * ARCMIN_PER_RAD, ".", ms=3)
    ax.set_xlabel("time since release, s")
    ax.set_ylabel("observed azimuth motion, arcmin")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def plot_error_histogram(errors_arcsec, predicted_std_arcsec, title):
    """Histogram of Monte Carlo north errors (arcsec) with the normal density of the predicted standard error.

    Parameters
    ----------
    errors_arcsec : array_like
        North errors (identified - true), arcsec (display unit; non-finite ones are left out).
    predicted_std_arcsec : float
        Predicted standard error of north, arcsec (0: no density drawn).
    title : str
        The figure's title.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.
    """
    errors = np.asarray(errors_arcsec, dtype=float)
    errors = errors[np.isfinite(errors)]
    fig, ax = _figure(7, 5)
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
    return fig
