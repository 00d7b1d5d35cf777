"""Reference for tests and benchmarks: the rasterizer as of commit 2526992, frozen.

Do not optimise this file: it is what runtime/render/raster.py is checked
against byte for byte (tests/runtime/render/test_raster_crosscheck.py) and
timed against (benchmarks/raster.py).  Its original description follows.

A vectorized z-buffer rasterizer for flat-shaded triangles.

No Python loop runs per triangle, row or pixel.  The pipeline:

1. to camera space; back faces dropped where ``cull`` allows;
2. clipping against the near plane (a triangle with one vertex behind it
   becomes a quadrilateral, i.e. two triangles; with two behind, a smaller
   triangle);
3. projection; each triangle splits at its middle vertex into two
   trapezoids, and each trapezoid gives one span per pixel row, bounded by
   its two edges' crossings of the row's centre line;
4. spans expand to fragments (pixels) with ``np.repeat``; each fragment
   gets an int64 key: the upper 32 bits of the float64 ``1/z`` (sign,
   exponent and 20 mantissa bits, so keys order like depths to about 1e-6
   relative) above the triangle's number.  One ``np.maximum.at`` then does
   the depth test *and* the tie rule: nearer wins, and at equal depth the
   higher triangle number wins.

Coverage rule: a pixel belongs to a triangle when its centre lies inside it;
a centre exactly on an edge belongs to the triangle to its right, or below it
for a horizontal edge (the top-left rule).  Two triangles sharing an edge
therefore never both cover, nor both miss, a pixel along it: the crossing
point of a shared edge is computed from the same two vertices in the same
order in both triangles, so it is bit-identical.

Speed notes (measured with callgrind and wall time; see
``benchmarks/raster.py``): ``np.repeat`` costs a few instructions per element
where a gather (``np.take``, fancy indexing) costs 15-30, so per-span values
reach fragments by repeating, never by gathering with a span index.  With
EMPTY = 0 a new depth buffer is ``np.zeros``, whose pages the kernel supplies
zeroed on first touch: cheaper than keeping a buffer and clearing it.
"""

from __future__ import annotations

import numpy as np

from liganimate.runtime.errors import RenderError
from liganimate.runtime.render.camera import Camera

# The depth buffer's "nothing drawn here".  Every fragment's key is
# positive (it starts with the bits of a positive float64).
EMPTY = 0

_INDEX_BITS = 32
_INDEX_MASK = (1 << _INDEX_BITS) - 1
_DEPTH_MASK = ~_INDEX_MASK
_MAX_TRIANGLES = 1 << 31

# Back-facing triangles have their 1/z scaled down by this fraction (about
# four units of the key's last depth bit).  For a closed solid seen from
# outside, every back-face pixel is also covered by a front face of the same
# solid at a depth no greater; along silhouettes the two depths are equal up
# to rounding, and the bias makes the front face win that near-tie, so
# drawing back faces (cull=None) gives exactly the image that culling them
# gives.
_BACK_BIAS = 4e-6

# Fragments expanded at once; bounds temporary memory at about 50 bytes each.
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
    # Nothing drawn yet: the depth buffer need only span the pixels touched.
    _draw(None, img, triangles, shade, camera, cull, 0)
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
        try:
            W, H = (int(s) for s in size)
            ok = W > 0 and H > 0 and (W, H) == tuple(size)
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise RenderError(f"The image size must be two positive whole numbers, not {size!r}.")
        self.size = (W, H)
        self.image = np.full((H, W), _grey(background, "background"), dtype=np.uint8)
        self.zbuf = np.zeros((H, W), dtype=np.int64)  # all EMPTY
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
            Camera-space depth to about 1e-6 relative (a back face that won
            reads about 4e-6 too far, see ``_BACK_BIAS``); ``inf`` where
            nothing was drawn.
        """
        drawn = self.zbuf != EMPTY
        out = np.full(self.zbuf.shape, np.inf)
        out[drawn] = 1.0 / (self.zbuf[drawn] & _DEPTH_MASK).view(np.float64)
        return out


def rasterize_into(zbuf, img, triangles, shade, camera: Camera, cull=None, first_index: int = 0) -> int:
    """Draw triangles into an existing image and depth buffer.

    Parameters
    ----------
    zbuf : ndarray, shape (H, W), int64, C-contiguous
        Depth keys, updated in place.  Start from all ``EMPTY`` (zero).  A key is
        the float64 ``1/z`` with its low 32 bits replaced by
        ``first_index + i``: the larger key is the nearer surface, or at
        equal depth the later triangle.  All draws into one buffer must
        use the same camera.
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
    return _draw(zbuf, img, triangles, shade, camera, cull, first_index)


def _draw(zbuf, img, triangles, shade, camera, cull, first_index):
    tris, shade = _check(triangles, shade, cull)
    n = len(tris)
    if first_index + n >= _MAX_TRIANGLES:
        raise RenderError(f"Too many triangles in one image (more than {_MAX_TRIANGLES - 1}).")
    spans = _spans(tris, cull, camera, first_index) if n else None
    if spans is None:
        return first_index + n
    offset, wstart, step, tag, count = spans
    flat_img = img.reshape(-1)
    if zbuf is None:
        # A fresh buffer: allocate depth keys for the touched range only.
        drawn = count > 0
        lo = int(offset[drawn].min())
        hi = int((offset[drawn] + count[drawn]).max())
        flat_z = np.zeros(hi - lo, dtype=np.int64)
        flat_img = flat_img[lo:hi]
        offset = offset - lo
    else:
        flat_z = zbuf.reshape(-1)
    ends = np.cumsum(count)
    if ends[-1] <= _CHUNK:
        pix, key = _expand(offset, wstart, step, tag, count, ends)
        np.maximum.at(flat_z, pix, key)
        won = flat_z[pix] == key
        # A pixel is won by at most one fragment (keys are unique per
        # triangle, and a triangle covers a pixel at most once), so this
        # assignment has no repeated indices.
        flat_img[pix[won]] = shade[(key[won] & _INDEX_MASK) - first_index]
        return first_index + n
    # Too many fragments for one go: depth-test chunk by chunk, then find
    # this draw's winners by scanning the whole buffer for its numbers.
    lo = 0
    for hi in np.searchsorted(ends, np.arange(_CHUNK, ends[-1], _CHUNK), side="right").tolist() + [len(count)]:
        if hi > lo:
            sl = slice(lo, hi)
            pix, key = _expand(offset[sl], wstart[sl], step[sl], tag[sl], count[sl], None)
            np.maximum.at(flat_z, pix, key)
            lo = hi
    num = flat_z & _INDEX_MASK
    sel = np.flatnonzero((flat_z != EMPTY) & (num >= first_index))
    flat_img[sel] = shade[num[sel] - first_index]
    return first_index + n


# Shared read-only aranges, grown as needed (replaced, never modified, so
# threads may use them concurrently).
_ARANGE = (np.arange(0, dtype=np.int64), np.arange(0, dtype=np.float64))


def _expand(offset, wstart, step, tag, count, ends):
    """Spans (P,) to fragments: pixel numbers (F,) and depth keys (F,)."""
    global _ARANGE
    if ends is None:
        ends = np.cumsum(count)
    n = int(ends[-1])
    iar, far = _ARANGE
    if len(iar) < n:
        iar = np.arange(max(n, 2 * len(iar)), dtype=np.int64)
        far = iar.astype(np.float64)
        _ARANGE = (iar, far)
    starts = ends - count
    pix = np.repeat(offset - starts, count)
    pix += iar[:n]
    # 1/z = wstart + (i - start) * step for fragment i.  Anchoring the
    # ramp at fragment 0 instead saves two passes; its extra rounding is
    # about 1e-16 * start * |step| (start < _CHUNK + W, and |step| at most
    # the triangle's 1/z range), far below the key's 1e-6 resolution.
    w = np.repeat(step, count)
    w *= far[:n]
    w += np.repeat(wstart - starts * step, count)
    key = w.view(np.int64)
    key &= _DEPTH_MASK
    key += np.repeat(tag, count)
    return pix, key


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


def _spans(tris, cull, camera: Camera, first_index: int):
    """Triangles (N, 3, 3) to spans: (pixel offset, 1/z at first pixel, 1/z step, key tag, length).

    The pixel offset is ``row * W + first column``; all five arrays have
    shape (P,), one entry per span, and some spans may be empty.  Returns
    None when nothing is visible.
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

    # Each triangle is two trapezoids: rows whose centre r + 0.5 lies in
    # [y0, y1) are bounded by the long edge 0-2 and the upper edge 0-1,
    # rows in [y1, y2) by the long edge and the lower edge 1-2.
    r0 = np.clip(np.ceil(y0 - 0.5), 0, H).astype(np.int64)
    r1 = np.clip(np.ceil(y1 - 0.5), 0, H).astype(np.int64)
    r2 = np.clip(np.ceil(y2 - 0.5), 0, H).astype(np.int64)
    det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    xmax = np.maximum(np.maximum(x0, x1), x2)
    xmin = np.minimum(np.minimum(x0, x1), x2)
    visible = (det != 0.0) & (xmax > 0.5 - 1e-9) & (xmin < W - 0.5 + 1e-9)
    nrows = np.concatenate([np.where(visible, r1 - r0, 0), np.where(visible, r2 - r1, 0)])
    if not nrows.any():
        return None

    # An edge's crossing with row centre cy is x = xtop + (cy - ytop) * s,
    # from the edge's top vertex: the same numbers, in the same order, for
    # every triangle sharing the edge.
    with np.errstate(divide="ignore", invalid="ignore"):
        s_long = (x2 - x0) / (y2 - y0)
        s_short = np.concatenate([(x1 - x0) / (y1 - y0), (x2 - x1) / (y2 - y1)])
        # 1/z is affine in screen space: 1/z = wc + gx x + gy y.
        gx = ((w1 - w0) * (y2 - y0) - (w2 - w0) * (y1 - y0)) / det
        gy = ((x1 - x0) * (w2 - w0) - (x2 - x0) * (w1 - w0)) / det
        wc = w0 - gx * x0 - gy * y0
    wmin = np.minimum(np.minimum(w0, w1), w2)
    wmax = np.maximum(np.maximum(w0, w1), w2)
    if not front.all():
        scale = np.where(front[src], 1.0, 1.0 - _BACK_BIAS)
        wc, gx, gy, wmin, wmax = wc * scale, gx * scale, gy * scale, wmin * scale, wmax * scale
    tag = first_index + src

    # One entry per (trapezoid, row).  Pairs are grouped by trapezoid, so
    # np.repeat spreads per-trapezoid values over them; it costs a few
    # instructions per element where a gather (np.take, fancy indexing)
    # costs 15-30.
    def per_row(values):
        return np.repeat(values, nrows)

    def both(values):
        return np.concatenate([values, values])

    cy = np.arange(int(nrows.sum())) + per_row(np.concatenate([r0, r1]) - (np.cumsum(nrows) - nrows) + 0.5)
    xa = per_row(both(x0)) + (cy - per_row(both(y0))) * per_row(both(s_long))
    xb = per_row(np.concatenate([x0, x1])) + (cy - per_row(np.concatenate([y0, y1]))) * per_row(s_short)
    c0 = np.minimum(np.maximum(np.ceil(np.minimum(xa, xb) - 0.5), 0), W)
    c1 = np.minimum(np.maximum(np.ceil(np.maximum(xa, xb) - 0.5), 0), W)
    count = (c1 - c0).astype(np.int64)
    if not (count > 0).any():
        return None

    # 1/z at the first and last pixel centre, clamped to the triangle's range
    # so that a sliver's ill-conditioned plane cannot produce a wild depth.
    tgx = per_row(both(gx))
    wrow = per_row(both(wc)) + cy * per_row(both(gy))
    lo, hi = per_row(both(wmin)), per_row(both(wmax))
    # (fmin/fmax also turn a NaN from a degenerate plane into a bound.)
    wstart = np.fmin(np.fmax(wrow + (c0 + 0.5) * tgx, lo), hi)
    wend = np.fmin(np.fmax(wrow + (c1 - 0.5) * tgx, lo), hi)
    step = (wend - wstart) / np.maximum(count - 1, 1)
    # Spans of no pixels stay: np.repeat skips them at no cost.
    offset = ((cy - 0.5) * W + c0).astype(np.int64)
    return offset, wstart, step, per_row(both(tag)), count


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
