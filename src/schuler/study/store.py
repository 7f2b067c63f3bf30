"""A sweep on disk: chunk files written as they finish, the plan's manifest, the evaluation of one chunk.

``DIR/chunks/chunk-NNNNNN.parquet`` holds one finished chunk (written
atomically, so an interrupted sweep loses only the chunks in flight);
``DIR/sweep.json`` records the plan, and a different plan is refused there.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from schuler import __version__
from schuler.exceptions import ScenarioError, SchulerError
from schuler.io import atomic_path, write_json
from schuler.params import Parameter
from schuler.study.plan import SweepPlan
from schuler.units import to_unit


def column_name(spec: Parameter) -> str:
    """Results column of a parameter: its name and display unit (``drift_east_deg_per_h``).

    Parameters
    ----------
    spec : Parameter
        The parameter (a quantity's column holds its values in the display unit ``spec.unit``).

    Returns
    -------
    str
        The name, with ``_UNIT`` appended for a quantity with a unit (``/`` written ``_per_``, ``.`` as ``p``).

    Examples
    --------
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
    evaluate: Callable[..., Mapping[str, np.ndarray]]


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

    Parameters
    ----------
    task : ChunkTask
        The plan, the chunk's index and the system's vectorised ``evaluate``.

    Returns
    -------
    ChunkResult
        The chunk's index, its cases (number of), the table as Parquet bytes (parameters in their display
        units, each column named by :func:`column_name`; results as ``evaluate`` returns them, SI) and the
        warnings raised.

    Raises
    ------
    ScenarioError
        The system refused some case of the chunk (naming the chunk's cases), or a result does not have one
        value per case.
    """
    import pandas as pd

    start, stop = task.plan.chunk_range(task.index)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            cases = task.plan.cases(start, stop)
            results = task.evaluate(cases)
    except SchulerError as error:
        raise ScenarioError(f"cases {start}..{stop - 1}: {error}") from None
    columns: dict[str, np.ndarray] = {"case": np.arange(start, stop, dtype=np.int64)}
    for spec in task.plan.parameters:
        shown = cases[spec.name]
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


def chunk_path(out_dir: Path, index: int) -> Path:
    """Where chunk ``index`` of a sweep is stored.

    Parameters
    ----------
    out_dir : Path
        The sweep's folder.
    index : int
        Chunk index, 0 to ``plan.chunks - 1``.

    Returns
    -------
    Path
        ``out_dir/chunks/chunk-NNNNNN.parquet`` (index written with six digits).
    """
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
                f"`out` {out_dir}: holds a different sweep (see its sweep.json); "
                "choose another folder or delete this one"
            )
        return
    (out_dir / "chunks").mkdir(parents=True, exist_ok=True)
    write_json(manifest_path, {"schuler_version": __version__, **manifest})


