"""Bases an artist makes in Blender, exported as OBJ for the tests and benchmarks (issue 23).

    blender -b --factory-startup --python tests/data/export_blender_bases.py -- OUT_DIR

Writes, each as Blender's operators make them (quads and n-gons kept, as an artist exports):
  uv_sphere_32x16.obj   Add > UV Sphere, the defaults (32 segments, 16 rings, radius 1)
  ico_sphere.obj        Add > Ico Sphere, the defaults (2 subdivisions)
  cube.obj              Add > Cube, scaled (2, 1, 0.5) and applied: creases and corners
  cylinder.obj          Add > Cylinder, the defaults (32 vertices, capped with n-gons)
  torus.obj             Add > Torus, the defaults
  suzanne.obj           Add > Monkey (eye sockets, brow, open-looking creases; 500 faces)
  suzanne_subdiv1.obj   the same with one Subdivision Surface level applied
  quadruped_open.obj    a four-legged animal from the Skin modifier, decimated to about 900
                        triangles, the ends of its legs and tail cut open (thin open tubes)
  mannequin.obj         a standing figure from the Skin modifier (about 6k triangles; the
                        modifier leaves small holes at branch points): thin arms hanging a hair's breadth from the torso, legs
                        close together, fingers-thin wrists (tight folds and thin parts)
  creature.obj          a crouching creature (about 4k triangles, small holes as above): large thin ears,
                        a tail curled against the back, claws (thin parts, tight folds)
Faces are written as Blender stores them; vertices at 9 significant digits.
"""

import math
import os
import sys

import bpy
import bmesh

OUT = sys.argv[sys.argv.index("--") + 1]
os.makedirs(OUT, exist_ok=True)


def clear():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def write_obj(obj, name):
    """The evaluated mesh in world space, faces as stored (no triangulation), in a fixed order:
    Blender 3.4's UV sphere lists its faces in a different order from one run to the next, and
    the quilting (a chain of discrete choices) follows the order, so the faces are sorted by their
    vertex indices, each face's own order (its winding) kept."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = obj.evaluated_get(depsgraph).to_mesh()
    mw = obj.matrix_world
    path = os.path.join(OUT, name)
    with open(path, "w") as f:
        f.write("# %s, exported by tests/data/export_blender_bases.py\n" % name)
        for v in mesh.vertices:
            p = mw @ v.co
            f.write("v %.9g %.9g %.9g\n" % (p.x, p.y, p.z))
        for face in sorted(tuple(poly.vertices) for poly in mesh.polygons):
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")
    print("[export] %s: %d vertices, %d faces" % (name, len(mesh.vertices), len(mesh.polygons)))
    obj.evaluated_get(depsgraph).to_mesh_clear()


def primitive(op, name, **kwargs):
    clear()
    op(**kwargs)
    write_obj(bpy.context.active_object, name)


def apply_all_modifiers(obj):
    bpy.context.view_layer.objects.active = obj
    for m in list(obj.modifiers):
        bpy.ops.object.modifier_apply(modifier=m.name)


primitive(bpy.ops.mesh.primitive_uv_sphere_add, "uv_sphere_32x16.obj")
primitive(bpy.ops.mesh.primitive_ico_sphere_add, "ico_sphere.obj")
primitive(bpy.ops.mesh.primitive_cylinder_add, "cylinder.obj")
primitive(bpy.ops.mesh.primitive_torus_add, "torus.obj")
primitive(bpy.ops.mesh.primitive_monkey_add, "suzanne.obj")

clear()
bpy.ops.mesh.primitive_cube_add()
cube = bpy.context.active_object
cube.scale = (2.0, 1.0, 0.5)
bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
write_obj(cube, "cube.obj")

clear()
bpy.ops.mesh.primitive_monkey_add()
monkey = bpy.context.active_object
subsurf = monkey.modifiers.new("Subdivision", "SUBSURF")
subsurf.levels = 1
write_obj(monkey, "suzanne_subdiv1.obj")


def skin_figure(name, points, chains, root, levels, faces=None):
    """A closed figure from the Skin modifier over a skeleton of (position, radius) points."""
    clear()
    names = list(points)
    index = {n: i for i, n in enumerate(names)}
    edges = []
    for chain in chains:
        edges += [(index[a], index[b]) for a, b in zip(chain, chain[1:])]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([points[n][0] for n in names], edges, [])
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.collection.objects.link(obj)
    obj.modifiers.new("Skin", "SKIN")
    for n in names:
        r = points[n][1]
        mesh.skin_vertices[0].data[index[n]].radius = r if isinstance(r, tuple) else (r, r)
    mesh.skin_vertices[0].data[index[root]].use_root = True
    sub = obj.modifiers.new("Subdivision", "SUBSURF")
    sub.levels = levels
    apply_all_modifiers(obj)
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    bmesh.ops.triangulate(bm, faces=bm.faces[:])
    bm.to_mesh(obj.data)
    bm.free()
    if faces:
        dec = obj.modifiers.new("Decimate", "DECIMATE")
        dec.ratio = min(1.0, faces / max(1, len(obj.data.polygons)))
        apply_all_modifiers(obj)
    write_obj(obj, name + ".obj")


def mannequin():
    p = {"pelvis": ((0, 0, 1.0), 0.16), "waist": ((0, 0, 1.2), 0.14),
         "chest": ((0, 0, 1.45), 0.17), "neck": ((0, 0, 1.62), 0.06),
         "head": ((0, 0, 1.78), 0.11), "crown": ((0, 0, 1.9), 0.08)}
    chains = [["pelvis", "waist", "chest", "neck", "head", "crown"]]
    for s, x in (("l", 1), ("r", -1)):
        # Arms hang down beside the torso, 0.01 from it; legs 0.02 apart.
        p["sh" + s] = ((x * 0.2, 0, 1.52), 0.06)
        p["el" + s] = ((x * 0.235, 0, 1.25), 0.045)
        p["wr" + s] = ((x * 0.235, 0, 1.02), 0.03)
        p["ha" + s] = ((x * 0.235, 0.01, 0.92), (0.045, 0.015))
        chains.append(["chest", "sh" + s, "el" + s, "wr" + s, "ha" + s])
        p["hip" + s] = ((x * 0.09, 0, 0.92), 0.08)
        p["kn" + s] = ((x * 0.08, 0, 0.5), 0.06)
        p["an" + s] = ((x * 0.075, 0, 0.08), 0.04)
        p["to" + s] = ((x * 0.075, 0.14, 0.03), 0.03)
        chains.append(["pelvis", "hip" + s, "kn" + s, "an" + s, "to" + s])
    skin_figure("mannequin", p, chains, "pelvis", 2)


def creature():
    p = {"hip": ((-0.5, 0, 0.6), 0.3), "back": ((0, 0, 0.75), 0.34),
         "chest": ((0.45, 0, 0.8), 0.3), "neck": ((0.75, 0, 1.0), 0.15),
         "head": ((0.95, 0, 1.15), 0.2), "snout": ((1.2, 0, 1.1), 0.09),
         # A tail that curls up over the back, close to it.
         "t1": ((-0.85, 0, 0.6), 0.1), "t2": ((-1.05, 0, 0.85), 0.07),
         "t3": ((-0.85, 0, 1.12), 0.05), "t4": ((-0.45, 0, 1.14), 0.04)}
    chains = [["t4", "t3", "t2", "t1", "hip", "back", "chest", "neck", "head", "snout"]]
    for s, y in (("l", 1), ("r", -1)):
        # Large thin ears.
        p["ear" + s] = ((0.92, y * 0.2, 1.35), (0.02, 0.08))
        p["eart" + s] = ((0.88, y * 0.32, 1.62), (0.01, 0.04))
        chains.append(["head", "ear" + s, "eart" + s])
        for e, x in (("f", 0.45), ("b", -0.5)):
            top, knee, paw, claw = e + s + "t", e + s + "k", e + s + "p", e + s + "c"
            p[top] = ((x, y * 0.25, 0.45), 0.12)
            p[knee] = ((x + 0.15, y * 0.3, 0.25), 0.07)
            p[paw] = ((x + 0.05, y * 0.3, 0.05), 0.06)
            p[claw] = ((x + 0.2, y * 0.3, 0.02), 0.015)
            chains.append(["chest" if e == "f" else "hip", top, knee, paw, claw])
    skin_figure("creature", p, chains, "back", 2, faces=4000)


def quadruped():
    """A skin-modifier animal: body, neck, head, four legs, a tail; ends of legs and tail open."""
    clear()
    # Skeleton: (position, skin radius); edges between consecutive indices of each chain.
    points = {
        "hip": ((-0.8, 0.0, 0.9), 0.32), "mid": ((0.0, 0.0, 0.95), 0.38),
        "chest": ((0.8, 0.0, 1.0), 0.35), "neck": ((1.2, 0.0, 1.4), 0.18),
        "head": ((1.55, 0.0, 1.55), 0.22), "snout": ((1.85, 0.0, 1.45), 0.13),
        "tail1": ((-1.25, 0.0, 1.0), 0.07), "tail2": ((-1.6, 0.0, 0.75), 0.05),
    }
    chains = [["tail2", "tail1", "hip", "mid", "chest", "neck", "head", "snout"]]
    for side, y in (("l", 0.22), ("r", -0.22)):
        for end, x in (("f", 0.8), ("b", -0.8)):
            top, knee, foot = end + side + "_top", end + side + "_knee", end + side + "_foot"
            points[top] = ((x, y, 0.75), 0.14)
            points[knee] = ((x + 0.05, y, 0.4), 0.09)
            points[foot] = ((x, y, 0.02), 0.08)
            chains.append(["chest" if end == "f" else "hip", top, knee, foot])
    names = list(points)
    index = {n: i for i, n in enumerate(names)}
    mesh = bpy.data.meshes.new("quadruped")
    edges = []
    for chain in chains:
        edges += [(index[a], index[b]) for a, b in zip(chain, chain[1:])]
    mesh.from_pydata([points[n][0] for n in names], edges, [])
    obj = bpy.data.objects.new("quadruped", mesh)
    bpy.context.collection.objects.link(obj)
    skin = obj.modifiers.new("Skin", "SKIN")
    skin.use_smooth_shade = True
    for n in names:
        r = points[n][1]
        mesh.skin_vertices[0].data[index[n]].radius = (r, r)
    mesh.skin_vertices[0].data[index["mid"]].use_root = True
    sub = obj.modifiers.new("Subdivision", "SUBSURF")
    sub.levels = 2
    apply_all_modifiers(obj)
    # Cut the ends open: the faces at the feet (lowest) and at the tail's tip.
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    foot_z = 0.06
    tail_x = -1.55
    doomed = [f for f in bm.faces
              if all(v.co.z < foot_z for v in f.verts) or all(v.co.x < tail_x for v in f.verts)]
    bmesh.ops.delete(bm, geom=doomed, context="FACES")
    bmesh.ops.triangulate(bm, faces=bm.faces[:])
    bm.to_mesh(obj.data)
    bm.free()
    dec = obj.modifiers.new("Decimate", "DECIMATE")
    dec.ratio = min(1.0, 900.0 / max(1, len(obj.data.polygons)))
    dec.use_collapse_triangulate = True
    apply_all_modifiers(obj)
    write_obj(obj, "quadruped_open.obj")


quadruped()
mannequin()
creature()
