"""Host values: 3-vectors and graphical objects.

A :class:`Graphical` is an immutable set of flat-shaded triangles in its own
coordinates, each with a LIGHTNESS (0 black .. 100 white), optionally a
COLOUR, and a flag saying whether it belongs to a closed, outward-wound solid
(so the rasterizer may cull it when it faces away).

Colour is an extension: a triangle's COLOUR (r, g, b), each 0..100, is the
colour of a surface that LIGHTNESS then lights, so the drawn channel is
``LIGHTNESS * c / 100``. White (100, 100, 100) is the thesis' grey exactly,
which is why a program that never says COLOUR draws the same bytes as
before, and why the BOX's brighter top and sides stay brighter in colour.
"""

from __future__ import annotations

import math

import numpy as np

from liganimate.lang.numbers import GEOMETRY_MAX, magnitude
from liganimate.runtime.errors import LigError


class Vec(tuple):
    """An immutable 3-vector with the arithmetic LIG programs use."""

    __slots__ = ()

    def __new__(cls, x, y, z):
        return tuple.__new__(cls, (float(x), float(y), float(z)))

    def __add__(self, o):
        return Vec(self[0] + o[0], self[1] + o[1], self[2] + o[2])

    def __sub__(self, o):
        return Vec(self[0] - o[0], self[1] - o[1], self[2] - o[2])

    def __mul__(self, k):
        return Vec(self[0] * k, self[1] * k, self[2] * k)

    __rmul__ = __mul__

    def __neg__(self):
        return Vec(-self[0], -self[1], -self[2])

    def __repr__(self):
        return f"({_num(self[0])}, {_num(self[1])}, {_num(self[2])})"

    def norm(self) -> float:
        """Euclidean length (scaled internally, so it overflows only if the length itself would)."""
        return math.hypot(self[0], self[1], self[2])


def _num(x: float) -> str:
    return f"{x:.6g}"


ZERO = Vec(0.0, 0.0, 0.0)


class Graphical:
    """Triangles with lightness, in object coordinates.

    Parameters
    ----------
    triangles : ndarray, shape (N, 3, 3)
    lightness : ndarray, shape (N,)
    closed : ndarray of bool, shape (N,)
        True where the triangle is part of a closed solid wound
        counter-clockwise seen from outside.
    colour : ndarray, shape (N, 3), or None
        Each triangle's COLOUR, components 0..100 (clipped when drawn); None
        when every triangle is white, as in the thesis.
    """

    __slots__ = ("_extent", "closed", "colour", "lightness", "triangles")

    def __init__(self, triangles, lightness, closed, colour=None):
        self.triangles = np.ascontiguousarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
        self.lightness = np.asarray(lightness, dtype=np.float64).reshape(-1)
        self.closed = np.asarray(closed, dtype=bool).reshape(-1)
        self.colour = None if colour is None else np.asarray(colour, dtype=np.float64).reshape(-1, 3)
        self._extent = None

    def colours(self) -> np.ndarray:
        """Every triangle's COLOUR, white where none was given: shape (N, 3), components 0..100."""
        if self.colour is not None:
            return self.colour
        return np.full((len(self), 3), 100.0)

    def shades(self) -> np.ndarray:
        """What the rasterizer draws: 8-bit grey levels, shape (N,), or RGB levels, shape (N, 3).

        Grey when the object has no COLOUR, so greyscale programs draw
        exactly the bytes they always did; see :func:`colour_levels`.
        """
        if self.colour is None:
            return grey_levels(self.lightness)
        return colour_levels(self.lightness, self.colour)

    def extent(self) -> float:
        """The largest coordinate magnitude of any vertex (0 when empty; NaN if one is NaN)."""
        if self._extent is None:
            t = self.triangles
            self._extent = float(np.max(np.abs(t))) if t.size else 0.0
        return self._extent

    def __len__(self):
        return len(self.triangles)

    def __add__(self, other: Graphical) -> Graphical:
        """Superposition: both objects' triangles.

        Raises
        ------
        LigError
            If the result would exceed :data:`MAX_TRIANGLES` (checked before
            anything is allocated, so ``G = G + G`` in a loop fails cleanly).
        """
        check_triangles(len(self) + len(other), "the superposed object")
        colour = None
        if self.colour is not None or other.colour is not None:
            colour = np.concatenate([self.colours(), other.colours()])
        return Graphical(
            np.concatenate([self.triangles, other.triangles]),
            np.concatenate([self.lightness, other.lightness]),
            np.concatenate([self.closed, other.closed]),
            colour,
        )

    def transformed(self, matrix) -> Graphical:
        """Apply a 4x4 affine transform; a mirror keeps the solids wound outward."""
        m = np.asarray(matrix, dtype=np.float64)
        tris = self.triangles @ m[:3, :3].T + m[:3, 3]
        if np.linalg.det(m[:3, :3]) < 0:
            tris = tris[:, ::-1, :]
        return Graphical(tris, self.lightness, self.closed, self.colour)

    def with_lightness(self, lightness: float) -> Graphical:
        """Every triangle at one lightness (its colour, if any, kept: LIGHTNESS lights it)."""
        return Graphical(self.triangles, np.full(len(self), _clip_lightness(lightness)), self.closed, self.colour)

    def with_colour(self, colour) -> Graphical:
        """Every triangle of one COLOUR ``(r, g, b)``, each 0..100; lightnesses kept."""
        rgb = np.array([_clip_lightness(c) for c in colour], dtype=np.float64)
        return Graphical(self.triangles, self.lightness, self.closed, np.broadcast_to(rgb, (len(self), 3)).copy())


EMPTY = Graphical(np.zeros((0, 3, 3)), np.zeros(0), np.zeros(0, dtype=bool))


def grey_levels(lightness) -> np.ndarray:
    """LIGHTNESS (0..100, clipped) to 8-bit grey levels, rounding half up."""
    l = np.clip(np.asarray(lightness, dtype=np.float64), 0.0, 100.0)
    return np.floor(l * 2.55 + 0.5).astype(np.uint8)


def colour_levels(lightness, colour) -> np.ndarray:
    """LIGHTNESS (N,) lighting COLOUR (N, 3), both 0..100 and clipped, to 8-bit RGB levels (N, 3).

    Channel ``c`` is the grey level (:func:`grey_levels`) of
    ``LIGHTNESS * c / 100``, so white (100) gives exactly the grey levels.
    """
    l = np.clip(np.asarray(lightness, dtype=np.float64), 0.0, 100.0)[:, None]
    c = np.clip(np.asarray(colour, dtype=np.float64), 0.0, 100.0)
    # l * 100 / 100 is l exactly in binary, which keeps white exact.
    return grey_levels(l * c / 100.0)


def rgb_levels(shade) -> np.ndarray:
    """Shades as RGB levels, shape (N, 3): grey levels (N,) become three equal channels."""
    shade = np.asarray(shade, dtype=np.uint8)
    return np.repeat(shade[:, None], 3, axis=1) if shade.ndim == 1 else shade


def joined_shades(shades) -> np.ndarray:
    """Concatenate per-triangle shades, grey (N,) and RGB (N, 3) alike.

    All grey stays grey; any RGB part makes the result RGB, a grey level g
    becoming (g, g, g), which is what it looks like.
    """
    shades = list(shades)
    if all(s.ndim == 1 for s in shades):
        return np.concatenate(shades) if shades else np.zeros(0, dtype=np.uint8)
    return np.concatenate([rgb_levels(s) for s in shades])


MAX_TRIANGLES = 10_000_000
"""Most triangles one graphical object may hold (about 720 MB of vertices)."""

_MANY_HINT = "build the object from fewer or simpler pieces (each doubling G = G + G doubles its triangles)"


def check_triangles(n: int, what: str) -> None:
    """LigError if ``n`` triangles exceed :data:`MAX_TRIANGLES`.

    Parameters
    ----------
    n : int
    what : str
        Names the object in the message.
    """
    if n > MAX_TRIANGLES:
        raise LigError(
            f"{what} would have {n:,} triangles, beyond the limit of {MAX_TRIANGLES:,} for one graphical object",
            _MANY_HINT,
        )


class Canvas:
    """What a PRIMITIVE draws into: DRAW WITH <LIGHTNESS l>, DRAW WITH <COLOUR c> and DRAW POLY."""

    def __init__(self):
        self.polys: list = []
        self.light = 40.0
        self.tint: tuple | None = None
        self.tints: list = []  # per polygon, when any polygon has a colour
        self.triangles = 0

    def lightness(self, value) -> None:
        """Set the lightness of the polygons drawn next (clipped to 0..100 when drawn)."""
        self.light = _clip_lightness(value)

    def colour(self, value) -> None:
        """Set the COLOUR ``(r, g, b)`` of the polygons drawn next (each clipped to 0..100 when drawn)."""
        self.tint = tuple(_clip_lightness(c) for c in value)

    def poly(self, points, at=None) -> None:
        """Add a polygon; a closing point equal to the first is dropped.

        Raises
        ------
        LigError
            For fewer than three corners, or a corner beyond the geometry
            limit (:data:`~liganimate.lang.numbers.GEOMETRY_MAX`).
        """
        pts = [tuple(p) for p in points]
        if len(pts) > 1 and pts[-1] == pts[0]:
            pts = pts[:-1]
        if len(pts) < 3:
            raise LigError(f"a polygon needs at least three corners; this one has {len(pts)}")
        far = max(abs(c) for p in pts for c in p)
        if not far <= GEOMETRY_MAX:
            raise LigError(
                f"this polygon has a corner {magnitude(far)} units along an axis, beyond the limit of "
                f"{magnitude(GEOMETRY_MAX)} for anything drawn",
                _FAR_HINT,
            )
        self.triangles += len(pts) - 2
        check_triangles(self.triangles, "the primitive's drawing")
        self.polys.append((np.asarray(pts, dtype=np.float64), self.light))
        self.tints.append(self.tint)

    def result(self) -> Graphical:
        """The drawn polygons as one Graphical (fan-triangulated, solids detected)."""
        g = polygons_to_graphical(self.polys)
        if all(t is None for t in self.tints):
            return g
        white = (100.0, 100.0, 100.0)
        per_poly = np.array([white if t is None else t for t in self.tints], dtype=np.float64)
        counts = [len(p) - 2 for p, _ in self.polys]
        return Graphical(g.triangles, g.lightness, g.closed, np.repeat(per_poly, counts, axis=0))


def polygons_to_graphical(polys) -> Graphical:
    """Fan-triangulate convex polygons; mark the closed solids among them.

    Polygons that together form a closed surface (every edge shared by
    exactly two of them) are a solid, whatever the order their corners were
    listed in: its triangles are wound outward (a polygon listed the other
    way round has each triangle's corners reversed, which draws the same
    pixels) and marked closed, so the rasterizer may skip those facing away.
    The thesis' own PRIMITIVE BOX lists three of its six faces inward.
    """
    if not polys:
        return EMPTY
    tris, light, owner = [], [], []
    for i, (pts, l) in enumerate(polys):
        for k in range(1, len(pts) - 1):
            tris.append((pts[0], pts[k], pts[k + 1]))
            light.append(l)
            owner.append(i)
    corners = np.asarray(tris, dtype=np.float64)
    side = np.asarray(_solid_orientation(polys), dtype=np.int8)[owner]
    flip = side < 0
    if flip.any():
        corners[flip] = corners[flip][:, ::-1, :]
    return Graphical(corners, light, side != 0)


def _solid_orientation(polys) -> list:
    """Per polygon: +1 (part of a closed solid, wound outward), -1 (closed, wound inward), 0 (not closed).

    The polygons are grouped into surfaces by shared edges.  A surface is a
    solid when every edge is used by exactly two polygons and the polygons
    can be wound consistently (each shared edge walked once each way); its
    outward side is the one that gives a positive enclosed volume.
    """
    # Plain floats, not NumPy scalars: the corners are hashed and compared as keys many times.
    keyed = [[tuple(p) for p in np.round(pts, 9).tolist()] for pts, _ in polys]
    uses, bad = _edge_uses(keyed)
    n = len(polys)
    side = [0] * n
    seen = [False] * n
    for first in range(n):
        if seen[first]:
            continue
        sign, ok = _walk_surface(first, keyed, uses, bad, seen)
        if not ok:
            continue
        vol = 0.0
        for i, sgn in sign.items():
            vol += sgn * _fan_volume(np.asarray(polys[i][0], dtype=np.float64).tolist())
        if vol == 0:
            continue
        outward = 1 if vol > 0 else -1
        for i, sgn in sign.items():
            side[i] = sgn * outward
    return side


def _fan_volume(pts: list) -> float:
    """Six times the signed volume of the cone from the origin over a polygon's fan triangles (plain floats).

    The triple product ``p0 . (pk x pk+1)`` of each triangle, written out: on
    three numbers NumPy's ``cross`` costs tens of microseconds a call.
    """
    (x0, y0, z0), *rest = pts
    vol = 0.0
    for (x1, y1, z1), (x2, y2, z2) in zip(rest, rest[1:]):
        vol += x0 * (y1 * z2 - z1 * y2) + y0 * (z1 * x2 - x1 * z2) + z0 * (x1 * y2 - y1 * x2)
    return vol


def _edges(ks: list):
    """A polygon's edges as (corner, next corner), skipping zero-length ones."""
    return ((a, b) for a, b in zip(ks, ks[1:] + ks[:1]) if a != b)


def _edge_uses(keyed: list) -> tuple:
    """Undirected edge -> [(polygon, walked forward)], and the polygons with a repeated corner."""
    uses: dict = {}
    bad = set()
    for i, ks in enumerate(keyed):
        if len(set(ks)) != len(ks):
            bad.add(i)  # a repeated corner: not a proper face
        for a, b in _edges(ks):
            key, forward = ((a, b), True) if a < b else ((b, a), False)
            uses.setdefault(key, []).append((i, forward))
    return uses, bad


def _walk_surface(first: int, keyed: list, uses: dict, bad: set, seen: list) -> tuple:
    """Walk the surface of polygon ``first``: each polygon's winding relative to it, and whether it is closed."""
    sign = {first: 1}
    stack, ok = [first], first not in bad
    seen[first] = True
    while stack:
        i = stack.pop()
        for a, b in _edges(keyed[i]):
            users = uses[(a, b) if a < b else (b, a)]
            if len(users) != 2:
                ok = False
                continue
            (p, fp), (q, fq) = users
            if p == q:
                ok = False
                continue
            other, f_other, f_self = (q, fq, fp) if p == i else (p, fp, fq)
            # Consistent winding walks a shared edge once each way.
            want = sign[i] * (1 if f_self != f_other else -1)
            if other in sign:
                ok = ok and sign[other] == want
            else:
                sign[other] = want
                seen[other] = True
                ok = ok and other not in bad
                stack.append(other)
    return sign, ok


_FAR_HINT = "everything drawn must stay within 1E12 units of the origin along each axis"


def _clip_lightness(value) -> float:
    # Drawing clips to 0..100 anyway; clipping early keeps 1.5 * LIGHTNESS finite.
    return min(max(float(value), -1000.0), 1000.0)


def box(centre, width, height, depth, light) -> Graphical:
    """The built-in BOX: exactly the polygons of the thesis' Appendix A PRIMITIVE BOX.

    Raises
    ------
    LigError
        If a corner would lie beyond the geometry limit
        (:data:`~liganimate.lang.numbers.GEOMETRY_MAX`).
    """
    c = np.asarray(centre, dtype=np.float64)
    w, h, d = float(width), float(height), float(depth)
    far = float(np.max(np.abs(c))) + max(abs(w), abs(h), abs(d)) / 2  # its corners are c +- size / 2
    if not far <= GEOMETRY_MAX:
        raise LigError(
            f"this BOX reaches {magnitude(far)} units from the origin along an axis, beyond the limit of "
            f"{magnitude(GEOMETRY_MAX)} for anything drawn",
            _FAR_HINT,
        )
    light = _clip_lightness(light)
    l1, l2 = light, light * 1.5
    ftr = c + (w / 2, h / 2, d / 2)
    ftl = ftr - (w, 0, 0)
    fbl = ftl - (0, h, 0)
    fbr = ftr - (0, h, 0)
    btr = ftr - (0, 0, d)
    btl = btr - (w, 0, 0)
    bbl = btl - (0, h, 0)
    bbr = btr - (0, h, 0)
    # Appendix A's faces and lightnesses; three of its faces are listed
    # inward, so they are reversed here to make a closed solid the rasterizer
    # may back-face cull (the picture is the same either way).
    polys = [
        (np.array([bbr, bbl, btl, btr]), l1),  # back
        (np.array([ftr, btr, btl, ftl]), l2),  # top
        (np.array([fbl, bbl, bbr, fbr]), l2),  # bottom
        (np.array([ftl, btl, bbl, fbl]), l2),  # left
        (np.array([fbr, bbr, btr, ftr]), l2),  # right
        (np.array([ftr, ftl, fbl, fbr]), l1),  # front
    ]
    return polygons_to_graphical(polys)
