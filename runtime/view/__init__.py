"""The browser viewer: a program's scenes as one self-contained HTML page.

This sub-package owns ``liganimate view`` and the notebook display's page:

* turning shot scenes (from :func:`liganimate.runtime.exchange.collect`)
  into compact arrays: segment matrices per tick, triangles per segment,
  cameras (:mod:`._scene_data`);
* the page itself, its JavaScript and CSS kept as package data files
  (``gl.js``, ``viewer.js``, ``viewer.css``, ``viewer.html``) and inlined
  when a page is built (:mod:`._html`);
* ``gl.js`` is also the studio's drawing code (``liganimate.runtime.studio``
  inlines it through :func:`asset`).

It is one of the tools, a layer above the runtime core (docs/architecture.md):
it may import the runtime (pose, values), ``liganimate.runtime.exchange``
(the collector's results), numpy and the standard library.  Of the rest of
liganimate only the studio imports it (for ``gl.js``); the runtime core, the
compiler and the language never do.  The command line reaches it through
``liganimate.view_cli`` and Python through ``liganimate.api``.  See
``docs/viewer.md``.
"""

from ._html import asset, fill, iframe, inline_code, json_for_script, viewer_html
from ._scene_data import Blob, scene_manifest

__all__ = ["Blob", "asset", "fill", "iframe", "inline_code", "json_for_script", "scene_manifest", "viewer_html"]
