"""One type for every reproduction of a source: printed value, computed value, verdict.

A row holds the quantity, the value exactly as the source prints it and where,
the toolkit's value in the same unit, and a verdict computed from a stated
tolerance by :func:`compare` — never written by hand:

* ``agrees within 0.5 %``: the computed value is within the tolerance;
* ``tuned to match within 0.5 %``: it agrees, but an input was chosen so that it
  does (the row says which);
* ``erratum``: it does not agree and the row explains the source's mistake;
* ``differs by 4.2 %``: it does not agree and nothing explains it (a failure;
  the tests allow none);
* ``not printed in the source``: a computed value the source does not give.

Examples
--------
>>> compare("velocity error, flat Earth", 10120.4, "ft", printed="10,120", where="Problem 3").verdict
'agrees within 0.5 %'
>>> compare("drift error, flat Earth", 269993.0, "ft", printed="1.62 x 10^6", where="Problem 3",
...         erratum="the 1/6 of the cubic term is dropped").verdict
'erratum'
>>> compare("W*_x", 0.0135, "m/s^2").verdict
'not printed in the source'
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any, ClassVar

from schuler.results import Footnotes, Result


@dataclass(frozen=True)
class Tolerance:
    """How close a computed value must be to the printed one: ``max(relative * |printed|, absolute)``."""

    relative: float = 0.005
    absolute: float = 0.0

    def allows(self, printed: float, computed: float) -> bool:
        """Whether ``computed`` agrees with ``printed``.

        Parameters
        ----------
        printed, computed : float
            The printed and the computed value, in the row's unit.
        """
        return abs(computed - printed) <= max(self.relative * abs(printed), self.absolute)

    def describe(self, unit: str = "") -> str:
        """The tolerance in words for a verdict: ``within 0.5 %``.

        Parameters
        ----------
        unit : str
            Unit of the absolute tolerance.
        """
        parts = []
        if self.relative:
            parts.append(f"{self.relative * 100:g} %")
        if self.absolute:
            parts.append(f"{self.absolute:g} {unit}".strip())
        return "within " + (" or ".join(parts) if parts else "rounding")


@dataclass(frozen=True)
class ReproductionRow:
    """A published number beside the computed one.

    Attributes
    ----------
    quantity : str
    printed : str or None
        Exactly as printed (digits, separators, exponent); None if the source does not print it.
    where : str
        Where it is printed (table, equation, page).
    computed : float
        The toolkit's value, in ``unit``.
    unit : str
        Unit of ``printed`` and ``computed`` (the source's own).
    verdict : str
        From :func:`compare`.
    note : str
        The explanation (an erratum, how the value was tuned, what was computed).
    """

    quantity: str
    printed: str | None
    where: str
    computed: float
    unit: str
    verdict: str
    note: str = ""

    @property
    def failed(self) -> bool:
        """True when the value disagrees and nothing explains why."""
        return self.verdict.startswith("differs")


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)")


def printed_value(text: str) -> float:
    """The number in a printed value: ``"3,650"`` -> 3650, ``"1.62 x 10^6"`` -> 1.62e6, ``"0.34 %"`` -> 0.34.

    Parameters
    ----------
    text : str
        The value exactly as printed (any unit: only the number is read).

    Examples
    --------
    >>> printed_value("1.62 x 10^6"), printed_value("3,650"), printed_value("5.6e-3"), printed_value("-12.5 arcmin")
    (1620000.0, 3650.0, 0.0056, -12.5)
    """
    cleaned = text.replace(",", "").replace("\u2212", "-").replace("\u00d7", "x").replace("\u00b7", "x")
    power = re.search(r"(?:x|\*)\s*10\s*\^\s*([-+]?\d+)", cleaned)
    exponent = re.search(r"(?<=\d)[eE]([-+]?\d+)", cleaned)
    mantissa = _NUMBER.search(cleaned)
    if mantissa is None:
        raise ValueError(f"no number in {text!r}")
    value = float(mantissa[0])
    if power:
        value *= 10.0 ** int(power[1])
    elif exponent:
        value *= 10.0 ** int(exponent[1])
    return value


def compare(quantity: str, computed: float, unit: str, *, printed: str | None = None, where: str = "",
            value: float | None = None, tolerance: Tolerance = Tolerance(), erratum: str = "", tuned: str = "",
            note: str = "") -> ReproductionRow:
    """A :class:`ReproductionRow` whose verdict follows from the tolerance.

    Parameters
    ----------
    quantity, unit : str
    computed : float
        The toolkit's value in ``unit``.
    printed : str, optional
        The value exactly as printed.
    where : str
        Where it is printed.
    value : float, optional
        The printed number in ``unit``, where :func:`printed_value` cannot read it from the text.
    tolerance : Tolerance
    erratum : str
        Why the printed value is wrong (used when the values disagree).
    tuned : str
        Which input was chosen so that the values agree.
    note : str
        Anything else the reader needs.
    """
    computed = float(computed)
    notes = [n for n in (note,) if n]
    if printed is None:
        return ReproductionRow(quantity, None, where, computed, unit, "not printed in the source", "; ".join(notes))
    number = printed_value(printed) if value is None else float(value)
    if not math.isfinite(computed):
        verdict = "differs: the computed value is not finite"
    elif tolerance.allows(number, computed):
        verdict = ("tuned to match " if tuned else "agrees ") + tolerance.describe(unit)
        notes = [tuned, *notes] if tuned else notes
    elif erratum:
        verdict = "erratum"
        notes = [erratum, *notes]
    else:
        off = abs(computed - number) / abs(number) * 100 if number else math.inf
        verdict = f"differs by {off:.3g} %"
    return ReproductionRow(quantity, printed, where, computed, unit, verdict, "; ".join(n for n in notes if n))


@dataclass
class Reproduction(Result):
    """A source's published case re-computed: one row per printed number, and notes.

    Attributes
    ----------
    system : str
    source : str
        The document, cited by author, title, venue and year.
    constants : str
        The constants of the source used in the reproduction.
    rows : list of ReproductionRow
    notes : list of str
        What the reader should know beyond the rows.
    details : dict
        Further results (SI, unit in the key or in ``details_units``).
    details_units : dict
        Units of the keys of ``details`` whose unit is not in their name.
    data : object
        What ``write_files`` needs for figures (not in ``to_dict``).
    """

    system: str
    source: str
    constants: str
    rows: list[ReproductionRow]
    notes: list[str] = field(default_factory=list)
    details: dict[str, Any] = field(default_factory=dict)
    details_units: dict[str, str] = field(default_factory=dict, repr=False)
    data: Any = field(default=None, repr=False)

    units: ClassVar[dict[str, str]] = {"computed": "the row's unit"}

    def to_dict(self) -> dict[str, Any]:
        data = super().to_dict()
        data["units"] = {**self.units, **self.details_units}
        return data

    @property
    def failures(self) -> list[ReproductionRow]:
        return [row for row in self.rows if row.failed]

    def render(self):
        from rich.console import Group
        from rich.table import Table
        from rich.text import Text

        footnotes = Footnotes()
        table = Table(title=f"{self.system}: {self.source}", caption=f"constants: {self.constants}")
        for heading, justify in (("quantity", "left"), ("printed", "right"), ("where", "left"),
                                 ("computed", "right"), ("unit", "left"), ("verdict", "left")):
            table.add_column(heading, justify=justify)  # type: ignore[arg-type]
        for row in self.rows:
            mark = footnotes.reference(row.note)
            table.add_row(row.quantity, row.printed or "-", row.where, f"{row.computed:.6g}", row.unit,
                          f"{row.verdict} {mark}".strip())
        lines = footnotes.lines() + [f"- {note}" for note in self.notes]
        return Group(table, *(Text(line) for line in lines))
