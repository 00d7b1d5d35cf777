"""Golden frames: every example is rendered small and compared with stored images.

The renderer is deterministic, so images normally match exactly. A render may
differ from the stored image in at most GOLDEN_TOLERANCE of its pixels
(edge pixels can flip when numpy's float rounding differs between
versions); anything more fails and leaves a diff image in
tests/golden/_failures/. Regenerate only on purpose:
``python -m pytest tests/test_golden.py --regen-golden``.
"""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
from PIL import Image

from liganimate.cli import load_program
from liganimate.runtime.render.imagefiles import read_png

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
GOLDEN = ROOT / "tests" / "golden"
FAILURES = GOLDEN / "_failures"
SIZE = (240, 180)
#: Largest fraction of pixels that may differ from the stored image.
GOLDEN_TOLERANCE = 0.002
#: Long scenes are compared on at most this many images, evenly spaced.
MAX_IMAGES = 8


def example_files():
    return sorted(p for p in EXAMPLES.glob("*.lig"))


def _selected(images: list) -> list:
    if len(images) <= MAX_IMAGES:
        return images
    idx = np.linspace(0, len(images) - 1, MAX_IMAGES).round().astype(int)
    return [images[i] for i in sorted(set(idx))]


def _diff_image(expected: np.ndarray, actual: np.ndarray, path: pathlib.Path) -> None:
    # Both (H, W, 3): expected, actual, and actual dimmed with the differing pixels in red.
    path.parent.mkdir(parents=True, exist_ok=True)
    rgb = actual // 2 + 64
    rgb[(expected != actual).any(axis=-1)] = (255, 0, 0)
    Image.fromarray(np.concatenate([expected, actual, rgb], axis=1)).save(path)


def _mode(path: pathlib.Path) -> str:
    with Image.open(path) as im:
        return im.mode


@pytest.mark.parametrize("path", example_files(), ids=lambda p: p.stem)
def test_example_matches_golden_frames(path, tmp_path, regen_golden):
    program, _ = load_program(str(path))
    out = tmp_path / "frames"
    program.render(str(out), size=SIZE, quiet=True, workers=1)
    rendered = sorted(out.rglob("*.png"))
    assert rendered, f"{path.name} rendered no images"
    golden_dir = GOLDEN / path.stem
    chosen = _selected([p.relative_to(out) for p in rendered])
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
    assert stored, f"no golden images for {path.name}; run with --regen-golden and look at them"
    assert [str(p) for p in stored] == [str(p) for p in chosen], "the set of images changed"
    for rel in stored:
        # A grey frame stays grey and a colour frame stays in colour; pixels are compared in RGB.
        assert _mode(out / rel) == _mode(golden_dir / rel), (
            f"{path.stem}/{rel}: the image changed between grey and colour"
        )
        expected = read_png(golden_dir / rel, colour=True)
        actual = read_png(out / rel, colour=True)
        assert expected.shape == actual.shape
        differing = np.count_nonzero((expected != actual).any(axis=-1)) / (expected.shape[0] * expected.shape[1])
        if differing > GOLDEN_TOLERANCE:
            diff = FAILURES / path.stem / rel
            _diff_image(expected, actual, diff)
            pytest.fail(f"{path.stem}/{rel}: {differing:.2%} of pixels differ; diff image at {diff}")


def test_rendering_is_deterministic(tmp_path):
    program, _ = load_program(str(EXAMPLES / "appendix_a.lig"))
    a, b = tmp_path / "a", tmp_path / "b"
    program.render(str(a), size=SIZE, quiet=True, workers=1)
    program.render(str(b), size=SIZE, quiet=True, workers=2)
    files = sorted(p.relative_to(a) for p in a.rglob("*.png"))
    assert files
    for rel in files:
        assert (a / rel).read_bytes() == (b / rel).read_bytes()
