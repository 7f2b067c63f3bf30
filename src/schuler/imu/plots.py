"""Figures of the IMU layer: log-log Allan deviation with confidence bands, the fit, slope lines and values.

Each function builds one matplotlib figure from SI results and shows gyros in
deg/h and accelerometers in ug. An analysis is drawn from an
:class:`~schuler.imu.results.AllanResult` or from its ``noise`` JSON (a run
keeps that), so a result redraws from what it holds. :func:`figures` is the
system's hook (every result of ``schuler imu``), :func:`data_files` its CSV
beside the generic writer's; :func:`write_figures` saves figures (PNG and SVG)
through :mod:`schuler.io`.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from schuler.imu.error_model import ErrorModel
from schuler.imu.evaluation import imu_of
from schuler.imu.instrument import resolve_model
from schuler.imu.noise_terms import SLOPES, model_allan_deviation, term_allan_deviations
from schuler.imu.results import DISPLAY_UNITS, AllanResult, IdentifiedTerms, sensor_of, shown_unit
from schuler.io import save_figure_formats, write_dataframe_csv
from schuler.reproduction import Reproduction
from schuler.results import Result, SystemResult
from schuler.units import to_unit

_ADEV_UNITS = {"gyro": "deg/h", "accel": "ug"}


def _figure(columns: int):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, columns, figsize=(5.2 * columns, 4.6), squeeze=False, sharey=True)
    return fig, axes[0]


def _noise(analysis: AllanResult | Mapping) -> Mapping[str, Mapping[str, Any]]:
    """Channel -> its ``noise.<channel>`` data (curve arrays, terms, ``resolved``) of an analysis or its JSON."""
    if isinstance(analysis, AllanResult):
        return {name: channel.to_dict() for name, channel in analysis.noise.items()}
    return analysis


def _curve(channel: Mapping[str, Any], key: str) -> np.ndarray:
    return np.asarray(channel[key], dtype=float)  # a JSON null (not finite) becomes NaN


def _exact(model: ErrorModel, name: str, tau) -> np.ndarray:
    errors = model.gyro if sensor_of(name) == "gyro" else model.accel
    return np.sqrt(errors.allan_variance(tau, "xyz".index(name[-1])))


def _title(analysis: AllanResult | Mapping, sensor: str, title: str | None) -> str:
    if title is not None:
        return title
    grade = analysis.grade if isinstance(analysis, AllanResult) else None
    source = analysis.source if isinstance(analysis, AllanResult) else "record"
    return f"{source}: {sensor} Allan deviation" + (f" (grade: {grade})" if grade else "")


def allan_figure(analysis: AllanResult | Mapping, sensor: str = "gyro", true_model: ErrorModel | None = None,
                 title: str | None = None):
    """Allan deviation of the three axes of one sensor: data with 68 % band, fit, term slope lines.

    Parameters
    ----------
    analysis : AllanResult or mapping
        The analysis, or its ``noise`` JSON (channel -> ``tau_s`` in s, ``adev`` and its bounds in rad/s or m/s^2,
        the terms in the units of :data:`~schuler.imu.results.TERM_UNITS`, ``resolved``).
    sensor : {"gyro", "accel"}
        Which triad to draw (gyros shown in deg/h, accelerometers in ug).
    true_model : ErrorModel, optional
        Draw the model's exact curve too (round trips).
    title : str, optional
        Title of the figure (not set: the record's name, the sensor and the grade).

    Returns
    -------
    matplotlib.figure.Figure
        One panel per axis.
    """
    unit = _ADEV_UNITS[sensor]
    noise = _noise(analysis)
    names = [name for name in noise if sensor_of(name) == sensor]
    fig, axes = _figure(len(names))
    for axis, name in zip(axes, names):
        channel = noise[name]
        tau = _curve(channel, "tau_s")
        values = {term: float(channel[term]) for term in SLOPES}
        axis.fill_between(tau, to_unit(_curve(channel, "adev_lower"), unit), to_unit(_curve(channel, "adev_upper"),
                          unit), alpha=0.25, color="C0", label="68 % confidence")
        axis.loglog(tau, to_unit(_curve(channel, "adev"), unit), "o", ms=3.5, color="C0", label="overlapping ADEV")
        axis.loglog(tau, to_unit(model_allan_deviation(values, tau), unit), "-", color="k", lw=1.2,
                    label="IEEE 952 fit")
        lines = term_allan_deviations(values, tau)
        for index, term in enumerate(("Q", "N", "B", "K", "R")):
            if not channel["resolved"][term]:
                continue
            display = DISPLAY_UNITS[sensor][term]
            axis.loglog(tau, to_unit(lines[term], unit), "--", lw=0.9, color=f"C{index + 1}",
                        label=f"{term} = {to_unit(values[term], display):.3g} {shown_unit(display)} "
                              f"(slope {SLOPES[term]:+g})")
        if true_model is not None:
            axis.loglog(tau, to_unit(_exact(true_model, name, tau), unit), ":", color="C3", lw=1.5,
                        label="true model")
        axis.set_title(name)
        axis.set_xlabel("averaging time tau [s]")
        axis.grid(True, which="both", alpha=0.3)
        axis.legend(loc="best", fontsize=6.5)
    axes[0].set_ylabel(f"Allan deviation [{shown_unit(unit)}]")
    fig.suptitle(_title(analysis, sensor, title))
    # fixed margins: tight_layout measures every log tick label and took most of the figure's time
    fig.subplots_adjust(left=0.06, right=0.99, bottom=0.11, top=0.88, wspace=0.06)
    return fig


def channel_curves(analysis: AllanResult | Mapping, sensor: str = "gyro", true_model: ErrorModel | None = None,
                   title: str | None = None):
    """Compact figure for the report (6.5 in wide, default font sizes): three axes' curves and fits on one plot.

    Markers: the overlapping Allan deviation of x, y, z with 68 % bars; lines:
    the IEEE 952 fit of each; dotted: the true model's curve when given.

    Parameters
    ----------
    analysis : AllanResult or mapping
        The analysis, or its ``noise`` JSON (curves SI); gyros shown in deg/h, accelerometers in ug.
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
    import matplotlib.pyplot as plt

    unit = _ADEV_UNITS[sensor]
    fig, axis = plt.subplots(figsize=(6.5, 4.4))
    noise = _noise(analysis)
    names = [name for name in noise if sensor_of(name) == sensor]
    for index, name in enumerate(names):
        channel, color = noise[name], f"C{index}"
        tau = _curve(channel, "tau_s")
        adev = to_unit(_curve(channel, "adev"), unit)
        bars = np.vstack([adev - to_unit(_curve(channel, "adev_lower"), unit),
                          to_unit(_curve(channel, "adev_upper"), unit) - adev])
        axis.errorbar(tau, adev, yerr=bars, fmt="o", ms=3.5, color=color, elinewidth=0.8, label=name)
        fit = model_allan_deviation({term: float(channel[term]) for term in SLOPES}, tau)
        axis.loglog(tau, to_unit(fit, unit), "-", color=color, lw=1.0)
        if true_model is not None:
            axis.loglog(tau, to_unit(_exact(true_model, name, tau), unit), ":", color="k", lw=1.2,
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
        Channel -> term -> true value, SI (a run's ``true_terms``); the ratio
        identified / true is a plain number, so only matching units matter.

    Returns
    -------
    matplotlib.figure.Figure
        Box plots of the ratios (terms with a zero true value or no finite sample are left out).
    """
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


def figures(result: Result) -> dict[str, Any]:
    """The figures of any ``schuler imu`` result, file stem -> Figure ({} for ``info`` and ``simulate``).

    A run: ``imu_allan_gyro`` and ``imu_allan_accel`` with the true model's
    curves (the model of its ``grade`` or ``spec``), and ``imu_monte_carlo``
    with a Monte Carlo; an Allan analysis (or its identified terms): its
    Allan figures (one per sensor analysed); the reproduction: two per
    analysed record.

    Parameters
    ----------
    result : Result
        What ``run``, ``reproduce``, an action, :func:`~schuler.imu.analysis.allan_deviation` or
        :func:`~schuler.imu.analysis.identify` returned.
    """
    if isinstance(result, IdentifiedTerms):
        result = result.analysis
    if isinstance(result, AllanResult):
        return _analysis_figures(result, "imu_allan")
    if isinstance(result, Reproduction):
        drawn: dict[str, Any] = {}
        for stem, analysis in (result.data or {}).items():
            drawn.update(_analysis_figures(analysis, stem))
        return drawn
    if not isinstance(result, SystemResult):
        return {}
    extras, parameters = result.extras, result.parameters
    model = resolve_model(imu_of(parameters["imu"]))
    grade = f" (grade: {extras['grade']})" if extras["grade"] else ""
    drawn = {f"imu_allan_{sensor}": allan_figure(
        extras["noise"], sensor, model, f"simulated {extras['model']}, seed {extras['seed']}, member "
                                        f"{extras['member']}: {sensor} Allan deviation{grade}")
        for sensor in ("gyro", "accel")}
    if result.monte_carlo is not None:
        drawn["imu_monte_carlo"] = monte_carlo_figure(result.monte_carlo, extras["true_terms"])
    return drawn


def _analysis_figures(analysis: AllanResult, stem: str) -> dict[str, Any]:
    sensors = {sensor_of(name) for name in analysis.noise}
    return {f"{stem}_{sensor}": allan_figure(analysis, sensor) for sensor in ("gyro", "accel") if sensor in sensors}


def data_files(result: Result, out_dir: Path) -> list[Path]:
    """The reproduction's curves as CSV, ``<stem>.csv`` per analysed record (a run's and an analysis' curves are
    their histories, which the generic writer writes as ``imu_allan.csv``).

    Parameters
    ----------
    result : Result
        What an ``imu`` command returned.
    out_dir : Path
        Folder to write into (created if missing).

    Returns
    -------
    list of Path
        The files written: columns ``tau_s`` (s), adev and bounds per channel (rad/s, m/s^2), edf.
    """
    if not isinstance(result, Reproduction):
        return []
    return [write_dataframe_csv(analysis.to_dataframe().reset_index(), Path(out_dir) / f"{stem}.csv")
            for stem, analysis in (result.data or {}).items()]
