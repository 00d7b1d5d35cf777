"""COLOUR, an extension (issue 13): the modifier, DRAW WITH <COLOUR>, its errors, and what it draws."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
from PIL import Image

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics, format_diagnostic

HEAD = """\
      GRAPHICAL RED, GREY, TRIANGLE
      MODEL M
      PRIMITIVE TRI
      TRI ::= 'TRI' ;
      DRAW WITH <COLOUR (10, 40, 100), LIGHTNESS 80>
      DRAW POLY FROM (0, 0, 0) TO (1, 0, 0) TO (0, 1, 0)
      RETURN
      END
      RED :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0, LIGHTNESS 60
      GREY :- BOX AT (1.5, 0.0, 0.0), WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0, LIGHTNESS 60
      TRIANGLE :- TRI <TRANS (-2.5, 0, 0)>
"""
SCENE = """\
      INITIALIZE SCENE 1
      VIEW POINT = (2.0, 2.0, 6.0)
      VIEW WIDTH = 6.0
      STARTSCENE LENGTH 1
      BACKGROUND {what}
      ENDSCENE
      SHOOTSCENE
      END
"""


def _errors(text: str) -> list[str]:
    with pytest.raises(LigDiagnostics) as info:
        load_program(None, text=text, name="colour.lig")
    return [format_diagnostic(d) for d in info.value.diagnostics]


def _render(tmp_path: pathlib.Path, body: str, what: str, name: str, look: str = "thesis") -> np.ndarray:
    # The thesis look draws each face in exactly the shade LIGHTNESS and COLOUR give.
    program, _ = load_program(None, text=HEAD + body + SCENE.format(what=what), name=f"{name}.lig")
    out = tmp_path / name
    program.render(str(out), size=(160, 120), quiet=True, workers=1, look=look)
    return np.asarray(Image.open(out / "scene1" / "00000.png"))


def test_colour_draws_in_colour_and_keeps_the_grey_parts_grey(tmp_path):
    image = _render(tmp_path, "      RED :- RED <COLOUR (100, 20, 10)>\n", "RED + GREY + TRIANGLE", "colour")
    assert image.ndim == 3 and image.shape[2] == 3
    colours = {tuple(p) for p in image.reshape(-1, 3).tolist()}
    # The red box's faces at LIGHTNESS 60 and 90 (the BOX's brighter sides), each channel the grey of l * c / 100.
    assert (153, 31, 15) in colours or (230, 46, 23) in colours
    assert any(r == g == b and r < 255 for r, g, b in colours)  # the grey box
    assert (20, 82, 204) in colours  # the triangle: LIGHTNESS 80 lighting (10, 40, 100)


def test_a_program_without_colour_still_draws_grey(tmp_path):
    image = _render(tmp_path, "", "RED + GREY", "grey")
    assert image.ndim == 2


@pytest.mark.parametrize("look", ["thesis", "modern"])
def test_white_is_grey(tmp_path, look):
    grey = _render(tmp_path, "", "RED + GREY", "plain", look)
    white = _render(tmp_path, "      RED :- RED <COLOUR (100, 100, 100)>\n", "RED + GREY", "white", look)
    assert white.ndim == 3
    for c in range(3):
        assert np.array_equal(white[:, :, c], grey)


def test_colour_takes_a_vector():
    (message,) = _errors(HEAD + "      RED :- RED <COLOUR 50>\n" + SCENE.format(what="RED"))
    assert "colour.lig:12:" in message and "COLOUR needs a colour (r, g, b), each 0 to 100, not an INTEGER" in message


def test_colour_applies_to_graphical_objects_only():
    text = HEAD + "      M :- JOINT 1, RED, (0,0,0), GREY, (0,0,0), (0,0), (0,0), (0,0)\n"
    text += "      M :- M <COLOUR (1, 2, 3)>\n" + SCENE.format(what="RED")
    (message,) = _errors(text)
    assert "COLOUR applies to graphical objects; this is a MODEL" in message


def test_draw_with_takes_lightness_or_colour_only():
    text = HEAD.replace("DRAW WITH <COLOUR (10, 40, 100), LIGHTNESS 80>", "DRAW WITH <SCALE 2>")
    (message,) = _errors(text + SCENE.format(what="RED"))
    assert "DRAW WITH takes <LIGHTNESS ...> or <COLOUR ...>" in message


def test_color_is_the_same_word():
    from liganimate.compiler import compile_text

    text = HEAD + "      RED :- RED <COLOR (100, 20, 10)>\n" + SCENE.format(what="RED")
    same = text.replace("<COLOR (", "<COLOUR(")  # the same length, so every position is the same
    assert same != text
    python = compile_text(text, "color.lig").python
    assert "rt.graphical_colour(" in python
    # The modules differ only in the program text they quote.
    assert python.replace(repr(text), "") == compile_text(same, "color.lig").python.replace(repr(same), "")


def test_colour_is_still_a_name_elsewhere():
    from liganimate.compiler import compile_text

    text = "      INTEGER COLOUR\n      COLOUR = 3\n      PRINT COLOUR + 1\n      END\n"
    assert compile_text(text, "name.lig").checked.main.types["COLOUR"] == "INTEGER"
    program, _ = load_program(None, text=text, name="name.lig")
    assert program is not None
