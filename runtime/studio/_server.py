"""The studio's web server: a handler from the standard library's ``http.server``, on loopback only.

Why the standard library: the studio serves one page, one JSON endpoint and
one file to one person on the same machine.  ``BaseHTTPRequestHandler``
parses requests with no dependency to install or keep up to date, and the
whole surface is the handler below, small enough to check line by line.
What a bigger framework would add (routing, templates, sessions) is not
needed, and what matters here is done explicitly:

* it binds ``127.0.0.1`` (port 0 asks the system for a free port), never
  another interface;
* it answers exactly four paths: ``GET /`` (the page, built in memory at
  start), ``GET /api/state``, ``POST /api/action`` and ``GET /library.lig``
  (the one library Save writes, once written).  No path is ever looked up
  on disk, so ``..``, encoded slashes or absolute paths reach nothing: they
  get 404;
* requests are checked before they are read: a ``Host`` other than this
  server's (DNS rebinding) or an ``Origin`` from another site is 403, a
  POST without a JSON content type 415, without a length 411, with two
  lengths or one that is not ASCII digits 400, over 64 KiB 413 (the body
  is not read); bad JSON of any shape, an unknown action or a bad field
  400; other methods 405.  Every answer is JSON or the page, never a
  traceback; a bug answers 500 with one line and the server keeps running;
* the sockets are the connection loop's (:mod:`._loop`): a fixed pool of
  workers, a bounded queue, 503 when full, deadlines for slow clients.
  The handler here runs on a whole request already in memory and writes
  its answer to memory, so it never waits for a client.  A Save is
  answered later, from the loop's slow lane, so that writing the library
  holds neither a worker nor the session (:meth:`Session.save`).
"""

from __future__ import annotations

import io
import json
import socket
import sys
import threading
from collections.abc import Callable
from http.server import BaseHTTPRequestHandler
from urllib.parse import urlsplit

from liganimate.lang.diagnostics import LigDiagnostics, format_diagnostic

from ._limits import StudioLimits
from ._loop import Answer, ConnectionLoop
from ._session import RequestError, Session

__all__ = ["MAX_BODY", "StudioServer", "serve"]

MAX_BODY = StudioLimits().max_body
HOST = "127.0.0.1"
#: Digits a JSON whole number may have: seeds, frames and indices need at most 10.
MAX_DIGITS = 20


def _stderr(line: str) -> None:
    sys.stderr.write(line + "\n")
    sys.stderr.flush()


class StudioServer:
    """The studio's HTTP server on loopback: the session, the page, and the connection loop serving them.

    Parameters
    ----------
    session : Session
    page : str
        The studio page (HTML).
    port : int
        0 for a free port.
    quiet : bool
        No per-request log lines (clients dropped and internal errors are always logged).
    limits : StudioLimits, optional
        Pool, queue, connections, timeouts and sizes (default :class:`StudioLimits`).
    log : callable, optional
        ``log(line)`` for log lines (default: standard error).
    """

    def __init__(
        self,
        session: Session,
        page: str,
        port: int = 0,
        quiet: bool = True,
        limits: StudioLimits | None = None,
        log=None,
    ):
        self.session = session
        session.warm()  # checks the library Save will write while the user poses
        self.page = page.encode("utf-8")
        self.quiet = quiet
        self.limits = limits or StudioLimits()
        self.log = log or _stderr
        self.socket = socket.create_server((HOST, port), backlog=min(self.limits.connections, 1024))
        self.server_address = self.socket.getsockname()
        self._loop = ConnectionLoop(self.socket, self._answer, self.limits, self.log)

    @property
    def port(self) -> int:
        """The port the server listens on."""
        return self.server_address[1]

    @property
    def url(self) -> str:
        """The page's address."""
        return f"http://{HOST}:{self.port}/"

    def serve_forever(self, poll_interval: float = 0.5) -> None:
        """Serve until :meth:`shutdown` is called from another thread (or KeyboardInterrupt)."""
        self._loop.serve_forever(poll_interval)

    def shutdown(self) -> None:
        """Stop :meth:`serve_forever` and wait until it has stopped, its workers with it."""
        self._loop.shutdown()

    def server_close(self) -> None:
        """Close the listening socket (after :meth:`shutdown`)."""
        self.socket.close()
        self._loop.close()

    def stats(self) -> dict:
        """Open connections, queued and busy requests, worker threads, and counts of 503s, drops and answers."""
        return self._loop.stats()

    def _answer(self, request: bytes, client: tuple) -> Answer:
        return _Handler(request, client, self).answer()


class _BadJSON(ValueError):
    """A body that parses as JSON the studio will not take; the message is the 400's."""


def _no_constant(name: str):
    raise _BadJSON(f"the body holds {name}, which is not a JSON number")


def _finite(text: str) -> float:
    value = float(text)
    if value in (float("inf"), float("-inf")):
        raise _BadJSON(f"the body holds the number {text[:20]}, beyond the largest a double holds")
    return value


def _whole(text: str) -> int:
    if len(text.lstrip("-")) > MAX_DIGITS:
        raise _BadJSON(
            f"the body holds a whole number of {len(text.lstrip('-'))} digits; the studio takes at most {MAX_DIGITS}"
        )
    return int(text)


def parse_body(raw: bytes):
    """The JSON of a request body, or ``_BadJSON`` (a ValueError) with the one sentence a 400 says."""
    try:
        return json.loads(raw.decode("utf-8"), parse_constant=_no_constant, parse_float=_finite, parse_int=_whole)
    except _BadJSON:
        raise
    except (UnicodeDecodeError, ValueError, RecursionError):  # 60,000 "[" nest past Python's stack
        raise _BadJSON("the body is not JSON") from None


class _Handler(BaseHTTPRequestHandler):
    """One request, already whole in memory; its answer is written to memory (the loop sends it)."""

    server: StudioServer  # type: ignore[assignment]
    server_version = "liganimate-studio"
    sys_version = ""
    protocol_version = "HTTP/1.1"

    def __init__(self, request: bytes, client: tuple, server: StudioServer):  # no socket: not the base's __init__
        self.rfile = io.BytesIO(request)
        self.wfile = self._out = io.BytesIO()
        self.client_address = client
        self.server = server
        self.close_connection = True
        self.deferred: Callable[[], None] | None = None
        self._length = len(request)

    def answer(self) -> Answer:
        """Handle the request; the answer, or a deferred one (a Save)."""
        self.handle_one_request()
        if self.deferred is not None:
            return Answer(deferred=self._later)
        return Answer(self._out.getvalue(), self.close_connection)

    def _later(self) -> Answer:
        self._guarded(self.deferred)
        return Answer(self._out.getvalue(), self.close_connection)

    # ------------------------------------------------------------ plumbing
    def log_message(self, format, *args):
        if not self.server.quiet:
            self.server.log("studio: " + (format % args))

    def version_string(self) -> str:
        return self.server_version

    def _send(self, status: int, body: bytes, ctype: str, extra: dict | None = None) -> None:
        if self.rfile.tell() < self._length:
            self.close_connection = True  # bytes this request did not use (a GET's body): never read as a request
        self.send_response(status)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("X-Frame-Options", "DENY")
        self.send_header("Referrer-Policy", "no-referrer")
        for k, v in (extra or {}).items():
            self.send_header(k, v)
        if self.close_connection:
            self.send_header("Connection", "close")
        self.end_headers()
        if self.command != "HEAD":
            self.wfile.write(body)

    def _json(self, status: int, value) -> None:
        self._send(status, json.dumps(value, allow_nan=False).encode("utf-8"), "application/json; charset=utf-8")

    def _error(self, status: int, message: str) -> None:
        self._json(status, {"error": message})

    def send_error(self, code, message=None, explain=None):
        """Errors found by the base class (bad request line, headers) as JSON, and the connection closed."""
        self.close_connection = True
        if int(code) >= 500:
            code = 400  # e.g. 505 for "HTTP/9.9": to us a malformed request like any other
        if getattr(self, "request_version", "HTTP/0.9") == "HTTP/0.9":
            # A request line too broken to name its version: answer with a
            # status line anyway (HTTP/0.9 answers have none).
            self.request_version = "HTTP/1.0"
        self._error(int(code), message or self.responses.get(code, ("error",))[0])

    def _allowed_origin(self) -> bool:
        # A page from another site, or a name resolving to 127.0.0.1 (DNS
        # rebinding), must not drive the studio or read its state.
        port = self.server.port
        mine = {f"127.0.0.1:{port}", f"localhost:{port}"}
        if self.headers.get("Host", "") not in mine:
            return False
        origin = self.headers.get("Origin")
        return origin is None or origin in {f"http://{h}" for h in mine}

    def handle_one_request(self):
        """As the base class, but a method we do not serve is 405 (the base class says 501)."""
        self.raw_requestline = self.rfile.readline(65537)
        if len(self.raw_requestline) > 65536:
            self.requestline = self.request_version = self.command = ""
            self.send_error(414)
            return
        if not self.parse_request():
            return
        method = getattr(self, "do_" + self.command, None) if self.command.isalpha() else None
        if method is None:
            self.close_connection = True
            self._error(405, f"the studio does not answer {self.command[:20]!r} requests")
            return
        method()

    def _guarded(self, fn) -> None:
        try:
            fn()
        except Exception as exc:  # noqa: BLE001 - a bug must not stop the server or show a traceback
            self.close_connection = True
            self.server.log(f"studio: internal error: {type(exc).__name__}: {exc}")
            self._error(500, "internal error in the studio; the server keeps running")

    # ------------------------------------------------------------- methods
    def do_GET(self):
        self._guarded(self._get)

    def do_HEAD(self):
        self._guarded(self._get)

    def do_POST(self):
        self._guarded(self._post)

    def _get(self) -> None:
        if not self._allowed_origin():
            self.close_connection = True
            return self._error(403, "the studio answers only its own page on 127.0.0.1")
        path = urlsplit(self.path).path
        if path in ("/", "/index.html"):
            csp = (
                "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; "
                "connect-src 'self'; img-src data:; base-uri 'none'; form-action 'none'"
            )
            return self._send(200, self.server.page, "text/html; charset=utf-8", {"Content-Security-Policy": csp})
        if path == "/api/state":
            return self._send(200, self.server.session.state_json(), "application/json; charset=utf-8")
        if path == "/library.lig":
            s = self.server.session
            if not s.has_saved:
                return self._error(404, "nothing saved yet")
            try:
                with open(s.save_path, "rb") as fh:
                    data = fh.read()
            except OSError:
                return self._error(404, "the saved library is gone")
            return self._send(
                200, data, "text/plain; charset=utf-8", {"Content-Disposition": 'attachment; filename="library.lig"'}
            )
        self._error(404, "no such page")

    def _body_length(self) -> int | None:
        """The one Content-Length, or None after answering why there is none the studio takes."""
        ctype = self.headers.get("Content-Type", "").split(";")[0].strip().lower()
        if ctype != "application/json":
            self._error(415, "send the action as application/json")
            return None
        lengths = self.headers.get_all("Content-Length") or []
        if self.headers.get("Transfer-Encoding") or not lengths:
            self._error(411, "say the body's length with Content-Length")
            return None
        # Strict: one Content-Length of ASCII digits only (int() would take "+2", "0_2" or " 2").
        text = lengths[0].strip(" \t")
        if len(lengths) != 1 or not text.isascii() or not text.isdigit():
            self._error(400, "Content-Length is not a length")
            return None
        if len(text) > 18 or int(text) > self.server.limits.max_body:
            self._error(413, f"the body is over {self.server.limits.max_body} bytes")
            return None
        return int(text)

    def _post(self) -> None:
        if not self._allowed_origin():
            self.close_connection = True
            return self._error(403, "the studio answers only its own page on 127.0.0.1")
        if urlsplit(self.path).path != "/api/action":
            self.close_connection = True
            return self._error(404, "no such page")
        n = self._body_length()
        if n is None:
            self.close_connection = True
            return
        raw = self.rfile.read(n)
        if len(raw) < n:
            self.close_connection = True
            return self._error(400, "the body is shorter than its Content-Length")
        try:
            body = parse_body(raw)
        except _BadJSON as exc:
            return self._error(400, str(exc))
        session = self.server.session
        try:
            if isinstance(body, dict) and body.get("action") == "save":
                ticket = session.ask_save()
                self.deferred = lambda: self._save(ticket)  # answered from the slow lane: the disk holds no worker
                return
            state = session.act(body)
        except RequestError as exc:
            return self._error(exc.status, str(exc))
        self._json(200, state)

    def _save(self, ticket: int) -> None:
        try:
            state = self.server.session.save(ticket)
        except RequestError as exc:
            return self._error(exc.status, str(exc))
        except LigDiagnostics as exc:
            return self._error(
                500, "the library to save does not compile: " + "; ".join(format_diagnostic(d) for d in exc.diagnostics)
            )
        except OSError as exc:
            return self._error(500, f"cannot write the library: {exc.strerror or exc}")
        self._json(200, state)


def serve(server: StudioServer, ready=None) -> None:
    """Serve until interrupted (KeyboardInterrupt) or :meth:`shutdown`; ``ready`` is set once listening."""
    if ready is not None:
        ready.set()
    try:
        server.serve_forever(poll_interval=0.2)
    finally:
        server.server_close()


def start_in_thread(server: StudioServer) -> threading.Thread:
    """Serve from a daemon thread (tests, notebooks); stop with ``server.shutdown()``."""
    t = threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.1}, daemon=True)
    t.start()
    return t
