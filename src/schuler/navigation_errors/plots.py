"""Figures of the navigation-error system (matplotlib, Agg; SI in, display units on the axes).

Every function returns a matplotlib Figure; writing it is the caller's job
(:func:`schuler.io.save_figure_formats`).
"""

from __future__ import annotations

import numpy as np

from schuler.units import to_unit

SOURCE_TITLES = {
    "tilt": "initial level misalignment",
    "velocity": "initial velocity error",
    "accelerometer": "accelerometer error",
    "drift": "gyro drift",
    "azimuth": "azimuth misalignment",
}


def _figure(*args, **kwargs):
    import matplotlib.pyplot as plt

    return plt.subplots(*args, **kwargs)


def plot_flat_vs_spherical(time, flat, spherical, unit: str, title: str, simulated=None):
    """One error source: flat vs spherical Earth (left), the spherical error alone (right).

    Parameters
    ----------
    time : ndarray
        t, s.
    flat, spherical : ndarray
        Position errors, m.
    unit : str
        Display unit of the errors ("ft", "m", "mi").
    title : str
        Figure title.
    simulated : (ndarray, ndarray), optional
        Times (s) and simulated spherical errors (m), drawn as markers (at most ~45).
    """
    fig, (both, alone) = _figure(1, 2, figsize=(11, 4.2))
    for axis in (both, alone):
        axis.plot(time, to_unit(spherical, unit), color="C0", lw=1.8, label="spherical Earth (Schuler)")
        if simulated is not None:
            simulated_time, simulated_error = simulated
            every = max(1, len(simulated_time) // 45)
            axis.plot(simulated_time[::every], to_unit(simulated_error[::every], unit), "o", ms=3.5, color="C2",
                      label="spherical, simulated")
        axis.set_xlabel("time since launch [s]")
        axis.set_ylabel(f"position error [{unit}]")
        axis.grid(True, alpha=0.3)
    both.plot(time, to_unit(flat, unit), color="C3", lw=1.8, ls="--", label="flat Earth")
    both.set_title("flat vs spherical Earth")
    alone.set_title("spherical Earth, enlarged")
    both.legend(loc="upper left")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_overview(time, flat: dict, spherical: dict, unit: str, title: str):
    """All sources on one log-scale axis: flat (dashed) and spherical (solid) |error|.

    Parameters
    ----------
    time : ndarray
        t, s.
    flat, spherical : dict of str -> ndarray
        Position errors per source, m.
    unit : str
        Display unit.
    title : str
    """
    fig, axis = _figure(figsize=(12, 5.5))
    floor = to_unit(1e-3, unit)
    for index, source in enumerate(spherical):
        color = f"C{index}"
        label = SOURCE_TITLES.get(source, source)
        axis.plot(time, np.maximum(np.abs(to_unit(spherical[source], unit)), floor), color=color, lw=1.6,
                  label=f"{label}, spherical")
        axis.plot(time, np.maximum(np.abs(to_unit(flat[source], unit)), floor), color=color, lw=1.2, ls="--",
                  label=f"{label}, flat")
    axis.set_yscale("log")
    axis.set_ylim(bottom=to_unit(1.0, unit))
    axis.set_xlabel("time since launch [s]")
    axis.set_ylabel(f"|position error| [{unit}] (log scale)")
    axis.set_title(title)
    axis.grid(True, which="both", alpha=0.25)
    axis.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    return fig


def plot_vertical(time, unaided, aided: dict, unit: str, title: str):
    """Pure-inertial (divergent) vs baro-aided altitude error.

    Parameters
    ----------
    time : ndarray
        t, s.
    unaided : ndarray
        Pure-inertial altitude error, m.
    aided : dict of str -> ndarray
        Label -> aided altitude error, m.
    unit : str
        Display unit.
    title : str
    """
    large = {"ft": "mi", "m": "km"}.get(unit, unit)  # the divergence reaches hundreds of miles
    fig, (left, right) = _figure(1, 2, figsize=(11, 4.2))
    left.plot(time, to_unit(unaided, large), color="C3", lw=1.8, label="pure inertial")
    for index, (label, values) in enumerate(aided.items()):
        left.plot(time, to_unit(values, large), color=f"C{index}", lw=1.4, label=label)
        right.plot(time, to_unit(values, unit), color=f"C{index}", lw=1.4, label=label)
    left.set_title("pure inertial diverges")
    right.set_title("baro-aided loops, enlarged")
    for axis, shown in ((left, large), (right, unit)):
        axis.set_xlabel("time [s]")
        axis.set_ylabel(f"altitude error [{shown}]")
        axis.grid(True, alpha=0.3)
        axis.legend()
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_foucault(time, north, east, unit: str, title: str):
    """Ground track of the horizontal position error: the Schuler swing turning at the Foucault rate.

    Parameters
    ----------
    time : ndarray
        t, s (colour).
    north, east : ndarray
        Position errors, m.
    unit : str
    title : str
    """
    fig, axis = _figure(figsize=(6.4, 6))
    hours = np.asarray(time) / 3600.0
    east_shown, north_shown = to_unit(np.asarray(east), unit), to_unit(np.asarray(north), unit)
    axis.plot(east_shown, north_shown, lw=0.5, color="0.6")
    points = axis.scatter(east_shown, north_shown, c=hours, s=3, cmap="viridis")
    fig.colorbar(points, ax=axis, label="time [h]")
    axis.set_xlabel(f"east error [{unit}]")
    axis.set_ylabel(f"north error [{unit}]")
    axis.set_aspect("equal")
    axis.set_title(title)
    axis.grid(True, alpha=0.3)
    fig.tight_layout()
    return fig


def plot_three_d(time, histories: dict, unit: str, title: str):
    """3-D model: horizontal position errors (left) and attitude errors psi (right) against time.

    Parameters
    ----------
    time : ndarray
        t, s (shown in hours).
    histories : dict of str -> ndarray
        State histories of the psi-angle model (``position_error_north`` ... in m,
        ``psi_north`` ... in rad).
    unit : str
        Display unit of the position errors.
    title : str
    """
    fig, (position, attitude) = _figure(1, 2, figsize=(11, 4.2))
    hours = np.asarray(time) / 3600.0
    for index, axis_name in enumerate(("north", "east", "down")):
        key = f"position_error_{axis_name}"
        if key in histories:
            position.plot(hours, to_unit(histories[key], unit), color=f"C{index}", lw=1.4, label=axis_name)
        attitude.plot(hours, to_unit(histories[f"psi_{axis_name}"], "arcsec"), color=f"C{index}", lw=1.4,
                      label=f"psi {axis_name}")
    position.set_ylabel(f"position error [{unit}]")
    attitude.set_ylabel("attitude error [arcsec]")
    for axis in (position, attitude):
        axis.set_xlabel("time [h]")
        axis.grid(True, alpha=0.3)
        axis.legend(loc="upper left")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_period(speeds, periods, speed: float, orbital_speed: float, title: str):
    """Effective Schuler period against level-flight speed, up to the orbital speed.

    Parameters
    ----------
    speeds : ndarray
        V, m/s.
    periods : ndarray
        T(V), s.
    speed : float
        The case's speed, m/s (marked).
    orbital_speed : float
        sqrt(g r), m/s (dashed line).
    title : str
    """
    fig, axis = _figure(figsize=(7, 4.2))
    axis.plot(np.asarray(speeds) / 1000.0, np.asarray(periods) / 60.0, color="C0", lw=1.6,
              label="T = 2 pi sqrt(R / (g - V^2 / r))")
    axis.axvline(orbital_speed / 1000.0, color="C3", ls="--", lw=1.2, label="orbital speed sqrt(g r)")
    if speed < orbital_speed:
        marked = np.interp(speed, speeds, periods) / 60.0
        axis.plot([speed / 1000.0], [marked], "o", color="C2", label=f"V = {speed:,.0f} m/s")
    axis.set_yscale("log")
    axis.set_xlabel("speed [km/s]")
    axis.set_ylabel("period [min] (log scale)")
    axis.set_title(title)
    axis.grid(True, which="both", alpha=0.3)
    axis.legend(loc="upper left")
    fig.tight_layout()
    return fig
