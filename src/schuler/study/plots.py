"""Summary plots of a sweep, drawn from streamed statistics (never from all cases)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from schuler.io import save_figure_formats
from schuler.units import to_unit

MAX_RESULTS_PLOTTED = 8
"""Results plotted at most (all of them are in results.csv and summary.json)."""


def plot_sweep_summary(plan, statistics: dict, per_axis: dict, out_dir) -> list[Path]:
    """One PNG per result: its mean and range against each swept parameter.

    A sweep without grid axes (a pure Monte Carlo) gets the percentiles of each
    result instead. Returns the files written (``summary_<result>.png``).
    """
    import matplotlib.pyplot as plt

    files: list[Path] = []
    for name in list(statistics)[:MAX_RESULTS_PLOTTED]:
        stats = statistics[name]
        panels = len(plan.axes) or 1
        fig, axes = plt.subplots(1, panels, figsize=(4.5 * panels, 3.6), squeeze=False)
        if plan.axes:
            for ax, axis in zip(axes[0], plan.axes):
                _axis_panel(ax, plan, axis, per_axis[(axis.name, name)], name)
        else:
            _percentile_panel(axes[0][0], stats, name)
        fig.suptitle(f"{plan.system} sweep: {name} ({plan.total} cases)")
        fig.tight_layout()
        files.extend(save_figure_formats(fig, Path(out_dir) / f"summary_{name}", ("png",), dpi=100))
    return files


def _axis_panel(ax, plan, axis, summary: dict, name: str) -> None:
    spec = next(p for p in plan.parameters if p.name == axis.name)
    x = axis.values
    label = axis.name
    if spec.kind == "quantity":
        x = to_unit(np.asarray(x, dtype=float), spec.unit)
        label = f"{axis.name} [{spec.unit}]" if spec.unit else axis.name
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


def _percentile_panel(ax, stats: dict, name: str) -> None:
    keys = ["min", "p05", "p50", "p95", "max"]
    values = [np.nan if stats[k] is None else stats[k] for k in keys]
    ax.bar(keys, values, color="tab:blue", alpha=0.7)
    if stats["mean"] is not None:
        ax.axhline(stats["mean"], color="tab:red", label=f"mean {stats['mean']:.4g}")
        ax.legend(fontsize="small")
    ax.set_ylabel(name)
    ax.set_xlabel("statistic over all cases")
    ax.grid(True, axis="y", alpha=0.3)
