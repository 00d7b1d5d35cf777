"""URDF import: real robot descriptions from a PyPI package (pybullet_data), checked against an
independent reader (yourdfpy), and malformed files refused at their line."""

from __future__ import annotations

import math
import os
import subprocess
import sys

import numpy as np
import pybullet_data  # the test extra installs pybullet, whose wheel ships these robot descriptions
import pytest
import yourdfpy

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.runtime import exchange as X
from liganimate.runtime.exchange._urdf_read import rpy_matrix
from liganimate.runtime.figure import kinematics as K

DATA = pybullet_data.getDataPath()
ROBOTS = [
    "kuka_iiwa/model.urdf",  # revolute joints, axes in turned frames, OBJ meshes
    "franka_panda/panda.urdf",  # fixed joints, a prismatic finger, a mimic joint, package:// meshes
    "r2d2.urdf",  # boxes, cylinders, spheres, continuous wheels, a prismatic gripper
    "xarm/xarm6_robot.urdf",
    "a1/a1.urdf",  # a quadruped: a tree, not a chain
    # Joint axes 6e-6 from -X (rpy 1.57079 0 1.57079, not quite a quarter turn), and toes drawn
    # as spheres of radius 0: the frame was off by 1e-6 and the library did not compile.
    "laikago/laikago_toes_zup_lores.urdf",
    "differential/diff_ring.urdf",  # blank lines before its XML declaration, which TinyXML takes
]


def imported(path: str, tmp_path, triangles: int = 24):
    """Import ``path`` and load the library: (figure, Urdf)."""
    robot = X.read_urdf(path)
    text, _ = X.import_urdf(robot, X.UrdfImportOptions(model="BOT", mesh_triangles=triangles))
    lib = tmp_path / "bot.lig"
    lib.write_bytes(text)
    program, _ = load_program(text=f"LOAD BOT FROM '{lib}'\n", name="use.lig")
    return program.execute("check").variables["BOT"], robot


def lig_values(fig, robot, cfg: dict) -> np.ndarray:
    """The LIG joint values for URDF joint positions ``cfg`` (mimic joints follow their leader)."""
    by_name = {j.name: j for j in robot.joints}
    values = np.zeros((fig.n_joints, 3))
    for k, joint in enumerate(fig.joints):
        name = fig.links[joint.secondary].source.joint
        j = by_name[name]
        if j.mimic is not None and j.type != "fixed":  # a fixed joint with a <mimic> (Talos) never moves
            q = j.mimic[1] * cfg[j.mimic[0]] + j.mimic[2]
        else:
            q = cfg.get(name, 0.0)
        values[k, 0] = q if j.type == "prismatic" else math.degrees(q)
    return values


@pytest.mark.parametrize("name", ROBOTS)
def test_forward_kinematics_agree_with_yourdfpy_at_random_joint_values(name, tmp_path):
    path = os.path.join(DATA, name)
    fig, robot = imported(path, tmp_path)
    ref = yourdfpy.URDF.load(path, load_meshes=False, build_collision_scene_graph=False, load_collision_meshes=False)
    assert fig.n_links == len(ref.robot.links) and fig.n_joints == len(ref.robot.joints)
    rng = np.random.default_rng(20)
    limits = {
        j.name: (j.lower, j.upper) if j.type in ("revolute", "prismatic") else (-math.pi, math.pi) for j in robot.joints
    }
    for _ in range(5):
        cfg = {n: float(rng.uniform(*limits[n])) for n in ref.actuated_joint_names}
        ref.update_cfg(np.array([cfg[n] for n in ref.actuated_joint_names]))
        X_lig = K.pose_transforms(fig, lig_values(fig, robot, cfg)[None])[0]
        for i, link in enumerate(fig.links):
            T = ref.get_transform(link.source.name, ref.base_link)
            R0 = rpy_matrix(link.source.rpy) if link.source.rpy is not None else np.eye(3)
            np.testing.assert_allclose(X_lig[i, :3, 3], T[:3, 3], rtol=0, atol=1e-9)
            np.testing.assert_allclose(X_lig[i, :3, :3] @ R0, T[:3, :3], rtol=0, atol=1e-9)


def test_names_extremes_and_kinds_come_from_the_urdf(tmp_path):
    fig, robot = imported(os.path.join(DATA, "franka_panda/panda.urdf"), tmp_path)
    names = [fig.links[j.secondary].source.joint for j in fig.joints]
    assert names[:7] == [f"panda_joint{k}" for k in range(1, 8)]
    finger = fig.joints[names.index("panda_finger_joint1")]
    assert finger.slide and tuple(finger.extremes[0]) == (0.0, 0.04)
    j1 = fig.joints[0]
    assert not j1.slide and j1.extremes[0] == pytest.approx((-math.degrees(2.9671), math.degrees(2.9671)))
    hand = fig.joints[names.index("panda_hand_joint")]
    assert not hand.extremes.any()  # fixed: locked
    assert fig.links[fig.root].source.name == "panda_link0"


def test_the_command_line_imports_a_robot_and_notes_its_mimic_joint(tmp_path):
    out = tmp_path / "panda.lig"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "liganimate",
            "import",
            os.path.join(DATA, "franka_panda/panda.urdf"),
            "-o",
            str(out),
            "--mesh-triangles",
            "30",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert "MODEL PANDA" in done.stderr and "panda_finger_joint2 mimics panda_finger_joint1" in done.stderr
    text = out.read_text()
    assert 'JOINT "panda_joint1"' in text and "SLIDE (0.0, 0.04)" in text


# ------------------------------------------------------------------ bad input


GOOD = """<?xml version="1.0"?>
<robot name="two">
  <link name="base"><visual><geometry><box size="1 1 1"/></geometry></visual></link>
  <link name="arm"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="arm"/>
    <origin xyz="0 0 1" rpy="0 0 0"/><axis xyz="0 1 1"/>
    <limit lower="-1" upper="1"/>
  </joint>
</robot>
"""


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        (GOOD.replace('<link name="arm"/>', '<link name="arm">'), 10, "not well-formed"),
        (GOOD.replace('<child link="arm"/>', '<child link="hand"/>'), 6, "hand, which the robot does not define"),
        (
            GOOD.replace(
                "</robot>", '<joint name="j2" type="fixed"><parent link="arm"/><child link="base"/></joint>\n</robot>'
            ),
            10,
            "cycle",
        ),
        (
            GOOD.replace("</robot>", '<link name="wheel"/>\n</robot>'),
            10,
            "2 root links",
        ),
        (GOOD.replace('type="revolute"', 'type="planar"'), 5, '"planar"'),
        (GOOD.replace('upper="1"', 'upper="x"'), 8, "finite number"),
        (
            '<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;">]>\n<robot name="x">&b;</robot>\n',
            2,
            "document type",
        ),
    ],
)
def test_malformed_urdf_is_refused_at_its_line_and_nothing_is_written(text, line, words, tmp_path):
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    with pytest.raises(LigDiagnostics) as info:
        X.read_urdf(str(path))
    d = info.value.diagnostics[0]
    assert words in d.message and d.pos.line == line, (d.message, d.pos.line)
    out = tmp_path / "bad.lig"
    done = subprocess.run(
        [sys.executable, "-m", "liganimate", "import", str(path), "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode != 0 and f"bad.urdf:{line}:" in done.stderr and "Traceback" not in done.stderr
    assert not out.exists()


def test_a_joint_axis_is_any_unit_direction(tmp_path):
    path = tmp_path / "two.urdf"
    path.write_text(GOOD)
    fig, _ = imported(str(path), tmp_path)
    np.testing.assert_allclose(fig.joints[0].axes[:, 0], [0, 2**-0.5, 2**-0.5], atol=1e-15)
    # Turning by 90 degrees about (0, 1, 1) takes the arm's X axis to (0, 1, -1) / sqrt 2.
    X_ = K.pose_transforms(fig, np.array([[[90.0, 0, 0]]]))[0, 1]
    np.testing.assert_allclose(X_[:3, :3] @ [1, 0, 0], [0, 2**-0.5, -(2**-0.5)], atol=1e-12)


# pinocchio's own URDF parser and forward kinematics, a second independent reader.
PINOCCHIO_ROBOTS = ROBOTS + ["racecar/racecar.urdf", "pendulum5.urdf", "quadruped/minitaur.urdf"]


@pytest.mark.parametrize("name", PINOCCHIO_ROBOTS)
def test_forward_kinematics_agree_with_pinocchio_at_random_joint_values(name, tmp_path):
    from exchange_support import pinocchio_links

    path = os.path.join(DATA, name)
    fig, robot = imported(path, tmp_path)
    rng = np.random.default_rng(31)
    movable = [j for j in robot.joints if j.type != "fixed" and j.mimic is None]
    checked = 0
    for _ in range(5):
        cfg = {
            j.name: float(rng.uniform(j.lower, j.upper) if j.type != "continuous" else rng.uniform(-math.pi, math.pi))
            for j in movable
        }
        # pinocchio reads a mimic joint as a joint of its own: give it the URDF's formula.
        full = dict(cfg)
        for j in robot.joints:
            if j.mimic is not None:
                full[j.name] = j.mimic[1] * cfg[j.mimic[0]] + j.mimic[2]
        ref = pinocchio_links(path, full)
        X_lig = K.pose_transforms(fig, lig_values(fig, robot, cfg)[None])[0]
        for i, link in enumerate(fig.links):
            T = ref[link.source.name]
            R0 = rpy_matrix(link.source.rpy) if link.source.rpy is not None else np.eye(3)
            np.testing.assert_allclose(X_lig[i, :3, 3], T[:3, 3], rtol=0, atol=1e-9, err_msg=link.source.name)
            np.testing.assert_allclose(X_lig[i, :3, :3] @ R0, T[:3, :3], rtol=0, atol=1e-9, err_msg=link.source.name)
            checked += 1
    assert checked == 5 * fig.n_links


def test_an_axis_next_to_minus_x_gives_an_orthonormal_frame():
    # 1 + cos cancels there: the frame came out 1e-6 from a rotation.
    from liganimate.runtime.figure.tree import frame_from_axis

    for axis in [(-1.0, 6e-6, -6e-6), (-1.0, 1e-7, 0.0), (-1.0, 0.0, 3e-9), (-1.0, 0.0, 0.0)]:
        F = frame_from_axis(axis)
        np.testing.assert_allclose(F.T @ F, np.eye(3), rtol=0, atol=1e-15)
        np.testing.assert_allclose(F[:, 0], np.asarray(axis) / np.linalg.norm(axis), rtol=0, atol=1e-15)


# ------------------------------------------------------------------ hostile and unusual files


def _import_cli(path, out, env=None):
    return subprocess.run(
        [sys.executable, "-m", "liganimate", "import", str(path), "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
        env=None if env is None else {**os.environ, **env},
    )


MESH = GOOD.replace('<box size="1 1 1"/>', '<mesh filename="{name}"/>')


@pytest.mark.parametrize(
    ("name", "words"),
    [
        ("../../../../../../etc/passwd", "not an STL, OBJ or DAE file"),
        ("/etc/passwd", "not an STL, OBJ or DAE file"),
        ("package://", "not an STL, OBJ or DAE file"),
        ("package://nopackage/meshes/arm.stl", "not found beside the URDF"),
        ("../../../../../../../nowhere/arm.stl", "not found beside the URDF"),
    ],
)
def test_a_mesh_name_that_leads_to_any_other_file_is_refused_at_its_line(name, words, tmp_path):
    path = tmp_path / "bad.urdf"
    path.write_text(MESH.format(name=name))
    out = tmp_path / "bad.lig"
    done = _import_cli(path, out)
    assert done.returncode == 1 and "bad.urdf:3:" in done.stderr and words in done.stderr, done.stderr
    assert "Traceback" not in done.stderr and not out.exists()


def test_a_mesh_over_the_budget_is_refused_before_it_is_read(tmp_path):
    big = tmp_path / "big.stl"
    with open(big, "wb") as fh:  # sparse: 200 MiB on paper, no disk used
        fh.truncate(200 * 1024 * 1024)
    path = tmp_path / "bad.urdf"
    path.write_text(MESH.format(name="big.stl"))
    out = tmp_path / "bad.lig"
    done = _import_cli(path, out)
    assert done.returncode == 1 and "bad.urdf:3:" in done.stderr, done.stderr
    assert "200 MiB, more than the 100 MiB" in done.stderr and "LIGANIMATE_MAX_MESH_MB" in done.stderr
    assert not out.exists()
    # The budget is the user's to raise: then the file is read (and this one, all zeros, is no mesh).
    done = _import_cli(path, out, {"LIGANIMATE_MAX_MESH_MB": "300"})
    assert done.returncode == 1 and "MiB" not in done.stderr and "Traceback" not in done.stderr, done.stderr
    assert not out.exists()


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        (GOOD.replace('xyz="0 0 1"', 'xyz="$(optenv ARM_XYZ 0 0 1)"'), 7, "xacro"),
        (GOOD.replace('xyz="0 0 1"', 'xyz="0, 0, 1"'), 7, "not commas"),
        (
            GOOD.split('<link name="arm"/>')[0] + "</robot>\n",
            3,
            "fixed joint from it",
        ),
        (
            '<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n<robot name="x">&x;</robot>\n',
            2,
            "document type",
        ),
    ],
)
def test_refusals_name_the_cause_in_a_hint(text, line, words, tmp_path):
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    out = tmp_path / "bad.lig"
    done = _import_cli(path, out)
    assert done.returncode == 1 and f"bad.urdf:{line}:" in done.stderr and words in done.stderr, done.stderr
    assert "Traceback" not in done.stderr and not out.exists()


@pytest.mark.parametrize("variant", ["crlf", "bom", "tabs", "blank-lines-first"])
def test_line_endings_bom_tabs_and_a_late_declaration_are_read(variant, tmp_path):
    text = GOOD
    if variant == "crlf":
        text = text.replace("\n", "\r\n")
    elif variant == "tabs":
        text = text.replace("  ", "\t")
    elif variant == "blank-lines-first":
        text = "\n\n  " + text
    raw = text.encode("utf-8")
    if variant == "bom":
        raw = b"\xef\xbb\xbf" + raw
    path = tmp_path / "two.urdf"
    path.write_bytes(raw)
    fig, robot = imported(str(path), tmp_path)
    assert [link.source.name for link in fig.links] == ["base", "arm"] and robot.joints[0].name == "j1"
    # Positions still count the file's own lines.
    bad = raw.replace(b'upper="1"', b'upper="x"')
    path.write_bytes(bad)
    with pytest.raises(LigDiagnostics) as info:
        X.read_urdf(str(path))
    assert info.value.diagnostics[0].pos.line == (10 if variant == "blank-lines-first" else 8)


def test_rpy_of_a_frame_near_a_quarter_pitch_gives_back_the_frame():
    # example-robot-data's UR5 with gripper turns by rpy="0 1.570796325 0": the name table's RPY
    # snapped to exactly pi/2 and the frame was 1.8e-9 off.
    from liganimate.runtime.exchange._urdf_lig import matrix_rpy

    rng = np.random.default_rng(3)
    for pitch in (1.570796325, -1.570796325, math.pi / 2, -math.pi / 2, 1.5707963267, 0.3):
        for _ in range(20):
            R = rpy_matrix((rng.uniform(-math.pi, math.pi), pitch, rng.uniform(-math.pi, math.pi)))
            np.testing.assert_allclose(rpy_matrix(matrix_rpy(R)), R, rtol=0, atol=1e-15)


def test_a_revolute_joint_with_limits_that_bound_nothing_turns_freely(tmp_path):
    # example-robot-data's iris drone (converted from SDF) gives its rotors lower="-1e+16" upper="1e+16":
    # the library was written with extremes LOAD refuses (beyond 1E9 degrees).
    path = tmp_path / "rotor.urdf"
    path.write_text(GOOD.replace('lower="-1" upper="1"', 'lower="-1e+16" upper="1e+16"'))
    robot = X.read_urdf(str(path))
    text, notes = X.import_urdf(robot, X.UrdfImportOptions(model="BOT", mesh_triangles=24))
    assert any("j1's limits (-1e+16, 1e+16) bound nothing" in n for n in notes)
    fig, _ = imported(str(path), tmp_path)
    ref = yourdfpy.URDF.load(str(path), load_meshes=False)
    for q in (-2.5, 0.7, 3.0):
        ref.update_cfg(np.array([q]))
        X_lig = K.pose_transforms(fig, lig_values(fig, robot, {"j1": q})[None])[0]
        T = ref.get_transform("arm", ref.base_link)
        np.testing.assert_allclose(X_lig[1, :3, :3], T[:3, :3], rtol=0, atol=1e-12)


def test_a_mesh_sliver_that_rounding_closes_is_left_out(tmp_path):
    # ANYmal C (example-robot-data) has triangles whose corners are a micrometre apart: written to six
    # digits two corners were one, and the library did not compile ("a polygon needs three corners").
    (tmp_path / "part.obj").write_text(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0.3886281 0.04685511 0.1612691\nv 0.3886279 0.04685509 0.1612689\nf 1 2 3\nf 4 2 5\n"
    )
    path = tmp_path / "part.urdf"
    path.write_text(MESH.format(name="part.obj"))
    fig, _ = imported(str(path), tmp_path)
    assert fig.n_links == 2
    text, _ = X.import_urdf(X.read_urdf(str(path)), X.UrdfImportOptions(model="BOT", mesh_triangles=24))
    assert text.decode().count("DRAW POLY") == 1 and "part.obj, 1 triangles" in text.decode()
