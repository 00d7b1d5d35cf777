"""Golden frames, shared by the golden tests: choose the images, store them on purpose, compare them.

A frame is compared in RGB, so a change of hue fails as a change of grey
does, and a grey frame must stay grey (and a colour one in colour). A few
pixels may differ (edge pixels that flip with numpy's float rounding); more
than ``TOLERANCE`` fails with a diff image in tests/golden/_failures/.
"""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
from paths import TESTS_DIR
from PIL import Image

from liganimate.runtime.render.imagefiles import read_png

GOLDEN = pathlib.Path(TESTS_DIR) / "golden"
FAILURES = GOLDEN / "_failures"
#: Largest fraction of pixels that may differ from the stored image.
TOLERANCE = 0.002


def selected(images: list, most: int) -> list:
    """At most ``most`` of ``images``, evenly spaced, first and last included."""
    if len(images) <= most:
        return images
    idx = np.linspace(0, len(images) - 1, most).round().astype(int)
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


def check_frames(out: pathlib.Path, chosen: list, name: str, regen: bool) -> None:
    """Compare the rendered frames ``chosen`` (paths relative to ``out``) with ``tests/golden/<name>``.

    With ``regen`` (``pytest --regen-golden``), store them instead: only on
    purpose, and the commit says why they changed.
    """
    golden_dir = GOLDEN / name
    if regen:
        if golden_dir.exists():
            for old in golden_dir.rglob("*.png"):
                old.unlink()
        for rel in chosen:
            dst = golden_dir / rel
            dst.parent.mkdir(parents=True, exist_ok=True)
            dst.write_bytes((out / rel).read_bytes())
        return
    stored = sorted(p.relative_to(golden_dir) for p in golden_dir.rglob("*.png"))
    assert stored, f"no golden images for {name}; run with --regen-golden and look at them"
    assert [str(p) for p in stored] == [str(p) for p in chosen], "the set of images changed"
    for rel in stored:
        assert _mode(out / rel) == _mode(golden_dir / rel), f"{name}/{rel}: the image changed between grey and colour"
        expected = read_png(golden_dir / rel, colour=True)
        actual = read_png(out / rel, colour=True)
        assert expected.shape == actual.shape
        differing = np.count_nonzero((expected != actual).any(axis=-1)) / (expected.shape[0] * expected.shape[1])
        if differing > TOLERANCE:
            diff = FAILURES / name / rel
            _diff_image(expected, actual, diff)
            pytest.fail(f"{name}/{rel}: {differing:.2%} of pixels differ; diff image at {diff}")
