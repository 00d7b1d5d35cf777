"""The geometry limit: what the camera may be asked to draw.

Rendering divides by depths and multiplies coordinates together (facing
tests, edge slopes); with every drawn point within
:data:`~liganimate.lang.numbers.GEOMETRY_MAX` of the origin along each axis,
a VIEW POINT as far at most and at least
:data:`~liganimate.lang.numbers.GEOMETRY_MIN` from the origin, and a VIEW
WIDTH of at least ``GEOMETRY_MIN``, every number the renderer computes stays
finite (pixel coordinates below about 1E33). The limit is enforced where
geometry is made (BOX, DRAW POLY, JOINT, STARTMODEL, host transformations,
SCALE MODEL), so every GRAPHICAL object and every MODEL a program holds is
drawable, in every pose: joint rotations keep distances, and a model's
:func:`figure_reach` bounds all its poses at once.

Each check raises :class:`~.errors.LigError`; the runtime reports it at the
statement that made the geometry.
"""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np

from liganimate.lang.numbers import GEOMETRY_MAX, GEOMETRY_MIN, magnitude
from liganimate.runtime.errors import LigError
from liganimate.runtime.values import Graphical

_HINT = "everything drawn must stay within 1E12 units of the origin along each axis"

# _reach_parts per model structure, least recently used first: id(joints) ->
# (joints, links, parts); a placed or re-rooted copy of a model shares its
# joints and links tuples.
_REACH: OrderedDict = OrderedDict()
_REACH_MAX = 16
# The attribute under which a Figure keeps its own _reach_parts.
_PARTS = "_liganimate_reach_parts"


def _fmt(x: float) -> str:
    return magnitude(x)


def check_graphical(g: Graphical, what: str = "this object") -> Graphical:
    """``g`` if all its vertices are within the geometry limit, else LigError."""
    e = g.extent()
    if not e <= GEOMETRY_MAX:
        raise LigError(
            f"{what} reaches {_fmt(e)} units from the origin along an axis, beyond the limit of "
            f"{_fmt(GEOMETRY_MAX)} for anything drawn",
            _HINT,
        )
    return g


def _joint_term(j) -> float:
    return float(np.max(np.abs(j.loc1))) + float(np.max(np.abs(j.loc2)))


def _link_size(link) -> float:
    if isinstance(link.shape, Graphical):  # the only shapes drawn (pose.MeshTable)
        return abs(link.scale) * link.shape.extent()
    return 0.0


def _reach_parts(fig) -> tuple[float, float]:
    """``(sum of the joints' location terms, largest drawn segment)`` of a Figure or a Link, memoised.

    A Link (a graphical object used as a segment) is a one-link model. The
    memo is the figure's own, else a small one keyed by the joints tuple,
    which placed and re-rooted copies of a model share with it.
    """
    if not hasattr(fig, "joints"):
        return 0.0, _link_size(fig)
    parts = fig.__dict__.get(_PARTS)
    if parts is not None:
        return parts
    key = id(fig.joints)
    hit = _REACH.get(key)
    if hit is not None and hit[0] is fig.joints and hit[1] is fig.links:
        _REACH.move_to_end(key)
        return _remember(fig, hit[2])
    with np.errstate(all="ignore"):
        joints = 0.0
        for j in fig.joints:  # in joint order, as check_joined adds them
            joints += _joint_term(j)
        size = max((_link_size(link) for link in fig.links), default=0.0)
    return _remember(fig, (joints, size))


def _remember(fig, parts: tuple[float, float]) -> tuple[float, float]:
    fig.__dict__[_PARTS] = parts  # a Figure is frozen, but keeps its caches in __dict__
    if len(_REACH) >= _REACH_MAX:
        _REACH.popitem(last=False)
    _REACH[id(fig.joints)] = (fig.joints, fig.links, parts)
    return parts


def figure_reach(fig) -> float:
    """A bound on how far from its main link's origin any point of ``fig`` can be, in any pose.

    Every joint location counts once at full length (as if all the model's
    joints lay in one straight chain), plus the largest segment; the bound
    is the same for every pose and every choice of main link.

    Parameters
    ----------
    fig : Figure

    Returns
    -------
    float
        Euclidean distance, in the main link's (unplaced) coordinates.
    """
    joints, size = _reach_parts(fig)
    with np.errstate(all="ignore"):
        return math.sqrt(3.0) * (joints + size)


def check_joined(fig, primary, secondary, what: str = "the joined model"):
    """:func:`check_figure` for ``fig = JOINT id, primary, ..., secondary, ...``, in time independent of their size.

    ``fig``'s joints are the primary's, the new joint, then the secondary's
    (``figure.tree.join``), so its reach is the sum of theirs; the operands'
    reaches are memoised (each was checked when it was made), which keeps a
    model built one JOINT at a time linear in its joints (a loop
    ``M :- JOINT I, M, ...`` used to measure all of M again on each pass).
    """
    pj, ps = _reach_parts(primary)
    sj, ss = _reach_parts(secondary)
    n = len(getattr(primary, "joints", ()))
    with np.errstate(all="ignore"):
        _remember(fig, (pj + sj + _joint_term(fig.joints[n]), max(ps, ss)))
    return check_figure(fig, what)


def check_figure(fig, what: str = "the model"):
    """``fig`` if every point of it, in any pose and placed as it is, is within the geometry limit, else LigError."""
    reach = figure_reach(fig)
    p = np.asarray(fig.placement, dtype=np.float64)
    with np.errstate(all="ignore"):
        far = float(np.linalg.norm(p[:3, :3]) * reach + np.max(np.abs(p[:3, 3])))
    if not far <= GEOMETRY_MAX:
        raise LigError(
            f"{what} can reach {_fmt(far)} units from the origin, beyond the limit of "
            f"{_fmt(GEOMETRY_MAX)} for anything drawn",
            "a model is measured by its segments and joint locations, so that it stays within the "
            "limit in every pose; " + _HINT,
        )
    return fig


def check_view_point(point) -> tuple:
    """The VIEW POINT as three floats, if within the limits, else LigError."""
    x, y, z = (float(c) for c in point)
    far = max(abs(x), abs(y), abs(z))
    if not far <= GEOMETRY_MAX:
        raise LigError(
            f"the VIEW POINT is {_fmt(far)} units from the origin along an axis, beyond the limit of "
            f"{_fmt(GEOMETRY_MAX)}",
            _HINT,
        )
    if math.hypot(x, y, z) < GEOMETRY_MIN:
        if x == y == z == 0:
            raise LigError("the VIEW POINT cannot be the origin: the camera looks at the origin")
        raise LigError(
            f"the VIEW POINT is closer to the origin than {_fmt(GEOMETRY_MIN)}, so the camera has no usable direction",
            "the camera looks at the origin from the VIEW POINT",
        )
    return (x, y, z)


def check_view_width(width) -> float:
    """The VIEW WIDTH as a float, if at least the smallest width, else LigError."""
    w = float(width)
    if not w > 0:
        raise LigError(f"the VIEW WIDTH must be positive, not {w:g}")
    if w < GEOMETRY_MIN:
        raise LigError(
            f"the VIEW WIDTH {w:g} is below the smallest width, {_fmt(GEOMETRY_MIN)}",
            "VIEW WIDTH is the width of the view around the origin, in world units",
        )
    return w
