"""Pixel-exact tests of the camera and the z-buffer rasterizer."""

from __future__ import annotations

import numpy as np
import pytest

from liganimate.runtime.errors import RenderError
from liganimate.runtime.render.camera import Camera
from liganimate.runtime.render.raster import Framebuffer, _expand, _spans, rasterize

# Camera used for exact tests: the plane through the origin is 8 px per unit,
# and every number involved is exact in binary floating point.
CAM = Camera((0.0, 0.0, 16.0), 8.0, (64, 48))


def fragments(tris, cull, cam):
    """Pixel numbers of every fragment the rasterizer generates, shape (F,)."""
    spans = _spans(np.asarray(tris, float), cull, cam, 0)
    if spans is None:
        return np.zeros(0, np.int64)
    count = spans.pixels
    ends0 = np.concatenate(([0], count.cumsum()))
    pix = _expand(spans.offset, spans.wstart, spans.step, count, ends0, count, count)[0]
    return pix + spans.origin


def quad(p0, p1, p2, p3):
    """Two triangles (0,1,2), (0,2,3): shape (2, 3, 3)."""
    p = np.array([p0, p1, p2, p3], dtype=float)
    return p[[[0, 1, 2], [0, 2, 3]]]


def box(centre, half, rot):
    """A closed box wound counter-clockwise seen from outside: shape (12, 3, 3)."""
    c = np.array([[x, y, z] for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)], float)
    c = (c * half) @ np.asarray(rot).T + centre
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return np.concatenate([quad(*c[list(q)]) for q in quads])


def random_rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return q


# --------------------------------------------------------------------------
# A slow reference: one ray per pixel centre, intersected with every triangle
# in camera space (Moller-Trumbore).  It shares nothing with the rasterizer
# but the camera, and also reports which pixels are genuinely ambiguous.


def reference(tris, shade, cam, background=255):
    W, H = cam.size
    tri = cam.to_camera(np.asarray(tris, float))
    xs = (np.arange(W) + 0.5 - W / 2) / cam.focal
    ys = -(np.arange(H) + 0.5 - H / 2) / cam.focal
    dx, dy = np.meshgrid(xs, ys)
    d = np.stack([dx, dy, np.ones_like(dx)], axis=-1).reshape(-1, 3)  # depth of t*d is t
    best = np.full(len(d), np.inf)
    second = np.full(len(d), np.inf)
    winner = np.full(len(d), -1)
    ambiguous = np.zeros(len(d), bool)
    eps = 1e-7
    for i, (a, b, c) in enumerate(tri):
        e1, e2 = b - a, c - a
        p = np.cross(d, e2)
        det = p @ e1
        if np.all(np.abs(det) < 1e-14):
            continue
        with np.errstate(divide="ignore", invalid="ignore"):
            s = -a
            u = (p @ s) / det
            q = np.cross(s, e1)
            v = (d @ q) / det
            t = (e2 @ q) / det
        inside = (u >= 0) & (v >= 0) & (u + v <= 1) & (t >= cam.near)
        edge = (np.minimum(np.minimum(u, v), 1 - u - v) > -eps) & (np.minimum(np.minimum(u, v), 1 - u - v) < eps)
        ambiguous |= edge | (np.abs(t - cam.near) < eps * cam.near)
        hit = inside & (t <= best)
        second = np.where(inside & ~hit, np.minimum(second, t), np.where(hit, best, second))
        best = np.where(hit, t, best)
        winner = np.where(hit, i, winner)
    with np.errstate(invalid="ignore"):
        ambiguous |= (second - best) < 1e-5 * best
    img = np.where(winner >= 0, np.asarray(shade)[winner], background).astype(np.uint8)
    return img.reshape(H, W), ambiguous.reshape(H, W)


def assert_matches_reference(tris, shade, cam, cull=None, max_edge_pixels=5):
    got = rasterize(tris, shade, cam, cull=cull)
    want, ambiguous = reference(tris, shade, cam)
    differ = got != want
    assert not (differ & ~ambiguous).any(), f"{(differ & ~ambiguous).sum()} unambiguous pixels differ"
    assert differ.sum() <= max_edge_pixels
    return got


# --------------------------------------------------------------------------
# Camera


def test_camera_view_width_and_centre():
    cam = Camera((0, 0, 10), 4.0, (64, 48))
    p = cam.project(np.array([[0, 0, 0], [2, 0, 0], [-2, 0, 0], [0, 1.5, 0], [0, -1.5, 0]], float))
    np.testing.assert_allclose(p[:, 0], [32, 64, 0, 32, 32])
    np.testing.assert_allclose(p[:, 1], [24, 24, 24, 0, 48])  # y grows downward
    np.testing.assert_allclose(p[:, 2], 10)


def test_camera_perspective_and_oblique_view():
    cam = Camera((3.0, 4.0, 12.0), 5.0)
    assert cam.size == (640, 480)
    np.testing.assert_allclose(cam.project([[0, 0, 0]]), [[320, 240, 13]])
    # A point twice as far away from the eye projects half as far from the centre.
    r, u, f = cam.axes
    near_pt = cam.point + 6.5 * f + 1.0 * r + 0.5 * u
    far_pt = cam.point + 13.0 * f + 2.0 * r + 1.0 * u
    np.testing.assert_allclose(cam.project([near_pt])[0, :2], cam.project([far_pt])[0, :2])
    assert cam.project([cam.point + f + 0.01 * r])[0, 0] > 320  # right is right
    assert cam.project([cam.point + f + 0.01 * u])[0, 1] < 240  # up is up
    assert abs(u @ [0, 1, 0]) > 0 and abs(r[1]) < 1e-12  # level horizon: +Y up


def test_camera_looking_along_y_uses_minus_z_up():
    for eye in [(0, 5, 0), (0, -5, 0)]:
        cam = Camera(eye, 4.0, (64, 48))
        p = cam.project([[0, 0, -1], [1, 0, 0]])
        assert p[0, 1] < 24 and abs(p[0, 0] - 32) < 1e-9  # -Z is towards the top
        assert abs(p[1, 1] - 24) < 1e-9


def test_camera_errors():
    with pytest.raises(RenderError, match="origin"):
        Camera((0, 0, 0), 4.0)
    for bad in [0.0, -1.0, float("nan"), "wide"]:
        with pytest.raises(RenderError):
            Camera((0, 0, 5), bad)
    for bad in [(0, 480), (640.5, 480), (640,)]:
        with pytest.raises(RenderError):
            Camera((0, 0, 5), 1.0, bad)
    with pytest.raises(RenderError):
        Camera((0, float("inf"), 5), 1.0)


# --------------------------------------------------------------------------
# Coverage


def test_square_on_pixel_boundaries_covers_exact_pixels():
    img = rasterize(quad((-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)), [0, 0], CAM)
    want = np.full((48, 64), 255, np.uint8)
    want[16:32, 24:40] = 0  # x: 32 +- 8, y: 24 +- 8
    np.testing.assert_array_equal(img, want)


def test_fill_rule_top_left_on_pixel_centres():
    # Edges pass exactly through pixel centres: x from 16.5 to 48.5, y from 7.5 to 39.5.
    a, b = -1.9375, 2.0625
    for tris in [quad((a, a, 0), (b, a, 0), (b, b, 0), (a, b, 0)), quad((a, a, 0), (a, b, 0), (b, b, 0), (b, a, 0))]:
        img = rasterize(tris, [0, 0], CAM)
        want = np.full((48, 64), 255, np.uint8)
        # Centres on the left and top edges are in; on the right and bottom edges out.
        want[7:39, 16:48] = 0
        np.testing.assert_array_equal(img, want)


def test_shared_edges_cover_each_pixel_exactly_once():
    rng = np.random.default_rng(7)
    for _ in range(5):
        # A random convex polygon, triangulated two different ways, tilted in depth.
        ang = np.sort(rng.uniform(0, 2 * np.pi, 9))
        pts = np.stack([2.5 * np.cos(ang), 2.5 * np.sin(ang)], axis=1) + rng.normal(0, 0.1, 2)
        z = lambda p: 0.3 * p[0] - 0.2 * p[1]
        P = np.array([[x, y, z((x, y))] for x, y in pts])
        centre = P.mean(axis=0)
        fan_vertex = np.array([[P[0], P[i], P[i + 1]] for i in range(1, len(P) - 1)])
        fan_centre = np.array([[centre, P[i], P[(i + 1) % len(P)]] for i in range(len(P))])
        counts = []
        for tris in (fan_vertex, fan_centre):
            pix = fragments(tris, None, CAM)
            c = np.bincount(pix, minlength=64 * 48)
            assert c.max() == 1  # no pixel drawn twice along a shared edge
            counts.append(c)
        np.testing.assert_array_equal(counts[0], counts[1])  # no cracks either


# --------------------------------------------------------------------------
# Depth


def test_interpenetrating_quads_split_exactly_where_they_cross():
    # Two quads crossing along x = 0, i.e. along pixel column boundary 32.
    # On the left B is nearer, on the right A.  Any painter's algorithm draws
    # one quad entirely over the other, so one of its colours would show on
    # the wrong side; only a per-pixel depth test passes.
    a = quad((-2, -1.5, -1), (2, -1.5, 1), (2, 1.5, 1), (-2, 1.5, -1))
    b = quad((-2, -1.5, 1), (2, -1.5, -1), (2, 1.5, -1), (-2, 1.5, 1))
    for tris, shade in [(np.concatenate([a, b]), [10, 10, 200, 200]), (np.concatenate([b, a]), [200, 200, 10, 10])]:
        img = rasterize(tris, shade, CAM)
        left, right = img[:, :32], img[:, 32:]
        assert set(np.unique(left)) == {200, 255} and set(np.unique(right)) == {10, 255}
        # B's near half covers A's far half entirely (and the other way round).
        assert (left == 200).sum() == (right == 10).sum() > 300


def test_depth_is_perspective_correct():
    cam = Camera((1.0, 2.0, 6.0), 6.0, (80, 60))
    tris = quad((-3, -2, -4), (3, -2, 1), (3, 2, 2), (-3, 2, -3))
    fb = Framebuffer(cam.size)
    fb.draw(tris, [0, 0], cam)
    depth = fb.depth()
    # Exact depth: intersect each pixel's ray with the quad's plane.
    c = cam.to_camera(tris[0])
    n = np.cross(c[1] - c[0], c[2] - c[0])
    W, H = cam.size
    xs = (np.arange(W) + 0.5 - W / 2) / cam.focal
    ys = -(np.arange(H) + 0.5 - H / 2) / cam.focal
    dx, dy = np.meshgrid(xs, ys)
    exact = (n @ c[0]) / (n[0] * dx + n[1] * dy + n[2])
    drawn = np.isfinite(depth)
    assert drawn.sum() > 1000
    np.testing.assert_allclose(depth[drawn], exact[drawn], rtol=2e-6)


def test_equal_depth_later_triangle_wins():
    sq = quad((-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0))
    img = rasterize(np.concatenate([sq, sq, sq]), [1, 1, 2, 2, 3, 3], CAM)
    assert set(np.unique(img)) == {3, 255}
    fb = Framebuffer(CAM.size, background=0)
    fb.draw(sq, [7, 7], CAM)
    fb.draw(sq, [9, 9], CAM)  # a later draw is later for the tie rule too
    assert set(np.unique(fb.image)) == {0, 9}


def test_large_draws_in_chunks_give_the_same_image(monkeypatch):
    from liganimate.runtime.render import raster

    rng = np.random.default_rng(5)
    tris = rng.uniform(-3, 3, (80, 3, 3))
    shade = np.arange(80, dtype=np.uint8) + 1
    one_go = rasterize(tris, shade, CAM)
    fb = Framebuffer(CAM.size)
    fb.draw(tris[:40], shade[:40], CAM)
    monkeypatch.setattr(raster, "_CHUNK", 300)  # far fewer than the fragments
    assert len(fragments(tris, None, CAM)) > 3000
    np.testing.assert_array_equal(rasterize(tris, shade, CAM), one_go)
    fb.draw(tris[40:], shade[40:], CAM)  # chunked, on top of an earlier draw
    np.testing.assert_array_equal(fb.image, one_go)


def test_framebuffer_draws_accumulate_like_one_draw():
    rng = np.random.default_rng(3)
    tris = rng.uniform(-3, 3, (60, 3, 3))
    shade = np.arange(60, dtype=np.uint8) + 1
    fb = Framebuffer(CAM.size, background=0)
    for part in np.array_split(np.arange(60), 4):
        fb.draw(tris[part], shade[part], CAM)
    np.testing.assert_array_equal(fb.image, rasterize(tris, shade, CAM, background=0))


# --------------------------------------------------------------------------
# Near plane


def test_triangles_behind_the_eye_draw_nothing():
    tris = np.array([[[0, 0, 20], [1, 0, 20], [0, 1, 25]], [[-5, -5, 16], [5, -5, 16], [0, 5, 16]]], float)
    img = rasterize(tris, [0, 0], CAM)
    assert (img == 255).all()


def test_floor_through_the_eye_is_clipped_at_the_near_plane():
    # A floor below the eye reaching far behind it: only the part in front shows,
    # below the horizon (row 24), and nothing leaks above it.
    floor = quad((-50, -1, -100), (50, -1, -100), (50, -1, 100), (-50, -1, 100))
    img = assert_matches_reference(floor, [0, 0], CAM)
    assert (img[:24] == 255).all() and (img[25:] == 0).all()


@pytest.mark.parametrize("seed", range(4))
def test_near_plane_clipping_matches_reference(seed):
    rng = np.random.default_rng(100 + seed)
    cam = Camera((0.0, 0.5, 4.0), 3.0, (96, 72), near=1.5)
    # Triangles around the eye: many cross the near plane, some lie behind it.
    tris = rng.uniform(-3, 3, (40, 3, 3)) + cam.point
    assert_matches_reference(tris, np.arange(40) + 1, cam)


# --------------------------------------------------------------------------
# Cross-check on random scenes


@pytest.mark.parametrize("seed", range(6))
def test_random_triangles_match_reference(seed):
    rng = np.random.default_rng(seed)
    eye = rng.normal(size=3)
    cam = Camera(6.0 * eye / np.linalg.norm(eye), 5.0, (96, 72))
    tris = rng.uniform(-2, 2, (50, 3, 3))
    img = assert_matches_reference(tris, np.arange(50) + 1, cam)
    assert len(np.unique(img)) > 15  # the scene really has depth-order decisions


@pytest.mark.parametrize("seed", range(3))
def test_random_boxes_match_reference(seed):
    rng = np.random.default_rng(20 + seed)
    tris = np.concatenate(
        [box(rng.uniform(-1.5, 1.5, 3), rng.uniform(0.2, 1.0, 3), random_rotation(rng)) for _ in range(8)]
    )
    cam = Camera((2.0, 3.0, 9.0), 6.0, (96, 72))
    shade = np.arange(len(tris)) % 250 + 1
    assert_matches_reference(tris, shade, cam)


# --------------------------------------------------------------------------
# Culling and determinism


@pytest.mark.parametrize("seed", range(4))
def test_culling_closed_solids_changes_nothing(seed):
    rng = np.random.default_rng(50 + seed)
    tris = np.concatenate(
        [box(rng.uniform(-2, 2, 3), rng.uniform(0.2, 1.2, 3), random_rotation(rng)) for _ in range(10)]
    )
    shade = rng.integers(0, 256, len(tris)).astype(np.uint8)
    cam = Camera(rng.normal(size=3) * 4 + [0, 0, 8], 7.0, (160, 120))
    cull = np.ones(len(tris), bool)
    with_cull = rasterize(tris, shade, cam, cull=cull)
    np.testing.assert_array_equal(with_cull, rasterize(tris, shade, cam))
    # ...and culling did take effect.
    assert len(fragments(tris, cull, cam)) < 0.7 * len(fragments(tris, None, cam))


def test_back_faces_lose_exact_ties_on_silhouettes():
    # A diamond prism whose left silhouette edge runs exactly through pixel
    # centres (x = 16.5), where a front and a back face tie in depth.  The
    # back faces come later, so by index alone they would win the tie there.
    a = 1.9375
    ring = [(a, 0), (0, a), (-a, 0), (0, -a)]  # (x, z), counter-clockwise seen from +Y
    tris, shade = [], []
    for i in range(4):
        (x0, z0), (x1, z1) = ring[i], ring[(i + 1) % 4]
        side = quad((x0, -1, z0), (x1, -1, z1), (x1, 1, z1), (x0, 1, z0))[:, ::-1]
        tris.append(side)
        shade += [50, 50] if z0 + z1 > 0 else [200, 200]
    tris.append(np.array([[[x, 1, z] for x, z in ring[:3]], [[x, 1, z] for x, z in [ring[0], ring[2], ring[3]]]]))
    tris.append(tris[-1][:, ::-1] * [1, -1, 1])
    shade += [120, 120, 120, 120]
    tris = np.concatenate(tris)
    img = rasterize(tris, shade, CAM)
    assert (img[:, 16] != 200).all() and (img[:, 16] == 50).sum() > 10
    np.testing.assert_array_equal(img, rasterize(tris, shade, CAM, cull=np.ones(len(tris), bool)))


def test_same_bytes_every_time():
    rng = np.random.default_rng(11)
    tris = rng.uniform(-3, 3, (300, 3, 3))
    shade = rng.integers(0, 256, 300).astype(np.uint8)
    cam = Camera((1, 2, 9), 6.0, (200, 150))
    first = rasterize(tris, shade, cam).tobytes()
    assert all(rasterize(tris, shade, cam).tobytes() == first for _ in range(3))


# --------------------------------------------------------------------------
# Inputs


def test_empty_and_offscreen_input():
    assert (rasterize(np.zeros((0, 3, 3)), np.zeros(0, np.uint8), CAM, background=7) == 7).all()
    far_left = quad((-90, -1, 0), (-80, -1, 0), (-80, 1, 0), (-90, 1, 0))
    assert (rasterize(far_left, [0, 0], CAM) == 255).all()
    sliver = np.array([[[0, 0, 0], [1, 1, 0], [2, 2, 0]]], float)  # zero area
    assert (rasterize(sliver, [0], CAM) == 255).all()
    # Rows 16-31 crossed, between the centres of columns 9 and 10: spans of
    # no pixels, so the rows they span (and the rest) show the background,
    # in grey and in colour.
    thin = np.array([[[-2.7375, 1, 0], [-2.7, 1, 0], [-2.72, -1, 0]]])
    assert (rasterize(thin, [0], CAM, background=9) == 9).all()
    assert (rasterize(thin, [[0, 0, 0]], CAM, background=(1, 2, 3)) == [1, 2, 3]).all()


def test_input_errors():
    sq = quad((-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0))
    with pytest.raises(RenderError):
        rasterize(sq[:, :, :2], [0, 0], CAM)
    with pytest.raises(RenderError):
        rasterize(sq, [0], CAM)
    with pytest.raises(RenderError):
        rasterize(sq, [0, 256], CAM)
    with pytest.raises(RenderError):
        rasterize(sq, [0, 0], CAM, background=300)
    with pytest.raises(RenderError):
        rasterize(sq * np.nan, [0, 0], CAM)
    # Checked before culling, and in a framebuffer's draw too.
    inf = sq.copy()
    inf[1, 2, 0] = np.inf
    with pytest.raises(RenderError, match="finite"):
        rasterize(inf, [0, 0], CAM, cull=[True, True])
    with pytest.raises(RenderError, match="finite"):
        Framebuffer(CAM.size).draw(inf, [0, 0], CAM)
    with pytest.raises(RenderError):
        rasterize(sq, [0, 0], CAM, cull=[True])
    with pytest.raises(RenderError, match="size"):
        Framebuffer((32, 32)).draw(sq, [0, 0], CAM)
