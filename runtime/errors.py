"""Errors raised by the runtime libraries.

The runtime knows nothing of source positions: it raises :class:`LigError`
with a plain sentence, and the program layer (which knows which statement
was running) attaches the ``file:line:col`` before the user sees it.
"""

from __future__ import annotations


class LigError(ValueError):
    """A problem in the user's program found while running it.

    Parameters
    ----------
    message : str
        One plain sentence saying what is wrong.
    hint : str, optional
        A short suggestion of how to fix it.
    """

    def __init__(self, message: str, hint: str | None = None):
        super().__init__(message)
        self.message = message
        self.hint = hint


class MotionError(LigError):
    """A motion operation that cannot be carried out (overlapping SYNCHRONIZE, bad keyframes...)."""


class FigureError(LigError):
    """A model operation that cannot be carried out (duplicate joint ids, cycles, unknown links...)."""


class RenderError(LigError):
    """A rendering request that cannot be honoured (no ffmpeg for MP4, a bad image size...)."""
