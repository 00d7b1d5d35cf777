"""A motion's ROOT track: drawn, recorded by --poses, and written by glTF and BVH export."""

from __future__ import annotations

import numpy as np
from exchange_support import load_gltf, pose_records, sample_channels, segment_nodes, world_transforms

from liganimate.compiler import load_program
from liganimate.runtime import exchange as X

FPS = 24.0

# A two-link stick whose motion walks 2 units along its own +X every 8 frames,
# repeated, placed turned by <ROT Y 90>: it travels along the world's -Z.
TRAVEL = """\
      MODEL STICK
      GRAPHICAL A, B
      A :- BOX WIDTH 1.0, HEIGHT 0.2, DEPTH 0.2
      B :- BOX AT (0.5, 0.0, 0.0), WIDTH 1.0, HEIGHT 0.1, DEPTH 0.1
      STARTMODEL STICK
        JOINT 1, A, (0.5, 0.0, 0.0), B, (0.0, 0.0, 0.0), (-90.0, 90.0), (-90.0, 90.0), (-90.0, 90.0)
      ENDMODEL
      STARTMOTION GO
        JOINT 1 POSITION 0.0, 0.0, 0.0
          FRAME 4 POSITION 0.0, 0.0, 30.0
          FRAME 8 POSITION 0.0, 0.0, 0.0
        ROOT POSITION 0.0, 0.0, 0.0
          FRAME 4 POSITION 1.0, 0.25, 0.0
          FRAME 8 POSITION 2.0, 0.0, 0.0
      ENDMOTION
      INITIALIZE SCENE 1
        VIEW POINT = (0.0, 2.0, 10.0)
      STARTSCENE LENGTH 20
        ANIMATE STICK FROM 0 TO 19 USING GO REPEAT
        STICK :- STICK <ROT Y 90.0> <TRANS (1.0, 0.0, 0.0)>
      ENDSCENE
      SHOOTSCENES
"""


def _program(tmp_path):
    path = tmp_path / "travel.lig"
    path.write_text(TRAVEL)
    return load_program(str(path))[0]


def _expected_path(program) -> np.ndarray:
    """Where the main link's origin should be at ticks 0..19: placement @ Trans(root(t))."""
    go = program.execute("check").variables["GO"]
    offset = (3 * go).root_offset(np.arange(20.0))
    turned = offset @ np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # ROT Y 90 on row vectors
    return turned + np.array([1.0, 0.0, 0.0])


def test_animate_carries_the_figure_along_its_root_track_in_the_model_frame(tmp_path):
    program = _program(tmp_path)
    want = _expected_path(program)
    records = pose_records(program, tmp_path)
    got = np.array([np.array(r["segments"][0]["matrix"]).reshape(4, 4)[:3, 3] for r in records])
    np.testing.assert_allclose(got, want, atol=1e-6)
    # Three copies walk on: 2 units a cycle, along the turned axis (world -Z).
    np.testing.assert_allclose(got[16] - got[0], [0.0, 0.0, -4.0], atol=1e-6)


def test_gltf_export_writes_the_path(tmp_path):
    program = _program(tmp_path)
    want = _expected_path(program)
    path = str(tmp_path / "travel.gltf")
    scenes = X.collect(program)
    data, _ = X.gltf_bytes(scenes, False, fps=FPS, rig="nodes")
    with open(path, "wb") as fh:
        fh.write(data)
    doc, blob = load_gltf(path)
    anim = doc.animations[0]
    node = segment_nodes(doc)[(1, "STICK", 0)]
    for tick in (0, 5, 12, 19):
        worlds = world_transforms(doc, 0, sample_channels(doc, blob, anim, tick / FPS))
        np.testing.assert_allclose(worlds[node][:3, 3], want[tick], atol=1e-5)


def test_bvh_export_writes_the_path_in_the_root_position_channels(tmp_path):
    program = _program(tmp_path)
    want = _expected_path(program)
    files = X.bvh_files(X.collect(program), str(tmp_path / "travel.bvh"), fps=FPS)
    text = files[0][1] if isinstance(files[0][1], str) else files[0][1].decode()
    rows = text.split("Frame Time:")[1].splitlines()[1:]
    positions = np.array([[float(v) for v in r.split()[:3]] for r in rows if r.strip()])
    np.testing.assert_allclose(positions, want, atol=1e-6)
