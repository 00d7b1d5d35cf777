"""Names survive: real captures imported and exported give back their hierarchy, names and channel order.

The captures are the BVH files of bvhtoolbox and bvhtools (tests/captures.py);
positions are compared with bvhio's reading of both files, not ours.
"""

from __future__ import annotations

import re
import subprocess
import sys

import numpy as np
import pytest
from captures import capture

from liganimate.lang.name_table import format_table, read_tables

pytestmark = pytest.mark.filterwarnings("ignore:Importing PyGLM:PendingDeprecationWarning")

PLAY = """\
      LOAD FIG, MOT FROM '{lib}'
      INITIALIZE SCENE 1
      STARTSCENE LENGTH {n}
        ANIMATE FIG FROM 0 TO {last} USING MOT
      ENDSCENE
      SHOOTSCENES
"""


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "liganimate", *args], capture_output=True, text=True, timeout=600)


def _hierarchy(text: str):
    head = text.split("MOTION")[0]
    joints = [(m.group(1), m.group(2).strip()) for m in re.finditer(r"(ROOT|JOINT)\s+(.+)", head)]
    channels = [c.split() for c in re.findall(r"CHANNELS\s+\d+\s+(.*)", head)]
    ends = [tuple(float(x) for x in m.split()) for m in re.findall(r"End Site\s*\{\s*OFFSET\s+([^\n]*)", head)]
    return joints, channels, ends


@pytest.mark.parametrize("name", ["mocapbank", "mixamo", "rigify"])
def test_import_then_export_gives_back_the_hierarchy_names_and_channels(tmp_path, name):
    import bvhio

    src = capture(name)
    lib = tmp_path / "cap.lig"
    r = _cli("import", src, "-o", str(lib), "--model", "FIG", "--motion", "MOT", "--joint-translation", "drop")
    assert r.returncode == 0, r.stderr
    n = 20
    (tmp_path / "play.lig").write_text(PLAY.format(lib="cap.lig", n=n, last=n - 1))
    out = tmp_path / "back.bvh"
    r = _cli("export", str(tmp_path / "play.lig"), "-o", str(out))
    assert r.returncode == 0, r.stderr
    original, back = open(src).read(), out.read_text()
    a, b = _hierarchy(original), _hierarchy(back)
    assert a[0] == b[0]  # ROOT/JOINT and every name, in order: no ORIGIN added
    assert a[1] == b[1]  # channel order
    assert np.allclose(a[2], b[2], atol=1e-6)  # End Sites
    assert "ORIGIN" not in back
    # Every joint where the capture has it (bvhio reads both files), except what --joint-translation drop dropped.
    A, B = bvhio.readAsHierarchy(src), bvhio.readAsHierarchy(str(out))
    ja, jb = A.layout(), B.layout()
    A.loadPose(0)
    size = float(np.ptp(np.array([j[0].PositionWorld for j in ja]), axis=0).max())
    worst = 0.0
    for frame in (0, 7, n - 1):
        A.loadPose(frame)
        B.loadPose(frame)
        pa = np.array([j[0].PositionWorld for j in ja])
        pb = np.array([j[0].PositionWorld for j in jb])
        worst = max(worst, float(np.abs(pa - pb).max()))
    # The Rigify thighs slide 2 cm in the capture; dropped, the legs below them move by up to that.
    assert worst <= (0.03 * size if name == "rigify" else 1e-6 * size), worst


def test_the_name_table_reads_back_what_it_writes():
    rows = [
        ("MIXAMORIG_HIPS", "mixamorig:Hips", ("Xposition", "Yposition", "Zposition", "Zrotation"), None),
        ("ODD", 'a "quoted" {braced} name é', (), (1.5, -2.0, 0.0)),
    ]
    text = "C a library\n" + format_table("FIG", rows) + "      MODEL FIG\n"
    assert read_tables(text) == {"FIG": {seg: (name, ch, end) for seg, name, ch, end in rows}}
    # It is one brace comment: no brace inside it ends it early.
    assert text.count("}") == 1


def test_a_description_is_not_a_name_table():
    assert read_tables("{@ FIG: a description }\n      MODEL FIG\n") == {}
