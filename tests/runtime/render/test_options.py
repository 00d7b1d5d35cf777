"""RenderOptions: one value from the command line and the Python API to the renderer, the checks and the lock.

The movie formats are a table (``MOVIES``): the command line's flags, the
output checks, the lock and the renderer's streams all come from it, so a
movie format is one field, one entry and its stream class.
"""

from __future__ import annotations

import dataclasses
import os

import pytest
from test_render import program, run

import liganimate
from liganimate.cli import build_parser
from liganimate.runtime.errors import RenderError
from liganimate.runtime.render import options as O
from liganimate.runtime.render.frames import Renderer


def test_every_movie_is_a_field_and_a_flag():
    fields = {f.name for f in dataclasses.fields(O.RenderOptions)}
    run_parser = build_parser()._subparsers._group_actions[0].choices["run"]
    flags = {s for a in run_parser._actions for s in a.option_strings}
    for movie in O.MOVIES:
        assert movie.name in fields and f"--{movie.name}" in flags
    # Every option of the command line's run is a field, and every field an option but
    # workers (the library's: tests and benchmarks draw in one process with workers=1).
    dests = {a.dest for a in run_parser._actions} - {"help", "file"}
    assert dests == fields - {"workers"}


def test_options_are_frozen_and_checked_into_their_types(tmp_path):
    o = O.RenderOptions(out=str(tmp_path / "f"), fps="30", aa="2", crf="18", preset=" Slow ", size=[64.0, 48])
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.fps = 3  # type: ignore[misc]
    c = O.checked(o)
    assert (c.fps, c.aa, c.crf, c.preset, c.size) == (30.0, 2, 18, "slow", (64, 48))
    assert c.files() == () and O.checked(c) == c
    with pytest.raises(RenderError, match=r"^size=\(0, 48\) is not an image size"):
        O.checked(dataclasses.replace(o, size=(0, 48)))
    with pytest.raises(RenderError, match=r"^workers=0 is not a number of processes"):
        O.checked(dataclasses.replace(o, workers=0))
    with pytest.raises(RenderError, match=r"^there is no frames folder \(out=\) and no gif= or mp4=: nothing"):
        O.checked(O.RenderOptions())
    with pytest.raises(RenderError, match="^scheduler is empty"):
        O.checked(dataclasses.replace(o, scheduler=" "))
    assert os.listdir(tmp_path) == []


def test_the_renderer_opens_the_movies_the_table_names(tmp_path, monkeypatch):
    # Swap the GIF's stream for a recorder: the renderer reaches movies only through MOVIES.
    class Recorder:
        def __init__(self, path, options):
            self.path, self.options, self.frames = path, options, 0
            opened.append(self)

        def add(self, frame):
            self.frames += 1

        def commit(self):
            with open(self.path, "w") as fh:
                fh.write(f"{self.frames} frames at {self.options.fps}\n")
            return self.frames

        def abort(self):
            pass

    opened: list = []
    gif = dataclasses.replace(O.MOVIES[0], open=Recorder)
    monkeypatch.setattr(O, "MOVIES", (gif, *O.MOVIES[1:]))
    src = program(tmp_path, 6)
    liganimate.load(src).render(gif=str(tmp_path / "a.gif"), fps=12, size=(32, 24), quiet=True, workers=1)
    assert (tmp_path / "a.gif").read_text() == "6 frames at 12.0\n"
    assert [r.path for r in opened] == [str(tmp_path / "a.gif")]


def test_the_api_renders_what_the_command_line_renders(tmp_path):
    src = program(tmp_path, 5)
    r = run("run", str(src), "-o", "cli", "--size", "64x48", "--gif", "cli.gif", "--poses", "cli.jsonl", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    liganimate.load(src).render(
        tmp_path / "api", size=(64, 48), gif=str(tmp_path / "api.gif"), poses=str(tmp_path / "api.jsonl"), quiet=True
    )
    for name in ("00000.png", "00004.png"):
        assert (tmp_path / "api" / "scene1" / name).read_bytes() == (tmp_path / "cli" / "scene1" / name).read_bytes()
    assert (tmp_path / "api.gif").read_bytes() == (tmp_path / "cli.gif").read_bytes()
    assert (tmp_path / "api.jsonl").read_bytes() == (tmp_path / "cli.jsonl").read_bytes()
    options = O.RenderOptions(out=str(tmp_path / "again"), size=(64, 48), quiet=True)
    liganimate.load(src).render(options=options)
    assert (tmp_path / "again" / "scene1" / "00004.png").read_bytes() == (
        tmp_path / "cli" / "scene1" / "00004.png"
    ).read_bytes()
    with pytest.raises(TypeError, match="unknown options: colour"):
        liganimate.load(src).render(tmp_path / "x", colour=True)
    with pytest.raises(ValueError, match="^fps= 0 is not a usable frame rate"):
        liganimate.load(src).render(tmp_path / "x", fps=0)
    assert not (tmp_path / "x").exists()


def test_the_lock_guards_every_file_the_options_name(tmp_path):
    held = Renderer(O.RenderOptions(out=str(tmp_path / "f"), gif=str(tmp_path / "a.gif"), quiet=True))
    try:
        with pytest.raises(RenderError, match="a.gif is being written by another liganimate run"):
            Renderer(O.RenderOptions(out=str(tmp_path / "g"), gif=str(tmp_path / "a.gif"), quiet=True))
    finally:
        held.close()
