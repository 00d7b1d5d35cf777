"""Film benchmark: what does a two-hour film (170,000 frames) cost to render to MP4, in CPU time?

The scene is ``benchmarks/five_humans.lig`` (five Appendix A humans, three
squatting and two walking on the spot) made N ticks long, one 640x480
image a tick, in the thesis' flat look (``--look thesis``, the look issue
22's goal is set for; the modern look is one more row).  Cachola's LIG
ANIMATE thesis counts a two-hour film as about 170,000 frames.  Every
figure is CPU time (this process and its children: the render workers and
ffmpeg, ``_clock.py``), with wall time and the load average beside it; the
goal (issue 22) is at most 4.5 ms of CPU a frame to MP4, all included.
Reported, the program compiled once outside the timing:

* CPU a frame to MP4 alone (``--mp4 film.mp4``: no PNG written) with the
  default workers; the CPU of one more frame (from runs of N/2 and N
  frames: the run's fixed costs, starting the workers and ffmpeg, left
  out), and from it the time 170,000 frames take on two idle cores (CPU
  time / 2) and on one;
* the CPU split of one frame, measured in a one-process run of the same
  ticks (``workers=1``): **posing** (joint angles, link transforms, world
  triangles: ``Renderer.flush`` less the drawing it calls), **drawing**
  (``frames.draw``), **encoding** (the ffmpeg child: x264 alone on the same
  frames), the **rest** of this process (running the program's ticks,
  feeding the stream); and **transport**: what the worker processes cost
  beyond the one-process run (handing tasks to them and images back);
* the worker message: bytes an image and CPU to pickle and unpickle it,
  as sent (link matrices) and as world triangles (what it was before);
* CPU a frame to PNG files alone (``-o DIR``), the same ticks (at most
  10,000);
* the cost of drawing one image (the ``draw`` step alone, one process) at
  1920x1080 over 640x480, for 6.75 times the pixels;
* if Dask and ``runtime/render/distributed.py`` are installed: frames a
  second (wall) to MP4 on a ``LocalCluster`` of two worker processes,
  beside the plain local run of the same ticks (Dask's workers are not
  this process's children, so only wall time compares).

The last line printed is one JSON object with the figures.

Usage: ``python benchmarks/film.py [--quick | --full-film] [--ticks N]``
(``--quick``: 800 ticks and 400 on Dask, under a minute on a loaded two-core
machine; default 10,000; ``--full-film``: 170,000, the whole film).
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import sys
import tempfile
import time

from _clock import Cost, cpu_seconds, load_text, measure

from liganimate.compiler import load_program
from liganimate.runtime.render import frames as R
from liganimate.runtime.render import message as M

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "five_humans.lig")
FILM = 170_000
QUICK_TICKS = 800
"""Ticks of ``--quick``: they measure the rates 2,000 did, within the shared machine's noise, in a third of the time."""
GOAL_MS = 4.5  # CPU a frame, MP4, everything included (issue 22)
SIZE = (640, 480)
LOOK = "thesis"


def scene_program(folder: str, ticks: int):
    """The benchmark scene, ``ticks`` long, compiled."""
    with open(SCENE, encoding="utf-8") as f:
        text = f.read()
    assert "LENGTH 1000" in text and text.count("TO 999") == 5
    text = text.replace("LENGTH 1000", f"LENGTH {ticks}").replace("TO 999", f"TO {ticks - 1}")
    path = os.path.join(folder, f"film{ticks}.lig")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    program, _ = load_program(path)
    program.check()
    return program


def mp4_cost(program, ticks: int, folder: str, **options) -> tuple[Cost, int]:
    """(cost a frame, bytes) of rendering to an MP4 alone."""
    path = os.path.join(folder, "film.mp4")
    options.setdefault("look", LOOK)
    cost = measure(lambda: program.render(None, checked=True, mp4=path, size=SIZE, quiet=True, **options))
    size = os.path.getsize(path)
    os.remove(path)
    return cost.per(ticks), size


def png_cost(program, ticks: int, folder: str) -> Cost:
    """Cost a frame of rendering to PNG files alone."""
    out = tempfile.mkdtemp(dir=folder)
    cost = measure(lambda: program.render(out, checked=True, size=SIZE, quiet=True, look=LOOK))
    n = len(os.listdir(os.path.join(out, "scene1")))
    assert n == ticks, n
    return cost.per(ticks)


def split(program, ticks: int, folder: str) -> dict:
    """CPU seconds a frame of posing, drawing, encoding and the rest, in a one-process MP4 render.

    ``Renderer.flush`` (posing, and the drawing it hands on) and
    ``frames.draw`` are wrapped to add up this process's CPU time in them;
    the ffmpeg child's CPU is read from ``getrusage`` when it has been
    waited for.
    """
    spent = {"flush": 0.0, "draw": 0.0}
    flush, draw = R.Renderer.flush, R.draw

    def timed_flush(self):
        t0 = time.process_time()
        try:
            return flush(self)
        finally:
            spent["flush"] += time.process_time() - t0

    def timed_draw(*args, **kw):
        t0 = time.process_time()
        try:
            return draw(*args, **kw)
        finally:
            spent["draw"] += time.process_time() - t0

    R.Renderer.flush, R.draw = timed_flush, timed_draw
    kids0 = cpu_seconds() - time.process_time()
    try:
        total, _ = mp4_cost(program, ticks, folder, workers=1)
    finally:
        R.Renderer.flush, R.draw = flush, draw
    encoding = (cpu_seconds() - time.process_time() - kids0) / ticks
    # Images are drawn inside flush (workers=1), and at the end by finish().
    drawing = spent["draw"] / ticks
    posing = max(0.0, spent["flush"] / ticks - drawing)
    return {
        "total": total.cpu,
        "posing": posing,
        "drawing": drawing,
        "encoding": encoding,
        "rest": total.cpu - posing - drawing - encoding,
    }


def captured_draws(program, count: int, look: str = LOOK) -> list:
    """The draw lists of the first ``count`` images in ``look`` (drawn here, one process, nothing written).

    benchmarks/background.py and raster.py take the scene's draws from here too.
    """
    got: list = []
    original = R.draw_images

    def grab(size, draws_list, *options):  # aa, png, raw, look: whatever draw_images takes
        got.extend(draws_list[: max(0, count - len(got))])
        return [(None, None)] * len(draws_list)

    R.draw_images = grab
    try:
        with tempfile.TemporaryDirectory() as out:
            program.render(out, checked=True, size=SIZE, quiet=True, workers=1, look=look)
    finally:
        R.draw_images = original
    return got


def message_sizes(program, count: int) -> dict:
    """What the first ``count`` images cost to send to a worker: the message as sent, and as world triangles.

    The tasks are taken as ``Renderer`` packs them (link matrices;
    :mod:`liganimate.runtime.render.message`), shapes not counted (they go
    once a render); beside them, the same images' draws with every figure's
    triangles in world coordinates, what a task carried before.  Bytes are
    pickled sizes, CPU the best of 5 rounds of pickling and unpickling.
    """
    tasks: list = []
    pack, original = R.pack, R.draw_images

    def keep(*args):
        got = pack(*args)
        if len(tasks) * R.CHUNK < count:
            tasks.append(got)
        return got

    R.pack = keep
    R.draw_images = lambda size, draws_list, *options: [(None, None)] * len(draws_list)
    try:
        with tempfile.TemporaryDirectory() as out:
            program.render(out, checked=True, size=SIZE, quiet=True, workers=1, look=LOOK)
    finally:
        R.pack, R.draw_images = pack, original
    sent = [task for task, _shapes in tasks[: max(1, count // R.CHUNK)]]
    triangles = [M.resolve(task.shipping(shapes)) for task, shapes in tasks[: len(sent)]]
    images = sum(len(task.images) for task in sent)
    out = {}
    for name, objs in (("link_matrices", sent), ("world_triangles", triangles)):
        size = sum(len(pickle.dumps(o, protocol=pickle.HIGHEST_PROTOCOL)) for o in objs)
        cpu = min(measure(lambda o=objs: [pickle.loads(pickle.dumps(x, protocol=5)) for x in o]).cpu for _ in range(5))
        out[name] = {
            "kb_per_image": round(size / images / 1024, 2),
            "pickling_us_per_image": round(cpu / images * 1e6, 1),
        }
    return out


def draw_ratio(draws: list, rounds: int) -> tuple:
    """(CPU ms an image at 640x480, at 1920x1080): the draw step alone, best of ``rounds``."""
    best = {}
    for size in (SIZE, (1920, 1080)):
        R.draw(size, draws[0], 1, LOOK)  # warm the camera memo
        best[size] = min(
            measure(lambda s=size: [R.draw(s, d, 1, LOOK) for d in draws]).cpu for _ in range(rounds)
        ) / len(draws)
    return 1000 * best[SIZE], 1000 * best[(1920, 1080)]


def dask_rates(program, ticks: int, folder: str) -> dict | None:
    """Frames/s (wall) to MP4 on a 2-worker LocalCluster, and locally, same ticks; None without Dask."""
    try:
        import distributed

        from liganimate.runtime.render.distributed import DaskExecutor
    except ImportError as exc:
        print(f"dask: not measured ({exc})")
        return None
    with distributed.LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=":0", silence_logs=40
    ) as cluster:
        dask_cost, _ = mp4_cost(program, ticks, folder, executor=DaskExecutor(cluster))
    local_cost, _ = mp4_cost(program, ticks, folder)
    return {"ticks": ticks, "dask_fps": round(1 / dask_cost.wall, 1), "local_fps": round(1 / local_cost.wall, 1)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--quick", action="store_true", help=f"{QUICK_TICKS:,} ticks (about 20 s)")
    mode.add_argument("--full-film", action="store_true", help="170,000 ticks: the whole film")
    ap.add_argument("--ticks", type=int, help="another number of ticks")
    ap.add_argument("--no-dask", action="store_true", help="skip the Dask LocalCluster run")
    args = ap.parse_args(argv)
    ticks = args.ticks or (QUICK_TICKS if args.quick else FILM if args.full_film else 10_000)
    dask_ticks = min(ticks, QUICK_TICKS // 2 if args.quick else 2_000)

    print(load_text(), flush=True)
    with tempfile.TemporaryDirectory() as folder:
        program = scene_program(folder, ticks)
        print(f"scene: five humans, {ticks:,} ticks, {SIZE[0]}x{SIZE[1]}, look {LOOK}", flush=True)
        mp4, mp4_bytes = mp4_cost(program, ticks, folder)
        half = ticks // 2
        mp4_half, _ = mp4_cost(scene_program(folder, half), half, folder)
        # What one more frame costs, without the run's fixed costs (workers, ffmpeg starting):
        # the basis for a film of 170,000 frames.
        marginal = (mp4.cpu * ticks - mp4_half.cpu * half) / (ticks - half)
        fixed = max(0.0, mp4.cpu * ticks - marginal * ticks)
        film_min = (fixed + FILM * marginal) / 60
        print(
            f"MP4 alone:  {mp4.cpu * 1e3:6.2f} ms CPU a frame over {ticks:,} frames (wall {mp4.wall * 1e3:.2f} ms, "
            f"load {mp4.load:.1f}; {mp4_bytes / ticks / 1024:.2f} kB a frame); goal {GOAL_MS} ms: "
            f"{'met' if mp4.cpu * 1e3 <= GOAL_MS else 'NOT met'}",
            flush=True,
        )
        print(
            f"one more frame: {marginal * 1e3:.2f} ms CPU (from {half:,} and {ticks:,} frames; fixed {fixed:.2f} s); "
            f"170,000 frames: {film_min / 2:.1f} min on two idle cores, {film_min:.1f} min on one",
            flush=True,
        )
        parts = split(program, ticks, folder)
        print(
            "CPU a frame, one process: "
            + ", ".join(f"{k} {v * 1e3:.2f} ms" for k, v in parts.items())
            + f"; transport (workers beyond one process) {(mp4.cpu - parts['total']) * 1e3:+.2f} ms",
            flush=True,
        )
        modern, _ = mp4_cost(program, ticks, folder, look="modern")
        print(f"MP4, modern look: {modern.cpu * 1e3:6.2f} ms CPU a frame (wall {modern.wall * 1e3:.2f} ms)", flush=True)
        png_ticks = min(ticks, 10_000)
        png = png_cost(program if png_ticks == ticks else scene_program(folder, png_ticks), png_ticks, folder)
        print(
            f"PNG alone:  {png.cpu * 1e3:6.2f} ms CPU a frame (wall {png.wall * 1e3:.2f} ms, {png_ticks:,} ticks)",
            flush=True,
        )
        small = program if ticks <= 2_000 else scene_program(folder, 2_000)
        message = message_sizes(small, 160)
        lm, wt = message["link_matrices"], message["world_triangles"]
        print(
            f"worker message: {lm['kb_per_image']:.1f} kB an image, {lm['pickling_us_per_image']:.1f} us to pickle "
            f"and unpickle (as world triangles: {wt['kb_per_image']:.1f} kB, {wt['pickling_us_per_image']:.1f} us)",
            flush=True,
        )
        draws = captured_draws(small, 40 if args.quick else 120)
        ms480, ms1080 = draw_ratio(draws, 5)
        print(
            f"draw step: {ms480:.2f} ms at 640x480, {ms1080:.2f} ms at 1920x1080: {ms1080 / ms480:.2f}x "
            f"for 6.75x the pixels",
            flush=True,
        )
        dask = None if args.no_dask else dask_rates(small, dask_ticks, folder)
        if dask:
            print(
                f"Dask LocalCluster (2 workers): {dask['dask_fps']:.1f} frames/s wall; local: {dask['local_fps']:.1f} "
                f"({dask['ticks']:,} ticks): {dask['dask_fps'] / dask['local_fps']:.2f}x",
                flush=True,
            )
    print(load_text())
    print(f"ratios (CPU): MP4/PNG {mp4.cpu / png.cpu:.2f}x, 1080p/480p draw {ms1080 / ms480:.2f}x")
    print(
        json.dumps(
            {
                "ticks": ticks,
                "size": f"{SIZE[0]}x{SIZE[1]}",
                "look": LOOK,
                "cores": os.cpu_count(),
                "mp4_ms_per_frame": mp4.json(1e3, 3),
                "mp4_kb_per_frame": round(mp4_bytes / ticks / 1024, 2),
                "mp4_marginal_ms_per_frame": round(marginal * 1e3, 3),
                "mp4_fixed_s": round(fixed, 3),
                "film_170k_min_two_cores": round(film_min / 2, 2),
                "goal_met": mp4.cpu * 1e3 <= GOAL_MS,
                "split_ms_per_frame": {k: round(v * 1e3, 3) for k, v in parts.items()}
                | {"transport": round((mp4.cpu - parts["total"]) * 1e3, 3)},
                "mp4_modern_ms_per_frame": modern.json(1e3, 3),
                "png_ms_per_frame": png.json(1e3, 3),
                "png_ticks": png_ticks,
                "ratio_mp4_png_cpu": round(mp4.cpu / png.cpu, 2),
                "draw_ms_480p": round(ms480, 3),
                "draw_ms_1080p": round(ms1080, 3),
                "ratio_1080p_480p": round(ms1080 / ms480, 2),
                "message": message,
                "dask": dask,
            }
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
