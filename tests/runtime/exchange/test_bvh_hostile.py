"""BVH files as other tools and hostile hands write them: every line ending, a byte order mark,
UTF-16, tabs are read as the same capture; a frame count that lies, or frames whose values do not
match the channels, are refused at the file's own line and column and nothing is written."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from liganimate.runtime import exchange as X

BASE = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 10 0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
0 90 0 0 0 0 0 0 0
0 90 0 10 0 0 5 0 0
0 90 0 20 0 0 10 0 0
"""


def _import(tmp_path, raw: bytes):
    path = tmp_path / "take.bvh"
    path.write_bytes(raw)
    out = tmp_path / "take.lig"
    done = subprocess.run(
        [sys.executable, "-m", "liganimate", "import", str(path), "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    return done, out


@pytest.mark.parametrize(
    "encode",
    [
        pytest.param(lambda t: t.replace("\n", "\r\n").encode(), id="crlf"),
        pytest.param(lambda t: t.replace("\n", "\r").encode(), id="cr-alone"),  # was one 341-column line
        pytest.param(lambda t: b"\xef\xbb\xbf" + t.encode(), id="utf8-bom"),
        pytest.param(lambda t: t.encode("utf-16"), id="utf16-bom"),  # was "starts with HIERARCHY, not '\xff\xfeH\x00'"
        pytest.param(lambda t: t.replace("  ", "\t").replace(" 90 ", "\t90\t").encode(), id="tabs"),
    ],
)
def test_line_endings_byte_order_marks_and_tabs_read_as_the_same_capture(encode, tmp_path):
    want = X.read_bvh(str(_write(tmp_path / "base.bvh", BASE.encode())))
    path = _write(tmp_path / "other.bvh", encode(BASE))
    got = X.read_bvh(str(path))
    assert got.names == want.names and got.channels == want.channels
    np.testing.assert_array_equal(got.data, want.data)
    np.testing.assert_array_equal(got.offsets, want.offsets)
    done, out = _import(tmp_path, encode(BASE))
    assert done.returncode == 0 and out.exists(), done.stderr


def _write(path, raw: bytes):
    path.write_bytes(raw)
    return path


@pytest.mark.parametrize(
    ("text", "where", "words"),
    [
        (BASE.replace("Frames: 3", "Frames: 1000000"), "21:21", "after 3 of the 1000000 frames"),
        (BASE.replace("Frames: 3", "Frames: 2"), "21:1", "more frame lines than the 2"),
        (BASE.replace("0 90 0 10 0 0 5 0 0", "0 90 0 10 0 0 5 0"), "20:18", "8 values"),
        (BASE.replace("0 90 0 10 0 0 5 0 0", "0 90 0 10 0 0 5 0 0 7"), "20:21", "10 values"),
        (BASE.replace("CHANNELS 3 Zrotation", "CHANNELS 4 Zrotation"), "9:14", "CHANNELS says 4"),
        (BASE.replace("0 90 0 10", "0 90 0 nan"), "20:8", "not a finite number"),
        (BASE.replace("Frame Time: 0.0333333", "Frame Time: 0"), "18:7", "must be positive"),
    ],
)
def test_a_capture_that_lies_is_refused_at_its_line_and_nothing_is_written(text, where, words, tmp_path):
    for raw in (text.encode(), text.replace("\n", "\r\n").encode(), text.replace("\n", "\r").encode()):
        done, out = _import(tmp_path, raw)
        assert done.returncode == 1 and f"take.bvh:{where}: error:" in done.stderr and words in done.stderr, done.stderr
        assert "Traceback" not in done.stderr and not out.exists()
