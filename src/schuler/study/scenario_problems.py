"""What a scenario file got wrong, in one line: the table, the key, what was given and what is expected.

:func:`first_problem` turns pydantic's first validation error into that line; values are quoted as short
excerpts (a 50-MB string or a deeply nested array is never echoed whole).
"""

from __future__ import annotations

import datetime
import difflib

from pydantic import BaseModel, ValidationError

from schuler.contract import System
from schuler.exceptions import InvalidParameter
from schuler.params import Parameter
from schuler.units import quoted

_TABLE_TITLES = {
    "parameters": "[parameters]",
    "simulation": "[simulation]",
    "outputs": "[outputs]",
    "monte_carlo": "[monte_carlo]",
    "instrument": "[instrument]",
}


def first_problem(error: ValidationError, model: type[BaseModel], system: System) -> str:
    """One line for the first validation problem: table, key, value, what is allowed.

    Parameters
    ----------
    error : pydantic.ValidationError
        What validating the file against ``model`` raised.
    model : type
        The scenario's pydantic schema (for the keys a table allows).
    system : System
        The scenario's system (what each parameter takes).

    Returns
    -------
    str
        The problem, without the file's name.
    """
    problem = error.errors(include_url=False)[0]
    location = [str(part) for part in problem["loc"]]
    if location[:2] == ["monte_carlo", "normal"] or location[:2] == ["monte_carlo", "uniform"]:
        table, keys = f"[monte_carlo.{location[1]}]", location[2:]
    elif location and location[0] in _TABLE_TITLES and len(location) > 1:
        table, keys = _TABLE_TITLES[location[0]], location[1:]
    else:
        table, keys = "", location
    key = keys[0] if keys else ""
    where = " ".join(part for part in (table, _short(key)) if part)
    kind = problem["type"]
    if kind == "extra_forbidden":
        renamed = system.parameters.renamed.get(key)
        if renamed is not None:  # a former name (scripts written for an older version) says what it became
            return f"{where}: renamed to {renamed!r} (see CHANGELOG.md)"
        allowed = _allowed_keys(model, location[:-1])
        hint = difflib.get_close_matches(key, allowed, n=1) if len(key) <= 100 else []
        suggestion = f"did you mean {hint[0]!r}? " if hint else ""
        return f"{where}: unknown key; {suggestion}allowed: {names(allowed)}"
    cause = problem.get("ctx", {}).get("error")
    if isinstance(cause, InvalidParameter):
        return f"{where}: {cause.reason}"
    value = problem.get("input")
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        return f"{where}: {shown(value)} must be a table"
    if kind == "literal_error":
        return f"{where}: {shown(value)} is not allowed; expected {problem['ctx']['expected']}"
    expected = _expected(table, keys, kind, {spec.name: spec for spec in system.parameters})
    if expected:
        return f"{where}: expected {expected}; got {_toml_type(value)} {shown(value)}"
    return f"{where}: {shown(value)}: {problem['msg']}"


def _expected(table: str, keys: list[str], kind: str, specs: dict[str, Parameter]) -> str:
    """What a key takes, said as a user writes it; empty when the problem is not one of type."""
    if not (kind.startswith(("bool", "string", "int", "float", "tuple")) or kind.endswith("_type")
            or kind in ("too_long", "too_short")):
        return ""
    if table == "[monte_carlo.uniform]":
        return "two values [low, high]"
    spec = specs.get(keys[0]) if keys and table in ("[parameters]", "[simulation]", "[monte_carlo.normal]") else None
    if spec is not None:
        return {"quantity": "a number or a string with a unit", "integer": "a whole number",
                "flag": "true or false", "choice": f"one of {', '.join(spec.choices)} (a string)"}.get(spec.kind,
                                                                                                   "a string")
    by_type = {"bool": "true or false", "int": "a whole number", "float": "a number", "string": "a string"}
    return by_type.get(kind.removesuffix("_type").removesuffix("_parsing"), "a number or a string")


def _toml_type(value) -> str:
    """The TOML type of a value as read, said in words ("an array", "a date")."""
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, int):
        return "an integer"
    if isinstance(value, float):
        return "a float"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, (list, tuple)):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, datetime.datetime):
        return "a date-time"
    if isinstance(value, datetime.date):
        return "a date"
    if isinstance(value, datetime.time):
        return "a time of day"
    return "a value"


def shown(value) -> str:
    """A value as the file writes it, cut to a short excerpt.

    Parameters
    ----------
    value : object
        A value read from TOML (dates as ISO text, anything else as its repr).
    """
    if isinstance(value, (datetime.date, datetime.time)):
        return value.isoformat()
    return quoted(value)


def _short(key: str) -> str:
    """A key as a message shows it: cut to a short excerpt when it is long."""
    return key if len(key) <= 80 else key[:80] + "..."


def _allowed_keys(model: type[BaseModel], location: list[str]) -> list[str]:
    """Keys allowed in the table at ``location`` of the scenario model."""
    for part in location:
        annotation = model.model_fields[part].annotation
        candidates = [a for a in getattr(annotation, "__args__", (annotation,)) if isinstance(a, type)]
        model = next(a for a in candidates if issubclass(a, BaseModel))
    return [info.alias or name for name, info in model.model_fields.items()]


def names(items) -> str:
    """``items`` joined by commas, or "(none)".

    Parameters
    ----------
    items : iterable of str
        Key or system names.
    """
    return ", ".join(items) if items else "(none)"
