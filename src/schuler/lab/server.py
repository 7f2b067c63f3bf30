"""Serving the lab: where it may listen, the HTTP server, and a clean stop.

The lab is a local application. :func:`check_host` refuses to listen on
anything but a loopback address unless remote access is asked for explicitly
(the lab has no authentication: anyone who can reach the port can run
computations). :class:`LabServer` serves the WSGI application with Werkzeug's
threaded server (one thread per request; computations run in background job
processes, see :mod:`schuler.lab.jobs`) and stops cleanly on Ctrl-C or SIGTERM:
the listening socket is closed, running jobs are ended, the job cache is removed.
"""

from __future__ import annotations

import ipaddress
import signal
import socket
import threading
from collections.abc import Callable

from schuler.exceptions import InvalidParameter

LOCAL_NAMES = frozenset({"localhost", "localhost.localdomain", "ip6-localhost"})
"""Host names taken as loopback without resolving them (resolving could ask a name server)."""


def is_loopback(host: str) -> bool:
    """Whether ``host`` is a loopback address (127.0.0.0/8, ::1) or a name for it.

    Parameters
    ----------
    host : str
        An IPv4 or IPv6 address (brackets allowed) or a host name; names other than ``localhost`` and its
        aliases are not resolved and count as not loopback.

    Returns
    -------
    bool
        True for 127.0.0.0/8, ::1 and the local names.

    Examples
    --------
    >>> is_loopback("127.0.0.1"), is_loopback("::1"), is_loopback("localhost"), is_loopback("0.0.0.0")
    (True, True, True, False)
    """
    text = str(host).strip().strip("[]").lower()
    if text in LOCAL_NAMES:
        return True
    try:
        return ipaddress.ip_address(text).is_loopback
    except ValueError:
        return False


def check_host(host: str, allow_remote: bool = False) -> str:
    """The host to listen on; refuses a non-loopback one unless ``allow_remote``.

    Parameters
    ----------
    host : str
        The address or name given with ``--host``.
    allow_remote : bool
        Whether ``--allow-remote`` was given (any address is then accepted).

    Returns
    -------
    str
        ``host`` without surrounding blanks.

    Raises
    ------
    InvalidParameter
        ``--host`` is not a loopback address and remote access was not allowed.

    Examples
    --------
    >>> check_host("127.0.0.1")
    '127.0.0.1'
    >>> check_host("0.0.0.0")
    Traceback (most recent call last):
    ...
    schuler.exceptions.InvalidParameter: host: '0.0.0.0' is not a loopback address; the lab has no login, so \
it listens only on this machine (127.0.0.1, ::1, localhost) unless `allow_remote` is given
    """
    text = str(host).strip()
    if not text:
        raise InvalidParameter("host", "empty host")
    if not allow_remote and not is_loopback(text):
        raise InvalidParameter("host", f"{text!r} is not a loopback address; the lab has no login, so it listens "
                                         "only on this machine (127.0.0.1, ::1, localhost) unless `allow_remote` "
                                         "is given")
    return text


def host_allowed(header: str, bound: str, port: int | None) -> bool:
    """Whether a request's ``Host`` header names this lab (a guard against DNS rebinding).

    A foreign page can make the browser send requests to the lab under a name
    of its own that resolves to 127.0.0.1; such a request carries that name in
    ``Host``. Accepted: the loopback names and addresses, and, when the lab was
    bound to another address (``--allow-remote``), that address written as an
    IP address (any IP address for a wildcard bind: a rebinding page can only
    send a name), each with the port served.

    Parameters
    ----------
    header : str
        The ``Host`` header (``127.0.0.1:8050``, ``[::1]:8050``, ``localhost``).
    bound : str
        The address the lab listens on.
    port : int or None
        TCP port served, a plain number from 0 to 65535 (None: any, for an application not bound to one).

    Returns
    -------
    bool
        True when the header names the lab.

    Examples
    --------
    >>> host_allowed("127.0.0.1:8050", "127.0.0.1", 8050), host_allowed("evil.example:8050", "127.0.0.1", 8050)
    (True, False)
    """
    text = (header or "").strip().lower()
    if text.startswith("["):
        name, _, rest = text[1:].partition("]")
        given = rest[1:] if rest.startswith(":") else (None if not rest else "bad")
    elif text.count(":") == 1:
        name, given = text.split(":")
    else:
        name, given = text, None
    if port is not None and (given or "80") != str(port):
        return False
    if is_loopback(name):
        return True
    try:
        address = ipaddress.ip_address(name)
    except ValueError:
        return False  # a name: never trusted beyond the local ones
    bound_text = bound.strip("[]")
    if bound_text in ("0.0.0.0", "::", ""):
        return True
    try:
        return address == ipaddress.ip_address(bound_text)
    except ValueError:  # bound by name: only the names of this machine's loopback are trusted
        return False


def check_port(port: int) -> int:
    """A TCP port number, 0 (any free port) to 65535.

    Parameters
    ----------
    port : int
        TCP port given with ``--port``, a plain number from 0 to 65535 (0: the system picks a free port).

    Returns
    -------
    int
        ``port`` itself.

    Raises
    ------
    InvalidParameter
        ``port`` is not an integer (a bool is not) or is outside [0, 65535].

    Examples
    --------
    >>> check_port(8050)
    8050
    """
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise InvalidParameter("port", f"{port!r} is outside [0, 65535]")
    return port


def url_of(host: str, port: int) -> str:
    """The URL people open: ``http://127.0.0.1:8050/`` (IPv6 in brackets).

    Parameters
    ----------
    host : str
        The address the lab listens on (``0.0.0.0`` and empty are shown as 127.0.0.1, ``::`` as localhost).
    port : int
        TCP port, a plain number from 0 to 65535.

    Returns
    -------
    str
        ``http://HOST:PORT/``.

    Examples
    --------
    >>> url_of("::1", 8050), url_of("0.0.0.0", 80)
    ('http://[::1]:8050/', 'http://127.0.0.1:80/')
    """
    shown = "127.0.0.1" if host in ("0.0.0.0", "") else ("localhost" if host == "::" else host)
    if ":" in shown:
        shown = f"[{shown}]"
    return f"http://{shown}:{port}/"


def listening_text(host: str, port: int) -> str:
    """Where the lab really listens, in words: ``192.168.1.20:8050`` or ``every address of this machine, port 8050``.

    Parameters
    ----------
    host : str
        The address the socket is bound to.
    port : int
        TCP port bound, a plain number from 0 to 65535.

    Returns
    -------
    str
        The address and port (a wildcard address said as every address).
    """
    if host in ("0.0.0.0", "::", ""):
        return f"every address of this machine ({host or '0.0.0.0'}), port {port}"
    return f"[{host}]:{port}" if ":" in host else f"{host}:{port}"


def listen(host: str, port: int) -> socket.socket:
    """A socket listening on ``host:port`` (port 0: a free one), or a one-line error when that is impossible.

    Bound here, before the application is built, so that a port in use is
    reported at once and in one line (the HTTP server would print several and
    exit by itself).

    Parameters
    ----------
    host : str
        Address to bind (IPv6 with or without brackets), as :func:`check_host` returned it.
    port : int
        TCP port, a plain number from 0 to 65535 (0: the system picks a free one).

    Returns
    -------
    socket.socket
        A bound socket listening with a backlog of 64 connections.

    Raises
    ------
    InvalidParameter
        The address cannot be bound (port in use, address not of this machine, no permission).
    """
    address = host.strip("[]")
    family = socket.AF_INET6 if ":" in address else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((address, port))
        sock.listen(64)
    except OSError as error:
        sock.close()
        raise InvalidParameter("port", f"cannot listen on {host}:{port}: {error.strerror or error}") from None
    return sock


class LabServer:
    """A threaded WSGI server for the lab, stoppable from a signal handler or another thread.

    Parameters
    ----------
    wsgi_app : callable
        The WSGI application (the Dash app's Flask server).
    sock : socket.socket
        The listening socket (:func:`listen`); the server takes it over.
    on_stop : callable, optional
        Called once after the server stopped (ends jobs, removes the job cache).
    """

    def __init__(self, wsgi_app, sock: socket.socket, on_stop: Callable[[], None] | None = None):
        from werkzeug.serving import WSGIRequestHandler, make_server

        class QuietHandler(WSGIRequestHandler):
            def log_request(self, code="-", size="-"):  # one line per request would flood the terminal
                pass

        host, port = sock.getsockname()[:2]
        self._server = make_server(host, port, wsgi_app, threaded=True, request_handler=QuietHandler,
                                   fd=sock.fileno())
        sock.close()  # the server holds its own duplicate of the descriptor
        self._server.daemon_threads = True  # type: ignore[attr-defined]  # threaded: a ThreadingMixIn server
        self.host = host
        self.port = int(port)
        self._on_stop = on_stop
        self._stopped = threading.Event()

    @property
    def url(self) -> str:
        return url_of(self.host, self.port)

    def serve(self) -> None:
        """Serve until :meth:`stop` is called (from a signal handler or another thread)."""
        try:
            self._server.serve_forever(poll_interval=0.2)
        finally:
            self._server.server_close()
            self._finish()

    def stop(self) -> None:
        """Ask :meth:`serve` to return; safe from any thread (not from the serving thread itself)."""
        threading.Thread(target=self._server.shutdown, daemon=True).start()

    def _finish(self) -> None:
        if not self._stopped.is_set():
            self._stopped.set()
            if self._on_stop is not None:
                self._on_stop()


def serve_until_signal(server: LabServer) -> str:
    """Serve in the main thread until Ctrl-C or SIGTERM; returns which one stopped it.

    Both signals end :meth:`LabServer.serve` the same way (the socket is closed,
    ``on_stop`` runs); the previous handlers are restored afterwards.

    Parameters
    ----------
    server : LabServer
        The server to run (its ``serve`` blocks until stopped).

    Returns
    -------
    str
        ``"Ctrl-C"`` or ``"SIGTERM"``; ``"shutdown"`` when the server stopped for another reason.
    """
    received: list[str] = []

    def stop(signum, frame):
        received.append("SIGTERM" if signum == signal.SIGTERM else "Ctrl-C")
        server.stop()

    previous = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        server.serve()
    except KeyboardInterrupt:
        received.append("Ctrl-C")
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return received[0] if received else "shutdown"
