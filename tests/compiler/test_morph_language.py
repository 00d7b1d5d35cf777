"""Morphing segments in the language: STARTMOTION's SCALE LINK and SHAPE LINK entries, PRINT, and their errors."""

from __future__ import annotations

import io

import numpy as np
import pytest

from liganimate.cli import main
from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics, format_diagnostic
from liganimate.runtime.figure import pose as P

MODEL = """\
      A :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0
      B :- BOX WIDTH 2.0, HEIGHT 1.0, DEPTH 1.0
      WIDE :- BOX AT (0.5, 0.0, 0.0), WIDTH 3.0, HEIGHT 0.5, DEPTH 1.0
      M :- JOINT 1, A, (0.0, 0.5, 0.0), B, (0.0, -0.5, 0.0), (0.0, 90.0)
"""

SCENE = """\
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 3
        ANIMATE M FROM 0 TO 2 USING GROW
      ENDSCENE
      SHOOTSCENES
"""


def run(text: str):
    program, _ = load_program(text=text, name="t.lig")
    out = io.StringIO()
    rt = program.execute("run", stdout=out)
    return rt, out.getvalue()


def error(text: str):
    with pytest.raises(LigDiagnostics) as info:
        program, _ = load_program(text=text, name="t.lig")
        program.check()
    d = info.value.diagnostics[0]
    text = format_diagnostic(d)
    assert text.startswith(f"t.lig:{d.pos.line}:{d.pos.column}: error: ")
    assert "^" in text  # the source line with a caret
    return d


def motion(body: str) -> str:
    return MODEL + "      STARTMOTION GROW\n" + body + "      ENDMOTION\n"


def test_scale_and_shape_tracks_are_keyframed_and_printed():
    rt, out = run(
        motion(
            """\
        SCALE LINK B POSITION 1.0, 1.0, 1.0
          FRAME 10 POSITION 2.0, 1.0, 0.5 INTERPOLATE ACCDCC
        SHAPE LINK A POSITION A
          FRAME 4 POSITION WIDE
          FRAME 8 POSITION A INTERPOLATE ACCELERATE
"""
        )
        + "      PRINT GROW\n"
    )
    m = rt.variables["GROW"]
    assert m.length == 10.0 and m.joints == ()
    np.testing.assert_allclose(m.morphs.scale("B", np.array([0.0, 10.0])), [[1, 1, 1], [2, 1, 0.5]])
    assert "  SCALE LINK B POSITION 1, 1, 1\n    FRAME 10 POSITION 2, 1, 0.5 INTERPOLATE ACCDCC\n" in out
    assert "SHAPE LINK A: weight of a shape of 12 triangles" in out
    # Drawn: link A is WIDE at frame 4, its own again at 8; B is scaled along its own axes.
    fig = rt.variables["M"]
    wide = rt.variables["WIDE"]
    g = P.posed_graphical(fig, m, 4.0)
    table = P.mesh_table(fig)
    X = P.world_transforms(fig, np.zeros((1, 1, 3)), np.asarray(fig.placement)[None])
    want = wide.triangles + X[0, 0, :3, 3]
    np.testing.assert_allclose(g.triangles[table.link == 0], want, atol=1e-12)


def test_a_morph_renders_and_the_figure_changes(tmp_path):
    text = motion("        SCALE LINK B\n          FRAME 2 POSITION 1.0, 3.0, 1.0\n") + SCENE
    program, _ = load_program(text=text, name="t.lig")
    program.render(str(tmp_path / "f"), size=(80, 60), quiet=True, workers=1, look="thesis")
    frames = sorted((tmp_path / "f").rglob("*.png"))
    assert len(frames) == 3 and frames[0].read_bytes() != frames[2].read_bytes()


def test_a_morph_does_not_care_which_link_is_main():
    rt, _ = run(
        motion(
            "        SCALE LINK B\n          FRAME 2 POSITION 1.0, 3.0, 1.0\n        SHAPE LINK A\n          FRAME 2 POSITION WIDE\n"
        )
        + "      N :- M\n      FIGURE N MAIN LINK B\n"
    )
    m, fig, rerooted = rt.variables["GROW"], rt.variables["M"], rt.variables["N"]
    t = np.array([0.0, 1.0, 2.0])
    for f in (fig, rerooted):
        X = P.world_transforms(f, np.zeros((3, 1, 3)), np.broadcast_to(np.eye(4), (3, 4, 4)))
        Y, local = P.morphed(f, m, t, X)
        # B's scale multiplies its own axes (not the joint's location), A's shape is WIDE's at frame 2.
        np.testing.assert_allclose(np.linalg.norm(Y[:, 1, :3, :3], axis=-2)[2], [1, 3, 1])
        np.testing.assert_allclose(local[2][P.mesh_table(f).link == 0], rt.variables["WIDE"].triangles)


def test_the_algebra_carries_morphs():
    rt, _ = run(
        motion("        SCALE LINK B\n          FRAME 4 POSITION 2.0, 2.0, 2.0\n")
        + "      BACK = GROW <SCALE FRAMES -1>\n      TWICE = 2 * GROW\n      S = TWICE <SCALE EXTREMES 0.5>\n"
    )
    v = rt.variables
    np.testing.assert_allclose(v["BACK"].morphs.scale("B", np.array([0.0, 4.0])), [[2, 2, 2], [1, 1, 1]])
    np.testing.assert_allclose(v["TWICE"].morphs.scale("B", np.array([4.0, 6.0, 8.0]))[:, 0], [1.0, 1.5, 2.0])
    assert v["TWICE"].length == 8.0
    t = np.linspace(0.0, 8.0, 17)
    np.testing.assert_array_equal(v["S"].morphs.scale("B", t), v["TWICE"].morphs.scale("B", t))


def test_shapes_of_different_structures_are_refused_at_the_keyframe():
    d = error(
        motion(
            """\
        SHAPE LINK A POSITION A
          FRAME 4 POSITION (A + B)
"""
        )
    )
    assert d.pos.line == 7
    assert "cannot in-between a shape of 12 triangles and a shape of 24 triangles" in d.message
    assert "same structure" in (d.hint or "")


def test_a_shape_not_the_links_structure_is_refused_at_the_animate():
    d = error(motion("        SHAPE LINK A\n          FRAME 2 POSITION (A + B)\n") + SCENE)
    assert d.pos.line == 11  # the ANIMATE
    assert "link A has a shape of 12 triangles, so it cannot morph into a shape of 24 triangles" in d.message


@pytest.mark.parametrize(("value", "word"), [("0.0", "flatten"), ("-1.0", "inside out")])
def test_a_scale_of_zero_or_below_is_refused_at_its_keyframe(value, word):
    d = error(motion(f"        SCALE LINK B\n          FRAME 4 POSITION 1.0, {value}, 1.0\n"))
    assert d.pos.line == 7 and word in d.message and "along Y" in d.message
    assert "positive" in d.hint


def test_a_scale_start_of_zero_is_refused_at_its_entry():
    d = error(motion("        SCALE LINK B POSITION 0.0, 1.0, 1.0\n"))
    assert d.pos.line == 6 and "flatten" in d.message


def test_a_link_the_model_has_not_is_refused_at_the_animate():
    d = error(motion("        SCALE LINK BB\n          FRAME 2 POSITION 2.0, 2.0, 2.0\n") + SCENE)
    assert d.pos.line == 11
    assert "morphs link BB, which the model does not have" in d.message
    assert "B" in (d.hint or "")


def test_a_shape_must_be_graphical_and_an_entry_appears_once():
    d = error(motion("        SHAPE LINK A\n          FRAME 2 POSITION 1.0, 2.0, 3.0\n"))
    assert "a shape is one graphical object" in d.message
    d = error(motion("        SHAPE LINK A\n          FRAME 2 POSITION M\n"))
    assert "must be a GRAPHICAL" in d.message or "GRAPHICAL" in d.message
    d = error(motion("        SCALE LINK B\n        SCALE LINK B\n"))
    assert "SCALE LINK B appears twice" in d.message


def test_bad_morph_input_writes_nothing(tmp_path, capsys):
    path = tmp_path / "bad.lig"
    path.write_text(motion("        SHAPE LINK A\n          FRAME 2 POSITION (A + B)\n") + SCENE, encoding="utf-8")
    out = tmp_path / "frames"
    assert main(["run", str(path), "-o", str(out), "--quiet"]) != 0
    assert not out.exists()
    err = capsys.readouterr().err
    assert "bad.lig:11:" in err and "Traceback" not in err


def test_poses_records_scale_and_how_much_of_its_own_shape_a_segment_shows(tmp_path):
    import json

    text = motion(
        "        SCALE LINK B\n          FRAME 2 POSITION 1.0, 3.0, 1.0\n        SHAPE LINK A\n          FRAME 2 POSITION WIDE\n"
    )
    program, _ = load_program(text=text + SCENE, name="t.lig")
    poses = tmp_path / "p.jsonl"
    program.render(str(tmp_path / "f"), size=(40, 30), quiet=True, workers=1, poses=str(poses))
    records = [json.loads(line) for line in poses.read_text().splitlines()]
    a = [r["segments"][0] for r in records]
    b = [r["segments"][1] for r in records]
    assert [s["shape"] for s in a] == [[1.0], [0.5], [0.0]] and "scale" not in a[0]
    assert [s["scale"] for s in b] == [[1.0, 1.0, 1.0], [1.0, 2.0, 1.0], [1.0, 3.0, 1.0]] and "shape" not in b[0]
    # The matrix carries the scale: B's Y column is three times as long at the end.
    m = np.reshape(b[2]["matrix"], (4, 4))
    np.testing.assert_allclose(np.linalg.norm(m[:3, :3], axis=0), [1.0, 3.0, 1.0])


def test_a_morph_that_would_draw_beyond_the_geometry_limit_is_refused_at_the_animate():
    d = error(motion("        SCALE LINK B\n          FRAME 2 POSITION 1.0E300, 1.0, 1.0\n") + SCENE)
    assert d.pos.line == 11 and "beyond the limit of 1E12" in d.message
    # A shape within the limit, which the link's scale then takes beyond it.
    huge = motion(
        "        SHAPE LINK A\n          FRAME 2 POSITION (A <SCALE 4.0E11>)\n"
        "        SCALE LINK A\n          FRAME 2 POSITION 10.0, 1.0, 1.0\n"
    )
    huge += SCENE
    assert "beyond the limit" in error(huge).message
