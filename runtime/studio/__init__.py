"""The studio: the posing thesis' Generator (chapter IV) on any model, in the browser.

This sub-package owns ``liganimate studio``:

* the hyper tessellated sphere and circle (:mod:`._spheres`);
* genes: each joint's flexion, pivot and twist axes and the alternatives
  a gene may take, coarsest first (:mod:`._genes`);
* the Generator: nine candidates, the user's limb-by-limb crossover,
  mutation with an intensity, separate flexion & pivot and twist
  mutation, a seed, frozen limbs, undo, kept poses (:mod:`._generator`);
* Save: the posed model and the kept poses as a LIG library
  (:mod:`._library`), written atomically;
* the session the page talks to (:mod:`._session`), the loopback web
  server (:mod:`._server`, a handler from the standard library's
  ``http.server``), the connection loop under it with its bounded pool
  and queue (:mod:`._loop`), their limits (:mod:`._limits`) and
  its page (:mod:`._page`, with ``studio.html``, ``studio.css`` and
  ``studio.js`` as package data and the viewer's ``gl.js``);
* finding the model to pose (:mod:`._model`).

The posing logic is pure Python and numpy, tested without a browser; the
page only shows poses and sends choices.  It may import the runtime
(figure, kinematics, pose, errors), ``liganimate.runtime.view`` (the page
helpers and ``gl.js``), ``liganimate.runtime.exchange`` (atomic writes),
the compiler (to load a program file) and ``liganimate.lang`` (to check the
library it saves); never ``liganimate.cli``, the layer above it.
Nothing imports it but ``liganimate.view_cli``.  See ``docs/viewer.md``.
"""

from ._generator import POPULATION, Generator
from ._genes import JointAxes, alternatives, joint_axes
from ._library import library_text, lig_name, widened_extremes
from ._limits import StudioLimits
from ._model import studio_model
from ._page import studio_page
from ._server import MAX_BODY, StudioServer, serve, start_in_thread
from ._session import ACTIONS, RequestError, Session, write_library
from ._spheres import LEVELS, circle, sphere

__all__ = [
    "ACTIONS",
    "LEVELS",
    "MAX_BODY",
    "POPULATION",
    "Generator",
    "JointAxes",
    "RequestError",
    "Session",
    "StudioLimits",
    "StudioServer",
    "alternatives",
    "circle",
    "joint_axes",
    "library_text",
    "lig_name",
    "serve",
    "sphere",
    "start_in_thread",
    "studio_model",
    "studio_page",
    "widened_extremes",
    "write_library",
]
