"""Golden frames: every example is rendered small and compared with stored images.

Every example in the thesis look (``look="thesis"``: flat shades on white,
the bytes it always had) under tests/golden/<example>/, and four of them in
the modern look, the default, under tests/golden/modern/<example>/.

The renderer is deterministic, so images normally match exactly. A render may
differ from the stored image in at most goldens.TOLERANCE of its pixels
(edge pixels can flip when numpy's float rounding differs between
versions); anything more fails and leaves a diff image in
tests/golden/_failures/. Regenerate only on purpose:
``python -m pytest tests/test_golden.py --regen-golden``.
"""

from __future__ import annotations

import pathlib

import goldens
import pytest

from liganimate.compiler import load_program

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
SIZE = (240, 180)
#: Long scenes are compared on at most this many images, evenly spaced.
MAX_IMAGES = 8


def example_files():
    return sorted(p for p in EXAMPLES.glob("*.lig"))


@pytest.mark.parametrize("path", example_files(), ids=lambda p: p.stem)
def test_example_matches_golden_frames(path, tmp_path, regen_golden):
    program, _ = load_program(str(path))
    out = tmp_path / "frames"
    program.render(str(out), size=SIZE, quiet=True, workers=1, look="thesis")
    rendered = sorted(out.rglob("*.png"))
    assert rendered, f"{path.name} rendered no images"
    chosen = goldens.selected([p.relative_to(out) for p in rendered], MAX_IMAGES)
    goldens.check_frames(out, chosen, path.stem, regen_golden)


#: The examples whose modern-look frames are stored too.
MODERN = ("appendix_a", "clock", "walk_and_wave", "colour_lamp")


@pytest.mark.parametrize("name", MODERN)
def test_example_matches_modern_golden_frames(name, tmp_path, regen_golden):
    program, _ = load_program(str(EXAMPLES / f"{name}.lig"))
    out = tmp_path / "frames"
    program.render(str(out), size=SIZE, quiet=True, workers=1)  # the default look
    rendered = sorted(out.rglob("*.png"))
    assert rendered, f"{name} rendered no images"
    chosen = goldens.selected([p.relative_to(out) for p in rendered], MAX_IMAGES)
    goldens.check_frames(out, chosen, f"modern/{name}", regen_golden)


@pytest.mark.parametrize("look", ["thesis", "modern"])
def test_rendering_is_deterministic(tmp_path, look):
    program, _ = load_program(str(EXAMPLES / "appendix_a.lig"))
    a, b = tmp_path / "a", tmp_path / "b"
    program.render(str(a), size=SIZE, quiet=True, workers=1, look=look)
    program.render(str(b), size=SIZE, quiet=True, workers=2, look=look)
    files = sorted(p.relative_to(a) for p in a.rglob("*.png"))
    assert files
    for rel in files:
        assert (a / rel).read_bytes() == (b / rel).read_bytes()
