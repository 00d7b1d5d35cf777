"""Animated models as graphical objects (thesis §5.1), PRINT in check, the triangle limit (issue 9)."""

from __future__ import annotations

import io
import pathlib

import numpy as np
import pytest
from PIL import Image

from liganimate.compiler import NotParsed, load_program
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.runtime import values

HEAD = """\
      GRAPHICAL ARM, BODY, G, FLOOR
      MODEL M
      MOTION SWING
      BODY :- BOX WIDTH 0.6, HEIGHT 1.0, DEPTH 0.4
      ARM :- BOX WIDTH 0.2, HEIGHT 0.8, DEPTH 0.2
      FLOOR :- BOX AT (0.0, -0.6, 0.0), WIDTH 3.0, HEIGHT 0.1, DEPTH 1.0
      M :- JOINT 1, BODY, (0.3, 0.4, 0.0), ARM, (0.0, 0.4, 0.0),
               (0.0, 0.0), (0.0, 0.0), (-90.0, 90.0)
      STARTMOTION SWING
        JOINT 1 POSITION 0.0, 0.0, -60.0
          FRAME 6 POSITION 0.0, 0.0, 60.0
      ENDMOTION
      INITIALIZE SCENE 1
          VIEW POINT = (0.0, 0.5, 6.0)
          VIEW WIDTH = 4.0
      STARTSCENE LENGTH 7
          ANIMATE M FROM 0 TO 6 USING SWING
"""
TAIL = """\
      ENDSCENE
      SHOOTSCENES
      END
"""


def render(tmp_path: pathlib.Path, body: str, name: str) -> list:
    src = tmp_path / f"{name}.lig"
    src.write_text(HEAD + body + TAIL)
    program, _ = load_program(str(src))
    out = tmp_path / name
    program.render(str(out), size=(160, 120), quiet=True, workers=1)
    return [np.asarray(Image.open(out / "scene1" / f"{t:05d}.png").convert("L"), dtype=int) for t in range(7)]


def test_a_model_animated_in_a_scene_is_a_graphical_object_in_this_ticks_pose(tmp_path):
    moved = render(
        tmp_path, "          G :- M <TRANS (1.5, 0.0, 0.0)>\n          G = G + FLOOR\n          BACKGROUND G\n", "moved"
    )
    alone = render(tmp_path, "", "alone")
    right = slice(110, 160)  # where the translated copy is drawn, away from M itself
    assert all((m[:, right] != a[:, right]).any() for m, a in zip(moved, alone))
    # The copy follows the swing: its pixels change from tick to tick.
    assert (moved[0][:, right] != moved[6][:, right]).any()


def test_background_of_an_animated_model_is_drawn_in_its_pose_not_neutral(tmp_path):
    with_bg = render(tmp_path, "          BACKGROUND M\n", "bg")
    alone = render(tmp_path, "", "alone2")
    # The pose-true copy lies exactly under the drawn model, so nothing else shows.
    for a, b in zip(with_bg, alone):
        assert (a != b).sum() <= 10


def test_a_model_not_animated_is_still_not_a_graphical_object(tmp_path):
    src = tmp_path / "bad.lig"
    src.write_text(
        HEAD.replace("          ANIMATE M FROM 0 TO 6 USING SWING\n", "")
        + "          G :- M <TRANS (1.5, 0.0, 0.0)>\n"
        + TAIL
    )
    with pytest.raises((NotParsed, LigDiagnostics)) as err:
        load_program(str(src))
    assert "G is a GRAPHICAL object, so it cannot hold a MODEL" in str(err.value)


def test_check_writes_print_output_and_run_writes_it_once(tmp_path):
    src = tmp_path / "p.lig"
    src.write_text(HEAD.replace("      INITIALIZE SCENE 1", "      PRINT SWING\n      INITIALIZE SCENE 1") + TAIL)
    program, _ = load_program(str(src))
    out = io.StringIO()
    program.check(stdout=out)
    assert out.getvalue().count("FRAME") == 1
    assert program.check() == []  # the default still writes nothing
    ran = io.StringIO()
    program.render(str(tmp_path / "o"), size=(16, 12), quiet=True, workers=1, stdout=ran)
    assert ran.getvalue().count("FRAME") == 1


def test_superposition_beyond_the_triangle_limit_is_a_positioned_error(tmp_path, monkeypatch):
    monkeypatch.setattr(values, "MAX_TRIANGLES", 1000)
    src = tmp_path / "big.lig"
    src.write_text(
        "      GRAPHICAL G\n      G :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0\n"
        "      DO 10 I = 1, 30\n        G = G + G\n 10   CONTINUE\n      END\n"
    )
    program, _ = load_program(str(src))
    with pytest.raises(LigDiagnostics) as err:
        program.check()
    d = err.value.diagnostics[0]
    assert (d.pos.line, "beyond the limit of 1,000") == (4, "beyond the limit of 1,000") and "1,536" in d.message
