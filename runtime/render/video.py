"""Movies written as the frames come: H.264 MP4 through ffmpeg, and animated GIF.

A stream (:class:`Mp4Stream`, :class:`GifStream`) takes frames one at a
time with :meth:`add`, from memory, and encodes them in a thread of its own
(the MP4's thread feeds an ffmpeg process through a pipe), so encoding runs
beside the drawing of the next frames.  At most a few frames wait in a
stream, so memory stays flat however long the movie.  :meth:`commit`
finishes the file under a temporary name and renames it over the
destination; :meth:`abort` (an error, Ctrl-C) stops the encoder and removes
the temporary file, so an unfinished movie is never seen and an earlier
one is left intact.

Frames are arrays of shape (H, W) (grey levels) or (H, W, 3) (RGB), uint8,
all the same shape.
"""

from __future__ import annotations

import contextlib
import os
import queue
import shutil
import subprocess
import tempfile
import threading
from collections.abc import Iterable
from fractions import Fraction

import numpy as np

from liganimate.runtime.errors import RenderError
from liganimate.runtime.files import AtomicWriter, publish, temporary_beside, write_error
from liganimate.runtime.render.imagefiles import check_image

# x264 presets, fastest first.  The defaults were chosen by measurement
# (docs/semantics-render.md has the table): on 640x480 frames of five
# flat-shaded figures, superfast at CRF 20 takes about 2 core-ms a frame
# (veryfast 2.8, medium 5) at a PSNR of 52 dB against the frames drawn
# (medium at CRF 18: 50.6), for files of 2.7 kB a frame (medium's 1.4):
# the film of 170,000 frames fits the quarter of an hour on two cores, and
# the files stay small.
PRESETS = ("ultrafast", "superfast", "veryfast", "faster", "fast", "medium", "slow", "slower", "veryslow")
DEFAULT_PRESET = "superfast"
DEFAULT_CRF = 20
MAX_CRF = 51
# x264's output depends on its number of threads: a fixed number gives the
# same bytes on every machine.  One: the render workers already keep the
# cores busy, and a second x264 thread only fights them (measured: about 8%
# less of ffmpeg's CPU a frame with one, the same PSNR, 52.2 dB).
X264_THREADS = 1
# Frames waiting in a stream for its thread: enough to ride out the encoder's bursts.
QUEUE_FRAMES = 16


def check_crf(crf, name: str = "--crf") -> int:
    """``crf`` as an int from 0 to 51 (x264's constant rate factor), or a RenderError saying why not."""
    try:
        n = int(crf)
        ok = not isinstance(crf, bool) and n == float(crf) and 0 <= n <= MAX_CRF
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok:
        shown = f"{name}{crf!r}" if name.endswith("=") else f"{name} {crf}"
        raise RenderError(
            f"{shown} is not a quality for the MP4; give a whole number from 0 (lossless) to {MAX_CRF} "
            f"(default {DEFAULT_CRF}; lower is better and larger)"
        )
    return n


def check_preset(preset, name: str = "--preset") -> str:
    """``preset`` as one of x264's :data:`PRESETS`, or a RenderError listing them."""
    if isinstance(preset, str) and preset.strip().lower() in PRESETS:
        return preset.strip().lower()
    shown = f"{name}{preset!r}" if name.endswith("=") else f"{name} {preset}"
    raise RenderError(f"{shown} is not an x264 preset; give one of {', '.join(PRESETS)} (default {DEFAULT_PRESET})")


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


def check_fps(fps) -> float:
    """``fps`` as a float from MIN_FPS to MAX_FPS (:mod:`.outputs`), or a RenderError."""
    from liganimate.runtime.render.outputs import MAX_FPS, MIN_FPS

    try:
        f = float(fps)
    except (TypeError, ValueError, OverflowError):
        f = float("nan")
    # GIF delays are 16-bit hundredths of a second: a slower rate cannot be stored.
    if not (MIN_FPS <= f <= MAX_FPS):
        raise RenderError(f"Frames per second must be from {MIN_FPS:g} to {MAX_FPS:g}, not {fps!r}.")
    return f


class _Stream:
    """Frames handed to a thread that encodes them in order; errors come back to the caller.

    Subclasses define ``_open(first)`` (called here, with the first
    frame), ``_encode(frame)`` and ``_close()`` (called in the thread), and
    ``_finish()``, ``_stop()`` and ``_discard()`` (called here by
    :meth:`commit` and :meth:`abort`: ``_stop`` ends an encoder the thread
    may be waiting on, ``_discard`` removes the file once the thread is done).
    """

    def __init__(self, path, fps):
        self.path = os.fspath(path)
        self.fps = check_fps(fps)
        self.frames = 0
        self.shape = None
        self._queue: queue.Queue = queue.Queue(QUEUE_FRAMES)
        self._thread = None
        self._error: BaseException | None = None
        self._done = False

    def add(self, frame) -> None:
        """Append one frame, shape (H, W) or (H, W, 3), uint8, the shape of the first.

        Raises
        ------
        RenderError
            A frame of another shape, or the encoder failed (the message
            names the file); the stream is aborted then.
        """
        if self._done:
            raise ValueError("add to a finished stream")
        try:
            frame = check_image(frame)
            if self.shape is None:
                self.shape = frame.shape
                self._open(frame)
                self._thread = threading.Thread(target=self._run, name="liganimate-encoder", daemon=True)
                self._thread.start()
            elif frame.shape != self.shape:
                raise RenderError(
                    f"Frame {self.frames} is {frame.shape[1]}x{frame.shape[0]}, "
                    f"but frame 0 is {self.shape[1]}x{self.shape[0]}."
                )
            if self._error is not None:
                raise self._error
            self._queue.put(np.ascontiguousarray(frame))
            self.frames += 1
        except BaseException:
            self.abort()
            raise

    def commit(self) -> int:
        """Encode the frames still waiting, finish the file and rename it into place; return the frame count.

        Raises
        ------
        RenderError
            No frames, or the encoder failed; nothing is written then.
        """
        if self._done:
            raise ValueError("commit of a finished stream")
        try:
            if self.shape is None:
                raise RenderError("There are no frames to write.")
            self._queue.put(None)
            self._thread.join()
            if self._error is not None:
                raise self._error
            self._finish()
        except BaseException:
            self.abort()
            raise
        self._done = True
        return self.frames

    def abort(self) -> None:
        """Stop encoding and remove the unfinished file; safe to call at any time, more than once."""
        if self._done:
            return
        self._done = True
        self._error = self._error or RenderError("stopped")  # the thread drops what is left
        with contextlib.suppress(BaseException):
            self._stop()
        if self._thread is not None:
            with contextlib.suppress(queue.Full):
                self._queue.put(None, timeout=10.0)
            self._thread.join(10.0)
        with contextlib.suppress(BaseException):
            self._discard()

    def _run(self) -> None:
        while True:
            frame = self._queue.get()
            if frame is None:
                break
            if self._error is not None:
                continue  # drain, so that add() never waits on a dead encoder
            try:
                self._encode(frame)
            except BaseException as exc:  # noqa: BLE001 - handed to the caller's thread
                self._error = exc
        try:
            self._close()
        except BaseException as exc:  # noqa: BLE001
            self._error = self._error or exc

    def _open(self, first) -> None:
        raise NotImplementedError

    def _encode(self, frame) -> None:
        raise NotImplementedError

    def _close(self) -> None:
        raise NotImplementedError

    def _finish(self) -> None:
        raise NotImplementedError

    def _stop(self) -> None:
        pass

    def _discard(self) -> None:
        raise NotImplementedError


class Mp4Stream(_Stream):
    """An H.264 MP4 movie, encoded by ffmpeg as the frames are added.

    Raw frames are piped to ffmpeg (imageio-ffmpeg's bundled binary, else
    ``ffmpeg`` on PATH) and encoded with libx264, yuv420p, the given CRF and
    preset, a fixed number of x264 threads, ffmpeg's bit-exact flags and no
    metadata: the same frames give the same bytes with the same ffmpeg.
    Odd image sizes are padded by one white pixel on the right/bottom
    (yuv420p needs even sizes).  ffmpeg runs in a process group of its own,
    so a Ctrl-C at the terminal reaches this process only, which then
    aborts the stream.

    Parameters
    ----------
    path : str or os.PathLike
        Destination; replaced on :meth:`commit`.
    fps : float
        Frames per second.
    crf : int, optional
        x264's constant rate factor, 0 to 51 (lower: better and larger).
    preset : str, optional
        One of :data:`PRESETS` (faster: more CPU time saved, larger files).

    Raises
    ------
    RenderError
        No ffmpeg, a bad option, or the temporary file cannot be created.
    """

    def __init__(self, path, fps, crf=DEFAULT_CRF, preset=DEFAULT_PRESET):
        super().__init__(path, fps)
        self.crf = check_crf(crf, "crf=")
        self.preset = check_preset(preset, "preset=")
        self.exe = find_ffmpeg()
        self._proc = None
        self._err = None
        self._fd = -1
        self._tmp = temporary_beside(self.path)

    def _open(self, first) -> None:
        H, W = first.shape[:2]
        # An exact rational rate, so e.g. 29.97 is not rounded by ffmpeg's parser.
        frac = Fraction(self.fps).limit_denominator(1_000_000)
        cmd = [
            self.exe, "-hide_banner", "-nostdin", "-loglevel", "error", "-y",
            "-f", "rawvideo", "-pix_fmt", "rgb24" if first.ndim == 3 else "gray", "-s", f"{W}x{H}",
            "-framerate", f"{frac.numerator}/{frac.denominator}", "-i", "pipe:0",
            "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white",
            "-c:v", "libx264", "-preset", self.preset, "-crf", str(self.crf), "-threads", str(X264_THREADS),
            "-pix_fmt", "yuv420p",
            "-map_metadata", "-1", "-fflags", "+bitexact", "-flags:v", "+bitexact", "-flags:a", "+bitexact",
            "-movflags", "+faststart", "-f", "mp4", self._tmp,
        ]  # fmt: skip
        # stderr goes to a file: a pipe nobody reads could fill and deadlock us.
        self._err = tempfile.TemporaryFile()
        try:
            self._proc = subprocess.Popen(
                cmd,
                stdin=subprocess.PIPE,
                stdout=subprocess.DEVNULL,
                stderr=self._err,
                bufsize=0,
                process_group=0,
            )
        except OSError as exc:
            raise RenderError(f"cannot start ffmpeg ({self.exe}) to write {self.path}: {exc.strerror or exc}") from None
        self._fd = self._proc.stdin.fileno()
        _PIPES.add(self._fd)

    def _encode(self, frame) -> None:
        view = memoryview(frame).cast("B")
        try:
            while view:
                n = os.write(self._fd, view)
                view = view[n:]
        except BrokenPipeError:
            raise self._failure() from None

    def _close(self) -> None:
        _PIPES.discard(self._fd)
        with contextlib.suppress(OSError):
            self._proc.stdin.close()
        if self._proc.wait() != 0:
            raise self._failure()

    def _failure(self) -> RenderError:
        """Why ffmpeg stopped: its exit status and last line of messages."""
        rc = self._proc.wait()
        self._err.seek(0)
        msg = self._err.read().decode("utf-8", "replace").strip().splitlines()
        return RenderError(
            f"ffmpeg could not write the MP4 file {self.path} (exit status {rc}).",
            hint=msg[-1] if msg else None,
        )

    def _finish(self) -> None:
        try:
            publish(self._tmp, self.path)
        except OSError as exc:
            raise write_error(exc, self.path) from None
        self._tmp = None
        self._err.close()

    def _stop(self) -> None:
        if self._proc is not None and self._proc.poll() is None:
            self._proc.kill()

    def _discard(self) -> None:
        try:
            if self._proc is not None:
                self._proc.wait()
        finally:
            _PIPES.discard(self._fd)
            if self._err is not None:
                self._err.close()
            if self._tmp is not None:
                with contextlib.suppress(OSError):
                    os.unlink(self._tmp)
                self._tmp = None


# Write ends of the pipes to running ffmpeg processes.  A worker process
# forked meanwhile inherits them; were it to keep them open, ffmpeg would
# never see the end of its input.  Forked children point them at /dev/null.
_PIPES: set = set()


def _after_fork_in_child() -> None:
    if not _PIPES:
        return
    null = os.open(os.devnull, os.O_WRONLY)
    for fd in list(_PIPES):
        with contextlib.suppress(OSError):
            os.dup2(null, fd)
    os.close(null)
    _PIPES.clear()


os.register_at_fork(after_in_child=_after_fork_in_child)


class GifStream(_Stream):
    """A looping animated GIF, encoded (Pillow's per-frame encoder) as the frames are added.

    Grey frames share a 256-grey global palette, so they are stored
    exactly.  Colour frames each get a palette of their own (median cut to
    at most 256 colours, no dithering: exact when a frame has no more
    colours, as flat-shaded frames rarely do).

    GIF delays are whole hundredths of a second; frame ``i`` is shown for
    ``round(100 (i+1) / fps) - round(100 i / fps)`` hundredths so the total
    duration stays exact (e.g. 30 fps gives 3, 4, 3, 3, 4, 3, ...).  Most
    viewers show delays under 2 hundredths as 10, so above 50 fps a GIF
    plays slower than intended.

    Parameters
    ----------
    path : str or os.PathLike
        Destination; replaced on :meth:`commit`.
    fps : float
        Frames per second.
    """

    def __init__(self, path, fps):
        super().__init__(path, fps)
        self._file = AtomicWriter(self.path)
        self._encoded = 0

    def _open(self, first) -> None:
        from PIL import GifImagePlugin, Image

        canvas = Image.new("L", (first.shape[1], first.shape[0]))
        header, _ = GifImagePlugin.getheader(canvas, None, {"loop": 0, "duration": 1, "optimize": False})
        for part in header:
            self._file.write(part)

    def _encode(self, frame) -> None:
        from PIL import GifImagePlugin, Image

        n = self._encoded
        delay = round(100 * (n + 1) / self.fps) - round(100 * n / self.fps)
        H, W = frame.shape[:2]
        if frame.ndim == 2:
            im = Image.frombuffer("L", (W, H), frame, "raw", "L", 0, 1)
            extra = {}
        else:
            rgb = Image.frombuffer("RGB", (W, H), frame, "raw", "RGB", 0, 1)
            im = rgb.quantize(256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
            extra = {"include_color_table": True}
        for part in GifImagePlugin.getdata(im, (0, 0), duration=10 * delay, **extra):
            self._file.write(part)
        self._encoded += 1

    def _close(self) -> None:
        pass

    def _finish(self) -> None:
        self._file.write(b";")
        self._file.commit()

    def _discard(self) -> None:
        self._file.abort()


def _write(stream: _Stream, frames_iter: Iterable) -> int:
    try:
        for frame in frames_iter:
            stream.add(frame)
    except BaseException:
        stream.abort()
        raise
    return stream.commit()


def write_mp4(path, frames_iter: Iterable, fps: float, crf=DEFAULT_CRF, preset=DEFAULT_PRESET) -> int:
    """Write frames as an H.264 MP4 movie, atomically (see :class:`Mp4Stream`).

    Parameters
    ----------
    path : str or os.PathLike
        Destination; replaced if it exists.
    frames_iter : iterable of ndarray, each shape (H, W) or (H, W, 3), uint8
        The frames, all the same shape.  They are streamed, not held.
    fps : float
        Frames per second; positive.
    crf, preset : optional
        x264's quality and speed (see :class:`Mp4Stream`).

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    RenderError
        If no ffmpeg can be found, ffmpeg fails, there are no frames, frames
        differ in shape, or an option is out of range.
    """
    return _write(Mp4Stream(path, fps, crf, preset), frames_iter)


def write_gif(path, frames_iter: Iterable, fps: float) -> int:
    """Write frames as a looping animated GIF, atomically (see :class:`GifStream`).

    Parameters
    ----------
    path : str or os.PathLike
        Destination; replaced if it exists.
    frames_iter : iterable of ndarray, each shape (H, W) or (H, W, 3), uint8
        The frames, all the same shape.  They are streamed, not held.
    fps : float
        Frames per second; positive.

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    RenderError
        If there are no frames, frames differ in shape, or fps is out of range.
    """
    return _write(GifStream(path, fps), frames_iter)


__all__ = [
    "DEFAULT_CRF",
    "DEFAULT_PRESET",
    "PRESETS",
    "GifStream",
    "Mp4Stream",
    "check_crf",
    "check_preset",
    "find_ffmpeg",
    "write_gif",
    "write_mp4",
]
