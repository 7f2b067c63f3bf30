"""Typed results of the navigation-error studies (JSON via ``to_dict``, tables via ``render``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from schuler.results import Footnotes, Result
from schuler.units import to_unit

DISPLAY_UNITS = ("ft", "m", "mi")
"""Units for lengths in human output (``--units``)."""


def _length(value_si: float, unit: str) -> str:
    value = to_unit(value_si, unit)
    return f"{value:,.0f}" if abs(value) >= 1e5 else f"{value:,.6g}"


def _sample_indices(size: int, count: int = 11) -> np.ndarray:
    return np.unique(np.linspace(0, size - 1, min(size, count)).round().astype(int))


@dataclass
class ErrorRunResult(Result):
    """Position error of one source over time: flat, spherical (closed form) and simulated.

    Arrays share the grid ``t_s``; lengths are in metres.
    """

    source: str
    earth: str
    magnitude_si: float
    radius_m: float
    gravity_m_s2: float
    speed_m_s: float
    schuler_period_s: float
    t_s: np.ndarray
    flat_m: np.ndarray
    spherical_m: np.ndarray
    simulated_m: np.ndarray
    final_flat_m: float
    final_spherical_m: float
    max_spherical_m: float
    max_simulation_difference_m: float
    display_unit: str = field(default="m", repr=False)

    units: ClassVar[dict[str, str]] = {"magnitude_si": "rad, m/s, m/s^2 or rad/s by source"}

    def render(self):
        from rich.console import Group
        from rich.table import Table

        unit = self.display_unit
        summary = Table(title=f"{self.source} error ({self.earth} Earth constants)", show_header=False)
        summary.add_column("quantity")
        summary.add_column("value", justify="right")
        summary.add_row("Schuler period", f"{self.schuler_period_s:,.1f} s ({self.schuler_period_s / 60:.2f} min)")
        summary.add_row("radius R, gravity g", f"{self.radius_m / 1e3:,.1f} km, {self.gravity_m_s2:.5g} m/s^2")
        summary.add_row(f"flat Earth at {self.t_s[-1]:,.0f} s", f"{_length(self.final_flat_m, unit)} {unit}")
        summary.add_row(f"spherical Earth at {self.t_s[-1]:,.0f} s", f"{_length(self.final_spherical_m, unit)} {unit}")
        summary.add_row("spherical maximum", f"{_length(self.max_spherical_m, unit)} {unit}")
        summary.add_row("simulation - closed form (max)", f"{self.max_simulation_difference_m:.3g} m")
        series = Table(title="error versus time")
        for column in ("t (s)", f"flat ({unit})", f"spherical ({unit})", f"simulated ({unit})"):
            series.add_column(column, justify="right")
        for k in _sample_indices(self.t_s.size):
            series.add_row(f"{self.t_s[k]:,.0f}", _length(self.flat_m[k], unit), _length(self.spherical_m[k], unit),
                           _length(self.simulated_m[k], unit))
        return Group(summary, series)


@dataclass
class ReproductionResult(Result):
    """Source 002's Problem 3 table and hover number, printed beside the recomputed values."""

    rows: list
    constants: dict
    notes: list
    display_unit: str = field(default="ft", repr=False)

    def render(self):
        from rich.console import Group
        from rich.table import Table

        unit = self.display_unit
        table = Table(title=f"Bollay, Problems 3 and 4: printed vs computed ({unit})")
        for column in ("source", "earth", "quantity", "printed", "computed", "agrees", "note"):
            table.add_column(column, justify="right" if column in ("printed", "computed") else "left")
        # notes are long: the table refers to them by number and lists them below it
        footnotes = Footnotes()
        for row in self.rows:
            computed_ft = 0.0 if abs(row.computed_ft) < 1e-6 else row.computed_ft  # rounding at omega t = 4 pi
            reference = footnotes.reference(f"{row.source}, {row.earth}, {row.quantity}: {row.note}" if row.note else "")
            table.add_row(row.source, row.earth, row.quantity, _length(row.printed_ft * 0.3048, unit),
                          _length(computed_ft * 0.3048, unit), "yes" if row.agrees else "NO", reference)
        return Group(table, *footnotes.lines(), *self.notes)


@dataclass
class VerticalResult(Result):
    """Altitude error: pure inertial (simulated and closed form) vs the baro-aided loop."""

    order: int
    k1_per_s: float
    k2_per_s2: float
    k3_per_s3: float
    accelerometer_error_m_s2: float
    baro_error_m: float
    t_s: np.ndarray
    unaided_m: np.ndarray
    closed_form_m: np.ndarray
    aided_m: np.ndarray
    aided_steady_state_m: float
    poles_real_per_s: np.ndarray
    poles_imag_rad_s: np.ndarray
    display_unit: str = field(default="m", repr=False)

    def render(self):
        from rich.console import Group
        from rich.table import Table

        unit = self.display_unit
        summary = Table(title=f"vertical channel: pure inertial vs order-{self.order} baro-aided loop",
                        show_header=False)
        summary.add_column("quantity")
        summary.add_column("value", justify="right")
        summary.add_row("gains k1, k2, k3", f"{self.k1_per_s:.4g} 1/s, {self.k2_per_s2:.4g} 1/s^2, "
                                            f"{self.k3_per_s3:.4g} 1/s^3")
        poles = ", ".join(f"{re:.3g}{im:+.3g}j" for re, im in zip(self.poles_real_per_s, self.poles_imag_rad_s))
        summary.add_row("aided loop poles (1/s)", poles)
        summary.add_row(f"pure inertial at {self.t_s[-1]:,.0f} s", f"{_length(self.unaided_m[-1], unit)} {unit}")
        summary.add_row(f"aided at {self.t_s[-1]:,.0f} s", f"{_length(self.aided_m[-1], unit)} {unit}")
        summary.add_row("aided steady state (closed form)", f"{_length(self.aided_steady_state_m, unit)} {unit}")
        series = Table(title="altitude error versus time")
        for column in ("t (s)", f"pure inertial ({unit})", f"closed form ({unit})", f"aided ({unit})"):
            series.add_column(column, justify="right")
        for k in _sample_indices(self.t_s.size):
            series.add_row(f"{self.t_s[k]:,.0f}", _length(self.unaided_m[k], unit),
                           _length(self.closed_form_m[k], unit), _length(self.aided_m[k], unit))
        return Group(summary, series)


@dataclass
class PeriodResult(Result):
    """Effective Schuler periods under thrust and in fast level flight (source 002 footnote)."""

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
