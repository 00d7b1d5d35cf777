"""Rendering scenes: batched poses, z-buffered images, files written atomically.

The runtime hands over each tick's drawings; images are gathered in small
batches so that poses are evaluated for a whole batch of frames at once,
then the images are rasterized and written by a pool of worker processes
(several images a task, so the cost of handing work over stays small), or
in this process for scenes of only a few images.  At most a few batches are
in flight at once, so memory stays flat however long a scene is.

Faults: the output options are checked and the outputs locked before the
first image (:mod:`.outputs`); worker processes ignore SIGINT and SIGTERM
and die with this process; :meth:`Renderer.close` always waits for the
images being written (bounded), stops the workers and removes temporary
files, so an interrupted or failed render leaves only whole files.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from concurrent.futures.process import BrokenProcessPool

import numpy as np

from liganimate.runtime.errors import RenderError
from liganimate.runtime.figure.pose import (
    joint_angles,
    mesh_table,
    static_triangles,
    world_transforms,
    world_triangles,
)
from liganimate.runtime.render.camera import Camera
from liganimate.runtime.render.imagefiles import (
    AtomicWriter,
    find_ffmpeg,
    fsync_folder,
    os_error_words,
    read_png,
    write_gif,
    write_mp4,
    write_png,
)
from liganimate.runtime.render.outputs import KEYWORD_NAMES, OutputLock, check_outputs
from liganimate.runtime.render.raster import Framebuffer, rasterize
from liganimate.runtime.values import Graphical, joined_shades

# Images whose poses are evaluated together.
BATCH = 32
# Images handed to a worker process in one task.
CHUNK = 8
# Bounds of the memory of evaluated joint angles: (model, motion) pairs, frames each.
_ANGLE_MODELS = 64
_ANGLE_FRAMES = 4096
# Seconds close() waits for the images being drawn before it kills the workers.
_CLOSE_WAIT = 30.0
_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Renderer:
    """Turns the ticks of shot scenes into files.

    Parameters
    ----------
    out_dir : str
        Frames go to ``out_dir/scene<ID>/<NNNNN>.png``.
    size : (int, int)
        Image width and height in pixels.
    gif, mp4, poses : str or None
        Extra outputs: an animated GIF, an MP4, a JSON Lines pose record.
    fps : float
        Frame rate of the GIF and MP4.
    quiet : bool
        No progress bar.
    workers : int or None
        Processes rasterizing in parallel (default: the machine's cores, at
        most 8); 1 draws everything in this process.
    aa : int
        Anti-aliasing factor, 1 (none, the default) or more: each image is
        drawn at ``aa`` times its size in each direction and averaged down.
    executor : object or None
        Where images are drawn instead of a pool of local processes: any
        object with ``submit(fn, *args) -> concurrent.futures.Future`` and
        ``shutdown(wait=True, cancel_futures=False)``, such as
        :class:`liganimate.runtime.render.distributed.DaskExecutor`.  The
        renderer uses it for every image and shuts it down when closed.

    Raises
    ------
    RenderError
        Before anything is written: an output option that cannot be
        honoured (see :func:`.outputs.check_outputs`), MP4 without ffmpeg,
        or an output another run is writing (see :class:`.outputs.OutputLock`).
    """

    def __init__(
        self,
        out_dir,
        size=(640, 480),
        gif=None,
        mp4=None,
        poses=None,
        fps=24.0,
        quiet=False,
        workers=None,
        stdout=None,
        progress=None,
        aa=1,
        executor=None,
    ):
        try:
            self._init(out_dir, size, gif, mp4, poses, fps, quiet, workers, progress, aa, executor)
        except BaseException:
            if executor is not None:
                executor.shutdown(wait=False, cancel_futures=True)
            raise

    def _init(self, out_dir, size, gif, mp4, poses, fps, quiet, workers, progress, aa, executor) -> None:
        self.aa = check_aa(aa, "aa=")
        self.executor = executor
        check_outputs(out_dir, gif, mp4, poses, fps, KEYWORD_NAMES, make_poses_folder=True)
        self.out_dir = out_dir
        self.size = (int(size[0]), int(size[1]))
        self.gif, self.mp4, self.fps = gif, mp4, float(fps)
        if mp4:
            # No ffmpeg, no render: say so before any file is written.
            find_ffmpeg()
        self.poses_path = poses
        self.quiet = quiet
        self.workers = workers if workers is not None else min(os.cpu_count() or 1, 8)
        self.pool = None
        self.pending: list = []
        self.current = None
        self.images = 0  # images handed over so far, all scenes
        self.scenes: list = []  # [scene id, images], for the GIF and MP4
        self.futures: list = []
        self._chunk: list = []
        self._angles: dict = {}
        self.scene_id = None
        self.scene_total = 0
        self.progress = progress if progress is not None else (not quiet and sys.stderr.isatty())
        self._poses_fh = None
        self._closed = False
        if poses:
            try:
                os.makedirs(os.path.dirname(os.path.abspath(poses)), exist_ok=True)
            except OSError as exc:
                raise RenderError(f"cannot create the folder of {poses}: {os_error_words(exc)}") from None
        self.lock = OutputLock(out_dir, (gif, mp4, poses))
        if poses:
            try:
                self._poses_fh = AtomicWriter(poses)
            except BaseException:
                self.lock.release()
                raise

    # --------------------------------------------------------------- scenes
    def begin_scene(self, scene_id) -> None:
        self.scene_id = scene_id
        self.scene_total = 0
        self.scenes.append([scene_id, 0])
        os.makedirs(os.path.join(self.out_dir, f"scene{scene_id}"), exist_ok=True)

    def end_scene(self) -> None:
        if self.current is not None:
            self.pending.append(self.current)
            self.current = None
        self.flush()

    def add_tick(self, state, rt) -> None:
        tick, k = state.tick, state.sameframe
        image = tick // k
        self.scene_total = -(-state.length // k)
        camera = (tuple(float(x) for x in state.view_point), float(state.view_width))
        if self.current is None or self.current["image"] != image:
            if self.current is not None:
                self.pending.append(self.current)
            self.current = {
                "scene": state.id,
                "image": image,
                "background": self._background(state, camera),
                "ticks": [],
            }
        self.current["ticks"].append((tick, camera, list(state.drawn)))
        if tick % k == k - 1 or tick == state.length - 1:
            self.pending.append(self.current)
            self.current = None
            if len(self.pending) >= BATCH:
                self.flush()

    def _background(self, state, camera):
        parts = []
        for item in state.background:
            if isinstance(item, Graphical):
                if len(item):
                    parts.append((item.triangles, item.shades(), item.closed))
            else:
                parts.append(static_triangles(item))
        return (camera, parts)

    # ---------------------------------------------------------------- batch
    def flush(self) -> None:
        if not self.pending:
            return
        requests = []  # (image slot, tick slot, order, name, posed, tick)
        for i, img in enumerate(self.pending):
            for j, (tick, _camera, drawn) in enumerate(img["ticks"]):
                for order, (name, posed) in enumerate(drawn):
                    requests.append((i, j, order, name, posed, tick))
        groups: dict = {}
        for r in requests:
            fig, motion = r[4].figure, r[4].motion
            key = (id(fig.links), id(fig.joints), fig.main, id(motion))
            groups.setdefault(key, []).append(r)
        results = {}
        for reqs in groups.values():
            fig, motion = reqs[0][4].figure, reqs[0][4].motion
            frames = np.array([r[4].frame for r in reqs])
            placements = np.stack([np.asarray(r[4].figure.placement, dtype=np.float64) for r in reqs])
            angles = self._joint_angles(fig, motion, frames.tolist())
            X = world_transforms(fig, angles, placements)
            table = mesh_table(fig)
            tris = world_triangles(table, X)
            mirrored = np.linalg.det(placements[:, :3, :3]) < 0
            for n, r in enumerate(reqs):
                cull = table.closed if not mirrored[n] else np.zeros(len(table.closed), dtype=bool)
                results[(r[0], r[1], r[2])] = (tris[n], table.shade, cull)
                if self._poses_fh is not None:
                    results[(r[0], r[1], r[2], "pose")] = (angles[n], X[n], fig)
        for i, img in enumerate(self.pending):
            draws = [(img["background"][0], img["background"][1])]
            for j, (tick, camera, drawn) in enumerate(img["ticks"]):
                parts = [results[(i, j, o)] for o in range(len(drawn))]
                draws.append((camera, parts))
                if self._poses_fh is not None:
                    for o, (name, _posed) in enumerate(drawn):
                        angles, X, fig = results[(i, j, o, "pose")]
                        self._write_pose(img["scene"], tick, img["image"], name, fig, angles, X)
            path = os.path.join(self.out_dir, f"scene{img['scene']}", f"{img['image']:05d}.png")
            self._submit(path, draws)
        self.pending = []

    def _joint_angles(self, fig, motion, frames: list) -> np.ndarray:
        """Clamped joint angles (T, J, 3) at ``frames``, each frame evaluated once per render.

        A REPEATed motion comes back to the same frames every period, so
        angles are remembered per (model's joints, motion, frame); a frame's
        angles do not depend on which other frames are evaluated with it.
        """
        key = (id(fig.joints), id(motion))
        entry = self._angles.get(key)
        if entry is None or entry[0] is not fig.joints or entry[1] is not motion:
            if len(self._angles) >= _ANGLE_MODELS:
                self._angles.clear()
            entry = self._angles[key] = (fig.joints, motion, {})
        memo = entry[2]
        missing = [f for f in dict.fromkeys(frames) if f not in memo]
        if missing:
            if len(memo) + len(missing) > _ANGLE_FRAMES:
                memo.clear()
                missing = list(dict.fromkeys(frames))
            for f, row in zip(missing, joint_angles(fig, motion, np.array(missing, dtype=np.float64))):
                memo[f] = row
        return np.stack([memo[f] for f in frames])

    def _write_pose(self, scene, tick, image, name, fig, angles, X) -> None:
        joints = {str(j): [_r(a) for a in angles[k]] for k, j in enumerate(fig.joint_ids)}
        segments = []
        for i, link in enumerate(fig.links):
            parent = fig.parent_joint_of(i)
            segments.append(
                {
                    "link": link.name,
                    "joint": parent.id if parent is not None else None,
                    "matrix": [_r(x) for x in X[i].reshape(-1)],
                }
            )
        rec = {"scene": scene, "tick": tick, "image": image, "model": name, "joints": joints, "segments": segments}
        self._poses_fh.write((json.dumps(rec, separators=(", ", ": ")) + "\n").encode("utf-8"))

    def _submit(self, path, draws) -> None:
        self._chunk.append((path, draws))
        self.images += 1
        self.scenes[-1][1] += 1
        if len(self._chunk) >= CHUNK:
            self._send()
        self._show_progress()

    def _send(self) -> None:
        """Hand the gathered images to a worker (or draw them here: one worker, or a short scene)."""
        chunk, self._chunk = self._chunk, []
        if not chunk:
            return
        if self.pool is None and self.executor is not None:
            self.pool = self.executor
            self._worker_procs = []
        if self.pool is None and self.workers > 1 and len(chunk) >= CHUNK:
            self.pool = ProcessPoolExecutor(max_workers=self.workers, initializer=_worker_init, initargs=(os.getpid(),))
            self._worker_procs: list = []
            # The first submit forks the workers.  With SIGINT and SIGTERM blocked
            # meanwhile, a signal cannot reach a worker before it has set itself to
            # ignore them; this process receives it once the mask is restored.
            old = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
            try:
                self.futures.append(self.pool.submit(draw_images, self.size, chunk, self.aa))
                self._worker_procs = list((getattr(self.pool, "_processes", None) or {}).values())
            finally:
                signal.pthread_sigmask(signal.SIG_SETMASK, old)
            return
        if self.pool is None:
            draw_images(self.size, chunk, self.aa)
            return
        self.futures.append(self.pool.submit(draw_images, self.size, chunk, self.aa))
        # Enough in flight to keep every worker busy, no more (memory stays flat).
        while len(self.futures) > 2 * max(self.workers, 2):
            _result(self.futures.pop(0))

    def _show_progress(self) -> None:
        if self.progress:
            total = f"/{self.scene_total}" if self.scene_total else ""
            sys.stderr.write(f"\rscene {self.scene_id}: {self.scenes[-1][1]}{total} images")
            sys.stderr.flush()

    # ---------------------------------------------------------------- finish
    def finish(self) -> None:
        """Wait for every image, then write the GIF, MP4 and pose record."""
        self._send()
        while self.futures:
            _result(self.futures.pop(0))
        if self.progress and self.images:
            sys.stderr.write("\n")
        if self._poses_fh is not None:
            self._poses_fh.commit()
            self._poses_fh = None
        if self.gif and self.images:
            write_gif(self.gif, self._frames(), self.fps)
        if self.mp4 and self.images:
            write_mp4(self.mp4, self._frames(), self.fps)
        self._sync_folders()

    def _sync_folders(self) -> None:
        """Each file was synced before its rename; syncing the folders makes the renames durable too."""
        folders = {os.path.join(self.out_dir, f"scene{scene_id}") for scene_id, _ in self.scenes}
        folders |= {os.path.dirname(os.path.abspath(p)) for p in (self.gif, self.mp4, self.poses_path) if p}
        for folder in sorted(folders) + [self.out_dir]:
            fsync_folder(folder)

    def _frames(self):
        """Every image written, in order, read back one at a time."""
        for scene_id, count in self.scenes:
            for i in range(count):
                yield read_png(os.path.join(self.out_dir, f"scene{scene_id}", f"{i:05d}.png"))

    def close(self) -> None:
        """Stop the workers and release everything; after an error or an interruption, leave only whole files.

        Images already being drawn are waited for (at most ``_CLOSE_WAIT``
        seconds, then their workers are killed), images not started are
        dropped, the unfinished pose record and any temporary file are
        removed, and the outputs' locks are released.  Safe to call more
        than once; each step runs even if an earlier one fails.
        """
        if self._closed:
            return
        self._closed = True
        try:
            self._stop_pool()
        finally:
            try:
                if self._poses_fh is not None:
                    self._poses_fh.abort()
                    self._poses_fh = None
                self.lock.sweep(self.out_dir, (self.gif, self.mp4, self.poses_path))
                self._sync_folders()  # the frames of an interrupted run survive a power loss too
            finally:
                self.lock.release()

    def _stop_pool(self) -> None:
        pool, self.pool = self.pool, None
        futures, self.futures, self._chunk = self.futures, [], []
        executor, self.executor = self.executor, None
        if executor is not None:
            # Not started: dropped; being drawn: waited for, so every file is whole.
            for f in futures:
                f.cancel()
            executor.shutdown(wait=True, cancel_futures=True)
            return
        if pool is None:
            return
        procs = self._worker_procs
        pool.shutdown(wait=False, cancel_futures=True)
        deadline = time.monotonic() + _CLOSE_WAIT
        for p in procs:
            p.join(max(0.0, deadline - time.monotonic()))
        for p in procs:
            if p.is_alive():
                p.kill()  # stuck (a hung disk?): its temporary file is swept afterwards
                p.join(5.0)


def _result(future):
    """A worker's result; a worker that died (killed, out of memory) is a RenderError, not a crash report."""
    try:
        return future.result()
    except BrokenProcessPool:
        raise RenderError(
            "a worker process drawing the images stopped unexpectedly (killed, or out of memory); "
            "the images written before it are complete"
        ) from None


def _worker_init(parent: int) -> None:
    """Set up a worker process: signals are the parent's business, die with it, keep freed memory for reuse.

    SIGINT and SIGTERM are ignored: the parent stops handing out work and
    waits for the images being drawn, so every file is whole; workers dying
    of KeyboardInterrupt mid-task would only print tracebacks.  If the
    parent dies without stopping the pool (SIGKILL), the kernel kills the
    worker (``PR_SET_PDEATHSIG`` on Linux) rather than leave it waiting for
    work forever.

    Each image allocates and frees the same few large arrays; by default
    glibc hands large blocks back to the kernel and gets them again as fresh
    zeroed pages every image.  Raising the mmap and trim thresholds (what
    the MALLOC_MMAP_THRESHOLD_ and MALLOC_TRIM_THRESHOLD_ environment
    variables do at start-up) keeps them in the heap.
    """
    for s in _SIGNALS:
        signal.signal(s, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _SIGNALS)  # blocked by the parent while it forked us
    try:
        import ctypes

        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return  # not glibc
    if sys.platform.startswith("linux"):
        PR_SET_PDEATHSIG = 1
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        if os.getppid() != parent:
            os._exit(1)  # the parent died before the death signal was armed
    M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
    mallopt(M_MMAP_THRESHOLD, 32 << 20)
    mallopt(M_TRIM_THRESHOLD, 256 << 20)


def draw_images(size, chunk, aa=1) -> None:
    """Draw and write several images: ``chunk`` is a list of (path, draws) (a worker's task).

    Each image is encoded and written by a helper thread while the next one
    is drawn: writing waits for the disk (``fsync``), and zlib and numpy
    release the interpreter lock, so the wait overlaps with drawing.  Every
    file is complete when this returns.
    """
    writer = _writer()
    writes = []
    try:
        for path, draws in chunk:
            writes.append(writer.submit(write_png, path, draw(size, draws, aa)))
    finally:
        for w in writes:
            w.result()


_WRITER: tuple = (None, None)  # (process id, executor): a forked child makes its own


def _writer() -> ThreadPoolExecutor:
    global _WRITER
    pid, ex = _WRITER
    if ex is None or pid != os.getpid():
        ex = ThreadPoolExecutor(max_workers=1, thread_name_prefix="liganimate-writer")
        _WRITER = (os.getpid(), ex)
    return ex


def draw_image(path, size, draws, aa=1) -> None:
    """Rasterize one image and write it atomically."""
    write_png(path, draw(size, draws, aa))


def draw(size, draws, aa=1) -> np.ndarray:
    """Rasterize one image from its draws: a list of (camera, parts).

    ``aa`` is the anti-aliasing factor (1: none).  The result is an array
    of shape (H, W) (grey levels) or (H, W, 3) (colour), uint8.

    Consecutive draws seen by the same camera (the background and every tick
    of a still camera) are rasterized as one list of triangles: the
    triangles keep their numbers, so the depth test and the tie rule give
    exactly the image separate draws give, with one pass of fixed costs.
    """
    merged: list = []  # [(camera, [parts])]
    for camera, parts in draws:
        if not parts:
            continue
        if merged and merged[-1][0] == camera:
            merged[-1][1].extend(parts)
        else:
            merged.append((camera, list(parts)))
    if len(merged) == 1:
        # The usual case: a fresh image, whose depth buffer need only cover what is drawn.
        camera, parts = merged[0]
        tris, grey, cull = _joined(parts)
        image = rasterize(tris, grey, _camera(camera, size), 255, cull, **_aa(aa))
    else:
        fb = Framebuffer(size, 255, **_aa(aa))
        for camera, parts in merged:
            tris, grey, cull = _joined(parts)
            fb.draw(tris, grey, _camera(camera, size), cull)
        image = fb.image
    return image


def _aa(aa) -> dict:
    """The anti-aliasing keyword for the rasterizer: none at factor 1, so any rasterizer draws plain images."""
    return {} if aa == 1 else {"aa": aa}


MAX_AA = 8


def check_aa(aa, name: str = "--aa") -> int:
    """``aa`` as an int from 1 to :data:`MAX_AA`, or a RenderError saying why it cannot be."""
    try:
        n = int(aa)
        ok = n == float(aa) and 1 <= n <= MAX_AA
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok or isinstance(aa, bool):
        shown = f"{name}{aa!r}" if name.endswith("=") else f"{name} {aa}"
        raise RenderError(f"{shown} is not an anti-aliasing factor; give a whole number from 1 (none) to {MAX_AA}")
    return n


def _joined(parts):
    """One (triangles, shade, cull) from several; grey shades become RGB if any part is in colour."""
    if len(parts) == 1:
        return parts[0]
    return (
        np.concatenate([p[0] for p in parts]),
        joined_shades(p[1] for p in parts),
        np.concatenate([p[2] for p in parts]),
    )


_cameras: dict = {}


def _camera(camera, size) -> Camera:
    """The :class:`Camera` of a ``((x, y, z), width)`` view, remembered (a few)."""
    key = (camera, size)
    cam = _cameras.get(key)
    if cam is None:
        if len(_cameras) >= 64:
            _cameras.clear()
        cam = _cameras[key] = Camera(camera[0], camera[1], size)
    return cam


def _r(x) -> float:
    v = float(x)
    return 0.0 if v == 0 else float(f"{v:.9g}")
