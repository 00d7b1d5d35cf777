"""Rendering scenes: batched poses, z-buffered images, files written atomically.

The runtime hands over each tick's drawings; images are gathered in small
batches so that poses are evaluated for a whole batch of frames at once,
then each image is rasterized and written (by a pool of worker processes
when there are many), so memory stays flat however long a scene is.
"""

from __future__ import annotations

import json
import os
import sys
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from .camera import Camera
from .imagefiles import read_png, write_gif, write_mp4, write_png
from .pose import joint_angles, mesh_table, static_triangles, world_transforms, world_triangles
from .raster import Framebuffer
from .values import Graphical, grey_levels

BATCH = 32


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
        Processes rasterizing in parallel (default: the machine's cores, at most 2... 8).
    """

    def __init__(self, out_dir, size=(640, 480), gif=None, mp4=None, poses=None, fps=24.0, quiet=False,
                 workers=None, stdout=None, progress=None):
        self.out_dir = out_dir
        self.size = (int(size[0]), int(size[1]))
        self.gif, self.mp4, self.fps = gif, mp4, fps
        self.poses_path = poses
        self.quiet = quiet
        self.workers = workers if workers is not None else min(os.cpu_count() or 1, 8)
        self.pool = None
        self.pending: list = []
        self.current = None
        self.written: list = []
        self.futures: list = []
        self.scene_id = None
        self.progress = progress if progress is not None else (not quiet and sys.stderr.isatty())
        self._poses_tmp = None
        self._poses_fh = None
        if poses:
            d = os.path.dirname(os.path.abspath(poses))
            os.makedirs(d, exist_ok=True)
            self._poses_tmp = os.path.join(d, f".{os.path.basename(poses)}.{os.getpid()}.tmp")
            self._poses_fh = open(self._poses_tmp, "w", encoding="utf-8")

    # --------------------------------------------------------------- scenes
    def begin_scene(self, scene_id) -> None:
        self.scene_id = scene_id
        os.makedirs(os.path.join(self.out_dir, f"scene{scene_id}"), exist_ok=True)

    def end_scene(self) -> None:
        if self.current is not None:
            self.pending.append(self.current)
            self.current = None
        self.flush()

    def add_tick(self, state, rt) -> None:
        tick, k = state.tick, state.sameframe
        image = tick // k
        camera = (tuple(float(x) for x in state.view_point), float(state.view_width))
        if self.current is None or self.current["image"] != image:
            if self.current is not None:
                self.pending.append(self.current)
            self.current = {"scene": state.id, "image": image, "background": self._background(state, camera),
                            "ticks": []}
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
                    parts.append((item.triangles, grey_levels(item.lightness), item.closed))
            else:
                parts.append(static_triangles(item))
        return (camera, parts)

    # ---------------------------------------------------------------- batch
    def flush(self) -> None:
        if not self.pending:
            return
        requests = []  # (image slot, tick slot, order, name, posed, tick)
        for i, img in enumerate(self.pending):
            for j, (tick, camera, drawn) in enumerate(img["ticks"]):
                for order, (name, posed) in enumerate(drawn):
                    requests.append((i, j, order, name, posed, tick))
        groups: dict = {}
        for r in requests:
            fig, motion = r[4].figure, r[4].motion
            key = (id(fig.links), id(fig.joints), fig.main, id(motion))
            groups.setdefault(key, []).append(r)
        results = {}
        for key, reqs in groups.items():
            fig, motion = reqs[0][4].figure, reqs[0][4].motion
            frames = np.array([r[4].frame for r in reqs])
            placements = np.stack([np.asarray(r[4].figure.placement, dtype=np.float64) for r in reqs])
            angles = joint_angles(fig, motion, frames)
            X = world_transforms(fig, angles, placements)
            table = mesh_table(fig)
            tris = world_triangles(table, X)
            mirrored = np.linalg.det(placements[:, :3, :3]) < 0
            for n, r in enumerate(reqs):
                cull = table.closed if not mirrored[n] else np.zeros(len(table.closed), dtype=bool)
                results[(r[0], r[1], r[2])] = (tris[n], table.grey, cull)
                if self._poses_fh is not None:
                    results[(r[0], r[1], r[2], "pose")] = (angles[n], X[n], fig)
        for i, img in enumerate(self.pending):
            draws = [(img["background"][0], img["background"][1])]
            for j, (tick, camera, drawn) in enumerate(img["ticks"]):
                parts = [results[(i, j, o)] for o in range(len(drawn))]
                draws.append((camera, parts))
                if self._poses_fh is not None:
                    for o, (name, posed) in enumerate(drawn):
                        angles, X, fig = results[(i, j, o, "pose")]
                        self._write_pose(img["scene"], tick, img["image"], name, fig, angles, X)
            path = os.path.join(self.out_dir, f"scene{img['scene']}", f"{img['image']:05d}.png")
            self._submit(path, draws)
        self.pending = []

    def _write_pose(self, scene, tick, image, name, fig, angles, X) -> None:
        joints = {str(j): [_r(a) for a in angles[k]] for k, j in enumerate(fig.joint_ids)}
        segments = []
        for i, link in enumerate(fig.links):
            parent = fig.parent_joint_of(i)
            segments.append({"link": link.name, "joint": parent.id if parent is not None else None,
                             "matrix": [_r(x) for x in X[i].reshape(-1)]})
        rec = {"scene": scene, "tick": tick, "image": image, "model": name, "joints": joints, "segments": segments}
        self._poses_fh.write(json.dumps(rec, separators=(", ", ": ")) + "\n")

    def _submit(self, path, draws) -> None:
        n = sum(len(parts) for _, parts in draws)
        if self.workers > 1 and self.pool is None and len(self.futures) + len(self.written) >= 4:
            self.pool = ProcessPoolExecutor(max_workers=self.workers)
        if self.pool is not None:
            self.futures.append(self.pool.submit(draw_image, path, self.size, draws))
            while len(self.futures) > 4 * self.workers:
                self.futures.pop(0).result()
        else:
            draw_image(path, self.size, draws)
        self.written.append(path)
        self._show_progress()

    def _show_progress(self) -> None:
        if self.progress:
            sys.stderr.write(f"\rscene {self.scene_id}: {len(self.written)} images")
            sys.stderr.flush()

    # ---------------------------------------------------------------- finish
    def finish(self) -> None:
        """Wait for every image, then write the GIF, MP4 and pose record."""
        for f in self.futures:
            f.result()
        self.futures = []
        if self.progress and self.written:
            sys.stderr.write("\n")
        if self._poses_fh is not None:
            self._poses_fh.flush()
            os.fsync(self._poses_fh.fileno())
            self._poses_fh.close()
            self._poses_fh = None
            os.replace(self._poses_tmp, self.poses_path)
        frames = (read_png(p) for p in self.written)
        if self.gif and self.written:
            write_gif(self.gif, frames, self.fps)
        if self.mp4 and self.written:
            write_mp4(self.mp4, (read_png(p) for p in self.written), self.fps)

    def close(self) -> None:
        """Release the worker pool and any half-written pose record."""
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=True)
            self.pool = None
        if self._poses_fh is not None:
            self._poses_fh.close()
            self._poses_fh = None
            try:
                os.unlink(self._poses_tmp)
            except OSError:
                pass


def draw_image(path, size, draws) -> None:
    """Rasterize one image and write it atomically (runs in worker processes too).

    Consecutive draws seen by the same camera (the background and every tick
    of a still camera) are rasterized as one list of triangles: the
    triangles keep their numbers, so the depth test and the tie rule give
    exactly the image separate draws give, with one pass of fixed costs.
    """
    fb = Framebuffer(size, 255)
    merged: list = []  # [camera, [parts]]
    for camera, parts in draws:
        if not parts:
            continue
        if merged and merged[-1][0] == camera:
            merged[-1][1].extend(parts)
        else:
            merged.append((camera, list(parts)))
    for camera, parts in merged:
        cam = _camera(camera, size)
        if len(parts) == 1:
            tris, grey, cull = parts[0]
        else:
            tris = np.concatenate([p[0] for p in parts])
            grey = np.concatenate([p[1] for p in parts])
            cull = np.concatenate([p[2] for p in parts])
        fb.draw(tris, grey, cam, cull)
    write_png(path, fb.image)


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
