"""Figures and motions in and out of liganimate: glTF 2.0 and BVH export, BVH import.

This sub-package owns the exchange formats and nothing else:

* running a program's scenes without drawing them (:func:`collect`, with a
  renderer stand-in that implements the renderer's ``begin_scene`` /
  ``add_tick`` / ``end_scene`` interface);
* glTF 2.0 export (:func:`gltf_bytes`), written through pygltflib;
* BVH export (:func:`bvh_files`) and BVH reading with diagnostics
  (:func:`read_bvh`);
* turning a BVH capture into a LIG library text (:func:`lig_library`);
* URDF robot descriptions: reading them with diagnostics (:func:`read_urdf`,
  expat with document types refused) and writing them as a library
  (:func:`import_urdf`; meshes through trimesh);
* writing several files all or nothing (:func:`write_files`).

It is one of the tools, a layer above the runtime core (docs/architecture.md):
it may import the runtime (figure, kinematics, pose, motion, camera, values,
errors), ``liganimate.lang.diagnostics`` and ``liganimate.lang.ast`` for
diagnostics, ``liganimate.compiler.names`` for the names a program may not
define (which imported segment names avoid), numpy, pygltflib and trimesh.  The
runtime core, the compiler and the language never import it; of the other
tools the viewer and the studio do (to run a program's scenes); the
command line reaches it through ``liganimate.exchange_cli``, Python through
``liganimate.api``.  See ``docs/exchange.md``.
"""

from importlib import import_module
from typing import TYPE_CHECKING, Any

# The format table is light (its writers import on first use): the command
# line reads it to build its options, and must not pay for numpy or
# pygltflib to print --help. Everything else loads when first named.
from ._formats import (
    EXPORT_FORMATS,
    EXPORT_OPTIONS,
    Export,
    ExportFormat,
    ExportOption,
    export_format,
    export_options,
    export_scenes,
)

if TYPE_CHECKING:
    from ._bvh_read import BvhClip, read_bvh
    from ._bvh_write import bvh_files, bvh_text
    from ._clip import ClipPose, clip_pose, cut_frames, resample
    from ._collect import ModelTake, SceneCollector, SceneTake, collect
    from ._files import write_files
    from ._gltf import RIGS, gltf_bytes, gltf_document, key_times
    from ._lig_write import ImportOptions, clip_angles, import_library, lig_library, read_root_path
    from ._onto import OntoOptions, retarget_library
    from ._retarget import RetargetOptions
    from ._urdf_lig import MESH_TRIANGLES, UrdfImportOptions, import_urdf, robot_model_name
    from ._urdf_read import Urdf, read_urdf

#: Name -> the module of this package that defines it, imported on first use.
_LAZY = {
    "BvhClip": "_bvh_read",
    "read_bvh": "_bvh_read",
    "bvh_files": "_bvh_write",
    "bvh_text": "_bvh_write",
    "ModelTake": "_collect",
    "SceneCollector": "_collect",
    "SceneTake": "_collect",
    "collect": "_collect",
    "write_files": "_files",
    "gltf_bytes": "_gltf",
    "gltf_document": "_gltf",
    "key_times": "_gltf",
    "RIGS": "_gltf",
    "ClipPose": "_clip",
    "clip_pose": "_clip",
    "cut_frames": "_clip",
    "resample": "_clip",
    "ImportOptions": "_lig_write",
    "OntoOptions": "_onto",
    "retarget_library": "_onto",
    "RetargetOptions": "_retarget",
    "import_library": "_lig_write",
    "clip_angles": "_lig_write",
    "lig_library": "_lig_write",
    "read_root_path": "_lig_write",
    "MESH_TRIANGLES": "_urdf_lig",
    "UrdfImportOptions": "_urdf_lig",
    "import_urdf": "_urdf_lig",
    "robot_model_name": "_urdf_lig",
    "Urdf": "_urdf_read",
    "read_urdf": "_urdf_read",
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


__all__ = [
    "EXPORT_FORMATS",
    "EXPORT_OPTIONS",
    "RIGS",
    "MESH_TRIANGLES",
    "Urdf",
    "UrdfImportOptions",
    "import_urdf",
    "read_urdf",
    "robot_model_name",
    "BvhClip",
    "ClipPose",
    "Export",
    "ExportFormat",
    "ExportOption",
    "ImportOptions",
    "ModelTake",
    "OntoOptions",
    "RetargetOptions",
    "SceneCollector",
    "SceneTake",
    "bvh_files",
    "bvh_text",
    "clip_angles",
    "clip_pose",
    "collect",
    "cut_frames",
    "export_format",
    "export_options",
    "export_scenes",
    "gltf_bytes",
    "gltf_document",
    "import_library",
    "key_times",
    "lig_library",
    "read_bvh",
    "read_root_path",
    "resample",
    "retarget_library",
    "write_files",
]
