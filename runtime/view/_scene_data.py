"""A program's shot scenes as compact arrays for the browser viewer.

What the page receives is exactly what the renderer draws: each drawn
model's segment matrices per tick (``placement @ pose @ diag(s, s, s, 1)``,
the same matrices ``--poses`` writes, see ``docs/poses.md``), its triangles
in segment coordinates with their grey levels, the background objects in
world coordinates, and the camera of every tick.  The page multiplies
vertices by those matrices and nothing else: no joint angle is ever turned
into a transform in JavaScript.

Every array goes into one binary blob (little-endian, each array 4-byte
aligned) described by a JSON manifest of ``{"o": offset, "n": count, "t":
type}`` references.  Matrices are kept as their top three rows (12 floats)
in float32: the bottom row is always ``0 0 0 1``.
"""

from __future__ import annotations

import numpy as np

from liganimate.runtime.figure.pose import mesh_table, morphed, static_triangles, world_transforms, world_triangles
from liganimate.runtime.render.framing import framing_view
from liganimate.runtime.values import Graphical, rgb_levels

__all__ = ["Blob", "scene_manifest"]

_TYPES = {
    np.dtype(np.float32): "f32",
    np.dtype(np.uint8): "u8",
    np.dtype(np.uint16): "u16",
    np.dtype(np.int32): "i32",
    np.dtype(np.uint32): "u32",
}


class Blob:
    """Arrays laid end to end in one little-endian byte string, each 4-byte aligned."""

    def __init__(self):
        self._parts: list = []
        self._size = 0

    def add(self, array, dtype) -> dict:
        """Append ``array`` converted to ``dtype``; return its manifest reference.

        Parameters
        ----------
        array : array_like
            Any shape; stored flattened in C order.
        dtype : numpy dtype
            One of float32, uint8, uint16, int32, uint32.

        Returns
        -------
        dict
            ``{"o": byte offset, "n": element count, "t": "f32" | "u8" | ...}``.
        """
        a = np.ascontiguousarray(array, dtype=np.dtype(dtype).newbyteorder("<")).reshape(-1)
        ref = {"o": self._size, "n": int(a.size), "t": _TYPES[np.dtype(dtype)]}
        data = a.tobytes()
        self._parts.append(data)
        self._size += len(data)
        pad = -self._size % 4
        if pad:
            self._parts.append(b"\0" * pad)
            self._size += pad
        return ref

    def __len__(self) -> int:
        return self._size

    def tobytes(self) -> bytes:
        """The whole blob."""
        return b"".join(self._parts)


def _link_boxes(table, n_links: int) -> np.ndarray:
    """Corners of each link's bounding box in its own coordinates, shape (n_links, 8, 3); zeros if empty."""
    corners = np.zeros((n_links, 8, 3))
    if len(table.triangles) == 0:
        return corners
    pts = table.triangles.reshape(-1, 3)
    owner = np.repeat(table.link, 3)
    lo = np.full((n_links, 3), np.inf)
    hi = np.full((n_links, 3), -np.inf)
    np.minimum.at(lo, owner, pts)
    np.maximum.at(hi, owner, pts)
    empty = ~np.isfinite(lo[:, 0])
    lo[empty] = 0.0
    hi[empty] = 0.0
    sel = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)], dtype=bool)
    return np.where(sel[None], hi[:, None, :], lo[:, None, :])


def _morphs(take, X: np.ndarray, table) -> tuple[np.ndarray, np.ndarray | None]:
    """The take's SCALE tracks folded into ``X``, and its SHAPE tracks' triangles per tick (None without)."""
    local = None
    for rows, fig, motion, frames in take.sources:
        if motion.morphs is None:
            continue
        X[rows], shaped = morphed(fig, motion, frames, X[rows])
        if shaped is not None:
            if local is None:
                local = np.broadcast_to(table.triangles, (len(X), *table.triangles.shape)).copy()
            local[rows] = shaped
    return X, local


def _model_entry(take, blob: Blob, extent: list) -> dict:
    fig = take.figure
    L = fig.n_links
    table = mesh_table(fig)
    X, local = _morphs(take, world_transforms(fig, take.angles, take.placements), table)  # (T, L, 4, 4)
    boxes = _link_boxes(table, L)  # (L, 8, 3)
    world = np.einsum("tlij,lkj->tlki", X[..., :3, :3], boxes) + X[:, :, None, :3, 3]
    extent.append(world.reshape(-1, 3))
    joints = []
    joint_of_link = []
    for i in range(L):
        parent = fig.parent_joint_of(i)
        joint_of_link.append(-1 if parent is None else fig.joint_index(parent.id))
    for j in fig.joints:
        joints.append(
            {
                "id": int(j.id),
                "ext": np.asarray(j.extremes, dtype=np.float64).round(9).tolist(),
                "slide": bool(j.slide),  # its values are a displacement, not degrees
            }
        )
    morph = None
    if local is not None:
        moving = np.flatnonzero((local != table.triangles[None]).any(axis=(0, 2, 3)))
        # (the boxes above are the links' own: a morphed shape that reaches further is still framed by them)
        extent.append(world_triangles(table, X, local).reshape(-1, 3))
        morph = {
            "rows": blob.add(moving, np.uint32),
            "pos": blob.add(local[:, moving].reshape(-1), np.float32),
        }
    return {
        "morph": morph,
        "name": take.name,
        "links": [link.name if link.name is not None else "<anonymous>" for link in fig.links],
        "jointOfLink": joint_of_link,
        "joints": joints,
        "mesh": {
            "pos": blob.add(table.triangles.reshape(-1), np.float32),
            "link": blob.add(table.link, np.uint16 if L < 65536 else np.uint32),
            "rgb": blob.add(rgb_levels(table.shade), np.uint8),
        },
        "ticks": blob.add(take.ticks, np.int32),
        "matrices": blob.add(X[:, :, :3, :], np.float32),
        "angles": blob.add(take.angles, np.float32),
    }


def _background_entry(obj, ticks, blob: Blob, extent: list):
    if isinstance(obj, Graphical):
        if len(obj) == 0:
            return None
        tris, shade = obj.triangles, obj.shades()
    else:
        tris, shade, _ = static_triangles(obj)
        if len(tris) == 0:
            return None
    extent.append(np.asarray(tris).reshape(-1, 3))
    return {
        "pos": blob.add(np.asarray(tris).reshape(-1), np.float32),
        "rgb": blob.add(rgb_levels(shade), np.uint8),
        "ticks": blob.add(ticks, np.int32),
    }


def scene_manifest(scenes, blob: Blob) -> list:
    """Describe shot scenes for the viewer, putting their arrays into ``blob``.

    Parameters
    ----------
    scenes : list of SceneTake
        From :func:`liganimate.runtime.exchange.collect`.
    blob : Blob
        Receives every array.

    Returns
    -------
    list of dict
        One JSON-ready entry per scene: ``id``, ``length``, ``sameframe``,
        ``cameras`` (per tick: eye x, y, z and VIEW WIDTH, float32),
        ``bounds`` (centre x, y, z and radius of everything drawn),
        ``framing`` (for a scene that sets no VIEW: the camera
        ``liganimate run`` uses for it in the modern look at 640x480,
        ``eye``, ``target``, ``width`` and ``k``, the view width over the
        distance, from the box the program's check measured; else None),
        ``models`` and ``backgrounds``.
    """
    out = []
    for take in scenes:
        extent: list = [np.zeros((1, 3))]
        cams = np.array([[*p, w] for p, w in take.cameras], dtype=np.float64).reshape(-1, 4)
        models = [_model_entry(m, blob, extent) for m in take.models]
        backgrounds = [b for b in (_background_entry(o, t, blob, extent) for o, t in take.backgrounds) if b]
        pts = np.concatenate(extent)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        framing = None
        if take.framing is not None:
            # The camera `liganimate run` uses for this scene at the viewer's 4:3 shape.
            eye, width, target = framing_view(take.framing, (640, 480))
            distance = float(np.linalg.norm(np.subtract(eye, target)))
            framing = {"eye": list(eye), "target": list(target), "k": width / distance, "width": width}
        centre = (lo + hi) / 2
        radius = float(np.linalg.norm(hi - lo) / 2) or 1.0
        out.append(
            {
                "id": int(take.id),
                "length": int(take.length),
                "sameframe": int(take.sameframe),
                "cameras": blob.add(cams, np.float32),
                "bounds": [float(c) for c in centre] + [radius],
                "framing": framing,
                "models": models,
                "backgrounds": backgrounds,
            }
        )
    return out
