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


# ---------------------------------------------------------------- the memory budget (issue 24)


def test_an_image_over_the_memory_budget_is_refused_before_anything_is_drawn(tmp_path, monkeypatch):
    monkeypatch.delenv(O.MEMORY_ENV, raising=False)
    options = O.RenderOptions(out=str(tmp_path / "out"), size=(16384, 16384), aa=8)
    with pytest.raises(RenderError) as info:
        O.checked(options, O.CLI_NAMES)
    message = str(info.value)
    assert "16384x16384 pixels with --aa 8 (64 samples a pixel)" in message
    assert "over the budget of 8192 MiB for one image" in message
    assert f"{O.MEMORY_ENV}=393216" in message
    assert not (tmp_path / "out").exists()
    # The largest side without anti-aliasing fits the default budget.
    O.checked(dataclasses.replace(options, aa=1), O.CLI_NAMES)


def test_the_memory_budget_is_raised_and_lowered_by_its_environment_variable(tmp_path, monkeypatch):
    options = O.RenderOptions(out=str(tmp_path / "out"), size=(640, 480), aa=2)
    monkeypatch.setenv(O.MEMORY_ENV, "1")  # 1 MiB: 640 x 480 x 4 samples do not fit
    with pytest.raises(RenderError, match=r"with aa 2 .* over the budget of 1 MiB"):
        O.checked(options)
    monkeypatch.setenv(O.MEMORY_ENV, "100")
    O.checked(options)
    monkeypatch.setenv(O.MEMORY_ENV, "lots")
    with pytest.raises(RenderError, match=f"{O.MEMORY_ENV}='lots' is not a number of MiB"):
        O.checked(options)


def test_a_size_beyond_the_limit_states_the_limit(tmp_path):
    src = program(tmp_path, 2)
    r = run("run", str(src), "-o", "out", "--size", "20000x20000", cwd=tmp_path)
    assert r.returncode == 2
    assert "'20000x20000' is out of range: width and height are 1 to 16384 pixels each" in r.stderr
    r = run("run", str(src), "-o", "out", "--size", "big", cwd=tmp_path)
    assert "'big' is not a size like 640x480" in r.stderr


def test_a_read_only_file_system_is_reported_as_such_not_as_a_permission(tmp_path, monkeypatch):
    from liganimate.runtime.render import outputs

    real_statvfs = os.statvfs

    class ReadOnly:
        def __init__(self, path):
            self.f_flag = real_statvfs(path).f_flag | os.ST_RDONLY

    monkeypatch.setattr(outputs.os, "access", lambda path, mode: False)
    monkeypatch.setattr(outputs.os, "statvfs", ReadOnly)
    with pytest.raises(RenderError, match="the file system is read-only \\(EROFS\\)"):
        O.checked(O.RenderOptions(out=str(tmp_path / "out")), O.CLI_NAMES)
    with pytest.raises(RenderError, match="the file system is read-only \\(EROFS\\) for the folder"):
        O.checked(O.RenderOptions(gif=str(tmp_path / "a.gif")), O.CLI_NAMES)
    monkeypatch.setattr(outputs.os, "statvfs", real_statvfs)
    with pytest.raises(RenderError, match="permission denied"):
        O.checked(O.RenderOptions(out=str(tmp_path / "out")), O.CLI_NAMES)


@pytest.mark.parametrize(
    ("cores", "options", "workers"),
    [
        (2, {"look": "thesis"}, 2),  # PNG frames: every core draws
        (2, {"look": "thesis", "mp4": "film.mp4"}, 1),  # the encoder gets a core of its own
        (2, {"look": "thesis", "gif": "film.gif", "out": "frames"}, 1),
        (2, {"look": "modern", "mp4": "film.mp4"}, 2),  # drawing sets the pace: every core draws
        (2, {"mp4": "film.mp4"}, 2),  # the modern look is the default
        (1, {"look": "thesis", "mp4": "film.mp4"}, 1),  # never none
        (16, {}, 8),  # at most 8
        (16, {"look": "thesis", "mp4": "film.mp4"}, 7),
        (2, {"look": "thesis", "mp4": "film.mp4", "workers": 2}, 2),  # as asked
    ],
)
def test_a_movie_s_encoder_keeps_a_core_of_the_drawing_workers(monkeypatch, cores, options, workers):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(cores)), raising=False)
    monkeypatch.setattr(os, "cpu_count", lambda: 64)  # the affinity counts where there is one
    assert O.RenderOptions(**options).drawing_workers() == workers
    monkeypatch.delattr(os, "sched_getaffinity")  # as on Windows and macOS
    monkeypatch.setattr(os, "cpu_count", lambda: cores)
    assert O.RenderOptions(**options).drawing_workers() == workers
