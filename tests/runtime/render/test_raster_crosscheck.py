"""The rasterizer against a second, independent one (raster_reference.py): byte-equal images.

raster_reference.py is written from the rules of docs/semantics-render.md
alone, one triangle at a time with edge functions and barycentric depth,
where runtime/render/raster.py draws row spans of every triangle at once.
Two implementations that share no code agreeing on every byte of these
scenes is the check that both implement the same rules: projection,
clipping, the top-left fill rule, the depth keys and the tie rule, the back
face bias, colours and the anti-aliasing box filter.

Random scenes meet exact edges and exact depth ties only by chance, so the
lattice scenes place every vertex on the half-pixel lattice (edges through
pixel centres, horizontal edges along centre rows, vertices on centres) at
two depths (ties everywhere), where both implementations compute without
rounding and the fill and tie rules alone decide.
"""

from __future__ import annotations

import numpy as np
import pytest
import raster_reference as ref

from liganimate.runtime.render import raster
from liganimate.runtime.render.camera import Camera


def soup(rng, n, spread=3.0, size=None):
    """Random triangles (n, 3, 3) in a cube of half-side ``spread``, of about ``size`` if given, and grey levels."""
    if size is None:
        tris = rng.uniform(-spread, spread, (n, 3, 3))
    else:
        tris = rng.uniform(-spread, spread, (n, 1, 3)) + rng.uniform(-size, size, (n, 3, 3))
    return tris, rng.integers(0, 256, n).astype(np.uint8)


def boxes(rng, count):
    """``count`` closed boxes (12 triangles each, outward winding) and grey levels."""
    c = np.array([[x, y, z] for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)], float)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    idx = np.array([[q[0], q[1], q[2]] for q in quads] + [[q[0], q[2], q[3]] for q in quads])
    out = []
    for _ in range(count):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        if np.linalg.det(q) < 0:
            q[:, 0] *= -1
        corners = (c * rng.uniform(0.2, 1.0, 3)) @ q.T + rng.uniform(-2, 2, 3)
        out.append(corners[idx])
    tris = np.concatenate(out)
    return tris, rng.integers(0, 256, len(tris)).astype(np.uint8)


def camera(rng, size):
    """A random view of the origin from distance 7."""
    eye = rng.normal(size=3)
    return Camera(7.0 * eye / np.linalg.norm(eye), rng.uniform(4.0, 8.0), size)


# Looking down -Z from (0, 0, 1) with 8 pixels per unit at depth 1: a point
# (X, Y, 1 - z) lands exactly on pixel (32 + 8 X / z, 24 - 8 Y / z).
LATTICE_CAM = Camera((0.0, 0.0, 1.0), 8.0, (64, 48))


def lattice(rng, n, dyadic=True):
    """``n`` triangles whose vertices project onto the half-pixel lattice of LATTICE_CAM, each at depth 1 or 2.

    ``dyadic``: every edge's height (in pixels) is 0 or a power of two, so
    its slope dx/dy is exact in binary and so is every crossing of a row
    centre, in both implementations; otherwise heights are any multiple of
    one half.
    """
    W, H = LATTICE_CAM.size
    F = W / LATTICE_CAM.width
    z = rng.choice([1.0, 2.0], (n, 1))
    px = rng.integers(-8, 2 * W + 8, (n, 3)) / 2
    if dyadic:
        # Rows a, a + d, a + 2d in some order, or two of them equal.
        steps = rng.permuted(np.array([[0, 1, 2], [0, 0, 1], [0, 1, 1]])[rng.integers(0, 3, n)], axis=1)
        py = rng.integers(-4, 2 * H, (n, 1)) / 2 + steps * 2.0 ** rng.integers(-1, 5, (n, 1))
    else:
        py = rng.integers(-8, 2 * H + 8, (n, 3)) / 2
    tris = np.stack([(px - W / 2) * z / F, (H / 2 - py) * z / F, np.repeat(1.0 - z, 3, axis=1)], axis=-1)
    return tris, np.arange(1, n + 1, dtype=np.uint8)


def same(tris, shade, cam, **kw):
    """Both implementations' image, asserted byte-equal."""
    want = ref.rasterize(tris, shade, cam, **kw)
    got = raster.rasterize(tris, shade, cam, **kw)
    assert got.dtype == want.dtype == np.uint8
    np.testing.assert_array_equal(got, want)
    return want


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("size", [(96, 72), (160, 120), (333, 201)])
def test_random_soups_byte_equal(seed, size):
    rng = np.random.default_rng(1000 * seed + size[0])
    tris, shade = soup(rng, 200)
    img = same(tris, shade, camera(rng, size), background=17)
    assert (img != 17).sum() > 0.05 * img.size  # something substantial was drawn


@pytest.mark.parametrize("seed", range(4))
def test_confetti_byte_equal(seed):
    # Many small triangles: many edges, few pixels each.
    rng = np.random.default_rng(50 + seed)
    tris, shade = soup(rng, 1500, spread=2.0, size=0.15)
    img = same(tris, shade, camera(rng, (240, 180)), background=0)
    assert len(np.unique(img)) > 200


def test_bands_of_a_large_frame_byte_equal():
    # Above raster._ONE_BAND_PIXELS, drawn in bands of rows with no help.
    rng = np.random.default_rng(5)
    tris, shade = soup(rng, 1200, spread=2.5, size=0.2)
    cam = camera(rng, (1280, 720))
    assert 1280 * 720 > raster._ONE_BAND_PIXELS
    same(tris, shade, cam)


@pytest.mark.parametrize("seed", range(6))
def test_closed_solids_with_and_without_culling_byte_equal(seed):
    rng = np.random.default_rng(77 + seed)
    tris, shade = boxes(rng, 12)
    cam = camera(rng, (200, 150))
    culled = same(tris, shade, cam, cull=np.ones(len(tris), bool))
    np.testing.assert_array_equal(same(tris, shade, cam), culled)


@pytest.mark.parametrize("seed", range(12))
def test_lattice_edges_and_ties_byte_equal(seed):
    rng = np.random.default_rng(300 + seed)
    tris, shade = lattice(rng, 40)
    img = same(tris, shade, LATTICE_CAM, background=0)
    assert len(np.unique(img)) > 10


def test_lattice_edges_of_any_slope_byte_equal():
    for seed in range(300, 312):
        tris, shade = lattice(np.random.default_rng(seed), 40, dyadic=False)
        same(tris, shade, LATTICE_CAM, background=0)


def test_a_centre_on_an_edge_of_inexact_slope_goes_to_the_triangle_on_its_right():
    # The edge (59, 32)-(-4, 45) has slope -63/13, not exact in binary; it
    # passes exactly through the centre (27.5, 38.5) of pixel (27, 38).  Its
    # crossing with that row once came out one ulp right of 27.5 (the slope
    # rounded first), giving the pixel to the triangle on the left.
    W, H = LATTICE_CAM.size
    px = np.array([[(59, 32), (46, 9), (-4, 45)], [(59, 32), (-4, 45), (59, 60)]], dtype=float)
    tris = np.stack([(px[..., 0] - W / 2) / 8, (H / 2 - px[..., 1]) / 8, np.zeros(px.shape[:2])], axis=-1)
    for order in ([0, 1], [1, 0]):  # whichever is drawn later
        img = same(tris[order], np.array([1, 2])[order], LATTICE_CAM, background=0)
        assert img[38, 27] == 2
        assert img[38, 26] == 1


def test_lattice_mesh_has_no_cracks():
    # A grid of quads over the whole image, rows of corners on pixel-centre
    # rows and corners moved sideways along the half-pixel lattice, each
    # quad split along one diagonal or the other: every pixel belongs to
    # exactly one triangle (all drawn, none twice, which would show as the
    # wrong triangle winning).
    rng = np.random.default_rng(8)
    W, H = LATTICE_CAM.size
    gy = np.arange(-8.0, H + 9, 8)[:, None] + 0.5 + np.zeros(W // 8 + 3)
    gx = np.arange(-8.0, W + 9, 8) + rng.integers(-6, 7, gy.shape) / 2
    tris = []
    for i in range(gx.shape[0] - 1):
        for j in range(gx.shape[1] - 1):
            a, b, c, d = ((gx[i + di, j + dj], gy[i + di, j + dj]) for di, dj in ((0, 0), (0, 1), (1, 1), (1, 0)))
            tris += [(a, b, c), (a, c, d)] if (i + j) % 2 else [(a, b, d), (b, c, d)]
    px = np.array(tris)
    tris = np.stack([(px[..., 0] - W / 2) / 8, (H / 2 - px[..., 1]) / 8, np.zeros(px.shape[:2])], axis=-1)
    shade = np.arange(len(tris)) % 255 + 1
    img = same(tris, shade, LATTICE_CAM, background=0)
    assert (img != 0).all()


def test_drawing_twice_shows_the_second_copy():
    rng = np.random.default_rng(11)
    tris, first = soup(rng, 100)
    second = 255 - first
    cam = camera(rng, (120, 90))
    twice = same(np.concatenate([tris, tris]), np.concatenate([first, second]), cam)
    np.testing.assert_array_equal(twice, ref.rasterize(tris, second, cam))


@pytest.mark.parametrize("band_pixels", [1, 50, 700, 5000])
def test_narrow_bands_change_nothing(monkeypatch, band_pixels):
    # Bands of one row up to many rows, trapezoids cut at every boundary.
    rng = np.random.default_rng(band_pixels)
    tris, shade = soup(rng, 150)
    cam = camera(rng, (120, 90))
    want = ref.rasterize(tris, shade, cam)
    monkeypatch.setattr(raster, "_BAND_PIXELS", band_pixels)
    monkeypatch.setattr(raster, "_ONE_BAND_PIXELS", 0)
    np.testing.assert_array_equal(raster.rasterize(tris, shade, cam), want)
    fb = raster.Framebuffer(cam.size)
    for part in np.array_split(np.arange(len(tris)), 3):
        fb.draw(tris[part], shade[part], cam)
    np.testing.assert_array_equal(fb.image, want)


def test_deep_overlap_in_chunks(monkeypatch):
    # Many fragments per band: the band is depth-tested in several chunks.
    rng = np.random.default_rng(4)
    tris, shade = soup(rng, 300, spread=1.5)
    cam = camera(rng, (200, 150))
    want = ref.rasterize(tris, shade, cam)
    monkeypatch.setattr(raster, "_CHUNK", 500)
    monkeypatch.setattr(raster, "_BAND_PIXELS", 4000)
    monkeypatch.setattr(raster, "_ONE_BAND_PIXELS", 0)
    np.testing.assert_array_equal(raster.rasterize(tris, shade, cam), want)


@pytest.mark.parametrize("seed", range(3))
def test_near_plane_clipping_byte_equal(seed):
    # Triangles around the eye: many cross the near plane (one or two
    # vertices behind it), some lie wholly behind it; back faces included.
    rng = np.random.default_rng(9 + seed)
    cam = Camera((0.0, 0.5, 4.0), 3.0, (150, 100), near=1.5)
    tris = rng.uniform(-3, 3, (120, 3, 3)) + cam.point
    shade = np.arange(120, dtype=np.uint8) + 1
    img = same(tris, shade, cam)
    assert len(np.unique(img)) > 8


@pytest.mark.parametrize("seed", range(4))
def test_colours_byte_equal(seed):
    rng = np.random.default_rng(600 + seed)
    tris, _ = soup(rng, 120)
    colours = rng.integers(0, 256, (120, 3)).astype(np.uint8)
    cam = camera(rng, (120, 90))
    img = same(tris, colours, cam, background=(10, 200, 30))
    assert img.shape == (90, 120, 3)
    # Grey levels on a colour background become colours.
    same(tris, colours[:, 0], cam, background=(10, 200, 30))


@pytest.mark.parametrize("aa", [2, 3, 4])
@pytest.mark.parametrize("seed", range(3))
def test_anti_aliasing_byte_equal(seed, aa):
    rng = np.random.default_rng(700 + seed)
    tris, shade = soup(rng, 120)
    img = same(tris, shade, camera(rng, (64, 48)), aa=aa)
    assert not set(np.unique(img)) <= set(shade.tolist()) | {255}  # edges really are blended
    # Samples of the lattice camera lie on a lattice too (edges' slopes do not change).
    tris, shade = lattice(rng, 40)
    same(tris, shade, LATTICE_CAM, aa=aa)
    same(tris, rng.integers(0, 256, (40, 3)), LATTICE_CAM, aa=aa, background=(0, 0, 255))
