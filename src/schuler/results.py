"""Typed results: every study returns a dataclass deriving from :class:`Result`.

A result knows how to turn itself into JSON-safe data (:meth:`Result.to_dict`)
and into something people read (:meth:`Result.render`, a rich renderable; its
``str`` is the plain-text form). Keys whose unit is not in their name are listed
in the class's ``units`` map.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, ClassVar

import numpy as np


def json_safe(value: Any) -> Any:
    """Convert numpy arrays and scalars, tuples and nested results to JSON-safe data.

    Non-finite floats become None (JSON has no NaN); floats keep 15 significant
    digits, so rounding noise (29.999999999999993) does not reach the user.

    Parameters
    ----------
    value : object
        Numbers (any unit: they are written as they are), arrays, mappings, sequences, results.

    Examples
    --------
    >>> json_safe({"a": np.array([1.0, np.nan]), "b": (np.int64(2),), "c": 29.999999999999993})
    {'a': [1.0, None], 'b': [2], 'c': 30.0}
    """
    if isinstance(value, Result):
        return value.to_dict()
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: json_safe(getattr(value, f.name)) for f in dataclasses.fields(value) if f.repr}
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_safe(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        return float(f"{value:.15g}") if math.isfinite(value) else None
    if hasattr(value, "__fspath__"):
        return str(value)
    return value


@dataclasses.dataclass
class Result:
    """Base of every result dataclass.

    Subclasses are dataclasses; fields declared with ``field(repr=False)`` are
    left out of :meth:`to_dict` (use it for large internal arrays).
    """

    units: ClassVar[dict[str, str]] = {}

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe dict of the public fields, plus ``units`` when the class defines it."""
        data = {f.name: json_safe(getattr(self, f.name)) for f in dataclasses.fields(self) if f.repr}
        if self.units:
            data["units"] = dict(self.units)
        return data

    def render(self):
        """A rich renderable for people; the default is a two-column table of scalars."""
        from rich.table import Table

        table = Table(title=type(self).__name__, show_header=False)
        table.add_column("quantity")
        table.add_column("value", justify="right")
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.repr and isinstance(value, (int, float, str, bool, np.floating, np.integer)):
                shown = f"{value:.6g}" if isinstance(value, (float, np.floating)) else str(value)
                unit = self.units.get(f.name, "")
                table.add_row(f.name, f"{shown} {unit}".strip())
        return table

    def __str__(self) -> str:
        from rich.console import Console

        console = Console(width=110)
        with console.capture() as capture:
            console.print(self.render())
        return capture.get()


class Footnotes:
    """Numbered notes for a table: the table shows ``[n]``, the notes go below it.

    A note given twice keeps its first number.

    >>> notes = Footnotes()
    >>> notes.reference("3,650 ft is the amplitude"), notes.reference(""), notes.reference("3,650 ft is the amplitude")
    ('[1]', '', '[1]')
    >>> notes.lines()
    ['[1] 3,650 ft is the amplitude']
    """

    def __init__(self) -> None:
        self._numbers: dict[str, int] = {}

    def reference(self, *notes: str) -> str:
        """The ``[n]`` marks for the given notes (empty notes are skipped).

        Parameters
        ----------
        *notes : str
            The notes to mark.
        """
        numbers = sorted({self._numbers.setdefault(note, len(self._numbers) + 1) for note in notes if note})
        return " ".join(f"[{n}]" for n in numbers)

    def lines(self) -> list[str]:
        """Each note once, in order of first reference: ``"[n] note"``."""
        return [f"[{n}] {note}" for note, n in self._numbers.items()]


@dataclasses.dataclass(kw_only=True)
class RunResult(Result):
    """Base of the results of ``System.run``: one case, and optionally its Monte Carlo.

    ``monte_carlo`` holds the statistics of every output over the members (see
    :class:`MonteCarloSummary`); None for the nominal case alone.
    """

    monte_carlo: MonteCarloSummary | None = None


@dataclasses.dataclass
class MonteCarloSummary(Result):
    """Statistics of each output over the members of a Monte Carlo (SI, keyed by output name).

    ``statistics[name]`` holds count (finite values), mean, std (sample, ddof = 1),
    rms, min, max, p05, p50, p95 (percentiles exact up to 100,000 members, from a
    uniform sample beyond). ``samples`` keeps the first 100,000 members' values.
    """

    members: int
    seed: int
    statistics: dict[str, dict[str, float | None]]
    display_units: dict[str, str] = dataclasses.field(default_factory=dict, repr=False)
    samples: dict[str, np.ndarray] = dataclasses.field(default_factory=dict, repr=False)

    units: ClassVar[dict[str, str]] = {"members": "1", "seed": "1"}

    @classmethod
    def from_statistics(cls, members, seed, outputs, statistics, samples) -> MonteCarloSummary:
        """The summary of streamed statistics: count, mean, std, min, max, rms and percentiles per output.

        Parameters
        ----------
        members : int
            Number of members.
        seed : int
            Seed of the random streams.
        outputs : sequence of Output
            The outputs summarised (SI units; display units for tables).
        statistics : dict of str to StreamingStatistics
            Per output, over the members (SI).
        samples : dict of str to ndarray
            Per output, the members' values kept for histograms (SI).
        """
        table = {}
        for output in outputs:
            stats = statistics[output.name]
            empty = stats.count == 0
            entry: dict[str, float | None] = {"count": int(stats.count)}
            for key, value in (("mean", stats.mean), ("std", stats.std), ("min", stats.min), ("max", stats.max)):
                entry[key] = None if empty else float(value[0])
            entry["rms"] = None if empty else float(stats.rms[0])
            for q in (5, 50, 95):
                entry[f"p{q:02d}"] = None if empty else float(stats.percentile(q)[0])
            table[output.name] = entry
        shown = {o.name: o.display for o in outputs if o.display}
        return cls(members=int(members), seed=int(seed), statistics=table, display_units=shown, samples=samples)

    def render(self):
        from rich.table import Table

        from schuler.units import to_unit

        constant = [name for name, stats in self.statistics.items() if stats["min"] == stats["max"]]
        table = Table(title=f"Monte Carlo: {self.members} members (seed {self.seed})",
                      caption=f"the same in every member: {', '.join(constant)}" if constant else None)
        table.add_column("output")
        for heading in ("mean", "std", "p05", "p95"):
            table.add_column(heading, justify="right")
        for name, stats in self.statistics.items():
            if name in constant:
                continue
            unit = self.display_units.get(name, "")
            cells = []
            for key in ("mean", "std", "p05", "p95"):
                value = stats[key]
                cells.append("-" if value is None else f"{float(to_unit(value, unit)) if unit else value:.4g}")
            table.add_row(display_label(name, unit), *cells)
        return table


_SI_SUFFIXES = ("_rad_s2", "_rad_s", "_m_s2", "_m_s", "_rad", "_s", "_m")


def display_label(name: str, unit: str = "") -> str:
    """A column label in a display unit: ``azimuth_error_rad`` in arcmin -> ``azimuth_error (arcmin)``.

    Parameters
    ----------
    name : str
        Key with an SI unit suffix (``_rad``, ``_s``, ``_m_s`` ...).
    unit : str
        Display unit (empty: keep the key).

    Examples
    --------
    >>> display_label("azimuth_error_rad", "arcmin"), display_label("settling_time_s")
    ('azimuth_error (arcmin)', 'settling_time_s')
    """
    if not unit:
        return name
    for suffix in _SI_SUFFIXES:
        if name.endswith(suffix):
            return f"{name[: -len(suffix)]} ({unit})"
    return f"{name} ({unit})"
