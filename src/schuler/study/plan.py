"""The plan of a sweep: grid axes, Monte Carlo draws, chunks — every case described compactly.

Cases are numbered ``0 .. n-1`` (grid point major, draw minor) and cut into
chunks of consecutive cases. Random draws depend only on the seed, the
parameter name and the case number (:class:`~schuler.core.random.RandomStreams`),
never on chunking, executor or order of completion.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from schuler.contract import Cases, System
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter, ScenarioError
from schuler.memory import require_time
from schuler.params import Parameter
from schuler.results import json_safe
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
    fidelity : str or None
        The system's evaluation fidelity (None: its default).
    """

    system: str
    parameters: tuple[Parameter, ...]
    base: dict[str, Any]
    axes: tuple[Axis, ...] = ()
    draws: int = 1
    distributions: dict[str, Distribution] = field(default_factory=dict)
    seed: int = 0
    chunk_size: int = DEFAULT_CHUNK_SIZE
    fidelity: str | None = None
    estimated_seconds: float | None = None
    """The work estimate, s (:func:`estimate_seconds`); None where the system declares no ``member_seconds``."""

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
        """First case and one past the last case of chunk ``index``.

        Parameters
        ----------
        index : int
            Chunk index, 0 to ``chunks - 1``.

        Returns
        -------
        start, stop : int
            Case numbers (indices): chunk ``index`` holds cases ``start .. stop-1``.
        """
        start = index * self.chunk_size
        return start, min(start + self.chunk_size, self.total)

    def grid_index(self, cases: np.ndarray) -> tuple[np.ndarray, ...]:
        """Index along each axis of the given case numbers.

        Parameters
        ----------
        cases : numpy.ndarray of int
            Case numbers (indices), 0 to ``total - 1``, any shape.

        Returns
        -------
        tuple of numpy.ndarray
            One index array per axis (outermost first), shaped like ``cases``; empty without axes.
        """
        if not self.axes:
            return ()
        return np.unravel_index(cases // self.draws, self.grid_shape)

    @property
    def random(self) -> bool:
        """Whether cases draw random terms: a Monte Carlo (``--monte-carlo``) draws them, a plain grid does not."""
        return self.draws > 1 or bool(self.distributions)

    def cases(self, start: int, stop: int) -> Cases:
        """Cases ``start .. stop-1`` for the system's ``evaluate``: members are the global case numbers.

        Parameters
        ----------
        start : int
            First case number (index).
        stop : int
            One past the last case number (index).

        Returns
        -------
        Cases
            The cases' parameters in SI (see :meth:`case_values`), their members (global case numbers), the
            seed's random streams when the plan draws random terms, and the plan's fidelity.
        """
        return Cases(self.case_values(start, stop), members=np.arange(start, stop, dtype=np.int64),
                     random=RandomStreams(self.seed) if self.random else None, fidelity=self.fidelity)

    def case_values(self, start: int, stop: int) -> dict[str, np.ndarray]:
        """Every parameter of cases ``start .. stop-1``, as arrays (SI).

        Parameters
        ----------
        start : int
            First case number (index).
        stop : int
            One past the last case number (index).

        Returns
        -------
        dict of str to numpy.ndarray
            Parameter name -> its values, shape (stop - start,), SI (choices as strings; an unset number is NaN,
            an unset text None): swept, drawn or the scenario's constant.
        """
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
        return self.distributions[spec.name].draw(spec, self.base[spec.name], self.seed, cases)

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
                "fidelity": self.fidelity,
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


# ------------------------------------------------------------------- grid specs
def grid_values(start: float, stop: float, step: float) -> np.ndarray:
    """``start, start+step, ...`` up to ``stop``, including ``stop`` when it is on the grid.

    "On the grid" allows a rounding error of 1e-9 step (plus the rounding of
    ``start`` and ``stop`` themselves), so ``0:1:0.1`` has 11 points whose
    last is exactly 1.

    Parameters
    ----------
    start : float
        First value, in SI as the sweep uses it (rad, rad/s, ...; any unit works when all three share it).
    stop : float
        Last value wanted, in the unit of ``start``.
    step : float
        Step, in the unit of ``start``; finite, non-zero, towards ``stop``.

    Returns
    -------
    numpy.ndarray
        The grid's values, in the unit of ``start``.

    Raises
    ------
    ValueError
        A zero or non-finite value, a step away from ``stop``, or more than :data:`MAX_CASES` points.

    Examples
    --------
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


def parse_axis(text: str, parameters: Iterable[Parameter]) -> Axis:
    """Read ``NAME=START:STOP:STEP`` or ``NAME=V1,V2,...`` (values as on the command line).

    A unit written only after the step applies to all three numbers:
    ``drift_east=0.001:0.01:0.001 deg/h``.

    Parameters
    ----------
    text : str
        ``NAME=START:STOP:STEP`` (numbers in the parameter's display unit, or each with its unit; a range only
        for numbers and integers) or ``NAME=V1,V2,...``.
    parameters : iterable of Parameter
        The system's parameters (``NAME`` must be one; ``-`` may stand for ``_``).

    Returns
    -------
    Axis
        The axis: its values in SI (choices as strings, integers as int64) and the text as written.

    Raises
    ------
    ScenarioError
        Unknown parameter, malformed range, or a value outside its allowed range.
    """
    by_name = {spec.name: spec for spec in parameters}
    name, equals, spec_text = text.partition("=")
    name = name.strip().replace("-", "_")
    if not equals or not spec_text.strip():
        raise ScenarioError(f"`param` {text!r}: expected NAME=START:STOP:STEP or NAME=V1,V2,...")
    if name not in by_name:
        raise ScenarioError(f"`param` {name}: unknown parameter; allowed: {', '.join(by_name)}")
    spec = by_name[name]
    label = f"`param` {name}"
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
    start: float
    stop: float
    step: float
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
    ends: tuple[float, float]
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
    fidelity: str | None = None,
) -> SweepPlan:
    """Build the plan of a sweep: grid axes from ``params``, Monte Carlo from the scenario.

    Parameters
    ----------
    scenario : Scenario
        The scenario: the base case (SI), its ``[monte_carlo]`` table (draws, distributions, seed) and
        fidelity.
    system : System
        The system swept (its parameters are the axes' and the cases').
    params : iterable of str
        ``NAME=START:STOP:STEP`` or ``NAME=V1,V2,...`` texts.
    monte_carlo : int, optional
        Monte Carlo draws per grid point, number of, at least 1; defaults to ``[monte_carlo] cases`` of the scenario
        (no Monte Carlo when neither is given).
    chunk_size : int
        Cases per chunk, number of, at least 1.
    fidelity : str, optional
        The system's evaluation fidelity (default: the scenario's, else the system's default).

    Returns
    -------
    SweepPlan
        The plan (no per-case arrays).

    Raises
    ------
    ScenarioError
        A malformed or repeated ``--param``, a chunk size or draw count below 1, Monte Carlo without random
        parameters, a swept parameter that is also random, an unknown fidelity, or more than
        :data:`MAX_CASES` cases.
    """
    axes = tuple(parse_axis(text, system.parameters) for text in params)
    names = [axis.name for axis in axes]
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise ScenarioError(f"`param` {repeated[0]}: given more than once")
    if chunk_size < 1:
        raise ScenarioError(f"`chunk_size`: {chunk_size} must be at least 1")
    table = scenario.monte_carlo
    draws = monte_carlo if monte_carlo is not None else (table.cases if table and table.cases else None)
    distributions: dict[str, Distribution] = {}
    if draws is not None:
        if draws < 1:
            raise ScenarioError(f"`monte_carlo`: {draws} must be at least 1")
        if table is None or not table.distributions:
            raise ScenarioError(
                "`monte_carlo`: the scenario has no random parameters; "
                "add a [monte_carlo.normal] or [monte_carlo.uniform] table"
            )
        distributions = dict(table.distributions)
        clash = sorted(set(distributions) & set(names))
        if clash:
            raise ScenarioError(f"`param` {clash[0]}: already random in the scenario's [monte_carlo] table")
    plan = SweepPlan(
        system=system.name,
        parameters=tuple(system.parameters),
        base=dict(scenario.values),
        axes=axes,
        draws=draws or 1,
        distributions=distributions,
        seed=table.seed if table else 0,
        chunk_size=int(chunk_size),
        fidelity=_fidelity(system, fidelity or scenario.fidelity),
    )
    if plan.total > MAX_CASES:
        raise ScenarioError(f"the sweep has {plan.total} cases, more than {MAX_CASES}; check the steps")
    seconds = estimate_seconds(plan, system)
    if seconds is not None:
        require_time(seconds, f"this sweep of {plan.total} cases", "the `param` steps, `monte_carlo` or the "
                     "scenario's [monte_carlo] cases")
    return replace(plan, estimated_seconds=seconds)


def estimate_seconds(plan: SweepPlan, system: System) -> float | None:
    """Time the plan's cases take, s: the system's seconds per member at the grid's corners, times the cases.

    The first and the last case of the plan (every axis at its first, then at
    its last value) are estimated and the larger counts for every case, so an
    axis that lengthens the work (a duration, a rate) is counted at its end.

    Parameters
    ----------
    plan : SweepPlan
        The sweep's plan.
    system : System
        The system swept.

    Returns
    -------
    float or None
        Estimated seconds; None where the system declares no ``member_seconds``.
    """
    if system.member_seconds is None or plan.total == 0:
        return None
    corners = []
    for number in (0, plan.total - 1):
        values = {name: array[0] for name, array in plan.case_values(number, number + 1).items()}
        given = {name: _plain(value) for name, value in values.items() if not _unset(value)}
        corners.append(float(system.member_seconds(system.parameters.case(given))))
    return max(corners) * plan.total


def _unset(value) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))




def _fidelity(system: System, fidelity: str | None) -> str | None:
    try:
        return system.check_fidelity(fidelity)
    except InvalidParameter as error:
        raise ScenarioError(f"`fidelity`: {error.reason}") from None
