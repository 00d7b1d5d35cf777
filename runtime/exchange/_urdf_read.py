"""Reading URDF robot descriptions, with diagnostics at the line of what is wrong.

A URDF file is XML: a ``<robot>`` holding ``<link>`` elements (with
``<visual>`` geometry) and ``<joint>`` elements (``revolute``,
``continuous``, ``prismatic``, ``fixed``; each with a parent and a child
link, an ``<origin xyz rpy>``, an ``<axis xyz>``, ``<limit>`` and maybe a
``<mimic>``).  This module reads one into a :class:`Urdf` and checks it: a
file that is not well-formed XML, a joint naming a link that does not
exist, a link that is the child of two joints (a cycle or a closed chain),
several root links, a joint type this importer does not take, a number that
is not one: each is a :class:`~liganimate.lang.diagnostics.LigDiagnostics`
error at its ``file:line:col``, never a Python exception.

XML is parsed with the standard library's expat with every document type
declaration refused, so no entity is ever defined or expanded (the
"billion laughs" and external-entity attacks need one); the file's size and
its numbers of links and joints are bounded before the work is done.
"""

from __future__ import annotations

import math
import os
import re
import xml.parsers.expat
from dataclasses import dataclass, field
from typing import NoReturn

import numpy as np

from liganimate.lang.ast import Pos
from liganimate.lang.diagnostics import Diagnostic, LigDiagnostics

__all__ = [
    "MAX_URDF_BYTES",
    "MAX_URDF_LINKS",
    "Urdf",
    "UrdfJoint",
    "UrdfLink",
    "UrdfVisual",
    "parse_urdf",
    "read_urdf",
    "rpy_matrix",
]

#: The largest URDF file read (bytes); real robot descriptions are well under 1 MB.
MAX_URDF_BYTES = 16 * 1024 * 1024
#: The most links (and so joints) a robot may have.
MAX_URDF_LINKS = 5000

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed")


@dataclass(frozen=True)
class UrdfVisual:
    """One ``<visual>`` of a link.

    Attributes
    ----------
    kind : str
        ``box``, ``cylinder``, ``sphere`` or ``mesh``.
    size : tuple of float
        box: (x, y, z); cylinder: (radius, length); sphere: (radius,);
        mesh: its scale (x, y, z).
    origin : numpy.ndarray, shape (4, 4)
        The visual's pose in its link's frame.
    filename : str or None
        A mesh's file name as written.
    rgba : tuple of 4 floats or None
        The colour of an inline ``<material>``, if any.
    pos : Pos
    """

    kind: str
    size: tuple
    origin: np.ndarray
    filename: str | None
    rgba: tuple | None
    pos: Pos


@dataclass(frozen=True)
class UrdfLink:
    """One ``<link>``: its name, visuals and where it is written."""

    name: str
    visuals: tuple
    pos: Pos


@dataclass(frozen=True)
class UrdfJoint:
    """One ``<joint>``.

    Attributes
    ----------
    name, type, parent, child : str
    origin : numpy.ndarray, shape (4, 4)
        The child link's frame in the parent's, at zero.
    axis : numpy.ndarray, shape (3,)
        Unit axis in the child's (joint's) frame; (1, 0, 0) by default.
    lower, upper : float
        Limits (radians or metres); 0 for a fixed or continuous joint.
    mimic : tuple or None
        ``(joint name, multiplier, offset)``.
    pos : Pos
    """

    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    lower: float
    upper: float
    mimic: tuple | None
    pos: Pos
    ends: tuple = ()  # where its <parent> and <child> are

    def end_pos(self, role: str) -> Pos:
        """Where the joint's ``<parent>`` or ``<child>`` is written."""
        return self.ends[0 if role == "parent" else 1] if self.ends else self.pos


@dataclass(frozen=True)
class Urdf:
    """A checked robot description: one tree of links.

    Attributes
    ----------
    name : str
        The robot's name.
    links : tuple of UrdfLink
    joints : tuple of UrdfJoint
        In the file's order.
    root : str
        The one link that is no joint's child.
    filename, source : str
        For diagnostics raised later (by the importer).
    """

    name: str
    links: tuple
    joints: tuple
    root: str
    filename: str
    source: str
    by_child: dict = field(default_factory=dict, repr=False)

    def error(self, pos: Pos, message: str, hint: str | None = None) -> LigDiagnostics:
        """A diagnostic about this file (the caller raises it)."""
        return LigDiagnostics([Diagnostic(self.filename, pos, message, hint, source=self.source)])

    def link(self, name: str) -> UrdfLink:
        """The link called ``name``."""
        return next(l for l in self.links if l.name == name)

    def children(self, link: str) -> list:
        """The joints whose parent is ``link``, in file order."""
        return [j for j in self.joints if j.parent == link]


def rpy_matrix(rpy) -> np.ndarray:
    """URDF's fixed-axis roll, pitch, yaw (radians) as a rotation: ``Rz(yaw) Ry(pitch) Rx(roll)``."""
    r, p, y = (float(v) for v in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def read_urdf(path: str) -> Urdf:
    """Read and check a URDF file.

    Raises
    ------
    LigDiagnostics
        For malformed content, at its line and column.
    OSError
        If the file cannot be read.
    """
    size = os.path.getsize(path)
    if size > MAX_URDF_BYTES:
        raise LigDiagnostics(
            [
                Diagnostic(
                    path,
                    Pos(1, 1, 1, 1),
                    f"the URDF file is {size} bytes, more than the {MAX_URDF_BYTES} this importer reads.",
                    None,
                )
            ]
        )
    with open(path, "rb") as fh:
        raw = fh.read(MAX_URDF_BYTES + 1)
    return parse_urdf(raw, path)


class _Element:
    __slots__ = ("attrs", "children", "pos", "tag")

    def __init__(self, tag: str, attrs: dict, pos: Pos):
        self.tag = tag
        self.attrs = attrs
        self.children: list = []
        self.pos = pos

    def first(self, tag: str):
        return next((c for c in self.children if c.tag == tag), None)

    def all(self, tag: str) -> list:
        return [c for c in self.children if c.tag == tag]


class _Refused(Exception):
    """A document type declaration: never read, so that no entity can be defined."""


# Blank lines before the XML declaration: XML forbids them, but ROS's and pybullet's parsers
# (TinyXML) take them, and pybullet_data ships such files (differential/diff_ring.urdf).
_LATE_DECLARATION = re.compile(rb"\A(?:\xef\xbb\xbf)?[ \t\r\n]+(<\?xml[^>]*\?>)")
_ENCODING = re.compile(rb"""encoding\s*=\s*["']([A-Za-z0-9._-]+)["']""")


def _late_declaration(raw: bytes) -> tuple[bytes, str | None]:
    """``raw`` with an XML declaration after leading white space blanked out (lines and columns
    unchanged), and the encoding it declared, for expat, which accepts a declaration only first."""
    m = _LATE_DECLARATION.match(raw)
    if m is None:
        return raw, None
    declaration = m.group(1)
    named = _ENCODING.search(declaration)
    blanked = raw[: m.start(1)] + b" " * len(declaration) + raw[m.end(1) :]
    return blanked, named.group(1).decode("ascii") if named else None


class _Reader:
    def __init__(self, raw: bytes, filename: str):
        self.filename = filename
        self.text = raw.decode("utf-8", errors="replace").removeprefix("\ufeff")
        self.lines = self.text.split("\n")
        self.raw = raw

    def pos(self, line: int, column: int = 1) -> Pos:
        """From ``column`` to the end of the line (at least one character)."""
        text = self.lines[line - 1] if 0 < line <= len(self.lines) else ""
        return Pos(line, column, line, max(len(text.rstrip()) + 1, column + 1))

    def fail(self, pos: Pos, message: str, hint: str | None = None) -> NoReturn:
        raise LigDiagnostics([Diagnostic(self.filename, pos, message, hint, source=self.text)])

    def parse(self) -> _Element:
        raw, encoding = _late_declaration(self.raw)
        parser = xml.parsers.expat.ParserCreate(encoding)
        stack: list = []
        root: list = []
        count = [0]

        def start(tag, attrs):
            count[0] += 1
            if count[0] > 50 * MAX_URDF_LINKS:
                raise _Refused("too many elements")
            el = _Element(tag, attrs, self.pos(parser.CurrentLineNumber, parser.CurrentColumnNumber + 1))
            if stack:
                stack[-1].children.append(el)
            else:
                root.append(el)
            stack.append(el)

        def end(tag):
            stack.pop()

        def doctype(*args):
            raise _Refused("doctype")

        def entity(*args):
            raise _Refused("doctype")

        parser.StartElementHandler = start
        parser.EndElementHandler = end
        parser.StartDoctypeDeclHandler = doctype
        parser.EntityDeclHandler = entity
        parser.SetParamEntityParsing(xml.parsers.expat.XML_PARAM_ENTITY_PARSING_NEVER)
        try:
            parser.Parse(raw, True)
        except xml.parsers.expat.ExpatError as exc:
            message = xml.parsers.expat.ErrorString(exc.code)
            self.fail(self.pos(exc.lineno, exc.offset + 1), f"the URDF is not well-formed XML: {message}.")
        except _Refused as exc:
            line = parser.CurrentLineNumber
            if str(exc) == "doctype":
                self.fail(
                    self.pos(line),
                    "the URDF declares a document type, which this importer refuses.",
                    "a URDF needs no DOCTYPE or entities; remove them (they can expand without bound)",
                )
            self.fail(self.pos(line), f"the URDF has more than {50 * MAX_URDF_LINKS} elements.")
        robot = root[0]
        if robot.tag != "robot":
            self.fail(robot.pos, f"a URDF's outer element is <robot>, not <{robot.tag}>.")
        return robot

    # -- values

    def numbers(self, el: _Element, attr: str, n: int, default=None) -> tuple:
        text = el.attrs.get(attr)
        if text is None:
            if default is None:
                self.fail(el.pos, f"<{el.tag}> needs its {attr} attribute.")
            return default
        words = text.split()
        try:
            values = tuple(float(w) for w in words)
        except ValueError:
            values = ()
        if len(values) != n or not all(math.isfinite(v) for v in values):
            hint = None
            if "$(" in text or "${" in text:  # husky.urdf in pybullet_data keeps $(optenv ...) unexpanded
                hint = "this is a xacro substitution: expand the file with xacro first (xacro robot.urdf.xacro > robot.urdf)"
            elif "," in text:
                hint = "URDF separates numbers with spaces, not commas"
            self.fail(
                el.pos,
                f'<{el.tag} {attr}="{text}"> must be {n} finite number{"s" if n > 1 else ""}.',
                hint,
            )
        return values

    def origin(self, el: _Element | None) -> np.ndarray:
        T = np.eye(4)
        if el is None:
            return T
        xyz = self.numbers(el, "xyz", 3, (0.0, 0.0, 0.0))
        rpy = self.numbers(el, "rpy", 3, (0.0, 0.0, 0.0))
        T[:3, :3] = rpy_matrix(rpy)
        T[:3, 3] = xyz
        return T

    def name(self, el: _Element, what: str) -> str:
        name = el.attrs.get("name")
        if not name:
            self.fail(el.pos, f"a {what} needs a name.")
        return name

    # -- links and joints

    def visual(self, el: _Element) -> UrdfVisual | None:
        geometry = el.first("geometry")
        if geometry is None or not geometry.children:
            self.fail(el.pos, "a <visual> needs a <geometry> with a box, cylinder, sphere or mesh.")
        shape = geometry.children[0]
        filename = None
        if shape.tag == "box":
            size = self.numbers(shape, "size", 3)
        elif shape.tag == "cylinder":
            size = self.numbers(shape, "radius", 1) + self.numbers(shape, "length", 1)
        elif shape.tag == "sphere":
            size = self.numbers(shape, "radius", 1)
        elif shape.tag == "mesh":
            filename = shape.attrs.get("filename")
            if not filename:
                self.fail(shape.pos, "a <mesh> needs a filename.")
            size = self.numbers(shape, "scale", 3, (1.0, 1.0, 1.0))
        else:
            self.fail(shape.pos, f"<{shape.tag}> is not a URDF geometry.", "use box, cylinder, sphere or mesh")
        material = el.first("material")
        color = material.first("color") if material is not None else None
        rgba = self.numbers(color, "rgba", 4) if color is not None else None
        return UrdfVisual(shape.tag, size, self.origin(el.first("origin")), filename, rgba, shape.pos)

    def link(self, el: _Element) -> UrdfLink:
        visuals = tuple(v for v in (self.visual(x) for x in el.all("visual")) if v is not None)
        return UrdfLink(self.name(el, "<link>"), visuals, el.pos)

    def joint(self, el: _Element) -> UrdfJoint:
        name = self.name(el, "<joint>")
        kind = el.attrs.get("type", "")
        if kind not in JOINT_TYPES:
            self.fail(
                el.pos,
                f'joint {name} has type "{kind}", which this importer does not take.',
                "it takes revolute, continuous, prismatic and fixed joints",
            )
        ends = {}
        where = []
        for role in ("parent", "child"):
            part = el.first(role)
            if part is None or not part.attrs.get("link"):
                self.fail(el.pos, f"joint {name} needs a <{role} link=...>.")
            ends[role] = part.attrs["link"]
            where.append(part.pos)
        axis_el = el.first("axis")
        axis = np.array(self.numbers(axis_el, "xyz", 3) if axis_el is not None else (1.0, 0.0, 0.0))
        norm = float(np.linalg.norm(axis))
        if kind != "fixed" and norm == 0.0:
            self.fail(axis_el.pos if axis_el is not None else el.pos, f"joint {name} has a zero axis.")
        axis = axis / norm if norm else np.array([1.0, 0.0, 0.0])
        lower = upper = 0.0
        if kind in ("revolute", "prismatic"):
            limit = el.first("limit")
            if limit is None:
                self.fail(el.pos, f"{kind} joint {name} needs a <limit lower=... upper=...>.")
            (lower,) = self.numbers(limit, "lower", 1, (0.0,))
            (upper,) = self.numbers(limit, "upper", 1, (0.0,))
            if lower > upper:
                self.fail(limit.pos, f"joint {name}'s lower limit {lower} is above its upper limit {upper}.")
        mimic = None
        mimic_el = el.first("mimic")
        if mimic_el is not None:
            other = mimic_el.attrs.get("joint")
            if not other:
                self.fail(mimic_el.pos, f"joint {name}'s <mimic> needs a joint.")
            (mult,) = self.numbers(mimic_el, "multiplier", 1, (1.0,))
            (offset,) = self.numbers(mimic_el, "offset", 1, (0.0,))
            mimic = (other, mult, offset)
        return UrdfJoint(
            name,
            kind,
            ends["parent"],
            ends["child"],
            self.origin(el.first("origin")),
            axis,
            lower,
            upper,
            mimic,
            el.pos,
            tuple(where),
        )


def parse_urdf(raw: bytes, filename: str) -> Urdf:
    """Parse and check the bytes of a URDF file (see the module's docstring).

    Raises
    ------
    LigDiagnostics
    """
    reader = _Reader(raw, filename)
    robot = reader.parse()
    link_els = robot.all("link")
    if not link_els:
        reader.fail(robot.pos, "the robot has no <link>.")
    if len(link_els) > MAX_URDF_LINKS:
        reader.fail(robot.pos, f"the robot has {len(link_els)} links, more than the {MAX_URDF_LINKS} imported.")
    links = [reader.link(el) for el in link_els]
    names: dict = {}
    for link in links:
        if link.name in names:
            reader.fail(
                link.pos, f"link {link.name} is defined twice.", f"the first is at line {names[link.name].line}"
            )
        names[link.name] = link.pos
    joints = [reader.joint(el) for el in robot.all("joint")]
    _check_tree(reader, links, joints, names)
    by_child = {j.child: j for j in joints}
    roots = [l.name for l in links if l.name not in by_child]
    return Urdf(
        robot.attrs.get("name", "robot"), tuple(links), tuple(joints), roots[0], filename, reader.text, by_child
    )


def _check_tree(reader: _Reader, links: list, joints: list, names: dict) -> None:
    """Every joint joins known links; each link is the child of at most one joint; one root; no cycle."""
    seen: dict = {}
    child_of: dict = {}
    for j in joints:
        if j.name in seen:
            reader.fail(j.pos, f"joint {j.name} is defined twice.", f"the first is at line {seen[j.name].line}")
        seen[j.name] = j.pos
        for role, link in (("parent", j.parent), ("child", j.child)):
            if link not in names:
                reader.fail(
                    j.end_pos(role), f"joint {j.name} names {role} link {link}, which the robot does not define."
                )
        if j.child in child_of:
            reader.fail(
                j.end_pos("child"),
                f"link {j.child} is the child of two joints, {child_of[j.child].name} and {j.name}: "
                "a URDF is a tree, so a closed chain cannot be written.",
            )
        if j.parent == j.child:
            reader.fail(j.pos, f"joint {j.name} joins link {j.child} to itself.")
        child_of[j.child] = j
    for j in joints:
        if j.mimic is not None and j.mimic[0] not in seen:
            reader.fail(j.pos, f"joint {j.name} mimics joint {j.mimic[0]}, which the robot does not define.")
    roots = [l for l in links if l.name not in child_of]
    if not roots:
        _refuse_cycle(reader, joints[0].child, child_of)
    if len(roots) > 1:
        reader.fail(
            roots[1].pos,
            f"the robot has {len(roots)} root links ({', '.join(l.name for l in roots[:6])}"
            f"{', ...' if len(roots) > 6 else ''}): a URDF is one tree.",
            "join the chains to one base link with fixed joints",
        )
    # One root and every other link the child of one joint: a cycle would leave links unreachable.
    reach = {roots[0].name}
    frontier = [roots[0].name]
    kids: dict = {}
    for j in joints:
        kids.setdefault(j.parent, []).append(j.child)
    while frontier:
        nxt = []
        for link in frontier:
            for c in kids.get(link, ()):
                if c not in reach:
                    reach.add(c)
                    nxt.append(c)
        frontier = nxt
    lost = [j for j in joints if j.child not in reach]
    if lost:
        _refuse_cycle(reader, lost[0].child, child_of)


def _refuse_cycle(reader: _Reader, link: str, child_of: dict) -> NoReturn:
    """Follow parents from ``link`` round the cycle it lies on; report the joint written last in it."""
    seen: list = []
    while link not in seen:
        seen.append(link)
        link = child_of[link].parent
    cycle = [child_of[l] for l in seen[seen.index(link) :]]
    last = max(cycle, key=lambda j: (j.pos.line, j.pos.column))
    path = " -> ".join(j.child for j in reversed(cycle)) + f" -> {cycle[-1].child}"
    reader.fail(
        last.end_pos("child"),
        f"joint {last.name} closes a cycle of joints ({path}): a URDF is a tree.",
        "a closed chain cannot be written in URDF; break it",
    )
