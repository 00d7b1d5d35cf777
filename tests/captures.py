"""Real motion captures for the tests: the BVH files shipped in the source distributions of bvhtoolbox and bvhtools.

Both packages are MIT-licensed.  Their source distributions are fetched
with ``pip download --no-deps --no-binary :all:`` into ``tests/.cache``
the first time and unpacked there; nothing of them is committed.  Outside
CI a failed download skips, saying why; in CI it fails.

* ``mocapbank``: bvhtoolbox's ``test_mocapbank.bvh``, CMU-style names
  (Hips, Chest, LeftHip, LeftKnee, LeftAnkle...), ZXY channels, 455 frames;
* ``mixamo``: bvhtoolbox's ``test_freebvh.bvh``, a Mixamo rig
  (``mixamorig:Hips``...), 55 joints with fingers, 69 frames;
* ``rigify``: bvhtools' ``test3.bvh``, a Blender/Rigify export (pelvis,
  thigh.L, shin.L...), position channels on every joint, XYZ, 3,089 frames;
* ``long``: bvhtools' ``test.bvh``, 7,184 frames (LeftUpLeg, LeftLeg...).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tarfile

import pytest
from paths import TESTS_DIR

CACHE = os.path.join(TESTS_DIR, ".cache", "captures")

#: name -> (package, version, path inside the source distribution)
CAPTURES = {
    "mocapbank": ("bvhtoolbox", "0.1.3", "tests/example_files/test_mocapbank.bvh"),
    "mixamo": ("bvhtoolbox", "0.1.3", "tests/example_files/test_freebvh.bvh"),
    "rigify": ("bvhtools", "1.6.0", "testBvhFiles/test3.bvh"),
    "long": ("bvhtools", "1.6.0", "testBvhFiles/test.bvh"),
}


def _give_up(message: str):
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)


def capture(name: str) -> str:
    """The path of a real capture, fetched from PyPI the first time (see the module's docstring)."""
    package, version, inner = CAPTURES[name]
    folder = os.path.join(CACHE, f"{package}-{version}")
    path = os.path.join(folder, inner)
    if os.path.isfile(path):
        return path
    os.makedirs(CACHE, exist_ok=True)
    archive = os.path.join(CACHE, f"{package}-{version}.tar.gz")
    if not os.path.isfile(archive):
        cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--no-binary", ":all:", "-d", CACHE]
        try:
            r = subprocess.run([*cmd, f"{package}=={version}"], capture_output=True, text=True, timeout=300)
        except subprocess.TimeoutExpired:
            _give_up(f"pip download {package}=={version} took over 5 minutes, so its BVH captures are not here")
        if r.returncode != 0 or not os.path.isfile(archive):
            _give_up(f"pip download {package}=={version} failed, so its BVH captures are not here:\n{r.stderr[-2000:]}")
    with tarfile.open(archive) as tar:
        member = tar.getmember(f"{package}-{version}/{inner}")
        tar.extract(member, CACHE, filter="data")
    return path
