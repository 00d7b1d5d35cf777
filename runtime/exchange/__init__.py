"""Figures and motions in and out of liganimate: glTF 2.0 and BVH export, BVH import.

This sub-package owns the exchange formats and nothing else:

* running a program's scenes without drawing them (:func:`collect`, with a
  renderer stand-in that implements the renderer's ``begin_scene`` /
  ``add_tick`` / ``end_scene`` interface);
* glTF 2.0 export (:func:`gltf_bytes`), a skinned rig or a node tree, written
  through pygltflib;
* BVH export (:func:`bvh_files`) and BVH reading with diagnostics
  (:func:`read_bvh`);
* turning a BVH capture into a LIG library text (:func:`lig_library`);
* writing several files all or nothing (:func:`write_files`).

It may import the runtime (figure, kinematics, pose, motion, camera, values,
errors), ``liganimate.lang.diagnostics`` and ``liganimate.lang.ast`` for
diagnostics, ``liganimate.compiler.types`` for the names of the built-in
functions (which imported segment names avoid), numpy and pygltflib.  Nothing in the runtime, the compiler or
the language imports it; the command line reaches it through
``liganimate.exchange_cli``.  See ``docs/exchange.md``.
"""

from ._bvh_read import BvhClip, read_bvh
from ._bvh_write import bvh_files, bvh_text
from ._collect import ModelTake, SceneCollector, SceneTake, collect
from ._files import write_files
from ._gltf import RIGS, gltf_bytes, gltf_document, key_times
from ._lig_write import clip_angles, lig_library, read_root_path

__all__ = [
    "RIGS",
    "BvhClip",
    "ModelTake",
    "SceneCollector",
    "SceneTake",
    "bvh_files",
    "bvh_text",
    "clip_angles",
    "collect",
    "gltf_bytes",
    "gltf_document",
    "key_times",
    "lig_library",
    "read_bvh",
    "read_root_path",
    "write_files",
]
