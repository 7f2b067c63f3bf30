"""Figures of the nonlinear INS (matplotlib, Agg; SI in, display units on the axes).

Every function returns a matplotlib Figure at most 7 in wide with matplotlib's
default fonts (legible in the report at its natural size); writing it is the
caller's job (:func:`schuler.io.save_figure_formats`).
"""

from __future__ import annotations

import numpy as np

from schuler.exceptions import renamed_keywords
from schuler.navigate.channels import DISPLAY_UNITS, suffix
from schuler.units import to_unit

WIDTH = 7.0
"""Width of every figure, in."""


def _figure(*args, **kwargs):
    import matplotlib.pyplot as plt

    return plt.subplots(*args, **kwargs)


def _label_bottom(axes, used: int, label: str) -> None:
    """Hide the panels beyond ``used``; label the time axis of the lowest panel of each column."""
    rows, columns = axes.shape
    for index, axis in enumerate(axes.flat):
        if index >= used:
            axis.set_visible(False)
        elif index + columns >= used:  # nothing below it
            axis.xaxis.set_tick_params(labelbottom=True)
            axis.set_xlabel(label)


def plot_errors(histories, mode: str = "strapdown", channels=None, hours: bool = True):
    """Error histories of a run, one panel per channel (:meth:`NavigationResult.histories
    <schuler.navigate.results.NavigationResult.histories>`, or a run's ``histories["navigate_errors"]``).

    A batch is drawn as its members' mean and the band of +/- one standard deviation.

    Parameters
    ----------
    histories : Histories
        Time (s) and channels named as :data:`~schuler.navigate.channels.ERROR_CHANNELS` (SI: m, m/s, rad),
        shape (n_out,) or (N, n_out).
    mode : str
        The mechanization, for the title (``strapdown`` or ``platform``).
    channels : sequence of str, optional
        Channels to draw (default: every channel of ``histories``).
    hours : bool
        Time axis in hours (else seconds).
    """
    names = list(channels or histories.names)
    rows = (len(names) + 1) // 2
    fig, axes = _figure(rows, 2, figsize=(WIDTH, 2.1 * rows + 0.6), sharex=True, squeeze=False)
    t = histories.time / 3600.0 if hours else histories.time
    for axis, name in zip(axes.flat, names):
        unit = DISPLAY_UNITS[suffix(name)]
        values = to_unit(np.asarray(histories[name]), unit)
        if values.ndim == 2 and values.shape[0] == 1:  # a batch of one member is a single run
            values = values[0]
        if values.ndim == 2:
            mean, spread = values.mean(axis=0), values.std(axis=0)
            axis.fill_between(t, mean - spread, mean + spread, color="C0", alpha=0.25, lw=0, label="+/- 1 sigma")
            axis.plot(t, mean, color="C0", lw=1.2, label="mean")
        else:
            axis.plot(t, values, color="C0", lw=1.2)
        axis.set_title(name.removesuffix("_" + suffix(name)).replace("_", " "))
        axis.set_ylabel(unit)
        axis.grid(True, alpha=0.3)
    _label_bottom(axes, len(names), "time [h]" if hours else "time [s]")
    fig.suptitle(f"{mode} INS errors (computed - true)")
    fig.tight_layout()
    return fig


@renamed_keywords(horizontal_m="horizontal")
def plot_final_errors(horizontal):
    """Histogram of the Monte Carlo members' final horizontal position errors (m).

    Parameters
    ----------
    horizontal : array_like
        Final horizontal position error of each member, m, shape (N,).

    Returns
    -------
    matplotlib.figure.Figure
        The histogram, with the rms marked.
    """
    fig, axis = _figure(figsize=(WIDTH, 4.0))
    values = np.asarray(horizontal, dtype=float)
    axis.hist(values, bins=min(60, max(10, values.size // 20)), color="C0", alpha=0.8)
    axis.axvline(float(np.sqrt(np.mean(values**2))), color="C3", ls="--", label="rms")
    axis.set_xlabel("final horizontal position error [m]")
    axis.set_ylabel("members")
    axis.grid(True, alpha=0.3)
    axis.legend()
    fig.tight_layout()
    return fig


def plot_bollay(comparison):
    """Bollay's (1966) five error sources: nonlinear WGS-84 beside the closed forms.

    ``comparison`` is :func:`~schuler.navigate.seeds.bollay_error_sources`'s.

    Parameters
    ----------
    comparison : BollayComparison
        The five sources' errors (m, SI), drawn in km against hours.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per error source.
    """
    fig, axes = _figure(3, 2, figsize=(WIDTH, 8.5), sharex=True)
    hours = comparison.t_s / 3600.0
    for axis, i in zip(axes.flat, range(len(comparison.sources))):
        axis.plot(hours, comparison.closed_bollay_m[i] / 1e3, color="C3", lw=1.2, ls="--",
                  label="closed form, Bollay's R and T")
        axis.plot(hours, comparison.closed_local_m[i] / 1e3, color="C1", lw=1.2,
                  label="closed form, the flight's R and g_eff")
        every = max(1, hours.size // 40)
        axis.plot(hours[::every], comparison.nonlinear_m[i][::every] / 1e3, "o", ms=3, color="C0",
                  label="nonlinear INS, WGS-84")
        axis.set_title(comparison.sources[i])
        axis.set_ylabel("error [km]")
        axis.grid(True, alpha=0.3)
    _label_bottom(axes, len(comparison.sources), "time since launch [h]")
    fig.legend(*axes.flat[0].get_legend_handles_labels(), loc="center", bbox_to_anchor=(0.75, 0.16))
    fig.suptitle("Bollay's five error sources, 0.5 mi/s due east on the equator")
    fig.tight_layout()
    return fig


def plot_drozdovich(comparison):
    """The worked example of Drozdovich (1959) on the nonlinear platform: velocity error along track beside (29).

    Parameters
    ----------
    comparison : DrozdovichComparison
        :func:`~schuler.navigate.seeds.drozdovich_worked_example`'s (velocity errors in m/s, times in s).

    Returns
    -------
    matplotlib.figure.Figure
        The velocity errors along and across track against hours.
    """
    fig, axis = _figure(figsize=(WIDTH, 5.2))
    hours = comparison.t_s / 3600.0
    axis.plot(hours, comparison.nonlinear_dv_along_m_s, color="C0", lw=0.9, label="nonlinear platform, along track")
    axis.plot(hours, comparison.nonlinear_dv_across_m_s, color="C2", lw=0.9, label="nonlinear platform, across track")
    axis.plot(hours, comparison.quasi_steady_dv_along_m_s, color="C3", lw=1.6, label="(26)/(29) forced, along track")
    axis.axhline(comparison.nonlinear_dv_along_mean_m_s, color="C0", ls=":", label="nonlinear mean, along track")
    axis.set_xlabel("time [h]")
    axis.set_ylabel("velocity error [m/s]")
    axis.set_title("10 m/s due west at 60 deg, W* uncompensated")
    axis.grid(True, alpha=0.3)
    axis.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    fig.tight_layout()
    return fig


def plot_gyrocompassing(comparison):
    """KPI gyrocompassing: azimuth transients and the departures of steady state and settling time.

    Parameters
    ----------
    comparison : GyrocompassingComparison
        :func:`~schuler.navigate.alignment.kpi_gyrocompassing`'s (angles in rad, times in s), drawn
        with the initial azimuth errors in arcmin and the departures in percent.

    Returns
    -------
    matplotlib.figure.Figure
        Normalised azimuth transients (top) and the nonlinear - linear departures (bottom).
    """
    fig, (transients, departures) = _figure(2, 1, figsize=(WIDTH, 8.0))
    arcmin = 180.0 * 60.0 / np.pi
    t = comparison.t_s
    for i in (0, comparison.initial_azimuth_errors_rad.size // 2, -1):
        delta0 = comparison.initial_azimuth_errors_rad[i]
        scale = 1.0 / (delta0 - comparison.steady_full_rad)
        transients.plot(t, (comparison.azimuth_error_nonlinear_rad[i] - comparison.steady_full_rad) * scale, lw=1.2,
                        label=f"nonlinear, delta0 = {delta0 * arcmin:,.0f} arcmin")
    transients.plot(t, (comparison.azimuth_error_full_rad[0] - comparison.steady_full_rad)
                    / (comparison.initial_azimuth_errors_rad[0] - comparison.steady_full_rad), "k--", lw=1,
                    label="(1.17), any delta0")
    transients.set_xlim(0, min(t[-1], 4 * comparison.settling_formula_s))
    transients.set_xlabel("time [s]")
    transients.set_ylabel("(delta - delta_ss) / (delta0 - delta_ss)")
    transients.grid(True, alpha=0.3)
    transients.legend()
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
    departures.legend()
    fig.suptitle("Gyrocompassing: nonlinear platform against the KPI models")
    fig.tight_layout()
    return fig
