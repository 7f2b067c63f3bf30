"""What a sweep found: statistics of every result (overall and per swept value), streamed from the chunk files.

One chunk is in memory at a time: :func:`gather` streams the chunk files into
``results.parquet`` (and ``results.csv``) while accumulating count, mean,
standard deviation, extremes and percentiles (from a uniform sample of 100,000
cases), and means per value of each swept parameter; :func:`histograms` is a
second streamed pass.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

import numpy as np

from schuler.core.stats import StreamingStatistics
from schuler.exceptions import ScenarioError
from schuler.io import atomic_path
from schuler.results import Result
from schuler.study.plan import SweepPlan
from schuler.study.store import _text_columns, chunk_path, column_name


@dataclass
class SweepSummary(Result):
    """What a sweep did and the statistics of each result over all cases.

    ``statistics`` maps each result column to count (finite values), nan_count,
    mean, std, min, max, p05, p50, p95 (percentiles exact up to 100,000 cases,
    from a uniform sample beyond).
    """

    system: str
    cases: int
    chunks: int
    chunks_computed: int
    chunks_resumed: int
    executor: str
    seconds: float
    cases_per_second: float
    out_dir: str
    statistics: dict[str, dict[str, float]]
    per_value: dict[str, dict]
    files: list[str]
    seconds_total: float = 0.0
    display_units: dict[str, str] = field(default_factory=dict, repr=False)

    units: ClassVar[dict[str, str]] = {"seconds": "s", "seconds_total": "s", "cases_per_second": "1/s",
                                       "cases": "1", "chunks": "1", "chunks_computed": "1", "chunks_resumed": "1",
                                       "count": "1", "nan_count": "1"}

    def render(self):
        from rich.console import Group
        from rich.table import Table

        from schuler.results import display_label
        from schuler.units import to_unit

        def shown(name, value):
            unit = self.display_units.get(name, "")
            if value is None or (isinstance(value, float) and not np.isfinite(value)):
                return "-"
            return f"{float(to_unit(value, unit)) if unit else value:.4g}"

        varying = [name for name, stats in self.statistics.items() if stats["min"] != stats["max"]]
        constant = [name for name in self.statistics if name not in varying]
        missing = {name: stats["nan_count"] for name, stats in self.statistics.items() if stats["nan_count"]}
        caption = (f"{self.chunks} chunks ({self.chunks_computed} computed, {self.chunks_resumed} resumed) on "
                   f"{self.executor}: {self.seconds_total:.3g} s in all ({self.seconds:.3g} s evaluating); "
                   f"results in {self.out_dir}" + (f"; not finite: {missing}" if missing else "")
                   + (f"; the same in every case: {', '.join(constant)}" if constant else ""))
        parts = []
        for axis, by_output in self.per_value.items():
            table = Table(title=f"{self.system} sweep: mean of each result per {axis}")
            table.add_column(axis, justify="right")
            names = [name for name in varying if name in by_output][:6]
            for name in names:
                table.add_column(display_label(name, self.display_units.get(name, "")), justify="right")
            values = by_output["_values"]
            for i, value in enumerate(values):
                cells = []
                for name in names:
                    mean, std = by_output[name]["mean"][i], by_output[name]["std"][i]
                    text = shown(name, mean)
                    if std is not None and np.isfinite(std) and std > 0:
                        text += f" ± {shown(name, std)}"
                    cells.append(text)
                table.add_row(str(value), *cells)
            parts.append(table)
        overall = Table(title=f"{self.system} sweep: {self.cases} cases, all together", caption=caption)
        overall.add_column("result", no_wrap=True)
        for heading in ("mean", "std", "min", "max"):
            overall.add_column(heading, justify="right", no_wrap=True)
        for name in varying:
            stats = self.statistics[name]
            overall.add_row(display_label(name, self.display_units.get(name, "")),
                            *(shown(name, stats[k]) for k in ("mean", "std", "min", "max")))
        parts.append(overall)
        return Group(*parts)


_RESERVOIR = 100_000


class _Accumulator:
    """Streaming statistics of the result columns, overall and per grid value."""

    def __init__(self, plan: SweepPlan, names: list[str]):
        self.plan = plan
        self.names = names
        self.overall = {name: StreamingStatistics((1,), reservoir_size=_RESERVOIR) for name in names}
        self.nan_count = dict.fromkeys(names, 0)
        size = {axis.name: len(axis.values) for axis in plan.axes}
        self.by_axis = {
            (axis, name): {
                "count": np.zeros(size[axis]),
                "sum": np.zeros(size[axis]),
                "sumsq": np.zeros(size[axis]),
                "min": np.full(size[axis], np.inf),
                "max": np.full(size[axis], -np.inf),
            }
            for axis in size
            for name in names
        }

    def update(self, table) -> None:
        """Add one chunk (an Arrow table)."""
        cases = table.column("case").to_numpy()
        index = dict(zip((a.name for a in self.plan.axes), self.plan.grid_index(cases)))
        for name in self.names:
            values = table.column(name).to_numpy().astype(float)
            finite = np.isfinite(values)
            self.nan_count[name] += int((~finite).sum())
            kept = values[finite]
            self.overall[name].update(kept[:, None])
            for axis, position in index.items():
                slot = self.by_axis[(axis, name)]
                where = position[finite]
                slot["count"] += np.bincount(where, minlength=slot["count"].size)
                slot["sum"] += np.bincount(where, weights=kept, minlength=slot["sum"].size)
                slot["sumsq"] += np.bincount(where, weights=kept**2, minlength=slot["sumsq"].size)
                np.minimum.at(slot["min"], where, kept)
                np.maximum.at(slot["max"], where, kept)

    def statistics(self) -> dict[str, dict[str, float | None]]:
        summary = {}
        for name, stats in self.overall.items():
            empty = stats.count == 0
            entry: dict[str, float | None] = {"count": int(stats.count), "nan_count": self.nan_count[name]}
            for key, value in (("mean", stats.mean), ("std", stats.std), ("min", stats.min), ("max", stats.max)):
                entry[key] = None if empty else float(value[0])
            for q in (5, 50, 95):
                entry[f"p{q:02d}"] = None if empty else float(stats.percentile(q)[0])
            summary[name] = entry
        return summary

    def per_axis(self) -> dict[tuple[str, str], dict[str, np.ndarray]]:
        """Count, mean, std, min and max of each result at each value of each axis (NaN where no case)."""
        out = {}
        for key, slot in self.by_axis.items():
            count = slot["count"]
            with np.errstate(invalid="ignore", divide="ignore"):
                mean = np.where(count > 0, slot["sum"] / np.maximum(count, 1), np.nan)
                # the sample variance from sums: enough for a summary (the exact values are in results.parquet)
                variance = (slot["sumsq"] - count * mean**2) / np.maximum(count - 1, 1)
            seen = count > 0
            out[key] = {
                "count": count.astype(np.int64),
                "mean": mean,
                "std": np.where(count > 1, np.sqrt(np.maximum(variance, 0.0)), np.nan),
                "min": np.where(seen, slot["min"], np.nan),
                "max": np.where(seen, slot["max"], np.nan),
            }
        return out


def _result_columns(schema, plan: SweepPlan) -> list[str]:
    """The numeric result columns of a chunk's Arrow schema (not the case number or parameters)."""
    import pyarrow as pa

    parameter_columns = {"case", *(column_name(spec) for spec in plan.parameters)}
    return [
        f.name
        for f in schema
        if f.name not in parameter_columns and (pa.types.is_integer(f.type) or pa.types.is_floating(f.type))
    ]


def gather(plan: SweepPlan, out_dir: Path, *, write_csv: bool = True) -> tuple[dict, dict, list[Path]]:
    """Stream the chunk files into results.parquet (and results.csv); accumulate statistics.

    One chunk is in memory at a time. Returns the statistics per result, the
    per-axis means and extremes, and the files written.

    Parameters
    ----------
    plan : SweepPlan
        The sweep's plan (number of chunks, axes, parameters).
    out_dir : Path
        The sweep's folder holding the chunk files; the results files are written there.
    write_csv : bool
        Whether to write ``results.csv`` beside ``results.parquet``.

    Returns
    -------
    statistics : dict of str to dict
        Result name -> ``count`` and ``nan_count`` (cases, number of), ``mean``, ``std``, ``min``, ``max``,
        ``p05``, ``p50``, ``p95`` over the finite values, in the result's SI unit (None when none is finite).
    per_axis : dict of (str, str) to dict of str to numpy.ndarray
        (axis name, result name) -> ``count``, ``mean``, ``std``, ``min``, ``max`` at each value of the axis
        (SI; NaN where no case is finite).
    files : list of Path
        The results files written.

    Raises
    ------
    ScenarioError
        The sweep has no chunk to gather.
    """
    import pyarrow.csv as pa_csv
    import pyarrow.parquet as pq

    out_dir = Path(out_dir)
    targets = [out_dir / "results.parquet"] + ([out_dir / "results.csv"] if write_csv else [])
    accumulator = None
    with contextlib.ExitStack() as stack:
        parquet_tmp = stack.enter_context(atomic_path(targets[0]))
        csv_tmp = stack.enter_context(atomic_path(targets[1])) if write_csv else None
        csv_writer = None
        writer = None
        for index in range(plan.chunks):
            table = pq.read_table(chunk_path(out_dir, index))
            if writer is None:
                writer = stack.enter_context(
                    pq.ParquetWriter(parquet_tmp, table.schema, use_dictionary=_text_columns(table.schema))
                )
            else:
                table = table.cast(writer.schema)
            writer.write_table(table)
            if accumulator is None:
                accumulator = _Accumulator(plan, _result_columns(table.schema, plan))
            accumulator.update(table)
            if csv_tmp is not None:
                if csv_writer is None:
                    options = pa_csv.WriteOptions(quoting_style="needed")
                    csv_writer = stack.enter_context(
                        pa_csv.CSVWriter(str(csv_tmp), writer.schema, write_options=options)
                    )
                csv_writer.write_table(table)
        if accumulator is None:  # raised inside, so that no empty results file is left behind
            raise ScenarioError(f"{out_dir}: the sweep has no cases to gather")
    return accumulator.statistics(), accumulator.per_axis(), targets


HISTOGRAM_BINS = 40


def histograms(plan: SweepPlan, out_dir: Path, statistics: dict) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Exact histograms (counts, bin edges) of the finite values of each result.

    A second streamed pass over the chunk files, reading only the result
    columns, with bins spanning each result's minimum to maximum.

    Parameters
    ----------
    plan : SweepPlan
        The sweep's plan (number of chunks).
    out_dir : Path
        The sweep's folder holding the chunk files.
    statistics : dict of str to dict
        Result name -> its ``count``, ``min`` and ``max`` (SI), as :func:`gather` returns them.

    Returns
    -------
    dict of str to (numpy.ndarray, numpy.ndarray)
        Result name -> (counts, cases per bin; the :data:`HISTOGRAM_BINS` + 1 bin edges, SI), only for the
        results whose values vary.
    """
    import pyarrow.parquet as pq

    edges = {
        name: np.linspace(stats["min"], stats["max"], HISTOGRAM_BINS + 1)
        for name, stats in statistics.items()
        if stats["count"] and stats["max"] > stats["min"]
    }
    counts = {name: np.zeros(HISTOGRAM_BINS, dtype=np.int64) for name in edges}
    if not edges:
        return {}
    for index in range(plan.chunks):
        table = pq.read_table(chunk_path(out_dir, index), columns=list(edges))
        for name, bins in edges.items():
            values = table.column(name).to_numpy().astype(float)
            counts[name] += np.histogram(values[np.isfinite(values)], bins=bins)[0]
    return {name: (counts[name], edges[name]) for name in edges}


