"""`liganimate view` and liganimate.load() without a browser: the page's data, its isolation, and errors."""

from __future__ import annotations

import base64
import html
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from paths import ROOT_DIR

import liganimate
from liganimate.api import LigProgramError, LoadedProgram
from liganimate.runtime import exchange as X
from liganimate.runtime.figure.pose import mesh_table, world_transforms
from liganimate.runtime.view import json_for_script, viewer_html

ROOT = ROOT_DIR
APPENDIX = os.path.join(ROOT, "examples", "appendix_a.lig")
FIVE = os.path.join(ROOT, "benchmarks", "five_humans.lig")
TYPES = {"f32": "<f4", "u8": "u1", "u16": "<u2", "i32": "<i4", "u32": "<u4"}


def _view(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "liganimate", "view", *args],
        check=False,
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=300,
    )


def _parts(page: str):
    manifest = re.search(r'<script type="application/json" id="lig-manifest">(.*?)</script>', page, re.DOTALL).group(1)
    blob = re.search(r'<script type="application/octet-stream" id="lig-blob">(.*?)</script>', page, re.DOTALL).group(1)
    return json.loads(manifest), base64.b64decode(blob)


def _array(blob: bytes, ref: dict) -> np.ndarray:
    dt = np.dtype(TYPES[ref["t"]])
    return np.frombuffer(blob, dtype=dt, count=ref["n"], offset=ref["o"])


def test_view_writes_one_self_contained_page(tmp_path):
    out = tmp_path / "a.html"
    r = _view(APPENDIX, "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert f"wrote {out}" in r.stderr
    page = out.read_text(encoding="utf-8")
    # Nothing outside the file: no URL with a scheme or host, no src/href at all, and a CSP forbidding requests.
    assert not re.search(r"https?:|//[a-z]|\bsrc\s*=|\bhref\s*=|@import|url\(", page, re.IGNORECASE)
    assert "default-src 'none'" in page
    assert page.count("<script") == 4  # manifest, blob, gl.js, viewer.js: all inline
    assert os.listdir(tmp_path) == ["a.html"]


def test_page_holds_the_runtimes_own_segment_matrices(tmp_path):
    """The page's matrices are the --poses record's, and its triangles the model's mesh."""
    out = tmp_path / "a.html"
    assert _view(APPENDIX, "-o", str(out)).returncode == 0
    manifest, blob = _parts(out.read_text(encoding="utf-8"))
    poses = tmp_path / "p.jsonl"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "liganimate",
            "run",
            APPENDIX,
            "--poses",
            str(poses),
            "-o",
            str(tmp_path / "f"),
            "--quiet",
        ],
        check=False,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    records = [json.loads(line) for line in poses.read_text(encoding="utf-8").splitlines()]
    scene = manifest["scenes"][0]
    assert scene["id"] == 1 and scene["sameframe"] == 6 and scene["length"] == 6
    model = scene["models"][0]
    L = len(model["links"])
    mats = _array(blob, model["matrices"]).reshape(-1, L, 3, 4)
    ticks = _array(blob, model["ticks"])
    angles = _array(blob, model["angles"]).reshape(len(ticks), -1, 3)
    assert len(records) == len(ticks) == 6
    for rec in records:
        row = int(np.flatnonzero(ticks == rec["tick"])[0])
        assert [s["link"] for s in rec["segments"]] == model["links"]
        expect = np.array([s["matrix"] for s in rec["segments"]]).reshape(L, 4, 4)[:, :3, :]
        assert np.allclose(mats[row], expect, rtol=1e-6, atol=1e-6)
        ids = [j["id"] for j in model["joints"]]
        got = {str(i): angles[row, k] for k, i in enumerate(ids)}
        for jid, value in rec["joints"].items():
            assert np.allclose(got[jid], value, atol=1e-4)
    program = liganimate.load(APPENDIX).program
    take = X.collect(program)[0].models[0]
    table = mesh_table(take.figure)
    assert np.array_equal(_array(blob, model["mesh"]["pos"]), table.triangles.reshape(-1).astype(np.float32))
    # Three levels a triangle (grey ones as three equal channels), as gl.js reads them.
    assert np.array_equal(_array(blob, model["mesh"]["rgb"]).reshape(-1, 3), np.repeat(table.shade[:, None], 3, axis=1))
    assert np.array_equal(_array(blob, model["mesh"]["link"]), table.link)
    cams = _array(blob, scene["cameras"]).reshape(-1, 4)
    assert np.allclose(cams[0], [*take_camera(program)], rtol=1e-6)


def take_camera(program):
    point, width = X.collect(program)[0].cameras[0]
    return (*point, width)


def test_five_figure_scene_is_under_ten_megabytes(tmp_path):
    out = tmp_path / "five.html"
    r = _view(FIVE, "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size < 10_000_000
    manifest, blob = _parts(out.read_text(encoding="utf-8"))
    scene = manifest["scenes"][0]
    assert scene["length"] == 1000 and len(scene["models"]) == 5
    # Every model's 1,000 ticks of matrices are there, matching the runtime's own evaluation.
    take = X.collect(liganimate.load(FIVE).program)[0]
    for entry, m in zip(scene["models"], take.models):
        L = len(entry["links"])
        mats = _array(blob, entry["matrices"]).reshape(-1, L, 3, 4)
        assert mats.shape[0] == 1000
        want = world_transforms(m.figure, m.angles, m.placements)[:, :, :3, :].astype(np.float32)
        assert np.array_equal(mats, want)


@pytest.mark.parametrize(
    "text, where",
    [
        ("X = (1,\n", ":1:"),
        (
            (
                "      REAL Y, Z\n      Y = 0.0\n      INITIALIZE SCENE 1\n      STARTSCENE LENGTH 3\n"
                "        Z = 1.0 / Y\n      ENDSCENE\n      SHOOTSCENES\n"
            ),
            ":5:17: error: division by zero",
        ),
    ],
)
def test_a_broken_program_gives_its_diagnostic_and_no_page(tmp_path, text, where):
    prog = tmp_path / "broken.lig"
    prog.write_text(text, encoding="utf-8")
    out = tmp_path / "broken.html"
    out.write_text("the old page", encoding="utf-8")
    r = _view(str(prog), "-o", str(out))
    assert r.returncode == 1
    assert f"broken.lig{where}" in r.stderr and ": error: " in r.stderr and "^" in r.stderr
    assert "Traceback" not in r.stderr
    assert out.read_text(encoding="utf-8") == "the old page"
    assert sorted(os.listdir(tmp_path)) == ["broken.html", "broken.lig"]


def test_a_program_without_scenes(tmp_path):
    prog = tmp_path / "lib.lig"
    prog.write_text("      GRAPHICAL A\n      A :- BOX WIDTH 1.0, HEIGHT 1.0, DEPTH 1.0\n", encoding="utf-8")
    r = _view(str(prog), cwd=tmp_path)
    assert r.returncode == 1 and "shoots no scene" in r.stderr
    assert os.listdir(tmp_path) == ["lib.lig"]
    with pytest.raises(ValueError, match="shoots no scene"):
        liganimate.load(prog).view()


def test_the_default_output_is_the_stem_in_the_current_folder(tmp_path):
    r = _view(APPENDIX, "--quiet", cwd=tmp_path)
    assert r.returncode == 0 and r.stderr.count("warning") == 1  # the program's own warning, nothing more
    assert os.listdir(tmp_path) == ["appendix_a.html"]


def test_program_text_never_reaches_the_page_as_markup():
    hostile = "</script><script>alert(1)</script><!--"
    take = X.collect(liganimate.load(APPENDIX).program)
    page = viewer_html(take, hostile)
    assert hostile not in page and "alert(1)</script>" not in page
    assert html.escape(hostile) in page
    assert (
        json_for_script({"a": hostile})
        == '{"a":"\\u003c/script\\u003e\\u003cscript\\u003ealert(1)\\u003c/script\\u003e\\u003c!--"}'
    )


def test_load_path_text_and_notebook_display(tmp_path):
    p = liganimate.load(APPENDIX)
    assert isinstance(p, LoadedProgram) and p.name == APPENDIX
    assert liganimate.load(Path(APPENDIX)).name == APPENDIX
    text = Path(APPENDIX).read_text(encoding="utf-8")
    q = liganimate.loads(text)
    assert q.name == "<text>"
    with pytest.raises(TypeError, match="give a program's text to liganimate.loads"):
        liganimate.load(text)
    shown = q._repr_html_()
    assert shown.startswith('<iframe srcdoc="') and 'sandbox="allow-scripts"' in shown
    inner = html.unescape(re.search(r'srcdoc="(.*?)"', shown, re.DOTALL).group(1))
    assert inner.startswith("<!DOCTYPE html>") and "lig-manifest" in inner
    v = p.view(scene=1)
    assert "lig-manifest" in v._repr_html_()
    saved = v.save(tmp_path / "v.html")
    assert Path(saved).read_text(encoding="utf-8") == v.html
    with pytest.raises(ValueError, match="no scene 7"):
        p.view(scene=7)


def test_load_errors_read_like_the_command_line(tmp_path):
    with pytest.raises(LigProgramError) as info:
        liganimate.loads("      X = (1,\n")
    assert re.match(r"<text>:1:\d+: error: ", str(info.value)) and "^" in str(info.value)
    bad = tmp_path / "rt.lig"
    bad.write_text(
        "      INITIALIZE SCENE 1\n      STARTSCENE LENGTH 2\n        PRINT 1 / 0\n      ENDSCENE\n      SHOOTSCENES\n",
        encoding="utf-8",
    )
    p = liganimate.load(bad)
    with pytest.raises(LigProgramError) as info:
        p.view()
    assert "rt.lig:3:" in str(info.value)
    with pytest.raises(OSError):
        liganimate.load(tmp_path / "missing.lig")
    with pytest.raises(TypeError):
        liganimate.load(42)
    with pytest.raises(TypeError):
        liganimate.loads(b"      X = 1\n")


def test_a_robots_slide_is_marked_so_the_page_shows_its_displacement_without_degrees(tmp_path):
    out = tmp_path / "arm.html"
    assert _view(os.path.join(ROOT, "examples", "robot_arm.lig"), "-o", str(out)).returncode == 0
    manifest, _ = _parts(out.read_text(encoding="utf-8"))
    (model,) = manifest["scenes"][0]["models"]
    assert [j["slide"] for j in model["joints"]] == [True, False, False, False]
    assert model["joints"][0]["ext"][0] == [-1.0, 1.0]
