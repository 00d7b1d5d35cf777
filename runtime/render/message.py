"""The worker message: what a render task carries to a worker, and how the worker turns it into draws.

A figure's geometry (its links' triangles in link coordinates, their shades
and culling: :class:`~liganimate.runtime.figure.pose.MeshTable`) and a
BACKGROUND object's drawing do not change from image to image, so a task
does not carry them image after image.  Each one has a **key**, a digest of
its content, and reaches each worker about once a render: the main process
ships it with the first tasks that use it (:class:`Shipping`), a worker
keeps what it was shipped (:func:`resolve`; at most :data:`KEPT` shapes and
:data:`KEPT_BYTES` bytes), and a task that names a key its worker has not
kept is answered with :class:`Missing` and sent again with the shape
(``Renderer._take``).  An image itself is only its cameras and, per figure,
its link matrices (L x 4 x 4, the motion's SCALE folded in), whether the
placement mirrors it (no culling then), and, for a figure whose motion
SHAPEs a segment, the morphed rows of its mesh table.  The worker forms the
world triangles with the same function the main process used before
(:func:`~liganimate.runtime.figure.pose.world_triangles`), whose result for
a frame does not depend on the frames batched with it, so the images are the
same bytes.

Keys are content digests, not counters, so a Dask worker that serves several
renders (or several clients) can never draw one render's shape for
another's key.
"""

from __future__ import annotations

import hashlib
import threading
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from liganimate.runtime.figure.pose import MeshTable, world_triangles

# Shapes a worker keeps between tasks (and their bytes): enough for every model of a long program.
KEPT = 256
KEPT_BYTES = 64 << 20
# Shapes the main process remembers the keys of (by identity), and keys it remembers shipping.
_KEYS = 1024
_SHIPPED = 4096


class Posed(NamedTuple):
    """One figure in one image, in the main process: what its part of the message is made from.

    Attributes
    ----------
    table : MeshTable
        The figure's links' triangles, shades and culling.
    matrices : ndarray, shape (L, 4, 4)
        Each link's shape-to-world transform (:func:`~.pose.world_transforms`, morphs' SCALE folded in).
    mirrored : bool
        The placement mirrors the figure: no face is culled.
    rows : ndarray of int, or None
        The mesh table's rows a SHAPE morph moves (None: no morph).
    moved : ndarray, shape (len(rows), 3, 3), or None
        Those rows' morphed triangles, in link coordinates.
    """

    table: MeshTable
    matrices: np.ndarray
    mirrored: bool
    rows: np.ndarray | None = None
    moved: np.ndarray | None = None


@dataclass(frozen=True)
class Task:
    """A render task: several images, their links' matrices in one array, and the shapes shipped with it.

    Attributes
    ----------
    size : (int, int)
    aa : int
    png, raw : bool
        Return each image's PNG bytes, its raw pixels.
    look : str
    images : tuple
        Per image, its draws: ``(camera, parts)``; a part is ``(key, start,
        links, mirrored, morph)``: the figure's link matrices are
        ``matrices[start:start + links]`` and ``morph`` indexes ``morphs``
        (or is -1); a background part has ``start`` -1 (its shape is already
        in world coordinates).
    matrices : ndarray, shape (N, 4, 4)
    morphs : tuple of (rows, moved)
    shapes : dict
        Key -> MeshTable or (triangles, shade, closed): the shapes this task ships.
    """

    size: tuple
    aa: int
    png: bool
    raw: bool
    look: str
    images: tuple
    matrices: np.ndarray
    morphs: tuple = ()
    shapes: dict = field(default_factory=dict)

    def keys(self) -> set:
        """Every shape key the task's images name."""
        return {part[0] for image in self.images for _camera, parts in image for part in parts}

    def shipping(self, shapes: dict) -> Task:
        """The same task, shipping ``shapes`` too."""
        return replace(self, shapes={**self.shapes, **shapes})


@dataclass(frozen=True)
class Missing:
    """A worker's answer to a task naming shapes it has not kept: send it again with them."""

    keys: tuple


def digest(arrays) -> str:
    """A key for a shape: a SHA-256 digest of its arrays' types, sizes and bytes."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}|".encode())
        h.update(a.tobytes())
    return h.hexdigest()[:32]


class Keys:
    """The main process's keys of shapes, remembered by identity (at most :data:`_KEYS`; each shape kept alive)."""

    def __init__(self) -> None:
        self._known: dict = {}  # id(shape) -> (shape, key)

    def key(self, shape) -> str:
        """The key of a MeshTable or of a background drawing ``(triangles, shade, closed)``."""
        hit = self._known.get(id(shape))
        if hit is not None and hit[0] is shape:
            return hit[1]
        if isinstance(shape, MeshTable):
            key = "m" + digest((shape.triangles, shape.link, shape.shade, shape.closed))
        else:
            key = "b" + digest(shape)
        if len(self._known) >= _KEYS:
            self._known.clear()
        self._known[id(shape)] = (shape, key)
        return key


class Shipping:
    """Which shapes go with which task: each with the first ``spread`` tasks that use it.

    ``spread`` is the number of tasks in flight, so every worker likely
    gets each shape with one of its first tasks; one that does not answers
    :class:`Missing` and the task is sent again (rare, and bounded: the
    second sending carries every shape the task names).
    """

    def __init__(self) -> None:
        self._sent: dict = {}  # key -> tasks it went with

    def pick(self, shapes: dict, spread: int) -> dict:
        """Of a task's shapes (key -> shape), those to ship with it, the first ``spread`` times each."""
        if len(self._sent) >= _SHIPPED:
            self._sent.clear()
        out = {}
        for key, shape in shapes.items():
            n = self._sent.get(key, 0)
            if n < spread:
                self._sent[key] = n + 1
                out[key] = shape
        return out


def pack(images: list, keys: Keys, options: tuple) -> tuple[Task, dict]:
    """The task of several images, with no shape shipped yet, and every shape it names (key -> shape).

    Parameters
    ----------
    images : list
        Per image, its draws ``(camera, parts)``; a part is a :class:`Posed`
        figure or a background drawing ``(triangles, shade, closed)``.
    keys : Keys
    options : tuple
        ``(size, aa, png, raw, look)``.
    """
    matrices: list = []
    morphs: list = []
    shapes: dict = {}
    start = 0
    packed = []
    for draws in images:
        image = []
        for camera, parts in draws:
            out = []
            for part in parts:
                if isinstance(part, Posed):
                    key = keys.key(part.table)
                    shapes[key] = part.table
                    morph = -1
                    if part.rows is not None:
                        morph = len(morphs)
                        morphs.append((part.rows, part.moved))
                    links = len(part.matrices)
                    out.append((key, start, links, bool(part.mirrored), morph))
                    matrices.append(part.matrices)
                    start += links
                else:
                    key = keys.key(part)
                    shapes[key] = part
                    out.append((key, -1, 0, False, -1))
            image.append((camera, tuple(out)))
        packed.append(tuple(image))
    stacked = np.concatenate(matrices) if matrices else np.zeros((0, 4, 4))
    size, aa, png, raw, look = options
    return Task(size, aa, png, raw, look, tuple(packed), stacked, tuple(morphs)), shapes


# The shapes this process keeps (a worker: what tasks shipped it); key -> shape, and their bytes.
# A Dask worker may run tasks in several threads: the store changes under a lock.
_kept: dict = {}
_kept_bytes = [0]
_keeping = threading.Lock()


def _nbytes(shape) -> int:
    arrays = (shape.triangles, shape.link, shape.shade, shape.closed) if isinstance(shape, MeshTable) else shape
    return sum(np.asarray(a).nbytes for a in arrays)


def _keep(shapes: dict) -> None:
    with _keeping:
        for key, shape in shapes.items():
            if key in _kept:
                continue
            size = _nbytes(shape)
            if len(_kept) >= KEPT or _kept_bytes[0] + size > KEPT_BYTES:
                _kept.clear()
                _kept_bytes[0] = 0
            _kept[key] = shape
            _kept_bytes[0] += size


def resolve(task: Task, keep: bool = True) -> list | Missing:
    """A task's draws, as :func:`.frames.draw` takes them, or :class:`Missing` if a shape is not here.

    Parameters
    ----------
    task : Task
    keep : bool
        Keep the shapes the task ships for later tasks (a worker); the main
        process, drawing a task with every shape it names, keeps none.

    Returns
    -------
    list or Missing
        Per image, a list of ``(camera, [(triangles, shade, cull), ...])``
        with each figure's triangles in world coordinates.
    """
    # Looked up before the task's own shapes are kept: keeping them may clear the store.
    shapes = {k: task.shapes[k] if k in task.shapes else _kept.get(k) for k in task.keys()}
    lacking = tuple(sorted(k for k, shape in shapes.items() if shape is None))
    if lacking:
        return Missing(lacking)
    if keep:
        _keep(task.shapes)
    drawn = _figures(task, shapes)
    out = []
    for i, image in enumerate(task.images):
        draws = []
        for d, (camera, parts) in enumerate(image):
            got = []
            for p, (key, start, _links, _mirrored, _morph) in enumerate(parts):
                got.append(shapes[key] if start < 0 else drawn[(i, d, p)])
            draws.append((camera, got))
        out.append(draws)
    return out


def _figures(task: Task, shapes: dict) -> dict:
    """(image, draw, part) -> (world triangles, shade, cull) of every figure: one batch per shape and kind."""
    groups: dict = {}
    for i, image in enumerate(task.images):
        for d, (_camera, parts) in enumerate(image):
            for p, part in enumerate(parts):
                if part[1] >= 0:
                    groups.setdefault((part[0], part[2], part[4] >= 0), []).append(((i, d, p), part))
    out = {}
    for (key, links, morphing), members in groups.items():
        table = shapes[key]
        X = _matrices(task.matrices, [part[1] for _, part in members], links)
        local = None
        if morphing:
            local = np.broadcast_to(table.triangles, (len(members), *table.triangles.shape)).copy()
            for n, (_, part) in enumerate(members):
                rows, moved = task.morphs[part[4]]
                local[n, rows] = moved
        tris = world_triangles(table, X, local)
        unculled = np.zeros(len(table.closed), dtype=bool)
        for n, (where, part) in enumerate(members):
            out[where] = (tris[n], table.shade, unculled if part[3] else table.closed)
    return out


def _matrices(matrices: np.ndarray, starts: list, links: int) -> np.ndarray:
    """The (n, links, 4, 4) link matrices of parts starting at ``starts``: a view when they lie end to end."""
    first = starts[0]
    if starts == list(range(first, first + links * len(starts), links)):
        return matrices[first : first + links * len(starts)].reshape(len(starts), links, 4, 4)
    return matrices[np.asarray(starts)[:, None] + np.arange(links)]
