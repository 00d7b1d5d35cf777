"""A second rasterizer, written plainly from the documented rules, to check runtime/render/raster.py against.

It shares no code with the live camera or rasterizer: from a ``Camera`` it
reads only the four numbers that define a view (``point``, ``width``,
``size``, ``near``) and derives the rest itself from the formulas in
docs/semantics-render.md ("Camera").  Where the live rasterizer turns
triangles into row spans for all triangles at once, this one takes one
triangle at a time and tests every pixel centre of its bounding box with
three edge functions; where the live one interpolates 1/z along each span,
this one weighs the vertices' 1/z by barycentric coordinates at each pixel
centre.  The rules it implements, all from docs/semantics-render.md:

* projection: ``x = W/2 + F x/z``, ``y = H/2 - F y/z``, ``F = |P| W / w``,
  camera axes from the forward direction and the +Y (or, looking along Y,
  -Z) up hint;
* near clipping: a triangle is cut along the plane ``z = near`` into one or
  two triangles keeping its number, new vertices interpolated from the
  vertex in front towards the one behind;
* coverage: a pixel whose centre is strictly inside, or exactly on a left
  or top edge (the top-left rule); triangles of no area draw nothing;
* depth: the key of a covered pixel is the upper 32 bits of the float64
  1/z at its centre (linear in screen space, kept within the vertices'
  range) above the triangle's number; the largest key wins, so the nearer
  surface, and at equal depth the later triangle;
* facing: ``(v1 - v0) x (v2 - v0)`` pointing towards the eye; a back face's
  1/z is scaled down by 4e-6, and one flagged in ``cull`` is not drawn;
* anti-aliasing: ``aa x aa`` samples per pixel, drawn as an image ``aa``
  times larger, each pixel the integer mean of its block rounded half up.

Float results agree with the live code's to the last bit or two, not
always exactly (operations in another order), so on random scenes the two
could disagree only where a pixel centre lies within about 1e-13 pixels of
an edge or two depths straddle a key boundary, which the cross-checked
scenes do not meet.  Where a centre lies exactly on an edge, this module's
edge functions are exact for the test's lattice scenes, so it applies the
top-left rule as documented; so does the live code, whose crossings
``xtop + ((cy - ytop) * dx) / dy`` are exact there too, whatever the slope.

Slow by design (a Python loop over triangles, numpy only over one
bounding box at a time): use small images.
"""

from __future__ import annotations

import math

import numpy as np

# docs/semantics-render.md, "Back faces and culling".
BACK_BIAS = 4e-6
# docs/semantics-render.md, "Camera": within this sine of the Y axis, -Z is the up hint.
PARALLEL_SINE = 1e-9


def rasterize(triangles, shade, camera, background=255, cull=None, aa: int = 1) -> np.ndarray:
    """Draw flat-shaded triangles with a depth buffer, one triangle at a time.

    Parameters
    ----------
    triangles : array_like, shape (N, 3, 3)
        Corner ``k`` of triangle ``i`` is ``triangles[i, k]``, in world coordinates.
    shade : array_like, shape (N,) or (N, 3)
        One level 0..255, or one ``(r, g, b)`` of them, per triangle.
    camera : Camera
        Read for ``point``, ``width``, ``size`` and ``near`` only.
    background : int or tuple of 3 int, optional
        What empty pixels show (default 255).
    cull : array_like of bool, shape (N,), optional
        Where True, the triangle is left out if it faces away from the eye.
    aa : int, optional
        Each pixel averages ``aa x aa`` samples (default 1).

    Returns
    -------
    ndarray, shape (H, W) or (H, W, 3), uint8
        RGB when ``shade`` or ``background`` is a colour.
    """
    tris = np.asarray(triangles, dtype=np.float64)
    shade = np.asarray(shade).astype(np.uint8)
    colour = shade.ndim == 2 or np.ndim(background) == 1
    if colour:
        shade = shade.reshape(len(tris), -1) * np.ones((1, 3), np.uint8)
        background = np.asarray(background, np.uint8) * np.ones(3, np.uint8)
    W, H = camera.size
    view = _View(camera.point, camera.width, W * aa, H * aa, camera.near)
    keys = np.zeros((H * aa, W * aa), dtype=np.int64)  # 0: nothing drawn
    eye = [float(c) for c in camera.point]
    for number, tri in enumerate(tris.tolist()):
        faces = _faces(tri, eye)
        if not faces and cull is not None and cull[number]:
            continue
        for piece in _clip(view, [view.to_camera(p) for p in tri]):
            _draw(keys, [view.to_pixels(p) for p in piece], number, 1.0 if faces else 1.0 - BACK_BIAS)
    drawn = keys != 0
    samples = np.empty(keys.shape + shade.shape[1:], np.uint8)
    samples[...] = background
    samples[drawn] = shade[keys[drawn] & 0xFFFFFFFF]
    return box_filter(samples, aa)


def box_filter(samples, aa: int) -> np.ndarray:
    """Each ``aa x aa`` block's mean, rounded half up, in integers.

    Parameters
    ----------
    samples : ndarray, shape (aa H, aa W) or (aa H, aa W, 3), uint8

    Returns
    -------
    ndarray, shape (H, W) or (H, W, 3), uint8
    """
    h, w = samples.shape[0] // aa, samples.shape[1] // aa
    blocks = samples.reshape((h, aa, w, aa) + samples.shape[2:]).astype(np.int64)
    total = blocks.sum(axis=(1, 3))
    return ((total + aa * aa // 2) // (aa * aa)).astype(np.uint8)


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _faces(tri, eye) -> bool:
    """Whether the triangle's right-hand normal points towards the eye."""
    v0, v1, v2 = tri
    return _dot(_cross(_sub(v1, v0), _sub(v2, v0)), _sub(eye, v0)) > 0.0


class _View:
    """The camera of docs/semantics-render.md, from its defining numbers."""

    def __init__(self, point, width, W, H, near):
        self.eye = [float(c) for c in point]
        distance = math.sqrt(_dot(self.eye, self.eye))
        forward = [-c / distance for c in self.eye]
        right = _cross(forward, [0.0, 1.0, 0.0])
        if math.sqrt(_dot(right, right)) < PARALLEL_SINE:
            right = _cross(forward, [0.0, 0.0, -1.0])
        length = math.sqrt(_dot(right, right))
        right = [c / length for c in right]
        self.axes = [right, _cross(right, forward), forward]
        self.F = distance * W / float(width)
        self.W, self.H, self.near = W, H, float(near)

    def to_camera(self, p):
        q = _sub(p, self.eye)
        return [_dot(q, axis) for axis in self.axes]

    def to_pixels(self, c):
        """Pixel x, pixel y and 1/z of a camera-space point."""
        x, y, z = c
        return (self.W / 2 + self.F * x / z, self.H / 2 - self.F * y / z, 1.0 / z)


def _clip(view, verts):
    """The triangles (lists of 3 camera-space points) of the part in front of the near plane.

    A walk round the triangle keeps the vertices in front and adds a cut
    point on each edge that crosses the plane, starting from a vertex in
    front whose predecessor is not; the polygon is then fanned from its
    first vertex.
    """
    near = view.near
    front = [v[2] >= near for v in verts]
    if all(front):
        return [verts]
    if not any(front):
        return []
    start = next(k for k in range(3) if front[k] and not front[k - 1])
    poly = []
    for k in range(start, start + 3):
        a, b = verts[k % 3], verts[(k + 1) % 3]
        if front[k % 3]:
            poly.append(a)
        if front[k % 3] != front[(k + 1) % 3]:
            inner, outer = (a, b) if front[k % 3] else (b, a)
            t = (near - inner[2]) / (outer[2] - inner[2])
            poly.append([inner[0] + t * (outer[0] - inner[0]), inner[1] + t * (outer[1] - inner[1]), near])
    return [[poly[0], poly[k], poly[k + 1]] for k in range(1, len(poly) - 1)]


def _edge(a, b, px, py):
    """Twice the signed area of (a, b, p): positive when p is right of a -> b on screen (y down)."""
    return (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0])


def _owns(a, b) -> bool:
    """Whether centres exactly on edge a -> b (interior on its positive side) are inside.

    With that orientation a left edge runs upward on screen (y down) and a
    top edge, horizontal, runs to the right.
    """
    return b[1] < a[1] or (b[1] == a[1] and b[0] > a[0])


def _draw(keys, pts, number, scale):
    """Depth-test one projected triangle (3 of (x, y, 1/z)) into ``keys`` (H, W), int64."""
    p0, p1, p2 = pts
    area = _edge(p0, p1, p2[0], p2[1])
    if area == 0.0:
        return
    if area < 0.0:
        p1, p2 = p2, p1
        area = -area
    H, W = keys.shape
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    c0, c1 = max(0, math.floor(min(xs))), min(W, math.floor(max(xs)) + 1)
    r0, r1 = max(0, math.floor(min(ys))), min(H, math.floor(max(ys)) + 1)
    if c0 >= c1 or r0 >= r1:
        return
    px = np.arange(c0, c1, dtype=np.float64)[None, :] + 0.5
    py = np.arange(r0, r1, dtype=np.float64)[:, None] + 0.5
    inside = np.ones((r1 - r0, c1 - c0), dtype=bool)
    # weight[k]: the edge function of the edge opposite vertex k.
    weight = {}
    for k, (a, b) in enumerate([(p1, p2), (p2, p0), (p0, p1)]):
        e = _edge(a, b, px, py)
        inside &= (e > 0.0) | ((e == 0.0) & _owns(a, b))
        weight[k] = e
    if not inside.any():
        return
    w = (weight[0] * p0[2] + weight[1] * p1[2] + weight[2] * p2[2]) / area
    w = np.clip(w, min(p[2] for p in pts), max(p[2] for p in pts)) * scale
    key = ((w.view(np.int64) >> 32) << 32) | number
    box = keys[r0:r1, c0:c1]
    np.copyto(box, key, where=inside & (key > box))
