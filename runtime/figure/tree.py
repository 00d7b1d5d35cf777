"""Articulated figures (LIG ANIMATE's MODEL type): structure and model operations.

A figure is a tree whose nodes are *links* (rigid segments, each drawn from an
opaque host shape) and whose arcs are *joints*.  Everything here is an
immutable value: every operation returns a new :class:`Figure` and shares the
unchanged parts (links, read-only arrays) with its operand, so copying a
submodel into a bigger model (the thesis' value semantics for ``:-``) costs
no more than building a tuple.

Conventions (see ``docs/semantics-figure.md``):

* A joint joins a primary link P and a secondary link S at ``loc1`` (in P's
  coordinates) and ``loc2`` (in S's).  With angles ``(ax, ay, az)`` in
  degrees, a point ``p`` of S is ``loc1 + R (p - loc2)`` in P, where
  ``R = Rz(az) Ry(ay) Rx(ax)`` (right-hand rule).  Neutral is ``(0, 0, 0)``.
* ``extremes`` is a ``(3, 2)`` array of ``(min, max)`` degrees per axis.
* The *original* main link (``root``) is never a secondary; it fixes the tree's
  structure.  The *current* main link (``main``, changed by FIGURE) is where a
  pose is evaluated from: it sits at the origin of the model frame.
* ``placement`` is the host's 4x4 transform placing the current main link in
  the world.

Operations always produce figures whose links and joints are in pre-order
(depth first from the root, children in joint order), so ``links[0]`` is the
root and joint ``k`` introduces link ``k + 1``; the constructor accepts any
valid tree, though, and nothing relies on that order.
"""

from __future__ import annotations

import dataclasses
import operator
from collections.abc import Sequence
from functools import cached_property
from typing import NamedTuple, overload

import numpy as np

from liganimate.lang import messages
from liganimate.lang.node_methods import record
from liganimate.lang.numbers import INT_MAX, MAX_ANGLE, magnitude
from liganimate.runtime.errors import FigureError

__all__ = [
    "AXES",
    "Figure",
    "Joint",
    "JointKind",
    "JointSpec",
    "Link",
    "LinkSource",
    "TraversalLevel",
    "assemble",
    "frame_from_axis",
    "join",
    "normalize_extremes",
]

AXES = ("X", "Y", "Z")


# --------------------------------------------------------------------------
# small helpers
# --------------------------------------------------------------------------


@overload
def _key(name: str) -> str: ...
@overload
def _key(name: None) -> None: ...
def _key(name: str | None) -> str | None:
    # LIG ANIMATE translates identifiers to upper case, so FOOT and foot are
    # the same segment name.
    return None if name is None else name.upper()


def _num(x: float) -> str:
    """Short decimal form for PRINT output (``-0`` printed as ``0``)."""
    x = float(x)
    if x == 0.0:
        return "0"
    return f"{x:.6g}"


def _vec(v) -> str:
    return "(" + ", ".join(_num(x) for x in v) + ")"


def _frozen(value, shape: tuple[int, ...], what: str) -> np.ndarray:
    """A finite, read-only float array of ``shape`` (reused when it already is one)."""
    if (
        isinstance(value, np.ndarray)
        and value.dtype == np.float64
        and value.shape == shape
        and not value.flags.writeable
    ):
        # Structural sharing: read-only arrays coming from another figure are
        # never copied again.
        return value
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise FigureError(f"{what} must be numbers of shape {shape}.") from exc
    if arr.shape != shape:
        raise FigureError(f"{what} must have shape {shape}, not {arr.shape}.")
    if not np.all(np.isfinite(arr)):
        # Never the array itself in the sentence: a diagnostic is one plain line.
        bad = arr[~np.isfinite(arr)].flat[0]
        raise FigureError(f"{what} must be finite numbers; one of them is {bad}.")
    arr = arr + 0.0  # turns -0.0 into 0.0 so printing and comparisons stay tidy
    arr.setflags(write=False)
    return arr


def _joint_id(value) -> int:
    if isinstance(value, bool):
        raise FigureError(f"a joint identifier must be an integer, not {value!r}.")
    try:
        return operator.index(value)
    except TypeError as exc:
        raise FigureError(f"a joint identifier must be an integer, not {value!r}.") from exc


def frame_from_axis(axis) -> np.ndarray:
    """The joint axes an ``AXIS (x, y, z)`` clause gives: the shortest turn taking X onto the axis.

    Parameters
    ----------
    axis : array_like, shape (3,)
        Any non-zero finite vector; it is normalised.

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        A rotation whose first column is the unit axis.  The other two
        columns are where the shortest rotation from X onto the axis takes
        Y and Z (for the axis -X, a half turn about Z), so the same axis
        always gives the same joint.

    Raises
    ------
    FigureError
        If the axis is zero, not finite or not three numbers.
    """
    try:
        a = np.array(axis, dtype=float)
    except (TypeError, ValueError) as exc:
        raise FigureError("a joint's AXIS must be a vector (x, y, z).") from exc
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise FigureError("a joint's AXIS must be a vector of three finite numbers.")
    norm = float(np.linalg.norm(a))
    if norm == 0.0 or not np.isfinite(norm):
        raise FigureError(
            "a joint's AXIS must not be the zero vector.", hint="give the direction the joint works along"
        )
    a = a / norm
    c = float(a[0])
    v = np.array([0.0, -a[2], a[1]])  # e_x cross a
    s2 = float(v @ v)  # sin^2 of the turn, exact to rounding however small
    if s2 == 0.0 and c < 0.0:
        return np.diag([-1.0, -1.0, 1.0])
    # 1 + c cancels near the axis -X (pybullet's Laikago has axes 6e-6 from it, where 1 + c lost
    # six digits and the frame was off by 1e-6): 1 + c = sin^2 / (1 - c) keeps every digit.
    one_plus_c = s2 / (1.0 - c) if c < 0.0 else 1.0 + c
    vx = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    R = np.eye(3) + vx + vx @ vx / one_plus_c
    R[:, 0] = a  # exactly the given direction
    return R


def normalize_extremes(extremes, slide: bool = False) -> np.ndarray:
    """Turn the extremes written in a JOINT statement into a ``(3, 2)`` array.

    Parameters
    ----------
    extremes : array_like, shape (k, 2) with k in 1..3, or (2,)
        ``(min, max)`` degree pairs for the X, Y and Z axes in that order.  A
        bare pair is the X pair.

    Returns
    -------
    numpy.ndarray, shape (3, 2)
        Read-only.  Omitted trailing axes are *locked* at ``(0, 0)``: the
        thesis' arm examples give only X and Y pairs for a joint that should
        not turn about Z.

    Raises
    ------
    FigureError
        If there are no pairs or more than three, a value is not finite, or a
        pair has its minimum above its maximum (the message names the axis).
    """
    if isinstance(extremes, np.ndarray) and extremes.shape == (3, 2) and not extremes.flags.writeable:
        return extremes
    unit = "lengths" if slide else "degrees"
    try:
        arr = np.array(extremes, dtype=float)
    except (TypeError, ValueError) as exc:
        raise FigureError(
            f"joint extremes must be one to three (min, max) pairs of {unit}.",
            hint="write them as (min, max), (min, max), (min, max) for X, Y and Z",
        ) from exc
    if arr.shape == (2,):
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 2 or not 1 <= arr.shape[0] <= 3:
        raise FigureError(
            f"joint extremes must be one to three (min, max) pairs of {unit}, not an array of shape {arr.shape}.",
            hint="write them as (min, max), (min, max), (min, max) for X, Y and Z",
        )
    if not np.all(np.isfinite(arr)):
        raise FigureError(f"joint extremes must be finite numbers of {unit}.")
    if not np.all(np.abs(arr) <= MAX_ANGLE):
        raise FigureError(
            f"joint extremes must lie within ±{magnitude(MAX_ANGLE)} {unit}.",
            hint=None if slide else "a range of 360 degrees or more already lets the joint turn freely",
        )
    out = np.zeros((3, 2))
    out[: arr.shape[0]] = arr
    for axis in range(3):
        lo, hi = out[axis]
        if lo > hi:
            raise FigureError(
                f"the {AXES[axis]} extremes ({_num(lo)}, {_num(hi)}) have their minimum above their maximum.",
                hint=f"write the pair as ({_num(hi)}, {_num(lo)})",
            )
    out = out + 0.0
    out.setflags(write=False)
    return out


# --------------------------------------------------------------------------
# values
# --------------------------------------------------------------------------


class LinkSource(NamedTuple):
    """A link's name and channels in the file it came from (see :attr:`Link.source`).

    Attributes
    ----------
    name : str
        The name as the source spelled it (any characters).
    channels : tuple of str
        Its BVH channels in the source's order (empty when unknown).
    end : tuple of 3 floats or None
        Its BVH End Site offset, for a leaf that had one.
    joint : str or None
        The name of the source's joint that attaches it (URDF).
    rpy : tuple of 3 floats or None
        The source link frame's turn from this link's frame, as URDF roll,
        pitch and yaw in radians (URDF: LIG link frames keep their
        primary's orientation at neutral, a URDF link's need not).
    mimic : tuple or None
        For a URDF mimic joint: ``(leader's name, multiplier, offset)``.
    """

    name: str
    channels: tuple = ()
    end: tuple | None = None
    joint: str | None = None
    rpy: tuple | None = None
    mimic: tuple | None = None  # (leader joint's source name, multiplier, offset)


@record(frozen=True, eq=False)
class Link:
    """A rigid segment of a figure.

    Parameters
    ----------
    name : str or None
        The host graphical variable the segment was drawn from, or ``None``
        for an anonymous expression.  Compared case-insensitively.
    shape : object
        The host graphical object; opaque here, drawn by the renderer.
    scale : float, default 1.0
        Uniform factor the renderer applies to ``shape``'s coordinates before
        the link's pose (SCALE MODEL accumulates here; negative mirrors).
    source : LinkSource or None
        How the link was written in the file it was imported from (a BVH
        joint's own name, such as ``mixamorig:Hips``, and its channels), so
        that export gives the names back; None for a link made in LIG.  A
        library's name table sets it (see docs/exchange.md, "Names").
    """

    name: str | None
    shape: object
    scale: float = 1.0
    source: LinkSource | None = None

    def __post_init__(self) -> None:
        if self.name is not None and not isinstance(self.name, str):
            raise FigureError(f"a link name must be a string or None, not {self.name!r}.")
        scale = float(self.scale)
        if not np.isfinite(scale) or scale == 0.0:
            raise FigureError(f"a link's scale must be a finite non-zero number, not {self.scale!r}.")
        object.__setattr__(self, "scale", scale)

    @property
    def label(self) -> str:
        """The name for messages and PRINT (``<anonymous>`` when unnamed)."""
        return self.name if self.name is not None else "<anonymous>"


@record(frozen=True, eq=False)
class Joint:
    """A joint between two links of a figure.

    Parameters
    ----------
    id : int
        The joint identifier used by motions (unique within a figure).
    primary, secondary : int
        Indices into the figure's ``links``: the stationary and the moving link.
    loc1 : array_like, shape (3,)
        The joint's location in the primary link's coordinates.
    loc2 : array_like, shape (3,)
        The joint's location in the secondary link's coordinates.
    extremes : array_like, shape (k, 2), k in 1..3
        ``(min, max)`` per axis, degrees (a slide: lengths); see
        :func:`normalize_extremes`.  Stored as a read-only ``(3, 2)`` array.
    slide : bool, default False
        A prismatic joint: its three values are a displacement of S along
        the joint's X, Y and Z axes instead of angles about them.
    axes : array_like, shape (3, 3), optional
        The joint's own axes as the columns of a rotation, in P's
        coordinates (identity when None, the thesis' joint); written
        ``AXIS (x, y, z)`` in a JOINT, which sets the X axis (see
        :func:`frame_from_axis`).
    slide_scale : float, default 1.0
        What a slide's displacement is multiplied by (SCALE MODEL multiplies
        it, so displacements scale with the model).
    """

    id: int
    primary: int
    secondary: int
    loc1: np.ndarray
    loc2: np.ndarray
    extremes: np.ndarray
    slide: bool = False
    axes: np.ndarray | None = None
    slide_scale: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "id", _joint_id(self.id))
        object.__setattr__(self, "primary", operator.index(self.primary))
        object.__setattr__(self, "secondary", operator.index(self.secondary))
        object.__setattr__(self, "loc1", _frozen(self.loc1, (3,), f"the primary location of joint {self.id}"))
        object.__setattr__(self, "loc2", _frozen(self.loc2, (3,), f"the secondary location of joint {self.id}"))
        object.__setattr__(self, "slide", bool(self.slide))
        object.__setattr__(self, "slide_scale", float(self.slide_scale))
        if self.axes is not None:
            axes = _frozen(self.axes, (3, 3), f"the axes of joint {self.id}")
            object.__setattr__(self, "axes", None if np.array_equal(axes, np.eye(3)) else axes)
        try:
            object.__setattr__(self, "extremes", normalize_extremes(self.extremes, slide=self.slide))
        except FigureError as exc:
            # Say which joint: a model block may hold dozens of JOINT statements.
            raise FigureError(f"joint {self.id}: {exc.message}", exc.hint) from None

    @property
    def kind(self) -> str:
        """``"slide"`` for a prismatic joint, ``"turn"`` for the thesis' rotational one."""
        return "slide" if self.slide else "turn"


class TraversalLevel(NamedTuple):
    """One depth level of a figure walked from its current main link.

    All arrays have shape ``(k,)``: the level's ``k`` joints (indices into
    ``Figure.joints``), the already-placed link each starts from, the link it
    reaches, and whether the joint is walked backwards (secondary to primary),
    in which case its inverse transform applies.
    """

    joints: np.ndarray
    parents: np.ndarray
    children: np.ndarray
    reversed: np.ndarray


@record(frozen=True)
class JointKind:
    """What a JOINT statement says beyond its extremes: SLIDE and AXIS.

    Parameters
    ----------
    slide : bool, default False
        ``SLIDE``: a prismatic joint.
    axis : array_like, shape (3,), optional
        ``AXIS (x, y, z)``: the joint's X axis (see :func:`frame_from_axis`).
    """

    slide: bool = False
    axis: object = None

    def fields(self, joint_id) -> dict:
        """The :class:`Joint` keyword arguments for this kind (the error names the joint)."""
        try:
            axes = None if self.axis is None else frame_from_axis(self.axis)
        except FigureError as exc:
            raise FigureError(f"joint {joint_id}: {exc.message}", exc.hint) from None
        return {"slide": self.slide, "axes": axes}


TURN = JointKind()


class JointSpec(NamedTuple):
    """One JOINT statement inside STARTMODEL ... ENDMODEL (see :func:`assemble`)."""

    joint_id: int
    primary_name: str
    loc1: object
    secondary: object  # str (a graphical object's name) or Figure (a submodel)
    secondary_shape: object
    loc2: object
    extremes: object
    statement_index: int
    slide: bool = False
    axis: object = None  # AXIS (x, y, z), or None


@record(frozen=True, eq=False)
class Figure:
    """An articulated model: a tree of links joined by joints.

    Parameters
    ----------
    links : sequence of Link, length n_links >= 1
    joints : sequence of Joint, length n_links - 1
        Their ``primary``/``secondary`` index ``links``.  The order is the
        figure's *joint order*: angle arrays are ``(..., n_joints, 3)`` in it.
    root : int, default 0
        The original main link; never a secondary.
    main : int, optional
        The current main link (default ``root``).
    placement : array_like, shape (4, 4), optional
        Host transform placing the current main link in the world
        (default identity).

    Figures are compared by identity; all array attributes are read-only.

    Raises
    ------
    FigureError
        If the links and joints do not form one tree rooted at ``root`` or two
        joints share an identifier.
    """

    links: tuple[Link, ...]
    joints: tuple[Joint, ...] = ()
    root: int = 0
    # None means the root; __post_init__ always stores an int, which is what readers see.
    main: int = None  # type: ignore[assignment]
    placement: np.ndarray | None = None

    def __post_init__(self) -> None:
        links = tuple(self.links)
        joints = tuple(self.joints)
        object.__setattr__(self, "links", links)
        object.__setattr__(self, "joints", joints)
        if not links or not all(isinstance(l, Link) for l in links):
            raise FigureError("a figure needs at least one link, and every link must be a Link.")
        if not all(isinstance(j, Joint) for j in joints):
            raise FigureError("every joint of a figure must be a Joint.")
        n = len(links)
        root = operator.index(self.root)
        main = root if self.main is None else operator.index(self.main)
        if not (0 <= root < n and 0 <= main < n):
            raise FigureError(f"the main links ({root}, {main}) must index the figure's {n} links.")
        object.__setattr__(self, "root", root)
        object.__setattr__(self, "main", main)
        placement = np.eye(4) if self.placement is None else self.placement
        object.__setattr__(self, "placement", _frozen(placement, (4, 4), "a figure's placement"))
        self._check_tree()

    def _check_tree(self) -> None:
        n = len(self.links)
        if len(self.joints) != n - 1:
            raise FigureError(f"a tree of {n} links needs {n - 1} joints, not {len(self.joints)}.")
        seen_ids: dict[int, int] = {}
        for k, j in enumerate(self.joints):
            if j.id in seen_ids:
                raise FigureError(
                    f"joint identifier {j.id} is used twice in one model.",
                    hint="translate one submodel's identifiers with <TRANS JOINTS BY n>",
                )
            seen_ids[j.id] = k
            if not (0 <= j.primary < n and 0 <= j.secondary < n) or j.primary == j.secondary:
                raise FigureError(f"joint {j.id} must join two different links of the figure.")
        # n - 1 joints that reach every link from the root form one tree: no
        # cycle and no loose piece.  A joint may point either way along it (a
        # submodel attached by the main link FIGURE chose keeps its joints as
        # they were defined), so the walk ignores the joints' directions.
        if len(self.preorder) != n:
            raise FigureError("the joints do not connect every link to the main link in one tree.")

    @classmethod
    def _grafted(cls, links: tuple, joints: tuple, base: Figure, index: dict[int, int]) -> Figure:
        """A figure made by :func:`_graft`, without re-checking its tree.

        Attaching one valid tree below a link of another by one new joint
        gives a valid tree, and ``_graft`` has checked the identifiers
        (``index``); re-walking every joint here would make building a model
        one JOINT at a time quadratic in its joints.
        """
        fig = object.__new__(cls)
        for name, value in (
            ("links", links),
            ("joints", joints),
            ("root", base.root),
            ("main", base.main),
            ("placement", base.placement),
        ):
            object.__setattr__(fig, name, value)
        fig.__dict__["_id_index"] = index
        return fig

    # ----------------------------------------------------------------- structure

    @classmethod
    def from_link(cls, link: Link) -> Figure:
        """A one-link figure (a graphical object used where a model is expected)."""
        return cls((link,))

    @property
    def n_links(self) -> int:
        """Number of links."""
        return len(self.links)

    @property
    def n_joints(self) -> int:
        """Number of joints (``n_links - 1``)."""
        return len(self.joints)

    @cached_property
    def joint_ids(self) -> tuple[int, ...]:
        """Joint identifiers in the figure's joint order."""
        return tuple(j.id for j in self.joints)

    @cached_property
    def _id_index(self) -> dict[int, int]:
        return {jid: k for k, jid in enumerate(self.joint_ids)}

    def joint_index(self, joint_id: int) -> int:
        """Position of joint ``joint_id`` in the joint order.

        Raises
        ------
        FigureError
            If the figure has no such joint (the message lists the ids).
        """
        try:
            return self._id_index[_joint_id(joint_id)]
        except KeyError:
            raise FigureError(
                f"the model has no joint {joint_id}.",
                hint=f"its joints are {', '.join(map(str, sorted(self.joint_ids))) or 'none'}",
            ) from None

    def joint(self, joint_id: int) -> Joint:
        """The :class:`Joint` with identifier ``joint_id``."""
        return self.joints[self.joint_index(joint_id)]

    @cached_property
    def _rooted(self) -> tuple[tuple[int, ...], tuple[tuple[int, ...], ...], tuple[int, ...]]:
        """The tree hung from the root: parent joint per link, child joints per link, pre-order.

        The joints are walked as undirected arcs (the thesis' nodes hold each
        arc at both ends), so a joint whose defined secondary is nearer the
        root (see :attr:`inverted`) is a child arc of that secondary.  One
        walk, linear in the number of links.
        """
        n = len(self.links)
        incident: list[list[int]] = [[] for _ in range(n)]
        for k, j in enumerate(self.joints):
            if 0 <= j.primary < n and 0 <= j.secondary < n:
                incident[j.primary].append(k)
                incident[j.secondary].append(k)
        parent = [-1] * n
        children: list[list[int]] = [[] for _ in range(n)]
        order: list[int] = []
        seen = [False] * n
        seen[self.root] = True
        stack = [self.root]
        while stack:
            link = stack.pop()
            order.append(link)
            for k in incident[link]:
                j = self.joints[k]
                other = j.secondary if j.primary == link else j.primary
                if not seen[other]:  # in a malformed joint list an arc may close a cycle
                    seen[other] = True
                    parent[other] = k
                    children[link].append(k)
            stack.extend(self._far_end(k, link) for k in reversed(children[link]))
        return tuple(parent), tuple(tuple(c) for c in children), tuple(order)

    def _far_end(self, k: int, link: int) -> int:
        j = self.joints[k]
        return j.secondary if j.primary == link else j.primary

    @property
    def _parent_joint(self) -> tuple[int, ...]:
        return self._rooted[0]

    @property
    def _child_joints(self) -> tuple[tuple[int, ...], ...]:
        return self._rooted[1]

    def parent_joint_of(self, link: int) -> Joint | None:
        """The joint that hangs ``link`` from the ORIGINAL structure's root side (None for the root).

        ``link`` is that joint's secondary unless the joint is :attr:`inverted`.
        """
        k = self._parent_joint[link]
        return None if k < 0 else self.joints[k]

    def child_joints_of(self, link: int) -> tuple[Joint, ...]:
        """The joints that hang links from ``link`` in the ORIGINAL structure, in joint order.

        ``link`` is their primary unless a joint is :attr:`inverted`.
        """
        return tuple(self.joints[k] for k in self._child_joints[link])

    def child_of(self, joint: Joint) -> int:
        """The link ``joint`` hangs from the root's side: its secondary, or its primary if inverted."""
        k = self.joint_index(joint.id)
        return joint.primary if self.inverted[k] else joint.secondary

    def parent_of(self, joint: Joint) -> int:
        """The link ``joint`` hangs from on the root's side: its primary, or its secondary if inverted."""
        k = self.joint_index(joint.id)
        return joint.secondary if self.inverted[k] else joint.primary

    @cached_property
    def inverted(self) -> np.ndarray:
        """Per joint, whether its defined secondary is on the root's side, shape ``(n_joints,)``, read-only.

        Only a submodel attached by the main link FIGURE chose for it has
        such joints: the ones between that link and the submodel's original
        main link.  They keep their definition (the motions' angles mean
        what they meant), and a walk from the root takes them backwards,
        as FIGURE ... MAIN makes a walk from the current main link do.
        """
        out = np.zeros(len(self.joints), dtype=bool)
        parent = self._parent_joint
        for k, j in enumerate(self.joints):
            out[k] = parent[j.primary] == k
        out.setflags(write=False)
        return out

    def joint_naming(self, link: int) -> Joint | None:
        """A joint whose defined secondary is ``link`` (what FIGURE m MAIN JOINT needs), or None.

        The parent joint when it is not inverted; else another joint of the
        link's, if one has it as its secondary.
        """
        up = self.parent_joint_of(link)
        if up is not None and up.secondary == link:
            return up
        return next((j for j in self.child_joints_of(link) if j.secondary == link), None)

    @property
    def preorder(self) -> tuple[int, ...]:
        """Link indices depth first from the root, children in joint order."""
        return self._rooted[2]

    def links_named(self, name: str) -> tuple[int, ...]:
        """Indices of the links called ``name`` (case-insensitive), in :attr:`preorder`."""
        key = _key(name)
        return tuple(i for i in self.preorder if _key(self.links[i].name) == key)

    @cached_property
    def extremes(self) -> np.ndarray:
        """All joints' extremes, shape ``(n_joints, 3, 2)``, read-only."""
        arr = np.array([j.extremes for j in self.joints]).reshape(len(self.joints), 3, 2)
        arr.setflags(write=False)
        return arr

    @cached_property
    def slides(self) -> np.ndarray:
        """Per joint, whether it is prismatic (a slide), shape ``(n_joints,)``, read-only."""
        arr = np.array([j.slide for j in self.joints], dtype=bool)
        arr.setflags(write=False)
        return arr

    @cached_property
    def frames(self) -> np.ndarray:
        """Every joint's axes (identity unless AXIS gave them), shape ``(n_joints, 3, 3)``, read-only."""
        arr = np.array([np.eye(3) if j.axes is None else j.axes for j in self.joints]).reshape(len(self.joints), 3, 3)
        arr.setflags(write=False)
        return arr

    @cached_property
    def has_frames(self) -> np.ndarray:
        """Per joint, whether AXIS turned its axes away from the primary's, shape ``(n_joints,)``."""
        arr = np.array([j.axes is not None for j in self.joints], dtype=bool)
        arr.setflags(write=False)
        return arr

    @cached_property
    def slide_scales(self) -> np.ndarray:
        """Per joint, the factor a slide's displacement is multiplied by, shape ``(n_joints,)``."""
        arr = np.array([j.slide_scale for j in self.joints], dtype=float)
        arr.setflags(write=False)
        return arr

    @cached_property
    def locations(self) -> tuple[np.ndarray, np.ndarray]:
        """``(loc1, loc2)`` of all joints, each shape ``(n_joints, 3)``, read-only."""
        loc1 = np.array([j.loc1 for j in self.joints]).reshape(len(self.joints), 3)
        loc2 = np.array([j.loc2 for j in self.joints]).reshape(len(self.joints), 3)
        loc1.setflags(write=False)
        loc2.setflags(write=False)
        return loc1, loc2

    @cached_property
    def link_scales(self) -> np.ndarray:
        """Per-link geometry scale factors, shape ``(n_links,)``."""
        arr = np.array([l.scale for l in self.links])
        arr.setflags(write=False)
        return arr

    @cached_property
    def traversal(self) -> tuple[TraversalLevel, ...]:
        """The tree walked breadth first from the CURRENT main link, level by level.

        A joint met from its secondary side is marked ``reversed``: it is
        walked from S to P and its inverse transform applies.  This is what
        makes FIGURE ... MAIN work without any sign bookkeeping.
        """
        adjacency: list[list[tuple[int, int, bool]]] = [[] for _ in self.links]
        for k, j in enumerate(self.joints):
            adjacency[j.primary].append((k, j.secondary, False))
            adjacency[j.secondary].append((k, j.primary, True))
        levels = []
        frontier = [self.main]
        visited = {self.main}
        while True:
            rows = []
            for link in frontier:
                for k, other, rev in adjacency[link]:
                    if other not in visited:
                        visited.add(other)
                        rows.append((k, link, other, rev))
            if not rows:
                break
            ks, parents, children, revs = (np.array(c) for c in zip(*rows))
            levels.append(
                TraversalLevel(ks.astype(np.intp), parents.astype(np.intp), children.astype(np.intp), revs.astype(bool))
            )
            frontier = [r[2] for r in rows]
        return tuple(levels)

    @cached_property
    def reversed_joints(self) -> np.ndarray:
        """Per joint, whether it is walked secondary to primary from the current main link, shape ``(n_joints,)``."""
        rev = np.zeros(len(self.joints), dtype=bool)
        for level in self.traversal:
            rev[level.joints] = level.reversed
        rev.setflags(write=False)
        return rev

    # ----------------------------------------------------------------- placement

    def with_placement(self, matrix) -> Figure:
        """The same figure with host placement ``matrix`` (shape (4, 4))."""
        return dataclasses.replace(self, placement=_frozen(matrix, (4, 4), "a figure's placement"))

    def placed(self, matrix) -> Figure:
        """Apply host transform ``matrix`` (shape (4, 4)) after the current placement.

        ``HUMAN :- HUMAN <TRANS (v)>`` is ``human.placed(translation(v))``: the
        new placement is ``matrix @ placement``.
        """
        m = _frozen(matrix, (4, 4), "a host transform")
        return dataclasses.replace(self, placement=m @ self.placement)

    # ----------------------------------------------------------------- transformations

    def trans_joints(self, n: int) -> Figure:
        """TRANS JOINTS BY ``n``: add ``n`` to every joint identifier."""
        n = _joint_id(n)
        ids = [j.id + n for j in self.joints]
        if ids and not -INT_MAX <= min(ids) <= max(ids) <= INT_MAX:
            raise FigureError(f"TRANS JOINTS {n} makes a joint identifier outside the INTEGER range ±{INT_MAX}.")
        return dataclasses.replace(self, joints=tuple(dataclasses.replace(j, id=i) for j, i in zip(self.joints, ids)))

    def scale_model(self, r: float) -> Figure:
        """SCALE MODEL ``r``: scale every link's geometry and every joint location by ``r``.

        The links' frames stay rigid: the factor is recorded on each
        :class:`Link` for the renderer and the joint locations are scaled, so
        the whole posed figure becomes ``r`` times itself.  A negative ``r``
        gives a mirror image (a point reflection, i.e. a plane mirror followed
        by a half turn).

        Raises
        ------
        FigureError
            If ``r`` is zero or not finite.
        """
        r = float(r)
        if not np.isfinite(r) or r == 0.0:
            raise FigureError(
                f"SCALE MODEL needs a finite non-zero factor, not {_num(r) if np.isfinite(r) else r}.",
                hint="a zero factor would shrink the model to a point",
            )
        links = tuple(dataclasses.replace(l, scale=l.scale * r) for l in self.links)
        # A slide's displacement scales with the model, so the scaled figure
        # is r times the original at every pose, slides included.
        joints = tuple(
            dataclasses.replace(j, loc1=j.loc1 * r, loc2=j.loc2 * r, slide_scale=j.slide_scale * r) for j in self.joints
        )
        return dataclasses.replace(self, links=links, joints=joints)

    def with_sources(self, sources: dict) -> Figure:
        """The same figure with each named link's :attr:`Link.source` set.

        Parameters
        ----------
        sources : dict of str to LinkSource
            By link name (case-insensitive); links not in it are unchanged.
        """
        table = {k.upper(): v for k, v in sources.items()}
        if not table:
            return self
        links = tuple(
            dataclasses.replace(l, source=table[_key(l.name)]) if _key(l.name) in table else l for l in self.links
        )
        return dataclasses.replace(self, links=links)

    def scale_extremes(self, r: float) -> Figure:
        """SCALE EXTREMES ``r``: multiply every joint extreme by ``r``.

        A negative ``r`` mirrors the ranges: ``(a, b) * -1 == (-b, -a)``.
        Zero locks every joint at neutral.
        """
        r = float(r)
        if not np.isfinite(r):
            raise FigureError(f"SCALE EXTREMES needs a finite factor, not {r}.")

        def scaled(ext: np.ndarray) -> np.ndarray:
            out = ext * r
            return out[:, ::-1] if r < 0 else out  # keep each pair (min, max)

        return dataclasses.replace(
            self, joints=tuple(dataclasses.replace(j, extremes=scaled(j.extremes)) for j in self.joints)
        )

    # ----------------------------------------------------------------- main link

    def with_main(self, link: int) -> Figure:
        """The figure animated from link index ``link`` (the structure is unchanged)."""
        link = operator.index(link)
        if not 0 <= link < len(self.links):
            raise FigureError(f"the model has no link number {link}.")
        return dataclasses.replace(self, main=link)

    def with_original_main(self) -> Figure:
        """FIGURE m MAIN: animate from the original main link again."""
        return dataclasses.replace(self, main=self.root)

    def with_main_joint(self, joint_id: int) -> Figure:
        """FIGURE m MAIN JOINT ``joint_id``: the joint's secondary link becomes main.

        Raises
        ------
        FigureError
            If the model has no such joint.
        """
        return self.with_main(self.joint(joint_id).secondary)

    def with_main_link(self, name: str, *, model_name: str | None = None) -> tuple[Figure, str | None]:
        """FIGURE m MAIN LINK ``name``.

        Parameters
        ----------
        name : str
            A link name (case-insensitive).
        model_name : str, optional
            The model variable, used in the warning's suggestion.

        Returns
        -------
        figure : Figure
            The figure animated from the chosen link.
        warning : str or None
            When several links bear ``name``: which one was chosen and how to
            choose another.  The first one met depth first from the original
            main link, children in joint order, is chosen.

        Raises
        ------
        FigureError
            If no link is called ``name`` (the message lists the closest names).
        """
        found = self.links_named(name)
        if not found:
            names = sorted({l.name.upper() for l in self.links if l.name is not None})
            # Link names are short and often abbreviated: a looser match than for program names.
            hint = messages.did_you_mean(name, names, cutoff=0.5)
            raise FigureError(
                f"the model has no link named {name}.",
                hint=hint or f"its links are named {', '.join(names) or 'nothing'}",
            )
        chosen = found[0]
        warning = None
        if len(found) > 1:
            m = model_name or "m"
            parent = self.parent_joint_of(chosen)
            which = "the original main link itself" if parent is None else f"the one attached by joint {parent.id}"
            # MAIN JOINT j chooses j's defined secondary; a link that is no
            # joint's secondary (a re-rooted submodel's old main link) has none.
            alts = [str(j.id) for i in found[1:] if (j := self.joint_naming(i)) is not None]
            more = f" (or {', '.join(alts[1:])})" if len(alts) > 1 else ""
            advice = (
                f"write FIGURE {m} MAIN JOINT {alts[0]}{more} to choose another."
                if alts
                else "no FIGURE MAIN JOINT chooses the others: rename a segment to tell them apart."
            )
            warning = (
                f"{len(found)} links are named {name}; FIGURE {m} MAIN LINK {name} uses {which} "
                f"(the first met depth first from the original main link {self.links[self.root].label}); " + advice
            )
        return self.with_main(chosen), warning

    # ----------------------------------------------------------------- PRINT

    def describe_tree(self, name: str | None = None) -> str:
        """The model's internal node relationships, as PRINT m shows them (thesis Figure 6).

        One block per link in :attr:`preorder`: the link's graphical object,
        scale and number of subjoints, then its arcs: row 0 is the joint that
        hangs it from the root's side (the upward arc), rows 1..n the joints
        that hang links from it, each with the joint id (marked ``reversed``
        where the joint's defined secondary is on the root's side), the node
        at the other end and the joint's location on THIS link.
        """
        head = f"MODEL {name}: " if name else "MODEL: "
        lines = [
            (
                f"{head}{self.n_links} links, {self.n_joints} joints; "
                f"original main link {self.links[self.root].label} (node {self.root}); "
                f"current main link {self.links[self.main].label} (node {self.main})"
            )
        ]
        for i in self.preorder:
            link = self.links[i]
            tags = []
            if i == self.root:
                tags.append("original main link")
            if i == self.main:
                tags.append("current main link")
            children = self.child_joints_of(i)
            lines.append(
                f"Node {i}: {link.label}  scale {_num(link.scale)}  subjoints {len(children)}"
                + (f"  [{', '.join(tags)}]" if tags else "")
            )
            rows = [("No.", "Joint #", "Node", "Joint location")]
            up = self.parent_joint_of(i)
            arcs = [] if up is None else [(0, up)]
            if up is None:
                rows.append(("0", "-", "-", "-"))
            arcs += list(enumerate(children, start=1))
            for n, j in arcs:
                # An arc taken against its definition (a re-rooted submodel's)
                # says so: its angles turn this link's other end the other way.
                other, here = (j.primary, j.loc2) if j.secondary == i else (j.secondary, j.loc1)
                flipped = self.inverted[self.joint_index(j.id)]
                rows.append(
                    (
                        str(n),
                        str(j.id) + (" reversed" if flipped else ""),
                        f"{other} {self.links[other].label}",
                        _vec(here),
                    )
                )
            lines.extend(_table(rows, indent="    "))
        return "\n".join(lines)

    def describe_table(self, angles=None, velocity=None, acceleration=None) -> str:
        """The model's symbol table, as PRINT $m shows it (thesis Figure 8).

        Parameters
        ----------
        angles, velocity, acceleration : array_like, shape (n_joints, 3), optional
            Current values per joint (in joint order) and axis; zeros when
            omitted.  Anything broadcastable to ``(n_joints, 3)`` is accepted.

        Returns
        -------
        str
            One row per joint: id, current orientation, X/Y/Z extremes,
            velocity and acceleration.
        """
        shape = (self.n_joints, 3)
        cols = [
            np.broadcast_to(np.asarray(0.0 if a is None else a, dtype=float), shape)
            for a in (angles, velocity, acceleration)
        ]
        rows = [
            (
                "Joint #",
                "Current orientation",
                "X extremes",
                "Y extremes",
                "Z extremes",
                "Current velocity",
                "Current acceleration",
            )
        ]
        for k, j in enumerate(self.joints):
            rows.append(
                (
                    f"No. {j.id}" + _kind_note(j),
                    _vec(cols[0][k]),
                    _vec(j.extremes[0]),
                    _vec(j.extremes[1]),
                    _vec(j.extremes[2]),
                    _vec(cols[1][k]),
                    _vec(cols[2][k]),
                )
            )
        return "\n".join(_table(rows))


def _kind_note(j: Joint) -> str:
    """What PRINT $m adds after a joint's number: nothing for the thesis' joint."""
    note = " SLIDE" if j.slide else ""
    if j.axes is not None:
        note += " AXIS " + _vec(j.axes[:, 0])
    return note


def _table(rows: Sequence[tuple[str, ...]], indent: str = "") -> list[str]:
    widths = [max(len(r[c]) for r in rows) for c in range(len(rows[0]))]
    return [indent + "  ".join(cell.ljust(w) for cell, w in zip(r, widths)).rstrip() for r in rows]


# --------------------------------------------------------------------------
# building figures
# --------------------------------------------------------------------------


def _as_figure(operand, role: str) -> Figure:
    if isinstance(operand, Figure):
        return operand
    if isinstance(operand, Link):
        return Figure.from_link(operand)
    raise FigureError(f"the {role} of a JOINT must be a graphical object or a model, not {type(operand).__name__}.")


def _rehung(sub: Figure) -> Figure:
    """``sub`` as a JOINT takes it: hung from its CURRENT main link, placement dropped.

    The thesis gives a submodel's joint location "with respect to the main
    link in the submodel", and FIGURE "assigns a new link as the model's main
    link", so the submodel joins by the link FIGURE chose.  Its joints keep
    their definitions; those between that link and the old main link are
    then walked backwards from the new root (:attr:`Figure.inverted`).
    """
    if sub.main == sub.root:
        return sub  # its placement and main are never read by the callers
    return _canonical(list(sub.links), list(sub.joints), sub.main)


def _graft(base: Figure, at: int, joint_id, loc1, sub: Figure, loc2, extremes, kind: JointKind) -> Figure:
    """Attach ``sub`` by its CURRENT main link to link ``at`` of ``base``.

    Keeps ``base``'s root, current main and placement.  If ``at`` is the root
    (as in :func:`join`) and ``base`` is in pre-order, so is the result: the
    new joint is the root's last child and ``sub``'s links follow, in
    pre-order from the link it is attached by.
    """
    sub = _rehung(sub)
    new = Joint(joint_id, at, len(base.links) + sub.root, loc1, loc2, extremes, **kind.fields(joint_id))
    # The result's identifier index is the base's, copied at C speed, plus the
    # new joint and sub's: Python-level work is O(1 + sub's joints), so a model
    # built one JOINT at a time stays linear in its joints.
    index = dict(base._id_index)
    for jid in (new.id, *sub.joint_ids):
        if jid in index:
            raise FigureError(
                f"joint identifier {jid} is used twice in one model.",
                hint="translate one submodel's identifiers with <TRANS JOINTS BY n>",
            )
        index[jid] = len(index)
    off = len(base.links)
    shifted = tuple(dataclasses.replace(j, primary=j.primary + off, secondary=j.secondary + off) for j in sub.joints)
    return Figure._grafted(
        base.links + sub.links,
        base.joints + (new,) + shifted,
        base,
        index,
    )


def join(joint_id: int, primary, loc1, secondary, loc2, extremes, kind: JointKind = TURN) -> Figure:
    """``m :- JOINT id, primary, loc1, secondary, loc2, extremes``.

    Parameters
    ----------
    joint_id : int
        The new joint's identifier.
    primary, secondary : Link or Figure
        Copied (value semantics).  A primary Figure is joined at its
        ORIGINAL main link; a secondary Figure is attached by its CURRENT
        main link, the one ``FIGURE s MAIN ...`` chose (the thesis: the
        location is "with respect to the main link in the submodel"), and the
        joints between that link and its original main link are then walked
        backwards, as re-rooting walks them.
    loc1, loc2 : array_like, shape (3,)
        The joint's location on the primary's original main link and on the
        secondary's current main link.
    extremes : array_like, shape (k, 2), k in 1..3
        ``(min, max)`` degrees (lengths for a slide); omitted trailing axes
        are locked at ``(0, 0)``.
    kind : JointKind, optional
        SLIDE and AXIS, if the statement gives them.

    Returns
    -------
    Figure
        Its original main link is the primary's original main link, its
        current main link and placement are the primary's; the secondary's
        placement is dropped.

    Raises
    ------
    FigureError
        On a repeated joint identifier (named) or malformed extremes.
    """
    p = _as_figure(primary, "primary segment")
    s = _as_figure(secondary, "secondary segment")
    return _graft(p, p.root, joint_id, loc1, s, loc2, extremes, kind)


def _canonical(links: list[Link], joints: list[Joint], root: int) -> Figure:
    """A figure rooted at ``root``, links and joints renumbered into pre-order (children in list order).

    Joints are walked as undirected arcs, so ``root`` may be any link: a
    joint met from its secondary keeps its definition and is inverted in the
    result.
    """
    incident: list[list[int]] = [[] for _ in links]
    for k, j in enumerate(joints):
        incident[j.primary].append(k)
        incident[j.secondary].append(k)
    order: list[int] = []
    joint_order: list[int] = []
    seen = [False] * len(links)
    seen[root] = True
    stack: list[tuple[int, int]] = [(root, -1)]
    while stack:
        link, via = stack.pop()
        order.append(link)
        if via >= 0:
            joint_order.append(via)
        below = []
        for k in incident[link]:
            other = joints[k].secondary if joints[k].primary == link else joints[k].primary
            if not seen[other]:
                seen[other] = True
                below.append((other, k))
        stack.extend(reversed(below))
    where = {old: new for new, old in enumerate(order)}
    new_joints = tuple(
        dataclasses.replace(joints[k], primary=where[joints[k].primary], secondary=where[joints[k].secondary])
        for k in joint_order
    )
    return Figure(tuple(links[i] for i in order), new_joints, root=0)


def assemble(specs: Sequence, shapes: dict) -> tuple[Figure, list[tuple[int, str]]]:
    """Build the model of a STARTMODEL ... ENDMODEL block.

    Parameters
    ----------
    specs : sequence of JointSpec or 8-tuples
        ``(joint_id, primary_name, loc1, secondary, secondary_shape, loc2,
        extremes, statement_index)`` in textual order.  ``secondary`` is a
        graphical object's name (its shape in ``secondary_shape``; when that
        is None, ``shapes[secondary]``), a :class:`Figure` submodel, attached
        by its current main link (as :func:`join` does) and copied, or a
        ready :class:`Link`.
    shapes : dict of str to object
        Shapes of the graphical objects named as primaries (only the main
        link's is needed: every other primary is a link some statement made).

    Returns
    -------
    figure : Figure
        In pre-order from the main link, siblings in textual order (a
        submodel's own joints before those attached to it in the block).
    warnings : list of (int, str)
        ``(statement_index, sentence)`` for each ambiguous primary reference.

    Raises
    ------
    FigureError
        No main link (every segment is a secondary somewhere), several
        candidate main links, a cycle, a repeated joint id, an ambiguous
        primary with no candidate created before its statement, or a missing
        shape.

    Notes
    -----
    Statements may come in any order.  The main link is the one name used as
    a primary but never as a secondary (nor inside a secondary submodel).
    Each statement creates a new link or a copy of its submodel.  A primary
    name resolves to the unique link bearing it; if several do, to the latest
    one created by a statement textually BEFORE this one (the main link counts
    as created first; within one submodel, the first in its pre-order), with
    a warning -- the thesis asks that such statements follow the structure's
    order.
    """
    specs = [JointSpec(*s) for s in specs]
    if not specs:
        raise FigureError("STARTMODEL ... ENDMODEL needs at least one JOINT statement.")
    pieces = _pieces(specs, shapes)
    root_name = _main_name(specs, pieces)
    root_link = Link(root_name, _lookup_shape(shapes, root_name))
    attach, warnings = _attachments(specs, pieces, root_name)
    _refuse_cycles(specs, attach)
    _refuse_repeated_ids(specs, pieces)
    return _flatten(specs, pieces, root_link, attach), warnings


def _pieces(specs: list[JointSpec], shapes: dict) -> list[Figure]:
    """Step 1 of :func:`assemble`: each statement's piece, a new link or a copy of a submodel."""
    pieces: list[Figure] = []
    for s in specs:
        if isinstance(s.secondary, Figure):
            # Attached by the main link FIGURE chose (as in JOINT); its placement stays behind.
            pieces.append(_rehung(s.secondary))
        elif isinstance(s.secondary, str):
            shape = s.secondary_shape if s.secondary_shape is not None else _lookup_shape(shapes, s.secondary)
            pieces.append(Figure.from_link(Link(s.secondary, shape)))
        elif isinstance(s.secondary, Link):
            pieces.append(Figure.from_link(s.secondary))
        else:
            raise FigureError(f"the secondary of JOINT {s.joint_id} must be a graphical object or a model.")
    return pieces


def _main_name(specs: list[JointSpec], pieces: list[Figure]) -> str:
    """Step 2 of :func:`assemble`: the main link, the one primary name never used as a secondary."""
    secondary_names = {_key(l.name) for p in pieces for l in p.links if l.name is not None}
    roots: dict[str, str] = {}  # key -> name as first written, in textual order
    for s in specs:
        if _key(s.primary_name) not in secondary_names:
            roots.setdefault(_key(s.primary_name), s.primary_name)
    root_names = list(roots.values())
    if not root_names:
        raise FigureError(
            "no segment can be the main link: every segment is a secondary somewhere, so the model has a cycle.",
            hint="the main link must appear only as a primary segment",
        )
    if len(root_names) > 1:
        raise FigureError(
            f"the model is not one tree: {', '.join(root_names)} are each used only as primary segments, "
            "so each would be a main link.",
            hint="join the pieces together, or check the spelling of the segment names",
        )
    return root_names[0]


def _attachments(specs: list[JointSpec], pieces: list[Figure], root_name: str):
    """Step 3 of :func:`assemble`: per statement, (creator position, link in that piece) of its primary.

    Candidate links per name are (textual position of their creator, link in
    its piece); the root's creator is position -1 ("created first").
    Returns the attachments and the ambiguity warnings.
    """
    candidates: dict[str, list[tuple[int, int]]] = {_key(root_name): [(-1, 0)]}
    for pos, piece in enumerate(pieces):
        for local in piece.preorder:
            name = piece.links[local].name
            if name is not None:
                candidates.setdefault(_key(name), []).append((pos, local))

    warnings: list[tuple[int, str]] = []
    attach: list[tuple[int, int]] = []  # per statement: (creator position, local link)
    for pos, s in enumerate(specs):
        cands = candidates.get(_key(s.primary_name), [])
        if len(cands) == 1:
            attach.append(cands[0])
            continue
        before = [c for c in cands if c[0] < pos]
        if not before:
            raise FigureError(
                f"JOINT {s.joint_id} names primary segment {s.primary_name}, which {len(cands)} links bear, "
                "and none of them is made by an earlier statement.",
                hint="with repeated segment names, place the JOINT statements in the order of the model's structure",
            )
        latest = max(c[0] for c in before)
        chosen = next(c for c in before if c[0] == latest)  # first in that piece's pre-order
        attach.append(chosen)
        made_by = "the main link" if latest < 0 else f"the one made by JOINT {specs[latest].joint_id}"
        warnings.append(
            (
                s.statement_index,
                (
                    f"JOINT {s.joint_id}: {len(cands)} segments are named {s.primary_name}, so the reference is "
                    f"ambiguous; using {made_by}, the latest made before this statement."
                ),
            )
        )
    return attach, warnings


def _refuse_cycles(specs: list[JointSpec], attach: list[tuple[int, int]]) -> None:
    """Step 4 of :func:`assemble`: each statement, followed up through the statements that made
    its primary, must reach the main link without meeting itself.

    Linear in the statements: a statement whose walk reached the main link
    is marked, and a later walk stops there (a chain of 10,000 JOINTs used
    to be walked from each of its statements, each step searching a list).
    """
    reaches_main = [False] * len(specs)
    for pos in range(len(specs)):
        chain: list[int] = []
        on_chain: dict[int, int] = {}
        cur = pos
        while cur >= 0 and not reaches_main[cur]:
            if cur in on_chain:
                loop = chain[on_chain[cur] :]
                ids = ", ".join(f"JOINT {specs[c].joint_id}" for c in loop)
                raise FigureError(
                    f"the model has a cycle: {ids} each hang from a segment made by the next"
                    if len(loop) > 1
                    else f"the model has a cycle: JOINT {specs[cur].joint_id} hangs its primary segment "
                    f"{specs[cur].primary_name} from its own secondary.",
                    hint="a segment cannot be both above and below itself",
                )
            on_chain[cur] = len(chain)
            chain.append(cur)
            cur = attach[cur][0]
        for c in chain:
            reaches_main[c] = True


def _refuse_repeated_ids(specs: list[JointSpec], pieces: list[Figure]) -> None:
    """Step 5 of :func:`assemble`: repeated joint identifiers, named with their statements."""
    owner: dict[int, int] = {}
    for pos, (s, piece) in enumerate(zip(specs, pieces)):
        for jid in (_joint_id(s.joint_id), *piece.joint_ids):
            if jid in owner:
                raise FigureError(
                    f"joint identifier {jid} is used twice in model (by JOINT {specs[owner[jid]].joint_id}"
                    f"{' or its submodel' if owner[jid] != pos else ''} and by JOINT {s.joint_id}"
                    f"{' or its submodel' if isinstance(s.secondary, Figure) else ''}).",
                    hint="translate a submodel's identifiers with <TRANS JOINTS BY n>",
                )
            owner[jid] = pos


def _flatten(specs: Sequence, pieces: list[Figure], root_link: Link, attach) -> Figure:
    """Step 6 of :func:`assemble`: root, then each piece's links; pieces' own joints first, then
    the statements' joints in textual order, so siblings keep that order."""
    offsets = []
    links: list[Link] = [root_link]
    for piece in pieces:
        offsets.append(len(links))
        links.extend(piece.links)
    joints: list[Joint] = []
    for off, piece in zip(offsets, pieces):
        joints.extend(
            dataclasses.replace(j, primary=j.primary + off, secondary=j.secondary + off) for j in piece.joints
        )
    for pos, s in enumerate(specs):
        creator, local = attach[pos]
        primary = 0 if creator < 0 else offsets[creator] + local
        kind = JointKind(s.slide, s.axis)
        joints.append(
            Joint(
                s.joint_id,
                primary,
                offsets[pos] + pieces[pos].root,
                s.loc1,
                s.loc2,
                s.extremes,
                **kind.fields(s.joint_id),
            )
        )
    return _canonical(links, joints, 0)


def _lookup_shape(shapes: dict, name: str):
    if name in shapes:
        return shapes[name]
    key = _key(name)
    for k, v in shapes.items():
        if isinstance(k, str) and _key(k) == key:
            return v
    raise FigureError(f"there is no graphical object named {name} to use as a segment.")
