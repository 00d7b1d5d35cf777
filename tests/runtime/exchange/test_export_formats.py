"""The export-format table: the command line and the Python API both read it, and nothing else.

A format added to ``EXPORT_FORMATS`` (with its writer) is reachable from
``liganimate export`` and ``LoadedProgram.export`` with no other edit; an
option that a format does not take is refused before the program runs.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

import liganimate
from liganimate import cli
from liganimate.runtime import exchange as X

WALK = """\
      LOAD HUMANOID, WALK FROM 'humanoid'
      INITIALIZE SCENE 1
      STARTSCENE LENGTH 5
        ANIMATE HUMANOID FROM 0 TO 4 USING WALK
      ENDSCENE
      SHOOTSCENES
"""


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "liganimate", *args], check=False, capture_output=True, text=True)


def _tab(scenes, path, *, fps):
    """A toy format for the test: one line per tick of every drawn model (not shipped)."""
    rows = [f"{take.id}\t{m.name}\t{fps}\t{len(m.ticks)}" for take in scenes for m in take.models]
    return X.Export(((path, ("\n".join(rows) + "\n").encode()),), ("tab files keep no geometry",))


def test_every_suffix_chooses_one_format():
    suffixes = [s for f in X.EXPORT_FORMATS for s in f.suffixes]
    assert len(suffixes) == len(set(suffixes)) and all(s == s.lower() and s.startswith(".") for s in suffixes)
    for f in X.EXPORT_FORMATS:
        assert set(f.options) <= set(X.EXPORT_OPTIONS), f.name
        for s in f.suffixes:
            assert X.export_format("a" + s.upper()) is f
    with pytest.raises(ValueError, match="cannot tell the format of film.obj") as caught:
        X.export_format("film.obj")
    assert caught.value.hint == f"write to a file ending in {', '.join(suffixes[:-1])} or {suffixes[-1]}"
    assert {".glb", ".gltf", ".bvh"} <= set(suffixes)


def test_options_are_converted_once_for_text_and_values():
    glb = X.export_format("a.glb")
    assert X.export_options(glb, {}) == {"fps": 24.0, "size": (640, 480), "rig": "skin"}
    assert X.export_options(glb, {"fps": "30", "size": "320x200", "rig": "nodes"}) == {
        "fps": 30.0,
        "size": (320, 200),
        "rig": "nodes",
    }
    assert X.export_options(glb, {"fps": 30, "size": (320, 200)}) == {"fps": 30.0, "size": (320, 200), "rig": "skin"}
    with pytest.raises(ValueError, match="--rig: 'bones' is not a glTF rig; the rigs are skin and nodes"):
        X.export_options(glb, {"rig": "bones"})
    with pytest.raises(ValueError, match="--rig does not apply to bvh files"):
        X.export_options(X.export_format("a.bvh"), {"rig": "skin"})
    # The table names the rigs the glTF writer has (it cannot import the writer to ask).
    for rig in X.RIGS:
        assert X.export_options(glb, {"rig": rig})["rig"] == rig
    with pytest.raises(ValueError, match="--fps: the frame rate must be a positive number, not -1"):
        X.export_options(glb, {"fps": -1})
    with pytest.raises(ValueError, match=r"--size: \(3\.5, 2\) is not a size like 640x480"):
        X.export_options(glb, {"size": (3.5, 2)})
    with pytest.raises(ValueError, match="'20000x20' is out of range: width and height are 1 to 16384 pixels each"):
        X.export_options(glb, {"size": "20000x20"})
    with pytest.raises(ValueError, match="--size does not apply to bvh files"):
        X.export_options(X.export_format("a.bvh"), {"size": (320, 200)})
    with pytest.raises(ValueError, match="no export option 'speed'"):
        X.export_options(glb, {"speed": 2})


def test_a_format_added_to_the_table_reaches_the_command_line_and_the_api(tmp_path, monkeypatch, capsys):
    tab = X.ExportFormat("tab", (".tab",), "ticks per model, tab-separated", ("fps",), _tab)
    formats = (*X.EXPORT_FORMATS, tab)
    monkeypatch.setattr(X._formats, "EXPORT_FORMATS", formats)
    monkeypatch.setattr(X, "EXPORT_FORMATS", formats)
    src = tmp_path / "walk.lig"
    src.write_text(WALK)
    out = tmp_path / "walk.tab"
    assert cli.main(["export", str(src), "-o", str(out), "--fps", "12"]) == 0
    assert out.read_text() == "1\tHUMANOID\t12.0\t5\n"
    err = capsys.readouterr().err
    assert "warning: tab files keep no geometry" in err and f"wrote {out}" in err
    # --size is the glTF cameras'; the tab format does not take it, and says so before running anything.
    assert cli.main(["export", str(src), "-o", str(tmp_path / "b.tab"), "--size", "10x10"]) == 1
    assert "--size does not apply to tab files" in capsys.readouterr().err
    assert not (tmp_path / "b.tab").exists()
    with pytest.warns(UserWarning, match="tab files keep no geometry"):
        written = liganimate.load(str(src)).export(tmp_path / "api.tab", fps=6)
    assert written == [str(tmp_path / "api.tab")]
    assert (tmp_path / "api.tab").read_text() == "1\tHUMANOID\t6.0\t5\n"


def test_the_api_writes_what_the_command_line_writes(tmp_path):
    src = tmp_path / "walk.lig"
    src.write_text(WALK)
    program = liganimate.load(str(src))
    for suffix in (".glb", ".gltf", ".bvh"):
        by_cli = tmp_path / f"cli{suffix}"
        r = _cli("export", str(src), "-o", str(by_cli), "--fps", "30")
        assert r.returncode == 0, r.stderr
        by_api = tmp_path / f"api{suffix}"
        assert program.export(by_api, fps=30) == [str(by_api)]
        assert by_api.read_bytes() == by_cli.read_bytes(), suffix
    with pytest.raises(ValueError, match="--size does not apply to bvh files"):
        program.export(tmp_path / "x.bvh", size=(10, 10))
    assert not os.path.exists(tmp_path / "x.bvh")


def test_a_bad_option_value_is_a_usage_error(tmp_path):
    src = tmp_path / "walk.lig"
    src.write_text(WALK)
    r = _cli("export", str(src), "-o", str(tmp_path / "a.glb"), "--fps", "0")
    assert r.returncode == 2 and "the frame rate must be a positive number, not 0" in r.stderr
    r = _cli("export", str(src), "-o", str(tmp_path / "a.glb"), "--size", "big")
    assert r.returncode == 2 and "'big' is not a size like 640x480" in r.stderr
    assert sorted(os.listdir(tmp_path)) == ["walk.lig"]
