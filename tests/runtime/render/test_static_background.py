"""The static-background table (issue 22): each BACKGROUND object is worked out once a render, and draws the same.

``Renderer._background`` remembers each background object's drawing (a
graphical object's triangles, shades and culling; a model's posed at its
placement) by identity.  The frames must be those of working every object
out afresh each image, and a model in the background is posed once.
"""

from __future__ import annotations

import pathlib

from paths import ROOT_DIR

from liganimate.compiler import load_program
from liganimate.runtime.figure.pose import static_triangles
from liganimate.runtime.render import frames as R
from liganimate.runtime.values import Graphical


def clock(tmp_path: pathlib.Path) -> pathlib.Path:
    """Thesis' clock, 20 ticks, with its DIAL and a second CLOCK (a model) in the background."""
    text = (pathlib.Path(ROOT_DIR) / "examples" / "clock.lig").read_text()
    text = text.replace(
        "        BACKGROUND DIAL\n", "        BACKGROUND DIAL\n        BACKGROUND CLOCK <TRANS (1.5, 0.0, 0.0)>\n"
    )
    text = text.replace("LENGTH 2881", "LENGTH 20").replace("FROM 0 TO 2880", "FROM 0 TO 19")
    path = tmp_path / "clock20.lig"
    path.write_text(text)
    return path


def afresh(self, state, camera):
    """The background worked out for every image, as before the table."""
    parts = []
    for item in state.background:
        if isinstance(item, Graphical):
            if len(item):
                parts.append((item.triangles, item.shades(), item.closed))
        else:
            parts.append(static_triangles(item))
    return (camera, parts)


def frames_of(folder: pathlib.Path) -> list[bytes]:
    return [p.read_bytes() for p in sorted((folder / "scene1").glob("*.png"))]


def test_background_objects_are_worked_out_once_and_draw_the_same(tmp_path, monkeypatch):
    program, _ = load_program(str(clock(tmp_path)))
    program.check()
    posed = []
    real = R.static_triangles
    monkeypatch.setattr(R, "static_triangles", lambda fig: posed.append(fig) or real(fig))
    program.render(str(tmp_path / "table"), checked=True, look="thesis", workers=1, quiet=True)
    assert len(posed) == 1  # the background CLOCK, once for 20 images
    monkeypatch.setattr(R.Renderer, "_background", afresh)
    program.render(str(tmp_path / "afresh"), checked=True, look="thesis", workers=1, quiet=True)
    table, fresh = frames_of(tmp_path / "table"), frames_of(tmp_path / "afresh")
    assert len(table) == 20 and table == fresh
