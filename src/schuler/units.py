"""Units at the boundary: parse what users type into SI, format SI for people.

The package works in SI inside (rad, rad/s, m, m/s, m/s^2, s). Users write
"0.01 deg/h", "6 h", "1e-4 g", "50 deg", "3960 mi": :func:`parse_quantity` turns
such a string, or a bare number in the option's display unit, into an SI float,
with a clear :class:`~schuler.exceptions.InvalidParameter` when it cannot.

**Unit text is data, not arithmetic.** A quantity is one number (scientific
notation kept: ``1e-4``, ``1.5e+3``) followed by a unit, at most
:data:`MAX_TEXT_LENGTH` characters. The unit is read here by a small grammar:
unit names joined by ``*``, ``/``, ``·`` or a space, parentheses, ``sqrt(...)``
and ``√``, and powers (``^`` or ``**``) that are small literal numbers
(``m/s^2``, ``Hz^0.5``, ``h^(-1/2)``; at most :data:`MAX_EXPONENT` in size).
Each name is looked up in the units library; nothing the user typed is ever
evaluated as an expression, so ``10**10**10 deg`` is refused at once instead of
computed for hours.

Three traps of the units library are closed here:

* **"g" is gram in pint.** Where an acceleration is expected, a bare ``g`` (and
  ``mg``, ``ug``/``µg``) means standard gravity g0 = 9.80665 m/s^2, as the field
  writes it ("1e-4 g"). The explicit spellings ``g0`` and ``gee`` mean standard
  gravity everywhere.
* **Spec sheets write square roots**: "deg/sqrt(h)", "ug/√Hz"; both are read as
  a power of 1/2.
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
>>> parse_quantity("10**10**10 deg", "deg", name="latitude")
Traceback (most recent call last):
...
schuler.exceptions.InvalidParameter: latitude: cannot read '10**10**10 deg' as a quantity in deg: a number and a \
unit, not an expression
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

MAX_TEXT_LENGTH = 100
"""Longest quantity text read, characters ("1.5e-3 deg/sqrt(h)" has 18)."""

MAX_EXPONENT = 4
"""Largest power written in a unit, in size (m/s^2, kg*m^2, Hz^0.5)."""

EXCERPT_LENGTH = 80
"""Characters of a user's text that a message quotes (longer text is cut, with "...")."""

_ANGLE_UNITS = frozenset(
    {"radian", "degree", "arcminute", "arcsecond", "revolution", "turn", "gradian", "milliarcsecond"}
)
_ANGLE_RATE_UNITS = frozenset({"revolutions_per_minute", "revolutions_per_second", "degree_per_second"})

# the number in front of a unit: decimal, scientific notation, or inf/nan (refused later as not finite)
_DIGITS = r"\d(?:_?\d)*"  # 10_000 as Python writes it
_NUMBER = re.compile(rf"[+-]?(?:(?:{_DIGITS}(?:\.(?:{_DIGITS})?)?|\.{_DIGITS})(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)",
                     re.IGNORECASE)
_NUMBER_WORD = re.compile(r"[+-]?(?:inf(?:inity)?|nan)", re.IGNORECASE)

# the tokens of a unit; a name may hold digits after its first letter (g0), never an operator
_UNIT_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<name>[A-Za-z_µμ°%‰][A-Za-z0-9_µμ]*)
  | (?P<power>\*\*|\^)
  | (?P<operator>[*/·×])
  | (?P<number>[+-]?\d+(?:\.\d+)?)
  | (?P<open>\()
  | (?P<close>\))
  | (?P<root>√)
""", re.VERBOSE)

_UNIT_NAME = re.compile(r"[A-Za-z_µμ][A-Za-z0-9_µμ]*")
_POWER_LITERAL = re.compile(r"(?:\*\*|\^)\s*(?:\([^()]*\)|[+-]?\d+(?:\.\d+)?)")

# a bare g (optionally milli or micro): standard gravity where an acceleration is expected
_G_NAME = re.compile(r"(m|u|µ|μ|micro|milli)?g")
_G_PREFIX = {None: "", "m": "milli", "milli": "milli", "u": "micro", "µ": "micro", "μ": "micro", "micro": "micro"}
_SYMBOLS = {"°": "degree", "%": "percent", "‰": "permille"}

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


def quoted(value, limit: int = EXCERPT_LENGTH) -> str:
    """A value as an error message quotes it: its repr, cut to about ``limit`` characters with "...".

    Parameters
    ----------
    value : object
        What the user gave (text, a number, a list ...).
    limit : int
        Longest excerpt of the text quoted, a count of characters.

    Examples
    --------
    >>> quoted("0.01 deg/h")
    "'0.01 deg/h'"
    >>> quoted("x" * 1000, limit=5)
    "'xxxxx...' (1,000 characters)"
    """
    if isinstance(value, str) and len(value) > limit:
        return f"{value[:limit]!r}"[:-1] + f"...' ({len(value):,} characters)"
    shown = repr(value)
    return shown if len(shown) <= limit + 2 else shown[:limit] + "..."


class _UnitSyntaxError(ValueError):
    """The text is not a unit of the grammar; the message says what was found."""


class _UnitReader:
    """Recursive descent over the tokens of a unit (see the module notes for the grammar)."""

    def __init__(self, text: str, gravity: bool):
        self.tokens = _tokens(text)
        self.position = 0
        self.gravity = gravity

    def read(self) -> PlainUnit:
        if not self.tokens:
            return ureg.Unit("")
        if self.tokens[0] == ("operator", "/"):  # "2/s": the number is the numerator
            self.tokens.insert(0, ("number", "1"))
        unit = self.product()
        if self.position != len(self.tokens):
            raise _UnitSyntaxError(f"unexpected {self.tokens[self.position][1]!r}")
        return unit

    def peek(self) -> tuple[str, str]:
        return self.tokens[self.position] if self.position < len(self.tokens) else ("end", "")

    def take(self) -> tuple[str, str]:
        token = self.peek()
        self.position += 1
        return token

    def product(self) -> PlainUnit:
        unit = self.factor()
        while True:
            kind, text = self.peek()
            if kind == "operator":
                self.take()
                right = self.factor()
                unit = unit / right if text == "/" else unit * right
            elif kind in ("name", "open", "root"):  # a space between names multiplies
                unit = unit * self.factor()
            else:
                return unit

    def factor(self) -> PlainUnit:
        unit = self.primary()
        if self.peek()[0] == "power":
            self.take()
            unit = unit ** self.exponent()
        return unit

    def primary(self) -> PlainUnit:
        kind, text = self.take()
        if kind == "root":
            return self.primary() ** 0.5
        if kind == "open":
            unit = self.product()
            if self.take()[0] != "close":
                raise _UnitSyntaxError("a parenthesis is not closed")
            return unit
        if kind == "number" and text == "1":  # "1/s"
            return ureg.Unit("")
        if kind == "name" and text == "sqrt" and self.peek()[0] == "open":
            return self.primary() ** 0.5
        if kind == "name":
            return ureg.Unit(self.lookup(text))
        if kind == "end":
            raise _UnitSyntaxError("the unit ends early")
        raise _UnitSyntaxError(f"unexpected {text!r}")

    def exponent(self) -> int | float:
        kind, text = self.take()
        if kind == "open":
            numerator = self.literal()
            denominator = 1.0
            if self.peek() == ("operator", "/"):
                self.take()
                denominator = self.literal()
            if self.take()[0] != "close" or denominator == 0:
                raise _UnitSyntaxError("a power in parentheses is a fraction like (1/2)")
            value = numerator / denominator
        elif kind == "number":
            value = float(text)
        else:
            raise _UnitSyntaxError("a power must be a number")
        if abs(value) > MAX_EXPONENT:
            raise _UnitSyntaxError(f"a power of {value:g} (at most {MAX_EXPONENT} in size)")
        return int(value) if value.is_integer() else value

    def literal(self) -> float:
        kind, text = self.take()
        if kind != "number":
            raise _UnitSyntaxError("a power must be a number")
        return float(text)

    def lookup(self, name: str) -> str:
        name = _SYMBOLS.get(name, name)
        match = _G_NAME.fullmatch(name)
        if self.gravity and match:
            name = f"{_G_PREFIX[match.group(1)]}g0"
        try:
            return ureg.get_name(name)
        except pint.errors.UndefinedUnitError:
            raise _UnitSyntaxError(f"unknown unit {name!r}") from None


def _tokens(text: str) -> list[tuple[str, str]]:
    tokens = []
    position = 0
    while position < len(text):
        match = _UNIT_TOKEN.match(text, position)
        if match is None:
            raise _UnitSyntaxError(f"unexpected {text[position]!r}")
        position = match.end()
        kind = match.lastgroup or ""
        if kind != "space":
            tokens.append((kind, match.group()))
    return tokens


def _exponents(unit: PlainUnit) -> dict[str, float]:
    """Each unit name in ``unit`` with its exponent (deg/h -> {"degree": 1.0, "hour": -1.0})."""
    # pint types an exponent as any scalar, complex included; the units built here have real ones
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
def _display_unit(unit: str) -> PlainUnit:
    return _UnitReader(unit, gravity=True).read()


def _describe(unit: PlainUnit) -> str:
    angle = _angle_power(unit)
    dims = str(unit.dimensionality)
    if angle == 1 and dims == "1 / [time]":
        return "an angular rate"
    if angle == 1 and dims == "dimensionless":
        return "an angle"
    if dims == "dimensionless":
        return "a plain number"
    return _KIND_NAMES.get(dims, f"a quantity in {unit:~P}")


def _gravity_units_expected(unit: PlainUnit) -> bool:
    """A bare g means standard gravity where the unit involves length and time but no mass
    (an acceleration, a noise density in ug/sqrt(Hz), a g-sensitivity in deg/h/g)."""
    dims = unit.dimensionality
    return dims.get("[mass]", 0) == 0 and dims.get("[length]", 0) != 0 and dims.get("[time]", 0) != 0


def _looks_like_expression(rest: str) -> bool:
    """Arithmetic after the number ("**10**10", "*3", "/2 deg", "+1") rather than a unit with a mistake."""
    if rest.lstrip().startswith(("*", "^", "+", "-")) or "+" in rest:
        return True
    # what is left of the unit without its names, its power literals and a leading "1" of "1/s"
    left = _POWER_LITERAL.sub(" ", _UNIT_NAME.sub(" ", rest))
    return re.search(r"\d", re.sub(r"(?<![\d.])1\s*/", "/", left)) is not None


def _number(text: str, shown: str, name: str) -> float:
    number = float(text)
    if math.isinf(number) and not _NUMBER_WORD.fullmatch(text):
        raise InvalidParameter(name, f"{shown}: the number is too large (floats end near 1.8e308)")
    return number


def parse_quantity(value, unit: str, *, name: str) -> float:
    """Convert a user value to an SI float.

    Parameters
    ----------
    value : str, int or float
        A number (taken in ``unit``) or a string with a unit ("0.01 deg/h"): one
        number, then a unit (see the module notes), at most :data:`MAX_TEXT_LENGTH`
        characters. A string holding only a number is also taken in ``unit``.
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
        Over-long or unreadable text, an expression, an unknown unit, a unit of the
        wrong dimension or without the angle the option needs, or a value that is
        not finite (too large for a float included).
    """
    target = _display_unit(unit)
    if isinstance(value, bool):
        raise InvalidParameter(name, f"{value!r} is not a number")
    if isinstance(value, (int, float)):
        shown = quoted(value)
        try:
            number = float(value)
        except OverflowError:
            raise InvalidParameter(name, f"{shown}: the number is too large (floats end near 1.8e308)") from None
        written = target
    else:
        text = str(value).strip()
        shown = quoted(text)
        if not text:
            raise InvalidParameter(name, "empty value")
        if len(text) > MAX_TEXT_LENGTH:
            raise InvalidParameter(name, f"{shown} is too long for a quantity (at most {MAX_TEXT_LENGTH} "
                                   "characters: a number and a unit)")
        match = _NUMBER.match(text)
        if match is None:
            raise InvalidParameter(name, f"cannot read {shown} as a quantity in {unit or 'plain numbers'}: it does "
                                   "not start with a number")
        number = _number(match.group(), shown, name)
        rest = text[match.end():]
        try:
            written = _UnitReader(rest, gravity=_gravity_units_expected(target)).read() if rest.strip() else target
        except _UnitSyntaxError as error:
            reason = "a number and a unit, not an expression" if _looks_like_expression(rest) else str(error)
            raise InvalidParameter(name, f"cannot read {shown} as a quantity in {unit or 'plain numbers'}: "
                                   f"{reason}") from None
    if not written.is_compatible_with(target) or _angle_power(written) != _angle_power(target):
        expected = f"expected a unit like {unit}" if unit else "expected a plain number, without a unit"
        raise InvalidParameter(name, f"{shown} is not {_describe(target)} ({expected})")
    try:
        magnitude = float(ureg.Quantity(number, written).to_base_units().magnitude)
    except (pint.errors.PintError, ArithmeticError):  # offset units (degC) in a product
        raise InvalidParameter(name, f"cannot convert {shown} to SI") from None
    if not math.isfinite(magnitude):
        if math.isfinite(number):
            raise InvalidParameter(name, f"{shown} is too large once in SI ({si_unit(unit)})")
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
