#!/usr/bin/env python3
"""Rigid copies of one swatch element scattered over a base mesh, as an instancing tool places
them (Blender's "distribute points on faces" + "instance on points": area-uniform random points,
each copy standing on the surface normal with a random turn about it). It is the comparison for
the README's picture pair: the same element and density as a quilt, none of its structure.

    python3 scripts/scatter_copies.py BASE SWATCH SCALE COUNT OUT [--seed N]

SCALE is the factor the quilt applied to the swatch (the `swatch_scale` of `surface --stats`),
COUNT the number of copies (the quilt's element count, for the same density). Standard library
only; OBJ or OFF base, OBJ swatch; writes OBJ.
"""
import math
import random
import sys


def read_mesh(path):
    verts, faces = [], []
    with open(path) as f:
        if path.lower().endswith(".off"):
            tokens = [t for line in f for t in line.split("#")[0].split()]
            if tokens[0] != "OFF":
                raise SystemExit(f"{path}: not an OFF file")
            nv, nf = int(tokens[1]), int(tokens[2])
            at = 4
            for _ in range(nv):
                verts.append(tuple(float(x) for x in tokens[at:at + 3]))
                at += 3
            for _ in range(nf):
                n = int(tokens[at])
                idx = [int(x) for x in tokens[at + 1:at + 1 + n]]
                at += 1 + n
                for k in range(1, n - 1):
                    faces.append((idx[0], idx[k], idx[k + 1]))
        else:
            for line in f:
                p = line.split()
                if not p:
                    continue
                if p[0] == "v":
                    verts.append(tuple(float(x) for x in p[1:4]))
                elif p[0] == "f":
                    idx = [int(x.split("/")[0]) - 1 for x in p[1:]]
                    for k in range(1, len(idx) - 1):
                        faces.append((idx[0], idx[k], idx[k + 1]))
    return verts, faces


def sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
def add(a, b): return (a[0] + b[0], a[1] + b[1], a[2] + b[2])
def mul(a, s): return (a[0] * s, a[1] * s, a[2] * s)
def dot(a, b): return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def norm(a): return math.sqrt(dot(a, a))


def first_element(verts, faces):
    """Vertices and faces of the swatch's first connected component."""
    parent = list(range(len(verts)))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a
    for f in faces:
        a, b, c = find(f[0]), find(f[1]), find(f[2])
        parent[b] = a
        parent[find(c)] = a
    root = find(faces[0][0])
    keep = [f for f in faces if find(f[0]) == root]
    used = sorted({v for f in keep for v in f})
    remap = {v: i for i, v in enumerate(used)}
    return [verts[v] for v in used], [tuple(remap[v] for v in f) for f in keep]


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    seed = 1
    if "--seed" in argv:
        seed = int(argv[argv.index("--seed") + 1])
        args.remove(str(seed))
    if len(args) != 5:
        raise SystemExit(__doc__)
    base_path, swatch_path, scale, count, out = args[0], args[1], float(args[2]), int(args[3]), args[4]
    bv, bf = read_mesh(base_path)
    sv, sf = read_mesh(swatch_path)
    ev, ef = first_element(sv, sf)
    # The element centred, thickness axis (the swatch's smallest box side) along z, scaled.
    lo = [min(v[k] for v in sv) for k in range(3)]
    hi = [max(v[k] for v in sv) for k in range(3)]
    thin = min(range(3), key=lambda k: hi[k] - lo[k])
    axes = [(thin + 1) % 3, (thin + 2) % 3, thin]
    centre = [sum(v[k] for v in ev) / len(ev) for k in range(3)]
    local = [tuple((v[a] - centre[a]) * scale for a in axes) for v in ev]
    height = (hi[thin] - lo[thin]) * scale
    areas = []
    total = 0.0
    for f in bf:
        a = norm(cross(sub(bv[f[1]], bv[f[0]]), sub(bv[f[2]], bv[f[0]]))) / 2
        total += a
        areas.append(total)
    rng = random.Random(seed)
    with open(out, "w") as o:
        o.write(f"# {count} rigid copies of {swatch_path}'s first element scattered on {base_path}\n")
        nv = 0
        for _ in range(count):
            r = rng.random() * total
            lo_i, hi_i = 0, len(areas) - 1
            while lo_i < hi_i:
                mid = (lo_i + hi_i) // 2
                if areas[mid] < r:
                    lo_i = mid + 1
                else:
                    hi_i = mid
            a, b, c = (bv[i] for i in bf[lo_i])
            u, v = rng.random(), rng.random()
            if u + v > 1:
                u, v = 1 - u, 1 - v
            p = add(a, add(mul(sub(b, a), u), mul(sub(c, a), v)))
            n = cross(sub(b, a), sub(c, a))
            n = mul(n, 1 / max(norm(n), 1e-300))
            t = sub(b, a)
            t = sub(t, mul(n, dot(t, n)))
            t = mul(t, 1 / max(norm(t), 1e-300))
            w = cross(n, t)
            turn = rng.random() * 2 * math.pi
            e1 = add(mul(t, math.cos(turn)), mul(w, math.sin(turn)))
            e2 = cross(n, e1)
            origin = add(p, mul(n, 0.5 * height))
            for x, y, z in local:
                q = add(origin, add(mul(e1, x), add(mul(e2, y), mul(n, z))))
                o.write(f"v {q[0]:.7g} {q[1]:.7g} {q[2]:.7g}\n")
            for f in ef:
                o.write(f"f {f[0] + nv + 1} {f[1] + nv + 1} {f[2] + nv + 1}\n")
            nv += len(local)


if __name__ == "__main__":
    main(sys.argv[1:])
