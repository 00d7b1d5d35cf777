"""The ``skin`` glTF rig: a model as a skeleton of joint nodes and one skinned mesh.

Under the model node (its host placement) hangs a skeleton with one joint
node, a *bone*, per link of the figure, walked from the current main link as
the renderer walks it:

* the bone of the main link sits at the model node's origin (a capture's
  importer-added empty ``ORIGIN`` main link has none: the capture's root
  bone hangs from the model node, as the capture had it);
* the bone of a link reached through a joint sits at the joint's pivot: its
  translation is the joint's location on the parent link less the parent
  bone's own pivot on that link (plus a SLIDE joint's displacement), and its
  rotation is the joint's rotation (its inverse when FIGURE ... MAIN walks
  the joint backwards).

So a bone's world transform is the ``--poses`` matrix of its segment,
without the segment's SCALE MODEL factor, moved to the joint: ``placement @
pose @ Trans(far)`` where ``far`` is the joint's location on the segment.
Bones carry no scale, which is what Blender's armatures expect.

The segments are merged into one mesh in the skeleton's rest pose (every
angle zero, no placement), each vertex bound to its segment's bone with
weight 1, its inverse bind matrix the translation back from the bone's rest
pivot.  The mesh node is a root of the scene, untransformed, as glTF asks of
a skinned mesh.  Each triangle's colour is a vertex colour (``COLOR_0``), so
a figure is one primitive per sidedness however many grey levels it has.
"""

from __future__ import annotations

import numpy as np
import pygltflib as G

from liganimate.runtime.figure.pose import mesh_table

from ._gltf import joint_motion, moving_joints
from ._gltf_morph import link_morphs, skin_targets
from ._names import added_origin, joint_names, link_names

__all__ = ["skin_rig"]


def skin_rig(b, take, model, anim, interp) -> list[int]:
    """Add one drawn model as a skeleton and a skinned mesh to builder ``b``; its scene-root nodes."""
    fig = model.figure
    root = b.model_node(take, model, anim, interp)
    qj, shift = joint_motion(model)  # (T, J, 4), (T, J, 3)
    turning, sliding = moving_joints(qj), moving_joints(shift)
    names, sourced = link_names(fig), joint_names(fig)
    loc1, loc2 = fig.locations
    rest = np.zeros((fig.n_links, 3))  # each bone's pivot in the rest pose, in the model node's space
    pivot = np.zeros((fig.n_links, 3))  # each bone's pivot on its own link
    # A capture's importer adds an empty ORIGIN main link; its capture's root is the skeleton's root again.
    bones = {} if added_origin(fig) else {fig.main: _bone(b, take, model, names, fig.main, None, root)}
    for level in fig.traversal:
        for k, p, c, r in zip(level.joints, level.parents, level.children, level.reversed):
            near, far = (loc2[k], loc1[k]) if r else (loc1[k], loc2[k])
            offset = near - pivot[p]
            bone = _bone(b, take, model, names, int(c), (int(k), bool(r), sourced[k]), bones.get(int(p), root))
            node = b.doc.nodes[bone]
            place = offset + shift[:, k]  # (T, 3): a slide moves the bone
            if place[0].any():
                node.translation = [float(v) for v in place[0]]
            node.rotation = [float(v) for v in qj[0, k]]
            if turning[k]:
                b.channel(anim, bone, "rotation", model.ticks, qj[:, k], interp)
            if sliding[k]:
                b.channel(anim, bone, "translation", model.ticks, place, interp)
            bones[int(c)] = bone
            rest[c] = rest[p] + offset
            pivot[c] = far
    order = list(bones)  # the main link (or the root it holds) first, then level by level: the skin's joint order
    ibm = np.zeros((len(order), 4, 4), dtype=np.float32)
    ibm[:] = np.eye(4)
    ibm[:, 3, :3] = -rest[order]  # column-major: the translation is the fourth column
    label = b.doc.nodes[root].name
    skin = G.Skin(
        name=label,
        joints=[bones[i] for i in order],
        skeleton=bones[order[0]],
        inverseBindMatrices=b.accessor(ibm.reshape(len(order), 16), G.MAT4, "ibm"),
    )
    b.doc.skins.append(skin)
    morphs = link_morphs(model)
    targets, weights = skin_targets(morphs, mesh_table(fig), fig.link_scales) if morphs else (None, None)
    mesh = _skinned_mesh(b, model, order, rest, pivot, morphs, targets)
    if mesh is None:
        return [root]
    node = b.node(
        name=f"{label} mesh",
        mesh=mesh,
        skin=len(b.doc.skins) - 1,
        extras={"liganimate": {"scene": take.id, "model": model.name}},
    )
    if weights is not None and weights.size:
        b.doc.nodes[node].weights = [float(v) for v in weights[0]]
        b.channel(anim, node, "weights", model.ticks, weights, interp)
    return [root, node]


def _bone(b, take, model, names, i: int, joint, parent: int) -> int:
    """The bone node of link ``i``; ``joint`` is (joint index, walked backwards, source's name) or None for the main link."""
    fig = model.figure
    link = fig.links[i]
    up = fig.parent_joint_of(i)
    info = {
        "scene": take.id,
        "model": model.name,
        "link": link.name,
        "segment": int(i),
        "joint": None if up is None else up.id,
        "bone": True,
    }
    if joint is not None:
        info["moved_by"] = fig.joints[joint[0]].id
        info["reversed"] = joint[1]
        if joint[2]:
            info["source_joint"] = joint[2]
    n = b.node(name=names[i], extras={"liganimate": info})
    b.doc.nodes[parent].children.append(n)
    return n


def _skinned_mesh(b, model, order, rest, pivot, morphs=None, targets=None):
    """The figure's segments as one mesh in the rest pose, each vertex bound to its segment's bone."""
    fig = model.figure
    table = mesh_table(fig)  # link coordinates; a mirrored link's triangles already rewound
    if len(table.triangles) == 0:
        return None
    # The renderer culls nothing of a model its placement mirrors; neither does the export.
    mirrored = bool((np.linalg.det(model.placements[:, :3, :3]) < 0).any())
    key = ("skin", id(fig.links), id(fig.joints), fig.main, mirrored)
    if key in b.meshes and not morphs:
        return b.meshes[key]
    scale = fig.link_scales[table.link]
    shift = rest[table.link] - pivot[table.link]
    tris = table.triangles * scale[:, None, None] + shift[:, None, :]
    joint_of = np.zeros(fig.n_links, dtype=np.int64)
    joint_of[order] = np.arange(len(order))
    closed = table.closed & (not mirrored)
    if morphs:  # its SCALE and SHAPE tracks: morph targets of this take's own mesh
        return b.mesh_by_vertex_colour(None, model.name, tris, table.shade, closed, joint_of[table.link], targets)
    return b.mesh_by_vertex_colour(key, model.name, tris, table.shade, closed, joints=joint_of[table.link])
