"""Scenario files: one TOML file describes one study of one system.

A scenario names the system and sets its ``run`` parameters by the same names
as the command-line options (underscores instead of dashes)::

    system = "align"
    title = "Gyrocompassing at 50 deg N"        # optional
    description = "..."                         # optional

    [parameters]        # bare numbers are in the option's display unit
    latitude = "50 deg"
    drift_east = "0.01 deg/h"

    [simulation]            # optional: the run's duration and output step (each may be
    duration = "6 h"        # set here or in [parameters], not both) and the system's
    output_step = "1 s"     # fidelity ("simulated" or "closed" where it offers both)
    fidelity = "simulated"

    [outputs]           # optional
    directory = "out"   # like --out (relative to the current folder)
    json = false        # like --json

    [monte_carlo]       # optional: members of ``schuler run`` (cases) and what
    seed = 1            # ``schuler sweep --monte-carlo N`` draws
    cases = 1000
    [monte_carlo.normal]    # standard deviation around the [parameters] value
    drift_east = "0.005 deg/h"
    [monte_carlo.uniform]   # two values: lower and upper end
    latitude = ["40 deg", "60 deg"]

    [instrument]        # optional, align, calibrate, north, errors, vertical: an IMU sets the
    imu = "tactical"    # instrument parameters the file does not set (like --imu): a grade,
    imu_window = "10 min"   # a TOML spec or a recording (paths relative to the scenario's
                        # folder); imu_window, imu_latitude as the options of that name

The file is validated against a schema built from the system's
:class:`~schuler.params.Parameter` definitions, with unknown keys forbidden.
Every problem raises :class:`~schuler.exceptions.ScenarioError` with one line
naming the file, the table and key, the value and what is allowed.

Examples
--------
>>> parse_scenario('system = "compass"', source="s.toml")
Traceback (most recent call last):
...
schuler.exceptions.ScenarioError: s.toml: system: 'compass' is not one of errors, vertical, calibrate, align, north,
imu, navigate, mission, aided
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    StrictBool,
    StrictFloat,
    StrictInt,
    StrictStr,
    ValidationError,
    create_model,
)
from scipy.special import ndtri

from schuler.contract import System
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter, ScenarioError
from schuler.imu.instrument import apply_instrument, instrument_options
from schuler.params import Case, Parameter
from schuler.registry import SYSTEM_MODULES, get_system
from schuler.study.scenario_problems import first_problem, names, shown
from schuler.study.systems import load_system
from schuler.units import to_unit

SIMULATION_KEYS = ("duration", "output_step")
"""Parameters that may also be set in the ``[simulation]`` table (where the system has them)."""


def simulation_keys(parameters) -> dict[str, str]:
    """``[simulation]`` key -> run parameter name, for the keys a system has.

    Parameters
    ----------
    parameters : iterable of Parameter
        The system's ``run`` parameters.

    Returns
    -------
    dict of str to str
        ``[simulation]`` key -> parameter name, for ``duration`` and ``output_step`` where the system has them.

    Examples
    --------
    >>> from schuler.params import Parameter
    >>> simulation_keys([Parameter("output_step", "s", 1.0, "Output step.")])
    {'output_step': 'output_step'}
    """
    names = {spec.name for spec in parameters}
    return {key: key for key in SIMULATION_KEYS if key in names}

Value = StrictBool | StrictInt | StrictFloat | StrictStr
"""What a TOML scalar can be; the Parameter decides what it means."""

_STRICT = ConfigDict(extra="forbid")


class OutputsTable(BaseModel):
    """The ``[outputs]`` table: where files go and how results are printed."""

    model_config = _STRICT
    directory: StrictStr | None = None
    json_: StrictBool = Field(default=False, alias="json")


class ScenarioTables(BaseModel):
    """The top level of a scenario file, for any system.

    :func:`scenario_model` derives one system's schema from it, narrowing ``system``
    to its name and the parameter tables to its parameters; the tables are declared
    here, in the file's order, so that code reading a validated scenario is typed.
    """

    model_config = _STRICT
    system: StrictStr
    title: StrictStr = ""
    description: StrictStr = ""
    parameters: BaseModel | None = None
    simulation: BaseModel | None = None
    outputs: OutputsTable | None = None
    monte_carlo: BaseModel | None = None


@dataclass(frozen=True)
class Distribution:
    """A random parameter of a Monte Carlo: ``normal`` (sigma, SI) or ``uniform`` (low, high, SI)."""

    kind: Literal["normal", "uniform"]
    first: float
    second: float = 0.0

    def draw(self, spec: Parameter, base, seed: int, cases: np.ndarray) -> np.ndarray:
        """The parameter's value for each case number (counter-based: independent of chunking).

        Parameters
        ----------
        spec : Parameter
            The random parameter (its kind, range and display unit; an integer's draws are rounded).
        base : float or None
            The scenario's value of the parameter, SI: the mean of a ``normal`` draw (unused by ``uniform``);
            None when neither the scenario nor the system's default sets it.
        seed : int
            The Monte Carlo's seed (plain number, 0 or more).
        cases : numpy.ndarray of int
            Case (member) numbers, shape (N,); the same number always draws the same value.

        Returns
        -------
        numpy.ndarray
            The drawn values, shape (N,), SI (int64 for an integer parameter).

        Raises
        ------
        ScenarioError
            A draw outside the parameter's range, or a ``normal`` spread on a parameter without a value.
        """
        if self.kind == "normal" and base is None:
            raise ScenarioError(f"[monte_carlo.normal] {spec.name}: has no value to spread around; "
                                f"set {spec.name} in the scenario's [parameters] (or use [monte_carlo.uniform])")
        # parameter draws have stream names of their own, apart from the system's random terms
        u = RandomStreams(seed).uniform(f"parameter/{spec.name}", cases)
        if self.kind == "normal":
            drawn = base + self.first * ndtri(u)
        else:
            drawn = self.first + (self.second - self.first) * u
        if spec.kind == "integer":
            drawn = np.rint(drawn).astype(np.int64)
        _check_draws(spec, drawn, self.kind)
        return drawn


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



@dataclass(frozen=True)
class MonteCarlo:
    """Random parameters, seed and default number of cases of a Monte Carlo."""

    seed: int = 0
    cases: int | None = None
    distributions: dict[str, Distribution] = field(default_factory=dict)


@dataclass(frozen=True)
class Scenario:
    """A validated scenario.

    Attributes
    ----------
    system : str
        CLI name of the system.
    values : Case
        Every ``run`` parameter in SI (defaults filled in; ``values.given`` are the ones the file sets).
    written : dict
        The parameter values exactly as written in the file (strings or numbers),
        including the ``[simulation]`` ones, in the file's order.
    title, description : str
    out_dir : Path or None
        The ``[outputs] directory``.
    as_json : bool
        The ``[outputs] json`` switch.
    monte_carlo : MonteCarlo or None
    fidelity : str or None
        The ``[simulation] fidelity`` (None: the system's default).
    source : str
        Where the scenario came from (file name), used in messages.
    instrument : dict
        The ``[instrument]`` table as written (its values are already in ``values``).
    """

    system: str
    values: Case
    written: dict[str, Any]
    title: str = ""
    description: str = ""
    out_dir: Path | None = None
    as_json: bool = False
    monte_carlo: MonteCarlo | None = None
    fidelity: str | None = None
    source: str = "<scenario>"
    instrument: dict[str, Any] = field(default_factory=dict)

    def definition(self) -> System:
        """The :class:`~schuler.registry.System` this scenario runs."""
        return get_system(self.system)

    def draw(self, cases: np.ndarray) -> dict[str, np.ndarray]:
        """The values of the ``[monte_carlo]`` random parameters for the given case (member) numbers.

        Parameters
        ----------
        cases : numpy.ndarray of int
            Case (member) numbers, shape (N,).

        Returns
        -------
        dict of str to numpy.ndarray
            Random parameter name -> its values, shape (N,), SI; empty without a ``[monte_carlo]`` table.

        Raises
        ------
        ScenarioError
            A draw outside its parameter's range, or a ``normal`` spread on a parameter without a value.
        """
        table = self.monte_carlo
        if table is None:
            return {}
        specs = {p.name: p for p in self.definition().parameters}
        try:
            return {name: d.draw(specs[name], self.values[name], table.seed, cases)
                    for name, d in table.distributions.items()}
        except ScenarioError as error:
            raise ScenarioError(f"{self.source}: {error}") from None

    def given(self) -> dict[str, Any]:
        """The SI values the file sets (what ``System.run`` takes; the rest are defaults)."""
        return {name: self.values[name] for name in self.values.given}


def load_scenario(path) -> Scenario:
    """Read and validate a scenario file.

    Parameters
    ----------
    path : str or Path
        The scenario's TOML file (UTF-8).

    Returns
    -------
    Scenario
        The validated scenario (values in SI).

    Raises
    ------
    ScenarioError
        The file is missing or unreadable, is not valid TOML, or fails validation.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError(f"{path}: no such scenario file") from None
    except (IsADirectoryError, PermissionError, UnicodeDecodeError) as error:
        raise ScenarioError(f"{path}: cannot read the scenario file ({type(error).__name__})") from None
    return parse_scenario(text, source=str(path))


def parse_scenario(text: str, source: str = "<scenario>") -> Scenario:
    """Validate scenario TOML text (see the module documentation for the layout).

    Parameters
    ----------
    text : str
        The scenario's TOML text.
    source : str
        Where the text came from (a file name), used in messages.

    Returns
    -------
    Scenario
        The validated scenario (values in SI).

    Raises
    ------
    ScenarioError
        Not valid TOML, an unknown or missing system, or a table, key or value the system does not accept.
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ScenarioError(f"{source}: not valid TOML: {error}") from None
    except RecursionError:  # the parser recurses into nested arrays and inline tables
        raise ScenarioError(f"{source}: not valid TOML: arrays or tables nested too deeply") from None
    if "system" not in data:
        raise ScenarioError(f"{source}: system: missing; set system = one of {names(SYSTEM_MODULES)}")
    name = data["system"]
    if not isinstance(name, str) or name not in SYSTEM_MODULES:
        raise ScenarioError(f"{source}: system: {shown(name)} is not one of {names(SYSTEM_MODULES)}")
    system = load_system(name)
    if system is None:
        raise ScenarioError(f"{source}: system: {name!r} is not available in this installation")
    model = scenario_model(system)
    try:
        parsed = model.model_validate(data)
    except ValidationError as error:
        raise ScenarioError(f"{source}: {first_problem(error, model, system)}") from None
    except RecursionError:
        raise ScenarioError(f"{source}: arrays or tables nested too deeply for a scenario") from None
    return _build(parsed, system, source)


def scenario_model(system: System) -> type[ScenarioTables]:
    """The pydantic schema of a scenario file of ``system`` (unknown keys forbidden).

    Every parameter is validated by its :meth:`Parameter.parse` (unit dimension
    and range), so a scenario accepts exactly what the command line accepts.

    Parameters
    ----------
    system : System
        The system the scenario runs (its parameters, fidelities and instrument options).

    Returns
    -------
    type
        A pydantic model, subclass of :class:`ScenarioTables`, whose ``model_validate`` checks a parsed file.
    """
    parameters = {spec.name: spec for spec in system.parameters}
    # (type, default) pairs built at run time: pydantic reads them, a type checker cannot
    fields: dict[str, Any] = {name: ((list[tuple[Value, Value]] | StrictStr | None) if getattr(spec, "pairs", False)
                                     else Value | None, None) for name, spec in parameters.items()}
    parameters_table = create_model(
        f"{system.name}_parameters", __config__=_STRICT, __validators__=_validators(parameters, fields), **fields
    )
    stands_for = simulation_keys(system.parameters)
    sim_fields: dict[str, Any] = {key: (Value | None, None) for key in stands_for}
    validators = _validators({key: parameters[name] for key, name in stands_for.items()}, dict(sim_fields))
    if system.fidelities:
        sim_fields["fidelity"] = (Literal[system.fidelities] | None, None)
    simulation_table = create_model(
        f"{system.name}_simulation", __config__=_STRICT, __validators__=validators, **sim_fields)
    random_fields: dict[str, Any] = {name: (Value | None, None) for name in parameters}
    normal_table = create_model(f"{system.name}_normal", __config__=_STRICT, **random_fields)
    uniform_fields: dict[str, Any] = {name: (tuple[Value, Value] | None, None) for name in parameters}
    uniform_table = create_model(f"{system.name}_uniform", __config__=_STRICT, **uniform_fields)
    monte_carlo_table = create_model(
        f"{system.name}_monte_carlo",
        __config__=_STRICT,
        seed=(StrictInt, 0),
        cases=(StrictInt | None, Field(None, ge=1)),
        normal=(normal_table | None, None),
        uniform=(uniform_table | None, None),
    )
    narrowed: dict[str, Any] = {
        "system": (Literal[system.name], ...),
        "parameters": (parameters_table | None, None),
        "simulation": (simulation_table | None, None),
        "monte_carlo": (monte_carlo_table | None, None),
    }
    instrument = instrument_options(system.name)
    if len(instrument):
        instrument_fields: dict[str, Any] = {spec.name: (Value | None, None) for spec in instrument}
        instrument_fields["imu"] = (StrictStr, ...)
        checked = {spec.name: spec for spec in instrument if spec.name != "imu"}
        instrument_table = create_model(
            f"{system.name}_instrument", __config__=_STRICT,
            __validators__=_validators(checked, {k: v for k, v in instrument_fields.items() if k != "imu"}),
            **instrument_fields)
        narrowed["instrument"] = (instrument_table | None, None)
    return create_model(f"{system.name}_scenario", __base__=ScenarioTables, **narrowed)


def _validators(parameters: dict[str, Parameter], fields: dict) -> dict:
    """One pydantic field validator per parameter, calling its Parameter.parse."""
    from pydantic import field_validator

    def check(cls, value, info):
        if value is not None:
            spec = parameters[info.field_name]
            spec.parse(value, spec.name)
        return value

    if not fields:
        return {}
    return {"check_parameters": field_validator(*fields)(check)}


def _build(parsed: ScenarioTables, system: System, source: str) -> Scenario:
    written: dict[str, Any] = {}
    if parsed.parameters is not None:
        written.update({k: v for k, v in parsed.parameters.model_dump().items() if v is not None})
    fidelity = None
    if parsed.simulation is not None:
        stands_for = simulation_keys(system.parameters)
        for key, value in parsed.simulation.model_dump().items():
            if value is None:
                continue
            if key == "fidelity":
                fidelity = value
                continue
            name = stands_for[key]
            if name in written:
                raise ScenarioError(f"{source}: [simulation] {key}: also set as [parameters] {name}; set it once")
            written[name] = value
    specs = {p.name: p for p in system.parameters}
    try:
        values = system.parameters.parse(written)
    except InvalidParameter as error:
        raise ScenarioError(f"{source}: [parameters] {error}") from None
    instrument = getattr(parsed, "instrument", None)
    instrument_written = {} if instrument is None else {k: v for k, v in instrument.model_dump().items()
                                                        if v is not None}
    if instrument_written:
        values = _with_instrument(system, values, instrument_written, source)
    outputs = parsed.outputs or OutputsTable()
    return Scenario(
        system=system.name,
        values=values,
        written=written,
        title=parsed.title,
        description=parsed.description,
        out_dir=Path(outputs.directory) if outputs.directory else None,
        as_json=outputs.json_,
        monte_carlo=_monte_carlo(parsed.monte_carlo, specs, source),
        fidelity=fidelity,
        source=source,
        instrument=instrument_written,
    )


def _with_instrument(system: System, values: Case, written: dict[str, Any], source: str) -> Case:
    """``values`` with the ``[instrument]`` IMU's parameters where the file sets none (as ``--imu`` does)."""
    options = instrument_options(system.name)
    folder = Path(source).parent if Path(source).is_file() else None
    try:
        parsed = options.parse(written)
        case, _ = apply_instrument(system.name, system.parameters, values, parsed["imu"],
                                   window=parsed.get("imu_window"), latitude=parsed.get("imu_latitude"),
                                   base=folder)
    except (InvalidParameter, ScenarioError) as error:
        raise ScenarioError(f"{source}: [instrument] {error}") from None
    return case


def _monte_carlo(table, specs: dict[str, Parameter], source: str) -> MonteCarlo | None:
    if table is None:
        return None
    distributions: dict[str, Distribution] = {}
    for kind in ("normal", "uniform"):
        written = getattr(table, kind)
        for name, raw in (written.model_dump() if written is not None else {}).items():
            if raw is None:
                continue
            where = f"[monte_carlo.{kind}] {name}"
            spec = specs[name]
            if spec.kind not in ("quantity", "integer"):
                raise ScenarioError(
                    f"{source}: {where}: only numeric parameters can be random ({name} is a {spec.kind})"
                )
            if name in distributions:
                raise ScenarioError(f"{source}: {where}: already random in [monte_carlo.normal]")
            try:
                if kind == "normal":
                    distributions[name] = Distribution("normal", _spread(spec, raw, where))
                else:
                    low, high = (spec.parse(v, where) for v in raw)
                    if not low < high:
                        raise ScenarioError(f"{source}: {where}: {list(raw)!r}: the lower end must be below the upper")
                    distributions[name] = Distribution("uniform", float(low), float(high))
            except InvalidParameter as error:
                raise ScenarioError(f"{source}: {error}") from None
    return MonteCarlo(seed=table.seed, cases=table.cases, distributions=distributions)


def _spread(spec: Parameter, raw, where: str) -> float:
    """A standard deviation in SI: same unit as the parameter, not negative, range not applied."""
    free = Parameter(spec.name, spec.unit, None, spec.help, minimum=0.0) if spec.kind == "quantity" else None
    if free is None:
        free = Parameter(spec.name, "", None, spec.help, minimum=0.0)
    return float(free.parse(raw, where))
