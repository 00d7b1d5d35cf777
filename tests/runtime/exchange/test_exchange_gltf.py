"""glTF export, checked by Khronos's glTF-Validator and by an independent reader against --poses."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from exchange_support import (
    EDGES,
    PROGRAMS,
    WALKING_HUMANOID,
    load_gltf,
    pose_records,
    program_named,
    sample_channels,
    segment_nodes,
    validate,
    world_transforms,
)

from liganimate.runtime import exchange as X

FPS = 24.0


def _export(program, path, rig="nodes"):
    scenes = X.collect(program)
    data, warnings = X.gltf_bytes(scenes, path.endswith(".glb"), fps=FPS, rig=rig)
    with open(path, "wb") as fh:
        fh.write(data)
    return scenes, warnings


@pytest.mark.parametrize("rig", X.RIGS)
@pytest.mark.parametrize("name", PROGRAMS)
def test_validator_reports_no_errors(tmp_path, name, rig):
    program = program_named(tmp_path, name)
    paths = [str(tmp_path / f"{name}.glb"), str(tmp_path / f"{name}.gltf")]
    for p in paths:
        _export(program, p, rig)
    reports = validate(paths)
    for p in paths:
        issues = reports[p]
        errors = [m for m in issues["messages"] if m["severity"] == 0]
        assert issues["numErrors"] == 0, errors[:5]
        assert issues["numWarnings"] == 0, issues["messages"][:5]


def test_validator_catches_a_broken_file(tmp_path):
    """The check can fail: the same export with a POSITION accessor's bounds spoiled is reported."""
    program = program_named(tmp_path, "appendix_a")
    doc, blob, _ = X.gltf_document(X.collect(program))
    acc = doc.meshes[0].primitives[0].attributes.POSITION
    doc.accessors[acc].max = [v - 1.0 for v in doc.accessors[acc].max]
    doc.set_binary_blob(blob)
    path = str(tmp_path / "broken.glb")
    with open(path, "wb") as fh:
        fh.write(b"".join(doc.save_to_bytes()))
    assert validate([path])[path]["numErrors"] > 0


@pytest.mark.parametrize("name", PROGRAMS)
@pytest.mark.parametrize("ext", [".glb", ".gltf"])
def test_node_world_transforms_equal_the_pose_record(tmp_path, name, ext):
    program = program_named(tmp_path, name)
    path = str(tmp_path / f"out{ext}")
    _export(program, path)
    doc, blob = load_gltf(path)
    records = pose_records(program, tmp_path)
    assert records
    scene_index = {s.name: i for i, s in enumerate(doc.scenes)}
    animations = {a.name: a for a in doc.animations}
    segments = segment_nodes(doc)
    checked = 0
    cache: dict = {}
    for rec in records:
        key = (rec["scene"], rec["tick"])
        if key not in cache:
            anim = animations.get(f"scene {rec['scene']}")
            override = sample_channels(doc, blob, anim, rec["tick"] / FPS) if anim is not None else {}
            cache[key] = world_transforms(doc, scene_index[f"scene {rec['scene']}"], override)
        worlds = cache[key]
        for i, seg in enumerate(rec["segments"]):
            node = segments[(rec["scene"], rec["model"], i)]
            expected = np.array(seg["matrix"]).reshape(4, 4)
            np.testing.assert_allclose(
                worlds[node],
                expected,
                rtol=0,
                atol=1e-5,
                err_msg=f"scene {rec['scene']} tick {rec['tick']} {rec['model']} segment {i}",
            )
            checked += 1
    assert checked == sum(len(r["segments"]) for r in records)


def test_sampling_is_linear_but_steps_at_sameframe_holds(tmp_path):
    doc, _ = _export_and_load(tmp_path, "edges")
    by_name = {a.name: a for a in doc.animations}
    assert {s.interpolation for s in by_name["scene 1"].samplers if s.interpolation != "STEP"} == {"LINEAR"}
    assert {s.interpolation for s in by_name["scene 2"].samplers} == {"STEP"}


def _export_and_load(tmp_path, name, ext=".glb", rig="nodes"):
    program = program_named(tmp_path, name)
    path = str(tmp_path / f"x{ext}")
    _export(program, path, rig)
    return load_gltf(path)


def test_a_model_not_drawn_at_a_tick_is_shrunk_to_nothing_there(tmp_path):
    doc, blob = _export_and_load(tmp_path, "edges")
    anim = next(a for a in doc.animations if a.name == "scene 1")
    mirror = next(n for n, node in enumerate(doc.nodes) if node.name == "MIRROR")
    for tick, shown in [(0, False), (2, False), (3, True), (8, True), (9, False), (11, False)]:
        scale = sample_channels(doc, blob, anim, tick / FPS)[mirror]["scale"]
        assert (np.abs(scale) > 0).all() == shown, (tick, scale)


def test_the_camera_is_the_view(tmp_path):
    doc, blob = _export_and_load(tmp_path, "edges")
    anim = next(a for a in doc.animations if a.name == "scene 1")
    cam_node = next(
        n for n, node in enumerate(doc.nodes) if node.camera is not None and node.name.startswith("scene 1")
    )
    cam = doc.cameras[doc.nodes[cam_node].camera].perspective
    for tick in (0, 5, 11):
        worlds = world_transforms(doc, 0, sample_channels(doc, blob, anim, tick / FPS))
        M = worlds[cam_node]
        point = np.array([1.0, 2.0, 6.0]) + 0.1 * (tick + 1) * np.array([1.0, 0.5, 0.0])
        np.testing.assert_allclose(M[:3, 3], point, atol=1e-5)
        looking = -M[:3, 2]  # a glTF camera looks down its -Z
        np.testing.assert_allclose(looking, -point / np.linalg.norm(point), atol=1e-6)
        assert M[1, 1] > 0  # +Y up
    # VIEW WIDTH 10 (the default) across a 4:3 image, at the eye's distance at tick 0.
    d = np.linalg.norm([1.1, 2.05, 6.0])
    assert cam.yfov == pytest.approx(2 * np.arctan(10.0 * 0.75 / 2 / d))
    assert cam.aspectRatio == pytest.approx(4 / 3)


def test_segments_carry_meshes_with_lightness_materials(tmp_path):
    doc, _ = _export_and_load(tmp_path, "edges")
    greys = set()
    for mesh in doc.meshes:
        for prim in mesh.primitives:
            greys.add(doc.materials[prim.material].name.split()[1])
    # LIGHTNESS 30, 60 and 40 (default), and 1.5 times each for a BOX's side faces.
    assert {"77", "153", "102", "115", "229"} <= greys  # 90 * 2.55 rounds to 229
    factors = {m.name: m.pbrMetallicRoughness.baseColorFactor[0] for m in doc.materials}
    assert factors["grey 77"] < factors["grey 153"]


def test_a_sheared_placement_is_refused_and_nothing_written(tmp_path):
    text = EDGES.replace("<SCALE (1.0, 2.0, 1.0)> <ROT Y 30.0>", "<ROT Z 30.0> <SCALE (1.0, 2.0, 1.0)>")
    src = tmp_path / "shear.lig"
    src.write_text(text)
    out = tmp_path / "shear.glb"
    r = subprocess.run(
        [sys.executable, "-m", "liganimate", "export", str(src), "-o", str(out)],
        check=False,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 1
    assert "shear" in r.stderr and "Traceback" not in r.stderr
    assert not out.exists()
    assert os.listdir(tmp_path) == ["shear.lig"]


def test_cli_export_writes_a_valid_glb(tmp_path):
    src = tmp_path / "walk.lig"
    src.write_text(WALKING_HUMANOID)
    out = tmp_path / "film.glb"
    r = subprocess.run(
        [sys.executable, "-m", "liganimate", "export", str(src), "-o", str(out), "--fps", "30"],
        check=False,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr
    doc, blob = load_gltf(str(out))
    times = [sampler.input for a in doc.animations for sampler in a.samplers]
    from exchange_support import accessor

    # Ticks 0..29 at 1/30 s, and the last one held a tick more: the 30-tick scene lasts one second.
    keys = accessor(doc, blob, times[0])[:, 0]
    assert keys[-2] == pytest.approx(29 / 30) and keys[-1] == pytest.approx(1.0)
    assert validate([str(out)])[str(out)]["numErrors"] == 0


def test_the_skin_rig_has_one_primitive_per_sidedness_and_vertex_colours(tmp_path):
    """The humanoid's 71 shades are vertex colours of one primitive, not 71 materials."""
    from exchange_support import accessor

    doc, blob = _export_and_load(tmp_path, "walking_humanoid", rig="skin")
    assert [m.name for m in doc.materials] == ["vertex colours"]
    (mesh,) = doc.meshes
    (prim,) = mesh.primitives
    colours = accessor(doc, blob, prim.attributes.COLOR_0)
    # sRGB grey levels back from the linear colours: the renderer's shades of the humanoid's triangles.
    levels = np.where(colours <= 0.0031308, colours * 12.92, 1.055 * colours ** (1 / 2.4) - 0.055) * 255
    assert np.abs(levels - levels.round()).max() < 1e-3
    assert len(np.unique(levels.round(), axis=0)) == 71
    (skin,) = doc.skins
    names = [doc.nodes[j].name for j in skin.joints]
    assert names[:4] == ["TOP", "R_HIP", "L_HIP", "SPINE"] and len(names) == 20


def test_cli_export_chooses_the_rig(tmp_path):
    src = tmp_path / "walk.lig"
    src.write_text(WALKING_HUMANOID)
    counts = {}
    for rig in ("skin", "nodes", None):
        out = tmp_path / f"{rig}.glb"
        cmd = [sys.executable, "-m", "liganimate", "export", str(src), "-o", str(out), "--quiet"]
        r = subprocess.run(cmd + (["--rig", rig] if rig else []), check=False, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        doc, _ = load_gltf(str(out))
        counts[rig] = (len(doc.skins), len(doc.meshes))
    assert counts == {"skin": (1, 1), "nodes": (0, 20), None: (1, 1)}
    r = subprocess.run(
        [sys.executable, "-m", "liganimate", "export", str(src), "-o", str(tmp_path / "x.glb"), "--rig", "bones"],
        check=False,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2 and "'bones' is not a glTF rig; the rigs are skin and nodes" in r.stderr
    assert not (tmp_path / "x.glb").exists()


@pytest.mark.parametrize("rig", X.RIGS)
def test_the_same_program_exports_the_same_bytes(tmp_path, rig):
    program = program_named(tmp_path, "edges")
    first, _ = X.gltf_bytes(X.collect(program), True, fps=FPS, rig=rig)
    again, _ = X.gltf_bytes(X.collect(program_named(tmp_path, "edges")), True, fps=FPS, rig=rig)
    assert first == again


def test_key_times_never_follow_the_tick_and_a_collision_is_refused():
    from liganimate.runtime.errors import LigError
    from liganimate.runtime.exchange import _gltf

    ticks = np.arange(100_000)
    for fps in (24.0, 25.0, 30.0, 60.0, 120.0, 29.97):
        t = X.key_times(ticks, fps)
        assert t.dtype == np.float32 and (t.astype(np.float64) <= ticks / fps).all()
        assert (np.diff(t) > 0).all()
        # Still the nearest float32 below: one step up is past the tick.
        assert (np.nextafter(t, np.float32(np.inf)).astype(np.float64) > ticks / fps).all()
    # At a million ticks a second, 16.777216 s and one tick later share a float32.
    b = _gltf.Builder(1e6, (640, 480), "skin")
    b.length = 2**25
    with pytest.raises(LigError, match="too long for glTF's 32-bit key times"):
        b._times(np.array([2**24, 2**24 + 1]))


NAMED_ARM = """\
      GRAPHICAL BASE, UPPER, LOWER
      MODEL ARM
      BASE :- BOX WIDTH 0.4, HEIGHT 0.2, DEPTH 0.4
      UPPER :- BOX AT (0.0, 0.5, 0.0), WIDTH 0.1, HEIGHT 1.0, DEPTH 0.1
      LOWER :- BOX AT (0.0, 0.4, 0.0), WIDTH 0.08, HEIGHT 0.8, DEPTH 0.08
      STARTMODEL ARM
        JOINT 1, BASE, (0.0, 0.1, 0.0), UPPER, (0.0, 0.0, 0.0), (-90.0, 90.0)
        JOINT 2, UPPER, (0.0, 1.0, 0.0), LOWER, (0.0, 0.0, 0.0), (-120.0, 120.0)
      ENDMODEL
{@names ARM
  BASE "base_link"
  UPPER "upper_arm_link" JOINT "shoulder_pan_joint"
  LOWER "forearm_link" JOINT "elbow_joint"
}
"""

PLAY_ARM = """\
      LOAD ARM FROM 'arm.lig'
      MOTION M
      STARTMOTION M
        JOINT 1 POSITION 0.0, 0.0, 0.0
          FRAME 5 POSITION 40.0, 0.0, 0.0
        JOINT 2 POSITION 0.0, 0.0, 0.0
          FRAME 5 POSITION 60.0, 0.0, 0.0
      ENDMOTION
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 6
        ANIMATE ARM FROM 0 TO 5 USING M
      ENDSCENE
      SHOOTSCENES
"""


def test_nodes_take_the_link_and_joint_names_of_the_source(tmp_path):
    """A library's name table (a URDF robot's links and joints) names the bones and the nodes."""
    from liganimate.compiler import load_program

    (tmp_path / "arm.lig").write_text(NAMED_ARM)
    (tmp_path / "play.lig").write_text(PLAY_ARM)
    program, _ = load_program(str(tmp_path / "play.lig"))
    names = {}
    for rig in X.RIGS:
        path = str(tmp_path / f"{rig}.glb")
        _export(program, path, rig)
        doc, _ = load_gltf(path)
        names[rig] = [n.name for n in doc.nodes if n.camera is None]
        if rig == "skin":
            (skin,) = doc.skins
            extras = [doc.nodes[j].extras["liganimate"].get("source_joint") for j in skin.joints]
            assert extras == [None, "shoulder_pan_joint", "elbow_joint"]
    assert names["skin"] == ["ARM", "base_link", "upper_arm_link", "forearm_link", "ARM mesh"]
    assert names["nodes"] == [
        "ARM",
        "ARM base_link",
        "ARM shoulder_pan_joint",
        "ARM upper_arm_link",
        "ARM elbow_joint",
        "ARM forearm_link",
    ]
