"""Typed results of ``schuler errors``: run, vertical channel, effective period, Problem 3 figures.

Every field is SI with its unit in the name (``final_spherical_m``,
``schuler_period_s``) or in the class's ``units`` map; ``render()`` shows
lengths in metres and feet. Time histories are kept for the figures and CSV
files (``--out``) but left out of ``to_dict()``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from schuler.navigation_errors.inputs import SOURCE_SI_UNITS, SOURCE_UNITS
from schuler.results import Result, SystemResult
from schuler.units import to_unit

LENGTH_UNITS = ("m", "ft")
"""Units in which human output shows lengths."""

NOISE_FRACTION = 1e-9
"""Below this fraction of its own series' largest magnitude a length shows as 0 (rounding noise, as the sine of a
whole number of periods): each series (flat, spherical) has its own scale."""


class SimulationAccuracyWarning(UserWarning):
    """The simulated error departs from the closed form beyond the simulation's accuracy."""


def length_text(value_si: float | None, unit: str, floor: float = 0.0) -> str:
    """A length for people: thousands separated, no float noise below ``floor`` (m), no negative zero.

    Parameters
    ----------
    value_si : float or None
        The length, m (None or NaN: ``-``).
    unit : str
        Display unit (``m``, ``ft``).
    floor : float
        Magnitudes below it show as 0, m.

    Examples
    --------
    >>> length_text(87782.4, "ft"), length_text(-1e-12, "m", floor=1e-9), length_text(None, "m")
    ('288,000', '0', '-')
    """
    if value_si is None or (isinstance(value_si, float) and math.isnan(value_si)):
        return "-"
    if abs(value_si) <= floor:
        return "0"
    value = float(to_unit(value_si, unit))
    return f"{value:,.0f}" if abs(value) >= 1e5 else f"{value:,.6g}"


def lengths(value_si: float | None, floor: float = 0.0) -> str:
    """A length in metres and feet: ``1,000 m (3,280.84 ft)``.

    Parameters
    ----------
    value_si : float or None
        The length, m (None or NaN: ``-``).
    floor : float
        Magnitudes below it show as 0, m.
    """
    shown = [f"{length_text(value_si, unit, floor)} {unit}" for unit in LENGTH_UNITS]
    return f"{shown[0]} ({shown[1]})" if shown[0] != "- m" else "-"


def sample_indices(size: int, count: int = 11) -> np.ndarray:
    """About ``count`` evenly spread indices of a history of ``size`` points (first and last included).

    Parameters
    ----------
    size : int
        Number of points of the history.
    count : int
        Number of indices wanted (about).
    """
    return np.unique(np.linspace(0, size - 1, min(size, count)).round().astype(int))


@dataclass(kw_only=True)
class ErrorRunResult(SystemResult):
    """What ``SYSTEM.run`` returns: the outputs, extras and histories of one source, shown in metres and feet.

    ``magnitude`` is SI in the source's unit (``to_dict()["units"]["magnitude"]``). With
    ``fidelity="simulated"`` ``final_spherical_m`` is the simulated error and
    ``simulation_minus_closed_m`` the largest difference from the closed form on
    the output grid; with ``"closed"`` both come from the closed form (the
    difference is NaN). ``warnings`` holds what the run warned of (a simulation
    that lost its accuracy), also shown on stderr. ``histories["errors_run_<source>"]``
    holds ``flat_m``, ``spherical_m`` (closed forms) and, simulated, ``simulated_m``.
    """

    def to_dict(self) -> dict[str, Any]:
        data = super().to_dict()
        # the magnitude's unit is the source's, so it is known only per result
        data["units"]["magnitude"] = SOURCE_SI_UNITS[self.source]
        return data

    def render(self):
        from rich.console import Group
        from rich.table import Table

        from schuler.navigation_errors.plots import SOURCE_TITLES

        histories = self.histories[f"errors_run_{self.source}"]
        t_s, flat_m, spherical_m = histories.time, histories["flat_m"], histories["spherical_m"]
        simulated_m = histories["simulated_m"] if "simulated_m" in histories else None
        flat_floor = NOISE_FRACTION * abs(self.max_flat_m)
        spherical_floor = NOISE_FRACTION * abs(self.max_spherical_m)
        shown_unit = SOURCE_UNITS[self.source]
        summary = Table(title=f"{SOURCE_TITLES[self.source]} of {to_unit(self.magnitude, shown_unit):.6g} "
                              f"{shown_unit} ({self.earth} Earth, {self.fidelity})", show_header=False)
        summary.add_column("quantity")
        summary.add_column("value", justify="right")
        end = f"{self.duration_s:,.6g} s"
        spherical_how = "simulated" if self.fidelity == "simulated" else "closed form"
        rows = [
            ("Schuler period", f"{self.schuler_period_s:,.1f} s ({self.schuler_period_s / 60:.2f} min)"),
            ("radius R, gravity g", f"{self.radius_m / 1e3:,.1f} km, {self.gravity_m_s2:.5g} m/s^2"),
            (f"flat Earth at {end}", lengths(self.final_flat_m, flat_floor)),
            (f"spherical Earth at {end} ({spherical_how})", lengths(self.final_spherical_m, spherical_floor)),
            ("largest flat-Earth error", lengths(self.max_flat_m, flat_floor)),
            ("largest spherical-Earth error (closed form)", lengths(self.max_spherical_m, spherical_floor)),
        ]
        if self.fidelity == "simulated":
            rows.append(("simulation - closed form (largest)", f"{self.simulation_minus_closed_m:.3g} m"))
        for row in rows:
            summary.add_row(*row)
        series = Table(title="error versus time")
        columns = ["t (s)", "flat (m)", "spherical (m)"] + (["simulated (m)"] if simulated_m is not None else [])
        for column in columns:
            series.add_column(column, justify="right")
        for k in sample_indices(t_s.size):
            cells = [f"{t_s[k]:,.6g}", length_text(flat_m[k], "m", flat_floor),
                     length_text(spherical_m[k], "m", spherical_floor)]
            if simulated_m is not None:
                cells.append(length_text(simulated_m[k], "m", spherical_floor))
            series.add_row(*cells)
        parts = [summary, series]
        if self.monte_carlo is not None:
            parts.append(self.monte_carlo.render())
        return Group(*parts)


@dataclass
class VerticalChannelResult(Result):
    """Altitude error: pure inertial (simulated and closed form, Bollay's Problem 4) vs the baro-aided loop.

    Altitude errors are indicated - true, positive up; ``accel_bias_up_m_s2``
    is the vertical accelerometer's bias (measured - true, positive when it reads
    high). Histories feed the figures and CSV, not ``to_dict()``.
    """

    order: int
    k1_per_s: float
    k2_per_s2: float
    k3_per_s3: float
    accel_bias_up_m_s2: float
    baro_bias_m: float
    duration_s: float
    final_unaided_m: float
    final_closed_form_m: float
    final_aided_m: float
    aided_steady_state_m: float
    poles_real_per_s: np.ndarray
    poles_imag_rad_s: np.ndarray
    t_s: np.ndarray = field(repr=False)
    unaided_m: np.ndarray = field(repr=False)
    closed_form_m: np.ndarray = field(repr=False)
    aided_m: np.ndarray = field(repr=False)

    units: ClassVar[dict[str, str]] = {"order": "1", "k1_per_s": "1/s", "k2_per_s2": "1/s^2", "k3_per_s3": "1/s^3",
                                       "poles_real_per_s": "1/s"}

    def to_dataframe(self):
        """The altitude errors, one row per time: ``t_s``, ``unaided_m``, ``closed_form_m``, ``aided_m``."""
        import pandas as pd

        return pd.DataFrame({"t_s": self.t_s, "unaided_m": self.unaided_m, "closed_form_m": self.closed_form_m,
                             "aided_m": self.aided_m})

    def render(self):
        from rich.console import Group
        from rich.table import Table

        summary = Table(title=f"vertical channel: pure inertial vs order-{self.order} baro-aided loop",
                        show_header=False)
        summary.add_column("quantity")
        summary.add_column("value", justify="right")
        poles = ", ".join(f"{re:.3g}{im:+.3g}j" for re, im in zip(self.poles_real_per_s, self.poles_imag_rad_s))
        end = f"{self.duration_s:,.6g} s"
        for row in (
            ("gains k1, k2, k3", f"{self.k1_per_s:.4g} 1/s, {self.k2_per_s2:.4g} 1/s^2, {self.k3_per_s3:.4g} 1/s^3"),
            ("aided loop poles (1/s)", poles),
            (f"pure inertial at {end}", lengths(self.final_unaided_m)),
            (f"aided at {end}", lengths(self.final_aided_m)),
            ("aided steady state (closed form)", lengths(self.aided_steady_state_m)),
        ):
            summary.add_row(*row)
        series = Table(title="altitude error versus time")
        for column in ("t (s)", "pure inertial (m)", "closed form (m)", "aided (m)"):
            series.add_column(column, justify="right")
        for k in sample_indices(self.t_s.size):
            series.add_row(f"{self.t_s[k]:,.6g}", length_text(self.unaided_m[k], "m"),
                           length_text(self.closed_form_m[k], "m"), length_text(self.aided_m[k], "m"))
        return Group(summary, series)


@dataclass
class PeriodResult(Result):
    """Effective Schuler periods under thrust and in fast level flight (Bollay 1966, footnote).

    ``flight_period_s`` is infinite (JSON null) at or above the orbital speed.
    """

    radius_m: float
    gravity_m_s2: float
    nominal_period_s: float
    thrust_factor: float
    thrust_period_s: float
    speed_m_s: float
    path_radius_m: float
    orbital_speed_m_s: float
    flight_effective_gravity_m_s2: float
    flight_period_s: float

    units: ClassVar[dict[str, str]] = {"thrust_factor": "1"}

    def render(self):
        from rich.table import Table

        def minutes(seconds):
            return "infinite (no restoring force)" if not np.isfinite(seconds) else f"{seconds / 60:,.2f} min"

        table = Table(title="effective Schuler period T = 2 pi sqrt(R / g_eff)", show_header=False)
        table.add_column("case")
        table.add_column("period", justify="right")
        table.add_row("at rest (g_eff = g)", minutes(self.nominal_period_s))
        table.add_row(f"vertical thrust n = {self.thrust_factor:g} (g_eff = n g)", minutes(self.thrust_period_s))
        table.add_row(f"level flight at {self.speed_m_s:,.0f} m/s (g_eff = g - V^2/r = "
                      f"{self.flight_effective_gravity_m_s2:.4g} m/s^2)", minutes(self.flight_period_s))
        table.add_row("orbital speed sqrt(g r)", f"{self.orbital_speed_m_s:,.0f} m/s")
        return table


@dataclass
class Problem3Curves:
    """Problem 3's errors over the flight and Problem 4's altitude errors, SI (for figures and CSV).

    Attributes
    ----------
    t_s : ndarray
        Times of the closed forms, s.
    flat_m, spherical_m : dict of str -> ndarray
        Closed-form errors per source, m.
    t_simulated_s : ndarray
        Times of the simulated errors (markers), s.
    simulated_m : dict of str -> ndarray
        Simulated spherical errors per source, m.
    vertical_t_s : ndarray
        Times of the vertical channel, s (one Schuler period).
    vertical_unaided_m : ndarray
        Pure-inertial altitude error (Problem 4), m.
    vertical_aided_m : dict of str -> ndarray
        Baro-aided altitude errors by loop, m.
    """

    t_s: np.ndarray
    flat_m: dict[str, np.ndarray]
    spherical_m: dict[str, np.ndarray]
    t_simulated_s: np.ndarray
    simulated_m: dict[str, np.ndarray]
    vertical_t_s: np.ndarray
    vertical_unaided_m: np.ndarray
    vertical_aided_m: dict[str, np.ndarray]


@dataclass
class Problem3Figures(Result):
    """Bollay's Problem 3 curves (each source, flat vs spherical, 0..10,120 s) and Problem 4's hover error.

    ``--out`` draws them; ``to_dict()`` holds the number of
    points and the largest errors, m.
    """

    points: int
    flight_time_s: float
    max_flat_m: dict[str, float]
    max_spherical_m: dict[str, float]
    largest_simulation_minus_closed_m: float
    curves: Problem3Curves = field(repr=False)

    def render(self):
        from rich.console import Group
        from rich.table import Table
        from rich.text import Text

        from schuler.navigation_errors.plots import SOURCE_TITLES

        table = Table(title=f"Problem 3 over 0..{self.flight_time_s:,.0f} s ({self.points} points): largest errors")
        for column in ("source", "flat Earth (ft)", "spherical Earth (ft)"):
            table.add_column(column, justify="left" if column == "source" else "right")
        for source, flat in self.max_flat_m.items():
            table.add_row(SOURCE_TITLES[source], length_text(flat, "ft"),
                          length_text(self.max_spherical_m[source], "ft"))
        note = (f"closed forms and simulation agree within {self.largest_simulation_minus_closed_m:.2g} m; "
                "add --out DIR to write the figures (PNG, SVG) and their data (CSV)")
        return Group(table, Text(note))
