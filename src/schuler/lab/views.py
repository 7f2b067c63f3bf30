"""What a page shows of a result: headline numbers, Monte Carlo statistics, the reproduction table.

Everything is built generically from the system's declared outputs: each
headline number is a ``<span data-result="KEY">`` (KEY as in the system's JSON)
whose text is only the number and its display unit ("3.556 arcmin").
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from dash import html

from schuler.contract import Output, System
from schuler.reproduction import Reproduction
from schuler.results import MonteCarloStatistics, display_label
from schuler.units import to_unit


def number_text(value: float) -> str:
    """A number for people: 4 significant digits (no trailing zeros), whole numbers below 10^6 in full.

    Parameters
    ----------
    value : float
        The number, already in the unit it is shown in (any unit: only its digits are chosen here).

    Returns
    -------
    str
        ``-`` for NaN (not computed, as in :func:`quantity_text`), ``inf``/``-inf`` for infinities, ``0`` for
        zero (also -0.0), fixed-point with 4 significant digits from 0.001 up to 10^6, otherwise ``%.4g``.

    Examples
    --------
    >>> number_text(3.55583), number_text(0.0533333), number_text(10800.0), number_text(1.2345e-7)
    ('3.556', '0.05333', '10800', '1.234e-07')
    >>> number_text(-0.0), number_text(float("inf")), number_text(30.0), number_text(0.8)
    ('0', 'inf', '30', '0.8')
    >>> number_text(float("nan"))
    '-'
    """
    if math.isnan(value):
        return "-"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    if value == 0:
        return "0"
    magnitude = math.floor(math.log10(abs(value)))
    if -3 <= magnitude < 6:
        text = f"{value:.{max(0, 3 - magnitude)}f}"
        if "." in text:
            text = text.rstrip("0").rstrip(".")
        return text[1:] if text.startswith("-") and float(text) == 0 else text
    return f"{value:.4g}"


RELATIVE_RESOLUTION = 1e-10
"""A value below this fraction of the largest value of the same unit in the same result is rounding noise."""

ABSOLUTE_RESOLUTION = 1e-9
"""A value below this many display units is shown as 0 (the command line's tables print 0.0000 there)."""


def quantity_text(value_si, output: Output, resolution_si: float = 0.0) -> str:
    """An output's value in its display unit: ``3.556 arcmin``; ``yes``/``no`` for a flag; ``-`` when not computed.

    Parameters
    ----------
    value_si : float or bool or None
        The output's value in its SI unit (``output.unit``: rad, s, ...); None or NaN: not computed; a bool is a
        flag.
    output : Output
        The output declaration (its ``display`` unit is the one shown; empty: the SI unit).
    resolution_si : float
        Values smaller in magnitude are shown as 0 (rounding noise; see :func:`resolutions`), SI unit of the
        output.

    Returns
    -------
    str
        The number (see :func:`number_text`) and the shown unit, ``yes``/``no``, or ``-``.

    Examples
    --------
    >>> quantity_text(1.0343e-3, Output("azimuth_error_rad", "rad", "arcmin"))
    '3.556 arcmin'
    >>> quantity_text(None, Output("settling_time_s", "s")), quantity_text(True, Output("constraints_ok", "1"))
    ('-', 'yes')
    >>> quantity_text(1.56e-86, Output("azimuth_error_rad", "rad", "arcmin"), resolution_si=3e-13)
    '0 arcmin'
    """
    if value_si is None:
        return "-"
    if isinstance(value_si, (bool, np.bool_)):
        return "yes" if value_si else "no"
    value = float(value_si)
    if math.isnan(value):
        return "-"
    if abs(value) < resolution_si:
        value = 0.0
    unit = output.shown_unit
    shown = float(to_unit(value, output.display)) if output.display else value
    return f"{number_text(shown)} {unit}".strip()


def resolutions(system: System, values: Mapping[str, object]) -> dict[str, float]:
    """Below which magnitude each output of a result is rounding noise, SI unit of the output.

    The larger of :data:`ABSOLUTE_RESOLUTION` display units and :data:`RELATIVE_RESOLUTION` times the largest
    magnitude among the result's outputs of the same SI unit (the case's scale: an east error of 1e-12 arcsec
    beside a heading of 1.2 deg is the arithmetic's noise, not a result).

    Parameters
    ----------
    system : System
        The system whose declared outputs are shown.
    values : mapping of str to object
        Output name -> value in SI (the output's ``unit``).

    Returns
    -------
    dict of str to float
        Output name -> resolution, SI unit of that output.
    """
    scale: dict[str, float] = {}
    for output in system.outputs:
        value = _magnitude(values.get(output.name))
        scale[output.unit] = max(scale.get(output.unit, 0.0), value)
    found = {}
    for output in system.outputs:
        display_unit_si = 1.0 / float(to_unit(1.0, output.display)) if output.display else 1.0
        found[output.name] = max(ABSOLUTE_RESOLUTION * display_unit_si, RELATIVE_RESOLUTION * scale[output.unit])
    return found


def _magnitude(value) -> float:
    """|value| for a finite number; 0 for flags, missing, NaN and infinite values (they set no scale)."""
    if value is None or isinstance(value, (bool, np.bool_)):
        return 0.0
    try:
        number = abs(float(value))  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return 0.0
    return number if math.isfinite(number) else 0.0


def data_attributes(**values) -> dict[str, Any]:
    """``data-*`` attributes for a Dash component: ``data_attributes(param="x")`` -> ``{"data-param": "x"}``.

    Parameters
    ----------
    **values
        Attribute name (underscores become hyphens) -> value.

    Returns
    -------
    dict of str to object
        ``data-NAME`` -> value, to be passed to a component as keyword arguments.
    """
    return {f"data-{key.replace('_', '-')}": value for key, value in values.items()}


RESULT = "result"
"""Component-id type of a headline number: ``{"type": RESULT, "key": KEY}`` (with ``data-result="KEY"``)."""


def headline(system: System, values: Mapping[str, object], with_ids: bool = False) -> html.Table:
    """The system's outputs as a table of ``data-result`` numbers (values: SI, keyed as in ``to_dict``).

    ``with_ids`` gives each number an id, so that a callback can replace its text in place.

    Parameters
    ----------
    system : System
        The system whose declared outputs are the rows.
    values : mapping of str to object
        Output name -> value in SI (the output's ``unit``: rad, s, ...); a missing output shows ``-``.
    with_ids : bool
        Whether each number gets the id ``{"type": RESULT, "key": NAME}``.

    Returns
    -------
    dash.html.Table
        One row per output: description, number with its display unit, key.
    """
    floors = resolutions(system, values)
    rows = []
    for output in system.outputs:
        ident: dict[str, Any] = {"id": {"type": RESULT, "key": output.name}} if with_ids else {}
        rows.append(html.Tr([
            html.Th(output.description or output.name, scope="row"),
            html.Td(html.Span(quantity_text(values.get(output.name), output, floors[output.name]), **ident,
                              **data_attributes(result=output.name)), className="number"),
            html.Td(output.name, className="key"),
        ]))
    return html.Table(html.Tbody(rows), className="headline")


def headline_texts(system: System, values: Mapping[str, object]) -> list[str]:
    """The texts of :func:`headline`'s numbers, in the order of the system's outputs.

    Parameters
    ----------
    system : System
        The system whose declared outputs are shown.
    values : mapping of str to object
        Output name -> value in SI (the output's ``unit``); a missing output gives ``-``.

    Returns
    -------
    list of str
        Number and display unit per output (see :func:`quantity_text`; rounding noise shown as 0, see
        :func:`resolutions`).
    """
    floors = resolutions(system, values)
    return [quantity_text(values.get(output.name), output, floors[output.name]) for output in system.outputs]


def monte_carlo_table(system: System, statistics: Mapping[str, MonteCarloStatistics], members: int) -> html.Div:
    """Mean, standard deviation and 5 %/95 % points of every output over the members (display units).

    Parameters
    ----------
    system : System
        The system whose declared outputs are the rows.
    statistics : mapping of str to MonteCarloStatistics
        Output name -> its statistics over the members in SI (the output's ``unit``): ``mean``, ``std``,
        ``p05``, ``p95``, ``min``, ``max`` (None where not computed). Outputs whose ``min`` equals their
        ``max`` (no spread) are left out.
    members : int
        Monte Carlo members, number of (shown in the heading).

    Returns
    -------
    dash.html.Div
        A heading and a table of the statistics in each output's display unit.
    """
    header = html.Tr([html.Th("output")] + [html.Th(h) for h in ("mean", "std", "p05", "p95")])
    rows = []
    for output in system.outputs:
        stats = statistics.get(output.name)
        if stats is None or stats.min == stats.max:
            continue
        cells = []
        for key in ("mean", "std", "p05", "p95"):
            value = getattr(stats, key)
            cells.append(html.Td("-" if value is None else number_text(
                float(to_unit(value, output.display)) if output.display else float(value)), className="number"))
        rows.append(html.Tr([html.Th(display_label(output.name, output.shown_unit), scope="row"), *cells]))
    return html.Div([html.H3(f"Monte Carlo: {members} members"),
                     html.Table([html.Thead(header), html.Tbody(rows)], className="statistics")])


def reproduction_table(reproduction: Reproduction) -> html.Div:
    """The source's printed values beside the computed ones, with verdicts, constants and notes.

    Parameters
    ----------
    reproduction : Reproduction
        A system's reproduction of its source's published case (each row's printed and computed values are
        in the row's own ``unit``).

    Returns
    -------
    dash.html.Div
        Source, constants, the table (one row per printed number) and the notes.
    """
    headings = ("quantity", "printed", "where", "computed", "unit", "verdict", "note")
    rows = [html.Tr([
        html.Td(row.quantity), html.Td(row.printed or "-", className="number"), html.Td(row.where),
        html.Td(f"{row.computed:.6g}", className="number"), html.Td(row.unit),
        html.Td(row.verdict, className="verdict failed" if row.failed else "verdict"), html.Td(row.note),
    ]) for row in reproduction.rows]
    return html.Div([
        html.P(["Source: ", reproduction.source]),
        html.P(["Constants: ", reproduction.constants]),
        html.Table([html.Thead(html.Tr([html.Th(h) for h in headings])), html.Tbody(rows)],
                   className="reproduction"),
        html.Ul([html.Li(note) for note in reproduction.notes]) if reproduction.notes else None,
    ], className="reproduction-view")
