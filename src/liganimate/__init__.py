"""liganimate: a compiler and runtime for LIG ANIMATE (Cachola, 1986).

The Python API (``liganimate.api``, reference in docs/api.md)::

    import liganimate

    film = liganimate.load("scene.lig")      # or liganimate.loads(text)
    film.render("frames", mp4="film.mp4")     # the options of `liganimate run`
    film.export("film.glb", fps=30)           # the formats of `liganimate export`
    film.view()                               # the viewer (in Jupyter, displayed)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

if TYPE_CHECKING:
    from liganimate.api import (
        LigProgramError,
        LoadedProgram,
        ModelTake,
        RenderOptions,
        SceneTake,
        View,
        load,
        loads,
    )

__all__ = [
    "LigProgramError",
    "LoadedProgram",
    "ModelTake",
    "RenderOptions",
    "SceneTake",
    "View",
    "__version__",
    "load",
    "loads",
]


def __getattr__(name: str) -> Any:
    # The API is imported on first use, so that `import liganimate` (which
    # every command does) stays light.
    if name in __all__:
        from liganimate import api

        return getattr(api, name)
    raise AttributeError(f"module 'liganimate' has no attribute {name!r}")
