"""Pictures: the camera, the rasterizer, frames of scenes and the files they go to.

Owns :mod:`.camera`, :mod:`.raster` (the z-buffer rasterizer), :mod:`.frames`
(batched poses to images, written by worker processes), :mod:`.imagefiles`
(PNG, GIF and MP4 writers), :mod:`.outputs` (output options and locks) and
:mod:`.plot` (a motion's angle curves).

May import: :mod:`liganimate.lang.diagnostics`, :mod:`liganimate.runtime.errors`,
:mod:`liganimate.runtime.values`, :mod:`liganimate.runtime.limits`,
:mod:`liganimate.runtime.figure`, :mod:`liganimate.runtime.motion` and its own
modules. Never the host or the command line.
"""
