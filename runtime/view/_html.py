"""The viewer's page: one self-contained HTML file, its script and style inlined.

The JavaScript and CSS are package data files (``shadow.js``, ``gl.js``, ``viewer.js``,
``viewer.css``, the ``viewer.html`` template) read when a page is built.
Nothing in the page refers to anything outside it: a Content-Security-Policy
of ``default-src 'none'`` forbids every request, so a page opened from a
file makes none.  Program-derived text (model, segment and file names)
reaches the page only JSON-encoded with ``<``, ``>`` and ``&`` escaped, or
HTML-escaped, and the script shows it with ``textContent``, never as HTML.
"""

from __future__ import annotations

import base64
import html
import json
import re
from importlib import resources

from liganimate import __version__

from ._scene_data import Blob, scene_manifest

__all__ = ["asset", "fill", "gl_script", "iframe", "json_for_script", "viewer_html"]

_SLOT = re.compile(r"\{\{([A-Z]+)\}\}")
_CLOSERS = re.compile(r"</(script|style)", re.IGNORECASE)


def asset(name: str) -> str:
    """The text of one of the viewer's package data files (``gl.js``, ``viewer.css``...)."""
    return resources.files(__package__).joinpath(name).read_text(encoding="utf-8")


def fill(template: str, values: dict) -> str:
    """Replace each ``{{NAME}}`` of ``template`` with ``values[NAME]``, in one pass.

    Inserted text is never scanned again, so a value holding ``{{...}}`` stays as it is.

    Raises
    ------
    KeyError
        For a slot with no value.
    """
    return _SLOT.sub(lambda m: values[m.group(1)], template)


def inline_code(text: str) -> str:
    """Script or style text made safe to sit inside its element (no closing tag in it)."""
    if _CLOSERS.search(text):
        raise ValueError("inlined code must not hold a </script or </style")
    return text


def gl_script() -> str:
    """The drawing code the viewer and the studio share: ``shadow.js`` (the contact shadow) and ``gl.js``."""
    return inline_code(asset("shadow.js") + "\n" + asset("gl.js"))


def json_for_script(value) -> str:
    """JSON text that can sit inside a ``<script>`` element whatever strings it holds."""
    text = json.dumps(value, ensure_ascii=True, separators=(",", ":"), allow_nan=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def viewer_html(scenes, title: str) -> str:
    """The viewer page for a program's shot scenes.

    Parameters
    ----------
    scenes : list of SceneTake
        From :func:`liganimate.runtime.exchange.collect`.
    title : str
        Shown as the page title (escaped here).

    Returns
    -------
    str
        A complete HTML document with no external references.
    """
    blob = Blob()
    manifest = {"version": 1, "title": title, "scenes": scene_manifest(scenes, blob)}
    return fill(
        asset("viewer.html"),
        {
            "VERSION": html.escape(__version__),
            "TITLE": html.escape(title),
            "CSS": inline_code(asset("viewer.css")),
            "MANIFEST": json_for_script(manifest),
            "BLOB": base64.b64encode(blob.tobytes()).decode("ascii"),
            "GLJS": gl_script(),
            "VIEWERJS": inline_code(asset("viewer.js")),
        },
    )


def iframe(page: str, height: int = 560) -> str:
    """A page wrapped for notebook output: an ``<iframe srcdoc>`` that runs its scripts sandboxed.

    The frame keeps the viewer's script and style away from the notebook's
    own, and several viewers on one notebook page apart from each other.
    """
    return (
        f'<iframe srcdoc="{html.escape(page, quote=True)}" sandbox="allow-scripts" '
        f'style="width:100%;height:{int(height)}px;border:1px solid #ccc" '
        'title="liganimate viewer"></iframe>'
    )
