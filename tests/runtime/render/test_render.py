"""Rendering as `liganimate run` does it: GIF and MP4, the progress bar, streaming, atomic and deterministic files.

Nothing here is timed; the speed is measured by benchmarks/scene.py and
benchmarks/pose.py.
"""

from __future__ import annotations

import os
import pathlib
import pty
import select
import signal
import subprocess
import sys
import time
import tracemalloc

import numpy as np
import pytest
from commands import liganimate as run
from paths import ROOT_DIR
from PIL import Image

from liganimate.compiler import load_program
from liganimate.runtime.errors import RenderError
from liganimate.runtime.render import imagefiles, video
from liganimate.runtime.render.imagefiles import read_png
from liganimate.runtime.values import _solid_orientation, polygons_to_graphical

# A body with a swinging arm: small and quick to draw, and each tick differs.
PROGRAM = """\
      GRAPHICAL ARM, BODY, FLOOR
      MODEL M
      MOTION SWING

      BODY :- BOX WIDTH 0.6, HEIGHT 1.0, DEPTH 0.4
      ARM :- BOX WIDTH 0.2, HEIGHT 0.8, DEPTH 0.2, LIGHTNESS 70.0
      FLOOR :- BOX AT (0.0, -0.6, 0.0), WIDTH 3.0, HEIGHT 0.1, DEPTH 1.0,
                   LIGHTNESS 85.0
      M :- JOINT 1, BODY, (0.3, 0.4, 0.0), ARM, (0.0, 0.4, 0.0),
               (0.0, 0.0), (0.0, 0.0), (-90.0, 90.0)

      STARTMOTION SWING
        JOINT 1 POSITION 0.0, 0.0, -60.0
          FRAME 6 POSITION 0.0, 0.0, 60.0
            INTERPOLATE ACCDCC
          FRAME 12 POSITION 0.0, 0.0, -60.0
            INTERPOLATE ACCDCC
      ENDMOTION

      INITIALIZE SCENE 1
          VIEW POINT = (0.0, 0.5, 6.0)
          VIEW WIDTH = 3.0
          BACKGROUND FLOOR
      STARTSCENE LENGTH {ticks}
          ANIMATE M FROM 0 TO {last} USING SWING REPEAT
      ENDSCENE

      SHOOTSCENES
      END
"""


def program(folder: pathlib.Path, ticks: int, name: str = "swing") -> pathlib.Path:
    path = folder / f"{name}.lig"
    path.write_text(PROGRAM.format(ticks=ticks, last=ticks - 1))
    return path


def render_small(src: pathlib.Path, *options: str, cwd, env=None) -> subprocess.CompletedProcess:
    """``liganimate run SRC`` into ``out/`` at 64x48 (quick to draw), with the other ``options`` given."""
    return run("run", str(src), "-o", "out", "--size", "64x48", *options, cwd=cwd, env=env)


def start_render(src: pathlib.Path, options: list, cwd: pathlib.Path, frames: int) -> subprocess.Popen:
    """Start ``liganimate run SRC`` into ``out/`` at 160x120 and return once more than ``frames`` are written.

    The command runs in a session of its own, so that a test can signal its
    whole process group as Ctrl-C at a terminal does.  The test fails if the
    command ends, or 120 s pass, before ``out/scene1`` holds that many frames.
    ``stdout`` and ``stderr`` are pipes, read with ``communicate``.
    """
    proc = subprocess.Popen(
        [sys.executable, "-m", "liganimate", "run", str(src), "-o", "out", "--size", "160x120", *options],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    scene = cwd / "out" / "scene1"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if scene.is_dir() and len(os.listdir(scene)) > frames:
            break
        time.sleep(0.05)
    assert proc.poll() is None, proc.communicate()
    return proc


def leftovers(folder: pathlib.Path) -> list:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.name.endswith(".tmp"))


def pngs(folder: pathlib.Path) -> list:
    return sorted(folder.rglob("*.png"))


def have_ffmpeg() -> bool:
    try:
        video.find_ffmpeg()
        return True
    except RenderError:
        return False


def no_ffmpeg_env(tmp_path) -> dict:
    """An environment where neither imageio-ffmpeg's binary nor a system ffmpeg can be found."""
    return {**os.environ, "IMAGEIO_FFMPEG_EXE": str(tmp_path / "no-such-ffmpeg"), "PATH": ""}


# --------------------------------------------------------------------------
# GIF and MP4 through the command line


def test_run_writes_gif_and_mp4(tmp_path):
    src = program(tmp_path, 12)
    r = render_small(src, "--gif", "a.gif", "--mp4", "a.mp4", "--fps", "12", "--quiet", cwd=tmp_path)
    if not have_ffmpeg():
        # Without ffmpeg, MP4 output is refused up front, clearly, and nothing is written.
        assert r.returncode == 1
        assert "ffmpeg" in r.stderr and "pip install imageio-ffmpeg" in r.stderr
        assert "Traceback" not in r.stderr
        assert sorted(p.name for p in tmp_path.iterdir()) == [src.name]
        return
    assert r.returncode == 0, r.stderr
    frames = [read_png(p) for p in pngs(tmp_path / "out")]
    assert len(frames) == 12 and frames[0].shape == (48, 64)
    assert len({f.tobytes() for f in frames}) > 6, "the arm moves"
    with Image.open(tmp_path / "a.gif") as gif:
        assert gif.n_frames == 12
        for i, frame in enumerate(frames):
            gif.seek(i)
            np.testing.assert_array_equal(np.asarray(gif.convert("L")), frame)  # 256 greys: exact
    raw = subprocess.run(
        [
            video.find_ffmpeg(),
            "-loglevel",
            "error",
            "-i",
            str(tmp_path / "a.mp4"),
            "-f",
            "rawvideo",
            "-pix_fmt",
            "gray",
            "pipe:1",
        ],
        capture_output=True,
        check=True,
    ).stdout
    movie = np.frombuffer(raw, np.uint8).reshape(-1, 48, 64)
    assert len(movie) == 12
    assert np.abs(movie.astype(int) - np.array(frames)).mean() < 3  # H.264 is lossy, but close
    assert leftovers(tmp_path) == []


def test_mp4_without_ffmpeg_is_refused_before_anything_is_written(tmp_path):
    src = program(tmp_path, 12)
    r = render_small(
        src, "--mp4", "a.mp4", "--gif", "a.gif", "--poses", "p.jsonl", cwd=tmp_path, env=no_ffmpeg_env(tmp_path)
    )
    assert r.returncode == 1
    assert "liganimate: error: MP4 output needs the ffmpeg program, and none was found\n" in r.stderr
    assert "hint: pip install imageio-ffmpeg" in r.stderr
    assert "Traceback" not in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [src.name]  # no frames, no GIF, no pose record, no temp


def test_imageio_ffmpeg_is_in_the_test_extra():
    # CI installs '.[test]': MP4 is exercised there, not skipped.
    import tomllib

    pyproject = tomllib.loads((pathlib.Path(ROOT_DIR) / "pyproject.toml").read_text())
    assert any(dep.startswith("imageio-ffmpeg") for dep in pyproject["project"]["optional-dependencies"]["test"])


# --------------------------------------------------------------------------
# The progress bar


def run_on_terminal(args, cwd) -> tuple[int, str]:
    """Run the command with stderr on a pseudo-terminal; return (status, what it showed there)."""
    master, slave = pty.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-m", "liganimate", *args],
        cwd=cwd,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=slave,
    )
    os.close(slave)
    shown = b""
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        ready, _, _ = select.select([master], [], [], 0.1)
        if ready:
            try:
                data = os.read(master, 4096)
            except OSError:  # the terminal closed: every writer has exited
                break
            if not data:
                break
            shown += data
        elif proc.poll() is not None:
            break
    os.close(master)
    return proc.wait(timeout=60), shown.decode("utf-8", "replace")


def test_progress_bar_on_a_terminal_and_quiet_silences_it(tmp_path):
    src = program(tmp_path, 40)
    rc, shown = run_on_terminal(["run", str(src), "-o", "loud", "--size", "64x48"], tmp_path)
    assert rc == 0, shown
    assert "scene 1: 40/40 images" in shown
    assert "frames written to loud" in shown
    rc, shown = run_on_terminal(["run", str(src), "-o", "quiet", "--size", "64x48", "--quiet"], tmp_path)
    assert rc == 0, shown
    assert shown == ""
    assert len(pngs(tmp_path / "quiet")) == 40


def test_no_progress_bar_when_stderr_is_not_a_terminal(tmp_path):
    r = render_small(program(tmp_path, 40), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "images" not in r.stderr and "\r" not in r.stderr


# --------------------------------------------------------------------------
# Streaming: memory does not grow with the number of ticks


def peak_traced(tmp_path, ticks: int) -> int:
    prog, _ = load_program(str(program(tmp_path, ticks, f"swing{ticks}")))
    tracemalloc.start()
    try:
        prog.render(str(tmp_path / f"out{ticks}"), size=(160, 120), quiet=True, workers=1)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_rendering_streams_in_process(tmp_path):
    # numpy reports its arrays to tracemalloc, so every image, triangle and
    # pose the renderer holds is counted.  Holding each image's triangles
    # alone would cost 1,000 x 36 x 72 bytes (2.6 MB) more at 1,000 ticks,
    # holding the images 19 MB.
    short = peak_traced(tmp_path, 100)
    long = peak_traced(tmp_path, 1000)
    assert len(pngs(tmp_path / "out1000")) == 1000
    assert long < short + 1_000_000, (short, long)


def peak_rss_kb(tmp_path, ticks: int) -> int:
    src = program(tmp_path, ticks, f"rss{ticks}")
    proc = subprocess.Popen(
        [sys.executable, "-m", "liganimate", "run", str(src), "-o", f"rss{ticks}", "--size", "320x240", "--quiet"],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    _, status, usage = os.wait4(proc.pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0, proc.stderr.read()
    proc.returncode = 0
    proc.stderr.close()
    assert len(pngs(tmp_path / f"rss{ticks}")) == ticks
    return usage.ru_maxrss  # kilobytes on Linux


def test_liganimate_run_streams(tmp_path):
    # The real command, worker processes and all: its peak memory for 2,000
    # ticks is that for 200 (2,000 images held would be 150 MB at 320x240).
    short = peak_rss_kb(tmp_path, 200)
    long = peak_rss_kb(tmp_path, 2000)
    assert long < short + 20_000, (short, long)


# --------------------------------------------------------------------------
# Atomic files and determinism


def test_two_runs_write_identical_bytes(tmp_path):
    src = program(tmp_path, 20)
    outputs = []
    for name in ("a", "b"):
        args = [
            "run",
            str(src),
            "-o",
            name,
            "--size",
            "96x72",
            "--gif",
            f"{name}.gif",
            "--poses",
            f"{name}.jsonl",
            "--quiet",
        ]
        if have_ffmpeg():
            args += ["--mp4", f"{name}.mp4"]
        r = run(*args, cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        files = {str(p.relative_to(tmp_path / name)): p.read_bytes() for p in pngs(tmp_path / name)}
        for ext in ("gif", "jsonl", "mp4"):
            if (tmp_path / f"{name}.{ext}").exists():
                files[ext] = (tmp_path / f"{name}.{ext}").read_bytes()
        outputs.append(files)
    assert len(outputs[0]) >= 22
    assert outputs[0] == outputs[1]
    assert leftovers(tmp_path) == []


# How each stop is sent: Ctrl-C at a terminal reaches the whole process
# group; `timeout -s INT` sends SIGINT to the command and then to its group
# within a millisecond (two signals; the second used to land in the cleanup
# and print a traceback); `timeout` and `kill` send SIGTERM to the command alone.
STOPS = {
    "ctrl-c": ([("group", signal.SIGINT)], 130, "interrupted; every file already written is complete"),
    "two-sigints": (
        [("pid", signal.SIGINT), ("group", signal.SIGINT)],
        130,
        "interrupted; every file already written is complete",
    ),
    "sigint-twice-to-the-command": (
        [("pid", signal.SIGINT), ("pid", signal.SIGINT)],
        130,
        "interrupted; every file already written is complete",
    ),
    "sigterm": ([("pid", signal.SIGTERM)], 143, "terminated (SIGTERM); every file already written is complete"),
    "sigterm-then-sigint": (
        [("pid", signal.SIGTERM), ("group", signal.SIGINT)],
        143,
        "terminated (SIGTERM); every file already written is complete",
    ),
}


@pytest.mark.parametrize("stop", list(STOPS))
def test_interrupted_render_leaves_only_whole_files(tmp_path, stop):
    sends, status, message = STOPS[stop]
    src = program(tmp_path, 100_000)
    out = tmp_path / "out"
    args = ["--gif", "a.gif", "--poses", "p.jsonl"]
    if have_ffmpeg():
        args += ["--mp4", "a.mp4"]
    proc = start_render(src, args, tmp_path, 40)
    workers = children(proc.pid)
    assert len(workers) >= 1  # the pool is up (two cores or more), and is what must not survive
    for to, sig in sends:
        (os.killpg if to == "group" else os.kill)(proc.pid, sig)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == status, err
    assert err == f"\nliganimate: {message}\n"
    written = pngs(out)
    assert 40 < len(written) < 100_000
    for p in written:
        assert read_png(p).shape == (120, 160)
    # Frames are numbered without gaps; the GIF, MP4 and pose record of an
    # unfinished render are never written.
    assert [p.name for p in written] == [f"{i:05d}.png" for i in range(len(written))]
    assert not (tmp_path / "a.gif").exists() and not (tmp_path / "p.jsonl").exists()
    assert not (tmp_path / "a.mp4").exists()
    assert leftovers(tmp_path) == []
    assert [p.name for p in tmp_path.rglob("*lock")] == []
    # No worker outlives the run (they used to linger, re-parented to PID 1, after SIGTERM).
    assert wait_gone(workers, 5) == []


# --------------------------------------------------------------------------
# Process trees: which workers a run has, and whether they are gone


def _state_and_start(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
    except (FileNotFoundError, ProcessLookupError):
        return None
    return fields[0], fields[19]  # state, start time


def children(pid) -> list:
    """(pid, start time) of each live child of ``pid``."""
    kids = []
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except FileNotFoundError:
        return []
    for t in tasks:
        try:
            with open(f"/proc/{pid}/task/{t}/children") as f:
                kids += [int(k) for k in f.read().split()]
        except FileNotFoundError:
            continue
    return [(k, s[1]) for k in kids if (s := _state_and_start(k)) is not None]


def wait_gone(procs, seconds) -> list:
    """Wait until none of ``procs`` (from :func:`children`) runs; return those still running."""
    deadline = time.monotonic() + seconds
    while True:
        alive = [
            (p, start) for p, start in procs if (s := _state_and_start(p)) is not None and s[0] != "Z" and s[1] == start
        ]
        if not alive or time.monotonic() > deadline:
            return alive
        time.sleep(0.02)


# --------------------------------------------------------------------------
# Closed solids, whatever order their faces were listed in


def unit_box_faces():
    """Appendix A's PRIMITIVE BOX faces in its own order: back, top, bottom, left, right, front."""
    w = h = d = 1.0
    ftr = np.array([w / 2, h / 2, d / 2])
    ftl, fbr = ftr - (w, 0, 0), ftr - (0, h, 0)
    fbl = ftl - (0, h, 0)
    btr, btl, bbr, bbl = ftr - (0, 0, d), ftl - (0, 0, d), fbr - (0, 0, d), fbl - (0, 0, d)
    return [
        [btr, btl, bbl, bbr],
        [ftr, btr, btl, ftl],
        [fbr, bbr, bbl, fbl],
        [ftl, btl, bbl, fbl],
        [ftr, btr, bbr, fbr],
        [ftr, ftl, fbl, fbr],
    ]


def outward(g) -> np.ndarray:
    t = g.triangles
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    return np.einsum("ij,ij->i", n, t.mean(axis=1) - t.mean(axis=(0, 1))) > 0


def test_a_box_listed_in_mixed_orders_is_a_closed_outward_solid():
    polys = [(np.array(f), 40.0) for f in unit_box_faces()]
    assert _solid_orientation(polys) == [-1, 1, -1, 1, -1, 1]  # the thesis lists three faces inward
    g = polygons_to_graphical(polys)
    assert g.closed.all() and outward(g).all()
    # Each triangle keeps its corners, only their order may be reversed.
    before = np.sort(np.array([[f[0], f[k], f[k + 1]] for f, _ in polys for k in (1, 2)]), axis=1)
    np.testing.assert_array_equal(np.sort(g.triangles, axis=1), before)


def test_each_solid_is_oriented_on_its_own():
    faces = unit_box_faces()
    inward = [(np.array(f[::-1]) + 5.0, 1.0) for f in faces]  # a second box, every face listed inward
    polys = [(np.array(f), 40.0) for f in faces] + inward
    assert _solid_orientation(polys)[6:] == [1, -1, 1, -1, 1, -1]
    g = polygons_to_graphical(polys)
    assert g.closed.all()
    for part in (slice(0, 12), slice(12, 24)):
        t = g.triangles[part]
        n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        assert (np.einsum("ij,ij->i", n, t.mean(axis=1) - t.mean(axis=(0, 1))) > 0).all()


def test_open_or_inconsistent_surfaces_are_not_culled():
    faces = [(np.array(f), 40.0) for f in unit_box_faces()]
    assert _solid_orientation(faces[:5]) == [0] * 5  # a box without its front is open
    lone = [(np.array([[9.0, 0, 0], [10, 0, 0], [10, 1, 0]]), 50.0)]
    assert _solid_orientation(faces + lone) == [-1, 1, -1, 1, -1, 1, 0]  # a closed box beside a lone face
    g = polygons_to_graphical(faces + lone)
    assert g.closed.tolist() == [True] * 12 + [False]
    # Three faces meeting along one edge: not a surface.
    fin = faces + [(np.array([[0.5, 0.5, 0.5], [0.5, -0.5, 0.5], [2.0, 0.0, 0.5]]), 10.0)]
    assert not polygons_to_graphical(fin).closed.any()


def test_culling_leaves_the_appendix_a_picture_unchanged(tmp_path):
    from liganimate.runtime.figure import pose
    from liganimate.runtime.render.camera import Camera
    from liganimate.runtime.render.raster import rasterize

    prog, _ = load_program(str(pathlib.Path(ROOT_DIR) / "examples" / "appendix_a.lig"))
    rt = prog.execute("check")
    human = rt.variables["HUMAN"]
    human = getattr(human, "figure", human)
    table = pose.mesh_table(human)
    assert table.closed.all(), "the thesis' BOX primitive makes closed solids"
    angles = pose.joint_angles(human, rt._motion(rt.variables["SQUAT"], 0), np.arange(6.0))
    X = pose.world_transforms(human, angles, np.broadcast_to(np.eye(4), (6, 4, 4)))
    tris = pose.world_triangles(table, X).reshape(-1, 3, 3)
    grey = np.tile(table.shade, 6)
    for eye in [(0.0, 0.0, 4.0), (3.0, 2.0, 2.0), (-1.0, -3.0, 2.5)]:
        cam = Camera(eye, 3.0, (200, 150))
        culled = rasterize(tris, grey, cam, cull=np.ones(len(tris), dtype=bool))
        drawn = rasterize(tris, grey, cam)
        np.testing.assert_array_equal(culled, drawn)


# --------------------------------------------------------------------------
# PNG: runs of rows equal to the row above are spliced in precomputed


@pytest.mark.parametrize("width", [1, 2, 13, 640])
def test_png_with_blank_runs_is_a_valid_zlib_stream(width):
    import zlib

    rng = np.random.default_rng(width)
    bands = [0, 7, 8, 9, 1, 16, 300, 3, 8]  # lengths of runs of equal rows, around the splicing threshold
    rows = []
    for n in bands:
        rows.append(rng.integers(0, 256, (1, width)))
        rows += [rows[-1]] * n
    img = np.concatenate(rows).astype(np.uint8)
    img[:9] = 255  # the first rows blank too
    data = imagefiles.encode_png(img)
    length = int.from_bytes(data[33:37], "big")
    assert data[37:41] == b"IDAT"
    raw = zlib.decompress(data[41 : 41 + length])  # checks the Adler-32 too
    assert len(raw) == img.shape[0] * (width + 1)
    with Image.open(__import__("io").BytesIO(data)) as im:
        np.testing.assert_array_equal(np.asarray(im), img)
    assert imagefiles.encode_png(img.copy()) == data


def test_a_long_check_reports_its_progress():
    # A scene of millions of ticks is checked tick by tick; the caller hears
    # of it every PROGRESS_TICKS ticks and once at the end.
    from liganimate.compiler import load_program
    from liganimate.runtime.host import PROGRESS_TICKS

    program, _ = load_program(text="INITIALIZE SCENE 3\nSTARTSCENE LENGTH 10000\nENDSCENE\nSHOOTSCENES\n")
    calls = []
    program.check(progress=lambda *a: calls.append(a))
    assert calls == [(3, t, 10000) for t in range(0, 10000, PROGRESS_TICKS)] + [(3, 10000, 10000)]


def test_check_shows_progress_on_a_terminal_and_clears_it(tmp_path):
    prog = tmp_path / "long.lig"
    # The longest scene allowed, with a statement a tick: a few seconds' check,
    # past the one second after which the line appears.
    prog.write_text("X = 0\nINITIALIZE SCENE 1\nSTARTSCENE LENGTH 10000000\nX = X + 1\nENDSCENE\nSHOOTSCENES\n")
    status, shown = run_on_terminal(["check", str(prog)], tmp_path)
    assert status == 0, shown
    assert "checking scene 1: " in shown and "10,000,000/10,000,000 ticks" in shown
    # The last thing written blanks the line out, leaving the cursor at its start.
    assert shown.endswith("\r") and shown.rsplit("\r", 2)[-2].strip() == ""
