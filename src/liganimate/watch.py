"""``liganimate view FILE --watch``: the viewer page, served on 127.0.0.1 and rebuilt when the file is saved.

One thread does everything: it answers one request at a time, with a
timeout of :data:`TICK` seconds, and between requests looks at the file
(its size, modification time and, when they change, its bytes). A changed
program is compiled and run again (the same path as ``liganimate view``);
the page's script (runtime/view/watch.js) asks ``/watch`` for the version
four times a second and reloads itself, keeping the scene, the frame and
the camera. A program that is wrong keeps the last good page and shows the
diagnostic over it. No queue and no thread grow with the requests or the
saves; the server listens on 127.0.0.1 only and answers only requests
addressed to it there (a ``Host`` check, against DNS rebinding).
"""

from __future__ import annotations

import hashlib
import html
import http.server
import json
import os
import time

#: Seconds between two looks at the file (and the longest a request waits to be read).
TICK = 0.1
#: The page shown before the program has ever run cleanly.
_EMPTY = (
    '<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>{title}</title></head>'
    "<body><h1>{title}</h1></body></html>"
)
_DIAGNOSTIC = (
    '<pre id="lig-diagnostic" hidden style="position:fixed;left:0;right:0;bottom:0;margin:0;padding:1em;'
    "max-height:50%;overflow:auto;background:#fff3f0;color:#900;border-top:2px solid #c00;"
    'font:13px/1.4 monospace;white-space:pre-wrap;z-index:10"></pre>'
)


class WatchedProgram:
    """A program file and the viewer page of its last clean run, rebuilt when the file changes.

    Parameters
    ----------
    path : str
        The .lig file.
    build : callable
        ``build(path) -> str``: the page, or an exception (a diagnostic) when the program is wrong.
    """

    def __init__(self, path: str, build) -> None:
        self.path = path
        self.build = build
        self.version = 0
        self.page: str | None = None
        self.error: str | None = None
        self._stamp: tuple | None = None
        self._digest: bytes | None = None

    def refresh(self) -> bool:
        """Look at the file; rebuild when its bytes changed. True when the version moved on."""
        try:
            st = os.stat(self.path)
            stamp = (st.st_mtime_ns, st.st_size)
        except OSError:
            stamp = None
        if stamp == self._stamp and self.version:
            return False
        self._stamp = stamp
        try:
            with open(self.path, "rb") as fh:
                digest = hashlib.sha256(fh.read()).digest()
        except OSError:
            digest = None
        if digest == self._digest and self.version:
            return False  # touched, not changed
        self._digest = digest
        try:
            self.page, self.error = self.build(self.path), None
        except Exception as exc:  # noqa: BLE001 - a wrong program is shown in the page, never a traceback
            self.error = describe(exc)
        self.version += 1
        return True


def describe(exc: Exception) -> str:
    """What the command line would print for ``exc``: diagnostics with their lines, or one sentence."""
    from liganimate.lang.diagnostics import LigDiagnostics, format_diagnostic
    from liganimate.lang.messages import sentence
    from liganimate.runtime.errors import LigError

    if isinstance(exc, LigDiagnostics):
        return "\n".join(format_diagnostic(d) for d in exc.diagnostics)
    if isinstance(exc, LigError):
        return "error: " + sentence(exc.message) + (f"\n  hint: {sentence(exc.hint)}" if exc.hint else "")
    if isinstance(exc, OSError):
        return f"error: {exc.strerror or exc}: {exc.filename}"
    return f"internal error: {type(exc).__name__}: {exc}"


def watch_page(page: str | None, title: str) -> str:
    """``page`` (the viewer's, or an empty one) made to watch: it may ask its own server, and it polls it."""
    from liganimate.runtime.view import asset

    page = page if page is not None else _EMPTY.format(title=html.escape(title))
    # The viewer's page forbids every request; this one may ask the server that served it.
    page = page.replace("default-src 'none';", "default-src 'none'; connect-src 'self';", 1)
    script = asset("watch.js")
    return page.replace("</body>", f"{_DIAGNOSTIC}\n<script>{script}</script>\n</body>", 1)


def make_handler(program: WatchedProgram, title: str, port_of):
    """The request handler class: ``/`` is the page, ``/watch`` the version and the diagnostic."""

    class Handler(http.server.BaseHTTPRequestHandler):
        def log_message(self, format, *args):  # noqa: A002 - the base class's name
            pass

        def do_GET(self):  # noqa: N802 - the base class's name
            port = port_of()
            if self.headers.get("Host", "") not in (f"127.0.0.1:{port}", f"localhost:{port}"):
                return self._send(403, "text/plain", b"this server answers only on 127.0.0.1")
            route = self.path.split("?", 1)[0]
            if route == "/":
                return self._send(200, "text/html; charset=utf-8", watch_page(program.page, title).encode("utf-8"))
            if route == "/watch":
                body = json.dumps({"version": program.version, "error": program.error}).encode("utf-8")
                return self._send(200, "application/json", body)
            return self._send(404, "text/plain", b"not found")

        def _send(self, status: int, kind: str, body: bytes) -> None:
            self.send_response(status)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

    return Handler


def serve(path: str, build, port: int = 0, ready=None, stop=None) -> None:
    """Serve the page of the program at ``path`` on 127.0.0.1 until Ctrl-C (or ``stop()`` is true).

    ``ready(url, program)`` is called once the server listens.
    """
    program = WatchedProgram(path, build)
    program.refresh()
    server: http.server.HTTPServer | None = None

    def port_of() -> int:
        assert server is not None
        return server.server_address[1]

    server = http.server.HTTPServer(("127.0.0.1", port), make_handler(program, os.path.basename(path), port_of))
    server.timeout = TICK
    try:
        if ready is not None:
            ready(f"http://127.0.0.1:{port_of()}/", program)
        last = time.monotonic()
        while stop is None or not stop():
            server.handle_request()  # one request, or TICK seconds of none
            if time.monotonic() - last >= TICK:
                program.refresh()
                last = time.monotonic()
    finally:
        server.server_close()
