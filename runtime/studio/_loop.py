"""The studio's connection loop: one thread does all the socket work, a fixed pool does the requests.

Why not a thread per connection (``ThreadingHTTPServer``, what the studio
had): 50 clients hammering it left 1,717 threads and 934 MB behind, and a
client sending one byte a second held its thread for good (issue 24).
Here:

* one thread (the caller of :meth:`ConnectionLoop.serve_forever`) accepts,
  reads and writes, never blocking (``selectors``).  A request is read
  into memory until it is whole (its head, then as many body bytes as its
  one ``Content-Length`` says), so a slow client costs a buffer and a
  deadline, not a thread: one that has not sent a whole request
  ``request_timeout`` seconds after its first byte gets 408 and is
  dropped;
* a whole request goes to a bounded queue served by a fixed pool of
  workers, cheap reads (GET) first.  When the queue is full the request
  is answered 503 with ``Retry-After``, and so is a connection beyond the
  limit of open ones: the server says it is busy instead of hanging;
* an answer may be *deferred* (a Save): the worker hands back a function,
  which one extra thread runs in turn, so that a slow disk holds neither a
  worker nor the session;
* a client that goes away (reset, broken pipe, timeout) is one log line
  naming it, never a traceback.

The loop knows nothing of the studio: ``handle(request, client)`` turns
the bytes of one whole request into an :class:`Answer`.
"""

from __future__ import annotations

import collections
import functools
import itertools
import queue
import selectors
import socket
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from ._limits import StudioLimits

__all__ = ["Answer", "ConnectionLoop", "request_length", "status_bytes"]

#: Seconds a connection being closed may still send (what it sends is discarded), so that
#: the answer is not lost to a reset when the client's unread bytes are thrown away.
_LINGER = 2.0


@dataclass
class Answer:
    """What the handler makes of one request.

    Attributes
    ----------
    data : bytes
        The whole HTTP answer (status line, headers, body).
    close : bool
        Close the connection once it is sent.
    deferred : callable or None
        If given, ``data`` is ignored: ``deferred()`` is run later on the
        loop's one slow-work thread and returns the real :class:`Answer`.
    """

    data: bytes = b""
    close: bool = True
    deferred: Callable[[], Answer] | None = None


def status_bytes(status: int, reason: str, body: bytes, extra: dict | None = None) -> bytes:
    """A small JSON answer that closes the connection, made without a handler (503, 408, 431)."""
    head = [
        f"HTTP/1.1 {status} {reason}",
        "Content-Type: application/json; charset=utf-8",
        f"Content-Length: {len(body)}",
        "Cache-Control: no-store",
        "Connection: close",
    ] + [f"{k}: {v}" for k, v in (extra or {}).items()]
    return ("\r\n".join(head) + "\r\n\r\n").encode("ascii") + body


def _json_error(message: str) -> bytes:
    import json

    return json.dumps({"error": message}).encode("utf-8")


def _head_end(buf: bytearray) -> int:
    """The length of the request's head (through its blank line), or -1 if the blank line has not come."""
    ends = [i for i in (buf.find(b"\n\r\n"), buf.find(b"\n\n")) if i >= 0]
    if not ends:
        return -1
    i = min(ends)
    return i + (3 if buf[i + 1 : i + 2] == b"\r" else 2)


def request_length(buf: bytearray, limits: StudioLimits) -> int | None:
    """How many bytes of ``buf`` make its first request, or None while it is not whole.

    A request whose framing is wrong (not HTTP, two ``Content-Length``
    headers or one that is not ASCII digits, ``Transfer-Encoding``, a body
    over the limit) is whole as it stands, without a body: the handler
    then refuses it and the connection is closed, so no byte after it is
    ever read as a request.

    Parameters
    ----------
    buf : bytearray
        What the client has sent so far (at least one byte).
    limits : StudioLimits

    Returns
    -------
    int or None
        -1 when the head is over ``limits.max_head`` without ending.
    """
    if not buf[:1].isalpha():
        return len(buf)  # no method starts with anything else: a TLS hello, a stray CRLF, junk
    end = _head_end(buf)
    if end < 0:
        return -1 if len(buf) > limits.max_head else None
    lengths, chunked = [], False
    for line in bytes(buf[:end]).split(b"\n")[1:]:
        name, _, value = line.partition(b":")
        name = name.strip().lower()
        if name == b"content-length":
            lengths.append(value.strip(b" \t\r"))
        elif name == b"transfer-encoding":
            chunked = True
    if chunked or len(lengths) > 1:
        return end
    text = lengths[0] if lengths else b"0"
    if not text.isdigit():
        return end
    n = int(text) if len(text) <= 18 else limits.max_body + 1  # int() refuses over 4,300 digits
    if n > limits.max_body:
        return end
    return end + n if len(buf) >= end + n else None


def _why(exc: OSError) -> str:
    if isinstance(exc, ConnectionResetError):
        return "the client reset the connection"
    if isinstance(exc, BrokenPipeError):
        return "the client closed the connection before reading the answer"
    return f"the connection failed ({exc.strerror or exc})"


@dataclass(eq=False)
class _Conn:
    """One client connection and what the loop is doing with it."""

    sock: socket.socket
    client: tuple
    inbuf: bytearray = field(default_factory=bytearray)
    out: memoryview | None = None
    sent: int = 0
    close_after: bool = False
    phase: str = "read"  # read, busy (a worker or the slow lane has it), write, closing
    deadline: float = 0.0
    events: int = 0

    @property
    def name(self) -> str:
        return f"{self.client[0]}:{self.client[1]}"


class ConnectionLoop:
    """Serve HTTP on a listening socket with a bounded pool, queue and set of connections.

    Parameters
    ----------
    listener : socket.socket
        Bound and listening.
    handle : callable
        ``handle(request: bytes, client: tuple) -> Answer`` for one whole
        request; run on a worker thread.  It must not raise.
    limits : StudioLimits
    log : callable
        ``log(line)`` for the lines about clients dropped.
    """

    def __init__(self, listener: socket.socket, handle, limits: StudioLimits, log: Callable[[str], None]):
        self.listener = listener
        self.handle = handle
        self.limits = limits
        self.log = log
        self._jobs: queue.PriorityQueue = queue.PriorityQueue(maxsize=limits.queue)
        self._slow: queue.SimpleQueue = queue.SimpleQueue()
        self._done: collections.deque = collections.deque()
        self._order = itertools.count()
        self._conns: set[_Conn] = set()
        self._busy = 0
        self._busy_lock = threading.Lock()
        self._counts: collections.Counter[str] = collections.Counter()
        self._stop = threading.Event()
        self._stopped = threading.Event()
        self._stopped.set()
        self._wake_r, self._wake_w = socket.socketpair()
        for s in (self._wake_r, self._wake_w, listener):
            s.setblocking(False)
        self._sel = selectors.DefaultSelector()
        self._threads: list[threading.Thread] = []

    # ------------------------------------------------------------ running
    def serve_forever(self, poll_interval: float = 0.5) -> None:
        """Serve until :meth:`shutdown` (or an exception such as KeyboardInterrupt); the pool lives as long."""
        self._stop.clear()
        self._stopped.clear()
        self._sel.register(self.listener, selectors.EVENT_READ, "accept")
        self._sel.register(self._wake_r, selectors.EVENT_READ, "wake")
        self._start_threads()
        try:
            while not self._stop.is_set():
                self._turn(poll_interval)
        finally:
            self._stop_threads()
            for conn in list(self._conns):
                self._close(conn)
            self._sel.unregister(self.listener)
            self._sel.unregister(self._wake_r)
            self._stopped.set()

    def shutdown(self) -> None:
        """Stop :meth:`serve_forever` (from another thread) and wait until it has."""
        self._stop.set()
        self._wake()
        self._stopped.wait()

    def close(self) -> None:
        """Release the loop's own sockets (after :meth:`shutdown`)."""
        self._sel.close()
        self._wake_r.close()
        self._wake_w.close()

    def stats(self) -> dict:
        """Counts for tests and benchmarks: open connections, queued and busy requests, and totals."""
        return {
            "connections": len(self._conns),
            "queued": self._jobs.qsize(),
            "busy": self._busy,
            "threads": sum(t.is_alive() for t in self._threads),
            **self._counts,
        }

    def _start_threads(self) -> None:
        for k in range(self.limits.workers):
            self._threads.append(threading.Thread(target=self._work, name=f"liganimate-studio-{k + 1}", daemon=True))
        self._threads.append(threading.Thread(target=self._slow_work, name="liganimate-studio-save", daemon=True))
        for t in self._threads:
            t.start()

    def _stop_threads(self) -> None:
        for _ in range(self.limits.workers):
            # First in the queue (and never compared past the order), so the workers stop before what is left;
            # put may wait for room, while the workers drain the queue.
            self._jobs.put((-1, next(self._order), None, b""))
        self._slow.put(None)
        for t in self._threads:
            t.join(timeout=30)
        self._threads = []

    def _wake(self) -> None:
        try:
            self._wake_w.send(b"x")
        except (BlockingIOError, OSError):
            pass  # full: the loop is waking anyway; closed: it has stopped

    # ------------------------------------------------------------ threads
    def _work(self) -> None:
        while True:
            _, _, conn, request = self._jobs.get()
            if conn is None:
                return
            with self._busy_lock:
                self._busy += 1
            try:
                answer = self._safely(functools.partial(self.handle, request, conn.client))
            finally:
                with self._busy_lock:
                    self._busy -= 1
            self._done.append((conn, answer))
            self._wake()

    def _slow_work(self) -> None:
        while True:
            item = self._slow.get()
            if item is None:
                return
            conn, deferred = item
            self._done.append((conn, self._safely(deferred)))
            self._wake()

    def _safely(self, make: Callable[[], Answer]) -> Answer:
        """``make()``, or a 500 if it raised: a bug costs one answer, never a worker of the pool."""
        try:
            return make()
        except Exception as exc:  # noqa: BLE001 - the handler guards itself; this is the last line
            self.log(f"studio: internal error: {type(exc).__name__}: {exc}")
            body = _json_error("internal error in the studio; the server keeps running")
            return Answer(status_bytes(500, "Internal Server Error", body))

    # --------------------------------------------------------------- loop
    def _turn(self, poll_interval: float) -> None:
        now = time.monotonic()
        deadlines = [c.deadline for c in self._conns if c.phase != "busy"]
        timeout = max(0.0, min([poll_interval] + [d - now for d in deadlines]))
        for key, events in self._sel.select(timeout):
            if key.data == "accept":
                self._accept()
            elif key.data == "wake":
                try:
                    self._wake_r.recv(4096)
                except BlockingIOError:
                    pass
            elif key.data in self._conns:
                self._ready(key.data, events)
        while self._done:
            self._answered(*self._done.popleft())
        self._expire(time.monotonic())

    def _ready(self, conn: _Conn, events: int) -> None:
        try:
            if events & selectors.EVENT_READ:
                self._read(conn)
            if events & selectors.EVENT_WRITE and conn in self._conns:
                self._write(conn)
        except Exception as exc:  # noqa: BLE001 - a bug costs one connection, never the server
            self.log(f"studio: internal error with {conn.name}: {type(exc).__name__}: {exc}")
            self._close(conn)

    def _watch(self, conn: _Conn, events: int) -> None:
        if events == conn.events:
            return
        if conn.events and events:
            self._sel.modify(conn.sock, events, conn)
        elif events:
            self._sel.register(conn.sock, events, conn)
        else:
            self._sel.unregister(conn.sock)
        conn.events = events

    def _accept(self) -> None:
        for _ in range(64):
            try:
                sock, client = self.listener.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError:  # out of descriptors, or the client gave up already: try again next turn
                return
            sock.setblocking(False)
            conn = _Conn(sock, client, deadline=time.monotonic() + self.limits.idle_timeout)
            if len(self._conns) >= self.limits.connections:
                self._counts["too_many_connections"] += 1
                if len(self._conns) >= 2 * self.limits.connections:
                    _refuse(sock)  # not even room to close gently
                    continue
                self._conns.add(conn)  # answered, then closed gently like any other (see _linger)
                self._send(conn, Answer(_busy(f"the studio has {self.limits.connections} connections open, its limit")))
                continue
            self._conns.add(conn)
            self._watch(conn, selectors.EVENT_READ)

    def _read(self, conn: _Conn) -> None:
        try:
            data = conn.sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as exc:
            return self._drop(conn, _why(exc), quiet=conn.phase == "closing")
        if conn.phase == "closing":
            if not data:
                self._close(conn)
            return  # what a closing client still sends is thrown away
        if not data:
            if conn.inbuf:
                return self._drop(conn, "the client closed the connection in the middle of a request")
            return self._close(conn)
        if not conn.inbuf:
            conn.deadline = time.monotonic() + self.limits.request_timeout
        conn.inbuf += data
        self._next_request(conn)

    def _next_request(self, conn: _Conn) -> None:
        """Hand the connection's first request to the pool if it is whole; else wait for more."""
        if not conn.inbuf:
            return self._watch(conn, selectors.EVENT_READ)
        n = request_length(conn.inbuf, self.limits)
        if n is None:
            return self._watch(conn, selectors.EVENT_READ)
        if n < 0:
            message = _json_error(f"the request line and headers are over {self.limits.max_head} bytes")
            return self._send(conn, Answer(status_bytes(431, "Request Header Fields Too Large", message)))
        request = bytes(conn.inbuf[:n])
        del conn.inbuf[:n]
        # Cheap reads first: the page's state and the page itself answer even while actions queue.
        priority = 0 if request.startswith((b"GET ", b"HEAD ")) else 1
        try:
            self._jobs.put_nowait((priority, next(self._order), conn, request))
        except queue.Full:
            self._counts["queue_full"] += 1
            return self._send(conn, Answer(_busy(f"the studio is busy: {self.limits.queue} requests wait already")))
        conn.phase = "busy"
        self._watch(conn, 0)

    def _answered(self, conn: _Conn, answer: Answer) -> None:
        if conn not in self._conns:
            return
        if answer.deferred is not None:
            self._slow.put((conn, answer.deferred))
            return
        self._counts["answered"] += 1
        self._send(conn, answer)

    def _send(self, conn: _Conn, answer: Answer) -> None:
        conn.out, conn.sent, conn.close_after = memoryview(answer.data), 0, answer.close
        conn.phase = "write"
        conn.deadline = time.monotonic() + self.limits.write_timeout
        self._write(conn)

    def _write(self, conn: _Conn) -> None:
        if conn.out is None:
            return
        try:
            conn.sent += conn.sock.send(conn.out[conn.sent : conn.sent + (1 << 20)])
        except (BlockingIOError, InterruptedError):
            return self._watch(conn, selectors.EVENT_WRITE)
        except OSError as exc:
            return self._drop(conn, _why(exc))
        if conn.sent < len(conn.out):
            return self._watch(conn, selectors.EVENT_WRITE)
        conn.out = None
        if conn.close_after:
            return self._linger(conn)
        conn.phase = "read"
        conn.deadline = time.monotonic() + (self.limits.request_timeout if conn.inbuf else self.limits.idle_timeout)
        self._next_request(conn)

    def _linger(self, conn: _Conn) -> None:
        """Close gently: no more writing, and the client's last bytes read and discarded for a moment."""
        conn.phase, conn.inbuf = "closing", bytearray()
        conn.deadline = time.monotonic() + _LINGER
        try:
            conn.sock.shutdown(socket.SHUT_WR)
        except OSError:
            return self._close(conn)
        self._watch(conn, selectors.EVENT_READ)

    def _expire(self, now: float) -> None:
        for conn in [c for c in self._conns if c.phase != "busy" and c.deadline <= now]:
            if conn.phase == "closing" or (conn.phase == "read" and not conn.inbuf):
                self._close(conn)  # a lingering close done, or a kept-alive connection left idle
            elif conn.phase == "read":
                t = self.limits.request_timeout
                self._counts["timed_out"] += 1
                self.log(f"studio: dropped {conn.name}: no whole request within {t:g} s (a slow client)")
                message = _json_error(f"the request did not arrive whole within {t:g} s")
                self._send(conn, Answer(status_bytes(408, "Request Timeout", message)))
            else:
                self._drop(conn, f"it did not read its answer within {self.limits.write_timeout:g} s")

    def _drop(self, conn: _Conn, why: str, quiet: bool = False) -> None:
        if not quiet:
            self._counts["dropped"] += 1
            self.log(f"studio: dropped {conn.name}: {why}")
        self._close(conn)

    def _close(self, conn: _Conn) -> None:
        self._watch(conn, 0)
        self._conns.discard(conn)
        conn.out, conn.inbuf = None, bytearray()
        try:
            conn.sock.close()
        except OSError:
            pass


def _busy(why: str) -> bytes:
    return status_bytes(503, "Service Unavailable", _json_error(why + "; try again in a second"), {"Retry-After": "1"})


def _refuse(sock: socket.socket) -> None:
    """Answer 503 and close at once: more connections are open than the loop will even linger on."""
    try:
        sock.send(_busy("the studio has too many connections open"))
    except OSError:
        pass
    finally:
        sock.close()
