"""What a render writes and how: one frozen :class:`RenderOptions` from the caller to the renderer.

The command line (``liganimate run``), ``Program.render`` and
``LoadedProgram.render`` all build one ``RenderOptions``; :func:`checked`
refuses what cannot be honoured before anything is computed, and the
renderer, the output checks (:mod:`.outputs`) and the output lock all read
that one value.

The movie files a render may write beside (or instead of) the PNG frames
are a table, :data:`MOVIES` (kept in :mod:`.movies`, which the command
line reads without importing the renderer): each names its ``RenderOptions`` field, its
``--help`` line, what must be present before anything is written (ffmpeg),
and how to open its stream (:mod:`.video`).  Adding a movie format (WebM)
is a field here, an entry in :data:`MOVIES` (in :mod:`.movies`), and its stream class; the
command line, the checks, the lock and the renderer take it from the table
(docs/architecture.md, "A new output format").
"""

from __future__ import annotations

import dataclasses
import numbers
import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from liganimate.runtime.errors import RenderError
from liganimate.runtime.render.look import DEFAULT_LOOK, check_look
from liganimate.runtime.render.raster import MAX_AA
from liganimate.runtime.render.video import DEFAULT_CRF, DEFAULT_PRESET, check_crf, check_preset

from .movies import MOVIES, Movie
from .outputs import check_fps, check_outputs

__all__ = [
    "CLI_NAMES",
    "KEYWORD_NAMES",
    "MOVIES",
    "Movie",
    "RenderOptions",
    "check_aa",
    "checked",
    "executor_for",
]

# The largest image side: bounds the memory of one framebuffer up front.
MAX_SIDE = 16384

#: Bytes one sample (a pixel, or one of its aa x aa parts) costs while an image
#: is drawn: its colour (3), its depth key (8) and the looks' per-sample
#: temporaries (depths, outlines, shadow), rounded up.
BYTES_PER_SAMPLE = 24
#: The environment variable that sets the memory budget of one image, in MiB.
MEMORY_ENV = "LIGANIMATE_IMAGE_MEMORY_MB"
#: The default budget of one image being drawn: 8 GiB (16384 x 16384 pixels without anti-aliasing fit).
DEFAULT_IMAGE_MEMORY_MB = 8192


def image_memory_budget() -> int:
    """The memory one image may take while drawn, in bytes: ``$LIGANIMATE_IMAGE_MEMORY_MB`` or 8 GiB.

    Raises
    ------
    RenderError
        When the variable is set but is not a whole number of MiB from 1.
    """
    text = os.environ.get(MEMORY_ENV)
    if text is None or not text.strip():
        return DEFAULT_IMAGE_MEMORY_MB << 20
    if not text.strip().isdigit() or int(text) < 1:
        raise RenderError(f"{MEMORY_ENV}={text!r} is not a number of MiB; give a whole number such as 16384")
    return int(text) << 20


def check_image_memory(size: tuple[int, int], aa: int, names: Mapping[str, str]) -> None:
    """Refuse, before anything is drawn, an image whose ``W x H x aa^2`` samples exceed the memory budget.

    Parameters
    ----------
    size : (int, int)
        Checked width and height.
    aa : int
        Checked anti-aliasing factor.
    names : mapping
        How the caller spells the options (:data:`CLI_NAMES` or :data:`KEYWORD_NAMES`).

    Raises
    ------
    RenderError
        One sentence naming the estimate, the limit and how to raise it.
    """
    need = size[0] * size[1] * aa * aa * BYTES_PER_SAMPLE
    budget = image_memory_budget()
    if need > budget:
        mib = -(-need // (1 << 20))
        raise RenderError(
            f"{size[0]}x{size[1]} pixels with {names['aa'].rstrip('=')} {aa} ({aa * aa} samples a pixel) "
            f"would take about {mib} MiB to draw, over the budget of {budget >> 20} MiB for one image; "
            f"lower the size or the anti-aliasing, or raise the budget with {MEMORY_ENV}={mib}"
        )


@dataclass(frozen=True)
class RenderOptions:
    """Everything a render writes and how: the one value the renderer, the checks and the lock read.

    Attributes
    ----------
    out : str or None
        Frames go to ``out/scene<ID>/<NNNNN>.png``; None writes no frames
        (then a movie must be asked for).
    size : (int, int)
        Image width and height in pixels, 1 to 16384 each.
    gif, mp4 : str or None
        Movie files (:data:`MOVIES`): an animated GIF, an MP4 (needs ffmpeg).
    poses : str or None
        The pose record, JSON Lines (docs/poses.md).
    fps : float
        Frame rate of the movies, 0.01 to 1000.
    aa : int
        Anti-aliasing factor, 1 (none) to 8: each pixel is the mean of ``aa x aa`` samples.
    look : str
        ``"modern"`` (the default: lit faces, outlines, a contact shadow,
        smoothed edges) or ``"thesis"`` (flat shades on white, the thesis'
        own look, byte for byte); see :mod:`.look`.
    crf, preset : int, str
        x264's quality (0 to 51, lower is better and larger) and speed
        (``ultrafast`` to ``veryslow``) for the MP4.
    workers : int or None
        Processes rasterizing in parallel (default: the machine's cores, at
        most 8, less one for a movie's encoder in the thesis look; see
        :meth:`drawing_workers`);
        1 draws everything in this process.
    scheduler : str or None
        The address of a Dask scheduler to draw the frames on (``tcp://host:8786``).
    quiet : bool
        No progress bar.
    progress : bool
        Show the check's and the render's progress on stderr even when it is
        not a terminal (a line a second), e.g. into a log.
    """

    out: str | None = None
    size: tuple[int, int] = (640, 480)
    gif: str | None = None
    mp4: str | None = None
    poses: str | None = None
    fps: float = 24.0
    aa: int = 1
    look: str = DEFAULT_LOOK
    crf: int = DEFAULT_CRF
    preset: str = DEFAULT_PRESET
    workers: int | None = None
    scheduler: str | None = None
    quiet: bool = False
    progress: bool = False

    def movies(self) -> list[tuple[Movie, str]]:
        """The movies asked for, with their paths, in the order of :data:`MOVIES`."""
        return [(m, path) for m in MOVIES if (path := getattr(self, m.name)) is not None]

    def drawing_workers(self) -> int:
        """The processes that draw: ``workers`` if given, else one a core (at most 8), less one for a movie's encoder.

        A movie's encoder (x264 in its own process, or the GIF writer's
        thread) keeps a core busy beside the drawing. Where a frame draws in
        less time than it is encoded (the thesis look: about 1.1 against 1.9
        ms at 640x480), the encoder sets the pace, and a core of its own
        beats a second drawing process that must send its images back: on
        two cores the five-humanoid film to MP4 took 3.5 ms of CPU and 1.9 ms
        of wall time a frame drawn in this process, against 4.3 and 2.5 ms
        with two drawing workers. The modern look draws a frame in about 6
        ms, so every core draws (4.5 ms of wall time a frame with two
        workers against 6.0 with one); see docs/semantics-render.md.
        """
        if self.workers is not None:
            return self.workers
        getaffinity = getattr(os, "sched_getaffinity", None)  # the cores this process may use (Linux)
        cores = len(getaffinity(0)) if getaffinity is not None else (os.cpu_count() or 1)
        encoder = 1 if self.movies() and self.look in _ENCODER_BOUND_LOOKS else 0
        return max(1, min(cores, 8) - encoder)

    def files(self) -> tuple[str, ...]:
        """Every output file asked for (movies, then the pose record): what the checks and the lock guard."""
        return tuple(path for _, path in self.movies()) + ((self.poses,) if self.poses is not None else ())


#: The looks whose frames draw faster than x264 encodes them (see :meth:`RenderOptions.drawing_workers`).
_ENCODER_BOUND_LOOKS = frozenset({"thesis"})

_FIELDS = tuple(f.name for f in dataclasses.fields(RenderOptions))
#: How the command line spells each option in messages.
CLI_NAMES: Mapping[str, str] = {name: "-o" if name == "out" else "--" + name for name in _FIELDS}
#: How the Python API spells them.
KEYWORD_NAMES: Mapping[str, str] = {name: name + "=" for name in _FIELDS}


def check_aa(aa: object, name: str = "--aa") -> int:
    """``aa`` as an int from 1 to the rasterizer's ``MAX_AA``, or a RenderError naming the option.

    Unlike the rasterizer's own check, this takes the option's text ("2")
    as the command line and ``Program.render`` options give it.
    """
    try:
        n = int(aa)  # type: ignore[call-overload]
        ok = n == float(aa) and 1 <= n <= MAX_AA  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok or isinstance(aa, bool):
        raise RenderError(
            f"{_shown(name, aa)} is not an anti-aliasing factor; give a whole number from 1 (none) to {MAX_AA}"
        )
    return n


def _shown(name: str, value: object) -> str:
    """An option and its value as the caller wrote them: ``size=(0, 1)`` or ``--size 0x1``."""
    return f"{name}{value!r}" if name.endswith("=") else f"{name} {value}"


def _side(v: Any) -> bool:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        return False
    x = float(v)
    return 0 < x <= MAX_SIDE and x.is_integer()


def _size(size: object, name: str) -> tuple[int, int]:
    try:
        values = list(size)  # type: ignore[call-overload]
    except TypeError:
        values = []
    ok = len(values) == 2 and all(_side(v) for v in values)
    if not ok:
        raise RenderError(
            f"{_shown(name, size)} is not an image size; give (width, height), 1 to {MAX_SIDE} pixels each"
        )
    return int(values[0]), int(values[1])


def _workers(workers: object, name: str) -> int | None:
    if workers is None:
        return None
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise RenderError(f"{_shown(name, workers)} is not a number of processes; give a whole number from 1")
    return workers


def checked(options: RenderOptions, names: Mapping[str, str] = KEYWORD_NAMES, make_poses_folder: bool = False):
    """``options`` with every value checked and in its type; nothing is written.

    Parameters
    ----------
    options : RenderOptions
        As the caller gave them (numbers may still be text, as the command line reads them).
    names : mapping, optional
        How to name each option in messages: :data:`KEYWORD_NAMES` (default) or :data:`CLI_NAMES`.
    make_poses_folder : bool, optional
        The pose record's folder may be missing, because the renderer creates it.

    Returns
    -------
    RenderOptions

    Raises
    ------
    RenderError
        One line naming the option: a bad number, an output that cannot be
        written (:func:`.outputs.check_outputs`), MP4 without ffmpeg.
    """
    paths = {
        k: os.fspath(v) for k in ("out", "poses", *(m.name for m in MOVIES)) if (v := getattr(options, k)) is not None
    }
    result = dataclasses.replace(
        options,
        **paths,
        size=_size(options.size, names["size"]),
        fps=check_fps(options.fps, names["fps"]),
        aa=check_aa(options.aa, names["aa"]),
        look=check_look(options.look, names["look"]),
        crf=check_crf(options.crf, names["crf"]),
        preset=check_preset(options.preset, names["preset"]),
        workers=_workers(options.workers, names["workers"]),
    )
    check_image_memory(result.size, result.aa, names)
    if result.scheduler is not None and not result.scheduler.strip():
        raise RenderError(
            f"{names['scheduler'].rstrip('=')} is empty; give the address of a Dask scheduler, like tcp://host:8786"
        )
    if result.out is None and not result.movies():
        movies = " or ".join(names[m.name] for m in MOVIES)
        raise RenderError(f"there is no frames folder ({names['out']}) and no {movies}: nothing would be written")
    check_outputs(result, names, make_poses_folder=make_poses_folder)
    for movie, _ in result.movies():
        if movie.require is not None:
            movie.require()
    return result


def executor_for(scheduler: str):
    """A DaskExecutor on ``scheduler``; Dask is imported here only, never for a local run.

    Raises
    ------
    RenderError
        When Dask is not installed, or the scheduler cannot be reached.
    """
    try:
        from liganimate.runtime.render.distributed import DaskExecutor
    except ImportError as exc:
        if exc.name is not None and exc.name.split(".")[0] not in ("dask", "distributed", "liganimate"):
            raise  # a bug in a module that is installed: the internal-error report names it
        raise RenderError("Dask is not installed: pip install 'liganimate[dask]'") from None
    return DaskExecutor(scheduler)
