"""Captures whose actor turns, retargeted and played: the figure turns with the actor (ROOT ORIENTATION).

The captures are bvhtoolbox's and bvhtools' (tests/captures.py): the Mixamo
take turns its actor about 180 degrees on the spot, bvhtools' long take
about four times round.  The capture's heading is measured here from the
BVH's own numbers (the hips' world rotation, applied to a horizontal
direction of the hips), independently of the retargeting; what the figure
does is measured from what ANIMATE draws (``exchange.collect``, the
placements ``--poses`` records) or from the exports, with glTF read back by
pygltflib.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from captures import capture
from PIL import Image

from liganimate.compiler import load_program
from liganimate.runtime import exchange as X
from liganimate.runtime.exchange._clip import clip_pose
from liganimate.runtime.figure.kinematics import matrix_from_euler_zyx, pose_transforms

PLAY = """\
      LOAD HUMANOID FROM 'humanoid'
      LOAD TAKE FROM '{lib}'
      INITIALIZE SCENE 1
        VIEW POINT = (0.0, 6.0, 0.5)
        VIEW WIDTH = 2.5
      STARTSCENE LENGTH {n}
        ANIMATE HUMANOID FROM 0 TO {last} USING TAKE
        HUMANOID :- HUMANOID <TRANS (0.0, 0.972, 0.0)>
      ENDSCENE
      SHOOTSCENES
"""


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "liganimate", *args], capture_output=True, text=True, timeout=900)


def capture_heading(clip) -> np.ndarray:
    """Degrees the capture's hips head about the file's Y, unwrapped, per frame (from the BVH's rotations alone)."""
    pose = clip_pose(clip, "drop")
    root = int(np.flatnonzero(clip.parents < 0)[0])
    Q = matrix_from_euler_zyx(pose.angles[:, root])
    # The hips' local axis that stays most horizontal: its heading is the actor's.
    axis = int(np.argmin([np.abs(Q[:, 1, a]).mean() for a in range(3)]))
    v = Q[:, :, axis]
    return np.degrees(np.unwrap(np.arctan2(v[:, 0], v[:, 2])))


def _yaw(R: np.ndarray) -> np.ndarray:
    """Degrees about Y that rotations (T, 3, 3) turn +X by, unwrapped."""
    return np.degrees(np.unwrap(np.arctan2(-R[:, 2, 0], R[:, 0, 0])))


@pytest.mark.parametrize(("name", "frames"), [("mixamo", 69), ("long", 7184)])
def test_the_turning_takes_end_facing_as_the_actor_does(name, frames):
    clip = X.read_bvh(capture(name))
    options = X.OntoOptions(library="humanoid", motion="TAKE", retarget=X.RetargetOptions(joint_translation="drop"))
    _, report, result = X.retarget_library(clip, options)
    want = capture_heading(clip)
    got = result.orientation[:, 1]
    assert len(got) == frames
    turned = want[-1] - want[0]
    assert abs(turned) > 170.0  # these actors do turn (180 degrees, and four times round)
    assert abs((got[-1] - got[0]) - turned) < 3.0, (got[-1] - got[0], turned)
    # Frame by frame the figure heads as the actor does, up to a constant (the figure's own facing).
    assert np.abs((got - got[0]) - (want - want[0])).max() < 5.0
    # The main link only turns about up: the tilt is the joints' below, as the hips' rest is.
    assert np.abs(result.orientation[:, [0, 2]]).max() < 1e-6
    assert not any("cannot turn" in line for line in report)


def test_a_turning_capture_plays_turned_and_its_planted_feet_hold(tmp_path):
    lib = tmp_path / "mixamo.lig"
    r = _cli("import", capture("mixamo"), "--onto", "humanoid", "-o", str(lib), "--motion", "TAKE")
    assert r.returncode == 0, r.stderr
    assert "ROOT ORIENTATION" in lib.read_text()
    play = tmp_path / "play.lig"
    play.write_text(PLAY.format(lib=lib.name, n=69, last=68))
    take = X.collect(load_program(str(play))[0])[0].models[0]
    fig, angles, placements = take.figure, take.angles, take.placements
    want = capture_heading(X.read_bvh(capture("mixamo")))
    played = _yaw(placements[:, :3, :3])
    assert abs((played[-1] - played[0]) - (want[-1] - want[0])) < 3.0
    # The shoulders, as drawn, swing round with the heading: the line from the left shoulder to the right.
    X_ = pose_transforms(fig, angles)
    world = np.einsum("tij,tnjk->tnik", placements, X_)
    left, right = (world[:, fig.links_named(n)[0], :3, 3] for n in ("L_UPPERARM", "R_UPPERARM"))
    across = right - left
    shoulders = np.degrees(np.unwrap(np.arctan2(-across[:, 2], across[:, 0])))
    assert abs((shoulders[-1] - shoulders[0]) - (want[-1] - want[0])) < 20.0
    # Planted feet hold while the figure turns: at most 1 mm a frame.
    clip = X.read_bvh(capture("mixamo"))
    _, _, result = X.retarget_library(clip, X.OntoOptions(library="humanoid", motion="TAKE"))
    held = 0
    for side, mask in result.planted.items():
        i = fig.links_named(f"{side}_FOOT")[0]
        ankle = world[:, i, :3, 3]
        both = mask[1:] & mask[:-1]
        step = np.linalg.norm(np.diff(ankle, axis=0), axis=1)[both]
        held += int(both.sum())
        if len(step):
            assert step.max() <= 1e-3, (side, step.max())
    assert held >= 10


def test_the_turn_shows_in_the_rendered_frames(tmp_path):
    """Seen from above, the figure's outline at the last frame is the first one's turned half round."""
    lib = tmp_path / "mixamo.lig"
    assert _cli("import", capture("mixamo"), "--onto", "humanoid", "-o", str(lib), "--motion", "TAKE").returncode == 0
    play = tmp_path / "play.lig"
    play.write_text(PLAY.format(lib=lib.name, n=69, last=68))
    r = _cli("run", str(play), "-o", str(tmp_path / "frames"), "--size", "200x200", "--look", "thesis")
    assert r.returncode == 0, r.stderr

    def outline(tick):
        img = np.asarray(Image.open(tmp_path / "frames" / "scene1" / f"{tick:05d}.png").convert("L"))
        ys, xs = np.nonzero(img < 200)
        assert len(xs) > 200, tick
        return xs - xs.mean(), ys - ys.mean()

    def facing(xs, ys):
        # Seen from above, the feet point forward: the drawn mass lies more to the front of the centre.
        return np.array([np.mean(xs**3), np.mean(ys**3)])

    first, last = facing(*outline(0)), facing(*outline(68))
    cos = first @ last / (np.linalg.norm(first) * np.linalg.norm(last))
    assert cos < -0.5, cos  # about half round


def test_exports_carry_the_turn(tmp_path):
    """glTF: a rotation channel on the model's node; BVH: the ROOT's rotation channels."""
    lib = tmp_path / "mixamo.lig"
    assert _cli("import", capture("mixamo"), "--onto", "humanoid", "-o", str(lib), "--motion", "TAKE").returncode == 0
    play = tmp_path / "play.lig"
    play.write_text(PLAY.format(lib=lib.name, n=69, last=68))
    want = capture_heading(X.read_bvh(capture("mixamo")))
    glb = tmp_path / "take.glb"
    r = _cli("export", str(play), "-o", str(glb), "--rig", "nodes")
    assert r.returncode == 0, r.stderr
    import pygltflib

    doc = pygltflib.GLTF2().load(str(glb))
    model = next(i for i, n in enumerate(doc.nodes) if n.name and n.name.startswith("HUMANOID"))
    channel = next(
        c for a in doc.animations for c in a.channels if c.target.node == model and c.target.path == "rotation"
    )
    sampler = doc.animations[0].samplers[channel.sampler]
    acc = doc.accessors[sampler.output]
    view = doc.bufferViews[acc.bufferView]
    blob = doc.binary_blob()
    q = np.frombuffer(blob, dtype=np.float32, count=acc.count * 4, offset=view.byteOffset + (acc.byteOffset or 0))
    q = q.reshape(-1, 4).astype(float)  # x, y, z, w
    yaw = np.degrees(np.unwrap(2 * np.arctan2(q[:, 1], q[:, 3])))
    assert abs((yaw[-1] - yaw[0]) - (want[-1] - want[0])) < 3.0
    bvh = tmp_path / "take.bvh"
    r = _cli("export", str(play), "-o", str(bvh))
    assert r.returncode == 0, r.stderr
    back = X.read_bvh(str(bvh))
    assert abs((capture_heading(back)[-1] - capture_heading(back)[0]) - (want[-1] - want[0])) < 3.0


def test_poses_record_the_turned_placement(tmp_path):
    lig = tmp_path / "turn.lig"
    lig.write_text(
        "      LOAD HUMANOID, WALK FROM 'humanoid'\n"
        "      MOTION TURN\n"
        "      STARTMOTION TURN\n"
        "        ROOT ORIENTATION\n"
        "          FRAME 12 POSITION 0.0, 90.0, 0.0\n"
        "      ENDMOTION\n"
        "      INITIALIZE SCENE 1\n"
        "      STARTSCENE LENGTH 13\n"
        "        ANIMATE HUMANOID FROM 0 TO 12 USING TURN\n"
        "      ENDSCENE\n"
        "      SHOOTSCENES\n"
        "      END\n"
    )
    poses = tmp_path / "poses.jsonl"
    r = _cli("run", str(lig), "-o", str(tmp_path / "f"), "--size", "80x60", "--poses", str(poses), "--quiet")
    assert r.returncode == 0, r.stderr
    records = [json.loads(line) for line in poses.read_text().splitlines() if line.strip()]
    last = records[-1]
    assert last["tick"] == 12
    main = next(seg for seg in last["segments"] if seg["joint"] is None)
    matrix = np.array(main["matrix"], dtype=float).reshape(4, 4)
    # The main link is turned 90 degrees about Y: +X onto -Z.
    d = matrix[:3, :3] @ [1.0, 0.0, 0.0]
    np.testing.assert_allclose(d / np.linalg.norm(d), [0, 0, -1], atol=1e-9)
    first = next(seg for seg in records[0]["segments"] if seg["joint"] is None)
    d0 = np.array(first["matrix"], dtype=float).reshape(4, 4)[:3, :3] @ [1.0, 0.0, 0.0]
    np.testing.assert_allclose(d0 / np.linalg.norm(d0), [1, 0, 0], atol=1e-9)


def test_a_plain_import_gives_the_actor_s_turn_to_the_root_orientation(tmp_path):
    """Without --onto the capture's own skeleton turns by ROOT ORIENTATION; the joints are where they were."""
    lib = tmp_path / "cap.lig"
    r = _cli("import", capture("mixamo"), "-o", str(lib), "--model", "FIG", "--motion", "TAKE")
    assert r.returncode == 0, r.stderr
    assert "ROOT ORIENTATION" in lib.read_text()
    program = (
        f"      LOAD FIG, TAKE FROM '{lib.name}'\n"
        "      MOTION TWICE\n"
        "      TWICE = TAKE + TAKE\n"
        "      INITIALIZE SCENE 1\n"
        "      STARTSCENE LENGTH 69\n"
        "        ANIMATE FIG FROM 0 TO 68 USING TAKE\n"
        "      ENDSCENE\n"
        "      SHOOTSCENES\n"
        "      END\n"
    )
    play = tmp_path / "play.lig"
    play.write_text(program)
    compiled = load_program(str(play))[0]
    take = X.collect(compiled)[0].models[0]
    clip = X.read_bvh(capture("mixamo"))
    want = capture_heading(clip)
    played = _yaw(take.placements[:, :3, :3])
    assert abs((played[-1] - played[0]) - (want[-1] - want[0])) < 1.0
    # The joints are where the file has them: world positions from the BVH's own numbers.
    from liganimate.runtime.exchange._retarget import _Source

    src = _Source(clip, "drop")
    X_ = pose_transforms(take.figure, take.angles)
    world = np.einsum("tij,tnjk->tnik", take.placements, X_)[:, :, :3, 3]
    compared = 0
    for j, name in enumerate(clip.names):
        links = take.figure.links_named(name.replace(":", "_").upper())
        if links:
            # A link's origin is its BVH joint's position (the importer's segments start at their joint).
            np.testing.assert_allclose(world[:, links[0]], src.P[:, j], atol=1e-6 * 200)
            compared += 1
    assert compared >= 20
    # TAKE + TAKE: the second copy starts facing where the first ended.
    twice = compiled.execute("check").variables["TWICE"]
    assert twice.length == 136.0  # 69 frames are 68 frames long
    h = twice.root_orientation([0.0, 68.0, 136.0])[:, 1]
    assert h[1] - h[0] == pytest.approx(want[-1] - want[0], abs=1.0)
    assert h[2] - h[0] == pytest.approx(2 * (want[-1] - want[0]), abs=2.0)


def test_the_viewer_s_matrices_show_the_turn(tmp_path):
    """The browser viewer draws from the scene manifest's matrices: its main link turns as ANIMATE draws it."""
    from liganimate.runtime.view._scene_data import Blob, scene_manifest

    program = (
        "      LOAD HUMANOID FROM 'humanoid'\n"
        "      MOTION TURN\n"
        "      STARTMOTION TURN\n"
        "        ROOT ORIENTATION\n"
        "          FRAME 12 POSITION 0.0, 90.0, 0.0\n"
        "      ENDMOTION\n"
        "      INITIALIZE SCENE 1\n"
        "      STARTSCENE LENGTH 13\n"
        "        ANIMATE HUMANOID FROM 0 TO 12 USING TURN\n"
        "      ENDSCENE\n"
        "      SHOOTSCENES\n"
        "      END\n"
    )
    scenes = X.collect(load_program(text=program, name="t.lig")[0])
    blob = Blob()
    model = scene_manifest(scenes, blob)[0]["models"][0]
    ref = model["matrices"]
    data = np.frombuffer(blob.tobytes(), dtype=np.float32, count=ref["n"], offset=ref["o"]).reshape(13, -1, 3, 4)
    main = scenes[0].models[0].figure.main
    first, last = data[0, main, :, :3] @ [1.0, 0.0, 0.0], data[-1, main, :, :3] @ [1.0, 0.0, 0.0]
    np.testing.assert_allclose(first / np.linalg.norm(first), [1, 0, 0], atol=1e-6)
    np.testing.assert_allclose(last / np.linalg.norm(last), [0, 0, -1], atol=1e-6)
