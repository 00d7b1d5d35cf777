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

A figure that came from a BVH file (its links carry a
:class:`~liganimate.runtime.figure.tree.LinkSource`, from the library's name
table) is written back as it came: each link under its source name with its
source channels (rotations converted to that order exactly, constant
position channels holding the offset), its End Site, and without the
importer's empty ``ORIGIN``: the source's ROOT is the ROOT again.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field

import numpy as np

from liganimate.runtime.errors import LigError
from liganimate.runtime.figure.kinematics import joint_transforms, matrix_from_euler_zyx
from liganimate.runtime.values import Graphical

from ._names import own_names
from ._numbers import format_rows
from ._rotations import decompose_trs, euler_from_matrix

__all__ = ["bvh_files", "bvh_text"]

# Enough digits that angles survive a round trip to well within 1e-6 degrees.
DECIMALS = 8
_ROTATIONS = ("Xrotation", "Yrotation", "Zrotation")
_POSITIONS = ("Xposition", "Yposition", "Zposition")


def _joint_names(fig) -> list:
    """A BVH name per link: its source name, else its own name where unique, else with its joint id."""
    return own_names(fig, lambda name: re.sub(r"[^A-Za-z0-9_]", "_", name.upper()), "_")


def _end_site(fig, i: int, far: np.ndarray) -> np.ndarray:
    """A leaf's bone tip: twice the way from its joint to the centre of its shape's bounding box."""
    g = fig.links[i].shape
    if not isinstance(g, Graphical) or len(g) == 0:
        return np.zeros(3)
    pts = g.triangles.reshape(-1, 3) * fig.links[i].scale
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2.0
    return 2.0 * (centre - far)


@dataclass
class _Node:
    """One BVH joint: the link it is, its parent node, OFFSET, channels and how each gets its values."""

    link: int
    parent: int  # index into the node list; -1 for the ROOT
    offset: np.ndarray
    channels: tuple
    joint: int | None = None  # index of the figure joint that turns it (None: the ROOT's placement)
    reversed: bool = False
    end: np.ndarray | None = None
    children: list = field(default_factory=list)


def _placement_factor(model, scene_id):
    """The model's constant uniform placement scale, refusing anything a rigid skeleton cannot carry."""
    t, R, s, ok = decompose_trs(model.placements)
    factor = s[0, 0]
    if not ok.all() or not np.allclose(s, factor, rtol=1e-12, atol=0) or factor <= 0:
        where = f" in scene {scene_id}" if scene_id is not None else ""
        raise LigError(
            f"model {model.name}{where} is scaled, mirrored or sheared by its placement, which a BVH skeleton "
            "cannot carry.",
            "export to glTF, which can, or scale the model with <SCALE MODEL r> instead of <SCALE r>",
        )
    return float(factor)


def _edges(fig, factor: float) -> tuple:
    """Children of each link as walked from the main link, and (joint, near, far, reversed) of each non-main link."""
    loc1, loc2 = fig.locations
    children: dict = {i: [] for i in range(fig.n_links)}
    edge_of: dict = {}
    for level in fig.traversal:
        for k, p, c, r in zip(level.joints, level.parents, level.children, level.reversed):
            children[int(p)].append(int(c))
            near, far = (loc2[k], loc1[k]) if r else (loc1[k], loc2[k])
            edge_of[int(c)] = (int(k), near * factor, far * factor, bool(r))
    return children, edge_of


def _folds_origin(fig, children: dict, edge_of: dict) -> bool:
    """Whether the main link is the importer's empty ORIGIN, which the source did not have."""
    main = fig.main
    if fig.links[main].source is not None or not any(l.source is not None for l in fig.links):
        return False
    kids = children[main]
    if len(kids) != 1 or fig.links[kids[0]].source is None or edge_of[kids[0]][3]:
        return False
    shape = fig.links[main].shape
    return not (isinstance(shape, Graphical) and len(shape) > 0)


def _own_channels(source, is_root: bool, rev: bool, slide: bool = False) -> tuple:
    """A node's channels: the source's, where they can be written exactly, else the joint convention's.

    A slide (prismatic joint) moves its node: position channels, and no rotation.
    """
    if slide and not is_root:
        return _POSITIONS
    if source is not None and source.channels:
        rot = [c for c in source.channels if c in _ROTATIONS]
        pos = [c for c in source.channels if c in _POSITIONS]
        if (len(rot) == 3 or _zyx_subsequence(rot)) and (not is_root or len(pos) == 3):
            return tuple(source.channels)
    if is_root:
        return _POSITIONS + ("Zrotation", "Yrotation", "Xrotation")
    return ("Xrotation", "Yrotation", "Zrotation") if rev else ("Zrotation", "Yrotation", "Xrotation")


def _zyx_subsequence(rot: list) -> bool:
    it = iter("ZYX")
    return bool(rot) and all(c[0] in it for c in rot)


def _skeleton(fig, factor: float) -> list:
    """The BVH joints of a figure, depth first from its ROOT."""
    children, edge_of = _edges(fig, factor)
    fold = _folds_origin(fig, children, edge_of)
    root = children[fig.main][0] if fold else fig.main
    nodes: list = []

    def visit(i: int, parent: int, far_parent: np.ndarray) -> None:
        link = fig.links[i]
        if parent < 0:
            k, rev = (edge_of[i][0], False) if fold else (None, False)
            offset, far = np.zeros(3), (edge_of[i][2] if fold else np.zeros(3))
        else:
            k, near, far, rev = edge_of[i]
            offset = near - far_parent
        slide = k is not None and bool(fig.joints[k].slide)
        node = _Node(i, parent, offset, _own_channels(link.source, parent < 0, rev, slide), k, rev)
        me = len(nodes)
        nodes.append(node)
        if parent >= 0:
            nodes[parent].children.append(me)
        for c in children[i]:
            visit(c, me, far)
        if not children[i]:
            if link.source is not None and link.source.end is not None:
                node.end = np.asarray(link.source.end, dtype=np.float64) * factor
            else:
                node.end = _end_site(fig, i, far / factor) * factor

    visit(root, -1, np.zeros(3))
    return nodes


def _hierarchy(nodes: list, names: list) -> list:
    """The HIERARCHY section's lines."""
    lines = ["HIERARCHY"]

    def visit(n: int, depth: int) -> None:
        node = nodes[n]
        pad = "  " * depth
        lines.append(f"{pad}{'ROOT' if node.parent < 0 else 'JOINT'} {names[node.link]}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET {_num(node.offset[0])} {_num(node.offset[1])} {_num(node.offset[2])}")
        lines.append(f"{pad}  CHANNELS {len(node.channels)} {' '.join(node.channels)}")
        for c in node.children:
            visit(c, depth + 1)
        if node.end is not None:
            e = node.end
            lines.extend([f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET {_num(e[0])} {_num(e[1])} {_num(e[2])}"])
            lines.append(f"{pad}  }}")
        lines.append(f"{pad}}}")

    visit(0, 0)
    return lines


def _node_frames(model, node: _Node, factor: float, fig) -> tuple:
    """(position (T, 3), rotation (T, 3, 3)) of a node relative to its parent node, per tick."""
    if node.parent >= 0:
        assert node.joint is not None  # every node below the ROOT hangs from a joint
        Rj, shift = _joint_motion(fig, model.angles, node.joint)
        if node.reversed:
            Rt = np.swapaxes(Rj, -1, -2)
            return node.offset - np.einsum("tij,tj->ti", Rt, shift) * factor, Rt
        return node.offset + shift * factor, Rj
    t, R, _, _ = decompose_trs(model.placements)
    if node.joint is None:
        return t, R
    # The folded ORIGIN: placement, then the joint at its location on ORIGIN.
    loc1, loc2 = fig.locations
    Rj, shift = _joint_motion(fig, model.angles, node.joint)
    pos = (
        t
        + np.einsum("tij,tj->ti", R, (loc1[node.joint] + shift) * factor)
        - np.einsum("tij,j->ti", R @ Rj, loc2[node.joint] * factor)
    )
    return pos, R @ Rj


def _joint_motion(fig, angles: np.ndarray, k: int) -> tuple:
    """Joint ``k``'s rotation (T, 3, 3) and a slide's shift (T, 3) per tick (AXIS and SLIDE included)."""
    a = angles[:, k]
    joint = fig.joints[k]
    if joint.axes is None and not joint.slide:
        return matrix_from_euler_zyx(a), np.zeros((len(a), 3))
    X = joint_transforms(fig, angles)[:, k]
    R = X[:, :3, :3]
    shift = X[:, :3, 3] - joint.loc1 + np.einsum("tij,j->ti", R, joint.loc2)
    if not joint.slide:
        shift = np.zeros_like(shift)
    return R, shift


def _node_columns(model, node: _Node, factor: float, fig) -> np.ndarray:
    """The node's channel values, (T, len(channels)), in its channels' order."""
    pos, R = _node_frames(model, node, factor, fig)
    rot = [c[0] for c in node.channels if c in _ROTATIONS]
    plain = node.joint is not None and fig.joints[node.joint].axes is None
    if node.parent >= 0 and plain and not node.reversed and rot and _zyx_subsequence(rot):
        # The joint convention's own axes: the very angles drawn, no conversion.
        a = model.angles[:, node.joint]
        angles = {axis: a[:, "XYZ".index(axis)] for axis in rot}
    elif node.parent >= 0 and plain and node.reversed and "".join(rot) == "XYZ":
        a = -model.angles[:, node.joint]
        angles = {axis: a[:, "XYZ".index(axis)] for axis in rot}
    else:
        order = "".join(rot) if len(rot) == 3 else "ZYX"
        e = np.unwrap(euler_from_matrix(order, R), period=360.0, axis=0)
        angles = {axis: e[:, n] for n, axis in enumerate(order)}
    cols = [pos[:, "XYZ".index(c[0])] if c in _POSITIONS else angles[c[0]] for c in node.channels]
    return np.column_stack(cols) if cols else np.zeros((len(model.ticks), 0))


def bvh_text(model, fps: float, scene_id=None) -> bytes:
    """The BVH file of one drawn model.

    Parameters
    ----------
    model : ModelTake
        Frames are the ticks at which the model is drawn.
    fps : float
        Frames per second (the file's ``Frame Time`` is ``1 / fps``).
    scene_id : int, optional
        For messages.

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
    factor = _placement_factor(model, scene_id)
    nodes = _skeleton(fig, factor)
    lines = _hierarchy(nodes, _joint_names(fig))
    T = len(model.ticks)
    lines += ["MOTION", f"Frames: {T}", f"Frame Time: {_num(1.0 / fps)}"]
    data = np.concatenate([_node_columns(model, n, factor, fig) for n in nodes], axis=1)
    data += 0.0  # no -0.0
    head = ("\n".join(lines) + "\n").encode("utf-8")
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


def bvh_notes(scenes) -> tuple[str, ...]:
    """What BVH cannot carry and the files leave out: a motion's SCALE LINK and SHAPE LINK tracks, per model.

    BVH has joint channels only (offsets, positions, rotations); a segment
    that changes size or shape (morphing segments) has nothing to say it in.
    """
    notes = []
    for take in scenes:
        for m in take.models:
            morphed = [motion.morphs for _rows, _fig, motion, _frames in m.sources if motion.morphs is not None]
            if not morphed:
                continue
            kinds = sorted({k[0] for morphs in morphed for k in morphs.channels()})
            links = sorted({k[1] for morphs in morphed for k in morphs.channels()})
            tracks = " and ".join(f"{kind} LINK" for kind in kinds)
            notes.append(
                f"model {m.name} in scene {take.id} morphs its segments ({tracks} tracks of "
                f"{', '.join(links)}), which BVH cannot carry: the file has its joints' motion only, "
                "every segment at its own size and shape (export glTF to keep them)"
            )
    return tuple(notes)
