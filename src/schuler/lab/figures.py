"""The lab's figures: interactive ones for gyrocompassing and aided navigation, the system's own files for any system.

A system's page shows interactive (plotly) figures where the lab knows its
result's histories (:data:`INTERACTIVE`: the gyrocompassing system, whose page
must follow a change within a second, and ``aided``: its errors inside the
filter's +-3-sigma and its track, GNSS outages marked), and otherwise the PNG figures of the
system's own ``write_files`` (slower: matplotlib renders them, so they come in
a second step with its own progress indicator).

Angles are shown as the source's figures show them: delta in arcmin, level
errors in arcsec, time in minutes; the aided heading in deg.
"""

from __future__ import annotations

import base64
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from dash import dcc, html

from schuler.contract import System
from schuler.core.earth import radii_of_curvature
from schuler.exceptions import InvalidParameter
from schuler.lab.views import data_attributes, number_text
from schuler.units import to_unit

MAX_POINTS = 400
"""Points per trace sent to the browser (histories are thinned evenly, first and last point kept)."""

SETTLING_TIMES_SHOWN = 4.0
"""The time axis of a history spans this many analytic settling times (or the whole run if shorter)."""

MIN_POINTS_SHOWN = 10
"""A history shows at least this many samples, so that a run settling within a step still draws a curve."""

GRAPH_CONFIG: Any = {"displaylogo": False, "responsive": True,
                "modeBarButtonsToRemove": ["select2d", "lasso2d", "autoScale2d"],
                "toImageButtonOptions": {"format": "png", "scale": 2}}
"""dcc.Graph config: the camera button saves a PNG (rendered in the browser, no server involved)."""

DASHES = ("solid", "dash", "dot")
"""Line styles of the runs drawn together (the model, then (1.19)), so that coinciding curves stay visible."""

# Figures are plain plotly dicts: building them through plotly's validating classes took longer
# (0.2-0.6 s a figure) than the simulation they show.


def thin(*arrays: np.ndarray, limit: int = MAX_POINTS) -> list[np.ndarray]:
    """Every k-th point of equally long arrays so that at most ``limit`` remain (the last kept).

    Parameters
    ----------
    *arrays : array_like
        Equally long 1-D arrays (a trace's x and y values, any unit: only points are dropped).
    limit : int
        Largest number of points to keep, at least 2 (the first and the last).

    Returns
    -------
    list of numpy.ndarray
        The arrays thinned alike; the arrays themselves when they hold ``limit`` points or fewer.

    Raises
    ------
    InvalidParameter
        ``limit`` is not a whole number >= 2.

    Examples
    --------
    >>> [a.tolist() for a in thin(np.arange(10), limit=4)]
    [[0, 3, 6, 9]]
    """
    if isinstance(limit, bool) or not isinstance(limit, int | np.integer) or limit < 2:
        raise InvalidParameter("limit", f"must be a whole number of points >= 2 (first and last), got {limit!r}")
    n = len(arrays[0])
    if n <= limit:
        return list(arrays)
    step = int(np.ceil((n - 1) / (limit - 1)))
    index = np.arange(0, n, step)
    if index[-1] != n - 1:
        index = np.append(index, n - 1)
    return [np.asarray(a)[index] for a in arrays]


def _line(x, y, name: str, row: int = 1, mode: str = "lines", **style) -> dict:
    suffix = "" if row == 1 else str(row)
    return {"type": "scatter", "x": np.asarray(x, dtype=float).tolist(), "y": np.asarray(y, dtype=float).tolist(),
            "name": name, "mode": mode, "xaxis": f"x{suffix}", "yaxis": f"y{suffix}", **style}


def _figure(traces: list[dict], title: str, y_titles: list[str], x_title: str, height: int, shapes=(),
            annotations=()) -> dict:
    """A figure of ``len(y_titles)`` rows stacked over one shared x axis."""
    rows = len(y_titles)
    gap = 0.07
    size = (1 - gap * (rows - 1)) / rows
    layout = {"title": {"text": title}, "height": height, "template": "plotly_white",
              "margin": {"l": 75, "r": 20, "t": 110, "b": 50}, "font": {"size": 13},
              "legend": {"orientation": "h", "x": 0, "y": 1.0, "yanchor": "bottom"}, "hovermode": "closest",
              "shapes": list(shapes), "annotations": list(annotations)}
    for row in range(1, rows + 1):
        suffix = "" if row == 1 else str(row)
        top = 1 - (row - 1) * (size + gap)
        layout[f"yaxis{suffix}"] = {"title": {"text": y_titles[row - 1]}, "domain": [top - size, top],
                                    "anchor": f"x{suffix}", "zeroline": True}
        layout[f"xaxis{suffix}"] = {"anchor": f"y{suffix}", "showticklabels": row == rows,
                                    **({"matches": "x"} if row > 1 else {}),
                                    **({"title": {"text": x_title}} if row == rows else {})}
    return {"data": traces, "layout": layout}


def _level(value: float, row: int, label: str, color: str = "black") -> tuple[dict, dict]:
    """A horizontal line across row ``row`` at ``value`` and its label."""
    suffix = "" if row == 1 else str(row)
    shape = {"type": "line", "xref": f"x{suffix} domain", "x0": 0, "x1": 1, "yref": f"y{suffix}", "y0": value,
             "y1": value, "line": {"dash": "dot", "color": color, "width": 1.5}}
    note = {"xref": f"x{suffix} domain", "x": 1, "xanchor": "right", "yref": f"y{suffix}", "y": value,
            "yanchor": "bottom", "text": label, "showarrow": False}
    return shape, note


def shown_window(run) -> np.ndarray:
    """The part of a run a history figure shows: a few settling times, at least the first ``MIN_POINTS_SHOWN`` points.

    Parameters
    ----------
    run : CaseRun
        A gyrocompassing run: ``time`` in s and ``analytic["settling_time_s"]``, the analytic settling time, s.

    Returns
    -------
    numpy.ndarray of bool
        Mask over ``run.time``: True up to ``SETTLING_TIMES_SHOWN`` settling times and at least for the first
        ``MIN_POINTS_SHOWN`` samples (all of a shorter run).
    """
    last_of_first = run.time[min(MIN_POINTS_SHOWN, run.time.size) - 1]
    end = max(SETTLING_TIMES_SHOWN * run.analytic["settling_time_s"], last_of_first)
    return run.time <= end


def window_text(run, window: np.ndarray) -> str:
    """What part of a run a history figure shows, for its time axis: empty when it shows the whole run.

    Parameters
    ----------
    run : CaseRun
        The run (``time`` in s).
    window : numpy.ndarray of bool
        The samples shown (:func:`shown_window`).

    Returns
    -------
    str
        ``" (the first 12.5 of 120 min simulated; the rest is steady)"`` or empty.
    """
    shown, simulated = run.time[window][-1] / 60.0, run.time[-1] / 60.0
    if shown >= simulated:
        return ""
    return f" (the first {number_text(shown)} of {number_text(simulated)} min simulated; the rest is steady)"


def time_history(runs: dict, title: str = "Azimuth and level errors (Fig. 1.4)") -> dict:
    """delta [arcmin] and beta [arcsec] against time [min] for runs (label -> CaseRun), delta_y dotted.

    Parameters
    ----------
    runs : dict of str to CaseRun
        Legend label -> run (histories in SI: ``time`` s, ``delta`` and ``beta`` rad); the first run's
        ``analytic["azimuth_error_analytic_rad"]`` (rad) is drawn as the dotted steady-state line.
    title : str
        Figure title.

    Returns
    -------
    dict
        A plotly figure (plain dict): delta in arcmin above beta in arcsec, against time in minutes.
    """
    traces = []
    for number, (label, run) in enumerate(runs.items()):
        window = shown_window(run)
        minutes, delta, beta = thin(run.time[window] / 60.0, to_unit(run.delta[window], "arcmin"),
                                    to_unit(run.beta[window], "arcsec"))
        line = {"dash": DASHES[number % len(DASHES)]}
        traces += [_line(minutes, delta, f"delta, {label}", line=line),
                   _line(minutes, beta, f"beta, {label}", row=2, line=line)]
    first = next(iter(runs.values()))
    steady = float(to_unit(first.analytic["azimuth_error_analytic_rad"], "arcmin"))
    shape, note = _level(steady, 1, "delta_y (1.21)")
    return _figure(traces, title, ["delta [arcmin]", "beta [arcsec]"],
                   "time [min]" + window_text(first, shown_window(first)), 520, [shape], [note])


def phase_trajectory(runs: dict, title: str = "Phase trajectory in the (delta, beta) plane (task 5)") -> dict:
    """The platform's path in the (delta [arcmin], beta [arcsec]) plane, start marked, steady state starred.

    Parameters
    ----------
    runs : dict of str to CaseRun
        Legend label -> run (``delta`` and ``beta`` in rad); the first run's analytic steady state
        (``azimuth_error_analytic_rad`` and ``level_error_beta_analytic_rad``, rad) is starred.
    title : str
        Figure title.

    Returns
    -------
    dict
        A plotly figure (plain dict): beta in arcsec against delta in arcmin.
    """
    traces = []
    for number, (label, run) in enumerate(runs.items()):
        window = shown_window(run)  # past a few settling times the path sits on the steady point
        delta, beta = thin(to_unit(run.delta[window], "arcmin"), to_unit(run.beta[window], "arcsec"))
        traces += [_line(delta, beta, label, line={"dash": DASHES[number % len(DASHES)]}),
                   _line(delta[:1], beta[:1], f"start, {label}", mode="markers", marker={"size": 9})]
    first_run = next(iter(runs.values()))
    first = first_run.analytic
    traces.append(_line([to_unit(first["azimuth_error_analytic_rad"], "arcmin")],
                        [to_unit(first["level_error_beta_analytic_rad"], "arcsec")],
                        "steady state (1.21), (1.25)", mode="markers",
                        marker={"size": 14, "symbol": "star", "color": "black"}))
    return _figure(traces, title + window_text(first_run, shown_window(first_run)), ["level error beta [arcsec]"],
                   "azimuth error delta [arcmin]", 480)


def level_angles(run, title: str = "Level errors in mu, nu and in beta, alpha (task 3)") -> dict:
    """mu, nu (platform axes, (1.17)) and beta, alpha (geographic, (1.18)) [arcsec] against time [min].

    Parameters
    ----------
    run : CaseRun
        A run of the full model (1.17): ``time`` in s, ``mu``, ``nu``, ``beta``, ``alpha`` in rad (a history
        that is None is left out).
    title : str
        Figure title.

    Returns
    -------
    dict
        A plotly figure (plain dict) of two rows: mu, nu above beta, alpha, in arcsec against time in minutes.
    """
    window = shown_window(run)
    minutes = run.time[window] / 60.0
    traces = []
    for row, names in ((1, ("mu", "nu")), (2, ("beta", "alpha"))):
        for name in names:
            values = getattr(run, name)
            if values is not None:
                x, y = thin(minutes, to_unit(values[window], "arcsec"))
                traces.append(_line(x, y, name, row=row))
    return _figure(traces, title, ["mu, nu [arcsec]", "beta, alpha [arcsec]"],
                   "time [min]" + window_text(run, window), 520)


def sweep_curves(x, x_label: str, columns: dict, constraints, title: str = "Accuracy and time against a parameter"):
    """Azimuth error, settling time and the constraint ratios against a swept parameter.

    ``columns`` holds display-unit arrays: ``azimuth_error_arcmin`` (simulated),
    ``azimuth_error_analytic_arcmin`` ((1.21)), ``settling_time_s``,
    ``settling_time_simulated_s`` and the maxima named by ``constraints`` (SI);
    optionally ``simplified_azimuth_error_arcmin``. ``constraints``: (output key,
    symbol, limit, unit) of each constraint; a ratio of 1 or more is a violation
    (drawn red).

    Parameters
    ----------
    x : array_like
        Values of the swept parameter, shape (N,), in its display unit (as ``x_label`` states).
    x_label : str
        Title of the x axis, with the unit (``latitude (deg)``).
    columns : dict of str to numpy.ndarray
        Column name -> values, shape (N,) each: the display-unit columns above (arcmin, s) and the
        constraints' maxima in SI (rad, rad/s).
    constraints : iterable of (str, str, float, str)
        Per constraint: key of its maximum in ``columns``, symbol, limit (SI, in the unit given next) and
        unit.
    title : str
        Figure title.

    Returns
    -------
    dict
        A plotly figure (plain dict) of three rows: azimuth error in arcmin, settling time in s, and
        maximum / limit (a plain ratio, log axis).
    """
    open_circle = {"symbol": "circle-open", "size": 8}
    traces = [_line(x, columns["azimuth_error_analytic_arcmin"], "analytic (1.21)"),
              _line(x, columns["azimuth_error_arcmin"], "simulated", mode="markers", marker=open_circle)]
    if "simplified_azimuth_error_arcmin" in columns:
        traces.append(_line(x, columns["simplified_azimuth_error_arcmin"], "simulated, (1.19)", mode="markers",
                            marker={"symbol": "x", "size": 7}))
    traces += [_line(x, columns["settling_time_s"], "settling time, analytic", row=2),
               _line(x, np.where(np.isfinite(columns["settling_time_simulated_s"]),
                                 columns["settling_time_simulated_s"], np.nan),
                     "settling time, 1 % band", row=2, mode="markers", marker=open_circle)]
    for key, symbol, limit, unit in constraints:
        ratio = np.asarray(columns[key], dtype=float) / limit
        traces.append(_line(x, ratio, f"max {symbol} / {limit:g} {unit}", row=3, mode="lines+markers",
                            marker={"color": np.where(ratio >= 1, "crimson", "seagreen").tolist(), "size": 7}))
    shape, note = _level(1.0, 3, "limit", color="crimson")
    fig = _figure(traces, title, ["azimuth error [arcmin]", "settling time [s]", "max / limit"], x_label, 760,
                  [shape], [note])
    fig["layout"]["yaxis2"]["rangemode"] = "tozero"
    fig["layout"]["yaxis3"]["type"] = "log"
    return fig


GRAPH = "lab-graph"
"""Component-id type of a system page's interactive graphs: ``{"type": GRAPH, "figure": STEM}``."""


def empty(note: str) -> dict:
    """A figure with nothing drawn but a note (before the first run, or when a run has no histories).

    Parameters
    ----------
    note : str
        The text shown in the middle of the figure.

    Returns
    -------
    dict
        A plotly figure (plain dict) with hidden axes.
    """
    return {"data": [], "layout": {"height": 200, "template": "plotly_white", "xaxis": {"visible": False},
                                   "yaxis": {"visible": False},
                                   "annotations": [{"text": note, "showarrow": False, "font": {"size": 14}}]}}


def block(stem: str, fig: dict, csv: bool = False, graph_id: dict | None = None) -> html.Div:
    """A figure with its export buttons: PNG and SVG (drawn by the browser), and CSV of its data if ``csv``.

    The CSV button (``{"type": "csv-export", "figure": stem}``) needs a
    callback of the page that knows the figure's data. ``graph_id`` gives the
    graph an id, so that a callback can replace its figure in place.

    Parameters
    ----------
    stem : str
        The figure's name (``data-figure`` attribute, export file name and button ids).
    fig : dict
        The plotly figure (plain dict).
    csv : bool
        Whether to add the CSV button and its download component.
    graph_id : dict, optional
        Component id of the graph; None: no id.

    Returns
    -------
    dash.html.Div
        ``div.figure[data-figure=STEM]`` with the graph and its export buttons.
    """
    buttons: list[Any] = [html.Button(fmt.upper(), id={"type": "image-export", "figure": stem, "format": fmt},
                           className="export", title=f"save the figure as {fmt.upper()}") for fmt in ("png", "svg")]
    if csv:
        buttons += [html.Button("CSV", id={"type": "csv-export", "figure": stem}, className="export",
                                title="download the figure's data as CSV"),
                    dcc.Download(id={"type": "csv-download", "figure": stem})]
    identity: dict[str, Any] = {} if graph_id is None else {"id": graph_id}
    graph = dcc.Graph(figure=fig, config=GRAPH_CONFIG, **identity)
    return html.Div([graph, html.Div([html.Span("export:", className="hint"), *buttons], className="exports")],
                    className="figure", **data_attributes(figure=stem))


@dataclass(frozen=True)
class Interactive:
    """The interactive figures the lab draws for one system: their names and how to build them from a result."""

    stems: tuple[str, ...]
    build: Callable[[object], list[dict]]


def _alignment_figures(result) -> list[dict]:
    from schuler.gyrocompassing.results import case_runs

    simulated = case_runs(result)
    if simulated is None:
        return [empty("no histories: the closed form computes none")] * 2
    run, simplified = simulated
    runs = {f"{result.model} model": run}
    if result.model != "simplified":
        runs["simplified (1.19)"] = simplified
    return [time_history(runs), phase_trajectory(runs)]


OUTAGE_FILL = "rgba(128, 128, 128, 0.25)"
"""Colour of a GNSS outage's band."""

ENVELOPE_ROWS = (("north_error_m", "north_sigma_m", "north [m]", "m"),
                 ("east_error_m", "east_sigma_m", "east [m]", "m"), ("down_error_m", "down_sigma_m", "down [m]", "m"),
                 ("heading_error_rad", "heading_sigma_rad", "heading [deg]", "deg"))
"""The rows of the aided error figure: error channel, its 1-sigma channel, axis title, display unit."""


def error_envelopes(histories, outages, title: str = "Errors inside the filter's +-3 sigma (GNSS outages grey)"):
    """North, east, down errors [m] and heading error [deg] of one member in the filter's +-3-sigma band.

    The time axis counts minutes from the run's first output (a file's seconds of week from its start); without a
    truth (no error channels) the bands alone are drawn.

    Parameters
    ----------
    histories : Histories
        ``aided_errors`` of an aided run (SI: s, m, rad).
    outages : list of dict
        The run's outages, ``start_s`` and ``duration_s`` (s, the histories' time scale).
    title : str
        Figure title.

    Returns
    -------
    dict
        A plotly figure (plain dict) of four rows sharing the time axis.
    """
    origin = float(histories.time[0]) if histories.time.size else 0.0
    minutes = (histories.time - origin) / 60.0
    traces: list[dict] = []
    shapes = []
    for row, (error, sigma, _, unit) in enumerate(ENVELOPE_ROWS, start=1):
        x, band = thin(minutes, 3.0 * np.asarray(to_unit(histories[sigma], unit), dtype=float))
        first = row == 1
        band_line = {"color": "rgba(31, 119, 180, 0.6)", "width": 1}
        traces += [_line(x, band, "+3 sigma", row, line=band_line, legendgroup="band", showlegend=False),
                   _line(x, -band, "+-3 sigma", row, line=band_line, fill="tonexty",
                         fillcolor="rgba(31, 119, 180, 0.15)", legendgroup="band", showlegend=first)]
        if error in histories:
            x, value = thin(minutes, to_unit(histories[error], unit))
            traces.append(_line(x, value, "error", row, line={"color": "crimson", "width": 1}, legendgroup="error",
                                showlegend=first))
        suffix = "" if first else str(row)
        shapes += [{"type": "rect", "xref": f"x{suffix}", "yref": f"y{suffix} domain", "y0": 0, "y1": 1,
                    "x0": (o["start_s"] - origin) / 60.0, "x1": (o["start_s"] + o["duration_s"] - origin) / 60.0,
                    "fillcolor": OUTAGE_FILL, "line": {"width": 0}, "layer": "below"} for o in outages]
    return _figure(traces, title, [row[2] for row in ENVELOPE_ROWS], "time from the start [min]", 820, shapes)


def track(navigation, outages, title: str = "Track: the aided solution, north against east (GNSS outages red)"):
    """The navigation solution's track in metres north and east of its first point, the outages' parts in red.

    Parameters
    ----------
    navigation : Histories
        An aided run's navigation (``latitude_rad``, ``longitude_rad``, ``height_m``; s).
    outages : list of dict
        The run's outages, ``start_s`` and ``duration_s`` (s, the navigation's time scale).
    title : str
        Figure title.

    Returns
    -------
    dict
        A plotly figure (plain dict), east [m] across, north [m] up, one metre the same length on both.
    """
    latitude, longitude, height = (np.asarray(navigation[n], dtype=float)
                                   for n in ("latitude_rad", "longitude_rad", "height_m"))
    R_N, R_E = radii_of_curvature(latitude[0])
    north = (latitude - latitude[0]) * (R_N + height[0])
    east = (longitude - longitude[0]) * (R_E + height[0]) * np.cos(latitude[0])
    x, y = thin(east, north)
    traces = [_line(x, y, "aided solution", line={"color": "rgb(31, 119, 180)"})]
    for number, outage in enumerate(outages):
        inside = (navigation.time > outage["start_s"]) & (navigation.time <= outage["start_s"] + outage["duration_s"])
        x, y = thin(east[inside], north[inside])
        traces.append(_line(x, y, "in outages", line={"color": "crimson", "width": 3}, legendgroup="outage",
                            showlegend=number == 0))
    traces.append(_line(east[:1], north[:1], "start", mode="markers", marker={"size": 9, "color": "black"}))
    fig = _figure(traces, title, ["north [m]"], "east [m]", 560)
    fig["layout"]["yaxis"]["scaleanchor"] = "x"
    return fig


def _aided_figures(result) -> list[dict]:
    histories = getattr(result, "histories", {})
    if "aided_errors" not in histories or getattr(result, "navigation", None) is None:
        return [empty("no histories in this result")] * 2
    outages = result.extras.get("outages", [])
    return [error_envelopes(histories["aided_errors"], outages), track(result.navigation, outages)]


INTERACTIVE = {"align": Interactive(("align_time_history", "align_phase_trajectory"), _alignment_figures),
               "aided": Interactive(("aided_errors", "aided_track"), _aided_figures)}
"""System name -> the interactive figures of its ``run`` result."""


def interactive_stems(system: System) -> tuple[str, ...]:
    """Names of the interactive figures of a system's page (empty: it shows its own files' figures).

    Parameters
    ----------
    system : System
        The system whose page is drawn.

    Returns
    -------
    tuple of str
        The figures' names, in the order :func:`interactive_figures` builds them.
    """
    return INTERACTIVE[system.name].stems if system.name in INTERACTIVE else ()


def interactive_figures(system: System, result) -> list[dict] | None:
    """The interactive figures of a result (in the order of :func:`interactive_stems`), or None.

    Parameters
    ----------
    system : System
        The system that computed ``result``.
    result : object
        What the system's ``run`` returned (for ``align``: an ``AlignmentRun``).

    Returns
    -------
    list of dict or None
        Plotly figures (plain dicts); None when the lab draws no interactive figures of this system.
    """
    return INTERACTIVE[system.name].build(result) if system.name in INTERACTIVE else None


def file_figures(system: System, result) -> list[tuple[str, str]]:
    """The system's own PNG figures of a result as (file name, data URI) pairs.

    Parameters
    ----------
    system : System
        The system that computed ``result`` (its ``write`` draws the figures).
    result : object
        What the system's ``run`` returned.

    Returns
    -------
    list of (str, str)
        File name and ``data:image/png;base64`` URI of each PNG.
    """
    return png_figures(system.write, result)


def png_figures(write_files: Callable[[Any, Path], list[Path]], result) -> list[tuple[str, str]]:
    """The PNG figures ``write_files`` draws of a result as (file name, data URI) pairs.

    Parameters
    ----------
    write_files : callable
        ``write_files(result, folder)`` -> the paths it wrote (a system's or an action's figure writer).
    result : object
        The result to draw (a choice of the writer: any result type it accepts).

    Returns
    -------
    list of (str, str)
        File name and ``data:image/png;base64`` URI of each PNG.
    """
    with tempfile.TemporaryDirectory(prefix="schuler-lab-") as folder:
        paths = write_files(result, Path(folder))
        return [(path.name, "data:image/png;base64," + base64.b64encode(path.read_bytes()).decode("ascii"))
                for path in paths if path.suffix == ".png"]
