"""The studio's "Save": a LIG library holding the posed model and the kept poses as a motion.

The model is written out as what is drawn, so the library stands on its
own: one PRIMITIVE per distinct segment shape, drawing its triangles with
DRAW POLY (corners to nine significant digits, scaled by the segment's SCALE MODEL factor, so the library's
model has scale 1), and a STARTMODEL block with the joints' locations and
extremes.  Segment names are kept where they are unique LIG names and made
unique otherwise.  Each extreme is widened, when a kept pose goes beyond
it, just enough to hold that pose (later generations may exceed the
extremes; LIG would clamp such a pose when it plays it).  Axes locked at
one value stay locked.

The motion drives every joint: the first kept pose is its starting
position and kept pose ``k`` is the keyframe at ``FRAME k * spacing``, so
playing it shows each kept pose at those frames exactly.  Joint locations,
extremes and angles are written with Python's shortest round-trip
``repr``, so they read back as the same doubles.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from liganimate.compiler.names import reserved

__all__ = ["Library", "library", "library_text", "lig_name"]

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
# Keywords and built-ins (compiler/names.py, read from the grammar), and the
# segment name the writers give a figure's empty root.
_RESERVED = reserved() | {"ORIGIN"}


def lig_name(text: str) -> bool:
    """Whether ``text`` is a LIG name a library may define (not a keyword or built-in)."""
    return bool(_NAME.match(text)) and text.upper() not in _RESERVED


def _num(x: float) -> str:
    return repr(float(x) + 0.0)


def _vec(v) -> str:
    return f"({_num(v[0])}, {_num(v[1])}, {_num(v[2])})"


def _short(x: float) -> str:
    s = f"{float(x) + 0.0:.9g}"
    return s if "." in s or "e" in s else s + ".0"


def _corner(v) -> str:
    # Nine significant digits: a millionth of a millimetre on a 1 km figure, and half the text of repr.
    return f"({_short(v[0])}, {_short(v[1])}, {_short(v[2])})"


def _segment_names(fig, taken: set) -> list:
    names = []
    for i, link in enumerate(fig.links):
        parent = fig.parent_joint_of(i)
        base = (link.name or "").upper()
        if not lig_name(base):
            base = "SEGMENT" if parent is None else f"SEGMENT_{parent.id}"
        name, n = base, 1
        while name in taken:
            n += 1
            name = f"{base}_{n}"
        taken.add(name)
        names.append(name)
    return names


def _primitive(name: str, triangles: np.ndarray, lightness: np.ndarray) -> list:
    out = [f"      PRIMITIVE {name}", f"      {name} ::= '{name}' ;"]
    light = None
    for tri, l in zip(triangles, lightness):
        if (tri[0] == tri[1]).all() or (tri[1] == tri[2]).all() or (tri[2] == tri[0]).all():
            continue  # a triangle with a repeated corner draws nothing, and DRAW POLY would refuse it
        if l != light:
            out.append(f"      DRAW WITH <LIGHTNESS {_num(l)}>")
            light = l
        out.append(f"      DRAW POLY FROM {_corner(tri[0])} TO {_corner(tri[1])} TO {_corner(tri[2])}")
    out.append("      END")
    out.append("")
    return out


def widened_extremes(fig, kept: np.ndarray) -> np.ndarray:
    """Each joint's extremes grown to hold the kept poses; locked axes as they are.

    Parameters
    ----------
    fig : Figure
    kept : ndarray, shape (K, J, 3)

    Returns
    -------
    ndarray, shape (J, 3, 2)
    """
    ext = np.array(fig.extremes, dtype=np.float64).reshape(fig.n_joints, 3, 2)
    if len(kept):
        locked = ext[..., 0] == ext[..., 1]
        lo = np.minimum(ext[..., 0], kept.min(axis=0))
        hi = np.maximum(ext[..., 1], kept.max(axis=0))
        ext[..., 0] = np.where(locked, ext[..., 0], lo)
        ext[..., 1] = np.where(locked, ext[..., 1], hi)
    return ext


@dataclass(frozen=True)
class Library:
    """A saved library in its parts: what depends on the figure alone, and what the kept poses change.

    Attributes
    ----------
    head : str
        The header comment.
    shapes : str
        One PRIMITIVE per distinct segment shape, drawing its triangles:
        most of the text, the same for every Save of one figure.
    skeleton : str
        The same PRIMITIVEs, each drawing only its first triangle: what
        checking the rest needs of them (their names and that they draw).
    body : str
        The declarations, the segments' assignments, STARTMODEL (with the
        widened extremes) and the motion.
    """

    head: str
    shapes: str
    skeleton: str
    body: str

    @property
    def text(self) -> str:
        """The library's text."""
        return self.head + self.shapes + self.body


def library_text(
    fig, model: str, motion: str, kept, spacing: int = 24, note: str = "", frames=None, method: str = "LINEAR"
) -> str:
    """The text of a library with ``fig`` as MODEL ``model`` and the kept poses as MOTION ``motion``.

    Parameters
    ----------
    fig : Figure
    model, motion : str
        LIG names (checked by the caller with :func:`lig_name`), different.
    kept : sequence of ndarray, shape (J, 3)
        At least one pose, in the figure's joint order.
    spacing : int
        Frames between kept poses.
    note : str
        One line for the header comment (no braces or line breaks).
    frames : sequence of int, optional
        Each kept pose's frame: 0, then increasing (default ``k * spacing``).
    method : str
        The interpolation method that leads to each keyframe (a name of
        :mod:`liganimate.runtime.motion.interpolation`); LINEAR is written
        as no INTERPOLATE clause.

    Returns
    -------
    str
        Library text that ``LOAD model, motion FROM 'file.lig'`` takes.
    """
    return library(fig, model, motion, kept, spacing, note, frames, method).text


def library(
    fig, model: str, motion: str, kept, spacing: int = 24, note: str = "", frames=None, method: str = "LINEAR"
) -> Library:
    """The library of :func:`library_text`, in its parts (see :class:`Library`)."""
    kept = np.asarray(kept, dtype=np.float64).reshape(-1, fig.n_joints, 3)
    frames = [k * spacing for k in range(len(kept))] if frames is None else [int(f) for f in frames]
    model, motion = model.upper(), motion.upper()
    taken = {model, motion}
    segs = _segment_names(fig, taken)
    ext = widened_extremes(fig, kept)
    head = _header(fig, model, motion, kept, spacing, note, ext, frames)
    kept, ext = _in_model_units(fig, kept, ext)
    shapes, skeleton, assign = _shapes(fig, segs, taken)
    body = []
    for k in range(0, len(segs), 6):
        body.append("      GRAPHICAL " + ", ".join(segs[k : k + 6]))
    pieces, build = _model(fig, model, segs, ext, taken)
    body += [f"      MODEL {', '.join([model, *pieces])}", f"      MOTION {motion}", ""] + assign + [""]
    body += build + [""] + _motion(fig, motion, kept, frames, method)
    return Library("\n".join(head) + "\n", "\n".join(shapes) + "\n", "\n".join(skeleton) + "\n", "\n".join(body) + "\n")


def _header(fig, model: str, motion: str, kept, spacing: int, note: str, ext, frames) -> list:
    grown = [
        fig.joints[k].id
        for k in range(fig.n_joints)
        if not np.array_equal(ext[k], np.asarray(fig.extremes[k]).reshape(3, 2))
    ]
    out = [
        f"C {model}, {motion}: posed with liganimate studio, the Generator of the thesis on",
        "C posing figures with interactive genetic algorithms.",
    ]
    if note:
        out.append(f"C {note}")
    out += [
        "C",
        f"C {motion} holds {len(kept)} kept pose(s): the first is its starting position and pose k",
        (
            f"C is its keyframe at FRAME k * {spacing}."
            if frames == [k * spacing for k in range(len(kept))]
            else "C is its keyframe at FRAME " + ", ".join(str(f) for f in frames[1:]) + " in turn."
        )
        + f" Play it with ANIMATE ... USING {motion}.",
        f"C {model} is the model as drawn: each segment's triangles, its joints and extremes.",
    ]
    if grown:
        out.append(
            "C The extremes of joint(s) "
            + ", ".join(str(j) for j in grown)
            + " are widened to hold poses the Generator took beyond them."
        )
    return out + [
        "",
        f"{{@ {model}: the posed model, {fig.n_links} segments and {fig.n_joints} joints }}",
        f"{{@ {motion}: {len(kept)} kept pose(s), {spacing} frames apart }}"
        if frames == [k * spacing for k in range(len(kept))]
        else f"{{@ {motion}: {len(kept)} kept pose(s), over {frames[-1]} frames }}",
        "",
    ]


def _shapes(fig, segs: list, taken: set) -> tuple:
    """(PRIMITIVE lines, the same with one triangle each, the segments' assignments)."""
    shapes: dict = {}  # (id(shape), scale) -> primitive name
    full, skeleton, assign = [], [], []
    for i, link in enumerate(fig.links):
        tris = getattr(link.shape, "triangles", None)
        if tris is None or len(tris) == 0:
            continue
        key = (id(link.shape), link.scale)
        prim = shapes.get(key)
        if prim is None:
            prim = f"SHAPE_{len(shapes) + 1}"
            while prim in taken:
                prim += "_"
            taken.add(prim)
            shapes[key] = prim
            lines = _primitive(prim, tris * link.scale, link.shape.lightness)
            full += lines
            draws = [n for n, line in enumerate(lines) if line.startswith("      DRAW POLY")]
            skeleton += lines[: draws[0] + 1] + lines[-2:] if draws else lines
        assign.append(f"      {segs[i]} :- ({prim})")
    return full, skeleton, assign


def _in_model_units(fig, kept: np.ndarray, ext: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Slides' displacements and extremes times their SCALE MODEL factor (the library's model has scale 1).

    A negative factor (a mirrored model) turns each pair round, so it stays ``(min, max)``.
    """
    gain = np.where(fig.slides, fig.slide_scales, 1.0)
    if np.all(gain == 1.0):
        return kept, ext
    kept = kept * gain[None, :, None]
    ext = ext * gain[:, None, None]
    ext = np.where((gain < 0)[:, None, None], ext[..., ::-1], ext)
    return kept, ext


def _model(fig, model: str, segs: list, ext, taken: set) -> tuple[list, list]:
    """(the MODEL variables it needs besides ``model``, the statements that build ``model``)."""
    if fig.inverted.any():
        return _grafted(fig, model, segs, ext, taken)
    return [], _startmodel(fig, model, segs, ext)


def _extremes(j, ext_k) -> str:
    """A joint's extremes as a JOINT writes them, with its SLIDE and AXIS words."""
    pairs = ", ".join(f"({_num(a)}, {_num(b)})" for a, b in ext_k)
    slide = "SLIDE " if j.slide else ""
    axis = "" if j.axes is None else f" AXIS {_vec(j.axes[:, 0])}"
    return f"              {slide}{pairs}{axis}"


def _joint_line(target: str, j, primary: str, secondary: str, ext_k) -> list:
    return [
        f"      {target} :- JOINT {j.id}, {primary}, {_vec(j.loc1)}, {secondary}, {_vec(j.loc2)},",
        _extremes(j, ext_k),
    ]


def _grafted(fig, model: str, segs: list, ext, taken: set) -> tuple[list, list]:
    """A figure with inverted joints as the JOINTs and FIGUREs that build it.

    A model block cannot say it: its secondaries are always new links.  So
    each piece is built from a link no joint of the piece has as its
    secondary (one always exists: the joints cannot make a cycle), joining
    at it, as a primary, the pieces beyond each of its joints, each a
    submodel re-rooted (``FIGURE ... MAIN LINK``) at the joint's secondary,
    which is where a JOINT takes a submodel (thesis 3.3).  Pieces are found
    with a work list, not recursion, so a long chain cannot overflow.
    """
    joints = fig.joints
    incident: list[list[int]] = [[] for _ in fig.links]
    for k, j in enumerate(joints):
        incident[j.primary].append(k)
        incident[j.secondary].append(k)
    # A piece: (the link it must be held by, the joint it hangs from), its variable, its root and joints.
    pieces: list = []
    cut: set = set()  # joints already written: a piece never reaches across one
    work = [(fig.root, -1, model)]
    while work:
        want, _, name = work.pop()
        links, inner = [want], []
        seen = {want}
        for x in links:  # the piece's links: everything reached from ``want`` without crossing a cut
            for k in incident[x]:
                other = joints[k].secondary if joints[k].primary == x else joints[k].primary
                if k not in cut and other not in seen:
                    seen.add(other)
                    links.append(other)
                    inner.append(k)
        heads = {joints[k].secondary for k in inner}
        root = want if want not in heads else next(x for x in links if x not in heads)
        parts = []
        for k in sorted(k for k in incident[root] if k not in cut):
            cut.add(k)
            child = joints[k].secondary
            sub = segs[child]
            if any(j not in cut for j in incident[child]):  # joints beyond it: a submodel
                sub = _fresh(f"{model}_{joints[k].id}", taken)
                work.append((child, k, sub))
            parts.append((k, sub))
        pieces.append((name, want, root, parts))
    extra = [name for name, *_ in pieces if name != model]
    out: list = []
    for name, want, root, parts in reversed(pieces):  # a piece after the pieces it joins
        primary = segs[root]
        for k, sub in parts:
            out += _joint_line(name, joints[k], primary, sub, ext[k])
            primary = name
        if want != root:
            out.append(f"      FIGURE {name} MAIN LINK {segs[want]}")
    if fig.main != fig.root:
        out.append(f"      FIGURE {model} MAIN LINK {segs[fig.main]}")
    return extra, out


def _fresh(base: str, taken: set) -> str:
    name, n = base, 1
    while name in taken:
        n += 1
        name = f"{base}_{n}"
    taken.add(name)
    return name


def _startmodel(fig, model: str, segs: list, ext) -> list:
    out = [f"      STARTMODEL {model}"]
    for k, j in enumerate(fig.joints):
        out.append(f"        JOINT {j.id}, {segs[j.primary]}, {_vec(j.loc1)}, {segs[j.secondary]}, {_vec(j.loc2)},")
        out.append(_extremes(j, ext[k]))
    out.append("      ENDMODEL")
    if fig.main is not None and fig.main != fig.root:
        parent = fig.parent_joint_of(fig.main)
        out.append(f"      FIGURE {model} MAIN JOINT {parent.id}")
    return out


def _motion(fig, motion: str, kept, frames, method: str) -> list:
    out = [f"      STARTMOTION {motion}"]
    how = "" if method == "LINEAR" else f" INTERPOLATE {method}"
    for k, j in enumerate(fig.joints):
        a = kept[0, k]
        out.append(f"        JOINT {j.id} POSITION {_num(a[0])}, {_num(a[1])}, {_num(a[2])}")
        for n in range(1, len(kept)):
            a = kept[n, k]
            out.append(f"          FRAME {frames[n]} POSITION {_num(a[0])}, {_num(a[1])}, {_num(a[2])}{how}")
    out.append("      ENDMOTION")
    return out
