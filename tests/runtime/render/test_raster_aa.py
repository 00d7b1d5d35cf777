"""Anti-aliasing (aa x aa supersampling) and RGB colours in the rasterizer."""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.runtime.errors import RenderError
from liganimate.runtime.render.camera import Camera
from liganimate.runtime.render.raster import MAX_AA, Framebuffer, downsample, rasterize

CAM = Camera((0.0, 0.0, 16.0), 8.0, (64, 48))


def quad(p0, p1, p2, p3):
    p = np.array([p0, p1, p2, p3], dtype=float)
    return p[[[0, 1, 2], [0, 2, 3]]]


def soup(seed, n=60):
    rng = np.random.default_rng(seed)
    tris = rng.uniform(-3, 3, (n, 3, 3))
    shade = rng.integers(0, 256, (n, 3)).astype(np.uint8)
    return tris, shade


def box_mean(samples, aa):
    """The reference box filter: mean of each block, halves rounded up, via floats."""
    H, W = samples.shape[0] // aa, samples.shape[1] // aa
    out = np.zeros((H, W) + samples.shape[2:])
    for a in range(aa):
        for b in range(aa):
            out += samples[a::aa, b::aa]
    return np.floor(out / (aa * aa) + 0.5).astype(np.uint8)


# --------------------------------------------------------------------------
# Anti-aliasing


def test_aa_one_is_the_plain_image():
    tris, shade = soup(1)
    grey = shade[:, 0]
    np.testing.assert_array_equal(rasterize(tris, grey, CAM, aa=1), rasterize(tris, grey, CAM))


@pytest.mark.parametrize("aa", [2, 3, 4])
def test_aa_is_the_rounded_mean_of_a_finer_image(aa):
    tris, shade = soup(2)
    grey = shade[:, 0]
    fine = rasterize(tris, grey, Camera(CAM.point, CAM.width, (64 * aa, 48 * aa), CAM.near))
    got = rasterize(tris, grey, CAM, aa=aa)
    assert got.shape == (48, 64) and got.dtype == np.uint8
    np.testing.assert_array_equal(got, box_mean(fine, aa))
    # Edges really are blended: values appear that no triangle has.
    assert not set(np.unique(got)) <= set(grey.tolist()) | {255}


def test_aa_blends_only_along_edges():
    # A black square on pixel boundaries (x 24..40, y 16..32) and one whose
    # left edge runs through the middle of pixel column 23.
    img = rasterize(quad((-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)), [0, 0], CAM, aa=4)
    want = np.full((48, 64), 255, np.uint8)
    want[16:32, 24:40] = 0
    np.testing.assert_array_equal(img, want)  # boundaries on pixel edges stay sharp
    img = rasterize(quad((-1.0625, -1, 0), (1, -1, 0), (1, 1, 0), (-1.0625, 1, 0)), [0, 0], CAM, aa=4)
    want[16:32, 23] = 128  # half covered: (8 * 255 + 8) // 16
    np.testing.assert_array_equal(img, want)


def test_downsample_rounds_halves_up_exactly():
    samples = np.array([[0, 1, 255, 255], [0, 0, 255, 254]], np.uint8)
    np.testing.assert_array_equal(downsample(samples, 2), [[0, 255]])  # 0.25 -> 0, 254.75 -> 255
    samples = np.array([[1, 2], [0, 1]], np.uint8)
    np.testing.assert_array_equal(downsample(samples, 2), [[1]])  # 1.0
    np.testing.assert_array_equal(downsample(np.array([[1, 1], [0, 0]], np.uint8), 2), [[1]])  # 0.5 -> 1
    full = np.full((8, 8, 3), 255, np.uint8)
    np.testing.assert_array_equal(downsample(full, 8), np.full((1, 1, 3), 255))  # no overflow


def test_aa_framebuffer_accumulates_like_one_draw():
    tris, shade = soup(3)
    grey = shade[:, 0]
    fb = Framebuffer(CAM.size, background=9, aa=3)
    for part in np.array_split(np.arange(len(tris)), 3):
        fb.draw(tris[part], grey[part], CAM)
    np.testing.assert_array_equal(fb.image, rasterize(tris, grey, CAM, background=9, aa=3))
    assert fb.zbuf.shape == (144, 192) and fb.depth().shape == (144, 192)


def test_aa_is_deterministic():
    tris, shade = soup(4, 300)
    first = rasterize(tris, shade, CAM, aa=4).tobytes()
    assert all(rasterize(tris, shade, CAM, aa=4).tobytes() == first for _ in range(2))


# --------------------------------------------------------------------------
# RGB


def test_rgb_channels_are_grey_images():
    tris, shade = soup(5)
    img = rasterize(tris, shade, CAM, background=(10, 20, 30))
    assert img.shape == (48, 64, 3) and img.dtype == np.uint8
    for k, bg in enumerate((10, 20, 30)):
        np.testing.assert_array_equal(img[:, :, k], rasterize(tris, shade[:, k], CAM, background=bg))


@pytest.mark.parametrize("aa", [2, 4])
def test_rgb_with_aa(aa):
    tris, shade = soup(6)
    img = rasterize(tris, shade, CAM, background=(0, 128, 255), aa=aa)
    assert img.shape == (48, 64, 3)
    for k, bg in enumerate((0, 128, 255)):
        np.testing.assert_array_equal(img[:, :, k], rasterize(tris, shade[:, k], CAM, background=bg, aa=aa))


def test_grey_and_colour_mix():
    tris, shade = soup(7)
    grey = shade[:, 0]
    # Grey triangles on a colour background: grey g is the colour (g, g, g).
    img = rasterize(tris, grey, CAM, background=(255, 0, 0))
    want = rasterize(tris, np.repeat(grey[:, None], 3, axis=1), CAM, background=(255, 0, 0))
    np.testing.assert_array_equal(img, want)
    # Colour triangles on a grey background.
    np.testing.assert_array_equal(rasterize(tris, shade, CAM, background=7), rasterize(tris, shade, CAM, (7, 7, 7)))
    # A framebuffer turns RGB at its first colour draw, keeping what was drawn.
    fb = Framebuffer(CAM.size, background=200, aa=2)
    fb.draw(tris[:30], grey[:30], CAM)
    assert fb.image.ndim == 2
    fb.draw(tris[30:], shade[30:], CAM)
    mixed = np.concatenate([np.repeat(grey[:30, None], 3, axis=1), shade[30:]])
    np.testing.assert_array_equal(fb.image, rasterize(tris, mixed, CAM, background=200, aa=2))


def test_grey_output_is_unchanged_by_colour_support():
    tris, shade = soup(8)
    img = rasterize(tris, shade[:, 1], CAM)
    assert img.shape == (48, 64)


# --------------------------------------------------------------------------
# Errors


@pytest.mark.parametrize("aa", [0, -1, MAX_AA + 1, 1.5, "2", True, None])
def test_bad_aa(aa):
    tris, shade = soup(9, 2)
    with pytest.raises(RenderError, match="Anti-aliasing"):
        rasterize(tris, shade, CAM, aa=aa)
    with pytest.raises(RenderError, match="Anti-aliasing"):
        Framebuffer(CAM.size, aa=aa)


@pytest.mark.parametrize("bg", [(1, 2), (0, 0, 256), (0.5, 0, 0), "white", (1, 2, 3, 4), -1, 256])
def test_bad_background(bg):
    tris, shade = soup(9, 2)
    with pytest.raises(RenderError, match="background"):
        rasterize(tris, shade, CAM, background=bg)


@pytest.mark.parametrize("shade", [np.zeros((2, 4)), np.zeros((2, 3)) + 256, np.full((2, 3), 0.5), np.zeros((3, 3))])
def test_bad_colours(shade):
    tris, _ = soup(9, 2)
    with pytest.raises(RenderError):
        rasterize(tris, shade, CAM)


def test_rgb_in_bands_and_chunks(monkeypatch):
    from liganimate.runtime.render import raster

    tris, shade = soup(10, 120)
    want = [rasterize(tris, shade[:, k], CAM, background=bg, aa=2) for k, bg in enumerate((3, 4, 5))]
    monkeypatch.setattr(raster, "_ONE_BAND_PIXELS", 0)
    monkeypatch.setattr(raster, "_BAND_PIXELS", 500)
    monkeypatch.setattr(raster, "_CHUNK", 200)
    img = rasterize(tris, shade, CAM, background=(3, 4, 5), aa=2)
    for k in range(3):
        np.testing.assert_array_equal(img[:, :, k], want[k])
    fb = Framebuffer(CAM.size, background=(3, 4, 5), aa=2)
    fb.draw(tris[:60], shade[:60], CAM)
    fb.draw(tris[60:], shade[60:], CAM)
    np.testing.assert_array_equal(fb.image, img)
