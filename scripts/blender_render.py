"""Renders a meshquilt result on its base in Blender with Cycles on the CPU, headless:

    blender -b --factory-startup --python scripts/blender_render.py -- BASE RESULT.ply OUT.png \
        [--view X Y Z] [--focus X Y Z RADIUS] [--y-up] [--samples N] [--size W H]

BASE may be OBJ, PLY or OFF; RESULT is the engine's PLY, read by the add-on's reader (element
ids and a material per kind, as Run brings it in). The camera looks at the result's centre
from the direction --view (default 1 -1 0.6), framing it whole.
"""

import math
import os
import sys

import bpy
import numpy as np
from mathutils import Vector

args = sys.argv[sys.argv.index("--") + 1:]
base_path, result_path, out_path = args[:3]
opts = {"view": (1.0, -1.0, 0.6), "samples": 48, "size": (960, 720), "focus": None,
        "y_up": False}
i = 3
while i < len(args):
    if args[i] == "--view":
        opts["view"] = tuple(float(x) for x in args[i + 1:i + 4]); i += 4
    elif args[i] == "--samples":
        opts["samples"] = int(args[i + 1]); i += 2
    elif args[i] == "--focus":  # X Y Z RADIUS: frame this ball instead of the whole result
        opts["focus"] = tuple(float(x) for x in args[i + 1:i + 5]); i += 5
    elif args[i] == "--y-up":  # the files' y axis is up (Blender's is z)
        opts["y_up"] = True; i += 1
    elif args[i] == "--size":
        opts["size"] = (int(args[i + 1]), int(args[i + 2])); i += 3
    else:
        raise SystemExit("unknown option %s" % args[i])

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "blender"))
import meshquilt  # noqa: E402  (the add-on package, for its reader and materials)
from meshquilt import exchange  # noqa: E402

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene


def read_base(path):
    ext = os.path.splitext(path)[1].lower()
    if ext == ".obj":  # v and f lines only, coordinates as they are (no axis conversion)
        V, F = [], []
        for line in open(path, errors="replace"):
            w = line.split()
            if w and w[0] == "v":
                V.append([float(x) for x in w[1:4]])
            elif w and w[0] == "f":
                idx = [int(x.split("/")[0]) for x in w[1:]]
                idx = [i - 1 if i > 0 else len(V) + i for i in idx]
                F += [(idx[0], idx[j], idx[j + 1]) for j in range(1, len(idx) - 1)]
        V, F = np.array(V), np.array(F)
    elif ext == ".ply":
        r = exchange.read_ply(path)
        V, F = r.V, r.F
    else:  # OFF
        words = open(path).read().split()
        nv, nf = int(words[1]), int(words[2])
        V = np.array(words[4:4 + 3 * nv], dtype=float).reshape(-1, 3)
        rest = words[4 + 3 * nv:]
        F, k = [], 0
        for _ in range(nf):
            n = int(rest[k]); idx = [int(x) for x in rest[k + 1:k + 1 + n]]; k += 1 + n
            F += [(idx[0], idx[j], idx[j + 1]) for j in range(1, n - 1)]
        F = np.array(F)
    me = bpy.data.meshes.new("base")
    me.from_pydata(V.tolist(), [], F.tolist())
    obj = bpy.data.objects.new("base", me)
    scene.collection.objects.link(obj)
    return obj


base = read_base(base_path)
grey = bpy.data.materials.new("base")
grey.use_nodes = True
grey.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.35, 0.33, 0.30, 1)
base.data.materials.clear()
base.data.materials.append(grey)
for p in base.data.polygons:
    p.use_smooth = True

result = exchange.read_ply(result_path)
me = exchange.build_mesh(bpy, "quilt", result, meshquilt.material_for)
quilt = bpy.data.objects.new("quilt", me)
scene.collection.objects.link(quilt)

lo, hi = result.V.min(axis=0), result.V.max(axis=0)
centre, radius = Vector((lo + hi) / 2), float(np.linalg.norm(hi - lo)) / 2
if opts["focus"]:
    centre, radius = Vector(opts["focus"][:3]), opts["focus"][3]
if opts["y_up"]:  # (x, y, z) -> (x, -z, y): a rotation, so the pictures are not mirrored
    from mathutils import Matrix
    turn = Matrix.Rotation(math.pi / 2, 4, "X")
    for obj in (base, quilt):
        obj.matrix_world = turn
    centre = turn @ centre
cam_data = bpy.data.cameras.new("camera")
cam_data.lens = 50
camera = bpy.data.objects.new("camera", cam_data)
scene.collection.objects.link(camera)
direction = Vector(opts["view"]).normalized()
distance = radius / math.tan(cam_data.angle / 2) * 1.05
camera.location = centre + direction * distance
camera.rotation_euler = (-direction).to_track_quat("-Z", "Y").to_euler()
scene.camera = camera
cam_data.clip_end = distance * 4
for energy, offset in ((3.0, (0.5, -0.3, 1.0)), (1.2, (-1.0, 0.5, 0.4))):
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = energy
    sun.rotation_euler = (-Vector(offset)).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(sun)
world = bpy.data.worlds.new("world")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.8, 0.82, 0.86, 1)
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
scene.world = world
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = opts["samples"]
scene.cycles.use_denoising = False
scene.render.resolution_x, scene.render.resolution_y = opts["size"]
scene.render.resolution_percentage = 100
scene.render.filepath = os.path.abspath(out_path)
bpy.ops.render.render(write_still=True)
print("[render] wrote %s: %d faces, materials %s" % (out_path, len(me.polygons),
                                                     [m.name for m in me.materials]), flush=True)
