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

It may import the runtime (pose, values), ``liganimate.runtime.exchange``
(only through the collector's results), numpy and the standard library.
Nothing in the runtime, the compiler or the language imports it; the
command line reaches it through ``liganimate.view_cli`` and Python through
``liganimate.api``.  See ``docs/viewer.md``.
"""

from ._html import asset, fill, iframe, inline_code, json_for_script, viewer_html
from ._scene_data import Blob, scene_manifest

__all__ = ["Blob", "asset", "fill", "iframe", "inline_code", "json_for_script", "scene_manifest", "viewer_html"]
