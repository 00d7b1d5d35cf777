"""Rendering scenes: batched poses, z-buffered images, frames and movies streamed to their files.

The runtime hands over each tick's drawings; images are gathered in small
batches so that poses are evaluated for a whole batch of frames at once,
then the images are rasterized by a pool of worker processes (several
images a task, so the cost of handing work over stays small), by an
executor given by the caller (a Dask cluster), or in this process for
scenes of only a few images.  A task carries each figure's link matrices,
not its triangles: the worker message (:mod:`.message`) sends a figure's
geometry and the background's once a render, and the worker forms the
world triangles.  Each task returns its images, PNG-encoded
when frames are written and raw when a movie is, and this process writes
them in order: PNG files, and the frames of the GIF and MP4 streams (whose
encoders run beside the drawing, :mod:`.video`).  At most a few tasks are
in flight at once, so memory stays flat however long a scene is.

Durability (:mod:`liganimate.runtime.files`): each frame is written under
a temporary name and renamed into place, without an ``fsync`` of its own;
every :data:`SYNC_EVERY` frames, and at the end (finished or interrupted),
the frames written since are flushed to disk together with their folders.
A crash of the process leaves only whole frames (numbered without gaps);
a power loss may in addition lose, or leave empty, the frames written
since the last flush.  Movies and the pose record are synced before they
are renamed into place, and exist only once complete.

Faults: the output options are checked and the outputs locked before the
first image (:mod:`.outputs`); worker processes ignore SIGINT and SIGTERM
and die with this process; :meth:`Renderer.close` always waits for the
images being drawn (bounded), stops the workers, abandons unfinished
movies and removes temporary files, so an interrupted or failed render
leaves only whole files.
"""

from __future__ import annotations

import collections
import contextlib
import json
import math
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
    morph_record,
    morphed,
    static_triangles,
    world_transforms,
)
from liganimate.runtime.files import AtomicWriter, SyncBatch, os_error_words
from liganimate.runtime.render.camera import Camera
from liganimate.runtime.render.framing import framing_view
from liganimate.runtime.render.imagefiles import encode_png, write_png_bytes
from liganimate.runtime.render.look import DEFAULT_LOOK, draw_modern, look_params
from liganimate.runtime.render.message import Keys, Missing, Posed, Shipping, Task, pack, resolve
from liganimate.runtime.render.options import RenderOptions, checked, executor_for
from liganimate.runtime.render.outputs import OutputLock
from liganimate.runtime.render.raster import Framebuffer, rasterize
from liganimate.runtime.values import Graphical, joined_shades

# Images whose poses are evaluated together.
BATCH = 32
# Images handed to a worker process in one task.
CHUNK = 8
# Frames written between two flushes to disk (see the module's notes).
SYNC_EVERY = 512
# Threads writing PNG files.
WRITERS = 2
# Bounds of the memory of evaluated joint angles: (model, motion) pairs, frames each.
_ANGLE_MODELS = 64
_ANGLE_FRAMES = 4096
# Background objects whose drawings are remembered (see Renderer._background).
_STATICS = 256
# Seconds close() waits for the images being drawn before it kills the workers.
_CLOSE_WAIT = 30.0
_SIGNALS = (signal.SIGINT, signal.SIGTERM)


# Frames and periods that are multiples of 2**-_DYADIC below 2**_EXACT_BELOW subtract exactly.
_DYADIC = 20
_EXACT_BELOW = 31


def _dyadic(x: float) -> bool:
    return abs(x) < 2.0**_EXACT_BELOW and math.ldexp(x, _DYADIC) == round(math.ldexp(x, _DYADIC))


def wrapped_frame(frame: float, n: int, period: float) -> float:
    """The frame of copy 1 of ``n * a`` that poses a figure exactly as ``frame`` does.

    Parameters
    ----------
    frame : float
        A frame of the repeated motion.
    n, period : int, float
        Its :attr:`Motion.cycle`.

    Returns
    -------
    float
        ``frame - (k - 1) * period`` when ``frame`` lies strictly inside a
        middle copy ``k`` (1 <= k <= n - 2) and every frame involved is
        exact in binary (a multiple of 2**-20 below 2**31, so the track
        graph's own subtractions give the same local time bit for bit);
        else ``frame`` itself.  Junction frames, the first and the last copy
        (each meets a neighbour on one side only) are never wrapped.
    """
    if n < 4 or not (_dyadic(frame) and _dyadic(period) and _dyadic(n * period)) or period * n >= 2.0**_EXACT_BELOW:
        return frame
    k = math.floor(frame / period)
    while k * period > frame:
        k -= 1
    while (k + 1) * period <= frame:
        k += 1
    if k < 2 or k > n - 2 or k * period == frame:
        return frame
    return frame - (k - 1) * period


class Renderer:
    """Turns the ticks of shot scenes into files.

    Parameters
    ----------
    options : RenderOptions
        What to write and how (:class:`.options.RenderOptions`: the frames
        folder, the size, the movies, the pose record, their rate and
        quality, the workers, the Dask scheduler); checked here again.
    progress : bool, optional
        Show a progress bar (default: unless ``options.quiet``, on a terminal).
    executor : object or None
        Where images are drawn instead of a pool of local processes: any
        object with ``submit(fn, *args) -> concurrent.futures.Future`` and
        ``shutdown(wait=True, cancel_futures=False)``, such as
        :class:`liganimate.runtime.render.distributed.DaskExecutor`.  The
        tasks return their images to this process, which writes every file.
        The renderer uses it for every image and shuts it down when closed.
        Default: a Dask cluster when ``options.scheduler`` names one.

    Raises
    ------
    RenderError
        Before anything is written: an option that cannot be honoured (see
        :func:`.options.checked`), MP4 without ffmpeg, or an output another
        run is writing (see :class:`.outputs.OutputLock`).
    """

    def __init__(self, options: RenderOptions, progress=None, executor=None):
        try:
            self._init(checked(options, make_poses_folder=True), progress, executor)
        except BaseException:
            if executor is not None:
                executor.shutdown(wait=False, cancel_futures=True)
            raise

    def _init(self, options, progress, executor):
        if executor is None and options.scheduler is not None:
            executor = executor_for(options.scheduler)
        self.options = options
        self.executor = executor
        self.out_dir = options.out
        self.size = options.size
        self.aa = options.aa
        self.look = options.look
        self._framed: dict = {}  # (scene id, size) -> default framing view
        self.fps = options.fps
        self.quiet = options.quiet
        self.workers = options.drawing_workers()
        self.pool = None
        self._worker_procs: list = []
        self.pending: list = []
        self.current = None
        self.images = 0  # images handed over so far, all scenes
        self.written = 0  # images delivered to their files so far
        self.scenes: list = []  # [scene id, images]
        self.futures: list = []  # (future, [(scene id, image number)], task, its shapes), in order
        self._chunk: list = []
        self._angles: dict = {}
        self._statics: dict = {}  # id(background item) -> (item, its drawing); see _background
        self.angle_frames = 0  # frames whose joint angles were evaluated (see _joint_angles)
        self._keys = Keys()  # the worker message's shape keys (see .message)
        self._shipping = Shipping()
        self.resent = 0  # tasks sent again because their worker lacked a shape
        self.scene_id = None
        self.scene_total = 0
        self.progress = progress if progress is not None else (not options.quiet and sys.stderr.isatty())
        self._poses_fh = None
        self._closed = False
        self._failed = False
        self._streams: list = []
        self._synced = SyncBatch(SYNC_EVERY)
        self._files = None  # threads writing the PNG files, started with the first
        self._writes: collections.deque = collections.deque()  # (future, path), in order
        # What the tasks send back: PNG bytes when frames are written, raw images for the movies.
        self._want = (options.out is not None, bool(options.movies()))
        poses = options.poses
        if poses:
            try:
                os.makedirs(os.path.dirname(os.path.abspath(poses)), exist_ok=True)
            except OSError as exc:
                raise RenderError(f"cannot create the folder of {poses}: {os_error_words(exc)}") from None
        self.lock = OutputLock(options.out, options.files())
        try:
            if poses:
                self._poses_fh = AtomicWriter(poses)
            for movie, path in options.movies():
                self._streams.append(movie.open(path, options))
        except BaseException:
            self._abort_outputs()
            self.lock.release()
            raise

    # --------------------------------------------------------------- scenes
    def begin_scene(self, scene_id) -> None:
        self.scene_id = scene_id
        self.scene_total = 0
        self.scenes.append([scene_id, 0])
        if self.out_dir is not None:
            os.makedirs(os.path.join(self.out_dir, f"scene{scene_id}"), exist_ok=True)

    def end_scene(self) -> None:
        """Hand over the scene's last images.

        Called from a ``finally`` block: after a failure or an interruption
        inside the renderer it does nothing, so no image is written after
        one that was lost (frames stay numbered without gaps).
        """
        if self._failed:
            return
        with self._failing():
            if self.current is not None:
                self.pending.append(self.current)
                self.current = None
            self.flush()

    @contextlib.contextmanager
    def _failing(self):
        """Note any exception (an interruption, a full disk) passing through, then let it go on."""
        try:
            yield
        except BaseException:
            self._failed = True
            raise

    def add_tick(self, state, rt) -> None:
        with self._failing():
            self._add_tick(state, rt.program.framings)

    def _add_tick(self, state, framings) -> None:
        tick, k = state.tick, state.sameframe
        image = tick // k
        self.scene_total = -(-state.length // k)
        camera = self._view(state, framings)
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

    def _view(self, state, framings) -> tuple:
        """The scene's camera: VIEW's, or in the modern look, for a scene without VIEW, the default framing.

        The framing needs the box of what the scene draws, which checking
        the program gathers (:mod:`.framing`); unchecked, the thesis' camera stays.
        """
        if self.look != "thesis" and not state.viewed and framings.get(state.id) is not None:
            key = (state.id, self.size)
            view = self._framed.get(key)
            if view is None:
                view = self._framed[key] = framing_view(framings[state.id], self.size)
            return view
        return (tuple(float(x) for x in state.view_point), float(state.view_width))

    def _background(self, state, camera):
        """The image's background: each BACKGROUND object's drawing, from the static-background table.

        A background object is a value that never changes (a graphical
        object, or a model drawn in its neutral pose at its placement), and
        the same objects stay in the background image after image: each
        one's triangles, shades and culling are worked out once per render
        (a model's pose included) and reused by identity, for at most
        :data:`_STATICS` objects, so memory stays flat.
        """
        parts = []
        for item in state.background:
            hit = self._statics.get(id(item))
            if hit is None or hit[0] is not item:
                if isinstance(item, Graphical):
                    part = (item.triangles, item.shades(), item.closed) if len(item) else None
                else:
                    part = static_triangles(item)
                if len(self._statics) >= _STATICS:
                    self._statics.clear()
                hit = self._statics[id(item)] = (item, part)
            if hit[1] is not None:
                parts.append(hit[1])
        return (camera, parts)

    # ---------------------------------------------------------------- batch
    def flush(self) -> None:
        if not self.pending:
            return
        results = self._pose_batch()
        for i, img in enumerate(self.pending):
            draws = [(img["background"][0], img["background"][1])]
            for j, (tick, camera, drawn) in enumerate(img["ticks"]):
                parts = [results[(i, j, o)] for o in range(len(drawn))]
                draws.append((camera, parts))
                if self._poses_fh is not None:
                    for o, (name, _posed) in enumerate(drawn):
                        angles, X, fig, morph = results[(i, j, o, "pose")]
                        self._write_pose(img["scene"], tick, img["image"], name, fig, angles, X, morph)
            self._submit((img["scene"], img["image"]), draws)
        self.pending = []

    def _pose_batch(self) -> dict:
        """Pose the pending images' figures, per (model, motion) for all their frames at once.

        Returns
        -------
        dict
            (image, tick, object) -> its :class:`.message.Posed` (link
            matrices, not triangles: the worker forms those); and, with a
            pose record, (image, tick, object, "pose") -> what it records.
        """
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
        results: dict[tuple, tuple] = {}
        for reqs in groups.values():
            fig, motion = reqs[0][4].figure, reqs[0][4].motion
            frames = np.array([r[4].frame for r in reqs])
            placements = np.stack([np.asarray(r[4].figure.placement, dtype=np.float64) for r in reqs])
            angles = self._joint_angles(fig, motion, frames.tolist())
            X, local = morphed(fig, motion, frames, world_transforms(fig, angles, placements))
            table = mesh_table(fig)
            mirrored = np.linalg.det(placements[:, :3, :3]) < 0
            rows, moved = _moved_rows(table, local)
            morphs = morph_record(fig, motion, frames) if self._poses_fh is not None else None
            for n, r in enumerate(reqs):
                results[(r[0], r[1], r[2])] = Posed(
                    table, X[n], bool(mirrored[n]), rows, None if moved is None else moved[n]
                )
                if morphs is not None:
                    results[(r[0], r[1], r[2], "pose")] = (angles[n], X[n], fig, morphs[n])
        return results

    def _joint_angles(self, fig, motion, frames: list) -> np.ndarray:
        """Clamped joint angles (T, J, 3) at ``frames``: a pose table per (model's joints, motion).

        Angles are remembered per frame (a frame's angles do not depend on
        which other frames are evaluated with it).  A REPEATed motion
        (``n * a``, :attr:`Motion.cycle`) plays its middle copies through the
        same track graph, so a frame in any of them is looked up under its
        wrapped frame (:func:`wrapped_frame`): each frame of a period is
        evaluated once per render, however many periods a scene plays.
        ``angle_frames`` counts the frames evaluated.
        """
        key = (id(fig.joints), id(motion))
        entry = self._angles.get(key)
        if entry is None or entry[0] is not fig.joints or entry[1] is not motion:
            if len(self._angles) >= _ANGLE_MODELS:
                self._angles.clear()
            entry = self._angles[key] = (fig.joints, motion, {})
        memo: dict = entry[2]
        cycle = motion.cycle
        keys = frames if cycle is None else [wrapped_frame(f, *cycle) for f in frames]
        missing = [f for f in dict.fromkeys(keys) if f not in memo]
        if missing:
            if len(memo) + len(missing) > _ANGLE_FRAMES:
                memo.clear()
                missing = list(dict.fromkeys(keys))
            self.angle_frames += len(missing)
            for f, row in zip(missing, joint_angles(fig, motion, np.array(missing, dtype=np.float64))):
                memo[f] = row
        return np.stack([memo[f] for f in keys])

    def _write_pose(self, scene, tick, image, name, fig, angles, X, morph) -> None:
        joints = {str(j): [_r(a) for a in angles[k]] for k, j in enumerate(fig.joint_ids)}
        segments = []
        for i, link in enumerate(fig.links):
            parent = fig.parent_joint_of(i)
            segment = {
                "link": link.name,
                "joint": parent.id if parent is not None else None,
                "matrix": [_r(x) for x in X[i].reshape(-1)],
            }
            for field, values in morph.get(i, {}).items():  # a morphed segment's "scale" and "shape"
                segment[field] = [_r(v) for v in values]
            segments.append(segment)
        rec = {"scene": scene, "tick": tick, "image": image, "model": name, "joints": joints, "segments": segments}
        self._poses_fh.write((json.dumps(rec, separators=(", ", ": ")) + "\n").encode("utf-8"))

    def _submit(self, name, draws) -> None:
        """Queue one image, ``name`` = (scene id, image number), for drawing."""
        self._chunk.append((name, draws))
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
        names = [name for name, _ in chunk]
        task, shapes = pack([draws for _, draws in chunk], self._keys, (self.size, self.aa, *self._want, self.look))
        if self.pool is None and self.executor is not None:
            self.pool = self.executor
        if self.pool is None and self.workers > 1 and len(chunk) >= CHUNK:
            self.pool = ProcessPoolExecutor(max_workers=self.workers, initializer=_worker_init, initargs=(os.getpid(),))
            _widen_result_pipe(self.pool)
            task = task.shipping(self._shipping.pick(shapes, self._in_flight()))
            # The first submit forks the workers.  With SIGINT and SIGTERM blocked
            # meanwhile, a signal cannot reach a worker before it has set itself to
            # ignore them; this process receives it once the mask is restored.
            with _signals_blocked():
                self.futures.append((self.pool.submit(draw_task, task), names, task, shapes))
                self._worker_procs = list((getattr(self.pool, "_processes", None) or {}).values())
            return
        if self.pool is None:
            # Drawn here: every shape goes with the task (nothing is copied).
            self._deliver(names, draw_task(task.shipping(shapes), keep=False))
            return
        task = task.shipping(self._shipping.pick(shapes, self._in_flight()))
        self.futures.append((self.pool.submit(draw_task, task), names, task, shapes))
        # Enough in flight to keep every worker busy, no more (memory stays flat);
        # results are taken in order as soon as they are ready.
        while self.futures and (len(self.futures) > self._in_flight() or self.futures[0][0].done()):
            self._take()

    def _in_flight(self) -> int:
        """How many tasks may be in flight: twice the workers (at least four)."""
        return 2 * max(int(getattr(self.pool, "workers", 0) or self.workers), 2)

    def _take(self) -> None:
        future, names, task, shapes = self.futures.pop(0)
        images = _result(future)
        if isinstance(images, Missing):
            # Its worker had not been shipped a shape: again, with every shape it names.
            self.resent += 1
            images = _result(self.pool.submit(draw_task, task.shipping(shapes)))
        self._deliver(names, images)

    def _deliver(self, names, images) -> None:
        """Write the images of one task, in order: PNG files, then frames of the movies."""
        for (scene_id, number), (png, raw) in zip(names, images):
            if png is not None:
                folder = os.path.join(self.out_dir, f"scene{scene_id}")
                path = os.path.join(folder, f"{number:05d}.png")
                self._write(path, png)
            if raw is not None:
                for stream in self._streams:
                    stream.add(raw)
            self.written += 1

    def _write(self, path, png) -> None:
        """Write one PNG file in a helper thread: creating and renaming files waits on the file system.

        The threads overlap that wait with the work of this process (the
        system calls release the interpreter lock).  Files are noted for
        the next flush to disk in order, as their writes complete.
        """
        if self._files is None:
            self._files = ThreadPoolExecutor(max_workers=WRITERS, thread_name_prefix="liganimate-png")
        self._writes.append((self._files.submit(write_png_bytes, path, png, fsync=False), path))
        while self._writes and (len(self._writes) > 8 * WRITERS or self._writes[0][0].done()):
            self._written()

    def _written(self) -> None:
        future, path = self._writes.popleft()
        future.result()
        self._synced.add(path)

    def _stop_writes(self) -> None:
        """Wait for every PNG being written (each is then whole, and none is missing before it)."""
        files, self._files = self._files, None
        if files is None:
            return
        try:
            while self._writes:
                future, path = self._writes.popleft()
                if future.exception() is None:
                    self._synced.add(path)
        finally:
            files.shutdown(wait=True)

    def _show_progress(self) -> None:
        if self.progress:
            total = f"/{self.scene_total}" if self.scene_total else ""
            sys.stderr.write(f"\rscene {self.scene_id}: {self.scenes[-1][1]}{total} images")
            sys.stderr.flush()

    # ---------------------------------------------------------------- finish
    def finish(self) -> None:
        """Wait for every image and write it, then finish the GIF, MP4 and pose record."""
        with self._failing():
            self._finish()

    def _finish(self) -> None:
        self._send()
        while self.futures:
            self._take()
        while self._writes:
            self._written()
        if self.progress and self.images:
            sys.stderr.write("\n")
        self._synced.sync()
        if self._poses_fh is not None:
            self._poses_fh.commit()
            self._poses_fh = None
        streams, self._streams = self._streams, []
        try:
            while streams:
                stream = streams[0]
                if stream.frames:
                    stream.commit()
                else:
                    stream.abort()  # no image at all: no movie, as no frame
                streams.pop(0)
        finally:
            for stream in streams:
                stream.abort()
        self._sync_folders()

    def _sync_folders(self) -> None:
        """Make the renames of the movies and pose record durable (each file was synced before its rename)."""
        folders = {os.path.dirname(os.path.abspath(p)) for p in self.options.files()}
        for folder in sorted(folders):
            self._synced.add_folder(folder)
        if self.out_dir is not None:
            self._synced.add_folder(self.out_dir)
        self._synced.sync()

    def _abort_outputs(self) -> None:
        """Remove the unfinished pose record and movies."""
        if self._poses_fh is not None:
            self._poses_fh.abort()
            self._poses_fh = None
        streams, self._streams = self._streams, []
        for stream in streams:
            stream.abort()

    def close(self) -> None:
        """Stop the workers and release everything; after an error or an interruption, leave only whole files.

        Images already being drawn are waited for (at most ``_CLOSE_WAIT``
        seconds, then their workers are killed) and dropped, images not
        started are dropped, the unfinished pose record and movies and any
        temporary file are removed, the frames written are flushed to disk,
        and the outputs' locks are released.  Safe to call more than once;
        each step runs even if an earlier one fails.
        """
        if self._closed:
            return
        self._closed = True
        try:
            self._stop_pool()
        finally:
            try:
                self._stop_writes()
                self._abort_outputs()
                self.lock.sweep(self.out_dir, self.options.files())
                self._sync_folders()  # the frames of an interrupted run survive a power loss too
            finally:
                self.lock.release()

    def _stop_pool(self) -> None:
        pool, self.pool = self.pool, None
        futures, self.futures, self._chunk = self.futures, [], []
        executor, self.executor = self.executor, None
        if executor is not None:
            # Not started: dropped; being drawn: waited for (their images are not written).
            for f, *_ in futures:
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
                p.kill()  # stuck: nothing of it is written
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


@contextlib.contextmanager
def _signals_blocked():
    """SIGINT and SIGTERM held back in this thread (where the system can: not on Windows)."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


# Bytes of the pipe the workers' results come back through (Linux; at most the system's pipe-max-size).
_RESULT_PIPE = 1 << 20
_F_SETPIPE_SZ = 1031


def _widen_result_pipe(pool) -> None:
    """Let a task's result (eight raw frames: 2.5 MB at 640x480 grey) cross the pipe in a few writes, not forty.

    A pipe holds 64 kB by default, so the worker's writer and this
    process's reader take turns, waking each other, about forty times a
    task; with 1 MB, three.  Measured on the five humanoids to MP4 with two
    workers (interleaved runs, load 5-7): 4.43 ms of CPU a frame against
    4.62.  Best effort: elsewhere than Linux, or where the system allows
    less, the pipe stays as it is.
    """
    if not sys.platform.startswith("linux"):
        return
    reader = getattr(getattr(pool, "_result_queue", None), "_reader", None)
    if reader is None:
        return
    try:
        import fcntl

        fcntl.fcntl(reader.fileno(), _F_SETPIPE_SZ, _RESULT_PIPE)
    except (AttributeError, OSError, ValueError, ImportError):
        return


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
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _SIGNALS)  # blocked by the parent while it forked us
    try:
        import ctypes

        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (OSError, AttributeError, TypeError, ImportError):
        return  # not glibc (Windows' CDLL takes no None)
    if sys.platform.startswith("linux"):
        PR_SET_PDEATHSIG = 1
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        if os.getppid() != parent:
            os._exit(1)  # the parent died before the death signal was armed
    M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
    mallopt(M_MMAP_THRESHOLD, 32 << 20)
    mallopt(M_TRIM_THRESHOLD, 256 << 20)


def draw_task(task: Task, keep: bool = True) -> list | Missing:
    """A worker's task: form the images' world triangles from their link matrices (:mod:`.message`), draw them.

    ``keep``: keep the shapes the task ships for later tasks (see :func:`.message.resolve`).

    Returns
    -------
    list or Missing
        What :func:`draw_images` returns, or :class:`.message.Missing` when
        the task names a shape this process has not been shipped.
    """
    draws = resolve(task, keep)
    if isinstance(draws, Missing):
        return draws
    return draw_images(task.size, draws, task.aa, task.png, task.raw, task.look)


def _moved_rows(table, local) -> tuple:
    """The mesh table's rows a SHAPE morph changed in any frame (bit for bit), and their triangles per frame."""
    if local is None:
        return None, None
    bits = np.dtype(f"u{local.dtype.itemsize}")  # compared as bits: -0.0 is not 0.0, a NaN equals itself
    own = np.ascontiguousarray(table.triangles, dtype=local.dtype).view(bits)
    changed = np.ascontiguousarray(local).view(bits) != own[None]
    rows = np.flatnonzero(changed.reshape(len(local), len(table.triangles), -1).any(axis=(0, 2)))
    return rows, local[:, rows]


def draw_images(size, draws_list, aa=1, png=True, raw=False, look=DEFAULT_LOOK) -> list:
    """Draw several images (a worker's task): ``draws_list`` holds each image's draws (see :func:`draw`).

    Returns
    -------
    list of (bytes or None, ndarray or None)
        For each image, its PNG file's bytes if ``png``, and the image
        itself, shape (H, W) or (H, W, 3), uint8, if ``raw``.
    """
    out = []
    for draws in draws_list:
        image = draw(size, draws, aa, look)
        out.append((encode_png(image) if png else None, image if raw else None))
    return out


def draw(size, draws, aa=1, look=DEFAULT_LOOK) -> np.ndarray:
    """Rasterize one image from its draws: a list of (camera, parts).

    ``aa`` is the anti-aliasing factor (1: none), ``look`` the name of the
    look (:mod:`.look`: ``"modern"`` or ``"thesis"``).  The result is an array
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
    params = look_params(look)
    if params is not None:
        return draw_modern(size, [(_camera(c, size), p) for c, p in merged], aa, params)
    if len(merged) == 1:
        # The usual case: a fresh image, whose depth buffer need only cover what is drawn.
        camera, parts = merged[0]
        tris, grey, cull = _joined(parts)
        image = rasterize(tris, grey, _camera(camera, size), 255, cull, aa=aa)
    else:
        fb = Framebuffer(size, 255, aa=aa)
        for camera, parts in merged:
            tris, grey, cull = _joined(parts)
            fb.draw(tris, grey, _camera(camera, size), cull)
        image = fb.image
    return image


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
    """The :class:`Camera` of a ``((x, y, z), width)`` or ``((x, y, z), width, target)`` view, remembered (a few)."""
    key = (camera, size)
    cam = _cameras.get(key)
    if cam is None:
        if len(_cameras) >= 64:
            _cameras.clear()
        cam = _cameras[key] = Camera(camera[0], camera[1], size, target=camera[2] if len(camera) > 2 else None)
    return cam


def _r(x) -> float:
    v = float(x)
    return 0.0 if v == 0 else float(f"{v:.9g}")
