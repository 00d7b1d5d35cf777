"""The studio's Save: a library LOAD takes, that `liganimate run` accepts, replaying the kept poses exactly."""

from __future__ import annotations

import os

import numpy as np
import pytest
from commands import liganimate

from liganimate.compiler import load_program
from liganimate.lang.diagnostics import LigDiagnostics
from liganimate.runtime import exchange as X
from liganimate.runtime.figure.pose import mesh_table, world_transforms, world_triangles
from liganimate.runtime.studio import Generator, Session, library_text, widened_extremes, write_library


def _posed(fig, seed=31):
    g = Generator(fig, seed=seed, intensity=0.9)
    g.take(0, 1)
    g.take(4, fig.n_joints - 1)
    g.keep()
    for k in range(3):
        g.next_generation()
        for j in range(0, fig.n_joints, 2):
            g.take((k + j) % 9, j)
        if k == 1:
            g.set_mode("twist")
        g.keep()
    return g


def _play(tmp_path, lib, model, motion, frames):
    prog = tmp_path / "play.lig"
    prog.write_text(
        f"      LOAD {model}, {motion} FROM '{lib.name}'\n"
        "      INITIALIZE SCENE 1\n"
        "        VIEW POINT = (0.0, 1.0, 8.0)\n"
        "        VIEW WIDTH = 4.0\n"
        f"      STARTSCENE LENGTH {frames}\n"
        f"        ANIMATE {model} FROM 0 TO {frames - 1} USING {motion}\n"
        "      ENDSCENE\n"
        "      SHOOTSCENES\n",
        encoding="utf-8",
    )
    program, _ = load_program(str(prog))
    return prog, X.collect(program)[0].models[0]


@pytest.mark.parametrize("which", ["humanoid", "human"])
def test_saved_library_replays_the_kept_poses_exactly(tmp_path, request, which):
    fig = request.getfixturevalue(which)
    g = _posed(fig)
    kept = np.array(g.kept)
    assert not ((kept >= np.asarray(fig.extremes)[..., 0]) & (kept <= np.asarray(fig.extremes)[..., 1])).all(), (
        "the run should have gone beyond an extreme, so that widening is exercised"
    )
    lib = tmp_path / "posed.lig"
    write_library(str(lib), library_text(fig, "POSED", "POSES", g.kept, spacing=10))
    _, take = _play(tmp_path, lib, "POSED", "POSES", 10 * (len(kept) - 1) + 1)
    at = np.arange(len(kept)) * 10
    # The angles drawn at the keyframes are the kept ones, to the bit.
    assert np.array_equal(take.angles[at], kept)
    # And so is the figure: the same triangles in the world (the library bakes SCALE MODEL into them).
    mine = world_triangles(mesh_table(fig), g.transforms(kept))
    theirs = world_triangles(
        mesh_table(take.figure), world_transforms(take.figure, take.angles[at], take.placements[at])
    )
    assert mine.shape == theirs.shape
    assert np.allclose(mine, theirs, atol=1e-7)
    # Extremes: widened exactly to what the poses need, locked axes still locked.
    ext = np.asarray(take.figure.extremes)
    assert np.array_equal(ext, widened_extremes(fig, kept))
    old = np.asarray(fig.extremes)
    locked = old[..., 0] == old[..., 1]
    assert np.array_equal(ext[locked], old[locked])


def test_liganimate_run_accepts_the_library_and_plays_it(tmp_path, humanoid):
    g = _posed(humanoid, seed=5)
    lib = tmp_path / "poses.lig"
    write_library(str(lib), library_text(humanoid, "HUMANOID", "POSES", g.kept))
    r = liganimate("run", str(lib), "-o", str(tmp_path / "lib_frames"), "--quiet", timeout=120)
    assert r.returncode == 0, r.stderr
    assert "error" not in r.stderr
    prog, _ = _play(tmp_path, lib, "HUMANOID", "POSES", 25)
    r = liganimate("run", str(prog), "-o", str(tmp_path / "frames"), "--quiet", timeout=120)
    assert r.returncode == 0, r.stderr
    assert len(os.listdir(tmp_path / "frames" / "scene1")) == 25


def test_library_names_segments_uniquely(human):
    """The Appendix A human has two FOOT, two BARM...: STARTMODEL needs one name per segment."""
    g = Generator(human, seed=1)
    g.keep()
    text = library_text(human, "HUMAN", "POSES", g.kept)
    assert "FOOT_2" in text and "BARM_2" in text
    assert text.count("PRIMITIVE ") < human.n_links  # shared shapes are drawn by one primitive


def test_a_library_that_would_not_compile_is_not_written(tmp_path, humanoid):
    lib = tmp_path / "poses.lig"
    lib.write_text("C the old library\n", encoding="utf-8")
    g = Generator(humanoid, seed=2)
    g.keep()
    text = library_text(humanoid, "HUMANOID", "POSES", g.kept).replace("ENDMODEL", "ENDMODLE")
    with pytest.raises(LigDiagnostics):
        write_library(str(lib), text)
    assert lib.read_text(encoding="utf-8") == "C the old library\n"
    assert os.listdir(tmp_path) == ["poses.lig"]  # no temporary file left behind


def _warm_session(tmp_path, humanoid, monkeypatch):
    from liganimate.runtime.studio import _session

    compiled = []
    real = _session.check_library
    monkeypatch.setattr(_session, "check_library", lambda text, path: (compiled.append(text), real(text, path)))
    s = Session(humanoid, "HUMANOID", "POSES", str(tmp_path / "poses.lig"), seed=4)
    s.warm()
    s._warming.join()
    return s, compiled


def test_save_after_the_warm_up_compiles_the_primitives_cut_short_and_writes_them_whole(
    tmp_path, humanoid, monkeypatch
):
    s, compiled = _warm_session(tmp_path, humanoid, monkeypatch)
    s.act({"action": "keep"})
    s.act({"action": "next"})
    s.act({"action": "take", "candidate": 2, "link": 3})
    s.act({"action": "keep"})
    s.act({"action": "save"})
    g = s.generator
    whole = library_text(humanoid, "HUMANOID", "POSES", g.kept, note=f"Seed {g.seed}, 2 pose(s) kept.")
    assert (tmp_path / "poses.lig").read_text(encoding="utf-8") == whole
    assert len(compiled) == 2  # the warm-up's whole library, then Save's
    assert len(compiled[1]) < len(whole) / 20
    assert whole.endswith(compiled[1][-2000:])  # the model and the motion are checked in full


def test_save_after_the_warm_up_still_refuses_a_library_that_would_not_compile(tmp_path, humanoid, monkeypatch):
    from liganimate.runtime.studio import _library, _session

    s, _ = _warm_session(tmp_path, humanoid, monkeypatch)
    real = _library.library

    def broken(*args, **kwargs):
        lib = real(*args, **kwargs)
        return _library.Library(lib.head, lib.shapes, lib.skeleton, lib.body.replace("ENDMODEL", "ENDMODLE"))

    monkeypatch.setattr(_session, "library", broken)
    s.act({"action": "keep"})
    with pytest.raises(LigDiagnostics):
        s.act({"action": "save"})
    assert not (tmp_path / "poses.lig").exists()


STANDING = """\
      LOAD HUMANOID FROM 'humanoid'
      GRAPHICAL PLINTH
      MODEL STATUE
      PLINTH :- BOX WIDTH 1.0, HEIGHT 0.4, DEPTH 1.0
      FIGURE HUMANOID MAIN LINK R_FOOT
      STATUE :- JOINT 99, PLINTH, (0.0, 0.2, 0.0), HUMANOID, (0.0, -0.05, 0.0), (-30.0, 30.0)
      FIGURE STATUE MAIN LINK L_FOOT
"""


@pytest.mark.parametrize("which", ["STATUE", "BOT", "SPUN"])
def test_a_model_built_from_a_re_rooted_submodel_is_saved_as_the_joints_and_figures_that_build_it(tmp_path, which):
    """A model block cannot hold a joint walked from its secondary: the library builds the model
    piece by piece, each piece re-rooted where the thesis' JOINT takes it, and replays the poses."""
    from exchange_support import GRAFTED

    from liganimate.compiler import load_program as compile_text

    text = STANDING if which == "STATUE" else GRAFTED
    program, _ = compile_text(text=text, name="graft.lig")
    fig = program.execute("check").variables[which]
    assert fig.inverted.any()
    g = _posed(fig)
    kept = np.array(g.kept)
    lib = tmp_path / "posed.lig"
    saved = library_text(fig, "POSED", "POSES", g.kept, spacing=10)
    assert "FIGURE" in saved and "STARTMODEL" not in saved
    write_library(str(lib), saved)
    _, take = _play(tmp_path, lib, "POSED", "POSES", 10 * (len(kept) - 1) + 1)
    at = np.arange(len(kept)) * 10
    got = take.figure
    assert sorted(got.joint_ids) == sorted(fig.joint_ids)
    # The same joints walked backwards, the same original and current main links.
    assert {j.id: bool(r) for j, r in zip(got.joints, got.inverted)} == {
        j.id: bool(r) for j, r in zip(fig.joints, fig.inverted)
    }
    assert got.links[got.root].name == fig.links[fig.root].name
    assert got.links[got.main].name == fig.links[fig.main].name
    order = [got.joint_index(j) for j in fig.joint_ids]
    # The library's model has scale 1: a slide's displacement is written times its SCALE MODEL factor.
    written = kept * np.where(fig.slides, fig.slide_scales, 1.0)[None, :, None]
    assert np.allclose(take.angles[at][:, order], written, rtol=0, atol=1e-12)
    mine = world_triangles(mesh_table(fig), g.transforms(kept))
    theirs = world_triangles(
        mesh_table(take.figure), world_transforms(take.figure, take.angles[at], take.placements[at])
    )
    assert mine.shape == theirs.shape
    assert np.allclose(mine, theirs, atol=1e-7)
