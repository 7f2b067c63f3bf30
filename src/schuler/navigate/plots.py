"""Figures of the nonlinear INS (matplotlib, Agg; SI in, display units on the axes).

Every function returns a matplotlib Figure; writing it is the caller's job
(:func:`schuler.io.save_figure_formats`).
"""

from __future__ import annotations

import numpy as np

from schuler.navigate.results import ERROR_CHANNELS, VERTICAL_CHANNELS_OUTPUT
from schuler.units import to_unit

_LABELS = {"m": ("m", "position"), "m_s": ("m/s", "velocity"), "rad": ("arcsec", "attitude")}


def _figure(*args, **kwargs):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.subplots(*args, **kwargs)


def _unit(name: str) -> str:
    return "m_s" if name.endswith("_m_s") else name.rsplit("_", 1)[-1]


def plot_errors(result, channels=None, hours: bool = True):
    """Error histories of a :class:`~schuler.navigate.results.NavigationResult`, one panel per channel.

    A batch is drawn as its members' mean and the band of +/- one standard deviation.

    Parameters
    ----------
    result : NavigationResult
    channels : sequence of str, optional
        Names from :data:`~schuler.navigate.results.ERROR_CHANNELS` (default: all, the vertical
        ones only when the vertical channel is on).
    hours : bool
        Time axis in hours (else seconds).
    """
    names = list(channels or [c for c in ERROR_CHANNELS
                              if result.vertical_channel != "off" or c not in VERTICAL_CHANNELS_OUTPUT])
    rows = (len(names) + 2) // 3
    fig, axes = _figure(rows, 3, figsize=(13, 2.8 * rows), sharex=True, squeeze=False)
    t = result.t_s / 3600.0 if hours else result.t_s
    for axis, name in zip(axes.flat, names):
        unit, _ = _LABELS[_unit(name)]
        values = to_unit(np.asarray(result.channel(name)), unit)
        if values.ndim == 2:
            mean, spread = values.mean(axis=0), values.std(axis=0)
            axis.fill_between(t, mean - spread, mean + spread, color="C0", alpha=0.25, lw=0, label="+/- 1 sigma")
            axis.plot(t, mean, color="C0", lw=1.2, label="mean")
        else:
            axis.plot(t, values, color="C0", lw=1.2)
        axis.set_title(name.removesuffix("_" + _unit(name)).replace("_", " "), fontsize=10)
        axis.set_ylabel(unit)
        axis.grid(True, alpha=0.3)
    for axis in axes.flat[len(names):]:
        axis.set_visible(False)
    for axis in axes[-1]:
        axis.set_xlabel("time [h]" if hours else "time [s]")
    fig.suptitle(f"{result.mode} INS errors (computed - true), vertical channel {result.vertical_channel}")
    fig.tight_layout()
    return fig


def plot_bollay(comparison):
    """Source 002's five error sources: nonlinear WGS-84 beside the closed forms (:func:`~schuler.navigate.seeds.bollay_error_sources`)."""
    fig, axes = _figure(2, 3, figsize=(14, 7), sharex=True)
    t = comparison.t_s
    for axis, i in zip(axes.flat, range(len(comparison.sources))):
        axis.plot(t, comparison.closed_bollay_m[i], color="C3", lw=1.2, ls="--", label="closed form, Bollay's R, T")
        axis.plot(t, comparison.closed_local_m[i], color="C1", lw=1.2, label="closed form, flight's R, g_eff")
        every = max(1, t.size // 60)
        axis.plot(t[::every], comparison.nonlinear_m[i][::every], "o", ms=3, color="C0", label="nonlinear INS, WGS-84")
        axis.set_title(comparison.sources[i])
        axis.set_ylabel("error [m]")
        axis.grid(True, alpha=0.3)
    axes.flat[0].legend(fontsize=8)
    axes.flat[-1].set_visible(False)
    for axis in axes[-1]:
        axis.set_xlabel("time since launch [s]")
    fig.suptitle("Bollay's error sources: launch due east on the equator, 0.5 mi/s for 10,120 s")
    fig.tight_layout()
    return fig


def plot_drozdovich(comparison):
    """Source 000's worked example on the nonlinear platform: velocity error along track beside (29)."""
    fig, axis = _figure(figsize=(10, 4.2))
    hours = comparison.t_s / 3600.0
    axis.plot(hours, comparison.nonlinear_dv_along_m_s, color="C0", lw=0.9, label="nonlinear platform, along track")
    axis.plot(hours, comparison.nonlinear_dv_across_m_s, color="C2", lw=0.9, label="nonlinear platform, across track")
    axis.plot(hours, comparison.quasi_steady_dv_along_m_s, color="C3", lw=1.6, label="(26)/(29) forced, along track")
    axis.axhline(comparison.nonlinear_dv_along_mean_m_s, color="C0", ls=":", label="nonlinear mean, along track")
    axis.set_xlabel("time [h]")
    axis.set_ylabel("velocity error [m/s]")
    axis.set_title("10 m/s due west at 60 deg, Coriolis and centripetal terms uncompensated")
    axis.grid(True, alpha=0.3)
    axis.legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_gyrocompassing(comparison):
    """KPI gyrocompassing: azimuth transients and the departures of steady state and settling time."""
    fig, (transients, departures) = _figure(1, 2, figsize=(13, 4.5))
    arcmin = 180.0 * 60.0 / np.pi
    t = comparison.t_s
    for i in (0, comparison.initial_azimuth_errors_rad.size // 2, -1):
        delta0 = comparison.initial_azimuth_errors_rad[i]
        scale = 1.0 / (delta0 - comparison.steady_full_rad)
        transients.plot(t, (comparison.azimuth_error_nonlinear_rad[i] - comparison.steady_full_rad) * scale, lw=1.2,
                        label=f"nonlinear, delta0 = {delta0 * arcmin:,.0f}'")
    transients.plot(t, (comparison.azimuth_error_full_rad[0] - comparison.steady_full_rad)
                    / (comparison.initial_azimuth_errors_rad[0] - comparison.steady_full_rad), "k--", lw=1,
                    label="(1.17), any delta0")
    transients.set_xlim(0, min(t[-1], 4 * comparison.settling_formula_s))
    transients.set_xlabel("time [s]")
    transients.set_ylabel("(delta - delta_ss) / (delta0 - delta_ss)")
    transients.grid(True, alpha=0.3)
    transients.legend(fontsize=8)
    delta0 = comparison.initial_azimuth_errors_rad * arcmin
    for values, label in ((comparison.steady_departure_full, "steady state vs (1.17)"),
                          (comparison.steady_departure_simplified, "steady state vs (1.19)"),
                          (comparison.settling_departure_full, "settling time vs (1.17)"),
                          (comparison.settling_departure_simplified, "settling time vs (1.19)"),
                          (comparison.decay_departure_full, "decay time vs (1.17)")):
        departures.semilogx(delta0, 100 * np.asarray(values), "o-", ms=3, label=label)
    for bound in (1.0, -1.0):
        departures.axhline(bound, color="k", lw=0.8, ls=":")
    departures.set_xlabel("initial azimuth error delta0 [arcmin]")
    departures.set_ylabel("nonlinear - linear [%]")
    departures.grid(True, alpha=0.3, which="both")
    departures.legend(fontsize=8)
    fig.suptitle("Gyrocompassing: nonlinear platform against the KPI models")
    fig.tight_layout()
    return fig
