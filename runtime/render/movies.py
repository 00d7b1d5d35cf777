"""The movie formats a render can write: the one table the command line, the checks and the renderer read.

It lives apart from :mod:`.options` so that building the command line's
argument parser (every ``liganimate`` command does, ``check`` included)
reads the formats' names and help lines without importing the renderer,
the video writers and numpy's drawing code: the writers are imported only
when a movie is opened or its requirement checked.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .options import RenderOptions

__all__ = ["MOVIES", "Movie"]


@dataclass(frozen=True)
class Movie:
    """A movie file a render can write, fed the drawn images in order.

    Attributes
    ----------
    name : str
        Its :class:`RenderOptions` field and keyword; the command line's flag is ``--<name>``.
    label : str
        What the command line calls it when done (``MP4 written to film.mp4``).
    help : str
        The ``--help`` line.
    open : callable
        ``open(path, options) -> stream``: the stream the frames go to (:mod:`.video`).
    require : callable, optional
        Called by :func:`.options.checked`, before anything is written: raises a
        :class:`RenderError` when the movie cannot be made here (no ffmpeg).
    """

    name: str
    label: str
    help: str
    open: Callable[[str, RenderOptions], Any] = field(repr=False)
    require: Callable[[], object] | None = field(default=None, repr=False)


def _open_gif(path: str, options: RenderOptions) -> Any:
    from .video import GifStream

    return GifStream(path, options.fps)


def _open_mp4(path: str, options: RenderOptions) -> Any:
    from .video import Mp4Stream

    return Mp4Stream(path, options.fps, options.crf, options.preset)


def _need_ffmpeg() -> object:
    from .video import find_ffmpeg

    return find_ffmpeg()


#: The movie formats, in the order their options are listed.
MOVIES: tuple[Movie, ...] = (
    Movie("gif", "GIF", "write an animated GIF", _open_gif),
    Movie("mp4", "MP4", "write an MP4 (needs ffmpeg: pip install imageio-ffmpeg)", _open_mp4, _need_ffmpeg),
)
