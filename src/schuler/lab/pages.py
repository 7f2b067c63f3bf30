"""Registering the callbacks of every page of the lab, in the web server and, the same, in the job server."""

from __future__ import annotations

from dash import Dash

from schuler.lab import compare_page, system_page


def register_pages(app: Dash):
    """Register the callbacks of every page; returns the KPI task pages' layout function (None: not offered).

    The job server calls it too, to hold the same background functions under the same keys.

    Parameters
    ----------
    app : Dash
        The application the callbacks are registered on.
    """
    system_page.register(app)
    compare_page.register(app)
    return _task_pages(app)


def _task_pages(app: Dash):
    """The KPI task pages' layout function, or None when they cannot be offered.

    They are built on the gyrocompassing system; imported here, so that a
    gyrocompassing module that fails to import makes them (and its own page)
    "not available" instead of stopping the lab.
    """
    try:
        from schuler.lab import tasks
    except Exception:  # the align page says why
        return None
    tasks.register(app)
    return tasks.layout
