"""Look benchmark: what the modern look costs a frame beside the thesis look.

The scene is the film scene, ``benchmarks/five_humans.lig`` (five Appendix A
humans, three squatting and two walking on the spot), made N ticks long,
one 640x480 image a tick.  Both looks render the same ticks side by side in
one run, in interleaved rounds (best round kept), in this process
(``workers=1``), so that CPU time is all counted:

* to MP4 alone (``--mp4``): this process's CPU time plus ffmpeg's (a child
  process), a frame, beside the wall time;
* to PNG files alone (``-o``): CPU and wall time a frame;
* drawing alone (``frames.draw`` on the same draws, no file): CPU a frame.

The goal (issue 25) is a modern look costing at most 2.5 times the thesis
look's CPU a frame on this scene.  The last line printed is one JSON object
with the figures.

Usage: ``python benchmarks/look.py [--quick] [--ticks N] [--rounds R]``
(``--quick``: 160 ticks, 2 rounds, under a minute).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

from film import SIZE, scene_program  # noqa: E402

from liganimate.runtime.render import frames as R  # noqa: E402

LOOKS = ("thesis", "modern")
BUDGET = 2.5


def _cpu() -> float:
    """CPU seconds of this process and its finished children (ffmpeg)."""
    me = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def measure(fn) -> tuple:
    """(CPU seconds, wall seconds) of ``fn()``."""
    c0, w0 = _cpu(), time.perf_counter()
    fn()
    return _cpu() - c0, time.perf_counter() - w0


def collect_draws(program, ticks: int) -> list:
    """The draws of every image of the scene, as the renderer hands them to ``draw``."""
    captured: list = []
    original = R.draw_images

    def keep(size, draws_list, *args, **kwargs):
        captured.extend(draws_list)
        return [(None, None) for _ in draws_list]

    R.draw_images = keep
    try:
        folder = tempfile.mkdtemp()
        try:
            program.render(folder, checked=True, size=SIZE, quiet=True, workers=1)
        finally:
            shutil.rmtree(folder, ignore_errors=True)
    finally:
        R.draw_images = original
    assert len(captured) == ticks, (len(captured), ticks)
    return captured


def _renders(program, draws, folder: str, look: str) -> list:
    """(what, function) for each thing timed in ``look``."""
    mp4 = os.path.join(folder, f"{look}.mp4")

    def to_mp4():
        program.render(None, checked=True, mp4=mp4, size=SIZE, quiet=True, workers=1, look=look)

    def to_png():
        out = tempfile.mkdtemp(dir=folder)
        try:
            program.render(out, checked=True, size=SIZE, quiet=True, workers=1, look=look)
        finally:
            shutil.rmtree(out)

    def draw_only():
        for d in draws:
            R.draw(SIZE, d, 1, look)

    return [("mp4", to_mp4), ("png", to_png), ("draw", draw_only)]


def run(ticks: int, rounds: int) -> dict:
    folder = tempfile.mkdtemp(prefix="liganimate-look-")
    try:
        program = scene_program(folder, ticks)
        draws = collect_draws(program, ticks)
        best: dict = {look: {} for look in LOOKS}

        def keep_best(look, what, cpu, wall):
            old = best[look].get(what)
            if old is None or cpu < old[0]:
                best[look][what] = (cpu, wall)

        for _ in range(rounds):
            for look in LOOKS:
                for what, fn in _renders(program, draws, folder, look):
                    keep_best(look, what, *measure(fn))
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    result: dict = {"ticks": ticks, "rounds": rounds, "size": list(SIZE), "budget": BUDGET}
    for what in ("mp4", "png", "draw"):
        for look in LOOKS:
            cpu, wall = best[look][what]
            result[f"{what}_{look}_cpu_ms"] = round(1000 * cpu / ticks, 3)
            result[f"{what}_{look}_wall_ms"] = round(1000 * wall / ticks, 3)
        result[f"{what}_ratio_cpu"] = round(best["modern"][what][0] / best["thesis"][what][0], 3)
        result[f"{what}_ratio_wall"] = round(best["modern"][what][1] / best["thesis"][what][1], 3)
    result["within_budget"] = result["mp4_ratio_cpu"] <= BUDGET
    return result


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="160 ticks, 2 rounds")
    ap.add_argument("--ticks", type=int, default=None)
    ap.add_argument("--rounds", type=int, default=None)
    args = ap.parse_args(argv)
    ticks = args.ticks or (160 if args.quick else 1000)
    rounds = args.rounds or (2 if args.quick else 3)
    r = run(ticks, rounds)
    print(f"five humans, {ticks} ticks at {SIZE[0]}x{SIZE[1]}, one process, best of {rounds} rounds")
    print(f"{'':22}{'thesis':>18}{'modern':>18}{'ratio':>14}")
    for what, label in (("mp4", "MP4 (with ffmpeg)"), ("png", "PNG files"), ("draw", "drawing alone")):
        cells = [f"{r[f'{what}_{look}_cpu_ms']:7.2f} ({r[f'{what}_{look}_wall_ms']:6.2f})" for look in LOOKS]
        ratio = f"{r[f'{what}_ratio_cpu']:.2f}x ({r[f'{what}_ratio_wall']:.2f}x)"
        print(f"{label:22}{cells[0]:>18}{cells[1]:>18}{ratio:>14}")
    print("CPU ms a frame (wall ms a frame); ratio modern/thesis, CPU (wall)")
    print(f"budget {BUDGET}x thesis CPU a frame (MP4): {'met' if r['within_budget'] else 'NOT met'}")
    print(json.dumps(r))
    return 0


if __name__ == "__main__":
    sys.exit(main())
