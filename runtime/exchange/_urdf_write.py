"""URDF export: every model a program's scenes draw, as a URDF robot description.

The mapping (``docs/exchange.md``, "URDF export"):

* every segment is a URDF link, named by its name table's URDF name where
  it has one (a model imported from URDF gets its names back), else by its
  LIG name (``LINK<k>`` for an anonymous one), made unique;
* a LIG joint turns ``F Rz(az) Ry(ay) Rx(ax) F^T`` (see
  docs/semantics-figure.md), which is ``Rot(F e_z, az) Rot(F e_y, ay)
  Rot(F e_x, ax)``: each axis whose extremes let it move is one URDF joint
  (``revolute``, ``continuous`` for a free axis, ``prismatic`` for a slide),
  Z, then Y, then X, joined through empty links named ``<child>__<axis>``;
  an axis locked at a value other than zero is a ``fixed`` joint turned by
  it; a joint with no moving axis is one ``fixed`` joint.  The first URDF
  joint of a LIG joint carries its name (the name table's, else
  ``joint<id>``), the others ``<name>__y`` and so on;
* a link's URDF frame is its LIG frame turned by the name table's ``RPY``
  (identity for a model made in LIG), so an imported robot's frames,
  origins and axes come back as they were;
* each segment's shape is a binary STL mesh beside the URDF
  (``<stem>_meshes/<link>.stl``), in the segment's own coordinates and
  scale, with a grey material.

The model's current main link, placement and motions are not part of a
URDF: the description is of the model as built, rooted at its original main
link (a joint of a submodel attached by a re-rooted main link is written from
its secondary to its primary, as the inverse of its turn).  Lengths are the
model's units; LIG has no effort or velocity limits (written as 0).
"""

from __future__ import annotations

import math
import os
import re
import struct
from xml.sax.saxutils import quoteattr

import numpy as np

from liganimate.runtime.errors import LigError
from liganimate.runtime.figure import tree as F
from liganimate.runtime.values import Graphical

from ._urdf_lig import matrix_rpy
from ._urdf_read import rpy_matrix

__all__ = ["joint_columns", "urdf_files", "urdf_text"]

_AXES = ("z", "y", "x")  # the order the chain turns: Rz Ry Rx read left to right


def _fmt(x: float) -> str:
    return repr(float(x) + 0.0)


def _vec(v) -> str:
    return " ".join(_fmt(x) for x in v)


def _safe(name: str) -> str:
    """A URDF name made of the name's printable characters (XML attributes are quoted separately)."""
    return re.sub(r"[\x00-\x1f\x7f]", "_", name) or "link"


def link_names(fig: F.Figure) -> list:
    """Each link's URDF name: its source's, else its LIG name, unique."""
    taken: set = set()
    out = []
    for k, link in enumerate(fig.links):
        base = link.source.name if link.source is not None else (link.name or f"LINK{k}")
        name, n = _safe(base), 1
        while name in taken:
            n += 1
            name = f"{_safe(base)}_{n}"
        taken.add(name)
        out.append(name)
    return out


def _frame(link: F.Link) -> np.ndarray:
    """The URDF frame's turn from the LIG link's (the name table's RPY)."""
    if link.source is not None and link.source.rpy is not None:
        return rpy_matrix(link.source.rpy)
    return np.eye(3)


def _pieces(joint: F.Joint):
    """A LIG joint as a list of ``(kind, axis index, vector, value)`` in the order they apply.

    ``kind`` is ``move`` (one moving axis along/about ``vector``) or
    ``turn`` (a fixed turn by ``value`` degrees about ``vector``).
    """
    Fm = np.eye(3) if joint.axes is None else joint.axes
    out = []
    for axis in (2, 1, 0):
        lo, hi = joint.extremes[axis]
        vector = Fm[:, axis]
        if hi > lo:
            out.append(("move", axis, vector, None))
        elif lo != 0.0:
            out.append(("turn" if not joint.slide else "shift", axis, vector, lo))
    return out


def joint_columns(fig: F.Figure) -> list:
    """The URDF joints that move, in the figure's joint order: ``(name, joint index, axis, slide)``.

    The names are those :func:`urdf_text` gives; a trajectory's columns use them.
    """
    out = []
    for k, joint in enumerate(fig.joints):
        base = _joint_name(fig, joint)
        first = True
        for kind, axis, _, _ in _hung_pieces(fig, k):
            if kind != "move":
                continue
            out.append((base if first else f"{base}__{'xyz'[axis]}", k, axis, joint.slide))
            first = False
    return out


def _hung_pieces(fig: F.Figure, k: int) -> list:
    """:func:`_pieces` of joint ``k`` in the order URDF hangs them, parent to child.

    A joint of a submodel attached by a re-rooted main link is walked from
    its secondary (``Figure.inverted``): its transform is the inverse,
    ``F Rx(-ax) Ry(-ay) Rz(-az) F^T``, so the pieces come in reverse order
    about (along) the opposite vectors, each still moved by the joint's own
    value, within the same limits.
    """
    pieces = _pieces(fig.joints[k])
    if not fig.inverted[k]:
        return pieces
    return [(kind, axis, -vector, value) for kind, axis, vector, value in reversed(pieces)]


def _joint_name(fig: F.Figure, joint: F.Joint) -> str:
    link = fig.links[joint.secondary]
    if link.source is not None and link.source.joint is not None:
        return _safe(link.source.joint)
    return f"joint{joint.id}"


def _origin(T: np.ndarray) -> str:
    rpy = matrix_rpy(T[:3, :3])
    return f'<origin xyz="{_vec(T[:3, 3])}" rpy="{_vec(rpy)}"/>'


def _rot(axis: np.ndarray, degrees: float) -> np.ndarray:
    a = np.asarray(axis, dtype=np.float64)
    t = math.radians(degrees)
    K = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + math.sin(t) * K + (1.0 - math.cos(t)) * (K @ K)


def _joint_xml(name, kind, parent, child, origin, axis=None, limits=None, mimic=None) -> list:
    out = [f"  <joint name={quoteattr(name)} type={quoteattr(kind)}>"]
    out.append(f"    <parent link={quoteattr(parent)}/>")
    out.append(f"    <child link={quoteattr(child)}/>")
    out.append("    " + _origin(origin))
    if axis is not None:
        out.append(f'    <axis xyz="{_vec(axis)}"/>')
    if limits is not None:
        out.append(f'    <limit lower="{_fmt(limits[0])}" upper="{_fmt(limits[1])}" effort="0" velocity="0"/>')
    if mimic is not None:
        out.append(f'    <mimic joint={quoteattr(mimic[0])} multiplier="{_fmt(mimic[1])}" offset="{_fmt(mimic[2])}"/>')
    out.append("  </joint>")
    return out


def _chain(fig: F.Figure, k: int, names: list) -> list:
    """The URDF joints (and empty links) of LIG joint ``k``."""
    joint = fig.joints[k]
    # URDF hangs the child from the parent: for an inverted joint (see
    # _hung_pieces) the parent is the defined secondary, and L1 and L2 swap.
    up, down = fig.parent_of(joint), fig.child_of(joint)
    near, far = (joint.loc1, joint.loc2) if up == joint.primary else (joint.loc2, joint.loc1)
    parent, child = names[up], names[down]
    Pp, Pc = _frame(fig.links[up]), _frame(fig.links[down])
    base = _joint_name(fig, joint)
    pieces = _hung_pieces(fig, k)
    # The chain applies, in the parent's URDF frame: Pp^T, Trans(L1), the pieces, Trans(-L2), Pc.
    start = np.eye(4)
    start[:3, :3] = Pp.T
    start[:3, 3] = Pp.T @ near
    tail: np.ndarray | None = np.eye(4)
    assert tail is not None
    tail[:3, :3] = Pc
    tail[:3, 3] = -far
    moving = [p for p in pieces if p[0] == "move"]
    if not far.any():
        # Fold Pc back through the pieces (Rot(a) Pc = Pc Rot(Pc^T a)): no fixed joint at the end.
        start[:3, :3] = start[:3, :3] @ Pc
        pieces = [(kind, axis, Pc.T @ v, value) for kind, axis, v, value in pieces]
        tail = None
    out: list = []
    links: list = []
    at = parent
    origin = start
    first = True
    for n, (kind, axis, vector, value) in enumerate(pieces):
        last = n == len(pieces) - 1 and tail is None
        target = child if last else f"{child}__{'xyz'[axis]}"
        if kind == "move":
            name = base if first else f"{base}__{'xyz'[axis]}"
            first = False
            lo, hi = joint.extremes[axis]
            if joint.slide:
                urdf_kind, limits = "prismatic", (lo * joint.slide_scale, hi * joint.slide_scale)
                if joint.slide_scale < 0:
                    limits = (limits[1], limits[0])
            elif hi - lo >= 360.0:
                urdf_kind, limits = "continuous", None
            else:
                urdf_kind, limits = "revolute", (math.radians(lo), math.radians(hi))
            source = fig.links[joint.secondary].source
            mimic = source.mimic if source is not None and name == base else None
            out += _joint_xml(name, urdf_kind, at, target, origin, vector, limits, mimic)
        else:
            step = np.eye(4)
            if kind == "turn":
                step[:3, :3] = _rot(vector, value)
            else:
                step[:3, 3] = vector * value * joint.slide_scale
            out += _joint_xml(f"{base}__fixed_{'xyz'[axis]}", "fixed", at, target, origin @ step)
        if not last:
            links.append(target)
        at = target
        origin = np.eye(4)
    if tail is not None or not pieces:
        end = origin @ (tail if tail is not None else np.eye(4))
        name = base if first and not moving else f"{base}__end"
        out += _joint_xml(name, "fixed", at, child, end)
    return [f"  <link name={quoteattr(l)}/>" for l in links] + out


def _stl(shape: Graphical, scale: float) -> bytes:
    tri = np.asarray(shape.triangles, dtype=np.float64) * scale
    if scale < 0:
        tri = tri[:, ::-1]  # a mirror turns the winding
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    rec = np.zeros(len(tri), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["n"] = normals
    rec["v"] = tri
    return b"liganimate URDF export".ljust(80, b" ") + struct.pack("<I", len(tri)) + rec.tobytes()


def urdf_text(fig: F.Figure, robot: str, mesh_dir: str, mesh_ref: str) -> tuple[bytes, list]:
    """One figure as URDF: ``(text, [(mesh path, bytes)])``.

    Parameters
    ----------
    fig : Figure
    robot : str
        The robot's name.
    mesh_dir : str
        Where the meshes are written.
    mesh_ref : str
        The same folder as the URDF refers to it (relative to the URDF).
    """
    names = link_names(fig)
    meshes = []
    out = ['<?xml version="1.0"?>', f"<robot name={quoteattr(_safe(robot))}>"]
    out.append('  <material name="lig_grey"><color rgba="0.7 0.7 0.7 1"/></material>')
    for k, link in enumerate(fig.links):
        shape = link.shape
        if isinstance(shape, Graphical) and len(shape.triangles):
            file = re.sub(r"[^A-Za-z0-9_.-]", "_", names[k]) + ".stl"
            meshes.append((os.path.join(mesh_dir, file), _stl(shape, link.scale)))
            back = np.eye(4)
            back[:3, :3] = _frame(link).T
            out += [
                f"  <link name={quoteattr(names[k])}>",
                "    <visual>",
                "      " + _origin(back),
                f"      <geometry><mesh filename={quoteattr(mesh_ref + '/' + file)}/></geometry>",
                '      <material name="lig_grey"/>',
                "    </visual>",
                "  </link>",
            ]
        else:
            out.append(f"  <link name={quoteattr(names[k])}/>")
    for k in range(fig.n_joints):
        out += _chain(fig, k, names)
    out.append("</robot>")
    return ("\n".join(out) + "\n").encode("utf-8"), meshes


def urdf_files(scenes, path: str) -> tuple[list, list]:
    """One URDF per drawn model (and structure) of every scene, meshes beside it.

    The only model goes to ``path``; with several, each goes to
    ``<stem>-<MODEL>.urdf`` (``-2``, ``-3``... for a later structure of the
    same model).  Meshes go to ``<stem>[-<MODEL>]_meshes/``.

    Returns
    -------
    (files, warnings)

    Raises
    ------
    LigError
        When no scene draws a model.
    """
    figures: list = []
    seen: set = set()
    for take in scenes:
        for m in take.models:
            key = (m.name, id(m.figure.links), id(m.figure.joints))
            if key not in seen:
                seen.add(key)
                figures.append((m.name, m.figure))
    if not figures:
        raise LigError(
            "the program draws no animated model, so there is nothing to write as URDF.",
            "a model is drawn while an ANIMATE covers it in a shot scene",
        )
    stem, ext = os.path.splitext(path)
    files: list = []
    counts: dict = {}
    for name, fig in figures:
        counts[name] = counts.get(name, 0) + 1
        if len(figures) == 1:
            target, base = path, stem
        else:
            base = f"{stem}-{name}" + (f"-{counts[name]}" if counts[name] > 1 else "")
            target = base + (ext or ".urdf")
        mesh_dir = base + "_meshes"
        text, meshes = urdf_text(fig, name.lower(), mesh_dir, os.path.basename(mesh_dir))
        files.append((target, text))
        files += meshes
    warnings = [
        f"{name}: URDF describes the model as built, so its FIGURE main link is not written"
        for name, fig in figures
        if fig.main != fig.root
    ]
    return files, warnings
