"""Issue 24: BVH import in its own terms: limits at the BVH line, long chains, no warning leaking.

Each import runs as ``python -W error -m liganimate import``, so a numpy or
Python warning is an error and shows.
"""

from __future__ import annotations

import subprocess
import sys

import pytest


def chain(n: int, value: str = "0", offset: str = "0 1 0") -> str:
    """A BVH file: a root and an ``n``-joint chain, two frames; ``value`` is frame 2's root Yposition."""
    out = ["HIERARCHY", "ROOT Hips", "{", "  OFFSET 0 0 0"]
    out.append("  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation")
    for i in range(n):
        out += [f"JOINT J{i}", "{", f"  OFFSET {offset}", "  CHANNELS 3 Zrotation Xrotation Yrotation"]
    out += ["End Site", "{", "  OFFSET 0 1 0", "}"] + ["}"] * (n + 1)
    out += ["MOTION", "Frames: 2", "Frame Time: 0.0333333"]
    values = ["0"] * (6 + 3 * n)
    out.append(" ".join(values))
    values[1] = value
    out.append(" ".join(values))
    return "\n".join(out) + "\n"


def liganimate(cwd, *args):
    return subprocess.run(
        [sys.executable, "-W", "error", "-m", "liganimate", *args], cwd=cwd, capture_output=True, text=True, timeout=600
    )


def imported(tmp_path, text: str):
    (tmp_path / "c.bvh").write_text(text)
    return liganimate(tmp_path, "import", "c.bvh", "-o", "c.lig")


def test_a_value_near_1e308_is_refused_at_its_bvh_line_and_nothing_is_written(tmp_path):
    r = imported(tmp_path, chain(3, value="1.5E308"))
    assert r.returncode == 1
    assert r.stderr.splitlines()[0] == (
        "c.bvh:30:3: error: '1.5E308' in frame 2 (Yposition of joint Hips) is beyond the limit of 1E12 units "
        "from the origin"
    )
    assert "Warning" not in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "c.lig").exists()


def test_an_angle_beyond_the_largest_is_refused_at_its_bvh_line(tmp_path):
    text = chain(3)
    lines = text.splitlines()
    lines[-1] = lines[-1].replace("0 0 0 0 0 0 0", "0 0 0 0 0 0 2E9", 1)
    r = imported(tmp_path, "\n".join(lines) + "\n")
    assert r.returncode == 1
    assert r.stderr.splitlines()[0] == (
        "c.bvh:30:13: error: '2E9' in frame 2 (Zrotation of joint J0) is beyond the limit of 1E9 degrees"
    )


def test_an_offset_beyond_the_geometry_limit_is_refused_at_its_bvh_line(tmp_path):
    r = imported(tmp_path, chain(3, offset="0 1E308 0"))
    assert r.returncode == 1
    assert r.stderr.splitlines()[0] == (
        "c.bvh:8:12: error: the Y offset of joint J0 is 1E308, beyond the limit of 1E12 units for anything drawn"
    )


def test_a_skeleton_whose_offsets_add_up_beyond_the_limit_is_refused_not_written_for_load_to_refuse(tmp_path):
    r = imported(tmp_path, chain(10, offset="0 9E11 0"))
    assert r.returncode == 1
    first = r.stderr.splitlines()[0]
    assert first.startswith("c.bvh:8:3: error: the skeleton reaches ")
    assert "at joint J0, counting its offsets end to end, beyond the limit of 1E12 units for a model" in first
    assert not (tmp_path / "c.lig").exists()
    # Just within: written, and LOAD takes it.
    r = imported(tmp_path, chain(10, offset="0 3E10 0"))
    assert r.returncode == 0, r.stderr
    (tmp_path / "use.lig").write_text("LOAD C_FIGURE FROM 'c.lig'\n")
    r = liganimate(tmp_path, "check", "use.lig")
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize(("n", "scene"), [(1_000, True), (10_000, False)])
def test_a_long_chain_imports_and_its_library_loads(tmp_path, n, scene):
    r = imported(tmp_path, chain(n))
    assert r.returncode == 0, r.stderr  # was: "the program is nested too deeply to compile", no file or line
    assert f"({n + 1} joints, 2 frames)" in r.stderr
    play = "INITIALIZE SCENE 1\nSTARTSCENE LENGTH 2\nANIMATE C_FIGURE FROM 0 TO 1 USING C\nENDSCENE\nSHOOTSCENES\n"
    (tmp_path / "use.lig").write_text("LOAD C_FIGURE, C FROM 'c.lig'\n" + (play if scene else ""))
    r = liganimate(tmp_path, "check", "use.lig")
    assert r.returncode == 0 and r.stderr == "", r.stderr
