"""Movies streamed from memory: --mp4 and --gif alone write no PNG, a stopped MP4 is absent or playable.

Also: the same program gives the same MP4 bytes, --crf and --preset are
checked before compiling, and colour images go through every writer.
"""

from __future__ import annotations

import os
import signal
import subprocess

import numpy as np
import pytest
from commands import liganimate as run
from commands import python
from PIL import Image
from test_render import have_ffmpeg, leftovers, pngs, program, start_render

from liganimate.runtime.errors import RenderError
from liganimate.runtime.render import video
from liganimate.runtime.render.imagefiles import encode_png, read_png, write_png

needs_ffmpeg = pytest.mark.skipif(not have_ffmpeg(), reason="no ffmpeg")


def decode(path, shape, fmt="gray"):
    """Every frame of a movie as raw pixels (ffmpeg decodes it, or the test fails)."""
    r = subprocess.run(
        [video.find_ffmpeg(), "-v", "error", "-i", str(path), "-f", "rawvideo", "-pix_fmt", fmt, "pipe:1"],
        capture_output=True,
        check=True,
    )
    assert r.stderr == b""
    return np.frombuffer(r.stdout, np.uint8).reshape(-1, *shape)


# --------------------------------------------------------------------------
# A movie alone writes no frames


@needs_ffmpeg
def test_mp4_alone_writes_no_pngs_and_o_adds_them(tmp_path):
    src = program(tmp_path, 30)
    r = run("run", str(src), "--mp4", "film.mp4", "--size", "64x48", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stderr.endswith("MP4 written to film.mp4\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["film.mp4", src.name]
    alone = decode(tmp_path / "film.mp4", (48, 64))
    assert len(alone) == 30
    r = run("run", str(src), "--mp4", "both.mp4", "-o", "out", "--size", "64x48", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    frames = [read_png(p) for p in pngs(tmp_path / "out")]
    assert len(frames) == 30
    assert (tmp_path / "both.mp4").read_bytes() == (tmp_path / "film.mp4").read_bytes()
    assert np.abs(alone.astype(int) - np.array(frames)).mean() < 3  # lossy, but the same pictures


def test_gif_alone_is_streamed_and_exact(tmp_path):
    src = program(tmp_path, 30)
    r = run("run", str(src), "--gif", "a.gif", "--size", "64x48", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.gif", src.name]
    r = run("run", str(src), "-o", "out", "--size", "64x48", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    frames = [read_png(p) for p in pngs(tmp_path / "out")]
    with Image.open(tmp_path / "a.gif") as gif:
        assert gif.n_frames == 30
        for i, frame in enumerate(frames):
            gif.seek(i)
            np.testing.assert_array_equal(np.asarray(gif.convert("L")), frame)


def test_the_library_writes_a_movie_without_a_frames_folder(tmp_path):
    from liganimate.compiler import load_program

    prog, _ = load_program(str(program(tmp_path, 12)))
    prog.render(None, gif=str(tmp_path / "a.gif"), size=(32, 24), quiet=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.gif", "swing.lig"]
    with pytest.raises(RenderError, match="nothing would be written"):
        prog.render(None, size=(32, 24), quiet=True)


def test_frames_are_not_read_back(tmp_path, monkeypatch):
    # The movies take the images from memory: reading a PNG back would fail here.
    from liganimate.compiler import load_program
    from liganimate.runtime.render import imagefiles

    def refuse(*args, **kw):
        raise AssertionError("a frame was read back")

    monkeypatch.setattr(imagefiles, "read_png", refuse)
    monkeypatch.setattr(Image, "open", refuse)
    prog, _ = load_program(str(program(tmp_path, 20)))
    prog.render(str(tmp_path / "out"), gif=str(tmp_path / "a.gif"), size=(32, 24), quiet=True)
    assert (tmp_path / "a.gif").stat().st_size > 0 and len(pngs(tmp_path / "out")) == 20


# --------------------------------------------------------------------------
# Same program, same MP4 bytes


@needs_ffmpeg
def test_the_same_program_gives_the_same_mp4_bytes(tmp_path):
    src = program(tmp_path, 60)
    outs = []
    for name, workers in (("a", None), ("b", None), ("c", "1")):
        env = {**os.environ}
        args = ["run", str(src), "--mp4", f"{name}.mp4", "--size", "96x72", "--quiet"]
        if workers:
            # One process: the images come in another rhythm, the bytes must not change.
            code = (
                "import sys; from liganimate.compiler import load_program; p, _ = load_program(sys.argv[1]); "
                "p.render(None, mp4=sys.argv[2], size=(96, 72), quiet=True, workers=1)"
            )
            r = python("-c", code, str(src), f"{name}.mp4", cwd=tmp_path)
        else:
            r = run(*args, cwd=tmp_path, env=env)
        assert r.returncode == 0, r.stderr
        outs.append((tmp_path / f"{name}.mp4").read_bytes())
    assert outs[0] == outs[1] == outs[2]
    assert len(decode(tmp_path / "a.mp4", (72, 96))) == 60


# --------------------------------------------------------------------------
# --crf and --preset


@pytest.mark.parametrize(
    "args, message",
    [
        (["--crf", "52"], "--crf 52 is not a quality for the MP4; give a whole number from 0 (lossless) to 51"),
        (["--crf", "high"], "--crf high is not a quality for the MP4; give a whole number from 0 (lossless) to 51"),
        (["--crf", "1.5"], "--crf 1.5 is not a quality for the MP4; give a whole number from 0 (lossless) to 51"),
        (["--preset", "quick"], "--preset quick is not an x264 preset; give one of ultrafast, superfast, veryfast"),
    ],
)
def test_bad_crf_or_preset_is_refused_before_compiling(tmp_path, args, message):
    src = program(tmp_path, 4)
    r = run("run", str(src), "--mp4", "a.mp4", *args, cwd=tmp_path)
    # A value no encoder could take is a usage error: exit 2, the usage line, then the sentence.
    assert r.returncode == 2
    assert r.stderr.startswith("usage: liganimate run ")
    last = r.stderr.splitlines()[-1]
    assert last.startswith(f"liganimate run: error: {message}") and "Traceback" not in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [src.name]


@needs_ffmpeg
def test_crf_and_preset_change_the_movie(tmp_path):
    src = program(tmp_path, 24)
    sizes = {}
    for crf, preset in (("18", "veryfast"), ("35", "veryfast"), ("18", "ultrafast")):
        name = f"{crf}{preset}.mp4"
        r = run("run", str(src), "--mp4", name, "--crf", crf, "--preset", preset, "--size", "96x72", cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        sizes[(crf, preset)] = (tmp_path / name).stat().st_size
    assert sizes[("35", "veryfast")] < sizes[("18", "veryfast")] < sizes[("18", "ultrafast")]


# --------------------------------------------------------------------------
# Ctrl-C during a streamed MP4


@needs_ffmpeg
@pytest.mark.parametrize("earlier", [False, True])
def test_ctrl_c_during_a_streamed_mp4_leaves_no_video_or_a_playable_one(tmp_path, earlier):
    src = program(tmp_path, 100_000)
    if earlier:
        # A movie from an earlier run is kept whole, not replaced by half of the new one.
        r = run("run", str(program(tmp_path, 10, "short")), "--mp4", "film.mp4", "--size", "160x120", cwd=tmp_path)
        assert r.returncode == 0, r.stderr
        before = (tmp_path / "film.mp4").read_bytes()
    out = tmp_path / "out"
    proc = start_render(src, ["--mp4", "film.mp4"], tmp_path, 60)
    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C at a terminal: the whole process group
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert err.endswith("\nliganimate: interrupted; every file already written is complete\n")
    written = pngs(out)
    assert 60 < len(written) < 100_000
    assert [p.name for p in written] == [f"{i:05d}.png" for i in range(len(written))]
    for p in written:
        assert read_png(p).shape == (120, 160)
    movie = tmp_path / "film.mp4"
    if earlier:
        assert movie.read_bytes() == before
    if movie.exists():
        assert len(decode(movie, (120, 160))) >= 1  # playable
    assert leftovers(tmp_path) == []
    # No ffmpeg is left running.
    left = subprocess.run(["pgrep", "-f", str(tmp_path / ".film.mp4")], capture_output=True, text=True).stdout
    assert left == ""


# --------------------------------------------------------------------------
# Colour images through every writer


def colour_frames(n, shape=(48, 64)):
    out = []
    for i in range(n):
        f = np.zeros((*shape, 3), np.uint8)
        f[...] = (250, 240, 200)
        f[5 + i : 25 + i, 10 + 2 * i : 30 + 2 * i] = (200, 30, 10 * i)
        f[30:40, 5:15] = (20, 90, 220)
        out.append(f)
    return out


def test_png_of_a_colour_image_is_rgb_and_exact(tmp_path):
    img = colour_frames(1)[0]
    img[0, 0] = (1, 2, 3)
    write_png(tmp_path / "c.png", img)
    with Image.open(tmp_path / "c.png") as im:
        assert im.mode == "RGB"
    np.testing.assert_array_equal(read_png(tmp_path / "c.png", colour=True), img)
    data = (tmp_path / "c.png").read_bytes()
    assert data[25] == 2  # IHDR colour type: truecolour
    assert encode_png(img.copy()) == data


def test_grey_png_bytes_are_unchanged():
    # The bytes the encoder gave this greyscale image before colour came in (sha-256 of the file).
    import hashlib

    img = np.full((48, 64), 200, np.uint8)
    img[10:30, 10:40] = np.arange(30, dtype=np.uint8)[None, :] * 5
    data = encode_png(img)
    assert data[25] == 0  # IHDR colour type: greyscale
    assert hashlib.sha256(data).hexdigest() == GREY_PNG_SHA256


GREY_PNG_SHA256 = "145d7421c0baa2a0bcb04226f058d5024a0467fb95fcac9e40e783d32bcc8fcb"  # the encoder of commit 2526992


def test_gif_of_colour_frames(tmp_path):
    fr = colour_frames(6)
    assert video.write_gif(tmp_path / "c.gif", fr, fps=12) == 6
    with Image.open(tmp_path / "c.gif") as gif:
        assert gif.n_frames == 6
        for i, frame in enumerate(fr):
            gif.seek(i)
            np.testing.assert_array_equal(np.asarray(gif.convert("RGB")), frame)  # few colours: exact
    video.write_gif(tmp_path / "d.gif", fr, fps=12)
    assert (tmp_path / "c.gif").read_bytes() == (tmp_path / "d.gif").read_bytes()


@needs_ffmpeg
def test_mp4_of_colour_frames(tmp_path):
    fr = colour_frames(8)
    assert video.write_mp4(tmp_path / "c.mp4", fr, fps=12) == 8
    got = decode(tmp_path / "c.mp4", (48, 64, 3), "rgb24")
    assert len(got) == 8
    assert np.abs(got[:, 30:40, 5:15].astype(int) - fr[0][30:40, 5:15]).mean() < 12  # the blue patch is blue
    with pytest.raises(RenderError, match="Frame 1 is"):
        video.write_mp4(tmp_path / "x.mp4", [fr[0], fr[0][..., 0]], fps=12)
    assert leftovers(tmp_path) == []
