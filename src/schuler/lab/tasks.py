"""The KPI lab tasks as guided pages: ``/align/task1``, ``task2``, ``task3``, ``task5``.

Each page gives the manual's task and the control questions it helps to answer,
the gyrocompassing parameters as controls (generated from the align system, as
on its own page), and the figures the task asks for, each exportable as PNG or
SVG (drawn by the browser) and CSV (computed again by the server from the same
inputs). Everything is computed through the align :class:`~schuler.contract.System`:
``run`` for one case, ``evaluate_values`` for a sweep over one parameter.

Task 1 sweeps one of the manual's parameters and draws accuracy and time
against it with the constraints delta < 0.4 rad, beta < 0.01 rad and
delta' < 0.2 rad/s, each case that breaks one marked; task 2 sets the
simplified model (1.19) beside the chosen one; task 3 shows the level errors in
mu, nu (model (1.17)) and beta, alpha; task 5 draws the phase trajectory.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from dash import ALL, MATCH, ClientsideFunction, Dash, Input, Output, State, dcc, html, no_update
from dash.exceptions import PreventUpdate

from schuler.contract import System
from schuler.exceptions import SchulerError, as_options
from schuler.gyrocompassing.results import case_runs
from schuler.gyrocompassing.simulation import MAX_BETA, MAX_DELTA, MAX_DELTA_RATE
from schuler.lab import figures, manual, views
from schuler.lab.controls import controls, error_owner, parse_typed, typed_values
from schuler.lab.system_page import POLL_MS, internal_error
from schuler.params import Parameter, ParameterSet
from schuler.registry import get_system
from schuler.units import to_unit

TASKS = manual.TASK_TITLES
PAGES = {f"task{n}": n for n in TASKS}
"""Page name (``task1``) -> task number."""

TASK_PARAM = "task-param"
SWEEP_PARAM = "sweep-param"

CONSTRAINTS = (("max_abs_delta_rad", "|delta|", MAX_DELTA, "rad"), ("max_abs_beta_rad", "|beta|", MAX_BETA, "rad"),
               ("max_abs_delta_rate_rad_s", "|delta'|", MAX_DELTA_RATE, "rad/s"))
"""The task-1 constraints (KPI manual, Sec. 3): output key, symbol, limit, unit."""

SWEEP_RANGES = {
    "latitude": ("0", "80"), "drift_x": ("-0.02", "0.02"), "drift_y": ("-0.02", "0.02"),
    "drift_z": ("-0.02", "0.02"), "c_a": ("5", "60"), "c_gamma": ("0.01", "0.2"),
    "latitude_error": ("-10", "10"), "accel_bias_x": ("-0.001", "0.001"), "accel_bias_y": ("-0.001", "0.001"),
    "azimuth": ("0", "360"),
}
"""The manual's parameters of task 1 and the range each sweep starts with (display units)."""

STARTING_CASE = {"drift_x": "0.01", "drift_y": "0.01", "drift_z": "0.01"}
"""What a task page starts from (display units): residual drifts of 0.01 deg/h about every platform axis, the
order the manual's gyros are calibrated to, so that every parameter swept moves the azimuth error."""

SWEEP_CHUNK = 4
"""Cases evaluated per step of a sweep (progress is reported, and a cancel takes effect, between steps)."""

SWEEP = ParameterSet((
    Parameter("sweep", "", "latitude", "The parameter varied.", choices=tuple(SWEEP_RANGES), kind="choice"),
    Parameter("sweep_from", "", SWEEP_RANGES["latitude"][0], "First value, in the varied parameter's unit.",
              kind="text"),
    Parameter("sweep_to", "", SWEEP_RANGES["latitude"][1], "Last value, in the varied parameter's unit.", kind="text"),
    Parameter("sweep_points", "", 21, "Cases in the sweep.", minimum=2, maximum=61, kind="integer"),
), owner="sweep")
"""The sweep controls of tasks 1 and 2."""


@dataclass
class TaskView:
    """What a task page shows: tables, figures (stem, figure, data) and notes."""

    tables: list = field(default_factory=list)
    figures: list[tuple[str, object, pd.DataFrame]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def layout(system: System, page: str) -> html.Div:
    """The guided page of one task.

    Parameters
    ----------
    system : System
        The ``align`` system (its parameters become the controls).
    page : {"task1", "task2", "task3", "task5"}
        Which task's page.

    Returns
    -------
    dash.html.Div
        The page's component tree: the task's text and questions, the controls (with the sweep's for tasks 1
        and 2) starting from :data:`STARTING_CASE`, and the places of tables and figures.
    """
    number = PAGES[page]
    sweeps = number in (1, 2)
    # numbered in order on the page, each with its number in the manual's list of control questions
    questions = [html.Li([html.Span(f"question {q} of the manual", className="manual-number"),
                          html.Span(manual.QUESTIONS[q], className="question"),
                          html.Span(manual.HINTS.get(q, ""), className="hint")])
                 for q in manual.TASK_QUESTIONS[number]]
    aside = [html.H2("Parameters"), *controls(system.parameters, id_type=TASK_PARAM, values=STARTING_CASE)]
    if sweeps:
        aside[1:1] = [html.H3("Sweep"), *controls(SWEEP, id_type=SWEEP_PARAM), html.H3("Case")]
    return html.Div([
        dcc.Store(id="task-page", data=page),
        html.Div([html.H1(f"Task {number}: {TASKS[number]}"),
                  html.Blockquote(manual.TASK_TEXT[number], className="manual"),
                  html.H2("Control questions (from the manual's list)"), html.Ol(questions, className="questions")],
                 className="page-head"),
        html.Div([
            html.Aside(aside, className="controls"),
            html.Main([
                html.Div([html.Span("running", className="label"), html.Progress(id="task-progress"),
                          html.Button("Cancel", id="task-cancel", disabled=True, className="cancel")],
                         id="task-status", className="status"),
                html.Div(id="task-message", className="page-error", role="alert"),
                html.Div(id="task-notes", className="notes"),
                html.Div(id="task-tables"),
                html.Div(id="task-figures", className="figures"),
            ], className="results"),
        ], className="workbench"),
    ])


def sweep_values(system: System, sweep_typed: dict[str, str]) -> tuple[str, np.ndarray]:
    """The swept parameter and its SI values; ends parsed by that parameter (its range and unit).

    Parameters
    ----------
    system : System
        The ``align`` system (the swept parameter's unit and range are its own).
    sweep_typed : dict of str to str
        The sweep controls' texts as typed: ``sweep`` (the parameter's name), ``sweep_from`` and ``sweep_to``
        (in that parameter's display unit, or with a unit), ``sweep_points`` (cases, number of); a missing end
        takes the parameter's range in :data:`SWEEP_RANGES`.

    Returns
    -------
    name : str
        The swept parameter.
    values : numpy.ndarray
        Its values, evenly spaced from first to last end, in SI (rad, rad/s, ...), shape (sweep_points,).

    Raises
    ------
    SchulerError
        A sweep control does not parse, or an end is outside the parameter's range.
    """
    case, errors = parse_typed(SWEEP, sweep_typed)
    if case is None:
        raise SchulerError(next(iter(errors.values())))
    name = case["sweep"]
    swept = system.parameters[name]
    default_from, default_to = SWEEP_RANGES[name]
    low = swept.parse(sweep_typed.get("sweep_from") or default_from, "--sweep-from")
    high = swept.parse(sweep_typed.get("sweep_to") or default_to, "--sweep-to")
    return name, np.linspace(low, high, case["sweep_points"])


def sweep_table(system: System, values: dict, name: str, x: np.ndarray, progress=None,
                models: tuple[str, ...] = ()) -> pd.DataFrame:
    """Simulated and analytic outputs of the case with ``name`` swept over ``x`` (display units).

    ``models`` adds the simulated azimuth error of other models (column
    ``<model>_azimuth_error_arcmin``).

    Parameters
    ----------
    system : System
        The ``align`` system.
    values : dict
        The case's other parameters, by name, in SI (as a parsed case holds them).
    name : str
        The swept parameter.
    x : numpy.ndarray
        Its values, shape (N,), SI.
    progress : callable, optional
        ``progress(done, total)``, called after each chunk of :data:`SWEEP_CHUNK` cases (cases, number of).
    models : tuple of str
        Other models whose simulated azimuth error is added (``"simplified"``).

    Returns
    -------
    pandas.DataFrame
        One row per value of ``x``: first the swept parameter in its display unit (column ``NAME (UNIT)``),
        then azimuth and level errors in arcmin (the full-minus-simplified difference in arcsec), settling
        times in s, the constraints' maxima in SI (rad, rad/s) and ``constraints_ok``.
    """
    outputs: dict[str, list] = {}
    extra: dict[str, list] = {model: [] for model in models}
    for start in range(0, x.size, SWEEP_CHUNK):
        chunk = x[start:start + SWEEP_CHUNK]
        part = system.evaluate_values({**values, name: chunk}, fidelity="simulated")
        for key, column in part.items():
            outputs.setdefault(key, []).append(column)
        for model in models:
            extra[model].append(system.evaluate_values({**values, name: chunk, "model": model},
                                                       fidelity="simulated")["azimuth_error_rad"])
        if progress is not None:
            progress(min(start + SWEEP_CHUNK, x.size), x.size)
    joined = {key: np.concatenate(parts) for key, parts in outputs.items()}
    swept = system.parameters[name]
    table = {f"{name} ({swept.unit})" if swept.unit else name: to_unit(x, swept.unit) if swept.unit else x,
             "azimuth_error_arcmin": to_unit(joined["azimuth_error_rad"], "arcmin"),
             "azimuth_error_analytic_arcmin": to_unit(joined["azimuth_error_analytic_rad"], "arcmin"),
             "full_minus_simplified_arcsec": to_unit(joined["full_minus_simplified_rad"], "arcsec"),
             "level_error_beta_arcmin": to_unit(joined["level_error_beta_rad"], "arcmin"),
             "settling_time_s": joined["settling_time_s"],
             "settling_time_simulated_s": joined["settling_time_simulated_s"]}
    for key, _, _, _ in CONSTRAINTS:
        table[key] = joined[key]
    table["constraints_ok"] = joined["constraints_ok"]
    for model, parts in extra.items():
        table[f"{model.replace('-', '_')}_azimuth_error_arcmin"] = to_unit(np.concatenate(parts), "arcmin")
    return pd.DataFrame(table)


def history_table(run) -> pd.DataFrame:
    """A run's histories in display units (arcmin for delta, arcsec for the level errors).

    Parameters
    ----------
    run : CaseRun
        A gyrocompassing run (histories in SI: ``time`` s, angles rad, ``delta_rate`` rad/s).

    Returns
    -------
    pandas.DataFrame
        Columns ``t_s`` (s), ``delta_arcmin``, ``beta_arcsec`` (and ``alpha_arcsec``, ``mu_arcsec``,
        ``nu_arcsec`` where the run has them) and ``delta_rate_rad_s`` (rad/s).
    """
    table = {"t_s": run.time, "delta_arcmin": to_unit(run.delta, "arcmin"), "beta_arcsec": to_unit(run.beta, "arcsec")}
    for name in ("alpha", "mu", "nu"):
        if getattr(run, name) is not None:
            table[f"{name}_arcsec"] = to_unit(getattr(run, name), "arcsec")
    table["delta_rate_rad_s"] = run.delta_rate
    return pd.DataFrame(table)


def constraint_panel(result) -> html.Table:
    """The three constraints of the case: largest value over the run, limit, and whether it holds.

    Parameters
    ----------
    result : AlignmentRun
        The ``align`` run's result; its ``max_abs_delta_rad``, ``max_abs_beta_rad`` (rad) and
        ``max_abs_delta_rate_rad_s`` (rad/s) are compared with the limits of :data:`CONSTRAINTS`.

    Returns
    -------
    dash.html.Table
        One row per constraint, with ``data-constraint`` naming it.
    """
    rows = []
    for key, symbol, limit, unit in CONSTRAINTS:
        value = getattr(result, key)
        shown = value is not None and not np.isnan(value)
        holds = shown and value < limit
        rows.append(html.Tr([html.Th(f"{symbol} < {limit:g} {unit}", scope="row"),
                             html.Td(f"{views.number_text(value)} {unit}" if shown else "-",
                                     className="number"),
                             html.Td("holds" if holds else "VIOLATED", className="ok" if holds else "violated")],
                            **views.data_attributes(constraint=key.removeprefix("max_abs_").removesuffix("_rad_s")
                                                    .removesuffix("_rad"))))
    return html.Table([html.Caption("Constraints over the run (KPI manual, task 1)"), html.Tbody(rows)],
                      className="constraints")


def sweep_violations(table: pd.DataFrame) -> list[str]:
    """One line per constraint that some case of a sweep breaks, naming those cases.

    Parameters
    ----------
    table : pandas.DataFrame
        A sweep as :func:`sweep_table` returns it (first column the swept parameter in its display unit,
        constraints' maxima in SI).

    Returns
    -------
    list of str
        One line per constraint broken, naming up to 8 of the swept values (display unit) where it is.
    """
    x_column = table.columns[0]
    lines = []
    for key, symbol, limit, unit in CONSTRAINTS:
        broken = table[x_column][~(table[key] < limit)]
        if len(broken):
            shown = ", ".join(views.number_text(float(v)) for v in broken[:8]) + (" ..." if len(broken) > 8 else "")
            lines.append(f"{symbol} < {limit:g} {unit} is violated at {x_column} = {shown}")
    return lines


def compute(system: System, page: str, typed: dict[str, str], sweep_typed: dict[str, str], progress=None) -> TaskView:
    """Everything a task page shows for the typed case (and sweep).

    Parameters
    ----------
    system : System
        The ``align`` system.
    page : {"task1", "task2", "task3", "task5"}
        Which task's page.
    typed : dict of str to str
        Parameter name -> the text typed (display unit, or a value with a unit), only for fields changed.
    sweep_typed : dict of str to str
        The sweep controls' texts (see :func:`sweep_values`); used by tasks 1 and 2 only.
    progress : callable, optional
        ``progress(done, total)`` during the sweep (cases, number of).

    Returns
    -------
    TaskView
        Tables, figures (stem, plotly figure, its data as a table) and notes (warnings, violations).

    Raises
    ------
    SchulerError
        A typed value does not parse, or the run refuses the case.
    """
    number = PAGES[page]
    case, errors = parse_typed(system.parameters, typed)
    if case is None:
        raise SchulerError(next(iter(errors.values())))
    values = {name: case[name] for name in case.given}
    if number == 3:
        values["model"] = "full"  # mu, nu are the states of (1.17) only
    view = TaskView()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result: Any = system.run(**values)
        simulated = case_runs(result)
        assert simulated is not None  # the task pages run the default fidelity, simulated
        run, simplified = simulated
        runs = {f"{result.model} model": run}
        if result.model != "simplified":
            runs["simplified (1.19)"] = simplified
        view.tables.append(views.headline(system, {o.name: getattr(result, o.name) for o in system.outputs}))
        if number in (1, 2):
            view.tables.insert(0, constraint_panel(result))
            name, x = sweep_values(system, sweep_typed)
            others = ("simplified",) if number == 2 and result.model != "simplified" else ()
            table = sweep_table(system, values, name, x, progress, models=others)
            columns = {c: table[c].to_numpy() for c in table.columns[1:]}
            view.notes += sweep_violations(table)
            view.figures.append((f"task{number}_sweep", figures.sweep_curves(
                table.iloc[:, 0].to_numpy(), table.columns[0], columns, CONSTRAINTS,
                title=f"Accuracy and time against {name} (task {number})"), table))
        if number in (1, 2):
            view.figures.append((f"task{number}_time_history", figures.time_history(runs), history_table(run)))
        elif number == 3:
            view.figures.append(("task3_level_angles", figures.level_angles(run), history_table(run)))
            view.figures.append(("task3_time_history", figures.time_history(runs), history_table(run)))
        else:
            view.figures.append(("task5_phase_trajectory", figures.phase_trajectory(runs), history_table(run)))
    view.notes += [f"warning: {w.message}" for w in caught]
    return view


def wanted_case(values, sweep_texts, ids, sweep_ids) -> tuple[dict, dict[str, str], dict[str, str]]:
    """The values typed on a task page ({"case": ..., "sweep": ...}) and the messages of the wrong ones.

    Parameters
    ----------
    values : list
        The case controls' texts, in the order of ``ids`` (None for a field never filled).
    sweep_texts : list
        The sweep controls' texts, in the order of ``sweep_ids``.
    ids : list of dict
        Component ids of the case controls (``{"type": ..., "name": NAME}``).
    sweep_ids : list of dict
        Component ids of the sweep controls (empty on pages without a sweep).

    Returns
    -------
    wanted : dict
        ``{"case": typed, "sweep": sweep_typed}``: name -> text as typed (display units).
    errors : dict of str to str
        Case parameter name -> its one-line message.
    sweep_errors : dict of str to str
        Sweep control name -> its one-line message.
    """
    system = get_system("align")
    typed = typed_values(system.parameters, ids, values)
    sweep_typed = {i["name"]: str(v) for i, v in zip(sweep_ids, sweep_texts) if v not in (None, "")}
    _, errors = parse_typed(system.parameters, typed)
    sweep_errors: dict[str, str] = {}
    if sweep_ids:
        try:
            sweep_values(system, sweep_typed)
        except SchulerError as error:
            owner, message = error_owner(SWEEP, error)
            sweep_errors[owner or "sweep"] = message
    return {"case": typed, "sweep": sweep_typed}, errors, sweep_errors


def register(app: Dash) -> None:
    """The callbacks of the task pages.

    Parameters
    ----------
    app : Dash
        The lab's application, on which the callbacks are registered (it needs a background callback manager).
    """

    @app.callback(
        Output({"type": f"{TASK_PARAM}-error", "name": ALL}, "children"),
        Output({"type": f"{SWEEP_PARAM}-error", "name": ALL}, "children"),
        Input({"type": TASK_PARAM, "name": ALL}, "value"),
        Input({"type": SWEEP_PARAM, "name": ALL}, "value"),
        State({"type": TASK_PARAM, "name": ALL}, "id"),
        State({"type": SWEEP_PARAM, "name": ALL}, "id"),
    )
    def check(values, sweep_texts, ids, sweep_ids):
        _, errors, sweep_errors = wanted_case(values, sweep_texts, ids, sweep_ids)
        return [errors.get(i["name"], "") for i in ids], [sweep_errors.get(i["name"], "") for i in sweep_ids]

    @app.callback(
        Output({"type": SWEEP_PARAM, "name": "sweep_from"}, "value"),
        Output({"type": SWEEP_PARAM, "name": "sweep_to"}, "value"),
        Input({"type": SWEEP_PARAM, "name": "sweep"}, "value"),
        prevent_initial_call=True,
    )
    def sweep_range(name):
        if name not in SWEEP_RANGES:
            raise PreventUpdate
        return SWEEP_RANGES[name]

    @app.callback(
        Output("task-tables", "children"),
        Output("task-figures", "children"),
        Output("task-message", "children"),
        Output("task-notes", "children"),
        Input({"type": TASK_PARAM, "name": ALL}, "value"),
        Input({"type": SWEEP_PARAM, "name": ALL}, "value"),
        State({"type": TASK_PARAM, "name": ALL}, "id"),
        State({"type": SWEEP_PARAM, "name": ALL}, "id"),
        State("task-page", "data"),
        State("session", "data"),
        background=True,
        interval=POLL_MS,
        progress=[Output("task-progress", "value"), Output("task-progress", "max")],
        running=[(Output("task-status", "className"), "status running", "status"),
                 (Output("task-cancel", "disabled"), False, True)],
        cancel=[Input("task-cancel", "n_clicks")],
    )
    def run(set_progress, values, sweep_texts, ids, sweep_ids, page, session):
        wanted, errors, sweep_errors = wanted_case(values, sweep_texts, ids, sweep_ids)
        if errors or sweep_errors:
            raise PreventUpdate
        try:
            view = compute(get_system("align"), page, wanted["case"], wanted["sweep"],
                           progress=lambda done, total: set_progress((done, total)))
        except SchulerError as error:
            return no_update, no_update, as_options(str(error)), no_update
        except Exception as error:  # a bug must not leave the page waiting: say it in one line
            return no_update, no_update, internal_error(error), no_update
        notes = [html.P(n, className="violated" if " is violated " in n else "warning") for n in view.notes]
        return view.tables, [figures.block(stem, fig, csv=True) for stem, fig, _ in view.figures], "", notes

    @app.callback(
        Output({"type": "csv-download", "figure": MATCH}, "data"),
        Input({"type": "csv-export", "figure": MATCH}, "n_clicks"),
        State({"type": "csv-export", "figure": MATCH}, "id"),
        State({"type": TASK_PARAM, "name": ALL}, "value"),
        State({"type": SWEEP_PARAM, "name": ALL}, "value"),
        State({"type": TASK_PARAM, "name": ALL}, "id"),
        State({"type": SWEEP_PARAM, "name": ALL}, "id"),
        State("task-page", "data"),
        State("session", "data"),
        background=True,
        interval=4 * POLL_MS,
        prevent_initial_call=True,
    )
    def csv(clicks, ident, values, sweep_texts, ids, sweep_ids, page, session):
        wanted, _, _ = wanted_case(values, sweep_texts, ids, sweep_ids)
        view = compute(get_system("align"), page, wanted["case"], wanted["sweep"])
        frame = next(frame for stem, _, frame in view.figures if stem == ident["figure"])
        return dcc.send_data_frame(frame.to_csv, f"{ident['figure']}.csv", index=False)

    app.clientside_callback(
        ClientsideFunction(namespace="lab", function_name="saveImage"),
        Output({"type": "image-export", "figure": MATCH, "format": MATCH}, "title"),
        Input({"type": "image-export", "figure": MATCH, "format": MATCH}, "n_clicks"),
        State({"type": "image-export", "figure": MATCH, "format": MATCH}, "id"),
        prevent_initial_call=True,
    )
