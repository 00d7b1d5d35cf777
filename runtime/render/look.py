"""The modern look: lit faces, a soft contact shadow, and soft outlines that also smooth the edges.

The thesis' own look (``look="thesis"``) draws every triangle flat in the
grey level or colour its LIGHTNESS and COLOUR give, on white: exactly the
rasterizer's output, byte for byte as it always was.  The modern look
(``look="modern"``, the default) draws the same triangles with the same
rasterizer and then:

1. **Lights** each triangle (faceted): its shade is multiplied by
   ``ambient + key * max(0, n . L)`` (at most white), ``n`` the unit
   normal of the side facing the eye and ``L`` the direction towards a key
   light fixed relative to the camera (upper left, in front of the
   figures).  Faces at the same angle to the light keep the order of their
   LIGHTNESS and the hue of their COLOUR.
2. **Shadows** the ground: a height map of the lowest surface above each
   point of the ground, drawn by the same rasterizer from far below, gives
   a darkness that fades with height (a planted foot casts a dark, sharp
   patch; a lifted one a faint one) and is blurred; the background pixels
   that see that ground are darkened by it.
3. **Outlines** every discontinuity of the depth buffer: between the drawn
   and the background (silhouettes), across a jump in depth (a limb over
   another), between different objects, and across a crease (normals more
   than ``crease`` degrees apart) or a change of shade.  The line is drawn
   on the nearer side, blurred with a [1 2 1] kernel each way, and laid
   over the image as a darkening of its own colour.  Since every colour
   edge gets a soft line, this is also the look's anti-aliasing: a
   post-pass over the pixels near the drawing, much cheaper than
   supersampling (which ``aa`` still adds on top, if asked).

Everything is computed over the rectangle of pixels the drawing (and its
shadow) touches, with numpy operations that do not depend on the machine:
the same scene gives the same bytes.  The parameters are those of
:class:`Look`; docs/semantics-render.md ("Looks") describes them.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from liganimate.runtime.errors import RenderError
from liganimate.runtime.render.camera import Camera
from liganimate.runtime.render.raster import DEPTH_MASK, INDEX_MASK, Framebuffer, downsample
from liganimate.runtime.values import joined_shades

#: The names ``look=`` and ``--look`` accept.
LOOK_NAMES = ("modern", "thesis")
#: The look used when none is named.
DEFAULT_LOOK = "modern"


@dataclass(frozen=True)
class Look:
    """The parameters of the modern look.

    Attributes
    ----------
    outline : float
        Outline strength in pixels: a line's core is ``outline`` times as
        dark as a full line, its soft edge spreads one pixel each side;
        0 draws no outlines (and so smooths no edges).
    ink : float
        How dark a full outline is, as the fraction of the colour under it
        that remains (0 black, 1 invisible).
    crease : float
        Angle in degrees between two faces' normals above which their
        common edge is outlined.
    light : tuple of 3 float
        Direction towards the key light in camera coordinates (x right,
        y up, z away from the eye); normalised when used.
    ambient : float
        Share of its shade a face turned away from the key light keeps.
    key : float
        Share added to a face turned straight to the key light (ambient
        plus key above 1 brightens it, up to white).
    shadow : float
        Darkness of the ground where a surface touches it (0 none, 1 black).
    shadow_reach : float
        Height above the ground, as a fraction of the drawing's height, at
        which a surface stops casting its contact shadow.
    background : int
        Grey level of the background.
    """

    outline: float = 1.0
    ink: float = 0.25
    crease: float = 50.0
    light: tuple = (-0.3, 0.6, -0.75)
    ambient: float = 0.75
    key: float = 0.4
    shadow: float = 0.55
    shadow_reach: float = 0.5
    background: int = 244


#: The modern look's parameters.
MODERN = Look()

# Texels along each side of a shadow map.
_SHADOW_TEXELS = 64
# The soft line's kernel: [1 2 1] / 4 each way, as offsets (rows or
# columns) and weights of the nine neighbours.
_SPREAD_AT = np.array([[-1, -1, -1, 0, 0, 0, 1, 1, 1]]), np.array([[-1, 0, 1, -1, 0, 1, -1, 0, 1]])
_SPREAD = np.array([[1.0, 2.0, 1.0, 2.0, 4.0, 2.0, 1.0, 2.0, 1.0]]) / 16.0
# How many times wider than high an object must be to count as a floor.
_FLOOR_RATIO = 20.0
# Relative difference of depth within which a drawn surface counts as the ground itself.
_ON_GROUND = 2e-3
# Cosine of the angle below which two faces' normals count as parallel.
_COPLANAR = 0.99995
# Relative jump in 1/z between neighbouring pixels that counts as a depth edge.
_DEPTH_JUMP = 0.01
# The shadow camera's distance below the ground, in shadow-map widths: far
# enough that its projection is nearly orthographic, near enough that the
# depth key's resolution (about 1e-6 of the distance) stays fine.
_SHADOW_DISTANCE = 100.0


def check_look(look, name: str = "--look") -> str:
    """``look`` as one of :data:`LOOK_NAMES`, or a RenderError naming the option.

    Parameters
    ----------
    look : object
        What the user gave.
    name : str
        The option, as shown in the message (``"--look"`` or ``"look="``).

    Returns
    -------
    str
    """
    if isinstance(look, str) and look in LOOK_NAMES:
        return look
    shown = f"{name}{look!r}" if name.endswith("=") else f"{name} {look}"
    raise RenderError(f"{shown} is not a look; give one of {', '.join(LOOK_NAMES)}")


def draw_modern(size, merged, aa: int = 1, look: Look = MODERN) -> np.ndarray:
    """Draw one image in the modern look.

    Parameters
    ----------
    size : (int, int)
        ``(W, H)``.
    merged : list of (Camera, list of (triangles, shade, cull))
        The image's draws, in order, each with its camera (already sized
        ``size``).
    aa : int
        Supersampling factor on top of the look's own smoothing.
    look : Look

    Returns
    -------
    ndarray, shape (H, W) or (H, W, 3), uint8
    """
    fb = Framebuffer(size, look.background, aa=aa)
    # Triangles are numbered from 1, so that a depth key's low word is 0
    # exactly where nothing is drawn; row 0 of the tables stands for that.
    fb.count = 1
    normals, shades, groups, world = [np.zeros((1, 3))], [np.zeros(1, np.uint8)], [np.full(1, -1)], []
    planes = [np.zeros(1)]
    group = 0
    cameras: list = []
    for camera, parts in merged:
        parts = [p for p in parts if len(p[0])]
        if not parts:
            continue
        tris = np.concatenate([p[0] for p in parts]) if len(parts) > 1 else parts[0][0]
        shade = joined_shades(p[1] for p in parts) if len(parts) > 1 else parts[0][1]
        cull = np.concatenate([p[2] for p in parts]) if len(parts) > 1 else parts[0][2]
        n = _visible_normals(tris, camera.point)
        lit = _lit(shade, n, camera, look)
        fb.draw(tris, lit, camera, cull)
        normals.append(n)
        planes.append(np.einsum("ij,ij->i", n, tris[:, 0]))
        shades.append(np.asarray(shade, dtype=np.uint8))  # as given: the light's steps between facets are no edge
        groups.append(np.repeat(np.arange(group, group + len(parts)), [len(p[0]) for p in parts]))
        world.append(tris)
        cameras.append(camera)
        group += len(parts)
    if not world:
        return fb.image
    img, zbuf = fb.samples, fb.zbuf
    cam = cameras[-1].supersampled(aa)
    tris = np.concatenate(world)
    _shadow(img, zbuf, tris, np.concatenate(groups[1:]), cam, look)
    if look.outline > 0:
        table = (np.concatenate(normals), np.concatenate(planes), _shade_codes(shades), np.concatenate(groups))
        box = _drawn_box([(c.supersampled(aa), t) for c, t in zip(cameras, world)], zbuf.shape)
        if box is not None:
            # Lines as strong as asked from 480 rows up, fainter on smaller images (thin limbs stay visible).
            _outline(img, zbuf, table, look.outline * min(1.0, math.sqrt(size[1] / 480.0)), look, box)
    return downsample(img, aa)


def _shade_codes(shades) -> np.ndarray:
    """One int64 a triangle that is equal exactly when two triangles' drawn shades are."""
    out = []
    for s in shades:
        s = s.astype(np.int64)
        out.append(s if s.ndim == 1 else (s[:, 0] << 16) | (s[:, 1] << 8) | s[:, 2])
    if any(s.ndim == 2 for s in shades):
        out = [o if s.ndim == 2 else o * 0x010101 for o, s in zip(out, shades)]
    return np.concatenate(out)


def _visible_normals(tris, eye) -> np.ndarray:
    """Unit normals (N, 3) of the triangles' sides facing ``eye`` (zero for triangles without area)."""
    a = tris[:, 1] - tris[:, 0]
    b = tris[:, 2] - tris[:, 0]
    n = np.cross(a, b)
    facing = np.einsum("ij,ij->i", n, eye - tris[:, 0])
    n[facing < 0] *= -1.0
    length = np.sqrt(np.einsum("ij,ij->i", n, n))
    length[length == 0] = np.inf
    return n / length[:, None]


def _lit(shade, normals, camera: Camera, look: Look) -> np.ndarray:
    """Shades (N,) or (N, 3) lit by the key light and the ambient term, as uint8."""
    light = np.asarray(look.light, dtype=np.float64)
    light = light / math.sqrt(float(light @ light))
    towards = light @ camera.axes  # camera (right, up, forward) to world
    diffuse = np.maximum(normals @ towards, 0.0)
    factor = look.ambient + look.key * diffuse
    s = np.asarray(shade, dtype=np.float64)
    out = s * (factor if s.ndim == 1 else factor[:, None])
    return np.minimum(np.floor(out + 0.5), 255.0).astype(np.uint8)


# ------------------------------------------------------------------ shadow
def _shadow(img, zbuf, tris, groups, camera: Camera, look: Look) -> None:
    """Darken the ground where it lies under the drawing (in place).

    Objects (``groups``) at least twenty times as wide or deep as they are
    high are floors: they receive the shadow and cast none, and the ground
    is the top of the highest of them.  Without a floor the ground is the
    plane y = 0, or the lowest point drawn if that is lower.  The
    background receives the shadow too, as if the ground went on.
    """
    if look.shadow <= 0:
        return
    floor = _floors(tris, groups)
    casters = tris[~floor]
    if not len(casters):
        return
    ys = casters[:, :, 1]
    ground = float(tris[floor][:, :, 1].max()) if floor.any() else min(0.0, float(ys.min()))
    reach = look.shadow_reach * max(float(ys.max()) - ground, 1e-9)
    # The map reaches past the casters by the blur's spread (see _shadow_map).
    x0, x1 = float(casters[:, :, 0].min()) - 0.8 * reach, float(casters[:, :, 0].max()) + 0.8 * reach
    z0, z1 = float(casters[:, :, 2].min()) - 0.8 * reach, float(casters[:, :, 2].max()) + 0.8 * reach
    extent = max(x1 - x0, z1 - z0)
    centre = (0.5 * (x0 + x1), ground, 0.5 * (z0 + z1))
    dark = _shadow_map(casters - np.array(centre), extent, reach, look.shadow)
    if dark is None:
        return
    region = _ground_region(camera, _dark_box(dark, centre, extent), ground, img.shape)
    if region is not None:
        _darken_ground(img, zbuf, camera, region, dark, centre, extent)


def _floors(tris, groups) -> np.ndarray:
    """True for the triangles (N,) of objects at least twenty times as wide or deep as they are high."""
    n = int(groups.max()) + 1
    lo = np.full((n, 3), np.inf)
    hi = np.full((n, 3), -np.inf)
    np.minimum.at(lo, groups, tris.min(axis=1))
    np.maximum.at(hi, groups, tris.max(axis=1))
    span = hi - lo
    flat = span[:, 1] * _FLOOR_RATIO <= np.maximum(span[:, 0], span[:, 2])
    flat &= np.maximum(span[:, 0], span[:, 2]) > 0
    return flat[groups]


def _dark_box(dark, centre, extent: float) -> tuple:
    """The ground rectangle (x0, x1, z0, z1) of the texels the shadow darkens by a visible amount."""
    n = _SHADOW_TEXELS
    tv, tu = (dark >= 0.5 / 255).nonzero()
    if not len(tv):
        return (centre[0], centre[0], centre[2], centre[2])
    texel = extent / n
    cx, cz = centre[0], centre[2]
    return (
        cx - (tu.max() + 1 - 0.5 * n) * texel,
        cx - (tu.min() - 0.5 * n) * texel,
        cz + (tv.min() - 0.5 * n) * texel,
        cz + (tv.max() + 1 - 0.5 * n) * texel,
    )


def _darken_ground(img, zbuf, camera: Camera, region, dark, centre, extent: float) -> None:
    """Darken the pixels of ``region`` that see the ground (background, or a surface on it) by the shadow map."""
    r0, r1, c0, c1 = region
    cx, ground, cz = centre
    rows, cols = np.divmod(np.arange((r1 - r0) * (c1 - c0)), c1 - c0)
    # The ray through each pixel's centre (camera z = 1 along it), met with the ground at depth t.
    W, H = camera.size
    px = (cols + (c0 + 0.5 - 0.5 * W)) / camera.focal
    py = ((0.5 * H - 0.5 - r0) - rows) / camera.focal
    right, up, forward = camera.axes
    dy = forward[1] + px * right[1] + py * up[1]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (ground - camera.point[1]) / dy
    hit = (t > 0) & np.isfinite(t)
    # The pixel shows the ground when nothing is drawn there, or a surface at the ground's depth.
    inv = (np.ascontiguousarray(zbuf[r0:r1, c0:c1]).reshape(-1) & DEPTH_MASK).view(np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        hit &= (inv == 0) | (np.abs(inv * t - 1.0) <= _ON_GROUND)
    gx = camera.point[0] + t * (forward[0] + px * right[0] + py * up[0]) - cx
    gz = camera.point[2] + t * (forward[2] + px * right[2] + py * up[2]) - cz
    # Shadow-map texel: column from -x, row from +z (the map's camera looks up; see _shadow_map).
    n = _SHADOW_TEXELS
    tu = np.floor(0.5 * n - gx * (n / extent))
    tv = np.floor(0.5 * n + gz * (n / extent))
    hit &= (tu >= 0) & (tu < n) & (tv >= 0) & (tv < n)
    sel = hit.nonzero()[0]
    if not len(sel):
        return
    keep = 1.0 - dark[tv[sel].astype(np.int64), tu[sel].astype(np.int64)]
    at = (rows[sel] + r0, cols[sel] + c0)
    pixels = img[at].astype(np.float64)
    img[at] = np.floor(pixels * (keep if pixels.ndim == 1 else keep[:, None]) + 0.5).astype(np.uint8)


def _shadow_map(tris, extent: float, reach: float, strength: float):
    """Darkness (n, n) of the ground under ``tris`` (ground at y = 0, centred on the origin), or None.

    The map is the depth buffer of a camera far below looking up: the depth
    of the nearest surface is its height above the ground, and the
    darkness fades from ``strength`` at the ground to 0 at ``reach``.
    """
    n = _SHADOW_TEXELS
    distance = _SHADOW_DISTANCE * extent
    cam = Camera((0.0, -distance, 0.0), extent, (n, n))
    fb = Framebuffer((n, n), 0)
    fb.draw(tris, np.zeros(len(tris), dtype=np.uint8), cam)
    depth = fb.depth()
    if not np.isfinite(depth).any():
        return None
    height = np.maximum(depth - distance, 0.0)
    near = np.clip(1.0 - height / reach, 0.0, 1.0)
    near[~np.isfinite(depth)] = 0.0
    dark = strength * near
    # Soft edges reaching out from under the casters: two box blurs each
    # way (near enough a Gaussian) of radius 0.35 of the reach.
    radius = max(1, int(round(0.35 * reach * n / extent)))
    for axis in (0, 1, 0, 1):
        dark = _box_blur(dark, radius, axis)
    return dark


def _box_blur(a: np.ndarray, radius: int, axis: int) -> np.ndarray:
    """Mean over ``2 radius + 1`` neighbours along ``axis`` (zeros beyond the edges), by running sums."""
    pad = [(0, 0), (0, 0)]
    pad[axis] = (radius + 1, radius)
    c = np.cumsum(np.pad(a, pad), axis=axis)
    hi = [slice(None), slice(None)]
    lo = [slice(None), slice(None)]
    hi[axis] = slice(2 * radius + 1, None)
    lo[axis] = slice(None, -2 * radius - 1)
    return (c[tuple(hi)] - c[tuple(lo)]) * (1.0 / (2 * radius + 1))


def _ground_region(camera: Camera, box, ground: float, shape):
    """The rows and columns (r0, r1, c0, c1) of the image that may see the box on the ground, or None."""
    x0, x1, z0, z1 = box
    corners = np.array([[x, ground, z] for x in (x0, x1) for z in (z0, z1)])
    cam = camera.to_camera(corners)
    H, W = shape[:2]
    if (cam[:, 2] <= camera.near).any():
        return 0, H, 0, W  # the ground box reaches behind the eye: look everywhere
    pix = camera.camera_to_pixels(cam)
    c0 = max(int(math.floor(pix[:, 0].min())), 0)
    c1 = min(int(math.ceil(pix[:, 0].max())) + 1, W)
    r0 = max(int(math.floor(pix[:, 1].min())), 0)
    r1 = min(int(math.ceil(pix[:, 1].max())) + 1, H)
    if c0 >= c1 or r0 >= r1:
        return None
    return r0, r1, c0, c1


def _blur(a: np.ndarray) -> np.ndarray:
    """A [1 2 1] / 4 blur along both axes of a 2-D float array, edges repeated."""
    p = np.pad(a, 1, mode="edge")
    h = p[:, :-2] + 2.0 * p[:, 1:-1] + p[:, 2:]
    return (h[:-2] + 2.0 * h[1:-1] + h[2:]) * (1.0 / 16.0)


# ----------------------------------------------------------------- outline
def _drawn_box(draws, shape):
    """Rows and columns (r0, r1, c0, c1) holding every pixel the triangles may cover, one more each way; None if none.

    From the projected vertices, so no pass over the frame is needed; the
    whole frame when a triangle reaches behind an eye.
    """
    H, W = shape
    lo, hi = np.array([np.inf, np.inf]), np.array([-np.inf, -np.inf])
    for camera, tris in draws:
        cam = camera.to_camera(tris.reshape(-1, 3))
        if (cam[:, 2] <= camera.near).any():
            return 0, H, 0, W
        pix = camera.camera_to_pixels(cam)[:, :2]
        lo, hi = np.minimum(lo, pix.min(axis=0)), np.maximum(hi, pix.max(axis=0))
    c0, c1 = max(int(math.floor(lo[0])) - 1, 0), min(int(math.ceil(hi[0])) + 2, W)
    r0, r1 = max(int(math.floor(lo[1])) - 1, 0), min(int(math.ceil(hi[1])) + 2, H)
    if c0 >= c1 or r0 >= r1:
        return None
    return r0, r1, c0, c1


def _outline(img, zbuf, table, strength_of_line: float, look: Look, box) -> None:
    """Draw soft outlines along the depth buffer's discontinuities (in place).

    Only the pixel pairs whose triangles differ are looked at closely (a
    few thousand in a frame); the blur is a sum of nine shifted copies of
    those marks, so only two comparisons run over every pixel of ``box``
    (see :func:`_drawn_box`).  Triangle numbers start at 1: a key's low
    word is the triangle, 0 the background.
    """
    r0, r1, c0, c1 = box
    key = zbuf[r0:r1, c0:c1]
    h, w = key.shape
    # The low word of each int64 key: the triangle number (contiguous, so
    # that the comparisons and the search for differences run flat).
    low = 0 if sys.byteorder == "little" else 1
    tid = np.ascontiguousarray(key.view(np.int32)[:, low::2]).reshape(-1)
    flat_key = zbuf.reshape(-1)
    marks, strengths = [], []
    for step in (w, 1):
        a = np.flatnonzero(tid[:-step] != tid[step:])
        if step == 1:
            a = a[a % w != w - 1]  # not from a row's end to the next row's start
        b = a + step
        pr, pc = np.divmod(a, w)
        fa = (pr + r0) * zbuf.shape[1] + (pc + c0)
        fb = fa + (zbuf.shape[1] if step == w else 1)
        ka, kb = flat_key.take(fa), flat_key.take(fb)
        near, strength = _pair_edges(ka, kb, ka & INDEX_MASK, kb & INDEX_MASK, table, look)
        marks.append(np.where(near, a, b))
        strengths.append(strength)
    mark = np.concatenate(marks)
    strength = np.concatenate(strengths)
    live = strength > 0
    mark, strength = mark[live], strength[live]
    if not len(mark):
        return
    # Soft line: the marks spread by a [1 2 1] / 4 kernel each way (an
    # edge may be marked twice, from two sides: the sum then saturates),
    # summed in a frame one pixel wider each way, so no neighbour falls off.
    wide = w + 2
    mr, mc = np.divmod(mark, w)
    spot = ((mr + 1) * wide + (mc + 1))[:, None] + _SPREAD_AT[0] * wide + _SPREAD_AT[1]
    alpha = np.bincount(spot.reshape(-1), (strength[:, None] * _SPREAD).reshape(-1), minlength=(h + 2) * wide)
    at = np.flatnonzero(alpha)
    a = np.minimum(alpha.take(at) * (2.0 * strength_of_line), 1.0)
    ar, ac = np.divmod(at, wide)
    ar += r0 - 1
    ac += c0 - 1
    inside = (ar >= 0) & (ar < zbuf.shape[0]) & (ac >= 0) & (ac < zbuf.shape[1])
    if not inside.all():
        ar, ac, a = ar[inside], ac[inside], a[inside]
    where = (ar, ac)
    factor = 1.0 - a * (1.0 - look.ink)
    pixels = img[where].astype(np.float64)
    img[where] = np.floor(pixels * (factor if pixels.ndim == 1 else factor[:, None]) + 0.5).astype(np.uint8)


def _pair_edges(ka, kb, ta, tb, table, look: Look):
    """For neighbouring pixels with different triangles (or one empty): is ``a`` the nearer, and the edge's strength.

    Strength 1 for a silhouette, a jump in depth or a border between two
    objects; 0.4 for a crease or a change of shade; 0 for none.  Two
    triangles of one plane (a polygon's pieces, a floor seen at a grazing
    angle) meet without a jump, however fast their depth changes.
    """
    normals, planes, shades, groups = table
    ia = (ka & DEPTH_MASK).view(np.float64)  # 1/z; 0 where nothing is drawn
    ib = (kb & DEPTH_MASK).view(np.float64)
    both = (ta != 0) & (tb != 0)
    a, b = ta, tb
    cosine = np.einsum("ij,ij->i", normals.take(a, axis=0), normals.take(b, axis=0))
    nearer = np.maximum(ia, ib)
    with np.errstate(divide="ignore"):
        coplanar = (cosine > _COPLANAR) & (np.abs(planes.take(a) - planes.take(b)) * nearer <= _ON_GROUND)
    jump = (np.abs(ia - ib) > _DEPTH_JUMP * nearer) & ~coplanar
    hard = ~both | jump | (groups.take(a) != groups.take(b))
    soft = (cosine < math.cos(math.radians(look.crease))) | (shades.take(a) != shades.take(b))
    return ia >= ib, np.where(hard, 1.0, np.where(soft, 0.4, 0.0))


def look_params(name: str) -> Look | None:
    """The parameters of the look ``name``: None for the thesis look (the rasterizer alone)."""
    if name == "thesis":
        return None
    if name == "modern":
        return MODERN
    raise RenderError(f"look={name!r} is not a look; give one of {', '.join(LOOK_NAMES)}")
