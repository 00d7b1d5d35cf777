"""Film benchmark: can a two-hour film (170,000 frames) be rendered to MP4 on a laptop?

The scene is ``benchmarks/five_humans.lig`` (five Appendix A humans, three
squatting and two walking on the spot) made N ticks long, one 640x480
image a tick.  Cachola's LIG ANIMATE thesis counts a two-hour film as about
170,000 frames; the goal is to render them to MP4 in under 15 minutes.
Reported, side by side, the program compiled once outside the timing:

* frames a second to MP4 alone (``--mp4 film.mp4``: no PNG written), and
  the time 170,000 frames would take at that rate;
* frames a second to PNG files alone (``-o DIR``), the same ticks (at
  most 10,000: the rate is steady by then, and 170,000 files are 0.5 GB);
* the cost of drawing one image (the ``draw`` step alone, one process) at
  1920x1080 over 640x480, for 6.75 times the pixels;
* if Dask and ``runtime/render/distributed.py`` are installed: frames a
  second to MP4 on a ``LocalCluster`` of two worker processes, beside the
  plain local run of the same ticks.

The last line printed is one JSON object with the figures.

Usage: ``python benchmarks/film.py [--quick | --full-film] [--ticks N]``
(``--quick``: 800 ticks and 400 on Dask, about 20 s on a loaded two-core
machine; default 10,000; ``--full-film``: 170,000, the whole film, about a
quarter of an hour).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time

from liganimate.compiler import load_program
from liganimate.runtime.render import frames as R

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "five_humans.lig")
FILM = 170_000
QUICK_TICKS = 800
"""Ticks of ``--quick``: they measure the rates 2,000 did, within the shared machine's noise, in a third of the time."""
GOAL_S = 15 * 60
SIZE = (640, 480)


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


def timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def mp4_rate(program, ticks: int, folder: str, **options) -> tuple:
    """(frames/s, bytes) of rendering to an MP4 alone."""
    path = os.path.join(folder, "film.mp4")
    dt = timed(lambda: program.render(None, checked=True, mp4=path, size=SIZE, quiet=True, **options))
    size = os.path.getsize(path)
    os.remove(path)
    return ticks / dt, size


def png_rate(program, ticks: int, folder: str) -> float:
    """Frames/s of rendering to PNG files alone."""
    out = tempfile.mkdtemp(dir=folder)
    dt = timed(lambda: program.render(out, checked=True, size=SIZE, quiet=True))
    n = len(os.listdir(os.path.join(out, "scene1")))
    assert n == ticks, n
    return ticks / dt


def captured_draws(program, count: int) -> list:
    """The draw lists of the first ``count`` images (drawn here, one process, nothing written)."""
    got: list = []
    original = R.draw_images

    def grab(size, draws_list, *options):  # aa, png, raw, look: whatever draw_images takes
        got.extend(draws_list[: max(0, count - len(got))])
        return [(None, None)] * len(draws_list)

    R.draw_images = grab
    try:
        with tempfile.TemporaryDirectory() as out:
            program.render(out, checked=True, size=SIZE, quiet=True, workers=1)
    finally:
        R.draw_images = original
    return got


def draw_ratio(draws: list, rounds: int) -> tuple:
    """(ms an image at 640x480, ms at 1920x1080): the draw step alone, best of ``rounds``."""
    best = {}
    for size in (SIZE, (1920, 1080)):
        R.draw(size, draws[0])  # warm the camera memo
        best[size] = min(timed(lambda s=size: [R.draw(s, d) for d in draws]) for _ in range(rounds)) / len(draws)
    return 1000 * best[SIZE], 1000 * best[(1920, 1080)]


def dask_rates(program, ticks: int, folder: str) -> dict | None:
    """Frames/s to MP4 on a 2-worker LocalCluster, and locally, same ticks; None without Dask."""
    try:
        import distributed

        from liganimate.runtime.render.distributed import DaskExecutor
    except ImportError as exc:
        print(f"dask: not measured ({exc})")
        return None
    with distributed.LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=":0", silence_logs=40
    ) as cluster:
        dask_fps, _ = mp4_rate(program, ticks, folder, executor=DaskExecutor(cluster))
    local_fps, _ = mp4_rate(program, ticks, folder)
    return {"ticks": ticks, "dask_fps": round(dask_fps, 1), "local_fps": round(local_fps, 1)}


def minutes(seconds: float) -> str:
    return f"{seconds / 60:.1f} min"


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

    with tempfile.TemporaryDirectory() as folder:
        program = scene_program(folder, ticks)
        print(f"scene: five humans, {ticks:,} ticks, {SIZE[0]}x{SIZE[1]}, {os.cpu_count()} cores", flush=True)
        mp4_fps, mp4_bytes = mp4_rate(program, ticks, folder)
        film_s = FILM / mp4_fps
        print(
            f"MP4 alone:  {mp4_fps:7.1f} frames/s  ({mp4_bytes / ticks / 1024:.2f} kB a frame); "
            f"170,000 frames: {minutes(film_s)} (goal {minutes(GOAL_S)}: {'met' if film_s < GOAL_S else 'NOT met'})",
            flush=True,
        )
        png_ticks = min(ticks, 10_000)
        png_fps = png_rate(program if png_ticks == ticks else scene_program(folder, png_ticks), png_ticks, folder)
        print(
            f"PNG alone:  {png_fps:7.1f} frames/s ({png_ticks:,} ticks);  170,000 frames: {minutes(FILM / png_fps)}",
            flush=True,
        )
        small = program if ticks <= 2_000 else scene_program(folder, 2_000)
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
                f"Dask LocalCluster (2 workers): {dask['dask_fps']:.1f} frames/s; local: {dask['local_fps']:.1f} "
                f"({dask['ticks']:,} ticks): {dask['dask_fps'] / dask['local_fps']:.2f}x",
                flush=True,
            )
    print(f"ratios: MP4/PNG {mp4_fps / png_fps:.2f}x, 1080p/480p draw {ms1080 / ms480:.2f}x")
    print(
        json.dumps(
            {
                "ticks": ticks,
                "size": f"{SIZE[0]}x{SIZE[1]}",
                "cores": os.cpu_count(),
                "mp4_fps": round(mp4_fps, 1),
                "mp4_kb_per_frame": round(mp4_bytes / ticks / 1024, 2),
                "film_170k_min": round(film_s / 60, 2),
                "goal_met": film_s < GOAL_S,
                "png_fps": round(png_fps, 1),
                "png_ticks": png_ticks,
                "ratio_mp4_png": round(mp4_fps / png_fps, 2),
                "draw_ms_480p": round(ms480, 3),
                "draw_ms_1080p": round(ms1080, 3),
                "ratio_1080p_480p": round(ms1080 / ms480, 2),
                "dask": dask,
                "ratio_dask_local": round(dask["dask_fps"] / dask["local_fps"], 2) if dask else None,
            }
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
