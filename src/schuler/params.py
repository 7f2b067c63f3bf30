"""Parameters at the boundary: one definition serves the CLI, scenario files and sweeps.

A :class:`Parameter` names a user-settable input of a system's ``run``, its
display unit (bare numbers are taken in it), its default, its allowed range and
its help. :meth:`ParameterSet.case` turns what the user wrote into SI values and
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

import difflib
import math
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

import numpy as np

from schuler.exceptions import InvalidParameter
from schuler.units import from_unit, parse_quantity, quoted, si_unit, to_unit

_LARGEST_INTEGER = 2**63 - 1
"""The largest whole-number parameter (a count or a seed): numpy's int64."""

Kind = Literal["quantity", "choice", "integer", "flag", "text"]


def _fmt(x: float) -> str:
    return f"{x:g}"


def _is_quantity(value) -> bool:
    """Whether ``value`` is a pint Quantity (of any unit registry)."""
    return hasattr(value, "magnitude") and hasattr(value, "units") and hasattr(value, "to")


class _Shown:
    """An SI value as the user should see it in a range message: ``114.6 deg``."""

    def __init__(self, value: float, unit: str):
        self.value, self.unit = value, unit

    def __repr__(self) -> str:
        return f"{self.value:.6g} {self.unit}".strip()


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
    choices : tuple of str
        Allowed values of a ``choice`` (which must have some); empty for other kinds.
    renamed_choices : tuple of (str, str)
        Former values of a ``choice`` with the value that replaced each; a former value is refused naming it.
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
    choices: tuple[str, ...] = ()
    kind: Kind = "quantity"
    renamed_choices: tuple[tuple[str, str], ...] = ()

    def __post_init__(self):
        if self.kind == "choice" and not self.choices:
            raise ValueError(f"parameter {self.name}: a choice needs its allowed values (choices=...)")

    @property
    def option(self) -> str:
        return "--" + self.name.replace("_", "-")

    @property
    def si_unit(self) -> str:
        """Unit of the SI value (``"rad/s"`` for deg/h); ``"1"`` for plain numbers and other kinds."""
        return si_unit(self.unit) if self.kind == "quantity" else "1"

    def check(self, value, label: str | None = None):
        """Validate an SI value given directly (Python API): type, finiteness, range.

        Returns the value as the kind's Python type (float, int, str or bool);
        None is returned as is (the parameter's "not set" rule applies).

        Parameters
        ----------
        value : float, int, str, bool, pint Quantity or None
            The value in SI (the parameter's SI unit: :attr:`si_unit`); a quantity
            may instead carry its unit, as text (``"50 deg"``) or a pint Quantity.
        label : str, optional
            Name used in error messages (default: the parameter's name).

        """
        label = label or self.name
        if value is None:
            return None
        if self.kind == "quantity" and _is_quantity(value):
            value = self._quantity_si(value, label)
        elif self.kind == "quantity" and isinstance(value, str) and type(self).check is Parameter.check:
            return self._text_si(value, label)
        if self.kind == "choice":
            return self.parse(value, label)
        if self.kind == "text":
            if not isinstance(value, str):
                raise InvalidParameter(label, f"{value!r} is not text")
            return value
        if self.kind == "flag":
            if not isinstance(value, (bool, np.bool_)):
                raise InvalidParameter(label, f"{value!r} is not true or false")
            return bool(value)
        if self.kind == "integer":
            if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
                if not (isinstance(value, (float, np.floating)) and float(value).is_integer()):
                    raise InvalidParameter(label, f"{value!r} is not a whole number")
            number = int(value)
            self._check_range(number, number, number, label)
            return number
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise InvalidParameter(label, f"{value!r} is not a number in SI ({self.si_unit})")
        value = float(value)
        if not math.isfinite(value):
            raise InvalidParameter(label, f"{value!r} is not a finite number")
        shown = float(to_unit(value, self.unit))
        self._check_range(shown, value, _Shown(shown, self.unit), label)
        return value

    def range_text(self) -> str:
        lo = "-inf" if self.minimum is None else _fmt(self.minimum)
        hi = "inf" if self.maximum is None else _fmt(self.maximum)
        left = "(" if self.exclusive_minimum or self.minimum is None else "["
        right = ")" if self.exclusive_maximum or self.maximum is None else "]"
        return f"{left}{lo}, {hi}{right}" + (f" {self.unit}" if self.unit and self.kind == "quantity" else "")

    def parse(self, value, label: str | None = None):
        """Convert a user value to its SI value (float), choice (str), int or bool.

        ``label`` is the name used in error messages (defaults to ``name``).

        Parameters
        ----------
        value : str, float, int or bool
            As written: a bare number in the display unit (:attr:`unit`) or a string with a unit ("0.01 deg/h").
        label : str, optional
            Name used in error messages (default: the parameter's name).

        """
        label = label or self.name
        if self.kind == "choice":
            text = str(value).strip().lower()
            renamed = dict(self.renamed_choices)
            if text in renamed:
                raise InvalidParameter(label, f"{value!r} is renamed to {renamed[text]!r} (see CHANGELOG.md)")
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
                raise InvalidParameter(label, f"{quoted(str(value))} is not a whole number") from None
            if abs(number) > _LARGEST_INTEGER:  # counts and seeds are 64-bit integers everywhere below
                raise InvalidParameter(label, f"{quoted(str(value))} is too large: at most {_LARGEST_INTEGER:,}")
            self._check_range(number, number, value, label)
            return number
        si = parse_quantity(value, self.unit, name=label)
        self._check_range(to_unit(si, self.unit), si, value, label)
        return si

    def _check_range(self, shown: float, si, raw, label: str) -> None:
        if self._out_of_range(np.asarray([shown], dtype=float))[0]:
            raise InvalidParameter(label, f"{raw!r} is outside {self.range_text()}")

    def _out_of_range(self, shown: np.ndarray) -> np.ndarray:
        """Which values (in the display unit) lie outside the range (bool array)."""
        # an inclusive bound tolerates the rounding of the unit conversion
        bad = np.zeros(shown.shape, dtype=bool)
        for bound, exclusive, outside in ((self.minimum, self.exclusive_minimum, np.less),
                                          (self.maximum, self.exclusive_maximum, np.greater)):
            if bound is None:
                continue
            if exclusive:
                bad |= outside(shown, bound) | (shown == bound)
            else:
                near = np.abs(shown - bound) <= np.maximum(1e-12 * np.maximum(np.abs(shown), abs(bound)), 1e-12)
                bad |= outside(shown, bound) & ~near
        return bad

    def check_array(self, values, label: str | None = None) -> np.ndarray:
        """Validate SI values given as a batch (Python API): what :meth:`check` does, on a whole 1-D array.

        Numbers are checked at once (finite, whole where the kind asks it, in
        range); anything else (text, choices, None for "not set", objects) value
        by value, once per distinct value. NaN is refused like any non-finite
        number: "not set" is written None.

        Parameters
        ----------
        values : array_like
            A 1-D array (or list) of values in SI (the parameter's SI unit: :attr:`si_unit`).
        label : str, optional
            Name used in error messages (default: the parameter's name).

        Returns
        -------
        ndarray
            float64 for quantities (NaN where not set), int64 for whole numbers,
            bool for flags, object otherwise (None where not set).

        Raises
        ------
        InvalidParameter
            Not a 1-D array, an empty one, or a value :meth:`check` refuses.
        """
        label = label or self.name
        if self.kind == "quantity" and _is_quantity(values):
            values = self._quantity_si(values, label)
        try:
            array = np.atleast_1d(np.asarray(values))
        except (ValueError, TypeError):
            raise InvalidParameter(label, "expected a number or a 1-D array of numbers (ragged input)") from None
        if array.ndim != 1:
            raise InvalidParameter(label, f"expected a number or a 1-D array, got an array of shape {array.shape}")
        if array.size == 0:
            raise InvalidParameter(label, "expected at least one value, got an empty array")
        numeric = array.dtype.kind in "iuf" and self.kind in ("quantity", "integer")
        if numeric and type(self).check is Parameter.check:
            return self._check_numbers(array, label)
        if self.kind == "flag" and array.dtype.kind == "b":
            return array.astype(bool)
        return self._check_each(array, label)

    def _quantity_si(self, quantity, label: str):
        """A pint Quantity's magnitude (number or array) in SI, its unit checked as text with a unit is."""
        per_unit = parse_quantity(f"1 {quantity.units}", self.unit, name=label)
        magnitude = quantity.magnitude
        if isinstance(magnitude, (bool, np.bool_)) or np.asarray(magnitude).dtype.kind not in "iuf":
            raise InvalidParameter(label, f"{quantity!r} is not a number with a unit")
        return magnitude * per_unit

    def _text_si(self, text: str, label: str) -> float:
        """A value written with its unit ("50 deg"), as the command line reads it; a bare number must be SI."""
        try:
            number = float(text)
        except ValueError:
            return self.parse(text, label)
        if self.unit and not math.isclose(float(from_unit(1.0, self.unit)), 1.0, rel_tol=1e-15):
            raise InvalidParameter(label, f"{text!r} has no unit: write it with one ('{text} {self.unit}') "
                                          f"or give a number in SI ({self.si_unit})")
        return self.check(number, label)

    def _check_numbers(self, array: np.ndarray, label: str) -> np.ndarray:
        numbers = array.astype(float)
        finite = np.isfinite(numbers)
        if not finite.all():
            raise InvalidParameter(label, f"{numbers[~finite][0]!r} is not a finite number (not set is None)")
        if self.kind == "integer":
            whole = numbers == np.round(numbers)
            if not whole.all():
                raise InvalidParameter(label, f"{numbers[~whole][0]!r} is not a whole number")
            bad = self._out_of_range(numbers)
            if bad.any():
                raise InvalidParameter(label, f"{int(numbers[bad][0])!r} is outside {self.range_text()}")
            return array.astype(np.int64)
        shown = np.asarray(to_unit(numbers, self.unit), dtype=float) if self.unit else numbers
        bad = self._out_of_range(shown)
        if bad.any():
            raise InvalidParameter(label, f"{_Shown(float(shown[bad][0]), self.unit)!r} is outside "
                                          f"{self.range_text()}")
        return numbers

    def _check_each(self, array: np.ndarray, label: str) -> np.ndarray:
        checked: dict[tuple[type, Any], Any] = {}
        out = np.empty(array.size, dtype=object)
        for i, value in enumerate(array.tolist()):
            try:
                key = (type(value), value)
                out[i] = checked[key] if key in checked else checked.setdefault(key, self.check(value, label))
            except TypeError:  # an unhashable value: checked on its own
                out[i] = self.check(value, label)
        numbers = [v for v in out if v is not None]
        if numbers and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in numbers):
            if self.kind == "integer" and len(numbers) == out.size:
                return out.astype(np.int64)
            return np.array([np.nan if v is None else v for v in out], dtype=float)
        return out

    def default_text(self) -> str:
        """The default as ``--help`` shows it: ``50 deg``, ``off``, ``full``, ``not set``."""
        if self.default is None:
            return "not set"
        if self.kind == "flag":
            return "on" if self.parse(self.default) else "off"
        shown = f"{self.default:.6g}" if isinstance(self.default, float) else str(self.default)
        if self.kind == "quantity" and self.unit and not isinstance(self.default, str):
            shown += f" {self.unit}"
        return shown

    def help_text(self) -> str:
        parts = [self.help]
        if self.kind in ("quantity", "integer") and (self.minimum is not None or self.maximum is not None):
            parts.append(f"Range {self.range_text()}.")
        parts.append(f"[default: {self.default_text()}]")
        return " ".join(parts)


@dataclass(frozen=True)
class IntervalsParameter(Parameter):
    """A list of time intervals, each ``(start, duration)``: GNSS outages scheduled one by one.

    Written on the command line as ``start:duration`` pairs separated by commas
    (``"400:60, 1000:90"``, bare numbers in :attr:`~Parameter.unit`, or each with
    its unit: ``"400 s:1.5 min"``); in a scenario or from Python as a list of pairs
    (``[[400, 60], [1000, 90]]``); ``"none"`` or an empty list for no interval. The
    value is a tuple of ``(start_s, duration_s)`` float pairs in SI, sorted by start;
    a duration <= 0 or two intervals that overlap are refused.

    Examples
    --------
    >>> IntervalsParameter("outages", "s", None, "Outages.").parse("400:60, 100 s:1 min")
    ((100.0, 60.0), (400.0, 60.0))
    """

    kind: Any = "text"
    pairs: ClassVar[bool] = True
    """A scenario writes the value as a list of pairs (scalar parameters have none)."""

    def check(self, value, label: str | None = None):
        label = label or self.name
        if value is None or isinstance(value, str):
            return None if value is None else self.parse(value, label)
        return self._pairs(value, label, lambda x: self._si(x, label, si=True))

    def parse(self, value, label: str | None = None):
        label = label or self.name
        if isinstance(value, str):
            text = value.strip()
            if text.lower() in ("", "none"):
                return ()
            value = [item.split(":") for item in text.split(",")]
        return self._pairs(value, label, lambda x: self._si(x, label, si=False))

    def _si(self, x, label: str, *, si: bool) -> float:
        if isinstance(x, str):
            return float(parse_quantity(x.strip(), self.unit, name=label))
        if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating)):
            raise InvalidParameter(label, f"{x!r} is not a number")
        return float(x) if si else float(from_unit(float(x), self.unit))

    def _pairs(self, value, label: str, to_si) -> tuple[tuple[float, float], ...]:
        try:
            items = list(value)
        except TypeError:
            raise InvalidParameter(label, f"{value!r} is not a list of (start, duration) pairs") from None
        pairs = []
        for item in items:
            shown = ":".join(item) if isinstance(item, list) and all(isinstance(x, str) for x in item) else item
            if isinstance(item, str) or not hasattr(item, "__len__") or len(item) != 2:
                raise InvalidParameter(label, f"{shown!r} is not a (start, duration) pair; write start:duration, "
                                              "e.g. 400:60")
            start, duration = (to_si(x) for x in item)
            if not (math.isfinite(start) and math.isfinite(duration)) or duration <= 0:
                raise InvalidParameter(label, f"{shown!r}: the start must be finite and the duration > 0")
            pairs.append((start, duration))
        pairs.sort()
        for (start, duration), (following, _) in zip(pairs, pairs[1:]):
            if following < start + duration:
                raise InvalidParameter(label, f"the interval at {following:g} s starts before the one at {start:g} s "
                                              f"ends ({start + duration:g} s)")
        return tuple(pairs)

    def check_array(self, values, label: str | None = None) -> np.ndarray:
        out = np.empty(1, dtype=object)
        out[0] = self.check(values, label)
        return out

    def help_text(self) -> str:
        return f"{self.help} [default: {self.default_text()}]"


class Case(Mapping):
    """One validated case: every parameter of a system in SI, and which of them were given.

    A read-only mapping ``name -> SI value`` (None where a parameter's "not set"
    rule applies). Build it with :meth:`ParameterSet.case` (SI values) or
    :meth:`ParameterSet.parse` (values as users write them).
    """

    def __init__(self, values: dict[str, Any], given: Iterable[str] = ()):
        self._values = dict(values)
        self.given = frozenset(given)

    def __getitem__(self, name: str):
        return self._values[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def __repr__(self) -> str:
        shown = ", ".join(f"{k}={v!r}" for k, v in self._values.items() if k in self.given)
        return f"Case({shown})"


class ParameterSet:
    """The parameters of one system (or one command), declared once.

    Every entry point builds its case here: unknown names are refused with a
    suggestion, defaults are filled in one place, values are checked against
    their range, and options that exclude each other are refused together.

    Parameters
    ----------
    parameters : iterable of Parameter
    owner : str
        Who the parameters belong to (``"align"``), for messages.
    exclusive : iterable of tuple of str
        Groups of parameters of which at most one may be given.
    renamed : mapping of str to str
        Former names -> current names: a former name is refused with a message
        naming its replacement (scripts written for an older version).

    Examples
    --------
    >>> ps = ParameterSet([Parameter("latitude", "deg", 50.0, "Latitude.", minimum=-90, maximum=90)], owner="demo")
    >>> round(ps.case()["latitude"], 6)
    0.872665
    >>> ps.case(latitud=0.1)
    Traceback (most recent call last):
    ...
    schuler.exceptions.InvalidParameter: latitud: unknown parameter of demo; did you mean 'latitude'? allowed: latitude
    >>> ps.case(latitude=2.0)
    Traceback (most recent call last):
    ...
    schuler.exceptions.InvalidParameter: latitude: 114.592 deg is outside [-90, 90] deg
    """

    def __init__(self, parameters: Iterable[Parameter], *, owner: str = "", exclusive: Iterable[tuple[str, ...]] = (),
                 renamed: Mapping[str, str] | None = None):
        self.parameters = tuple(parameters)
        self.owner = owner
        self.renamed = dict(renamed or {})
        self._by_name = {p.name: p for p in self.parameters}
        if len(self._by_name) != len(self.parameters):
            raise ValueError(f"{owner}: a parameter is declared twice")
        self.exclusive = tuple(tuple(group) for group in exclusive)
        for group in self.exclusive:
            missing = set(group) - set(self._by_name)
            if missing:
                raise ValueError(f"{owner}: exclusive group names unknown parameters {sorted(missing)}")

    def __iter__(self) -> Iterator[Parameter]:
        return iter(self.parameters)

    def __len__(self) -> int:
        return len(self.parameters)

    def __getitem__(self, name: str) -> Parameter:
        return self._by_name[name]

    def __contains__(self, name: object) -> bool:
        return name in self._by_name

    def __add__(self, other: Iterable[Parameter]) -> ParameterSet:
        extra = other.exclusive if isinstance(other, ParameterSet) else ()
        renamed = {**self.renamed, **(other.renamed if isinstance(other, ParameterSet) else {})}
        return ParameterSet((*self.parameters, *other), owner=self.owner, exclusive=(*self.exclusive, *extra),
                            renamed=renamed)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self._by_name)

    def refuse_unknown(self, names: Iterable[str], label=lambda name: name) -> None:
        """Raise :class:`InvalidParameter` for the first name that is not a parameter, suggesting the closest.

        Parameters
        ----------
        names : iterable of str
            The names given.
        label : callable
            ``label(name) -> str``: how an error message names a parameter (a key or a CLI option).
        """
        for name in names:
            if name in self.renamed and name not in self._by_name:
                raise InvalidParameter(label(name), f"renamed to {label(self.renamed[name])!r} (see CHANGELOG.md)")
            if name not in self._by_name:
                hint = difflib.get_close_matches(name, self.names, n=1, cutoff=0.6)
                suggestion = f"did you mean {label(hint[0])!r}? " if hint else ""
                of = f" of {self.owner}" if self.owner else ""
                allowed = ", ".join(label(n) for n in self.names) or "(none)"
                raise InvalidParameter(label(name), f"unknown parameter{of}; {suggestion}allowed: {allowed}")

    def refuse_conflicts(self, given: Iterable[str], label=lambda name: name) -> None:
        """Raise :class:`InvalidParameter` when two parameters of an exclusive group are both given.

        Parameters
        ----------
        given : iterable of str
            The names given (set, not None).
        label : callable
            ``label(name) -> str``: how an error message names a parameter.
        """
        given = set(given)
        for group in self.exclusive:
            both = [name for name in group if name in given]
            if len(both) > 1:
                raise InvalidParameter(label(both[0]), f"cannot be combined with {label(both[1])}; give one of them")

    def defaults(self) -> dict[str, Any]:
        """Every parameter's default in SI (None where the "not set" rule applies)."""
        return {p.name: None if p.default is None else p.parse(p.default) for p in self.parameters}

    def case(self, values: Mapping[str, Any] | None = None, /, **si_values) -> Case:
        """A validated :class:`Case` from SI values (Python API); missing or None values take the default.

        Parameters
        ----------
        values : mapping of str to value, optional
            Parameters by name, in SI (each parameter's SI unit).
        **si_values
            More parameters by name, in SI.
        """
        given = {**(values or {}), **si_values}
        self.refuse_unknown(given)
        given = {name: value for name, value in given.items() if value is not None}
        self.refuse_conflicts(given, str)
        checked = self.defaults()
        for name, value in given.items():
            checked[name] = self._by_name[name].check(value)
        return Case(checked, given)

    def parse(self, written: Mapping[str, Any], *, labels: str = "name") -> Case:
        """A validated :class:`Case` from values as users write them (display units or unit strings).

        ``labels="option"`` names problems by CLI option (``--drift-east``).

        Parameters
        ----------
        written : mapping of str to value
            Values as written: bare numbers in each parameter's display unit, or strings with units.
        labels : {"name", "option"}
            How errors name a parameter.

        """
        label = (lambda name: self._by_name[name].option if name in self._by_name else "--" + name.replace("_", "-")) \
            if labels == "option" else (lambda name: name)
        given = {name: raw for name, raw in written.items() if raw is not None}
        self.refuse_unknown(given, label)
        self.refuse_conflicts(given, label)
        values = self.defaults()
        for name, raw in given.items():
            values[name] = self._by_name[name].parse(raw, label(name))
        return Case(values, given)

