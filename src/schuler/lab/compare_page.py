"""The alignment comparison's page (``/align/compare``): ``schuler align compare`` in the browser.

The controls are the action's own options (generated as a system page's are:
display units, defaults, ranges, the command line's parser and messages). A
change runs the action as a background job and shows every method's roll,
pitch and heading with its 1-sigma and accuracy limits (each number a
``span[data-result="methods.NAME.KEY"]``), and the action's own figure (the PNG
its ``write_files`` draws, as the lab shows every figure it has no interactive
version of).
"""

from __future__ import annotations

import warnings
from functools import partial

from dash import ALL, Dash, Input, Output, State, dcc, html, no_update
from dash.exceptions import PreventUpdate

from schuler import contract
from schuler.contract import Action
from schuler.exceptions import SchulerError
from schuler.lab import views
from schuler.lab.controls import controls, error_owner, parse_typed, typed_values
from schuler.lab.figures import png_figures
from schuler.lab.system_page import POLL_MS, internal_error, notes
from schuler.registry import get_system

SYSTEM = "align"
ACTION = "compare"
"""The page shows ``schuler align compare``: the ``compare`` action of the align system."""

PAGE_PARAM = "compare-param"
"""Component-id type of the page's inputs (apart from a system page's, whose callbacks would otherwise fire)."""
PAGE_ERROR = f"{PAGE_PARAM}-error"

STARTING_CASE = {"imu": "tactical", "duration": "120"}
"""What the page starts from (display units): the action needs a record or a grade, and a 2-minute simulated
record computes in a fraction of a second where the command's 300 s take longer (every method's history)."""

COLUMNS = (
    contract.Output("roll_rad", "rad", "deg", "roll"),
    contract.Output("pitch_rad", "rad", "deg", "pitch"),
    contract.Output("heading_rad", "rad", "deg", "heading"),
    contract.Output("heading_sigma_rad", "rad", "arcmin", "heading 1-sigma"),
    contract.Output("convergence_time_s", "s", "", "converged"),
    contract.Output("limit_roll_rad", "rad", "arcsec", "roll limit"),
    contract.Output("limit_pitch_rad", "rad", "arcsec", "pitch limit"),
    contract.Output("limit_heading_rad", "rad", "arcmin", "heading limit"),
)
"""The table's columns: a method's key in the result, its SI and display units, the heading shown."""


def compare_action() -> Action:
    """The ``align compare`` action, as the align system offers it to the command line."""
    return next(action for action in get_system(SYSTEM).actions if action.name == ACTION)


def run_typed(typed: dict[str, str]):
    """Run the comparison the user typed (values parsed as the command line parses them).

    Parameters
    ----------
    typed : dict of str to str
        Option name -> the text typed in its field (a number in the option's display unit, or a value with a
        unit), only for the fields the user changed.

    Returns
    -------
    AlignmentComparison
        What ``schuler align compare`` computes for the same options.
    """
    action = compare_action()
    case, errors = parse_typed(action.parameters, typed)
    if case is None:
        raise SchulerError(next(iter(errors.values())))
    return action.function(**{name: case[name] for name in case.given})


def method_table(methods: dict[str, dict] | None = None) -> html.Table:
    """Every method's numbers as ``span[data-result="methods.NAME.KEY"]`` in display units (``-``: none).

    Parameters
    ----------
    methods : dict of str to dict, optional
        ``methods`` of the comparison's JSON: method name -> its values in SI (rad, s); none: an empty table.
    """
    header = html.Tr([html.Th("method"), *(html.Th(f"{c.description} [{c.shown_unit}]") for c in COLUMNS)])
    rows = []
    for name, row in (methods or {}).items():
        cells = [html.Td(html.Span(views.quantity_text(row.get(c.name), c),
                                   **views.data_attributes(result=f"methods.{name}.{c.name}")), className="number")
                 for c in COLUMNS]
        rows.append(html.Tr([html.Th(name, scope="row"), *cells]))
    return html.Table([html.Thead(header), html.Tbody(rows)], className="statistics", id="compare-table")


def figure_elements(result) -> list:
    """The action's PNG figures of a result as ``figure[data-figure=NAME]`` images.

    Parameters
    ----------
    result : AlignmentComparison
        What the comparison returned (any result its figure writer accepts).
    """
    images = png_figures(partial(get_system(SYSTEM).write, action=compare_action().name), result)
    return [html.Figure([html.Img(src=uri, alt=stem), html.Figcaption(stem)], **views.data_attributes(figure=stem))
            for stem, uri in images] or [html.P("this comparison has no figures")]


def layout(action: Action) -> html.Div:
    """The page: the action's options as controls on the left, the table and the figure on the right.

    Parameters
    ----------
    action : Action
        The ``align compare`` action (a choice: its options become the controls).
    """
    return html.Div([
        html.Div([
            html.H1("Self-alignment methods compared"),
            html.P(action.help.splitlines()[0]),
            html.P([dcc.Link("back to the align page", href=f"/{SYSTEM}"), f" (the same: schuler {SYSTEM} {ACTION})"]),
        ], className="page-head"),
        html.Div([
            html.Aside([html.H2("Options"),
                        html.P("Type a value (a bare number is in the unit shown, or write a unit: '2 min'); "
                               "Enter or leaving the field applies it.", className="hint"),
                        *controls(action.parameters, id_type=PAGE_PARAM, values=STARTING_CASE)],
                       className="controls"),
            html.Main([
                html.Div([html.Span("running", className="label"),
                          html.Button("Cancel", id="compare-cancel", disabled=True, className="cancel")],
                         id="compare-status", className="status"),
                html.Div(id="compare-message", className="page-error", role="alert"),
                html.Div(id="compare-notes", className="notes"),
                html.H2("Methods"),
                html.Div(method_table(), id="compare-methods"),
                html.H2("Figure"),
                html.Div(id="compare-figures", className="figures"),
            ], className="results"),
        ], className="workbench"),
    ])


def show(typed: dict[str, str]) -> tuple[object, object, dict[str, str], str, list]:
    """What the page shows for a typed case: table, figures, messages per option, page message, notes.

    A wrong case leaves table and figures as they are (``no_update``).

    Parameters
    ----------
    typed : dict of str to str
        Option name -> the text typed in its field (display units), only for the fields the user changed.
    """
    parameters = compare_action().parameters
    _, errors = parse_typed(parameters, typed)
    if errors:
        return no_update, no_update, errors, "", []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = run_typed(typed)
            shown = method_table(result.methods), figure_elements(result)
        except SchulerError as error:
            owner, message = error_owner(parameters, error)
            return no_update, no_update, {owner: message} if owner else {}, "" if owner else message, []
        except Exception as error:  # a bug must not leave the page waiting: say it in one line
            return no_update, no_update, {}, internal_error(error), []
    return *shown, {}, "", notes(caught) + [html.P(note) for note in result.notes]


def register(app: Dash) -> None:
    """The page's callback: check and run on every change, messages beside the options.

    Parameters
    ----------
    app : Dash
        The lab's application (a choice: the callback is registered on it).
    """

    @app.callback(
        Output("compare-methods", "children"),
        Output("compare-figures", "children"),
        Output({"type": PAGE_ERROR, "name": ALL}, "children"),
        Output("compare-message", "children"),
        Output("compare-notes", "children"),
        Input({"type": PAGE_PARAM, "name": ALL}, "value"),
        State({"type": PAGE_PARAM, "name": ALL}, "id"),
        State("session", "data"),
        background=True,
        interval=4 * POLL_MS,
        running=[(Output("compare-status", "className"), "status running", "status"),
                 (Output("compare-cancel", "disabled"), False, True)],
        cancel=[Input("compare-cancel", "n_clicks")],
    )
    def run(values, ids, session):
        if not ids:
            raise PreventUpdate
        typed = typed_values(compare_action().parameters, ids, values)
        table, images, errors, message, caught = show(typed)
        return table, images, [errors.get(ident["name"], "") for ident in ids], message, caught
