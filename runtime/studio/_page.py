"""The studio page: built once when the server starts, the model's triangles inlined.

The page is ``studio.html`` with ``studio.css``, the viewer's drawing code
(``shadow.js`` and ``gl.js``) and ``studio.js`` inlined, and the model's segments (triangles in segment
coordinates, grey levels, names, joints) in the same compact form the
viewer uses.  The poses themselves come from the server as segment
matrices.
"""

from __future__ import annotations

import base64
import html
from importlib import resources

import numpy as np

from liganimate import __version__
from liganimate.runtime.figure.pose import mesh_table
from liganimate.runtime.values import rgb_levels
from liganimate.runtime.view import Blob, fill, gl_script, inline_code, json_for_script

from ._generator import POPULATION

__all__ = ["studio_page"]

# The studio's camera looks from the front right and a little above
# (the library HUMANOID faces +X with its right side towards +Z).
_EYE_DIRECTION = np.array([0.8, 0.35, 0.6])


def _own(name: str) -> str:
    return resources.files(__package__).joinpath(name).read_text(encoding="utf-8")


def studio_page(generator, title: str) -> str:
    """The studio's HTML page for a :class:`~._generator.Generator`'s figure.

    Returns
    -------
    str
        A complete HTML document; it fetches the poses from the server.
    """
    fig = generator.figure
    table = mesh_table(fig)
    blob = Blob()
    X = generator.transforms(generator.neutral[None])[0]
    pts = table.triangles.reshape(-1, 3)
    links = np.repeat(table.link, 3)
    world = np.einsum("nij,nj->ni", X[links, :3, :3], pts) + X[links, :3, 3] if len(pts) else np.zeros((1, 3))
    lo, hi = world.min(axis=0), world.max(axis=0)
    centre = (lo + hi) / 2
    radius = float(np.linalg.norm(hi - lo) / 2) or 1.0
    eye = centre + _EYE_DIRECTION / np.linalg.norm(_EYE_DIRECTION) * 3.2 * radius
    joints = []
    for ax in generator.axes:
        joints.append(
            {
                "id": ax.id,
                "ext": np.stack([ax.lo, ax.hi], axis=-1).round(9).tolist(),
                "twist": "XYZ"[ax.twist],
                "pivot": "XYZ"[ax.pivot],
                "flexion": "XYZ"[ax.flexion],
            }
        )
    manifest = {
        "model": title,
        "population": POPULATION,
        "links": [link.label for link in fig.links],
        "jointOfLink": [-1 if j is None else j for j in (generator.joint_of_link(i) for i in range(fig.n_links))],
        "joints": joints,
        "mesh": {
            "pos": blob.add(table.triangles.reshape(-1), np.float32),
            "link": blob.add(table.link, np.uint16 if fig.n_links < 65536 else np.uint32),
            "rgb": blob.add(rgb_levels(table.shade), np.uint8),
        },
        # Candidates reach further than the standing figure: room for them.
        "bounds": [float(c) for c in centre] + [radius * 2.0],
        # A view width of 3.4 radii: room for limbs swung out to their full length.
        "camera": {"eye": [float(c) for c in eye], "target": [float(c) for c in centre], "k": 3.4 / 3.2},
    }
    return fill(
        _own("studio.html"),
        {
            "VERSION": html.escape(__version__),
            "TITLE": html.escape(title),
            "CSS": inline_code(_own("studio.css")),
            "MANIFEST": json_for_script(manifest),
            "BLOB": base64.b64encode(blob.tobytes()).decode("ascii"),
            "GLJS": gl_script(),
            "STUDIOJS": inline_code(_own("studio.js")),
        },
    )
