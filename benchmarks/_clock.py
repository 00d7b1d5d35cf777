"""How the benchmarks measure: CPU time (this process and its children) beside wall time, and the load.

The machine the benchmarks run on is shared, so wall time swings three- to
eightfold with other load while CPU time barely moves: every benchmark
judges its goals on CPU time (``user + system`` of this process plus that of
the child processes it has waited for, e.g. ffmpeg or a ``liganimate``
subprocess) and prints wall time and the load average beside it, so that a
reader can tell a busy machine from a slow program.

``python benchmarks/<name>.py`` puts this folder on ``sys.path``, which is
how the benchmarks import this module.
"""

from __future__ import annotations

import os
import resource
import time
from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["Cost", "cpu_seconds", "load", "load_text", "measure", "best_of"]


def cpu_seconds() -> float:
    """CPU seconds used so far by this process and its waited-for children (user + system)."""
    # process_time has nanosecond resolution (os.times counts 10 ms ticks);
    # children's time comes from getrusage, in microseconds.
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + kids.ru_utime + kids.ru_stime


def load() -> tuple[float, float, float]:
    """The 1-, 5- and 15-minute load averages (zeros where the system has none)."""
    try:
        return os.getloadavg()
    except OSError:
        return (0.0, 0.0, 0.0)


def load_text() -> str:
    """The load average and core count, as a benchmark's header line states them."""
    one, five, fifteen = load()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} on {os.cpu_count()} cores"


@dataclass(frozen=True)
class Cost:
    """What one timed piece of work cost: CPU and wall seconds, and the 1-minute load when it ended."""

    cpu: float
    wall: float
    load: float

    def per(self, n: float) -> Cost:
        """The cost of one of ``n`` units (frames, solves, calls)."""
        return Cost(self.cpu / n, self.wall / n, self.load)

    def json(self, scale: float = 1.0, digits: int = 4) -> dict:
        """``{"cpu": ..., "wall": ..., "load": ...}``, times multiplied by ``scale`` (1e3 for ms, 1e6 for µs)."""
        return {
            "cpu": round(self.cpu * scale, digits),
            "wall": round(self.wall * scale, digits),
            "load": round(self.load, 2),
        }


def measure(fn: Callable[[], object]) -> Cost:
    """Run ``fn`` once and return its cost."""
    c0, w0 = cpu_seconds(), time.perf_counter()
    fn()
    return Cost(cpu_seconds() - c0, time.perf_counter() - w0, load()[0])


def best_of(costs: list[Cost]) -> Cost:
    """The round with the least CPU time (other load only ever adds to a round; wall time is its own)."""
    return min(costs, key=lambda c: c.cpu)
