"""A vectorized z-buffer rasterizer for flat-shaded triangles.

No Python loop runs per triangle, row or pixel.  The pipeline is:

1. to camera space; back faces dropped where ``cull`` allows;
2. clipping against the near plane (a triangle with one vertex behind it
   becomes a quadrilateral, i.e. two triangles; with two behind, a smaller
   triangle);
3. projection, then one span per (triangle, pixel row), bounded by the two
   edges that cross the row's centre line;
4. spans expanded to fragments (pixels); each fragment gets an int64 key
   ``(float32 bits of 1/z) << 32 | triangle number``, so one
   ``np.maximum.at`` performs the depth test *and* the tie rule: nearer wins,
   and at exactly equal depth the higher triangle number wins.

Coverage rule: a pixel belongs to a triangle when its centre lies inside it;
a centre exactly on an edge belongs to the triangle to its right, or below it
for a horizontal edge (the top-left rule).  Two triangles sharing an edge
therefore never both cover, nor both miss, a pixel along it: the crossing
point of a shared edge is computed from the same two vertices in the same
order in both triangles, so it is bit-identical.

Speed note: at 640x480 the fragment arrays are a few hundred kB each, and
freshly allocated memory of that size costs a page fault per 4 kB (glibc
returns it to the system between calls), which measured as more than the
arithmetic itself.  Fragment work therefore runs in per-thread scratch
buffers, reused across calls and bounded by processing at most
``_CHUNK`` fragments at a time.
"""

from __future__ import annotations

import threading

import numpy as np

from .camera import Camera
from .errors import RenderError

# A key no fragment can produce: the depth buffer's "nothing drawn here".
EMPTY = np.iinfo(np.int64).min

_INDEX_BITS = 32
_INDEX_MASK = (1 << _INDEX_BITS) - 1
_MAX_TRIANGLES = 1 << 31

# Back-facing triangles have their depth key lowered by this many float32
# ulps of 1/z (about 2e-6 relative).  For a closed solid seen from outside,
# every back-face pixel is also covered by a front face of the same solid at
# a depth no greater; along silhouettes those depths are equal up to
# rounding, and the bias makes the front face win that near-tie, so drawing
# back faces (cull=None) gives exactly the image that culling them gives.
_BACK_BIAS = 16

# Fragments expanded at once; bounds scratch memory at about 40 bytes each.
_CHUNK = 1 << 18


def rasterize(triangles, shade, camera: Camera, background: int = 255, cull=None) -> np.ndarray:
    """Draw flat-shaded triangles with a z-buffer into a new image.

    Parameters
    ----------
    triangles : array_like, shape (N, 3, 3)
        World-space vertices, ``triangles[i, k]`` is vertex ``k`` of
        triangle ``i``.
    shade : array_like, shape (N,)
        Grey level (0 black .. 255 white) of each triangle.
    camera : Camera
        The view; its ``size`` is the image size.
    background : int, optional
        Grey level where no triangle is drawn; default 255 (white).
    cull : array_like of bool, shape (N,), optional
        True where the triangle is part of a closed solid whose faces are
        wound counter-clockwise seen from outside (outward right-hand
        normals); such triangles are dropped when they face away from the
        eye.  This is only a speed-up: for closed solids seen from outside
        the image is the same with or without it.

    Returns
    -------
    ndarray, shape (H, W), uint8
        The image, row 0 at the top.

    Raises
    ------
    RenderError
        If the arrays have the wrong shape, coordinates are not finite, or a
        grey level is outside 0..255.
    """
    W, H = camera.size
    img = np.full((H, W), _grey(background, "background"), dtype=np.uint8)
    zbuf = _SCRATCH.clean_zbuf((H, W))
    try:
        _draw(zbuf, img, triangles, shade, camera, cull, 0, restore=True)
    except BaseException:
        zbuf.fill(EMPTY)
        raise
    return img


class Framebuffer:
    """An image and its depth buffer, accumulating several draws.

    Draws share the depth test, so e.g. several ticks drawn into one image
    hide each other correctly; a later draw counts as "later" for the tie
    rule.

    Parameters
    ----------
    size : tuple of int
        ``(W, H)`` in pixels.
    background : int, optional
        Initial grey level; default 255.

    Attributes
    ----------
    image : ndarray, shape (H, W), uint8
        The image so far (updated in place by :meth:`draw`).
    zbuf : ndarray, shape (H, W), int64
        Depth keys (see :func:`rasterize_into`); ``EMPTY`` where nothing is drawn.
    count : int
        Triangles drawn so far; the next draw's triangles are numbered from here.
    """

    def __init__(self, size, background: int = 255):
        W, H = (int(s) for s in size)
        self.size = (W, H)
        self.image = np.full((H, W), _grey(background, "background"), dtype=np.uint8)
        self.zbuf = np.full((H, W), EMPTY, dtype=np.int64)
        self.count = 0

    def draw(self, triangles, shade, camera: Camera, cull=None) -> None:
        """Draw triangles over what is already there, depth-tested.

        Parameters
        ----------
        triangles : array_like, shape (N, 3, 3)
            World-space vertices.
        shade : array_like, shape (N,)
            Grey levels 0..255.
        camera : Camera
            The view; ``camera.size`` must equal the framebuffer's size.
        cull : array_like of bool, shape (N,), optional
            See :func:`rasterize`.
        """
        self.count = rasterize_into(self.zbuf, self.image, triangles, shade, camera, cull, self.count)

    def depth(self) -> np.ndarray:
        """The depth of the visible surface at each pixel centre.

        Returns
        -------
        ndarray, shape (H, W), float64
            Camera-space depth, to float32 precision (a back face that won
            is reported slightly too far, see ``_BACK_BIAS``); ``inf`` where
            nothing was drawn.
        """
        drawn = self.zbuf != EMPTY
        inv = (self.zbuf >> _INDEX_BITS).astype(np.int32).view(np.float32)
        out = np.full(self.zbuf.shape, np.inf)
        out[drawn] = 1.0 / inv[drawn].astype(np.float64)
        return out


def rasterize_into(zbuf, img, triangles, shade, camera: Camera, cull=None, first_index: int = 0) -> int:
    """Draw triangles into an existing image and depth buffer.

    Parameters
    ----------
    zbuf : ndarray, shape (H, W), int64, C-contiguous
        Depth keys, updated in place.  Start from all ``EMPTY``.  A key is
        ``(float32 bits of 1/z) << 32 | (first_index + i)``: the larger key
        is the nearer surface, or at equal depth the later triangle.
    img : ndarray, shape (H, W), uint8, C-contiguous
        The image, updated in place where a triangle wins the depth test.
    triangles : array_like, shape (N, 3, 3)
        World-space vertices.
    shade : array_like, shape (N,)
        Grey levels 0..255.
    camera : Camera
        The view; ``camera.size`` must be ``(W, H)``.
    cull : array_like of bool, shape (N,), optional
        See :func:`rasterize`.
    first_index : int, optional
        Number of triangle 0 for the tie rule; pass the previous call's
        return value so later draws win ties.

    Returns
    -------
    int
        ``first_index + N``: the number to give the next draw.
    """
    W, H = camera.size
    if img.shape != (H, W) or zbuf.shape != (H, W):
        raise RenderError(
            f"The camera's image size {W}x{H} does not match the {img.shape[1]}x{img.shape[0]} image being drawn into."
        )
    if not (img.flags.c_contiguous and zbuf.flags.c_contiguous and zbuf.dtype == np.int64 and img.dtype == np.uint8):
        raise RenderError("The image and depth buffer must be C-contiguous uint8 and int64 arrays.")
    return _draw(zbuf, img, triangles, shade, camera, cull, first_index, restore=False)


def _draw(zbuf, img, triangles, shade, camera, cull, first_index, restore):
    """rasterize_into; with ``restore``, leave zbuf all EMPTY again afterwards."""
    tris, shade = _check(triangles, shade, cull)
    n = len(tris)
    if first_index + n >= _MAX_TRIANGLES:
        raise RenderError(f"Too many triangles in one image (more than {_MAX_TRIANGLES - 1}).")
    spans = _spans(tris, cull, camera, first_index) if n else None
    if spans is None:
        return first_index + n
    offset, wstart, step, tag, count = spans
    flat_z = zbuf.reshape(-1)
    flat_img = img.reshape(-1)
    scratch = _SCRATCH
    ends = np.cumsum(count)
    if ends[-1] <= _CHUNK:
        pix, key = scratch.expand(offset, wstart, step, tag, count, ends)
        np.maximum.at(flat_z, pix, key)
        won = np.equal(np.take(flat_z, pix, out=scratch.buf("won_key", len(pix), np.int64)), key,
                       out=scratch.buf("won", len(pix), bool))
        # Each pixel is won by at most one fragment (keys are unique per
        # triangle, and a triangle covers a pixel at most once), so this
        # assignment has no repeated indices.
        sel = pix[won]
        flat_img[sel] = shade[(flat_z[sel] & _INDEX_MASK) - first_index]
        if restore:
            flat_z[pix] = EMPTY
        return first_index + n
    # Too many fragments for one go: depth-test chunk by chunk, then find
    # this draw's winners by scanning the whole buffer for its numbers.
    lo = 0
    for hi in np.searchsorted(ends, np.arange(_CHUNK, ends[-1], _CHUNK), side="right").tolist() + [len(count)]:
        if hi > lo:
            sl = slice(lo, hi)
            pix, key = scratch.expand(offset[sl], wstart[sl], step[sl], tag[sl], count[sl], None)
            np.maximum.at(flat_z, pix, key)
            lo = hi
    num = flat_z & _INDEX_MASK
    sel = np.flatnonzero((flat_z != EMPTY) & (num >= first_index))
    flat_img[sel] = shade[num[sel] - first_index]
    if restore:
        flat_z.fill(EMPTY)
    return first_index + n


class _Scratch(threading.local):
    """Per-thread buffers reused across calls (see the module's speed note)."""

    def __init__(self):
        self.bufs = {}
        self.zbuf = None
        self.arange = np.arange(0, dtype=np.int64)

    def buf(self, name, n, dtype):
        b = self.bufs.get(name)
        if b is None or len(b) < n:
            b = self.bufs[name] = np.empty(max(n, 2 * (0 if b is None else len(b)), 1 << 12), dtype)
        return b[:n]

    def clean_zbuf(self, shape):
        """An all-EMPTY int64 buffer of ``shape``; callers must leave it all EMPTY."""
        if self.zbuf is None or self.zbuf.shape != shape:
            self.zbuf = np.full(shape, EMPTY, dtype=np.int64)
        return self.zbuf

    def expand(self, offset, wstart, step, tag, count, ends):
        """Spans to fragments: pixel numbers and depth keys (views of scratch buffers)."""
        if ends is None:
            ends = np.cumsum(count)
        n = int(ends[-1])
        if len(self.arange) < n:
            self.arange = np.arange(max(n, 2 * len(self.arange)), dtype=np.int64)
        ar = self.arange[:n]
        starts = ends - count
        # span number of each fragment: a cumulative sum of span starts
        sid = self.buf("sid", n, np.int64)
        sid.fill(0)
        sid[starts[1:]] = 1
        np.cumsum(sid, out=sid)
        pix = np.take(offset - starts, sid, out=self.buf("pix", n, np.int64))
        pix += ar
        k = np.take(starts, sid, out=self.buf("k", n, np.int64))
        np.subtract(ar, k, out=k)
        w = np.take(step, sid, out=self.buf("w", n, np.float64))
        w *= k
        w += np.take(wstart, sid, out=self.buf("w2", n, np.float64))
        w32 = self.buf("w32", n, np.float32)
        w32[:] = w
        key = self.buf("key", n, np.int64)
        key[:] = w32.view(np.int32)
        key <<= _INDEX_BITS
        key += np.take(tag, sid, out=k)
        return pix, key


_SCRATCH = _Scratch()


def _grey(value, what: str) -> int:
    try:
        v = int(value)
    except (TypeError, ValueError):
        v = -1
    if v != value or not 0 <= v <= 255:
        raise RenderError(f"The {what} grey level must be a whole number from 0 to 255, not {value!r}.")
    return v


def _check(triangles, shade, cull):
    tris = np.asarray(triangles, dtype=np.float64)
    if tris.ndim != 3 or tris.shape[1:] != (3, 3):
        raise RenderError(f"Triangles must be an array of shape (N, 3, 3), not {tris.shape}.")
    if not np.isfinite(tris).all():
        raise RenderError("A triangle has a coordinate that is not a finite number.")
    s = np.asarray(shade)
    if s.shape != (len(tris),):
        raise RenderError(f"Expected {len(tris)} grey levels, one per triangle, got shape {s.shape}.")
    if s.dtype != np.uint8:
        if s.size and (not np.all(np.isfinite(s)) or s.min() < 0 or s.max() > 255 or np.any(s != np.round(s))):
            raise RenderError("Grey levels must be whole numbers from 0 to 255.")
        s = s.astype(np.uint8)
    if cull is not None and np.shape(cull) != (len(tris),):
        raise RenderError(f"Expected {len(tris)} cull flags, one per triangle, got shape {np.shape(cull)}.")
    return tris, s


# Per-triangle parameters, one row each, so that spans gather them in one
# np.take: edge crossings use x = xtop + (y - ytop) * slope for the long edge
# (0-2) and the upper (0-1) / lower (1-2) short edges, vertices sorted by y.
_Y0, _Y1, _X0, _X1, _S02, _S01, _S12, _W0, _GX, _GY, _WMIN, _WMAX = range(12)


def _spans(tris, cull, camera: Camera, first_index: int):
    """Triangles to non-empty spans: (pixel offset, 1/z at first pixel, 1/z step, key tag, length).

    The pixel offset is ``row * W + first column``; all arrays have one
    entry per span.  Returns None when nothing is visible.
    """
    W, H = camera.size
    v0, v1, v2 = tris[:, 0], tris[:, 1], tris[:, 2]
    # Facing is decided in world space (camera space is left-handed).
    a, b = v1 - v0, v2 - v0
    c = camera.point - v0
    front = (
        (a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]) * c[:, 0]
        + (a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]) * c[:, 1]
        + (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) * c[:, 2]
    ) > 0.0
    src = np.arange(len(tris))
    if cull is not None:
        keep = front | ~np.asarray(cull, dtype=bool)
        if not keep.all():
            src = np.flatnonzero(keep)
            tris = tris[src]
    cam, src = _clip_near(camera.to_camera(tris), src, camera.near)
    m = len(src)
    if m == 0:
        return None

    scr = camera.camera_to_pixels(cam)  # (m, 3, 3): x, y, depth
    # Sorting vertices by y fixes the orientation of every edge (top end
    # first), which is what makes shared edges bit-identical.
    order = np.argsort(scr[:, :, 1], axis=1, kind="stable") + 3 * np.arange(m)[:, None]
    scr = np.take(scr.reshape(-1, 3), order.reshape(-1), axis=0).reshape(m, 3, 3)
    x0, x1, x2 = scr[:, 0, 0], scr[:, 1, 0], scr[:, 2, 0]
    y0, y1, y2 = scr[:, 0, 1], scr[:, 1, 1], scr[:, 2, 1]
    w0, w1, w2 = 1.0 / scr[:, 0, 2], 1.0 / scr[:, 1, 2], 1.0 / scr[:, 2, 2]

    # Rows whose centre r + 0.5 lies in [y0, y2).
    r0 = np.clip(np.ceil(y0 - 0.5), 0, H).astype(np.int64)
    r1 = np.clip(np.ceil(y2 - 0.5), 0, H).astype(np.int64)
    det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    xmax = np.maximum(np.maximum(x0, x1), x2)
    xmin = np.minimum(np.minimum(x0, x1), x2)
    visible = (r1 > r0) & (det != 0.0) & (xmax > 0.5 - 1e-9) & (xmin < W - 0.5 + 1e-9)
    nrows = np.where(visible, r1 - r0, 0)
    if not nrows.any():
        return None

    p = np.empty((m, 12))
    p[:, _Y0], p[:, _Y1], p[:, _X0], p[:, _X1] = y0, y1, x0, x1
    with np.errstate(divide="ignore", invalid="ignore"):
        p[:, _S02] = (x2 - x0) / (y2 - y0)
        p[:, _S01] = (x1 - x0) / (y1 - y0)
        p[:, _S12] = (x2 - x1) / (y2 - y1)
        # 1/z is affine in screen space: 1/z = w0 + gx (x - x0) + gy (y - y0).
        p[:, _GX] = ((w1 - w0) * (y2 - y0) - (w2 - w0) * (y1 - y0)) / det
        p[:, _GY] = ((x1 - x0) * (w2 - w0) - (x2 - x0) * (w1 - w0)) / det
    p[:, _W0] = w0
    p[:, _WMIN] = np.minimum(np.minimum(w0, w1), w2)
    p[:, _WMAX] = np.maximum(np.maximum(w0, w1), w2)

    # One entry per (triangle, row).
    t = np.repeat(np.arange(m), nrows)
    row = np.arange(len(t)) - np.repeat(np.cumsum(nrows) - nrows - r0, nrows)
    q = np.take(p, t, axis=0)
    cy = row + 0.5
    dy = cy - q[:, _Y0]
    xa = q[:, _X0] + dy * q[:, _S02]
    # Unused branches may hold inf/nan from horizontal edges; np.where drops them.
    with np.errstate(invalid="ignore"):
        xb = np.where(cy < q[:, _Y1], q[:, _X0] + dy * q[:, _S01], q[:, _X1] + (cy - q[:, _Y1]) * q[:, _S12])
    c0 = np.clip(np.ceil(np.minimum(xa, xb) - 0.5), 0, W).astype(np.int64)
    c1 = np.clip(np.ceil(np.maximum(xa, xb) - 0.5), 0, W).astype(np.int64)
    count = c1 - c0
    nz = np.flatnonzero(count > 0)
    if len(nz) == 0:
        return None
    if len(nz) < len(count):
        q, t, row, c0, c1, count, dy = q[nz], t[nz], row[nz], c0[nz], c1[nz], count[nz], dy[nz]

    # 1/z at the first and last pixel centre, clamped to the triangle's range
    # so that a sliver's steep plane cannot produce a wild depth.
    gx = q[:, _GX]
    wrow = q[:, _W0] + dy * q[:, _GY] - q[:, _X0] * gx
    wstart = np.clip(wrow + (c0 + 0.5) * gx, q[:, _WMIN], q[:, _WMAX])
    wend = np.clip(wrow + (c1 - 0.5) * gx, q[:, _WMIN], q[:, _WMAX])
    step = (wend - wstart) / np.maximum(count - 1, 1)

    orig = src[t]
    tag = first_index + orig
    if not front.all():
        tag -= (~front[orig]).astype(np.int64) * (_BACK_BIAS << _INDEX_BITS)
    return row * W + c0, wstart, step, tag, count


def _clip_near(cam, src, near: float):
    """Clip camera-space triangles (M, 3, 3) to depth >= near.

    Returns the clipped triangles and, for each, the index of the triangle
    it came from.  New vertices are always interpolated from the vertex in
    front towards the vertex behind, so an edge shared by two triangles is
    cut at a bit-identical point in both.
    """
    inside = cam[:, :, 2] >= near
    nin = inside.sum(axis=1)
    if (nin == 3).all():
        return cam, src
    out = [cam[nin == 3]]
    out_src = [src[nin == 3]]

    def cut(a, b):
        # a in front, b behind the plane.
        t = (near - a[:, 2]) / (b[:, 2] - a[:, 2])
        p = a + t[:, None] * (b - a)
        p[:, 2] = near
        return p

    one = np.flatnonzero(nin == 1)
    if len(one):
        # Rotate so the vertex in front comes first; rotation keeps winding.
        k = np.argmax(inside[one], axis=1)
        v = cam[one]
        a = v[np.arange(len(one)), k]
        b = v[np.arange(len(one)), (k + 1) % 3]
        c = v[np.arange(len(one)), (k + 2) % 3]
        out.append(np.stack([a, cut(a, b), cut(a, c)], axis=1))
        out_src.append(src[one])

    two = np.flatnonzero(nin == 2)
    if len(two):
        k = np.argmin(inside[two], axis=1)  # the vertex behind
        v = cam[two]
        a = v[np.arange(len(two)), k]
        b = v[np.arange(len(two)), (k + 1) % 3]
        c = v[np.arange(len(two)), (k + 2) % 3]
        pb, pc = cut(b, a), cut(c, a)
        out.append(np.stack([b, c, pc], axis=1))
        out.append(np.stack([b, pc, pb], axis=1))
        out_src += [src[two], src[two]]
    return np.concatenate(out), np.concatenate(out_src)
