"""What the navigation-error commands take: the error's magnitude, the Earth constants, the output grid.

Three things are shared by ``schuler errors run`` and its actions:

* **The magnitude of an error source**, whose unit follows the source (tilt and
  azimuth: an angle, velocity: a speed, accelerometer: an acceleration, drift: an
  angular rate). A written value ("0.01", "0.01 deg/h") can only be converted
  once the case's source is known, so :class:`MagnitudeParameter` keeps it as
  text and :class:`SourceParameters` converts it to SI when it builds the case.
  Not set, a source takes its Problem 3 value (Bollay 1966).
* **The Earth**: a preset of :data:`schuler.core.earth.PRESETS`, with the radius
  and gravity optionally overridden (:func:`earth_constants`).
* **The output time grid**: the core's rule (:func:`schuler.core.geometry.time_grid`:
  0, step, 2 step, ..., duration, a last, shorter step ending on the duration),
  sized before it is allocated (:func:`schuler.core.geometry.grid_points`) and
  named in its messages by :data:`GRID_NAMES`.

Examples
--------
>>> magnitude_si("drift", "0.01")          # bare number: the source's unit, deg/h
4.84813681109536e-08
>>> magnitude_si("tilt", "1 ft/s")
Traceback (most recent call last):
...
schuler.exceptions.InvalidParameter: magnitude: '1 ft/s' is not an angle (expected a unit like deg)
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from schuler.core.earth import PRESETS
from schuler.exceptions import InvalidParameter
from schuler.navigation_errors.single_channel import SOURCES, check_source
from schuler.params import Case, Parameter, ParameterSet
from schuler.units import parse_quantity, quoted, si_unit

SOURCE_UNITS: dict[str, str] = {
    "tilt": "deg",
    "velocity": "ft/s",
    "accelerometer": "g",
    "drift": "deg/h",
    "azimuth": "deg",
}
"""Display unit of each source's magnitude (bare numbers are taken in it)."""

SOURCE_SI_UNITS: dict[str, str] = {source: si_unit(unit) for source, unit in SOURCE_UNITS.items()}
"""SI unit of each source's magnitude (rad, m/s, m/s^2, rad/s, rad)."""

SOURCE_DEFAULTS: dict[str, float] = {"tilt": 0.01, "velocity": 1.0, "accelerometer": 1e-4, "drift": 0.01,
                                     "azimuth": 0.01}
"""Problem 3's magnitudes (Bollay 1966) in the display units."""

SOURCE_MAXIMA: dict[str, float] = {"tilt": 10.0, "velocity": 3e4, "accelerometer": 1.0, "drift": 3600.0,
                                   "azimuth": 90.0}
"""Largest magnitude of each source in the display units: the error equations are linearised (small angles),
and beyond these the numbers would stand for no instrument."""

FLIGHT_TIME = 10_120.0
"""Problem 3's flight time (Bollay 1966), s: 2 x 5060 s, the default duration of ``run``."""

MAX_GROWTH_EXPONENT = 200.0
"""Largest sqrt(2) omega_s t of a divergent vertical channel (its error grows as exp of it: e^200 = 7e86)."""

GRID_NAMES = ("duration", "output_step")
"""The output grid's parameters, as the core's time grid names them in its messages."""


def magnitude_si(source: str, value, label: str = "magnitude") -> float:
    """SI magnitude of ``source`` from None (its Problem 3 value), an SI number, or text.

    Parameters
    ----------
    source : str
        One of :data:`~schuler.navigation_errors.single_channel.SOURCES`.
    value : None, float or str
        None: the Problem 3 value; a number: SI (rad, m/s, m/s^2, rad/s by
        source); text: a bare number in the source's display unit
        (:data:`SOURCE_UNITS`) or a value with a unit of the source's dimension.
    label : str
        Name used in error messages.

    Returns
    -------
    float
        The magnitude in SI, finite and >= 0.
    """
    check_source(source)
    unit = SOURCE_UNITS[source]
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return parse_quantity(SOURCE_DEFAULTS[source], unit, name=label)
    shown: object = value
    if isinstance(value, str):
        number = parse_quantity(value, unit, name=label)
    else:
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise InvalidParameter(label, f"{value!r} is not a number in SI ({SOURCE_SI_UNITS[source]})")
        number = float(value)
    if not math.isfinite(number) or number < 0:
        raise InvalidParameter(label, f"{shown!r} must be finite and >= 0 (the source's direction sets the sign)")
    largest = parse_quantity(SOURCE_MAXIMA[source], unit, name=label)
    if number > largest * (1 + 1e-12):
        raise InvalidParameter(label, f"{shown!r} is more than {SOURCE_MAXIMA[source]:g} {unit}, the largest {source} "
                                      "error the linearised equations stand for")
    return number


@dataclass(frozen=True)
class MagnitudeParameter(Parameter):
    """The size of an error source: text until the case's ``source`` gives it a unit.

    :meth:`check` (Python API, SI) accepts a number >= 0 in the source's SI unit
    or text; :meth:`parse` (what users write) keeps the text, after checking that
    it is a number >= 0 or a value with the unit of one of the five sources.
    :class:`SourceParameters` converts it with the case's source.
    """

    kind: Any = "text"

    def check(self, value, label: str | None = None):
        label = label or self.name
        if value is None or isinstance(value, str):
            return None if value is None else self.parse(value, label)
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise InvalidParameter(label, f"{value!r} is not a number in SI or a value with a unit")
        number = float(value)
        if not math.isfinite(number) or number < 0:
            raise InvalidParameter(label, f"{value!r} must be finite and >= 0")
        return number

    def parse(self, value, label: str | None = None):
        label = label or self.name
        text = str(value).strip()
        problems = {}
        for source in SOURCES:
            try:
                magnitude_si(source, text, label)
                return text
            except InvalidParameter as error:
                problems[source] = error.reason
        if any("must be finite and >= 0" in reason for reason in problems.values()):
            raise InvalidParameter(label, f"{quoted(text)} must be finite and >= 0 (the source's direction sets "
                                   "the sign)")
        too_large = [source for source, reason in problems.items() if " is more than " in reason]
        if too_large:
            largest = ", ".join(f"{SOURCE_MAXIMA[source]:g} {SOURCE_UNITS[source]} ({source})" for source in too_large)
            raise InvalidParameter(label, f"{quoted(text)} is out of range: a magnitude is at most {largest}")
        raise InvalidParameter(label, f"cannot read {quoted(text)} as a magnitude: a number in the source's unit "
                                      "or a value with an angle, speed, acceleration or angular-rate unit")

    def help_text(self) -> str:
        return self.help


class SourceParameters(ParameterSet):
    """A :class:`ParameterSet` whose cases hold a given ``magnitude`` in SI, converted with their ``source``.

    A magnitude not given stays None: each source then takes its Problem 3
    value (so a sweep over ``source`` compares the sources at their own values).
    """

    def case(self, values: Mapping[str, Any] | None = None, /, **si_values) -> Case:
        return self._resolve(super().case(values, **si_values), "magnitude")

    def parse(self, written: Mapping[str, Any], *, labels: str = "name") -> Case:
        label = self["magnitude"].option if labels == "option" else "magnitude"
        return self._resolve(super().parse(written, labels=labels), label)

    @staticmethod
    def _resolve(case: Case, label: str) -> Case:
        if case["magnitude"] is None:
            return case
        values = dict(case)
        values["magnitude"] = magnitude_si(case["source"], case["magnitude"], label)
        return Case(values, case.given)


EARTH_PARAMETERS: tuple[Parameter, ...] = (
    Parameter("earth", "", "default", "Earth constants preset (default: mean radius 6371 km, standard "
              "gravity; bollay: R = 3960 mi, T = 5060 s; drozdovich: R = 6400 km).",
              choices=tuple(PRESETS), kind="choice"),
    Parameter("radius", "km", None, "Earth radius R (not set: the preset's).", minimum=1.0, maximum=1e5),
    Parameter("gravity", "m/s^2", None, "Gravity g of the Schuler loop (not set: the preset's; with only the "
              "radius set, the preset's g).", minimum=1e-3, maximum=1e3),
)
"""The Earth of every command: a preset, its radius and gravity optionally overridden."""


def earth_constants(earth: str = "default", radius: float | None = None, gravity: float | None = None):
    """(R, g) of a preset, overridden by explicit values, m and m/s^2.

    A preset that states its Schuler period (Bollay's 5060 s) uses the loop's
    effective gravity omega_s^2 R unless the radius or the gravity is given.

    Parameters
    ----------
    earth : str
        Preset name.
    radius : float, optional
        R overriding the preset's, m.
    gravity : float, optional
        g0 overriding the preset's, m/s^2.

    Examples
    --------
    >>> [round(x, 4) for x in earth_constants("bollay")]
    [6373002.24, 9.8266]
    """
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


def earth_constant_arrays(earth: np.ndarray, radius: np.ndarray, gravity: np.ndarray):
    """:func:`earth_constants` for arrays of cases (NaN radius or gravity: not set), m and m/s^2.

    Parameters
    ----------
    earth : ndarray
        Preset name of each case (None: the default), shape (N,), object array of str (names: no unit).
    radius : ndarray
        R of each case, m (NaN: the preset's).
    gravity : ndarray
        g0 of each case, m/s^2 (NaN: the preset's).

    Returns
    -------
    R : ndarray
        Radius of each case, m, shape (N,).
    g : ndarray
        Gravity of each case, m/s^2, shape (N,): the preset's loop effective gravity when neither radius nor
        gravity is given, its g0 when only the radius is (as :func:`earth_constants` does).
    """
    # numpy's stubs leave out None, which object arrays compare elementwise
    earth = np.where(np.equal(earth, None), "default", earth)  # type: ignore[call-overload]
    R, g = radius.astype(float).copy(), gravity.astype(float).copy()
    for name in set(earth.tolist()):
        chosen = earth == name
        preset_R, preset_g = earth_constants(str(name))
        # an explicit radius keeps the preset's g (as earth_constants does), else the loop's effective g
        g = np.where(chosen & np.isnan(g), np.where(np.isnan(R), preset_g, PRESETS[str(name)].gravity), g)
        R = np.where(chosen & np.isnan(R), preset_R, R)
    return R, g


def check_vertical_growth(duration: float, radius: float, gravity: float) -> None:
    """Refuse a run whose pure-inertial vertical error would grow beyond exp(:data:`MAX_GROWTH_EXPONENT`).

    Parameters
    ----------
    duration : float
        Simulated time, s.
    radius : float
        R, m.
    gravity : float
        g0, m/s^2.

    Examples
    --------
    >>> check_vertical_growth(1e6, 6.371e6, 9.80665)
    Traceback (most recent call last):
    ...
    schuler.exceptions.InvalidParameter: duration: 1e+06 s lets the vertical error grow as exp(1755);
    at most 113,988 s here
    """
    rate = math.sqrt(2.0 * gravity / radius)
    if rate * duration > MAX_GROWTH_EXPONENT:
        raise InvalidParameter("duration",
                               f"{duration:g} s lets the vertical error grow as exp({rate * duration:.0f}); "
                               f"at most {MAX_GROWTH_EXPONENT / rate:,.0f} s here")
