"""Figures of the mission study: the error budget stacked over time."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from schuler.mission.covariance import CovarianceBudget

SHOWN_SOURCES = 8
"""Sources drawn separately in the stacked plot (the rest are summed as "others")."""


def stacked_budget(budget: CovarianceBudget):
    """Horizontal position-error variance over time, stacked by source (largest final shares first).

    Parameters
    ----------
    budget : CovarianceBudget
        The mission's covariance analysis (variances in m^2, times in s; drawn in km^2 over hours).

    Returns
    -------
    matplotlib.figure.Figure
        Two panels: the variance stacked by source, and each source's share of it.
    """
    import matplotlib.pyplot as plt

    horizontal = budget.horizontal()
    order = np.argsort(-horizontal[-1])
    shown = [i for i in order[:SHOWN_SOURCES] if horizontal[-1, i] > 0]
    rest = [i for i in order if i not in shown]
    layers = [horizontal[:, i] for i in shown]
    labels = [budget.sources[i] for i in shown]
    if rest and np.any(horizontal[:, rest]):
        layers.append(horizontal[:, rest].sum(axis=1))
        labels.append("others")
    hours = budget.time / 3600.0
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    total = horizontal.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        fractions = [np.where(total > 0, layer / total, 0.0) for layer in layers]
    top.stackplot(hours, [layer / 1e6 for layer in layers], labels=labels)
    top.set_ylabel("horizontal position variance [km^2]")
    top.set_title("Error budget: each source's share of the horizontal position-error variance")
    top.legend(loc="upper left", fontsize=8)
    bottom.stackplot(hours, fractions, labels=labels)
    bottom.set_ylabel("share of the variance")
    bottom.set_xlabel("time [h]")
    bottom.set_ylim(0.0, 1.0)
    fig.tight_layout()
    return fig


def write_figures(figures: dict, out_dir, formats=("png", "svg")) -> list[Path]:
    """Save figures (stem -> Figure) into ``out_dir`` in ``formats``; returns the paths.

    Parameters
    ----------
    figures : dict of str to matplotlib.figure.Figure
        File stem -> figure.
    out_dir : str or Path
        Folder to write into.
    formats : tuple of str
        File formats (suffixes without the dot), e.g. ``("png", "svg")``.

    Returns
    -------
    list of Path
        The files written.
    """
    from schuler.io import save_figure_formats

    paths: list[Path] = []
    for stem, fig in figures.items():
        paths += save_figure_formats(fig, Path(out_dir) / stem, formats)
    return paths
