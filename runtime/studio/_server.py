"""The studio's web server: the standard library's ``http.server``, on loopback only.

Why the standard library: the studio serves one page, one JSON endpoint and
one file to one person on the same machine.  ``ThreadingHTTPServer`` does
that with no dependency to install or keep up to date, and the whole
surface is the handler below, small enough to check line by line.  What a
bigger framework would add (routing, templates, sessions) is not needed,
and what matters here is done explicitly:

* it binds ``127.0.0.1`` (port 0 asks the system for a free port), never
  another interface;
* it answers exactly four paths: ``GET /`` (the page, built in memory at
  start), ``GET /api/state``, ``POST /api/action`` and ``GET /library.lig``
  (the one library Save writes, once written).  No path is ever looked up
  on disk, so ``..``, encoded slashes or absolute paths reach nothing: they
  get 404;
* requests are checked before they are read: a ``Host`` other than this
  server's (DNS rebinding) or an ``Origin`` from another site is 403, a
  POST without a JSON content type 415, without a length 411, over 64 KiB
  413 (the body is not read); bad JSON, an unknown action or a bad field
  400; other methods 405.  Every answer is JSON or the page, never a
  traceback; a bug answers 500 with one line and the server keeps running;
* a slow client is dropped after 30 s without blocking the others.
"""

from __future__ import annotations

import json
import sys
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import urlsplit

from liganimate.lang.diagnostics import LigDiagnostics, format_diagnostic

from ._session import RequestError, Session

__all__ = ["MAX_BODY", "StudioServer", "serve"]

MAX_BODY = 64 * 1024
HOST = "127.0.0.1"


class StudioServer(ThreadingHTTPServer):
    """A ThreadingHTTPServer bound to loopback, holding the session and the page.

    Parameters
    ----------
    session : Session
    page : str
        The studio page (HTML).
    port : int
        0 for a free port.
    quiet : bool
        No per-request log lines.
    """

    daemon_threads = True
    allow_reuse_address = False

    def __init__(self, session: Session, page: str, port: int = 0, quiet: bool = True):
        self.session = session
        session.warm()  # checks the library Save will write while the user poses
        self.page = page.encode("utf-8")
        self.quiet = quiet
        super().__init__((HOST, port), _Handler)

    @property
    def port(self) -> int:
        """The port the server listens on."""
        return self.server_address[1]

    @property
    def url(self) -> str:
        """The page's address."""
        return f"http://{HOST}:{self.port}/"


class _Handler(BaseHTTPRequestHandler):
    server: StudioServer
    server_version = "liganimate-studio"
    sys_version = ""
    protocol_version = "HTTP/1.1"
    timeout = 30

    # ------------------------------------------------------------ plumbing
    def log_message(self, format, *args):
        if not self.server.quiet:
            sys.stderr.write("studio: " + (format % args) + "\n")

    def version_string(self) -> str:
        return self.server_version

    def _send(self, status: int, body: bytes, ctype: str, extra: dict | None = None) -> None:
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
        try:
            self._error(int(code), message or self.responses.get(code, ("error",))[0])
        except OSError:
            pass

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
        try:
            self.raw_requestline = self.rfile.readline(65537)
            if len(self.raw_requestline) > 65536:
                self.requestline = self.request_version = self.command = ""
                self.send_error(414)
                return
            if not self.raw_requestline:
                self.close_connection = True
                return
            if not self.parse_request():
                return
            method = getattr(self, "do_" + self.command, None) if self.command.isalpha() else None
            if method is None:
                self.close_connection = True
                self._error(405, f"the studio does not answer {self.command[:20]!r} requests")
                return
            method()
            self.wfile.flush()
        except TimeoutError:
            self.close_connection = True

    def _guarded(self, fn) -> None:
        try:
            fn()
        except (BrokenPipeError, ConnectionResetError):
            self.close_connection = True
        except Exception as exc:  # noqa: BLE001 - a bug must not stop the server or show a traceback
            self.close_connection = True
            sys.stderr.write(f"studio: internal error: {type(exc).__name__}: {exc}\n")
            try:
                self._error(500, "internal error in the studio; the server keeps running")
            except OSError:
                pass

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
            s = self.server.session
            with s.lock:
                return self._json(200, s.state())
        if path == "/library.lig":
            s = self.server.session
            if not s.saved:
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

    def _post(self) -> None:
        if not self._allowed_origin():
            self.close_connection = True
            return self._error(403, "the studio answers only its own page on 127.0.0.1")
        if urlsplit(self.path).path != "/api/action":
            self.close_connection = True
            return self._error(404, "no such page")
        ctype = self.headers.get("Content-Type", "").split(";")[0].strip().lower()
        if ctype != "application/json":
            self.close_connection = True
            return self._error(415, "send the action as application/json")
        lengths = self.headers.get_all("Content-Length") or []
        if self.headers.get("Transfer-Encoding") or not lengths:
            self.close_connection = True
            return self._error(411, "say the body's length with Content-Length")
        # Strict: one Content-Length of ASCII digits only (int() would take "+2", "0_2" or " 2").
        text = lengths[0].strip(" \t")
        n = int(text) if len(lengths) == 1 and text.isascii() and text.isdigit() else -1
        if n < 0:
            self.close_connection = True
            return self._error(400, "Content-Length is not a length")
        if n > MAX_BODY:
            self.close_connection = True
            return self._error(413, f"the body is over {MAX_BODY} bytes")
        raw = self.rfile.read(n)
        try:
            body = json.loads(raw.decode("utf-8"))
        except (UnicodeDecodeError, ValueError, RecursionError):  # 60,000 "[" nest past Python's stack
            return self._error(400, "the body is not JSON")
        try:
            state = self.server.session.act(body)
        except RequestError as exc:
            return self._error(400, str(exc))
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
