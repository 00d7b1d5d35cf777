"""Rasterizer benchmark: liganimate vs matplotlib mplot3d on the same polygons.

The scene is five box humanoids (11 boxes of 12 triangles each) spread
across a 640x480 frame, each about 170 px tall, posed differently every
frame.  Every figure is the best of several rounds (other load on the
machine only slows rounds down), liganimate and mplot3d rounds interleaved.
Reported, side by side:

* images/second of liganimate's ``rasterize`` and of mplot3d
  (``Poly3DCollection`` drawn by the Agg canvas and read back as an array),
  and their ratio;
* images/second of ``rasterize`` + ``write_png`` with one process and with
  two workers (processes and threads, both reported; the faster is
  ``png_ips_2proc``);
* the cost of one frame at 640x480, 1920x1080 and 3840x2160 (same view, so
  the figures cover proportionally more pixels), for this rasterizer
  ("new") and for the previous one ("old") side by side, with the ratios
  1080p/480p (6.75x the pixels) and 4K/1080p (4x);
* the cost of one frame of the film scene (``benchmarks/five_humans.lig``:
  five Appendix A humans on a ground box, 732 triangles, as the thesis
  look draws them at 640x480: the triangles ``frames.draw`` hands the
  rasterizer), old and new (issue 22's goal: at most 1.0 ms of CPU);
* the fixed cost of a frame: a tiny scene (one box, 12 triangles) at
  640x480, and the five figures at 64x48 (per-triangle work, almost no
  pixels), old and new;
* the cost multiplier of anti-aliasing (aa=2, aa=4) at 640x480 (new only:
  the old one has no anti-aliasing).

"Old" is the rasterizer before its optimisation (issue 13): the file
``runtime/render/raster.py`` of commit ``PREVIOUS`` (before bands of rows,
per-trapezoid tables and anti-aliasing), read with ``git show`` when the
benchmark runs and loaded as a module from a temporary file;
``--previous COMMIT`` takes it from another commit instead (e.g. the one
before a change, to see the change's effect in one run).  Without git
or without that history (an installed copy, a shallow clone) the output
says so and the old figures are null.  (Until the rasterizer got an
independent, deliberately slow cross-check reference, "old" was a frozen
copy of that same version under tests/; it no longer is.)

Frame costs are CPU time of this process (``time.process_time``), best of
several rounds with old and new interleaved: on a shared machine, wall time
also counts other processes' turns. Images a second are given both ways:
by CPU time (this process, its threads and its worker processes; the
``*_ips`` keys, and the ratios) and by wall time (``*_ips_wall``), from
the round of least CPU time.  The load average is printed first and
last: other processes also compete for the caches and memory, which CPU
time does feel (in the runs of issue 22 the same frames cost up to 10%
more at a load of 2 than of 1 on this project's two-core machine).

The last line printed is one JSON object with the figures.  Keys
``old_ms_<case>``, ``old_ratio_1080p_480p`` and ``old_ratio_4k_1080p`` are
null when the old rasterizer is not available; ``old_source`` names where
it came from (``"git <commit>:runtime/render/raster.py"``), or is null, and
``old_same_image`` and ``old_same_film`` say whether it drew the 480p
benchmark frame and the film scene's frames with the same bytes.

Usage: ``python benchmarks/raster.py [--quick]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import multiprocessing as mp
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

# One BLAS thread, set before numpy loads: building the scenes uses matrix
# products, and OpenBLAS's idle threads then spin on this 2-core machine,
# slowing whichever renderer is timed next (mplot3d most: it measured 20%
# faster with this set, so the comparison favours mplot3d if anything).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from _clock import load, load_text  # noqa: E402

from liganimate.runtime.render.camera import Camera  # noqa: E402
from liganimate.runtime.render.imagefiles import write_png  # noqa: E402
from liganimate.runtime.render.raster import rasterize  # noqa: E402

#: The film scene (issue 22): its frames are drawn by the rasterizer as ``liganimate run`` draws them.
FILM_SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "five_humans.lig")

#: The commit whose runtime/render/raster.py is the "old" rasterizer: the
#: last one before the optimisations of issue 13.
PREVIOUS = "2526992"
_REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SIZE = (640, 480)
VIEW_POINT = (3.0, 4.0, 14.0)
VIEW_WIDTH = 6.8

# Unit cube corners (+-1) and its faces as quads, counter-clockwise seen
# from outside (outward right-hand normals), as the rasterizer's cull flag
# expects.
_CORNERS = np.array([[x, y, z] for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)], dtype=float)
_QUADS = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
_BOX_TRIS = np.array([[q[0], q[1], q[2]] for q in _QUADS] + [[q[0], q[2], q[3]] for q in _QUADS])


def _rot(axis: int, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) about a coordinate axis."""
    c, s = np.cos(angle), np.sin(angle)
    m = np.zeros(np.shape(angle) + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m[..., axis, axis] = 1.0
    m[..., i, i] = c
    m[..., j, j] = c
    m[..., i, j] = -s
    m[..., j, i] = s
    return m


def humanoid_boxes(t: float, seed: int):
    """Boxes of one posed humanoid at time t: centres (11, 3), half sizes (11, 3), rotations (11, 3, 3)."""
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0, 2 * np.pi)
    swing = 0.6 * np.sin(2.0 * t + phase)
    centres, halves, rots = [], [], []

    def seg(top, length, hx, hz, angle):
        # A box hanging down from ``top``, swung by ``angle`` about X; returns its lower end.
        r = _rot(0, np.asarray(angle))
        centres.append(np.asarray(top) + r @ np.array([0.0, -length / 2, 0.0]))
        halves.append([hx, length / 2, hz])
        rots.append(r)
        return np.asarray(top) + r @ np.array([0.0, -length, 0.0])

    seg([0, 1.55, 0], 0.55, 0.2, 0.11, 0.0)  # torso
    seg([0, 1.0, 0], 0.12, 0.17, 0.1, 0.0)  # pelvis
    seg([0, 1.8, 0], 0.22, 0.1, 0.1, 0.1 * swing)  # head (top at 1.8)
    for side in (-1, 1):
        elbow = seg([0.27 * side, 1.52, 0], 0.3, 0.06, 0.06, side * swing)
        seg(elbow, 0.28, 0.05, 0.05, side * swing - 0.4)
        knee = seg([0.1 * side, 0.9, 0], 0.42, 0.08, 0.08, -side * swing)
        seg(knee, 0.42, 0.065, 0.065, -side * swing + 0.3)
    return np.array(centres), np.array(halves), np.array(rots)


def boxes_to_triangles(centres, halves, rots) -> np.ndarray:
    """Closed, outward-wound boxes (B, ...) to triangles (12 B, 3, 3)."""
    corners = _CORNERS[None] * halves[:, None, :]  # (B, 8, 3)
    corners = np.einsum("bij,bkj->bki", rots, corners) + centres[:, None, :]
    return corners[:, _BOX_TRIS].reshape(-1, 3, 3)


def scene(frame: int, fps: float = 25.0):
    """Five humanoids at one frame: triangles (N, 3, 3) and grey levels (N,)."""
    t = frame / fps
    tris = []
    for h, x in enumerate(np.linspace(-2.4, 2.4, 5)):
        c, s, r = humanoid_boxes(t, seed=h)
        yaw = _rot(1, np.asarray(0.5 * h - 1.0 + 0.3 * t))
        c = c @ yaw.T + np.array([x, -0.9, 0.4 * (h % 2)])
        tris.append(boxes_to_triangles(c, s, np.einsum("ij,bjk->bik", yaw, r)))
    tris = np.concatenate(tris)
    # Lambert-like grey from the face normal, as the runtime would do.
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    light = np.array([0.4, 0.8, 0.45]) / np.linalg.norm([0.4, 0.8, 0.45])
    shade = (40 + 180 * np.clip(n @ light, 0, 1)).astype(np.uint8)
    return tris, shade


def _camera() -> Camera:
    return Camera(VIEW_POINT, VIEW_WIDTH, SIZE)


class Rate(NamedTuple):
    """Images a second of one round: by its CPU time (this process, its threads and its worker processes) and by wall time."""

    cpu: float
    wall: float


def _rate(run, frames: int) -> Rate:
    """One round of ``run(frames)``, which returns the images drawn and the CPU seconds its worker processes spent."""
    c0, w0 = time.process_time(), time.perf_counter()
    done, workers_cpu = run(frames)
    cpu, wall = time.process_time() - c0 + workers_cpu, time.perf_counter() - w0
    return Rate(done / cpu, done / wall)


def _best_rate(run, frames: int, rounds: int) -> Rate:
    """The round of least CPU time among several (other work on the machine only ever slows a round down)."""
    return max((_rate(run, frames) for _ in range(rounds)), key=lambda r: r.cpu)


def liganimate_runner(cull=True):
    """A function rendering n frames with liganimate; scenes are built outside the timing."""
    cam = _camera()
    scenes = _scene_cache(50)
    flags = np.ones(len(scenes[0][0]), dtype=bool) if cull else None
    rasterize(*scenes[0], cam, cull=flags)

    def run(n):
        for i in range(n):
            tris, shade = scenes[i % len(scenes)]
            rasterize(tris, shade, cam, cull=flags)
        return n, 0.0

    return run


_TO_MPL = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])


def mplot3d_runner(save=None):
    """The same frames drawn by mplot3d: Poly3DCollection on an Agg canvas, read back as an array."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig = Figure(figsize=(SIZE[0] / 100, SIZE[1] / 100), dpi=100)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes([0, 0, 1, 1], projection="3d")
    # Same view as liganimate's camera: mplot3d is Z-up, so world (x, y, z)
    # is drawn as (x, -z, y); the focal length matches VIEW WIDTH, and the
    # zoom was fitted so the figures cover the same pixels (about 29000).
    p = _TO_MPL @ np.array(VIEW_POINT)
    d = np.linalg.norm(p)
    ax.set_proj_type("persp", focal_length=d / (VIEW_WIDTH / 2))
    ax.view_init(elev=np.degrees(np.arcsin(p[2] / d)), azim=np.degrees(np.arctan2(p[1], p[0])))
    ax.set_axis_off()
    for setlim in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        setlim(-4.0, 4.0)
    ax.set_box_aspect((1, 1, 1), zoom=2.61)
    # Vertices and colours are prepared outside the timing, to be fair to mplot3d.
    scenes = [(tris @ _TO_MPL.T, np.repeat(shade[:, None] / 255.0, 3, axis=1)) for tris, shade in _scene_cache(50)]
    coll = Poly3DCollection(scenes[0][0], facecolors=scenes[0][1], edgecolors="none")
    ax.add_collection3d(coll)
    canvas.draw()

    def run(n):
        for i in range(n):
            verts, colours = scenes[i % len(scenes)]
            coll.set_verts(verts)
            coll.set_facecolor(colours)
            canvas.draw()
            img = np.asarray(canvas.buffer_rgba())[:, :, 0].copy()
        if save:
            write_png(save, img)
        return n, 0.0

    return run


def _scene_cache(frames):
    return [scene(f) for f in range(frames)]


_SCENES: list = []


def _init_worker():
    global _SCENES
    _SCENES = _scene_cache(50)


def _render_and_write(args):
    """Worker body: rasterize + write_png ``count`` frames into ``folder``."""
    worker, count, folder = args
    cam = _camera()
    cull = np.ones(len(_SCENES[0][0]), dtype=bool)
    for i in range(count):
        tris, shade = _SCENES[i % len(_SCENES)]
        img = rasterize(tris, shade, cam, cull=cull)
        write_png(os.path.join(folder, f"w{worker}_{i % 50:03d}.png"), img)
    return count


def _render_and_write_cpu(args) -> tuple[int, float]:
    """:func:`_render_and_write` in a worker process: the frames and the worker's CPU seconds."""
    t0 = time.process_time()
    count = _render_and_write(args)
    return count, time.process_time() - t0


def bench_png(frames: int, rounds: int, workers: int, mode: str) -> Rate:
    """Best images/second of rasterize + write_png with 1 or more workers (threads count in this process's CPU)."""
    with tempfile.TemporaryDirectory() as folder:
        if mode == "process":
            ctx = mp.get_context("fork")
            with ctx.Pool(workers, initializer=_init_worker) as pool:
                pool.map(_render_and_write, [(w, 2, folder) for w in range(workers)])  # warm up

                def run(n):
                    share = [(w, n // workers, folder) for w in range(workers)]
                    done = pool.map(_render_and_write_cpu, share)
                    return sum(d for d, _ in done), sum(c for _, c in done)

                return _best_rate(run, frames, rounds)
        _init_worker()
        _render_and_write((0, 2, folder))
        if workers == 1:
            return _best_rate(lambda n: (_render_and_write((0, n, folder)), 0.0), frames, rounds)
        with ThreadPoolExecutor(workers) as ex:

            def run(n):
                return sum(ex.map(_render_and_write, [(w, n // workers, folder) for w in range(workers)])), 0.0

            return _best_rate(run, frames, rounds)


def previous_rasterizer(commit: str = PREVIOUS):
    """The old rasterizer's ``rasterize`` (that of ``commit``), out of git history, or why it is not available.

    Returns
    -------
    tuple
        ``(rasterize, source)`` with ``source`` naming the commit and file,
        or ``(None, reason)``.
    """
    where = f"{commit}:runtime/render/raster.py"
    try:
        shown = subprocess.run(
            ["git", "-C", _REPO, "show", where], capture_output=True, text=True, check=False, timeout=60
        )
    except (OSError, subprocess.SubprocessError) as exc:
        return None, f"git could not be run ({exc})"
    if shown.returncode != 0:
        first = (shown.stderr.strip().splitlines() or ["no output"])[0]
        return None, f"git show {where} failed: {first}"
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, f"raster_{commit}.py")
        with open(path, "w", encoding="utf-8") as f:
            f.write(shown.stdout)
        spec = importlib.util.spec_from_file_location(f"raster_{commit}", path)
        if spec is None or spec.loader is None:
            return None, f"{where} could not be loaded as a module"
        module = importlib.util.module_from_spec(spec)
        try:
            spec.loader.exec_module(module)
        except Exception as exc:  # its imports may no longer exist in this tree
            return None, f"{where} does not load any more ({type(exc).__name__}: {exc})"
    return module.rasterize, f"git {where}"


RESOLUTIONS = {"480p": (640, 480), "1080p": (1920, 1080), "4K": (3840, 2160)}


def film_frames(count: int = 20) -> list:
    """The first ``count`` images of the film scene as the rasterizer is given them.

    The scene (``FILM_SCENE``, made ``count`` ticks long) is compiled and
    rendered in the thesis look at 640x480, one process, with the drawing
    step replaced by a recorder; each image's draws (one camera) are joined
    as ``frames.draw`` joins them.  Returns ``(triangles, grey levels, cull
    flags, camera)`` per image.
    """
    from film import captured_draws, scene_program

    from liganimate.runtime.render import frames as R

    with tempfile.TemporaryDirectory() as folder:
        got = captured_draws(scene_program(folder, count), count, "thesis")
    frames = []
    for draws in got:
        cameras = {camera for camera, _parts in draws}
        assert len(cameras) == 1, cameras  # a still camera: one list of triangles an image
        tris, grey, cull = R._joined([part for _camera, parts in draws for part in parts])
        frames.append((tris, grey, cull, R._camera(cameras.pop(), SIZE)))
    return frames


def _frame_cost(draw, scenes, camera, frames: int, **kw) -> float:
    """CPU milliseconds per frame of ``draw`` over ``frames`` frames of ``scenes``.

    A scene is ``(triangles, shade)``, drawn by ``camera`` with every
    triangle culled where it faces away, or ``(triangles, shade, cull,
    camera)``.
    """
    cull = np.ones(len(scenes[0][0]), dtype=bool)
    t0 = time.process_time()
    for i in range(frames):
        scene = scenes[i % len(scenes)]
        if len(scene) == 4:
            draw(scene[0], scene[1], scene[3], cull=scene[2], **kw)
        else:
            draw(scene[0], scene[1], camera, cull=cull[: len(scene[0])], **kw)
    return (time.process_time() - t0) / frames * 1e3


def bench_costs(frames: int, rounds: int, old=None, film=None) -> dict:
    """Best CPU ms per frame: old and new at each resolution, the fixed costs, and aa.

    ``old`` is the previous rasterizer's ``rasterize``, or None to time only
    this one; ``film`` the film scene's frames (:func:`film_frames`).
    Returns a dict keyed ``(implementation, case)``.
    """
    scenes = _scene_cache(20)
    tiny = [(tris[:12], shade[:12]) for tris, shade in scenes]
    cases = {name: (scenes, Camera(VIEW_POINT, VIEW_WIDTH, size), {}) for name, size in RESOLUTIONS.items()}
    cases["film"] = (film or film_frames(), None, {})
    cases["tiny"] = (tiny, _camera(), {})
    cases["64x48"] = (scenes, Camera(VIEW_POINT, VIEW_WIDTH, (64, 48)), {})
    impls = {"new": rasterize} if old is None else {"old": old, "new": rasterize}
    jobs = [(impl, case) for case in cases for impl in impls]
    jobs += [("new", "aa2"), ("new", "aa4")]
    cases["aa2"] = (scenes, _camera(), {"aa": 2})
    cases["aa4"] = (scenes, _camera(), {"aa": 4})
    # Frames per round: fewer where a frame costs more, at least 2.
    weight = {"480p": 1, "film": 1, "1080p": 6, "4K": 24, "tiny": 0.1, "64x48": 0.2, "aa2": 4, "aa4": 16}
    best = {job: float("inf") for job in jobs}
    for job in jobs:  # warm up (shared aranges, cameras)
        impl, case = job
        _frame_cost(impls[impl], cases[case][0], cases[case][1], 1, **cases[case][2])
    for _ in range(rounds):
        for job in jobs:
            impl, case = job
            n = max(2, int(frames / weight[case]))
            best[job] = min(best[job], _frame_cost(impls[impl], cases[case][0], cases[case][1], n, **cases[case][2]))
    return best


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a short run (under a minute)")
    ap.add_argument("--previous", default=PREVIOUS, metavar="COMMIT", help=f"the old rasterizer's commit ({PREVIOUS})")
    args = ap.parse_args(argv)
    frames, rounds = (50, 5) if args.quick else (200, 15)
    print(load_text())
    load_start = load()[0]

    tris, _ = scene(0)
    img = rasterize(*scene(0), _camera())
    ys, _ = np.nonzero(img != 255)
    print(
        f"scene: {len(tris)} triangles, {SIZE[0]}x{SIZE[1]}, figures span rows {ys.min()}..{ys.max()}, "
        f"{(img != 255).sum()} pixels covered"
    )
    print(f"timing: best of {rounds} rounds of {frames} images (liganimate and mplot3d rounds interleaved)")

    lig, lig_nocull, mpl = liganimate_runner(True), liganimate_runner(False), mplot3d_runner()
    rates: dict[str, list[Rate]] = {"lig": [], "nocull": [], "mpl": []}
    for _ in range(rounds):
        for name, run, n in [("lig", lig, frames), ("nocull", lig_nocull, frames), ("mpl", mpl, max(frames // 5, 5))]:
            rates[name].append(_rate(run, n))
    best = {name: max(r, key=lambda x: x.cpu) for name, r in rates.items()}

    def rate(r: Rate) -> str:
        return f"{r.cpu:8.1f} images/CPU s (wall {r.wall:8.1f} images/s)"

    print(f"liganimate rasterize (culling): {rate(best['lig'])}")
    print(f"liganimate rasterize (no cull): {rate(best['nocull'])}")
    print(f"mplot3d Poly3DCollection/Agg:   {rate(best['mpl'])}   (painter's sort, no z-buffer)")
    print(
        f"ratio (CPU): {best['lig'].cpu / best['mpl'].cpu:.1f}x (no cull: {best['nocull'].cpu / best['mpl'].cpu:.1f}x); "
        f"wall: {best['lig'].wall / best['mpl'].wall:.1f}x"
    )

    png1 = bench_png(frames, rounds, 1, "thread")
    png2p = bench_png(2 * frames, rounds, 2, "process")
    png2t = bench_png(2 * frames, rounds, 2, "thread")
    print(f"rasterize + write_png, 1 process:   {rate(png1)}")
    print(f"rasterize + write_png, 2 processes: {rate(png2p)}")
    print(f"rasterize + write_png, 2 threads:   {rate(png2t)}")

    film = film_frames()
    ftris, fgrey, fcull, fcam = film[0]
    fimg = rasterize(ftris, fgrey, fcam, cull=fcull)
    print(
        f"film scene ({os.path.basename(FILM_SCENE)}, thesis look): {len(ftris)} triangles, {SIZE[0]}x{SIZE[1]}, "
        f"{(fimg != 255).sum()} pixels covered, {len(film)} images"
    )
    old, source = previous_rasterizer(args.previous)
    same_image = same_film = None
    if old is None:
        print(f"previous rasterizer not available: {source}; timing this one only")
    else:
        cam, flags = _camera(), np.ones(len(tris), dtype=bool)
        same_image = bool(np.array_equal(old(*scene(0), cam, cull=flags), rasterize(*scene(0), cam, cull=flags)))
        same_film = all(np.array_equal(old(t, g, c, cull=f), rasterize(t, g, c, cull=f)) for t, g, f, c in film)
        print(
            f"previous rasterizer: {source} (same 480p image: {'yes' if same_image else 'NO'}; "
            f"same film images: {'yes' if same_film else 'NO'})"
        )
    cost = bench_costs(frames, rounds, old, film)
    impls = ("new",) if old is None else ("old", "new")
    print("CPU ms per frame (best of rounds), " + ("previous rasterizer vs this one:" if old else "this rasterizer:"))
    for case in ["480p", "film", "1080p", "4K", "tiny", "64x48"]:
        new = cost["new", case]
        if old is None:
            print(f"  {case:6s} new {new:8.3f}")
        else:
            print(f"  {case:6s} old {cost['old', case]:8.3f}   new {new:8.3f}   old/new {cost['old', case] / new:5.2f}")
    ratios = {
        impl: (cost[impl, "1080p"] / cost[impl, "480p"], cost[impl, "4K"] / cost[impl, "1080p"]) for impl in impls
    }
    for impl, (r1, r2) in ratios.items():
        print(f"  {impl}: 1080p/480p {r1:5.2f} (pixels 6.75)   4K/1080p {r2:5.2f} (pixels 4)")
    aa2, aa4 = cost["new", "aa2"] / cost["new", "480p"], cost["new", "aa4"] / cost["new", "480p"]
    print(f"  anti-aliasing at 480p: aa=2 costs {aa2:5.2f}x aa=1, aa=4 {aa4:5.2f}x")
    figures = {}
    for case in ["480p", "film", "1080p", "4K", "tiny", "64x48", "aa2", "aa4"]:
        for impl in ("old", "new"):
            if (impl, case) in cost:
                figures[f"{impl}_ms_{case}"] = round(cost[impl, case], 4)
            elif impl == "old" and case not in ("aa2", "aa4"):
                figures[f"{impl}_ms_{case}"] = None
    ratios.setdefault("old", (None, None))
    print(load_text())
    print(
        json.dumps(
            {
                # Images a second: by CPU time (the judged figure) and by wall time.
                "liganimate_ips": round(best["lig"].cpu, 1),
                "liganimate_nocull_ips": round(best["nocull"].cpu, 1),
                "mplot3d_ips": round(best["mpl"].cpu, 1),
                "liganimate_ips_wall": round(best["lig"].wall, 1),
                "liganimate_nocull_ips_wall": round(best["nocull"].wall, 1),
                "mplot3d_ips_wall": round(best["mpl"].wall, 1),
                "ratio": round(best["lig"].cpu / best["mpl"].cpu, 2),
                "ratio_nocull": round(best["nocull"].cpu / best["mpl"].cpu, 2),
                "ratio_wall": round(best["lig"].wall / best["mpl"].wall, 2),
                "png_ips_1proc": round(png1.cpu, 1),
                "png_ips_2proc": round(max(png2p.cpu, png2t.cpu), 1),
                "png_ips_2proc_processes": round(png2p.cpu, 1),
                "png_ips_2proc_threads": round(png2t.cpu, 1),
                "png_ips_1proc_wall": round(png1.wall, 1),
                "png_ips_2proc_processes_wall": round(png2p.wall, 1),
                "png_ips_2proc_threads_wall": round(png2t.wall, 1),
                **figures,
                "old_ratio_1080p_480p": _rounded(ratios["old"][0]),
                "new_ratio_1080p_480p": _rounded(ratios["new"][0]),
                "old_ratio_4k_1080p": _rounded(ratios["old"][1]),
                "new_ratio_4k_1080p": _rounded(ratios["new"][1]),
                "old_source": source if old else None,
                "old_same_image": same_image,
                "old_same_film": same_film,
                "aa2_cost_x": round(aa2, 2),
                "aa4_cost_x": round(aa4, 2),
                "cores": os.cpu_count(),
                "load_start": round(load_start, 2),
                "load_end": round(load()[0], 2),
                "quick": args.quick,
            }
        )
    )
    return 0


def _rounded(value):
    return None if value is None else round(value, 2)


if __name__ == "__main__":
    sys.exit(main())
