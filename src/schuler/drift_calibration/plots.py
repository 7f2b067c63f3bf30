"""Figures of the drift calibration: one measurement cycle and Monte Carlo error histograms."""

from __future__ import annotations


import numpy as np


def plot_cycle(time, platform_angle, sensor_signal, integrator_output, title: str = "One measurement cycle"):
    """Platform angle (arcsec), sensor signal and integrator output (V) versus time (s); returns the figure."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    axes[0].plot(time, np.degrees(platform_angle) * 3600.0, label="platform angle alpha_X")
    axes[0].set_ylabel("angle [arcsec]")
    axes[1].plot(time, sensor_signal, color="tab:orange", label="command-sensor signal U")
    axes[1].set_ylabel("U [V]")
    axes[2].plot(time, integrator_output, color="tab:green", label="integrator output")
    axes[2].set_ylabel("integrator [V s]")
    axes[2].set_xlabel("time since start [s]")
    for axis in axes:
        axis.axvline(time[-1] / 2.0, color="grey", lw=0.8, ls="--")
        axis.grid(True, alpha=0.3)
        axis.legend(loc="best")
    axes[0].set_title(title)
    fig.tight_layout()
    return fig


def plot_histograms(drift_errors, azimuth_errors, title: str = "Monte Carlo errors"):
    """Histograms of the drift errors (deg/h) and azimuth errors (arcmin); returns the figure."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
    drift = np.degrees(np.atleast_2d(drift_errors.T).T) * 3600.0
    for column, name in zip(drift.T, ("X gyro", "Y gyro")):
        axes[0].hist(column, bins=40, alpha=0.6, label=name)
    axes[0].set_xlabel("drift error [deg/h]")
    axes[0].set_ylabel("procedures")
    axes[0].legend()
    axes[1].hist(np.degrees(azimuth_errors) * 60.0, bins=40, color="tab:purple")
    axes[1].set_xlabel("azimuth error [arcmin]")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_trade_offs(positions, azimuth_by_positions, cycle_times, azimuth_by_tau):
    """RMS azimuth error (arcmin) versus number of positions and versus cycle time (s)."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
    axes[0].plot(positions, np.degrees(azimuth_by_positions) * 60.0, "o-", label="Monte Carlo")
    axes[0].plot(positions, np.degrees(azimuth_by_positions[0]) * 60.0 * np.sqrt(positions[0] / positions), "--",
                 label="1/sqrt(N) from N = 2")
    axes[0].set_xlabel("platform positions N")
    axes[0].set_ylabel("RMS azimuth error [arcmin]")
    axes[0].legend()
    axes[1].plot(cycle_times, np.degrees(azimuth_by_tau) * 60.0, "o-")
    axes[1].axvspan(8.0, 15.0, color="grey", alpha=0.2, label="source's cycles")
    axes[1].set_xlabel("cycle time 2 tau [s]")
    axes[1].set_ylabel("RMS azimuth error [arcmin]")
    axes[1].legend()
    for axis in axes:
        axis.grid(True, alpha=0.3)
    fig.suptitle("Multi-position schemes and cycle time (latitude 70 deg, azimuth 80 deg)")
    fig.tight_layout()
    return fig


__all__ = ["plot_cycle", "plot_histograms", "plot_trade_offs"]
