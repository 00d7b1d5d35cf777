"""glTF 2.0 export: every drawn model of every scene, one animation per scene.

A model leaves as one of two rigs (``docs/exchange.md``):

* ``skin`` (:mod:`._gltf_skin`): a skeleton of joint nodes, one bone per
  link, and the model's segments merged into one skinned mesh with rigid
  weights, the animation on the joint nodes: what Blender imports as an
  armature and three.js as a SkinnedMesh;
* ``nodes`` (:mod:`._gltf_nodes`): a rigid tree of segment and joint nodes,
  each segment carrying its own mesh.

This module holds what both share: the buffer and its accessors, the time
axis, the model node that carries a model's host placement, materials,
backgrounds, the camera and the container.  The container is written by
pygltflib.
"""

from __future__ import annotations

import base64

import numpy as np
import pygltflib as G
from numpy.typing import ArrayLike

from liganimate.runtime.errors import LigError
from liganimate.runtime.figure.kinematics import joint_transforms
from liganimate.runtime.figure.pose import static_triangles
from liganimate.runtime.render.camera import Camera
from liganimate.runtime.values import Graphical, rgb_levels

from ._rotations import (
    continuous_quaternions,
    decompose_trs,
    quaternion_from_matrix,
)

__all__ = ["RIGS", "gltf_bytes", "gltf_document", "key_times"]

#: The rigs ``--rig`` chooses from; the first is the default.
RIGS = ("skin", "nodes")

_ARRAY_BUFFER = 34962
_FLOAT = 5126
_UNSIGNED_BYTE = 5121
_UNSIGNED_SHORT = 5123
_COMPONENT = {np.dtype(np.float32): _FLOAT, np.dtype(np.uint8): _UNSIGNED_BYTE, np.dtype(np.uint16): _UNSIGNED_SHORT}
_WIDTH = {G.SCALAR: 1, G.VEC3: 3, G.VEC4: 4, G.MAT4: 16}


def gltf_bytes(scenes, binary: bool, fps: float = 24.0, size=(640, 480), rig: str = "skin"):
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
    rig : {"skin", "nodes"}
        How a model leaves: a skinned mesh on a skeleton, or a tree of rigid
        segment nodes.

    Returns
    -------
    data : bytes
    warnings : list of str
    """
    doc, blob, warnings = gltf_document(scenes, fps, size, rig)
    if binary:
        doc.set_binary_blob(blob)
        return b"".join(doc.save_to_bytes()), warnings
    if blob:
        doc.buffers[0].uri = "data:application/octet-stream;base64," + base64.b64encode(blob).decode("ascii")
    return doc.gltf_to_json().encode("utf-8"), warnings


def gltf_document(scenes, fps: float = 24.0, size=(640, 480), rig: str = "skin"):
    """Lay out the glTF document of some shot scenes.

    Parameters are those of :func:`gltf_bytes`.

    Returns
    -------
    doc : pygltflib.GLTF2
    blob : bytes
        The one buffer's contents.
    warnings : list of str

    Raises
    ------
    LigError
        When a model's placement shears, which no glTF node can express, or
        a scene is so long at ``fps`` that 32-bit key times would collide.
    ValueError
        For a rig not in :data:`RIGS`.
    """
    if rig not in RIGS:
        raise ValueError(f"unknown glTF rig {rig!r}; the rigs are {', '.join(RIGS)}")
    b = Builder(float(fps), size, rig)
    for take in scenes:
        b.scene(take)
    return b.finish()


def key_times(ticks: np.ndarray, fps: float) -> np.ndarray:
    """The 32-bit key times of ticks: for each, the largest float32 not after ``tick / fps``.

    A player that samples at ``k / fps`` (computed in double or single
    precision) then finds key ``k`` at or before its time, never after, so a
    STEP sampler shows tick ``k`` and not the one before (``float32(k / 24)``
    rounded to nearest lands up to 4 ns after ``k / 24`` for many ``k``).

    Parameters
    ----------
    ticks : ndarray of int
    fps : float

    Returns
    -------
    ndarray of float32
    """
    exact = np.asarray(ticks, dtype=np.float64) / fps
    t = exact.astype(np.float32)
    late = t.astype(np.float64) > exact
    t[late] = np.nextafter(t[late], np.float32(-np.inf))
    return t


def linear_from_grey(grey: ArrayLike) -> np.ndarray:
    """sRGB-encoded levels (what the PNGs show) to glTF's linear colour factors."""
    c = np.asarray(grey, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def joint_motion(model):
    """Every joint node's rotation and extra translation at every drawn tick.

    A joint's transform (:func:`~liganimate.runtime.figure.kinematics.joint_transforms`,
    which knows AXIS frames and SLIDE joints) is ``Trans(L1) R Trans(-L2)``
    moved by a slide's shift ``d``.  Walked forwards, the joint node at ``L1``
    turns by ``R`` and moves by ``d``; walked backwards (FIGURE ... MAIN),
    the node at ``L2`` turns by ``R^T`` and moves by ``-R^T d``.

    Returns
    -------
    q : ndarray, shape (T, J, 4)
        Rotations as quaternions, continuous along T.
    shift : ndarray, shape (T, J, 3)
        Translations to add to the joint node's location (zero but for slides).
    """
    fig = model.figure
    X = joint_transforms(fig, model.angles)  # (T, J, 4, 4)
    R = X[..., :3, :3].copy()
    loc1, loc2 = fig.locations
    shift = X[..., :3, 3] - loc1 + np.einsum("...ij,...j->...i", R, np.broadcast_to(loc2, R.shape[:-1]))
    rev = fig.reversed_joints
    if rev.any():
        Rt = np.swapaxes(R[:, rev], -1, -2)
        R[:, rev] = Rt
        shift[:, rev] = -np.einsum("...ij,...j->...i", Rt, shift[:, rev])
    shift[:, ~fig.slides] = 0.0  # exactly zero where nothing slides, not rounding noise
    return continuous_quaternions(quaternion_from_matrix(R)), shift


def moving_joints(values: np.ndarray) -> np.ndarray:
    """Per joint, whether ``values`` (T, J, k) change over the ticks."""
    if len(values) < 2:
        return np.zeros(values.shape[1], dtype=bool)
    return (values != values[:1]).any(axis=(0, 2))


class Builder:
    """The glTF document being laid out: nodes, accessors, materials, one scene at a time.

    ``rig`` is one of :data:`RIGS`: how each drawn model is laid out, and
    whether meshes carry their colours as materials (``nodes``) or as
    vertex colours (``skin``).
    """

    def __init__(self, fps: float, size, rig: str):
        # Imported here: both rig modules build on this module's Builder.
        from ._gltf_nodes import node_rig
        from ._gltf_skin import skin_rig

        self.fps = fps
        self.aspect = float(size[0]) / float(size[1])
        self.model_rig = skin_rig if rig == "skin" else node_rig
        self.background_mesh = self.mesh_by_vertex_colour if rig == "skin" else self.mesh_by_colour
        self.doc = G.GLTF2(asset=G.Asset(generator="liganimate", version="2.0"))
        # Buffer views by name: vertex data of one element size share a view with that stride.
        self.views: dict = {}
        self.accessor_view: list = []
        self.materials: dict = {}
        self.meshes: dict = {}
        self.inputs: dict = {}
        self.warnings: list = []
        self.length = 0  # the current scene's number of ticks
        self.labels: set = set()  # model node names given so far

    # -- data -----------------------------------------------------------------
    def accessor(
        self, data: np.ndarray, kind: str, use: str = "data", minmax: bool = False, normalized: bool = False
    ) -> int:
        """Append ``data`` (float32, uint8 or uint16) to the buffer as an accessor of type ``kind``.

        ``use`` is ``"vertex"`` (a vertex attribute), ``"ibm"`` (inverse bind
        matrices) or ``"data"`` (animation): glTF wants each buffer view to
        serve one use.  Vertex attributes of one element size share a view
        with that stride, as glTF requires of a view several attributes share.
        """
        a = np.ascontiguousarray(data)
        a = a.reshape(len(a), _WIDTH[kind])
        component = _COMPONENT[a.dtype]
        stride = a.itemsize * a.shape[1] if use == "vertex" else 0
        name = f"vertex {stride}" if stride else use
        view = self.views.setdefault(name, {"chunks": [], "size": 0, "stride": stride})
        acc = G.Accessor(byteOffset=view["size"], componentType=component, count=len(a), type=kind)
        if normalized:
            acc.normalized = True
        if minmax:
            acc.min = [float(v) for v in a.min(axis=0)]
            acc.max = [float(v) for v in a.max(axis=0)]
        raw = a.tobytes()
        view["chunks"].append(raw)
        view["size"] += len(raw)
        self.doc.accessors.append(acc)
        self.accessor_view.append(name)
        return len(self.doc.accessors) - 1

    def _times(self, ticks: np.ndarray) -> int:
        key = ticks.tobytes()
        hit = self.inputs.get(key)
        if hit is None:
            t = key_times(ticks, self.fps)
            if len(t) > 1 and not (np.diff(t) > 0).all():
                raise LigError(
                    f"a scene of {self.length} ticks is too long for glTF's 32-bit key times at {self.fps:g} "
                    "ticks per second: two ticks would share a time.",
                    "export at a lower --fps, or shoot the scene in shorter scenes",
                )
            hit = self.inputs[key] = self.accessor(t, G.SCALAR, minmax=True)
        return hit

    def channel(self, anim, node: int, path: str, ticks: np.ndarray, values: np.ndarray, interp: str) -> None:
        """Animate ``path`` of ``node`` with ``values`` at ``ticks``.

        A channel that reaches the scene's last tick holds that value one tick
        more, so the animation lasts the scene's ``length / fps`` seconds, as
        the film does, and a looping player shows the last tick for a tick
        before it starts again.
        """
        ticks = np.asarray(ticks, dtype=np.int64)
        values = np.asarray(values, dtype=np.float64)
        if len(ticks) and ticks[-1] == self.length - 1:
            ticks = np.append(ticks, self.length)
            values = np.concatenate([values, values[-1:]])
        kind = {"translation": G.VEC3, "rotation": G.VEC4, "scale": G.VEC3, "weights": G.SCALAR}[path]
        if path == "weights":  # (T, N) morph target weights: N scalars per key, key after key
            values = values.reshape(-1, 1)
        sampler = G.AnimationSampler(
            input=self._times(ticks), output=self.accessor(values.astype(np.float32), kind), interpolation=interp
        )
        anim.samplers.append(sampler)
        anim.channels.append(
            G.AnimationChannel(sampler=len(anim.samplers) - 1, target=G.AnimationChannelTarget(node=node, path=path))
        )

    # -- looks ----------------------------------------------------------------
    def material(self, rgb: int | None, double: bool) -> int:
        """The material of one colour (``r << 16 | g << 8 | b`` levels), or of vertex colours (``None``)."""
        key = (rgb, double)
        hit = self.materials.get(key)
        if hit is None:
            if rgb is None:
                levels, look = [255, 255, 255], "vertex colours"
            else:
                levels = [(rgb >> 16) & 255, (rgb >> 8) & 255, rgb & 255]
                look = f"grey {levels[0]}" if len(set(levels)) == 1 else "colour {} {} {}".format(*levels)
            r, g, b = (float(c) for c in linear_from_grey(np.array(levels)))
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

    def mesh_by_colour(self, key, name, triangles, shade, closed, targets=None):
        """A mesh of flat triangles, one primitive per material (colour and sidedness); None when empty.

        ``shade`` is per triangle: grey levels (M,) or RGB levels (M, 3);
        ``targets`` (N, M, 3, 3), displacements of the triangles' corners, become
        the mesh's morph targets.
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
                tris = np.asarray(triangles)[mat == m].reshape(-1, 3).astype(np.float32)
                acc = self.accessor(tris, G.VEC3, "vertex", minmax=True)
                prims.append(
                    G.Primitive(
                        attributes=G.Attributes(POSITION=acc),
                        material=self.material(int(m // 2), bool(m % 2)),
                        mode=4,
                        targets=self._targets(targets, mat == m),
                    )
                )
            self.doc.meshes.append(G.Mesh(name=name, primitives=prims, weights=self._rest_weights(targets)))
            index = len(self.doc.meshes) - 1
        if key is not None:
            self.meshes[key] = index
        return index

    def _targets(self, targets, sel) -> list | None:
        """The morph targets of one primitive, its triangles ``sel`` of ``targets`` (N, M, 3, 3)."""
        if targets is None or not len(targets):
            return None
        out = []
        for d in np.asarray(targets):
            acc = self.accessor(d[sel].reshape(-1, 3).astype(np.float32), G.VEC3, "vertex", minmax=True)
            out.append(G.Attributes(POSITION=acc))
        return out

    @staticmethod
    def _rest_weights(targets) -> list | None:
        return None if targets is None or not len(targets) else [0.0] * len(targets)

    def mesh_by_vertex_colour(self, key, name, triangles, shade, closed, joints=None, targets=None):
        """A mesh whose triangles carry their colour as ``COLOR_0``: one primitive per sidedness.

        Parameters
        ----------
        triangles : ndarray, shape (M, 3, 3)
        shade : ndarray, shape (M,) or (M, 3)
            Grey or RGB levels per triangle.
        closed : ndarray of bool, shape (M,)
            One-sided (culled when facing away) where true.
        joints : ndarray of int, shape (M,), optional
            The skin joint that carries each triangle (weight 1), for a
            skinned mesh.
        targets : ndarray, shape (N, M, 3, 3), optional
            Morph targets: displacements of the triangles' corners.

        Returns
        -------
        int or None
            The mesh, None when there are no triangles.
        """
        if key is not None and key in self.meshes:
            return self.meshes[key]
        index = None
        if len(triangles):
            tris = np.asarray(triangles, dtype=np.float64)
            colour = linear_from_grey(rgb_levels(shade))  # (M, 3)
            closed = np.asarray(closed, dtype=bool)
            prims = []
            for double in (False, True):
                sel = closed != double
                if not sel.any():
                    continue
                attrs = G.Attributes(
                    POSITION=self.accessor(tris[sel].reshape(-1, 3).astype(np.float32), G.VEC3, "vertex", True),
                    COLOR_0=self.accessor(np.repeat(colour[sel], 3, axis=0).astype(np.float32), G.VEC3, "vertex"),
                )
                if joints is not None:
                    self._skin_attributes(attrs, np.repeat(np.asarray(joints)[sel], 3))
                prim = G.Primitive(attributes=attrs, material=self.material(None, double), mode=4)
                prim.targets = self._targets(targets, sel)
                prims.append(prim)
            self.doc.meshes.append(G.Mesh(name=name, primitives=prims, weights=self._rest_weights(targets)))
            index = len(self.doc.meshes) - 1
        if key is not None:
            self.meshes[key] = index
        return index

    def _skin_attributes(self, attrs, joint) -> None:
        # One joint per vertex, weight 1 (255 of a normalized byte); the unused
        # slots name joint 0 with weight 0.
        dtype = np.uint8 if joint.max(initial=0) < 256 else np.uint16
        j = np.zeros((len(joint), 4), dtype=dtype)
        j[:, 0] = joint
        w = np.zeros((len(joint), 4), dtype=np.uint8)
        w[:, 0] = 255
        attrs.JOINTS_0 = self.accessor(j, G.VEC4, "vertex")
        attrs.WEIGHTS_0 = self.accessor(w, G.VEC4, "vertex", normalized=True)

    # -- nodes ----------------------------------------------------------------
    def node(self, **kw) -> int:
        """Append a node; its index."""
        self.doc.nodes.append(G.Node(**kw))
        return len(self.doc.nodes) - 1

    def scene(self, take) -> None:
        """Add one shot scene: its models, backgrounds and camera, and their animation."""
        anim = G.Animation(name=f"scene {take.id}")
        interp = G.ANIM_LINEAR if take.sameframe == 1 else G.ANIM_STEP
        self.length = take.length
        roots = []
        for model in take.models:
            roots.extend(self.model_rig(self, take, model, anim, interp))
        for n, (obj, ticks) in enumerate(take.backgrounds):
            roots.append(self._background(take, n, obj, ticks, anim))
        if take.cameras:
            roots.append(self._camera(take, anim, interp))
        self.doc.scenes.append(G.Scene(name=f"scene {take.id}", nodes=roots))
        if anim.channels:
            self.doc.animations.append(anim)

    def visibility(self, ticks, scale, anim, node):
        """A STEP scale channel that shrinks a node to nothing at the ticks it is not drawn; its rest scale.

        The rest scale (the node's own, which a viewer shows without the
        animation) is the scale at the first tick the node is drawn, never
        zero: Blender's importer cannot make an armature of a zero-scale node.
        """
        all_ticks = np.arange(self.length, dtype=np.int64)
        shown = np.zeros(len(all_ticks), dtype=bool)
        shown[ticks] = True
        values = np.zeros((len(all_ticks), 3))
        where = np.searchsorted(ticks, all_ticks).clip(0, len(ticks) - 1)
        values[shown] = scale[where[shown]]
        self.channel(anim, node, "scale", all_ticks, values, G.ANIM_STEP)
        return scale[0]

    def model_node(self, take, model, anim, interp) -> int:
        """The node that carries a model's host placement (translation, rotation, scale), animated.

        Raises
        ------
        LigError
            When the placement shears at some tick.
        """
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
        root = self.node(name=self._label(take, model), extras={"liganimate": {"scene": take.id, "model": model.name}})
        node = self.doc.nodes[root]
        node.translation = [float(v) for v in t[0]]
        node.rotation = [float(v) for v in q[0]]
        for path, values in (("translation", t), ("rotation", q)):
            if len(values) > 1 and (values != values[0]).any():
                self.channel(anim, root, path, ticks, values, interp)
        if len(ticks) < self.length:
            node.scale = [float(v) for v in self.visibility(ticks, s, anim, root)]
        else:
            node.scale = [float(v) for v in s[0]]
            if len(s) > 1 and (s != s[0]).any():
                self.channel(anim, root, "scale", ticks, s, interp)
        return root

    def _label(self, take, model) -> str:
        """The model node's name: the MODEL's, made distinct within the file.

        A model drawn in several scenes (or in several structures in one)
        gets ``<MODEL> scene <id>`` after its first appearance, so that a
        viewer that names objects by node (Blender) shows which is which.
        """
        label = model.name
        if label in self.labels:
            label = f"{model.name} scene {take.id}"
        unique, n = label, 2
        while unique in self.labels:
            unique, n = f"{label} ({n})", n + 1
        self.labels.add(unique)
        return unique

    def _background(self, take, n, obj, ticks, anim) -> int:
        mesh = self.background_mesh
        if isinstance(obj, Graphical):
            m = mesh(("link", id(obj)), f"background {n + 1}", obj.triangles, obj.shades(), obj.closed)
        else:
            tris, shade, closed = static_triangles(obj)
            m = mesh(("figure", id(obj)), f"background {n + 1}", tris, shade, closed)
        node = self.node(name=f"scene {take.id} background {n + 1}", mesh=m)
        if len(ticks) < self.length:
            scale = np.ones((len(ticks), 3))
            self.doc.nodes[node].scale = [float(v) for v in self.visibility(ticks, scale, anim, node)]
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
        node = self.node(
            name=f"scene {take.id} camera",
            camera=len(self.doc.cameras) - 1,
            translation=[float(v) for v in points[0]],
            rotation=[float(v) for v in q[0]],
        )
        ticks = np.arange(len(points), dtype=np.int64)
        if (points != points[0]).any():
            self.channel(anim, node, "translation", ticks, points, interp)
            self.channel(anim, node, "rotation", ticks, q, interp)
        return node

    # -- the container ----------------------------------------------------------
    def finish(self):
        """The document, its buffer's bytes and the warnings."""
        blob = bytearray()
        remap = {}
        for name in sorted(self.views, key=lambda n: (not n.startswith("vertex"), n)):
            view = self.views[name]
            while len(blob) % 4:
                blob.append(0)
            bv = G.BufferView(buffer=0, byteOffset=len(blob), byteLength=view["size"])
            if view["stride"]:
                # Several vertex attributes share this view, which glTF allows only with a stride.
                bv.target = _ARRAY_BUFFER
                bv.byteStride = view["stride"]
            for raw in view["chunks"]:
                blob += raw
            self.doc.bufferViews.append(bv)
            remap[name] = len(self.doc.bufferViews) - 1
        for acc, name in zip(self.doc.accessors, self.accessor_view):
            acc.bufferView = remap[name]
        if blob:
            self.doc.buffers.append(G.Buffer(byteLength=len(blob)))
        if self.materials:
            self.doc.extensionsUsed = ["KHR_materials_unlit"]
        self.doc.scene = 0 if self.doc.scenes else None
        return self.doc, bytes(blob), self.warnings
