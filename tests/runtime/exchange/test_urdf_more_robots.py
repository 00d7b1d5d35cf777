"""URDF import on robots beyond pybullet_data: example-robot-data's wheel (the descriptions
pinocchio's examples use), fetched once with pip into tests/.cache. Each robot here broke
something before: the forward kinematics must agree with yourdfpy to 1e-9 m at random joint values."""

from __future__ import annotations

import glob
import math
import os
import subprocess
import sys
import zipfile

import numpy as np
import pytest
import yourdfpy
from captures import _give_up  # the captures' rule: a failed download skips outside CI, fails in CI
from test_urdf_import import imported, lig_values

from liganimate.runtime.exchange._urdf_read import rpy_matrix
from liganimate.runtime.figure import kinematics as K

VERSION = "6.0.0"
CACHE = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), ".cache", "robots")
ROBOTS = [
    "ur_description/urdf/ur5_gripper.urdf",  # rpy="0 1.570796325 0": its RPY snapped to pi/2, 1.8e-9 off
    "anymal_c_simple_description/urdf/anymal.urdf",  # mesh slivers that closed when written: did not compile
    "iris_description/robots/iris.urdf",  # rotors limited to +-1e16 rad: extremes LOAD refused
    "talos_data/robots/talos_left_arm.urdf",  # mimic tags on fixed joints
    "baxter_description/urdf/baxter.urdf",
]


def robots_folder() -> str:
    """example-robot-data's robots folder, from its wheel, downloaded the first time."""
    folder = os.path.join(CACHE, f"example_robot_data-{VERSION}")
    robots = os.path.join(folder, "cmeel.prefix", "share", "example-robot-data", "robots")
    if os.path.isdir(robots):
        return robots
    os.makedirs(CACHE, exist_ok=True)
    wheels = glob.glob(os.path.join(CACHE, f"example_robot_data-{VERSION}-*.whl"))
    if not wheels:
        cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary", ":all:", "-d", CACHE]
        try:
            r = subprocess.run([*cmd, f"example-robot-data=={VERSION}"], capture_output=True, text=True, timeout=600)
        except subprocess.TimeoutExpired:
            _give_up("pip download example-robot-data took over 10 minutes, so its robots are not here")
        wheels = glob.glob(os.path.join(CACHE, f"example_robot_data-{VERSION}-*.whl"))
        if r.returncode != 0 or not wheels:
            _give_up(f"pip download example-robot-data failed, so its robots are not here:\n{r.stderr[-2000:]}")
    with zipfile.ZipFile(wheels[0]) as wheel:
        wheel.extractall(folder, [n for n in wheel.namelist() if n.startswith("cmeel.prefix/share/")])
    return robots


@pytest.mark.parametrize("name", ROBOTS)
def test_forward_kinematics_agree_with_yourdfpy(name, tmp_path):
    path = os.path.join(robots_folder(), name)
    fig, robot = imported(path, tmp_path)
    ref = yourdfpy.URDF.load(path, load_meshes=False, build_collision_scene_graph=False, load_collision_meshes=False)
    assert fig.n_links == len(ref.robot.links)
    rng = np.random.default_rng(7)
    # Limits past a full turn each way (iris's +-1e16) are sampled within one turn.
    limits = {
        j.name: (max(j.lower, -math.pi), min(j.upper, math.pi))
        if j.type in ("revolute", "prismatic")
        else (-math.pi, math.pi)
        for j in robot.joints
    }
    for _ in range(3):
        cfg = {n: float(rng.uniform(*limits[n])) for n in ref.actuated_joint_names}
        ref.update_cfg(np.array([cfg[n] for n in ref.actuated_joint_names]))
        X_lig = K.pose_transforms(fig, lig_values(fig, robot, cfg)[None])[0]
        for i, link in enumerate(fig.links):
            T = ref.get_transform(link.source.name, ref.base_link)
            R0 = rpy_matrix(link.source.rpy) if link.source.rpy is not None else np.eye(3)
            np.testing.assert_allclose(X_lig[i, :3, 3], T[:3, 3], rtol=0, atol=1e-9)
            np.testing.assert_allclose(X_lig[i, :3, :3] @ R0, T[:3, :3], rtol=0, atol=1e-9)
