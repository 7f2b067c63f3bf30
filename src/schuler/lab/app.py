"""The lab application: pages from the registry, routing, limits, and the job manager.

:func:`create_app` builds one Dash application. Its pages: ``/`` (what there
is), ``/NAME`` for every registered system (:mod:`schuler.lab.system_page`),
``/NAME/reproduction``, the KPI lab tasks at ``/align/task1`` ...
(:mod:`schuler.lab.tasks`) and the alignment comparison at ``/align/compare``
(:mod:`schuler.lab.compare_page`). Systems whose module fails to import are listed as
"not available" with the reason, and the rest of the lab works.

Every asset (Dash's renderer, React, plotly.js, the lab's CSS and scripts) is
served by the application itself from the installed packages; the page's
Content-Security-Policy lets the browser load nothing from anywhere else.
Requests larger than :data:`MAX_REQUEST_BYTES` are refused (HTTP 413).
Computations run as background jobs (one process per job, forked by the job
server of :mod:`schuler.lab.jobs`, never by the threaded web server; results in a
job cache in a temporary folder removed at shutdown).
"""

from __future__ import annotations

import shutil
import tempfile
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from dash import Dash, Input, Output, dcc, html

from schuler import __version__
from schuler.contract import System
from schuler.lab import compare_page, manual, system_page
from schuler.lab.jobs import JobServerManager
from schuler.lab.pages import register_pages
from schuler.registry import SYSTEM_MODULES, get_system

MAX_REQUEST_BYTES = 256 * 1024
"""Largest request body the lab accepts, bytes (a page's callbacks send a few kB)."""

ASSETS = Path(__file__).parent / "assets"

COMPARE_HREF = f"/{compare_page.SYSTEM}/{compare_page.ACTION}"
"""The alignment comparison's page."""

TASK_PAGES = {f"task{n}" for n in manual.TASK_TITLES}
"""The KPI task pages under ``/align/``."""

CONTENT_SECURITY_POLICY = ("default-src 'self'; connect-src 'self'; img-src 'self' data: blob:; "
                           "style-src 'self' 'unsafe-inline'; font-src 'self' data:; object-src 'none'; "
                           "base-uri 'self'; form-action 'self'; frame-ancestors 'self'")
"""Nothing outside the lab's own origin; ``script-src`` adds the hashes of Dash's inline scripts."""


@dataclass(frozen=True)
class Availability:
    """A registered system and whether it can be used here (the import error's line otherwise)."""

    name: str
    system: System | None
    reason: str = ""


def systems_available() -> list[Availability]:
    """Every registered system, imported once (jobs then start warm); failures become "not available"."""
    found = []
    for name in SYSTEM_MODULES:
        try:
            found.append(Availability(name, get_system(name)))
        except Exception as error:  # any import failure of one system must not take the lab down
            found.append(Availability(name, None, f"{type(error).__name__}: {error}".splitlines()[0]))
    return found


class Lab:
    """The Dash application and what it owns: the job cache folder and the job manager.

    Attributes
    ----------
    app : dash.Dash
    server : flask.Flask
        The WSGI application to serve.
    cache_dir : Path
        Where background jobs leave their results (removed by :meth:`close`).
    jobs : JobServerManager
        The job manager (its job server forks the jobs).
    """

    def __init__(self, app: Dash, cache_dir: Path, manager: JobServerManager):
        self.app = app
        self.server = app.server
        self.cache_dir = cache_dir
        self.jobs = manager

    def close(self) -> None:
        """End the job server and its running jobs, and remove the job cache."""
        self.jobs.close()
        for _ in range(3):  # a job ending just now may still be closing its files in the folder
            shutil.rmtree(self.cache_dir, ignore_errors=True)
            if not self.cache_dir.exists():
                break
            time.sleep(0.2)


def create_app(host: str = "127.0.0.1", port: int | None = None) -> Lab:
    """Build the lab (pages for every registered system, the KPI tasks, limits and headers).

    Parameters
    ----------
    host : str
        The address the lab listens on (requests whose ``Host`` names another are refused).
    port : int, optional
        TCP port served, a plain number from 0 to 65535 (requests for another are refused); None accepts any.
    """
    cache_dir = Path(tempfile.mkdtemp(prefix="schuler-lab-jobs-"))
    manager = JobServerManager(cache_dir)  # spawned first: it imports and warms while the pages are built
    app = Dash(
        __name__,
        title="schuler lab",
        update_title="",  # the tab keeps its title while a page updates
        assets_folder=str(ASSETS),
        serve_locally=True,
        suppress_callback_exceptions=True,
        background_callback_manager=manager,
        enable_mcp=False,
        compress=False,
    )
    available = systems_available()
    app.layout = lambda: _shell(available)
    _routing(app, {a.name: a for a in available}, register_pages(app))
    _limits(app, host, port)
    return Lab(app, cache_dir, manager)


def _shell(available: list[Availability]) -> html.Div:
    """The frame of every page; a new session token per page load keeps sessions' jobs apart."""
    links: list[Any] = []
    for item in available:
        if item.system is None:
            links.append(html.Span(item.name, className="unavailable", title=f"not available: {item.reason}"))
        else:
            links.append(dcc.Link(item.name, href=f"/{item.name}", title=item.system.title))
    task_links = [dcc.Link(f"task {n}", href=f"/align/task{n}") for n in manual.TASK_TITLES]
    return html.Div([
        dcc.Location(id="url"),
        dcc.Store(id="session", data=uuid.uuid4().hex),
        html.Header([
            dcc.Link("schuler lab", href="/", className="brand"),
            html.Nav([html.Span("systems:", className="hint"), *links], className="systems"),
            html.Nav([html.Span("KPI lab tasks:", className="hint"), *task_links], className="tasks"),
        ]),
        html.Div(id="page"),
        html.Footer(f"schuler {__version__}: computations run on this machine; nothing leaves it."),
    ])


def _routing(app: Dash, by_name: dict[str, Availability], task_layout) -> None:
    @app.callback(Output("page", "children"), Input("url", "pathname"))
    def route(pathname):
        parts = [p for p in (pathname or "/").split("/") if p]
        if not parts:
            return _index(list(by_name.values()))
        item = by_name.get(parts[0])
        if item is None:
            return _not_found(pathname)
        if item.system is None:
            return html.Div([html.H1(item.name), html.P(f"not available: {item.reason}", className="page-error")])
        if len(parts) == 1:
            return system_page.layout(item.system)
        if len(parts) == 2 and parts[1] == "reproduction":
            return system_page.reproduction_layout(item.system)
        if (item.name, parts[1:]) == (compare_page.SYSTEM, [compare_page.ACTION]):
            return compare_page.layout(compare_page.compare_action())
        if item.name == "align" and len(parts) == 2 and parts[1] in TASK_PAGES and task_layout is not None:
            return task_layout(item.system, parts[1])
        return _not_found(pathname)


def _index(available: list[Availability]) -> html.Div:
    rows = []
    for item in available:
        if item.system is None:
            rows.append(html.Li([html.Strong(item.name), f": not available ({item.reason})"], className="unavailable"))
        else:
            rows.append(html.Li([dcc.Link(item.name, href=f"/{item.name}"), f": {item.system.title} (",
                                 dcc.Link("reproduction", href=f"/{item.name}/reproduction"), ")"]))
    return html.Div([
        html.H1("schuler lab bench"),
        html.P("Every system's parameters are controls; the numbers and figures follow as they change."),
        html.H2("Systems"), html.Ul(rows),
        html.H2("Comparisons"),
        html.Ul([html.Li([dcc.Link("Self-alignment methods compared", href=COMPARE_HREF),
                          f" (schuler {compare_page.SYSTEM} {compare_page.ACTION})"])]),
        html.H2("KPI lab tasks (gyrocompassing)"),
        html.Ul([html.Li(dcc.Link(f"Task {n}: {title}", href=f"/align/task{n}"))
                 for n, title in manual.TASK_TITLES.items()]),
        html.P("Task 4 (the MIS-2 system) is left out: the manual does not give that system's parameters.",
               className="hint"),
    ])


def _not_found(pathname: str) -> html.Div:
    return html.Div([html.H1("Not found"), html.P(f"There is no page {pathname!r} in the lab."),
                     dcc.Link("the list of pages", href="/")])


def _limits(app: Dash, host: str, port: int | None) -> None:
    """Refuse foreign Host headers and large requests before reading them; an asset that does not exist is
    404; headers that keep the page to its own origin."""
    from dash.exceptions import DependencyException
    from flask import abort, request

    from schuler.lab.server import host_allowed

    server = app.server
    server.config["MAX_CONTENT_LENGTH"] = MAX_REQUEST_BYTES
    policy = f"{CONTENT_SECURITY_POLICY}; script-src 'self' {' '.join(app.csp_hashes())}"

    @server.before_request
    def refuse_foreign_or_large():
        if not host_allowed(request.host, host, port):
            abort(400)  # a page elsewhere reaching the lab under its own name (DNS rebinding)
        if request.content_length is not None and request.content_length > MAX_REQUEST_BYTES:
            abort(413)

    @server.errorhandler(DependencyException)
    def no_such_asset(error):
        return "not found", 404

    @server.after_request
    def headers(response):
        response.headers["Content-Security-Policy"] = policy
        response.headers["X-Content-Type-Options"] = "nosniff"
        response.headers["Referrer-Policy"] = "no-referrer"
        return response
