"""URDF and trajectory export: read back by yourdfpy with the same forward kinematics; an imported
robot's names and frames come back; trajectories carry the interpolation's own velocities."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import subprocess
import sys

import numpy as np
import pybullet_data
import pytest
import yourdfpy

from liganimate.compiler import load_program
from liganimate.runtime import exchange as X
from liganimate.runtime.exchange._urdf_write import joint_columns, urdf_text
from liganimate.runtime.figure import kinematics as K

DATA = pybullet_data.getDataPath()


def load_ref(path):
    return yourdfpy.URDF.load(
        str(path), load_meshes=False, build_collision_scene_graph=False, load_collision_meshes=False
    )


def export(program_text: str, tmp_path, out: str):
    src = tmp_path / "prog.lig"
    src.write_text(program_text)
    done = subprocess.run(
        [sys.executable, "-m", "liganimate", "export", str(src), "-o", str(tmp_path / out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    return done.stderr


SCENE = """
INITIALIZE SCENE 1
STARTSCENE LENGTH 12
  ANIMATE {model} FROM 0 TO 12 USING {motion}
ENDSCENE
SHOOTSCENES
"""


@pytest.mark.parametrize("name", ["kuka_iiwa/model.urdf", "franka_panda/panda.urdf", "r2d2.urdf"])
def test_import_then_export_gives_the_original_forward_kinematics_and_names(name, tmp_path):
    original = os.path.join(DATA, name)
    robot = X.read_urdf(original)
    text, _ = X.import_urdf(robot, X.UrdfImportOptions(model="BOT", mesh_triangles=20))
    (tmp_path / "bot.lig").write_bytes(text)
    program = "LOAD BOT FROM 'bot.lig'\nMOTION STILL\nSTARTMOTION STILL\nENDMOTION\n" + SCENE.format(
        model="BOT", motion="STILL"
    )
    export(program, tmp_path, "back.urdf")
    ref, back = load_ref(original), load_ref(tmp_path / "back.urdf")
    assert {l.name for l in back.robot.links} == {l.name for l in ref.robot.links}
    assert {j.name for j in back.robot.joints} == {j.name for j in ref.robot.joints}
    types = {j.name: j.type for j in ref.robot.joints}
    assert {j.name: j.type for j in back.robot.joints} == types
    rng = np.random.default_rng(5)
    for _ in range(4):
        cfg = []
        for n in ref.actuated_joint_names:
            j = ref.joint_map[n]
            lo, hi = (j.limit.lower, j.limit.upper) if j.type in ("revolute", "prismatic") else (-math.pi, math.pi)
            cfg.append(rng.uniform(lo, hi))
        ref.update_cfg(np.array(cfg))
        back.update_cfg(np.array([cfg[ref.actuated_joint_names.index(n)] for n in back.actuated_joint_names]))
        for link in ref.robot.links:
            np.testing.assert_allclose(
                back.get_transform(link.name, back.base_link),
                ref.get_transform(link.name, ref.base_link),
                rtol=0,
                atol=1e-9,
            )


ARM = """
GRAPHICAL BASE, CAR, UPPER, LOWER
MODEL ARM
MOTION M
BASE :- BOX WIDTH 2, HEIGHT 0.2, DEPTH 1
CAR :- BOX WIDTH 0.4, HEIGHT 0.4, DEPTH 0.4
UPPER :- BOX AT (0, 0.5, 0), WIDTH 0.1, HEIGHT 1, DEPTH 0.1
LOWER :- BOX AT (0, 0.4, 0), WIDTH 0.1, HEIGHT 0.8, DEPTH 0.1
STARTMODEL ARM
  JOINT 1, BASE, (-0.8, 0.1, 0), CAR, (0, -0.2, 0.1), SLIDE (0, 1.6), (0, 0), (-0.2, 0.2) AXIS (1, 0, 0.5)
  JOINT 2, CAR, (0, 0.2, 0), UPPER, (0, -0.05, 0), (-90, 90), (-30, 60), (0, 180)
  JOINT 3, UPPER, (0, 1, 0), LOWER, (0.02, 0, 0), (0, 0), (0, 0), (-150, 0) AXIS (0, 1, 1)
ENDMODEL
ARM :- ARM <SCALE MODEL 1.5>
STARTMOTION M
  JOINT 1 POSITION 0, 0, 0
    FRAME 12 POSITION 1.2, 0, 0.1 INTERPOLATE ACCDCC
  JOINT 2 POSITION 10, 0, 0
    FRAME 6 POSITION 40, 30, 90 INTERPOLATE ACCELERATE
    FRAME 12 POSITION -20, 10, 45
  JOINT 3
    FRAME 12 POSITION 0, 0, -100 INTERPOLATE DECELERATE
ENDMOTION
"""


def test_a_figure_made_in_lig_exports_with_the_same_forward_kinematics(tmp_path):
    """Multi-axis joints become chains, slides prismatic joints, offsets fixed ends; SCALE MODEL included."""
    program, _ = load_program(text=ARM, name="arm.lig")
    fig = program.execute("check").variables["ARM"]
    text, meshes = urdf_text(fig, "arm", str(tmp_path / "m"), "m")
    os.makedirs(tmp_path / "m")
    for path, data in meshes:
        with open(path, "wb") as fh:
            fh.write(data)
    (tmp_path / "arm.urdf").write_bytes(text)
    ref = load_ref(tmp_path / "arm.urdf")
    cols = joint_columns(fig)
    assert sorted(ref.actuated_joint_names) == sorted(c[0] for c in cols)
    rng = np.random.default_rng(9)
    lo, hi = fig.extremes[..., 0], fig.extremes[..., 1]
    for _ in range(5):
        values = rng.uniform(lo, hi)
        q = {}
        for name, k, axis, slide in cols:
            q[name] = values[k, axis] * (fig.joints[k].slide_scale if slide else math.pi / 180)
        ref.update_cfg(np.array([q[n] for n in ref.actuated_joint_names]))
        X_ = K.pose_transforms(fig, values[None])[0]
        for i, link in enumerate(fig.links):
            np.testing.assert_allclose(ref.get_transform(link.name, ref.base_link), X_[i], rtol=0, atol=1e-9)


def test_trajectories_hold_positions_in_radians_and_metres_and_the_interpolations_velocities(tmp_path):
    export(ARM + SCENE.format(model="ARM", motion="M"), tmp_path, "traj.csv")
    rows = list(csv.reader(io.StringIO((tmp_path / "traj.csv").read_text())))
    head, body = rows[0], np.array(rows[1:], dtype=float)
    # Each LIG joint's moving axes, Z then Y then X, the first named after the joint.
    assert head[:7] == ["time", "joint1", "joint1__x", "joint2", "joint2__y", "joint2__x", "joint3"]
    assert head[-1] == "joint3.velocity" and len(head) == 1 + 2 * 6
    assert body.shape == (12, 13)
    np.testing.assert_allclose(body[:, 0], np.arange(12) / 24.0)
    program, _ = load_program(text=ARM, name="arm.lig")
    variables = program.execute("check").variables
    from liganimate.runtime.figure.pose import joint_angles

    fig, motion = variables["ARM"], variables["M"]
    angles, vel, _ = joint_angles(fig, motion, np.arange(12.0), full=True)
    # joint1 slides (metres, scaled by SCALE MODEL 1.5); joint3 turns (radians).
    np.testing.assert_allclose(body[:, 2], 1.5 * angles[:, 0, 0], atol=1e-12)
    np.testing.assert_allclose(body[:, 6], np.radians(angles[:, 2, 2]), atol=1e-12)
    np.testing.assert_allclose(body[:, 8], 1.5 * vel[:, 0, 0] * 24.0, atol=1e-12)
    # The velocities are the derivatives of the positions (central differences, away from keyframes).
    step = 1e-4
    ahead = joint_angles(fig, motion, np.arange(12.0) + step)
    behind = joint_angles(fig, motion, np.arange(12.0) - step)
    numeric = np.radians((ahead[:, 2, 2] - behind[:, 2, 2]) / (2 * step)) * 24.0
    np.testing.assert_allclose(body[1:11, 12], numeric[1:11], rtol=1e-5, atol=1e-6)
    export(ARM + SCENE.format(model="ARM", motion="M"), tmp_path, "traj.json")
    doc = json.loads((tmp_path / "traj.json").read_text())
    (model,) = doc["models"]
    assert model["model"] == "ARM" and model["joints"] == head[1:7]
    np.testing.assert_allclose(np.array(model["position"]), body[:, 1:7], atol=0)


@pytest.mark.filterwarnings("ignore:Importing PyGLM:PendingDeprecationWarning")
def test_bvh_carries_slides_as_position_channels_and_axes_exactly(tmp_path):
    """bvhio (another implementation) puts every exported joint where LIG has it, slides and AXIS included."""
    import bvhio

    from liganimate.runtime.figure.pose import joint_angles

    export(ARM + SCENE.format(model="ARM", motion="M"), tmp_path, "arm.bvh")
    text = (tmp_path / "arm.bvh").read_text()
    assert "JOINT CAR" in text and "CHANNELS 3 Xposition Yposition Zposition" in text
    program, _ = load_program(text=ARM, name="arm.lig")
    variables = program.execute("check").variables
    fig, motion = variables["ARM"], variables["M"]
    X_ = K.pose_transforms(fig, joint_angles(fig, motion, np.arange(12.0)))
    hierarchy = bvhio.readAsHierarchy(str(tmp_path / "arm.bvh"))
    for t in range(12):
        hierarchy.loadPose(t)
        got = {j.Name: np.array(j.PositionWorld) for j, _, _ in hierarchy.layout()}
        for joint in fig.joints:
            link = fig.links[joint.secondary]
            where = X_[t, joint.secondary, :3, :3] @ joint.loc2 + X_[t, joint.secondary, :3, 3]
            np.testing.assert_allclose(got[link.name], where, atol=1e-5)  # bvhio computes in float32


def test_gltf_moves_slides_by_translation_channels_and_turns_axes_exactly(tmp_path):
    """Every segment node of the glTF (the nodes rig, whose segment nodes carry the shape's
    transform) is where the pose record puts the segment, at every tick."""
    from exchange_support import load_gltf, pose_records, sample_channels, segment_nodes, world_transforms

    src = tmp_path / "arm.lig"
    src.write_text(ARM + SCENE.format(model="ARM", motion="M"))
    out = tmp_path / "arm.glb"
    done = subprocess.run(
        [sys.executable, "-m", "liganimate", "export", str(src), "-o", str(out), "--rig", "nodes"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    doc, blob = load_gltf(str(out))
    program, _ = load_program(str(src))
    records = pose_records(program, tmp_path)
    (anim,) = doc.animations
    assert any(ch.target.path == "translation" for ch in anim.channels)
    segments = segment_nodes(doc)
    for rec in records:
        worlds = world_transforms(doc, 0, sample_channels(doc, blob, anim, rec["tick"] / 24.0))
        for i, seg in enumerate(rec["segments"]):
            expected = np.array(seg["matrix"]).reshape(4, 4)
            np.testing.assert_allclose(worlds[segments[(1, "ARM", i)]], expected, rtol=0, atol=1e-5)


@pytest.mark.parametrize("name", ["kuka_iiwa/model.urdf", "franka_panda/panda.urdf", "r2d2.urdf", "a1/a1.urdf"])
def test_import_then_export_keeps_pinocchios_forward_kinematics(name, tmp_path):
    """The round trip read by pinocchio: every original link where the original puts it."""
    from exchange_support import pinocchio_links

    original = os.path.join(DATA, name)
    robot = X.read_urdf(original)
    text, _ = X.import_urdf(robot, X.UrdfImportOptions(model="BOT", mesh_triangles=20))
    (tmp_path / "bot.lig").write_bytes(text)
    program = "LOAD BOT FROM 'bot.lig'\nMOTION STILL\nSTARTMOTION STILL\nENDMOTION\n" + SCENE.format(
        model="BOT", motion="STILL"
    )
    export(program, tmp_path, "back.urdf")
    rng = np.random.default_rng(17)
    for _ in range(4):
        cfg = {}
        for j in robot.joints:
            if j.type in ("revolute", "prismatic"):
                cfg[j.name] = float(rng.uniform(j.lower, j.upper))
            elif j.type == "continuous":
                cfg[j.name] = float(rng.uniform(-math.pi, math.pi))
        for j in robot.joints:
            if j.mimic is not None:
                cfg[j.name] = j.mimic[1] * cfg[j.mimic[0]] + j.mimic[2]
        ref, back = pinocchio_links(original, cfg), pinocchio_links(tmp_path / "back.urdf", cfg)
        for link in robot.links:
            np.testing.assert_allclose(back[link.name], ref[link.name], rtol=0, atol=1e-9, err_msg=link.name)


@pytest.mark.parametrize("reader", ["yourdfpy", "pinocchio"])
def test_a_figure_with_a_re_rooted_submodel_exports_with_the_same_forward_kinematics(reader, tmp_path):
    """Joints walked from their secondary (a submodel attached by the link FIGURE chose) are written
    parent to child as the inverse turn: Rx, Ry, Rz about the opposite axes, slides the other way."""
    from exchange_support import GRAFTED, pinocchio_links

    program, _ = load_program(text=GRAFTED, name="grafted.lig")
    variables = program.execute("check").variables
    for model in ("BOT", "SPUN"):
        fig = variables[model]
        assert fig.inverted.any()
        text, _ = urdf_text(fig, model.lower(), str(tmp_path / "m"), "m")
        path = tmp_path / f"{model}.urdf"
        path.write_bytes(text)
        cols = joint_columns(fig)
        rng = np.random.default_rng(3)
        lo, hi = fig.extremes[..., 0], fig.extremes[..., 1]
        for _ in range(5):
            values = rng.uniform(lo, hi)
            q = {
                name: values[k, axis] * (fig.joints[k].slide_scale if slide else math.pi / 180)
                for name, k, axis, slide in cols
            }
            # The URDF is the model as built: seen from its original main link.
            X_ = K.pose_transforms(fig.with_original_main(), values[None])[0]
            if reader == "yourdfpy":
                ref = load_ref(path)
                assert sorted(ref.actuated_joint_names) == sorted(q)
                ref.update_cfg(np.array([q[n] for n in ref.actuated_joint_names]))
                got = {link.name: ref.get_transform(link.name, ref.base_link) for link in fig.links}
            else:
                got = pinocchio_links(path, q)
            for i, link in enumerate(fig.links):
                np.testing.assert_allclose(got[link.name], X_[i], rtol=0, atol=1e-9, err_msg=f"{model} {link.name}")
