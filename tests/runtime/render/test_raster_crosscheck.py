"""The rasterizer against the previous implementation (raster_reference.py): byte-equal images.

raster_reference.py is the rasterizer as it was before it drew in bands of
rows (one np.maximum.at over every fragment of the frame, then a scan of the
whole depth buffer when the fragments did not fit in one chunk).  Its images
are what the golden files were made from, so the new one must give the very
same bytes: same coverage rule, same depth keys, same tie rule.
"""

from __future__ import annotations

import numpy as np
import pytest
import raster_reference as ref

from liganimate.runtime.render import raster
from liganimate.runtime.render.camera import Camera


def soup(rng, n, spread=3.0):
    return rng.uniform(-spread, spread, (n, 3, 3)), rng.integers(0, 256, n).astype(np.uint8)


def boxes(rng, count):
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
    eye = rng.normal(size=3)
    return Camera(7.0 * eye / np.linalg.norm(eye), rng.uniform(4.0, 8.0), size)


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("size", [(96, 72), (333, 201), (1280, 720)])
def test_random_soups_byte_equal(seed, size):
    rng = np.random.default_rng(1000 * seed + size[0])
    tris, shade = soup(rng, 200)
    cam = camera(rng, size)
    want = ref.rasterize(tris, shade, cam, background=17)
    got = raster.rasterize(tris, shade, cam, background=17)
    assert (want != 17).sum() > 0.05 * want.size  # something substantial was drawn
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("seed", range(6))
def test_closed_solids_with_and_without_culling_byte_equal(seed):
    rng = np.random.default_rng(77 + seed)
    tris, shade = boxes(rng, 12)
    cam = camera(rng, (400, 300))
    cull = np.ones(len(tris), bool)
    for flags in (None, cull):
        np.testing.assert_array_equal(
            raster.rasterize(tris, shade, cam, cull=flags), ref.rasterize(tris, shade, cam, cull=flags)
        )


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


def test_near_plane_clipping_byte_equal():
    rng = np.random.default_rng(9)
    cam = Camera((0.0, 0.5, 4.0), 3.0, (300, 200), near=1.5)
    tris = rng.uniform(-3, 3, (120, 3, 3)) + cam.point
    shade = np.arange(120, dtype=np.uint8) + 1
    np.testing.assert_array_equal(raster.rasterize(tris, shade, cam), ref.rasterize(tris, shade, cam))
