"""What a sweep found: statistics of every result (overall and per swept value), streamed from the chunk files.

One chunk is in memory at a time: :func:`gather` streams the chunk files into
``results.parquet`` (and ``results.csv``) while accumulating count, mean,
standard deviation, extremes and percentiles (from a uniform sample of 100,000
cases), and means per value of each swept parameter; :func:`histograms` is a
second streamed pass.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass
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
    files: list[str]

    units: ClassVar[dict[str, str]] = {"seconds": "s", "cases_per_second": "1/s"}

    def render(self):
        from rich.table import Table

        missing = {name: stats["nan_count"] for name, stats in self.statistics.items() if stats["nan_count"]}
        table = Table(
            title=f"{self.system} sweep: {self.cases} cases",
            caption=f"{self.chunks} chunks ({self.chunks_computed} computed, {self.chunks_resumed} resumed) "
            f"on {self.executor} in {self.seconds:.3g} s; results in {self.out_dir}"
            + (f"; not finite: {missing}" if missing else ""),
        )
        table.add_column("result", no_wrap=True)
        for heading in ("mean", "std", "min", "max"):
            table.add_column(heading, justify="right", no_wrap=True)
        for name, stats in self.statistics.items():
            table.add_row(
                name, *(f"{stats[k]:.4g}" if stats[k] is not None else "-" for k in ("mean", "std", "min", "max"))
            )
        return table


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
        """Mean, min and max of each result at each value of each axis (NaN where no case)."""
        out = {}
        for key, slot in self.by_axis.items():
            with np.errstate(invalid="ignore", divide="ignore"):
                mean = np.where(slot["count"] > 0, slot["sum"] / np.maximum(slot["count"], 1), np.nan)
            seen = slot["count"] > 0
            out[key] = {
                "mean": mean,
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


