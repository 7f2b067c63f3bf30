"""Scenario files: one TOML file describes one study of one system.

A scenario names the system and sets its ``run`` parameters by the same names
as the command-line options (underscores instead of dashes)::

    system = "align"
    title = "Gyrocompassing at 50 deg N"        # optional
    description = "..."                         # optional

    [parameters]        # bare numbers are in the option's display unit
    latitude = "50 deg"
    drift_east = "0.01 deg/h"

    [simulation]        # optional: the run's duration and step parameter (step may
    duration = "6 h"    # stand for time_step or output_step); each may be set here or in
    step = "1 s"        # [parameters], not both

    [outputs]           # optional
    directory = "out"   # like --out (relative to the current folder)
    json = false        # like --json

    [monte_carlo]       # optional: what ``schuler sweep --monte-carlo N`` draws
    seed = 1
    cases = 1000
    [monte_carlo.normal]    # standard deviation around the [parameters] value
    drift_east = "0.005 deg/h"
    [monte_carlo.uniform]   # two values: lower and upper end
    latitude = ["40 deg", "60 deg"]

The file is validated against a schema built from the system's
:class:`~schuler.params.Parameter` definitions, with unknown keys forbidden.
Every problem raises :class:`~schuler.exceptions.ScenarioError` with one line
naming the file, the table and key, the value and what is allowed.

Examples
--------
>>> parse_scenario('system = "compass"', source="s.toml")
Traceback (most recent call last):
...
schuler.exceptions.ScenarioError: s.toml: system: 'compass' is not one of errors, vertical, calibrate, align, north
"""

from __future__ import annotations

import difflib
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, Union

from pydantic import BaseModel, ConfigDict, Field, StrictBool, StrictFloat, StrictInt, StrictStr, ValidationError
from pydantic import create_model

from schuler.exceptions import InvalidParameter, ScenarioError
from schuler.params import Parameter
from schuler.registry import SYSTEM_MODULES, System, get_system
from schuler.study.systems import load_system

SIMULATION_KEYS: dict[str, tuple[str, ...]] = {
    "duration": ("duration",),
    "step": ("step", "time_step", "output_step"),
}
"""Keys of the ``[simulation]`` table and the run parameter each may stand for."""


def simulation_keys(parameters) -> dict[str, str]:
    """``[simulation]`` key -> run parameter name, for the keys a system supports.

    >>> from schuler.params import Parameter
    >>> simulation_keys([Parameter("time_step", "s", 1.0, "Output step.")])
    {'step': 'time_step'}
    """
    names = {spec.name for spec in parameters}
    found = {}
    for key, candidates in SIMULATION_KEYS.items():
        match = next((name for name in candidates if name in names), None)
        if match is not None:
            found[key] = match
    return found

Value = Union[StrictBool, StrictInt, StrictFloat, StrictStr]
"""What a TOML scalar can be; the Parameter decides what it means."""

_STRICT = ConfigDict(extra="forbid")


class OutputsTable(BaseModel):
    """The ``[outputs]`` table: where files go and how results are printed."""

    model_config = _STRICT
    directory: StrictStr | None = None
    json_: StrictBool = Field(False, alias="json")


@dataclass(frozen=True)
class Distribution:
    """A random parameter of a Monte Carlo: ``normal`` (sigma, SI) or ``uniform`` (low, high, SI)."""

    kind: Literal["normal", "uniform"]
    first: float
    second: float = 0.0


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
    values : dict
        Every ``run`` parameter in SI (defaults filled in), ready for ``System.run``.
    written : dict
        The parameter values exactly as written in the file (strings or numbers),
        including the ``[simulation]`` ones, in the file's order.
    title, description : str
    out_dir : Path or None
        The ``[outputs] directory``.
    as_json : bool
        The ``[outputs] json`` switch.
    monte_carlo : MonteCarlo or None
    source : str
        Where the scenario came from (file name), used in messages.
    """

    system: str
    values: dict[str, Any]
    written: dict[str, Any]
    title: str = ""
    description: str = ""
    out_dir: Path | None = None
    as_json: bool = False
    monte_carlo: MonteCarlo | None = None
    source: str = "<scenario>"

    def definition(self) -> System:
        """The :class:`~schuler.registry.System` this scenario runs."""
        return get_system(self.system)

    def run(self):
        """Run the scenario with the system's API; returns its Result."""
        return self.definition().run(**self.values)

    def command_line(self) -> list[str]:
        """The equivalent ``schuler SYSTEM run`` arguments (values as written)."""
        by_name = {p.name: p for p in self.definition().parameters}
        args = [self.system, "run"]
        for name, raw in self.written.items():
            spec = by_name[name]
            if spec.kind == "flag":
                args.append(spec.option if spec.parse(raw, name) else f"--no-{spec.option[2:]}")
            else:
                args.extend([spec.option, str(raw)])
        return args


def load_scenario(path) -> Scenario:
    """Read and validate a scenario file.

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
    """Validate scenario TOML text (see the module documentation for the layout)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ScenarioError(f"{source}: not valid TOML: {error}") from None
    if "system" not in data:
        raise ScenarioError(f"{source}: system: missing; set system = one of {_names(SYSTEM_MODULES)}")
    name = data["system"]
    if name not in SYSTEM_MODULES:
        raise ScenarioError(f"{source}: system: {name!r} is not one of {_names(SYSTEM_MODULES)}")
    system = load_system(name)
    if system is None:
        raise ScenarioError(f"{source}: system: {name!r} is not available in this installation")
    model = scenario_model(system)
    try:
        parsed = model.model_validate(data)
    except ValidationError as error:
        raise ScenarioError(f"{source}: {_first_problem(error, model)}") from None
    return _build(parsed, system, source)


def scenario_model(system: System) -> type[BaseModel]:
    """The pydantic schema of a scenario file of ``system`` (unknown keys forbidden).

    Every parameter is validated by its :meth:`Parameter.parse` (unit dimension
    and range), so a scenario accepts exactly what the command line accepts.
    """
    parameters = {spec.name: spec for spec in system.parameters}
    fields = {name: (Value | None, None) for name in parameters}
    parameters_table = create_model(
        f"{system.name}_parameters", __config__=_STRICT, __validators__=_validators(parameters, fields), **fields
    )
    stands_for = simulation_keys(system.parameters)
    sim_fields = {key: (Value | None, None) for key in stands_for}
    simulation_table = create_model(
        f"{system.name}_simulation",
        __config__=_STRICT,
        __validators__=_validators({key: parameters[name] for key, name in stands_for.items()}, sim_fields),
        **sim_fields,
    )
    random_fields = {name: (Value | None, None) for name in parameters}
    normal_table = create_model(f"{system.name}_normal", __config__=_STRICT, **random_fields)
    uniform_fields = {name: (tuple[Value, Value] | None, None) for name in parameters}
    uniform_table = create_model(f"{system.name}_uniform", __config__=_STRICT, **uniform_fields)
    monte_carlo_table = create_model(
        f"{system.name}_monte_carlo",
        __config__=_STRICT,
        seed=(StrictInt, 0),
        cases=(StrictInt | None, Field(None, ge=1)),
        normal=(normal_table | None, None),
        uniform=(uniform_table | None, None),
    )
    return create_model(
        f"{system.name}_scenario",
        __config__=_STRICT,
        system=(Literal[system.name], ...),
        title=(StrictStr, ""),
        description=(StrictStr, ""),
        parameters=(parameters_table | None, None),
        simulation=(simulation_table | None, None),
        outputs=(OutputsTable | None, None),
        monte_carlo=(monte_carlo_table | None, None),
    )


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


_TABLE_TITLES = {
    "parameters": "[parameters]",
    "simulation": "[simulation]",
    "outputs": "[outputs]",
    "monte_carlo": "[monte_carlo]",
}


def _first_problem(error: ValidationError, model: type[BaseModel]) -> str:
    """One line for the first validation problem: table, key, value, what is allowed."""
    problem = error.errors(include_url=False)[0]
    location = [str(part) for part in problem["loc"]]
    if location[:2] == ["monte_carlo", "normal"] or location[:2] == ["monte_carlo", "uniform"]:
        table, keys = f"[monte_carlo.{location[1]}]", location[2:]
    elif location and location[0] in _TABLE_TITLES and len(location) > 1:
        table, keys = _TABLE_TITLES[location[0]], location[1:]
    else:
        table, keys = "", location
    key = keys[0] if keys else ""
    where = " ".join(part for part in (table, key) if part)
    kind = problem["type"]
    if kind == "extra_forbidden":
        allowed = _allowed_keys(model, location[:-1])
        hint = difflib.get_close_matches(key, allowed, n=1)
        suggestion = f"did you mean {hint[0]!r}? " if hint else ""
        return f"{where}: unknown key; {suggestion}allowed: {_names(allowed)}"
    cause = problem.get("ctx", {}).get("error")
    if isinstance(cause, InvalidParameter):
        return f"{where}: {cause.reason}"
    value = problem.get("input")
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        return f"{where}: {value!r} must be a table"
    if kind == "literal_error":
        return f"{where}: {value!r} is not allowed; expected {problem['ctx']['expected']}"
    if kind.startswith(("bool", "string", "int", "float", "tuple")) or kind.endswith("_type"):
        return f"{where}: {value!r} is not a single number or string with a unit ({problem['msg'].lower()})"
    return f"{where}: {value!r}: {problem['msg']}"


def _allowed_keys(model: type[BaseModel], location: list[str]) -> list[str]:
    """Keys allowed in the table at ``location`` of the scenario model."""
    for part in location:
        annotation = model.model_fields[part].annotation
        candidates = [a for a in getattr(annotation, "__args__", (annotation,)) if isinstance(a, type)]
        model = next(a for a in candidates if issubclass(a, BaseModel))
    return [info.alias or name for name, info in model.model_fields.items()]


def _names(items) -> str:
    return ", ".join(items) if items else "(none)"


def _build(parsed: BaseModel, system: System, source: str) -> Scenario:
    written: dict[str, Any] = {}
    if parsed.parameters is not None:
        written.update({k: v for k, v in parsed.parameters.model_dump().items() if v is not None})
    if parsed.simulation is not None:
        stands_for = simulation_keys(system.parameters)
        for key, value in parsed.simulation.model_dump().items():
            if value is None:
                continue
            name = stands_for[key]
            if name in written:
                raise ScenarioError(f"{source}: [simulation] {key}: also set as [parameters] {name}; set it once")
            written[name] = value
    specs = {p.name: p for p in system.parameters}
    values = {}
    for name, spec in specs.items():
        raw = written.get(name, spec.default)
        values[name] = None if raw is None else spec.parse(raw, name)
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
        source=source,
    )


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
                raise ScenarioError(f"{source}: {where}: only numeric parameters can be random ({name} is a {spec.kind})")
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
