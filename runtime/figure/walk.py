"""How forward kinematics walks a figure's tree: its links and joints in breadth-first order, prepared once.

:func:`liganimate.runtime.figure.kinematics.placed_transforms` composes a
figure's link transforms down the tree from its current main link; both of
its paths (:mod:`.short` for one pose and short batches, :mod:`.folded` for
long ones) start from the figure's :class:`Walk`, prepared here once per
figure (per tree walk, a few hundred remembered): the links in
breadth-first order, so that the children of one depth level are one
contiguous run, the joints in the same order, and per walked joint what
its 4x4 needs: ``near`` and ``far`` (``L1`` and ``L2``, swapped for a joint
walked from its secondary), whether it is walked backwards, its AXIS and
a slide's gain.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from liganimate.runtime.figure.tree import Figure

__all__ = ["Walk", "walk_of"]


@dataclass(frozen=True, eq=False)
class Walk:
    """What one figure's walk needs, prepared once (see the module's notes).

    Joints are numbered in walk order: joint ``order[q]`` of the figure is
    the one that places link ``links[q + 1]``.
    """

    order: np.ndarray  # (J,) the figure's joint index of each walked joint
    links: np.ndarray  # (L,) the figure's link at each breadth-first place; links[0] is the main link
    where: np.ndarray  # (L,) the breadth-first place of each of the figure's links
    levels: tuple  # per depth level: (first child place, end, parent places (n,), first joint, end joint)
    near: np.ndarray  # (3, J): L1, or L2 for a joint walked backwards
    minus_far: np.ndarray  # (3, J): -L2, or -L1 backwards (-far[m] for the sum over m)
    framed: np.ndarray  # (f,) walk numbers of joints with an AXIS that turn (a slide's axes only move it)
    slides: np.ndarray  # (s,) walk numbers of slides
    slide_axes: np.ndarray  # (3, 3, s) their axes F, F[i, a]
    slide_gain: np.ndarray  # (s,) their scale, negated for a slide walked backwards
    # Per walked joint, as Python values (for .folded):
    parent_link: tuple  # the link it hangs from
    child_link: tuple  # the link it places
    reversed: tuple  # walked secondary to primary
    near_list: tuple  # near, far as floats
    far_list: tuple


def walk_of(figure: Figure) -> Walk:
    """The figure's :class:`Walk`, remembered per tree walk (a few hundred)."""
    levels = figure.traversal
    hit = _WALKS.get(id(levels))
    if hit is not None and hit[0] is levels and hit[1] is figure.joints:
        return hit[2]
    walk = _prepare(figure)
    if len(_WALKS) >= 256:
        _WALKS.clear()
    _WALKS[id(levels)] = (levels, figure.joints, walk)
    return walk


_WALKS: dict = {}  # id(traversal) -> (traversal, joints, Walk); the stored objects keep the id valid


def _prepare(figure: Figure) -> Walk:
    order = np.array([int(k) for level in figure.traversal for k in level.joints], dtype=np.intp)
    links = np.array([figure.main] + [int(c) for level in figure.traversal for c in level.children], dtype=np.intp)
    where = np.empty(figure.n_links, dtype=np.intp)
    where[links] = np.arange(figure.n_links)
    levels, first = [], 1
    for level in figure.traversal:
        n = len(level.joints)
        levels.append((first, first + n, where[level.parents], first - 1, first - 1 + n))
        first += n
    rev = figure.reversed_joints[order]
    slides = figure.slides[order]
    framed = figure.has_frames[order] & ~slides  # a slide's axes move it; it never turns
    loc1, loc2 = figure.locations
    loc1, loc2 = loc1[order], loc2[order]
    near = np.where(rev[:, None], loc2, loc1)
    far = np.where(rev[:, None], loc1, loc2)
    k = order[slides]
    return Walk(
        order=order,
        links=links,
        where=where,
        levels=tuple(levels),
        near=np.ascontiguousarray(near.T),
        minus_far=np.ascontiguousarray(-far.T),
        framed=np.flatnonzero(framed),
        slides=np.flatnonzero(slides),
        slide_axes=np.ascontiguousarray(figure.frames[k].transpose(1, 2, 0)),
        slide_gain=figure.slide_scales[k] * np.where(rev[slides], -1.0, 1.0),
        parent_link=tuple(int(p) for level in figure.traversal for p in level.parents),
        child_link=tuple(int(c) for level in figure.traversal for c in level.children),
        reversed=tuple(bool(r) for r in rev),
        near_list=tuple(tuple(float(x) for x in row) for row in near),
        far_list=tuple(tuple(float(x) for x in row) for row in far),
    )
