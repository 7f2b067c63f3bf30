"""How long a GNSS outage each IMU survives: the outage at which the horizontal 1-sigma reaches a bound.

The question asked before buying an IMU. A sweep of the aided mission over
``outage_duration`` (and ``imu``),

    schuler mission sweep SCENARIO --param imu=navigation,tactical,industrial,consumer \\
        --param outage_duration=1,2,5,10,...

gives per instrument the covariance's horizontal 1-sigma at the end of the worst
outage, sigma(d) (``outage_horizontal_error_sigma_m``,
:func:`schuler.mission.aiding.aided_budget`). It grows with d, piecewise like a
power of it (d from a velocity error, d^2 from a tilt or an accelerometer bias,
d^3 from a gyro bias, Groves 2013, Sec. 14.4), so the longest outage within a
bound b is found between the two sweep points around it by interpolation
linear in log d and log sigma: log d_b = log d_i + (log b - log sigma_i)
(log d_i+1 - log d_i) / (log sigma_i+1 - log sigma_i).

References
----------
P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed.,
Artech House, 2013, Sec. 14.4 (the drift of an INS through a GNSS outage).
"""

from __future__ import annotations

import math

import numpy as np

from schuler.exceptions import InvalidParameter

BOUNDS = (1.0, 10.0, 100.0)
"""Horizontal 1-sigma bounds of the survival table, m."""

DURATION = "outage_duration_s"
"""The sweep's column of the outage duration, s."""

SIGMA = "outage_horizontal_error_sigma_m"
"""The sweep's column of the 1-sigma at the worst outage's end, m."""


def longest_outage(durations, sigmas, bound: float) -> float:
    """The longest outage whose horizontal 1-sigma at its end stays within ``bound`` (module docstring), s.

    Parameters
    ----------
    durations : array_like
        Outage durations of the sweep, s (> 0, any order).
    sigmas : array_like
        The horizontal 1-sigma at each one's end, m (> 0).
    bound : float
        The bound, m (> 0).

    Returns
    -------
    float
        s; 0 when even the shortest outage exceeds the bound, ``inf`` when the longest stays within it.

    Examples
    --------
    >>> round(longest_outage([10.0, 100.0], [1.0, 100.0], 10.0), 6)   # sigma ~ d^2
    31.622777
    """
    d = np.asarray(durations, dtype=float)
    s = np.asarray(sigmas, dtype=float)
    if d.shape != s.shape or d.size == 0 or not (np.all(d > 0) and np.all(s > 0) and bound > 0):
        raise InvalidParameter("outage_duration", "the survival needs outages > 0 s with 1-sigma > 0 m, one each")
    order = np.argsort(d)
    d, s = d[order], np.maximum.accumulate(s[order])  # the drift never shrinks with a longer outage
    if s[0] > bound:
        return 0.0
    if s[-1] <= bound:
        return math.inf
    i = int(np.flatnonzero(s > bound)[0]) - 1
    if s[i + 1] == s[i]:
        return float(d[i])
    fraction = (math.log(bound) - math.log(s[i])) / (math.log(s[i + 1]) - math.log(s[i]))
    return float(math.exp(math.log(d[i]) + fraction * (math.log(d[i + 1]) - math.log(d[i]))))


def survival_table(frame, by: str = "imu", bounds=BOUNDS):
    """The longest outage within each bound, per instrument, from a sweep's results (``results.parquet``).

    Parameters
    ----------
    frame : pandas.DataFrame
        The sweep's cases: ``by`` (the instrument), :data:`DURATION` (s) and :data:`SIGMA` (m) among its columns.
    by : str
        The column that names the instrument.
    bounds : sequence of float
        Horizontal 1-sigma bounds, m.

    Returns
    -------
    pandas.DataFrame
        One row per instrument (in the sweep's order), one column per bound (``"1 m"`` ...): the longest outage, s.
    """
    import pandas as pd

    rows = {}
    for name, group in frame.groupby(by, sort=False):
        rows[name] = {f"{bound:g} m": longest_outage(group[DURATION], group[SIGMA], bound)
                      for bound in bounds}
    table = pd.DataFrame.from_dict(rows, orient="index")
    table.index.name = by
    return table


def survival_figure(frame, by: str = "imu", bounds=BOUNDS):
    """The horizontal 1-sigma at the outage's end against its duration, per instrument, with the bounds.

    Parameters
    ----------
    frame : pandas.DataFrame
        The sweep's cases (as :func:`survival_table`): durations in s, 1-sigma in m.
    by : str
        The column that names the instrument.
    bounds : sequence of float
        Horizontal 1-sigma bounds drawn, m.

    Returns
    -------
    matplotlib.figure.Figure
        Log-log: one line per instrument, the bounds dashed.
    """
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5))
    for name, group in frame.groupby(by, sort=False):
        group = group.sort_values(DURATION)
        ax.loglog(group[DURATION], group[SIGMA], marker="o", label=str(name))
    for bound in bounds:
        ax.axhline(bound, color="grey", linestyle="--", linewidth=0.8)
    ax.set_xlabel("GNSS outage [s]")
    ax.set_ylabel("horizontal position error at its end, 1-sigma [m]")
    ax.set_title("How long an outage each IMU survives")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig
