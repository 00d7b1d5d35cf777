"""URDF import: a robot description as a LIG library holding one MODEL.

The mapping (``docs/exchange.md``, "URDF", has it whole):

* every URDF link is a segment named after it (a LIG name; the URDF names
  are kept in the library's name table, which URDF export reads back);
* a LIG link's frame keeps its primary's orientation at neutral, a URDF
  link's need not: each segment's frame is its URDF link's origin with the
  robot base's axes, and the turn between the two frames (``R0``, the URDF
  link's orientation with every joint at zero) is folded into the joint
  axes and the visuals, and kept in the name table (``RPY``);
* URDF joint ``k`` (depth first from the root, children in file order)
  becomes ``JOINT k`` from its parent's segment to its child's, at the
  child's origin; a revolute or continuous joint turns about its axis
  (``AXIS``, in the base's axes) by its X angle, in degrees; a prismatic
  joint slides along it (``SLIDE``) by its X displacement, in metres; a
  fixed joint is locked at ``(0, 0)``.  Limits become the X extremes
  (a continuous joint's are ``(-180, 180)``, free);
* visuals: ``box`` is BOX, ``cylinder`` and ``sphere`` the standard
  library's CYLINDER and SPHERE, a ``mesh`` (STL, OBJ, DAE, read with
  trimesh) a PRIMITIVE of its triangles, thinned by vertex clustering to
  at most :data:`MESH_TRIANGLES` triangles; each placed by its origin,
  ``R0`` and coloured by its inline material.

Mimic joints are imported as ordinary joints with a note (a LIG motion
drives each joint itself).  Lengths stay in metres.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from liganimate.lang import name_table
from liganimate.runtime.budgets import budget

from ._lig_write import _identifier, _num, comment_text
from ._urdf_read import Urdf, UrdfJoint, UrdfVisual

__all__ = ["MESH_TRIANGLES", "UrdfImportOptions", "import_urdf", "matrix_rpy", "robot_model_name", "zero_frames"]

#: The most triangles one mesh keeps (more are thinned by vertex clustering).
MESH_TRIANGLES = 1500
#: The most triangles all of a robot's meshes keep together.
ROBOT_TRIANGLES = 40000
#: Mesh files URDF import reads (by name, before opening): a URDF cannot make it read other files.
MESH_SUFFIXES = (".stl", ".obj", ".dae")
#: The environment variable that sets the largest mesh file read, in MiB (docs/security.md).
MESH_MB_ENV = "LIGANIMATE_MAX_MESH_MB"
MESH_MB = 100
_DIGITS = 6  # significant digits of mesh vertices (a micrometre on a metre-sized robot)


@dataclass(frozen=True)
class UrdfImportOptions:
    """How ``liganimate import robot.urdf`` writes its library.

    Attributes
    ----------
    model : str
        The MODEL's name (a valid LIG name, checked by the caller).
    source_name : str, optional
        The URDF file's name as the comments mention it.
    mesh_triangles : int
        :data:`MESH_TRIANGLES`.
    """

    model: str = "ROBOT"
    source_name: str | None = None
    mesh_triangles: int = MESH_TRIANGLES


def robot_model_name(robot: Urdf) -> str:
    """The MODEL's default name: the robot's, as a LIG name that no segment takes."""
    taken = {_identifier(link.name, set()) for link in robot.links}
    return _identifier(robot.name or "ROBOT", taken)


def zero_frames(robot: Urdf) -> dict:
    """Each URDF link's frame in the root's with every joint at zero, ``{link: (4, 4)}``."""
    frames = {robot.root: np.eye(4)}
    for j in _preorder(robot):
        frames[j.child] = frames[j.parent] @ j.origin
    return frames


def _preorder(robot: Urdf) -> list:
    """The joints depth first from the root, children in file order."""
    out: list = []
    stack = list(reversed(robot.children(robot.root)))
    while stack:
        j = stack.pop()
        out.append(j)
        stack.extend(reversed(robot.children(j.child)))
    return out


def matrix_rpy(R: np.ndarray) -> tuple[float, float, float]:
    """URDF roll, pitch, yaw (radians) of a rotation, ``R = Rz(yaw) Ry(pitch) Rx(roll)``."""
    # Near pitch +-90 degrees (UR's rpy="0 1.570796325 0") yaw is ill-conditioned and asin loses half
    # the digits; taking yaw out first and reading roll and pitch from what is left gives angles whose
    # matrix is R to rounding, whatever error yaw has (at the exact singularity, yaw is 0).
    R = np.asarray(R, dtype=np.float64)
    yaw = math.atan2(float(R[1, 0]), float(R[0, 0])) if math.hypot(R[0, 0], R[1, 0]) > 0.0 else 0.0
    c, s = math.cos(yaw), math.sin(yaw)
    M = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]) @ R  # Rz(-yaw) R = Ry(pitch) Rx(roll)
    return math.atan2(-float(M[1, 2]), float(M[1, 1])), math.atan2(-float(M[2, 0]), float(M[0, 0])), yaw


def _placed(expr: str, R: np.ndarray, t: np.ndarray) -> str:
    """``expr`` turned by ``R`` (as ROT X, Y, Z, which LIG applies left to right) and moved by ``t``."""
    roll, pitch, yaw = (math.degrees(a) for a in matrix_rpy(R))
    mods = [f"ROT {axis} {_num(a)}" for axis, a in (("X", roll), ("Y", pitch), ("Z", yaw)) if a != 0.0]
    if np.any(t != 0.0):
        mods.append(f"TRANS ({_num(t[0])}, {_num(t[1])}, {_num(t[2])})")
    return f"({expr}) <{', '.join(mods)}>" if mods else f"({expr})"  # parenthesised either way, for what follows


_ALONG_Y_TO_Z = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # Rx(90): LIG's Y axis onto Z


class _Meshes:
    """Mesh visuals as PRIMITIVEs, one per file and scale, read and thinned once."""

    def __init__(self, robot: Urdf, options: UrdfImportOptions, taken: set):
        self.robot = robot
        self.options = options
        self.base = os.path.dirname(os.path.abspath(robot.filename))
        self.names: dict = {}
        self.texts: list = []
        self.taken = taken  # shared with the segments' names
        self.triangles = 0
        self.notes: list = []

    def resolve(self, visual: UrdfVisual) -> str:
        name = visual.filename or ""
        for prefix in ("package://", "file://"):
            if name.startswith(prefix):
                name = name[len(prefix) :]
        if os.path.isabs(name) and os.path.exists(name):
            return name
        # package:// paths name a ROS package: look for the rest beside the URDF and in the folders above it.
        parts = name.split("/")
        folder = self.base
        for _ in range(6):
            for skip in range(len(parts)):
                candidate = os.path.join(folder, *parts[skip:])
                if os.path.isfile(candidate):
                    return candidate
            parent = os.path.dirname(folder)
            if parent == folder:
                break
            folder = parent
        raise self.robot.error(
            visual.pos,
            f"the mesh {visual.filename} is not found beside the URDF.",
            "meshes are looked for relative to the URDF's folder (and, for package:// names, the folders above it)",
        )

    def primitive(self, visual: UrdfVisual) -> str:
        if not (visual.filename or "").lower().endswith(MESH_SUFFIXES):
            raise self.robot.error(
                visual.pos,
                f"the mesh {visual.filename} is not an STL, OBJ or DAE file.",
                "URDF import reads meshes named .stl, .obj or .dae, and no other file",
            )
        path = self.resolve(visual)
        limit = budget(MESH_MB_ENV, MESH_MB)
        size = os.path.getsize(path)
        if size > limit * 1024 * 1024:
            # Estimated before reading: trimesh would hold the whole file and more in memory.
            raise self.robot.error(
                visual.pos,
                f"the mesh {os.path.basename(path)} is {size / 1048576:.0f} MiB, more than the {limit} MiB "
                "URDF import reads.",
                f"simplify the mesh, or raise the budget with {MESH_MB_ENV}",
            )
        key = (path, visual.size)
        if key in self.names:
            return self.names[key]
        V, F = self._load(path, visual)
        V = V * np.asarray(visual.size, dtype=np.float64)
        V, F = thin_mesh(V, F, self.options.mesh_triangles)
        self.triangles += len(F)
        if self.triangles > ROBOT_TRIANGLES:
            raise self.robot.error(
                visual.pos,
                f"the robot's meshes keep more than {ROBOT_TRIANGLES} triangles in all.",
                "lower --mesh-triangles",
            )
        base = os.path.splitext(os.path.basename(path))[0]
        name = _identifier("MESH_" + base, self.taken)
        self.names[key] = name
        self.texts.append(_mesh_primitive(name, V, F, os.path.basename(path)))
        return name

    def _load(self, path: str, visual: UrdfVisual):
        try:
            import trimesh
        except ImportError as exc:  # a declared dependency; a broken install says so
            raise self.robot.error(
                visual.pos, f"reading meshes needs trimesh ({exc}).", "pip install trimesh"
            ) from None
        try:
            mesh: Any = trimesh.load(path, force="mesh", process=False)  # force="mesh": a Trimesh
        except Exception as exc:  # trimesh raises many kinds; any is the same for the user
            raise self.robot.error(
                visual.pos,
                f"the mesh {os.path.basename(path)} cannot be read: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}.",
                "URDF import reads STL, OBJ and DAE (DAE needs pycollada)",
            ) from None
        V = np.asarray(mesh.vertices, dtype=np.float64).reshape(-1, 3)
        F = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
        if len(F) == 0 or not np.all(np.isfinite(V)):
            raise self.robot.error(visual.pos, f"the mesh {os.path.basename(path)} has no finite triangles.")
        return V, F


def thin_mesh(V: np.ndarray, F: np.ndarray, budget: int) -> tuple[np.ndarray, np.ndarray]:
    """At most ``budget`` triangles: vertex clustering on ever coarser grids.

    Vertices in one cell of a grid over the mesh's bounding box merge at
    their mean; triangles that collapse (two corners in one cell) and
    repeats go.  The finest grid that meets the budget is taken, so a mesh
    already within it is returned unchanged.

    Parameters
    ----------
    V : numpy.ndarray, shape (n, 3)
    F : numpy.ndarray of int, shape (m, 3)
    budget : int

    Returns
    -------
    (V, F) with ``len(F) <= budget`` (unless even the coarsest grid, 2 cells
    a side, leaves more, which no mesh of a closed surface does).
    """
    if len(F) <= budget:
        return V, F
    lo = V.min(axis=0)
    size = float((V.max(axis=0) - lo).max()) or 1.0
    cells = 256
    best = (V, F)
    while cells >= 2:
        q = np.minimum(np.floor((V - lo) / size * cells), cells - 1).astype(np.int64)
        keys = (q[:, 0] * (cells + 1) + q[:, 1]) * (cells + 1) + q[:, 2]
        uniq, inverse = np.unique(keys, return_inverse=True)
        inverse = inverse.reshape(-1)
        counts = np.bincount(inverse, minlength=len(uniq)).astype(np.float64)
        sums = np.stack([np.bincount(inverse, weights=V[:, k], minlength=len(uniq)) for k in range(3)], axis=1)
        merged = np.asarray(sums, dtype=np.float64) / counts[:, None]
        G = inverse[F]
        keep = (G[:, 0] != G[:, 1]) & (G[:, 1] != G[:, 2]) & (G[:, 0] != G[:, 2])
        G = G[keep]
        _, first = np.unique(np.sort(G, axis=1), axis=0, return_index=True)
        G = G[np.sort(first)]
        best = (merged, G)
        if len(G) <= budget:
            break
        cells = int(cells * 0.75)
    used, G = np.unique(best[1], return_inverse=True)
    return best[0][used], G.reshape(-1, 3)


def _g(x: float) -> str:
    text = f"{float(x):.{_DIGITS}g}"
    return "0.0" if float(text) == 0.0 else (text if any(c in text for c in ".e") else text + ".0")


def _mesh_primitive(name: str, V: np.ndarray, F: np.ndarray, source: str) -> str:
    """A PRIMITIVE without parameters that draws a mesh's triangles."""
    head = [
        f"{{@ {name}: the mesh {comment_text(source)}, {len(F)} triangles }}",
        "",
        f"      PRIMITIVE {name}",
        f"      {name} ::= '{name}' ;",
    ]
    pts = [f"({_g(v[0])}, {_g(v[1])}, {_g(v[2])})" for v in V]
    # Corners a micrometre apart are one corner once written to _DIGITS digits (ANYmal C's meshes):
    # such a sliver draws nothing, and the compiler refuses a polygon with two corners, so it is left out.
    kept = [(a, b, c) for a, b, c in F if len({pts[a], pts[b], pts[c]}) == 3]
    head[0] = f"{{@ {name}: the mesh {comment_text(source)}, {len(kept)} triangles }}"
    body = [f"      DRAW POLY FROM {pts[a]} TO {pts[b]} TO {pts[c]}" for a, b, c in kept]
    return "\n".join(head + body + ["      RETURN", "      END", ""])


def _shape(visual: UrdfVisual, meshes: _Meshes) -> str:
    if visual.kind == "box":
        x, y, z = visual.size
        return f"BOX WIDTH {_num(x)}, HEIGHT {_num(y)}, DEPTH {_num(z)}"
    if visual.kind == "cylinder":
        r, length = visual.size
        return f"CYLINDER RADIUS {_num(r)}, HEIGHT {_num(length)}, SIDES 16"
    if visual.kind == "sphere":
        return f"SPHERE RADIUS {_num(visual.size[0])}, SIDES 16"
    return meshes.primitive(visual)


def _segment_expr(visuals, R0: np.ndarray, meshes: _Meshes) -> str | None:
    parts = []
    for v in visuals:
        native = _ALONG_Y_TO_Z if v.kind == "cylinder" else np.eye(3)
        R = R0 @ v.origin[:3, :3] @ native
        t = R0 @ v.origin[:3, 3]
        expr = _placed(_shape(v, meshes), R, t)
        if v.rgba is not None:
            r, g, b = (round(max(0.0, min(100.0, 100.0 * float(c))), 6) for c in v.rgba[:3])
            expr = f"{expr} <COLOUR ({_num(r)}, {_num(g)}, {_num(b)})>"
        parts.append(expr)
    return " +\n          ".join(parts) if parts else None


#: Beyond this a revolute joint's limit is no limit (LIG's extremes stop at 1E9 degrees).
_UNBOUNDED_DEGREES = 1e9


def _unbounded(j: UrdfJoint) -> bool:
    """A revolute joint whose limits say "none": SDF converters write lower="-1e+16" upper="1e+16"."""
    return j.type == "revolute" and max(abs(math.degrees(j.lower)), abs(math.degrees(j.upper))) > _UNBOUNDED_DEGREES


def _extremes(j: UrdfJoint) -> str:
    if j.type == "fixed":
        return "(0.0, 0.0)"
    if j.type == "continuous" or _unbounded(j):
        return "(-180.0, 180.0)"
    if j.type == "prismatic":
        return f"SLIDE ({_num(j.lower)}, {_num(j.upper)})"
    return f"({_num(math.degrees(j.lower))}, {_num(math.degrees(j.upper))})"


def import_urdf(robot: Urdf, options: UrdfImportOptions) -> tuple[bytes, list]:
    """A robot description as a library: ``(UTF-8 text, notes)``.

    Raises
    ------
    LigDiagnostics
        For a mesh that cannot be found or read, at its line in the URDF.
    """
    frames = zero_frames(robot)
    joints = _preorder(robot)
    taken = {options.model}
    segment = {robot.root: _identifier(robot.root, taken)}
    for j in joints:
        segment[j.child] = _identifier(j.child, taken)
    meshes = _Meshes(robot, options, taken)
    shapes = {}
    notes = []
    for link in robot.links:
        # A zero size (pybullet's Laikago marks its toes with <sphere radius="0.0"/>) draws nothing, and
        # LIG's shapes would be degenerate polygons the compiler refuses: such a visual is left out.
        visuals = [v for v in link.visuals if all(s != 0.0 for s in v.size)]
        if len(visuals) < len(link.visuals):
            notes.append(f"link {link.name} has a visual of zero size, which draws nothing; it is left out")
        expr = _segment_expr(visuals, frames[link.name][:3, :3], meshes)
        if expr is not None:
            shapes[link.name] = expr
    for j in joints:
        if _unbounded(j):
            notes.append(
                f"joint {j.name}'s limits ({j.lower:g}, {j.upper:g}) bound nothing; it turns freely, as a continuous joint"
            )
        if j.mimic is not None and j.type != "fixed":
            notes.append(
                f"joint {j.name} mimics {j.mimic[0]} (x {j.mimic[1]:g} + {j.mimic[2]:g}); it is imported as a joint "
                "of its own, which a motion drives itself"
            )
    if not joints:
        raise robot.error(
            robot.link(robot.root).pos,
            "the robot has no joints, so it is not a MODEL.",
            "a LIG model is links joined by joints; to import a single rigid object, add a link "
            '<link name="world"/> and a fixed joint from it to this link',
        )
    text = _library_text(robot, options, joints, segment, shapes, frames, meshes)
    return text.encode("utf-8"), notes


def _library_text(robot, options, joints, segment, shapes, frames, meshes) -> str:
    model = options.model
    source = comment_text(options.source_name or os.path.basename(robot.filename))
    out = [
        f"C {model}: the robot {comment_text(robot.name)} from the URDF file {source}, made by liganimate import.",
        "C Lengths are in metres; JOINT k is URDF joint k, depth first from the root link; a revolute",
        "C joint turns by its X angle about its AXIS, a prismatic one slides by its X displacement.",
        "C The name table below keeps the URDF's link and joint names for URDF export.",
        "",
    ]
    used = [p for p in ("CYLINDER", "SPHERE") if any(p + " RADIUS" in s for s in shapes.values())]
    if used:
        out += [f"      LOAD {', '.join(used)} FROM 'shapes'", ""]
    out += meshes.texts
    names = [segment[robot.root]] + [segment[j.child] for j in joints]
    for k in range(0, len(names), 6):
        out.append("      GRAPHICAL " + ", ".join(names[k : k + 6]))
    out += [f"      MODEL {model}", ""]
    for link in [robot.root] + [j.child for j in joints]:
        if link in shapes:
            out.append(f"      {segment[link]} :- {shapes[link]}")
    out += ["", f"      STARTMODEL {model}"]
    for k, j in enumerate(joints, start=1):
        loc = frames[j.child][:3, 3] - frames[j.parent][:3, 3]
        axis = frames[j.child][:3, :3] @ j.axis
        line = (
            f"        JOINT {k}, {segment[j.parent]}, ({_num(loc[0])}, {_num(loc[1])}, {_num(loc[2])}), "
            f"{segment[j.child]}, (0.0, 0.0, 0.0), {_extremes(j)}"
        )
        if j.type != "fixed":
            line += f" AXIS ({_num(axis[0])}, {_num(axis[1])}, {_num(axis[2])})"
        out.append(line)
    out += ["      ENDMODEL", ""]
    rows: list = [(segment[robot.root], robot.root, (), None, None, _rpy(frames[robot.root]))]
    rows += [(segment[j.child], j.child, (), None, j.name, _rpy(frames[j.child]), j.mimic) for j in joints]
    out.append(name_table.format_table(model, rows))
    return "\n".join(out)


def _rpy(frame: np.ndarray):
    rpy = matrix_rpy(frame[:3, :3])
    return None if rpy == (0.0, 0.0, 0.0) else rpy
