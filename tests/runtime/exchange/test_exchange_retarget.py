"""Retargeting real captures onto the library HUMANOID: maps, alignment, size, held feet, bad input.

The captures are bvhtoolbox's and bvhtools' (tests/captures.py).  What the
retargeted motion does is measured by running a program that LOADs it and
the HUMANOID and collecting what ANIMATE draws (``exchange.collect``, the
angles and placements ``--poses`` records), with the runtime's own
kinematics, not the retargeting's.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from captures import capture
from PIL import Image

from liganimate.compiler import load_program
from liganimate.runtime import exchange as X
from liganimate.runtime.figure.kinematics import pose_transforms

PLAY = """\
      LOAD HUMANOID FROM 'humanoid'
      LOAD {motion} FROM '{lib}'
      INITIALIZE SCENE 1
        VIEW POINT = (4.0, 1.0, 3.0)
        VIEW WIDTH = 3.5
      STARTSCENE LENGTH {n}
        ANIMATE HUMANOID FROM 0 TO {last} USING {motion}
        HUMANOID :- HUMANOID <TRANS (0.0, 0.972, 0.0)>
      ENDSCENE
      SHOOTSCENES
"""


def _cli(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "liganimate", *args], capture_output=True, text=True, timeout=900, cwd=cwd
    )


def _retarget(tmp_path, name, *extra):
    out = tmp_path / f"{name}.lig"
    r = _cli("import", capture(name), "--onto", "humanoid", "-o", str(out), "--motion", "TAKE", *extra)
    assert r.returncode == 0, r.stderr
    return out, r.stderr


def _played(tmp_path, lib, n):
    """What ANIMATE draws of HUMANOID playing TAKE for frames 0..n-1: (figure, angles, placements)."""
    path = tmp_path / "play.lig"
    path.write_text(PLAY.format(motion="TAKE", lib=os.path.basename(lib), n=n, last=n - 1))
    take = X.collect(load_program(str(path))[0])[0].models[0]
    return take.figure, take.angles, take.placements


def _ankles(fig, angles, placements):
    """World positions of both ankles (the feet's joints), per tick: {"L": (T, 3), "R": (T, 3)}."""
    X_ = pose_transforms(fig, angles)
    out = {}
    for side, name in (("L", "L_FOOT"), ("R", "R_FOOT")):
        i = fig.links_named(name)[0]
        local = X_[:, i, :3, 3]  # the foot's joint is at its origin (its location on the foot is 0)
        out[side] = np.einsum("tij,tj->ti", placements[:, :3, :3], local) + placements[:, :3, 3]
    return out


@pytest.mark.parametrize(
    ("name", "frames", "profile"),
    [("mocapbank", 455, "CMU/mocapbank"), ("mixamo", 69, "Mixamo"), ("rigify", 600, "Rigify")],
)
def test_a_real_capture_retargets_onto_the_humanoid_and_its_planted_feet_hold(tmp_path, name, frames, profile):
    extra = ("--joint-translation", "drop", "--frames", f"0:{frames - 1}") if name == "rigify" else ()
    lib, report = _retarget(tmp_path, name, *extra)
    assert f"capture as {profile}, figure as liganimate humanoid" in report
    assert "-> L_THIGH" in report and "-> R_FOOT" in report
    # The Python API gives the contact frames it held; the program's own run must keep them still.
    clip = X.read_bvh(capture(name))
    if name == "rigify":
        clip = X.cut_frames(clip, 0, frames - 1)
    options = X.OntoOptions(library="humanoid", motion="TAKE", retarget=X.RetargetOptions(joint_translation="drop"))
    _, _, result = X.retarget_library(clip, options)
    fig, angles, placements = _played(tmp_path, lib, frames)
    ankles = _ankles(fig, angles, placements)
    held = 0
    for side, mask in result.planted.items():
        both = mask[1:] & mask[:-1]
        step = np.linalg.norm(np.diff(ankles[side], axis=0), axis=1)[both]
        held += int(both.sum())
        if len(step):
            assert step.max() <= 1e-3, (side, step.max())  # at most 1 mm a frame, HUMANOID being in metres
    assert held >= 10
    # The figure stands on its feet: the lowest ankle is at HUMANOID's ankle height over the floor, y = 0.
    lowest = min(a[:, 1].min() for a in ankles.values())
    assert 0.03 <= lowest <= 0.12, lowest


def test_the_root_path_is_the_capture_s_scaled_by_the_legs(tmp_path):
    clip = X.read_bvh(capture("mocapbank"))
    options = X.OntoOptions(library="humanoid", motion="TAKE")
    _, report, result = X.retarget_library(clip, options)
    # HUMANOID's leg (hip to ankle) is 0.9 m; the capture's is its own rest pose's.
    from liganimate.runtime.exchange._clip import clip_pose, rest_positions

    pose = clip_pose(clip)
    rest = rest_positions(clip.parents, pose.offsets)
    hip, knee, ankle = (clip.names.index(n) for n in ("LeftHip", "LeftKnee", "LeftAnkle"))
    leg = np.linalg.norm(rest[knee] - rest[hip]) + np.linalg.norm(rest[ankle] - rest[knee])
    assert result.scale == pytest.approx(0.9 / leg, rel=0.05)
    # Horizontal travel is the capture's, scaled (turned to face +X, and levelled by the rest pose's up
    # direction, a few degrees off the file's Y: so lengths, to 2% of the whole travel).
    src = result.scale * np.linalg.norm(pose.path[:, [0, 2]] - pose.path[0, [0, 2]], axis=1)
    got = np.linalg.norm(result.path[:, [0, 2]] - result.path[0, [0, 2]], axis=1)
    assert src.max() > 0.03
    assert np.abs(got - src).max() <= 0.02 * src.max()
    assert f"scale {result.scale:.6g}" in " ".join(report)


def _t_pose_capture(path, frames=3):
    """The Mixamo rig of bvhtoolbox at its rest pose, which is a T-pose, every frame."""
    text = open(capture("mixamo")).read()
    head = text.split("MOTION")[0]
    n = sum(int(line.split()[1]) for line in head.splitlines() if line.strip().startswith("CHANNELS"))
    rows = ["0 90 0" + " 0" * (n - 3)] * frames
    path.write_text(head + f"MOTION\nFrames: {frames}\nFrame Time: 0.04\n" + "\n".join(rows) + "\n")
    return str(path)


def test_a_t_pose_capture_holds_the_humanoid_s_arms_out(tmp_path):
    src = _t_pose_capture(tmp_path / "tpose.bvh")
    out = tmp_path / "tpose.lig"
    r = _cli("import", src, "--onto", "humanoid", "-o", str(out), "--motion", "TAKE")
    assert r.returncode == 0, r.stderr
    fig, angles, _ = _played(tmp_path, out, 3)
    X_ = pose_transforms(fig, angles)
    for upper, fore in (("L_UPPERARM", "L_FOREARM"), ("R_UPPERARM", "R_FOREARM")):
        a = X_[0, fig.links_named(upper)[0], :3, 3]
        b = X_[0, fig.links_named(fore)[0], :3, 3]
        d = (b - a) / np.linalg.norm(b - a)
        # HUMANOID's arms hang at rest; the T-pose lifts them sideways (along Z), level.
        assert abs(d[1]) < 0.05 and abs(d[2]) > 0.99, (upper, d)


def test_the_retargeted_capture_renders(tmp_path):
    lib, _ = _retarget(tmp_path, "mocapbank")
    play = tmp_path / "play.lig"
    play.write_text(PLAY.format(motion="TAKE", lib=lib.name, n=241, last=240))
    r = _cli("run", str(play), "-o", str(tmp_path / "frames"), "--size", "160x120")
    assert r.returncode == 0, r.stderr
    for tick in (0, 120, 240):
        img = np.asarray(Image.open(tmp_path / "frames" / "scene1" / f"{tick:05d}.png").convert("L"))
        assert (img < 200).sum() > 300, tick  # the figure is drawn, not an empty frame


def test_a_map_file_names_the_pairs_and_an_unknown_joint_is_refused_at_its_line(tmp_path):
    good = tmp_path / "good.map"
    good.write_text(
        "# mocapbank onto HUMANOID, legs only\n"
        "Hips = TOP\nLeftHip = L_THIGH\nLeftKnee = L_SHIN\nLeftAnkle = L_FOOT\n"
        "RightHip = R_THIGH\nRightKnee = R_SHIN\nRightAnkle = R_FOOT\n"
    )
    out = tmp_path / "legs.lig"
    r = _cli("import", capture("mocapbank"), "--onto", "humanoid", "--map", str(good), "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert "capture joints left out (12)" in r.stderr and "R_UPPERARM" in r.stderr
    bad = tmp_path / "bad.map"
    bad.write_text("Hips = TOP\nLeftHipp = L_THIGH\n")
    out2 = tmp_path / "bad.lig"
    r = _cli("import", capture("mocapbank"), "--onto", "humanoid", "--map", str(bad), "-o", str(out2))
    assert r.returncode == 1
    assert f"{bad}:2:1" in r.stderr and "no joint called LeftHipp" in r.stderr and "LeftHip?" in r.stderr
    assert "Traceback" not in r.stderr and not out2.exists()
    bad.write_text("Hips = TOP\nLeftHip = L_THIGHS\n")
    r = _cli("import", capture("mocapbank"), "--onto", "humanoid", "--map", str(bad), "-o", str(out2))
    assert r.returncode == 1 and f"{bad}:2:11" in r.stderr and "no link called L_THIGHS" in r.stderr
    assert not out2.exists()


NO_LEGS = """\
HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Chest
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
Frames: 2
Frame Time: 0.04
0 90 0 0 0 0 0 0 0
0 90 0 0 0 5 0 0 0
"""


def test_a_capture_without_legs_a_figure_without_feet_and_a_file_that_is_not_bvh_are_refused(tmp_path):
    out = tmp_path / "out.lig"
    (tmp_path / "nolegs.bvh").write_text(NO_LEGS)
    r = _cli("import", str(tmp_path / "nolegs.bvh"), "--onto", "humanoid", "-o", str(out))
    assert r.returncode == 1 and "capture has no legs" in r.stderr and "--map" in r.stderr
    r = _cli("import", capture("mocapbank"), "--onto", "arm", "-o", str(out))
    assert r.returncode == 1 and "figure has no legs" in r.stderr
    (tmp_path / "photo.bvh").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)))
    r = _cli("import", str(tmp_path / "photo.bvh"), "--onto", "humanoid", "-o", str(out))
    assert r.returncode == 1 and "photo.bvh:1:1" in r.stderr and "HIERARCHY" in r.stderr
    assert "Traceback" not in r.stderr and not out.exists()


def test_sliding_joints_are_refused_with_a_hint_or_dropped_with_a_note(tmp_path):
    out = tmp_path / "rigify.lig"
    r = _cli("import", capture("rigify"), "-o", str(out), "--frames", "0:99")
    assert r.returncode == 1 and "--joint-translation drop" in r.stderr and not out.exists()
    assert "moves along its Yposition channel" in r.stderr or "moves along its" in r.stderr
    r = _cli("import", capture("rigify"), "-o", str(out), "--frames", "0:99", "--joint-translation", "drop")
    assert r.returncode == 0, r.stderr
    assert "note: dropped 47 position channels of 17 joints" in r.stderr
    assert "note: dropped the sliding of 2 joints" in r.stderr and "100 frames" in r.stderr


def test_frames_and_fps_cut_and_resample(tmp_path):
    clip = X.read_bvh(capture("mocapbank"))
    cut = X.cut_frames(clip, 10, 19)
    assert np.array_equal(cut.data, clip.data[10:20])
    fast = X.resample(cut, 2.0 / clip.frame_time)
    assert fast.data.shape[0] == 19
    assert np.allclose(fast.data[::2], cut.data, atol=1e-6)
    # A midpoint of a joint's rotation is its rotation halfway, whatever the channel order.
    from liganimate.runtime.exchange._rotations import matrix_from_axes, quaternion_from_matrix

    j = clip.names.index("LeftKnee")
    cols = list(clip.first[j] + np.arange(3))
    q0, q1, qm = (
        quaternion_from_matrix(matrix_from_axes("ZXY", d[cols])) for d in (cut.data[3], cut.data[4], fast.data[7])
    )
    mid = (q0 + q1 * np.sign(q0 @ q1)) / np.linalg.norm(q0 + q1 * np.sign(q0 @ q1))
    assert min(np.abs(qm - mid).max(), np.abs(qm + mid).max()) < 1e-9
    out = tmp_path / "c.lig"
    r = _cli("import", capture("mocapbank"), "-o", str(out), "--frames", "100:", "--fps", "60")
    assert r.returncode == 0, r.stderr
    # 355 frames of 0.033333 s last 11.79988 s: 708 frames at 60 per second (the file's rate is not quite 30).
    assert "(19 joints, 708 frames)" in r.stderr
    r = _cli("import", capture("mocapbank"), "-o", str(out), "--frames", "500:600")
    assert r.returncode == 1 and "outside the capture's frames 0 to 454" in r.stderr
