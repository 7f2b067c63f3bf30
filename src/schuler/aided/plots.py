"""The figures of ``schuler aided``: the errors inside the filter's +-3-sigma envelopes, and the drift per outage."""

from __future__ import annotations

import numpy as np

from schuler.units import to_unit


def _outage_spans(axis, outages, scale: float = 1.0 / 60.0) -> None:
    for outage in outages:
        start, duration = outage["start_s"], outage["duration_s"]
        axis.axvspan(start * scale, (start + duration) * scale, color="0.85", lw=0)


PLOTTED_POINTS = 4000
"""Points drawn per curve at most: a 200-Hz run is thinned to a stride (the figure shows minutes, not samples)."""


def error_envelopes(histories, outages):
    """North, east, down and heading errors of one member with the filter's +-3-sigma (outages shaded).

    Without a truth (no error channels) the envelopes alone are drawn; with the smoother's channels
    (``smoothed_``, :func:`schuler.aided.histories.error_histories`) its errors and +-3-sigma are drawn beside.

    Parameters
    ----------
    histories : Histories
        ``aided_errors`` of a run (m, rad).
    outages : list of dict
        The run's outages (``start_s``, ``duration_s``, s).
    """
    import matplotlib.pyplot as plt

    stride = max(1, int(np.ceil(histories.time.size / PLOTTED_POINTS)))
    origin = histories.time[0] if histories.time.size else 0.0  # seconds of week on files: minutes from the start
    minutes = (histories.time[::stride] - origin) / 60.0
    fig, axes = plt.subplots(4, 1, sharex=True, figsize=(8, 8.5))
    rows = [("north_error_m", "north_sigma_m", "north [m]", 1.0), ("east_error_m", "east_sigma_m", "east [m]", 1.0),
            ("down_error_m", "down_sigma_m", "down [m]", 1.0),
            ("heading_error_rad", "heading_sigma_rad", "heading [deg]", float(to_unit(1.0, "deg")))]
    shifted = [{**o, "start_s": o["start_s"] - origin} for o in outages]
    for axis, (error, sigma, label, scale) in zip(axes, rows):
        _outage_spans(axis, shifted)
        envelope = 3 * histories[sigma][::stride] * scale
        axis.fill_between(minutes, -envelope, envelope, color="tab:blue", alpha=0.2, lw=0, label="+-3 sigma")
        if error in histories:
            axis.plot(minutes, histories[error][::stride] * scale, color="tab:red", lw=0.8, label="error")
        if f"smoothed_{sigma}" in histories:
            envelope = 3 * histories[f"smoothed_{sigma}"][::stride] * scale
            axis.plot(minutes, envelope, color="tab:green", lw=0.6, ls="--", label="+-3 sigma smoothed")
            axis.plot(minutes, -envelope, color="tab:green", lw=0.6, ls="--")
        if f"smoothed_{error}" in histories:
            axis.plot(minutes, histories[f"smoothed_{error}"][::stride] * scale, color="tab:green", lw=0.8,
                      label="smoothed error")
        axis.set_ylabel(label)
        axis.grid(True, alpha=0.3)
    axes[0].legend(loc="upper right", fontsize=9, ncol=2)
    truth = "errors and " if "north_error_m" in histories else ""
    if "smoothed_north_sigma_m" in histories:
        axes[0].set_title(f"Aided INS: {truth}+-3-sigma, forward and smoothed (GNSS outages shaded)")
    else:
        axes[0].set_title(f"Aided INS: {truth}the filter's +-3-sigma (GNSS outages shaded)")
    axes[-1].set_xlabel("time from the start [min]")
    fig.tight_layout()
    return fig


def outage_drift(outages):
    """Largest horizontal error in each outage beside the filter's 1-sigma at its end.

    Parameters
    ----------
    outages : list of dict
        The run's outages (``start_s``, ``horizontal_error_max_m``, ``horizontal_error_sigma_m``; s, m).
    """
    import matplotlib.pyplot as plt

    fig, axis = plt.subplots(figsize=(7, 3.5))
    x = np.arange(len(outages))
    if all(o["horizontal_error_max_m"] is not None for o in outages):
        axis.bar(x - 0.2, [o["horizontal_error_max_m"] for o in outages], 0.4, label="largest horizontal error")
    axis.bar(x + 0.2, [o["horizontal_error_sigma_m"] for o in outages], 0.4, label="filter 1-sigma at the end")
    # a simulated drive's times count from its start; a file's are seconds of week, shown as they are
    axis.set_xticks(x, [(f"{o['start_s'] / 60:.0f} min" if o["start_s"] < 86_400 else f"{o['start_s']:.0f} s")
                        + f", {o['duration_s']:.0f} s" for o in outages])
    axis.set_ylabel("horizontal [m]")
    axis.set_title("Drift through each GNSS outage")
    axis.legend(fontsize=9)
    axis.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    return fig


def innovations(histories, outages):
    """Each GNSS residual over the filter's predicted 1-sigma at every epoch, with +-3 (rejected epochs marked).

    A consistent filter keeps about 99.7 % of the points inside the band; a drift of the points or a band
    crossed often says the filter's Q or R is wrong (the NIS of the JSON counts it).

    Parameters
    ----------
    histories : Histories
        ``aided_innovations`` of a run (plain numbers).
    outages : list of dict
        The run's outages (``start_s``, ``duration_s``, s).
    """
    import matplotlib.pyplot as plt

    origin = histories.time[0] if histories.time.size else 0.0
    minutes = (histories.time - origin) / 60.0
    groups = [name for name in ("position", "velocity") if f"{name}_north_normalised" in histories]
    fig, axes = plt.subplots(len(groups), 1, sharex=True, figsize=(8, 2.8 * len(groups) + 0.6), squeeze=False)
    rejected = histories["accepted"] < 0.5
    shifted = [{**o, "start_s": o["start_s"] - origin} for o in outages]
    for axis, group in zip(axes[:, 0], groups):
        _outage_spans(axis, shifted)
        for axis_name, colour in (("north", "tab:blue"), ("east", "tab:orange"), ("down", "tab:green")):
            values = histories[f"{group}_{axis_name}_normalised"]
            axis.plot(minutes, values, ".", ms=2, color=colour, label=axis_name)
            if rejected.any():
                axis.plot(minutes[rejected], values[rejected], "x", color="k", ms=5)
        axis.axhline(3.0, color="grey", lw=0.8, ls="--")
        axis.axhline(-3.0, color="grey", lw=0.8, ls="--", label="+-3")
        axis.set_ylabel(f"GNSS {group} residual / sigma")
        axis.grid(True, alpha=0.3)
    axes[0, 0].legend(loc="upper right", fontsize=8, ncol=4)
    axes[0, 0].set_title("Innovations over their predicted 1-sigma" + (" (x: rejected)" if rejected.any() else ""))
    axes[-1, 0].set_xlabel("time from the start [min]")
    fig.tight_layout()
    return fig


def figures(result) -> dict:
    """The figures of an aided run (``{}`` for results without histories).

    Parameters
    ----------
    result : SystemResult
        What ``schuler aided run`` returned.
    """
    histories = getattr(result, "histories", {})
    if "aided_errors" not in histories:
        return {}
    outages = result.extras.get("outages", [])
    drawn = {"aided_errors": error_envelopes(histories["aided_errors"], outages)}
    if outages:
        drawn["aided_outage_drift"] = outage_drift(outages)
    if "aided_innovations" in histories and histories["aided_innovations"].time.size:
        drawn["aided_innovations"] = innovations(histories["aided_innovations"], outages)
    return drawn
