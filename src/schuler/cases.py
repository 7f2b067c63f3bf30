"""A batch of validated cases, one array per parameter: what a system's ``evaluate`` takes.

:class:`Cases` is the batch (SI arrays of one length, the member numbers that
address the random draws, the random streams and the fidelity);
:func:`default_arrays` fills a batch's parameters that were not given.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from schuler.core.random import RandomStreams
from schuler.core.stats import StreamingStatistics
from schuler.exceptions import InvalidParameter
from schuler.memory import require_time
from schuler.params import Case, ParameterSet
from schuler.results import MonteCarloSummary, Output

MONTE_CARLO_CHUNK = 2_000
"""Members evaluated at once in a Monte Carlo (unless the system sizes its chunks from its memory per member)."""

MONTE_CARLO_SAMPLES = 100_000
"""Members whose outputs a Monte Carlo summary keeps for histograms."""


class Cases:
    """A batch of validated cases: every parameter an array of length ``n`` (SI).

    Numbers are float arrays (NaN where a parameter is not set and its own rule
    applies, see :meth:`value_or`), integers int64 arrays, choices and text
    object arrays (None where not set), flags bool arrays.

    Attributes
    ----------
    members : ndarray of int64
        Global case or member numbers: the addresses of the random draws.
    random : RandomStreams or None
        Where random terms come from; None evaluates the nominal case (no noise).
    fidelity : str or None
        The system's evaluation fidelity (``"simulated"``, ``"closed"``) or None
        for its default.
    """

    def __init__(self, values: Mapping[str, Any], *, members=None, random: RandomStreams | None = None,
                 fidelity: str | None = None):
        arrays = {name: np.asarray(value) for name, value in values.items()}
        lengths = {a.shape[0] for a in arrays.values() if a.ndim == 1}
        if any(a.ndim != 1 for a in arrays.values()) or len(lengths) > 1:
            raise InvalidParameter("cases", "every parameter must be a 1-D array of the same length")
        self.n = lengths.pop() if lengths else 0
        self._values = arrays
        self.members = np.arange(self.n, dtype=np.int64) if members is None else np.asarray(members, dtype=np.int64)
        if self.members.shape != (self.n,):
            raise InvalidParameter("members", f"expected {self.n} member numbers, got shape {self.members.shape}")
        self.random = random
        self.fidelity = fidelity

    @classmethod
    def from_case(cls, case: Case, n: int = 1, **kwargs) -> Cases:
        """``n`` copies of one case (a Monte Carlo's members, or a single evaluation).

        Parameters
        ----------
        case : Case
            A validated case (SI values).
        n : int
            Number of copies (members).
        **kwargs
            ``members``, ``random`` and ``fidelity``, as in :class:`Cases`.
        """
        values = {}
        for name, value in case.items():
            if value is None or isinstance(value, (str, tuple)):  # a tuple is one value (a list of intervals)
                values[name] = np.empty(n, dtype=object)
                values[name].fill(value)
            else:
                values[name] = np.full(n, value)
        return cls(values, **kwargs)

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, name: str) -> np.ndarray:
        return self._values[name]

    def __contains__(self, name: object) -> bool:
        return name in self._values

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self._values)

    def float(self, name: str) -> np.ndarray:
        """A numeric parameter as a float array (NaN where not set).

        Parameters
        ----------
        name : str
            Parameter name; its values are SI (the parameter's SI unit).
        """
        array = self._values[name]
        if array.dtype == object:
            # numpy's stubs leave out None, which object arrays compare elementwise
            unset = np.equal(array, None)  # type: ignore[call-overload]
            return np.where(unset, np.nan, array).astype(float) if unset.any() else array.astype(float)
        return array.astype(float)

    def value_or(self, name: str, fallback) -> np.ndarray:
        """A numeric parameter with its "not set" entries replaced by ``fallback`` (scalar or array).

        Parameters
        ----------
        name : str
            Parameter name.
        fallback : float or ndarray
            Value of the cases that do not set it, in the parameter's SI unit.
        """
        values = self.float(name)
        return np.where(np.isnan(values), fallback, values)

    def is_set(self, name: str) -> np.ndarray:
        """Which cases set the parameter (bool array).

        Parameters
        ----------
        name : str
            Parameter name.
        """
        array = self._values[name]
        if array.dtype == object:
            # numpy's stubs leave out None, which object arrays compare elementwise
            return ~np.equal(array, None)  # type: ignore[call-overload]
        if array.dtype.kind == "f":
            return ~np.isnan(array)
        return np.ones(self.n, dtype=bool)

    def take(self, index) -> Cases:
        """The cases at ``index`` (an index array or boolean mask), keeping their member numbers.

        Parameters
        ----------
        index : ndarray of int or bool
            Indices (or a mask of length ``len(self)``) of the cases kept.
        """
        return Cases({k: v[index] for k, v in self._values.items()}, members=self.members[index],
                     random=self.random, fidelity=self.fidelity)

    def groups(self, *names: str) -> Iterator[tuple[np.ndarray, Cases]]:
        """Split the batch by the distinct values of ``names``: (indices, sub-batch) pairs.

        For parameters that change the shape of a computation (a duration, an
        output step, a model choice), so each group is evaluated at once.

        Parameters
        ----------
        *names : str
            Parameters whose distinct values define the groups.

        """
        if not names or self.n == 0:
            yield np.arange(self.n), self
            return
        keys = [tuple(_key(self._values[name][i]) for name in names) for i in range(self.n)]
        order: dict[tuple, list[int]] = {}
        for i, key in enumerate(keys):
            order.setdefault(key, []).append(i)
        for indices in order.values():
            index = np.asarray(indices, dtype=np.int64)
            yield index, self.take(index)

    def case(self, i: int) -> Case:
        """Case ``i`` as a :class:`Case` (NaN and None become "not set").

        Parameters
        ----------
        i : int
            Index of the case in the batch.
        """
        values = {}
        for name, array in self._values.items():
            value = array[i]
            value = value.item() if isinstance(value, np.generic) else value
            values[name] = None if isinstance(value, float) and math.isnan(value) else value
        return Case(values, [k for k, v in values.items() if v is not None])


def _key(value):
    value = value.item() if isinstance(value, np.generic) else value
    return "nan" if isinstance(value, float) and math.isnan(value) else value


def default_arrays(parameters: ParameterSet, n: int) -> dict[str, np.ndarray]:
    """Every parameter's default, ``n`` times (an unset number NaN, an unset text None, as in a sweep's plan).

    Read-only views of one value each: a batch of a million cases costs no copies.

    Parameters
    ----------
    parameters : ParameterSet
        The system's parameters (their defaults, SI).
    n : int
        Number of cases.
    """
    arrays = {}
    for name, value in parameters.case().items():
        if value is None:
            unset = np.nan if parameters[name].kind in ("quantity", "integer") else None
            one = np.array([unset], dtype=None if unset is not None else object)
        else:
            one = np.array([value], dtype=object if isinstance(value, str) else None)
        arrays[name] = np.broadcast_to(one, (n,))
    return arrays


def monte_carlo(evaluate: Callable[..., Mapping[str, np.ndarray]], outputs: tuple[Output, ...], case: Case,
                members: int, streams: RandomStreams, fidelity: str | None = None, *, chunk: int = MONTE_CARLO_CHUNK,
                draw: Callable[[np.ndarray], Mapping[str, np.ndarray]] | None = None,
                progress: Callable[[int, int], None] | None = None, executor=None) -> MonteCarloSummary:
    """Statistics of every output over ``members`` random members of ``case``, streamed in chunks.

    Member ``i`` draws its random terms from ``streams`` at address ``i``, so the
    statistics do not depend on ``chunk``, nor on where the chunks are evaluated:
    with an ``executor`` they may finish in any order, and are summarised in the
    members' order. ``draw(member_numbers) -> {parameter: values}`` optionally
    replaces parameters per member (a scenario's distributions); it runs here,
    the chunks' evaluation where the executor sends them.

    Parameters
    ----------
    evaluate : callable
        A system's ``evaluate(cases) -> {output: array}`` (SI).
    outputs : tuple of Output
        The outputs to summarise.
    case : Case
        The nominal case (SI values).
    members : int
        Number of random members.
    streams : RandomStreams
        Where the members' random terms come from.
    fidelity : str, optional
        Passed to ``evaluate`` through :attr:`Cases.fidelity`.
    chunk : int
        Members evaluated at once (a count; it does not change the result).
    draw : callable, optional
        ``draw(member_numbers) -> {parameter: values}``, SI values per member.
    progress : callable, optional
        ``progress(done, total)`` after each chunk, in members.
    executor : optional
        Where the chunks are evaluated: an object whose ``map(function, tasks)`` yields each task's result in any
        order (:mod:`schuler.study.executors`; ``evaluate`` and the case must pickle for worker processes).
        None: here, one chunk after another.

    """
    statistics = {output.name: StreamingStatistics((1,), reservoir_size=MONTE_CARLO_SAMPLES) for output in outputs}
    samples: dict[str, list[np.ndarray]] = {output.name: [] for output in outputs}
    names = tuple(statistics)

    def tasks():
        for start in range(0, members, chunk):
            numbers = np.arange(start, min(start + chunk, members), dtype=np.int64)
            yield MonteCarloChunk(evaluate, case, numbers, streams, fidelity,
                                  None if draw is None else dict(draw(numbers)), names)

    finished = _in_order(run_chunk, tasks(), executor)
    kept = 0
    for numbers, results in finished:
        for name, stats in statistics.items():
            values = np.asarray(results[name], dtype=float)
            stats.update(values[np.isfinite(values)][:, None])
            if kept < MONTE_CARLO_SAMPLES:
                samples[name].append(values[:MONTE_CARLO_SAMPLES - kept])
        kept = min(MONTE_CARLO_SAMPLES, kept + numbers.size)
        if progress is not None:
            progress(int(numbers[-1]) + 1, members)
    return MonteCarloSummary.from_statistics(members, streams.seed, outputs, statistics,
                                             {k: np.concatenate(v) if v else np.empty(0) for k, v in samples.items()})


@dataclass(frozen=True)
class MonteCarloChunk:
    """Members of a Monte Carlo evaluated together: what a worker process receives (it pickles).

    Attributes
    ----------
    evaluate : callable
        The system's ``evaluate(cases)``.
    case : Case
        The nominal case, SI.
    members : ndarray of int64
        The chunk's member numbers (contiguous).
    streams : RandomStreams
        Where their random terms come from.
    fidelity : str or None
        The evaluation's fidelity.
    drawn : dict of str to ndarray, or None
        Parameters drawn per member (SI), replacing the case's.
    outputs : tuple of str
        The outputs returned.
    """

    evaluate: Callable[..., Mapping[str, np.ndarray]]
    case: Case
    members: np.ndarray
    streams: RandomStreams
    fidelity: str | None
    drawn: dict[str, np.ndarray] | None
    outputs: tuple[str, ...]


def run_chunk(chunk: MonteCarloChunk) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The chunk's member numbers and its outputs, float arrays (one value per member).

    Parameters
    ----------
    chunk : MonteCarloChunk
        What to evaluate.
    """
    numbers = chunk.members
    batch = Cases.from_case(chunk.case, numbers.size, members=numbers, random=chunk.streams, fidelity=chunk.fidelity)
    if chunk.drawn is not None:
        values = {name: batch[name] for name in batch.names}
        values.update(chunk.drawn)
        batch = Cases(values, members=numbers, random=chunk.streams, fidelity=chunk.fidelity)
    results = chunk.evaluate(batch)
    return numbers, {name: np.asarray(results[name], dtype=float) for name in chunk.outputs}


def _in_order(function, tasks: Iterator[MonteCarloChunk], executor) -> Iterator:
    """``function`` of each task, in the tasks' order, wherever the executor evaluates them (in any order)."""
    if executor is None:
        yield from map(function, tasks)
        return
    waiting: dict[int, Any] = {}
    following = 0
    for numbers, results in executor.map(function, tasks):
        waiting[int(numbers[0])] = (numbers, results)
        while following in waiting:
            ready = waiting.pop(following)
            following = int(ready[0][-1]) + 1
            yield ready


class MeasuredPace:
    """The time estimate of a system that declares none: the pace of a Monte Carlo's chunks after the first.

    The first chunk is left out (it pays one-off compilation); from the second
    on, what remains is extrapolated at the pace measured so far, and refused
    past the time budget — so at most two chunks' time is spent on work refused.
    """

    def __init__(self, members: int, what: str, progress: Callable[[int, int], None] | None):
        self.members, self.what, self.progress = members, what, progress
        self.first: tuple[int, float] | None = None

    def __call__(self, done: int, total: int) -> None:
        now = time.perf_counter()
        if self.first is None:
            self.first = (done, now)
        elif done > self.first[0] and done < self.members:
            pace = (now - self.first[1]) / (done - self.first[0])
            require_time(pace * (self.members - done), f"{self.what} ({self.members} members; pace measured)",
                         "`monte_carlo`")
        if self.progress is not None:
            self.progress(done, total)
