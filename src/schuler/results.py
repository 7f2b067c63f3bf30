"""Typed results: every study returns a dataclass deriving from :class:`Result`.

A result knows how to turn itself into JSON-safe data (:meth:`Result.to_dict`)
and into something people read (:meth:`Result.render`, a rich renderable; its
``str`` is the plain-text form). Keys whose unit is not in their name are listed
in the class's ``units`` map.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, ClassVar

import numpy as np


@dataclasses.dataclass(frozen=True)
class Output:
    """One output of a system's ``evaluate``: its key, SI unit, display unit and meaning.

    Parameters
    ----------
    name : str
        Key in ``evaluate``'s dict and in the result's ``to_dict()`` (unit in
        the name where it is not obvious: ``azimuth_error_rad``).
    unit : str
        SI unit of the values (``"rad"``, ``"s"``, ``"1"``).
    display : str
        Unit shown to people (``"arcmin"``); empty: the SI unit.
    description : str
        One line for tables, plots and documentation.
    """

    name: str
    unit: str
    display: str = ""
    description: str = ""

    @property
    def shown_unit(self) -> str:
        return self.display or ("" if self.unit == "1" else self.unit)


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

    def _repr_html_(self) -> str:
        """The readable table as HTML, for notebooks (inline styles, no scripts)."""
        import io

        from rich.console import Console

        console = Console(width=110, record=True, file=io.StringIO())
        console.print(self.render())
        return console.export_html(inline_styles=True, code_format="<pre style=\"font-family:monospace\">{code}</pre>")

    def figures(self) -> dict[str, Any]:
        """The result's figures, file stem -> matplotlib Figure, drawn by the system that made it ({}: none).

        The system attaches its ``figures(result)`` hook when it returns the result
        (:meth:`attach_figures`); the files ``--out`` writes are these figures.
        """
        draw = self.__dict__.get("_draw_figures")
        return dict(draw(self)) if draw is not None else {}

    def attach_figures(self, draw) -> Result:
        """Let :meth:`figures` and :meth:`plot` draw with ``draw(result) -> {stem: Figure}``; returns the result.

        Parameters
        ----------
        draw : callable or None
            A system's ``figures`` hook (None: the result has no figures).
        """
        self.__dict__["_draw_figures"] = draw
        return self

    def plot(self, name: str | None = None):
        """One of the result's figures (the first by default) as a matplotlib Figure; no backend is switched.

        Parameters
        ----------
        name : str, optional
            The figure's stem, as in the ``--out`` files (``align_time_history``); default: the first.

        Raises
        ------
        ValueError
            The result has no figures.
        KeyError
            No figure called ``name`` (the figures there are named).
        """
        import matplotlib.pyplot as plt

        figures = self.figures()
        if not figures:
            raise ValueError(f"{type(self).__name__} has no figures")
        chosen = next(iter(figures)) if name is None else name
        if chosen not in figures:
            for figure in figures.values():
                plt.close(figure)
            raise KeyError(f"no figure {name!r}; figures: {', '.join(figures)}")
        for stem, figure in figures.items():
            if stem != chosen:
                plt.close(figure)
        return figures[chosen]

    def to_dataframe(self):
        """The result as a pandas DataFrame: here one row of its scalar fields, units in the column names.

        Results with time histories or members override it (histories indexed by time, one row per member).
        """
        import pandas as pd

        row = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if f.repr and isinstance(value, (int, float, str, bool, np.floating, np.integer, np.bool_)):
                unit = self.units.get(f.name, "")
                row[f"{f.name} [{unit}]" if unit and unit != "1" else f.name] = value
        return pd.DataFrame([row])


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


@dataclasses.dataclass(kw_only=True)
class SystemResult(RunResult):
    """What :meth:`System.run <schuler.contract.System.run>` returns for every system: one case in full.

    ``outputs`` holds every declared output of the system's ``evaluate`` for the
    case (SI; the same values ``evaluate`` gives, by construction), readable as
    attributes (``result.azimuth_error_rad``); ``histories`` the named time
    histories (:class:`~schuler.core.response.Histories`, keyed by the stem of
    the CSV file ``--out`` writes); ``extras`` structured results beside the
    outputs (lists, tables: an aided run's outages), also readable as attributes.
    A system subclasses it only to change how it renders.
    """

    system: str
    outputs: dict[str, Any]
    fidelity: str | None = None
    extras: dict[str, Any] = dataclasses.field(default_factory=dict)
    parameters: dict[str, Any] = dataclasses.field(default_factory=dict, repr=False)
    histories: dict[str, Any] = dataclasses.field(default_factory=dict, repr=False)
    output_units: dict[str, str] = dataclasses.field(default_factory=dict, repr=False)
    display_units: dict[str, str] = dataclasses.field(default_factory=dict, repr=False)
    extra_units: dict[str, str] = dataclasses.field(default_factory=dict, repr=False)

    def __getattr__(self, name: str) -> Any:
        # only reached when normal lookup fails: outputs and extras read as attributes
        if not name.startswith("_"):
            for holder in ("outputs", "extras"):
                values = self.__dict__.get(holder, {})
                if name in values:
                    return values[name]
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r}")

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe: every output and extra at the top level, ``units`` of the outputs, ``monte_carlo``."""
        data = {name: json_safe(value) for name, value in self.outputs.items()}
        data.update({name: json_safe(value) for name, value in self.extras.items()})
        if self.fidelity is not None:
            data["fidelity"] = self.fidelity
        data["monte_carlo"] = None if self.monte_carlo is None else self.monte_carlo.to_dict()
        data["units"] = {**self.output_units, **self.extra_units, **type(self).units}
        return data

    def to_dataframe(self):
        """The first histories indexed by time (``t_s``), or one row of the outputs where there are none.

        Units are in the column names (``azimuth_error_rad``, ``c_gamma [1/s]``) and in ``attrs["units"]``;
        every set of histories is ``result.histories[stem].to_dataframe()``.
        """
        import pandas as pd

        if self.histories:
            return next(iter(self.histories.values())).to_dataframe()
        row = {}
        for name, value in self.outputs.items():
            unit = self.output_units.get(name, "")
            row[name if not unit or unit == "1" or name.endswith(_suffix_of(unit)) else f"{name} [{unit}]"] = value
        frame = pd.DataFrame([row])
        frame.attrs["units"] = dict(self.output_units)
        return frame

    def render(self):
        """The outputs in their display units, then the Monte Carlo's statistics."""
        from rich.console import Group
        from rich.table import Table

        from schuler.units import to_unit

        table = Table(title=f"{self.system}" + (f" ({self.fidelity})" if self.fidelity else ""), show_header=False)
        table.add_column("output")
        table.add_column("value", justify="right")
        for name, value in self.outputs.items():
            unit = self.display_units.get(name, "")
            if isinstance(value, (float, int, np.floating, np.integer)) and not isinstance(value, bool):
                shown = float(to_unit(value, unit)) if unit else float(value)
                table.add_row(display_label(name, unit), f"{shown:.6g}")
            else:
                table.add_row(name, str(value))
        return table if self.monte_carlo is None else Group(table, self.monte_carlo.render())


@dataclasses.dataclass
class MonteCarloStatistics(Result):
    """Statistics of one output over the members of a Monte Carlo, in the output's SI unit.

    ``count`` is the number of members with a finite value; ``std`` is the sample
    standard deviation (ddof = 1); ``p05``, ``p50``, ``p95`` are percentiles
    (exact up to 100,000 members, from a uniform sample beyond). Every other
    field is None when no member has a finite value.
    """

    count: int
    mean: float | None
    std: float | None
    min: float | None
    max: float | None
    rms: float | None
    p05: float | None
    p50: float | None
    p95: float | None

    def __getitem__(self, key: str) -> float | int | None:
        """Field by name, as the statistics were read before they were typed (``stats["std"]``)."""
        if key not in _STATISTIC_FIELDS:
            raise KeyError(key)
        return getattr(self, key)


_STATISTIC_FIELDS = ("count", "mean", "std", "min", "max", "rms", "p05", "p50", "p95")


@dataclasses.dataclass
class MonteCarloSummary(Result):
    """Statistics of each output over the members of a Monte Carlo (SI, keyed by output name).

    ``summary["azimuth_error_rad"]`` (or ``summary.statistics[name]``) is an
    :class:`MonteCarloStatistics`: ``.mean``, ``.std``, ``.rms``, ``.p95`` ...
    ``samples`` keeps the first 100,000 members' values, and
    :meth:`to_dataframe` gives them as one row per member.
    """

    members: int
    seed: int
    statistics: dict[str, MonteCarloStatistics]
    display_units: dict[str, str] = dataclasses.field(default_factory=dict, repr=False)
    samples: dict[str, np.ndarray] = dataclasses.field(default_factory=dict, repr=False)
    si_units: dict[str, str] = dataclasses.field(default_factory=dict, repr=False)

    units: ClassVar[dict[str, str]] = {"members": "1", "seed": "1"}

    def __getitem__(self, name: str) -> MonteCarloStatistics:
        """The statistics of output ``name`` (KeyError naming the outputs there are)."""
        try:
            return self.statistics[name]
        except KeyError:
            raise KeyError(f"{name!r} is not an output of this Monte Carlo; outputs: {', '.join(self.statistics)}") \
                from None

    def __contains__(self, name: object) -> bool:
        return name in self.statistics

    def to_dataframe(self):
        """The members' outputs, one row per member kept (the first 100,000), SI units in the column names."""
        import pandas as pd

        columns = {}
        for name, values in self.samples.items():
            unit = self.si_units.get(name, "")
            columns[f"{name} [{unit}]" if unit and unit != "1" and not name.endswith(_suffix_of(unit)) else name] = \
                np.asarray(values)
        frame = pd.DataFrame(columns)
        frame.index.name = "member"
        frame.attrs["seed"] = self.seed
        frame.attrs["members"] = self.members
        return frame

    def statistics_frame(self):
        """The statistics as a DataFrame: one row per output, one column per statistic (SI)."""
        import pandas as pd

        return pd.DataFrame({name: dataclasses.asdict(stats) for name, stats in self.statistics.items()}).T

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

            def value(array, empty=empty):
                return None if empty else float(array[0])

            table[output.name] = MonteCarloStatistics(
                count=int(stats.count), mean=value(stats.mean), std=value(stats.std), min=value(stats.min),
                max=value(stats.max), rms=value(stats.rms), p05=None if empty else value(stats.percentile(5)),
                p50=None if empty else value(stats.percentile(50)), p95=None if empty else value(stats.percentile(95)))
        shown = {o.name: o.display for o in outputs if o.display}
        return cls(members=int(members), seed=int(seed), statistics=table, display_units=shown, samples=samples,
                   si_units={o.name: o.unit for o in outputs})

    def render(self):
        from rich.table import Table

        from schuler.units import to_unit

        constant = [name for name, stats in self.statistics.items() if stats.min == stats.max]
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
                value = getattr(stats, key)
                cells.append("-" if value is None else f"{float(to_unit(value, unit)) if unit else value:.4g}")
            table.add_row(display_label(name, unit), *cells)
        return table


_SI_SUFFIXES = ("_rad_s2", "_rad_s", "_m_s2", "_m_s", "_rad", "_s", "_m")


def _suffix_of(unit: str) -> str:
    """The key suffix that names an SI unit (``m/s`` -> ``_m_s``), as output keys spell it."""
    return "_" + unit.replace("/", "_").replace("^", "")


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


class Evaluation(Mapping[str, np.ndarray]):
    """What a system's ``evaluate(cases, histories=False)`` returns: its outputs and, when asked, histories.

    It reads as the mapping of outputs (``evaluation["azimuth_error_rad"]``, an
    array of length ``len(cases)``, SI), so sweeps and Monte Carlo use it as
    the dict of outputs; ``histories`` holds named
    :class:`~schuler.core.response.Histories` (keyed by file stem) and
    ``extras`` structured results (tables, lists) of a batch's first case,
    present only when ``evaluate`` was asked for histories.

    Parameters
    ----------
    outputs : mapping of str to array_like
        Every declared output, one value per case (SI).
    histories : mapping of str to Histories, optional
        Time histories by file stem (``align_time_history``).
    extras : mapping of str to object, optional
        JSON-safe structured results beside the outputs.
    units : mapping of str to str, optional
        Units of the extras' numbers whose key does not end in one (``{"magnitude": "m/s"}``, ``"1"``: none).
    """

    def __init__(self, outputs: Mapping[str, Any], histories: Mapping[str, Any] | None = None,
                 extras: Mapping[str, Any] | None = None, units: Mapping[str, str] | None = None):
        self.outputs = dict(outputs)
        self.histories = dict(histories or {})
        self.extras = dict(extras or {})
        self.units = dict(units or {})

    def __getitem__(self, name: str) -> np.ndarray:
        return self.outputs[name]

    def __iter__(self):
        return iter(self.outputs)

    def __len__(self) -> int:
        return len(self.outputs)


def write_result(result: Result, out_dir: Path, data_files: Callable[[Result, Path], list[Path]] | None = None
                 ) -> list[Path]:
    """The one writer of every system: histories as CSV (``STEM.csv``), figures (``STEM.png``, ``.svg``), data files.

    Each CSV has the time column ``t_s`` first and one column per channel, the
    SI unit in the column's name; ``data_files(result, out_dir)`` adds files in
    a field's own formats (a KF-GINS navigation file).

    Parameters
    ----------
    result : Result
        What a system returned (its figures from :meth:`Result.figures`).
    out_dir : Path
        Folder to write into (created if missing).
    data_files : callable, optional
        ``data_files(result, out_dir) -> [paths]``: the system's own data files.
    """
    from schuler.io import save_figure_formats, write_dataframe_csv

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    for stem, histories in getattr(result, "histories", {}).items():
        paths.append(write_dataframe_csv(histories.to_dataframe().reset_index(), out_dir / f"{stem}.csv"))
    for stem, figure in result.figures().items():
        paths += save_figure_formats(figure, out_dir / stem)
    if data_files is not None:
        paths += data_files(result, out_dir)
    return paths
