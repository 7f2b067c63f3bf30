"""Figures of the gyro vertical: tilts, velocity errors, spectrum, friction (matplotlib, Agg).

Each function returns a Figure; saving goes through :mod:`schuler.io`. Time is
shown in hours, tilts in arcmin, velocities in m/s.
"""

from __future__ import annotations

import numpy as np

from schuler.core.geometry import ARCMIN

HOUR = 3600.0


def _figure(rows: int, height: float = 2.6):
    # a bare Figure: no pyplot state and no backend switch for the caller's session
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, height * rows))
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False)
    return fig, axes[:, 0]


def _dress(axis, ylabel: str, legend_location: str | None = "outside") -> None:
    """Label and grid; the legend beside the axes (``"outside"``: off the data), at a location, or none."""
    axis.set_ylabel(ylabel)
    axis.grid(True, alpha=0.3)
    if legend_location == "outside":
        axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    elif legend_location:
        axis.legend(loc=legend_location, fontsize=8)


def _finish(fig, axes, title: str, xlabel: str = "time [h]"):
    axes[0].set_title(title)
    axes[-1].set_xlabel(xlabel)
    fig.tight_layout()  # no label clipped at the figure's edge
    return fig


def plot_tilts(analysis, title: str = "Gyro vertical: tilts"):
    """alpha and beta (arcmin) against time, with the forced motion (26).

    Parameters
    ----------
    analysis : Analysis
        A simulated run with its quasi-steady solution (SI).
    title : str
        Figure title.
    """
    r, q = analysis.response, analysis.quasi_steady
    hours = r.time / HOUR
    fig, axes = _figure(2)
    for axis, name, simulated, forced in ((axes[0], "alpha", r.alpha, q.alpha_r), (axes[1], "beta", r.beta, q.beta_r)):
        axis.plot(hours, simulated / ARCMIN, lw=0.8, label="simulation")
        axis.plot(hours, forced / ARCMIN, "--", lw=1.2, label="forced motion (26)")
        _dress(axis, f"{name} [arcmin]")
    return _finish(fig, axes, title)


def plot_velocity_errors(analysis, compensated=None, title: str = "Gyro vertical: velocity errors"):
    """Delta v_x and Delta v_y (m/s) against time, with (29), its slowly-varying form and the compensated run.

    Parameters
    ----------
    analysis : Analysis
        A simulated run with its quasi-steady solution (SI).
    compensated : Analysis, optional
        The same run with the errors compensated, drawn beside it.
    title : str
        Figure title.
    """
    r, q = analysis.response, analysis.quasi_steady
    hours = r.time / HOUR
    fig, axes = _figure(2)
    channels = (("Delta v_x", r.velocity_error_x, q.dv_x, q.slow_dv_x, "velocity_error_x"),
                ("Delta v_y", r.velocity_error_y, q.dv_y, q.slow_dv_y, "velocity_error_y"))
    for axis, (name, simulated, forced, slow, attribute) in zip(axes, channels):
        axis.plot(hours, simulated, lw=0.8, label="simulation")
        axis.plot(hours, forced, "--", lw=1.2, label="quasi-steady (29)")
        axis.plot(hours, slow, ":", lw=1.2, label="slowly varying R omega_2 (alpha_r, beta_r)")
        if compensated is not None:
            axis.plot(hours, getattr(compensated.response, attribute), lw=0.8,
                      label="transport + Coriolis compensated")
        _dress(axis, f"{name} [m/s]")
    return _finish(fig, axes, title)


def plot_quasi_steady(quasi, title: str = "Gyro vertical: quasi-steady velocity errors (29)"):
    """Forced tilts (26) (arcmin) and the quasi-steady errors (29) (m/s) of a closed-form run.

    Parameters
    ----------
    quasi : QuasiSteady
        The closed-form run (SI).
    title : str
        Figure title.
    """
    hours = quasi.time / HOUR
    fig, axes = _figure(2)
    axes[0].plot(hours, quasi.alpha_r / ARCMIN, color="C0", lw=1.2, label="alpha_r")
    axes[0].plot(hours, quasi.beta_r / ARCMIN, color="C1", lw=1.2, label="beta_r")
    for name, forced, slow, colour in (("Delta v_x", quasi.dv_x, quasi.slow_dv_x, "C0"),
                                       ("Delta v_y", quasi.dv_y, quasi.slow_dv_y, "C1")):
        axes[1].plot(hours, forced, color=colour, lw=1.2, label=f"{name} (29)")
        axes[1].plot(hours, slow, ":", color=colour, lw=1.4, label=f"{name} slowly varying")
    _dress(axes[0], "forced tilt [arcmin]")
    _dress(axes[1], "velocity error [m/s]")
    return _finish(fig, axes, title)


def plot_monte_carlo(samples_x, samples_y, title: str = "Monte Carlo: systematic velocity errors"):
    """Histograms of the members' mean velocity errors Delta v_x and Delta v_y (m/s), each on its own axis.

    Parameters
    ----------
    samples_x, samples_y : array_like
        Each member's mean velocity error, m/s.
    title : str
        Figure title.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 5.6))
    axes = fig.subplots(2, 1)
    for axis, name, samples in zip(axes, ("Delta v_x", "Delta v_y"), (samples_x, samples_y)):
        values = np.asarray(samples, dtype=float)
        values = values[np.isfinite(values)]
        if values.size and np.ptp(values) > 1e-12 * max(np.max(np.abs(values)), 1e-300):
            axis.hist(values, bins=min(60, max(10, values.size // 25)), alpha=0.7, label=f"{values.size} members")
        else:  # nothing to bin: every member has the same value (or none)
            for value in values[:1]:
                axis.axvline(value, lw=2, label=f"the same in all {values.size} members: {value:.4g} m/s")
        _dress(axis, "members")
        axis.set_xlabel(f"mean {name} over the run [m/s]")
    axes[0].set_title(title)
    fig.tight_layout()
    return fig


def plot_spectrum(analysis, title: str = "Spectrum of the velocity-error oscillation"):
    """Amplitude of u = Delta v_x - i Delta v_y minus (29) against signed frequency (cycles/h).

    Parameters
    ----------
    analysis : Analysis
        A simulated run with its spectrum (SI).
    title : str
        Figure title.
    """
    fig, axes = _figure(1, height=3.6)
    axis = axes[0]
    spectrum = analysis.spectrum
    cycles_per_hour = spectrum.frequency * HOUR
    shown = np.abs(cycles_per_hour) < 2.0
    axis.semilogy(cycles_per_hour[shown], np.maximum(spectrum.amplitude[shown], 1e-12), lw=0.8, label="simulation")
    for sign, period in zip((1, -1), analysis.eigen_periods):
        axis.axvline(sign * HOUR / period, color="C1", ls="--", lw=0.8)
    axis.axvline(HOUR / 86400, color="C3", ls=":", lw=1.0, label="24 h (source's claim)")
    axis.axvline(-HOUR / 86400, color="C3", ls=":", lw=1.0)
    axis.plot([], [], color="C1", ls="--", label="eigenvalues (split Schuler modes)")
    _dress(axis, "amplitude [m/s]", "upper center")  # between the mode lines; "best" is slow on long spectra
    return _finish(fig, axes, title, "frequency [cycles/h] (sign: sense of rotation of the error vector)")


def plot_friction(response, q, radius, title: str = "Coulomb friction: velocity errors and the dead zone +-R q",
                  zoom_hours: float = 3.0):
    """Delta v_x, Delta v_y (m/s) with the dead zone and stick intervals; below, the first hours enlarged.

    Parameters
    ----------
    response : FrictionResponse
        The friction simulation: ``time`` in s, ``velocity_error_x`` and ``velocity_error_y`` in m/s, and the
        stick intervals as (begin, end) pairs in s.
    q : pair of float
        (q_1, q_2) = M_fr / H of the outer (x) and inner (y) axis, rad/s.
    radius : float
        R, m (the dead zone is +-R q).
    title : str
        Title of the top panel.
    zoom_hours : float
        Length of the enlarged start shown in the bottom panel, hours.

    Returns
    -------
    matplotlib.figure.Figure
        Three panels: Delta v_x and Delta v_y against time in hours, then the first ``zoom_hours`` enlarged.
    """
    from matplotlib.figure import Figure

    hours = response.time / HOUR
    fig = Figure(figsize=(9, 8))
    grid = fig.add_gridspec(3, 1)
    top = fig.add_subplot(grid[0])
    axes = [top, fig.add_subplot(grid[1], sharex=top)]
    zoom = fig.add_subplot(grid[2])
    limits = (radius * q[0], radius * q[1])
    for axis, name, values, limit in zip(axes, ("Delta v_x", "Delta v_y"),
                                         (response.velocity_error_x, response.velocity_error_y), limits):
        axis.plot(hours, values, lw=0.8, label="simulation")
        axis.axhspan(-limit, limit, color="C2", alpha=0.25, label="dead zone +-R q")
        for begin, end in response.stick_intervals:
            axis.axvspan(begin / HOUR, end / HOUR, color="0.6", alpha=0.3, lw=0)
        _dress(axis, f"{name} [m/s]", None)
    axes[0].plot([], [], color="0.6", alpha=0.5, lw=6, label="both gimbals stuck")
    axes[0].legend(loc="upper left", fontsize=8)
    axes[0].set_title(title)
    early = hours <= zoom_hours
    for name, values, colour in (("Delta v_x", response.velocity_error_x, "C0"),
                                 ("Delta v_y", response.velocity_error_y, "C1")):
        zoom.plot(hours[early], values[early], lw=1.0, color=colour, label=name)
    for limit, style in zip(limits, ("--", ":")):
        zoom.axhline(limit, color="C2", ls=style, lw=1.0)
        zoom.axhline(-limit, color="C2", ls=style, lw=1.0)
    for begin, end in response.stick_intervals:
        if begin / HOUR < zoom_hours:
            zoom.axvspan(begin / HOUR, min(end / HOUR, zoom_hours), color="0.6", alpha=0.3, lw=0)
    _dress(zoom, "velocity error [m/s]", "upper left")
    zoom.set_xlabel(f"time [h] (first {zoom_hours:g} h; lines: +-R q_1 dashed, +-R q_2 dotted)")
    fig.tight_layout()
    return fig
