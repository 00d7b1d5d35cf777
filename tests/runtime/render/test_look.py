"""The modern look (runtime/render/look.py) and the thesis look beside it.

Properties rather than bytes (the golden frames of tests/test_golden.py
hold the bytes): outlines where figures overlap, light that keeps
LIGHTNESS's order and COLOUR's hue, a contact shadow that tells a planted
box from a lifted one, smoothed edges, and the thesis look unchanged.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from liganimate.runtime.errors import RenderError
from liganimate.runtime.render import frames
from liganimate.runtime.render.camera import Camera
from liganimate.runtime.render.look import MODERN, check_look, draw_modern
from liganimate.runtime.render.options import RenderOptions
from liganimate.runtime.render.raster import rasterize

SIZE = (160, 120)


def box(centre, size):
    """A closed box, 12 triangles wound outward, shape (12, 3, 3)."""
    c, h = np.asarray(centre, float), np.asarray(size, float) / 2
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * h + c
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, d, e in faces:
        tris += [[v[a], v[b], v[d]], [v[a], v[d], v[e]]]
    return np.array(tris)


def part(tris, shade):
    shade = np.asarray(shade, dtype=np.uint8)
    return (tris, np.broadcast_to(shade, (len(tris),) + shade.shape[1:]).copy(), np.zeros(len(tris), bool))


def modern(parts, camera=None, size=SIZE):
    camera = camera or Camera((0.0, 0.0, 10.0), 6.0, size)
    return draw_modern(size, [(camera, parts)], 1, MODERN)


def test_overlapping_figures_of_one_shade_are_separated_by_an_outline():
    # Two boxes of the same grey, the second in front of the first and overlapping it.
    back, front = box((-0.5, 0, 0), (2, 2, 1)), box((0.5, -0.3, 1.5), (2, 2, 1))
    cam = Camera((0.0, 0.0, 10.0), 6.0, SIZE)
    flat = rasterize(np.concatenate([back, front]), np.full(24, 150, np.uint8), cam)
    image = modern([part(back, 150), part(front, 150)], cam)
    # The front box's left edge crosses the back box: find its column on a row inside both.
    row = SIZE[1] // 2 - 10
    edge = cam.project([[-0.5, 0.0, 2.0]])[0][0]
    col = int(round(edge))
    band = slice(col - 2, col + 3)
    assert len(set(flat[row, band].tolist())) == 1  # the thesis look: one grey, the boxes melt together
    assert image[row, band].min() < 0.75 * np.median(image[row, col - 15 : col - 5])  # the modern look: a dark line


def test_light_keeps_the_order_of_lightness_and_the_hue_of_colour():
    cam = Camera((0.0, 0.0, 10.0), 6.0, SIZE)
    dim, bright = box((-1.2, 0, 0), (1, 1, 1)), box((1.2, 0, 0), (1, 1, 1))
    grey = modern([part(dim, 80), part(bright, 160)], cam)
    centre_dim = cam.project([[-1.2, 0.0, 0.5]])[0].astype(int)
    centre_bright = cam.project([[1.2, 0.0, 0.5]])[0].astype(int)
    a, b = int(grey[centre_dim[1], centre_dim[0]]), int(grey[centre_bright[1], centre_bright[0]])
    assert a < b and abs(b - 2 * a) <= 2  # the same face at twice the lightness: twice as light
    colour = modern([part(dim, [[200, 100, 50]])], cam)
    r, g, bl = colour[centre_dim[1], centre_dim[0]].astype(int)
    assert abs(r - 2 * g) <= 2 and abs(g - 2 * bl) <= 2


def test_a_planted_box_casts_a_darker_contact_shadow_than_a_lifted_one():
    cam = Camera((0.0, 3.0, 10.0), 8.0, SIZE)
    floor = box((0, -0.05, 0), (8, 0.1, 8))
    planted, lifted = box((-1.5, 0.5, 0), (1, 1, 1)), box((1.5, 0.9, 0), (1, 1, 1))
    image = modern([part(floor, 200), part(planted, 120), part(lifted, 120)], cam)
    without = draw_modern(SIZE, [(cam, [part(floor, 200)])], 1, MODERN)
    # Just in front of each box's bottom front edge, on the floor.
    spots = cam.project([[-1.5, 0.0, 0.62], [1.5, 0.0, 0.62], [0.0, 0.0, 3.5]]).astype(int)
    darkening = [int(without[y, x]) - int(image[y, x]) for x, y, _ in spots]
    assert darkening[0] > darkening[1] >= 0
    assert darkening[0] >= 20
    assert darkening[2] == 0  # far from both: no shadow
    # The floor casts no shadow on itself, and is drawn as the thesis look would light it.
    assert len(set(without[spots[2][1], 10:-10].tolist())) <= 2


def test_edges_are_smoothed_without_supersampling():
    cam = Camera((0.0, 0.0, 10.0), 6.0, SIZE)
    tri = np.array([[[-2.0, -1.5, 0.0], [2.0, -1.0, 0.0], [0.3, 2.0, 0.0]]])
    flat = rasterize(tri, np.array([0], np.uint8), cam, 255)
    smooth = modern([part(tri, 0)], cam)
    assert set(np.unique(flat).tolist()) == {0, 255}
    levels = np.unique(smooth)
    assert len(levels) > 8  # in-between levels along the edges
    # Away from the edges, the surfaces keep their shades.
    assert smooth[2, 2] == MODERN.background and smooth[60, 80] == 0


def test_the_same_draws_give_the_same_bytes():
    parts = [part(box((0, 0, 0), (2, 1, 1)), 90), part(box((0.5, 0.5, 1), (1, 2, 1)), [[10, 200, 90]])]
    a, b = modern(parts), modern([(t.copy(), s.copy(), c.copy()) for t, s, c in parts])
    assert a.tobytes() == b.tobytes()


def test_the_thesis_look_is_the_rasterizer_alone():
    cam = ((0.0, 1.0, 8.0), 5.0)
    tris = np.concatenate([box((0, 0, 0), (2, 1, 1)), box((0.5, 0.5, 1), (1, 2, 1))])
    p = (tris, np.arange(24, dtype=np.uint8) * 10, np.ones(24, bool))
    image = frames.draw(SIZE, [(cam, [p])], 1, "thesis")
    assert np.array_equal(image, rasterize(tris, p[1], Camera(cam[0], cam[1], SIZE), 255, p[2]))
    assert not np.array_equal(image, frames.draw(SIZE, [(cam, [p])], 1, "modern"))
    assert not np.array_equal(frames.draw(SIZE, [(cam, [p])]), image)  # the default is the modern look


def test_nothing_drawn_is_the_background():
    image = frames.draw(SIZE, [(((0.0, 0.0, 5.0), 2.0), [])], 1, "modern")
    assert image.shape == (SIZE[1], SIZE[0]) and (image == MODERN.background).all()


def test_a_look_that_does_not_exist_is_refused():
    assert check_look("thesis") == "thesis"
    with pytest.raises(RenderError, match="--look fancy is not a look; give one of modern, thesis"):
        check_look("fancy")
    with pytest.raises(RenderError, match="look='x' is not a look"):
        frames.Renderer(RenderOptions(gif="x.gif", look="x"))


def test_the_command_line_refuses_an_unknown_look(tmp_path):
    src = tmp_path / "p.lig"
    src.write_text(
        "      INITIALIZE SCENE 1\n      STARTSCENE LENGTH 1\n      ENDSCENE\n      SHOOTSCENES\n      END\n"
    )
    r = subprocess.run(
        [sys.executable, "-m", "liganimate", "run", str(src), "--look", "fancy"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert r.returncode == 1
    assert "liganimate: error: --look fancy is not a look; give one of modern, thesis" in r.stderr
    assert not list(tmp_path.glob("p_frames*"))


# ------------------------------------------------------------ default framing
SWING = """\
      GRAPHICAL A, B
      MODEL M
      MOTION GO
      A :- BOX AT ({x}, 3.0, -4.0), WIDTH 0.4, HEIGHT 0.8, DEPTH 0.4, LIGHTNESS 50.0
      B :- BOX AT (1.0, 0.0, 0.0), WIDTH 1.0, HEIGHT 0.2, DEPTH 0.2, LIGHTNESS 70.0
      M :- JOINT 1, A, ({x}, 3.0, -4.0), B, (0.0, 0.0, 0.0), (-180.0, 180.0), (-180.0, 180.0), (-180.0, 180.0)
      STARTMOTION GO
        JOINT 1 POSITION 0.0, 0.0, 0.0
          FRAME {last} POSITION 0.0, 0.0, 170.0
      ENDMOTION
      INITIALIZE SCENE 1
{view}      STARTSCENE LENGTH {length}
        ANIMATE M FROM 0 TO {last} USING GO
      ENDSCENE
      SHOOTSCENES
"""


def _frames(tmp_path, name, look, view="", length=1, x=6.0):
    from liganimate.compiler import load_program
    from liganimate.runtime.render.imagefiles import read_png

    text = SWING.format(view=view, length=length, last=max(length - 1, 1), x=x)
    program, _ = load_program(None, text=text, name=f"{name}.lig")
    out = tmp_path / f"{name}_{look}"
    program.render(str(out), size=SIZE, quiet=True, workers=1, look=look)
    return [read_png(p) for p in sorted(out.rglob("*.png"))]


def _drawn_box(image, background):
    rows, cols = np.nonzero(image != background)
    return rows.min(), rows.max(), cols.min(), cols.max()


THESIS_VIEW = "        VIEW POINT = (0.0, 0.0, 10.0)\n        VIEW WIDTH = 10.0\n"


def test_a_scene_without_view_frames_what_it_draws_in_the_modern_look(tmp_path):
    (modern_image,) = _frames(tmp_path, "far", "modern")
    r0, r1, c0, c1 = _drawn_box(modern_image, MODERN.background)
    # The model fills the frame, with a margin, however far from the origin it is.
    assert max(r1 - r0 > 0.5 * SIZE[1], c1 - c0 > 0.5 * SIZE[0])
    assert r0 > 0 and c0 > 0 and r1 < SIZE[1] - 1 and c1 < SIZE[0] - 1
    # The thesis look keeps the thesis' camera: (0, 0, 10) looking at the origin, 10 wide.
    (thesis_image,) = _frames(tmp_path, "far", "thesis")
    (explicit,) = _frames(tmp_path, "far_view", "thesis", THESIS_VIEW)
    assert np.array_equal(thesis_image, explicit)
    r0, r1, c0, c1 = _drawn_box(thesis_image, 255)
    assert c1 - c0 < 0.25 * SIZE[0]


def test_a_scene_that_sets_view_keeps_it_in_the_modern_look(tmp_path):
    (image,) = _frames(tmp_path, "viewed", "modern", THESIS_VIEW)
    r0, r1, c0, c1 = _drawn_box(image, MODERN.background)
    assert c1 - c0 < 0.25 * SIZE[0]  # as small as the thesis' camera shows it


def test_the_framing_holds_what_every_tick_draws(tmp_path):
    images = _frames(tmp_path, "swing", "modern", length=60, x=-3.0)
    assert len(images) == 60
    boxes = np.array([_drawn_box(im, MODERN.background) for im in images])
    # Every tick inside the frame; together they fill it.
    assert (boxes[:, 0] > 0).all() and (boxes[:, 2] > 0).all()
    assert (boxes[:, 1] < SIZE[1] - 1).all() and (boxes[:, 3] < SIZE[0] - 1).all()
    assert boxes[:, 1].max() - boxes[:, 0].min() > 0.6 * SIZE[1]
