"""A vectorized z-buffer rasterizer for flat-shaded triangles, grey or RGB, with optional supersampling.

No Python loop runs per triangle, row or pixel (only per band of rows, a
handful per frame).  The pipeline:

1. to camera space; back faces dropped where ``cull`` allows;
2. clipping against the near plane (a triangle with one vertex behind it
   becomes a quadrilateral, i.e. two triangles; with two behind, a smaller
   triangle);
3. projection; each triangle splits at its middle vertex into two
   trapezoids, and each trapezoid gives one span per pixel row, bounded by
   its two edges' crossings of the row's centre line;
4. on frames above ``_ONE_BAND_PIXELS``, trapezoids are cut at the edges
   of bands of rows (about ``_BAND_PIXELS`` pixels each) and drawn band by
   band, so a band's depth keys stay in the cache and no pass ever runs
   over the whole frame: the cost grows with the pixels drawn, not faster;
5. spans expand to fragments (pixels) with ``np.repeat``; each fragment
   gets an int64 key: the upper 32 bits of the float64 ``1/z`` (sign,
   exponent and 20 mantissa bits, so keys order like depths to about 1e-6
   relative) above the triangle's number.  One ``np.maximum.at`` then does
   the depth test *and* the tie rule: nearer wins, and at equal depth the
   higher triangle number wins.  The fragments whose key is still there
   afterwards paint their triangle's grey level or colour; in a new grey
   image (``rasterize``) the tag is the triangle's number shifted left by 8
   bits above its grey level (less the background's, modulo 256), so the
   depth keys cast to bytes, plus the background, are the pixels, and no
   fragment is looked at again.

Coverage rule: a pixel belongs to a triangle when its centre lies inside it;
a centre exactly on an edge belongs to the triangle to its right, or below it
for a horizontal edge (the top-left rule).  Two triangles sharing an edge
therefore never both cover, nor both miss, a pixel along it: the crossing
point of a shared edge is computed from the same two vertices in the same
order in both triangles, so it is bit-identical.  It is computed as
``xtop + ((cy - ytop) * dx) / dy``, not with a rounded slope, so a centre
lying exactly on an edge is found exactly on it whenever the product is
exact and the crossing representable.

Anti-aliasing (``aa=N``) draws the same triangles with a camera of N times
the resolution in each direction (:meth:`Camera.supersampled`), so each
pixel gets N x N samples on a regular grid, then :func:`downsample` takes
each block's mean rounded half up, in integers: the bytes are exact.

Speed notes (measured with callgrind and CPU time; see
``benchmarks/raster.py``): ``np.repeat`` costs a few instructions per element
where a gather (``np.take``, fancy indexing) costs 15-30, so per-span values
reach fragments by repeating, never by gathering with a span index.  With a
few hundred triangles a frame costs mostly numpy calls (about a microsecond
each), so the per-triangle steps work on whole (k, N) blocks.  At 640x480
the fragments' arrays and the depth keys outgrow the processor's cache,
and a pass over memory that has left it costs two to three times one over
memory still there: work is ordered so that an array is made just before
it is used (the depth keys are zeroed just before the depth test).  The
benchmark
times this rasterizer beside its version before these optimisations (that
of commit 2526992, read from git history).

``tests/runtime/render/raster_reference.py`` is an independent
per-triangle edge-function rasterizer written from the rules of
docs/semantics-render.md; the tests check byte equality with it on random
scenes and on scenes where edges pass exactly through pixel centres and
depths tie.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from liganimate.runtime.errors import RenderError
from liganimate.runtime.render.camera import Camera, image_size

# The depth buffer's "nothing drawn here".  Every fragment's key is
# positive (it starts with the bits of a positive float64).
EMPTY = 0

_INDEX_BITS = 32
_INDEX_MASK = (1 << _INDEX_BITS) - 1
_DEPTH_MASK = ~_INDEX_MASK
#: A depth key's triangle number (its low 32 bits) and its 1/z (the rest, as float64 bits).
INDEX_MASK, DEPTH_MASK = _INDEX_MASK, _DEPTH_MASK
_MAX_TRIANGLES = 1 << 31

#: Largest anti-aliasing factor: aa x aa samples per pixel.
MAX_AA = 8

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

# Spans are drawn in bands of whole rows of about this many pixels, one band
# at a time: the band's depth keys (8 bytes a pixel) then stay in the L2
# cache, and no pass ever runs over the whole frame's depth buffer.
_BAND_PIXELS = 1 << 16
# ...except in frames of at most this many pixels, drawn as one band: a band
# costs a few dozen numpy calls, more than the cache saves on a small frame.
_ONE_BAND_PIXELS = 1 << 19


def rasterize(triangles, shade, camera: Camera, background=255, cull=None, aa: int = 1) -> np.ndarray:
    """Draw flat-shaded triangles with a z-buffer into a new image.

    Parameters
    ----------
    triangles : array_like, shape (N, 3, 3)
        World-space vertices, ``triangles[i, k]`` is vertex ``k`` of
        triangle ``i``.
    shade : array_like, shape (N,) or (N, 3)
        Grey level (0 black .. 255 white) of each triangle, or its
        ``(r, g, b)`` colour (each 0..255).
    camera : Camera
        The view; its ``size`` is the image size.
    background : int or tuple of 3 int, optional
        Grey level, or ``(r, g, b)`` colour, where no triangle is drawn;
        default 255 (white).
    cull : array_like of bool, shape (N,), optional
        True where the triangle is part of a closed solid whose faces are
        wound counter-clockwise seen from outside (outward right-hand
        normals); such triangles are dropped when they face away from the
        eye.  This is only a speed-up: for closed solids seen from outside
        the image is the same with or without it.
    aa : int, optional
        Anti-aliasing: each pixel is the rounded mean of ``aa x aa``
        samples on a regular grid (1, the default, is one sample at the
        pixel centre).  See :func:`downsample`.

    Returns
    -------
    ndarray, shape (H, W) or (H, W, 3), uint8
        The image, row 0 at the top; (H, W, 3) RGB when ``shade`` or
        ``background`` is a colour, else (H, W) grey.

    Raises
    ------
    RenderError
        If the arrays have the wrong shape, coordinates are not finite, a
        grey level or colour component is outside 0..255, or ``aa`` is not
        a whole number from 1 to ``MAX_AA``.
    """
    aa = _aa(aa)
    tris, shade, cull = _check(triangles, shade, cull)
    bg = _background(background)
    shade, bg = _same_kind(shade, bg)
    cam = camera.supersampled(aa)
    W, H = cam.size
    img = np.empty((H, W) + np.shape(bg), dtype=np.uint8)  # (filled by _draw)
    # Nothing drawn yet: the depth buffer need only span the pixels touched.
    _draw(None, img, tris, shade, cam, cull, 0, bg)
    return downsample(img, aa)


def downsample(img, aa: int) -> np.ndarray:
    """Box-filter an image supersampled ``aa`` times in each direction.

    Each output pixel is the mean of its ``aa x aa`` block, rounded to the
    nearest integer with halves rounded up, in exact integer arithmetic
    (so the bytes never depend on floating point).

    Parameters
    ----------
    img : ndarray, shape (aa H, aa W) or (aa H, aa W, 3), uint8
        The supersampled image.
    aa : int
        The supersampling factor.

    Returns
    -------
    ndarray, shape (H, W) or (H, W, 3), uint8
        ``img`` itself when ``aa`` is 1.
    """
    if aa == 1:
        return img
    # Sums of aa columns, then of aa rows of those, over strided views: a
    # few contiguous passes, where a reduction over two axes of a
    # (H, aa, W, aa) view runs an order of magnitude slower.  uint16 holds
    # 64 * 255.
    cols = img[:, 0::aa].astype(np.uint16)
    for b in range(1, aa):
        cols += img[:, b::aa]
    total = cols[0::aa].copy()
    for a in range(1, aa):
        total += cols[a::aa]
    n = aa * aa
    total += n // 2
    total //= n
    return total.astype(np.uint8)


class Framebuffer:
    """An image and its depth buffer, accumulating several draws.

    Draws share the depth test, so e.g. several ticks drawn into one image
    hide each other correctly; a later draw counts as "later" for the tie
    rule.  The buffers hold ``aa x aa`` samples per pixel; :attr:`image` is
    their box-filtered mean.  The image turns RGB at the first draw in
    colour (grey levels ``g`` are then the colour ``(g, g, g)``).

    Parameters
    ----------
    size : tuple of int
        ``(W, H)`` in pixels.
    background : int or tuple of 3 int, optional
        Initial grey level or ``(r, g, b)`` colour; default 255.
    aa : int, optional
        Samples per pixel in each direction (see :func:`rasterize`); default 1.

    Attributes
    ----------
    samples : ndarray, shape (aa H, aa W) or (aa H, aa W, 3), uint8
        The supersampled image so far (updated in place by :meth:`draw`).
    zbuf : ndarray, shape (aa H, aa W), int64
        Depth keys; ``EMPTY`` (zero) where nothing is drawn.  A key is the
        float64 ``1/z`` with its low 32 bits replaced by the triangle's
        number: the larger key is the nearer surface, or at equal depth the
        later triangle.
    count : int
        Triangles drawn so far; the next draw's triangles are numbered from here.
    aa : int
        The supersampling factor.
    """

    def __init__(self, size, background=255, aa: int = 1):
        W, H = image_size(size)
        self.aa = _aa(aa)
        self.size = (W, H)
        bg = _background(background)
        self.samples = np.empty((H * self.aa, W * self.aa) + np.shape(bg), dtype=np.uint8)
        self.samples[...] = bg
        self.zbuf = np.zeros((H * self.aa, W * self.aa), dtype=np.int64)  # all EMPTY
        self.count = 0

    @property
    def image(self) -> np.ndarray:
        """The image so far, shape (H, W) or (H, W, 3), uint8.

        With ``aa`` 1 this is :attr:`samples` itself, updated in place by
        later draws; otherwise a new downsampled array.
        """
        return downsample(self.samples, self.aa)

    def draw(self, triangles, shade, camera: Camera, cull=None) -> None:
        """Draw triangles over what is already there, depth-tested.

        Parameters
        ----------
        triangles : array_like, shape (N, 3, 3)
            World-space vertices.
        shade : array_like, shape (N,) or (N, 3)
            Grey levels or ``(r, g, b)`` colours, 0..255.
        camera : Camera
            The view; ``camera.size`` must equal the framebuffer's size.
        cull : array_like of bool, shape (N,), optional
            See :func:`rasterize`.
        """
        tris, shade, cull = _check(triangles, shade, cull)
        if shade.ndim == 2 and self.samples.ndim == 2:
            self.samples = np.repeat(self.samples[:, :, None], 3, axis=2)
        elif shade.ndim == 1 and self.samples.ndim == 3:
            shade = np.repeat(shade[:, None], 3, axis=1)
        W, H = camera.size
        if (W, H) != self.size:
            raise RenderError(
                f"The camera's image size {W}x{H} does not match the {self.size[0]}x{self.size[1]} image being drawn into."
            )
        self.count = _draw(self.zbuf, self.samples, tris, shade, camera.supersampled(self.aa), cull, self.count)

    def depth(self) -> np.ndarray:
        """The depth of the visible surface at each sample.

        Returns
        -------
        ndarray, shape (aa H, aa W), float64
            Camera-space depth to about 1e-6 relative (a back face that won
            reads about 4e-6 too far, see ``_BACK_BIAS``); ``inf`` where
            nothing was drawn.
        """
        drawn = self.zbuf != EMPTY
        out = np.full(self.zbuf.shape, np.inf)
        out[drawn] = 1.0 / (self.zbuf[drawn] & _DEPTH_MASK).view(np.float64)
        return out


def _draw(zbuf, img, tris, shade, camera, cull, first_index, background=None):
    """Draw triangles into ``img`` (its depth keys ``zbuf``, or None for a new image, of ``background``).

    A new image's pixels are all written here, the background where nothing
    is drawn.  Returns the next draw's first triangle number.
    """
    n = len(tris)
    if first_index + n >= _MAX_TRIANGLES:
        raise RenderError(f"Too many triangles in one image (more than {_MAX_TRIANGLES - 1}).")
    W, H = camera.size
    band_rows = None if W * H <= _ONE_BAND_PIXELS else max(1, _BAND_PIXELS // W)
    # A fresh image's depth keys are this draw's alone, so their tags may
    # carry each triangle's grey level in their low byte, less the
    # background's (modulo 256): the depth keys cast to bytes, plus the
    # background's grey level, are then the image, EMPTY (0) giving the
    # background (see _band).
    packed = zbuf is None and shade.ndim == 1 and np.ndim(background) == 0 and n <= _PACKED_TRIANGLES
    grey = shade - np.uint8(background) if packed else None
    spans = _spans(tris, cull, camera, first_index, band_rows, grey) if n else None
    single = spans is not None and len(spans.bounds) == 2
    if zbuf is None and not (single and packed):
        img[...] = background
    if spans is None:
        return first_index + n
    flat_img = img.reshape((-1,) + img.shape[2:])
    flat_z = None if zbuf is None else zbuf.reshape(-1)
    bounds, tbounds = spans.bounds, spans.tbounds
    if single:
        lo, hi = spans.origin, spans.origin + spans.size
        if zbuf is None and packed:
            # _band writes every pixel of rows lo..hi; the rest is background.
            flat_img[:lo] = background
            flat_img[hi:] = background
        zb = None if flat_z is None else flat_z[lo:hi]  # (None: made by _band, when it needs it)
        _band(zb, flat_img[lo:hi], spans, shade, first_index, flat_z is None, background if packed else None)
        return first_index + n
    starts = bounds[:-1]
    offset, count = spans.offset, spans.pixels
    los = np.minimum.reduceat(offset, starts).tolist()
    his = np.maximum.reduceat(offset + count, starts).tolist()
    if flat_z is None:
        # One buffer for every band: clearing it while it is still in the
        # cache is cheaper than fresh zeroed pages from the kernel.
        scratch = np.zeros(max(h - l for l, h in zip(los, his)), dtype=np.int64)
    for i, (lo, hi) in enumerate(zip(los, his)):
        sl, tl = slice(bounds[i], bounds[i + 1]), slice(tbounds[i], tbounds[i + 1])
        if flat_z is not None:
            zb = flat_z[lo:hi]
        else:
            zb = scratch[: hi - lo]
            if i:
                zb.fill(EMPTY)
        band = _Spans(
            offset[sl] - lo, spans.wstart[sl], spans.step[sl], count[sl], spans.tag[tl], spans.nrows[tl], [], [], 0, 0
        )
        _band(zb, flat_img[lo:hi], band, shade, first_index, flat_z is None, background if packed else None)
    return first_index + n


# At most this many triangles (2**24) in a draw whose keys carry grey levels:
# tag (number << 8 | grey) must fit the key's low 32 bits.
_PACKED_TRIANGLES = 1 << 24


class _Spans(NamedTuple):
    """What :func:`_spans` gives: spans (P,) grouped by trapezoid, trapezoids (T,) grouped by band."""

    offset: np.ndarray  #: (P,) int64: pixel number of the span's first pixel, counted from ``origin``
    wstart: np.ndarray  #: (P,) 1/z at the span's first pixel
    step: np.ndarray  #: (P,) 1/z step from pixel to pixel
    pixels: np.ndarray  #: (P,) int64: the span's pixels (some spans are empty)
    tag: np.ndarray  #: (T,) int64: the key tag of each trapezoid's fragments
    nrows: np.ndarray  #: (T,) int64: each trapezoid's spans, in order
    bounds: list  #: B + 1 span numbers: band k's spans are ``bounds[k]:bounds[k + 1]``
    tbounds: list  #: B + 1 trapezoid numbers: band k's trapezoids
    origin: int  #: with one band: the pixel number offsets count from (the first row drawn's)
    size: int  #: with one band: the pixels from ``origin`` to the end of the last row drawn


def _band(zb, im, spans: _Spans, shade, first_index, fresh, packed):
    """Depth-test one band's spans into its depth keys and image (views of the band's pixel range).

    ``zb`` None stands for new depth keys, all EMPTY.  ``fresh``: the depth
    keys were all EMPTY before this draw.  ``packed``
    (only in a fresh draw): None, or the background's grey level ``b`` (an
    int 0..255), the tags being ``number << 8 | (grey level - b) % 256``.
    """
    offset, wstart, step, count = spans.offset, spans.wstart, spans.step, spans.pixels
    # ends[k]: fragments up to the end of span k; ends0 has a 0 before them.
    ends0 = np.empty(len(count) + 1, dtype=np.int64)
    ends0[0] = 0
    ends = np.add.accumulate(count, out=ends0[1:])
    if ends[-1] == 0 and packed is None:
        return
    if ends[-1] <= _CHUNK:
        # A trapezoid's fragments are consecutive, so its tag is repeated
        # over all of them at once (np.repeat costs about as much per input
        # element as per output element, and there are ten times fewer
        # trapezoids than spans).
        frags = ends0.take(spans.nrows.cumsum())
        frags[1:] -= frags[:-1].copy()
        pix, key = _expand(offset, wstart, step, count, ends0, spans.tag, frags)
        if zb is None:
            # Zeroed only now, so that it is still in the cache for the
            # depth test rather than pushed out by the fragments' arrays.
            zb = np.zeros(len(im), dtype=np.int64)
        np.maximum.at(zb, pix, key)
        if packed is not None:
            _unpack(im, zb, packed)
            return
        if fresh:
            # Every key in the buffer is this draw's: each fragment may
            # paint its pixel's winner (some pixels several times, alike).
            key = zb.take(pix)
            key &= _INDEX_MASK
            if first_index:
                key -= first_index
            im[pix] = shade.take(key, axis=0)
            return
        won = (zb.take(pix) == key).nonzero()[0]
        # A pixel is won by at most one fragment (keys are unique per
        # triangle, and a triangle covers a pixel at most once), so this
        # assignment has no repeated indices.
        key = key.take(won)
        key &= _INDEX_MASK
        key -= first_index
        im[pix.take(won)] = shade.take(key, axis=0)
        return
    # Too many fragments for one go (deep overlap): depth-test chunk by
    # chunk, then find this draw's winners by scanning the band.
    if zb is None:
        zb = np.zeros(len(im), dtype=np.int64)
    tag = spans.tag.repeat(spans.nrows)  # each span's
    lo = 0
    for hi in np.searchsorted(ends, np.arange(_CHUNK, ends[-1], _CHUNK), side="right").tolist() + [len(count)]:
        if hi > lo:
            sl = slice(lo, hi)
            cut = count[sl]
            pix, key = _expand(offset[sl], wstart[sl], step[sl], cut, ends0[lo : hi + 1] - ends0[lo], tag[sl], cut)
            np.maximum.at(zb, pix, key)
            lo = hi
    if packed is not None:
        _unpack(im, zb, packed)
        return
    num = zb & _INDEX_MASK
    sel = ((zb != EMPTY) & (num >= first_index)).nonzero()[0]
    im[sel] = shade.take(num.take(sel) - first_index, axis=0)


def _unpack(im, zb, background: int) -> None:
    """Pixels from a packed draw's depth keys: the low byte (the winner's grey level less the background's) plus the background's."""
    np.copyto(im, zb, casting="unsafe")  # (a cast to bytes keeps the low byte)
    if background:
        im += np.uint8(background)


# Shared read-only aranges, grown as needed (replaced, never modified, so
# threads may use them concurrently).
_ARANGE = (np.arange(0, dtype=np.int64), np.arange(0, dtype=np.float64))


def _aranges(n: int):
    """``arange`` of at least ``n`` elements as int64 and float64 (shared; do not modify)."""
    global _ARANGE
    iar, far = _ARANGE
    if len(iar) < n:
        iar = np.arange(max(n, 2 * len(iar)), dtype=np.int64)
        far = iar.astype(np.float64)
        _ARANGE = (iar, far)
    return iar, far


def _expand(offset, wstart, step, count, ends0, tag, tag_count):
    """Spans (P,) to fragments: pixel numbers (F,) and depth keys (F,).

    ``ends0`` (P + 1,) is 0 then ``count.cumsum()``: each span's first
    fragment, and the number of fragments.  The fragments' tags are
    ``tag.repeat(tag_count)``.
    """
    n = int(ends0[-1])
    iar, far = _aranges(n)
    starts = ends0[:-1]
    # 1/z = wstart + (i - start) * step for fragment i.  Anchoring the
    # ramp at fragment 0 instead saves two passes; its extra rounding is
    # about 1e-16 * start * |step| (start < _CHUNK + W, and |step| at most
    # the triangle's 1/z range), far below the key's 1e-6 resolution.
    w = step.repeat(count)
    w *= far[:n]
    w += (wstart - starts * step).repeat(count)
    key = w.view(np.int64)
    key &= _DEPTH_MASK
    key += tag.repeat(tag_count)
    # (The pixel numbers last: the depth test reads them next.)
    pix = (offset - starts).repeat(count)
    pix += iar[:n]
    return pix, key


def _aa(aa) -> int:
    try:
        v = int(aa)
    except (TypeError, ValueError, OverflowError):
        v = 0
    if isinstance(aa, bool) or v != aa or not 1 <= v <= MAX_AA:
        raise RenderError(
            f"Anti-aliasing must be a whole number of samples from 1 to {MAX_AA} per pixel side, not {aa!r}."
        )
    return v


def _background(value):
    """A grey level (int) or a colour (uint8 array, shape (3,))."""
    if np.ndim(value) == 0:
        try:
            v = int(value)
        except (TypeError, ValueError, OverflowError):
            v = -1
        if isinstance(value, bool) or v != value or not 0 <= v <= 255:
            raise RenderError(f"The background grey level must be a whole number from 0 to 255, not {value!r}.")
        return v
    try:
        c = np.asarray(value, dtype=np.float64)
        ok = c.shape == (3,) and bool(np.all(c == np.round(c))) and bool(np.all((c >= 0) & (c <= 255)))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise RenderError(f"The background colour must be three whole numbers from 0 to 255, not {value!r}.")
    return c.astype(np.uint8)


def _same_kind(shade, bg):
    """Grey shades and background stay grey; if either is a colour, both become colours."""
    if shade.ndim == 2 and np.ndim(bg) == 0:
        bg = np.full(3, bg, dtype=np.uint8)
    elif shade.ndim == 1 and np.ndim(bg) == 1:
        shade = np.repeat(shade[:, None], 3, axis=1)
    return shade, bg


def _check(triangles, shade, cull):
    tris = np.asarray(triangles, dtype=np.float64)
    if tris.ndim != 3 or tris.shape[1:] != (3, 3):
        raise RenderError(f"Triangles must be an array of shape (N, 3, 3), not {tris.shape}.")
    # (Whether every coordinate is finite is checked by _camera_triangles,
    # on its component-major copy while that is still in the cache.)
    s = np.asarray(shade)
    if s.shape not in ((len(tris),), (len(tris), 3)):
        raise RenderError(
            f"Expected {len(tris)} grey levels or {len(tris)} (r, g, b) colours, one per triangle, got shape {s.shape}."
        )
    if s.dtype != np.uint8:
        try:
            bad = s.size and (not np.all(np.isfinite(s)) or s.min() < 0 or s.max() > 255 or np.any(s != np.round(s)))
        except TypeError:
            bad = True
        if bad:
            what = "Colour components" if s.ndim == 2 else "Grey levels"
            raise RenderError(f"{what} must be whole numbers from 0 to 255.")
        s = s.astype(np.uint8)
    if cull is not None:
        cull = np.asarray(cull, dtype=bool)
        if cull.shape != (len(tris),):
            raise RenderError(f"Expected {len(tris)} cull flags, one per triangle, got shape {cull.shape}.")
    return tris, s, cull


def _spans(tris, cull, camera: Camera, first_index: int, band_rows: int | None = None, grey=None) -> _Spans | None:
    """Triangles (N, 3, 3) to spans, grouped by trapezoid and into bands of rows.

    Returns the spans (see :class:`_Spans`), or None when nothing is
    visible.  A span's ``offset`` is ``row * W + first column`` counted
    from ``origin``.  Spans ``bounds[k]:bounds[k + 1]`` (trapezoids
    ``tbounds[k]:tbounds[k + 1]``) lie in rows ``[b * band_rows, (b + 1) *
    band_rows)`` for some band ``b`` that grows with ``k``; ``band_rows``
    None means one band.  A trapezoid's tag is ``first_index`` plus its
    triangle's number, or, given the triangles' ``grey`` levels (uint8, and
    ``first_index`` 0), its number shifted left by 8 bits with its grey
    level in the low byte.

    Every step works on whole (k, N) or (k, P) blocks: with a few hundred
    triangles, the cost of a frame is mostly the number of numpy calls.
    """
    W, H = camera.size
    drawn = _camera_triangles(tris, cull, camera)
    if drawn is None:
        return None
    cam, front, src = drawn
    found = _trapezoids(_pixel_vertices(cam, camera), front, src, first_index, (W, H), grey)
    if found is None:
        return None
    table, first_row, nrows, total, tag = found
    table, nrows, tag, bounds, tbounds, rows = _banded(table, first_row, nrows, total, tag, band_rows, H)

    # One entry per (trapezoid, row), grouped by trapezoid, so np.repeat
    # spreads per-trapezoid values over them: it costs a few instructions
    # per element where a gather (np.take, fancy indexing) costs 15-30.
    t = table.repeat(nrows, axis=1)
    cy = np.add(_aranges(total)[1][:total], t[13])
    # Crossings of the long and the short edge (rows 0 and 1 of xab), then
    # the first and one past the last pixel column (rows 0 and 1 of cols).
    xab = np.subtract(cy, t[2:4])
    xab *= t[4:6]
    xab /= t[6:8]
    xab += t[0:2]
    cols = np.empty((2, total))
    np.minimum(xab[0], xab[1], out=cols[0])
    np.maximum(xab[0], xab[1], out=cols[1])
    cols -= 0.5
    np.ceil(cols, out=cols)
    np.maximum(cols, 0, out=cols)
    np.minimum(cols, W, out=cols)
    length = cols[1] - cols[0]
    count = length.astype(np.int64)

    # 1/z at the first and last pixel centre, clamped to the triangle's range
    # so that a sliver's ill-conditioned plane cannot produce a wild depth.
    # (fmin/fmax also turn a NaN from a degenerate plane into a bound.)
    wrow = cy * t[10]
    wrow += t[9]
    ws = cols + _CENTRES
    ws *= t[8]
    ws += wrow
    np.fmax(ws, t[11], out=ws)
    np.fmin(ws, t[12], out=ws)
    step = ws[1] - ws[0]
    length -= 1
    step /= np.maximum(length, 1, out=length)  # (as floats: exact, and no int-to-float pass)
    # Spans of no pixels stay: np.repeat skips them at no cost.
    cy -= 0.5 + rows[0]  # the row, counted from the first row drawn
    cy *= W
    cy += cols[0]
    origin, size = rows[0] * W, (rows[1] - rows[0]) * W
    return _Spans(cy.astype(np.int64), ws[0], step, count, tag, nrows, bounds, tbounds, origin, size)


def _camera_triangles(tris, cull, camera: Camera):
    """:func:`_spans`' first stage: the triangles drawn, in camera space and clipped at the near plane.

    Returns ``(cam, front, src)``: ``cam[k, i, j]`` coordinate k of vertex
    i of triangle j, whether each given triangle faces the camera, and the
    given triangle each drawn one comes from (None: itself); or None when
    nothing is left.
    """
    # Component-major from here on, v[i, k] being coordinate k of vertex i
    # of every triangle: numpy's loops over a last axis of length 3 cost
    # more per element than the arithmetic.
    n = len(tris)
    v = np.ascontiguousarray(tris.reshape(n, 9).T).reshape(3, 3, n)
    if not np.logical_and.reduce(np.isfinite(v), axis=None):
        raise RenderError("A triangle has a coordinate that is not a finite number.")
    # Facing is decided in world space (camera space is left-handed): the
    # sign of ((v1 - v0) x (v2 - v0)) . (eye - v0), cross product
    # component k being a[k+1] b[k+2] - a[k+2] b[k+1].
    a, b = v[1] - v[0], v[2] - v[0]
    cross = a.take(_NEXT, axis=0) * b.take(_AFTER, axis=0)
    cross -= a.take(_AFTER, axis=0) * b.take(_NEXT, axis=0)
    cross *= camera.point[:, None] - v[0]
    front = cross[0] + cross[1]
    front += cross[2]
    front = front > 0.0
    src = None  # the triangle each drawn one comes from; None for "itself"
    if cull is not None:
        keep = front | ~cull
        if not np.logical_and.reduce(keep):
            src = keep.nonzero()[0]
            v = v.take(src, axis=2)
    # To camera space as Camera.to_camera: component k is
    # x a[k, 0] + y a[k, 1] + z a[k, 2], added in that order.
    q = v - camera.point[:, None]
    axes = camera.axes[:, :, None, None]
    cam = q[:, 0] * axes[:, 0]  # (3 components, 3 vertices, n)
    cam += q[:, 1] * axes[:, 1]
    cam += q[:, 2] * axes[:, 2]
    if cam.shape[2] and np.minimum.reduce(cam[2], axis=None) < camera.near:
        clipped, src = _clip_near(cam.transpose(2, 1, 0), src, camera.near)
        cam = np.ascontiguousarray(clipped.transpose(2, 1, 0))
    if cam.shape[2] == 0:
        return None
    return cam, front, src


def _pixel_vertices(cam: np.ndarray, camera: Camera) -> np.ndarray:
    """:func:`_spans`' second stage: x, y and 1/z of each vertex (3, 3, m), sorted by y within a triangle."""
    W, H = camera.size
    m = cam.shape[2]
    # Projection to pixels (as Camera.camera_to_pixels), then the vertices
    # of each triangle sorted by y: that fixes the orientation of every edge
    # (top end first), which is what makes shared edges bit-identical.
    xyw = np.empty((3, 3, m))  # x, y and 1/z of each vertex
    s = camera.focal / cam[2]
    y = np.multiply(cam[1], s, out=xyw[1])
    np.subtract(0.5 * H, y, out=y)
    x = np.multiply(cam[0], s, out=xyw[0])
    x += 0.5 * W
    np.divide(1.0, cam[2], out=xyw[2])
    # A stable sort of three: vertices ordered by y, ties kept in their
    # order.  Its permutation follows from the three comparisons of a later
    # vertex's y with an earlier one's (y1 < y0, y2 < y1, y2 < y0), packed
    # into a code 0..7 (two codes cannot occur); one gather then moves x, y
    # and 1/z of all vertices at once.
    less = np.empty((3, m), dtype=bool)
    np.less(xyw[1, 1:], xyw[1, :2], out=less[:2])
    np.less(xyw[1, 2], xyw[1, 0], out=less[2])
    bits = less.view(np.uint8)
    code = bits[2] << 2
    code |= bits[1] << 1
    code |= bits[0]
    where = (_SORTED * m).take(code, axis=1)  # (3 positions, m): flat index of the vertex there
    where += _aranges(m)[0][:m]
    return xyw.reshape(3, 3 * m).take(where.reshape(-1), axis=1).reshape(3, 3, m)


# _pixel_vertices' sort: _SORTED[p, code] is the vertex at position p.
_SORTED = np.array([[0, 1, 0, 0, 0, 1, 2, 2], [1, 0, 2, 1, 1, 2, 0, 1], [2, 2, 1, 2, 2, 0, 1, 0]])


def _trapezoids(xyw: np.ndarray, front, src, first_index: int, size: tuple, grey=None):
    """:func:`_spans`' third stage: the table of trapezoids (see the notes after :func:`_spans`).

    Returns ``(table, first_row, nrows, total, tag)``: the table (14, 2m),
    each trapezoid's first row and number of rows, their sum, and each
    trapezoid's tag (see :func:`_spans`); or None when no row is covered.
    """
    W, H = size
    m = xyw.shape[2]
    x, y, w = xyw
    x0, y0, w0 = x[0], y[0], w[0]

    # Each triangle is two trapezoids: rows whose centre r + 0.5 lies in
    # [y0, y1) are bounded by the long edge 0-2 and the upper edge 0-1,
    # rows in [y1, y2) by the long edge and the lower edge 1-2.
    # Trapezoids are numbered upper ones first, then lower ones.
    r = y - 0.5
    np.ceil(r, out=r)
    np.maximum(r, 0, out=r)
    np.minimum(r, H, out=r)
    r = r.astype(np.int64)
    d = xyw[:, 1:] - xyw[:, :1]  # (3, 2, m): vertices 1 and 2 minus vertex 0
    dx, dy, dw = d
    det = dx[0] * dy[1]
    det -= dx[1] * dy[0]
    visible = det != 0.0
    visible &= np.maximum(np.maximum(x0, x[1]), x[2]) > 0.5 - 1e-9
    visible &= np.minimum(np.minimum(x0, x[1]), x[2]) < W - 0.5 + 1e-9
    rows = r[1:] - r[:2]  # (2, m): rows of the upper and the lower trapezoid
    rows *= visible
    nrows = rows.reshape(-1)
    total = int(np.add.reduce(nrows))
    if total == 0:
        return None

    # A table of per-trapezoid values, one row per quantity (listed after
    # this function); a triangle's two trapezoids share the long edge, the
    # plane, the depth range and the tag.  An edge's crossing with row centre cy is
    # x = xtop + ((cy - ytop) * dx) / dy, from the edge's top vertex: the
    # same numbers, in the same order, for every triangle sharing the edge.
    # Multiplying before dividing (never by a rounded slope dx/dy) makes
    # the crossing exact whenever it is representable and the product is
    # exact, so a centre exactly on an edge is found exactly on it and the
    # top-left rule decides (e.g. edges between half-pixel points).
    table = np.empty((14, 2, m))
    upper = table[:, 0]
    table[0:4:2] = xyw[:2, :1]  # x and y of the long edge's top, vertex 0
    table[1:4:2] = xyw[:2, :2]  # ... of the short edge's top, vertex 0 or 1
    table[4:8:2] = d[:2, 1:]  # dx and dy of the long edge, 0 to 2
    np.subtract(xyw[:2, 1:], xyw[:2, :2], out=table[5:8:2])  # ... of the short edge, 0 to 1 or 1 to 2
    with np.errstate(divide="ignore", invalid="ignore"):
        # 1/z is affine in screen space: 1/z = wc + gx x + gy y.
        gx, wc, gy = upper[8], upper[9], upper[10]
        np.multiply(dw[0], dy[1], out=gx)
        gx -= dw[1] * dy[0]
        gx /= det
        np.multiply(dx[0], dw[1], out=gy)
        gy -= dx[1] * dw[0]
        gy /= det
        np.multiply(gx, x0, out=wc)
        np.subtract(w0, wc, out=wc)
        wc -= gy * y0
    np.minimum(np.minimum(w0, w[1]), w[2], out=upper[11])
    np.maximum(np.maximum(w0, w[1]), w[2], out=upper[12])
    faces = front if src is None else front.take(src)
    if not np.logical_and.reduce(faces):
        upper[8:13] *= np.where(faces, 1.0, 1.0 - _BACK_BIAS)
    table[8:13, 1] = upper[8:13]
    number = _aranges(m)[0][:m] if src is None else src
    if grey is None:
        tag = first_index + number
    else:
        tag = number << 8
        tag |= grey.take(number)
    first_row = r[:2].reshape(-1)  # (a view of r, which is not needed any more)
    return table.reshape(14, 2 * m), first_row, nrows, total, np.concatenate((tag, tag))


def _banded(table: np.ndarray, first_row: np.ndarray, nrows: np.ndarray, total: int, tag, band_rows, H: int):
    """:func:`_spans`' fourth stage: trapezoids cut at band boundaries and ordered by band; row 13 set.

    Returns ``(table, nrows, tag, bounds, tbounds, rows)``: ``rows`` is the
    first row drawn and one past the last with one band, else ``(0, H)``.
    """
    if band_rows is not None and band_rows < H:
        # Cut trapezoids at band boundaries, and order the pieces by band.
        live = nrows.nonzero()[0]
        top_band = first_row.take(live) // band_rows
        pieces = (first_row.take(live) + nrows.take(live) - 1) // band_rows - top_band + 1
        trap = live.repeat(pieces)
        band = (top_band - (pieces.cumsum() - pieces)).repeat(pieces)
        band += _aranges(len(trap))[0][: len(trap)]
        order = band.argsort(kind="stable")
        trap, band = trap.take(order), band.take(order)
        start = np.maximum(first_row.take(trap), band * band_rows)
        nrows = np.minimum(first_row.take(trap) + nrows.take(trap), (band + 1) * band_rows) - start
        first_row = start
        table, tag = table.take(trap, axis=1), tag.take(trap)
        ends = nrows.cumsum()
        change = (band[1:] != band[:-1]).nonzero()[0]
        bounds = [0] + ends.take(change).tolist() + [total]
        tbounds = [0] + (change + 1).tolist() + [len(trap)]
        rows = (0, H)
    else:
        ends = nrows.cumsum()
        bounds, tbounds = [0, total], [0, len(nrows)]
        # The rows drawn: one depth buffer covers them (and no more).
        drawn = nrows.nonzero()[0]  # (not empty: total > 0)
        rows = (
            int(np.minimum.reduce(first_row.take(drawn))),
            int(np.maximum.reduce((first_row + nrows).take(drawn))),
        )
    # Row 13: the trapezoid's first row centre minus the number of spans before it.
    first_row -= ends
    first_row += nrows
    np.add(first_row, 0.5, out=table[13])
    return table, nrows, tag, bounds, tbounds, rows


# Rows of _spans' table: 0-1 x of the top of the long and the short edge,
# 2-3 their y, 4-5 their dx (bottom minus top), 6-7 their dy, 8-10 gx, wc,
# gy of the plane 1/z = wc + gx x + gy y, 11-12 the least and greatest 1/z,
# 13 first row centre minus the number of spans before.
_NEXT, _AFTER = np.array([1, 2, 0]), np.array([2, 0, 1])

# From the first and one-past-last pixel column to the first and last centre.
_CENTRES = np.array([[0.5], [-0.5]])


def _clip_near(cam, src, near: float):
    """Clip camera-space triangles (M, 3, 3) to depth >= near.

    Returns the clipped triangles and, for each, the index of the triangle
    it came from (``src`` of it; ``src`` None stands for ``arange(M)``, and
    is returned as None when nothing is clipped).  New vertices are always interpolated from the vertex in
    front towards the vertex behind, so an edge shared by two triangles is
    cut at a bit-identical point in both.
    """
    inside = cam[:, :, 2] >= near
    nin = inside.sum(axis=1)
    if (nin == 3).all():
        return cam, src
    if src is None:
        src = np.arange(len(cam))
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
