"""Image and movie files: greyscale PNG, animated GIF and MP4.

Every writer is atomic: it writes a temporary file in the destination's
folder and renames it over the destination only when complete, so a reader
never sees a half-written file and a failed write leaves any earlier file
intact.  Whatever fails (creating, writing, flushing, syncing, closing or
renaming), the temporary file is removed and the error names the file the
caller asked for (see :class:`AtomicWriter`).
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import struct
import subprocess
import tempfile
import zlib
from collections.abc import Iterable
from fractions import Fraction
from typing import Self

import numpy as np

from liganimate.runtime.errors import RenderError

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
# Chosen by measurement on flat-shaded 640x480 frames of five figures
# (filters None/Sub/Up x zlib levels 1-6 x default/RLE strategy): the Up
# filter turns the many rows equal to the row above into zeros, and RLE at
# level 1 then gives the smallest files of all (4.5 kB, as small as level 6
# unfiltered) in 0.8 ms, where level 6 takes 2.1 ms.  zlib's memory level
# 4 (rather than 9) then takes 0.46 ms instead of 0.73 on the 1,000 frames
# of benchmarks/scene.py, and gives slightly smaller files (3.0 kB, not
# 3.1): with RLE, the larger buffers only cost time to set up.  Splicing
# in cached blocks for runs of rows equal to the row above (_zlib_rows)
# then brings it to 0.29 ms, at 3.2 kB.
_PNG_LEVEL = 1
_PNG_STRATEGY = zlib.Z_RLE
_PNG_MEMLEVEL = 4
_PNG_FILTER_UP = 2


def _check_image(img) -> np.ndarray:
    a = np.asarray(img)
    if a.ndim != 2 or a.shape[0] < 1 or a.shape[1] < 1:
        raise RenderError(f"An image must be a 2-D array of grey levels, not shape {a.shape}.")
    if a.dtype != np.uint8:
        raise RenderError(f"An image must hold 8-bit grey levels (uint8), not {a.dtype}.")
    return a


def encode_png(img) -> bytes:
    """Encode a greyscale image as PNG bytes.

    The output depends only on the pixels: no timestamp, gamma or other
    ancillary chunk is written.

    Parameters
    ----------
    img : array_like, shape (H, W), uint8
        Grey levels, row 0 at the top.

    Returns
    -------
    bytes
        A complete PNG file (8-bit greyscale, not interlaced).
    """
    a = _check_image(img)
    H, W = a.shape
    rows = np.empty((H, W + 1), dtype=np.uint8)
    rows[:, 0] = _PNG_FILTER_UP
    rows[0, 1:] = a[0]  # Up on the first row sees a row of zeros
    np.subtract(a[1:], a[:-1], out=rows[1:, 1:])  # uint8 arithmetic wraps mod 256, as PNG wants
    header = struct.pack(">IIBBBBB", W, H, 8, 0, 0, 0, 0)
    data = _zlib_rows(rows)
    return b"".join([_PNG_SIGNATURE, _chunk(b"IHDR", header), _chunk(b"IDAT", data), _chunk(b"IEND", b"")])


# A run of at least this many rows equal to the row above is not compressed
# again but spliced in from a cache (see _zlib_rows).
_BLANK_RUN = 8


def _zlib_rows(rows: np.ndarray) -> bytes:
    """The zlib stream of filtered PNG rows (H, W + 1), spliced for speed.

    With the Up filter, a row equal to the row above filters to zeros (a
    "blank" row), and in flat-shaded frames most rows are: background above
    and below the figures.  Runs of blank rows are not deflated every time:
    their deflate blocks, ended by a full flush (which aligns to a byte and
    forgets the history), are computed once per width and length and
    spliced between the blocks of the other rows, each stretch of which is
    likewise ended by a full flush.  The Adler-32 checksum runs over the
    other rows and is advanced over blank runs by formula.  The stream is a
    valid zlib stream for any pixels, and depends on the pixels alone.
    """
    H, W1 = rows.shape
    blank = rows[:, 1:].max(axis=1, initial=0) == 0
    if H > 1 and rows.shape[1] > 1:
        # Runs of blank rows: [start, end) pairs at least _BLANK_RUN long.
        edges = np.flatnonzero(np.diff(np.concatenate([[False], blank, [False]]).astype(np.int8)))
        runs = [(int(b), int(e)) for b, e in zip(edges[0::2], edges[1::2]) if e - b >= _BLANK_RUN]
    else:
        runs = []
    comp = zlib.compressobj(_PNG_LEVEL, zlib.DEFLATED, -15, _PNG_MEMLEVEL, _PNG_STRATEGY)
    out = [b"\x78\x01"]  # zlib header: deflate, 32 kB window, fastest
    adler = 1
    at = 0
    for start, end in runs:
        if start > at:
            out.append(comp.compress(rows[at:start].data))
            out.append(comp.flush(zlib.Z_FULL_FLUSH))
            adler = zlib.adler32(rows[at:start].data, adler)
        out.append(_blank_blocks(W1, end - start))
        adler = _adler32_blank(adler, W1, end - start)
        at = end
    if at < H:
        out.append(comp.compress(rows[at:].data))
        adler = zlib.adler32(rows[at:].data, adler)
    out.append(comp.flush(zlib.Z_FINISH))
    out.append(struct.pack(">I", adler))
    return b"".join(out)


def _adler32_blank(adler: int, width: int, count: int) -> int:
    """Adler-32 continued over ``count`` blank rows: the Up filter byte, then ``width - 1`` zeros.

    Each row adds 2 to A, then A (now A + 2) to B once per byte of the row:
    over k rows, A grows by 2k and B by ``width (k A + k (k + 1))``.
    """
    a, b = adler & 0xFFFF, adler >> 16
    b = (b + width * (count * a + count * (count + 1))) % 65521
    a = (a + 2 * count) % 65521
    return (b << 16) | a


_BLANK_CACHE: dict = {}


def _blank_blocks(width: int, count: int) -> bytes:
    """Deflate blocks (byte-aligned, history-free, not final) of ``count`` blank rows of ``width`` bytes."""
    parts = []
    bit = 1
    while count:
        if count & bit:
            key = (width, bit)
            block = _BLANK_CACHE.get(key)
            if block is None:
                row = bytes([_PNG_FILTER_UP]) + bytes(width - 1)
                comp = zlib.compressobj(_PNG_LEVEL, zlib.DEFLATED, -15, _PNG_MEMLEVEL, _PNG_STRATEGY)
                block = comp.compress(row * bit) + comp.flush(zlib.Z_FULL_FLUSH)
                if len(_BLANK_CACHE) > 256:
                    _BLANK_CACHE.clear()
                _BLANK_CACHE[key] = block
            parts.append(block)
            count -= bit
        bit <<= 1
    return b"".join(parts)


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(data, zlib.crc32(kind)))


def write_png(path, img, *, fsync: bool = True) -> None:
    """Write a greyscale image as a PNG file, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        Destination; replaced if it exists.
    img : array_like, shape (H, W), uint8
        Grey levels, row 0 at the top.
    fsync : bool, optional
        Flush the data to disk before the rename (default), so that after a
        crash the file is either the old one or the complete new one.
    """
    data = encode_png(img)
    with AtomicWriter(path, fsync) as f:
        f.write(data)


def read_png(path) -> np.ndarray:
    """Read a PNG file as a greyscale image.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    ndarray, shape (H, W), uint8
        Grey levels (colour images are converted to luminance).
    """
    from PIL import Image

    with Image.open(path) as im:
        return np.asarray(im.convert("L")).copy()


def write_gif(path, frames_iter: Iterable, fps: float) -> int:
    """Write greyscale frames as a looping animated GIF, atomically.

    Frames are encoded and written one at a time (using Pillow's per-frame
    GIF encoder), so memory does not grow with the length of the animation.
    Every frame is stored whole with a 256-grey global palette.

    GIF delays are whole hundredths of a second; frame ``i`` is shown for
    ``round(100 (i+1) / fps) - round(100 i / fps)`` hundredths so the total
    duration stays exact (e.g. 30 fps gives 3, 4, 3, 3, 4, 3, ...).  Most
    viewers show delays under 2 hundredths as 10, so above 50 fps a GIF
    plays slower than intended.

    Parameters
    ----------
    path : str or os.PathLike
        Destination; replaced if it exists.
    frames_iter : iterable of ndarray, each shape (H, W), uint8
        The frames, all the same size.
    fps : float
        Frames per second; positive.

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    RenderError
        If there are no frames, frames differ in size, or fps is not positive.
    """
    from PIL import GifImagePlugin, Image

    fps = _check_fps(fps)
    frames = iter(frames_iter)
    first = _first_frame(frames)
    size = first.shape
    canvas = Image.new("L", (size[1], size[0]))
    header, _ = GifImagePlugin.getheader(canvas, None, {"loop": 0, "duration": 1, "optimize": False})
    n = 0
    with AtomicWriter(path) as f:
        for part in header:
            f.write(part)
        for frame in _chain_checked(first, frames, size):
            delay = round(100 * (n + 1) / fps) - round(100 * n / fps)
            im = Image.frombuffer("L", (size[1], size[0]), np.ascontiguousarray(frame), "raw", "L", 0, 1)
            for part in GifImagePlugin.getdata(im, (0, 0), duration=10 * delay):
                f.write(part)
            n += 1
        f.write(b";")
    return n


def write_mp4(path, frames_iter: Iterable, fps: float) -> int:
    """Write greyscale frames as an H.264 MP4 movie, atomically.

    Raw frames are piped to ffmpeg (imageio-ffmpeg's bundled binary, else
    ``ffmpeg`` on PATH) and encoded with libx264, yuv420p, CRF 18, with
    ffmpeg's bit-exact flags and no metadata so that the same frames give
    the same bytes with the same ffmpeg.  Odd image sizes are padded by one
    white pixel on the right/bottom (yuv420p needs even sizes).

    Parameters
    ----------
    path : str or os.PathLike
        Destination; replaced if it exists.
    frames_iter : iterable of ndarray, each shape (H, W), uint8
        The frames, all the same size.  They are streamed, not held.
    fps : float
        Frames per second; positive.

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    RenderError
        If no ffmpeg can be found, ffmpeg fails, there are no frames, frames
        differ in size, or fps is not positive.
    """
    fps = _check_fps(fps)
    exe = find_ffmpeg()
    frames = iter(frames_iter)
    first = _first_frame(frames)
    H, W = first.shape
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    try:
        fd, tmp = tempfile.mkstemp(dir=folder, prefix="." + os.path.basename(path) + ".", suffix=".tmp")
        os.close(fd)
    except OSError as exc:
        raise write_error(exc, path) from None
    # An exact rational rate, so e.g. 29.97 is not rounded by ffmpeg's parser.
    frac = Fraction(fps).limit_denominator(1_000_000)
    rate = f"{frac.numerator}/{frac.denominator}"
    cmd = [
        exe, "-hide_banner", "-nostdin", "-loglevel", "error", "-y",
        "-f", "rawvideo", "-pix_fmt", "gray", "-s", f"{W}x{H}", "-framerate", rate, "-i", "pipe:0",
        "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white",
        "-c:v", "libx264", "-preset", "medium", "-crf", "18", "-pix_fmt", "yuv420p",
        "-map_metadata", "-1", "-fflags", "+bitexact", "-flags:v", "+bitexact", "-flags:a", "+bitexact",
        "-movflags", "+faststart", "-f", "mp4", tmp,
    ]  # fmt: skip
    n = 0
    try:
        # stderr goes to a file: a pipe nobody reads could fill and deadlock us.
        with tempfile.TemporaryFile() as err:
            proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=err)
            try:
                try:
                    for frame in _chain_checked(first, frames, (H, W)):
                        proc.stdin.write(np.ascontiguousarray(frame).data)
                        n += 1
                except BrokenPipeError:
                    pass  # ffmpeg stopped early; its exit status and message say why
                finally:
                    with contextlib.suppress(BrokenPipeError):
                        proc.stdin.close()
                rc = proc.wait()
            except BaseException:
                proc.kill()
                proc.wait()
                raise
            if rc != 0:
                err.seek(0)
                msg = err.read().decode("utf-8", "replace").strip().splitlines()
                raise RenderError(
                    f"ffmpeg could not write the MP4 file {path} (exit status {rc}).",
                    hint=msg[-1] if msg else None,
                )
        try:
            with open(tmp, "rb+") as f:
                os.fsync(f.fileno())
            os.chmod(tmp, 0o666 & ~_UMASK)
            os.replace(tmp, path)
        except OSError as exc:
            raise write_error(exc, path) from None
    finally:
        with contextlib.suppress(OSError):
            os.remove(tmp)
    return n


def find_ffmpeg() -> str:
    """The ffmpeg executable to use for MP4 output.

    Returns
    -------
    str
        imageio-ffmpeg's binary if that package is installed and works,
        otherwise ``ffmpeg`` from PATH.

    Raises
    ------
    RenderError
        If neither can be found.
    """
    try:
        import imageio_ffmpeg

        exe = imageio_ffmpeg.get_ffmpeg_exe()
        if exe and os.path.exists(exe):
            return exe
    except (ImportError, RuntimeError, OSError):
        pass
    exe = shutil.which("ffmpeg")
    if exe:
        return exe
    raise RenderError(
        "MP4 output needs the ffmpeg program, and none was found.",
        hint="pip install imageio-ffmpeg (it bundles ffmpeg), or install ffmpeg on your PATH; GIF and PNG output need neither.",
    )


def _check_fps(fps) -> float:
    from liganimate.runtime.render.outputs import MAX_FPS, MIN_FPS

    try:
        f = float(fps)
    except (TypeError, ValueError, OverflowError):
        f = float("nan")
    # GIF delays are 16-bit hundredths of a second: a slower rate cannot be stored.
    if not (MIN_FPS <= f <= MAX_FPS):
        raise RenderError(f"Frames per second must be from {MIN_FPS:g} to {MAX_FPS:g}, not {fps!r}.")
    return f


def _first_frame(frames) -> np.ndarray:
    try:
        return _check_image(next(frames))
    except StopIteration:
        raise RenderError("There are no frames to write.") from None


def _chain_checked(first, rest, shape):
    yield first
    for i, frame in enumerate(rest, start=1):
        frame = _check_image(frame)
        if frame.shape != shape:
            raise RenderError(f"Frame {i} is {frame.shape[1]}x{frame.shape[0]}, but frame 0 is {shape[1]}x{shape[0]}.")
        yield frame


# Plain words for the errors a full, read-only or forbidden destination gives.
_ERRNO_WORDS = {
    errno.ENOSPC: "no space left on device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EFBIG: "the file grew larger than the system allows",
    errno.EROFS: "the file system is read-only",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EIO: "input/output error",
}


def os_error_words(exc: OSError) -> str:
    """A plain, lower-case phrase for an OSError ("no space left on device")."""
    words = _ERRNO_WORDS.get(exc.errno)
    if words is None:
        text = exc.strerror or str(exc) or type(exc).__name__
        words = text[:1].lower() + text[1:]
    return words


def write_error(exc: OSError, path) -> RenderError:
    """The error to show for ``exc`` raised while writing ``path``: it names ``path``, not a temporary file."""
    path = os.fspath(path)
    if exc.errno == errno.EISDIR:
        return RenderError(f"{path} is a folder, not a file")
    if exc.errno == errno.ENOENT:
        return RenderError(f"cannot write {path}: the folder {os.path.dirname(path) or '.'} does not exist")
    if exc.errno == errno.ENOTDIR:
        return RenderError(f"cannot write {path}: part of its path is not a folder")
    return RenderError(f"{os_error_words(exc)} while writing {path}")


class AtomicWriter:
    """A file written under a temporary name and renamed over ``path`` by :meth:`commit`.

    The temporary file (``.<name>.<random>.tmp``) lives in the destination's
    folder, so the rename is atomic.  Data is written with ``os.write`` from
    an in-memory buffer (no Python file object whose ``close`` could fail
    half-way).  On any failure, and on :meth:`abort`, the temporary file is
    unlinked before anything else is tried, so a full disk gets its space
    back; :meth:`abort` may be called any number of times.

    Parameters
    ----------
    path : str or os.PathLike
        Destination; replaced if it exists.  It is also the name errors give.
    fsync : bool, optional
        Flush the data to disk before the rename (default), so that after a
        crash the file is either the old one or the complete new one.
    buffer : int, optional
        Bytes gathered before each ``os.write``.

    Raises
    ------
    RenderError
        From any method, when the system refuses: the message names ``path``
        and says why in words ("no space left on device while writing out/a.gif").
    """

    def __init__(self, path, fsync: bool = True, buffer: int = 1 << 18):
        self.path = os.fspath(path)
        self._fsync = fsync
        self._limit = buffer
        self._buf = bytearray()
        self._fd = -1
        self._tmp = None
        folder = os.path.dirname(os.path.abspath(self.path))
        try:
            self._fd, self._tmp = tempfile.mkstemp(
                dir=folder, prefix="." + os.path.basename(self.path) + ".", suffix=".tmp"
            )
        except OSError as exc:
            raise write_error(exc, self.path) from None

    @property
    def temporary(self):
        """The temporary file's path while it exists, else None."""
        return self._tmp

    def write(self, data) -> None:
        """Append bytes (or any buffer) to the file."""
        if self._tmp is None:
            raise ValueError("write to a finished AtomicWriter")
        self._buf += data
        if len(self._buf) >= self._limit:
            self._guarded(self._drain)

    def commit(self) -> None:
        """Write what is buffered, sync, and rename the file over the destination."""
        if self._tmp is None:
            raise ValueError("commit of a finished AtomicWriter")
        self._guarded(self._finish)

    def abort(self) -> None:
        """Remove the temporary file and release the descriptor; never raises an OSError."""
        tmp, fd = self._tmp, self._fd
        self._tmp, self._fd, self._buf = None, -1, bytearray()
        # Unlink first: if closing fails (or is interrupted) the space is already given back.
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        if fd >= 0:
            with contextlib.suppress(OSError):
                os.close(fd)

    def _guarded(self, step) -> None:
        try:
            step()
        except OSError as exc:
            self.abort()
            raise write_error(exc, self.path) from None
        except BaseException:
            self.abort()
            raise

    def _drain(self) -> None:
        view = memoryview(self._buf)
        try:
            while view:
                n = os.write(self._fd, view)
                if n <= 0:  # a regular file never does this; do not spin if one does
                    raise OSError(errno.EIO, "write wrote nothing")
                view = view[n:]
        finally:
            view.release()
        self._buf.clear()

    def _finish(self) -> None:
        self._drain()
        if self._fsync:
            os.fsync(self._fd)
        # mkstemp creates the file 0600; give it the permissions a plain open() would.
        os.fchmod(self._fd, 0o666 & ~_UMASK)
        fd, self._fd = self._fd, -1
        os.close(fd)  # close can report a late write error (NFS, quotas): before the rename
        os.replace(self._tmp, self.path)
        self._tmp = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, kind, exc, tb) -> None:
        if kind is None:
            self.commit()
        else:
            self.abort()


def _atomic(path, fsync: bool) -> AtomicWriter:
    """An open binary file that replaces ``path`` only if the ``with`` block succeeds."""
    return AtomicWriter(path, fsync)


def fsync_folder(path) -> None:
    """Make the renames done in folder ``path`` durable (a no-op where folders cannot be opened)."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass  # some file systems refuse to sync a folder; the files themselves are synced
    finally:
        os.close(fd)


# os.umask can only be read by setting it; do that once, at import, rather
# than briefly changing it under other threads on every write.
_UMASK = os.umask(0o022)
os.umask(_UMASK)
