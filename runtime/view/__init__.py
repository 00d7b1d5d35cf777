"""The browser viewer: a program's scenes as one self-contained HTML page.

This sub-package owns ``liganimate view`` and the notebook display's page:

* turning shot scenes (from :func:`liganimate.runtime.exchange.collect`)
  into compact arrays: segment matrices per tick, triangles per segment,
  cameras (:mod:`._scene_data`);
* the page itself, its JavaScript and CSS kept as package data files
  (``shadow.js``, ``gl.js``, ``viewer.js``, ``viewer.css``, ``viewer.html``)
  and inlined when a page is built (:mod:`._html`);
* ``shadow.js`` and ``gl.js`` are also the studio's drawing code
  (``liganimate.runtime.studio`` inlines them through :func:`gl_script`).

It is one of the tools, a layer above the runtime core (docs/architecture.md):
it may import the runtime (pose, values), ``liganimate.runtime.exchange``
(the collector's results), numpy and the standard library.  Of the rest of
liganimate only the studio imports it (for its drawing code); the runtime core, the
compiler and the language never do.  The command line reaches it through
``liganimate.view_cli`` and Python through ``liganimate.api``.  See
``docs/viewer.md``.
"""

from ._html import asset, fill, gl_script, iframe, inline_code, json_for_script, viewer_html
from ._scene_data import Blob, scene_manifest

__all__ = [
    "Blob",
    "asset",
    "fill",
    "gl_script",
    "iframe",
    "inline_code",
    "json_for_script",
    "scene_manifest",
    "viewer_html",
]
