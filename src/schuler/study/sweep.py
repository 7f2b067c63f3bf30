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
Ctrl-C or SIGTERM stops a sweep at once: the worker processes of a local pool
are terminated (they ignore SIGINT themselves), and the KeyboardInterrupt says
how many chunks are kept.
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

import time
import warnings
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np

from schuler.io import remove_stale_parts, signals_deferred, write_json
from schuler.memory import format_bytes, format_seconds
from schuler.results import json_safe
from schuler.study.executors import InProcess, make_executor
from schuler.study.plan import DEFAULT_CHUNK_SIZE, SweepPlan, plan_sweep
from schuler.study.scenario import Scenario
from schuler.study.store import ChunkTask, _prepare, _write_chunk, chunk_path, evaluate_chunk
from schuler.study.summary import SweepSummary, gather, histograms

__all__ = ["DEFAULT_CHUNK_SIZE", "run_sweep"]


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
    fidelity: str | None = None,
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
        Random draws per grid point, number of, at least 1 (default: the scenario's ``[monte_carlo] cases``;
        neither: no Monte Carlo).
    chunk_size : int
        Cases per chunk, number of, at least 1 (one vectorised evaluation, one file).
    scheduler : str, optional
        ``"local"`` (start a Dask LocalCluster) or a Dask scheduler address.
    workers : int, optional
        Processes of a local pool (without ``scheduler``), or of the LocalCluster, number of, at least 1.
    progress : bool
        Show a progress bar on stderr.
    write_csv, plots : bool
        Also write results.csv / the summary plots.
    on_chunk : callable, optional
        Called with each chunk index once its file is stored.
    fidelity : str, optional
        The system's evaluation fidelity (``--fidelity``).

    Returns
    -------
    SweepSummary
        Cases and chunks (computed, resumed), timings in s, the statistics of every result (SI) overall and
        per swept value, and the files written.

    Raises
    ------
    ScenarioError
        A malformed plan (see :func:`~schuler.study.plan.plan_sweep`), ``out_dir`` holding a different
        sweep, or a case the system refuses.
    """
    from schuler.study.plots import plot_sweep_summary

    system = scenario.definition()
    plan = plan_sweep(scenario, system, params, monte_carlo, chunk_size, fidelity)
    out_dir = Path(out_dir)
    _prepare(out_dir, plan)
    remove_stale_parts(out_dir)  # what an interrupted run was writing (a resumed run starts those files anew)
    done = {i for i in range(plan.chunks) if chunk_path(out_dir, i).exists()}
    todo = [i for i in range(plan.chunks) if i not in done]
    tasks = (ChunkTask(plan, index, system.evaluate) for index in todo)
    started = began = time.perf_counter()
    caught: dict = {}
    # a pool cannot share out a single chunk: its start-up would be pure cost
    executor = make_executor(scheduler, workers) if len(todo) > 1 or (todo and scheduler) else InProcess()
    stored = len(done)
    try:
        try:
            with _progress_bar(plan, done, enabled=progress) as advance:
                for result in executor.map(evaluate_chunk, tasks):
                    _write_chunk(result, out_dir)
                    stored += 1
                    caught.update(dict.fromkeys(result.warnings))
                    advance(result.cases)
                    if on_chunk is not None:
                        on_chunk(result.index)
        except BaseException:
            # the chunks in flight are lost anyway: stop the workers now rather than after their chunks;
            # a second Ctrl-C while they are terminated must not leave them running
            with signals_deferred(deliver=False):
                executor.close(abort=True)
            raise
        executor.close()
        _report_warnings(caught)
        seconds = time.perf_counter() - began
        if write_csv:
            _warn_about_csv_size(plan, system)
        statistics, per_axis, files = gather(plan, out_dir, write_csv=write_csv)
        per_value = _per_value(plan, per_axis)
        files.append(write_json(out_dir / "summary.json", json_safe(
            {"manifest": plan.manifest(), "statistics": statistics, "per_value": per_value})))
        display = {output.name: output.display for output in system.outputs if output.display}
        if plots:
            files.extend(plot_sweep_summary(plan, statistics, per_axis, histograms(plan, out_dir, statistics),
                                            out_dir, display))
    except KeyboardInterrupt:
        raise KeyboardInterrupt(f"{stored} of {plan.chunks} chunks are kept in {out_dir}, "
                                "from which the same command resumes") from None
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
        per_value=per_value,
        files=[str(f) for f in files],
        seconds_total=time.perf_counter() - started,
        display_units=display,
    )


CSV_WARNING_BYTES = 2**30
"""A results.csv expected to be larger than this gets a warning (``--no-csv`` skips it)."""


def _warn_about_csv_size(plan: SweepPlan, system) -> None:
    # about 12 bytes per number in CSV: the case, every parameter and every output
    estimate = plan.total * (1 + len(plan.parameters) + len(system.outputs)) * 12
    if estimate > CSV_WARNING_BYTES:
        warnings.warn(f"results.csv will be about {format_bytes(estimate)}; add --no-csv to write results.parquet "
                      "only", UserWarning, stacklevel=3)


def _per_value(plan: SweepPlan, per_axis: dict) -> dict[str, dict]:
    """Per swept parameter: its values (display unit) and each result's count, mean, std, min, max per value."""
    from schuler.units import to_unit

    table: dict[str, dict] = {}
    for axis in plan.axes:
        spec = next(p for p in plan.parameters if p.name == axis.name)
        values = axis.values
        if spec.kind == "quantity" and spec.unit:
            values = to_unit(np.asarray(values, dtype=float), spec.unit)
        label = f"{axis.name} ({spec.unit})" if spec.kind == "quantity" and spec.unit else axis.name
        entry: dict = {"_values": [float(f"{v:.10g}") if isinstance(v, (float, np.floating)) else
                                   v.item() if isinstance(v, np.generic) else v for v in values]}
        for (name, output), stats in per_axis.items():
            if name == axis.name:
                entry[output] = {key: np.asarray(value).tolist() for key, value in stats.items()}
        table[label] = entry
    return table


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
            TextColumn(f"{self.plan.system} sweep" + (f" (estimate {format_seconds(self.plan.estimated_seconds)})"
                                                      if self.plan.estimated_seconds else "")),
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
