"""Language-server latency: diagnostics, hover and completion after a change, against ``liganimate check`` on save.

The server is the real ``liganimate lsp``, started as an editor starts it
and driven over stdio by pygls' client. For programs of 100, 1,000 and
5,000 lines (Appendix A's models, motion and scene copied under new names,
as benchmarks/compile.py makes them: comments, blank lines, about five
tokens a line; and, as a stress figure, the dense program where every
line is a statement, about fifteen tokens a line), each round types or
deletes one digit of a number in the middle of the text (so every later
offset moves) and measures, in one run:

* diagnostics: from the change sent to the diagnostics of that version
  received;
* hover and completion at a name in the middle, right after a change,
  while that change's analysis is running;
* the same with ``liganimate lsp --whole-parse``, which parses the whole
  text after every change, as the server did before it parsed only the
  part around the change (lang/incremental.py);
* what a user would otherwise do: save and run ``liganimate check FILE``
  (a new process, which also runs the program).

Wall time is the median round; CPU time is the server process's own
(``/proc/PID/stat``), or the ``check`` process's, for the same rounds: on
a shared machine wall time is mostly waiting for a core (the load average
is printed), so CPU time is the fair figure. The diagnostics' CPU time is
that of every thread of the server but the one that builds the index and
values after the diagnostics are out (``lig-index``); that one's is
printed beside it ("then the index"), measured once the server is idle
again. Hover and completion count the whole process, the change's own
analysis included. Issue 21's target: a 5,000-line program answered
within 200 ms of a change.

Usage: ``python benchmarks/lsp.py [--quick]``. The last line printed is one
JSON object holding the figures.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

from lsprotocol import types as T
from pygls.lsp.client import LanguageClient
from pygls.uris import from_fs_path

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests"))
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))

from bigprograms import mixed_lines  # noqa: E402 - found through the sys.path lines above
from compile import thesis_style_program  # noqa: E402

TICK = os.sysconf("SC_CLK_TCK")


def process_cpu(pid: int) -> float:
    """CPU seconds (user + system) process ``pid`` has used so far."""
    with open(f"/proc/{pid}/stat") as fh:
        fields = fh.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICK


#: The server's thread that builds the index and values after the diagnostics are out (lsp/server.py names it).
INDEX_THREAD = "lig-index"


def server_cpu(pid: int) -> tuple:
    """``(CPU seconds of the server but its index thread, CPU seconds of its index thread)`` so far.

    The index of a text is built after its diagnostics are published, in a
    thread of its own, while the client reads the CPU clock: counted apart,
    the first figure is the work from a change to its diagnostics.
    """
    index = 0.0
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/comm") as fh:
                name = fh.read().strip()
            if name != INDEX_THREAD:
                continue
            with open(f"/proc/{pid}/task/{tid}/stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
            index += (int(fields[11]) + int(fields[12])) / TICK
        except FileNotFoundError:
            continue  # a thread that ended meanwhile
    return process_cpu(pid) - index, index


_DECIMAL = re.compile(r"(?<![A-Za-z0-9_])\d+\.(\d)")


def edit(text: str, round_no: int) -> tuple:
    """A keystroke near the middle of ``text``: ``(new text, the change)``.

    Even rounds type a digit after the decimal point of a number (0.25 ->
    0.725), odd rounds delete it again, so every offset after it moves by
    one character and the program stays valid. The server asks for whole
    texts (see src/liganimate/lsp/server.py), so an editor sends the whole
    new text for a keystroke.
    """
    m = _DECIMAL.search(text, len(text) // 2) or _DECIMAL.search(text)
    assert m is not None
    at = m.start(1)
    if round_no % 2 == 0:
        new = text[:at] + str(round_no % 10) + text[at:]
    else:
        new = text[:at] + text[at + 1 :]
    return new, T.TextDocumentContentChangeWholeDocument(text=new)


def name_position(text: str) -> T.Position:
    """A name near the middle of ``text`` (the target of an assignment; the first one after the middle)."""
    lines = text.split("\n")
    for i in list(range(len(lines) // 2, len(lines))) + list(range(len(lines) // 2)):
        stripped = lines[i].lstrip()
        if stripped[:1].isalpha() and re.match(r"[A-Za-z]\w*\s*(:-|:=|=)", stripped) and lines[i][:1] not in "Cc":
            return T.Position(line=i, character=len(lines[i]) - len(stripped) + 1)
    raise ValueError("no assignment after the middle")


class Session:
    """One server, one open document, and the diagnostics of each version it publishes."""

    def __init__(self, whole_parse: bool) -> None:
        self.whole_parse = whole_parse
        self.client = LanguageClient("liganimate-benchmark", "1")
        self.published: dict = {}

        @self.client.feature(T.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
        def _diagnostics(params: T.PublishDiagnosticsParams) -> None:
            self.published[params.version] = time.perf_counter()

    async def start(self) -> None:
        flags = ["--whole-parse"] if self.whole_parse else []
        await self.client.start_io(sys.executable, "-m", "liganimate", "lsp", *flags)
        await self.client.initialize_async(T.InitializeParams(capabilities=T.ClientCapabilities()))
        self.client.initialized(T.InitializedParams())

    @property
    def pid(self) -> int:
        server = self.client._server
        assert server is not None
        return server.pid

    async def wait_for(self, version: int, timeout: float = 60.0) -> float:
        deadline = time.perf_counter() + timeout
        while version not in self.published:
            if time.perf_counter() > deadline:
                raise TimeoutError(f"no diagnostics for version {version}")
            await asyncio.sleep(0.001)
        return self.published[version]

    async def idle(self, quiet: float = 0.05, timeout: float = 30.0) -> None:
        """Wait until the server has used no CPU for ``quiet`` seconds (the index of the last text is built)."""
        deadline = time.perf_counter() + timeout
        before = process_cpu(self.pid)
        while time.perf_counter() < deadline:
            await asyncio.sleep(quiet)
            now = process_cpu(self.pid)
            if now == before:
                return
            before = now

    async def stop(self) -> None:
        await self.client.shutdown_async(None)
        self.client.exit(None)
        await self.client.stop()


async def measure_server(text: str, path: str, rounds: int, whole_parse: bool = False) -> dict:
    """Median wall and mean CPU seconds of diagnostics, hover and completion after a change."""
    session = Session(whole_parse)
    await session.start()
    uri = from_fs_path(path)
    doc = T.TextDocumentIdentifier(uri=uri)
    session.client.text_document_did_open(
        T.DidOpenTextDocumentParams(text_document=T.TextDocumentItem(uri=uri, language_id="lig", version=1, text=text))
    )
    await session.wait_for(1)
    where = name_position(text)
    kinds = ("diagnostics",) if whole_parse else ("diagnostics", "hover", "completion")
    walls: dict = {kind: [] for kind in kinds}
    cpus: dict = {kind: [] for kind in kinds}
    index_cpus: list = []
    version = 1
    for _ in range(rounds):
        for kind in kinds:
            version += 1
            text, change = edit(text, version)
            await session.idle()
            cpu0, index0 = server_cpu(session.pid)
            sent = time.perf_counter()
            session.client.text_document_did_change(
                T.DidChangeTextDocumentParams(
                    text_document=T.VersionedTextDocumentIdentifier(uri=uri, version=version),
                    content_changes=[change],
                )
            )
            if kind == "diagnostics":
                got = await session.wait_for(version)
                walls[kind].append(got - sent)
                cpu1, _ = server_cpu(session.pid)
                cpus[kind].append(cpu1 - cpu0)
                await session.idle()
                index_cpus.append(server_cpu(session.pid)[1] - index0)
                continue
            await asyncio.sleep(0.01)  # the change's analysis is running now
            cpu0 = process_cpu(session.pid)
            asked = time.perf_counter()
            if kind == "hover":
                answer = await session.client.text_document_hover_async(
                    T.HoverParams(text_document=doc, position=where)
                )
            else:
                answer = await session.client.text_document_completion_async(
                    T.CompletionParams(text_document=doc, position=where)
                )
            walls[kind].append(time.perf_counter() - asked)
            cpus[kind].append(process_cpu(session.pid) - cpu0)
            assert answer is not None, kind
            await session.wait_for(version)
    await session.stop()
    out = {kind: {"wall_s": statistics.median(walls[kind]), "cpu_s": statistics.mean(cpus[kind])} for kind in walls}
    out["diagnostics"]["index_cpu_s"] = statistics.mean(index_cpus)
    return out


def measure_check(path: str, rounds: int) -> dict:
    """Median wall and mean CPU seconds of ``liganimate check FILE`` in a new process (what saving costs without the server)."""
    walls, cpus = [], []
    for _ in range(rounds):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-m", "liganimate", "check", path], capture_output=True, text=True, timeout=600
        )
        walls.append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
        assert done.returncode == 0, done.stderr[-2000:]
    return {"wall_s": statistics.median(walls), "cpu_s": statistics.mean(cpus)}


def _row(server: dict) -> str:
    row = "  ".join(
        f"{kind} {v['wall_s'] * 1000:7.1f} ms wall {v['cpu_s'] * 1000:6.1f} ms CPU" for kind, v in server.items()
    )
    return row + f"  (then the index: {server['diagnostics']['index_cpu_s'] * 1000:.1f} ms CPU)"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer rounds (under a minute)")
    args = parser.parse_args()
    rounds = 3 if args.quick else 9
    check_rounds = 1 if args.quick else 3
    results: dict = {"load_average": os.getloadavg()[0]}
    print(f"load average {results['load_average']:.1f} (2 cores here: wall time waits for a core; judge by CPU time)")
    with tempfile.TemporaryDirectory() as tmp:
        programs = [(f"thesis_{n}", thesis_style_program(n)) for n in (100, 1000, 5000)]
        programs.append(("dense_5000", mixed_lines(5000)))
        for name, text in programs:
            path = os.path.join(tmp, f"{name}.lig")
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(text)
            server = asyncio.run(measure_server(text, path, rounds))
            whole = asyncio.run(measure_server(text, path, rounds, whole_parse=True))
            check = measure_check(path, check_rounds) if not name.startswith("dense") else None
            lines = text.count("\n")
            diagnostics, before = server["diagnostics"], whole["diagnostics"]
            results[name] = {
                "lines": lines,
                "server": server,
                "server_whole_parse": whole,
                "whole_parse_over_incremental": {
                    "wall": before["wall_s"] / max(diagnostics["wall_s"], 1e-9),
                    "cpu": before["cpu_s"] / max(diagnostics["cpu_s"], 1e-9),
                },
                "check_on_save": check,
            }
            print(f"{name:12s} {lines:5d} lines  {_row(server)}")
            print(f"{'':12s} --whole-parse {_row(whole)}")
            print(
                f"{'':12s} diagnostics with --whole-parse cost "
                f"{results[name]['whole_parse_over_incremental']['cpu']:.1f}x the CPU"
            )
            if check is not None:
                ratio = check["wall_s"] / diagnostics["wall_s"]
                cpu_ratio = check["cpu_s"] / max(diagnostics["cpu_s"], 1e-9)
                results[name]["check_over_diagnostics"] = {"wall": ratio, "cpu": cpu_ratio}
                print(
                    f"{'':12s} liganimate check on save {check['wall_s'] * 1000:7.1f} ms wall "
                    f"{check['cpu_s'] * 1000:7.1f} ms CPU: {ratio:.1f}x the server's diagnostics (wall), "
                    f"{cpu_ratio:.1f}x (CPU)"
                )
    big = results["thesis_5000"]["server"]
    results["target_5000_lines_200ms"] = {
        kind: {"wall": big[kind]["wall_s"] <= 0.2, "cpu": big[kind]["cpu_s"] <= 0.2}
        for kind in ("diagnostics", "hover", "completion")
    }
    results["load_average_after"] = os.getloadavg()[0]
    print(json.dumps(results))


if __name__ == "__main__":
    main()
