"""Summary plots of a sweep, drawn from streamed statistics (never from all cases)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from schuler.io import save_figure_formats
from schuler.results import display_label
from schuler.units import to_unit

MAX_RESULTS_PLOTTED = 8
"""Results plotted at most (all of them are in results.csv and summary.json)."""


def plot_sweep_summary(plan, statistics: dict, per_axis: dict, histograms: dict, out_dir,
                       display_units: dict | None = None) -> list[Path]:
    """One figure per result that varies: its mean and range against each swept parameter, and its histogram.

    Values are shown in the result's display unit (``display_units``: name ->
    unit, e.g. arcmin for an angle in rad). Returns the files written
    (``summary_<result>.png``).

    Parameters
    ----------
    plan : SweepPlan
        The sweep's plan (its axes, parameters' units, system name and number of cases).
    statistics : dict of str to dict
        Result name -> ``count``, ``min``, ``max``, ``mean``, ``p05``, ``p50``, ``p95``, ... over all cases,
        in the result's SI unit (as :func:`~schuler.study.summary.gather` returns them).
    per_axis : dict of (str, str) to dict
        (axis name, result name) -> arrays over the axis' values of ``mean``, ``min``, ``max`` (SI) and
        ``count``.
    histograms : dict of str to (numpy.ndarray, numpy.ndarray)
        Result name -> (counts, bin edges in SI), as :func:`~schuler.study.summary.histograms` returns them.
    out_dir : str or Path
        Folder the PNG files are written to.
    display_units : dict of str to str, optional
        Result name -> the unit it is shown in (``arcmin``); a result not in it is shown in SI.

    Returns
    -------
    list of Path
        The files written, one per varying result (at most :data:`MAX_RESULTS_PLOTTED`).
    """
    import matplotlib.pyplot as plt

    display_units = display_units or {}
    files: list[Path] = []
    varying = [name for name, stats in statistics.items() if stats["count"] and stats["max"] > stats["min"]]
    for name in varying[:MAX_RESULTS_PLOTTED]:
        unit = display_units.get(name, "")
        label = display_label(name, unit)
        scale = 1.0 / float(to_unit(1.0, unit)) if unit else 1.0

        def shown(values, scale=scale):
            return np.asarray(values, dtype=float) / scale

        panels = len(plan.axes) + 1
        fig, axes = plt.subplots(1, panels, figsize=(min(4.5 * panels, 13.5), 3.8), squeeze=False)
        for ax, axis in zip(axes[0], plan.axes):
            summary = {key: shown(value) for key, value in per_axis[(axis.name, name)].items() if key != "count"}
            _axis_panel(ax, plan, axis, summary, label)
        stats = {key: (None if value is None else float(shown(value)) if key not in ("count", "nan_count")
                       else value) for key, value in statistics[name].items()}
        histogram = histograms.get(name)
        if histogram is not None:
            histogram = (histogram[0], shown(histogram[1]))
        _histogram_panel(axes[0][-1], stats, histogram, label)
        fig.suptitle(f"{plan.system} sweep: {label} ({plan.total} cases)")
        fig.tight_layout()
        files.extend(save_figure_formats(fig, Path(out_dir) / f"summary_{name}", ("png",), dpi=100))
    return files


def _axis_panel(ax, plan, axis, summary: dict, name: str) -> None:
    spec = next(p for p in plan.parameters if p.name == axis.name)
    x = axis.values
    label = axis.name
    if spec.kind == "quantity":
        x = to_unit(np.asarray(x, dtype=float), spec.unit)
        label = f"{axis.name} ({spec.unit})" if spec.unit else axis.name
    positions = np.arange(len(x)) if x.dtype.kind in "USO" else x
    ax.plot(positions, summary["mean"], marker="o", markersize=3, label="mean")
    if plan.total > len(x):
        ax.fill_between(positions, summary["min"], summary["max"], alpha=0.25, label="min to max")
    if x.dtype.kind in "USO":
        ax.set_xticks(positions, [str(v) for v in x])
    ax.set_xlabel(label)
    ax.set_ylabel(name)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")


def _histogram_panel(ax, stats: dict, histogram, name: str) -> None:
    if histogram is None:
        # every case gave the same value (or none was finite): say so instead of drawing one bar
        shown = "no finite value" if stats["mean"] is None else f"every case: {stats['mean']:.6g}"
        ax.text(0.5, 0.5, shown, ha="center", va="center", transform=ax.transAxes)
        ax.set_axis_off()
        return
    counts, edges = histogram
    ax.stairs(counts, edges, fill=True, alpha=0.6, label=f"{int(counts.sum())} cases")
    for key, style in (("p05", ":"), ("p50", "--"), ("p95", ":")):
        if stats[key] is not None:
            ax.axvline(stats[key], color="black", linestyle=style, linewidth=1)
    ax.axvline(stats["mean"], color="tab:red", label=f"mean {stats['mean']:.4g}")
    ax.set_xlabel(name)
    ax.set_ylabel("cases")
    ax.set_title("distribution (dotted: 5 % and 95 %, dashed: median)", fontsize="small")
    ax.legend(fontsize="small")
    ax.grid(True, alpha=0.3)
