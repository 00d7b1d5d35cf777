"""BVH: export, import, the round trip, a file written by another implementation (bvhio), bad input."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from exchange_support import pose_records
from paths import ROOT_DIR
from scipy.optimize import linear_sum_assignment
from scipy.spatial.transform import Rotation

from liganimate.compiler import load_program
from liganimate.runtime import exchange as X

# bvhio imports PyGLM under its old name; not ours to fix.
pytestmark = pytest.mark.filterwarnings("ignore:Importing PyGLM:PendingDeprecationWarning")

WALK = """\
      LOAD HUMANOID, WALK FROM 'humanoid'
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 25
        ANIMATE HUMANOID FROM 0 TO 24 USING WALK
      ENDSCENE
      SHOOTSCENES
"""

# The standard humanoid re-rooted at its right foot and moved and turned
# every tick: reversed joints, and a root that travels and turns.
REROOTED = """\
      LOAD HUMANOID, SQUAT FROM 'humanoid'
      VECTOR P
      FIGURE HUMANOID MAIN LINK R_FOOT
      INITIALIZE SCENE 1
        P = (0.0, 0.0, 0.0)
      STARTSCENE LENGTH 20
        ANIMATE HUMANOID FROM 0 TO 19 USING SQUAT
        HUMANOID :- HUMANOID <ROT Y 30.0> <TRANS (P)>
        P = P + (0.02, 0.0, 0.01)
      ENDSCENE
      SHOOTSCENES
"""


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "liganimate", *args], check=False, capture_output=True, text=True)


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def _player(tmp_path, lib, model, motion, frames):
    """A program that LOADs an imported library and plays its motion once, one tick per frame."""
    return _write(
        tmp_path,
        "play.lig",
        f"""\
      LOAD {model}, {motion} FROM '{os.path.basename(lib)}'
      INITIALIZE SCENE 1
      STARTSCENE LENGTH {frames}
        ANIMATE {model} FROM 0 TO {frames - 1} USING {motion}
      ENDSCENE
      SHOOTSCENES
""",
    )


def _bvh_joint_names(text: str) -> list:
    return re.findall(r"^\s*(?:ROOT|JOINT)\s+(\S+)", text, flags=re.MULTILINE)


def test_round_trip_gives_the_same_angles(tmp_path):
    src = _write(tmp_path, "walk.lig", WALK)
    bvh = str(tmp_path / "walk.bvh")
    assert _cli("export", src, "-o", bvh).returncode == 0
    lib = str(tmp_path / "walk_lib.lig")
    r = _cli("import", bvh, "-o", lib, "--model", "BACK", "--motion", "AGAIN")
    assert r.returncode == 0, r.stderr
    original = X.collect(load_program(src)[0])[0].models[0]
    again = X.collect(load_program(_player(tmp_path, lib, "BACK", "AGAIN", 25))[0])[0].models[0]
    names = _bvh_joint_names((tmp_path / "walk.bvh").read_text())
    assert len(names) == original.figure.n_joints + 1  # the root (main link) and one per joint
    fig = original.figure
    compared = 0
    for n, name in enumerate(names[1:], start=2):
        # The humanoid's link names are unique, so each BVH joint is named after its link.
        link = next(i for i, l in enumerate(fig.links) if l.name == name)
        k = fig.joint_index(fig.parent_joint_of(link).id)
        a = original.angles[:, k]
        b = again.angles[:, again.figure.joint_index(n)]
        diff = (a - b + 180.0) % 360.0 - 180.0
        assert np.abs(diff).max() <= 1e-6, name
        compared += 1
    assert compared == 19
    # The root joint carries the placement's rotation: none here.
    assert np.abs(again.angles[:, again.figure.joint_index(1)]).max() <= 1e-6


def test_round_trip_of_a_rerooted_travelling_figure_keeps_every_joint_in_place(tmp_path):
    src = _write(tmp_path, "squat.lig", REROOTED)
    bvh = str(tmp_path / "squat.bvh")
    assert _cli("export", src, "-o", bvh).returncode == 0
    text = (tmp_path / "squat.bvh").read_text()
    assert "CHANNELS 3 Xrotation Yrotation Zrotation" in text  # joints walked backwards
    lib = str(tmp_path / "squat_lib.lig")
    assert _cli("import", bvh, "-o", lib, "--model", "BACK", "--motion", "AGAIN").returncode == 0
    program = load_program(src)[0]
    original = pose_records(program, tmp_path / "a")
    again = pose_records(load_program(_player(tmp_path, lib, "BACK", "AGAIN", 20))[0], tmp_path / "b")
    path = X.read_root_path(lib)
    take = X.collect(program)[0].models[0]
    fig = take.figure
    for t, (ra, rb) in enumerate(zip(original, again)):
        seg = {s["joint"]: np.array(s["matrix"]).reshape(4, 4) for s in ra["segments"]}
        # Every joint of the original, in the world, from its secondary's side.
        expected = np.array(
            [seg[j.id][:3, :3] @ (j.loc2 / fig.links[j.secondary].scale) + seg[j.id][:3, 3] for j in fig.joints]
        )
        # The imported figure: each BVH joint's segment has its origin at the joint; ANIMATE
        # carries the figure along the ROOT track, so the path is in the poses already.
        got = np.array(
            [np.array(s["matrix"]).reshape(4, 4)[:3, 3] for s in rb["segments"] if s["joint"] not in (None, 1)]
        )
        assert len(got) == len(expected)
        # Each original joint is met by its own imported joint (some of the humanoid's joints coincide,
        # so they are paired by the assignment that moves them least).
        d = np.linalg.norm(expected[:, None, :] - got[None, :, :], axis=2)
        rows, cols = linear_sum_assignment(d)
        assert d[rows, cols].max() <= 1e-6 * 1.78, (t, d[rows, cols].max())
        # The root (the main link R_FOOT) is where the placement puts it, the imported ROOT track's value.
        root = np.array(rb["segments"][1]["matrix"]).reshape(4, 4)[:3, 3]
        np.testing.assert_allclose(root, seg[33][:3, 3], atol=1e-6)
        np.testing.assert_allclose(root, path[t], atol=1e-6)
    assert np.linalg.norm(path[-1] - path[0]) > 0.3  # the figure travels: the test sees the path


# -- a file written by another implementation ----------------------------------------


def _bvhio_file(path, frames=30, seed=7):
    """A 23-joint skeleton with End Sites, ZXY and other orders and a travelling root, written by bvhio."""
    import bvhio
    import glm
    from SpatialTransform import Pose

    rng = np.random.default_rng(seed)
    spec = [  # name, parent, offset, channels
        ("Hips", None, (0, 0, 0)),
        ("Spine", "Hips", (0, 10, 0)),
        ("Spine1", "Spine", (0, 12, 1)),
        ("Neck", "Spine1", (0, 15, 0)),
        ("Head", "Neck", (0, 8, 2)),
    ]
    for side, s in (("L", 1), ("R", -1)):
        spec += [
            (f"{side}Shoulder", "Spine1", (s * 4, 12, 0)),
            (f"{side}Arm", f"{side}Shoulder", (s * 12, 0, 0)),
            (f"{side}ForeArm", f"{side}Arm", (s * 26, 0, 0)),
            (f"{side}Hand", f"{side}ForeArm", (s * 24, 0, 1)),
            (f"{side}Finger", f"{side}Hand", (s * 8, 0, 0)),
            (f"{side}UpLeg", "Hips", (s * 9, -3, 0)),
            (f"{side}Leg", f"{side}UpLeg", (0, -42, 1)),
            (f"{side}Foot", f"{side}Leg", (0, -40, -2)),
            (f"{side}Toe", f"{side}Foot", (0, -4, 12)),
        ]
    orders = {"LArm": "XYZ", "RLeg": "YXZ", "Neck": "YZX"}
    joints = {}
    t = np.linspace(0, 1, frames)
    for n, (name, parent, off) in enumerate(spec):
        j = bvhio.BvhJoint(name, glm.vec3(*off))
        order = orders.get(name, "ZXY")
        j.Channels = ([f"{a}position" for a in "XYZ"] if parent is None else []) + [f"{a}rotation" for a in order]
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        amp = rng.uniform(20, 70)
        phase = rng.uniform(0, 6)
        for k in range(frames):
            rot = Rotation.from_rotvec(axis * np.radians(amp * np.sin(6 * t[k] + phase))).as_quat()  # x, y, z, w
            pos = glm.vec3(30.0 * t[k], 90.0 + 3 * np.sin(9 * t[k]), -10.0 * t[k]) if parent is None else glm.vec3(off)
            j.Keyframes.append(Pose(pos, glm.quat(rot[3], rot[0], rot[1], rot[2])))
        j.EndSite = glm.vec3(0.0, 5.0, 1.0)
        joints[name] = j
        if parent is not None:
            joints[parent].Children.append(j)
    bvhio.writeBvh(str(path), bvhio.BvhContainer(joints["Hips"], frames, 1 / 30), percision=9)
    return len(spec)


def _reference_positions(text: str):
    """World joint positions per frame of a BVH text, by the standard reading, with scipy's rotations."""
    lines = text.splitlines()
    names, parents, offsets, channels, stack = [], [], [], [], []
    i = 0
    while lines[i].strip() != "MOTION":
        tok = lines[i].split()
        if tok and tok[0] in ("ROOT", "JOINT"):
            names.append(tok[1])
            parents.append(stack[-1] if stack else -1)
        elif tok and tok[0] == "End":
            stack.append(None)  # the End Site's own braces
        elif tok and tok[0] == "{" and names and (not stack or stack[-1] != len(names) - 1):
            if stack and stack[-1] is None and len(stack) and lines[i - 1].split()[0] == "End":
                pass
            else:
                stack.append(len(names) - 1)
        elif tok and tok[0] == "}":
            stack.pop()
        elif tok and tok[0] == "OFFSET" and (not stack or stack[-1] is not None):
            offsets.append([float(v) for v in tok[1:4]])
        elif tok and tok[0] == "CHANNELS":
            channels.append(tok[2:])
        i += 1
    frames = np.array([[float(v) for v in l.split()] for l in lines[i + 3 :] if l.strip()])
    J = len(names)
    world = np.zeros((len(frames), J, 4, 4))
    col = 0
    for j in range(J):
        chans = channels[j]
        vals = frames[:, col : col + len(chans)]
        col += len(chans)
        pos = np.tile(np.array(offsets[j]), (len(frames), 1))
        rot_axes = "".join(c[0] for c in chans if c.endswith("rotation"))
        rot_vals = np.stack([vals[:, n] for n, c in enumerate(chans) if c.endswith("rotation")], axis=1)
        for n, c in enumerate(chans):
            if c.endswith("position"):
                pos[:, "XYZ".index(c[0])] = vals[:, n]
        local = np.zeros((len(frames), 4, 4))
        local[:, :3, :3] = Rotation.from_euler(rot_axes, rot_vals, degrees=True).as_matrix()
        local[:, :3, 3] = pos
        local[:, 3, 3] = 1.0
        world[:, j] = local if parents[j] < 0 else world[:, parents[j]] @ local
    return names, world[:, :, :3, 3], np.array(offsets)


def test_import_of_a_bvhio_file_puts_every_joint_where_the_capture_has_it(tmp_path):
    bvh = tmp_path / "capture.bvh"
    n_joints = _bvhio_file(bvh)
    assert n_joints >= 20
    text = bvh.read_text()
    assert "End Site" in text and "Zrotation Xrotation Yrotation" in text and "Yrotation Zrotation Xrotation" in text
    names, expected, _ = _reference_positions(text)
    lib = str(tmp_path / "capture.lig")
    r = _cli("import", str(bvh), "-o", lib)
    assert r.returncode == 0, r.stderr
    frames = expected.shape[0]
    records = pose_records(load_program(_player(tmp_path, lib, "CAPTURE_FIGURE", "CAPTURE", frames))[0], tmp_path)
    assert len(records) == frames
    assert "ROOT PATH" not in Path(lib).read_text()  # the path is a ROOT track, not a comment table
    size = np.ptp(expected[0], axis=0).max()
    worst = 0.0
    for t, rec in enumerate(records):
        # ANIMATE follows the imported ROOT track: the poses hold the travelling root, nothing added.
        by_joint = {s["joint"]: np.array(s["matrix"]).reshape(4, 4) for s in rec["segments"]}
        got = np.array([by_joint[j + 1][:3, 3] for j in range(len(names))])
        worst = max(worst, np.abs(got - expected[t]).max())
    assert worst <= 1e-6 * size, worst
    assert np.linalg.norm(expected[-1, 0] - expected[0, 0]) > 0.2 * size  # the capture's root does travel


def test_import_converts_other_orders_through_matrices(tmp_path):
    """An XYZ joint's angles are not relabelled: the imported rotation equals the file's."""
    text = BAD_BASE.replace("CHANNELS 3 Zrotation Yrotation Xrotation", "CHANNELS 3 Xrotation Yrotation Zrotation")
    clip = X.read_bvh(_write(tmp_path, "xyz.bvh", text))
    angles, _, _, _ = X.clip_angles(clip)
    values = clip.data[:, clip.first[1] : clip.first[1] + 3]
    want = Rotation.from_euler("XYZ", values, degrees=True).as_matrix()
    got = Rotation.from_euler("ZYX", angles[:, 1, ::-1], degrees=True).as_matrix()
    np.testing.assert_allclose(got, want, atol=1e-12)
    assert not np.allclose(angles[:, 1], values)  # a relabelling would have kept them


# -- export choices ----------------------------------------------------------------------


def test_several_models_go_to_one_file_each(tmp_path):
    root = ROOT_DIR
    out = tmp_path / "rr.bvh"
    r = _cli("export", os.path.join(root, "examples", "rerooting.lig"), "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert sorted(os.listdir(tmp_path)) == ["rr-scene1-ON_FOOT.bvh", "rr-scene1-ON_TORSO.bvh"]
    for name in os.listdir(tmp_path):
        assert (tmp_path / name).read_text().startswith("HIERARCHY\nROOT ")


def test_frame_time_comes_from_fps(tmp_path):
    src = _write(tmp_path, "walk.lig", WALK)
    out = tmp_path / "walk.bvh"
    assert _cli("export", src, "-o", str(out), "--fps", "50").returncode == 0
    text = out.read_text()
    assert "\nFrames: 25\nFrame Time: 0.02\n" in text
    first = text.split("Frame Time: 0.02\n")[1].splitlines()[0].split()
    assert len(first) == 6 + 3 * 19


def test_a_scaled_placement_is_refused_for_bvh(tmp_path):
    src = _write(
        tmp_path,
        "big.lig",
        WALK.replace(
            "ANIMATE HUMANOID FROM 0 TO 24 USING WALK",
            "ANIMATE HUMANOID FROM 0 TO 24 USING WALK\n        HUMANOID :- HUMANOID <SCALE (1.0, 2.0, 1.0)>",
        ),
    )
    out = tmp_path / "big.bvh"
    r = _cli("export", src, "-o", str(out))
    assert r.returncode == 1 and "BVH skeleton cannot carry" in r.stderr and "Traceback" not in r.stderr
    assert not out.exists()


def test_an_imported_motion_is_an_ordinary_motion(tmp_path):
    src = _write(tmp_path, "walk.lig", WALK)
    bvh = str(tmp_path / "walk.bvh")
    assert _cli("export", src, "-o", bvh).returncode == 0
    lib = str(tmp_path / "w.lig")
    assert _cli("import", bvh, "-o", lib, "--model", "W", "--motion", "M").returncode == 0
    prog = _write(
        tmp_path,
        "algebra.lig",
        """\
      LOAD W, M FROM 'w.lig'
      MOTION BOTH, SLOW, BACK, LEGS
      BOTH = M + M
      SLOW = M <SCALE FRAMES 2.0>
      BACK = M <SCALE FRAMES -1.0>
      LEGS = STRIP M, 2, 3
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 60
        ANIMATE W FROM 0 TO 59 USING (SYNCHRONIZE LEGS, (STRIP M, 7)) + BOTH REPEAT
      ENDSCENE
      SHOOTSCENES
""",
    )
    program = load_program(prog)[0]
    rt = program.execute("check")
    assert rt.variables["BOTH"].length == 48
    assert rt.variables["SLOW"].length == 48
    assert rt.variables["BACK"].length == 24
    assert rt.variables["LEGS"].joints == (2, 3)


# -- bad input ----------------------------------------------------------------------------

BAD_BASE = """\
HIERARCHY
ROOT Hips
{
  OFFSET 0.0 0.0 0.0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT Chest
  {
    OFFSET 0.0 10.0 0.0
    CHANNELS 3 Zrotation Yrotation Xrotation
    End Site
    {
      OFFSET 0.0 5.0 0.0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
0.0 90.0 0.0 0.0 0.0 0.0 10.0 20.0 30.0
1.0 90.0 0.0 5.0 0.0 0.0 15.0 25.0 35.0
2.0 90.0 0.0 10.0 0.0 0.0 20.0 30.0 40.0
"""

BAD = {
    "truncated_mid_frame": (BAD_BASE[: BAD_BASE.rindex("30.0 40.0")], "21:", "ends in the middle of frame 3"),
    "truncated_frames": (BAD_BASE[: BAD_BASE.rindex("2.0 90.0")], "20:", "ends after 2 of the 3 frames"),
    "truncated_hierarchy": (BAD_BASE[: BAD_BASE.index("End Site")], ":", "the file ends where"),
    "extra_value": (BAD_BASE.replace("15.0 25.0 35.0", "15.0 25.0 35.0 45.0"), "20:41:", "frame 2 has 10 values"),
    "missing_value": (BAD_BASE.replace("15.0 25.0 35.0", "15.0 25.0"), "20:", "frame 2 has 8 values"),
    "channel_count": (BAD_BASE.replace("CHANNELS 3 Zrotation", "CHANNELS 4 Zrotation"), "9:14:", "CHANNELS says 4"),
    "non_numeric": (
        BAD_BASE.replace("15.0 25.0 35.0", "15.0 2x5 35.0"),
        "20:31:",
        "'2x5' in frame 2 is not a finite number",
    ),
    "nan": (BAD_BASE.replace("15.0 25.0 35.0", "15.0 nan 35.0"), "20:31:", "not a finite number"),
    "bad_offset": (BAD_BASE.replace("OFFSET 0.0 10.0 0.0", "OFFSET 0.0 ten 0.0"), "8:16:", "'ten' is not a number"),
    "no_motion": (BAD_BASE[: BAD_BASE.index("MOTION")], ":", "has no MOTION section"),
    "unknown_channel": (
        BAD_BASE.replace("Yrotation Xrotation\n    End", "Yrot Xrotation\n    End"),
        "9:26:",
        "'Yrot' is not a BVH channel",
    ),
    "more_frames": (BAD_BASE + "3.0 90.0 0.0 10.0 0.0 0.0 20.0 30.0 40.0\n", "22:1:", "more frame lines"),
    "empty": ("", "1:1:", "empty"),
    "not_bvh": ("hello\n", "1:1:", "starts with HIERARCHY"),
}


def test_the_good_base_file_imports(tmp_path):
    src = _write(tmp_path, "good.bvh", BAD_BASE)
    r = _cli("import", src, "-o", str(tmp_path / "good.lig"))
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_bvh_gets_a_diagnostic_and_nothing_is_written(tmp_path, case):
    text, where, message = BAD[case]
    src = _write(tmp_path, "bad.bvh", text)
    out = tmp_path / "bad.lig"
    r = _cli("import", src, "-o", str(out))
    assert r.returncode == 1, r.stderr
    first = r.stderr.splitlines()[0]
    assert first.startswith(f"{src}:"), first
    assert re.match(re.escape(src) + r":\d+:\d+: error: ", first), first
    assert where in first, first
    assert message in first, first
    assert "Traceback" not in r.stderr and "internal error" not in r.stderr
    assert sorted(os.listdir(tmp_path)) == ["bad.bvh"]


def test_a_moving_non_root_position_channel_is_refused(tmp_path):
    text = BAD_BASE.replace(
        "CHANNELS 3 Zrotation Yrotation Xrotation", "CHANNELS 4 Xposition Zrotation Yrotation Xrotation"
    )
    text = text.replace("10.0 20.0 30.0\n", "0.0 10.0 20.0 30.0\n").replace("15.0 25.0 35.0", "1.0 15.0 25.0 35.0")
    text = text.replace("20.0 30.0 40.0", "2.0 20.0 30.0 40.0")
    src = _write(tmp_path, "slide.bvh", text)
    r = _cli("import", src, "-o", str(tmp_path / "slide.lig"))
    assert r.returncode == 1
    assert f"{src}:9:14: error: joint Chest moves along its Xposition channel" in r.stderr


def test_another_reader_takes_our_bvh(tmp_path):
    """bvhio parses an exported file and finds our skeleton, channels and frames."""
    import bvhio

    src = _write(tmp_path, "squat.lig", REROOTED)
    out = tmp_path / "squat.bvh"
    assert _cli("export", src, "-o", str(out)).returncode == 0
    bvh = bvhio.readAsBvh(str(out))
    layout = bvh.Root.layout()
    assert len(layout) == 20 and bvh.FrameCount == 20
    assert bvh.Root.Name == "R_FOOT"
    assert bvh.FrameTime == pytest.approx(1 / 24)
    root_positions = np.array([list(k.Position) for k in bvh.Root.Keyframes])
    np.testing.assert_allclose(root_positions[:, 0], 0.02 * np.arange(20), atol=1e-6)


def _keyframes(text: str) -> int:
    """Keyframes of a library: its FRAME lines, and a keyframe table's rows after the first, once per column."""
    count = text.count(" FRAME ")
    if "TABLE " in text:
        head = text[text.index("TABLE ") + 6 : text.index("{", text.index("TABLE "))]
        columns = len([c for c in head.split(",") if c.strip()])
        count += (text.count("\n          |") - 1) * columns
    return count


@pytest.mark.parametrize("tolerance", [0.05, 1.0])
def test_fewer_keyframes_within_a_stated_tolerance(tmp_path, tolerance):
    bvh = tmp_path / "capture.bvh"
    _bvhio_file(bvh, frames=240)  # a second at 240 Hz
    full, reduced = str(tmp_path / "full.lig"), str(tmp_path / "reduced.lig")
    assert _cli("import", str(bvh), "-o", full, "--motion", "M", "--model", "F").returncode == 0
    r = _cli("import", str(bvh), "-o", reduced, "--motion", "M", "--model", "F", "--tolerance", str(tolerance))
    assert r.returncode == 0, r.stderr
    count = [_keyframes(Path(p).read_text()) for p in (full, reduced)]
    assert "TABLE" in Path(full).read_text()  # every frame: one row a frame
    assert count[1] < 0.8 * count[0], count
    played = []
    for lib in (full, reduced):
        folder = tmp_path / os.path.basename(lib)[:-4]
        folder.mkdir()
        (folder / "lib.lig").write_text(Path(lib).read_text())
        played.append(X.collect(load_program(_player(folder, str(folder / "lib.lig"), "F", "M", 240))[0])[0].models[0])
    diff = (played[0].angles - played[1].angles + 180.0) % 360.0 - 180.0
    assert 0 < np.abs(diff).max() <= tolerance


def test_awkward_joint_names_become_safe_segment_names(tmp_path):
    """Spaces, braces, digits first, keywords, function names, repeats: the library still LOADs."""
    names = ["Hips", "left hand", "Spine{1}", "2nd", "JOINT", "SIN", "ORIGIN", "Hips", "C", "end"]
    lines = [
        "HIERARCHY",
        f"ROOT {names[0]}",
        "{",
        "  OFFSET 0 0 0",
        "  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation",
    ]
    for n in names[1:]:
        lines += [
            f"  JOINT {n}",
            "  {",
            "    OFFSET 0 1 0",
            "    CHANNELS 3 Zrotation Xrotation Yrotation",
            "    End Site",
            "    {",
            "      OFFSET 0 1 0",
            "    }",
            "  }",
        ]
    lines += ["}", "MOTION", "Frames: 2", "Frame Time: 0.1"]
    lines += [" ".join(["0"] * (6 + 3 * 9)), " ".join(["1"] * (6 + 3 * 9))]
    bvh = _write(tmp_path, "odd {name}.bvh", "\n".join(lines) + "\n")
    lib = str(tmp_path / "odd.lig")
    r = _cli("import", bvh, "-o", lib, "--model", "ODD", "--motion", "MOVE")
    assert r.returncode == 0, r.stderr
    text = Path(lib).read_text()
    segments = re.findall(r"JOINT \d+, \w+, \([^)]*\), (\w+),", text)
    assert segments == ["HIPS", "LEFT_HAND", "SPINE_1", "J_2ND", "JOINT_", "SIN_", "ORIGIN_", "HIPS_2", "C", "END_"]
    take = X.collect(load_program(_player(tmp_path, lib, "ODD", "MOVE", 2))[0])[0].models[0]
    assert take.figure.n_joints == 10
    assert [l.name for l in take.figure.links[1:]] == segments


# The humanoid held by its right foot on a plinth (a submodel attached by the link FIGURE chose,
# thesis 3.3), then animated from its left foot: joints walked from their secondaries twice over.
STATUE = """\
      LOAD HUMANOID, SQUAT FROM 'humanoid'
      GRAPHICAL PLINTH
      MODEL STATUE
      PLINTH :- BOX WIDTH 1.0, HEIGHT 0.4, DEPTH 1.0
      FIGURE HUMANOID MAIN LINK R_FOOT
      STATUE :- JOINT 99, PLINTH, (0.0, 0.2, 0.0), HUMANOID, (0.0, -0.05, 0.0), (-30.0, 30.0)
      FIGURE STATUE MAIN LINK L_FOOT
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 20
        ANIMATE STATUE FROM 0 TO 19 USING SQUAT
        STATUE :- STATUE <ROT Y 30.0>
      ENDSCENE
      SHOOTSCENES
"""


def test_round_trip_of_a_figure_built_from_a_re_rooted_submodel_keeps_every_joint_in_place(tmp_path):
    src = _write(tmp_path, "statue.lig", STATUE)
    bvh = str(tmp_path / "statue.bvh")
    done = _cli("export", src, "-o", bvh)
    assert done.returncode == 0, done.stderr
    lib = str(tmp_path / "statue_lib.lig")
    assert _cli("import", bvh, "-o", lib, "--model", "BACK", "--motion", "AGAIN").returncode == 0
    program = load_program(src)[0]
    fig = X.collect(program)[0].models[0].figure
    assert fig.inverted.any()
    original = pose_records(program, tmp_path / "a")
    again = pose_records(load_program(_player(tmp_path, lib, "BACK", "AGAIN", 20))[0], tmp_path / "b")
    for t, (ra, rb) in enumerate(zip(original, again)):
        X_ = [np.array(s["matrix"]).reshape(4, 4) for s in ra["segments"]]
        # Every joint of the original, in the world, on its (defined) secondary.
        expected = np.array(
            [
                X_[j.secondary][:3, :3] @ (j.loc2 / fig.links[j.secondary].scale) + X_[j.secondary][:3, 3]
                for j in fig.joints
            ]
        )
        got = np.array(
            [np.array(s["matrix"]).reshape(4, 4)[:3, 3] for s in rb["segments"] if s["joint"] not in (None, 1)]
        )
        assert len(got) == len(expected)
        d = np.linalg.norm(expected[:, None, :] - got[None, :, :], axis=2)
        rows, cols = linear_sum_assignment(d)
        assert d[rows, cols].max() <= 1e-5, (t, d[rows, cols].max())
