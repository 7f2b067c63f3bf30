"""Units at the boundary: parse what users type into SI, format SI for people.

The package works in SI inside (rad, rad/s, m, m/s, m/s^2, s). Users write
"0.01 deg/h", "6 h", "1e-4 g", "50 deg", "3960 mi": :func:`parse_quantity` turns
such a string, or a bare number in the option's display unit, into an SI float,
with a clear :class:`~schuler.exceptions.InvalidParameter` when it cannot.

Two traps of the units library are closed here:

* **"g" is gram in pint.** Where an acceleration is expected, a bare ``g`` (and
  ``mg``, ``ug``/``µg``) means standard gravity g0 = 9.80665 m/s^2, as the field
  writes it ("1e-4 g"). The explicit spellings ``g0`` and ``gee`` mean standard
  gravity everywhere.
* **Spec sheets write square roots**: "deg/sqrt(h)", "ug/√Hz". pint knows
  neither spelling (it silently drops "√"), so both become ``**0.5`` first.
* **Radians are dimensionless in pint**, so "0.01 Hz" would pass as an angular
  rate and "95 percent" as an angle. Every option whose display unit carries an
  angle (deg, deg/h, arcmin ...) requires the value to carry an angle unit too,
  with the same power.

Examples
--------
>>> parse_quantity("0.01 deg/h", "deg/h", name="drift")
4.84813681109536e-08
>>> parse_quantity(50, "deg", name="latitude")   # bare number: display unit
0.8726646259971648
>>> parse_quantity("1e-4 g", "g", name="bias")
0.000980665
>>> parse_quantity("0.01 Hz", "deg/h", name="drift")
Traceback (most recent call last):
...
schuler.exceptions.InvalidParameter: drift: '0.01 Hz' is not an angular rate (expected a unit like deg/h)
"""

from __future__ import annotations

import math
import re
from functools import lru_cache

import pint
from pint.facets.plain import PlainUnit

from schuler.exceptions import InvalidParameter

ureg: pint.UnitRegistry = pint.UnitRegistry()
ureg.define("standard_gravity_unit = 9.80665 meter / second ** 2 = g0 = gee")
ureg.define("statute_mile = 1609.344 meter = smi")

_ANGLE_UNITS = frozenset(
    {"radian", "degree", "arcminute", "arcsecond", "revolution", "turn", "gradian", "milliarcsecond"}
)
_ANGLE_RATE_UNITS = frozenset({"revolutions_per_minute", "revolutions_per_second", "degree_per_second"})

# A bare g (optionally milli or micro) as a whole token: standard gravity where an
# acceleration is expected.
_G_TOKEN = re.compile(r"(?<![A-Za-z_])(m|u|µ|micro|milli)?g(?![A-Za-z_0-9])")
_G_PREFIX = {None: "", "m": "milli", "milli": "milli", "u": "micro", "µ": "micro", "micro": "micro"}

# sqrt(X) and √X / √(X) as spec sheets write them
_SQRT_CALL = re.compile(r"(?:sqrt|√)\s*\(([^()]*)\)")
_SQRT_SIGN = re.compile(r"√\s*([A-Za-zµ_][A-Za-z0-9µ_]*)")

_KIND_NAMES = {
    "[length]": "a length",
    "[length] / [time]": "a speed",
    "[length] / [time] ** 2": "an acceleration",
    "[time]": "a time",
    "1 / [time]": "a rate (1/s)",
    "[mass] * [length] ** 2": "a moment of inertia",
    "[mass] * [length] ** 2 / [time]": "an angular momentum",
    "[mass] * [length] ** 2 / [time] ** 2": "a torque",
}


def _exponents(unit: PlainUnit) -> dict[str, float]:
    """Each unit name in ``unit`` with its exponent (deg/h -> {"degree": 1.0, "hour": -1.0})."""
    # pint types an exponent as any scalar, complex included; the units it builds have real ones
    return {name: float(exponent) for name, exponent in unit._units.items()}  # type: ignore[arg-type]


def _angle_power(unit: PlainUnit) -> int:
    """The power of angle units in a unit (deg/h -> 1, Hz -> 0, rad^2 -> 2)."""
    power = 0.0
    for name, exponent in _exponents(unit).items():
        _, base, _ = ureg.parse_unit_name(name)[0] if ureg.parse_unit_name(name) else ("", name, "")
        if base in _ANGLE_UNITS or base in _ANGLE_RATE_UNITS:
            power += exponent
    return int(round(power))


@lru_cache(maxsize=256)
def _display_unit(unit: str) -> pint.Unit:
    return ureg.Unit(_standard_gravity_spelling(unit))


def _standard_gravity_spelling(text: str) -> str:
    return _G_TOKEN.sub(lambda m: f"{_G_PREFIX[m.group(1)]}g0", _square_roots(text))


def _square_roots(text: str) -> str:
    """"deg/sqrt(h)", "ug/√Hz" -> "deg/(h)**0.5", "ug/Hz**0.5"."""
    return _SQRT_SIGN.sub(r"\1**0.5", _SQRT_CALL.sub(r"(\1)**0.5", text))


def _describe(unit: pint.Unit) -> str:
    angle = _angle_power(unit)
    dims = str(unit.dimensionality)
    if angle == 1 and dims == "1 / [time]":
        return "an angular rate"
    if angle == 1 and dims == "dimensionless":
        return "an angle"
    if dims == "dimensionless":
        return "a plain number"
    return _KIND_NAMES.get(dims, f"a quantity in {unit:~P}")


def _gravity_units_expected(unit: pint.Unit) -> bool:
    """A bare g means standard gravity where the unit involves length and time but no mass
    (an acceleration, a noise density in ug/sqrt(Hz), a g-sensitivity in deg/h/g)."""
    dims = unit.dimensionality
    return dims.get("[mass]", 0) == 0 and dims.get("[length]", 0) != 0 and dims.get("[time]", 0) != 0


def parse_quantity(value, unit: str, *, name: str) -> float:
    """Convert a user value to an SI float.

    Parameters
    ----------
    value : str, int or float
        A number (taken in ``unit``) or a string with a unit ("0.01 deg/h").
        A string holding only a number is also taken in ``unit``.
    unit : str
        The display unit of the option, e.g. ``"deg"``, ``"deg/h"``, ``"s"``,
        ``"ft"``, ``"g"`` (standard gravity), ``""`` for a plain number.
    name : str
        The option or key name, used in error messages.

    Returns
    -------
    float
        The value in SI (angles in rad).

    Raises
    ------
    InvalidParameter
        Unparseable text, an unknown unit, a unit of the wrong dimension or
        without the angle the option needs, or a value that is not finite.
    """
    target = _display_unit(unit)
    if isinstance(value, bool):
        raise InvalidParameter(name, f"{value!r} is not a number")
    if isinstance(value, (int, float)):
        quantity = ureg.Quantity(float(value), target)
        shown = repr(value)
    else:
        text = str(value).strip()
        shown = repr(text)
        if not text:
            raise InvalidParameter(name, "empty value")
        try:
            quantity = ureg.Quantity(float(text), target)
        except ValueError:
            spelled = _standard_gravity_spelling(text) if _gravity_units_expected(target) else _square_roots(text)
            try:
                quantity = ureg.Quantity(spelled)
            except Exception:  # pint raises many kinds on malformed text: "()" asserts, "deg (" fails to tokenize
                raise InvalidParameter(
                    name, f"cannot read {shown} as a quantity in {unit or 'plain numbers'}"
                ) from None
            if not isinstance(quantity, ureg.Quantity):
                quantity = ureg.Quantity(float(quantity), "")
            if not str(quantity.units) and str(target):
                # "50" with spaces or an expression: a bare number in the display unit
                quantity = ureg.Quantity(float(quantity.magnitude), target)
    if not quantity.is_compatible_with(target) or _angle_power(quantity.units) != _angle_power(target):
        raise InvalidParameter(
            name, f"{shown} is not {_describe(target)} (expected a unit like {unit or 'a plain number'})"
        )
    si = quantity.to_base_units()
    try:
        magnitude = float(si.magnitude)
    except TypeError:
        raise InvalidParameter(name, f"{shown} is not a single number") from None
    if not math.isfinite(magnitude):
        raise InvalidParameter(name, f"{shown} is not a finite number")
    return magnitude


def to_unit(value_si, unit: str):
    """Express an SI value (float or array) in ``unit`` (e.g. rad -> "arcmin").

    Parameters
    ----------
    value_si : float or ndarray
        Value in the SI unit of ``unit``'s dimension.
    unit : str
        Target unit ("deg/h", "arcmin", "ft" ...).

    Examples
    --------
    >>> round(to_unit(4.84813681109536e-08, "deg/h"), 12)
    0.01
    """
    target = _display_unit(unit)
    base = ureg.Quantity(1.0, target).to_base_units()
    return value_si / base.magnitude


def from_unit(value, unit: str):
    """Express a value given in ``unit`` in SI (the inverse of :func:`to_unit`).

    Parameters
    ----------
    value : float or ndarray
        Value in ``unit``.
    unit : str
        Its unit ("deg/h", "arcmin", "ft" ...).
    """
    target = _display_unit(unit)
    return value * ureg.Quantity(1.0, target).to_base_units().magnitude


def format_quantity(value_si: float, unit: str, digits: int = 4) -> str:
    """Format an SI value in ``unit`` for people: ``"3.556 arcmin"``.

    Parameters
    ----------
    value_si : float
        Value in the SI unit of ``unit``'s dimension.
    unit : str
        Display unit.
    digits : int
        Number of significant digits.

    Examples
    --------
    >>> format_quantity(1e-3, "arcmin")
    '3.438 arcmin'
    """
    return f"{to_unit(value_si, unit):.{digits}g} {unit}".rstrip()


_SI_SYMBOLS = {"radian": "rad", "meter": "m", "second": "s", "kilogram": "kg", "ampere": "A", "kelvin": "K"}


@lru_cache(maxsize=256)
def si_unit(unit: str) -> str:
    """The SI unit (as written in ``units`` maps) of values whose display unit is ``unit``.

    Angles are in rad; a plain number is ``"1"``.

    >>> si_unit("deg/h"), si_unit("g"), si_unit("arcmin"), si_unit(""), si_unit("deg/h^0.5")
    ('rad/s', 'm/s^2', 'rad', '1', 'rad/s^0.5')
    """
    base = ureg.Quantity(1.0, _display_unit(unit)).to_base_units().units
    powers = {_SI_SYMBOLS.get(name, name): exponent for name, exponent in _exponents(base).items()}
    if _angle_power(_display_unit(unit)) and "rad" not in powers:
        powers = {"rad": _angle_power(_display_unit(unit)), **powers}

    def term(symbol, exponent):
        exponent = abs(exponent)
        if exponent == 1:
            return symbol
        return f"{symbol}^{int(exponent) if float(exponent).is_integer() else exponent:g}"

    top = [term(s, e) for s, e in powers.items() if e > 0]
    bottom = [term(s, e) for s, e in powers.items() if e < 0]
    text = "*".join(top) or "1"
    if bottom:
        text += "/" + ("/".join(bottom))
    return text
