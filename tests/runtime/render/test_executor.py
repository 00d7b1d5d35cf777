"""Renderer(executor=...), --scheduler and --aa: where images are drawn, and how finely.

The executor is any object with ``submit`` and ``shutdown`` (what
runtime/render/distributed.py's DaskExecutor offers); here a thread pool
stands in for a cluster, so these tests need no Dask.
"""

from __future__ import annotations

import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import pytest

from liganimate.compiler import load_program
from liganimate.runtime.errors import RenderError
from liganimate.runtime.render import frames
from liganimate.runtime.render.options import RenderOptions
from tests.runtime.render.test_render import program


class CountingExecutor:
    """A thread pool that counts what it is given and whether it was shut down."""

    def __init__(self):
        self.pool = ThreadPoolExecutor(max_workers=2)
        self.submitted = 0
        self.shutdowns = []

    def submit(self, fn, *args):
        self.submitted += 1
        return self.pool.submit(fn, *args)

    def shutdown(self, wait=True, cancel_futures=False):
        self.shutdowns.append((wait, cancel_futures))
        self.pool.shutdown(wait=wait, cancel_futures=cancel_futures)


def files(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*.png"))}


def test_an_executor_draws_every_image_and_the_bytes_are_those_of_a_local_run(tmp_path):
    prog, _ = load_program(str(program(tmp_path, 40)))
    ex = CountingExecutor()
    prog.render(str(tmp_path / "remote"), size=(64, 48), quiet=True, executor=ex)
    prog.render(str(tmp_path / "local"), size=(64, 48), quiet=True, workers=1)
    assert ex.submitted >= 40 // frames.CHUNK  # every chunk went to it, none was drawn here
    assert ex.shutdowns, "the renderer shuts its executor down when closed"
    remote = files(tmp_path / "remote")
    assert len(remote) == 40
    assert remote == files(tmp_path / "local")


def test_an_executor_is_shut_down_when_the_render_is_refused(tmp_path):
    ex = CountingExecutor()
    with pytest.raises(RenderError):
        frames.Renderer(RenderOptions(out=str(tmp_path / "out"), fps=0), executor=ex)
    assert ex.shutdowns


@pytest.mark.parametrize("value", ["0", "9", "2.5", "two", "-1"])
def test_bad_aa_is_refused_before_compiling(tmp_path, value):
    src = program(tmp_path, 4)
    r = subprocess.run(
        [sys.executable, "-m", "liganimate", "run", str(src), "--aa", value],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    # A value no run could take is a usage error: exit 2, the usage line, then the sentence.
    assert r.returncode == 2
    assert r.stderr.startswith("usage: liganimate run ")
    assert r.stderr.endswith(
        f"liganimate run: error: --aa {value} is not an anti-aliasing factor; give a whole number from 1 (none) to 8\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == [src.name]


def test_the_library_refuses_a_bad_aa_by_its_keyword_name(tmp_path):
    with pytest.raises(RenderError, match=r"^aa=0 is not an anti-aliasing factor"):
        frames.Renderer(RenderOptions(out=str(tmp_path / "out"), aa=0))


def test_aa_reaches_the_rasterizer(monkeypatch):
    seen = []

    def fake(tris, grey, camera, background, cull, **kw):
        seen.append(kw)
        import numpy as np

        return np.zeros((2, 2), np.uint8)

    monkeypatch.setattr(frames, "rasterize", fake)
    import numpy as np

    part = (np.zeros((1, 3, 3)), np.zeros(1, np.uint8), np.zeros(1, bool))
    frames.draw((2, 2), [(((0.0, 0.0, 5.0), 2.0), [part])], 3, "thesis")
    frames.draw((2, 2), [(((0.0, 0.0, 5.0), 2.0), [part])], 1, "thesis")
    assert seen == [{"aa": 3}, {"aa": 1}]


def test_run_with_aa_smooths_the_edges(tmp_path):
    src = program(tmp_path, 2)
    for aa in ("1", "3"):
        r = subprocess.run(
            [
                sys.executable,
                "-m",
                "liganimate",
                "run",
                str(src),
                "-o",
                f"aa{aa}",
                "--size",
                "64x48",
                "--aa",
                aa,
                "--look",
                "thesis",
            ],
            capture_output=True,
            text=True,
            cwd=tmp_path,
        )
        assert r.returncode == 0, r.stderr
    from liganimate.runtime.render.imagefiles import read_png

    plain = read_png(tmp_path / "aa1" / "scene1" / "00000.png")
    smooth = read_png(tmp_path / "aa3" / "scene1" / "00000.png")
    # Edge pixels take levels between the surfaces' own: more distinct levels, same picture overall.
    assert len(set(smooth.ravel().tolist())) > len(set(plain.ravel().tolist())) + 3
    assert abs(smooth.astype(int) - plain).mean() < 8


def run_env(tmp_path, *args, env):
    return subprocess.run(
        [sys.executable, "-m", "liganimate", *args], capture_output=True, text=True, cwd=tmp_path, env=env
    )


DASK_PROBE = """
import runpy, sys
sys.argv = ["liganimate", "run", {src!r}, "--size", "32x24", "--quiet"]
try:
    runpy.run_module("liganimate", run_name="__main__")
except SystemExit as exc:
    assert not exc.code, exc.code
print(sorted(m for m in sys.modules if m.split(".")[0] in ("dask", "distributed")
             or m.endswith("render.distributed")))
"""


def test_a_local_run_imports_nothing_of_dask(tmp_path):
    src = program(tmp_path, 4)
    env = {k: v for k, v in os.environ.items() if k != "LIGANIMATE_SCHEDULER"}
    r = subprocess.run(
        [sys.executable, "-c", DASK_PROBE.format(src=str(src))], capture_output=True, text=True, cwd=tmp_path, env=env
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().splitlines()[-1] == "[]"
    assert len(list((tmp_path / "swing_frames" / "scene1").glob("*.png"))) == 4


def test_scheduler_without_dask_says_how_to_install_it(tmp_path):
    # A folder named like the packages, but empty, hides any installed Dask.
    hide = tmp_path / "hide"
    for name in ("dask", "distributed"):
        (hide / name).mkdir(parents=True)
        (hide / name / "__init__.py").write_text("raise ImportError('hidden', name=__name__)\n")
    src = program(tmp_path, 4)
    for how in ("option", "environment"):
        env = {**os.environ, "PYTHONPATH": str(hide)}
        args = ["run", str(src), "-o", "out", "--quiet"]
        if how == "option":
            args += ["--scheduler", "tcp://127.0.0.1:1"]
        else:
            env["LIGANIMATE_SCHEDULER"] = "tcp://127.0.0.1:1"
        r = run_env(tmp_path, *args, env=env)
        assert r.returncode == 1, r.stderr
        assert r.stderr == "liganimate: error: dask is not installed: pip install 'liganimate[dask]'\n"
        assert not (tmp_path / "out").exists()
