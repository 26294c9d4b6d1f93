"""Meshes between Blender and the engine, as binary PLY files read and written with numpy.

The engine writes its results with per-vertex `element_id` and `kind` properties and names the
kinds in "comment kind K NAME" and "comment kind_material K R G B METALLIC ROUGHNESS" header
lines (core/mesh/mesh_io.h); the add-on sends bases and swatches the same way (a swatch's kinds are
its material names).
"""

import numpy as np

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
    "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}


def mesh_arrays(mesh):
    """Vertices (#V x 3), triangles (#T x 3) and each triangle's polygon material index."""
    mesh.calc_loop_triangles()
    V = np.empty(3 * len(mesh.vertices), dtype=np.float64)
    mesh.vertices.foreach_get("co", V)
    T = np.empty(3 * len(mesh.loop_triangles), dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", T)
    M = np.empty(len(mesh.loop_triangles), dtype=np.int32)
    mesh.loop_triangles.foreach_get("material_index", M)
    T, M = canonical_triangles(T.reshape(-1, 3), M)
    return V.reshape(-1, 3), T, M


def canonical_triangles(T, M):
    """The triangles (#T x 3) and their material indices in one order that depends only on the
    set of triangles: each starts at its lowest vertex (its orientation kept), all sorted.
    Blender's loop triangles of the same mesh came in a different order from run to run (a UV
    sphere: 838 to 883 rings from one Run to the next), and the engine's result depends on the
    order of the base's faces."""
    if len(T) == 0:
        return T, M
    first = T.argmin(axis=1)
    rows = np.arange(len(T))[:, None]
    R = T[rows, (first[:, None] + np.arange(3)[None, :]) % 3]
    order = np.lexsort((R[:, 2], R[:, 1], R[:, 0]))
    return np.ascontiguousarray(R[order]), M[order]


def part_face_counts(T, vertex_count):
    """Triangles per connected part (triangles joined by shared vertices): a swatch's elements
    as the engine counts them."""
    label = np.arange(vertex_count)
    while True:
        lowest = label[T].min(axis=1)
        new = label.copy()
        for k in range(3):
            np.minimum.at(new, T[:, k], lowest)
        new = new[new]  # each vertex takes its label's label: a long part settles in few passes
        if np.array_equal(new, label):
            break
        label = new
    counts = np.bincount(label[T[:, 0]], minlength=vertex_count)
    return counts[counts > 0]


def write_ply(path, V, T, kinds=None, triangle_kind=None):
    """Binary PLY; with kinds, each vertex takes the kind of a triangle using it."""
    V = np.ascontiguousarray(V, dtype="<f8")
    T = np.ascontiguousarray(T, dtype="<i4")
    header = ["ply", "format binary_little_endian 1.0"]
    fields = [("x", "<f8"), ("y", "<f8"), ("z", "<f8")]
    if kinds:
        for k, name in enumerate(kinds):
            header.append("comment kind %d %s" % (k, name))
        fields.append(("kind", "<i4"))
    header.append("element vertex %d" % len(V))
    header += ["property double x", "property double y", "property double z"]
    if kinds:
        header.append("property int kind")
    header += ["element face %d" % len(T), "property list uchar int vertex_indices",
               "end_header"]
    vertices = np.zeros(len(V), dtype=fields)
    vertices["x"], vertices["y"], vertices["z"] = V[:, 0], V[:, 1], V[:, 2]
    if kinds:
        vk = np.zeros(len(V), dtype="<i4")
        vk[T.ravel()] = np.repeat(np.asarray(triangle_kind, dtype="<i4"), 3)
        vertices["kind"] = vk
    faces = np.zeros(len(T), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    faces["n"] = 3
    faces["v"] = T
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        f.write(vertices.tobytes())
        f.write(faces.tobytes())


class PlyResult:
    """A result read back: V, N (or None), F, per-vertex element id and kind, kind names and
    looks (name -> (r, g, b, metallic, roughness))."""

    def __init__(self, V, N, F, element, kind, kinds, looks):
        self.V, self.N, self.F = V, N, F
        self.vertex_element, self.vertex_kind = element, kind
        self.kinds, self.looks = kinds, looks

    @property
    def face_element(self):
        return self.vertex_element[self.F[:, 0]]

    @property
    def face_kind(self):
        return self.vertex_kind[self.F[:, 0]]


def read_ply(path):
    """Reads a binary little-endian triangle PLY as the engine writes it."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        raise ValueError("%s: not a PLY file" % path)
    lines = data[:end].decode("ascii", "replace").splitlines()
    body = end + len(b"end_header\n")
    kinds, looks, elements = {}, {}, []
    for line in lines:
        w = line.split()
        if not w:
            continue
        if w[0] == "format" and w[1] != "binary_little_endian":
            raise ValueError("%s: expected a binary little-endian PLY" % path)
        if w[0] == "comment" and len(w) >= 4 and w[1] == "kind":
            kinds[int(w[2])] = w[3]
        elif w[0] == "comment" and len(w) == 8 and w[1] == "kind_material":
            looks[int(w[2])] = tuple(float(x) for x in w[3:8])
        elif w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property":
            elements[-1][2].append(w[1:])
    offset = body
    out = {}
    for name, count, props in elements:
        if name == "face":
            if props != [["list", "uchar", "int", "vertex_indices"]]:
                raise ValueError("%s: unexpected face properties %s" % (path, props))
            dt = np.dtype([("n", "u1"), ("v", "<i4", (3,))])
        else:
            dt = np.dtype([(p[-1], "<" + _PLY_TYPES[p[0]]) for p in props])
        arr = np.frombuffer(data, dtype=dt, count=count, offset=offset)
        offset += dt.itemsize * count
        out[name] = arr
    v, f = out["vertex"], out["face"]
    if len(f) and not np.all(f["n"] == 3):
        raise ValueError("%s: faces must be triangles" % path)
    V = np.stack([v["x"], v["y"], v["z"]], axis=1)
    names = v.dtype.names
    N = np.stack([v["nx"], v["ny"], v["nz"]], axis=1) if "nx" in names else None
    element = np.array(v["element_id"], dtype=np.int32) if "element_id" in names else \
        np.zeros(len(v), dtype=np.int32)
    kind = np.array(v["kind"], dtype=np.int32) if "kind" in names else \
        np.zeros(len(v), dtype=np.int32)
    count = int(kind.max()) + 1 if len(kind) else 1
    kind_names = [kinds.get(k, "kind_%d" % k) for k in range(count)]
    kind_looks = {kind_names[k]: looks[k] for k in range(count) if k in looks}
    return PlyResult(V, N, np.array(f["v"], dtype=np.int32), element, kind, kind_names,
                     kind_looks)


def build_mesh(bpy, name, result, material_for):
    """A Blender mesh from a PlyResult: one material slot per kind, the integer face attribute
    `element_id` (and `kind`), smooth shading with auto smooth at 60 degrees so that sharp
    edges stay sharp."""
    import math
    me = bpy.data.meshes.new(name)
    nv, nf = len(result.V), len(result.F)
    me.vertices.add(nv)
    me.vertices.foreach_set("co", result.V.astype(np.float32).ravel())
    me.loops.add(3 * nf)
    me.loops.foreach_set("vertex_index", result.F.ravel())
    me.polygons.add(nf)
    me.polygons.foreach_set("loop_start", np.arange(0, 3 * nf, 3, dtype=np.int32))
    # MeshPolygon.loop_total is read-only from Blender 4.0 (a face's size follows from the next
    # face's loop_start); before 4.0 it must be set.
    if bpy.app.version < (4, 0, 0):
        me.polygons.foreach_set("loop_total", np.full(nf, 3, dtype=np.int32))
    for name_k in result.kinds:
        me.materials.append(material_for(name_k, result.looks.get(name_k)))
    me.polygons.foreach_set("material_index", result.face_kind.astype(np.int32))
    me.polygons.foreach_set("use_smooth", np.ones(nf, dtype=bool))
    me.update(calc_edges=True)
    ids = me.attributes.new("element_id", "INT", "FACE")
    ids.data.foreach_set("value", result.face_element.astype(np.int32))
    kinds = me.attributes.new("kind", "INT", "FACE")
    kinds.data.foreach_set("value", result.face_kind.astype(np.int32))
    # Mesh.use_auto_smooth and auto_smooth_angle were removed in Blender 4.1: there, edges over
    # 60 degrees are marked sharp once instead (Mesh.set_sharp_from_angle, new in 4.1).
    if bpy.app.version < (4, 1, 0):
        me.use_auto_smooth = True
        me.auto_smooth_angle = math.radians(60)
    elif hasattr(me, "set_sharp_from_angle"):
        me.set_sharp_from_angle(angle=math.radians(60))
    return me


DISTORTED_SIZE_RATIO = 1.5  # an element over 1.5x its swatch element's size is "distorted"


def read_elements_csv(path):
    """meshquilt info --elements: each element's id and size ratio against its swatch element
    (0 where not measured)."""
    import csv
    ids, ratios = [], []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            ids.append(int(row["element"]))
            ratios.append(float(row.get("size_ratio") or 0.0))
    return np.array(ids, dtype=np.int32), np.array(ratios, dtype=np.float64)


def structure_report(stats_path=None, elements_csv=None):
    """A result's structure for the artist, from surface --stats JSON and info --elements CSV
    (either may be missing): elements, links_kept (% of interior rings with their swatch kind's
    links; rings only), coverage (%), distorted (count) and distorted_ids."""
    import json
    import os
    report = {}
    if stats_path and os.path.exists(stats_path):
        with open(stats_path) as f:
            stats = json.load(f)
        structure = stats.get("structure") or {}
        elements = structure.get("elements", (stats.get("output") or {}).get("elements"))
        if elements is not None:
            report["elements"] = int(elements)
        if structure.get("share_with_swatch_links") is not None:
            report["links_kept"] = 100.0 * float(structure["share_with_swatch_links"])
        if stats.get("coverage") is not None:
            report["coverage"] = 100.0 * float(stats["coverage"])
        # The engine's own check of the structure (core/structure/structure_check): each figure
        # outside its limit, one sentence each, joined (ID properties hold no list of strings).
        shortfalls = (stats.get("structure_check") or {}).get("shortfalls") or []
        if shortfalls:
            report["warnings"] = "; ".join(str(s["text"]) for s in shortfalls)
    if elements_csv and os.path.exists(elements_csv):
        ids, ratios = read_elements_csv(elements_csv)
        report.setdefault("elements", len(ids))
        distorted = ids[ratios > DISTORTED_SIZE_RATIO]
        report["distorted"] = len(distorted)
        report["distorted_ids"] = [int(i) for i in distorted]
    return report
