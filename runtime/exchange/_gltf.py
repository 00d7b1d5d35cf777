"""glTF 2.0 export: every drawn model of every scene, its segments as nodes, one animation per scene.

Layout (see ``docs/exchange.md``): a model is a node carrying its host
placement (translation, rotation, scale); under it the node of its current
main link; then, walking the tree from the main link as the renderer does,
for each joint a *joint node* at the joint's location whose rotation is the
joint's (its inverse when FIGURE ... MAIN makes the walk go from secondary to
primary), and under it the node of the link it reaches.  Every segment
node's world transform is exactly the ``--poses`` matrix of that segment,
``placement @ pose @ diag(s, s, s, 1)``.  The container is written by
pygltflib; this module only lays out nodes, accessors and animations.
"""

from __future__ import annotations

import base64

import numpy as np
import pygltflib as G
from numpy.typing import ArrayLike

from liganimate.runtime.errors import LigError
from liganimate.runtime.figure.pose import static_triangles
from liganimate.runtime.render.camera import Camera
from liganimate.runtime.values import Graphical, rgb_levels

from ._rotations import (
    continuous_quaternions,
    decompose_trs,
    matrix_from_euler_zyx,
    quaternion_from_matrix,
)

__all__ = ["gltf_bytes", "gltf_document"]

_ARRAY_BUFFER = 34962
_FLOAT = 5126


def gltf_bytes(scenes, binary: bool, fps: float = 24.0, size=(640, 480)):
    """The bytes of a ``.glb`` (``binary``) or a self-contained ``.gltf`` file.

    Parameters
    ----------
    scenes : list of SceneTake
    binary : bool
        GLB container, or JSON with the buffer embedded as a base64 data URI.
    fps : float
        Ticks per second of the animations' time axis.
    size : (int, int)
        The image size whose aspect ratio the cameras take.

    Returns
    -------
    data : bytes
    warnings : list of str
    """
    doc, blob, warnings = gltf_document(scenes, fps, size)
    if binary:
        doc.set_binary_blob(blob)
        return b"".join(doc.save_to_bytes()), warnings
    if blob:
        doc.buffers[0].uri = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
    return doc.gltf_to_json().encode("utf-8"), warnings


def gltf_document(scenes, fps: float = 24.0, size=(640, 480)):
    """Lay out the glTF document of some shot scenes.

    Returns
    -------
    doc : pygltflib.GLTF2
    blob : bytes
        The one buffer's contents.
    warnings : list of str

    Raises
    ------
    LigError
        When a model's placement shears, which no glTF node can express.
    """
    b = _Builder(float(fps), size)
    for take in scenes:
        b.scene(take)
    return b.finish()


def _linear_from_grey(grey: ArrayLike) -> np.ndarray:
    """sRGB-encoded grey levels (what the PNGs show) to glTF's linear colour factors."""
    c = np.asarray(grey, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


class _Builder:
    def __init__(self, fps: float, size):
        self.fps = fps
        self.aspect = float(size[0]) / float(size[1])
        self.doc = G.GLTF2(asset=G.Asset(generator="liganimate", version="2.0"))
        self.chunks: dict[int, list[bytes]] = {0: [], 1: []}  # view 0: vertex data; view 1: animation data
        self.sizes = {0: 0, 1: 0}
        self.accessor_view: list = []
        self.materials: dict = {}
        self.meshes: dict = {}
        self.inputs: dict = {}
        self.warnings: list = []

    # -- data -----------------------------------------------------------------
    def _accessor(self, data: np.ndarray, kind: str, view: int, minmax: bool) -> int:
        a = np.ascontiguousarray(data, dtype=np.float32)
        raw = a.tobytes()
        acc = G.Accessor(bufferView=view, byteOffset=self.sizes[view], componentType=_FLOAT, count=len(a), type=kind)
        if minmax:
            flat = a.reshape(len(a), -1)
            acc.min = [float(v) for v in flat.min(axis=0)]
            acc.max = [float(v) for v in flat.max(axis=0)]
        self.chunks[view].append(raw)
        self.sizes[view] += len(raw)
        self.doc.accessors.append(acc)
        return len(self.doc.accessors) - 1

    def _times(self, ticks: np.ndarray) -> int:
        key = ticks.tobytes()
        hit = self.inputs.get(key)
        if hit is None:
            hit = self.inputs[key] = self._accessor(ticks / self.fps, G.SCALAR, 1, True)
        return hit

    # -- looks ----------------------------------------------------------------
    def _material(self, rgb: int, double: bool) -> int:
        # rgb packs the three 8-bit levels as r << 16 | g << 8 | b.
        key = (rgb, double)
        hit = self.materials.get(key)
        if hit is None:
            levels = [(rgb >> 16) & 255, (rgb >> 8) & 255, rgb & 255]
            r, g, b = (float(c) for c in _linear_from_grey(np.array(levels)))
            look = f"grey {levels[0]}" if len(set(levels)) == 1 else "colour {} {} {}".format(*levels)
            m = G.Material(
                name=look + (" two-sided" if double else ""),
                pbrMetallicRoughness=G.PbrMetallicRoughness(
                    baseColorFactor=[r, g, b, 1.0], metallicFactor=0.0, roughnessFactor=1.0
                ),
                doubleSided=double,
                extensions={"KHR_materials_unlit": {}},
            )
            self.doc.materials.append(m)
            hit = self.materials[key] = len(self.doc.materials) - 1
        return hit

    def _mesh(self, key, name, triangles, shade, closed):
        """A mesh of flat triangles, one primitive per material; None when there are none.

        ``shade`` is per triangle: grey levels (M,) or RGB levels (M, 3).
        """
        if key is not None and key in self.meshes:
            return self.meshes[key]
        index = None
        if len(triangles):
            prims = []
            rgb = rgb_levels(shade).astype(np.int64)
            packed = rgb[:, 0] << 16 | rgb[:, 1] << 8 | rgb[:, 2]
            mat = packed * 2 + (~np.asarray(closed, dtype=bool))
            for m in np.unique(mat):
                tris = np.asarray(triangles)[mat == m].reshape(-1, 3)
                acc = self._accessor(tris, G.VEC3, 0, True)
                prims.append(
                    G.Primitive(
                        attributes=G.Attributes(POSITION=acc), material=self._material(int(m // 2), bool(m % 2)), mode=4
                    )
                )
            self.doc.meshes.append(G.Mesh(name=name, primitives=prims))
            index = len(self.doc.meshes) - 1
        if key is not None:
            self.meshes[key] = index
        return index

    def _link_mesh(self, link):
        g = link.shape
        if not isinstance(g, Graphical) or len(g) == 0:
            return None
        return self._mesh(("link", id(g)), link.label, g.triangles, g.shades(), g.closed)

    # -- nodes ----------------------------------------------------------------
    def _node(self, **kw) -> int:
        self.doc.nodes.append(G.Node(**kw))
        return len(self.doc.nodes) - 1

    def _channel(self, anim, node, path, ticks, values, interp):
        kind = {"translation": G.VEC3, "rotation": G.VEC4, "scale": G.VEC3}[path]
        sampler = G.AnimationSampler(
            input=self._times(ticks), output=self._accessor(values, kind, 1, False), interpolation=interp
        )
        anim.samplers.append(sampler)
        anim.channels.append(
            G.AnimationChannel(sampler=len(anim.samplers) - 1, target=G.AnimationChannelTarget(node=node, path=path))
        )

    def scene(self, take) -> None:
        anim = G.Animation(name=f"scene {take.id}")
        interp = G.ANIM_LINEAR if take.sameframe == 1 else G.ANIM_STEP
        all_ticks = np.arange(take.length, dtype=np.int64)
        roots = []
        for model in take.models:
            roots.append(self._model(take, model, anim, interp, all_ticks))
        for n, (obj, ticks) in enumerate(take.backgrounds):
            roots.append(self._background(take, n, obj, ticks, anim, all_ticks))
        if take.cameras:
            roots.append(self._camera(take, anim, interp))
        self.doc.scenes.append(G.Scene(name=f"scene {take.id}", nodes=roots))
        if anim.channels:
            self.doc.animations.append(anim)

    def _visibility(self, ticks, all_ticks, scale, anim, node):
        """A STEP scale channel that shrinks a node to nothing at the ticks it is not drawn; its rest scale."""
        shown = np.zeros(len(all_ticks), dtype=bool)
        shown[ticks] = True
        values = np.zeros((len(all_ticks), 3))
        where = np.searchsorted(ticks, all_ticks).clip(0, len(ticks) - 1)
        values[shown] = scale[where[shown]]
        self._channel(anim, node, "scale", all_ticks, values, G.ANIM_STEP)
        return values[0]

    def _model(self, take, model, anim, interp, all_ticks) -> int:
        fig = model.figure
        t, R, s, ok = decompose_trs(model.placements)
        if not ok.all():
            tick = int(model.ticks[np.argmin(ok)])
            raise LigError(
                f"model {model.name} is placed with a shear at tick {tick} of scene {take.id}, "
                "which a glTF node cannot express.",
                "a <SCALE (a, b, c)> with unequal factors followed by a <ROT> shears; scale after rotating, "
                "or scale the shapes instead",
            )
        q = continuous_quaternions(quaternion_from_matrix(R))
        ticks = model.ticks
        root = self._node(name=model.name, extras={"liganimate": {"scene": take.id, "model": model.name}})
        node = self.doc.nodes[root]
        node.translation = [float(v) for v in t[0]]
        node.rotation = [float(v) for v in q[0]]
        for path, values in (("translation", t), ("rotation", q)):
            if len(values) > 1 and (values != values[0]).any():
                self._channel(anim, root, path, ticks, values, interp)
        hidden = len(ticks) < len(all_ticks)
        if hidden:
            node.scale = [float(v) for v in self._visibility(ticks, all_ticks, s, anim, root)]
        else:
            node.scale = [float(v) for v in s[0]]
            if len(s) > 1 and (s != s[0]).any():
                self._channel(anim, root, "scale", ticks, s, interp)
        # Joint rotations, reversed (transposed) where the walk goes from secondary to primary.
        Rj = matrix_from_euler_zyx(model.angles)  # (T, J, 3, 3)
        rev = fig.reversed_joints
        if rev.any():
            Rj[:, rev] = np.swapaxes(Rj[:, rev], -1, -2)
        qj = continuous_quaternions(quaternion_from_matrix(Rj))  # (T, J, 4)
        moving = (qj != qj[:1]).any(axis=(0, 2)) if len(qj) > 1 else np.zeros(fig.n_joints, dtype=bool)
        scales = fig.link_scales
        loc1, loc2 = fig.locations
        seg = {}
        seg[fig.main] = self._segment(model, fig, fig.main, root, take)
        for level in fig.traversal:
            for k, p, c, r in zip(level.joints, level.parents, level.children, level.reversed):
                near, far = (loc2[k], loc1[k]) if r else (loc1[k], loc2[k])
                sp = scales[p]
                jid = fig.joints[k].id
                jn = self._node(
                    name=f"{model.name} joint {jid}",
                    translation=[float(v) for v in near / sp],
                    rotation=[float(v) for v in qj[0, k]],
                    extras={"liganimate": {"scene": take.id, "model": model.name, "joint": jid, "reversed": bool(r)}},
                )
                if sp != 1.0:
                    self.doc.nodes[jn].scale = [1.0 / sp] * 3
                self.doc.nodes[seg[p]].children.append(jn)
                if moving[k]:
                    self._channel(anim, jn, "rotation", ticks, qj[:, k], interp)
                seg[c] = self._segment(model, fig, c, jn, take, offset=-far)
        return root

    def _segment(self, model, fig, i, parent, take, offset=None) -> int:
        link = fig.links[i]
        up = fig.parent_joint_of(i)
        n = self._node(
            name=f"{model.name} {link.label}" + (f" {up.id}" if up is not None else ""),
            mesh=self._link_mesh(link),
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
        node = self.doc.nodes[n]
        if offset is not None and offset.any():
            node.translation = [float(v) for v in offset]
        if link.scale != 1.0:
            node.scale = [link.scale] * 3
        self.doc.nodes[parent].children.append(n)
        return n

    def _background(self, take, n, obj, ticks, anim, all_ticks) -> int:
        if isinstance(obj, Graphical):
            mesh = self._mesh(("link", id(obj)), f"background {n + 1}", obj.triangles, obj.shades(), obj.closed)
        else:
            tris, shade, closed = static_triangles(obj)
            mesh = self._mesh(("figure", id(obj)), f"background {n + 1}", tris, shade, closed)
        node = self._node(name=f"scene {take.id} background {n + 1}", mesh=mesh)
        if len(ticks) < len(all_ticks):
            scale = np.ones((len(ticks), 3))
            self.doc.nodes[node].scale = [float(v) for v in self._visibility(ticks, all_ticks, scale, anim, node)]
        return node

    def _camera(self, take, anim, interp) -> int:
        points = np.array([c[0] for c in take.cameras])
        widths = np.array([c[1] for c in take.cameras])
        if (widths != widths[0]).any():
            self.warnings.append(
                f"scene {take.id} changes its VIEW WIDTH; a glTF camera's field of view cannot change, so "
                f"the camera keeps the first width, {widths[0]:g}."
            )
        axes = {}
        for p in {tuple(p) for p in points}:
            cam = Camera(p, widths[0])
            right, up, forward = cam.axes
            axes[p] = np.stack([right, up, -forward], axis=1)
        R = np.stack([axes[tuple(p)] for p in points])
        q = continuous_quaternions(quaternion_from_matrix(R))
        dist = np.linalg.norm(points[0])
        yfov = 2.0 * np.arctan(widths[0] / self.aspect / 2.0 / dist)
        self.doc.cameras.append(
            G.Camera(
                name=f"scene {take.id} VIEW",
                type="perspective",
                perspective=G.Perspective(
                    aspectRatio=self.aspect, yfov=float(yfov), znear=float(1e-4 * np.linalg.norm(points, axis=1).min())
                ),
            )
        )
        node = self._node(
            name=f"scene {take.id} camera",
            camera=len(self.doc.cameras) - 1,
            translation=[float(v) for v in points[0]],
            rotation=[float(v) for v in q[0]],
        )
        ticks = np.arange(len(points), dtype=np.int64)
        if (points != points[0]).any():
            self._channel(anim, node, "translation", ticks, points, interp)
            self._channel(anim, node, "rotation", ticks, q, interp)
        return node

    # -- the container ----------------------------------------------------------
    def finish(self):
        blob = bytearray()
        remap = {}
        for view in (0, 1):
            if not self.sizes[view]:
                continue
            while len(blob) % 4:
                blob.append(0)
            bv = G.BufferView(buffer=0, byteOffset=len(blob), byteLength=self.sizes[view])
            if view == 0:
                # Several POSITION accessors share this view, which glTF allows only with a stride.
                bv.target = _ARRAY_BUFFER
                bv.byteStride = 12
            for raw in self.chunks[view]:
                blob += raw
            self.doc.bufferViews.append(bv)
            remap[view] = len(self.doc.bufferViews) - 1
        for acc in self.doc.accessors:
            acc.bufferView = remap[acc.bufferView]
        if blob:
            self.doc.buffers.append(G.Buffer(byteLength=len(blob)))
        if self.materials:
            self.doc.extensionsUsed = ["KHR_materials_unlit"]
        self.doc.scene = 0 if self.doc.scenes else None
        return self.doc, bytes(blob), self.warnings
