"""Parameter sweeps and Monte Carlo studies over a scenario, resumable and scalable.

A sweep takes a scenario and varies some of its parameters:

* a **grid**: ``NAME=START:STOP:STEP`` (STOP included when it falls on the grid,
  to within 1e-9 of a step) or ``NAME=V1,V2,...``; several grids give their
  cartesian product;
* a **Monte Carlo**: N random draws per grid point of the parameters listed in
  the scenario's ``[monte_carlo.normal]`` / ``[monte_carlo.uniform]`` tables.

The cases are numbered ``0 .. n-1`` (grid point major, draw minor) and cut into
chunks of ``chunk_size`` consecutive cases. Each chunk is evaluated at once by
the system's vectorised ``System.sweep`` (or, for a system without one, by
calling ``System.run`` case by case) on an executor: in-process (default), a
pool of local processes, or a Dask cluster (a LocalCluster started here, or an
existing scheduler at ``tcp://HOST:PORT``).

The workers of an existing Dask cluster need the same version of schuler
installed; the chunk files are written by the client, on its own disk.

**Resumable.** The client writes each finished chunk atomically to
``DIR/chunks/chunk-NNNNNN.parquet`` as soon as it arrives, so an interrupted
sweep, or a Dask worker that dies, loses only chunks still being computed;
re-running the same sweep into the same folder skips every chunk on disk.
``DIR/sweep.json`` records the plan, and a different plan is refused there.

**Reproducible.** Random draws depend only on the seed, the parameter name and
the case number (a counter-based generator, SplitMix64), never on chunking,
executor or order of completion: every executor gives identical results.

**Bounded memory.** Only a few chunks are in flight at once; the gathering step
streams the chunk files one at a time into ``DIR/results.parquet`` and
``DIR/results.csv`` (both written chunk by chunk, so a 10^7-case sweep needs
disk, not memory: about 10 bytes per value in CSV, 3.5 GB for 10^7 cases of
the 36-column gyrocompassing sweep, whose peak memory stayed under 400 MB) and
accumulates statistics (count, mean, standard deviation, extremes,
percentiles from a uniform sample of 100,000 cases, means per grid value;
histograms in a second pass) for ``DIR/summary.json`` and the summary plots.
``--no-csv`` skips the CSV for very large sweeps.
"""

from __future__ import annotations

import contextlib
import json
import math
import re
import time
import warnings
import zlib
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from schuler import __version__
from schuler.core.stats import StreamingStatistics
from schuler.exceptions import InvalidParameter, ScenarioError, SchulerError
from schuler.io import atomic_path, write_json
from schuler.params import Parameter
from schuler.registry import System
from schuler.results import Result, json_safe
from schuler.study.scenario import Distribution, Scenario
from schuler.units import parse_quantity, to_unit

DEFAULT_CHUNK_SIZE = 50_000
"""Cases per chunk: large enough to vectorise well, small enough to resume cheaply."""

MAX_CASES = 10**9
"""A sweep larger than this is almost certainly a typo in a step."""

_GRID_TOLERANCE = 1e-9
"""Relative tolerance (in steps) within which STOP counts as a grid point."""


# --------------------------------------------------------------------- the plan
@dataclass(frozen=True)
class Axis:
    """One swept parameter: its values (SI, or choices) and how it was written."""

    name: str
    values: np.ndarray
    written: str


@dataclass(frozen=True)
class SweepPlan:
    """Every case of a sweep, described compactly (no per-case arrays).

    Attributes
    ----------
    system : str
    parameters : tuple of Parameter
        The system's parameters, in order.
    base : dict
        The scenario's SI values (defaults filled in).
    axes : tuple of Axis
        Grid axes, outermost first.
    draws : int
        Monte Carlo draws per grid point (1 without Monte Carlo).
    distributions : dict
        Random parameters (name -> Distribution); empty without Monte Carlo.
    seed : int
    chunk_size : int
    """

    system: str
    parameters: tuple[Parameter, ...]
    base: dict[str, Any]
    axes: tuple[Axis, ...] = ()
    draws: int = 1
    distributions: dict[str, Distribution] = field(default_factory=dict)
    seed: int = 0
    chunk_size: int = DEFAULT_CHUNK_SIZE

    @property
    def grid_shape(self) -> tuple[int, ...]:
        return tuple(len(axis.values) for axis in self.axes)

    @property
    def total(self) -> int:
        """Number of cases."""
        return math.prod(self.grid_shape) * self.draws

    @property
    def chunks(self) -> int:
        return -(-self.total // self.chunk_size)

    def chunk_range(self, index: int) -> tuple[int, int]:
        """First case and one past the last case of chunk ``index``."""
        start = index * self.chunk_size
        return start, min(start + self.chunk_size, self.total)

    def grid_index(self, cases: np.ndarray) -> tuple[np.ndarray, ...]:
        """Index along each axis of the given case numbers."""
        if not self.axes:
            return ()
        return np.unravel_index(cases // self.draws, self.grid_shape)

    def case_values(self, start: int, stop: int) -> dict[str, np.ndarray]:
        """Every parameter of cases ``start .. stop-1``, as arrays (SI)."""
        cases = np.arange(start, stop, dtype=np.int64)
        n = cases.size
        index = dict(zip((axis.name for axis in self.axes), self.grid_index(cases)))
        swept = {axis.name: axis for axis in self.axes}
        values = {}
        for spec in self.parameters:
            if spec.name in swept:
                values[spec.name] = swept[spec.name].values[index[spec.name]]
            elif spec.name in self.distributions:
                values[spec.name] = self._draw(spec, cases)
            else:
                values[spec.name] = _constant(spec, self.base[spec.name], n)
        return values

    def _draw(self, spec: Parameter, cases: np.ndarray) -> np.ndarray:
        from scipy.special import ndtri

        distribution = self.distributions[spec.name]
        u = uniform_stream(self.seed, spec.name, cases)
        if distribution.kind == "normal":
            drawn = self.base[spec.name] + distribution.first * ndtri(u)
        else:
            drawn = distribution.first + (distribution.second - distribution.first) * u
        if spec.kind == "integer":
            drawn = np.rint(drawn).astype(np.int64)
        _check_draws(spec, drawn, distribution.kind)
        return drawn

    def manifest(self) -> dict:
        """What identifies this sweep (stored in ``sweep.json``, compared on resume)."""
        return json_safe(
            {
                "system": self.system,
                "base": {k: _plain(v) for k, v in self.base.items()},
                "axes": [{"name": a.name, "written": a.written, "points": len(a.values)} for a in self.axes],
                "draws": self.draws,
                "distributions": {
                    name: {"kind": d.kind, "parameters_si": [d.first, d.second]}
                    for name, d in sorted(self.distributions.items())
                },
                "seed": self.seed,
                "chunk_size": self.chunk_size,
                "cases": self.total,
            }
        )


def _plain(value):
    return value.item() if isinstance(value, np.generic) else value


def _constant(spec: Parameter, value, n: int) -> np.ndarray:
    """``n`` copies of a parameter's value.

    A value left unset (None) is NaN for a number and None (in an object
    array) for a text or choice, so that ``System.sweep`` applies its default.
    """
    if value is None:
        return np.full(n, np.nan) if spec.kind in ("quantity", "integer") else np.full(n, None, dtype=object)
    return np.full(n, value)


def _check_draws(spec: Parameter, drawn: np.ndarray, kind: str) -> None:
    shown = to_unit(drawn, spec.unit) if spec.kind == "quantity" else drawn
    low = shown.min()
    high = shown.max()
    too_low = spec.minimum is not None and (low < spec.minimum or (spec.exclusive_minimum and low <= spec.minimum))
    too_high = spec.maximum is not None and (high > spec.maximum or (spec.exclusive_maximum and high >= spec.maximum))
    if too_low or too_high:
        bad = low if too_low else high
        unit = f" {spec.unit}" if spec.kind == "quantity" and spec.unit else ""
        raise ScenarioError(
            f"[monte_carlo.{kind}] {spec.name}: a draw of {bad:g}{unit} is outside {spec.range_text()}; "
            "narrow the distribution"
        )


# SplitMix64 (Steele, Lea and Flood 2014): a counter-based generator, so case i
# gets the same numbers however the cases are chunked or scheduled.
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)


def _mix(z: np.ndarray) -> np.ndarray:
    z = (z ^ (z >> np.uint64(30))) * _MIX1
    z = (z ^ (z >> np.uint64(27))) * _MIX2
    return z ^ (z >> np.uint64(31))


def uniform_stream(seed: int, name: str, cases: np.ndarray) -> np.ndarray:
    """Uniform numbers in (0, 1), one per case, from ``seed`` and a parameter ``name``.

    The number of case ``i`` depends only on ``(seed, name, i)``.

    >>> a = uniform_stream(1, "drift_east", np.arange(10))
    >>> b = uniform_stream(1, "drift_east", np.arange(5, 10))
    >>> bool(np.array_equal(a[5:], b)), bool(((a > 0) & (a < 1)).all())
    (True, True)
    """
    # integer array arithmetic wraps modulo 2^64 silently, as SplitMix64 needs
    key = _mix(np.array([seed % 2**64], dtype=np.uint64) ^ np.array([zlib.crc32(name.encode())], dtype=np.uint64))
    state = key + (np.asarray(cases, dtype=np.uint64) + np.uint64(1)) * _GOLDEN
    return ((_mix(state) >> np.uint64(11)).astype(float) + 0.5) * 2.0**-53


# ------------------------------------------------------------------- grid specs
def grid_values(start: float, stop: float, step: float) -> np.ndarray:
    """``start, start+step, ...`` up to ``stop``, including ``stop`` when it is on the grid.

    "On the grid" allows a rounding error of 1e-9 step (plus the rounding of
    ``start`` and ``stop`` themselves), so ``0:1:0.1`` has 11 points whose
    last is exactly 1.

    >>> float(grid_values(0.0, 1.0, 0.1)[-1]), len(grid_values(0.0, 1.0, 0.1))
    (1.0, 11)
    >>> grid_values(0.0, 1.0, 0.3).tolist()
    [0.0, 0.3, 0.6, 0.8999999999999999]
    >>> grid_values(10.0, 0.0, -5.0).tolist()
    [10.0, 5.0, 0.0]
    """
    if step == 0 or not all(map(math.isfinite, (start, stop, step))):
        raise ValueError("the step must be a finite non-zero number")
    intervals = (stop - start) / step
    if intervals < -_GRID_TOLERANCE:
        raise ValueError("the step goes away from the stop value")
    nearest = round(intervals)
    # start and stop themselves carry a rounding error of about eps * |value|
    rounding = 4 * np.finfo(float).eps * max(abs(start), abs(stop)) / abs(step)
    on_grid = abs(intervals - nearest) <= _GRID_TOLERANCE * max(1.0, abs(intervals)) + rounding
    count = (nearest if on_grid else math.floor(intervals)) + 1
    if count > MAX_CASES:
        raise ValueError(f"{count} points is more than {MAX_CASES}")
    values = start + step * np.arange(count)
    if on_grid:
        values[-1] = stop
    return values


_NUMBER_AND_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S.*)$")


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def parse_axis(text: str, parameters: Sequence[Parameter]) -> Axis:
    """Read ``NAME=START:STOP:STEP`` or ``NAME=V1,V2,...`` (values as on the command line).

    A unit written only after the step applies to all three numbers:
    ``drift_east=0.001:0.01:0.001 deg/h``.

    Raises
    ------
    ScenarioError
        Unknown parameter, malformed range, or a value outside its allowed range.
    """
    by_name = {spec.name: spec for spec in parameters}
    name, equals, spec_text = text.partition("=")
    name = name.strip().replace("-", "_")
    if not equals or not spec_text.strip():
        raise ScenarioError(f"--param {text!r}: expected NAME=START:STOP:STEP or NAME=V1,V2,...")
    if name not in by_name:
        raise ScenarioError(f"--param {name}: unknown parameter; allowed: {', '.join(by_name)}")
    spec = by_name[name]
    label = f"--param {name}"
    try:
        if ":" in spec_text:
            values = _range_values(spec, spec_text, label)
        else:
            values = np.array([spec.parse(part.strip(), label) for part in spec_text.split(",")])
    except InvalidParameter as error:
        raise ScenarioError(str(error)) from None
    return Axis(name, values, spec_text.strip())


def _range_values(spec: Parameter, text: str, label: str) -> np.ndarray:
    if spec.kind not in ("quantity", "integer"):
        raise InvalidParameter(label, f"{text!r}: a {spec.kind} parameter takes a list V1,V2,... not a range")
    parts = [part.strip() for part in text.split(":")]
    if len(parts) != 3:
        raise InvalidParameter(label, f"{text!r} is not START:STOP:STEP")
    match = _NUMBER_AND_UNIT.match(parts[2])
    if _is_number(parts[0]) and _is_number(parts[1]) and match and not _is_number(parts[2]):
        parts = [f"{parts[0]} {match[2]}", f"{parts[1]} {match[2]}", parts[2]]
    if spec.kind == "integer":
        try:
            start, stop, step = (int(part) for part in parts)
        except ValueError:
            raise InvalidParameter(label, f"{text!r} is not three whole numbers") from None
    else:
        start, stop, step = (parse_quantity(part, spec.unit, name=label) for part in parts)
    try:
        values = grid_values(start, stop, step)
    except ValueError as error:
        raise InvalidParameter(label, f"{text!r}: {error}") from None
    if spec.kind == "integer":
        values = np.rint(values).astype(np.int64)
        ends = (int(values[0]), int(values[-1]))
    else:
        ends = (float(to_unit(values[0], spec.unit)), float(to_unit(values[-1], spec.unit)))
    for end in ends:
        spec.parse(end, label)
    return values


def plan_sweep(
    scenario: Scenario,
    system: System,
    params: Iterable[str] = (),
    monte_carlo: int | None = None,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
) -> SweepPlan:
    """Build the plan of a sweep: grid axes from ``params``, Monte Carlo from the scenario.

    Parameters
    ----------
    scenario : Scenario
    system : System
    params : iterable of str
        ``NAME=START:STOP:STEP`` or ``NAME=V1,V2,...`` texts.
    monte_carlo : int, optional
        Draws per grid point; defaults to ``[monte_carlo] cases`` of the scenario
        (no Monte Carlo when neither is given).
    chunk_size : int
        Cases per chunk.
    """
    axes = tuple(parse_axis(text, system.parameters) for text in params)
    names = [axis.name for axis in axes]
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise ScenarioError(f"--param {repeated[0]}: given more than once")
    if chunk_size < 1:
        raise ScenarioError(f"--chunk-size: {chunk_size} must be at least 1")
    table = scenario.monte_carlo
    draws = monte_carlo if monte_carlo is not None else (table.cases if table and table.cases else None)
    distributions: dict[str, Distribution] = {}
    if draws is not None:
        if draws < 1:
            raise ScenarioError(f"--monte-carlo: {draws} must be at least 1")
        if table is None or not table.distributions:
            raise ScenarioError(
                "--monte-carlo: the scenario has no random parameters; "
                "add a [monte_carlo.normal] or [monte_carlo.uniform] table"
            )
        distributions = dict(table.distributions)
        clash = sorted(set(distributions) & set(names))
        if clash:
            raise ScenarioError(f"--param {clash[0]}: already random in the scenario's [monte_carlo] table")
    plan = SweepPlan(
        system=system.name,
        parameters=tuple(system.parameters),
        base=dict(scenario.values),
        axes=axes,
        draws=draws or 1,
        distributions=distributions,
        seed=table.seed if table else 0,
        chunk_size=int(chunk_size),
    )
    if plan.total > MAX_CASES:
        raise ScenarioError(f"the sweep has {plan.total} cases, more than {MAX_CASES}; check the steps")
    return plan


# ------------------------------------------------------------------- evaluation
@dataclass(frozen=True)
class RunLoop:
    """Evaluate cases one by one with ``System.run`` (for systems without ``sweep``).

    Keeps the numeric top-level entries of each result's ``to_dict()``.
    """

    run: Callable

    def __call__(self, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        n = len(next(iter(values.values())))
        rows = []
        for i in range(n):
            kwargs = {name: _scalar(array[i]) for name, array in values.items()}
            data = self.run(**kwargs).to_dict()
            rows.append({k: v for k, v in data.items() if isinstance(v, (int, float)) and not isinstance(v, bool)})
        names = list(rows[0]) if rows else []
        return {name: np.array([row.get(name, np.nan) for row in rows], dtype=float) for name in names}


def _scalar(value):
    value = value.item() if isinstance(value, np.generic) else value
    return None if isinstance(value, float) and math.isnan(value) else value


def column_name(spec: Parameter) -> str:
    """Results column of a parameter: its name and display unit (``drift_east_deg_per_h``).

    >>> column_name(Parameter("drift_east", "deg/h", 0.0, "Drift."))
    'drift_east_deg_per_h'
    """
    if spec.kind != "quantity" or not spec.unit:
        return spec.name
    unit = spec.unit.replace("**", "").replace("^", "").replace("/", "_per_").replace("*", "_").replace(" ", "")
    unit = unit.replace(".", "p")
    return f"{spec.name}_{unit}"


@dataclass(frozen=True)
class ChunkTask:
    """What a worker needs to evaluate one chunk (small: no per-case arrays)."""

    plan: SweepPlan
    index: int
    evaluate: Callable[[dict[str, np.ndarray]], dict[str, np.ndarray]]


@dataclass(frozen=True)
class ChunkResult:
    """A finished chunk: its Parquet file's bytes and the warnings raised meanwhile."""

    index: int
    cases: int
    parquet: bytes
    warnings: list[tuple[type, str]]


def evaluate_chunk(task: ChunkTask) -> ChunkResult:
    """Evaluate one chunk: a table with ``case``, one column per parameter and per result.

    The worker encodes the table as Parquet (compact to send, and the client
    only writes the bytes); the warnings raised meanwhile come back as
    (category, message) pairs so that the client reports each once.
    Errors a user can cause come back as a :class:`ScenarioError` naming the
    cases (it pickles across processes and Dask workers).
    """
    import pandas as pd

    start, stop = task.plan.chunk_range(task.index)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            values = task.plan.case_values(start, stop)
            results = task.evaluate(dict(values))
    except SchulerError as error:
        raise ScenarioError(f"cases {start}..{stop - 1}: {error}") from None
    columns: dict[str, np.ndarray] = {"case": np.arange(start, stop, dtype=np.int64)}
    for spec in task.plan.parameters:
        shown = values[spec.name]
        if spec.kind == "quantity":
            shown = to_unit(np.asarray(shown, dtype=float), spec.unit)
        columns[column_name(spec)] = shown
    for name, array in results.items():
        array = np.asarray(array)
        if array.shape != (stop - start,):
            raise ScenarioError(
                f"system {task.plan.system!r}: sweep output {name!r} has shape {array.shape}, "
                f"expected ({stop - start},)"
            )
        # a result named like a parameter column (e.g. the damping actually used) keeps both
        columns[f"{name}_result" if name in columns else name] = array
    data = _parquet_bytes(pd.DataFrame(columns))
    return ChunkResult(task.index, stop - start, data, [(w.category, str(w.message)) for w in caught])


# -------------------------------------------------------------------- executors
class InProcess:
    """Evaluate chunks one after another in this process (vectorised within each)."""

    name = "in-process"

    def map(self, function, tasks: Iterable) -> Iterator:
        for task in tasks:
            yield function(task)

    def close(self) -> None:
        """Nothing to release."""


class LocalProcesses:
    """A pool of local worker processes (spawned: safe beside threads)."""

    name = "processes"

    def __init__(self, workers: int):
        import multiprocessing

        self.workers = workers
        self.pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))

    def map(self, function, tasks: Iterable) -> Iterator:
        yield from _windowed(lambda task: self.pool.submit(function, task), tasks, 2 * self.workers, _wait_futures)

    def close(self) -> None:
        self.pool.shutdown(wait=True, cancel_futures=True)


class DaskCluster:
    """A Dask cluster: a LocalCluster started here (``"local"``) or an existing scheduler."""

    name = "dask"

    def __init__(self, scheduler: str, workers: int | None = None):
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise ScenarioError("--scheduler: Dask is not installed; install schuler[dask]") from None
        self.cluster = None
        if scheduler == "local":
            self.cluster = LocalCluster(
                n_workers=workers or 2,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",  # any free port: never clashes with another cluster
                silence_logs=50,
            )
            self.client = Client(self.cluster)
        elif scheduler.startswith(("tcp://", "tls://", "inproc://", "ws://", "wss://")):
            try:
                self.client = Client(scheduler, timeout="20s")
            except OSError as error:
                raise ScenarioError(f"--scheduler: cannot reach {scheduler}: {error}") from None
        else:
            raise ScenarioError(f"--scheduler: {scheduler!r} is neither 'local' nor an address like tcp://HOST:8786")

    def map(self, function, tasks: Iterable) -> Iterator:
        from distributed import as_completed

        threads = max(1, sum(self.client.nthreads().values()))
        completed = as_completed()

        def submit(task):
            future = self.client.submit(function, task, pure=False)
            completed.add(future)
            return future

        def next_done(pending):
            future = next(completed)
            pending.discard(future)
            result = future.result()
            future.release()
            return [result]

        yield from _windowed(submit, tasks, 2 * threads, next_done)

    def close(self) -> None:
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def _wait_futures(pending: set) -> list:
    done, _ = wait(pending, return_when=FIRST_COMPLETED)
    pending -= done
    return [future.result() for future in done]


def _windowed(submit, tasks: Iterable, window: int, next_done) -> Iterator:
    """Keep at most ``window`` tasks in flight; yield results as they complete."""
    pending: set = set()
    for task in tasks:
        pending.add(submit(task))
        if len(pending) >= window:
            yield from next_done(pending)
    while pending:
        yield from next_done(pending)


def make_executor(scheduler: str | None = None, workers: int | None = None):
    """In-process (default), local processes (``workers`` > 1) or Dask (``scheduler``)."""
    if workers is not None and workers < 1:
        raise ScenarioError(f"--workers: {workers} must be at least 1")
    if scheduler:
        return DaskCluster(scheduler, workers)
    if workers and workers > 1:
        return LocalProcesses(workers)
    return InProcess()


# ------------------------------------------------------------ storage on disk
def chunk_path(out_dir: Path, index: int) -> Path:
    return Path(out_dir) / "chunks" / f"chunk-{index:06d}.parquet"


def _text_columns(schema) -> list[str]:
    """Columns worth dictionary encoding in Parquet: the text ones (choices)."""
    import pyarrow as pa

    return [f.name for f in schema if pa.types.is_string(f.type) or pa.types.is_large_string(f.type)]


def _parquet_bytes(frame) -> bytes:
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pandas(frame, preserve_index=False)
    sink = pa.BufferOutputStream()
    # dictionary encoding of float columns costs five times the write time for no gain
    pq.write_table(table, sink, use_dictionary=_text_columns(table.schema))
    return sink.getvalue().to_pybytes()


def _write_chunk(result: ChunkResult, out_dir: Path) -> Path:
    path = chunk_path(out_dir, result.index)
    with atomic_path(path) as tmp:
        tmp.write_bytes(result.parquet)
    return path


def _prepare(out_dir: Path, plan: SweepPlan) -> None:
    """Create ``out_dir`` and its ``sweep.json``, or check that it holds this same sweep."""
    manifest_path = out_dir / "sweep.json"
    manifest = plan.manifest()
    if manifest_path.exists():
        stored = json.loads(manifest_path.read_text(encoding="utf-8"))
        stored.pop("schuler_version", None)
        if stored != manifest:
            raise ScenarioError(
                f"--out {out_dir}: holds a different sweep (see its sweep.json); "
                "choose another folder or delete this one"
            )
        return
    (out_dir / "chunks").mkdir(parents=True, exist_ok=True)
    write_json(manifest_path, {"schuler_version": __version__, **manifest})


# ---------------------------------------------------------------------- results
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

    def statistics(self) -> dict[str, dict[str, float]]:
        summary = {}
        for name, stats in self.overall.items():
            empty = stats.count == 0
            entry = {"count": int(stats.count), "nan_count": self.nan_count[name]}
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
                    csv_writer = stack.enter_context(pa_csv.CSVWriter(str(csv_tmp), writer.schema, write_options=options))
                csv_writer.write_table(table)
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


def run_sweep(
    scenario: Scenario,
    out_dir,
    params: Iterable[str] = (),
    monte_carlo: int | None = None,
    *,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: bool = True,
    write_csv: bool = True,
    plots: bool = True,
    on_chunk: Callable[[int], None] | None = None,
) -> SweepSummary:
    """Run (or resume) a sweep and write its results into ``out_dir``.

    Parameters
    ----------
    scenario : Scenario
        The base case; its ``[monte_carlo]`` table gives the random parameters.
    out_dir : path
        Folder for ``sweep.json``, ``chunks/``, ``results.parquet``,
        ``results.csv``, ``summary.json`` and the summary plots.
    params : iterable of str
        Grid axes ``NAME=START:STOP:STEP`` or ``NAME=V1,V2,...``.
    monte_carlo : int, optional
        Random draws per grid point.
    chunk_size : int
        Cases per chunk (one vectorised evaluation, one file).
    scheduler : str, optional
        ``"local"`` (start a Dask LocalCluster) or a Dask scheduler address.
    workers : int, optional
        Processes of a local pool (without ``scheduler``), or of the LocalCluster.
    progress : bool
        Show a progress bar on stderr.
    write_csv, plots : bool
        Also write results.csv / the summary plots.
    on_chunk : callable, optional
        Called with each chunk index once its file is stored.
    """
    from schuler.study.plots import plot_sweep_summary

    system = scenario.definition()
    plan = plan_sweep(scenario, system, params, monte_carlo, chunk_size)
    out_dir = Path(out_dir)
    _prepare(out_dir, plan)
    done = {i for i in range(plan.chunks) if chunk_path(out_dir, i).exists()}
    todo = [i for i in range(plan.chunks) if i not in done]
    evaluate = system.sweep if system.sweep is not None else RunLoop(system.run)
    tasks = (ChunkTask(plan, index, evaluate) for index in todo)
    began = time.perf_counter()
    caught: dict = {}
    executor = make_executor(scheduler, workers) if todo else InProcess()
    try:
        with _progress_bar(plan, done, enabled=progress) as advance:
            for result in executor.map(evaluate_chunk, tasks):
                _write_chunk(result, out_dir)
                caught.update(dict.fromkeys(result.warnings))
                advance(result.cases)
                if on_chunk is not None:
                    on_chunk(result.index)
    finally:
        executor.close()
        _report_warnings(caught)
    seconds = time.perf_counter() - began
    statistics, per_axis, files = gather(plan, out_dir, write_csv=write_csv)
    files.append(write_json(out_dir / "summary.json", json_safe({"manifest": plan.manifest(), "statistics": statistics})))
    if plots:
        files.extend(plot_sweep_summary(plan, statistics, per_axis, histograms(plan, out_dir, statistics), out_dir))
    computed_cases = sum(plan.chunk_range(i)[1] - plan.chunk_range(i)[0] for i in todo)
    return SweepSummary(
        system=plan.system,
        cases=plan.total,
        chunks=plan.chunks,
        chunks_computed=len(todo),
        chunks_resumed=len(done),
        executor=executor.name,
        seconds=seconds,
        cases_per_second=computed_cases / seconds if seconds > 0 and computed_cases else 0.0,
        out_dir=str(out_dir),
        statistics=statistics,
        files=[str(f) for f in files],
    )


_WARNINGS_SHOWN = 3


def _report_warnings(caught: dict) -> None:
    """Re-raise the distinct warnings of all chunks here, the first few of them."""
    distinct = list(caught)
    for category, message in distinct[:_WARNINGS_SHOWN]:
        warnings.warn(message, category, stacklevel=3)
    if len(distinct) > _WARNINGS_SHOWN:
        warnings.warn(f"... and {len(distinct) - _WARNINGS_SHOWN} more warnings like these", UserWarning, stacklevel=3)


class _progress_bar:
    """A rich progress bar over cases on stderr (a no-op when disabled)."""

    def __init__(self, plan: SweepPlan, done: set[int], enabled: bool):
        self.plan = plan
        self.resumed = sum(plan.chunk_range(i)[1] - plan.chunk_range(i)[0] for i in done)
        self.enabled = enabled
        self.progress = None

    def __enter__(self):
        if not self.enabled:
            return lambda n: None
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

        self.progress = Progress(
            TextColumn(f"{self.plan.system} sweep"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("cases"),
            TimeRemainingColumn(),
            console=Console(stderr=True),
        )
        self.progress.start()
        task = self.progress.add_task("sweep", total=self.plan.total, completed=self.resumed)
        return lambda n: self.progress.advance(task, n)

    def __exit__(self, *exc_info):
        if self.progress is not None:
            self.progress.stop()
        return False
