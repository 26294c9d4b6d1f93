"""Import time in Blender of one meshquilt output in each format (issue 15).

    blender -b --factory-startup --python bench/blender_import.py -- OUT_STEM [RUNS]

OUT_STEM.obj, .ply and .glb are imported with Blender's own importers (File > Import), and the
.ply also with the add-on's reader (blender/meshquilt/exchange.py, what Run uses), each RUNS
times into an empty scene; prints the median seconds, the faces and what came in (objects,
materials, whether element ids are there) as one JSON line.
"""

import json
import os
import statistics
import sys
import time

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
stem = args[0]
runs = int(args[1]) if len(args) > 1 else 3
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "blender"))
import meshquilt.exchange as exchange  # noqa: E402


def material_for(name, look):
    return bpy.data.materials.get(name) or bpy.data.materials.new(name)


def addon_reader(path):
    result = exchange.read_ply(path)
    me = exchange.build_mesh(bpy, "quilt", result, material_for)
    bpy.context.scene.collection.objects.link(bpy.data.objects.new("quilt", me))


importers = {
    "obj": lambda p: bpy.ops.wm.obj_import(filepath=p),
    "ply": lambda p: bpy.ops.import_mesh.ply(filepath=p),
    # "SMOOTH": Debian 12's Blender 3.4 glTF importer fails in its default shading mode with
    # numpy 1.24 (numpy.bool).
    "glb": lambda p: bpy.ops.import_scene.gltf(filepath=p, import_shading="SMOOTH"),
    "ply (add-on reader)": addon_reader,
}
report = {}
for name, load in importers.items():
    path = stem + "." + name.split()[0]
    times = []
    for _ in range(runs):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        start = time.perf_counter()
        load(path)
        times.append(time.perf_counter() - start)
    meshes = [o for o in bpy.data.objects if o.type == "MESH"]
    report[name] = {
        "seconds": round(statistics.median(times), 2),
        "runs": runs,
        "objects": len(meshes),
        "faces": sum(len(o.data.polygons) for o in meshes),
        "materials": sorted({m.name for o in meshes for m in o.data.materials if m}),
        "element_id": any("element_id" in o.data.attributes for o in meshes),
        "bytes": os.path.getsize(path),
    }
    print("[import] %s: %s" % (name, json.dumps(report[name])), flush=True)
print("[import] " + json.dumps(report), flush=True)
