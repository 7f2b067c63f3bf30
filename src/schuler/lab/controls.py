"""Controls generated from a :class:`~schuler.params.ParameterSet`, and what they send back.

Every control is a ``<div data-param="NAME">`` holding a label with the display
unit, a text ``<input>`` (a typed value, applied on Enter or when the field is
left), the default and range, and a place for the one-line error. A text
parameter a page offers names for gets them as suggestions of its input, or,
when it takes several comma-separated names, as check boxes whose ticked names
travel joined by commas (:class:`Names`). Values travel
as the text the user typed and are converted only by
:meth:`~schuler.params.ParameterSet.parse` (the command line's own parser), so
the messages are the command line's too and nothing typed is ever evaluated.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from dash import dcc, html

from schuler.exceptions import InvalidParameter, SchulerError, as_options
from schuler.lab.views import data_attributes
from schuler.params import Case, Parameter, ParameterSet
from schuler.units import to_unit

MAX_VALUE_CHARS = 200
"""Longest text a control accepts (the input refuses more; the server checks again)."""

PARAM = "param"
"""Component-id type of a control's input: ``{"type": PARAM, "name": NAME}``."""
ERROR = "param-error"
"""Component-id type of a control's message line."""


@dataclass(frozen=True)
class Names:
    """The names a text parameter takes, offered by its control.

    Attributes
    ----------
    names : tuple of str
        The names, in the order shown.
    several : bool
        Whether the parameter takes several of them, comma-separated (check boxes) or one (suggestions of the
        text input, which still takes any other text: a file's path).
    """

    names: tuple[str, ...]
    several: bool = False


def initial_text(parameter: Parameter) -> str:
    """The default as the input shows it: ``50``, ``0.0001``, ``full``; empty when not set.

    Parameters
    ----------
    parameter : Parameter
        The parameter whose default is shown (its ``default`` is in its display unit).

    Returns
    -------
    str
        The default as text in the display unit (12 significant digits for floats), ``true``/``false`` for a
        flag, empty when the default is None.

    Examples
    --------
    >>> initial_text(Parameter("latitude", "deg", 50.0, "Latitude."))
    '50'
    >>> initial_text(Parameter("c_a", "1/s", None, "Gain."))
    ''
    >>> initial_text(Parameter("alpha0", "deg", "0.5 rad", "Start angle."))
    '28.6478897565'
    """
    default = parameter.default
    if default is None:
        return ""
    if isinstance(default, str) and parameter.kind == "quantity":
        try:  # a default written with its unit ("3.69*pi/540 rad"): the number in the display unit
            return f"{float(to_unit(parameter.parse(default), parameter.unit)):.12g}"
        except Exception:  # a text the parser does not take is shown as written (the run reports it)
            return default
    if isinstance(default, bool):
        return "true" if default else "false"
    if isinstance(default, float):
        return f"{default:.12g}"
    return str(default)


def describe(parameter: Parameter) -> str:
    """The line under a control: default and allowed range or choices.

    Parameters
    ----------
    parameter : Parameter
        The parameter the control sets (default and bounds in its display unit).

    Returns
    -------
    str
        ``default ...; range ...`` (or ``one of ...`` for a choice, ``true or false`` for a flag).
    """
    shown = initial_text(parameter)
    written_with_unit = isinstance(parameter.default, str) and parameter.kind == "quantity" and parameter.unit
    parts = [f"default {shown} {parameter.unit}" if written_with_unit else f"default {parameter.default_text()}"]
    if parameter.kind == "choice":
        parts.append("one of " + ", ".join(parameter.choices or ()))
    elif parameter.kind == "flag":
        parts.append("true or false")
    elif parameter.minimum is not None or parameter.maximum is not None:
        parts.append(f"range {parameter.range_text()}")
    return "; ".join(parts)


def unit_label(parameter: Parameter) -> str:
    """The display unit written beside a control's name; empty for plain numbers and other kinds.

    Parameters
    ----------
    parameter : Parameter
        The parameter the control sets.

    Returns
    -------
    str
        Its display unit (``deg/h``) when it is a quantity with a unit, else empty.
    """
    return parameter.unit if parameter.kind == "quantity" and parameter.unit else ""


def human_label(name: str) -> str:
    """A parameter's name as people read it: ``drift_east`` -> ``drift east`` (a symbol like ``c_a`` stays).

    Parameters
    ----------
    name : str
        The parameter's name (snake_case, as in the Python API and the scenario files).

    Returns
    -------
    str
        The words of the name separated by blanks; names starting with a one-letter symbol unchanged.

    Examples
    --------
    >>> human_label("drift_east"), human_label("initial_azimuth_error"), human_label("c_a"), human_label("hm")
    ('drift east', 'initial azimuth error', 'c_a', 'hm')
    """
    words = name.split("_")
    return name if len(words[0]) == 1 else " ".join(words)


def control(parameter: Parameter, value: str | None = None, id_type: str = PARAM,
            names: Names | None = None) -> html.Div:
    """One control: ``div[data-param=NAME]`` with label (``drift east``, unit), ``<input>``, option, default and
    range, error line.

    Parameters
    ----------
    parameter : Parameter
        The parameter the control sets.
    value : str, optional
        Text to show in the input instead of the default (as typed, display unit); None: the default.
    id_type : str
        Component-id type of the input (``{"type": id_type, "name": NAME}``); the message line's type is
        ``param-error`` for the default, ``ID_TYPE-error`` otherwise, so that two pages' controls stay apart.
    names : Names, optional
        The names a text parameter takes: suggestions of its input, or check boxes when it takes several.

    Returns
    -------
    dash.html.Div
        ``div.control[data-param=NAME]`` holding label (with the display unit), input, hint and message line.
    """
    name = parameter.name
    unit = unit_label(parameter)
    options = None
    text = initial_text(parameter) if value is None else value
    if parameter.kind == "choice":
        choices: tuple[str, ...] = parameter.choices or ()
    elif parameter.kind == "flag":
        choices = ("true", "false")
    else:
        choices = names.names if names is not None and not names.several else ()
    if choices:
        options = html.Datalist(id=f"{id_type}-{name}-choices", children=[html.Option(value=c) for c in choices])
    field: Any
    if names is not None and names.several:  # none ticked: not set, the parameter's own default
        field = dcc.Checklist(id={"type": id_type, "name": name}, options=list(names.names),
                              value=[n for n in (part.strip() for part in text.split(",")) if n in names.names],
                              inline=True, className="value names")
    else:
        field = dcc.Input(id={"type": id_type, "name": name}, type="text", value=text, debounce=True,
                          maxLength=MAX_VALUE_CHARS, placeholder="not set" if parameter.default is None else "",
                          list=f"{id_type}-{name}-choices" if options is not None else None, autoComplete="off",
                          spellCheck=False, className="value")
    label = html.Label([html.Span(human_label(name), className="name"),
                        html.Span(unit, className="unit") if unit else None], title=parameter.help)
    hint = f"{parameter.option}; {describe(parameter)}"  # the option the command line takes for the same value
    children = [label, field, options, html.Div(hint, className="hint", title=parameter.help),
                html.Div(id={"type": ERROR if id_type == PARAM else f"{id_type}-error", "name": name},
                         className="error", role="alert")]
    return html.Div([c for c in children if c is not None], className="control", **data_attributes(param=name))


def controls(parameters: Iterable[Parameter], id_type: str = PARAM, values: Mapping[str, str] | None = None,
             names: Mapping[str, Names] | None = None) -> list[html.Div]:
    """A control per parameter; ``values`` are texts to start with instead of the defaults.

    Parameters
    ----------
    parameters : iterable of Parameter
        The parameters to make controls for, in the order shown.
    id_type : str
        Component-id type of the inputs (see :func:`control`).
    values : mapping of str to str, optional
        Parameter name -> text to start with (as typed, display unit); names not in it show their default.
    names : mapping of str to Names, optional
        Parameter name -> the names its control offers (text parameters).

    Returns
    -------
    list of dash.html.Div
        One control per parameter.
    """
    return [control(p, (values or {}).get(p.name), id_type=id_type, names=(names or {}).get(p.name))
            for p in parameters]


def typed_values(parameters: ParameterSet, ids: list[dict], values: list) -> dict[str, str]:
    """The values the user changed from the defaults shown, as typed (names of ``parameters`` only).

    An emptied field goes back to its default ("not set" where there is none).

    Parameters
    ----------
    parameters : ParameterSet
        The parameters the page shows; inputs naming any other parameter are ignored.
    ids : list of dict
        Component ids of the inputs (``{"type": ..., "name": NAME}``), as Dash passes them.
    values : list
        The inputs' current texts, in the order of ``ids`` (None for an input never filled; a list of the names
        ticked for check boxes, joined by commas).

    Returns
    -------
    dict of str to str
        Parameter name -> text as typed (display unit), only where it differs from the default shown.
    """
    typed: dict[str, str] = {}
    for ident, value in zip(ids, values):
        name = ident.get("name") if isinstance(ident, Mapping) else None
        if not isinstance(name, str) or name not in parameters:
            continue
        text = "" if value is None else ",".join(map(str, value)) if isinstance(value, list) else str(value)
        if text.strip() and text.strip() != initial_text(parameters[name]):
            typed[name] = text
    return typed


def parse_typed(parameters: ParameterSet, typed: Mapping[str, str]) -> tuple[Case | None, dict[str, str]]:
    """Parse typed values as the command line does: a case, or the one-line message per control.

    Each value is parsed on its own first, so that every wrong field gets its
    message; then the set as a whole (options that exclude each other).
    Messages name the option as the command line does (``--latitude: '95' is
    outside (-90, 90) deg``).

    Parameters
    ----------
    parameters : ParameterSet
        The parameters of the system or command the page runs.
    typed : mapping of str to str
        Parameter name -> text as typed (a number in the parameter's display unit, or a value with its unit);
        parameters not in it take their default.

    Returns
    -------
    case : Case or None
        The parsed case, values in SI (rad, rad/s, s, ...); None when any value is wrong.
    errors : dict of str to str
        Parameter name -> its one-line message naming the option; empty when the case parsed.

    Examples
    --------
    >>> ps = ParameterSet([Parameter("latitude", "deg", 50.0, "Latitude.", minimum=-90, maximum=90)])
    >>> parse_typed(ps, {"latitude": "95"})[1]
    {'latitude': "--latitude: '95' is outside [-90, 90] deg"}
    >>> round(parse_typed(ps, {"latitude": "45"})[0]["latitude"], 6)
    0.785398
    """
    errors: dict[str, str] = {}
    for name, text in typed.items():
        parameter = parameters[name]
        if len(text) > MAX_VALUE_CHARS:
            errors[name] = f"{parameter.option}: longer than {MAX_VALUE_CHARS} characters"
            continue
        try:
            parameter.parse(text, parameter.option)
        except SchulerError as error:
            errors[name] = as_options(str(error))
        except Exception:  # the units library fails on some texts ("()") with errors of its own
            unit = (parameter.unit if parameter.kind == "quantity" else "") or "plain numbers"
            errors[name] = f"{parameter.option}: cannot read {text.strip()!r} as a quantity in {unit}"
    if errors:
        return None, errors
    try:
        return parameters.parse(dict(typed), labels="option"), {}
    except InvalidParameter as error:
        return None, {_owner(parameters, error.name) or parameters.names[0]: as_options(str(error))}


def _owner(parameters: ParameterSet, label: str) -> str | None:
    """The parameter a message names, by name or by option (None when it names none)."""
    for parameter in parameters:
        if label in (parameter.option, parameter.name):
            return parameter.name
    return None


def error_owner(parameters: ParameterSet, error: SchulerError) -> tuple[str | None, str]:
    """Where a run's error belongs and its message in the command line's words.

    An error naming a parameter (``latitude: ...``) goes beside that control and
    names its option (``--latitude: ...``); any other goes to the page (None).

    Parameters
    ----------
    parameters : ParameterSet
        The parameters of the page, whose controls may own the message.
    error : SchulerError
        The error the run raised (its ``name`` and ``reason`` when it has them, else its text
        ``NAME: REASON``).

    Returns
    -------
    owner : str or None
        Name of the parameter whose control shows the message; None for the page.
    message : str
        The message, naming the option (``--latitude: ...``) when it has an owner.
    """
    name = getattr(error, "name", None)
    reason = getattr(error, "reason", None)
    if name is None:
        name, _, reason = str(error).partition(": ")
    owner = _owner(parameters, name)
    if owner is not None and reason:
        return owner, as_options(f"{parameters[owner].option}: {reason}")
    return None, as_options(str(error))
