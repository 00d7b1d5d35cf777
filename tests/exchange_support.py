"""Helpers for the exchange tests: the glTF-Validator, an independent glTF pose reader, --poses records.

Nothing here uses liganimate's exchange code: the validator is Khronos's,
glTF files are read with pygltflib and posed by the plain node-graph walk
below, and pose records come from ``Program.render(poses=...)``, as
``liganimate run --poses`` writes them.
"""

from __future__ import annotations

import json
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
