"""The interactive lab bench in the browser (``schuler lab``).

A local web application in which every system's parameters are controls and
its headline numbers and figures follow as they change, with the KPI lab tasks
of gyrocompassing as guided pages.

Framework: `Dash <https://dash.plotly.com>`_ (Plotly; Flask underneath). Why:

* it is made for scientific dashboards and is actively maintained; its plots
  are plotly.js (zoom, hover, PNG/SVG export in the browser);
* **every asset ships inside the Python packages** and is served by the
  application itself (``serve_locally``, the default): no CDN, nothing fetched
  at run time, so the lab works on a machine without internet;
* callbacks are functions of the values the browser sends, so no user state
  lives in the server and two sessions cannot disturb each other;
* long computations run as *background callbacks* with progress and
  cancellation built in (a process per job, forked by the single-threaded job
  server of :mod:`~schuler.lab.jobs`, results through Dash's disk cache);
* components accept ``data-*`` attributes, which give scripts and tests their
  stable hooks (``data-param``, ``data-result``).

Panel/Bokeh were the alternative; their templates and several extensions load
resources from CDNs by default, which had to be undone piece by piece.

Modules: :mod:`~schuler.lab.app` (the application, routing, limits),
:mod:`~schuler.lab.server` (binding, Host check, serving, clean stop),
:mod:`~schuler.lab.jobs` (the job server), :mod:`~schuler.lab.pages` (callback registration),
:mod:`~schuler.lab.controls` (controls from parameters, parsing as the CLI),
:mod:`~schuler.lab.views` (headline numbers, tables),
:mod:`~schuler.lab.figures` (plotly figures), :mod:`~schuler.lab.system_page`
(``/NAME`` and ``/NAME/reproduction``), :mod:`~schuler.lab.tasks` and
:mod:`~schuler.lab.manual` (the KPI tasks).
"""
