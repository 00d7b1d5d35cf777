"""PNG, GIF and MP4 writers (imagefiles, video) and atomic files (runtime/files.py): round trips, determinism, atomicity, errors."""

from __future__ import annotations

import errno
import os
import struct
import subprocess
import zlib

import numpy as np
import pytest
from PIL import Image

from liganimate.runtime import files
from liganimate.runtime.errors import RenderError
from liganimate.runtime.render import video
from liganimate.runtime.render.imagefiles import encode_png, read_png, write_png
from liganimate.runtime.render.video import write_gif, write_mp4


def frames(n, shape=(48, 64), seed=0):
    """n flat-shaded-looking frames: a moving dark square on grey, shape (H, W) each."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        f = np.full(shape, 200, np.uint8)
        f[5 + i : 25 + i, 10 + 2 * i : 30 + 2 * i] = 40 + 10 * i
        f[-3:, :] = rng.integers(0, 256, (3, shape[1]))
        out.append(f)
    return out


def chunks(data: bytes):
    """PNG chunk types in order."""
    pos, kinds = 8, []
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length : pos + 12 + length])
        assert crc == zlib.crc32(kind + body)
        kinds.append(kind)
        pos += 12 + length
    return kinds


def leftovers(folder):
    return [n for n in os.listdir(folder) if n.endswith(".tmp")]


# --------------------------------------------------------------------------
# PNG


@pytest.mark.parametrize("shape", [(1, 1), (480, 640), (7, 13), (300, 1)])
def test_png_round_trip(tmp_path, shape):
    img = np.random.default_rng(1).integers(0, 256, shape).astype(np.uint8)
    img[: shape[0] // 2] = 77  # some flat area as well as noise
    path = tmp_path / "a.png"
    write_png(path, img)
    np.testing.assert_array_equal(read_png(path), img)
    with Image.open(path) as im:
        assert im.mode == "L" and im.size == (shape[1], shape[0])


def test_png_is_minimal_and_deterministic(tmp_path):
    img = frames(1, (480, 640))[0]
    data = encode_png(img)
    assert data.startswith(b"\x89PNG\r\n\x1a\n")
    assert chunks(data) == [b"IHDR", b"IDAT", b"IEND"]  # no time or text chunks
    assert encode_png(img.copy()) == data
    write_png(tmp_path / "a.png", img)
    write_png(tmp_path / "b.png", img)
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes() == data
    assert len(data) < 20_000  # flat images compress well


def test_png_write_is_atomic(tmp_path, monkeypatch):
    path = tmp_path / "frame.png"
    write_png(path, np.zeros((4, 4), np.uint8))
    old = path.read_bytes()

    def fail(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(files.os, "fsync", fail)
    with pytest.raises(RenderError, match=f"^no space left on device while writing {path}$"):
        write_png(path, np.full((4, 4), 255, np.uint8))
    assert path.read_bytes() == old  # the old file is intact
    assert leftovers(tmp_path) == []  # and no temporary file remains
    monkeypatch.undo()
    write_png(path, np.full((4, 4), 255, np.uint8))
    assert (read_png(path) == 255).all()
    umask = os.umask(0)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask  # not mkstemp's 0600


def test_png_rejects_bad_images(tmp_path):
    for bad in [
        np.zeros((4, 4), np.float64),
        np.zeros((4, 4, 2), np.uint8),
        np.zeros((4, 4, 4), np.uint8),
        np.zeros((0, 4), np.uint8),
    ]:
        with pytest.raises(RenderError):
            write_png(tmp_path / "x.png", bad)
    assert os.listdir(tmp_path) == []


# --------------------------------------------------------------------------
# GIF


def test_gif_round_trip_and_timing(tmp_path):
    fr = frames(7)
    path = tmp_path / "a.gif"
    assert write_gif(path, iter(fr), fps=30) == 7
    with Image.open(path) as im:
        assert im.n_frames == 7 and im.size == (64, 48)
        assert im.info.get("loop") == 0
        durations = []
        for i in range(7):
            im.seek(i)
            np.testing.assert_array_equal(np.asarray(im.convert("L")), fr[i])
            durations.append(im.info["duration"])
    # Hundredths of a second, spread so the total stays exact: 7 frames at 30 fps = 0.233 s.
    assert durations == [30, 40, 30, 30, 40, 30, 30]


def test_gif_is_deterministic_and_streams(tmp_path):
    pulled = []

    def gen():
        for i, f in enumerate(frames(5)):
            pulled.append(i)
            yield f

    write_gif(tmp_path / "a.gif", gen(), fps=10)
    write_gif(tmp_path / "b.gif", frames(5), fps=10)
    assert (tmp_path / "a.gif").read_bytes() == (tmp_path / "b.gif").read_bytes()
    assert pulled == list(range(5))


def test_gif_errors_leave_nothing(tmp_path):
    path = tmp_path / "a.gif"
    with pytest.raises(RenderError, match="no frames"):
        write_gif(path, [], fps=10)
    with pytest.raises(RenderError, match="Frame 1"):
        write_gif(path, [np.zeros((4, 4), np.uint8), np.zeros((5, 4), np.uint8)], fps=10)
    for fps in (0, -1, float("nan"), float("inf"), 0.001, 1e6):
        with pytest.raises(RenderError, match="Frames per second must be from 0.01 to 1000"):
            write_gif(path, frames(2), fps=fps)
    assert os.listdir(tmp_path) == []


def test_gif_at_the_slowest_and_fastest_rates(tmp_path):
    # 0.01 fps is 10,000 hundredths a frame, within a GIF's 16-bit delay.
    for fps, delay in ((0.01, 100_000), (1000, 0)):
        write_gif(tmp_path / "a.gif", frames(2), fps=fps)
        with Image.open(tmp_path / "a.gif") as im:
            assert im.n_frames == 2
            assert im.info.get("duration", 0) == delay


# --------------------------------------------------------------------------
# MP4

needs_ffmpeg = pytest.mark.skipif(
    not any(
        [
            __import__("importlib").util.find_spec("imageio_ffmpeg"),
            __import__("shutil").which("ffmpeg"),
        ]
    ),
    reason="no ffmpeg",
)


def decode_mp4(path, shape):
    exe = video.find_ffmpeg()
    out = subprocess.run(
        [exe, "-loglevel", "error", "-i", str(path), "-f", "rawvideo", "-pix_fmt", "gray", "pipe:1"],
        capture_output=True,
        check=True,
    ).stdout
    return np.frombuffer(out, np.uint8).reshape(-1, *shape)


@needs_ffmpeg
def test_mp4_round_trip_and_determinism(tmp_path):
    fr = frames(12, (48, 64))
    a, b = tmp_path / "a.mp4", tmp_path / "b.mp4"
    assert write_mp4(a, (f for f in fr), fps=25) == 12
    write_mp4(b, fr, fps=25)
    data = a.read_bytes()
    assert data[4:8] == b"ftyp"
    assert data == b.read_bytes()
    got = decode_mp4(a, (48, 64))
    assert len(got) == 12
    umask = os.umask(0)
    os.umask(umask)
    assert a.stat().st_mode & 0o777 == 0o666 & ~umask
    # Lossy, but close on flat areas.
    assert np.abs(got[:, :40].astype(int) - np.array(fr)[:, :40]).mean() < 3
    assert leftovers(tmp_path) == []


@needs_ffmpeg
def test_mp4_odd_size_is_padded(tmp_path):
    path = tmp_path / "odd.mp4"
    write_mp4(path, frames(3, (49, 65)), fps=29.97)
    got = decode_mp4(path, (50, 66))
    assert got.shape == (3, 50, 66)
    assert (got[:, :, -1] > 230).all()  # padded with white


def test_mp4_without_ffmpeg_says_how_to_get_it(tmp_path, monkeypatch):
    import imageio_ffmpeg

    def missing():
        raise RuntimeError("no ffmpeg")

    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", missing)
    monkeypatch.setattr(video.shutil, "which", lambda name: None)
    with pytest.raises(RenderError) as err:
        write_mp4(tmp_path / "a.mp4", frames(2), fps=10)
    assert "ffmpeg" in err.value.message
    assert "pip install imageio-ffmpeg" in err.value.hint
    assert os.listdir(tmp_path) == []


def test_mp4_ffmpeg_failure_is_a_render_error(tmp_path, monkeypatch):
    monkeypatch.setattr(video, "find_ffmpeg", lambda: "false")  # exits 1 at once
    path = tmp_path / "a.mp4"
    path.write_bytes(b"old")
    with pytest.raises(RenderError, match="ffmpeg"):
        write_mp4(path, frames(3), fps=10)
    assert path.read_bytes() == b"old"
    assert leftovers(tmp_path) == []


# --------------------------------------------------------------------------
# Faults: whatever step fails, the temporary file goes and the error names the file


def _failing_at(monkeypatch, name, when=1, err=errno.ENOSPC):
    """Make os.<name> (as runtime/files.py calls it) raise OSError(err) on its ``when``-th call (1-based) from now on."""
    real = getattr(files.os, name)
    calls = []

    def fake(*args, **kw):
        calls.append(args)
        if len(calls) >= when:
            raise OSError(err, os.strerror(err))
        return real(*args, **kw)

    monkeypatch.setattr(files.os, name, fake)
    return calls


@pytest.mark.parametrize("step", ["write", "fsync", "fchmod", "close", "replace"])
def test_atomic_writer_cleans_up_whatever_step_fails(tmp_path, monkeypatch, step):
    path = tmp_path / "poses.jsonl"
    path.write_bytes(b"old")
    calls = _failing_at(monkeypatch, step)
    with pytest.raises(RenderError) as info, files.AtomicWriter(path, buffer=4) as f:
        f.write(b"0123456789" * 100)
    assert calls, f"os.{step} was never called"
    assert info.value.message == f"no space left on device while writing {path}"
    assert ".tmp" not in info.value.message
    monkeypatch.undo()
    assert path.read_bytes() == b"old"
    assert leftovers(tmp_path) == []


def test_atomic_writer_unlinks_before_closing(tmp_path, monkeypatch):
    # A full disk gets its space back even when close() itself fails (the old
    # writer raised from close() before reaching its unlink, keeping 3 MB).
    seen = []
    real_close = os.close

    def close(fd):
        seen.append(leftovers(tmp_path))
        real_close(fd)
        raise OSError(errno.ENOSPC, "No space left on device")

    writer = files.AtomicWriter(tmp_path / "a.gif")
    writer.write(b"x" * 10)
    monkeypatch.setattr(files.os, "close", close)
    writer.abort()
    writer.abort()  # idempotent
    assert seen == [[]]
    assert leftovers(tmp_path) == []


def test_atomic_writer_interrupted_leaves_nothing(tmp_path, monkeypatch):
    def interrupt(fd, data):
        raise KeyboardInterrupt

    monkeypatch.setattr(files.os, "write", interrupt)
    with pytest.raises(KeyboardInterrupt), files.AtomicWriter(tmp_path / "a.png") as f:
        f.write(b"data")
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize(
    "code, words",
    [(errno.EDQUOT, "disk quota exceeded"), (errno.EROFS, "read-only"), (errno.EFBIG, "larger than the system allows")],
)
def test_write_errors_are_plain_words_naming_the_file(tmp_path, monkeypatch, code, words):
    _failing_at(monkeypatch, "write", err=code)
    path = tmp_path / "x.gif"
    with pytest.raises(RenderError, match=f"{words}.* while writing {path}$"):
        write_gif(path, frames(3), fps=10)
    monkeypatch.undo()
    assert os.listdir(tmp_path) == []


def test_a_missing_folder_or_a_folder_in_the_way_is_named(tmp_path):
    with pytest.raises(RenderError, match=f"^{tmp_path} is a folder, not a file$"):
        write_png(tmp_path, np.zeros((2, 2), np.uint8))
    path = tmp_path / "missing" / "a.png"
    with pytest.raises(RenderError, match=f"^cannot write {path}: the folder {path.parent} does not exist$"):
        write_png(path, np.zeros((2, 2), np.uint8))


def test_gif_on_a_full_file_system_in_a_subprocess(tmp_path):
    # A real write failure, not a patched one: RLIMIT_FSIZE makes write() fail
    # with EFBIG past 20 kB (SIGXFSZ ignored), as a full disk fails with ENOSPC.
    code = f"""
import resource, signal, sys
import numpy as np
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))
from liganimate.runtime.errors import RenderError
from liganimate.runtime.render.video import write_gif
rng = np.random.default_rng(0)
try:
    write_gif({str(tmp_path / "big.gif")!r}, (rng.integers(0, 256, (64, 64), dtype=np.uint8) for _ in range(40)), 10)
except RenderError as exc:
    print(exc.message)
"""
    out = subprocess.run(
        [__import__("sys").executable, "-c", code], check=False, capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == f"the file grew larger than the system allows while writing {tmp_path / 'big.gif'}"
    assert os.listdir(tmp_path) == []
