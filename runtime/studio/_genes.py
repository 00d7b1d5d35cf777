"""Genes of the Generator: each joint's flexion, pivot and twist, and its alternatives.

The posing thesis gives every limb a main axis (along the limb), a flexion
axis and a pivot axis, and splits a joint's configuration in two: the
*flexion & pivot* (where the limb points) and the *twist* (about itself).
A LIG joint has three Euler angles instead, ``R = Rz Ry Rx``.  Here:

* the **limb axis** is the direction, in the limb's own coordinates, from
  its joint to the joints of its children (their mean), or to the middle of
  its shape when it has none;
* the **twist axis** is the LIG axis closest to the limb axis;
* of the two other axes, the one turned last (outer in ``Rz Ry Rx``) is
  **flexion** and the other **pivot**.  For the library HUMANOID this gives
  exactly the table of ``docs/stdlib.md``: flexion about Z everywhere, pivot
  about X (about Y for the feet), twist about Y (about X for the feet).

A flexion & pivot alternative is a direction, a point of the tessellated
sphere: the angles that turn the limb's main axis (the twist axis, signed
like the limb) onto that direction with no twist.  An Euler pair has two
such solutions, ``(p, f)`` and ``(180 - p, f + 180)``; the one within the
extremes (first generation) or the one nearer the seed (later ones) is
used.  A joint whose flexion or pivot is locked moves on a tessellated
circle of its one free angle instead, as the thesis does; so does every
twist.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from liganimate.runtime.figure.kinematics import matrix_from_euler_zyx

from . import _spheres

__all__ = ["Alternatives", "JointAxes", "alternatives", "joint_axes", "wrap"]

# Angles are rounded to this many decimals: the sphere's directions give
# 90.00000000000001 where 90 is meant, and a saved library should say 90.
_DECIMALS = 9
# Tolerance of the extremes check, in degrees (for those rounded angles).
_EPS = 1e-7

# (twist axis) -> (pivot axis, flexion axis): the pivot turns first.
_PAIRS = {0: (1, 2), 1: (0, 2), 2: (0, 1)}


@dataclass(frozen=True)
class JointAxes:
    """How one joint's three LIG axes map onto the thesis' flexion, pivot and twist.

    Attributes
    ----------
    index : int
        The joint's index in the figure's joint order.
    id : int
        The joint identifier.
    link : int
        The link (segment) the joint moves: its secondary.
    twist, pivot, flexion : int
        LIG axis indices (0 X, 1 Y, 2 Z).
    sign : float
        +1 or -1: the limb points along +twist axis or -twist axis.
    lo, hi : ndarray, shape (3,)
        The extremes per axis.
    locked : ndarray of bool, shape (3,)
        Axes whose extremes are one value (``min == max``): they never move.
    slide : bool
        A prismatic joint (SLIDE): its gene is a displacement along its rail.
    """

    index: int
    id: int
    link: int
    twist: int
    pivot: int
    flexion: int
    sign: float
    lo: np.ndarray
    hi: np.ndarray
    locked: np.ndarray
    slide: bool = False


def _limb_axis(fig, k: int) -> np.ndarray:
    joint = fig.joints[k]
    link = joint.secondary
    # The link's other joints, wherever they sit in the tree (a re-rooted
    # submodel's joints may hang the link's own primary from it), each at
    # its location on this link.
    up = fig.parent_joint_of(link)
    others = [c for c in ((up,) if up is not None else ()) + fig.child_joints_of(link) if c is not joint]
    ends = [c.loc1 if c.primary == link else c.loc2 for c in others]
    if ends:
        u = np.mean(ends, axis=0) - joint.loc2
    else:
        u = np.zeros(3)
    if np.linalg.norm(u) < 1e-12:
        shape = fig.links[link].shape
        tris = getattr(shape, "triangles", None)
        if tris is not None and len(tris):
            u = fig.links[link].scale * tris.reshape(-1, 3).mean(axis=0) - joint.loc2
    if np.linalg.norm(u) < 1e-12:
        u = np.array([0.0, 1.0, 0.0])
    return u


def joint_axes(fig) -> list:
    """The flexion, pivot and twist axes of every joint of ``fig``.

    Returns
    -------
    list of JointAxes
        In the figure's joint order.
    """
    out = []
    for k, joint in enumerate(fig.joints):
        u = _limb_axis(fig, k)
        t = int(np.argmax(np.abs(u)))
        p, f = _PAIRS[t]
        ext = np.asarray(joint.extremes, dtype=np.float64)
        lo, hi = ext[:, 0].copy(), ext[:, 1].copy()
        out.append(
            JointAxes(
                k,
                int(joint.id),
                int(joint.secondary),
                t,
                p,
                f,
                1.0 if u[t] >= 0 else -1.0,
                lo,
                hi,
                lo == hi,
                joint.slide,
            )
        )
    return out


def wrap(a):
    """Angles in degrees brought into ``(-180, 180]``."""
    a = np.asarray(a, dtype=np.float64)
    return 180.0 - np.mod(180.0 - a, 360.0)


def directions(ax: JointAxes, pivot, flexion) -> np.ndarray:
    """Where the limb's main axis points for given pivot and flexion angles, no twist.

    Parameters
    ----------
    ax : JointAxes
    pivot, flexion : array_like, shape (N,)
        Degrees.

    Returns
    -------
    ndarray, shape (N, 3)
        Unit vectors in the parent's coordinates.
    """
    pivot = np.asarray(pivot, dtype=np.float64).reshape(-1)
    angles = np.zeros((len(pivot), 3))
    angles[:, ax.pivot] = pivot
    angles[:, ax.flexion] = np.asarray(flexion, dtype=np.float64).reshape(-1)
    return matrix_from_euler_zyx(angles)[..., :, ax.twist] * ax.sign


def solutions(ax: JointAxes, v: np.ndarray):
    """Both pivot/flexion solutions that point the main axis along each direction.

    Parameters
    ----------
    ax : JointAxes
    v : ndarray, shape (N, 3)
        Unit directions in the parent's coordinates.

    Returns
    -------
    ndarray, shape (2, N, 2)
        ``[solution, point, (pivot, flexion)]`` in degrees, in ``(-180, 180]``.
    """
    w = np.asarray(v, dtype=np.float64) * ax.sign
    x, y, z = w[:, 0], w[:, 1], w[:, 2]
    if ax.twist == 0:  # w = (cy cz, cy sz, -sy)
        p, f = np.arcsin(np.clip(-z, -1, 1)), np.arctan2(y, x)
    elif ax.twist == 1:  # w = (-sz cx, cz cx, sx)
        p, f = np.arcsin(np.clip(z, -1, 1)), np.arctan2(-x, y)
    else:  # w = (sy cx, -sx, cy cx)
        p, f = np.arcsin(np.clip(-y, -1, 1)), np.arctan2(x, z)
    p, f = np.degrees(p), np.degrees(f)
    first = np.stack([p, f], axis=-1)
    second = np.stack([180.0 - p, f + 180.0], axis=-1)
    return np.round(wrap(np.stack([first, second])), _DECIMALS)


def _fit(values, lo: float, hi: float):
    """Each angle moved by whole turns into ``[lo, hi]`` where it can be; (fitted, ok)."""
    v = np.asarray(values, dtype=np.float64)
    shifted = v + 360.0 * np.ceil((lo - _EPS - v) / 360.0)
    ok = shifted <= hi + _EPS
    return np.clip(np.where(ok, shifted, v), lo, hi), ok


def _near(values, seed: float):
    """Each angle moved by whole turns to the value nearest ``seed``."""
    return np.round(seed + wrap(np.asarray(values, dtype=np.float64) - seed), _DECIMALS)


@dataclass
class Alternatives:
    """The candidate configurations of one gene, in presentation order.

    Attributes
    ----------
    axes : tuple of int
        The LIG axes the values set: ``(pivot, flexion)`` or one axis.
    values : ndarray, shape (N, len(axes))
        Degrees.
    level : ndarray of int, shape (N,)
        The tessellation level each comes from (coarsest is 0).
    """

    axes: tuple
    values: np.ndarray
    level: np.ndarray


def _order(level, plain, distance, values):
    """Presentation order: coarsest level first, then flexion only, then nearest, then by value."""
    keys = [values[:, i] for i in reversed(range(values.shape[1]))]
    return np.lexsort((*keys, np.round(distance, 6), ~plain, level))


def alternatives(
    ax: JointAxes, seed: np.ndarray, mode: str, first: bool, max_distance: float, need: int = 9
) -> Alternatives:
    """The configurations this gene may take, from the coarsest levels, sorted for presentation.

    Parameters
    ----------
    ax : JointAxes
    seed : ndarray, shape (3,)
        The joint's angles in the seed pose.
    mode : {"flexion", "twist"}
        Flexion & pivot, or twist.
    first : bool
        The first generation: the extremes bound every angle and distance
        does not.  Later, only ``max_distance`` does (locked axes excepted).
    max_distance : float
        Degrees: how far (angle between directions, or between twists) an
        alternative may be from the seed in later generations.
    need : int
        Levels are taken coarsest first until they hold at least this many
        alternatives (Fig. IV.9); finer levels are left out.

    Returns
    -------
    Alternatives
        Never the seed's own configuration.  Empty when the gene's axes
        for this mode are all locked, or nothing lies within reach.
    """
    if ax.slide:
        return _on_rail(ax, seed, mode, first, max_distance, need)
    if mode == "twist" or ax.locked[ax.pivot] or ax.locked[ax.flexion]:
        if mode == "twist":
            free = [ax.twist] if not ax.locked[ax.twist] else []
        else:
            free = [a for a in (ax.pivot, ax.flexion) if not ax.locked[a]]
        if not free:
            return Alternatives((), np.zeros((0, 0)), np.zeros(0, dtype=np.int64))
        return _on_circle(ax, free[0], seed, first, max_distance, need)
    return _on_sphere(ax, seed, first, max_distance, need)


def _coarsest(ok: np.ndarray, level: np.ndarray, need: int) -> np.ndarray:
    """Indices where ``ok``, keeping only the coarsest levels that together hold ``need``.

    ``level`` is non-decreasing (the tessellations list their points level
    by level), so each level is one slice.
    """
    ends = np.searchsorted(level, np.arange(1, int(level[-1]) + 2))
    counts = np.cumsum(np.add.reduceat(ok, np.r_[0, ends[:-1]]))
    enough = np.flatnonzero(counts >= need)
    end = int(ends[enough[0]]) if len(enough) else len(ok)
    return np.flatnonzero(ok[:end])


def _on_circle(ax: JointAxes, axis: int, seed: np.ndarray, first: bool, max_distance: float, need: int) -> Alternatives:
    angles, level = _spheres.circle()
    s = float(seed[axis])
    distance = np.abs(wrap(angles - s))
    if first:
        values, ok = _fit(angles, ax.lo[axis], ax.hi[axis])
        ok &= distance > _EPS
    else:
        values = _near(angles, s)
        ok = (distance > _EPS) & (distance <= max_distance + _EPS)
    idx = _coarsest(ok, level, need)
    values = values[idx][:, None]
    order = _order(level[idx], np.ones(len(idx), dtype=bool), distance[idx], values)
    return Alternatives((axis,), values[order], level[idx][order])


#: Levels of the rail's tessellation: level k halves the spacing of level k - 1.
_RAIL_LEVELS = 6


def _on_rail(ax: JointAxes, seed: np.ndarray, mode: str, first: bool, max_distance: float, need: int) -> Alternatives:
    """A slide's gene: displacements along its first free axis (the flexion mode) or its second (twist).

    Level 0 is the rail's two ends, each further level the midpoints of the
    last; later generations stay within ``max_distance / 180`` of the rail's
    length from the seed, as a turn stays within ``max_distance`` degrees.
    """
    free = [a for a in range(3) if not ax.locked[a]]
    pick = 0 if mode != "twist" else 1
    if len(free) <= pick:
        return Alternatives((), np.zeros((0, 0)), np.zeros(0, dtype=np.int64))
    axis = free[pick]
    lo, hi = float(ax.lo[axis]), float(ax.hi[axis])
    steps = 2**_RAIL_LEVELS
    fractions = np.arange(steps + 1) / steps
    level = np.array([0 if i in (0, steps) else _RAIL_LEVELS - (i & -i).bit_length() + 1 for i in range(steps + 1)])
    order = np.argsort(level, kind="stable")
    values, level = np.round(lo + (hi - lo) * fractions[order], _DECIMALS), level[order]
    s = float(seed[axis])
    distance = np.abs(values - s)
    ok = distance > _EPS * max(1.0, hi - lo)
    if not first:
        ok &= distance <= max_distance / 180.0 * (hi - lo) + _EPS
    idx = _coarsest(ok, level, need)
    vals = values[idx][:, None]
    ranked = _order(level[idx], np.ones(len(idx), dtype=bool), distance[idx], vals)
    return Alternatives((axis,), vals[ranked], level[idx][ranked])


def _on_sphere(ax: JointAxes, seed: np.ndarray, first: bool, max_distance: float, need: int) -> Alternatives:
    points, level = _spheres.sphere()
    sp, sf = float(seed[ax.pivot]), float(seed[ax.flexion])
    here = directions(ax, [sp], [sf])[0]
    cosine = points @ here
    # Compared as cosines, so that only the points kept need an arccos.
    other = cosine < np.cos(np.radians(1e-6))
    if first:
        valid, pivot_all, flexion_all = _within_extremes(ax, points)
        idx = _coarsest(valid & other, level, need)
        pivot, flexion = pivot_all[idx], flexion_all[idx]
    else:
        idx = _coarsest(other & (cosine >= np.cos(np.radians(max_distance)) - 1e-12), level, need)
        sol = _solutions_cached(ax, points)[:, idx]  # (2, n, 2)
        cost = [np.abs(wrap(sol[k, :, 0] - sp)) + np.abs(wrap(sol[k, :, 1] - sf)) for k in (0, 1)]
        chosen = np.where((cost[1] < cost[0])[:, None], sol[1], sol[0])
        pivot, flexion = _near(chosen[:, 0], sp), _near(chosen[:, 1], sf)
    distance = np.degrees(np.arccos(np.clip(cosine[idx], -1.0, 1.0)))
    values = np.stack([pivot, flexion], axis=-1)
    plain = np.abs(wrap(values[:, 0] - sp)) < 1e-6
    order = _order(level[idx], plain, distance, values)
    return Alternatives((ax.pivot, ax.flexion), values[order], level[idx][order])


_extremes_memo: dict = {}


def _within_extremes(ax: JointAxes, points: np.ndarray):
    """Which sphere points a joint reaches within its extremes, and with which (pivot, flexion).

    Returns ``(ok, pivot, flexion)``, each shape (N,); the first solution is
    used when it fits, else the second.  Memoized per axes and extremes.
    """
    key = (ax.twist, ax.sign, ax.pivot, ax.flexion, tuple(ax.lo), tuple(ax.hi), len(points))
    hit = _extremes_memo.get(key)
    if hit is not None:
        return hit
    sol = _solutions_cached(ax, points)
    fits = []
    for k in (0, 1):
        p, okp = _fit(sol[k, :, 0], ax.lo[ax.pivot], ax.hi[ax.pivot])
        f, okf = _fit(sol[k, :, 1], ax.lo[ax.flexion], ax.hi[ax.flexion])
        fits.append((p, f, okp & okf))
    (p0, f0, ok0), (p1, f1, ok1) = fits
    hit = (ok0 | ok1, np.where(ok0, p0, p1), np.where(ok0, f0, f1))
    if len(_extremes_memo) > 256:
        _extremes_memo.clear()
    _extremes_memo[key] = hit
    return hit


_solutions_memo: dict = {}


def _solutions_cached(ax: JointAxes, points: np.ndarray) -> np.ndarray:
    """:func:`solutions` of the whole sphere, once per (twist axis, sign)."""
    key = (ax.twist, ax.sign, len(points))
    hit = _solutions_memo.get(key)
    if hit is None:
        hit = _solutions_memo[key] = solutions(ax, points)
        hit.setflags(write=False)
    return hit
