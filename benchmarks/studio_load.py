"""Studio under load: 50 clients x 100 mixed requests on loopback, against the studio's server and the stock one.

Issue 24 saw 50 clients hammer ``liganimate studio`` (then Python's
``ThreadingHTTPServer``, a thread per connection, Save compiling under the
session lock): the clients did not finish in 500 s, and the server held
1,717 threads and 934 MB and answered nothing for a minute.  This runs the
same crowd, in one run, against two servers in their own processes, each
serving the same HUMANOID session with the same handler:

* ``loop``: the studio's server (``runtime/studio/_loop.py``): one loop
  thread, a fixed pool of workers, a bounded queue, Saves on a slow lane;
* ``stock``: the standard library's ``ThreadingHTTPServer`` calling that
  same handler for each request on its connection's own thread: what a
  user of ``http.server`` would otherwise write.

Each client keeps one connection alive and sends its requests in a mix
drawn from a seeded generator: the page's state (most of them), next
generation, take, set, undo, keep, delete, play, save and the page.  A
503 is honoured (the client waits its ``Retry-After``).  Meanwhile a probe
asks for the state every half second on a new connection: the time a new
user waits.  Reported for each server: p50 and p99 latency (state
requests, all requests, the probe), errors (no answer, or a 5xx other than
503) and 503s, the server's threads and memory (RSS) before, at most
during, and after the crowd has gone, the server's CPU time beside the
wall time, and the load average.  The goals: p99 of the state under 1 s
and the threads back to idle, with no errors.  Memory after a crowd is the
idle server's plus the session's own state, which the crowd's Keeps and
actions grow up to its caps (200 kept poses, 500 undo steps): crowd after
crowd on one server, the loop's RSS levels off near 110 MB (from 69 MB
idle) once 200 poses are kept.  Each run is bounded in time: the clients
stop asking at a deadline.

The stock server is used as it comes: its listen backlog of 5 is what
makes some of the 50 clients' connections fail or wait for a SYN resent
after a second.

Usage: ``python benchmarks/studio_load.py [--quick] [--clients N] [--requests N]``
(``--quick``: 50 clients x 12 requests, under a minute).  The last line is
one JSON object.
"""

from __future__ import annotations

import argparse
import collections
import http.client
import json
import os
import random
import socketserver
import subprocess
import sys
import tempfile
import threading
import time
from http.server import ThreadingHTTPServer
from types import SimpleNamespace

GOAL_P99_S = 1.0
#: (action, weight): what the clients send; None is GET /api/state, "page" is GET /.
MIX = (
    (None, 40),
    ("next", 12),
    ("take", 12),
    ("set", 6),
    ("undo", 6),
    ("keep", 8),
    ("delete", 3),
    ("play", 4),
    ("save", 4),
    ("page", 5),
)


# ------------------------------------------------------------------ servers
def _serve(kind: str, folder: str) -> None:
    """The server process: build the session, print the port, serve until stdin closes."""
    from liganimate.runtime.studio import Session, StudioServer, start_in_thread, studio_model, studio_page

    fig, model, _ = studio_model(None, None)
    session = Session(fig, model, "POSES", os.path.join(folder, f"{kind}.lig"), seed=11)
    page = studio_page(session.generator, model)
    if kind == "loop":
        server = StudioServer(session, page)
        session._warming.join()
        start_in_thread(server)
        port = server.port
    else:
        stock = _stock_server(session, page)
        session.warm()
        session._warming.join()
        threading.Thread(target=stock.serve_forever, daemon=True).start()
        port = stock.server_address[1]
    print(port, flush=True)
    sys.stdin.read()


def _stock_server(session, page: str) -> ThreadingHTTPServer:
    """``ThreadingHTTPServer`` (a thread per connection) calling the studio's handler for each request."""
    from liganimate.runtime.studio import StudioLimits
    from liganimate.runtime.studio._loop import request_length
    from liganimate.runtime.studio._server import _Handler

    limits = StudioLimits()
    shim = SimpleNamespace(session=session, page=page.encode("utf-8"), quiet=True, limits=limits, log=lambda line: None)

    class Stock(socketserver.StreamRequestHandler):
        timeout = 30  # as the studio's old handler

        def handle(self):
            buf = bytearray()
            while True:
                n = request_length(buf, limits) if buf else None
                while n is None:
                    data = self.request.recv(65536)
                    if not data:
                        return
                    buf += data
                    n = request_length(buf, limits)
                if n < 0:
                    return
                request = bytes(buf[:n])
                del buf[:n]
                answer = _Handler(request, self.client_address, shim).answer()
                if answer.deferred is not None:
                    answer = answer.deferred()  # the Save, on this connection's thread
                self.request.sendall(answer.data)
                if answer.close:
                    return

    class Server(ThreadingHTTPServer):
        daemon_threads = True

        def handle_error(self, request, client_address):
            pass  # a dropped client; the studio's loop logs a line, this counts as an error at the client

    server = Server(("127.0.0.1", 0), Stock)
    shim.port = server.server_address[1]
    return server


def _proc(pid: int) -> dict:
    """Threads, RSS (MB) and CPU seconds of a process, from /proc."""
    status = {}
    with open(f"/proc/{pid}/status", encoding="ascii") as fh:
        for line in fh:
            key, _, value = line.partition(":")
            status[key] = value.strip()
    with open(f"/proc/{pid}/stat", encoding="ascii") as fh:
        fields = fh.read().rsplit(")", 1)[1].split()
    tick = os.sysconf("SC_CLK_TCK")
    return {
        "threads": int(status["Threads"]),
        "rss_mb": round(int(status["VmRSS"].split()[0]) / 1024, 1),
        "cpu_s": (int(fields[11]) + int(fields[12])) / tick,
    }


# ------------------------------------------------------------------ clients
class _Client:
    """One client: a kept-alive connection and a seeded mix of requests."""

    def __init__(self, port: int, seed: int, results: list, deadline: float):
        self.port, self.rng, self.results, self.deadline = port, random.Random(seed), results, deadline
        self.conn: http.client.HTTPConnection | None = None

    def request(self, method: str, path: str, body: dict | None) -> tuple:
        if self.conn is None:
            self.conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=30)
        headers = {"Host": f"127.0.0.1:{self.port}"}
        data = None
        if body is not None:
            headers["Content-Type"] = "application/json"
            data = json.dumps(body)
        try:
            self.conn.request(method, path, body=data, headers=headers)
            r = self.conn.getresponse()
            r.read()
            if r.getheader("Connection", "").lower() == "close":
                self.conn.close()
                self.conn = None
            return r.status, r.getheader("Retry-After")
        except (OSError, http.client.HTTPException):
            self.conn.close()
            self.conn = None
            return None, None

    def body(self, action: str) -> dict:
        rng = self.rng
        extra = {
            "take": {"candidate": rng.randrange(9), "link": rng.randrange(1, 20)},
            "set": {"link": rng.randrange(1, 20), "angles": [rng.uniform(-40, 40) for _ in range(3)]},
            "delete": {"index": 0},
            "next": {"intensity": round(rng.uniform(0.05, 0.5), 3)},
        }
        return {"action": action, **extra.get(action, {})}

    def run(self, n: int) -> None:
        actions = [a for a, _ in MIX]
        weights = [w for _, w in MIX]
        for _ in range(n):
            if time.monotonic() > self.deadline:
                self.results.append(("unsent", None, 0.0))
                continue
            action = self.rng.choices(actions, weights)[0]
            if action is None or action == "page":
                method, path, body, kind = "GET", "/api/state" if action is None else "/", None, action or "state"
            else:
                method, path, body, kind = "POST", "/api/action", self.body(action), action
            t0 = time.perf_counter()
            status, retry = self.request(method, path, body)
            self.results.append((kind, status, time.perf_counter() - t0))
            if status == 503:
                time.sleep(min(float(retry or 1), 1.0))
        if self.conn is not None:
            self.conn.close()


def _probe(port: int, stop: threading.Event, out: list) -> None:
    """A new user every half second: one state request on a new connection."""
    while not stop.wait(0.5):
        t0 = time.perf_counter()
        try:
            conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
            conn.request("GET", "/api/state", headers={"Host": f"127.0.0.1:{port}"})
            r = conn.getresponse()
            r.read()
            conn.close()
            out.append((r.status, time.perf_counter() - t0))
        except (OSError, http.client.HTTPException):
            out.append((None, time.perf_counter() - t0))


def _pct(values: list, q: float) -> float | None:
    if not values:
        return None
    v = sorted(values)
    return round(v[min(len(v) - 1, int(q * len(v)))], 4)


# --------------------------------------------------------------------- runs
def crowd(kind: str, clients: int, requests: int, budget_s: float) -> dict:
    """Start a server of ``kind`` in its own process, put the crowd on it, and measure."""
    folder = tempfile.mkdtemp(prefix="liganimate-load-")
    proc = subprocess.Popen(
        [sys.executable, __file__, "--serve", kind, "--folder", folder],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        port = int(proc.stdout.readline())
        time.sleep(0.5)
        before = _proc(proc.pid)
        results: list = []
        probes: list = []
        peak = dict(before)
        stop = threading.Event()

        def sample():
            while not stop.wait(0.1):
                now = _proc(proc.pid)
                peak["threads"] = max(peak["threads"], now["threads"])
                peak["rss_mb"] = max(peak["rss_mb"], now["rss_mb"])

        deadline = time.monotonic() + budget_s
        workers = [
            threading.Thread(target=_Client(port, 1000 + k, results, deadline).run, args=(requests,))
            for k in range(clients)
        ]
        helpers = [threading.Thread(target=sample), threading.Thread(target=_probe, args=(port, stop, probes))]
        load0, cpu0, wall0 = os.getloadavg()[0], time.process_time(), time.perf_counter()
        for t in helpers + workers:
            t.start()
        for t in workers:
            t.join(budget_s + 60)
        wall = time.perf_counter() - wall0
        client_cpu = time.process_time() - cpu0
        stop.set()
        for t in helpers:
            t.join()
        during = _proc(proc.pid)
        after = _settle(proc.pid, before)
        return _report(kind, results, probes, before, peak, during, after, wall, client_cpu, load0)
    finally:
        proc.stdin.close()
        proc.wait(30)


def _settle(pid: int, idle: dict, within: float = 10.0) -> dict:
    """The server's figures once the crowd has gone: when its threads are back to idle, or after ``within`` s."""
    end = time.monotonic() + within
    now = _proc(pid)
    while now["threads"] > idle["threads"] and time.monotonic() < end:
        time.sleep(0.2)
        now = _proc(pid)
    now["settle_s"] = round(within - max(0.0, end - time.monotonic()), 1)
    return now


def _report(kind, results, probes, before, peak, during, after, wall, client_cpu, load0) -> dict:
    sent = [r for r in results if r[0] != "unsent"]
    state = [t for k, s, t in sent if k == "state" and s == 200]
    every = [t for _, s, t in sent if s is not None]
    errors = sum(1 for _, s, _ in sent if s is None or (s >= 500 and s != 503))
    probe_t = [t for s, t in probes if s == 200]
    return {
        "server": kind,
        "requests": len(sent),
        "unsent_at_deadline": len(results) - len(sent),
        "errors": errors,
        "busy_503": sum(1 for _, s, _ in sent if s == 503),
        "refused_4xx": sum(1 for _, s, _ in sent if s is not None and 400 <= s < 500),
        "statuses": dict(sorted(collections.Counter(f"{k} {s}" for k, s, _ in sent).items())),
        "state_p50_s": _pct(state, 0.5),
        "state_p99_s": _pct(state, 0.99),
        "all_p50_s": _pct(every, 0.5),
        "all_p99_s": _pct(every, 0.99),
        "probe_max_s": round(max(probe_t), 4) if probe_t else None,
        "probe_failed": sum(1 for s, _ in probes if s != 200),
        "wall_s": round(wall, 2),
        "server_cpu_s": round(during["cpu_s"] - before["cpu_s"], 2),
        "clients_cpu_s": round(client_cpu, 2),
        "threads": {"before": before["threads"], "peak": peak["threads"], "after": after["threads"]},
        "rss_mb": {"before": before["rss_mb"], "peak": peak["rss_mb"], "after": after["rss_mb"]},
        "settle_s": after["settle_s"],
        "load_average": {"before": round(load0, 2), "after": round(os.getloadavg()[0], 2)},
    }


def _ratio(a, b):
    return round(a / b, 2) if a is not None and b else None


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="50 clients x 12 requests, under a minute")
    ap.add_argument("--clients", type=int, default=50)
    ap.add_argument("--requests", type=int, default=None, help="per client (default 100, 12 with --quick)")
    ap.add_argument("--serve", choices=("loop", "stock"), help=argparse.SUPPRESS)
    ap.add_argument("--folder", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.serve:
        _serve(args.serve, args.folder)
        return 0
    requests = args.requests or (12 if args.quick else 100)
    budget = 15.0 if args.quick else 240.0
    runs = {kind: crowd(kind, args.clients, requests, budget) for kind in ("loop", "stock")}
    print(f"{args.clients} clients x {requests} requests on loopback, each run stopped at {budget:g} s")
    print(f"{'':22}{'loop':>22}{'stock':>22}")
    for key in ("requests", "errors", "busy_503", "refused_4xx", "state_p50_s", "state_p99_s", "all_p99_s"):
        print(f"{key:22}{runs['loop'][key]!s:>22}{runs['stock'][key]!s:>22}")
    for key in ("probe_max_s", "wall_s", "server_cpu_s", "clients_cpu_s"):
        print(f"{key:22}{runs['loop'][key]!s:>22}{runs['stock'][key]!s:>22}")
    for key in ("threads", "rss_mb", "load_average"):
        cells = ["/".join(str(v) for v in runs[k][key].values()) for k in ("loop", "stock")]
        print(
            f"{key + ' (before/peak/after)' if key != 'load_average' else 'load avg (before/after)':22}{cells[0]:>22}{cells[1]:>22}"
        )
    loop, stock = runs["loop"], runs["stock"]
    result = {
        "clients": args.clients,
        "requests_per_client": requests,
        "goal_state_p99_s": GOAL_P99_S,
        "loop": loop,
        "stock": stock,
        "ratios_stock_over_loop": {
            "state_p99": _ratio(stock["state_p99_s"], loop["state_p99_s"]),
            "probe_max": _ratio(stock["probe_max_s"], loop["probe_max_s"]),
            "server_cpu": _ratio(stock["server_cpu_s"], loop["server_cpu_s"]),
            "wall": _ratio(stock["wall_s"], loop["wall_s"]),
            "peak_threads": _ratio(stock["threads"]["peak"], loop["threads"]["peak"]),
            "peak_rss": _ratio(stock["rss_mb"]["peak"], loop["rss_mb"]["peak"]),
        },
        "goal_met": bool(
            loop["state_p99_s"] is not None
            and loop["state_p99_s"] < GOAL_P99_S
            and loop["errors"] == 0
            and loop["threads"]["after"] == loop["threads"]["before"]
        ),
    }
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
