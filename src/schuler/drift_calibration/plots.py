"""Figures of the drift calibration: one measurement cycle, Monte Carlo errors, trade-offs.

Inputs are SI (rad, rad/s, s); the figures show arcsec, deg/h and arcmin.
"""

from __future__ import annotations

import numpy as np

from schuler.units import to_unit


def plot_cycle(history, title: str = "One measurement cycle"):
    """Platform angle (arcsec), sensor signal (V) and integrator output (V s) against time; returns the figure.

    Parameters
    ----------
    history : Histories
        The cycle's time histories (:class:`~schuler.core.response.Histories`: ``platform_angle_rad``,
        ``sensor_signal_V``, ``integrator_output_V_s`` against time, s).
    title : str
        Figure title.
    """
    import matplotlib.pyplot as plt

    time = history.time
    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    axes[0].plot(time, to_unit(history["platform_angle_rad"], "arcsec"), label="platform angle alpha_X")
    axes[0].set_ylabel("angle [arcsec]")
    axes[1].plot(time, history["sensor_signal_V"], color="tab:orange", label="command-sensor signal U")
    axes[1].set_ylabel("U [V]")
    axes[2].plot(time, history["integrator_output_V_s"], color="tab:green", label="integrator output")
    axes[2].set_ylabel("integrator [V s]")
    axes[2].set_xlabel("time [s]")
    for axis in axes:
        axis.axvline(time[-1] / 2.0, color="grey", lw=0.8, ls="--")
        axis.grid(True, alpha=0.3)
        axis.legend(loc="upper right")
    axes[0].set_title(title)
    fig.tight_layout()
    return fig


def plot_histograms(samples: dict, title: str = "Monte Carlo errors"):
    """Histograms of the drift errors (deg/h) and the azimuth errors (arcmin) of Monte Carlo members.

    Returns the figure.

    Parameters
    ----------
    samples : dict
        ``drift_x_error_rad_s``, ``drift_y_error_rad_s`` (rad/s, NaN when not
        measured) and ``azimuth_error_rad`` (rad), each an array over members.
    title : str
        Figure title.
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
    for name, label in (("drift_x_error_rad_s", "X gyro"), ("drift_y_error_rad_s", "Y gyro")):
        values = np.asarray(samples[name], dtype=float)
        values = values[np.isfinite(values)]
        if values.size:
            axes[0].hist(to_unit(values, "deg/h"), bins=40, alpha=0.6, label=label)
    axes[0].set_xlabel("drift error, estimated - true [deg/h]")
    axes[0].set_ylabel("members")
    axes[0].legend(loc="upper right")
    azimuth = np.asarray(samples["azimuth_error_rad"], dtype=float)
    axes[1].hist(to_unit(azimuth[np.isfinite(azimuth)], "arcmin"), bins=40, color="tab:purple")
    axes[1].set_xlabel("azimuth error, estimated - true [arcmin]")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_trade_offs(positions, azimuth_by_positions, cycle_times, azimuth_by_cycle):
    """RMS azimuth error (rad in, arcmin shown) against the number of positions and against the cycle time (s).

    Parameters
    ----------
    positions : array_like
        Number of platform positions of each point.
    azimuth_by_positions : array_like
        RMS azimuth error at each number of positions, rad.
    cycle_times : array_like
        Cycle time 2 tau of each point, s.
    azimuth_by_cycle : array_like
        RMS azimuth error at each cycle time, rad.
    """
    import matplotlib.pyplot as plt

    positions = np.asarray(positions, dtype=float)
    by_positions = to_unit(np.asarray(azimuth_by_positions), "arcmin")
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
    axes[0].plot(positions, by_positions, "o-", label="Monte Carlo")
    axes[0].plot(positions, by_positions[0] * np.sqrt(positions[0] / positions), "--", label="1/sqrt(N) from N = 2")
    axes[0].set_xlabel("platform positions N")
    axes[0].set_ylabel("RMS azimuth error [arcmin]")
    axes[0].legend(loc="upper right")
    axes[1].plot(cycle_times, to_unit(np.asarray(azimuth_by_cycle), "arcmin"), "o-")
    axes[1].axvspan(8.0, 15.0, color="grey", alpha=0.2, label="source's cycles")
    axes[1].set_xlabel("cycle time 2 tau [s]")
    axes[1].set_ylabel("RMS azimuth error [arcmin]")
    axes[1].legend(loc="upper right")
    for axis in axes:
        axis.grid(True, alpha=0.3)
    fig.suptitle("Multi-position schemes and cycle time (latitude 70 deg, azimuth 80 deg)")
    fig.tight_layout()
    return fig


__all__ = ["plot_cycle", "plot_histograms", "plot_trade_offs"]
