"""Helpers for the exchange tests: the glTF-Validator, an independent glTF pose reader, --poses records.

Nothing here uses liganimate's exchange code: the validator is Khronos's,
glTF files are read with pygltflib and posed by the plain node-graph walk
below, and pose records come from ``Program.render(poses=...)``, as
``liganimate run --poses`` writes them.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess

import numpy as np
import pygltflib
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
VALIDATOR_DIR = os.path.join(HERE, ".cache", "gltf-validator")
VALIDATOR_MODULE = os.path.join(VALIDATOR_DIR, "node_modules", "gltf-validator")
VALIDATE_JS = os.path.join(HERE, "exchange_tools", "validate_gltf.js")


def validator_or_skip() -> str:
    """The gltf-validator module folder, installed from npm the first time.

    Skips only outside CI, and says why; in CI a missing node or npm fails.
    """
    node, npm = shutil.which("node"), shutil.which("npm")
    missing = [n for n, p in (("node", node), ("npm", npm)) if p is None]
    if missing:
        if os.environ.get("CI"):
            pytest.fail(f"{' and '.join(missing)} not found: CI must run the Khronos glTF-Validator")
        pytest.skip(f"{' and '.join(missing)} not found, so the Khronos glTF-Validator cannot run here")
    if not os.path.isfile(os.path.join(VALIDATOR_MODULE, "index.js")):
        os.makedirs(VALIDATOR_DIR, exist_ok=True)
        r = subprocess.run(
            [npm, "install", "--no-audit", "--no-fund", "--prefix", VALIDATOR_DIR, "gltf-validator"],
            check=False,
            capture_output=True,
            text=True,
            timeout=600,
        )
        if r.returncode != 0 or not os.path.isfile(os.path.join(VALIDATOR_MODULE, "index.js")):
            message = f"npm install gltf-validator failed:\n{r.stdout}\n{r.stderr}"
            if os.environ.get("CI"):
                pytest.fail(message)
            pytest.skip(message)
    return VALIDATOR_MODULE


def validate(paths) -> dict:
    """Validator reports by file: ``{path: issues}`` (``numErrors``, ``messages``...)."""
    module = validator_or_skip()
    r = subprocess.run(["node", VALIDATE_JS, module, *paths], check=False, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    out = {}
    for line in r.stdout.splitlines():
        rec = json.loads(line)
        out[rec["file"]] = rec["issues"]
    return out


# -- an independent glTF reader -------------------------------------------------


def load_gltf(path):
    """(document, buffer bytes) of a .glb or a .gltf with an embedded buffer, via pygltflib."""
    doc = pygltflib.GLTF2().load(path)
    if doc.buffers and doc.buffers[0].uri:
        blob = doc.decode_data_uri(doc.buffers[0].uri)
    else:
        blob = doc.binary_blob() or b""
    return doc, blob


def accessor(doc, blob, index) -> np.ndarray:
    """An accessor's float data, shape (count, components)."""
    acc = doc.accessors[index]
    view = doc.bufferViews[acc.bufferView]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[acc.type]
    assert acc.componentType == 5126
    stride = view.byteStride or 4 * width
    start = (view.byteOffset or 0) + (acc.byteOffset or 0)
    raw = np.frombuffer(blob, dtype=np.uint8, count=stride * (acc.count - 1) + 4 * width, offset=start)
    rows = np.lib.stride_tricks.as_strided(raw, shape=(acc.count, 4 * width), strides=(stride, 1))
    return np.ascontiguousarray(rows).view(np.float32).astype(np.float64).reshape(acc.count, width)


def _quat_matrix(q) -> np.ndarray:
    x, y, z, w = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _local(node, override) -> np.ndarray:
    if node.matrix is not None:
        return np.array(node.matrix, dtype=np.float64).reshape(4, 4).T  # column-major
    t = override.get("translation", node.translation or [0.0, 0.0, 0.0])
    r = override.get("rotation", node.rotation or [0.0, 0.0, 0.0, 1.0])
    s = override.get("scale", node.scale or [1.0, 1.0, 1.0])
    M = np.eye(4)
    M[:3, :3] = _quat_matrix(np.asarray(r, dtype=np.float64)) * np.asarray(s, dtype=np.float64)[None, :]
    M[:3, 3] = t
    return M


def sample_channels(doc, blob, animation, time: float) -> dict:
    """``{node: {path: value}}`` of an animation at ``time``, which must be one of its key times (or past them)."""
    out: dict = {}
    for ch in animation.channels:
        sampler = animation.samplers[ch.sampler]
        times = accessor(doc, blob, sampler.input)[:, 0]
        values = accessor(doc, blob, sampler.output)
        hit = np.flatnonzero(np.isclose(times, time, rtol=0, atol=1e-6))
        if len(hit):
            k = hit[0]
        elif time > times[-1]:
            k = len(times) - 1
        elif time < times[0]:
            k = 0
        else:
            raise AssertionError(f"time {time} falls between keys of node {ch.target.node}")
        out.setdefault(ch.target.node, {})[ch.target.path] = values[k]
    return out


def world_transforms(doc, scene_index: int, override: dict) -> dict:
    """``{node: 4x4 world matrix}`` for every node of a glTF scene."""
    out = {}

    def walk(n, parent):
        node = doc.nodes[n]
        M = parent @ _local(node, override.get(n, {}))
        out[n] = M
        for c in node.children or []:
            walk(c, M)

    for n in doc.scenes[scene_index].nodes:
        walk(n, np.eye(4))
    return out


def segment_nodes(doc) -> dict:
    """``{(scene, model, segment index): node}`` from the liganimate extras of segment nodes."""
    out = {}
    for n, node in enumerate(doc.nodes):
        info = (node.extras or {}).get("liganimate", {})
        if "segment" in info:
            out[(info["scene"], info["model"], info["segment"])] = n
    return out


# -- the --poses record ------------------------------------------------------------


def pose_records(program, tmp_path) -> list:
    """The program's ``--poses`` records, rendered as ``liganimate run --poses`` does (tiny images)."""
    poses = str(tmp_path / "poses.jsonl")
    program.render(str(tmp_path / "frames"), size=(8, 6), poses=poses, quiet=True, workers=1)
    with open(poses, encoding="utf-8") as fh:
        return [json.loads(line) for line in fh]


# -- programs the exchange tests export ---------------------------------------------

# Two scenes: a figure scaled unevenly, turned and moved every tick, with a
# clamped joint and a free axis; a mirrored copy re-rooted at its forearm
# that is drawn only from tick 3 to 8; a camera that follows; a second scene
# with SAMEFRAME 2 (STEP sampling).
EDGES = """\
      GRAPHICAL A, B, C, FLOOR
      MODEL ARM, MIRROR
      MOTION SWING
      VECTOR P
      A :- BOX WIDTH 0.2, HEIGHT 1.0, DEPTH 0.2, LIGHTNESS 30.0
      B :- BOX WIDTH 0.15, HEIGHT 0.8, DEPTH 0.15, LIGHTNESS 60.0
      C :- BOX WIDTH 0.3, HEIGHT 0.1, DEPTH 0.3
      ARM :- JOINT 1, A, (0.0, 0.5, 0.0), B, (0.0, -0.4, 0.0), (-90.0, 90.0), (-180.0, 180.0), (-120.0, 120.0)
      ARM :- JOINT 2, ARM, (0.0, -0.5, 0.0), C, (0.0, 0.05, 0.0), (-30.0, 30.0), (-30.0, 30.0), (-30.0, 30.0)
      MIRROR :- ARM <SCALE MODEL -0.5>
      FIGURE MIRROR MAIN JOINT 1
      STARTMOTION SWING
        JOINT 1 POSITION 10.0, 20.0, 30.0
          FRAME 10 POSITION -50.0, 170.0, 100.0 INTERPOLATE ACCDCC
        JOINT 2 POSITION 0.0, 0.0, 0.0
          FRAME 10 POSITION 40.0, -40.0, 20.0
      ENDMOTION
      FLOOR :- BOX AT (0.0, -1.0, 0.0), WIDTH 4.0, HEIGHT 0.1, DEPTH 4.0
      INITIALIZE SCENE 1
        P = (0.0, 0.0, 0.0)
        BACKGROUND FLOOR
      STARTSCENE LENGTH 12
        ANIMATE ARM FROM 0 TO 11 USING SWING
        ARM :- ARM <SCALE (1.0, 2.0, 1.0)> <ROT Y 30.0> <TRANS (P)>
        ANIMATE MIRROR FROM 3 TO 8 USING SWING
        MIRROR :- MIRROR <ROT Z 20.0> <TRANS (1.0, 0.0, 0.0)>
        P = P + (0.1, 0.05, 0.0)
        VIEW POINT = (1.0, 2.0, 6.0) + P
      ENDSCENE
      INITIALIZE SCENE 2
      STARTSCENE LENGTH 4 SAMEFRAME 2
        ANIMATE ARM FROM 0 TO 3 USING SWING <SCALE FRAMES 0.5>
      ENDSCENE
      SHOOTSCENES
"""

WALKING_HUMANOID = """\
      LOAD HUMANOID, WALK FROM 'humanoid'
      INITIALIZE SCENE 1
        VIEW POINT = (0.0, 1.0, 5.0)
      STARTSCENE LENGTH 30
        ANIMATE HUMANOID FROM 0 TO 29 USING WALK REPEAT
C       WALK's ROOT track carries the body forward; the scene places its start.
        HUMANOID :- HUMANOID <TRANS (-1.0, 0.972, 0.0)>
      ENDSCENE
      SHOOTSCENES
"""


# A crane: a carriage SLIDEs along its rail while a boom swings about its own AXIS, and a copy re-rooted
# at the boom (the slide and the turn walked backwards), both moving every tick.
CRANE = """\
GRAPHICAL RAIL, CARRIAGE, BOOM, HOOK
MODEL CRANE, HANGING
MOTION WORK
RAIL :- BOX WIDTH 4.0, HEIGHT 0.2, DEPTH 1.0, LIGHTNESS 30.0
CARRIAGE :- BOX WIDTH 0.5, HEIGHT 0.5, DEPTH 0.5
BOOM :- BOX AT (0.0, 1.0, 0.0), WIDTH 0.2, HEIGHT 2.0, DEPTH 0.2, LIGHTNESS 70.0
HOOK :- BOX WIDTH 0.3, HEIGHT 0.1, DEPTH 0.3
STARTMODEL CRANE
  JOINT 1, RAIL, (-1.5, 0.1, 0.0), CARRIAGE, (0.0, -0.25, 0.0), SLIDE (0.0, 3.0), (-0.2, 0.2)
  JOINT 2, CARRIAGE, (0.0, 0.25, 0.0), BOOM, (0.0, 0.0, 0.0), (-90.0, 90.0), (-30.0, 30.0) AXIS (1.0, 1.0, 0.0)
  JOINT 3, BOOM, (0.0, 2.0, 0.0), HOOK, (0.0, 0.05, 0.0), SLIDE (-0.5, 0.5), (-0.5, 0.5), (-0.5, 0.5)
ENDMODEL
HANGING :- CRANE <SCALE MODEL 0.5>
FIGURE HANGING MAIN LINK BOOM
STARTMOTION WORK
  JOINT 1 POSITION 0.0, 0.0, 0.0
    FRAME 10 POSITION 2.5, 0.15, 0.0
  JOINT 2 POSITION -60.0, 10.0, 0.0
    FRAME 10 POSITION 70.0, -25.0, 0.0
  JOINT 3 POSITION 0.0, 0.0, 0.0
    FRAME 10 POSITION 0.3, -0.4, 0.2
ENDMOTION
INITIALIZE SCENE 1
STARTSCENE LENGTH 11
  ANIMATE CRANE FROM 0 TO 10 USING WORK
  ANIMATE HANGING FROM 0 TO 10 USING WORK
  HANGING :- HANGING <ROT Y 30.0> <TRANS (0.5, 2.0, 1.0)>
ENDSCENE
SHOOTSCENES
"""


# A figure built from a re-rooted submodel (thesis 3.3 and 3.5): the arm, re-rooted at its HAND,
# is attached to the body by the hand, so its wrist (an inverted slide about its own AXIS) and
# elbow are walked from their secondaries; a mirrored copy is re-rooted again at the UPPER arm.
GRAFTED = """\
GRAPHICAL BODY, UPPER, LOWER, HAND
MODEL ARM, BOT, SPUN
MOTION WAVE
BODY :- BOX WIDTH 0.6, HEIGHT 1.0, DEPTH 0.4, LIGHTNESS 30.0
UPPER :- BOX AT (0.0, -0.3, 0.0), WIDTH 0.15, HEIGHT 0.6, DEPTH 0.15
LOWER :- BOX AT (0.0, -0.25, 0.0), WIDTH 0.12, HEIGHT 0.5, DEPTH 0.12, LIGHTNESS 60.0
HAND :- BOX WIDTH 0.2, HEIGHT 0.1, DEPTH 0.2, LIGHTNESS 80.0
STARTMODEL ARM
  JOINT 1, UPPER, (0.0, -0.6, 0.0), LOWER, (0.0, 0.0, 0.0), (-10.0, 120.0), (-30.0, 30.0), (-45.0, 45.0)
  JOINT 2, LOWER, (0.0, -0.5, 0.0), HAND, (0.0, 0.05, 0.0), SLIDE (-0.1, 0.1), (0.0, 0.0), (-0.1, 0.1) AXIS (1.0, 1.0, 0.0)
ENDMODEL
FIGURE ARM MAIN LINK HAND
BOT :- JOINT 3, BODY, (0.3, 0.5, 0.0), ARM, (0.0, -0.05, 0.0), (-90.0, 90.0), (-180.0, 180.0), (-60.0, 60.0) AXIS (0.0, 1.0, 1.0)
SPUN :- BOT <SCALE MODEL -0.5>
FIGURE SPUN MAIN LINK UPPER
STARTMOTION WAVE
  JOINT 1 POSITION 10.0, 0.0, 0.0
    FRAME 10 POSITION 100.0, 20.0, -30.0 INTERPOLATE ACCDCC
  JOINT 2 POSITION 0.0, 0.0, 0.0
    FRAME 10 POSITION 0.08, 0.0, -0.05
  JOINT 3 POSITION 0.0, 0.0, 0.0
    FRAME 10 POSITION 60.0, 150.0, -40.0
ENDMOTION
INITIALIZE SCENE 1
STARTSCENE LENGTH 11
  ANIMATE BOT FROM 0 TO 10 USING WAVE
  ANIMATE SPUN FROM 0 TO 10 USING WAVE
  SPUN :- SPUN <ROT Y 30.0> <TRANS (1.5, 0.5, 0.0)>
ENDSCENE
SHOOTSCENES
"""


def program_named(tmp_path, name):
    """A compiled program: ``edges``, ``crane``, ``grafted`` or ``walking_humanoid`` (above), or an example's name."""
    from paths import ROOT_DIR

    from liganimate.compiler import load_program

    if name == "edges":
        path = tmp_path / "edges.lig"
        path.write_text(EDGES)
    elif name == "crane":
        path = tmp_path / "crane.lig"
        path.write_text(CRANE)
    elif name == "grafted":
        path = tmp_path / "grafted.lig"
        path.write_text(GRAFTED)
    elif name == "walking_humanoid":
        path = tmp_path / "walk.lig"
        path.write_text(WALKING_HUMANOID)
    else:
        path = os.path.join(ROOT_DIR, "examples", name + ".lig")
    program, _ = load_program(str(path))
    return program


PROGRAMS = [
    "edges",
    "walking_humanoid",
    "crane",
    "grafted",
    "appendix_a",
    "rerooting",
    "big_and_small_robot",
    "there_and_back",
]


# -- real clients: three.js in node, Blender's bpy ---------------------------------

THREE_DIR = os.path.join(HERE, ".cache", "three")
THREE_MODULE = os.path.join(THREE_DIR, "node_modules", "three")
THREE_POSE_JS = os.path.join(HERE, "exchange_tools", "three_pose.mjs")
BPY_DIR = os.path.join(HERE, ".cache", "bpy")
BLENDER_POSE_PY = os.path.join(HERE, "exchange_tools", "blender_pose.py")
# Blender's Python module: 4.5 is Blender's long-term-support line; its wheel
# is built for CPython 3.11 only (about 370 MB, 950 MB installed; `import bpy`
# takes under a second).  It pins numpy < 2, so it lives in a venv of its own
# under tests/.cache rather than in the test extra, where it would hold the
# whole suite to numpy 1.
BPY_VERSION = "4.5.15"
BPY_PYTHON = (3, 11)


def _missing(message: str):
    """Fail under CI, where every client must run; elsewhere skip, saying why."""
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)


def three_or_skip() -> str:
    """The three.js package folder, installed from npm into tests/.cache the first time.

    Skips only outside CI, and says why; in CI a missing node or npm fails.
    """
    node, npm = shutil.which("node"), shutil.which("npm")
    missing = [n for n, p in (("node", node), ("npm", npm)) if p is None]
    if missing:
        _missing(f"{' and '.join(missing)} not found, so three.js cannot load the exported files here")
    if not os.path.isfile(os.path.join(THREE_MODULE, "build", "three.module.js")):
        os.makedirs(THREE_DIR, exist_ok=True)
        r = subprocess.run(
            [npm, "install", "--no-audit", "--no-fund", "--prefix", THREE_DIR, "three"],
            check=False,
            capture_output=True,
            text=True,
            timeout=600,
        )
        if r.returncode != 0 or not os.path.isfile(os.path.join(THREE_MODULE, "build", "three.module.js")):
            _missing(f"npm install three failed:\n{r.stdout}\n{r.stderr}")
    return THREE_MODULE


def three_pose(path: str, times) -> dict:
    """What three.js's GLTFLoader and AnimationMixer make of a file at each time (see three_pose.mjs)."""
    module = three_or_skip()
    r = subprocess.run(
        ["node", THREE_POSE_JS, module, path, *(repr(float(t)) for t in times)],
        check=False,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def _python_311():
    import sys

    if sys.version_info[:2] == BPY_PYTHON:
        return sys.executable
    return shutil.which("python{}.{}".format(*BPY_PYTHON))


def bpy_python_or_skip() -> str:
    """A Python that imports Blender's ``bpy``: a venv in tests/.cache, made the first time.

    Skips only outside CI, and says why; in CI a missing Python 3.11 or a
    failed install fails.
    """
    python = os.path.join(BPY_DIR, "bin", "python")
    marker = os.path.join(BPY_DIR, f"bpy-{BPY_VERSION}.ok")
    if os.path.isfile(marker):
        return python
    base = _python_311()
    if base is None:
        _missing("Blender's bpy {} needs CPython {}.{}, which is not here".format(BPY_VERSION, *BPY_PYTHON))
    steps = [
        [base, "-m", "venv", "--clear", BPY_DIR],
        [python, "-m", "pip", "install", "--no-input", "--disable-pip-version-check", f"bpy=={BPY_VERSION}"],
        [python, "-c", "import bpy"],
    ]
    for cmd in steps:
        r = subprocess.run(cmd, check=False, capture_output=True, text=True, timeout=1200)
        if r.returncode != 0:
            _missing(f"installing Blender's bpy failed at {' '.join(cmd[:4])}:\n{r.stdout[-2000:]}\n{r.stderr[-2000:]}")
    with open(marker, "w", encoding="utf-8") as fh:
        fh.write(BPY_VERSION + "\n")
    return python


def blender_pose(path: str, fps: float, frames) -> dict:
    """What Blender's glTF importer makes of a file at each frame (see blender_pose.py)."""
    python = bpy_python_or_skip()
    out = path + ".blender.json"
    r = subprocess.run(
        [python, BLENDER_POSE_PY, path, out, repr(float(fps)), *(str(int(f)) for f in frames)],
        check=False,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    with open(out, encoding="utf-8") as fh:
        return json.load(fh)


# -- pinocchio: an independent URDF reader (the robotics library, `pin` on PyPI) ------------


def pinocchio_links(path, q_by_joint: dict) -> dict:
    """Each URDF link's placement in the root link's frame, by pinocchio's forward kinematics.

    ``q_by_joint`` gives a joint's position (radians or metres) by URDF joint
    name; joints not in it stay at zero.  A continuous joint is pinocchio's
    unbounded revolute (``cos q, sin q``); a mimic joint is read as a joint
    of its own, so the caller gives its value (the URDF's formula).
    """
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    q = pin.neutral(model)
    for jid in range(1, model.njoints):
        joint = model.joints[jid]
        value = float(q_by_joint.get(model.names[jid], 0.0))
        if joint.nq == 2:  # continuous: a point on the unit circle
            q[joint.idx_q], q[joint.idx_q + 1] = math.cos(value), math.sin(value)
        else:
            q[joint.idx_q] = value
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    return {f.name: data.oMf[i].homogeneous.copy() for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY}
