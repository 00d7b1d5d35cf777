"""BVH export: one drawn model of one scene as a Biovision hierarchy and its frames.

The skeleton is the figure's joint tree walked from its current main link,
as the renderer walks it.  The ROOT is the main link, placed by the model's
host placement (position channels, and rotation channels in the joint
convention's order ``Zrotation Yrotation Xrotation``).  Each JOINT is one
joint of the figure, its frame at the joint's location: its OFFSET is the
joint's location on the link it hangs from, less that link's own joint
location.  A joint walked forwards has channels ``Zrotation Yrotation
Xrotation`` holding ``(az, ay, ax)``: BVH composes channels in the order
listed, so that is ``Rz Ry Rx``, the joint convention itself, with the very
angles drawn.  A joint walked backwards (FIGURE ... MAIN) turns by the
inverse, ``Rx(-ax) Ry(-ay) Rz(-az)``, written as ``Xrotation Yrotation
Zrotation`` with negated angles: exact again, no conversion.
"""

from __future__ import annotations

import os
import re

import numpy as np

from liganimate.runtime.errors import LigError
from liganimate.runtime.values import Graphical

from ._numbers import format_rows
from ._rotations import decompose_trs, euler_zyx_from_matrix

__all__ = ["bvh_files", "bvh_text"]

# Enough digits that angles survive a round trip to well within 1e-6 degrees.
DECIMALS = 8


def _joint_names(fig) -> list:
    """A BVH name per link: its own name where unique, else with its joint id; unnamed links by joint."""
    counts: dict = {}
    for l in fig.links:
        if l.name is not None:
            counts[l.name.upper()] = counts.get(l.name.upper(), 0) + 1
    names = []
    for i, l in enumerate(fig.links):
        up = fig.parent_joint_of(i)
        if l.name is None or l.name.startswith("<"):
            base = "SEGMENT"
        else:
            base = re.sub(r"[^A-Za-z0-9_]", "_", l.name.upper())
        if l.name is None or counts.get(l.name.upper(), 0) > 1 or l.name.startswith("<"):
            base = f"{base}_{up.id}" if up is not None else f"{base}_ROOT"
        names.append(base)
    return names


def _end_site(fig, i: int, far: np.ndarray) -> np.ndarray:
    """A leaf's bone tip: twice the way from its joint to the centre of its shape's bounding box."""
    g = fig.links[i].shape
    if not isinstance(g, Graphical) or len(g) == 0:
        return np.zeros(3)
    pts = g.triangles.reshape(-1, 3) * fig.links[i].scale
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2.0
    return 2.0 * (centre - far)


def bvh_text(model, fps: float, scene_id=None) -> bytes:
    """The BVH file of one drawn model.

    Parameters
    ----------
    model : ModelTake
        Frames are the ticks at which the model is drawn.
    fps : float
        Frames per second (the file's ``Frame Time`` is ``1 / fps``).

    Returns
    -------
    bytes

    Raises
    ------
    LigError
        If the model's placement scales it (other than by one constant,
        positive, uniform factor, which is folded into the offsets) or
        mirrors it: BVH skeletons are rigid.
    """
    fig = model.figure
    t, R, s, ok = decompose_trs(model.placements)
    factor = s[0, 0]
    if not ok.all() or not np.allclose(s, factor, rtol=1e-12, atol=0) or factor <= 0:
        where = f" in scene {scene_id}" if scene_id is not None else ""
        raise LigError(
            f"model {model.name}{where} is scaled, mirrored or sheared by its placement, which a BVH skeleton "
            "cannot carry.",
            "export to glTF, which can, or scale the model with <SCALE MODEL r> instead of <SCALE r>",
        )
    loc1, loc2 = fig.locations
    names = _joint_names(fig)
    children: dict = {i: [] for i in range(fig.n_links)}
    edge_of: dict = {}
    for level in fig.traversal:
        for k, p, c, r in zip(level.joints, level.parents, level.children, level.reversed):
            children[int(p)].append(int(c))
            near, far = (loc2[k], loc1[k]) if r else (loc1[k], loc2[k])
            edge_of[int(c)] = (int(k), near * factor, far * factor, bool(r))

    lines = ["HIERARCHY"]
    # Each channel, in the file's order, as (column, sign) of the (T, C) table
    # [position (3), root angles (3), joint angles (3 per joint)] built below.
    columns: list[tuple[int, float]] = []

    def visit(i: int, depth: int) -> None:
        pad = "  " * depth
        if i == fig.main:
            lines.append(f"ROOT {names[i]}")
            lines.append("{")
            lines.append("  OFFSET 0.0 0.0 0.0")
            lines.append("  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation")
            columns.extend([(0, 1.0), (1, 1.0), (2, 1.0), (3 + 2, 1.0), (3 + 1, 1.0), (3 + 0, 1.0)])
            far_here = np.zeros(3)
        else:
            k, near, far, rev = edge_of[i]
            parent_far = np.zeros(3) if edge_of.get(_parent[i]) is None else edge_of[_parent[i]][2]
            off = near - parent_far
            lines.append(f"{pad}JOINT {names[i]}")
            lines.append(f"{pad}{{")
            lines.append(f"{pad}  OFFSET {_num(off[0])} {_num(off[1])} {_num(off[2])}")
            if rev:
                lines.append(f"{pad}  CHANNELS 3 Xrotation Yrotation Zrotation")
                columns.extend([(6 + 3 * k + axis, -1.0) for axis in (0, 1, 2)])
            else:
                lines.append(f"{pad}  CHANNELS 3 Zrotation Yrotation Xrotation")
                columns.extend([(6 + 3 * k + axis, 1.0) for axis in (2, 1, 0)])
            far_here = far
        if children[i]:
            for c in children[i]:
                visit(c, depth + 1)
        else:
            tip = _end_site(fig, i, far_here / factor) * factor
            lines.append(f"{pad}  End Site")
            lines.append(f"{pad}  {{")
            lines.append(f"{pad}    OFFSET {_num(tip[0])} {_num(tip[1])} {_num(tip[2])}")
            lines.append(f"{pad}  }}")
        lines.append(f"{pad}}}")

    _parent = {c: p for p, cs in children.items() for c in cs}
    visit(fig.main, 0)
    T = len(model.ticks)
    lines += ["MOTION", f"Frames: {T}", f"Frame Time: {_num(1.0 / fps)}"]
    # Every channel is one column of a (T, C) table gathered with indices.
    root = euler_zyx_from_matrix(R)  # (T, 3)
    angles = model.angles.reshape(T, -1)
    table = np.concatenate([t, root, angles], axis=1)
    J3 = angles.shape[1]
    idx = np.array([c for c, _ in columns], dtype=np.int64)
    sign = np.array([sg for _, sg in columns], dtype=np.float64)
    assert table.shape[1] == 6 + J3
    data = table[:, idx] * sign
    data += 0.0  # no -0.0
    head = ("\n".join(lines) + "\n").encode("ascii")
    return head + format_rows(data, DECIMALS)


def _num(x: float) -> str:
    x = float(x) + 0.0
    return repr(x)


def bvh_files(scenes, path: str, fps: float) -> list:
    """One BVH file per drawn model of every scene: ``[(path, bytes)]``.

    The only model of the only scene goes to ``path`` itself; with several,
    each goes to ``<stem>-scene<ID>-<MODEL>.bvh`` beside it (a model whose
    structure changes within a scene gets ``-2``, ``-3``... for its later
    structures).

    Raises
    ------
    LigError
        When no scene draws any model, or a model cannot be written.
    """
    models = [(take.id, m) for take in scenes for m in take.models]
    if not models:
        raise LigError(
            "the program draws no animated model, so there is nothing to write as BVH.",
            "a model is drawn while an ANIMATE covers it in a shot scene",
        )
    if len(models) == 1:
        return [(path, bvh_text(models[0][1], fps, models[0][0]))]
    stem, ext = os.path.splitext(path)
    out = []
    seen: dict = {}
    for scene_id, m in models:
        key = (scene_id, m.name)
        seen[key] = seen.get(key, 0) + 1
        suffix = f"-{seen[key]}" if seen[key] > 1 else ""
        out.append((f"{stem}-scene{scene_id}-{m.name}{suffix}{ext or '.bvh'}", bvh_text(m, fps, scene_id)))
    return out
