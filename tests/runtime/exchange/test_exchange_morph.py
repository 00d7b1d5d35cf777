"""Morphing segments exported: glTF scale channels and morph targets (Khronos validator, three.js), BVH's note.

The thesis' mailbox (examples/mailbox.lig) morphs every segment of its
figure (SHAPE LINK tracks) and scales its head (a SCALE LINK track).  Both
glTF rigs must pass the Khronos glTF-Validator, and three.js, playing the
file at ``k / fps``, must put every vertex where the renderer draws it at
tick ``k``: the skin rig's skinned mesh through its morph targets, the
nodes rig's shape nodes through their scale channels and morph targets.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from exchange_support import three_pose, validate
from paths import ROOT_DIR
from scipy.spatial import cKDTree

from liganimate.compiler import load_program
from liganimate.runtime import exchange as X
from liganimate.runtime.figure import pose as P

FPS = 24.0
TICKS = [0, 20, 30, 40, 47, 60]


@pytest.fixture(scope="module")
def mailbox():
    program, _ = load_program(os.path.join(ROOT_DIR, "examples", "mailbox.lig"))
    return program


def _export(program, path, rig):
    data, warnings = X.gltf_bytes(X.collect(program), True, fps=FPS, rig=rig)
    with open(path, "wb") as fh:
        fh.write(data)
    return warnings


def _drawn(program) -> dict:
    """The renderer's world triangles of the model at each tick, as (N, 3) points."""
    (take,) = X.collect(program)
    (model,) = take.models
    out = {}
    for rows, fig, motion, frames in model.sources:
        for row, frame in zip(rows, frames):
            tick = int(model.ticks[row])
            out[tick] = P.posed_graphical(fig, motion, float(frame)).triangles.reshape(-1, 3)
    return out


def _same_points(got, want, tol, what):
    got = np.asarray(got, dtype=np.float64).reshape(-1, 3)
    assert len(got) == len(want), what
    d1, _ = cKDTree(want).query(got)
    d2, _ = cKDTree(got).query(want)
    assert max(d1.max(), d2.max()) <= tol, f"{what}: off by {max(d1.max(), d2.max()):.3g}"


@pytest.mark.parametrize("rig", ["skin", "nodes"])
def test_the_khronos_validator_accepts_morph_targets_and_scale_channels(mailbox, tmp_path, rig):
    path = str(tmp_path / f"mailbox_{rig}.glb")
    _export(mailbox, path, rig)
    report = validate([path])[path]
    assert report["numErrors"] == 0, report["messages"][:5]


@pytest.mark.parametrize("rig", ["skin", "nodes"])
def test_three_js_draws_the_mailbox_becoming_a_human_as_the_renderer_does(mailbox, tmp_path, rig):
    path = str(tmp_path / f"mailbox_{rig}.glb")
    _export(mailbox, path, rig)
    seen = three_pose(path, [t / FPS for t in TICKS])
    drawn = _drawn(mailbox)
    (scene,) = seen["scenes"]
    size = float(np.linalg.norm(np.ptp(np.concatenate(list(drawn.values())), axis=0)))
    moved = []
    for tick, shown in zip(TICKS, scene["ticks"]):
        if rig == "skin":
            (skinned,) = shown["skinned"]
            got = np.asarray(skinned["vertices"])
        else:
            got = np.concatenate([np.asarray(m["vertices"]) for m in shown["morphed"]])
        _same_points(got, drawn[tick], 1e-5 * size, f"{rig} tick {tick}")
        moved.append(got)
    # The file really morphs: the mailbox (tick 0) and the human (tick 60) differ.
    assert np.abs(moved[0] - moved[-1]).max() > 0.1


def test_the_nodes_rig_scales_the_heads_shape_node_only(mailbox, tmp_path):
    import pygltflib

    path = str(tmp_path / "mailbox_nodes.glb")
    _export(mailbox, path, "nodes")
    doc = pygltflib.GLTF2().load(path)
    scaled = {doc.nodes[c.target.node].name for a in doc.animations for c in a.channels if c.target.path == "scale"}
    weighted = {doc.nodes[c.target.node].name for a in doc.animations for c in a.channels if c.target.path == "weights"}
    assert "HUMAN HEAD shape" in scaled and not any("joint" in n for n in scaled)
    assert {n.rsplit(" ", 2)[1] for n in weighted} == {"BODY", "HEAD", "LARM", "RARM", "LLEG", "RLEG"}


def test_bvh_export_drops_shape_and_scale_with_a_note(mailbox, tmp_path):
    from liganimate.runtime.exchange._formats import export_scenes

    result = export_scenes(X.collect(mailbox), str(tmp_path / "mailbox.bvh"))
    notes = " ".join(result.warnings)
    assert len(result.files) == 1
    assert "BVH" in notes and "SCALE LINK" in notes and "SHAPE LINK" in notes and "HUMAN" in notes
