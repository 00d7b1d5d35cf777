"""The exported glTF in the clients people use: three.js (GLTFLoader, AnimationMixer) and Blender (bpy).

Each client loads the file and plays it at tick times ``k / fps``; what it
shows is compared with ``--poses`` (``Program.render(poses=...)``):

* skin rig: one SkinnedMesh (three.js) / one armature with a skinned mesh
  (Blender) per drawn model, one bone per link; every bone's world position
  is its joint's pivot as posed, every deformed vertex is where the
  renderer draws it, within 1e-5 of the figure's size;
* nodes rig: every segment node's world matrix is the segment's --poses
  matrix;
* in both, sampling at ``k / fps`` shows tick ``k`` (STEP keys included),
  and a file written with round-to-nearest key times is caught.
"""

from __future__ import annotations

import numpy as np
import pytest
from exchange_support import blender_pose, pose_records, program_named, three_pose
from scipy.spatial import cKDTree

from liganimate.runtime import exchange as X
from liganimate.runtime.exchange import _gltf

FPS = 24.0
# Figures the rig must carry: a mirrored, re-rooted, unevenly scaled model
# shown part of the time beside a STEP scene (edges), the library humanoid
# walking, sliding and AXIS joints walked both ways (crane), a re-rooted figure, SCALE MODEL figures,
# Appendix A's figure.
SKINNED = ["edges", "walking_humanoid", "crane", "rerooting", "big_and_small_robot", "appendix_a"]


def _export(program, path, rig, fps=FPS):
    data, _ = X.gltf_bytes(X.collect(program), path.endswith(".glb"), fps=fps, rig=rig)
    with open(path, "wb") as fh:
        fh.write(data)


def _by_tick(records):
    """``{(scene, tick): {model: record}}``."""
    out: dict = {}
    for rec in records:
        out.setdefault((rec["scene"], rec["tick"]), {})[rec["model"]] = rec
    return out


def _ticks_to_check(records, scene, count=4):
    ticks = sorted({r["tick"] for r in records if r["scene"] == scene})
    pick = np.unique(np.linspace(0, len(ticks) - 1, count).round().astype(int))
    return [ticks[i] for i in pick]


def _figures(program):
    """``{(scene, model): figure}`` as drawn (structure only: links, joints, current main link)."""
    return {(take.id, m.name): m.figure for take in X.collect(program) for m in take.models}


def _pivots(fig) -> np.ndarray:
    """Each link's pivot on its own link: where the joint that moves it (walking from the main link) sits."""
    pivot = np.zeros((fig.n_links, 3))
    loc1, loc2 = fig.locations
    for level in fig.traversal:
        for k, c, r in zip(level.joints, level.children, level.reversed):
            pivot[c] = loc1[k] if r else loc2[k]
    return pivot


def _expected(fig, rec):
    """(bone world positions (L, 3), drawn vertices (N, 3), size) of one model at one tick, from --poses."""
    M = np.array([np.array(s["matrix"]).reshape(4, 4) for s in rec["segments"]])
    scales = fig.link_scales
    pivots = _pivots(fig)
    joints = np.einsum("lij,lj->li", M[:, :3, :3], pivots / scales[:, None]) + M[:, :3, 3]
    points = []
    for i, link in enumerate(fig.links):
        tris = getattr(link.shape, "triangles", np.zeros((0, 3, 3))).reshape(-1, 3)
        points.append(tris @ M[i, :3, :3].T + M[i, :3, 3])
    verts = np.concatenate(points)
    size = float(np.linalg.norm(np.ptp(np.concatenate([verts, joints]), axis=0)))
    return joints, verts, size


def _same_points(got, expected, tol, what):
    """Every point of ``got`` has one of ``expected`` within ``tol``, and the other way round."""
    got = np.asarray(got, dtype=np.float64).reshape(-1, 3)
    assert len(got) == len(expected), what
    d1, _ = cKDTree(expected).query(got)
    d2, _ = cKDTree(got).query(expected)
    assert max(d1.max(), d2.max()) <= tol, f"{what}: off by {max(d1.max(), d2.max()):.3g} > {tol:.3g}"


# -- three.js ------------------------------------------------------------------------


def _three_skin(program, tmp_path, fps=FPS):
    path = str(tmp_path / "film.glb")
    _export(program, path, "skin", fps)
    records = pose_records(program, tmp_path)
    ticks = sorted({r["tick"] for r in records})
    seen = three_pose(path, [t / fps for t in ticks])
    return records, ticks, seen


@pytest.mark.parametrize("name", SKINNED)
def test_three_js_sees_a_skinned_mesh_per_model_posed_as_drawn(tmp_path, name):
    program = program_named(tmp_path, name)
    figures = _figures(program)
    records, ticks, seen = _three_skin(program, tmp_path)
    by_tick = _by_tick(records)
    checked = 0
    for s, scene in enumerate(seen["scenes"]):
        scene_id = int(scene["name"].split("_")[-1])
        models = {m["skeletonExtras"][0]["liganimate"]["model"]: n for n, m in enumerate(scene["skinned"])}
        drawn = {model for (sid, model) in figures if sid == scene_id}
        assert set(models) == drawn
        for model, n in models.items():
            fig = figures[(scene_id, model)]
            skinned = scene["skinned"][n]
            # One bone per link, named as the program names the segments.
            assert len(skinned["skeleton"]) == fig.n_links
            segments = [e["liganimate"]["segment"] for e in skinned["skeletonExtras"]]
            assert sorted(segments) == list(range(fig.n_links))
            assert skinned["vertices"] == 3 * sum(len(getattr(l.shape, "triangles", ())) for l in fig.links)
        for tick in _ticks_to_check(records, scene_id):
            shown = scene["ticks"][ticks.index(tick)]
            for model, rec in by_tick[(scene_id, tick)].items():
                fig = figures[(scene_id, model)]
                joints, verts, size = _expected(fig, rec)
                got = shown["skinned"][models[model]]
                segments = [e["liganimate"]["segment"] for e in scene["skinned"][models[model]]["skeletonExtras"]]
                bones = np.array([np.array(m).reshape(4, 4).T[:3, 3] for m in got["bones"]])
                where = f"scene {scene_id} tick {tick} {model}"
                np.testing.assert_allclose(bones, joints[segments], rtol=0, atol=1e-5 * size, err_msg=where)
                _same_points(got["vertices"], verts, 1e-5 * size, where)
                checked += 1
    assert checked >= 4


def test_three_js_plays_a_scene_for_its_whole_length(tmp_path):
    """The clip lasts length / fps, so a looping mixer shows the last tick at its time, not the first."""
    program = program_named(tmp_path, "walking_humanoid")
    records, ticks, seen = _three_skin(program, tmp_path)
    assert seen["animations"][0]["duration"] == pytest.approx(30 / FPS)


@pytest.mark.parametrize("rig", X.RIGS)
def test_three_js_sampling_at_k_over_fps_sees_tick_k(tmp_path, rig):
    """SAMEFRAME scenes hold each tick (STEP keys): the mixer at exactly k / fps must show tick k."""
    _check_step_scene(tmp_path, rig, expect_exact=True)


def test_round_to_nearest_key_times_would_show_the_tick_before(tmp_path, monkeypatch):
    """The check above can fail: float32(k / fps) rounded to nearest lands after k / fps for some k."""
    ticks = np.arange(2000)
    nearest = (ticks / FPS).astype(np.float32)
    assert (nearest.astype(np.float64) > ticks / FPS).any()
    assert (X.key_times(ticks, FPS).astype(np.float64) <= ticks / FPS).all()
    monkeypatch.setattr(_gltf, "key_times", lambda t, fps: (np.asarray(t) / fps).astype(np.float32))
    _check_step_scene(tmp_path, "nodes", expect_exact=False, fps=30.0)


STEPPING = """\
      GRAPHICAL A, B
      MODEL ARM
      MOTION SWING
      A :- BOX WIDTH 0.2, HEIGHT 1.0, DEPTH 0.2
      B :- BOX WIDTH 0.15, HEIGHT 0.8, DEPTH 0.15
      ARM :- JOINT 1, A, (0.0, 0.5, 0.0), B, (0.0, -0.4, 0.0), (-180.0, 180.0), (-180.0, 180.0), (-180.0, 180.0)
      STARTMOTION SWING
        JOINT 1 POSITION 0.0, 0.0, 0.0
          FRAME 120 POSITION 0.0, 0.0, 240.0
      ENDMOTION
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 120 SAMEFRAME 2
        ANIMATE ARM FROM 0 TO 119 USING SWING
      ENDSCENE
      SHOOTSCENES
"""


def _check_step_scene(tmp_path, rig, expect_exact, fps=FPS):
    src = tmp_path / "step.lig"
    src.write_text(STEPPING)
    from liganimate.compiler import load_program

    program, _ = load_program(str(src))
    path = str(tmp_path / "step.glb")
    _export(program, path, rig, fps)
    records = pose_records(program, tmp_path)
    ticks = [r["tick"] for r in records]
    seen = three_pose(path, [t / fps for t in ticks])["scenes"][0]
    fig = _figures(program)[(1, "ARM")]
    # Every tick turns the arm (2 degrees, less where LINEAR ramps its speed at the ends), so showing
    # the tick before is far more than the tolerance off.
    axes = [np.array(r["segments"][1]["matrix"]).reshape(4, 4)[:3, 1] for r in records]
    assert min(np.linalg.norm(np.diff(axes, axis=0), axis=1)) > 1e-3
    wrong = []
    for rec, shown in zip(records, seen["ticks"]):
        joints, _, size = _expected(fig, rec)
        if rig == "skin":
            got = np.array([np.array(m).reshape(4, 4).T[:3, 3] for m in shown["skinned"][0]["bones"]])
            segments = [e["liganimate"]["segment"] for e in seen["skinned"][0]["skeletonExtras"]]
            ok = np.allclose(got, joints[segments], rtol=0, atol=1e-5 * size)
        else:
            expected = {i: np.array(s["matrix"]).reshape(4, 4) for i, s in enumerate(rec["segments"])}
            got = {s["segment"]: np.array(s["matrix"]).reshape(4, 4).T for s in shown["segments"]}
            ok = all(np.allclose(got[i], expected[i], rtol=0, atol=1e-5 * size) for i in expected)
        if not ok:
            wrong.append(rec["tick"])
    if expect_exact:
        assert wrong == []
    else:
        assert wrong, "round-to-nearest key times should have shown some tick's predecessor"


# -- Blender ---------------------------------------------------------------------------


def _blender(x):
    """glTF's +Y-up coordinates as Blender's importer turns them: +Z up, glTF's +Z to Blender's -Y."""
    x = np.asarray(x, dtype=np.float64)
    return np.stack([x[..., 0], -x[..., 2], x[..., 1]], axis=-1)


@pytest.mark.parametrize("name", ["walking_humanoid", "edges", "crane", "rerooting"])
def test_blender_makes_an_armature_per_model_posed_as_drawn(tmp_path, name):
    program = program_named(tmp_path, name)
    figures = _figures(program)
    path = str(tmp_path / "film.glb")
    _export(program, path, "skin", 30.0)
    records = [r for r in pose_records(program, tmp_path) if r["scene"] == 1]
    frames = _ticks_to_check(records, 1)
    seen = blender_pose(path, 30.0, frames)
    drawn = {model: fig for (sid, model), fig in figures.items() if sid == 1}
    armatures = {a["name"]: a for a in seen["armatures"]}
    # One armature per model of every scene (Blender imports them all), named after the model node:
    # the MODEL's name where it first appears.
    assert len(armatures) == len(figures) and set(drawn) <= set(armatures)
    for model, fig in drawn.items():
        assert len(armatures[model]["bones"]) == fig.n_links
        meshes = [m for m in seen["meshes"] if m["armatures"] == [model]]
        assert len(meshes) == 1 and meshes[0]["parent"] == model
        assert meshes[0]["vertices"] == 3 * sum(len(getattr(l.shape, "triangles", ())) for l in fig.links)
        assert meshes[0]["colours"], "the triangles' colours come in as a colour attribute"
    by_tick = _by_tick(records)
    from exchange_support import load_gltf

    doc, _ = load_gltf(path)
    segment_of = {}
    for skin in doc.skins:
        for j in skin.joints:
            info = doc.nodes[j].extras["liganimate"]
            segment_of[(info["model"], doc.nodes[j].name)] = info["segment"]
    for f, shown in zip(frames, seen["frames"]):
        for model, rec in by_tick[(1, f)].items():
            joints, verts, size = _expected(drawn[model], rec)
            heads = shown["bones"][model]
            got = np.array([heads[name] for (m, name) in segment_of if m == model])
            want = _blender(np.array([joints[segment_of[(model, name)]] for (m, name) in segment_of if m == model]))
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-5 * size, err_msg=f"frame {f} {model}")
            mesh = next(m["name"] for m in seen["meshes"] if m["armatures"] == [model])
            _same_points(shown["vertices"][mesh], _blender(verts), 1e-5 * size, f"frame {f} {model}")


# -- imported captures keep their names -------------------------------------------------------

CAPTURE_PLAY = """\
      LOAD FIG, MOT FROM 'cap.lig'
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 12
        ANIMATE FIG FROM 0 TO 11 USING MOT
      ENDSCENE
      SHOOTSCENES
"""


@pytest.mark.filterwarnings("ignore:Importing PyGLM:PendingDeprecationWarning")
@pytest.mark.parametrize("name", ["mixamo", "rigify"])
def test_an_imported_capture_keeps_its_names_and_root_in_both_clients(tmp_path, name):
    """Bones are the capture's joints by their own names (``mixamorig:Hips``), with no ORIGIN root added."""
    import re
    import subprocess
    import sys

    from captures import capture

    src = capture(name)
    r = subprocess.run(
        [sys.executable, "-m", "liganimate", "import", src, "-o", str(tmp_path / "cap.lig")]
        + ["--model", "FIG", "--motion", "MOT", "--joint-translation", "drop", "--quiet"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    with open(src, encoding="utf-8") as fh:
        source_names = re.findall(r"(?:ROOT|JOINT)\s+(\S[^\r\n]*?)\s*$", fh.read().split("MOTION")[0], re.M)
    (tmp_path / "play.lig").write_text(CAPTURE_PLAY)
    from liganimate.compiler import load_program

    program, _ = load_program(str(tmp_path / "play.lig"))
    path = str(tmp_path / "film.glb")
    _export(program, path, "skin", 30.0)
    fig = _figures(program)[(1, "FIG")]
    records = pose_records(program, tmp_path)
    seen = three_pose(path, [t / 30.0 for t in range(12)])["scenes"][0]
    (skinned,) = seen["skinned"]
    # three.js strips characters its property paths reserve (':' '.'), so compare with the file's names too.
    from exchange_support import load_gltf

    doc, _ = load_gltf(path)
    (skin,) = doc.skins
    assert [doc.nodes[j].name for j in skin.joints][0] == source_names[0]
    assert sorted(doc.nodes[j].name for j in skin.joints) == sorted(source_names)
    assert len(skinned["skeleton"]) == len(source_names) == fig.n_links - 1  # no bone for ORIGIN
    segments = [e["liganimate"]["segment"] for e in skinned["skeletonExtras"]]
    for tick in (0, 5, 11):
        joints, verts, size = _expected(fig, records[tick])
        got = seen["ticks"][tick]["skinned"][0]
        bones = np.array([np.array(m).reshape(4, 4).T[:3, 3] for m in got["bones"]])
        np.testing.assert_allclose(bones, joints[segments], rtol=0, atol=1e-5 * size, err_msg=f"tick {tick}")
        _same_points(got["vertices"], verts, 1e-5 * size, f"tick {tick}")
    blender = blender_pose(path, 30.0, [0, 11])
    (armature,) = blender["armatures"]
    assert sorted(armature["bones"]) == sorted(source_names)
    for f, shown in zip((0, 11), blender["frames"]):
        joints, verts, size = _expected(fig, records[f])
        named = {doc.nodes[j].name: doc.nodes[j].extras["liganimate"]["segment"] for j in skin.joints}
        heads = shown["bones"][armature["name"]]
        got = np.array([heads[n] for n in named])
        want = _blender(np.array([joints[s] for s in named.values()]))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-5 * size, err_msg=f"frame {f}")
