"""Import a glTF file with Blender's own importer (``bpy``) and write what Blender made of it, as JSON.

Run with a Python that has ``bpy`` (the test suite's venv in tests/.cache/bpy):

    python blender_pose.py FILE.glb OUT.json FPS FRAME...

The scene's frame rate is set to FPS before the import, as a user exporting
at that rate would set it, so that tick k of the file is frame k.  The JSON
holds the objects by type, every armature with its bones, every mesh with
its modifiers, parent, materials and colour attributes, and at each frame
every bone's head in world coordinates and every vertex of every skinned
mesh as the armature deforms it, in world coordinates.
"""

import json
import sys

import bpy


def main(path, out, fps, frames):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = round(fps)
    scene.render.fps_base = round(fps) / fps
    bpy.ops.import_scene.gltf(filepath=path)
    objects = list(bpy.data.objects)
    record = {
        "objects": [{"name": o.name, "type": o.type, "parent": o.parent.name if o.parent else None} for o in objects],
        "armatures": [],
        "meshes": [],
        "frames": [],
    }
    armatures = [o for o in objects if o.type == "ARMATURE"]
    skinned = [o for o in objects if o.type == "MESH" and any(m.type == "ARMATURE" for m in o.modifiers)]
    for a in armatures:
        record["armatures"].append({"name": a.name, "bones": [b.name for b in a.data.bones]})
    for m in (o for o in objects if o.type == "MESH"):
        record["meshes"].append(
            {
                "name": m.name,
                "parent": m.parent.name if m.parent else None,
                "armatures": [x.object.name for x in m.modifiers if x.type == "ARMATURE" and x.object],
                "materials": [s.material.name for s in m.material_slots if s.material],
                "colours": list(m.data.color_attributes.keys()),
                "vertices": len(m.data.vertices),
            }
        )
    for f in frames:
        scene.frame_set(f)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        tick = {"frame": f, "bones": {}, "vertices": {}}
        for a in armatures:
            W = a.matrix_world
            tick["bones"][a.name] = {pb.name: list(W @ pb.head) for pb in a.pose.bones}
        for m in skinned:
            e = m.evaluated_get(depsgraph)
            mesh = e.to_mesh()
            W = e.matrix_world
            tick["vertices"][m.name] = [list(W @ v.co) for v in mesh.vertices]
            e.to_mesh_clear()
        record["frames"].append(tick)
    with open(out, "w", encoding="utf-8") as fh:
        json.dump(record, fh)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]), [int(f) for f in sys.argv[4:]])
