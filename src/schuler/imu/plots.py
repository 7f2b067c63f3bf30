"""Figures of the IMU layer: log-log Allan deviation with confidence bands, the fit, slope lines and values.

Each function builds one matplotlib figure from SI results and shows gyros in
deg/h and accelerometers in ug; :func:`write_figures` saves figures (PNG and
SVG) through :mod:`schuler.io`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from schuler.imu.error_model import ErrorModel
from schuler.imu.identify import SLOPES, term_allan_deviations
from schuler.imu.results import DISPLAY_UNITS, AllanResult, sensor_of, shown_unit
from schuler.io import save_figure_formats
from schuler.units import to_unit

_ADEV_UNITS = {"gyro": "deg/h", "accel": "ug"}


def _figure(columns: int):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, columns, figsize=(5.2 * columns, 4.6), squeeze=False, sharey=True)
    return fig, axes[0]


def allan_figure(result: AllanResult, sensor: str = "gyro", true_model: ErrorModel | None = None):
    """Allan deviation of the three axes of one sensor: data with 68 % band, fit, term slope lines.

    Parameters
    ----------
    result : AllanResult
    sensor : {"gyro", "accel"}
    true_model : ErrorModel, optional
        Draw the model's exact curve too (round trips).
    """
    unit = _ADEV_UNITS[sensor]
    names = [name for name in result.noise if sensor_of(name) == sensor]
    fig, axes = _figure(len(names))
    for axis, name in zip(axes, names):
        channel = result.noise[name]
        curve, terms = channel.curve, channel.terms
        tau = curve.tau_s
        axis.fill_between(tau, to_unit(curve.adev_lower, unit), to_unit(curve.adev_upper, unit), alpha=0.25,
                          color="C0", label="68 % confidence")
        axis.loglog(tau, to_unit(curve.adev, unit), "o", ms=3.5, color="C0", label="overlapping ADEV")
        axis.loglog(tau, to_unit(terms.model_adev(tau), unit), "-", color="k", lw=1.2, label="IEEE 952 fit")
        lines = term_allan_deviations(terms.values, tau)
        for index, term in enumerate(("Q", "N", "B", "K", "R")):
            if not terms.resolved[term]:
                continue
            display = DISPLAY_UNITS[sensor][term]
            axis.loglog(tau, to_unit(lines[term], unit), "--", lw=0.9, color=f"C{index + 1}",
                        label=f"{term} = {to_unit(terms.values[term], display):.3g} {shown_unit(display)} "
                              f"(slope {SLOPES[term]:+g})")
        if true_model is not None:
            errors = true_model.gyro if sensor == "gyro" else true_model.accel
            exact = np.sqrt(errors.allan_variance(tau, "xyz".index(name[-1])))
            axis.loglog(tau, to_unit(exact, unit), ":", color="C3", lw=1.5, label="true model")
        axis.set_title(name)
        axis.set_xlabel("averaging time tau [s]")
        axis.grid(True, which="both", alpha=0.3)
        axis.legend(loc="best", fontsize=6.5)
    axes[0].set_ylabel(f"Allan deviation [{shown_unit(unit)}]")
    fig.suptitle(f"{result.source}: {sensor} Allan deviation" + (f" (grade: {result.grade})" if result.grade else ""))
    # fixed margins: tight_layout measures every log tick label and took most of the figure's time
    fig.subplots_adjust(left=0.06, right=0.99, bottom=0.11, top=0.88, wspace=0.06)
    return fig


def channel_curves(result: AllanResult, sensor: str = "gyro", true_model: ErrorModel | None = None,
                   title: str | None = None):
    """Compact figure for the report (6.5 in wide, default font sizes): three axes' curves and fits on one plot.

    Markers: the overlapping Allan deviation of x, y, z with 68 % bars; lines:
    the IEEE 952 fit of each; dotted: the true model's curve when given.

    Parameters
    ----------
    result : AllanResult
        The analysis whose curves (SI) are drawn; gyros shown in deg/h, accelerometers in ug.
    sensor : {"gyro", "accel"}
        Which triad's three axes to draw.
    true_model : ErrorModel, optional
        Draw the model's exact curve too (round trips).
    title : str, optional
        Title of the plot (not set: "<sensor> Allan deviation").

    Returns
    -------
    matplotlib.figure.Figure
        The figure, 6.5 x 4.4 in.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    unit = _ADEV_UNITS[sensor]
    fig, axis = plt.subplots(figsize=(6.5, 4.4))
    names = [name for name in result.noise if sensor_of(name) == sensor]
    for index, name in enumerate(names):
        channel = result.noise[name]
        curve, color = channel.curve, f"C{index}"
        adev = to_unit(curve.adev, unit)
        bars = np.vstack([adev - to_unit(curve.adev_lower, unit), to_unit(curve.adev_upper, unit) - adev])
        axis.errorbar(curve.tau_s, adev, yerr=bars, fmt="o", ms=3.5, color=color, elinewidth=0.8, label=name)
        axis.loglog(curve.tau_s, to_unit(channel.terms.model_adev(curve.tau_s), unit), "-", color=color, lw=1.0)
        if true_model is not None:
            errors = true_model.gyro if sensor == "gyro" else true_model.accel
            exact = np.sqrt(errors.allan_variance(curve.tau_s, "xyz".index(name[-1])))
            axis.loglog(curve.tau_s, to_unit(exact, unit), ":", color="k", lw=1.2,
                        label="true model" if index == 0 else None)
    axis.plot([], [], "-", color="0.4", label="IEEE 952 fit")
    axis.set_xscale("log")
    axis.set_yscale("log")
    axis.set_xlabel("averaging time tau [s]")
    axis.set_ylabel(f"Allan deviation [{shown_unit(unit)}]")
    axis.grid(True, which="both", alpha=0.3)
    axis.legend(loc="best")
    axis.set_title(title or f"{sensor} Allan deviation")
    fig.subplots_adjust(left=0.15, right=0.97, bottom=0.12, top=0.92)
    return fig


def monte_carlo_figure(summary, true_terms: dict):
    """Identified / true of each resolved term over the Monte Carlo records, gyro x and accelerometer x.

    Parameters
    ----------
    summary : MonteCarloSummary
        The Monte Carlo of ``schuler imu run``: its ``samples`` of ``noise_<channel>_<term>`` (SI) per member.
    true_terms : dict of str to dict of str to float
        Channel -> term -> true value, SI (:attr:`~schuler.imu.run_results.ImuRunResult.true_terms`); the ratio
        identified / true is a plain number, so only matching units matter.

    Returns
    -------
    matplotlib.figure.Figure
        Box plots of the ratios (terms with a zero true value or no finite sample are left out).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axis = plt.subplots(figsize=(6.5, 4.0))
    labels, ratios = [], []
    for channel in ("gyro_x", "accel_x"):
        for term in ("N", "B", "K", "Q"):
            truth = true_terms[channel][term]
            samples = np.asarray(summary.samples.get(f"noise_{channel}_{term}", []), dtype=float)
            samples = samples[np.isfinite(samples)]
            if truth > 0 and samples.size:
                labels.append(f"{channel} {term}")
                ratios.append(samples / truth)
    if ratios:
        axis.boxplot(ratios, tick_labels=labels)
    axis.axhline(1.0, color="k", lw=0.8)
    axis.set_ylabel("identified / true")
    axis.set_title(f"Round trip over {summary.members} records (seed {summary.seed})")
    axis.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    return fig


def write_figures(figures: dict, outdir, formats=("png", "svg")) -> list[Path]:
    """Save figures (stem -> Figure) into ``outdir`` in ``formats``; returns the paths.

    Parameters
    ----------
    figures : dict of str to matplotlib.figure.Figure
        File stem -> figure.
    outdir : str or Path
        Folder to write into.
    formats : tuple of str
        File formats (suffixes without the dot), e.g. ``("png", "svg")``.

    Returns
    -------
    list of Path
        The files written.
    """
    paths = []
    for stem, fig in figures.items():
        paths += save_figure_formats(fig, Path(outdir) / stem, formats)
    return paths
