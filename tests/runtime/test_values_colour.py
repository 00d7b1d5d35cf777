"""COLOUR on graphical objects (an extension): how it combines with LIGHTNESS, superposition and PRIMITIVEs."""

import numpy as np

from liganimate.runtime.values import (
    Canvas,
    Graphical,
    box,
    colour_levels,
    grey_levels,
    joined_shades,
)


def _box(light=40.0):
    return box((0, 0, 0), 1, 1, 1, light)


def test_white_is_the_thesis_grey_exactly():
    rng = np.random.default_rng(7)
    light = rng.uniform(-20, 120, 500)
    white = np.full((500, 3), 100.0)
    rgb = colour_levels(light, white)
    assert rgb.shape == (500, 3) and rgb.dtype == np.uint8
    for c in range(3):
        assert np.array_equal(rgb[:, c], grey_levels(light))


def test_lightness_lights_the_colour():
    rgb = colour_levels(np.array([50.0, 100.0, 0.0]), np.array([[100, 0, 50]] * 3, dtype=float))
    # Each channel is the grey level of LIGHTNESS * c / 100.
    assert rgb.tolist() == [grey_levels([50.0, 0.0, 25.0]).tolist(), [255, 0, grey_levels(50.0)], [0, 0, 0]]
    assert rgb[0].tolist() == [127, 0, 64]


def test_an_object_without_colour_shades_grey():
    g = _box()
    assert g.colour is None
    assert np.array_equal(g.shades(), grey_levels(g.lightness))


def test_colour_keeps_the_box_faces_lighting():
    g = _box(40.0).with_colour((100, 50, 0))
    shades = g.shades()
    assert shades.shape == (len(g), 3)
    # The front and back faces are at 40, the others at 60 (Appendix A's BOX).
    assert {tuple(r) for r in shades.tolist()} == {(102, 51, 0), (153, 77, 0)}


def test_lightness_after_colour_keeps_the_colour():
    g = _box().with_colour((0, 100, 0)).with_lightness(100)
    assert g.shades().tolist()[0] == [0, 255, 0]


def test_superposing_grey_and_colour_makes_the_grey_part_white():
    grey, red = _box(40.0), _box(40.0).with_colour((100, 0, 0))
    both = grey + red
    assert both.colour is not None and len(both) == 2 * len(grey)
    shades = both.shades()
    assert np.array_equal(shades[: len(grey)], np.repeat(grey.shades()[:, None], 3, axis=1))
    assert np.array_equal(shades[len(grey) :], red.shades())
    assert (grey + grey).colour is None


def test_transforming_keeps_colour():
    g = _box().with_colour((10, 20, 30))
    m = np.diag([-1.0, 1.0, 1.0, 1.0])
    assert np.array_equal(g.transformed(m).colour, g.colour)


def test_joined_shades_promotes_only_when_needed():
    a = np.array([1, 2], dtype=np.uint8)
    b = np.array([[3, 4, 5]], dtype=np.uint8)
    assert joined_shades([a, a]).tolist() == [1, 2, 1, 2]
    assert joined_shades([a, b]).tolist() == [[1, 1, 1], [2, 2, 2], [3, 4, 5]]
    assert joined_shades([]).shape == (0,)


def test_a_primitive_canvas_colours_the_polygons_drawn_next():
    c = Canvas()
    square = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
    c.poly(square)  # two triangles, white
    c.colour((100, 0, 0))
    c.poly([(0, 0, 1), (1, 0, 1), (1, 1, 1)])  # one triangle, red
    g = c.result()
    assert len(g) == 3
    assert g.colour.tolist() == [[100, 100, 100], [100, 100, 100], [100, 0, 0]]


def test_a_primitive_without_colour_is_grey():
    c = Canvas()
    c.poly([(0, 0, 0), (1, 0, 0), (1, 1, 0)])
    assert c.result().colour is None


def test_colour_components_are_clipped_when_drawn():
    g = Graphical(np.zeros((1, 3, 3)), [100.0], [False], [[150.0, -5.0, 100.0]])
    assert g.shades().tolist() == [[255, 0, 255]]
