"""The hyper tessellated sphere and circle of the posing thesis' Generator (chapter IV, 2.2).

A tessellated sphere is a set of nearly evenly spaced directions.  The
thesis builds it from the octahedron (6 points, 8 triangles): each
iteration takes every triangle, puts a point at the middle of each edge,
pushes it out onto the unit sphere and splits the triangle in four.  The
*hyper* tessellated sphere is the chain of these spheres, coarsest first;
the thesis uses seven levels.  Every point of a sphere is also a point of
every finer one, so each point here carries the level at which it first
appears: level 0 holds the octahedron's 6 points and level ``n`` the
``2 + 4**(n+1) - (2 + 4**n)`` points that iteration ``n`` adds (16,386
points in all at level 6).

Joints that may turn about only one axis of their flexion/pivot pair, and
every twist, use the hyper tessellated circle instead: level 0 is the four
quarter turns, and each level halves the spacing (``4 * 2**n`` angles at
level ``n``).
"""

from __future__ import annotations

from functools import cache

import numpy as np

__all__ = ["LEVELS", "circle", "sphere"]

# The thesis: "Seven levels of decomposition appeared to be sufficient."
LEVELS = 7


@cache
def sphere(levels: int = LEVELS):
    """The hyper tessellated sphere.

    Parameters
    ----------
    levels : int
        Number of levels (the octahedron is level 0).

    Returns
    -------
    points : ndarray, shape (N, 3)
        Unit vectors, read-only; N is ``2 + 4**levels``.
    level : ndarray of int, shape (N,)
        The level at which each point first appears, read-only.  Points are
        listed level by level in the order the subdivision makes them.
    """
    pts = [np.array(p, dtype=np.float64) for p in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))]
    lev = [0] * 6
    # The octahedron's faces, wound outward.
    faces = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    for n in range(1, levels):
        faces = _subdivide(faces, pts, lev, n)
    points = np.array(pts)
    level = np.array(lev, dtype=np.int64)
    points.setflags(write=False)
    level.setflags(write=False)
    return points, level


def _subdivide(faces: list, pts: list, lev: list, n: int) -> list:
    """Split each triangle in four, appending the new edge midpoints (pushed onto the sphere) at level n."""
    middle: dict = {}

    def mid(a: int, b: int) -> int:
        key = (a, b) if a < b else (b, a)
        hit = middle.get(key)
        if hit is None:
            m = pts[a] + pts[b]
            pts.append(m / np.linalg.norm(m))
            lev.append(n)
            hit = middle[key] = len(pts) - 1
        return hit

    split = []
    for a, b, c in faces:
        ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
        split += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    return split


@cache
def circle(levels: int = LEVELS):
    """The hyper tessellated circle: angles in degrees and their levels.

    Returns
    -------
    angles : ndarray, shape (4 * 2**(levels - 1),)
        In ``(-180, 180]``, level by level, each level's new angles going
        round from 0; read-only.
    level : ndarray of int, same shape
        The level at which each angle first appears; read-only.
    """
    angles, lev = [], []
    for n in range(levels):
        count = 4 * 2**n
        step = 360.0 / count
        for i in range(count):
            if n and i % 2 == 0:
                continue  # already in a coarser level
            a = i * step
            angles.append(a - 360.0 if a > 180.0 else a)
            lev.append(n)
    out = np.array(angles)
    level = np.array(lev, dtype=np.int64)
    out.setflags(write=False)
    level.setflags(write=False)
    return out, level
