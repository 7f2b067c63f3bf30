"""A system's page (``/NAME``) and its reproduction page (``/NAME/reproduction``), generated from its System.

The controls are the system's parameters plus the options every ``run`` has
(``monte_carlo``, ``seed``, ``fidelity`` where offered). A change flows in two
steps: a quick check in the web server (each value parsed by the command
line's parser; a wrong one gets its message beside its control and nothing else
changes), then the run itself as a background job (its own process, so it can
be cancelled and two sessions never share state) with progress for Monte Carlo
members. What a job needs travels with the request: the values typed and the
page's session token; nothing about a user is kept in the server.
"""

from __future__ import annotations

import importlib
import io
import logging
import tempfile
import warnings
import zipfile
from pathlib import Path

from dash import ALL, Dash, Input, Output, State, dcc, html, no_update
from dash.exceptions import PreventUpdate

from schuler.contract import RUN_OPTIONS, System
from schuler.exceptions import SchulerError, as_options
from schuler.lab import views
from schuler.lab.controls import ERROR, PARAM, Names, controls, error_owner, parse_typed, typed_values
from schuler.lab.figures import GRAPH, block, empty, file_figures, interactive_figures, interactive_stems
from schuler.params import Parameter, ParameterSet
from schuler.registry import get_system

_LOG = logging.getLogger(__name__)

POLL_MS = 150
"""How often the browser asks whether a background job has finished, ms (it bounds the added latency; at 50 ms
four sessions' polls alone kept a loaded 2-core machine's web server busy and answers took 10-40 s)."""


ACTION_PAGES = {"align": {"compare": "Every self-alignment method on the same data, compared"}}
"""System name -> its actions that have a page of their own (``/NAME/ACTION``) and the link's text."""


OFFERED_NAMES = {"aided": {"trajectory": ("schuler.navigate.evaluation", "TRAJECTORIES", False),
                           "imu": ("schuler.imu.spec", "GRADES", False),
                           "aiding": ("schuler.aided.evaluation", "AIDING", True)}}
"""System name -> its text parameters whose controls offer names: (module, attribute holding the names the
parameter takes, whether it takes several). The names are read from where the parameter checks them, so that a
name added there appears on the page."""


def offered_names(system: System) -> dict[str, Names]:
    """The names a system page's text controls offer (:data:`OFFERED_NAMES`), read from their modules.

    Parameters
    ----------
    system : System
        Whose page is drawn (by its name).

    Returns
    -------
    dict of str to Names
        Parameter name -> its names; empty for a system without such parameters.
    """
    return {name: Names(tuple(getattr(importlib.import_module(module), attribute)), several)
            for name, (module, attribute, several) in OFFERED_NAMES.get(system.name, {}).items()}


def page_parameters(system: System) -> ParameterSet:
    """The page's controls: the system's parameters, ``monte_carlo``, ``seed`` and ``fidelity`` where offered.

    Parameters
    ----------
    system : System
        The system the page shows.

    Returns
    -------
    ParameterSet
        The system's parameters followed by ``monte_carlo`` and ``seed`` (and ``fidelity``, a choice of the
        system's fidelities, the first being the default, when it offers any).
    """
    extra = list(RUN_OPTIONS)
    if system.fidelities:
        extra.append(Parameter("fidelity", "", system.fidelities[0],
                               f"How outputs are computed: {', '.join(system.fidelities)}.",
                               choices=system.fidelities, kind="choice"))
    return system.parameters + extra


def run_typed(system: System, typed: dict[str, str], progress=None):
    """Run the case the user typed (values parsed as the command line parses them).

    Parameters
    ----------
    system : System
        The system to run.
    typed : dict of str to str
        Parameter name -> the text typed in its field (a number in the parameter's display unit, or a value
        with a unit), only for the fields the user changed; may include ``monte_carlo``, ``seed``,
        ``fidelity``.
    progress : callable, optional
        ``progress(done, total)``, called as Monte Carlo members finish (members, number of).

    Returns
    -------
    object
        What ``system.run`` returns for the case (the system's result type).

    Raises
    ------
    SchulerError
        A typed value does not parse (the first message), or the run refuses the case.
    """
    parameters = page_parameters(system)
    case, errors = parse_typed(parameters, typed)
    if case is None:
        raise SchulerError(next(iter(errors.values())))
    values = {name: case[name] for name in case.given}
    options = {name: values.pop(name) for name in ("monte_carlo", "seed", "fidelity") if name in values}
    return system.run(progress=progress, **options, **values)


def layout(system: System) -> html.Div:
    """The page of one system: controls on the left, status, headline numbers and figures on the right.

    Parameters
    ----------
    system : System
        The system the page shows (its parameters become the controls).

    Returns
    -------
    dash.html.Div
        The page's component tree.
    """
    name = system.name
    return html.Div([
        dcc.Store(id="system-name", data=name),
        dcc.Store(id="run-error"),
        dcc.Store(id="figure-request"),
        dcc.Store(id="shown-case"),
        dcc.Store(id="rerun", data=0),
        html.Div([
            html.H1(system.title),
            html.P(["Source: ", system.reference], className="source"),
            html.P([dcc.Link("Reproduction table of the source's published case", href=f"/{name}/reproduction",
                             id="reproduction-link"),
                    f" (schuler {name} reproduce)"]),
            *[html.P([dcc.Link(title, href=f"/{name}/{action}", id=f"{action}-link"), f" (schuler {name} {action})"])
              for action, title in ACTION_PAGES.get(name, {}).items()],
        ], className="page-head"),
        html.Div([
            html.Aside([html.H2("Parameters"),
                        html.P("Type a value (a bare number is in the unit shown, or write a unit: "
                               "'0.02 deg/h'); Enter or leaving the field applies it.", className="hint"),
                        *controls(page_parameters(system), names=offered_names(system))],
                       className="controls"),
            html.Main([
                html.Div([html.Span("running", className="label"), html.Progress(id="run-progress"),
                          html.Button("Cancel", id="run-cancel", disabled=True, className="cancel")],
                         id="run-status", className="status"),
                html.Div(id="run-message", className="page-error", role="alert"),
                html.Div(id="run-notes", className="notes"),
                html.H2("Headline numbers"),
                views.headline(system, {}, with_ids=True),
                html.Div(id="monte-carlo"),
                html.H2("Figures"),
                html.Div([block(stem, empty("running..."), graph_id={"type": GRAPH, "figure": stem})
                          for stem in interactive_stems(system)], id="figures", className="figures"),
                html.Div([html.Button("Download figures and data (PNG, SVG, CSV)", id="download-files"),
                          html.Span(id="download-status", className="hint"), dcc.Download(id="download")],
                         className="exports"),
            ], className="results"),
        ], className="workbench"),
    ])


def reproduction_layout(system: System) -> html.Div:
    """The reproduction page of one system: the table its ``reproduce`` computes, filled in by a background job.

    Parameters
    ----------
    system : System
        The system whose reproduction table is shown.

    Returns
    -------
    dash.html.Div
        The page's component tree (the table's place is empty until the job ends).
    """
    return html.Div([
        dcc.Store(id="reproduction-system", data=system.name),
        html.H1(f"{system.title}: reproduction"),
        html.P([dcc.Link(f"back to the {system.name} page", href=f"/{system.name}"),
                f" (the same table: schuler {system.name} reproduce)"]),
        dcc.Loading(html.Div(id="reproduction-table"), type="default"),
    ])


def register(app: Dash) -> None:
    """The callbacks of every system page (one set: the page says which system it shows).

    Parameters
    ----------
    app : Dash
        The lab's application, on which the callbacks are registered (it needs a background callback manager).
    """

    @app.callback(
        Output({"type": ERROR, "name": ALL}, "children"),
        Input({"type": PARAM, "name": ALL}, "value"),
        Input("run-error", "data"),
        State({"type": PARAM, "name": ALL}, "id"),
        State("system-name", "data"),
    )
    def check(values, run_error, ids, name):
        parameters = page_parameters(get_system(name))
        typed = typed_values(parameters, ids, values)
        _, errors = parse_typed(parameters, typed)
        if run_error and run_error.get("typed") == typed and run_error.get("name"):
            errors.setdefault(run_error["name"], run_error["message"])
        return [errors.get(ident["name"], "") for ident in ids]

    # The run starts from the inputs themselves (not after the check above): one round trip less. A case that
    # does not parse changes nothing; the check shows why.
    @app.callback(
        Output({"type": views.RESULT, "key": ALL}, "children"),
        Output("monte-carlo", "children"),
        Output({"type": GRAPH, "figure": ALL}, "figure"),
        Output("figure-request", "data"),
        Output("run-error", "data"),
        Output("run-message", "children"),
        Output("run-notes", "children"),
        Output("shown-case", "data"),
        Input({"type": PARAM, "name": ALL}, "value"),
        Input("rerun", "data"),
        State({"type": PARAM, "name": ALL}, "id"),
        State("system-name", "data"),
        State("session", "data"),
        background=True,
        interval=POLL_MS,
        progress=[Output("run-progress", "value"), Output("run-progress", "max")],
        running=[(Output("run-status", "className"), "status running", "status"),
                 (Output("run-cancel", "disabled"), False, True)],
        cancel=[Input("run-cancel", "n_clicks")],
    )
    def run(set_progress, values, rerun, ids, name, session):
        system = get_system(name)
        typed = typed_values(page_parameters(system), ids, values)
        if parse_typed(page_parameters(system), typed)[0] is None:
            raise PreventUpdate
        unchanged = (no_update,) * 4
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                result = run_typed(system, typed, progress=lambda done, total: set_progress((done, total)))
            except SchulerError as error:
                owner, message = error_owner(page_parameters(system), error)
                return (*unchanged, {"typed": typed, "name": owner, "message": message}, "" if owner else message,
                        no_update, typed)
            except Exception as error:  # a bug must not leave the page waiting: say it in one line
                return *unchanged, None, internal_error(error), no_update, typed
        data = result.to_dict()
        values = {o.name: getattr(result, o.name, data.get(o.name)) for o in system.outputs}
        summary = getattr(result, "monte_carlo", None)
        statistics = views.monte_carlo_table(system, summary.statistics, summary.members) if summary else None
        figures = interactive_figures(system, result)
        request = typed if figures is None else no_update
        return (views.headline_texts(system, values), statistics, figures or [], request, None, "",
                notes(caught), typed)

    # When a result arrives for other values than the fields now hold (a change made while an earlier run
    # was starting can lose its own run), run again: the page always ends showing what its fields say.
    @app.callback(
        Output("rerun", "data"),
        Input("shown-case", "data"),
        State({"type": PARAM, "name": ALL}, "value"),
        State({"type": PARAM, "name": ALL}, "id"),
        State("system-name", "data"),
        State("rerun", "data"),
        prevent_initial_call=True,
    )
    def follow(shown, values, ids, name, rerun):
        parameters = page_parameters(get_system(name))
        typed = typed_values(parameters, ids, values)
        if shown == typed or parse_typed(parameters, typed)[0] is None:
            raise PreventUpdate
        return (rerun or 0) + 1

    @app.callback(
        Output("figures", "children", allow_duplicate=True),
        Input("figure-request", "data"),
        State("system-name", "data"),
        State("session", "data"),
        background=True,
        interval=4 * POLL_MS,
        running=[(Output("run-status", "className"), "status running", "status"),
                 (Output("run-cancel", "disabled"), False, True)],
        cancel=[Input("run-cancel", "n_clicks")],
        prevent_initial_call=True,
    )
    def render_files(typed, name, session):
        if typed is None:
            raise PreventUpdate
        system = get_system(name)
        images = file_figures(system, run_typed(system, typed))
        return [html.Figure([html.Img(src=uri, alt=stem), html.Figcaption(stem)], **views.data_attributes(figure=stem))
                for stem, uri in images] or html.P("this run has no figures")

    @app.callback(
        Output("download", "data"),
        Output("download-status", "children"),
        Input("download-files", "n_clicks"),
        State({"type": PARAM, "name": ALL}, "value"),
        State({"type": PARAM, "name": ALL}, "id"),
        State("system-name", "data"),
        State("session", "data"),
        background=True,
        interval=4 * POLL_MS,
        running=[(Output("download-files", "disabled"), True, False),
                 (Output("download-status", "children"), "writing files...", "")],
        prevent_initial_call=True,
    )
    def download(clicks, values, ids, name, session):
        system = get_system(name)
        try:
            archive = files_archive(system, run_typed(system, typed_values(page_parameters(system), ids, values)))
        except SchulerError as error:
            return no_update, as_options(str(error))
        return dcc.send_bytes(archive, f"{name}_lab.zip"), ""

    @app.callback(
        Output("reproduction-table", "children"),
        Input("reproduction-system", "data"),
        State("session", "data"),
        background=True,
        interval=4 * POLL_MS,
    )
    def reproduction(name, session):
        return views.reproduction_table(get_system(name).reproduce())


def internal_error(error: Exception) -> str:
    """The one line a page shows for an unexpected failure; its traceback goes to the server's log.

    Parameters
    ----------
    error : Exception
        The unexpected exception (logged with its traceback at ERROR level on this module's logger).

    Returns
    -------
    str
        ``internal error: TYPE: MESSAGE``, cut at the message's first line break.
    """
    _LOG.error("unexpected failure behind a page", exc_info=error)
    return f"internal error: {type(error).__name__}: {error}".splitlines()[0]


def notes(caught) -> list:
    """Warnings raised during a computation, one line each (the command line prints them on stderr).

    Parameters
    ----------
    caught : iterable of warnings.WarningMessage
        The warnings recorded by ``warnings.catch_warnings(record=True)``.

    Returns
    -------
    list of dash.html.P
        One ``p.warning`` per warning.
    """
    return [html.P(f"warning: {w.message}", className="warning") for w in caught]


def files_archive(system: System, result) -> bytes:
    """The system's files of a result (figures as PNG and SVG, data as CSV) in one zip archive.

    Parameters
    ----------
    system : System
        The system that computed ``result`` (its ``write`` writes the files).
    result : object
        What the system's ``run`` returned.

    Returns
    -------
    bytes
        The zip archive (deflated), one entry per file written, by file name.
    """
    buffer = io.BytesIO()
    with tempfile.TemporaryDirectory(prefix="schuler-lab-") as folder:
        paths = system.write(result, Path(folder))
        with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
            for path in paths:
                archive.write(path, path.name)
    return buffer.getvalue()
