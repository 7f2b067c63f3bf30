"""Figures of the mission study: the error budget stacked over time (the ``figures`` hook of ``SYSTEM``)."""

from __future__ import annotations

import numpy as np

from schuler.core.response import Histories

SHOWN_SOURCES = 8
"""Sources drawn separately in the stacked plot (the rest are summed as "others")."""

BUDGET_HISTORIES = "mission_budget"
"""Stem of the budget's histories (``mission_budget.csv``) and of its figure."""

_PREFIX, _SUFFIX = "variance_", "_m2"


def stacked_budget(histories: Histories):
    """Horizontal position-error variance over time, stacked by source (largest final shares first).

    Parameters
    ----------
    histories : Histories
        The budget's histories (:func:`~schuler.mission.evaluation.budget_histories`): each source's
        ``variance_<source>_m2`` in m^2 over ``t_s`` in s (drawn in km^2 over hours).

    Returns
    -------
    matplotlib.figure.Figure
        Two panels: the variance stacked by source, and each source's share of it.
    """
    import matplotlib.pyplot as plt

    names = [name for name in histories.names if name.startswith(_PREFIX) and name.endswith(_SUFFIX)]
    sources = [name[len(_PREFIX):-len(_SUFFIX)] for name in names]
    horizontal = np.stack([np.asarray(histories[name], dtype=float) for name in names], axis=1)
    order = np.argsort(-horizontal[-1])
    shown = [i for i in order[:SHOWN_SOURCES] if horizontal[-1, i] > 0]
    rest = [i for i in order if i not in shown]
    layers = [horizontal[:, i] for i in shown]
    labels = [sources[i] for i in shown]
    if rest and np.any(horizontal[:, rest]):
        layers.append(horizontal[:, rest].sum(axis=1))
        labels.append("others")
    hours = np.asarray(histories.time, dtype=float) / 3600.0
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


def figures(result) -> dict:
    """The figures of a mission result: the stacked budget of a run (``{}`` for results without histories).

    Parameters
    ----------
    result : Result
        What a ``mission`` command returned (a run's :class:`~schuler.mission.results.MissionResult`, or the
        reproduction, which draws none).
    """
    histories = getattr(result, "histories", {})
    if BUDGET_HISTORIES not in histories:
        return {}
    return {BUDGET_HISTORIES: stacked_budget(histories[BUDGET_HISTORIES])}
