"""Golden frames with anti-aliasing: a few examples rendered at aa=2 and aa=4.

Like tests/test_golden.py (same size, same ``--regen-golden`` flag, same
tolerance for edge pixels that flip with numpy's float rounding, a diff
image in tests/golden/_failures/ on failure), for images whose pixels are
the rounded mean of ``aa x aa`` samples.  Stored under tests/golden/aa2/
and tests/golden/aa4/, one folder per example.  Regenerate only on purpose:
``python -m pytest tests/runtime/render/test_golden_aa.py --regen-golden``.
"""

from __future__ import annotations

import pathlib

import goldens
import numpy as np
import pytest
from paths import ROOT_DIR, TESTS_DIR

from liganimate.compiler import load_program
from liganimate.runtime.render.imagefiles import read_png

EXAMPLES = pathlib.Path(ROOT_DIR) / "examples"
GOLDEN = pathlib.Path(TESTS_DIR) / "golden"
SIZE = (240, 180)
#: Images compared per example, evenly spaced over the scene.
MAX_IMAGES = 3
#: Small examples with figures, solids and edges at many angles.
CASES = ["appendix_a", "walk_and_wave", "ring_the_bell", "big_and_small_robot"]


def _render(name: str, out: pathlib.Path, aa: int, workers: int = 1) -> list:
    program, _ = load_program(str(EXAMPLES / f"{name}.lig"))
    program.render(str(out), size=SIZE, quiet=True, workers=workers, aa=aa, look="thesis")
    return sorted(p.relative_to(out) for p in out.rglob("*.png"))


@pytest.mark.parametrize("aa", [2, 4])
@pytest.mark.parametrize("name", CASES)
def test_example_matches_aa_golden_frames(name, aa, tmp_path, regen_golden):
    out = tmp_path / "frames"
    rendered = _render(name, out, aa)
    assert rendered, f"{name} rendered no images"
    chosen = goldens.selected(rendered, MAX_IMAGES)
    goldens.check_frames(out, chosen, f"aa{aa}/{name}", regen_golden)


def test_aa_goldens_are_smoothed_versions_of_the_plain_ones():
    # The aa=4 golden of a still scene is not the plain one, but close to it:
    # it differs only along edges, by blending, and agrees in flat regions.
    plain = read_png(GOLDEN / "appendix_a" / "scene1" / "00000.png").astype(int)
    smooth = read_png(GOLDEN / "aa4" / "appendix_a" / "scene1" / "00000.png").astype(int)
    differ = plain != smooth
    assert 0.005 < differ.mean() < 0.2
    # Blended pixels take values between those of their neighbours.
    assert len(np.unique(smooth)) > len(np.unique(plain)) + 10


def test_aa_render_is_deterministic(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    files = _render("walk_and_wave", a, 4, workers=1)
    assert files == _render("walk_and_wave", b, 4, workers=2)
    for rel in files:
        assert (a / rel).read_bytes() == (b / rel).read_bytes()
