"""Bollay's Problem 3 table and Problem 4 hover number, recomputed with the source's constants.

Source: Bollay, "A Critical Meeting on the Development of Inertial Navigation -
Related to 'The Story of 84 Minutes'", Engineering Case Library, Stanford
University, 1966 (:data:`schuler.references.BOLLAY_1966`): the solutions of
Problems 1-3, their summary table, and the solution of Problem 4.

Constants as Bollay uses them (:data:`schuler.core.earth.BOLLAY`): R = 3960
statute miles, T = 5060 s, so omega = 2 pi / 5060 s and the loop's gravity is
g_eff = omega^2 R = 32.24 ft/s^2 (2 pi sqrt(R / 32.2 ft/s^2) would be 5063.1 s;
only T = 5060 s makes omega t = 4 pi at t = 10,120 s, as the source states).
Flat and spherical errors use the same g_eff, so the flat Earth is exactly the
spherical model's R -> infinity limit. Flight time 10,120 s, speed 0.5 mi/s
(range 5060 mi); Delta_theta = 0.01 deg, Delta_V = 1 ft/s, Delta_a = 1e-4 g,
epsilon = 0.01 deg/h, Delta_theta_z = 0.01 deg; hover: k = 1e-4, t = T.

A computed value agrees with the printed one within 0.5 % (the source prints
three significant figures, whose rounding is at most 0.5 %) or within 0.5 ft of
a printed zero; every value is compared as printed, in the source's unit.

Examples
--------
>>> rows = problem3_rows()
>>> [row.verdict for row in rows if row.quantity.startswith("launch velocity 1 ft/s, spherical Earth, largest")]
['agrees within 0.5 %']
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from schuler.contract import FigureRef, ReportSection
from schuler.core.earth import BOLLAY, FOOT, PRESETS, STATUTE_MILE
from schuler.core.geometry import time_grid
from schuler.navigation_errors import plots
from schuler.navigation_errors.actions import altitude_errors, loop_gains
from schuler.navigation_errors.files import problem3_figures, problem3_tables
from schuler.navigation_errors.inputs import FLIGHT_TIME
from schuler.navigation_errors.results import Problem3Curves, Problem3Figures
from schuler.navigation_errors.single_channel import (
    SOURCES,
    flat_error,
    maximum_error,
    simulate_error,
    spherical_error,
)
from schuler.navigation_errors.three_d import foucault_velocity_response
from schuler.navigation_errors.vertical_channel import (
    hover_altitude_error,
    printed_hover_expression,
)
from schuler.params import Parameter, ParameterSet
from schuler.references import BOLLAY_1966
from schuler.reproduction import Reproduction, ReproductionRow, Tolerance, compare
from schuler.units import to_unit

SPEED = 0.5 * STATUTE_MILE
"""Problem 3's flying speed, m/s (0.5 statute mi/s)."""

HOVER_K = 1e-4
"""Problem 4's accelerometer error, in units of g."""

MAGNITUDES: dict[str, float] = {
    "tilt": math.radians(0.01),
    "velocity": 1.0 * FOOT,
    "accelerometer": 1e-4 * BOLLAY.effective_gravity,
    "drift": math.radians(0.01) / 3600.0,
    "azimuth": math.radians(0.01),
}
"""Problem 3's error sizes, SI (Delta_a = k g with the loop's g, as the source writes kR)."""

ROUNDING = Tolerance(0.005)
"""Three printed significant figures: 0.5 %."""
PRINTED_ZERO = Tolerance(0.0, 0.5)
"""A printed zero: within 0.5 ft."""

SUMMARY = "Problem 3, summary table"
SOLUTION = {"tilt": "Problem 3, solution (a)", "azimuth": "Problem 3, solution (a)",
            "velocity": "Problem 3, solution (b)", "accelerometer": "Problem 3, solution (c)",
            "drift": "Problem 3, solution (d)"}
HOVER = "Problem 4, solution"

FIGURE_POINTS = 1013
"""Time points of the Problem 3 figures over 0..10,120 s (10 s steps)."""
SIMULATED_MARKERS = 45
"""Simulated points drawn as markers on the Problem 3 figures."""
VERTICAL_TIME_CONSTANT = 100.0
"""tau of the baro-aided loops drawn beside Problem 4's divergence, s."""


def _feet(value_m) -> float:
    return abs(float(value_m)) / FOOT


def _printed_zero(value_m) -> float:
    """|value| in ft to 0.001 ft: an error that vanishes at omega t = 4 pi shows as 0, not as rounding noise."""
    return round(_feet(value_m), 3) + 0.0


def problem3_rows() -> list[ReproductionRow]:
    """Every number of Problem 3 (summary table and solution text) and Problem 4, printed beside the computed one.

    Returns
    -------
    list of ReproductionRow
        In the source's order: level misalignment, launch velocity,
        accelerometer, gyro drift, azimuth, then the hover error of Problem 4.
    """
    R, g, t = BOLLAY.radius, BOLLAY.effective_gravity, FLIGHT_TIME
    flat = {s: flat_error(s, MAGNITUDES[s], t, g, SPEED) for s in SOURCES}
    sphere = {s: spherical_error(s, MAGNITUDES[s], t, R, g, SPEED) for s in SOURCES}
    peak = {s: maximum_error(s, MAGNITUDES[s], t, R, g, SPEED) for s in SOURCES}
    flat_with_32_2 = _feet(flat_error("tilt", MAGNITUDES["tilt"], t, BOLLAY.gravity))
    accel_flat = _feet(flat["accelerometer"])
    drift_flat = _feet(flat["drift"])
    drift_angle = MAGNITUDES["drift"] * t
    platform_tilt = MAGNITUDES["drift"] / BOLLAY.schuler_frequency
    range_angle = SPEED * t / R
    hover_mi = -float(hover_altitude_error(BOLLAY.schuler_period, -HOVER_K * g, R, g)) / STATUTE_MILE
    sinh_mi = float(printed_hover_expression(BOLLAY.schuler_period, HOVER_K, R, g)) / STATUTE_MILE
    hover_84_min_mi = (-float(hover_altitude_error(84 * 60.0, -HOVER_K * BOLLAY.gravity, R, BOLLAY.gravity))
                       / STATUTE_MILE)
    mile = STATUTE_MILE
    return [
        compare("level misalignment 0.01 deg, flat Earth at 10,120 s", _feet(flat["tilt"]), "ft",
                printed="288,000", where=SUMMARY, tolerance=ROUNDING,
                note="g Delta_theta t^2 / 2 with the loop's g_eff"),
        compare("level misalignment 0.01 deg, flat Earth at 10,120 s", _feet(flat["tilt"]), "ft",
                printed="287,500", where=SOLUTION["tilt"], tolerance=ROUNDING,
                note=f"the text's 28 t^2 x 10^-4 ft rounds g Delta_theta / 2 (with g = 32.2 ft/s^2: "
                     f"{flat_with_32_2:,.0f} ft)"),
        compare("level misalignment, spherical Earth at 10,120 s", _printed_zero(sphere["tilt"]), "ft",
                printed="0", where=SUMMARY, tolerance=PRINTED_ZERO, note="omega t = 4 pi: cos omega t = 1"),
        compare("level misalignment, spherical Earth, largest error", _feet(peak["tilt"]), "ft",
                printed="3650", where=SUMMARY, tolerance=ROUNDING,
                erratum="3650 ft is the amplitude R Delta_theta; the largest error 2 R Delta_theta at omega t = pi "
                        "is twice it, as the solution text says (7300 ft)"),
        compare("level misalignment, spherical Earth, largest error", _feet(peak["tilt"]), "ft",
                printed="7300", where=SOLUTION["tilt"], tolerance=ROUNDING, note="2 R Delta_theta at omega t = pi"),
        compare("level misalignment, amplitude R Delta_theta", _feet(R * MAGNITUDES["tilt"]), "ft",
                printed="3650", where=SOLUTION["tilt"], tolerance=ROUNDING,
                note="Delta_S_x = 3650 ft [1 - cos(2 pi t / T)]"),
        compare("launch velocity 1 ft/s, flat Earth at 10,120 s", _feet(flat["velocity"]), "ft",
                printed="10,120", where=SUMMARY, tolerance=ROUNDING, note="Delta_V t"),
        compare("launch velocity, spherical Earth at 10,120 s", _printed_zero(sphere["velocity"]), "ft",
                printed="0", where=SUMMARY, tolerance=PRINTED_ZERO, note="sin 4 pi = 0"),
        compare("launch velocity 1 ft/s, spherical Earth, largest error", _feet(peak["velocity"]), "ft",
                printed="805", where=SUMMARY, tolerance=ROUNDING,
                note="Delta_V / omega at omega t = pi/2; the table's formula Delta_V sin(omega t) lacks the 1/omega "
                     "that its own number (and the solution text) uses"),
        compare("accelerometer 1e-4 g, flat Earth at 10,120 s", accel_flat, "ft",
                printed="341,000", where=SUMMARY, tolerance=ROUNDING,
                erratum=f"k g t^2 / 2 = {accel_flat:,.0f} ft; the printed 341,000 ft matches neither k g t^2 / 2 "
                        f"nor k g t^2 ({2 * accel_flat:,.0f} ft)"),
        compare("accelerometer, spherical Earth at 10,120 s", _printed_zero(sphere["accelerometer"]), "ft",
                printed="0", where=SUMMARY, tolerance=PRINTED_ZERO, note="1 - cos 4 pi = 0"),
        compare("accelerometer 1e-4 g, spherical Earth, largest error", _feet(peak["accelerometer"]), "ft",
                printed="4,170", where=SUMMARY, tolerance=ROUNDING,
                note=f"2 k R = {_feet(peak['accelerometer']):,.0f} ft; the source rounds 0.792 mi to 4,170 ft"),
        compare("accelerometer 1e-4 g, spherical Earth, largest error", float(peak["accelerometer"]) / mile, "mi",
                printed="0.792", where=SOLUTION["accelerometer"], tolerance=ROUNDING, note="2 k R"),
        compare("gyro drift 0.01 deg/h, flat Earth at 10,120 s", drift_flat, "ft",
                printed="1.62 \u00d7 10^6", where=SUMMARY, tolerance=ROUNDING,
                erratum=f"epsilon g t^3 / 6 = {drift_flat:,.0f} ft; the printed 1.62 x 10^6 ft is epsilon g t^3 "
                        "(the 1/6 of the formula is dropped in the arithmetic)"),
        compare("gyro drift 0.01 deg/h, spherical Earth at 10,120 s", _feet(sphere["drift"]), "ft",
                printed="10,250", where=SUMMARY, tolerance=ROUNDING,
                note="R epsilon t at omega t = 4 pi; the error grows monotonically, so it is also the largest"),
        compare("gyro drift 0.01 deg/h, spherical Earth at 10,120 s", float(sphere["drift"]) / mile, "mi",
                printed="1.94", where=SOLUTION["drift"], tolerance=ROUNDING, note="R epsilon t"),
        compare("gyro drift angle epsilon t after 2.8 h", float(to_unit(drift_angle, "arcmin")), "arcmin",
                printed="1.68", where=SOLUTION["drift"], tolerance=ROUNDING,
                note=f"the source calls it the platform error angle; it is the drift angle epsilon t (= x / R at "
                     f"omega t = 4 pi). The platform's tilt from the local vertical, (epsilon / omega) sin(omega t), "
                     f"is at most {float(to_unit(platform_tilt, 'arcsec')):.3g} arcsec and zero at 10,120 s"),
        compare("azimuth 0.01 deg, flat Earth at 10,120 s", _feet(flat["azimuth"]), "ft",
                printed="4660", where=SUMMARY, tolerance=ROUNDING, note="range 5060 mi x Delta_theta_z"),
        compare("azimuth 0.01 deg, spherical Earth at 10,120 s", _feet(sphere["azimuth"]), "ft",
                printed="3500", where=SUMMARY, tolerance=ROUNDING, note="R sin(r / R) Delta_theta_z"),
        compare("azimuth: range angle phi = r / R", math.degrees(range_angle), "deg",
                printed="73.3", where=SOLUTION["azimuth"], tolerance=ROUNDING, note="5060 mi / 3960 mi"),
        compare("azimuth: sin phi", math.sin(range_angle), "1", printed=".957", where=SOLUTION["azimuth"],
                tolerance=ROUNDING),
        compare("hover, k = 1e-4, altitude error after t = T", hover_mi, "mi", printed="724", where=HOVER,
                tolerance=ROUNDING,
                erratum=f"with z(0) = z'(0) = 0 the error is (k R / 2)(cosh(sqrt(2) omega t) - 1) = {hover_mi:.1f} mi "
                        f"at t = T; the printed (k R / 2) sinh(sqrt(2) omega t) gives {sinh_mi:.1f} mi "
                        f"({sinh_mi * 4000 / 3960:.1f} mi with R = 4000 mi, {hover_84_min_mi:.0f} mi for t = 84 min "
                        f"with omega = sqrt(g / R)); the printed 724 mi follows from none of these"),
    ]


def reproduce() -> Reproduction:
    """Bollay's Problem 3 table (summary and solution text) and Problem 4's hover error, with the source's constants.

    ``data`` holds the Problem 3 curves (the figures and CSV of ``--out``).

    Examples
    --------
    >>> r = reproduce()
    >>> len(r.rows), r.failures, sum(row.verdict == "erratum" for row in r.rows)
    (22, [], 4)
    """
    details = {
        "radius_m": BOLLAY.radius,
        "schuler_period_s": BOLLAY.schuler_period,
        "effective_gravity_m_s2": BOLLAY.effective_gravity,
        "flight_time_s": FLIGHT_TIME,
        "speed_m_s": SPEED,
    }
    return Reproduction(
        system="errors",
        source=BOLLAY_1966.citation,
        constants=f"R = 3960 statute mi, T = 5060 s (omega = 2 pi / T), g_eff = omega^2 R = "
                  f"{BOLLAY.effective_gravity / FOOT:.3f} ft/s^2, t = 10,120 s, V = 0.5 mi/s",
        rows=problem3_rows(),
        notes=[
            ("2 pi sqrt(R / 32.2 ft/s^2) = 5063.1 s; only T = 5060 s gives omega t = 4 pi at 10,120 s as the source "
            "states, so the loop's gravity is taken as omega^2 R. Flat and spherical use the same g_eff."),
            "Agreement: within 0.5 % (three printed significant figures) or 0.5 ft of a printed zero.",
        ],
        details=details,
        data=problem3_curves(),
    )


def problem3_curves(points: int = FIGURE_POINTS, simulated_points: int = SIMULATED_MARKERS) -> Problem3Curves:
    """Problem 3's errors over 0..10,120 s and Problem 4's over one period, with the source's constants.

    Closed forms on ``points`` times, the simulated spherical errors on
    ``simulated_points`` times (markers), and the pure-inertial altitude error
    beside the second- and third-order baro-aided loops (tau = 100 s).

    Parameters
    ----------
    points : int
        Times of the closed forms over the flight, number of (at least 2).
    simulated_points : int
        Times of the simulated errors (markers), number of (at least 2).

    Returns
    -------
    Problem3Curves
        Times in s and errors in m, with Bollay's constants (R and the loop's effective g).
    """
    R, g = BOLLAY.radius, BOLLAY.effective_gravity
    t = time_grid(FLIGHT_TIME, FLIGHT_TIME / (points - 1))
    t_simulated = time_grid(FLIGHT_TIME, FLIGHT_TIME / (simulated_points - 1))
    period = BOLLAY.schuler_period
    t_vertical = time_grid(period, period / 150)
    bias = -HOVER_K * g
    aided = {}
    for order in (2, 3):
        gains = loop_gains(order, VERTICAL_TIME_CONSTANT, None, None, None, R, g)
        unaided, aided[f"baro-aided, order {order} (tau = {VERTICAL_TIME_CONSTANT:g} s)"] = altitude_errors(
            t_vertical, gains, bias, 0.0, R, g)
    return Problem3Curves(
        t_s=t,
        flat_m={s: flat_error(s, MAGNITUDES[s], t, g, SPEED) for s in SOURCES},
        spherical_m={s: spherical_error(s, MAGNITUDES[s], t, R, g, SPEED) for s in SOURCES},
        t_simulated_s=t_simulated,
        simulated_m={s: simulate_error(s, MAGNITUDES[s], t_simulated, R, g, SPEED) for s in SOURCES},
        vertical_t_s=t_vertical,
        vertical_unaided_m=unaided,
        vertical_aided_m=aided,
    )


PLOT_PARAMETERS = ParameterSet((
    Parameter("points", "", FIGURE_POINTS, "Time points of the closed forms over 0..10,120 s.", minimum=3,
              maximum=100_001, kind="integer"),
), owner="errors plot")
"""Options of ``schuler errors plot``."""


def plot(*, points: int) -> Problem3Figures:
    """Problem 3's curves (figures with ``--out``): each source flat vs spherical, the overview, Problem 4.

    Parameters
    ----------
    points : int
        Times of the closed forms over 0..10,120 s, number of (3 to 100,001).

    Returns
    -------
    Problem3Figures
        The largest flat and spherical errors per source (m), the largest simulated - closed-form difference
        (m) and the curves.

    Examples
    --------
    >>> r = plot(points=101)
    >>> round(r.max_spherical_m["velocity"] / 0.3048)
    805
    """
    curves = problem3_curves(points)
    R, g = BOLLAY.radius, BOLLAY.effective_gravity
    difference = max(float(np.max(np.abs(curves.simulated_m[s] - spherical_error(
        s, MAGNITUDES[s], curves.t_simulated_s, R, g, SPEED)))) for s in SOURCES)
    return Problem3Figures(
        points=points, flight_time_s=FLIGHT_TIME,
        max_flat_m={s: float(maximum_error(s, MAGNITUDES[s], FLIGHT_TIME, R, g, SPEED, earth="flat"))
                    for s in SOURCES},
        max_spherical_m={s: float(maximum_error(s, MAGNITUDES[s], FLIGHT_TIME, R, g, SPEED)) for s in SOURCES},
        largest_simulation_minus_closed_m=difference, curves=curves,
    )


def report(figures_dir: Path) -> ReportSection:
    """Write this system's figures into ``figures_dir`` and describe them with the reproduction table.

    Parameters
    ----------
    figures_dir : Path
        The report's figure folder.
    """
    from schuler.io import save_figure_formats

    figures_dir = Path(figures_dir)
    reproduction = reproduce()
    for stem, figure in problem3_figures(reproduction.data).items():
        save_figure_formats(figure, figures_dir / stem)
    problem3_tables(reproduction.data, figures_dir)
    t = np.linspace(0.0, 86_400.0, 1441)
    earth = PRESETS["default"]
    north, east = foucault_velocity_response(t, FOOT, math.radians(45.0), earth.radius, earth.gravity, earth.rate)
    save_figure_formats(plots.plot_foucault(t, north, east, "ft", "3-D model: 1 ft/s north velocity error at "
                                                                  "45 deg N, 24 h"), figures_dir / "errors_foucault")
    figures = [FigureRef(f"errors_{s}.png", f"Problem 3, {plots.SOURCE_TITLES[s]}: flat vs spherical Earth over "
                                            "0..10,120 s (markers: simulation of the error equations)")
               for s in SOURCES]
    figures += [
        FigureRef("errors_overview.png", "All five error sources on a log scale: flat Earth (dashed) grows as "
                                         "t, t^2 or t^3, the Schuler loop bounds it"),
        FigureRef("errors_vertical.png", "Problem 4: the pure-inertial vertical channel diverges (715 mi after "
                                         "one Schuler period); a baro-aided loop holds it"),
        FigureRef("errors_foucault.png", "Beyond the source: the 3-D psi-angle model; the Schuler swing of a "
                                         "velocity error turns at the Foucault rate Omega sin L"),
    ]
    return ReportSection(
        system="errors",
        title="Schuler-tuned INS error propagation",
        source=reproduction.source,
        summary="Five error sources on a flat and a spherical Earth (closed forms and exact simulation agree), "
                "the divergent vertical channel and its baro-aided loop, and the 3-D error model on the "
                "rotating Earth. Source constants: R = 3960 mi, T = 5060 s (g_eff = 32.24 ft/s^2).",
        rows=reproduction.rows,
        figures=figures,
        commands=[
            "schuler errors reproduce --out errors",
            "schuler errors plot --points 4001 --out errors",
            "schuler errors run --source drift --magnitude '0.01 deg/h' --duration '6 h' --output-step '60 s'",
            "schuler errors vertical --order 3 --out errors",
            "schuler errors period --thrust-factor 9",
            "schuler errors three-d --latitude 45 --initial-velocity-error-north '1 ft/s' --out errors",
            "schuler sweep examples/errors_bollay_drift.toml --param duration=600:10120:100 --out errors-sweep",
        ],
        notes=reproduction.notes + [(f"Figures use {FIGURE_POINTS:,} points over 10,120 s; "
                                    "'schuler errors plot --points N --out DIR' draws more.")],
    )
