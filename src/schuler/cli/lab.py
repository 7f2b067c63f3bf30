"""``schuler lab``: open the interactive lab bench in the browser.

A thin command over :mod:`schuler.lab`: checks where to listen, builds the
application, prints its URL, serves until Ctrl-C or SIGTERM and says in one
line how it stopped (exit code 0: stopping is how a server ends).
"""

from __future__ import annotations

import sys
import threading
import webbrowser

import click

from schuler.cli.common import options_named
from schuler.lab.server import (
    LabServer,
    check_host,
    check_port,
    is_loopback,
    listen,
    listening_text,
    serve_until_signal,
)


@click.command("lab", context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.option("--port", type=int, default=8050, show_default=True, help="TCP port (0: any free port).")
@click.option("--host", default="127.0.0.1", show_default=True,
              help="Address to listen on; only loopback addresses unless --allow-remote.")
@click.option("--allow-remote", is_flag=True,
              help="Allow a non-loopback --host. The lab has no login: anyone reaching the port can run it.")
@click.option("--no-browser", is_flag=True, help="Do not open a browser window.")
def lab(port: int, host: str, allow_remote: bool, no_browser: bool) -> None:
    """Open the interactive lab bench in the browser.

    Every system's parameters are controls; its headline numbers and figures
    follow as they change. The KPI lab tasks of gyrocompassing are guided
    pages. Everything runs on this machine: the pages need no internet.
    Stop with Ctrl-C.
    """
    with options_named((), names=("host", "port")):
        address = check_host(host, allow_remote)
        sock = listen(address, check_port(port))
    from schuler.lab.app import create_app

    bench = create_app(address, sock.getsockname()[1])
    try:
        server = LabServer(bench.server, sock, on_stop=bench.close)
    except BaseException:
        bench.close()  # the job cache folder goes with it
        raise
    click.echo(f"schuler lab: serving on {server.url} (Ctrl-C to stop)")
    if not is_loopback(server.host):
        click.echo(f"schuler lab: warning: listening on {listening_text(server.host, server.port)}; the lab has no "
                   "login: anyone who can reach this port can run computations on this machine", err=True)
    sys.stdout.flush()
    if not no_browser:
        threading.Timer(0.5, webbrowser.open, args=(server.url,)).start()
    how = serve_until_signal(server)
    click.echo(f"schuler lab: stopped ({how})", err=True)
