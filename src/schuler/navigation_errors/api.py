"""Public entry points of the navigation-error system: run, reproduce, report, sweep, SYSTEM.

This is the boundary layer: parameters arrive in SI from :mod:`schuler.params`
(the magnitude of an error may also arrive as text, parsed here with its
source's display unit), results leave as typed :mod:`results` objects.

Examples
--------
>>> result = run(source="velocity", magnitude=0.3048, duration=10120.0, earth="bollay")
>>> round(result.max_spherical_m / 0.3048)
805
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from schuler.core.earth import BOLLAY, FOOT, PRESETS, STATUTE_MILE
from schuler.core.lti import simulate
from schuler.exceptions import InvalidParameter
from schuler.io import save_figure_formats, write_dataframe_csv
from schuler.navigation_errors import plots
from schuler.navigation_errors.effective_period import (
    effective_schuler_period,
    flight_gravity,
    orbital_speed,
    thrust_gravity,
)
from schuler.navigation_errors.reproduction import FLIGHT_TIME, MAGNITUDES, SPEED, problem3_rows
from schuler.navigation_errors.results import ErrorRunResult, PeriodResult, ReproductionResult, VerticalResult
from schuler.navigation_errors.single_channel import (
    SOURCES,
    check_source,
    flat_error,
    maximum_error,
    simulate_error,
    spherical_error,
)
from schuler.navigation_errors.three_d import foucault_velocity_response
from schuler.navigation_errors.vertical_channel import (
    BaroLoopGains,
    aided_steady_state_error,
    baro_aided_model,
    check_stable,
    critically_damped_gains,
    hover_altitude_error,
    unaided_model,
)
from schuler.params import Parameter
from schuler.registry import FigureRef, ReportSection, ReproductionRow, System

SOURCE_UNITS: dict[str, str] = {
    "tilt": "deg",
    "velocity": "ft/s",
    "accelerometer": "g",
    "drift": "deg/h",
    "azimuth": "deg",
}
"""Display unit of each source's magnitude (bare numbers are taken in it)."""

SOURCE_DEFAULTS: dict[str, float] = {"tilt": 0.01, "velocity": 1.0, "accelerometer": 1e-4, "drift": 0.01,
                                     "azimuth": 0.01}
"""Problem 3's magnitudes in the display units."""

MAX_POINTS = 200_001

PARAMETERS: tuple[Parameter, ...] = (
    Parameter("source", "", "drift", "Error source.", choices=SOURCES, kind="choice"),
    Parameter(
        "magnitude", "", None,
        "Size of the error; a bare number is in the source's unit: tilt and azimuth deg, velocity ft/s, "
        "accelerometer g, drift deg/h (default: the source's Problem 3 value: 0.01 deg, 1 ft/s, 1e-4 g, "
        "0.01 deg/h).",
        kind="text",
    ),
    Parameter("duration", "s", 10120.0, "Length of the run.", minimum=0.0, exclusive_minimum=True),
    Parameter("step", "s", None, "Time step of the output grid (default duration / 1000).", minimum=0.0,
              exclusive_minimum=True),
    Parameter("speed", "mi/s", 0.5, "Vehicle speed, turning time into range (azimuth source).", minimum=0.0),
    Parameter("earth", "", "default", "Earth constants preset (bollay: R = 3960 mi, T = 5060 s).",
              choices=tuple(PRESETS), kind="choice"),
    Parameter("radius", "km", None, "Earth radius R (default: the preset's).", minimum=0.0,
              exclusive_minimum=True),
    Parameter("gravity", "m/s^2", None, "Gravity g of the Schuler loop (default: the preset's).", minimum=0.0,
              exclusive_minimum=True),
)
"""The ``schuler errors run`` options."""

_EARTH_PARAMETERS = PARAMETERS[-3:]

VERTICAL_PARAMETERS: tuple[Parameter, ...] = (
    Parameter("accelerometer_error", "g", -1e-4,
              "Vertical accelerometer error, positive when it reads high (Problem 4: reads 1e-4 g low)."),
    Parameter("duration", "s", 5060.0, "Length of the run.", minimum=0.0, exclusive_minimum=True),
    Parameter("step", "s", None, "Output step (default duration / 1000).", minimum=0.0, exclusive_minimum=True),
    Parameter("order", "", 3, "Order of the baro-aided loop.", minimum=2, maximum=3, kind="integer"),
    Parameter("time_constant", "s", 100.0, "Loop time constant tau: critically damped gains, all poles at -1/tau.",
              minimum=0.0, exclusive_minimum=True),
    Parameter("k1", "1/s", None, "Altitude feedback gain (overrides tau's).", minimum=0.0, exclusive_minimum=True),
    Parameter("k2", "1/s^2", None, "Velocity feedback gain (overrides tau's).", minimum=0.0, exclusive_minimum=True),
    Parameter("k3", "1/s^3", None, "Accelerometer-error estimator gain, third order (overrides tau's).",
              minimum=0.0, exclusive_minimum=True),
    Parameter("baro_error", "m", 0.0, "Constant barometric altitude error."),
) + _EARTH_PARAMETERS
"""The ``schuler errors vertical`` options."""

PERIOD_PARAMETERS: tuple[Parameter, ...] = (
    Parameter("thrust_factor", "", 9.0, "Vertical thrust n in units of the weight (g_eff = n g).", minimum=0.0,
              exclusive_minimum=True),
    Parameter("speed", "m/s", 0.0, "Level-flight speed V (g_eff = g - V^2/r).", minimum=0.0),
    Parameter("path_radius", "km", None, "Radius of curvature r of the flight path (default: R).", minimum=0.0,
              exclusive_minimum=True),
) + _EARTH_PARAMETERS
"""The ``schuler errors period`` options."""


def magnitude_parameter(source: str) -> Parameter:
    """The magnitude of ``source`` as a Parameter in that source's display unit (>= 0)."""
    check_source(source)
    return Parameter("magnitude", SOURCE_UNITS[source], SOURCE_DEFAULTS[source], "Size of the error.", minimum=0.0)


def parse_magnitude(source: str, value, label: str = "magnitude") -> float:
    """SI magnitude of ``source`` from None (Problem 3 value), an SI number, or text in/with units.

    >>> parse_magnitude("drift", "0.01 deg/h")
    4.84813681109536e-08
    >>> parse_magnitude("tilt", "1 ft/s")
    Traceback (most recent call last):
    ...
    schuler.exceptions.InvalidParameter: magnitude: '1 ft/s' is not an angle (expected a unit like deg)
    """
    spec = magnitude_parameter(source)
    if value is None:
        return spec.parse(spec.default, label)
    if isinstance(value, str):
        return spec.parse(value, label)
    number = float(value)
    if not math.isfinite(number) or number < 0:
        raise InvalidParameter(label, f"must be finite and >= 0, got {value!r}")
    return number


def earth_constants(earth: str = "default", radius: float | None = None, gravity: float | None = None):
    """(R, g) of a preset, overridden by explicit values; the Bollay preset's g is omega^2 R (T = 5060 s)."""
    if earth not in PRESETS:
        raise InvalidParameter("earth", f"{earth!r} is not one of {', '.join(PRESETS)}")
    preset = PRESETS[earth]
    R = preset.radius if radius is None else float(radius)
    if gravity is not None:
        g = float(gravity)
    elif radius is None:
        g = preset.effective_gravity
    else:
        g = preset.gravity
    for name, value in (("radius", R), ("gravity", g)):
        if not (math.isfinite(value) and value > 0):
            raise InvalidParameter(name, f"must be finite and > 0, got {value!r}")
    return R, g


def time_grid(duration: float, step: float | None) -> np.ndarray:
    """0, step, 2 step, ..., duration (a last, shorter step ends on duration), s.

    >>> time_grid(100.0, 30.0)
    array([  0.,  30.,  60.,  90., 100.])
    """
    if not (math.isfinite(duration) and duration > 0):
        raise InvalidParameter("duration", f"must be finite and > 0, got {duration!r}")
    step = duration / 1000.0 if step is None else float(step)
    if not (math.isfinite(step) and step > 0):
        raise InvalidParameter("step", f"must be finite and > 0, got {step!r}")
    if step > duration:
        raise InvalidParameter("step", f"{step:g} s is longer than the duration {duration:g} s")
    steps = duration / step
    divides = abs(steps - round(steps)) < 1e-6
    whole = round(steps) if divides else math.floor(steps)
    if whole + 2 > MAX_POINTS:
        raise InvalidParameter("step", f"gives {whole + 1:,} points; at most {MAX_POINTS:,} (use a longer step)")
    grid = step * np.arange(whole + 1)
    if divides:
        grid[-1] = duration  # moves the end by under a millionth of a step
        return grid
    return np.append(grid, duration)


def run(source: str = "drift", magnitude=None, duration: float = FLIGHT_TIME, step: float | None = None,
        speed: float = SPEED, earth: str = "default", radius: float | None = None,
        gravity: float | None = None) -> ErrorRunResult:
    """Error of one source over time: flat and spherical closed forms, and the simulated spherical model.

    Parameters
    ----------
    source : str
        One of ``tilt``, ``velocity``, ``accelerometer``, ``drift``, ``azimuth``.
    magnitude : float, str or None
        SI size of the error (rad, m/s, m/s^2, rad/s, rad by source), a text
        value in or with units, or None for the Problem 3 value.
    duration : float
        s (> 0).
    step : float or None
        Output step, s (default duration / 1000).
    speed : float
        V, m/s (azimuth: range r = V t).
    earth : str
        Preset of :data:`schuler.core.earth.PRESETS`.
    radius, gravity : float or None
        R (m) and g (m/s^2) overriding the preset; omega_s = sqrt(g / R).
    """
    check_source(source)
    size = parse_magnitude(source, magnitude)
    R, g = earth_constants(earth, radius, gravity)
    if not (math.isfinite(speed) and speed >= 0):
        raise InvalidParameter("speed", f"must be finite and >= 0, got {speed!r}")
    t = time_grid(duration, step)
    flat = flat_error(source, size, t, g, speed)
    spherical = spherical_error(source, size, t, R, g, speed)
    simulated = simulate_error(source, size, t, R, g, speed)
    return ErrorRunResult(
        source=source, earth=earth, magnitude_si=size, radius_m=R, gravity_m_s2=g, speed_m_s=float(speed),
        schuler_period_s=2.0 * math.pi * math.sqrt(R / g), t_s=t, flat_m=flat, spherical_m=spherical,
        simulated_m=simulated, final_flat_m=float(flat[-1]), final_spherical_m=float(spherical[-1]),
        max_spherical_m=float(maximum_error(source, size, t[-1], R, g, speed)),
        max_simulation_difference_m=float(np.max(np.abs(simulated - spherical))),
    )


def write_run_outputs(result: ErrorRunResult, outdir: Path, unit: str = "m") -> list[Path]:
    """Figure (PNG, SVG) and CSV table of a :func:`run` result in ``outdir``."""
    import pandas as pd

    fig = plots.plot_flat_vs_spherical(result.t_s, result.flat_m, result.spherical_m, unit,
                                       f"{plots.SOURCE_TITLES[result.source]}: flat vs spherical Earth",
                                       simulated=(result.t_s, result.simulated_m))
    paths = save_figure_formats(fig, Path(outdir) / f"errors_run_{result.source}")
    table = pd.DataFrame({"t_s": result.t_s, "flat_m": result.flat_m, "spherical_m": result.spherical_m,
                          "simulated_m": result.simulated_m})
    paths.append(write_dataframe_csv(table, Path(outdir) / f"errors_run_{result.source}.csv"))
    return paths


def reproduce() -> ReproductionResult:
    """Source 002's Problem 3 table and Problem 4 hover number with the source's constants."""
    constants = {
        "radius_m": BOLLAY.radius,
        "radius_statute_mi": 3960.0,
        "schuler_period_s": BOLLAY.schuler_period,
        "effective_gravity_m_s2": BOLLAY.effective_gravity,
        "effective_gravity_ft_s2": BOLLAY.effective_gravity / FOOT,
        "flight_time_s": FLIGHT_TIME,
        "speed_m_s": SPEED,
    }
    notes = [
        "Constants: R = 3960 statute mi, omega = 2 pi / 5060 s, g_eff = omega^2 R = "
        f"{BOLLAY.effective_gravity / FOOT:.3f} ft/s^2 (2 pi sqrt(R / 32.2 ft/s^2) = 5063.1 s; only T = 5060 s "
        "gives omega t = 4 pi at 10,120 s as the source states). Flat and spherical use the same g_eff.",
        "Agreement: within 0.5 % (three printed significant figures) or 0.5 ft of a printed zero.",
    ]
    return ReproductionResult(rows=problem3_rows(), constants=constants, notes=notes)


def vertical(accelerometer_error: float, duration: float, step: float | None = None, order: int = 3,
             time_constant: float = 100.0, k1: float | None = None, k2: float | None = None,
             k3: float | None = None, baro_error: float = 0.0, earth: str = "default",
             radius: float | None = None, gravity: float | None = None) -> VerticalResult:
    """Pure-inertial vertical channel (source 002, Problem 4) vs the baro-aided loop.

    Parameters
    ----------
    accelerometer_error : float
        b, m/s^2, positive when the vertical accelerometer reads high.
    duration, step : float
        s.
    order : {2, 3}
        Order of the baro-aided loop.
    time_constant : float
        tau, s: gains put all poles at -1/tau unless k1, k2, k3 are given.
    k1, k2, k3 : float or None
        Explicit gains (1/s, 1/s^2, 1/s^3) replacing the critically damped ones.
    baro_error : float
        Constant barometric altitude error, m.
    earth, radius, gravity
        As in :func:`run`.
    """
    R, g = earth_constants(earth, radius, gravity)
    if not math.isfinite(accelerometer_error):
        raise InvalidParameter("accelerometer_error", "must be finite")
    default = critically_damped_gains(order, time_constant, R, g)
    gains = BaroLoopGains(default.k1 if k1 is None else k1, default.k2 if k2 is None else k2,
                          (default.k3 if k3 is None else k3) if order == 3 else 0.0, order)
    check_stable(gains, R, g)
    t = time_grid(duration, step)
    unaided = simulate(unaided_model(R, g), t, inputs=[accelerometer_error])["altitude_error"]
    aided_system = baro_aided_model(gains, R, g)
    aided = simulate(aided_system, t, inputs=[accelerometer_error, baro_error])["altitude_error"]
    poles = aided_system.eigenvalues()
    return VerticalResult(
        order=order, k1_per_s=gains.k1, k2_per_s2=gains.k2, k3_per_s3=gains.k3,
        accelerometer_error_m_s2=accelerometer_error, baro_error_m=baro_error, t_s=t, unaided_m=unaided,
        closed_form_m=hover_altitude_error(t, accelerometer_error, R, g), aided_m=aided,
        aided_steady_state_m=float(aided_steady_state_error(gains, accelerometer_error, baro_error, R, g)),
        poles_real_per_s=poles.real, poles_imag_rad_s=poles.imag,
    )


def period(thrust_factor: float = 9.0, speed: float = 0.0, path_radius: float | None = None,
           earth: str = "default", radius: float | None = None, gravity: float | None = None) -> PeriodResult:
    """Effective Schuler periods (source 002 footnote): vertical thrust n g and level flight at V.

    Parameters
    ----------
    thrust_factor : float
        n (> 0).
    speed : float
        V, m/s (>= 0).
    path_radius : float or None
        r, m (default R).
    earth, radius, gravity
        As in :func:`run`.
    """
    R, g = earth_constants(earth, radius, gravity)
    r = R if path_radius is None else path_radius
    g_flight = float(flight_gravity(g, speed, r))
    return PeriodResult(
        radius_m=R, gravity_m_s2=g, nominal_period_s=float(effective_schuler_period(R, g)),
        thrust_factor=thrust_factor,
        thrust_period_s=float(effective_schuler_period(R, thrust_gravity(thrust_factor, g))),
        speed_m_s=speed, path_radius_m=r, orbital_speed_m_s=float(orbital_speed(g, r)),
        flight_effective_gravity_m_s2=g_flight, flight_period_s=float(effective_schuler_period(R, g_flight)),
    )


def problem3_curves(points: int = 1013, simulated_points: int = 45):
    """Problem 3's errors over 0..10,120 s with the source's constants, m.

    Returns ``(t, flat, spherical, t_simulated, simulated)``: closed forms on
    ``points`` times and the simulated spherical errors on ``simulated_points``
    times (markers in the figures), each a dict by source.
    """
    R, g = BOLLAY.radius, BOLLAY.effective_gravity
    t = time_grid(FLIGHT_TIME, FLIGHT_TIME / (points - 1))
    t_simulated = time_grid(FLIGHT_TIME, FLIGHT_TIME / (simulated_points - 1))
    flat = {s: flat_error(s, MAGNITUDES[s], t, g, SPEED) for s in SOURCES}
    spherical = {s: spherical_error(s, MAGNITUDES[s], t, R, g, SPEED) for s in SOURCES}
    simulated = {s: simulate_error(s, MAGNITUDES[s], t_simulated, R, g, SPEED) for s in SOURCES}
    return t, flat, spherical, t_simulated, simulated


def write_problem3_figures(outdir: Path, unit: str = "ft", points: int = 1013) -> list[Path]:
    """Problem 3's figures (one per source, flat vs spherical) and the log overview, PNG and SVG."""
    if points < 3:
        raise InvalidParameter("points", f"must be at least 3, got {points}")
    t, flat, spherical, t_simulated, simulated = problem3_curves(points)
    paths = []
    for source in SOURCES:
        fig = plots.plot_flat_vs_spherical(
            t, flat[source], spherical[source], unit,
            f"Problem 3: {plots.SOURCE_TITLES[source]} ({SOURCE_DEFAULTS[source]:g} {SOURCE_UNITS[source]})",
            simulated=(t_simulated, simulated[source]),
        )
        paths += save_figure_formats(fig, Path(outdir) / f"errors_{source}")
    fig = plots.plot_overview(t, flat, spherical, unit, "Problem 3: all five error sources, flat vs spherical Earth")
    paths += save_figure_formats(fig, Path(outdir) / "errors_overview")
    return paths


def write_vertical_figure(outdir: Path, unit: str = "ft") -> list[Path]:
    """Hover divergence (Problem 4) against the second- and third-order baro-aided loops, PNG and SVG."""
    bias = -1e-4 * BOLLAY.effective_gravity
    step = BOLLAY.schuler_period / 150
    second = vertical(bias, BOLLAY.schuler_period, step, order=2, earth="bollay")
    third = vertical(bias, BOLLAY.schuler_period, step, order=3, earth="bollay")
    fig = plots.plot_vertical(second.t_s, second.unaided_m,
                              {"baro-aided, 2nd order (tau = 100 s)": second.aided_m,
                               "baro-aided, 3rd order (tau = 100 s)": third.aided_m},
                              unit, "Problem 4: hover with an accelerometer reading 1e-4 g low")
    return save_figure_formats(fig, Path(outdir) / "errors_vertical")


def write_foucault_figure(outdir: Path, unit: str = "ft") -> list[Path]:
    """The 3-D model's Schuler swing turning at the Foucault rate (1 ft/s north, 45 deg, 24 h)."""
    t = np.linspace(0.0, 86_400.0, 1441)
    north, east = foucault_velocity_response(t, FOOT, math.radians(45.0), PRESETS["default"].radius,
                                             PRESETS["default"].gravity, PRESETS["default"].rate)
    fig = plots.plot_foucault(t, north, east, unit, "3-D model: 1 ft/s north velocity error at 45 deg N, 24 h")
    return save_figure_formats(fig, Path(outdir) / "errors_foucault")


def _report_row(row) -> ReproductionRow:
    """A Problem 3 row as the report shows it: feet to 0.1 ft (zeros at omega t = 4 pi are
    rounding), the hover error in miles as the source prints it."""
    quantity = f"{row.source}, {row.earth}, {row.quantity}"
    if row.source == "hover":
        mile_ft = STATUTE_MILE / FOOT
        return ReproductionRow(quantity, round(row.printed_ft / mile_ft, 1), round(row.computed_ft / mile_ft, 1), "mi",
                               row.agrees, row.note)
    return ReproductionRow(quantity, row.printed_ft, round(row.computed_ft, 1) + 0.0, "ft", row.agrees, row.note)


def report(outdir: Path) -> ReportSection:
    """Write this system's figures into ``outdir`` and describe them with the reproduction table."""
    outdir = Path(outdir)
    write_problem3_figures(outdir)
    write_vertical_figure(outdir)
    write_foucault_figure(outdir)
    rows = [_report_row(r) for r in problem3_rows()]
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
        source="Bollay, 'A Critical Meeting on the Development of Inertial Navigation' (The Story of 84 Minutes)",
        summary="Five error sources on a flat and a spherical Earth (closed forms and exact simulation agree), "
                "the divergent vertical channel and its baro-aided loop, and the 3-D error model on the "
                "rotating Earth. Source constants: R = 3960 mi, T = 5060 s (g_eff = 32.24 ft/s^2).",
        rows=rows,
        figures=figures,
        commands=["schuler errors reproduce", "schuler errors plot --out DIR",
                  "schuler errors run --source drift --magnitude '0.01 deg/h' --duration '6 h' --step '60 s'",
                  "schuler errors vertical --order 3", "schuler errors period --thrust-factor 9"],
        notes=reproduce().notes + ["Figures use 1,013 points over 10,120 s; 'schuler errors plot --points N' draws more."],
    )


def _numeric_column(values: dict, name: str, size: int) -> np.ndarray:
    """SI float column of length ``size``; missing or None entries become NaN (= default)."""
    if name not in values or values[name] is None:
        return np.full(size, np.nan)
    column = np.asarray(values[name])
    if column.dtype.kind in "fiu":
        return np.broadcast_to(column.astype(float), (size,)).copy()
    return np.array([np.nan if v is None else float(v) for v in np.broadcast_to(column, (size,))])


def sweep(values: dict) -> dict:
    """Vectorised closed-form evaluation of many cases.

    Parameters
    ----------
    values : dict of str -> ndarray
        Every :data:`PARAMETERS` name as an array of length n (SI; ``source`` and
        ``earth`` as strings; ``magnitude`` SI numbers or text with units; None
        or NaN take the default). ``step`` does not enter the closed forms.

    Returns
    -------
    dict of str -> ndarray
        ``final_flat_m``, ``final_spherical_m`` (error at the end of the
        duration), ``max_flat_m``, ``max_spherical_m`` (largest |error| over the
        run) and ``schuler_period_s``, each of length n.

    Examples
    --------
    >>> out = sweep({"source": np.array(["tilt", "velocity"]), "duration": np.array([5060.0, 1265.0]),
    ...              "earth": np.array(["bollay", "bollay"])})
    >>> [round(v / 0.3048) for v in out["max_spherical_m"]]
    [7299, 805]
    """
    lengths = {np.size(v) for v in values.values() if v is not None and np.ndim(v) > 0}
    size = max(lengths) if lengths else 1
    sources = np.broadcast_to(np.asarray(values.get("source", "drift"), dtype=object), (size,))
    earths = np.broadcast_to(np.asarray(values.get("earth", "default"), dtype=object), (size,))
    earths = np.where(earths == None, "default", earths)  # noqa: E711 (element-wise test for None)
    duration = _numeric_column(values, "duration", size)
    duration = np.where(np.isnan(duration), FLIGHT_TIME, duration)
    speed = _numeric_column(values, "speed", size)
    speed = np.where(np.isnan(speed), SPEED, speed)
    radius = _numeric_column(values, "radius", size)
    gravity = _numeric_column(values, "gravity", size)
    for name in set(earths):
        chosen = earths == name
        R, g = earth_constants(str(name))
        preset_gravity = PRESETS[str(name)].gravity
        # an explicit radius keeps the preset's g (as earth_constants does), else the loop's effective g
        gravity = np.where(chosen & np.isnan(gravity), np.where(np.isnan(radius), g, preset_gravity), gravity)
        radius = np.where(chosen & np.isnan(radius), R, radius)
    raw_magnitude = values.get("magnitude")
    numeric = raw_magnitude is not None and np.asarray(raw_magnitude).dtype.kind in "fiu"
    magnitude = _numeric_column(values, "magnitude", size) if numeric else np.full(size, np.nan)
    if numeric and np.any(magnitude < 0):
        raise InvalidParameter("magnitude", "must be >= 0")
    outputs = {key: np.empty(size) for key in ("final_flat_m", "final_spherical_m", "max_flat_m", "max_spherical_m")}
    for source in set(sources):
        chosen = sources == source
        check_source(str(source))
        if raw_magnitude is not None and not numeric:
            # text magnitudes carry units that depend on the source: parse them one by one
            column = np.broadcast_to(np.asarray(raw_magnitude, dtype=object), (size,))
            magnitude[chosen] = [np.nan if v is None else parse_magnitude(str(source), v) for v in column[chosen]]
        magnitude[chosen] = np.where(np.isnan(magnitude[chosen]), parse_magnitude(str(source), None),
                                     magnitude[chosen])
        args = (magnitude[chosen], duration[chosen])
        R, g, V = radius[chosen], gravity[chosen], speed[chosen]
        outputs["final_flat_m"][chosen] = flat_error(source, *args, g, V)
        outputs["final_spherical_m"][chosen] = spherical_error(source, *args, R, g, V)
        outputs["max_flat_m"][chosen] = maximum_error(source, *args, R, g, V, earth="flat")
        outputs["max_spherical_m"][chosen] = maximum_error(source, *args, R, g, V)
    outputs["schuler_period_s"] = 2.0 * np.pi * np.sqrt(radius / gravity)
    return outputs


SYSTEM = System(
    name="errors",
    title="Schuler-tuned INS error propagation",
    source="Bollay, 'The Story of 84 Minutes' (source 002)",
    parameters=PARAMETERS,
    run=run,
    reproduce=reproduce,
    report=report,
    sweep=sweep,
)
