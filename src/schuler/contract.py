"""The system contract: what every instrument system provides, in one place.

A system (``schuler errors``, ``align``, ``imu`` ...) is one :class:`System`
value in its subpackage's ``api`` module. Everything above it — the Python API
(:meth:`System.run`), scenario files, sweeps, the report and the command line,
which is generated from it — goes through the same few entries:

1. **Parameters** (:class:`~schuler.params.ParameterSet`) declared once: names,
   display units, defaults, ranges, help. Every entry point builds a validated
   :class:`~schuler.params.Case` from them; nothing else fills defaults.
2. ``evaluate(cases, histories=False) -> Evaluation``: the vectorised evaluation
   of a batch of cases (:class:`Cases`), each output an array of length
   ``len(cases)`` in SI, declared in ``outputs`` (:class:`Output`); with
   ``histories=True`` also the first case's named time histories
   (:class:`~schuler.core.response.Histories`) and structured extras. Sweeps
   and Monte Carlo use the outputs; :meth:`System.run` evaluates the one case
   with histories into one :class:`~schuler.results.SystemResult`, so a run
   equals ``evaluate`` by construction.
3. ``figures(result) -> {stem: Figure}``: the figures of any result of the
   system, drawn on demand (``result.plot()``) and written by the one writer,
   :func:`write_result` (histories as CSV, figures, the system's ``data_files``).
4. ``reproduce(**options) -> Reproduction``: the source's published case, rows
   of printed and computed values with verdicts from stated tolerances.
5. ``actions``: the system's own commands beyond ``run`` and ``reproduce``
   (``north identify``), each a function of validated parameters returning a Result.

Randomness belongs to the driver: a case's random terms (sensor noise,
Monte Carlo perturbations) are drawn by ``evaluate`` from ``cases.random``
(counter-based :class:`~schuler.core.random.RandomStreams`) addressed by
``cases.members``, the global case or member numbers — so results never depend
on chunking or executor. ``cases.random is None`` means the nominal case: every
random term zero.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from functools import partial, wraps
from pathlib import Path
from typing import Any

import numpy as np

from schuler.cases import MONTE_CARLO_CHUNK, MONTE_CARLO_SAMPLES, Cases, MeasuredPace, default_arrays, monte_carlo
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter
from schuler.memory import require_time
from schuler.params import Case, Parameter, ParameterSet
from schuler.results import Evaluation, MonteCarloSummary, Output, Result, SystemResult, write_result

RUN_CASE_MEMBERS = 4
"""Members a run in full counts as in a time estimate: its histories cost a few members where the work is large
(measured: north 1.1-3.2, mission 4.1, navigate 1.2 with IMU noise and 7 without); where members cost well under a
millisecond (align, calibrate, errors) the run in full is tens of members, still milliseconds."""

@dataclass(frozen=True)
class Argument:
    """A positional argument of an action: a file it reads (``north identify RECORD``)."""

    name: str
    help: str
    metavar: str = "FILE"


@dataclass(frozen=True)
class Action:
    """A command of a system beyond ``run`` and ``reproduce``.

    Parameters
    ----------
    name : str
        Command name (``identify``).
    help : str
        Help text; its first line is the short help.
    function : callable
        ``function(**si_values, **arguments) -> Result``; ``arguments`` are the
        positional files (Path) and, with ``output_file``, ``output`` (a Path).
    parameters : ParameterSet
        The command's options.
    arguments : tuple of Argument
        Positional file arguments.
    output_file : str
        Help of a required ``-o/--output FILE`` option; empty: no such option.
    write_files : callable, optional
        ``write_files(result, out_dir) -> [paths]`` for an action whose results are
        not the system's own types (a comparison built by another package); None:
        the system's one writer.
    figures : callable, optional
        ``figures(result) -> {stem: Figure}`` for an action whose results the
        system's ``figures`` does not draw; None: the system's.
    """

    name: str
    help: str
    function: Callable[..., Result]
    parameters: ParameterSet
    arguments: tuple[Argument, ...] = ()
    output_file: str = ""
    write_files: Callable[[Result, Path], list[Path]] | None = None
    figures: Callable[[Result], dict[str, Any]] | None = None


@dataclass(frozen=True)
class System:
    """An instrument system: the contract every subpackage's ``api.SYSTEM`` fulfils.

    Attributes
    ----------
    name : str
        Command name (``align``).
    title : str
        What it models, in a line.
    reference : str
        The source it follows, cited by author, title, venue and year.
    parameters : ParameterSet
        The parameters of ``run``, sweeps and scenarios.
    outputs : tuple of Output
        What ``evaluate`` returns.
    evaluate : callable
        ``evaluate(cases: Cases, histories=False) -> Evaluation`` (vectorised; see the module notes).
    reproduce : callable
        ``reproduce(**options) -> Reproduction``: the source's published case.
    reproduce_parameters : ParameterSet
        Options of ``reproduce``.
    report : callable
        ``report(figures_dir: Path) -> ReportSection``.
    fidelities : tuple of str
        Named evaluation choices, the default first (empty: one way only).
    actions : tuple of Action
        Further commands.
    random_terms : bool
        Whether the model has random terms of its own (sensor noise, Monte
        Carlo sigmas), so that ``--monte-carlo`` means something without a
        scenario's parameter distributions.
    member_bytes : callable or None
        ``member_bytes(case) -> int``: memory one member of a Monte Carlo or
        sweep chunk needs while evaluated (sizes the chunks).
    member_seconds : callable or None
        ``member_seconds(case) -> float``: time one member of a Monte Carlo or
        sweep takes, s, from the work it declares (samples, grid points) times
        a rate measured and stated where it is defined; long work is refused
        with the estimate before it starts (:meth:`work_seconds`). None: the
        Monte Carlo's rate is measured on its first chunks instead.
    guide : str
        Name of the system's page in the user guide.
    figures : callable or None
        ``figures(result) -> {stem: Figure}``: the figures of any result of the
        system (run, reproduction, actions), drawn on demand (``result.plot()``)
        and written by :meth:`write`.
    data_files : callable or None
        ``data_files(result, out_dir) -> [paths]``: files in a field's own
        formats beside the generic CSV and figures.
    result_type : type
        The :class:`~schuler.results.SystemResult` subclass ``run`` returns (it
        changes only how a result renders).
    realisation : bool
        A run without Monte Carlo is member 0 of ``seed`` (every random term
        drawn), not the nominal case.
    instrument : callable or None
        ``instrument(parameters, case, options) -> case``: the case with the
        values an IMU gives (``imu=`` a grade, a spec file, a recording), for
        the parameters not given explicitly.
    instrument_parameters : ParameterSet
        The options of ``instrument`` (``imu``, ``imu_window`` ...), accepted by
        :meth:`case` and :meth:`run` beside the system's parameters.
    """

    name: str
    title: str
    reference: str
    parameters: ParameterSet
    outputs: tuple[Output, ...]
    evaluate: Callable[..., Mapping[str, np.ndarray]]
    reproduce: Callable[..., Result]
    report: Callable[[Path], Any]
    figures: Callable[[Result], dict[str, Any]] | None = None
    data_files: Callable[[Result, Path], list[Path]] | None = None
    result_type: type[SystemResult] = SystemResult
    realisation: bool = False
    instrument: Callable[[ParameterSet, Case, Case], Case] | None = None
    instrument_parameters: ParameterSet = field(default_factory=lambda: ParameterSet(()))
    reproduce_parameters: ParameterSet = field(default_factory=lambda: ParameterSet(()))
    fidelities: tuple[str, ...] = ()
    actions: tuple[Action, ...] = ()
    random_terms: bool = False
    member_bytes: Callable[[Case], int] | None = None
    member_seconds: Callable[[Case], float] | None = None
    guide: str = ""

    def __post_init__(self) -> None:
        if self.figures is None:
            return
        # what reproduce and the actions return can plot itself, as run's result does
        object.__setattr__(self, "reproduce", _attaching(self.reproduce, self.figures))
        object.__setattr__(self, "actions", tuple(
            replace(action, function=_attaching(action.function, action.figures or self.figures))
            for action in self.actions))

    def write(self, result: Result, out_dir: Path, action: str | None = None) -> list[Path]:
        """Write a result's files into ``out_dir``: its histories as CSV, its figures, the system's data files.

        Parameters
        ----------
        result : Result
            What :meth:`run`, ``reproduce`` or an action returned.
        out_dir : Path
            Folder to write into (created if missing).
        action : str, optional
            The action that made ``result`` (its own writer, where it has one).
        """
        chosen = None if action is None else self.actions[[a.name for a in self.actions].index(action)]
        if chosen is not None and chosen.write_files is not None:
            # an action whose results another package builds (a comparison) writes its own files
            return chosen.write_files(result, Path(out_dir))
        return write_result(result, Path(out_dir), self.data_files)

    def case(self, **si_values) -> Case:
        """A validated case from SI values; unknown names raise :class:`InvalidParameter` with a suggestion.

        Parameters
        ----------
        **si_values
            Parameters by name, in SI (each parameter's SI unit: rad, rad/s, m, s ...), or as text or pint
            quantities in any unit of the parameter's dimension (``latitude="50 deg"``); ``imu=`` and its
            options where the system takes its sensor errors from an IMU (:attr:`instrument_parameters`).
        """
        options = {name: si_values.pop(name) for name in list(si_values) if name in self.instrument_parameters}
        case = self.parameters.case(si_values)
        given = {name: value for name, value in options.items() if value is not None}
        if not given:
            return case
        chosen = self.instrument_parameters.case(given)
        if chosen["imu"] is None:
            raise InvalidParameter(sorted(given)[0], "applies with imu only")
        assert self.instrument is not None
        return self.instrument(self.parameters, case, chosen)

    def action(self, name: str) -> Callable[..., Result]:
        """The function of the system's action ``name`` (``north.action("identify")``), to call from Python.

        Parameters
        ----------
        name : str
            The action's command name (one of :attr:`actions`).

        Raises
        ------
        InvalidParameter
            A name that is not one of the system's actions (the closest suggested).
        """
        names = [action.name for action in self.actions]
        if name not in names:
            hint = difflib.get_close_matches(str(name), names, n=1)
            suggestion = f"did you mean {hint[0]!r}? " if hint else ""
            offered = ", ".join(names) or "none"
            raise InvalidParameter("action", f"{name!r} is not an action of {self.name}; {suggestion}"
                                             f"choose from {offered}")
        return self.actions[names.index(name)].function

    def check_fidelity(self, fidelity: str | None) -> str | None:
        """The fidelity to use (the default when None); refuses one the system does not offer.

        Parameters
        ----------
        fidelity : str or None
            One of :attr:`fidelities`, or None for the default.
        """
        if fidelity is None:
            return self.fidelities[0] if self.fidelities else None
        if fidelity not in self.fidelities:
            offered = ", ".join(self.fidelities) or "none (this system has one way of evaluating)"
            raise InvalidParameter("fidelity", f"{fidelity!r} is not offered; choose from {offered}")
        return fidelity

    def run(self, *, monte_carlo: int = 0, seed: int = 0, fidelity: str | None = None,
            progress: Callable[[int, int], None] | None = None,
            draw: Callable[[np.ndarray], Mapping[str, np.ndarray]] | None = None, executor=None,
            **si_values) -> Result:
        """Run one case from SI values (every parameter not given takes its default).

        Parameters
        ----------
        monte_carlo : int
            Members of a Monte Carlo around the case (0: none). Each member draws
            the system's random terms; statistics of every output are attached
            to the result as ``monte_carlo``.
        seed : int
            Seed of the Monte Carlo's random streams.
        fidelity : str, optional
            One of :attr:`fidelities` (default: the first).
        progress : callable, optional
            ``progress(done, total)`` after each chunk of members.
        draw : callable, optional
            ``draw(member_numbers) -> {parameter: values}``: parameters drawn per
            member (a scenario's ``[monte_carlo]`` distributions).
        executor : optional
            Where the Monte Carlo's chunks are evaluated (:func:`schuler.study.executors.make_executor`, e.g.
            ``make_executor(workers=2)``: two worker processes; close it when done); None: in this process. The
            statistics are the same either way.
        **si_values
            Parameters in SI.

        Raises
        ------
        InvalidParameter
            An unknown name (with the closest known one suggested), a value out
            of range, options that exclude each other.
        """
        case = self.case(**si_values)
        fidelity = self.check_fidelity(fidelity)
        members = _count(monte_carlo, "monte_carlo")
        if members and not self.random_terms and draw is None:
            raise InvalidParameter("monte_carlo", f"{self.name} has no random terms of its own: every member would be "
                                   "the nominal case; draw parameters with a scenario's [monte_carlo] tables")
        streams = RandomStreams(_count(seed, "seed"))
        estimate = self.work_seconds(case, members, workers=getattr(executor, "workers", 1))
        if estimate is not None:
            what = f"this {self.name} run" + (f" with {members} Monte Carlo members" if members else "")
            require_time(estimate, what, ("`monte_carlo`, " if members else "") + self._work_options())
        summary = None
        if members:
            summary = self.monte_carlo(case, members, streams, fidelity, draw=draw, progress=progress,
                                       executor=executor)
        return self.result(case, fidelity, streams if self.realisation else None, summary)

    def result(self, case: Case, fidelity: str | None = None, random: RandomStreams | None = None,
               monte_carlo: MonteCarloSummary | None = None) -> SystemResult:
        """One case in full: ``evaluate`` with histories, as the system's result type (what :meth:`run` returns).

        Parameters
        ----------
        case : Case
            A validated case (SI values).
        fidelity : str, optional
            One of :attr:`fidelities` (default: the first).
        random : RandomStreams, optional
            Where the case's random terms come from (member 0); None: the nominal case.
        monte_carlo : MonteCarloSummary, optional
            Statistics of a Monte Carlo around the case, attached to the result.
        """
        fidelity = self.check_fidelity(fidelity)
        cases = Cases.from_case(case, 1, members=np.zeros(1, dtype=np.int64), random=random, fidelity=fidelity)
        evaluation = self.evaluate(cases, histories=True)
        outputs = {output.name: _scalar(evaluation[output.name]) for output in self.outputs}
        result = self.result_type(
            system=self.name, outputs=outputs, fidelity=fidelity, extras=dict(getattr(evaluation, "extras", {})),
            parameters=dict(case), histories=dict(getattr(evaluation, "histories", {})), monte_carlo=monte_carlo,
            output_units={output.name: output.unit for output in self.outputs},
            extra_units=dict(getattr(evaluation, "units", {})),
            display_units={output.name: output.display for output in self.outputs if output.display})
        result.attach_figures(self.figures)
        return result

    def work_seconds(self, case: Case, members: int = 0, workers: int = 1) -> float | None:
        """Estimated time of :meth:`run` on ``case`` with ``members`` Monte Carlo members, s (None: not declared).

        The run in full (histories for figures) counts as :data:`RUN_CASE_MEMBERS` members; the members share
        ``workers`` processes, at most one per core.

        Parameters
        ----------
        case : Case
            A validated case (SI values).
        members : int
            Monte Carlo members (0: the case alone).
        workers : int
            Processes evaluating the members, number of.
        """
        if self.member_seconds is None:
            return None
        sharing = max(1, min(int(workers), len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                             else os.cpu_count() or 1))
        return float(self.member_seconds(case)) * (members / sharing + RUN_CASE_MEMBERS)

    def _work_options(self) -> str:
        # the parameters that set a system's amount of work, where it has them (quoted: the CLI shows options)
        names = [f"`{p.name}`" for p in self.parameters if p.name in ("duration", "imu_rate", "output_step")]
        return ", ".join(names[:-1]) + f" or {names[-1]}" if len(names) > 1 else (names or ["the case"])[0]

    def monte_carlo(self, case: Case, members: int, streams: RandomStreams, fidelity: str | None = None, *,
                    draw: Callable[[np.ndarray], Mapping[str, np.ndarray]] | None = None,
                    progress: Callable[[int, int], None] | None = None, executor=None) -> MonteCarloSummary:
        """Statistics of every output over ``members`` random members of ``case`` (see :func:`monte_carlo`).

        Parameters
        ----------
        case : Case
            The nominal case (SI values).
        members : int
            Number of random members.
        streams : RandomStreams
            Where the members' random terms come from.
        fidelity : str, optional
            One of :attr:`fidelities`.
        draw : callable, optional
            ``draw(member_numbers) -> {parameter: values}``, SI values per member.
        progress : callable, optional
            ``progress(done, total)`` after each chunk, in members.
        executor : optional
            Where the chunks are evaluated (see :meth:`run`); None: in this process.
        """
        checked = None if draw is None else partial(self._checked_draw, draw)
        if self.member_seconds is None:
            progress = MeasuredPace(members, f"this {self.name} Monte Carlo", progress)
        chunk = self._chunk_size(case)
        workers = getattr(executor, "workers", None)
        if workers:  # at least two chunks per worker, so that none waits while another finishes
            chunk = min(chunk, max(1, -(-members // (2 * workers))))
        return monte_carlo(self.evaluate, self.outputs, case, members, streams, fidelity,
                           chunk=chunk, draw=checked, progress=progress, executor=executor)

    def _checked_draw(self, draw: Callable[[np.ndarray], Mapping[str, np.ndarray]],
                      numbers: np.ndarray) -> dict[str, np.ndarray]:
        """A draw's values validated like :meth:`evaluate_values`' (a misspelt name is refused, not ignored)."""
        drawn = self.checked_arrays(draw(numbers))
        for name, values in drawn.items():
            if values.size != numbers.size:
                raise InvalidParameter(name, f"draw gave {values.size} values for {numbers.size} members")
        return drawn

    def _chunk_size(self, case: Case) -> int:
        if self.member_bytes is None:
            return MONTE_CARLO_CHUNK
        from schuler.memory import chunk_members

        return chunk_members(self.member_bytes(case))

    def evaluate_values(self, values: Mapping[str, Any], *, members=None, random: RandomStreams | None = None,
                        fidelity: str | None = None) -> dict[str, np.ndarray]:
        """``evaluate`` on parameter arrays in SI (unset parameters take their defaults).

        Parameters
        ----------
        values : mapping of str to array_like
            Parameter arrays (or scalars, broadcast) in SI, each of the same length.
        members : array_like of int, optional
            Global member numbers (the addresses of the random draws; default 0 .. n-1).
        random : RandomStreams, optional
            Where random terms come from; None evaluates the nominal case.
        fidelity : str, optional
            One of :attr:`fidelities`.
        """
        given = self.checked_arrays(values)
        # a list of intervals is one value, not a batch of cases
        lengths = {array.size for name, array in given.items()
                   if np.ndim(values[name]) > 0 and not getattr(self.parameters[name], "pairs", False)}
        if len(lengths) > 1:
            raise InvalidParameter("cases", f"parameter arrays have different lengths: {sorted(lengths)}")
        n = lengths.pop() if lengths else 1
        arrays = default_arrays(self.parameters, n)
        arrays.update({name: np.broadcast_to(array, (n,)) for name, array in given.items()})
        cases = Cases(arrays, members=members, random=random, fidelity=self.check_fidelity(fidelity))
        return dict(self.evaluate(cases))

    def checked_arrays(self, values: Mapping[str, Any]) -> dict[str, np.ndarray]:
        """The given parameter arrays validated as :meth:`run` validates one case (ranges on whole arrays).

        Unknown names (with a suggestion), values of the wrong type,
        non-finite or out of range, empty or multi-dimensional arrays are
        refused; None means "not set". Options that exclude each other may be
        given together in a batch (each system's own precedence applies: a
        speed profile replaces the speed).

        Parameters
        ----------
        values : mapping of str to array_like
            Parameter arrays (or scalars) in SI.

        Returns
        -------
        dict of str to ndarray
            The given (not None) parameters, each a validated 1-D array (a scalar has length 1).
        """
        self.parameters.refuse_unknown(values)
        given = {name: value for name, value in values.items() if value is not None}
        return {name: self.parameters[name].check_array(value, name) for name, value in given.items()}

    def output(self, name: str) -> Output:
        """The declared :class:`Output` called ``name`` (KeyError if there is none).

        Parameters
        ----------
        name : str
            Output key (``azimuth_error_rad``).
        """
        for output in self.outputs:
            if output.name == name:
                return output
        raise KeyError(name)


def _attaching(function: Callable[..., Result], figures: Callable[[Result], dict[str, Any]] | None
               ) -> Callable[..., Result]:
    """``function`` whose result draws its figures with ``figures`` (:meth:`Result.attach_figures`)."""
    if getattr(function, "attached_figures", None) is figures:
        return function

    @wraps(function)
    def attached(*args, **kwargs):
        return function(*args, **kwargs).attach_figures(figures)

    attached.attached_figures = figures  # type: ignore[attr-defined]
    return attached


def _scalar(values) -> Any:
    """The first case's value of an output array, as a Python number (or the object it holds)."""
    value = np.asarray(values).reshape(-1)[0]
    return value.item() if isinstance(value, np.generic) else value


def _count(value, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise InvalidParameter(name, f"{value!r} must be a whole number >= 0")
    return int(value)


RUN_OPTIONS = (
    Parameter("monte_carlo", "", 0, "Monte Carlo members around the case (0: the nominal case only).",
              minimum=0, kind="integer"),
    Parameter("seed", "", 0, "Seed of the random streams (a member's draws depend only on seed and member).",
              minimum=0, kind="integer"),
)
"""Options every ``run`` has besides the system's parameters."""


@dataclass(frozen=True)
class FigureRef:
    """A figure file (relative to the report folder) and its caption."""

    path: str
    caption: str


@dataclass
class ReportSection:
    """What one system contributes to the HTML report."""

    system: str
    title: str
    source: str
    summary: str
    rows: list = field(default_factory=list)
    figures: list[FigureRef] = field(default_factory=list)
    commands: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


__all__ = ["MONTE_CARLO_CHUNK", "MONTE_CARLO_SAMPLES", "RUN_OPTIONS", "Action", "Argument", "Cases", "Evaluation",
           "FigureRef", "Output", "ReportSection", "System", "monte_carlo", "write_result"]
