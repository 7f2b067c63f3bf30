"""Parameters at the boundary: one definition serves the CLI, scenario files and sweeps.

A :class:`Parameter` names a user-settable input of a system's ``run``, its
display unit (bare numbers are taken in it), its default, its allowed range and
its help. :func:`parse_parameters` turns what the user wrote into SI values and
raises :class:`~schuler.exceptions.InvalidParameter` naming the option or key.

Examples
--------
>>> lat = Parameter("latitude", "deg", 50.0, "Latitude of the site.", minimum=-90, maximum=90)
>>> round(lat.parse("45 deg"), 6)
0.785398
>>> lat.parse("95 deg")
Traceback (most recent call last):
...
schuler.exceptions.InvalidParameter: latitude: '95 deg' is outside [-90, 90] deg
>>> lat.option
'--latitude'
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

from schuler.exceptions import InvalidParameter
from schuler.units import parse_quantity, to_unit

Kind = Literal["quantity", "choice", "integer", "flag", "text"]


def _fmt(x: float) -> str:
    return f"{x:g}"


@dataclass(frozen=True)
class Parameter:
    """One user-settable input.

    Parameters
    ----------
    name : str
        Python and scenario name (``drift_east``); the CLI option is ``--drift-east``.
    unit : str
        Display unit of a quantity ("deg", "deg/h", "s", "ft", "g", "" for a plain
        number); ignored for other kinds.
    default : Any
        Default in the display unit (a number, or a string with a unit), a choice,
        or None for "not set" (the API then applies its own rule).
    help : str
        One sentence for ``--help``.
    minimum, maximum : float, optional
        Allowed range in the display unit.
    exclusive_minimum, exclusive_maximum : bool
        Whether the bounds themselves are excluded.
    choices : tuple of str, optional
        Allowed values of a ``choice``.
    kind : {"quantity", "choice", "integer", "flag", "text"}
    """

    name: str
    unit: str
    default: Any
    help: str
    minimum: float | None = None
    maximum: float | None = None
    exclusive_minimum: bool = False
    exclusive_maximum: bool = False
    choices: tuple[str, ...] | None = None
    kind: Kind = "quantity"

    @property
    def option(self) -> str:
        return "--" + self.name.replace("_", "-")

    def range_text(self) -> str:
        lo = "-inf" if self.minimum is None else _fmt(self.minimum)
        hi = "inf" if self.maximum is None else _fmt(self.maximum)
        left = "(" if self.exclusive_minimum or self.minimum is None else "["
        right = ")" if self.exclusive_maximum or self.maximum is None else "]"
        return f"{left}{lo}, {hi}{right}" + (f" {self.unit}" if self.unit and self.kind == "quantity" else "")

    def parse(self, value, label: str | None = None):
        """Convert a user value to its SI value (float), choice (str), int or bool.

        ``label`` is the name used in error messages (defaults to ``name``).
        """
        label = label or self.name
        if self.kind == "choice":
            text = str(value).strip().lower()
            if text not in self.choices:
                raise InvalidParameter(label, f"{value!r} is not one of {', '.join(self.choices)}")
            return text
        if self.kind == "text":
            return str(value)
        if self.kind == "flag":
            if isinstance(value, bool):
                return value
            text = str(value).strip().lower()
            if text in ("true", "yes", "1", "on"):
                return True
            if text in ("false", "no", "0", "off"):
                return False
            raise InvalidParameter(label, f"{value!r} is not true or false")
        if self.kind == "integer":
            try:
                number = int(str(value).strip()) if not isinstance(value, int) or isinstance(value, bool) else value
            except ValueError:
                raise InvalidParameter(label, f"{value!r} is not a whole number")
            self._check_range(number, number, value, label)
            return number
        si = parse_quantity(value, self.unit, name=label)
        self._check_range(to_unit(si, self.unit), si, value, label)
        return si

    def _check_range(self, shown: float, si, raw, label: str) -> None:
        low_bad = self.minimum is not None and (
            shown < self.minimum or (self.exclusive_minimum and shown <= self.minimum)
        )
        high_bad = self.maximum is not None and (
            shown > self.maximum or (self.exclusive_maximum and shown >= self.maximum)
        )
        # tolerate rounding of unit conversion at an inclusive bound
        if low_bad and not self.exclusive_minimum and math.isclose(shown, self.minimum, rel_tol=1e-12, abs_tol=1e-12):
            low_bad = False
        if high_bad and not self.exclusive_maximum and math.isclose(shown, self.maximum, rel_tol=1e-12, abs_tol=1e-12):
            high_bad = False
        if low_bad or high_bad:
            raise InvalidParameter(label, f"{raw!r} is outside {self.range_text()}")

    def help_text(self) -> str:
        parts = [self.help]
        bounded = self.minimum is not None or self.maximum is not None
        if self.kind == "quantity":
            parts.append(f"[{self.unit or 'number'}; range {self.range_text()}]" if bounded else f"[{self.unit or 'number'}]")
        elif self.kind == "integer" and bounded:
            parts.append(f"[range {self.range_text()}]")
        if self.default is not None and self.kind != "flag":
            parts.append(f"(default {self.default})")
        return " ".join(parts)


def parse_parameters(parameters, values: dict[str, Any], *, labels: str = "name") -> dict[str, Any]:
    """Parse user values (display units or unit strings) into SI for a set of parameters.

    Parameters
    ----------
    parameters : iterable of Parameter
    values : dict
        name -> value as written; missing or None values take the default
        (None defaults stay None).
    labels : {"name", "option"}
        Name errors by key (scenario files) or by CLI option.

    Raises
    ------
    InvalidParameter
        For an unknown name or an invalid value.
    """
    by_name = {p.name: p for p in parameters}
    unknown = sorted(set(values) - set(by_name))
    if unknown:
        raise InvalidParameter(unknown[0], f"unknown parameter; allowed: {', '.join(sorted(by_name))}")
    parsed = {}
    for name, spec in by_name.items():
        raw = values.get(name)
        label = spec.option if labels == "option" else name
        if raw is None:
            parsed[name] = None if spec.default is None else spec.parse(spec.default, label)
        else:
            parsed[name] = spec.parse(raw, label)
    return parsed
