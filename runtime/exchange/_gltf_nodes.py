"""The ``nodes`` glTF rig: a model as a rigid tree of segment and joint nodes.

Under the model node (its host placement) hangs the node of its current main
link; then, walking the tree from the main link as the renderer does, for
each joint a *joint node* at the joint's location whose rotation is the
joint's (its inverse when FIGURE ... MAIN makes the walk go from secondary to
primary), and under it the node of the link it reaches.  Every segment
node's world transform is exactly the ``--poses`` matrix of that segment,
``placement @ pose @ diag(s, s, s, 1)``; each carries its own mesh.
"""

from __future__ import annotations

import numpy as np

from liganimate.runtime.values import Graphical

from ._gltf import joint_motion, moving_joints
from ._gltf_morph import link_morphs
from ._names import joint_names, link_names

__all__ = ["node_rig"]


def node_rig(b, take, model, anim, interp) -> list[int]:
    """Add one drawn model as a node tree to builder ``b``; its scene-root node, in a list."""
    fig = model.figure
    root = b.model_node(take, model, anim, interp)
    label = b.doc.nodes[root].name
    qj, shift = joint_motion(model)  # (T, J, 4), (T, J, 3)
    turning, sliding = moving_joints(qj), moving_joints(shift)
    names = link_names(fig)
    sourced = joint_names(fig)
    scales = fig.link_scales
    loc1, loc2 = fig.locations
    morphs = link_morphs(model)
    seg = {
        fig.main: _segment(b, take, model, f"{label} {names[fig.main]}", fig.main, root, morphs=(morphs, anim, interp))
    }
    for level in fig.traversal:
        for k, p, c, r in zip(level.joints, level.parents, level.children, level.reversed):
            near, far = (loc2[k], loc1[k]) if r else (loc1[k], loc2[k])
            sp = scales[p]
            jid = fig.joints[k].id
            place = (near + shift[:, k]) / sp  # (T, 3): a slide moves the joint node
            jn = b.node(
                name=f"{label} {sourced[k]}" if sourced[k] else f"{label} joint {jid}",
                translation=[float(v) for v in place[0]],
                rotation=[float(v) for v in qj[0, k]],
                extras={"liganimate": {"scene": take.id, "model": model.name, "joint": jid, "reversed": bool(r)}},
            )
            if sp != 1.0:
                b.doc.nodes[jn].scale = [1.0 / sp] * 3
            b.doc.nodes[seg[p]].children.append(jn)
            if turning[k]:
                b.channel(anim, jn, "rotation", model.ticks, qj[:, k], interp)
            if sliding[k]:
                b.channel(anim, jn, "translation", model.ticks, place, interp)
            seg[c] = _segment(b, take, model, f"{label} {names[c]}", c, jn, offset=-far, morphs=(morphs, anim, interp))
    return [root]


def _segment(b, take, model, name, i, parent, offset=None, morphs=({}, None, None)) -> int:
    """A segment's node (with its mesh; a morphed segment's mesh on a shape node under it)."""
    fig = model.figure
    link = fig.links[i]
    up = fig.parent_joint_of(i)
    g = link.shape
    mesh = None
    morph = morphs[0].get(i)
    if isinstance(g, Graphical) and len(g) and morph is None:
        mesh = b.mesh_by_colour(("link", id(g)), link.label, g.triangles, g.shades(), g.closed)
    n = b.node(
        name=name,
        mesh=mesh,
        extras={
            "liganimate": {
                "scene": take.id,
                "model": model.name,
                "link": link.name,
                "segment": int(i),
                "joint": None if up is None else up.id,
            }
        },
    )
    node = b.doc.nodes[n]
    if offset is not None and offset.any():
        node.translation = [float(v) for v in offset]
    if link.scale != 1.0:
        node.scale = [link.scale] * 3
    b.doc.nodes[parent].children.append(n)
    if morph is not None and isinstance(g, Graphical) and len(g):
        _shape_node(b, model, (name, n), g, morph, link.scale < 0, morphs[1:])
    return n


def _shape_node(b, model, where, g, morph, mirrored, animation) -> None:
    """A morphed segment's mesh on a node of its own: its SCALE track as a scale channel, its SHAPE track as morph targets."""
    name, segment = where
    anim, interp = animation
    # The morphs' targets follow the renderer's table, which rewinds a mirrored link's triangles.
    targets = [t[:, ::-1, :] if mirrored else t for t in morph.targets]
    deltas = np.array([t - g.triangles for t in targets]).reshape(-1, len(g), 3, 3)
    mesh = b.mesh_by_colour(None, f"{name} shape", g.triangles, g.shades(), g.closed, targets=deltas)
    n = b.node(name=f"{name} shape", mesh=mesh, extras={"liganimate": {"model": model.name, "morph": True}})
    b.doc.nodes[segment].children.append(n)
    node = b.doc.nodes[n]
    if morph.scale is not None:
        node.scale = [float(v) for v in morph.scale[0]]
        b.channel(anim, n, "scale", model.ticks, morph.scale, interp)
    if len(targets):
        node.weights = [float(v) for v in morph.weights[0]]
        b.channel(anim, n, "weights", model.ticks, morph.weights, interp)
