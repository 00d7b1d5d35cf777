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

import numpy as np
import pytest
from paths import ROOT_DIR, TESTS_DIR
from PIL import Image

from liganimate.cli import load_program
from liganimate.runtime.render.imagefiles import read_png

EXAMPLES = pathlib.Path(ROOT_DIR) / "examples"
GOLDEN = pathlib.Path(TESTS_DIR) / "golden"
FAILURES = GOLDEN / "_failures"
SIZE = (240, 180)
GOLDEN_TOLERANCE = 0.002
#: Images compared per example, evenly spaced over the scene.
MAX_IMAGES = 3
#: Small examples with figures, solids and edges at many angles.
CASES = ["appendix_a", "walk_and_wave", "ring_the_bell", "big_and_small_robot"]


def _selected(images: list) -> list:
    if len(images) <= MAX_IMAGES:
        return images
    idx = np.linspace(0, len(images) - 1, MAX_IMAGES).round().astype(int)
    return [images[i] for i in sorted(set(idx))]


def _diff_image(expected: np.ndarray, actual: np.ndarray, path: pathlib.Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    rgb = np.stack([actual] * 3, axis=-1).astype(np.uint8) // 2 + 64
    rgb[expected != actual] = (255, 0, 0)
    Image.fromarray(np.concatenate([np.stack([expected] * 3, -1), np.stack([actual] * 3, -1), rgb], axis=1)).save(path)


def _render(name: str, out: pathlib.Path, aa: int, workers: int = 1) -> list:
    program, _ = load_program(str(EXAMPLES / f"{name}.lig"))
    program.render(str(out), size=SIZE, quiet=True, workers=workers, aa=aa)
    return sorted(p.relative_to(out) for p in out.rglob("*.png"))


@pytest.mark.parametrize("aa", [2, 4])
@pytest.mark.parametrize("name", CASES)
def test_example_matches_aa_golden_frames(name, aa, tmp_path, regen_golden):
    out = tmp_path / "frames"
    rendered = _render(name, out, aa)
    assert rendered, f"{name} rendered no images"
    chosen = _selected(rendered)
    golden_dir = GOLDEN / f"aa{aa}" / name
    if regen_golden:
        if golden_dir.exists():
            for old in golden_dir.rglob("*.png"):
                old.unlink()
        for rel in chosen:
            dst = golden_dir / rel
            dst.parent.mkdir(parents=True, exist_ok=True)
            dst.write_bytes((out / rel).read_bytes())
        return
    stored = sorted(p.relative_to(golden_dir) for p in golden_dir.rglob("*.png"))
    assert stored, f"no aa={aa} golden images for {name}; run with --regen-golden and look at them"
    assert [str(p) for p in stored] == [str(p) for p in chosen], "the set of images changed"
    for rel in stored:
        expected = read_png(golden_dir / rel)
        actual = read_png(out / rel)
        assert expected.shape == actual.shape == (SIZE[1], SIZE[0])
        differing = np.count_nonzero(expected != actual) / expected.size
        if differing > GOLDEN_TOLERANCE:
            diff = FAILURES / f"aa{aa}" / name / rel
            _diff_image(expected, actual, diff)
            pytest.fail(f"aa{aa}/{name}/{rel}: {differing:.2%} of pixels differ; diff image at {diff}")


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
