"""Source 002's Problem 3 table and Problem 4 hover number, recomputed with the source's constants.

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
a printed zero.

Examples
--------
>>> rows = problem3_rows()
>>> [round(r.computed_ft) for r in rows if r.source == "velocity" and r.quantity == "max"]
[805]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from schuler.core.earth import BOLLAY, FOOT, STATUTE_MILE
from schuler.core.geometry import DEG_PER_HOUR, DEGREE
from schuler.navigation_errors.single_channel import flat_error, maximum_error, spherical_error
from schuler.navigation_errors.vertical_channel import hover_altitude_error, printed_hover_expression

FLIGHT_TIME = 10_120.0
"""Problem 3's flight time, s (2 x 5060 s)."""

SPEED = 0.5 * STATUTE_MILE
"""Problem 3's flying speed, m/s (0.5 statute mi/s)."""

HOVER_K = 1e-4
"""Problem 4's accelerometer error, in units of g."""

MAGNITUDES: dict[str, float] = {
    "tilt": 0.01 * DEGREE,
    "velocity": 1.0 * FOOT,
    "accelerometer": 1e-4 * BOLLAY.effective_gravity,
    "drift": 0.01 * DEG_PER_HOUR,
    "azimuth": 0.01 * DEGREE,
}
"""Problem 3's error sizes, SI (Delta_a = k g with the loop's g, as the source writes kR)."""

RELATIVE_TOLERANCE = 0.005
ZERO_TOLERANCE_FT = 0.5


@dataclass(frozen=True)
class ReproducedValue:
    """One number of the source's table beside the recomputed one.

    Attributes
    ----------
    source : str
        Error source (``tilt`` ... ``azimuth``, or ``hover``).
    earth : str
        ``flat``, ``spherical`` or ``vertical``.
    quantity : str
        ``at_10120s``, ``max`` or ``at_T``.
    computed_ft, printed_ft : float
        Magnitudes, ft.
    agrees : bool
        Whether they agree within the source's rounding.
    note : str
        Why they differ, or what the source rounded.
    """

    source: str
    earth: str
    quantity: str
    computed_ft: float
    printed_ft: float
    agrees: bool
    note: str = ""


def _agrees(computed_ft: float, printed_ft: float) -> bool:
    if printed_ft == 0.0:
        return abs(computed_ft) <= ZERO_TOLERANCE_FT
    return abs(computed_ft - printed_ft) <= RELATIVE_TOLERANCE * abs(printed_ft)


def _row(source, earth, quantity, computed_m, printed_ft, note="") -> ReproducedValue:
    computed_ft = float(abs(computed_m)) / FOOT
    return ReproducedValue(source, earth, quantity, computed_ft, float(printed_ft),
                           _agrees(computed_ft, printed_ft), note)


def problem3_rows() -> list[ReproducedValue]:
    """The Problem 3 summary table (flat and spherical, at 10,120 s and maxima) and the hover case.

    Returns
    -------
    list of ReproducedValue
        In the source's order: tilt, velocity, accelerometer, drift, azimuth,
        then hover (Problem 4).
    """
    R, g = BOLLAY.radius, BOLLAY.effective_gravity
    t = FLIGHT_TIME

    def flat(source):
        return flat_error(source, MAGNITUDES[source], t, g, SPEED)

    def sphere(source):
        return spherical_error(source, MAGNITUDES[source], t, R, g, SPEED)

    def peak(source):
        return maximum_error(source, MAGNITUDES[source], t, R, g, SPEED)

    flat_with_32_2 = flat_error("tilt", MAGNITUDES["tilt"], t, BOLLAY.gravity) / FOOT
    accel_flat_ft = float(flat("accelerometer")) / FOOT
    drift_flat_ft = float(flat("drift")) / FOOT
    hover_m = hover_altitude_error(BOLLAY.schuler_period, -HOVER_K * g, R, g)
    sinh_mi = float(printed_hover_expression(BOLLAY.schuler_period, HOVER_K, R, g)) / STATUTE_MILE
    sinh_4000_mi = sinh_mi * 4000.0 / 3960.0
    hover_84_min_mi = float(-hover_altitude_error(84 * 60.0, -HOVER_K * BOLLAY.gravity, R, BOLLAY.gravity)) / STATUTE_MILE
    hover_mi = float(-hover_m) / STATUTE_MILE
    return [
        _row("tilt", "flat", "at_10120s", flat("tilt"), 288_000,
             f"g Delta_theta t^2/2; the solution text prints 287,500 ft (with g = 32.2 ft/s^2 it is "
             f"{flat_with_32_2:,.0f} ft)"),
        _row("tilt", "spherical", "at_10120s", sphere("tilt"), 0, "omega t = 4 pi: cos omega t = 1"),
        _row("tilt", "spherical", "max", peak("tilt"), 3_650,
             "erratum: the summary table prints 3,650 ft, the amplitude R Delta_theta; the maximum "
             "2 R Delta_theta at omega t = pi is 7,300 ft, as the solution text itself says"),
        _row("velocity", "flat", "at_10120s", flat("velocity"), 10_120, "Delta_V t"),
        _row("velocity", "spherical", "at_10120s", sphere("velocity"), 0, "sin 4 pi = 0"),
        _row("velocity", "spherical", "max", peak("velocity"), 805,
             "Delta_V / omega at omega t = pi/2; the summary table's formula Delta_V sin omega t "
             "lacks the 1/omega that its own number uses"),
        _row("accelerometer", "flat", "at_10120s", flat("accelerometer"), 341_000,
             f"erratum: k g t^2/2 = {accel_flat_ft:,.0f} ft; the printed 341,000 ft matches neither "
             f"k g t^2/2 nor k g t^2 ({2 * accel_flat_ft:,.0f} ft)"),
        _row("accelerometer", "spherical", "at_10120s", sphere("accelerometer"), 0, "1 - cos 4 pi = 0"),
        _row("accelerometer", "spherical", "max", peak("accelerometer"), 4_170,
             "2 k R = 0.792 mi = 4,182 ft; the source rounds 0.792 mi to 4,170 ft"),
        _row("drift", "flat", "at_10120s", flat("drift"), 1.62e6,
             f"erratum: epsilon g t^3/6 = {drift_flat_ft:,.0f} ft; the printed 1.62e6 ft is epsilon g t^3 "
             f"(the 1/6 is dropped in the arithmetic)"),
        _row("drift", "spherical", "at_10120s", sphere("drift"), 10_250,
             "R epsilon t at omega t = 4 pi (the maximum, the error grows monotonically); the source's "
             "'platform error angle 1.68 arcmin' is the drift angle epsilon t, the platform's tilt from "
             "the vertical (epsilon/omega) sin omega t is at most 8 arcsec and zero here"),
        _row("azimuth", "flat", "at_10120s", flat("azimuth"), 4_660, "range 5060 mi x Delta_theta_z"),
        _row("azimuth", "spherical", "at_10120s", sphere("azimuth"), 3_500,
             f"R sin(r/R) Delta_theta_z; r/R = {np.degrees(5060 / 3960):.2f} deg (the source: 73.3 deg), "
             f"sin = {np.sin(5060 / 3960):.4f} (0.957)"),
        _row("hover", "vertical", "at_T", hover_m, 724 * 5280,
             f"erratum: with z(0) = z'(0) = 0 the error is (k R/2)(cosh(sqrt 2 omega t) - 1) = "
             f"{hover_mi:.1f} mi at t = T; the printed (k R/2) sinh(sqrt 2 omega t) gives {sinh_mi:.1f} mi "
             f"({sinh_4000_mi:.1f} mi with R = 4000 mi, {hover_84_min_mi:.0f} mi for t = 84 min with "
             f"omega = sqrt(g/R)); the printed 724 mi follows from none of these"),
    ]
